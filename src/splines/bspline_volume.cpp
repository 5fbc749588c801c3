#include "interpatch/bspline_volume.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include "splines/basis_table.hpp"
#include "base/parallel.hpp"
#include "base/kernel.hpp"
#include "splines/row_window.hpp"
#include "splines/sample_row.hpp"
#include "base/text.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;

namespace {

constexpr int W = max_degree + 1;
constexpr int D = max_volume_derivative + 1;
using H = std::array<double, 4>;  // homogeneous point (w x, w y, w z, w)

using detail::check_parameter;
double into_domain(const KnotVector& k, double t) {
  return k.periodic() ? k.wrap(t) : std::clamp(t, k.front(), k.back());
}
// Rows of basis functions with first derivatives, computed once per batch.
using Basis = detail::BasisRow<2>;
std::vector<Basis> bases(const KnotVector& k, std::span<const double> ts, int nd, const char* dir) {
  return detail::basis_table<2>(k, ts, nd, dir);
}

// nu × nv × nw items, refused (too_large) when the product overflows or does not fit.
std::size_t grid_items(std::size_t nu, std::size_t nv, std::size_t nw, std::size_t item_bytes, const char* what) {
  const std::size_t max = std::numeric_limits<std::size_t>::max();
  if ((nv != 0 && nu > max / nv) || (nw != 0 && nu * nv > max / nw))
    fail(errc::too_large, what, " ", nu, "x", nv, "x", nw, " has more points than can be addressed");
  const std::size_t n = nu * nv * nw;
  require_memory(n, item_bytes, detail::cat(what, " ", nu, "x", nv, "x", nw));
  return n;
}

// The contraction behind every batch evaluation. For each u: U_k = Σ_a N_a^(k)(u) Pw_a
// (a net in v, w); for each v: V_kl = Σ_b N_b^(l)(v) U_k (a row in w); for each w the
// point and, with Partials, the three first partials, handed to sink(i, j, m, d).
// Rows of u are split over the threads; every number is computed by the same
// operations whatever their count.
// What the contraction reads: knots, the control planes (the whole net, or a window
// of it) and the weights of a rational volume (empty for a polynomial one, which
// is all a window holds).
struct Net {
  const KnotVector& ku;
  const KnotVector& kv;
  const KnotVector& kw;
  detail::RowWindow planes;
  const Grid<double, 3>& weights;
  std::size_t ncv, ncw;
};

Net net_of(const BSplineVolume& b) {
  const PointGrid3& cp = b.control_points();
  return {b.knots_u(), b.knots_v(), b.knots_w(), {cp.data(), 0, cp.extent(0), cp.extent(0), cp.extent(1) * cp.extent(2)},
          b.weights(), cp.extent(1), cp.extent(2)};
}

// The points of one (u, v) line of a polynomial volume from its row of homogeneous
// points contracted over u and v: detail::sample_points over 4 doubles a point, the
// loop unrolled for degrees 1 to 3. The same products summed in the same order as
// the point-by-point loop of contract (this file is compiled without fused
// multiply-adds), so every clone gives the same bits.
INTERPATCH_KERNEL void sample_line(const int* spans, const double* weights, int r, std::size_t nw, const double* row,
                                   double* out) {
  detail::sample_by_degree<4>(spans, weights, r, nw, row, out);
}

using v4 = double __attribute__((vector_size(32)));

// out[x] = Σ_e c[e] t for x < n, term(e, x, t) giving t, homogeneous points (4 doubles) summed over
// e in order in four lanes and stored once: contract's sums, the same bits in every
// clone (no fused multiply-adds in this file). Count = the terms when known at
// compile time (degrees 1 to 3, unrolled), 0 when not.
template <int Count, class Term>
[[gnu::always_inline]] inline void combine(const double* c, int count, std::size_t n, H* out, const Term& term) {
  const int terms = Count != 0 ? Count : count;
  for (std::size_t x = 0; x < n; ++x) {
    v4 acc = {0, 0, 0, 0};
    for (int e = 0; e < terms; ++e) {
      v4 t;
      term(e, x, t);
      acc += c[e] * t;
    }
    std::memcpy(out[x].data(), &acc, sizeof acc);
  }
}

template <class Term>
[[gnu::always_inline]] inline void combine_by_count(const double* c, int count, std::size_t n, H* out, const Term& term) {
  switch (count) {
    case 4: return combine<4>(c, count, n, out, term);
    case 3: return combine<3>(c, count, n, out, term);
    case 2: return combine<2>(c, count, n, out, term);
    default: return combine<0>(c, count, n, out, term);
  }
}

// Rows of homogeneous points combined: the rows of v of contract.
INTERPATCH_KERNEL void combine_rows(const double* c, int count, const H* const* in, std::size_t n, H* out) {
  combine_by_count(c, count, n, out, [&](int e, std::size_t x, v4& t) { std::memcpy(&t, in[e][x].data(), sizeof t); });
}

// The control planes of a polynomial volume combined over u, each point with weight
// 1: the planes of u of contract.
INTERPATCH_KERNEL void combine_planes(const double* c, int count, const Vec3* const* planes, std::size_t n, H* out) {
  combine_by_count(c, count, n, out, [&](int e, std::size_t x, v4& t) {
    const Vec3& P = planes[e][x];
    t = v4{P.x, P.y, P.z, 1.0};
  });
}

// Where contract<false> writes a polynomial volume's points a line at a time (points
// null: point by point through the sink), with the w basis packed for sample_line.
struct LineOut {
  Vec3* points = nullptr;
  detail::PackedBasis w;
};

// One net of contract's planes of u: U = Σ_e c[e] Pw_e over the p + 1 planes of the
// span of basis row a, c its derivatives of order k. Each entry summed over the
// planes in registers, in the order of the planes, and stored once (a pass per plane
// read each entry back from the store before: stalls on this processor).
void contract_u(const Net& b, const Basis& a, int k, H* out) {
  const int p = b.ku.degree();
  const Grid<double, 3>& wt = b.weights;
  const bool rat = !wt.empty();
  const std::size_t plane = b.ncv * b.ncw;
  const Vec3* planes[max_degree + 1];
  const double* weights[max_degree + 1];
  double c[max_degree + 1];
  for (int e = 0; e <= p; ++e) {
    c[e] = a.d[k * (p + 1) + e];
    const auto ii = static_cast<std::size_t>(b.ku.wrap_index(a.span - p + e));
    planes[e] = b.planes.row(ii);
    weights[e] = rat ? &wt(ii, 0, 0) : nullptr;
  }
  if (rat) {
    for (std::size_t x = 0; x < plane; ++x) {
      H h{0, 0, 0, 0};
      for (int e = 0; e <= p; ++e) {
        const Vec3& P = planes[e][x];
        const double cw = c[e] * weights[e][x];
        h[0] += cw * P.x;
        h[1] += cw * P.y;
        h[2] += cw * P.z;
        h[3] += cw;
      }
      out[x] = h;
    }
  } else {
    combine_planes(c, p + 1, planes, plane, out);
  }
}

// The point at the w of basis row bm and, with Partials, its three first partials,
// from contract's rows V of one (u, v): V[0] the row, V[1] and V[2] its derivatives
// in u and v.
template <bool Partials>
VolumeDerivatives contract_w(const Net& b, const Basis& bm, const std::vector<H>* V) {
  const int r = b.kw.degree();
  const bool rat = !b.weights.empty();
  // h[0] = S, h[1] = S_u, h[2] = S_v, h[3] = S_w, homogeneous.
  H h[4]{};
  for (int e = 0; e <= r; ++e) {
    const double c0 = bm.d[e];
    const auto x = static_cast<std::size_t>(b.kw.wrap_index(bm.span - r + e));
    for (std::size_t y = 0; y < 4; ++y) h[0][y] += c0 * V[0][x][y];
    if constexpr (Partials) {
      const double c1 = bm.d[(r + 1) + e];
      for (std::size_t y = 0; y < 4; ++y) {
        h[1][y] += c0 * V[1][x][y];
        h[2][y] += c0 * V[2][x][y];
        h[3][y] += c1 * V[0][x][y];
      }
    }
  }
  auto vec = [](const H& g) { return Vec3{g[0], g[1], g[2]}; };
  VolumeDerivatives d;
  if (!rat) {
    d = {vec(h[0]), vec(h[1]), vec(h[2]), vec(h[3])};
  } else {
    const double w = h[0][3];
    d.s = vec(h[0]) / w;
    if constexpr (Partials) {
      d.su = (vec(h[1]) - h[1][3] * d.s) / w;
      d.sv = (vec(h[2]) - h[2][3] * d.s) / w;
      d.sw = (vec(h[3]) - h[3][3] * d.s) / w;
    }
  }
  return d;
}

template <bool Partials, class Sink>
void contract(const Net& b, const std::vector<Basis>& bu, const std::vector<Basis>& bv,
              const std::vector<Basis>& bw, std::size_t r0, std::size_t r1, [[maybe_unused]] bool threads, const Sink& sink,
              const LineOut& lines) {
  const int q = b.kv.degree(), r = b.kw.degree();
  const std::size_t ncv = b.ncv, ncw = b.ncw, plane = ncv * ncw;
  const std::size_t nv = bv.size(), nw = bw.size();
  constexpr int nu_terms = Partials ? 2 : 1;  // u-derivative orders 0..1
  constexpr int nv_terms = Partials ? 3 : 1;  // (k, l) = (0,0), (1,0), (0,1)
  constexpr int kk[3] = {0, 1, 0}, ll[3] = {0, 0, 1};
  const auto first = static_cast<long long>(r0), last = static_cast<long long>(r1);
  detail::ParallelFailure failure;  // allocating a thread's nets
#pragma omp parallel if (threads)
  {
    // Per-thread nets, reused for every u: no allocation per point.
    std::vector<H> U[nu_terms];
    std::vector<H> V[nv_terms];
    // A periodic w: the row's first r points repeated after it, so that spans past
    // the last control point read on (sample_line never wraps).
    const std::size_t wrap = b.kw.periodic() ? static_cast<std::size_t>(r) : 0;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      for (auto& x : U) x.resize(plane);
      for (auto& x : V) x.resize(ncw + wrap);
    });
#pragma omp for schedule(static)
    for (long long ri = first; ri < last; ++ri) {
      if (failure.failed()) continue;
      const auto i = static_cast<std::size_t>(ri);
      for (int k = 0; k < nu_terms; ++k) contract_u(b, bu[i], k, U[k].data());
      for (std::size_t j = 0; j < nv; ++j) {
        const Basis& bj = bv[j];
        for (int t = 0; t < nv_terms; ++t) {
          const H* in[max_degree + 1];
          for (int e = 0; e <= q; ++e)
            in[e] = U[kk[t]].data() + static_cast<std::size_t>(b.kv.wrap_index(bj.span - q + e)) * ncw;
          combine_rows(bj.d + ll[t] * (q + 1), q + 1, in, ncw, V[t].data());
        }
        if (!Partials && lines.points) {  // a polynomial volume's points: the line at once
          std::copy_n(V[0].data(), wrap, V[0].data() + ncw);
          sample_line(lines.w.spans.data(), lines.w.weights.data(), r, nw, V[0].data()->data(),
                      reinterpret_cast<double*>(lines.points + (i * nv + j) * nw));
          continue;
        }
        for (std::size_t m = 0; m < nw; ++m) sink(i, j, m, contract_w<Partials>(b, bw[m], V));
      }
    }
  }
  failure.rethrow();
}

