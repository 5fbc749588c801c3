#pragma once
// The least-squares fit of a grid of points, private to the approximation: what the
// single process's fit (src/constructions/approximate/approximate.cpp: approximate_curve, approximate_surface,
// approximate_volume) and the fit split between processes (src/constructions/approximate/approximate_rows.cpp:
// detail::approximate_rows) share. The split run calls these very functions on its
// blocks, so that both find the same control points.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "constructions/approximate/approx_check.hpp"
#include "linalg/banded.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::approx {

// ------------------------------------------------------------------ data
//
// Every array of points or control points is a C-order array of doubles whose last
// axis holds the 3 coordinates; shapes count points, not doubles.

template <std::size_t R>
using Shape = std::array<std::size_t, R>;

template <std::size_t R>
std::size_t count_of(const Shape<R>& s) {
  std::size_t n = 1;
  for (auto e : s) n *= e;
  return n;
}

constexpr const char* axis_name(std::size_t a) { return a == 0 ? "u" : (a == 1 ? "v" : "w"); }

inline bool is_missing(const Vec3& q) { return std::isnan(q.x) || std::isnan(q.y) || std::isnan(q.z); }

template <std::size_t R>
std::string index_text(std::size_t flat, const Shape<R>& s) {
  std::string at;
  for (std::size_t a = R; a-- > 0; flat /= s[a]) at = detail::cat("[", flat % s[a], "]", at);
  return at;
}

template <std::size_t R>
std::vector<std::size_t> unflatten(std::size_t flat, const Shape<R>& s) {
  std::vector<std::size_t> idx(R);
  for (std::size_t a = R; a-- > 0; flat /= s[a]) idx[a] = flat % s[a];
  return idx;
}

// The data as the fit sees it: points, each point's weight (0 where missing).
template <std::size_t R>
struct Data {
  Shape<R> shape{};
  Grid<Vec3, R> points;
  std::vector<double> weight;  // empty: every point present with weight 1
  std::size_t missing = 0;
  std::size_t present = 0;  // points with a positive weight
  double weight_sum = 0;
  [[nodiscard]] bool uniform() const { return weight.empty(); }
  [[nodiscard]] double w(std::size_t i) const { return weight.empty() ? 1.0 : weight[i]; }
};

// ------------------------------------------------------------------ one direction

// A band of a symmetric matrix along one direction: entry (i, i + d) for |d| <= h,
// the column taken modulo c in a closed direction.
struct Band {
  int c = 0, h = 0;
  std::vector<double> v;  // c × (2h + 1)
  Band() = default;
  Band(int count, int half) : c(count), h(half), v(static_cast<std::size_t>(count) * static_cast<std::size_t>(2 * half + 1), 0.0) {}
  double& at(int i, int d) { return v[static_cast<std::size_t>(i) * static_cast<std::size_t>(2 * h + 1) + static_cast<std::size_t>(d + h)]; }
  [[nodiscard]] double at(int i, int d) const {
    return v[static_cast<std::size_t>(i) * static_cast<std::size_t>(2 * h + 1) + static_cast<std::size_t>(d + h)];
  }
};

struct Axis {
  std::size_t n = 0;  // data points along it
  int p = 1;
  bool periodic = false;
  std::vector<double> t;  // data parameters
  KnotVector knots = KnotVector::bezier(1);
  int c = 0;                 // control points
  std::vector<int> first;    // per data point: its first basis function (unwrapped)
  std::vector<double> b;     // per data point: p + 1 basis values
  std::vector<int> interval; // per data point: the knot interval it lies in
  int intervals = 0;

  [[nodiscard]] std::size_t col(int i) const { return static_cast<std::size_t>(i >= c ? i - c : i); }

  void set_knots(KnotVector k) {
    knots = std::move(k);
    c = knots.count();
    const auto pp = static_cast<std::size_t>(p) + 1;
    first.assign(n, 0);
    b.assign(n * pp, 0.0);
    interval.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const double x = knots.periodic() ? knots.wrap(t[i]) : std::clamp(t[i], knots.front(), knots.back());
      const int span = knots.find_span(x);
      knots.basis(span, x, &b[i * pp]);
      first[i] = span - p;
      interval[i] = span - p;
    }
    intervals = periodic ? c : c - p;
  }

  // The Gram matrix Σ_i B(t_i) B(t_i)ᵀ of the basis at the data parameters.
  [[nodiscard]] Band gram(int h) const {
    Band g(c, h);
    const auto pp = static_cast<std::size_t>(p) + 1;
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k <= p; ++k)
        for (int l = 0; l <= p; ++l)
          g.at(static_cast<int>(col(first[i] + k)), l - k) += b[i * pp + static_cast<std::size_t>(k)] * b[i * pp + static_cast<std::size_t>(l)];
    return g;
  }

  // Σ ω_i d_i d_iᵀ: d_i the second divided difference of the control polygon at
  // Greville abscissa i, ω_i half the distance of its neighbours (∫ f''² in effect).
  [[nodiscard]] Band fairness(int h) const {
    Band r(c, h);
    const auto& u = knots.values();
    auto greville = [&](int i) {  // i may be -1 or c in a closed direction
      const double period = knots.back() - knots.front();
      const int j = i < 0 ? i + c : (i >= c ? i - c : i);
      double s = 0;
      for (int k = 1; k <= p; ++k) s += u[static_cast<std::size_t>(j + k)];
      return s / p + (i < 0 ? -period : (i >= c ? period : 0.0));
    };
    const int lo = periodic ? 0 : 1, hi = periodic ? c : c - 1;
    for (int i = lo; i < hi; ++i) {
      const double g0 = greville(i - 1), g1 = greville(i), g2 = greville(i + 1);
      const double h1 = g1 - g0, h2 = g2 - g1, span = g2 - g0;
      if (!(h1 > 0 && h2 > 0)) continue;  // coincident abscissae: no curvature to measure there
      const double alpha = 2.0 / span, omega = 0.5 * span;
      const double d[3] = {alpha / h1, -alpha * (1.0 / h1 + 1.0 / h2), alpha / h2};
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) {
          const int row = i - 1 + k;
          r.at(static_cast<int>(col(row < 0 ? row + c : row)), l - k) += omega * d[k] * d[l];
        }
    }
    return r;
  }
};

using AxisSolver = std::variant<detail::BandedLU, detail::CyclicLU>;

// The factored Gram matrix of a direction (the least-squares system along it).
AxisSolver factor_gram(const Axis& ax, std::size_t a);

// ------------------------------------------------------------------ tensor passes

