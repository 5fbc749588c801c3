#include "io/crc32.hpp"

#include <array>
#include <new>
#include <vector>

#include "base/parallel.hpp"

namespace interpatch::io::internal {

namespace {

constexpr std::uint32_t polynomial = 0xEDB88320u;  // x^32 + x^26 + ... + 1, bits reflected

// Slicing-by-16: table[k][b] is the CRC of byte b followed by k zero bytes, so that
// sixteen bytes are folded into the register with sixteen look-ups and no loop over
// bits. 16 KiB of tables, which stay in the first-level cache.
constexpr std::size_t slices = 16;
using Tables = std::array<std::array<std::uint32_t, 256>, slices>;

constexpr Tables make_tables() {
  Tables t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t c = b;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (c >> 1) ^ polynomial : c >> 1;
    t[0][b] = c;
  }
  for (std::size_t k = 1; k < slices; ++k)
    for (std::size_t b = 0; b < 256; ++b) t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xffu];
  return t;
}

constexpr Tables tables = make_tables();

// Four bytes as a little-endian number, whatever the host's byte order (the
// compiler makes one load of it on a little-endian host).
inline std::uint32_t load_le32(const unsigned char* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// a(x) b(x) modulo the polynomial, both in the reflected representation (bit 31 is
// x^0): what appending zero bytes does to a CRC, as a product.
constexpr std::uint32_t multiply_mod(std::uint32_t a, std::uint32_t b) noexcept {
  std::uint32_t product = 0;
  for (std::uint32_t m = 1u << 31; m != 0; m >>= 1) {
    if (a & m) product ^= b;
    b = (b & 1u) ? (b >> 1) ^ polynomial : b >> 1;
  }
  return product;
}

// x^(2^k) modulo the polynomial, k = 0..63 (x^1 is 1 << 30 reflected).
constexpr std::array<std::uint32_t, 64> make_powers() {
  std::array<std::uint32_t, 64> p{};
  std::uint32_t v = 1u << 30;
  for (std::size_t k = 0; k < p.size(); ++k) {
    p[k] = v;
    v = multiply_mod(v, v);
  }
  return p;
}

constexpr std::array<std::uint32_t, 64> powers = make_powers();

// x^(8 n) modulo the polynomial: the factor n zero bytes multiply a CRC by.
std::uint32_t shift_of_bytes(std::uint64_t n) noexcept {
  std::uint32_t r = 1u << 31;  // x^0
  // 8 n = n << 3: bit i of n stands for x^(2^(i+3)).
  for (std::size_t k = 3; n != 0 && k < powers.size(); ++k, n >>= 1)
    if (n & 1u) r = multiply_mod(powers[k], r);
  return r;
}

}  // namespace

std::uint32_t crc32_serial(const void* data, std::size_t n, std::uint32_t crc) noexcept {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint32_t c = ~crc;
  const auto& t = tables;
  for (; n >= slices; n -= slices, p += slices) {
    const std::uint32_t a = load_le32(p) ^ c, b = load_le32(p + 4), d = load_le32(p + 8), e = load_le32(p + 12);
    c = t[15][a & 0xffu] ^ t[14][(a >> 8) & 0xffu] ^ t[13][(a >> 16) & 0xffu] ^ t[12][a >> 24] ^
        t[11][b & 0xffu] ^ t[10][(b >> 8) & 0xffu] ^ t[9][(b >> 16) & 0xffu] ^ t[8][b >> 24] ^
        t[7][d & 0xffu] ^ t[6][(d >> 8) & 0xffu] ^ t[5][(d >> 16) & 0xffu] ^ t[4][d >> 24] ^
        t[3][e & 0xffu] ^ t[2][(e >> 8) & 0xffu] ^ t[1][(e >> 16) & 0xffu] ^ t[0][e >> 24];
  }
  for (; n > 0; --n, ++p) c = t[0][(c ^ *p) & 0xffu] ^ (c >> 8);
  return ~c;
}

std::uint32_t crc32_combine(std::uint32_t crc_a, std::uint32_t crc_b, std::uint64_t len_b) noexcept {
  // CRC(A B) = CRC(A) x^(8 |B|) + CRC(B), the inversions at the ends cancelling.
  return multiply_mod(shift_of_bytes(len_b), crc_a) ^ crc_b;
}

std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc) noexcept {
  // Below a few MiB the second thread costs more to start than it saves.
  constexpr std::size_t parallel_bytes = std::size_t{4} << 20;
  if (n < parallel_bytes) return crc32_serial(data, n, crc);
  const auto* p = static_cast<const unsigned char*>(data);
  // One piece a thread, its checksum kept in memory taken before the region (an
  // allocation inside would throw out of it); without that memory, one thread.
  std::vector<std::uint32_t> part;
  try {
    part.resize(detail::max_threads());
  } catch (const std::bad_alloc&) {
    return crc32_serial(data, n, crc);
  }
  std::size_t parts = 1;
  const auto end = [&](std::size_t k) { return k + 1 == parts ? n : n / parts * (k + 1); };
#pragma omp parallel
  {
#pragma omp single
    parts = detail::thread_count();
    const auto k = static_cast<std::size_t>(detail::thread_index());
    if (parts <= part.size()) {
      const std::size_t begin = k == 0 ? 0 : end(k - 1);
      part[k] = crc32_serial(p + begin, end(k) - begin);
    }
  }
  if (parts > part.size()) return crc32_serial(data, n, crc);
  for (std::size_t k = 0; k < parts; ++k) crc = crc32_combine(crc, part[k], end(k) - (k == 0 ? 0 : end(k - 1)));
  return crc;
}

}  // namespace interpatch::io::internal
