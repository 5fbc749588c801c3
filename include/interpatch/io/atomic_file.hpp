#pragma once
/// @file io/atomic_file.hpp
/// Output files written whole or not at all, even when the process is killed: an
/// unnamed file in the target's directory, given the target's name when complete.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace interpatch::io {

/// Refuses an output path before any work is done: its directory must exist (it is
/// never created) and be writable, and the path must not be a directory or another
/// non-regular file. Creates nothing.
/// @throws error file_unwritable naming the path and the reason.
void check_writable(const std::filesystem::path& path);

/// Refuses an output of `bytes` that does not fit in the space free to this user on
/// the file system of `path`'s directory, before any work is done. A file system
/// that cannot tell its free space is not refused.
/// @throws error too_large: "<what> needs 240 GB (240000000000 bytes), 76.2 GB
/// available on disk in 'dir' (76200000000 bytes)".
void check_disk_space(const std::filesystem::path& path, std::uintmax_t bytes, std::string_view what);

/// Whether write_atomically also waits until the file and its directory entry are
/// on the disk (fsync) before it returns. Off by default: the rename (or link)
/// alone already keeps every promise of a failed or killed run (no half-written
/// file, no good file replaced by a bad one), and on ext4 (data=ordered, auto_da_alloc) a rename over an
/// existing file is ordered after its data, so even a power loss leaves the old
/// file or the new one. On, it protects new files on any file system against a
/// power loss or a kernel crash, at the price of waiting for the disk: 4–12 ms per
/// 25 MB on the machine of docs/BENCHMARKS.md. The interpatch command turns it on
/// when the environment holds INTERPATCH_SYNC=1. Process-wide.
void set_durable_writes(bool on) noexcept;
[[nodiscard]] bool durable_writes() noexcept;

/// Runs `write` on a stream to a new file in `path`'s directory, flushes it (and
/// syncs it, when durable_writes()), then puts it at `path`, replacing what is
/// there; `path` holds the old file or the complete new one at every moment.
///
/// On Linux file systems with O_TMPFILE (ext4, XFS, Btrfs, tmpfs; /proc mounted)
/// the new file has no name while it is written, nothing of it shows in the
/// directory, and a process killed at any moment, even by SIGKILL, leaves nothing
/// behind. Complete, a new output gets its name in one step (linkat); an existing
/// one is replaced by a rename from a name ".name.interpatch-tmp.<pid>.XXXXXX"
/// (the name cut to 199 characters) given to the file just before, so that only a
/// kill between those two system calls leaves something: that complete file
/// beside the intact old output. Where O_TMPFILE is not supported (some NFS,
/// overlay and FUSE file systems) the file has a name of that pattern for the
/// whole write, and a killed run leaves it there, partial. Either way each write
/// first removes the files of that pattern in the directory whose process no
/// longer exists and that no live process holds locked (flock, held by the writer
/// until its file is in place). Files ".name.tmp.XXXXXX" of earlier versions carry
/// no pid and are never removed.
///
/// If `write` throws or any write fails, the new file is removed, `path` is left as
/// it was, and the error propagates: the writer's own exception unchanged, a failed
/// write (disk full, file too large) as file_unwritable naming the path and the
/// reason; the stream throws on the first failure, so a writer stops early. The
/// result gets the permissions of the file it replaces, or 0666 minus the umask
/// when new; a symbolic link at `path` is kept and the file it points to replaced.
/// `size`, when the writer knows it, is the number of bytes it will write: the
/// file's space is then allocated in one go (a file that ends up shorter is cut to
/// what was written).
/// The stream can seek (seekp, tellp) within what was written, so that a header
/// can be filled in once the data after it are written (a ZIP member's checksum);
/// the file's size is the end of the furthest byte written.
///
/// Example:
/// @code
///   interpatch::io::write_atomically("out.txt", [](std::ostream& os) { os << "hello\n"; });
/// @endcode
/// @throws error file_unwritable.
void write_atomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& write,
                      std::uintmax_t size = 0);

/// Refuses an output directory (an OpenFOAM polyMesh) before any work: its parent must
/// exist (it is never created) and be writable, and the path must be a directory or
/// nothing. Creates nothing. @throws error file_unwritable naming the path and the reason.
void check_writable_directory(const std::filesystem::path& path);

/// Runs `write` on a new, empty directory beside `path` (".name.interpatch-tmp.<pid>.XXXXXX"),
/// then puts it at `path`: a new output by one rename, an existing directory swapped
/// with it in one step (renameat2 RENAME_EXCHANGE) and then removed. `path` holds the
/// old directory or the whole new one at every moment. If `write` throws, the new
/// directory is removed and the exception propagates; a process killed while writing
/// leaves the temporary directory behind.
/// @throws error file_unwritable, and what `write` throws.
void write_directory_atomically(const std::filesystem::path& path,
                                const std::function<void(const std::filesystem::path&)>& write);

}  // namespace interpatch::io
