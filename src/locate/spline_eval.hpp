#pragma once
// Points and derivatives of a Spline (pieces.hpp) in a known knot span: the
// queries' inner loop, which knows its span from its piece and needs no search.
// Points are in the spline's own units (Spline::local).

#include <array>
#include <utility>

#include "interpatch/surface.hpp"
#include "interpatch/volume.hpp"
#include "locate/pieces.hpp"

namespace interpatch::detail {

namespace eval_impl {
struct Acc {
  double x = 0, y = 0, z = 0, w = 0;
  void add(double c, const H4& h) noexcept { x += c * h.x, y += c * h.y, z += c * h.z, w += c * h.w; }
  void add(double c, const Acc& h) noexcept { x += c * h.x, y += c * h.y, z += c * h.z, w += c * h.w; }
  [[nodiscard]] Vec3 xyz() const noexcept { return {x, y, z}; }
};
// S and its derivatives from those of the homogeneous numerator and the weight
// (the quotient rule; one division).
inline SurfaceDerivatives quotient(const Acc& a00, const Acc& a10, const Acc& a01, const Acc& a20, const Acc& a11,
                                   const Acc& a02) noexcept {
  SurfaceDerivatives d;
  const double iw = 1 / a00.w;
  d.s = a00.xyz() * iw;
  d.su = (a10.xyz() - a10.w * d.s) * iw;
  d.sv = (a01.xyz() - a01.w * d.s) * iw;
  d.suu = (a20.xyz() - 2 * a10.w * d.su - a20.w * d.s) * iw;
  d.suv = (a11.xyz() - a10.w * d.sv - a01.w * d.su - a11.w * d.s) * iw;
  d.svv = (a02.xyz() - 2 * a01.w * d.sv - a02.w * d.s) * iw;
  return d;
}

// S and its derivatives up to second order from the basis functions and their
// derivatives in u (N[k * P + i]) and v, over the rows row(i) of the local net (Q
// homogeneous points each).
template <class Row>
SurfaceDerivatives tensor(const double* Nu, std::size_t P, const double* Nv, std::size_t Q, Row&& row) noexcept {
  Acc a00, a10, a20, a01, a11, a02;
  for (std::size_t i = 0; i < P; ++i) {
    Acc r0, r1, r2;
    const H4* h = row(i);
    for (std::size_t j = 0; j < Q; ++j) {
      r0.add(Nv[j], h[j]);
      r1.add(Nv[Q + j], h[j]);
      r2.add(Nv[2 * Q + j], h[j]);
    }
    a00.add(Nu[i], r0), a10.add(Nu[P + i], r0), a20.add(Nu[2 * P + i], r0);
    a01.add(Nu[i], r1), a11.add(Nu[P + i], r1), a02.add(Nu[i], r2);
  }
  return quotient(a00, a10, a01, a20, a11, a02);
}
}  // namespace eval_impl

/// The Bernstein polynomials of degree p at s in [0, 1] and their first and second
/// derivatives: B[k * (p + 1) + i] = d^k/ds^k B_i^p(s). No division.
inline void bernstein2(int p, double s, double* B) noexcept {
  const double t = 1 - s;
  // Degree k to k + 1: b_i = t a_i + s a_(i−1).
  const auto raise = [&](const double* from, int k, double* to) {
    to[0] = t * from[0];
    for (int i = 1; i <= k; ++i) to[i] = t * from[i] + s * from[i - 1];
    to[k + 1] = s * from[k];
  };
  double x[max_degree + 1], y[max_degree + 1], lower[max_degree + 1], top[max_degree + 1];
  const auto P = static_cast<std::size_t>(p + 1);
  if (p == 1) {
    B[0] = t, B[1] = s, B[2] = -1, B[3] = 1, B[4] = 0, B[5] = 0;
    return;
  }
  double* cur = x;
  double* next = y;
  cur[0] = 1;
  for (int k = 0; k < p - 2; ++k) {
    raise(cur, k, next);
    std::swap(cur, next);
  }
  raise(cur, p - 2, lower);  // degree p − 1
  raise(lower, p - 1, top);  // degree p
  const double c1 = p, c2 = p * (p - 1);
  for (int i = 0; i <= p; ++i) {
    const auto I = static_cast<std::size_t>(i);
    B[I] = top[I];
    B[P + I] = c1 * ((i > 0 ? lower[I - 1] : 0.0) - (i < p ? lower[I] : 0.0));
    B[2 * P + I] = c2 * ((i >= 2 ? cur[I - 2] : 0.0) - 2 * (i >= 1 && i - 1 <= p - 2 ? cur[I - 1] : 0.0) +
                         (i <= p - 2 ? cur[I] : 0.0));
  }
}

/// The same derivatives from a piece's Bézier net (PieceNets), at parameters of the
/// piece's box: Bernstein polynomials of the local parameters.
inline std::array<Vec3, 3> curve_derivatives(const PieceNets& nets, const Piece& pc, double t) noexcept {
  const int p = nets.n[0] - 1;
  const double h = pc.hi[0] - pc.lo[0];
  double B[3 * (max_degree + 1)];
  bernstein2(p, (t - pc.lo[0]) / h, B);
  eval_impl::Acc a[3];
  const H4* c = &nets.h[pc.net];
  const auto P = static_cast<std::size_t>(p + 1);
  const double ih = 1 / h;
  for (std::size_t j = 0; j < P; ++j) B[P + j] *= ih, B[2 * P + j] *= ih * ih;
  for (std::size_t j = 0; j < P; ++j)
    for (std::size_t k = 0; k < 3; ++k) a[k].add(B[k * P + j], c[j]);
  const double w = a[0].w;
  const Vec3 c0 = a[0].xyz() / w;
  const Vec3 c1 = (a[1].xyz() - a[1].w * c0) / w;
  const Vec3 c2 = (a[2].xyz() - 2 * a[1].w * c1 - a[2].w * c0) / w;
  return {c0, c1, c2};
}

namespace eval_impl {
// PP, QQ: the degrees plus one when known at compile time (a bicubic's loops unrolled),
// 0 for any.
// bernstein2 of a cubic, in closed form.
inline void bernstein2_cubic(double s, double* B) noexcept {
  const double t = 1 - s;
  B[0] = t * t * t, B[1] = 3 * s * t * t, B[2] = 3 * s * s * t, B[3] = s * s * s;
  B[4] = -3 * t * t, B[5] = 3 * t * (t - 2 * s), B[6] = 3 * s * (2 * t - s), B[7] = 3 * s * s;
  B[8] = 6 * t, B[9] = 6 * s - 12 * t, B[10] = 6 * t - 12 * s, B[11] = 6 * s;
}

template <int PP>
void bernstein_of(int p, double s, double* B) noexcept {
  if constexpr (PP == 4) bernstein2_cubic(s, B);
  else bernstein2(p, s, B);
}

template <int PP, int QQ>
SurfaceDerivatives net_derivatives(const PieceNets& nets, const Piece& pc, double u, double v) noexcept {
  const int p = PP ? PP - 1 : nets.n[0] - 1, q = QQ ? QQ - 1 : nets.n[1] - 1;
  const double hu = pc.hi[0] - pc.lo[0], hv = pc.hi[1] - pc.lo[1];
  double Nu[3 * (max_degree + 1)], Nv[3 * (max_degree + 1)];
  bernstein_of<PP>(p, (u - pc.lo[0]) / hu, Nu);
  bernstein_of<QQ>(q, (v - pc.lo[1]) / hv, Nv);
  const auto P = static_cast<std::size_t>(p + 1), Q = static_cast<std::size_t>(q + 1);
  const double iu = 1 / hu, iv = 1 / hv;
  for (std::size_t i = 0; i < P; ++i) Nu[P + i] *= iu, Nu[2 * P + i] *= iu * iu;
  for (std::size_t j = 0; j < Q; ++j) Nv[Q + j] *= iv, Nv[2 * Q + j] *= iv * iv;
  return tensor(Nu, P, Nv, Q, [&](std::size_t i) { return &nets.h[pc.net + i * Q]; });
}
}  // namespace eval_impl

inline SurfaceDerivatives surface_derivatives(const PieceNets& nets, const Piece& pc, double u, double v) noexcept {
  if (nets.n[0] == 4 && nets.n[1] == 4) return eval_impl::net_derivatives<4, 4>(nets, pc, u, v);
  return eval_impl::net_derivatives<0, 0>(nets, pc, u, v);
}

/// C, C' and C'' at t in span `span` of a curve (dims 1).
inline std::array<Vec3, 3> curve_derivatives(const Spline& s, int span, double t) noexcept {
  const int p = s.knots[0].degree();
  std::array<double, 3 * (max_degree + 1)> N;
  s.knots[0].basis_derivatives(span, t, 2, N.data());
  eval_impl::Acc a[3];
  for (int j = 0; j <= p; ++j) {
    const H4& c = s.at(span - p + j, 0, 0);
    for (int k = 0; k < 3; ++k) a[k].add(N[static_cast<std::size_t>(k * (p + 1) + j)], c);
  }
  const double w = a[0].w;
  const Vec3 c0 = a[0].xyz() / w;
  const Vec3 c1 = (a[1].xyz() - a[1].w * c0) / w;
  const Vec3 c2 = (a[2].xyz() - 2 * a[1].w * c1 - a[2].w * c0) / w;
  return {c0, c1, c2};
}

/// S and its partial derivatives up to second order at (u, v) in spans (su, sv) of a
/// surface (dims 2).
inline SurfaceDerivatives surface_derivatives(const Spline& s, int su, int sv, double u, double v) noexcept {
  const int p = s.knots[0].degree(), q = s.knots[1].degree();
  std::array<double, 3 * (max_degree + 1)> Nu, Nv;
  s.knots[0].basis_derivatives(su, u, 2, Nu.data());
  s.knots[1].basis_derivatives(sv, v, 2, Nv.data());
  const auto P = static_cast<std::size_t>(p + 1), Q = static_cast<std::size_t>(q + 1);
  return eval_impl::tensor(Nu.data(), P, Nv.data(), Q, [&](std::size_t i) { return &s.at(su - p + static_cast<int>(i), sv - q, 0); });
}

/// V and its first partial derivatives at (u, v, w) in spans `sp` of a volume (dims 3).
inline VolumeDerivatives volume_derivatives(const Spline& s, const std::array<int, 3>& sp, double u, double v,
                                            double w) noexcept {
  const int p = s.knots[0].degree(), q = s.knots[1].degree(), r = s.knots[2].degree();
  std::array<double, 2 * (max_degree + 1)> Nu, Nv, Nw;
  s.knots[0].basis_derivatives(sp[0], u, 1, Nu.data());
  s.knots[1].basis_derivatives(sp[1], v, 1, Nv.data());
  s.knots[2].basis_derivatives(sp[2], w, 1, Nw.data());
  const auto P = static_cast<std::size_t>(p + 1), Q = static_cast<std::size_t>(q + 1), R = static_cast<std::size_t>(r + 1);
  eval_impl::Acc a0, au, av, aw;
  for (std::size_t i = 0; i < P; ++i) {
    eval_impl::Acc b0, bv, bw;
    for (std::size_t j = 0; j < Q; ++j) {
      eval_impl::Acc c0, cw;
      const H4* line = &s.at(sp[0] - p + static_cast<int>(i), sp[1] - q + static_cast<int>(j), sp[2] - r);
      for (std::size_t k = 0; k < R; ++k) c0.add(Nw[k], line[k]), cw.add(Nw[R + k], line[k]);
      b0.add(Nv[j], c0), bv.add(Nv[Q + j], c0), bw.add(Nv[j], cw);
    }
    a0.add(Nu[i], b0), au.add(Nu[P + i], b0), av.add(Nu[i], bv), aw.add(Nu[i], bw);
  }
  VolumeDerivatives d;
  const double h = a0.w;
  d.s = a0.xyz() / h;
  d.su = (au.xyz() - au.w * d.s) / h;
  d.sv = (av.xyz() - av.w * d.s) / h;
  d.sw = (aw.xyz() - aw.w * d.s) / h;
  return d;
}

}  // namespace interpatch::detail

namespace interpatch::detail {

/// A piece's points and derivatives: from its Bézier net when the nets are kept,
/// otherwise from the spline's knot span.
inline SurfaceDerivatives piece_derivatives(const Spline& s, const PieceNets& n, const Piece& pc, double u,
                                            double v) noexcept {
  return n.kept() ? surface_derivatives(n, pc, u, v) : surface_derivatives(s, pc.span[0], pc.span[1], u, v);
}
inline std::array<Vec3, 3> piece_derivatives(const Spline& s, const PieceNets& n, const Piece& pc, double t) noexcept {
  return n.kept() ? curve_derivatives(n, pc, t) : curve_derivatives(s, pc.span[0], t);
}

}  // namespace interpatch::detail
