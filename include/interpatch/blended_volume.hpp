#pragma once
/// @file blended_volume.hpp
/// Volumes made by blending faces, edges and corner data: the trilinear,
/// tricubic Hermite and transfinite (Coons) volumes are all
///
///   S(u,v,w) = Σ f_a(t_a) F(other two) + Σ c f_a(t_a) g_b(t_b) E(t_c) + Σ f(u) g(v) h(w) P
///
/// with blending functions of one parameter (linear, cubic Hermite or any Blend),
/// boundary surfaces F, lines E on them (positions and cross derivatives along the 12
/// edges) and corner data P. Every ingredient is a B-spline, so the sum converts
/// exactly to one B-spline volume.

#include <memory>
#include <string>
#include <vector>

#include "interpatch/bspline_volume.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/volume.hpp"

namespace interpatch {

namespace detail {
struct VolumeTerms;
struct PlaneCache;
std::shared_ptr<PlaneCache> make_plane_cache();
}

/// One of the blended volume constructions. Built by the functions of
/// volume_patches.hpp and coons_volume.hpp; evaluates its own formula exactly over
/// [0, 1]³ and converts exactly to a B-spline volume.
class BlendedVolume final : public Volume {
 public:
  explicit BlendedVolume(std::shared_ptr<const detail::VolumeTerms> terms);

  /// S and its first partials from the terms; no allocation. @throws error out_of_domain.
  [[nodiscard]] VolumeDerivatives derivatives(double u, double v, double w) const override;
  /// Points at every (us[i], vs[j], ws[k]) into out[(i * vs.size() + j) * ws.size() + k].
  /// Every term is filed under one of its blending functions, which folds the faces,
  /// edges and corners into at most four planes per axis, each evaluated once on the
  /// grid of its two axes; a point is then at most 12 products. The planes of u (over
  /// vs × ws) are kept for the next call with the same vs and ws (up to 256 MiB), so
  /// a grid evaluated slab by slab along u makes them once. The threads share the
  /// lines along w; the result depends neither on the thread count nor on how the u
  /// values are split into calls. @throws error out_of_domain, size_mismatch, too_large.
  void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                     std::span<Vec3> out, const progress_callback& progress = {}) const override;
  /// Points and first partials at every grid point, folded as evaluate_into().
  /// @throws error out_of_domain, too_large.
  [[nodiscard]] Grid<VolumeDerivatives, 3> evaluate_derivatives(std::span<const double> us, std::span<const double> vs,
                                                                std::span<const double> ws) const override;
  /// Points and det J at every grid point, folded as evaluate_into().
  /// @throws error out_of_domain, too_large.
  [[nodiscard]] VolumeJacobians evaluate_jacobians(std::span<const double> us, std::span<const double> vs,
                                                   std::span<const double> ws,
                                                   const progress_callback& progress = {}) const override;
  /// Every function of u made compatible (common degree and knots, by degree
  /// elevation and knot insertion), likewise v and w, then the control points of
  /// the tensor-product terms summed: each control point once, in one pass over the
  /// net, the rows shared between threads; the result does not depend on the thread
  /// count.
  /// @throws error no_exact_form (a rational face or cross-derivative surface, or a
  ///   blending function given as a callable).
  [[nodiscard]] BSplineVolume to_bspline() const override;
  /// The same, telling `progress` the fraction of the net made (from the first thread);
  /// what the callback throws stops the work and is rethrown.
  [[nodiscard]] BSplineVolume to_bspline(const progress_callback& progress) const;
  /// Whether to_bspline() succeeds.
  [[nodiscard]] bool has_exact_form() const noexcept;
  /// Notes on how the data were used (e.g. the largest gap found between faces along an edge).
  [[nodiscard]] const std::vector<std::string>& notes() const noexcept;

 private:
  std::shared_ptr<const detail::VolumeTerms> t_;
  // The planes of the last grid evaluation along u, which the slabs of a large grid
  // share (evaluate_into); shared by copies, as are the terms.
  std::shared_ptr<detail::PlaneCache> planes_ = detail::make_plane_cache();
};

}  // namespace interpatch