// Runs `contract` over all u rows in chunks, reporting progress between chunks from
// the calling thread.
template <bool Partials, class Sink>
void contract_all(const Net& b, std::span<const double> us, std::span<const double> vs,
                  std::span<const double> ws, const progress_callback& progress, const Sink& sink,
                  Vec3* points = nullptr) {
  const int nd = Partials ? 1 : 0;
  const auto bu = bases(b.ku, us, nd, "u");
  const auto bv = bases(b.kv, vs, nd, "v");
  const auto bw = bases(b.kw, ws, nd, "w");
  LineOut lines;
  if (!Partials && b.weights.empty() && points != nullptr) lines = {points, detail::packed(bw, b.kw.degree())};
  const std::size_t ncv = b.ncv, ncw = b.ncw;
  // Starting the second thread costs milliseconds: small grids stay on one.
  [[maybe_unused]] const bool threads = us.size() * (vs.size() * ws.size() + ncv * ncw) >= detail::parallel_min_work;
  constexpr std::size_t chunk = 16;
  for (std::size_t r0 = 0; r0 < us.size(); r0 += chunk) {
    const std::size_t r1 = std::min(us.size(), r0 + chunk);
    contract<Partials>(b, bu, bv, bw, r0, r1, threads, sink, lines);
    if (progress) progress(static_cast<double>(r1) / static_cast<double>(us.size()));
  }
}