// Passes with fewer multiply-adds than this stay on the calling thread: a fit to a
// tolerance makes a few dozen passes, the early ones over a thinned grid, and a
// parallel region costs as much as a few hundred thousand multiply-adds (more when
// the machine is shared and a thread waits for the other to be scheduled).
constexpr std::size_t parallel_work = detail::parallel_min_work * 16;

// Runs f(o, c0, c1) over blocks of `outer` slabs × columns [c0, c1) of `width`
// doubles, in parallel when there is enough work. Every number is computed by the
// same operations whatever the thread count. f must not throw (it only multiplies
// and adds into memory its caller allocated).
template <class F>
void for_blocks(std::size_t outer, std::size_t width, std::size_t work, const F& f) {
  constexpr std::size_t chunk = 2048;
  const std::size_t per = outer >= 8 ? 1 : (width + chunk - 1) / chunk;
  const auto tasks = static_cast<long long>(outer * per);
#pragma omp parallel for schedule(static) if (work >= parallel_work)
  for (long long k = 0; k < tasks; ++k) {
    const auto task = static_cast<std::size_t>(k);
    const std::size_t o = task / per, part = task % per;
    const std::size_t c0 = per == 1 ? 0 : part * chunk, c1 = per == 1 ? width : std::min(width, c0 + chunk);
    f(o, c0, c1);
  }
}

// One pass of the basis matrix B (n × c) of direction a over an array: out = Bᵀ in
// (Transpose: `in` has shape[a] = n, out gets c) or out = B in (c to n). Both walk
// the data rows i and their p + 1 basis functions; whole slabs of the other axes
// move at once.
template <bool Transpose, std::size_t R>
void basis_pass(const Axis& ax, const double* in, Shape<R>& shape, std::size_t a, std::vector<double>& out) {
  std::size_t outer = 1, inner = 3;
  for (std::size_t x = 0; x < a; ++x) outer *= shape[x];
  for (std::size_t x = a + 1; x < R; ++x) inner *= shape[x];
  const std::size_t n = ax.n, c = static_cast<std::size_t>(ax.c), pp = static_cast<std::size_t>(ax.p) + 1;
  const std::size_t in_rows = Transpose ? n : c, out_rows = Transpose ? c : n;
  if (Transpose) out.assign(outer * out_rows * inner, 0.0);
  else out.resize(outer * out_rows * inner);
  double* o_ = out.data();
  for_blocks(outer, inner, outer * n * inner * pp, [&](std::size_t o, std::size_t c0, std::size_t c1) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!Transpose) std::fill(o_ + (o * n + i) * inner + c0, o_ + (o * n + i) * inner + c1, 0.0);
      for (std::size_t k = 0; k < pp; ++k) {
        const double w = ax.b[i * pp + k];
        const std::size_t j = ax.col(ax.first[i] + static_cast<int>(k));
        const double* src = in + (o * in_rows + (Transpose ? i : j)) * inner;
        double* dst = o_ + (o * out_rows + (Transpose ? j : i)) * inner;
        for (std::size_t x = c0; x < c1; ++x) dst[x] += w * src[x];
      }
    }
  });
  shape[a] = out_rows;
}

// ------------------------------------------------------------------ solvers

// The normal equations of the control points as a sparse symmetric matrix: entries
// of control point k with its neighbours k + δ, |δ_a| <= h_a, gathered in a stencil
// per control point and handed to the sparse Cholesky decomposition.
template <std::size_t R>
struct Stencil {
  Shape<R> c{}, half{}, stride{};  // stride of an offset code per direction
  std::size_t size = 1, count = 1;
  std::vector<double> v;  // count × size

  explicit Stencil(const std::array<Axis, R>& axes) {
    for (std::size_t a = R; a-- > 0;) {
      c[a] = static_cast<std::size_t>(axes[a].c);
      half[a] = static_cast<std::size_t>(std::max(axes[a].p, 2));
      stride[a] = size;
      size *= 2 * half[a] + 1;
      count *= c[a];
    }
    require_memory(count * size, sizeof(double), "the normal equations of the control points");
    v.assign(count * size, 0.0);
  }

  // Kronecker product of one band per direction, scaled, added in.
  void add_kronecker(const std::array<const Band*, R>& bands, double scale) {
    for (std::size_t k = 0; k < count; ++k) {
      const std::vector<std::size_t> idx = unflatten<R>(k, c);
      for (std::size_t code = 0; code < size; ++code) {
        double prod = scale;
        for (std::size_t a = 0; a < R && prod != 0.0; ++a) {
          const int d = static_cast<int>((code / stride[a]) % (2 * half[a] + 1)) - static_cast<int>(half[a]);
          prod = std::abs(d) <= bands[a]->h ? prod * bands[a]->at(static_cast<int>(idx[a]), d) : 0.0;
        }
        v[k * size + code] += prod;
      }
    }
  }

  Eigen::SparseMatrix<double> lower(const std::array<Axis, R>& axes) const {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(count * (size / 2 + 1));
    for (std::size_t k = 0; k < count; ++k) {
      const std::vector<std::size_t> idx = unflatten<R>(k, c);
      for (std::size_t code = 0; code < size; ++code) {
        const double val = v[k * size + code];
        if (val == 0.0) continue;
        std::size_t col = 0;
        bool inside = true;
        for (std::size_t a = 0; a < R; ++a) {
          const long long d = static_cast<long long>((code / stride[a]) % (2 * half[a] + 1)) - static_cast<long long>(half[a]);
          long long j = static_cast<long long>(idx[a]) + d;
          const auto ca = static_cast<long long>(c[a]);
          if (axes[a].periodic) j = ((j % ca) + ca) % ca;
          else if (j < 0 || j >= ca) inside = false;
          col = col * c[a] + static_cast<std::size_t>(std::max(j, 0LL));
        }
        if (inside && col <= k) trip.emplace_back(static_cast<int>(k), static_cast<int>(col), val);
      }
    }
    Eigen::SparseMatrix<double> m(static_cast<Eigen::Index>(count), static_cast<Eigen::Index>(count));
    m.setFromTriplets(trip.begin(), trip.end());
    return m;
  }
};

