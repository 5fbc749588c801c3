#include "interpatch/io/json_out.hpp"
#include "interpatch/projection.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <span>
#include <type_traits>
#include <variant>

#include "base/text.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/memory.hpp"
#include "io/box.hpp"
#include "io/json_mesh.hpp"

namespace interpatch::io {

using interpatch::detail::cat;
using interpatch::detail::fail;
using internal::blocks_info;
using internal::mesh_info;
using internal::sampling_info;
using ojson = nlohmann::ordered_json;

namespace {

// Used only in discarded static_asserts, which clang counts as unused.
template <class>
[[maybe_unused]] inline constexpr bool unhandled_exact_form = false;

// Shortest text that reads back to the same double (std::to_chars without a
// precision), which is always a valid JSON number for finite values.
void put(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void put(std::string& out, const Vec3& p) {
  out += '[';
  put(out, p.x);
  out += ", ";
  put(out, p.y);
  out += ", ";
  put(out, p.z);
  out += ']';
}

void put(std::string& out, std::span<const double> v) {
  out += '[';
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out += ", ";
    put(out, v[i]);
  }
  out += ']';
}

// One grid row per line: readable, and a 4096 × 4096 net never sits in memory as text.
template <class T>
void put_grid(std::ostream& os, const Grid<T, 2>& g) {
  os << "[\n";
  std::string row;
  for (std::size_t i = 0; i < g.extent(0); ++i) {
    row = "    [";
    for (std::size_t j = 0; j < g.extent(1); ++j) {
      if (j) row += ", ";
      put(row, g(i, j));
    }
    row += i + 1 < g.extent(0) ? "],\n" : "]\n";
    os << row;
  }
  os << "  ]";
}

// The "periodic" line of a form closed in some direction, after its degrees:
// "  \"periodic\": [false, true],\n"; nothing for an open form.
std::string periodic_line(std::span<const bool> periodic) {
  if (std::none_of(periodic.begin(), periodic.end(), [](bool p) { return p; })) return "";
  std::string line = "  \"periodic\": [";
  for (std::size_t a = 0; a < periodic.size(); ++a) line += cat(a ? ", " : "", periodic[a] ? "true" : "false");
  return line + "],\n";
}

void write_surface(std::ostream& os, const BSplineSurface& s) {
  std::string head = cat("{\n  \"type\": \"bspline_surface\",\n  \"degree\": [", s.degree_u(), ", ", s.degree_v(), "],\n",
                         periodic_line(s.periodic()), "  \"knots\": {\n    \"u\": ");
  put(head, s.knots_u().values());
  head += ",\n    \"v\": ";
  put(head, s.knots_v().values());
  head += "\n  },\n  \"control_points\": ";
  os << head;
  put_grid(os, s.control_points());
  if (s.rational()) {
    os << ",\n  \"weights\": ";
    put_grid(os, s.weights());
  }
  os << "\n}\n";
}

// A volume grid: one list per u index, one line per innermost row along w.
template <class T>
void put_grid(std::ostream& os, const Grid<T, 3>& g) {
  os << "[\n";
  std::string row;
  for (std::size_t i = 0; i < g.extent(0); ++i) {
    os << "    [\n";
    for (std::size_t j = 0; j < g.extent(1); ++j) {
      row = "      [";
      for (std::size_t k = 0; k < g.extent(2); ++k) {
        if (k) row += ", ";
        put(row, g(i, j, k));
      }
      row += j + 1 < g.extent(1) ? "],\n" : "]\n";
      os << row;
    }
    os << (i + 1 < g.extent(0) ? "    ],\n" : "    ]\n");
  }
  os << "  ]";
}

void write_volume(std::ostream& os, const BSplineVolume& v) {
  std::string head = cat("{\n  \"type\": \"bspline_volume\",\n  \"degree\": [", v.degree_u(), ", ", v.degree_v(), ", ",
                         v.degree_w(), "],\n", periodic_line(v.periodic()), "  \"knots\": {\n    \"u\": ");
  put(head, v.knots_u().values());
  head += ",\n    \"v\": ";
  put(head, v.knots_v().values());
  head += ",\n    \"w\": ";
  put(head, v.knots_w().values());
  head += "\n  },\n  \"control_points\": ";
  os << head;
  put_grid(os, v.control_points());
  if (v.rational()) {
    os << ",\n  \"weights\": ";
    put_grid(os, v.weights());
  }
  os << "\n}\n";
}

ojson vec(const Vec3& p) { return ojson::array({p.x, p.y, p.z}); }

double round_ms(double ms) { return std::round(ms * 1000.0) / 1000.0; }

using internal::Box;

// The surface at the data parameters, a block of rows at a time.
// A result that is not finite where a data point is: never a data error that skips
// it (a NaN compares as no distance at all).
[[noreturn]] void result_not_finite(const Vec3& value, const std::string& at, std::initializer_list<double> params) {
  std::string where;
  for (double x : params) where += (where.empty() ? "" : ", ") + cat(x);
  fail(errc::not_finite, at, ": the result at (", where, ") is (", value.x, ", ", value.y, ", ", value.z,
       "): the construction's arithmetic left the range of a double there (coordinates near 1e308, "
       "knot spans or weights so small they vanish)");
}

// Points without a grid: the surface at each point's own site.
void scattered_data_error(const Surface& s, const DataSet& d, DataError& e, std::size_t& done, std::size_t total,
                          const progress_callback& progress) {
  const auto& us = d.params[0];
  const auto& vs = d.params[1];
  if (d.points.size() != us.size() || vs.size() != us.size())
    fail(errc::internal, d.pointer, ": ", d.points.size(), " scattered points for ", us.size(), " sites");
  for (std::size_t k = 0; k < us.size(); ++k) {
    const Vec3& q = d.points[k];
    if (progress && ++done % 65536 == 0) progress(static_cast<double>(done) / static_cast<double>(total));
    if (!is_finite(q) || std::isnan(us[k])) continue;  // a missing point, or one of weight 0: no site
    const Vec3 p = s.point(us[k], vs[k]);
    const double dist = distance(p, q);
    if (!std::isfinite(dist)) result_not_finite(p, cat(d.pointer, "/", k), {us[k], vs[k]});
    if (dist > e.absolute || e.pointer.empty()) {
      e.absolute = dist;
      e.pointer = cat(d.pointer, "/", k);
      e.params = {us[k], vs[k]};
    }
  }
}

void surface_data_error(const Surface& s, const DataSet& d, DataError& e, std::size_t& done, std::size_t total,
                        const progress_callback& progress) {
  if (d.params.size() != 2)
    fail(errc::internal, d.pointer, ": data for a surface needs 2 parameter lists, got ", d.params.size());
  const auto& us = d.params[0];
  const auto& vs = d.params[1];
  if (d.scattered) {
    scattered_data_error(s, d, e, done, total, progress);
    return;
  }
  const std::size_t nu = us.size(), nv = vs.size();
  if (d.points.size() != nu * nv)
    fail(errc::internal, d.pointer, ": ", d.points.size(), " data points for ", nu, " x ", nv, " parameters");
  if (nv == 0) return;
  const std::size_t block = std::max<std::size_t>(1, (std::size_t{1} << 16) / nv);
  for (std::size_t i0 = 0; i0 < nu; i0 += block) {
    const std::size_t nb = std::min(block, nu - i0);
    const PointGrid p = s.evaluate(std::span<const double>(us).subspan(i0, nb), vs);
    for (std::size_t i = 0; i < nb; ++i)
      for (std::size_t j = 0; j < nv; ++j) {
        const Vec3& q = d.points[(i0 + i) * nv + j];
        if (!is_finite(q)) continue;  // a missing point (approximation's data)
        const double dist = distance(p(i, j), q);
        if (!std::isfinite(dist)) result_not_finite(p(i, j), cat(d.pointer, "/", i0 + i, "/", j), {us[i0 + i], vs[j]});
        if (dist > e.absolute || e.pointer.empty()) {
          e.absolute = dist;
          e.pointer = cat(d.pointer, "/", i0 + i, "/", j);
          e.params = {us[i0 + i], vs[j]};
        }
      }
    done += nb * nv;
    if (progress) progress(static_cast<double>(done) / static_cast<double>(total));
  }
}

// The volume at the data parameters, a block of u slices at a time.
void volume_data_error(const Volume& s, const DataSet& d, DataError& e, std::size_t& done, std::size_t total,
                       const progress_callback& progress) {
  if (d.params.size() != 3)
    fail(errc::internal, d.pointer, ": data for a volume needs 3 parameter lists, got ", d.params.size());
  const auto& us = d.params[0];
  const auto& vs = d.params[1];
  const auto& ws = d.params[2];
  const std::size_t nu = us.size(), nv = vs.size(), nw = ws.size();
  if (d.points.size() != nu * nv * nw)
    fail(errc::internal, d.pointer, ": ", d.points.size(), " data points for ", nu, " x ", nv, " x ", nw, " parameters");
  if (nv == 0 || nw == 0) return;
  const std::size_t block = std::max<std::size_t>(1, (std::size_t{1} << 16) / (nv * nw));
  for (std::size_t i0 = 0; i0 < nu; i0 += block) {
    const std::size_t nb = std::min(block, nu - i0);
    const PointGrid3 p = s.evaluate(std::span<const double>(us).subspan(i0, nb), vs, ws);
    for (std::size_t i = 0; i < nb; ++i)
      for (std::size_t j = 0; j < nv; ++j)
        for (std::size_t k = 0; k < nw; ++k) {
          const Vec3& q = d.points[((i0 + i) * nv + j) * nw + k];
          if (!is_finite(q)) continue;  // a missing point (approximation's data)
          const double dist = distance(p(i, j, k), q);
          if (!std::isfinite(dist))
            result_not_finite(p(i, j, k), cat(d.pointer, "/", i0 + i, "/", j, "/", k), {us[i0 + i], vs[j], ws[k]});
          if (dist > e.absolute || e.pointer.empty()) {
            e.absolute = dist;
            e.pointer = cat(d.pointer, "/", i0 + i, "/", j, "/", k);
            e.params = {us[i0 + i], vs[j], ws[k]};
          }
        }
    done += nb * nv * nw;
    if (progress) progress(static_cast<double>(done) / static_cast<double>(total));
  }
}

// The names of the directions in info: u, v, w; a curve's one direction is t.
constexpr const char* uvw[] = {"u", "v", "w"};
constexpr const char* t_axis[] = {"t"};

// "continuity" per direction (a closed direction's seam counts as one of its knots),
// and "seam_continuity" of the closed directions alone.
void continuity_info(ojson& j, std::initializer_list<const KnotVector*> knots, const char* const* names = uvw) {
  ojson all = ojson::object(), seams = ojson::object();
  std::size_t a = 0;
  for (const KnotVector* k : knots) {
    const char* name = names[a];
    all[name] = continuity_name(*k);
    if (k->periodic()) seams[name] = cat("C", k->degree() - k->multiplicity(k->front()));
    ++a;
  }
  j["continuity"] = std::move(all);
  j["seam_continuity"] = std::move(seams);
}

ojson volume_info(const BSplineVolume& v) {
  ojson j;
  j["kind"] = "volume";
  j["exact_form"] = "bspline_volume";
  j["degree"] = {v.degree_u(), v.degree_v(), v.degree_w()};
  const auto& cp = v.control_points();
  j["control_points"] = {cp.extent(0), cp.extent(1), cp.extent(2)};
  j["rational"] = v.rational();
  j["periodic"] = v.periodic();
  j["knots"] = {{"u", v.knots_u().values()}, {"v", v.knots_v().values()}, {"w", v.knots_w().values()}};
  continuity_info(j, {&v.knots_u(), &v.knots_v(), &v.knots_w()});
  const auto d = v.domain();
  j["domain"] = {{"u", {d[0].first, d[0].second}}, {"v", {d[1].first, d[1].second}}, {"w", {d[2].first, d[2].second}}};
  Box box;
  for (const Vec3& p : cp.values()) box.add(p);
  j["bounding_box"] = {{"min", vec(box.lo)}, {"max", vec(box.hi)}, {"diagonal", box.diagonal()}};
  return j;
}

// Where the volume folds, det J sampled on a jacobian_samples³ grid.
constexpr std::size_t jacobian_samples = 17;

ojson jacobian_info(const Volume& v) {
  const InvertedCells r = inverted_cells(v, jacobian_samples);
  ojson at = ojson::array();
  for (const auto& l : r.locations) at.push_back({l[0], l[1], l[2]});
  return {{"samples_per_direction", jacobian_samples},
          {"samples", r.samples},
          {"inverted_points", r.inverted_points},
          {"cells", r.cells},
          {"inverted_cells", r.inverted_cells},
          {"min_determinant", r.min_determinant},
          {"max_determinant", r.max_determinant},
          {"min_at", {r.min_at[0], r.min_at[1], r.min_at[2]}},
          {"inverted_at", std::move(at)}};
}

ojson surface_info(const BSplineSurface& s) {
  ojson j;
  j["kind"] = "surface";
  j["exact_form"] = "bspline_surface";
  j["degree"] = {s.degree_u(), s.degree_v()};
  j["control_points"] = {s.control_points().extent(0), s.control_points().extent(1)};
  j["rational"] = s.rational();
  j["periodic"] = s.periodic();
  j["knots"] = {{"u", s.knots_u().values()}, {"v", s.knots_v().values()}};
  continuity_info(j, {&s.knots_u(), &s.knots_v()});
  const auto [u0, u1] = s.domain_u();
  const auto [v0, v1] = s.domain_v();
  j["domain"] = {{"u", {u0, u1}}, {"v", {v0, v1}}};
  Box box;
  for (const Vec3& p : s.control_points().values()) box.add(p);
  j["bounding_box"] = {{"min", vec(box.lo)}, {"max", vec(box.hi)}, {"diagonal", box.diagonal()}};
  return j;
}

ojson curve_info(const BSplineCurve& c) {
  ojson j;
  j["kind"] = "curve";
  j["exact_form"] = "bspline_curve";
  j["degree"] = {c.degree()};
  j["control_points"] = {c.control_points().size()};
  j["rational"] = c.rational();
  j["periodic"] = {c.periodic()};
  j["knots"] = {{"t", c.knots().values()}};
  continuity_info(j, {&c.knots()}, t_axis);
  const auto [t0, t1] = c.domain();
  j["domain"] = {{"t", {t0, t1}}};
  Box box;
  for (const Vec3& p : c.control_points()) box.add(p);
  j["bounding_box"] = {{"min", vec(box.lo)}, {"max", vec(box.hi)}, {"diagonal", box.diagonal()}};
  return j;
}

// The curve at its data parameters.
void curve_data_error(const BSplineCurve& c, const DataSet& d, DataError& e) {
  if (d.params.size() != 1 || d.params[0].size() != d.points.size())
    fail(errc::internal, d.pointer, ": ", d.points.size(), " data points for ", d.params.size(), " parameter lists");
  for (std::size_t i = 0; i < d.points.size(); ++i) {
    const double dist = distance(c.point(d.params[0][i]), d.points[i]);
    if (std::isnan(dist)) continue;  // a missing point (approximation's data)
    if (dist > e.absolute || e.pointer.empty()) {
      e.absolute = dist;
      e.pointer = cat(d.pointer, "/", i);
      e.params = {d.params[0][i]};
    }
  }
}

// The error's size relative to the data's bounding box.
void set_relative(DataError& e, const Box& box, std::size_t total) {
  e.count = total;
  e.diagonal = box.diagonal();
  e.relative = e.diagonal > 0 ? e.absolute / e.diagonal
                              : (e.absolute == 0 ? 0.0 : std::numeric_limits<double>::infinity());
}

// The members of info that every kind shares after its form's: the error at the
// data, then (after a volume's Jacobian) the data sets, the options, the warnings
// and the times.
void put_data_error(ojson& j, const std::optional<DataError>& err) {
  if (err) {
    j["max_data_error"] = {{"absolute", err->absolute}, {"relative", err->relative}, {"diagonal", err->diagonal},
                           {"points", err->count},      {"at", err->pointer},       {"params", err->params}};
  } else {
    j["max_data_error"] = nullptr;
  }
}

void put_data(ojson& j, const std::vector<DataSet>& sets, const char* const* names, const nlohmann::ordered_json& parameters,
              const std::vector<std::string>& warnings, const Timings& t, double check_ms) {
  ojson data = ojson::array();
  for (const DataSet& d : sets) {
    ojson shape = ojson::array(), params = ojson::object();
    if (d.scattered) {
      // Each point's site is its own: as many as the points, too many to list.
      data.push_back({{"pointer", d.pointer}, {"shape", {d.params[0].size()}}, {"scattered", true}});
      continue;
    }
    for (std::size_t a = 0; a < d.params.size(); ++a) {
      shape.push_back(d.params[a].size());
      params[names[a]] = d.params[a];
    }
    data.push_back({{"pointer", d.pointer}, {"shape", shape}, {"params", params}});
  }
  j["data"] = std::move(data);
  j["parameters"] = parameters;
  j["warnings"] = warnings;
  j["timings"] = {{"parse_ms", round_ms(t.parse_ms)},
                  {"build_ms", round_ms(t.build_ms)},
                  {"check_ms", round_ms(check_ms)},
                  {"total_ms", round_ms(t.parse_ms + t.build_ms + check_ms)}};
}

bool is_flat(const ojson& j) {
  return std::all_of(j.begin(), j.end(), [](const ojson& e) { return !e.is_structured(); });
}

void pretty(std::string& out, const ojson& j, std::size_t indent) {
  if (j.is_array() && is_flat(j)) {
    out += '[';
    for (std::size_t i = 0; i < j.size(); ++i) out += (i ? ", " : "") + j[i].dump();
    out += ']';
    return;
  }
  if (!j.is_structured() || j.empty()) {
    out += j.dump();
    return;
  }
  const std::string pad(indent + 2, ' ');
  out += j.is_array() ? "[\n" : "{\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    out += first ? pad : ",\n" + pad;
    first = false;
    if (j.is_object()) out += ojson(it.key()).dump() + ": ";
    pretty(out, it.value(), indent + 2);
  }
  out += "\n" + std::string(indent, ' ') + (j.is_array() ? "]" : "}");
}

}  // namespace

