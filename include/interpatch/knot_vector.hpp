#pragma once
/// @file knot_vector.hpp
/// A knot vector with its degree, clamped (open) or periodic (closed), validated
/// once when built, and the B-spline basis functions over it (Cox–de Boor; The
/// NURBS Book A2.1–A2.3).

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

  /// A periodic knot vector of degree p: `knots` are the knots of one period
  /// [a, b), first a itself (as many times as its multiplicity), b = `end` the
  /// same point one period on. The N = knots.size() knots of the period repeat
  /// every b − a on both sides; a closed spline over them has N control points,
  /// and basis function i (the one starting at knot i of the extended vector, see
  /// values()) belongs to control point i mod N. The domain is [a, b]; parameters
  /// outside it wrap around (wrap).
  ///
  /// Example:
  /// @code
  ///   // A closed cubic with 6 control points and uniform knots over [0, 1].
  ///   auto k = interpatch::KnotVector::periodic_from(3, {0, 1 / 6., 2 / 6., 3 / 6., 4 / 6., 5 / 6.}, 1.0);
  ///   int n = k.count();          // 6 control points
  ///   double t = k.wrap(1.25);    // 0.25: one period on
  /// @endcode
  /// @throws error invalid_degree, too_few_points (fewer than degree + 1 knots in
  ///   the period), not_finite, non_increasing, invalid_knots (a knot outside [a, b),
  ///   a multiplicity above the degree, or an empty period).
  static KnotVector periodic_from(int degree, std::vector<double> knots, double end);

  /// The periodic knot vector whose extended knots (values() of one) are `knots`:
  /// N + 2p + 1 of them, N the number of control points, the domain
  /// [knots[p], knots[p + N]]. The p knots on either side must repeat the period's
  /// within 1e-12 of the period (files written by other programs round them); the
  /// result has them exactly as periodic_from makes them.
  /// @throws error as periodic_from, and invalid_knots when the knots do not repeat.
  static KnotVector periodic_from_extended(int degree, const std::vector<double>& knots);

  /// The knots of one Bézier segment of the given degree over [0, 1]: degree + 1
  /// zeros, then degree + 1 ones (bezier(1) is {0, 0, 1, 1}, a straight line's).
  /// @throws error invalid_degree.
  static KnotVector bezier(int degree);

  [[nodiscard]] int degree() const noexcept { return p_; }
  /// True for a periodic (closed) knot vector.
  [[nodiscard]] bool periodic() const noexcept { return periodic_; }
  /// The number of knots: count() + p + 1 for a clamped vector, count() + 2p + 1
  /// extended knots for a periodic one.
  [[nodiscard]] std::size_t size() const noexcept { return u_.size(); }
  /// Number of control points, n+1: of basis functions for a clamped vector, of
  /// distinct ones (basis function i and i + count() are one) for a periodic one.
  [[nodiscard]] int count() const noexcept { return count_; }
  [[nodiscard]] double operator[](std::size_t i) const noexcept { return u_[i]; }
  /// All knots; for a periodic vector the extended ones, p before the domain and p
  /// after it.
  [[nodiscard]] const std::vector<double>& values() const noexcept { return u_; }
  [[nodiscard]] double front() const noexcept { return u_[static_cast<std::size_t>(p_)]; }
  [[nodiscard]] double back() const noexcept { return u_[static_cast<std::size_t>(end_)]; }
  /// The control point of basis function i: i itself, or i − count() for the
  /// basis functions of a periodic vector past the last control point (i < count() + p).
  [[nodiscard]] int wrap_index(int i) const noexcept { return i >= count_ ? i - count_ : i; }
  /// t itself inside the domain [front(), back()]; for a periodic vector a t outside
  /// moved by whole periods into [front(), back()).
  [[nodiscard]] double wrap(double t) const noexcept;
  /// The knots of one period, [front(), back()) (periodic vectors; empty otherwise).
  [[nodiscard]] std::vector<double> period_knots() const;
  /// The clamped knot vector of the same spline space over the domain: for a
  /// periodic vector front() and back() p+1 times each and the knots in between;
  /// a clamped vector as it is.
  [[nodiscard]] KnotVector clamped() const;

  /// The span index s with knots[s] <= t < knots[s+1] and knots[s] < knots[s+1],
  /// p <= s <= n (periodic: p <= s < count() + p); t = back() gives the last
  /// non-empty span. t outside the domain is clamped (callers check or wrap it).
  [[nodiscard]] int find_span(double t) const noexcept;

  /// The p+1 non-zero basis functions N_{s-p..s} at t into N. No allocation.
  void basis(int span, double t, double* N) const noexcept;

  /// Basis functions and their derivatives up to order `nd` at t:
  /// ders[k*(p+1) + j] = d^k/dt^k N_{s-p+j}(t), k = 0..nd. Orders above p are zero.
  /// No allocation.
  void basis_derivatives(int span, double t, int nd, double* ders) const noexcept;

  /// Multiplicity of the value t among the knots (0 when t is not a knot).
  [[nodiscard]] int multiplicity(double t) const noexcept;

  /// Distinct interior knots with their multiplicities. For a periodic vector every
  /// distinct knot of one period, front() (the seam) included when it is a knot.
  [[nodiscard]] std::vector<std::pair<double, int>> interior_breaks() const;

  /// Greville abscissae: the n+1 averages of p consecutive knots (periodic: one per
  /// control point, increasing, the first ones before front()).
  [[nodiscard]] std::vector<double> greville() const;

  /// The same knots mapped linearly onto [a, b].
  [[nodiscard]] KnotVector mapped(double a, double b) const;

  /// Smallest continuity over the interior, p − max interior multiplicity
  /// (p−1 ... ; p means polynomial, no interior knots; −1 never occurs). For a
  /// periodic vector the seam counts as interior.
  [[nodiscard]] int continuity() const noexcept;

  friend bool operator==(const KnotVector&, const KnotVector&) = default;

 private:
  KnotVector(int degree, std::vector<double> knots, int count, bool periodic);

  int p_;
  std::vector<double> u_;
  int count_ = 0;
  int end_ = 0;  // index of back() in u_
  bool periodic_ = false;
};

/// The one knot vector of B-splines made compatible (make_compatible in
/// bspline_curve.hpp): the highest degree p among them, every interior knot value
/// with the highest multiplicity it has in any of them once raised to degree p
/// (raising the degree by t raises each multiplicity by t). It tells the size of an
/// exact form before any control point is made: count() control points along it.
/// The knot vectors are taken to share their domain (make_compatible checks).
/// Periodic vectors merge into a periodic one, the seam a break like the others.
/// @throws error too_few_points (no knot vectors), invalid_knots (periodic and
///   clamped vectors mixed).
[[nodiscard]] KnotVector merged_knots(std::span<const KnotVector> knots);

/// The knot vectors with knots that differ by rounding moved onto one value: knots
/// of different vectors within 256 ε of the domain's size (the same parameter
/// reached along different computations) take the smallest of them, so knots keep
/// their order (and curves their control points). Merged as they are, such knots would give a space with basis functions over a
/// few units of rounding (nearly singular). A vector that would then hold a knot more
/// than its degree times is left as it is. The knot vectors share their domain.
[[nodiscard]] std::vector<KnotVector> snapped_together(std::span<const KnotVector> knots);

}  // namespace interpatch
