// Tensor-product constructions in a spec, surfaces and volumes alike: interpolation
// through a grid of points (interpolate, interpolate_volume) and the exact forms
// build writes (bspline_surface, bspline_volume). One builder of each serves both
// dimensions; Tensor<D> says what differs.

#include <algorithm>
#include <array>
#include <utility>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/memory.hpp"
#include "io/npz_internal.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

template <std::size_t D>
struct Tensor;

// The exact form and its parameters, moved: `return {form, {params...}}` would pick
// std::pair's copying constructor (a braced list deduces no type) and copy the whole
// control net, and the list of parameters would copy each vector.
template <class Exact, class... Params>
std::pair<Exact, std::vector<std::vector<double>>> moved(Exact form, Params... params) {
  std::vector<std::vector<double>> p;
  p.reserve(sizeof...(Params));
  (p.push_back(std::move(params)), ...);
  return {std::move(form), std::move(p)};
}

template <>
struct Tensor<2> {
  using Exact = BSplineSurface;
  using Points = PointGrid;
  static constexpr const char* kind = "surface";
  static constexpr const char* interpolate_type = "interpolate";
  static constexpr const char* bspline_type = "bspline_surface";
  static constexpr const char* grid_form = "(n+1) x (m+1) x 3";
  static constexpr const char* degree_form = "an integer degree or [p, q]";
  static constexpr const char* knots_form = "an object {\"u\": [...], \"v\": [...]}";

  static std::pair<Exact, std::vector<std::vector<double>>> interpolate(Points grid, const std::vector<std::optional<int>>& d,
                                                                        Parametrization param, const std::array<bool, 3>& periodic,
                                                                        const progress_callback& progress) {
    SurfaceInterpolationOptions o;
    o.degree_u = d[0];
    o.degree_v = d[1];
    o.param = param;
    o.progress = progress;
    o.periodic = {periodic[0], periodic[1]};
    SurfaceInterpolation r = interpolate_surface(std::move(grid), o);
    return moved(std::move(r.surface), std::move(r.params_u), std::move(r.params_v));
  }
  static Exact make(std::array<KnotVector, 2> k, Points cp, Grid<double, 2> w) {
    return Exact(std::move(k[0]), std::move(k[1]), std::move(cp), std::move(w));
  }
  static std::vector<int> degrees(const Exact& s) { return {s.degree_u(), s.degree_v()}; }
  static Exact on_unit_domain(Exact s) { return s.mapped(0.0, 1.0, 0.0, 1.0); }
};

template <>
struct Tensor<3> {
  using Exact = BSplineVolume;
  using Points = PointGrid3;
  static constexpr const char* kind = "volume";
  static constexpr const char* interpolate_type = "interpolate_volume";
  static constexpr const char* bspline_type = "bspline_volume";
  static constexpr const char* grid_form = "(n+1) x (m+1) x (l+1) x 3";
  static constexpr const char* degree_form = "an integer degree or [p, q, r]";
  static constexpr const char* knots_form = "an object {\"u\": [...], \"v\": [...], \"w\": [...]}";

  static std::pair<Exact, std::vector<std::vector<double>>> interpolate(Points grid, const std::vector<std::optional<int>>& d,
                                                                        Parametrization param, const std::array<bool, 3>& periodic,
                                                                        const progress_callback& progress) {
    VolumeInterpolationOptions o;
    o.degree_u = d[0];
    o.degree_v = d[1];
    o.degree_w = d[2];
    o.param = param;
    o.progress = progress;
    o.periodic = periodic;
    VolumeInterpolation r = interpolate_volume(std::move(grid), o);
    return moved(std::move(r.volume), std::move(r.params_u), std::move(r.params_v), std::move(r.params_w));
  }
  static Exact make(std::array<KnotVector, 3> k, Points cp, Grid<double, 3> w) {
    return Exact(std::move(k[0]), std::move(k[1]), std::move(k[2]), std::move(cp), std::move(w));
  }
  static std::vector<int> degrees(const Exact& v) { return {v.degree_u(), v.degree_v(), v.degree_w()}; }
  static Exact on_unit_domain(Exact v) { return v.mapped(0.0, 1.0, 0.0, 1.0, 0.0, 1.0); }
};

template <std::size_t D>
bool on_unit_domain(const typename Tensor<D>::Exact& s) {
  for (const auto& d : s.domain())
    if (d != std::pair{0.0, 1.0}) return false;
  return true;
}

// The grid's shape as a Grid's shape.
template <std::size_t D>
typename Grid<Vec3, D>::shape_type grid_shape(const std::vector<std::size_t>& shape) {
  typename Grid<Vec3, D>::shape_type s{};
  for (std::size_t a = 0; a < D; ++a) s[a] = shape[a];
  return s;
}

