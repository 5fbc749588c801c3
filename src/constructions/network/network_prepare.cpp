// A curve network prepared for the construction: every curve over [0, 1], the curves
// along a closed direction closed, and a closing curve that repeats the first left out.
#include <cmath>

#include "base/data_scale.hpp"
#include "interpatch/evaluate.hpp"
#include "constructions/network/network_build.hpp"

namespace interpatch::detail {

namespace {

std::vector<BSplineCurve> on_unit(const std::vector<BSplineCurve>& cs) {
  std::vector<BSplineCurve> out;
  out.reserve(cs.size());
  for (const auto& c : cs) out.push_back(unit(c));
  return out;
}

void check_counts(const CurveNetwork& n) {
  if (n.u_curves.size() < 2 || n.v_curves.size() < 2)
    fail(errc::too_few_points, "a curve network needs at least 2 u_curves and 2 v_curves, got ", n.u_curves.size(),
         " and ", n.v_curves.size());
}

DataScale scale_of(const CurveNetwork& n) {
  DataScale s;
  for (const auto* list : {&n.u_curves, &n.v_curves})
    for (const auto& c : *list) s.add(c.control_points());
  return s;
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

}  // namespace

Prepared prepare(const CurveNetwork& n, const NetworkOptions& o) {
  check_counts(n);
  Prepared r;
  const DataScale scale = scale_of(n);
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
      for (std::size_t j : opened) which += cat(which.empty() ? "" : ", ", j);
      r.notes.push_back(cat(curves_name(a), " ", which, ": open curves whose ends meet, closed with a C0 seam"));
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
    r.notes.push_back(cat("the last of the ", curves_name(1 - a), " repeats the first: the closing curve, left out"));
    if (across.size() < 2)
      fail(errc::too_few_points, "a curve network closed in ", a == 0 ? "u" : "v", " needs at least 2 distinct ",
           curves_name(1 - a), ", got 1 and the closing curve");
  }
  return r;
}

}  // namespace interpatch::detail
