// Volumes: the Jacobian and the search for inverted cells (volume.hpp), B-spline
// volumes (bspline_volume.hpp), the trilinear and tricubic Hermite volumes of corner
// data (volume_patches.hpp), transfinite volumes from six faces (coons_volume.hpp),
// interpolation of a grid of points (interpolate.hpp) and volumes through section
// surfaces (loft.hpp). Every comment that states a value is checked. Links interpatch::core only.

#include <array>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include <interpatch/core.hpp>

#include "check.hpp"

namespace {

void jacobians() {
  interpatch::VolumeDerivatives d{{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}};
  double det = interpatch::jacobian(d).determinant;  // 24
  example::expect_near(det, 24, "jacobian(d).determinant == 24");
  example::expect_near(interpatch::jacobian(d).matrix[1][1], 3, "matrix[r][c] is coordinate r of column c");
  std::printf("det J of diag(2, 3, 4) = %g\n", det);
}

void inverted() {
  using namespace interpatch;
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) c[n] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
  std::swap(c[0], c[7]);                        // two corners exchanged: the cube turns inside out
  InvertedCells r = inverted_cells(trilinear(c), 21);
  // r.inverted_points > 0; r.locations holds the first (u, v, w) where det J <= 0
  example::expect(r.samples == 21 * 21 * 21 && r.cells == 20 * 20 * 20, "a 21 × 21 × 21 sample grid");
  example::expect(r.inverted_points > 0 && r.inverted_cells > 0, "r.inverted_points > 0");
  example::expect(!r.locations.empty(), "r.locations holds where det J <= 0");
  const auto& at = r.locations.front();
  example::expect(trilinear(c).jacobian(at[0], at[1], at[2]).determinant <= 1e-12, "det J <= 0 at r.locations[0]");
  std::printf("cube with two corners exchanged: %zu of %zu samples inverted, first at (%g, %g, %g), min det J %g\n",
              r.inverted_points, r.samples, at[0], at[1], at[2], r.min_determinant);
}

void bspline_volumes() {
  using namespace interpatch;
  const KnotVector lin = KnotVector::bezier(1);  // a straight line's knots: {0, 0, 1, 1}
  PointGrid3 cp({2, 2, 2});
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) cp(i, j, k) = {double(i), double(j), double(k) * (1 + i)};
  BSplineVolume b(lin, lin, lin, cp);
  Vec3 p = b.point(0.5, 0.5, 0.5);                    // (0.5, 0.5, 0.75)
  double det = b.jacobian(0.5, 0.5, 0.5).determinant; // 1.5
  example::expect(lin.values() == std::vector<double>{0, 0, 1, 1}, "KnotVector::bezier(1) is {0, 0, 1, 1}");
  example::expect_near(p, {0.5, 0.5, 0.75}, "b.point(0.5, 0.5, 0.5) == (0.5, 0.5, 0.75)");
  example::expect_near(det, 1.5, "b.jacobian(0.5, 0.5, 0.5).determinant == 1.5");
  std::printf("trilinear B-spline volume at the centre: %s, det J = %g\n", example::str(p).c_str(), det);
}

void trilinear_volumes() {
  using namespace interpatch;
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) c[n] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
  auto cube = trilinear(c);               // the identity map of the unit cube
  Vec3 p = cube.point(0.2, 0.3, 0.4);      // (0.2, 0.3, 0.4)
  example::expect_near(p, {0.2, 0.3, 0.4}, "cube.point(0.2, 0.3, 0.4) == (0.2, 0.3, 0.4)");
  example::expect_near(cube.jacobian(0.7, 0.1, 0.9).determinant, 1, "the identity map has det J = 1");
  std::printf("trilinear unit cube at (0.2, 0.3, 0.4): %s\n", example::str(p).c_str());
}

void hermite_volumes() {
  std::array<interpatch::HermiteVolumeCorner, 8> c{};
  for (int n = 0; n < 8; ++n) {
    c[n].p = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
    c[n].du = {1, 0, 0}; c[n].dv = {0, 1, 0}; c[n].dw = {0, 0, 1};
  }
  auto s = interpatch::hermite_volume(c);  // the unit cube again, cubic in form only
  example::expect_near(s.point(0.2, 0.3, 0.4), {0.2, 0.3, 0.4}, "the Hermite volume is the unit cube");
  const interpatch::BSplineVolume b = s.to_bspline();
  example::expect(b.degree_u() == 3 && b.degree_v() == 3 && b.degree_w() == 3, "cubic in form");
  example::expect_near(b.point(0.9, 0.5, 0.1), {0.9, 0.5, 0.1}, "its tricubic Bézier form is the unit cube too");
  std::printf("tricubic Hermite unit cube at (0.2, 0.3, 0.4): %s\n", example::str(s.point(0.2, 0.3, 0.4)).c_str());
}

