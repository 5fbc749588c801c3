#pragma once
/// @file coons.hpp
/// Coons patches from four boundary curves: linear, with general
/// blending functions, and bicubically blended with cross-boundary derivatives.

#include <array>
#include <optional>

#include "interpatch/blended_surface.hpp"

namespace interpatch {

/// The four boundary curves: v0 = S(u,0), v1 = S(u,1), u0 = S(0,v), u1 = S(1,v).
/// Each is used over its own domain mapped onto [0, 1].
struct CoonsBoundary {
  BSplineCurve v0, v1, u0, u1;
};

/// Cross-boundary derivative curves: v0 = S_v(u,0), v1 = S_v(u,1), u0 = S_u(0,v),
/// u1 = S_u(1,v), with derivatives taken in the patch's parameters [0, 1]².
struct CoonsCrossDerivatives {
  BSplineCurve v0, v1, u0, u1;
};

enum class TwistCorrection {
  none,     ///< incompatible twists are an error
  gregory,  ///< Gregory's rational twist blend: matches both cross-derivative curves (no exact B-spline form)
};

struct CoonsOptions {
  /// Blending functions f(u), g(v) in place of u and v.
  Blend blend_u = Blend::linear(), blend_v = Blend::linear();
  /// Corners farther apart than this are an error; unset means 1e-7 × the diagonal
  /// of the curves' control points' bounding box.
  std::optional<double> tolerance;
};

/// S = (1−f)·S(0,v) + f·S(1,v) + (1−g)·S(u,0) + g·S(u,1)
///     − [(1−f)(1−g) P00 + f(1−g) P10 + (1−f)g P01 + fg P11],  f = f(u), g = g(v).
///
/// Example:
/// @code
///   using namespace interpatch;
///   CoonsBoundary b{line({0,0,0}, {1,0,0}), line({0,1,0}, {1,1,1}), line({0,0,0}, {0,1,0}), line({1,0,0}, {1,1,1})};
///   auto s = coons(b);            // the bilinear patch of those corners
///   CoonsOptions o;
///   o.blend_u = o.blend_v = Blend::hermite();
///   auto h = coons(b, o);         // same boundary, blends with zero slope at 0 and 1
/// @endcode
/// @throws error corner_gap (naming the corner, both curves and the gap).
[[nodiscard]] BlendedSurface coons(const CoonsBoundary& boundary, const CoonsOptions& options = {});

struct HermiteCoonsOptions {
  /// Twists S_uv at p00, p01, p10, p11 (index 2i + j); unset ones come from the
  /// cross-derivative curves.
  std::array<std::optional<Vec3>, 4> twists;
  TwistCorrection twist_correction = TwistCorrection::none;
  /// Position tolerance as in CoonsOptions; derivatives are compared with
  /// 1e-7 × max(|a|, |b|, bounding-box diagonal).
  std::optional<double> tolerance;
};

/// The bicubically blended Coons patch S = P_u + P_v − P_uv with
/// P_u = Σ_i α_i(u) S(i,v) + β_i(u) S_u(i,v), P_v likewise in v, and P_uv the
/// tensor-product Hermite interpolant of the corner positions, tangents and twists.
/// Interpolates the boundary curves and the cross-boundary derivatives.
/// @throws error corner_gap, tangent_mismatch (a cross-derivative curve disagrees with
///   a boundary tangent at a corner), incompatible_twist (the two cross-derivative
///   curves, or a given twist, disagree at a corner: naming it and the size), unless
///   twist_correction is gregory.
[[nodiscard]] BlendedSurface coons(const CoonsBoundary& boundary, const CoonsCrossDerivatives& cross,
                                   const HermiteCoonsOptions& options = {});

}  // namespace interpatch
