// A blended surface on grids of parameters: rows of points summed by the row kernel,
// derivative grids, and points with normals, each factor evaluated once per u or v.
#include <algorithm>
#include <array>
#include <atomic>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "blends/blended_terms.hpp"
#include "interpatch/blended_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/memory.hpp"
#include "splines/normals.hpp"

namespace interpatch {

using detail::D3;
using detail::S3;

namespace {

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
      D3 p = l < T.b.size() ? detail::eval(T.b[l], u) : D3{};
      if (!T.c.empty())
        for (std::size_t k = 0; k < K; ++k)
          for (int r = 0; r < 3; ++r) p.v[r] += F[i * K + k].v[r] * T.c(k, l);
      P[i * L + l] = p;
    }
  }
}

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
    for (std::size_t k = 0; k < KA; ++k) A[j * KA + k] = detail::eval(T.a[k], v);
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
        const D3 a = detail::eval(T.a[k], v);
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

}  // namespace interpatch
