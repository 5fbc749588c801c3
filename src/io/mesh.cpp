#include "interpatch/io/mesh.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>

#include "base/parallel.hpp"
#include "base/pipeline.hpp"
#include "base/text.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"
#include "io/box.hpp"
#include "io/extension.hpp"
#include "io/finite.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------
// Output in bounded chunks: text and binary values are gathered in a buffer of
// about a megabyte and handed to the stream, so no file is ever built in memory.

// Native doubles turned in place into the given byte order.
void to_byte_order(char* bytes, std::size_t size, std::endian order) {
  if (order == std::endian::native) return;
  for (std::size_t d = 0; d + sizeof(std::uint64_t) <= size; d += sizeof(std::uint64_t)) {
    std::uint64_t w;
    std::memcpy(&w, bytes + d, sizeof w);
    w = __builtin_bswap64(w);
    std::memcpy(bytes + d, &w, sizeof w);
  }
}

class Sink {
 public:
  /// Gathers about a megabyte, then hands it to the stream.
  explicit Sink(std::ostream& os) : os_(&os), buf_(&own_) { own_.reserve(limit + 256); }
  /// Appends to `out` and never flushes: a piece of a file made on a thread of its own.
  explicit Sink(std::string& out) : buf_(&out) {}
  Sink(const Sink&) = delete;
  Sink& operator=(const Sink&) = delete;
  ~Sink() = default;

  void flush() {
    if (!os_) return;
    os_->write(buf_->data(), static_cast<std::streamsize>(buf_->size()));
    buf_->clear();
  }

  Sink& text(std::string_view s) {
    *buf_ += s;
    maybe_flush();
    return *this;
  }
  Sink& ch(char c) {
    *buf_ += c;
    return *this;
  }
  Sink& uint(std::uint64_t v) {
    char b[24];
    const auto r = std::to_chars(b, b + sizeof b, v);
    buf_->append(b, r.ptr);
    return *this;
  }
  /// Shortest text that reads back as the same double.
  Sink& shortest(double v) {
    char b[32];
    const auto r = std::to_chars(b, b + sizeof b, v);
    buf_->append(b, r.ptr);
    return *this;
  }
  template <class T>
  Sink& little(T v) {
    return bytes(v, std::endian::little);
  }
  template <class T>
  Sink& big(T v) {
    return bytes(v, std::endian::big);
  }
  /// Values (points, three doubles each, or doubles) p[0], p[stride], ..., n of
  /// them, in the given byte order.
  template <class T>
  Sink& gather(const T* p, std::size_t n, std::size_t stride, std::endian order) {
    const std::size_t at = buf_->size();
    buf_->resize(at + n * sizeof(T));
    char* to = buf_->data() + at;
    for (std::size_t i = 0; i < n; ++i) std::memcpy(to + i * sizeof(T), p + i * stride, sizeof(T));
    to_byte_order(to, n * sizeof(T), order);
    maybe_flush();
    return *this;
  }

 private:
  template <class T>
  Sink& bytes(T v, std::endian order) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (order != std::endian::native) std::reverse(b, b + sizeof(T));
    buf_->append(b, sizeof(T));
    return *this;
  }
  void maybe_flush() {
    if (os_ && buf_->size() >= limit) flush();
  }

  static constexpr std::size_t limit = std::size_t{1} << 20;
  std::ostream* os_ = nullptr;
  std::string own_;
  std::string* buf_;
};

/// Writes records 0 .. count − 1 to `os` in order, record(sink, r) putting record r
/// into the sink: the bytes of that loop; returns how many bytes that was. Every
/// thread turns a block of records into bytes, a piece of about 64 KiB each into a
/// buffer of its own, while one thread writes the block before (detail::pipeline):
/// text and packed binary cost more to make than to write. `record_bytes` is about
/// what one record takes.
template <class Record>
std::uint64_t write_records(std::ostream& os, std::size_t count, std::size_t record_bytes, Record&& record) {
  constexpr std::size_t piece_bytes = std::size_t{1} << 16, block_pieces = 16;
  const std::size_t per_piece = std::max<std::size_t>(1, piece_bytes / std::max<std::size_t>(1, record_bytes));
  const std::size_t per_block = per_piece * block_pieces;
  const std::size_t blocks = (count + per_block - 1) / per_block;
  // Two blocks of pieces alive at once: block b's in buffers[b % 2].
  std::array<std::vector<std::string>, 2> buffers;
  for (auto& b : buffers) b.resize(block_pieces);
  const auto pieces = [&](std::size_t b) {
    const std::size_t left = count - b * per_block;
    return std::min(block_pieces, (left + per_piece - 1) / per_piece);
  };
  const auto make = [&](std::size_t b, std::size_t p) {
    // The piece grows in a string of this thread's own (its memory taken over from the
    // buffer): the buffers' string objects share cache lines, and every character
    // appended updates its string's size.
    std::string out;
    out.swap(buffers[b % 2][p]);
    out.clear();
    {
      Sink s(out);
      const std::size_t first = b * per_block + p * per_piece, last = std::min(count, first + per_piece);
      for (std::size_t r = first; r < last; ++r) record(s, r);
    }
    out.swap(buffers[b % 2][p]);
  };
  std::uint64_t written = 0;
  const auto write = [&](std::size_t b) {
    const std::size_t n = pieces(b);
    for (std::size_t p = 0; p < n; ++p) {
      const std::string& out = buffers[b % 2][p];
      os.write(out.data(), static_cast<std::streamsize>(out.size()));
      written += out.size();
    }
  };
  detail::pipeline(blocks, count * record_bytes >= 4 * piece_bytes, pieces, make, write);
  return written;
}

