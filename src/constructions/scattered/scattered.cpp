// approximate_scattered: the sites (scattered_sites.hpp), the values centred and
// scaled, the net's normal equations (scattered_system.hpp) solved with multigrid
// (scattered_multigrid.hpp), and the checks every result passes on the finished spline.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/scattered/scattered_fit.hpp"
#include "constructions/scattered/scattered_multigrid.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::scattered {

namespace {

// The largest of distance(k) over n points (those of weight above 0 when `weight` is
// given), and where, the threads in blocks whose results are merged in order (the lowest
// index wins a tie); a NaN distance counts as infinite. Adds the squares to *sum_sq
// when given.
template <class F>
ApproxDistance worst_point(std::size_t n, std::span<const double> weight, double* sum_sq, F&& distance) {
  constexpr std::size_t block = 8192;
  const std::size_t blocks = (n + block - 1) / block;
  std::vector<ApproxDistance> part(blocks);
  std::vector<double> sq(blocks, 0.0);
  parallel_for(blocks, n >= parallel_min_work / 64, Share::blocks, [&](std::size_t b) {
    for (std::size_t k = b * block; k < std::min(n, (b + 1) * block); ++k) {
      if (!weight.empty() && !(weight[k] > 0)) continue;
      const double d = distance(k);
      sq[b] += d * d;
      if (!(d <= part[b].max)) part[b] = {std::isnan(d) ? std::numeric_limits<double>::infinity() : d, k};
    }
  });
  ApproxDistance e;
  for (std::size_t b = 0; b < blocks; ++b) {
    if (part[b].max > e.max) e = part[b];
    if (sum_sq) *sum_sq += sq[b];
  }
  return e;
}

// Largest distance from the points present to a surface at their sites, through the
// surface's own evaluator: the check of the spline returned.
ApproxDistance distances(const BSplineSurface& s, std::span<const std::array<double, 2>> site, std::span<const Vec3> target,
                         std::span<const double> weight, double* sum_sq) {
  return worst_point(target.size(), weight, sum_sq, [&](std::size_t k) { return distance(s.point(site[k][0], site[k][1]), target[k]); });
}

// The same for a fit still in the fit's frame, from the net's values and the basis at
// each site (no surface built, no derivatives): what the tolerance's refinement
// measures after each fit. The worst point is named by its index in the problem's order.
ApproxDistance net_distances(const Problem& pr, const Net& net, std::span<const double> x) {
  return worst_point(pr.size(), pr.weight, nullptr, [&](std::size_t k) {
    pr.prefetch(k + 16);
    return distance_at(pr, net, x, k);
  });
}

// The same over the input, in its order: the worst point as the user numbers it.
ApproxDistance input_distances(const Problem& pr, const Net& net, std::span<const double> x) {
  return worst_point(pr.points.size(), pr.sites->weight, nullptr, [&](std::size_t k) {
    double v[3];
    pr.input_value(k, v);
    return distance_of(net, x, pr.cols, pr.input_unit(k), v);
  });
}

// About `cells` knot cells, shaped after the domain (cells near square in its units).
std::array<int, 2> spans_for(double aspect, double cells) {
  const auto round = [](double x) { return static_cast<int>(std::clamp(std::lround(x), 1L, 1L << 20)); };
  return {round(std::sqrt(cells * aspect)), round(std::sqrt(cells / aspect))};
}

// A smoothing fit's net: about one control point per point present, so that λ alone
// sets how closely the surface follows the data, at most 1024 a direction.
std::array<int, 2> smoothing_spans(const Problem& pr, const Sites& s) {
  auto sp = spans_for(pr.aspect, static_cast<double>(s.present));
  sp[0] = std::min(sp[0], smoothing_max_scattered - pr.p);
  sp[1] = std::min(sp[1], smoothing_max_scattered - pr.q);
  return sp;
}

struct Fitted {
  Net net;
  Level level;
  int fits = 0;
};

// The fit's last use of `pr`'s points: their order is let go once the data term is
// made, before the solve's peak of memory (4 MB of a million points).
Fitted solve_once(Problem& pr, std::array<int, 2> spans, std::optional<double> smoothing, const progress_callback& progress,
                  std::vector<double> start = {}) {
  Fitted f{Net(pr.p, pr.q, spans[0] + pr.p, spans[1] + pr.q, pr.range), {}, 1};
  System data = data_system(pr, f.net, pr.weight);
  std::vector<std::uint32_t>().swap(pr.order);  // = {} would keep the capacity
  f.level = solve_level(pr, f.net, smoothing, nullptr, std::move(start), nullptr, std::move(data));
  if (progress) progress(0.9);
  return f;
}

// A smoothing fit, λ given or chosen by cross-validation.
Fitted solve_smoothing(Problem& pr, const ScatteredApproximationOptions& o) {
  const auto spans = smoothing_spans(pr, *pr.sites);
  if (!o.auto_smoothing) return solve_once(pr, spans, o.smoothing, o.progress);
  Chosen c = choose_lambda(pr, Net(pr.p, pr.q, spans[0] + pr.p, spans[1] + pr.q, pr.range), o.progress, 0.0, 0.85);
  Fitted f = solve_once(pr, spans, c.lambda, o.progress, std::move(c.x));
  f.fits = c.fits + 1;
  return f;
}

// The largest net a tolerance may reach: as asked, or 4096 a direction.
std::array<int, 2> largest_net(const ScatteredApproximationOptions& o) {
  return o.max_control_points.value_or(std::array<int, 2>{4096, 4096});
}

bool within(const std::array<int, 2>& net, const std::array<int, 2>& limit, const ScatteredApproximationOptions& o, const Sites& s) {
  if (net[0] > limit[0] || net[1] > limit[1]) return false;
  if (o.max_control_points) return true;
  const double total = static_cast<double>(net[0]) * static_cast<double>(net[1]);
  return total <= std::max(static_cast<double>(s.present) / 4, 4096.0);
}

[[noreturn]] void refuse_tolerance(double tolerance, const Problem& pr, const Net& net, std::span<const double> x,
                                   const std::array<int, 2>& limit, bool given) {
  const ApproxDistance e = input_distances(pr, net, x);
  fail(errc::tolerance_not_met, "tolerance ", tolerance, " not met: point [", e.worst, "] is ", e.max * pr.unit_length,
       " from the approximation with ", net.nu, " x ", net.nv, " control points, and doubling the knots would pass the ",
       "largest net allowed (", limit[0], " x ", limit[1], given ? " control points, max_control_points" :
       " control points, and at most one per 4 points present", "): points closer together than the knots can separate, ",
       "with values farther apart than twice the tolerance, or a tolerance below the rounding of the coordinates");
}

// The data terms of the doubling sequence's first nets, up to the last whose cells
// hold 64 points or more on average: that one assembled from the points, each coarser
// one restricted from the next finer (a pass over the points for all of them, where
// each took one; restricting costs a few numbers a control point). Empty when the
// first net is already that fine. Not finer: the pass costs the same, but a finer net's
// terms, held beside the points while the first nets are fitted, took 10^6 smooth
// points to a tolerance from 2.8 to 3.0 times the input's memory.
std::vector<std::optional<System>> restricted_terms(const Problem& pr, std::array<int, 2> spans, const std::array<int, 2>& limit,
                                                    const ScatteredApproximationOptions& o) {
  const Sites& s = *pr.sites;
  std::vector<Net> nets;
  for (;;) {
    nets.emplace_back(pr.p, pr.q, spans[0] + pr.p, spans[1] + pr.q, pr.range);
    const std::array<int, 2> next{2 * spans[0] + pr.p, 2 * spans[1] + pr.q};
    const double cells = 4.0 * spans[0] * spans[1];
    if (!within(next, limit, o, s) || cells * 64 > static_cast<double>(s.present)) break;
    spans = {2 * spans[0], 2 * spans[1]};
  }
  if (nets.size() < 2) return {};
  System top = data_system(pr, nets.back(), pr.weight);
  std::vector<System> below = restrict_down(top, nets.back(), std::span<const Net>(nets).first(nets.size() - 1));  // doubling: they nest
  std::vector<std::optional<System>> out;
  for (System& t : below) out.emplace_back(std::move(t));
  out.emplace_back(std::move(top));
  return out;
}

// Σ w |z|² and Σ w over the points present, in the fit's frame.
struct Squares {
  double values = 0, weights = 0;
};

Squares squares_of(const Problem& pr) {
  Squares out;
  const Sites& s = *pr.sites;
  for (std::size_t k = 0; k < s.size(); ++k) {  // in the input's order: no gathers
    if (!s.counts(k)) continue;
    const double w = s.weight_at(k);
    double v[3];
    pr.input_value(k, v);
    for (int c = 0; c < pr.cols; ++c) out.values += w * v[c] * v[c];
    out.weights += w;
  }
  return out;
}

// Whether a fit surely misses tolerance d, told from its normal equations without a pass
// over the points: the largest distance is at least the root mean square one, and
// Σ w |S − z|² = Σ w |z|² − 2 xᵀb + xᵀDx with xᵀDx = xᵀAx − s xᵀFx (A = D + s F). Only
// when that passes d² Σ w by more than the rounding of its sums could move it (1e-9 of
// their sizes, a million terms' worst case): a coarse net, far from the tolerance,
// then skips its pass.
bool surely_missed(const Problem& pr, const Squares& sq, const Fitted& f, double d) {
  const double fair = f.level.lambda * pr.sites->weight_sum * fairness_energy(f.net, f.level.x, pr.cols);
  const double sum = sq.values - 2 * f.level.x_b + f.level.x_a_x - fair;
  const double rounding = 1e-9 * (sq.values + 2 * std::abs(f.level.x_b) + std::abs(f.level.x_a_x) + fair);
  return sum - rounding > d * d * sq.weights;
}

Fitted solve_tolerance(const Problem& pr, double tolerance, const ScatteredApproximationOptions& o, const progress_callback& progress) {
  const Sites& s = *pr.sites;
  const double d = tolerance / pr.unit_length;
  const std::array<int, 2> limit = largest_net(o);
  std::array<int, 2> spans = spans_for(pr.aspect, 1);
  std::optional<BSplineSurface> coarser;
  Fitted f{Net(pr.p, pr.q, pr.p + 1, pr.q + 1, pr.range), {}, 0};
  KeptMatrices kept;  // each net's matrix, the next nets' multigrid levels
  std::vector<std::optional<System>> terms = restricted_terms(pr, spans, limit, o);
  const Squares squares = squares_of(pr);
  for (std::size_t k = 0;; ++k) {
    f.net = Net(pr.p, pr.q, spans[0] + pr.p, spans[1] + pr.q, pr.range);
    f.level = solve_level(pr, f.net, std::nullopt, coarser ? &*coarser : nullptr, {}, &kept,
                          k < terms.size() ? std::move(terms[k]) : std::nullopt);
    ++f.fits;
    if (!surely_missed(pr, squares, f, d) && net_distances(pr, f.net, f.level.x).max <= d) return f;
    coarser = unit_surface(f.net, f.level.x, pr.cols);
    const std::array<int, 2> next{2 * spans[0] + pr.p, 2 * spans[1] + pr.q};
    if (!within(next, limit, o, s)) refuse_tolerance(tolerance, pr, f.net, f.level.x, limit, o.max_control_points.has_value());
    spans = {2 * spans[0], 2 * spans[1]};
    if (progress) progress(std::min(0.9, 0.1 * f.fits));
  }
}

// The fit and the frame that maps it back. Its problem (a site and a value per point)
// is gone when it returns, before the result's sites are made.
struct Solution {
  Fitted f;
  double unit_length = 1;
  Vec3 centre{};
};

Solution solve(std::span<const Vec3> points, const Sites& s, int p, int q, const ScatteredApproximationOptions& o) {
  Problem pr = frame(points, s, p, q, o.param == ScatteredParam::xy, o.auto_smoothing, !o.control_points);
  Fitted f = o.tolerance ? solve_tolerance(pr, *o.tolerance, o, o.progress)
             : o.control_points
                 ? solve_once(pr, {(*o.control_points)[0] - p, (*o.control_points)[1] - q}, std::nullopt, o.progress)
                 : solve_smoothing(pr, o);
  return {std::move(f), pr.unit_length, pr.centre};
}

}  // namespace

}  // namespace interpatch::detail::scattered

