// Approximation in a spec: {"type": "approximate"} through a grid of points,
// {"type": "approximate_volume"} through a 3-D grid, and curves {"approximate":
// points}. One reader of the options serves the three; missing points (a null
// coordinate in an inline list, NaN in a .npy or .csv file) are allowed here only.

#include <array>
#include <cmath>

#include "base/excerpt.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/memory.hpp"
#include "io/spec/forms.hpp"
#include "interpatch/projection.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

// "smoothing": the fairness weight λ ≥ 0, or "auto" to have it chosen.
template <class Options>
void read_smoothing(const json& way, const std::string& at_way, Options& o) {
  if (way.is_string()) {
    if (way.get<std::string>() != "auto")
      fail(errc::wrong_type, place(at_way), ": expected a number or \"auto\", got \"", interpatch::detail::excerpt(way.get<std::string>()), "\"");
    o.auto_smoothing = true;
    return;
  }
  const double l = number(way, at_way);
  if (!(l >= 0)) fail(errc::wrong_type, place(at_way), ": smoothing ", l, " is negative");
  o.smoothing = l;
}

// Which of "control_points", "tolerance" and "smoothing" the approximation at `ptr`
// gives: exactly one.
std::string approximation_way(const json& obj, std::string_view ptr) {
  std::vector<std::string> given;
  for (const char* way : {"control_points", "tolerance", "smoothing"})
    if (find_member(obj, way)) given.push_back(way);
  if (given.empty())
    fail(errc::missing_field, place(ptr), ": an approximation needs one of \"control_points\" (a count per direction), "
         "\"tolerance\" (a distance) and \"smoothing\" (a number or \"auto\")");
  if (given.size() > 1)
    fail(errc::wrong_type, place(child(ptr, given[1])), ": give exactly one of \"control_points\", \"tolerance\" and ",
         "\"smoothing\"; \"", given[0], "\" is given too");
  return given[0];
}

double positive_tolerance(const json& way, const std::string& at_way) {
  const double d = number(way, at_way);
  if (!(d > 0)) fail(errc::wrong_type, place(at_way), ": tolerance ", d, " is not a positive distance");
  return d;
}

// The options of an approximation whose points (of `shape`) are at `pts_at`; `ptr`
// the object holding the fields.
template <std::size_t D>
ApproximationOptions<D> read_options(const json& obj, std::string_view ptr, const std::vector<std::size_t>& shape,
                                     std::string_view pts_at) {
  ApproximationOptions<D> o;
  const auto degree = degrees(obj, ptr, D);
  for (std::size_t a = 0; a < D; ++a) o.degree[a] = degree[a];
  o.param = parametrization(obj, ptr);
  const auto periodic = periodic_flags(obj, ptr, D);
  for (std::size_t a = 0; a < D; ++a) o.periodic[a] = periodic[a];

  const std::string given = approximation_way(obj, ptr);
  const std::string at_way = child(ptr, given);
  const json& way = obj.at(given);
  if (given == "control_points") {
    std::array<int, D> c{};
    auto count = [&](const json& j, std::size_t a, const std::string& where) {
      const std::int64_t v = integer(j, where, "an integer count of control points");
      const std::int64_t p = o.degree[a] ? *o.degree[a] : std::min<std::int64_t>(3, static_cast<std::int64_t>(shape[a]) - 1);
      if (v < p + 1)
        fail(errc::too_few_points, place(where), ": ", v, " control points along ", axis_name(a), " are fewer than degree ", p,
             " needs (", p + 1, ")");
      if (static_cast<std::size_t>(v) > shape[a])
        fail(errc::too_few_points, place(where), ": ", v, " control points along ", axis_name(a), " are more than the ",
             shape[a], " data points there (", pts_at, " has shape ", extents_text(shape), ")");
      c[a] = static_cast<int>(v);
    };
    if (way.is_array()) {
      if (way.size() != D)
        fail(errc::size_mismatch, place(at_way), ": ", way.size(), " counts for ", D, " direction", D == 1 ? "" : "s");
      for (std::size_t a = 0; a < D; ++a) count(way[a], a, child(at_way, a));
    } else {
      for (std::size_t a = 0; a < D; ++a) count(way, a, at_way);
    }
    o.control_points = c;
  } else if (given == "tolerance") {
    o.tolerance = positive_tolerance(way, at_way);
  } else {
    read_smoothing(way, at_way, o);
  }

  if (const json* w = find_member(obj, "weights")) {
    const std::string wptr = child(ptr, "weights");
    if constexpr (D == 1) {
      const std::vector<double> v = numbers(*w, wptr);
      o.weights = Grid<double, 1>({v.size()}, v);
    } else {
      o.weights = inline_number_grid<D>(*w, wptr);
    }
    std::vector<std::size_t> ws(o.weights.shape().begin(), o.weights.shape().end());
    if (ws != shape)
      fail(errc::size_mismatch, place(wptr), ": shape ", extents_text(ws), " differs from ", pts_at, ", ", extents_text(shape));
    for (std::size_t i = 0; i < o.weights.size(); ++i)
      if (o.weights.values()[i] < 0) {
        std::vector<std::size_t> idx(D);
        for (std::size_t a = D, r = i; a-- > 0; r /= shape[a]) idx[a] = r % shape[a];
        fail(errc::invalid_weight, place(index_pointer(wptr, idx, D)), ": weight ", o.weights.values()[i], " is negative");
      }
  }
  return o;
}

