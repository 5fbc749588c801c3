// The .npy preamble and header, read and made: the magic and version, the
// header's length, and the header itself, a Python dict literal of 'descr',
// 'fortran_order' and 'shape'; the dtypes the readers decode.

#include <bit>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <istream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "base/text.hpp"
#include "io/npy_bytes.hpp"
#include "io/npy_format.hpp"

namespace interpatch::io::internal {

namespace {

using npy_io::read_exact;

constexpr char magic[6] = {'\x93', 'N', 'U', 'M', 'P', 'Y'};

// NumPy itself refuses headers longer than 10000 bytes unless told otherwise; a
// megabyte leaves room for any plausible shape while stopping absurd lengths.
constexpr std::size_t max_header = std::size_t{1} << 20;

// ---------------------------------------------------------------------------
// The header is a Python dict literal; this parser accepts what NumPy's
// ast.literal_eval-based reader accepts for the three keys it defines.

struct Header {
  std::string descr;
  bool fortran_order = false;
  std::vector<std::size_t> shape;
};

class HeaderParser {
 public:
  HeaderParser(std::string_view text, const std::string& name) : s_(text), file_(name) {}

  Header parse() {
    Header h;
    bool have_descr = false, have_order = false, have_shape = false;
    skip_space();
    expect('{');
    for (;;) {
      skip_space();
      if (peek() == '}') {
        ++pos_;
        break;
      }
      const std::size_t key_pos = pos_;
      const std::string key = string_literal("a key");
      skip_space();
      expect(':');
      skip_space();
      auto seen = [&](bool& flag) {
        if (flag) fail_at(key_pos, "key '" + key + "' appears twice");
        flag = true;
      };
      if (key == "descr") {
        seen(have_descr);
        if (peek() == '[') {
          detail::fail(errc::malformed_file, file_,
                       ": structured dtype is not supported; use float64 or float32");
        }
        h.descr = string_literal("a dtype string");
      } else if (key == "fortran_order") {
        seen(have_order);
        h.fortran_order = boolean();
      } else if (key == "shape") {
        seen(have_shape);
        h.shape = tuple();
      } else {
        fail_at(key_pos, "unexpected key '" + key + "' (NPY headers hold 'descr', 'fortran_order', 'shape')");
      }
      skip_space();
      if (peek() == ',') {
        ++pos_;
      } else if (peek() != '}') {
        fail_at(pos_, "expected ',' or '}'");
      }
    }
    skip_space();
    if (pos_ != s_.size()) fail_at(pos_, "unexpected text after the closing '}'");
    if (!have_descr) fail_missing("descr");
    if (!have_order) fail_missing("fortran_order");
    if (!have_shape) fail_missing("shape");
    return h;
  }

 private:
  [[nodiscard]] char peek() const { return pos_ < s_.size() ? s_[pos_] : '\0'; }

  void skip_space() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) ++pos_;
  }

  void expect(char c) {
    if (peek() != c) fail_at(pos_, std::string("expected '") + c + "'");
    ++pos_;
  }

  std::string string_literal(const char* what) {
    const char q = peek();
    if (q != '\'' && q != '"') fail_at(pos_, std::string("expected ") + what + " in quotes");
    const std::size_t end = s_.find(q, pos_ + 1);
    if (end == std::string_view::npos) fail_at(pos_, "unterminated string");
    std::string v(s_.substr(pos_ + 1, end - pos_ - 1));
    pos_ = end + 1;
    return v;
  }

  bool boolean() {
    if (s_.substr(pos_, 4) == "True") {
      pos_ += 4;
      return true;
    }
    if (s_.substr(pos_, 5) == "False") {
      pos_ += 5;
      return false;
    }
    fail_at(pos_, "expected True or False for 'fortran_order'");
  }

  std::vector<std::size_t> tuple() {
    std::vector<std::size_t> dims;
    expect('(');
    for (;;) {
      skip_space();
      if (peek() == ')') {
        ++pos_;
        break;
      }
      const std::size_t start = pos_;
      std::uint64_t v = 0;
      const auto r = std::from_chars(s_.data() + pos_, s_.data() + s_.size(), v);
      if (r.ec == std::errc::result_out_of_range) {
        detail::fail(errc::too_large, file_, ": dimension ", std::string(s_.substr(start, static_cast<std::size_t>(r.ptr - (s_.data() + start)))),
                     " in the shape is too large");
      }
      if (r.ec != std::errc()) fail_at(start, "expected a non-negative integer in 'shape'");
      pos_ = static_cast<std::size_t>(r.ptr - s_.data());
      if (peek() == 'L' || peek() == 'l') ++pos_;  // Python 2 long literals, as old NumPy wrote them
      if (v > std::numeric_limits<std::size_t>::max()) detail::fail(errc::too_large, file_, ": dimension ", v, " is too large");
      dims.push_back(static_cast<std::size_t>(v));
      skip_space();
      if (peek() == ',') {
        ++pos_;
      } else if (peek() != ')') {
        fail_at(pos_, "expected ',' or ')' in 'shape'");
      }
    }
    return dims;
  }

