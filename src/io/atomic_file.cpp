#include "interpatch/io/atomic_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ios>
#include <memory>
#include <mutex>
#include <streambuf>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "base/text.hpp"
#include "io/extension.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

using internal::quoted;

fs::path directory_of(const fs::path& path) {
  fs::path dir = path.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

/// Follows a chain of symbolic links so that writing "through" a link replaces the
/// file it points to and keeps the link.
fs::path resolve_links(fs::path path) {
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(path, ec))) return path;
    fs::path target = fs::read_symlink(path, ec);
    if (ec) return path;
    path = target.is_absolute() ? target : path.parent_path() / target;
  }
  detail::fail(errc::file_unwritable, "cannot write ", quoted(path), ": too many levels of symbolic links");
}

/// The permission bits a new file gets from open(..., 0666): 0666 minus the umask.
mode_t default_file_mode() {
  // /proc/self/status reports the umask without changing it (Linux >= 4.7).
  if (std::FILE* f = std::fopen("/proc/self/status", "re")) {
    char line[256];
    unsigned mask = 0;
    bool found = false;
    while (std::fgets(line, sizeof line, f)) {
      if (std::sscanf(line, "Umask: %o", &mask) == 1) {
        found = true;
        break;
      }
    }
    std::fclose(f);
    if (found) return static_cast<mode_t>(0666 & ~mask);
  }
  // Reading the umask means setting it; serialize our own readers at least.
  static std::mutex m;
  std::lock_guard<std::mutex> lock(m);
  const mode_t mask = umask(022);
  umask(mask);
  return static_cast<mode_t>(0666 & ~mask);
}

std::atomic<bool> durable_flag{false};

/// An output buffer over a file descriptor that remembers the first write error.
/// It can seek back into what was written (seekp), so that a writer may fill in a
/// header once the data after it are known (a ZIP member's checksum).
class fd_buffer : public std::streambuf {
 public:
  fd_buffer(int fd, bool durable) : fd_(fd), durable_(durable), buf_(std::make_unique_for_overwrite<char[]>(size)) {
    setp(buf_.get(), buf_.get() + size);
  }
  fd_buffer(const fd_buffer&) = delete;
  fd_buffer& operator=(const fd_buffer&) = delete;

  /// errno of the first failed write, 0 if none.
  [[nodiscard]] int error() const noexcept { return errno_; }
  /// The size of the file so far: the end of the furthest byte handed to it.
  [[nodiscard]] std::size_t written() const noexcept { return end_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }

  std::streamsize xsputn(const char* s, std::streamsize n) override {
    const auto room = static_cast<std::streamsize>(epptr() - pptr());
    // Small writes gather in the buffer. Large blocks bypass it, even when they would
    // fit: a copy through it costs about as much as the write itself, and it falls
    // on the thread that writes while the others compute.
    if (n <= room && n < large) {
      if (n > 0) std::memcpy(pptr(), s, static_cast<std::size_t>(n));  // s may be null for nothing (an empty array)
      pbump(static_cast<int>(n));
      return n;
    }
    if (!drain() || !write_all(s, static_cast<std::size_t>(n))) return 0;
    return n;
  }

