// Closed (periodic) interpolation: interpolate_curve, interpolate_surface and
// interpolate_volume with `periodic`, the parameters and knots under them
// (closed_curve_parameters, periodic_knots, closing_point) and the periodic knot
// vectors and curves they build on.
//
// The SciPy comparison reads tests/data/periodic_reference.json, made by
// tools/reference/make_periodic_reference.py (its header tells how); CTest checks
// that the JSON is what the script produces when python3-scipy is installed.
//
// Every random input comes from a fixed seed (test::rng): a failure reproduces.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "test_util.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace interpatch {
namespace {

using nlohmann::json;

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr Parametrization kAllParams[] = {Parametrization::uniform, Parametrization::chord,
                                          Parametrization::centripetal};

// ---------------------------------------------------------------------------
// Tolerances (relative to the bounding-box diagonal of the data unless said).
// ---------------------------------------------------------------------------

/// A point of an interpolant against the data or against another double-precision
/// solve of the same system (SciPy's): the periodic collocation matrices here have
/// condition numbers below ~100, so the rounding of the cyclic banded solve (~1e-16
/// per operation, a few dozen operations per unknown) stays near 1e-14; a wrong
/// knot, parameter or wrapped index moves points by 1e-3 or more (checked with
/// INTERPATCH_PERIODIC_REFERENCE_JSON pointed at the output of mutated scripts: the
/// closing chord left out of the parameters, SciPy's even-degree knots, grid lines
/// normalized without their closing chords: differences of 2e-3 to 8e-2). Seen
/// against SciPy (GCC 12 -O3, x86-64): points 7.6e-16, first and second derivatives
/// (relative to their largest size) 1.7e-14 and 7.8e-14, the largest for degree 5
/// on the most uneven parameters.
constexpr double kSolveTol = 1e-12;

/// Parameters (absolute; they lie in [0, 1)): sums of at most 40 correctly rounded
/// chord lengths over their total, averaged over at most 10 lines, computed in
/// another order by the other side: a few dozen roundings of 1.1e-16. Seen: 2.2e-16.
constexpr double kParamTol = 1e-14;

/// Derivative jumps across the seam, relative to the largest derivative of that
/// order on the curve: both one-sided values are sums of p+1 basis derivatives
/// times control points, each rounding at 1e-16 of the terms, which for order k
/// are up to (p / smallest knot span)^k times the control points — for the uneven
/// random data here up to ~1e3 times the derivative itself.
constexpr double kSeamTol = 1e-10;

/// Knot insertion, refinement, elevation and the clamped form of a periodic curve
/// re-solve in the new space (a well-conditioned collocation, condition < 100):
/// a little rounding of the control points, no change in geometry.
constexpr double kRefineTol = 1e-13;

// ---------------------------------------------------------------------------
// Data
// ---------------------------------------------------------------------------

/// n distinct points around a closed 3-D loop (an ellipse bent out of its plane),
/// angle steps jittered by up to ±30 % and coordinates by up to 5 % of a step:
/// no chord is shorter than about 20 % of the average one.
std::vector<Vec3> random_loop(std::mt19937_64& g, std::size_t n) {
  const double r = test::uniform(g, 0.5, 3.0);
  const Vec3 c = test::random_point(g, 2.0);
  const double step = kTwoPi / static_cast<double>(n);
  std::vector<Vec3> q;
  for (std::size_t k = 0; k < n; ++k) {
    const double a = step * (static_cast<double>(k) + test::uniform(g, -0.3, 0.3));
    q.push_back(c + r * Vec3{1.6 * std::cos(a), std::sin(a), 0.4 * std::sin(2 * a)} +
                test::random_point(g, 0.05 * r * step));
  }
  return q;
}

/// The contribution of index fraction s (i / n) along one axis: around a loop in a
/// plane of its own for a closed axis, along a line for an open one.
Vec3 axis_shape(int axis, bool closed, double s) {
  if (!closed) return 4.0 * s * Vec3{axis == 0 ? 1.0 : 0.3, axis == 1 ? 1.0 : 0.2, axis == 2 ? 1.0 : 0.1};
  const double a = kTwoPi * s, R = axis == 0 ? 3.0 : (axis == 1 ? 1.2 : 0.6);
  const double c = R * std::cos(a), d = R * std::sin(a);
  if (axis == 0) return {c, d, 0.3 * std::sin(2 * a)};
  if (axis == 1) return {0.2 * d, c, d};
  return {d, 0.25 * c, c};
}

double index_fraction(std::mt19937_64& g, std::size_t i, std::size_t n, bool closed) {
  const double jitter = test::uniform(g, -0.2, 0.2);
  return (static_cast<double>(i) + jitter) / static_cast<double>(closed ? n : n - 1);
}

/// A grid closed along the axes `periodic` says: loops along closed axes, lines along
/// open ones, the first axis' shape scaled along the second so that lines differ;
/// `noise` well below the smallest step between neighbours (~0.5 for up to 12 lines).
PointGrid random_closed_grid(std::mt19937_64& g, std::size_t nu, std::size_t nv, std::array<bool, 2> periodic,
                             double noise = 0.02) {
  PointGrid q({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const double s = index_fraction(g, i, nu, periodic[0]), t = index_fraction(g, j, nv, periodic[1]);
      q(i, j) = (1 + 0.2 * std::cos(kTwoPi * t)) * axis_shape(0, periodic[0], s) + axis_shape(1, periodic[1], t) +
                test::random_point(g, noise);
    }
  return q;
}

PointGrid3 random_closed_grid3(std::mt19937_64& g, std::array<std::size_t, 3> n, std::array<bool, 3> periodic) {
  PointGrid3 q({n[0], n[1], n[2]});
  for (std::size_t i = 0; i < n[0]; ++i)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t k = 0; k < n[2]; ++k) {
        const double s = index_fraction(g, i, n[0], periodic[0]), t = index_fraction(g, j, n[1], periodic[1]),
                     w = index_fraction(g, k, n[2], periodic[2]);
        q(i, j, k) = (1 + 0.2 * std::cos(kTwoPi * t)) * axis_shape(0, periodic[0], s) +
                     (1 + 0.15 * std::sin(kTwoPi * w)) * axis_shape(1, periodic[1], t) +
                     axis_shape(2, periodic[2], w) + test::random_point(g, 0.02);
      }
  return q;
}

std::vector<Vec3> with_closing_point(std::vector<Vec3> q) {
  q.push_back(q.front());
  return q;
}

/// The grid with its first line along `axis` repeated at the end.
PointGrid with_closing_line(const PointGrid& q, int axis) {
  const std::size_t nu = q.extent(0), nv = q.extent(1);
  PointGrid out({nu + (axis == 0), nv + (axis == 1)});
  for (std::size_t i = 0; i < out.extent(0); ++i)
    for (std::size_t j = 0; j < out.extent(1); ++j) out(i, j) = q(i % nu, j % nv);
  return out;
}

PointGrid3 with_closing_plane(const PointGrid3& q, int axis) {
  const auto& n = q.shape();
  PointGrid3 out({n[0] + (axis == 0), n[1] + (axis == 1), n[2] + (axis == 2)});
  for (std::size_t i = 0; i < out.extent(0); ++i)
    for (std::size_t j = 0; j < out.extent(1); ++j)
      for (std::size_t k = 0; k < out.extent(2); ++k) out(i, j, k) = q(i % n[0], j % n[1], k % n[2]);
  return out;
}

CurveInterpolationOptions closed_curve(int degree, Parametrization param) {
  CurveInterpolationOptions o;
  o.degree = degree;
  o.param = param;
  o.periodic = true;
  return o;
}

double max_abs_derivative(const BSplineCurve& c, int k) {
  double m = 0;
  for (double t : linspace(0, 1, 401)) m = std::max(m, norm(c.derivative(t, k)));
  return m;
}

// ---------------------------------------------------------------------------
// The SciPy reference
// ---------------------------------------------------------------------------

/// tests/data/periodic_reference.json, or the file INTERPATCH_PERIODIC_REFERENCE_JSON
/// names (e.g. one made by a deliberately wrong variant of the script, to see the
/// comparison fail).
const json& reference() {
  static const json doc = [] {
    const char* env = std::getenv("INTERPATCH_PERIODIC_REFERENCE_JSON");
    const std::string path = env && *env ? env : INTERPATCH_TEST_DATA "/periodic_reference.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    return json::parse(in);
  }();
  return doc;
}

Vec3 vec(const json& a) { return {a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>()}; }

std::vector<Vec3> vecs(const json& a) {
  std::vector<Vec3> out;
  for (const json& p : a) out.push_back(vec(p));
  return out;
}

Parametrization param_named(const std::string& s) {
  if (s == "uniform") return Parametrization::uniform;
  if (s == "chord") return Parametrization::chord;
  if (s == "centripetal") return Parametrization::centripetal;
  throw std::runtime_error("unknown parametrization " + s);
}

/// Largest |v| over a list of reference vectors: derivatives are compared relative to it.
double largest(const json& list) {
  double m = 0;
  for (const json& v : list) m = std::max(m, norm(vec(v)));
  return m;
}

TEST(PeriodicReference, FileHasTheExpectedCases) {
  const json& doc = reference();
  EXPECT_EQ(doc.at("generator"), "tools/reference/make_periodic_reference.py");
  EXPECT_GE(doc.at("curves").size(), 16u);
  EXPECT_GE(doc.at("grids").size(), 8u);
}

TEST(PeriodicReference, CurvesMatchSciPy) {
  for (const json& c : reference().at("curves")) {
    const std::string name = c.at("name");
    SCOPED_TRACE(name);
    const std::vector<Vec3> q = vecs(c.at("points"));
    const auto want_t = c.at("params").get<std::vector<double>>();
    const bool closing = c.at("closing_point").get<bool>();
    ASSERT_EQ(q.size(), want_t.size() + (closing ? 1 : 0));
    const double scale = test::bbox_diagonal(q);
    const int p = c.at("degree").get<int>();

    // Twice: parameters computed by interpatch, and the script's given as parameters
    // (then the solves alone differ).
    for (bool given : {false, true}) {
      SCOPED_TRACE(given ? "given parameters" : "own parameters");
      CurveInterpolationOptions o = closed_curve(p, param_named(c.at("param")));
      if (given) {
        o.params = want_t;
        if (closing) o.params.push_back(want_t.front() + 1);
      }
      const CurveInterpolation r = interpolate_curve(q, o);
      ASSERT_TRUE(r.curve.periodic());
      ASSERT_EQ(r.params.size(), q.size());
      for (std::size_t k = 0; k < want_t.size(); ++k) EXPECT_NEAR(r.params[k], want_t[k], kParamTol) << "point " << k;
      if (closing) {
        EXPECT_EQ(r.params.back(), 1.0);
      }
      const json& ev = c.at("eval");
      const auto ts = ev.at("t").get<std::vector<double>>();
      for (std::size_t k = 0; k < ts.size(); ++k)
        EXPECT_LT(distance(r.curve.point(ts[k]), vec(ev.at("points").at(k))), kSolveTol * scale) << "t = " << ts[k];
      for (int d = 1; d <= 2; ++d) {
        const std::string key = "d" + std::to_string(d);
        if (!ev.contains(key)) continue;
        // Derivatives relative to their largest size on the curve: the control-point
        // rounding (kSolveTol) times p / (knot span), which that size carries too.
        const double big = largest(ev.at(key));
        for (std::size_t k = 0; k < ts.size(); ++k)
          EXPECT_LT(norm(r.curve.derivative(ts[k], d) - vec(ev.at(key).at(k))), kSolveTol * big)
              << key << " at t = " << ts[k];
      }
    }
  }
}

TEST(PeriodicReference, GridsMatchSciPy) {
  for (const json& c : reference().at("grids")) {
    const std::string name = c.at("name");
    SCOPED_TRACE(name);
    const auto shape = c.at("shape").get<std::vector<std::size_t>>();
    const std::vector<Vec3> pts = vecs(c.at("points"));
    ASSERT_EQ(pts.size(), shape[0] * shape[1]);
    PointGrid q({shape[0], shape[1]}, pts);
    const auto per = c.at("periodic").get<std::vector<bool>>();
    const auto closing = c.at("closing_line").get<std::vector<bool>>();
    const auto deg = c.at("degree").get<std::vector<int>>();
    SurfaceInterpolationOptions o;
    o.degree_u = deg[0];
    o.degree_v = deg[1];
    o.param = param_named(c.at("param"));
    o.periodic = {per[0], per[1]};
    const SurfaceInterpolation r = interpolate_surface(q, o);
    EXPECT_EQ(r.surface.periodic(), (std::array<bool, 2>{per[0], per[1]}));
    const double scale = test::bbox_diagonal(q.values());

    const std::vector<double>* got[2] = {&r.params_u, &r.params_v};
    const char* keys[2] = {"params_u", "params_v"};
    for (int a = 0; a < 2; ++a) {
      const auto want = c.at(keys[a]).get<std::vector<double>>();
      ASSERT_EQ(got[a]->size(), shape[static_cast<std::size_t>(a)]) << keys[a];
      ASSERT_EQ(want.size() + (closing[static_cast<std::size_t>(a)] ? 1 : 0), got[a]->size()) << keys[a];
      for (std::size_t k = 0; k < want.size(); ++k) EXPECT_NEAR((*got[a])[k], want[k], kParamTol) << keys[a] << k;
      if (closing[static_cast<std::size_t>(a)]) {
        EXPECT_EQ(got[a]->back(), 1.0) << keys[a];
      }
    }

    const json& ev = c.at("eval");
    const auto us = ev.at("u").get<std::vector<double>>(), vs = ev.at("v").get<std::vector<double>>();
    // Partials relative to their largest size over the samples, as for curves.
    const double big_u = ev.contains("du") ? largest(ev.at("du")) : 0;
    const double big_v = ev.contains("dv") ? largest(ev.at("dv")) : 0;
    for (std::size_t k = 0; k < us.size(); ++k) {
      const double u = us[k], v = vs[k];
      EXPECT_LT(distance(r.surface.point(u, v), vec(ev.at("points").at(k))), kSolveTol * scale)
          << "(u, v) = (" << u << ", " << v << ")";
      if (ev.contains("du")) {
        EXPECT_LT(norm(r.surface.derivative(u, v, 1, 0) - vec(ev.at("du").at(k))), kSolveTol * big_u)
            << "S_u at (" << u << ", " << v << ")";
      }
      if (ev.contains("dv")) {
        EXPECT_LT(norm(r.surface.derivative(u, v, 0, 1) - vec(ev.at("dv").at(k))), kSolveTol * big_v)
            << "S_v at (" << u << ", " << v << ")";
      }
    }
  }
}

// ---------------------------------------------------------------------------
// Parameters, knots, closing point
// ---------------------------------------------------------------------------

TEST(PeriodicParameters, ClosedPolygonWithTheClosingChord) {
  // A 3-4-5 right triangle: chords 3, 4, 5 (total 12), the closing one included.
  const std::vector<Vec3> tri{{0, 0, 0}, {3, 0, 0}, {3, 4, 0}};
  EXPECT_EQ(closed_curve_parameters(tri, Parametrization::chord), (std::vector<double>{0, 0.25, 7.0 / 12}));
  const std::vector<double> cen = closed_curve_parameters(tri, Parametrization::centripetal);
  const double s = std::sqrt(3.0) + 2 + std::sqrt(5.0);
  ASSERT_EQ(cen.size(), 3u);
  EXPECT_EQ(cen[0], 0.0);
  // Square roots of square roots, their sum and the quotient, rounded in another
  // order: a few units in the last place (1.1e-16 here).
  EXPECT_NEAR(cen[1], std::sqrt(3.0) / s, 4e-16);
  EXPECT_NEAR(cen[2], (std::sqrt(3.0) + 2) / s, 4e-16);
  EXPECT_EQ(closed_curve_parameters(tri, Parametrization::uniform), (std::vector<double>{0, 1.0 / 3, 2.0 / 3}));
}

TEST(PeriodicParameters, RandomLoopsAgainstTheFormula) {
  auto g = test::rng(701);
  for (int trial = 0; trial < 60; ++trial) {
    const std::size_t n = 2 + static_cast<std::size_t>(trial % 23);
    const auto q = random_loop(g, n);
    for (Parametrization param : kAllParams) {
      std::vector<double> d(n);
      double total = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const double c = distance(q[(k + 1) % n], q[k]);
        d[k] = param == Parametrization::uniform ? 1.0 : (param == Parametrization::chord ? c : std::sqrt(c));
        total += d[k];
      }
      const auto t = closed_curve_parameters(q, param);
      ASSERT_EQ(t.size(), n);
      EXPECT_EQ(t[0], 0.0);
      double acc = 0;
      for (std::size_t k = 1; k < n; ++k) {
        acc += d[k - 1];
        // Running sums of <= 24 terms in another order: a few dozen roundings.
        EXPECT_NEAR(t[k], acc / total, 1e-15) << "n = " << n << ", point " << k;
        EXPECT_GT(t[k], t[k - 1]);
      }
      EXPECT_LT(t.back(), 1.0);
    }
  }
}