// Σ_i w_i B(t_i) B(t_i)ᵀ over the points, the tensor basis of each point expanded.
// Points [first, first + count) in storage order, into v (a stencil's values):
// the same additions in the same order whichever block of the points a process holds.
// Only the stencil rows (control points) `keep` accepts are added to.
template <std::size_t R, class Weight, class Keep>
void add_weighted_points(double* v_, const Stencil<R>& st, const std::array<Axis, R>& axes, const Shape<R>& shape,
                         std::size_t first, std::size_t count, const Weight& weight, const Keep& keep) {
  std::array<std::size_t, R> pp{};
  std::size_t support = 1;
  for (std::size_t a = 0; a < R; ++a) {
    pp[a] = static_cast<std::size_t>(axes[a].p) + 1;
    support *= pp[a];
  }
  std::vector<double> val(support);
  std::vector<std::size_t> row(support), code(support);
  for (std::size_t i = first; i < first + count; ++i) {
    const double w = weight(i);
    if (!(w > 0)) continue;
    std::array<std::size_t, R> idx{};
    for (std::size_t a = R, rest = i; a-- > 0; rest /= shape[a]) idx[a] = rest % shape[a];
    for (std::size_t s = 0; s < support; ++s) {
      double v = w;
      std::size_t r = 0, cd = 0;
      for (std::size_t a = 0, rest = s; a < R; ++a) {
        const std::size_t div = support / [&] {
          std::size_t q = 1;
          for (std::size_t x = 0; x <= a; ++x) q *= pp[x];
          return q;
        }();
        const std::size_t k = (rest / div) % pp[a];
        const Axis& ax = axes[a];
        v *= ax.b[idx[a] * pp[a] + k];
        r = r * st.c[a] + ax.col(ax.first[idx[a]] + static_cast<int>(k));
        cd += k * st.stride[a];
      }
      val[s] = v;
      row[s] = r;
      code[s] = cd;
    }
    std::size_t centre = 0;
    for (std::size_t a = 0; a < R; ++a) centre += st.half[a] * st.stride[a];
    for (std::size_t s = 0; s < support; ++s) {
      if (val[s] == 0.0 || !keep(row[s])) continue;
      double* dst = v_ + row[s] * st.size + centre - code[s];
      // x / 1 is x exactly: the division only where a weight is not 1.
      if (w == 1.0)
        for (std::size_t t = 0; t < support; ++t) dst[code[t]] += val[s] * val[t];
      else
        for (std::size_t t = 0; t < support; ++t) dst[code[t]] += val[s] * val[t] / w;
    }
  }
}

template <std::size_t R>
void add_weighted_data(Stencil<R>& st, const std::array<Axis, R>& axes, const Data<R>& d) {
  add_weighted_points<R>(st.v.data(), st, axes, d.shape, 0, d.points.size(), [&](std::size_t i) { return d.w(i); },
                         [](std::size_t) { return true; });
}

// The data term of points all present with weight 1: the Kronecker product of the
// directions' Gram matrices.
template <std::size_t R>
void add_grams(Stencil<R>& st, const std::array<Axis, R>& axes) {
  std::array<Band, R> g;
  std::array<const Band*, R> bands{};
  for (std::size_t a = 0; a < R; ++a) {
    g[a] = axes[a].gram(axes[a].p);
    bands[a] = &g[a];
  }
  st.add_kronecker(bands, 1.0);
}

// The sparse normal equations G + λ s K: G the data term, K the fairness term
// (Σ_a n_a R_a ⊗ the Gram matrices of the other directions), s = Σw / N.
template <std::size_t R>
struct SparseSystem {
  Eigen::SparseMatrix<double> data, fairness;
  double scale = 0;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool analyzed = false;

  SparseSystem(const std::array<Axis, R>& axes, const Data<R>& d)
      : SparseSystem(axes, data_term(axes, d), d.weight_sum, count_of<R>(d.shape)) {}

  // The data term as a stencil: with every point present and of weight 1, the
  // Kronecker product of the Gram matrices; otherwise summed over the points.
  static Stencil<R> data_term(const std::array<Axis, R>& axes, const Data<R>& d) {
    Stencil<R> st(axes);
    if (d.uniform()) add_grams<R>(st, axes);
    else add_weighted_data<R>(st, axes, d);
    return st;
  }

  // `points` data points of total weight `weight_sum`.
  SparseSystem(const std::array<Axis, R>& axes, const Stencil<R>& data_stencil, double weight_sum, std::size_t points) {
    std::array<Band, R> gram, fair;
    for (std::size_t a = 0; a < R; ++a) {
      gram[a] = axes[a].gram(axes[a].p);
      fair[a] = axes[a].fairness(2);
    }
    data = data_stencil.lower(axes);
    Stencil<R> k(axes);
    for (std::size_t a = 0; a < R; ++a) {
      std::array<const Band*, R> bands{};
      for (std::size_t b = 0; b < R; ++b) bands[b] = b == a ? &fair[b] : &gram[b];
      k.add_kronecker(bands, static_cast<double>(axes[a].n));
    }
    fairness = k.lower(axes);
    scale = weight_sum / static_cast<double>(points);
  }

  void factor(double lambda) {
    Eigen::SparseMatrix<double> m = data;
    if (lambda > 0) m += (lambda * scale) * fairness;
    if (!analyzed) {
      ldlt.analyzePattern(m);
      analyzed = true;
    }
    ldlt.factorize(m);
    bool ok = ldlt.info() == Eigen::Success;
    // A positive definite matrix has positive pivots; one at or below 1e-14 of the
    // largest (rounding) means no unique solution.
    const double largest = ok ? ldlt.vectorD().cwiseAbs().maxCoeff() : 0.0;
    for (Eigen::Index i = 0; i < ldlt.vectorD().size() && ok; ++i) ok = ldlt.vectorD()[i] > 1e-14 * largest;
    if (!ok)
      fail(errc::singular, "the least-squares system of ", m.rows(),
           " control points has no unique solution: some control points have no data under them and no fairness "
           "term to fix them");
  }

  // The ratio of the data term's diagonal to the fairness term's: what makes λ s K
  // a given fraction of the data term.
  [[nodiscard]] double diagonal_ratio() const {
    const double k = fairness.diagonal().sum() * scale;
    return k > 0 ? data.diagonal().sum() / k : 0.0;
  }

  std::vector<double> solve(const std::vector<double>& rhs) const {
    const auto n = data.rows();
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> b(rhs.data(), n, 3);
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> x = ldlt.solve(Eigen::MatrixXd(b));
    return {x.data(), x.data() + x.size()};
  }

