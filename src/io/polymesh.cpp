// OpenFOAM's polyMesh: points, faces, owner, neighbour and boundary, ASCII, in a
// directory written whole or not at all.

#include <charconv>
#include <fstream>
#include <string>

#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/mesh.hpp"
#include "io/mesh_formats.hpp"
#include "mesh/hex_mesh.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;

namespace {

void header(std::ostream& os, const char* cls, const char* object, const std::string& note = {}) {
  os << "FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       " << cls << ";\n";
  if (!note.empty()) os << "    note        \"" << note << "\";\n";
  os << "    location    \"constant/polyMesh\";\n    object      " << object << ";\n}\n\n";
}

// The shortest text that reads back as the same double.
void put(std::ostream& os, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  os.write(buf, r.ptr - buf);
}

void write_file(const fs::path& path, const std::function<void(std::ostream&)>& body) {
  std::ofstream os(path, std::ios::binary);
  if (!os) detail::fail(errc::file_unwritable, "cannot write '", path.string(), "'");
  os.exceptions(std::ios::failbit | std::ios::badbit);
  try {
    body(os);
    os.close();
  } catch (const std::ios::failure&) {
    detail::fail(errc::file_unwritable, "cannot write '", path.string(), "': the write failed (disk full?)");
  }
}

template <class List, class Put>
void list(std::ostream& os, const List& items, Put put_item) {
  os << items.size() << "\n(\n";
  for (const auto& x : items) {
    put_item(x);
    os << '\n';
  }
  os << ")\n";
}

}  // namespace

bool is_polymesh_path(const fs::path& path) { return path.filename() == "polyMesh"; }

namespace internal::mesh_io {

void write_polymesh(const fs::path& dir, const PointGrid3& nodes) { write_polymesh(dir, mesh::structured_hex_mesh(nodes)); }

void write_polymesh(const fs::path& dir, const mesh::HexMesh& m) {
  const mesh::PolyMesh p = mesh::poly_mesh(m);
  const std::string note = detail::cat("nPoints:", m.points.size(), "  nCells:", m.cells.size(), "  nFaces:",
                                       p.faces.size(), "  nInternalFaces:", p.neighbour.size());
  write_directory_atomically(dir, [&](const fs::path& tmp) {
    write_file(tmp / "points", [&](std::ostream& os) {
      header(os, "vectorField", "points");
      list(os, m.points, [&](const Vec3& x) {
        os << '(';
        put(os, x.x);
        os << ' ';
        put(os, x.y);
        os << ' ';
        put(os, x.z);
        os << ')';
      });
    });
    write_file(tmp / "faces", [&](std::ostream& os) {
      header(os, "faceList", "faces");
      list(os, p.faces, [&](const std::array<std::uint32_t, 4>& f) {
        os << "4(" << f[0] << ' ' << f[1] << ' ' << f[2] << ' ' << f[3] << ')';
      });
    });
    write_file(tmp / "owner", [&](std::ostream& os) {
      header(os, "labelList", "owner", note);
      list(os, p.owner, [&](std::uint32_t c) { os << c; });
    });
    write_file(tmp / "neighbour", [&](std::ostream& os) {
      header(os, "labelList", "neighbour", note);
      list(os, p.neighbour, [&](std::uint32_t c) { os << c; });
    });
    write_file(tmp / "boundary", [&](std::ostream& os) {
      header(os, "polyBoundaryMesh", "boundary");
      os << p.patches.size() << "\n(\n";
      for (const mesh::Patch& b : p.patches)
        os << "    " << b.name << "\n    {\n        type            patch;\n        nFaces          " << b.size
           << ";\n        startFace       " << b.start << ";\n    }\n";
      os << ")\n";
    });
  });
}

}  // namespace internal::mesh_io

}  // namespace interpatch::io