// Data parameters mapped from a direction's domain onto [0, 1]; in a closed direction
// whose period starts between two data lines (an even degree), those before the
// start wrap to the end.
std::vector<double> unit_params(std::vector<double> t, std::pair<double, double> domain, bool closed) {
  if (!closed) return to_unit(std::move(t), domain);
  const auto [a, b] = domain;
  for (double& x : t) {
    x = (x - a) / (b - a);
    x -= std::floor(x);
  }
  return t;
}

// The report as info shows it.
nlohmann::ordered_json report_json(const ApproximationReport& r, std::string_view pts_at) {
  nlohmann::ordered_json j;
  j["control_points"] = r.control_points;
  j["max_error"] = r.max_error;
  j["max_error_at"] = index_pointer(pts_at, r.max_error_at, r.max_error_at.size());
  j["rms_error"] = r.rms_error;
  j["lambda"] = r.lambda;
  j["missing_points"] = r.missing;
  j["fits"] = r.fits;
  return j;
}

// How the approximation was asked for, as info shows it.
template <class Options>
void put_way(nlohmann::ordered_json& j, const Options& o) {
  if (o.tolerance) j["tolerance"] = *o.tolerance;
  if (o.smoothing) j["smoothing"] = *o.smoothing;
  if constexpr (requires { o.auto_smoothing; })
    if (o.auto_smoothing) j["smoothing"] = "auto";
  if (!o.weights.empty()) j["weights"] = true;
}

// ---------------------------------------------------------------------------
// Scattered points: {"type": "approximate", "points": a list of N points}.

// Sites given in "param": an inline list of N pairs [u, v], an (N, 2) .npy file, or an
// in-memory array (the x and y of its points).
std::vector<std::array<double, 2>> read_sites(const json& j, std::size_t n, Context& ctx) {
  const std::string ptr = "/param";
  std::vector<std::array<double, 2>> out;
  if (j.is_object() && find_member(j, "array")) {
    const PointArray a = points_impl(j, 1, ptr, ctx);
    for (const Vec3& p : a.points) out.push_back({p.x, p.y});
  } else if (j.is_object() && find_member(j, "npy")) {
    check_fields(j, ptr, forms::npy, ctx);
    const std::string file = file_name(j, "npy", ptr);
    const NpyArray a = at(ptr, [&] { return read_npy(ctx.resolve(file)); });
    if (a.shape.size() != 2 || a.shape[1] != 2)
      fail(errc::size_mismatch, place(ptr), ": ", file, " has shape ", extents_text(a.shape), "; sites are (N, 2), one (u, v) per point");
    for (std::size_t k = 0; k < a.shape[0]; ++k) out.push_back({a.data[2 * k], a.data[2 * k + 1]});
  } else if (j.is_array()) {
    for (std::size_t k = 0; k < j.size(); ++k) {
      const std::string at_k = child(ptr, k);
      const std::vector<double> uv = numbers(j[k], at_k, "a site [u, v]");
      if (uv.size() != 2) fail(errc::size_mismatch, place(at_k), ": a site is 2 numbers [u, v], got ", uv.size());
      out.push_back({uv[0], uv[1]});
    }
  } else {
    fail(errc::wrong_type, place(ptr), ": scattered points take \"xy\", \"plane\" or their sites (a list of [u, v], ",
         "or {\"npy\": file} of shape (N, 2))");
  }
  if (out.size() != n)
    fail(errc::size_mismatch, place(ptr), ": ", out.size(), " sites for ", n, " points (/points): give one (u, v) per point");
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(out[k][0]) || !std::isfinite(out[k][1]))
      fail(errc::not_finite, place(child(ptr, k)), ": site (", out[k][0], ", ", out[k][1], ") is not finite");
  return out;
}

