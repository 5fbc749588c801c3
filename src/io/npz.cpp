// The exact form as an .npz archive: a ZIP (PKWARE APPNOTE 6.3) of stored .npy
// members. The writer streams each member from the form's memory and fills in its
// checksum afterwards, as Python's zipfile does on a seekable file; the reader
// trusts nothing in the file: every offset and size is checked against the file
// before it is used, and every member's CRC-32 against the bytes read.

#include "interpatch/io/npz.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <istream>
#include <optional>
#include <sstream>
#include <span>
#include <streambuf>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "base/excerpt.hpp"
#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "io/crc32.hpp"
#include "io/npy_format.hpp"
#include "io/npz_internal.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;
using detail::cat;
using detail::fail;
using internal::crc32;

namespace {

// ---------------------------------------------------------------------------
// ZIP records (APPNOTE sections 4.3 and 4.5): signatures, fixed sizes, the value
// of a 16- or 32-bit field whose real value is in the ZIP64 record.

constexpr std::uint32_t local_signature = 0x04034b50, central_signature = 0x02014b50, end_signature = 0x06054b50,
                        end64_signature = 0x06064b50, locator_signature = 0x07064b50;
constexpr std::size_t local_size = 30, central_size = 46, end_size = 22, end64_size = 56, locator_size = 20;
constexpr std::uint16_t zip64_extra_id = 0x0001;
constexpr std::uint64_t escape32 = 0xFFFFFFFFu, escape16 = 0xFFFFu;
// The date field of 1980-01-01 (the format's first day) and time 00:00, so that an
// archive depends on the form only.
constexpr std::uint16_t dos_date = (0 << 9) | (1 << 5) | 1, dos_time = 0;
// Version 2.0 of the format for plain members, 4.5 for ZIP64; made on Unix (3),
// so that unzip gives the files mode 0644.
constexpr std::uint16_t version_plain = 20, version_zip64 = 45, made_on_unix = 3 << 8;
constexpr std::uint32_t regular_file_0644 = 0100644u << 16;

void put_le(std::string& s, std::uint64_t v, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; ++i, v >>= 8) s += static_cast<char>(v & 0xffu);
}

std::uint64_t get_le(const unsigned char* p, std::size_t bytes) {
  std::uint64_t v = 0;
  for (std::size_t i = bytes; i-- > 0;) v = (v << 8) | p[i];
  return v;
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

constexpr const char* axis_name(std::size_t a) { return a == 0 ? "u" : (a == 1 ? "v" : "w"); }

// The arrays of the format, in the order they are written.
constexpr std::array<std::string_view, 7> member_names = {"degree.npy",         "knots_u.npy",  "knots_v.npy", "knots_w.npy",
                                                         "control_points.npy", "weights.npy", "periodic.npy"};
constexpr const char* member_list = "degree, knots_u, knots_v, knots_w (volumes), control_points, weights (rational forms), periodic";

std::string knots_member(std::size_t a) { return cat("knots_", axis_name(a), ".npy"); }

// What the writer and the reader know of a form, surface or volume alike.
struct FormView {
  std::vector<int> degrees;
  std::vector<const KnotVector*> knots;
  std::vector<std::size_t> shape;  // of the control net, without the 3 coordinates
  const Vec3* points = nullptr;
  const double* weights = nullptr;  // null for a polynomial form
};

FormView view(const BSplineSurface& s) {
  const auto& cp = s.control_points();
  return {{s.degree_u(), s.degree_v()},
          {&s.knots_u(), &s.knots_v()},
          {cp.extent(0), cp.extent(1)},
          cp.data(),
          s.rational() ? s.weights().data() : nullptr};
}

FormView view(const BSplineVolume& v) {
  const auto& cp = v.control_points();
  return {{v.degree_u(), v.degree_v(), v.degree_w()},
          {&v.knots_u(), &v.knots_v(), &v.knots_w()},
          {cp.extent(0), cp.extent(1), cp.extent(2)},
          cp.data(),
          v.rational() ? v.weights().data() : nullptr};
}

FormView view(const BSplineCurve& c) {
  return {{c.degree()}, {&c.knots()}, {c.control_points().size()}, c.control_points().data(),
          c.rational() ? c.weights().data() : nullptr};
}

// ---------------------------------------------------------------------------
// Writing.

struct OutMember {
  std::string_view name;
  std::string head;                // the .npy preamble and header
  std::string bytes;               // the data of a small int64 or bool array, little-endian
  std::span<const double> values;  // or the data, in the form's own memory
  std::uint64_t elsewhere = 0;     // or bytes of data another writer puts in place (exact_npz_frame)
  std::uint64_t offset = 0;        // of the local header
  std::uint32_t crc = 0;
  bool zip64_size = false, zip64_offset = false;

  [[nodiscard]] std::uint64_t size() const {
    return head.size() + bytes.size() + values.size() * sizeof(double) + elsewhere;
  }
  [[nodiscard]] std::uint16_t version() const { return zip64_size || zip64_offset ? version_zip64 : version_plain; }
};

std::vector<OutMember> members_of(const FormView& f) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "control points are written as triples of doubles");
  const std::size_t dims = f.degrees.size();
  const std::size_t axes[1] = {dims};
  std::vector<OutMember> m;
  std::string degree;
  for (const int d : f.degrees) put_le(degree, static_cast<std::uint64_t>(d), 8);
  m.push_back({member_names[0], internal::npy_header("<i8", axes), std::move(degree), {}});
  for (std::size_t a = 0; a < dims; ++a) {
    const std::vector<double>& k = f.knots[a]->values();
    const std::size_t n[1] = {k.size()};
    m.push_back({member_names[1 + a], internal::npy_header("<f8", n), {}, k});
  }
  std::size_t count = 1;
  for (const std::size_t e : f.shape) count *= e;
  std::vector<std::size_t> points_shape = f.shape;
  points_shape.push_back(3);
  m.push_back({member_names[4], internal::npy_header("<f8", points_shape), {}, {}});
  if (f.points) m.back().values = {&f.points->x, 3 * count};
  else m.back().elsewhere = 3 * count * sizeof(double);
  if (f.weights) m.push_back({member_names[5], internal::npy_header("<f8", f.shape), {}, {f.weights, count}});
  std::string periodic;
  for (const KnotVector* k : f.knots) periodic += k->periodic() ? '\1' : '\0';
  m.push_back({member_names[6], internal::npy_header("|b1", axes), std::move(periodic), {}});
  return m;
}

