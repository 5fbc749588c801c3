#include "interpatch/bspline_surface.hpp"

#include "interpatch/evaluate.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

KnotVector random_knots(std::mt19937_64& g, int p, int count) {
  std::vector<double> u(static_cast<std::size_t>(p + 1), 0.0), in;
  for (int i = 0; i < count - p - 1; ++i) in.push_back(test::uniform(g, 0.05, 0.95));
  std::sort(in.begin(), in.end());
  u.insert(u.end(), in.begin(), in.end());
  u.insert(u.end(), static_cast<std::size_t>(p + 1), 1.0);
  return KnotVector(p, u);
}

BSplineSurface random_surface(std::mt19937_64& g, int p, int q, int nu, int nv, bool rational) {
  PointGrid cp({static_cast<std::size_t>(nu), static_cast<std::size_t>(nv)});
  Grid<double, 2> w;
  if (rational) w = Grid<double, 2>(cp.shape());
  for (auto& x : cp.values()) x = test::random_point(g, 2);
  if (rational)
    for (auto& x : w.values()) x = test::uniform(g, 0.4, 2.5);
  return BSplineSurface(random_knots(g, p, nu), random_knots(g, q, nv), cp, w);
}

TEST(BSplineSurface, BilinearByHand) {
  PointGrid cp({2, 2});
  cp(0, 0) = {0, 0, 0};
  cp(1, 0) = {1, 0, 0};
  cp(0, 1) = {0, 1, 0};
  cp(1, 1) = {1, 1, 1};
  BSplineSurface s(KnotVector::bezier(1), KnotVector::bezier(1), cp);
  EXPECT_EQ(s.point(0.5, 0.5), (Vec3{0.5, 0.5, 0.25}));
  EXPECT_EQ(s.derivative(0.5, 0.5, 1, 1), (Vec3{0, 0, 1}));
  EXPECT_EQ(s.derivative(0.5, 0.5, 2, 0), (Vec3{0, 0, 0}));
}

TEST(BSplineSurface, PartitionOfUnityReproducesTranslations) {
  // Σ N_i N_j = 1: moving every control point by d moves every surface point by d.
  auto g = test::rng(50);
  for (int trial = 0; trial < 30; ++trial) {
    const auto s = random_surface(g, 1 + trial % 4, 1 + trial % 5, 7, 8, trial % 2 == 0);
    const Vec3 d = test::random_point(g, 10);
    PointGrid moved = s.control_points();
    for (auto& x : moved.values()) x += d;
    const BSplineSurface t(s.knots_u(), s.knots_v(), moved, s.weights());
    for (int k = 0; k < 20; ++k) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1);
      EXPECT_LT(norm(t.point(u, v) - s.point(u, v) - d), 1e-13 * (1 + norm(d)));
    }
  }
}

TEST(BSplineSurface, DerivativesAgreeWithFiniteDifferences) {
  auto g = test::rng(51);
  for (int trial = 0; trial < 40; ++trial) {
    const auto s = random_surface(g, 2 + trial % 3, 2 + trial % 4, 6, 7, trial % 2 == 1);
    for (int k = 0; k < 8; ++k) {
      const double u = test::uniform(g, 0.02, 0.98), v = test::uniform(g, 0.02, 0.98), h = 1e-6;
      const auto d = s.derivatives(u, v);
      const double su_span_ok = s.knots_u().find_span(u - h) == s.knots_u().find_span(u + h);
      const double sv_span_ok = s.knots_v().find_span(v - h) == s.knots_v().find_span(v + h);
      if (!su_span_ok || !sv_span_ok) continue;  // finite differences across a knot are not derivatives
      const Vec3 fu = (s.point(u + h, v) - s.point(u - h, v)) / (2 * h);
      const Vec3 fv = (s.point(u, v + h) - s.point(u, v - h)) / (2 * h);
      const Vec3 fuu = (s.derivative(u + h, v, 1, 0) - s.derivative(u - h, v, 1, 0)) / (2 * h);
      const Vec3 fuv = (s.derivative(u, v + h, 1, 0) - s.derivative(u, v - h, 1, 0)) / (2 * h);
      const Vec3 fvv = (s.derivative(u, v + h, 0, 1) - s.derivative(u, v - h, 0, 1)) / (2 * h);
      // O(h²) truncation with third derivatives up to ~1e4 on short random spans, plus eps/h rounding.
      auto tol = [](const Vec3& x) { return 1e-4 * (1 + norm(x)); };
      EXPECT_LT(norm(d.su - fu), tol(fu));
      EXPECT_LT(norm(d.sv - fv), tol(fv));
      EXPECT_LT(norm(d.suu - fuu), tol(fuu));
      EXPECT_LT(norm(d.suv - fuv), tol(fuv));
      EXPECT_LT(norm(d.svv - fvv), tol(fvv));
    }
  }
}

