// Surfaces from corners, curves and networks of curves: the README's Coons and
// network example, then the examples of bspline_surface.hpp, patches.hpp, coons.hpp,
// network.hpp and loft.hpp. Every comment that states a value or a property is checked.
// Links interpatch::core only.

#include <cmath>
#include <cstdio>
#include <vector>

#include <interpatch/core.hpp>

#include "check.hpp"

namespace {

void readme_coons_and_network() {
  using namespace interpatch;
  // Four sides, S(u,0), S(u,1), S(0,v), S(1,v), in any curve form; their ends meet at the corners
  BSplineCurve v0 = interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {0.5, 0, 0.1}, {1, 0, 0}}).curve;
  BSplineCurve v1 = line({0, 1, 0}, {1, 1, 0.5});
  BSplineCurve u0 = line({0, 0, 0}, {0, 1, 0});
  BSplineCurve u1 = HermiteCurve({{1, 0, 0}, {1, 0.5, 0.4}, {1, 1, 0.5}}).to_bspline();

  CoonsBoundary b{v0, v1, u0, u1};             // S(u,0), S(u,1), S(0,v), S(1,v)
  CoonsOptions o;
  o.blend_u = o.blend_v = Blend::hermite();    // 3t² − 2t³: C1 networks
  BlendedSurface s = coons(b, o);
  BSplineSurface exact = s.to_bspline();       // the same surface, one B-spline

  // A network: u_curves[j] = S(u, v_j), v_curves[i] = S(u_i, v); here lines on z = x y
  std::vector<BSplineCurve> u_curves, v_curves;
  for (double t : {0.0, 0.5, 1.0}) {
    u_curves.push_back(line({0, t, 0}, {1, t, t}));
    v_curves.push_back(line({t, 0, 0}, {t, 1, t}));
  }
  BlendedSurface g = curve_network({u_curves, v_curves, {}, {}});  // Gordon; crossings found

  // The patch takes its four sides (each curve's domain is [0, 1] here) ...
  for (double t : linspace(0, 1, 11)) {
    example::expect_near(s.point(t, 0), v0.point(t), "S(u, 0) is v0");
    example::expect_near(s.point(t, 1), v1.point(t), "S(u, 1) is v1");
    example::expect_near(s.point(0, t), u0.point(t), "S(0, v) is u0");
    example::expect_near(s.point(1, t), u1.point(t), "S(1, v) is u1");
  }
  // ... and its B-spline form is the same surface everywhere, not only on the sides.
  for (double u : linspace(0, 1, 7))
    for (double v : linspace(0, 1, 7))
      example::expect_near(exact.point(u, v), s.point(u, v), "s.to_bspline() is the same surface");
  // Lines on z = x y cross where the network's nodes are; the Gordon surface through
  // them is that hyperbolic paraboloid.
  for (double u : linspace(0, 1, 5))
    for (double v : linspace(0, 1, 5))
      example::expect_near(g.point(u, v), {u, v, u * v}, "the Gordon surface of lines on z = x y is z = x y");
  std::printf("Coons patch of four curve forms: S(0.5, 0.5) = %s; as one B-spline of degrees %d × %d, %zu × %zu "
              "control points\n",
              example::str(s.point(0.5, 0.5)).c_str(), exact.degree_u(), exact.degree_v(),
              exact.control_points().extent(0), exact.control_points().extent(1));
}

void bspline_surfaces() {
  using namespace interpatch;
  PointGrid cp({2, 2});
  cp(0, 0) = {0, 0, 0}; cp(1, 0) = {1, 0, 0}; cp(0, 1) = {0, 1, 0}; cp(1, 1) = {1, 1, 1};
  BSplineSurface s(KnotVector::bezier(1), KnotVector::bezier(1), cp);
  Vec3 p = s.point(0.5, 0.5);  // (0.5, 0.5, 0.25)
  example::expect_near(p, {0.5, 0.5, 0.25}, "s.point(0.5, 0.5) == (0.5, 0.5, 0.25)");
  std::printf("bilinear B-spline surface at (0.5, 0.5): %s\n", example::str(p).c_str());
}

