#pragma once
/// @file coons_volume.hpp
/// Transfinite (Gordon–Hall, Coons) volumes from six boundary surfaces : linear or general blending, and the Hermite-blended volume that
/// also interpolates cross-boundary derivatives ("generalized Hermite interpolation").

#include <optional>

#include "interpatch/blend.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/bspline_surface.hpp"

namespace interpatch {

/// The six boundary surfaces of a volume S(u,v,w) over [0,1]³: u0 = S(0,v,w) and
/// u1 = S(1,v,w) parametrized by (v, w); v0 = S(u,0,w), v1 = S(u,1,w) by (u, w);
/// w0 = S(u,v,0), w1 = S(u,v,1) by (u, v). Each is used over its own domain mapped
/// onto [0, 1]².
struct VolumeFaces {
  BSplineSurface u0, u1, v0, v1, w0, w1;
};

/// Cross-boundary derivative fields, each optional: u0 = S_u(0,v,w), u1 = S_u(1,v,w)
/// by (v, w); v0, v1 = S_v on v = 0, 1 by (u, w); w0, w1 = S_w on w = 0, 1 by (u, v).
/// Derivatives are taken in the volume's parameters [0, 1]³; each surface is used over
/// its own domain mapped onto [0, 1]².
struct VolumeCrossDerivatives {
  std::optional<BSplineSurface> u0, u1, v0, v1, w0, w1;
};

struct CoonsVolumeOptions {
  /// Blending functions f(u), g(v), h(w) in place of u, v, w in every term. A blend
  /// given as a callable is evaluated exactly but leaves the volume without an exact
  /// B-spline form.
  Blend blend_u = Blend::linear(), blend_v = Blend::linear(), blend_w = Blend::linear();
  /// Faces that disagree along a shared edge by more than this are an error; unset
  /// means 1e-7 × the diagonal of the faces' control points' bounding box.
  std::optional<double> tolerance;
};

/// The linear transfinite volume (Gordon–Hall) S = U + V + W − UV − VW − UW + UVW, the
/// Boolean sum of the projectors
///   U = (1−f(u)) S(0,v,w) + f(u) S(1,v,w)   (faces u0, u1), V and W likewise,
/// whose products need the 12 edge curves (UV: S(i,j,w) along w, on faces u_i and v_j)
/// and the 8 corners (UVW). Each edge curve is the mean of the two faces meeting
/// there, each corner the mean of its three faces. With consistent faces the volume
/// takes every face exactly; it reproduces every trilinear volume, and with linear
/// blending every volume that is linear in one of u, v, w.
///
/// Example (the unit cube from its six bilinear faces):
/// @code
///   using namespace interpatch;
///   const KnotVector lin = KnotVector::bezier(1);
///   auto face = [&](int axis, double t) {  // coordinate `axis` = t, the other two from the parameters
///     PointGrid cp({2, 2});
///     for (int a = 0; a < 2; ++a)
///       for (int b = 0; b < 2; ++b) {
///         Vec3 p;
///         p[axis] = t;
///         p[axis == 0 ? 1 : 0] = a;
///         p[axis == 2 ? 1 : 2] = b;
///         cp(a, b) = p;
///       }
///     return BSplineSurface(lin, lin, cp);
///   };
///   auto s = coons_volume({face(0, 0), face(0, 1), face(1, 0), face(1, 1), face(2, 0), face(2, 1)});
///   Vec3 p = s.point(0.2, 0.3, 0.4);  // (0.2, 0.3, 0.4)
///   BSplineVolume b = s.to_bspline();  // trilinear, exact
/// @endcode
/// @throws error corner_gap: two faces disagree along their shared edge, naming both
///   faces, the edge, the gap and where ("faces u0 and v0 disagree along their shared
///   edge (u=0, v=0) by 0.25 at w = 0.4 (tolerance 1e-07)"); out_of_domain (a negative
///   or non-finite tolerance).
[[nodiscard]] BlendedVolume coons_volume(const VolumeFaces& faces, const CoonsVolumeOptions& options = {});

struct HermiteCoonsVolumeOptions {
  /// Position tolerance as in CoonsVolumeOptions; derivatives a, b are compared with
  /// max(tolerance, 1e-7 × max(|a|, |b|)).
  std::optional<double> tolerance;
};

/// The Hermite-blended transfinite volume ("generalized Hermite
/// interpolation"): the Boolean sum P_u ⊕ P_v ⊕ P_w = P_u + P_v + P_w − P_uP_v −
/// P_vP_w − P_uP_w + P_uP_vP_w of the cubic Hermite projectors
///
///   P_u = α0(u) S(0,v,w) + α1(u) S(1,v,w) + β0(u) S_u(0,v,w) + β1(u) S_u(1,v,w),
///
/// P_v, P_w likewise, where a β term is present only when its cross-derivative field
/// is given (without any, the volume is the linear one with α1(t) = 3t² − 2t³ as blend).
/// The data each term uses, with i, j, k the ends 0/1 and "face" / "field" the given
/// surfaces:
///   - P_u: faces u_i, fields u_i (S_u on u = i); P_v, P_w likewise.
///   - P_uP_v (along w at u = i, v = j): S(i,j,w), S_u(i,j,w), S_v(i,j,w), S_uv(i,j,w).
///     Each is taken from both surfaces meeting there and averaged: S from face u_i
///     (at v = j) and face v_j (at u = i); S_u from field u_i and d/du of face v_j;
///     S_v from d/dv of face u_i and field v_j; S_uv from d/dv of field u_i and d/du
///     of field v_j. P_vP_w and P_uP_w likewise.
///   - P_uP_vP_w (corner (i,j,k)): S and its partials S_u, S_v, S_w, S_uv, S_uw, S_vw,
///     S_uvw there, each the mean of its three sources, e.g. S_uvw from d2/dvdw of
///     field u_i, d2/dudw of field v_j and d2/dudv of field w_k.
/// With consistent data the volume takes every face and every given cross derivative
/// exactly, and reproduces every volume that is a cubic polynomial in a direction
/// whose two fields are given.
///
/// Example (the unit cube of the example above, with S_w = (0, 0, 1) given on w = 0 and w = 1):
/// @code
///   VolumeCrossDerivatives d;
///   d.w0 = d.w1 = BSplineSurface(lin, lin, PointGrid({2, 2}, Vec3{0, 0, 1}));
///   auto h = coons_volume({face(0, 0), face(0, 1), face(1, 0), face(1, 1), face(2, 0), face(2, 1)}, d);
///   Vec3 sw = h.derivatives(0.5, 0.5, 0).sw;  // (0, 0, 1)
/// @endcode
///
/// Every pair of sources is checked along its whole edge, and every triple at its
/// corner; the error names the place, both sources and the size.
/// @throws error corner_gap (faces disagree along an edge, as for the linear volume),
///   tangent_mismatch (a first derivative: a field disagrees with the derivative of
///   an adjacent face, along an edge or at a corner), incompatible_twist (a mixed
///   derivative: two fields, or their derivatives, disagree along an edge or at a
///   corner), out_of_domain (a negative or non-finite tolerance).
[[nodiscard]] BlendedVolume coons_volume(const VolumeFaces& faces, const VolumeCrossDerivatives& cross,
                                         const HermiteCoonsVolumeOptions& options = {});

}  // namespace interpatch
