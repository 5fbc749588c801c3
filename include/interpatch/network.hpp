#pragma once
/// @file network.hpp
/// Surfaces through rectangular networks of curves: piecewise Coons
/// patches (C0 with linear blending, C1 with Hermite blending) and the Gordon surface.

#include <optional>
#include <vector>

#include "interpatch/blended_surface.hpp"

namespace interpatch {

/// u_curves[j] = S(u, v_j), j = 0..m; v_curves[i] = S(u_i, v), i = 0..n. Each curve is
/// used over its own domain mapped onto [0, 1].
struct CurveNetwork {
  std::vector<BSplineCurve> u_curves, v_curves;
  /// Where the curves cross, increasing from 0 to 1; empty means found from the curves.
  std::vector<double> u_params, v_params;
};

enum class NetworkMethod {
  coons_linear,   ///< bilinearly blended Coons patch per cell: C0 across cells
  coons_hermite,  ///< Coons patches with cubic Hermite blending: C1 across cells (f'(0) = f'(1) = 0 makes the cells C1)
  gordon,         ///< one smooth surface: spline cardinal functions of degree min(3, count − 1)
};

struct NetworkOptions {
  NetworkMethod method = NetworkMethod::gordon;
  /// Curves missing each other at a node by more than this are an error; unset means
  /// 1e-7 × the diagonal of the control points' bounding box.
  std::optional<double> tolerance;
};

/// The parameters where the curves cross, when not given: for every pair (u-curve
/// j, v-curve i) the closest points are found, and u_i (v_j) is the average of the
/// parameters on the u-curves (v-curves).
struct NetworkParameters {
  std::vector<double> u_params, v_params;
};
/// @throws error too_few_points (fewer than 2 curves a direction), network_gap,
///   non_increasing.
[[nodiscard]] NetworkParameters network_parameters(const CurveNetwork& network);

/// S = Σ_i r_i(v) φ_i(u) + Σ_j r_j(u) ψ_j(v) − Σ_i Σ_j r(u_i, v_j) φ_i(u) ψ_j(v), with
/// cardinal functions φ_i(u_k) = δ_ik: piecewise linear or Hermite (Coons
/// networks), or B-spline interpolants (Gordon). Interpolates every curve of the
/// network.
///
/// Example:
/// @code
///   interpatch::CurveNetwork net{u_curves, v_curves, {}, {}};
///   auto s = interpatch::curve_network(net);  // Gordon
///   auto b = s.to_bspline();                  // one B-spline surface through every curve
/// @endcode
/// @throws error too_few_points, size_mismatch (params and curve counts), non_increasing,
///   out_of_domain (params not from 0 to 1), network_gap (naming both curves, the node and the gap).
[[nodiscard]] BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options = {});

}  // namespace interpatch
