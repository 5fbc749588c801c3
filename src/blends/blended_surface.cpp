#include "interpatch/blended_surface.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>

#include "blends/blended_terms.hpp"
#include "base/kernel.hpp"
#include "splines/normals.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/hermite.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;

namespace detail {

BSplineCurve scalar(KnotVector knots, const std::vector<double>& coefficients) {
  std::vector<Vec3> cp(coefficients.size());
  for (std::size_t i = 0; i < cp.size(); ++i) cp[i] = {coefficients[i], 0, 0};
  return BSplineCurve(std::move(knots), std::move(cp));
}

void Scalar::eval(double t, double out[3]) const {
  if (spline) {
    Vec3 d[3];
    spline->derivatives(t, 2, d);
    for (int k = 0; k < 3; ++k) out[k] = d[k].x;
  } else {
    for (int k = 0; k < 3; ++k) out[k] = fn(t, k);
  }
}

Scalar one_minus(const Scalar& f) {
  if (!f.spline) {
    auto fn = f.fn;
    return Scalar(std::function<double(double, int)>([fn](double t, int k) { return (k == 0 ? 1.0 : 0.0) - fn(t, k); }));
  }
  std::vector<Vec3> cp = f.spline->control_points();
  for (auto& x : cp) x = {1.0 - x.x, 0, 0};
  return BSplineCurve(f.spline->knots(), std::move(cp));
}

Scalar scalar(const Blend& f) {
  if (f.is_spline()) return scalar(f.knots(), f.coefficients());
  return Scalar(f.function());
}

std::vector<Scalar> hermite_scalars() {
  const KnotVector k(3, {0, 0, 0, 0, 1, 1, 1, 1});
  return {scalar(k, {1, 1, 0, 0}), scalar(k, {0, 0, 1, 1}), scalar(k, {0, 1.0 / 3, 0, 0}), scalar(k, {0, 0, -1.0 / 3, 0})};
}

BSplineCurve unit(const BSplineCurve& c) {
  return c.domain() == std::pair<double, double>{0.0, 1.0} ? c : c.mapped(0.0, 1.0);
}

INTERPATCH_KERNEL void sum_terms(double* o, std::size_t n, const std::vector<LineTerm>& lines,
                                 const std::vector<PointTerm>& points) {
  std::size_t i = 0;
#if defined(__GNUC__)
  using v4 = double __attribute__((vector_size(32)));
  for (; i + 4 <= n; i += 4) {
    // Twelve doubles, three vectors, each loaded and stored by a memcpy of its own:
    // one of the whole array goes through the stack in halves.
    v4 s0 = {}, s1 = {}, s2 = {}, a0, a1, a2, p0, p1, p2;
    for (const auto& t : lines) {
      const double* a = t.a + 3 * i;
      std::memcpy(&a0, a, sizeof a0);
      std::memcpy(&a1, a + 4, sizeof a1);
      std::memcpy(&a2, a + 8, sizeof a2);
      s0 += t.s * a0;
      s1 += t.s * a1;
      s2 += t.s * a2;
    }
    for (const auto& t : points) {
      const double* g = t.g + 3 * i;
      std::memcpy(&a0, g, sizeof a0);
      std::memcpy(&a1, g + 4, sizeof a1);
      std::memcpy(&a2, g + 8, sizeof a2);
      std::memcpy(&p0, t.p4, sizeof p0);
      std::memcpy(&p1, t.p4 + 4, sizeof p1);
      std::memcpy(&p2, t.p4 + 8, sizeof p2);
      s0 += a0 * p0;
      s1 += a1 * p1;
      s2 += a2 * p2;
    }
    std::memcpy(o + 3 * i, &s0, sizeof s0);
    std::memcpy(o + 3 * i + 4, &s1, sizeof s1);
    std::memcpy(o + 3 * i + 8, &s2, sizeof s2);
  }
#endif
  for (; i < n; ++i) {  // the same operations, one point at a time
    double acc[3] = {};
    for (const auto& t : lines)
      for (std::size_t c = 0; c < 3; ++c) acc[c] += t.s * t.a[3 * i + c];
    for (const auto& t : points)
      for (std::size_t c = 0; c < 3; ++c) acc[c] += t.g[3 * i + c] * t.p4[c];
    for (std::size_t c = 0; c < 3; ++c) o[3 * i + c] = acc[c];
  }
}

Coefficients coefficients(const BSplineCurve& f) {
  const auto& cp = f.control_points();
  Coefficients r;
  r.c.resize(3 * cp.size());
  for (std::size_t i = 0; i < cp.size(); ++i) r.c[3 * i] = r.c[3 * i + 1] = r.c[3 * i + 2] = cp[i].x;
  const auto nz = [](const Vec3& p) { return p.x != 0.0; };
  const auto first = std::find_if(cp.begin(), cp.end(), nz);
  if (first == cp.end()) return r;
  r.lo = static_cast<std::size_t>(first - cp.begin());
  r.hi = cp.size() - static_cast<std::size_t>(std::find_if(cp.rbegin(), cp.rend(), nz) - cp.rbegin());
  return r;
}

}  // namespace detail