// "domain": {"u": [a, b], ...}, as the exact form had it before it was mapped onto [0, 1].
template <class Exact>
nlohmann::ordered_json domain_json(const Exact& s) {
  nlohmann::ordered_json d = nlohmann::ordered_json::object();
  const auto dom = s.domain();
  for (std::size_t a = 0; a < dom.size(); ++a) d[axis_name(a)] = {dom[a].first, dom[a].second};
  return {{"domain", d}};
}

// A bspline_surface or bspline_volume spec's result: the form over the unit domain,
// its own domain in the parameters.
template <std::size_t D>
Construction exact_construction(typename Tensor<D>::Exact s) {
  Construction c;
  c.type = Tensor<D>::bspline_type;
  c.parameters = domain_json(s);
  c.exact = on_unit_domain<D>(s) ? std::move(s) : Tensor<D>::on_unit_domain(std::move(s));
  return c;
}

// {"type": "bspline_surface", "npz": "x.npz"}: the form from an archive that
// `build -o x.npz` wrote, which holds every field; none of them may be given too.
template <std::size_t D>
Construction bspline_from_npz(const json& spec, Context& ctx) {
  using T = Tensor<D>;
  for (const char* field : {"degree", "knots", "control_points", "weights", "periodic"})
    if (find_member(spec, field))
      fail(errc::wrong_type, "/npz: give either \"npz\" or \"", field, "\" (with the other fields of ", T::bspline_type,
           "), not both: the archive holds the whole form");
  const std::string file = file_name(spec, "npz", "");
  typename T::Exact s =
      std::get<typename T::Exact>(at("/npz", [&] { return internal::read_exact_npz(ctx.resolve(file), D); }));
  ctx.parsed();
  return exact_construction<D>(std::move(s));
}

}  // namespace

nlohmann::ordered_json check_grid_axes(const json& spec, const std::vector<std::optional<int>>& degree,
                                       const std::array<bool, 3>& periodic, std::span<const std::size_t> shape,
                                       const char* kind, const std::function<Closing(std::size_t)>& closing,
                                       Context& ctx) {
  const std::size_t D = degree.size();
  const std::string shape_text = extents_text(shape);
  nlohmann::ordered_json notes = nlohmann::ordered_json::array();
  for (std::size_t a = 0; a < D; ++a) {
    const std::size_t count = shape[a];
    if (count < 2)
      fail(errc::too_few_points, "/points: the grid has ", count, " point", count == 1 ? "" : "s", " along ", axis_name(a),
           " (shape ", shape_text, "); interpolation needs at least 2");
  }
  for (std::size_t a = 0; a < D; ++a) {
    const std::size_t count = shape[a];
    // Interpolation's own rule (grid_closing): whether the last line repeats the first.
    const Closing ending = closing(a);
    // A closed direction is made of its distinct lines: a closing line is left out.
    const bool dropped = periodic[a] && ending.dropped;
    const std::size_t lines = dropped ? count - 1 : count;
    // A closing line nearly equal to the first: interpolation refuses it (closing_gap) before any degree.
    const bool refused = periodic[a] && ending.nearly;
    if (degree[a] && static_cast<std::size_t>(*degree[a]) >= lines && !refused)
      fail(errc::too_few_points, degree_pointer(spec, "", a), ": degree ", *degree[a], periodic[a] ? " around " : " along ",
           axis_name(a), periodic[a] ? " (closed)" : "", " needs at least ", *degree[a] + 1,
           periodic[a] ? " distinct points" : " points", ", /points has ", count, " (shape ", shape_text, ")",
           dropped ? ", the last repeating the first" : "");
    if (dropped)
      notes.push_back(cat("the last line of points along ", axis_name(a), " repeats the first and is left out: ", lines,
                          " distinct lines around ", axis_name(a)));
    if (!periodic[a] && ending.dropped) {
      std::array<bool, 3> suggested = periodic;
      suggested[a] = true;
      const std::string what = cat("the data close along ", axis_name(a), " (the last line of points repeats the first), but ",
                                   axis_name(a), " is not periodic: the ", kind, " meets itself there with a crease; \"periodic\": ",
                                   periodic_text(suggested, D), " makes it smooth across the seam");
      ctx.warn(cat("/points: ", what));
      notes.push_back(what);
    }
  }
  return notes;
}

