#include "interpatch/io/npy.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "base/pipeline.hpp"
#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"
#include "io/crc32.hpp"
#include "io/finite.hpp"
#include "io/input_stream.hpp"
#include "io/npy_format.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

constexpr char magic[6] = {'\x93', 'N', 'U', 'M', 'P', 'Y'};
// NumPy itself refuses headers longer than 10000 bytes unless told otherwise; a
// megabyte leaves room for any plausible shape while stopping absurd lengths.
constexpr std::size_t max_header = std::size_t{1} << 20;

std::string shape_text(std::span<const std::size_t> shape) { return internal::npy_shape_text(shape); }

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

// ---------------------------------------------------------------------------
// Element decoding.

using internal::crc32;
using internal::crc32_combine;
using internal::crc32_serial;
using internal::NpyDtype;

template <class U>
U byteswap(U v) noexcept {
  U r = 0;
  for (std::size_t i = 0; i < sizeof(U); ++i) {
    r = static_cast<U>((r << 8) | (v & 0xffu));
    v = static_cast<U>(v >> 8);
  }
  return r;
}

/// One element from its bytes in the file.
inline double decode(const unsigned char* p, const NpyDtype& d) noexcept {
  const bool swap = d.big_endian != (std::endian::native == std::endian::big);
  if (d.kind == 'f' && d.size == 8) {
    std::uint64_t u;
    std::memcpy(&u, p, 8);
    if (swap) u = byteswap(u);
    return std::bit_cast<double>(u);
  }
  if (d.kind == 'f') {
    std::uint32_t u;
    std::memcpy(&u, p, 4);
    if (swap) u = byteswap(u);
    return static_cast<double>(std::bit_cast<float>(u));
  }
  // Integers and bools: the bytes as an unsigned number, then its sign.
  std::uint64_t u = 0;
  for (std::size_t i = 0; i < d.size; ++i) {
    const std::size_t at = d.big_endian ? i : d.size - 1 - i;  // most significant byte first
    u = (u << 8) | p[at];
  }
  if (d.kind == 'b') return u != 0 ? 1.0 : 0.0;
  if (d.kind == 'i' && d.size < 8 && (u >> (8 * d.size - 1)) != 0) u |= ~std::uint64_t{0} << (8 * d.size);
  return d.kind == 'i' ? static_cast<double>(static_cast<std::int64_t>(u)) : static_cast<double>(u);
}

std::uint32_t read_le(const unsigned char* p, std::size_t n) {
  std::uint32_t v = 0;
  for (std::size_t i = n; i-- > 0;) v = (v << 8) | p[i];
  return v;
}

[[noreturn]] void fail_read(const std::string& name, int err) {
  detail::fail(errc::file_unreadable, "cannot read '", name, "': ",
               err != 0 ? std::strerror(err) : "read error");
}

void read_exact(std::istream& in, char* dst, std::size_t n, const std::string& name) {
  while (n > 0) {
    const std::size_t step = std::min<std::size_t>(n, std::size_t{1} << 30);
    errno = 0;
    in.read(dst, static_cast<std::streamsize>(step));
    if (static_cast<std::size_t>(in.gcount()) != step) fail_read(name, errno);
    dst += step;
    n -= step;
  }
}

}  // namespace

