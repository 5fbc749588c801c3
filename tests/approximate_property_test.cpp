// Random approximation cases against the promises of include/interpatch/approximate.hpp
// (docs/spec-format.md, "approximate"): on success every point present within the
// tolerance, a finite control net near the data; on failure only an interpatch::error
// of a documented code. Every check here evaluates the returned spline with its own
// evaluator at the returned parameters, never the fitting code.

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <optional>
#include <map>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "interpatch/approximate.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

struct Case {
  std::size_t rank = 2;
  std::array<std::size_t, 3> n{};
  std::array<std::optional<int>, 3> degree{};
  std::array<bool, 3> periodic{};
  Parametrization param = Parametrization::chord;
  std::optional<std::array<int, 3>> control_points;
  std::optional<double> tolerance, smoothing;
  bool auto_smoothing = false;
  std::vector<Vec3> points;
};

// A smooth field with noise and holes over an index grid, or points thrown into a cube.
Case random_case(std::mt19937_64& g) {
  Case c;
  const double pick = test::uniform(g, 0, 1);
  c.rank = pick < 0.25 ? 1 : (pick < 0.85 ? 2 : 3);
  std::size_t count = 1;
  for (std::size_t a = 0; a < c.rank; ++a) {
    const std::size_t top = c.rank == 1 ? 30 : (c.rank == 2 ? 12 : 6);
    c.n[a] = 2 + static_cast<std::size_t>(test::uniform(g, 0, 1) * static_cast<double>(top - 1));
    count *= c.n[a];
    c.degree[a] = 1 + static_cast<int>(test::uniform(g, 0, 3));
    c.periodic[a] = test::uniform(g, 0, 1) < 0.3;
  }
  const double kind = test::uniform(g, 0, 1);
  c.param = kind < 0.5 ? Parametrization::chord : (kind < 0.8 ? Parametrization::uniform : Parametrization::centripetal);
  const double noise = std::pow(10.0, test::uniform(g, -4, 0));
  const bool cloud = test::uniform(g, 0, 1) < 0.2;
  const double holes = test::uniform(g, 0, 1) < 0.3 ? test::uniform(g, 0, 0.3) : 0.0;
  const double f1 = test::uniform(g, 0.5, 4), f2 = test::uniform(g, 0.5, 4), ph = test::uniform(g, 0, 6);
  for (std::size_t i = 0; i < count; ++i) {
    std::array<double, 3> x{};
    for (std::size_t a = c.rank, rest = i; a-- > 0; rest /= c.n[a]) x[a] = static_cast<double>(rest % c.n[a]);
    Vec3 q = cloud ? test::random_point(g)
                   : Vec3{x[0] + (c.rank < 3 ? 0.0 : 0.1 * std::sin(x[1])), c.rank == 1 ? std::sin(f1 * x[0] + ph) : x[1],
                          c.rank == 3 ? x[2] : std::sin(f1 * x[0] / 3 + ph) * std::cos(f2 * x[1] / 3)};
    q = q + test::random_point(g, noise);
    if (test::uniform(g, 0, 1) < holes) q.z = std::numeric_limits<double>::quiet_NaN();
    c.points.push_back(q);
  }
  const double mode = test::uniform(g, 0, 1);
  if (mode < 0.5) {
    c.tolerance = std::pow(10.0, test::uniform(g, -7, 0));
  } else if (mode < 0.8) {
    std::array<int, 3> cp{};
    for (std::size_t a = 0; a < c.rank; ++a) cp[a] = 2 + static_cast<int>(test::uniform(g, 0, 1) * static_cast<double>(c.n[a]));
    c.control_points = cp;
  } else if (mode < 0.97) {
    c.smoothing = std::pow(10.0, test::uniform(g, -8, 2));
  } else {
    c.auto_smoothing = true;
  }
  return c;
}

template <std::size_t R>
ApproximationOptions<R> options_of(const Case& c) {
  ApproximationOptions<R> o;
  for (std::size_t a = 0; a < R; ++a) {
    o.degree[a] = c.degree[a];
    o.periodic[a] = c.periodic[a];
  }
  o.param = c.param;
  if (c.control_points) {
    std::array<int, R> cp{};
    for (std::size_t a = 0; a < R; ++a) cp[a] = (*c.control_points)[a];
    o.control_points = cp;
  }
  o.tolerance = c.tolerance;
  o.smoothing = c.smoothing;
  o.auto_smoothing = c.auto_smoothing;
  return o;
}

