// Points, knot vectors, B-spline and Hermite curves, blending functions: the
// examples of vec3.hpp, knot_vector.hpp, bspline_curve.hpp, hermite.hpp and
// blend.hpp, each run and its comments checked. Links interpatch::core only.

#include <cstdio>

#include <interpatch/core.hpp>

#include "check.hpp"

namespace {

void vectors() {
  interpatch::Vec3 a{1, 0, 0}, b{0, 1, 0};
  interpatch::Vec3 n = cross(a, b);  // (0, 0, 1)
  example::expect_near(n, {0, 0, 1}, "cross(a, b) == (0, 0, 1)");
  std::printf("cross((1, 0, 0), (0, 1, 0)) = %s\n", example::str(n).c_str());
}

void knot_vectors() {
  interpatch::KnotVector k(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});  // 5 cubic basis functions
  double N[4];
  int span = k.find_span(0.25);      // 3
  k.basis(span, 0.25, N);            // N_0..N_3 at 0.25, summing to 1
  example::expect(k.count() == 5, "5 cubic basis functions");
  example::expect(span == 3, "find_span(0.25) == 3");
  example::expect_near(N[0] + N[1] + N[2] + N[3], 1, "the basis functions at 0.25 sum to 1");
  std::printf("cubic basis at t = 0.25 (span %d): %g %g %g %g\n", span, N[0], N[1], N[2], N[3]);
}

void periodic_knot_vectors() {
  // A closed cubic with 6 control points and uniform knots over [0, 1].
  auto k = interpatch::KnotVector::periodic_from(3, {0, 1 / 6., 2 / 6., 3 / 6., 4 / 6., 5 / 6.}, 1.0);
  int n = k.count();          // 6 control points
  double t = k.wrap(1.25);    // 0.25: one period on
  example::expect(k.periodic() && n == 6, "6 control points");
  example::expect_near(t, 0.25, "k.wrap(1.25) == 0.25");
  example::expect(k.size() == 6 + 2 * 3 + 1, "6 + 2p + 1 extended knots");
  example::expect(k.front() == 0.0 && k.back() == 1.0, "the domain [0, 1]");
  std::printf("closed cubic knots: %d control points, wrap(1.25) = %g\n", n, t);
}

void bspline_curves() {
  using namespace interpatch;
  BSplineCurve c(KnotVector::bezier(2), {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}});  // a parabola
  Vec3 mid = c.point(0.5);            // (1, 1, 0)
  Vec3 tangent = c.derivative(0.5, 1);  // (2, 0, 0)
  example::expect_near(mid, {1, 1, 0}, "c.point(0.5) == (1, 1, 0)");
  example::expect_near(tangent, {2, 0, 0}, "c.derivative(0.5, 1) == (2, 0, 0)");
  // Knot insertion and degree elevation change the representation, never the curve.
  const BSplineCurve finer = c.inserted(0.3).elevated();
  example::expect(finer.degree() == 3 && finer.control_points().size() == 6, "c.inserted(0.3).elevated() is cubic");
  example::expect_near(finer.point(0.7), c.point(0.7), "inserting and elevating keep the curve");
  std::printf("parabola: C(0.5) = %s, C'(0.5) = %s\n", example::str(mid).c_str(), example::str(tangent).c_str());
}

void lines() {
  interpatch::BSplineCurve edge = interpatch::line({0, 0, 0}, {2, 0, 0});
  interpatch::Vec3 mid = edge.point(0.5);  // (1, 0, 0)
  example::expect_near(mid, {1, 0, 0}, "edge.point(0.5) == (1, 0, 0)");
  example::expect(edge.degree() == 1 && edge.knots() == interpatch::KnotVector::bezier(1),
                  "line() is a degree-1 B-spline over [0, 1]");
  std::printf("line((0, 0, 0), (2, 0, 0)) at 0.5 = %s\n", example::str(mid).c_str());
}

void hermite_functions() {
  auto h = interpatch::hermite_basis(0.5);  // {0.5, 0.5, 0.125, -0.125}
  example::expect_near(h.a0, 0.5, "alpha0(0.5) == 0.5");
  example::expect_near(h.a1, 0.5, "alpha1(0.5) == 0.5");
  example::expect_near(h.b0, 0.125, "beta0(0.5) == 0.125");
  example::expect_near(h.b1, -0.125, "beta1(0.5) == -0.125");
  std::printf("Hermite functions at 0.5: %g %g %g %g\n", h.a0, h.a1, h.b0, h.b1);
}

void hermite_curves() {
  using namespace interpatch;
  HermiteCurve c({{0, 0, 0}, {1, 1, 0}, {2, 0, 0}});  // params 0, 0.5, 1; Catmull–Rom tangents
  Vec3 p = c.point(0.25);           // (0.5, 0.625, 0)
  BSplineCurve b = c.to_bspline();  // the same curve, cubic, double interior knots
  example::expect(c.params() == std::vector<double>{0, 0.5, 1}, "params 0, 0.5, 1");
  // Catmull–Rom: (P2 − P0) / (t2 − t0) inside, one-sided differences at the ends.
  example::expect_near(c.tangents()[1], {2, 0, 0}, "the Catmull–Rom tangent at the middle point");
  example::expect_near(c.tangents()[0], {2, 2, 0}, "the one-sided tangent at the first point");
  example::expect_near(p, {0.5, 0.625, 0}, "c.point(0.25) == (0.5, 0.625, 0)");
  example::expect(b.degree() == 3 && b.knots().multiplicity(0.5) == 2, "to_bspline() is cubic with a double knot at 0.5");
  for (double t : {0.0, 0.1, 0.25, 0.5, 0.8, 1.0})
    example::expect_near(b.point(t), c.point(t), "to_bspline() is the same curve");
  std::printf("Hermite curve: C(0.25) = %s, as a B-spline with %zu control points\n", example::str(p).c_str(),
              b.control_points().size());
}

void blends() {
  auto h = interpatch::Blend::hermite();   // 3t² − 2t³, zero slope at both ends
  double y = h(0.5);                       // 0.5
  example::expect_near(y, 0.5, "Blend::hermite()(0.5) == 0.5");
  example::expect_near(h(0.25), 3 * 0.0625 - 2 * 0.015625, "Blend::hermite() is 3t² − 2t³");
  example::expect_near(h.derivative(0, 1), 0, "zero slope at 0");
  example::expect_near(h.derivative(1, 1), 0, "zero slope at 1");
  example::expect(h.is_spline(), "Blend::hermite() is a B-spline (surfaces built with it have an exact form)");
  std::printf("Hermite blend: f(0.5) = %g, f'(0) = %g, f'(1) = %g\n", y, h.derivative(0, 1), h.derivative(1, 1));
}

}  // namespace

int main() {
  return example::run("curves", [] {
    vectors();
    knot_vectors();
    periodic_knot_vectors();
    bspline_curves();
    lines();
    hermite_functions();
    hermite_curves();
    blends();
  });
}