using internal::lower_extension;

std::string normalized(std::string_view extension) {
  std::string ext(extension);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!ext.empty() && ext.front() != '.') ext.insert(ext.begin(), '.');
  return ext;
}

constexpr std::array<std::string_view, 6> surface_formats = {".obj", ".stl", ".ply", ".vtk", ".vts", ".xyz"};
constexpr std::array<std::string_view, 3> volume_formats = {".vtk", ".vts", ".xyz"};

template <std::size_t N>
std::string list(const std::array<std::string_view, N>& formats) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) {
    if (i) s += ", ";
    s += formats[i];
  }
  return s;
}

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// ---------------------------------------------------------------------------
// Vertices and faces of a structured surface grid.

/// The vertices the unstructured formats (.obj, .ply, .stl) write: the grid's
/// points less the last row (column) in a direction the mesh closes in, which
/// repeats the first; cells next to it use the first row's vertices instead. Vertex
/// (i, j) of the rows written is number i * cols + j.
class Vertices {
 public:
  explicit Vertices(const SurfaceMesh& m)
      : g_(m.points),
        rows_(g_.extent(0) - (m.closed[0] ? 1 : 0)),
        cols_(g_.extent(1) - (m.closed[1] ? 1 : 0)) {}

  [[nodiscard]] std::size_t rows() const noexcept { return rows_; }
  [[nodiscard]] std::size_t cols() const noexcept { return cols_; }
  [[nodiscard]] std::size_t count() const noexcept { return rows_ * cols_; }
  [[nodiscard]] const PointGrid& grid() const noexcept { return g_; }
  /// The row (column) of vertices grid row (column) i stands for: i itself, or 0 for
  /// the last one of a closed direction.
  [[nodiscard]] std::size_t row(std::size_t i) const noexcept { return i == rows_ ? 0 : i; }
  [[nodiscard]] std::size_t col(std::size_t j) const noexcept { return j == cols_ ? 0 : j; }

 private:
  const PointGrid& g_;
  std::size_t rows_, cols_;
};

/// A corner of a face: its vertex and the vertex's point, and the grid point it
/// stands for (C order), which differ across a seam.
struct Corner {
  std::size_t vertex = 0, grid = 0;
  const Vec3* point = nullptr;
};

/// The corners of cell (i, j), counterclockwise in (u, v) so that the face normal
/// is S_u x S_v. Corners at the same point as their predecessor (a pole row or a
/// collapsed edge) are dropped: 4 corners is a quad, 3 a triangle, 0 a cell with no
/// area left to draw.
std::size_t cell_corners(const Vertices& v, std::size_t i, std::size_t j, Corner out[4]) {
  const std::size_t nv = v.grid().extent(1);
  const std::size_t ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
  std::size_t n = 0;
  for (std::size_t c = 0; c < 4; ++c) {
    const std::size_t r = v.row(ci[c]), q = v.col(cj[c]);
    const Corner k{r * v.cols() + q, ci[c] * nv + cj[c], &v.grid()(r, q)};
    if (n == 0 || !(*k.point == *out[n - 1].point)) out[n++] = k;
  }
  while (n > 1 && *out[n - 1].point == *out[0].point) --n;
  return n >= 3 ? n : 0;
}

/// The cells of the grid, (nu − 1) × (nv − 1) of them, cell r at row r / (nv − 1)
/// and column r % (nv − 1): the records of the formats' face lists.
std::size_t cell_count(const Vertices& v) {
  const std::size_t nu = v.grid().extent(0), nv = v.grid().extent(1);
  return nu < 2 || nv < 2 ? 0 : (nu - 1) * (nv - 1);
}

/// Calls f(corners, n) for the face of cell r, if it has one.
template <class F>
void cell_face(const Vertices& v, std::size_t r, F&& f) {
  const std::size_t cols = v.grid().extent(1) - 1;
  Corner c[4];
  if (const std::size_t n = cell_corners(v, r / cols, r % cols, c); n != 0) f(c, n);
}

/// Calls f(a, b, c, normal) for the triangles of cell r's face (a fan from its
/// first corner), skipping those of zero area.
template <class F>
void cell_triangles(const Vertices& v, std::size_t r, F&& f) {
  cell_face(v, r, [&](const Corner* c, std::size_t n) {
    for (std::size_t k = 1; k + 1 < n; ++k) {
      const Vec3& a = *c[0].point;
      const Vec3& b = *c[k].point;
      const Vec3& d = *c[k + 1].point;
      const Vec3 nrm = cross(b - a, d - a);
      if (nrm == Vec3{}) continue;
      f(a, b, d, nrm);
    }
  });
}

/// How many of the cells' faces (count_triangles false) or triangles there are;
/// every thread counts cells.
std::uint64_t count_faces(const Vertices& v, bool count_triangles) {
  const std::size_t cells = cell_count(v);
  std::uint64_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) if (cells >= detail::parallel_min_work / 16)
  for (std::size_t r = 0; r < cells; ++r) {
    if (count_triangles) cell_triangles(v, r, [&](const Vec3&, const Vec3&, const Vec3&, const Vec3&) { ++count; });
    else cell_face(v, r, [&](const Corner*, std::size_t) { ++count; });
  }
  return count;
}

