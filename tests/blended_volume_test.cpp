#include "interpatch/blended_volume.hpp"

#include "base/parallel.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/volume_patches.hpp"
#include "thread_util.hpp"
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

// Coons volumes whose nets are large enough to be filled by every thread (net size
// times terms a point above detail::parallel_min_work; a point's terms are the blends
// of u, the faces of v and the blends of w, 2 + 2 + 2 for the linear volume, 4 + 4 + 4
// for the Hermite-blended one): linear, with faces on different knots and degrees so
// that the conversion merges and elevates, and Hermite-blended with cross-derivatives.
std::vector<std::pair<BlendedVolume, std::size_t>> large_blended_volumes() {
  auto g = test::rng(242);
  const auto b = test::random_bspline_volume(g, 3, 2, 3, 60, 50, 40);
  auto faces = test::faces_of(b);
  faces.u1 = faces.u1.refined(std::vector<double>{0.15, 0.33, 0.5}, std::vector<double>{0.61});
  faces.w0 = faces.w0.elevated(1, 0);
  return {{coons_volume(faces), 6}, {hermite_coons_of(test::random_bspline_volume(g, 3, 3, 3, 40, 40, 30)), 12}};
}

TEST(BlendedVolume, LargeExactFormsEqualTheFormula) {
  auto g = test::rng(243);
  for (const auto& [s, terms] : large_blended_volumes()) {
    const BSplineVolume b = s.to_bspline();
    ASSERT_GE(b.control_points().size() * terms, detail::parallel_min_work);
    // Data of size ~60 (control point (i, j, k) near (i, j, k)); the net sums its terms
    // in another order than the formula, after knot insertions and an elevation: a
    // few ulps of the data, far below 1e-12 of them.
    const double scale = test::scale_of(b);
    for (int k = 0; k < 200; ++k) {
      const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1), w = test::uniform(g, 0, 1);
      EXPECT_LT(distance(b.point(u, v, w), s.point(u, v, w)), 1e-12 * scale)
          << "at (" << u << ", " << v << ", " << w << ")";
    }
  }
}

#ifdef _OPENMP
// Each control point is summed by one thread in one order.
TEST(BlendedVolume, LargeExactFormsDoNotDependOnTheThreadCount) {
  test::expect_exact_forms_independent_of_threads(large_blended_volumes());
}
#endif

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
