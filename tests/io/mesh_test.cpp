#include "interpatch/io/mesh.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "interpatch/bspline_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/patches.hpp"
#include "io/closed_shapes.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;

using test::TempDir;

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// --- Test data ------------------------------------------------------------------------

/// A paraboloid cap z = 1 - r^2 over three quarters of a turn, sampled at
/// nu radii (the first is 0: a pole row of identical points) and nv angles.
SurfaceMesh cap(std::size_t nu, std::size_t nv, std::size_t pole_rows = 1) {
  SurfaceMesh m;
  m.points = PointGrid({nu, nv});
  m.normals = PointGrid({nu, nv});
  for (std::size_t i = 0; i < nu; ++i) {
    const double r = i < pole_rows ? 0.0 : static_cast<double>(i) / static_cast<double>(nu - 1);
    for (std::size_t j = 0; j < nv; ++j) {
      const double t = 1.5 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(nv - 1);
      const Vec3 p = i < pole_rows ? Vec3{0, 0, 1} : Vec3{r * std::cos(t), r * std::sin(t), 1 - r * r};
      m.points(i, j) = p;
      const Vec3 n{2 * p.x, 2 * p.y, 1};
      m.normals(i, j) = n / norm(n);
    }
  }
  return m;
}

/// The faces the writers must produce, worked out here independently: vertex
/// indices in C order, a triangle for each cell touching a single pole row, no
/// face for a cell between two pole rows.
std::vector<std::vector<std::size_t>> expected_faces(std::size_t nu, std::size_t nv, std::size_t pole_rows) {
  std::vector<std::vector<std::size_t>> faces;
  for (std::size_t i = 0; i + 1 < nu; ++i)
    for (std::size_t j = 0; j + 1 < nv; ++j) {
      const std::size_t a = i * nv + j, b = (i + 1) * nv + j, c = (i + 1) * nv + j + 1, d = i * nv + j + 1;
      if (i + 1 < pole_rows) continue;
      if (i + 1 == pole_rows) faces.push_back({a, b, c});
      else faces.push_back({a, b, c, d});
    }
  return faces;
}

PointGrid3 box(std::size_t nu, std::size_t nv, std::size_t nw, Grid<double, 3>* jac) {
  PointGrid3 g({nu, nv, nw});
  if (jac) *jac = Grid<double, 3>({nu, nv, nw});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      for (std::size_t k = 0; k < nw; ++k) {
        const double u = static_cast<double>(i) / 3.0, v = static_cast<double>(j) / 7.0, w = static_cast<double>(k) / 11.0;
        g(i, j, k) = {u + 0.1 * v * w, 2 * v + std::sin(u), 3 * w + u * v};
        if (jac) (*jac)(i, j, k) = 1.0 + u - 0.5 * v + w / 3.0;
      }
  return g;
}

// --- Readers used to check the files ---------------------------------------------------

template <class T>
T get(const std::string& s, std::size_t off, std::endian order) {
  EXPECT_LE(off + sizeof(T), s.size());
  char b[sizeof(T)];
  std::memcpy(b, s.data() + std::min(off, s.size() - sizeof(T)), sizeof(T));
  if (order != std::endian::native) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}
template <class T>
T le(const std::string& s, std::size_t off) { return get<T>(s, off, std::endian::little); }
template <class T>
T be(const std::string& s, std::size_t off) { return get<T>(s, off, std::endian::big); }

double number(std::string_view s) {
  double v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  EXPECT_TRUE(r.ec == std::errc() && r.ptr == s.data() + s.size()) << "'" << s << "'";
  return v;
}

std::vector<std::string> tokens(const std::string& line, char sep = ' ') {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == sep || c == '\n' || c == '\t') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

/// Reads text lines from a position in a byte string, for headers before binary data.
class Cursor {
 public:
  explicit Cursor(const std::string& s, std::size_t pos = 0) : s_(s), pos_(pos) {}
  std::string line() {
    const auto nl = s_.find('\n', pos_);
    if (nl == std::string::npos) {
      ADD_FAILURE() << "missing line at byte " << pos_;
      pos_ = s_.size();
      return "<missing>";
    }
    std::string l = s_.substr(pos_, nl - pos_);
    pos_ = nl + 1;
    return l;
  }
  std::size_t skip(std::size_t n) {
    const std::size_t at = pos_;
    pos_ += n;
    return at;
  }
  [[nodiscard]] std::size_t pos() const { return pos_; }

 private:
  const std::string& s_;
  std::size_t pos_;
};

// --- Surface formats --------------------------------------------------------------------

/// The sizes the surface-format tests run at: a few cells, and a mesh whose lists of
/// records (vertices, normals, faces, coordinates) are each made in several blocks
/// of pieces, shared by the threads (write_records: pieces of 64 KiB, blocks of 16).
constexpr std::array<std::array<std::size_t, 2>, 2> format_sizes = {{{5, 6}, {301, 257}}};

/// The file at `path` that write() makes, written on 1, 2 and 3 threads: the same
/// bytes every time (checked here, for the file beside it too when there is one),
/// returned once.
template <class Write>
std::string written_on_every_thread_count(const fs::path& path, Write&& write) {
  fs::path beside = path;
  beside.replace_extension(".f");  // a Plot3D function file
  std::string first, first_beside;
#ifdef _OPENMP
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
  for (const int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
#else
  for (const int threads : {1}) {
#endif
    write();
    std::string bytes = read_bytes(path), bytes_beside = fs::exists(beside) ? read_bytes(beside) : "";
    if (threads == 1) {
      first = std::move(bytes);
      first_beside = std::move(bytes_beside);
    } else {
      EXPECT_TRUE(bytes == first) << path << " on " << threads << " threads is not the file of one thread";
      EXPECT_TRUE(bytes_beside == first_beside) << beside << " on " << threads << " threads";
    }
  }
#ifdef _OPENMP
  omp_set_num_threads(before);
#endif
  return first;
}

std::string written_on_every_thread_count(const fs::path& path, const SurfaceMesh& m) {
  return written_on_every_thread_count(path, [&] { write_surface_mesh(path, m); });
}


TEST(Mesh, ObjHasVerticesUvNormalsAndQuadsWithPoleTriangles) {
  TempDir dir;
  for (const auto [nu, nv] : format_sizes) {
  const SurfaceMesh m = cap(nu, nv);
  std::vector<Vec3> v, vn;
  std::vector<std::array<double, 2>> vt;
  std::vector<std::vector<std::size_t>> faces;
  for (const auto& l : lines(written_on_every_thread_count(dir / "cap.obj", m))) {
    const auto t = tokens(l);
    if (t.empty() || t[0] == "#") continue;
    if (t[0] == "v") {
      ASSERT_EQ(t.size(), 4u) << l;
      v.push_back({number(t[1]), number(t[2]), number(t[3])});
    } else if (t[0] == "vt") {
      ASSERT_EQ(t.size(), 3u) << l;
      vt.push_back({number(t[1]), number(t[2])});
    } else if (t[0] == "vn") {
      ASSERT_EQ(t.size(), 4u) << l;
      vn.push_back({number(t[1]), number(t[2]), number(t[3])});
    } else if (t[0] == "f") {
      std::vector<std::size_t> f;
      for (std::size_t k = 1; k < t.size(); ++k) {
        const auto parts = tokens(t[k], '/');
        ASSERT_EQ(parts.size(), 3u) << l;
        EXPECT_EQ(parts[0], parts[1]);
        EXPECT_EQ(parts[0], parts[2]);
        f.push_back(static_cast<std::size_t>(std::stoul(parts[0])) - 1);
      }
      faces.push_back(f);
    } else {
      ADD_FAILURE() << "unexpected OBJ line: " << l;
    }
  }
  ASSERT_EQ(v.size(), nu * nv);
  ASSERT_EQ(vt.size(), nu * nv);
  ASSERT_EQ(vn.size(), nu * nv);
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const std::size_t q = i * nv + j;
      EXPECT_EQ(v[q], m.points(i, j)) << q;  // shortest round-trip text: exact
      EXPECT_EQ(vn[q], m.normals(i, j)) << q;
      EXPECT_EQ(vt[q][0], static_cast<double>(i) / static_cast<double>(nu - 1));
      EXPECT_EQ(vt[q][1], static_cast<double>(j) / static_cast<double>(nv - 1));
    }
  EXPECT_EQ(faces, expected_faces(nu, nv, 1));
  }
}

