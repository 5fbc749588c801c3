// The promise harness for curve networks (issue 36): the methods gordon,
// coons_linear and coons_hermite, from curves that cross at given common parameters
// and from curves as drawn (no parameters, listed out of order, some reversed), open
// and closed in u. The curves are iso-curves of a random B-spline surface of the
// harness's own ("the truth"), so the harness knows where each curve must lie on the
// network's surface. See promise_harness.hpp for the generators and the oracle.

#include <gtest/gtest.h>

#include <numeric>

#include "promise_harness.hpp"

namespace interpatch::promise {
namespace {

// Network cases are the costliest of the harness (crossings, sorting and
// re-expression per case): 1000 per run, each of 2 to 4 curves per family.
constexpr std::size_t kCases = 1000;

struct NetCurve {
  Tensor curve;        // the curve as given, over [0, 1]
  double at = 0;       // its true parameter across (v_j of a u_curve, u_i of a v_curve)
  bool reversed = false;
};

struct Network {
  std::vector<NetCurve> u_curves, v_curves;  // in the order the spec lists them
  bool closed_u = false, drawn = false;
  std::string method;
  Box box;
};

// The curve run backwards over the same knot range: knots reflected, control
// points reversed (for a periodic curve the control point of basis function i of the
// reflected knots is that of function N + p − 1 − i of the original).
Tensor reversed(const Tensor& c) {
  Tensor r = c;
  const auto& k = c.knots[0];
  const double a = c.domain(0).first, b = c.domain(0).second;
  for (std::size_t i = 0; i < k.size(); ++i) r.knots[0][i] = a + b - k[k.size() - 1 - i];
  const std::size_t n = c.n[0], p = static_cast<std::size_t>(c.p[0]);
  for (std::size_t i = 0; i < n; ++i) r.cp[i] = c.periodic[0] ? c.cp[(n + p - 1 - i) % n] : c.cp[n - 1 - i];
  return r;
}

Network random_network(std::mt19937_64& g) {
  Network net;
  const Frame f = random_frame(g);
  net.closed_u = chance(g, 0.25);
  net.drawn = chance(g, 0.5);
  net.method = std::vector<std::string>{"gordon", "coons_linear", "coons_hermite"}[static_cast<std::size_t>(pick(g, 0, 2))];
  int p[2];
  std::size_t n[2];
  const bool periodic[2] = {net.closed_u, false};
  for (int a = 0; a < 2; ++a) {
    p[a] = pick(g, 1, 3);
    n[a] = static_cast<std::size_t>(p[a] + 1 + pick(g, 0, 2));
    // a closed polygon of 2 points runs along one segment and back: every curve
    // across meets it twice, and the surface may pass the curves with another
    // parametrization than the truth's
    if (periodic[a]) n[a] = std::max<std::size_t>(n[a], 3);
  }
  Tensor truth = random_tensor(g, f, 2, p, n, periodic, 0.1);
  if (!net.closed_u && chance(g, 0.1))  // a pole: the surface's v = 0 line is one point
    for (std::size_t i = 0; i < n[0]; ++i) truth.cp[i * n[1]] = truth.cp[0];
  // where the curves lie: v_curves at u_i (closed: 0 and then below 1), u_curves at v_j
  const std::size_t nv = static_cast<std::size_t>(pick(g, net.closed_u ? 3 : 2, 4));
  const std::size_t nu = static_cast<std::size_t>(pick(g, 2, 4));
  auto stations = [&](std::size_t count, bool closed) {
    std::vector<double> t;
    for (std::size_t i = 0; i < count; ++i)
      t.push_back(closed ? (double(i) + uni(g, -0.25, 0.25) * (i > 0)) / double(count)
                         : (i == 0 ? 0.0 : i + 1 == count ? 1.0 : (double(i) + uni(g, -0.3, 0.3)) / double(count - 1)));
    if (chance(g, 0.05) && count > 2 && !closed) t[1] = t[0] + 1e-6;  // two curves of a family nearly together
    return t;
  };
  const auto tu = stations(nv, net.closed_u), tv = stations(nu, false);
  for (double v : tv) net.u_curves.push_back({contract(truth, 1, v), v, false});
  for (double u : tu) net.v_curves.push_back({contract(truth, 0, u), u, false});
  if (net.drawn) {
    // as drawn: listed out of order, some backwards; a closed direction keeps
    // v_curves[0] first (it is where u = 0) and its closed curves forwards
    auto shuffle = [&](std::vector<NetCurve>& cs, bool keep_first, bool may_reverse) {
      std::shuffle(cs.begin() + (keep_first ? 1 : 0), cs.end(), g);
      for (std::size_t i = keep_first ? 1 : 0; i < cs.size(); ++i)
        if (may_reverse && chance(g, 0.3)) {
          cs[i].curve = reversed(cs[i].curve);
          cs[i].reversed = true;
        }
    };
    shuffle(net.u_curves, false, !net.closed_u);
    shuffle(net.v_curves, net.closed_u, true);
  }
  for (const auto* fam : {&net.u_curves, &net.v_curves})
    for (const auto& c : *fam)
      for (const Vec3& q : c.curve.cp) net.box.add(q);
  return net;
}

json network_spec(const Network& net) {
  json us = json::array(), vs = json::array(), up = json::array(), vp = json::array();
  for (const auto& c : net.u_curves) {
    us.push_back(curve_spec(c.curve));
    vp.push_back(c.at);
  }
  for (const auto& c : net.v_curves) {
    vs.push_back(curve_spec(c.curve));
    up.push_back(c.at);
  }
  json spec = {{"type", "network"}, {"method", net.method}, {"u_curves", us}, {"v_curves", vs}};
  if (!net.drawn) {
    spec["u_params"] = up;
    spec["v_params"] = vp;
  }
  if (net.closed_u) spec["periodic"] = {true, false};
  return spec;
}

// The distance from q to the curve as a point set: the closest of 1025 samples,
// then golden-section search over the intervals beside it (the harness's curves turn
// by far less than a sample step's worth between samples, so the distance has one
// minimum there).
double distance_to_curve(const Tensor& c, const Vec3& q) {
  const auto [a, b] = c.domain(0);
  constexpr int n = 1024;
  int best = 0;
  double dbest = distance(c.eval(a).s, q);
  for (int k = 1; k <= n; ++k) {
    const double d = distance(c.eval(a + (b - a) * k / n).s, q);
    if (d < dbest) dbest = d, best = k;
  }
  double lo = a + (b - a) * std::max(best - 1, 0) / n, hi = a + (b - a) * std::min(best + 1, n) / n;
  const double r = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 80; ++it) {
    const double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
    if (distance(c.eval(x1).s, q) < distance(c.eval(x2).s, q)) hi = x2;
    else lo = x1;
  }
  return std::min(dbest, distance(c.eval(0.5 * (lo + hi)).s, q));
}

// How much interpolating across a family amplifies the rounding of its curves'
// values: the cardinal functions of sites h apart (relative to the domain) reach
// about 1/h, so the formula, a sum of curve values times cardinal functions, and
// its exact form, a solve of the same system, differ by rounding times 1/h
// (docs/spec-format.md, "Surfaces": agreement to rounding "amplified by curves close
// together"). The tensor-product term carries both families' factors.
double cross_amplification(const Network& net) {
  double a = 1;
  for (const auto* fam : {&net.u_curves, &net.v_curves}) {
    std::vector<double> at;
    for (const auto& c : *fam) at.push_back(c.at);
    if (net.closed_u && fam == &net.v_curves) at.push_back(1.0);  // the seam: u_0 again at 1
    std::sort(at.begin(), at.end());
    double h = 1;
    for (std::size_t i = 1; i < at.size(); ++i) h = std::min(h, at[i] - at[i - 1]);
    a *= 1 / std::max(h, 1e-12);
  }
  return a;
}

void network_family() {
  Network net;
  run_family(
      "network", 0x4e7, kCases,
      {errc::missing_field, errc::wrong_type, errc::too_few_points, errc::size_mismatch, errc::non_increasing,
       errc::out_of_domain, errc::network_gap, errc::network_order, errc::tolerance_not_met},
      [&](std::mt19937_64& g) {
        net = random_network(g);
        return network_spec(net);
      },
      [&](const json&, io::Construction& c, Findings& f) {
        const double amplification = cross_amplification(net);
        const auto t = check_surface_common(c, net.box, f, 5, amplification);
        if (!t) {
          // Curves of both families close together can amplify rounding past the 1e-8
          // by which the exact form may differ from the formula (1e4 rounding steps,
          // as data_tol, times the amplification): build then refuses it, as it says.
          if (conversion_refused(c) && 1e4 * eps * amplification >= 1e-8) return;
          return f.add("network of polynomial curves without an exact form");
        }
        if (t->periodic[0] != net.closed_u) f.add("exact form periodic in u differs from the spec");
        // Where each curve lies: its parameter as the construction reports it (given,
        // or found from the curves), which must be the truth's up to the closest-point
        // search (1e-6 of the unit domain: crossings are found to a far smaller
        // distance, 1e-7 of the diagonal, and the curves cross at angles of order 1).
        const auto& up = c.parameters["u_params"];
        const auto& vp = c.parameters["v_params"];
        // A curve used as given lies on the surface to data_tol; a re-expressed one
        // (drawn networks) within half of 1e-7 of the control points' diagonal
        // (docs/spec-format.md, network step 4), plus data_tol.
        // Curves close together amplify the rounding of the curves' values (see
        // cross_amplification): 16 rounding steps of the coordinates, times that.
        const double tol = (net.drawn ? 1e-7 * net.box.diagonal() : 0.0) + data_tol(net.box) +
                           rounding(net.box, 16) * amplification;
        // The surface may run against the truth along a direction: a family runs the
        // way most of its curves run (docs/spec-format.md, network step 2), so when
        // most u_curves were drawn backwards, u runs backwards. The reported
        // parameters say which: v_curves[i] at 1 − u_i instead of u_i.
        // In a closed direction the reflection is u → 1 − u taken round the period, so
        // that u_0 = 0 stays at 0.
        auto flipped = [&](const std::vector<NetCurve>& fam, const json& params, bool closed) {
          bool all = true;
          for (std::size_t i = 0; i < fam.size(); ++i) {
            double d = std::abs(params.at(i).get<double>() - (1 - fam[i].at));
            if (closed) d = std::min(d, std::abs(1 - d));
            all = all && d <= 1e-6;
          }
          bool same = true;
          for (std::size_t i = 0; i < fam.size(); ++i) same = same && std::abs(params.at(i).get<double>() - fam[i].at) <= 1e-6;
          return all && !same;
        };
        const bool flip_u = flipped(net.v_curves, up, net.closed_u), flip_v = flipped(net.u_curves, vp, false);
        auto check = [&](const std::vector<NetCurve>& fam, const json& params, int axis, bool flip_along, bool flip_across,
                         const char* name) {
          for (std::size_t i = 0; i < fam.size(); ++i) {
            const double at = params.at(i).get<double>();
            const double truth = flip_across ? 1 - fam[i].at : fam[i].at;
            // given parameters are reported as given (found ones are checked only by the
            // surface passing through the curve there: a closed family may be sorted
            // round the other way)
            if (!net.drawn && !(std::abs(at - truth) <= 1e-6))
              f.add(std::string(name) + "[" + std::to_string(i) + "] reported at " + std::to_string(at) + ", truth " +
                    std::to_string(truth));
            const auto [a, b] = fam[i].curve.domain(0);
            if (net.drawn) {
              // Curves as drawn are passed as point sets: the parametrization along a
              // curve is the construction's, from crossings found to the rounding of
              // the coordinates (docs/spec-format.md, network step 4).
              const std::string what = std::string(name) + "[" + std::to_string(i) + "]";
              for (int k = 0; k <= 16; ++k) {
                const double s = k / 16.0;
                const Vec3 on = axis == 1 ? t->eval(s, at).s : t->eval(at, s).s;
                const double d = distance_to_curve(fam[i].curve, on);
                if (!(d <= tol))
                  f.add(what + " at " + std::to_string(s) + ": the surface is " + std::to_string(d) +
                        " from the curve, tolerance " + std::to_string(tol));
              }
              // and over the whole of an open curve: the line's ends are the curve's
              if (!fam[i].curve.periodic[0]) {
                const Vec3 e0 = axis == 1 ? t->eval(0, at).s : t->eval(at, 0).s;
                const Vec3 e1 = axis == 1 ? t->eval(1, at).s : t->eval(at, 1).s;
                const Vec3 c0 = fam[i].curve.eval(a).s, c1 = fam[i].curve.eval(b).s;
                const double ends = std::min(std::max(distance(e0, c0), distance(e1, c1)),
                                             std::max(distance(e0, c1), distance(e1, c0)));
                if (!(ends <= tol))
                  f.add(what + ": the surface's line ends " + std::to_string(ends) + " from the curve's ends, tolerance " +
                        std::to_string(tol));
              }
              continue;
            }
            for (int k = 0; k <= 8; ++k) {
              const double s = k / 8.0, along = flip_along ? 1 - s : s, own = fam[i].reversed ? 1 - along : along;
              const Vec3 on = axis == 1 ? t->eval(s, at).s : t->eval(at, s).s;
              f.near(std::string(name) + "[" + std::to_string(i) + "] at " + std::to_string(s), on,
                     fam[i].curve.eval(a + own * (b - a)).s, tol);
            }
          }
        };
        check(net.u_curves, vp, 1, flip_u, flip_v, "/u_curves");
        check(net.v_curves, up, 0, flip_v, flip_u, "/v_curves");
      },
      0.7);
}

TEST(PromiseNetworks, GordonAndCoonsNetworks) { network_family(); }

}  // namespace
}  // namespace interpatch::promise
