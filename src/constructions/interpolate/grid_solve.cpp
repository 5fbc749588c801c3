// The grid interpolation's steps on the rows a process holds (solve_grid_rows), for
// the single process and for a grid split between processes alike: closing lines,
// degrees, scale, the row solves, the transposes between blocks of rows and blocks
// of columns around the solve along u, and the seams of closed axes.

#include <algorithm>
#include <string>
#include <tuple>
#include <type_traits>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "linalg/banded.hpp"
#include "base/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail {

namespace {

// Gives a buffer's memory back now (v = {} would keep its capacity).
template <class Values>
void release(Values& v) {
  Values().swap(v);
}

// Values as a Grid and back: the grid's own storage moves; a plain vector is copied
// (and given back before the grid is handed on).
template <std::size_t R, class Values>
Grid<Vec3, R> as_grid(Values& v, const std::array<std::size_t, R>& shape) {
  if constexpr (std::is_same_v<Values, typename Grid<Vec3, R>::storage_type>) {
    return Grid<Vec3, R>(shape, std::move(v));
  } else {
    Grid<Vec3, R> g(shape, for_overwrite);
    std::copy(v.begin(), v.end(), g.data());
    release(v);
    return g;
  }
}

template <std::size_t R, class Values>
void take_grid(Grid<Vec3, R>& g, Values& v) {
  if constexpr (std::is_same_v<Values, typename Grid<Vec3, R>::storage_type>) v = std::move(g.values());
  else v.assign(g.data(), g.data() + g.size());
}

// The shape of `rows` rows of extents n.
template <std::size_t R>
std::array<std::size_t, R> rows_shape(const std::array<std::size_t, 3>& n, std::size_t rows) {
  std::array<std::size_t, R> s{};
  s[0] = rows;
  for (std::size_t a = 1; a < R; ++a) s[a] = n[a];
  return s;
}

template <std::size_t Rank>
void check_extents(const std::array<std::size_t, 3>& n) {
  auto dims = [&](bool wanted) {  // "2 x 2 x 2" or the actual "nu x nv x nw"
    std::string s;
    for (std::size_t a = 0; a < Rank; ++a) s += cat(a ? " x " : "", wanted ? std::size_t{2} : n[a]);
    return s;
  };
  if (std::any_of(n.begin(), n.begin() + Rank, [](std::size_t e) { return e < 2; }))
    fail(errc::too_few_points, Rank == 2 ? "surface" : "volume", " interpolation needs at least ", dims(true),
         " points, got ", dims(false));
}

// Closed directions: a last line repeating the first is left out.
template <std::size_t Rank, class Values>
std::array<bool, 3> drop_closing_lines(HeldRows<Rank, Values>& held, const std::array<bool, 3>& periodic,
                                       const RowTeam& team) {
  std::array<bool, 3> dropped{};
  for (std::size_t a = 0; a < Rank; ++a) {
    const GridBlock b = held.block();
    if (!periodic[a] || !block_closing(b, a, b.ends, true, team).dropped) continue;
    dropped[a] = true;
    if (a == 0) {
      --held.n[0];
      if (!held.whole()) held.halo[4] = held.halo[3];  // the new last row
      if (held.first + held.count > held.n[0]) {
        held.count = held.n[0] - held.first;
        held.rows.resize(held.count * held.row_size());
      }
      continue;
    }
    Grid<Vec3, Rank> g = as_grid(held.rows, rows_shape<Rank>(held.n, held.count));
    drop_last_line(g, a);
    take_grid(g, held.rows);
    for (Values& h : held.halo) {
      if (h.empty()) continue;
      Grid<Vec3, Rank> row = as_grid(h, rows_shape<Rank>(held.n, 1));
      drop_last_line(row, a);
      take_grid(row, h);
    }
    --held.n[a];
  }
  return dropped;
}

// A process's columns of the grid: columns [first[s], first[s] + count[s]) of every
// row are process s's, `values` this one's, n[0] rows of its `width` columns.
template <class Values>
struct Columns {
  std::vector<std::size_t> first, count;
  std::size_t width = 0;
  Values values;
};

// Rows to columns, one all-to-all; alone, the rows are the columns already.
template <std::size_t Rank, class Values>
Columns<Values> to_columns(HeldRows<Rank, Values>& held, const RowTeam& team, const GridSteps& steps) {
  const std::size_t P = team.processes(), M = held.row_size(), nrows = held.count;
  Columns<Values> c;
  c.first.resize(P);
  c.count.resize(P);
  for (std::size_t s = 0; s < P; ++s) std::tie(c.first[s], c.count[s]) = even_share(M, s, P);
  c.width = c.count[team.process()];
  if (P == 1) {
    c.values = std::move(held.rows);
    steps(GridStep::to_columns, 0);
    return c;
  }
  const std::vector<std::uint64_t> row_counts = team.all(nrows);
  Values send;
  std::vector<std::size_t> sc(P), rc(P);
  team.run([&] {
    require_memory(held.rows.size(), sizeof(Vec3), "the transpose of this process's rows");
    send.resize(held.rows.size());
  });
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    for (std::size_t i = 0; i < nrows; ++i)
      std::copy_n(held.rows.data() + i * M + c.first[s], c.count[s], send.data() + at + i * c.count[s]);
    sc[s] = nrows * c.count[s];
    rc[s] = row_counts[s] * c.width;
    at += sc[s];
  }
  release(held.rows);
  team.run([&] {
    require_memory(held.n[0] * c.width, sizeof(Vec3), "this process's columns of the grid");
    c.values.resize(held.n[0] * c.width);
  });
  team.exchange(send.data(), sc, c.values.data(), rc);
  steps(GridStep::to_columns, (send.size() - sc[team.process()]) * sizeof(Vec3));
  return c;
}

