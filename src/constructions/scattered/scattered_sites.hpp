#pragma once
// Where each scattered point sits (its site (u, v)), which points count, and the
// domain the net covers: the first step of approximate_scattered.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "interpatch/approximate.hpp"

namespace interpatch::detail::scattered {

struct Sites {
  /// Per point, 0 for a missing one; empty when every point is present with weight 1
  /// (8 bytes a point at the peak of a large fit's memory).
  std::vector<double> weight;
  std::array<std::array<double, 2>, 2> domain{};
  Vec3 origin{}, axis_u{}, axis_v{};  ///< ScatteredParam::plane
  std::size_t present = 0, missing = 0;
  double weight_sum = 0;
  ScatteredParam param = ScatteredParam::plane;
  std::span<const Vec3> points;
  std::span<const std::array<double, 2>> given;  ///< ScatteredParam::sites

  [[nodiscard]] std::size_t size() const { return points.size(); }
  /// Whether point k counts: present, of weight above 0.
  [[nodiscard]] bool counts(std::size_t k) const { return weight.empty() || weight[k] > 0; }
  [[nodiscard]] double weight_at(std::size_t k) const { return weight.empty() ? 1.0 : weight[k]; }

  /// Point k's site (u, v); NaN for a point not present. Derived from the point (or the
  /// site given) on each call rather than stored: a million sites are 16 MB.
  [[nodiscard]] std::array<double, 2> uv(std::size_t k) const {
    if (!counts(k)) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    return site_of(k);
  }
  /// The same for a point known to be present.
  [[nodiscard]] std::array<double, 2> site_of(std::size_t k) const {
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

/// The points present as a fit sees them: each one's unit site in the fit's domain
/// [0, range[0]] × [0, range[1]] (the longer side 1) and its value centred on `centre`
/// and scaled by `scale`, read from the points as given on each use through `order`
/// rather than copied: a copy is 24 bytes a point, a third of a large fit's memory,
/// against 4 for the order.
struct FitPoints {
  const Sites* sites = nullptr;
  /// The input index of each point present, in the order a fit visits them.
  std::vector<std::uint32_t> order;
  int cols = 3;  ///< the values' columns: 1 (z alone) or 3 (x, y, z)
  Vec3 centre{};
  double scale = 1;
  /// The domain in the fit's frame, [0, range[0]] × [0, range[1]], the longer side 1,
  /// so that the fairness weighs both directions alike.
  std::array<double, 2> range{1, 1};
  std::array<double, 2> lower{0, 0};  ///< the domain's lower corner, in the sites' units
  double side = 1;  ///< its longer side

  [[nodiscard]] std::size_t size() const { return order.size(); }
  /// Input point k's unit site, present or not (a point not present: NaN).
  [[nodiscard]] std::array<double, 2> input_unit(std::size_t k) const { return to_unit(sites->uv(k)); }
  /// Its value (cols numbers into v).
  void input_value(std::size_t k, double* v) const {
    const Vec3& q = sites->points[k];
    for (int m = 0; m < cols; ++m) {
      const int a = cols == 1 ? 2 : m;
      v[m] = (q[a] - centre[a]) * scale;
    }
  }
  /// The unit site and the value of point i in `order`.
  [[nodiscard]] std::array<double, 2> unit(std::size_t i) const { return to_unit(sites->site_of(order[i])); }
  void value(std::size_t i, double* v) const { input_value(order[i], v); }
  /// Asks for point i's input ahead of its use (nothing past the end): a pass whose
  /// work per point outlasts the processor's look-ahead otherwise waits on memory at
  /// every point (two thirds of a cubic pass's time).
  /// Inlined always: GCC takes a function holding only prefetches for one without
  /// effects and drops its calls.
  [[gnu::always_inline]] void prefetch(std::size_t i) const {
    if (i >= order.size()) return;
    __builtin_prefetch(sites->points.data() + order[i]);
    if (!sites->given.empty()) __builtin_prefetch(sites->given.data() + order[i]);
  }

 private:
  [[nodiscard]] std::array<double, 2> to_unit(std::array<double, 2> uv) const {
    return {std::clamp((uv[0] - lower[0]) / side, 0.0, range[0]), std::clamp((uv[1] - lower[1]) / side, 0.0, range[1])};
  }
};

/// The sites, weights and domain of `points` as `o` asks, checked: a NaN coordinate
/// marks a missing point; an infinite one, a bad weight, sites of another count, too few
/// points for the degrees, points (or sites) all on one line are refused.
Sites scattered_sites(std::span<const Vec3> points, const ScatteredApproximationOptions& o, int p, int q);

}  // namespace interpatch::detail::scattered