namespace internal {

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

std::vector<std::size_t> read_npy_data(std::istream& in, const NpyHeader& h, std::uint64_t file_size,
                                       const std::string& name, const NpyDestination& destination, const BulkRead& bulk,
                                       bool integers) {
  const std::optional<NpyDtype> parsed = parse_npy_dtype(h.descr);
  if (!parsed || (parsed->kind != 'f' && !integers))
    detail::fail(errc::malformed_file, name, ": dtype '", h.descr, "' is not supported; use float64 or float32");
  const NpyDtype dt = *parsed;

  // Sizes, before allocating anything for the data.
  std::size_t count = 1;
  for (std::size_t d : h.shape) {
    if (d != 0 && count > std::numeric_limits<std::size_t>::max() / d) {
      detail::fail(errc::too_large, name, ": shape ", shape_text(h.shape), " has more elements than can be addressed");
    }
    count *= d;
  }
  if (count > std::numeric_limits<std::size_t>::max() / 8) {
    detail::fail(errc::too_large, name, ": shape ", shape_text(h.shape), " needs more bytes than can be addressed");
  }
  require_memory(count, sizeof(double), name + ": array of shape " + shape_text(h.shape));
  const std::uint64_t need = static_cast<std::uint64_t>(count) * dt.size;
  const std::uint64_t have = file_size - h.data_offset;
  if (have < need) {
    detail::fail(errc::malformed_file, name, ": truncated: shape ", shape_text(h.shape), " needs ", need,
                 " bytes of data, found ", have);
  }
  if (have > need) {
    detail::fail(errc::malformed_file, name, ": ", have - need, " bytes of extra data: shape ", shape_text(h.shape),
                 " needs ", need, " bytes of data, found ", have);
  }

  double* const out = destination(h.shape, count);
  const bool fortran = h.fortran_order && h.shape.size() > 1;
  const bool native = dt.big_endian == (std::endian::native == std::endian::big);

  if (!fortran && dt.kind == 'f' && dt.size == 8) {
    // The common case: the file's bytes are the result, up to byte order.
    // In pieces only in the native byte order: what a bulk read's visitor sees are
    // then the values.
    if (bulk && native) bulk(reinterpret_cast<char*>(out), count * 8, file_size - count * 8);
    else read_exact(in, reinterpret_cast<char*>(out), count * 8, name);
    if (!native) {
      for (std::size_t k = 0; k < count; ++k) out[k] = std::bit_cast<double>(byteswap(std::bit_cast<std::uint64_t>(out[k])));
    }
    return h.shape;
  }

  // Decode in chunks; Fortran order (first index fastest) is scattered into C order.
  const std::size_t rank = h.shape.size();
  std::vector<std::size_t> stride(rank, 1), index(rank, 0);
  for (std::size_t a = rank; a-- > 1;) stride[a - 1] = stride[a] * h.shape[a];
  std::size_t offset = 0;  // C-order offset of `index`
  auto advance = [&]() {
    if (!fortran) {
      ++offset;
      return;
    }
    for (std::size_t a = 0; a < rank; ++a) {
      offset += stride[a];
      if (++index[a] < h.shape[a]) return;
      offset -= stride[a] * h.shape[a];
      index[a] = 0;
    }
  };

  constexpr std::size_t chunk_elems = std::size_t{1} << 16;
  std::vector<unsigned char> buf(std::min(count, chunk_elems) * dt.size);
  for (std::size_t done = 0; done < count;) {
    const std::size_t n = std::min(count - done, chunk_elems);
    read_exact(in, reinterpret_cast<char*>(buf.data()), n * dt.size, name);
    for (std::size_t k = 0; k < n; ++k) {
      out[offset] = decode(buf.data() + k * dt.size, dt);
      advance();
    }
    done += n;
  }
  return h.shape;
}

// The data block of a file, read by both threads at once in pieces with pread:
// copying out of the page cache, and the first touch of the destination's pages,
// are most of the cost of reading, and both go twice as fast on two cores. The
// checksum of each piece is taken while the piece is still in the cache, and the
// pieces' checksums are combined in order afterwards.
void read_pieces(const fs::path& path, const std::string& name, char* dst, std::size_t n, std::uint64_t offset,
                 std::uint32_t* crc, const PieceVisitor& visit) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail_read(name, errno);
  constexpr std::size_t piece = std::size_t{1} << 20;
  const auto pieces = static_cast<long long>((n + piece - 1) / piece);
  std::vector<std::uint32_t> sums(crc ? static_cast<std::size_t>(pieces) : 0);
  std::atomic<int> failure{0};
  detail::ParallelFailure visit_failure;  // what `visit` throws, by piece
#pragma omp parallel for schedule(static) if (n >= 8 * piece)
  for (long long k = 0; k < pieces; ++k) {
    const std::size_t begin = static_cast<std::size_t>(k) * piece;
    const std::size_t end = std::min(n, begin + piece);
    std::size_t at = begin;
    while (at < end && failure.load(std::memory_order_relaxed) == 0) {
      const ssize_t got = ::pread(fd, dst + at, end - at, static_cast<off_t>(offset + at));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        failure = got < 0 ? errno : EIO;  // 0: the file shrank while being read
        break;
      }
      at += static_cast<std::size_t>(got);
    }
    if (crc && at == end) sums[static_cast<std::size_t>(k)] = crc32_serial(dst + begin, end - begin);
    if (visit && at == end) visit_failure.attempt(static_cast<std::size_t>(k), [&] { visit(dst + begin, end - begin); });
  }
  ::close(fd);
  if (const int e = failure.load(); e != 0) fail_read(name, e);
  visit_failure.rethrow();
  if (!crc) return;
  for (std::size_t k = 0; k < sums.size(); ++k)
    *crc = crc32_combine(*crc, sums[k], std::min(piece, n - k * piece));
}

