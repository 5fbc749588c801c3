#pragma once
// The row-split fit's checks before it returns (approx_check.hpp's, on blocks of
// rows): the control net near the data's box, and the tolerance measured with the
// finished surface's own evaluator at each process's rows.

#include <algorithm>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/interpolate/grid_rows.hpp"

namespace interpatch::detail::approx {

// This process's rows of the data as the checks of approx_check.hpp take
// them (`w` holds their weights).
template <class Weight>
detail::ApproxData block_data(const detail::GridBlock& b, const Weight& weight, std::vector<double>& w) {
  const std::size_t M = b.n[1], base = b.first * M;
  w.resize(b.count * M);
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = weight(base + i);
  return {{b.count, M}, std::span<const Vec3>(b.data, b.count * M), w};
}

// The data's bounding box over every process, as two corners (check_rows_net).
template <class Weight>
std::vector<Vec3> block_box(const detail::GridBlock& b, const Weight& weight, const detail::RowTeam& team) {
  std::vector<double> w;
  const detail::ApproxData mine = block_data(b, weight, w);
  std::vector<double> box(6, -std::numeric_limits<double>::infinity());  // −lo, hi
  for (std::size_t i = 0; i < mine.points.size(); ++i)
    if (mine.present(i))
      for (std::size_t k = 0; k < 3; ++k) {
        const double x = mine.points[i][static_cast<int>(k)];
        box[k] = std::max(box[k], -x);
        box[k + 3] = std::max(box[k + 3], x);
      }
  team.max(box);
  return {{-box[0], -box[1], -box[2]}, {box[3], box[4], box[5]}};
}

// check_approx_net on a split run, `box` from block_box: each process checks its own
// control rows (the first with a bad one reports it).
void check_rows_net(const detail::ApproxRows& out, const std::vector<Vec3>& box, const detail::RowTeam& team);

// The tolerance kept or refused on a split run, measured as approximate_surface
// measures it (the spline's own evaluator): each process at its rows, the worst
// over the processes (the first in row order among equals).
template <class Weight>
void check_rows_tolerance(const Fit<2>& f, const detail::GridBlock& b, const Weight& weight, double tol,
                          const detail::RowTeam& team) {
  PointGrid net({static_cast<std::size_t>(f.axes[0].c), static_cast<std::size_t>(f.axes[1].c)}, for_overwrite);
  std::copy_n(f.cp.data(), f.cp.size(), &net.data()->x);
  std::vector<double> w;
  detail::ApproxData mine = block_data(b, weight, w);
  detail::ApproxDistance e;
  team.run([&] {
    const BSplineSurface s(f.axes[0].knots, f.axes[1].knots, std::move(net));
    if (b.count > 0) {
      const std::vector<double> tu(f.axes[0].t.begin() + static_cast<std::ptrdiff_t>(b.first),
                                   f.axes[0].t.begin() + static_cast<std::ptrdiff_t>(b.first + b.count));
      e = detail::approx_distance(s, tu, f.axes[1].t, mine);
    }
  });
  const std::vector<double> all = team.gather(std::vector<double>{e.max, static_cast<double>(b.first * b.n[1] + e.worst)});
  detail::ApproxDistance worst;
  for (std::size_t k = 0; k < all.size(); k += 2)
    if (all[k] > worst.max) worst = {all[k], static_cast<std::size_t>(all[k + 1])};
  mine.shape = {b.n[0], b.n[1]};
  std::vector<int> cps{f.axes[0].c, f.axes[1].c};
  team.run([&] { detail::check_approx_tolerance(worst, tol, mine, cps); });
}

}  // namespace interpatch::detail::approx
