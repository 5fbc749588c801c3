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

#include "detail/parallel.hpp"
#include "detail/pipeline.hpp"
#include "detail/text.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------
// Output in bounded chunks: text and binary values are gathered in a buffer of
// about a megabyte and handed to the stream, so no file is ever built in memory.

// Native doubles turned in place into the given byte order.
void to_byte_order(char* bytes, std::size_t size, std::endian order) {
  if (order != std::endian::native)
    for (std::size_t d = 0; d < size; d += sizeof(double)) std::reverse(bytes + d, bytes + d + sizeof(double));
}

class Sink {
 public:
  explicit Sink(std::ostream& os) : os_(os) { buf_.reserve(limit + 256); }
  Sink(const Sink&) = delete;
  Sink& operator=(const Sink&) = delete;
  ~Sink() = default;

  void flush() {
    os_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    buf_.clear();
  }

  Sink& text(std::string_view s) {
    buf_ += s;
    maybe_flush();
    return *this;
  }
  Sink& ch(char c) {
    buf_ += c;
    return *this;
  }
  Sink& uint(std::uint64_t v) {
    char b[24];
    const auto r = std::to_chars(b, b + sizeof b, v);
    buf_.append(b, r.ptr);
    return *this;
  }
  /// Shortest text that reads back as the same double.
  Sink& shortest(double v) {
    char b[32];
    const auto r = std::to_chars(b, b + sizeof b, v);
    buf_.append(b, r.ptr);
    return *this;
  }
  /// "%.17g", independent of the locale.
  Sink& digits17(double v) {
    char b[32];
    const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::general, 17);
    buf_.append(b, r.ptr);
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
  void end_record() { maybe_flush(); }
  /// Points, three doubles each, in the given byte order: a run at a time.
  Sink& points(std::span<const Vec3> p, std::endian order) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "a point is three doubles");
    const std::size_t at = buf_.size();
    buf_.append(reinterpret_cast<const char*>(p.data()), p.size() * sizeof(Vec3));
    to_byte_order(buf_.data() + at, buf_.size() - at, order);
    maybe_flush();
    return *this;
  }

 private:
  template <class T>
  Sink& bytes(T v, std::endian order) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (order != std::endian::native) std::reverse(b, b + sizeof(T));
    buf_.append(b, sizeof(T));
    return *this;
  }
  void maybe_flush() {
    if (buf_.size() >= limit) flush();
  }

  static constexpr std::size_t limit = std::size_t{1} << 20;
  std::ostream& os_;
  std::string buf_;
};

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

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
  /// Visits every vertex written, in order, with its row and column.
  template <class F>
  void each(F&& f) const {
    for (std::size_t i = 0; i < rows_; ++i)
      for (std::size_t j = 0; j < cols_; ++j) f(i, j);
  }
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

template <class F>
void for_each_face(const Vertices& v, F&& f) {
  const std::size_t nu = v.grid().extent(0), nv = v.grid().extent(1);
  if (nu < 2 || nv < 2) return;
  Corner c[4];
  for (std::size_t i = 0; i + 1 < nu; ++i)
    for (std::size_t j = 0; j + 1 < nv; ++j)
      if (const std::size_t n = cell_corners(v, i, j, c); n != 0) f(c, n);
}