// The ZIP64 extra field of a record: the fields whose 32-bit places hold the escape.
std::string zip64_extra(const OutMember& m, bool sizes, bool offset) {
  std::string e;
  if (!sizes && !offset) return e;
  put_le(e, zip64_extra_id, 2);
  put_le(e, (sizes ? 16 : 0) + (offset ? 8 : 0), 2);
  if (sizes) {
    put_le(e, m.size(), 8);  // uncompressed
    put_le(e, m.size(), 8);  // compressed: the same, stored
  }
  if (offset) put_le(e, m.offset, 8);
  return e;
}

// What the local and the central header share: the version needed, flags, method,
// date, checksum, sizes, and the lengths of the name and of the extra field.
void put_member_fields(std::string& h, const OutMember& m, const std::string& extra) {
  put_le(h, m.version(), 2);
  put_le(h, 0, 2);  // flags
  put_le(h, 0, 2);  // method: stored
  put_le(h, dos_time, 2);
  put_le(h, dos_date, 2);
  put_le(h, m.crc, 4);
  for (int k = 0; k < 2; ++k) put_le(h, m.zip64_size ? escape32 : m.size(), 4);  // compressed, uncompressed
  put_le(h, m.name.size(), 2);
  put_le(h, extra.size(), 2);
}

std::string local_header(const OutMember& m) {
  std::string h;
  put_le(h, local_signature, 4);
  const std::string extra = zip64_extra(m, m.zip64_size, false);
  put_member_fields(h, m, extra);
  return h + std::string(m.name) + extra;
}

std::string central_header(const OutMember& m) {
  std::string h;
  put_le(h, central_signature, 4);
  put_le(h, made_on_unix | m.version(), 2);
  const std::string extra = zip64_extra(m, m.zip64_size, m.zip64_offset);
  put_member_fields(h, m, extra);
  put_le(h, 0, 2);  // comment length
  put_le(h, 0, 2);  // disk
  put_le(h, 0, 2);  // internal attributes
  put_le(h, regular_file_0644, 4);
  put_le(h, m.zip64_offset ? escape32 : m.offset, 4);
  return h + std::string(m.name) + extra;
}

