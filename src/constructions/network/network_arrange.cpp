// A network's crossings arranged: where every pair of curves meets, the order of each
// family along the other, the curves that run against theirs, and the common
// parameters of the crossings (found as the average over the curves, or given).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "constructions/network/network_build.hpp"

namespace interpatch::detail {

namespace {

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

// Given crossing parameters of the family across direction a, one per curve given:
// the closing curve's (1) is left out with the curve.
void given_params(std::vector<double>& p, std::size_t curves, const Prepared& n, int a) {
  if (p.size() != curves)
    fail(errc::size_mismatch, curves, " ", curves_name(1 - a), " need ", curves, " ", params_name(a), ", got ", p.size());
  if (n.closing[static_cast<std::size_t>(a)]) p.pop_back();
}

// A curve shrunk to a point (a pole): every control point within tol of the first.
bool is_point(const BSplineCurve& c, double tol) {
  return std::all_of(c.control_points().begin(), c.control_points().end(),
                     [&](const Vec3& p) { return distance(p, c.control_points().front()) <= tol; });
}

// The order in which curve j of family a meets the other family (closed: from the
// seam curve, 0, on).
std::vector<std::size_t> order_on(const Prepared& n, const Arrangement& r, int a, std::size_t j) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const int b = 1 - a;
  const std::size_t nb = n.along[bz].size();
  const bool closed = n.closed[az];
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
}

// The order in which a curve running the other way meets the other family.
std::vector<std::size_t> turned(std::vector<std::size_t> o, bool closed) {
  if (closed) std::reverse(o.begin() + 1, o.end());
  else std::reverse(o.begin(), o.end());
  return o;
}

// Each curve's crossings in its family's direction (σ: the own parameter turned
// when the curve runs against it), the ends (open) or seam (closed) snapped to
// the curve's own when it passes there within `keep`: r.to[a], and returned, per
// curve, the normalized crossing positions (R: the other family's order).
std::vector<std::vector<double>> own_crossings(const Prepared& n, Arrangement& r, int a,
                                               const std::vector<std::size_t>& R) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const auto& along = n.along[az];
  const std::size_t na = along.size(), nb = n.along[bz].size();
  const bool closed = n.closed[az];
  const auto& deg = r.degenerate[az];
  const auto& rev = r.reversed[az];
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
  return lam;
}

// The common parameters of the family across a, by its position: the average of the
// live curves' normalized crossing positions (closed: each within half a period of
// the first curve's), which must increase.
void common_params(const Prepared& n, Arrangement& r, int a, const std::vector<std::size_t>& live,
                   const std::vector<std::vector<double>>& lam) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const int b = 1 - a;
  const std::size_t nb = n.along[bz].size();
  const bool closed = n.closed[az];
  const std::size_t ref = live.front();
  const auto& R = r.order[bz];
  auto& p = r.params[bz];
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

// Orders the family across a's curves (1 − a) by where they cross the curves of
// family a, turns those of family a that run the other way, and finds the common
// parameters of family 1 − a (or takes the given ones).
void arrange(const Prepared& n, Arrangement& r, int a, const std::vector<double>& given) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const int b = 1 - a;
  const std::size_t na = n.along[az].size(), nb = n.along[bz].size();
  const bool closed = n.closed[az];
  const auto& deg = r.degenerate[az];
  std::vector<std::size_t> live;
  for (std::size_t j = 0; j < na; ++j)
    if (!deg[j]) live.push_back(j);
  if (live.empty())
    fail(errc::network_gap, "every one of the ", curves_name(a), " is a single point: the network has no extent in ",
         a == 0 ? "u" : "v");
  const std::size_t ref = live.front();
  std::vector<std::size_t> R(nb);
  std::iota(R.begin(), R.end(), 0);
  if (given.empty()) R = order_on(n, r, a, ref);
  auto& rev = r.reversed[az];
  rev.assign(na, false);
  std::size_t against = 0;
  for (std::size_t j : live) {
    const auto o = order_on(n, r, a, j);
    if (o == R) continue;
    if (o != turned(R, closed))
      fail(errc::network_order, n.name(a, j), " crosses the ", curves_name(b), " in the order ", index_list(o), ", ",
           given.empty() ? n.name(a, ref) : std::string(params_name(a)), given.empty() ? " in the order " : " put them in the order ",
           index_list(R), ": no order of the ", curves_name(b), " and direction of the ", curves_name(a), " agrees with both");
    rev[j] = true;
    ++against;
  }
  if (given.empty() && 2 * against > live.size()) {  // most run the other way: that is the family's direction
    R = turned(R, closed);
    for (std::size_t j : live) rev[j] = !rev[j];
  }
  r.order[bz] = R;
  const std::vector<std::vector<double>> lam = own_crossings(n, r, a, R);
  if (!given.empty()) {
    r.params[bz] = given;
    return;
  }
  common_params(n, r, a, live, lam);
}

}  // namespace

std::string index_list(const std::vector<std::size_t>& v) {
  std::string s;
  for (std::size_t x : v) s += cat(s.empty() ? "" : ", ", x);
  return s;
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
    std::vector<std::vector<Crossing>> X(U.size(), std::vector<Crossing>(V.size()));
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
  std::vector<CurveSamples> su, sv;
  for (const auto& c : U) su.emplace_back(c);
  for (const auto& c : V) sv.emplace_back(c);
  r.X.assign(U.size(), std::vector<Crossing>(V.size()));
  for (std::size_t j = 0; j < U.size(); ++j)
    for (std::size_t i = 0; i < V.size(); ++i) {
      auto x = closest_points(U[j], V[i], n.closed[0], n.closed[1], n.tol, su[j], sv[i]);
      // Every place they meet: a u-curve crosses each v-curve once; and where the
      // search above settled on a near miss, a crossing it passed by.
      const auto all = crossings(U[j], V[i], n.closed[0], n.closed[1], n.tol, su[j], sv[i]);
      if (all.size() > 1) {
        std::string where;
        for (std::size_t k = 0; k < all.size() && k < 4; ++k) where += cat(k ? ", " : "", all[k].a);
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

}  // namespace interpatch::detail
