#pragma once
/// @file io/mesh.hpp
/// Tessellated surfaces and structured grids in the formats graphics, CAD and
/// CFD-meshing tools read.

#include <array>
#include <filesystem>
#include <string>
#include <vector>
#include <span>
#include <string_view>

#include "interpatch/grid.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"

namespace interpatch::io {

/// A surface sampled on a structured NU × NV grid of vertices (first index along u).
struct SurfaceMesh {
  PointGrid points;
  /// Unit normals per vertex (same shape as points), or empty.
  PointGrid normals;
  /// Whether the grid closes on itself in u (its last row of points is its first
  /// again) and in v (its last column): a surface periodic there, sampled over one
  /// whole period. The .obj, .ply and .stl writers write that row (column) once.
  std::array<bool, 2> closed = {false, false};
};

/// The mesh of a surface on the grid us × vs: points and unit normals
/// (unit_normal()). Derivatives are taken a block of rows at a time (the whole grid
/// of them would be six times the mesh); the threads share every block. Where the
/// surface is a B-spline surface periodic in a direction and the parameters span
/// exactly one period there (first and last a period apart, to 1e-12 of it), the
/// mesh is closed in that direction: its last row (column) of points and normals is
/// set to the first.
/// @throws error out_of_domain, too_large, and what the surface's evaluation throws.
[[nodiscard]] SurfaceMesh sample_mesh(const Surface& surface, std::span<const double> us, std::span<const double> vs,
                                      const progress_callback& progress = {});

/// The mesh formats a surface can be written to, chosen by extension:
/// .obj (Wavefront, quads with normals and uv), .stl (binary, triangles),
/// .ply (binary little endian, vertices with normals, quads), .vtk (legacy
/// binary STRUCTURED_GRID), .vts (VTK XML StructuredGrid), .xyz (Plot3D, one
/// block, ASCII). `extension` may be given with or without the dot, in any case.
[[nodiscard]] bool is_mesh_format(std::string_view extension) noexcept;

/// Writes the mesh atomically in the format named by the path's extension (case
/// does not matter). Every thread turns a block of its vertices, normals, faces or
/// coordinates into the format's bytes while the block before is written; the
/// bytes do not depend on the number of threads. Faces are the grid cells, counterclockwise in (u, v) so that
/// their normals point along S_u x S_v. A cell with two coincident corners (next to
/// a pole row) is written as a triangle, a cell with no area left is dropped; STL
/// splits quads into two triangles and drops those of zero area. Structured
/// formats (.vtk, .vts, .xyz) keep every point, u index fastest.
///
/// A mesh closed in u (v) has no seam of doubled vertices in .obj, .ply and .stl:
/// its last row (column) is not written, and the cells next to it use the first
/// row's vertices and normals — (NU − 1) × NV vertices and still (NU − 1) × (NV − 1)
/// cells, a torus closed both ways watertight. OBJ texture coordinates stay one per
/// grid point, the seam cells running up to 1. Structured formats keep the doubled
/// row, which a structured grid needs.
///
/// Example:
/// @code
///   const auto t = interpatch::linspace(0, 1, 64);
///   interpatch::io::SurfaceMesh m{surface.evaluate(t, t), {}};  // 64 × 64 vertices, no normals
///   interpatch::io::write_surface_mesh("patch.obj", m);
/// @endcode
/// @throws error wrong_type (unknown extension), size_mismatch (no points, normals
///   not of the points' shape, or closed in a direction with fewer than 2 samples),
///   closing_gap (closed in a direction whose last row or column is not the first
///   again, to 1e-9 of the bounding-box diagonal; the message names the point),
///   too_large (more than 2^32 - 1 STL triangles), not_finite (a point or normal
///   with NaN or infinity, named by its index; nothing written), file_unwritable.
/// @returns warnings for the user, empty when there are none: binary STL holds
///   float32 coordinates (7 digits), and where rounding to them moves a point by more
///   than 1e-5 of the mesh's diagonal (a part far from the origin for its size) the
///   warning says by how much and which formats keep doubles. The file is written.
std::vector<std::string> write_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh);

/// The mesh of a surface on the grid us × vs written as
/// write_surface_mesh(path, sample_mesh(surface, us, vs, progress)) writes it, the
/// same bytes. A .vts or a legacy .vtk is written without the mesh in memory: a
/// block of columns at a time, evaluated by every thread while the block before is
/// written (memory for two blocks of about 2^15 points; `progress` is then called
/// from one thread at a time, not always the calling one); the other formats sample
/// the mesh first (.obj, .ply and .stl number their vertices and faces across the
/// whole grid).
///
/// Example:
/// @code
///   const auto t1000 = interpatch::linspace(0, 1, 1000);
///   interpatch::io::write_surface_mesh("patch.vts", surface, t1000, t1000);  // 10^6 points and normals
/// @endcode
/// @throws error as sample_mesh and write_surface_mesh. @returns its warnings.
std::vector<std::string> write_surface_mesh(const std::filesystem::path& path, const Surface& surface, std::span<const double> us,
                        std::span<const double> vs, const progress_callback& progress = {});

/// Whether `path` names an OpenFOAM polyMesh directory (its last component is
/// "polyMesh", as in CASE/constant/polyMesh): a volume mesh format.
[[nodiscard]] bool is_polymesh_path(const std::filesystem::path& path);

/// Writes a structured NU × NV × NW grid of points (a volume mesh, first index
/// along u) to .vtk (legacy STRUCTURED_GRID), .vts or .xyz (Plot3D), or as the
/// hexahedral cells of an OpenFOAM polyMesh directory (is_polymesh_path: points,
/// faces, owner, neighbour and boundary, ASCII; internal faces in upper-triangular
/// order, every face's normal out of its owner, the outer faces in the patches u0,
/// u1, v0, v1, w0, w1; written whole or not at all, write_directory_atomically;
/// the jacobian is not written there); `jacobian`,
/// if not empty, is written as a point field named "jacobian". Plot3D grid files
/// hold coordinates only, so for .xyz the field goes to a Plot3D function file
/// beside it (same name, extension .f: block count, "ni nj nk 1", values).
/// @throws error wrong_type (unknown extension, or a surface-only format),
///   size_mismatch (no points, or a jacobian of another shape), not_finite (a point
///   or determinant with NaN or infinity; nothing written), file_unwritable.
void write_volume_mesh(const std::filesystem::path& path, const PointGrid3& points,
                       const Grid<double, 3>& jacobian = {});

}  // namespace interpatch::io