// A line of control points (and weights) along `axis` through the fixed indices of the other two.
BSplineCurve line(const KnotVector& k, const PointGrid3& cp, const Grid<double, 3>& w, int axis, std::size_t f0,
                  std::size_t f1) {
  const std::size_t n = cp.extent(static_cast<std::size_t>(axis));
  std::vector<Vec3> pts(n);
  std::vector<double> ws;
  if (!w.empty()) ws.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::array<std::size_t, 3> ix = axis == 0 ? std::array{i, f0, f1} : (axis == 1 ? std::array{f0, i, f1} : std::array{f0, f1, i});
    pts[i] = cp(ix[0], ix[1], ix[2]);
    if (!w.empty()) ws[i] = w(ix[0], ix[1], ix[2]);
  }
  return BSplineCurve(k, std::move(pts), std::move(ws));
}

// Applies a curve operation to every line of control points along `axis` and reassembles the net.
template <class Op>
BSplineVolume along(const BSplineVolume& b, int axis, Op op) {
  const auto& cp = b.control_points();
  const auto& w = b.weights();
  const std::array<const KnotVector*, 3> ks{&b.knots_u(), &b.knots_v(), &b.knots_w()};
  const int a0 = axis == 0 ? 1 : 0, a1 = axis == 2 ? 1 : 2;  // the other two axes, in order
  const std::size_t n0 = cp.extent(static_cast<std::size_t>(a0)), n1 = cp.extent(static_cast<std::size_t>(a1));
  std::vector<BSplineCurve> out;
  out.reserve(n0 * n1);
  for (std::size_t f0 = 0; f0 < n0; ++f0)
    for (std::size_t f1 = 0; f1 < n1; ++f1) out.push_back(op(line(*ks[static_cast<std::size_t>(axis)], cp, w, axis, f0, f1)));
  const std::size_t n = out.front().control_points().size();
  PointGrid3::shape_type shape = cp.shape();
  shape[static_cast<std::size_t>(axis)] = n;
  PointGrid3 ncp(shape);
  Grid<double, 3> nw;
  if (b.rational()) nw = Grid<double, 3>(shape);
  for (std::size_t f0 = 0; f0 < n0; ++f0)
    for (std::size_t f1 = 0; f1 < n1; ++f1) {
      const BSplineCurve& c = out[f0 * n1 + f1];
      for (std::size_t i = 0; i < n; ++i) {
        const std::array<std::size_t, 3> ix = axis == 0 ? std::array{i, f0, f1} : (axis == 1 ? std::array{f0, i, f1} : std::array{f0, f1, i});
        ncp(ix[0], ix[1], ix[2]) = c.control_points()[i];
        if (b.rational()) nw(ix[0], ix[1], ix[2]) = c.weights()[i];
      }
    }
  std::array<KnotVector, 3> nk{b.knots_u(), b.knots_v(), b.knots_w()};
  nk[static_cast<std::size_t>(axis)] = out.front().knots();
  return BSplineVolume(nk[0], nk[1], nk[2], std::move(ncp), std::move(nw));
}

}  // namespace

