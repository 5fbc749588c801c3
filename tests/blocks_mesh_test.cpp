// Blocks merged into one hexahedral mesh: boxes of a lattice, each block's nodes
// numbered along its own axes in any of the 48 ways (turned, mirrored), must give
// the mesh of the whole lattice: its distinct points counted by coordinates here,
// every cell right-handed by its own corners, faces inside matched in pairs. And the
// refusals: counts that differ, faces apart, faces that nearly meet.

#include "mesh/blocks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "interpatch/error.hpp"
#include "mesh/hex_mesh.hpp"

namespace interpatch::mesh {
namespace {

// The lattice box [lo, lo + cells) (unit spacing) as a block whose index axes are the
// world axes permuted by `perm` and reversed where `flip` says.
PointGrid3 box(std::array<int, 3> lo, std::array<std::size_t, 3> cells, std::array<int, 3> perm = {0, 1, 2},
               std::array<bool, 3> flip = {false, false, false}) {
  std::array<std::size_t, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = cells[static_cast<std::size_t>(perm[a])] + 1;
  PointGrid3 g(n);
  for (std::size_t i = 0; i < n[0]; ++i)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t k = 0; k < n[2]; ++k) {
        const std::size_t idx[3] = {i, j, k};
        double x[3] = {0, 0, 0};
        for (int a = 0; a < 3; ++a) {
          const auto w = static_cast<std::size_t>(perm[a]);
          const std::size_t t = flip[a] ? n[a] - 1 - idx[a] : idx[a];
          x[w] = lo[w] + static_cast<double>(t);
        }
        g(i, j, k) = {x[0], x[1], x[2]};
      }
  return g;
}

std::vector<std::array<std::string, 6>> default_patches(std::size_t blocks) {
  std::vector<std::array<std::string, 6>> p(blocks);
  for (std::size_t b = 0; b < blocks; ++b)
    for (std::size_t f = 0; f < 6; ++f) p[b][f] = "block" + std::to_string(b) + "_" + block_face_names[f];
  return p;
}

std::size_t distinct_points(const std::vector<PointGrid3>& blocks) {
  std::set<std::array<long, 3>> s;
  for (const PointGrid3& g : blocks)
    for (std::size_t i = 0; i < g.size(); ++i) {
      const Vec3& p = g.data()[i];
      s.insert({std::lround(p.x), std::lround(p.y), std::lround(p.z)});
    }
  return s.size();
}

// Every cell right-handed: det J at each corner, from the VTK order's edges.
void expect_right_handed(const HexMesh& m) {
  static constexpr int next[8][3] = {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}};
  for (std::size_t c = 0; c < m.cells.size(); ++c)
    for (int n = 0; n < 8; ++n) {
      const Vec3 o = m.points[m.cells[c][n]];
      const Vec3 a = m.points[m.cells[c][next[n][0]]] - o, b = m.points[m.cells[c][next[n][1]]] - o,
                 d = m.points[m.cells[c][next[n][2]]] - o;
      ASSERT_GT(dot(cross(a, b), d), 0) << "cell " << c << " corner " << n;
    }
}

TEST(Blocks, TwoBoxesInEveryOrientationMergeIntoTheLattice) {
  std::mt19937_64 rng(34);
  std::array<int, 3> perm{0, 1, 2};
  std::size_t reference_faces = 0;
  for (int trial = 0; trial < 48; ++trial) {
    std::shuffle(perm.begin(), perm.end(), rng);
    const std::array<bool, 3> flip{(trial & 1) != 0, (trial & 2) != 0, (trial & 4) != 0};
    const std::vector<PointGrid3> blocks{box({0, 0, 0}, {3, 4, 5}), box({3, 0, 0}, {2, 4, 5}, perm, flip)};
    const std::vector<SharedFace> shared = shared_faces(blocks, 1e-9);
    ASSERT_EQ(shared.size(), 1u) << trial;
    EXPECT_EQ(shared[0].face[0], 1) << trial;  // block 0's u1
    EXPECT_EQ(shared[0].gap, 0) << trial;
    const HexMesh m = merge_blocks(blocks, shared, default_patches(2));
    EXPECT_EQ(m.points.size(), distinct_points(blocks)) << trial;
    EXPECT_EQ(m.cells.size(), 3u * 4 * 5 + 2u * 4 * 5) << trial;
    expect_right_handed(m);
    const PolyMesh p = poly_mesh(m);
    EXPECT_FALSE(p.flipped);
    // Faces inside the 5 x 4 x 5 lattice of cells: 4 * 4 * 5 + 5 * 3 * 5 + 5 * 4 * 4.
    EXPECT_EQ(p.neighbour.size(), 4u * 4 * 5 + 5u * 3 * 5 + 5u * 4 * 4) << trial;
    EXPECT_EQ(m.patch_names.size(), 10u) << trial;  // 5 outer faces a block
    if (trial == 0) reference_faces = p.faces.size();
    EXPECT_EQ(p.faces.size(), reference_faces) << trial;
  }
}