std::string pretty_json(const nlohmann::ordered_json& j) {
  std::string out;
  pretty(out, j, 0);
  return out + "\n";
}

void write_exact_json(std::ostream& os, const ExactForm& exact) {
  std::visit(
      [&](const auto& form) {
        using T = std::decay_t<decltype(form)>;
        if constexpr (std::is_same_v<T, BSplineSurface>) write_surface(os, form);
        else if constexpr (std::is_same_v<T, BSplineVolume>) write_volume(os, form);
        else static_assert(unhandled_exact_form<T>, "write_exact_json: an exact form without a writer");
      },
      exact);
}

void write_exact_json(const std::filesystem::path& path, const ExactForm& exact) {
  write_atomically(path, [&](std::ostream& os) { write_exact_json(os, exact); });
}

std::string continuity_name(const KnotVector& knots) {
  if (knots.interior_breaks().empty()) return "Cinf";
  return cat("C", knots.continuity());
}

std::optional<DataError> max_data_error(const Construction& c, const progress_callback& progress) {
  if (c.data.empty()) return std::nullopt;
  DataError e;
  Box box;
  std::size_t total = 0, done = 0;
  for (const DataSet& d : c.data) {
    total += d.points.size();
    for (const Vec3& p : d.points) box.add(p);
  }
  if (total == 0) return std::nullopt;
  if (is_volume(c)) {
    const Volume& v = volume_evaluator(c);
    for (const DataSet& d : c.data) volume_data_error(v, d, e, done, total, progress);
  } else {
    const Surface& s = evaluator(c);
    for (const DataSet& d : c.data) surface_data_error(s, d, e, done, total, progress);
  }
  set_relative(e, box, total);
  return e;
}

