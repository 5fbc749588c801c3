// The row-split fit's solves (approx_rows_solve.hpp).

#include "constructions/approximate/approx_rows_solve.hpp"

#include <type_traits>
#include <utility>
#include <variant>

#include "constructions/approximate/approx_passes.hpp"
#include "constructions/approximate/approx_rows_transpose.hpp"

namespace interpatch::detail::approx {

Axis axis_slice(const Axis& ax, std::size_t first, std::size_t count) {
  Axis s = ax;
  const auto pp = static_cast<std::size_t>(ax.p) + 1;
  auto part = [&](const auto& v, std::size_t per) {
    using V = std::decay_t<decltype(v)>;
    return V(v.begin() + static_cast<std::ptrdiff_t>(first * per), v.begin() + static_cast<std::ptrdiff_t>((first + count) * per));
  };
  s.n = count;
  s.t = part(ax.t, 1);
  s.first = part(ax.first, 1);
  s.b = part(ax.b, pp);
  s.interval = part(ax.interval, 1);
  return s;
}

std::vector<double> block_rhs(const std::array<Axis, 2>& axes, const std::vector<double>& cols, std::size_t M,
                              const detail::RowTeam& team, const std::function<void()>& read) {
  const std::size_t P = team.processes(), me = team.process();
  const auto c0 = static_cast<std::size_t>(axes[0].c);
  std::vector<double> tmp, rhs;
  Shape<2> cs{axes[0].n, detail::even_share(M, me, P).second};
  basis_pass<true, 2>(axes[0], cols.data(), cs, 0, tmp);
  if (read) read();
  std::vector<double> rows = columns_to_rows(tmp, c0, M, team);
  Shape<2> rs{detail::even_share(c0, me, P).second, M};
  basis_pass<true, 2>(axes[1], rows.data(), rs, 1, rhs);
  return rhs;
}

std::array<std::optional<AxisSolver>, 2> separable_solvers(const std::array<Axis, 2>& axes, const detail::RowTeam& team) {
  std::array<std::optional<AxisSolver>, 2> lu;
  team.run([&] {
    try {
      for (std::size_t a = 0; a < 2; ++a) lu[a] = factor_gram(axes[a], a);
    } catch (const error& e) {
      if (e.code() != errc::singular) throw;
      lu = {};
    }
  });
  return lu;
}

// The separable solve of the right-hand side's rows (block_rhs: this process's even
// share of the c0 control rows): its control rows, along u on columns, along v on rows.
std::vector<double> separable_rows(const std::array<std::optional<AxisSolver>, 2>& lu, const std::vector<double>& rhs,
                                   std::size_t c0, std::size_t c1, const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process(), nr = detail::even_share(c0, me, P).second;
  std::vector<double> cols = rows_to_columns(as_points(rhs.data()), nr, c1, team);
  const std::size_t cshape[2] = {c0, detail::even_share(c1, me, P).second}, rshape[2] = {nr, c1};
  std::visit([&](const auto& s) { solve_along_axis(s, cols.data(), cshape, 2, 0, 3); }, *lu[0]);
  std::vector<double> rows = columns_to_rows(cols, c0, c1, team);
  std::visit([&](const auto& s) { solve_along_axis(s, rows.data(), rshape, 2, 1, 3); }, *lu[1]);
  return rows;
}

detail::ApproxRows net_rows(const Fit<2>& f, const detail::RowTeam& team, const double* mine) {
  detail::ApproxRows out;
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const std::pair<std::size_t, std::size_t> share = detail::even_share(c0, team.process(), team.processes());
  if (!mine) mine = f.cp.data() + 3 * share.first * c1;
  out.first = share.first;
  if (share.second > 0) out.rows.assign(as_points(mine), as_points(mine) + share.second * c1);
  for (std::size_t a = 0; a < 2; ++a) {
    out.degree[a] = f.axes[a].p;
    out.knots[a] = f.axes[a].knots.mapped(0.0, 1.0);
  }
  out.net = {c0, c1};
  return out;
}

}  // namespace interpatch::detail::approx