// Magic, version, header length and the header dictionary padded to 64 bytes.
std::string npy_header(std::string_view descr, std::span<const std::size_t> shape) {
  std::string header =
      "{'descr': '" + std::string(descr) + "', 'fortran_order': False, 'shape': " + shape_text(shape) + ", }";
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

void write_values(std::ostream& os, const double* data, std::size_t n, std::uint32_t* crc) {
  const auto put = [&](const void* bytes, std::size_t count) {
    if (crc) *crc = crc32(bytes, count, *crc);
    os.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(count));
  };
  if constexpr (std::endian::native == std::endian::little) {
    // With a checksum, in pieces of 8 MiB: each is summed (by both threads) and
    // written while it is still in the cache. Without, all at once.
    const std::size_t step = crc ? std::size_t{1} << 20 : std::max<std::size_t>(n, 1);
    for (std::size_t done = 0; done < n; done += step) put(data + done, std::min(step, n - done) * sizeof(double));
  } else {
    std::vector<std::uint64_t> chunk(std::min<std::size_t>(n, std::size_t{1} << 16));
    for (std::size_t done = 0; done < n;) {
      const std::size_t k = std::min(chunk.size(), n - done);
      for (std::size_t i = 0; i < k; ++i) chunk[i] = byteswap(std::bit_cast<std::uint64_t>(data[done + i]));
      put(chunk.data(), k * 8);
      done += k;
    }
  }
}

}  // namespace internal

namespace {

/// The array in `in`, which holds `file_size` bytes; `name` names it in messages.
/// What read_npy and parse_npy share: one reader for files and memory.
std::vector<std::size_t> read_npy_stream(std::istream& in, std::uint64_t file_size, const std::string& name,
                                         const NpyDestination& destination, const internal::BulkRead& bulk = {}) {
  const internal::NpyHeader h = internal::read_npy_header(in, file_size, name);
  return internal::read_npy_data(in, h, file_size, name, destination, bulk);
}

}  // namespace

namespace internal {

std::vector<std::size_t> read_npy_visiting(const fs::path& path, const NpyDestination& destination,
                                           const PieceVisitor& visit) {
  std::ifstream in = detail::open_input(path);
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  in.seekg(0, std::ios::beg);
  if (end < 0 || !in) fail_read(path.string(), errno);
  return read_npy_stream(in, static_cast<std::uint64_t>(end), path.string(), destination,
                         [&](char* dst, std::size_t n, std::uint64_t offset) {
                           read_pieces(path, path.string(), dst, n, offset, nullptr, visit);
                         });
}

}  // namespace internal

std::vector<std::size_t> read_npy_into(const fs::path& path, const NpyDestination& destination) {
  return internal::read_npy_visiting(path, destination, {});
}

namespace {
// An NpyArray's own storage as the destination.
NpyDestination into(NpyArray& a) {
  return [&a](std::span<const std::size_t>, std::size_t count) {
    a.data.resize(count);
    return a.data.data();
  };
}
}  // namespace

NpyArray read_npy(const fs::path& path) {
  NpyArray a;
  a.shape = read_npy_into(path, into(a));
  return a;
}

NpyArray parse_npy(std::string_view bytes, std::string_view name) {
  detail::MemoryStream in(bytes);
  NpyArray a;
  a.shape = read_npy_stream(in, bytes.size(), std::string(name), into(a));
  return a;
}

namespace {

// The array's element count, refused when the shape overflows.
std::size_t element_count(const fs::path& path, const std::vector<std::size_t>& dims) {
  std::size_t count = 1;
  for (std::size_t d : dims) {
    if (d != 0 && count > std::numeric_limits<std::size_t>::max() / d)
      detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': shape ", shape_text(dims), " overflows");
    count *= d;
  }
  return count;
}

}  // namespace

void write_npy(const fs::path& path, std::span<const std::size_t> shape, std::span<const double> data) {
  const std::vector<std::size_t> dims(shape.begin(), shape.end());
  if (const std::size_t count = element_count(path, dims); count != data.size())
    detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': shape ", shape_text(dims), " has ", count,
                 " elements, data has ", data.size());
  // The data in one block, the caller's memory as it is.
  write_npy(path, shape, std::max<std::size_t>(data.size(), 1),
            [&](std::size_t first, std::size_t count) { return data.subspan(first, count); });
}

