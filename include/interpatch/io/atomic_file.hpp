#pragma once
/// @file io/atomic_file.hpp
/// Output files written whole or not at all: a temporary file in the target's
/// directory, renamed into place when complete.

#include <filesystem>
#include <functional>
#include <ostream>

namespace interpatch::io {

/// Refuses an output path before any work is done: its directory must exist (it is
/// never created) and be writable, and the path must not be a directory.
/// @throws error file_unwritable naming the path and the reason.
void check_writable(const std::filesystem::path& path);

/// Runs `write` on a stream to a temporary file beside `path`, flushes and syncs
/// it, then renames it onto `path`. If `write` throws or any write fails, the
/// temporary file is removed, `path` is left as it was, and the error propagates.
///
/// Example:
/// @code
///   interpatch::io::write_atomically("out.txt", [](std::ostream& os) { os << "hello\n"; });
/// @endcode
/// @throws error file_unwritable.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

}  // namespace interpatch::io
