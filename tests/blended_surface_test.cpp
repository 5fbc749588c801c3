#include "interpatch/blended_surface.hpp"

#include <numbers>

#include "base/parallel.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/network.hpp"
#include "interpatch/patches.hpp"
#include "surface_util.hpp"
#include "thread_util.hpp"

namespace interpatch {
namespace {

// The blended form r(u,v) = Σ c_k(u,v) r_k with c_k(u_l, v_l) = δ_kl and Σ c_k ≡ 1. For
// constructions from curves the "data" r_k are whole curves; both properties are
// checked through linearity in the data.

BSplineCurve scaled(const BSplineCurve& c, double s, const Vec3& shift = {}) {
  auto cp = c.control_points();
  for (auto& x : cp) x = s * x + shift;
  return BSplineCurve(c.knots(), cp);
}

TEST(BlendedSurface, BlendValues) {
  EXPECT_EQ(Blend::linear()(0.25), 0.25);
  EXPECT_NEAR(Blend::hermite()(0.25), 3 * 0.0625 - 2 * 0.015625, 1e-16);
  EXPECT_NEAR(Blend::hermite().derivative(0.0, 1), 0.0, 1e-16);  // zero slopes: C1 networks
  EXPECT_NEAR(Blend::hermite().derivative(1.0, 1), 0.0, 1e-16);
  EXPECT_TRUE(Blend::hermite().is_spline());
}

TEST(BlendedSurface, NetworkCardinalFunctionsAreDeltas) {
  // Every curve zero except v_curves[k], a bump that vanishes at the node parameters:
  // the surface is that bump along u = u_k and zero along every other network line.
  // Closed in u, the same with periodic cardinal functions over 0 = u_0 < ... < u_n <
  // 1, and u = 1 is u_0 again; the zero u_curves' ends meet: closed with a C0 seam.
  const BSplineCurve zero(KnotVector::bezier(1), {{0, 0, 0}, {0, 0, 0}});
  // Cubic through (0,0), (0.4, 0) and (1, 0) with a non-zero middle: t (t − 0.4)(t − 1) · (1,2,3).
  auto bump_at = [](double t) { return (t * (t - 0.4) * (t - 1)) * Vec3{1, 2, 3}; };
  std::vector<Vec3> samples;
  for (int k = 0; k < 4; ++k) samples.push_back(bump_at(k / 3.0));
  CurveInterpolationOptions o;
  o.params = {0, 1.0 / 3, 2.0 / 3, 1};
  const BSplineCurve bump = interpolate_curve(samples, o).curve;  // the cubic itself
  for (const bool closed : {false, true}) {
    const std::vector<double> tu{0, 0.3, 0.65, closed ? 0.8 : 1.0}, tv{0, 0.4, 1};
    for (auto method : {NetworkMethod::coons_linear, NetworkMethod::coons_hermite, NetworkMethod::gordon})
      for (std::size_t k = 0; k < tu.size(); ++k) {
        CurveNetwork n{std::vector<BSplineCurve>(tv.size(), zero), std::vector<BSplineCurve>(tu.size(), zero), tu, tv,
                       {closed, false}};
        n.v_curves[k] = bump;
        const auto s = curve_network(n, {method, {}, {}});
        for (double t : linspace(0, 1, 11)) {
          for (std::size_t i = 0; i < tu.size(); ++i)
            EXPECT_LT(distance(s.point(tu[i], t), i == k ? bump_at(t) : Vec3{}), 1e-15 * 16);
          if (closed) {
            EXPECT_LT(distance(s.point(1.0, t), k == 0 ? bump_at(t) : Vec3{}), 1e-15 * 16);
          }
          for (double v : tv) EXPECT_LT(norm(s.point(t, v)), 1e-15 * 16);
        }
      }
  }
}

TEST(BlendedSurface, TranslatingTheDataTranslatesTheSurface) {
  auto g = test::rng(90);
  const auto src = test::random_bspline_surface(g, 3, 3, 6, 6);
  const std::vector<double> tu{0, 0.5, 1}, tv{0, 0.3, 0.7, 1};
  CurveNetwork n, m;
  const Vec3 d{5, -1, 0.5};
  for (double v : tv) n.u_curves.push_back(test::iso_curve(src, 1, v));
  for (double u : tu) n.v_curves.push_back(test::iso_curve(src, 0, u));
  for (const auto& c : n.u_curves) m.u_curves.push_back(scaled(c, 1, d));
  for (const auto& c : n.v_curves) m.v_curves.push_back(scaled(c, 1, d));
  n.u_params = m.u_params = tu;
  n.v_params = m.v_params = tv;
  for (auto method : {NetworkMethod::coons_linear, NetworkMethod::coons_hermite, NetworkMethod::gordon}) {
    const auto a = curve_network(n, {method, {}, {}}), b = curve_network(m, {method, {}, {}});
    for (double u : linspace(0, 1, 9))
      for (double v : linspace(0, 1, 9)) EXPECT_LT(distance(b.point(u, v) - d, a.point(u, v)), 1e-13);
  }
  const Vec3 p[4] = {test::random_point(g), test::random_point(g), test::random_point(g), test::random_point(g)};
  const auto bl = bilinear(p[0], p[1], p[2], p[3]), bt = bilinear(p[0] + d, p[1] + d, p[2] + d, p[3] + d);
  std::array<HermiteCorner, 4> hc, ht;
  for (std::size_t k = 0; k < 4; ++k) {
    hc[k] = {p[k], test::random_point(g), test::random_point(g), test::random_point(g)};
    ht[k] = hc[k];
    ht[k].p += d;  // only positions move; derivatives of a translated surface are the same
  }
  const auto h0 = hermite_patch(hc), h1 = hermite_patch(ht);
  for (double u : linspace(0, 1, 9))
    for (double v : linspace(0, 1, 9)) {
      EXPECT_LT(distance(bt.point(u, v) - d, bl.point(u, v)), 1e-14 * 8);
      EXPECT_LT(distance(h1.point(u, v) - d, h0.point(u, v)), 1e-14 * 8);
    }
}

// The batch path evaluates each function once per parameter and sums products; the
// pointwise path (derivatives) sums the same terms per point. Both must agree for
// every kind of blended construction, at parameters that are not grid-aligned.
TEST(BlendedSurface, BatchEvaluationMatchesPointwise) {
  auto g = test::rng(91);
  for (int trial = 0; trial < 6; ++trial) {
    const auto src = test::random_bspline_surface(g, 3, 3, 7, 6);
    const std::vector<double> tu{0, 0.35, 0.6, 1}, tv{0, 0.5, 1};
    CurveNetwork n;
    for (double v : tv) n.u_curves.push_back(test::iso_curve(src, 1, v));
    for (double u : tu) n.v_curves.push_back(test::iso_curve(src, 0, u));
    n.u_params = tu;
    n.v_params = tv;
    const CoonsBoundary b{test::iso_curve(src, 1, 0), test::iso_curve(src, 1, 1), test::iso_curve(src, 0, 0),
                          test::iso_curve(src, 0, 1)};
    const CoonsCrossDerivatives cross{test::iso_curve(src, 1, 0, 1), test::iso_curve(src, 1, 1, 1),
                                      test::iso_curve(src, 0, 0, 1), test::iso_curve(src, 0, 1, 1)};
    CoonsOptions hermite, callable;
    hermite.blend_u = hermite.blend_v = Blend::hermite();
    callable.blend_u = Blend([](double t, int k) { return k == 0 ? t * t : (k == 1 ? 2 * t : 2.0); });
    HermiteCoonsOptions gregory;
    gregory.twist_correction = TwistCorrection::gregory;
    gregory.twists[0] = Vec3{1, 2, 3};  // disagrees with the curves: Gregory's terms are active
    const std::vector<BlendedSurface> surfaces{
        coons(b), coons(b, hermite), coons(b, callable), coons(b, cross), coons(b, cross, gregory),
        ruled(b.v0, b.v1), curve_network(n, {NetworkMethod::coons_linear, {}, {}}),
        curve_network(n, {NetworkMethod::coons_hermite, {}, {}}), curve_network(n, {NetworkMethod::gordon, {}, {}})};
    std::vector<double> us = linspace(0, 1, 23), vs = linspace(0, 1, 17);
    for (auto& u : us) u = u * u;  // uneven spacing, ends kept
    for (const auto& s : surfaces) {
      const PointGrid grid = s.evaluate(us, vs);
      ASSERT_EQ(grid.extent(0), us.size());
      ASSERT_EQ(grid.extent(1), vs.size());
      double worst = 0;
      for (std::size_t i = 0; i < us.size(); ++i)
        for (std::size_t j = 0; j < vs.size(); ++j)
          worst = std::max(worst, distance(grid(i, j), s.derivatives(us[i], vs[j]).s));
      // Both sum the same few products of values of size ~1 in another order: a few ulps.
      EXPECT_LT(worst, 1e-13) << "trial " << trial;
    }
  }
}

// Constructions whose control nets are large enough to be filled by every thread
// (net size times terms a point above detail::parallel_min_work; the terms are 2 + 2
// for the Coons patch, 7 + 5 for the networks): boundary curves on different knots
// and degrees so that the conversion merges and elevates, and a C1 network whose
// blends of v vanish over most of each row, rows of 700 points, so that their
// supports begin and end inside the stretches rows are summed by.
std::vector<std::pair<BlendedSurface, std::size_t>> large_blended_surfaces() {
  auto g = test::rng(92);
  const auto src = test::random_bspline_surface(g, 3, 3, 200, 700);
  auto b = test::boundary_of(src);
  std::vector<double> extra(200);
  for (auto& t : extra) t = test::uniform(g, 0.01, 0.99);
  b.v1 = b.v1.refined(extra);
  b.u0 = b.u0.elevated(1);
  const auto net = test::network_on(src, linspace(0, 1, 7), {0, 0.2, 0.45, 0.7, 1});
  return {{coons(b), 4},
          {curve_network(net, {NetworkMethod::gordon, {}, {}}), 12},
          {curve_network(net, {NetworkMethod::coons_hermite, {}, {}}), 12}};
}

TEST(BlendedSurface, LargeExactFormsEqualTheFormula) {
  auto g = test::rng(93);
  for (const auto& [s, terms] : large_blended_surfaces()) {
    const BSplineSurface b = s.to_bspline();
    ASSERT_GE(b.control_points().size() * terms, detail::parallel_min_work);
    // The data are of size ~700 (random_bspline_surface puts control point (i, j) near
    // (i, j, 0)). The net sums its terms in another order than the formula, after knot
    // insertions (convex combinations) and an elevation (a collocation solve): a few
    // ulps of the data, far below 1e-12 of them.
    const double scale = test::bbox_diagonal(b.control_points().values());
    for (int k = 0; k < 300; ++k) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1);
      EXPECT_LT(distance(b.point(u, v), s.point(u, v)), 1e-12 * scale) << "at (" << u << ", " << v << ")";
    }
  }
}

