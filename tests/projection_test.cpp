#include "interpatch/projection.hpp"

#include <cstring>

#include "interpatch/bspline_volume.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/evaluate.hpp"
#include "test_util.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace interpatch {
namespace {

// The oracle: the nearest of a dense sample of the surface, by brute force. It never
// comes closer than the true nearest point, so the projection's distance must be no
// more than the oracle's (plus the promised 1e-10 of the diagonal); where a search
// stopped in a local minimum, the oracle is nearer by far more than that.
struct Samples {
  std::vector<Vec3> points;
  std::vector<std::array<double, 2>> params;
  double diagonal = 0;
};

Samples dense(const Surface& s, std::size_t n) {
  const auto d = s.domain();
  const auto us = linspace(d[0].first, d[0].second, n), vs = linspace(d[1].first, d[1].second, n);
  const PointGrid g = s.evaluate(us, vs);
  Samples out;
  Vec3 lo = g.values()[0], hi = lo;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const Vec3 p = g(i, j);
      out.points.push_back(p);
      out.params.push_back({us[i], vs[j]});
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    }
  out.diagonal = distance(lo, hi);
  return out;
}

double oracle(const Samples& s, const Vec3& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& p : s.points) best = std::min(best, dot(p - q, p - q));
  return std::sqrt(best);
}

// Every query: the answer is the surface's own point at its parameters, its distance
// is that point's, and no sample of the surface is nearer by more than the promise.
void expect_global(const Surface& s, const std::vector<Vec3>& queries, std::size_t n, const char* what) {
  const Samples o = dense(s, n);
  const SurfaceProjector on(s);
  std::vector<SurfacePoint> got(queries.size());
  on.closest(queries, got);
  for (std::size_t k = 0; k < queries.size(); ++k) {
    const SurfacePoint& a = got[k];
    ASSERT_EQ(a.point, s.point(a.u, a.v)) << what << " query " << k;
    ASSERT_EQ(a.distance, distance(a.point, queries[k])) << what << " query " << k;
    // 1e-10 of the diagonal: the promise; the sample's own rounding is far below it.
    ASSERT_LE(a.distance, oracle(o, queries[k]) + 1e-10 * o.diagonal) << what << " query " << k << " at "
                                                                       << queries[k].x << ", " << queries[k].y << ", "
                                                                       << queries[k].z;
  }
}

std::vector<Vec3> queries_around(std::mt19937_64& g, const Vec3& lo, const Vec3& hi, std::size_t n) {
  std::vector<Vec3> q(n);
  const Vec3 c = (lo + hi) * 0.5, h = (hi - lo) * 0.75;
  for (auto& p : q) p = {c.x + test::uniform(g, -1, 1) * h.x, c.y + test::uniform(g, -1, 1) * h.y, c.z + test::uniform(g, -1, 1) * h.z};
  return q;
}

// A height field with a bump or a dip in every span: many local minima of distance.
BSplineSurface bumpy(std::mt19937_64& g, int n) {
  PointGrid cp({static_cast<std::size_t>(n), static_cast<std::size_t>(n)});
  for (std::size_t i = 0; i < cp.extent(0); ++i)
    for (std::size_t j = 0; j < cp.extent(1); ++j)
      cp(i, j) = {static_cast<double>(i) / (n - 1), static_cast<double>(j) / (n - 1), test::uniform(g, -0.3, 0.3)};
  return BSplineSurface(KnotVector::uniform(3, n), KnotVector::uniform(3, n), cp);
}

// A closed pipe: a periodic cubic circle of radius 1 in u, straight along z in v.
BSplineSurface pipe() {
  const int m = 8;
  PointGrid cp({static_cast<std::size_t>(m), 2});
  std::vector<double> k;
  for (int i = 0; i < m; ++i) {
    const double a = 2 * M_PI * i / m;
    cp(static_cast<std::size_t>(i), 0) = {std::cos(a), std::sin(a), 0};
    cp(static_cast<std::size_t>(i), 1) = {std::cos(a), std::sin(a), 2};
    k.push_back(static_cast<double>(i) / m);
  }
  return BSplineSurface(KnotVector::periodic_from(3, k, 1.0), KnotVector::bezier(1), cp);
}