TEST(PeriodicKnotsForInterpolation, OddParametersEvenMidpoints) {
  const std::vector<double> t{0, 0.1, 0.3, 0.6, 0.8};
  for (int p : {1, 3}) {
    const KnotVector k = periodic_knots(t, p);
    EXPECT_TRUE(k.periodic());
    EXPECT_EQ(k.period_knots(), t);
    EXPECT_EQ(k.front(), 0.0);
    EXPECT_EQ(k.back(), 1.0);
    EXPECT_EQ(k.count(), 5);
  }
  for (int p : {2, 4}) {
    // The midpoints, the last from 0.8 and 1, one period of them: which one starts
    // the period is left open (a midpoint; interpolate_curve re-anchors it at 0).
    const KnotVector k = periodic_knots(t, p);
    EXPECT_TRUE(k.periodic());
    EXPECT_EQ(k.count(), 5);
    EXPECT_NEAR(k.back() - k.front(), 1.0, 1e-15);  // a midpoint less the same one period back
    std::vector<double> mid = k.period_knots();
    for (double& m : mid) m -= std::floor(m);  // into [0, 1)
    std::sort(mid.begin(), mid.end());
    const double want[] = {0.05, 0.2, 0.45, 0.7, 0.9};
    ASSERT_EQ(mid.size(), 5u);
    for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(mid[i], want[i], 1e-15) << i;  // (a + b) / 2, maybe moved by 1
    const double start = k.front() - std::floor(k.front());
    EXPECT_TRUE(std::any_of(std::begin(want), std::end(want), [&](double w) { return std::abs(start - w) < 1e-15; }))
        << "the period starts at " << k.front() << ", no midpoint";
  }
  EXPECT_ERRC((void)periodic_knots(t, 5), too_few_points, "degree 5 needs at least 6 distinct points, got 5");
  EXPECT_ERRC((void)periodic_knots(std::vector<double>{0, 0.3, 0.2, 0.6}, 3), non_increasing, "parameter 2 = 0.2");
  EXPECT_ERRC((void)periodic_knots(std::vector<double>{0, 0.3, 0.6, 1.2}, 3), out_of_domain,
              "parameter 3 = 1.2 is not inside the period [0, 1)");
}