TEST(Blocks, FourBlocksAroundAnEdgeShareItsNodes) {
  const std::vector<PointGrid3> blocks{box({0, 0, 0}, {2, 2, 3}), box({2, 0, 0}, {3, 2, 3}, {1, 0, 2}),
                                       box({0, 2, 0}, {2, 1, 3}, {0, 1, 2}, {true, false, true}),
                                       box({2, 2, 0}, {3, 1, 3}, {2, 1, 0})};
  const std::vector<SharedFace> shared = shared_faces(blocks, 1e-9);
  EXPECT_EQ(shared.size(), 4u);
  const HexMesh m = merge_blocks(blocks, shared, default_patches(4));
  EXPECT_EQ(m.points.size(), distinct_points(blocks));  // (5 + 1) * (3 + 1) * (3 + 1)
  EXPECT_EQ(m.points.size(), 6u * 4 * 4);
  expect_right_handed(m);
  const PolyMesh p = poly_mesh(m);
  EXPECT_EQ(p.neighbour.size(), 4u * 3 * 3 + 5u * 2 * 3 + 5u * 3 * 2);
}

TEST(Blocks, PatchesNamedTogetherAreOne) {
  const std::vector<PointGrid3> blocks{box({0, 0, 0}, {1, 1, 1}), box({1, 0, 0}, {1, 1, 1})};
  auto names = default_patches(2);
  for (auto& b : names)
    for (std::size_t f = 2; f < 6; ++f) b[f] = "walls";
  const HexMesh m = merge_blocks(blocks, shared_faces(blocks, 1e-9), names);
  EXPECT_EQ(m.patch_names, (std::vector<std::string>{"block0_u0", "walls", "block1_u1"}));
  const PolyMesh p = poly_mesh(m);
  ASSERT_EQ(p.patches.size(), 3u);
  EXPECT_EQ(p.patches[1].size, 8u);
}

std::string refusal(const std::vector<PointGrid3>& blocks) {
  try {
    (void)shared_faces(blocks, 1e-9);
  } catch (const error& e) {
    EXPECT_EQ(e.code(), errc::block_mismatch) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

TEST(Blocks, Refusals) {
  // The same face, with 4 nodes along y where the other has 3.
  PointGrid3 finer({3, 4, 3});
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t k = 0; k < 3; ++k)
        finer(i, j, k) = {2.0 + static_cast<double>(i), static_cast<double>(j) * 2 / 3, static_cast<double>(k)};
  std::string m = refusal({box({0, 0, 0}, {2, 2, 2}), finer});
  EXPECT_NE(m.find("block 0 face u1 (3 x 3 nodes) and block 1 face u0 (4 x 3 nodes) meet at their corners but their "
                   "node counts differ"),
            std::string::npos)
      << m;
  // A node of the shared face pushed off it.
  std::vector<PointGrid3> pushed{box({0, 0, 0}, {2, 2, 2}), box({2, 0, 0}, {2, 2, 2})};
  pushed[1](0, 1, 1) = {2.01, 1, 1};
  m = refusal(pushed);
  EXPECT_NE(m.find("block 0 face u1 and block 1 face u0 meet at their corners but not along the face"),
            std::string::npos) << m;
  EXPECT_NE(m.find("0.01 apart"), std::string::npos) << m;
  // A block moved by a little: nearly meeting is a mistake, not two separate blocks.
  std::vector<PointGrid3> moved{box({0, 0, 0}, {2, 2, 2}), box({2, 0, 0}, {2, 2, 2})};
  for (std::size_t i = 0; i < moved[1].size(); ++i) moved[1].data()[i].x += 1e-3;
  m = refusal(moved);
  EXPECT_NE(m.find("nearly meet: their corners are up to 0.001"), std::string::npos) << m;
  // Far apart, or meeting along an edge only: nothing shared, nothing refused.
  EXPECT_TRUE(shared_faces(std::vector<PointGrid3>{box({0, 0, 0}, {1, 1, 1}), box({1, 1, 0}, {1, 1, 1})}, 1e-9).empty());
  // A face three blocks claim.
  m = refusal({box({0, 0, 0}, {1, 1, 1}), box({1, 0, 0}, {1, 1, 1}), box({1, 0, 0}, {1, 1, 1}, {0, 2, 1})});
  EXPECT_NE(m.find("meets both"), std::string::npos) << m;
}

}  // namespace
}  // namespace interpatch::mesh
