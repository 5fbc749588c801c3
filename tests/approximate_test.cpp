// Approximation of curves, grids and volumes (include/interpatch/approximate.hpp).

#include "interpatch/approximate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "test_util.hpp"

namespace interpatch {
namespace {

const double nan_v = std::numeric_limits<double>::quiet_NaN();

double terrain(double u, double v) { return std::sin(3 * u) * std::cos(2 * v) + 0.3 * u * v; }

// A terrain over a uniform grid of [0, 2] × [0, 1], z noisy.
PointGrid noisy_terrain(std::mt19937_64& g, std::size_t n, std::size_t m, double noise_amp) {
  PointGrid q({n, m});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      const double u = static_cast<double>(i) / static_cast<double>(n - 1), v = static_cast<double>(j) / static_cast<double>(m - 1);
      q(i, j) = {2 * u, v, terrain(u, v) + test::uniform(g, -noise_amp, noise_amp)};
    }
  return q;
}

double max_distance_at_data(const BSplineSurface& s, const std::vector<double>& pu, const std::vector<double>& pv,
                            const PointGrid& target) {
  double worst = 0;
  for (std::size_t i = 0; i < pu.size(); ++i)
    for (std::size_t j = 0; j < pv.size(); ++j)
      if (!std::isnan(target(i, j).z)) worst = std::max(worst, distance(s.point(pu[i], pv[j]), target(i, j)));
  return worst;
}

SurfaceApproximationOptions uniform_options() {
  SurfaceApproximationOptions o;
  o.param = Parametrization::uniform;
  return o;
}

TEST(ApproximateSurface, ToleranceBringsNoisyDataBackWithinThreeSigma) {
  for (unsigned seed = 0; seed < 3; ++seed) {
    auto g = test::rng(seed);
    const double sigma = 0.01;
    // Uniform noise of standard deviation σ: within ±√3 σ.
    const double amp = std::sqrt(3.0) * sigma;
    PointGrid q = noisy_terrain(g, 60, 45, amp);
    PointGrid truth({60, 45});
    for (std::size_t i = 0; i < 60; ++i)
      for (std::size_t j = 0; j < 45; ++j) truth(i, j) = {q(i, j).x, q(i, j).y, terrain(static_cast<double>(i) / 59, static_cast<double>(j) / 44)};
    auto o = uniform_options();
    o.tolerance = 2.5 * sigma;
    const auto r = approximate_surface(q, o);
    EXPECT_LE(r.report.max_error, *o.tolerance) << seed;
    EXPECT_NEAR(max_distance_at_data(r.surface, r.params_u, r.params_v, q), r.report.max_error, 1e-12) << seed;
    EXPECT_LE(max_distance_at_data(r.surface, r.params_u, r.params_v, truth), 3 * sigma) << seed;
    // It smooths rather than interpolates: far fewer control points than data.
    EXPECT_LT(r.report.control_points[0] * r.report.control_points[1], 60 * 45 / 4) << seed;
    EXPECT_EQ(r.report.lambda, 0.0);
  }
}

// Grids of 2^18 points and more grow their first knots on every 4th line: the result
// still keeps every point present within the tolerance, and the truth within 3σ.
TEST(ApproximateSurface, LargeGridsToATolerance) {
  auto g = test::rng(11);
  const double sigma = 0.01, amp = std::sqrt(3.0) * sigma;  // uniform noise of standard deviation σ
  PointGrid q = noisy_terrain(g, 520, 510, amp);
  for (std::size_t i = 200; i < 260; ++i)
    for (std::size_t j = 300; j < 330; ++j) q(i, j).z = nan_v;
  auto o = uniform_options();
  o.tolerance = 2.5 * sigma;
  const auto r = approximate_surface(q, o);
  EXPECT_LE(r.report.max_error, *o.tolerance);
  EXPECT_EQ(r.report.missing, 60u * 30u);
  double worst = 0;
  for (std::size_t i = 0; i < 520; i += 7)
    for (std::size_t j = 0; j < 510; j += 5) {
      const double z = r.surface.point(r.params_u[i], r.params_v[j]).z;
      worst = std::max(worst, std::abs(z - terrain(static_cast<double>(i) / 519, static_cast<double>(j) / 509)));
    }
  EXPECT_LE(worst, 3 * sigma);
  EXPECT_LT(r.report.control_points[0] * r.report.control_points[1], 400);
}

TEST(ApproximateSurface, AsManyControlPointsAsDataReproduceInterpolation) {
  for (unsigned seed = 0; seed < 4; ++seed) {
    auto g = test::rng(seed);
    const std::size_t n = 5 + seed * 3, m = 7 + seed;
    const PointGrid q = test::random_grid(g, n, m);
    for (auto param : {Parametrization::chord, Parametrization::centripetal, Parametrization::uniform}) {
      SurfaceApproximationOptions o;
      o.param = param;
      o.control_points = std::array<int, 2>{static_cast<int>(n), static_cast<int>(m)};
      const auto a = approximate_surface(q, o);
      SurfaceInterpolationOptions io;
      io.param = param;
      const auto in = interpolate_surface(q, io);
      ASSERT_EQ(a.surface.knots_u(), in.surface.knots_u());
      ASSERT_EQ(a.surface.knots_v(), in.surface.knots_v());
      // The normal equations square the collocation matrix's condition number (at most
      // about 1e3 for these grids): 1e-8 of the grid's extent leaves room for it.
      const auto& ca = a.surface.control_points().values();
      const auto& ci = in.surface.control_points().values();
      for (std::size_t k = 0; k < ca.size(); ++k) EXPECT_LT(distance(ca[k], ci[k]), 1e-8 * static_cast<double>(n + m));
      EXPECT_LT(a.report.max_error, 1e-8 * static_cast<double>(n + m));
    }
  }
}

// The least-squares fit a + b u + c v + d u v of each coordinate at the data (the
// null space of the fairness term), solved from its 4 × 4 normal equations.
PointGrid bilinear_fit(const PointGrid& q, const std::vector<double>& pu, const std::vector<double>& pv) {
  double m[4][5][3] = {};
  auto basis = [](double u, double v) { return std::array<double, 4>{1, u, v, u * v}; };
  for (std::size_t i = 0; i < pu.size(); ++i)
    for (std::size_t j = 0; j < pv.size(); ++j) {
      const auto b = basis(pu[i], pv[j]);
      for (int k = 0; k < 3; ++k)
        for (int r = 0; r < 4; ++r) {
          for (int c = 0; c < 4; ++c) m[r][c][k] += b[r] * b[c];
          m[r][4][k] += b[r] * q(i, j)[k];
        }
    }
  std::array<std::array<double, 4>, 3> coef{};
  for (int k = 0; k < 3; ++k) {  // Gauss–Jordan on a 4 × 4 positive definite system
    double a[4][5];
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 5; ++c) a[r][c] = m[r][c][k];
    for (int piv = 0; piv < 4; ++piv)
      for (int r = 0; r < 4; ++r) {
        if (r == piv) continue;
        const double f = a[r][piv] / a[piv][piv];
        for (int c = 0; c < 5; ++c) a[r][c] -= f * a[piv][c];
      }
    for (int r = 0; r < 4; ++r) coef[static_cast<std::size_t>(k)][static_cast<std::size_t>(r)] = a[r][4] / a[r][r];
  }
  PointGrid out(q.shape());
  for (std::size_t i = 0; i < pu.size(); ++i)
    for (std::size_t j = 0; j < pv.size(); ++j) {
      const auto b = basis(pu[i], pv[j]);
      for (int k = 0; k < 3; ++k) {
        double s = 0;
        for (int r = 0; r < 4; ++r) s += coef[static_cast<std::size_t>(k)][static_cast<std::size_t>(r)] * b[static_cast<std::size_t>(r)];
        out(i, j)[k] = s;
      }
    }
  return out;
}

