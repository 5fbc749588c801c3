// The polygon-mesh formats: Wavefront .obj, binary .stl and binary little-endian
// .ply, their faces the cells of the grid (mesh_cells.hpp).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "base/text.hpp"
#include "io/box.hpp"
#include "io/mesh_cells.hpp"
#include "io/mesh_formats.hpp"
#include "io/mesh_sink.hpp"

namespace interpatch::io::internal::mesh_io {
namespace fs = std::filesystem;

// Vertices, normals and faces share numbers; texture coordinates are one per grid
// point, so that the cells across a seam still run up to u (v) = 1.
void write_obj(std::ostream& os, const SurfaceMesh& m) {
  const PointGrid& g = m.points;
  const Vertices vx(m);
  const std::size_t nu = g.extent(0), nv = g.extent(1), cols = vx.cols();
  const bool normals = !m.normals.empty();
  {
    Sink s(os);
    s.text("# interpatch surface mesh: ").uint(vx.rows()).text(" x ").uint(vx.cols()).text(" vertices, first index along u");
    s.text(closed_note(m)).ch('\n');
    s.flush();
  }
  const auto vector_lines = [&](const char* tag, const PointGrid& from) {
    write_records(os, vx.count(), 60, [&](Sink& s, std::size_t r) {
      const Vec3& p = from(r / cols, r % cols);
      s.text(tag).shortest(p.x).ch(' ').shortest(p.y).ch(' ').shortest(p.z).ch('\n');
    });
  };
  vector_lines("v ", g);
  // Texture coordinates i / (nu − 1), j / (nv − 1): each one's text made once.
  const auto fractions = [](std::size_t n) {
    std::vector<std::string> t(n);
    for (std::size_t i = 0; i < n; ++i) {
      Sink s(t[i]);
      s.shortest(n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 0.0);
    }
    return t;
  };
  const std::vector<std::string> tu = fractions(nu), tv = fractions(nv);
  write_records(os, nu * nv, 30, [&](Sink& s, std::size_t r) {
    s.text("vt ").text(tu[r / nv]).ch(' ').text(tv[r % nv]).ch('\n');
  });
  if (normals) vector_lines("vn ", m.normals);
  write_records(os, cell_count(vx), 40, [&](Sink& s, std::size_t r) {
    cell_face(vx, r, [&](const Corner* c, std::size_t n) {
      s.ch('f');
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t v = c[k].vertex + 1;  // OBJ counts from 1; v and vn share the index
        s.ch(' ').uint(v).ch('/').uint(c[k].grid + 1);
        if (normals) s.ch('/').uint(v);
      }
      s.ch('\n');
    });
  });
}

/// Binary STL counts its triangles in 32 bits. Where the cells could hold more (two
/// triangles each), they are counted before anything is written, and too many
/// refused; otherwise write_stl counts what it writes.
void check_stl_triangle_count(const SurfaceMesh& m, const fs::path& path) {
  const Vertices vx(m);
  if (2 * std::uint64_t{cell_count(vx)} <= std::numeric_limits<std::uint32_t>::max()) return;
  const std::uint64_t count = count_faces(vx, true);
  if (count > std::numeric_limits<std::uint32_t>::max()) {
    detail::fail(errc::too_large, "cannot write ", quoted(path), ": ", count,
                 " triangles; binary STL holds at most 4294967295");
  }
}

// The header's triangle count is filled in once the triangles are written.
void write_stl(std::ostream& os, const SurfaceMesh& m) {
  constexpr std::uint64_t triangle_bytes = 50, count_at = 80;
  {
    Sink s(os);
    // Must not start with "solid": readers take that for ASCII STL.
    char header[80];
    std::memset(header, ' ', sizeof header);
    const char title[] = "interpatch binary STL surface mesh";
    std::memcpy(header, title, sizeof title - 1);
    s.text(std::string_view(header, sizeof header));
    s.little(std::uint32_t{0});
    s.flush();
  }
  const Vertices vx(m);
  auto f32 = [](double v) { return static_cast<float>(v); };
  const std::uint64_t bytes = write_records(os, cell_count(vx), 100, [&](Sink& s, std::size_t r) {
    cell_triangles(vx, r, [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n) {
      const Vec3 unit = n / norm(n);
      s.little(f32(unit.x)).little(f32(unit.y)).little(f32(unit.z));
      for (const Vec3* p : {&a, &b, &c}) s.little(f32(p->x)).little(f32(p->y)).little(f32(p->z));
      s.little(std::uint16_t{0});
    });
  });
  os.seekp(static_cast<std::streamoff>(count_at));
  Sink(os).little(static_cast<std::uint32_t>(bytes / triangle_bytes)).flush();
}

void write_ply(std::ostream& os, const SurfaceMesh& m) {
  const Vertices vx(m);
  const std::size_t cols = vx.cols();
  const bool normals = !m.normals.empty();
  const std::uint64_t faces = count_faces(vx, false);
  const bool fits_int = vx.count() <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  {
    Sink s(os);
    s.text("ply\nformat binary_little_endian 1.0\ncomment interpatch surface mesh ")
        .uint(vx.rows())
        .text(" x ")
        .uint(vx.cols())
        .text(", first index along u")
        .text(closed_note(m))
        .text("\nelement vertex ")
        .uint(vx.count())
        .text("\nproperty double x\nproperty double y\nproperty double z\n");
    if (normals) s.text("property double nx\nproperty double ny\nproperty double nz\n");
    s.text("element face ").uint(faces).text("\nproperty list uchar ").text(fits_int ? "int" : "uint").text(" vertex_indices\nend_header\n");
    s.flush();
  }
  write_records(os, vx.count(), normals ? 48 : 24, [&](Sink& s, std::size_t r) {
    const std::size_t i = r / cols, j = r % cols;
    const Vec3& p = m.points(i, j);
    s.little(p.x).little(p.y).little(p.z);
    if (normals) {
      const Vec3& n = m.normals(i, j);
      s.little(n.x).little(n.y).little(n.z);
    }
  });
  write_records(os, cell_count(vx), 17, [&](Sink& s, std::size_t r) {
    cell_face(vx, r, [&](const Corner* c, std::size_t n) {
      s.little(static_cast<std::uint8_t>(n));
      for (std::size_t k = 0; k < n; ++k) {
        if (fits_int) s.little(static_cast<std::int32_t>(c[k].vertex));
        else s.little(static_cast<std::uint32_t>(c[k].vertex));
      }
    });
  });
}

/// Binary STL stores float32: a part far from the origin for its size loses its
/// shape there. Says by how much, when that is over 1e-5 of the mesh's diagonal
/// (1 µm on a 100 mm part).
std::vector<std::string> float32_warnings(const fs::path& path, const PointGrid& g) {
  internal::Box box;
  double moved = 0;
  for (const Vec3& p : g.values()) {
    box.add(p);
    for (int a = 0; a < 3; ++a) moved = std::max(moved, std::abs(p[a] - static_cast<double>(static_cast<float>(p[a]))));
  }
  const double diagonal = box.diagonal();
  if (!(moved > 1e-5 * diagonal)) return {};
  return {detail::cat(quoted(path), " holds float32 coordinates (binary STL has no others): rounding moves its points by up to ",
              moved, diagonal > 0 ? detail::cat(", ", moved / diagonal, " of the mesh's diagonal ", diagonal) : std::string(),
              "; .ply, .obj, .vtk and .vts keep every digit")};
}

}  // namespace interpatch::io::internal::mesh_io
