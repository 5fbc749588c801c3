// Interpolating grids of points: the README's first example (section "The
// library") and its closed pipe, then the examples of interpolate.hpp for a curve
// and a surface, open and closed, grid.hpp, and threads.hpp's main(). Every comment that states a value is checked.
// Links interpatch::core only.

#include <array>
#include <cstdio>
#include <span>
#include <vector>

#include "check.hpp"

#include <cmath>
#include <interpatch/core.hpp>   // curves, surfaces, volumes: interpatch::core; interpatch.hpp adds io
using namespace interpatch;

namespace {

void readme_library() {
  PointGrid q({7, 13});                       // Q[p][q]: 7 points along u, 13 along v
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = 0; j < 13; ++j)
      q(i, j) = {double(i), 0.5 * double(j), std::sin(double(i) + 0.5 * double(j))};

  SurfaceInterpolationOptions opt;
  opt.param = Parametrization::centripetal;    // or chord (default), uniform
  auto r = interpolate_surface(q, opt);        // bicubic, exactly 7 × 13 control points

  Vec3 p = r.surface.point(r.params_u[3], r.params_v[5]);   // == q(3, 5) to rounding
  SurfaceDerivatives d = r.surface.derivatives(0.5, 0.5);   // S, Su, Sv, Suu, Suv, Svv
  Curvature k = curvature(d);                                // Gaussian, mean, principal
  PointGrid g = r.surface.evaluate(linspace(0, 1, 1000), linspace(0, 1, 1000));  // batch

  // Or into memory you own, a block of rows at a time (no buffer for the whole grid):
  std::vector<Vec3> rows(50 * 1000);
  auto us = linspace(0, 1, 1000), vs = linspace(0, 1, 1000);
  for (std::size_t i = 0; i < us.size(); i += 50)
    r.surface.evaluate_into(std::span(us).subspan(i, 50), vs, rows);  // then use the 50 rows

  example::expect(r.surface.degree_u() == 3 && r.surface.degree_v() == 3, "bicubic");
  example::expect(r.surface.control_points().shape() == PointGrid::shape_type{7, 13}, "exactly 7 × 13 control points");
  example::expect_near(p, q(3, 5), "r.surface.point(r.params_u[3], r.params_v[5]) == q(3, 5)");
  // Every data point, not only q(3, 5).
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = 0; j < 13; ++j)
      example::expect_near(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j), "the surface passes through q");
  example::expect_near(d.s, r.surface.point(0.5, 0.5), "derivatives().s is the point");
  example::expect(k.k1 >= k.k2, "principal curvatures ordered k1 >= k2");
  example::expect_near(k.gaussian, k.k1 * k.k2, "Gaussian curvature = k1 k2");
  example::expect_near(k.mean, 0.5 * (k.k1 + k.k2), "mean curvature = (k1 + k2) / 2");
  example::expect(g.shape() == PointGrid::shape_type{1000, 1000}, "evaluate() gives a 1000 × 1000 grid");
  example::expect_near(g(0, 0), q(0, 0), "the batch's first point is the first data point");
  example::expect_near(g(999, 999), q(6, 12), "the batch's last point is the last data point");
  example::expect_near(g(500, 250), r.surface.point(us[500], vs[250]), "the batch is the surface");
  // After the loop `rows` holds the last block, rows 950..999: the same points as the batch.
  for (std::size_t a = 0; a < 50; ++a)
    for (std::size_t b = 0; b < 1000; b += 37)
      example::expect(rows[a * 1000 + b] == g(950 + a, b), "evaluate_into() writes what evaluate() returns");
  std::printf("7 × 13 grid, centripetal: knots u");
  for (double t : r.surface.knots_u().values()) std::printf(" %.4g", t);
  std::printf("\n  at (0.5, 0.5): point %s, K = %.6g, H = %.6g\n", example::str(d.s).c_str(), k.gaussian, k.mean);
}

void curve() {
  using namespace interpatch;
  std::vector<Vec3> q{{0, 0, 0}, {1, 2, 0}, {3, 3, 0}, {4, 0, 1}};
  auto r = interpolate_curve(q);  // cubic, chord-length parameters
  Vec3 p = r.curve.point(r.params[2]);  // == q[2] up to rounding
  example::expect(r.curve.degree() == 3, "interpolate_curve(q) is cubic");
  const double chord = distance(q[0], q[1]) + distance(q[1], q[2]) + distance(q[2], q[3]);
  example::expect_near(r.params[1], distance(q[0], q[1]) / chord, "chord-length parameters");
  example::expect_near(p, q[2], "r.curve.point(r.params[2]) == q[2]");
  std::printf("curve through 4 points: params %.6g %.6g %.6g %.6g\n", r.params[0], r.params[1], r.params[2],
              r.params[3]);
}

void closed_curve() {
  using namespace interpatch;
  CurveInterpolationOptions closed;
  closed.periodic = true;
  std::vector<Vec3> ring{{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 0, 0}};  // last repeats the first
  auto c = interpolate_curve(ring, closed);  // 4 control points, C2 at the seam too
  Vec3 same = c.curve.point(1.25);           // == c.curve.point(0.25): parameters wrap
  example::expect(c.curve.periodic() && c.curve.control_points().size() == 4, "4 control points, closed");
  example::expect_near(same, c.curve.point(0.25), "c.curve.point(1.25) == c.curve.point(0.25)");
  for (int k = 0; k <= 2; ++k)
    example::expect_near(c.curve.derivative(1.0, k), c.curve.derivative(0.0, k), "C2 at the seam");
  for (std::size_t i = 0; i < ring.size(); ++i)
    example::expect_near(c.curve.point(c.params[i]), ring[i], "the closed curve passes through every point");
  example::expect(c.params.back() == 1.0, "the closing point's parameter is 1");
  std::printf("closed curve through 4 points: %zu control points, C(0.25) = %s\n", c.curve.control_points().size(),
              example::str(c.curve.point(0.25)).c_str());
}