void coons_volumes() {
  using namespace interpatch;
  const KnotVector lin = KnotVector::bezier(1);
  auto face = [&](int axis, double t) {  // coordinate `axis` = t, the other two from the parameters
    PointGrid cp({2, 2});
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        Vec3 p;
        p[axis] = t;
        p[axis == 0 ? 1 : 0] = a;
        p[axis == 2 ? 1 : 2] = b;
        cp(a, b) = p;
      }
    return BSplineSurface(lin, lin, cp);
  };
  auto s = coons_volume({face(0, 0), face(0, 1), face(1, 0), face(1, 1), face(2, 0), face(2, 1)});
  Vec3 p = s.point(0.2, 0.3, 0.4);  // (0.2, 0.3, 0.4)
  BSplineVolume b = s.to_bspline();  // trilinear, exact
  example::expect_near(p, {0.2, 0.3, 0.4}, "s.point(0.2, 0.3, 0.4) == (0.2, 0.3, 0.4)");
  example::expect(b.degree_u() == 1 && b.degree_v() == 1 && b.degree_w() == 1, "s.to_bspline() is trilinear");
  example::expect_near(b.point(0.2, 0.3, 0.4), p, "s.to_bspline() is the same volume");
  std::printf("Coons volume of six faces at (0.2, 0.3, 0.4): %s\n", example::str(p).c_str());

  // The Hermite-blended volume of the same faces, with S_w given on w = 0 and w = 1.
  VolumeCrossDerivatives d;
  d.w0 = d.w1 = BSplineSurface(lin, lin, PointGrid({2, 2}, Vec3{0, 0, 1}));
  auto h = coons_volume({face(0, 0), face(0, 1), face(1, 0), face(1, 1), face(2, 0), face(2, 1)}, d);
  Vec3 sw = h.derivatives(0.5, 0.5, 0).sw;  // (0, 0, 1)
  example::expect_near(sw, {0, 0, 1}, "h.derivatives(0.5, 0.5, 0).sw == (0, 0, 1)");
  example::expect_near(h.point(0.2, 0.3, 0.4), {0.2, 0.3, 0.4}, "the Hermite-blended volume is the unit cube too");
  std::printf("Hermite-blended Coons volume: S_w at (0.5, 0.5, 0) = %s\n", example::str(sw).c_str());
}

void interpolated_volumes() {
  using namespace interpatch;
  PointGrid3 q({5, 6, 4});
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 4; ++k) q(i, j, k) = {double(i), double(j) + 0.1 * i * i, double(k) + std::sin(i + j)};
  auto r = interpolate_volume(q);  // degrees (3, 3, 3)
  Vec3 p = r.volume.point(r.params_u[2], r.params_v[3], r.params_w[1]);  // == q(2, 3, 1) up to rounding
  example::expect(r.volume.degree_u() == 3 && r.volume.degree_v() == 3 && r.volume.degree_w() == 3,
                  "interpolate_volume(q) has degrees (3, 3, 3)");
  example::expect_near(p, q(2, 3, 1), "r.volume.point(...) == q(2, 3, 1)");
  std::printf("volume through 5 × 6 × 4 points: S(u2, v3, w1) = %s\n", example::str(p).c_str());
}

// loft.hpp's volume example: a solid between a flat square and a lid above it.
void loft_volumes() {
  using namespace interpatch;
  BSplineSurface floor = bilinear({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}).to_bspline();
  BSplineSurface lid = bilinear({0, 0, 1}, {0, 1, 1}, {1, 0, 1}, {1, 1, 1}).to_bspline().elevated(1, 1);
  LoftVolume body = loft_volume(std::vector<BSplineSurface>{floor, lid});
  Vec3 p = body.volume.point(0.5, 0.5, 1.0);  // (0.5, 0.5, 1): the lid
  int q = body.report.degree[2];              // 1: two sections, straight across

  example::expect_near(p, {0.5, 0.5, 1}, "the lid at w = 1");
  example::expect(q == 1, "two sections give degree 1 across");
  example::expect(body.report.degree[0] == 2 && body.report.degree[1] == 2, "the floor raised to the lid's degrees");
  for (double u : linspace(0, 1, 5))
    for (double v : linspace(0, 1, 5)) {
      example::expect_near(body.volume.point(u, v, 0.0), floor.point(u, v), "the floor at w = 0");
      example::expect_near(body.volume.point(u, v, 0.25), Vec3{u, v, 0.25}, "straight between them");
    }
}

}  // namespace

int main() {
  return example::run("volumes", [] {
    jacobians();
    inverted();
    bspline_volumes();
    trilinear_volumes();
    hermite_volumes();
    coons_volumes();
    interpolated_volumes();
    loft_volumes();
  });
}