// An approximation's data against its surface by the closest point (SurfaceProjector),
// not at each point's own parameters: how far the points lie from the surface as a
// user measures it. Null for what is not a surface approximation with its exact form.
ojson closest_distance(const Construction& c) {
  const auto* s = c.exact ? std::get_if<BSplineSurface>(&*c.exact) : nullptr;
  if (!s || c.data.empty() || !c.parameters.contains("max_error")) return nullptr;
  const SurfaceProjector on(*s, *s);
  double worst = -1;
  std::string at;
  for (const DataSet& d : c.data) {
    std::vector<Vec3> q;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < d.points.size(); ++i)
      if (is_finite(d.points[i])) q.push_back(d.points[i]), index.push_back(i);  // NaN: a missing point
    std::vector<SurfacePoint> a(q.size());
    on.closest(q, a);
    const std::size_t nv = d.scattered || d.params.size() < 2 ? 0 : d.params[1].size();
    for (std::size_t k = 0; k < a.size(); ++k)
      if (a[k].distance > worst) {
        worst = a[k].distance;
        at = nv ? cat(d.pointer, "/", index[k] / nv, "/", index[k] % nv) : cat(d.pointer, "/", index[k]);
      }
  }
  if (worst < 0) return nullptr;
  return {{"absolute", worst}, {"at", at}};
}