  int sync() override { return drain() ? 0 : -1; }

  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    const auto here = static_cast<off_type>(offset_) + static_cast<off_type>(pptr() - pbase());
    if (dir == std::ios_base::cur && off == 0) return pos_type(here);  // tellp: no need to write anything
    const off_type base = dir == std::ios_base::beg   ? 0
                          : dir == std::ios_base::cur ? here
                                                      : std::max(here, static_cast<off_type>(end_));
    return seekpos(pos_type(base + off), which);
  }

  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    const off_type to = pos;
    if (!(which & std::ios_base::out) || to < 0 || !drain()) return pos_type(off_type(-1));
    if (::lseek(fd_, static_cast<off_t>(to), SEEK_SET) < 0) {
      errno_ = errno;
      return pos_type(off_type(-1));
    }
    offset_ = static_cast<std::size_t>(to);
    return pos;
  }

 private:
  bool drain() {
    const auto n = static_cast<std::size_t>(pptr() - pbase());
    const bool ok = write_all(pbase(), n);
    setp(buf_.get(), buf_.get() + size);
    return ok;
  }

  // Writes in pieces of a few MiB. For a durable write, on Linux, the disk
  // writeback of each piece starts at once (sync_file_range, which does not wait):
  // the fsync before the rename then waits for the last pieces only.
  bool write_all(const char* s, std::size_t n) {
    if (errno_ != 0) return false;
    constexpr std::size_t piece = std::size_t{4} << 20;
    while (n > 0) {
      const ssize_t w = ::write(fd_, s, std::min(n, piece));
      if (w < 0) {
        if (errno == EINTR) continue;
        errno_ = errno;
        return false;
      }
#ifdef __linux__
      if (durable_) ::sync_file_range(fd_, static_cast<off_t>(offset_), static_cast<off_t>(w), SYNC_FILE_RANGE_WRITE);
#endif
      offset_ += static_cast<std::size_t>(w);
      end_ = std::max(end_, offset_);
      s += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  }

  static constexpr std::size_t size = std::size_t{1} << 20;            // the buffer's bytes
  static constexpr std::streamsize large = std::streamsize{64} << 10;  // bytes written without the buffer

  int fd_;
  bool durable_;
  std::size_t offset_ = 0;  // where the file descriptor is: the file position of pbase()
  std::size_t end_ = 0;
  // Not zeroed: a page of it is touched only when a write reaches it (an .npy's
  // header touches one; zeroing all of it cost a third of a millisecond before the
  // first byte was written).
  std::unique_ptr<char[]> buf_;
  int errno_ = 0;
};

[[noreturn]] void fail_write(const fs::path& path, const std::string& reason) {
  detail::fail(errc::file_unwritable, "cannot write ", quoted(path), ": ", reason);
}

// Names of the files this code creates under a name in an output's directory:
// ".<output name>.interpatch-tmp.<pid>.<6 letters or digits>". A run killed at the
// wrong moment may leave one behind; the pid in the name lets the next write into
// the directory tell a leftover of a dead process from a file still being written.
constexpr std::string_view leftover_marker = ".interpatch-tmp.";
constexpr std::size_t leftover_random = 6;

std::string random_letters() {
  static constexpr char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  unsigned char bytes[leftover_random] = {};
  if (::getrandom(bytes, sizeof bytes, GRND_NONBLOCK) != static_cast<ssize_t>(sizeof bytes)) {
    // No entropy yet (early boot): a counter and the clock still differ from call
    // to call, and a name already taken is retried anyway.
    static std::atomic<std::uint64_t> counter{0};
    std::uint64_t x = counter.fetch_add(1) * 0x9e3779b97f4a7c15u ^
                      static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
    for (unsigned char& b : bytes) {
      b = static_cast<unsigned char>(x);
      x = (x >> 8) | (x << 56);
    }
  }
  std::string s;
  for (const unsigned char b : bytes) s += alphabet[b % (sizeof alphabet - 1)];
  return s;
}

std::string leftover_name(const std::string& target_name) {
  std::string name = "." + target_name;
  if (name.size() > 200) name.resize(200);  // room for the rest within NAME_MAX (255)
  return name + std::string(leftover_marker) + std::to_string(::getpid()) + "." + random_letters();
}

/// The pid in a name of the leftover pattern; 0 for any other name.
pid_t leftover_pid(std::string_view name) {
  if (name.size() < 1 + leftover_marker.size() + 1 + 1 + leftover_random || name.front() != '.') return 0;
  const std::size_t dot = name.size() - leftover_random - 1;
  if (name[dot] != '.') return 0;
  for (std::size_t i = dot + 1; i < name.size(); ++i)
    if (std::isalnum(static_cast<unsigned char>(name[i])) == 0) return 0;
  std::size_t first = dot;
  while (first > 0 && name[first - 1] >= '0' && name[first - 1] <= '9') --first;
  if (first == dot || dot - first > 9) return 0;  // pids stay below 2^22
  if (first < 1 + leftover_marker.size() || name.substr(first - leftover_marker.size(), leftover_marker.size()) !=
                                                leftover_marker)
    return 0;
  pid_t pid = 0;
  for (std::size_t i = first; i < dot; ++i) pid = static_cast<pid_t>(pid * 10 + (name[i] - '0'));
  return pid;
}

