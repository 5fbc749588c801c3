#include "interpatch/bspline_surface.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <new>

#include "splines/basis_table.hpp"
#include "base/kernel.hpp"
#include "base/parallel.hpp"
#include "splines/row_window.hpp"
#include "splines/sample_row.hpp"
#include "base/text.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;

namespace {

constexpr int W = max_degree + 1;

using detail::check_parameter;
// Rows of basis functions with derivatives up to second order.
using Basis = detail::BasisRow<3>;
std::vector<Basis> bases(const KnotVector& k, std::span<const double> ts, int nd, const char* dir) {
  return detail::basis_table<3>(k, ts, nd, dir);
}

// out[x] = Σ_a w[a] rows[a][x] for x < n: rows of the control net (3 doubles a
// point) weighted by the basis functions of one u. Cubics (4 rows) in one sweep;
// other degrees row by row.
INTERPATCH_KERNEL void weighted_rows(const double* w, int count, const double* const* rows, std::size_t n, double* out) {
  if (count == 4) {
    const double *r0 = rows[0], *r1 = rows[1], *r2 = rows[2], *r3 = rows[3];
    for (std::size_t x = 0; x < n; ++x) out[x] = w[0] * r0[x] + w[1] * r1[x] + w[2] * r2[x] + w[3] * r3[x];
    return;
  }
  for (std::size_t x = 0; x < n; ++x) out[x] = w[0] * rows[0][x];
  for (int a = 1; a < count; ++a) {
    const double c = w[a];
    const double* r = rows[a];
    for (std::size_t x = 0; x < n; ++x) out[x] += c * r[x];
  }
}

// The points of one u row from the row of the net contracted over u (3 doubles a
// point, one of slack after them): detail::sample_points.
INTERPATCH_KERNEL void sample_row(const int* spans, const double* weights, int q, std::size_t nv, const double* row,
                                  double* out) {
  detail::sample_by_degree<3>(spans, weights, q, nv, row, out);
}

// A line of homogeneous control points along u at column j (or along v at row i).
BSplineCurve line(const KnotVector& k, const PointGrid& cp, const Grid<double, 2>& w, std::size_t fixed, int axis) {
  const std::size_t n = cp.extent(static_cast<std::size_t>(axis));
  std::vector<Vec3> pts(n);
  std::vector<double> ws;
  if (!w.empty()) ws.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    pts[i] = axis == 0 ? cp(i, fixed) : cp(fixed, i);
    if (!w.empty()) ws[i] = axis == 0 ? w(i, fixed) : w(fixed, i);
  }
  return BSplineCurve(k, std::move(pts), std::move(ws));
}

// Applies a curve operation to every line along `axis` and reassembles the net.
template <class Op>
BSplineSurface along(const BSplineSurface& s, int axis, Op op) {
  const auto& cp = s.control_points();
  const auto& w = s.weights();
  const KnotVector& k = axis == 0 ? s.knots_u() : s.knots_v();
  const std::size_t lines = cp.extent(axis == 0 ? 1 : 0);
  std::vector<BSplineCurve> out;
  out.reserve(lines);
  for (std::size_t l = 0; l < lines; ++l) out.push_back(op(line(k, cp, w, l, axis)));
  const std::size_t n = out.front().control_points().size();
  PointGrid ncp(axis == 0 ? PointGrid::shape_type{n, lines} : PointGrid::shape_type{lines, n});
  Grid<double, 2> nw;
  if (s.rational()) nw = Grid<double, 2>(ncp.shape());
  for (std::size_t l = 0; l < lines; ++l)
    for (std::size_t i = 0; i < n; ++i) {
      (axis == 0 ? ncp(i, l) : ncp(l, i)) = out[l].control_points()[i];
      if (s.rational()) (axis == 0 ? nw(i, l) : nw(l, i)) = out[l].weights()[i];
    }
  const KnotVector& nk = out.front().knots();
  return axis == 0 ? BSplineSurface(nk, s.knots_v(), std::move(ncp), std::move(nw))
                   : BSplineSurface(s.knots_u(), nk, std::move(ncp), std::move(nw));
}

}  // namespace

