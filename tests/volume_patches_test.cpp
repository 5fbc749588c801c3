#include "interpatch/volume_patches.hpp"

#include "interpatch/hermite.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

std::array<Vec3, 8> random_corners(std::mt19937_64& g) {
  std::array<Vec3, 8> c;
  for (std::size_t n = 0; n < 8; ++n)
    c[n] = Vec3{static_cast<double>(n >> 2), static_cast<double>((n >> 1) & 1), static_cast<double>(n & 1)} +
           test::random_point(g, 0.3);
  return c;
}

TEST(Trilinear, HeaderExampleIsTheIdentity) {
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) c[static_cast<std::size_t>(n)] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
  const auto cube = trilinear(c);
  EXPECT_LT(distance(cube.point(0.2, 0.3, 0.4), {0.2, 0.3, 0.4}), 1e-16 * 4);  // a few roundings of values < 1
  EXPECT_NEAR(cube.jacobian(0.7, 0.1, 0.9).determinant, 1.0, 1e-15);
}

TEST(Trilinear, CornersStraightLinesFormulaAndExactForm) {
  auto g = test::rng(210);
  for (int trial = 0; trial < 10; ++trial) {
    const auto c = random_corners(g);
    const auto s = trilinear(c);
    for (std::size_t n = 0; n < 8; ++n)
      EXPECT_EQ(s.point(static_cast<double>(n >> 2), static_cast<double>((n >> 1) & 1), static_cast<double>(n & 1)), c[n]);
    for (int k = 0; k < 20; ++k) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1), w = test::uniform(g, 0, 1);
      Vec3 expect{};
      for (std::size_t n = 0; n < 8; ++n)
        expect += ((n >> 2 ? u : 1 - u) * ((n >> 1) & 1 ? v : 1 - v) * (n & 1 ? w : 1 - w)) * c[n];
      EXPECT_LT(distance(s.point(u, v, w), expect), 1e-15 * 16);  // 8 products of size ~2: rounding
      // Every isoparametric line is straight: the midpoint is the mean of the ends.
      EXPECT_LT(distance(s.point(0.5, v, w), 0.5 * (s.point(0, v, w) + s.point(1, v, w))), 1e-15 * 8);
      EXPECT_LT(distance(s.point(u, v, 0.5), 0.5 * (s.point(u, v, 0) + s.point(u, v, 1))), 1e-15 * 8);
      // A trilinear map is linear along each parameter: central differences are exact up to rounding.
      const auto d = s.derivatives(u, v, w);
      const auto f = test::finite_differences(s, u, v, w, 1e-3);
      EXPECT_LT(distance(d.su, f.su), 1e-11);  // rounding 1e-16 × 2 / 1e-3
      EXPECT_LT(distance(d.sw, f.sw), 1e-11);
    }
    const auto b = s.to_bspline();
    EXPECT_EQ(b.degree_u(), 1);
    EXPECT_EQ(b.control_points().shape(), (PointGrid3::shape_type{2, 2, 2}));
    for (std::size_t n = 0; n < 8; ++n) EXPECT_EQ(b.control_points()(n >> 2, (n >> 1) & 1, n & 1), c[n]);
    EXPECT_LT(test::max_distance(s, b), 1e-12 * test::bbox_diagonal(c));
  }
}

TEST(Trilinear, InvalidInput) {
  std::array<Vec3, 8> c{};
  c[5].z = NAN;
  EXPECT_ERRC((void)trilinear(c), not_finite, "corner p101 is");
}


TEST(HermiteVolume, ReproducesTricubicPolynomialsFromTheirOwnCornerData) {
  auto g = test::rng(211);
  for (int trial = 0; trial < 8; ++trial) {
    // One tricubic Bézier volume is a tricubic polynomial; lower degrees are too.
    const auto b = test::random_bspline_volume(g, 3 - trial % 3, 3, 1 + trial % 3, 4 - static_cast<std::size_t>(trial % 3), 4,
                                               2 + static_cast<std::size_t>(trial % 3), 0.4);
    const auto h = hermite_volume(test::frame_of(b));
    const double scale = test::scale_of(b);
    // Sums of 64 products of corner data with cubic functions: rounding only.
    EXPECT_LT(test::max_distance(h, b), 1e-13 * scale);
    for (int k = 0; k < 10; ++k) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1), w = test::uniform(g, 0, 1);
      const auto d = h.derivatives(u, v, w), e = b.derivatives(u, v, w);
      EXPECT_LT(distance(d.su, e.su), 1e-12 * scale);  // derivative data of size ~3 × scale
      EXPECT_LT(distance(d.sw, e.sw), 1e-12 * scale);
    }
  }
}