TEST(PeriodicClosingPoint, DetectsDropsAndRefuses) {
  const std::vector<Vec3> sq{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  EXPECT_FALSE(closing_point(sq).dropped);
  EXPECT_EQ(closing_point(sq).count, 4u);
  auto closed = with_closing_point(sq);
  EXPECT_TRUE(closing_point(closed).dropped);
  EXPECT_EQ(closing_point(closed).count, 4u);
  // 1e-14 of the diagonal (sqrt 2): within 1e-12 of it, the closing point.
  closed.back() = {1e-14, 0, 0};
  EXPECT_TRUE(closing_point(closed).dropped);
  // 1e-8 from the first point, chords next to it of length 1: a gap (< 1e-3 of them).
  closed.back() = {0, 1e-8, 0};
  EXPECT_ERRC((void)closing_point(closed), closing_gap, "point 4");
  // 0.01 from it (1 % of the chords): a point of its own, the curve closes from it.
  closed.back() = {0, 0.01, 0};
  EXPECT_FALSE(closing_point(closed).dropped);
  EXPECT_EQ(closing_point(closed).count, 5u);
}

TEST(PeriodicClosingPoint, GridClosingReportsWithoutThrowing) {
  // A 4 x 5 ring closed along v: the last column repeats the first.
  PointGrid g({4, 5});
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 5; ++j) {
      const double a = 2 * std::numbers::pi * static_cast<double>(j % 4) / 4;
      g(i, j) = {std::cos(a), std::sin(a), static_cast<double>(i)};
    }
  const Closing v = grid_closing(g, 1);
  EXPECT_TRUE(v.dropped);
  EXPECT_FALSE(v.nearly);
  EXPECT_EQ(v.count, 4u);
  const Closing u = grid_closing(g, 0);  // rows at z = 0 and 3: not closed
  EXPECT_FALSE(u.dropped);
  EXPECT_FALSE(u.nearly);
  EXPECT_EQ(u.count, 4u);
  // One point of the last column 1e-8 off its first (chords next to it about 1.4):
  // a near miss, reported here, refused by interpolation closed along v.
  g(2, 4).z += 1e-8;
  const Closing near = grid_closing(g, 1);
  EXPECT_FALSE(near.dropped);
  EXPECT_TRUE(near.nearly);
  EXPECT_EQ(near.count, 5u);
  SurfaceInterpolationOptions o;
  o.periodic = {false, true};
  EXPECT_ERRC((void)interpolate_surface(g, o), closing_gap, "point [2][4], the last along v,");
  EXPECT_ERRC((void)grid_closing(g, 2), out_of_domain, "axis 2 is outside 0..1");
}

// ---------------------------------------------------------------------------
// Interpolation at every data point
// ---------------------------------------------------------------------------

TEST(PeriodicInterpolation, CurvesPassThroughEveryPoint) {
  auto g = test::rng(702);
  for (int trial = 0; trial < 240; ++trial) {
    const int p = 1 + trial % 5;
    const std::size_t n = static_cast<std::size_t>(p) + 1 + static_cast<std::size_t>((trial * 7) % 31);
    const auto distinct = random_loop(g, n);
    const bool closing = trial % 4 >= 2;
    const auto q = closing ? with_closing_point(distinct) : distinct;
    const Parametrization param = kAllParams[(trial / 5) % 3];
    const auto r = interpolate_curve(q, closed_curve(p, param));
    ASSERT_TRUE(r.curve.periodic());
    EXPECT_EQ(r.curve.degree(), p);
    EXPECT_EQ(r.curve.domain(), (std::pair<double, double>{0.0, 1.0}));
    // One control point per distinct point; even degrees one more, for the knot at 0.
    EXPECT_EQ(r.curve.control_points().size(), n + (p % 2 == 0 ? 1 : 0)) << "degree " << p;
    EXPECT_EQ(r.curve.knots().continuity(), p - 1);  // the seam counts as interior
    ASSERT_EQ(r.params.size(), q.size());
    EXPECT_EQ(r.params, [&] {
      auto t = closed_curve_parameters(distinct, param);
      if (closing) t.push_back(1.0);
      return t;
    }());
    const double scale = test::bbox_diagonal(q);
    for (std::size_t i = 0; i < q.size(); ++i)
      EXPECT_LT(distance(r.curve.point(r.params[i]), q[i]), kSolveTol * scale)
          << "trial " << trial << ", degree " << p << ", point " << i;
  }
}

