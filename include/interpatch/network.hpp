#pragma once
/// @file network.hpp
/// Surfaces through rectangular networks of curves: piecewise Coons
/// patches (C0 with linear blending, C1 with Hermite blending) and the Gordon surface.

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "interpatch/blended_surface.hpp"

namespace interpatch {

/// u_curves[j] = S(u, v_j), j = 0..m; v_curves[i] = S(u_i, v), i = 0..n. Each curve is
/// used over its own domain mapped onto [0, 1].
///
/// The curves may be given as they are drawn: in any order within their family,
/// either direction, crossing each other at different parameters of their own, and
/// missing each other by up to the tolerance (see curve_network).
///
/// A network closed in u (periodic[0], the sections of a tube, say): every u_curve is
/// a closed curve, whose seam may lie anywhere (the surface's u = 0 is where it
/// crosses v_curves[0]; a curve crossing there at its parameter 0 is kept as it is), and the
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
  /// Curves missing each other by more than this are an error; unset means 1e-7 ×
  /// the diagonal of the control points' bounding box. In a closed direction also how
  /// close the ends of an open curve must be for it to close, and how close a last
  /// curve must stay to the first to be the closing curve. The re-expression of a
  /// curve (see curve_network) keeps within half of the smaller of this and the
  /// default, so a loose tolerance lets curves miss each other, never loosens a fit.
  std::optional<double> tolerance;
  /// How messages name a curve: family 0 (u_curves) or 1 (v_curves) and its index
  /// as given. Unset: "u_curves[3]"; a spec reader names them by JSON Pointer.
  std::function<std::string(int family, std::size_t index)> curve_name;
};

/// A monotone map from the surface's parameter (over [0, 1]) to a curve's own
/// parameter: the piecewise cubic Hermite function through (at[i], to[i]) with slopes
/// slope[i]: the C2 cubic spline through the points when it is monotone, otherwise
/// C1 with Fritsch–Butland slopes (a weighted harmonic mean of the secants) throughout. Decreasing for a curve that runs against its
/// family. For a closed curve the value is moved by whole periods into
/// [start, start + period) (period > 0).
struct Reparametrization {
  std::vector<double> at, to, slope;
  double start = 0, period = 0;
  [[nodiscard]] double operator()(double t) const;
};

/// How the network used one of its input curves.
struct NetworkCurveReport {
  /// Its place in its family as sorted: the surface has u_curves[j] at v_params[j]
  /// and v_curves[i] at u_params[i] of the report (the closing curve of a closed
  /// family: the count of the others, and its parameter 1).
  std::size_t position = 0;
  bool reversed = false;     ///< it runs against its family, and was turned round
  bool reexpressed = false;  ///< false: used exactly as given (it crossed at the common parameters)
  bool closing = false;      ///< the closing curve of a closed family, left out
  bool degenerate = false;   ///< a curve shrunk to a point (a pole), used as given
  /// Surface parameter (along the curve) → its own parameter. The part of the curve
  /// the surface uses is map(0) to map(1): all of it unless it runs past the end
  /// curves of the other family.
  Reparametrization map;
  /// Its own parameters where it crosses the curves of the other family, in their sorted order.
  std::vector<double> crossings;
  double max_gap = 0;    ///< largest distance to a curve it crosses, at the crossing
  /// Largest distance between the re-expressed curve and the input curve at the same
  /// surface parameter (0 when used as given), measured at 4 points of every span.
  double fit_error = 0;
  /// Largest distance from the input curve to the surface, measured at the same
  /// points: |S(u, v_j) − C(map(u))| for u_curves[j] (the surface along its line
  /// against the curve at the matching parameter; the distance to the nearest point
  /// of the surface is no larger).
  double distance = 0;
};

/// What curve_network found and did, curve by curve (in the order given).
struct NetworkReport {
  std::vector<double> u_params, v_params;  ///< as network_parameters returns them
  std::vector<NetworkCurveReport> u_curves, v_curves;
  double max_gap = 0;                         ///< largest gap at a crossing
  std::array<std::size_t, 2> max_gap_at{0, 0};  ///< where: (u-curve, v-curve) as given
  double tolerance = 0;                       ///< NetworkOptions::tolerance in effect
  double diagonal = 0;                        ///< of the control points' bounding box
  /// The default tolerance: 1e-7 of the diagonal, or 16 units in the last place of the
  /// largest coordinate where that is larger (a small part far from the origin).
  double strict = 0;
};