TEST(Mesh, ObjWithoutNormalsAndFullyDegenerateCellsDropped) {
  TempDir dir;
  SurfaceMesh m = cap(5, 4, 2);  // two pole rows: the cells between them have no area
  m.normals = {};
  write_surface_mesh(dir / "cap.obj", m);
  std::vector<std::vector<std::size_t>> faces;
  std::size_t vn = 0;
  for (const auto& l : lines(read_bytes(dir / "cap.obj"))) {
    const auto t = tokens(l);
    if (!t.empty() && t[0] == "vn") ++vn;
    if (t.empty() || t[0] != "f") continue;
    std::vector<std::size_t> f;
    for (std::size_t k = 1; k < t.size(); ++k) {
      const auto parts = tokens(t[k], '/');
      ASSERT_EQ(parts.size(), 2u) << l;
      f.push_back(static_cast<std::size_t>(std::stoul(parts[0])) - 1);
    }
    faces.push_back(f);
  }
  EXPECT_EQ(vn, 0u);
  EXPECT_EQ(faces, expected_faces(5, 4, 2));
  EXPECT_EQ(faces.size(), 3u + 2u * 3u);
}

TEST(Mesh, StlIsBinaryWithOrientedUnitNormalsAndNoDegenerateTriangles) {
  TempDir dir;
  for (const auto [nu, nv] : format_sizes) {
  const SurfaceMesh m = cap(nu, nv);
  const std::string s = written_on_every_thread_count(dir / "cap.stl", m);
  ASSERT_GE(s.size(), 84u);
  const std::string header = s.substr(0, 80);
  EXPECT_NE(header.substr(0, 5), "solid");  // would read as ASCII STL
  EXPECT_NE(header.find("interpatch"), std::string::npos);
  const auto count = le<std::uint32_t>(s, 80);
  // Each quad is two triangles, each pole cell one.
  std::size_t expected = 0;
  for (const auto& f : expected_faces(nu, nv, 1)) expected += f.size() - 2;
  EXPECT_EQ(count, expected);
  ASSERT_EQ(s.size(), 84u + 50u * count);

  // Every triangle is a fan triangle of an expected face, in single precision.
  auto f32 = [&](std::size_t q) {
    const Vec3& p = m.points.data()[q];
    return Vec3{static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
  };
  std::vector<std::array<Vec3, 3>> want;
  for (const auto& f : expected_faces(nu, nv, 1))
    for (std::size_t k = 1; k + 1 < f.size(); ++k) want.push_back({f32(f[0]), f32(f[k]), f32(f[k + 1])});
  ASSERT_EQ(want.size(), count);
  for (std::size_t t = 0; t < count; ++t) {
    const std::size_t off = 84 + 50 * t;
    const Vec3 n{le<float>(s, off), le<float>(s, off + 4), le<float>(s, off + 8)};
    std::array<Vec3, 3> tri;
    for (std::size_t c = 0; c < 3; ++c)
      tri[c] = {le<float>(s, off + 12 + 12 * c), le<float>(s, off + 16 + 12 * c), le<float>(s, off + 20 + 12 * c)};
    EXPECT_EQ(tri, want[t]) << t;
    EXPECT_EQ(le<std::uint16_t>(s, off + 48), 0u);
    EXPECT_NEAR(norm(n), 1.0, 1e-6);
    const Vec3 geo = cross(tri[1] - tri[0], tri[2] - tri[0]);
    EXPECT_GT(dot(geo / norm(geo), n), 0.9999) << t;
    EXPECT_GT(n.z, 0.0) << t;  // S_u x S_v points up on this cap
  }
  }
}

TEST(Mesh, StlDropsZeroAreaTriangles) {
  TempDir dir;
  // A flat strip whose middle row is collinear with the first: the cells are
  // non-degenerate quads, but a grid folded onto a line has no area at all.
  SurfaceMesh m;
  m.points = PointGrid({3, 2});
  m.points(0, 0) = {0, 0, 0};
  m.points(0, 1) = {1, 0, 0};
  m.points(1, 0) = {2, 0, 0};
  m.points(1, 1) = {3, 0, 0};
  m.points(2, 0) = {0, 1, 0};
  m.points(2, 1) = {1, 1, 0};
  write_surface_mesh(dir / "line.stl", m);
  const std::string s = read_bytes(dir / "line.stl");
  // Cell 0 lies on the x axis: both triangles dropped. Cell 1 has area.
  EXPECT_EQ(le<std::uint32_t>(s, 80), 2u);
  EXPECT_EQ(s.size(), 84u + 100u);
}

TEST(Mesh, PlyBinaryLittleEndianWithNormalsAndFaces) {
  TempDir dir;
  for (const auto [nu, nv] : format_sizes) {
  const SurfaceMesh m = cap(nu, nv);
  const std::string s = written_on_every_thread_count(dir / "cap.ply", m);
  const auto end = s.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  std::vector<std::string> header;
  for (const auto& l : lines(s.substr(0, end + 11)))
    if (l.rfind("comment", 0) != 0) header.push_back(l);
  const auto faces = expected_faces(nu, nv, 1);
  const std::vector<std::string> want = {"ply",
                                         "format binary_little_endian 1.0",
                                         "element vertex " + std::to_string(nu * nv),
                                         "property double x",
                                         "property double y",
                                         "property double z",
                                         "property double nx",
                                         "property double ny",
                                         "property double nz",
                                         "element face " + std::to_string(faces.size()),
                                         "property list uchar int vertex_indices",
                                         "end_header"};
  EXPECT_EQ(header, want);
  std::size_t off = end + 11;
  for (std::size_t q = 0; q < nu * nv; ++q, off += 48) {
    EXPECT_EQ((Vec3{le<double>(s, off), le<double>(s, off + 8), le<double>(s, off + 16)}), m.points.data()[q]);
    EXPECT_EQ((Vec3{le<double>(s, off + 24), le<double>(s, off + 32), le<double>(s, off + 40)}), m.normals.data()[q]);
  }
  for (const auto& f : faces) {
    ASSERT_EQ(static_cast<std::size_t>(static_cast<unsigned char>(s[off])), f.size());
    ++off;
    for (std::size_t k = 0; k < f.size(); ++k, off += 4) EXPECT_EQ(le<std::int32_t>(s, off), static_cast<std::int32_t>(f[k]));
  }
  EXPECT_EQ(off, s.size());
  }
}

TEST(Mesh, PlyWithoutNormals) {
  TempDir dir;
  SurfaceMesh m = cap(3, 3);
  m.normals = {};
  write_surface_mesh(dir / "n.ply", m);
  const std::string s = read_bytes(dir / "n.ply");
  EXPECT_EQ(s.find("property double nx"), std::string::npos);
  const auto end = s.find("end_header\n") + 11;
  // 9 vertices of 24 bytes, 2 triangles (1 + 3 indices) and 2 quads (1 + 4 indices).
  EXPECT_EQ(s.size() - end, 9u * 24u + 2u * 13u + 2u * 17u);
}

/// Points (and optional 3-vector and scalar fields) of a legacy VTK structured grid.
struct VtkGrid {
  std::array<std::size_t, 3> dims{};
  std::vector<Vec3> points, normals;
  std::vector<double> scalars;
};

VtkGrid read_legacy_vtk(const std::string& s) {
  VtkGrid g;
  Cursor c(s);
  EXPECT_EQ(c.line(), "# vtk DataFile Version 3.0");
  EXPECT_NE(c.line().find("interpatch"), std::string::npos);
  EXPECT_EQ(c.line(), "BINARY");
  EXPECT_EQ(c.line(), "DATASET STRUCTURED_GRID");
  const auto d = tokens(c.line());
  EXPECT_EQ(d.size(), 4u);
  EXPECT_EQ(d[0], "DIMENSIONS");
  for (std::size_t a = 0; a < 3; ++a) g.dims[a] = std::stoul(d[a + 1]);
  const std::size_t n = g.dims[0] * g.dims[1] * g.dims[2];
  EXPECT_EQ(c.line(), "POINTS " + std::to_string(n) + " double");
  auto vectors = [&](std::vector<Vec3>& out) {
    const std::size_t at = c.skip(24 * n);
    for (std::size_t q = 0; q < n; ++q)
      out.push_back({be<double>(s, at + 24 * q), be<double>(s, at + 24 * q + 8), be<double>(s, at + 24 * q + 16)});
    EXPECT_EQ(c.line(), "");  // newline after the binary block
  };
  vectors(g.points);
  while (c.pos() < s.size()) {
    const std::string l = c.line();
    if (l.empty()) continue;
    if (l.rfind("POINT_DATA", 0) == 0) {
      EXPECT_EQ(l, "POINT_DATA " + std::to_string(n));
    } else if (l == "NORMALS normals double") {
      vectors(g.normals);
    } else if (l == "SCALARS jacobian double 1") {
      EXPECT_EQ(c.line(), "LOOKUP_TABLE default");
      const std::size_t at = c.skip(8 * n);
      for (std::size_t q = 0; q < n; ++q) g.scalars.push_back(be<double>(s, at + 8 * q));
      EXPECT_EQ(c.line(), "");
    } else {
      ADD_FAILURE() << "unexpected VTK line: " << l;
      break;
    }
  }
  return g;
}

TEST(Mesh, LegacyVtkStructuredGridBigEndianUFastest) {
  TempDir dir;
  for (const auto [nu, nv] : format_sizes) {
  const SurfaceMesh m = cap(nu, nv);
  const VtkGrid g = read_legacy_vtk(written_on_every_thread_count(dir / "cap.vtk", m));
  EXPECT_EQ(g.dims, (std::array<std::size_t, 3>{nu, nv, 1}));
  ASSERT_EQ(g.points.size(), nu * nv);
  ASSERT_EQ(g.normals.size(), nu * nv);
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i) {
      EXPECT_EQ(g.points[i + nu * j], m.points(i, j));
      EXPECT_EQ(g.normals[i + nu * j], m.normals(i, j));
    }
  EXPECT_TRUE(g.scalars.empty());
  }
}