TEST(HermiteVolume, CornerDataAndHermiteEdges) {
  auto g = test::rng(212);
  std::array<HermiteVolumeCorner, 8> c;
  for (std::size_t n = 0; n < 8; ++n)
    c[n] = {random_corners(g)[n], test::random_point(g), test::random_point(g), test::random_point(g),
            test::random_point(g), test::random_point(g), test::random_point(g), test::random_point(g)};
  const auto h = hermite_volume(c);
  const auto b = h.to_bspline();  // exact: its derivatives of every order are the volume's
  EXPECT_EQ(b.degree_u(), 3);
  EXPECT_EQ(b.control_points().shape(), (PointGrid3::shape_type{4, 4, 4}));  // one tricubic Bézier volume
  EXPECT_LT(test::max_distance(h, b), 1e-12 * 4);  // to_bspline() equals the formula (data of size ~4)
  for (std::size_t n = 0; n < 8; ++n) {
    const double u = static_cast<double>(n >> 2), v = static_cast<double>((n >> 1) & 1), w = static_cast<double>(n & 1);
    const Vec3 data[8] = {c[n].p, c[n].du, c[n].dv, c[n].dw, c[n].duv, c[n].duw, c[n].dvw, c[n].duvw};
    const int orders[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
    for (int k = 0; k < 8; ++k)  // Bézier control points times factors 3, 9, 27: rounding
      EXPECT_LT(distance(b.derivative(u, v, w, orders[k][0], orders[k][1], orders[k][2]), data[k]), 1e-13 * 30)
          << "corner " << n << " kind " << k;
    EXPECT_LT(distance(h.derivatives(u, v, w).su, c[n].du), 1e-14 * 8);
  }
  // Edges are the cubic Hermite curves (cubic Hermite functions I_i0, I_i1): S(u,j,k) = Σ_i S(i,j,k) I_i0(u) + S_u(i,j,k) I_i1(u).
  for (double t : linspace(0, 1, 11))
    for (std::size_t jk = 0; jk < 4; ++jk) {
      const auto a = hermite_basis(t);
      const auto& c0 = c[jk];      // i = 0
      const auto& c1 = c[4 + jk];  // i = 1
      const Vec3 expect = a.a0 * c0.p + a.a1 * c1.p + a.b0 * c0.du + a.b1 * c1.du;
      EXPECT_LT(distance(h.point(t, static_cast<double>(jk >> 1), static_cast<double>(jk & 1)), expect), 1e-15 * 16);
    }
}

TEST(HermiteVolume, OmittedMixedDerivativesAreZero) {
  auto g = test::rng(213);
  std::array<HermiteVolumeCorner, 8> c{};
  const auto p = random_corners(g);
  for (std::size_t n = 0; n < 8; ++n) c[n] = {p[n], test::random_point(g), test::random_point(g), test::random_point(g)};
  const auto b = hermite_volume(c).to_bspline();
  for (std::size_t n = 0; n < 8; ++n) {
    const double u = static_cast<double>(n >> 2), v = static_cast<double>((n >> 1) & 1), w = static_cast<double>(n & 1);
    EXPECT_LT(norm(b.derivative(u, v, w, 1, 1, 0)), 1e-13 * 30);  // Bézier differences × 9: rounding
    EXPECT_LT(norm(b.derivative(u, v, w, 1, 1, 1)), 1e-13 * 30);
    EXPECT_LT(distance(b.point(u, v, w), p[n]), 1e-15 * 4);
  }
  // A constant frame (all derivatives zero) gives the constant volume: Σ α products ≡ 1.
  std::array<HermiteVolumeCorner, 8> k{};
  for (auto& x : k) x.p = {1, -2, 3};
  EXPECT_LT(distance(hermite_volume(k).point(0.3, 0.6, 0.9), {1, -2, 3}), 1e-15 * 8);
}

TEST(HermiteVolume, HeaderExampleIsTheUnitCube) {
  std::array<HermiteVolumeCorner, 8> c{};
  for (int n = 0; n < 8; ++n) {
    auto& x = c[static_cast<std::size_t>(n)];
    x.p = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
    x.du = {1, 0, 0};
    x.dv = {0, 1, 0};
    x.dw = {0, 0, 1};
  }
  const auto s = hermite_volume(c);
  EXPECT_LT(distance(s.point(0.2, 0.3, 0.4), {0.2, 0.3, 0.4}), 1e-15 * 4);  // cubic functions summing to t: rounding
  EXPECT_NEAR(s.jacobian(0.6, 0.1, 0.5).determinant, 1.0, 1e-14);
}

TEST(HermiteVolume, InvalidInput) {
  std::array<HermiteVolumeCorner, 8> c{};
  c[3].duw.y = INFINITY;
  EXPECT_ERRC((void)hermite_volume(c), not_finite, "corner p011 duw is");
}

}  // namespace
}  // namespace interpatch