// Columns back to rows: process s gets control rows [lo_s, lo_s + window_s) (modulo
// the N rows) from each process's columns; alone with every row, the columns are
// the rows already.
template <class Values>
Values to_rows(Columns<Values>& c, std::size_t N, std::size_t M, long long lo, std::size_t window, const RowTeam& team,
               const GridSteps& steps) {
  const std::size_t P = team.processes(), C = c.width;
  if (P == 1 && lo == 0 && window == N) {
    steps(GridStep::to_rows, 0);
    return std::move(c.values);
  }
  const std::vector<std::uint64_t> los = team.all(static_cast<std::uint64_t>(lo)), counts = team.all(window);
  std::vector<std::size_t> sc(P), rc(P);
  std::size_t send_total = 0;
  for (std::size_t s = 0; s < P; ++s) {
    sc[s] = counts[s] * C;
    rc[s] = window * c.count[s];
    send_total += sc[s];
  }
  Values send, recv, cp;
  team.run([&] {
    require_memory(send_total, sizeof(Vec3), "the transpose of the control points");
    send.resize(send_total);
  });
  std::size_t at = 0;
  const auto rows = static_cast<long long>(N);
  for (std::size_t s = 0; s < P; ++s)
    for (std::size_t v = 0; v < counts[s]; ++v, at += C)
      std::copy_n(c.values.data() + ((static_cast<long long>(los[s]) + static_cast<long long>(v)) % rows) * C, C,
                  send.data() + at);
  release(c.values);
  team.run([&] {
    require_memory(window * M, sizeof(Vec3), "this process's rows of the control points");
    recv.resize(window * M);
  });
  team.exchange(send.data(), sc, recv.data(), rc);
  steps(GridStep::to_rows, (send.size() - sc[team.process()]) * sizeof(Vec3));
  release(send);
  team.run([&] {
    require_memory(window * M, sizeof(Vec3), "this process's rows of the control points");
    cp.resize(window * M);
  });
  at = 0;
  for (std::size_t s = 0; s < P; ++s)
    for (std::size_t v = 0; v < window; ++v, at += c.count[s])
      std::copy_n(recv.data() + at, c.count[s], cp.data() + v * M + c.first[s]);
  return cp;
}

// The solve along u on whole columns, scaled back by 2^shift, and the seam of a
// closed u of even degree. Returns whether the solution is known to be finite.
template <class Values>
void solve_along_u(Columns<Values>& c, std::size_t n0, RowSolution& rs, int degree, bool closed, int shift,
                   const RowTeam& team, const GridSteps& steps) {
  AxisSolver lu0 = BandedLU(0, 0, 0);
  team.run([&] { lu0 = factor_axis(rs.knots[0], rs.params[0], 0); });
  solve_columns(lu0, &c.values.data()->x, n0, 3 * c.width);
  if (shift != 0) scale_points(c.values.data(), c.values.size(), shift);
  steps(GridStep::solve_u, 0);
  if (!closed || degree % 2 != 0) return;
  team.run([&] {
    Grid<Vec3, 2> g = as_grid(c.values, std::array<std::size_t, 2>{n0, c.width});
    insert_seam(g, 0, rs.knots[0], rs.params[0].front());
    take_grid(g, c.values);
  });
}

// The knots and extents of the control net once the axes inside the rows have their
// seams; the rows get them in seam_rows.
template <std::size_t Rank, class Values>
void net_knots(SolvedGrid<Values>& s, const RowSolution& rs, const std::array<bool, 3>& seam, const RowTeam& team) {
  team.run([&] {
    s.knots = rs.knots;
    for (std::size_t a = 1; a < Rank; ++a)
      if (seam[a]) {
        Grid<Vec3, Rank> none(rows_shape<Rank>(s.net, 0), for_overwrite);
        insert_seam(none, a, s.knots[a], rs.params[a].front());
        s.net[a] = static_cast<std::size_t>(s.knots[a].count());
      }
  });
}

