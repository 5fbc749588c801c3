#pragma once
/// @file hermite.hpp
/// Cubic Hermite functions  and piecewise cubic Hermite curves.

#include <span>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch {

/// The four cubic Hermite functions on [0, 1] and their derivatives:
/// α0 = 1 − 3g² + 2g³, α1 = 3g² − 2g³, β0 = g − 2g² + g³, β1 = −g² + g³, so that
/// r(g) = r(0) α0 + r(1) α1 + r'(0) β0 + r'(1) β1.
struct HermiteBasis {
  double a0, a1, b0, b1;
};

/// The Hermite functions at g, or their `order`-th derivative (order 0..3; zero above).
///
/// Example:
/// @code
///   auto h = interpatch::hermite_basis(0.5);  // {0.5, 0.5, 0.125, -0.125}
/// @endcode
constexpr HermiteBasis hermite_basis(double g, int order = 0) noexcept {
  switch (order) {
    case 0: return {1 - g * g * (3 - 2 * g), g * g * (3 - 2 * g), g * (1 - g) * (1 - g), g * g * (g - 1)};
    case 1: return {6 * g * (g - 1), 6 * g * (1 - g), 1 - 4 * g + 3 * g * g, g * (3 * g - 2)};
    case 2: return {12 * g - 6, 6 - 12 * g, 6 * g - 4, 6 * g - 2};
    case 3: return {12, -12, 6, 6};
    default: return {0, 0, 0, 0};
  }
}

/// How a piecewise Hermite curve gets tangents that were not given.
enum class TangentRule {
  catmull_rom,  ///< (P_{i+1} − P_{i−1}) / (t_{i+1} − t_{i−1}) inside, one-sided differences at the ends
  bessel,       ///< derivative of the parabola through P_{i−1}, P_i, P_{i+1}; of the end parabolas at the ends
};

/// A C1 piecewise cubic Hermite curve through points P_i at increasing parameters
/// t_i with tangents T_i = dC/dt at t_i.
///
/// Example:
/// @code
///   using namespace interpatch;
///   HermiteCurve c({{0, 0, 0}, {1, 1, 0}, {2, 0, 0}});  // params 0, 0.5, 1; Catmull–Rom tangents
///   Vec3 p = c.point(0.25);           // (0.5, 0.625, 0)
///   BSplineCurve b = c.to_bspline();  // the same curve, cubic, double interior knots
/// @endcode
class HermiteCurve {
 public:
  /// @param params increasing, one per point; empty means uniform in [0, 1].
  /// @param tangents one per point; empty means estimated by `rule`.
  /// @throws error too_few_points (< 2 points), size_mismatch, not_finite,
  ///   non_increasing (params, naming the index).
  explicit HermiteCurve(std::vector<Vec3> points, std::vector<Vec3> tangents = {}, std::vector<double> params = {},
                        TangentRule rule = TangentRule::catmull_rom);

  [[nodiscard]] const std::vector<Vec3>& points() const noexcept { return p_; }
  [[nodiscard]] const std::vector<Vec3>& tangents() const noexcept { return t_; }
  [[nodiscard]] const std::vector<double>& params() const noexcept { return u_; }
  [[nodiscard]] std::pair<double, double> domain() const noexcept { return {u_.front(), u_.back()}; }

  /// C(t). @throws error out_of_domain.
  [[nodiscard]] Vec3 point(double t) const { return derivative(t, 0); }
  /// d^k C / dt^k at t. @throws error out_of_domain.
  [[nodiscard]] Vec3 derivative(double t, int k) const;

  /// The exact cubic B-spline form: Bézier points P_i, P_i + h T_i / 3,
  /// P_{i+1} − h T_{i+1} / 3, P_{i+1} per segment of length h, interior knots doubled.
  [[nodiscard]] BSplineCurve to_bspline() const;

 private:
  std::vector<Vec3> p_, t_;
  std::vector<double> u_;
};

}  // namespace interpatch
