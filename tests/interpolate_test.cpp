#include "interpatch/interpolate.hpp"

#include <cmath>
#include <string>

#include "interpatch/evaluate.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

constexpr double kPi = 3.14159265358979323846;

double max_error_at_data(const SurfaceInterpolation& r, const PointGrid& q) {
  double e = 0;
  for (std::size_t i = 0; i < q.extent(0); ++i)
    for (std::size_t j = 0; j < q.extent(1); ++j)
      e = std::max(e, distance(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j)));
  return e;
}

TEST(CurveParameters, ChordCentripetalUniform) {
  const std::vector<Vec3> p{{0, 0, 0}, {1, 0, 0}, {1, 4, 0}, {1, 4, 4}};
  EXPECT_EQ(curve_parameters(p, Parametrization::chord), (std::vector<double>{0, 1.0 / 9, 5.0 / 9, 1}));
  EXPECT_EQ(curve_parameters(p, Parametrization::centripetal), (std::vector<double>{0, 0.2, 0.6, 1}));
  EXPECT_EQ(curve_parameters(p, Parametrization::uniform), (std::vector<double>{0, 1.0 / 3, 2.0 / 3, 1}));
}

TEST(AveragedKnots, NurbsBookEq98AndEndConditions) {
  const std::vector<double> t{0, 0.1, 0.3, 0.6, 0.8, 1};
  EXPECT_EQ(averaged_knots(t, 3).values(),
            (std::vector<double>{0, 0, 0, 0, (0.1 + 0.3 + 0.6) / 3, (0.3 + 0.6 + 0.8) / 3, 1, 1, 1, 1}));
  // Both end derivatives: windows of p over all parameters.
  const auto both = averaged_knots(t, 3, true, true);
  EXPECT_EQ(both.count(), 8);
  EXPECT_DOUBLE_EQ(both[4], (0 + 0.1 + 0.3) / 3);
  EXPECT_DOUBLE_EQ(both[7], (0.6 + 0.8 + 1) / 3);
  EXPECT_EQ(averaged_knots(t, 1).values(), (std::vector<double>{0, 0, 0.1, 0.3, 0.6, 0.8, 1, 1}));
}

TEST(InterpolateCurve, PassesThroughRandomPointsEveryDegreeAndParametrization) {
  auto g = test::rng(30);
  for (int trial = 0; trial < 150; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 19);
    const auto q = test::random_polyline(g, n, 0.45);
    CurveInterpolationOptions o;
    o.degree = std::min(1 + trial % 5, static_cast<int>(n) - 1);
    o.param = static_cast<Parametrization>(trial % 3);
    const auto r = interpolate_curve(q, o);
    ASSERT_EQ(r.curve.control_points().size(), n);
    const double scale = test::bbox_diagonal(q);
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_LT(distance(r.curve.point(r.params[i]), q[i]), 1e-12 * scale);  // banded solve rounding
  }
}

TEST(InterpolateCurve, EndDerivativesAreMet) {
  auto g = test::rng(31);
  for (int trial = 0; trial < 60; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 9);
    const auto q = test::random_polyline(g, n, 0.4);
    CurveInterpolationOptions o;
    o.degree = n >= 3 ? 3 : 2;
    if (trial % 3 != 2) o.start_derivative = test::random_point(g, 5);
    if (trial % 3 != 1) o.end_derivative = test::random_point(g, 5);
    const auto r = interpolate_curve(q, o);
    const double scale = test::bbox_diagonal(q);
    for (std::size_t i = 0; i < n; ++i) EXPECT_LT(distance(r.curve.point(r.params[i]), q[i]), 1e-12 * scale);
    // Derivative rows carry factors ~1/span: a little more rounding than the points.
    if (o.start_derivative) {
      EXPECT_LT(norm(r.curve.derivative(0, 1) - *o.start_derivative), 1e-11 * (1 + scale));
    }
    if (o.end_derivative) {
      EXPECT_LT(norm(r.curve.derivative(1, 1) - *o.end_derivative), 1e-11 * (1 + scale));
    }
  }
}

TEST(InterpolateCurve, ReproducesPolynomialsOfItsDegree) {
  // Points on a cubic in the parameter are reproduced everywhere, not just at the data.
  auto f = [](double t) { return Vec3{t, 2 * t * t - t, t * t * t - 0.5 * t}; };
  std::vector<double> t{0, 0.15, 0.2, 0.45, 0.7, 0.9, 1};
  std::vector<Vec3> q;
  for (double x : t) q.push_back(f(x));
  CurveInterpolationOptions o;
  o.params = t;
  const auto r = interpolate_curve(q, o);
  for (int s = 0; s <= 100; ++s) EXPECT_LT(distance(r.curve.point(s / 100.0), f(s / 100.0)), 1e-14);
}