nlohmann::ordered_json info_json(const Construction& c, const progress_callback& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  if (c.blocks) {
    ojson j = blocks_info(c, progress);
    const double check_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    put_data(j, c.data, uvw, c.parameters, c.warnings, c.timings, check_ms);
    return j;
  }
  const std::optional<DataError> err = max_data_error(c, progress);
  const ojson closest = closest_distance(c);
  const bool volume = is_volume(c);
  const ojson jac = volume ? jacobian_info(volume_evaluator(c)) : ojson();
  const ojson mesh = volume ? mesh_info(c) : ojson();
  const double check_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  ojson j;
  j["type"] = c.type;
  if (c.exact) {
    std::visit(
        [&](const auto& form) {
          using T = std::decay_t<decltype(form)>;
          if constexpr (std::is_same_v<T, BSplineSurface>) j.update(surface_info(form));
          else if constexpr (std::is_same_v<T, BSplineVolume>) j.update(volume_info(form));
          else static_assert(unhandled_exact_form<T>, "info_json: an exact form without a description");
        },
        *c.exact);
  } else {
    j["kind"] = volume ? "volume" : "surface";
    j["exact_form"] = nullptr;
    j["no_exact_form"] = c.no_exact_form;
  }
  put_data_error(j, err);
  if (!closest.is_null()) j["max_closest_distance"] = closest;
  if (volume) j["jacobian"] = jac;
  if (volume) j["mesh"] = mesh;
  if (c.sampling) j["sampling"] = sampling_info(c);
  put_data(j, c.data, uvw, c.parameters, c.warnings, c.timings, check_ms);
  return j;
}