// ---------------------------------------------------------------- BlendedSurface

BlendedSurface::BlendedSurface(std::shared_ptr<const detail::BlendedTerms> terms) : t_(std::move(terms)) {}

const std::vector<std::string>& BlendedSurface::notes() const noexcept { return t_->notes; }

namespace {

struct D3 {  // value and first two derivatives of a function of one parameter
  Vec3 v[3];
};

struct S3 {  // the same for a scalar
  double v[3];
};

D3 eval(const BSplineCurve& c, double t) {
  D3 d;
  c.derivatives(t, 2, d.v);
  return d;
}

// d += X(u) Y(v) with its derivatives up to second order; x and y hold a value and
// its first two derivatives (one of them a scalar, the other a point).
template <class X, class Y>
void add_product(SurfaceDerivatives& d, const X* x, const Y* y) {
  d.s += x[0] * y[0];
  d.su += x[1] * y[0];
  d.sv += x[0] * y[1];
  d.suu += x[2] * y[0];
  d.suv += x[1] * y[1];
  d.svv += x[0] * y[2];
}

// The factors of u with their first two derivatives at every us[i]: F[i][k] = f_k(u_i)
// and P[i][l] = b_l(u_i) + Σ_k c_kl f_k(u_i), the factor of g_l(v).
void u_factors(const detail::BlendedTerms& T, std::span<const double> us, std::vector<S3>& F, std::vector<D3>& P) {
  const std::size_t nu = us.size(), K = T.f.size(), L = T.g.size();
  F.assign(nu * K, S3{});
  P.assign(nu * L, D3{});
  for (std::size_t i = 0; i < nu; ++i) {
    const double u = std::clamp(us[i], 0.0, 1.0);
    for (std::size_t k = 0; k < K; ++k) T.f[k].eval(u, F[i * K + k].v);
    for (std::size_t l = 0; l < L; ++l) {
      D3 p = l < T.b.size() ? eval(T.b[l], u) : D3{};
      if (!T.c.empty())
        for (std::size_t k = 0; k < K; ++k)
          for (int r = 0; r < 3; ++r) p.v[r] += F[i * K + k].v[r] * T.c(k, l);
      P[i * L + l] = p;
    }
  }
}

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
    const D3 A = eval(T.a[k], v);
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
    const D3 B = eval(T.b[l], u);
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

namespace {

double clamped(double t) { return std::clamp(t, 0.0, 1.0); }
double value(const detail::Scalar& f, double t) { return f.spline ? f.spline->point(t).x : f.fn(t, 0); }

// The rows of a blended surface on one set of v: per v, a line of values for each
// function of v, A[k][j] = a_k(v_j) and G[l][j] = g_l(v_j) three times over (as
// detail::PointTerm takes it); per block of u, F[i][k] = f_k(u_i) and P[i][l] = b_l(u_i)
// + Σ_k c_kl f_k(u_i), the factor of g_l(v); then row i is Σ_k f_k(u_i) A[k] + Σ_l
// G[l] P[i][l], summed in that order four points at a time in registers (the kernel
// of the exact conversion).
class BlendedRows final : public Surface::Rows {
 public:
  BlendedRows(std::shared_ptr<const detail::BlendedTerms> terms, std::span<const double> vs)
      : t_(std::move(terms)), nv_(vs.size()) {
    const auto& T = *t_;
    detail::check_unit_parameters(vs, "v");
    const std::size_t KA = T.a.size(), L = T.g.size();
    A_.resize(KA * nv_);
    G_.resize(L * 3 * nv_);
    for (std::size_t j = 0; j < nv_; ++j) {
      const double v = clamped(vs[j]);
      for (std::size_t l = 0; l < L; ++l) {
        const double g = value(T.g[l], v);
        for (std::size_t c = 0; c < 3; ++c) G_[(l * nv_ + j) * 3 + c] = g;
      }
      for (std::size_t k = 0; k < KA; ++k) A_[k * nv_ + j] = T.a[k].point(v);
    }
  }

