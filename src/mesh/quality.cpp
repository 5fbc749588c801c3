#include "mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "base/text.hpp"

namespace interpatch {
namespace {

using Corners = std::array<Vec3, 8>;
using mesh::HexMesh;
using mesh::PolyMesh;

// Node n of a hexahedron in VTK order sits at (a, b, c) = ((n & 1) ^ ((n >> 1) & 1),
// (n >> 1) & 1, n >> 2); its neighbour across direction `dir`.
constexpr int across(int n, int dir) {
  const int a = (n & 1) ^ ((n >> 1) & 1), b = (n >> 1) & 1, c = n >> 2;
  const int p[3] = {dir == 0 ? 1 - a : a, dir == 1 ? 1 - b : b, dir == 2 ? 1 - c : c};
  return p[2] * 4 + (p[1] ? (p[0] ? 2 : 3) : p[0]);
}
constexpr bool at_plus(int n, int dir) {
  return dir == 0 ? ((n & 1) ^ ((n >> 1) & 1)) != 0 : dir == 1 ? ((n >> 1) & 1) != 0 : (n >> 2) != 0;
}

// A flat corner counts as inverted whatever the sign its rounding takes.
constexpr double flat = 1e-12;

// Running corner-Jacobian figures, before the mesh's orientation is known: the cells
// inverted if it is right-handed (a corner at or below +flat) and if it is left-handed.
struct JacobianPass {
  double min_det = std::numeric_limits<double>::infinity(), max_det = -min_det;
  double sum_det = 0;
  double min_scaled = std::numeric_limits<double>::infinity(), max_scaled = -min_scaled;
  std::size_t cells = 0, inverted_right = 0, inverted_left = 0;
  std::size_t first_right = 0, first_left = 0;

  void add(const Corners& x, std::size_t cell) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int n = 0; n < 8; ++n) {
      Vec3 e[3];
      for (int d = 0; d < 3; ++d)  // edges along +a, +b, +c whichever side the corner is on
        e[d] = at_plus(n, d) ? x[n] - x[across(n, d)] : x[across(n, d)] - x[n];
      const double det = dot(cross(e[0], e[1]), e[2]);
      const double lengths = norm(e[0]) * norm(e[1]) * norm(e[2]);
      const double scaled = lengths > 0 ? det / lengths : 0;
      min_det = std::min(min_det, det);
      max_det = std::max(max_det, det);
      sum_det += det;
      lo = std::min(lo, scaled);
      hi = std::max(hi, scaled);
    }
    min_scaled = std::min(min_scaled, lo);
    max_scaled = std::max(max_scaled, hi);
    if (lo <= flat && inverted_right++ == 0) first_right = cell;
    if (hi >= -flat && inverted_left++ == 0) first_left = cell;
    ++cells;
  }

  void put(MeshQuality& q) const {
    const bool left = sum_det < 0;
    q.cells = cells;
    q.min_det_j = min_det;
    q.max_det_j = max_det;
    q.min_scaled_jacobian = left ? -max_scaled : min_scaled;
    q.inverted_cells = left ? inverted_left : inverted_right;
    q.first_inverted = {q.inverted_cells ? (left ? first_left : first_right) : 0, 0, 0};
  }
};

Corners corners_of(const HexMesh& m, std::size_t c) {
  Corners x;
  for (int n = 0; n < 8; ++n) x[n] = m.points[m.cells[c][n]];
  return x;
}

// Per cell, the mean edge length along its longest direction over its shortest's.
double aspect_ratio(const Corners& x) {
  double mean[3] = {0, 0, 0};
  for (int n = 0; n < 8; ++n)
    for (int d = 0; d < 3; ++d)
      if (!at_plus(n, d)) mean[d] += norm(x[across(n, d)] - x[n]);
  const double lo = std::min({mean[0], mean[1], mean[2]}), hi = std::max({mean[0], mean[1], mean[2]});
  return lo > 0 ? hi / lo : std::numeric_limits<double>::infinity();
}

struct FaceGeometry {
  Vec3 centre, area;
};