/// Arrays of a VTK XML StructuredGrid written with raw appended data.
struct VtsGrid {
  std::array<std::size_t, 6> extent{};
  std::map<std::string, std::vector<double>> arrays;  // by Name, components interleaved
  std::map<std::string, int> components;
};

std::string attribute(const std::string& tag, const std::string& name) {
  const auto at = tag.find(" " + name + "=\"");
  if (at == std::string::npos) return {};
  const auto start = at + name.size() + 3;
  return tag.substr(start, tag.find('"', start) - start);
}

VtsGrid read_vts(const std::string& s) {
  VtsGrid g;
  EXPECT_EQ(s.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"StructuredGrid\"", 0), 0u);
  const std::string file_tag = s.substr(s.find("<VTKFile"), s.find('>', s.find("<VTKFile")) - s.find("<VTKFile"));
  EXPECT_EQ(attribute(file_tag, "byte_order"), "LittleEndian");
  EXPECT_EQ(attribute(file_tag, "header_type"), "UInt64");
  const auto grid_at = s.find("<StructuredGrid ");
  const std::string whole = attribute(s.substr(grid_at, s.find('>', grid_at) - grid_at), "WholeExtent");
  const auto piece_at = s.find("<Piece ");
  EXPECT_EQ(attribute(s.substr(piece_at, s.find('>', piece_at) - piece_at), "Extent"), whole);
  const auto e = tokens(whole);
  EXPECT_EQ(e.size(), 6u);
  for (std::size_t k = 0; k < 6 && k < e.size(); ++k) g.extent[k] = std::stoul(e[k]);
  const std::size_t n = (g.extent[1] - g.extent[0] + 1) * (g.extent[3] - g.extent[2] + 1) * (g.extent[5] - g.extent[4] + 1);
  const auto app = s.find("<AppendedData encoding=\"raw\">");
  EXPECT_NE(app, std::string::npos);
  const std::size_t base = s.find('_', app) + 1;
  for (std::size_t at = s.find("<DataArray"); at < app; at = s.find("<DataArray", at + 1)) {
    const std::string tag = s.substr(at, s.find('>', at) - at);
    EXPECT_EQ(attribute(tag, "type"), "Float64");
    EXPECT_EQ(attribute(tag, "format"), "appended");
    const std::string name = attribute(tag, "Name");
    const int comps = attribute(tag, "NumberOfComponents").empty() ? 1 : std::stoi(attribute(tag, "NumberOfComponents"));
    const std::size_t off = base + std::stoul(attribute(tag, "offset"));
    const auto bytes = le<std::uint64_t>(s, off);
    EXPECT_EQ(bytes, 8u * static_cast<std::size_t>(comps) * n) << name;
    std::vector<double> values;
    for (std::size_t k = 0; k < bytes / 8; ++k) values.push_back(le<double>(s, off + 8 + 8 * k));
    g.arrays[name] = values;
    g.components[name] = comps;
  }
  EXPECT_NE(s.find("</AppendedData>\n</VTKFile>", base), std::string::npos);
  return g;
}