TEST(InterpolateCurve, InvalidInput) {
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}}), too_few_points, "at least 2 points, got 1");
  CurveInterpolationOptions o;
  o.degree = 4;
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {2, 1, 0}}, o), too_few_points,
              "degree 4 needs at least 5 points, got 3");
  o.degree = 0;
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}}, o), invalid_degree, "degree 0");
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {2, 0, 0}}), zero_chord,
              "points 1 and 2 coincide");
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {1, NAN, 0}}), not_finite, "point 1");
  CurveInterpolationOptions given;
  given.params = {0, 0.5, 0.4};
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, given), non_increasing,
              "parameter 2 = 0.4");
  given.params = {0, 1};
  EXPECT_ERRC((void)interpolate_curve(std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, given), size_mismatch,
              "3 parameters, got 2");
}

TEST(InterpolateSurface, PassesThroughRandomGridsOfManyShapesAndDegrees) {
  auto g = test::rng(40);
  for (int trial = 0; trial < 120; ++trial) {
    const std::size_t nu = 2 + static_cast<std::size_t>(trial % 11), nv = 2 + static_cast<std::size_t>((trial * 7) % 17);
    const auto q = test::random_grid(g, nu, nv, 0.35);
    SurfaceInterpolationOptions o;
    o.degree_u = 1 + trial % std::min<int>(5, static_cast<int>(nu) - 1);
    o.degree_v = 1 + (trial / 3) % std::min<int>(5, static_cast<int>(nv) - 1);
    o.param = static_cast<Parametrization>(trial % 3);
    const auto r = interpolate_surface(q, o);
    EXPECT_EQ(r.surface.control_points().extent(0), nu);  // exactly (n+1) x (m+1) control points
    EXPECT_EQ(r.surface.control_points().extent(1), nv);
    EXPECT_EQ(r.surface.degree_u(), *o.degree_u);
    // Two banded solves: rounding grows with the (small) condition number of the collocation matrices.
    EXPECT_LT(max_error_at_data(r, q), 1e-12 * test::bbox_diagonal(q.values())) << nu << "x" << nv;
  }
}

TEST(InterpolateSurface, PassesThroughGridsWhoseRowsAreSolvedInSeveralColumnSlices) {
  // The solve along u takes the rows' 3 × nv numbers a column slice at a time: about
  // 512 wide (a multiple of the thread count of slices) when nu ≤ 2048; beyond, a
  // quarter of the row but at least 512. These shapes give several slices with a
  // short last one on both sides of that bound.
  auto g = test::rng(42);
  for (const auto& [nu, nv] : {std::pair<std::size_t, std::size_t>{40, 700}, {2049, 190}}) {
    const auto q = test::random_grid(g, nu, nv, 0.35);
    const auto r = interpolate_surface(q);
    const PointGrid at_data = r.surface.evaluate(r.params_u, r.params_v);
    double e = 0;
    for (std::size_t k = 0; k < q.size(); ++k) e = std::max(e, distance(at_data.data()[k], q.data()[k]));
    // As for the small random grids above: two banded solves of small condition number.
    EXPECT_LT(e, 1e-12 * test::bbox_diagonal(q.values())) << nu << "x" << nv;
  }
}

TEST(InterpolateSurface, SevenByThirteenDegreesTwoThreeAndFiveFive) {
  auto g = test::rng(41);
  PointGrid q({7, 13});
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = 0; j < 13; ++j) {
      const double x = static_cast<double>(i), y = 0.5 * static_cast<double>(j);
      q(i, j) = {x, y, std::sin(x) * std::cos(y) + 0.01 * test::uniform(g)};
    }
  for (auto [p, d] : {std::pair{2, 3}, std::pair{3, 3}, std::pair{5, 5}}) {
    SurfaceInterpolationOptions o;
    o.degree_u = p;
    o.degree_v = d;
    const auto r = interpolate_surface(q, o);
    EXPECT_LT(max_error_at_data(r, q), 1e-12 * test::bbox_diagonal(q.values()));
    EXPECT_EQ(r.surface.knots_u().size(), 7u + static_cast<std::size_t>(p) + 1);
  }
  SurfaceInterpolationOptions dflt;
  EXPECT_EQ(interpolate_surface(q, dflt).surface.degree_u(), 3);
  PointGrid small({3, 2});
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 2; ++j) small(i, j) = {double(i), double(j), double(i * j)};
  const auto r = interpolate_surface(small);
  EXPECT_EQ(r.surface.degree_u(), 2);  // min(3, points - 1)
  EXPECT_EQ(r.surface.degree_v(), 1);
}