/// " (closed in u and v: ...)" for the formats' comment lines, or nothing.
std::string closed_note(const SurfaceMesh& m) {
  if (!m.closed[0] && !m.closed[1]) return {};
  const char* dirs = m.closed[0] && m.closed[1] ? "u and v" : m.closed[0] ? "u" : "v";
  return std::string(" (closed in ") + dirs + ": the last row of samples is the first, written once)";
}

// ---------------------------------------------------------------------------
// Surface-only formats. Each list of records (vertices, faces, ...) is made by
// every thread, a block at a time (write_records).

// Vertices, normals and faces share numbers; texture coordinates are one per grid
// point, so that the cells across a seam still run up to u (v) = 1.
void write_obj(std::ostream& os, const SurfaceMesh& m) {
  const PointGrid& g = m.points;
  const Vertices vx(m);
  const std::size_t nu = g.extent(0), nv = g.extent(1), cols = vx.cols();
  const bool normals = !m.normals.empty();
  {
    Sink s(os);
    s.text("# interpatch surface mesh: ").uint(vx.rows()).text(" x ").uint(vx.cols()).text(" vertices, first index along u");
    s.text(closed_note(m)).ch('\n');
    s.flush();
  }
  const auto vector_lines = [&](const char* tag, const PointGrid& from) {
    write_records(os, vx.count(), 60, [&](Sink& s, std::size_t r) {
      const Vec3& p = from(r / cols, r % cols);
      s.text(tag).shortest(p.x).ch(' ').shortest(p.y).ch(' ').shortest(p.z).ch('\n');
    });
  };
  vector_lines("v ", g);
  // Texture coordinates i / (nu − 1), j / (nv − 1): each one's text made once.
  const auto fractions = [](std::size_t n) {
    std::vector<std::string> t(n);
    for (std::size_t i = 0; i < n; ++i) {
      Sink s(t[i]);
      s.shortest(n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 0.0);
    }
    return t;
  };
  const std::vector<std::string> tu = fractions(nu), tv = fractions(nv);
  write_records(os, nu * nv, 30, [&](Sink& s, std::size_t r) {
    s.text("vt ").text(tu[r / nv]).ch(' ').text(tv[r % nv]).ch('\n');
  });
  if (normals) vector_lines("vn ", m.normals);
  write_records(os, cell_count(vx), 40, [&](Sink& s, std::size_t r) {
    cell_face(vx, r, [&](const Corner* c, std::size_t n) {
      s.ch('f');
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t v = c[k].vertex + 1;  // OBJ counts from 1; v and vn share the index
        s.ch(' ').uint(v).ch('/').uint(c[k].grid + 1);
        if (normals) s.ch('/').uint(v);
      }
      s.ch('\n');
    });
  });
}

/// Binary STL counts its triangles in 32 bits. Where the cells could hold more (two
/// triangles each), they are counted before anything is written, and too many
/// refused; otherwise write_stl counts what it writes.
void check_stl_triangle_count(const SurfaceMesh& m, const fs::path& path) {
  const Vertices vx(m);
  if (2 * std::uint64_t{cell_count(vx)} <= std::numeric_limits<std::uint32_t>::max()) return;
  const std::uint64_t count = count_faces(vx, true);
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    detail::fail(errc::too_large, "cannot write ", quoted(path), ": ", count,
                 " triangles; binary STL holds at most 4294967295");
  }
}

// The header's triangle count is filled in once the triangles are written.
void write_stl(std::ostream& os, const SurfaceMesh& m) {
  constexpr std::uint64_t triangle_bytes = 50, count_at = 80;
  {
    Sink s(os);
    // Must not start with "solid": readers take that for ASCII STL.
    char header[80];
    std::memset(header, ' ', sizeof header);
    const char title[] = "interpatch binary STL surface mesh";
    std::memcpy(header, title, sizeof title - 1);
    s.text(std::string_view(header, sizeof header));
    s.little(std::uint32_t{0});
    s.flush();
  }
  const Vertices vx(m);
  auto f32 = [](double v) { return static_cast<float>(v); };
  const std::uint64_t bytes = write_records(os, cell_count(vx), 100, [&](Sink& s, std::size_t r) {
    cell_triangles(vx, r, [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n) {
      const Vec3 unit = n / norm(n);
      s.little(f32(unit.x)).little(f32(unit.y)).little(f32(unit.z));
      for (const Vec3* p : {&a, &b, &c}) s.little(f32(p->x)).little(f32(p->y)).little(f32(p->z));
      s.little(std::uint16_t{0});
    });
  });
  os.seekp(static_cast<std::streamoff>(count_at));
  Sink(os).little(static_cast<std::uint32_t>(bytes / triangle_bytes)).flush();
}

