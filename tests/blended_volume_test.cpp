#include "interpatch/blended_volume.hpp"

#include "interpatch/coons_volume.hpp"
#include "interpatch/volume_patches.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

using test::iso_surface;

BlendedVolume hermite_coons_of(const BSplineVolume& b) {
  return coons_volume({iso_surface(b, 0, 0), iso_surface(b, 0, 1), iso_surface(b, 1, 0), iso_surface(b, 1, 1),
                       iso_surface(b, 2, 0), iso_surface(b, 2, 1)},
                      {iso_surface(b, 0, 0, 1), iso_surface(b, 0, 1, 1), iso_surface(b, 1, 0, 1),
                       iso_surface(b, 1, 1, 1), iso_surface(b, 2, 0, 1), iso_surface(b, 2, 1, 1)});
}

TEST(BlendedVolume, JacobianMatchesFiniteDifferences) {
  auto g = test::rng(240);
  // The formula's own derivatives, for a Hermite-blended Coons volume and a trilinear one.
  const auto b = test::random_bspline_volume(g, 3, 2, 3, 5, 4, 5);
  const auto s = hermite_coons_of(b);
  std::array<Vec3, 8> c;
  for (auto& x : c) x = test::random_point(g, 2);
  const auto t = trilinear(c);
  for (const BlendedVolume* v : {&s, &t})
    for (int k = 0; k < 25; ++k) {
      const double u = test::uniform(g, 0.05, 0.95), vv = test::uniform(g, 0.05, 0.95), w = test::uniform(g, 0.05, 0.95);
      const auto d = v->derivatives(u, vv, w);
      const auto f = test::finite_differences(*v, u, vv, w);
      // Central differences with h = 1e-5: truncation h² |S'''| <~ 1e-10 × 1e3, rounding 1e-16 |S| / h.
      EXPECT_LT(distance(d.su, f.su), 1e-6 * (1 + norm(d.su)));
      EXPECT_LT(distance(d.sv, f.sv), 1e-6 * (1 + norm(d.sv)));
      EXPECT_LT(distance(d.sw, f.sw), 1e-6 * (1 + norm(d.sw)));
      const auto j = v->jacobian(u, vv, w);
      EXPECT_EQ(j.determinant, dot(d.su, cross(d.sv, d.sw)));
    }
}

// Grid evaluation against the pointwise formula: tests/blended_grid_test.cpp.

TEST(BlendedVolume, OutOfDomain) {
  std::array<Vec3, 8> c{};
  const auto t = trilinear(c);
  EXPECT_ERRC((void)t.point(0.5, 1.5, 0), out_of_domain, "parameters (0.5, 1.5, 0) are outside the domain [0, 1]");
  const std::vector<double> ok{0, 1}, bad{-0.5};
  EXPECT_ERRC((void)t.evaluate(ok, ok, bad), out_of_domain, "parameter w = -0.5 is outside the domain [0, 1]");
  EXPECT_ERRC((void)t.evaluate_jacobians(bad, ok, ok), out_of_domain, "parameter u = -0.5");
  const std::vector<double> many(1000000, 0.5);
  EXPECT_ERRC((void)t.evaluate_derivatives(many, many, many), too_large, "volume derivative grid 1000000x1000000x1000000");
}

}  // namespace
}  // namespace interpatch