BSplineVolume::BSplineVolume(KnotVector knots_u, KnotVector knots_v, KnotVector knots_w, PointGrid3 control_points,
                             Grid<double, 3> weights)
    : ku_(std::move(knots_u)),
      kv_(std::move(knots_v)),
      kw_(std::move(knots_w)),
      cp_(std::move(control_points)),
      w_(std::move(weights)) {
  const auto nu = static_cast<std::size_t>(ku_.count()), nv = static_cast<std::size_t>(kv_.count()),
             nw = static_cast<std::size_t>(kw_.count());
  if (cp_.extent(0) != nu || cp_.extent(1) != nv || cp_.extent(2) != nw)
    fail(errc::size_mismatch, "knots need ", nu, " x ", nv, " x ", nw, " control points, got ", cp_.extent(0), " x ",
         cp_.extent(1), " x ", cp_.extent(2));
  if (!w_.empty() && w_.shape() != cp_.shape())
    fail(errc::size_mismatch, nu, " x ", nv, " x ", nw, " control points need as many weights, got ", w_.extent(0),
         " x ", w_.extent(1), " x ", w_.extent(2));
  if (const std::size_t m = detail::first_non_finite(cp_.data(), cp_.size()); m < cp_.size())
    fail(errc::not_finite, "control point [", m / (nv * nw), "][", m / nw % nv, "][", m % nw, "] is ", cp_.data()[m]);
  if (!w_.empty())
    for (std::size_t i = 0; i < nu; ++i)
      for (std::size_t j = 0; j < nv; ++j)
        for (std::size_t k = 0; k < nw; ++k) {
          const double x = w_(i, j, k);
          if (!std::isfinite(x)) fail(errc::not_finite, "weight [", i, "][", j, "][", k, "] is ", x);
          if (!(x > 0))
            fail(errc::invalid_weight, "weight [", i, "][", j, "][", k, "] is ", x, "; weights must be positive");
        }
}