TEST(Mesh, VtsAppendedRawStructuredGrid) {
  TempDir dir;
  for (const auto [nu, nv] : format_sizes) {
  const SurfaceMesh m = cap(nu, nv);
  const std::string s = written_on_every_thread_count(dir / "cap.vts", m);
  EXPECT_NE(s.find("WholeExtent=\"0 " + std::to_string(nu - 1) + " 0 " + std::to_string(nv - 1) + " 0 0\""), std::string::npos);
  const VtsGrid g = read_vts(s);
  ASSERT_EQ(g.arrays.count("Points"), 1u);
  ASSERT_EQ(g.arrays.count("Normals"), 1u);
  EXPECT_EQ(g.components.at("Points"), 3);
  const auto& p = g.arrays.at("Points");
  const auto& n = g.arrays.at("Normals");
  ASSERT_EQ(p.size(), 3 * nu * nv);
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i) {
      const std::size_t q = 3 * (i + nu * j);
      EXPECT_EQ((Vec3{p[q], p[q + 1], p[q + 2]}), m.points(i, j));
      EXPECT_EQ((Vec3{n[q], n[q + 1], n[q + 2]}), m.normals(i, j));
    }
  }
}

/// The single grid of a Plot3D ASCII multi-grid file.
struct Plot3d {
  std::array<std::size_t, 3> dims{};
  std::vector<Vec3> points;  // i fastest
};

Plot3d read_plot3d(const std::string& text) {
  const auto t = tokens(text);
  Plot3d g;
  EXPECT_GE(t.size(), 4u);
  EXPECT_EQ(t[0], "1");  // number of grids
  for (std::size_t a = 0; a < 3; ++a) g.dims[a] = std::stoul(t[1 + a]);
  const std::size_t n = g.dims[0] * g.dims[1] * g.dims[2];
  EXPECT_EQ(t.size(), 4 + 3 * n);
  if (t.size() != 4 + 3 * n) return g;
  g.points.resize(n);
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t q = 0; q < n; ++q) g.points[q][static_cast<int>(c)] = number(t[4 + c * n + q]);
  const auto first = lines(text);
  EXPECT_EQ(first[0], "1");
  EXPECT_EQ(first[1], std::to_string(g.dims[0]) + " " + std::to_string(g.dims[1]) + " " + std::to_string(g.dims[2]));
  return g;
}

TEST(Mesh, Plot3dAsciiWholeMultiGrid) {
  TempDir dir;
  for (const auto [nu, nv] : format_sizes) {
  const SurfaceMesh m = cap(nu, nv);
  const std::string text = written_on_every_thread_count(dir / "cap.xyz", m);
  const Plot3d g = read_plot3d(text);
  EXPECT_EQ(g.dims, (std::array<std::size_t, 3>{nu, nv, 1}));
  ASSERT_EQ(g.points.size(), nu * nv);
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t i = 0; i < nu; ++i) EXPECT_EQ(g.points[i + nu * j], m.points(i, j));  // shortest round-trip text: exact
  // Four values a line, each coordinate starting a line of its own.
  const auto l = lines(text);
  const std::size_t per_coordinate = (nu * nv + 3) / 4;
  ASSERT_EQ(l.size(), 2 + 3 * per_coordinate);
  for (std::size_t k = 2; k < l.size(); ++k) {
    const std::size_t in_coordinate = (k - 2) % per_coordinate;
    const std::size_t want = in_coordinate + 1 < per_coordinate || nu * nv % 4 == 0 ? 4 : nu * nv % 4;
    EXPECT_EQ(tokens(l[k]).size(), want) << "line " << k;
  }
  EXPECT_EQ(dir.count(), 1u);  // no function file without a field
  }
}

TEST(Mesh, ExtensionIsCaseInsensitive) {
  TempDir dir;
  const SurfaceMesh m = cap(3, 4);
  write_surface_mesh(dir / "CAP.OBJ", m);
  write_surface_mesh(dir / "Cap.Vtk", m);
  EXPECT_NE(read_bytes(dir / "CAP.OBJ").find("\nv "), std::string::npos);
  EXPECT_EQ(read_legacy_vtk(read_bytes(dir / "Cap.Vtk")).points.size(), 12u);
}

TEST(Mesh, LargeGridStreamsInChunks) {
  // Several megabytes per file: crosses the writers' flush threshold many times.
  TempDir dir;
  const std::size_t nu = 301, nv = 257;
  const SurfaceMesh m = cap(nu, nv);
  write_surface_mesh(dir / "big.vtk", m);
  const VtkGrid g = read_legacy_vtk(read_bytes(dir / "big.vtk"));
  ASSERT_EQ(g.points.size(), nu * nv);
  for (std::size_t j = 0; j < nv; j += 13)
    for (std::size_t i = 0; i < nu; i += 7) EXPECT_EQ(g.points[i + nu * j], m.points(i, j));
  write_surface_mesh(dir / "big.stl", m);
  const std::string s = read_bytes(dir / "big.stl");
  EXPECT_EQ(le<std::uint32_t>(s, 80), (nv - 1) + 2 * (nu - 2) * (nv - 1));
  EXPECT_EQ(s.size(), 84 + 50 * static_cast<std::size_t>(le<std::uint32_t>(s, 80)));
  write_surface_mesh(dir / "big.obj", m);
  const std::string obj = read_bytes(dir / "big.obj");
  EXPECT_EQ(static_cast<std::size_t>(std::count(obj.begin(), obj.end(), '\n')),
            1 + 3 * nu * nv + (nu - 1) * (nv - 1));
}

TEST(Mesh, SingleRowHasPointsButNoFaces) {
  TempDir dir;
  SurfaceMesh m = cap(2, 5);
  m.points = PointGrid({1, 5}, Vec3{});
  for (std::size_t j = 0; j < 5; ++j) m.points(0, j) = {static_cast<double>(j), 0, 0};
  m.normals = {};
  write_surface_mesh(dir / "row.stl", m);
  EXPECT_EQ(le<std::uint32_t>(read_bytes(dir / "row.stl"), 80), 0u);
  write_surface_mesh(dir / "row.vts", m);
  EXPECT_EQ(read_vts(read_bytes(dir / "row.vts")).arrays.at("Points").size(), 15u);
}

// --- Closed meshes ---------------------------------------------------------------------

/// An unstructured mesh as these tests read it back: vertex positions, per-vertex
/// normals (empty without), faces as vertex indices, and for OBJ each corner's
/// texture coordinate.
struct MeshRead {
  std::vector<Vec3> vertices, normals;
  std::vector<std::vector<std::size_t>> faces;
  std::vector<std::vector<std::array<double, 2>>> uv;
};

MeshRead read_obj(const std::string& text) {
  MeshRead r;
  std::vector<std::array<double, 2>> vt;
  for (const auto& l : lines(text)) {
    const auto t = tokens(l);
    if (t.empty() || t[0] == "#") continue;
    if (t[0] == "v") r.vertices.push_back({number(t[1]), number(t[2]), number(t[3])});
    if (t[0] == "vt") vt.push_back({number(t[1]), number(t[2])});
    if (t[0] == "vn") r.normals.push_back({number(t[1]), number(t[2]), number(t[3])});
    if (t[0] != "f") continue;
    std::vector<std::size_t> f;
    std::vector<std::array<double, 2>> uv;
    for (std::size_t k = 1; k < t.size(); ++k) {
      const auto parts = tokens(t[k], '/');
      EXPECT_EQ(parts.size(), r.normals.empty() ? 2u : 3u) << l;
      if (parts.size() == 3) {
        EXPECT_EQ(parts[0], parts[2]) << l;  // v and vn share the index
      }
      f.push_back(std::stoul(parts[0]) - 1);
      const std::size_t q = std::stoul(parts[1]) - 1;
      EXPECT_LT(q, vt.size()) << l;
      uv.push_back(q < vt.size() ? vt[q] : std::array<double, 2>{});
    }
    r.faces.push_back(f);
    r.uv.push_back(uv);
  }
  return r;
}