/// The triangles of a face (a fan from its first corner), skipping those of zero area.
template <class F>
void for_each_triangle(const Vertices& v, F&& f) {
  for_each_face(v, [&](const Corner* c, std::size_t n) {
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

/// " (closed in u and v: ...)" for the formats' comment lines, or nothing.
std::string closed_note(const SurfaceMesh& m) {
  if (!m.closed[0] && !m.closed[1]) return {};
  const char* dirs = m.closed[0] && m.closed[1] ? "u and v" : m.closed[0] ? "u" : "v";
  return std::string(" (closed in ") + dirs + ": the last row of samples is the first, written once)";
}

// ---------------------------------------------------------------------------
// Surface-only formats.

// Vertices, normals and faces share numbers; texture coordinates are one per grid
// point, so that the cells across a seam still run up to u (v) = 1.
void write_obj(std::ostream& os, const SurfaceMesh& m) {
  const PointGrid& g = m.points;
  const Vertices vx(m);
  const std::size_t nu = g.extent(0), nv = g.extent(1);
  const bool normals = !m.normals.empty();
  Sink s(os);
  s.text("# interpatch surface mesh: ").uint(vx.rows()).text(" x ").uint(vx.cols()).text(" vertices, first index along u");
  s.text(closed_note(m)).ch('\n');
  vx.each([&](std::size_t i, std::size_t j) {
    const Vec3& p = g(i, j);
    s.text("v ").shortest(p.x).ch(' ').shortest(p.y).ch(' ').shortest(p.z).ch('\n');
    s.end_record();
  });
  for (std::size_t i = 0; i < nu; ++i) {
    const double u = nu > 1 ? static_cast<double>(i) / static_cast<double>(nu - 1) : 0.0;
    for (std::size_t j = 0; j < nv; ++j) {
      const double v = nv > 1 ? static_cast<double>(j) / static_cast<double>(nv - 1) : 0.0;
      s.text("vt ").shortest(u).ch(' ').shortest(v).ch('\n');
      s.end_record();
    }
  }
  if (normals) {
    vx.each([&](std::size_t i, std::size_t j) {
      const Vec3& n = m.normals(i, j);
      s.text("vn ").shortest(n.x).ch(' ').shortest(n.y).ch(' ').shortest(n.z).ch('\n');
      s.end_record();
    });
  }
  for_each_face(vx, [&](const Corner* c, std::size_t n) {
    s.ch('f');
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t v = c[k].vertex + 1;  // OBJ counts from 1; v and vn share the index
      s.ch(' ').uint(v).ch('/').uint(c[k].grid + 1);
      if (normals) s.ch('/').uint(v);
    }
    s.ch('\n');
    s.end_record();
  });
  s.flush();
}

std::uint32_t stl_triangle_count(const SurfaceMesh& m, const fs::path& path) {
  std::uint64_t count = 0;
  for_each_triangle(Vertices(m), [&](const Vec3&, const Vec3&, const Vec3&, const Vec3&) { ++count; });
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    detail::fail(errc::too_large, "cannot write ", quoted(path), ": ", count,
                 " triangles; binary STL holds at most 4294967295");
  }
  return static_cast<std::uint32_t>(count);
}

void write_stl(std::ostream& os, const SurfaceMesh& m, std::uint32_t triangles) {
  Sink s(os);
  // Must not start with "solid": readers take that for ASCII STL.
  char header[80];
  std::memset(header, ' ', sizeof header);
  const char title[] = "interpatch binary STL surface mesh";
  std::memcpy(header, title, sizeof title - 1);
  s.text(std::string_view(header, sizeof header));
  s.little(triangles);
  auto f32 = [](double v) { return static_cast<float>(v); };
  for_each_triangle(Vertices(m), [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n) {
    const Vec3 unit = n / norm(n);
    s.little(f32(unit.x)).little(f32(unit.y)).little(f32(unit.z));
    for (const Vec3* p : {&a, &b, &c}) s.little(f32(p->x)).little(f32(p->y)).little(f32(p->z));
    s.little(std::uint16_t{0});
    s.end_record();
  });
  s.flush();
}

void write_ply(std::ostream& os, const SurfaceMesh& m) {
  const Vertices vx(m);
  const bool normals = !m.normals.empty();
  std::uint64_t faces = 0;
  for_each_face(vx, [&](const Corner*, std::size_t) { ++faces; });
  const bool fits_int = vx.count() <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());

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
  vx.each([&](std::size_t i, std::size_t j) {
    const Vec3& p = m.points(i, j);
    s.little(p.x).little(p.y).little(p.z);
    if (normals) {
      const Vec3& n = m.normals(i, j);
      s.little(n.x).little(n.y).little(n.z);
    }
    s.end_record();
  });
  for_each_face(vx, [&](const Corner* c, std::size_t n) {
    s.little(static_cast<std::uint8_t>(n));
    for (std::size_t k = 0; k < n; ++k) {
      if (fits_int) s.little(static_cast<std::int32_t>(c[k].vertex));
      else s.little(static_cast<std::uint32_t>(c[k].vertex));
    }
    s.end_record();
  });
  s.flush();
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

  /// Visits the C-order index of every point with i fastest, then j, then k: the
  /// order of VTK and Plot3D files.
  template <class F>
  void each_i_fastest(F&& f) const {
    for (std::size_t k = 0; k < nw; ++k)
      for (std::size_t j = 0; j < nv; ++j)
        for (std::size_t i = 0; i < nu; ++i) f((i * nv + j) * nw + k);
  }

  /// The points of `v` (C order, as `points`) in the order of each_i_fastest, handed
  /// to f a run at a time. A surface's (nw 1) are gathered eight columns at once, so
  /// that the grid is read row after row rather than with a stride of a whole row.
  template <class F>
  void runs_i_fastest(const Vec3* v, F&& f) const {
    if (nw != 1) {
      each_i_fastest([&](std::size_t q) { f(std::span<const Vec3>(v + q, 1)); });
      return;
    }
    constexpr std::size_t columns = 8;
    std::vector<Vec3> t(columns * nu);
    for (std::size_t j0 = 0; j0 < nv; j0 += columns) {
      const std::size_t nc = std::min(columns, nv - j0);
      for (std::size_t i = 0; i < nu; ++i)
        for (std::size_t c = 0; c < nc; ++c) t[c * nu + i] = v[i * nv + j0 + c];
      for (std::size_t c = 0; c < nc; ++c) f(std::span<const Vec3>(t.data() + c * nu, nu));
    }
  }
};