TEST(PeriodicInterpolation, SurfacesPassThroughEveryPoint) {
  auto g = test::rng(703);
  const std::array<std::array<bool, 2>, 3> closed_dirs{{{true, false}, {false, true}, {true, true}}};
  for (int trial = 0; trial < 90; ++trial) {
    const int pu = 1 + trial % 5, pv = 1 + (trial / 5) % 5;
    const auto per = closed_dirs[static_cast<std::size_t>(trial % 3)];
    const std::size_t nu = static_cast<std::size_t>(pu) + 1 + static_cast<std::size_t>(trial % 6),
                      nv = static_cast<std::size_t>(pv) + 1 + static_cast<std::size_t>((trial * 5) % 7);
    PointGrid q = random_closed_grid(g, nu, nv, per);
    if (trial % 4 == 1 && per[0]) q = with_closing_line(q, 0);
    if (trial % 4 == 2 && per[1]) q = with_closing_line(q, 1);
    SurfaceInterpolationOptions o;
    o.degree_u = pu;
    o.degree_v = pv;
    o.param = kAllParams[static_cast<std::size_t>(trial / 3) % 3];
    o.periodic = per;
    const auto r = interpolate_surface(q, o);
    EXPECT_EQ(r.surface.periodic(), per);
    ASSERT_EQ(r.params_u.size(), q.extent(0));
    ASSERT_EQ(r.params_v.size(), q.extent(1));
    const double scale = test::bbox_diagonal(q.values());
    double e = 0;
    for (std::size_t i = 0; i < q.extent(0); ++i)
      for (std::size_t j = 0; j < q.extent(1); ++j)
        e = std::max(e, distance(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j)));
    // Two solves, one cyclic, each of small condition number.
    EXPECT_LT(e, kSolveTol * scale) << "trial " << trial << ": " << q.extent(0) << "x" << q.extent(1) << " degrees "
                                    << pu << "," << pv << " closed " << per[0] << per[1];
  }
}

TEST(PeriodicInterpolation, VolumesPassThroughEveryPoint) {
  auto g = test::rng(704);
  for (int trial = 0; trial < 40; ++trial) {
    const std::array<bool, 3> per{trial % 2 == 0, trial % 3 == 0, trial % 5 < 2};
    const std::array<int, 3> p{1 + trial % 5, 1 + (trial / 2) % 4, 1 + (trial / 3) % 5};
    std::array<std::size_t, 3> n{};
    for (std::size_t a = 0; a < 3; ++a)
      n[a] = static_cast<std::size_t>(p[a]) + 1 + static_cast<std::size_t>((trial + 3 * static_cast<int>(a)) % 3);
    PointGrid3 q = random_closed_grid3(g, n, per);
    const int closing_axis = trial % 4 - 1;  // -1: none
    if (closing_axis >= 0 && per[static_cast<std::size_t>(closing_axis)]) q = with_closing_plane(q, closing_axis);
    VolumeInterpolationOptions o;
    o.degree_u = p[0];
    o.degree_v = p[1];
    o.degree_w = p[2];
    o.param = kAllParams[static_cast<std::size_t>(trial) % 3];
    o.periodic = per;
    const auto r = interpolate_volume(q, o);
    EXPECT_EQ(r.volume.periodic(), per);
    double e = 0;
    for (std::size_t i = 0; i < q.extent(0); ++i)
      for (std::size_t j = 0; j < q.extent(1); ++j)
        for (std::size_t k = 0; k < q.extent(2); ++k)
          e = std::max(e, distance(r.volume.point(r.params_u[i], r.params_v[j], r.params_w[k]), q(i, j, k)));
    // Three solves of small condition number.
    EXPECT_LT(e, kSolveTol * test::bbox_diagonal(q.values()))
        << "trial " << trial << " closed " << per[0] << per[1] << per[2];
    // The batch evaluation, across the seams (a closed direction's last span reads
    // its first control points again): the points of the derivative grid, bit for
    // bit, and of point() to rounding.
    const std::vector<double> ts{0.0, 0.37, 0.91, 0.999, 1.0};
    const auto pts = r.volume.evaluate(ts, ts, ts);
    const auto der = r.volume.evaluate_derivatives(ts, ts, ts);
    for (std::size_t i = 0; i < ts.size(); ++i)
      for (std::size_t j = 0; j < ts.size(); ++j)
        for (std::size_t k = 0; k < ts.size(); ++k) {
          EXPECT_EQ(pts(i, j, k), der(i, j, k).s) << "trial " << trial;
          // Sums of the same products in another order.
          EXPECT_LT(distance(pts(i, j, k), r.volume.point(ts[i], ts[j], ts[k])), 1e-13 * test::bbox_diagonal(q.values()));
        }
  }
}

// ---------------------------------------------------------------------------
// Smoothness across the seam
// ---------------------------------------------------------------------------

TEST(PeriodicSeam, CurveDerivativesAgreeAtBothEndsOfTheDomain) {
  auto g = test::rng(705);
  for (int trial = 0; trial < 75; ++trial) {
    const int p = 1 + trial % 5;
    const std::size_t n = static_cast<std::size_t>(p) + 1 + static_cast<std::size_t>((trial * 3) % 17);
    const auto q = random_loop(g, n);
    const auto r = interpolate_curve(q, closed_curve(p, kAllParams[(trial / 5) % 3]));
    const auto [a, b] = r.curve.domain();
    // t = back() is evaluated on the last span from the left, t = front() on the
    // first span from the right; the clamped form has separate end control points,
    // so its ends meet only if the geometry does.
    const BSplineCurve open = r.curve.clamped();
    ASSERT_FALSE(open.periodic());
    EXPECT_LT(distance(r.curve.point(a), r.curve.point(b)), kSolveTol * test::bbox_diagonal(q));
    EXPECT_LT(distance(open.point(a), open.point(b)), kSolveTol * test::bbox_diagonal(q));
    for (int k = 1; k < p; ++k) {
      const double big = max_abs_derivative(r.curve, k);
      EXPECT_LT(norm(r.curve.derivative(a, k) - r.curve.derivative(b, k)), kSeamTol * big)
          << "trial " << trial << ", degree " << p << ", order " << k;
      EXPECT_LT(norm(open.derivative(a, k) - open.derivative(b, k)), kSeamTol * big)
          << "clamped form, trial " << trial << ", degree " << p << ", order " << k;
    }
    // Order p: for odd p the seam is a data parameter and a knot, where a spline of
    // degree p is only C^(p-1), and the p-th derivative jumps (random data): the
    // checks above look at a real knot. For even p the knots are the midpoints and
    // the seam 0 an inserted knot inside a polynomial piece: no jump at all.
    const double jump = norm(open.derivative(a, p) - open.derivative(b, p)), big_p = max_abs_derivative(r.curve, p);
    if (p % 2 == 1) {
      EXPECT_GT(jump, 1e-6 * big_p) << "trial " << trial << ", degree " << p;
    } else {
      EXPECT_LT(jump, kSeamTol * big_p) << "trial " << trial << ", degree " << p;
    }
  }
}