void write_ply(std::ostream& os, const SurfaceMesh& m) {
  const Vertices vx(m);
  const std::size_t cols = vx.cols();
  const bool normals = !m.normals.empty();
  const std::uint64_t faces = count_faces(vx, false);
  const bool fits_int = vx.count() <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  {
    Sink s(os);
    s.text("ply\nformat binary_little_endian 1.0\ncomment interpatch surface mesh ")
        .uint(vx.rows())
        .text(" x ")
        .uint(vx.cols())
        .text(", first index along u")
        .text(closed_note(m))
        .text("\nelement vertex ")
        .uint(vx.count())
        .text("\nproperty double x\nproperty double y\nproperty double z\n");
    if (normals) s.text("property double nx\nproperty double ny\nproperty double nz\n");
    s.text("element face ").uint(faces).text("\nproperty list uchar ").text(fits_int ? "int" : "uint").text(" vertex_indices\nend_header\n");
    s.flush();
  }
  write_records(os, vx.count(), normals ? 48 : 24, [&](Sink& s, std::size_t r) {
    const std::size_t i = r / cols, j = r % cols;
    const Vec3& p = m.points(i, j);
    s.little(p.x).little(p.y).little(p.z);
    if (normals) {
      const Vec3& n = m.normals(i, j);
      s.little(n.x).little(n.y).little(n.z);
    }
  });
  write_records(os, cell_count(vx), 17, [&](Sink& s, std::size_t r) {
    cell_face(vx, r, [&](const Corner* c, std::size_t n) {
      s.little(static_cast<std::uint8_t>(n));
      for (std::size_t k = 0; k < n; ++k) {
        if (fits_int) s.little(static_cast<std::int32_t>(c[k].vertex));
        else s.little(static_cast<std::uint32_t>(c[k].vertex));
      }
    });
  });
}

// ---------------------------------------------------------------------------
// Structured-grid formats, shared by surfaces (nw = 1) and volumes.

struct Structured {
  std::size_t nu = 1, nv = 1, nw = 1;
  const Vec3* points = nullptr;   // C order: index (i * nv + j) * nw + k
  const Vec3* vectors = nullptr;  // per-point unit normals, or nullptr
  const double* scalars = nullptr;  // per-point jacobian, or nullptr
  const char* kind = "surface";

  [[nodiscard]] std::size_t size() const noexcept { return nu * nv * nw; }
  /// The C-order index of the point the file holds at place t, i fastest, then j,
  /// then k: the order of VTK and Plot3D files.
  [[nodiscard]] std::size_t at(std::size_t t) const noexcept {
    const std::size_t i = t % nu, rest = t / nu;
    return (i * nv + rest % nv) * nw + rest / nv;
  }

  /// The values of `v` (C order, as `points`; T is Vec3 or double) in the order of
  /// the files, in the given byte order: a line of nu values along i at a time, the
  /// lines made by every thread.
  template <class T>
  void write_lines(std::ostream& os, const T* v, std::endian order) const {
    const std::size_t stride = nv * nw;
    write_records(os, nv * nw, nu * sizeof(T), [&](Sink& s, std::size_t line) {
      s.gather(v + at(line * nu), nu, stride, order);
    });
  }
};

// Legacy VTK: the head before the points, and what stands between the points and
// the point data.
std::string legacy_vtk_head(std::size_t nu, std::size_t nv, std::size_t nw, std::string_view kind) {
  std::string head;
  Sink s(head);
  s.text("# vtk DataFile Version 3.0\ninterpatch ")
      .text(kind)
      .text(" grid\nBINARY\nDATASET STRUCTURED_GRID\nDIMENSIONS ")
      .uint(nu).ch(' ').uint(nv).ch(' ').uint(nw)
      .text("\nPOINTS ").uint(nu * nv * nw).text(" double\n");
  return head;
}

std::string legacy_vtk_point_data(std::size_t size, bool vectors, bool scalars) {
  std::string text = "\n";
  Sink s(text);
  if (vectors || scalars) s.text("POINT_DATA ").uint(size).ch('\n');
  if (vectors) s.text("NORMALS normals double\n");
  return text;
}

void write_legacy_vtk(std::ostream& os, const Structured& g) {
  os << legacy_vtk_head(g.nu, g.nv, g.nw, g.kind);
  g.write_lines(os, g.points, std::endian::big);
  os << legacy_vtk_point_data(g.size(), g.vectors != nullptr, g.scalars != nullptr);
  if (g.vectors) {
    g.write_lines(os, g.vectors, std::endian::big);
    os << '\n';
  }
  if (g.scalars) {
    os << "SCALARS jacobian double 1\nLOOKUP_TABLE default\n";
    g.write_lines(os, g.scalars, std::endian::big);
    os << '\n';
  }
}

