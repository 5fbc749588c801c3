#pragma once
// What the pieces of the .npz reader and writer (src/io/npz_*.cpp) share: the ZIP
// records' constants (PKWARE APPNOTE 6.3, sections 4.3 and 4.5), the exact form's
// member names, where an archive's bytes come from, and its central directory.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

#include "base/text.hpp"

namespace interpatch::io::internal::npz_io {

// ---------------------------------------------------------------------------
// ZIP records: signatures, fixed sizes, the value of a 16- or 32-bit field whose
// real value is in the ZIP64 record.

inline constexpr std::uint32_t local_signature = 0x04034b50, central_signature = 0x02014b50,
                               end_signature = 0x06054b50, end64_signature = 0x06064b50,
                               locator_signature = 0x07064b50;
inline constexpr std::size_t local_size = 30, central_size = 46, end_size = 22, end64_size = 56, locator_size = 20;
inline constexpr std::uint16_t zip64_extra_id = 0x0001;
inline constexpr std::uint64_t escape32 = 0xFFFFFFFFu, escape16 = 0xFFFFu;

inline void put_le(std::string& s, std::uint64_t v, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; ++i, v >>= 8) s += static_cast<char>(v & 0xffu);
}

inline std::uint64_t get_le(const unsigned char* p, std::size_t bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = bytes; i-- > 0;) v = (v << 8) | p[i];
  return v;
}

/// Refuses the archive `name` as malformed, saying why.
template <class... A>
[[noreturn]] void malformed(const std::string& name, const A&... parts) {
  detail::fail(errc::malformed_file, name, ": ", parts...);
}

// ---------------------------------------------------------------------------
// The exact form's arrays.

constexpr const char* axis_name(std::size_t a) { return a == 0 ? "u" : (a == 1 ? "v" : "w"); }

// The arrays of the format, in the order they are written.
inline constexpr std::array<std::string_view, 7> member_names = {"degree.npy",         "knots_u.npy",  "knots_v.npy", "knots_w.npy",
                                                                "control_points.npy", "weights.npy", "periodic.npy"};
inline constexpr const char* member_list = "degree, knots_u, knots_v, knots_w (volumes), control_points, weights (rational forms), periodic";

inline std::string knots_member(std::size_t a) { return detail::cat("knots_", axis_name(a), ".npy"); }

// ---------------------------------------------------------------------------
// Where the bytes come from (npz_source.cpp).

class Source {
 public:
  Source() = default;
  Source(const Source&) = delete;
  Source& operator=(const Source&) = delete;
  virtual ~Source() = default;
  [[nodiscard]] virtual std::uint64_t size() const = 0;
  /// n bytes at `offset` (within size()) into dst.
  virtual void read(char* dst, std::size_t n, std::uint64_t offset) const = 0;
  /// The same for a large block, with the CRC-32 of its bytes.
  virtual void read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const = 0;
};

class FileSource final : public Source {
 public:
  FileSource(const std::filesystem::path& path, std::string name);
  ~FileSource() override;

  [[nodiscard]] std::uint64_t size() const override { return size_; }
  void read(char* dst, std::size_t n, std::uint64_t offset) const override;
  void read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const override;

 private:
  [[noreturn]] void fail_read(int e) const;

  std::filesystem::path path_;
  std::string name_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

class MemorySource final : public Source {
 public:
  explicit MemorySource(std::string_view bytes) : bytes_(bytes) {}
  [[nodiscard]] std::uint64_t size() const override { return bytes_.size(); }
  void read(char* dst, std::size_t n, std::uint64_t offset) const override;
  void read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const override;

 private:
  std::string_view bytes_;
};

/// A member's bytes as a stream, for the .npy reader, with the CRC-32 of the bytes
/// the stream has handed out (not of what it read ahead).
class MemberBuffer final : public std::streambuf {
 public:
  MemberBuffer(const Source& src, std::uint64_t begin, std::uint64_t size);

  /// CRC-32 of every byte read from the stream so far.
  std::uint32_t checksum();

 protected:
  int_type underflow() override;

 private:
  const Source& src_;
  std::uint64_t begin_, size_, next_ = 0;
  std::vector<char> buf_;
  std::uint32_t crc_ = 0;
  char* summed_ = nullptr;  // the bytes of the get area before this are in crc_
};

// ---------------------------------------------------------------------------
// The central directory (npz_directory.cpp).

struct Entry {
  std::string name;
  std::uint32_t crc = 0;
  std::uint64_t size = 0;
  std::uint64_t local = 0;  // offset of the local header
  std::uint64_t data = 0;   // offset of the member's bytes
};

/// The members of the archive in `src`, each found at its local header: the end
/// record, the ZIP64 one when there is one, and the central directory, every
/// offset and size checked against the file; only the exact form's members, each
/// once, plain and stored. `name` names the archive in messages.
/// @throws error malformed_file, file_unreadable.
std::vector<Entry> read_directory(const Source& src, const std::string& name);

}  // namespace interpatch::io::internal::npz_io
