#include "interpatch/network.hpp"

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
      const auto c = curve_network(n, {m, {}});
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
  EXPECT_GT(test::max_distance(curve_network(n, {NetworkMethod::coons_linear, {}}), bez), 1e-3);
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
  EXPECT_LT(jump(curve_network(n, {NetworkMethod::coons_hermite, {}})), 1e-5);
  EXPECT_LT(jump(curve_network(n, {NetworkMethod::gordon, {}})), 1e-5);
  EXPECT_GT(jump(curve_network(n, {NetworkMethod::coons_linear, {}})), 1e-2);  // the kink the check must see
  const auto b = curve_network(n, {NetworkMethod::coons_hermite, {}}).to_bspline();
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
  EXPECT_ERRC((void)curve_network(bad), network_gap, "u_curves[1] and v_curves[0] miss each other at node (0, 1)");
  EXPECT_ERRC((void)curve_network(bad), network_gap, "gap 0.125");
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

}  // namespace
}  // namespace interpatch