TEST(PeriodicSeam, SurfaceDerivativesAgreeAcrossBothSeams) {
  auto g = test::rng(706);
  for (int trial = 0; trial < 30; ++trial) {
    const int pu = 1 + trial % 5, pv = 1 + (trial / 5) % 5;
    const std::size_t nu = static_cast<std::size_t>(pu) + 2 + static_cast<std::size_t>(trial % 5),
                      nv = static_cast<std::size_t>(pv) + 2 + static_cast<std::size_t>((trial * 3) % 5);
    const auto q = random_closed_grid(g, nu, nv, {true, true});
    SurfaceInterpolationOptions o;
    o.degree_u = pu;
    o.degree_v = pv;
    o.param = kAllParams[static_cast<std::size_t>(trial) % 3];
    o.periodic = {true, true};
    const auto r = interpolate_surface(q, o);
    const auto& S = r.surface;
    const auto [u0, u1] = S.domain_u();
    const auto [v0, v1] = S.domain_v();
    const auto grid = linspace(0, 1, 23);
    // The largest partial of each order over the surface, the scale of its jump.
    auto largest_partial = [&](int ku, int kv) {
      double m = 0;
      for (double u : grid)
        for (double v : grid) m = std::max(m, norm(S.derivative(u0 + u * (u1 - u0), v0 + v * (v1 - v0), ku, kv)));
      return m;
    };
    // Across the seam of each closed direction: orders 1..p-1 along it, with 0 or 1
    // along the other, at points spread along the seam.
    const int deg[2] = {pu, pv};
    for (int axis = 0; axis < 2; ++axis)
      for (int k = 1; k < deg[axis]; ++k)
        for (int k_other = 0; k_other <= std::min(1, deg[1 - axis]); ++k_other) {
          const int ku = axis == 0 ? k : k_other, kv = axis == 0 ? k_other : k;
          const double big = largest_partial(ku, kv);
          for (double s : grid) {
            const double u = u0 + s * (u1 - u0), v = v0 + s * (v1 - v0);
            const Vec3 lo = axis == 0 ? S.derivative(u0, v, ku, kv) : S.derivative(u, v0, ku, kv);
            const Vec3 hi = axis == 0 ? S.derivative(u1, v, ku, kv) : S.derivative(u, v1, ku, kv);
            EXPECT_LT(norm(lo - hi), kSeamTol * big) << (axis == 0 ? "u" : "v") << " seam, trial " << trial
                                                     << ", orders " << ku << "," << kv << " at " << s;
          }
        }
  }
}

// ---------------------------------------------------------------------------
// Invariances
// ---------------------------------------------------------------------------

TEST(PeriodicInvariance, CyclicShiftOfTheDataMovesOnlyTheParameterOrigin) {
  auto g = test::rng(707);
  for (int p = 1; p <= 5; ++p)
    for (Parametrization param : kAllParams) {
      const std::size_t n = static_cast<std::size_t>(p) + 6 + static_cast<std::size_t>(p * 3 % 5);
      const auto q = random_loop(g, n);
      const auto r = interpolate_curve(q, closed_curve(p, param));
      const double scale = test::bbox_diagonal(q);
      for (std::size_t s : {std::size_t{1}, n / 2, n - 1}) {
        std::vector<Vec3> qs(q.begin() + static_cast<std::ptrdiff_t>(s), q.end());
        qs.insert(qs.end(), q.begin(), q.begin() + static_cast<std::ptrdiff_t>(s));
        const auto rs = interpolate_curve(qs, closed_curve(p, param));
        const double ts = r.params[s];
        // The new parameters are the old ones less ts, wrapped: running sums started
        // elsewhere round differently (kParamTol).
        for (std::size_t k = 0; k < n; ++k) {
          double want = r.params[(k + s) % n] - ts;
          if (want < 0) want += 1;
          EXPECT_NEAR(rs.params[k], want, kParamTol) << "degree " << p << ", shift " << s << ", point " << k;
        }
        // C_shift(t) = C(t + ts): the parameter rounding above times |C'| (~10 x the
        // scale here) plus the two solves' rounding.
        double e = 0;
        for (double t : linspace(0, 1, 397)) e = std::max(e, distance(rs.curve.point(t), r.curve.point(t + ts)));
        EXPECT_LT(e, kSolveTol * scale) << "degree " << p << ", param " << static_cast<int>(param) << ", shift " << s;
      }
    }
}

TEST(PeriodicInvariance, CyclicShiftOfAClosedGridRow) {
  auto g = test::rng(708);
  for (int p = 1; p <= 5; ++p) {
    const auto q = random_closed_grid(g, 9, 6, {true, false});
    SurfaceInterpolationOptions o;
    o.degree_u = p;
    o.degree_v = 3;
    o.param = kAllParams[static_cast<std::size_t>(p) % 3];
    o.periodic = {true, false};
    const auto r = interpolate_surface(q, o);
    const std::size_t s = 4;
    PointGrid qs({9, 6});
    for (std::size_t i = 0; i < 9; ++i)
      for (std::size_t j = 0; j < 6; ++j) qs(i, j) = q((i + s) % 9, j);
    const auto rs = interpolate_surface(qs, o);
    const double us = r.params_u[s];
    // The same lines along v, averaged in another order: rounding only.
    for (std::size_t j = 0; j < 6; ++j) EXPECT_NEAR(rs.params_v[j], r.params_v[j], kParamTol);
    double e = 0;
    for (double u : linspace(0, 1, 41))
      for (double v : linspace(0, 1, 13)) e = std::max(e, distance(rs.surface.point(u, v), r.surface.point(u + us, v)));
    // As for curves: parameter rounding times |S_u| plus the solves' rounding.
    EXPECT_LT(e, kSolveTol * test::bbox_diagonal(q.values())) << "degree " << p;
  }
}

TEST(PeriodicInvariance, ClosingPointOrLineChangesNothing) {
  // The closing point is recognized and dropped before any arithmetic: what is left is
  // the same doubles, so the result is the same bit for bit.
  auto g = test::rng(709);
  for (int p = 1; p <= 5; ++p)
    for (Parametrization param : kAllParams) {
      const auto q = random_loop(g, static_cast<std::size_t>(p) + 4);
      const auto a = interpolate_curve(q, closed_curve(p, param));
      const auto b = interpolate_curve(with_closing_point(q), closed_curve(p, param));
      EXPECT_EQ(a.curve.knots(), b.curve.knots());
      EXPECT_EQ(a.curve.control_points(), b.curve.control_points());
      ASSERT_EQ(b.params.size(), a.params.size() + 1);
      EXPECT_TRUE(std::equal(a.params.begin(), a.params.end(), b.params.begin()));
      EXPECT_EQ(b.params.back(), 1.0);
    }
  for (int trial = 0; trial < 12; ++trial) {
    const std::array<bool, 2> per{trial % 3 != 1, trial % 3 != 0};
    const auto q = random_closed_grid(g, 7, 6, per);
    SurfaceInterpolationOptions o;
    o.degree_u = 1 + trial % 5;
    o.degree_v = 1 + (trial + 2) % 5;
    o.param = kAllParams[static_cast<std::size_t>(trial) % 3];
    o.periodic = per;
    const auto a = interpolate_surface(q, o);
    PointGrid closed = q;
    if (per[0]) closed = with_closing_line(closed, 0);
    if (per[1]) closed = with_closing_line(closed, 1);
    const auto b = interpolate_surface(closed, o);
    EXPECT_EQ(a.surface.knots_u(), b.surface.knots_u()) << "trial " << trial;
    EXPECT_EQ(a.surface.knots_v(), b.surface.knots_v()) << "trial " << trial;
    EXPECT_EQ(a.surface.control_points().values(), b.surface.control_points().values()) << "trial " << trial;
    if (per[0]) {
      EXPECT_EQ(b.params_u.back(), 1.0);
    }
    if (per[1]) {
      EXPECT_EQ(b.params_v.back(), 1.0);
    }
  }
  const auto q3 = random_closed_grid3(g, {5, 6, 5}, {true, false, true});
  VolumeInterpolationOptions o3;
  o3.periodic = {true, false, true};
  const auto a3 = interpolate_volume(q3, o3);
  const auto b3 = interpolate_volume(with_closing_plane(with_closing_plane(q3, 0), 2), o3);
  EXPECT_EQ(a3.volume.control_points().values(), b3.volume.control_points().values());
  EXPECT_EQ(a3.volume.knots_w(), b3.volume.knots_w());
  EXPECT_EQ(b3.params_u.size(), 6u);
  EXPECT_EQ(b3.params_w.back(), 1.0);
}

