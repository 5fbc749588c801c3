#include "interpatch/evaluate.hpp"

#include <cmath>
#include <limits>

namespace interpatch {

Vec3 unit_normal(const SurfaceDerivatives& d) noexcept {
  const Vec3 n = cross(d.su, d.sv);
  const double len = norm(n);
  const double big = std::max(norm(d.su), norm(d.sv));
  // Against the larger partial: at a pole the vanishing one is rounding noise of
  // size ~1e-15 |S|, and its cross product with the other means nothing. A
  // parametrization stretched by more than 1e10 is treated as degenerate too.
  if (len > 1e-10 * big * big) return n / len;
  // A pole: one partial vanishes; the normal is the limit along it.
  Vec3 m = norm(d.sv) <= norm(d.su) ? cross(d.su, d.suv) : cross(d.suv, d.sv);
  const double lm = norm(m);
  return lm > 0 ? m / lm : Vec3{};
}

Curvature curvature(const SurfaceDerivatives& d) noexcept {
  const double E = dot(d.su, d.su), F = dot(d.su, d.sv), G = dot(d.sv, d.sv);
  const double det = E * G - F * F;
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (!(det > 0)) return {nan, nan, nan, nan};
  const Vec3 n = unit_normal(d);
  const double L = dot(d.suu, n), M = dot(d.suv, n), N = dot(d.svv, n);
  const double K = (L * N - M * M) / det;
  const double H = (E * N - 2 * F * M + G * L) / (2 * det);
  const double disc = std::sqrt(std::max(H * H - K, 0.0));
  return {K, H, H + disc, H - disc};
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
