// Curves in a spec — {"interpolate": points}, {"bspline": {...}}, {"hermite": {...}},
// {"line": [A, B]} — each mapped onto [0, 1].

#include <array>

#include "interpatch/hermite.hpp"
#include "interpatch/interpolate.hpp"
#include "io/spec/forms.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

BSplineCurve on_unit_domain(BSplineCurve c) {
  const auto [a, b] = c.domain();
  if (a == 0.0 && b == 1.0) return c;
  return c.mapped(0.0, 1.0);
}

std::vector<Vec3> curve_points(const json& j, std::string_view ptr, Context& ctx) {
  const PointArray a = points_impl(j, 1, ptr, ctx);
  if (a.points.size() < 2) fail(errc::too_few_points, place(ptr), ": a curve needs at least 2 points, got ", a.points.size());
  return {a.points.begin(), a.points.end()};
}

// {"interpolate": points, ...}: open, or closed ("periodic": true) through the
// distinct points, a last point repeating the first left out.
SpecCurve interpolated_curve(const json& obj, std::string_view ptr, Context& ctx) {
  check_fields(obj, ptr, forms::interpolate_curve, ctx);
  const std::string pts_at = child(ptr, "interpolate");
  const std::vector<Vec3> pts = curve_points(obj.at("interpolate"), pts_at, ctx);
  CurveInterpolationOptions options;
  options.periodic = periodic_flags(obj, ptr, 1)[0];
  for (const char* end : {"start_derivative", "end_derivative"}) {
    const json* d = find_member(obj, end);
    if (!d) continue;
    const std::string dptr = child(ptr, end);
    if (options.periodic)
      fail(errc::wrong_type, place(dptr), ": a closed curve (\"periodic\": true) has no ends; give either \"periodic\" or ",
           "end derivatives, not both");
    (end[0] == 's' ? options.start_derivative : options.end_derivative) = point_value(*d, dptr);
  }
  const Closing closing = options.periodic ? at(pts_at, [&] { return closing_point(pts); }) : Closing{pts.size(), false, false};
  const std::size_t n = closing.count;  // the points the curve is made of
  const std::size_t ends = (options.start_derivative ? 1u : 0u) + (options.end_derivative ? 1u : 0u);
  options.degree = degrees(obj, ptr, 1)[0];
  if (const auto p = options.degree; p && static_cast<std::size_t>(*p) >= n + ends)
    fail(errc::too_few_points, degree_pointer(obj, ptr, 0), ": degree ", *p, options.periodic ? " of a closed curve" : "",
         " needs at least ", static_cast<std::size_t>(*p) + 1 - ends, options.periodic ? " distinct points" : " points",
         ends == 0 ? "" : cat(" besides its ", ends, " end derivative", ends == 1 ? "" : "s"), ", ", pts_at, " has ", n,
         closing.dropped ? " (its last point repeats the first and is left out)" : "");
  options.param = parametrization(obj, ptr);
  if (options.param != Parametrization::uniform) {
    for (std::size_t i = 1; i < n; ++i)
      if (pts[i] == pts[i - 1])
        fail(errc::zero_chord, child(pts_at, i), ": point ", i, " ", pts[i], " coincides with point ", i - 1,
             " (a zero chord); ", param_name(options.param), " parameters need distinct consecutive points");
    if (options.periodic && n >= 2 && pts[n - 1] == pts[0])
      fail(errc::zero_chord, child(pts_at, n - 1), ": point ", n - 1, " ", pts[n - 1],
           " coincides with point 0 (the closing chord of a closed curve has zero length); ", param_name(options.param),
           " parameters need distinct consecutive points, the last and the first included");
  }
  CurveInterpolation r = at(ptr, [&] { return interpolate_curve(pts, options); });
  SpecCurve out(on_unit_domain(r.curve), to_unit(std::move(r.params), r.curve.domain()), pts);
  out.parameters = {{"degree", r.curve.degree()}, {"param", param_name(options.param)}, {"periodic", options.periodic}};
  for (const auto& [name, d] : {std::pair{"start_derivative", options.start_derivative}, {"end_derivative", options.end_derivative}})
    if (d) out.parameters[name] = {d->x, d->y, d->z};
  return out;
}