// The data's box and diagonal over the points present.
struct Box {
  Vec3 lo{}, hi{};
  bool any = false;
  void add(const Vec3& q) {
    if (!is_finite(q)) return;
    for (int k = 0; k < 3; ++k) {
      lo[k] = any ? std::min(lo[k], q[k]) : q[k];
      hi[k] = any ? std::max(hi[k], q[k]) : q[k];
    }
    any = true;
  }
  // How far a point lies outside.
  [[nodiscard]] double outside(const Vec3& p) const {
    Vec3 d{};
    for (int k = 0; k < 3; ++k) d[k] = std::max({lo[k] - p[k], p[k] - hi[k], 0.0});
    return norm(d);
  }
};

// What a result must be: finite, its net near the data, every point present within
// the tolerance. `value(i)`: the spline at data point i by its own evaluator.
template <class Value>
void expect_kept(const Case& c, const std::vector<Vec3>& net, const ApproximationReport& rep, const Value& value,
                 const std::string& what) {
  Box box;
  for (const Vec3& q : c.points) box.add(q);
  const double diag = distance(box.lo, box.hi);
  for (const Vec3& p : net) {
    ASSERT_TRUE(is_finite(p)) << what;
    // The promise: no control point farther from the box than 3^rank diagonals (and
    // the rounding of coordinates of size 1–30, 1e-9 of them, for a box of one point).
    ASSERT_LE(box.outside(p), std::pow(3.0, static_cast<double>(c.rank)) * diag + 1e-9 * 30) << what;
  }
  double worst = 0;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (!is_finite(c.points[i])) continue;
    const Vec3 s = value(i);
    ASSERT_TRUE(is_finite(s)) << what;
    worst = std::max(worst, distance(s, c.points[i]));
  }
  // The report's figure is this one (the same evaluator; the order of the points alike).
  EXPECT_NEAR(rep.max_error, worst, 1e-12 * (1 + diag)) << what;
  if (c.tolerance) {
    EXPECT_LE(worst, *c.tolerance) << what;  // the promise itself, exactly
  }
}

void run_case(const Case& c, std::size_t k) {
  const std::string what = "case " + std::to_string(k);
  if (c.rank == 1) {
    const auto r = approximate_curve(c.points, options_of<1>(c));
    expect_kept(c, r.curve.control_points(), r.report, [&](std::size_t i) { return r.curve.point(r.params[i]); }, what);
  } else if (c.rank == 2) {
    PointGrid q({c.n[0], c.n[1]}, c.points);
    const auto r = approximate_surface(q, options_of<2>(c));
    const auto& net = r.surface.control_points().values();
    expect_kept(c, {net.begin(), net.end()}, r.report,
                [&](std::size_t i) { return r.surface.point(r.params_u[i / c.n[1]], r.params_v[i % c.n[1]]); }, what);
  } else {
    PointGrid3 q({c.n[0], c.n[1], c.n[2]}, c.points);
    const auto r = approximate_volume(q, options_of<3>(c));
    const auto& net = r.volume.control_points().values();
    const std::size_t nvw = c.n[1] * c.n[2];
    expect_kept(c, {net.begin(), net.end()}, r.report, [&](std::size_t i) {
      return r.volume.point(r.params_u[i / nvw], r.params_v[i / c.n[2] % c.n[1]], r.params_w[i % c.n[2]]);
    }, what);
  }
}

TEST(ApproximateProperty, RandomCasesKeepThePromiseOrFailWithADocumentedCode) {
  auto g = test::rng(36);
  // Input errors random data can reach (too few points or control points for a
  // degree, coincident points), and the two refusals the promise allows.
  const std::set<errc> allowed{errc::too_few_points, errc::invalid_degree, errc::zero_chord, errc::closing_gap,
                               errc::tolerance_not_met, errc::ill_conditioned};
  std::map<std::string, int> outcomes;
  constexpr std::size_t cases = 1500;
  for (std::size_t k = 0; k < cases; ++k) {
    const Case c = random_case(g);
    try {
      run_case(c, k);
      ++outcomes["kept"];
    } catch (const error& e) {
      ++outcomes[std::string(to_string(e.code()))];
      EXPECT_TRUE(allowed.count(e.code()) > 0) << "case " << k << ": " << to_string(e.code()) << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << k << ": not an interpatch::error: " << e.what();
    }
    if (HasFatalFailure()) return;
  }
  for (const auto& [name, count] : outcomes) std::printf("  %s: %d\n", name.c_str(), count);
  // Most cases are kept: the property is about results, not refusals.
  EXPECT_GT(outcomes["kept"], static_cast<int>(cases) / 2);
}