#ifdef _OPENMP
// Each control point is summed by one thread in one order.
TEST(BlendedSurface, LargeExactFormsDoNotDependOnTheThreadCount) {
  test::expect_exact_forms_independent_of_threads(large_blended_surfaces());
}
#endif

TEST(BlendedSurface, BatchEvaluationRefusesParametersOutsideTheDomain) {
  const auto s = coons(CoonsBoundary{line({0, 0, 0}, {1, 0, 0}), line({0, 1, 0}, {1, 1, 1}), line({0, 0, 0}, {0, 1, 0}),
                                     line({1, 0, 0}, {1, 1, 1})});
  const std::vector<double> good{0, 0.5, 1}, bad{0, 1.5};
  EXPECT_ERRC((void)s.evaluate(bad, good), out_of_domain, "parameter u = 1.5");
  EXPECT_ERRC((void)s.evaluate(good, bad), out_of_domain, "parameter v = 1.5");
}

// Sections collapsed to points on one curve C(v), every line that curve: S(u, v) =
// C(v) Σ φ_i(u) + Σ_j C(v_j) ψ_j(v) (1 − Σ φ_i(u)), which is C(v) exactly when the
// periodic cardinal functions sum to 1 everywhere, between the nodes and across the seam.
TEST(BlendedSurface, ClosedNetworkCardinalFunctionsSumToOne) {
  auto g = test::rng(94);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<Vec3> q;
    for (int k = 0; k < 6; ++k) q.push_back(test::random_point(g));
    const BSplineCurve C = interpolate_curve(q).curve;
    std::vector<double> tu{0};
    for (int i = 0; i < 2 + trial % 4; ++i) tu.push_back(test::uniform(g, 0.05, 0.95));
    std::sort(tu.begin(), tu.end());
    const std::vector<double> tv{0, 0.35, 0.7, 1};
    CurveNetwork n;
    for (double v : tv) n.u_curves.push_back(line(C.point(v), C.point(v)));
    n.v_curves.assign(tu.size(), C);
    n.u_params = tu;
    n.v_params = tv;
    n.periodic = {true, false};
    for (auto method : {NetworkMethod::coons_linear, NetworkMethod::coons_hermite, NetworkMethod::gordon}) {
      const auto s = curve_network(n, {method, {}, {}});
      // Sums of up to 6 cardinal functions (up to ~2 between the nodes) times points of
      // size ~1, twice: rounding, up to 1e-14 in these trials.
      for (double u : linspace(0, 1, 23))
        for (double v : linspace(0, 1, 9)) EXPECT_LT(distance(s.point(u, v), C.point(v)), 1e-13) << trial;
    }
  }
}