// The end of the archive: the ZIP64 end record and its locator when asked for, then
// the end record, whose fields that do not fit hold the escape.
std::string end_records(std::size_t entries, std::uint64_t directory_offset, std::uint64_t directory_size, bool zip64,
                        bool escape_all) {
  std::string e;
  if (zip64) {
    put_le(e, end64_signature, 4);
    put_le(e, end64_size - 12, 8);  // the record's size after this field
    put_le(e, made_on_unix | version_zip64, 2);
    put_le(e, version_zip64, 2);
    put_le(e, 0, 4);  // this disk
    put_le(e, 0, 4);  // the disk of the directory
    put_le(e, entries, 8);
    put_le(e, entries, 8);
    put_le(e, directory_size, 8);
    put_le(e, directory_offset, 8);
    put_le(e, locator_signature, 4);
    put_le(e, 0, 4);  // the disk of the ZIP64 end record
    put_le(e, directory_offset + directory_size, 8);
    put_le(e, 1, 4);  // disks in all
  }
  const auto field = [&](std::uint64_t v, std::uint64_t escape) { return escape_all ? escape : std::min(v, escape); };
  put_le(e, end_signature, 4);
  put_le(e, 0, 2);
  put_le(e, 0, 2);
  put_le(e, field(entries, escape16), 2);
  put_le(e, field(entries, escape16), 2);
  put_le(e, field(directory_size, escape32), 4);
  put_le(e, field(directory_offset, escape32), 4);
  put_le(e, 0, 2);  // comment length
  return e;
}

// Where the members and the directory go: each member's offset and ZIP64 flags.
struct Layout {
  std::uint64_t directory_offset = 0, directory_size = 0, total = 0;
  bool zip64_end = false;
};

Layout lay_out(std::vector<OutMember>& members, bool force_zip64) {
  std::uint64_t at = 0;
  for (OutMember& m : members) {
    m.offset = at;
    m.zip64_size = force_zip64 || m.size() >= escape32;
    m.zip64_offset = force_zip64 || m.offset >= escape32;
    at += local_header(m).size() + m.size();
  }
  Layout l;
  l.directory_offset = at;
  for (const OutMember& m : members) l.directory_size += central_header(m).size();
  l.zip64_end = force_zip64 || l.directory_offset + l.directory_size >= escape32 || members.size() >= escape16;
  l.total = l.directory_offset + l.directory_size + end_records(members.size(), 0, 0, l.zip64_end, force_zip64).size();
  return l;
}

void write_archive(const fs::path& path, const FormView& f, bool force_zip64) {
  std::vector<OutMember> members = members_of(f);
  const Layout layout = lay_out(members, force_zip64);
  const std::uint64_t directory_offset = layout.directory_offset, directory_size = layout.directory_size;
  const bool zip64_end = layout.zip64_end;
  const std::uint64_t total = layout.total;

  check_disk_space(path, total, cat("the archive '", path.string(), "'"));
  write_atomically(path, [&](std::ostream& os) {
    for (OutMember& m : members) {
      os << local_header(m);  // its checksum 0 for now
      m.crc = crc32(m.head.data(), m.head.size());
      os << m.head;
      m.crc = crc32(m.bytes.data(), m.bytes.size(), m.crc);
      os << m.bytes;
      internal::write_values(os, m.values.data(), m.values.size(), &m.crc);
      // The checksum is known now that the data are written: into the local header.
      const auto end = os.tellp();
      std::string crc;
      put_le(crc, m.crc, 4);
      os.seekp(static_cast<std::streamoff>(m.offset + 14));
      os << crc;
      os.seekp(end);
    }
    for (const OutMember& m : members) os << central_header(m);
    os << end_records(members.size(), directory_offset, directory_size, zip64_end, force_zip64);
  }, total);
}