/// The XML of a .vts file before its appended data (up to the "_" that opens it)
/// and after it. The arrays are raw appended little-endian data, each preceded by
/// its byte count as UInt64 (header_type), so grids of any size fit: the normals
/// (when there are vectors), the jacobian (scalars), then the points.
std::string vts_head(std::size_t nu, std::size_t nv, std::size_t nw, bool vectors, bool scalars) {
  const std::uint64_t n = std::uint64_t{nu} * nv * nw;
  const std::uint64_t vec_bytes = 24 * n, scal_bytes = 8 * n;
  std::uint64_t offset = 0;
  auto next_offset = [&](std::uint64_t bytes) {
    const std::uint64_t o = offset;
    offset += 8 + bytes;
    return o;
  };
  std::string head;
  Sink s(head);
  auto extent = [&]() { s.text("0 ").uint(nu - 1).text(" 0 ").uint(nv - 1).text(" 0 ").uint(nw - 1); };
  s.text("<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
         "  <StructuredGrid WholeExtent=\"");
  extent();
  s.text("\">\n    <Piece Extent=\"");
  extent();
  s.text("\">\n      <PointData");
  if (vectors) s.text(" Normals=\"Normals\"");
  if (scalars) s.text(" Scalars=\"jacobian\"");
  s.text(">\n");
  if (vectors) {
    s.text("        <DataArray type=\"Float64\" Name=\"Normals\" NumberOfComponents=\"3\" format=\"appended\" offset=\"")
        .uint(next_offset(vec_bytes))
        .text("\"/>\n");
  }
  if (scalars) {
    s.text("        <DataArray type=\"Float64\" Name=\"jacobian\" NumberOfComponents=\"1\" format=\"appended\" offset=\"")
        .uint(next_offset(scal_bytes))
        .text("\"/>\n");
  }
  s.text("      </PointData>\n      <Points>\n"
         "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"")
      .uint(next_offset(vec_bytes))
      .text("\"/>\n      </Points>\n    </Piece>\n  </StructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
  return head;
}

constexpr std::string_view vts_tail = "\n  </AppendedData>\n</VTKFile>\n";

/// An appended array's byte count, as the .vts holds it before the array.
std::string vts_count(std::uint64_t bytes) {
  std::string count;
  Sink(count).little(bytes);
  return count;
}

/// VTK XML StructuredGrid (vts_head), the arrays i fastest.
void write_vts(std::ostream& os, const Structured& g) {
  const std::uint64_t n = g.size();
  os << vts_head(g.nu, g.nv, g.nw, g.vectors != nullptr, g.scalars != nullptr);
  if (g.vectors) {
    os << vts_count(24 * n);
    g.write_lines(os, g.vectors, std::endian::little);
  }
  if (g.scalars) {
    os << vts_count(8 * n);
    g.write_lines(os, g.scalars, std::endian::little);
  }
  os << vts_count(24 * n);
  g.write_lines(os, g.points, std::endian::little);
  os << vts_tail;
}

/// Plot3D's ASCII values, four to a line: value(t) for t < n, i fastest. Each is the
/// shortest text that reads back as the same double: exact, and no longer than 17
/// digits.
template <class Value>
void write_plot3d_values(std::ostream& os, std::size_t n, Value&& value) {
  write_records(os, n, 20, [&](Sink& s, std::size_t t) {
    if (t % 4 != 0) s.ch(' ');
    s.shortest(value(t));
    if (t % 4 == 3 || t + 1 == n) s.ch('\n');
  });
}

/// Plot3D grid file, ASCII, 3D, multi-grid with one grid, whole (not planes): the
/// block count, the dimensions, then every x (i fastest), every y, every z.
void write_plot3d(std::ostream& os, const Structured& g) {
  Sink(os).text("1\n").uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw).ch('\n').flush();
  for (int c = 0; c < 3; ++c) write_plot3d_values(os, g.size(), [&](std::size_t t) { return g.points[g.at(t)][c]; });
}

/// Plot3D function file (multi-grid, ASCII): the block count, "ni nj nk nvars",
/// then the values, i fastest.
void write_plot3d_function(std::ostream& os, const Structured& g) {
  Sink(os).text("1\n").uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw).text(" 1\n").flush();
  write_plot3d_values(os, g.size(), [&](std::size_t t) { return g.scalars[g.at(t)]; });
}

template <std::size_t N>
void check_extension(const fs::path& path, const std::string& ext, const std::array<std::string_view, N>& formats,
                     const char* kind) {
  if (std::find(formats.begin(), formats.end(), ext) != formats.end()) return;
  if (ext.empty()) {
    detail::fail(errc::wrong_type, "cannot write ", quoted(path), ": no extension to choose the ", kind,
                 " mesh format by (supported: ", list(formats), ")");
  }
  if (std::find(surface_formats.begin(), surface_formats.end(), ext) != surface_formats.end()) {
    detail::fail(errc::wrong_type, "cannot write ", quoted(path), ": '", ext, "' holds surfaces, not ", kind,
                 " grids (supported for ", kind, "s: ", list(formats), ")");
  }
  detail::fail(errc::wrong_type, "cannot write ", quoted(path), ": unknown ", kind, " mesh format '", ext,
               "' (supported: ", list(formats), ")");
}

void write_structured(const fs::path& path, const std::string& ext, const Structured& g) {
  if (ext == ".vtk") {
    write_atomically(path, [&](std::ostream& os) { write_legacy_vtk(os, g); });
  } else if (ext == ".vts") {
    write_atomically(path, [&](std::ostream& os) { write_vts(os, g); });
  } else {
    if (g.scalars) {
      // Plot3D grids hold coordinates only; fields go to a function file.
      fs::path function_path = path;
      function_path.replace_extension(".f");
      check_writable(path);
      write_atomically(function_path, [&](std::ostream& os) { write_plot3d_function(os, g); });
    }
    write_atomically(path, [&](std::ostream& os) { write_plot3d(os, g); });
  }
}

