// Reading an .npy array's data into the caller's memory as float64 in C order:
// decoding other dtypes and Fortran order, and the data block of a file read by
// every thread at once (read_pieces); read_npy and parse_npy.

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/memory.hpp"
#include "io/crc32.hpp"
#include "io/input_stream.hpp"
#include "io/npy_bytes.hpp"
#include "io/npy_format.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

using internal::crc32_combine;
using internal::crc32_serial;
using internal::NpyDtype;
using internal::npy_shape_text;
using internal::npy_io::byteswap;
using internal::npy_io::fail_read;
using internal::npy_io::read_exact;

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

}  // namespace

namespace internal {

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
      detail::fail(errc::too_large, name, ": shape ", npy_shape_text(h.shape), " has more elements than can be addressed");
    }
    count *= d;
  }
  if (count > std::numeric_limits<std::size_t>::max() / 8) {
    detail::fail(errc::too_large, name, ": shape ", npy_shape_text(h.shape), " needs more bytes than can be addressed");
  }
  require_memory(count, sizeof(double), name + ": array of shape " + npy_shape_text(h.shape));
  const std::uint64_t need = static_cast<std::uint64_t>(count) * dt.size;
  const std::uint64_t have = file_size - h.data_offset;
  if (have < need) {
    detail::fail(errc::malformed_file, name, ": truncated: shape ", npy_shape_text(h.shape), " needs ", need,
                 " bytes of data, found ", have);
  }
  if (have > need) {
    detail::fail(errc::malformed_file, name, ": ", have - need, " bytes of extra data: shape ", npy_shape_text(h.shape),
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

// The data block of a file, read by every thread at once in pieces with pread:
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

}  // namespace interpatch::io