  void evaluate_into(std::span<const double> us, std::span<Vec3> out, const progress_callback& progress) const override {
    const auto& T = *t_;
    detail::check_output_size(out.size(), {us.size(), nv_}, "surface evaluation");
    detail::check_unit_parameters(us, "u");
    const std::size_t nu = us.size(), nv = nv_, K = T.f.size(), L = T.g.size(), KA = T.a.size();
    if (nu == 0 || nv == 0) {
      if (progress) progress(1.0);
      return;
    }
    std::vector<double> F(nu * K);
    std::vector<Vec3> P(nu * L);
    for (std::size_t i = 0; i < nu; ++i) {
      const double u = clamped(us[i]);
      for (std::size_t k = 0; k < K; ++k) F[i * K + k] = value(T.f[k], u);
      for (std::size_t l = 0; l < L; ++l) {
        Vec3 p = l < T.b.size() ? T.b[l].point(u) : Vec3{};
        if (!T.c.empty())
          for (std::size_t k = 0; k < K; ++k) p += F[i * K + k] * T.c(k, l);
        P[i * L + l] = p;
      }
    }
    const auto rows = static_cast<long long>(nu);
    std::atomic<std::size_t> done{0};
    detail::RegionProgress report(progress);
    detail::ParallelFailure failure;  // making the terms' vectors of a thread
#pragma omp parallel if (nu * nv * (KA + L) >= detail::parallel_min_work)
    {
      std::vector<detail::LineTerm> lines;
      std::vector<detail::PointTerm> points;
      failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
        lines.resize(KA);
        points.reserve(L);  // then emplace_back below never allocates
      });
#pragma omp for schedule(static, 16)
      for (long long ri = 0; ri < rows; ++ri) {
        if (report.stopped() || failure.failed()) continue;  // stopped by a progress callback or a failure
        const auto i = static_cast<std::size_t>(ri);
        for (std::size_t k = 0; k < KA; ++k) lines[k] = {F[i * K + k], &A_[k * nv].x};
        points.clear();
        for (std::size_t l = 0; l < L; ++l) points.emplace_back(G_.data() + l * 3 * nv, P[i * L + l]);
        detail::sum_terms(&out[i * nv].x, nv, lines, points);
        const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
        if (detail::thread_index() == 0 && d % 64 == 0) report.report(static_cast<double>(d) / static_cast<double>(nu));
      }
    }
    failure.rethrow();
    report.rethrow();
    if (progress) progress(1.0);
  }

 private:
  std::shared_ptr<const detail::BlendedTerms> t_;
  std::size_t nv_;
  std::vector<Vec3> A_;
  std::vector<double> G_;
};

}  // namespace

std::unique_ptr<Surface::Rows> BlendedSurface::rows(std::span<const double> vs) const {
  if (!t_->gregory.empty()) return Surface::rows(vs);
  return std::make_unique<BlendedRows>(t_, vs);
}

