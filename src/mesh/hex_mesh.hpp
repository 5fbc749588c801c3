#pragma once
// Unstructured hexahedral meshes: cells of 8 nodes, and the faces a finite-volume
// solver reads (OpenFOAM's polyMesh: each face once, owned by the lower-numbered of
// its cells, its normal out of that owner; internal faces in upper-triangular order,
// then the boundary faces patch by patch).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "interpatch/grid.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::mesh {

// Local faces of a hexahedron, nodes in VTK_HEXAHEDRON order (0..3 the bottom
// quadrilateral, 4..7 the top, node n at (n & 1) ^ ((n >> 1) & 1), (n >> 1) & 1,
// n >> 2 along a, b, c): -a, +a, -b, +b, -c, +c; each ordered so that its normal
// points out of a cell whose a, b, c are right-handed.
inline constexpr std::array<std::array<int, 4>, 6> hex_faces = {{
    {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

struct HexMesh {
  std::vector<Vec3> points;
  std::vector<std::array<std::uint32_t, 8>> cells;
  // For each cell and local face, the patch its face belongs to when on the boundary
  // (an index into patch_names), or -1 for a face inside.
  std::vector<std::array<std::int32_t, 6>> face_patch;
  std::vector<std::string> patch_names;
};

// The cells of a structured ni × nj × nk grid of nodes (first index along u, C order),
// their outer faces in the patches u0, u1, v0, v1, w0, w1 (-a, +a, ...).
// @throws error size_mismatch (fewer than 2 nodes along a direction), too_large
//   (more than 2^32 - 1 nodes).
HexMesh structured_hex_mesh(const PointGrid3& nodes);

struct Patch {
  std::string name;
  std::size_t start = 0, size = 0;  // faces [start, start + size)
};

struct PolyMesh {
  std::vector<std::array<std::uint32_t, 4>> faces;
  std::vector<std::uint32_t> owner, neighbour;  // neighbour: the internal faces'
  std::vector<Patch> patches;
  bool flipped = false;  // the cells were left-handed: every face reversed
};

// The faces of the mesh. Cells whose a, b, c run left-handed (the volume's
// parametrization turned inside out) have every face reversed, so that normals point
// out of their owners. @throws error internal (a face of more than two cells, or a
// boundary face in no patch).
PolyMesh poly_mesh(const HexMesh& m);

}  // namespace interpatch::mesh
