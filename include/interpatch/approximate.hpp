#pragma once
/// @file approximate.hpp
/// Least-squares approximation of noisy and incomplete data: curves through a
/// sequence of points, surfaces through a grid, volumes through a 3-D grid. The
/// result is a B-spline that passes near the data rather than through it: with a
/// given number of control points, with the fewest control points that keep every
/// data point within a tolerance, or with a fairness (smoothing) term whose weight
/// is given or chosen by generalized cross-validation.
///
/// Missing points: a point with a NaN coordinate is no data. It gets weight 0 and
/// the fairness term fills the hole smoothly, whatever the hole's shape (whole
/// rows and columns included).
///
/// The fit minimizes
///
///   E(S) = (1 / Σw) Σ w_i |S(t_i) − Q_i|²  +  λ J(S),
///
/// J the fairness of S: for each direction a, the squared second derivative along
/// a of the lines of S through the data parameters of the other directions,
/// integrated along a and averaged over those lines; the second derivative is the
/// second divided difference of the line's control polygon over its Greville
/// abscissae (which follows the second derivative as the knots get finer, and
/// takes degree 1 too). J vanishes exactly on the multilinear functions of the parameters
/// (a + b u + c v + d u v for a surface): λ → ∞ gives the least-squares
/// multilinear fit, λ → 0 the plain least-squares fit (interpolation when there
/// are as many control points as data points). λ does not depend on the scale of
/// the data.
///
/// The solver keeps the tensor structure: with every point present and equal
/// weights, the normal equations of the plain least-squares fit are a Kronecker
/// product of banded matrices, solved direction by direction in O(N); with
/// missing points, weights or a fairness term, the normal equations (of the
/// control points only, never of the whole grid) are a sparse matrix factored by
/// a sparse Cholesky decomposition.

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/progress.hpp"