// The curve S(t, ·) (axis 0) or S(·, t) (axis 1) of a B-spline surface closed in any
// direction: its control points the basis functions at t times the rows of the net,
// their indices wrapped around a closed direction.
BSplineCurve iso(const BSplineSurface& s, int axis, double t) {
  const KnotVector& across = axis == 0 ? s.knots_u() : s.knots_v();
  const KnotVector& along = axis == 0 ? s.knots_v() : s.knots_u();
  const int p = across.degree(), span = across.find_span(t);
  double N[max_degree + 1];
  across.basis(span, t, N);
  std::vector<Vec3> cp(static_cast<std::size_t>(along.count()));
  for (std::size_t l = 0; l < cp.size(); ++l)
    for (int a = 0; a <= p; ++a) {
      const auto i = static_cast<std::size_t>(across.wrap_index(span - p + a));
      cp[l] += N[a] * (axis == 0 ? s.control_points()(i, l) : s.control_points()(l, i));
    }
  return BSplineCurve(along, cp);
}

// A tube closed in u (and a torus, closed in both): the batch paths evaluate the closed
// curves and cardinal functions through the same wrapped evaluation as the pointwise one.
TEST(BlendedSurface, ClosedNetworkBatchEvaluationMatchesPointwise) {
  auto g = test::rng(95);
  for (int trial = 0; trial < 6; ++trial) {
    const bool closed_v = trial % 2 == 1;
    // Closed (and open) curves through points of a random closed (or open) grid.
    SurfaceInterpolationOptions o;
    o.periodic = {true, closed_v};
    PointGrid q({7, 6});
    for (std::size_t i = 0; i < 7; ++i)
      for (std::size_t j = 0; j < 6; ++j) {
        const double th = 2 * std::numbers::pi * static_cast<double>(i) / 7;
        q(i, j) = Vec3{std::cos(th), std::sin(th), static_cast<double>(j)} + 0.2 * test::random_point(g);
      }
    const BSplineSurface src = interpolate_surface(q, o).surface;
    const std::vector<double> tu{0, 0.3, 0.55, 0.8};
    const std::vector<double> tv = closed_v ? std::vector<double>{0, 0.3, 0.7} : std::vector<double>{0, 0.5, 1};
    CurveNetwork n;
    for (double v : tv) n.u_curves.push_back(iso(src, 1, v));
    for (double u : tu) n.v_curves.push_back(iso(src, 0, u));
    n.u_params = tu;
    n.v_params = tv;
    n.periodic = {true, closed_v};
    std::vector<double> us = linspace(0, 1, 23), vs = linspace(0, 1, 17);
    for (auto& u : us) u = u * u;  // uneven spacing, both ends kept: the seam from both sides
    for (auto method : {NetworkMethod::coons_linear, NetworkMethod::coons_hermite, NetworkMethod::gordon}) {
      const auto s = curve_network(n, {method, {}, {}});
      const PointGrid grid = s.evaluate(us, vs);
      const auto d = s.evaluate_derivatives(us, vs);
      double worst = 0;
      for (std::size_t i = 0; i < us.size(); ++i)
        for (std::size_t j = 0; j < vs.size(); ++j) {
          const SurfaceDerivatives p = s.derivatives(us[i], vs[j]);
          worst = std::max({worst, distance(grid(i, j), p.s), distance(d(i, j).s, p.s), distance(d(i, j).su, p.su),
                            distance(d(i, j).svv, p.svv), distance(d(i, j).suv, p.suv)});
        }
      // The same products summed in another order; second derivatives up to ~100 (a
      // unit ring over a unit parameter: (2π)² ≈ 40, and the random wobble): a few ulps
      // of them, 2e-13 in these trials.
      EXPECT_LT(worst, 1e-12) << "trial " << trial;
    }
  }
}