BSplineSurface::BSplineSurface(KnotVector knots_u, KnotVector knots_v, PointGrid control_points,
                               Grid<double, 2> weights)
    : ku_(std::move(knots_u)), kv_(std::move(knots_v)), cp_(std::move(control_points)), w_(std::move(weights)) {
  const auto nu = static_cast<std::size_t>(ku_.count()), nv = static_cast<std::size_t>(kv_.count());
  if (cp_.extent(0) != nu || cp_.extent(1) != nv)
    fail(errc::size_mismatch, "knots need ", nu, " x ", nv, " control points, got ", cp_.extent(0), " x ",
         cp_.extent(1));
  if (!w_.empty() && (w_.extent(0) != nu || w_.extent(1) != nv))
    fail(errc::size_mismatch, nu, " x ", nv, " control points need as many weights, got ", w_.extent(0), " x ",
         w_.extent(1));
  if (const std::size_t k = detail::first_non_finite(cp_.data(), cp_.size()); k < cp_.size())
    fail(errc::not_finite, "control point [", k / nv, "][", k % nv, "] is ", cp_.data()[k]);
  if (!w_.empty())
    for (std::size_t i = 0; i < nu; ++i)
      for (std::size_t j = 0; j < nv; ++j) {
        if (!std::isfinite(w_(i, j))) fail(errc::not_finite, "weight [", i, "][", j, "] is ", w_(i, j));
        if (!(w_(i, j) > 0))
          fail(errc::invalid_weight, "weight [", i, "][", j, "] is ", w_(i, j), "; weights must be positive");
      }
}

Vec3 BSplineSurface::point(double u, double v) const {
  // derivative(u, v, 0, 0) without its tables of derivatives (twice as fast, which a check
  // of every point of a large fit feels), the same sums in the same order.
  check_parameter(ku_, u, "u");
  check_parameter(kv_, v, "v");
  u = ku_.periodic() ? ku_.wrap(u) : std::clamp(u, ku_.front(), ku_.back());
  v = kv_.periodic() ? kv_.wrap(v) : std::clamp(v, kv_.front(), kv_.back());
  const int p = degree_u(), q = degree_v();
  const int su = ku_.find_span(u), sv = kv_.find_span(v);
  double Nu[W], Nv[W];
  ku_.basis(su, u, Nu);
  kv_.basis(sv, v, Nv);
  Vec3 a{};
  double wsum = 0;
  for (int i = 0; i <= p; ++i) {
    if (Nu[i] == 0.0) continue;
    const auto ii = static_cast<std::size_t>(ku_.wrap_index(su - p + i));
    for (int j = 0; j <= q; ++j) {
      const auto jj = static_cast<std::size_t>(kv_.wrap_index(sv - q + j));
      const double c = Nu[i] * Nv[j] * (w_.empty() ? 1.0 : w_(ii, jj));
      a += c * cp_(ii, jj);
      wsum += c;
    }
  }
  return rational() ? a / wsum : a;
}

