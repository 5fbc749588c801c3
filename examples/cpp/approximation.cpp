// Approximating noisy and incomplete data: the examples of approximate.hpp for a
// curve, a surface with a missing row and a volume. Every comment that states a
// value is checked. Links interpatch::core only.

#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "check.hpp"

#include <interpatch/core.hpp>

namespace {

void curve() {
  using namespace interpatch;
  std::vector<Vec3> q;
  for (int i = 0; i <= 40; ++i) q.push_back({i / 40.0, std::sin(i / 8.0) + 0.01 * ((i * 7) % 3 - 1), 0});
  CurveApproximationOptions o;
  o.tolerance = 0.02;
  auto r = approximate_curve(q, o);  // r.report.max_error <= 0.02, far fewer than 41 control points
  example::expect(r.report.max_error <= 0.02, "r.report.max_error <= 0.02");
  example::expect(r.curve.control_points().size() < 41 / 2, "far fewer than 41 control points");
  std::printf("curve through 41 noisy points: %zu control points, max error %g\n", r.curve.control_points().size(),
              r.report.max_error);
}

void surface() {
  using namespace interpatch;
  PointGrid q({30, 40});
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 40; ++j) q(i, j) = {i / 29.0, j / 39.0, std::sin(i / 5.0) * std::cos(j / 7.0)};
  for (int j = 0; j < 40; ++j) q(12, j).z = std::nan("");  // a missing row
  SurfaceApproximationOptions o;
  o.param = Parametrization::uniform;  // a grid sampled evenly: its parameters are its indices
  o.tolerance = 1e-3;
  auto r = approximate_surface(q, o);  // the row is filled smoothly; r.report.missing == 40
  example::expect(r.report.missing == 40, "r.report.missing == 40");
  example::expect(r.report.max_error <= 1e-3, "every point present within the tolerance");
  // Filled smoothly: the missing row's points lie near the function the others sample.
  const double z = r.surface.point(r.params_u[12], r.params_v[20]).z;
  // Within the tolerance of the function the other rows sample (1e-3, with room for the missing row's own error).
  example::expect_near(z, std::sin(12 / 5.0) * std::cos(20 / 7.0), "the filled row follows the surface", 2e-3);
  std::printf("surface over 30 x 40 points, a row missing: %d x %d control points\n", r.report.control_points[0],
              r.report.control_points[1]);
}

void volume() {
  using namespace interpatch;
  PointGrid3 q({8, 9, 10});
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 9; ++j)
      for (int k = 0; k < 10; ++k) q(i, j, k) = {double(i), double(j), k + 0.1 * std::sin(i + j)};
  VolumeApproximationOptions o;
  o.control_points = std::array<int, 3>{5, 5, 5};
  auto r = approximate_volume(q, o);  // 5 x 5 x 5 control points, least squares
  example::expect(r.volume.control_points().size() == 125, "5 x 5 x 5 control points");
  std::printf("volume of 8 x 9 x 10 points in 5 x 5 x 5 control points: rms error %g\n", r.report.rms_error);
}

void scattered() {
  using namespace interpatch;
  std::vector<Vec3> q;
  for (int k = 0; k < 2000; ++k) {
    const double x = std::fmod(k * 0.618034, 1.0), y = std::fmod(k * 0.414214, 1.0);
    q.push_back({100 * x, 80 * y, 5 * std::sin(x * 6) * std::cos(y * 4)});
  }
  ScatteredApproximationOptions o;
  o.param = ScatteredParam::xy;
  o.tolerance = 0.05;
  auto r = approximate_scattered(q, o);  // z = f(x, y); every point within 0.05
  example::expect(r.report.max_error <= 0.05, "every scattered point within the tolerance");
  // A height field: x(u, v) = u, to rounding.
  example::expect_near(r.surface.point(50, 40).x, 50, "x(u, v) = u", 1e-12);
  std::printf("2000 scattered points within 0.05: %d x %d control points\n", r.report.control_points[0],
              r.report.control_points[1]);
}

}  // namespace

int main() {
  return example::run("approximation", [] {
    curve();
    surface();
    scattered();
    volume();
  });
}