/// A mesh closed in u (v) needs two rows (columns) or more, its last one repeating
/// the first.
void check_closed(const fs::path& path, const SurfaceMesh& m) {
  const PointGrid& g = m.points;
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  if (m.closed[0] || m.closed[1])
    for (const Vec3& p : g.values())
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], p[d]);
        hi[d] = std::max(hi[d], p[d]);
      }
  // sample_mesh copies the first row exactly; a surface evaluated at both ends of
  // its period agrees to rounding (~1e-15 of its size). 1e-9 of the bounding-box
  // diagonal takes that and refuses any real gap.
  const double tol = 1e-9 * norm(hi - lo);
  for (const std::size_t a : {0u, 1u}) {
    if (!m.closed[a]) continue;
    const char* dir = a == 0 ? "u" : "v";
    const char* line = a == 0 ? "row" : "column";
    const std::size_t n = g.extent(a), across = g.extent(1 - a);
    if (n < 2) {
      detail::fail(errc::size_mismatch, "cannot write ", quoted(path), ": a mesh closed in ", dir, " needs 2 ", line,
                   "s or more, the last repeating the first; it has ", n);
    }
    for (std::size_t t = 0; t < across; ++t) {
      const Vec3& first = a == 0 ? g(0, t) : g(t, 0);
      const Vec3& last = a == 0 ? g(n - 1, t) : g(t, n - 1);
      if (const double gap = norm(last - first); gap > tol) {
        const std::size_t i = a == 0 ? n - 1 : t, j = a == 0 ? t : n - 1;
        detail::fail(errc::closing_gap, "cannot write ", quoted(path), ": the mesh is closed in ", dir,
                     " but its last ", line, " does not repeat the first: point [", i, "][", j, "] is ", gap,
                     " away from point [", a == 0 ? 0 : i, "][", a == 0 ? j : 0, "] (allowed: ", tol, ")");
      }
    }
  }
}

}  // namespace

bool is_mesh_format(std::string_view extension) noexcept {
  try {
    const std::string ext = normalized(extension);
    return std::find(surface_formats.begin(), surface_formats.end(), ext) != surface_formats.end();
  } catch (...) {
    return false;
  }
}

namespace {

/// Binary STL stores float32: a part far from the origin for its size loses its
/// shape there. Says by how much, when that is over 1e-5 of the mesh's diagonal
/// (1 µm on a 100 mm part).
std::vector<std::string> float32_warnings(const fs::path& path, const PointGrid& g) {
  internal::Box box;
  double moved = 0;
  for (const Vec3& p : g.values()) {
    box.add(p);
    for (int a = 0; a < 3; ++a) moved = std::max(moved, std::abs(p[a] - static_cast<double>(static_cast<float>(p[a]))));
  }
  const double diagonal = box.diagonal();
  if (!(moved > 1e-5 * diagonal)) return {};
  return {detail::cat(quoted(path), " holds float32 coordinates (binary STL has no others): rounding moves its points by up to ",
              moved, diagonal > 0 ? detail::cat(", ", moved / diagonal, " of the mesh's diagonal ", diagonal) : std::string(),
              "; .ply, .obj, .vtk and .vts keep every digit")};
}

}  // namespace

std::vector<std::string> write_surface_mesh(const fs::path& path, const SurfaceMesh& mesh) {
  const std::string ext = lower_extension(path);
  check_extension(path, ext, surface_formats, "surface");
  const PointGrid& g = mesh.points;
  if (g.empty()) {
    detail::fail(errc::size_mismatch, "cannot write ", quoted(path), ": the surface mesh has no points (",
                 g.extent(0), " x ", g.extent(1), ")");
  }
  if (!mesh.normals.empty() && mesh.normals.shape() != g.shape()) {
    detail::fail(errc::size_mismatch, "cannot write ", quoted(path), ": ", mesh.normals.extent(0), " x ",
                 mesh.normals.extent(1), " normals for ", g.extent(0), " x ", g.extent(1), " points");
  }
  check_closed(path, mesh);
  const std::size_t shape[3] = {g.extent(0), g.extent(1), 3};
  internal::require_finite(&g.data()->x, 3 * g.size(), 0, shape, "the points of " + quoted(path));
  if (!mesh.normals.empty())
    internal::require_finite(&mesh.normals.data()->x, 3 * g.size(), 0, shape, "the normals of " + quoted(path));

  if (ext == ".obj") {
    write_atomically(path, [&](std::ostream& os) { write_obj(os, mesh); });
  } else if (ext == ".stl") {
    check_stl_triangle_count(mesh, path);
    write_atomically(path, [&](std::ostream& os) { write_stl(os, mesh); });
    return float32_warnings(path, g);
  } else if (ext == ".ply") {
    write_atomically(path, [&](std::ostream& os) { write_ply(os, mesh); });
  } else {
    Structured s;
    s.nu = g.extent(0);
    s.nv = g.extent(1);
    s.points = g.data();
    s.vectors = mesh.normals.empty() ? nullptr : mesh.normals.data();
    s.kind = "surface";
    write_structured(path, ext, s);
  }
  return {};
}

void write_volume_mesh(const fs::path& path, const PointGrid3& points, const Grid<double, 3>& jacobian) {
  const std::string ext = lower_extension(path);
  check_extension(path, ext, volume_formats, "volume");
  if (points.empty()) {
    detail::fail(errc::size_mismatch, "cannot write ", quoted(path), ": the volume grid has no points (",
                 points.extent(0), " x ", points.extent(1), " x ", points.extent(2), ")");
  }
  if (!jacobian.empty() && jacobian.shape() != points.shape()) {
    detail::fail(errc::size_mismatch, "cannot write ", quoted(path), ": jacobian of shape ", jacobian.extent(0),
                 " x ", jacobian.extent(1), " x ", jacobian.extent(2), " for ", points.extent(0), " x ",
                 points.extent(1), " x ", points.extent(2), " points");
  }
  const std::size_t shape[4] = {points.extent(0), points.extent(1), points.extent(2), 3};
  internal::require_finite(&points.data()->x, 3 * points.size(), 0, shape, "the points of " + quoted(path));
  if (!jacobian.empty())
    internal::require_finite(jacobian.data(), jacobian.size(), 0, std::span(shape).first(3), "the jacobians of " + quoted(path));
  Structured s;
  s.nu = points.extent(0);
  s.nv = points.extent(1);
  s.nw = points.extent(2);
  s.points = points.data();
  s.scalars = jacobian.empty() ? nullptr : jacobian.data();
  s.kind = "volume";
  write_structured(path, ext, s);
}