// A direction that mixes closed and open functions (a ruled surface between a closed
// curve and an open one whose ends meet) converts through the open forms of all; two
// closed curves give a closed exact form.
TEST(BlendedSurface, ClosedAndOpenCurvesConvertExactly) {
  auto g = test::rng(96);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<Vec3> ring, other;
    for (int k = 0; k < 8; ++k) {
      const double th = 2 * std::numbers::pi * k / 8;
      ring.push_back(Vec3{std::cos(th), std::sin(th), 0} + 0.1 * test::random_point(g));
      other.push_back(Vec3{2 * std::cos(th), std::sin(th), 1} + 0.1 * test::random_point(g));
    }
    CurveInterpolationOptions closed;
    closed.periodic = true;
    const BSplineCurve a = interpolate_curve(ring, closed).curve, b = interpolate_curve(other, closed).curve;
    other.push_back(other.front());
    const BSplineCurve b_open = interpolate_curve(other).curve;  // open, its ends the same point
    for (const auto& [c1, periodic] : {std::pair{b, true}, std::pair{b_open, false}}) {
      const auto s = ruled(a, c1);
      const BSplineSurface e = s.to_bspline();
      EXPECT_EQ(e.periodic()[0], periodic);
      EXPECT_EQ(s.exact_knots()[0], e.knots_u());
      // The open form of a closed curve is re-solved by collocation: rounding of data of
      // size ~2, 1.5e-15 in these trials.
      EXPECT_LT(test::max_distance(e, s), 1e-13) << trial;
    }
  }
}

}  // namespace
}  // namespace interpatch