SpecCurve bspline_curve(const json& b, std::string_view ptr, Context& ctx) {
  expect_object(b, ptr, "an object {\"degree\", \"knots\", \"control_points\", \"weights\"}");
  check_fields(b, ptr, forms::bspline_curve, ctx);
  const int p = degree_value(member(b, "degree", ptr, "an integer degree"), child(ptr, "degree"));
  const std::string kptr = child(ptr, "knots"), cptr = child(ptr, "control_points"), wptr = child(ptr, "weights");
  std::vector<double> knots = numbers(member(b, "knots", ptr, "an array of knots"), kptr);
  const bool closed = periodic_flags(b, ptr, 1)[0];
  const PointStorage cps = points_impl(member(b, "control_points", ptr, "a list of points"), 1, cptr, ctx).points;
  std::vector<Vec3> cp(cps.begin(), cps.end());
  std::vector<double> w;
  if (const json* wj = find_member(b, "weights")) w = numbers(*wj, wptr);
  KnotVector k = at(kptr, [&] { return knot_vector(p, std::move(knots), closed); });
  if (static_cast<std::size_t>(k.count()) != cp.size())
    fail(errc::size_mismatch, cptr, ": ", knots_text(k), " need ", k.count(), " control points, got ", cp.size());
  if (!w.empty() && w.size() != cp.size())
    fail(errc::size_mismatch, wptr, ": ", cp.size(), " control points need ", cp.size(), " weights, got ", w.size());
  for (std::size_t i = 0; i < w.size(); ++i)
    if (!(w[i] > 0)) fail(errc::invalid_weight, child(wptr, i), ": weight ", w[i], " is not positive");
  return SpecCurve(at(ptr, [&] { return on_unit_domain(BSplineCurve(std::move(k), std::move(cp), std::move(w))); }));
}

SpecCurve hermite_curve(const json& h, std::string_view ptr, Context& ctx) {
  expect_object(h, ptr, "an object {\"points\", \"tangents\", \"params\"}");
  check_fields(h, ptr, forms::hermite_curve, ctx);
  const std::string pptr = child(ptr, "points"), tptr = child(ptr, "tangents"), uptr = child(ptr, "params");
  std::vector<Vec3> pts = curve_points(member(h, "points", ptr, "a list of points"), pptr, ctx);
  std::vector<Vec3> tangents;
  if (const json* t = find_member(h, "tangents")) {
    const PointStorage ts = points_impl(*t, 1, tptr, ctx).points;
    tangents.assign(ts.begin(), ts.end());
    if (tangents.size() != pts.size())
      fail(errc::size_mismatch, tptr, ": ", pts.size(), " points need ", pts.size(), " tangents, got ", tangents.size());
  }
  std::vector<double> params;
  if (const json* u = find_member(h, "params")) {
    params = numbers(*u, uptr);
    if (params.size() != pts.size())
      fail(errc::size_mismatch, uptr, ": ", pts.size(), " points need ", pts.size(), " params, got ", params.size());
    for (std::size_t i = 1; i < params.size(); ++i)
      if (!(params[i] > params[i - 1]))
        fail(errc::non_increasing, child(uptr, i), ": param ", params[i], " is not greater than the one before, ",
             params[i - 1]);
  }
  const bool given = !tangents.empty();
  const HermiteCurve c = at(ptr, [&] { return HermiteCurve(std::move(pts), std::move(tangents), std::move(params)); });
  return SpecCurve(at(ptr, [&] { return on_unit_domain(c.to_bspline()); }), to_unit(c.params(), c.domain()), c.points(),
                   {{"tangents", given ? "given" : "catmull_rom"}});
}

SpecCurve line_curve(const json& l, std::string_view ptr, Context& ctx) {
  const PointStorage pts = points_impl(l, 1, ptr, ctx).points;
  if (pts.size() != 2) fail(errc::size_mismatch, place(ptr), ": a line needs exactly 2 points [A, B], got ", pts.size());
  // A == B is allowed: a collapsed boundary (a triangular patch) is a point.
  return SpecCurve(line(pts[0], pts[1]));
}

}  // namespace

BSplineCurve curve_impl(const json& j, std::string_view ptr, Context& ctx) { return read_curve(j, ptr, ctx).curve; }

SpecCurve read_curve(const json& j, std::string_view ptr, Context& ctx) {
  static constexpr std::array<std::string_view, 5> forms{"interpolate", "bspline", "hermite", "line", "approximate"};
  constexpr std::string_view expected =
      "a curve: an object with one of \"interpolate\", \"bspline\", \"hermite\", \"line\", \"approximate\"";
  if (!j.is_object()) wrong_type(ptr, expected, j);
  std::vector<std::string_view> present;
  for (const auto f : forms)
    if (j.contains(std::string(f))) present.push_back(f);
  if (present.empty()) fail(errc::missing_field, place(ptr), ": expected ", expected);
  if (present.size() > 1)
    fail(errc::wrong_type, place(ptr), ": a curve has exactly one of \"interpolate\", \"bspline\", \"hermite\", \"line\", \"approximate\"; got \"",
         present[0], "\" and \"", present[1], "\"");
  const std::string_view form = present[0];
  SpecCurve r = [&] {
    if (form == "interpolate") return interpolated_curve(j, ptr, ctx);
    if (form == "approximate") return approximated_curve(j, ptr, ctx);
    check_fields(j, ptr, {form}, ctx);
    const json& body = j.at(std::string(form));
    const std::string bptr = child(ptr, form);
    if (form == "bspline") return bspline_curve(body, bptr, ctx);
    if (form == "hermite") return hermite_curve(body, bptr, ctx);
    return line_curve(body, bptr, ctx);
  }();
  r.form = form;
  return r;
}

}  // namespace interpatch::io::reader
