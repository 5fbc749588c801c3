// approximate_scattered: the sites (scattered_sites.hpp), the values centred and
// scaled, a cascade of nets solved coarse to fine (scattered_system.hpp), and the
// checks every result passes on the finished spline.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/scattered/scattered_sites.hpp"
#include "constructions/scattered/scattered_system.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::scattered {

namespace {

// The largest net solved by a sparse factorization (about 8 s at 200 x 200, its time
// growing as n^1.5): below it conjugate gradients are no faster where the points are
// dense, and far slower across voids, where the fairness term alone holds the net.
constexpr std::size_t direct_limit = 40000;

// The fit in its own frame: unit sites, values centred on the points' mean and scaled
// into a power of two near their size (sums of squares neither overflow nor vanish).
struct Problem {
  int p = 3, q = 3, cols = 3;
  std::vector<std::array<double, 2>> unit;
  std::vector<double> value;  // cols per point
  const Sites* sites = nullptr;
  Vec3 centre{};
  double unit_length = 1;
  double aspect = 1;  // the domain's extent along u over its extent along v
  // The domain in the fit's frame: [0, range[0]] × [0, range[1]], the longer side 1, so
  // that J weighs both directions alike (the thin-plate energy of the domain itself).
  std::array<double, 2> range{1, 1};
};

Problem frame(std::span<const Vec3> points, const Sites& s, int p, int q, bool xy) {
  Problem pr;
  pr.p = p, pr.q = q, pr.cols = xy ? 1 : 3, pr.sites = &s;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.weight[k] > 0) pr.centre = pr.centre + points[k];
  pr.centre = pr.centre * (1.0 / static_cast<double>(s.present));
  double top = 0;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.weight[k] > 0) top = std::max(top, max_abs(points[k] - pr.centre));
  pr.unit_length = approximation_unit(top);
  const double inv = 1 / pr.unit_length;
  const auto [u0, u1] = s.domain[0];
  const auto [v0, v1] = s.domain[1];
  pr.aspect = (u1 - u0) / (v1 - v0);
  const double side = std::max(u1 - u0, v1 - v0);
  pr.range = {(u1 - u0) / side, (v1 - v0) / side};
  pr.unit.assign(points.size(), {0, 0});
  pr.value.assign(points.size() * static_cast<std::size_t>(pr.cols), 0.0);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!(s.weight[k] > 0)) continue;
    pr.unit[k] = {std::clamp((s.uv[k][0] - u0) / side, 0.0, pr.range[0]), std::clamp((s.uv[k][1] - v0) / side, 0.0, pr.range[1])};
    const Vec3 d = (points[k] - pr.centre) * inv;
    if (xy) pr.value[k] = d.z;
    else pr.value[3 * k] = d.x, pr.value[3 * k + 1] = d.y, pr.value[3 * k + 2] = d.z;
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

struct Level {
  std::vector<double> x;
  double lambda = 0;  // in E's units: the weight of J against the mean squared distance
};

// One net solved: the normal equations assembled, λ (at least the small one that fills
// voids), and conjugate gradients from the coarser fit's values at this net's Greville
// abscissae (zero for the first).
Level solve_level(const Problem& pr, const Net& net, std::optional<double> smoothing, const BSplineSurface* coarser) {
  require_memory(net.size(), sizeof(double) * static_cast<std::size_t>(std::max(net.p, 2) * (2 * std::max(net.q, 2) + 1) + 8 + 5 * pr.cols),
                 cat("scattered approximation's net of ", net.nu, " x ", net.nv, " control points"));
  const Sites& s = *pr.sites;
  System sys{NetMatrix(net.nu, net.nv, std::max(net.p, 2), std::max(net.q, 2)), std::vector<double>(net.size() * static_cast<std::size_t>(pr.cols), 0.0),
             pr.cols};
  add_data_term(net, Samples{pr.unit, s.weight, pr.value, pr.cols}, sys);
  std::vector<double> fair_diagonal(net.size(), 0.0);
  add_fairness(net, nullptr, 0, &fair_diagonal);
  const double fair_mean = std::accumulate(fair_diagonal.begin(), fair_diagonal.end(), 0.0) / static_cast<double>(net.size());
  const double fill = 1e-5 * (mean_diagonal(sys.a) / s.weight_sum) / fair_mean;
  Level out;
  out.lambda = std::max(fill, smoothing.value_or(0.0));
  add_fairness(net, &sys.a, s.weight_sum * out.lambda);

  // Nets up to direct_limit control points are factored: exact whatever λ and the
  // points' spacing. Larger ones take conjugate gradients to a residual of 1e-12 of the
  // right-hand side, the fit to about twelve digits of the data's size; their λ is the
  // small one of tolerance and control_points (smoothing's nets stay below the limit).
  out.x.assign(sys.rhs.size(), 0.0);
  if (net.size() <= direct_limit) {
    if (!solve_direct(sys.a, sys.rhs, out.x, pr.cols))
      fail(errc::singular, "scattered approximation with ", net.nu, " x ", net.nv, " control points: the normal ",
           "equations are not positive definite (points all on one line of the parameter plane)");
    return out;
  }
  if (coarser) {
    const std::vector<double> gu = net.ku.greville(), gv = net.kv.greville();
    std::vector<Vec3> at(net.size());
    coarser->evaluate_into(gu, gv, at);
    for (std::size_t r = 0; r < net.size(); ++r) {
      if (pr.cols == 1) out.x[r] = at[r].z;
      else out.x[3 * r] = at[r].x, out.x[3 * r + 1] = at[r].y, out.x[3 * r + 2] = at[r].z;
    }
  }
  const int cap = 200 + 40 * (net.nu + net.nv);
  const Solved sol = solve_cg(sys.a, sys.rhs, out.x, pr.cols, 1e-12, cap);
  if (!(sol.residual <= 1e-9))
    fail(errc::ill_conditioned, "scattered approximation with ", net.nu, " x ", net.nv, " control points: conjugate gradients ",
         "left a residual of ", sol.residual, " of the data after ", sol.iterations, " steps");
  return out;
}

