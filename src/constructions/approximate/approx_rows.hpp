#pragma once
// Surface approximation (approximate_surface) of a grid held in blocks of whole rows
// by the processes of a RowTeam (src/mpi/): the same control points, bit for bit, as
// the single process finds, every sum over the data made in the single process's
// order: a given number of control points, smoothing (a number or "auto") and a fit
// to a tolerance, with missing points (NaN), weights, open and closed directions.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "constructions/interpolate/grid_rows.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail {

/// The power of two a fit works in for data whose largest finite coordinate is
/// `top`: 1 for ordinary data, whose squared distances lie far from either end of
/// double (top within 2^±64); otherwise the power of two near top, where the fit's
/// sums of squares, its rms and its search for knots neither overflow nor vanish.
/// Scaling by it is exact both ways.
inline double approximation_unit(double top) noexcept {
  constexpr double low = 0x1p-64, high = 0x1p64;
  if (top == 0 || (top >= low && top <= high)) return 1;
  int e = 0;
  (void)std::frexp(top, &e);
  return std::ldexp(1.0, e);
}

/// The largest absolute finite coordinate of the points (0 when there is none; NaN
/// marks a missing point).
inline double largest_coordinate(std::span<const Vec3> points) noexcept {
  double top = 0;
  for (const Vec3& q : points)
    if (is_finite(q)) top = std::max({top, std::abs(q.x), std::abs(q.y), std::abs(q.z)});
  return top;
}

/// The fitted surface, its control rows split evenly between the processes.
struct ApproxRows {
  std::array<int, 2> degree{};
  std::array<KnotVector, 2> knots{KnotVector::bezier(1), KnotVector::bezier(1)};  ///< mapped onto [0, 1]
  std::array<std::size_t, 2> net{};  ///< control points along u and v
  std::size_t first = 0;             ///< this process's first control row (even_share)
  std::vector<Vec3> rows;            ///< its control rows, C order
};

/// The approximation of the grid `b` (rows may hold NaN: missing points). Errors as
/// approximate_surface's.
/// Along a closed u, b.ends must hold the whole grid's rows 0, 1, n−2, n−1; a closed
/// v's closing column, when left out, is left out of b's rows in place.
/// `release` is called once the block's points are read no more: the caller may
/// free them then (a smoothing "auto" and a tolerance read them to the end).
ApproxRows approximate_rows(const GridBlock& b, const SurfaceApproximationOptions& o, const RowTeam& team,
                            const std::function<void()>& release = {});

}  // namespace interpatch::detail
