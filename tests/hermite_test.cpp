#include "interpatch/hermite.hpp"

#include "test_util.hpp"

namespace interpatch {
namespace {

TEST(Hermite, BasisInterpolatesEndValuesAndSlopes) {
  for (int order = 0; order <= 1; ++order) {
    const auto h0 = hermite_basis(0.0, order), h1 = hermite_basis(1.0, order);
    // Order 0: values (α0, α1, β0, β1) = (1,0,0,0) at 0 and (0,1,0,0) at 1.
    // Order 1: slopes (0,0,1,0) at 0 and (0,0,0,1) at 1.
    EXPECT_EQ(h0.a0, order == 0 ? 1.0 : 0.0);
    EXPECT_EQ(h0.a1, 0.0);
    EXPECT_EQ(h0.b0, order == 1 ? 1.0 : 0.0);
    EXPECT_EQ(h0.b1, 0.0);
    EXPECT_EQ(h1.a0, 0.0);
    EXPECT_EQ(h1.a1, order == 0 ? 1.0 : 0.0);
    EXPECT_EQ(h1.b0, 0.0);
    EXPECT_EQ(h1.b1, order == 1 ? 1.0 : 0.0);
  }
  for (int i = 0; i <= 20; ++i) {
    const double g = i / 20.0;
    const auto h = hermite_basis(g);
    EXPECT_NEAR(h.a0 + h.a1, 1.0, 1e-15);  // partition of unity of the position functions
    // The cubic Hermite functions written out.
    EXPECT_NEAR(h.a0, 1 - 3 * g * g + 2 * g * g * g, 1e-15);
    EXPECT_NEAR(h.b0, g - 2 * g * g + g * g * g, 1e-15);
    EXPECT_NEAR(h.b1, -g * g + g * g * g, 1e-15);
    // Derivatives of every order against finite differences of the order below.
    for (int k = 1; k <= 3; ++k) {
      const double e = 1e-6;
      const auto a = hermite_basis(g + e, k - 1), b = hermite_basis(g - e, k - 1), d = hermite_basis(g, k);
      EXPECT_NEAR(d.a0, (a.a0 - b.a0) / (2 * e), 1e-7);  // cubic: truncation ~e², rounding ~eps/e
      EXPECT_NEAR(d.b1, (a.b1 - b.b1) / (2 * e), 1e-7);
    }
  }
}

TEST(Hermite, CurveMatchesDataAndConvertsExactly) {
  auto g = test::rng(20);
  for (int trial = 0; trial < 40; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 7);
    std::vector<Vec3> p, t;
    std::vector<double> u{0.0};
    for (std::size_t i = 0; i < n; ++i) {
      p.push_back(test::random_point(g));
      t.push_back(test::random_point(g, 3));
      if (i > 0) u.push_back(u.back() + test::uniform(g, 0.1, 1.0));
    }
    const bool given = trial % 2 == 0;
    HermiteCurve c(p, given ? t : std::vector<Vec3>{}, u, trial % 4 == 1 ? TangentRule::bessel : TangentRule::catmull_rom);
    const auto b = c.to_bspline();
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_LT(norm(c.point(u[i]) - p[i]), 1e-14);
      if (given) {
        EXPECT_LT(norm(c.derivative(u[i], 1) - t[i]), 1e-12 * (1 + norm(t[i])));
      }
      EXPECT_LT(norm(b.point(u[i]) - p[i]), 1e-14);
    }
    for (int s = 0; s <= 100; ++s) {
      const double x = u.front() + (u.back() - u.front()) * s / 100.0;
      // Bézier form of the same cubic pieces: agreement to rounding.
      EXPECT_LT(norm(b.point(x) - c.point(x)), 1e-13);
      EXPECT_LT(norm(b.derivative(x, 1) - c.derivative(x, 1)), 1e-11 * (1 + norm(c.derivative(x, 1))));
    }
  }
}

TEST(Hermite, CatmullRomAndBesselTangents) {
  const std::vector<Vec3> p{{0, 0, 0}, {1, 1, 0}, {3, 1, 0}};
  const std::vector<double> u{0, 1, 3};
  HermiteCurve cr(p, {}, u, TangentRule::catmull_rom);
  EXPECT_EQ(cr.tangents()[0], (Vec3{1, 1, 0}));
  EXPECT_EQ(cr.tangents()[1], (Vec3{1, 1.0 / 3, 0}));
  EXPECT_EQ(cr.tangents()[2], (Vec3{1, 0, 0}));
  HermiteCurve be(p, {}, u, TangentRule::bessel);
  // Parabola through the three points, y(t) = t - t²/3... evaluated: y'(0)=4/3, y'(1)=2/3, y'(3)=-2/3.
  EXPECT_NEAR(be.tangents()[0].y, 4.0 / 3, 1e-15);
  EXPECT_NEAR(be.tangents()[1].y, 2.0 / 3, 1e-15);
  EXPECT_NEAR(be.tangents()[2].y, -2.0 / 3, 1e-15);
  EXPECT_NEAR(be.tangents()[1].x, 1.0, 1e-15);  // x(t) = t exactly
}

TEST(Hermite, InvalidInput) {
  EXPECT_ERRC(HermiteCurve({{0, 0, 0}}), too_few_points, "at least 2 points, got 1");
  EXPECT_ERRC(HermiteCurve({{0, 0, 0}, {1, 0, 0}}, {{1, 0, 0}}), size_mismatch, "2 tangents, got 1");
  EXPECT_ERRC(HermiteCurve({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {}, {0, 0.5, 0.5}), non_increasing, "param 2");
  EXPECT_ERRC(HermiteCurve({{0, 0, 0}, {1, INFINITY, 0}}), not_finite, "point 1");
  HermiteCurve c({{0, 0, 0}, {1, 0, 0}});
  EXPECT_ERRC((void)c.point(-0.5), out_of_domain, "-0.5");
}

}  // namespace
}  // namespace interpatch
