#pragma once
/// @file interpolate.hpp
/// Global B-spline interpolation of curves and of grids of points, surfaces and
/// volumes (The NURBS Book §9.2), solved as banded systems factored once.

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/progress.hpp"

namespace interpatch {

/// How data points get their parameters.
enum class Parametrization {
  uniform,      ///< equally spaced
  chord,        ///< proportional to chord length (default)
  centripetal,  ///< proportional to the square root of chord length
};

/// Parameters in [0, 1] of points along a polyline, first 0, last 1.
/// @throws error too_few_points (< 2), not_finite, zero_chord (two consecutive
///   points coincide, naming the indices and the chord), when `param` is not uniform.
[[nodiscard]] std::vector<double> curve_parameters(std::span<const Vec3> points, Parametrization param);

/// Knots of degree p by averaging (The NURBS Book eq. 9.8) for interpolation at
/// `params`, with `extra_start`/`extra_end` additional conditions (end derivatives)
/// at the first/last parameter. Clamped over [params.front(), params.back()].
/// @throws error too_few_points, non_increasing.
[[nodiscard]] KnotVector averaged_knots(std::span<const double> params, int degree, bool extra_start = false,
                                        bool extra_end = false);

/// Parameters in [0, 1) of the points of a closed polygon, the closing chord from
/// the last point back to the first included: 0 at the first point, and 1 would be
/// the first point again. The points are the distinct ones (no closing point).
/// @throws error too_few_points (< 2), not_finite, zero_chord (two consecutive
///   points coincide, the last and the first included).
[[nodiscard]] std::vector<double> closed_curve_parameters(std::span<const Vec3> points, Parametrization param);

/// Knots of a closed (periodic) spline of degree p through points at `params`
/// (increasing, within one period [params[0], params[0] + 1)): for odd p the
/// parameters themselves, for even p the midpoints of consecutive ones (the last
/// with params[0] + 1), both extended periodically. Either way the spline does not
/// depend on which point comes first. (For even p the domain starts at a midpoint;
/// interpolate_curve then inserts params[0] as a knot so that its domain is
/// [params[0], params[0] + 1].)
/// @throws error too_few_points (fewer than p + 1 parameters), non_increasing,
///   out_of_domain (a parameter outside the period).
[[nodiscard]] KnotVector periodic_knots(std::span<const double> params, int degree);

/// How a closed direction ends: the number of data lines kept (the closing line, equal
/// to the first, left out) and whether one was left out.
struct Closing {
  std::size_t count = 0;
  bool dropped = false;
  /// A last point nearly repeats its first: closer than 1e-3 of the chords next to it,
  /// farther than 1e-12 of the diagonal (closing_point refuses it as closing_gap).
  bool nearly = false;
};

/// Whether the last point of a closed curve repeats the first: within 1e-12 of the
/// bounding-box diagonal it does and is left out. A last point nearly on the first
/// — closer than 1e-3 of the chords next to it, but farther than that — is
/// refused: a closing point copied with a rounding error would put a kink of that
/// size at the seam.
/// @throws error closing_gap (naming the point, its distance and the tolerance).
[[nodiscard]] Closing closing_point(std::span<const Vec3> points);

/// The same rule for the lines of a grid along `axis` (0: u, 1: v, 2: w), all at once:
/// the last line is left out when every point of it repeats the first line's. It
/// does not throw: a near miss is reported in `nearly` (interpolating the grid closed
/// along `axis` refuses it as closing_gap). For callers that warn about data that
/// close in a direction not declared periodic.
/// @throws error out_of_domain (no such axis).
[[nodiscard]] Closing grid_closing(const PointGrid& points, int axis);
[[nodiscard]] Closing grid_closing(const PointGrid3& points, int axis);

struct CurveInterpolationOptions {
  /// Degree; unset means min(3, points − 1).
  std::optional<int> degree;
  Parametrization param = Parametrization::chord;
  /// Given parameters (increasing) instead of `param`. For a periodic curve within
  /// one period [params[0], params[0] + 1) (a closing point's parameter, if given, is
  /// params[0] + 1).
  std::vector<double> params;
  /// Derivative dC/dt at the first / last point, t in [0, 1]. Not for a periodic curve.
  std::optional<Vec3> start_derivative, end_derivative;
  /// A closed curve, C^(p−1) everywhere, the seam included, over periodic knots
  /// (periodic_knots). A last point equal to the first is the closing point and is
  /// left out (closing_point); otherwise the curve closes from the last point back
  /// to the first. The points need at least degree + 1 distinct ones.
  bool periodic = false;
};

struct CurveInterpolation {
  BSplineCurve curve;
  std::vector<double> params;  ///< where the curve passes through each point (a closing point: 1)
};

/// The B-spline curve of the given degree through every point.
///
/// Example:
/// @code
///   using namespace interpatch;
///   std::vector<Vec3> q{{0, 0, 0}, {1, 2, 0}, {3, 3, 0}, {4, 0, 1}};
///   auto r = interpolate_curve(q);  // cubic, chord-length parameters
///   Vec3 p = r.curve.point(r.params[2]);  // == q[2] up to rounding
/// @endcode
/// A closed curve:
/// @code
///   CurveInterpolationOptions closed;
///   closed.periodic = true;
///   std::vector<Vec3> ring{{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 0, 0}};  // last repeats the first
///   auto c = interpolate_curve(ring, closed);  // 4 control points, C2 at the seam too
///   Vec3 same = c.curve.point(1.25);           // == c.curve.point(0.25): parameters wrap
/// @endcode
/// @throws error too_few_points, invalid_degree, not_finite, zero_chord, non_increasing, singular,
///   closing_gap, wrong_type (end derivatives on a periodic curve).
[[nodiscard]] CurveInterpolation interpolate_curve(std::span<const Vec3> points,
                                                   const CurveInterpolationOptions& options = {});

struct SurfaceInterpolationOptions {
  /// Degrees in u and v; unset means min(3, points − 1) in that direction.
  std::optional<int> degree_u, degree_v;
  Parametrization param = Parametrization::chord;
  progress_callback progress;
  /// Closed directions, u then v: every line along a closed direction is closed as a
  /// periodic curve is (interpolate_curve), its parameters averaged over the lines
  /// with their closing chords; a last line equal to the first is left out. The
  /// surface is C^(p−1) across the seam.
  std::array<bool, 2> periodic{false, false};
};

struct SurfaceInterpolation {
  BSplineSurface surface;
  /// S(params_u[p], params_v[q]) = Q[p][q]; a closing line left out has parameter
  /// params[0] + 1 (the first line's, one period on).
  std::vector<double> params_u, params_v;
};

/// Parameters of a grid along `axis` (0: u, 1: v): each line of points along the
/// axis gets chord parameters; lines of zero length (a pole) are left out; the rest
/// are averaged.
/// @throws error too_few_points, not_finite, zero_chord (every line has a zero
///   chord at the same place, or all lines have zero length).
[[nodiscard]] std::vector<double> grid_parameters(const PointGrid& points, int axis, Parametrization param);

/// The B-spline surface with exactly (n+1) × (m+1) control points through every
/// point Q[p][q] of the grid (first index along u): rows first, then across (seed
/// 003). Two banded solves, each factored once; the control points are computed in
/// place of a copy of the data.
///
/// Example:
/// @code
///   using namespace interpatch;
///   PointGrid q({7, 13});
///   for (int i = 0; i < 7; ++i)
///     for (int j = 0; j < 13; ++j) q(i, j) = {double(i), double(j), std::sin(i + 0.5 * j)};
///   auto r = interpolate_surface(q);  // bicubic
///   Vec3 p = r.surface.point(r.params_u[3], r.params_v[5]);  // == q(3, 5) up to rounding
/// @endcode
/// A pipe, closed in v:
/// @code
///   SurfaceInterpolationOptions pipe;
///   pipe.periodic = {false, true};
///   PointGrid ring({5, 12});
///   for (int i = 0; i < 5; ++i)
///     for (int j = 0; j < 12; ++j) ring(i, j) = {std::cos(j * M_PI / 6), std::sin(j * M_PI / 6), double(i)};
///   auto tube = interpolate_surface(ring, pipe);  // 5 x 12 control points, C2 around
/// @endcode
/// @throws error too_few_points, invalid_degree, not_finite, zero_chord, singular, too_large, closing_gap.
[[nodiscard]] SurfaceInterpolation interpolate_surface(PointGrid points, const SurfaceInterpolationOptions& options = {});

struct VolumeInterpolationOptions {
  /// Degrees in u, v and w; unset means min(3, points − 1) in that direction.
  std::optional<int> degree_u, degree_v, degree_w;
  Parametrization param = Parametrization::chord;
  progress_callback progress;
  /// Closed directions u, v, w, as for surfaces.
  std::array<bool, 3> periodic{false, false, false};
};

struct VolumeInterpolation {
  BSplineVolume volume;
  std::vector<double> params_u, params_v, params_w;  ///< S(params_u[i], params_v[j], params_w[k]) = Q[i][j][k]
};

/// Parameters of a volume grid along `axis` (0: u, 1: v, 2: w): as for surfaces, each
/// of the lines of points along the axis gets chord parameters, lines of zero length
/// (a collapsed edge or face) are left out, the rest are averaged.
/// @throws error too_few_points, not_finite, zero_chord (every line has a zero chord at
///   the same place, or all lines have zero length), too_large.
[[nodiscard]] std::vector<double> grid_parameters(const PointGrid3& points, int axis, Parametrization param);

/// The B-spline volume with exactly (n+1) × (m+1) × (l+1) control points through every
/// point Q[i][j][k] of the grid (indices along u, v, w): the three-pass tensor extension
/// of interpolate_surface . Every line along u is interpolated, then every
/// line of the result along v, then along w; each pass is one banded solve factored
/// once, computed in place of the data.
///
/// Example:
/// @code
///   using namespace interpatch;
///   PointGrid3 q({5, 6, 4});
///   for (int i = 0; i < 5; ++i)
///     for (int j = 0; j < 6; ++j)
///       for (int k = 0; k < 4; ++k) q(i, j, k) = {double(i), double(j) + 0.1 * i * i, double(k) + std::sin(i + j)};
///   auto r = interpolate_volume(q);  // degrees (3, 3, 3)
///   Vec3 p = r.volume.point(r.params_u[2], r.params_v[3], r.params_w[1]);  // == q(2, 3, 1) up to rounding
/// @endcode
/// @throws error too_few_points (fewer than 2 points along an axis, or fewer than the
///   degree needs), invalid_degree, not_finite (naming [i][j][k]), zero_chord, singular, too_large,
///   closing_gap.
[[nodiscard]] VolumeInterpolation interpolate_volume(PointGrid3 points, const VolumeInterpolationOptions& options = {});

}  // namespace interpatch
