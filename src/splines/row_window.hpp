#pragma once
// Control points of a B-spline surface or volume held as a window of rows along u
// (a surface's rows, a volume's planes): the whole net, or the rows one process of a
// split run holds (src/mpi/). Evaluation through a window computes every point by the
// same operations as the whole surface or volume does.

#include <cstddef>
#include <span>

#include "interpatch/knot_vector.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail {

/// Window row v, for v from `first` (negative, or past the net's end, around a
/// periodic u), holds net row v modulo `rows`, at data + (v − first) · row_size.
struct RowWindow {
  const Vec3* data = nullptr;
  long long first = 0;
  std::size_t count = 0;     ///< rows in the window
  std::size_t rows = 0;      ///< rows of the net
  std::size_t row_size = 0;  ///< points in a row
  /// Net row i (0 ≤ i < rows), which the window must hold.
  [[nodiscard]] const Vec3* row(std::size_t i) const noexcept {
    auto v = static_cast<long long>(i);
    const auto n = static_cast<long long>(rows);
    if (v < first) v += n;
    else if (v >= first + static_cast<long long>(count)) v -= n;
    return data + static_cast<std::size_t>(v - first) * row_size;
  }
};

/// The points of the polynomial surface of knots ku, kv and control rows `net` at
/// every (us[i], vs[j]), into out[i · |vs| + j]: BSplineSurface::evaluate_into.
void evaluate_surface_rows(const KnotVector& ku, const KnotVector& kv, const RowWindow& net, std::span<const double> us,
                           std::span<const double> vs, std::span<Vec3> out, const progress_callback& progress = {});

/// The same for a polynomial volume: BSplineVolume::evaluate_into.
void evaluate_volume_rows(const KnotVector& ku, const KnotVector& kv, const KnotVector& kw, const RowWindow& net,
                          std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                          std::span<Vec3> out, const progress_callback& progress = {});

}  // namespace interpatch::detail
