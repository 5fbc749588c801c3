// Scattered points (include/interpatch/approximate.hpp, approximate_scattered): the
// height field's x(u, v) = u, a tolerance met at every point and converging, sites
// given equal to "xy", voids filled within the data around them, the same bits on any
// thread count, invariance under translation and reordering, and every refusal.
// Distances are measured by tests/property/promise_harness.hpp's own Cox–de Boor,
// which shares no code with the fit.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>
#include <cmath>
#include <numeric>
#include <random>

#include "interpatch/approximate.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/spec.hpp"
#include "constructions/scattered/scattered_system.hpp"
#include "property/promise_harness.hpp"
#include "thread_util.hpp"

namespace interpatch {
namespace {

using promise::Tensor;
using promise::tensor_of;

// A smooth height field over [0, 1000] × [0, 800] (metres).
double height(double x, double y) { return 40 * std::sin(x / 170) * std::cos(y / 130) + 0.02 * x + 5 * std::sin((x + y) / 90); }

std::vector<Vec3> survey(std::mt19937_64& g, std::size_t n, double noise = 0, Vec3 shift = {}) {
  std::uniform_real_distribution<double> ux(0, 1000), uy(0, 800);
  std::normal_distribution<double> e(0, noise > 0 ? noise : 1);
  std::vector<Vec3> q(n);
  for (Vec3& p : q) {
    const double x = ux(g), y = uy(g);
    p = Vec3{x, y, height(x, y) + (noise > 0 ? e(g) : 0.0)} + shift;
  }
  return q;
}

// The largest distance from the points present to the surface at their sites, by the
// harness's own evaluation of the finished spline.
double own_max_distance(const ScatteredApproximation& r, std::span<const Vec3> q) {
  const Tensor t = tensor_of(r.surface);
  double worst = 0;
  for (std::size_t k = 0; k < q.size(); ++k)
    if (is_finite(q[k])) worst = std::max(worst, distance(t.eval(r.sites[k][0], r.sites[k][1]).s, q[k]));
  return worst;
}

ScatteredApproximationOptions xy_tolerance(double d) {
  ScatteredApproximationOptions o;
  o.param = ScatteredParam::xy;
  o.tolerance = d;
  return o;
}

TEST(Scattered, HeightFieldHasXEqualToUAndYEqualToV) {
  std::mt19937_64 g(11);
  // Far from the origin, as survey coordinates are (UTM metres).
  const auto q = survey(g, 3000, 0.1, {512000, 4180000, 300});
  const auto r = approximate_scattered(q, xy_tolerance(0.5));
  const Tensor t = tensor_of(r.surface);
  const auto [u0, u1] = r.domain[0];
  const auto [v0, v1] = r.domain[1];
  double worst = 0;
  for (int i = 0; i <= 37; ++i)
    for (int j = 0; j <= 29; ++j) {
      const double u = u0 + (u1 - u0) * i / 37, v = v0 + (v1 - v0) * j / 29;
      const Vec3 p = t.eval(u, v).s;
      worst = std::max({worst, std::abs(p.x - u) / std::abs(u), std::abs(p.y - v) / std::abs(v)});
    }
  EXPECT_LE(worst, 1e-12);  // the promise: to rounding, relative
  EXPECT_EQ(r.surface.domain_u().first, u0);
  EXPECT_EQ(r.surface.domain_u().second, u1);
}

TEST(Scattered, ToleranceIsMetAtEveryPointAndTheFitConverges) {
  std::mt19937_64 g(12);
  const auto q = survey(g, 4000);
  double last = std::numeric_limits<double>::infinity();
  for (const double d : {2.0, 0.2, 0.02, 0.002}) {
    const auto r = approximate_scattered(q, xy_tolerance(d));
    const double own = own_max_distance(r, q);
    EXPECT_LE(own, d) << d;
    // The report is the same check's figure; the own evaluation agrees to rounding.
    EXPECT_NEAR(r.report.max_error, own, 1e-9 * 1000) << d;
    // Off the data too: the true function between the points comes closer each time.
    std::mt19937_64 h(99);
    const auto probe = survey(h, 500);
    double off = 0;
    const Tensor t = tensor_of(r.surface);
    for (const Vec3& p : probe) off = std::max(off, std::abs(t.eval(p.x, p.y).s.z - p.z));
    EXPECT_LT(off, last) << d;
    last = off;
  }
  EXPECT_LT(last, 0.01);  // 4000 points of a smooth field: to a hundredth between them
}

TEST(Scattered, SitesGivenAsXAndYGiveTheHeightField) {
  std::mt19937_64 g(13);
  const auto q = survey(g, 1500, 0.3);
  ScatteredApproximationOptions xy;
  xy.param = ScatteredParam::xy;
  xy.control_points = std::array<int, 2>{14, 12};
  ScatteredApproximationOptions given = xy;
  given.param = ScatteredParam::sites;
  for (const Vec3& p : q) given.sites.push_back({p.x, p.y});
  const auto a = approximate_scattered(q, xy), b = approximate_scattered(q, given);
  ASSERT_EQ(a.report.control_points, b.report.control_points);
  const PointGrid& ca = a.surface.control_points();
  const PointGrid& cb = b.surface.control_points();
  // x and y fitted by least squares reproduce the plane u, v they lie on (J vanishes
  // there); the solver's residual of 1e-12 of the data bounds the difference.
  for (std::size_t i = 0; i < ca.size(); ++i) EXPECT_LE(distance(ca.values()[i], cb.values()[i]), 1e-6) << i;
}

// A survey with a round void: inside it the surface stays within the range of the
// heights on the ring around it (5 % of that range at most beyond), never swinging out.
TEST(Scattered, AVoidIsFilledWithinTheDataAroundIt) {
  std::mt19937_64 g(14);
  auto q = survey(g, 6000, 0.2);
  const double cx = 480, cy = 390, radius = 140;
  double ring_lo = 1e300, ring_hi = -1e300;
  for (Vec3& p : q) {
    const double d = std::hypot(p.x - cx, p.y - cy);
    if (d < radius) p.z = std::nan("");
    else if (d < radius + 60) ring_lo = std::min(ring_lo, p.z), ring_hi = std::max(ring_hi, p.z);
  }
  // Tolerances above the noise's largest draw (about 4 σ among 6000): they can hold.
  for (const double d : {2.0, 1.0}) {
    const auto r = approximate_scattered(q, xy_tolerance(d));
    const Tensor t = tensor_of(r.surface);
    const double slack = 0.05 * (ring_hi - ring_lo);
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j <= 40; ++j) {
        const double x = cx - radius + 2 * radius * i / 40, y = cy - radius + 2 * radius * j / 40;
        if (std::hypot(x - cx, y - cy) >= radius) continue;
        const double z = t.eval(x, y).s.z;
        EXPECT_GE(z, ring_lo - slack) << d << " at " << x << ", " << y;
        EXPECT_LE(z, ring_hi + slack) << d << " at " << x << ", " << y;
      }
    EXPECT_GT(r.report.missing, 100u);
  }
}

using test::with_threads;

// A net of multigrid's size, and a tolerance whose refinement reaches one (its coarse
// levels the matrices of the fits before it).
TEST(Scattered, TheSameBitsOnOneTwoAndThreeThreads) {
  std::mt19937_64 g(15);
  const auto q = survey(g, 40000, 0.05);
  ScatteredApproximationOptions net, tolerance;
  net.param = tolerance.param = ScatteredParam::xy;
  net.control_points = std::array<int, 2>{150, 140};
  tolerance.tolerance = 0.2;  // missed at 35 x 35, kept at 67 x 67 (0.194): past 4096 control points
  for (const auto* o : {&net, &tolerance}) {
    std::vector<std::vector<Vec3>> nets;
    for (const int threads : {1, 2, 3}) {
      const auto r = with_threads(threads, [&] { return approximate_scattered(q, *o); });
      nets.emplace_back(r.surface.control_points().values().begin(), r.surface.control_points().values().end());
      if (o == &tolerance) {
        EXPECT_GT(r.report.control_points[0] * r.report.control_points[1], 4096);
      }
    }
    for (std::size_t t = 1; t < nets.size(); ++t) {
      ASSERT_EQ(nets[t].size(), nets[0].size());
      EXPECT_EQ(0, std::memcmp(nets[t].data(), nets[0].data(), nets[0].size() * sizeof(Vec3))) << t + 1 << " threads";
    }
  }
}

// Conjugate gradients on a net past the factored ones (90 000 control points, 3
// columns), 40 steps: every sum in fixed blocks, the same bits on any thread count.
TEST(Scattered, ConjugateGradientsGiveTheSameBitsOnAnyThreadCount) {
  using namespace detail::scattered;
  const Net net(3, 3, 300, 300);
  std::mt19937_64 g(19);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<std::array<double, 2>> site(200000);
  std::vector<double> weight(site.size(), 1.0), value(3 * site.size());
  for (auto& s : site) s = {U(g), U(g)};
  for (double& v : value) v = U(g) - 0.5;
  System sys{NetMatrix(net.nu, net.nv, 3, 3), std::vector<double>(3 * net.size(), 0.0), 3};
  add_data_term(net, Samples{site, weight, value, 3}, sys);
  add_fairness(net, &sys.a, 1e-6);
  std::vector<std::vector<double>> out;
  for (const int threads : {1, 2, 3}) {
    out.emplace_back(sys.rhs.size(), 0.0);
    const Solved s = with_threads(threads, [&] { return solve_cg(sys.a, sys.rhs, out.back(), 3, 1e-30, 40); });
    EXPECT_EQ(s.iterations, 40);
  }
  for (std::size_t t = 1; t < out.size(); ++t)
    EXPECT_EQ(0, std::memcmp(out[t].data(), out[0].data(), out[0].size() * sizeof(double))) << t + 1 << " threads";
}

// Points missing (NaN) or of weight 0 take no part: the fit is the same, to the bit, as
// that of the other points alone, which keeps no weights at all. For each way of
// placing the sites, on a factored net and on one past them (conjugate gradients over
// multigrid), the points read from the input through the fit's own order.
TEST(Scattered, PointsLeftOutAreAsIfAbsent) {
  std::mt19937_64 g(23);
  const auto all = survey(g, 9000, 0.05);
  std::vector<Vec3> with = all, without;
  std::vector<std::array<double, 2>> sites_with, sites_without;
  std::vector<double> weights(all.size(), 1.0);
  for (std::size_t k = 0; k < all.size(); ++k) {
    const bool nan = k % 97 == 3, zero = k % 89 == 5;
    if (nan) with[k].y = std::numeric_limits<double>::quiet_NaN();
    if (zero) weights[k] = 0;
    const std::array<double, 2> site{all[k].x / 1000 + 0.1 * all[k].y / 800, all[k].y / 800};
    sites_with.push_back(site);
    if (nan || zero) continue;
    without.push_back(all[k]);
    sites_without.push_back(site);
  }
  for (const ScatteredParam param : {ScatteredParam::xy, ScatteredParam::plane, ScatteredParam::sites})
    for (const int n : {12, 75}) {
      ScatteredApproximationOptions a, b;
      a.param = b.param = param;
      a.control_points = b.control_points = std::array<int, 2>{n, n};
      a.weights = weights;
      if (param == ScatteredParam::sites) a.sites = sites_with, b.sites = sites_without;
      const auto r = approximate_scattered(with, a), s = approximate_scattered(without, b);
      const auto& x = r.surface.control_points().values();
      const auto& y = s.surface.control_points().values();
      ASSERT_EQ(x.size(), y.size());
      EXPECT_EQ(0, std::memcmp(x.data(), y.data(), x.size() * sizeof(Vec3))) << static_cast<int>(param) << ", " << n << " x " << n;
      EXPECT_EQ(r.report.missing, all.size() / 97 + 1);
      EXPECT_EQ(s.report.missing, 0U);
    }
}

// A sheet tilted in space, its points in random order and far from the origin: the
// least-squares plane's sites, the tolerance met; moved and shuffled, the same surface.
TEST(Scattered, PlaneSitesOnATiltedSheetAndInvarianceUnderTranslationAndReordering) {
  std::mt19937_64 g(16);
  const Vec3 e1 = Vec3{1, 2, 0.5} / norm(Vec3{1, 2, 0.5}), c = cross(Vec3{0, 0, 1}, e1), e2 = c / norm(c), n = cross(e1, e2);
  std::uniform_real_distribution<double> ua(-3, 3), ub(-2, 2);
  std::vector<Vec3> q(2500);
  for (Vec3& p : q) {
    const double a = ua(g), b = ub(g);
    p = a * e1 + b * e2 + (0.3 * std::sin(a) * std::cos(1.3 * b)) * n;
  }
  ScatteredApproximationOptions o;
  o.tolerance = 1e-3;
  const auto r = approximate_scattered(q, o);
  EXPECT_LE(own_max_distance(r, q), 1e-3);
  EXPECT_NEAR(std::abs(dot(r.axis_u, e1)), 1.0, 1e-3);  // the larger extent

  const Vec3 shift{2.5e6, -7.1e5, 1.3e3};
  std::vector<std::size_t> order(q.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), g);
  std::vector<Vec3> moved(q.size());
  for (std::size_t k = 0; k < q.size(); ++k) moved[k] = q[order[k]] + shift;
  const auto m = approximate_scattered(moved, o);
  EXPECT_LE(own_max_distance(m, moved), 1e-3);
  ASSERT_EQ(m.report.control_points, r.report.control_points);
  // Compared where the two sit: the same plane and domain up to rounding of 1e6.
  const Tensor tr = tensor_of(r.surface), tm = tensor_of(m.surface);
  double worst = 0;
  for (std::size_t k = 0; k < q.size(); k += 25) {
    const std::size_t at = static_cast<std::size_t>(std::find(order.begin(), order.end(), k) - order.begin());
    worst = std::max(worst, distance(tr.eval(r.sites[k][0], r.sites[k][1]).s + shift, tm.eval(m.sites[at][0], m.sites[at][1]).s));
  }
  EXPECT_LE(worst, 1e-6);
}

