#pragma once
// The least-squares fit of data held whole by one process: the right-hand side, the
// separable fit, each direction's parameters, the residuals and the line fits, and
// Whole, the data source a fit to a tolerance works on (approx_tolerance.hpp).

#include <algorithm>
#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_knots.hpp"
#include "constructions/approximate/approx_normal.hpp"
#include "constructions/approximate/approx_passes.hpp"
#include "constructions/approximate/approx_residuals.hpp"
#include "constructions/approximate/approx_smoothing.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::approx {

// Bᵀ (w Q) over every direction: the right-hand side of the normal equations.
template <std::size_t R>
std::vector<double> right_hand_side(const std::array<Axis, R>& axes, const Data<R>& d) {
  Shape<R> shape = d.shape;
  std::vector<double> a0, a1;
  const double* src = &d.points.data()->x;
  if (!d.uniform()) {
    require_memory(d.points.size(), sizeof(Vec3), "the weighted data points");
    a1.resize(d.points.size() * 3);
    for (std::size_t i = 0; i < d.points.size(); ++i) {
      const double w = d.weight[i];
      for (std::size_t k = 0; k < 3; ++k) a1[i * 3 + k] = w > 0 ? w * d.points.data()[i][static_cast<int>(k)] : 0.0;
    }
    src = a1.data();
  }
  // The first direction first: its rows are whole rows of the grid (long, contiguous
  // runs the multiply-adds stream through), and it shrinks the grid for the others.
  for (std::size_t a = 0; a < R; ++a) {
    basis_pass<true, R>(axes[a], src, shape, a, a0);
    std::swap(a0, a1);
    src = a1.data();
  }
  return a1;
}

// The separable least-squares fit: every point present with weight 1, no fairness
// term. The normal equations are the Kronecker product of the directions' Gram
// matrices, solved direction by direction.
template <std::size_t R>
std::vector<double> separable_fit(const std::array<Axis, R>& axes, const Data<R>& d) {
  std::vector<double> x = right_hand_side<R>(axes, d);
  Shape<R> shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(axes[a].c);
  for (std::size_t a = 0; a < R; ++a) {
    const AxisSolver lu = factor_gram(axes[a], a);
    std::visit([&](const auto& s) { detail::solve_along_axis(s, x.data(), shape.data(), R, a, 3); }, lu);
  }
  return x;
}

// Parameters along axis a, averaged over the lines of the grid: the mean chord of
// each step over the lines where both its points are present (a step with none
// takes the mean of the others). Without missing points along an open direction,
// interpolation's own parameters.
template <std::size_t R>
std::vector<double> axis_parameters(const Data<R>& d, std::size_t a, Parametrization param, bool closed) {
  const std::size_t n = d.shape[a];
  const std::size_t steps = closed ? n : n - 1;
  if (param == Parametrization::uniform) return uniform_parameters(n, closed);
  if (!closed && d.missing == 0) {
    if constexpr (R == 1) return curve_parameters(std::span<const Vec3>(d.points.data(), n), param);
    else return grid_parameters(d.points, static_cast<int>(a), param);
  }
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= d.shape[x];
  for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
  std::vector<double> sum(steps, 0.0);
  std::vector<std::size_t> used(steps, 0);
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t in = 0; in < inner; ++in)
      for (std::size_t k = 1; k <= steps; ++k)
        add_chord(d.points.data()[(o * n + k - 1) * inner + in], d.points.data()[(o * n + k % n) * inner + in], sum[k - 1],
                  used[k - 1]);
  return parameters_from_sums(std::move(sum), used, n, a, param, closed);
}

// The distances |S(t_i) − Q_i| at every point present, evaluated a row at a time
// (every index but the last fixed) and never stored: the control net goes through B
// along every direction but the last once (n_0 ⋯ n_{R−2} × c_{R−1} values), and each
// row of S is made from its row of that and compared at once. Blocks of rows run in
// parallel and merge in order.
template <std::size_t R>
Residuals<R> residuals(const std::array<Axis, R>& axes, const Data<R>& d, const std::vector<double>& cp) {
  Shape<R> shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(axes[a].c);
  std::vector<double> partial = cp, scratch;
  for (std::size_t a = 0; a + 1 < R; ++a) {
    basis_pass<false, R>(axes[a], partial.data(), shape, a, scratch);
    std::swap(partial, scratch);
  }
  Residuals<R> all = residual_blocks<R>(axes, d.shape, partial.data(), d.points.data(), 0, 0, d.points.size() / axes[R - 1].n,
                                        [&](std::size_t i) { return d.w(i); });
  take_roots<R>(all);
  return all;
}

// Whether the sparse system is needed: missing points, weights, or a fairness term.
template <std::size_t R>
bool needs_fill(const Data<R>& d) {
  if (d.uniform()) return false;
  return std::any_of(d.weight.begin(), d.weight.end(), [](double w) { return !(w > 0); });
}

template <std::size_t R>
void solve_once(Fit<R>& f, const Data<R>& d, std::optional<double> lambda) {
  ++f.fits;
  bool fill = needs_fill(d);
  if (!lambda && d.uniform()) {
    try {
      f.lambda = 0;
      f.cp = separable_fit<R>(f.axes, d);
      return;
    } catch (const error& e) {
      // Knot intervals with too little data under them: the fairness term settles
      // what the data leave open, as in a hole.
      if (e.code() != errc::singular) throw;
      fill = true;
    }
  }
  SparseSystem<R> sys(f.axes, d);
  sparse_fit<R>(f, sys, right_hand_side<R>(f.axes, d), lambda, fill);
}

