#include "interpatch/bspline_volume.hpp"

#include <cmath>

#include "volume_util.hpp"

namespace interpatch {
namespace {

const KnotVector lin(1, {0, 0, 1, 1});

TEST(BSplineVolume, HeaderExample) {
  PointGrid3 cp({2, 2, 2});
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) cp(i, j, k) = {double(i), double(j), double(k) * (1 + i)};
  BSplineVolume b(lin, lin, lin, cp);
  EXPECT_EQ(b.point(0.5, 0.5, 0.5), (Vec3{0.5, 0.5, 0.75}));  // dyadic values: exact
  EXPECT_DOUBLE_EQ(b.jacobian(0.5, 0.5, 0.5).determinant, 1.5);
}

TEST(BSplineVolume, CornersEdgesAndLinearPrecision) {
  // Control points at their Greville abscissae reproduce the identity map (linear
  // precision of B-splines), so every point is its own parameters.
  auto g = test::rng(200);
  for (int trial = 0; trial < 6; ++trial) {
    const int p = 1 + trial % 4, q = 1 + (trial + 1) % 4, r = 1 + (trial + 2) % 4;
    const auto ku = test::random_knots(g, p, 6), kv = test::random_knots(g, q, 5), kw = test::random_knots(g, r, 7);
    const auto gu = ku.greville(), gv = kv.greville(), gw = kw.greville();
    PointGrid3 cp({gu.size(), gv.size(), gw.size()});
    for (std::size_t i = 0; i < gu.size(); ++i)
      for (std::size_t j = 0; j < gv.size(); ++j)
        for (std::size_t k = 0; k < gw.size(); ++k) cp(i, j, k) = {gu[i], gv[j], gw[k]};
    const BSplineVolume b(ku, kv, kw, cp);
    for (int s = 0; s < 50; ++s) {
      const Vec3 x{test::uniform(g, 0, 1), test::uniform(g, 0, 1), test::uniform(g, 0, 1)};
      EXPECT_LT(distance(b.point(x.x, x.y, x.z), x), 1e-15 * 8);  // a few roundings of values <= 1
      const auto j = b.jacobian(x.x, x.y, x.z);
      EXPECT_NEAR(j.determinant, 1.0, 1e-13);  // derivatives carry factors p / span: more rounding
    }
    // Corners are the corner control points, whatever the degrees (clamped knots), up
    // to the rounding of the basis recurrence at the domain's end.
    const auto& c = b.control_points();
    EXPECT_LT(distance(b.point(1, 0, 1), c(gu.size() - 1, 0, gw.size() - 1)), 1e-15 * 2);
  }
}

TEST(BSplineVolume, DerivativesMatchFiniteDifferences) {
  auto g = test::rng(201);
  for (int trial = 0; trial < 8; ++trial) {
    const bool rational = trial % 2 == 1;
    const auto b = test::random_bspline_volume(g, 1 + trial % 3 + 1, 2, 3, 5, 4, 6, 0.3, rational);
    for (int s = 0; s < 20; ++s) {
      const double u = test::uniform(g, 0.05, 0.95), v = test::uniform(g, 0.05, 0.95), w = test::uniform(g, 0.05, 0.95);
      const auto d = b.derivatives(u, v, w);
      const auto f = test::finite_differences(b, u, v, w);
      // Central differences with h = 1e-5: truncation h² |S'''| ~ 1e-10 × 1e3 (knot spans
      // ~0.2, control points ~5 apart), rounding 1e-16 |S| / h ~ 1e-10.
      EXPECT_LT(distance(d.su, f.su), 1e-6 * (1 + norm(d.su)));
      EXPECT_LT(distance(d.sv, f.sv), 1e-6 * (1 + norm(d.sv)));
      EXPECT_LT(distance(d.sw, f.sw), 1e-6 * (1 + norm(d.sw)));
      EXPECT_LT(distance(d.s, b.point(u, v, w)), 1e-15 * 16);  // the same sum in another order
      // The general routine agrees with the first-order one (same sums, other order).
      EXPECT_LT(distance(b.derivative(u, v, w, 1, 0, 0), d.su), 1e-12 * (1 + norm(d.su)));
      EXPECT_LT(distance(b.derivative(u, v, w, 0, 0, 1), d.sw), 1e-12 * (1 + norm(d.sw)));
      // Mixed partials: S_uvw against a central difference of S_uv along w.
      const double h = 1e-5;
      const Vec3 fd = (b.derivative(u, v, w + h, 1, 1, 0) - b.derivative(u, v, w - h, 1, 1, 0)) / (2 * h);
      const Vec3 ex = b.derivative(u, v, w, 1, 1, 1);
      EXPECT_LT(distance(fd, ex), 1e-5 * (1 + norm(ex)));  // as above, one derivative order higher
      // The Jacobian's columns are the partials.
      const auto j = b.jacobian(u, v, w);
      for (int r = 0; r < 3; ++r) {
        EXPECT_EQ(j.matrix[static_cast<std::size_t>(r)][0], d.su[r]);
        EXPECT_EQ(j.matrix[static_cast<std::size_t>(r)][2], d.sw[r]);
      }
    }
  }
}

TEST(BSplineVolume, RationalQuarterAnnulusIsExact) {
  // u: a quarter circle (degree 2, weights 1, √2/2, 1); v: radius 1..2; w: height 0..3.
  const KnotVector arc(2, {0, 0, 0, 1, 1, 1});
  const double s = std::sqrt(0.5);
  PointGrid3 cp({3, 2, 2});
  Grid<double, 3> w({3, 2, 2});
  const Vec3 dir[3] = {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 2; ++j)
      for (std::size_t k = 0; k < 2; ++k) {
        cp(i, j, k) = (1.0 + static_cast<double>(j)) * dir[i] + Vec3{0, 0, 3.0 * static_cast<double>(k)};
        w(i, j, k) = i == 1 ? s : 1.0;
      }
  const BSplineVolume b(arc, lin, lin, cp, w);
  EXPECT_TRUE(b.rational());
  const auto t = linspace(0, 1, 9);
  const auto grid = b.evaluate(t, t, t);
  for (std::size_t i = 0; i < t.size(); ++i)
    for (std::size_t j = 0; j < t.size(); ++j)
      for (std::size_t k = 0; k < t.size(); ++k) {
        const Vec3 p = grid(i, j, k);
        EXPECT_NEAR(std::hypot(p.x, p.y), 1 + t[j], 1e-15 * 4);  // exact conic: rounding only
        EXPECT_NEAR(p.z, 3 * t[k], 1e-15 * 4);
      }
  // S_v is the unit radial direction; S_u is tangent to the circle.
  const auto d = b.derivatives(0.3, 0.4, 0.5);
  EXPECT_NEAR(norm(d.sv), 1.0, 1e-14);
  EXPECT_NEAR(dot(d.su, d.s - Vec3{0, 0, d.s.z}), 0.0, 1e-13);
}

TEST(BSplineVolume, BatchEvaluationEqualsPointwise) {
  auto g = test::rng(202);
  for (int trial = 0; trial < 6; ++trial) {
    const bool rational = trial >= 3;
    const auto b = test::random_bspline_volume(g, 1 + trial % 3, 3, 2 + trial % 2, 6, 5, 7, 0.3, rational);
    // Unsorted, repeated and end parameters.
    std::vector<double> us{0, 1, 0.3, 0.3, 0.999}, vs{0.5, 0, 1}, ws{0.7, 0.1, 0, 1, 0.25, 0.6};
    const double scale = test::scale_of(b);
    const auto pts = b.evaluate(us, vs, ws);
    const auto der = b.evaluate_derivatives(us, vs, ws);
    const auto jac = b.evaluate_jacobians(us, vs, ws);
    ASSERT_EQ(pts.shape(), (PointGrid3::shape_type{5, 3, 6}));
    for (std::size_t i = 0; i < us.size(); ++i)
      for (std::size_t j = 0; j < vs.size(); ++j)
        for (std::size_t k = 0; k < ws.size(); ++k) {
          const auto d = b.derivatives(us[i], vs[j], ws[k]);
          // The contraction sums the same products in another order: rounding only.
          EXPECT_LT(distance(pts(i, j, k), d.s), 1e-14 * scale);
          EXPECT_LT(distance(der(i, j, k).s, d.s), 1e-14 * scale);
          EXPECT_LT(distance(der(i, j, k).su, d.su), 1e-13 * (scale + norm(d.su)));
          EXPECT_LT(distance(der(i, j, k).sv, d.sv), 1e-13 * (scale + norm(d.sv)));
          EXPECT_LT(distance(der(i, j, k).sw, d.sw), 1e-13 * (scale + norm(d.sw)));
          EXPECT_EQ(jac.points(i, j, k), der(i, j, k).s);
          // Points a line at a time in vector lanes (polynomial volumes), without fused
          // multiply-adds: the very sums of the derivative grid.
          EXPECT_EQ(pts(i, j, k), der(i, j, k).s);
          const double det = jacobian(d).determinant;
          EXPECT_NEAR(jac.determinants(i, j, k), det, 1e-12 * (1 + std::abs(det)));
        }
  }
}

TEST(BSplineVolume, LargeBatchUsesBothCoresAndStaysExact) {
  // 64³ points: above the threading threshold, so the parallel path runs (and is
  // checked by the sanitizer build); progress arrives in order and ends at 1.
  auto g = test::rng(203);
  const auto b = test::random_bspline_volume(g, 3, 3, 3, 8, 8, 8);
  const auto t = linspace(0, 1, 64);
  std::vector<double> seen;
  const auto jac = b.evaluate_jacobians(t, t, t, [&](double f) { seen.push_back(f); });
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), 1.0);
  const double scale = test::scale_of(b);
  for (std::size_t i = 0; i < 64; i += 9)
    for (std::size_t j = 0; j < 64; j += 7)
      for (std::size_t k = 0; k < 64; k += 5) {
        EXPECT_LT(distance(jac.points(i, j, k), b.point(t[i], t[j], t[k])), 1e-14 * scale);  // summation order only
        const double det = b.jacobian(t[i], t[j], t[k]).determinant;
        EXPECT_NEAR(jac.determinants(i, j, k), det, 1e-12 * (1 + std::abs(det)));
      }
}