MeshRead read_ply(const std::string& s) {
  MeshRead r;
  const auto end = s.find("end_header\n");
  EXPECT_NE(end, std::string::npos);
  std::size_t nvert = 0, nface = 0;
  bool normals = false;
  for (const auto& l : lines(s.substr(0, end))) {
    const auto t = tokens(l);
    if (t.size() == 3 && t[0] == "element") (t[1] == "vertex" ? nvert : nface) = std::stoul(t[2]);
    normals = normals || l == "property double nx";
  }
  std::size_t off = end + 11;
  for (std::size_t k = 0; k < nvert; ++k) {
    r.vertices.push_back({le<double>(s, off), le<double>(s, off + 8), le<double>(s, off + 16)});
    off += 24;
    if (normals) {
      r.normals.push_back({le<double>(s, off), le<double>(s, off + 8), le<double>(s, off + 16)});
      off += 24;
    }
  }
  for (std::size_t k = 0; k < nface; ++k) {
    const std::size_t n = static_cast<unsigned char>(s[off++]);
    std::vector<std::size_t> f;
    for (std::size_t c = 0; c < n; ++c, off += 4) f.push_back(static_cast<std::size_t>(le<std::int32_t>(s, off)));
    r.faces.push_back(f);
  }
  EXPECT_EQ(off, s.size());
  return r;
}

/// STL triangles, their corners as vertices: equal floats are one vertex.
MeshRead read_stl(const std::string& s) {
  MeshRead r;
  std::map<std::array<float, 3>, std::size_t> index;
  const auto count = le<std::uint32_t>(s, 80);
  EXPECT_EQ(s.size(), 84u + 50u * count);
  for (std::size_t t = 0; t < count; ++t) {
    std::vector<std::size_t> f;
    for (std::size_t c = 0; c < 3; ++c) {
      const std::size_t off = 84 + 50 * t + 12 + 12 * c;
      const std::array<float, 3> p{le<float>(s, off), le<float>(s, off + 4), le<float>(s, off + 8)};
      const auto [it, added] = index.try_emplace(p, r.vertices.size());
      if (added) r.vertices.push_back({p[0], p[1], p[2]});
      f.push_back(it->second);
    }
    r.faces.push_back(f);
  }
  return r;
}

/// Newell's normal of a polygon: its area vector, whatever its corner count.
Vec3 polygon_normal(const MeshRead& r, const std::vector<std::size_t>& f) {
  Vec3 n{};
  for (std::size_t k = 0; k < f.size(); ++k) n = n + cross(r.vertices[f[k]], r.vertices[f[(k + 1) % f.size()]]);
  return n;
}

/// The properties every mesh of a surface closed in some directions has, written
/// from the NU × NV samples m: the vertices are the samples less the repeated last
/// row (column), no two at one place; every face index is a vertex; every inner
/// edge joins exactly two faces that run it in opposite directions (one orientation
/// throughout, the seam included), and the edges used once are those of the open
/// boundary lines only — none for a torus. `cells_are` says how many faces a cell
/// makes (1, or 2 triangles in STL).
void expect_closed_mesh(const MeshRead& r, const SurfaceMesh& m, std::size_t cells_are, const std::string& what) {
  SCOPED_TRACE(what);
  const std::size_t nu = m.points.extent(0), nv = m.points.extent(1);
  const std::size_t rows = nu - (m.closed[0] ? 1 : 0), cols = nv - (m.closed[1] ? 1 : 0);
  ASSERT_EQ(r.vertices.size(), rows * cols);
  EXPECT_EQ(r.faces.size(), cells_are * (nu - 1) * (nv - 1));
  // Doubled seam vertices would be copies or differ by rounding (~1e-15 of the
  // size); distinct samples of these meshes lie 1e-2 of it apart or more.
  const double close = 1e-9 * test::bbox_diagonal(m.points.values());
  for (std::size_t a = 0; a < r.vertices.size(); ++a)
    for (std::size_t b = a + 1; b < r.vertices.size(); ++b)
      EXPECT_GT(norm(r.vertices[a] - r.vertices[b]), close) << "vertices " << a << " and " << b;
  std::map<std::pair<std::size_t, std::size_t>, int> directed;
  for (const auto& f : r.faces)
    for (std::size_t k = 0; k < f.size(); ++k) {
      ASSERT_LT(f[k], r.vertices.size());
      ++directed[{f[k], f[(k + 1) % f.size()]}];
    }
  std::size_t boundary = 0;
  for (const auto& [e, n] : directed) {
    EXPECT_EQ(n, 1) << "edge " << e.first << " -> " << e.second << " run " << n << " times the same way";
    boundary += directed.count({e.second, e.first}) == 0;
  }
  EXPECT_EQ(boundary, (m.closed[0] ? 0 : 2 * (nv - 1)) + (m.closed[1] ? 0 : 2 * (nu - 1)));
}

/// Each vertex keeps the point and normal of its sample (the first row's on the
/// seam), and every face turns the way its vertices' normals point.
void expect_vertex_normals(const MeshRead& r, const SurfaceMesh& m, const std::string& what) {
  SCOPED_TRACE(what);
  const std::size_t cols = m.points.extent(1) - (m.closed[1] ? 1 : 0);
  ASSERT_EQ(r.normals.size(), r.vertices.size());
  for (std::size_t k = 0; k < r.vertices.size(); ++k) {
    EXPECT_EQ(r.vertices[k], m.points(k / cols, k % cols)) << k;
    EXPECT_EQ(r.normals[k], m.normals(k / cols, k % cols)) << k;
  }
  for (const auto& f : r.faces) {
    const Vec3 n = polygon_normal(r, f);
    for (const std::size_t q : f) EXPECT_GT(dot(n, r.normals[q]), 0) << "a face turned against vertex " << q;
  }
}

std::vector<std::pair<std::string, SurfaceMesh>> closed_meshes() {
  std::vector<std::pair<std::string, SurfaceMesh>> out;
  const std::array<bool, 2> directions[] = {{true, false}, {false, true}, {true, true}};
  // Five samples or more about every closed direction: coarser, a face across a third
  // of a turn may lean away from its corners' normals for reasons the seam has no part in.
  const std::array<std::size_t, 2> sizes[] = {{5, 6}, {8, 7}, {13, 10}};
  for (const auto& periodic : directions)
    for (unsigned seed = 1; seed <= 3; ++seed)
      for (const auto& [nu, nv] : sizes) {
        const BSplineSurface s = test::closed_surface(periodic, seed);
        const auto [u0, u1] = s.domain_u();
        const auto [v0, v1] = s.domain_v();
        SurfaceMesh m = sample_mesh(s, linspace(u0, u1, nu), linspace(v0, v1, nv));
        EXPECT_EQ(m.closed, periodic);
        out.push_back({std::string(periodic[0] ? "u" : "") + (periodic[1] ? "v" : "") + " seed " +
                           std::to_string(seed) + " " + std::to_string(nu) + "x" + std::to_string(nv),
                       std::move(m)});
      }
  return out;
}