void write_legacy_vtk(std::ostream& os, const Structured& g) {
  Sink s(os);
  s.text("# vtk DataFile Version 3.0\ninterpatch ")
      .text(g.kind)
      .text(" grid\nBINARY\nDATASET STRUCTURED_GRID\nDIMENSIONS ")
      .uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw)
      .text("\nPOINTS ").uint(g.size()).text(" double\n");
  g.runs_i_fastest(g.points, [&](std::span<const Vec3> run) { s.points(run, std::endian::big); });
  s.ch('\n');
  if (g.vectors || g.scalars) s.text("POINT_DATA ").uint(g.size()).ch('\n');
  if (g.vectors) {
    s.text("NORMALS normals double\n");
    g.runs_i_fastest(g.vectors, [&](std::span<const Vec3> run) { s.points(run, std::endian::big); });
    s.ch('\n');
  }
  if (g.scalars) {
    s.text("SCALARS jacobian double 1\nLOOKUP_TABLE default\n");
    g.each_i_fastest([&](std::size_t q) {
      s.big(g.scalars[q]);
      s.end_record();
    });
    s.ch('\n');
  }
  s.flush();
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
  std::ostringstream os;
  Sink s(os);
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
  s.flush();
  return std::move(os).str();
}

constexpr std::string_view vts_tail = "\n  </AppendedData>\n</VTKFile>\n";

/// VTK XML StructuredGrid (vts_head), the arrays i fastest.
void write_vts(std::ostream& os, const Structured& g) {
  const std::uint64_t n = g.size();
  const std::uint64_t vec_bytes = 24 * n, scal_bytes = 8 * n;
  Sink s(os);
  s.text(vts_head(g.nu, g.nv, g.nw, g.vectors != nullptr, g.scalars != nullptr));
  auto vec_array = [&](const Vec3* v) {
    s.little(vec_bytes);
    g.runs_i_fastest(v, [&](std::span<const Vec3> run) { s.points(run, std::endian::little); });
  };
  if (g.vectors) vec_array(g.vectors);
  if (g.scalars) {
    s.little(scal_bytes);
    g.each_i_fastest([&](std::size_t q) {
      s.little(g.scalars[q]);
      s.end_record();
    });
  }
  vec_array(g.points);
  s.text(vts_tail);
  s.flush();
}

/// Plot3D grid file, ASCII, 3D, multi-grid with one grid, whole (not planes): the
/// block count, the dimensions, then every x (i fastest), every y, every z.
void write_plot3d(std::ostream& os, const Structured& g) {
  Sink s(os);
  s.text("1\n").uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw).ch('\n');
  for (int c = 0; c < 3; ++c) {
    std::size_t col = 0;
    g.each_i_fastest([&](std::size_t q) {
      if (col) s.ch(' ');
      s.digits17(g.points[q][c]);
      if (++col == 4) {
        s.ch('\n');
        col = 0;
      }
      s.end_record();
    });
    if (col) s.ch('\n');
  }
  s.flush();
}

