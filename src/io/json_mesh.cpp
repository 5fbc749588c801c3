#include "io/json_mesh.hpp"

#include "interpatch/evaluate.hpp"
#include "interpatch/grading.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/mesh_quality.hpp"
#include "base/text.hpp"
#include "io/blocks_mesh.hpp"
#include "mesh/quality.hpp"

namespace interpatch::io::internal {

using detail::cat;
using ojson = nlohmann::ordered_json;

namespace {
constexpr const char* uvw[] = {"u", "v", "w"};
}  // namespace

ojson sampling_info(const Construction& c) {
  if (!c.sampling) return nullptr;
  const Resolution res = default_resolution(c);
  const GradedParameters p = sample_parameters(c, res);
  ojson j = ojson::object();
  for (std::size_t d = 0; d < (is_volume(c) ? 3u : 2u); ++d) {
    const Grading& g = (*c.sampling)[d];
    ojson a = {{"count", p.params[d].size()}};
    if (g.ratio != 0) a["ratio"] = g.ratio;
    if (g.first != 0) a["first"] = g.first;
    if (g.last != 0) a["last"] = g.last;
    if (g.graded()) a["max_growth"] = g.max_growth;
    a["achieved"] = {{"first", p.report[d].first}, {"last", p.report[d].last}, {"growth", p.report[d].growth}};
    j[uvw[d]] = std::move(a);
  }
  return j;
}

namespace {

// The measures of a mesh; end cells only where the mesh is one structured block.
ojson quality_json(const MeshQuality& q, bool structured) {
  ojson j = {{"cells", q.cells},
             {"det_j", {{"min", q.min_det_j}, {"max", q.max_det_j}}},
             {"min_scaled_jacobian", q.min_scaled_jacobian},
             {"inverted_cells", q.inverted_cells}};
  if (q.inverted_cells) j["first_inverted"] = structured ? ojson(q.first_inverted) : ojson(q.first_inverted[0]);
  j["non_orthogonality"] = {{"max", q.max_non_orthogonality}, {"mean", q.mean_non_orthogonality}};
  j["max_skewness"] = q.max_skewness;
  j["max_aspect_ratio"] = q.max_aspect_ratio;
  if (structured) {
    ojson ends = ojson::object();
    for (std::size_t d = 0; d < 3; ++d) ends[uvw[d]] = {{"first", q.end_cells[d][0]}, {"last", q.end_cells[d][1]}};
    j["end_cells"] = std::move(ends);
  }
  return j;
}

ojson grading_json(const Grading& g, const GradingReport& r) {
  ojson a = {{"count", g.count}};
  if (g.ratio != 0) a["ratio"] = g.ratio;
  if (g.first != 0) a["first"] = g.first;
  if (g.last != 0) a["last"] = g.last;
  if (g.graded()) a["max_growth"] = g.max_growth;
  a["achieved"] = {{"first", r.first}, {"last", r.last}, {"growth", r.growth}};
  return a;
}

}  // namespace

ojson mesh_info(const Construction& c) {
  const Resolution res = default_resolution(c);
  const GradedParameters p = sample_parameters(c, res);
  const MeshQuality q = mesh_quality(volume_evaluator(c).evaluate(p.params[0], p.params[1], p.params[2]));
  ojson j = {{"nodes", {res.nu, res.nv, res.nw}}};
  j.update(quality_json(q, true));
  return j;
}

ojson blocks_info(const Construction& c, const progress_callback& progress) {
  const BlockSet& set = *c.blocks;
  const BlocksMesh b = mesh_blocks(c, progress);
  ojson blocks = ojson::array();
  for (std::size_t k = 0; k < set.blocks.size(); ++k) {
    const PointGrid3& x = b.grids[k].points;
    ojson one = {{"name", set.names[k]}, {"type", set.blocks[k].type}, {"nodes", x.shape()}};
    one["quality"] = quality_json(mesh_quality(x), true);
    blocks.push_back(std::move(one));
  }
  ojson shared = ojson::array();
  for (const mesh::SharedFace& f : b.shared)
    shared.push_back({{"blocks", {set.names[f.block[0]], set.names[f.block[1]]}},
                      {"faces", {mesh::block_face_names[static_cast<std::size_t>(f.face[0])],
                                 mesh::block_face_names[static_cast<std::size_t>(f.face[1])]}},
                      {"transposed", f.map.transpose},
                      {"reversed", {f.map.flip_s, f.map.flip_t}},
                      {"gap", f.gap}});
  ojson ties = ojson::array();
  for (std::size_t k = 0; k < b.classes.size(); ++k) {
    const mesh::DirectionClass& t = b.classes[k];
    ojson members = ojson::array();
    for (const mesh::DirectionMember& m : t.members)
      members.push_back(cat(set.names[m.block], " ", uvw[m.dir], m.reversed ? " (reversed)" : ""));
    ojson one = grading_json(t.grading, b.report[k]);
    one["directions"] = std::move(members);
    ties.push_back(std::move(one));
  }
  const mesh::PolyMesh faces = mesh::poly_mesh(b.hex);
  ojson patches = ojson::object();
  for (const mesh::Patch& p : faces.patches) patches[p.name] = p.size;
  ojson j = {{"type", c.type}, {"kind", "volume"}, {"exact_form", nullptr}, {"no_exact_form", c.no_exact_form},
             {"blocks", std::move(blocks)}, {"shared_faces", std::move(shared)}, {"directions", std::move(ties)},
             {"patches", std::move(patches)}, {"tolerance", b.tolerance}};
  ojson mesh = {{"points", b.hex.points.size()}};
  mesh.update(quality_json(mesh::quality(b.hex, faces), false));
  j["mesh"] = std::move(mesh);
  return j;
}

}  // namespace interpatch::io::internal