TEST(Mesh, ClosedSurfaceObjAndPlyShareTheSeamVertices) {
  TempDir dir;
  for (const auto& [what, m] : closed_meshes()) {
    for (const char* name : {"closed.obj", "closed.ply"}) {
      write_surface_mesh(dir / name, m);
      const std::string bytes = read_bytes(dir / name);
      const MeshRead r = fs::path(name).extension() == ".obj" ? read_obj(bytes) : read_ply(bytes);
      expect_closed_mesh(r, m, 1, what + " " + name);
      expect_vertex_normals(r, m, what + " " + name);
    }
    // OBJ's texture coordinates stay one per sample: no face spans more than one
    // cell of them, those across the seam included.
    const MeshRead r = read_obj(read_bytes(dir / "closed.obj"));
    const double du = 1.0 / static_cast<double>(m.points.extent(0) - 1);
    const double dv = 1.0 / static_cast<double>(m.points.extent(1) - 1);
    for (const auto& uv : r.uv)
      for (const auto& a : uv)
        for (const auto& b : uv) {
          EXPECT_LE(std::abs(a[0] - b[0]), du * (1 + 1e-12)) << what;  // 1e-12: the quotient's rounding
          EXPECT_LE(std::abs(a[1] - b[1]), dv * (1 + 1e-12)) << what;
        }
  }
}

/// The mesh with every seam sample's x on the far side of a float rounding boundary
/// from the first row's (column's) x, a few 1e-15 away: rounding in evaluating the
/// two ends of a period can leave them so.
SurfaceMesh straddling_floats(SurfaceMesh m) {
  const std::size_t nu = m.points.extent(0), nv = m.points.extent(1);
  const std::size_t rows = nu - (m.closed[0] ? 1 : 0), cols = nv - (m.closed[1] ? 1 : 0);
  const auto midpoint = [](double x) {  // halfway between float(x) and the next float up
    const float f = static_cast<float>(x);
    return 0.5 * (static_cast<double>(f) + static_cast<double>(std::nextafter(f, HUGE_VALF)));
  };
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t j = 0; j < cols; ++j) {
      const double mid = midpoint(m.points(i, j).x);
      m.points(i, j).x = mid - 1e-15 * std::abs(mid);
    }
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      if (i < rows && j < cols) continue;
      const double mid = midpoint(m.points(i % rows, j % cols).x);
      m.points(i, j).x = mid + 1e-15 * std::abs(mid);
      EXPECT_NE(static_cast<float>(m.points(i, j).x), static_cast<float>(m.points(i % rows, j % cols).x));
    }
  return m;
}

// STL has no shared vertices, only coordinates: the seam's triangles on both sides
// carry the first row's floats, so a torus is watertight edge for edge even where
// the last row's own coordinates would round to other floats.
TEST(Mesh, ClosedSurfaceStlIsWatertightAcrossTheSeam) {
  TempDir dir;
  for (const auto& [what, m] : closed_meshes()) {
    write_surface_mesh(dir / "closed.stl", m);
    expect_closed_mesh(read_stl(read_bytes(dir / "closed.stl")), m, 2, what);
    write_surface_mesh(dir / "straddling.stl", straddling_floats(m));
    expect_closed_mesh(read_stl(read_bytes(dir / "straddling.stl")), m, 2, what + ", seam straddling floats");
  }
}

// The structured formats keep the doubled row: a structured grid needs it.
// Binary STL holds float32. A part far from the origin for its size loses its shape
// there: the writer warns exactly when the file's points, read back, are further than
// 1e-5 of the mesh's diagonal from the mesh's, and says by how much.
TEST(Mesh, StlWarnsWhereFloat32MovesThePointsOfAFarPart) {
  TempDir dir;
  auto g = test::rng(29);
  int warned = 0, quiet = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const double size = std::pow(10.0, test::uniform(g, -3, 3));
    const double offset = trial % 3 == 0 ? 0.0 : size * std::pow(10.0, test::uniform(g, 0, 9));
    SurfaceMesh m{PointGrid({5, 4}), {}};
    for (Vec3& p : m.points.values())
      p = Vec3{offset, 2 * offset, -offset} + Vec3{test::uniform(g, -1, 1), test::uniform(g, -1, 1), test::uniform(g, -1, 1)} * size;
    const std::vector<std::string> warnings = write_surface_mesh(dir / "part.stl", m);
    // Measured on the file: each vertex against the nearest of the mesh's points.
    const MeshRead r = read_stl(read_bytes(dir / "part.stl"));
    double moved = 0;
    for (const Vec3& v : r.vertices) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Vec3& p : m.points.values())
        nearest = std::min(nearest, std::max({std::abs(v.x - p.x), std::abs(v.y - p.y), std::abs(v.z - p.z)}));
      moved = std::max(moved, nearest);
    }
    Vec3 lo = m.points.values()[0], hi = lo;
    for (const Vec3& p : m.points.values())
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    const double ratio = moved / norm(hi - lo);
    // Within a factor 2 of the limit the nearest point may not be the vertex's own.
    if (ratio > 0.5e-5 && ratio < 2e-5) continue;
    SCOPED_TRACE(testing::Message() << "size " << size << " offset " << offset << " moved " << ratio << " of the diagonal");
    if (ratio > 1e-5) {
      ++warned;
      ASSERT_EQ(warnings.size(), 1u);
      EXPECT_NE(warnings[0].find("float32"), std::string::npos) << warnings[0];
      EXPECT_NE(warnings[0].find("part.stl"), std::string::npos) << warnings[0];
    } else {
      ++quiet;
      EXPECT_TRUE(warnings.empty()) << warnings[0];
    }
    // Formats of doubles never warn.
    EXPECT_TRUE(write_surface_mesh(dir / "part.ply", m).empty());
  }
  EXPECT_GT(warned, 10);
  EXPECT_GT(quiet, 10);
}

TEST(Mesh, ClosedSurfaceStructuredGridKeepsEverySample) {
  TempDir dir;
  const BSplineSurface s = test::closed_surface({true, true}, 4);
  const SurfaceMesh m = sample_mesh(s, linspace(0, 1, 6), linspace(0.5, 2.5, 5));
  ASSERT_EQ(m.closed, (std::array{true, true}));
  write_surface_mesh(dir / "torus.vtk", m);
  const VtkGrid g = read_legacy_vtk(read_bytes(dir / "torus.vtk"));
  EXPECT_EQ(g.dims, (std::array<std::size_t, 3>{6, 5, 1}));
  ASSERT_EQ(g.points.size(), 30u);
  for (std::size_t j = 0; j < 5; ++j) EXPECT_EQ(g.points[5 + 6 * j], g.points[6 * j]) << j;
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(g.points[i + 6 * 4], g.points[i]) << i;
}