/// Plot3D function file (multi-grid, ASCII): the block count, "ni nj nk nvars",
/// then the values, i fastest.
void write_plot3d_function(std::ostream& os, const Structured& g) {
  Sink s(os);
  s.text("1\n").uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw).text(" 1\n");
  std::size_t col = 0;
  g.each_i_fastest([&](std::size_t q) {
    if (col) s.ch(' ');
    s.digits17(g.scalars[q]);
    if (++col == 4) {
      s.ch('\n');
      col = 0;
    }
    s.end_record();
  });
  if (col) s.ch('\n');
  s.flush();
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

void write_surface_mesh(const fs::path& path, const SurfaceMesh& mesh) {
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

  if (ext == ".obj") {
    write_atomically(path, [&](std::ostream& os) { write_obj(os, mesh); });
  } else if (ext == ".stl") {
    const std::uint32_t triangles = stl_triangle_count(mesh, path);
    write_atomically(path, [&](std::ostream& os) { write_stl(os, mesh, triangles); });
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

// Points written little-endian, turned in place first where the machine is not.
void write_little(std::ostream& os, Vec3* p, std::size_t n) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "a point is three doubles");
  auto* bytes = reinterpret_cast<char*>(p);
  to_byte_order(bytes, n * sizeof(Vec3), std::endian::little);
  os.write(bytes, static_cast<std::streamsize>(n * sizeof(Vec3)));
}

// The .vts of a surface's mesh (points and normals) without the mesh in memory:
// blocks of whole columns (v values), each a run of both arrays, i fastest. Every
// thread evaluates a few rows of the block and puts them in the file's order while
// the block before is written at its two places in the file; the bytes are those
// of write_surface_mesh(path, sample_mesh(...)).
void stream_vts(const fs::path& path, const Surface& surface, std::span<const double> us, std::span<const double> vs,
                const progress_callback& progress) {
  const std::size_t nu = us.size(), nv = vs.size(), n = nu * nv;
  const std::array<bool, 2> closed = closed_directions(surface, us, vs);
  const std::string head = vts_head(nu, nv, 1, true, false);
  const std::uint64_t vec_bytes = std::uint64_t{24} * n;
  const std::uint64_t normals_at = head.size() + 8, points_at = normals_at + vec_bytes + 8, tail_at = points_at + vec_bytes;
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
  const auto make = [&](std::size_t b, std::size_t p) {
    const auto [j0, m] = columns(b);
    const std::size_t i0 = p * piece_rows, k = std::min(piece_rows, nu - i0);
    // The piece's rows in the grid's order (not zeroed), then put in the file's.
    const auto P = std::make_unique_for_overwrite<Vec3[]>(k * m), N = std::make_unique_for_overwrite<Vec3[]>(k * m);
    grid->evaluate_into(i0, k, j0, m, std::span(P.get(), k * m), std::span(N.get(), k * m));
    Vec3 *to_p = points[b % 2].data(), *to_n = normals[b % 2].data();
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = 0; j < m; ++j) {
        to_p[j * nu + i0 + i] = P[i * m + j];
        to_n[j * nu + i0 + i] = N[i * m + j];
      }
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
    os.seekp(static_cast<std::streamoff>(normals_at + std::uint64_t{24} * j0 * nu));
    write_little(os, N, m * nu);
    os.seekp(static_cast<std::streamoff>(points_at + std::uint64_t{24} * j0 * nu));
    write_little(os, P, m * nu);
    if (progress) progress(static_cast<double>(j0 + m) / static_cast<double>(nv));
  };
  write_atomically(path, [&](std::ostream& os) {
    Sink s(os);
    s.text(head).little(vec_bytes);
    s.flush();
    detail::pipeline(
        blocks, n >= detail::parallel_min_work / 16, [&](std::size_t) { return pieces; }, make,
        [&](std::size_t b) { write(os, b); });
    os.seekp(static_cast<std::streamoff>(points_at - 8));
    s.little(vec_bytes);
    s.flush();
    os.seekp(static_cast<std::streamoff>(tail_at));
    s.text(vts_tail);
    s.flush();
  }, tail_at + vts_tail.size());
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

void write_surface_mesh(const fs::path& path, const Surface& surface, std::span<const double> us,
                        std::span<const double> vs, const progress_callback& progress) {
  const std::string ext = lower_extension(path);
  check_extension(path, ext, surface_formats, "surface");
  if (ext != ".vts" || us.empty() || vs.empty()) return write_surface_mesh(path, sample_mesh(surface, us, vs, progress));
  stream_vts(path, surface, us, vs, progress);
}

}  // namespace interpatch::io
