#pragma once
/// @file io/atomic_file.hpp
/// Output files written whole or not at all: a temporary file in the target's
/// directory, renamed into place when complete.

#include <filesystem>
#include <functional>
#include <ostream>

namespace interpatch::io {

/// Refuses an output path before any work is done: its directory must exist (it is
/// never created) and be writable, and the path must not be a directory or another
/// non-regular file. Creates nothing.
/// @throws error file_unwritable naming the path and the reason.
void check_writable(const std::filesystem::path& path);

/// Runs `write` on a stream to a temporary file beside `path` (".name.tmp.XXXXXX"),
/// flushes and syncs it, then renames it onto `path`. If `write` throws or any
/// write fails, the temporary file is removed, `path` is left as it was, and the
/// error propagates: the writer's own exception unchanged, a failed write (disk
/// full, file too large) as file_unwritable naming the path and the reason; the
/// stream throws on the first failure, so a writer stops early. The result gets
/// the permissions of the file it replaces, or 0666 minus the umask when new; a
/// symbolic link at `path` is kept and the file it points to replaced.
///
/// Example:
/// @code
///   interpatch::io::write_atomically("out.txt", [](std::ostream& os) { os << "hello\n"; });
/// @endcode
/// @throws error file_unwritable.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write);

}  // namespace interpatch::io
