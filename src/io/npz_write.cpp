// Writing the exact form as an .npz archive: a ZIP of stored .npy members, each
// streamed from the form's memory and its checksum filled in afterwards, as
// Python's zipfile does on a seekable file; or the archive's bytes around control
// points another writer puts in place (exact_npz_frame).

#include "interpatch/io/npz.hpp"

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "io/crc32.hpp"
#include "io/npy_format.hpp"
#include "io/npz_archive.hpp"
#include "io/npz_internal.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;
using detail::cat;
using internal::crc32;

namespace {

using namespace internal::npz_io;

// The date field of 1980-01-01 (the format's first day) and time 00:00, so that an
// archive depends on the form only.
constexpr std::uint16_t dos_date = (0 << 9) | (1 << 5) | 1, dos_time = 0;
// Version 2.0 of the format for plain members, 4.5 for ZIP64; made on Unix (3),
// so that unzip gives the files mode 0644.
constexpr std::uint16_t version_plain = 20, version_zip64 = 45, made_on_unix = 3 << 8;
constexpr std::uint32_t regular_file_0644 = 0100644u << 16;

// What the writer knows of a form, surface or volume alike.
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

}  // namespace internal

void write_exact_npz(const fs::path& path, const ExactForm& exact) { internal::write_exact_npz(path, exact, false); }

void write_exact_npz(const fs::path& path, const BSplineCurve& curve) { write_archive(path, view(curve), false); }

}  // namespace interpatch::io

namespace interpatch::io::internal {

struct NpzColumns::Impl {
  std::vector<std::string> names;  // the members' file names, which OutMember views
  std::vector<OutMember> members;
  std::vector<std::uint64_t> at;  // where each member's next bytes go
  Layout layout;
};

NpzColumns::NpzColumns(const std::vector<Member>& members) : i_(std::make_unique<Impl>()) {
  i_->names.reserve(members.size());
  for (const Member& m : members) {
    i_->names.push_back(m.name + ".npy");
    const auto dtype = parse_npy_dtype(m.descr);
    std::uint64_t count = 1;
    for (const std::size_t e : m.shape) count *= e;
    OutMember o{i_->names.back(), npy_header(m.descr, m.shape), {}, {}};
    o.elsewhere = count * (dtype ? dtype->size : 8);
    i_->members.push_back(std::move(o));
  }
  i_->layout = lay_out(i_->members, false);
  for (const OutMember& m : i_->members) i_->at.push_back(m.offset + local_header(m).size() + m.head.size());
}

NpzColumns::~NpzColumns() = default;

std::uint64_t NpzColumns::total() const { return i_->layout.total; }

void NpzColumns::begin(std::ostream& os) {
  for (OutMember& m : i_->members) {
    os.seekp(static_cast<std::streamoff>(m.offset));
    os << local_header(m) << m.head;  // its checksum 0 for now
    m.crc = crc32(m.head.data(), m.head.size());
  }
}

void NpzColumns::append(std::ostream& os, std::size_t member, const void* bytes, std::size_t n) {
  OutMember& m = i_->members[member];
  os.seekp(static_cast<std::streamoff>(i_->at[member]));
  os.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(n));
  m.crc = crc32(bytes, n, m.crc);
  i_->at[member] += n;
}

void NpzColumns::finish(std::ostream& os) {
  for (std::size_t k = 0; k < i_->members.size(); ++k) {
    const OutMember& m = i_->members[k];
    if (i_->at[k] != m.offset + local_header(m).size() + m.size())
      detail::fail(errc::internal, "the archive's member ", m.name, " got ", i_->at[k] - m.offset, " bytes of ",
                   local_header(m).size() + m.size());
    std::string crc;
    put_le(crc, m.crc, 4);
    os.seekp(static_cast<std::streamoff>(m.offset + 14));
    os << crc;
  }
  os.seekp(static_cast<std::streamoff>(i_->layout.directory_offset));
  for (const OutMember& m : i_->members) os << central_header(m);
  os << end_records(i_->members.size(), i_->layout.directory_offset, i_->layout.directory_size, i_->layout.zip64_end, false);
}

}  // namespace interpatch::io::internal