// OpenFOAM's face centre and area vector: triangles from each edge to the vertex
// average, the centre their area-weighted centroid.
FaceGeometry face_geometry(const HexMesh& m, const std::array<std::uint32_t, 4>& f) {
  Vec3 mid{};
  for (const std::uint32_t p : f) mid = mid + m.points[p];
  mid = 0.25 * mid;
  Vec3 sum_n{}, sum_ac{};
  double sum_a = 0;
  for (std::size_t e = 0; e < 4; ++e) {
    const Vec3& p = m.points[f[e]];
    const Vec3& q = m.points[f[(e + 1) % 4]];
    const Vec3 n = cross(q - p, mid - p);
    const double a = norm(n);
    sum_n = sum_n + n;
    sum_a += a;
    sum_ac = sum_ac + a * (p + q + mid);
  }
  if (sum_a <= 0) return {mid, Vec3{}};
  return {(1.0 / (3 * sum_a)) * sum_ac, 0.5 * sum_n};
}

// Pyramid-volume-weighted cell centres: the pyramids from each face to the mean of
// the cell's face centres.
std::vector<Vec3> cell_centres(const HexMesh& m, const PolyMesh& faces, const std::vector<FaceGeometry>& g) {
  const std::size_t nc = m.cells.size();
  std::vector<Vec3> estimate(nc, Vec3{}), centre(nc, Vec3{});
  std::vector<double> count(nc, 0), volume(nc, 0);
  const auto each_side = [&](auto&& fn) {
    for (std::size_t f = 0; f < faces.faces.size(); ++f) {
      fn(faces.owner[f], f, 1.0);
      if (f < faces.neighbour.size()) fn(faces.neighbour[f], f, -1.0);
    }
  };
  each_side([&](std::uint32_t c, std::size_t f, double) {
    estimate[c] = estimate[c] + g[f].centre;
    count[c] += 1;
  });
  for (std::size_t c = 0; c < nc; ++c) estimate[c] = (1.0 / count[c]) * estimate[c];
  each_side([&](std::uint32_t c, std::size_t f, double side) {
    const double v = std::max(side * dot(g[f].area, g[f].centre - estimate[c]), 1e-300);
    centre[c] = centre[c] + v * (0.75 * g[f].centre + 0.25 * estimate[c]);
    volume[c] += v;
  });
  for (std::size_t c = 0; c < nc; ++c) centre[c] = (1.0 / volume[c]) * centre[c];
  return centre;
}

constexpr double degrees = 180 / std::numbers::pi;

// OpenFOAM's skewness of a face: the vector from where the line from `from` along d
// crosses the face's plane to the face centre, over the face's extent in that vector's
// direction (at least `floor`).
double skewness(const HexMesh& m, const std::array<std::uint32_t, 4>& f, const FaceGeometry& g, const Vec3& from,
                const Vec3& d, double floor) {
  const Vec3 to_face = g.centre - from;
  const double along = dot(g.area, d);
  const Vec3 sv = to_face - (along != 0 ? dot(g.area, to_face) / along : 0.0) * d;
  const double length = norm(sv);
  if (length == 0) return 0;
  double extent = floor;
  for (const std::uint32_t p : f) extent = std::max(extent, std::abs(dot(sv, m.points[p] - g.centre)) / length);
  return extent > 0 ? length / extent : 0;
}

void face_measures(const HexMesh& m, const PolyMesh& faces, MeshQuality& q) {
  std::vector<FaceGeometry> g(faces.faces.size());
  for (std::size_t f = 0; f < g.size(); ++f) g[f] = face_geometry(m, faces.faces[f]);
  const std::vector<Vec3> centre = cell_centres(m, faces, g);
  double sum_cos = 0;
  for (std::size_t f = 0; f < g.size(); ++f) {
    const Vec3 own = centre[faces.owner[f]];
    const double s = norm(g[f].area);
    if (f < faces.neighbour.size()) {
      const Vec3 d = centre[faces.neighbour[f]] - own;
      const double c = std::clamp(s > 0 && norm(d) > 0 ? dot(d, g[f].area) / (norm(d) * s) : -1.0, -1.0, 1.0);
      q.max_non_orthogonality = std::max(q.max_non_orthogonality, std::acos(c) * degrees);
      sum_cos += c;
      q.max_skewness = std::max(q.max_skewness, skewness(m, faces.faces[f], g[f], own, d, 0.2 * norm(d)));
    } else if (s > 0) {  // d: the cell centre's offset from the face along the normal
      const Vec3 normal = (1.0 / s) * g[f].area;
      const Vec3 d = dot(normal, g[f].centre - own) * normal;
      q.max_skewness = std::max(q.max_skewness, skewness(m, faces.faces[f], g[f], own, d, 0.4 * norm(d)));
    }
  }
  // OpenFOAM's average: the angle of the mean cosine.
  if (!faces.neighbour.empty())
    q.mean_non_orthogonality = std::acos(std::clamp(sum_cos / static_cast<double>(faces.neighbour.size()), -1.0, 1.0)) * degrees;
}

}  // namespace