TEST(Scattered, SmoothingGoesFromTheDataToTheirPlane) {
  std::mt19937_64 g(17);
  const auto q = survey(g, 2000, 1.0);
  ScatteredApproximationOptions o;
  o.param = ScatteredParam::xy;
  double last_rms = 0;
  for (const double l : {1e-9, 1e-5, 1e-1, 1e4}) {
    o.smoothing = l;
    const auto r = approximate_scattered(q, o);
    EXPECT_GE(r.report.rms_error, last_rms) << l;  // more smoothing, farther from the data
    last_rms = r.report.rms_error;
    EXPECT_DOUBLE_EQ(r.report.lambda, std::max(l, r.report.lambda));
  }
  // λ = 1e4: near the least-squares plane z = a + b x + c y, far from the field's 40 m waves.
  EXPECT_GT(last_rms, 10.0);
}

TEST(Scattered, Refusals) {
  std::mt19937_64 g(18);
  auto q = survey(g, 200);
  auto code = [&](const std::vector<Vec3>& pts, const ScatteredApproximationOptions& o) {
    try {
      (void)approximate_scattered(pts, o);
    } catch (const error& e) {
      return e.code();
    }
    return errc::internal;
  };
  ScatteredApproximationOptions o = xy_tolerance(0.1);
  EXPECT_EQ(code(std::vector<Vec3>(q.begin(), q.begin() + 15), o), errc::too_few_points);  // 16 for bicubic
  std::vector<Vec3> line;
  for (int k = 0; k < 50; ++k) line.push_back({k * 1.0, 2 * k + 1.0, std::sin(k)});
  EXPECT_EQ(code(line, o), errc::singular);  // a vertical section: no height field
  ScatteredApproximationOptions plane;
  plane.tolerance = 0.1;
  for (Vec3& p : line) p.z = 3 * p.x;
  EXPECT_EQ(code(line, plane), errc::singular);  // every point on one line
  ScatteredApproximationOptions sites = o;
  sites.param = ScatteredParam::sites;
  sites.sites.assign(199, {0.0, 0.0});
  EXPECT_EQ(code(q, sites), errc::size_mismatch);
  auto bad = q;
  bad[7].y = std::numeric_limits<double>::infinity();
  EXPECT_EQ(code(bad, o), errc::not_finite);
  ScatteredApproximationOptions w = o;
  w.weights.assign(q.size(), 1.0);
  w.weights[3] = -1;
  EXPECT_EQ(code(q, w), errc::invalid_weight);
  ScatteredApproximationOptions two = o;
  two.smoothing = 1;
  EXPECT_EQ(code(q, two), errc::wrong_type);
  ScatteredApproximationOptions dom = o;
  dom.domain = std::array<std::array<double, 2>, 2>{{{0, 500}, {0, 800}}};
  EXPECT_EQ(code(q, dom), errc::out_of_domain);
  // Two points 1e-9 apart with heights 1 apart, a tolerance of 0.1, the net held small.
  auto close = q;
  close[0] = {500, 400, 0};
  close[1] = {500 + 1e-9, 400, 1};
  ScatteredApproximationOptions lim = xy_tolerance(0.1);
  lim.max_control_points = std::array<int, 2>{40, 40};
  try {
    (void)approximate_scattered(close, lim);
    ADD_FAILURE() << "no tolerance_not_met";
  } catch (const error& e) {
    EXPECT_EQ(e.code(), errc::tolerance_not_met);
    EXPECT_NE(std::string(e.what()).find("point ["), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("control points"), std::string::npos) << e.what();
  }
}