TEST(PeriodicInvariance, ClosingLineOfALargeGridIsLeftOutInPlace) {
  // Grids of more than 2^18 points, where the closing line inside the rows is left
  // out by both cores, each moving its share of rows: the result is the same bits as
  // the grid without the line, with 1, 2 and 3 threads (uneven shares).
  auto g = test::rng(721);
  const PointGrid q = random_closed_grid(g, 181, 1451, {false, true}, 1e-4);
  const PointGrid3 q3 = random_closed_grid3(g, {37, 61, 119}, {false, true, true});
  SurfaceInterpolationOptions o;
  o.periodic = {false, true};
  VolumeInterpolationOptions o3;
  o3.periodic = {false, true, true};
#ifdef _OPENMP
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
  omp_set_num_threads(1);
#endif
  const auto a = interpolate_surface(q, o);
  const auto a3 = interpolate_volume(q3, o3);
  for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    const auto b = interpolate_surface(with_closing_line(q, 1), o);
    EXPECT_EQ(b.surface.control_points().values(), a.surface.control_points().values()) << threads << " threads";
    for (int axis : {1, 2}) {
      const auto b3 = interpolate_volume(with_closing_plane(q3, axis), o3);
      EXPECT_EQ(b3.volume.control_points().values(), a3.volume.control_points().values())
          << "closing plane along axis " << axis << ", " << threads << " threads";
    }
  }
#ifdef _OPENMP
  omp_set_num_threads(before);
#endif
}

TEST(PeriodicInvariance, NearlyRepeatedClosingPointIsDropped) {
  // A closing point 1e-14 of the diagonal off the first (within the 1e-12 that makes
  // it the closing point): dropped before any arithmetic, so the curve is the one
  // without it, bit for bit.
  auto g = test::rng(710);
  for (int p = 1; p <= 5; ++p) {
    const auto q = random_loop(g, 10);
    auto near = with_closing_point(q);
    const double diag = test::bbox_diagonal(q);
    near.back() = near.back() + Vec3{1e-14 * diag, -0.5e-14 * diag, 0};
    const auto a = interpolate_curve(q, closed_curve(p, Parametrization::chord));
    const auto b = interpolate_curve(near, closed_curve(p, Parametrization::chord));
    EXPECT_EQ(b.curve.knots(), a.curve.knots()) << "degree " << p;
    EXPECT_EQ(b.curve.control_points(), a.curve.control_points()) << "degree " << p;
    EXPECT_EQ(b.params.back(), 1.0);
  }
}

// Scaling the data by 2^k scales every length by 2^k exactly; the parameters are
// ratios of lengths (or of their square roots) and do not change at all, and the
// control points are solved linearly from the data: 2^k times the unscaled ones, bit
// for bit, while they are normal doubles. Odd k too: sqrt(2^k) is no power of two,
// so centripetal parameters stay the same only because the lengths are brought to
// one scale by a power of two before the roots (as the open interpolation does);
// 2^±900 where squares of the coordinates would overflow or underflow.
const int kScales[] = {500, -500, 501, -501, 900, -900, 37, -3};

/// a == 2^k b, bit for bit, unless 2^k b is not a normal double (then not compared).
void expect_scaled(const Vec3& a, const Vec3& b, int k, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    const double want = std::ldexp(b[c], k);
    if (b[c] != 0 && !std::isnormal(want)) continue;
    EXPECT_EQ(a[c], want) << what << " component " << c << " at 2^" << k;
  }
}

TEST(PeriodicInvariance, ScalingByPowersOfTwo) {
  auto g = test::rng(711);
  for (int p = 1; p <= 5; ++p)
    for (Parametrization param : kAllParams) {
      const auto q = random_loop(g, static_cast<std::size_t>(p) + 5);
      const auto r = interpolate_curve(with_closing_point(q), closed_curve(p, param));
      for (int k : kScales) {
        std::vector<Vec3> qs;
        for (const Vec3& x : with_closing_point(q)) qs.push_back(ldexp(x, k));
        const auto rs = interpolate_curve(qs, closed_curve(p, param));
        EXPECT_EQ(rs.params, r.params) << "degree " << p << " at 2^" << k;
        EXPECT_EQ(rs.curve.knots(), r.curve.knots()) << "degree " << p << " at 2^" << k;
        ASSERT_EQ(rs.curve.control_points().size(), r.curve.control_points().size());
        for (std::size_t i = 0; i < r.curve.control_points().size(); ++i)
          expect_scaled(rs.curve.control_points()[i], r.curve.control_points()[i], k,
                        "control point " + std::to_string(i) + ", degree " + std::to_string(p));
      }
    }
  const auto q = random_closed_grid(g, 7, 6, {true, true});
  SurfaceInterpolationOptions o;
  o.param = Parametrization::centripetal;
  o.periodic = {true, true};
  o.degree_u = 3;
  o.degree_v = 4;
  const auto r = interpolate_surface(with_closing_line(q, 1), o);
  for (int k : kScales) {
    PointGrid qs = with_closing_line(q, 1);
    for (Vec3& x : qs.values()) x = ldexp(x, k);
    const auto rs = interpolate_surface(qs, o);
    EXPECT_EQ(rs.params_u, r.params_u) << "at 2^" << k;
    EXPECT_EQ(rs.params_v, r.params_v) << "at 2^" << k;
    for (std::size_t i = 0; i < r.surface.control_points().size(); ++i)
      expect_scaled(rs.surface.control_points().values()[i], r.surface.control_points().values()[i], k,
                    "surface control point " + std::to_string(i));
  }
}

// ---------------------------------------------------------------------------
// Periodic knot vectors and curves
// ---------------------------------------------------------------------------

TEST(PeriodicKnotVector, PeriodicFromExtendsThePeriod) {
  const KnotVector k = KnotVector::periodic_from(3, {0, 0.1, 0.3, 0.6, 0.8}, 1.0);
  EXPECT_TRUE(k.periodic());
  EXPECT_EQ(k.degree(), 3);
  EXPECT_EQ(k.count(), 5);
  EXPECT_EQ(k.size(), 5u + 2 * 3 + 1);
  const std::vector<double> want{0.3 - 1, 0.6 - 1, 0.8 - 1, 0, 0.1, 0.3, 0.6, 0.8, 1, 0.1 + 1, 0.3 + 1, 0.6 + 1};
  EXPECT_EQ(k.values(), want);
  EXPECT_EQ(k.front(), 0.0);
  EXPECT_EQ(k.back(), 1.0);
  EXPECT_EQ(k.period_knots(), (std::vector<double>{0, 0.1, 0.3, 0.6, 0.8}));
  EXPECT_EQ(k.wrap_index(6), 1);
  EXPECT_EQ(k.wrap_index(4), 4);
  EXPECT_EQ(k.continuity(), 2);
  // A double knot in the period (multiplicity up to the degree is allowed).
  const KnotVector d = KnotVector::periodic_from(2, {0.5, 0.7, 0.7, 1.2}, 1.5);
  EXPECT_EQ(d.count(), 4);
  EXPECT_EQ(d.continuity(), 0);
  EXPECT_EQ(d.front(), 0.5);
  EXPECT_EQ(d.back(), 1.5);
  EXPECT_ERRC((void)KnotVector::periodic_from(3, {0, 0.2, 0.5}, 1.0), too_few_points, "got 3");
  EXPECT_ERRC((void)KnotVector::periodic_from(3, {0, 0.2, 0.5, 1.0}, 1.0), invalid_knots, "knot 3");
  EXPECT_ERRC((void)KnotVector::periodic_from(2, {0, 0.2, 0.2, 0.2, 0.5}, 1.0), invalid_knots, "multiplicity 3");
  EXPECT_ERRC((void)KnotVector::periodic_from(2, {0, 0.4, 0.2, 0.5}, 1.0), non_increasing, "knot 2");
}