TEST(ApproximateSurface, SmoothingLimits) {
  for (unsigned seed = 0; seed < 3; ++seed) {
    auto g = test::rng(seed);
    const PointGrid q = noisy_terrain(g, 14, 11, 0.05);
    double previous = std::numeric_limits<double>::infinity();
    // λ → 0: the fit tends to the interpolant (14 x 11 control points, one per point).
    for (double lambda : {1e-4, 1e-7, 1e-10, 1e-13}) {
      auto o = uniform_options();
      o.smoothing = lambda;
      const auto r = approximate_surface(q, o);
      const double d = max_distance_at_data(r.surface, r.params_u, r.params_v, q);
      EXPECT_LT(d, previous) << seed << " " << lambda;
      previous = d;
    }
    // Rounding of a system whose fairness part is 1e-13 of the data part: 1e-6 of the data's extent.
    EXPECT_LT(previous, 1e-6) << seed;
    // λ → ∞: the least-squares bilinear fit in the parameters, the fairness term's null space.
    double away = std::numeric_limits<double>::infinity();
    for (double lambda : {1e0, 1e1, 1e2, 1e3}) {
      auto o = uniform_options();
      o.smoothing = lambda;
      const auto r = approximate_surface(q, o);
      const PointGrid plane = bilinear_fit(q, r.params_u, r.params_v);
      const double d = max_distance_at_data(r.surface, r.params_u, r.params_v, plane);
      EXPECT_LT(d, away) << seed << " " << lambda;
      away = d;
      EXPECT_EQ(r.report.lambda, lambda);
    }
    // The distance shrinks like 1 / λ (about 2e-6 at λ = 1e3); beyond 1e4 the rounding
    // of a system whose fairness part is that many times the data part takes over.
    EXPECT_LT(away, 1e-5) << seed;
  }
}

