#include "interpatch/network.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <string>

#include "blends/blended_terms.hpp"
#include "base/data_scale.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "constructions/network/network_curves.hpp"

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

detail::DataScale scale_of(const CurveNetwork& n) {
  detail::DataScale s;
  for (const auto* list : {&n.u_curves, &n.v_curves})
    for (const auto& c : *list) s.add(c.control_points());
  return s;
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

// How far apart two curves over [0, 1] are at 129 parameters, b taken either way
// round: 0 for a repeated curve, drawn in either direction.
double curve_distance(const BSplineCurve& a, const BSplineCurve& b) {
  double d = 0, r = 0;
  for (double t : linspace(0, 1, 129)) {
    d = std::max(d, distance(a.point(t), b.point(t)));
    r = std::max(r, distance(a.point(t), b.point(1 - t)));
  }
  return std::min(d, r);
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
  std::array<std::vector<BSplineCurve>, 2> input;  // the curves as given, over [0, 1]
  std::array<std::vector<bool>, 2> reshaped;       // along[a][j] is not input[a][j] (closed with a C0 seam)
  double tol = 0;       // how far curves may miss each other (NetworkOptions::tolerance)
  double diagonal = 0;  // of the control points' bounding box
  double rounding = 0;  // DataScale::rounding
  double strict = 0;    // 1e-7 of the diagonal, or the rounding floor where that is larger
  // How near curves must be, how near a fit: the tolerance, never below the rounding.
  [[nodiscard]] double fit() const { return std::max(std::min(tol, strict), rounding); }
  std::vector<std::string> notes;
  std::function<std::string(int, std::size_t)> curve_name;
  [[nodiscard]] std::string name(int family, std::size_t index) const {
    return curve_name ? curve_name(family, index) : detail::cat(curves_name(family), "[", index, "]");
  }
};

Prepared prepare(const CurveNetwork& n, const NetworkOptions& o) {
  check_counts(n);
  Prepared r;
  const detail::DataScale scale = scale_of(n);
  r.diagonal = scale.diagonal();
  r.rounding = scale.rounding();
  r.strict = scale.strict();
  const double tol = r.tol = o.tolerance ? *o.tolerance : r.strict;
  r.closed = n.periodic;
  r.curve_name = o.curve_name;
  r.input = {on_unit(n.u_curves), on_unit(n.v_curves)};
  r.along = r.input;
  r.reshaped = {std::vector<bool>(r.input[0].size(), false), std::vector<bool>(r.input[1].size(), false)};
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
        fail(errc::network_gap, r.name(a, j), " is not closed, and the network is closed in ",
             a == 0 ? "u" : "v", ": its ends ", along[j].point(0.0), " and ", along[j].point(1.0), " are ",
             distance(along[j].point(0.0), along[j].point(1.0)), " apart (tolerance ", tol, ")");
      along[j] = closed_form(along[j]);
      r.reshaped[static_cast<std::size_t>(a)][j] = true;
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
      fail(errc::network_gap, r.name(1 - a, across.size() - 1), " is at ", a == 0 ? "u" : "v", " = 1 (",
           params_name(a), "[", across.size() - 1, "]), where a network closed in ", a == 0 ? "u" : "v", " has ",
           r.name(1 - a, 0), " again, but the two are up to ", apart, " apart (tolerance ", tol,
           "): give parameters below 1, or repeat ", r.name(1 - a, 0), " there");
    across.pop_back();
    r.closing[static_cast<std::size_t>(a)] = true;
    r.notes.push_back(detail::cat("the last of the ", curves_name(1 - a), " repeats the first: the closing curve, left out"));
    if (across.size() < 2)
      fail(errc::too_few_points, "a curve network closed in ", a == 0 ? "u" : "v", " needs at least 2 distinct ",
           curves_name(1 - a), ", got 1 and the closing curve");
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

// ---------------------------------------------------------------- as drawn

// What the crossings tell: every pair's closest points, the order of each family,
// the curves that run against theirs, and the common parameters. Family 0 is the
// u-curves, 1 the v-curves; indices are those of the prepared curves (the given ones,
// a closing curve left out).
struct Arrangement {
  std::vector<std::vector<detail::Crossing>> X;  // X[j][i]: u-curve j and v-curve i
  std::array<std::vector<std::size_t>, 2> order;  // order[a][k]: the curve of family a at position k
  std::array<std::vector<bool>, 2> reversed, degenerate;
  std::array<std::vector<double>, 2> params;  // params[a][k]: where the surface has the curve at position k
  // to[a][j]: curve j's own parameters at its crossings, by position of the other family
  // (closed: unwrapped, from the seam's on; a curve against its family: decreasing).
  std::array<std::vector<std::vector<double>>, 2> to;
  double keep = 0;  // how close a curve must pass its crossings at the common parameters to be kept
  double snap = 0;  // how near its end a crossing must be to be at its end: min(tolerance, 1e-7 diagonal)
};

// Own parameter on curve j of family a where it crosses curve i of the other family.
double crossing_param(const Arrangement& r, int a, std::size_t j, std::size_t i) {
  return a == 0 ? r.X[j][i].s : r.X[i][j].t;
}

// A curve shrunk to a point (a pole): every control point within tol of the first.
bool is_point(const BSplineCurve& c, double tol) {
  return std::all_of(c.control_points().begin(), c.control_points().end(),
                     [&](const Vec3& p) { return distance(p, c.control_points().front()) <= tol; });
}

std::string list(const std::vector<std::size_t>& v) {
  std::string s;
  for (std::size_t x : v) s += detail::cat(s.empty() ? "" : ", ", x);
  return s;
}

// Orders the family across a's curves (1 − a) by where they cross the curves of
// family a, turns those of family a that run the other way, and finds the common
// parameters of family 1 − a (or takes the given ones).
void arrange(const Prepared& n, Arrangement& r, int a, const std::vector<double>& given) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const int b = 1 - a;
  const auto& along = n.along[az];
  const std::size_t na = along.size(), nb = n.along[bz].size();
  const bool closed = n.closed[az];
  const auto& deg = r.degenerate[az];
  std::vector<std::size_t> live;
  for (std::size_t j = 0; j < na; ++j)
    if (!deg[j]) live.push_back(j);
  if (live.empty())
    fail(errc::network_gap, "every one of the ", curves_name(a), " is a single point: the network has no extent in ",
         a == 0 ? "u" : "v");
  const std::size_t ref = live.front();
  // The order in which curve j meets the other family (closed: from the seam curve, 0, on).
  const auto order_on = [&](std::size_t j) {
    std::vector<double> key(nb);
    for (std::size_t i = 0; i < nb; ++i) {
      const double x = crossing_param(r, a, j, i);
      key[i] = closed ? wrap_unit(x - crossing_param(r, a, j, 0)) : x;
    }
    std::vector<std::size_t> o(nb);
    std::iota(o.begin(), o.end(), 0);
    std::stable_sort(o.begin(), o.end(), [&](std::size_t x, std::size_t y) { return key[x] < key[y]; });
    for (std::size_t k = 0; k + 1 < nb; ++k)
      if (!(key[o[k]] + 1e-12 < key[o[k + 1]]))
        fail(errc::network_order, n.name(b, std::min(o[k], o[k + 1])), " and ", n.name(b, std::max(o[k], o[k + 1])),
             " cross ", n.name(a, j), " at the same point ",
             a == 0 ? r.X[j][o[k]].a : r.X[o[k]][j].b,
             ": curves of one family must not meet");
    return o;
  };
  const auto turned = [&](std::vector<std::size_t> o) {
    if (closed) std::reverse(o.begin() + 1, o.end());
    else std::reverse(o.begin(), o.end());
    return o;
  };
  std::vector<std::size_t> R(nb);
  std::iota(R.begin(), R.end(), 0);
  if (given.empty()) R = order_on(ref);
  auto& rev = r.reversed[az];
  rev.assign(na, false);
  std::size_t against = 0;
  for (std::size_t j : live) {
    const auto o = order_on(j);
    if (o == R) continue;
    if (o != turned(R))
      fail(errc::network_order, n.name(a, j), " crosses the ", curves_name(b), " in the order ", list(o), ", ",
           given.empty() ? n.name(a, ref) : std::string(params_name(a)), given.empty() ? " in the order " : " put them in the order ",
           list(R), ": no order of the ", curves_name(b), " and direction of the ", curves_name(a), " agrees with both");
    rev[j] = true;
    ++against;
  }
  if (given.empty() && 2 * against > live.size()) {  // most run the other way: that is the family's direction
    R = turned(R);
    for (std::size_t j : live) rev[j] = !rev[j];
  }
  r.order[bz] = R;
  // Each curve's crossings in its family's direction (σ: the own parameter turned
  // when the curve runs against it), the ends (open) or seam (closed) snapped to
  // the curve's own when it passes there within `keep`.
  auto& to = r.to[az];
  to.assign(na, {});
  std::vector<std::vector<double>> lam(na);  // per curve: normalized crossing positions
  for (std::size_t j = 0; j < na; ++j) {
    std::vector<double> x(nb);
    for (std::size_t k = 0; k < nb; ++k) x[k] = crossing_param(r, a, j, R[k]);
    if (deg[j]) {
      to[j] = x;
      continue;
    }
    const bool rj = rev[j];
    const auto sigma = [&](double t) { return rj ? (closed ? -t : 1 - t) : t; };
    const BSplineCurve& c = along[j];
    if (!closed) {
      double first = sigma(x.front()), last = sigma(x.back());
      // A crossing this near the curve's end is at its end: the search stops a rounding
      // short of an end that lies on the other curve.
      if (distance(c.point(rj ? 1.0 : 0.0), c.point(x.front())) <= r.snap) first = 0;
      if (distance(c.point(rj ? 0.0 : 1.0), c.point(x.back())) <= r.snap) last = 1;
      lam[j].resize(nb);
      for (std::size_t k = 0; k < nb; ++k) lam[j][k] = (sigma(x[k]) - first) / (last - first);
      to[j] = x;
      to[j].front() = sigma(first);  // σ is its own inverse
      to[j].back() = sigma(last);
    } else {
      const double shift = distance(c.point(0.0), c.point(x.front())) <= r.keep ? 0.0 : sigma(x.front());
      lam[j].resize(nb);
      for (std::size_t k = 0; k < nb; ++k) lam[j][k] = sigma(x[k]) - shift;
      to[j].resize(nb + 1);
      for (std::size_t k = 0; k < nb; ++k) to[j][k] = sigma(shift + (k == 0 ? 0.0 : wrap_unit(sigma(x[k]) - shift)));
      to[j][nb] = sigma(shift + 1.0);
    }
  }
  auto& p = r.params[bz];
  if (!given.empty()) {
    p = given;
    return;
  }
  p.assign(nb, 0.0);
  const auto count = static_cast<double>(live.size());
  for (std::size_t k = 0; k < nb; ++k)
    for (std::size_t j : live) {
      double x = lam[j][k];
      if (closed) x += std::round(lam[ref][k] - x);  // within half a period of the first curve's
      p[k] += x / count;
    }
  if (closed) {
    for (double& x : p) x = wrap_unit(x);
    p.front() = 0.0;  // where the closed curves start
  } else {
    p.front() = 0.0;  // the end curves bound the network
    p.back() = 1.0;
  }
  for (std::size_t k = 1; k < nb; ++k)
    if (!(p[k] > p[k - 1]))
      fail(errc::non_increasing, n.name(b, R[k - 1]), " and ", n.name(b, R[k]), " cross the ", curves_name(a),
           " at parameters ", p[k - 1], " and ", p[k], " on average, which do not increase");
}

Arrangement arrangement(const Prepared& n, const CurveNetwork& net) {
  Arrangement r;
  const double strict = n.fit();
  r.keep = 1e-3 * strict;
  r.snap = strict;
  const auto& U = n.along[0];
  const auto& V = n.along[1];
  for (std::size_t a = 0; a < 2; ++a) {
    r.degenerate[a].clear();
    for (const auto& c : n.along[a]) r.degenerate[a].push_back(is_point(c, n.tol));
  }
  std::vector<double> gu = net.u_params, gv = net.v_params;
  if (!gu.empty()) given_params(gu, net.v_curves.size(), n, 0);
  if (!gv.empty()) given_params(gv, net.u_curves.size(), n, 1);
  if (!gu.empty()) check_params(gu, "u_params", n.closed[0]);
  if (!gv.empty()) check_params(gv, "v_params", n.closed[1]);
  // Both families' parameters given and every pair of curves meeting there: the
  // network as it was given, every curve kept, nothing searched.
  if (!gu.empty() && !gv.empty()) {
    std::vector<std::vector<detail::Crossing>> X(U.size(), std::vector<detail::Crossing>(V.size()));
    bool meet = true;
    for (std::size_t j = 0; j < U.size() && meet; ++j)
      for (std::size_t i = 0; i < V.size() && meet; ++i) {
        auto& x = X[j][i];
        x = {gu[i], gv[j], U[j].point(gu[i]), V[i].point(gv[j]), 0};
        x.gap = distance(x.a, x.b);
        meet = x.gap <= n.tol;
      }
    if (meet) {
      r.X = std::move(X);
      for (std::size_t a = 0; a < 2; ++a) {
        const std::size_t count = n.along[a].size();
        r.order[a].resize(count);
        std::iota(r.order[a].begin(), r.order[a].end(), 0);
        r.reversed[a].assign(count, false);
        std::vector<double> at = a == 0 ? gv : gu;  // family a lies at these
        r.params[a] = at;
        std::vector<double> along = a == 0 ? gu : gv;  // and crosses the other there
        if (n.closed[a]) along.push_back(1.0);
        r.to[a].assign(count, along);
      }
      return r;
    }
  }
  std::vector<detail::CurveSamples> su, sv;
  for (const auto& c : U) su.emplace_back(c);
  for (const auto& c : V) sv.emplace_back(c);
  r.X.assign(U.size(), std::vector<detail::Crossing>(V.size()));
  for (std::size_t j = 0; j < U.size(); ++j)
    for (std::size_t i = 0; i < V.size(); ++i) {
      auto x = detail::closest_points(U[j], V[i], n.closed[0], n.closed[1], n.tol, su[j], sv[i]);
      // Every place they meet: a u-curve crosses each v-curve once; and where the
      // search above settled on a near miss, a crossing it passed by.
      const auto all = detail::crossings(U[j], V[i], n.closed[0], n.closed[1], n.tol, su[j], sv[i]);
      if (all.size() > 1) {
        std::string where;
        for (std::size_t k = 0; k < all.size() && k < 4; ++k) where += detail::cat(k ? ", " : "", all[k].a);
        fail(errc::network_order, n.name(0, j), " and ", n.name(1, i), " cross ", all.size(), " times (at ", where,
             all.size() > 4 ? ", ..." : "", "): each curve of a network crosses each curve of the other family once");
      }
      if (!(x.gap <= n.tol) && !all.empty()) x = all.front();
      if (!(x.gap <= n.tol)) {
        const auto own = [](const BSplineCurve& given, double t) {
          const auto [lo, hi] = given.domain();
          return lo + t * (hi - lo);
        };
        fail(errc::network_gap, n.name(0, j), " and ", n.name(1, i), " do not meet: they come closest at ", x.a,
             " (t = ", own(net.u_curves[j], x.s), " on ", n.name(0, j), ") and ", x.b, " (t = ", own(net.v_curves[i], x.t), " on ", n.name(1, i),
             "), ", x.gap, " apart (tolerance ", n.tol, ")");
      }
      r.X[j][i] = x;
    }
  arrange(n, r, 0, gu);  // orders the v-curves, turns u-curves, finds u_params
  arrange(n, r, 1, gv);
  return r;
}

// Σ_k g_k φ_k(t) for the cardinal functions φ_k (B-splines on one knot vector) as one curve.
BSplineCurve combination(const std::vector<detail::Scalar>& phi, const std::vector<Vec3>& g) {
  const BSplineCurve& first = *phi.front().spline;
  std::vector<Vec3> cp(first.control_points().size());
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const auto& c = phi[k].spline->control_points();
    INTERPATCH_ASSERT(c.size() == cp.size());
    for (std::size_t q = 0; q < cp.size(); ++q) cp[q] += c[q].x * g[k];
  }
  return BSplineCurve(first.knots(), std::move(cp));
}

