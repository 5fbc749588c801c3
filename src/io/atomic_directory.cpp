// Output directories (an OpenFOAM polyMesh) written whole or not at all: a new
// directory beside the target, filled, then swapped in with one rename.

#include <stdio.h>  // renameat2
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail_directory(const fs::path& path, const std::string& reason) {
  detail::fail(errc::file_unwritable, "cannot write '", path.string(), "': ", reason);
}

fs::path parent_of(const fs::path& path) {
  const fs::path p = path.parent_path();
  return p.empty() ? fs::path(".") : p;
}

}  // namespace

void check_writable_directory(const fs::path& path) {
  if (path.empty() || path.filename().empty()) fail_directory(path, "give the directory's name");
  std::error_code ec;
  const fs::path parent = parent_of(path);
  const auto parent_status = fs::status(parent, ec);
  if (!fs::exists(parent_status)) fail_directory(path, "directory '" + parent.string() + "' does not exist");
  if (!fs::is_directory(parent_status)) fail_directory(path, "'" + parent.string() + "' is not a directory");
  const auto st = fs::symlink_status(path, ec);
  if (fs::exists(st) && !fs::is_directory(st)) fail_directory(path, "it exists and is not a directory");
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    const int e = errno;
    fail_directory(path, "directory '" + parent.string() + "' is not writable (" + std::strerror(e) + ")");
  }
}

void write_directory_atomically(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  check_writable_directory(path);
  const fs::path parent = parent_of(path);
  std::string name = (parent / ("." + path.filename().string() + ".interpatch-tmp." + std::to_string(::getpid()) +
                                ".XXXXXX")).string();
  std::vector<char> buf(name.begin(), name.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data())) {
    const int e = errno;
    fail_directory(path, "cannot create a temporary directory in '" + parent.string() + "': " + std::strerror(e));
  }
  const fs::path tmp(buf.data());
  std::error_code ec;
  try {
    write(tmp);
    if (durable_writes()) {
      for (const auto& entry : fs::directory_iterator(tmp)) {
        const int fd = ::open(entry.path().c_str(), O_RDONLY);
        if (fd >= 0) ::fsync(fd), ::close(fd);
      }
    }
    if (fs::exists(fs::symlink_status(path, ec))) {
      // Swapped in one step: the old directory or the new one is there at every moment.
      if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, path.c_str(), RENAME_EXCHANGE) != 0) {
        const int e = errno;
        fail_directory(path, std::string("cannot replace it: ") + std::strerror(e));
      }
      fs::remove_all(tmp, ec);  // the old directory, now under the temporary name
    } else if (::rename(tmp.c_str(), path.c_str()) != 0) {
      const int e = errno;
      fail_directory(path, std::string("cannot put it in place: ") + std::strerror(e));
    }
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace interpatch::io