  // tr(M⁻¹ λ s K) = C − tr(M⁻¹ G), M = G + λ s K: the control points minus the
  // degrees of freedom of the fit, by Hutchinson's estimator, the mean of
  // zᵀ M⁻¹ λ s K z over random ±1 vectors z (a fixed seed: the same value on every
  // run). Estimating this part rather than tr(M⁻¹ G) keeps the estimate's error
  // (of the order of its Frobenius norm) small where it is small: near
  // interpolation, where n − tr H is the small difference that decides the score.
  [[nodiscard]] double fairness_trace(double lambda, int probes) const {
    const auto n = data.rows();
    std::mt19937_64 rng(20261124);
    double sum = 0;
    for (int k = 0; k < probes; ++k) {
      Eigen::VectorXd z(n);
      for (Eigen::Index i = 0; i < n; ++i) z[i] = (rng() & 1) != 0 ? 1.0 : -1.0;
      const Eigen::VectorXd kz = fairness.selfadjointView<Eigen::Lower>() * z;
      sum += z.dot(ldlt.solve(kz));
    }
    return lambda * scale * sum / probes;
  }
};

// ------------------------------------------------------------------ parameters and knots

// Uniform parameters of n points: evenly spaced over [0, 1] (closed: n steps, the
// last one back to the first at 1).
std::vector<double> uniform_parameters(std::size_t n, bool closed);

// Parameters from the chords summed per step over the lines (sum[k]: step k to
// k + 1, used[k] lines adding to it).
std::vector<double> parameters_from_sums(std::vector<double> sum, const std::vector<std::size_t>& used, std::size_t n,
                                         std::size_t a, Parametrization param, bool closed);

// The chord from p0 to p1 added to a step's sum when both are present.
inline void add_chord(const Vec3& p0, const Vec3& p1, double& sum, std::size_t& used) {
  if (is_missing(p0) || is_missing(p1)) return;
  sum += distance(p0, p1);
  ++used;
}

// Knots of a clamped spline with the given interior knots over [t.front(), t.back()].
KnotVector clamped_knots(const Axis& ax, const std::vector<double>& interior);

// The interior knots (open) or the period's knots (closed) of `c` control points
// for least squares over the data parameters. Open: c parameters spread evenly over
// the data's order (linear between data parameters), and interpolation's knots
// averaged from them (The NURBS Book eq. 9.8): every basis function has data under
// the middle of its support, so the normal equations stay as well conditioned as
// interpolation's whatever c (The NURBS Book eq. 9.69 reaches condition numbers of
// 1e16 as c nears the point count, and a fit then swings between the data). With as
// many control points as data, interpolation's knots. Closed: evenly spaced in the
// data's order, shifted by half a step for an even degree.
std::vector<double> least_squares_breaks(const Axis& ax, int c);

KnotVector knots_from_breaks(const Axis& ax, const std::vector<double>& breaks);

// ------------------------------------------------------------------ errors

template <std::size_t R>
struct Residuals {
  double max = -1, sum_sq = 0, weighted_sq = 0;
  std::size_t worst = 0;
  std::array<std::vector<double>, R> interval_max;
  std::array<std::vector<std::size_t>, R> interval_worst;

  explicit Residuals(const std::array<Axis, R>& axes) {
    for (std::size_t a = 0; a < R; ++a) {
      interval_max[a].assign(static_cast<std::size_t>(axes[a].intervals), -1.0);
      interval_worst[a].assign(static_cast<std::size_t>(axes[a].intervals), 0);
    }
  }
  // Another block's, of later points: the same result as one pass in storage order.
  void merge(const Residuals& o) {
    sum_sq += o.sum_sq;
    weighted_sq += o.weighted_sq;
    if (o.max > max) {
      max = o.max;
      worst = o.worst;
    }
    for (std::size_t a = 0; a < R; ++a)
      for (std::size_t k = 0; k < interval_max[a].size(); ++k)
        if (o.interval_max[a][k] > interval_max[a][k]) {
          interval_max[a][k] = o.interval_max[a][k];
          interval_worst[a][k] = o.interval_worst[a][k];
        }
  }
};

// Residuals of data rows [q0, q1) (every index but the last fixed; row q of
// `partial` at partial + (q − base)·3c, of the points at pts + (q − base)·n): the
// distances, their sums in row order and the maxima, into r. off[i·(p+1) + k]: where
// basis function k of point i along the last axis finds its control point's
// coordinates in a row of `partial` (residual_offsets); `row` and `e2` are scratch
// of 3n and n doubles.
template <std::size_t R, class Weight>
void residual_rows(Residuals<R>& r, const std::array<Axis, R>& axes, const Shape<R>& shape, const double* partial,
                   const Vec3* pts_, std::size_t base, std::size_t q0, std::size_t q1, const Weight& weight,
                   const std::size_t* off, double* row, double* e2) {
  const Axis& last = axes[R - 1];
  const std::size_t n = last.n, c = static_cast<std::size_t>(last.c), pp = static_cast<std::size_t>(last.p) + 1;
  for (std::size_t q = q0; q < q1; ++q) {
    const double* src = partial + (q - base) * c * 3;
    for (std::size_t i = 0; i < n; ++i) {
      double x = 0, y = 0, z = 0;
      for (std::size_t k = 0; k < pp; ++k) {
        const double w = last.b[i * pp + k];
        const double* v = src + off[i * pp + k];
        x += w * v[0];
        y += w * v[1];
        z += w * v[2];
      }
      row[3 * i] = x, row[3 * i + 1] = y, row[3 * i + 2] = z;
    }
    // Squared distances first (a loop the compiler vectorizes), then the maxima:
    // of the row for the axes before the last, per interval along the last.
    const Vec3* pts = pts_ + (q - base) * n;
    for (std::size_t i = 0; i < n; ++i) {
      const double dx = row[3 * i] - pts[i].x, dy = row[3 * i + 1] - pts[i].y, dz = row[3 * i + 2] - pts[i].z;
      e2[i] = dx * dx + dy * dy + dz * dz;
    }
    double row_max = -1;
    std::size_t row_worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double w = weight(q * n + i);
      if (!(w > 0)) continue;
      r.sum_sq += e2[i];
      r.weighted_sq += w * e2[i];
      if (e2[i] > row_max) {
        row_max = e2[i];
        row_worst = i;
      }
      auto& m = r.interval_max[R - 1][static_cast<std::size_t>(last.interval[i])];
      if (e2[i] > m) {
        m = e2[i];
        r.interval_worst[R - 1][static_cast<std::size_t>(last.interval[i])] = q * n + i;
      }
    }
    if (row_max < 0) continue;  // every point of the row missing
    const std::size_t flat = q * n + row_worst;
    if (row_max > r.max) {
      r.max = row_max;
      r.worst = flat;
    }
    for (std::size_t a = R - 1, rest = q; a-- > 0; rest /= shape[a]) {
      const auto k = static_cast<std::size_t>(axes[a].interval[rest % shape[a]]);
      if (row_max > r.interval_max[a][k]) {
        r.interval_max[a][k] = row_max;
        r.interval_worst[a][k] = flat;
      }
    }
  }
}