// Which curves of family a are kept as they are and which re-expressed, with their
// maps (over [0, 1] both ways) in the report; the points each will have at the
// common parameters of the other family: node[k][i] for the curve at position k.
struct Plan {
  std::vector<bool> keep;  // by position
  std::vector<std::vector<Vec3>> node;
};

Plan plan(const Prepared& n, const Arrangement& r, int a, std::vector<NetworkCurveReport>& report) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const auto& along = n.along[az];
  const bool closed = n.closed[az];
  std::vector<double> at = r.params[bz];
  if (closed) at.push_back(1.0);
  Plan out;
  for (std::size_t k = 0; k < along.size(); ++k) {
    const std::size_t j = r.order[az][k];
    NetworkCurveReport& rep = report[j];
    rep.position = k;
    rep.reversed = r.reversed[az][j];
    rep.degenerate = r.degenerate[az][j];
    const auto& to = r.to[az][j];
    bool keep = !rep.reversed;
    for (std::size_t q = 0; keep && q < at.size() && !rep.degenerate; ++q)
      keep = distance(along[j].point(at[q]), along[j].point(to[q])) <= r.keep;
    rep.reexpressed = !keep;
    rep.map = keep ? detail::monotone_map({0.0, 1.0}, {0.0, 1.0}, false) : detail::monotone_map(at, to, closed);
    out.keep.push_back(keep);
    // A re-expressed curve interpolates C(map(u_i)) = C(to_i) at u_i.
    std::vector<Vec3> pts;
    for (std::size_t i = 0; i < r.params[bz].size(); ++i) pts.push_back(along[j].point(keep ? at[i] : to[i]));
    out.node.push_back(std::move(pts));
  }
  return out;
}

