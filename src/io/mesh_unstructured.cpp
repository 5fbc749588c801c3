// Hexahedral meshes for finite-element and finite-volume codes: VTK's
// UnstructuredGrid (.vtu) and Gmsh's MSH 4.1 (.msh), both from the cells of a
// structured grid of nodes, their outer faces in the patches u0 ... w1.

#include <string>

#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "io/mesh_formats.hpp"
#include "io/mesh_sink.hpp"
#include "mesh/hex_mesh.hpp"

namespace interpatch::io::internal::mesh_io {

namespace {

// A cell's nodes in the order whose a, b, c are right-handed: the top and bottom
// quadrilaterals swapped where the volume's parametrization is left-handed, so that
// every reader sees cells of positive volume.
std::array<std::uint32_t, 8> right_handed(const std::array<std::uint32_t, 8>& c, bool flipped) {
  if (!flipped) return c;
  return {c[4], c[5], c[6], c[7], c[0], c[1], c[2], c[3]};
}

// VTK XML UnstructuredGrid, raw appended little-endian arrays, each after its byte
// count (UInt64): the jacobian (when given), the points, connectivity, offsets, types.
void write_vtu(std::ostream& os, const mesh::HexMesh& m, bool flipped, const double* jacobian) {
  const std::uint64_t np = m.points.size(), nc = m.cells.size();
  AppendedOffsets offsets;
  std::string head;
  {
    Sink s(head);
    s.text("<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
           "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"")
        .uint(np)
        .text("\" NumberOfCells=\"")
        .uint(nc)
        .text("\">\n      <PointData");
    if (jacobian) s.text(" Scalars=\"jacobian\"");
    s.text(">\n");
    if (jacobian)
      s.text("        <DataArray type=\"Float64\" Name=\"jacobian\" format=\"appended\" offset=\"")
          .uint(offsets.next(8 * np))
          .text("\"/>\n");
    s.text("      </PointData>\n      <Points>\n"
           "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"")
        .uint(offsets.next(24 * np))
        .text("\"/>\n      </Points>\n      <Cells>\n"
              "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"")
        .uint(offsets.next(64 * nc))
        .text("\"/>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"")
        .uint(offsets.next(8 * nc))
        .text("\"/>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"")
        .uint(offsets.next(nc))
        .text("\"/>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
  }
  os << head;
  Sink s(os);
  if (jacobian) {
    s.little(std::uint64_t{8 * np});
    s.gather(jacobian, np, 1, std::endian::little);
  }
  s.little(std::uint64_t{24 * np});
  s.gather(&m.points.data()->x, 3 * np, 1, std::endian::little);
  s.little(std::uint64_t{64 * nc});
  for (const auto& c : m.cells)
    for (std::uint32_t n : right_handed(c, flipped)) s.little(std::int64_t{n});
  s.little(std::uint64_t{8 * nc});
  for (std::uint64_t k = 1; k <= nc; ++k) s.little(static_cast<std::int64_t>(8 * k));
  s.little(std::uint64_t{nc});
  for (std::uint64_t k = 0; k < nc; ++k) s.ch(char{12});  // VTK_HEXAHEDRON
  s.text("\n  </AppendedData>\n</VTKFile>\n");
  s.flush();
}

// Gmsh MSH 4.1, ASCII: one volume entity holding every node and hexahedron, a
// surface entity per patch holding its quadrilaterals (oriented out of the volume),
// each entity a physical group named after its patch ("volume" for the cells).
void write_msh(std::ostream& os, const mesh::HexMesh& m, const mesh::PolyMesh& p) {
  Sink s(os);
  s.text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n").uint(p.patches.size() + 1).ch('\n');
  for (std::size_t q = 0; q < p.patches.size(); ++q) s.text("2 ").uint(q + 1).text(" \"").text(p.patches[q].name).text("\"\n");
  s.text("3 ").uint(p.patches.size() + 1).text(" \"volume\"\n$EndPhysicalNames\n$Entities\n0 0 ");
  s.uint(p.patches.size()).text(" 1\n");
  auto box = [&](auto&& nodes) {
    Vec3 lo = m.points[*nodes.begin()], hi = lo;
    for (std::uint32_t n : nodes)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], m.points[n][a]), hi[a] = std::max(hi[a], m.points[n][a]);
    for (const Vec3& v : {lo, hi})
      for (int a = 0; a < 3; ++a) s.shortest(v[a]).ch(' ');
  };
  for (std::size_t q = 0; q < p.patches.size(); ++q) {
    std::vector<std::uint32_t> nodes;
    for (std::size_t f = p.patches[q].start; f < p.patches[q].start + p.patches[q].size; ++f)
      nodes.insert(nodes.end(), p.faces[f].begin(), p.faces[f].end());
    s.uint(q + 1).ch(' ');
    box(nodes);
    s.text("1 ").uint(q + 1).text(" 0\n");
  }
  std::vector<std::uint32_t> all(m.points.size());
  for (std::uint32_t n = 0; n < all.size(); ++n) all[n] = n;
  s.text("1 ");
  box(all);
  s.text("1 ").uint(p.patches.size() + 1).ch(' ').uint(p.patches.size());
  for (std::size_t q = 0; q < p.patches.size(); ++q) s.ch(' ').uint(q + 1);
  s.text("\n$EndEntities\n$Nodes\n1 ").uint(m.points.size()).text(" 1 ").uint(m.points.size());
  s.text("\n3 1 0 ").uint(m.points.size()).ch('\n');
  s.flush();
  write_records(os, m.points.size(), 8, [&](Sink& r, std::size_t n) { r.uint(n + 1).ch('\n'); });
  write_records(os, m.points.size(), 60, [&](Sink& r, std::size_t n) {
    const Vec3& x = m.points[n];
    r.shortest(x.x).ch(' ').shortest(x.y).ch(' ').shortest(x.z).ch('\n');
  });
  std::size_t boundary = 0;
  for (const mesh::Patch& b : p.patches) boundary += b.size;
  const std::size_t elements = boundary + m.cells.size();
  s.text("$EndNodes\n$Elements\n").uint(p.patches.size() + 1).ch(' ').uint(elements).text(" 1 ").uint(elements).ch('\n');
  std::size_t tag = 1;
  for (std::size_t q = 0; q < p.patches.size(); ++q) {
    s.text("2 ").uint(q + 1).text(" 3 ").uint(p.patches[q].size).ch('\n');
    s.flush();
    const std::size_t first = p.patches[q].start, t0 = tag;
    write_records(os, p.patches[q].size, 40, [&](Sink& r, std::size_t k) {
      r.uint(t0 + k);
      for (std::uint32_t n : p.faces[first + k]) r.ch(' ').uint(n + 1);
      r.ch('\n');
    });
    tag += p.patches[q].size;
  }
  s.text("3 1 5 ").uint(m.cells.size()).ch('\n');
  s.flush();
  const std::size_t t0 = tag;
  write_records(os, m.cells.size(), 70, [&](Sink& r, std::size_t k) {
    r.uint(t0 + k);
    for (std::uint32_t n : right_handed(m.cells[k], p.flipped)) r.ch(' ').uint(n + 1);
    r.ch('\n');
  });
  s.text("$EndElements\n");
  s.flush();
}

}  // namespace

void write_unstructured(const std::filesystem::path& path, const std::string& ext, const PointGrid3& nodes,
                        const Grid<double, 3>& jacobian) {
  write_unstructured(path, ext, mesh::structured_hex_mesh(nodes),
                     std::span<const double>(jacobian.data(), jacobian.empty() ? 0 : jacobian.size()));
}

void write_unstructured(const std::filesystem::path& path, const std::string& ext, const mesh::HexMesh& m,
                        std::span<const double> jacobian) {
  const mesh::PolyMesh p = mesh::poly_mesh(m);
  write_atomically(path, [&](std::ostream& os) {
    if (ext == ".vtu") write_vtu(os, m, p.flipped, jacobian.empty() ? nullptr : jacobian.data());
    else write_msh(os, m, p);
  });
}

}  // namespace interpatch::io::internal::mesh_io
