#pragma once
/// @file bspline_surface.hpp
/// Tensor-product B-spline and rational B-spline surfaces, with batch grid evaluation.

#include <array>
#include <span>
#include <utility>
#include <vector>

#include "interpatch/grid.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch {

/// S(u,v) = Σ_i Σ_j N_i(u) N_j(v) w_ij P_ij / Σ_i Σ_j N_i(u) N_j(v) w_ij.
/// Control points are an (n+1) × (m+1) grid, first index along u. Valid by
/// construction; evaluation never allocates per point. A direction whose knot vector
/// is periodic is closed (a pipe, a torus): its control points are the distinct ones
/// and its parameters wrap around (see KnotVector::periodic_from).
///
/// Example:
/// @code
///   using namespace interpatch;
///   PointGrid cp({2, 2});
///   cp(0, 0) = {0, 0, 0}; cp(1, 0) = {1, 0, 0}; cp(0, 1) = {0, 1, 0}; cp(1, 1) = {1, 1, 1};
///   BSplineSurface s(KnotVector::bezier(1), KnotVector::bezier(1), cp);
///   Vec3 p = s.point(0.5, 0.5);  // (0.5, 0.5, 0.25)
/// @endcode
class BSplineSurface final : public Surface {
 public:
  /// @param weights empty, or the same shape as control_points.
  /// @throws error size_mismatch, not_finite, invalid_weight.
  BSplineSurface(KnotVector knots_u, KnotVector knots_v, PointGrid control_points, Grid<double, 2> weights = {});

  [[nodiscard]] int degree_u() const noexcept { return ku_.degree(); }
  [[nodiscard]] int degree_v() const noexcept { return kv_.degree(); }
  [[nodiscard]] const KnotVector& knots_u() const noexcept { return ku_; }
  [[nodiscard]] const KnotVector& knots_v() const noexcept { return kv_; }
  [[nodiscard]] const PointGrid& control_points() const noexcept { return cp_; }
  [[nodiscard]] const Grid<double, 2>& weights() const noexcept { return w_; }
  [[nodiscard]] bool rational() const noexcept { return !w_.empty(); }
  /// Which directions are closed (periodic knot vectors), u then v.
  [[nodiscard]] std::array<bool, 2> periodic() const noexcept { return {ku_.periodic(), kv_.periodic()}; }
  [[nodiscard]] std::pair<double, double> domain_u() const noexcept { return {ku_.front(), ku_.back()}; }
  [[nodiscard]] std::pair<double, double> domain_v() const noexcept { return {kv_.front(), kv_.back()}; }
  /// The knot domains [knots[p], knots[n+1]] in u and v.
  [[nodiscard]] std::array<std::pair<double, double>, 2> domain() const override { return {domain_u(), domain_v()}; }

  /// S(u, v). @throws error out_of_domain.
  [[nodiscard]] Vec3 point(double u, double v) const override;
  /// S and its partial derivatives up to second order. @throws error out_of_domain.
  [[nodiscard]] SurfaceDerivatives derivatives(double u, double v) const override;
  /// ∂^{ku+kv} S / ∂u^ku ∂v^kv for any orders. @throws error out_of_domain.
  [[nodiscard]] Vec3 derivative(double u, double v, int ku, int kv) const;

  /// Points at every (us[i], vs[j]) into out[i * vs.size() + j]. Basis functions
  /// are computed once per parameter; each u row first contracts the control net
  /// to one curve in v. The threads share the rows; the result does not depend on
  /// the thread count. @throws error out_of_domain, size_mismatch.
  void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                     const progress_callback& progress = {}) const override;
  /// Rows on the parameters vs: a polynomial surface works out the basis functions
  /// of v here, once (the same points as evaluate_into()).
  [[nodiscard]] std::unique_ptr<Rows> rows(std::span<const double> vs) const override;
  /// Points and derivatives at every (us[i], vs[j]). @throws error out_of_domain, too_large.
  [[nodiscard]] Grid<SurfaceDerivatives, 2> evaluate_derivatives(std::span<const double> us,
                                                                 std::span<const double> vs) const override;
  /// A copy: a B-spline surface is its own exact form.
  [[nodiscard]] BSplineSurface to_bspline() const override { return *this; }

  /// The same surface with knots inserted in u and v. @throws error out_of_domain, invalid_knots.
  [[nodiscard]] BSplineSurface refined(std::span<const double> knots_u, std::span<const double> knots_v) const;
  /// The same surface with degrees raised by tu and tv.
  [[nodiscard]] BSplineSurface elevated(int tu, int tv) const;
  /// The same surface over [u0,u1] × [v0,v1].
  [[nodiscard]] BSplineSurface mapped(double u0, double u1, double v0, double v1) const;
  /// The same surface over clamped knot vectors: each periodic direction as the open
  /// surface of its domain, its first and last control lines on the seam
  /// (BSplineCurve::clamped on every line). Open surfaces are returned as they are.
  [[nodiscard]] BSplineSurface clamped() const;

 private:
  KnotVector ku_, kv_;
  PointGrid cp_;
  Grid<double, 2> w_;
};

}  // namespace interpatch
