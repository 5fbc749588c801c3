#include "interpatch/approximate.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <random>
#include <variant>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_fit.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "linalg/banded.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::approx {

// The functions approx_fit.hpp declares, described there.

AxisSolver factor_gram(const Axis& ax, std::size_t a) {
  const Band g = ax.gram(ax.p);
  auto singular = [&](int row) {
    fail(errc::singular, "along ", axis_name(a), ": the least-squares system of ", ax.c, " control points over ", ax.n,
         " data points has no unique solution (control point ", row, " has no data under it)");
  };
  if (ax.periodic) {
    std::vector<std::vector<detail::CyclicLU::Entry>> rows(static_cast<std::size_t>(ax.c));
    for (int i = 0; i < ax.c; ++i)
      for (int d = -ax.p; d <= ax.p; ++d)
        if (const double v = g.at(i, d); v != 0.0) rows[static_cast<std::size_t>(i)].push_back({((i + d) % ax.c + ax.c) % ax.c, v});
    detail::CyclicLU lu(ax.c, rows);
    if (!lu.factor()) singular(lu.failed_row());
    return lu;
  }
  detail::BandedLU lu(ax.c, ax.p, ax.p);
  for (int i = 0; i < ax.c; ++i)
    for (int d = -ax.p; d <= ax.p; ++d)
      if (i + d >= 0 && i + d < ax.c) lu.at(i, i + d) = g.at(i, d);
  if (!lu.factor()) singular(lu.failed_row());
  return lu;
}