std::vector<std::size_t> residual_offsets(const Axis& last);

// Data rows are taken in blocks of this many, each block's sums formed on its own
// and the blocks' added in order (in one process as in a split run).
constexpr std::size_t residual_block_rows = 16;

// Residuals of data rows [q0, q1) (row q of `partial` at partial + (q − base)·3c, of
// the points at pts + (q − base)·n, as residual_rows): blocks of
// residual_block_rows rows from q0 in parallel, merged in order.
template <std::size_t R, class Weight>
Residuals<R> residual_blocks(const std::array<Axis, R>& axes, const Shape<R>& shape, const double* partial, const Vec3* pts,
                             std::size_t base, std::size_t q0, std::size_t q1, const Weight& weight) {
  const std::size_t n = axes[R - 1].n, pp = static_cast<std::size_t>(axes[R - 1].p) + 1;
  const std::size_t blocks = (q1 - q0 + residual_block_rows - 1) / residual_block_rows;
  std::vector<Residuals<R>> part(blocks, Residuals<R>(axes));
  const auto nb = static_cast<long long>(blocks);
  const std::vector<std::size_t> off = residual_offsets(axes[R - 1]);
  detail::ParallelFailure failure;  // allocating a thread's scratch
#pragma omp parallel if ((q1 - q0) * n * pp * 3 >= parallel_work)
  {
    std::vector<double> row, e2;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      row.resize(3 * n);
      e2.resize(n);
    });
#pragma omp for schedule(static)
    for (long long bi = 0; bi < nb; ++bi) {
      if (failure.failed()) continue;
      const std::size_t b0 = q0 + static_cast<std::size_t>(bi) * residual_block_rows;
      residual_rows<R>(part[static_cast<std::size_t>(bi)], axes, shape, partial, pts, base, b0,
                       std::min(q1, b0 + residual_block_rows), weight, off.data(), row.data(), e2.data());
    }
  }
  failure.rethrow();
  Residuals<R> all(axes);
  for (const auto& r : part) all.merge(r);
  return all;
}

// Squares were compared; distances are reported.
template <std::size_t R>
void take_roots(Residuals<R>& r) {
  r.max = r.max < 0 ? 0.0 : std::sqrt(r.max);
  for (std::size_t a = 0; a < R; ++a)
    for (double& m : r.interval_max[a]) m = m < 0 ? m : std::sqrt(m);
}

// S at one data point (its flat index), from the control net.
template <std::size_t R>
Vec3 value_at(const std::array<Axis, R>& axes, const std::vector<double>& cp, std::size_t flat, const Shape<R>& data_shape) {
  const std::vector<std::size_t> idx = unflatten<R>(flat, data_shape);
  std::array<std::size_t, R> pp{}, k{};
  for (std::size_t a = 0; a < R; ++a) pp[a] = static_cast<std::size_t>(axes[a].p) + 1;
  Vec3 s{};
  for (;;) {
    double w = 1;
    std::size_t at = 0;
    for (std::size_t a = 0; a < R; ++a) {
      const Axis& ax = axes[a];
      w *= ax.b[idx[a] * pp[a] + k[a]];
      at = at * static_cast<std::size_t>(ax.c) + ax.col(ax.first[idx[a]] + static_cast<int>(k[a]));
    }
    s = s + w * Vec3{cp[3 * at], cp[3 * at + 1], cp[3 * at + 2]};
    std::size_t a = R;
    while (a-- > 0) {
      if (++k[a] < pp[a]) break;
      k[a] = 0;
    }
    if (a == static_cast<std::size_t>(-1)) return s;
  }
}

// ------------------------------------------------------------------ the fit

template <std::size_t R>
struct Fit {
  std::array<Axis, R> axes;
  std::vector<double> cp;
  double lambda = 0;
  int fits = 0;
};

// The fairness weight that fills holes: a fraction 1e-5 of the data term's mean
// diagonal. It keeps the system definite where there is no data and changes the fit
// elsewhere by about that fraction at the finest scale of the control net, far below
// any tolerance a user asks for.
constexpr double fill_fraction = 1e-5;

// The fit of the sparse system with fairness weight λ (none: 0), at least the
// weight that fills holes when `fill`.
template <std::size_t R>
void sparse_fit(Fit<R>& f, SparseSystem<R>& sys, const std::vector<double>& rhs, std::optional<double> lambda, bool fill) {
  const double filler = fill ? fill_fraction * sys.diagonal_ratio() : 0.0;
  f.lambda = lambda ? std::max(*lambda, filler) : filler;
  sys.factor(f.lambda);
  f.cp = sys.solve(rhs);
}

// λ by generalized cross-validation: the minimum over λ of
//   V(λ) = n Σ w r² / (n − tr H(λ))²,
// n the points present, H the map from data to fitted values (its trace estimated),
// first on a grid of one value per decade, then by golden section around the best.
// `present` points with data, `fill`: some are missing; rss(cp): the weighted sum of
// squared residuals of control points cp.
template <std::size_t R, class Rss>
void gcv_fit(Fit<R>& f, SparseSystem<R>& sys, const std::vector<double>& rhs, std::size_t present, bool fill, const Rss& rss_of) {
  const auto n = static_cast<double>(present);
  // Probes of the trace estimate: its error, about sqrt(2 / probes) of the Frobenius
  // norm of M⁻¹ λ s K (at most sqrt(C)), stays a small part of n − tr H.
  constexpr int probes = 24;
  // With holes, λ never goes below the weight that fills them.
  const double floor = fill ? fill_fraction * sys.diagonal_ratio() : 0.0;
  auto score = [&](double log_lambda) {
    ++f.fits;
    const double lambda = std::max(floor, std::pow(10.0, log_lambda));
    try {
      sys.factor(lambda);
    } catch (const error& e) {
      if (e.code() != errc::singular) throw;
      return std::numeric_limits<double>::infinity();  // too little fairness for the data: not a candidate
    }
    f.cp = sys.solve(rhs);
    const double rss = rss_of(f.cp);
    // n − tr H = n − C + tr(M⁻¹ λ s K).
    const double rest = n - static_cast<double>(sys.data.rows()) + sys.fairness_trace(lambda, probes);
    if (!(rest > 0)) return std::numeric_limits<double>::infinity();
    return n * rss / (rest * rest);
  };
  double best = -12, best_v = std::numeric_limits<double>::infinity();
  for (int e = -12; e <= 4; ++e)
    if (const double v = score(e); v < best_v) {
      best_v = v;
      best = e;
    }
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = best - 1, hi = best + 1;
  double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo);
  double v1 = score(x1), v2 = score(x2);
  for (int it = 0; it < 10; ++it) {
    if (v1 < v2) {
      hi = x2, x2 = x1, v2 = v1;
      x1 = hi - phi * (hi - lo);
      v1 = score(x1);
    } else {
      lo = x1, x1 = x2, v1 = v2;
      x2 = lo + phi * (hi - lo);
      v2 = score(x2);
    }
  }
  double x = v1 < v2 ? x1 : x2;
  if (std::min(v1, v2) > best_v) x = best;
  f.lambda = std::max(floor, std::pow(10.0, x));
  sys.factor(f.lambda);
  f.cp = sys.solve(rhs);
}