TEST(BSplineVolume, RefinedElevatedMappedKeepTheGeometry) {
  auto g = test::rng(204);
  for (bool rational : {false, true}) {
    const auto b = test::random_bspline_volume(g, 2, 3, 1, 5, 6, 4, 0.3, rational);
    const std::vector<double> ku{0.25, 0.5, 0.5}, kv{0.1}, kw{0.33, 0.66};
    const auto r = b.refined(ku, kv, kw);
    EXPECT_EQ(r.control_points().extent(0), 8u);
    EXPECT_EQ(r.control_points().extent(2), 6u);
    const auto e = b.elevated(1, 0, 2);
    EXPECT_EQ(e.degree_u(), 3);
    EXPECT_EQ(e.degree_w(), 3);
    const auto m = b.mapped(2, 3, -1, 1, 0, 10);
    EXPECT_EQ(m.domain()[1], (std::pair<double, double>{-1, 1}));
    const double scale = test::scale_of(b);
    for (int s = 0; s < 40; ++s) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1), w = test::uniform(g, 0, 1);
      const Vec3 p = b.point(u, v, w);
      EXPECT_LT(distance(r.point(u, v, w), p), 1e-14 * scale);      // knot insertion: convex combinations
      EXPECT_LT(distance(e.point(u, v, w), p), 1e-13 * scale);      // elevation: a banded solve per line
      EXPECT_LT(distance(m.point(2 + u, -1 + 2 * v, 10 * w), p), 1e-14 * scale);  // rounding of the mapped parameters
    }
  }
}