std::array<std::pair<double, double>, 3> BSplineVolume::domain() const {
  return {{{ku_.front(), ku_.back()}, {kv_.front(), kv_.back()}, {kw_.front(), kw_.back()}}};
}

Vec3 BSplineVolume::point(double u, double v, double w) const { return derivative(u, v, w, 0, 0, 0); }

Vec3 BSplineVolume::derivative(double u, double v, double w, int du, int dv, int dw) const {
  check_parameter(ku_, u, "u");
  check_parameter(kv_, v, "v");
  check_parameter(kw_, w, "w");
  for (int k : {du, dv, dw})
    if (k < 0 || k > max_volume_derivative)
      fail(errc::invalid_degree, "derivative order (", du, ", ", dv, ", ", dw, ") is outside 0..",
           max_volume_derivative, " in some direction");
  u = into_domain(ku_, u);
  v = into_domain(kv_, v);
  w = into_domain(kw_, w);
  const int p = degree_u(), q = degree_v(), r = degree_w();
  const int su = ku_.find_span(u), sv = kv_.find_span(v), sw = kw_.find_span(w);
  double Nu[D * W], Nv[D * W], Nw[D * W];
  ku_.basis_derivatives(su, u, du, Nu);
  kv_.basis_derivatives(sv, v, dv, Nv);
  kw_.basis_derivatives(sw, w, dw, Nw);
  // Homogeneous partials A^(k,l,m) and w^(k,l,m) for k <= du, l <= dv, m <= dw; only
  // the requested order when the volume is polynomial.
  const bool rat = rational();
  Vec3 A[D][D][D];
  double Wt[D][D][D];
  for (int k = rat ? 0 : du; k <= du; ++k)
    for (int l = rat ? 0 : dv; l <= dv; ++l)
      for (int m = rat ? 0 : dw; m <= dw; ++m) {
        Vec3 acc{};
        double wsum = 0;
        for (int a = 0; a <= p; ++a) {
          const double fa = Nu[k * (p + 1) + a];
          if (fa == 0.0) continue;
          const auto ii = static_cast<std::size_t>(ku_.wrap_index(su - p + a));
          for (int b = 0; b <= q; ++b) {
            const double fb = fa * Nv[l * (q + 1) + b];
            if (fb == 0.0) continue;
            const auto jj = static_cast<std::size_t>(kv_.wrap_index(sv - q + b));
            for (int c = 0; c <= r; ++c) {
              const auto kk = static_cast<std::size_t>(kw_.wrap_index(sw - r + c));
              const double f = fb * Nw[m * (r + 1) + c] * (rat ? w_(ii, jj, kk) : 1.0);
              acc += f * cp_(ii, jj, kk);
              wsum += f;
            }
          }
        }
        A[k][l][m] = acc;
        Wt[k][l][m] = wsum;
      }
  if (!rat) return A[du][dv][dw];
  // The quotient rule in three variables (The NURBS Book eq. 4.20 extended): S^(k,l,m) =
  // (A^(k,l,m) − Σ_{(i,j,h) ≠ 0} C(k,i) C(l,j) C(m,h) w^(i,j,h) S^(k−i,l−j,m−h)) / w.
  auto binom = [](int n, int k) {
    double c = 1;
    for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
    return c;
  };
  Vec3 S[D][D][D];
  for (int k = 0; k <= du; ++k)
    for (int l = 0; l <= dv; ++l)
      for (int m = 0; m <= dw; ++m) {
        Vec3 x = A[k][l][m];
        for (int i = 0; i <= k; ++i)
          for (int j = 0; j <= l; ++j)
            for (int h = 0; h <= m; ++h) {
              if (i == 0 && j == 0 && h == 0) continue;
              x -= (binom(k, i) * binom(l, j) * binom(m, h) * Wt[i][j][h]) * S[k - i][l - j][m - h];
            }
        S[k][l][m] = x / Wt[0][0][0];
      }
  return S[du][dv][dw];
}

