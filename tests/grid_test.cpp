#include "interpatch/grid.hpp"

#include <algorithm>
#include <array>

#include "test_util.hpp"

namespace interpatch {
namespace {

// Outputs of the batch evaluations are made with `zeroed`: small grids come from
// operator new and are zero-filled, large ones are fresh zero pages left untouched.
TEST(Grid, ZeroedGridsAreZeroSmallAndLarge) {
  for (std::size_t n : {std::size_t{3}, std::size_t{700}}) {  // 216 bytes; 11.8 MB, a mapped buffer
    PointGrid g({n, n}, zeroed);
    ASSERT_EQ(g.size(), n * n);
    EXPECT_TRUE(std::all_of(g.values().begin(), g.values().end(),
                            [](const Vec3& p) { return p.x == 0 && p.y == 0 && p.z == 0; }))
        << n;
    g(n - 1, n - 1) = {1, 2, 3};
    EXPECT_EQ(g(n - 1, n - 1).z, 3.0);
  }
  // The deferral ends with the constructor: other vectors are value-initialized as usual.
  EXPECT_EQ(detail::start, detail::Start::values);
  std::vector<double, large_allocator<double>> v(1 << 18, 7.0);
  v.clear();
  v.resize(1 << 18);
  EXPECT_TRUE(std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; }));
}

TEST(Grid, ZeroedLeavesAnExistingVectorToResize) {
  std::vector<double, large_allocator<double>> v(4, 5.0);
  resize_zeroed(v, 8);  // not empty: an ordinary resize, new elements value-initialized
  ASSERT_EQ(v.size(), 8u);
  EXPECT_EQ(v[0], 5.0);
  EXPECT_EQ(v[7], 0.0);
}

// Outputs overwritten whole take the touched pages of a large buffer freed before
// (same rounded size); zero pages and constructed values never see old contents.
TEST(Grid, ForOverwriteReusesFreedPagesAndZeroedNeverDoes) {
  const std::array<std::size_t, 2> shape{1237, 1001};  // 29.7 MB: a mapped buffer, a size no other test uses
  const Vec3 mark{1.5, -2.5, 3.5};
  const Vec3* first = nullptr;
  {
    PointGrid g(shape, for_overwrite);
    ASSERT_EQ(g.size(), shape[0] * shape[1]);
    std::fill(g.values().begin(), g.values().end(), mark);
    first = g.data();
  }
  {
    PointGrid g(shape, for_overwrite);  // the mapping given back just now
    EXPECT_EQ(g.data(), first);
    EXPECT_EQ(g(shape[0] - 1, shape[1] - 1).y, mark.y);  // its pages as they were: nothing was redone
    std::fill(g.values().begin(), g.values().end(), mark);
  }
  {
    PointGrid g(shape, zeroed);  // zero pages are always fresh
    EXPECT_NE(g.data(), first);
    EXPECT_TRUE(std::all_of(g.values().begin(), g.values().end(),
                            [](const Vec3& p) { return p.x == 0 && p.y == 0 && p.z == 0; }));
  }
  {
    PointGrid g(shape, Vec3{7, 8, 9});  // constructed values, on a reused mapping or not
    EXPECT_TRUE(std::all_of(g.values().begin(), g.values().end(),
                            [](const Vec3& p) { return p.x == 7 && p.y == 8 && p.z == 9; }));
  }
  EXPECT_EQ(detail::start, detail::Start::values);
}

TEST(Grid, ForOverwriteSmallGridsAreValueInitialized) {
  PointGrid g({3, 4}, for_overwrite);  // 288 bytes from operator new
  ASSERT_EQ(g.size(), 12u);
  EXPECT_TRUE(std::all_of(g.values().begin(), g.values().end(),
                          [](const Vec3& p) { return p.x == 0 && p.y == 0 && p.z == 0; }));
}

}  // namespace
}  // namespace interpatch