TEST(InterpolateSurface, HemisphereWithAPoleRow) {
  // Row u = 0 is the pole: every point equal. Its zero-length line is left out of the
  // v-parameter average and must not break the interpolation.
  const std::size_t nu = 9, nv = 17;
  PointGrid q({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const double th = 0.5 * kPi * static_cast<double>(i) / (nu - 1), ph = 2 * kPi * static_cast<double>(j) / (nv - 1);
      q(i, j) = {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
    }
  for (auto param : {Parametrization::chord, Parametrization::centripetal, Parametrization::uniform}) {
    SurfaceInterpolationOptions o;
    o.param = param;
    const auto r = interpolate_surface(q, o);
    EXPECT_LT(max_error_at_data(r, q), 1e-12 * 2);  // bbox diagonal ~2
    // Averaged over the 16 non-pole rows the v-parameters are uniform by symmetry.
    for (std::size_t j = 0; j < nv; ++j) EXPECT_NEAR(r.params_v[j], static_cast<double>(j) / (nv - 1), 1e-12);
    // The pole row of control points collapses to the pole.
    for (std::size_t j = 0; j < nv; ++j) EXPECT_LT(distance(r.surface.control_points()(0, j), {0, 0, 1}), 1e-14);
    // Between the data the surface stays close to the sphere (interpolation error, not rounding).
    for (int s = 1; s < 20; ++s) {
      const Vec3 x = r.surface.point(s / 20.0, (s * 7 % 20) / 20.0);
      EXPECT_NEAR(norm(x), 1.0, 2e-3);
    }
    // The normal at the pole is the limit: the z axis.
    const auto d = r.surface.derivatives(0.0, 0.3);
    EXPECT_GT(std::abs(unit_normal(d).z), 0.999);
  }
}

TEST(InterpolateSurface, ReproducesTensorPolynomialsEverywhere) {
  // A surface polynomial of degree (3,3) in uniform parameters lies in the spline space.
  auto f = [](double u, double v) { return Vec3{u + 0.1 * v * v, v - u * u * v, u * u * u * v - 2 * v * v * v + u * v}; };
  const std::size_t nu = 8, nv = 6;
  PointGrid q({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) q(i, j) = f(static_cast<double>(i) / (nu - 1), static_cast<double>(j) / (nv - 1));
  SurfaceInterpolationOptions o;
  o.param = Parametrization::uniform;
  const auto r = interpolate_surface(q, o);
  for (int s = 0; s <= 30; ++s)
    for (int t = 0; t <= 30; ++t) EXPECT_LT(distance(r.surface.point(s / 30.0, t / 30.0), f(s / 30.0, t / 30.0)), 1e-14);
}

TEST(InterpolateSurface, ParametersAverageTheRows) {
  // Two lines along u with different spacing: the u-parameters are their average.
  PointGrid q({3, 2});
  q(0, 0) = {0, 0, 0}; q(1, 0) = {1, 0, 0}; q(2, 0) = {4, 0, 0};
  q(0, 1) = {0, 1, 0}; q(1, 1) = {3, 1, 0}; q(2, 1) = {4, 1, 0};
  const auto tu = grid_parameters(q, 0, Parametrization::chord);
  EXPECT_DOUBLE_EQ(tu[1], 0.5 * (0.25 + 0.75));
  const auto tv = grid_parameters(q, 1, Parametrization::chord);
  EXPECT_EQ(tv, (std::vector<double>{0, 1}));
}

TEST(InterpolateSurface, InvalidInput) {
  auto g = test::rng(42);
  PointGrid q = test::random_grid(g, 4, 5);
  SurfaceInterpolationOptions o;
  o.degree_v = 5;
  EXPECT_ERRC((void)interpolate_surface(q, o), too_few_points, "degree 5 in v needs at least 6 points, got 5");
  PointGrid thin({1, 5});
  EXPECT_ERRC((void)interpolate_surface(thin), too_few_points, "at least 2 x 2 points, got 1 x 5");
  PointGrid bad = q;
  bad(2, 3).y = INFINITY;
  EXPECT_ERRC((void)interpolate_surface(bad), not_finite, "point [2][3]");
  PointGrid dup = q;
  for (std::size_t i = 0; i < 4; ++i) dup(i, 2) = dup(i, 1);  // column 2 repeats column 1 on every line
  EXPECT_ERRC((void)interpolate_surface(dup), zero_chord, "grid points 1 and 2 along v coincide on every line");
  PointGrid flat({3, 3}, Vec3{1, 1, 1});
  EXPECT_ERRC((void)interpolate_surface(flat), zero_chord, "every line of the grid along u has zero length");
}

// --- Volumes -----------------------------------------------------------------------

double max_error_at_data(const VolumeInterpolation& r, const PointGrid3& q) {
  double e = 0;
  for (std::size_t i = 0; i < q.extent(0); ++i)
    for (std::size_t j = 0; j < q.extent(1); ++j)
      for (std::size_t k = 0; k < q.extent(2); ++k)
        e = std::max(e, distance(r.volume.point(r.params_u[i], r.params_v[j], r.params_w[k]), q(i, j, k)));
  return e;
}

PointGrid3 random_grid3(std::mt19937_64& g, std::size_t nu, std::size_t nv, std::size_t nw, double noise) {
  PointGrid3 q({nu, nv, nw});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      for (std::size_t k = 0; k < nw; ++k)
        q(i, j, k) = Vec3{static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)} + test::random_point(g, noise);
  return q;
}

TEST(InterpolateVolume, PassesThroughRandomGridsOfManyShapesAndDegrees) {
  auto g = test::rng(250);
  for (int trial = 0; trial < 60; ++trial) {
    const std::size_t nu = 2 + static_cast<std::size_t>(trial % 7), nv = 2 + static_cast<std::size_t>((trial * 5) % 6),
                      nw = 2 + static_cast<std::size_t>((trial * 3) % 9);
    const auto q = random_grid3(g, nu, nv, nw, 0.35);
    VolumeInterpolationOptions o;
    o.degree_u = 1 + trial % std::min<int>(5, static_cast<int>(nu) - 1);
    o.degree_v = 1 + (trial / 2) % std::min<int>(5, static_cast<int>(nv) - 1);
    o.degree_w = 1 + (trial / 3) % std::min<int>(5, static_cast<int>(nw) - 1);
    o.param = static_cast<Parametrization>(trial % 3);
    const auto r = interpolate_volume(q, o);
    EXPECT_EQ(r.volume.control_points().shape(), q.shape());  // exactly (n+1) x (m+1) x (l+1) control points
    EXPECT_EQ(r.volume.degree_w(), *o.degree_w);
    // Three banded solves: rounding grows with the (small) condition numbers of the collocation matrices.
    EXPECT_LT(max_error_at_data(r, q), 1e-12 * test::bbox_diagonal(q.values())) << nu << "x" << nv << "x" << nw;
  }
}

TEST(InterpolateVolume, HeaderExample) {
  PointGrid3 q({5, 6, 4});
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 4; ++k) q(i, j, k) = {double(i), double(j) + 0.1 * i * i, double(k) + std::sin(i + j)};
  auto r = interpolate_volume(q);
  EXPECT_EQ(r.volume.degree_w(), 3);
  EXPECT_LT(distance(r.volume.point(r.params_u[2], r.params_v[3], r.params_w[1]), q(2, 3, 1)), 1e-12 * 10);  // rounding
}

TEST(InterpolateVolume, DefaultDegreesAndProgress) {
  auto g = test::rng(251);
  const auto q = random_grid3(g, 6, 3, 2, 0.3);
  std::vector<double> seen;
  VolumeInterpolationOptions o;
  o.progress = [&](double f) { seen.push_back(f); };
  const auto r = interpolate_volume(q, o);
  EXPECT_EQ(r.volume.degree_u(), 3);  // min(3, points - 1)
  EXPECT_EQ(r.volume.degree_v(), 2);
  EXPECT_EQ(r.volume.degree_w(), 1);
  EXPECT_EQ(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_LT(max_error_at_data(r, q), 1e-12 * test::bbox_diagonal(q.values()));
}

TEST(InterpolateVolume, ReproducesTrivariatePolynomialsEverywhere) {
  // A polynomial of degree (3, 2, 3) in uniform parameters lies in the spline space.
  auto f = [](double u, double v, double w) {
    return Vec3{u + 0.1 * v * w, v - u * u * w, u * u * u * v - 2 * w * w * w + u * v * w};
  };
  const std::size_t n[3] = {7, 5, 6};
  PointGrid3 q({n[0], n[1], n[2]});
  for (std::size_t i = 0; i < n[0]; ++i)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t k = 0; k < n[2]; ++k)
        q(i, j, k) = f(static_cast<double>(i) / static_cast<double>(n[0] - 1), static_cast<double>(j) / static_cast<double>(n[1] - 1),
                       static_cast<double>(k) / static_cast<double>(n[2] - 1));
  VolumeInterpolationOptions o;
  o.param = Parametrization::uniform;
  o.degree_v = 2;
  const auto r = interpolate_volume(q, o);
  for (double u : linspace(0, 1, 9))
    for (double v : linspace(0, 1, 9))
      for (double w : linspace(0, 1, 9)) EXPECT_LT(distance(r.volume.point(u, v, w), f(u, v, w)), 1e-14 * 4);
}

TEST(InterpolateVolume, ParametersAverageAllLinesAndSkipACollapsedLine) {
  // Lines along u: (j, k) in a 2 x 2 set; three have spacings 1, 3 (and one 3, 1), the
  // line (0, 0) collapses to one point and is left out of the average.
  PointGrid3 q({3, 2, 2});
  const double x[3][3] = {{0, 1, 4}, {0, 3, 4}, {0, 1, 4}};
  for (std::size_t j = 0; j < 2; ++j)
    for (std::size_t k = 0; k < 2; ++k) {
      const std::size_t line = 2 * j + k;
      for (std::size_t i = 0; i < 3; ++i)
        q(i, j, k) = line == 0 ? Vec3{0, 0, 0} : Vec3{x[line - 1][i], 2.0 * static_cast<double>(j), 2.0 * static_cast<double>(k)};
    }
  const auto tu = grid_parameters(q, 0, Parametrization::chord);
  EXPECT_DOUBLE_EQ(tu[1], (0.25 + 0.75 + 0.25) / 3);
  EXPECT_EQ(tu.front(), 0.0);
  EXPECT_EQ(tu.back(), 1.0);
  // Still interpolated, the collapsed line included.
  const auto r = interpolate_volume(q);
  EXPECT_LT(max_error_at_data(r, q), 1e-12 * test::bbox_diagonal(q.values()));
  EXPECT_EQ(r.params_u, tu);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_LT(norm(r.volume.control_points()(i, 0, 0)), 1e-14);  // the line stays a point
}

TEST(InterpolateVolume, SurfaceParametersUnchangedByTheGeneralCode) {
  // grid_parameters of a surface is the volume code with one axis of extent 1 less:
  // both must give the same numbers for the same lines.
  auto g = test::rng(252);
  const auto q2 = test::random_grid(g, 5, 7, 0.3);
  PointGrid3 q3({5, 7, 1});
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 7; ++j) q3(i, j, 0) = q2(i, j);
  for (auto param : {Parametrization::chord, Parametrization::centripetal}) {
    EXPECT_EQ(grid_parameters(q2, 0, param), grid_parameters(q3, 0, param));
    EXPECT_EQ(grid_parameters(q2, 1, param), grid_parameters(q3, 1, param));
  }
}

