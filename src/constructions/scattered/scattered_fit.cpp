#include "constructions/scattered/scattered_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/scattered/scattered_multigrid.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::scattered {

namespace {

// The largest net factored when conjugate gradients would take many steps: 78 400
// control points took 6.4 s and 305 MB, against 28 s of conjugate gradients; the time
// grows as n^1.5. Factored only when the memory (up to direct_bytes a control point)
// is there.
constexpr std::size_t direct_limit = 100000;
constexpr std::size_t direct_bytes = 8192;
// Conjugate gradients' steps between two looks at their rate, from which the steps to
// the end are told, and the most steps worth taking when the factorization is the other
// way.
constexpr int probe_steps = 40;
constexpr int slow_steps = 150;

[[noreturn]] void not_definite(const Net& net) {
  fail(errc::singular, "scattered approximation with ", net.nu, " x ", net.nv, " control points: the normal ",
       "equations are not positive definite (points all on one line of the parameter plane)");
}

// The coarsest net of `net`'s multigrid, its matrix (data and fairness at `scaled`,
// the weight times the points' weight sum) moved out of `kept`, and the preconditioner
// over it and `top`.
struct Hierarchy {
  Net coarse;
  std::optional<NetMatrix> coarsest;
  std::optional<Multigrid> mg;
};

Hierarchy hierarchy_for(const Net& net, const NetMatrix& top, double scaled, KeptMatrices& kept, int cols) {
  Hierarchy h{hierarchy(net, coarsest_net).front(), std::nullopt, std::nullopt};
  h.coarsest = kept.take(h.coarse, scaled);
  if (!h.coarsest) fail(errc::internal, "scattered multigrid: no matrix for the coarse net of ", h.coarse.nu, " x ", h.coarse.nv, " control points");
  h.mg.emplace(h.coarse, net, &*h.coarsest, &top, cols);
  return h;
}

}  // namespace

namespace {

// A 10-bit index's bits spread to the even places of 20: a cell's place on a Z-curve is
// spread(i) << 1 | spread(j).
constexpr auto spread = [] {
  std::array<std::uint32_t, 1024> out{};
  for (std::uint32_t i = 0; i < 1024; ++i)
    for (int b = 0; b < 10; ++b) out[i] |= ((i >> b) & 1U) << (2 * b);
  return out;
}();

// The points present in the order of their cells on a 1024 × 1024 grid over the domain
// along a Z-curve, the order given within a cell (two stable counting sorts of 10 bits),
// on the threads: each in contiguous blocks of points, each block's count of each bin,
// the blocks placing their points after those of the blocks before. A stable sort has
// one result, whatever the blocks.
template <class UnitAt>
std::vector<std::uint32_t> z_sorted(const Sites& s, const UnitAt& unit_at, std::array<double, 2> range) {
  const std::size_t n = s.size();
  const bool parallel = n >= parallel_min_work / 16;
  const std::size_t blocks = parallel ? max_threads() : 1;
  const auto cut = [&](std::size_t b, std::size_t count) { return std::array<std::size_t, 2>{count * b / blocks, count * (b + 1) / blocks}; };
  std::vector<std::uint32_t> key(n);
  std::vector<std::size_t> present(blocks + 1, 0);
  parallel_for(blocks, parallel, Share::blocks, [&](std::size_t b) {
    const auto cell = [](double t, double r) { return static_cast<std::uint32_t>(std::clamp(t / r * 1024, 0.0, 1023.0)); };
    const auto [lo, hi] = cut(b, n);
    for (std::size_t k = lo; k < hi; ++k) {
      if (!s.counts(k)) continue;
      const std::array<double, 2> u = unit_at(k);
      key[k] = spread[cell(u[0], range[0])] << 1 | spread[cell(u[1], range[1])];
      ++present[b + 1];
    }
  });
  for (std::size_t b = 0; b < blocks; ++b) present[b + 1] += present[b];
  std::vector<std::uint32_t> order(present.back()), next(present.back());
  parallel_for(blocks, parallel, Share::blocks, [&](std::size_t b) {
    const auto [lo, hi] = cut(b, n);
    std::size_t at = present[b];
    for (std::size_t k = lo; k < hi; ++k)
      if (s.counts(k)) order[at++] = static_cast<std::uint32_t>(k);
  });
  const std::size_t m = order.size();
  std::vector<std::size_t> start(1024 * blocks);  // bin-major: where block b's points of a bin go
  for (const int shift : {0, 10}) {
    const auto bin = [&](std::uint32_t k) { return (key[k] >> shift) & 1023U; };
    std::fill(start.begin(), start.end(), 0);
    parallel_for(blocks, parallel, Share::blocks, [&](std::size_t b) {
      const auto [lo, hi] = cut(b, m);
      for (std::size_t x = lo; x < hi; ++x) ++start[bin(order[x]) * blocks + b];
    });
    std::size_t sum = 0;
    for (std::size_t& v : start) sum += std::exchange(v, sum);
    parallel_for(blocks, parallel, Share::blocks, [&](std::size_t b) {
      const auto [lo, hi] = cut(b, m);
      for (std::size_t x = lo; x < hi; ++x) next[start[bin(order[x]) * blocks + b]++] = order[x];
    });
    order.swap(next);
  }
  return order;
}

}  // namespace