// The residual at point `pos` of `line` (n points along axis `ax`, 3 doubles each)
// of the least-squares fit along that axis alone: whether the direction lacks knots
// there.
double line_fit_residual(const Axis& ax, const AxisSolver& lu, const std::vector<double>& line, std::size_t pos);

// A data point for a line fit: the point where present, else the approximation's
// value there (cp: the control net).
template <std::size_t R>
Vec3 point_or_fit(const std::array<Axis, R>& axes, const std::vector<double>& cp, const Shape<R>& shape, const Vec3& q,
                  bool present, std::size_t flat) {
  return present ? q : value_at<R>(axes, cp, flat, shape);
}

// Whether the clamped knots of an open axis with interior knots `breaks` (sorted)
// meet the Schoenberg–Whitney condition on the lines that hold data: basis function
// j can be given its own line i_j, i_0 < i_1 < …, inside its support. Without it
// the least-squares system is singular (more control points than data somewhere).
// The smallest line that fits each function in turn is the best choice: the
// supports' ends rise with j.
bool whitney(const Axis& ax, const std::vector<double>& breaks, const std::vector<bool>& has_data);

// Splits knot interval k of an axis at the middle of the data in it, between two
// lines across the axis that hold data (a knot between missing lines would leave
// the fairness term alone to settle a control point there); false when it holds
// fewer than 2 such lines, when the direction has as many control points as data,
// or when the new knot would break the Schoenberg–Whitney condition (whitney).
bool split_interval(const Axis& ax, std::vector<double>& breaks, int k, const std::vector<bool>& has_data);

// What removing each interior knot of an open axis a would cost, estimated from the
// fit: the largest jump, over the lines of the control net along a, of the p-th
// derivative at the knot (where the two polynomial pieces differ), times the p-th
// power of the two intervals beside it (The NURBS Book §5.4: the deviation a
// removal brings is of that order).
template <std::size_t R>
std::vector<double> removal_costs(const Fit<R>& f, std::size_t a, const std::vector<double>& breaks) {
  const Axis& ax = f.axes[a];
  const int p = ax.p;
  const auto pp = static_cast<std::size_t>(p) + 1;
  std::vector<double> u{ax.t.front()};
  u.insert(u.end(), breaks.begin(), breaks.end());
  u.push_back(ax.t.back());
  const std::size_t pieces = u.size() - 1;
  // The p-th derivatives of the basis on each piece (constant there).
  std::vector<int> first(pieces);
  std::vector<double> der(pieces * pp);
  double tmp[(max_degree + 1) * (max_degree + 1)];
  for (std::size_t j = 0; j < pieces; ++j) {
    const double mid = 0.5 * (u[j] + u[j + 1]);
    const int span = ax.knots.find_span(mid);
    ax.knots.basis_derivatives(span, mid, p, tmp);
    first[j] = span - p;
    std::copy(tmp + static_cast<std::size_t>(p) * pp, tmp + static_cast<std::size_t>(p + 1) * pp, der.begin() + static_cast<std::ptrdiff_t>(j * pp));
  }
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= static_cast<std::size_t>(f.axes[x].c);
  for (std::size_t x = a + 1; x < R; ++x) inner *= static_cast<std::size_t>(f.axes[x].c);
  const auto c = static_cast<std::size_t>(ax.c);
  std::vector<double> jump(breaks.size(), 0.0);
  std::vector<Vec3> d(pieces);
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t in = 0; in < inner; ++in) {
      for (std::size_t j = 0; j < pieces; ++j) {
        Vec3 v{};
        for (std::size_t k = 0; k < pp; ++k) {
          const std::size_t i = (o * c + static_cast<std::size_t>(first[j]) + k) * inner + in;
          v = v + der[j * pp + k] * Vec3{f.cp[3 * i], f.cp[3 * i + 1], f.cp[3 * i + 2]};
        }
        d[j] = v;
      }
      for (std::size_t k = 0; k < breaks.size(); ++k) jump[k] = std::max(jump[k], distance(d[k + 1], d[k]));
    }
  for (std::size_t k = 0; k < breaks.size(); ++k) jump[k] *= std::pow(u[k + 2] - u[k], p);
  return jump;
}

// A control net's doubles as points.
std::span<const Vec3> net_points(const std::vector<double>& cp);

