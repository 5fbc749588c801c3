#include "interpatch/network.hpp"

#include <cmath>
#include <numbers>
#include <regex>

#include "interpatch/interpolate.hpp"
#include "interpatch/io/spec.hpp"
#include "surface_util.hpp"

namespace interpatch {
namespace {


void expect_interpolates(const Surface& c, const CurveNetwork& n, double tol) {
  for (double t : linspace(0, 1, 29)) {
    for (std::size_t i = 0; i < n.v_curves.size(); ++i)
      EXPECT_LT(distance(c.point(n.u_params[i], t), n.v_curves[i].point(t)), tol) << "v_curves[" << i << "]";
    for (std::size_t j = 0; j < n.u_curves.size(); ++j)
      EXPECT_LT(distance(c.point(t, n.v_params[j]), n.u_curves[j].point(t)), tol) << "u_curves[" << j << "]";
  }
}

const NetworkMethod kMethods[] = {NetworkMethod::coons_linear, NetworkMethod::coons_hermite, NetworkMethod::gordon};

TEST(Network, EveryMethodInterpolatesEveryCurveAndConvertsExactly) {
  auto g = test::rng(80);
  for (int trial = 0; trial < 6; ++trial) {
    const auto s = test::random_bspline_surface(g, 3, 2 + trial % 2, 7, 6);
    const auto n = test::network_on(s, {0, 0.2, 0.45, 0.7, 1}, {0, 0.3, 0.6, 1});
    for (auto m : kMethods) {
      const auto c = curve_network(n, {m, {}, {}});
      expect_interpolates(c, n, 1e-13);
      // Exact form: elevation and merging of up to ~15 knots per direction.
      EXPECT_LT(test::max_distance(c, c.to_bspline()), 1e-12 * 8);
    }
  }
}

TEST(Network, GordonReproducesBicubicsAndTwoByTwoIsCoons) {
  auto g = test::rng(81);
  const auto bez = test::random_bspline_surface(g, 3, 3, 4, 4);
  const auto n = test::network_on(bez, {0, 0.25, 0.6, 0.8, 1}, {0, 0.4, 0.7, 1});
  const auto gordon = curve_network(n);
  EXPECT_LT(test::max_distance(gordon, bez), 1e-13);  // cubic cardinal splines reproduce cubics
  EXPECT_EQ(gordon.to_bspline().knots_u().continuity(), 2);  // C2 across the nodes
  EXPECT_GT(test::max_distance(curve_network(n, {NetworkMethod::coons_linear, {}, {}}), bez), 1e-3);
}

TEST(Network, HermiteBlendingIsC1AcrossCellsLinearIsNot) {
  auto g = test::rng(82);
  const auto s = test::random_bspline_surface(g, 3, 3, 6, 6);
  const auto n = test::network_on(s, {0, 0.35, 0.65, 1}, {0, 0.5, 1});
  const double h = 1e-7;
  auto jump = [&](const Surface& c) {  // largest jump of S_u across u = 0.35 and of S_v across v = 0.5
    double e = 0;
    for (double t : linspace(0.05, 0.95, 10)) {
      e = std::max(e, distance(c.derivatives(0.35 - h, t).su, c.derivatives(0.35 + h, t).su));
      e = std::max(e, distance(c.derivatives(t, 0.5 - h).sv, c.derivatives(t, 0.5 + h).sv));
    }
    return e;
  };
  // Smooth: the jump is second derivative × 2h ~ 1e-5 at most.
  EXPECT_LT(jump(curve_network(n, {NetworkMethod::coons_hermite, {}, {}})), 1e-5);
  EXPECT_LT(jump(curve_network(n, {NetworkMethod::gordon, {}, {}})), 1e-5);
  EXPECT_GT(jump(curve_network(n, {NetworkMethod::coons_linear, {}, {}})), 1e-2);  // the kink the check must see
  const auto b = curve_network(n, {NetworkMethod::coons_hermite, {}, {}}).to_bspline();
  EXPECT_GE(b.knots_u().continuity(), 1);
}

TEST(Network, ParametersFoundFromTheCurves) {
  auto g = test::rng(83);
  const auto s = test::random_bspline_surface(g, 3, 3, 5, 5, 0.1);
  auto n = test::network_on(s, {0, 0.3, 0.55, 1}, {0, 0.45, 1});
  const auto p = network_parameters(n);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(p.u_params[i], n.u_params[i], 1e-9);  // Gauss–Newton to rounding
  for (std::size_t j = 0; j < 3; ++j) EXPECT_NEAR(p.v_params[j], n.v_params[j], 1e-9);
  n.u_params.clear();
  n.v_params.clear();
  const auto c = curve_network(n);
  EXPECT_FALSE(c.notes().empty());
  EXPECT_LT(distance(c.point(0.3, 0.7), s.point(0.3, 0.7)), 1e-8);
}

TEST(Network, InvalidInput) {
  auto g = test::rng(84);
  const auto s = test::random_bspline_surface(g, 3, 3, 5, 5);
  auto n = test::network_on(s, {0, 0.5, 1}, {0, 0.5, 1});
  auto bad = n;
  auto cp = bad.u_curves[1].control_points();
  for (auto& x : cp) x.z += 0.125;
  bad.u_curves[1] = BSplineCurve(bad.u_curves[1].knots(), cp);
  // Lifted by 0.125, u_curves[1] comes no closer than that to v_curves[0] where they
  // would cross, and a little closer where v_curves[0] climbs: the gap named is the
  // closest distance, found, with the closest points and their parameters.
  EXPECT_ERRC((void)curve_network(bad), network_gap, "u_curves[1] and v_curves[0] do not meet: they come closest at (");
  try {
    (void)curve_network(bad);
  } catch (const error& e) {
    std::smatch m;
    const std::string what = e.what();
    ASSERT_TRUE(std::regex_search(what, m, std::regex(R"(\(t = ([^ ]+) on u_curves\[1\]\) and .* \(t = ([^ ]+) on v_curves\[0\]\), ([^ ]+) apart)")))
        << what;
    const double s_at = std::stod(m[1]), t_at = std::stod(m[2]), gap = std::stod(m[3]);
    EXPECT_NEAR(gap, distance(bad.u_curves[1].point(s_at), bad.v_curves[0].point(t_at)), 1e-5);  // printed to 6 digits
    EXPECT_LE(gap, 0.125 + 1e-6);
    EXPECT_GT(gap, 0.1);
  }
  auto few = n;
  few.u_curves.pop_back();
  few.u_curves.pop_back();
  EXPECT_ERRC((void)curve_network(few), too_few_points, "at least 2 u_curves");
  auto params = n;
  params.u_params = {0, 0.6, 0.5};
  EXPECT_ERRC((void)curve_network(params), non_increasing, "u_params[2] = 0.5");
  params.u_params = {0, 1};
  EXPECT_ERRC((void)curve_network(params), size_mismatch, "3 v_curves need 3 u_params, got 2");
  params.u_params = {0.1, 0.5, 1};
  EXPECT_ERRC((void)curve_network(params), out_of_domain, "from 0 to 1");
}

// ---------------------------------------------------------------- closed networks

// A tube closed in u, of period 1: sections around a bent centre line, or (closed_v)
// around a circle, a torus, closed in v too; the radius wobbles by random amounts.
struct Tube {
  double a[5];
  bool closed_v;
  [[nodiscard]] Vec3 operator()(double u, double v) const {
    const double pi2 = 2 * std::numbers::pi, th = pi2 * u;
    const double r = 1 + 0.2 * a[2] * std::cos(th + a[3]) + 0.1 * a[4] * std::sin(2 * th + pi2 * v);
    Vec3 c, n1;
    if (closed_v) {
      c = {3 * std::cos(pi2 * v), 3 * std::sin(pi2 * v), 0};
      n1 = {std::cos(pi2 * v), std::sin(pi2 * v), 0};
    } else {
      c = {3 * v, a[0] * std::sin(2 * v), a[1] * v * v};
      n1 = {0, 1, 0};
    }
    return c + r * (std::cos(th) * n1 + std::sin(th) * Vec3{0, 0, 1});
  }
};

constexpr std::size_t kSections = 24, kStations = 16;  // points per u-curve, intervals per v-curve

// The curve of the tube through its points at t = k / count (k < count; closed) or
// k <= count (open), k / count its parameters.
BSplineCurve tube_curve(const Tube& tube, bool along_u, double fixed, bool closed, std::size_t count) {
  std::vector<Vec3> q;
  CurveInterpolationOptions o;
  o.periodic = closed;
  for (std::size_t k = 0; k < count + (closed ? 0 : 1); ++k) {
    const double t = static_cast<double>(k) / static_cast<double>(count);
    q.push_back(along_u ? tube(t, fixed) : tube(fixed, t));
    o.params.push_back(t);
  }
  return interpolate_curve(q, o).curve;
}

// n node parameters k / count: 0, then distinct random k, with 1 (k = count) last
// when the direction is open; sorted.
std::vector<double> nodes(std::mt19937_64& g, std::size_t n, std::size_t count, bool closed) {
  std::vector<std::size_t> ks{0};
  if (!closed) ks.push_back(count);
  while (ks.size() < n) {
    const auto k = static_cast<std::size_t>(test::uniform(g, 1, static_cast<double>(count)));
    if (k < count && std::find(ks.begin(), ks.end(), k) == ks.end()) ks.push_back(k);
  }
  std::sort(ks.begin(), ks.end());
  std::vector<double> t;
  for (std::size_t k : ks) t.push_back(static_cast<double>(k) / static_cast<double>(count));
  return t;
}

// The network of closed sections (u-curves, interpolated periodically) and lines
// along the tube (v-curves) at node parameters tu, tv: the curves cross exactly there.
CurveNetwork tube_network(const Tube& tube, const std::vector<double>& tu, const std::vector<double>& tv) {
  CurveNetwork n;
  for (double v : tv) n.u_curves.push_back(tube_curve(tube, true, v, true, kSections));
  for (double u : tu) n.v_curves.push_back(tube_curve(tube, false, u, tube.closed_v, kStations));
  n.u_params = tu;
  n.v_params = tv;
  n.periodic = {true, tube.closed_v};
  return n;
}

Tube random_tube(std::mt19937_64& g, bool closed_v) {
  Tube t{{}, closed_v};
  for (double& x : t.a) x = test::uniform(g);
  return t;
}

// A random tube network: 3..6 sections (a torus: 3..5) and 2..6 lines.
CurveNetwork random_tube_network(std::mt19937_64& g, bool closed_v) {
  const Tube tube = random_tube(g, closed_v);
  const auto nu = static_cast<std::size_t>(test::uniform(g, 2, 7)), nv = static_cast<std::size_t>(test::uniform(g, 3, 7));
  return tube_network(tube, nodes(g, nu, kSections, true), nodes(g, nv, kStations, closed_v));
}

double data_scale(const CurveNetwork& n) {
  std::vector<Vec3> pts;
  for (const auto* list : {&n.u_curves, &n.v_curves})
    for (const auto& c : *list) pts.insert(pts.end(), c.control_points().begin(), c.control_points().end());
  return test::bbox_diagonal(pts);
}

// Each curve sampled at 101 parameters against the surface along its line.
double worst_miss(const Surface& s, const CurveNetwork& n) {
  double e = 0;
  for (double t : linspace(0, 1, 101)) {
    for (std::size_t i = 0; i < n.v_curves.size(); ++i)
      e = std::max(e, distance(s.point(n.u_params[i], t), n.v_curves[i].point(t)));
    for (std::size_t j = 0; j < n.u_curves.size(); ++j)
      e = std::max(e, distance(s.point(t, n.v_params[j]), n.u_curves[j].point(t)));
  }
  return e;
}

TEST(Network, ClosedNetworksInterpolateEveryCurveAndConvertExactly) {
  auto g = test::rng(85);
  for (int trial = 0; trial < 12; ++trial) {
    const bool closed_v = trial % 3 == 2;
    const CurveNetwork n = random_tube_network(g, closed_v);
    const double scale = data_scale(n);
    for (auto m : kMethods) {
      const auto s = curve_network(n, {m, {}, {}});
      // The curves cross at the nodes to the rounding of their interpolations (~1e-15
      // of the data); the surface misses a curve by that times the cardinal functions'
      // sum of magnitudes (a few), plus the rounding of its own few terms.
      EXPECT_LT(worst_miss(s, n), 1e-13 * scale) << "trial " << trial;
      const BSplineSurface b = s.to_bspline();
      EXPECT_EQ(b.periodic(), (std::array<bool, 2>{true, closed_v}));
      const auto k = s.exact_knots();
      EXPECT_EQ(k[0], b.knots_u());
      EXPECT_EQ(k[1], b.knots_v());
      // The exact form sums the same terms after knot insertion and degree elevation
      // (collocation solves in the refined spaces): a few ulps of the data, well
      // within 1e-12 of them, as for open networks.
      for (int p = 0; p < 60; ++p) {
        const double u = test::uniform(g, 0, 1), v = test::uniform(g, 0, 1);
        EXPECT_LT(distance(b.point(u, v), s.point(u, v)), 1e-12 * scale) << "trial " << trial << " at (" << u << ", " << v << ")";
      }
      // Parameters past the seam wrap: the exact form one period on is the same.
      EXPECT_LT(distance(b.point(1.25, 0.5), s.point(0.25, 0.5)), 1e-12 * scale);
    }
  }
}

// |a − b| against the larger of |a| and |b|, the size of that derivative (0 when both
// vanish).
double relative(const Vec3& a, const Vec3& b) { return distance(a, b) / std::max({norm(a), norm(b), 1e-300}); }

// The largest relative jump across the seam u = 0 ≡ 1 (axis 0) or v = 0 ≡ 1 (axis 1)
// of the value (order 0), the first derivatives (order 1) or the second (order 2).
double seam_jump(const Surface& s, int axis, int order) {
  double e = 0;
  for (double t : linspace(0, 1, 13)) {
    const auto a = axis == 0 ? s.derivatives(0, t) : s.derivatives(t, 0);
    const auto b = axis == 0 ? s.derivatives(1, t) : s.derivatives(t, 1);
    const std::vector<Vec3 SurfaceDerivatives::*> parts =
        order == 0 ? std::vector{&SurfaceDerivatives::s}
        : order == 1 ? std::vector{&SurfaceDerivatives::su, &SurfaceDerivatives::sv}
                     : std::vector{&SurfaceDerivatives::suu, &SurfaceDerivatives::suv, &SurfaceDerivatives::svv};
    for (auto part : parts) e = std::max(e, relative(a.*part, b.*part));
  }
  return e;
}

TEST(Network, GordonIsC2AcrossTheSeamHermiteC1LinearC0) {
  auto g = test::rng(86);
  for (int trial = 0; trial < 10; ++trial) {
    const bool closed_v = trial % 2 == 1;
    const Tube tube = random_tube(g, closed_v);
    // 4..6 sections and lines around: cubic closed cardinal functions.
    const auto nu = static_cast<std::size_t>(test::uniform(g, 4, 7)), nv = static_cast<std::size_t>(test::uniform(g, 4, 7));
    const CurveNetwork n = tube_network(tube, nodes(g, nu, kSections, true), nodes(g, nv, kStations, closed_v));
    const auto gordon = curve_network(n), hermite = curve_network(n, {NetworkMethod::coons_hermite, {}, {}}),
               linear = curve_network(n, {NetworkMethod::coons_linear, {}, {}});
    for (int axis = 0; axis < (closed_v ? 2 : 1); ++axis) {
      // Both sides of the seam evaluate the same closed splines on different spans:
      // they agree to rounding, ~1e-14 of each derivative; 1e-10 leaves room for the
      // second derivatives' larger rounding.
      for (int order = 0; order <= 2; ++order) EXPECT_LT(seam_jump(gordon, axis, order), 1e-10) << trial << " " << order;
      for (int order = 0; order <= 1; ++order) EXPECT_LT(seam_jump(hermite, axis, order), 1e-10) << trial << " " << order;
      EXPECT_LT(seam_jump(linear, axis, 0), 1e-10) << trial;
      // The kink of the linear cardinal functions, which the check must see: 3e-3 of the
      // tangent and more in these trials, far above the 1e-10 the smooth ones are held to.
      EXPECT_GT(seam_jump(linear, axis, 1), 1e-4) << trial;
    }
    // The exact forms are as smooth at the seam as anywhere: Gordon C2, Hermite C1.
    EXPECT_EQ(gordon.to_bspline().knots_u().continuity(), 2);
    EXPECT_GE(hermite.to_bspline().knots_u().continuity(), 1);
    EXPECT_TRUE(linear.to_bspline().knots_u().periodic());
  }
}

TEST(Network, ClosedCrossingsFoundAroundTheSeam) {
  auto g = test::rng(87);
  for (int trial = 0; trial < 8; ++trial) {
    const bool closed_v = trial % 2 == 1;
    const Tube tube = random_tube(g, closed_v);
    auto tu = nodes(g, 4, kSections, true);
    tu.back() = 23.0 / 24;  // a line just before the seam: its crossings are found across it
    CurveNetwork n = tube_network(tube, tu, nodes(g, 4, kStations, closed_v));
    const auto p = network_parameters(n);
    ASSERT_EQ(p.u_params.size(), n.u_params.size());
    ASSERT_EQ(p.v_params.size(), n.v_params.size());
    // The curves cross exactly at the nodes; Gauss–Newton finds them to rounding.
    for (std::size_t i = 0; i < n.u_params.size(); ++i) EXPECT_NEAR(p.u_params[i], n.u_params[i], 1e-9) << trial;
    for (std::size_t j = 0; j < n.v_params.size(); ++j) EXPECT_NEAR(p.v_params[j], n.v_params[j], 1e-9) << trial;
    CurveNetwork found = n;
    found.u_params.clear();
    found.v_params.clear();
    const auto s = curve_network(found);
    // Found parameters differ from the true ones by ~1e-15: the surface by that times
    // its slopes, far below 1e-12 of the data.
    EXPECT_LT(test::max_distance(s, curve_network(n)), 1e-12 * data_scale(n)) << trial;
  }
}

TEST(Network, ClosingCurveIsLeftOut) {
  auto g = test::rng(88);
  for (int trial = 0; trial < 6; ++trial) {
    const bool closed_v = trial % 2 == 1;
    CurveNetwork n = random_tube_network(g, closed_v);
    CurveNetwork c = n;  // the first v-curve again at u = 1 (and the first u-curve at v = 1 on a torus)
    c.v_curves.push_back(c.v_curves.front());
    c.u_params.push_back(1.0);
    if (closed_v) {
      c.u_curves.push_back(c.u_curves.front());
      c.v_params.push_back(1.0);
    }
    for (auto m : kMethods) {
      const auto a = curve_network(n, {m, {}, {}}), b = curve_network(c, {m, {}, {}});
      for (double u : linspace(0, 1, 7))
        for (double v : linspace(0, 1, 7)) EXPECT_EQ(a.point(u, v), b.point(u, v));  // the same terms exactly
      EXPECT_NE(std::find_if(b.notes().begin(), b.notes().end(),
                             [](const std::string& x) { return x.find("closing curve") != std::string::npos; }),
                b.notes().end());
    }
    // Found: the closing curve's parameter is 1, the others as without it.
    CurveNetwork cf = c;
    cf.u_params.clear();
    cf.v_params.clear();
    CurveNetwork nf = n;
    nf.u_params.clear();
    nf.v_params.clear();
    const auto pc = network_parameters(cf), pn = network_parameters(nf);
    EXPECT_EQ(pc.u_params.size(), pn.u_params.size() + 1);
    EXPECT_EQ(pc.u_params.back(), 1.0);
    EXPECT_EQ(std::vector<double>(pc.u_params.begin(), pc.u_params.end() - 1), pn.u_params);
    EXPECT_EQ(curve_network(cf).point(0.3, 0.6), curve_network(nf).point(0.3, 0.6));
  }
}

TEST(Network, OpenCurvesWhoseEndsMeetCloseWithASeamOfMultiplicityP) {
  auto g = test::rng(89);
  for (int trial = 0; trial < 6; ++trial) {
    const CurveNetwork n = random_tube_network(g, false);
    CurveNetwork open = n;  // the same sections as open curves of their domain
    for (auto& c : open.u_curves) c = c.clamped();
    const double scale = data_scale(n);
    for (auto m : kMethods) {
      const auto a = curve_network(n, {m, {}, {}}), b = curve_network(open, {m, {}, {}});
      // clamped() re-solves each section in the open space: ~1e-15 of the data apart.
      EXPECT_LT(test::max_distance(a, b), 1e-13 * scale) << trial;
      EXPECT_LT(worst_miss(b, open), 1e-13 * scale) << trial;
      const BSplineSurface e = b.to_bspline();
      EXPECT_TRUE(e.knots_u().periodic());
      EXPECT_EQ(e.knots_u().multiplicity(0.0), 3);  // the sections' seam, C0 as far as the knots tell
      EXPECT_LT(test::max_distance(e, b), 1e-12 * scale) << trial;
      EXPECT_FALSE(b.notes().empty());
    }
  }
}

TEST(Network, ClosedDirectionErrors) {
  auto g = test::rng(90);
  const CurveNetwork n = random_tube_network(g, false);
  auto open = n;  // a section cut open: its ends do not meet
  auto cp = open.u_curves[1].clamped().control_points();
  cp.back().z += 0.25;
  open.u_curves[1] = BSplineCurve(open.u_curves[1].clamped().knots(), cp);
  EXPECT_ERRC((void)curve_network(open), network_gap, "u_curves[1] is not closed");
  EXPECT_ERRC((void)network_parameters(open), network_gap, "u_curves[1] is not closed");
  auto params = n;  // 1 for a curve that is not the first again
  params.u_params.back() = 1.0;
  EXPECT_ERRC((void)curve_network(params), network_gap, "where a network closed in u has v_curves[0] again");
  params.u_params = n.u_params;
  params.u_params.front() = -0.25;
  EXPECT_ERRC((void)curve_network(params), out_of_domain, "must run from 0 to below 1");
  auto closing = n;  // a last v-curve at u = 1 that is not the first again
  closing.v_curves.push_back(closing.v_curves.back());
  closing.u_params.push_back(1.0);
  EXPECT_ERRC((void)curve_network(closing), network_gap, "v_curves[0] again, but the two are up to");
  closing.v_curves.back() = closing.v_curves.front();
  closing.u_params.pop_back();
  EXPECT_ERRC((void)curve_network(closing), size_mismatch, "u_params, got");
  auto two = n;  // one line and its closing copy: one distinct v-curve
  two.v_curves = {n.v_curves[0], n.v_curves[0]};
  two.u_params = {0, 1};
  EXPECT_ERRC((void)curve_network(two), too_few_points, "at least 2 distinct v_curves");
}

// Closed curves in a network that is not closed: each used as the open curve of its
// domain (a tube cut open along v_curves[0], which is repeated at u = 1).
TEST(Network, ClosedCurvesInAnOpenNetworkAreUsedOpen) {
  auto g = test::rng(92);
  for (int trial = 0; trial < 4; ++trial) {
    CurveNetwork n = random_tube_network(g, false);
    n.periodic = {false, false};
    n.v_curves.push_back(n.v_curves.front());
    n.u_params.push_back(1.0);
    const double scale = data_scale(n);
    for (auto m : kMethods) {
      const auto s = curve_network(n, {m, {}, {}});
      EXPECT_LT(worst_miss(s, n), 1e-13 * scale) << trial;  // as for closed networks
      const BSplineSurface e = s.to_bspline();
      EXPECT_EQ(e.periodic(), (std::array<bool, 2>{false, false}));
      EXPECT_LT(test::max_distance(e, s), 1e-12 * scale) << trial;  // as for closed networks
    }
  }
}

// The spec's "periodic" builds the network closed in u: the same surface as the
// library's from the same curves. The spec's curves are open B-splines: the sections
// go in as the open forms of the closed ones.
TEST(Network, SpecPeriodicBuildsTheSameSurface) {
  auto g = test::rng(91);
  for (int trial = 0; trial < 4; ++trial) {
    const CurveNetwork closed = random_tube_network(g, false);
    CurveNetwork open = closed;
    for (auto& c : open.u_curves) c = c.clamped();
    auto curves = [](const std::vector<BSplineCurve>& cs) {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& c : cs) {
        nlohmann::json pts = nlohmann::json::array();
        for (const Vec3& p : c.control_points()) pts.push_back({p.x, p.y, p.z});
        a.push_back({{"bspline", {{"degree", c.degree()}, {"knots", c.knots().values()}, {"control_points", pts}}}});
      }
      return a;
    };
    const nlohmann::json spec = {{"type", "network"},         {"u_curves", curves(open.u_curves)},
                                 {"v_curves", curves(open.v_curves)}, {"u_params", open.u_params},
                                 {"v_params", open.v_params},  {"periodic", {true, false}}};
    io::Construction c = io::build(spec);
    ASSERT_TRUE(c.exact.has_value());
    const auto& e = std::get<BSplineSurface>(*c.exact);
    const BSplineSurface lib = curve_network(open).to_bspline();
    EXPECT_EQ(e.knots_u(), lib.knots_u());
    EXPECT_EQ(e.knots_v(), lib.knots_v());
    EXPECT_EQ(e.control_points().values(), lib.control_points().values());  // the same curves, the same arithmetic
    EXPECT_EQ(c.parameters["periodic"], nlohmann::json({true, false}));
    // And the surface of the closed sections themselves, to the rounding of clamped().
    EXPECT_LT(test::max_distance(e, curve_network(closed)), 1e-12 * data_scale(closed)) << trial;
  }
  nlohmann::json bad = {{"type", "network"},
                        {"u_curves", {{{"line", {{0, 0, 0}, {1, 0, 0}}}}, {{"line", {{0, 1, 0}, {1, 1, 0}}}}}},
                        {"v_curves", {{{"line", {{0, 0, 0}, {0, 1, 0}}}}, {{"line", {{1, 0, 0}, {1, 1, 0}}}}}}};
  bad["periodic"] = true;
  EXPECT_ERRC((void)io::build(bad), wrong_type, "/periodic: expected an array of 2 booleans [u, v]");
  bad["periodic"] = {true};
  EXPECT_ERRC((void)io::build(bad), wrong_type, "/periodic: expected 2 booleans [u, v], one per direction, got 1");
  bad["periodic"] = {true, 1};
  EXPECT_ERRC((void)io::build(bad), wrong_type, "/periodic/1: expected true or false (is v closed?), got a number");
  bad["periodic"] = {true, false};  // the u_curves are open and far from closed
  EXPECT_ERRC((void)io::build(bad), network_gap, "/u_curves/0 is not closed");
}

}  // namespace
}  // namespace interpatch
