#include "interpatch/volume.hpp"

#include "interpatch/bspline_volume.hpp"
#include "interpatch/volume_patches.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

TEST(VolumeJacobian, MatrixColumnsAndDeterminant) {
  const VolumeDerivatives d{{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}};
  const auto j = jacobian(d);
  EXPECT_EQ(j.determinant, 24.0);
  EXPECT_EQ(j.matrix[0], (std::array<double, 3>{2, 0, 0}));
  EXPECT_EQ(j.matrix[1], (std::array<double, 3>{0, 3, 0}));
  // Swapping two columns reverses the orientation.
  EXPECT_EQ(jacobian({{}, d.sv, d.su, d.sw}).determinant, -24.0);
  // A shear keeps the volume: det = 1.
  EXPECT_DOUBLE_EQ(jacobian({{}, {1, 0, 0}, {0.7, 1, 0}, {0.2, -0.4, 1}}).determinant, 1.0);
}

// x = f(u), y = v, z = w with f a cubic Bézier function of u whose control values are
// c0..c3: det J = f'(u).
BSplineVolume stretched(const std::array<double, 4>& c) {
  const KnotVector cubic(3, {0, 0, 0, 0, 1, 1, 1, 1}), lin(1, {0, 0, 1, 1});
  PointGrid3 cp({4, 2, 2});
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 2; ++j)
      for (std::size_t k = 0; k < 2; ++k) cp(i, j, k) = {c[i], static_cast<double>(j), static_cast<double>(k)};
  return BSplineVolume(cubic, lin, lin, cp);
}

TEST(VolumeJacobian, InvertedCellsFoundInAFoldedVolumeAndNoneInAGoodOne) {
  // Control values 0, 1/3, 2/3, 1: the identity, det J = 1 everywhere.
  const auto good = inverted_cells(stretched({0, 1.0 / 3, 2.0 / 3, 1}), 11);
  EXPECT_EQ(good.samples, 1331u);
  EXPECT_EQ(good.cells, 1000u);
  EXPECT_EQ(good.inverted_points, 0u);
  EXPECT_EQ(good.inverted_cells, 0u);
  EXPECT_TRUE(good.locations.empty());
  EXPECT_NEAR(good.min_determinant, 1.0, 1e-14);  // rounding of the basis derivatives
  // Control values 0, 1.5, −0.5, 1: f'(u) = 3 (7u² − 7u + 1.5) < 0 for u in (0.311, 0.689):
  // of the 11 layers u = 0, 0.1, .., 1 the three at 0.4, 0.5, 0.6 fold (121 samples
  // each), and the four layers of cells 0.3..0.7 touch them (100 cells each).
  const auto bad = inverted_cells(stretched({0, 1.5, -0.5, 1}), 11, 5);
  EXPECT_EQ(bad.inverted_points, 3u * 121u);
  EXPECT_EQ(bad.inverted_cells, 4u * 100u);
  ASSERT_EQ(bad.locations.size(), 5u);
  EXPECT_NEAR(bad.locations[0][0], 0.4, 1e-15);
  EXPECT_EQ(bad.locations[0][1], 0.0);
  EXPECT_EQ(bad.locations[0][2], 0.0);
  EXPECT_NEAR(bad.locations[4][2], 0.4, 1e-15);  // C order: w fastest
  EXPECT_NEAR(bad.min_determinant, -0.75, 1e-14);  // f'(0.5)
  EXPECT_NEAR(bad.min_at[0], 0.5, 1e-15);
  EXPECT_NEAR(bad.max_determinant, 4.5, 1e-14);  // f'(0) = f'(1) = 3 × 1.5
}

TEST(VolumeJacobian, DegenerateEdgeCountsAsNotPositive) {
  // A prism whose cross-section flattens at one corner: S_u and S_v become parallel
  // along the edge u = 1, v = 1, where det J = 1 − (u + v)/2 vanishes (exactly, in
  // floating point too). Those 3 samples (w = 0, 0.5, 1) count; nothing else does.
  const KnotVector lin(1, {0, 0, 1, 1});
  PointGrid3 cp({2, 2, 2});
  for (std::size_t k = 0; k < 2; ++k) {
    const double z = static_cast<double>(k);
    cp(0, 0, k) = {0, 0, z};
    cp(1, 0, k) = {1, 0, z};
    cp(0, 1, k) = {0, 1, z};
    cp(1, 1, k) = {0.5, 0.5, z};  // on the segment from (1,0) to (0,1): the cell flattens there
  }
  const auto r = inverted_cells(BSplineVolume(lin, lin, lin, cp), 3);
  EXPECT_EQ(r.inverted_points, 3u);
  EXPECT_EQ(r.inverted_cells, 2u);  // of the 2 x 2 x 2 cells, the two in the corner column touch the edge
  EXPECT_EQ(r.locations[0], (std::array<double, 3>{1, 1, 0}));
  EXPECT_EQ(r.min_determinant, 0.0);
}

TEST(VolumeJacobian, SamplesTheVolumesOwnDomain) {
  const auto b = stretched({0, 1.5, -0.5, 1}).mapped(10, 20, 0, 1, -1, 1);
  const auto r = inverted_cells(b, 11);
  EXPECT_EQ(r.inverted_points, 3u * 121u);
  EXPECT_NEAR(r.locations[0][0], 14.0, 1e-13);
  EXPECT_NEAR(r.locations[1][2], -0.8, 1e-13);
}

TEST(VolumeJacobian, HeaderExampleTurnsTheCubeInsideOut) {
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) c[static_cast<std::size_t>(n)] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
  EXPECT_EQ(inverted_cells(trilinear(c), 21).inverted_points, 0u);
  std::swap(c[0], c[7]);
  const InvertedCells r = inverted_cells(trilinear(c), 21);
  EXPECT_GT(r.inverted_points, 0u);
  EXPECT_EQ(r.locations.front(), (std::array<double, 3>{0, 0, 0}));  // det J = −2 at the first corner
  EXPECT_DOUBLE_EQ(r.min_determinant, -2.0);
}

TEST(VolumeJacobian, InvalidInput) {
  EXPECT_ERRC((void)inverted_cells(stretched({0, 1, 2, 3}), 1), too_few_points, "at least 2 samples per direction, got 1");
}

}  // namespace
}  // namespace interpatch
