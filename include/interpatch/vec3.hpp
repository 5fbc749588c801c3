#pragma once
/// @file vec3.hpp
/// A point or vector in 3-space: three doubles, nothing hidden.

#include <cmath>

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
inline double norm(const Vec3& a) noexcept { return std::sqrt(dot(a, a)); }
inline double distance(const Vec3& a, const Vec3& b) noexcept { return norm(a - b); }
inline bool is_finite(const Vec3& a) noexcept {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

}  // namespace interpatch
