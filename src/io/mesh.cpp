// The mesh writers' entry points: the format chosen by the path's extension and the
// mesh checked, then written by its family's writer (the polygon meshes of
// mesh_polygons.cpp, the structured grids of mesh_structured.cpp, or streamed by
// mesh_sample.cpp).

#include "interpatch/io/mesh.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <string_view>

#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "io/extension.hpp"
#include "io/finite.hpp"
#include "io/mesh_formats.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

using interpatch::detail::fail;
using internal::lower_extension;
using internal::mesh_io::check_stl_triangle_count;
using internal::mesh_io::float32_warnings;
using internal::quoted;
using internal::mesh_io::Structured;
using internal::mesh_io::write_obj;
using internal::mesh_io::write_ply;
using internal::mesh_io::write_stl;
using internal::mesh_io::write_structured;

std::string normalized(std::string_view extension) {
  std::string ext(extension);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!ext.empty() && ext.front() != '.') ext.insert(ext.begin(), '.');
  return ext;
}

constexpr std::array<std::string_view, 6> surface_formats = {".obj", ".stl", ".ply", ".vtk", ".vts", ".xyz"};
constexpr std::array<std::string_view, 5> volume_formats = {".vtk", ".vts", ".xyz", ".vtu", ".msh"};

template <std::size_t N>
std::string list(const std::array<std::string_view, N>& formats) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) {
    if (i) s += ", ";
    s += formats[i];
  }
  return s;
}

template <std::size_t N>
void check_extension(const fs::path& path, const std::string& ext, const std::array<std::string_view, N>& formats,
                     const char* kind) {
  if (std::find(formats.begin(), formats.end(), ext) != formats.end()) return;
  if (ext.empty()) {
    fail(errc::wrong_type, "cannot write ", quoted(path), ": no extension to choose the ", kind,
                 " mesh format by (supported: ", list(formats), ")");
  }
  if (std::find(surface_formats.begin(), surface_formats.end(), ext) != surface_formats.end()) {
    fail(errc::wrong_type, "cannot write ", quoted(path), ": '", ext, "' holds surfaces, not ", kind,
                 " grids (supported for ", kind, "s: ", list(formats), ")");
  }
  fail(errc::wrong_type, "cannot write ", quoted(path), ": unknown ", kind, " mesh format '", ext,
               "' (supported: ", list(formats), ")");
}

/// A mesh closed in u (v) needs two rows (columns) or more, its last one repeating
/// the first.
void check_closed(const fs::path& path, const SurfaceMesh& m) {
  const PointGrid& g = m.points;
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  if (m.closed[0] || m.closed[1])
    for (const Vec3& p : g.values())
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], p[d]);
        hi[d] = std::max(hi[d], p[d]);
      }
  // sample_mesh copies the first row exactly; a surface evaluated at both ends of
  // its period agrees to rounding (~1e-15 of its size). 1e-9 of the bounding-box
  // diagonal takes that and refuses any real gap.
  const double tol = 1e-9 * norm(hi - lo);
  for (const std::size_t a : {0u, 1u}) {
    if (!m.closed[a]) continue;
    const char* dir = a == 0 ? "u" : "v";
    const char* line = a == 0 ? "row" : "column";
    const std::size_t n = g.extent(a), across = g.extent(1 - a);
    if (n < 2) {
      fail(errc::size_mismatch, "cannot write ", quoted(path), ": a mesh closed in ", dir, " needs 2 ", line,
                   "s or more, the last repeating the first; it has ", n);
    }
    for (std::size_t t = 0; t < across; ++t) {
      const Vec3& first = a == 0 ? g(0, t) : g(t, 0);
      const Vec3& last = a == 0 ? g(n - 1, t) : g(t, n - 1);
      if (const double gap = norm(last - first); gap > tol) {
        const std::size_t i = a == 0 ? n - 1 : t, j = a == 0 ? t : n - 1;
        fail(errc::closing_gap, "cannot write ", quoted(path), ": the mesh is closed in ", dir,
                     " but its last ", line, " does not repeat the first: point [", i, "][", j, "] is ", gap,
                     " away from point [", a == 0 ? 0 : i, "][", a == 0 ? j : 0, "] (allowed: ", tol, ")");
      }
    }
  }
}

}  // namespace

bool is_mesh_format(std::string_view extension) noexcept {
  try {
    const std::string ext = normalized(extension);
    return std::find(surface_formats.begin(), surface_formats.end(), ext) != surface_formats.end() ||
           std::find(volume_formats.begin(), volume_formats.end(), ext) != volume_formats.end();
  } catch (...) {
    return false;
  }
}