// The case's data (and tolerance) times 2^e.
Case scaled(Case c, int e) {
  for (Vec3& q : c.points)
    for (int k = 0; k < 3; ++k) q[k] = std::ldexp(q[k], e);
  if (c.tolerance) c.tolerance = std::ldexp(*c.tolerance, e);
  return c;
}

// The control net and report of a case's fit, or the code it failed with.
struct Outcome {
  std::optional<errc> code;
  std::vector<Vec3> net;
  ApproximationReport report;
};

Outcome outcome(const Case& c) {
  Outcome o;
  try {
    if (c.rank == 1) {
      const auto r = approximate_curve(c.points, options_of<1>(c));
      o.net = r.curve.control_points();
      o.report = r.report;
    } else if (c.rank == 2) {
      const auto r = approximate_surface(PointGrid({c.n[0], c.n[1]}, c.points), options_of<2>(c));
      o.net.assign(r.surface.control_points().values().begin(), r.surface.control_points().values().end());
      o.report = r.report;
    } else {
      const auto r = approximate_volume(PointGrid3({c.n[0], c.n[1], c.n[2]}, c.points), options_of<3>(c));
      o.net.assign(r.volume.control_points().values().begin(), r.volume.control_points().values().end());
      o.report = r.report;
    }
  } catch (const error& e) {
    o.code = e.code();
  }
  return o;
}

// Squared distances of data of 1e-200 vanished and those of 1e200 overflowed: a
// tolerance fit of tiny data stopped at 4 x 4 control points, and the rms of large
// data was infinite. The fit is the same at any scale: the same outcome, the same
// control points scaled, the report scaled.
TEST(ApproximateProperty, TheSameFitAtEveryScale) {
  auto g = test::rng(37);
  int compared = 0;
  for (std::size_t k = 0; k < 300; ++k) {
    const Case c = random_case(g);
    const int e = std::array<int, 6>{-900, -640, -330, 330, 640, 900}[k % 6];
    const Outcome one = outcome(c), big = outcome(scaled(c, e));
    SCOPED_TRACE(testing::Message() << "case " << k << " scaled by 2^" << e);
    ASSERT_EQ(one.code.has_value(), big.code.has_value());
    if (one.code) {
      EXPECT_EQ(*one.code, *big.code);
      continue;
    }
    ++compared;
    EXPECT_EQ(one.report.control_points, big.report.control_points);
    ASSERT_EQ(one.net.size(), big.net.size());
    Box box;
    for (const Vec3& q : c.points) box.add(q);
    // The fit at 1 and at 2^e differ only in rounding: the solves are linear in the
    // data, and the choices (knots, lambda) depend on ratios of distances. 1e-9 of the
    // data's size leaves room for the rounding of ill-conditioned systems.
    const double size = distance(box.lo, box.hi) + 1;
    for (std::size_t i = 0; i < one.net.size(); ++i)
      ASSERT_LE(distance(one.net[i], big.net[i] * std::ldexp(1.0, -e)), 1e-9 * size) << "control point " << i;
    EXPECT_NEAR(std::ldexp(big.report.max_error, -e), one.report.max_error, 1e-9 * size);
    EXPECT_NEAR(std::ldexp(big.report.rms_error, -e), one.report.rms_error, 1e-9 * size);
    EXPECT_TRUE(std::isfinite(big.report.rms_error));
    // lambda by cross-validation: the minimum of a flat function, found to its rounding.
    EXPECT_NEAR(big.report.lambda, one.report.lambda, 1e-6 * one.report.lambda);
  }
  EXPECT_GT(compared, 150);
}

}  // namespace
}  // namespace interpatch