TEST(InterpolateVolume, InvalidInput) {
  auto g = test::rng(253);
  const auto q = random_grid3(g, 4, 3, 5, 0.3);
  EXPECT_ERRC((void)interpolate_volume(PointGrid3({2, 1, 3})), too_few_points,
              "at least 2 x 2 x 2 points, got 2 x 1 x 3");
  VolumeInterpolationOptions o;
  o.degree_v = 3;
  EXPECT_ERRC((void)interpolate_volume(q, o), too_few_points, "degree 3 in v needs at least 4 points, got 3");
  o.degree_v.reset();
  o.degree_u = 0;
  EXPECT_ERRC((void)interpolate_volume(q, o), invalid_degree, "degree 0 in u");
  PointGrid3 bad = q;
  bad(1, 2, 0).x = NAN;
  EXPECT_ERRC((void)interpolate_volume(bad), not_finite, "point [1][2][0] is");
  PointGrid3 dup = q;
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 3; ++j) dup(i, j, 2) = dup(i, j, 1);  // layer w = 2 repeats layer 1 on every line
  EXPECT_ERRC((void)interpolate_volume(dup), zero_chord, "grid points 1 and 2 along w coincide on every line");
  PointGrid3 flat = q;
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t k = 0; k < 5; ++k)
      for (std::size_t j = 0; j < 3; ++j) flat(i, j, k) = flat(i, 0, k);  // nothing varies along v
  EXPECT_ERRC((void)interpolate_volume(flat), zero_chord, "every line of the grid along v has zero length");
}