// sample_mesh closes a direction exactly when the surface is periodic there and the
// samples span one whole period (wherever it starts); the last row is then a copy of
// the first, points and normals.
TEST(Mesh, SampleMeshClosesWhereTheSamplesSpanAPeriod) {
  const BSplineSurface torus = test::closed_surface({true, true}, 6);
  const BSplineSurface pipe = test::closed_surface({false, true}, 6);
  struct Case {
    const BSplineSurface* s;
    double u0, u1, v0, v1;
    std::array<bool, 2> closed;
  };
  const Case cases[] = {{&torus, 0, 1, 0.5, 2.5, {true, true}},   {&torus, 0.3, 1.3, 0.5, 2.5, {true, true}},
                        {&torus, 1, 0, 2.5, 0.5, {true, true}},   {&torus, 0, 0.5, 0.5, 2.5, {false, true}},
                        {&torus, 0, 1, 0.5, 2.0, {true, false}},  {&pipe, 0, 1, 0.5, 2.5, {false, true}},
                        {&pipe, 0, 1, 1.0, 3.0, {false, true}}};
  for (const Case& c : cases) {
    const std::size_t nu = 5, nv = 6;
    const SurfaceMesh m = sample_mesh(*c.s, linspace(c.u0, c.u1, nu), linspace(c.v0, c.v1, nv));
    EXPECT_EQ(m.closed, c.closed) << c.u0 << ".." << c.u1 << " x " << c.v0 << ".." << c.v1;
    for (std::size_t j = 0; c.closed[0] && j < nv; ++j) {
      EXPECT_EQ(m.points(nu - 1, j), m.points(0, j));
      EXPECT_EQ(m.normals(nu - 1, j), m.normals(0, j));
    }
    for (std::size_t i = 0; c.closed[1] && i < nu; ++i) {
      EXPECT_EQ(m.points(i, nv - 1), m.points(i, 0));
      EXPECT_EQ(m.normals(i, nv - 1), m.normals(i, 0));
    }
  }
}

// write_surface_mesh from the surface writes a .vts or a legacy .vtk a block of
// columns at a time on every thread; its bytes are those of the mesh sampled whole
// and written: closed in u, v or both (the seam copied into the right blocks), a pole
// row, a blended surface; one block, several with a short last one, a single row or
// column; 1, 2 and 3 threads. The other formats go through sample_mesh.
TEST(Mesh, SurfaceVtsWrittenByBlocksHasTheBytesOfTheWholeMesh) {
  TempDir dir;
  const BSplineSurface torus = test::closed_surface({true, true}, 8);
  const BSplineSurface pipe = test::closed_surface({false, true}, 9, true);
  const BSplineSurface ring = test::closed_surface({true, false}, 10);
  const BlendedSurface pole = bilinear({0, 0, 0}, {0, 0, 0}, {1, 0, 0.5}, {1, 1, 0});  // the row u = 0 is a point
  struct Case {
    const Surface* s;
    double u0, u1, v0, v1;
    std::size_t nu, nv;
  };
  const Case cases[] = {{&torus, 0, 1, 0.5, 2.5, 1000, 70},  {&torus, 0.3, 1.3, 0.5, 2.5, 7, 13000},
                        {&pipe, 0, 1, 0.5, 2.5, 301, 299},   {&ring, 0, 1, 0.5, 2.5, 5, 6},
                        {&pole, 0, 1, 0, 1, 333, 401},       {&pole, 0, 1, 0, 1, 1, 5},
                        {&pole, 0, 1, 0, 1, 5, 1},           {&torus, 0, 1, 0.5, 2.5, 70000, 2}};
#ifdef _OPENMP
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
#endif
  for (const Case& c : cases) {
    const auto us = linspace(c.u0, c.u1, c.nu), vs = linspace(c.v0, c.v1, c.nv);
    for (const std::string ext : {".vts", ".vtk"}) {
      write_surface_mesh(dir / ("whole" + ext), sample_mesh(*c.s, us, vs));
      const std::string want = read_bytes(dir / ("whole" + ext));
      for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
        omp_set_num_threads(threads);
#endif
        write_surface_mesh(dir / ("blocks" + ext), *c.s, us, vs);
        EXPECT_TRUE(read_bytes(dir / ("blocks" + ext)) == want) << ext << ", " << c.nu << " x " << c.nv << ", " << threads << " threads";
      }
    }
    write_surface_mesh(dir / "m.obj", *c.s, us, vs);
    write_surface_mesh(dir / "whole.obj", sample_mesh(*c.s, us, vs));
    EXPECT_TRUE(read_bytes(dir / "m.obj") == read_bytes(dir / "whole.obj")) << c.nu << " x " << c.nv;
  }
#ifdef _OPENMP
  omp_set_num_threads(before);
#endif
  EXPECT_ERRC(write_surface_mesh(dir / "m.vts", pole, std::vector<double>{0, 1.5}, std::vector<double>{0, 1}),
              out_of_domain, "");
  EXPECT_ERRC(write_surface_mesh(dir / "m.vtk", pole, std::vector<double>{0, 1.5}, std::vector<double>{0, 1}),
              out_of_domain, "");
  EXPECT_FALSE(fs::exists(dir / "m.vtk"));
  EXPECT_ERRC(write_surface_mesh(dir / "m.dat", pole, std::vector<double>{0, 1}, std::vector<double>{0, 1}), wrong_type,
              "unknown surface mesh format '.dat'");
  EXPECT_ERRC(write_surface_mesh(dir / "m.vts", pole, std::vector<double>{}, std::vector<double>{0, 1}), size_mismatch,
              "no points");
  EXPECT_FALSE(fs::exists(dir / "m.vts"));
}

TEST(Mesh, ClosedMeshWhoseLastRowIsNotTheFirstIsRefused) {
  TempDir dir;
  SurfaceMesh m = sample_mesh(test::closed_surface({true, true}, 7), linspace(0, 1, 5), linspace(0.5, 2.5, 6));
  m.points(4, 2) = m.points(4, 2) + Vec3{0, 0, 1e-3};
  for (const char* name : {"m.obj", "m.ply", "m.stl", "m.vtk"})
    EXPECT_ERRC(write_surface_mesh(dir / name, m), closing_gap, "closed in u but its last row does not repeat the first: point [4][2]");
  m = sample_mesh(test::closed_surface({true, true}, 7), linspace(0, 1, 5), linspace(0.5, 2.5, 6));
  m.points(1, 5) = m.points(1, 5) + Vec3{1e-3, 0, 0};
  EXPECT_ERRC(write_surface_mesh(dir / "m.obj", m), closing_gap, "closed in v but its last column does not repeat the first: point [1][5]");
  SurfaceMesh line = cap(3, 1);
  line.closed = {false, true};
  EXPECT_ERRC(write_surface_mesh(dir / "m.obj", line), size_mismatch, "closed in v needs 2 columns or more");
  EXPECT_EQ(dir.count(), 0u);
}

// --- Volumes -------------------------------------------------------------------------

TEST(Mesh, VolumeLegacyVtkWithJacobian) {
  TempDir dir;
  Grid<double, 3> jac;
  const PointGrid3 g = box(3, 4, 5, &jac);
  write_volume_mesh(dir / "box.vtk", g, jac);
  const VtkGrid v = read_legacy_vtk(read_bytes(dir / "box.vtk"));
  EXPECT_EQ(v.dims, (std::array<std::size_t, 3>{3, 4, 5}));
  ASSERT_EQ(v.points.size(), 60u);
  ASSERT_EQ(v.scalars.size(), 60u);
  EXPECT_TRUE(v.normals.empty());
  for (std::size_t k = 0; k < 5; ++k)
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(v.points[i + 3 * (j + 4 * k)], g(i, j, k));
        EXPECT_EQ(v.scalars[i + 3 * (j + 4 * k)], jac(i, j, k));
      }
  // Without the field, no POINT_DATA section.
  write_volume_mesh(dir / "plain.vtk", g);
  EXPECT_EQ(read_bytes(dir / "plain.vtk").find("POINT_DATA"), std::string::npos);
}