VolumeDerivatives BSplineVolume::derivatives(double u, double v, double w) const {
  check_parameter(ku_, u, "u");
  check_parameter(kv_, v, "v");
  check_parameter(kw_, w, "w");
  u = into_domain(ku_, u);
  v = into_domain(kv_, v);
  w = into_domain(kw_, w);
  const int p = degree_u(), q = degree_v(), r = degree_w();
  const int su = ku_.find_span(u), sv = kv_.find_span(v), sw = kw_.find_span(w);
  double Nu[2 * W], Nv[2 * W], Nw[2 * W];
  ku_.basis_derivatives(su, u, 1, Nu);
  kv_.basis_derivatives(sv, v, 1, Nv);
  kw_.basis_derivatives(sw, w, 1, Nw);
  // One pass over the (p+1)(q+1)(r+1) control points for all four homogeneous values.
  const bool rat = rational();
  H h[4]{};
  for (int a = 0; a <= p; ++a) {
    const auto ii = static_cast<std::size_t>(ku_.wrap_index(su - p + a));
    for (int b = 0; b <= q; ++b) {
      const auto jj = static_cast<std::size_t>(kv_.wrap_index(sv - q + b));
      for (int c = 0; c <= r; ++c) {
        const auto kk = static_cast<std::size_t>(kw_.wrap_index(sw - r + c));
        const double wt = rat ? w_(ii, jj, kk) : 1.0;
        const Vec3& P = cp_(ii, jj, kk);
        const H x{wt * P.x, wt * P.y, wt * P.z, wt};
        const double f[4] = {Nu[a] * Nv[b] * Nw[c], Nu[p + 1 + a] * Nv[b] * Nw[c], Nu[a] * Nv[q + 1 + b] * Nw[c],
                             Nu[a] * Nv[b] * Nw[r + 1 + c]};
        for (std::size_t t = 0; t < 4; ++t)
          for (std::size_t y = 0; y < 4; ++y) h[t][y] += f[t] * x[y];
      }
    }
  }
  auto vec = [](const H& g) { return Vec3{g[0], g[1], g[2]}; };
  if (!rat) return {vec(h[0]), vec(h[1]), vec(h[2]), vec(h[3])};
  const double wt = h[0][3];
  const Vec3 s = vec(h[0]) / wt;
  return {s, (vec(h[1]) - h[1][3] * s) / wt, (vec(h[2]) - h[2][3] * s) / wt, (vec(h[3]) - h[3][3] * s) / wt};
}

void BSplineVolume::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                                  std::span<Vec3> out, const progress_callback& progress) const {
  detail::check_output_size(out.size(), {us.size(), vs.size(), ws.size()}, "volume evaluation");
  const std::size_t nv = vs.size(), nw = ws.size();
  contract_all<false>(
      net_of(*this), us, vs, ws, progress,
      [&](std::size_t i, std::size_t j, std::size_t k, const VolumeDerivatives& d) { out[(i * nv + j) * nw + k] = d.s; },
      out.data());
}

