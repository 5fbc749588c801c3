// Tests of loft (include/interpatch/loft.hpp): every section reproduced along its
// line v = v_k over its own domain mapped onto [0, 1]; C^(q−1) across the sections;
// closed sections turned and shifted so that rotated or reversed input makes the
// aligned surface (circles, a wing); the knots kept within 4 times the largest
// section's; the periodic loft; rational sections; the degree lowered for few
// sections; tangents across; similarity invariance; the errors; the spec form.
// Sections are evaluated by BSplineCurve::point, the surface by BSplineSurface::point
// and ::derivative, and the expected values come from the sections and formulas
// (ruled, Hermite), never from the loft's own code.

#include "interpatch/loft.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/io/spec.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

using json = nlohmann::json;
using std::numbers::pi;
constexpr double eps = std::numeric_limits<double>::epsilon();

// ------------------------------------------------------------------ helpers

double diagonal_of(const std::vector<BSplineCurve>& s) {
  std::vector<Vec3> all;
  for (const auto& c : s) all.insert(all.end(), c.control_points().begin(), c.control_points().end());
  return test::bbox_diagonal(all);
}

/// The section's own parameter at surface parameter u, as the header defines it: its
/// domain mapped linearly onto [0, 1], turned round when reversed, and for a closed
/// section started where the report puts the seam (map(0)), wrapped by whole periods.
double own_parameter(const BSplineCurve& c, const LoftSectionReport& r, double u) {
  const auto [lo, hi] = c.domain();
  const double len = hi - lo;
  if (!r.closed) return r.reversed ? hi - u * len : lo + u * len;
  const double seam = r.map(0.0);
  double t = r.reversed ? seam - u * len : seam + u * len;
  t -= std::floor((t - lo) / len) * len;
  return std::clamp(t, lo, hi);  // rounding may leave it a unit outside; a closed curve's ends are one point
}

/// Largest |S(u, v_k) − C_k(own parameter)| of section k over n parameters u.
double section_error(const LoftSurface& L, const std::vector<BSplineCurve>& s, std::size_t k, std::size_t n = 257) {
  double e = 0;
  for (double u : linspace(0, 1, n))
    e = std::max(e, distance(L.surface.point(u, L.report.params[k]), s[k].point(own_parameter(s[k], L.report.sections[k], u))));
  return e;
}

// S(u, v_k) is the interpolation across of the sections' control points evaluated
// back at its node: rounding of coordinates of about the data's size, amplified by
// the conditioning of the collocation across (sections spread evenly: below 10) and
// by knot insertion and degree elevation (convex combinations). A few hundred units
// in the last place of data lying within a diagonal of the origin; 1e-12 of the
// diagonal is about 4500 units.
constexpr double kReproduce = 1e-12;

/// Every section reproduced along its line over its own domain, the reported maps
/// the linear ones own_parameter makes (modulo a period for closed sections).
void expect_sections_reproduced(const LoftSurface& L, const std::vector<BSplineCurve>& s, double tol,
                                const std::string& what = "") {
  ASSERT_EQ(L.report.sections.size(), s.size()) << what;
  ASSERT_GE(L.report.params.size(), s.size()) << what;
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_LE(section_error(L, s, k), tol) << what << " section " << k;
    const auto [lo, hi] = s[k].domain();
    const LoftSectionReport& r = L.report.sections[k];
    for (double u : linspace(0, 1, 9)) {
      double d = std::abs(r.map(u) - own_parameter(s[k], r, u));
      if (r.closed) d = std::min(d, std::abs(d - (hi - lo)));  // the two ends of a period are one point
      // The map is linear: its values to rounding of the domain's size.
      EXPECT_LE(d, 1e-12 * (std::abs(lo) + std::abs(hi))) << what << " section " << k << " map at u = " << u;
    }
  }
}

/// Largest distance between two surfaces on an n × m grid.
double surface_distance(const BSplineSurface& a, const BSplineSurface& b, std::size_t n = 41, std::size_t m = 41) {
  double e = 0;
  for (double u : linspace(0, 1, n))
    for (double v : linspace(0, 1, m)) e = std::max(e, distance(a.point(u, v), b.point(u, v)));
  return e;
}

/// K points round a circle of radius r about `centre` (in its plane z = centre.z),
/// the first at angle 2π start / K, going round the other way when reversed.
std::vector<Vec3> circle_points(int K, double r, const Vec3& centre, int start = 0, bool reversed = false) {
  std::vector<Vec3> p;
  for (int i = 0; i < K; ++i) {
    const int j = (((reversed ? start - i : start + i) % K) + K) % K;
    const double a = 2 * pi * j / K;
    p.push_back(centre + Vec3{r * std::cos(a), r * std::sin(a), 0});
  }
  return p;
}

/// The closed (periodic) interpolant through the points, chord parameters.
BSplineCurve closed_through(const std::vector<Vec3>& p, int degree = 3) {
  CurveInterpolationOptions o;
  o.periodic = true;
  o.degree = degree;
  return interpolate_curve(p, o).curve;
}

BSplineCurve open_through(const std::vector<Vec3>& p, Parametrization param = Parametrization::chord) {
  CurveInterpolationOptions o;
  o.param = param;
  return interpolate_curve(p, o).curve;
}

/// The rotation of the list so that it starts at point m, reversed (starting at
/// point m and going backwards) or not.
std::vector<Vec3> rotated(const std::vector<Vec3>& p, std::size_t m, bool reversed) {
  std::vector<Vec3> r;
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i) r.push_back(p[reversed ? (m + n - i) % n : (m + i) % n]);
  return r;
}

/// The same clamped curve run the other way: knots reflected in the domain, control
/// points and weights reversed (exact, bit for bit, up to the knots' reflection).
BSplineCurve reversed_curve(const BSplineCurve& c) {
  const auto& k = c.knots().values();
  const double lo = c.domain().first, hi = c.domain().second;
  std::vector<double> r;
  for (std::size_t i = k.size(); i-- > 0;) r.push_back(lo + hi - k[i]);
  for (int i = 0; i <= c.degree(); ++i) {  // the ends exactly
    r[static_cast<std::size_t>(i)] = lo;
    r[r.size() - 1 - static_cast<std::size_t>(i)] = hi;
  }
  std::vector<Vec3> cp(c.control_points().rbegin(), c.control_points().rend());
  std::vector<double> w(c.weights().rbegin(), c.weights().rend());
  return BSplineCurve(KnotVector(c.degree(), r), cp, w);
}

/// A gently bent open curve from x = 0 to x = len at height z: n points, spacing
/// jittered, on y = a sin(ω x + φ).
std::vector<Vec3> wave_points(std::mt19937_64& g, std::size_t n, double len, double z, double a, double w, double phase) {
  std::vector<Vec3> p;
  for (std::size_t i = 0; i < n; ++i) {
    double x = len * (static_cast<double>(i) + (i == 0 || i + 1 == n ? 0.0 : test::uniform(g, -0.3, 0.3))) /
               static_cast<double>(n - 1);
    p.push_back({x, a * std::sin(w * x + phase), z + 0.1 * std::cos(0.7 * x)});
  }
  return p;
}

/// A variety of open sections stacked along z: interpolants of different degrees and
/// parameters, a quadratic B-spline over [2, 5], a line, a quartic over [-1, 0.5].
std::vector<BSplineCurve> mixed_open_sections() {
  auto g = test::rng(900);
  std::vector<BSplineCurve> s;
  s.push_back(open_through(wave_points(g, 7, 4, 0, 0.4, 1.1, 0.2)));
  s.push_back(BSplineCurve(KnotVector(2, {2, 2, 2, 3, 3.5, 5, 5, 5}),
                           {{0, 0.1, 1.1}, {1, 0.6, 0.9}, {2, -0.3, 1.2}, {3, 0.2, 1}, {4, 0, 1.05}}));
  s.push_back(line({0.1, -0.2, 2}, {3.9, 0.3, 2.2}));
  s.push_back(open_through(wave_points(g, 12, 4, 3, 0.3, 1.7, 1.0), Parametrization::centripetal));
  s.push_back(BSplineCurve(KnotVector(4, {-1, -1, -1, -1, -1, -0.4, 0.5, 0.5, 0.5, 0.5, 0.5}),
                           {{0, 0, 4}, {0.7, 0.5, 4.2}, {1.6, -0.4, 3.9}, {2.5, 0.3, 4.1}, {3.3, -0.2, 4}, {4, 0.1, 4}}));
  return s;
}

/// A NURBS circle of radius r about `centre` in its plane z = centre.z: 9 control
/// points, quadratic, an open knot vector whose ends meet (a closed section).
BSplineCurve nurbs_circle(double r, const Vec3& centre) {
  const double h = std::sqrt(0.5);
  std::vector<Vec3> cp;
  const Vec3 corners[9] = {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}, {0, -1, 0}, {1, -1, 0}, {1, 0, 0}};
  for (const Vec3& c : corners) cp.push_back(centre + r * c);
  return BSplineCurve(KnotVector(2, {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}), cp, {1, h, 1, h, 1, h, 1, h, 1});
}