TEST(PeriodicKnotVector, WrapMovesByWholePeriods) {
  const KnotVector k = KnotVector::periodic_from(3, {0.25, 0.5, 1.0, 1.5, 2.0}, 2.25);  // period 2
  EXPECT_EQ(k.wrap(1.0), 1.0);
  EXPECT_EQ(k.wrap(0.25), 0.25);
  EXPECT_EQ(k.wrap(2.25), 2.25);  // back() is inside the domain
  EXPECT_EQ(k.wrap(2.75), 0.75);
  EXPECT_EQ(k.wrap(-0.25), 1.75);
  EXPECT_EQ(k.wrap(8.5), 0.5);
  EXPECT_EQ(k.wrap(-5.75), 0.25);
  auto g = test::rng(712);
  for (int i = 0; i < 1000; ++i) {
    const double t = test::uniform(g, -50, 50), w = k.wrap(t);
    EXPECT_GE(w, k.front());
    EXPECT_LE(w, k.back());
    const double periods = (t - w) / 2.0;
    EXPECT_NEAR(periods, std::round(periods), 1e-13) << t;  // rounding of t - 2m for |t| <= 50
  }
  const KnotVector open(3, {0, 0, 0, 0, 1, 1, 1, 1});
  EXPECT_EQ(open.wrap(1.5), 1.5);  // clamped vectors leave t alone
}

TEST(PeriodicKnotVector, ClampedHasTheSameSpaceOverTheDomain) {
  const KnotVector k = KnotVector::periodic_from(3, {0, 0.1, 0.3, 0.6, 0.8}, 1.0);
  const KnotVector c = k.clamped();
  EXPECT_FALSE(c.periodic());
  EXPECT_EQ(c.values(), (std::vector<double>{0, 0, 0, 0, 0.1, 0.3, 0.6, 0.8, 1, 1, 1, 1}));
  // Even degree: the seam 0.05 is no knot of its own; it becomes the clamped ends.
  const KnotVector e = KnotVector::periodic_from(2, {0.05, 0.2, 0.45, 0.7, 0.9}, 1.05);
  EXPECT_EQ(e.clamped().values(), (std::vector<double>{0.05, 0.05, 0.05, 0.2, 0.45, 0.7, 0.9, 1.05, 1.05, 1.05}));
  const KnotVector open(2, {0, 0, 0, 0.5, 1, 1, 1});
  EXPECT_EQ(open.clamped(), open);
}

TEST(PeriodicKnotVector, PartitionOfUnityOverThePeriod) {
  auto g = test::rng(713);
  for (int trial = 0; trial < 100; ++trial) {
    const int p = 1 + trial % 5;
    const std::size_t n = static_cast<std::size_t>(p) + 1 + static_cast<std::size_t>(trial % 9);
    const double a = test::uniform(g, -2, 2), T = test::uniform(g, 0.5, 3);
    std::vector<double> knots{a};
    for (std::size_t i = 1; i < n; ++i) knots.push_back(a + T * (static_cast<double>(i) + test::uniform(g, -0.4, 0.4)) / static_cast<double>(n));
    const KnotVector k = KnotVector::periodic_from(p, knots, a + T);
    std::vector<double> ts = knots;
    // The period's end itself, then points inside (clamped: a + T * s / 50 may round past it).
    ts.push_back(k.back());
    for (int s = 0; s <= 50; ++s) ts.push_back(std::min(a + T * s / 50.0, k.back()));
    double N[max_degree + 1], D[(max_degree + 1) * 3];
    for (double t : ts) {
      const int span = k.find_span(t);
      ASSERT_GE(span, p);
      ASSERT_LT(span, k.count() + p);
      k.basis(span, t, N);
      double sum = 0;
      for (int j = 0; j <= p; ++j) {
        EXPECT_GE(N[j], 0.0);
        sum += N[j];
      }
      // p+1 values, each from p levels of convex combinations: a few roundings.
      EXPECT_NEAR(sum, 1.0, 1e-14) << "degree " << p << ", t = " << t;
      k.basis_derivatives(span, t, std::min(p, 2), D);
      for (int d = 1; d <= std::min(p, 2); ++d) {
        double s = 0, m = 0;
        for (int j = 0; j <= p; ++j) {
          s += D[d * (p + 1) + j];
          m = std::max(m, std::abs(D[d * (p + 1) + j]));
        }
        EXPECT_NEAR(s, 0.0, 1e-13 * m) << "order " << d << ", t = " << t;  // cancellation among terms of size m
      }
    }
  }
}

TEST(PeriodicKnotVector, PeriodicFromExtendedRoundTrip) {
  auto g = test::rng(714);
  for (int p = 1; p <= 5; ++p) {
    std::vector<double> knots{0.2};
    for (int i = 1; i < p + 4; ++i) knots.push_back(0.2 + (i + test::uniform(g, -0.3, 0.3)) / (p + 4));
    const KnotVector k = KnotVector::periodic_from(p, knots, 1.2);
    EXPECT_EQ(KnotVector::periodic_from_extended(p, k.values()), k);
    // Another program's images of the period, off by rounding: the same vector back.
    std::vector<double> rounded = k.values();
    rounded.front() += 3e-16;
    rounded.back() -= 3e-16;
    EXPECT_EQ(KnotVector::periodic_from_extended(p, rounded), k);
    std::vector<double> wrong = k.values();
    wrong.back() += 1e-6;
    EXPECT_ERRC((void)KnotVector::periodic_from_extended(p, wrong), invalid_knots, "does not repeat the period");
  }
}

/// A random closed curve: n control points over a jittered period [a, a + T).
BSplineCurve random_periodic_curve(std::mt19937_64& g, int p, std::size_t n) {
  const double a = test::uniform(g, -1, 1), T = test::uniform(g, 0.5, 2);
  std::vector<double> knots{a};
  for (std::size_t i = 1; i < n; ++i) knots.push_back(a + T * (static_cast<double>(i) + test::uniform(g, -0.3, 0.3)) / static_cast<double>(n));
  std::vector<Vec3> cp;
  for (std::size_t i = 0; i < n; ++i) cp.push_back(test::random_point(g, 2.0));
  return BSplineCurve(KnotVector::periodic_from(p, knots, a + T), cp);
}

/// Largest distance between two curves over the first one's domain, sampled densely.
double curve_distance(const BSplineCurve& a, const BSplineCurve& b) {
  const auto [t0, t1] = a.domain();
  double e = 0;
  for (double s : linspace(0, 1, 301)) e = std::max(e, distance(a.point(t0 + s * (t1 - t0)), b.point(t0 + s * (t1 - t0))));
  return e;
}

TEST(PeriodicCurve, InsertRefineElevateClampKeepTheGeometry) {
  auto g = test::rng(715);
  for (int trial = 0; trial < 40; ++trial) {
    const int p = 1 + trial % 5;
    const std::size_t n = static_cast<std::size_t>(p) + 2 + static_cast<std::size_t>(trial % 6);
    const BSplineCurve c = random_periodic_curve(g, p, n);
    const double scale = test::bbox_diagonal(c.control_points());
    const auto [a, b] = c.domain();
    const double inside = a + 0.37 * (b - a);
    for (int times = 1; times <= p; ++times) {
      const BSplineCurve ins = c.inserted(inside, times);
      EXPECT_TRUE(ins.periodic());
      EXPECT_EQ(ins.control_points().size(), n + static_cast<std::size_t>(times));
      EXPECT_EQ(ins.knots().multiplicity(inside), times);
      EXPECT_LT(curve_distance(c, ins), kRefineTol * scale) << "trial " << trial << ", insert x" << times;
    }
    // The seam itself is a knot like any other (already of multiplicity 1: degree 1
    // takes no more there).
    if (p >= 2) {
      const BSplineCurve seam = c.inserted(a, 1);
      EXPECT_EQ(seam.control_points().size(), n + 1);
      EXPECT_EQ(seam.knots().multiplicity(a), 2);
      EXPECT_LT(curve_distance(c, seam), kRefineTol * scale) << "trial " << trial << ", insert at the seam";
    } else {
      EXPECT_ERRC((void)c.inserted(a, 1), invalid_knots, "multiplicity 2");
    }
    const std::vector<double> extra{a + 0.11 * (b - a), a + 0.5 * (b - a), a + 0.93 * (b - a)};
    const BSplineCurve ref = c.refined(extra);
    EXPECT_EQ(ref.control_points().size(), n + 3);
    EXPECT_LT(curve_distance(c, ref), kRefineTol * scale) << "trial " << trial << ", refined";
    for (int t = 1; t <= 2; ++t) {
      const BSplineCurve el = c.elevated(t);
      EXPECT_TRUE(el.periodic());
      EXPECT_EQ(el.degree(), p + t);
      EXPECT_EQ(el.knots().continuity(), c.knots().continuity());  // every multiplicity grows by t
      EXPECT_LT(curve_distance(c, el), kRefineTol * scale) << "trial " << trial << ", elevated by " << t;
    }
    const BSplineCurve cl = c.clamped();
    EXPECT_FALSE(cl.periodic());
    EXPECT_EQ(cl.domain(), c.domain());
    EXPECT_LT(curve_distance(c, cl), kRefineTol * scale) << "trial " << trial << ", clamped";
    EXPECT_LT(distance(cl.control_points().front(), c.point(a)), kRefineTol * scale);
    EXPECT_LT(distance(cl.control_points().back(), c.point(a)), kRefineTol * scale);
    // Parameters one period on are the same points.
    EXPECT_LT(distance(c.point(inside + (b - a)), c.point(inside)), 1e-14 * scale);  // wrap: one subtraction
  }
}

