#include "interpatch/blended_volume.hpp"

#include <algorithm>
#include <atomic>

#include "base/parallel.hpp"
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

// ---------------------------------------------------------------- exact conversion

namespace {

// The knots of the exact form along u, v and w: every function of one direction
// on one knot vector and degree (merged_knots), blends, faces and edges alike.
std::array<KnotVector, 3> exact_knots(const detail::VolumeTerms& T) {
  std::array<std::vector<KnotVector>, 3> ks;
  for (std::size_t a = 0; a < 3; ++a)
    for (const auto& b : T.blends[a]) ks[a].push_back(b.spline->knots());
  for (const auto& face : T.faces) {
    const auto o = detail::other_axes(face.axis);
    ks[static_cast<std::size_t>(o[0])].push_back(face.surface.knots_u());
    ks[static_cast<std::size_t>(o[1])].push_back(face.surface.knots_v());
  }
  for (const auto& e : T.edges) ks[static_cast<std::size_t>(e.axis)].push_back(e.line.knots());
  return {merged_knots(ks[0]), merged_knots(ks[1]), merged_knots(ks[2])};
}

// Knots to insert into `k`, once elevated to the target's degree, to reach the target.
std::vector<double> missing_knots(const KnotVector& k, const KnotVector& target) {
  const int t = target.degree() - k.degree();
  std::vector<double> out;
  for (const auto& [x, m] : target.interior_breaks()) {
    const int have = k.multiplicity(x);
    out.insert(out.end(), static_cast<std::size_t>(m - (have > 0 ? have + t : 0)), x);
  }
  return out;
}

BSplineCurve fitted(const BSplineCurve& f, const KnotVector& target) {
  BSplineCurve c = f.elevated(target.degree() - f.degree());
  const auto add = missing_knots(f.knots(), target);
  if (!add.empty()) c = c.refined(add);
  INTERPATCH_ASSERT(c.knots().count() == target.count());
  return c;
}

BSplineSurface fitted(const BSplineSurface& s, const KnotVector& ku, const KnotVector& kv) {
  const auto au = missing_knots(s.knots_u(), ku), av = missing_knots(s.knots_v(), kv);
  return s.elevated(ku.degree() - s.degree_u(), kv.degree() - s.degree_v()).refined(au, av);
}

}  // namespace

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

bool BlendedVolume::has_exact_form() const noexcept {
  for (const auto& list : t_->blends)
    for (const auto& b : list)
      if (!b.spline) return false;
  for (const auto& face : t_->faces)
    if (face.surface.rational()) return false;
  for (const auto& e : t_->edges)
    if (e.line.rational()) return false;
  return true;
}

BSplineVolume BlendedVolume::to_bspline() const { return to_bspline(progress_callback{}); }