void require_indexable(std::size_t points) {
  if (points > std::numeric_limits<std::uint32_t>::max())
    fail(errc::too_large, "scattered approximation of ", points, " points: at most ", std::numeric_limits<std::uint32_t>::max(),
         " (points are indexed in 32 bits)");
}

Problem frame(std::span<const Vec3> points, const Sites& s, int p, int q, bool xy, bool folds, bool z_curve) {
  require_indexable(points.size());
  Problem pr;
  pr.p = p, pr.q = q, pr.cols = xy ? 1 : 3, pr.sites = &s, pr.points = points;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.counts(k)) pr.centre = pr.centre + points[k];
  pr.centre = pr.centre * (1.0 / static_cast<double>(s.present));
  double top = 0;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.counts(k)) top = std::max(top, max_abs(points[k] - pr.centre));
  pr.unit_length = approximation_unit(top);
  pr.scale = 1 / pr.unit_length;
  const auto [u0, u1] = s.domain[0];
  const auto [v0, v1] = s.domain[1];
  pr.aspect = (u1 - u0) / (v1 - v0);
  pr.side = std::max(u1 - u0, v1 - v0);
  pr.lower = {u0, v0};
  pr.range = {(u1 - u0) / pr.side, (v1 - v0) / pr.side};
  if (z_curve) {
    pr.order = z_sorted(s, [&pr](std::size_t k) { return pr.input_unit(k); }, pr.range);
  } else {
    pr.order.reserve(s.present);
    for (std::size_t k = 0; k < points.size(); ++k)
      if (s.counts(k)) pr.order.push_back(static_cast<std::uint32_t>(k));
  }
  const std::size_t n = pr.order.size();
  bool unit_weights = true;
  for (std::size_t i = 0; i < n && unit_weights; ++i) unit_weights = s.weight_at(pr.order[i]) == 1;
  if (!unit_weights) {
    pr.weight.resize(n);
    for (std::size_t i = 0; i < n; ++i) pr.weight[i] = s.weight[pr.order[i]];
  }
  if (folds) {
    pr.fold.resize(n);
    for (std::size_t i = 0; i < n; ++i) pr.fold[i] = fold_of(points[pr.order[i]]);
  }
  return pr;
}

// A net's values (cols per control point) as a surface over the net's domain (one
// column: in z).
BSplineSurface unit_surface(const Net& net, std::span<const double> x, int cols) {
  PointGrid cp({static_cast<std::size_t>(net.nu), static_cast<std::size_t>(net.nv)});
  for (std::size_t r = 0; r < net.size(); ++r)
    cp.values()[r] = cols == 1 ? Vec3{0, 0, x[r]} : Vec3{x[3 * r], x[3 * r + 1], x[3 * r + 2]};
  return BSplineSurface(net.ku, net.kv, std::move(cp));
}

System data_system(const Problem& pr, const Net& net, std::span<const double> weight) {
  const int hu = std::max(net.p, 2), hv = std::max(net.q, 2);
  require_memory(net.size(), NetMatrix::bytes_per_row(hu, hv) + StripSmoother::bytes_per_row(hu, hv) + sizeof(double) * static_cast<std::size_t>(8 + 5 * pr.cols),
                 cat("scattered approximation's net of ", net.nu, " x ", net.nv, " control points"));
  System sys{NetMatrix(net.nu, net.nv, hu, hv), std::vector<double>(net.size() * static_cast<std::size_t>(pr.cols), 0.0),
             pr.cols};
  add_data_term(net, pr.samples(weight), sys);
  return sys;
}