void BlendedSurface::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                                   const progress_callback& progress) const {
  if (!t_->gregory.empty()) return Surface::evaluate_into(us, vs, out, progress);
  detail::check_output_size(out.size(), {us.size(), vs.size()}, "surface evaluation");
  BlendedRows(t_, vs).evaluate_into(us, out, progress);
}

Grid<SurfaceDerivatives, 2> BlendedSurface::evaluate_derivatives(std::span<const double> us,
                                                                 std::span<const double> vs) const {
  const auto& T = *t_;
  if (!T.gregory.empty()) return Surface::evaluate_derivatives(us, vs);
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  require_memory(us.size() * vs.size(), sizeof(SurfaceDerivatives), "surface derivative grid");
  const std::size_t nu = us.size(), nv = vs.size(), K = T.f.size(), L = T.g.size(), KA = T.a.size();
  auto clamp = [](double t) { return std::clamp(t, 0.0, 1.0); };
  // As evaluate_into, with the first two derivatives of every factor: per u, F[i][k]
  // = f_k(u_i) and P[i][l] = b_l(u_i) + Σ_k c_kl f_k(u_i); per v, G[j][l] = g_l(v_j)
  // and A[j][k] = a_k(v_j).
  std::vector<S3> F, G(nv * L);
  std::vector<D3> P, A(nv * KA);
  u_factors(T, us, F, P);
  for (std::size_t j = 0; j < nv; ++j) {
    const double v = clamp(vs[j]);
    for (std::size_t l = 0; l < L; ++l) T.g[l].eval(v, G[j * L + l].v);
    for (std::size_t k = 0; k < KA; ++k) A[j * KA + k] = eval(T.a[k], v);
  }
  Grid<SurfaceDerivatives, 2> out({nu, nv}, for_overwrite);
  const auto rows = static_cast<long long>(nu);
#pragma omp parallel for schedule(static, 16) if (nu * nv * (KA + L) * 6 >= detail::parallel_min_work)
  for (long long ri = 0; ri < rows; ++ri) {
    const auto i = static_cast<std::size_t>(ri);
    for (std::size_t j = 0; j < nv; ++j) {
      SurfaceDerivatives d{};
      for (std::size_t k = 0; k < KA; ++k) add_product(d, F[i * K + k].v, A[j * KA + k].v);
      for (std::size_t l = 0; l < L; ++l) add_product(d, P[i * L + l].v, G[j * L + l].v);
      out(i, j) = d;
    }
  }
  return out;
}

namespace {

// Points and normals of a blended surface on a grid us × vs. Per u, each factor with
// its derivatives: F[i][k] (f_k) and P[i][l] (the factor of g_l), as
// evaluate_derivatives makes them. Per v, lines of values and of first derivatives:
// A[d][k][j] = a_k^(d)(v_j), G[d][l][j] = g_l^(d)(v_j) three times over. Row i of a
// rectangle: S and its partials su (f', P'), sv (a', g') and suv (both), each summed
// by the kernel of evaluate_into from column j0 on, then the normal of every point
// (the kernel and the normals give a point the same bits wherever the rectangle
// starts).
class BlendedNormalGrid final : public Surface::NormalGrid {
 public:
  BlendedNormalGrid(std::shared_ptr<const detail::BlendedTerms> terms, std::span<const double> us,
                    std::span<const double> vs)
      : t_(std::move(terms)), nu_(us.size()), nv_(vs.size()) {
    const auto& T = *t_;
    detail::check_unit_parameters(us, "u");
    detail::check_unit_parameters(vs, "v");
    const std::size_t L = T.g.size(), KA = T.a.size();
    u_factors(T, us, F_, P_);
    for (std::size_t d = 0; d < 2; ++d) {
      A_[d].resize(KA * nv_);
      G_[d].resize(L * 3 * nv_);
    }
    for (std::size_t j = 0; j < nv_; ++j) {
      const double v = clamped(vs[j]);
      for (std::size_t l = 0; l < L; ++l) {
        double g[3];
        T.g[l].eval(v, g);
        for (std::size_t d = 0; d < 2; ++d)
          for (std::size_t c = 0; c < 3; ++c) G_[d][(l * nv_ + j) * 3 + c] = g[d];
      }
      for (std::size_t k = 0; k < KA; ++k) {
        const D3 a = eval(T.a[k], v);
        for (std::size_t d = 0; d < 2; ++d) A_[d][k * nv_ + j] = a.v[d];
      }
    }
  }

