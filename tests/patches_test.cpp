#include "interpatch/patches.hpp"

#include "surface_util.hpp"

namespace interpatch {
namespace {

TEST(Bilinear, TextbookExample6_9) {
  // Rogers & Adams, Mathematical Elements for Computer Graphics, Example 6-9: P00=(0,0,1), P01=(1,1,1), P10=(1,0,0), P11=(0,1,0).
  const auto s = bilinear({0, 0, 1}, {1, 1, 1}, {1, 0, 0}, {0, 1, 0});
  EXPECT_EQ(s.point(0.5, 0.5), (Vec3{0.5, 0.5, 0.5}));
  EXPECT_EQ(s.to_bspline().point(0.5, 0.5), (Vec3{0.5, 0.5, 0.5}));
}

TEST(Bilinear, CornersStraightLinesAndExactForm) {
  auto g = test::rng(60);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 p00 = test::random_point(g), p01 = test::random_point(g), p10 = test::random_point(g),
               p11 = test::random_point(g);
    const auto s = bilinear(p00, p01, p10, p11);
    EXPECT_EQ(s.point(0, 0), p00);
    EXPECT_EQ(s.point(0, 1), p01);
    EXPECT_EQ(s.point(1, 0), p10);
    EXPECT_EQ(s.point(1, 1), p11);
    const auto b = s.to_bspline();
    EXPECT_EQ(b.degree_u(), 1);
    EXPECT_LT(test::max_distance(s, b), 1e-15 * 4);
    for (double v : {0.0, 0.3, 0.9}) {
      // Doubly ruled: every isoparametric line is straight, S_uu = S_vv = 0.
      const auto d = s.derivatives(0.37, v);
      EXPECT_EQ(d.suu, (Vec3{}));
      EXPECT_EQ(d.svv, (Vec3{}));
      EXPECT_LT(distance(s.point(0.25, v), 0.75 * s.point(0, v) + 0.25 * s.point(1, v)), 1e-15 * 4);
    }
  }
}

TEST(Ruled, ReproducesItsCurvesAndConvertsExactly) {
  auto g = test::rng(61);
  for (int trial = 0; trial < 20; ++trial) {
    // Two curves of different degrees and knots: the exact form needs merging.
    const auto s0 = test::random_bspline_surface(g, 2 + trial % 2, 3, 5 + static_cast<std::size_t>(trial % 3), 6);
    const auto s1 = test::random_bspline_surface(g, 3, 2, 7, 4);
    const auto c0 = test::iso_curve(s0, 1, 0.3), c1 = test::iso_curve(s1, 1, 0.6);
    const auto r = ruled(c0, c1);
    for (double u : linspace(0, 1, 17)) {
      EXPECT_LT(distance(r.point(u, 0), c0.point(u)), 1e-15 * 8);
      EXPECT_LT(distance(r.point(u, 1), c1.point(u)), 1e-15 * 8);
      EXPECT_LT(distance(r.point(u, 0.25), 0.75 * c0.point(u) + 0.25 * c1.point(u)), 1e-14);
    }
    // Degree elevation and knot merging: a few ulps times the collocation condition number.
    EXPECT_LT(test::max_distance(r, r.to_bspline()), 1e-12 * 4);
  }
}

TEST(HermitePatch, ReproducesBicubicPolynomialsFromTheirCornerData) {
  auto g = test::rng(62);
  for (int trial = 0; trial < 10; ++trial) {
    Vec3 a[4][4];  // S = Σ a_kl u^k v^l
    for (auto& row : a)
      for (auto& x : row) x = test::random_point(g);
    auto eval = [&](double u, double v, int du, int dv) {
      Vec3 s{};
      for (int k = du; k < 4; ++k)
        for (int l = dv; l < 4; ++l) {
          double c = 1;
          for (int m = 0; m < du; ++m) c *= k - m;
          for (int m = 0; m < dv; ++m) c *= l - m;
          s += c * std::pow(u, k - du) * std::pow(v, l - dv) * a[k][l];
        }
      return s;
    };
    std::array<HermiteCorner, 4> c;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        c[static_cast<std::size_t>(2 * i + j)] = {eval(i, j, 0, 0), eval(i, j, 1, 0), eval(i, j, 0, 1), eval(i, j, 1, 1)};
    const auto s = hermite_patch(c);
    const auto b = s.to_bspline();
    for (double u : linspace(0, 1, 11))
      for (double v : linspace(0, 1, 11)) {
        EXPECT_LT(distance(s.point(u, v), eval(u, v, 0, 0)), 1e-14);
        EXPECT_LT(distance(b.point(u, v), eval(u, v, 0, 0)), 1e-14);
        const auto d = s.derivatives(u, v);
        EXPECT_LT(distance(d.suv, eval(u, v, 1, 1)), 1e-13);
        EXPECT_LT(distance(d.svv, eval(u, v, 0, 2)), 1e-13);
      }
  }
}

TEST(Patches, InvalidInput) {
  EXPECT_ERRC((void)bilinear({0, 0, 0}, {0, NAN, 0}, {}, {}), not_finite, "corner p01");
  std::array<HermiteCorner, 4> c{};
  c[3].duv.z = INFINITY;
  EXPECT_ERRC((void)hermite_patch(c), not_finite, "corner p11 duv");
  const auto s = bilinear({}, {}, {}, {});
  EXPECT_ERRC((void)s.point(1.5, 0), out_of_domain, "(1.5, 0)");
}

}  // namespace
}  // namespace interpatch
