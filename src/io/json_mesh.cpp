#include "io/json_mesh.hpp"

#include "interpatch/evaluate.hpp"
#include "interpatch/grading.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/mesh_quality.hpp"

namespace interpatch::io::internal {

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

ojson mesh_info(const Construction& c) {
  const Resolution res = default_resolution(c);
  const GradedParameters p = sample_parameters(c, res);
  const MeshQuality q = mesh_quality(volume_evaluator(c).evaluate(p.params[0], p.params[1], p.params[2]));
  ojson j = {{"nodes", {res.nu, res.nv, res.nw}},
             {"cells", q.cells},
             {"det_j", {{"min", q.min_det_j}, {"max", q.max_det_j}}},
             {"min_scaled_jacobian", q.min_scaled_jacobian},
             {"inverted_cells", q.inverted_cells}};
  if (q.inverted_cells) j["first_inverted"] = q.first_inverted;
  j["non_orthogonality"] = {{"max", q.max_non_orthogonality}, {"mean", q.mean_non_orthogonality}};
  j["max_skewness"] = q.max_skewness;
  j["max_aspect_ratio"] = q.max_aspect_ratio;
  ojson ends = ojson::object();
  for (std::size_t d = 0; d < 3; ++d) ends[uvw[d]] = {{"first", q.end_cells[d][0]}, {"last", q.end_cells[d][1]}};
  j["end_cells"] = std::move(ends);
  return j;
}

}  // namespace interpatch::io::internal