// The seams of the axes inside the rows, on the window's control rows.
template <std::size_t Rank, class Values>
void seam_rows(SolvedGrid<Values>& s, const RowSolution& rs, std::array<std::size_t, 3> extents,
               const std::array<bool, 3>& seam, const RowTeam& team) {
  team.run([&] {
    for (std::size_t a = 1; a < Rank; ++a)
      if (seam[a]) {
        Grid<Vec3, Rank> g = as_grid(s.rows, rows_shape<Rank>(extents, s.window));
        KnotVector k = rs.knots[a];
        insert_seam(g, a, k, rs.params[a].front());
        extents[a] = g.extent(a);
        take_grid(g, s.rows);
      }
  });
}

}  // namespace

template <std::size_t Rank, class Values>
SolvedGrid<Values> solve_grid_rows(HeldRows<Rank, Values>& held, const GridOptions& o, const RowTeam& team,
                                   const GridSteps& steps, const ControlWindow& window) {
  team.run([&] { check_extents<Rank>(held.n); });
  const std::array<bool, 3> dropped = drop_closing_lines(held, o.periodic, team);
  static constexpr const char* in_axis[3] = {" in u", " in v", " in w"};
  static constexpr const char* around_axis[3] = {" around u (closed)", " around v (closed)", " around w (closed)"};
  SolvedGrid<Values> s;
  s.degrees.resize(Rank);
  team.run([&] {
    for (std::size_t a = 0; a < Rank; ++a)
      s.degrees[a] = resolve_degree(o.degree[a], held.n[a], 0, o.periodic[a] ? around_axis[a] : in_axis[a]);
  });
  steps(GridStep::degrees, 0);

  // Passes 1 and 2, the knots and factorizations of the axes inside the rows.
  const GridBlock b = held.block();
  const int shift = o.param == Parametrization::uniform ? 0 : block_shift(b, team);
  if (shift != 0) {
    team.run([&] { check_finite(b); });  // before scaling: the message shows the point as given
    scale_points(held.rows.data(), held.rows.size(), -shift);
    for (Values& h : held.halo) scale_points(h.data(), h.size(), -shift);
  }
  steps(GridStep::checks, 0);
  RowSolution rs = solve_rows(b, s.degrees, o.param, std::span<const bool>(o.periodic.data(), Rank), team);
  steps(GridStep::rows, 0);
  for (Values& h : held.halo) release(h);

  // Pass 3: along u, on whole columns.
  const std::array<std::size_t, 3> n = held.n;
  const std::size_t M = held.row_size();
  Columns<Values> columns = to_columns(held, team, steps);
  solve_along_u(columns, n[0], rs, s.degrees[0], o.periodic[0], shift, team, steps);
  std::array<bool, 3> seam{};
  for (std::size_t a = 1; a < Rank; ++a) seam[a] = o.periodic[a] && s.degrees[a] % 2 == 0;
  s.net = n;
  s.net[0] = n[0] + (o.periodic[0] && s.degrees[0] % 2 == 0 ? 1 : 0);
  net_knots<Rank>(s, rs, seam, team);

  // Which control rows this process keeps, back from the columns.
  std::tie(s.lo, s.window) = window(s.knots, s.net[0]);
  s.rows = to_rows(columns, s.net[0], M, s.lo, s.window, team, steps);
  seam_rows<Rank>(s, rs, n, seam, team);
  for (std::size_t a = 0; a < Rank; ++a) {
    if (dropped[a]) rs.params[a].push_back(rs.params[a].front() + 1.0);
  }
  s.params = std::move(rs.params);
  steps(GridStep::done, 0);
  return s;
}

using GridValues = Grid<Vec3, 2>::storage_type;
static_assert(std::is_same_v<GridValues, Grid<Vec3, 3>::storage_type>);
template SolvedGrid<GridValues> solve_grid_rows<2, GridValues>(HeldRows<2, GridValues>&, const GridOptions&,
                                                                const RowTeam&, const GridSteps&, const ControlWindow&);
template SolvedGrid<GridValues> solve_grid_rows<3, GridValues>(HeldRows<3, GridValues>&, const GridOptions&,
                                                                const RowTeam&, const GridSteps&, const ControlWindow&);
template SolvedGrid<std::vector<Vec3>> solve_grid_rows<2, std::vector<Vec3>>(HeldRows<2, std::vector<Vec3>>&,
                                                                            const GridOptions&, const RowTeam&,
                                                                            const GridSteps&, const ControlWindow&);
template SolvedGrid<std::vector<Vec3>> solve_grid_rows<3, std::vector<Vec3>>(HeldRows<3, std::vector<Vec3>>&,
                                                                            const GridOptions&, const RowTeam&,
                                                                            const GridSteps&, const ControlWindow&);

}  // namespace interpatch::detail