// Sites from the closest points of a base surface (its exact form over [0, 1]²): for
// sheets that fold over every plane, which neither "xy" nor "plane" can take. A missing
// point (NaN) gets the centre, which the fit does not look at.
std::vector<std::array<double, 2>> base_sites(const json& base, const PointStorage& points, Context& ctx) {
  const BSplineSurface s = face_surface(base, "/param/base", ctx);
  const SurfaceProjector on(s, s);
  std::vector<Vec3> q(points.begin(), points.end());
  for (Vec3& x : q)
    if (!is_finite(x)) x = s.point(0.5, 0.5);
  std::vector<SurfacePoint> a(q.size());
  on.closest(q, a);
  std::vector<std::array<double, 2>> sites(q.size());
  for (std::size_t k = 0; k < q.size(); ++k) sites[k] = {a[k].u, a[k].v};
  return sites;
}

void scattered_param(const json& spec, const PointStorage& points, ScatteredApproximationOptions& o, Context& ctx) {
  const std::size_t n = points.size();
  const json* j = find_member(spec, "param");
  if (!j) return;
  if (j->is_string()) {
    const std::string name = j->get<std::string>();
    if (name == "xy") o.param = ScatteredParam::xy;
    else if (name == "plane") o.param = ScatteredParam::plane;
    else
      fail(errc::wrong_type, "/param: \"", interpatch::detail::excerpt(name), "\" is for grids; scattered points take \"xy\" ",
           "(a height field), \"plane\" (the default) or their sites ([[u, v], ...] or {\"npy\": file})");
    return;
  }
  o.param = ScatteredParam::sites;
  if (j->is_object() && find_member(*j, "base")) {
    if (j->size() != 1) fail(errc::wrong_type, "/param: {\"base\": surface spec} takes nothing beside the surface");
    o.sites = base_sites(j->at("base"), points, ctx);
    return;
  }
  o.sites = read_sites(*j, n, ctx);
}

std::array<int, 2> net_counts(const json& j, const std::string& ptr, const std::array<int, 2>& deg) {
  std::array<int, 2> c{};
  for (std::size_t a = 0; a < 2; ++a) {
    const json& x = j.is_array() ? j.at(a) : j;
    const std::string where = j.is_array() ? child(ptr, a) : ptr;
    const std::int64_t v = integer(x, where, "an integer count of control points");
    if (v < deg[a] + 1)
      fail(errc::too_few_points, place(where), ": ", v, " control points along ", axis_name(a), " are fewer than degree ",
           deg[a], " needs (", deg[a] + 1, ")");
    if (v > 1 << 20) fail(errc::too_large, place(where), ": ", v, " control points along ", axis_name(a), " are more than 1048576");
    c[a] = static_cast<int>(v);
  }
  if (j.is_array() && j.size() != 2) fail(errc::size_mismatch, place(ptr), ": ", j.size(), " counts for 2 directions");
  return c;
}