// ---------------------------------------------------------------------------
// The cyclic solve at scale
// ---------------------------------------------------------------------------

TEST(PeriodicLarge, TenThousandPointsStayAccurate) {
  // A circle through 10^4 points at jittered angles: the cyclic banded solve must
  // neither lose accuracy with N (its condition is that of the local collocation,
  // independent of N) nor pick up the closing coupling wrongly.
  auto g = test::rng(716);
  const std::size_t n = 10000;
  std::vector<Vec3> q;
  for (std::size_t k = 0; k < n; ++k) {
    const double a = kTwoPi * (static_cast<double>(k) + test::uniform(g, -0.3, 0.3)) / static_cast<double>(n);
    q.push_back({std::cos(a), std::sin(a), 0});
  }
  for (int p = 1; p <= 5; ++p) {
    const auto r = interpolate_curve(q, closed_curve(p, Parametrization::chord));
    double e = 0;
    for (std::size_t i = 0; i < n; ++i) e = std::max(e, distance(r.curve.point(r.params[i]), q[i]));
    EXPECT_LT(e, kSolveTol * 2) << "degree " << p;  // the diagonal is 2; seen 3.5e-16
    // Between the data the curve stays on the circle to the interpolation error:
    // h^2 / 8 = 1.2e-7 for the chords (h = 1e-3 at most), O(h^3) ~ 1e-9 at most for
    // higher degrees (seen 1e-14 halfway between the data, where it is smallest).
    double off = 0;
    for (std::size_t i = 0; i + 1 < n; i += 7)
      off = std::max(off, std::abs(norm(r.curve.point(0.5 * (r.params[i] + r.params[i + 1]))) - 1));
    EXPECT_LT(off, p == 1 ? 2e-7 : 1e-9) << "degree " << p;
  }
  // A pipe 4000 lines around, closed in u.
  // Noise below the step around (3 * 2 pi / 4000 = 5e-3).
  PointGrid pipe = random_closed_grid(g, 4000, 5, {true, false}, 2e-4);
  SurfaceInterpolationOptions o;
  o.periodic = {true, false};
  const auto r = interpolate_surface(pipe, o);
  double e = 0;
  for (std::size_t i = 0; i < pipe.extent(0); i += 3)
    for (std::size_t j = 0; j < pipe.extent(1); ++j)
      e = std::max(e, distance(r.surface.point(r.params_u[i], r.params_v[j]), pipe(i, j)));
  EXPECT_LT(e, kSolveTol * test::bbox_diagonal(pipe.values()));
}

// ---------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------

TEST(PeriodicBadInput, TooFewDistinctPoints) {
  const std::vector<Vec3> tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  // Three distinct points and a closing point: a closed cubic needs four.
  EXPECT_ERRC((void)interpolate_curve(with_closing_point(tri), closed_curve(3, Parametrization::chord)), too_few_points,
              "degree 3 needs at least 4 distinct points, got 3 (the last point repeats the first and is left out)");
  EXPECT_ERRC((void)interpolate_curve(tri, closed_curve(3, Parametrization::chord)), too_few_points,
              "degree 3 needs at least 4 distinct points, got 3");
  EXPECT_NO_THROW((void)interpolate_curve(tri, closed_curve(2, Parametrization::chord)));
  auto g = test::rng(717);
  SurfaceInterpolationOptions o;
  o.periodic = {false, true};
  o.degree_v = 4;
  // Five lines along v with a closing one: four distinct, degree 4 needs five.
  EXPECT_ERRC((void)interpolate_surface(with_closing_line(random_closed_grid(g, 5, 4, {false, true}), 1), o),
              too_few_points, "degree 4 around v (closed) needs at least 5 points, got 4");
}

TEST(PeriodicBadInput, ClosingGap) {
  auto g = test::rng(718);
  const auto q = random_loop(g, 8);
  auto gap = with_closing_point(q);
  // 1e-7 of the shortest chord: far below 1e-3 of the chords next to it, far above
  // 1e-12 of the diagonal.
  double shortest = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < q.size(); ++k) shortest = std::min(shortest, distance(q[k], q[(k + 1) % q.size()]));
  gap.back() = gap.back() + Vec3{1e-7 * shortest, 0, 0};
  EXPECT_ERRC((void)interpolate_curve(gap, closed_curve(3, Parametrization::chord)), closing_gap,
              "point 8 = ");
  // The open curve has no closing point: the same data are fine.
  EXPECT_NO_THROW((void)interpolate_curve(gap));

  PointGrid grid = with_closing_line(random_closed_grid(g, 6, 5, {true, false}), 0);
  grid(6, 2) = grid(6, 2) + Vec3{0, 1e-9, 0};
  SurfaceInterpolationOptions o;
  o.periodic = {true, false};
  EXPECT_ERRC((void)interpolate_surface(grid, o), closing_gap, "point [6][2], the last along u");

  PointGrid3 vol = with_closing_plane(random_closed_grid3(g, {5, 4, 6}, {false, false, true}), 2);
  vol(1, 2, 6) = vol(1, 2, 6) + Vec3{0, 0, 1e-9};
  VolumeInterpolationOptions ov;
  ov.periodic = {false, false, true};
  EXPECT_ERRC((void)interpolate_volume(vol, ov), closing_gap, "point [1][2][6], the last along w");
}

TEST(PeriodicBadInput, ZeroClosingChord) {
  auto g = test::rng(719);
  const auto q = random_loop(g, 7);
  auto twice = with_closing_point(with_closing_point(q));  // the last two points both equal the first
  EXPECT_ERRC((void)interpolate_curve(twice, closed_curve(3, Parametrization::chord)), zero_chord, "points 7 and 0");
  EXPECT_ERRC((void)closed_curve_parameters(with_closing_point(q), Parametrization::chord), zero_chord,
              "points 7 and 0 (the closing chord) coincide");
  // Two equal points in a row inside the loop.
  auto dup = q;
  dup.insert(dup.begin() + 3, q[3]);
  EXPECT_ERRC((void)interpolate_curve(dup, closed_curve(3, Parametrization::chord)), zero_chord, "points 3 and 4 coincide");
  // A grid whose last two lines along v both repeat the first: one is the closing
  // line, the other leaves a closing chord of zero length on every line.
  const PointGrid grid = with_closing_line(with_closing_line(random_closed_grid(g, 5, 6, {false, true}), 1), 1);
  SurfaceInterpolationOptions o;
  o.periodic = {false, true};
  EXPECT_ERRC((void)interpolate_surface(grid, o), zero_chord,
              "the last and the first grid points along v coincide on every line");
}

TEST(PeriodicBadInput, EndDerivativesOnAClosedCurve) {
  auto g = test::rng(720);
  CurveInterpolationOptions o = closed_curve(3, Parametrization::chord);
  o.start_derivative = Vec3{1, 0, 0};
  EXPECT_ERRC((void)interpolate_curve(random_loop(g, 6), o), wrong_type,
              "start and end derivatives do not apply to a periodic curve");
}

}  // namespace
}  // namespace interpatch
