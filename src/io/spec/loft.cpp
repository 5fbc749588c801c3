// "loft": a surface through section curves, and "loft_volume": a volume through
// section surfaces. Each section as given is checked against the result along its
// line (its face) by `info`, through the map that turned and shifted it.
#include <optional>
#include <string>

#include "interpatch/loft.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

// An array of curves at `key` (entries null allowed when `nulls`): the curves, read on
// every thread when it can.
std::vector<std::optional<BSplineCurve>> curve_array(const json& spec, const char* key, bool nulls, Context& ctx) {
  const std::string ptr = child("", key);
  const json& a = *find_member(spec, key);
  const char* expected = nulls ? "an array of curves (null for none)" : "an array of curves";
  if (!a.is_array()) wrong_type(ptr, expected, a);
  std::vector<const json*> items;
  std::vector<std::string> ptrs;
  for (std::size_t i = 0; i < a.size(); ++i) {
    items.push_back(nulls && a[i].is_null() ? nullptr : &a[i]);
    ptrs.push_back(child(ptr, i));
  }
  return read_curve_list(items, ptrs, ctx);
}

// The options both lofts take: degree, param (a name or the places), periodic; the
// param's name as info shows it ("given" for places).
template <class Options>
std::string across_options(const json& spec, Options& o) {
  if (const json* d = find_member(spec, "degree")) o.degree = degree_value(*d, "/degree");
  o.periodic = periodic_flags(spec, "", 1)[0];
  o.spec_pointers = true;
  if (const json* p = find_member(spec, "param"); p != nullptr && p->is_array()) {
    o.params = numbers(*p, "/param", "an array of numbers, one per section");
    return "given";
  }
  o.param = parametrization(spec, "");
  return param_name(o.param);
}

}  // namespace

Construction build_loft(const json& spec, Context& ctx) {
  const json& given = member(spec, "sections", "", "an array of curves [c0, c1, ...]");
  if (given.is_array() && given.size() < 2)
    fail(errc::too_few_points, "/sections: a loft needs at least 2 sections, got ", given.size());
  std::vector<BSplineCurve> sections;
  for (auto& c : curve_array(spec, "sections", false, ctx)) sections.push_back(std::move(*c));
  LoftOptions o;
  const std::string param = across_options(spec, o);
  o.tolerance = tolerance_of(spec);
  if (find_member(spec, "tangents") != nullptr) o.tangents = curve_array(spec, "tangents", true, ctx);
  if (find_member(spec, "guides") != nullptr)
    for (auto& c : curve_array(spec, "guides", false, ctx)) o.guides.push_back(std::move(*c));
  ctx.parsed();
  // The library's messages name their sections, tangents and parameters by pointer.
  LoftSurface built = loft(sections, o);
  const LoftReport& r = built.report;
  std::vector<DataSet> data;
  nlohmann::ordered_json reported = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < sections.size(); ++k) {
    const std::string ptr = child("/sections", k);
    const LoftSectionReport& s = r.sections[k];
    data.push_back(curve_data(sections[k], 0, r.params[k], ptr, s.map));
    reported[ptr] = {{"closed", s.closed}, {"reversed", s.reversed}};
    if (s.closed) reported[ptr]["seam"] = s.map(0.0);  // where u = 0 falls on it
    reported[ptr]["deviation"] = s.deviation;
    // The tangent given for this section, if any: one per section, or the first and the last.
    const std::size_t n = sections.size(), t = o.tangents.size() == n ? k : (k == 0 ? 0 : (k + 1 == n ? 1 : 2));
    if (t < o.tangents.size() && o.tangents[t]) reported[ptr]["tangent_deviation"] = s.tangent_deviation;
  }
  // Guides run along v: each against S(u_i, v) through its map.
  nlohmann::ordered_json guides = nlohmann::ordered_json::object();
  for (std::size_t i = 0; i < r.guides.size(); ++i) {
    const std::string ptr = child("/guides", i);
    data.push_back(curve_data(o.guides[i], 1, r.network->u_params[i], ptr, r.guides[i].map));
    guides[ptr] = {{"reversed", r.guides[i].reversed}, {"deviation", r.guides[i].deviation}};
  }
  nlohmann::ordered_json parameters = {{"degree", {r.degree_u, r.degree_v}},
                                       {"param", param},
                                       {"params", r.params},
                                       {"periodic", o.periodic},
                                       {"closed", r.closed},
                                       {"sections", sections.size()},
                                       {"knots", {{"merged", r.merged_knots},
                                                  {"largest_section", r.section_knots},
                                                  {"reexpressed", r.reexpressed}}},
                                       {"max_deviation", r.max_deviation},
                                       {"tolerance", r.tolerance}};
  parameters["loft_sections"] = std::move(reported);
  if (r.network) {
    parameters.erase("knots");
    parameters["guides"] = std::move(guides);
    parameters["crossings"] = {{"max_gap", r.network->max_gap}, {"tolerance", r.network->tolerance}};
  }
  Construction c;
  c.type = "loft";
  c.exact = std::move(built.surface);
  c.data = std::move(data);
  c.parameters = std::move(parameters);
  return c;
}

Construction build_loft_volume(const json& spec, Context& ctx) {
  const json& given = member(spec, "sections", "", "an array of surface specs [s0, s1, ...]");
  if (!given.is_array()) wrong_type("/sections", "an array of surface specs [s0, s1, ...]", given);
  if (given.size() < 2) fail(errc::too_few_points, "/sections: a loft needs at least 2 sections, got ", given.size());
  std::vector<BSplineSurface> sections;
  for (std::size_t k = 0; k < given.size(); ++k) sections.push_back(face_surface(given[k], child("/sections", k), ctx));
  LoftVolumeOptions o;
  const std::string param = across_options(spec, o);
  ctx.parsed();
  LoftVolume built = loft_volume(sections, o);
  const LoftVolumeReport& r = built.report;
  std::vector<DataSet> data;
  nlohmann::ordered_json deviation = nlohmann::ordered_json::object();
  for (std::size_t k = 0; k < sections.size(); ++k) {
    data.push_back(face_data(sections[k], 2, r.params[k], child("/sections", k)));
    deviation[child("/sections", k)] = r.deviation[k];
  }
  Construction c;
  c.type = "loft_volume";
  c.parameters = {{"degree", r.degree},  {"param", param},       {"params", r.params},
                  {"periodic", o.periodic}, {"sections", sections.size()}, {"max_deviation", r.max_deviation},
                  {"deviation", std::move(deviation)}};
  c.exact = std::move(built.volume);
  c.data = std::move(data);
  return c;
}

}  // namespace interpatch::io::reader