// Growth from the knots in `breaks`: knots go where the error is largest, in every
// interval whose worst point is beyond the tolerance, in the directions along which
// that point's line, fitted on its own, misses it by more than half the tolerance
// (where neither does, in every direction). True when the fit is within the
// tolerance; false when no interval can split any more. `s`: the data (Whole, or a
// block of a split run), every decision here the same on every process.
template <std::size_t R, class Source>
bool grow(Fit<R>& f, const Source& s, double tol, std::array<std::vector<double>, R>& breaks,
          const progress_callback& progress) {
  const std::array<std::vector<bool>, R> has_data = s.has_data();
  for (;;) {
    s.fit(f);
    if (progress) progress(std::min(0.9, 0.1 + 0.04 * f.fits));
    const Residuals<R> r = s.errors(f);
    // Within the tolerance but swinging between the data (knots that leave a basis
    // function little data): climb() takes the least-squares knots instead.
    if (r.max <= tol) return s.sane(f);
    // The intervals beyond the tolerance; those of a direction with a line fit are
    // decided by it, all lines of one round at once.
    std::array<std::vector<int>, R> bad;
    std::array<std::optional<AxisSolver>, R> lu;
    std::vector<std::pair<std::size_t, std::size_t>> lines;
    for (std::size_t a = 0; a < R; ++a) {
      const Axis& ax = f.axes[a];
      if (static_cast<std::size_t>(ax.c) >= ax.n) continue;
      // A direction whose knots outnumber the data under them (the fit then leans on
      // the fairness term) has no line fit of its own: every bad interval of it splits.
      try {
        lu[a] = factor_gram(ax, a);
      } catch (const error& e) {
        if (e.code() != errc::singular) throw;
      }
      for (int k = 0; k < ax.intervals; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        if (!(r.interval_max[a][kk] > tol)) continue;
        bad[a].push_back(k);
        if (R > 1 && lu[a]) lines.emplace_back(a, r.interval_worst[a][kk]);
      }
    }
    const std::vector<double> line_error = s.line_residuals(f, lu, lines);
    std::array<std::vector<int>, R> split;
    bool any = false;
    std::size_t next = 0;
    for (std::size_t a = 0; a < R; ++a)
      for (const int k : bad[a])
        if (R == 1 || !lu[a] || line_error[next++] > 0.5 * tol) {
          split[a].push_back(k);
          any = true;
        }
    if (!any) {
      const std::vector<std::size_t> w = unflatten<R>(r.worst, s.shape());
      for (std::size_t a = 0; a < R; ++a) split[a].push_back(f.axes[a].interval[w[a]]);
    }
    bool added = false;
    for (std::size_t a = 0; a < R; ++a) {
      const std::size_t before = breaks[a].size();
      for (int k : split[a])
        if (split_interval(f.axes[a], breaks[a], k, has_data[a])) added = true;
      if (breaks[a].size() != before) {
        std::sort(breaks[a].begin(), breaks[a].end());
        f.axes[a].set_knots(knots_from_breaks(f.axes[a], breaks[a]));
      }
    }
    if (!added) return false;  // every interval is as fine as the data allow
  }
}

// Growth stalled (no interval beyond the tolerance can split): the knots of the
// least-squares rule (least_squares_breaks), half as many more control points again
// along every direction each time, up to as many as data points (interpolation, which
// meets any tolerance on a complete grid but for rounding). True when the fit is
// within the tolerance; false with the fit of the most control points (the caller's
// check then refuses it, naming the worst point).
template <std::size_t R, class Source>
bool climb(Fit<R>& f, const Source& s, double tol, std::array<std::vector<double>, R>& breaks,
           const progress_callback& progress) {
  for (;;) {
    // A direction growth left with as many control points as data takes
    // interpolation's knots too: growth's may be poorly conditioned there.
    bool more = false;
    for (std::size_t a = 0; a < R; ++a) {
      Axis& ax = f.axes[a];
      const int n = static_cast<int>(ax.n), c = ax.c < n ? std::max(ax.c + 1, ax.c + ax.c / 2) : n;
      std::vector<double> next = least_squares_breaks(ax, std::min(n, c));
      if (next == breaks[a]) continue;
      more = true;
      breaks[a] = std::move(next);
      ax.set_knots(knots_from_breaks(ax, breaks[a]));
    }
    if (!more) return false;
    s.fit(f);
    if (progress) progress(std::min(0.9, 0.1 + 0.04 * f.fits));
    if (s.errors(f).max <= tol && s.sane(f)) return true;
  }
}

