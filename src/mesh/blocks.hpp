#pragma once
// Several structured blocks as one conforming hexahedral mesh: the faces they share
// found by geometry, in any orientation, and the nodes on them merged.

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "interpatch/grid.hpp"
#include "mesh/hex_mesh.hpp"

namespace interpatch::mesh {

// A block's faces, in the order of hex_faces: u0 (first index 0), u1, v0, v1, w0, w1.
inline constexpr std::array<const char*, 6> block_face_names = {"u0", "u1", "v0", "v1", "w0", "w1"};

// How the nodes of one face lie on another's. A face's nodes are (s, t) along its
// two directions in order (v, w for a u face; u, w for a v face; u, v for a w face).
// Node (s, t) of the first face is node (s', t') of the second, where (x, y) is
// (t, s) when transposed and (s, t) otherwise, s' = x or n's − 1 − x when flip_s,
// and t' likewise.
struct FaceMap {
  bool transpose = false, flip_s = false, flip_t = false;
};

struct SharedFace {
  std::array<std::size_t, 2> block{};  // block[0] <= block[1]
  std::array<int, 2> face{};
  FaceMap map;
  double gap = 0;  // the largest distance between nodes the map pairs
};

// The faces the blocks share: every pair of faces (of two blocks, or two faces of one)
// whose corners coincide within `tolerance` in some orientation, and then every node.
// Collapsed faces (all four corners within the tolerance of each other) share nothing.
// @throws error block_mismatch: a face whose corners meet another's but whose node
//   counts differ, or whose nodes are further apart than the tolerance (the message
//   names both blocks and faces and the gap); a face that nearly meets another (every
//   corner within a twentieth of the face's shortest side, and not within the
//   tolerance); a face shared with more than one other.
std::vector<SharedFace> shared_faces(std::span<const PointGrid3> blocks, double tolerance);

// One hexahedral mesh of the blocks: nodes that shared faces pair (and so the nodes of
// edges and corners several blocks share) are one node, at the position of the first
// block's; cells block after block, each block's in C order, turned so that every cell
// is right-handed. A block's outer face is in the patch patch_of[block][face], a name
// (several faces may share one). `origin`, when given, gets for each point the
// index of the node it came from, counting the blocks' nodes one block after another.
HexMesh merge_blocks(std::span<const PointGrid3> blocks, std::span<const SharedFace> shared,
                     std::span<const std::array<std::string, 6>> patch_of, std::vector<std::size_t>* origin = nullptr);

}  // namespace interpatch::mesh