// ---------------------------------------------------------------------------
// Reading: where the bytes come from.

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
  FileSource(const fs::path& path, std::string name) : path_(path), name_(std::move(name)) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) {
      const int e = errno;
      fail(errc::file_unreadable, "cannot open '", name_, "': ", std::strerror(e));
    }
    struct stat st {};
    const bool known = ::fstat(fd_, &st) == 0;
    const int e = errno;
    if (!known || S_ISDIR(st.st_mode)) {
      ::close(fd_);  // no destructor runs for a constructor that throws
      if (!known) fail_read(e);
      fail(errc::file_unreadable, "cannot read '", name_, "': it is a directory");
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
  }
  ~FileSource() override { ::close(fd_); }

  [[nodiscard]] std::uint64_t size() const override { return size_; }

  void read(char* dst, std::size_t n, std::uint64_t offset) const override {
    while (n > 0) {
      const ssize_t got = ::pread(fd_, dst, n, static_cast<off_t>(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) fail_read(got < 0 ? errno : EIO);  // 0: the file shrank while being read
      dst += got;
      offset += static_cast<std::uint64_t>(got);
      n -= static_cast<std::size_t>(got);
    }
  }

  void read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const override {
    internal::read_pieces(path_, name_, dst, n, offset, crc);
  }

 private:
  [[noreturn]] void fail_read(int e) const {
    fail(errc::file_unreadable, "cannot read '", name_, "': ", std::strerror(e));
  }

  fs::path path_;
  std::string name_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

class MemorySource final : public Source {
 public:
  explicit MemorySource(std::string_view bytes) : bytes_(bytes) {}
  [[nodiscard]] std::uint64_t size() const override { return bytes_.size(); }
  void read(char* dst, std::size_t n, std::uint64_t offset) const override {
    if (n > 0) std::memcpy(dst, bytes_.data() + offset, n);
  }
  void read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const override {
    read(dst, n, offset);
    *crc = crc32(dst, n, *crc);
  }

 private:
  std::string_view bytes_;
};

/// A member's bytes as a stream, for the .npy reader, with the CRC-32 of the bytes
/// the stream has handed out (not of what it read ahead).
class MemberBuffer final : public std::streambuf {
 public:
  MemberBuffer(const Source& src, std::uint64_t begin, std::uint64_t size)
      : src_(src), begin_(begin), size_(size), buf_(static_cast<std::size_t>(std::min<std::uint64_t>(size, 1 << 16))) {}

  /// CRC-32 of every byte read from the stream so far.
  std::uint32_t checksum() {
    crc_ = internal::crc32_serial(summed_, static_cast<std::size_t>(gptr() - summed_), crc_);
    summed_ = gptr();
    return crc_;
  }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    (void)checksum();
    if (next_ >= size_) return traits_type::eof();
    const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(buf_.size(), size_ - next_));
    src_.read(buf_.data(), n, begin_ + next_);
    next_ += n;
    setg(buf_.data(), buf_.data(), buf_.data() + n);
    summed_ = buf_.data();
    return traits_type::to_int_type(buf_[0]);
  }

 private:
  const Source& src_;
  std::uint64_t begin_, size_, next_ = 0;
  std::vector<char> buf_;
  std::uint32_t crc_ = 0;
  char* summed_ = nullptr;  // the bytes of the get area before this are in crc_
};

// ---------------------------------------------------------------------------
// Reading: the archive.

struct Entry {
  std::string name;
  std::uint32_t crc = 0;
  std::uint64_t size = 0;
  std::uint64_t local = 0;  // offset of the local header
  std::uint64_t data = 0;   // offset of the member's bytes
};

class Reader {
 public:
  Reader(const Source& src, std::string name) : src_(src), name_(std::move(name)) {}

  ExactForm read(std::size_t want_dims) {
    read_directory();
    const std::vector<double> deg = read_degrees();
    const std::size_t dims = deg.size();
    if (want_dims != 0 && dims != want_dims)
      fail(errc::wrong_type, name_, " holds a ", dims == 3 ? "volume" : "surface", " (degree.npy has shape (", dims,
           ",)); bspline_surface reads the archive of a surface, bspline_volume that of a volume");
    if (dims == 2 && find("knots_w.npy"))
      fail(errc::size_mismatch, name_, ": knots_w.npy is the third direction of a volume, but degree.npy has shape (2,), a surface's");
    std::vector<int> degrees;
    for (std::size_t a = 0; a < dims; ++a) {
      if (!(deg[a] >= 1 && deg[a] <= max_degree))
        fail(errc::invalid_degree, name_, ": degree.npy: degree ", integer_text(deg[a]), " along ", axis_name(a),
             " is outside 1..", max_degree);
      degrees.push_back(static_cast<int>(deg[a]));
    }
    const std::vector<bool> periodic = read_periodic(dims);
    if (dims == 2) return read_form<2>(degrees, periodic);
    return read_form<3>(degrees, periodic);
  }

 private:
  template <class... A>
  [[noreturn]] void malformed(const A&... parts) const {
    fail(errc::malformed_file, name_, ": ", parts...);
  }

  static std::string integer_text(double v) {
    return std::fabs(v) < 1e18 ? std::to_string(static_cast<long long>(v)) : detail::num(v);
  }