Vec3 BSplineSurface::derivative(double u, double v, int du, int dv) const {
  check_parameter(ku_, u, "u");
  check_parameter(kv_, v, "v");
  if (du < 0 || dv < 0 || du > max_degree || dv > max_degree)
    fail(errc::invalid_degree, "derivative order (", du, ", ", dv, ") is outside 0..", max_degree);
  u = ku_.periodic() ? ku_.wrap(u) : std::clamp(u, ku_.front(), ku_.back());
  v = kv_.periodic() ? kv_.wrap(v) : std::clamp(v, kv_.front(), kv_.back());
  const int p = degree_u(), q = degree_v();
  const int su = ku_.find_span(u), sv = kv_.find_span(v);
  double Nu[W * W], Nv[W * W];
  ku_.basis_derivatives(su, u, du, Nu);
  kv_.basis_derivatives(sv, v, dv, Nv);
  // Homogeneous partials A^(k,l), w^(k,l) for k <= du, l <= dv; only those used are
  // made (whole W × W arrays of Vec3 would be zeroed on every call, most of a point's cost).
  alignas(Vec3) unsigned char a_store[sizeof(Vec3) * W * W], s_store[sizeof(Vec3) * W * W];
  const auto slot = [](unsigned char* store, int k, int l) { return store + sizeof(Vec3) * static_cast<std::size_t>(k * W + l); };
  const auto A = [&](int k, int l) -> const Vec3& { return *std::launder(reinterpret_cast<const Vec3*>(slot(a_store, k, l))); };
  const auto S = [&](int k, int l) -> const Vec3& { return *std::launder(reinterpret_cast<const Vec3*>(slot(s_store, k, l))); };
  double Wt[W][W];
  for (int k = 0; k <= du; ++k)
    for (int l = 0; l <= dv; ++l) {
      Vec3 a{};
      double wsum = 0;
      for (int i = 0; i <= p; ++i) {
        const double nu_ = Nu[k * (p + 1) + i];
        if (nu_ == 0.0) continue;
        const auto ii = static_cast<std::size_t>(ku_.wrap_index(su - p + i));
        for (int j = 0; j <= q; ++j) {
          const auto jj = static_cast<std::size_t>(kv_.wrap_index(sv - q + j));
          const double c = nu_ * Nv[l * (q + 1) + j] * (w_.empty() ? 1.0 : w_(ii, jj));
          a += c * cp_(ii, jj);
          wsum += c;
        }
      }
      ::new (slot(a_store, k, l)) Vec3(a);
      Wt[k][l] = wsum;
    }
  if (!rational()) return A(du, dv);
  // Quotient rule for surfaces (The NURBS Book eq. 4.20), built up from low orders.
  for (int k = 0; k <= du; ++k)
    for (int l = 0; l <= dv; ++l) {
      Vec3 r = A(k, l);
      double bk = 1;
      for (int i = 0; i <= k; ++i) {
        if (i > 0) bk = bk * (k - i + 1) / i;
        double bl = 1;
        for (int j = 0; j <= l; ++j) {
          if (j > 0) bl = bl * (l - j + 1) / j;
          if (i == 0 && j == 0) continue;
          r -= (bk * bl * Wt[i][j]) * S(k - i, l - j);
        }
      }
      ::new (slot(s_store, k, l)) Vec3(r / Wt[0][0]);
    }
  return S(du, dv);
}

SurfaceDerivatives BSplineSurface::derivatives(double u, double v) const {
  // Second-order partials through the general routine: six small sums, no allocation.
  return {derivative(u, v, 0, 0), derivative(u, v, 1, 0), derivative(u, v, 0, 1),
          derivative(u, v, 2, 0), derivative(u, v, 1, 1), derivative(u, v, 0, 2)};
}