ScatteredApproximationOptions scattered_options(const json& spec, const PointStorage& points, Context& ctx) {
  const std::size_t n = points.size();
  ScatteredApproximationOptions o;
  const auto deg = degrees(spec, "", 2);
  o.degree = {deg[0], deg[1]};
  const std::array<int, 2> p{deg[0].value_or(3), deg[1].value_or(3)};
  if (find_member(spec, "periodic"))
    fail(errc::wrong_type, "/periodic: scattered points have no closed directions (a grid of points does)");
  scattered_param(spec, points, o, ctx);
  const std::string given = approximation_way(spec, "");
  const std::string at_way = child("", given);
  const json& way = spec.at(given);
  if (given == "control_points") {
    o.control_points = net_counts(way, at_way, p);
  } else if (given == "tolerance") {
    o.tolerance = positive_tolerance(way, at_way);
  } else {
    read_smoothing(way, at_way, o);
  }
  if (const json* m = find_member(spec, "max_control_points")) {
    if (!o.tolerance) fail(errc::wrong_type, "/max_control_points: it limits a tolerance's refinement; give \"tolerance\"");
    o.max_control_points = net_counts(*m, "/max_control_points", p);
  }
  if (const json* d = find_member(spec, "domain")) {
    std::array<std::array<double, 2>, 2> dom{};
    if (!d->is_array() || d->size() != 2) wrong_type("/domain", "[[u0, u1], [v0, v1]]", *d);
    for (std::size_t a = 0; a < 2; ++a) {
      const std::vector<double> r = numbers((*d)[a], child("/domain", a), "[low, high]");
      if (r.size() != 2) fail(errc::size_mismatch, place(child("/domain", a)), ": a range is 2 numbers, got ", r.size());
      dom[a] = {r[0], r[1]};
    }
    o.domain = dom;
  }
  if (const json* w = find_member(spec, "weights")) {
    o.weights = numbers(*w, "/weights");
    if (o.weights.size() != n) fail(errc::size_mismatch, "/weights: ", o.weights.size(), " weights for ", n, " points (/points)");
    for (std::size_t k = 0; k < n; ++k)
      if (o.weights[k] < 0) fail(errc::invalid_weight, place(child("/weights", k)), ": weight ", o.weights[k], " is negative");
  }
  o.progress = ctx.progress;
  return o;
}

const char* scattered_param_name(ScatteredParam p) {
  return p == ScatteredParam::xy ? "xy" : p == ScatteredParam::plane ? "plane" : "sites";
}

bool on_base(const json& spec) {
  const json* p = find_member(spec, "param");
  return p && p->is_object() && p->contains("base");
}

Construction approximate_scattered_points(const json& spec, Context& ctx) {
  PointArray pts = points_impl(spec.at("points"), 1, "/points", ctx, true);
  const std::size_t n = pts.shape[0];
  const ScatteredApproximationOptions o = scattered_options(spec, pts.points, ctx);
  DataSet data = grid_data(spec.at("points"), pts.points, pts.shape, ctx);
  ctx.parsed();
  ScatteredApproximation r = at("/points", [&] { return approximate_scattered(pts.points, o); });

  Construction c;
  c.type = "approximate";
  c.exact = r.surface.mapped(0.0, 1.0, 0.0, 1.0);
  c.parameters = {{"points", n},
                  {"degree", {r.surface.degree_u(), r.surface.degree_v()}},
                  {"param", on_base(spec) ? "base" : scattered_param_name(o.param)},
                  {"domain", r.domain}};
  if (o.param == ScatteredParam::plane)
    c.parameters["plane"] = {{"origin", {r.origin.x, r.origin.y, r.origin.z}},
                             {"axis_u", {r.axis_u.x, r.axis_u.y, r.axis_u.z}},
                             {"axis_v", {r.axis_v.x, r.axis_v.y, r.axis_v.z}}};
  if (o.max_control_points) c.parameters["max_control_points"] = *o.max_control_points;
  put_way(c.parameters, o);
  c.parameters.update(report_json(r.report, "/points"));
  if (ctx.keep_data) {
    data.scattered = true;
    data.params.assign(2, std::vector<double>(n));
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t a = 0; a < 2; ++a)
        data.params[a][k] = (r.sites[k][a] - r.domain[a][0]) / (r.domain[a][1] - r.domain[a][0]);
    c.data.push_back(std::move(data));
  }
  return c;
}