TEST(Mesh, VolumeVtsWithJacobian) {
  TempDir dir;
  Grid<double, 3> jac;
  const PointGrid3 g = box(3, 4, 5, &jac);
  write_volume_mesh(dir / "box.vts", g, jac);
  const std::string s = read_bytes(dir / "box.vts");
  EXPECT_NE(s.find("WholeExtent=\"0 2 0 3 0 4\""), std::string::npos);
  EXPECT_NE(s.find("Scalars=\"jacobian\""), std::string::npos);
  const VtsGrid v = read_vts(s);
  ASSERT_EQ(v.arrays.count("jacobian"), 1u);
  EXPECT_EQ(v.arrays.count("Normals"), 0u);
  const auto& p = v.arrays.at("Points");
  const auto& d = v.arrays.at("jacobian");
  for (std::size_t k = 0; k < 5; ++k)
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t i = 0; i < 3; ++i) {
        const std::size_t q = i + 3 * (j + 4 * k);
        EXPECT_EQ((Vec3{p[3 * q], p[3 * q + 1], p[3 * q + 2]}), g(i, j, k));
        EXPECT_EQ(d[q], jac(i, j, k));
      }
}

TEST(Mesh, VolumePlot3dWithFunctionFile) {
  TempDir dir;
  Grid<double, 3> jac;
  const PointGrid3 g = box(3, 4, 5, &jac);
  write_volume_mesh(dir / "box.xyz", g, jac);
  const Plot3d v = read_plot3d(read_bytes(dir / "box.xyz"));
  EXPECT_EQ(v.dims, (std::array<std::size_t, 3>{3, 4, 5}));
  for (std::size_t k = 0; k < 5; ++k)
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(v.points[i + 3 * (j + 4 * k)], g(i, j, k));
  // The jacobian goes to the Plot3D function file beside the grid.
  const auto f = tokens(read_bytes(dir / "box.f"));
  ASSERT_EQ(f.size(), 5u + 60u);
  EXPECT_EQ(f[0], "1");
  EXPECT_EQ(f[1] + " " + f[2] + " " + f[3] + " " + f[4], "3 4 5 1");
  for (std::size_t k = 0; k < 5; ++k)
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(number(f[5 + i + 3 * (j + 4 * k)]), jac(i, j, k));
}

// A volume grid whose lines along i (the files' records) are made in several blocks:
// every point and value in place, the same bytes on 1, 2 and 3 threads.
TEST(Mesh, LargeVolumeGridsOnEveryThreadCount) {
  TempDir dir;
  const std::size_t nu = 61, nv = 53, nw = 47;
  Grid<double, 3> jac;
  const PointGrid3 g = box(nu, nv, nw, &jac);
  const auto at = [&](std::size_t i, std::size_t j, std::size_t k) { return i + nu * (j + nv * k); };
  const auto write = [&](const char* name) {
    return written_on_every_thread_count(dir / name, [&] { write_volume_mesh(dir / name, g, jac); });
  };
  const VtkGrid vtk = read_legacy_vtk(write("box.vtk"));
  const VtsGrid vts = read_vts(write("box.vts"));
  const Plot3d xyz = read_plot3d(write("box.xyz"));
  const auto f = tokens(read_bytes(dir / "box.f"));
  ASSERT_EQ(vtk.points.size(), nu * nv * nw);
  ASSERT_EQ(vtk.scalars.size(), nu * nv * nw);
  ASSERT_EQ(vts.arrays.at("Points").size(), 3 * nu * nv * nw);
  ASSERT_EQ(vts.arrays.at("jacobian").size(), nu * nv * nw);
  ASSERT_EQ(xyz.points.size(), nu * nv * nw);
  ASSERT_EQ(f.size(), 5 + nu * nv * nw);
  const auto& p = vts.arrays.at("Points");
  std::size_t wrong = 0;  // counted, not reported point by point: 150 000 points
  for (std::size_t k = 0; k < nw; ++k)
    for (std::size_t j = 0; j < nv; ++j)
      for (std::size_t i = 0; i < nu; ++i) {
        const std::size_t q = at(i, j, k);
        wrong += vtk.points[q] != g(i, j, k) || vtk.scalars[q] != jac(i, j, k) ||
                 (Vec3{p[3 * q], p[3 * q + 1], p[3 * q + 2]}) != g(i, j, k) ||
                 vts.arrays.at("jacobian")[q] != jac(i, j, k) || xyz.points[q] != g(i, j, k) ||
                 number(f[5 + q]) != jac(i, j, k);
      }
  EXPECT_EQ(wrong, 0u);
}

// --- Errors -------------------------------------------------------------------------

TEST(Mesh, UnknownExtensionIsWrongType) {
  TempDir dir;
  const SurfaceMesh m = cap(3, 3);
  EXPECT_ERRC(write_surface_mesh(dir / "m.foo", m), wrong_type,
              "unknown surface mesh format '.foo' (supported: .obj, .stl, .ply, .vtk, .vts, .xyz)");
  EXPECT_ERRC(write_surface_mesh(dir / "m", m), wrong_type, "no extension");
  const PointGrid3 g = box(2, 2, 2, nullptr);
  EXPECT_ERRC(write_volume_mesh(dir / "v.obj", g), wrong_type, "'.obj' holds surfaces, not volume grids");
  EXPECT_ERRC(write_volume_mesh(dir / "v.npy", g), wrong_type, "'.npy' (supported: .vtk, .vts, .xyz, .vtu, .msh)");
  EXPECT_EQ(dir.count(), 0u);
}

TEST(Mesh, IsMeshFormat) {
  for (const char* e : {".obj", ".stl", ".ply", ".vtk", ".vts", ".xyz", "obj", ".OBJ", "Vts"}) EXPECT_TRUE(is_mesh_format(e)) << e;
  for (const char* e : {".npy", ".csv", ".json", "", ".", ".objx", ".step"}) EXPECT_FALSE(is_mesh_format(e)) << e;
}

TEST(Mesh, ShapeMismatchesAreRefused) {
  TempDir dir;
  SurfaceMesh m = cap(3, 4);
  m.normals = PointGrid({4, 3});
  EXPECT_ERRC(write_surface_mesh(dir / "m.obj", m), size_mismatch, "4 x 3 normals for 3 x 4 points");
  EXPECT_ERRC(write_surface_mesh(dir / "e.obj", SurfaceMesh{}), size_mismatch, "no points");
  Grid<double, 3> jac({2, 2, 3});
  const PointGrid3 g = box(2, 2, 2, nullptr);
  EXPECT_ERRC(write_volume_mesh(dir / "v.vtk", g, jac), size_mismatch, "jacobian of shape 2 x 2 x 3 for 2 x 2 x 2 points");
  EXPECT_ERRC(write_volume_mesh(dir / "v.vtk", PointGrid3{}), size_mismatch, "no points");
  EXPECT_EQ(dir.count(), 0u);
}

TEST(Mesh, UnwritablePath) {
  TempDir dir;
  const SurfaceMesh m = cap(3, 3);
  EXPECT_ERRC(write_surface_mesh(dir / "missing" / "m.stl", m), file_unwritable, "does not exist");
  Grid<double, 3> jac;
  const PointGrid3 g = box(2, 2, 2, &jac);
  EXPECT_ERRC(write_volume_mesh(dir / "missing" / "v.xyz", g, jac), file_unwritable, "does not exist");
  EXPECT_FALSE(fs::exists(dir / "missing"));
}

}  // namespace
}  // namespace interpatch::io