TEST(ApproximateSurface, AutoSmoothingLeavesResidualsNearTheNoise) {
  for (unsigned seed = 0; seed < 3; ++seed) {
    auto g = test::rng(seed + 10);
    const double sigma = 0.02;
    PointGrid q({40, 36});
    std::normal_distribution<double> noise(0.0, sigma);
    for (std::size_t i = 0; i < 40; ++i)
      for (std::size_t j = 0; j < 36; ++j) {
        const double u = static_cast<double>(i) / 39, v = static_cast<double>(j) / 35;
        q(i, j) = {2 * u, v, terrain(u, v) + noise(g)};
      }
    auto o = uniform_options();
    o.auto_smoothing = true;
    const auto r = approximate_surface(q, o);
    EXPECT_GT(r.report.rms_error, 0.7 * sigma) << seed;
    EXPECT_LT(r.report.rms_error, 1.3 * sigma) << seed;
    EXPECT_GT(r.report.lambda, 0.0);
  }
}

// The surface over the hole stays within the range of the data around it, give or
// take 5% of that range.
void expect_hole_filled(const SurfaceApproximation& r, const PointGrid& q, std::size_t i0, std::size_t i1, std::size_t j0,
                        std::size_t j1, const char* what) {
  const std::size_t n = q.extent(0), m = q.extent(1);
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = (i0 > 2 ? i0 - 2 : 0); i < std::min(n, i1 + 2); ++i)
    for (std::size_t j = (j0 > 2 ? j0 - 2 : 0); j < std::min(m, j1 + 2); ++j)
      if (!std::isnan(q(i, j).z)) {
        lo = std::min(lo, q(i, j).z);
        hi = std::max(hi, q(i, j).z);
      }
  const double slack = 0.05 * (hi - lo);
  const double ua = r.params_u[i0 > 0 ? i0 - 1 : 0], ub = r.params_u[std::min(n - 1, i1)];
  const double va = r.params_v[j0 > 0 ? j0 - 1 : 0], vb = r.params_v[std::min(m - 1, j1)];
  for (int a = 0; a <= 20; ++a)
    for (int b = 0; b <= 20; ++b) {
      const double z = r.surface.point(ua + (ub - ua) * a / 20, va + (vb - va) * b / 20).z;
      EXPECT_GE(z, lo - slack) << what;
      EXPECT_LE(z, hi + slack) << what;
    }
}

