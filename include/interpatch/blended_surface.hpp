#pragma once
/// @file blended_surface.hpp
/// Surfaces made by blending curves and corner data: the bilinear,
/// ruled, Coons, Hermite (Ferguson), curve-network and Gordon surfaces are all
///
///   S(u,v) = Σ_k f_k(u) a_k(v) + Σ_l b_l(u) g_l(v) + Σ_k Σ_l c_kl f_k(u) g_l(v)
///
/// with blending functions f_k, g_l (B-spline functions: linear, cubic Hermite or
/// spline cardinal functions), curves a_k(v), b_l(u) and corner data c_kl. Because
/// every ingredient is a B-spline, the sum converts exactly to one B-spline surface.

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "interpatch/blend.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"

namespace interpatch {

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
  /// point). The threads share the rows; the result does not depend on the thread
  /// count. @throws error out_of_domain, size_mismatch.
  void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                     const progress_callback& progress = {}) const override;
  /// Rows on the parameters vs: the blending functions and curves of v evaluated
  /// here, once; each block of rows then costs its functions of u and the sums.
  /// (Gregory-corrected patches: Surface::rows.) @throws error out_of_domain.
  [[nodiscard]] std::unique_ptr<Rows> rows(std::span<const double> vs) const override;
  /// Points and unit normals: per row, the point and its first partials (su, sv and
  /// suv, for poles) summed as evaluate_into() sums the point, then the normal.
  /// (Gregory-corrected patches: Surface::evaluate_normals_into.) @throws error out_of_domain, size_mismatch.
  void evaluate_normals_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> points,
                             std::span<Vec3> normals, const progress_callback& progress = {}) const override;
  /// The grid us × vs with every function of u and of v and their first derivatives
  /// evaluated here, once; each rectangle then costs its sums and normals.
  /// (Gregory-corrected patches: Surface::normal_grid.) @throws error out_of_domain.
  [[nodiscard]] std::unique_ptr<NormalGrid> normal_grid(std::span<const double> us,
                                                        std::span<const double> vs) const override;
  /// Points and derivatives up to second order at every (us[i], vs[j]), the same
  /// way: each factor with its derivatives once per parameter, then short sums per
  /// point (Gregory-corrected patches point by point). @throws error out_of_domain, too_large.
  [[nodiscard]] Grid<SurfaceDerivatives, 2> evaluate_derivatives(std::span<const double> us,
                                                                 std::span<const double> vs) const override;
  /// Every function of u made compatible (common degree and knots, by degree
  /// elevation and knot insertion), likewise v, then the control points of the
  /// tensor-product terms summed: each control point once, in one pass over the
  /// net, the rows shared between threads; the result does not depend on the thread
  /// count.
  /// @throws error no_exact_form (rational boundary curves, Gregory's twists).
  [[nodiscard]] BSplineSurface to_bspline() const override;
  /// The same, telling `progress` the fraction of the net made (from the first thread,
  /// at most every 64 rows); what the callback throws stops the work and is rethrown.
  [[nodiscard]] BSplineSurface to_bspline(const progress_callback& progress) const;
  /// The knot vectors (u, v) of the exact form, without making its control net:
  /// what to_bspline() gives, count() control points along each. Cheap: the knots
  /// of the curves and blending functions merged. @throws error no_exact_form.
  [[nodiscard]] std::array<KnotVector, 2> exact_knots() const;
  /// The products evaluate_into() sums per point: the curve terms of the formula,
  /// what a point costs by formula against a point of the exact form.
  [[nodiscard]] std::size_t terms() const noexcept;
  /// Whether to_bspline() succeeds.
  [[nodiscard]] bool has_exact_form() const noexcept;
  /// Notes on how the data were used (e.g. twists taken from the cross-derivative
  /// curves, Gregory's correction applied at corner p00).
  [[nodiscard]] const std::vector<std::string>& notes() const noexcept;

 private:
  std::shared_ptr<const detail::BlendedTerms> t_;
};

}  // namespace interpatch
