#pragma once
/// @file network.hpp
/// Surfaces through rectangular networks of curves: piecewise Coons
/// patches (C0 with linear blending, C1 with Hermite blending) and the Gordon surface.

#include <array>
#include <optional>
#include <vector>

#include "interpatch/blended_surface.hpp"

namespace interpatch {

/// u_curves[j] = S(u, v_j), j = 0..m; v_curves[i] = S(u_i, v), i = 0..n. Each curve is
/// used over its own domain mapped onto [0, 1].
///
/// A network closed in u (periodic[0], the sections of a tube, say): every u_curve is
/// a closed curve starting (parameter 0) where it crosses v_curves[0], and the
/// v_curves are a cyclic family at 0 = u_0 < u_1 < ... < u_n < 1, v_curves[0] serving
/// at u = 1 as well. A last v_curve that repeats the first is the closing curve and
/// is left out, as closed interpolation leaves out a closing point: given u_params
/// tell it by its parameter 1 (it must then lie within the tolerance of the first),
/// found ones by its lying within the tolerance of the first. A u_curve may be a
/// periodic B-spline (the surface is then as smooth across the seam as anywhere), or
/// an open one whose ends meet within the tolerance, taken as the closed curve it is
/// (its seam a knot of multiplicity p, so the surface is only as smooth across the
/// seam as that curve).
/// Closed in v likewise with the roles swapped. In a direction that is not closed,
/// a periodic curve is used as the open curve of its domain.
struct CurveNetwork {
  std::vector<BSplineCurve> u_curves, v_curves;
  /// Where the curves cross, increasing from 0 to 1 (closed direction: from 0 to
  /// below 1, a closing curve's 1); empty means found from the curves.
  std::vector<double> u_params, v_params;
  /// Closed directions, u then v: the cardinal functions across the curves are
  /// periodic, and the surface and its exact form are closed (periodic) in that direction.
  std::array<bool, 2> periodic{false, false};
};

enum class NetworkMethod {
  coons_linear,   ///< bilinearly blended Coons patch per cell: C0 across cells
  coons_hermite,  ///< Coons patches with cubic Hermite blending: C1 across cells (f'(0) = f'(1) = 0 makes the cells C1)
  gordon,         ///< one smooth surface: spline cardinal functions of degree min(3, count − 1)
};

struct NetworkOptions {
  NetworkMethod method = NetworkMethod::gordon;
  /// Curves missing each other at a node by more than this are an error; unset means
  /// 1e-7 × the diagonal of the control points' bounding box. In a closed direction
  /// also how close the ends of an open curve must be for it to close, and how close
  /// a last curve must stay to the first to be the closing curve.
  std::optional<double> tolerance;
};

/// Where the curves cross: u_params[i] for v_curves[i], v_params[j] for u_curves[j].
struct NetworkParameters {
  std::vector<double> u_params, v_params;
};
/// The parameters where the curves cross, when not given: for every pair (u-curve
/// j, v-curve i) the closest points are found, and u_i (v_j) is the average of the
/// parameters on the u-curves (v-curves). The first and last are 0 and 1 by
/// convention; in a closed direction the first is 0 (where the closed curves start),
/// the search wraps around their seam, and a closing curve gets 1. One parameter per
/// curve given. `options.tolerance` tells closing curves (see CurveNetwork).
/// @throws error too_few_points (fewer than 2 curves a direction, a closing curve
///   not counted), network_gap (an open curve of a closed direction whose ends do
///   not meet), non_increasing.
[[nodiscard]] NetworkParameters network_parameters(const CurveNetwork& network, const NetworkOptions& options = {});

/// S = Σ_i r_i(v) φ_i(u) + Σ_j r_j(u) ψ_j(v) − Σ_i Σ_j r(u_i, v_j) φ_i(u) ψ_j(v), with
/// cardinal functions φ_i(u_k) = δ_ik: piecewise linear or Hermite (Coons
/// networks), or B-spline interpolants (Gordon). Interpolates every curve of the
/// network. In a closed direction the cardinal functions are periodic: Gordon's
/// closed spline interpolants (C2 across the seam from 4 curves on), the linear hat
/// functions with the last cell from u_n to 1, the Hermite functions of every cell,
/// the last one wrapping.
///
/// Example:
/// @code
///   interpatch::CurveNetwork net{u_curves, v_curves, {}, {}};
///   auto s = interpatch::curve_network(net);  // Gordon
///   auto b = s.to_bspline();                  // one B-spline surface through every curve
/// @endcode
/// A tube from closed sections is the same with `periodic = {true, false}`: its exact
/// form is periodic in u.
/// @throws error too_few_points, size_mismatch (params and curve counts), non_increasing,
///   out_of_domain (params not from 0 to 1; a closing curve's not 1), network_gap
///   (naming both curves, the node and the gap; an open curve of a closed direction
///   whose ends do not meet).
[[nodiscard]] BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options = {});

}  // namespace interpatch
