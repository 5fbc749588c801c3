// Mesh quality: on meshes whose answers are known in closed form (boxes, sheared
// parallelepipeds of random edge vectors), under translation, scaling and mirroring,
// and with a node pushed through its neighbours. The OpenFOAM measures are compared
// with checkMesh itself in tools/check_polymesh.py.

#include "interpatch/mesh_quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "interpatch/error.hpp"

namespace interpatch {
namespace {

PointGrid3 lattice(std::array<std::size_t, 3> n, Vec3 origin, Vec3 a, Vec3 b, Vec3 c) {
  PointGrid3 g(n);
  for (std::size_t i = 0; i < n[0]; ++i)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t k = 0; k < n[2]; ++k)
        g(i, j, k) = origin + static_cast<double>(i) * a + static_cast<double>(j) * b + static_cast<double>(k) * c;
  return g;
}

double angle_deg(Vec3 x, Vec3 y) {
  return std::acos(std::clamp(dot(x, y) / (norm(x) * norm(y)), -1.0, 1.0)) * 180 / std::numbers::pi;
}

TEST(MeshQuality, BoxOfUnevenSpacings) {
  const MeshQuality q = mesh_quality(lattice({5, 4, 3}, {1, 2, 3}, {0.5, 0, 0}, {0, 0.25, 0}, {0, 0, 2}));
  EXPECT_EQ(q.cells, 4u * 3u * 2u);
  // Every corner spans the three spacings: their product, to rounding.
  EXPECT_NEAR(q.min_det_j, 0.25, 1e-15);
  EXPECT_NEAR(q.max_det_j, 0.25, 1e-15);
  EXPECT_NEAR(q.min_scaled_jacobian, 1, 1e-15);
  EXPECT_EQ(q.inverted_cells, 0u);
  EXPECT_NEAR(q.max_non_orthogonality, 0, 1e-6);  // acos near 1 magnifies rounding to ~1e-7 degrees
  EXPECT_NEAR(q.mean_non_orthogonality, 0, 1e-6);
  EXPECT_NEAR(q.max_skewness, 0, 1e-12);
  EXPECT_NEAR(q.max_aspect_ratio, 8, 1e-12);  // 2 over 0.25
  EXPECT_NEAR(q.end_cells[0][0], 0.5, 1e-15);
  EXPECT_NEAR(q.end_cells[1][1], 0.25, 1e-15);
  EXPECT_NEAR(q.end_cells[2][0], 2, 1e-15);
}

// A lattice of parallelepipeds: every corner's det J is a . (b x c), every face inside
// is crossed by its centres' line at its centre (no skewness there), and the
// non-orthogonality of the faces across a is the angle between a and b x c (likewise
// for b and c). On a boundary face across a, the cell centre is a / 2 inside: OpenFOAM's
// skewness is the part of a / 2 along the face over the face's half-extent that way.
double boundary_skewness(Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 s = cross(b, c);
  const Vec3 n = (1 / norm(s)) * s;
  const Vec3 to_face = 0.5 * a, along = dot(n, to_face) * n, sv = to_face - along;
  if (norm(sv) == 0) return 0;
  const Vec3 hat = (1 / norm(sv)) * sv;
  const double extent = std::max({0.4 * norm(along), std::abs(dot(hat, 0.5 * (b + c))), std::abs(dot(hat, 0.5 * (b - c)))});
  return norm(sv) / extent;
}

TEST(MeshQuality, ShearedLatticesOfRandomEdges) {
  std::mt19937_64 rng(20261130);
  std::uniform_real_distribution<double> r(-0.4, 0.4), len(0.2, 3);
  for (int trial = 0; trial < 60; ++trial) {
    Vec3 e[3];
    for (int d = 0; d < 3; ++d) {
      Vec3 x{0, 0, 0};
      (d == 0 ? x.x : d == 1 ? x.y : x.z) = 1;
      e[d] = len(rng) * (x + Vec3{r(rng), r(rng), r(rng)});
    }
    const bool mirror = trial % 2 == 1;
    if (mirror) std::swap(e[0], e[1]);  // left-handed: det J negative, nothing inverted
    const std::array<std::size_t, 3> n{3 + static_cast<std::size_t>(trial % 3), 4, 3};
    const MeshQuality q = mesh_quality(lattice(n, {r(rng) * 100, r(rng), 5}, e[0], e[1], e[2]));
    const double det = dot(e[0], cross(e[1], e[2]));
    EXPECT_EQ(det < 0, mirror) << trial;
    // Differences of coordinates near 100 carry rounding of 100 * 2^-52 into each edge.
    const double tol = 1e-11 * std::abs(det) / std::min({norm(e[0]), norm(e[1]), norm(e[2])});
    EXPECT_NEAR(q.min_det_j, det, tol) << trial;
    EXPECT_NEAR(q.max_det_j, det, tol) << trial;
    EXPECT_NEAR(q.min_scaled_jacobian, std::abs(det) / (norm(e[0]) * norm(e[1]) * norm(e[2])), 1e-9) << trial;
    EXPECT_EQ(q.inverted_cells, 0u) << trial;
    double expected = 0, skew = 0;
    for (int d = 0; d < 3; ++d) {
      const Vec3 s = cross(e[(d + 1) % 3], e[(d + 2) % 3]);
      expected = std::max(expected, std::min(angle_deg(e[d], s), angle_deg(e[d], -1.0 * s)));
      skew = std::max(skew, boundary_skewness(e[d], e[(d + 1) % 3], e[(d + 2) % 3]));
    }
    EXPECT_NEAR(q.max_non_orthogonality, expected, 1e-6) << trial;  // acos's rounding near 0 and 180
    EXPECT_NEAR(q.max_skewness, skew, 1e-9) << trial;
    double mean[3];
    for (int d = 0; d < 3; ++d) mean[d] = norm(e[d]);
    EXPECT_NEAR(q.max_aspect_ratio, *std::max_element(mean, mean + 3) / *std::min_element(mean, mean + 3), 1e-9)
        << trial;
  }
}

PointGrid3 wavy(double scale, Vec3 shift) {
  PointGrid3 g({7, 6, 5});
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = 0; j < 6; ++j)
      for (std::size_t k = 0; k < 5; ++k) {
        const double u = static_cast<double>(i) / 6, v = static_cast<double>(j) / 5, w = static_cast<double>(k) / 4;
        g(i, j, k) = shift + scale * Vec3{u + 0.1 * std::sin(3 * v + w), v + 0.15 * u * u, w + 0.1 * std::cos(2 * u)};
      }
  return g;
}