TEST(BSplineSurface, BatchEvaluationEqualsPointwise) {
  auto g = test::rng(52);
  for (int trial = 0; trial < 12; ++trial) {
    const auto s = random_surface(g, 1 + trial % 5, 1 + (trial + 2) % 4, 9, 6, trial % 3 == 0);
    const auto us = linspace(0, 1, 37), vs = linspace(0, 1, 23);
    const auto grid = s.evaluate(us, vs);
    const auto dgrid = s.evaluate_derivatives(us, vs);
    for (std::size_t i = 0; i < us.size(); ++i)
      for (std::size_t j = 0; j < vs.size(); ++j) {
        const Vec3 x = s.point(us[i], vs[j]);
        const auto d = s.derivatives(us[i], vs[j]);
        // Same sums in a different order (row contraction first): a few ulps.
        const double sc = 1 + norm(x);
        EXPECT_LT(distance(grid(i, j), x), 1e-14 * sc);
        EXPECT_LT(distance(dgrid(i, j).s, x), 1e-14 * sc);
        EXPECT_LT(distance(dgrid(i, j).su, d.su), 1e-12 * (1 + norm(d.su)));
        EXPECT_LT(distance(dgrid(i, j).suv, d.suv), 1e-11 * (1 + norm(d.suv)));
        EXPECT_LT(distance(dgrid(i, j).svv, d.svv), 1e-11 * (1 + norm(d.svv)));
      }
  }
}

TEST(BSplineSurface, RefinementAndElevationKeepTheGeometry) {
  auto g = test::rng(53);
  for (int trial = 0; trial < 16; ++trial) {
    const auto s = random_surface(g, 2 + trial % 3, 1 + trial % 3, 6, 5, trial % 2 == 0);
    const std::vector<double> ku{0.21, 0.5}, kv{0.33};
    const auto r = s.refined(ku, kv);
    const auto e = s.elevated(1, 2);
    EXPECT_EQ(r.control_points().extent(0), 8u);
    EXPECT_EQ(e.degree_u(), s.degree_u() + 1);
    EXPECT_EQ(e.degree_v(), s.degree_v() + 2);
    for (int k = 0; k < 30; ++k) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1);
      const Vec3 x = s.point(u, v);
      EXPECT_LT(distance(r.point(u, v), x), 1e-13 * (1 + norm(x)));  // convex combinations
      EXPECT_LT(distance(e.point(u, v), x), 1e-12 * (1 + norm(x)));  // collocation solve per line
    }
  }
}

TEST(BSplineSurface, InvalidInput) {
  const KnotVector k(1, {0, 0, 1, 1});
  EXPECT_ERRC(BSplineSurface(k, k, PointGrid({3, 2})), size_mismatch, "need 2 x 2 control points, got 3 x 2");
  PointGrid cp({2, 2});
  cp(1, 0).z = NAN;
  EXPECT_ERRC(BSplineSurface(k, k, cp), not_finite, "control point [1][0]");
  EXPECT_ERRC(BSplineSurface(k, k, PointGrid({2, 2}), Grid<double, 2>({2, 2}, 0.0)), invalid_weight, "weight [0][0] is 0");
  const BSplineSurface s(k, k, PointGrid({2, 2}));
  EXPECT_ERRC((void)s.point(0.5, 1.25), out_of_domain, "parameter v = 1.25");
  const std::vector<double> us{0, 2};
  EXPECT_ERRC((void)s.evaluate(us, us), out_of_domain, "parameter u = 2");
  const std::vector<double> many(1u << 20);  // 2^40 points x 24 bytes: refused before allocating
  EXPECT_ERRC((void)s.evaluate(many, many), too_large, "surface evaluation grid");
}

}  // namespace
}  // namespace interpatch
