#pragma once
/// @file bspline_volume.hpp
/// Trivariate tensor-product B-spline and rational B-spline volumes, with batch
/// evaluation of points and Jacobians over parameter grids.

#include <array>
#include <span>
#include <utility>

#include "interpatch/grid.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/vec3.hpp"
#include "interpatch/volume.hpp"

namespace interpatch {

/// Highest derivative order in each direction BSplineVolume::derivative() takes.
inline constexpr int max_volume_derivative = 3;

/// S(u,v,w) = Σ_ijk N_i(u) N_j(v) N_k(w) w_ijk P_ijk / Σ_ijk N_i(u) N_j(v) N_k(w) w_ijk.
/// Control points are an (n+1) × (m+1) × (l+1) grid, indices along u, v, w. Valid by
/// construction; evaluation never allocates per point. Directions over periodic knot
/// vectors are closed, as for BSplineSurface.
///
/// Example:
/// @code
///   using namespace interpatch;
///   const KnotVector lin = KnotVector::bezier(1);  // a straight line's knots: {0, 0, 1, 1}
///   PointGrid3 cp({2, 2, 2});
///   for (int i = 0; i < 2; ++i)
///     for (int j = 0; j < 2; ++j)
///       for (int k = 0; k < 2; ++k) cp(i, j, k) = {double(i), double(j), double(k) * (1 + i)};
///   BSplineVolume b(lin, lin, lin, cp);
///   Vec3 p = b.point(0.5, 0.5, 0.5);                    // (0.5, 0.5, 0.75)
///   double det = b.jacobian(0.5, 0.5, 0.5).determinant; // 1.5
/// @endcode
class BSplineVolume final : public Volume {
 public:
  /// @param weights empty, or the same shape as control_points.
  /// @throws error size_mismatch (control points or weights do not fit the knots),
  ///   not_finite (a coordinate or weight, naming [i][j][k]), invalid_weight (w <= 0).
  BSplineVolume(KnotVector knots_u, KnotVector knots_v, KnotVector knots_w, PointGrid3 control_points,
                Grid<double, 3> weights = {});

  [[nodiscard]] int degree_u() const noexcept { return ku_.degree(); }
  [[nodiscard]] int degree_v() const noexcept { return kv_.degree(); }
  [[nodiscard]] int degree_w() const noexcept { return kw_.degree(); }
  [[nodiscard]] const KnotVector& knots_u() const noexcept { return ku_; }
  [[nodiscard]] const KnotVector& knots_v() const noexcept { return kv_; }
  [[nodiscard]] const KnotVector& knots_w() const noexcept { return kw_; }
  [[nodiscard]] const PointGrid3& control_points() const noexcept { return cp_; }
  /// Empty for a polynomial (non-rational) volume.
  [[nodiscard]] const Grid<double, 3>& weights() const noexcept { return w_; }
  [[nodiscard]] bool rational() const noexcept { return !w_.empty(); }
  /// Which directions are closed (periodic knot vectors), u, v, w.
  [[nodiscard]] std::array<bool, 3> periodic() const noexcept { return {ku_.periodic(), kv_.periodic(), kw_.periodic()}; }
  /// The knot domains [knots[p], knots[n+1]] in u, v and w.
  [[nodiscard]] std::array<std::pair<double, double>, 3> domain() const override;

  /// S(u, v, w). @throws error out_of_domain.
  [[nodiscard]] Vec3 point(double u, double v, double w) const override;
  /// S, S_u, S_v, S_w (quotient rule for rational volumes). @throws error out_of_domain.
  [[nodiscard]] VolumeDerivatives derivatives(double u, double v, double w) const override;
  /// ∂^{ku+kv+kw} S / ∂u^ku ∂v^kv ∂w^kw, orders 0..max_volume_derivative in each direction.
  /// @throws error out_of_domain, invalid_degree (an order outside 0..3).
  [[nodiscard]] Vec3 derivative(double u, double v, double w, int ku, int kv, int kw) const;

  /// Points at every (us[i], vs[j], ws[k]) into out[(i * vs.size() + j) * ws.size() + k].
  /// Basis functions are computed once per parameter; for each u the control net is
  /// contracted with the u-basis to a net in (v, w), then per v to a row in w, then
  /// per w to the point. The threads share the u values; the result does not depend
  /// on the thread count. @throws error out_of_domain, size_mismatch.
  void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                     std::span<Vec3> out, const progress_callback& progress = {}) const override;
  /// Points and first partials at every (us[i], vs[j], ws[k]), by the same contraction.
  /// @throws error out_of_domain, too_large.
  [[nodiscard]] Grid<VolumeDerivatives, 3> evaluate_derivatives(std::span<const double> us,
                                                                std::span<const double> vs,
                                                                std::span<const double> ws) const override;
  /// Points and det J at every (us[i], vs[j], ws[k]), by the same contraction.
  /// @throws error out_of_domain, too_large.
  [[nodiscard]] VolumeJacobians evaluate_jacobians(std::span<const double> us, std::span<const double> vs,
                                                   std::span<const double> ws,
                                                   const progress_callback& progress = {}) const override;
  /// A copy: a B-spline volume is its own exact form.
  [[nodiscard]] BSplineVolume to_bspline() const override { return *this; }

  /// The same volume with the given knots inserted in u, v and w (each line of
  /// control points refined as a curve). Geometry unchanged.
  /// @throws error out_of_domain, invalid_knots.
  [[nodiscard]] BSplineVolume refined(std::span<const double> knots_u, std::span<const double> knots_v,
                                      std::span<const double> knots_w) const;
  /// The same volume with the degrees raised by tu, tv, tw (each line elevated as a
  /// curve, which keeps the continuity at every knot). @throws error invalid_degree.
  [[nodiscard]] BSplineVolume elevated(int tu, int tv, int tw) const;
  /// The same volume over clamped knot vectors: each periodic direction open over its
  /// domain, first and last control planes on the seam (BSplineCurve::clamped on every
  /// line). Open volumes are returned as they are.
  [[nodiscard]] BSplineVolume clamped() const;
  /// The same volume over [u0,u1] × [v0,v1] × [w0,w1] (a linear change of parameters).
  [[nodiscard]] BSplineVolume mapped(double u0, double u1, double v0, double v1, double w0, double w1) const;

 private:
  KnotVector ku_, kv_, kw_;
  PointGrid3 cp_;
  Grid<double, 3> w_;
};

}  // namespace interpatch
