// Whether the last point of a closed curve, or the last line along an axis of a
// grid, repeats the first and is left out: closing_point, grid_closing, and
// block_closing for a grid held in blocks of rows.

#include <algorithm>
#include <limits>
#include <string>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "base/text.hpp"
#include "interpatch/interpolate.hpp"

namespace interpatch {

using detail::fail;
using detail::GridBlock;
using detail::RowTeam;

namespace {

// The largest coordinate extent of points: the bounding-box diagonal.
template <class PointAt>
double box_diagonal(std::size_t count, const PointAt& point) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3& q = point(i);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], q[k]);
      hi[k] = std::max(hi[k], q[k]);
    }
  }
  return norm(hi - lo);
}

// Whether the last point of each of `lines` closed lines of n points repeats the
// first (closing_point; the rule is the same for every line of a grid, and all must
// repeat for the last line to be left out). point(l, k) is point k of line l;
// diagonal() the data's bounding-box diagonal, computed only when a gap is small.
// With a near miss, `line` is the first line that misses. A grid split between the
// processes of `team`: each passes its own lines, the first being line `first_line`
// of the grid, and all agree; `mine` says whether the near miss is among them.
struct LineEnding {
  Closing closing;
  std::size_t line = 0;
  double gap = 0, adjacent = 0, tol = 0;
  bool mine = true;
};

const RowTeam solo;  // the single process

template <class PointAt, class Diagonal>
LineEnding line_ending(std::size_t lines, std::size_t n, const PointAt& point, const Diagonal& diagonal,
                       const RowTeam& team = solo, std::size_t first_line = 0) {
  if (n < 3) return {{n, false, false}};
  bool all_zero = true, near = false;
  for (std::size_t l = 0; l < lines; ++l) {
    const double gap = distance(point(l, n - 1), point(l, 0));
    if (gap == 0.0) continue;
    all_zero = false;
    const double adjacent = std::min(distance(point(l, 1), point(l, 0)), distance(point(l, n - 1), point(l, n - 2)));
    near = near || gap < 1e-3 * adjacent;
  }
  std::size_t flags[2] = {all_zero ? 0u : 1u, near ? 1u : 0u};  // lines with a gap, processes with a near one
  team.sum(flags);
  if (flags[0] == 0) return {{n - 1, true, false}};
  if (flags[1] == 0) return {{n, false, false}};
  const double tol = 1e-12 * diagonal();
  bool all_close = true;
  for (std::size_t l = 0; l < lines && all_close; ++l) all_close = distance(point(l, n - 1), point(l, 0)) <= tol;
  std::size_t open[1] = {all_close ? 0u : 1u};
  team.sum(open);
  if (open[0] == 0) return {{n - 1, true, false}};
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  LineEnding found{{n, false, false}};
  std::size_t first[1] = {none};
  for (std::size_t l = 0; l < lines; ++l) {
    const double gap = distance(point(l, n - 1), point(l, 0));
    const double adjacent = std::min(distance(point(l, 1), point(l, 0)), distance(point(l, n - 1), point(l, n - 2)));
    if (gap > tol && gap < 1e-3 * adjacent) {
      found = {{n, false, true}, first_line + l, gap, adjacent, tol};
      first[0] = found.line;
      break;
    }
  }
  team.min(first);
  if (first[0] == none) return {{n, false, false}};
  if (found.closing.nearly && found.line == first[0]) return found;
  LineEnding other{{n, false, true}, first[0]};
  other.mine = false;
  return other;
}

// line_ending, a near miss refused (by the process whose line it is); where(l) names
// line l's last point.
template <class PointAt, class Diagonal, class Where>
Closing find_closing(std::size_t lines, std::size_t n, const PointAt& point, const Diagonal& diagonal,
                     const Where& where, const RowTeam& team = solo, std::size_t first_line = 0) {
  const LineEnding e = line_ending(lines, n, point, diagonal, team, first_line);
  if (e.closing.nearly)
    team.run([&] {
      if (!e.mine) return;
      const std::size_t l = e.line - first_line;
      fail(errc::closing_gap, where(l), " = ", point(l, n - 1), " nearly repeats the first point ", point(l, 0),
           ": gap ", e.gap, ", more than the ", e.tol,
           " (1e-12 of the bounding-box diagonal) that makes it the closing point and less than ",
           "1e-3 of the chords next to it (", e.adjacent,
           "), which would leave a kink at the seam; repeat the first point "
           "exactly, or leave the last one out");
    });
  return e.closing;
}