// A point of weight 0 takes no part and has no site: info measures the data error at
// the other points' sites, where the fit's own report measured it, and the point, far
// off the surface, is not the worst one.
TEST(Scattered, InfoLeavesOutThePointsOfWeightZero) {
  std::mt19937_64 g(21);
  auto q = survey(g, 80);
  q[5].z += 1000;
  nlohmann::json pts = nlohmann::json::array();
  for (const Vec3& p : q) pts.push_back({p.x, p.y, p.z});
  std::vector<double> w(q.size(), 1.0);
  w[5] = 0;
  const nlohmann::json spec = {{"type", "approximate"}, {"param", "xy"}, {"tolerance", 0.5}, {"points", pts}, {"weights", w}};
  const io::Construction c = io::build(spec);
  const nlohmann::ordered_json info = io::info_json(c);
  const auto& e = info["max_data_error"];
  ASSERT_TRUE(e.is_object()) << info.dump();
  EXPECT_NE(e["at"], "/points/5");
  EXPECT_LE(e["absolute"].get<double>(), 0.5);
  // The same distances by two evaluations of one spline (info's evaluator, the fit's own
  // check): equal to their rounding, within ten ulps of the coordinates' size.
  EXPECT_NEAR(e["absolute"].get<double>(), c.parameters["max_error"].get<double>(), 1e-15 * e["diagonal"].get<double>()) << info.dump();
}

