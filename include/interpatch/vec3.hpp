#pragma once
/// @file vec3.hpp
/// A point or vector in 3-space: three doubles, nothing hidden.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace interpatch {

/// A point or vector in 3-space.
///
/// Example:
/// @code
///   interpatch::Vec3 a{1, 0, 0}, b{0, 1, 0};
///   interpatch::Vec3 n = cross(a, b);  // (0, 0, 1)
/// @endcode
struct Vec3 {
  double x = 0, y = 0, z = 0;

  constexpr double& operator[](int i) noexcept { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr double operator[](int i) const noexcept { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3& operator+=(const Vec3& o) noexcept { x += o.x; y += o.y; z += o.z; return *this; }
  constexpr Vec3& operator-=(const Vec3& o) noexcept { x -= o.x; y -= o.y; z -= o.z; return *this; }
  constexpr Vec3& operator*=(double s) noexcept { x *= s; y *= s; z *= s; return *this; }
  constexpr Vec3& operator/=(double s) noexcept { x /= s; y /= s; z /= s; return *this; }
  friend constexpr Vec3 operator+(Vec3 a, const Vec3& b) noexcept { return a += b; }
  friend constexpr Vec3 operator-(Vec3 a, const Vec3& b) noexcept { return a -= b; }
  friend constexpr Vec3 operator-(const Vec3& a) noexcept { return {-a.x, -a.y, -a.z}; }
  friend constexpr Vec3 operator*(Vec3 a, double s) noexcept { return a *= s; }
  friend constexpr Vec3 operator*(double s, Vec3 a) noexcept { return a *= s; }
  friend constexpr Vec3 operator/(Vec3 a, double s) noexcept { return a /= s; }
  friend constexpr bool operator==(const Vec3&, const Vec3&) noexcept = default;
};

constexpr double dot(const Vec3& a, const Vec3& b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline bool is_finite(const Vec3& a) noexcept {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

/// The largest magnitude of a's components.
inline double max_abs(const Vec3& a) noexcept { return std::max({std::abs(a.x), std::abs(a.y), std::abs(a.z)}); }

/// The exponent e of m > 0 (2^e <= m < 2^(e+1), subnormal m too): multiplying by
/// 2^-e brings m into [1, 2), exactly. 0 for m = 0, infinite or NaN.
inline int scale_exponent(double m) noexcept {
  if (!(m > 0 && m <= std::numeric_limits<double>::max())) return 0;
  if (m < std::numeric_limits<double>::min()) return std::ilogb(m);
  return static_cast<int>((std::bit_cast<std::uint64_t>(m) >> 52) & 0x7ff) - 1023;
}

/// 2^k a, exact while the components stay normal numbers (or were subnormal and grow).
inline Vec3 ldexp(const Vec3& a, int k) noexcept {
  // One multiplication by 2^k rounds as std::ldexp does; 2^k is a normal double for these k.
  if (k >= -1022 && k <= 1023) return a * std::bit_cast<double>(static_cast<std::uint64_t>(k + 1023) << 52);
  return {std::ldexp(a.x, k), std::ldexp(a.y, k), std::ldexp(a.z, k)};
}

/// |a|, free of the range limits of its squares: for a power of two s,
/// norm(s a) = s norm(a) bit for bit whenever both are normal numbers.
///
/// The plain sqrt(a · a) while a · a lies in [2^-900, DBL_MAX]: no square has
/// overflowed, and one that underflowed is below 2^-122 of the sum, under its rounding.
/// Otherwise (|a| beyond about 1e154 or below 3e-136, the zero vector among them) the
/// components are scaled by 2^-e, e the exponent of the largest, which is
/// exact; and sqrt(4^e x) = 2^e sqrt(x), so scaling the root back by 2^e gives the
/// plain formula's result as if the exponent range had no limits.
inline double norm(const Vec3& a) noexcept {
  const double s = dot(a, a);
  if (s >= 0x1p-900 && s <= std::numeric_limits<double>::max()) return std::sqrt(s);
  if (!is_finite(a)) return std::sqrt(s);  // inf or NaN, as the plain formula
  const int e = scale_exponent(max_abs(a));
  const Vec3 b = ldexp(a, -e);
  return std::ldexp(std::sqrt(dot(b, b)), e);
}
inline double distance(const Vec3& a, const Vec3& b) noexcept { return norm(a - b); }

/// a · (b × c), the determinant of the columns a, b, c, free of range limits like
/// norm(): for powers of two r, s, t, triple(r a, s b, t c) = r s t triple(a, b, c)
/// bit for bit whenever both are normal numbers.
///
/// The plain formula while every component is 0 or within [2^-250, 2^250]: then no
/// product or difference in it can leave the normal range. Otherwise from the columns
/// each scaled by a power of two to a largest component in [1, 2) (exact), the
/// result scaled back by the product of the three.
inline double triple(const Vec3& a, const Vec3& b, const Vec3& c) noexcept {
  const auto plain = [](const Vec3& v) {
    for (int i = 0; i < 3; ++i) {
      const double m = std::abs(v[i]);
      if (m != 0 && !(m >= 0x1p-250 && m <= 0x1p250)) return false;
    }
    return true;
  };
  if ((plain(a) && plain(b) && plain(c)) || !(is_finite(a) && is_finite(b) && is_finite(c)))
    return dot(a, cross(b, c));
  const int ea = scale_exponent(max_abs(a)), eb = scale_exponent(max_abs(b)), ec = scale_exponent(max_abs(c));
  return std::ldexp(dot(ldexp(a, -ea), cross(ldexp(b, -eb), ldexp(c, -ec))), ea + eb + ec);
}

}  // namespace interpatch