/// Multiplicities of the distinct interior knots of a clamped vector, or of every
/// knot of one period of a periodic one (the seam included).
std::vector<int> interior_multiplicities(const KnotVector& k) {
  const auto& v = k.values();
  const std::size_t p = static_cast<std::size_t>(k.degree());
  std::size_t first = p, last = v.size() - p;  // [first, last): the domain's knots
  if (!k.periodic()) {
    while (first < v.size() && v[first] == v[p]) ++first;
    while (last > 0 && v[last - 1] == v[v.size() - 1 - p]) --last;
  } else {
    last = p + static_cast<std::size_t>(k.count());
  }
  std::vector<int> m;
  for (std::size_t i = first; i < last; ++i) {
    if (i > first && v[i] == v[i - 1]) ++m.back();
    else m.push_back(1);
  }
  return m;
}

/// Expects an interpatch::error with the code; returns its message.
std::string expect_code(const std::function<void()>& f, errc code, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": expected interpatch::error " << to_string(code);
  } catch (const error& e) {
    EXPECT_EQ(e.code(), code) << what << ": " << e.what();
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": threw a std::exception that is not interpatch::error: " << e.what();
  }
  return "";
}

// ------------------------------------------------------------------ sections and parameters

TEST(Loft, ReproducesEverySectionOverItsOwnDomain) {
  const auto s = mixed_open_sections();
  const LoftSurface L = loft(s);
  const double diag = diagonal_of(s);
  EXPECT_EQ(L.surface.degree_u(), 4);  // the highest section degree
  EXPECT_EQ(L.surface.degree_v(), 3);
  EXPECT_EQ(L.report.degree_u, 4);
  EXPECT_EQ(L.report.degree_v, 3);
  EXPECT_FALSE(L.report.closed);
  EXPECT_FALSE(L.surface.periodic()[0]);
  EXPECT_FALSE(L.surface.periodic()[1]);
  // The diagonal and the default tolerance of the control points' box, to rounding.
  EXPECT_NEAR(L.report.diagonal, diag, 1e-14 * diag);
  EXPECT_NEAR(L.report.tolerance, 1e-7 * diag, 1e-20 * diag);
  ASSERT_EQ(L.report.params.size(), s.size());
  EXPECT_EQ(L.report.params.front(), 0.0);
  EXPECT_EQ(L.report.params.back(), 1.0);
  for (std::size_t k = 1; k < s.size(); ++k) EXPECT_LT(L.report.params[k - 1], L.report.params[k]);
  for (const auto& r : L.report.sections) {
    EXPECT_FALSE(r.closed);
    EXPECT_FALSE(r.reversed);  // all given running the same way
    EXPECT_LE(r.deviation, L.report.max_deviation);
  }
  EXPECT_FALSE(L.report.reexpressed);
  expect_sections_reproduced(L, s, kReproduce * diag);
  // The surface over [0, 1]²: the sections' ends at u = 0 and u = 1.
  EXPECT_EQ(L.surface.domain_u(), (std::pair<double, double>{0.0, 1.0}));
  EXPECT_EQ(L.surface.domain_v(), (std::pair<double, double>{0.0, 1.0}));
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_LE(distance(L.surface.point(0, L.report.params[k]), s[k].point(s[k].domain().first)), kReproduce * diag);
    EXPECT_LE(distance(L.surface.point(1, L.report.params[k]), s[k].point(s[k].domain().second)), kReproduce * diag);
  }
}

// Translated copies of one curve are the same distance apart at every u, so each
// rule's parameters follow from the translations alone, however the loft samples u.
TEST(Loft, ParametersOfTranslatedSections) {
  auto g = test::rng(901);
  const auto base = open_through(wave_points(g, 9, 3, 0, 0.5, 1.3, 0.4));
  const std::vector<Vec3> offsets = {{0, 0, 0}, {0.1, 0.2, 1}, {0.1, 0.2, 3.5}, {-0.4, 0.9, 4}, {-0.4, 0.9, 6.25}};
  std::vector<BSplineCurve> s;
  for (const Vec3& o : offsets) {
    std::vector<Vec3> cp;
    for (const Vec3& q : base.control_points()) cp.push_back(q + o);
    s.push_back(BSplineCurve(base.knots(), cp));
  }
  const double diag = diagonal_of(s);
  for (Parametrization p : {Parametrization::chord, Parametrization::centripetal, Parametrization::uniform}) {
    std::vector<double> want{0};
    for (std::size_t k = 1; k < offsets.size(); ++k) {
      const double d = distance(offsets[k], offsets[k - 1]);
      want.push_back(want.back() + (p == Parametrization::chord ? d : p == Parametrization::centripetal ? std::sqrt(d) : 1.0));
    }
    for (double& w : want) w /= want.back();
    LoftOptions o;
    o.param = p;
    const LoftSurface L = loft(s, o);
    ASSERT_EQ(L.report.params.size(), want.size());
    // Averages of one distance computed at many u: a few units of rounding.
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(L.report.params[k], want[k], 64 * eps) << "k = " << k;
    expect_sections_reproduced(L, s, kReproduce * diag);
  }
  // Given parameters are used as they are.
  LoftOptions given;
  given.params = {0, 0.1, 0.5, 0.55, 1};
  const LoftSurface G = loft(s, given);
  EXPECT_EQ(G.report.params, given.params);
  expect_sections_reproduced(G, s, kReproduce * diag);
}

// C^(q−1) across: the v knots are simple (the B-spline is C^(q−1) at a simple knot),
// and, numerically, the derivatives of orders below q do not jump at any knot or
// section: across 2h a derivative of order d moves by at most 2h times the largest
// derivative of order d + 1 nearby (a jump at a double knot would be of the
// derivative's own size), plus rounding of the derivative's evaluation.
TEST(Loft, IsSmoothOfOrderQMinusOneAcrossTheSections) {
  auto g = test::rng(902);
  std::vector<BSplineCurve> s;
  for (int k = 0; k < 7; ++k)
    s.push_back(open_through(wave_points(g, 6 + static_cast<std::size_t>(k), 4, 0.8 * k + 0.3 * (k % 2), 0.3 + 0.1 * k, 1.0, 0.3 * k)));
  for (int q : {2, 3, 4}) {
    LoftOptions o;
    o.degree = q;
    const LoftSurface L = loft(s, o);
    ASSERT_EQ(L.surface.degree_v(), q);
    EXPECT_EQ(L.report.degree_v, q);
    for (int m : interior_multiplicities(L.surface.knots_v())) EXPECT_EQ(m, 1) << "q = " << q;
    EXPECT_GE(L.surface.knots_v().continuity(), q - 1);
    std::vector<double> at;
    for (const auto& [x, mult] : L.surface.knots_v().interior_breaks()) at.push_back(x);
    at.insert(at.end(), L.report.params.begin() + 1, L.report.params.end() - 1);
    const double h = 1e-6, diag = diagonal_of(s);
    for (double v : at)
      for (double u : linspace(0, 1, 7))
        for (int d = 0; d < q; ++d) {
          const Vec3 below = L.surface.derivative(u, v - h, 0, d), above = L.surface.derivative(u, v + h, 0, d);
          const double next = std::max(norm(L.surface.derivative(u, v - h, 0, d + 1)), norm(L.surface.derivative(u, v + h, 0, d + 1)));
          EXPECT_LE(distance(below, above), 3 * h * next + 1e-10 * std::max({norm(below), norm(above), diag}))
              << "q = " << q << ", order " << d << " at (" << u << ", " << v << ")";
        }
    expect_sections_reproduced(L, s, kReproduce * diagonal_of(s), "q = " + std::to_string(q));
  }
}

TEST(Loft, OpenSectionGivenBackwardsIsTurnedRound) {
  const auto s = mixed_open_sections();
  auto t = s;
  t[2] = reversed_curve(s[2]);
  t[4] = reversed_curve(s[4]);
  const LoftSurface A = loft(s), B = loft(t);
  const double diag = diagonal_of(s);
  for (std::size_t k = 0; k < s.size(); ++k) EXPECT_EQ(B.report.sections[k].reversed, k == 2 || k == 4) << k;
  expect_sections_reproduced(B, t, kReproduce * diag);
  // Reversing a curve reflects its knots (rounding of the domain's size): the same surface.
  EXPECT_LE(surface_distance(A.surface, B.surface), kReproduce * diag);
}

// ------------------------------------------------------------------ closed sections

struct Circles {
  std::vector<double> radius;
  std::vector<Vec3> centre;
};

