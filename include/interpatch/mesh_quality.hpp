#pragma once
/// @file mesh_quality.hpp
/// The quality of a structured hexahedral mesh, in the measures a finite-volume solver
/// and its users judge a mesh by: the corner Jacobians of its cells (inverted cells),
/// OpenFOAM's face non-orthogonality and skewness, the cells' aspect ratio, and the
/// lengths of the first and last cells along each direction.

#include <array>
#include <cstddef>

#include "interpatch/grid.hpp"

namespace interpatch {

/// The quality of a hexahedral mesh. Every cell is the trilinear map of its 8 nodes.
struct MeshQuality {
  std::size_t cells = 0;
  /// det J of each cell's trilinear map at its 8 corners: the triple product of the
  /// three edges leaving the corner along the cell's a, b, c. Negative throughout for
  /// a mesh whose directions run left-handed.
  double min_det_j = 0, max_det_j = 0;
  /// det J over the product of the three edges' lengths, at the worst corner, with the
  /// sign of the mesh's orientation taken out: 1 for a right-angled corner, 0 for a
  /// flat one, negative for a corner turned inside out.
  double min_scaled_jacobian = 0;
  /// Cells with a corner whose scaled Jacobian is 1e-12 or less (flat, or turned
  /// against the mesh's orientation), and the nodes (i, j, k) of the first in C order.
  std::size_t inverted_cells = 0;
  std::array<std::size_t, 3> first_inverted{};
  /// OpenFOAM's non-orthogonality, in degrees, over the faces inside: the angle
  /// between the line from the owner cell's centre to the neighbour's and the face's
  /// area vector; the mean is, as OpenFOAM's checkMesh gives it, the angle whose cosine
  /// is the mean cosine. Face centres and areas come from triangles about each face's
  /// vertex average; cell centres are the pyramid-volume-weighted centres.
  double max_non_orthogonality = 0, mean_non_orthogonality = 0;
  /// OpenFOAM's skewness, the largest over all faces: the distance from where the line
  /// from the owner's centre to the neighbour's (on a boundary face, the face's normal
  /// through the owner's centre) crosses the face's plane to the face's centre, over
  /// the face's extent in that direction (at least 0.2 of the centres' distance inside,
  /// 0.4 of the centre's distance from the face on the boundary).
  double max_skewness = 0;
  /// Per cell, the mean length of its 4 edges along the longest direction over that of
  /// the shortest; the largest over the cells.
  double max_aspect_ratio = 0;
  /// Along u, v, w: the longest first cell ({0}) and last cell ({1}) of the mesh's lines.
  std::array<std::array<double, 2>, 3> end_cells{};
};

/// The quality of the mesh whose nodes are `nodes` (ni × nj × nk, first index along u),
/// as `interpatch mesh` writes it.
/// @throws error size_mismatch (fewer than 2 nodes along a direction), too_large (more
///   than 2^32 − 1 nodes).
[[nodiscard]] MeshQuality mesh_quality(const PointGrid3& nodes);

/// Only the corner Jacobians (min_det_j, max_det_j, min_scaled_jacobian,
/// inverted_cells, first_inverted; cells), in one pass over the nodes without building
/// faces: what `interpatch mesh` checks on every volume mesh it writes.
[[nodiscard]] MeshQuality corner_jacobians(const PointGrid3& nodes);

}  // namespace interpatch