std::vector<double> uniform_parameters(std::size_t n, bool closed) {
  const std::size_t steps = closed ? n : n - 1;
  std::vector<double> t(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / static_cast<double>(steps);
  if (!closed) t.back() = 1.0;
  return t;
}

std::vector<double> parameters_from_sums(std::vector<double> sum, const std::vector<std::size_t>& used, std::size_t n,
                                         std::size_t a, Parametrization param, bool closed) {
  const std::size_t steps = sum.size();
  double known = 0;
  std::size_t known_count = 0;
  for (std::size_t k = 0; k < steps; ++k)
    if (used[k] > 0) {
      sum[k] /= static_cast<double>(used[k]);
      known += sum[k];
      ++known_count;
    }
  if (known_count == 0) return uniform_parameters(n, closed);
  for (std::size_t k = 0; k < steps; ++k) {
    if (used[k] == 0) sum[k] = known / static_cast<double>(known_count);
    // Means below 1e-14 of the total are rounding noise: the points coincide in every line.
    if (!(sum[k] > 1e-14 * known))
      fail(errc::zero_chord, "along ", axis_name(a), ": points ", k, " and ", (k + 1) % n,
           " coincide in every line (mean chord ", sum[k], "): parameters must increase");
    if (param == Parametrization::centripetal) sum[k] = std::sqrt(sum[k]);
  }
  double total = 0;
  for (std::size_t k = 0; k < steps; ++k) total += sum[k];
  std::vector<double> t(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) t[k] = t[k - 1] + sum[k - 1];
  for (std::size_t k = 1; k < n; ++k) t[k] /= total;
  if (!closed) t.back() = 1.0;
  return t;
}

KnotVector clamped_knots(const Axis& ax, const std::vector<double>& interior) {
  std::vector<double> u(static_cast<std::size_t>(ax.p) + 1, ax.t.front());
  u.insert(u.end(), interior.begin(), interior.end());
  u.insert(u.end(), static_cast<std::size_t>(ax.p) + 1, ax.t.back());
  return KnotVector(ax.p, std::move(u));
}

std::vector<double> least_squares_breaks(const Axis& ax, int c) {
  const auto& t = ax.t;
  const auto n = static_cast<double>(ax.n);
  std::vector<double> k;
  if (ax.periodic) {
    auto at = [&](double x) {  // the data parameters extended periodically, linear between
      const double f = std::floor(x);
      const auto i = static_cast<long long>(f);
      auto tt = [&](long long j) {
        const auto m = static_cast<long long>(ax.n);
        const long long q = (j % m + m) % m;
        return t[static_cast<std::size_t>(q)] + static_cast<double>((j - q) / m);
      };
      return tt(i) + (x - f) * (tt(i + 1) - tt(i));
    };
    const double shift = ax.p % 2 == 0 ? 0.5 : 0.0;
    for (int j = 0; j < c; ++j) k.push_back(at(j * n / c + shift));
    return k;
  }
  std::vector<double> s(static_cast<std::size_t>(c));
  for (int j = 0; j < c; ++j) {
    // j (n − 1) / (c − 1) is exact at c = n: the data parameters themselves.
    const double x = static_cast<double>(j) * (n - 1) / static_cast<double>(c - 1);
    const auto i = std::min(static_cast<std::size_t>(std::floor(x)), ax.n - 1);
    const double alpha = x - static_cast<double>(i);
    s[static_cast<std::size_t>(j)] = alpha > 0 ? (1 - alpha) * t[i] + alpha * t[i + 1] : t[i];
  }
  const KnotVector avg = averaged_knots(s, ax.p);
  const auto& u = avg.values();
  return {u.begin() + ax.p + 1, u.end() - ax.p - 1};
}

KnotVector knots_from_breaks(const Axis& ax, const std::vector<double>& breaks) {
  if (ax.periodic) return KnotVector::periodic_from(ax.p, breaks, breaks.front() + 1.0);
  return clamped_knots(ax, breaks);
}

std::vector<std::size_t> residual_offsets(const Axis& last) {
  const std::size_t pp = static_cast<std::size_t>(last.p) + 1;
  std::vector<std::size_t> off(last.n * pp);
  for (std::size_t i = 0; i < last.n; ++i)
    for (std::size_t k = 0; k < pp; ++k) off[i * pp + k] = 3 * last.col(last.first[i] + static_cast<int>(k));
  return off;
}

double line_fit_residual(const Axis& ax, const AxisSolver& lu, const std::vector<double>& line, std::size_t pos) {
  const std::size_t n = ax.n;
  const auto pp = static_cast<std::size_t>(ax.p) + 1;
  std::vector<double> x(static_cast<std::size_t>(ax.c) * 3, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t l = 0; l < pp; ++l)
      for (std::size_t m = 0; m < 3; ++m) x[3 * ax.col(ax.first[k] + static_cast<int>(l)) + m] += ax.b[k * pp + l] * line[3 * k + m];
  std::visit([&](const auto& solver) { solver.solve(x.data(), 3, 3); }, lu);
  Vec3 e{};
  for (std::size_t l = 0; l < pp; ++l)
    for (std::size_t m = 0; m < 3; ++m)
      e[static_cast<int>(m)] += ax.b[pos * pp + l] * x[3 * ax.col(ax.first[pos] + static_cast<int>(l)) + m];
  return distance(e, Vec3{line[3 * pos], line[3 * pos + 1], line[3 * pos + 2]});
}

bool whitney(const Axis& ax, const std::vector<double>& breaks, const std::vector<bool>& has_data) {
  std::vector<double> u(static_cast<std::size_t>(ax.p) + 1, ax.t.front());
  u.insert(u.end(), breaks.begin(), breaks.end());
  u.insert(u.end(), static_cast<std::size_t>(ax.p) + 1, ax.t.back());
  const std::size_t c = breaks.size() + static_cast<std::size_t>(ax.p) + 1, p1 = static_cast<std::size_t>(ax.p) + 1;
  std::size_t i = 0;
  for (std::size_t j = 0; j < c; ++j) {
    const double lo = u[j], hi = u[j + p1];
    while (i < ax.n && (!has_data[i] || ax.t[i] < lo || (ax.t[i] == lo && j > 0))) ++i;
    if (i == ax.n || !(ax.t[i] < hi || (j + 1 == c && ax.t[i] == hi))) return false;
    ++i;
  }
  return true;
}

bool split_interval(const Axis& ax, std::vector<double>& breaks, int k, const std::vector<bool>& has_data) {
  if (static_cast<std::size_t>(ax.c) >= ax.n) return false;
  std::vector<std::size_t> in;  // the lines across the axis in the interval that hold data
  for (std::size_t i = 0; i < ax.n; ++i)
    if (ax.interval[i] == k && has_data[i]) in.push_back(i);
  if (in.size() < 2) return false;
  // In a closed direction, the order along the interval is that of the parameters
  // wrapped into the period: the interval across the seam holds the last lines and
  // then the first.
  auto at = [&](std::size_t i) { return ax.periodic ? ax.knots.wrap(ax.t[i]) : ax.t[i]; };
  if (ax.periodic) std::stable_sort(in.begin(), in.end(), [&](std::size_t x, std::size_t y) { return at(x) < at(y); });
  const std::size_t mid = in.size() / 2;
  const double knot = 0.5 * (at(in[mid - 1]) + at(in[mid]));
  if (!ax.periodic) {
    std::vector<double> next = breaks;  // this round's earlier knots at its end
    next.push_back(knot);
    std::sort(next.begin(), next.end());
    if (!whitney(ax, next, has_data)) return false;
  }
  breaks.push_back(knot);
  return true;
}

std::span<const Vec3> net_points(const std::vector<double>& cp) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "a control net is triples of doubles");
  return {reinterpret_cast<const Vec3*>(cp.data()), cp.size() / 3};
}

