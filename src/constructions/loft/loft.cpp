// A surface through section curves: the sections prepared and aligned
// (loft_sections.cpp), made compatible (merged knots, or re-expressed on common knots
// when merging would make too many), their parameters across, the interpolation
// across them control point by control point, and the check of every section.
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>
#include <string>

#include "base/text.hpp"
#include "constructions/interpolate/interpolate_internal.hpp"
#include "constructions/loft/loft_across.hpp"
#include "constructions/loft/loft_sections.hpp"
#include "constructions/network/network_curves.hpp"
#include "interpatch/loft.hpp"
#include "linalg/collocation.hpp"

namespace interpatch {

namespace {

using detail::fail;
using detail::PreparedSection;

// The identity map of [0, 1] (closed: with period 1): the re-expression's jobs are
// the sections themselves.
Reparametrization identity(bool closed) {
  Reparametrization m;
  m.at = {0.0, 1.0};
  m.to = {0.0, 1.0};
  m.slope = {1.0, 1.0};
  if (closed) m.period = 1.0;
  return m;
}

// The largest |S(u, v) − C(u)| at 4 points of every span of the surface in u.
double deviation(const BSplineSurface& s, double v, const BSplineCurve& c) {
  double worst = 0;
  for (double u : detail::span_samples(s.knots_u())) worst = std::max(worst, distance(s.point(u, v), c.point(u)));
  return worst;
}

// How messages name the loft's parts (LoftOptions::spec_pointers).
struct Names {
  bool pointers;
  [[nodiscard]] std::string at(const char* field, std::size_t k) const {
    return pointers ? detail::cat("/", field, "/", k) : detail::cat(field, "[", k, "]");
  }
  [[nodiscard]] std::string section(std::size_t k) const { return at("sections", k); }
  [[nodiscard]] std::string tangent(std::size_t k) const { return at("tangents", k); }
  [[nodiscard]] std::string param(std::size_t k) const { return at(pointers ? "param" : "params", k); }
  [[nodiscard]] const char* whole(const char* field) const {
    return pointers ? (field[0] == 't' ? "/tangents" : "/param") : (field[0] == 't' ? "tangents" : "params");
  }
};

// Where the data are and how large: the centre the solve works about, the default
// tolerance, the bound of rounding.
struct Frame {
  Vec3 centre;
  double diagonal = 0, largest = 0, tol = 0;
};

Frame frame_of(std::span<const BSplineCurve> given, const std::optional<double>& tolerance) {
  Vec3 lo = given.front().control_points().front(), hi = lo;
  Frame f;
  for (const BSplineCurve& c : given)
    for (const Vec3& p : c.control_points()) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      f.largest = std::max(f.largest, max_abs(p));
    }
  f.diagonal = distance(lo, hi);
  f.centre = 0.5 * lo + 0.5 * hi;
  // 16 units in the last place of the largest coordinate where 1e-7 of the diagonal is
  // less: a small part far from the origin.
  f.tol = tolerance.value_or(std::max(1e-7 * f.diagonal, 16 * std::numeric_limits<double>::epsilon() * f.largest));
  if (!(f.tol >= 0) || !std::isfinite(f.tol)) fail(errc::not_finite, "tolerance is ", f.tol);
  return f;
}

// The tangents, one slot per section (null where none); the index each was given at.
std::vector<const BSplineCurve*> tangent_slots(const LoftOptions& o, std::size_t n, const Names& names,
                                               std::vector<std::size_t>& given_at) {
  std::vector<const BSplineCurve*> t(n, nullptr);
  given_at.assign(n, 0);
  if (o.tangents.empty()) return t;
  if (o.tangents.size() != 2 && o.tangents.size() != n)
    fail(errc::size_mismatch, names.whole("tangents"), ": 2 (the first and the last section) or ", n,
         " (one per section), got ", o.tangents.size());
  for (std::size_t i = 0; i < o.tangents.size(); ++i) {
    if (!o.tangents[i]) continue;
    if (o.periodic) fail(errc::wrong_type, names.tangent(i), ": a periodic loft has no first or last section to join at");
    if (o.tangents[i]->rational())
      fail(errc::wrong_type, names.tangent(i),
           ": a tangent is a polynomial curve (a derivative across the sections), and this one is rational");
    const std::size_t k = o.tangents.size() == n ? i : (i == 0 ? 0 : n - 1);
    t[k] = &*o.tangents[i];
    given_at[k] = i;
  }
  return t;
}

// The sections over [0, 1], closed or open (never mixed), turned and restarted.
std::vector<PreparedSection> prepare(std::span<const BSplineCurve> given, const std::vector<const BSplineCurve*>& tangent,
                                     const std::vector<std::size_t>& tangent_given, double tol, const Names& names) {
  const std::size_t n = given.size();
  const bool any_tangent = std::any_of(tangent.begin(), tangent.end(), [](auto* t) { return t != nullptr; });
  std::vector<PreparedSection> s;
  s.reserve(n);
  std::vector<double> gaps(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    s.push_back({given[k].mapped(0.0, 1.0), std::nullopt, false, false, 0.0, 0.0});
    if (given[k].rational() && any_tangent)
      fail(errc::wrong_type, names.section(k), ": tangents are taken for polynomial sections only, and this one is rational");
    gaps[k] = s[k].curve.periodic() ? 0.0 : distance(s[k].curve.point(0.0), s[k].curve.point(1.0));
    s[k].closed = s[k].curve.periodic() || gaps[k] <= tol;
    s[k].gap = gaps[k];
    if (tangent[k]) s[k].tangent = tangent[k]->mapped(0.0, 1.0);
  }
  for (std::size_t k = 1; k < n; ++k)
    if (s[k].closed != s[0].closed) {
      const std::size_t open = s[k].closed ? 0 : k, shut = s[k].closed ? k : 0;
      fail(errc::closing_gap, names.section(open), " is open (its ends are ", gaps[open],
           " apart, more than the tolerance ", tol, ") and ", names.section(shut),
           " is closed: a loft's sections are all closed or all open");
    }
  for (std::size_t k = 0; k < n; ++k)
    if (s[k].tangent && s[k].closed && s[k].tangent->periodic() != s[k].curve.periodic())
      fail(errc::wrong_type, names.tangent(tangent_given[k]), ": ",
           s[k].curve.periodic() ? "its section is periodic and it is not" : "it is periodic and its section is not");
  detail::align_sections(s, s[0].closed);
  // A rational curve is the same with all its weights scaled; the sections' weights are
  // interpolated across, so each is brought to a largest weight in [1, 2) (a power of
  // two: exact), lest an arbitrary scale of one section swing the weights between them.
  for (PreparedSection& x : s)
    if (x.curve.rational()) {
      const int e = scale_exponent(*std::max_element(x.curve.weights().begin(), x.curve.weights().end()));
      std::vector<double> w = x.curve.weights();
      for (double& y : w) y = std::ldexp(y, -e);
      x.curve = BSplineCurve(x.curve.knots(), x.curve.control_points(), std::move(w));
    }
  // Periodic and open-knotted closed sections together: all open-knotted.
  if (!std::all_of(s.begin(), s.end(), [](const PreparedSection& x) { return x.curve.periodic(); }))
    for (PreparedSection& x : s) {
      x.curve = x.curve.clamped();
      if (x.tangent) x.tangent = x.tangent->clamped();
    }
  return s;
}

// The largest |a(u) − b(u)| at 4 points of every piece between the breaks of both.
double farthest(const BSplineCurve& a, const BSplineCurve& b) {
  std::vector<double> x{0.0, 1.0};
  for (const BSplineCurve* c : {&a, &b})
    for (const auto& [t, m] : c->knots().interior_breaks())
      if (t > 0.0 && t < 1.0) x.push_back(t);
  std::sort(x.begin(), x.end());
  x.erase(std::unique(x.begin(), x.end()), x.end());
  double worst = 0;
  for (std::size_t i = 0; i + 1 < x.size(); ++i)
    for (int j = 0; j <= 4; ++j) {
      const double t = x[i] + (x[i + 1] - x[i]) * j / 4.0;
      worst = std::max(worst, distance(a.point(t), b.point(t)));
    }
  return worst;
}

// The curves on common knots within `tol` of their own, on fewer knots than merging
// makes; empty when that cannot be had.
std::optional<std::vector<BSplineCurve>> reexpressed(const std::vector<BSplineCurve>& curves, double tol) {
  std::vector<KnotVector> kv;
  for (const BSplineCurve& x : curves) kv.push_back(x.knots());
  const std::size_t merged = merged_knots(snapped_together(kv)).size();
  const bool periodic = curves.front().periodic();
  std::vector<detail::FitJob> jobs;
  for (const BSplineCurve& x : curves) jobs.push_back({&x, nullptr, nullptr, identity(periodic)});
  const detail::FamilyKnots start = detail::family_knots(jobs, {}, periodic);
  std::vector<std::size_t> all(curves.size());
  std::iota(all.begin(), all.end(), 0);
  for (double target = tol; target >= 0.25 * tol; target *= 0.5) {
    std::vector<detail::Refit> fits;
    try {
      // The fit gives up at once (empty) when its distance calls for more halvings of
      // every span than would keep the knots within 4 times the merged count (each
      // halving divides the distance by 8 or more; most spans need fewer than the
      // worst): a tolerance near rounding, where merging is exact and smaller.
      auto got = detail::fit_group(jobs, all, start.interior, {}, periodic, target, 4 * merged, nullptr);
      if (!got) return std::nullopt;
      fits = std::move(*got);
    } catch (const detail::RefitShortfall&) {
      return std::nullopt;
    }
    if (fits.front().curve.knots().size() >= merged) return std::nullopt;
    bool within = true;
    for (std::size_t j = 0; j < curves.size() && within; ++j) within = farthest(fits[j].curve, curves[j]) <= tol;
    if (!within) continue;
    std::vector<BSplineCurve> out;
    for (detail::Refit& f : fits) out.push_back(std::move(f.curve));
    return out;
  }
  return std::nullopt;
}

// The sections (then the tangents present) of one degree on one knot vector: merged,
// or re-expressed on common knots within the tolerance when merging would make more
// than 4 times the largest section's knots (and would still make more than that).
struct Common {
  std::vector<BSplineCurve> curves;
  std::vector<std::size_t> tangent_at;  // index in curves of section k's tangent
};

Common common_knots(const std::vector<PreparedSection>& s, double tol, LoftReport& r) {
  const std::size_t n = s.size();
  int p = 0;
  for (const PreparedSection& x : s) p = std::max({p, x.curve.degree(), x.tangent ? x.tangent->degree() : 0});
  Common c;
  c.tangent_at.assign(n, 0);
  for (const PreparedSection& x : s) c.curves.push_back(x.curve.elevated(p - x.curve.degree()));
  for (std::size_t k = 0; k < n; ++k)
    if (s[k].tangent) {
      c.tangent_at[k] = c.curves.size();
      c.curves.push_back(s[k].tangent->elevated(p - s[k].tangent->degree()));
    }
  r.degree_u = p;
  std::vector<KnotVector> kv;
  for (const BSplineCurve& x : c.curves) {
    kv.push_back(x.knots());
    r.section_knots = std::max(r.section_knots, x.knots().size());
  }
  r.merged_knots = merged_knots(snapped_together(kv)).size();
  if (r.merged_knots <= 4 * r.section_knots) {
    c.curves = make_compatible(c.curves);
    return c;
  }
  // Re-expressed, each curve checked against its own at 4 points of every piece between
  // the union of both knot vectors (where the difference is one polynomial): the fit
  // itself measures at 4 points of its own spans and can miss a peak between them.
  // Short of the tolerance there, the fit is made again aiming at half as far, twice;
  // when that, or the refinement itself, does not get there, or it needs as many knots
  // as merging, the sections are merged: exact.
  if (auto fitted = reexpressed(c.curves, tol)) {
    r.reexpressed = true;
    c.curves = std::move(*fitted);
    return c;
  }
  c.curves = make_compatible(c.curves);
  return c;
}

// The control points of every section (homogeneous when rational), about the centre,
// interpolated across at v (with the tangents' as derivative conditions), degree q.
BSplineSurface across(const Common& c, const std::vector<double>& v, const std::vector<bool>& derivative, int q,
                      bool periodic, const Vec3& centre) {
  const std::size_t n = v.size();
  const bool rational = std::any_of(c.curves.begin(), c.curves.end(), [](const BSplineCurve& x) { return x.rational(); });
  const std::size_t nu = c.curves.front().control_points().size(), stride = rational ? 4 : 3;
  const std::size_t width = nu * stride;
  std::vector<double> rows;
  std::vector<detail::Condition> conds;
  auto push = [&](const BSplineCurve& x, bool is_tangent, double t) {
    conds.push_back({t, is_tangent ? 1 : 0});
    for (std::size_t i = 0; i < nu; ++i) {
      const double w = x.rational() ? x.weights()[i] : 1.0;
      const Vec3 d = is_tangent ? x.control_points()[i] : x.control_points()[i] - centre;
      rows.insert(rows.end(), {w * d.x, w * d.y, w * d.z});
      if (rational) rows.push_back(is_tangent ? 0.0 : w);
    }
  };
  for (std::size_t k = 0; k < n; ++k) {
    // Q_0, D_0, ..., Q_k, D_k, ..., D_{n-1}, Q_{n-1}: the matrix stays banded.
    const bool last = k + 1 == n;
    if (derivative[k] && last) push(c.curves[c.tangent_at[k]], true, v[k]);
    push(c.curves[k], false, v[k]);
    if (derivative[k] && !last) push(c.curves[c.tangent_at[k]], true, v[k]);
  }
  KnotVector kv = detail::interpolate_across(rows, width, v, derivative, conds, q, periodic);
  const std::size_t nv = rows.size() / width;
  PointGrid cp({nu, nv});
  Grid<double, 2> weights;
  if (rational) weights = Grid<double, 2>({nu, nv});
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i) {
      const double* r = &rows[j * width + i * stride];
      const double w = rational ? r[3] : 1.0;
      if (!(w > 0))
        fail(errc::invalid_weight, "the sections' weights, interpolated across them, fall to ", w, " at control point (",
             i, ", ", j, "): rational sections whose weights differ too much for a loft");
      cp(i, j) = Vec3{r[0], r[1], r[2]} / w + centre;
      if (rational) weights(i, j) = w;
    }
  return BSplineSurface(c.curves.front().knots(), std::move(kv), std::move(cp), std::move(weights));
}

