#pragma once
// The checks every approximation passes before it is returned (docs/spec-format.md,
// "approximate": what a tolerance promises). They evaluate the finished B-spline with
// its own evaluator at the data parameters, never the fitting code's basis tables, so
// a fault in the fit cannot hide from them.

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"

namespace interpatch::detail {

/// The largest distance |S(t) − Q| over the points present, and where.
struct ApproxDistance {
  double max = 0;
  std::size_t worst = 0;  ///< flat index into the data, C order
};

/// Data of `shape` (C order, up to 3 directions, `points` of count ∏ shape), a point
/// present where finite and of weight > 0 (`weights` empty: every finite point).
struct ApproxData {
  std::vector<std::size_t> shape;
  std::span<const Vec3> points;
  std::span<const double> weights;
  [[nodiscard]] bool present(std::size_t i) const;
};

/// Distances of each approximation to its data, at the parameters of the data (one
/// list per direction, in the direction's order).
ApproxDistance approx_distance(const BSplineCurve& c, const std::vector<double>& t, const ApproxData& d);
ApproxDistance approx_distance(const BSplineSurface& s, const std::vector<double>& tu, const std::vector<double>& tv,
                               const ApproxData& d);
ApproxDistance approx_distance(const BSplineVolume& s, const std::vector<double>& tu, const std::vector<double>& tv,
                               const std::vector<double>& tw, const ApproxData& d);

/// The bounding box {lo, hi} of the points present.
std::array<Vec3, 2> approx_box(const ApproxData& d);

/// Whether every control point of a net of `rank` directions is finite and no farther
/// from `box` than 3^rank times its diagonal (check_approx_net's test).
bool approx_net_sane(std::span<const Vec3> net, std::size_t rank, const std::array<Vec3, 2>& box);

/// Refuses (ill_conditioned) a control net with a non-finite coordinate or a point
/// farther from the data's bounding box than 3^R times the box's diagonal (R the
/// directions of `net_shape`): least squares that swing between the data. `what` names the fit ("surface approximation").
void check_approx_net(std::span<const Vec3> net, const std::vector<std::size_t>& net_shape, const ApproxData& d,
                      const char* what);

/// Refuses (tolerance_not_met) a fit whose distance exceeds the tolerance, naming the
/// worst point, its distance, the tolerance and the control points reached.
void check_approx_tolerance(const ApproxDistance& e, double tolerance, const ApproxData& d,
                            const std::vector<int>& control_points);

}  // namespace interpatch::detail