double fill_lambda(const Net& net, const NetMatrix& data, double weight_sum) {
  std::vector<double> fair_diagonal(net.size(), 0.0);
  add_fairness(net, nullptr, 0, &fair_diagonal);
  const double fair_mean = std::accumulate(fair_diagonal.begin(), fair_diagonal.end(), 0.0) / static_cast<double>(net.size());
  return 1e-5 * (mean_diagonal(data) / weight_sum) / fair_mean;
}

// Solves one net's system from the x given: factored when small, otherwise conjugate
// gradients to a residual of 1e-12 of the right-hand side (the fit to about twelve
// digits of the data's size), preconditioned by multigrid. Where cells hold a few
// points or more they take one or two dozen steps; where they hold about one or fewer
// (only the small fill between the points), hundreds: a net the factorization takes is
// then factored as soon as the first steps show the rate, a larger one runs on and is
// refused if it stalls.
std::optional<NetMatrix> KeptMatrices::take(const Net& net, double scaled) {
  for (auto e = kept_.begin(); e != kept_.end(); ++e) {
    if (!e->net.same_knots(net)) continue;
    NetMatrix a = std::move(e->a);
    if (scaled != e->scaled) add_fairness(net, &a, scaled - e->scaled);
    kept_.erase(e);
    return a;
  }
  return std::nullopt;
}

bool KeptMatrices::has(const Net& net) const {
  return std::any_of(kept_.begin(), kept_.end(), [&](const Entry& e) { return e.net.same_knots(net); });
}

void KeptMatrices::keep(const Net& net, NetMatrix a, double scaled) {
  a.unmirror();
  kept_.push_back(Entry{net, scaled, std::move(a)});
}

void solve_net(const Problem& pr, const Net& net, System& sys, double scaled, std::vector<double>& x, KeptMatrices& kept,
               bool rhs_after) {
  if (net.size() <= coarsest_net) {
    if (!solve_direct(sys.a, sys.rhs, x, pr.cols)) not_definite(net);
    return;
  }
  const bool factorable = net.size() <= direct_limit && available_memory() / direct_bytes >= net.size();
  Solved sol;
  {
    sys.a.mirror();
    sys.a.pack();  // before the strips' factors are made: the peak of a large net's memory
    Hierarchy h = hierarchy_for(net, sys.a, scaled, kept, pr.cols);
    if (!h.mg->factor()) not_definite(h.coarse);
    Multigrid& mg = *h.mg;
    double before = 0;  // the residual probe_steps ago
    const KeepGoing keep_going = [&](int steps, double residual) {
      if (!factorable || steps % probe_steps != 0) return true;
      const double rate = std::log(residual / before) / probe_steps;  // per step, below 0 while converging
      before = residual;
      return steps == 0 || (rate < 0 && steps + std::log(1e-12 / residual) / rate <= slow_steps);
    };
    // Without the factorization to fall back on, nor a caller that needs it, the
    // right-hand side's memory holds the residual.
    const bool consume = !factorable && !rhs_after;
    if (std::all_of(x.begin(), x.end(), [](double v) { return v == 0; })) mg.coarse_guess(sys.rhs, x);
    sol = solve_cg(sys.a, sys.rhs, x, pr.cols, 1e-12, factorable ? 4 * slow_steps : 200 + 40 * (net.nu + net.nv),
                   [&mg](std::span<const double> r, std::span<double> z, int) { mg.apply(r, z); }, keep_going,
                   consume ? std::span<double>(sys.rhs) : std::span<double>());
    if (consume) std::vector<double>().swap(sys.rhs);
    kept.keep(h.coarse, std::move(*h.coarsest), scaled);
  }
  if (sol.residual <= 1e-12) return;
  if (factorable) {
    if (!solve_direct(sys.a, sys.rhs, x, pr.cols)) not_definite(net);
    return;
  }
  if (!(sol.residual <= 1e-9))
    fail(errc::ill_conditioned, "scattered approximation with ", net.nu, " x ", net.nv, " control points: conjugate gradients ",
         "left a residual of ", sol.residual, " of the data after ", sol.iterations, " steps");
}