  // The end record, the ZIP64 one when there is one, and the central directory.
  void read_directory() {
    const std::uint64_t size = src_.size();
    if (size >= 6) {
      char start[6];
      src_.read(start, 6, 0);
      if (std::memcmp(start, "\x93NUMPY", 6) == 0)
        malformed("a single .npy array, not an .npz archive of the exact form's arrays (", member_list, ")");
    }
    if (size < end_size)
      malformed("not an .npz archive (", size, " bytes, shorter than the 22-byte end record of a ZIP file)");
    // The end record is the last 22 bytes, followed by a comment of at most 64 KiB.
    const auto tail_size = static_cast<std::size_t>(std::min<std::uint64_t>(size, end_size + 0xFFFF));
    std::vector<unsigned char> tail(tail_size);
    src_.read(reinterpret_cast<char*>(tail.data()), tail_size, size - tail_size);
    std::optional<std::size_t> found;
    for (std::size_t p = tail_size - end_size + 1; p-- > 0;)
      if (get_le(&tail[p], 4) == end_signature && p + end_size + get_le(&tail[p + 20], 2) == tail_size) {
        found = p;
        break;
      }
    if (!found) {
      unsigned char start[4] = {};
      src_.read(reinterpret_cast<char*>(start), std::min<std::size_t>(4, size), 0);
      if (get_le(start, 4) == local_signature)
        malformed("truncated ZIP archive: no end-of-central-directory record in its last ", tail_size, " of ", size,
                  " bytes");
      malformed("not an .npz archive: no ZIP end-of-central-directory record in its last ", tail_size, " of ", size,
                " bytes");
    }
    const unsigned char* end = &tail[*found];
    const std::uint64_t end_at = size - tail_size + *found;
    if (get_le(end + 4, 2) != 0 || get_le(end + 6, 2) != 0)
      malformed("the archive spans several disks (end record: disk ", get_le(end + 4, 2), ", directory on disk ",
                get_le(end + 6, 2), "); only single-file archives are read");
    std::uint64_t entries = get_le(end + 10, 2), dir_size = get_le(end + 12, 4), dir_offset = get_le(end + 16, 4);
    std::uint64_t records_at = end_at;  // where the end records begin: the directory ends before
    if (*found >= locator_size && get_le(end - locator_size, 4) == locator_signature) {
      const unsigned char* loc = end - locator_size;
      const std::uint64_t at = get_le(loc + 8, 8);
      records_at = end_at - locator_size;
      if (at > records_at || records_at - at < end64_size)
        malformed("the ZIP64 end record at offset ", at, " lies outside the ", records_at, " bytes before its locator");
      unsigned char z[end64_size];
      src_.read(reinterpret_cast<char*>(z), end64_size, at);
      if (get_le(z, 4) != end64_signature) malformed("no ZIP64 end record at offset ", at, ", where its locator points");
      if (get_le(z + 16, 4) != 0 || get_le(z + 20, 4) != 0 || get_le(loc + 16, 4) > 1)
        malformed("the archive spans several disks (ZIP64 end record); only single-file archives are read");
      entries = get_le(z + 32, 8);
      dir_size = get_le(z + 40, 8);
      dir_offset = get_le(z + 48, 8);
      records_at = at;
    } else if (entries == escape16 || dir_size == escape32 || dir_offset == escape32) {
      malformed("the end record refers to a ZIP64 end record (", entries, " entries, directory of ", dir_size,
                " bytes at offset ", dir_offset, "), but there is none");
    }
    if (dir_offset > records_at || dir_size > records_at - dir_offset)
      malformed("the central directory (", dir_size, " bytes at offset ", dir_offset, ") runs past the end records at offset ",
                records_at, " (the file has ", size, " bytes)");
    // An exact form has at most seven members: a directory of a megabyte is not one.
    constexpr std::uint64_t max_directory = std::uint64_t{1} << 20;
    if (dir_size > max_directory)
      malformed("a central directory of ", dir_size, " bytes (", entries, " entries) is not that of an exact form (",
                member_list, ")");
    std::vector<unsigned char> dir(static_cast<std::size_t>(dir_size));
    src_.read(reinterpret_cast<char*>(dir.data()), dir.size(), dir_offset);
    std::size_t p = 0;
    for (std::uint64_t k = 0; k < entries; ++k) {
      if (dir.size() - p < central_size || get_le(&dir[p], 4) != central_signature)
        malformed("the central directory (", dir_size, " bytes) ends or is damaged at its byte ", p, ", in entry ", k + 1,
                  " of ", entries);
      const unsigned char* h = &dir[p];
      const std::size_t name_len = get_le(h + 28, 2), extra_len = get_le(h + 30, 2), comment_len = get_le(h + 32, 2);
      if (dir.size() - p - central_size < name_len + extra_len + comment_len)
        malformed("entry ", k + 1, " of the central directory runs past its end (", dir_size, " bytes)");
      Entry e;
      e.name.assign(reinterpret_cast<const char*>(h + central_size), name_len);
      const std::string shown = "'" + detail::excerpt(e.name, 60) + "'";
      if (get_le(h + 8, 2) & 1u) malformed("member ", shown, " is encrypted; only plain stored members are read");
      if (const std::uint64_t method = get_le(h + 10, 2); method != 0)
        malformed("member ", shown, " is compressed (method ", method, method == 8 ? ", deflate" : "",
                  "); only stored members are read: write the archive with numpy.savez, not numpy.savez_compressed");
      e.crc = static_cast<std::uint32_t>(get_le(h + 16, 4));
      std::uint64_t compressed = get_le(h + 20, 4), size_field = get_le(h + 24, 4);
      e.local = get_le(h + 42, 4);
      // The ZIP64 extra field holds, in this order, the fields whose places hold the escape.
      const unsigned char* extra = h + central_size + name_len;
      for (std::size_t q = 0; q + 4 <= extra_len;) {
        const std::uint64_t id = get_le(extra + q, 2), len = get_le(extra + q + 2, 2);
        if (q + 4 + len > extra_len) malformed("member ", shown, ": extra field ", id, " runs past the extra data");
        if (id == zip64_extra_id) {
          std::size_t r = q + 4;
          for (std::uint64_t* field : {&size_field, &compressed, &e.local}) {
            if (*field != escape32) continue;
            if (r + 8 > q + 4 + len) malformed("member ", shown, ": the ZIP64 extra field lacks a size or an offset");
            *field = get_le(extra + r, 8);
            r += 8;
          }
        }
        q += 4 + len;
      }
      for (const std::uint64_t v : {size_field, compressed, e.local})
        if (v == escape32) malformed("member ", shown, " refers to a ZIP64 extra field it does not have");
      if (compressed != size_field)
        malformed("stored member ", shown, " has ", compressed, " bytes in the archive but a size of ", size_field);
      e.size = size_field;
      p += central_size + name_len + extra_len + comment_len;
      entries_.push_back(std::move(e));
    }
    if (p != dir.size())
      malformed("the central directory holds ", dir.size() - p, " bytes after its ", entries, " entries");
    for (std::size_t k = 0; k < entries_.size(); ++k) {
      const Entry& e = entries_[k];
      const std::string shown = "'" + detail::excerpt(e.name, 60) + "'";
      if (std::find(member_names.begin(), member_names.end(), e.name) == member_names.end())
        malformed("member ", shown, " is not an array of an exact form (", member_list, ")");
      for (std::size_t j = 0; j < k; ++j)
        if (entries_[j].name == e.name) malformed("member ", shown, " appears twice");
      locate(entries_[k], dir_offset);
    }
  }