// Five circles of 12 points, interpolated closed, given starting at other points
// and some the other way round: the surface is the one of the aligned circles (the
// first one sets the seam and the direction, and stays as it is).
TEST(Loft, RotatedAndReversedCirclesMakeTheAlignedSurface) {
  const Circles c{{1, 1.4, 0.8, 1.1, 0.6}, {{0, 0, 0}, {0.2, -0.1, 1}, {-0.3, 0.2, 2.2}, {0.1, 0.1, 3}, {0, 0.3, 4.5}}};
  const int starts[5] = {0, 5, 0, 9, 3};
  const bool back[5] = {false, false, true, true, false};
  std::vector<BSplineCurve> aligned, given;
  for (std::size_t k = 0; k < 5; ++k) {
    aligned.push_back(closed_through(circle_points(12, c.radius[k], c.centre[k])));
    given.push_back(closed_through(circle_points(12, c.radius[k], c.centre[k], starts[k], back[k])));
  }
  const LoftSurface A = loft(aligned), B = loft(given);
  const double diag = diagonal_of(aligned);
  EXPECT_TRUE(A.report.closed);
  EXPECT_TRUE(B.report.closed);
  EXPECT_TRUE(B.surface.periodic()[0]);  // periodic sections: periodic in u
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_TRUE(B.report.sections[k].closed) << k;
    EXPECT_FALSE(A.report.sections[k].reversed) << k;
    EXPECT_EQ(B.report.sections[k].reversed, back[k]) << k;
    // The seam falls where the aligned circle starts, at angle 0.
    const Vec3 start = c.centre[k] + Vec3{c.radius[k], 0, 0};
    EXPECT_LE(distance(given[k].point(B.report.sections[k].map(0.0)), start), kReproduce * diag) << k;
    EXPECT_LE(distance(aligned[k].point(A.report.sections[k].map(0.0)), start), kReproduce * diag) << k;
  }
  expect_sections_reproduced(A, aligned, kReproduce * diag, "aligned");
  expect_sections_reproduced(B, given, kReproduce * diag, "given");
  // The rotated interpolants are the aligned ones shifted by a knot, to rounding of
  // their solves: the same surface to rounding.
  EXPECT_LE(surface_distance(A.surface, B.surface), kReproduce * diag);
}

// Circles about one axis are scaled copies of one closed curve: lofted without a
// twist, S(u, v) = r(v) C(u) + z(v) e_z lies in the half-plane through the axis and
// C(u), whatever start and direction each circle was given with.
TEST(Loft, CirclesAboutOneAxisGiveIsolinesInAPlaneThroughIt) {
  const double radius[4] = {1, 1.6, 0.7, 1.2}, height[4] = {0, 1, 2.5, 3};
  const int starts[4] = {0, 7, 2, 11};
  const bool back[4] = {false, true, false, true};
  std::vector<BSplineCurve> s;
  for (std::size_t k = 0; k < 4; ++k) s.push_back(closed_through(circle_points(12, radius[k], {0, 0, height[k]}, starts[k], back[k])));
  const LoftSurface L = loft(s);
  const double diag = diagonal_of(s);
  expect_sections_reproduced(L, s, kReproduce * diag);
  for (double u : linspace(0, 1, 25)) {
    const Vec3 d = L.surface.point(u, 0.0);  // section 0, about the axis
    for (double v : linspace(0, 1, 21)) {
      const Vec3 p = L.surface.point(u, v);
      // |p_xy × d_xy| / |d_xy|: the distance of p from the plane through the axis and d.
      const double off = std::abs(p.x * d.y - p.y * d.x) / std::hypot(d.x, d.y);
      EXPECT_LE(off, kReproduce * diag) << "(" << u << ", " << v << ")";
      EXPECT_GT(p.x * d.x + p.y * d.y, 0) << "(" << u << ", " << v << ")";  // on the same side of the axis
    }
  }
}

/// A NACA 4-digit airfoil (camber m at p, thickness t) of unit chord as a closed
/// polygon: the upper side from the trailing edge to the leading edge, then the lower
/// side back, 2n + 1 points at cosine spacing (the trailing edge is open: two points).
std::vector<Vec3> naca(double m, double p, double t, std::size_t n) {
  auto yt = [&](double x) {
    return 5 * t * (0.2969 * std::sqrt(x) - 0.1260 * x - 0.3516 * x * x + 0.2843 * x * x * x - 0.1015 * x * x * x * x);
  };
  auto camber = [&](double x) {
    const double yc = x < p ? m / (p * p) * (2 * p * x - x * x) : m / ((1 - p) * (1 - p)) * (1 - 2 * p + 2 * p * x - x * x);
    const double dy = x < p ? 2 * m / (p * p) * (p - x) : 2 * m / ((1 - p) * (1 - p)) * (p - x);
    return std::pair<double, double>{yc, std::atan(dy)};
  };
  auto side = [&](double x, double sign) {
    const auto [yc, th] = camber(x);
    return Vec3{x - sign * yt(x) * std::sin(th), yc + sign * yt(x) * std::cos(th), 0};
  };
  std::vector<Vec3> q;
  for (std::size_t i = n + 1; i-- > 0;) q.push_back(side(0.5 * (1 - std::cos(pi * static_cast<double>(i) / static_cast<double>(n))), 1));
  for (std::size_t i = 1; i <= n; ++i) q.push_back(side(0.5 * (1 - std::cos(pi * static_cast<double>(i) / static_cast<double>(n))), -1));
  return q;
}

// A wing: six NACA 2412 sections, each scaled, twisted about its quarter chord, swept
// and raised, interpolated closed through their points given with starts anywhere
// round the section and some the other way round: the same wing as from the aligned
// sections.
TEST(Loft, WingOfShiftedAndReversedAirfoilsIsTheAlignedWing) {
  const std::vector<Vec3> airfoil = naca(0.02, 0.4, 0.12, 20);
  const std::size_t n = airfoil.size();
  auto g = test::rng(903);
  std::vector<BSplineCurve> aligned, given;
  std::vector<bool> back;
  for (std::size_t k = 0; k < 6; ++k) {
    const double chord = std::pow(0.92, static_cast<double>(k)), twist = -2.0 * pi / 180 * static_cast<double>(k);
    std::vector<Vec3> q;
    for (const Vec3& a : airfoil) {
      const double x = chord * (a.x - 0.25), y = chord * a.y;
      q.push_back({0.25 + 0.12 * static_cast<double>(k) + x * std::cos(twist) - y * std::sin(twist),
                   x * std::sin(twist) + y * std::cos(twist), 0.7 * static_cast<double>(k)});
    }
    const std::size_t start = k == 0 ? 0 : static_cast<std::size_t>(std::uniform_int_distribution<int>(1, static_cast<int>(n) - 1)(g));
    back.push_back(k == 1 || k == 4 || (k > 1 && test::uniform(g, 0, 1) < 0.5));
    aligned.push_back(closed_through(q));
    given.push_back(closed_through(rotated(q, start, back.back())));
  }
  const LoftSurface A = loft(aligned), B = loft(given);
  const double diag = diagonal_of(aligned);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(B.report.sections[k].reversed, back[k]) << k;
  expect_sections_reproduced(A, aligned, kReproduce * diag, "aligned");
  expect_sections_reproduced(B, given, kReproduce * diag, "given");
  EXPECT_LE(surface_distance(A.surface, B.surface, 121, 21), kReproduce * diag);
}

// Open curves whose ends meet (exactly, or within the tolerance) are closed
// sections; the surface's edges u = 0 and u = 1 then meet.
TEST(Loft, OpenCurvesWhoseEndsMeetAreClosedSections) {
  std::vector<BSplineCurve> s;
  for (int k = 0; k < 3; ++k) {
    auto p = circle_points(9, 1 + 0.2 * k, {0.1 * k, 0, 1.0 * k});
    for (Vec3& q : p) q.y *= 0.6;  // ellipses
    p.push_back(p.front());        // the end on the start: closed, open knots
    s.push_back(open_through(p));
  }
  const double diag = diagonal_of(s);
  const LoftSurface L = loft(s);
  EXPECT_TRUE(L.report.closed);
  for (const auto& r : L.report.sections) EXPECT_TRUE(r.closed);
  expect_sections_reproduced(L, s, kReproduce * diag);
  // The edges are the sections' start and end, one point each: to rounding.
  for (double v : linspace(0, 1, 11)) EXPECT_LE(distance(L.surface.point(0, v), L.surface.point(1, v)), kReproduce * diag);

  // A fourth whose end misses its start by 1e-9 of the diagonal: closed under the
  // default tolerance (1e-7 of it), open under 1e-10 of it (then mixed: refused).
  auto p = circle_points(9, 1.5, {0.3, 0, 3.0});
  for (Vec3& q : p) q.y *= 0.6;
  p.push_back(p.front() + Vec3{0, 0, 1e-9 * diag});
  s.push_back(open_through(p));
  const LoftSurface M = loft(s);
  EXPECT_TRUE(M.report.sections[3].closed);
  // Closing it may move it by up to its gap: every section within the tolerance (and
  // rounding).
  for (std::size_t k = 0; k < s.size(); ++k) EXPECT_LE(section_error(M, s, k), M.report.tolerance + kReproduce * diag) << k;
  LoftOptions strict;
  strict.tolerance = 1e-10 * diag;
  expect_code([&] { (void)loft(s, strict); }, errc::closing_gap, "a gap above the tolerance");
}

TEST(Loft, MixingClosedAndOpenSectionsIsRefused) {
  const std::vector<BSplineCurve> s = {closed_through(circle_points(8, 1, {0, 0, 0})), closed_through(circle_points(8, 1.2, {0, 0, 1})),
                                       line({-1, 0, 2}, {1, 0, 2})};
  const std::string m = expect_code([&] { (void)loft(s); }, errc::closing_gap, "two circles and a line");
  // Naming both: the open one and a closed one.
  EXPECT_NE(m.find("sections[2]"), std::string::npos) << m;
  EXPECT_TRUE(m.find("sections[0]") != std::string::npos || m.find("sections[1]") != std::string::npos) << m;
  LoftOptions o;
  o.spec_pointers = true;  // named as in a loft spec
  const std::string named = expect_code([&] { (void)loft(s, o); }, errc::closing_gap, "named by pointer");
  EXPECT_NE(named.find("/sections/2"), std::string::npos) << named;
}

// ------------------------------------------------------------------ knots

