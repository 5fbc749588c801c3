#pragma once
// What the pieces of the .npy reader and writer (src/io/npy_*.cpp) share: byte
// swapping, and reading a stream's bytes exactly.

#include <algorithm>
#include <cerrno>
#include <cstddef>
#include <cstring>
#include <istream>
#include <string>

#include "base/text.hpp"

namespace interpatch::io::internal::npy_io {

template <class U>
U byteswap(U v) noexcept {
  U r = 0;
  for (std::size_t i = 0; i < sizeof(U); ++i) {
    r = static_cast<U>((r << 8) | (v & 0xffu));
    v = static_cast<U>(v >> 8);
  }
  return r;
}

[[noreturn]] inline void fail_read(const std::string& name, int err) {
  detail::fail(errc::file_unreadable, "cannot read '", name, "': ",
               err != 0 ? std::strerror(err) : "read error");
}

inline void read_exact(std::istream& in, char* dst, std::size_t n, const std::string& name) {
  while (n > 0) {
    const std::size_t step = std::min<std::size_t>(n, std::size_t{1} << 30);
    errno = 0;
    in.read(dst, static_cast<std::streamsize>(step));
    if (static_cast<std::size_t>(in.gcount()) != step) fail_read(name, errno);
    dst += step;
    n -= step;
  }
}

}  // namespace interpatch::io::internal::npy_io