namespace interpatch {

/// How an approximation is set up, for data of `Rank` directions (1: a curve, 2: a
/// surface, 3: a volume). Exactly one of `control_points`, `tolerance` and
/// `smoothing` (or `auto_smoothing`) is given.
template <std::size_t Rank>
struct ApproximationOptions {
  /// Degrees; unset means min(3, points − 1) in that direction.
  std::array<std::optional<int>, Rank> degree{};
  /// Parameters of the data: as interpolation, averaged over the lines of the grid
  /// (a missing point leaves out the two chords next to it). With `uniform`,
  /// point p of n + 1 sits at p / n.
  Parametrization param = Parametrization::chord;
  /// Closed directions, as for interpolation (a last line equal to the first is left out).
  std::array<bool, Rank> periodic{};
  /// Least squares with this many control points per direction (degree + 1 up to the
  /// number of data points along that direction).
  std::optional<std::array<int, Rank>> control_points;
  /// The fewest control points found with every data point within this distance of
  /// the approximation: knots are inserted in the spans where the error is largest,
  /// refitting each time, up to as many control points as data (interpolation). A
  /// promise: every point present is within it, checked on the finished spline by
  /// its own evaluator; when the finest fit misses it, tolerance_not_met is thrown.
  std::optional<double> tolerance;
  /// The fairness weight λ ≥ 0 over one control point per data point along each
  /// direction, at most `smoothing_max_control_points`.
  std::optional<double> smoothing;
  /// λ chosen by generalized cross-validation (instead of `smoothing`).
  bool auto_smoothing = false;
  /// Non-negative weights, one per data point (same shape as the data); empty means 1.
  Grid<double, Rank> weights;
  progress_callback progress;
};

/// The most control points per direction of a smoothing fit: longer directions get
/// this many, knots placed by the least-squares rule.
inline constexpr int smoothing_max_control_points = 128;

/// The most control points per direction of a scattered smoothing fit (one per point
/// present along each direction below it).
inline constexpr int smoothing_max_scattered = 1024;

using CurveApproximationOptions = ApproximationOptions<1>;
using SurfaceApproximationOptions = ApproximationOptions<2>;
using VolumeApproximationOptions = ApproximationOptions<3>;

/// How close an approximation came to its data.
struct ApproximationReport {
  double max_error = 0;                  ///< largest distance |S(t_i) − Q_i| over the points present
  std::vector<std::size_t> max_error_at; ///< index of that point (one per direction)
  double rms_error = 0;                  ///< root mean square of the distances over the points present
  std::vector<int> control_points;       ///< per direction
  double lambda = 0;                     ///< the fairness weight used (a small one fills holes)
  std::size_t missing = 0;               ///< points with a NaN coordinate
  int fits = 0;                          ///< least-squares solves made (tolerance: one per refinement)
};

struct CurveApproximation {
  BSplineCurve curve;
  std::vector<double> params;  ///< data parameters (a closing point: params[0] + 1)
  ApproximationReport report;
};

struct SurfaceApproximation {
  BSplineSurface surface;
  std::vector<double> params_u, params_v;
  ApproximationReport report;
};

struct VolumeApproximation {
  BSplineVolume volume;
  std::vector<double> params_u, params_v, params_w;
  ApproximationReport report;
};

/// A B-spline curve near the points (see the file comment for what is minimized).
///
/// Example:
/// @code
///   using namespace interpatch;
///   std::vector<Vec3> q;
///   for (int i = 0; i <= 40; ++i) q.push_back({i / 40.0, std::sin(i / 8.0) + 0.01 * ((i * 7) % 3 - 1), 0});
///   CurveApproximationOptions o;
///   o.tolerance = 0.02;
///   auto r = approximate_curve(q, o);  // r.report.max_error <= 0.02, far fewer than 41 control points
/// @endcode
/// @throws error wrong_type (not exactly one of control_points, tolerance, smoothing,
///   auto_smoothing;
///   tolerance ≤ 0; negative smoothing), too_few_points (all points missing, more
///   control points than data, fewer than degree + 1), invalid_degree, not_finite
///   (an infinite coordinate, a NaN weight), size_mismatch (weights of another
///   shape), invalid_weight (a negative weight), zero_chord, singular, too_large,
///   tolerance_not_met (the finest fit still leaves a point farther than the
///   tolerance: missing points, or a tolerance below rounding; the message names the
///   point, its distance, the tolerance and the control points reached),
///   ill_conditioned (a control point farther than 3^Rank times the data's
///   bounding-box diagonal from that box, or not finite: a fit that swings between
///   or beyond the data).
[[nodiscard]] CurveApproximation approximate_curve(std::span<const Vec3> points, const CurveApproximationOptions& options);

/// A B-spline surface near the grid Q[p][q] ((n+1) × (m+1), first index along u),
/// NaN marking missing points.
///
/// Example:
/// @code
///   using namespace interpatch;
///   PointGrid q({30, 40});
///   for (int i = 0; i < 30; ++i)
///     for (int j = 0; j < 40; ++j) q(i, j) = {i / 29.0, j / 39.0, std::sin(i / 5.0) * std::cos(j / 7.0)};
///   for (int j = 0; j < 40; ++j) q(12, j).z = std::nan("");  // a missing row
///   SurfaceApproximationOptions o;
///   o.param = Parametrization::uniform;  // a grid sampled evenly: its parameters are its indices
///   o.tolerance = 1e-3;
///   auto r = approximate_surface(q, o);  // the row is filled smoothly; r.report.missing == 40
/// @endcode
/// @throws error as approximate_curve.
[[nodiscard]] SurfaceApproximation approximate_surface(PointGrid points, const SurfaceApproximationOptions& options);

/// A B-spline volume near the grid Q[i][j][k] (indices along u, v, w), NaN marking
/// missing points.
///
/// Example:
/// @code
///   using namespace interpatch;
///   PointGrid3 q({8, 9, 10});
///   for (int i = 0; i < 8; ++i)
///     for (int j = 0; j < 9; ++j)
///       for (int k = 0; k < 10; ++k) q(i, j, k) = {double(i), double(j), k + 0.1 * std::sin(i + j)};
///   VolumeApproximationOptions o;
///   o.control_points = std::array<int, 3>{5, 5, 5};
///   auto r = approximate_volume(q, o);  // 5 x 5 x 5 control points, least squares
/// @endcode
/// @throws error as approximate_curve.
[[nodiscard]] VolumeApproximation approximate_volume(PointGrid3 points, const VolumeApproximationOptions& options);

/// Where each point of a scattered approximation sits in the parameter plane.
enum class ScatteredParam {
  /// The projection onto the least-squares plane of the points: u along its principal
  /// axis of larger extent, v along the other, both in the points' unit of length.
  plane,
  /// A height field: u = x, v = y. Only z is fitted; the control points' x and y are
  /// the Greville abscissae, so x(u, v) = u and y(u, v) = v to rounding.
  xy,
  /// The sites given in ScatteredApproximationOptions::sites, the general scheme.
  sites,
};

/// How a scattered approximation is set up. Exactly one of `control_points`,
/// `tolerance`, `smoothing` and `auto_smoothing` is given.
struct ScatteredApproximationOptions {
  /// Degrees in u and v; unset means 3.
  std::array<std::optional<int>, 2> degree{};
  ScatteredParam param = ScatteredParam::plane;
  /// With ScatteredParam::sites: (u_k, v_k) of each point, as many as the points.
  std::vector<std::array<double, 2>> sites;
  /// The domain [[u0, u1], [v0, v1]]; unset: the bounding rectangle of the sites of
  /// the points present. It must hold every such site.
  std::optional<std::array<std::array<double, 2>, 2>> domain;
  /// Least squares (with the small fairness term that fills voids) on uniform knots
  /// with this many control points in u and v.
  std::optional<std::array<int, 2>> control_points;
  /// Every point present within this distance of S(u_k, v_k): uniform knots, their
  /// spans doubled in both directions until it holds. A promise, checked on the
  /// finished spline by its own evaluator; tolerance_not_met when the net would pass
  /// `max_control_points`.
  std::optional<double> tolerance;
  /// The fairness weight λ ≥ 0, on a net of about one control point per point present
  /// (at most smoothing_max_scattered a direction).
  std::optional<double> smoothing;
  /// λ chosen by cross-validation on the same net (instead of `smoothing`): the
  /// points present split into 5 folds by their coordinates, and the λ whose fits
  /// predict held-out points best (ApproximationReport::lambda) is kept.
  bool auto_smoothing = false;
  /// The largest net a tolerance may reach, per direction; unset: 4096 a direction and
  /// at most one control point per 4 points present (and never fewer than 64 × 64):
  /// finer nets leave most knot cells without a point, held by the small fairness term
  /// alone, and the fit swings between the points.
  std::optional<std::array<int, 2>> max_control_points;
  /// Non-negative weights, one per point; empty means 1.
  std::vector<double> weights;
  progress_callback progress;
};

/// A scattered approximation, its sites and its report (max_error_at holds one index).
struct ScatteredApproximation {
  /// Over `domain`: with ScatteredParam::xy, x(u, v) = u and y(u, v) = v.
  BSplineSurface surface;
  /// (u_k, v_k) of every point; NaN for a missing one.
  std::vector<std::array<double, 2>> sites;
  std::array<std::array<double, 2>, 2> domain{};
  /// ScatteredParam::plane: u = (p − origin) · axis_u, v = (p − origin) · axis_v.
  Vec3 origin{}, axis_u{}, axis_v{};
  ApproximationReport report;
};

/// A B-spline surface near points without a grid (survey points, scans, boreholes).
/// It minimizes
///
///   E(S) = (1 / Σw) Σ w_k |S(u_k, v_k) − Q_k|²  +  λ J(S),
///
/// J the thin-plate energy ∫∫ S_uu² + 2 S_uv² + S_vv² over the domain scaled to a
/// longer side of 1 (both directions alike), on the control net (second divided differences over the Greville
/// abscissae). J vanishes on the planes a + b u + c v: λ → ∞ gives the least-squares
/// plane. With `control_points` or `tolerance`, λ is 1e-5 of the data term's mean
/// diagonal over J's: too small to pull the fit from its data, large enough to fill
/// voids and the region outside the points smoothly, bounded by the data around them.
///
/// The normal equations are assembled in one pass over the points, each touching
/// (p+1)(q+1) basis functions, into a banded matrix of the control net (no dense
/// matrix, memory O(N + control points)), and solved by a sparse LDLᵀ decomposition up
/// to 4 096 control points, beyond by conjugate gradients preconditioned by multigrid
/// (the same fit on nets of halved spans). `auto_smoothing` chooses λ by 5-fold
/// cross-validation. The result has the same bits on any number of threads.
///
/// Example:
/// @code
///   using namespace interpatch;
///   std::vector<Vec3> q;
///   for (int k = 0; k < 2000; ++k) {
///     const double x = std::fmod(k * 0.618034, 1.0), y = std::fmod(k * 0.414214, 1.0);
///     q.push_back({100 * x, 80 * y, 5 * std::sin(x * 6) * std::cos(y * 4)});
///   }
///   ScatteredApproximationOptions o;
///   o.param = ScatteredParam::xy;
///   o.tolerance = 0.05;
///   auto r = approximate_scattered(q, o);  // z = f(x, y); every point within 0.05
/// @endcode
/// @throws error wrong_type (not exactly one of control_points, tolerance, smoothing,
///   auto_smoothing;
///   tolerance ≤ 0; negative smoothing), too_few_points (fewer points present than
///   (p+1)(q+1), fewer control points than p + 1), invalid_degree, not_finite (an
///   infinite coordinate or site, a NaN weight), size_mismatch (sites or weights of
///   another count), invalid_weight, singular (every point on one line, or every site
///   on one line: no plane), out_of_domain (a site outside `domain`), too_large,
///   tolerance_not_met, ill_conditioned.
[[nodiscard]] ScatteredApproximation approximate_scattered(std::span<const Vec3> points,
                                                           const ScatteredApproximationOptions& options);

}  // namespace interpatch