struct NetworkSurface {
  BlendedSurface surface;
  NetworkReport report;
};

/// Where the curves cross: u_params[i] for v_curves[i], v_params[j] for u_curves[j].
struct NetworkParameters {
  std::vector<double> u_params, v_params;
};
/// The common parameters of the crossings, one per curve given (u_params[i] for
/// v_curves[i]): the given ones, or found. Found: for every pair (u-curve j, v-curve
/// i) the closest points are found; each family is sorted by where it crosses the
/// other (curves running the other way turned round, see curve_network), each
/// curve's crossings are scaled to run from 0 at its first to 1 at its last, and
/// u_i (v_j) is their mean over the u-curves (v-curves). In a closed direction the
/// first is 0 (where the closed curves cross v_curves[0]), the search wraps around
/// the curves' seams, and a closing curve gets 1.
/// @throws error too_few_points (fewer than 2 curves a direction, a closing curve
///   not counted), network_gap (curves that do not meet; an open curve of a closed
///   direction whose ends do not meet), network_order, non_increasing.
[[nodiscard]] NetworkParameters network_parameters(const CurveNetwork& network, const NetworkOptions& options = {});

/// S = Σ_i r_i(v) φ_i(u) + Σ_j r_j(u) ψ_j(v) − Σ_i Σ_j r(u_i, v_j) φ_i(u) ψ_j(v), with
/// cardinal functions φ_i(u_k) = δ_ik: piecewise linear or Hermite (Coons
/// networks), or B-spline interpolants (Gordon). In a closed direction the cardinal
/// functions are periodic: Gordon's closed spline interpolants (C2 across the seam
/// from 4 curves on), the linear hat functions with the last cell from u_n to 1, the
/// Hermite functions of every cell, the last one wrapping.
///
/// The curves r_i, r_j are the curves given, placed so that they cross at common
/// parameters:
/// - every u-curve is met with every v-curve at their closest points (a coarse
///   pass and Gauss–Newton, then a search over 8 samples of every knot span when
///   that ends farther apart than the tolerance); farther apart than the tolerance
///   is an error naming both curves, their closest points and the gap;
/// - each family is sorted by where it crosses the other, and a curve crossing the
///   other family in the reverse order is turned round (most curves keep their
///   direction); orders that no sorting makes agree are an error (network_order);
/// - the common parameters are network_parameters' (or the given ones);
/// - a curve that passes its crossings at the common parameters within 1e-3 of
///   min(tolerance, 1e-7 × the diagonal) is used as it is — networks of curves
///   parametrized alike build as they always did —, any other is re-expressed:
///   D(u) ≈ C(map(u)) with a monotone map taking the common parameters to its own
///   (NetworkCurveReport::map), a B-spline of its degree through its crossings at
///   the common parameters, within half of min(tolerance, 1e-7 × the diagonal) of
///   the curve given (measured at 4 points of every span). The curves of a family
///   share their knots where they can, so the exact form grows no more than the
///   densest curve needs; an open curve running past the end curves of the other
///   family is used between them.
/// The surface then passes within about the tolerance of every curve given (the
/// report tells how far from each). With a loose tolerance, curves that miss each
/// other by more than 1e-7 of the diagonal are accepted, the surface passing
/// halfway between them: notes() and the report say by how much.
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
///   (curves that do not meet, naming both, their closest points and the gap; an
///   open curve of a closed direction whose ends do not meet), network_order.
[[nodiscard]] BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options = {});

/// The same, with what was found and done curve by curve: the crossings and their
/// gaps, the order and direction of each family, which curves were re-expressed, and
/// how far the surface is from each input curve (NetworkReport).
/// @throws error as curve_network.
[[nodiscard]] NetworkSurface network_surface(const CurveNetwork& network, const NetworkOptions& options = {});

}  // namespace interpatch