  void evaluate_into(std::size_t i0, std::size_t ni, std::size_t j0, std::size_t nj, std::span<Vec3> points,
                     std::span<Vec3> normals) const override {
    evaluate_into(i0, ni, j0, nj, points, normals, {});
  }

  void evaluate_into(std::size_t i0, std::size_t ni, std::size_t j0, std::size_t nj, std::span<Vec3> points,
                     std::span<Vec3> normals, const progress_callback& progress) const {
    const auto& T = *t_;
    detail::check_rectangle(i0, ni, j0, nj, nu_, nv_);
    detail::check_output_size(points.size(), {ni, nj}, "surface evaluation (points)");
    detail::check_output_size(normals.size(), {ni, nj}, "surface evaluation (normals)");
    const std::size_t nv = nv_, K = T.f.size(), L = T.g.size(), KA = T.a.size();
    if (ni == 0 || nj == 0) {
      if (progress) progress(1.0);
      return;
    }
    const auto rows = static_cast<long long>(ni);
    std::atomic<std::size_t> done{0};
    detail::RegionProgress report(progress);
    detail::ParallelFailure failure;  // making the vectors of a thread
#pragma omp parallel if (ni * nj * (KA + L) * 4 >= detail::parallel_min_work)
    {
      std::vector<detail::LineTerm> lines;
      std::vector<detail::PointTerm> terms;
      std::array<std::vector<Vec3>, 3> partial;
      failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
        lines.resize(KA);
        terms.reserve(L);  // then emplace_back below never allocates
        for (auto& p : partial) p.resize(nj);
      });
      // The row's sum of derivative order du in u and dv in v into o.
      const auto sum = [&](std::size_t i, std::size_t du, std::size_t dv, Vec3* o) {
        for (std::size_t k = 0; k < KA; ++k) lines[k] = {F_[i * K + k].v[du], &A_[dv][k * nv + j0].x};
        terms.clear();
        for (std::size_t l = 0; l < L; ++l) terms.emplace_back(G_[dv].data() + (l * nv + j0) * 3, P_[i * L + l].v[du]);
        detail::sum_terms(&o->x, nj, lines, terms);
      };
#pragma omp for schedule(static, 16)
      for (long long ri = 0; ri < rows; ++ri) {
        if (report.stopped() || failure.failed()) continue;  // stopped by a progress callback or a failure
        const auto r = static_cast<std::size_t>(ri), i = i0 + r;
        sum(i, 0, 0, points.data() + r * nj);
        sum(i, 1, 0, partial[0].data());
        sum(i, 0, 1, partial[1].data());
        sum(i, 1, 1, partial[2].data());
        detail::unit_normals(partial[0].data(), partial[1].data(), partial[2].data(), nj, normals.data() + r * nj);
        const std::size_t n = done.fetch_add(1, std::memory_order_relaxed) + 1;
        if (detail::thread_index() == 0 && n % 64 == 0) report.report(static_cast<double>(n) / static_cast<double>(ni));
      }
    }
    failure.rethrow();
    report.rethrow();
    if (progress) progress(1.0);
  }

 private:
  std::shared_ptr<const detail::BlendedTerms> t_;
  std::size_t nu_, nv_;
  std::vector<S3> F_;
  std::vector<D3> P_;
  std::array<std::vector<Vec3>, 2> A_;
  std::array<std::vector<double>, 2> G_;
};

}  // namespace

