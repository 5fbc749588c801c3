#pragma once
// Bytes of .npy files and of ZIP (.npz) archives made by hand, independently of the
// library's writers: the readers are tested against files they did not write, and
// bad files are made by changing one thing in a good one.

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace interpatch::test {

/// An NPY file as NumPy lays it out: magic, version, header length, the dict padded
/// with spaces and ended by '\n' to a multiple of 64 bytes, then the data.
inline std::string make_npy(const std::string& dict, const std::string& data, int major = 1, int minor = 0) {
  const std::size_t prefix = major == 1 ? 10 : 12;
  std::string header = dict;
  const std::size_t total = (prefix + header.size() + 1 + 63) / 64 * 64;
  header.append(total - prefix - header.size() - 1, ' ');
  header += '\n';
  std::string out = "\x93NUMPY";
  out += static_cast<char>(major);
  out += static_cast<char>(minor);
  std::size_t len = header.size();
  for (std::size_t i = 0; i < (major == 1 ? 2u : 4u); ++i, len >>= 8) out += static_cast<char>(len & 0xff);
  return out + header + data;
}

/// A version 1.0 .npy of the given dtype and shape ("(2, 3)") holding `payload`.
inline std::string npy_bytes(const std::string& descr, const std::string& shape, const std::string& payload) {
  return make_npy("{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape + ", }", payload);
}

/// Values as little-endian bytes.
template <class T>
std::string le_bytes(const std::vector<T>& v) {
  std::string s;
  for (T x : v) {
    char b[sizeof(T)];
    std::memcpy(b, &x, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
  }
  return s;
}

/// float64, little endian.
inline std::string f8(const std::vector<double>& v) { return le_bytes(v); }

/// CRC-32 bit by bit, straight from the definition (reflected 0xEDB88320, inverted
/// at both ends): slow, and independent of the library's table-driven one.
inline std::uint32_t crc32_bitwise(const std::string& bytes) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (const char ch : bytes) {
    c ^= static_cast<unsigned char>(ch);
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
  }
  return ~c;
}

/// A member of a hand-made ZIP archive: its bytes are stored as they are; `method`
/// only labels them (8 says deflate without deflating), and `crc` overrides the
/// checksum recorded for them.
struct ZipMember {
  std::string name;
  std::string data;
  std::uint16_t method = 0;
  std::uint16_t flags = 0;
  std::int64_t crc = -1;  // -1: the data's own
};

inline void put_le(std::string& s, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i, v >>= 8) s += static_cast<char>(v & 0xff);
}

/// A plain ZIP archive as Python's zipfile writes one without ZIP64: local headers
/// and data, the central directory, the end record.
inline std::string zip_archive(const std::vector<ZipMember>& members) {
  std::string out, dir;
  for (const ZipMember& m : members) {
    const auto crc = m.crc >= 0 ? static_cast<std::uint32_t>(m.crc) : crc32_bitwise(m.data);
    std::string common;
    put_le(common, 20, 2);  // version needed
    put_le(common, m.flags, 2);
    put_le(common, m.method, 2);
    put_le(common, 0, 2);  // time
    put_le(common, 0x21, 2);  // date 1980-01-01
    put_le(common, crc, 4);
    put_le(common, m.data.size(), 4);
    put_le(common, m.data.size(), 4);
    put_le(common, m.name.size(), 2);
    put_le(common, 0, 2);  // extra length
    const std::size_t offset = out.size();
    put_le(out, 0x04034b50, 4);
    out += common + m.name + m.data;
    put_le(dir, 0x02014b50, 4);
    put_le(dir, 20, 2);  // made by
    dir += common;
    put_le(dir, 0, 2);  // comment
    put_le(dir, 0, 2);  // disk
    put_le(dir, 0, 2);  // internal attributes
    put_le(dir, 0, 4);  // external attributes
    put_le(dir, offset, 4);
    dir += m.name;
  }
  const std::size_t dir_offset = out.size();
  out += dir;
  put_le(out, 0x06054b50, 4);
  put_le(out, 0, 4);
  put_le(out, members.size(), 2);
  put_le(out, members.size(), 2);
  put_le(out, dir.size(), 4);
  put_le(out, dir_offset, 4);
  put_le(out, 0, 2);
  return out;
}

/// The members of the archive of a bilinear patch over [0, 1]², corners (0,0,0),
/// (0,1,0), (1,0,0), (1,1,1): degree, knots_u, knots_v, control_points, periodic.
inline std::vector<ZipMember> bilinear_members() {
  const std::vector<double> knots{0, 0, 1, 1};
  return {{"degree.npy", npy_bytes("<i8", "(2,)", le_bytes<std::int64_t>({1, 1}))},
          {"knots_u.npy", npy_bytes("<f8", "(4,)", f8(knots))},
          {"knots_v.npy", npy_bytes("<f8", "(4,)", f8(knots))},
          {"control_points.npy", npy_bytes("<f8", "(2, 2, 3)", f8({0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 1}))},
          {"periodic.npy", npy_bytes("|b1", "(2,)", std::string(2, '\0'))}};
}

/// bilinear_members() with member `name`'s bytes replaced (or the member removed,
/// for an empty `data`).
inline std::string bilinear_npz_with(const std::string& name, const std::string& data) {
  std::vector<ZipMember> m = bilinear_members();
  for (auto it = m.begin(); it != m.end(); ++it)
    if (it->name == name) {
      if (data.empty()) m.erase(it);
      else it->data = data;
      break;
    }
  return zip_archive(m);
}

}  // namespace interpatch::test
