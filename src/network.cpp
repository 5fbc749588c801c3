#include "interpatch/network.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "blended_terms.hpp"
#include "detail/text.hpp"
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

// Closest points of two curves over [0, 1]: a coarse search, then Gauss–Newton on
// F(s, t) = U(s) − V(t).
std::pair<double, double> closest(const BSplineCurve& U, const BSplineCurve& V) {
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
    const double ns = std::clamp(s + ds, 0.0, 1.0), nt = std::clamp(t + dt, 0.0, 1.0);
    const bool done = std::abs(ns - s) < 1e-15 && std::abs(nt - t) < 1e-15;
    s = ns;
    t = nt;
    if (done) break;
  }
  return {s, t};
}

void check_params(const std::vector<double>& p, const char* name) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!std::isfinite(p[i])) fail(errc::not_finite, name, "[", i, "] is ", p[i]);
    if (i > 0 && !(p[i] > p[i - 1]))
      fail(errc::non_increasing, name, "[", i, "] = ", p[i], " is not greater than ", name, "[", i - 1, "] = ", p[i - 1]);
  }
  if (p.front() != 0.0 || p.back() != 1.0)
    fail(errc::out_of_domain, name, " must run from 0 to 1, got ", p.front(), " to ", p.back());
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

// Cardinal functions φ_i(t_k) = δ_ik over the node parameters t.
std::vector<detail::Scalar> cardinals(const std::vector<double>& t, NetworkMethod method) {
  const std::size_t n = t.size();
  std::vector<detail::Scalar> out;
  out.reserve(n);
  if (method == NetworkMethod::coons_linear) {
    std::vector<double> k{t.front()};
    k.insert(k.end(), t.begin(), t.end());
    k.push_back(t.back());
    const KnotVector kv(1, k);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> c(n, 0.0);
      c[i] = 1.0;
      out.push_back(detail::scalar(kv, c));
    }
  } else if (method == NetworkMethod::coons_hermite) {
    // α0/α1 of each cell in Bézier form: the two control coefficients next to node
    // i are 1, all others 0; double interior knots keep the pieces C1 (f' = 0 at nodes).
    std::vector<double> k(4, t.front());
    for (std::size_t i = 1; i + 1 < n; ++i) k.insert(k.end(), 2, t[i]);
    k.insert(k.end(), 4, t.back());
    const KnotVector kv(3, k);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> c(2 * n, 0.0);
      c[2 * i] = c[2 * i + 1] = 1.0;
      out.push_back(detail::scalar(kv, c));
    }
  } else {
    CurveInterpolationOptions o;
    o.degree = std::min<int>(3, static_cast<int>(n) - 1);
    o.params = t;
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<Vec3> e(n);
      e[i] = {1, 0, 0};
      out.push_back(interpolate_curve(e, o).curve);
    }
  }
  return out;
}

}  // namespace

NetworkParameters network_parameters(const CurveNetwork& network) {
  check_counts(network);
  const auto U = on_unit(network.u_curves), V = on_unit(network.v_curves);
  const std::size_t nu = V.size(), nv = U.size();  // nodes along u, along v
  NetworkParameters r{std::vector<double>(nu, 0.0), std::vector<double>(nv, 0.0)};
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const auto [s, t] = closest(U[j], V[i]);
      r.u_params[i] += s / static_cast<double>(nv);
      r.v_params[j] += t / static_cast<double>(nu);
    }
  r.u_params.front() = r.v_params.front() = 0.0;  // the end curves bound the network
  r.u_params.back() = r.v_params.back() = 1.0;
  for (const auto* p : {&r.u_params, &r.v_params})
    for (std::size_t i = 1; i < p->size(); ++i)
      if (!((*p)[i] > (*p)[i - 1]))
        fail(errc::non_increasing, "the ", p == &r.u_params ? "v_curves" : "u_curves", " ", i - 1, " and ", i,
             " cross the other curves at parameters ", (*p)[i - 1], " and ", (*p)[i],
             ", which do not increase: the curves are not in order");
  return r;
}

BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options) {
  check_counts(network);
  const auto U = on_unit(network.u_curves), V = on_unit(network.v_curves);
  const std::size_t nu = V.size(), nv = U.size();
  std::vector<double> tu = network.u_params, tv = network.v_params;
  if (tu.empty() || tv.empty()) {
    const auto found = network_parameters(network);
    if (tu.empty()) tu = found.u_params;
    if (tv.empty()) tv = found.v_params;
  }
  if (tu.size() != nu)
    fail(errc::size_mismatch, nu, " v_curves need ", nu, " u_params, got ", tu.size());
  if (tv.size() != nv)
    fail(errc::size_mismatch, nv, " u_curves need ", nv, " v_params, got ", tv.size());
  check_params(tu, "u_params");
  check_params(tv, "v_params");
  const double tol = options.tolerance ? *options.tolerance : 1e-7 * control_diagonal(network);
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
  t->f = cardinals(tu, options.method);
  t->a = V;
  t->g = cardinals(tv, options.method);
  t->b = U;
  if (network.u_params.empty() || network.v_params.empty())
    t->notes.push_back("crossing parameters found from the curves");
  return BlendedSurface(std::move(t));
}

}  // namespace interpatch
