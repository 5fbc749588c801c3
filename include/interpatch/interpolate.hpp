#pragma once
/// @file interpolate.hpp
/// Global B-spline interpolation of curves and of grids of points, surfaces and
/// volumes (The NURBS Book §9.2), solved as banded systems factored once.

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

struct CurveInterpolationOptions {
  /// Degree; unset means min(3, points − 1).
  std::optional<int> degree;
  Parametrization param = Parametrization::chord;
  /// Given parameters (increasing) instead of `param`.
  std::vector<double> params;
  /// Derivative dC/dt at the first / last point, t in [0, 1].
  std::optional<Vec3> start_derivative, end_derivative;
};

struct CurveInterpolation {
  BSplineCurve curve;
  std::vector<double> params;  ///< where the curve passes through each point
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
/// @throws error too_few_points, invalid_degree, not_finite, zero_chord, non_increasing, singular.
[[nodiscard]] CurveInterpolation interpolate_curve(std::span<const Vec3> points,
                                                   const CurveInterpolationOptions& options = {});

struct SurfaceInterpolationOptions {
  /// Degrees in u and v; unset means min(3, points − 1) in that direction.
  std::optional<int> degree_u, degree_v;
  Parametrization param = Parametrization::chord;
  progress_callback progress;
};

struct SurfaceInterpolation {
  BSplineSurface surface;
  std::vector<double> params_u, params_v;  ///< S(params_u[p], params_v[q]) = Q[p][q]
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
/// @throws error too_few_points, invalid_degree, not_finite, zero_chord, singular, too_large.
[[nodiscard]] SurfaceInterpolation interpolate_surface(PointGrid points, const SurfaceInterpolationOptions& options = {});

struct VolumeInterpolationOptions {
  /// Degrees in u, v and w; unset means min(3, points − 1) in that direction.
  std::optional<int> degree_u, degree_v, degree_w;
  Parametrization param = Parametrization::chord;
  progress_callback progress;
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
///   degree needs), invalid_degree, not_finite (naming [i][j][k]), zero_chord, singular, too_large.
[[nodiscard]] VolumeInterpolation interpolate_volume(PointGrid3 points, const VolumeInterpolationOptions& options = {});

}  // namespace interpatch
