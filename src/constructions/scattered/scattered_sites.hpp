#pragma once
// Where each scattered point sits (its site (u, v)), which points count, and the
// domain the net covers: the first step of approximate_scattered.

#include <array>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "interpatch/approximate.hpp"

namespace interpatch::detail::scattered {

struct Sites {
  std::vector<double> weight;  ///< per point; 0 for a missing one
  std::array<std::array<double, 2>, 2> domain{};
  Vec3 origin{}, axis_u{}, axis_v{};  ///< ScatteredParam::plane
  std::size_t present = 0, missing = 0;
  double weight_sum = 0;
  ScatteredParam param = ScatteredParam::plane;
  std::span<const Vec3> points;
  std::span<const std::array<double, 2>> given;  ///< ScatteredParam::sites

  /// Point k's site (u, v); NaN for a point not present. Derived from the point (or the
  /// site given) on each call rather than stored: a million sites are 16 MB.
  [[nodiscard]] std::array<double, 2> uv(std::size_t k) const {
    if (!(weight[k] > 0)) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    switch (param) {
      case ScatteredParam::xy: return {points[k].x, points[k].y};
      case ScatteredParam::plane: {
        const Vec3 d = points[k] - origin;
        return {dot(d, axis_u), dot(d, axis_v)};
      }
      case ScatteredParam::sites: break;
    }
    return given[k];
  }
};

/// The sites, weights and domain of `points` as `o` asks, checked: a NaN coordinate
/// marks a missing point; an infinite one, a bad weight, sites of another count, too few
/// points for the degrees, points (or sites) all on one line are refused.
Sites scattered_sites(std::span<const Vec3> points, const ScatteredApproximationOptions& o, int p, int q);

}  // namespace interpatch::detail::scattered
