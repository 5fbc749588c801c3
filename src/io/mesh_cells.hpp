#pragma once
// The faces the polygon formats (.obj, .ply, .stl) make of a structured surface
// grid: its vertices, less a closing row written once, and the corners of each cell.

#include <cstddef>
#include <cstdint>
#include <string>

#include "base/parallel.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::io::internal::mesh_io {

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
inline std::size_t cell_corners(const Vertices& v, std::size_t i, std::size_t j, Corner out[4]) {
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
inline std::size_t cell_count(const Vertices& v) {
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
inline std::uint64_t count_faces(const Vertices& v, bool count_triangles) {
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
inline std::string closed_note(const SurfaceMesh& m) {
  if (!m.closed[0] && !m.closed[1]) return {};
  const char* dirs = m.closed[0] && m.closed[1] ? "u and v" : m.closed[0] ? "u" : "v";
  return std::string(" (closed in ") + dirs + ": the last row of samples is the first, written once)";
}

}  // namespace interpatch::io::internal::mesh_io
