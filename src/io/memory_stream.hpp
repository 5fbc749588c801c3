#pragma once
// An input stream over bytes already in memory, without copying them: what lets
// the file readers and their in-memory entry points share one code path.

#include <cstddef>
#include <istream>
#include <streambuf>
#include <string_view>

namespace interpatch::detail {

class MemoryStream : private std::streambuf, public std::istream {
 public:
  explicit MemoryStream(std::string_view bytes) : std::istream(static_cast<std::streambuf*>(this)) {
    // The get area is only read from: the const_cast never leads to a write.
    char* p = const_cast<char*>(bytes.data());
    setg(p, p, p + bytes.size());
  }
};

}  // namespace interpatch::detail