TEST(MeshQuality, InvariantUnderTranslationAndScaling) {
  const MeshQuality a = mesh_quality(wavy(1, {0, 0, 0}));
  const MeshQuality b = mesh_quality(wavy(1e3, {5e4, -2e4, 1e4}));
  EXPECT_GT(a.max_non_orthogonality, 1);  // the test means something: the mesh is skewed
  EXPECT_GT(a.max_skewness, 0.01);
  // Rounding of coordinates near 5e4 over cells of about 150: 5e4 * 2^-52 / 150.
  EXPECT_NEAR(b.max_non_orthogonality, a.max_non_orthogonality, 1e-8);
  EXPECT_NEAR(b.mean_non_orthogonality, a.mean_non_orthogonality, 1e-8);
  EXPECT_NEAR(b.max_skewness, a.max_skewness, 1e-9);
  EXPECT_NEAR(b.max_aspect_ratio, a.max_aspect_ratio, 1e-9);
  EXPECT_NEAR(b.min_scaled_jacobian, a.min_scaled_jacobian, 1e-9);
  EXPECT_NEAR(b.min_det_j, 1e9 * a.min_det_j, 1e-9 * 1e9 * a.max_det_j);
  EXPECT_NEAR(b.end_cells[1][0], 1e3 * a.end_cells[1][0], 1e-9 * 1e3);
}

TEST(MeshQuality, NodePushedThroughItsNeighbours) {
  PointGrid3 g = lattice({6, 5, 4}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1});
  g(2, 2, 1) = {3.6, 2, 1};  // past its +u neighbour at x = 3: the cells beside it fold
  const MeshQuality q = mesh_quality(g);
  EXPECT_GT(q.inverted_cells, 0u);
  EXPECT_LT(q.min_scaled_jacobian, 0);
  EXPECT_LT(q.min_det_j, 0);
  // The first inverted cell in C order has node (2, 2, 1) among its corners.
  for (std::size_t d = 0; d < 3; ++d) {
    const std::size_t node = d == 2 ? 1 : 2;
    EXPECT_TRUE(q.first_inverted[d] == node || q.first_inverted[d] + 1 == node) << d << " " << q.first_inverted[d];
  }
  const MeshQuality only = corner_jacobians(g);
  EXPECT_EQ(only.inverted_cells, q.inverted_cells);
  EXPECT_EQ(only.first_inverted, q.first_inverted);
  EXPECT_EQ(only.min_det_j, q.min_det_j);
  // Mirrored, the same cells are inverted against the left-handed rest.
  for (std::size_t i = 0; i < g.size(); ++i) g.data()[i].x = -g.data()[i].x;
  EXPECT_EQ(corner_jacobians(g).inverted_cells, q.inverted_cells);
}

TEST(MeshQuality, RefusesFewerThanTwoNodes) {
  EXPECT_THROW((void)mesh_quality(PointGrid3({1, 4, 4})), error);
  EXPECT_THROW((void)corner_jacobians(PointGrid3({4, 4, 1})), error);
}

}  // namespace
}  // namespace interpatch
