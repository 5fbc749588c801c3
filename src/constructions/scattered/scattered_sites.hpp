#pragma once
// Where each scattered point sits (its site (u, v)), which points count, and the
// domain the net covers: the first step of approximate_scattered.

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "interpatch/approximate.hpp"

namespace interpatch::detail::scattered {

struct Sites {
  std::vector<std::array<double, 2>> uv;  ///< per point; NaN for a missing one
  std::vector<double> weight;             ///< per point; 0 for a missing one
  std::array<std::array<double, 2>, 2> domain{};
  Vec3 origin{}, axis_u{}, axis_v{};      ///< ScatteredParam::plane
  std::size_t present = 0, missing = 0;
  double weight_sum = 0;
};

/// The sites, weights and domain of `points` as `o` asks, checked: a NaN coordinate
/// marks a missing point; an infinite one, a bad weight, sites of another count, too few
/// points for the degrees, points (or sites) all on one line are refused.
Sites scattered_sites(std::span<const Vec3> points, const ScatteredApproximationOptions& o, int p, int q);

}  // namespace interpatch::detail::scattered