// A dome whose first row of control points is one point: a pole at u = 0, where
// every v gives the same point.
BSplineSurface dome() {
  const int m = 8, rows = 4;
  PointGrid cp({static_cast<std::size_t>(rows), static_cast<std::size_t>(m)});
  std::vector<double> k;
  for (int j = 0; j < m; ++j) k.push_back(static_cast<double>(j) / m);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < m; ++j) {
      const double r = static_cast<double>(i) / (rows - 1), a = 2 * M_PI * j / m;
      cp(static_cast<std::size_t>(i), static_cast<std::size_t>(j)) = {r * std::cos(a), r * std::sin(a), 1 - r * r};
    }
  return BSplineSurface(KnotVector::uniform(3, rows), KnotVector::periodic_from(3, k, 1.0), cp);
}

TEST(CurveProjector, TheHeadersParabola) {
  const BSplineCurve c(KnotVector::bezier(2), {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}});
  const CurveProjector on(c);
  const CurvePoint p = on.closest({1, 3, 0});
  EXPECT_NEAR(p.t, 0.5, 1e-12);
  EXPECT_NEAR(p.distance, 2.0, 1e-12);
  EXPECT_EQ(p.point, c.point(p.t));
}

TEST(CurveProjector, RandomCurvesAgainstDenseSamples) {
  std::mt19937_64 g(20261130);
  for (int trial = 0; trial < 40; ++trial) {
    const int p = 1 + trial % 5;
    const int n = p + 1 + static_cast<int>(g() % 12);
    std::vector<Vec3> cp(static_cast<std::size_t>(n));
    for (auto& x : cp) x = test::random_point(g, 2);
    std::vector<double> w;
    if (trial % 3 == 0)
      for (int i = 0; i < n; ++i) w.push_back(test::uniform(g, 0.3, 3));
    const BSplineCurve c(KnotVector::uniform(p, n), cp, w);
    const auto ts = linspace(0, 1, 20001);
    std::vector<Vec3> s;
    for (const double t : ts) s.push_back(c.point(t));
    Vec3 lo = s[0], hi = s[0];
    for (const Vec3& x : s)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], x[a]), hi[a] = std::max(hi[a], x[a]);
    const double diag = distance(lo, hi);
    const CurveProjector on(c);
    for (int k = 0; k < 50; ++k) {
      const Vec3 q = test::random_point(g, 3);
      const CurvePoint a = on.closest(q);
      double best = std::numeric_limits<double>::infinity();
      for (const Vec3& x : s) best = std::min(best, distance(x, q));
      ASSERT_EQ(a.point, c.point(a.t));
      ASSERT_LE(a.distance, best + 1e-10 * diag) << "trial " << trial << " query " << k;
    }
  }
}

TEST(CurveProjector, AClosedCurveAtItsSeam) {
  const int m = 7;
  std::vector<Vec3> cp;
  std::vector<double> k;
  for (int i = 0; i < m; ++i) {
    const double a = 2 * M_PI * i / m;
    cp.push_back({std::cos(a), std::sin(a), 0});
    k.push_back(static_cast<double>(i) / m);
  }
  const BSplineCurve c(KnotVector::periodic_from(3, k, 1.0), cp);
  const CurveProjector on(c);
  const Vec3 seam = c.point(0);
  const CurvePoint a = on.closest(seam * 2);
  EXPECT_NEAR(distance(a.point, seam), 0, 1e-9);
  EXPECT_TRUE(a.t < 1e-6 || a.t > 1 - 1e-6);
}

TEST(SurfaceProjector, ABumpySurfaceWithManyLocalMinima) {
  std::mt19937_64 g(7);
  const BSplineSurface s = bumpy(g, 14);
  expect_global(s, queries_around(g, {0, 0, -0.3}, {1, 1, 0.3}, 300), 700, "bumpy");
}

TEST(SurfaceProjector, ARationalSurface) {
  std::mt19937_64 g(8);
  PointGrid cp({6, 5});
  Grid<double, 2> w({6, 5});
  for (std::size_t i = 0; i < 6; ++i)
    for (std::size_t j = 0; j < 5; ++j) cp(i, j) = {static_cast<double>(i) / 5, static_cast<double>(j) / 4, test::uniform(g, -0.4, 0.4)}, w(i, j) = test::uniform(g, 0.3, 3);
  const BSplineSurface s(KnotVector::uniform(2, 6), KnotVector::uniform(3, 5), cp, w);
  expect_global(s, queries_around(g, {0, 0, -0.4}, {1, 1, 0.4}, 200), 600, "rational");
}