  // The member's local header, and where its bytes are; all before the directory.
  void locate(Entry& e, std::uint64_t dir_offset) const {
    if (e.local > dir_offset || dir_offset - e.local < local_size)
      malformed("member '", e.name, "': its local header at offset ", e.local, " is not before the central directory at ",
                dir_offset);
    unsigned char h[local_size];
    src_.read(reinterpret_cast<char*>(h), local_size, e.local);
    if (get_le(h, 4) != local_signature)
      malformed("member '", e.name, "': no local header at offset ", e.local, " (bad signature)");
    if (get_le(h + 8, 2) != 0) malformed("member '", e.name, "' is compressed in its local header; only stored members are read");
    const std::uint64_t name_len = get_le(h + 26, 2), extra_len = get_le(h + 28, 2);
    const std::uint64_t room = dir_offset - e.local - local_size;
    if (name_len + extra_len > room || e.size > room - name_len - extra_len)
      malformed("member '", e.name, "' of ", e.size, " bytes at offset ", e.local + local_size + name_len + extra_len,
                " runs past the central directory at offset ", dir_offset, " (the file has ", src_.size(), " bytes)");
    std::string local_name(name_len, '\0');
    src_.read(local_name.data(), local_name.size(), e.local + local_size);
    if (local_name != e.name)
      malformed("member '", e.name, "': its local header names it '", detail::excerpt(local_name, 60), "'");
    e.data = e.local + local_size + name_len + extra_len;
  }

  [[nodiscard]] const Entry* find(std::string_view member) const {
    for (const Entry& e : entries_)
      if (e.name == member) return &e;
    return nullptr;
  }

  const Entry& require(std::string_view member) const {
    if (const Entry* e = find(member)) return *e;
    std::string present;
    for (const Entry& e : entries_) present += (present.empty() ? "" : ", ") + e.name;
    malformed("no member '", member, "' (an exact form holds ", member_list, "; this archive holds ",
              present.empty() ? "none" : present, ")");
  }

