#pragma once
// The size of a construction's data, for its default tolerances: the diagonal of the
// control points' bounding box, and the largest coordinate. A tolerance of 1e-7 of
// the diagonal cannot hold for a small part far from the origin (0.1 across at 1e8,
// where doubles are 1.5e-8 apart): two evaluations of the same point there differ by
// a few units in the last place. Such tolerances never go below `rounding()`.

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include "interpatch/vec3.hpp"

namespace interpatch::detail {

class DataScale {
 public:
  void add(std::span<const Vec3> points) noexcept {
    for (const Vec3& p : points)
      for (int k = 0; k < 3; ++k) {
        lo_[k] = std::min(lo_[k], p[k]);
        hi_[k] = std::max(hi_[k], p[k]);
        largest_ = std::max(largest_, std::abs(p[k]));
      }
  }
  /// 0 for no points.
  [[nodiscard]] double diagonal() const noexcept { return lo_.x <= hi_.x ? norm(hi_ - lo_) : 0.0; }
  /// 16 units in the last place of the largest coordinate, but at most 1e-5 of the
  /// diagonal: a part so small for its place (1e-3 across at 1e8 keeps 5 digits) that
  /// its rounding is coarser than that is refused by its tolerances, not built loosely.
  [[nodiscard]] double rounding() const noexcept {
    return std::min(16 * std::numeric_limits<double>::epsilon() * largest_, 1e-5 * diagonal());
  }
  /// The default tolerance: 1e-7 of the diagonal, or the rounding where that is larger.
  [[nodiscard]] double strict() const noexcept { return std::max(1e-7 * diagonal(), rounding()); }

 private:
  static constexpr double inf = std::numeric_limits<double>::infinity();  // 1e300 would cap data beyond it
  Vec3 lo_{inf, inf, inf}, hi_{-inf, -inf, -inf};
  double largest_ = 0;
};

}  // namespace interpatch::detail