namespace {

// The data terms of the nets of `net`'s multigrid that `kept` lacks, each restricted
// from the next finer one's (from `data`, the net's own, for the first), summed with the
// fairness at `scaled` and kept: all of them when `all` (finer nets to be solved later
// take them), otherwise the coarsest alone, the only one the solve uses. A pass over the
// points costs about as much on every net; a restriction, a few hundred numbers a fine
// control point.
void restrict_hierarchy(const Net& net, const System& data, double scaled, KeptMatrices& kept, bool all) {
  std::vector<Net> below = hierarchy(net, coarsest_net);  // coarsest first
  below.pop_back();
  std::size_t first = below.size();
  while (first > 0 && !kept.has(below[first - 1])) --first;  // the nets below a kept one are kept with it
  below.erase(below.begin(), below.begin() + static_cast<std::ptrdiff_t>(first));
  if (below.empty()) return;
  if (!all) below.erase(below.begin() + 1, below.end());
  // The coarsest alone straight from `data`: P (knot insertion from it to `net`) still has
  // p + 1 entries a fine row, and the nets between take no pass.
  std::vector<System> terms = all ? restrict_down(data, net, below) : std::vector<System>{};
  if (!all) terms.push_back(restrict_between(data, net, below[0]));
  for (std::size_t l = 0; l < below.size(); ++l) {
    add_fairness(below[l], &terms[l].a, scaled);
    kept.keep(below[l], std::move(terms[l].a), scaled);
  }
}

}  // namespace

// One net solved: the normal equations assembled, λ (at least the small one that fills
// voids), from the coarser fit's values at this net's Greville abscissae (zero for the
// first).
Level solve_level(const Problem& pr, const Net& net, std::optional<double> smoothing, const BSplineSurface* coarser,
                  std::vector<double> start, KeptMatrices* kept, std::optional<System> data) {
  const Sites& s = *pr.sites;
  System sys = data ? std::move(*data) : data_system(pr, net, pr.weight);
  Level out;
  out.lambda = std::max(fill_lambda(net, sys.a, s.weight_sum), smoothing.value_or(0.0));
  KeptMatrices own;
  if (net.size() > coarsest_net) restrict_hierarchy(net, sys, s.weight_sum * out.lambda, kept ? *kept : own, kept != nullptr);
  add_fairness(net, &sys.a, s.weight_sum * out.lambda);
  const bool started = start.size() == sys.rhs.size();
  if (started) out.x = std::move(start);
  else out.x.assign(sys.rhs.size(), 0.0);
  if (coarser && !started && net.size() > coarsest_net) {
    const std::vector<double> gu = net.ku.greville(), gv = net.kv.greville();
    std::vector<Vec3> at(net.size());
    coarser->evaluate_into(gu, gv, at);
    for (std::size_t r = 0; r < net.size(); ++r) {
      if (pr.cols == 1) out.x[r] = at[r].z;
      else out.x[3 * r] = at[r].x, out.x[3 * r + 1] = at[r].y, out.x[3 * r + 2] = at[r].z;
    }
  }
  solve_net(pr, net, sys, s.weight_sum * out.lambda, out.x, kept ? *kept : own, kept != nullptr);
  if (kept) {
    std::vector<double> ax(out.x.size());
    sys.a.multiply(out.x, ax, pr.cols);
    for (std::size_t k = 0; k < ax.size(); ++k) out.x_a_x += out.x[k] * ax[k], out.x_b += out.x[k] * sys.rhs[k];
    kept->keep(net, std::move(sys.a), s.weight_sum * out.lambda);
  }
  return out;
}

namespace {

// The spline's value at a site minus the value given, C columns: the sums in registers
// (a runtime column count kept them in memory, each step waiting on the last).
template <int C>
double distance_in(const Net& net, std::span<const double> x, std::array<double, 2> site, const double* value) {
  const std::size_t nv = static_cast<std::size_t>(net.nv);
  double bu[max_degree + 1], bv[max_degree + 1];
  const int su = net.span_u(site[0]), sv = net.span_v(site[1]);
  net.basis_u(su, site[0], bu);
  net.basis_v(sv, site[1], bv);
  double at[C] = {};
  for (int a = 0; a <= net.p; ++a) {
    const double* row = &x[(static_cast<std::size_t>(su - net.p + a) * nv + static_cast<std::size_t>(sv - net.q)) * C];
    double part[C] = {};
    for (int e = 0; e <= net.q; ++e)
      for (int m = 0; m < C; ++m) part[m] += bv[e] * row[e * C + m];
    for (int m = 0; m < C; ++m) at[m] += bu[a] * part[m];
  }
  double sq = 0;
  for (int m = 0; m < C; ++m) sq += (at[m] - value[m]) * (at[m] - value[m]);
  return std::sqrt(sq);
}

}  // namespace

double distance_of(const Net& net, std::span<const double> x, int cols, std::array<double, 2> site, const double* value) {
  return cols == 1 ? distance_in<1>(net, x, site, value) : distance_in<3>(net, x, site, value);
}

}  // namespace interpatch::detail::scattered