void bilinear_patches() {
  auto s = interpatch::bilinear({0, 0, 1}, {1, 1, 1}, {1, 0, 0}, {0, 1, 0});
  interpatch::Vec3 q = s.point(0.5, 0.5);  // (0.5, 0.5, 0.5)
  example::expect_near(q, {0.5, 0.5, 0.5}, "s.point(0.5, 0.5) == (0.5, 0.5, 0.5)");
  example::expect_near(s.point(0, 1), {1, 1, 1}, "p01 is the corner at (u, v) = (0, 1)");
  example::expect_near(s.point(1, 0), {1, 0, 0}, "p10 is the corner at (u, v) = (1, 0)");
  // Every isoparametric line is straight: its midpoint is the mean of its ends.
  example::expect_near(s.point(0.3, 0.5), 0.5 * (s.point(0.3, 0) + s.point(0.3, 1)), "the line u = 0.3 is straight");
  example::expect_near(s.point(0.5, 0.7), 0.5 * (s.point(0, 0.7) + s.point(1, 0.7)), "the line v = 0.7 is straight");
  std::printf("bilinear patch (Rogers & Adams, Example 6-9) at (0.5, 0.5): %s\n", example::str(q).c_str());
}

void coons_patches() {
  using namespace interpatch;
  CoonsBoundary b{line({0,0,0}, {1,0,0}), line({0,1,0}, {1,1,1}), line({0,0,0}, {0,1,0}), line({1,0,0}, {1,1,1})};
  auto s = coons(b);            // the bilinear patch of those corners
  CoonsOptions o;
  o.blend_u = o.blend_v = Blend::hermite();
  auto h = coons(b, o);         // same boundary, blends with zero slope at 0 and 1
  const auto corners = bilinear({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 1});
  for (double u : linspace(0, 1, 5))
    for (double v : linspace(0, 1, 5))
      example::expect_near(s.point(u, v), corners.point(u, v), "coons(b) is the bilinear patch of the corners");
  for (double t : linspace(0, 1, 9)) {
    example::expect_near(h.point(t, 0), s.point(t, 0), "the Hermite-blended patch has the same boundary (v = 0)");
    example::expect_near(h.point(t, 1), s.point(t, 1), "the Hermite-blended patch has the same boundary (v = 1)");
    example::expect_near(h.point(0, t), s.point(0, t), "the Hermite-blended patch has the same boundary (u = 0)");
    example::expect_near(h.point(1, t), s.point(1, t), "the Hermite-blended patch has the same boundary (u = 1)");
  }
  // Inside, the blends replace u and v in the Coons formula: with these straight sides
  // S = (1−f)(0, v, 0) + f (1, v, v) + (1−g)(u, 0, 0) + g (u, 1, u) − (f, g, f g)
  //   = (u, v, f v + g u − f g),  f = f(u), g = g(v).
  for (double u : linspace(0, 1, 5))
    for (double v : linspace(0, 1, 5)) {
      const double fu = o.blend_u(u), gv = o.blend_v(v);
      example::expect_near(h.point(u, v), {u, v, fu * v + gv * u - fu * gv}, "the Coons formula with Hermite blends");
    }
  std::printf("Coons patch at (0.25, 0.25): linear %s, Hermite blends %s\n", example::str(s.point(0.25, 0.25)).c_str(),
              example::str(h.point(0.25, 0.25)).c_str());
}