namespace {

template <std::size_t D>
Construction interpolate_grid(const json& spec, Context& ctx) {
  using T = Tensor<D>;
  PointArray pts = interpolation_points(member(spec, "points", "", cat("a grid of points, ", T::grid_form)), D, "/points", ctx);
  const auto degree = degrees(spec, "", D);
  const Parametrization param = parametrization(spec, "");
  const std::array<bool, 3> periodic = periodic_flags(spec, "", D);
  typename T::Points grid(grid_shape<D>(pts.shape), std::move(pts.points));
  nlohmann::ordered_json notes = check_grid_axes(spec, degree, periodic, pts.shape, T::kind,
                                                 [&](std::size_t a) { return grid_closing(grid, static_cast<int>(a)); }, ctx);
  DataSet data = grid_data(spec.at("points"), grid.values(), pts.shape, ctx);
  ctx.parsed();
  auto [exact, params] = at("/points", [&] { return T::interpolate(std::move(grid), degree, param, periodic, ctx.progress); });
  const auto dom = exact.domain();
  for (std::size_t a = 0; a < D; ++a) data.params.push_back(to_unit(std::move(params[a]), dom[a]));
  if (!on_unit_domain<D>(exact)) exact = T::on_unit_domain(std::move(exact));

  Construction c;
  c.type = T::interpolate_type;
  c.parameters = {{"grid", pts.shape},
                  {"degree", T::degrees(exact)},
                  {"param", param_name(param)},
                  {"periodic", std::vector<bool>(periodic.begin(), periodic.begin() + D)}};
  if (!notes.empty()) c.parameters["notes"] = std::move(notes);
  c.exact = std::move(exact);
  if (ctx.keep_data) c.data.push_back(std::move(data));
  return c;
}

template <std::size_t D>
Construction exact_form(const json& spec, Context& ctx) {
  using T = Tensor<D>;
  if (find_member(spec, "npz")) return bspline_from_npz<D>(spec, ctx);
  member(spec, "degree", "", T::degree_form);
  const auto degree = degrees(spec, "", D);
  const json& knots = member(spec, "knots", "", T::knots_form);
  expect_object(knots, "/knots", T::knots_form);
  static constexpr std::string_view axes[] = {"u", "v", "w"};
  check_fields(knots, "/knots", Fields(axes, D), ctx);
  std::array<std::vector<double>, D> kv;
  for (std::size_t a = 0; a < D; ++a)
    kv[a] = numbers(member(knots, axis_name(a), "/knots", "an array of knots"), child("/knots", axis_name(a)));
  PointArray cp =
      points_impl(member(spec, "control_points", "", cat("a grid of control points, ", T::grid_form)), D, "/control_points", ctx);
  const std::string shape = extents_text(cp.shape);
  Grid<double, D> weights;
  if (const json* w = find_member(spec, "weights")) {
    weights = inline_number_grid<D>(*w, "/weights");
    const auto ws = weights.shape();
    if (!std::equal(ws.begin(), ws.end(), cp.shape.begin()))
      fail(errc::size_mismatch, "/weights: shape ", extents_text(ws), " differs from /control_points, ", shape);
    for (std::size_t i = 0; i < weights.size(); ++i)
      if (!(weights.values()[i] > 0)) {
        std::vector<std::size_t> idx(D);
        for (std::size_t a = D, r = i; a-- > 0; r /= ws[a]) idx[a] = r % ws[a];
        fail(errc::invalid_weight, index_pointer("/weights", idx, D), ": weight ", weights.values()[i], " is not positive");
      }
  }
  const std::array<bool, 3> periodic = periodic_flags(spec, "", D);
  auto knots_of = [&](std::size_t a) {
    return at(child("/knots", axis_name(a)), [&] { return knot_vector(*degree[a], std::move(kv[a]), periodic[a]); });
  };
  // Braced lists evaluate in order: the u knots are checked first.
  std::array<KnotVector, D> k = [&]<std::size_t... A>(std::index_sequence<A...>) {
    return std::array<KnotVector, D>{knots_of(A)...};
  }(std::make_index_sequence<D>{});
  for (std::size_t a = 0; a < D; ++a)
    if (static_cast<std::size_t>(k[a].count()) != cp.shape[a])
      fail(errc::size_mismatch, "/control_points: ", cp.shape[a], " control points along ", axis_name(a), " (shape ",
           shape, "), but the ", knots_text(k[a]), " in /knots/", axis_name(a), " need ", k[a].count());
  ctx.parsed();
  typename T::Exact s = at("/control_points", [&] {
    return T::make(std::move(k), typename T::Points(grid_shape<D>(cp.shape), std::move(cp.points)), std::move(weights));
  });
  return exact_construction<D>(std::move(s));
}

}  // namespace

Construction build_interpolate(const json& spec, Context& ctx) { return interpolate_grid<2>(spec, ctx); }
Construction build_interpolate_volume(const json& spec, Context& ctx) { return interpolate_grid<3>(spec, ctx); }
Construction build_bspline_surface(const json& spec, Context& ctx) { return exact_form<2>(spec, ctx); }
Construction build_bspline_volume(const json& spec, Context& ctx) { return exact_form<3>(spec, ctx); }

}  // namespace interpatch::io::reader
