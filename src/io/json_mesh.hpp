#pragma once
// info's descriptions of the mesh a construction gives: what its "sampling" asks
// and achieves, and the quality of its cells.

#include <nlohmann/json.hpp>

#include "interpatch/io/spec.hpp"
#include "interpatch/progress.hpp"

namespace interpatch::io::internal {

// Per direction what the spec's sampling asks and what the nodes of a mesh at its
// counts achieve. Null without a sampling.
nlohmann::ordered_json sampling_info(const Construction& c);

// The quality of the volume mesh `interpatch mesh` writes by default (the sampling's
// counts and grading when the spec has one).
nlohmann::ordered_json mesh_info(const Construction& c);

// The description of a "blocks" spec: each block and its mesh's quality, the faces
// they share, the directions tied across them with their counts and gradings, the
// patches, and the quality of the whole mesh.
nlohmann::ordered_json blocks_info(const Construction& c, const progress_callback& progress);

}  // namespace interpatch::io::internal