namespace detail {

// The basis functions of the v parameters packed for sample_row.
using VTable = PackedBasis;
VTable v_table(const KnotVector& kv, std::span<const double> vs) { return packed(bases(kv, vs, 0, "v"), kv.degree()); }

// The points of a polynomial surface at the u parameters of the basis rows `bu` and
// the v parameters of `vt`.
void evaluate_rows_on(const KnotVector& ku_, const KnotVector& kv_, const RowWindow& net, const std::vector<Basis>& bu,
                      const VTable& vt, std::span<Vec3> out, const progress_callback& progress) {
  const int p = ku_.degree(), q = kv_.degree();
  const std::size_t ncv = net.row_size;
  const std::size_t nv = vt.spans.size();
  // One parallel region: opening one costs microseconds with pinned threads but up
  // to milliseconds on a loaded machine, where the idle thread spins. Progress is
  // reported by the calling thread (thread 0) from a shared row count.
  [[maybe_unused]] const bool threads = bu.size() * (nv + ncv) >= parallel_min_work;
  std::atomic<std::size_t> done{0};
  detail::RegionProgress report(progress);
  const auto nu = static_cast<long long>(bu.size());
  const std::size_t row_doubles = 3 * ncv;
  // A periodic v: the row's first q points repeated after it, so that spans past
  // the last control point read on (sample_row never wraps).
  const std::size_t wrap_doubles = kv_.periodic() ? 3 * static_cast<std::size_t>(q) : 0;
  detail::ParallelFailure failure;  // allocating a thread's row
#pragma omp parallel if (threads)
  {
    std::vector<double> row;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()),
                    [&] { row.resize(row_doubles + wrap_doubles + 1); });  // one double of slack for sample_row
    const double* rows[W];
    const bool reporter = detail::thread_index() == 0;
#pragma omp for schedule(static, 16)
    for (long long ri = 0; ri < nu; ++ri) {
      if (report.stopped() || failure.failed()) continue;  // stopped by a progress callback or a failure
      const auto i = static_cast<std::size_t>(ri);
      const Basis& b = bu[i];
      for (int a = 0; a <= p; ++a) rows[a] = &net.row(static_cast<std::size_t>(ku_.wrap_index(b.span - p + a)))->x;
      weighted_rows(b.d, p + 1, rows, row_doubles, row.data());
      std::copy_n(row.data(), wrap_doubles, row.data() + row_doubles);
      // Not &out[i * nv].x: with no v values there is no element to index.
      sample_row(vt.spans.data(), vt.weights.data(), q, nv, row.data(), reinterpret_cast<double*>(out.data() + i * nv));
      const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (reporter && d % 64 == 0) report.report(static_cast<double>(d) / static_cast<double>(bu.size()));
    }
  }
  failure.rethrow();
  report.rethrow();
  if (progress) progress(1.0);
}

// The points of a polynomial surface over a grid, its control rows taken from a
// window (the whole net, or the rows one process of a split run holds).
void evaluate_surface_rows(const KnotVector& ku_, const KnotVector& kv_, const RowWindow& net, std::span<const double> us,
                           std::span<const double> vs, std::span<Vec3> out, const progress_callback& progress) {
  const auto bu = bases(ku_, us, 0, "u");  // u checked first, then v, as every evaluation checks
  evaluate_rows_on(ku_, kv_, net, bu, v_table(kv_, vs), out, progress);
}

}  // namespace detail

namespace {

// Rows of a polynomial surface: the v basis functions worked out once.
class PolynomialRows final : public Surface::Rows {
 public:
  PolynomialRows(const BSplineSurface& s, std::span<const double> vs)
      : s_(s), nv_(vs.size()), table_(detail::v_table(s.knots_v(), vs)) {}
  void evaluate_into(std::span<const double> us, std::span<Vec3> out, const progress_callback& progress) const override {
    detail::check_output_size(out.size(), {us.size(), nv_}, "surface evaluation");
    const auto& cp = s_.control_points();
    detail::evaluate_rows_on(s_.knots_u(), s_.knots_v(), {cp.data(), 0, cp.extent(0), cp.extent(0), cp.extent(1)},
                             bases(s_.knots_u(), us, 0, "u"), table_, out, progress);
  }

 private:
  const BSplineSurface& s_;
  std::size_t nv_;
  detail::VTable table_;
};

}  // namespace

std::unique_ptr<Surface::Rows> BSplineSurface::rows(std::span<const double> vs) const {
  if (rational()) return Surface::rows(vs);
  return std::make_unique<PolynomialRows>(*this, vs);
}