/// Own merged knot count of clamped sections of one degree p: the ends p + 1 times
/// each, every interior knot value once per section holding it (distinct sections'
/// knots here are distinct values; values within 256 ε of each other are one, as
/// snapped_together makes them).
std::size_t own_merged_count(const std::vector<BSplineCurve>& s) {
  const int p = s.front().degree();
  std::vector<double> in;
  for (const auto& c : s) {
    const auto& k = c.knots().values();
    for (std::size_t i = static_cast<std::size_t>(p + 1); i + static_cast<std::size_t>(p + 1) < k.size(); ++i) in.push_back(k[i]);
  }
  std::sort(in.begin(), in.end());
  std::size_t distinct = 0;
  for (std::size_t i = 0; i < in.size(); ++i)
    if (i == 0 || in[i] - in[i - 1] > 256 * eps) ++distinct;
  return distinct + 2 * static_cast<std::size_t>(p + 1);
}

// Eight open sections, cubic interpolants through 5 to 200 points each: merged, their
// knots would number about the sum of theirs. The surface keeps to at most 4 times
// the largest section's knot count along u, re-expressing the sections when merging
// would exceed that, each within the tolerance; a tolerance no re-expression on fewer
// knots can meet leaves them merged.
TEST(Loft, ManyKnotsAreReexpressedWithinTheTolerance) {
  auto g = test::rng(904);
  const auto sections_of = [&](std::size_t lo, std::size_t hi) {
    std::vector<BSplineCurve> s;
    for (int k = 0; k < 8; ++k) {
      const auto n = static_cast<std::size_t>(std::uniform_int_distribution<int>(static_cast<int>(lo), static_cast<int>(hi))(g));
      // gentle waves (ω below 0.8 over a length of 10): the sections' interpolants
      // differ from each other's knots' spaces by far less than the tolerance
      s.push_back(open_through(wave_points(g, n, 10, 0.9 * k, test::uniform(g, 0.5, 1), test::uniform(g, 0.3, 0.8),
                                           test::uniform(g, 0, 2 * pi))));
    }
    return s;
  };
  struct Case {
    const char* what;
    std::size_t lo, hi;
    int reexpressed;  // 1: must be, 0: must not be, -1: as the counts say
    double tolerance;  // of the diagonal; 0: the default
  };
  for (const Case& cs : {Case{"5..200 points", 5, 200, -1, 0}, Case{"150..200 points", 150, 200, 1, 0},
                         Case{"6..8 points", 6, 8, 0, 0}, Case{"150..200 points, a tolerance below rounding", 150, 200, 0, 1e-15}}) {
    const auto s = sections_of(cs.lo, cs.hi);
    const double diag = diagonal_of(s);
    std::size_t largest = 0;
    for (const auto& c : s) largest = std::max(largest, c.knots().size());
    const std::size_t merged = own_merged_count(s);
    if (cs.reexpressed == 1 || cs.tolerance > 0) {
      ASSERT_GT(merged, 4 * largest) << cs.what << ": the case no longer needs re-expressing";
    }
    if (cs.reexpressed == 0 && cs.tolerance == 0) {
      ASSERT_LE(merged, 4 * largest) << cs.what << ": the case now needs re-expressing";
    }
    LoftOptions o;
    if (cs.tolerance > 0) o.tolerance = cs.tolerance * diag;
    const LoftSurface L = loft(s, o);
    EXPECT_EQ(L.report.section_knots, largest) << cs.what;
    EXPECT_EQ(L.report.merged_knots, merged) << cs.what;
    // Re-expressed when merging makes too many, unless the tolerance needs as many
    // knots as merging makes (below rounding: merged after all).
    EXPECT_EQ(L.report.reexpressed, merged > 4 * largest && cs.tolerance == 0) << cs.what;
    if (L.report.reexpressed) {
      EXPECT_LE(L.surface.knots_u().size(), 4 * largest) << cs.what;
    } else {
      EXPECT_EQ(L.surface.knots_u().size(), merged) << cs.what;
    }
    EXPECT_NEAR(L.report.tolerance, cs.tolerance > 0 ? cs.tolerance * diag : 1e-7 * diag, 1e-20 * diag) << cs.what;
    EXPECT_LE(L.report.max_deviation, L.report.tolerance) << cs.what;
    // Every section within the tolerance (re-expressed) or to rounding, measured here
    // at 8 points of every span of the section and of the surface, and at their knots;
    // evaluation adds rounding of the data's size (1e-12 of the diagonal, as above).
    const double allowed = (L.report.reexpressed ? L.report.tolerance : 0.0) + kReproduce * diag;
    double worst_all = 0;
    for (std::size_t k = 0; k < s.size(); ++k) {
      std::vector<double> us;
      const auto add_spans = [&](const std::vector<double>& knots, double lo, double hi) {
        for (std::size_t i = 0; i + 1 < knots.size(); ++i)
          if (knots[i + 1] > knots[i])
            for (int j = 0; j <= 8; ++j) us.push_back((knots[i] + (knots[i + 1] - knots[i]) * j / 8.0 - lo) / (hi - lo));
      };
      add_spans(s[k].knots().values(), s[k].domain().first, s[k].domain().second);
      add_spans(L.surface.knots_u().values(), 0.0, 1.0);
      double worst = 0;
      for (double u : us) {
        u = std::clamp(u, 0.0, 1.0);
        worst = std::max(worst, distance(L.surface.point(u, L.report.params[k]), s[k].point(own_parameter(s[k], L.report.sections[k], u))));
      }
      EXPECT_LE(worst, allowed) << cs.what << ", section " << k;
      EXPECT_LE(L.report.sections[k].deviation, L.report.max_deviation) << cs.what << ", section " << k;
      worst_all = std::max(worst_all, worst);
    }
    // Without re-expression the sections are used as they are: the deviation the loft
    // measured is rounding.
    if (!L.report.reexpressed) {
      EXPECT_LE(L.report.max_deviation, kReproduce * diag) << cs.what;
      EXPECT_LE(worst_all, kReproduce * diag) << cs.what;
    }
    double largest_reported = 0;
    for (const auto& r : L.report.sections) largest_reported = std::max(largest_reported, r.deviation);
    EXPECT_EQ(L.report.max_deviation, largest_reported) << cs.what;
  }
}

// ------------------------------------------------------------------ periodic loft

// Eight circles round the z axis, each in its plane through the axis: closed in v
// (a torus), C2 across the seam v = 0 / 1 as anywhere, each ring reproduced.
TEST(Loft, PeriodicLoftOfRingsIsASmoothTorus) {
  std::vector<BSplineCurve> s;
  for (int k = 0; k < 8; ++k) {
    const double phi = 2 * pi * k / 8, R = 3, r = 1 + 0.15 * std::sin(2 * phi);
    const Vec3 radial{std::cos(phi), std::sin(phi), 0}, up{0, 0, 1};
    std::vector<Vec3> p;
    for (int i = 0; i < 12; ++i) {
      const double a = 2 * pi * i / 12;
      p.push_back(R * radial + r * (std::cos(a) * radial + std::sin(a) * up));
    }
    s.push_back(closed_through(p));
  }
  LoftOptions o;
  o.periodic = true;
  const LoftSurface L = loft(s, o);
  const double diag = diagonal_of(s);
  ASSERT_TRUE(L.surface.periodic()[1]);
  EXPECT_TRUE(L.surface.periodic()[0]);
  EXPECT_TRUE(L.report.closed);
  EXPECT_EQ(L.surface.degree_v(), 3);
  for (int m : interior_multiplicities(L.surface.knots_v())) EXPECT_EQ(m, 1);
  EXPECT_GE(L.surface.knots_v().continuity(), 2);
  // v_k from 0 to below 1; the header's report adds the first section again at 1.
  ASSERT_GE(L.report.params.size(), s.size());
  EXPECT_EQ(L.report.params.front(), 0.0);
  for (std::size_t k = 1; k < s.size(); ++k) EXPECT_LT(L.report.params[k - 1], L.report.params[k]);
  EXPECT_LT(L.report.params[s.size() - 1], 1.0);
  if (L.report.params.size() > s.size()) {
    EXPECT_EQ(L.report.params[s.size()], 1.0);
  }
  // The rings' centres are evenly spaced round the axis and their radii differ by
  // at most 15 %: chords within a few per cent of each other, parameters within 0.02
  // of k / 8.
  for (std::size_t k = 0; k < s.size(); ++k) EXPECT_NEAR(L.report.params[k], static_cast<double>(k) / 8, 0.02);
  expect_sections_reproduced(L, s, kReproduce * diag);
  // v = 0 evaluates the first span, v = 1 the last: the two sides of the seam. At a
  // simple knot of a cubic they agree in value and two derivatives, to rounding of
  // each derivative's evaluation (differences of control points over spans of about
  // 1/8, a few hundred units of the derivative's size).
  for (double u : linspace(0, 1, 13))
    for (int d = 0; d <= 2; ++d) {
      const Vec3 a = L.surface.derivative(u, 0.0, 0, d), b = L.surface.derivative(u, 1.0, 0, d);
      EXPECT_LE(distance(a, b), 1e-11 * std::max({norm(a), norm(b), diag})) << "order " << d << " at u = " << u;
    }
  // The third derivative does jump there: v = 0 and v = 1 are evaluated on different
  // spans, so the check above compares the two sides of the seam.
  double jump = 0;
  for (double u : linspace(0, 1, 13))
    jump = std::max(jump, distance(L.surface.derivative(u, 0.0, 0, 3), L.surface.derivative(u, 1.0, 0, 3)));
  EXPECT_GT(jump, 0.0);
}