namespace interpatch {

ScatteredApproximation approximate_scattered(std::span<const Vec3> points, const ScatteredApproximationOptions& o) {
  using namespace detail::scattered;
  using detail::fail;
  const int ways = (o.control_points ? 1 : 0) + (o.tolerance ? 1 : 0) + (o.smoothing ? 1 : 0) + (o.auto_smoothing ? 1 : 0);
  if (ways != 1)
    fail(errc::wrong_type, "scattered approximation takes exactly one of control_points, tolerance, smoothing and ",
         "automatic smoothing, got ", ways);
  if (o.tolerance && !(*o.tolerance > 0 && std::isfinite(*o.tolerance)))
    fail(errc::wrong_type, "tolerance ", *o.tolerance, " is not a positive distance");
  if (o.smoothing && !(*o.smoothing >= 0 && std::isfinite(*o.smoothing)))
    fail(errc::wrong_type, "smoothing ", *o.smoothing, " is not a non-negative number");
  int deg[2];
  for (int a = 0; a < 2; ++a) {
    deg[a] = o.degree[static_cast<std::size_t>(a)].value_or(3);
    if (deg[a] < 1 || deg[a] > max_degree)
      fail(errc::invalid_degree, "degree ", deg[a], " along ", a == 0 ? "u" : "v", " is outside 1..", max_degree);
  }
  for (const auto* c : {o.control_points ? &*o.control_points : nullptr, o.max_control_points ? &*o.max_control_points : nullptr})
    if (c)
      for (int a = 0; a < 2; ++a)
        if ((*c)[static_cast<std::size_t>(a)] < deg[a] + 1)
          fail(errc::too_few_points, (*c)[static_cast<std::size_t>(a)], " control points along ", a == 0 ? "u" : "v",
               " are fewer than degree ", deg[a], " needs (", deg[a] + 1, ")");
  if (o.progress) o.progress(0.0);

  const Sites s = scattered_sites(points, o, deg[0], deg[1]);
  const bool xy = o.param == ScatteredParam::xy;
  const auto [f, unit_length, centre] = solve(points, s, deg[0], deg[1], o);

  // The surface in the data's own frame, over the domain.
  const auto [u0, u1] = s.domain[0];
  const auto [v0, v1] = s.domain[1];
  KnotVector ku = f.net.ku.mapped(u0, u1), kv = f.net.kv.mapped(v0, v1);
  const std::vector<double> gu = ku.greville(), gv = kv.greville();
  PointGrid net({static_cast<std::size_t>(f.net.nu), static_cast<std::size_t>(f.net.nv)});
  const std::vector<double>& x = f.level.x;
  for (std::size_t i = 0; i < gu.size(); ++i)
    for (std::size_t j = 0; j < gv.size(); ++j) {
      const std::size_t r = i * gv.size() + j;
      net(i, j) = xy ? Vec3{gu[i], gv[j], x[r] * unit_length + centre.z}
                     : Vec3{x[3 * r], x[3 * r + 1], x[3 * r + 2]} * unit_length + centre;
    }
  const detail::ApproxData data{{points.size()}, points, s.weight};
  detail::check_approx_net(std::span<const Vec3>(net.data(), net.size()), {gu.size(), gv.size()}, data,
                           "scattered approximation");

  ScatteredApproximation r{BSplineSurface(std::move(ku), std::move(kv), std::move(net)), {}, s.domain, s.origin,
                           s.axis_u, s.axis_v, {}};
  r.sites.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) r.sites.push_back(s.uv(k));
  double sum_sq = 0;
  const detail::ApproxDistance e = distances(r.surface, r.sites, points, s.weight, &sum_sq);
  ApproximationReport& rep = r.report;
  rep.max_error = e.max;
  rep.max_error_at = {e.worst};
  rep.rms_error = std::sqrt(sum_sq / static_cast<double>(s.present));
  rep.control_points = {f.net.nu, f.net.nv};
  rep.lambda = f.level.lambda;
  rep.missing = s.missing;
  rep.fits = f.fits;
  if (o.tolerance && !(e.max <= *o.tolerance))
    fail(errc::tolerance_not_met, "tolerance ", *o.tolerance, " not met: point [", e.worst, "] is ", e.max,
         " from the approximation with ", f.net.nu, " x ", f.net.nv, " control points (the rounding of coordinates of ",
         "this size)");
  if (o.progress) o.progress(1.0);
  return r;
}

}  // namespace interpatch