TEST(ApproximateSurface, HolesAreFilledWithoutOvershoot) {
  auto g = test::rng(5);
  PointGrid q = noisy_terrain(g, 40, 30, 0.005);
  for (std::size_t i = 14; i < 22; ++i)
    for (std::size_t j = 9; j < 18; ++j) q(i, j).z = nan_v;  // an 8 x 9 void
  for (std::size_t j = 0; j < 30; ++j) q(30, j) = {nan_v, nan_v, nan_v};  // a whole row
  std::size_t missing = 0;
  for (const Vec3& p : q.values()) missing += std::isnan(p.z) ? 1 : 0;
  {
    auto o = uniform_options();
    o.tolerance = 0.02;
    const auto r = approximate_surface(q, o);
    EXPECT_EQ(r.report.missing, missing);
    EXPECT_LE(r.report.max_error, 0.02);
    EXPECT_GT(r.report.lambda, 0.0);
    expect_hole_filled(r, q, 14, 22, 9, 18, "tolerance, void");
    expect_hole_filled(r, q, 30, 31, 0, 30, "tolerance, row");
  }
  {
    auto o = uniform_options();
    o.smoothing = 1e-6;
    const auto r = approximate_surface(q, o);
    expect_hole_filled(r, q, 14, 22, 9, 18, "smoothing, void");
    expect_hole_filled(r, q, 30, 31, 0, 30, "smoothing, row");
  }
  {
    auto o = uniform_options();
    o.auto_smoothing = true;  // cross-validation over the points present, λ never below the weight that fills
    const auto r = approximate_surface(q, o);
    EXPECT_GT(r.report.lambda, 0.0);
    EXPECT_EQ(r.report.missing, missing);
    expect_hole_filled(r, q, 14, 22, 9, 18, "auto, void");
    expect_hole_filled(r, q, 30, 31, 0, 30, "auto, row");
  }
  {
    auto o = uniform_options();
    o.control_points = std::array<int, 2>{40, 30};  // as many as data: the hole holds control points with no data
    const auto r = approximate_surface(q, o);
    EXPECT_LT(r.report.max_error, 1e-3);  // the fill term barely touches the data elsewhere
    expect_hole_filled(r, q, 14, 22, 9, 18, "control points, void");
  }
}

TEST(ApproximateSurface, MatchesAnIndependentLeastSquaresFit) {
  std::ifstream in(std::string(INTERPATCH_TEST_DATA) + "/approximate_reference.json");
  ASSERT_TRUE(in.good());
  const auto ref = nlohmann::json::parse(in);
  for (const auto& c : ref["cases"]) {
    const std::size_t n = c["shape"][0], m = c["shape"][1];
    PointGrid q({n, m});
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < m; ++j)
        for (int k = 0; k < 3; ++k) q(i, j)[k] = c["points"][i][j][static_cast<std::size_t>(k)].get<double>();
    auto o = uniform_options();
    o.control_points = std::array<int, 2>{c["control_points"][0].get<int>(), c["control_points"][1].get<int>()};
    if (c.contains("weights")) {
      o.weights = Grid<double, 2>({n, m});
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < m; ++j) o.weights(i, j) = c["weights"][i][j].get<double>();
    }
    const auto r = approximate_surface(q, o);
    const auto knots_u = c["knots_u"].get<std::vector<double>>(), knots_v = c["knots_v"].get<std::vector<double>>();
    const auto& ku = r.surface.knots_u().values();
    ASSERT_EQ(ku.size(), knots_u.size() + 8);
    // The knot rule in double precision on both sides: a few units in the last place.
    for (std::size_t k = 0; k < knots_u.size(); ++k) EXPECT_NEAR(ku[k + 4], knots_u[k], 1e-15);
    for (std::size_t k = 0; k < knots_v.size(); ++k) EXPECT_NEAR(r.surface.knots_v().values()[k + 4], knots_v[k], 1e-15);
    // Two solutions of the same least-squares problem (FITPACK's Givens rotations, our
    // normal equations, condition number about 1e2 squared): 1e-9 of the errors' size.
    EXPECT_NEAR(r.report.max_error, c["max_error"].get<double>(), 1e-9) << c["name"];
    EXPECT_NEAR(r.report.rms_error, c["rms_error"].get<double>(), 1e-9) << c["name"];
    EXPECT_EQ(r.report.max_error_at, (std::vector<std::size_t>{c["max_error_at"][0], c["max_error_at"][1]})) << c["name"];
  }
}

