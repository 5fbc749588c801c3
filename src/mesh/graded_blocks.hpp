#pragma once
// Graded nodes for several volumes at once, whose directions are tied where they
// share faces: one grading and one list of nodes per class of tied directions, so
// that the nodes of a shared face are the same from both sides.

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "interpatch/grading.hpp"
#include "interpatch/volume.hpp"

namespace interpatch::mesh {

// Direction `dir` (0, 1, 2: u, v, w) of block `block`, running the class's way or
// (reversed) the other way.
struct DirectionMember {
  std::size_t block = 0, dir = 0;
  bool reversed = false;
};

// Directions whose nodes move together, with the grading they share (its first and
// last at the class's start and end) and the name messages give it ("sampling NAME:").
struct DirectionClass {
  Grading grading;
  std::vector<DirectionMember> members;
  std::string name;
};

struct GradedBlocks {
  std::vector<std::array<std::vector<double>, 3>> params;  // per block, its nodes' parameters along u, v, w
  std::vector<GradingReport> report;                       // per class: first and last at its start and end
};

// The nodes of every block. A first (last) length is met over every line of every
// member along the class's direction; otherwise as graded_parameters.
// @throws error as graded_parameters does, naming the class; internal when a block's
// direction is in no class or in two.
GradedBlocks graded_blocks(std::span<const Volume* const> blocks, std::span<const DirectionClass> classes);

}  // namespace interpatch::mesh
