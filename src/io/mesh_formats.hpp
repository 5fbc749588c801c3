#pragma once
// What the pieces of the mesh writer (src/io/mesh*.cpp) share: the format
// families' writers, which mesh.cpp chooses between by extension after checking
// the mesh, and the texts of the VTK files that the streaming writer lays out.

#include "mesh/hex_mesh.hpp"
#include <bit>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "interpatch/grid.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"
#include "interpatch/vec3.hpp"
#include "io/extension.hpp"

namespace interpatch::io::internal::mesh_io {

// ---------------------------------------------------------------------------
// Polygon meshes (mesh_polygons.cpp). Each list of records (vertices, faces, ...)
// is made by every thread, a block at a time (write_records).

void write_obj(std::ostream& os, const SurfaceMesh& m);
/// Binary STL counts its triangles in 32 bits. Where the cells could hold more (two
/// triangles each), they are counted before anything is written, and too many
/// refused; otherwise write_stl counts what it writes.
void check_stl_triangle_count(const SurfaceMesh& m, const std::filesystem::path& path);
void write_stl(std::ostream& os, const SurfaceMesh& m);
void write_ply(std::ostream& os, const SurfaceMesh& m);
/// Binary STL stores float32: a part far from the origin for its size loses its
/// shape there. Says by how much, when that is over 1e-5 of the mesh's diagonal
/// (1 µm on a 100 mm part).
std::vector<std::string> float32_warnings(const std::filesystem::path& path, const PointGrid& g);

// ---------------------------------------------------------------------------
// Structured grids (mesh_structured.cpp): legacy VTK, VTK XML (.vts) and Plot3D
// (.xyz), shared by surfaces (nw = 1) and volumes.

// Where each array starts in a VTK XML file's raw appended data, each array after its
// UInt64 byte count: next(bytes) gives an array's offset and moves past it.
struct AppendedOffsets {
  std::uint64_t end = 0;
  std::uint64_t next(std::uint64_t bytes) {
    const std::uint64_t at = end;
    end += 8 + bytes;
    return at;
  }
};

struct Structured {
  std::size_t nu = 1, nv = 1, nw = 1;
  const Vec3* points = nullptr;   // C order: index (i * nv + j) * nw + k
  const Vec3* vectors = nullptr;  // per-point unit normals, or nullptr
  const double* scalars = nullptr;  // per-point jacobian, or nullptr
  const char* kind = "surface";

  [[nodiscard]] std::size_t size() const noexcept { return nu * nv * nw; }
  /// The C-order index of the point the file holds at place t, i fastest, then j,
  /// then k: the order of VTK and Plot3D files.
  [[nodiscard]] std::size_t at(std::size_t t) const noexcept {
    const std::size_t i = t % nu, rest = t / nu;
    return (i * nv + rest % nv) * nw + rest / nv;
  }

  /// The values of `v` (C order, as `points`; T is Vec3 or double) in the order of
  /// the files, in the given byte order: a line of nu values along i at a time, the
  /// lines made by every thread.
  template <class T>
  void write_lines(std::ostream& os, const T* v, std::endian order) const;
};

// Legacy VTK: the head before the points, and what stands between the points and
// the point data.
std::string legacy_vtk_head(std::size_t nu, std::size_t nv, std::size_t nw, std::string_view kind);
std::string legacy_vtk_point_data(std::size_t size, bool vectors, bool scalars);

/// The XML of a .vts file before its appended data (up to the "_" that opens it)
/// and after it. The arrays are raw appended little-endian data, each preceded by
/// its byte count as UInt64 (header_type), so grids of any size fit: the normals
/// (when there are vectors), the jacobian (scalars), then the points.
std::string vts_head(std::size_t nu, std::size_t nv, std::size_t nw, bool vectors, bool scalars);
inline constexpr std::string_view vts_tail = "\n  </AppendedData>\n</VTKFile>\n";

/// An appended array's byte count, as the .vts holds it before the array.
std::string vts_count(std::uint64_t bytes);

/// The file `path` of the grid in the structured format `ext` (.vtk, .vts, .xyz);
/// a Plot3D grid with scalars has them in a function file beside it (.f).
void write_structured(const std::filesystem::path& path, const std::string& ext, const Structured& g);

// ---------------------------------------------------------------------------
// Unstructured volume meshes (polymesh.cpp).

/// The hexahedra of a structured grid of nodes as an OpenFOAM polyMesh directory.
void write_polymesh(const std::filesystem::path& dir, const PointGrid3& nodes);
/// Any hexahedral mesh (several blocks merged) as a polyMesh directory.
void write_polymesh(const std::filesystem::path& dir, const mesh::HexMesh& m);

/// The same cells as a VTK UnstructuredGrid (`ext` .vtu, with the jacobian as point
/// data when given) or a Gmsh MSH 4.1 file (.msh, the outer faces as quadrilaterals
/// in physical groups u0 ... w1, the cells in "volume") (mesh_unstructured.cpp).
void write_unstructured(const std::filesystem::path& path, const std::string& ext, const PointGrid3& nodes,
                        const Grid<double, 3>& jacobian);
/// Any hexahedral mesh so, `jacobian` one value a point (or empty).
void write_unstructured(const std::filesystem::path& path, const std::string& ext, const mesh::HexMesh& m,
                        std::span<const double> jacobian);

// ---------------------------------------------------------------------------
// Sampling (mesh_sample.cpp).

/// write_surface_mesh(path, sample_mesh(surface, us, vs, progress)) for a .vts or
/// .vtk path (`ext`) and a grid of points, byte for byte, without the mesh in
/// memory.
void stream_surface(const std::filesystem::path& path, const std::string& ext, const Surface& surface,
                    std::span<const double> us, std::span<const double> vs, const progress_callback& progress);

}  // namespace interpatch::io::internal::mesh_io
