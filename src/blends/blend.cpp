#include "interpatch/blend.hpp"

#include <algorithm>
#include <cmath>

#include "base/text.hpp"

namespace interpatch {

using detail::fail;

Blend::Blend(KnotVector knots, std::vector<double> coefficients) : knots_(std::move(knots)), c_(std::move(coefficients)) {
  if (knots_.front() != 0.0 || knots_.back() != 1.0)
    fail(errc::invalid_knots, "a blending function is defined over [0, 1]; its knots span [", knots_.front(), ", ",
         knots_.back(), "]");
  if (c_.size() != static_cast<std::size_t>(knots_.count()))
    fail(errc::size_mismatch, "a blending function with ", knots_.size(), " knots of degree ", knots_.degree(),
         " needs ", knots_.count(), " coefficients, got ", c_.size());
  for (std::size_t i = 0; i < c_.size(); ++i)
    if (!std::isfinite(c_[i])) fail(errc::not_finite, "blending coefficient ", i, " is ", c_[i]);
  if (c_.front() != 0.0) fail(errc::invalid_blend, "a blending function must be 0 at 0; its first coefficient is ", c_.front());
  if (c_.back() != 1.0) fail(errc::invalid_blend, "a blending function must be 1 at 1; its last coefficient is ", c_.back());
  for (std::size_t i = 1; i < c_.size(); ++i)
    if (c_[i] < c_[i - 1])
      fail(errc::invalid_blend, "a blending function must not decrease: coefficient ", i, " = ", c_[i],
           " is below coefficient ", i - 1, " = ", c_[i - 1]);
}

Blend::Blend(std::function<double(double, int)> f) : fn_(std::move(f)) {
  if (!fn_) fail(errc::invalid_blend, "a blending function must be callable");
  const double f0 = fn_(0.0, 0), f1 = fn_(1.0, 0);
  if (!std::isfinite(f0) || !std::isfinite(f1)) fail(errc::not_finite, "blending function gives f(0) = ", f0, ", f(1) = ", f1);
  // 1e-12: a closed-form blend evaluated in double is exact at the ends to a few ulps.
  if (std::abs(f0) > 1e-12) fail(errc::invalid_blend, "a blending function must be 0 at 0; f(0) = ", f0);
  if (std::abs(f1 - 1) > 1e-12) fail(errc::invalid_blend, "a blending function must be 1 at 1; f(1) = ", f1);
  constexpr int samples = 1024;
  double prev = f0;
  for (int k = 1; k <= samples; ++k) {
    const double t = static_cast<double>(k) / samples, y = fn_(t, 0);
    if (!std::isfinite(y)) fail(errc::not_finite, "blending function gives f(", t, ") = ", y);
    if (y < prev - 1e-12)
      fail(errc::invalid_blend, "a blending function must not decrease: f(", t, ") = ", y, " is below f(",
           static_cast<double>(k - 1) / samples, ") = ", prev);
    prev = y;
  }
}

Blend Blend::linear() { return Blend(KnotVector::bezier(1), {0, 1}); }
Blend Blend::hermite() { return Blend(KnotVector(3, {0, 0, 0, 0, 1, 1, 1, 1}), {0, 0, 1, 1}); }

double Blend::derivative(double t, int order) const {
  if (!(t >= -1e-12 && t <= 1 + 1e-12)) fail(errc::out_of_domain, "blending parameter ", t, " is outside [0, 1]");
  t = std::clamp(t, 0.0, 1.0);
  if (fn_) return fn_(t, order);
  const int p = knots_.degree();
  if (order > p) return 0.0;
  const int s = knots_.find_span(t);
  double d[(max_degree + 1) * (max_degree + 1)];
  knots_.basis_derivatives(s, t, order, d);
  double r = 0;
  for (int j = 0; j <= p; ++j) r += d[order * (p + 1) + j] * c_[static_cast<std::size_t>(s - p + j)];
  return r;
}

}  // namespace interpatch