void closed_surface() {
  using namespace interpatch;
  SurfaceInterpolationOptions pipe;
  pipe.periodic = {false, true};
  PointGrid ring({5, 12});
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 12; ++j) ring(i, j) = {std::cos(j * M_PI / 6), std::sin(j * M_PI / 6), double(i)};
  auto tube = interpolate_surface(ring, pipe);  // 5 x 12 control points, C2 around
  example::expect(tube.surface.control_points().shape() == PointGrid::shape_type{5, 12}, "5 x 12 control points");
  example::expect(tube.surface.periodic() == std::array<bool, 2>{false, true}, "closed around v");
  example::expect(tube.surface.knots_v().continuity() == 2, "C2 around, the seam included");
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 12; ++j)
      example::expect_near(tube.surface.point(tube.params_u[i], tube.params_v[j]), ring(i, j), "the tube passes through ring");
  example::expect_near(tube.surface.derivative(0.5, 1.0, 0, 2), tube.surface.derivative(0.5, 0.0, 0, 2),
                       "S_vv across the seam");
  std::printf("tube closed around v: %zu x %zu control points\n", tube.surface.control_points().extent(0),
              tube.surface.control_points().extent(1));
}

void readme_closed() {
  // A pipe closed around v: 20 sections of 32 distinct points (a 33rd repeating the first would be left out)
  PointGrid ring({20, 32});
  for (std::size_t i = 0; i < 20; ++i)
    for (std::size_t j = 0; j < 32; ++j) {
      const double a = 2 * M_PI * double(j) / 32, r = 1 + 0.2 * std::sin(0.3 * double(i));
      ring(i, j) = {r * std::cos(a), r * std::sin(a), 0.5 * double(i)};
    }
  SurfaceInterpolationOptions closed;
  closed.periodic = {false, true};                // u open, v closed
  auto pipe = interpolate_surface(ring, closed);  // 20 × 32 control points, C2 across the seam
  Vec3 seam = pipe.surface.point(0.5, 1.0);       // == pipe.surface.point(0.5, 0.0)
  BSplineSurface open = pipe.surface.clamped();   // the same surface over clamped knots, for programs that want them

  example::expect(pipe.surface.control_points().shape() == PointGrid::shape_type{20, 32}, "20 × 32 control points");
  example::expect(pipe.surface.periodic() == std::array<bool, 2>{false, true}, "u open, v closed");
  example::expect_near(seam, pipe.surface.point(0.5, 0.0), "pipe.surface.point(0.5, 1.0) == pipe.surface.point(0.5, 0.0)");
  example::expect(pipe.surface.knots_v().continuity() == 2, "C2 across the seam");
  example::expect(open.periodic() == std::array<bool, 2>{false, false}, "clamped() is open in both directions");
  for (double u : {0.0, 0.3, 1.0})
    for (double v : {0.0, 0.1, 0.55, 1.0})
      example::expect_near(open.point(u, v), pipe.surface.point(u, v), "clamped() is the same surface");
  std::printf("pipe: %zu x %zu control points closed around v, %zu x %zu clamped\n", pipe.surface.control_points().extent(0),
              pipe.surface.control_points().extent(1), open.control_points().extent(0), open.control_points().extent(1));
}

void surface() {
  using namespace interpatch;
  PointGrid q({7, 13});
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 13; ++j) q(i, j) = {double(i), double(j), std::sin(i + 0.5 * j)};
  auto r = interpolate_surface(q);  // bicubic
  Vec3 p = r.surface.point(r.params_u[3], r.params_v[5]);  // == q(3, 5) up to rounding
  example::expect(r.surface.degree_u() == 3 && r.surface.degree_v() == 3, "interpolate_surface(q) is bicubic");
  example::expect_near(p, q(3, 5), "r.surface.point(r.params_u[3], r.params_v[5]) == q(3, 5)");
  std::printf("surface through 7 × 13 points: S(u3, v5) = %s\n", example::str(p).c_str());
}

void grids() {
  interpatch::PointGrid g({4, 5});
  g(3, 4) = {1, 2, 3};
  // C order, first index slowest: (3, 4) is the last of the 20 elements.
  example::expect(g.size() == 20 && g.values().back() == interpatch::Vec3{1, 2, 3}, "g(3, 4) is element 3 * 5 + 4");
  example::expect(g(0, 0) == interpatch::Vec3{}, "the other elements are zero");
}

// Everything but thread binding, which threads.hpp's example does first in main().
int run() {
  return example::run("grid_interpolation", [] {
    readme_library();
    readme_closed();
    curve();
    closed_curve();
    surface();
    closed_surface();
    grids();
  });
}

}  // namespace

int main() {
  interpatch::bind_threads();  // first, before any of interpatch's parallel loops
  return run();                // the program's work: interpolate_surface(...), ...
}
