// Graded nodes for blocks whose directions are tied across a shared face: the nodes
// of the face are the same from both sides (whichever way each block runs), and a
// first length holds over the lines of every block of the class.

#include "mesh/graded_blocks.hpp"

#include <gtest/gtest.h>

#include "interpatch/error.hpp"
#include "interpatch/volume_patches.hpp"
#include "mesh/blocks.hpp"

namespace interpatch::mesh {
namespace {

// Corner (i, j, k) at 4i + 2j + k.
BlendedVolume unit_cube() {
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) c[n] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
  return trilinear(c);
}

// Beside the cube along x, widening to y in [0, 1.5] at x = 2, its v running from
// the top (v = 0) down to y = 0.
BlendedVolume widening_block() {
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) {
    const int i = n >> 2, j = (n >> 1) & 1, k = n & 1;
    const double top = i == 0 ? 1.0 : 1.5;
    c[n] = {1.0 + i, j == 0 ? top : 0.0, double(k)};
  }
  return trilinear(c);
}

PointGrid3 nodes(const Volume& v, const std::array<std::vector<double>, 3>& p) { return v.evaluate(p[0], p[1], p[2]); }

TEST(BlocksGrading, TiedDirectionsGiveOneFaceFromBothSides) {
  const BlendedVolume a = unit_cube(), b = widening_block();
  const Volume* blocks[] = {&a, &b};
  std::vector<DirectionClass> classes{
      {{.count = 6}, {{0, 0, false}}, "block 0 u"},
      {{.count = 9, .ratio = 3}, {{1, 0, false}}, "block 1 u"},
      {{.count = 31, .first = 1e-3}, {{0, 1, false}, {1, 1, true}}, "y"},
      {{.count = 9, .first = 0.1, .last = 0.15}, {{0, 2, false}, {1, 2, false}}, "z"}};
  const GradedBlocks g = graded_blocks(blocks, classes);
  const std::vector<PointGrid3> grids{nodes(a, g.params[0]), nodes(b, g.params[1])};
  const std::vector<SharedFace> shared = shared_faces(grids, 1e-12);
  ASSERT_EQ(shared.size(), 1u);
  EXPECT_LE(shared[0].gap, 1e-15);  // the same parameters of the same bilinear face
  // The first cell at y = 0, measured here on every line of both blocks: the longest is
  // 1e-3 (on block 1's widest lines), none longer.
  double longest = 0;
  for (std::size_t i = 0; i < grids[0].extent(0); ++i)
    for (std::size_t k = 0; k < grids[0].extent(2); ++k) longest = std::max(longest, norm(grids[0](i, 1, k) - grids[0](i, 0, k)));
  const std::size_t last = grids[1].extent(1) - 1;
  double in_b = 0;
  for (std::size_t i = 0; i < grids[1].extent(0); ++i)
    for (std::size_t k = 0; k < grids[1].extent(2); ++k) in_b = std::max(in_b, norm(grids[1](i, last - 1, k) - grids[1](i, last, k)));
  EXPECT_LT(longest, in_b);  // the cube's lines are shorter: block 1 decides
  EXPECT_LE(in_b, 1e-3);
  EXPECT_GE(in_b, 1e-3 * (1 - 1e-9));
  EXPECT_NEAR(g.report[2].first, in_b, 1e-15);
  // z: both ends over both blocks.
  EXPECT_LE(g.report[3].first, 0.1);
  EXPECT_GE(g.report[3].first, 0.1 * (1 - 1e-9));
  EXPECT_LE(g.report[3].last, 0.15);
  EXPECT_GE(g.report[3].last, 0.15 * (1 - 1e-9));
  // And the merged mesh is whole: (6 + 9 - 1) x 31 x 9 nodes.
  const HexMesh m = merge_blocks(grids, shared, std::vector<std::array<std::string, 6>>(2, {"a", "b", "c", "d", "e", "f"}));
  EXPECT_EQ(m.points.size(), 14u * 31 * 9);
}

TEST(BlocksGrading, ADirectionInNoClassIsAnInternalError) {
  const BlendedVolume a = unit_cube();
  const Volume* blocks[] = {&a};
  const std::vector<DirectionClass> classes{{{.count = 3}, {{0, 0, false}}, "u"}, {{.count = 3}, {{0, 1, false}}, "v"}};
  EXPECT_THROW((void)graded_blocks(blocks, classes), error);
}

TEST(BlocksGrading, ErrorsNameTheClass) {
  const BlendedVolume a = unit_cube();
  const Volume* blocks[] = {&a};
  const std::vector<DirectionClass> classes{{{.count = 3, .first = 2}, {{0, 0, false}}, "the pipe's length"},
                                            {{.count = 3}, {{0, 1, false}}, "v"},
                                            {{.count = 3}, {{0, 2, false}}, "w"}};
  try {
    (void)graded_blocks(blocks, classes);
    ADD_FAILURE() << "accepted";
  } catch (const error& e) {
    EXPECT_EQ(e.code(), errc::invalid_grading);
    EXPECT_NE(std::string(e.what()).find("sampling the pipe's length: first 2 is longer than the direction"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace interpatch::mesh
