#include "interpatch/evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "base/kernel.hpp"
#include "splines/normals.hpp"

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

namespace detail {

// Four points a block: the components gathered into lanes, n = su × sv, and n / |n|
// where |n|² lies in [2^-900, DBL_MAX] and |n| > 1e-10 max(|su|, |sv|)², the test of
// unit_normal on squares (both sides of it squared). There no product overflowed,
// and one that underflowed is below 2^-450 of |n|, under its rounding: the normal is
// unit_normal's up to rounding. Any other point (a pole, huge or tiny partials, NaN)
// goes to unit_normal.
INTERPATCH_KERNEL void unit_normals(const Vec3* su, const Vec3* sv, const Vec3* suv, std::size_t n, Vec3* out) {
#if defined(__GNUC__)
  using v4 = double __attribute__((vector_size(32)));
  // The last n % 4 points go through the lanes too, beside copies of the last one:
  // a point's normal is the same wherever it falls in the span (a mesh written a
  // block of columns at a time gets the bits of the whole grid at once).
  Vec3 pa[4], pb[4], pc[4], po[4];
  for (std::size_t j = 0; j < n; j += 4) {
    const std::size_t m = std::min<std::size_t>(4, n - j);
    const Vec3 *a = su + j, *b = sv + j, *c = suv + j;
    Vec3* o = out + j;
    if (m < 4) {
      for (std::size_t k = 0; k < 4; ++k) {
        pa[k] = a[std::min(k, m - 1)];
        pb[k] = b[std::min(k, m - 1)];
        pc[k] = c[std::min(k, m - 1)];
      }
      a = pa;
      b = pb;
      c = pc;
      o = po;
    }
    const v4 ax = {a[0].x, a[1].x, a[2].x, a[3].x}, ay = {a[0].y, a[1].y, a[2].y, a[3].y}, az = {a[0].z, a[1].z, a[2].z, a[3].z};
    const v4 bx = {b[0].x, b[1].x, b[2].x, b[3].x}, by = {b[0].y, b[1].y, b[2].y, b[3].y}, bz = {b[0].z, b[1].z, b[2].z, b[3].z};
    const v4 nx = ay * bz - az * by, ny = az * bx - ax * bz, nz = ax * by - ay * bx;
    const v4 len2 = nx * nx + ny * ny + nz * nz;
    const v4 a2 = ax * ax + ay * ay + az * az, b2 = bx * bx + by * by + bz * bz;
    v4 big2, len;
    for (int k = 0; k < 4; ++k) {
      big2[k] = std::max(a2[k], b2[k]);
      len[k] = std::sqrt(len2[k]);
    }
    constexpr double top = std::numeric_limits<double>::max();
    const auto plain = (len2 >= 0x1p-900) & (len2 <= top) & (big2 <= top) & (len2 > 1e-20 * (big2 * big2));
    const v4 ox = nx / len, oy = ny / len, oz = nz / len;
    for (std::size_t k = 0; k < m; ++k) {
      if (plain[k]) {
        o[k] = {ox[k], oy[k], oz[k]};
      } else {
        SurfaceDerivatives d{};
        d.su = a[k];
        d.sv = b[k];
        d.suv = c[k];
        o[k] = unit_normal(d);
      }
    }
    if (m < 4) std::copy_n(po, m, out + j);
  }
#else
  for (std::size_t j = 0; j < n; ++j) {
    SurfaceDerivatives d{};
    d.su = su[j];
    d.sv = sv[j];
    d.suv = suv[j];
    out[j] = unit_normal(d);
  }
#endif
}

}  // namespace detail

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
