#pragma once
/// @file blend.hpp
/// Blending functions f(t) on [0, 1] with f(0) = 0 and f(1) = 1: what Coons patches,
/// curve networks and transfinite volumes put in place of the parameter.

#include <functional>
#include <vector>

#include "interpatch/knot_vector.hpp"

namespace interpatch {

/// A blending function f on [0, 1] with f(0) = 0, f(1) = 1, non-decreasing: either a
/// scalar B-spline with clamped knots and non-decreasing coefficients from 0 to 1
/// (which makes it monotone; a surface built with it converts exactly to a
/// B-spline surface), or any callable (the surface then evaluates exactly by its
/// formula but has no exact B-spline form).
///
/// Example:
/// @code
///   auto h = interpatch::Blend::hermite();   // 3t² − 2t³, zero slope at both ends
///   double y = h(0.5);                       // 0.5
/// @endcode
class Blend {
 public:
  /// @throws error invalid_knots (knots not over [0, 1]), size_mismatch,
  ///   invalid_blend (first coefficient not 0, last not 1, or a decrease).
  Blend(KnotVector knots, std::vector<double> coefficients);
  /// Any function: `f(t, order)` returns f(t) for order 0 and its first and second
  /// derivatives for orders 1 and 2. Checked once: f(0) = 0 and f(1) = 1 within
  /// 1e-12, and no decrease between 1025 equally spaced samples.
  /// @throws error invalid_blend, not_finite.
  explicit Blend(std::function<double(double, int)> f);
  /// f(t) = t.
  static Blend linear();
  /// f(t) = α1(t) = 3t² − 2t³ : zero slopes at both ends.
  static Blend hermite();

  [[nodiscard]] double operator()(double t) const { return derivative(t, 0); }
  [[nodiscard]] double derivative(double t, int order) const;
  /// Whether the blend is a B-spline (then knots() and coefficients() describe it).
  [[nodiscard]] bool is_spline() const noexcept { return !fn_; }
  [[nodiscard]] const KnotVector& knots() const noexcept { return knots_; }
  [[nodiscard]] const std::vector<double>& coefficients() const noexcept { return c_; }
  [[nodiscard]] const std::function<double(double, int)>& function() const noexcept { return fn_; }

 private:
  KnotVector knots_ = KnotVector(1, {0, 0, 1, 1});
  std::vector<double> c_{0, 1};
  std::function<double(double, int)> fn_;
};

}  // namespace interpatch
