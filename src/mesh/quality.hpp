#pragma once
// The measures of interpatch/mesh_quality.hpp on any hexahedral mesh, so that a mesh
// of several blocks is judged by the same code as one block.

#include <cstddef>
#include <span>

#include "interpatch/mesh_quality.hpp"
#include "mesh/hex_mesh.hpp"

namespace interpatch::mesh {

// The corner Jacobians and aspect ratios of the cells, their faces' non-orthogonality
// and skewness. first_inverted[0] is the number of the first inverted cell (the
// structured caller turns it into nodes); end_cells is left to the caller.
MeshQuality quality(const HexMesh& m, const PolyMesh& faces);

// Only the corner Jacobians of the cells (first_inverted[0] the first inverted cell).
MeshQuality corner_jacobians(const HexMesh& m);

}  // namespace interpatch::mesh