[[noreturn]] void refuse_closing_gap(std::size_t a) {
  fail(errc::closing_gap, "the last line of points along ", axis_name(a),
       " nearly repeats the first: repeat the first line exactly, or leave the last one out");
}

namespace {

// ------------------------------------------------------------------ tensor passes

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

// ------------------------------------------------------------------ solvers

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

// ------------------------------------------------------------------ parameters and knots

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

// ------------------------------------------------------------------ errors

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

// ------------------------------------------------------------------ the fit

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
// own, Block in the section "split between processes"): what the knot logic of
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

template <std::size_t R>
struct Result {
  Fit<R> fit;
  ApproximationReport report;
  Data<R> data;  // the points fitted (a closed direction's closing line left out)
};

template <std::size_t R>
Result<R> approximate(Data<R> d, const ApproximationOptions<R>& o, const char* what) {
  check_request<R>(o, d.shape, what);

  // Missing points, weights.
  const std::size_t total = d.points.size();
  if (!o.weights.empty()) {
    check_weights<R>(o.weights, d.shape);
    d.weight.assign(o.weights.values().begin(), o.weights.values().end());
  }
  for (std::size_t i = 0; i < total; ++i) {
    const Vec3& q = d.points.data()[i];
    if (is_missing(q)) {
      if (d.weight.empty()) d.weight.assign(total, 1.0);
      d.weight[i] = 0;
      ++d.missing;
    } else if (!is_finite(q)) {
      fail(errc::not_finite, "point ", index_text<R>(i, d.shape), " is ", q, " (NaN marks a missing point; infinity is refused)");
    }
  }
  d.weight_sum = 0;
  d.present = 0;
  for (std::size_t i = 0; i < total; ++i)
    if (d.w(i) > 0) {
      d.weight_sum += d.w(i);
      ++d.present;
    }
  if (d.present == 0)
    fail(errc::too_few_points, "all ", total, " points are missing or have weight 0: there is nothing to approximate");
  // Data on a single line across a direction leave the fit free along it (nothing
  // fixes its slope there).
  if (!d.weight.empty())
    for (std::size_t a = 0; a < R; ++a) {
      std::size_t inner = 1;
      for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
      std::vector<bool> has(d.shape[a], false);
      for (std::size_t i = 0; i < total; ++i)
        if (d.weight[i] > 0) has[(i / inner) % d.shape[a]] = true;
      if (std::count(has.begin(), has.end(), true) < 2)
        fail(errc::too_few_points, "along ", axis_name(a), " only one line of points holds data (the others are missing ",
             "or have weight 0): an approximation needs two");
    }
  if (!d.weight.empty() && d.missing == 0 &&
        std::all_of(d.weight.begin(), d.weight.end(), [&](double w) { return w == d.weight.front(); })) {
    d.weight.clear();  // equal weights: the plain least-squares fit
    d.weight_sum = static_cast<double>(total);
  }

  Result<R> res;
  Fit<R>& f = res.fit;
  for (std::size_t a = 0; a < R; ++a) {
    set_degree<R>(f.axes[a], o, a, d.shape[a]);
    f.axes[a].t = axis_parameters<R>(d, a, o.param, f.axes[a].periodic);
  }
  check_control_points<R>(f.axes, o);
  if (o.progress) o.progress(0.0);

  if (o.tolerance) {
    solve_tolerance<R>(f, Whole<R>{nullptr, &d, std::nullopt}, *o.tolerance, o.progress);
  } else {
    set_fit_knots<R>(f.axes, o);
    if (o.auto_smoothing) solve_gcv<R>(f, d);
    else solve_once<R>(f, d, o.smoothing);
  }

  // The report.
  const Residuals<R> r = residuals<R>(f.axes, d, f.cp);
  ApproximationReport& rep = res.report;
  rep.max_error = r.max;
  rep.max_error_at = unflatten<R>(r.worst, d.shape);
  rep.rms_error = std::sqrt(r.sum_sq / static_cast<double>(d.present));
  for (std::size_t a = 0; a < R; ++a) rep.control_points.push_back(f.axes[a].c);
  rep.lambda = f.lambda;
  rep.missing = d.missing;
  rep.fits = f.fits;
  if (o.progress) o.progress(1.0);
  res.data = std::move(d);
  return res;
}

template <std::size_t R>
Grid<Vec3, R> control_net(const Fit<R>& f) {
  typename Grid<Vec3, R>::shape_type shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(f.axes[a].c);
  Grid<Vec3, R> g(shape, for_overwrite);
  std::copy_n(f.cp.data(), f.cp.size(), &g.data()->x);
  return g;
}

// A closed direction's last line, when it repeats the first (interpolation's rule),
// is left out, with its weights.
template <std::size_t R>
Data<R> closed_data(Grid<Vec3, R> points, Grid<double, R>& weights, const std::array<bool, R>& periodic) {
  Data<R> d;
  for (std::size_t a = 0; a < R; ++a) {
    if (!periodic[a] || points.extent(a) < 3) continue;
    if (std::any_of(points.values().begin(), points.values().end(), is_missing)) break;
    Closing c;
    if constexpr (R == 1) c = closing_point(std::span<const Vec3>(points.data(), points.size()));
    else c = grid_closing(points, static_cast<int>(a));
    if (c.nearly) refuse_closing_gap(a);
    if (!c.dropped) continue;
    cut_last_line<Vec3, R>(points, a);
    if (!weights.empty()) cut_last_line<double, R>(weights, a);
  }
  for (std::size_t a = 0; a < R; ++a) d.shape[a] = points.extent(a);
  d.points = std::move(points);
  return d;
}

// Finite points scaled by 1 / unit (NaN marks a missing point; infinite ones are kept
// for approximate() to name as given).
template <std::size_t R>
void scale_points(Grid<Vec3, R>& points, double factor) {
  for (Vec3& q : points.values())
    if (is_finite(q)) q = q * factor;
}

template <std::size_t R>
Result<R> run(Grid<Vec3, R> points, const ApproximationOptions<R>& options, const char* what) {
  check_request<R>(options, [&] {
    Shape<R> shape{};
    for (std::size_t a = 0; a < R; ++a) shape[a] = points.extent(a);
    return shape;
  }(), what);
  // Data beyond 2^±64 are fitted in a power of two of their own size (exact both ways).
  const double unit = detail::approximation_unit(detail::largest_coordinate(points.values()));
  const bool closed = std::any_of(options.periodic.begin(), options.periodic.end(), [](bool b) { return b; });
  // A copy of the options (and their weights) only where they change.
  std::optional<ApproximationOptions<R>> changed;
  if (unit != 1 || closed) changed = options;
  if (unit != 1) {
    scale_points<R>(points, 1 / unit);
    // Below the smallest double in the data's unit it could not be met anyway: the
    // refinement goes to its finest fit and says so.
    if (changed->tolerance)
      changed->tolerance = std::max(*changed->tolerance / unit, std::numeric_limits<double>::denorm_min());
  }
  const auto given = points.shape();
  Data<R> d;
  if (closed) {
    d = closed_data<R>(std::move(points), changed->weights, changed->periodic);
  } else {
    for (std::size_t a = 0; a < R; ++a) d.shape[a] = points.extent(a);
    d.points = std::move(points);
  }
  Result<R> r = approximate<R>(std::move(d), changed ? *changed : options, what);
  // A closing line left out has the parameter one period after the first line's.
  for (std::size_t a = 0; a < R; ++a)
    if (r.fit.axes[a].n < given[a]) r.fit.axes[a].t.push_back(r.fit.axes[a].t.front() + 1.0);
  if (unit != 1) {
    for (double& x : r.fit.cp) x *= unit;
    scale_points<R>(r.data.points, unit);
    r.report.max_error *= unit;
    r.report.rms_error *= unit;
  }
  return r;
}

// The fitted data as the checks of approx_check.hpp take them.
template <std::size_t R>
detail::ApproxData check_data(const Data<R>& d) {
  return {std::vector<std::size_t>(d.shape.begin(), d.shape.end()), std::span<const Vec3>(d.points.data(), d.points.size()),
          std::span<const double>(d.weight)};
}

// The checks every result passes (docs/spec-format.md, "approximate"): a sane
// control net before the spline is made of it.
template <std::size_t R>
void check_net(const Result<R>& r, const Grid<Vec3, R>& net, const char* what) {
  std::vector<std::size_t> shape;
  for (std::size_t a = 0; a < R; ++a) shape.push_back(static_cast<std::size_t>(r.fit.axes[a].c));
  detail::check_approx_net(std::span<const Vec3>(net.data(), net.size()), shape, check_data<R>(r.data), what);
}

// Then the distances, measured on the finished spline by its own evaluator: the
// report's largest one, and the tolerance kept or refused.
template <std::size_t R>
void check_distance(Result<R>& r, const detail::ApproxDistance& e, const ApproximationOptions<R>& o) {
  r.report.max_error = e.max;
  r.report.max_error_at = unflatten<R>(e.worst, r.data.shape);
  if (o.tolerance) detail::check_approx_tolerance(e, *o.tolerance, check_data<R>(r.data), r.report.control_points);
}

}  // namespace

}  // namespace interpatch::detail::approx