void BSplineSurface::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                                   const progress_callback& progress) const {
  detail::check_output_size(out.size(), {us.size(), vs.size()}, "surface evaluation");
  const bool rat = rational();
  const std::size_t ncv = cp_.extent(1);
  if (!rat)
    return detail::evaluate_surface_rows(ku_, kv_, {cp_.data(), 0, cp_.extent(0), cp_.extent(0), ncv}, us, vs, out,
                                         progress);
  const auto bu = bases(ku_, us, 0, "u");
  const auto bv = bases(kv_, vs, 0, "v");
  const int p = degree_u(), q = degree_v();
  const std::size_t nv = vs.size();
  [[maybe_unused]] const bool threads = us.size() * (nv + ncv) >= detail::parallel_min_work;
  std::atomic<std::size_t> done{0};
  detail::RegionProgress report(progress);
  const auto nu = static_cast<long long>(us.size());
  detail::ParallelFailure failure;  // allocating a thread's row
#pragma omp parallel if (threads)
  {
    // One contracted row of homogeneous points per thread, reused for every u.
    std::vector<std::array<double, 4>> row;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] { row.resize(ncv); });
    const KnotVector& kv = kv_;
    const bool reporter = detail::thread_index() == 0;
#pragma omp for schedule(static, 16)
    for (long long ri = 0; ri < nu; ++ri) {
      if (report.stopped() || failure.failed()) continue;  // stopped by a progress callback or a failure
      const auto i = static_cast<std::size_t>(ri);
      const Basis& b = bu[i];
      for (std::size_t l = 0; l < ncv; ++l) {
        double x = 0, y = 0, z = 0, w = 0;
        for (int a = 0; a <= p; ++a) {
          const auto ii = static_cast<std::size_t>(ku_.wrap_index(b.span - p + a));
          const double c = b.d[a] * (rat ? w_(ii, l) : 1.0);
          const Vec3& P = cp_(ii, l);
          x += c * P.x;
          y += c * P.y;
          z += c * P.z;
          w += c;
        }
        row[l] = {x, y, z, w};
      }
      Vec3* o = out.data() + i * nv;
      for (std::size_t j = 0; j < nv; ++j) {
        const Basis& c = bv[j];
        double x = 0, y = 0, z = 0, w = 0;
        for (int k = 0; k <= q; ++k) {
          const auto& h = row[static_cast<std::size_t>(kv.wrap_index(c.span - q + k))];
          x += c.d[k] * h[0];
          y += c.d[k] * h[1];
          z += c.d[k] * h[2];
          w += c.d[k] * h[3];
        }
        o[j] = rat ? Vec3{x / w, y / w, z / w} : Vec3{x, y, z};
      }
      const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (reporter && d % 64 == 0) report.report(static_cast<double>(d) / static_cast<double>(us.size()));
    }
  }
  failure.rethrow();
  report.rethrow();
  if (progress) progress(1.0);
}

Grid<SurfaceDerivatives, 2> BSplineSurface::evaluate_derivatives(std::span<const double> us,
                                                                 std::span<const double> vs) const {
  require_memory(us.size() * vs.size(), sizeof(SurfaceDerivatives), "surface derivative grid");
  const auto bu = bases(ku_, us, 2, "u");
  const auto bv = bases(kv_, vs, 2, "v");
  const int p = degree_u(), q = degree_v();
  const std::size_t ncv = cp_.extent(1);
  const std::size_t nv = vs.size();
  Grid<SurfaceDerivatives, 2> out({us.size(), nv}, for_overwrite);
  const bool rat = rational();
  const auto nu = static_cast<long long>(us.size());
  detail::ParallelFailure failure;  // allocating a thread's rows
#pragma omp parallel if (us.size() * (nv + ncv) >= detail::parallel_min_work)
  {
    // rows[k][l]: the net contracted with the k-th u-derivative of the basis.
    std::vector<std::array<double, 4>> rows[3];
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      for (auto& r : rows) r.resize(ncv);
    });