// ------------------------------------------------------------------ rational sections

// NURBS circles (closed sections with open knots) about the z axis, of different radii
// and heights, share their weights: interpolated across in homogeneous form, the
// surface between them is r(v) × circle(u) + z(v) e_z, every u-isoline an exact circle.
TEST(Loft, RationalCirclesAreReproducedAndBlendIntoCircles) {
  const double radius[4] = {1, 1.5, 1.2, 0.7}, height[4] = {0, 1, 2.2, 3};
  std::vector<BSplineCurve> s;
  for (std::size_t k = 0; k < 4; ++k) s.push_back(nurbs_circle(radius[k], {0, 0, height[k]}));
  const LoftSurface L = loft(s);
  const double diag = diagonal_of(s);
  EXPECT_TRUE(L.surface.rational());
  EXPECT_TRUE(L.report.closed);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_TRUE(L.report.sections[k].closed) << k;
    EXPECT_FALSE(L.report.sections[k].reversed) << k;
  }
  expect_sections_reproduced(L, s, kReproduce * diag);
  for (double v : linspace(0, 1, 13)) {
    const Vec3 p0 = L.surface.point(0, v);
    const double r0 = std::hypot(p0.x, p0.y);
    for (double u : linspace(0, 1, 37)) {
      const Vec3 p = L.surface.point(u, v);
      EXPECT_NEAR(std::hypot(p.x, p.y), r0, kReproduce * diag) << "(" << u << ", " << v << ")";
      EXPECT_NEAR(p.z, p0.z, kReproduce * diag) << "(" << u << ", " << v << ")";
    }
  }
  // Rational and polynomial sections together: the polynomial ones with weights 1.
  std::vector<BSplineCurve> open = {BSplineCurve(KnotVector(2, {0, 0, 0, 1, 1, 1}), {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {1, std::sqrt(0.5), 1}),
                                    line({1.5, 0, 1}, {0, 1.5, 1}),
                                    BSplineCurve(KnotVector(2, {0, 0, 0, 1, 1, 1}), {{0.8, 0, 2}, {0.8, 0.8, 2}, {0, 0.8, 2}}, {1, 2.0, 1})};
  const LoftSurface M = loft(open);
  EXPECT_TRUE(M.surface.rational());
  expect_sections_reproduced(M, open, kReproduce * diagonal_of(open));
}

// ------------------------------------------------------------------ few sections

TEST(Loft, TwoSectionsMakeARuledSurface) {
  auto g = test::rng(905);
  const std::vector<BSplineCurve> s = {open_through(wave_points(g, 6, 3, 0, 0.5, 1.2, 0)),
                                       BSplineCurve(KnotVector(2, {1, 1, 1, 2, 4, 4, 4}), {{0, 1, 2}, {1, 0, 2.5}, {2, 1, 1.5}, {3, 0.5, 2}})};
  const LoftSurface L = loft(s);
  const double diag = diagonal_of(s);
  EXPECT_EQ(L.surface.degree_v(), 1);
  EXPECT_EQ(L.report.degree_v, 1);
  EXPECT_EQ(L.report.params, (std::vector<double>{0, 1}));
  // The line between the sections at equal u: two terms of the data's size.
  for (double u : linspace(0, 1, 31))
    for (double v : linspace(0, 1, 7)) {
      const Vec3 a = s[0].point(own_parameter(s[0], L.report.sections[0], u));
      const Vec3 b = s[1].point(own_parameter(s[1], L.report.sections[1], u));
      EXPECT_LE(distance(L.surface.point(u, v), (1 - v) * a + v * b), kReproduce * diag) << "(" << u << ", " << v << ")";
    }
  // Three sections: at most quadratic across.
  std::vector<BSplineCurve> three = s;
  three.push_back(open_through(wave_points(g, 5, 3, 4, 0.4, 0.9, 1)));
  const LoftSurface T = loft(three);
  EXPECT_EQ(T.surface.degree_v(), 2);
  expect_sections_reproduced(T, three, kReproduce * diagonal_of(three));
  // Degree 1 asked: straight between consecutive sections.
  LoftOptions linear;
  linear.degree = 1;
  const LoftSurface P = loft(three, linear);
  EXPECT_EQ(P.surface.degree_v(), 1);
  for (double u : linspace(0, 1, 11))
    for (std::size_t k = 0; k + 1 < three.size(); ++k) {
      const double v0 = P.report.params[k], v1 = P.report.params[k + 1], v = 0.3 * v0 + 0.7 * v1;
      EXPECT_LE(distance(P.surface.point(u, v), 0.3 * P.surface.point(u, v0) + 0.7 * P.surface.point(u, v1)), kReproduce * diag);
    }
}

// ------------------------------------------------------------------ tangents

// The Hermite functions on [0, 1].
double a0(double t) { return 1 - 3 * t * t + 2 * t * t * t; }
double a1(double t) { return 3 * t * t - 2 * t * t * t; }
double b0(double t) { return t - 2 * t * t + t * t * t; }
double b1(double t) { return -t * t + t * t * t; }

/// A tangent curve evaluated at the same fraction of its own domain as its section
/// at surface parameter u ("taken at the same u as its section").
Vec3 tangent_at(const BSplineCurve& T, const BSplineCurve& c, const LoftSectionReport& r, double u) {
  const auto [lo, hi] = c.domain();
  const double f = (own_parameter(c, r, u) - lo) / (hi - lo);
  const auto [tlo, thi] = T.domain();
  return T.point(std::clamp(tlo + f * (thi - tlo), tlo, thi));
}

// ∂S/∂v comes from control points solved with rows of basis derivatives (entries of
// about q / Δv): the rounding of the solve, of the size of the data and of the
// tangents, grows by that factor. 1e-11 of (diagonal / smallest Δv + largest
// tangent) leaves a factor of 100 over it.
double derivative_tol(const LoftSurface& L, double diag, double tangent_size) {
  double dv = 1;
  for (std::size_t k = 1; k < L.report.params.size(); ++k) dv = std::min(dv, L.report.params[k] - L.report.params[k - 1]);
  return 1e-11 * (diag / dv + tangent_size);
}

double largest_control_point(const BSplineCurve& c) {
  double m = 0;
  for (const Vec3& q : c.control_points()) m = std::max(m, norm(q));
  return m;
}

TEST(Loft, TangentsAtTheEndSections) {
  auto g = test::rng(906);
  // Two sections and two tangents: four conditions, cubic across, and the cubic
  // through them is the Hermite one, S = α0 C0 + α1 C1 + β0 T0 + β1 T1.
  const std::vector<BSplineCurve> s = {open_through(wave_points(g, 7, 3, 0, 0.4, 1.0, 0)),
                                       BSplineCurve(KnotVector(3, {2, 2, 2, 2, 3, 5, 5, 5, 5}),
                                                    {{0, 0.3, 2}, {0.8, -0.5, 2.3}, {1.6, 0.6, 1.8}, {2.3, 0, 2.1}, {3, 0.2, 2}})};
  const std::vector<BSplineCurve> T = {BSplineCurve(KnotVector(2, {-2, -2, -2, 0, 3, 3, 3}), {{0.5, 0, 2}, {0, 1, 3}, {-0.5, 0, 2.5}, {0, -1, 2}}),
                                       line({1, 0.5, 1.5}, {-1, 0.5, 2.5})};
  LoftOptions o;
  o.tangents = {T[0], T[1]};
  const LoftSurface L = loft(s, o);
  const double diag = diagonal_of(s), tsize = std::max(largest_control_point(T[0]), largest_control_point(T[1]));
  EXPECT_EQ(L.surface.degree_v(), 3);
  EXPECT_EQ(L.report.params, (std::vector<double>{0, 1}));
  // Four terms with Hermite functions below 1 of sections and tangents: rounding of
  // their size.
  for (double u : linspace(0, 1, 21))
    for (double v : linspace(0, 1, 9)) {
      const Vec3 want = a0(v) * s[0].point(own_parameter(s[0], L.report.sections[0], u)) +
                        a1(v) * s[1].point(own_parameter(s[1], L.report.sections[1], u)) +
                        b0(v) * tangent_at(T[0], s[0], L.report.sections[0], u) + b1(v) * tangent_at(T[1], s[1], L.report.sections[1], u);
      EXPECT_LE(distance(L.surface.point(u, v), want), 1e-12 * (diag + tsize)) << "(" << u << ", " << v << ")";
    }

  // Five sections, the last given backwards with its tangent parametrized as it is
  // given: the tangent turns round with its section.
  std::vector<BSplineCurve> five;
  for (int k = 0; k < 5; ++k) five.push_back(open_through(wave_points(g, 5 + static_cast<std::size_t>(k), 3, 0.8 * k, 0.3, 1.0 + 0.2 * k, 0.5 * k)));
  const BSplineCurve T0 = line({0.2, 0.1, 1}, {-0.1, 0.3, 0.8});
  const BSplineCurve T4 = BSplineCurve(KnotVector(2, {0, 0, 0, 0.5, 1, 1, 1}), {{0, 0, 1}, {0.3, -0.4, 1.5}, {-0.2, 0.2, 0.9}, {0.1, 0, 1.2}});
  LoftOptions forward;
  forward.tangents = {T0, T4};
  const LoftSurface F = loft(five, forward);
  auto given = five;
  given[4] = reversed_curve(five[4]);
  LoftOptions backward;
  backward.tangents = {T0, reversed_curve(T4)};
  const LoftSurface B = loft(given, backward);
  EXPECT_EQ(F.surface.degree_v(), 3);
  EXPECT_TRUE(B.report.sections[4].reversed);
  const double d5 = diagonal_of(five), t5 = std::max(largest_control_point(T0), largest_control_point(T4));
  expect_sections_reproduced(F, five, kReproduce * d5, "forward");
  expect_sections_reproduced(B, given, kReproduce * d5, "backward");
  for (const auto* X : {&F, &B}) {
    const auto& sec = X == &F ? five : given;
    const auto& tan = X == &F ? forward.tangents : backward.tangents;
    const double tol = derivative_tol(*X, d5, t5);
    for (double u : linspace(0, 1, 41)) {
      EXPECT_LE(distance(X->surface.derivative(u, 0.0, 0, 1), tangent_at(*tan[0], sec[0], X->report.sections[0], u)), tol)
          << (X == &F ? "forward" : "backward") << " at v = 0, u = " << u;
      EXPECT_LE(distance(X->surface.derivative(u, 1.0, 0, 1), tangent_at(*tan[1], sec[4], X->report.sections[4], u)), tol)
          << (X == &F ? "forward" : "backward") << " at v = 1, u = " << u;
    }
    // What the loft measured of its own tangents, within the same bound; none elsewhere.
    EXPECT_LE(X->report.sections[0].tangent_deviation, tol);
    EXPECT_LE(X->report.sections[4].tangent_deviation, tol);
    for (std::size_t k = 1; k < 4; ++k) EXPECT_EQ(X->report.sections[k].tangent_deviation, 0.0) << k;
  }
  EXPECT_LE(surface_distance(F.surface, B.surface), kReproduce * (d5 + t5));
}

