#pragma once
// Text from the user (a spec, a key, a file's bytes) quoted in an error message:
// printable and short, so that a binary file given as a spec or a pointer into a
// 100000-deep document makes a one-line message a person can read.

#include <cstddef>
#include <string>
#include <string_view>

namespace interpatch::detail {

/// `text` with every byte outside printable ASCII written as \xNN, and, when that is
/// longer than `limit` characters, only its start and its end around "...".
inline std::string excerpt(std::string_view text, std::size_t limit = 120) {
  static constexpr char hex[] = "0123456789abcdef";
  auto escaped = [](std::string_view t) {
    std::string s;
    s.reserve(t.size());
    for (const char ch : t) {
      const auto c = static_cast<unsigned char>(ch);
      if (c >= 0x20 && c < 0x7f) {
        s += ch;
      } else {
        s += "\\x";
        s += hex[c >> 4];
        s += hex[c & 15];
      }
    }
    return s;
  };
  // Escaping at most quadruples a byte: escape only the two ends of a long text.
  if (text.size() <= limit) {
    std::string s = escaped(text);
    if (s.size() <= limit) return s;
  }
  const std::size_t half = limit / 2;
  std::string head = escaped(text.substr(0, half)), tail = escaped(text.substr(text.size() - std::min(half, text.size())));
  head.resize(std::min(head.size(), half));
  tail.erase(0, tail.size() > half ? tail.size() - half : 0);
  return head + "..." + tail;
}

}  // namespace interpatch::detail