// The chord sums find a NaN or an infinity by the length of its line along v (not
// by a scan of every row): whatever the point, coordinate, value and
// parametrization, the error names the first bad point in storage order, as the
// scan would, on grids large enough for the chord pass to run on both threads.
TEST(InterpolateSurface, NonFinitePointIsNamedWhereverItIs) {
  auto g = test::rng(91);
  const PointGrid q = test::random_grid(g, 700, 400);
  const std::size_t places[][2] = {{0, 0}, {0, 399}, {699, 0}, {699, 399}, {350, 17}, {64, 200}};
  for (const Parametrization param : {Parametrization::uniform, Parametrization::chord, Parametrization::centripetal}) {
    SurfaceInterpolationOptions o;
    o.param = param;
    for (const auto& at : places)
      for (int c = 0; c < 3; ++c)
        for (const double bad : {NAN, INFINITY, -INFINITY}) {
          PointGrid b = q;
          b(at[0], at[1])[c] = bad;
          EXPECT_ERRC((void)interpolate_surface(b, o), not_finite,
                      "point [" + std::to_string(at[0]) + "][" + std::to_string(at[1]) + "] is");
        }
    PointGrid two = q;  // a late row (the second thread's) and an early one
    two(600, 5).z = NAN;
    two(3, 390).x = INFINITY;
    EXPECT_ERRC((void)interpolate_surface(two, o), not_finite, "point [3][390] is");
  }
}

