#include "interpatch/bspline_curve.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <vector>

#include "linalg/collocation.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"

namespace interpatch {

using detail::fail;
using Homogeneous = std::array<double, 4>;  // homogeneous point (w x, w y, w z, w)

namespace {

std::vector<Homogeneous> homogeneous(const std::vector<Vec3>& cp, const std::vector<double>& w) {
  std::vector<Homogeneous> h(cp.size());
  for (std::size_t i = 0; i < cp.size(); ++i) {
    const double wi = w.empty() ? 1.0 : w[i];
    h[i] = {cp[i].x * wi, cp[i].y * wi, cp[i].z * wi, wi};
  }
  return h;
}

BSplineCurve from_homogeneous(KnotVector k, const std::vector<Homogeneous>& h, bool rational) {
  std::vector<Vec3> cp(h.size());
  std::vector<double> w;
  if (rational) w.resize(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const double wi = rational ? h[i][3] : 1.0;
    cp[i] = {h[i][0] / wi, h[i][1] / wi, h[i][2] / wi};
    if (rational) w[i] = wi;
  }
  return BSplineCurve(std::move(k), std::move(cp), std::move(w));
}

// q ← α q + (1 − α) q1, coordinate by coordinate.
void mix(Vec3& q, const Vec3& q1, double alpha) { q = alpha * q + (1.0 - alpha) * q1; }
void mix(Homogeneous& q, const Homogeneous& q1, double alpha) {
  for (std::size_t c = 0; c < 4; ++c) q[c] = alpha * q[c] + (1.0 - alpha) * q1[c];
}

template <class T>
struct Refined {
  std::vector<double> knots;
  std::vector<T> points;
};

// Every knot of X (sorted, inside the open domain, multiplicities within the degree)
// inserted in one pass (The NURBS Book A5.4, with the erratum U[i-p+l] for
// U[i-l+1]): from the last new knot down, each old point is moved once and p new
// ones are formed per new knot, so the cost is O(n + p·r), not the O(n·r) of r
// single insertions. Points are Vec3 (non-rational curves) or homogeneous.
template <class T>
Refined<T> refine(const KnotVector& knots, const std::vector<T>& P, const std::vector<double>& X) {
  const auto& U = knots.values();
  const int p = knots.degree();
  const int n = knots.count() - 1, m = n + p + 1, r = static_cast<int>(X.size()) - 1;
  const int a = knots.find_span(X.front()), b = knots.find_span(X.back()) + 1;
  Refined<T> out{std::vector<double>(U.size() + X.size()), std::vector<T>(P.size() + X.size())};
  auto& Q = out.points;
  auto& V = out.knots;
  auto at = [](auto& v, int i) -> auto& { return v[static_cast<std::size_t>(i)]; };
  for (int j = 0; j <= a - p; ++j) at(Q, j) = at(P, j);
  for (int j = b - 1; j <= n; ++j) at(Q, j + r + 1) = at(P, j);
  for (int j = 0; j <= a; ++j) at(V, j) = at(U, j);
  for (int j = b + p; j <= m; ++j) at(V, j + r + 1) = at(U, j);
  int i = b + p - 1, k = b + p + r;
  for (int j = r; j >= 0; --j) {
    const double x = at(X, j);
    for (; x <= at(U, i) && i > a; --k, --i) {
      at(Q, k - p - 1) = at(P, i - p - 1);
      at(V, k) = at(U, i);
    }
    at(Q, k - p - 1) = at(Q, k - p);
    for (int l = 1; l <= p; ++l) {
      const int ind = k - p + l;
      const double num = at(V, k + l) - x;
      if (num == 0.0) at(Q, ind - 1) = at(Q, ind);
      else mix(at(Q, ind - 1), at(Q, ind), num / (at(V, k + l) - at(U, i - p + l)));
    }
    at(V, k) = x;
    --k;
  }
  return out;
}

// The homogeneous point of a curve at t (inside its domain, or wrapped).
Homogeneous homogeneous_at(const KnotVector& k, const std::vector<Vec3>& cp, const std::vector<double>& w, double t) {
  t = k.wrap(t);
  const int p = k.degree(), span = k.find_span(t);
  double N[max_degree + 1];
  k.basis(span, t, N);
  Homogeneous h{0, 0, 0, 0};
  for (int j = 0; j <= p; ++j) {
    const auto idx = static_cast<std::size_t>(k.wrap_index(span - p + j));
    const double c = N[j] * (w.empty() ? 1.0 : w[idx]);
    h[0] += c * cp[idx].x;
    h[1] += c * cp[idx].y;
    h[2] += c * cp[idx].z;
    h[3] += c;
  }
  return h;
}

// The curve in a spline space that contains it (a refinement, an elevation, the
// clamped form of a closed curve): interpolation at the space's Greville abscissae
// recovers its control points exactly, up to rounding of a well-conditioned banded
// (or cyclic banded) solve.
BSplineCurve in_space(KnotVector target, const KnotVector& k, const std::vector<Vec3>& cp, const std::vector<double>& w) {
  const auto g = target.greville();
  std::vector<Homogeneous> rhs(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) rhs[i] = homogeneous_at(k, cp, w, g[i]);
  if (target.periodic()) detail::factor_periodic_collocation(target, g).solve(rhs.data()->data(), 4, 4);
  else detail::factor_collocation(target, g).solve(rhs.data()->data(), 4, 4);
  return from_homogeneous(std::move(target), rhs, !w.empty());
}

void check_domain(const KnotVector& k, double t) {
  if (k.periodic()) {
    if (!std::isfinite(t)) fail(errc::out_of_domain, "parameter ", t, " is not a number on the closed curve");
    return;
  }
  // A parameter a few ulps outside the domain is rounding from the caller's mapping.
  const double a = k.front(), b = k.back();
  const double slack = 1e-12 * (b - a);
  if (!(t >= a - slack && t <= b + slack))
    fail(errc::out_of_domain, "parameter ", t, " is outside the domain [", a, ", ", b, "]");
}

}  // namespace

BSplineCurve::BSplineCurve(KnotVector knots, std::vector<Vec3> control_points, std::vector<double> weights)
    : knots_(std::move(knots)), cp_(std::move(control_points)), w_(std::move(weights)) {
  const auto n = static_cast<std::size_t>(knots_.count());
  if (cp_.size() != n)
    fail(errc::size_mismatch, knots_.size(), " knots of degree ", degree(), " need ", n, " control points, got ",
         cp_.size());
  if (!w_.empty() && w_.size() != n)
    fail(errc::size_mismatch, n, " control points need ", n, " weights, got ", w_.size());
  for (std::size_t i = 0; i < n; ++i)
    if (!is_finite(cp_[i])) fail(errc::not_finite, "control point ", i, " is ", cp_[i]);
  for (std::size_t i = 0; i < w_.size(); ++i) {
    if (!std::isfinite(w_[i])) fail(errc::not_finite, "weight ", i, " is ", w_[i]);
    if (!(w_[i] > 0)) fail(errc::invalid_weight, "weight ", i, " is ", w_[i], "; weights must be positive");
  }
}

Vec3 BSplineCurve::point(double t) const {
  Vec3 out;
  derivatives(t, 0, &out);
  return out;
}

Vec3 BSplineCurve::derivative(double t, int k) const {
  if (k <= max_degree) {
    Vec3 out[max_degree + 1];
    derivatives(t, k, out);
    return out[k];
  }
  return derivatives(t, k)[static_cast<std::size_t>(k)];
}

std::vector<Vec3> BSplineCurve::derivatives(double t, int n) const {
  std::vector<Vec3> out(static_cast<std::size_t>(n) + 1);
  derivatives(t, n, out.data());
  return out;
}

void BSplineCurve::derivatives(double t, int n, Vec3* out) const {
  check_domain(knots_, t);
  t = knots_.wrap(t);
  const int p = degree();
  const int nb = std::min(n, p);
  const int s = knots_.find_span(t);
  double ders[(max_degree + 1) * (max_degree + 1)];
  if (nb == 0) knots_.basis(s, t, ders);  // the same numbers, without the derivative table
  else knots_.basis_derivatives(s, t, nb, ders);
  for (int k = nb + 1; k <= n; ++k) out[k] = {};  // polynomial pieces of degree p
  if (!rational()) {
    for (int k = 0; k <= nb; ++k) {
      Vec3 d{};
      for (int j = 0; j <= p; ++j) d += ders[k * (p + 1) + j] * cp_[static_cast<std::size_t>(knots_.wrap_index(s - p + j))];
      out[k] = d;
    }
    return;
  }
  // Rational: derivatives of A(t) = Σ N w P and w(t) = Σ N w, then the quotient
  // rule C^(k) = (A^(k) − Σ_{i=1..k} C(k,i) w^(i) C^(k−i)) / w (The NURBS Book eq. 4.8).
  Vec3 A[max_degree + 1];
  double W[max_degree + 1] = {};
  for (int k = 0; k <= nb; ++k) {
    Vec3 a{};
    double w = 0;
    for (int j = 0; j <= p; ++j) {
      const auto idx = static_cast<std::size_t>(knots_.wrap_index(s - p + j));
      const double c = ders[k * (p + 1) + j] * w_[idx];
      a += c * cp_[idx];
      w += c;
    }
    A[k] = a;
    W[k] = w;
  }
  for (int k = 0; k <= n; ++k) {
    Vec3 v = k <= nb ? A[k] : Vec3{};
    double binom = 1;  // C(k, i)
    for (int i = 1; i <= k; ++i) {
      binom = binom * (k - i + 1) / i;
      if (i <= nb) v -= binom * W[i] * out[k - i];
    }
    out[k] = v / W[0];
  }
}

BSplineCurve BSplineCurve::inserted(double t, int times) const {
  if (periodic()) return refined(std::vector<double>(static_cast<std::size_t>(std::max(times, 0)), t));
  const int p = degree();
  const auto& U = knots_.values();
  if (!(t > knots_.front() && t < knots_.back()))
    fail(errc::out_of_domain, "knot ", t, " to insert is not inside the open domain (", knots_.front(), ", ",
         knots_.back(), ")");
  const int s = knots_.multiplicity(t);
  if (times < 0 || s + times > p)
    fail(errc::invalid_knots, "inserting ", t, " ", times, " times gives multiplicity ", s + times,
         ", more than degree ", p);
  if (times == 0) return *this;
  const int k = knots_.find_span(t);
  const int np = knots_.count() - 1;
  const auto P = homogeneous(cp_, w_);
  std::vector<Homogeneous> Q(P.size() + static_cast<std::size_t>(times));
  for (int i = 0; i <= k - p; ++i) Q[static_cast<std::size_t>(i)] = P[static_cast<std::size_t>(i)];
  for (int i = k - s; i <= np; ++i) Q[static_cast<std::size_t>(i + times)] = P[static_cast<std::size_t>(i)];
  std::vector<Homogeneous> R(static_cast<std::size_t>(p - s + 1));
  for (int i = 0; i <= p - s; ++i) R[static_cast<std::size_t>(i)] = P[static_cast<std::size_t>(k - p + i)];
  int L = 0;
  for (int j = 1; j <= times; ++j) {
    L = k - p + j;
    for (int i = 0; i <= p - j - s; ++i) {
      const double a = (t - U[static_cast<std::size_t>(L + i)]) /
                       (U[static_cast<std::size_t>(i + k + 1)] - U[static_cast<std::size_t>(L + i)]);
      auto& r = R[static_cast<std::size_t>(i)];
      const auto& r1 = R[static_cast<std::size_t>(i + 1)];
      for (int c = 0; c < 4; ++c) r[c] = a * r1[c] + (1.0 - a) * r[c];
    }
    Q[static_cast<std::size_t>(L)] = R[0];
    Q[static_cast<std::size_t>(k + times - j - s)] = R[static_cast<std::size_t>(p - j - s)];
  }
  for (int i = L + 1; i < k - s; ++i) Q[static_cast<std::size_t>(i)] = R[static_cast<std::size_t>(i - L)];
  std::vector<double> V(U.begin(), U.begin() + k + 1);
  V.insert(V.end(), static_cast<std::size_t>(times), t);
  V.insert(V.end(), U.begin() + k + 1, U.end());
  return from_homogeneous(KnotVector(p, std::move(V)), Q, rational());
}

BSplineCurve BSplineCurve::refined(std::span<const double> knots) const {
  if (knots.empty()) return *this;
  for (double t : knots) {
    if (periodic() && !std::isfinite(t)) fail(errc::out_of_domain, "knot ", t, " to insert is not a number");
    if (!periodic() && !(t > knots_.front() && t < knots_.back()))
      fail(errc::out_of_domain, "knot ", t, " to insert is not inside the open domain (", knots_.front(), ", ",
           knots_.back(), ")");
  }
  std::vector<double> X(knots.begin(), knots.end());
  if (periodic())
    for (double& t : X) {
      t = knots_.wrap(t);
      if (t == knots_.back()) t = knots_.front();  // the seam
    }
  if (!std::is_sorted(X.begin(), X.end())) std::sort(X.begin(), X.end());
  const int p = degree();
  for (std::size_t i = 0; i < X.size();) {
    std::size_t j = i;
    while (j < X.size() && X[j] == X[i]) ++j;
    const int s = knots_.multiplicity(X[i]), times = static_cast<int>(j - i);
    if (s + times > p)
      fail(errc::invalid_knots, "inserting ", X[i], " ", times, " times gives multiplicity ", s + times,
           ", more than degree ", p);
    i = j;
  }
  if (periodic()) {
    std::vector<double> k = knots_.period_knots();
    k.insert(k.end(), X.begin(), X.end());
    std::sort(k.begin(), k.end());
    return in_space(KnotVector::periodic_from(p, std::move(k), knots_.back()), knots_, cp_, w_);
  }
  if (!rational()) {
    auto r = refine(knots_, cp_, X);
    return BSplineCurve(KnotVector(p, std::move(r.knots)), std::move(r.points));
  }
  auto r = refine(knots_, homogeneous(cp_, w_), X);
  return from_homogeneous(KnotVector(p, std::move(r.knots)), r.points, true);
}

BSplineCurve BSplineCurve::elevated(int times) const {
  if (times < 0) fail(errc::invalid_degree, "cannot elevate by ", times, " degrees");
  if (times == 0) return *this;
  const int p = degree();
  const int q = p + times;
  if (q > max_degree) fail(errc::invalid_degree, "elevated degree ", q, " exceeds ", max_degree);
  // The elevated space has every knot's multiplicity raised by `times`; the curve
  // lies in it (in_space).
  if (periodic()) {
    std::vector<double> V;
    for (const auto& [x, m] : knots_.interior_breaks()) V.insert(V.end(), static_cast<std::size_t>(m + times), x);
    return in_space(KnotVector::periodic_from(q, std::move(V), knots_.back()), knots_, cp_, w_);
  }
  std::vector<double> V;
  const auto& U = knots_.values();
  for (std::size_t i = 0; i < U.size();) {
    std::size_t j = i;
    while (j < U.size() && U[j] == U[i]) ++j;
    V.insert(V.end(), j - i + static_cast<std::size_t>(times), U[i]);
    i = j;
  }
  return in_space(KnotVector(q, std::move(V)), knots_, cp_, w_);
}

BSplineCurve BSplineCurve::clamped() const {
  if (!periodic()) return *this;
  return in_space(knots_.clamped(), knots_, cp_, w_);
}

BSplineCurve BSplineCurve::mapped(double a, double b) const {
  return BSplineCurve(knots_.mapped(a, b), cp_, w_);
}

std::vector<BSplineCurve> make_compatible(std::span<const BSplineCurve> curves) {
  if (curves.empty()) fail(errc::too_few_points, "no curves to make compatible");
  int p = 0;
  const auto dom = curves.front().domain();
  for (std::size_t k = 0; k < curves.size(); ++k) {
    p = std::max(p, curves[k].degree());
    if (curves[k].domain() != dom)
      fail(errc::out_of_domain, "curve ", k, " has domain [", curves[k].domain().first, ", ",
           curves[k].domain().second, "], curve 0 has [", dom.first, ", ", dom.second, "]");
  }
  std::vector<KnotVector> knots;
  knots.reserve(curves.size());
  for (const auto& c : curves) knots.push_back(c.knots());
  // Knots a rounding apart are one knot of every curve (each curve moves by rounding).
  knots = snapped_together(knots);
  const auto merged = merged_knots(knots).interior_breaks();
  std::vector<BSplineCurve> out;
  out.reserve(curves.size());
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const BSplineCurve& c = curves[k];
    if (knots[k].values() == c.knots().values()) out.push_back(c.elevated(p - c.degree()));
    else out.push_back(BSplineCurve(knots[k], c.control_points(), c.weights()).elevated(p - c.degree()));
  }
  // Each curve refined on its own, the curves shared between the threads.
  detail::parallel_for(out.size(), out.size() > 1, detail::Share::one_by_one, [&](std::size_t k) {
    auto& c = out[k];
    std::vector<double> missing;
    const auto have = c.knots().interior_breaks();
    std::size_t j = 0;
    for (const auto& [t, m] : merged) {
      while (j < have.size() && have[j].first < t) ++j;
      const int h = j < have.size() && have[j].first == t ? have[j].second : 0;
      missing.insert(missing.end(), static_cast<std::size_t>(m - h), t);
    }
    if (!missing.empty()) c = c.refined(missing);
  });
  return out;
}

BSplineCurve line(const Vec3& a, const Vec3& b) { return BSplineCurve(KnotVector::bezier(1), {a, b}); }

}  // namespace interpatch