/// Removes `name` from the directory if it is a regular file nobody holds: its
/// writer takes a lock on it from the start (flock, released by the kernel when the
/// process dies however it dies). The lock matters where the pid cannot tell:
/// a writer in another pid namespace (a container sharing the directory) whose pid
/// means nothing here. A file that cannot be opened to check (no read permission,
/// or a file system without locks) is judged by its pid alone.
void remove_if_unheld(int dirfd, const std::string& name) {
  struct stat st {};
  if (::fstatat(dirfd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode)) return;
  const int fd = ::openat(dirfd, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd >= 0) {
    // A shared lock conflicts with the writer's exclusive one all the same, and
    // needs only read access where flock is emulated by POSIX locks (NFS).
    const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    struct stat now {};
    const bool same = ::fstat(fd, &now) == 0 && now.st_dev == st.st_dev && now.st_ino == st.st_ino;
    if (held || !same) {
      ::close(fd);
      return;
    }
  }
  ::unlinkat(dirfd, name.c_str(), 0);  // still holding the lock, if taken
  if (fd >= 0) ::close(fd);
}

/// Removes the leftovers (see leftover_marker) in the directory whose process no
/// longer exists. A pid that exists again (reused) keeps its leftover until a later
/// write: the cost is some disk space for a while, never someone's file in use.
/// Errors are ignored: cleaning up is a courtesy, the write goes ahead regardless.
void remove_stale_leftovers(int dirfd) {
  const int fd = ::openat(dirfd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  DIR* dir = ::fdopendir(fd);
  if (dir == nullptr) {
    ::close(fd);
    return;
  }
  std::vector<std::string> stale;
  while (const dirent* e = ::readdir(dir)) {
    const pid_t pid = leftover_pid(e->d_name);
    // kill(pid, 0) fails with ESRCH only when no such process exists; EPERM is
    // another user's live process.
    if (pid > 0 && ::kill(pid, 0) != 0 && errno == ESRCH) stale.emplace_back(e->d_name);
  }
  ::closedir(dir);
  for (const std::string& name : stale) remove_if_unheld(dirfd, name);
}

/// A descriptor closed on every way out.
class unique_fd {
 public:
  explicit unique_fd(int fd) noexcept : fd_(fd) {}
  unique_fd(const unique_fd&) = delete;
  unique_fd& operator=(const unique_fd&) = delete;
  ~unique_fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] int get() const noexcept { return fd_; }

 private:
  int fd_;
};

/// Set (to anything but "0") only by the tests, to take the path of a file system
/// without O_TMPFILE on one that has it. Not part of the command's interface.
bool named_file_forced() {
  const char* v = std::getenv("INTERPATCH_TEST_NAMED_TEMP_FILE");
  return v != nullptr && *v != '\0' && std::string_view(v) != "0";
}

