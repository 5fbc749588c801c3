#pragma once
// The bounding box of points, and its diagonal: the size the io library measures
// data by (info's relative error).

#include <algorithm>
#include <limits>

#include "interpatch/vec3.hpp"

namespace interpatch::io::internal {

struct Box {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi = -lo;
  void add(const Vec3& p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  /// 0 for a box of no points.
  [[nodiscard]] double diagonal() const { return lo.x <= hi.x ? norm(hi - lo) : 0.0; }
};

}  // namespace interpatch::io::internal
