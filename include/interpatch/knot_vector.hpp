#pragma once
/// @file knot_vector.hpp
/// A clamped knot vector with its degree, validated once when built, and the
/// B-spline basis functions over it (Cox–de Boor; The NURBS Book A2.1–A2.3).

#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace interpatch {

/// Highest degree interpatch evaluates; basis work arrays live on the stack.
inline constexpr int max_degree = 30;

/// A clamped (open) knot vector of degree p: the first p+1 and the last p+1
/// knots are equal, the knots never decrease, an interior knot appears at most p
/// times, and the domain [knots[p], knots[n+1]] is not empty. n+1 = size() − p − 1
/// basis functions live on it.
///
/// Example:
/// @code
///   interpatch::KnotVector k(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});  // 5 cubic basis functions
///   double N[4];
///   int span = k.find_span(0.25);      // 3
///   k.basis(span, 0.25, N);            // N_0..N_3 at 0.25, summing to 1
/// @endcode
class KnotVector {
 public:
  /// @throws error invalid_degree (degree < 1 or > max_degree), invalid_knots (too few
  ///   knots, not clamped, interior multiplicity > degree, empty domain),
  ///   non_increasing (a knot smaller than the one before, naming both), not_finite.
  KnotVector(int degree, std::vector<double> knots);

  /// Knots of a clamped spline of `count` basis functions with uniformly spaced
  /// interior knots over [a, b].
  /// @throws error invalid_degree, too_few_points (count <= degree).
  static KnotVector uniform(int degree, int count, double a = 0.0, double b = 1.0);

  /// The knots of one Bézier segment of the given degree over [0, 1]: degree + 1
  /// zeros, then degree + 1 ones (bezier(1) is {0, 0, 1, 1}, a straight line's).
  /// @throws error invalid_degree.
  static KnotVector bezier(int degree);

  [[nodiscard]] int degree() const noexcept { return p_; }
  [[nodiscard]] std::size_t size() const noexcept { return u_.size(); }
  /// Number of basis functions, n+1.
  [[nodiscard]] int count() const noexcept { return static_cast<int>(u_.size()) - p_ - 1; }
  [[nodiscard]] double operator[](std::size_t i) const noexcept { return u_[i]; }
  [[nodiscard]] const std::vector<double>& values() const noexcept { return u_; }
  [[nodiscard]] double front() const noexcept { return u_[static_cast<std::size_t>(p_)]; }
  [[nodiscard]] double back() const noexcept { return u_[static_cast<std::size_t>(count())]; }

  /// The span index s with knots[s] <= t < knots[s+1] and knots[s] < knots[s+1],
  /// p <= s <= n; t = back() gives the last non-empty span. t outside the domain is
  /// clamped (callers check the domain).
  [[nodiscard]] int find_span(double t) const noexcept;

  /// The p+1 non-zero basis functions N_{s-p..s} at t into N. No allocation.
  void basis(int span, double t, double* N) const noexcept;

  /// Basis functions and their derivatives up to order `nd` at t:
  /// ders[k*(p+1) + j] = d^k/dt^k N_{s-p+j}(t), k = 0..nd. Orders above p are zero.
  /// No allocation.
  void basis_derivatives(int span, double t, int nd, double* ders) const noexcept;

  /// Multiplicity of the value t among the knots (0 when t is not a knot).
  [[nodiscard]] int multiplicity(double t) const noexcept;

  /// Distinct interior knots with their multiplicities.
  [[nodiscard]] std::vector<std::pair<double, int>> interior_breaks() const;

  /// Greville abscissae: the n+1 averages of p consecutive knots.
  [[nodiscard]] std::vector<double> greville() const;

  /// The same knots mapped linearly onto [a, b].
  [[nodiscard]] KnotVector mapped(double a, double b) const;

  /// Smallest continuity over the interior, p − max interior multiplicity
  /// (p−1 ... ; p means polynomial, no interior knots; −1 never occurs).
  [[nodiscard]] int continuity() const noexcept;

  friend bool operator==(const KnotVector&, const KnotVector&) = default;

 private:
  int p_;
  std::vector<double> u_;
};

/// The one knot vector of B-splines made compatible (make_compatible in
/// bspline_curve.hpp): the highest degree p among them, every interior knot value
/// with the highest multiplicity it has in any of them once raised to degree p
/// (raising the degree by t raises each multiplicity by t). It tells the size of an
/// exact form before any control point is made: count() control points along it.
/// The knot vectors are taken to share their domain (make_compatible checks).
/// @throws error too_few_points (no knot vectors).
[[nodiscard]] KnotVector merged_knots(std::span<const KnotVector> knots);

}  // namespace interpatch
