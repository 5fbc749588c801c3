#include "interpatch/evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace interpatch {

// The formulas below are homogeneous in the derivatives: they are evaluated on
// derivatives scaled by a power of two 2^-e (exact) chosen from their largest
// component, which keeps the products of two or four of them (|Su × Sv|, EG − F²)
// in range at any scale of the data, and the results are scaled back exactly. On
// data of ordinary size the values are those of the unscaled formulas bit for bit.

Vec3 unit_normal(const SurfaceDerivatives& d) noexcept {
  const int e = scale_exponent(std::max(max_abs(d.su), max_abs(d.sv)));
  const Vec3 su = ldexp(d.su, -e), sv = ldexp(d.sv, -e);
  const Vec3 n = cross(su, sv);
  const double len = norm(n);
  const double big = std::max(norm(su), norm(sv));
  // Against the larger partial: at a pole the vanishing one is rounding noise of
  // size ~1e-15 |S|, and its cross product with the other means nothing. A
  // parametrization stretched by more than 1e10 is treated as degenerate too.
  if (len > 1e-10 * big * big) return n / len;
  // A pole: one partial vanishes; the normal is the limit along it.
  const Vec3 suv = ldexp(d.suv, -scale_exponent(max_abs(d.suv)));
  Vec3 m = norm(sv) <= norm(su) ? cross(su, suv) : cross(suv, sv);
  const double lm = norm(m);
  return lm > 0 ? m / lm : Vec3{};
}

Curvature curvature(const SurfaceDerivatives& d) noexcept {
  // With the derivatives scaled by 2^-e, K grows by 2^2e and H and the principal
  // curvatures by 2^e (curvature is 1 / length): scaled back at the end.
  const int e = scale_exponent(std::max({max_abs(d.su), max_abs(d.sv), max_abs(d.suu), max_abs(d.suv), max_abs(d.svv)}));
  const Vec3 su = ldexp(d.su, -e), sv = ldexp(d.sv, -e);
  const double E = dot(su, su), F = dot(su, sv), G = dot(sv, sv);
  const double det = E * G - F * F;
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (!(det > 0)) return {nan, nan, nan, nan};
  const Vec3 n = unit_normal(d);
  const double L = dot(ldexp(d.suu, -e), n), M = dot(ldexp(d.suv, -e), n), N = dot(ldexp(d.svv, -e), n);
  const double K = (L * N - M * M) / det;
  const double H = (E * N - 2 * F * M + G * L) / (2 * det);
  const double disc = std::sqrt(std::max(H * H - K, 0.0));
  return {std::ldexp(K, -2 * e), std::ldexp(H, -e), std::ldexp(H + disc, -e), std::ldexp(H - disc, -e)};
}

std::vector<double> linspace(double a, double b, std::size_t n) {
  std::vector<double> t(n);
  if (n == 1) {
    t[0] = a;
    return t;
  }
  for (std::size_t i = 0; i < n; ++i)
    t[i] = a + (b - a) * (static_cast<double>(i) / static_cast<double>(n - 1));
  if (n > 0) t.back() = b;
  return t;
}

}  // namespace interpatch
