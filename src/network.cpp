#include "interpatch/network.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "blended_terms.hpp"
#include "detail/text.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"

namespace interpatch {

using detail::fail;

namespace {

std::vector<BSplineCurve> on_unit(const std::vector<BSplineCurve>& cs) {
  std::vector<BSplineCurve> out;
  out.reserve(cs.size());
  for (const auto& c : cs) out.push_back(detail::unit(c));
  return out;
}

void check_counts(const CurveNetwork& n) {
  if (n.u_curves.size() < 2 || n.v_curves.size() < 2)
    fail(errc::too_few_points, "a curve network needs at least 2 u_curves and 2 v_curves, got ", n.u_curves.size(),
         " and ", n.v_curves.size());
}

// t moved by whole periods into [0, 1).
double wrap_unit(double t) {
  const double r = t - std::floor(t);
  return r < 1.0 ? r : 0.0;  // a tiny negative t rounds to 1
}

// Closest points of two curves over [0, 1]: a coarse search, then Gauss–Newton on
// F(s, t) = U(s) − V(t). A closed curve's parameter wraps around its seam; an open
// one's stays in [0, 1].
std::pair<double, double> closest(const BSplineCurve& U, const BSplineCurve& V, bool closed_u, bool closed_v) {
  constexpr int samples = 64;
  Vec3 us[samples + 1], vs[samples + 1];
  for (int k = 0; k <= samples; ++k) {
    us[k] = U.point(static_cast<double>(k) / samples);
    vs[k] = V.point(static_cast<double>(k) / samples);
  }
  double best = std::numeric_limits<double>::infinity(), s = 0, t = 0;
  for (int a = 0; a <= samples; ++a)
    for (int b = 0; b <= samples; ++b) {
      const double d = distance(us[a], vs[b]);
      if (d < best) {
        best = d;
        s = static_cast<double>(a) / samples;
        t = static_cast<double>(b) / samples;
      }
    }
  // The next parameter, and how far it moved (around the circle for a closed curve).
  const auto step = [](double x, double dx, bool closed) {
    if (!closed) {
      const double n = std::clamp(x + dx, 0.0, 1.0);
      return std::pair{n, std::abs(n - x)};
    }
    const double n = wrap_unit(x + dx), moved = std::abs(n - x);
    return std::pair{n, std::min(moved, 1.0 - moved)};
  };
  for (int it = 0; it < 50; ++it) {
    Vec3 du[2], dv[2];
    U.derivatives(s, 1, du);
    V.derivatives(t, 1, dv);
    // Normal equations of J = [U'(s), −V'(t)], with U', V' and F in units of 2^e, e the
    // exponent of the largest component of U' and V': exact, and it keeps det, a
    // product of four of them, in range at any scale of the data (and the test below
    // relative to the tangents), while the steps ds, dt come out as they are.
    const int e = scale_exponent(std::max(max_abs(du[1]), max_abs(dv[1])));
    const Vec3 Us = ldexp(du[1], -e), Vs = ldexp(dv[1], -e), F = ldexp(du[0] - dv[0], -e);
    const double a11 = dot(Us, Us), a12 = -dot(Us, Vs), a22 = dot(Vs, Vs);
    const double r1 = -dot(Us, F), r2 = dot(Vs, F);
    const double det = a11 * a22 - a12 * a12;
    if (!(std::abs(det) > 1e-300)) break;  // parallel tangents: keep the sampled pair
    const double ds = (r1 * a22 - a12 * r2) / det, dt = (a11 * r2 - a12 * r1) / det;
    const auto [ns, ms] = step(s, ds, closed_u);
    const auto [nt, mt] = step(t, dt, closed_v);
    const bool done = ms < 1e-15 && mt < 1e-15;
    s = ns;
    t = nt;
    if (done) break;
  }
  return {s, t};
}

// Given crossing parameters of a family of curves: increasing, from 0 to 1, or in a
// closed direction from 0 to below 1 (the first curve again at 1).
void check_params(const std::vector<double>& p, const char* name, bool closed) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!std::isfinite(p[i])) fail(errc::not_finite, name, "[", i, "] is ", p[i]);
    if (i > 0 && !(p[i] > p[i - 1]))
      fail(errc::non_increasing, name, "[", i, "] = ", p[i], " is not greater than ", name, "[", i - 1, "] = ", p[i - 1]);
  }
  if (closed) {
    if (p.front() != 0.0 || !(p.back() < 1.0))
      fail(errc::out_of_domain, name, " of a closed direction must run from 0 to below 1 (1 is the first curve "
                                      "again), got ", p.front(), " to ", p.back());
  } else if (p.front() != 0.0 || p.back() != 1.0) {
    fail(errc::out_of_domain, name, " must run from 0 to 1, got ", p.front(), " to ", p.back());
  }
}

