#pragma once
/// @file bspline_curve.hpp
/// B-spline and rational B-spline (NURBS) curves in 3-space.

#include <span>
#include <utility>
#include <vector>

#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch {

/// C(t) = Σ N_{i,p}(t) w_i P_i / Σ N_{i,p}(t) w_i over the domain [knots[p], knots[n+1]];
/// without weights all w_i = 1 and the curve is polynomial on each span. Over a
/// periodic knot vector the curve is closed: its control points are the distinct
/// ones (basis function i + n + 1 belongs to P_i), it is as smooth across the seam
/// as at any knot, and parameters outside the domain wrap around.
/// Valid by construction: n+1 control points for n+p+2 knots, finite coordinates,
/// positive weights.
///
/// Example:
/// @code
///   using namespace interpatch;
///   BSplineCurve c(KnotVector::bezier(2), {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}});  // a parabola
///   Vec3 mid = c.point(0.5);            // (1, 1, 0)
///   Vec3 tangent = c.derivative(0.5, 1);  // (2, 0, 0)
/// @endcode
class BSplineCurve {
 public:
  /// @throws error size_mismatch (control point or weight count does not fit the
  ///   knots), not_finite (a coordinate or weight), invalid_weight (w <= 0).
  BSplineCurve(KnotVector knots, std::vector<Vec3> control_points, std::vector<double> weights = {});

  [[nodiscard]] int degree() const noexcept { return knots_.degree(); }
  [[nodiscard]] const KnotVector& knots() const noexcept { return knots_; }
  [[nodiscard]] const std::vector<Vec3>& control_points() const noexcept { return cp_; }
  /// Empty for a polynomial (non-rational) curve.
  [[nodiscard]] const std::vector<double>& weights() const noexcept { return w_; }
  [[nodiscard]] bool rational() const noexcept { return !w_.empty(); }
  /// True for a closed curve over a periodic knot vector.
  [[nodiscard]] bool periodic() const noexcept { return knots_.periodic(); }
  [[nodiscard]] std::pair<double, double> domain() const noexcept { return {knots_.front(), knots_.back()}; }

  /// C(t). @throws error out_of_domain (never for a periodic curve: t wraps).
  [[nodiscard]] Vec3 point(double t) const;
  /// d^k C / dt^k at t, any k >= 0. @throws error out_of_domain.
  [[nodiscard]] Vec3 derivative(double t, int k) const;
  /// C and its derivatives of orders 0..n at t into out[0..n]. No allocation
  /// for n <= max_degree. @throws error out_of_domain.
  void derivatives(double t, int n, Vec3* out) const;
  [[nodiscard]] std::vector<Vec3> derivatives(double t, int n) const;

  /// The same curve with t inserted `times` more times (Boehm's algorithm on
  /// homogeneous points; a periodic curve is re-solved in the refined space, exact
  /// up to rounding, and takes any t, the seam included). Geometry unchanged.
  /// @throws error out_of_domain (t outside the open domain), invalid_knots (the
  ///   multiplicity would exceed the degree).
  [[nodiscard]] BSplineCurve inserted(double t, int times = 1) const;
  /// The same curve with every value of `knots` inserted once (a refinement).
  [[nodiscard]] BSplineCurve refined(std::span<const double> knots) const;
  /// The same curve as a B-spline of degree p + times: every knot's multiplicity
  /// grows by `times`, which keeps the continuity at every knot.
  [[nodiscard]] BSplineCurve elevated(int times = 1) const;
  /// The same curve over [a, b] instead of its own domain (a linear change of parameter).
  [[nodiscard]] BSplineCurve mapped(double a = 0.0, double b = 1.0) const;
  /// The same curve over a clamped knot vector: a periodic curve as the open curve
  /// of its domain (knots front() and back() p+1 times, the period's other knots in
  /// between; its first and last control points are the seam point), found by
  /// interpolation at the Greville abscissae of that space, exact up to rounding. A
  /// clamped curve is returned as it is.
  [[nodiscard]] BSplineCurve clamped() const;

 private:
  KnotVector knots_;
  std::vector<Vec3> cp_;
  std::vector<double> w_;
};

/// The straight segment C(t) = (1 − t)·a + t·b over [0, 1], as a degree-1 B-spline:
/// a boundary edge, a ruling, the side of a Coons patch. a == b is allowed (a
/// boundary collapsed to a point).
///
/// Example:
/// @code
///   interpatch::BSplineCurve edge = interpatch::line({0, 0, 0}, {2, 0, 0});
///   interpatch::Vec3 mid = edge.point(0.5);  // (1, 0, 0)
/// @endcode
/// @throws error not_finite.
[[nodiscard]] BSplineCurve line(const Vec3& a, const Vec3& b);

/// The same curves over one knot vector and one degree: each is elevated to the
/// highest degree among them, then every knot value gets the highest multiplicity
/// it has in any of them (knot merging). Geometry unchanged.
/// @throws error out_of_domain (the domains differ), too_few_points (no curves).
[[nodiscard]] std::vector<BSplineCurve> make_compatible(std::span<const BSplineCurve> curves);

}  // namespace interpatch