const std::vector<double> nine{0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 1.0};

// Every section against the surface along its line, through its map: within rounding
// (32 units in the last place of the largest coordinate beside 1e-10 of the diagonal,
// for the solve across), or within the tolerance when re-expressed. A tangent against
// ∂S/∂v: rounding relative to its size and to the slope the sections' spacing alone
// gives (diagonal / smallest gap in v); re-expressed, it moved by up to the tolerance
// itself.
void check_sections(LoftSurface& out, std::span<const BSplineCurve> given, const std::vector<PreparedSection>& s,
                    const Frame& f, const Names& names, const std::vector<std::size_t>& tangent_given) {
  LoftReport& r = out.report;
  const std::vector<double>& v = r.params;
  const double bound = r.reexpressed ? f.tol : 1e-10 * f.diagonal + 32 * std::numeric_limits<double>::epsilon() * f.largest;
  double gap = 1.0;
  for (std::size_t j = 0; j + 1 < v.size(); ++j) gap = std::min(gap, v[j + 1] - v[j]);
  for (std::size_t k = 0; k < s.size(); ++k) {
    LoftSectionReport& sr = r.sections[k];
    sr.closed = s[k].closed;
    sr.reversed = s[k].reversed;
    const auto [a, b] = given[k].domain();
    sr.map = detail::section_map(s[k], a, b);
    double worst = 0;
    for (double u : nine) worst = std::max(worst, distance(out.surface.point(u, v[k]), given[k].point(sr.map(u))));
    sr.deviation = std::max(worst, deviation(out.surface, v[k], s[k].curve));
    r.max_deviation = std::max(r.max_deviation, sr.deviation);
    // An open-knotted closed section: its ends, up to the tolerance apart, are one point
    // of the section taken closed (u = 1 wraps to its start), and restarted it has them
    // joined at their midpoint: it is held to within that gap.
    const double joined = s[k].closed && !given[k].periodic() ? s[k].gap : 0.0;
    if (!(sr.deviation <= bound + joined))
      fail(r.reexpressed ? errc::tolerance_not_met : errc::ill_conditioned, names.section(k),
           ": the loft departs from it by ", sr.deviation, ", more than ", bound + joined,
           r.reexpressed ? " (the tolerance)" : " (rounding): the system across the sections is ill-conditioned");
    if (!s[k].tangent) continue;
    double size = 0;
    for (double u : nine) {
      const Vec3 t = s[k].tangent->point(u);
      size = std::max(size, norm(t));
      sr.tangent_deviation = std::max(sr.tangent_deviation, distance(out.surface.derivative(u, v[k], 0, 1), t));
    }
    const double t_bound = (r.reexpressed ? f.tol : 0.0) + 1e-9 * (size + f.diagonal / gap) +
                           32 * std::numeric_limits<double>::epsilon() * f.largest / gap;
    if (!(sr.tangent_deviation <= t_bound))
      fail(errc::ill_conditioned, names.tangent(tangent_given[k]),
           ": the loft's derivative across the sections departs from it by ", sr.tangent_deviation, ", more than ", t_bound);
  }
}

