// Approximation in a spec: {"type": "approximate"} through a grid of points,
// {"type": "approximate_volume"} through a 3-D grid, and curves {"approximate":
// points}. One reader of the options serves the three; missing points (a null
// coordinate in an inline list, NaN in a .npy or .csv file) are allowed here only.

#include <array>
#include <cmath>

#include "base/excerpt.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/memory.hpp"
#include "io/spec/forms.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

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

  std::vector<std::string> given;
  for (const char* way : {"control_points", "tolerance", "smoothing"})
    if (find_member(obj, way)) given.push_back(way);
  if (given.empty())
    fail(errc::missing_field, place(ptr), ": an approximation needs one of \"control_points\" (a count per direction), "
         "\"tolerance\" (a distance) and \"smoothing\" (a number or \"auto\")");
  if (given.size() > 1)
    fail(errc::wrong_type, place(child(ptr, given[1])), ": give exactly one of \"control_points\", \"tolerance\" and ",
         "\"smoothing\"; \"", given[0], "\" is given too");
  const std::string at_way = child(ptr, given[0]);
  const json& way = obj.at(given[0]);
  if (given[0] == "control_points") {
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
  } else if (given[0] == "tolerance") {
    const double d = number(way, at_way);
    if (!(d > 0)) fail(errc::wrong_type, place(at_way), ": tolerance ", d, " is not a positive distance");
    o.tolerance = d;
  } else if (way.is_string()) {
    if (way.get<std::string>() != "auto")
      fail(errc::wrong_type, place(at_way), ": expected a number or \"auto\", got \"", interpatch::detail::excerpt(way.get<std::string>()), "\"");
    o.auto_smoothing = true;
  } else {
    const double l = number(way, at_way);
    if (!(l >= 0)) fail(errc::wrong_type, place(at_way), ": smoothing ", l, " is negative");
    o.smoothing = l;
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
template <std::size_t D>
void put_way(nlohmann::ordered_json& j, const ApproximationOptions<D>& o) {
  if (o.tolerance) j["tolerance"] = *o.tolerance;
  if (o.smoothing) j["smoothing"] = *o.smoothing;
  if (o.auto_smoothing) j["smoothing"] = "auto";
  if (!o.weights.empty()) j["weights"] = true;
}

template <std::size_t D>
Construction approximate_grid(const json& spec, Context& ctx) {
  constexpr const char* grid_form = D == 2 ? "(n+1) x (m+1) x 3" : "(n+1) x (m+1) x (l+1) x 3";
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