TEST(ApproximateSurface, ScalingTheDataScalesTheFit) {
  auto g = test::rng(3);
  const PointGrid q = noisy_terrain(g, 30, 24, 0.01);
  auto o = uniform_options();
  o.tolerance = 0.02;
  const auto r = approximate_surface(q, o);
  for (double scale : {8.0, 3.7, 1e-3}) {
    PointGrid s = q;
    for (Vec3& p : s.values()) p = scale * p;
    auto os = o;
    os.tolerance = scale * *o.tolerance;
    const auto rs = approximate_surface(s, os);
    ASSERT_EQ(rs.report.control_points, r.report.control_points) << scale;
    // The same solve on scaled numbers: rounding differs at 1e-13 of the extent.
    EXPECT_NEAR(rs.report.max_error, scale * r.report.max_error, 1e-12 * scale) << scale;
    const auto& a = r.surface.control_points().values();
    const auto& b = rs.surface.control_points().values();
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_LT(distance(scale * a[k], b[k]), 1e-12 * scale) << scale;
  }
  // Smoothing too: λ has no unit of length.
  auto sm = uniform_options();
  sm.smoothing = 1e-5;
  const auto r1 = approximate_surface(q, sm);
  PointGrid s = q;
  for (Vec3& p : s.values()) p = 5.0 * p;
  const auto r5 = approximate_surface(s, sm);
  EXPECT_NEAR(r5.report.max_error, 5 * r1.report.max_error, 1e-11);
}

TEST(ApproximateSurface, WeightsPullTheFitTowardsTheirPoints) {
  auto g = test::rng(8);
  const PointGrid q = noisy_terrain(g, 25, 20, 0.05);
  auto o = uniform_options();
  o.control_points = std::array<int, 2>{8, 7};
  const auto plain = approximate_surface(q, o);
  o.weights = Grid<double, 2>({25, 20}, 1.0);
  o.weights(12, 9) = 1e6;
  const auto heavy = approximate_surface(q, o);
  const double before = distance(plain.surface.point(plain.params_u[12], plain.params_v[9]), q(12, 9));
  const double after = distance(heavy.surface.point(heavy.params_u[12], heavy.params_v[9]), q(12, 9));
  EXPECT_LT(after, 1e-3 * before);
  // Zero weights are missing points.
  o.weights = Grid<double, 2>({25, 20}, 1.0);
  o.weights(3, 3) = 0;
  PointGrid holed = q;
  holed(3, 3).z = nan_v;
  auto oh = uniform_options();
  oh.control_points = o.control_points;
  const auto a = approximate_surface(q, o), b = approximate_surface(holed, oh);
  EXPECT_EQ(a.surface.control_points().values(), b.surface.control_points().values());
}