std::unique_ptr<Surface::NormalGrid> BlendedSurface::normal_grid(std::span<const double> us,
                                                                 std::span<const double> vs) const {
  if (!t_->gregory.empty()) return Surface::normal_grid(us, vs);
  return std::make_unique<BlendedNormalGrid>(t_, us, vs);
}

void BlendedSurface::evaluate_normals_into(std::span<const double> us, std::span<const double> vs,
                                           std::span<Vec3> points, std::span<Vec3> normals,
                                           const progress_callback& progress) const {
  if (!t_->gregory.empty()) return Surface::evaluate_normals_into(us, vs, points, normals, progress);
  detail::check_output_size(points.size(), {us.size(), vs.size()}, "surface evaluation (points)");
  detail::check_output_size(normals.size(), {us.size(), vs.size()}, "surface evaluation (normals)");
  BlendedNormalGrid(t_, us, vs).evaluate_into(0, us.size(), 0, vs.size(), points, normals, progress);
}

bool BlendedSurface::has_exact_form() const noexcept {
  if (!t_->gregory.empty()) return false;
  for (const auto* list : {&t_->f, &t_->g})
    for (const auto& s : *list)
      if (!s.spline) return false;
  for (const auto* list : {&t_->a, &t_->b})
    for (const auto& c : *list)
      if (c.rational()) return false;
  return true;
}

namespace {

// Refuses, saying why, a blended surface without an exact form.
void require_exact_form(const detail::BlendedTerms& T) {
  if (!T.gregory.empty())
    fail(errc::no_exact_form, "Gregory's twist correction is a rational blend of u and v with a singular point at "
                              "each corrected corner; the patch has no exact B-spline form");
  for (const auto* list : {&T.a, &T.b})
    for (std::size_t k = 0; k < list->size(); ++k)
      if ((*list)[k].rational())
        fail(errc::no_exact_form, "curve ", k, " of the ", list == &T.a ? "v" : "u",
             "-direction terms is rational; blends of rational curves with different weights have no B-spline "
             "form of the same kind");
  for (const auto* list : {&T.f, &T.g})
    for (const auto& s : *list)
      if (!s.spline)
        fail(errc::no_exact_form, "a blending function given as a callable has no B-spline form; give it as a "
                                  "B-spline (knots and coefficients) for an exact conversion");
}

// Functions of one parameter (curves or their knot vectors) all closed or all open:
// a direction that mixes periodic ones with clamped ones (a closed boundary curve
// blended by open functions, say) merges as the clamped forms of all, the exact form
// of a surface that is closed only geometrically there.
template <class T>
void same_kind(std::vector<T>& xs) {
  const auto closed = [](const T& x) { return x.periodic(); };
  if (std::any_of(xs.begin(), xs.end(), closed) && !std::all_of(xs.begin(), xs.end(), closed))
    for (auto& x : xs) x = x.clamped();
}

}  // namespace

std::size_t BlendedSurface::terms() const noexcept { return t_->a.size() + t_->g.size(); }

std::array<KnotVector, 2> BlendedSurface::exact_knots() const {
  const auto& T = *t_;
  require_exact_form(T);
  std::vector<KnotVector> ku, kv;
  for (const auto& s : T.f) ku.push_back(s.spline->knots());
  for (const auto& c : T.b) ku.push_back(c.knots());
  for (const auto& s : T.g) kv.push_back(s.spline->knots());
  for (const auto& c : T.a) kv.push_back(c.knots());
  same_kind(ku);
  same_kind(kv);
  return {merged_knots(snapped_together(ku)), merged_knots(snapped_together(kv))};  // as make_compatible
}

BSplineSurface BlendedSurface::to_bspline() const { return to_bspline(progress_callback{}); }