TEST(InterpolateVolume, NonFinitePointIsNamedWhereverItIs) {
  auto g = test::rng(92);
  const auto q = random_grid3(g, 70, 60, 50, 0.3);
  const std::size_t places[][3] = {{0, 0, 0}, {69, 59, 49}, {0, 59, 0}, {69, 0, 49}, {35, 30, 25}};
  for (const Parametrization param : {Parametrization::uniform, Parametrization::chord}) {
    VolumeInterpolationOptions o;
    o.param = param;
    for (const auto& at : places)
      for (const double bad : {NAN, -INFINITY}) {
        PointGrid3 b = q;
        b(at[0], at[1], at[2]).y = bad;
        EXPECT_ERRC((void)interpolate_volume(b, o), not_finite,
                    "point [" + std::to_string(at[0]) + "][" + std::to_string(at[1]) + "][" + std::to_string(at[2]) +
                        "] is");
      }
  }
}

// A solve that overflows is refused, whichever pass overflows: the pass along u
// looks at its solution for NaN and infinities as it makes it, and the B-spline
// reads it again only when that pass found one (or when the solution is scaled back
// afterwards: extreme data measured by chords, whose other coordinates are large too
// so that the grid's lines keep their lengths when scaled down).
TEST(InterpolateSurface, SolutionBeyondTheLargestDoubleIsRefused) {
  constexpr double big = 1.5e308;
  for (const Parametrization param : {Parametrization::uniform, Parametrization::chord}) {
    SurfaceInterpolationOptions o;
    o.param = param;
    for (const bool along_u : {true, false}) {
      PointGrid zig({9, 8});
      for (std::size_t i = 0; i < 9; ++i)
        for (std::size_t j = 0; j < 8; ++j) {
          const std::size_t k = along_u ? i : j;
          zig(i, j) = {1e300 * static_cast<double>(i), 1e300 * static_cast<double>(j), (k % 2 == 0 ? big : -big)};
        }
      SCOPED_TRACE(along_u ? "zig-zag along u" : "zig-zag along v");
      EXPECT_ERRC((void)interpolate_surface(zig, o), not_finite, "control point [");
      PointGrid3 zig3({9, 8, 7});
      for (std::size_t i = 0; i < 9; ++i)
        for (std::size_t j = 0; j < 8; ++j)
          for (std::size_t l = 0; l < 7; ++l) {
            const std::size_t k = along_u ? i : l;
            zig3(i, j, l) = {1e300 * static_cast<double>(i), 1e300 * (static_cast<double>(j) + 0.1 * static_cast<double>(l)),
                             (k % 2 == 0 ? big : -big)};
          }
      VolumeInterpolationOptions o3;
      o3.param = param;
      EXPECT_ERRC((void)interpolate_volume(zig3, o3), not_finite, "control point [");
    }
  }
}

}  // namespace
}  // namespace interpatch