namespace interpatch {

CurveApproximation approximate_curve(std::span<const Vec3> points, const CurveApproximationOptions& options) {
  using namespace detail::approx;
  Grid<Vec3, 1> g({points.size()}, std::vector<Vec3>(points.begin(), points.end()));
  Result<1> r = run<1>(std::move(g), options, "curve");
  Grid<Vec3, 1> net = control_net<1>(r.fit);
  check_net<1>(r, net, "curve approximation");
  std::vector<Vec3> cp(net.values().begin(), net.values().end());
  Axis& u = r.fit.axes[0];
  BSplineCurve curve(u.knots, std::move(cp));
  check_distance<1>(r, detail::approx_distance(curve, u.t, check_data<1>(r.data)), options);
  return {std::move(curve), std::move(u.t), std::move(r.report)};
}

SurfaceApproximation approximate_surface(PointGrid points, const SurfaceApproximationOptions& options) {
  using namespace detail::approx;
  Result<2> r = run<2>(std::move(points), options, "surface");
  PointGrid net = control_net<2>(r.fit);
  check_net<2>(r, net, "surface approximation");
  auto& ax = r.fit.axes;
  BSplineSurface surface(ax[0].knots, ax[1].knots, std::move(net));
  check_distance<2>(r, detail::approx_distance(surface, ax[0].t, ax[1].t, check_data<2>(r.data)), options);
  return {std::move(surface), std::move(ax[0].t), std::move(ax[1].t), std::move(r.report)};
}

VolumeApproximation approximate_volume(PointGrid3 points, const VolumeApproximationOptions& options) {
  using namespace detail::approx;
  Result<3> r = run<3>(std::move(points), options, "volume");
  PointGrid3 net = control_net<3>(r.fit);
  check_net<3>(r, net, "volume approximation");
  auto& ax = r.fit.axes;
  BSplineVolume volume(ax[0].knots, ax[1].knots, ax[2].knots, std::move(net));
  check_distance<3>(r, detail::approx_distance(volume, ax[0].t, ax[1].t, ax[2].t, check_data<3>(r.data)), options);
  return {std::move(volume), std::move(ax[0].t), std::move(ax[1].t), std::move(ax[2].t), std::move(r.report)};
}

}  // namespace interpatch