// Tangents at every section but one (left free), along closed sections given with
// other starts and directions: each tangent curve, made as its section's control
// points moved (α (P − centre) + β e_z, so that T(t) = α (C(t) − centre) + β e_z at
// every t), is taken at its section's parameter, turned and shifted with it.
TEST(Loft, TangentsAtEverySectionTurnAndShiftWithThem) {
  const double radius[4] = {1, 1.3, 0.9, 1.1};
  const Vec3 centre[4] = {{0, 0, 0}, {0.1, 0, 1}, {0, -0.2, 2.2}, {0.2, 0.1, 3}};
  const int starts[4] = {0, 4, 9, 2};
  const bool back[4] = {false, true, false, true};
  const double alpha[4] = {0.5, -0.3, 0, 0.2}, beta[4] = {1, 1.2, 0, 0.8};
  auto radial = [&](const BSplineCurve& c, std::size_t k) {
    std::vector<Vec3> cp;
    for (const Vec3& q : c.control_points()) cp.push_back(alpha[k] * (q - centre[k]) + Vec3{0, 0, beta[k]});
    return BSplineCurve(c.knots(), cp);
  };
  std::vector<BSplineCurve> aligned, given;
  LoftOptions oa, og;
  for (std::size_t k = 0; k < 4; ++k) {
    aligned.push_back(closed_through(circle_points(12, radius[k], centre[k])));
    given.push_back(closed_through(circle_points(12, radius[k], centre[k], starts[k], back[k])));
    oa.tangents.push_back(k == 2 ? std::nullopt : std::optional<BSplineCurve>(radial(aligned.back(), k)));
    og.tangents.push_back(k == 2 ? std::nullopt : std::optional<BSplineCurve>(radial(given.back(), k)));
  }
  const LoftSurface A = loft(aligned, oa), G = loft(given, og);
  double tsize = 0;
  for (const auto& t : og.tangents)
    if (t) tsize = std::max(tsize, largest_control_point(*t));
  const double diag = diagonal_of(aligned);
  EXPECT_EQ(G.surface.degree_v(), 3);
  expect_sections_reproduced(G, given, kReproduce * diag);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(G.report.sections[k].reversed, back[k]) << k;
    if (k == 2) continue;
    for (double u : linspace(0, 1, 49))
      EXPECT_LE(distance(G.surface.derivative(u, G.report.params[k], 0, 1), tangent_at(*og.tangents[k], given[k], G.report.sections[k], u)),
                derivative_tol(G, diag, tsize))
          << "section " << k << ", u = " << u;
    EXPECT_LE(G.report.sections[k].tangent_deviation, derivative_tol(G, diag, tsize)) << k;
  }
  EXPECT_LE(surface_distance(A.surface, G.surface), kReproduce * (diag + tsize));
}

// ------------------------------------------------------------------ invariance

BSplineCurve transformed(const BSplineCurve& c, double s, const Vec3& b) {
  std::vector<Vec3> cp;
  for (const Vec3& q : c.control_points()) cp.push_back(s * q + b);
  return BSplineCurve(c.knots(), cp, c.weights());
}

std::vector<std::vector<BSplineCurve>> invariance_cases() {
  std::vector<BSplineCurve> circles;
  const int starts[4] = {0, 3, 8, 5};
  const bool back[4] = {false, true, true, false};
  for (int k = 0; k < 4; ++k)
    circles.push_back(closed_through(circle_points(12, 1 + 0.2 * k, {0.1 * k, -0.05 * k, 1.0 * k}, starts[k], back[k])));
  auto open = mixed_open_sections();
  open[3] = reversed_curve(open[3]);
  return {open, circles};
}

// Multiplying every section by 2^k multiplies every control point by 2^k, bit for
// bit, and leaves the knots, weights, parameters and choices as they are: every
// rounding in between commutes with it (odd k too: no square root of a length
// goes unpaired; 2^±500 far from both ends of the range).
TEST(Loft, ScalingByAPowerOfTwoIsExact) {
  for (const auto& s : invariance_cases())
    for (Parametrization param : {Parametrization::chord, Parametrization::centripetal})
      for (int k : {4, -10, 7, 500, -500}) {
        std::vector<BSplineCurve> t;
        for (const auto& c : s) t.push_back(transformed(c, std::ldexp(1.0, k), {}));
        LoftOptions o;
        o.param = param;
        const LoftSurface A = loft(s, o), B = loft(t, o);
        const std::string what = "2^" + std::to_string(k) + (param == Parametrization::chord ? ", chord" : ", centripetal");
        EXPECT_EQ(A.surface.knots_u(), B.surface.knots_u()) << what;
        EXPECT_EQ(A.surface.knots_v(), B.surface.knots_v()) << what;
        EXPECT_EQ(A.report.params, B.report.params) << what;
        EXPECT_EQ(std::ldexp(A.report.tolerance, k), B.report.tolerance) << what;
        for (std::size_t i = 0; i < s.size(); ++i) {
          EXPECT_EQ(A.report.sections[i].reversed, B.report.sections[i].reversed) << what;
          EXPECT_EQ(A.report.sections[i].map(0.0), B.report.sections[i].map(0.0)) << what;
        }
        ASSERT_EQ(A.surface.control_points().size(), B.surface.control_points().size()) << what;
        const Vec3* a = A.surface.control_points().data();
        const Vec3* b = B.surface.control_points().data();
        std::size_t differ = 0;
        for (std::size_t i = 0; i < A.surface.control_points().size(); ++i)
          if (!(ldexp(a[i], k) == b[i])) ++differ;
        EXPECT_EQ(differ, 0u) << what;
        const auto& wa = A.surface.weights();
        const auto& wb = B.surface.weights();
        ASSERT_EQ(wa.size(), wb.size()) << what;
        for (std::size_t i = 0; i < wa.size(); ++i) EXPECT_EQ(wa.data()[i], wb.data()[i]) << what;
      }
}

// Any scale and a translation: S'(u, v) = a S(u, v) + b to rounding, relative to the
// transformed data's diagonal, plus rounding of coordinates of the offset's size
// (the translated data's own rounding, amplified as S(u, v_k) is).
TEST(Loft, TranslatedAndScaledSectionsTransformTheSurface) {
  const Vec3 b{40.25, -25.5, 13};
  for (const auto& s : invariance_cases())
    for (double a : {2.7, 0.013, 170.0}) {
      std::vector<BSplineCurve> t;
      for (const auto& c : s) t.push_back(transformed(c, a, b));
      const LoftSurface A = loft(s), B = loft(t);
      const double tol = kReproduce * diagonal_of(t) + 1e3 * eps * (max_abs(b) + a * diagonal_of(s));
      for (std::size_t i = 0; i < s.size(); ++i) EXPECT_EQ(A.report.sections[i].reversed, B.report.sections[i].reversed) << a;
      // Parameters from distances of the translated data: rounding of the offset's size
      // relative to distances of a few hundredths at the smallest scale, 1e-12 at most.
      for (std::size_t k = 0; k < s.size(); ++k) EXPECT_NEAR(A.report.params[k], B.report.params[k], 1e-10) << a;
      for (double u : linspace(0, 1, 31))
        for (double v : linspace(0, 1, 11))
          EXPECT_LE(distance(B.surface.point(u, v), a * A.surface.point(u, v) + b), tol) << a << " at (" << u << ", " << v << ")";
    }
}

