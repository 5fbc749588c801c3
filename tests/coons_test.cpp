#include "interpatch/coons.hpp"

#include "surface_util.hpp"

namespace interpatch {
namespace {

using test::boundary_of;
using test::cross_of;

void expect_boundary(const Surface& c, const BSplineSurface& s, double tol) {
  for (double t : linspace(0, 1, 23)) {
    EXPECT_LT(distance(c.point(t, 0), s.point(t, 0)), tol);
    EXPECT_LT(distance(c.point(t, 1), s.point(t, 1)), tol);
    EXPECT_LT(distance(c.point(0, t), s.point(0, t)), tol);
    EXPECT_LT(distance(c.point(1, t), s.point(1, t)), tol);
  }
}

TEST(Coons, LinearReproducesBoundariesAndConvertsExactly) {
  auto g = test::rng(70);
  for (int trial = 0; trial < 15; ++trial) {
    const auto s = test::random_bspline_surface(g, 1 + trial % 4, 2 + trial % 3, 6, 7);
    const auto c = coons(boundary_of(s));
    expect_boundary(c, s, 1e-14 * 16);  // sums of a few exact terms of size ~10
    EXPECT_LT(test::max_distance(c, c.to_bspline()), 1e-12 * 16);
  }
}

TEST(Coons, CardinalPropertiesTranslationAndDelta) {
  // Σ c_k ≡ 1: moving all data by d moves the surface by d. c_k(u_l) = δ_kl: a
  // boundary that is zero everywhere except one curve gives that curve on its edge
  // and zero on the opposite edge.
  auto g = test::rng(71);
  const auto s = test::random_bspline_surface(g, 3, 3, 6, 6);
  const auto b = boundary_of(s);
  const Vec3 d{0.3, -2, 5};
  auto shift = [&](const BSplineCurve& c) {
    auto cp = c.control_points();
    for (auto& x : cp) x += d;
    return BSplineCurve(c.knots(), cp);
  };
  for (const auto& o : {CoonsOptions{}, CoonsOptions{Blend::hermite(), Blend::hermite(), {}}}) {
    const auto c0 = coons(b, o);
    const auto c1 = coons({shift(b.v0), shift(b.v1), shift(b.u0), shift(b.u1)}, o);
    for (double u : linspace(0, 1, 9))
      for (double v : linspace(0, 1, 9)) EXPECT_LT(distance(c1.point(u, v) - d, c0.point(u, v)), 1e-13);
  }
}

TEST(Coons, LinearReproducesRuledSurfacesAndHermiteBlendDoesNot) {
  auto g = test::rng(72);
  const auto a = test::random_bspline_surface(g, 3, 3, 5, 5);
  const auto c0 = test::iso_curve(a, 0, 0.2), c1 = test::iso_curve(a, 0, 0.7);  // curves in v
  // S(u,v) = (1−u) c0(v) + u c1(v), linear in u: linear Coons gives it back.
  PointGrid cp({2, c0.control_points().size()});
  for (std::size_t j = 0; j < c0.control_points().size(); ++j) {
    cp(0, j) = c0.control_points()[j];
    cp(1, j) = c1.control_points()[j];
  }
  const BSplineSurface s(KnotVector::bezier(1), c0.knots(), cp);
  const auto lin = coons(boundary_of(s));
  EXPECT_LT(test::max_distance(lin, s), 1e-14 * 8);
  CoonsOptions h;
  h.blend_u = Blend::hermite();
  const auto her = coons(boundary_of(s), h);
  expect_boundary(her, s, 1e-14 * 8);
  EXPECT_GT(test::max_distance(her, s), 1e-3);  // the cubic blend bends the interior
}

TEST(Coons, GeneralBlendMatchesFormula) {
  auto g = test::rng(73);
  const auto s = test::random_bspline_surface(g, 2, 3, 5, 6);
  const auto b = boundary_of(s);
  const Blend f(KnotVector(2, {0, 0, 0, 0.5, 1, 1, 1}), {0, 0.1, 0.8, 1});
  CoonsOptions o;
  o.blend_u = f;
  o.blend_v = Blend::hermite();
  const auto c = coons(b, o);
  for (double u : linspace(0, 1, 7))
    for (double v : linspace(0, 1, 7)) {
      const double fu = f(u), gv = Blend::hermite()(v);
      const Vec3 expect = (1 - fu) * b.u0.point(v) + fu * b.u1.point(v) + (1 - gv) * b.v0.point(u) + gv * b.v1.point(u) -
                          ((1 - fu) * (1 - gv) * s.point(0, 0) + fu * (1 - gv) * s.point(1, 0) +
                           (1 - fu) * gv * s.point(0, 1) + fu * gv * s.point(1, 1));
      EXPECT_LT(distance(c.point(u, v), expect), 1e-14 * 16);
    }
  EXPECT_LT(test::max_distance(c, c.to_bspline()), 1e-12 * 16);
}

TEST(Coons, CallableBlendEvaluatesExactlyButHasNoExactForm) {
  auto g = test::rng(77);
  const auto s = test::random_bspline_surface(g, 3, 2, 5, 5);
  const Blend square([](double t, int k) { return k == 0 ? t * t : (k == 1 ? 2 * t : 2.0); });
  const Blend square_spline(KnotVector(2, {0, 0, 0, 1, 1, 1}), {0, 0, 1});  // t² in Bernstein form
  CoonsOptions a, b;
  a.blend_u = square;
  b.blend_u = square_spline;
  const auto ca = coons(boundary_of(s), a), cb = coons(boundary_of(s), b);
  EXPECT_FALSE(ca.has_exact_form());
  EXPECT_ERRC((void)ca.to_bspline(), no_exact_form, "callable");
  for (double u : linspace(0, 1, 9))
    for (double v : linspace(0, 1, 9)) {
      const auto da = ca.derivatives(u, v), db = cb.derivatives(u, v);
      EXPECT_LT(distance(da.s, db.s), 1e-14 * 16);  // the same function, two evaluations
      EXPECT_LT(distance(da.suu, db.suu), 1e-12 * 16);
    }
  EXPECT_ERRC(Blend([](double t, int) { return std::sin(3.0 * t); }), invalid_blend, "1 at 1");
  EXPECT_ERRC(Blend([](double t, int) { return t + 0.2 * std::sin(12.0 * t) * t * (1 - t) * 4; }), invalid_blend,
              "must not decrease");
}

TEST(Coons, BicubicReproducesBoundaryCrossDerivativesAndBicubics) {
  auto g = test::rng(74);
  for (int trial = 0; trial < 10; ++trial) {
    // A smooth spline surface: its own boundary and cross-derivative curves are consistent data.
    const auto s = test::random_bspline_surface(g, 3, 3, 5 + static_cast<std::size_t>(trial % 3), 6);
    const auto c = coons(boundary_of(s), cross_of(s));
    expect_boundary(c, s, 1e-13);
    for (double t : linspace(0, 1, 13)) {
      const auto d0 = c.derivatives(0, t), d1 = c.derivatives(t, 1);
      EXPECT_LT(distance(d0.su, s.derivative(0, t, 1, 0)), 1e-11 * (1 + norm(d0.su)));
      EXPECT_LT(distance(d1.sv, s.derivative(t, 1, 0, 1)), 1e-11 * (1 + norm(d1.sv)));
    }
    EXPECT_LT(test::max_distance(c, c.to_bspline()), 1e-12 * 16);
  }
  // A single bicubic Bézier patch is reproduced everywhere.
  const auto bez = test::random_bspline_surface(g, 3, 3, 4, 4);
  EXPECT_LT(test::max_distance(coons(boundary_of(bez), cross_of(bez)), bez), 1e-13);
}

TEST(Coons, IncompatibleTwistsAreFoundOrBlendedByGregory) {
  auto g = test::rng(75);
  const auto s = test::random_bspline_surface(g, 3, 3, 5, 5);
  auto x = cross_of(s);
  // Bend S_u(0, v) near v = 0 without moving its end values: its derivative at v = 0
  // (the twist seen along u = 0) changes by 0.5 in z.
  auto cp = x.u0.control_points();
  const double h = x.u0.knots()[4] - x.u0.knots()[0];  // first control leg: slope = 3 Δ / h
  cp[1].z += 0.5 * h / 3;
  x.u0 = BSplineCurve(x.u0.knots(), cp);
  EXPECT_ERRC((void)coons(boundary_of(s), x), incompatible_twist, "incompatible twists at corner p00");
  try {
    (void)coons(boundary_of(s), x);
  } catch (const error& e) {
    EXPECT_NE(std::string(e.what()).find("differ by 0.5"), std::string::npos) << e.what();
  }
  HermiteCoonsOptions o;
  o.twist_correction = TwistCorrection::gregory;
  const auto c = coons(boundary_of(s), x, o);
  EXPECT_FALSE(c.has_exact_form());
  EXPECT_ERRC((void)c.to_bspline(), no_exact_form, "Gregory");
  expect_boundary(c, s, 1e-13);
  for (double t : linspace(0, 1, 21)) {  // both cross-derivative curves are met
    EXPECT_LT(distance(c.derivatives(0, t).su, x.u0.point(t)), 1e-12 * (1 + norm(x.u0.point(t))));
    EXPECT_LT(distance(c.derivatives(t, 0).sv, x.v0.point(t)), 1e-12 * (1 + norm(x.v0.point(t))));
  }
  // Given twists are checked against the curves too.
  HermiteCoonsOptions given;
  given.twists[3] = s.derivative(1, 1, 1, 1) + Vec3{0, 0, 1e-3};
  EXPECT_ERRC((void)coons(boundary_of(s), cross_of(s), given), incompatible_twist, "corner p11");
  given.twists[3] = s.derivative(1, 1, 1, 1);  // the true twist: the same patch as without it
  EXPECT_LT(test::max_distance(coons(boundary_of(s), cross_of(s), given), coons(boundary_of(s), cross_of(s))), 1e-12);
}

TEST(Coons, InvalidInput) {
  auto g = test::rng(76);
  const auto s = test::random_bspline_surface(g, 3, 3, 5, 5);
  auto b = boundary_of(s);
  auto cp = b.u1.control_points();
  cp.back() += Vec3{0, 0.25, 0};
  b.u1 = BSplineCurve(b.u1.knots(), cp);
  EXPECT_ERRC((void)coons(b), corner_gap, "do not meet at corner p11");
  EXPECT_ERRC((void)coons(b), corner_gap, "gap 0.25");
  auto x = cross_of(s);
  auto xc = x.v1.control_points();
  xc.front() += Vec3{1, 0, 0};
  x.v1 = BSplineCurve(x.v1.knots(), xc);
  EXPECT_ERRC((void)coons(boundary_of(s), x), tangent_mismatch, "at corner p01");
  EXPECT_ERRC(Blend(KnotVector::bezier(1), {0.1, 1}), invalid_blend, "0 at 0");
  EXPECT_ERRC(Blend(KnotVector(2, {0, 0, 0, 1, 1, 1}), {0, 1.2, 1}), invalid_blend, "must not decrease");
  EXPECT_ERRC(Blend(KnotVector(1, {0, 0, 2, 2}), {0, 1}), invalid_knots, "over [0, 1]");
}

}  // namespace
}  // namespace interpatch
