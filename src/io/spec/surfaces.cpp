// Surfaces from corners and curves in a spec: bilinear, ruled, coons, network,
// hermite_patch. Their data (corners, curves) are checked against the exact form by
// `info`, as curves sampled at `curve_samples` parameters.

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <memory>
#include <optional>
#include <string>

#include "base/parallel.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/network.hpp"
#include "interpatch/patches.hpp"
#include "io/box.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

// A curve of the spec sampled for the data check: S(u, fixed) (axis 0) or S(fixed, v)
// against the curve at map(u) (a network's curves) or at u itself.
DataSet curve_data(const BSplineCurve& c, int axis, double fixed, std::string pointer,
                   const std::optional<Reparametrization>& map) {
  constexpr std::size_t curve_samples = 65;
  DataSet d;
  const std::vector<double> t = linspace(0, 1, curve_samples);
  d.params = axis == 0 ? std::vector<std::vector<double>>{t, {fixed}} : std::vector<std::vector<double>>{{fixed}, t};
  for (double x : t) d.points.push_back(c.point(map ? (*map)(x) : x));
  d.pointer = std::move(pointer);
  return d;
}

namespace {

DataSet corner_data(const std::array<Vec3, 4>& p, std::string pointer) {
  DataSet d;
  d.params = {{0.0, 1.0}, {0.0, 1.0}};
  d.points.assign(p.begin(), p.end());  // p00, p01, p10, p11: C order of (u, v)
  d.pointer = std::move(pointer);
  return d;
}

// The exact form evaluates to the formula's points (SPEC: a relative difference of at
// most 1e-12). Checked on every conversion, at a grid of parameters, so that a
// conversion that goes wrong (a defect, such as two closed curves of different
// degrees whose merged knots misalign) is refused rather than written: no_exact_form,
// naming where and by how much. 1e-8 of the size leaves room for the rounding of
// long sums far from the origin, and is far below any misplaced control point.
double largest_coordinate(const Vec3& p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

void check_exact_form(const BlendedSurface& f, const ExactForm& e, std::string_view type) {
  const auto& b = std::get<BSplineSurface>(e);
  const std::vector<double> t = linspace(0, 1, 9);
  internal::Box box;
  double large = 0, worst = 0, wu = 0, wv = 0;
  for (double u : t)
    for (double v : t) {
      const Vec3 a = f.point(u, v), x = b.point(u, v);
      if (!is_finite(a)) continue;  // overflowed: the outputs refuse it (not_finite)
      box.add(a);
      large = std::max(large, largest_coordinate(a));
      if (const double d = distance(a, x); !(d <= worst)) {
        worst = d;
        wu = u;
        wv = v;
      }
    }
  const double tol = 1e-8 * std::max(box.diagonal(), 1e-4 * large);
  if (!(worst <= tol))
    fail(errc::no_exact_form, type, ": its B-spline form differs from it by ", worst, " at (u, v) = (", wu, ", ", wv,
         "), more than ", tol, " (1e-8 of its size): a conversion this far off is refused, not written; eval, mesh "
         "and view use the construction itself");
}

void check_exact_form(const BlendedVolume& f, const ExactForm& e, std::string_view type) {
  const auto& b = std::get<BSplineVolume>(e);
  const std::vector<double> t = linspace(0, 1, 5);
  internal::Box box;
  double large = 0, worst = 0;
  std::array<double, 3> at{0, 0, 0};
  for (double u : t)
    for (double v : t)
      for (double w : t) {
        const Vec3 a = f.point(u, v, w), x = b.point(u, v, w);
        if (!is_finite(a)) continue;
        box.add(a);
        large = std::max(large, largest_coordinate(a));
        if (const double d = distance(a, x); !(d <= worst)) {
          worst = d;
          at = {u, v, w};
        }
      }
  const double tol = 1e-8 * std::max(box.diagonal(), 1e-4 * large);
  if (!(worst <= tol))
    fail(errc::no_exact_form, type, ": its B-spline form differs from it by ", worst, " at (u, v, w) = (", at[0], ", ",
         at[1], ", ", at[2], "), more than ", tol, " (1e-8 of its size): a conversion this far off is refused, not "
         "written; eval, mesh and view use the construction itself");
}

// A blended construction (surface or volume): the formula, stored in `slot`, and
// its conversion to the exact form when it has one (run by build_impl, or deferred
// to exact_form()); otherwise the reason it has none.
template <class Formula, class Slot>
Construction blended_with(std::string_view type, Formula f, std::vector<DataSet> data, nlohmann::ordered_json parameters,
                          Slot Construction::*slot) {
  Construction c;
  c.type = type;
  auto formula = std::make_shared<const Formula>(std::move(f));
  if (formula->has_exact_form()) {
    c.convert = [formula, type = std::string(type)](const progress_callback& progress) {
      std::optional<ExactForm> e;
      try {
        e.emplace(formula->to_bspline(progress));
      } catch (const error& x) {
        // Data near ±1e308 whose sums overflow: say whose form and why.
        if (x.code() != errc::not_finite) throw;
        fail(errc::not_finite, type, ": its B-spline form's ", x.what(),
             ": the conversion's arithmetic left the range of a double (coordinates near 1e308)");
      }
      check_exact_form(*formula, *e, type);
      return std::move(*e);
    };
  } else {
    try {
      (void)formula->to_bspline();  // refuses at once, saying why
      fail(errc::internal, type, ": has_exact_form() and to_bspline() disagree");
    } catch (const error& e) {
      if (e.code() != errc::no_exact_form) throw;
      c.no_exact_form = e.what();
    }
  }
  if (!formula->notes().empty()) parameters["notes"] = formula->notes();
  c.*slot = std::move(formula);
  c.data = std::move(data);
  c.parameters = std::move(parameters);
  return c;
}

}  // namespace

Construction blended(std::string_view type, BlendedSurface s, std::vector<DataSet> data, nlohmann::ordered_json parameters) {
  return blended_with(type, std::move(s), std::move(data), std::move(parameters), &Construction::formula);
}

Construction blended(std::string_view type, BlendedVolume v, std::vector<DataSet> data, nlohmann::ordered_json parameters) {
  return blended_with(type, std::move(v), std::move(data), std::move(parameters), &Construction::volume_formula);
}

Construction build_bilinear(const json& spec, Context& ctx) {
  std::array<Vec3, 4> p;
  const char* names[4] = {"p00", "p01", "p10", "p11"};
  for (std::size_t k = 0; k < 4; ++k)
    p[k] = point_value(member(spec, names[k], "", "a point [x, y, z]"), child("", names[k]));
  ctx.parsed();
  return blended("bilinear", bilinear(p[0], p[1], p[2], p[3]), {corner_data(p, "/p00")}, nlohmann::ordered_json::object());
}

Construction build_ruled(const json& spec, Context& ctx) {
  const json& cs = member(spec, "curves", "", "an array of two curves [c0, c1]");
  if (!cs.is_array() || cs.size() != 2) wrong_type("/curves", "an array of two curves [c0, c1]", cs);
  const BSplineCurve c0 = curve_impl(cs[0], "/curves/0", ctx), c1 = curve_impl(cs[1], "/curves/1", ctx);
  // Two closed curves make a closed surface (a tube); a closed and an open one nothing.
  if (c0.periodic() != c1.periodic())
    fail(errc::invalid_knots, "/curves/1: the curve is ", c1.periodic() ? "closed" : "open", " and /curves/0 is ",
         c0.periodic() ? "closed" : "open", "; a ruled surface joins two closed curves (\"periodic\": true, a tube) or two open ones");
  ctx.parsed();
  return blended("ruled", ruled(c0, c1), {curve_data(c0, 0, 0.0, "/curves/0"), curve_data(c1, 0, 1.0, "/curves/1")},
                 nlohmann::ordered_json::object());
}

namespace {

// A curve of the spec read with its own copy of the reader's context: the curve, the
// warnings it gave and the error it met.
struct CurveRead {
  std::optional<BSplineCurve> curve;
  std::vector<std::string> warnings;
  std::exception_ptr error;
};

// The curves at items[i] (null: none there), each as curve_impl reads it at ptrs[i].
// Read on every thread when the spec names no in-memory arrays (their use counts are
// the reader's shared state), else one after another up to the first error.
std::vector<CurveRead> read_curves(const std::vector<const json*>& items, const std::vector<std::string>& ptrs,
                                   const Context& ctx) {
  const std::size_t n = items.size();
  std::vector<CurveRead> out(n);
  const auto read = [&](std::size_t i) {
    if (items[i] == nullptr) return;
    Context own = ctx;
    own.warnings.clear();
    try {
      out[i].curve = curve_impl(*items[i], ptrs[i], own);
      out[i].warnings = std::move(own.warnings);
    } catch (...) {
      out[i].error = std::current_exception();
    }
  };
  if (ctx.arrays != nullptr || n < 2) {
    for (std::size_t i = 0; i < n; ++i) {
      read(i);
      if (out[i].error) break;
    }
    return out;
  }
  interpatch::detail::parallel_for(n, true, interpatch::detail::Share::one_by_one, read);
  return out;
}

// A network interpolates its curves, but curves nearly on top of one another (two
// sections 1e-6 apart) make the cardinal functions swing far between them: the
// surface then leaves the curves' box by more than its size, which is said, never
// silent. Measured on a 33 x 33 sampling (the swings span whole cells).
void warn_if_far_from_curves(const Surface& s, const CurveNetwork& net, Context& ctx) {
  internal::Box data, surface;
  for (const auto* family : {&net.u_curves, &net.v_curves})
    for (const BSplineCurve& c : *family)
      for (double t : linspace(c.domain().first, c.domain().second, 33)) data.add(c.point(t));
  const std::vector<double> t = linspace(0, 1, 33);
  const PointGrid g = s.evaluate(t, t);
  for (const Vec3& p : g.values()) surface.add(p);
  const double d = data.diagonal();
  double beyond = 0;
  for (int k = 0; k < 3; ++k) beyond = std::max({beyond, data.lo[k] - surface.lo[k], surface.hi[k] - data.hi[k]});
  if (beyond > d)
    ctx.warn(cat("the surface reaches ", beyond, " beyond the box of its curves, more than the box's diagonal (", d,
                 "): curves of a family nearly on top of one another make it swing between them; ",
                 "leave one of them out, or space them further apart"));
}

// A curve read by read_curves, in the spec's order: its warnings to ctx, its error
// thrown, else the curve.
BSplineCurve take(CurveRead& r, Context& ctx) {
  if (r.error) std::rethrow_exception(r.error);
  for (std::string& w : r.warnings) ctx.warn(std::move(w));
  return std::move(*r.curve);
}

}  // namespace

std::vector<std::optional<BSplineCurve>> read_curve_list(const std::vector<const json*>& items,
                                                         const std::vector<std::string>& ptrs, Context& ctx) {
  std::vector<CurveRead> read = read_curves(items, ptrs, ctx);
  std::vector<std::optional<BSplineCurve>> out(read.size());
  for (std::size_t i = 0; i < read.size(); ++i)
    if (items[i] != nullptr) out[i] = take(read[i], ctx);
  return out;
}

Construction build_coons(const json& spec, Context& ctx) {
  const char* sides[4] = {"v0", "v1", "u0", "u1"};
  auto four_curves = [&](const json& obj, const std::string& ptr) {
    expect_object(obj, ptr, "an object {\"v0\", \"v1\", \"u0\", \"u1\"} of curves");
    check_fields(obj, ptr, {"v0", "v1", "u0", "u1"}, ctx);
    std::vector<const json*> items;
    std::vector<std::string> ptrs;
    for (const char* side : sides) {
      items.push_back(find_member(obj, side));
      ptrs.push_back(child(ptr, side));
    }
    std::vector<CurveRead> read = read_curves(items, ptrs, ctx);
    std::vector<BSplineCurve> c;
    for (std::size_t k = 0; k < 4; ++k) {
      const char* side = sides[k];
      (void)member(obj, side, ptr, "a curve");  // a missing side, in its turn
      c.push_back(take(read[k], ctx));
      if (c.back().periodic())
        fail(errc::invalid_knots, place(child(ptr, side)), ": a closed curve (\"periodic\": true) cannot be a side of a ",
             "Coons patch, whose sides run from corner to corner");
    }
    return c;
  };
  const auto b = four_curves(member(spec, "boundary", "", "an object {\"v0\", \"v1\", \"u0\", \"u1\"} of curves"), "/boundary");
  const CoonsBoundary boundary{b[0], b[1], b[2], b[3]};
  const std::string blending = choice(spec, "blending", "", {"linear", "hermite"}, "linear");
  const std::optional<double> tol = tolerance_of(spec);
  std::vector<DataSet> data{curve_data(b[0], 0, 0.0, "/boundary/v0"), curve_data(b[1], 0, 1.0, "/boundary/v1"),
                            curve_data(b[2], 1, 0.0, "/boundary/u0"), curve_data(b[3], 1, 1.0, "/boundary/u1")};
  nlohmann::ordered_json parameters = {{"blending", blending}};
  if (const json* x = find_member(spec, "cross_derivatives")) {
    const auto d = four_curves(*x, "/cross_derivatives");
    HermiteCoonsOptions o;
    o.tolerance = tol;
    o.twist_correction = choice(spec, "twist_correction", "", {"none", "gregory"}, "none") == "gregory"
                             ? TwistCorrection::gregory
                             : TwistCorrection::none;
    if (const json* tw = find_member(spec, "twists")) {
      expect_object(*tw, "/twists", "an object {\"p00\", \"p01\", \"p10\", \"p11\"} of vectors");
      check_fields(*tw, "/twists", {"p00", "p01", "p10", "p11"}, ctx);
      const char* corners[4] = {"p00", "p01", "p10", "p11"};
      for (std::size_t k = 0; k < 4; ++k)
        if (const json* t = find_member(*tw, corners[k])) o.twists[k] = point_value(*t, child("/twists", corners[k]));
    }
    ctx.parsed();
    parameters = {{"blending", "hermite"},
                  {"cross_derivatives", true},
                  {"twist_correction", o.twist_correction == TwistCorrection::gregory ? "gregory" : "none"}};
    return blended("coons", at("", [&] { return coons(boundary, CoonsCrossDerivatives{d[0], d[1], d[2], d[3]}, o); }),
                   std::move(data), std::move(parameters));
  }
  for (const char* k : {"twists", "twist_correction"})
    if (find_member(spec, k)) ctx.warn(cat("/", k, ": ignored without \"cross_derivatives\""));
  CoonsOptions o;
  o.tolerance = tol;
  if (blending == "hermite") o.blend_u = o.blend_v = Blend::hermite();
  ctx.parsed();
  return blended("coons", at("", [&] { return coons(boundary, o); }), std::move(data), std::move(parameters));
}

Construction build_network(const json& spec, Context& ctx) {
  auto curves = [&](const char* key) {
    const std::string ptr = child("", key);
    const json& a = member(spec, key, "", "an array of curves");
    if (!a.is_array()) wrong_type(ptr, "an array of curves", a);
    std::vector<const json*> items;
    std::vector<std::string> ptrs;
    for (std::size_t i = 0; i < a.size(); ++i) {
      items.push_back(&a[i]);
      ptrs.push_back(child(ptr, i));
    }
    std::vector<BSplineCurve> c;
    for (auto& r : read_curve_list(items, ptrs, ctx)) c.push_back(std::move(*r));
    return c;
  };
  const std::array<bool, 3> closed = periodic_flags(spec, "", 2);
  CurveNetwork net{curves("u_curves"), curves("v_curves"), {}, {}, {closed[0], closed[1]}};
  if (const json* p = find_member(spec, "u_params")) net.u_params = numbers(*p, "/u_params");
  if (const json* p = find_member(spec, "v_params")) net.v_params = numbers(*p, "/v_params");
  const std::string method = choice(spec, "method", "", {"coons_linear", "coons_hermite", "gordon"}, "gordon");
  NetworkOptions o;
  o.method = method == "coons_linear" ? NetworkMethod::coons_linear
             : method == "coons_hermite" ? NetworkMethod::coons_hermite
                                         : NetworkMethod::gordon;
  o.tolerance = tolerance_of(spec);
  o.curve_name = [](int family, std::size_t i) { return child(family == 0 ? "/u_curves" : "/v_curves", i); };
  ctx.parsed();
  NetworkSurface built = at("", [&] { return network_surface(net, o); });
  const NetworkReport& r = built.report;
  // Each curve as given against the surface along its line, point for point through its map.
  std::vector<DataSet> data;
  nlohmann::ordered_json reported = nlohmann::ordered_json::object();
  for (int a = 0; a < 2; ++a) {
    const auto& given = a == 0 ? net.u_curves : net.v_curves;
    const auto& reports = a == 0 ? r.u_curves : r.v_curves;
    const auto& line = a == 0 ? r.v_params : r.u_params;
    for (std::size_t j = 0; j < given.size(); ++j) {
      const std::string ptr = child(a == 0 ? "/u_curves" : "/v_curves", j);
      const NetworkCurveReport& c = reports[j];
      data.push_back(curve_data(given[j], a, line[j], ptr, c.map));
      const double from = c.map(0.0), to = c.map(1.0);
      reported[ptr] = {{"position", c.position},
                     {"reversed", c.reversed},
                     {"reexpressed", c.reexpressed},
                     {"fit_error", c.fit_error},
                     {"distance", c.distance},
                     {"max_gap", c.max_gap}};
      // The part used (open curves), or where the surface's seam u = 0 falls on the curve (closed ones).
      if (c.map.period > 0) reported[ptr]["seam"] = from;
      else reported[ptr]["range"] = {from, to};
      if (c.closing) reported[ptr]["closing"] = true;
      if (c.degenerate) reported[ptr]["degenerate"] = true;
      // Curves missing each other by up to the tolerance move the surface by about half
      // of that, the re-expression by up to half the tolerance more, and the cardinal
      // functions' overshoot spreads a correction by less than twice: beyond 4 times the
      // tolerance the network is not what it was given as (a curve arranged the wrong
      // way round, say), and the promise to pass the curves is not kept.
      if (c.distance > 4 * r.tolerance)
        fail(errc::tolerance_not_met, ptr, ": the surface departs from this curve by up to ", c.distance,
             ", more than 4 times the tolerance ", r.tolerance,
             " could explain: the curves are not held as given (a part too small for its distance from the origin, "
             "or curves nearly on top of one another)");
      if (c.distance > r.strict)
        ctx.warn(cat(ptr, ": the surface departs from this curve by up to ", c.distance, ", more than ",
                     r.strict > 1e-7 * r.diagonal ? "the rounding of its coordinates" : "1e-7 of the diagonal", " (",
                     r.strict, "): the tolerance ", r.tolerance, " lets curves miss each other by that much"));
      const auto [lo, hi] = given[j].domain();
      const double a0 = std::min(from, to), a1 = std::max(from, to);
      if (!c.degenerate && c.map.period == 0 && (a0 > lo || a1 < hi))
        ctx.warn(cat(ptr, ": only t from ", a0, " to ", a1, " (of ", lo, " to ", hi, ") lies between the end curves; ",
                     "the rest runs past them and is not on the surface"));
    }
  }
  nlohmann::ordered_json parameters = {{"method", method},
                                       {"curves", {net.u_curves.size(), net.v_curves.size()}},
                                       {"u_params", r.u_params},
                                       {"v_params", r.v_params}};
  if (net.periodic[0] || net.periodic[1]) parameters["periodic"] = net.periodic;
  parameters["crossings"] = {{"max_gap", r.max_gap},
                             {"at", {child("/u_curves", r.max_gap_at[0]), child("/v_curves", r.max_gap_at[1])}},
                             {"tolerance", r.tolerance}};
  parameters["network_curves"] = std::move(reported);
  warn_if_far_from_curves(built.surface, net, ctx);
  return blended("network", std::move(built.surface), std::move(data), std::move(parameters));
}

Construction build_hermite_patch(const json& spec, Context& ctx) {
  const json& cs = member(spec, "corners", "", "an object {\"p00\", \"p01\", \"p10\", \"p11\"} of corners");
  expect_object(cs, "/corners", "an object {\"p00\", \"p01\", \"p10\", \"p11\"} of corners");
  check_fields(cs, "/corners", {"p00", "p01", "p10", "p11"}, ctx);
  std::array<HermiteCorner, 4> c{};
  std::array<Vec3, 4> p;
  const char* names[4] = {"p00", "p01", "p10", "p11"};
  for (std::size_t k = 0; k < 4; ++k) {
    const std::string ptr = child("/corners", names[k]);
    const json& o = member(cs, names[k], "/corners", "a corner {\"p\", \"du\", \"dv\", \"duv\"}");
    expect_object(o, ptr, "a corner {\"p\", \"du\", \"dv\", \"duv\"}");
    check_fields(o, ptr, {"p", "du", "dv", "duv"}, ctx);
    c[k].p = point_value(member(o, "p", ptr, "a point [x, y, z]"), child(ptr, "p"));
    c[k].du = point_value(member(o, "du", ptr, "a vector [x, y, z]"), child(ptr, "du"));
    c[k].dv = point_value(member(o, "dv", ptr, "a vector [x, y, z]"), child(ptr, "dv"));
    if (const json* t = find_member(o, "duv")) c[k].duv = point_value(*t, child(ptr, "duv"));
    p[k] = c[k].p;
  }
  ctx.parsed();
  return blended("hermite_patch", hermite_patch(c), {corner_data(p, "/corners")}, nlohmann::ordered_json::object());
}

}  // namespace interpatch::io::reader