#pragma omp for schedule(static)
    for (long long ri = 0; ri < nu; ++ri) {
      if (failure.failed()) continue;
      const auto i = static_cast<std::size_t>(ri);
      const Basis& b = bu[i];
      for (int k = 0; k <= 2; ++k)
        for (std::size_t l = 0; l < ncv; ++l) {
          std::array<double, 4> h{0, 0, 0, 0};
          for (int a = 0; a <= p; ++a) {
            const auto ii = static_cast<std::size_t>(ku_.wrap_index(b.span - p + a));
            const double c = b.d[k * (p + 1) + a] * (rat ? w_(ii, l) : 1.0);
            const Vec3& P = cp_(ii, l);
            h[0] += c * P.x;
            h[1] += c * P.y;
            h[2] += c * P.z;
            h[3] += c;
          }
          rows[k][l] = h;
        }
      for (std::size_t j = 0; j < nv; ++j) {
        const Basis& c = bv[j];
        // A[k][l] homogeneous partials for k + l <= 2.
        std::array<double, 4> A[3][3]{};
        for (int k = 0; k <= 2; ++k)
          for (int l = 0; l + k <= 2; ++l) {
            std::array<double, 4> h{0, 0, 0, 0};
            for (int m = 0; m <= q; ++m) {
              const double f = c.d[l * (q + 1) + m];
              const auto& r = rows[k][static_cast<std::size_t>(kv_.wrap_index(c.span - q + m))];
              for (int e = 0; e < 4; ++e) h[static_cast<std::size_t>(e)] += f * r[static_cast<std::size_t>(e)];
            }
            A[k][l] = h;
          }
        auto vec = [](const std::array<double, 4>& h) { return Vec3{h[0], h[1], h[2]}; };
        SurfaceDerivatives& d = out(i, j);
        if (!rat) {
          d = {vec(A[0][0]), vec(A[1][0]), vec(A[0][1]), vec(A[2][0]), vec(A[1][1]), vec(A[0][2])};
          continue;
        }
        const double w = A[0][0][3], wu = A[1][0][3], wv = A[0][1][3];
        const double wuu = A[2][0][3], wuv = A[1][1][3], wvv = A[0][2][3];
        const Vec3 s = vec(A[0][0]) / w;
        const Vec3 su = (vec(A[1][0]) - wu * s) / w;
        const Vec3 sv = (vec(A[0][1]) - wv * s) / w;
        const Vec3 suu = (vec(A[2][0]) - 2 * wu * su - wuu * s) / w;
        const Vec3 suv = (vec(A[1][1]) - wu * sv - wv * su - wuv * s) / w;
        const Vec3 svv = (vec(A[0][2]) - 2 * wv * sv - wvv * s) / w;
        d = {s, su, sv, suu, suv, svv};
      }
    }
  }
  failure.rethrow();
  return out;
}

BSplineSurface BSplineSurface::refined(std::span<const double> knots_u, std::span<const double> knots_v) const {
  BSplineSurface s = *this;
  if (!knots_u.empty()) s = along(s, 0, [&](const BSplineCurve& c) { return c.refined(knots_u); });
  if (!knots_v.empty()) s = along(s, 1, [&](const BSplineCurve& c) { return c.refined(knots_v); });
  return s;
}

BSplineSurface BSplineSurface::elevated(int tu, int tv) const {
  BSplineSurface s = *this;
  if (tu > 0) s = along(s, 0, [&](const BSplineCurve& c) { return c.elevated(tu); });
  if (tv > 0) s = along(s, 1, [&](const BSplineCurve& c) { return c.elevated(tv); });
  return s;
}

BSplineSurface BSplineSurface::clamped() const {
  BSplineSurface s = *this;
  if (ku_.periodic()) s = along(s, 0, [](const BSplineCurve& c) { return c.clamped(); });
  if (kv_.periodic()) s = along(s, 1, [](const BSplineCurve& c) { return c.clamped(); });
  return s;
}

BSplineSurface BSplineSurface::mapped(double u0, double u1, double v0, double v1) const {
  return BSplineSurface(ku_.mapped(u0, u1), kv_.mapped(v0, v1), cp_, w_);
}

}  // namespace interpatch