double control_diagonal(const CurveNetwork& n) {
  constexpr double inf = std::numeric_limits<double>::infinity();  // 1e300 would cap data beyond it
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (const auto* list : {&n.u_curves, &n.v_curves})
    for (const auto& c : *list)
      for (const Vec3& p : c.control_points())
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], p[k]);
          hi[k] = std::max(hi[k], p[k]);
        }
  return norm(hi - lo);
}

// Cardinal functions φ_i(t_k) = δ_ik over the node parameters t; periodic over
// [0, 1) for a closed direction (t from 0 to below 1).
std::vector<detail::Scalar> cardinals(const std::vector<double>& t, NetworkMethod method, bool closed) {
  const std::size_t n = t.size();
  std::vector<detail::Scalar> out;
  out.reserve(n);
  if (method == NetworkMethod::coons_linear) {
    // Hat functions; closed, basis function i of the periodic knots t peaks at t_i,
    // and the one of the last node falls to 0 at 1, where the first rises from.
    std::vector<double> k{t.front()};
    k.insert(k.end(), t.begin(), t.end());
    k.push_back(t.back());
    const KnotVector kv = closed ? KnotVector::periodic_from(1, t, 1.0) : KnotVector(1, k);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> c(n, 0.0);
      c[i] = 1.0;
      out.push_back(detail::scalar(kv, c));
    }
  } else if (method == NetworkMethod::coons_hermite) {
    // α0/α1 of each cell in Bézier form: the two control coefficients next to node
    // i are 1, all others 0; double interior knots keep the pieces C1 (f' = 0 at nodes).
    // Closed: every node a double knot, the seam too, and the two coefficients of
    // node i are 2i + 1 and 2i + 2 (the seam's, 2n − 1 and 0, wrapped).
    std::vector<double> k;
    if (closed) {
      for (double x : t) k.insert(k.end(), 2, x);
    } else {
      k.assign(4, t.front());
      for (std::size_t i = 1; i + 1 < n; ++i) k.insert(k.end(), 2, t[i]);
      k.insert(k.end(), 4, t.back());
    }
    const KnotVector kv = closed ? KnotVector::periodic_from(3, k, 1.0) : KnotVector(3, k);
    const std::size_t shift = closed ? 1 : 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> c(2 * n, 0.0);
      c[(2 * i + shift) % (2 * n)] = c[(2 * i + 1 + shift) % (2 * n)] = 1.0;
      out.push_back(detail::scalar(kv, c));
    }
  } else {
    CurveInterpolationOptions o;
    o.degree = std::min<int>(3, static_cast<int>(n) - 1);
    o.params = t;
    o.periodic = closed;
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<Vec3> e(n);
      e[i] = {1, 0, 0};
      if (!closed) {
        out.push_back(interpolate_curve(e, o).curve);
        continue;
      }
      // y = k keeps the last point from repeating the first (both 0 in x for most i),
      // which closed interpolation would take for a closing point; the x coordinates
      // are solved for independently of y, and only they are kept.
      for (std::size_t k = 0; k < n; ++k) e[k].y = static_cast<double>(k);
      const BSplineCurve c = interpolate_curve(e, o).curve;
      std::vector<double> x;
      x.reserve(c.control_points().size());
      for (const Vec3& q : c.control_points()) x.push_back(q.x);
      out.push_back(detail::scalar(c.knots(), x));
    }
  }
  return out;
}

// The ends of a curve over [0, 1] are within tol of each other.
bool ends_meet(const BSplineCurve& c, double tol) { return distance(c.point(0.0), c.point(1.0)) <= tol; }

// An open curve over [0, 1] whose ends meet, as the closed curve it is: over the
// periodic knots of its interior knots and the seam p times (C0 there, as the open
// curve is), its first and last control points made one (their mean). Open basis
// function j has the knots of periodic basis function p − 1 + j over the domain, so
// control point j goes to (p − 1 + j) mod N, N = the open curve's count − 1.
BSplineCurve closed_form(BSplineCurve c) {
  if (c.periodic()) return c;
  if (c.knots().interior_breaks().empty()) c = c.inserted(0.5);  // a closed spline needs p + 1 control points
  const KnotVector& k = c.knots();
  const auto p = static_cast<std::size_t>(k.degree());
  std::vector<double> period(p, k.front());
  for (std::size_t i = p + 1; i + p + 1 < k.size(); ++i) period.push_back(k[i]);
  KnotVector closed = KnotVector::periodic_from(k.degree(), std::move(period), k.back());
  const auto N = static_cast<std::size_t>(closed.count());
  const auto& P = c.control_points();
  const auto& W = c.weights();
  std::vector<Vec3> q(N);
  std::vector<double> w(W.empty() ? 0 : N);
  for (std::size_t j = 0; j < N; ++j) {
    q[(p - 1 + j) % N] = P[j];
    if (!W.empty()) w[(p - 1 + j) % N] = W[j];
  }
  q[p - 1] = 0.5 * (P[0] + P[N]);
  if (!W.empty()) w[p - 1] = 0.5 * (W[0] + W[N]);
  return BSplineCurve(std::move(closed), std::move(q), std::move(w));
}