  // One member as an .npy array of the dtype kind `kind` ('f': float, 'i': integer,
  // 'b': bool) into `destination`; its checksum checked. Returns the shape.
  std::vector<std::size_t> read_member(const Entry& e, char kind, const NpyDestination& destination) const {
    const std::string where = cat(name_, ": ", e.name);
    MemberBuffer buf(src_, e.data, e.size);
    std::istream in(&buf);
    const internal::NpyHeader h = internal::read_npy_header(in, e.size, where);
    const std::optional<internal::NpyDtype> dt = internal::parse_npy_dtype(h.descr);
    const char got = !dt ? '?' : (dt->kind == 'u' ? 'i' : dt->kind);
    if (got != kind)
      fail(errc::wrong_type, where, ": dtype '", detail::excerpt(h.descr, 40), "'; expected ",
           kind == 'f' ? "float64 (or float32)" : kind == 'i' ? "integers (int64)" : "bool");
    std::optional<std::uint32_t> crc;
    const std::vector<std::size_t> shape = internal::read_npy_data(
        in, h, e.size, where, destination,
        [&](char* dst, std::size_t n, std::uint64_t offset) {
          const std::uint32_t head = buf.checksum();
          std::uint32_t body = 0;
          src_.read_bulk(dst, n, e.data + offset, &body);
          crc = internal::crc32_combine(head, body, n);
        },
        kind != 'f');
    if (!crc) crc = buf.checksum();
    if (*crc != e.crc)
      fail(errc::malformed_file, where, ": CRC-32 of its ", e.size, " bytes is ", hex32(*crc), ", the archive records ",
           hex32(e.crc), ": the file is damaged");
    return shape;
  }

  // A short 1-D member (degree, periodic) of `dims` entries, or 2 or 3 when dims is 0.
  std::vector<double> read_vector(const Entry& e, char kind, std::size_t dims) const {
    std::vector<double> v;
    read_member(e, kind, [&](std::span<const std::size_t> shape, std::size_t count) {
      const bool fits = shape.size() == 1 && (dims != 0 ? shape[0] == dims : (shape[0] == 2 || shape[0] == 3));
      if (!fits)
        fail(errc::size_mismatch, name_, ": ", e.name, " has shape ", internal::npy_shape_text(shape), "; expected ",
             dims != 0 ? cat("(", dims, ",), one entry per direction") : std::string("(2,) (a surface) or (3,) (a volume)"));
      v.resize(count);
      return v.data();
    });
    return v;
  }

  std::vector<double> read_degrees() const { return read_vector(require("degree.npy"), 'i', 0); }

  // Which directions are closed; none without the member (an archive of numpy.savez).
  std::vector<bool> read_periodic(std::size_t dims) const {
    std::vector<bool> periodic(dims, false);
    if (const Entry* e = find("periodic.npy")) {
      const std::vector<double> flags = read_vector(*e, 'b', dims);
      for (std::size_t a = 0; a < dims; ++a) periodic[a] = flags[a] != 0;
    }
    return periodic;
  }

  // The knots of a closed direction are the extended ones (KnotVector::values()).
  template <std::size_t D>
  ExactForm read_form(const std::vector<int>& degrees, const std::vector<bool>& periodic) const {
    std::vector<KnotVector> knots;
    for (std::size_t a = 0; a < D; ++a) {
      const Entry& e = require(knots_member(a));
      std::vector<double> values;
      read_member(e, 'f', [&](std::span<const std::size_t> shape, std::size_t count) {
        if (shape.size() != 1)
          fail(errc::size_mismatch, name_, ": ", e.name, " has shape ", internal::npy_shape_text(shape),
               "; expected a 1-D array of knots");
        values.resize(count);
        return values.data();
      });
      knots.push_back(detail::prefixed(cat(name_, ": ", e.name), [&] {
        return periodic[a] ? KnotVector::periodic_from_extended(degrees[a], values) : KnotVector(degrees[a], std::move(values));
      }));
    }

    using Shape = typename Grid<Vec3, D>::shape_type;
    Shape shape{};
    for (std::size_t a = 0; a < D; ++a) shape[a] = static_cast<std::size_t>(knots[a].count());
    const auto expected = [&] {
      std::string s = "(";
      for (std::size_t a = 0; a < D; ++a) s += cat(shape[a], ", ");
      return s;
    };
    Grid<Vec3, D> points;
    const Entry& cp = require("control_points.npy");
    read_member(cp, 'f', [&](std::span<const std::size_t> s, std::size_t) {
      if (s.size() != D + 1 || s[D] != 3)
        fail(errc::size_mismatch, name_, ": control_points.npy has shape ", internal::npy_shape_text(s), "; expected ",
             D == 2 ? "(n, m, 3)" : "(n, m, l, 3)", ", the knots need ", expected(), "3)");
      for (std::size_t a = 0; a < D; ++a)
        if (s[a] != shape[a])
          fail(errc::size_mismatch, name_, ": control_points.npy has shape ", internal::npy_shape_text(s), ", but the ",
               knots[a].size(), knots[a].periodic() ? " periodic knots" : " knots", " of degree ", knots[a].degree(), " in ",
               knots_member(a), " need ", shape[a],
               " control points along ", axis_name(a), ", ", expected(), "3)");
      points = Grid<Vec3, D>(shape, for_overwrite);
      static_assert(sizeof(Vec3) == 3 * sizeof(double), "control points are read as triples of doubles");
      return &points.data()->x;
    });

    Grid<double, D> weights;
    if (const Entry* w = find("weights.npy")) {
      read_member(*w, 'f', [&](std::span<const std::size_t> s, std::size_t) {
        if (!std::equal(s.begin(), s.end(), shape.begin(), shape.end()))
          fail(errc::size_mismatch, name_, ": weights.npy has shape ", internal::npy_shape_text(s),
               "; the control points need one weight each, ", expected().substr(0, expected().size() - 2), ")");
        weights = Grid<double, D>(shape, for_overwrite);
        return weights.data();
      });
      check_weights(weights);
    }
    return detail::prefixed(cat(name_, ": control_points.npy"), [&]() -> ExactForm {
      if constexpr (D == 2) {
        return BSplineSurface(std::move(knots[0]), std::move(knots[1]), std::move(points), std::move(weights));
      } else {
        return BSplineVolume(std::move(knots[0]), std::move(knots[1]), std::move(knots[2]), std::move(points),
                             std::move(weights));
      }
    });
  }