/// The file being written, until it is the output. Where the file system allows,
/// it has no name at all while it is written (O_TMPFILE): whatever kills the
/// process, the kernel frees it, and nothing shows in the directory. Elsewhere
/// (kernels before 3.11, NFS, some overlay and FUSE file systems) it is a named
/// file of the leftover pattern, which the next write into the directory removes
/// if its process died. Either way the file is locked (flock) by this process
/// until it is in place: see remove_if_unheld.
class output_file {
 public:
  output_file(int dirfd, const fs::path& target) : dirfd_(dirfd) {
    if (!named_file_forced()) {
      fd_ = ::openat(dirfd, ".", O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
      // Not supported: EOPNOTSUPP (the file system), EISDIR (a kernel without
      // O_TMPFILE takes it for O_DIRECTORY), EINVAL. Any other failure is tried
      // again the other way too, which then reports its own reason.
      // The name is given through /proc/self/fd: without /proc, a named file.
      if (fd_ >= 0 && !proc_fd_available()) {
        ::close(fd_);
        fd_ = -1;
      }
    }
    if (fd_ < 0) {
      for (int attempt = 0; attempt < 100; ++attempt) {
        name_ = leftover_name(target.filename().string());
        fd_ = ::openat(dirfd, name_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
        if (fd_ >= 0 || errno != EEXIST) break;
      }
      if (fd_ < 0) {
        const int e = errno;
        name_.clear();
        fail_write(target, "cannot create a temporary file in " + quoted(directory_of(target)) + ": " +
                               std::strerror(e));
      }
    }
    // A file system without locks has the pid alone to protect the file.
    (void)::flock(fd_, LOCK_EX | LOCK_NB);
  }
  output_file(const output_file&) = delete;
  output_file& operator=(const output_file&) = delete;
  ~output_file() {
    if (fd_ >= 0) ::close(fd_);
    if (!in_place_ && !name_.empty()) ::unlinkat(dirfd_, name_.c_str(), 0);
    if (held_ >= 0) ::close(held_);  // the lock goes last: it covers the name until the name is gone
  }

  [[nodiscard]] int fd() const noexcept { return fd_; }

  /// Closes the written descriptor and reports what close() reports: some file
  /// systems (NFS) report a failed write-back only there, and it must come before
  /// anything is named or replaced. A duplicate stays open: the unnamed file needs
  /// it to be linked, and it keeps the lock until the file is in place.
  void close(const fs::path& target) {
    held_ = ::fcntl(fd_, F_DUPFD_CLOEXEC, 0);
    if (held_ < 0) {
      const int e = errno;
      fail_write(target, std::string("close failed: ") + std::strerror(e));
    }
    const int r = ::close(fd_);
    fd_ = -1;
    if (r != 0) {
      const int e = errno;
      fail_write(target, std::string("close failed: ") + std::strerror(e));
    }
  }

  /// Puts the closed file at `target` (in the directory of dirfd), replacing what
  /// is there.
  void put_in_place(const fs::path& target) {
    const std::string target_name = target.filename().string();
    if (name_.empty()) {
      // A new output gets its name in one step: nothing else is ever visible.
      if (link_as(target_name) == 0) {
        in_place_ = true;
        return;
      }
      if (errno != EEXIST) {
        const int e = errno;
        fail_write(target, std::string("cannot give the file its name: ") + std::strerror(e));
      }
      // An existing output is replaced by a rename from a name of the leftover
      // pattern. No way without that window exists: linkat never replaces a file,
      // and Linux has no call that gives an unnamed file a name already taken
      // (renameat2, RENAME_EXCHANGE included, needs two names; a link-and-replace
      // flag for linkat was proposed but never merged). Moving the old output
      // aside first would leave no output at all to a kill in between, which is
      // worse. So a kill between the linkat and the rename below leaves the
      // complete new file under the leftover name beside the intact old output,
      // locked until this process dies, and the next write into the directory
      // removes it; the window is from the end of one system call to the end of
      // the next, where the named fallback spends the whole write.
      int e = EEXIST;
      for (int attempt = 0; attempt < 100 && e == EEXIST; ++attempt) {
        name_ = leftover_name(target_name);
        e = link_as(name_) == 0 ? 0 : errno;
      }
      if (e != 0) {
        name_.clear();  // not linked: no name of ours to remove
        fail_write(target, std::string("cannot give the file a name: ") + std::strerror(e));
      }
    }
    if (::renameat(dirfd_, name_.c_str(), dirfd_, target_name.c_str()) != 0) {
      const int e = errno;
      fail_write(target, std::string("cannot rename the temporary file into place: ") + std::strerror(e));
    }
    in_place_ = true;
  }

 private:
  bool proc_fd_available() const {
    char link[PATH_MAX];
    return ::readlink(proc_path().c_str(), link, sizeof link) > 0;
  }
  [[nodiscard]] std::string proc_path() const {
    return "/proc/self/fd/" + std::to_string(held_ >= 0 ? held_ : fd_);
  }

  /// Links the unnamed file as `name` in the directory; returns 0 or -1 with errno.
  int link_as(const std::string& name) const {
    errno = 0;
    if (::linkat(AT_FDCWD, proc_path().c_str(), dirfd_, name.c_str(), AT_SYMLINK_FOLLOW) == 0) return 0;
    if (errno == EEXIST) return -1;
    // Without /proc after all: AT_EMPTY_PATH, which some kernels allow only with
    // CAP_DAC_READ_SEARCH. The first reason is the one reported.
    const int e = errno;
    if (::linkat(held_, "", dirfd_, name.c_str(), AT_EMPTY_PATH) == 0) return 0;
    if (errno != EEXIST) errno = e;
    return -1;
  }

  int dirfd_;
  int fd_ = -1;    // the descriptor written to, until close()
  int held_ = -1;  // its duplicate, from close() until the file is in place
  std::string name_;  // the file's name in the directory while it has one of its own
  bool in_place_ = false;
};

}  // namespace

void check_writable(const fs::path& path) {
  if (path.empty()) detail::fail(errc::file_unwritable, "cannot write '': the output path is empty");
  std::error_code ec;
  const fs::path dir = directory_of(path);
  const auto dir_status = fs::status(dir, ec);
  if (!fs::exists(dir_status)) {
    fail_write(path, "directory " + quoted(dir) + " does not exist");
  }
  if (!fs::is_directory(dir_status)) fail_write(path, quoted(dir) + " is not a directory");
  const auto st = fs::status(path, ec);
  if (fs::is_directory(st)) fail_write(path, "it is a directory");
  if (fs::exists(st) && !fs::is_regular_file(st)) fail_write(path, "it exists and is not a regular file");
  // The file itself is replaced by a rename, so what matters is the directory.
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    const int e = errno;
    fail_write(path, "directory " + quoted(dir) + " is not writable (" + std::strerror(e) + ")");
  }
}