TEST(ApproximateSurface, ClosedDirectionsStaySmoothAcrossTheSeam) {
  auto g = test::rng(2);
  PointGrid q({12, 40});
  for (std::size_t i = 0; i < 12; ++i)
    for (std::size_t j = 0; j < 40; ++j) {
      const double a = 2 * M_PI * static_cast<double>(j) / 40;
      const double r = 1 + 0.1 * std::cos(3 * a) + test::uniform(g, -0.002, 0.002);
      q(i, j) = {r * std::cos(a), r * std::sin(a), 0.2 * static_cast<double>(i)};
    }
  SurfaceApproximationOptions o;
  o.periodic = {false, true};
  o.tolerance = 0.01;
  const auto r = approximate_surface(q, o);
  EXPECT_LE(r.report.max_error, 0.01);
  EXPECT_TRUE(r.surface.knots_v().periodic());
  const auto [v0, v1] = r.surface.domain_v();
  for (double u : {0.1, 0.5, 0.9}) {
    // One period on is the same point: a closed direction wraps exactly (rounding of the parameter only).
    EXPECT_LT(distance(r.surface.point(u, v0 + 1e-9), r.surface.point(u, v1 - 1e-9)), 1e-7);
  }
}

TEST(ApproximateCurve, ToleranceAndMissingPoints) {
  auto g = test::rng(4);
  std::vector<Vec3> q;
  for (int i = 0; i <= 200; ++i) {
    const double t = i / 200.0;
    q.push_back({t, std::sin(6 * t) + test::uniform(g, -0.003, 0.003), 0.5 * t * t});
  }
  q[50] = {nan_v, nan_v, nan_v};
  CurveApproximationOptions o;
  o.tolerance = 0.01;
  const auto r = approximate_curve(q, o);
  EXPECT_LE(r.report.max_error, 0.01);
  EXPECT_EQ(r.report.missing, 1u);
  EXPECT_LT(r.curve.control_points().size(), 40u);
  double worst = 0;
  for (std::size_t i = 0; i < q.size(); ++i)
    if (i != 50) worst = std::max(worst, distance(r.curve.point(r.params[i]), q[i]));
  EXPECT_NEAR(worst, r.report.max_error, 1e-12);
}

TEST(ApproximateCurve, ClosedCurvesCloseSmoothly) {
  auto g = test::rng(9);
  std::vector<Vec3> q;
  for (int i = 0; i < 120; ++i) {
    const double a = 2 * M_PI * i / 120;
    q.push_back({(2 + 0.3 * std::cos(5 * a)) * std::cos(a), (2 + 0.3 * std::cos(5 * a)) * std::sin(a),
                 test::uniform(g, -0.002, 0.002)});
  }
  q.push_back(q.front());  // the closing point, left out
  for (int degree : {2, 3}) {
    CurveApproximationOptions o;
    o.periodic = {true};
    o.degree = {degree};
    o.tolerance = 0.01;
    const auto r = approximate_curve(q, o);
    EXPECT_LE(r.report.max_error, 0.01) << degree;
    EXPECT_TRUE(r.curve.knots().periodic()) << degree;
    EXPECT_EQ(r.params.size(), q.size()) << degree;  // the closing point's parameter: the first's, one period on
    double worst = 0;
    for (std::size_t i = 0; i < q.size(); ++i) worst = std::max(worst, distance(r.curve.point(r.params[i]), q[i]));
    EXPECT_NEAR(worst, r.report.max_error, 1e-12) << degree;
    EXPECT_LT(r.curve.control_points().size(), 60u) << degree;
  }
}