void gordon_surfaces() {
  using namespace interpatch;
  // A network on z = sin(x) cos(2y) over [0, 1]²: 4 curves along u (at y = 0, 1/3, 2/3,
  // 1) and 3 along v (at x = 0, 1/2, 1), each interpolating 7 points of the surface
  // at uniform parameters k/6, so every curve passes through every node it meets.
  const auto f = [](double x, double y) { return Vec3{x, y, std::sin(x) * std::cos(2 * y)}; };
  CurveInterpolationOptions uniform;
  uniform.param = Parametrization::uniform;
  std::vector<BSplineCurve> u_curves, v_curves;
  for (double y : {0.0, 1.0 / 3, 2.0 / 3, 1.0}) {
    std::vector<Vec3> pts;
    for (int k = 0; k <= 6; ++k) pts.push_back(f(k / 6.0, y));
    u_curves.push_back(interpolate_curve(pts, uniform).curve);
  }
  for (double x : {0.0, 0.5, 1.0}) {
    std::vector<Vec3> pts;
    for (int k = 0; k <= 6; ++k) pts.push_back(f(x, k / 6.0));
    v_curves.push_back(interpolate_curve(pts, uniform).curve);
  }
  interpatch::CurveNetwork net{u_curves, v_curves, {}, {}};
  auto s = interpatch::curve_network(net);  // Gordon
  auto b = s.to_bspline();                  // one B-spline surface through every curve
  const NetworkParameters nodes = network_parameters(net);
  for (std::size_t j = 0; j < u_curves.size(); ++j)
    for (double t : linspace(0, 1, 13))
      example::expect_near(b.point(t, nodes.v_params[j]), u_curves[j].point(t), "b passes through every u-curve",
                           1e-10);
  for (std::size_t i = 0; i < v_curves.size(); ++i)
    for (double t : linspace(0, 1, 13))
      example::expect_near(b.point(nodes.u_params[i], t), v_curves[i].point(t), "b passes through every v-curve",
                           1e-10);
  std::printf("Gordon surface of 4 + 3 curves: crossings found at v =");
  for (double v : nodes.v_params) std::printf(" %.6g", v);
  std::printf("; one B-spline of %zu × %zu control points\n", b.control_points().extent(0),
              b.control_points().extent(1));
}

// loft.hpp's example: rings lofted, the middle one given from another start.
void lofts() {
  using namespace interpatch;
  auto ring = [](double r, double z, int start) {
    std::vector<Vec3> p;
    for (int i = 0; i < 8; ++i) {
      const double a = 0.7853981633974483 * (i + start);  // 45° steps
      p.push_back({r * std::cos(a), r * std::sin(a), z});
    }
    CurveInterpolationOptions closed;
    closed.periodic = true;
    return interpolate_curve(p, closed).curve;
  };
  std::vector<BSplineCurve> sections{ring(1, 0, 0), ring(0.8, 1, 3), ring(0.5, 2, 0)};
  LoftSurface s = loft(sections);
  Vec3 p = s.surface.point(0.25, s.report.params[1]);  // (0, 0.8, 1): the middle ring, not twisted
  double seam = s.report.sections[1].map(0.0);           // 0.625: where u = 0 falls on it

  example::expect_near(p, {0, 0.8, 1}, "the middle ring at u = 0.25");
  example::expect_near(seam, 0.625, "the middle ring's seam");
  // Every ring is the surface's line at its v, through its map; every u-line stays in
  // its half-plane of angle (no twist).
  for (std::size_t k = 0; k < sections.size(); ++k)
    for (double u : linspace(0, 1, 17))
      example::expect_near(s.surface.point(u, s.report.params[k]), sections[k].point(s.report.sections[k].map(u)),
                           "a ring on the loft");
  for (double v : linspace(0, 1, 9)) {
    const Vec3 q = s.surface.point(0.25, v);
    example::expect_near(q.x, 0.0, "u = 0.25 stays at x = 0");
  }
}

}  // namespace

int main() {
  return example::run("coons_and_networks", [] {
    readme_coons_and_network();
    bspline_surfaces();
    bilinear_patches();
    coons_patches();
    gordon_surfaces();
    lofts();
  });
}