TEST(SurfaceProjector, AClosedPipeAtItsSeam) {
  std::mt19937_64 g(9);
  const BSplineSurface s = pipe();
  std::vector<Vec3> q = queries_around(g, {-1, -1, 0}, {1, 1, 2}, 200);
  const Vec3 seam = s.point(0, 0.5);
  q.push_back(seam * 1.5);
  q.push_back(seam * 0.5);
  q.push_back({seam.x * 1.5, 1e-13, 1});  // just across the seam
  q.push_back({seam.x * 1.5, -1e-13, 1});
  expect_global(s, q, 800, "pipe");
}

TEST(SurfaceProjector, ADomeAtItsPole) {
  std::mt19937_64 g(10);
  const BSplineSurface s = dome();
  std::vector<Vec3> q = queries_around(g, {-1, -1, 0}, {1, 1, 1}, 200);
  q.push_back({0, 0, 2});  // above the pole: every v is the answer
  q.push_back({1e-9, 0, 1.5});
  q.push_back({0, 0, -3});  // below the dome, farther from the pole than from its rim
  expect_global(s, q, 700, "dome");
  const SurfaceProjector on(s);
  EXPECT_NEAR(on.closest({0, 0, 2}).distance, 1.0, 1e-12);
}

TEST(SurfaceProjector, ACoonsPatchThroughItsExactForm) {
  std::mt19937_64 g(11);
  const auto edge = [&](Vec3 a, Vec3 b) {
    std::vector<Vec3> cp{a, a + (b - a) / 3 + test::random_point(g, 0.3), a + (b - a) * 2 / 3 + test::random_point(g, 0.3), b};
    return BSplineCurve(KnotVector::bezier(3), cp);
  };
  const Vec3 p00{0, 0, 0}, p10{1, 0, 0.2}, p01{0, 1, -0.1}, p11{1, 1, 0.4};
  CoonsBoundary b{edge(p00, p10), edge(p01, p11), edge(p00, p01), edge(p10, p11)};
  const BlendedSurface s = coons(b);
  expect_global(s, queries_around(g, {0, 0, -0.3}, {1, 1, 0.5}, 200), 600, "coons");
}