// ------------------------------------------------------------------ errors

TEST(Loft, ErrorsCarryTheirCodes) {
  auto g = test::rng(907);
  std::vector<BSplineCurve> s;
  for (int k = 0; k < 4; ++k) s.push_back(open_through(wave_points(g, 6, 3, 1.0 * k, 0.3, 1, 0.2 * k)));
  const auto fails = [&](const std::vector<BSplineCurve>& sections, const LoftOptions& o, errc code, const std::string& what) {
    return expect_code([&] { (void)loft(sections, o); }, code, what);
  };
  fails({}, {}, errc::too_few_points, "no sections");
  fails({s[0]}, {}, errc::too_few_points, "one section");
  for (int d : {0, -1}) {
    LoftOptions o;
    o.degree = d;
    fails(s, o, errc::invalid_degree, "degree " + std::to_string(d));
  }
  {
    const std::string m = fails({s[0], s[1], s[1], s[2]}, {}, errc::zero_chord, "a section repeated");
    EXPECT_NE(m.find("sections["), std::string::npos) << m;
  }
  {
    LoftOptions o;
    o.params = {0, 0.6, 0.4, 1};
    fails(s, o, errc::non_increasing, "params decreasing");
    o.params = {0, 0.5, 0.5, 1};
    fails(s, o, errc::non_increasing, "params repeated");
    o.params = {0, 0.5, 1};
    fails(s, o, errc::size_mismatch, "3 params for 4 sections");
    o.params = {0, 0.2, 0.5, 0.7, 1};
    fails(s, o, errc::size_mismatch, "5 params for 4 sections");
    o.params = {-0.25, 0.2, 0.5, 1};
    fails(s, o, errc::out_of_domain, "a param below 0");
    o.params = {0, 0.2, 0.5, 1.25};
    fails(s, o, errc::out_of_domain, "a param above 1");
    o.params = {0, std::numeric_limits<double>::quiet_NaN(), 0.5, 1};
    fails(s, o, errc::not_finite, "a NaN param");
    o.periodic = true;
    o.params = {0, 0.3, 0.6, 1};
    fails(s, o, errc::out_of_domain, "a periodic loft's param at 1 (the first section again)");
  }
  {
    LoftOptions o;
    o.tangents = {line({0, 0, 0}, {0, 0, 1})};
    fails(s, o, errc::size_mismatch, "one tangent");
    o.tangents = {line({0, 0, 0}, {0, 0, 1}), std::nullopt, line({0, 0, 0}, {0, 0, 1})};
    fails(s, o, errc::size_mismatch, "three tangents for four sections");
    o.tangents = {line({0, 0, 1}, {0, 0, 1}), line({0, 0, 1}, {0, 0, 1})};
    o.periodic = true;
    fails(s, o, errc::wrong_type, "tangents on a periodic loft");
  }
  {
    std::vector<BSplineCurve> r;
    for (int k = 0; k < 3; ++k) r.push_back(nurbs_circle(1 + 0.1 * k, {0, 0, 1.0 * k}));
    LoftOptions o;
    o.tangents = {line({0, 0, 1}, {0, 0, 1}), line({0, 0, 1}, {0, 0, 1})};
    fails(r, o, errc::wrong_type, "tangents of rational sections");
  }
  {
    // Weights interpolated across fall below 0: control point 1 weighs 1000 at the
    // ends and 1 in between (a cubic across dips to (−1000 + 9 + 9 − 1000) / 16 at
    // v = 1/2), control point 3 the other way round, so that no common factor per
    // section (the same weights in every section, permuted) makes both positive.
    std::vector<BSplineCurve> r;
    const double w1[4] = {1000, 1, 1, 1000};
    for (std::size_t k = 0; k < 4; ++k) {
      const double z = static_cast<double>(k);
      r.push_back(BSplineCurve(KnotVector(2, {0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1}),
                               {{0, 0, z}, {1, 1, z}, {2, 0, z}, {3, 1, z}, {4, 0, z}}, {1, w1[k], 1, 1001 - w1[k], 1}));
    }
    LoftOptions o;
    o.params = {0, 1.0 / 3, 2.0 / 3, 1};
    fails(r, o, errc::invalid_weight, "weights falling to 0 across");
  }
}

// ------------------------------------------------------------------ the spec

// info's report of a loft. The brief names "sections" (an object keyed by pointer),
// "merged_knots", "section_knots" and "reexpressed"; the reader as first written
// names "loft_sections" and "knots": {"merged", "largest_section", "reexpressed"}.
// Either is read here until one is settled.
const nlohmann::ordered_json& section_info(const nlohmann::ordered_json& P, const std::string& ptr) {
  return P.at("loft_sections").at(ptr);
}

const nlohmann::ordered_json& knots_info(const nlohmann::ordered_json& P, const char* key) {
  return P.at("knots").at(key);
}

json points_json(const std::vector<Vec3>& p) {
  json a = json::array();
  for (const Vec3& q : p) a.push_back({q.x, q.y, q.z});
  return a;
}

// The spec form: the sections and tangents in any curve form, read as curve specs
// are; the exact form is the library's loft of those curves, and info's parameters
// and data report it.
TEST(LoftSpec, BuildsTheLoftOfItsCurvesAndReportsIt) {
  auto g = test::rng(908);
  const json sections = json::array(
      {{{"interpolate", points_json(wave_points(g, 7, 3, 0, 0.4, 1, 0))}, {"param", "centripetal"}},
       {{"bspline", {{"degree", 2}, {"knots", {2, 2, 2, 3, 5, 5, 5}}, {"control_points", {{0, 0, 1}, {1, 0.5, 1.2}, {2, -0.3, 0.9}, {3, 0, 1}}}}}},
       {{"line", {{3.1, 0.2, 2}, {-0.1, 0, 2.2}}}},  // backwards
       {{"hermite", {{"points", {{0, 0, 3}, {1.5, 0.4, 3.1}, {3, 0, 3}}}}}}});
  const json tangents = json::array({{{"line", {{0, 0, 1}, {0.2, 0, 1}}}}, nullptr, nullptr,
                                     {{"interpolate", {{0, 0.1, 1}, {0, 0, 1.3}, {0.1, 0, 1}}}, {"degree", 2}}});
  const json spec = {{"type", "loft"}, {"sections", sections}, {"degree", 3}, {"param", "chord"}, {"tangents", tangents}};
  io::Construction c = io::build(spec);
  ASSERT_TRUE(c.exact.has_value());
  const auto& S = std::get<BSplineSurface>(*c.exact);

  std::vector<BSplineCurve> s;
  for (const json& j : sections) s.push_back(io::build_curve(j).curve);
  LoftOptions o;
  o.tangents = {io::build_curve(tangents[0]).curve, std::nullopt, std::nullopt, io::build_curve(tangents[3]).curve};
  const LoftSurface L = loft(s, o);
  const double diag = diagonal_of(s);
  // The same curves and options: the same surface (the reader may map domains onto
  // [0, 1] first, rounding the knots).
  EXPECT_LE(surface_distance(S, L.surface), kReproduce * diag);

  const auto& P = c.parameters;
  ASSERT_EQ(P.at("degree").size(), 2u);
  EXPECT_EQ(P.at("degree")[0].get<int>(), L.report.degree_u);
  EXPECT_EQ(P.at("degree")[1].get<int>(), L.report.degree_v);
  ASSERT_EQ(P.at("params").size(), s.size());
  for (std::size_t k = 0; k < s.size(); ++k) EXPECT_NEAR(P.at("params")[k].get<double>(), L.report.params[k], 1e-15);
  EXPECT_EQ(P.at("closed").get<bool>(), false);
  EXPECT_EQ(knots_info(P, "reexpressed").get<bool>(), L.report.reexpressed);
  EXPECT_EQ(knots_info(P, "merged").get<std::size_t>(), L.report.merged_knots);
  EXPECT_EQ(knots_info(P, "largest_section").get<std::size_t>(), L.report.section_knots);
  EXPECT_NEAR(P.at("tolerance").get<double>(), L.report.tolerance, 1e-6 * L.report.tolerance);
  EXPECT_LE(P.at("max_deviation").get<double>(), P.at("tolerance").get<double>());
  for (std::size_t k = 0; k < s.size(); ++k) {
    const std::string key = "/sections/" + std::to_string(k);
    const auto& r = section_info(P, key);
    EXPECT_FALSE(r.at("closed").get<bool>()) << key;
    EXPECT_EQ(r.at("reversed").get<bool>(), k == 2) << key;  // the line given backwards
    EXPECT_NEAR(r.at("deviation").get<double>(), L.report.sections[k].deviation, 1e-12 * diag) << key;
  }
  // One data set per section: the section as given, sampled, on its line v = v_k.
  ASSERT_EQ(c.data.size(), s.size());
  for (std::size_t k = 0; k < s.size(); ++k) {
    const io::DataSet& d = c.data[k];
    ASSERT_EQ(d.params.size(), 2u);
    ASSERT_EQ(d.params[1].size(), 1u);
    EXPECT_NEAR(d.params[1][0], L.report.params[k], 1e-15);
    ASSERT_EQ(d.points.size(), d.params[0].size());
    for (std::size_t i = 0; i < d.points.size(); ++i) {
      const double u = d.params[0][i];
      EXPECT_LE(distance(d.points[i], s[k].point(own_parameter(s[k], L.report.sections[k], u))), kReproduce * diag) << k << ", " << i;
      EXPECT_LE(distance(S.point(u, d.params[1][0]), d.points[i]), kReproduce * diag) << k << ", " << i;
    }
  }
}

