// A blended volume evaluated point by point, and the lines and partials of surfaces
// its terms are made of.
#include "interpatch/blended_volume.hpp"

#include <algorithm>

#include "base/text.hpp"
#include "blends/volume_terms.hpp"

namespace interpatch {

using detail::fail;

namespace {

constexpr int W = max_degree + 1;
using H = std::array<double, 4>;

Vec3 xyz(const H& h) { return {h[0], h[1], h[2]}; }

}  // namespace

// ---------------------------------------------------------------- helpers

namespace detail {

IsoLine::IsoLine(const BSplineSurface& s, int fixed, double at, int order)
    : k_(fixed == 0 ? s.knots_v() : s.knots_u()), order_(order), rational_(s.rational()) {
  INTERPATCH_ASSERT((fixed == 0 || fixed == 1) && (order == 0 || order == 1));
  const KnotVector& kf = fixed == 0 ? s.knots_u() : s.knots_v();
  at = std::clamp(at, kf.front(), kf.back());
  const int pf = kf.degree();
  const int span = kf.find_span(at);
  double N[2 * W];
  kf.basis_derivatives(span, at, order, N);
  const auto n = static_cast<std::size_t>(k_.count());
  const auto& cp = s.control_points();
  const auto& wt = s.weights();
  for (int o = 0; o <= order; ++o) h_[o].assign(n, H{0, 0, 0, 0});
  for (int e = 0; e <= pf; ++e) {
    const auto idx = static_cast<std::size_t>(span - pf + e);
    for (std::size_t l = 0; l < n; ++l) {
      const Vec3& P = fixed == 0 ? cp(idx, l) : cp(l, idx);
      const double w = rational_ ? (fixed == 0 ? wt(idx, l) : wt(l, idx)) : 1.0;
      for (int o = 0; o <= order; ++o) {
        const double c = N[o * (pf + 1) + e] * w;
        H& h = h_[o][l];
        h[0] += c * P.x;
        h[1] += c * P.y;
        h[2] += c * P.z;
        h[3] += c;
      }
    }
  }
}

IsoLine::Value IsoLine::eval(double t) const noexcept {
  t = std::clamp(t, k_.front(), k_.back());
  const int p = k_.degree();
  const int span = k_.find_span(t);
  double N[2 * W];
  k_.basis_derivatives(span, t, 1, N);
  // a[o][k]: the o-th fixed-parameter line, k-th derivative along the free parameter.
  H a[2][2]{};
  for (int o = 0; o <= order_; ++o)
    for (int e = 0; e <= p; ++e) {
      const H& h = h_[o][static_cast<std::size_t>(span - p + e)];
      for (std::size_t y = 0; y < 4; ++y) {
        a[o][0][y] += N[e] * h[y];
        a[o][1][y] += N[p + 1 + e] * h[y];
      }
    }
  if (!rational_) return {xyz(a[order_][0]), xyz(a[order_][1])};
  // Quotient rule: A0 = w0 S, A1 = w1 S + w0 X with X = S_s, each differentiated along t.
  const double w0 = a[0][0][3], w0t = a[0][1][3];
  const Vec3 S = xyz(a[0][0]) / w0;
  const Vec3 St = (xyz(a[0][1]) - w0t * S) / w0;
  if (order_ == 0) return {S, St};
  const double w1 = a[1][0][3], w1t = a[1][1][3];
  const Vec3 X = (xyz(a[1][0]) - w1 * S) / w0;
  const Vec3 Xt = (xyz(a[1][1]) - w1t * S - w1 * St - w0t * X) / w0;
  return {X, Xt};
}

BSplineCurve IsoLine::curve() const {
  INTERPATCH_ASSERT(!rational_);
  std::vector<Vec3> cp(h_[order_].size());
  for (std::size_t i = 0; i < cp.size(); ++i) cp[i] = xyz(h_[order_][i]);
  return BSplineCurve(k_, std::move(cp));
}

std::array<Vec3, 3> surface_partials(const BSplineSurface& surface, double s, double t) noexcept {
  const KnotVector& ku = surface.knots_u();
  const KnotVector& kv = surface.knots_v();
  s = std::clamp(s, ku.front(), ku.back());
  t = std::clamp(t, kv.front(), kv.back());
  const int p = ku.degree(), q = kv.degree();
  const int su = ku.find_span(s), sv = kv.find_span(t);
  double Nu[2 * W], Nv[2 * W];
  ku.basis_derivatives(su, s, 1, Nu);
  kv.basis_derivatives(sv, t, 1, Nv);
  const bool rat = surface.rational();
  const auto& cp = surface.control_points();
  const auto& wt = surface.weights();
  H h[3]{};
  for (int a = 0; a <= p; ++a) {
    const auto ii = static_cast<std::size_t>(su - p + a);
    for (int b = 0; b <= q; ++b) {
      const auto jj = static_cast<std::size_t>(sv - q + b);
      const double w = rat ? wt(ii, jj) : 1.0;
      const Vec3& P = cp(ii, jj);
      const H x{w * P.x, w * P.y, w * P.z, w};
      const double f[3] = {Nu[a] * Nv[b], Nu[p + 1 + a] * Nv[b], Nu[a] * Nv[q + 1 + b]};
      for (std::size_t k = 0; k < 3; ++k)
        for (std::size_t y = 0; y < 4; ++y) h[k][y] += f[k] * x[y];
    }
  }
  if (!rat) return {xyz(h[0]), xyz(h[1]), xyz(h[2])};
  const Vec3 S = xyz(h[0]) / h[0][3];
  return {S, (xyz(h[1]) - h[1][3] * S) / h[0][3], (xyz(h[2]) - h[2][3] * S) / h[0][3]};
}

BSplineSurface unit(const BSplineSurface& s) {
  const std::pair<double, double> u01{0.0, 1.0};
  return s.domain_u() == u01 && s.domain_v() == u01 ? s : s.mapped(0.0, 1.0, 0.0, 1.0);
}

}  // namespace detail

// ---------------------------------------------------------------- BlendedVolume

BlendedVolume::BlendedVolume(std::shared_ptr<const detail::VolumeTerms> terms) : t_(std::move(terms)) {
  INTERPATCH_ASSERT(std::all_of(t_->blends.begin(), t_->blends.end(),
                                [](const auto& b) { return b.size() <= detail::max_volume_blends; }));
}

const std::vector<std::string>& BlendedVolume::notes() const noexcept { return t_->notes; }

VolumeDerivatives BlendedVolume::derivatives(double u, double v, double w) const {
  const double lo = -1e-12, hi = 1 + 1e-12;  // rounding of the caller's parameter mapping
  if (!(u >= lo && u <= hi && v >= lo && v <= hi && w >= lo && w <= hi))
    fail(errc::out_of_domain, "parameters (", u, ", ", v, ", ", w, ") are outside the domain [0, 1]³");
  const double t[3] = {std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0), std::clamp(w, 0.0, 1.0)};
  const auto& T = *t_;
  // f[a][k] = {value, derivative} of blend k of axis a.
  double f[3][detail::max_volume_blends][2];
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t k = 0; k < T.blends[a].size(); ++k) {
      double d[3];
      T.blends[a][k].eval(t[a], d);
      f[a][k][0] = d[0];
      f[a][k][1] = d[1];
    }
  Vec3 s{}, ds[3]{};  // S and ∂S/∂t_a
  for (const auto& face : T.faces) {
    const auto a = static_cast<std::size_t>(face.axis);
    const auto o = detail::other_axes(face.axis);
    const auto P = detail::surface_partials(face.surface, t[o[0]], t[o[1]]);
    const double f0 = f[a][face.blend][0], f1 = f[a][face.blend][1];
    s += f0 * P[0];
    ds[a] += f1 * P[0];
    ds[o[0]] += f0 * P[1];
    ds[o[1]] += f0 * P[2];
  }
  for (const auto& e : T.edges) {
    const auto c = static_cast<std::size_t>(e.axis);
    const auto o = detail::other_axes(e.axis);
    const auto a = static_cast<std::size_t>(o[0]), b = static_cast<std::size_t>(o[1]);
    const auto E = e.line.eval(t[c]);
    const double* fa = f[a][e.blends[0]];
    const double* fb = f[b][e.blends[1]];
    const double g = e.scale * fa[0] * fb[0];
    s += g * E.d0;
    ds[a] += (e.scale * fa[1] * fb[0]) * E.d0;
    ds[b] += (e.scale * fa[0] * fb[1]) * E.d0;
    ds[c] += g * E.d1;
  }
  for (const auto& k : T.corners) {
    const double* fu = f[0][k.blends[0]];
    const double* fv = f[1][k.blends[1]];
    const double* fw = f[2][k.blends[2]];
    s += (fu[0] * fv[0] * fw[0]) * k.point;
    ds[0] += (fu[1] * fv[0] * fw[0]) * k.point;
    ds[1] += (fu[0] * fv[1] * fw[0]) * k.point;
    ds[2] += (fu[0] * fv[0] * fw[1]) * k.point;
  }
  return {s, ds[0], ds[1], ds[2]};
}

}  // namespace interpatch
