// The approximation of a surface split between processes by rows
// (detail::approximate_rows, approx_rows.hpp): the grid's blocks closed and weighed,
// the parameters found, then the single process's fit (approx_*.hpp) run on blocks
// of rows (approx_rows_*.hpp), every sum over the data made in the single process's order.

#include "constructions/approximate/approx_rows.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <exception>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_knots.hpp"
#include "constructions/approximate/approx_passes.hpp"
#include "constructions/approximate/approx_request.hpp"
#include "constructions/approximate/approx_residuals.hpp"
#include "constructions/approximate/approx_rows_block.hpp"
#include "constructions/approximate/approx_rows_check.hpp"
#include "constructions/approximate/approx_rows_data_term.hpp"
#include "constructions/approximate/approx_rows_solve.hpp"
#include "constructions/approximate/approx_rows_transpose.hpp"
#include "constructions/approximate/approx_smoothing.hpp"
#include "constructions/approximate/approx_tolerance.hpp"

namespace interpatch::detail::approx {

namespace {

// Counts held as doubles (gathered between processes), as counts.
template <class It>
std::vector<std::size_t> as_counts(It first, It last) {
  std::vector<std::size_t> c;
  for (; first != last; ++first) c.push_back(static_cast<std::size_t>(*first));
  return c;
}

// closed_data on a grid held in blocks of rows: a closed direction's last line that
// repeats the first is left out of the block (along v out of each of its rows, in
// place); one that nearly repeats it is refused. Whether each was left out.
std::array<bool, 2> close_block(detail::GridBlock& b, const std::array<bool, 2>& periodic, bool missing,
                                const detail::RowTeam& team) {
  std::array<bool, 2> dropped{};
  for (std::size_t a = 0; a < 2; ++a) {
    if (!periodic[a] || b.n[a] < 3) continue;
    if (missing) break;
    INTERPATCH_ASSERT(a > 0 || b.ends[0] != nullptr);
    const Closing c = detail::block_closing(b, a, b.ends, false, team);
    if (c.nearly) team.run([&] { refuse_closing_gap(a); });
    if (!c.dropped) continue;
    dropped[a] = true;
    const std::size_t n = b.n[a]--;
    if (a == 0) {
      b.count = b.first < n - 1 ? std::min(b.count, n - 1 - b.first) : 0;
      b.last = b.ends[2];
    } else {
      for (std::size_t r = 1; r < b.count; ++r) std::copy(b.data + r * n, b.data + r * n + n - 1, b.data + r * (n - 1));
    }
  }
  return dropped;
}

// The grid of a split run as approximate() sees it: a closed direction's closing
// line left out (with its weights), and each point's weight: 0 where missing; 1
// everywhere when every point is present and the weights (if any) are equal.
struct RowsData {
  GridBlock b;
  Grid<double, 2> cut;                       // the weights without the lines left out (a copy only then)
  const Grid<double, 2>* weights = nullptr;  // the weights fitted: o.weights or cut
  Shape<2> shape{};
  std::size_t M = 0, total = 0, mine = 0, base = 0;  // columns, points, this block's points and its first
  const Vec3* pts = nullptr;
  std::size_t missing = 0;     // over the whole grid
  bool uniform = false, fill = false;  // Data::uniform, needs_fill
  std::vector<bool> present_here;      // which points are present, kept past the points themselves
  std::size_t present = 0;     // points with a positive weight
  double weight_sum = 0;       // their weights' sum in the order of the points

  RowsData(const GridBlock& given, const SurfaceApproximationOptions& o, const RowTeam& team);
  RowsData(const RowsData&) = delete;
  RowsData& operator=(const RowsData&) = delete;

  [[nodiscard]] double given_weight(std::size_t flat) const {
    if (!present_here.empty() && !present_here[flat - base]) return 0.0;
    return weights->empty() ? 1.0 : weights->values()[flat];
  }
  [[nodiscard]] double weight(std::size_t flat) const { return uniform ? 1.0 : given_weight(flat); }
  // weight() as the functions on blocks of rows take it.
  [[nodiscard]] auto weight_fn() const {
    return [this](std::size_t flat) { return weight(flat); };
  }

