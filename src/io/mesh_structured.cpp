// The structured-grid formats, shared by surfaces (nw = 1) and volumes: legacy
// VTK (binary STRUCTURED_GRID), VTK XML StructuredGrid (.vts, raw appended data)
// and Plot3D (.xyz, ASCII, with a function file for a field).

#include <bit>
#include <cstdint>
#include <string>

#include "interpatch/io/atomic_file.hpp"
#include "io/mesh_formats.hpp"
#include "io/mesh_sink.hpp"

namespace interpatch::io::internal::mesh_io {
namespace fs = std::filesystem;

template <class T>
void Structured::write_lines(std::ostream& os, const T* v, std::endian order) const {
  const std::size_t stride = nv * nw;
  write_records(os, nv * nw, nu * sizeof(T), [&](Sink& s, std::size_t line) {
    s.gather(v + at(line * nu), nu, stride, order);
  });
}

// Legacy VTK: the head before the points, and what stands between the points and
// the point data.
std::string legacy_vtk_head(std::size_t nu, std::size_t nv, std::size_t nw, std::string_view kind) {
  std::string head;
  Sink s(head);
  s.text("# vtk DataFile Version 3.0\ninterpatch ")
      .text(kind)
      .text(" grid\nBINARY\nDATASET STRUCTURED_GRID\nDIMENSIONS ")
      .uint(nu).ch(' ').uint(nv).ch(' ').uint(nw)
      .text("\nPOINTS ").uint(nu * nv * nw).text(" double\n");
  return head;
}

std::string legacy_vtk_point_data(std::size_t size, bool vectors, bool scalars) {
  std::string text = "\n";
  Sink s(text);
  if (vectors || scalars) s.text("POINT_DATA ").uint(size).ch('\n');
  if (vectors) s.text("NORMALS normals double\n");
  return text;
}

std::string vts_head(std::size_t nu, std::size_t nv, std::size_t nw, bool vectors, bool scalars) {
  const std::uint64_t n = std::uint64_t{nu} * nv * nw;
  const std::uint64_t vec_bytes = 24 * n, scal_bytes = 8 * n;
  AppendedOffsets offsets;
  std::string head;
  Sink s(head);
  auto extent = [&]() { s.text("0 ").uint(nu - 1).text(" 0 ").uint(nv - 1).text(" 0 ").uint(nw - 1); };
  s.text("<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"StructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
         "  <StructuredGrid WholeExtent=\"");
  extent();
  s.text("\">\n    <Piece Extent=\"");
  extent();
  s.text("\">\n      <PointData");
  if (vectors) s.text(" Normals=\"Normals\"");
  if (scalars) s.text(" Scalars=\"jacobian\"");
  s.text(">\n");
  if (vectors) {
    s.text("        <DataArray type=\"Float64\" Name=\"Normals\" NumberOfComponents=\"3\" format=\"appended\" offset=\"")
        .uint(offsets.next(vec_bytes))
        .text("\"/>\n");
  }
  if (scalars) {
    s.text("        <DataArray type=\"Float64\" Name=\"jacobian\" NumberOfComponents=\"1\" format=\"appended\" offset=\"")
        .uint(offsets.next(scal_bytes))
        .text("\"/>\n");
  }
  s.text("      </PointData>\n      <Points>\n"
         "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"appended\" offset=\"")
      .uint(offsets.next(vec_bytes))
      .text("\"/>\n      </Points>\n    </Piece>\n  </StructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
  return head;
}

std::string vts_count(std::uint64_t bytes) {
  std::string count;
  Sink(count).little(bytes);
  return count;
}

namespace {

void write_legacy_vtk(std::ostream& os, const Structured& g) {
  os << legacy_vtk_head(g.nu, g.nv, g.nw, g.kind);
  g.write_lines(os, g.points, std::endian::big);
  os << legacy_vtk_point_data(g.size(), g.vectors != nullptr, g.scalars != nullptr);
  if (g.vectors) {
    g.write_lines(os, g.vectors, std::endian::big);
    os << '\n';
  }
  if (g.scalars) {
    os << "SCALARS jacobian double 1\nLOOKUP_TABLE default\n";
    g.write_lines(os, g.scalars, std::endian::big);
    os << '\n';
  }
}

/// VTK XML StructuredGrid (vts_head), the arrays i fastest.
void write_vts(std::ostream& os, const Structured& g) {
  const std::uint64_t n = g.size();
  os << vts_head(g.nu, g.nv, g.nw, g.vectors != nullptr, g.scalars != nullptr);
  if (g.vectors) {
    os << vts_count(24 * n);
    g.write_lines(os, g.vectors, std::endian::little);
  }
  if (g.scalars) {
    os << vts_count(8 * n);
    g.write_lines(os, g.scalars, std::endian::little);
  }
  os << vts_count(24 * n);
  g.write_lines(os, g.points, std::endian::little);
  os << vts_tail;
}

/// Plot3D's ASCII values, four to a line: value(t) for t < n, i fastest. Each is the
/// shortest text that reads back as the same double: exact, and no longer than 17
/// digits.
template <class Value>
void write_plot3d_values(std::ostream& os, std::size_t n, Value&& value) {
  write_records(os, n, 20, [&](Sink& s, std::size_t t) {
    if (t % 4 != 0) s.ch(' ');
    s.shortest(value(t));
    if (t % 4 == 3 || t + 1 == n) s.ch('\n');
  });
}

/// Plot3D grid file, ASCII, 3D, multi-grid with one grid, whole (not planes): the
/// block count, the dimensions, then every x (i fastest), every y, every z.
void write_plot3d(std::ostream& os, const Structured& g) {
  Sink(os).text("1\n").uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw).ch('\n').flush();
  for (int c = 0; c < 3; ++c) write_plot3d_values(os, g.size(), [&](std::size_t t) { return g.points[g.at(t)][c]; });
}

/// Plot3D function file (multi-grid, ASCII): the block count, "ni nj nk nvars",
/// then the values, i fastest.
void write_plot3d_function(std::ostream& os, const Structured& g) {
  Sink(os).text("1\n").uint(g.nu).ch(' ').uint(g.nv).ch(' ').uint(g.nw).text(" 1\n").flush();
  write_plot3d_values(os, g.size(), [&](std::size_t t) { return g.scalars[g.at(t)]; });
}

}  // namespace

void write_structured(const fs::path& path, const std::string& ext, const Structured& g) {
  if (ext == ".vtk") {
    write_atomically(path, [&](std::ostream& os) { write_legacy_vtk(os, g); });
  } else if (ext == ".vts") {
    write_atomically(path, [&](std::ostream& os) { write_vts(os, g); });
  } else {
    if (g.scalars) {
      // Plot3D grids hold coordinates only; fields go to a function file.
      fs::path function_path = path;
      function_path.replace_extension(".f");
      check_writable(path);
      write_atomically(function_path, [&](std::ostream& os) { write_plot3d_function(os, g); });
    }
    write_atomically(path, [&](std::ostream& os) { write_plot3d(os, g); });
  }
}

}  // namespace interpatch::io::internal::mesh_io
