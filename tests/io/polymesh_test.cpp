// OpenFOAM polyMesh: the faces of hexahedral meshes checked by their geometry (every
// face once, normals out of their owners, each cell closed, upper-triangular order),
// right- and left-handed; the directory written whole, replaced whole, refused whole.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/mesh.hpp"
#include "mesh/hex_mesh.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

// A warped block of ni × nj × nk nodes; `mirror` turns it left-handed.
PointGrid3 warped(std::size_t ni, std::size_t nj, std::size_t nk, bool mirror, unsigned seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  PointGrid3 x({ni, nj, nk});
  for (std::size_t i = 0; i < ni; ++i)
    for (std::size_t j = 0; j < nj; ++j)
      for (std::size_t k = 0; k < nk; ++k) {
        const double a = static_cast<double>(i) + jitter(g), b = static_cast<double>(j) + jitter(g),
                     c = static_cast<double>(k) + jitter(g);
        // bent round the z axis a little, so that no face is flat
        const Vec3 p{(3 + a) * std::cos(0.2 * b), (3 + a) * std::sin(0.2 * b), c + 0.1 * a * b};
        x(i, j, k) = mirror ? Vec3{p.x, p.y, -p.z} : p;
      }
  return x;
}

Vec3 centre(const std::vector<Vec3>& pts, std::span<const std::uint32_t> ids) {
  Vec3 c{};
  for (std::uint32_t i : ids) c += pts[i];
  return c / static_cast<double>(ids.size());
}

// The area vector of a quadrilateral: triangles about its vertex average.
Vec3 area(const std::vector<Vec3>& pts, const std::array<std::uint32_t, 4>& f) {
  const Vec3 c = centre(pts, f);
  Vec3 a{};
  for (std::size_t e = 0; e < 4; ++e) a += 0.5 * cross(pts[f[e]] - c, pts[f[(e + 1) % 4]] - c);
  return a;
}

void check_faces(const PointGrid3& nodes, bool left_handed) {
  const auto n = nodes.shape();
  const mesh::HexMesh m = mesh::structured_hex_mesh(nodes);
  const mesh::PolyMesh p = mesh::poly_mesh(m);
  EXPECT_EQ(p.flipped, left_handed);
  const std::size_t cells = (n[0] - 1) * (n[1] - 1) * (n[2] - 1);
  ASSERT_EQ(m.cells.size(), cells);
  const std::size_t internal = (n[0] - 2) * (n[1] - 1) * (n[2] - 1) + (n[0] - 1) * (n[1] - 2) * (n[2] - 1) +
                               (n[0] - 1) * (n[1] - 1) * (n[2] - 2);
  const std::size_t boundary = 2 * ((n[1] - 1) * (n[2] - 1) + (n[0] - 1) * (n[2] - 1) + (n[0] - 1) * (n[1] - 1));
  ASSERT_EQ(p.neighbour.size(), internal);
  ASSERT_EQ(p.faces.size(), internal + boundary);
  ASSERT_EQ(p.owner.size(), p.faces.size());
  // Upper-triangular: owner below neighbour, faces by owner then neighbour.
  for (std::size_t f = 0; f < internal; ++f) {
    EXPECT_LT(p.owner[f], p.neighbour[f]) << f;
    if (f) {
      EXPECT_TRUE(p.owner[f - 1] < p.owner[f] || (p.owner[f - 1] == p.owner[f] && p.neighbour[f - 1] < p.neighbour[f]));
    }
  }
  // Every face once; every cell in six of them; every normal out of its owner; each
  // cell's outward areas summing to zero (a closed cell).
  std::set<std::array<std::uint32_t, 4>> seen;
  std::vector<int> faces_of(cells, 0);
  std::vector<Vec3> closure(cells, Vec3{});
  std::vector<Vec3> cell_centre(cells);
  for (std::size_t c = 0; c < cells; ++c) cell_centre[c] = centre(m.points, m.cells[c]);
  for (std::size_t f = 0; f < p.faces.size(); ++f) {
    auto key = p.faces[f];
    std::sort(key.begin(), key.end());
    EXPECT_TRUE(seen.insert(key).second) << "face " << f << " twice";
    const Vec3 a = area(m.points, p.faces[f]), fc = centre(m.points, p.faces[f]);
    EXPECT_GT(dot(a, fc - cell_centre[p.owner[f]]), 0) << "face " << f << " points into its owner";
    ++faces_of[p.owner[f]];
    closure[p.owner[f]] += a;
    if (f < internal) {
      EXPECT_GT(dot(a, cell_centre[p.neighbour[f]] - fc), 0) << "face " << f << " points away from its neighbour";
      ++faces_of[p.neighbour[f]];
      closure[p.neighbour[f]] -= a;
    }
  }
  for (std::size_t c = 0; c < cells; ++c) {
    EXPECT_EQ(faces_of[c], 6) << c;
    EXPECT_LT(norm(closure[c]), 1e-12) << "cell " << c << " is not closed";
  }
  // The patches: u0, u1, v0, v1, w0, w1, one after the other, each a face of the block.
  ASSERT_EQ(p.patches.size(), 6u);
  const std::size_t sizes[] = {(n[1] - 1) * (n[2] - 1), (n[0] - 1) * (n[2] - 1), (n[0] - 1) * (n[1] - 1)};
  std::size_t start = internal;
  for (std::size_t q = 0; q < 6; ++q) {
    EXPECT_EQ(p.patches[q].name, std::string(1, "uvw"[q / 2]) + char('0' + q % 2));
    EXPECT_EQ(p.patches[q].start, start);
    EXPECT_EQ(p.patches[q].size, sizes[q / 2]);
    start += p.patches[q].size;
  }
}