void write_npy(const fs::path& path, std::span<const std::size_t> shape, std::size_t block,
               const NpyProducer& produce) {
  const std::vector<std::size_t> dims(shape.begin(), shape.end());
  const std::size_t count = element_count(path, dims);
  if (block == 0) detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': blocks of 0 values");
  const std::string header = internal::npy_header("<f8", dims);
  // The file's size, for write_atomically to allocate at once; 0 (unknown) for a
  // shape whose bytes cannot be counted, which the writes then refuse.
  const std::uintmax_t bytes = count <= (std::numeric_limits<std::uintmax_t>::max() - header.size()) / sizeof(double)
                                   ? header.size() + count * sizeof(double)
                                   : 0;
  write_atomically(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    for (std::size_t first = 0; first < count; first += block) {
      const std::size_t n = std::min(block, count - first);
      const std::span<const double> values = produce(first, n);
      if (values.size() != n)
        detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': values ", first, " to ", first + n - 1,
                     " came as ", values.size(), " values");
      internal::write_values(os, values.data(), n);
    }
  }, bytes);
}

namespace {

// About 2^17 values (1 MiB) a block of write_npy_rows, in pieces of about 2^13 for
// the threads to share: still in the cache when it is written, and few fresh pages
// (on the machine of docs/BENCHMARKS.md blocks of 4 MiB cost more in page faults
// than the overlap gains). At least 2 rows a block, so that the threads share rows
// as large as a volume's.
std::size_t block_rows_of(std::size_t per_row) {
  return std::max<std::size_t>(2, (std::size_t{1} << 17) / std::max<std::size_t>(per_row, 1));
}
std::size_t piece_rows_of(std::size_t per_row) {
  return std::max<std::size_t>(1, (std::size_t{1} << 13) / std::max<std::size_t>(per_row, 1));
}

}  // namespace

std::size_t write_npy_rows_held(std::size_t rows, std::size_t per_row) noexcept {
  const std::size_t n = std::min(block_rows_of(per_row), rows);
  return per_row != 0 && n > std::numeric_limits<std::size_t>::max() / 2 / per_row ? std::numeric_limits<std::size_t>::max()
                                                                                    : 2 * n * per_row;
}

void write_npy_rows(const fs::path& path, std::span<const std::size_t> shape, const NpyRowsMaker& make,
                    const progress_callback& progress) {
  const std::vector<std::size_t> dims(shape.begin(), shape.end());
  if (dims.empty()) detail::fail(errc::size_mismatch, "cannot write '", path.string(), "' by rows: the shape has no axis");
  const std::size_t count = element_count(path, dims);
  const std::size_t rows = dims[0], per_row = rows == 0 ? 0 : count / rows;
  const std::size_t block_rows = block_rows_of(per_row), piece_rows = piece_rows_of(per_row);
  // The first block is an eighth of the others: nothing is written until it is made,
  // with the first touches of its pages; every block after it is made while the one
  // before is written.
  const std::size_t first_rows = std::min(rows, std::max<std::size_t>(1, block_rows / 8));
  const std::size_t blocks = rows == 0 ? 0 : 1 + (rows - first_rows + block_rows - 1) / block_rows;
  const std::string header = internal::npy_header("<f8", dims);
  const std::uintmax_t bytes = count <= (std::numeric_limits<std::uintmax_t>::max() - header.size()) / sizeof(double)
                                   ? header.size() + count * sizeof(double)
                                   : 0;
  require_memory(write_npy_rows_held(rows, per_row), sizeof(double), "the blocks of '" + path.string() + "'");
  const std::size_t held = std::min(block_rows, rows) * per_row;
  // Not zeroed: the threads' first writes touch the pages.
  const std::unique_ptr<double[]> buffers[2] = {std::make_unique_for_overwrite<double[]>(held),
                                                std::make_unique_for_overwrite<double[]>(held)};
  const auto block_span = [&](std::size_t b) {
    if (b == 0) return std::pair(std::size_t{0}, first_rows);
    const std::size_t r0 = first_rows + (b - 1) * block_rows;
    return std::pair(r0, std::min(block_rows, rows - r0));
  };
  write_atomically(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    detail::pipeline(
        blocks, count >= detail::parallel_min_work / 4,
        [&](std::size_t b) { return (block_span(b).second + piece_rows - 1) / piece_rows; },
        [&](std::size_t b, std::size_t p) {
          const auto [r0, n] = block_span(b);
          const std::size_t first = p * piece_rows, k = std::min(piece_rows, n - first);
          make(r0 + first, k, std::span<double>(buffers[b % 2].get() + first * per_row, k * per_row));
        },
        [&](std::size_t b) {
          const auto [r0, n] = block_span(b);
          internal::require_finite(buffers[b % 2].get(), n * per_row, r0 * per_row, dims, "'" + path.string() + "'");
          internal::write_values(os, buffers[b % 2].get(), n * per_row);
          if (progress) progress(static_cast<double>(r0 + n) / static_cast<double>(rows));
        });
  }, bytes);
}

}  // namespace interpatch::io
