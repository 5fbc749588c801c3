// A blended surface evaluated point by point: the sum of its terms and their
// derivatives, Gregory's twist corrections included.
#include "interpatch/blended_surface.hpp"

#include <algorithm>
#include <cmath>

#include "base/text.hpp"
#include "blends/blended_terms.hpp"
#include "interpatch/hermite.hpp"

namespace interpatch {

using detail::fail;
using detail::D3;
using detail::S3;

BlendedSurface::BlendedSurface(std::shared_ptr<const detail::BlendedTerms> terms) : t_(std::move(terms)) {}

const std::vector<std::string>& BlendedSurface::notes() const noexcept { return t_->notes; }

std::size_t BlendedSurface::terms() const noexcept { return t_->a.size() + t_->g.size(); }

namespace {

// Gregory's blend weight w = a / (a + b) and its partials, a = |u − i|, b = |v − j|.
struct Weight {
  double w, wu, wv, wuu, wuv, wvv;
};

Weight gregory_weight(double u, double v, int i, int j) {
  const double a = std::abs(u - i), b = std::abs(v - j);
  const double su = i == 0 ? 1.0 : -1.0, sv = j == 0 ? 1.0 : -1.0;
  const double s = a + b;
  if (s == 0.0) return {0.5, 0, 0, 0, 0, 0};  // the corner itself: the β factors vanish there
  const double s2 = s * s, s3 = s2 * s;
  return {a / s, su * b / s2, -sv * a / s2, -2 * b / s3, su * sv * (a - b) / s3, 2 * a / s3};
}

}  // namespace

SurfaceDerivatives BlendedSurface::derivatives(double u, double v) const {
  if (!(u >= -1e-12 && u <= 1 + 1e-12 && v >= -1e-12 && v <= 1 + 1e-12))
    fail(errc::out_of_domain, "parameters (", u, ", ", v, ") are outside the domain [0, 1]²");
  u = std::clamp(u, 0.0, 1.0);
  v = std::clamp(v, 0.0, 1.0);
  const auto& T = *t_;
  // Per-thread scratch: sized once, so repeated evaluation does not allocate.
  thread_local std::vector<S3> F, G;
  F.resize(T.f.size());
  G.resize(T.g.size());
  for (std::size_t k = 0; k < T.f.size(); ++k) T.f[k].eval(u, F[k].v);
  for (std::size_t l = 0; l < T.g.size(); ++l) T.g[l].eval(v, G[l].v);
  SurfaceDerivatives d{};
  // Σ f_k(u) a_k(v)
  for (std::size_t k = 0; k < T.a.size(); ++k) {
    const D3 A = detail::eval(T.a[k], v);
    const double f0 = F[k].v[0], f1 = F[k].v[1], f2 = F[k].v[2];
    d.s += f0 * A.v[0];
    d.su += f1 * A.v[0];
    d.sv += f0 * A.v[1];
    d.suu += f2 * A.v[0];
    d.suv += f1 * A.v[1];
    d.svv += f0 * A.v[2];
  }
  // Σ b_l(u) g_l(v)
  for (std::size_t l = 0; l < T.b.size(); ++l) {
    const D3 B = detail::eval(T.b[l], u);
    const double g0 = G[l].v[0], g1 = G[l].v[1], g2 = G[l].v[2];
    d.s += g0 * B.v[0];
    d.su += g0 * B.v[1];
    d.sv += g1 * B.v[0];
    d.suu += g0 * B.v[2];
    d.suv += g1 * B.v[1];
    d.svv += g2 * B.v[0];
  }
  // Σ c_kl f_k(u) g_l(v)
  if (!T.c.empty())
    for (std::size_t k = 0; k < T.f.size(); ++k)
      for (std::size_t l = 0; l < T.g.size(); ++l) {
        const Vec3& c = T.c(k, l);
        const double f0 = F[k].v[0], f1 = F[k].v[1], f2 = F[k].v[2];
        const double g0 = G[l].v[0], g1 = G[l].v[1], g2 = G[l].v[2];
        d.s += (f0 * g0) * c;
        d.su += (f1 * g0) * c;
        d.sv += (f0 * g1) * c;
        d.suu += (f2 * g0) * c;
        d.suv += (f1 * g1) * c;
        d.svv += (f0 * g2) * c;
      }
  // Gregory: −β_i(u) β_j(v) (tv + w (tu − tv)). Along the edge u = i (w = 0) the
  // twist must be d/du of S_v(u, j) for S_u(i, v) to follow its cross-derivative curve;
  // along v = j (w = 1), d/dv of S_u(i, v).
  for (const auto& gc : T.gregory) {
    const HermiteBasis bu[3] = {hermite_basis(u, 0), hermite_basis(u, 1), hermite_basis(u, 2)};
    const HermiteBasis bv[3] = {hermite_basis(v, 0), hermite_basis(v, 1), hermite_basis(v, 2)};
    double B[3], C[3];
    for (int k = 0; k < 3; ++k) {
      B[k] = gc.i == 0 ? bu[k].b0 : bu[k].b1;
      C[k] = gc.j == 0 ? bv[k].b0 : bv[k].b1;
    }
    const Weight w = gregory_weight(u, v, gc.i, gc.j);
    const Vec3 diff = gc.tu - gc.tv;
    const Vec3 g = gc.tv + w.w * diff, gu = w.wu * diff, gv = w.wv * diff;
    const Vec3 guu = w.wuu * diff, guv = w.wuv * diff, gvv = w.wvv * diff;
    d.s -= B[0] * C[0] * g;
    d.su -= B[1] * C[0] * g + B[0] * C[0] * gu;
    d.sv -= B[0] * C[1] * g + B[0] * C[0] * gv;
    d.suu -= B[2] * C[0] * g + 2 * B[1] * C[0] * gu + B[0] * C[0] * guu;
    d.suv -= B[1] * C[1] * g + B[1] * C[0] * gv + B[0] * C[1] * gu + B[0] * C[0] * guv;
    d.svv -= B[0] * C[2] * g + 2 * B[0] * C[1] * gv + B[0] * C[0] * gvv;
  }
  return d;
}

}  // namespace interpatch