// How far apart two curves over [0, 1] are at 129 parameters: 0 for a repeated curve.
double curve_distance(const BSplineCurve& a, const BSplineCurve& b) {
  double d = 0;
  for (double t : linspace(0, 1, 129)) d = std::max(d, distance(a.point(t), b.point(t)));
  return d;
}

constexpr const char* curves_name(int a) { return a == 0 ? "u_curves" : "v_curves"; }
constexpr const char* params_name(int a) { return a == 0 ? "u_params" : "v_params"; }

// The network as the construction uses it: every curve over [0, 1]; in a closed
// direction a), the curves along it closed and the closing curve of the family across
// it left out; in an open direction, the curves along it open.
struct Prepared {
  std::array<std::vector<BSplineCurve>, 2> along;  // along[0]: the u_curves, along[1]: the v_curves
  std::array<bool, 2> closed{false, false};
  std::array<bool, 2> closing{false, false};  // closing[a]: the last curve across direction a left out
  double tol = 0;  // how far curves may miss each other (NetworkOptions::tolerance)
  std::vector<std::string> notes;
};

Prepared prepare(const CurveNetwork& n, const NetworkOptions& o) {
  check_counts(n);
  Prepared r;
  const double tol = r.tol = o.tolerance ? *o.tolerance : 1e-7 * control_diagonal(n);
  r.closed = n.periodic;
  r.along = {on_unit(n.u_curves), on_unit(n.v_curves)};
  for (int a = 0; a < 2; ++a) {
    auto& along = r.along[static_cast<std::size_t>(a)];
    if (!r.closed[static_cast<std::size_t>(a)]) {
      for (auto& c : along) c = c.clamped();
      continue;
    }
    std::vector<std::size_t> opened;
    for (std::size_t j = 0; j < along.size(); ++j) {
      if (along[j].periodic()) continue;
      if (!ends_meet(along[j], tol))
        fail(errc::network_gap, curves_name(a), "[", j, "] is not closed, and the network is closed in ",
             a == 0 ? "u" : "v", ": its ends ", along[j].point(0.0), " and ", along[j].point(1.0), " are ",
             distance(along[j].point(0.0), along[j].point(1.0)), " apart (tolerance ", tol, ")");
      along[j] = closed_form(along[j]);
      opened.push_back(j);
    }
    if (!opened.empty()) {
      std::string which;
      for (std::size_t j : opened) which += detail::cat(which.empty() ? "" : ", ", j);
      r.notes.push_back(detail::cat(curves_name(a), " ", which, ": open curves whose ends meet, closed with a C0 seam"));
    }
  }
  // The closing curve: given parameters say it (the last is 1); without them, a last
  // curve on the first is one (a curve the same as the first at another parameter
  // could not cross the others further on).
  for (int a = 0; a < 2; ++a) {
    auto& across = r.along[static_cast<std::size_t>(1 - a)];
    if (!r.closed[static_cast<std::size_t>(a)]) continue;
    const auto& given = a == 0 ? n.u_params : n.v_params;
    const double apart = curve_distance(across.front(), across.back());
    if (given.empty() ? !(apart <= tol) : given.size() != across.size() || given.back() != 1.0) continue;
    if (!(apart <= tol))
      fail(errc::network_gap, curves_name(1 - a), "[", across.size() - 1, "] is at ", a == 0 ? "u" : "v", " = 1 (",
           params_name(a), "[", across.size() - 1, "]), where a network closed in ", a == 0 ? "u" : "v", " has ",
           curves_name(1 - a), "[0] again, but the two are up to ", apart, " apart (tolerance ", tol,
           "): give parameters below 1, or repeat ", curves_name(1 - a), "[0] there");
    across.pop_back();
    r.closing[static_cast<std::size_t>(a)] = true;
    r.notes.push_back(detail::cat("the last of the ", curves_name(1 - a), " repeats the first: the closing curve, left out"));
    if (across.size() < 2)
      fail(errc::too_few_points, "a curve network closed in ", a == 0 ? "u" : "v", " needs at least 2 distinct ",
           curves_name(1 - a), ", got 1 and the closing curve");
  }
  return r;
}

