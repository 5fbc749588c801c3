#pragma once
/// @file volume_patches.hpp
/// Volumes from corner data ("body portions"): the trilinear volume of 8
/// corners and the tricubic Hermite volume of a point frame.

#include <array>

#include "interpatch/blended_volume.hpp"

namespace interpatch {

/// S(u,v,w) = Σ_ijk P_ijk l_i(u) l_j(v) l_k(w) with l_0(t) = 1 − t, l_1(t) = t;
/// corner (i, j, k) at index 4i + 2j + k. Every isoparametric line is straight;
/// the faces are bilinear surfaces.
///
/// Example:
/// @code
///   using namespace interpatch;
///   std::array<Vec3, 8> c;
///   for (int n = 0; n < 8; ++n) c[n] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
///   auto cube = trilinear(c);               // the identity map of the unit cube
///   Vec3 p = cube.point(0.2, 0.3, 0.4);      // (0.2, 0.3, 0.4)
/// @endcode
/// @throws error not_finite (naming the corner).
[[nodiscard]] BlendedVolume trilinear(const std::array<Vec3, 8>& corners);

/// Position and partial derivatives at one corner of a point frame. The mixed
/// derivatives are optional in the seed: leave them out ({p, du, dv, dw}) and they are zero.
struct HermiteVolumeCorner {
  Vec3 p{}, du{}, dv{}, dw{}, duv{}, duw{}, dvw{}, duvw{};
};

/// The tricubic Hermite volume of a point frame (cubic Hermite functions in each
/// direction): with I_i0 = α_i and I_i1 = β_i the cubic Hermite functions,
///
///   S(u,v,w) = Σ_{ijk ∈ {0,1}³} Σ_{abc ∈ {0,1}³} I_ia(u) I_jb(v) I_kc(w) ∂^{a+b+c}S/∂u^a∂v^b∂w^c (i,j,k),
///
/// the 8 derivative kinds p, du, dv, dw, duv, duw, dvw, duvw at corner (i, j, k) =
/// corners[4i + 2j + k]. Its edges are the cubic Hermite curves of eq. 1.23, e.g.
/// S(u,j,k) = Σ_i S(i,j,k) I_i0(u) + S_u(i,j,k) I_i1(u); it reproduces every tricubic
/// polynomial volume from that volume's own corner data, and converts exactly to a
/// tricubic Bézier volume (α0 = B0 + B1, α1 = B2 + B3, β0 = B1/3, β1 = −B2/3).
///
/// Example:
/// @code
///   std::array<interpatch::HermiteVolumeCorner, 8> c{};
///   for (int n = 0; n < 8; ++n) {
///     c[n].p = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
///     c[n].du = {1, 0, 0}; c[n].dv = {0, 1, 0}; c[n].dw = {0, 0, 1};
///   }
///   auto s = interpatch::hermite_volume(c);  // the unit cube again, cubic in form only
/// @endcode
/// @throws error not_finite (naming the corner and the derivative).
[[nodiscard]] BlendedVolume hermite_volume(const std::array<HermiteVolumeCorner, 8>& corners);

}  // namespace interpatch
