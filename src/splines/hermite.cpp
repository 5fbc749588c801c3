#include "interpatch/hermite.hpp"

#include <algorithm>
#include <cmath>

#include "base/text.hpp"

namespace interpatch {

using detail::fail;

namespace {

std::vector<Vec3> estimate_tangents(const std::vector<Vec3>& p, const std::vector<double>& u, TangentRule rule) {
  const std::size_t n = p.size();
  std::vector<Vec3> t(n);
  if (n == 2) {
    t[0] = t[1] = (p[1] - p[0]) / (u[1] - u[0]);
    return t;
  }
  if (rule == TangentRule::catmull_rom) {
    t[0] = (p[1] - p[0]) / (u[1] - u[0]);
    for (std::size_t i = 1; i + 1 < n; ++i) t[i] = (p[i + 1] - p[i - 1]) / (u[i + 1] - u[i - 1]);
    t[n - 1] = (p[n - 1] - p[n - 2]) / (u[n - 1] - u[n - 2]);
    return t;
  }
  // Bessel: the derivative of the parabola through three consecutive points.
  auto parabola = [&](std::size_t i, int where) {  // points i-1, i, i+1; where = -1, 0, +1
    const double h0 = u[i] - u[i - 1], h1 = u[i + 1] - u[i];
    const Vec3 d0 = (p[i] - p[i - 1]) / h0, d1 = (p[i + 1] - p[i]) / h1;
    if (where < 0) return ((2 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (where > 0) return ((2 * h1 + h0) * d1 - h1 * d0) / (h0 + h1);
    return (h1 * d0 + h0 * d1) / (h0 + h1);
  };
  t[0] = parabola(1, -1);
  for (std::size_t i = 1; i + 1 < n; ++i) t[i] = parabola(i, 0);
  t[n - 1] = parabola(n - 2, +1);
  return t;
}

}  // namespace

HermiteCurve::HermiteCurve(std::vector<Vec3> points, std::vector<Vec3> tangents, std::vector<double> params,
                           TangentRule rule)
    : p_(std::move(points)), t_(std::move(tangents)), u_(std::move(params)) {
  const std::size_t n = p_.size();
  if (n < 2) fail(errc::too_few_points, "a Hermite curve needs at least 2 points, got ", n);
  for (std::size_t i = 0; i < n; ++i)
    if (!is_finite(p_[i])) fail(errc::not_finite, "point ", i, " is ", p_[i]);
  if (u_.empty()) {
    u_.resize(n);
    for (std::size_t i = 0; i < n; ++i) u_[i] = static_cast<double>(i) / static_cast<double>(n - 1);
    u_.back() = 1.0;
  }
  if (u_.size() != n) fail(errc::size_mismatch, n, " points need ", n, " params, got ", u_.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(u_[i])) fail(errc::not_finite, "param ", i, " is ", u_[i]);
    if (i > 0 && !(u_[i] > u_[i - 1]))
      fail(errc::non_increasing, "param ", i, " = ", u_[i], " is not greater than param ", i - 1, " = ", u_[i - 1]);
  }
  if (t_.empty()) {
    t_ = estimate_tangents(p_, u_, rule);
  } else {
    if (t_.size() != n) fail(errc::size_mismatch, n, " points need ", n, " tangents, got ", t_.size());
    for (std::size_t i = 0; i < n; ++i)
      if (!is_finite(t_[i])) fail(errc::not_finite, "tangent ", i, " is ", t_[i]);
  }
}

Vec3 HermiteCurve::derivative(double t, int k) const {
  const double a = u_.front(), b = u_.back();
  const double slack = 1e-12 * (b - a);  // rounding of the caller's parameter mapping
  if (!(t >= a - slack && t <= b + slack))
    fail(errc::out_of_domain, "parameter ", t, " is outside the domain [", a, ", ", b, "]");
  t = std::clamp(t, a, b);
  const auto it = std::upper_bound(u_.begin(), u_.end() - 1, t);
  const auto i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - u_.begin() - 1, 0));
  const double h = u_[i + 1] - u_[i];
  const double g = (t - u_[i]) / h;
  const HermiteBasis f = hermite_basis(g, k);
  const double scale = std::pow(h, -k);  // d/dt = (1/h) d/dg
  return scale * (f.a0 * p_[i] + f.a1 * p_[i + 1] + h * (f.b0 * t_[i] + f.b1 * t_[i + 1]));
}

BSplineCurve HermiteCurve::to_bspline() const {
  const std::size_t s = p_.size() - 1;  // segments
  std::vector<double> knots;
  knots.reserve(2 * s + 6);
  knots.insert(knots.end(), 4, u_.front());
  for (std::size_t i = 1; i < s; ++i) knots.insert(knots.end(), 2, u_[i]);
  knots.insert(knots.end(), 4, u_.back());
  // With double interior knots the control points are the inner Bézier points of
  // each segment; the knot point P_i lies between its two neighbours.
  std::vector<Vec3> cp;
  cp.reserve(2 * s + 2);
  for (std::size_t i = 0; i < s; ++i) {
    const double h = u_[i + 1] - u_[i];
    if (i == 0) cp.push_back(p_[0]);
    cp.push_back(p_[i] + (h / 3) * t_[i]);
    cp.push_back(p_[i + 1] - (h / 3) * t_[i + 1]);
  }
  cp.push_back(p_[s]);
  return BSplineCurve(KnotVector(3, std::move(knots)), std::move(cp));
}

}  // namespace interpatch
