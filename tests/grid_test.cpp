#include "interpatch/grid.hpp"

#include <algorithm>

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
  EXPECT_FALSE(detail::leave_zero_pages);
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

}  // namespace
}  // namespace interpatch