  [[noreturn]] void fail_at(std::size_t at, const std::string& what) const {
    detail::fail(errc::malformed_file, file_, ": malformed NPY header: ", what, " at character ", at,
                 " of \"", excerpt(), "\"");
  }
  [[noreturn]] void fail_missing(const char* key) const {
    detail::fail(errc::malformed_file, file_, ": malformed NPY header: key '", key, "' is missing in \"",
                 excerpt(), "\"");
  }
  [[nodiscard]] std::string excerpt() const {
    // Without the padding NumPy puts at the end ("...}   \n"), which says nothing.
    std::string_view t = s_;
    while (!t.empty() && (t.back() == ' ' || t.back() == '\n')) t.remove_suffix(1);
    std::string e;
    for (char c : t.substr(0, 200)) {
      if (c == '\n') e += "\\n";
      else if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) e += '?';
      else e += c;
    }
    if (t.size() > 200) e += "...";
    return e;
  }

  std::string_view s_;
  const std::string& file_;
  std::size_t pos_ = 0;
};

std::uint32_t read_le(const unsigned char* p, std::size_t n) {
  std::uint32_t v = 0;
  for (std::size_t i = n; i-- > 0;) v = (v << 8) | p[i];
  return v;
}

}  // namespace

std::string npy_shape_text(std::span<const std::size_t> shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i) s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

std::optional<NpyDtype> parse_npy_dtype(std::string_view descr) {
  if (descr.size() != 3) return std::nullopt;
  NpyDtype d;
  d.kind = descr[1];
  if (descr[2] < '1' || descr[2] > '8') return std::nullopt;
  d.size = static_cast<std::size_t>(descr[2] - '0');
  switch (descr[0]) {
    case '<': d.big_endian = false; break;
    case '>': d.big_endian = true; break;
    case '=': d.big_endian = std::endian::native == std::endian::big; break;
    case '|': if (d.size != 1) return std::nullopt; break;  // no byte order: single bytes only
    default: return std::nullopt;
  }
  const bool known = (d.kind == 'f' && (d.size == 4 || d.size == 8)) ||
                     ((d.kind == 'i' || d.kind == 'u') && (d.size == 1 || d.size == 2 || d.size == 4 || d.size == 8)) ||
                     (d.kind == 'b' && d.size == 1);
  if (!known) return std::nullopt;
  return d;
}

NpyHeader read_npy_header(std::istream& in, std::uint64_t file_size, const std::string& name) {
  unsigned char pre[12] = {};
  if (file_size < 10) {
    detail::fail(errc::malformed_file, name, ": not an NPY file (", file_size, " bytes, shorter than the NPY preamble)");
  }
  read_exact(in, reinterpret_cast<char*>(pre), 10, name);
  if (std::memcmp(pre, magic, sizeof magic) != 0) {
    detail::fail(errc::malformed_file, name, ": not an NPY file (bad magic: the file does not start with \\x93NUMPY)");
  }
  const int major = pre[6], minor = pre[7];
  std::size_t prefix = 10, len_bytes = 2;
  if (major == 2 || major == 3) {
    prefix = 12;
    len_bytes = 4;
    if (file_size < 12) detail::fail(errc::malformed_file, name, ": truncated NPY preamble (", file_size, " bytes)");
    read_exact(in, reinterpret_cast<char*>(pre) + 10, 2, name);
  } else if (major != 1) {
    detail::fail(errc::malformed_file, name, ": NPY format version ", major, ".", minor,
                 " is not supported (1.0, 2.0 and 3.0 are)");
  }
  const std::size_t header_len = read_le(pre + 8, len_bytes);
  if (header_len > max_header) {
    detail::fail(errc::malformed_file, name, ": malformed NPY header: declared length ", header_len,
                 " bytes is implausible");
  }
  if (prefix + header_len > file_size) {
    detail::fail(errc::malformed_file, name, ": truncated NPY header: declares ", header_len, " bytes, file has ",
                 file_size - prefix, " after the preamble");
  }
  std::string text(header_len, '\0');
  read_exact(in, text.data(), header_len, name);
  Header h = HeaderParser(text, name).parse();
  return {std::move(h.descr), h.fortran_order, std::move(h.shape), prefix + header_len};
}

// Magic, version, header length and the header dictionary padded to 64 bytes.
std::string npy_header(std::string_view descr, std::span<const std::size_t> shape) {
  std::string header =
      "{'descr': '" + std::string(descr) + "', 'fortran_order': False, 'shape': " + npy_shape_text(shape) + ", }";
  // Version 1.0 holds header lengths below 65536; only an absurd rank needs 2.0.
  const bool v1 = header.size() + 1 + 10 + 64 <= 65535;
  const std::size_t prefix = v1 ? 10 : 12;
  const std::size_t total = (prefix + header.size() + 1 + 63) / 64 * 64;
  header.append(total - prefix - header.size() - 1, ' ');
  header += '\n';
  std::string pre(magic, sizeof magic);
  pre += static_cast<char>(v1 ? 1 : 2);
  pre += '\0';
  std::size_t len = header.size();
  for (std::size_t i = 0; i < (v1 ? 2u : 4u); ++i, len >>= 8) pre += static_cast<char>(len & 0xffu);
  return pre + header;
}

}  // namespace interpatch::io::internal
