#pragma once
// The mesh of a "blocks" spec: its blocks' directions tied across the faces they
// share, one grading per tie, the nodes evaluated and merged into one hex mesh.

#include <string>
#include <vector>

#include "interpatch/io/spec.hpp"
#include "interpatch/progress.hpp"
#include "mesh/blocks.hpp"
#include "mesh/graded_blocks.hpp"

namespace interpatch::io::internal {

struct BlocksMesh {
  std::vector<VolumeJacobians> grids;              // per block, its nodes and det J
  std::vector<mesh::SharedFace> shared;            // the faces the blocks share
  std::vector<mesh::DirectionClass> classes;       // directions tied across them
  std::vector<GradingReport> report;               // per class, what its nodes achieve
  mesh::HexMesh hex;                               // every cell, shared nodes merged
  std::vector<double> jacobian;                    // det J at each of hex's points
  double tolerance = 0;
};

// @throws error block_mismatch (faces that nearly meet or meet apart, counts or
//   gradings that differ across a tie, a patch named on a shared face), and what
//   grading and evaluation throw.
BlocksMesh mesh_blocks(const Construction& c, const progress_callback& progress = {});

}  // namespace interpatch::io::internal