namespace {

// A direction in which a B-spline surface is periodic and the samples span one
// whole period closes: its last row (column) is its first again.
std::array<bool, 2> closed_directions(const Surface& surface, std::span<const double> us, std::span<const double> vs) {
  std::array<bool, 2> closed = {false, false};
  if (const auto* b = dynamic_cast<const BSplineSurface*>(&surface)) {
    const auto domain = b->domain();
    for (const std::size_t a : {0u, 1u}) {
      const std::span<const double> t = a == 0 ? us : vs;
      const double period = domain[a].second - domain[a].first;
      // Parameters made by linspace over a period end on its ends to an ulp or so.
      closed[a] = b->periodic()[a] && t.size() >= 2 && std::abs(std::abs(t.back() - t.front()) - period) <= 1e-12 * period;
    }
  }
  return closed;
}

/// Where the two arrays of a structured surface file (.vts, .vtk) go, and the
/// bytes that stand around them: what stream_structured writes.
struct ArrayLayout {
  std::uint64_t points_at = 0, normals_at = 0, size = 0;
  std::endian order = std::endian::little;
  std::vector<std::pair<std::uint64_t, std::string>> texts;  // (offset, bytes)
};

/// The layout write_vts gives a surface's points and normals.
ArrayLayout vts_layout(std::size_t nu, std::size_t nv) {
  const std::uint64_t vec_bytes = std::uint64_t{24} * nu * nv;
  std::string head = vts_head(nu, nv, 1, true, false) + vts_count(vec_bytes);
  ArrayLayout l;
  l.normals_at = head.size();
  l.points_at = l.normals_at + vec_bytes + 8;
  l.size = l.points_at + vec_bytes + vts_tail.size();
  l.texts = {{0, std::move(head)}, {l.points_at - 8, vts_count(vec_bytes)}, {l.points_at + vec_bytes, std::string(vts_tail)}};
  return l;
}

/// The layout write_legacy_vtk gives them.
ArrayLayout legacy_vtk_layout(std::size_t nu, std::size_t nv) {
  const std::uint64_t vec_bytes = std::uint64_t{24} * nu * nv;
  std::string head = legacy_vtk_head(nu, nv, 1, "surface"), between = legacy_vtk_point_data(nu * nv, true, false);
  ArrayLayout l;
  l.order = std::endian::big;
  l.points_at = head.size();
  l.normals_at = l.points_at + vec_bytes + between.size();
  l.size = l.normals_at + vec_bytes + 1;
  l.texts = {{0, std::move(head)}, {l.points_at + vec_bytes, std::move(between)}, {l.normals_at + vec_bytes, "\n"}};
  return l;
}

// A .vts or .vtk of a surface's mesh (points and normals) without the mesh in
// memory: blocks of whole columns (v values), each a run of both arrays, i fastest.
// Every thread evaluates a few rows of the block and puts them in the file's order
// while the block before is written at its two places in the file; the bytes are
// those of write_surface_mesh(path, sample_mesh(...)).
static_assert(sizeof(Vec3) == 3 * sizeof(double), "a point is three doubles, written as they are");

void stream_structured(const fs::path& path, const ArrayLayout& layout, const Surface& surface,
                       std::span<const double> us, std::span<const double> vs, const progress_callback& progress) {
  const std::size_t nu = us.size(), nv = vs.size(), n = nu * nv;
  const std::array<bool, 2> closed = closed_directions(surface, us, vs);
  // About 2^15 points a block (1.5 MiB of points and normals), pieces of about 2^11:
  // few fresh pages (write_npy_rows).
  constexpr std::size_t block_points = std::size_t{1} << 15, piece_points = std::size_t{1} << 11;
  const std::size_t block_cols = std::clamp<std::size_t>(block_points / nu, 1, nv);
  const std::size_t piece_rows = std::max<std::size_t>(1, piece_points / block_cols);
  const std::size_t blocks = (nv + block_cols - 1) / block_cols, pieces = (nu + piece_rows - 1) / piece_rows;
  require_memory(4 * block_cols * nu + 2 * nu, sizeof(Vec3), "the blocks of the mesh '" + path.string() + "'");
  // Column j of a block, i fastest; not zeroed (every element is written).
  PointGrid points[2] = {PointGrid({block_cols, nu}, for_overwrite), PointGrid({block_cols, nu}, for_overwrite)};
  PointGrid normals[2] = {PointGrid({block_cols, nu}, for_overwrite), PointGrid({block_cols, nu}, for_overwrite)};
  std::vector<Vec3> first_points, first_normals;  // column 0, for the last of a surface closed in v
  const auto grid = surface.normal_grid(us, vs);  // what depends on u alone or v alone, once
  const auto columns = [&](std::size_t b) { return std::pair(b * block_cols, std::min(block_cols, nv - b * block_cols)); };
  const std::string points_of = "the points of " + quoted(path), normals_of = "the normals of " + quoted(path);
  const auto make = [&](std::size_t b, std::size_t p) {
    const auto [j0, m] = columns(b);
    const std::size_t i0 = p * piece_rows, k = std::min(piece_rows, nu - i0);
    // The piece's rows in the grid's order (not zeroed), then put in the file's.
    const auto P = std::make_unique_for_overwrite<Vec3[]>(k * m), N = std::make_unique_for_overwrite<Vec3[]>(k * m);
    grid->evaluate_into(i0, k, j0, m, std::span(P.get(), k * m), std::span(N.get(), k * m));
    // Points and normals of rows i0.. and columns j0..: named by their place in the mesh.
    for (std::size_t i = 0; i < k; ++i) {
      const std::size_t shape[3] = {nu, nv, 3};
      const std::size_t first = ((i0 + i) * nv + j0) * 3;
      internal::require_finite(&P[i * m].x, 3 * m, first, shape, points_of);
      internal::require_finite(&N[i * m].x, 3 * m, first, shape, normals_of);
    }
    Vec3 *to_p = points[b % 2].data(), *to_n = normals[b % 2].data();
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = 0; j < m; ++j) {
        to_p[j * nu + i0 + i] = P[i * m + j];
        to_n[j * nu + i0 + i] = N[i * m + j];
      }
    // In the file's byte order here, on every thread (the seams are copied as bytes).
    for (std::size_t j = 0; layout.order != std::endian::native && j < m; ++j)
      for (Vec3* a : {to_p, to_n}) to_byte_order(reinterpret_cast<char*>(a + j * nu + i0), k * sizeof(Vec3), layout.order);
  };
  const auto write = [&](std::ostream& os, std::size_t b) {
    const auto [j0, m] = columns(b);
    Vec3 *P = points[b % 2].data(), *N = normals[b % 2].data();
    for (std::size_t j = 0; closed[0] && j < m; ++j) {
      P[j * nu + nu - 1] = P[j * nu];
      N[j * nu + nu - 1] = N[j * nu];
    }
    if (closed[1] && b == 0) {
      first_points.assign(P, P + nu);
      first_normals.assign(N, N + nu);
    }
    if (closed[1] && j0 + m == nv) {
      std::copy(first_points.begin(), first_points.end(), P + (m - 1) * nu);
      std::copy(first_normals.begin(), first_normals.end(), N + (m - 1) * nu);
    }
    os.seekp(static_cast<std::streamoff>(layout.normals_at + std::uint64_t{24} * j0 * nu));
    os.write(reinterpret_cast<const char*>(N), static_cast<std::streamsize>(m * nu * sizeof(Vec3)));
    os.seekp(static_cast<std::streamoff>(layout.points_at + std::uint64_t{24} * j0 * nu));
    os.write(reinterpret_cast<const char*>(P), static_cast<std::streamsize>(m * nu * sizeof(Vec3)));
    if (progress) progress(static_cast<double>(j0 + m) / static_cast<double>(nv));
  };
  write_atomically(path, [&](std::ostream& os) {
    os << layout.texts.front().second;
    detail::pipeline(
        blocks, n >= detail::parallel_min_work / 16, [&](std::size_t) { return pieces; }, make,
        [&](std::size_t b) { write(os, b); });
    for (std::size_t t = 1; t < layout.texts.size(); ++t) {
      os.seekp(static_cast<std::streamoff>(layout.texts[t].first));
      os << layout.texts[t].second;
    }
  }, layout.size);
}

}  // namespace

