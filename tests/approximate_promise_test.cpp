// What a tolerance promises, closed directions and well-conditioned least squares
// (include/interpatch/approximate.hpp; issue 36, classes 4–6): each case reproduces a
// failure of an earlier release, with data made from a seeded generator.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "interpatch/approximate.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

// |S(t) − Q| at every data point present, by the spline's own evaluator.
double max_distance(const SurfaceApproximation& r, const PointGrid& q) {
  double worst = 0;
  for (std::size_t i = 0; i < q.extent(0); ++i)
    for (std::size_t j = 0; j < q.extent(1); ++j)
      if (is_finite(q(i, j))) worst = std::max(worst, distance(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j)));
  return worst;
}

// The largest |z| of a surface on a fine grid of its domain (between the data too).
double max_abs_z(const BSplineSurface& s, int samples) {
  const auto [u0, u1] = s.domain_u();
  const auto [v0, v1] = s.domain_v();
  double m = 0;
  for (int i = 0; i <= samples; ++i)
    for (int j = 0; j <= samples; ++j)
      m = std::max(m, std::abs(s.point(u0 + (u1 - u0) * i / samples, v0 + (v1 - v0) * j / samples).z));
  return m;
}

// A 40 × 50 grid of a unit step across u = 19.5.
PointGrid step_grid() {
  PointGrid q({40, 50});
  for (std::size_t i = 0; i < 40; ++i)
    for (std::size_t j = 0; j < 50; ++j) q(i, j) = {double(i), double(j), i < 20 ? 0.0 : 1.0};
  return q;
}

TEST(ApproximatePromise, StepGridMeetsEveryTolerance) {
  const PointGrid q = step_grid();
  // 0.1 once ended at 0.125 with 18 × 4 control points; the others for the same data.
  for (const double tol : {0.3, 0.1, 0.01, 1e-3}) {
    SurfaceApproximationOptions o;
    o.tolerance = tol;
    const auto r = approximate_surface(q, o);
    EXPECT_LE(max_distance(r, q), tol) << tol;  // the promise, exactly
    EXPECT_LE(r.report.max_error, tol) << tol;
    EXPECT_LE(r.report.control_points[0], 40);
    EXPECT_LE(r.report.control_points[1], 50);
  }
}

// Rough terrain as a survey gives it: 172 × 202 points 10 m apart, heights a sum of
// sines of random phase over 40 m to 2 km plus noise of σ = 2 m.
PointGrid rough_terrain(std::mt19937_64& g) {
  PointGrid q({172, 202});
  std::vector<std::array<double, 4>> waves;
  for (int k = 0; k < 24; ++k) {
    const double length = 40 * std::pow(50.0, test::uniform(g, 0, 1)), angle = test::uniform(g, 0, M_PI);
    waves.push_back({2 * M_PI / length * std::cos(angle), 2 * M_PI / length * std::sin(angle), test::uniform(g, 0, 2 * M_PI),
                     length / 20});
  }
  std::normal_distribution<double> noise(0.0, 2.0);
  for (std::size_t i = 0; i < 172; ++i)
    for (std::size_t j = 0; j < 202; ++j) {
      const double x = 10.0 * static_cast<double>(i), y = 10.0 * static_cast<double>(j);
      double z = 300;
      for (const auto& w : waves) z += w[3] * std::sin(w[0] * x + w[1] * y + w[2]);
      q(i, j) = {x, y, z + noise(g)};
    }
  return q;
}

TEST(ApproximatePromise, RoughTerrainMeetsToleranceAtTheNoiseLevel) {
  auto g = test::rng(1);
  const PointGrid q = rough_terrain(g);
  // 3 σ (the noise's own size, once missed at 6.76) and 5 σ.
  for (const double tol : {6.0, 10.0}) {
    SurfaceApproximationOptions o;
    o.tolerance = tol;
    const auto r = approximate_surface(q, o);
    EXPECT_LE(max_distance(r, q), tol) << tol;
  }
}

TEST(ApproximatePromise, CurvesAndVolumesMeetTheirTolerance) {
  std::vector<Vec3> c;
  for (int i = 0; i < 60; ++i) c.push_back({double(i), i < 30 ? 0.0 : 1.0, 0});
  CurveApproximationOptions oc;
  oc.tolerance = 0.05;  // a step of 1: far below what a smooth curve gets near it
  const auto rc = approximate_curve(c, oc);
  for (std::size_t i = 0; i < c.size(); ++i) EXPECT_LE(distance(rc.curve.point(rc.params[i]), c[i]), 0.05) << i;

  PointGrid3 v({10, 9, 8});
  for (std::size_t i = 0; i < 10; ++i)
    for (std::size_t j = 0; j < 9; ++j)
      for (std::size_t k = 0; k < 8; ++k) v(i, j, k) = {double(i), double(j), double(k) + (i + j < 9 ? 0.0 : 0.8)};
  VolumeApproximationOptions ov;
  ov.tolerance = 0.05;  // a jump of 0.8 in w across a diagonal plane
  const auto rv = approximate_volume(v, ov);
  for (std::size_t i = 0; i < 10; ++i)
    for (std::size_t j = 0; j < 9; ++j)
      for (std::size_t k = 0; k < 8; ++k)
        EXPECT_LE(distance(rv.volume.point(rv.params_u[i], rv.params_v[j], rv.params_w[k]), v(i, j, k)), 0.05);
}