// Largest distance from the points present to a surface at their sites, and where,
// the threads in blocks whose results are merged in order (the lowest index wins a tie).
ApproxDistance distances(const BSplineSurface& s, std::span<const std::array<double, 2>> site, std::span<const Vec3> target,
                         std::span<const double> weight, double* sum_sq) {
  constexpr std::size_t block = 8192;
  const std::size_t n = site.size(), blocks = (n + block - 1) / block;
  std::vector<ApproxDistance> part(blocks);
  std::vector<double> sq(blocks, 0.0);
  parallel_for(blocks, n >= parallel_min_work / 64, Share::blocks, [&](std::size_t b) {
    for (std::size_t k = b * block; k < std::min(n, (b + 1) * block); ++k) {
      if (!(weight[k] > 0)) continue;
      const double d = distance(s.point(site[k][0], site[k][1]), target[k]);
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

// About `cells` knot cells, shaped after the domain (cells near square in its units).
std::array<int, 2> spans_for(double aspect, double cells) {
  const auto round = [](double x) { return static_cast<int>(std::clamp(std::lround(x), 1L, 1L << 20)); };
  return {round(std::sqrt(cells * aspect)), round(std::sqrt(cells / aspect))};
}

// The nets a fit of `spans` solves in turn: halved until a net is small enough to be
// factored, each larger one then started from the one before.
std::vector<std::array<int, 2>> cascade(std::array<int, 2> spans, int p, int q) {
  std::vector<std::array<int, 2>> out{spans};
  const auto size = [&](const std::array<int, 2>& s) { return static_cast<std::size_t>(s[0] + p) * static_cast<std::size_t>(s[1] + q); };
  while (size(spans) > direct_limit) {
    spans = {(spans[0] + 1) / 2, (spans[1] + 1) / 2};
    out.push_back(spans);
  }
  std::reverse(out.begin(), out.end());
  return out;
}

struct Fitted {
  Net net;
  Level level;
  int fits = 0;
};

Fitted solve_cascade(const Problem& pr, std::array<int, 2> spans, std::optional<double> smoothing, const progress_callback& progress) {
  const auto nets = cascade(spans, pr.p, pr.q);
  std::optional<BSplineSurface> coarser;
  Fitted f{Net(pr.p, pr.q, pr.p + 1, pr.q + 1, pr.range), {}, 0};
  for (std::size_t l = 0; l < nets.size(); ++l) {
    f.net = Net(pr.p, pr.q, nets[l][0] + pr.p, nets[l][1] + pr.q, pr.range);
    f.level = solve_level(pr, f.net, smoothing, coarser ? &*coarser : nullptr);
    ++f.fits;
    if (progress) progress(static_cast<double>(l + 1) / static_cast<double>(nets.size() + 1));
    if (l + 1 < nets.size()) coarser = unit_surface(f.net, f.level.x, pr.cols);
  }
  return f;
}

// The data in the fit's frame, as points (one column: in z).
std::vector<Vec3> frame_targets(const Problem& pr) {
  std::vector<Vec3> t(pr.unit.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    t[k] = pr.cols == 1 ? Vec3{0, 0, pr.value[k]} : Vec3{pr.value[3 * k], pr.value[3 * k + 1], pr.value[3 * k + 2]};
  return t;
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

[[noreturn]] void refuse_tolerance(double tolerance, const ApproxDistance& e, const Problem& pr, const Net& net,
                                   const std::array<int, 2>& limit, bool given) {
  fail(errc::tolerance_not_met, "tolerance ", tolerance, " not met: point [", e.worst, "] is ", e.max * pr.unit_length,
       " from the approximation with ", net.nu, " x ", net.nv, " control points, and doubling the knots would pass the ",
       "largest net allowed (", limit[0], " x ", limit[1], given ? " control points, max_control_points" :
       " control points, and at most one per 4 points present", "): points closer together than the knots can separate, ",
       "with values farther apart than twice the tolerance, or a tolerance below the rounding of the coordinates");
}

Fitted solve_tolerance(const Problem& pr, double tolerance, const ScatteredApproximationOptions& o, const progress_callback& progress) {
  const Sites& s = *pr.sites;
  const double d = tolerance / pr.unit_length;
  const std::vector<Vec3> target = frame_targets(pr);
  const std::array<int, 2> limit = largest_net(o);
  std::array<int, 2> spans = spans_for(pr.aspect, 1);
  std::optional<BSplineSurface> coarser;
  Fitted f{Net(pr.p, pr.q, pr.p + 1, pr.q + 1, pr.range), {}, 0};
  for (;;) {
    f.net = Net(pr.p, pr.q, spans[0] + pr.p, spans[1] + pr.q, pr.range);
    f.level = solve_level(pr, f.net, std::nullopt, coarser ? &*coarser : nullptr);
    ++f.fits;
    coarser = unit_surface(f.net, f.level.x, pr.cols);
    const ApproxDistance e = distances(*coarser, pr.unit, target, s.weight, nullptr);
    if (e.max <= d) return f;
    const std::array<int, 2> next{2 * spans[0] + pr.p, 2 * spans[1] + pr.q};
    if (!within(next, limit, o, s)) refuse_tolerance(tolerance, e, pr, f.net, limit, o.max_control_points.has_value());
    spans = {2 * spans[0], 2 * spans[1]};
    if (progress) progress(std::min(0.9, 0.1 * f.fits));
  }
}

}  // namespace

}  // namespace interpatch::detail::scattered

namespace interpatch {

ScatteredApproximation approximate_scattered(std::span<const Vec3> points, const ScatteredApproximationOptions& o) {
  using namespace detail::scattered;
  using detail::fail;
  const int ways = (o.control_points ? 1 : 0) + (o.tolerance ? 1 : 0) + (o.smoothing ? 1 : 0);
  if (ways != 1)
    fail(errc::wrong_type, "scattered approximation takes exactly one of control_points, tolerance and smoothing, got ", ways);
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
  const Problem pr = frame(points, s, deg[0], deg[1], xy);
  Fitted f = o.tolerance ? solve_tolerance(pr, *o.tolerance, o, o.progress)
             : o.control_points
                 ? solve_cascade(pr, {(*o.control_points)[0] - deg[0], (*o.control_points)[1] - deg[1]}, std::nullopt, o.progress)
                 : solve_cascade(pr, [&] {
                     auto sp = spans_for(pr.aspect, static_cast<double>(s.present));
                     sp[0] = std::min(sp[0], smoothing_max_control_points - deg[0]);
                     sp[1] = std::min(sp[1], smoothing_max_control_points - deg[1]);
                     return sp;
                   }(), o.smoothing, o.progress);

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
      net(i, j) = xy ? Vec3{gu[i], gv[j], x[r] * pr.unit_length + pr.centre.z}
                     : Vec3{x[3 * r], x[3 * r + 1], x[3 * r + 2]} * pr.unit_length + pr.centre;
    }
  const detail::ApproxData data{{points.size()}, points, s.weight};
  detail::check_approx_net(std::span<const Vec3>(net.data(), net.size()), {gu.size(), gv.size()}, data,
                           "scattered approximation");

  ScatteredApproximation r{BSplineSurface(std::move(ku), std::move(kv), std::move(net)), s.uv, s.domain, s.origin,
                           s.axis_u, s.axis_v, {}};
  double sum_sq = 0;
  const detail::ApproxDistance e = distances(r.surface, s.uv, points, s.weight, &sum_sq);
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