// With guides: the Gordon surface of the network of sections (u-curves) and guides
// (v-curves), its exact form, and each curve within 4 times the tolerance (curves
// missing each other by the tolerance move the surface by half of it, the
// re-expression by half more, and the cardinal functions spread a correction by less
// than twice).
LoftSurface loft_with_guides(std::span<const BSplineCurve> given, const LoftOptions& o, const Names& names) {
  if (std::any_of(o.tangents.begin(), o.tangents.end(), [](const auto& t) { return t.has_value(); }))
    fail(errc::wrong_type, names.whole("tangents"), ": a loft with guides takes its slopes from them, not tangents");
  const Frame f = frame_of(given, o.tolerance);
  bool closed = true;
  for (const BSplineCurve& c : given)
    closed = closed && (c.periodic() || distance(c.point(c.domain().first), c.point(c.domain().second)) <= f.tol);
  CurveNetwork net{{given.begin(), given.end()}, o.guides, {}, o.params, {closed, o.periodic}};
  NetworkOptions no;
  no.tolerance = o.tolerance;
  no.curve_name = [&](int family, std::size_t i) { return family == 0 ? names.section(i) : names.at("guides", i); };
  NetworkSurface ns = network_surface(net, no);
  LoftSurface out{ns.surface.to_bspline(), LoftReport{}};
  LoftReport& r = out.report;
  r.closed = closed;
  r.degree_u = out.surface.degree_u();
  r.degree_v = out.surface.degree_v();
  r.tolerance = ns.report.tolerance;
  r.diagonal = ns.report.diagonal;
  r.params = ns.report.v_params;
  if (o.periodic && r.params.size() == given.size()) r.params.push_back(1.0);
  const auto used = [&](const NetworkCurveReport& c, std::size_t i, int family) {
    LoftSectionReport s;
    s.closed = family == 0 && closed;
    s.reversed = c.reversed;
    s.map = c.map;
    s.deviation = c.distance;
    r.reexpressed = r.reexpressed || c.reexpressed;
    r.max_deviation = std::max(r.max_deviation, c.distance);
    if (!(c.distance <= 4 * r.tolerance))
      fail(errc::tolerance_not_met, family == 0 ? names.section(i) : names.at("guides", i),
           ": the loft departs from it by ", c.distance, ", more than 4 times the tolerance ", r.tolerance);
    return s;
  };
  for (std::size_t i = 0; i < ns.report.u_curves.size(); ++i) r.sections.push_back(used(ns.report.u_curves[i], i, 0));
  for (std::size_t i = 0; i < ns.report.v_curves.size(); ++i) r.guides.push_back(used(ns.report.v_curves[i], i, 1));
  r.network = std::move(ns.report);
  return out;
}

}  // namespace

