// Where points are: the examples of projection.hpp (closest points on a curve and a
// surface, a ray's hits, points located in a volume), each run and its comments
// checked. Links interpatch::core only.

#include <cstdio>
#include <vector>

#include <interpatch/core.hpp>

#include "check.hpp"

namespace {

void curve() {
  interpatch::BSplineCurve c(interpatch::KnotVector::bezier(2), {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}});
  interpatch::CurveProjector on(c);
  interpatch::CurvePoint p = on.closest({1, 3, 0});  // t = 0.5, point (1, 1, 0), distance 2
  example::expect_near(p.t, 0.5, "t = 0.5");
  example::expect_near(p.point, {1, 1, 0}, "point (1, 1, 0)");
  example::expect_near(p.distance, 2, "distance 2");
  std::printf("closest point of the parabola to (1, 3, 0): t = %s, %s\n", example::str(p.t).c_str(), example::str(p.point).c_str());
}

// A saddle z = (x - 0.5)(y - 0.5) over the unit square, as a biquadratic Bézier patch.
interpatch::BSplineSurface saddle() {
  interpatch::PointGrid cp({3, 3});
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) {
      const double x = 0.5 * static_cast<double>(i), y = 0.5 * static_cast<double>(j);
      cp(i, j) = {x, y, (x - 0.5) * (y - 0.5)};
    }
  return interpatch::BSplineSurface(interpatch::KnotVector::bezier(2), interpatch::KnotVector::bezier(2), cp);
}

void surface_queries(const interpatch::Surface& surface) {
  interpatch::SurfaceProjector on(surface);
  interpatch::SurfacePoint p = on.closest({0.3, 0.4, 2.0});
  std::vector<interpatch::RayHit> hits = on.intersect({0.5, 0.5, 5.0}, {0, 0, -1});
  example::expect(p.point == surface.point(p.u, p.v), "the closest point is the surface's point at (u, v)");
  example::expect(hits.size() == 1, "the ray down the middle meets the saddle once");
  example::expect_near(hits[0].point, {0.5, 0.5, 0}, "at its centre", 1e-12);
  example::expect_near(hits[0].t, 5, "5 along the ray", 1e-12);
  std::printf("closest point to (0.3, 0.4, 2): (u, v) = (%s, %s), distance %s; the ray hits at t = %s\n",
              example::str(p.u).c_str(), example::str(p.v).c_str(), example::str(p.distance).c_str(),
              example::str(hits[0].t).c_str());
}

double found[3];
void use(double u, double v, double w) { found[0] = u, found[1] = v, found[2] = w; }

void volume_queries(const interpatch::Volume& volume) {
  interpatch::VolumeLocator in(volume);
  interpatch::VolumePoint p = in.locate({0.2, 0.3, 0.4});
  if (p.inside) use(p.u, p.v, p.w);
  example::expect(p.inside, "(0.2, 0.3, 0.4) is inside the unit cube");
  example::expect_near(interpatch::Vec3{found[0], found[1], found[2]}, {0.2, 0.3, 0.4}, "at its own parameters", 1e-12);
  const interpatch::VolumePoint out = in.locate({2, 0.5, 0.5});
  example::expect(!out.inside, "(2, 0.5, 0.5) is outside");
  example::expect_near(out.residual, 1, "1 from the face x = 1", 1e-12);
  std::printf("located (0.2, 0.3, 0.4) at (%s, %s, %s); (2, 0.5, 0.5) is outside, %s from the cube\n",
              example::str(p.u).c_str(), example::str(p.v).c_str(), example::str(p.w).c_str(),
              example::str(out.residual).c_str());
}

}  // namespace

int main() {
  return example::run("projection", [] {
    curve();
    surface_queries(saddle());
    interpatch::PointGrid3 cube({2, 2, 2});
    for (std::size_t i = 0; i < 2; ++i)
      for (std::size_t j = 0; j < 2; ++j)
        for (std::size_t k = 0; k < 2; ++k)
          cube(i, j, k) = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)};
    const interpatch::BSplineVolume v(interpatch::KnotVector::bezier(1), interpatch::KnotVector::bezier(1),
                                      interpatch::KnotVector::bezier(1), cube);
    volume_queries(v);
  });
}
