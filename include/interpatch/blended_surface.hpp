#pragma once
/// @file blended_surface.hpp
/// Surfaces made by blending curves and corner data (seed 002): the bilinear,
/// ruled, Coons, Hermite (Ferguson), curve-network and Gordon surfaces are all
///
///   S(u,v) = Σ_k f_k(u) a_k(v) + Σ_l b_l(u) g_l(v) + Σ_k Σ_l c_kl f_k(u) g_l(v)
///
/// with blending functions f_k, g_l (B-spline functions: linear, cubic Hermite or
/// spline cardinal functions), curves a_k(v), b_l(u) and corner data c_kl. Because
/// every ingredient is a B-spline, the sum converts exactly to one B-spline surface.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/surface.hpp"

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
  /// f(t) = α1(t) = 3t² − 2t³ (seed 004 eq. 1.24): zero slopes at both ends.
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

namespace detail {
struct BlendedTerms;
}

/// One of the blended constructions. Built by the functions of patches.hpp,
/// coons.hpp and network.hpp; evaluates its own formula exactly and converts
/// exactly to a B-spline surface.
class BlendedSurface final : public Surface {
 public:
  explicit BlendedSurface(std::shared_ptr<const detail::BlendedTerms> terms);

  [[nodiscard]] SurfaceDerivatives derivatives(double u, double v) const override;
  /// Points at every (us[i], vs[j]) into out[i * vs.size() + j]: each blending
  /// function and curve is evaluated once per parameter, then every point is a
  /// short sum of products of those values (Gregory-corrected patches go point by
  /// point). Both cores share the rows; the result does not depend on the thread
  /// count. @throws error out_of_domain, size_mismatch.
  void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                     const progress_callback& progress = {}) const override;
  /// @throws error no_exact_form (rational boundary curves, Gregory's twists).
  [[nodiscard]] BSplineSurface to_bspline() const override;
  /// Whether to_bspline() succeeds.
  [[nodiscard]] bool has_exact_form() const noexcept;
  /// Notes on how the data were used (e.g. twists taken from the cross-derivative
  /// curves, Gregory's correction applied at corner p00).
  [[nodiscard]] const std::vector<std::string>& notes() const noexcept;

 private:
  std::shared_ptr<const detail::BlendedTerms> t_;
};

}  // namespace interpatch
