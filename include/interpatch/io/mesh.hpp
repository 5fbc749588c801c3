#pragma once
/// @file io/mesh.hpp
/// Tessellated surfaces and structured grids in the formats graphics, CAD and
/// CFD-meshing tools read.

#include <filesystem>
#include <string_view>

#include "interpatch/grid.hpp"

namespace interpatch::io {

/// A surface sampled on a structured NU × NV grid of vertices (first index along u).
struct SurfaceMesh {
  PointGrid points;
  /// Unit normals per vertex (same shape as points), or empty.
  PointGrid normals;
};

/// The mesh formats a surface can be written to, chosen by extension:
/// .obj (Wavefront, quads with normals and uv), .stl (binary, triangles),
/// .ply (binary little endian, vertices with normals, quads), .vtk (legacy
/// binary STRUCTURED_GRID), .vts (VTK XML StructuredGrid), .xyz (Plot3D, one
/// block, ASCII).
[[nodiscard]] bool is_mesh_format(std::string_view extension) noexcept;

/// Writes the mesh atomically in the format named by the path's extension.
/// Degenerate quads (a pole row) become triangles or are dropped where the format
/// needs non-degenerate faces (STL).
/// @throws error wrong_type (unknown extension), file_unwritable.
void write_surface_mesh(const std::filesystem::path& path, const SurfaceMesh& mesh);

/// Writes a structured NU × NV × NW grid of points (a volume mesh, first index
/// along u) to .vtk (legacy STRUCTURED_GRID), .vts or .xyz (Plot3D); `scalars`,
/// if not empty, is written as a point field named "jacobian".
/// @throws error wrong_type (unknown extension), file_unwritable.
void write_volume_mesh(const std::filesystem::path& path, const PointGrid3& points,
                       const Grid<double, 3>& jacobian = {});

}  // namespace interpatch::io