namespace detail {

void evaluate_volume_rows(const KnotVector& ku, const KnotVector& kv, const KnotVector& kw, const RowWindow& net,
                          std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                          std::span<Vec3> out, const progress_callback& progress) {
  const Grid<double, 3> polynomial;
  const std::size_t nv = vs.size(), nw = ws.size();
  contract_all<false>(Net{ku, kv, kw, net, polynomial, static_cast<std::size_t>(kv.count()), static_cast<std::size_t>(kw.count())},
                      us, vs, ws, progress,
                      [&](std::size_t i, std::size_t j, std::size_t k, const VolumeDerivatives& d) {
                        out[(i * nv + j) * nw + k] = d.s;
                      },
                      out.data());
}

}  // namespace detail

Grid<VolumeDerivatives, 3> BSplineVolume::evaluate_derivatives(std::span<const double> us, std::span<const double> vs,
                                                               std::span<const double> ws) const {
  grid_items(us.size(), vs.size(), ws.size(), sizeof(VolumeDerivatives), "volume derivative grid");
  Grid<VolumeDerivatives, 3> out({us.size(), vs.size(), ws.size()}, for_overwrite);
  contract_all<true>(net_of(*this), us, vs, ws, {},
                     [&out](std::size_t i, std::size_t j, std::size_t k, const VolumeDerivatives& d) { out(i, j, k) = d; });
  return out;
}

VolumeJacobians BSplineVolume::evaluate_jacobians(std::span<const double> us, std::span<const double> vs,
                                                  std::span<const double> ws, const progress_callback& progress) const {
  grid_items(us.size(), vs.size(), ws.size(), sizeof(Vec3) + sizeof(double), "volume Jacobian grid");
  VolumeJacobians out{PointGrid3({us.size(), vs.size(), ws.size()}), Grid<double, 3>({us.size(), vs.size(), ws.size()})};
  contract_all<true>(net_of(*this), us, vs, ws, progress,
                     [&out](std::size_t i, std::size_t j, std::size_t k, const VolumeDerivatives& d) {
                       out.points(i, j, k) = d.s;
                       out.determinants(i, j, k) = triple(d.su, d.sv, d.sw);
                     });
  return out;
}

BSplineVolume BSplineVolume::refined(std::span<const double> knots_u, std::span<const double> knots_v,
                                     std::span<const double> knots_w) const {
  BSplineVolume b = *this;
  if (!knots_u.empty()) b = along(b, 0, [&](const BSplineCurve& c) { return c.refined(knots_u); });
  if (!knots_v.empty()) b = along(b, 1, [&](const BSplineCurve& c) { return c.refined(knots_v); });
  if (!knots_w.empty()) b = along(b, 2, [&](const BSplineCurve& c) { return c.refined(knots_w); });
  return b;
}

BSplineVolume BSplineVolume::elevated(int tu, int tv, int tw) const {
  for (int t : {tu, tv, tw})
    if (t < 0) fail(errc::invalid_degree, "cannot elevate by ", t, " degrees");
  BSplineVolume b = *this;
  if (tu > 0) b = along(b, 0, [&](const BSplineCurve& c) { return c.elevated(tu); });
  if (tv > 0) b = along(b, 1, [&](const BSplineCurve& c) { return c.elevated(tv); });
  if (tw > 0) b = along(b, 2, [&](const BSplineCurve& c) { return c.elevated(tw); });
  return b;
}

BSplineVolume BSplineVolume::clamped() const {
  BSplineVolume b = *this;
  for (int a = 0; a < 3; ++a)
    if ((a == 0 ? ku_ : a == 1 ? kv_ : kw_).periodic()) b = along(b, a, [](const BSplineCurve& c) { return c.clamped(); });
  return b;
}

BSplineVolume BSplineVolume::mapped(double u0, double u1, double v0, double v1, double w0, double w1) const {
  return BSplineVolume(ku_.mapped(u0, u1), kv_.mapped(v0, v1), kw_.mapped(w0, w1), cp_, w_);
}

}  // namespace interpatch