void set_durable_writes(bool on) noexcept { durable_flag.store(on); }
bool durable_writes() noexcept { return durable_flag.load(); }

void check_disk_space(const fs::path& path, std::uintmax_t bytes, std::string_view what) {
  std::error_code ec;
  const fs::path dir = directory_of(path);
  const fs::space_info space = fs::space(dir, ec);
  if (ec || space.available == static_cast<std::uintmax_t>(-1)) return;
  if (bytes > space.available)
    detail::fail(errc::too_large, std::string(what), " needs ", detail::human_bytes(bytes), " (", bytes, " bytes), ",
                 detail::human_bytes(space.available), " available on disk in ", quoted(dir), " (", space.available,
                 " bytes)");
}

void write_atomically(const fs::path& requested, const std::function<void(std::ostream&)>& write,
                      std::uintmax_t size) {
  check_writable(requested);
  const fs::path path = resolve_links(requested);
  if (path != requested) check_writable(path);

  // The result keeps the permissions of the file it replaces, or gets those of a
  // newly created file; never the 0600 the file is created with.
  mode_t mode = 0;
  struct stat old {};
  if (::stat(path.c_str(), &old) == 0) {
    mode = old.st_mode & 07777;
  } else {
    mode = default_file_mode();
  }

  // Everything happens relative to the directory as opened now, even if its path
  // changes meanwhile. O_PATH: the directory needs to be searchable, not readable.
  const unique_fd dir(::open(directory_of(path).c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0) {
    const int e = errno;
    fail_write(path, "cannot open directory " + quoted(directory_of(path)) + ": " + std::strerror(e));
  }
  // Before this write adds its own: the space of leftovers comes back first.
  remove_stale_leftovers(dir.get());

  output_file tmp(dir.get(), path);
  if (::fchmod(tmp.fd(), mode) != 0) {
    const int e = errno;
    fail_write(path, std::string("cannot set permissions of the temporary file: ") + std::strerror(e));
  }

  const bool sync = durable_writes();
#ifdef __linux__
  // The file's blocks allocated at once rather than page by page as the writes come:
  // 25 MB are written in 4 ms instead of 6–8 (and without the occasional 50 ms
  // stall) on ext4. Advice only: a file system without fallocate is written as it
  // is, and no space is reported by the writes themselves.
  if (size > 0) (void)::fallocate(tmp.fd(), 0, 0, static_cast<off_t>(size));
#endif
  {
    fd_buffer buf(tmp.fd(), sync);
    std::ostream os(&buf);
    os.exceptions(std::ios::badbit);
    try {
      write(os);
      os.flush();
    } catch (const std::ios_base::failure& e) {
      fail_write(path, buf.error() != 0 ? std::strerror(buf.error()) : e.what());
    }
    if (!os || buf.error() != 0) fail_write(path, buf.error() != 0 ? std::strerror(buf.error()) : "stream error");
    // A writer that wrote less than it announced leaves no allocated tail behind.
    if (size > 0 && buf.written() < size && ::ftruncate(tmp.fd(), static_cast<off_t>(buf.written())) != 0) {
      const int e = errno;
      fail_write(path, std::string("cannot set the file's size: ") + std::strerror(e));
    }
  }

  if (sync && ::fsync(tmp.fd()) != 0) {
    const int e = errno;
    fail_write(path, std::string("fsync failed: ") + std::strerror(e));
  }
  tmp.close(path);
  tmp.put_in_place(path);

  // Make the new name durable; a failure here loses nothing already written.
  if (!sync) return;
  const int dfd = ::openat(dir.get(), ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace interpatch::io
