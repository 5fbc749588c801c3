#pragma once
// Where the data readers (NPY, CSV) read from: a file, or bytes already in memory
// (without copying them). Both give a std::istream, so the file readers and their
// in-memory entry points share one code path.

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <streambuf>
#include <string_view>

#include "base/text.hpp"

namespace interpatch::detail {

class MemoryStream : private std::streambuf, public std::istream {
 public:
  explicit MemoryStream(std::string_view bytes) : std::istream(static_cast<std::streambuf*>(this)) {
    // The get area is only read from: the const_cast never leads to a write.
    char* p = const_cast<char*>(bytes.data());
    setg(p, p, p + bytes.size());
  }
};

/// A data file opened for reading. @throws error file_unreadable (a directory, or
/// cannot open: naming the file and the reason).
inline std::ifstream open_input(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail(errc::file_unreadable, "cannot read '", path.string(), "': it is a directory");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int e = errno;
    fail(errc::file_unreadable, "cannot open '", path.string(), "': ", e != 0 ? std::strerror(e) : "open failed");
  }
  return in;
}

}  // namespace interpatch::detail
