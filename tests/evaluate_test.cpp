#include "interpatch/evaluate.hpp"

#include <cstring>
#include <limits>
#include <vector>

#include "splines/normals.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

// z = a x² + b y² over [0,1]² as a biquadratic Bézier patch (exact): x = u, y = v.
BSplineSurface paraboloid(double a, double b) {
  PointGrid cp({3, 3});
  const double xs[3] = {0, 0.5, 1};
  const double zx[3] = {0, 0, a};  // Bernstein coefficients of a u²
  const double zy[3] = {0, 0, b};
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) cp(i, j) = {xs[i], xs[j], zx[i] + zy[j]};
  const KnotVector k(2, {0, 0, 0, 1, 1, 1});
  return BSplineSurface(k, k, cp);
}

TEST(Curvature, ParaboloidMatchesClosedForm) {
  for (auto [a, b] : {std::pair{1.0, 1.0}, std::pair{0.5, -2.0}, std::pair{3.0, 0.0}}) {
    const auto s = paraboloid(a, b);
    for (double u : {0.0, 0.3, 0.8})
      for (double v : {0.0, 0.45, 1.0}) {
        const auto d = s.derivatives(u, v);
        // Monge patch z = f(x,y): K = (fxx fyy − fxy²)/(1+fx²+fy²)², H from the standard formula.
        const double fx = 2 * a * u, fy = 2 * b * v, fxx = 2 * a, fyy = 2 * b;
        const double w = 1 + fx * fx + fy * fy;
        const double K = fxx * fyy / (w * w);
        const double H = ((1 + fy * fy) * fxx + (1 + fx * fx) * fyy) / (2 * std::pow(w, 1.5));
        const auto c = curvature(d);
        EXPECT_NEAR(c.gaussian, K, 1e-13);
        EXPECT_NEAR(c.mean, H, 1e-13);
        EXPECT_NEAR(c.k1 + c.k2, 2 * H, 1e-13);
        EXPECT_NEAR(c.k1 * c.k2, K, 1e-12);
        const Vec3 n = unit_normal(d);
        EXPECT_NEAR(norm(n), 1.0, 1e-15);
        EXPECT_NEAR(dot(n, Vec3{-fx, -fy, 1} / std::sqrt(w)), 1.0, 1e-14);
      }
  }
}

TEST(Curvature, SingularFirstFormGivesNaN) {
  SurfaceDerivatives d{};
  d.su = {1, 0, 0};
  const auto c = curvature(d);
  EXPECT_TRUE(std::isnan(c.gaussian));
  EXPECT_TRUE(std::isnan(c.mean));
  EXPECT_EQ(unit_normal(SurfaceDerivatives{}), (Vec3{0, 0, 0}));
}

// The batched normals of a mesh are unit_normal's: on partials of ordinary size to
// rounding (the lanes may use fused multiply-adds: a few ulps of a unit vector, held
// to 4e-16), and at poles, nearly parallel partials, partials of 1e±200 and NaN
// (which go to unit_normal itself) bit for bit; any count of points, the last few
// outside the blocks of four, which get the same bits as inside them.
TEST(UnitNormals, AreThoseOfUnitNormal) {
  auto g = test::rng(31);
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t n : {0u, 1u, 3u, 4u, 7u, 64u, 203u}) {
    std::vector<Vec3> su(n), sv(n), suv(n), out(n);
    std::vector<int> kind(n);
    for (std::size_t j = 0; j < n; ++j) {
      kind[j] = static_cast<int>(g() % 6);
      su[j] = test::random_point(g, 3.0);
      sv[j] = test::random_point(g, 3.0);
      suv[j] = test::random_point(g, 3.0);
      switch (kind[j]) {
        case 1: sv[j] = Vec3{}; break;                                    // a pole
        case 2: sv[j] = 2.0 * su[j] + 1e-12 * test::random_point(g); break;  // nearly parallel
        case 3: su[j] = 1e200 * su[j]; sv[j] = 1e200 * sv[j]; break;     // their squares overflow
        case 4: su[j] = 1e-200 * su[j]; sv[j] = 1e-200 * sv[j]; break;   // and underflow
        case 5: su[j].y = nan; break;
        default: break;
      }
    }
    detail::unit_normals(su.data(), sv.data(), suv.data(), n, out.data());
    for (std::size_t j = 0; j < n; ++j) {
      SurfaceDerivatives d{};
      d.su = su[j];
      d.sv = sv[j];
      d.suv = suv[j];
      const Vec3 want = unit_normal(d);
      // The point alone, and in a span starting anywhere before it (a mesh's block of
      // columns): the same bits as in the whole span.
      Vec3 alone{};
      detail::unit_normals(&su[j], &sv[j], &suv[j], 1, &alone);
      const std::size_t from = j - std::min<std::size_t>(j, g() % 6);
      std::vector<Vec3> part(j + 1 - from);
      detail::unit_normals(&su[from], &sv[from], &suv[from], part.size(), part.data());
      EXPECT_EQ(std::memcmp(&alone, &out[j], sizeof alone), 0) << "point " << j << " of " << n << " alone";
      EXPECT_EQ(std::memcmp(&part.back(), &out[j], sizeof alone), 0) << "point " << j << " of " << n << " from " << from;
      if (kind[j] == 0) {
        EXPECT_LE(norm(out[j] - want), 4e-16) << "point " << j << " of " << n;
      } else {  // NaN included: the same bits
        EXPECT_EQ(std::memcmp(&out[j], &want, sizeof want), 0) << "point " << j << " of " << n << ", kind " << kind[j];
      }
    }
  }
}

TEST(Linspace, EndsExact) {
  const auto t = linspace(0.1, 0.7, 7);
  EXPECT_EQ(t.front(), 0.1);
  EXPECT_EQ(t.back(), 0.7);
  EXPECT_NEAR(t[3], 0.4, 1e-16);
  EXPECT_EQ(linspace(0, 1, 1), (std::vector<double>{0}));
  EXPECT_TRUE(linspace(0, 1, 0).empty());
}

}  // namespace
}  // namespace interpatch