// The fit to a tolerance of the data `s` (Whole, or a block of a split run).
template <std::size_t R, class Source>
void solve_tolerance(Fit<R>& f, const Source& s, double tol, const progress_callback& progress) {
  std::array<std::vector<double>, R> breaks;
  for (std::size_t a = 0; a < R; ++a) {
    Axis& ax = f.axes[a];
    breaks[a] = ax.periodic ? least_squares_breaks(ax, ax.p + 1) : std::vector<double>{};
    ax.set_knots(knots_from_breaks(ax, breaks[a]));
  }
  // A large grid grows its first knots on every 4th line of directions with 128 or
  // more points (a sixteenth of a surface's work per fit): the coarse knots a smooth
  // part of the data needs show on it as well. The whole grid then refines them.
  constexpr std::size_t thin = 4, thin_from = 128;
  const bool thinning = s.size() >= (std::size_t{1} << 18);
  Fit<R> coarse;
  std::optional<Source> sub;
  if (thinning) {
    std::array<std::vector<std::size_t>, R> kept;
    for (std::size_t a = 0; a < R; ++a) {
      const std::size_t n = s.shape()[a], step = n >= thin_from ? thin : 1;
      for (std::size_t i = 0; i < n; i += step) kept[a].push_back(i);
      if (!f.axes[a].periodic && kept[a].back() != n - 1) kept[a].push_back(n - 1);
      Axis& ax = coarse.axes[a];
      ax.n = kept[a].size();
      ax.p = f.axes[a].p;
      ax.periodic = f.axes[a].periodic;
      for (std::size_t i : kept[a]) ax.t.push_back(f.axes[a].t[i]);
      ax.set_knots(knots_from_breaks(ax, breaks[a]));
    }
    sub.emplace(s.thinned(kept));
    (void)grow<R>(coarse, *sub, tol, breaks, {});
    f.fits += coarse.fits;
    coarse.fits = 0;
    for (std::size_t a = 0; a < R; ++a) f.axes[a].set_knots(knots_from_breaks(f.axes[a], breaks[a]));
  }
  if (!grow<R>(f, s, tol, breaks, progress) && !climb<R>(f, s, tol, breaks, progress)) return;
  auto max_error = [&] {
    s.fit(f);
    if (progress) progress(std::min(0.9, 0.1 + 0.04 * f.fits));
    return s.errors(f);
  };
  // Pruning: growth splits several intervals at once and overshoots. The knots whose
  // removal costs least go, as long as the refit stays within the tolerance: first
  // a quarter of them at once, half as many after each refusal, one at a time at
  // the end; a few refused single removals end it. On a large grid a removal is
  // first tried on the thinned grid (a sixteenth of the work): one that fails there
  // is refused without the whole grid's fit.
  constexpr int refusals = 3;
  std::vector<std::pair<std::size_t, double>> refused;
  std::size_t total = 0;
  for (std::size_t a = 0; a < R; ++a) total += f.axes[a].periodic ? 0 : breaks[a].size();
  std::size_t batch = std::max<std::size_t>(1, total / 4);
  while (static_cast<int>(refused.size()) < refusals) {
    struct Candidate {
      double cost;
      std::size_t axis;
      double knot;
    };
    std::vector<Candidate> cand;
    for (std::size_t a = 0; a < R; ++a) {
      if (f.axes[a].periodic) continue;
      const std::vector<double> cost = removal_costs<R>(f, a, breaks[a]);
      for (std::size_t k = 0; k < cost.size(); ++k)
        if (std::none_of(refused.begin(), refused.end(),
                         [&](const auto& x) { return x.first == a && x.second == breaks[a][k]; }))
          cand.push_back({cost[k], a, breaks[a][k]});
    }
    if (cand.empty()) return;
    std::stable_sort(cand.begin(), cand.end(), [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
    batch = std::min(batch, cand.size());
    const Fit<R> kept = f;
    const std::array<std::vector<double>, R> kept_breaks = breaks;
    std::array<bool, R> changed{};
    for (std::size_t k = 0; k < batch; ++k) {
      auto& b = breaks[cand[k].axis];
      b.erase(std::find(b.begin(), b.end(), cand[k].knot));
      changed[cand[k].axis] = true;
    }
    for (std::size_t a = 0; a < R; ++a)
      if (changed[a]) f.axes[a].set_knots(knots_from_breaks(f.axes[a], breaks[a]));
    bool within = true;
    if (thinning) {
      for (std::size_t a = 0; a < R; ++a) coarse.axes[a].set_knots(knots_from_breaks(coarse.axes[a], breaks[a]));
      sub->fit(coarse);
      within = sub->errors(coarse).max <= tol;
      f.fits += coarse.fits;
      coarse.fits = 0;
    }
    if (within && max_error().max <= tol && s.sane(f)) continue;
    const int fits = f.fits;
    f = kept;
    f.fits = fits;
    breaks = kept_breaks;
    if (batch == 1) refused.emplace_back(cand[0].axis, cand[0].knot);
    batch = std::max<std::size_t>(1, batch / 2);
  }
}

// Exactly one of the three ways, and enough points.
template <std::size_t R>
void check_request(const ApproximationOptions<R>& o, const Shape<R>& shape, const char* what) {
  // Exactly one of the three ways.
  const int ways = (o.control_points ? 1 : 0) + (o.tolerance ? 1 : 0) + ((o.smoothing || o.auto_smoothing) ? 1 : 0);
  if (ways != 1)
    fail(errc::wrong_type, what, " approximation takes exactly one of control_points, tolerance and smoothing, got ",
         ways);
  if (o.smoothing && o.auto_smoothing) fail(errc::wrong_type, "smoothing is either a number or auto, not both");
  if (o.tolerance && !(*o.tolerance > 0 && std::isfinite(*o.tolerance)))
    fail(errc::wrong_type, "tolerance ", *o.tolerance, " is not a positive distance");
  if (o.smoothing && !(*o.smoothing >= 0 && std::isfinite(*o.smoothing)))
    fail(errc::wrong_type, "smoothing ", *o.smoothing, " is not a non-negative number");
  for (std::size_t a = 0; a < R; ++a)
    if (shape[a] < 2)
      fail(errc::too_few_points, what, " approximation needs at least 2 points along ", axis_name(a), ", got ",
           shape[a]);
}

// Direction a of n data points: its degree, checked.
template <std::size_t R>
void set_degree(Axis& ax, const ApproximationOptions<R>& o, std::size_t a, std::size_t n) {
  ax.n = n;
  ax.periodic = o.periodic[a];
  const int p = o.degree[a] ? *o.degree[a] : std::min<int>(3, static_cast<int>(ax.n) - 1);
  if (p < 1 || p > max_degree)
    fail(errc::invalid_degree, "degree ", p, " along ", axis_name(a), " is outside 1..", max_degree);
  if (ax.n < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "degree ", p, " along ", axis_name(a), " needs at least ", p + 1, " points, got ", ax.n);
  ax.p = p;
}

template <std::size_t R>
void check_control_points(const std::array<Axis, R>& axes, const ApproximationOptions<R>& o) {
  if (o.control_points)
    for (std::size_t a = 0; a < R; ++a) {
      const int c = (*o.control_points)[a];
      const Axis& ax = axes[a];
      if (c < ax.p + 1)
        fail(errc::too_few_points, c, " control points along ", axis_name(a), " are fewer than degree ", ax.p,
             " needs (", ax.p + 1, ")");
      if (static_cast<std::size_t>(c) > ax.n)
        fail(errc::too_few_points, c, " control points along ", axis_name(a), " are more than the ", ax.n,
             " data points there: least squares needs at least as many data as control points");
    }
}

// The knots of a fit with a given number of control points or a smoothing fit.
template <std::size_t R>
void set_fit_knots(std::array<Axis, R>& axes, const ApproximationOptions<R>& o) {
  for (std::size_t a = 0; a < R; ++a) {
    Axis& ax = axes[a];
    int c = 0;
    if (o.control_points) c = (*o.control_points)[a];
    else c = std::max(ax.p + 1, std::min(static_cast<int>(ax.n), smoothing_max_control_points));
    ax.set_knots(knots_from_breaks(ax, least_squares_breaks(ax, c)));
  }
}

// Weights of the shape of the points, finite and not negative.
template <std::size_t R>
void check_weights(const Grid<double, R>& weights, const Shape<R>& shape) {
  for (std::size_t a = 0; a < R; ++a)
    if (weights.extent(a) != shape[a])
      fail(errc::size_mismatch, "weights: ", weights.extent(a), " along ", axis_name(a), ", the points have ", shape[a]);
  for (std::size_t i = 0; i < weights.size(); ++i) {
    const double w = weights.values()[i];
    if (std::isnan(w) || std::isinf(w)) fail(errc::not_finite, "weight ", index_text<R>(i, shape), " is ", w);
    if (w < 0) fail(errc::invalid_weight, "weight ", index_text<R>(i, shape), " = ", w, " is negative");
  }
}

// A closed direction's last line that nearly repeats the first.
[[noreturn]] void refuse_closing_gap(std::size_t a);

// The grid without its last line along axis a.
template <class T, std::size_t R>
void cut_last_line(Grid<T, R>& g, std::size_t a) {
  auto shape = g.shape();
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= shape[x];
  for (std::size_t x = a + 1; x < R; ++x) inner *= shape[x];
  const std::size_t n = shape[a];
  shape[a] = n - 1;
  Grid<T, R> kept(shape, for_overwrite);
  for (std::size_t o = 0; o < outer; ++o) std::copy_n(g.data() + o * n * inner, (n - 1) * inner, kept.data() + o * (n - 1) * inner);
  g = std::move(kept);
}

}  // namespace interpatch::detail::approx