BSplineSurface BlendedSurface::to_bspline(const progress_callback& progress) const {
  const auto& T = *t_;
  require_exact_form(T);
  // Every function of u on one knot vector and degree, every function of v likewise.
  std::vector<BSplineCurve> us, vs;
  for (const auto& s : T.f) us.push_back(*s.spline);
  for (const auto& s : T.g) vs.push_back(*s.spline);
  us.insert(us.end(), T.b.begin(), T.b.end());
  vs.insert(vs.end(), T.a.begin(), T.a.end());
  same_kind(us);
  same_kind(vs);
  const auto cu = make_compatible(us), cv = make_compatible(vs);
  const std::size_t nf = T.f.size(), ng = T.g.size(), na = T.a.size();
  const KnotVector& ku = cu.front().knots();
  const KnotVector& kv = cv.front().knots();
  const auto nu = static_cast<std::size_t>(ku.count()), nv = static_cast<std::size_t>(kv.count());
  // With f_k = Σ_x F[x][k] N_x(u) and g_l = Σ_y G[y][l] N_y(v), control point (x, y) is
  //   Σ_k F[x][k] a_k[y] + Σ_l G[y][l] B[x][l],  B[x][l] = b_l[x] + Σ_k c_kl F[x][k],
  // B being the factor of g_l. Per u index: F and B; per v index: the curves a_k and
  // the coefficients of g_l, each over the range where they are not zero.
  std::vector<double> F(nu * nf);
  for (std::size_t k = 0; k < nf; ++k)
    for (std::size_t x = 0; x < nu; ++x) F[x * nf + k] = cu[k].control_points()[x].x;
  const std::size_t nb = T.b.empty() && T.c.empty() ? 0 : ng;
  std::vector<Vec3> B(nu * nb);
  for (std::size_t x = 0; x < nu; ++x)
    for (std::size_t l = 0; l < nb; ++l) {
      Vec3 p = l < T.b.size() ? cu[nf + l].control_points()[x] : Vec3{};
      if (!T.c.empty())
        for (std::size_t k = 0; k < nf; ++k) p += F[x * nf + k] * T.c(k, l);
      B[x * nb + l] = p;
    }
  std::vector<detail::Coefficients> G;
  for (std::size_t l = 0; l < nb; ++l) G.push_back(detail::coefficients(cv[l]));
  // One pass over the net: each control point written once, by one thread, with the
  // a_k of the nonzero F[x][k] and the g_l that are not zero over each stretch.
  PointGrid P({nu, nv}, for_overwrite);
  const auto rows = static_cast<long long>(nu);
  detail::ParallelFailure failure;  // making the terms' vectors of a thread
  detail::RegionProgress report(progress);
  std::atomic<std::size_t> done{0};
#pragma omp parallel if (nu * nv * (na + nb) >= detail::parallel_min_work)
  {
    std::vector<detail::LineTerm> lines;
    std::vector<detail::PointTerm> points;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      lines.reserve(na);  // a stretch's terms at most: push_back below never allocates
      points.reserve(nb);
    });
#pragma omp for schedule(static)
    for (long long r = 0; r < rows; ++r) {
      if (failure.failed() || report.stopped()) continue;  // a failure, or stopped by the progress callback
      const auto x = static_cast<std::size_t>(r);
      detail::fill_row(&P(x, 0).x, nv, lines, points, [&](std::size_t y0, std::size_t y1, auto& ls, auto& ps) {
        for (std::size_t k = 0; k < na; ++k)
          if (const double f = F[x * nf + k]; f != 0.0) ls.push_back({f, &cv[ng + k].control_points()[y0].x});
        for (std::size_t l = 0; l < nb; ++l)
          if (const Vec3& b = B[x * nb + l]; b != Vec3{} && G[l].lo < y1 && G[l].hi > y0)
            ps.emplace_back(G[l].c.data() + 3 * y0, b);
      });
      const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (detail::thread_index() == 0 && d % 64 == 0) report.report(static_cast<double>(d) / static_cast<double>(nu));
    }
  }
  failure.rethrow();
  report.rethrow();
  if (progress) progress(1.0);
  return BSplineSurface(ku, kv, std::move(P));
}

}  // namespace interpatch