TEST(BSplineVolume, InvalidInput) {
  PointGrid3 cp({2, 2, 2}, Vec3{1, 2, 3});
  EXPECT_ERRC(BSplineVolume(lin, lin, KnotVector(2, {0, 0, 0, 1, 1, 1}), cp), size_mismatch,
              "knots need 2 x 2 x 3 control points, got 2 x 2 x 2");
  EXPECT_ERRC(BSplineVolume(lin, lin, lin, cp, Grid<double, 3>({2, 1, 2}, 1.0)), size_mismatch,
              "need as many weights, got 2 x 1 x 2");
  PointGrid3 bad = cp;
  bad(1, 0, 1).y = NAN;
  EXPECT_ERRC(BSplineVolume(lin, lin, lin, bad), not_finite, "control point [1][0][1]");
  Grid<double, 3> w({2, 2, 2}, 1.0);
  w(0, 1, 0) = -1;
  EXPECT_ERRC(BSplineVolume(lin, lin, lin, cp, w), invalid_weight, "weight [0][1][0] is -1");
  w(0, 1, 0) = INFINITY;
  EXPECT_ERRC(BSplineVolume(lin, lin, lin, cp, w), not_finite, "weight [0][1][0] is inf");
  const BSplineVolume b(lin, lin, lin, cp);
  EXPECT_ERRC((void)b.point(0.5, 0.5, 1.5), out_of_domain, "parameter w = 1.5 is outside the domain [0, 1]");
  EXPECT_ERRC((void)b.derivative(0.5, 0.5, 0.5, 0, 4, 0), invalid_degree, "derivative order (0, 4, 0)");
  const std::vector<double> ok{0, 1}, outside{0.5, -0.1};
  EXPECT_ERRC((void)b.evaluate(ok, outside, ok), out_of_domain, "parameter v = -0.1");
  EXPECT_ERRC((void)b.evaluate_jacobians(outside, ok, ok), out_of_domain, "parameter u = -0.1");
  // 10^18 points: refused before anything is allocated for them.
  const std::vector<double> many(1000000, 0.5);
  EXPECT_ERRC((void)b.evaluate(many, many, many), too_large, "volume evaluation grid 1000000x1000000x1000000");
  EXPECT_ERRC((void)b.elevated(-1, 0, 0), invalid_degree, "cannot elevate by -1");
}

}  // namespace
}  // namespace interpatch