TEST(PolyMesh, FacesOfRightAndLeftHandedBlocks) {
  check_faces(warped(4, 5, 3, false, 1), false);
  check_faces(warped(4, 5, 3, true, 2), true);
  check_faces(warped(2, 2, 2, false, 3), false);  // one cell: six boundary faces
  check_faces(warped(7, 2, 6, true, 4), true);
}

TEST(PolyMesh, FewerThanTwoNodesIsRefused) {
  EXPECT_ERRC((void)mesh::structured_hex_mesh(PointGrid3({1, 3, 3})), size_mismatch, "at least 2 nodes");
}

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(PolyMesh, DirectoryWrittenWholeAndReplacedWhole) {
  test::TempDir dir;
  std::filesystem::create_directory(dir / "constant");
  const std::filesystem::path out = dir / "constant" / "polyMesh";
  io::write_volume_mesh(out, warped(3, 3, 3, false, 5));
  for (const char* f : {"points", "faces", "owner", "neighbour", "boundary"})
    EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;
  EXPECT_NE(read(out / "points").find("\n27\n("), std::string::npos);
  EXPECT_NE(read(out / "owner").find("nCells:8"), std::string::npos);
  // Written again, smaller: the new mesh replaces the old, nothing left beside it.
  io::write_volume_mesh(out, warped(2, 2, 2, false, 6));
  EXPECT_NE(read(out / "points").find("\n8\n("), std::string::npos);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "constant"), {}), 1);
  // A NaN node is refused before anything is written: the old mesh stays.
  PointGrid3 bad = warped(3, 3, 3, false, 7);
  bad(1, 1, 1).y = std::nan("");
  EXPECT_ERRC(io::write_volume_mesh(out, bad), not_finite, "the points of");
  EXPECT_NE(read(out / "points").find("\n8\n("), std::string::npos);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "constant"), {}), 1);
}

TEST(PolyMesh, DirectoryRefusals) {
  test::TempDir dir;
  EXPECT_ERRC(io::check_writable_directory(dir / "missing" / "polyMesh"), file_unwritable, "does not exist");
  std::ofstream(dir / "polyMesh") << "a file";
  EXPECT_ERRC(io::check_writable_directory(dir / "polyMesh"), file_unwritable, "is not a directory");
  // A writer that throws leaves nothing behind.
  std::filesystem::create_directory(dir / "case");
  EXPECT_THROW(io::write_directory_atomically(dir / "case" / "polyMesh",
                                              [](const std::filesystem::path& tmp) {
                                                std::ofstream(tmp / "points") << "half";
                                                throw std::runtime_error("stopped");
                                              }),
               std::runtime_error);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "case"), {}), 0);
}

}  // namespace
}  // namespace interpatch