std::vector<std::string> write_surface_mesh(const fs::path& path, const SurfaceMesh& mesh) {
  const std::string ext = lower_extension(path);
  check_extension(path, ext, surface_formats, "surface");
  const PointGrid& g = mesh.points;
  if (g.empty()) {
    fail(errc::size_mismatch, "cannot write ", quoted(path), ": the surface mesh has no points (",
                 g.extent(0), " x ", g.extent(1), ")");
  }
  if (!mesh.normals.empty() && mesh.normals.shape() != g.shape()) {
    fail(errc::size_mismatch, "cannot write ", quoted(path), ": ", mesh.normals.extent(0), " x ",
                 mesh.normals.extent(1), " normals for ", g.extent(0), " x ", g.extent(1), " points");
  }
  check_closed(path, mesh);
  const std::size_t shape[3] = {g.extent(0), g.extent(1), 3};
  internal::require_finite(&g.data()->x, 3 * g.size(), 0, shape, "the points of " + quoted(path));
  if (!mesh.normals.empty())
    internal::require_finite(&mesh.normals.data()->x, 3 * g.size(), 0, shape, "the normals of " + quoted(path));

  if (ext == ".obj") {
    write_atomically(path, [&](std::ostream& os) { write_obj(os, mesh); });
  } else if (ext == ".stl") {
    check_stl_triangle_count(mesh, path);
    write_atomically(path, [&](std::ostream& os) { write_stl(os, mesh); });
    return float32_warnings(path, g);
  } else if (ext == ".ply") {
    write_atomically(path, [&](std::ostream& os) { write_ply(os, mesh); });
  } else {
    Structured s;
    s.nu = g.extent(0);
    s.nv = g.extent(1);
    s.points = g.data();
    s.vectors = mesh.normals.empty() ? nullptr : mesh.normals.data();
    s.kind = "surface";
    write_structured(path, ext, s);
  }
  return {};
}

void write_volume_mesh(const fs::path& path, const PointGrid3& points, const Grid<double, 3>& jacobian) {
  const std::string ext = lower_extension(path);
  if (is_polymesh_path(path)) {
    const std::size_t shape[4] = {points.extent(0), points.extent(1), points.extent(2), 3};
    internal::require_finite(&points.data()->x, 3 * points.size(), 0, shape, "the points of " + quoted(path));
    return internal::mesh_io::write_polymesh(path, points);
  }
  check_extension(path, ext, volume_formats, "volume");
  if (points.empty()) {
    fail(errc::size_mismatch, "cannot write ", quoted(path), ": the volume grid has no points (",
                 points.extent(0), " x ", points.extent(1), " x ", points.extent(2), ")");
  }
  if (!jacobian.empty() && jacobian.shape() != points.shape()) {
    fail(errc::size_mismatch, "cannot write ", quoted(path), ": jacobian of shape ", jacobian.extent(0),
                 " x ", jacobian.extent(1), " x ", jacobian.extent(2), " for ", points.extent(0), " x ",
                 points.extent(1), " x ", points.extent(2), " points");
  }
  const std::size_t shape[4] = {points.extent(0), points.extent(1), points.extent(2), 3};
  internal::require_finite(&points.data()->x, 3 * points.size(), 0, shape, "the points of " + quoted(path));
  if (!jacobian.empty())
    internal::require_finite(jacobian.data(), jacobian.size(), 0, std::span(shape).first(3), "the jacobians of " + quoted(path));
  if (ext == ".vtu" || ext == ".msh") return internal::mesh_io::write_unstructured(path, ext, points, jacobian);
  Structured s;
  s.nu = points.extent(0);
  s.nv = points.extent(1);
  s.nw = points.extent(2);
  s.points = points.data();
  s.scalars = jacobian.empty() ? nullptr : jacobian.data();
  s.kind = "volume";
  write_structured(path, ext, s);
}

std::vector<std::string> write_surface_mesh(const fs::path& path, const Surface& surface, std::span<const double> us,
                                            std::span<const double> vs, const progress_callback& progress) {
  const std::string ext = lower_extension(path);
  check_extension(path, ext, surface_formats, "surface");
  if (us.empty() || vs.empty() || (ext != ".vts" && ext != ".vtk"))
    return write_surface_mesh(path, sample_mesh(surface, us, vs, progress));
  internal::mesh_io::stream_surface(path, ext, surface, us, vs, progress);
  return {};
}

}  // namespace interpatch::io
