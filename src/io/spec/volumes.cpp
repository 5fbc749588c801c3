// Volumes from corners and faces in a spec: trilinear, hermite_volume, coons_volume
// (whose faces and cross-derivative fields are surface specs).

#include <array>
#include <memory>

#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/volume_patches.hpp"
#include "base/excerpt.hpp"
#include "io/spec/reader.hpp"

namespace interpatch::io::reader {

namespace {

// The 8 corners of a volume as data: (i, j, k) at index 4i + 2j + k, the C order of (u, v, w).
DataSet volume_corner_data(const std::array<Vec3, 8>& p, std::string pointer) {
  DataSet d;
  d.params = {{0.0, 1.0}, {0.0, 1.0}, {0.0, 1.0}};
  d.points.assign(p.begin(), p.end());
  d.pointer = std::move(pointer);
  return d;
}

// Samples per direction of a boundary surface checked against a Coons volume.
constexpr std::size_t face_samples = 17;


// A message of a nested spec, whose places are pointers from the nested object,
// placed under `ptr`: "/points/3: ..." becomes "/faces/u1/points/3: ...".
std::string rebased(std::string_view message, std::string_view ptr) {
  constexpr std::string_view top = "(top level)";
  if (message.substr(0, top.size()) == top) return cat(ptr, message.substr(top.size()));
  if (!message.empty() && message[0] == '/') return cat(ptr, message);
  return cat(ptr, ": ", message);
}


}  // namespace

// A face of a volume sampled for the data check: face u_i at (i, v, w), v_j at
// (u, j, w), w_k at (u, v, k), the face's own parameters running over [0, 1]².
DataSet face_data(const BSplineSurface& f, std::size_t axis, double fixed, std::string pointer) {
  DataSet d;
  const std::vector<double> t = linspace(0, 1, face_samples);
  const PointGrid g = f.evaluate(t, t);
  d.params.assign(3, t);
  d.params[axis] = {fixed};
  d.points.assign(g.values().begin(), g.values().end());
  d.pointer = std::move(pointer);
  return d;
}

// A surface spec inside a volume spec (a face, a cross-derivative field): built by
// the surface constructions, used by its exact form over [0, 1]².
BSplineSurface face_surface(const json& j, const std::string& ptr, Context& ctx) {
  const std::string surfaces = type_list(2);
  if (!j.is_object()) wrong_type(ptr, cat("a surface spec: an object with a \"type\", one of ", surfaces), j);
  const json& t = member(j, "type", ptr, cat("a string, one of ", surfaces));
  if (!t.is_string()) wrong_type(child(ptr, "type"), cat("a string, one of ", surfaces), t);
  const auto& name = t.get_ref<const std::string&>();
  const ConstructionType* type = find_type(name);
  if (!type || type->dims != 2)
    fail(errc::unknown_type, child(ptr, "type"), ": \"", interpatch::detail::excerpt(name),
         "\" is not a surface type; a face takes one of ", surfaces);
  // The face reads files beside the spec and the arrays given with it, as the
  // volume does; its warnings and errors are placed below `ptr`.
  Context sub;
  sub.base_dir = ctx.base_dir;
  sub.arrays = ctx.arrays;
  sub.array_uses = ctx.array_uses;
  sub.borrow_arrays = ctx.borrow_arrays;
  check_fields(j, "", type->fields, sub);
  Construction c;
  try {
    c = type->build(j, sub);
  } catch (const error& e) {
    throw error(e.code(), rebased(e.what(), ptr));
  }
  for (const std::string& w : sub.warnings) ctx.warn(rebased(w, ptr));
  if (!has_exact_form(c))
    fail(errc::no_exact_form, place(ptr), ": the ", name, " surface has no exact B-spline form (", c.no_exact_form,
         "); a face needs one");
  return std::get<BSplineSurface>(exact_form(c));
}

Construction build_trilinear(const json& spec, Context& ctx) {
  std::array<Vec3, 8> p;
  for (std::size_t n = 0; n < 8; ++n) {
    const std::string name = cat("p", n >> 2, (n >> 1) & 1, n & 1);
    p[n] = point_value(member(spec, name, "", "a point [x, y, z]"), child("", name));
  }
  ctx.parsed();
  return blended("trilinear", at("", [&] { return trilinear(p); }), {volume_corner_data(p, "/p000")},
                        nlohmann::ordered_json::object());
}

Construction build_hermite_volume(const json& spec, Context& ctx) {
  constexpr std::string_view expected = "an array of 8 corners {\"p\", \"du\", \"dv\", \"dw\"}, corner (i,j,k) at index 4i+2j+k";
  const json& cs = member(spec, "corners", "", expected);
  if (!cs.is_array()) wrong_type("/corners", expected, cs);
  if (cs.size() != 8) fail(errc::size_mismatch, "/corners: expected 8 corners (corner (i,j,k) at index 4i+2j+k), got ", cs.size());
  std::array<HermiteVolumeCorner, 8> c{};
  std::array<Vec3, 8> p;
  for (std::size_t n = 0; n < 8; ++n) {
    const std::string ptr = child("/corners", n);
    const json& o = cs[n];
    expect_object(o, ptr, "a corner {\"p\", \"du\", \"dv\", \"dw\", \"duv\", \"duw\", \"dvw\", \"duvw\"}");
    check_fields(o, ptr, {"p", "du", "dv", "dw", "duv", "duw", "dvw", "duvw"}, ctx);
    c[n].p = point_value(member(o, "p", ptr, "a point [x, y, z]"), child(ptr, "p"));
    c[n].du = point_value(member(o, "du", ptr, "a vector [x, y, z]"), child(ptr, "du"));
    c[n].dv = point_value(member(o, "dv", ptr, "a vector [x, y, z]"), child(ptr, "dv"));
    c[n].dw = point_value(member(o, "dw", ptr, "a vector [x, y, z]"), child(ptr, "dw"));
    if (const json* t = find_member(o, "duv")) c[n].duv = point_value(*t, child(ptr, "duv"));
    if (const json* t = find_member(o, "duw")) c[n].duw = point_value(*t, child(ptr, "duw"));
    if (const json* t = find_member(o, "dvw")) c[n].dvw = point_value(*t, child(ptr, "dvw"));
    if (const json* t = find_member(o, "duvw")) c[n].duvw = point_value(*t, child(ptr, "duvw"));
    p[n] = c[n].p;
  }
  ctx.parsed();
  return blended("hermite_volume", at("/corners", [&] { return hermite_volume(c); }),
                        {volume_corner_data(p, "/corners")}, nlohmann::ordered_json::object());
}

Construction build_coons_volume(const json& spec, Context& ctx) {
  static constexpr const char* names[6] = {"u0", "u1", "v0", "v1", "w0", "w1"};
  constexpr std::string_view expected = "an object {\"u0\", \"u1\", \"v0\", \"v1\", \"w0\", \"w1\"} of surface specs";
  const json& fj = member(spec, "faces", "", expected);
  expect_object(fj, "/faces", expected);
  check_fields(fj, "/faces", {"u0", "u1", "v0", "v1", "w0", "w1"}, ctx);
  std::vector<BSplineSurface> f;
  for (const char* n : names) f.push_back(face_surface(member(fj, n, "/faces", "a surface spec"), child("/faces", n), ctx));
  const VolumeFaces faces{f[0], f[1], f[2], f[3], f[4], f[5]};
  std::string blending = choice(spec, "blending", "", {"linear", "hermite"}, "linear");
  const std::optional<double> tol = tolerance_of(spec);
  std::vector<DataSet> data;
  for (std::size_t n = 0; n < 6; ++n) data.push_back(face_data(f[n], n / 2, static_cast<double>(n % 2), child("/faces", names[n])));
  if (const json* x = find_member(spec, "cross_derivatives")) {
    constexpr std::string_view cexpected = "an object with any of \"u0\", \"u1\", \"v0\", \"v1\", \"w0\", \"w1\": surface specs";
    expect_object(*x, "/cross_derivatives", cexpected);
    check_fields(*x, "/cross_derivatives", {"u0", "u1", "v0", "v1", "w0", "w1"}, ctx);
    VolumeCrossDerivatives cross;
    std::optional<BSplineSurface>* slots[6] = {&cross.u0, &cross.u1, &cross.v0, &cross.v1, &cross.w0, &cross.w1};
    nlohmann::ordered_json given = nlohmann::ordered_json::array();
    for (std::size_t n = 0; n < 6; ++n)
      if (const json* s = find_member(*x, names[n])) {
        *slots[n] = face_surface(*s, child("/cross_derivatives", names[n]), ctx);
        given.push_back(names[n]);
      }
    if (blending == "linear" && find_member(spec, "blending"))
      ctx.warn("/blending: \"linear\" ignored with \"cross_derivatives\" (the volume is Hermite-blended)");
    HermiteCoonsVolumeOptions o;
    o.tolerance = tol;
    ctx.parsed();
    nlohmann::ordered_json parameters = {{"blending", "hermite"}, {"cross_derivatives", given}};
    return blended("coons_volume", at("", [&] { return coons_volume(faces, cross, o); }), std::move(data),
                          std::move(parameters));
  }
  CoonsVolumeOptions o;
  o.tolerance = tol;
  if (blending == "hermite") o.blend_u = o.blend_v = o.blend_w = Blend::hermite();
  ctx.parsed();
  nlohmann::ordered_json parameters = {{"blending", blending}};
  return blended("coons_volume", at("/faces", [&] { return coons_volume(faces, o); }), std::move(data),
                        std::move(parameters));
}

}  // namespace interpatch::io::reader