template <std::size_t R>
void solve_gcv(Fit<R>& f, const Data<R>& d) {
  SparseSystem<R> sys(f.axes, d);
  gcv_fit<R>(f, sys, right_hand_side<R>(f.axes, d), d.present, needs_fill(d),
             [&](const std::vector<double>& cp) { return residuals<R>(f.axes, d, cp).weighted_sq; });
}

// The residual at point `i` of the least-squares fit along axis a alone of the line
// through it (missing points taking the approximation's values).
template <std::size_t R>
double line_residual(const std::array<Axis, R>& axes, const AxisSolver& lu, const Data<R>& d, const std::vector<double>& cp,
                     std::size_t a, std::size_t i) {
  std::size_t inner = 1;
  for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
  const std::size_t n = d.shape[a], pos = (i / inner) % n, base = i - pos * inner;
  std::vector<double> line(n * 3);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = base + k * inner;
    const Vec3 v = point_or_fit<R>(axes, cp, d.shape, d.points.data()[j], d.w(j) > 0, j);
    for (std::size_t m = 0; m < 3; ++m) line[3 * k + m] = v[static_cast<int>(m)];
  }
  return line_fit_residual(axes[a], lu, line, pos);
}

// The data a fit to a tolerance works on, all in this process (the split run has its
// own, Block in approx_rows_block.hpp): what the knot logic of
// grow() and solve_tolerance() asks of the data.
template <std::size_t R>
struct Whole {
  std::shared_ptr<const Data<R>> own;  // a thinned grid's data; none for the caller's
  const Data<R>* d = nullptr;

  [[nodiscard]] std::size_t size() const { return d->points.size(); }
  [[nodiscard]] const Shape<R>& shape() const { return d->shape; }
  void fit(Fit<R>& f) const { solve_once<R>(f, *d, std::nullopt); }
  [[nodiscard]] Residuals<R> errors(const Fit<R>& f) const { return residuals<R>(f.axes, *d, f.cp); }
  // Whether f's control net stays near the data (detail::approx_net_sane).
  [[nodiscard]] bool sane(const Fit<R>& f) const {
    if (!box) box = detail::approx_box({{}, std::span<const Vec3>(d->points.data(), d->points.size()), d->weight});
    return detail::approx_net_sane(net_points(f.cp), R, *box);
  }
  mutable std::optional<std::array<Vec3, 2>> box;  // of the data, found once
  // line_residual at each (axis, point) of `at`, lu[axis] the axis's line solver.
  [[nodiscard]] std::vector<double> line_residuals(const Fit<R>& f, const std::array<std::optional<AxisSolver>, R>& lu,
                                                   const std::vector<std::pair<std::size_t, std::size_t>>& at) const {
    std::vector<double> e;
    for (const auto& [a, i] : at) e.push_back(line_residual<R>(f.axes, *lu[a], *d, f.cp, a, i));
    return e;
  }
  // Which lines across each axis (every point with that index along it) hold data.
  [[nodiscard]] std::array<std::vector<bool>, R> has_data() const {
    std::array<std::vector<bool>, R> has;
    for (std::size_t a = 0; a < R; ++a) has[a].assign(d->shape[a], d->uniform());
    if (!d->uniform())
      for (std::size_t i = 0; i < d->points.size(); ++i)
        if (d->w(i) > 0) {
          const std::vector<std::size_t> idx = unflatten<R>(i, d->shape);
          for (std::size_t a = 0; a < R; ++a) has[a][idx[a]] = true;
        }
    return has;
  }
  [[nodiscard]] Whole thinned(const std::array<std::vector<std::size_t>, R>& kept) const;
};

// Every `step[a]`-th line of the data along each axis (the last one too): a grid to
// grow the knots on before the whole grid refines them.
template <std::size_t R>
Data<R> thinned(const Data<R>& d, const std::array<std::vector<std::size_t>, R>& kept) {
  Data<R> t;
  typename Grid<Vec3, R>::shape_type shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = t.shape[a] = kept[a].size();
  t.points = Grid<Vec3, R>(shape, for_overwrite);
  if (!d.uniform()) t.weight.resize(t.points.size());
  std::array<std::size_t, R> k{};
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    std::size_t src = 0;
    for (std::size_t a = 0; a < R; ++a) src = src * d.shape[a] + kept[a][k[a]];
    t.points.data()[i] = d.points.data()[src];
    if (!d.uniform()) t.weight[i] = d.weight[src];
    if (d.w(src) > 0) {
      ++t.present;
      t.weight_sum += d.w(src);
    } else {
      ++t.missing;
    }
    for (std::size_t a = R; a-- > 0;) {
      if (++k[a] < kept[a].size()) break;
      k[a] = 0;
    }
  }
  return t;
}

template <std::size_t R>
Whole<R> Whole<R>::thinned(const std::array<std::vector<std::size_t>, R>& kept) const {
  auto t = std::make_shared<const Data<R>>(approx::thinned<R>(*d, kept));
  return {t, t.get(), std::nullopt};
}

}  // namespace interpatch::detail::approx