LoftSurface loft(std::span<const BSplineCurve> given, const LoftOptions& o) {
  const std::size_t n = given.size();
  const Names names{o.spec_pointers};
  if (n < 2) fail(errc::too_few_points, "a loft needs at least 2 sections, got ", n);
  if (!o.guides.empty()) return loft_with_guides(given, o, names);
  if (o.degree < 1 || o.degree > max_degree) fail(errc::invalid_degree, "degree ", o.degree, " is outside 1..", max_degree);
  std::vector<std::size_t> tangent_given;
  const std::vector<const BSplineCurve*> tangent = tangent_slots(o, n, names, tangent_given);
  const Frame f = frame_of(given, o.tolerance);
  const std::vector<PreparedSection> s = prepare(given, tangent, tangent_given, f.tol, names);
  LoftReport report;
  report.closed = s[0].closed;
  report.tolerance = f.tol;
  report.diagonal = f.diagonal;
  report.sections.resize(n);
  const Common c = common_knots(s, f.tol, report);
  // The parameters across, and the degree across (lowered to the conditions − 1).
  std::vector<double> v;
  if (!o.params.empty()) {
    detail::check_given_params(o.params, n, o.periodic, [&](std::size_t k) { return names.param(k); }, names.whole("params"));
    v = o.params;
  } else {
    v = detail::across_params(
        n, 129, [&](std::size_t k, std::size_t i) { return s[k].curve.point(static_cast<double>(i) / 128.0); },
        o.param, o.periodic, f.largest, [&](std::size_t k) { return names.section(k); });
  }
  std::vector<bool> derivative(n, false);
  std::size_t conditions = n;
  for (std::size_t k = 0; k < n; ++k)
    if (s[k].tangent) {
      derivative[k] = true;
      ++conditions;
    }
  const int q = std::min<int>(o.degree, static_cast<int>(conditions) - 1);
  if (conditions > n && q < 2)
    fail(errc::invalid_degree, "tangents need a degree of 2 or more across the sections, got ", q);
  LoftSurface out{across(c, v, derivative, q, o.periodic, f.centre), std::move(report)};
  out.report.degree_v = q;
  out.report.params = v;
  check_sections(out, given, s, f, names, tangent_given);
  if (o.periodic) out.report.params.push_back(1.0);
  return out;
}

}  // namespace interpatch