// The curves of family a in position order, as planned, and how far the surface is
// from each given curve: S(u, v_j) = D_j(u) + Σ_i g_i φ_i(u) along u-curve j's line,
// g_i = ½ (V_i(v_j) − D_j(u_i)), since ψ_l(v_j) = δ_lj (likewise for v-curves).
std::vector<BSplineCurve> place_curves(const Prepared& n, const Arrangement& r, int a, const Plan& mine,
                                       const Plan& other, const std::vector<detail::Scalar>& phi,
                                       std::vector<NetworkCurveReport>& report) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const auto& along = n.along[az];
  const bool closed = n.closed[az];
  const double target = 0.5 * n.fit();
  std::vector<std::optional<BSplineCurve>> out(along.size());
  std::vector<std::size_t> redo;  // positions of the curves to re-express
  std::vector<detail::FitJob> jobs;
  std::vector<BSplineCurve> G;
  G.reserve(along.size());
  for (std::size_t k = 0; k < along.size(); ++k) {
    std::vector<Vec3> g(other.node.size());
    for (std::size_t i = 0; i < g.size(); ++i) g[i] = 0.5 * (other.node[i][k] - mine.node[k][i]);
    G.push_back(combination(phi, g));
  }
  // How far each kept curve's line of the surface is from the given curve: a few
  // points per knot interval, the curves shared between the threads.
  detail::parallel_for(along.size(), along.size() > 1, detail::Share::one_by_one, [&](std::size_t k) {
    if (!mine.keep[k]) return;
    const std::size_t j = r.order[az][k];
    const BSplineCurve& given = n.input[az][j];
    const std::vector<double> own = detail::check_params(along[j].knots());
    const std::vector<Vec3> line = detail::points_at(along[j], own), g = detail::points_at(G[k], own);
    std::vector<double> at = own;
    if (closed)
      for (double& u : at) u -= std::floor(u);
    // A curve taken as given is its line's curve: its points are those already
    // found, but where a closed curve's parameter wrapped.
    std::vector<Vec3> want;
    if (n.reshaped[az][j]) {
      want = detail::points_at(given, at);
    } else {
      want = line;
      for (std::size_t i = 0; i < at.size(); ++i)
        if (at[i] != own[i]) want[i] = given.point(at[i]);
    }
    double d = 0;
    for (std::size_t i = 0; i < at.size(); ++i) d = std::max(d, distance(line[i] + g[i], want[i]));
    report[j].distance = d;
  });
  for (std::size_t k = 0; k < along.size(); ++k) {
    const std::size_t j = r.order[az][k];
    const BSplineCurve& given = n.input[az][j];
    if (mine.keep[k]) {
      out[k] = along[j];
      continue;
    }
    redo.push_back(k);
    jobs.push_back({&along[j], n.reshaped[az][j] ? &given : nullptr, &G[k], report[j].map});
  }
  if (!redo.empty()) {
    std::vector<detail::Refit> fits;
    try {
      fits = detail::refit(jobs, r.params[bz], closed, target);
    } catch (const detail::RefitShortfall& e) {
      fail(errc::tolerance_not_met, n.name(a, r.order[az][redo[e.job()]]), ": ", e.what());
    }
    for (std::size_t q = 0; q < redo.size(); ++q) {
      auto& rep = report[r.order[az][redo[q]]];
      rep.fit_error = fits[q].error;
      rep.distance = fits[q].distance;
      out[redo[q]] = std::move(fits[q].curve);
    }
  }
  std::vector<BSplineCurve> placed;
  placed.reserve(out.size());
  for (auto& c : out) placed.push_back(std::move(*c));
  return placed;
}