TEST(ApproximatePromise, ToleranceBelowRoundingIsRefusedNamingThePoint) {
  auto g = test::rng(4);
  const PointGrid q = test::random_grid(g, 9, 7);
  SurfaceApproximationOptions o;
  o.tolerance = 1e-320;  // below any rounding of coordinates of size 1 to 9
  try {
    (void)approximate_surface(q, o);
    ADD_FAILURE() << "a tolerance of 1e-320 met";
  } catch (const error& e) {
    EXPECT_EQ(e.code(), errc::tolerance_not_met) << e.what();
    const std::string m = e.what();
    EXPECT_NE(m.find(" not met: point ["), std::string::npos) << m;
    // Never more control points than points: interpolation is the finest fit.
    EXPECT_NE(m.find("9 x 7 control points"), std::string::npos) << m;
  }
}

// Closed directions (issue 36 class 5).
TEST(ApproximatePromise, ClosedBothWaysStaysWithTheData) {
  auto g = test::rng(5);
  PointGrid q({6, 5});
  for (Vec3& p : q.values()) p = {test::uniform(g, 0, 1), test::uniform(g, 0, 1), test::uniform(g, 0, 1)};
  SurfaceApproximationOptions o;
  o.periodic = {true, true};
  o.tolerance = 0.01;  // the case that once ended at 4.44 with control points at ±140
  const auto r = approximate_surface(q, o);
  EXPECT_LE(max_distance(r, q), 0.01);
  for (const Vec3& p : r.surface.control_points().values())
    for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(p[k] - 0.5), 0.5 + 9 * std::sqrt(3.0)) << k;  // the box and 9 diagonals, the promise
}

TEST(ApproximatePromise, NoisyPipeClosedAroundStaysOnThePipe) {
  auto g = test::rng(6);
  PointGrid q({16, 24});
  for (std::size_t i = 0; i < 16; ++i)
    for (std::size_t j = 0; j < 24; ++j) {
      const double a = 2 * M_PI * static_cast<double>(j) / 24;
      q(i, j) = Vec3{std::cos(a), std::sin(a), 0.2 * static_cast<double>(i)} + test::random_point(g, 0.02);
    }
  SurfaceApproximationOptions o;
  o.periodic = {false, true};
  o.tolerance = 0.01;  // below the noise: the fit comes near interpolation
  const auto r = approximate_surface(q, o);
  EXPECT_LE(max_distance(r, q), 0.01);
  // The pipe is 3 high (once a spike reached z = 8.45): between the data too, within
  // the noise and a cubic's overshoot of it.
  EXPECT_LT(max_abs_z(r.surface, 200), 3.2);
}

TEST(ApproximatePromise, AsManyControlPointsAsPointsInterpolateAClosedDirection) {
  auto g = test::rng(7);
  for (int degree = 1; degree <= 3; ++degree) {
    PointGrid q({7, 9});
    for (Vec3& p : q.values()) p = test::random_point(g);
    SurfaceApproximationOptions o;
    o.periodic = {degree != 2, true};
    o.degree = {degree, degree};
    o.control_points = std::array<int, 2>{7, 9};
    const auto r = approximate_surface(q, o);
    EXPECT_LT(max_distance(r, q), 1e-12) << degree;  // interpolation, up to rounding (once 0.29)
  }
}

// Least squares that swung between the data (issue 36 class 6).
TEST(ApproximatePromise, NearlyAsManyControlPointsAsDataStayBetweenTheData) {
  auto g = test::rng(8);
  PointGrid q({20, 20});
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < 20; ++i)
    for (std::size_t j = 0; j < 20; ++j) {
      q(i, j) = {double(i), double(j), 0.1 * std::sin(0.3 * double(i)) * std::cos(0.4 * double(j)) + 0.1 + test::uniform(g, -0.01, 0.01)};
      lo = std::min(lo, q(i, j).z);
      hi = std::max(hi, q(i, j).z);
    }
  for (int c = 16; c <= 20; ++c) {
    SurfaceApproximationOptions o;
    o.control_points = std::array<int, 2>{c, c};
    const auto r = approximate_surface(q, o);
    // Once 4.5e6 at 19 × 19 with data in [-0.14, 0.32]: a cubic's overshoot between
    // noisy data stays within the data's range again.
    EXPECT_LT(max_abs_z(r.surface, 400), hi + (hi - lo)) << c;
    EXPECT_LT(max_distance(r, q), 0.02) << c;  // the noise's size, ±0.01, twice
  }
}

}  // namespace
}  // namespace interpatch