// The crossing parameters of the prepared curves, one per curve used (closing curves
// left out).
NetworkParameters crossings(const Prepared& n) {
  const auto& U = n.along[0];
  const auto& V = n.along[1];
  const std::size_t nu = V.size(), nv = U.size();  // nodes along u, along v
  NetworkParameters r{std::vector<double>(nu, 0.0), std::vector<double>(nv, 0.0)};
  // In a closed direction a curve's crossings are taken within half a period of its
  // first one before they are averaged, so that crossings on either side of the seam
  // do not average to the far side of the curve.
  std::vector<double> first_u(nu), first_v(nv);
  auto near = [](double x, double ref, bool closed) { return closed ? x + std::round(ref - x) : x; };
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      auto [s, t] = closest(U[j], V[i], n.closed[0], n.closed[1]);
      if (j == 0) first_u[i] = s;
      if (i == 0) first_v[j] = t;
      s = near(s, first_u[i], n.closed[0]);
      t = near(t, first_v[j], n.closed[1]);
      r.u_params[i] += s / static_cast<double>(nv);
      r.v_params[j] += t / static_cast<double>(nu);
    }
  for (int a = 0; a < 2; ++a) {
    auto& p = a == 0 ? r.u_params : r.v_params;
    if (n.closed[static_cast<std::size_t>(a)]) {
      for (double& x : p) x = wrap_unit(x);
      p.front() = 0.0;  // where the closed curves start
    } else {
      p.front() = 0.0;  // the end curves bound the network
      p.back() = 1.0;
    }
    for (std::size_t i = 1; i < p.size(); ++i)
      if (!(p[i] > p[i - 1]))
        fail(errc::non_increasing, "the ", curves_name(1 - a), " ", i - 1, " and ", i,
             " cross the other curves at parameters ", p[i - 1], " and ", p[i],
             ", which do not increase: the curves are not in order");
  }
  return r;
}

// Given crossing parameters of the family across direction a, one per curve given:
// the closing curve's (1) is left out with the curve.
void given_params(std::vector<double>& p, std::size_t curves, const Prepared& n, int a) {
  if (p.size() != curves)
    fail(errc::size_mismatch, curves, " ", curves_name(1 - a), " need ", curves, " ", params_name(a), ", got ", p.size());
  if (n.closing[static_cast<std::size_t>(a)]) p.pop_back();
}

}  // namespace

NetworkParameters network_parameters(const CurveNetwork& network, const NetworkOptions& options) {
  const Prepared n = prepare(network, options);
  NetworkParameters r = crossings(n);
  if (n.closing[0]) r.u_params.push_back(1.0);
  if (n.closing[1]) r.v_params.push_back(1.0);
  return r;
}

BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options) {
  Prepared n = prepare(network, options);
  const double tol = n.tol;
  const auto& U = n.along[0];
  const auto& V = n.along[1];
  const std::size_t nu = V.size(), nv = U.size();
  std::vector<double> tu = network.u_params, tv = network.v_params;
  if (tu.empty() || tv.empty()) {
    const auto found = crossings(n);
    if (tu.empty()) tu = found.u_params;
    else given_params(tu, network.v_curves.size(), n, 0);
    if (tv.empty()) tv = found.v_params;
    else given_params(tv, network.u_curves.size(), n, 1);
  } else {
    given_params(tu, network.v_curves.size(), n, 0);
    given_params(tv, network.u_curves.size(), n, 1);
  }
  check_params(tu, "u_params", n.closed[0]);
  check_params(tv, "v_params", n.closed[1]);
  auto t = std::make_shared<detail::BlendedTerms>();
  t->c = PointGrid({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const Vec3 a = U[j].point(tu[i]), b = V[i].point(tv[j]);
      const double gap = distance(a, b);
      if (gap > tol)
        fail(errc::network_gap, "u_curves[", j, "] and v_curves[", i, "] miss each other at node (", i, ", ", j,
             ") = (u ", tu[i], ", v ", tv[j], "): u_curves[", j, "] gives ", a, ", v_curves[", i, "] gives ", b,
             ", gap ", gap, " (tolerance ", tol, ")");
      t->c(i, j) = -0.5 * (a + b);
    }
  t->f = cardinals(tu, options.method, n.closed[0]);
  t->a = V;
  t->g = cardinals(tv, options.method, n.closed[1]);
  t->b = U;
  t->notes = std::move(n.notes);
  if (network.u_params.empty() || network.v_params.empty())
    t->notes.push_back("crossing parameters found from the curves");
  return BlendedSurface(std::move(t));
}

}  // namespace interpatch