TEST(LoftSpec, ClosedSectionsReportTheirSeam) {
  json sections = json::array();
  std::vector<BSplineCurve> s;
  for (int k = 0; k < 3; ++k) {
    const auto p = circle_points(10, 1 + 0.3 * k, {0, 0, 1.0 * k}, 3 * k, k == 1);
    sections.push_back({{"interpolate", points_json(p)}, {"periodic", true}});
    s.push_back(closed_through(p));
  }
  io::Construction c = io::build(json{{"type", "loft"}, {"sections", sections}});
  const LoftSurface L = loft(s);
  EXPECT_TRUE(c.parameters.at("closed").get<bool>());
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& r = section_info(c.parameters, "/sections/" + std::to_string(k));
    EXPECT_TRUE(r.at("closed").get<bool>());
    EXPECT_EQ(r.at("reversed").get<bool>(), k == 1);
    // where u = 0 falls on the section, in its own parameter: the aligned start
    const Vec3 start{1 + 0.3 * static_cast<double>(k), 0, static_cast<double>(k)};
    EXPECT_LE(distance(s[k].point(r.at("seam").get<double>()), start), kReproduce * diagonal_of(s)) << k;
    EXPECT_NEAR(r.at("seam").get<double>(), L.report.sections[k].map(0.0), 1e-14) << k;
  }
}

TEST(LoftSpec, ANanInASectionIsNotFinite) {
  json spec = {{"type", "loft"},
               {"sections", json::array({{{"interpolate", {{0, 0, 0}, {1, 0.2, 0}, {2, 0, 0}}}},
                                         {{"interpolate", {{0, 0, 1}, {1, 0.2, 1}, {2, 0, 1}}}}})}};
  spec["sections"][1]["interpolate"][1][0] = std::numeric_limits<double>::quiet_NaN();
  const std::string m = expect_code([&] { (void)io::build(spec); }, errc::not_finite, "a NaN coordinate");
  EXPECT_NE(m.find("/sections/1/interpolate/1/0"), std::string::npos) << m;
}

// ------------------------------------------------------------------ guides

TEST(Loft, GuidesMakeTheGordonSurfaceOfTheNetwork) {
  // Sections across x, guides along y; the last section and one guide given backwards.
  std::vector<BSplineCurve> sections, guides;
  for (int k = 0; k < 3; ++k) {
    std::vector<Vec3> p;
    for (int i = 0; i <= 4; ++i) p.push_back({0.5 * i, 1.0 * k, 0.2 * std::sin(1.3 * i + k)});
    if (k == 2) std::reverse(p.begin(), p.end());
    sections.push_back(open_through(p));
  }
  for (int i : {0, 4}) {
    std::vector<Vec3> p;
    for (int k = 0; k < 3; ++k) p.push_back({0.5 * i, 1.0 * k, 0.2 * std::sin(1.3 * i + k)});
    if (i == 4) std::reverse(p.begin(), p.end());
    guides.push_back(open_through(p));
  }
  LoftOptions o;
  o.guides = guides;
  const LoftSurface L = loft(sections, o);
  // The same network built on its own: the loft is its exact form.
  const BSplineSurface g = curve_network({sections, guides, {}, {}}).to_bspline();
  // The same construction both ways: 1e-12 of the data's size (about 3), for rounding.
  for (double u : linspace(0, 1, 9))
    for (double v : linspace(0, 1, 9)) EXPECT_LE(distance(L.surface.point(u, v), g.point(u, v)), 1e-12 * 3);
  ASSERT_TRUE(L.report.network.has_value());
  EXPECT_TRUE(L.report.sections[2].reversed);
  EXPECT_TRUE(L.report.guides[1].reversed);
  // Every section on the surface through its map: 1e-9, the network's re-expression
  // of curves crossing at other parameters stays within half of 1e-7 of the diagonal
  // and these cross at common ones (used as given, to rounding).
  for (std::size_t k = 0; k < sections.size(); ++k)
    for (double u : linspace(0, 1, 33))
      EXPECT_LE(distance(L.surface.point(u, L.report.params[k]), sections[k].point(L.report.sections[k].map(u))), 1e-9);
  // Tangents are refused with guides: the guides give the slopes.
  o.tangents = {line({0, 1, 0}, {1, 1, 0}), line({0, 1, 0}, {1, 1, 0})};
  expect_code([&] { (void)loft(sections, o); }, errc::wrong_type, "tangents with guides");
}

// ------------------------------------------------------------------ volumes

// A surface through a grid of n x m points over [0, 1]² at height z, bumped by `a`.
BSplineSurface layer(std::size_t n, std::size_t m, double z, double a) {
  PointGrid g({n, m});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      const double x = double(i) / double(n - 1), y = double(j) / double(m - 1);
      g(i, j) = {x, y, z + a * std::sin(3 * x) * std::cos(2 * y)};
    }
  return interpolate_surface(g).surface;
}

TEST(LoftVolume, ReproducesEverySectionAndIsSmoothAcross) {
  // Layers of different sizes (unrelated knots), one rational (a bilinear patch with
  // weights is the same patch): merged in u and v, interpolated across.
  std::vector<BSplineSurface> s{layer(4, 5, 0, 0.1), layer(7, 4, 1, 0.3), layer(5, 6, 2.2, -0.2), layer(6, 6, 3, 0.1)};
  const LoftVolume V = loft_volume(s);
  EXPECT_EQ(V.report.degree[2], 3);
  ASSERT_EQ(V.report.params.size(), s.size());
  // Each section at w_k over its own domain (all [0, 1]² here), at points that are
  // not the check's own (a 23 x 19 grid): 1e-12 of the diagonal (about 3.3) for the
  // rounding of the solve across.
  for (std::size_t k = 0; k < s.size(); ++k)
    for (double u : linspace(0, 1, 23))
      for (double v : linspace(0, 1, 19))
        EXPECT_LE(distance(V.volume.point(u, v, V.report.params[k]), s[k].point(u, v)), 1e-12 * 3.3) << k;
  // C2 across: simple interior knots in w.
  for (const auto& [x, mult] : V.volume.knots_w().interior_breaks()) EXPECT_EQ(mult, 1) << x;
  // Uniform places are k / 3; two sections make a volume straight across.
  LoftVolumeOptions o;
  o.param = Parametrization::uniform;
  EXPECT_EQ(loft_volume(s, o).report.params, (std::vector<double>{0, 1.0 / 3, 2.0 / 3, 1}));
  const LoftVolume two = loft_volume(std::vector<BSplineSurface>{s[0], s[3]});
  EXPECT_EQ(two.report.degree[2], 1);
  for (double u : linspace(0, 1, 5))
    for (double v : linspace(0, 1, 5))
      EXPECT_LE(distance(two.volume.point(u, v, 0.25), 0.75 * s[0].point(u, v) + 0.25 * s[3].point(u, v)), 1e-12 * 4);
}

TEST(LoftVolume, PeriodicAcrossAndErrors) {
  // Four sheets around the z axis, periodic across: closed in w, each sheet reproduced.
  std::vector<BSplineSurface> s;
  for (int k = 0; k < 4; ++k) {
    const double a = k * pi / 2;
    PointGrid g({3, 3});
    for (std::size_t i = 0; i < 3; ++i)
      for (std::size_t j = 0; j < 3; ++j) {
        const double r = 1 + 0.5 * double(i), z = double(j);
        g(i, j) = {r * std::cos(a), r * std::sin(a), z};
      }
    s.push_back(interpolate_surface(g).surface);
  }
  LoftVolumeOptions o;
  o.periodic = true;
  const LoftVolume V = loft_volume(s, o);
  EXPECT_TRUE(V.volume.periodic()[2]);
  EXPECT_EQ(V.report.params.back(), 1.0);
  for (std::size_t k = 0; k < s.size(); ++k)
    for (double u : linspace(0, 1, 7))
      for (double v : linspace(0, 1, 7))
        EXPECT_LE(distance(V.volume.point(u, v, V.report.params[k]), s[k].point(u, v)), 1e-12 * 6);
  expect_code([&] { (void)loft_volume(std::vector<BSplineSurface>{s[0]}); }, errc::too_few_points, "one section");
  expect_code([&] { (void)loft_volume(std::vector<BSplineSurface>{s[0], s[0]}); }, errc::zero_chord, "one place");
  LoftVolumeOptions bad;
  bad.params = {0, 0.5};
  expect_code([&] { (void)loft_volume(s, bad); }, errc::size_mismatch, "two places for four sections");
  // A section closed in v among open ones.
  PointGrid ring({3, 9});
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 9; ++j)
      ring(i, j) = {std::cos(2 * pi * double(j) / 8), std::sin(2 * pi * double(j) / 8), double(i)};
  SurfaceInterpolationOptions closed;
  closed.periodic = {false, true};
  const BSplineSurface tube = interpolate_surface(ring, closed).surface;
  expect_code([&] { (void)loft_volume(std::vector<BSplineSurface>{s[0], tube}); }, errc::closing_gap, "closed in v");
}

}  // namespace
}  // namespace interpatch