BSplineVolume BlendedVolume::to_bspline(const progress_callback& progress) const {
  const auto& T = *t_;
  for (std::size_t a = 0; a < 3; ++a)
    for (const auto& b : T.blends[a])
      if (!b.spline)
        fail(errc::no_exact_form, "the blending function of ", detail::axis_letter(static_cast<int>(a)),
             " is a callable; only B-spline blends have an exact B-spline form");
  for (std::size_t k = 0; k < T.faces.size(); ++k)
    if (T.faces[k].surface.rational())
      fail(errc::no_exact_form, T.faces[k].name, " is a rational surface; blends of rational surfaces with "
           "different weights have no B-spline form of the same kind");
  for (std::size_t k = 0; k < T.edges.size(); ++k)
    if (T.edges[k].line.rational())
      fail(errc::no_exact_form, "edge line ", k, " along ", detail::axis_letter(T.edges[k].axis),
           " lies on a rational surface; blends of rational data have no B-spline form of the same kind");
  // Every function of u on one knot vector and degree, likewise v and w.
  const std::array<KnotVector, 3> target = exact_knots(T);
  // Each blend's coefficients; each face's net and each edge's line on the common knots.
  std::array<std::vector<detail::Coefficients>, 3> coef;
  for (std::size_t a = 0; a < 3; ++a)
    for (const auto& b : T.blends[a]) coef[a].push_back(detail::coefficients(fitted(*b.spline, target[a])));
  // A face on the common knots already is used as it is: no copy of its net.
  std::vector<BSplineSurface> refit;
  refit.reserve(T.faces.size());
  std::vector<const PointGrid*> Q;
  for (const auto& face : T.faces) {
    const auto o = detail::other_axes(face.axis);
    const KnotVector& ku = target[static_cast<std::size_t>(o[0])];
    const KnotVector& kv = target[static_cast<std::size_t>(o[1])];
    const bool fits = face.surface.knots_u().values() == ku.values() && face.surface.knots_v().values() == kv.values();
    Q.push_back(fits ? &face.surface.control_points()
                     : &refit.emplace_back(fitted(face.surface, ku, kv)).control_points());
  }
  std::vector<std::vector<Vec3>> E;
  for (const auto& e : T.edges)
    E.push_back(fitted(e.line.curve(), target[static_cast<std::size_t>(e.axis)]).control_points());
  const std::array<std::size_t, 3> n{static_cast<std::size_t>(target[0].count()),
                                     static_cast<std::size_t>(target[1].count()),
                                     static_cast<std::size_t>(target[2].count())};
  // Control point (x, y, z) is a sum over the terms of rows along w: a line along w
  // times a number of (x, y) (faces of u and v, edges along w), or a point of (x, y)
  // times a blend of w (faces of w, edges along u and v, corners), the points of one
  // blend of w added first. Each control point is written once, by one thread, each
  // point's terms added in one order.
  struct RowTerm {  // scale · fu[x] · fv[y] (a missing blend is 1) times the line or point at base + x sx + y sy
    double scale;
    const detail::Coefficients *fu, *fv;
    const Vec3* base;
    std::size_t sx, sy, blend;  // blend: of w, for points
  };
  std::vector<RowTerm> line_terms, point_terms;
  auto blend = [&coef](std::size_t axis, std::size_t k) { return &coef[axis][k]; };
  // The faces of u and the edges along w of one blend of u first make one grid of
  // (v, w), R_i = Σ faces + Σ scale g_b(v) E(w), so rows take one term for them.
  std::vector<PointGrid> R;
  R.reserve(T.blends[0].size());
  for (std::size_t i = 0; i < T.blends[0].size(); ++i) {
    std::vector<std::size_t> faces, edges;
    for (std::size_t k = 0; k < T.faces.size(); ++k)
      if (T.faces[k].axis == 0 && T.faces[k].blend == i) faces.push_back(k);
    for (std::size_t k = 0; k < T.edges.size(); ++k)
      if (T.edges[k].axis == 2 && T.edges[k].blends[0] == i) edges.push_back(k);
    if (faces.empty() && edges.empty()) continue;
    PointGrid& g = R.emplace_back(PointGrid::shape_type{n[1], n[2]}, for_overwrite);
    for (std::size_t y = 0; y < n[1]; ++y)
      for (std::size_t z = 0; z < n[2]; ++z) {
        Vec3 p{};
        for (std::size_t k : faces) p += (*Q[k])(y, z);
        for (std::size_t k : edges) p += (T.edges[k].scale * coef[1][T.edges[k].blends[1]].c[3 * y]) * E[k][z];
        g(y, z) = p;
      }
    line_terms.push_back({1.0, blend(0, i), nullptr, g.data(), 0, n[2], 0});
  }
  for (std::size_t k = 0; k < T.faces.size(); ++k) {
    const auto& f = T.faces[k];
    const Vec3* q = Q[k]->data();
    if (f.axis == 1) line_terms.push_back({1.0, nullptr, blend(1, f.blend), q, n[2], 0, 0});
    if (f.axis == 2) point_terms.push_back({1.0, nullptr, nullptr, q, n[1], 1, f.blend});
  }
  for (std::size_t k = 0; k < T.edges.size(); ++k) {
    const auto& e = T.edges[k];
    const Vec3* l = E[k].data();
    if (e.axis == 0) point_terms.push_back({e.scale, nullptr, blend(1, e.blends[0]), l, 1, 0, e.blends[1]});
    if (e.axis == 1) point_terms.push_back({e.scale, blend(0, e.blends[0]), nullptr, l, 0, 1, e.blends[1]});
  }
  for (const auto& k : T.corners)
    point_terms.push_back({1.0, blend(0, k.blends[0]), blend(1, k.blends[1]), &k.point, 0, 0, k.blends[2]});
  const std::size_t nh = T.blends[2].size();
  PointGrid3 P(n, for_overwrite);
  const auto rows = static_cast<long long>(n[0] * n[1]);
  detail::ParallelFailure failure;  // making the terms' vectors of a thread
  detail::RegionProgress report(progress);
  std::atomic<std::size_t> done{0};
#pragma omp parallel if (n[0] * n[1] * n[2] * (line_terms.size() + nh) >= detail::parallel_min_work)
  {
    std::vector<detail::LineTerm> lines;
    std::vector<detail::PointTerm> points;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      lines.reserve(line_terms.size());  // a stretch's terms at most: push_back below never allocates
      points.reserve(nh);
    });
    std::array<Vec3, detail::max_volume_blends> h;  // the point of each blend of w
#pragma omp for schedule(static)
    for (long long r = 0; r < rows; ++r) {
      if (failure.failed() || report.stopped()) continue;  // a failure, or stopped by the progress callback
      const std::size_t x = static_cast<std::size_t>(r) / n[1], y = static_cast<std::size_t>(r) % n[1];
      auto factor = [x, y](const RowTerm& t) {
        const double a = t.fu ? t.scale * t.fu->c[3 * x] : t.scale;
        return t.fv ? a * t.fv->c[3 * y] : a;
      };
      h.fill(Vec3{});
      for (const auto& t : point_terms) h[t.blend] += factor(t) * t.base[x * t.sx + y * t.sy];
      detail::fill_row(&P(x, y, 0).x, n[2], lines, points, [&](std::size_t z0, std::size_t z1, auto& ls, auto& ps) {
        for (const auto& t : line_terms)
          if (const double f = factor(t); f != 0.0) ls.push_back({f, &t.base[x * t.sx + y * t.sy + z0].x});
        for (std::size_t b = 0; b < nh; ++b)
          if (h[b] != Vec3{} && coef[2][b].lo < z1 && coef[2][b].hi > z0)
            ps.emplace_back(coef[2][b].c.data() + 3 * z0, h[b]);
      });
      const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (detail::thread_index() == 0 && d % 256 == 0)
        report.report(static_cast<double>(d) / static_cast<double>(n[0] * n[1]));
    }
  }
  failure.rethrow();
  report.rethrow();
  if (progress) progress(1.0);
  return BSplineVolume(target[0], target[1], target[2], std::move(P));
}

}  // namespace interpatch