namespace mesh {

MeshQuality corner_jacobians(const HexMesh& m) {
  JacobianPass pass;
  for (std::size_t c = 0; c < m.cells.size(); ++c) pass.add(corners_of(m, c), c);
  MeshQuality q;
  pass.put(q);
  return q;
}

MeshQuality quality(const HexMesh& m, const PolyMesh& faces) {
  MeshQuality q = corner_jacobians(m);
  for (std::size_t c = 0; c < m.cells.size(); ++c) q.max_aspect_ratio = std::max(q.max_aspect_ratio, aspect_ratio(corners_of(m, c)));
  face_measures(m, faces, q);
  return q;
}

}  // namespace mesh

namespace {

// Cell number -> the nodes (i, j, k) of its first corner, cells in C order.
std::array<std::size_t, 3> cell_nodes(const PointGrid3& nodes, std::size_t cell) {
  const std::size_t nj = nodes.extent(1) - 1, nk = nodes.extent(2) - 1;
  return {cell / (nj * nk), cell / nk % nj, cell % nk};
}

void check_shape(const PointGrid3& nodes) {
  const auto n = nodes.shape();
  if (n[0] < 2 || n[1] < 2 || n[2] < 2)
    detail::fail(errc::size_mismatch, "a hexahedral mesh needs at least 2 nodes along each direction, got ", n[0],
                 " x ", n[1], " x ", n[2]);
}

}  // namespace

MeshQuality corner_jacobians(const PointGrid3& nodes) {
  check_shape(nodes);
  const auto n = nodes.shape();
  JacobianPass pass;
  std::size_t cell = 0;
  for (std::size_t i = 0; i + 1 < n[0]; ++i)
    for (std::size_t j = 0; j + 1 < n[1]; ++j)
      for (std::size_t k = 0; k + 1 < n[2]; ++k, ++cell)
        pass.add({nodes(i, j, k), nodes(i + 1, j, k), nodes(i + 1, j + 1, k), nodes(i, j + 1, k), nodes(i, j, k + 1),
                  nodes(i + 1, j, k + 1), nodes(i + 1, j + 1, k + 1), nodes(i, j + 1, k + 1)},
                 cell);
  MeshQuality q;
  pass.put(q);
  q.first_inverted = cell_nodes(nodes, q.first_inverted[0]);
  return q;
}

MeshQuality mesh_quality(const PointGrid3& nodes) {
  const mesh::HexMesh m = mesh::structured_hex_mesh(nodes);
  MeshQuality q = mesh::quality(m, mesh::poly_mesh(m));
  q.first_inverted = cell_nodes(nodes, q.first_inverted[0]);
  const auto n = nodes.shape();
  for (std::size_t d = 0; d < 3; ++d) {  // the lines along d: every node of the other two directions
    const std::size_t last = n[d] - 1;
    for (std::size_t i = 0; i < (d == 0 ? 1 : n[0]); ++i)
      for (std::size_t j = 0; j < (d == 1 ? 1 : n[1]); ++j)
        for (std::size_t k = 0; k < (d == 2 ? 1 : n[2]); ++k) {
          const auto at = [&](std::size_t s) {
            std::array<std::size_t, 3> x{i, j, k};
            x[d] = s;
            return nodes(x[0], x[1], x[2]);
          };
          q.end_cells[d][0] = std::max(q.end_cells[d][0], norm(at(1) - at(0)));
          q.end_cells[d][1] = std::max(q.end_cells[d][1], norm(at(last) - at(last - 1)));
        }
  }
  return q;
}

}  // namespace interpatch
