#pragma once
/// @file patches.hpp
/// Surfaces from corners and from pairs of curves: bilinear (Rogers & Adams, Mathematical Elements for Computer
/// Graphics, §6-7), ruled and the bicubic Hermite (Ferguson) patch.

#include <array>

#include "interpatch/blended_surface.hpp"

namespace interpatch {

/// Q(u,w) = P00(1−u)(1−w) + P01(1−u)w + P10 u(1−w) + P11 uw; p_uv names the corner
/// at (u, v). Every isoparametric line is straight.
///
/// Example (Rogers & Adams, Example 6-9):
/// @code
///   auto s = interpatch::bilinear({0, 0, 1}, {1, 1, 1}, {1, 0, 0}, {0, 1, 0});
///   interpatch::Vec3 q = s.point(0.5, 0.5);  // (0.5, 0.5, 0.5)
/// @endcode
/// @throws error not_finite.
[[nodiscard]] BlendedSurface bilinear(const Vec3& p00, const Vec3& p01, const Vec3& p10, const Vec3& p11);

/// r(u,v) = (1−v) c0(u) + v c1(u); each curve is used over its own domain mapped
/// onto [0, 1].
[[nodiscard]] BlendedSurface ruled(const BSplineCurve& c0, const BSplineCurve& c1);

/// Position, partial derivatives and twist at one corner of a Hermite patch.
struct HermiteCorner {
  Vec3 p, du, dv, duv;
};

/// The bicubic Hermite (Ferguson) patch: S(u,v) = Σ_ij [α_i(u)α_j(v) p + β_i(u)α_j(v) du
/// + α_i(u)β_j(v) dv + β_i(u)β_j(v) duv]_ij over the corners (i, j) ∈ {0,1}²,
/// corners[2i + j] = p_ij. Reproduces every bicubic polynomial from its own corner data.
/// @throws error not_finite.
[[nodiscard]] BlendedSurface hermite_patch(const std::array<HermiteCorner, 4>& corners);

}  // namespace interpatch