TEST(ApproximateVolume, AsManyControlPointsAsDataReproduceInterpolationAndHolesFill) {
  auto g = test::rng(6);
  PointGrid3 q({6, 7, 5});
  for (std::size_t i = 0; i < 6; ++i)
    for (std::size_t j = 0; j < 7; ++j)
      for (std::size_t k = 0; k < 5; ++k)
        q(i, j, k) = Vec3{double(i), double(j), double(k)} + test::random_point(g, 0.2);
  VolumeApproximationOptions o;
  o.control_points = std::array<int, 3>{6, 7, 5};
  const auto a = approximate_volume(q, o);
  const auto in = interpolate_volume(q);
  const auto& ca = a.volume.control_points().values();
  const auto& ci = in.volume.control_points().values();
  ASSERT_EQ(ca.size(), ci.size());
  // As for surfaces: the normal equations' squared condition number.
  for (std::size_t k = 0; k < ca.size(); ++k) EXPECT_LT(distance(ca[k], ci[k]), 1e-8);
  PointGrid3 holed = q;
  holed(3, 3, 2) = {nan_v, nan_v, nan_v};
  VolumeApproximationOptions t;
  t.tolerance = 0.3;
  const auto h = approximate_volume(holed, t);
  EXPECT_LE(h.report.max_error, 0.3);
  EXPECT_EQ(h.report.missing, 1u);
  // The filled point lies among its neighbours (spacing 1): within one spacing of where the grid puts it.
  EXPECT_LT(distance(h.volume.point(h.params_u[3], h.params_v[3], h.params_w[2]), Vec3{3, 3, 2}), 1.0);
}

template <class F>
void expect_code(errc code, F&& f) {
  try {
    f();
    ADD_FAILURE() << "no error, expected " << to_string(code);
  } catch (const error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
  }
}

TEST(ApproximateErrors, EachCode) {
  auto g = test::rng(1);
  const PointGrid q = test::random_grid(g, 8, 9);
  auto with = [&](auto change) {
    SurfaceApproximationOptions o;
    o.tolerance = 0.1;
    change(o);
    return o;
  };
  expect_code(errc::wrong_type, [&] { (void)approximate_surface(q, SurfaceApproximationOptions{}); });
  expect_code(errc::wrong_type, [&] { (void)approximate_surface(q, with([](auto& o) { o.smoothing = 1.0; })); });
  expect_code(errc::wrong_type, [&] { (void)approximate_surface(q, with([](auto& o) { o.tolerance = 0.0; })); });
  expect_code(errc::wrong_type, [&] { (void)approximate_surface(q, with([](auto& o) { o.tolerance = -1.0; })); });
  expect_code(errc::wrong_type, [&] {
    (void)approximate_surface(q, with([](auto& o) {
      o.tolerance.reset();
      o.smoothing = -1.0;
    }));
  });
  expect_code(errc::too_few_points, [&] {
    (void)approximate_surface(q, with([](auto& o) {
      o.tolerance.reset();
      o.control_points = std::array<int, 2>{9, 9};
    }));
  });
  expect_code(errc::too_few_points, [&] {
    (void)approximate_surface(q, with([](auto& o) {
      o.tolerance.reset();
      o.control_points = std::array<int, 2>{3, 5};
    }));
  });
  PointGrid all_missing = q;
  for (Vec3& p : all_missing.values()) p.y = nan_v;
  expect_code(errc::too_few_points, [&] { (void)approximate_surface(all_missing, with([](auto&) {})); });
  expect_code(errc::size_mismatch, [&] { (void)approximate_surface(q, with([](auto& o) { o.weights = Grid<double, 2>({8, 8}, 1.0); })); });
  expect_code(errc::invalid_weight, [&] {
    (void)approximate_surface(q, with([](auto& o) {
      o.weights = Grid<double, 2>({8, 9}, 1.0);
      o.weights(2, 3) = -0.5;
    }));
  });
  expect_code(errc::not_finite, [&] {
    (void)approximate_surface(q, with([](auto& o) {
      o.weights = Grid<double, 2>({8, 9}, 1.0);
      o.weights(2, 3) = nan_v;
    }));
  });
  PointGrid inf = q;
  inf(1, 1).x = std::numeric_limits<double>::infinity();
  expect_code(errc::not_finite, [&] { (void)approximate_surface(inf, with([](auto&) {})); });
  expect_code(errc::invalid_degree, [&] { (void)approximate_surface(q, with([](auto& o) { o.degree[0] = 0; })); });
}

}  // namespace
}  // namespace interpatch