// The spec's own refusals for scattered points, each with its code and its place.
TEST(Scattered, SpecRefusalsNameTheField) {
  std::mt19937_64 g(20);
  const auto q = survey(g, 60);
  nlohmann::json pts = nlohmann::json::array();
  for (const Vec3& p : q) pts.push_back({p.x, p.y, p.z});
  const nlohmann::json base = {{"type", "approximate"}, {"param", "xy"}, {"tolerance", 1.0}, {"points", pts}};
  auto refused = [&](const std::function<void(nlohmann::json&)>& change, errc code, const std::string& text) {
    nlohmann::json spec = base;
    change(spec);
    try {
      (void)io::build(spec);
      ADD_FAILURE() << "built: " << text;
    } catch (const error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  refused([](nlohmann::json& s) { s["max_control_points"] = 10; s.erase("tolerance"); s["control_points"] = 6; },
          errc::wrong_type, "/max_control_points: it limits a tolerance's refinement");
  refused([](nlohmann::json& s) { s["param"] = {{"base", {{"type", "bilinear"}}}}; }, errc::missing_field,
          "/param/base/p00: missing field");
  refused([](nlohmann::json& s) { s["param"] = {{"base", {{"type", "trilinear"}}}, {"more", 1}}; }, errc::wrong_type,
          "/param: {\"base\": surface spec} takes nothing beside the surface");
  refused([](nlohmann::json& s) { s["domain"] = {{1000, 0}, {0, 800}}; }, errc::non_increasing,
          "domain along u is [1000, 0]: it must increase");
  refused([](nlohmann::json& s) { s["domain"] = {{0, 500}, {0, 800}}; }, errc::out_of_domain, "outside the domain [0, 500]");
  refused([](nlohmann::json& s) { s.erase("tolerance"); s["smoothing"] = "fast"; }, errc::wrong_type,
          "/smoothing: expected a number or \"auto\", got \"fast\"");
  refused([](nlohmann::json& s) { s["periodic"] = {true, false}; }, errc::wrong_type,
          "/periodic: scattered points have no closed directions");
  refused([](nlohmann::json& s) { s["weights"] = {1, 2}; }, errc::size_mismatch, "/weights: 2 weights for 60 points");
  refused([](nlohmann::json& s) { s["weights"] = std::vector<double>(60, 1.0); s["weights"][5] = -1; }, errc::invalid_weight,
          "/weights/5: weight -1 is negative");
  refused([](nlohmann::json& s) { s["param"] = std::vector<std::vector<double>>(60, {0.0, 0.0}); s["param"][3] = {1, 2, 3}; },
          errc::size_mismatch, "/param/3: a site is 2 numbers [u, v], got 3");
  refused([](nlohmann::json& s) { s.erase("tolerance"); s["control_points"] = {3, 6}; }, errc::too_few_points,
          "/control_points/0: 3 control points along u are fewer than degree 3 needs (4)");
}

}  // namespace
}  // namespace interpatch
