#pragma once
// The row-split fit's data term Σ w B Bᵀ of the normal equations, each process
// summing its rows' points and the sums of control rows that straddle two blocks
// handed on in process order, so that every entry is the single process's sum; and
// the sparse system made of it.

#include <algorithm>
#include <array>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_normal.hpp"
#include "constructions/interpolate/grid_rows.hpp"

namespace interpatch::detail::approx {

// Data rows [first, first + count) of a surface's grid held by this process: their
// part of the data term Σ w B Bᵀ, summed as one process sums it (point after point)
// and gathered into st on every process. A control row's entries take sums over the
// data rows its basis functions reach, in order: the rows whose data lie in one
// process's block are summed there, all at once; those whose data straddle the
// block before (a few rows at each boundary) start from the sums the processes
// before have reached, handed on in order, and go on with this process's points.
template <class Weight>
void add_block_data(Stencil<2>& st, const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b,
                    const Weight& weight, const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process(), c0 = st.c[0], c1 = st.c[1];
  const std::size_t row_len = c1 * st.size;  // doubles of a control row of the stencil
  const std::size_t base = b.first * shape[1], mine = b.count * shape[1];
  const Axis& u = axes[0];
  // The control rows each process's data rows reach: [lo, hi], −1 for none.
  const double lo_here = b.count > 0 ? static_cast<double>(u.first[b.first]) : -1.0;
  const double hi_here = b.count > 0 ? static_cast<double>(u.first[b.first + b.count - 1] + u.p) : -1.0;
  const std::vector<double> los = team.gather(std::vector<double>{lo_here}), his = team.gather(std::vector<double>{hi_here});
  auto has = [&](std::size_t r) { return los[r] >= 0; };
  auto lo_of = [&](std::size_t r) { return static_cast<std::size_t>(los[r]); };
  auto hi_of = [&](std::size_t r) { return static_cast<std::size_t>(his[r]); };
  auto before = [&](std::size_t r) {  // the last process before r with data rows, P for none
    for (std::size_t q = r; q-- > 0;)
      if (has(q)) return q;
    return P;
  };
  auto after = [&](std::size_t r) {
    for (std::size_t q = r + 1; q < P; ++q)
      if (has(q)) return q;
    return P;
  };
  // Rows [s_lo, s_hi] of process r continue the sums of the processes before it.
  auto continued = [&](std::size_t r) -> std::pair<std::size_t, std::size_t> {
    const std::size_t q = before(r);
    if (!has(r) || q == P || hi_of(q) < lo_of(r)) return {1, 0};
    return {lo_of(r), std::min(hi_of(r), hi_of(q))};
  };
  const std::pair<std::size_t, std::size_t> mine_continued = continued(me);
  const std::size_t s_lo = mine_continued.first, s_hi = mine_continued.second;
  auto in_continued = [&](std::size_t row) { return row / c1 >= s_lo && row / c1 <= s_hi; };
  add_weighted_points<2>(st.v.data(), st, axes, shape, base, mine, weight, [&](std::size_t row) { return !in_continued(row); });
  std::size_t width = 0;
  for (std::size_t r = 0; r < P; ++r) {
    const std::pair<std::size_t, std::size_t> c = continued(r);
    if (c.second >= c.first) width = std::max(width, c.second - c.first + 1);
  }
  std::vector<double> acc(width * row_len, 0.0);
  team.fold(acc, [&](std::span<double> a) {
    if (!has(me)) return;  // hands on what it got
    if (s_hi >= s_lo) {
      std::copy_n(a.data(), (s_hi - s_lo + 1) * row_len, st.v.data() + s_lo * row_len);
      add_weighted_points<2>(st.v.data(), st, axes, shape, base, mine, weight, in_continued);
    }
    if (const std::size_t next = after(me); next < P) {
      const std::pair<std::size_t, std::size_t> c = continued(next);
      if (c.second >= c.first) std::copy_n(st.v.data() + c.first * row_len, (c.second - c.first + 1) * row_len, a.data());
    }
  });
  // Each control row from the last process that added to it: process r the rows from
  // its first (0 for the first process with data) up to the next one's first.
  std::size_t own_lo = 0, own_hi = 0;
  if (has(me)) {
    own_lo = before(me) == P ? 0 : lo_of(me);
    own_hi = after(me) == P ? c0 : lo_of(after(me));
  }
  std::vector<double> all = team.gather(std::span<const double>(st.v.data() + own_lo * row_len, (own_hi - own_lo) * row_len));
  INTERPATCH_ASSERT(all.size() == st.v.size());
  st.v = std::move(all);
}

// add_block_data along a closed u. There the basis functions of the data rows near
// the seam wrap: the first rows (of an even degree, whose period starts half a step
// in) reach the last control rows, and the last rows the first ones, so a control
// row near the seam takes the sums of two runs of data rows, one at each end, the
// earlier run first. The control rows are unwrapped (data row i reaching rows
// first_i .. first_i + p, non-decreasing in i, with c0 + L rows in all, L ≤ p) and
// summed there by add_block_data; the rows past c0 repeat rows 0 .. L − 1, and
// their run of data continues the sums the earlier run reached: the processes that
// hold it add their points again to those rows, starting from the earlier sums and
// handing them on in order. Then the rows are wrapped back.
template <class Weight>
void add_closed_block_data(Stencil<2>& st, const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b,
                           const Weight& weight, const detail::RowTeam& team) {
  const Axis& u = axes[0];
  const int c0 = u.c;
  const std::size_t n = u.n;
  // Wrapped onto the knots' period, the parameters rise, drop once (where the data
  // pass the period's start) and rise again: the rows before the drop are a period lower.
  std::size_t drop = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (u.first[i] < u.first[i - 1]) {
      INTERPATCH_ASSERT(drop == 0);
      drop = i;
    }
  std::array<Axis, 2> open = axes;
  Axis& un = open[0];
  const int low = u.first[0] - (drop > 0 ? c0 : 0);
  for (std::size_t i = 0; i < n; ++i) un.first[i] = u.first[i] - (i < drop ? c0 : 0) - low;
  un.c = std::max(c0, un.first[n - 1] + u.p + 1);
  INTERPATCH_ASSERT(un.c <= 2 * c0);  // a control row repeated at most once
  Stencil<2> sw(open);
  add_block_data(sw, open, shape, b, weight, team);

  const auto extra = static_cast<std::size_t>(un.c - c0), c = static_cast<std::size_t>(c0);
  const std::size_t c1 = sw.c[1], row_len = c1 * sw.size;
  std::vector<double> late(extra * row_len, 0.0);
  if (extra > 0) {
    const std::size_t base = b.first * shape[1], mine = b.count * shape[1];
    const bool reaches = b.count > 0 && static_cast<std::size_t>(un.first[b.first + b.count - 1] + u.p) >= c;
    const std::vector<double> all = team.gather(std::vector<double>{reaches ? 1.0 : 0.0});
    const bool first_to_reach = reaches && std::find(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(team.process()), 1.0) ==
                                               all.begin() + static_cast<std::ptrdiff_t>(team.process());
    team.fold(late, [&](std::span<double> acc) {
      if (!reaches) return;  // hands on what it got
      double* rows = sw.v.data() + c * row_len;
      std::copy_n(first_to_reach ? sw.v.data() : acc.data(), extra * row_len, rows);
      add_weighted_points<2>(sw.v.data(), sw, open, shape, base, mine, weight, [&](std::size_t row) { return row / c1 >= c; });
      std::copy_n(rows, extra * row_len, acc.data());
    });
  }
  // Unwrapped row x is control row x + low, modulo c0.
  for (std::size_t x = 0; x < c; ++x) {
    const auto row = static_cast<std::size_t>(((static_cast<long long>(x) + low) % c0 + c0) % c0);
    std::copy_n(x < extra ? late.data() + x * row_len : sw.v.data() + x * row_len, row_len, st.v.data() + row * row_len);
  }
}

// The sparse normal equations of a grid held in blocks of rows (b: this process's),
// its weights summing to `weight_sum`: the data term from the Gram matrices when every
// point is present with weight 1 (`uniform`), else summed over the points
// (add_block_data; add_closed_block_data along a closed u).
template <class Weight>
SparseSystem<2> block_system(const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b, bool uniform,
                             const Weight& weight, double weight_sum, const detail::RowTeam& team) {
  Stencil<2> st(axes);
  if (uniform) add_grams<2>(st, axes);
  else if (axes[0].periodic) add_closed_block_data(st, axes, shape, b, weight, team);
  else add_block_data(st, axes, shape, b, weight, team);
  return SparseSystem<2>(axes, st, weight_sum, shape[0] * shape[1]);
}

}  // namespace interpatch::detail::approx