TEST(SurfaceProjector, TheSameBitsOnAnyThreadCount) {
#ifdef _OPENMP
  std::mt19937_64 g(12);
  const BSplineSurface s = bumpy(g, 30);
  const std::vector<Vec3> q = queries_around(g, {0, 0, -0.3}, {1, 1, 0.3}, 5000);
  const SurfaceProjector on(s);
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
  omp_set_num_threads(1);
  std::vector<SurfacePoint> one(q.size()), many(q.size());
  on.closest(q, one);
  omp_set_num_threads(3);
  on.closest(q, many);
  omp_set_num_threads(before);
  for (std::size_t k = 0; k < q.size(); ++k) {
    ASSERT_EQ(std::memcmp(&one[k], &many[k], sizeof(SurfacePoint)), 0) << k;
  }
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

TEST(SurfaceProjector, BadPointsAreNamed) {
  std::mt19937_64 g(13);
  const BSplineSurface s = bumpy(g, 5);
  const SurfaceProjector on(s);
  std::vector<Vec3> q(10, Vec3{0.5, 0.5, 1});
  q[7].y = std::nan("");
  std::vector<SurfacePoint> out(q.size());
  EXPECT_ERRC(on.closest(q, out), not_finite, "point 7");
  std::vector<SurfacePoint> short_out(3);
  EXPECT_ERRC(on.closest(std::span<const Vec3>(q).first(5), short_out), size_mismatch, "3 answers for 5 points");
  EXPECT_ERRC((void)on.intersect({0, 0, 1}, {0, 0, 0}), wrong_type, "zero vector");
}

TEST(SurfaceProjector, RaysMeetAHeightFieldOnceAndAPipeTwice) {
  std::mt19937_64 g(14);
  const BSplineSurface s = bumpy(g, 10);
  const SurfaceProjector on(s);
  for (int k = 0; k < 200; ++k) {
    const Vec3 o{test::uniform(g, 0.01, 0.99), test::uniform(g, 0.01, 0.99), 2};
    const auto hits = on.intersect(o, {0, 0, -test::uniform(g, 0.5, 3)});
    ASSERT_EQ(hits.size(), 1u) << k;
    EXPECT_EQ(hits[0].point, s.point(hits[0].u, hits[0].v));
    // On the ray: its x and y, to the rounding of a point of a unit-sized surface.
    EXPECT_NEAR(hits[0].point.x, o.x, 1e-12);
    EXPECT_NEAR(hits[0].point.y, o.y, 1e-12);
  }
  const BSplineSurface p = pipe();
  const SurfaceProjector at(p);
  const auto through = at.intersect({-5, 0.1, 1}, {1, 0, 0});
  ASSERT_EQ(through.size(), 2u);
  EXPECT_LT(through[0].t, through[1].t);
  EXPECT_LT(through[0].point.x, 0);
  EXPECT_GT(through[1].point.x, 0);
  EXPECT_TRUE(at.intersect({-5, 0.1, 3}, {1, 0, 0}).empty());  // above the pipe's end
  EXPECT_TRUE(at.intersect({5, 0.1, 1}, {1, 0, 0}).empty());   // pointing away
  const auto inside = at.intersect({0, 0, 1}, {0, 1, 0});       // from the axis: one wall ahead
  ASSERT_EQ(inside.size(), 1u);
  EXPECT_GT(inside[0].point.y, 0.9);
}

// A unit cube bent smoothly: an injective map, so that every point has one preimage.
BSplineVolume bent_cube(std::mt19937_64& g) {
  const std::size_t n = 5;
  PointGrid3 cp({n, n, n});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t k = 0; k < n; ++k) {
        const Vec3 x{static_cast<double>(i) / 4, static_cast<double>(j) / 4, static_cast<double>(k) / 4};
        cp(i, j, k) = x + Vec3{0.3 * x.y * x.y, 0.2 * std::sin(3 * x.x), 0.1 * x.x * x.y} + test::random_point(g, 0.02);
      }
  return BSplineVolume(KnotVector::uniform(3, 5), KnotVector::uniform(2, 5), KnotVector::uniform(3, 5), cp);
}

TEST(VolumeLocator, RecoversParametersAndFlagsOutsidePoints) {
  std::mt19937_64 g(15);
  const BSplineVolume v = bent_cube(g);
  const VolumeLocator in(v);
  std::vector<Vec3> x;
  std::vector<std::array<double, 3>> uvw;
  for (int k = 0; k < 500; ++k) {
    uvw.push_back({test::uniform(g, 0, 1), test::uniform(g, 0, 1), test::uniform(g, 0, 1)});
    x.push_back(v.point(uvw.back()[0], uvw.back()[1], uvw.back()[2]));
  }
  std::vector<VolumePoint> got(x.size());
  in.locate(x, got);
  for (std::size_t k = 0; k < x.size(); ++k) {
    ASSERT_TRUE(got[k].inside) << k;
    EXPECT_NEAR(got[k].u, uvw[k][0], 1e-10);
    EXPECT_NEAR(got[k].v, uvw[k][1], 1e-10);
    EXPECT_NEAR(got[k].w, uvw[k][2], 1e-10);
    EXPECT_EQ(got[k].point, v.point(got[k].u, got[k].v, got[k].w));
  }
  // Outside: flagged, and the answer is the nearest point of the boundary (against
  // dense samples of the six faces).
  std::vector<Vec3> faces;
  const auto ts = linspace(0, 1, 161);
  for (const double a : ts)
    for (const double b : ts)
      for (const double e : {0.0, 1.0})
        faces.push_back(v.point(e, a, b)), faces.push_back(v.point(a, e, b)), faces.push_back(v.point(a, b, e));
  for (int k = 0; k < 100; ++k) {
    Vec3 q = test::random_point(g, 1);
    q = Vec3{0.5, 0.5, 0.5} + q * (1.2 / max_abs(q));
    const VolumePoint a = in.locate(q);
    ASSERT_FALSE(a.inside) << k;
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3& f : faces) best = std::min(best, distance(f, q));
    EXPECT_LE(a.residual, best + 1e-10 * std::sqrt(3.0)) << k;
    EXPECT_EQ(a.point, v.point(a.u, a.v, a.w));
  }
}

}  // namespace
}  // namespace interpatch