  // The first weight that is not finite or not positive, named by its indices.
  template <std::size_t D>
  void check_weights(const Grid<double, D>& w) const {
    const auto* bad = std::find_if(w.data(), w.data() + w.size(), [](double x) { return !(std::isfinite(x) && x > 0); });
    if (bad == w.data() + w.size()) return;
    std::string index;
    for (std::size_t a = D, r = static_cast<std::size_t>(bad - w.data()); a-- > 0; r /= w.extent(a))
      index.insert(0, cat("[", r % w.extent(a), "]"));
    if (!std::isfinite(*bad)) fail(errc::not_finite, name_, ": weights.npy: weight ", index, " is ", *bad);
    fail(errc::invalid_weight, name_, ": weights.npy: weight ", index, " is ", *bad, "; weights must be positive");
  }

  const Source& src_;
  std::string name_;
  std::vector<Entry> entries_;
};

}  // namespace

namespace internal {

NpzFrame exact_npz_frame(std::span<const int> degrees, std::span<const KnotVector* const> knots,
                         std::span<const std::size_t> shape, std::uint32_t points_crc) {
  FormView f{{degrees.begin(), degrees.end()}, {knots.begin(), knots.end()}, {shape.begin(), shape.end()}, nullptr, nullptr};
  std::vector<OutMember> members = members_of(f);
  const Layout layout = lay_out(members, false);
  NpzFrame frame;
  std::string* to = &frame.head;
  for (OutMember& m : members) {
    m.crc = crc32(m.head.data(), m.head.size());
    m.crc = crc32(m.bytes.data(), m.bytes.size(), m.crc);
    std::ostringstream values;
    internal::write_values(values, m.values.data(), m.values.size(), &m.crc);
    if (m.elsewhere) m.crc = internal::crc32_combine(m.crc, points_crc, m.elsewhere);
    *to += local_header(m) + m.head + m.bytes + values.str();
    if (m.elsewhere) {
      frame.points_offset = to->size();
      to = &frame.tail;
    }
  }
  for (const OutMember& m : members) frame.tail += central_header(m);
  frame.tail += end_records(members.size(), layout.directory_offset, layout.directory_size, layout.zip64_end, false);
  frame.total = layout.total;
  return frame;
}

void write_exact_npz(const fs::path& path, const ExactForm& exact, bool zip64) {
  std::visit([&](const auto& form) { write_archive(path, view(form), zip64); }, exact);
}

ExactForm read_exact_npz(const fs::path& path, std::size_t dims) {
  const FileSource src(path, path.string());
  return Reader(src, path.string()).read(dims);
}

}  // namespace internal

void write_exact_npz(const fs::path& path, const ExactForm& exact) { internal::write_exact_npz(path, exact, false); }

void write_exact_npz(const fs::path& path, const BSplineCurve& curve) { write_archive(path, view(curve), false); }

ExactForm read_exact_npz(const fs::path& path) { return internal::read_exact_npz(path, 0); }

ExactForm parse_exact_npz(std::string_view bytes, std::string_view name) {
  const MemorySource src(bytes);
  return Reader(src, std::string(name)).read(0);
}

}  // namespace interpatch::io