 private:
  void weigh(const RowTeam& team);
};

RowsData::RowsData(const GridBlock& given, const SurfaceApproximationOptions& o, const RowTeam& team) : b(given) {
  // Missing points (NaN); closed directions, whose closing line is looked for only
  // where none is missing (closed_data).
  std::size_t missing_count[1] = {0};
  for (std::size_t i = 0; i < given.count * given.n[1]; ++i) missing_count[0] += is_missing(given.data[i]) ? 1 : 0;
  team.sum(missing_count);
  missing = missing_count[0];
  const std::array<bool, 2> dropped = close_block(b, o.periodic, missing > 0, team);
  if (!o.weights.empty() && (dropped[0] || dropped[1])) {
    cut = o.weights;
    for (std::size_t a = 0; a < 2; ++a)
      if (dropped[a]) cut_last_line<double, 2>(cut, a);
  }
  weights = cut.empty() ? &o.weights : &cut;
  shape = {b.n[0], b.n[1]};
  M = shape[1];
  total = shape[0] * shape[1];
  mine = b.count * M;
  base = b.first * M;
  pts = b.data;
  team.run([&] {
    check_request<2>(o, shape, "surface");
    if (!weights->empty()) check_weights<2>(*weights, shape);
  });
  weigh(team);
}

void RowsData::weigh(const RowTeam& team) {
  const auto& values = weights->values();
  uniform = missing == 0 && std::all_of(values.begin(), values.end(), [&](double w) { return w == values.front(); });
  const bool zero_weight = std::any_of(values.begin(), values.end(), [](double w) { return !(w > 0); });
  fill = !uniform && (missing > 0 || zero_weight);
  present_here.resize(missing > 0 ? mine : 0);
  for (std::size_t i = 0; i < present_here.size(); ++i) present_here[i] = !is_missing(pts[i]);
  std::size_t present_count[1] = {0};
  for (std::size_t i = base; i < base + mine; ++i) present_count[0] += given_weight(i) > 0 ? 1 : 0;
  team.sum(present_count);
  present = present_count[0];
  std::vector<double> sum(1, static_cast<double>(total));
  if (!uniform) {
    sum[0] = 0;
    team.fold(sum, [&](std::span<double> acc) {
      for (std::size_t i = base; i < base + mine; ++i)
        if (const double w = weight(i); w > 0) acc[0] += w;
    });
  }
  weight_sum = sum[0];
  team.run([&] {
    if (present == 0)
      fail(errc::too_few_points, "all ", total, " points are missing or have weight 0: there is nothing to approximate");
  });
}

// The parameters along u from the mean chords (axis_parameters). Each step's chords
// lie in the rows of one process (the row before the block from its neighbour; the
// closing step, back to row 0, in the last rows) and are summed over the row, as in
// one process.
void chord_parameters_u(Fit<2>& f, const RowsData& d, const SurfaceApproximationOptions& o, const RowTeam& team) {
  const GridBlock& b = d.b;
  const std::size_t M = d.M;
  const Vec3* pts = d.pts;
  std::vector<double> sum0, used0;
  auto step = [&](const Vec3* prev, const Vec3* next) {
    double sum = 0;
    std::size_t used = 0;
    for (std::size_t i = 0; i < M; ++i) add_chord(prev[i], next[i], sum, used);
    sum0.push_back(sum);
    used0.push_back(static_cast<double>(used));
  };
  for (std::size_t k = b.first == 0 ? 1 : 0; k < b.count; ++k) step(k == 0 ? b.before : pts + (k - 1) * M, pts + k * M);
  if (o.periodic[0] && b.count > 0 && b.first + b.count == d.shape[0]) step(pts + (b.count - 1) * M, b.row0);
  const std::vector<double> all_sum0 = team.gather(sum0), all_used0 = team.gather(used0);
  team.run([&] {
    f.axes[0].t = parameters_from_sums(all_sum0, as_counts(all_used0.begin(), all_used0.end()), d.shape[0], 0, o.param,
                                       o.periodic[0]);
  });
}

// The parameters along v from the mean chords: the lines along v are summed row
// after row, a running sum passed on in order.
void chord_parameters_v(Fit<2>& f, const RowsData& d, const SurfaceApproximationOptions& o, const RowTeam& team) {
  const std::size_t M = d.M;
  const Vec3* pts = d.pts;
  const std::size_t steps1 = o.periodic[1] ? M : M - 1;
  std::vector<double> acc1(2 * steps1, 0.0);
  team.fold(acc1, [&](std::span<double> acc) {
    for (std::size_t r = 0; r < d.b.count; ++r)
      for (std::size_t k = 1; k <= steps1; ++k) {
        std::size_t used = 0;
        add_chord(pts[r * M + k - 1], pts[r * M + k % M], acc[k - 1], used);
        acc[steps1 + k - 1] += static_cast<double>(used);
      }
  });
  team.run([&] {
    f.axes[1].t = parameters_from_sums(std::vector<double>(acc1.begin(), acc1.begin() + static_cast<std::ptrdiff_t>(steps1)),
                                       as_counts(acc1.begin() + static_cast<std::ptrdiff_t>(steps1), acc1.end()), d.shape[1], 1,
                                       o.param, o.periodic[1]);
  });
}

// Degrees and parameters, in one process's order: the degree along u, the
// parameters along u, the degree along v (a refusal kept until the parameters along
// u are found), along v. As axis_parameters: interpolation's parameters along an
// open direction without missing points, else the mean chords summed over the lines.
Fit<2> degrees_and_parameters(const RowsData& d, const SurfaceApproximationOptions& o, const RowTeam& team) {
  constexpr std::size_t R = 2;
  Fit<R> f;
  team.run([&] { set_degree<R>(f.axes[0], o, 0, d.shape[0]); });
  std::exception_ptr v_degree;
  try {
    set_degree<R>(f.axes[1], o, 1, d.shape[1]);
  } catch (const error&) {
    v_degree = std::current_exception();
  }
  const std::size_t axes = v_degree ? 1 : R;
  std::array<bool, R> by_sums{};
  for (std::size_t a = 0; a < R; ++a) by_sums[a] = o.periodic[a] || d.missing > 0;
  if (o.param == Parametrization::uniform) {
    for (std::size_t a = 0; a < R; ++a) f.axes[a].t = uniform_parameters(d.shape[a], o.periodic[a]);
  } else if (!by_sums[0] && !by_sums[1] && axes == R) {
    std::vector<std::vector<double>> t = block_parameters(d.b, o.param, team, axes);
    for (std::size_t a = 0; a < R; ++a) f.axes[a].t = std::move(t[a]);
  } else {
    for (std::size_t a = 0; a < axes; ++a) {
      if (by_sums[a] && a == 0) {
        chord_parameters_u(f, d, o, team);
      } else if (by_sums[a]) {
        chord_parameters_v(f, d, o, team);
      } else {
        const std::vector<std::vector<double>> t = block_parameters(d.b, o.param, team, a + 1, a == 0);
        f.axes[a].t = t[a];
      }
    }
  }
  team.run([&] {
    if (v_degree) std::rethrow_exception(v_degree);
  });
  return f;
}

// The fit to a tolerance: the knots grow and are pruned on every process alike
// (solve_tolerance), the fits and measures on the blocks (Block).
ApproxRows fit_to_tolerance(Fit<2>& f, const RowsData& d, double tol, const std::vector<Vec3>& box, const RowTeam& team) {
  const Grid<double, 2>& weights = *d.weights;
  const Block whole(team, d.shape, nullptr, d.pts, d.b.first, d.b.count, d.uniform, nullptr,
                    weights.empty() ? nullptr : weights.values().data() + std::min(d.base, weights.size()));
  solve_tolerance<2>(f, whole, tol, {});
  check_rows_tolerance(f, d.b, d.weight_fn(), tol, team);
  ApproxRows out = net_rows(f, team);
  check_rows_net(out, box, team);
  return out;
}

// Bᵀ (w Q): along u on columns of the data, along v on rows of the result. `release`
// is called once the points are read no more (a smoothing "auto" reads them on).
std::vector<double> rows_rhs(const Fit<2>& f, const RowsData& d, const SurfaceApproximationOptions& o, const RowTeam& team,
                             const std::function<void()>& release) {
  std::vector<double> cols = rows_to_columns(
      d.pts, d.b.count, d.M, team, [&] {
        if (release && !o.auto_smoothing) release();
      },
      [&](std::size_t i, const Vec3&) { return d.weight(d.base + i); });
  return block_rhs(f.axes, cols, d.M, team, [&] { std::vector<double>().swap(cols); });
}

// λ by generalized cross-validation (gcv_fit), Σ w r² over the data in blocks of rows
// as in residuals(), their sums added in order.
void rows_gcv_fit(Fit<2>& f, SparseSystem<2>& sys, const std::vector<double>& all_rhs, const RowsData& d,
                  const RowTeam& team) {
  constexpr std::size_t R = 2;
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const GridBlock& b = d.b;
  const auto weight = d.weight_fn();
  const Axis slice = axis_slice(f.axes[0], b.first, b.count);
  const std::vector<std::size_t> off = residual_offsets(f.axes[1]);
  std::vector<double> row(3 * d.M), e2(d.M);
  auto rss = [&](const std::vector<double>& cp) {
    Shape<R> sh{c0, c1};
    std::vector<double> partial;
    basis_pass<false, R>(slice, cp.data(), sh, 0, partial);
    std::vector<double> sums;
    for (std::size_t q = b.first; q < b.first + b.count; q += residual_block_rows) {
      Residuals<R> r(f.axes);
      residual_rows<R>(r, f.axes, d.shape, partial.data(), d.pts, b.first, q,
                       std::min(b.first + b.count, q + residual_block_rows), weight, off.data(), row.data(), e2.data());
      sums.push_back(r.weighted_sq);
    }
    std::vector<double> acc(1, 0.0);
    team.fold(acc, [&](std::span<double> a) {
      for (const double x : sums) a[0] += x;
    });
    return acc[0];
  };
  team.run([&] { gcv_fit<R>(f, sys, all_rhs, d.present, d.fill, rss); });
}

// A fit with a given number of control points or smoothing: the separable fit when
// it applies (separable_fit), else the sparse system, with the term that fills holes
// where some weight is 0 or the separable fit fails.
ApproxRows fit_given(Fit<2>& f, const RowsData& d, const SurfaceApproximationOptions& o, const std::vector<Vec3>& box,
                     const RowTeam& team, const std::function<void()>& release) {
  constexpr std::size_t R = 2;
  team.run([&] {
    check_control_points<R>(f.axes, o);
    set_fit_knots<R>(f.axes, o);
  });
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const std::vector<double> rhs = rows_rhs(f, d, o, team, release);
  std::array<std::optional<AxisSolver>, R> lu;
  const bool separable = !o.smoothing && !o.auto_smoothing && d.uniform;
  if (separable) lu = separable_solvers(f.axes, team);
  if (lu[0]) {
    ApproxRows out = net_rows(f, team, separable_rows(lu, rhs, c0, c1, team).data());
    check_rows_net(out, box, team);
    return out;
  }
  const bool filled = d.fill || separable;
  {  // the sparse system
    SparseSystem<R> sys = block_system(f.axes, d.shape, d.b, d.uniform, d.weight_fn(), d.weight_sum, team);
    const std::vector<double> all_rhs = team.gather(rhs);
    if (o.auto_smoothing) rows_gcv_fit(f, sys, all_rhs, d, team);
    else team.run([&] { sparse_fit<R>(f, sys, all_rhs, o.smoothing, filled); });
  }
  ApproxRows out = net_rows(f, team);
  check_rows_net(out, box, team);
  return out;
}

}  // namespace

}  // namespace interpatch::detail::approx

namespace interpatch::detail {

ApproxRows approximate_rows(const GridBlock& given, const SurfaceApproximationOptions& o, const RowTeam& team,
                            const std::function<void()>& release) {
  using namespace approx;  // the fit the single process runs (approx_*.hpp)
  INTERPATCH_ASSERT(given.rank == 2);
  const RowsData d(given, o, team);
  Fit<2> f = degrees_and_parameters(d, o, team);
  // The data's box, taken before the points may be released.
  const std::vector<Vec3> box = block_box(d.b, d.weight_fn(), team);
  if (o.tolerance) return fit_to_tolerance(f, d, *o.tolerance, box, team);
  return fit_given(f, d, o, box, team, release);
}

}  // namespace interpatch::detail