template <std::size_t Rank>
Closing grid_closing_of(const Grid<Vec3, Rank>& points, int axis) {
  if (axis < 0 || axis >= static_cast<int>(Rank))
    fail(errc::out_of_domain, "axis ", axis, " is outside 0..", Rank - 1, " for a grid of rank ", Rank);
  return detail::block_closing(detail::whole_grid(points), static_cast<std::size_t>(axis), detail::end_rows(points), false,
                               solo);
}

}  // namespace

Closing closing_point(std::span<const Vec3> points) {
  return find_closing(
      1, points.size(), [&](std::size_t, std::size_t k) -> const Vec3& { return points[k]; },
      [&] { return box_diagonal(points.size(), [&](std::size_t i) -> const Vec3& { return points[i]; }); },
      [&](std::size_t) { return detail::cat("point ", points.size() - 1); });
}

Closing grid_closing(const PointGrid& points, int axis) { return grid_closing_of(points, axis); }
Closing grid_closing(const PointGrid3& points, int axis) { return grid_closing_of(points, axis); }

namespace detail {

Closing block_closing(const GridBlock& b, std::size_t axis, std::span<const Vec3* const> ends, bool refuse,
                      const RowTeam& team) {
  const GridShape g = grid_shape(b);
  const std::size_t M = g.row, n = g.n[axis];
  // The bounding-box diagonal of the whole grid; -max(-x) is min(x), bit for bit.
  auto diagonal = [&] {
    constexpr double inf = std::numeric_limits<double>::infinity();
    double box[6] = {-inf, -inf, -inf, -inf, -inf, -inf};  // -lo, hi
    for (std::size_t i = 0; i < b.count * M; ++i)
      for (int k = 0; k < 3; ++k) {
        box[k] = std::max(box[k], -b.data[i][k]);
        box[3 + k] = std::max(box[3 + k], b.data[i][k]);
      }
    team.max(box);
    return norm(Vec3{box[3], box[4], box[5]} - Vec3{-box[0], -box[1], -box[2]});
  };
  auto where_flat = [&](std::size_t flat) {
    std::string idx;
    for (std::size_t a = g.rank, rest = flat; a-- > 0; rest /= g.n[a]) idx = cat("[", rest % g.n[a], "]", idx);
    return cat("point ", idx, ", the last along ", axis_name(static_cast<int>(axis)), ",");
  };
  if (axis == 0) {  // every process has the rows it looks at: each finds the same
    auto point = [&](std::size_t l, std::size_t k) -> const Vec3& {
      return (k == 0 ? ends[0] : k == 1 ? ends[1] : k + 2 == n ? ends[2] : ends[3])[l];
    };
    auto where = [&](std::size_t l) { return where_flat((n - 1) * M + l); };
    Closing c;
    team.run([&] {
      c = refuse ? find_closing(M, n, point, diagonal, where) : line_ending(M, n, point, diagonal).closing;
    });
    return c;
  }
  std::size_t inner = 1;
  for (std::size_t a = axis + 1; a < g.rank; ++a) inner *= g.n[a];
  auto index = [&](std::size_t l, std::size_t k) { return (l / inner) * n * inner + k * inner + l % inner; };
  auto point = [&](std::size_t l, std::size_t k) -> const Vec3& { return b.data[index(l, k)]; };
  auto where = [&](std::size_t l) { return where_flat(b.first * M + index(l, n - 1)); };
  const std::size_t lines = b.count * M / n, first_line = b.first * M / n;
  if (!refuse) return line_ending(lines, n, point, diagonal, team, first_line).closing;
  return find_closing(lines, n, point, diagonal, where, team, first_line);
}

}  // namespace detail

}  // namespace interpatch
