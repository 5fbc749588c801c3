// A volume through section surfaces: the sections raised to one pair of degrees, their
// knots merged in u and in v, their control nets interpolated across, and every
// section checked against the result.
#include <algorithm>
#include <cmath>
#include <limits>

#include "base/text.hpp"
#include "constructions/loft/loft_across.hpp"
#include "interpatch/loft.hpp"

namespace interpatch {

namespace {

using detail::fail;

// The knots of `have` missing from `want` (both of one direction, merged), each as
// often as it is missing: what refines a section to the merged knots.
std::vector<double> missing(const KnotVector& want, const KnotVector& have) {
  const auto w = want.interior_breaks(), h = have.interior_breaks();
  std::vector<double> out;
  for (const auto& [x, m] : w) {
    int had = 0;
    for (const auto& [y, n] : h)
      if (y == x) had = n;
    out.insert(out.end(), static_cast<std::size_t>(std::max(0, m - had)), x);
  }
  return out;
}

// The sections over [0, 1]², of one pair of degrees and one pair of knot vectors.
std::vector<BSplineSurface> compatible(std::span<const BSplineSurface> given, const std::function<std::string(std::size_t)>& name) {
  std::vector<BSplineSurface> s;
  int pu = 0, pv = 0;
  for (const BSplineSurface& g : given) {
    s.push_back(g.mapped(0.0, 1.0, 0.0, 1.0));
    pu = std::max(pu, g.degree_u());
    pv = std::max(pv, g.degree_v());
  }
  for (std::size_t k = 1; k < s.size(); ++k)
    for (int a = 0; a < 2; ++a)
      if (s[k].periodic()[a] != s[0].periodic()[a])
        fail(errc::closing_gap, name(k), " is ", s[k].periodic()[a] ? "closed" : "open", " in ", a == 0 ? "u" : "v",
             " and ", name(0), " is ", s[0].periodic()[a] ? "closed" : "open",
             ": a loft's sections are closed in the same directions");
  std::vector<KnotVector> ku, kv;
  for (BSplineSurface& x : s) {
    x = x.elevated(pu - x.degree_u(), pv - x.degree_v());
    ku.push_back(x.knots_u());
    kv.push_back(x.knots_v());
  }
  // Knots a rounding apart are one knot of every section.
  ku = snapped_together(ku);
  kv = snapped_together(kv);
  const KnotVector mu = merged_knots(ku), mv = merged_knots(kv);
  for (std::size_t k = 0; k < s.size(); ++k) {
    const BSplineSurface snapped(ku[k], kv[k], s[k].control_points(), s[k].weights());
    s[k] = snapped.refined(missing(mu, ku[k]), missing(mv, kv[k]));
  }
  return s;
}

// Every section against the volume at its w, through its own evaluation over its own
// domain, at 4 × 4 points of every patch: within rounding (1e-10 of the diagonal
// beside 32 units in the last place of the largest coordinate, for the solve across).
void check_sections(LoftVolume& out, std::span<const BSplineSurface> given, double largest,
                    const std::function<std::string(std::size_t)>& name) {
  LoftVolumeReport& rep = out.report;
  const std::vector<double>& w = rep.params;
  const double bound = 1e-10 * rep.diagonal + 32 * std::numeric_limits<double>::epsilon() * largest;
  const std::vector<double> us = detail::span_samples(out.volume.knots_u()), vs = detail::span_samples(out.volume.knots_v());
  for (std::size_t k = 0; k < given.size(); ++k) {
    const auto [u0, u1] = given[k].domain_u();
    const auto [v0, v1] = given[k].domain_v();
    double worst = 0;
    for (double u : us)
      for (double v : vs)
        worst = std::max(worst, distance(out.volume.point(u, v, w[k]),
                                         given[k].point(u0 + u * (u1 - u0), v0 + v * (v1 - v0))));
    rep.deviation.push_back(worst);
    rep.max_deviation = std::max(rep.max_deviation, worst);
    if (!(worst <= bound))
      fail(errc::ill_conditioned, name(k), ": the loft departs from it by ", worst, ", more than ", bound,
           " (rounding): the system across the sections is ill-conditioned");
  }
}

}  // namespace

LoftVolume loft_volume(std::span<const BSplineSurface> given, const LoftVolumeOptions& o) {
  const std::size_t n = given.size();
  const auto name = [&](std::size_t k) {
    return o.spec_pointers ? detail::cat("/sections/", k) : detail::cat("sections[", k, "]");
  };
  if (n < 2) fail(errc::too_few_points, "a loft needs at least 2 sections, got ", n);
  if (o.degree < 1 || o.degree > max_degree) fail(errc::invalid_degree, "degree ", o.degree, " is outside 1..", max_degree);
  const std::vector<BSplineSurface> s = compatible(given, name);
  // Where the data are: the solve works about the centre of the control points.
  Vec3 lo = s[0].control_points().values().front(), hi = lo;
  double largest = 0;
  for (const BSplineSurface& x : s)
    for (const Vec3& p : x.control_points().values()) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      largest = std::max(largest, max_abs(p));
    }
  const Vec3 centre = 0.5 * lo + 0.5 * hi;
  LoftVolumeReport r;
  r.diagonal = distance(lo, hi);
  // The places across: chords between points at equal (u, v), on a 17 × 17 grid.
  constexpr std::size_t side = 17;
  std::vector<double> w;
  if (!o.params.empty()) {
    detail::check_given_params(
        o.params, n, o.periodic,
        [&](std::size_t k) { return o.spec_pointers ? detail::cat("/param/", k) : detail::cat("params[", k, "]"); },
        o.spec_pointers ? "/param" : "params");
    w = o.params;
  } else {
    w = detail::across_params(
        n, side * side,
        [&](std::size_t k, std::size_t i) {
          return s[k].point(static_cast<double>(i / side) / (side - 1), static_cast<double>(i % side) / (side - 1));
        },
        o.param, o.periodic, largest, name);
  }
  const int q = std::min<int>(o.degree, static_cast<int>(n) - 1);
  const bool rational = std::any_of(s.begin(), s.end(), [](const BSplineSurface& x) { return x.rational(); });
  const std::size_t nu = s[0].control_points().shape()[0], nv = s[0].control_points().shape()[1];
  const std::size_t stride = rational ? 4 : 3, width = nu * nv * stride;
  std::vector<double> rows;
  rows.reserve(n * width);
  std::vector<detail::Condition> conds;
  for (std::size_t k = 0; k < n; ++k) {
    conds.push_back({w[k], 0});
    for (std::size_t i = 0; i < nu; ++i)
      for (std::size_t j = 0; j < nv; ++j) {
        const double h = s[k].rational() ? s[k].weights()(i, j) : 1.0;
        const Vec3 d = s[k].control_points()(i, j) - centre;
        rows.insert(rows.end(), {h * d.x, h * d.y, h * d.z});
        if (rational) rows.push_back(h);
      }
  }
  KnotVector kw = detail::interpolate_across(rows, width, w, std::vector<bool>(n, false), conds, q, o.periodic);
  const std::size_t nw = rows.size() / width;
  PointGrid3 cp({nu, nv, nw});
  Grid<double, 3> weights;
  if (rational) weights = Grid<double, 3>({nu, nv, nw});
  for (std::size_t l = 0; l < nw; ++l)
    for (std::size_t i = 0; i < nu; ++i)
      for (std::size_t j = 0; j < nv; ++j) {
        const double* x = &rows[l * width + (i * nv + j) * stride];
        const double h = rational ? x[3] : 1.0;
        if (!(h > 0))
          fail(errc::invalid_weight, "the sections' weights, interpolated across them, fall to ", h,
               " at control point (", i, ", ", j, ", ", l, "): rational sections whose weights differ too much for a loft");
        cp(i, j, l) = Vec3{x[0], x[1], x[2]} / h + centre;
        if (rational) weights(i, j, l) = h;
      }
  LoftVolume out{BSplineVolume(s[0].knots_u(), s[0].knots_v(), std::move(kw), std::move(cp), std::move(weights)),
                 std::move(r)};
  LoftVolumeReport& rep = out.report;
  rep.degree = {s[0].degree_u(), s[0].degree_v(), q};
  rep.params = w;
  check_sections(out, given, largest, name);
  if (o.periodic) rep.params.push_back(1.0);
  return out;
}

}  // namespace interpatch