struct Built {
  std::optional<BlendedSurface> surface;
  NetworkReport report;
};

// The construction; with `fit` false only the parameters of the report.
Built build(const CurveNetwork& network, const NetworkOptions& options, bool fit) {
  Prepared n = prepare(network, options);
  Arrangement r = arrangement(n, network);
  NetworkReport rep;
  rep.tolerance = n.tol;
  rep.diagonal = n.diagonal;
  rep.strict = n.strict;
  rep.u_curves.resize(network.u_curves.size());
  rep.v_curves.resize(network.v_curves.size());
  // Common parameters per curve as given (a closing curve: 1).
  for (int a = 0; a < 2; ++a) {
    const auto az = static_cast<std::size_t>(a);
    auto& out = a == 0 ? rep.v_params : rep.u_params;  // the parameters of family a
    out.assign((a == 0 ? network.u_curves : network.v_curves).size(), 1.0);
    for (std::size_t k = 0; k < r.order[az].size(); ++k) out[r.order[az][k]] = r.params[az][k];
  }
  const bool found = network.u_params.empty() || network.v_params.empty();
  for (std::size_t j = 0; j < r.X.size(); ++j)
    for (std::size_t i = 0; i < r.X[j].size(); ++i) {
      const double g = r.X[j][i].gap;
      rep.u_curves[j].max_gap = std::max(rep.u_curves[j].max_gap, g);
      rep.v_curves[i].max_gap = std::max(rep.v_curves[i].max_gap, g);
      if (g > rep.max_gap) {
        rep.max_gap = g;
        rep.max_gap_at = {j, i};
      }
    }
  if (!fit) return {std::nullopt, std::move(rep)};
  const auto& tu = r.params[1];  // u of the v-curves, by position
  const auto& tv = r.params[0];
  auto t = std::make_shared<detail::BlendedTerms>();
  t->f = cardinals(tu, options.method, n.closed[0]);
  t->g = cardinals(tv, options.method, n.closed[1]);
  const Plan pu = plan(n, r, 0, rep.u_curves), pv = plan(n, r, 1, rep.v_curves);
  std::vector<BSplineCurve> U = place_curves(n, r, 0, pu, pv, t->f, rep.u_curves);
  std::vector<BSplineCurve> V = place_curves(n, r, 1, pv, pu, t->g, rep.v_curves);
  const std::size_t nu = V.size(), nv = U.size();
  t->c = PointGrid({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) t->c(i, j) = -0.5 * (U[j].point(tu[i]) + V[i].point(tv[j]));
  // Own parameters of the crossings, in the given curves' domains, and the maps.
  for (int a = 0; a < 2; ++a) {
    const auto az = static_cast<std::size_t>(a);
    const auto& given = a == 0 ? network.u_curves : network.v_curves;
    auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    for (std::size_t j = 0; j < n.along[az].size(); ++j) {
      const auto [lo, hi] = given[j].domain();
      auto& c = reports[j];
      c.crossings.clear();
      for (std::size_t k = 0; k < r.order[1 - az].size(); ++k)
        c.crossings.push_back(lo + crossing_param(r, a, j, r.order[1 - az][k]) * (hi - lo));
      for (double& x : c.map.to) x = lo + x * (hi - lo);
      for (double& x : c.map.slope) x *= hi - lo;
      c.map.start = lo;
      c.map.period = n.closed[az] ? hi - lo : 0.0;
    }
  }
  t->a = std::move(V);
  t->b = std::move(U);
  // Each curve against the finished surface: where curves of a family lie close
  // together their cardinal functions reach about 1/the gap, and spread what the
  // crossings' mismatch left over that far onto the other curves' lines.
  const BlendedSurface finished(t);
  for (int a = 0; a < 2; ++a) {
    const auto az = static_cast<std::size_t>(a);
    const auto& given = a == 0 ? network.u_curves : network.v_curves;
    auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    for (std::size_t k = 0; k < r.order[az].size(); ++k) {
      const std::size_t j = r.order[az][k];
      const double at = r.params[az][k];
      double d = 0;
      for (double x : linspace(0, 1, 129))
        d = std::max(d, distance(a == 0 ? finished.point(x, at) : finished.point(at, x), given[j].point(reports[j].map(x))));
      reports[j].distance = std::max(reports[j].distance, d);
    }
  }
  const double strict = n.strict;
  std::vector<std::string> far;
  for (int a = 0; a < 2; ++a) {
    const auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    for (std::size_t j = 0; j < n.along[static_cast<std::size_t>(a)].size(); ++j)
      if (reports[j].distance > strict) far.push_back(detail::cat(n.name(a, j), " by ", reports[j].distance));
  }
  // The closing curves: the seam curve's line against each, on the finished surface.
  for (int a = 0; a < 2; ++a) {
    if (!n.closing[static_cast<std::size_t>(1 - a)]) continue;
    auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    const auto& given = a == 0 ? network.u_curves : network.v_curves;
    NetworkCurveReport& c = reports.back();
    const std::size_t seam = r.order[static_cast<std::size_t>(a)].front();
    c = reports[seam];
    c.closing = true;
    c.position = n.along[static_cast<std::size_t>(a)].size();
    // Plain variables, not structured bindings: the lambda below captures them.
    const double lo = given.back().domain().first, hi = given.back().domain().second;
    const double slo = given[seam].domain().first, shi = given[seam].domain().second;
    // Drawn the other way round from the seam curve: its parameter runs back.
    const auto& unit = n.input[static_cast<std::size_t>(a)];
    double ahead = 0, back = 0;
    for (double x : linspace(0, 1, 129)) {
      ahead = std::max(ahead, distance(unit[seam].point(x), unit.back().point(x)));
      back = std::max(back, distance(unit[seam].point(x), unit.back().point(1 - x)));
    }
    const bool turn = back < ahead;
    if (turn) c.reversed = !c.reversed;
    const auto move = [&](double x) {
      const double f = (x - slo) / (shi - slo);
      return lo + (turn ? 1 - f : f) * (hi - lo);
    };
    for (double& x : c.map.to) x = move(x);
    for (double& x : c.map.slope) x *= (turn ? -1 : 1) * (hi - lo) / (shi - slo);
    for (double& x : c.crossings) x = move(x);
    c.map.start = lo;
    if (c.map.period > 0) c.map.period = hi - lo;
    double d = 0;
    const BlendedSurface probe(t);
    for (double x : linspace(0, 1, 129)) {
      const Vec3 s = a == 0 ? probe.point(x, 1.0) : probe.point(1.0, x);
      d = std::max(d, distance(s, given.back().point(c.map(x))));
    }
    c.distance = d;
    if (d > strict) far.push_back(detail::cat(n.name(a, given.size() - 1), " by ", d));
  }
  t->notes = std::move(n.notes);
  if (found) t->notes.push_back("crossing parameters found from the curves");
  for (int a = 0; a < 2; ++a) {
    const auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    std::vector<std::size_t> re, turned;
    double worst = 0;
    bool sorted = true;
    for (std::size_t j = 0; j < reports.size(); ++j) {
      if (reports[j].reexpressed) {
        re.push_back(j);
        worst = std::max(worst, reports[j].fit_error);
      }
      if (reports[j].reversed) turned.push_back(j);
      if (!reports[j].closing && reports[j].position != j) sorted = false;
    }
    if (!sorted) {
      std::vector<std::size_t> o(r.order[static_cast<std::size_t>(a)]);
      t->notes.push_back(detail::cat(curves_name(a), " sorted into the order ", list(o)));
    }
    if (!turned.empty()) t->notes.push_back(detail::cat(curves_name(a), " ", list(turned), " turned round to run with the others"));
    if (!re.empty())
      t->notes.push_back(detail::cat(curves_name(a), " ", list(re), " re-expressed with their crossings at the common "
                                     "parameters, within ", worst, " of the curves given"));
  }
  if (!far.empty()) {
    std::string s;
    for (const auto& f : far) s += (s.empty() ? "" : ", ") + f;
    t->notes.push_back(detail::cat("the surface departs from ", s, ": more than ",
                                   n.strict > 1e-7 * n.diagonal ? "the rounding of its coordinates" : "1e-7 of the diagonal",
                                   " (", strict, "); the tolerance ", n.tol, " lets curves miss each other by that much"));
  }
  return {BlendedSurface(std::move(t)), std::move(rep)};
}

}  // namespace

NetworkParameters network_parameters(const CurveNetwork& network, const NetworkOptions& options) {
  auto r = build(network, options, false).report;
  return {std::move(r.u_params), std::move(r.v_params)};
}

NetworkSurface network_surface(const CurveNetwork& network, const NetworkOptions& options) {
  auto b = build(network, options, true);
  return {std::move(*b.surface), std::move(b.report)};
}

BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options) {
  return std::move(*build(network, options, true).surface);
}

}  // namespace interpatch
