#pragma once
// Test helpers for constructions from curves: random smooth B-spline surfaces and
// the exact curves on them (iso-parametric lines and cross-derivative curves), so
// that consistent boundary data come with a surface to compare against.

#include "interpatch/bspline_surface.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/network.hpp"
#include "test_util.hpp"

namespace interpatch::test {

/// A random non-rational B-spline surface over [0,1]², degrees (p, q), with
/// nu × nv control points near a plane.
inline BSplineSurface random_bspline_surface(std::mt19937_64& g, int p, int q, std::size_t nu, std::size_t nv,
                                             double noise = 0.3) {
  auto knots = [&](int deg, std::size_t n) {
    std::vector<double> u(static_cast<std::size_t>(deg + 1), 0.0), in;
    for (std::size_t i = 0; i + static_cast<std::size_t>(deg) + 1 < n; ++i) in.push_back(uniform(g, 0.1, 0.9));
    std::sort(in.begin(), in.end());
    u.insert(u.end(), in.begin(), in.end());
    u.insert(u.end(), static_cast<std::size_t>(deg + 1), 1.0);
    return KnotVector(deg, u);
  };
  return BSplineSurface(knots(p, nu), knots(q, nv), random_grid(g, nu, nv, noise));
}

/// ∂^k S/∂u^k (u, ·) as a B-spline curve in v (axis 0), or ∂^k S/∂v^k (·, v) in u (axis 1).
inline BSplineCurve iso_curve(const BSplineSurface& s, int axis, double t, int k = 0) {
  const KnotVector& across = axis == 0 ? s.knots_u() : s.knots_v();
  const KnotVector& along = axis == 0 ? s.knots_v() : s.knots_u();
  const int p = across.degree();
  const int span = across.find_span(t);
  double d[(max_degree + 1) * (max_degree + 1)];
  across.basis_derivatives(span, t, k, d);
  const std::size_t n = static_cast<std::size_t>(along.count());
  std::vector<Vec3> cp(n);
  for (std::size_t l = 0; l < n; ++l)
    for (int a = 0; a <= p; ++a) {
      const auto i = static_cast<std::size_t>(span - p + a);
      cp[l] += d[k * (p + 1) + a] * (axis == 0 ? s.control_points()(i, l) : s.control_points()(l, i));
    }
  return BSplineCurve(along, cp);
}

/// The four boundary curves of a surface over [0,1]², as a Coons patch takes them.
inline CoonsBoundary boundary_of(const BSplineSurface& s) {
  return {iso_curve(s, 1, 0.0), iso_curve(s, 1, 1.0), iso_curve(s, 0, 0.0), iso_curve(s, 0, 1.0)};
}

/// Its cross-boundary derivative curves, as the Hermite-blended Coons patch takes them.
inline CoonsCrossDerivatives cross_of(const BSplineSurface& s) {
  return {iso_curve(s, 1, 0.0, 1), iso_curve(s, 1, 1.0, 1), iso_curve(s, 0, 0.0, 1), iso_curve(s, 0, 1.0, 1)};
}

/// Largest distance between two surfaces on an n × n grid over [0,1]².
inline double max_distance(const Surface& a, const Surface& b, std::size_t n = 41) {
  const auto t = linspace(0, 1, n);
  double e = 0;
  for (double u : t)
    for (double v : t) e = std::max(e, distance(a.point(u, v), b.point(u, v)));
  return e;
}

// The network of a surface's iso-curves at u = tu[i] and v = tv[j], crossing at those parameters.
inline CurveNetwork network_on(const BSplineSurface& s, const std::vector<double>& tu, const std::vector<double>& tv) {
  CurveNetwork n;
  for (double v : tv) n.u_curves.push_back(test::iso_curve(s, 1, v));
  for (double u : tu) n.v_curves.push_back(test::iso_curve(s, 0, u));
  n.u_params = tu;
  n.v_params = tv;
  return n;
}

}  // namespace interpatch::test
