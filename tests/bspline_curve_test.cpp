#include "interpatch/bspline_curve.hpp"

#include "test_util.hpp"

namespace interpatch {
namespace {

BSplineCurve random_curve(std::mt19937_64& g, int p, int count, bool rational) {
  std::vector<double> u(static_cast<std::size_t>(p + 1), 0.0);
  std::vector<double> in;
  for (int i = 0; i < count - p - 1; ++i) in.push_back(test::uniform(g, 0.0, 1.0));
  std::sort(in.begin(), in.end());
  u.insert(u.end(), in.begin(), in.end());
  u.insert(u.end(), static_cast<std::size_t>(p + 1), 1.0);
  std::vector<Vec3> cp;
  std::vector<double> w;
  for (int i = 0; i < count; ++i) {
    cp.push_back(test::random_point(g, 2.0));
    if (rational) w.push_back(test::uniform(g, 0.3, 3.0));
  }
  return BSplineCurve(KnotVector(p, u), cp, w);
}

TEST(BSplineCurve, LinearAndQuadraticByHand) {
  BSplineCurve c(KnotVector(2, {0, 0, 0, 1, 1, 1}), {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}});
  EXPECT_EQ(c.point(0.5), (Vec3{1, 1, 0}));
  EXPECT_EQ(c.derivative(0.5, 1), (Vec3{2, 0, 0}));
  EXPECT_EQ(c.derivative(0.5, 2), (Vec3{0, -8, 0}));
  EXPECT_EQ(c.derivative(0.5, 3), (Vec3{0, 0, 0}));
  EXPECT_EQ(c.point(0.0), (Vec3{0, 0, 0}));
  EXPECT_EQ(c.point(1.0), (Vec3{2, 0, 0}));
}

TEST(BSplineCurve, RationalQuarterCircleIsExact) {
  // Quadratic rational arc with middle weight √2/2: every point lies on the unit circle.
  const double h = std::sqrt(0.5);
  BSplineCurve c(KnotVector(2, {0, 0, 0, 1, 1, 1}), {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {1, h, 1});
  for (int i = 0; i <= 50; ++i) {
    const double t = i / 50.0;
    EXPECT_NEAR(norm(c.point(t)), 1.0, 1e-15);
    // The tangent is perpendicular to the radius on a circle.
    EXPECT_NEAR(dot(c.point(t), c.derivative(t, 1)), 0.0, 1e-14);
  }
}

TEST(BSplineCurve, DerivativesAgreeWithFiniteDifferences) {
  auto g = test::rng(10);
  for (int trial = 0; trial < 60; ++trial) {
    const auto c = random_curve(g, 1 + trial % 5, 8, trial % 2 == 1);
    for (int s = 0; s < 10; ++s) {
      const double t = test::uniform(g, 0.02, 0.98);
      const double h = 1e-5;
      const auto d = c.derivatives(t, 2);
      // Central differences are inaccurate across a knot where the curve is only C0/C1.
      const int span = c.knots().find_span(t);
      if (t - h < c.knots()[static_cast<std::size_t>(span)] || t + h > c.knots()[static_cast<std::size_t>(span) + 1])
        continue;
      const Vec3 fd1 = (c.point(t + h) - c.point(t - h)) / (2 * h);
      const Vec3 fd2 = (c.derivative(t + h, 1) - c.derivative(t - h, 1)) / (2 * h);
      // O(h^2) truncation with derivatives of size up to ~1e3 on short spans, plus rounding eps/h.
      EXPECT_LT(norm(d[1] - fd1), 1e-4 * (1 + norm(d[1])));
      EXPECT_LT(norm(d[2] - fd2), 1e-4 * (1 + norm(d[2])));
      EXPECT_EQ(d[0], c.point(t));
    }
  }
}

TEST(BSplineCurve, KnotInsertionAndElevationKeepTheGeometry) {
  auto g = test::rng(11);
  for (int trial = 0; trial < 80; ++trial) {
    const int p = 1 + trial % 5;
    const auto c = random_curve(g, p, p + 1 + trial % 6, trial % 3 == 0);
    const double t0 = test::uniform(g, 0.05, 0.95);
    const auto ins = c.inserted(t0, std::min(p, 2) - (c.knots().multiplicity(t0) > 0 ? 1 : 0));
    const std::vector<double> many{0.1, 0.3, 0.3, 0.77};
    const auto ref = p >= 2 ? c.refined(many) : c;
    const auto el = c.elevated(1 + trial % 2);
    EXPECT_EQ(el.degree(), p + 1 + trial % 2);
    // Each knot's multiplicity grows with the degree: the continuity at every knot stays.
    EXPECT_EQ(el.knots().interior_breaks().size(), c.knots().interior_breaks().size());
    if (!c.knots().interior_breaks().empty()) {
      EXPECT_EQ(el.knots().continuity(), c.knots().continuity());
    }
    for (int s = 0; s <= 40; ++s) {
      const double t = s / 40.0;
      const Vec3 x = c.point(t);
      const double scale = 1 + norm(x);
      EXPECT_LT(norm(ins.point(t) - x), 1e-13 * scale);  // convex combinations only: a few ulps
      EXPECT_LT(norm(ref.point(t) - x), 1e-13 * scale);
      // Elevation solves a banded collocation system: rounding times its small condition number.
      EXPECT_LT(norm(el.point(t) - x), 1e-12 * scale);
    }
  }
}

TEST(BSplineCurve, BoehmInsertionByHand) {
  // Inserting 0.5 into a cubic Bézier splits the control polygon by de Casteljau.
  BSplineCurve c(KnotVector(3, {0, 0, 0, 0, 1, 1, 1, 1}), {{0, 0, 0}, {1, 3, 0}, {3, 3, 0}, {4, 0, 0}});
  const auto d = c.inserted(0.5, 3);
  ASSERT_EQ(d.control_points().size(), 7u);
  EXPECT_EQ(d.control_points()[3], c.point(0.5));
  EXPECT_EQ(d.control_points()[1], (Vec3{0.5, 1.5, 0}));
  EXPECT_EQ(d.knots().values(), (std::vector<double>{0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1}));
}

TEST(BSplineCurve, MappedDomain) {
  auto g = test::rng(12);
  const auto c = random_curve(g, 3, 7, true);
  const auto m = c.mapped(2.0, 5.0);
  EXPECT_EQ(m.domain(), (std::pair<double, double>{2.0, 5.0}));
  for (int s = 0; s <= 10; ++s) {
    const double t = s / 10.0;
    EXPECT_LT(norm(m.point(2.0 + 3.0 * t) - c.point(t)), 1e-14 * (1 + norm(c.point(t))));
    EXPECT_LT(norm(3.0 * m.derivative(2.0 + 3.0 * t, 1) - c.derivative(t, 1)), 1e-12 * (1 + norm(c.derivative(t, 1))));
  }
}

TEST(BSplineCurve, InvalidInput) {
  const KnotVector k(2, {0, 0, 0, 1, 1, 1});
  EXPECT_ERRC(BSplineCurve(k, {{0, 0, 0}, {1, 1, 1}}), size_mismatch, "need 3 control points, got 2");
  EXPECT_ERRC(BSplineCurve(k, {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, {1, 1}), size_mismatch, "3 weights, got 2");
  EXPECT_ERRC(BSplineCurve(k, {{0, 0, 0}, {1, std::nan(""), 1}, {2, 2, 2}}), not_finite, "control point 1");
  EXPECT_ERRC(BSplineCurve(k, {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, {1, -2, 1}), invalid_weight, "weight 1 is -2");
  const BSplineCurve c(k, {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}});
  EXPECT_ERRC((void)c.point(1.5), out_of_domain, "parameter 1.5");
  EXPECT_ERRC((void)c.inserted(1.0), out_of_domain, "open domain");
  EXPECT_ERRC((void)c.inserted(0.5, 3), invalid_knots, "multiplicity 3");
}

}  // namespace
}  // namespace interpatch