SurfaceMesh sample_mesh(const Surface& surface, std::span<const double> us, std::span<const double> vs,
                        const progress_callback& progress) {
  const std::size_t nu = us.size(), nv = vs.size();
  SurfaceMesh mesh{PointGrid({nu, nv}, for_overwrite), PointGrid({nu, nv}, for_overwrite), {false, false}};
  surface.evaluate_normals_into(us, vs, std::span<Vec3>(mesh.points.data(), mesh.points.size()),
                                std::span<Vec3>(mesh.normals.data(), mesh.normals.size()), progress);
  // Points and normals of the last row (column) of a closed direction are copied
  // from the first, so that every format sees one seam.
  mesh.closed = closed_directions(surface, us, vs);
  for (std::size_t j = 0; mesh.closed[0] && j < nv; ++j) {
    mesh.points(nu - 1, j) = mesh.points(0, j);
    mesh.normals(nu - 1, j) = mesh.normals(0, j);
  }
  for (std::size_t i = 0; mesh.closed[1] && i < nu; ++i) {
    mesh.points(i, nv - 1) = mesh.points(i, 0);
    mesh.normals(i, nv - 1) = mesh.normals(i, 0);
  }
  return mesh;
}

std::vector<std::string> write_surface_mesh(const fs::path& path, const Surface& surface, std::span<const double> us,
                                            std::span<const double> vs, const progress_callback& progress) {
  const std::string ext = lower_extension(path);
  check_extension(path, ext, surface_formats, "surface");
  if (us.empty() || vs.empty() || (ext != ".vts" && ext != ".vtk"))
    return write_surface_mesh(path, sample_mesh(surface, us, vs, progress));
  stream_structured(path, ext == ".vts" ? vts_layout(us.size(), vs.size()) : legacy_vtk_layout(us.size(), vs.size()),
                    surface, us, vs, progress);
  return {};
}

}  // namespace interpatch::io