nlohmann::ordered_json curve_info_json(const CurveConstruction& c) {
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<DataError> err;
  Box box;
  std::size_t total = 0;
  for (const DataSet& d : c.data) {
    total += d.points.size();
    for (const Vec3& p : d.points) box.add(p);
  }
  if (total > 0) {
    err.emplace();
    for (const DataSet& d : c.data) curve_data_error(c.curve, d, *err);
    set_relative(*err, box, total);
  }
  const double check_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ojson j;
  j["type"] = c.form;
  j.update(curve_info(c.curve));
  put_data_error(j, err);
  put_data(j, c.data, t_axis, c.parameters, c.warnings, c.timings, check_ms);
  return j;
}

void write_exact_json(std::ostream& os, const BSplineCurve& c) {
  ojson b;
  b["degree"] = c.degree();
  if (c.periodic()) b["periodic"] = true;
  b["knots"] = c.knots().values();
  ojson cp = ojson::array();
  for (const Vec3& p : c.control_points()) cp.push_back(vec(p));
  b["control_points"] = std::move(cp);
  if (c.rational()) b["weights"] = c.weights();
  os << pretty_json({{"bspline", std::move(b)}});
}

void write_exact_json(const std::filesystem::path& path, const BSplineCurve& c) {
  write_atomically(path, [&](std::ostream& os) { write_exact_json(os, c); });
}

}  // namespace interpatch::io