template <std::size_t D>
Construction approximate_grid(const json& spec, Context& ctx) {
  constexpr const char* grid_form = D == 2 ? "(n+1) x (m+1) x 3" : "(n+1) x (m+1) x (l+1) x 3";
  if constexpr (D == 2)
    if (const json* p = find_member(spec, "points"); p && point_array_rank(*p, ctx) == 1) return approximate_scattered_points(spec, ctx);
  for (const char* only : {"domain", "max_control_points"})
    if (find_member(spec, only))
      fail(errc::wrong_type, "/", only, ": only scattered points (an (N, 3) list) take it; /points is a grid");
  PointArray pts = points_impl(member(spec, "points", "", cat("a grid of points, ", grid_form)), D, "/points", ctx, true);
  const std::vector<std::size_t> shape = pts.shape;
  for (std::size_t a = 0; a < D; ++a)
    if (shape[a] < 2)
      fail(errc::too_few_points, "/points: the grid has ", shape[a], " point", shape[a] == 1 ? "" : "s", " along ",
           axis_name(a), " (shape ", extents_text(shape), "); approximation needs at least 2");
  ApproximationOptions<D> o = read_options<D>(spec, "", shape, "/points");
  o.progress = ctx.progress;
  typename Grid<Vec3, D>::shape_type gs{};
  for (std::size_t a = 0; a < D; ++a) gs[a] = shape[a];
  Grid<Vec3, D> grid(gs, std::move(pts.points));
  // The data as given, missing points and all: info's error at the data skips them.
  DataSet data = grid_data(spec.at("points"), grid.values(), shape, ctx);
  ctx.parsed();

  Construction c;
  ApproximationReport report;
  std::vector<int> degree;
  if constexpr (D == 2) {
    SurfaceApproximation r = at("/points", [&] { return approximate_surface(std::move(grid), o); });
    c.type = "approximate";
    degree = {r.surface.degree_u(), r.surface.degree_v()};
    data.params = {unit_params(std::move(r.params_u), r.surface.domain_u(), o.periodic[0]),
                   unit_params(std::move(r.params_v), r.surface.domain_v(), o.periodic[1])};
    c.exact = r.surface.mapped(0.0, 1.0, 0.0, 1.0);
    report = std::move(r.report);
  } else {
    VolumeApproximation r = at("/points", [&] { return approximate_volume(std::move(grid), o); });
    c.type = "approximate_volume";
    degree = {r.volume.degree_u(), r.volume.degree_v(), r.volume.degree_w()};
    const auto dom = r.volume.domain();
    data.params = {unit_params(std::move(r.params_u), dom[0], o.periodic[0]),
                   unit_params(std::move(r.params_v), dom[1], o.periodic[1]),
                   unit_params(std::move(r.params_w), dom[2], o.periodic[2])};
    c.exact = r.volume.mapped(0.0, 1.0, 0.0, 1.0, 0.0, 1.0);
    report = std::move(r.report);
  }
  c.parameters = {{"grid", shape},
                  {"degree", degree},
                  {"param", param_name(o.param)},
                  {"periodic", std::vector<bool>(o.periodic.begin(), o.periodic.end())}};
  put_way(c.parameters, o);
  c.parameters.update(report_json(report, "/points"));
  if (ctx.keep_data) c.data.push_back(std::move(data));
  return c;
}

}  // namespace

Construction build_approximate(const json& spec, Context& ctx) { return approximate_grid<2>(spec, ctx); }
Construction build_approximate_volume(const json& spec, Context& ctx) { return approximate_grid<3>(spec, ctx); }

template <std::size_t D>
ApproximationOptions<D> approximation_options(const json& obj, std::string_view ptr, const std::vector<std::size_t>& shape,
                                              std::string_view pts_at) {
  return read_options<D>(obj, ptr, shape, pts_at);
}
template ApproximationOptions<2> approximation_options<2>(const json&, std::string_view, const std::vector<std::size_t>&,
                                                          std::string_view);

SpecCurve approximated_curve(const json& obj, std::string_view ptr, Context& ctx) {
  check_fields(obj, ptr, forms::approximate_curve, ctx);
  const std::string pts_at = child(ptr, "approximate");
  const PointArray a = points_impl(obj.at("approximate"), 1, pts_at, ctx, true);
  if (a.points.size() < 2) fail(errc::too_few_points, place(pts_at), ": a curve needs at least 2 points, got ", a.points.size());
  const ApproximationOptions<1> o = read_options<1>(obj, ptr, a.shape, pts_at);
  std::vector<Vec3> pts(a.points.begin(), a.points.end());
  CurveApproximation r = at(ptr, [&] { return approximate_curve(pts, o); });
  const auto [t0, t1] = r.curve.domain();
  SpecCurve out(t0 == 0.0 && t1 == 1.0 ? r.curve : r.curve.mapped(0.0, 1.0),
                unit_params(std::move(r.params), r.curve.domain(), o.periodic[0]), std::move(pts));
  out.parameters = {{"degree", r.curve.degree()}, {"param", param_name(o.param)}, {"periodic", o.periodic[0]}};
  put_way(out.parameters, o);
  out.parameters.update(report_json(r.report, pts_at));
  return out;
}

}  // namespace interpatch::io::reader
