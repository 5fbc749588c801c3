#include "interpatch/approximate.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <random>
#include <variant>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "detail/approx_check.hpp"
#include "detail/approx_rows.hpp"
#include "detail/banded.hpp"
#include "detail/parallel.hpp"
#include "detail/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;

namespace {

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

bool is_missing(const Vec3& q) { return std::isnan(q.x) || std::isnan(q.y) || std::isnan(q.z); }

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
AxisSolver factor_gram(const Axis& ax, std::size_t a) {
  const Band g = ax.gram(ax.p);
  auto singular = [&](int row) {
    fail(errc::singular, "along ", axis_name(a), ": the least-squares system of ", ax.c, " control points over ", ax.n,
         " data points has no unique solution (control point ", row, " has no data under it)");
  };
  if (ax.periodic) {
    std::vector<std::vector<detail::CyclicLU::Entry>> rows(static_cast<std::size_t>(ax.c));
    for (int i = 0; i < ax.c; ++i)
      for (int d = -ax.p; d <= ax.p; ++d)
        if (const double v = g.at(i, d); v != 0.0) rows[static_cast<std::size_t>(i)].push_back({((i + d) % ax.c + ax.c) % ax.c, v});
    detail::CyclicLU lu(ax.c, rows);
    if (!lu.factor()) singular(lu.failed_row());
    return lu;
  }
  detail::BandedLU lu(ax.c, ax.p, ax.p);
  for (int i = 0; i < ax.c; ++i)
    for (int d = -ax.p; d <= ax.p; ++d)
      if (i + d >= 0 && i + d < ax.c) lu.at(i, i + d) = g.at(i, d);
  if (!lu.factor()) singular(lu.failed_row());
  return lu;
}

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

// Bᵀ (w Q) over every direction: the right-hand side of the normal equations.
template <std::size_t R>
std::vector<double> right_hand_side(const std::array<Axis, R>& axes, const Data<R>& d) {
  Shape<R> shape = d.shape;
  std::vector<double> a0, a1;
  const double* src = &d.points.data()->x;
  if (!d.uniform()) {
    require_memory(d.points.size(), sizeof(Vec3), "the weighted data points");
    a1.resize(d.points.size() * 3);
    for (std::size_t i = 0; i < d.points.size(); ++i) {
      const double w = d.weight[i];
      for (std::size_t k = 0; k < 3; ++k) a1[i * 3 + k] = w > 0 ? w * d.points.data()[i][static_cast<int>(k)] : 0.0;
    }
    src = a1.data();
  }
  // The first direction first: its rows are whole rows of the grid (long, contiguous
  // runs the multiply-adds stream through), and it shrinks the grid for the others.
  for (std::size_t a = 0; a < R; ++a) {
    basis_pass<true, R>(axes[a], src, shape, a, a0);
    std::swap(a0, a1);
    src = a1.data();
  }
  return a1;
}

// ------------------------------------------------------------------ solvers

// The separable least-squares fit: every point present with weight 1, no fairness
// term. The normal equations are the Kronecker product of the directions' Gram
// matrices, solved direction by direction.
template <std::size_t R>
std::vector<double> separable_fit(const std::array<Axis, R>& axes, const Data<R>& d) {
  std::vector<double> x = right_hand_side<R>(axes, d);
  Shape<R> shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(axes[a].c);
  for (std::size_t a = 0; a < R; ++a) {
    const AxisSolver lu = factor_gram(axes[a], a);
    std::visit([&](const auto& s) { detail::solve_along_axis(s, x.data(), shape.data(), R, a, 3); }, lu);
  }
  return x;
}

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

// Parameters along axis a, averaged over the lines of the grid: the mean chord of
// each step over the lines where both its points are present (a step with none
// takes the mean of the others). Without missing points along an open direction,
// interpolation's own parameters.
std::vector<double> uniform_parameters(std::size_t n, bool closed) {
  const std::size_t steps = closed ? n : n - 1;
  std::vector<double> t(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / static_cast<double>(steps);
  if (!closed) t.back() = 1.0;
  return t;
}

// Parameters from the chords summed per step over the lines (sum[k]: step k to
// k + 1, used[k] lines adding to it).
std::vector<double> parameters_from_sums(std::vector<double> sum, const std::vector<std::size_t>& used, std::size_t n,
                                         std::size_t a, Parametrization param, bool closed) {
  const std::size_t steps = sum.size();
  double known = 0;
  std::size_t known_count = 0;
  for (std::size_t k = 0; k < steps; ++k)
    if (used[k] > 0) {
      sum[k] /= static_cast<double>(used[k]);
      known += sum[k];
      ++known_count;
    }
  if (known_count == 0) return uniform_parameters(n, closed);
  for (std::size_t k = 0; k < steps; ++k) {
    if (used[k] == 0) sum[k] = known / static_cast<double>(known_count);
    // Means below 1e-14 of the total are rounding noise: the points coincide in every line.
    if (!(sum[k] > 1e-14 * known))
      fail(errc::zero_chord, "along ", axis_name(a), ": points ", k, " and ", (k + 1) % n,
           " coincide in every line (mean chord ", sum[k], "): parameters must increase");
    if (param == Parametrization::centripetal) sum[k] = std::sqrt(sum[k]);
  }
  double total = 0;
  for (std::size_t k = 0; k < steps; ++k) total += sum[k];
  std::vector<double> t(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) t[k] = t[k - 1] + sum[k - 1];
  for (std::size_t k = 1; k < n; ++k) t[k] /= total;
  if (!closed) t.back() = 1.0;
  return t;
}

// The chord from p0 to p1 added to a step's sum when both are present.
inline void add_chord(const Vec3& p0, const Vec3& p1, double& sum, std::size_t& used) {
  if (is_missing(p0) || is_missing(p1)) return;
  sum += distance(p0, p1);
  ++used;
}

// Parameters along axis a, averaged over the lines of the grid: the mean chord of
// each step over the lines where both its points are present (a step with none
// takes the mean of the others). Without missing points along an open direction,
// interpolation's own parameters.
template <std::size_t R>
std::vector<double> axis_parameters(const Data<R>& d, std::size_t a, Parametrization param, bool closed) {
  const std::size_t n = d.shape[a];
  const std::size_t steps = closed ? n : n - 1;
  if (param == Parametrization::uniform) return uniform_parameters(n, closed);
  if (!closed && d.missing == 0) {
    if constexpr (R == 1) return curve_parameters(std::span<const Vec3>(d.points.data(), n), param);
    else return grid_parameters(d.points, static_cast<int>(a), param);
  }
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= d.shape[x];
  for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
  std::vector<double> sum(steps, 0.0);
  std::vector<std::size_t> used(steps, 0);
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t in = 0; in < inner; ++in)
      for (std::size_t k = 1; k <= steps; ++k)
        add_chord(d.points.data()[(o * n + k - 1) * inner + in], d.points.data()[(o * n + k % n) * inner + in], sum[k - 1],
                  used[k - 1]);
  return parameters_from_sums(std::move(sum), used, n, a, param, closed);
}

// Knots of a clamped spline with the given interior knots over [t.front(), t.back()].
KnotVector clamped_knots(const Axis& ax, const std::vector<double>& interior) {
  std::vector<double> u(static_cast<std::size_t>(ax.p) + 1, ax.t.front());
  u.insert(u.end(), interior.begin(), interior.end());
  u.insert(u.end(), static_cast<std::size_t>(ax.p) + 1, ax.t.back());
  return KnotVector(ax.p, std::move(u));
}

// The interior knots (open) or the period's knots (closed) of `c` control points
// for least squares over the data parameters. Open: c parameters spread evenly over
// the data's order (linear between data parameters), and interpolation's knots
// averaged from them (The NURBS Book eq. 9.8): every basis function has data under
// the middle of its support, so the normal equations stay as well conditioned as
// interpolation's whatever c (The NURBS Book eq. 9.69 reaches condition numbers of
// 1e16 as c nears the point count, and a fit then swings between the data). With as
// many control points as data, interpolation's knots. Closed: evenly spaced in the
// data's order, shifted by half a step for an even degree.
std::vector<double> least_squares_breaks(const Axis& ax, int c) {
  const auto& t = ax.t;
  const auto n = static_cast<double>(ax.n);
  std::vector<double> k;
  if (ax.periodic) {
    auto at = [&](double x) {  // the data parameters extended periodically, linear between
      const double f = std::floor(x);
      const auto i = static_cast<long long>(f);
      auto tt = [&](long long j) {
        const auto m = static_cast<long long>(ax.n);
        const long long q = (j % m + m) % m;
        return t[static_cast<std::size_t>(q)] + static_cast<double>((j - q) / m);
      };
      return tt(i) + (x - f) * (tt(i + 1) - tt(i));
    };
    const double shift = ax.p % 2 == 0 ? 0.5 : 0.0;
    for (int j = 0; j < c; ++j) k.push_back(at(j * n / c + shift));
    return k;
  }
  std::vector<double> s(static_cast<std::size_t>(c));
  for (int j = 0; j < c; ++j) {
    // j (n − 1) / (c − 1) is exact at c = n: the data parameters themselves.
    const double x = static_cast<double>(j) * (n - 1) / static_cast<double>(c - 1);
    const auto i = std::min(static_cast<std::size_t>(std::floor(x)), ax.n - 1);
    const double alpha = x - static_cast<double>(i);
    s[static_cast<std::size_t>(j)] = alpha > 0 ? (1 - alpha) * t[i] + alpha * t[i + 1] : t[i];
  }
  const KnotVector avg = averaged_knots(s, ax.p);
  const auto& u = avg.values();
  return {u.begin() + ax.p + 1, u.end() - ax.p - 1};
}

KnotVector knots_from_breaks(const Axis& ax, const std::vector<double>& breaks) {
  if (ax.periodic) return KnotVector::periodic_from(ax.p, breaks, breaks.front() + 1.0);
  return clamped_knots(ax, breaks);
}

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

std::vector<std::size_t> residual_offsets(const Axis& last) {
  const std::size_t pp = static_cast<std::size_t>(last.p) + 1;
  std::vector<std::size_t> off(last.n * pp);
  for (std::size_t i = 0; i < last.n; ++i)
    for (std::size_t k = 0; k < pp; ++k) off[i * pp + k] = 3 * last.col(last.first[i] + static_cast<int>(k));
  return off;
}

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

// The distances |S(t_i) − Q_i| at every point present, evaluated a row at a time
// (every index but the last fixed) and never stored: the control net goes through B
// along every direction but the last once (n_0 ⋯ n_{R−2} × c_{R−1} values), and each
// row of S is made from its row of that and compared at once. Blocks of rows run in
// parallel and merge in order.
template <std::size_t R>
Residuals<R> residuals(const std::array<Axis, R>& axes, const Data<R>& d, const std::vector<double>& cp) {
  Shape<R> shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(axes[a].c);
  std::vector<double> partial = cp, scratch;
  for (std::size_t a = 0; a + 1 < R; ++a) {
    basis_pass<false, R>(axes[a], partial.data(), shape, a, scratch);
    std::swap(partial, scratch);
  }
  Residuals<R> all = residual_blocks<R>(axes, d.shape, partial.data(), d.points.data(), 0, 0, d.points.size() / axes[R - 1].n,
                                        [&](std::size_t i) { return d.w(i); });
  take_roots<R>(all);
  return all;
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

// Whether the sparse system is needed: missing points, weights, or a fairness term.
template <std::size_t R>
bool needs_fill(const Data<R>& d) {
  if (d.uniform()) return false;
  return std::any_of(d.weight.begin(), d.weight.end(), [](double w) { return !(w > 0); });
}

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

template <std::size_t R>
void solve_once(Fit<R>& f, const Data<R>& d, std::optional<double> lambda) {
  ++f.fits;
  bool fill = needs_fill(d);
  if (!lambda && d.uniform()) {
    try {
      f.lambda = 0;
      f.cp = separable_fit<R>(f.axes, d);
      return;
    } catch (const error& e) {
      // Knot intervals with too little data under them: the fairness term settles
      // what the data leave open, as in a hole.
      if (e.code() != errc::singular) throw;
      fill = true;
    }
  }
  SparseSystem<R> sys(f.axes, d);
  sparse_fit<R>(f, sys, right_hand_side<R>(f.axes, d), lambda, fill);
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

template <std::size_t R>
void solve_gcv(Fit<R>& f, const Data<R>& d) {
  SparseSystem<R> sys(f.axes, d);
  gcv_fit<R>(f, sys, right_hand_side<R>(f.axes, d), d.present, needs_fill(d),
             [&](const std::vector<double>& cp) { return residuals<R>(f.axes, d, cp).weighted_sq; });
}

// The residual at point `pos` of `line` (n points along axis `ax`, 3 doubles each)
// of the least-squares fit along that axis alone: whether the direction lacks knots
// there.
double line_fit_residual(const Axis& ax, const AxisSolver& lu, const std::vector<double>& line, std::size_t pos) {
  const std::size_t n = ax.n;
  const auto pp = static_cast<std::size_t>(ax.p) + 1;
  std::vector<double> x(static_cast<std::size_t>(ax.c) * 3, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t l = 0; l < pp; ++l)
      for (std::size_t m = 0; m < 3; ++m) x[3 * ax.col(ax.first[k] + static_cast<int>(l)) + m] += ax.b[k * pp + l] * line[3 * k + m];
  std::visit([&](const auto& solver) { solver.solve(x.data(), 3, 3); }, lu);
  Vec3 e{};
  for (std::size_t l = 0; l < pp; ++l)
    for (std::size_t m = 0; m < 3; ++m)
      e[static_cast<int>(m)] += ax.b[pos * pp + l] * x[3 * ax.col(ax.first[pos] + static_cast<int>(l)) + m];
  return distance(e, Vec3{line[3 * pos], line[3 * pos + 1], line[3 * pos + 2]});
}

// A data point for a line fit: the point where present, else the approximation's
// value there (cp: the control net).
template <std::size_t R>
Vec3 point_or_fit(const std::array<Axis, R>& axes, const std::vector<double>& cp, const Shape<R>& shape, const Vec3& q,
                  bool present, std::size_t flat) {
  return present ? q : value_at<R>(axes, cp, flat, shape);
}

// The residual at point `i` of the least-squares fit along axis a alone of the line
// through it (missing points taking the approximation's values).
template <std::size_t R>
double line_residual(const std::array<Axis, R>& axes, const AxisSolver& lu, const Data<R>& d, const std::vector<double>& cp,
                     std::size_t a, std::size_t i) {
  std::size_t inner = 1;
  for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
  const std::size_t n = d.shape[a], pos = (i / inner) % n, base = i - pos * inner;
  std::vector<double> line(n * 3);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t j = base + k * inner;
    const Vec3 v = point_or_fit<R>(axes, cp, d.shape, d.points.data()[j], d.w(j) > 0, j);
    for (std::size_t m = 0; m < 3; ++m) line[3 * k + m] = v[static_cast<int>(m)];
  }
  return line_fit_residual(axes[a], lu, line, pos);
}

// Whether the clamped knots of an open axis with interior knots `breaks` (sorted)
// meet the Schoenberg–Whitney condition on the lines that hold data: basis function
// j can be given its own line i_j, i_0 < i_1 < …, inside its support. Without it
// the least-squares system is singular (more control points than data somewhere).
// The smallest line that fits each function in turn is the best choice: the
// supports' ends rise with j.
bool whitney(const Axis& ax, const std::vector<double>& breaks, const std::vector<bool>& has_data) {
  std::vector<double> u(static_cast<std::size_t>(ax.p) + 1, ax.t.front());
  u.insert(u.end(), breaks.begin(), breaks.end());
  u.insert(u.end(), static_cast<std::size_t>(ax.p) + 1, ax.t.back());
  const std::size_t c = breaks.size() + static_cast<std::size_t>(ax.p) + 1, p1 = static_cast<std::size_t>(ax.p) + 1;
  std::size_t i = 0;
  for (std::size_t j = 0; j < c; ++j) {
    const double lo = u[j], hi = u[j + p1];
    while (i < ax.n && (!has_data[i] || ax.t[i] < lo || (ax.t[i] == lo && j > 0))) ++i;
    if (i == ax.n || !(ax.t[i] < hi || (j + 1 == c && ax.t[i] == hi))) return false;
    ++i;
  }
  return true;
}

// Splits knot interval k of an axis at the middle of the data in it, between two
// lines across the axis that hold data (a knot between missing lines would leave
// the fairness term alone to settle a control point there); false when it holds
// fewer than 2 such lines, when the direction has as many control points as data,
// or when the new knot would break the Schoenberg–Whitney condition (whitney).
bool split_interval(const Axis& ax, std::vector<double>& breaks, int k, const std::vector<bool>& has_data) {
  if (static_cast<std::size_t>(ax.c) >= ax.n) return false;
  std::vector<std::size_t> in;  // the lines across the axis in the interval that hold data
  for (std::size_t i = 0; i < ax.n; ++i)
    if (ax.interval[i] == k && has_data[i]) in.push_back(i);
  if (in.size() < 2) return false;
  // In a closed direction, the order along the interval is that of the parameters
  // wrapped into the period: the interval across the seam holds the last lines and
  // then the first.
  auto at = [&](std::size_t i) { return ax.periodic ? ax.knots.wrap(ax.t[i]) : ax.t[i]; };
  if (ax.periodic) std::stable_sort(in.begin(), in.end(), [&](std::size_t x, std::size_t y) { return at(x) < at(y); });
  const std::size_t mid = in.size() / 2;
  const double knot = 0.5 * (at(in[mid - 1]) + at(in[mid]));
  if (!ax.periodic) {
    std::vector<double> next = breaks;  // this round's earlier knots at its end
    next.push_back(knot);
    std::sort(next.begin(), next.end());
    if (!whitney(ax, next, has_data)) return false;
  }
  breaks.push_back(knot);
  return true;
}

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

// The data a fit to a tolerance works on, all in this process (the split run has its
// own, Block in the section "split between processes"): what the knot logic of
// grow() and solve_tolerance() asks of the data.
// A control net's doubles as points.
std::span<const Vec3> net_points(const std::vector<double>& cp) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "a control net is triples of doubles");
  return {reinterpret_cast<const Vec3*>(cp.data()), cp.size() / 3};
}

template <std::size_t R>
struct Whole {
  std::shared_ptr<const Data<R>> own;  // a thinned grid's data; none for the caller's
  const Data<R>* d = nullptr;

  [[nodiscard]] std::size_t size() const { return d->points.size(); }
  [[nodiscard]] const Shape<R>& shape() const { return d->shape; }
  void fit(Fit<R>& f) const { solve_once<R>(f, *d, std::nullopt); }
  [[nodiscard]] Residuals<R> errors(const Fit<R>& f) const { return residuals<R>(f.axes, *d, f.cp); }
  // Whether f's control net stays near the data (detail::approx_net_sane).
  [[nodiscard]] bool sane(const Fit<R>& f) const {
    if (!box) box = detail::approx_box({{}, std::span<const Vec3>(d->points.data(), d->points.size()), d->weight});
    return detail::approx_net_sane(net_points(f.cp), R, *box);
  }
  mutable std::optional<std::array<Vec3, 2>> box;  // of the data, found once
  // line_residual at each (axis, point) of `at`, lu[axis] the axis's line solver.
  [[nodiscard]] std::vector<double> line_residuals(const Fit<R>& f, const std::array<std::optional<AxisSolver>, R>& lu,
                                                   const std::vector<std::pair<std::size_t, std::size_t>>& at) const {
    std::vector<double> e;
    for (const auto& [a, i] : at) e.push_back(line_residual<R>(f.axes, *lu[a], *d, f.cp, a, i));
    return e;
  }
  // Which lines across each axis (every point with that index along it) hold data.
  [[nodiscard]] std::array<std::vector<bool>, R> has_data() const {
    std::array<std::vector<bool>, R> has;
    for (std::size_t a = 0; a < R; ++a) has[a].assign(d->shape[a], d->uniform());
    if (!d->uniform())
      for (std::size_t i = 0; i < d->points.size(); ++i)
        if (d->w(i) > 0) {
          const std::vector<std::size_t> idx = unflatten<R>(i, d->shape);
          for (std::size_t a = 0; a < R; ++a) has[a][idx[a]] = true;
        }
    return has;
  }
  [[nodiscard]] Whole thinned(const std::array<std::vector<std::size_t>, R>& kept) const;
};

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

// Every `step[a]`-th line of the data along each axis (the last one too): a grid to
// grow the knots on before the whole grid refines them.
template <std::size_t R>
Data<R> thinned(const Data<R>& d, const std::array<std::vector<std::size_t>, R>& kept) {
  Data<R> t;
  typename Grid<Vec3, R>::shape_type shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = t.shape[a] = kept[a].size();
  t.points = Grid<Vec3, R>(shape, for_overwrite);
  if (!d.uniform()) t.weight.resize(t.points.size());
  std::array<std::size_t, R> k{};
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    std::size_t src = 0;
    for (std::size_t a = 0; a < R; ++a) src = src * d.shape[a] + kept[a][k[a]];
    t.points.data()[i] = d.points.data()[src];
    if (!d.uniform()) t.weight[i] = d.weight[src];
    if (d.w(src) > 0) {
      ++t.present;
      t.weight_sum += d.w(src);
    } else {
      ++t.missing;
    }
    for (std::size_t a = R; a-- > 0;) {
      if (++k[a] < kept[a].size()) break;
      k[a] = 0;
    }
  }
  return t;
}

template <std::size_t R>
Whole<R> Whole<R>::thinned(const std::array<std::vector<std::size_t>, R>& kept) const {
  auto t = std::make_shared<const Data<R>>(interpatch::thinned<R>(*d, kept));
  return {t, t.get(), std::nullopt};
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

template <std::size_t R>
struct Result {
  Fit<R> fit;
  ApproximationReport report;
  Data<R> data;  // the points fitted (a closed direction's closing line left out)
};

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

template <std::size_t R>
Result<R> approximate(Data<R> d, const ApproximationOptions<R>& o, const char* what) {
  check_request<R>(o, d.shape, what);

  // Missing points, weights.
  const std::size_t total = d.points.size();
  if (!o.weights.empty()) {
    check_weights<R>(o.weights, d.shape);
    d.weight.assign(o.weights.values().begin(), o.weights.values().end());
  }
  for (std::size_t i = 0; i < total; ++i) {
    const Vec3& q = d.points.data()[i];
    if (is_missing(q)) {
      if (d.weight.empty()) d.weight.assign(total, 1.0);
      d.weight[i] = 0;
      ++d.missing;
    } else if (!is_finite(q)) {
      fail(errc::not_finite, "point ", index_text<R>(i, d.shape), " is ", q, " (NaN marks a missing point; infinity is refused)");
    }
  }
  d.weight_sum = 0;
  d.present = 0;
  for (std::size_t i = 0; i < total; ++i)
    if (d.w(i) > 0) {
      d.weight_sum += d.w(i);
      ++d.present;
    }
  if (d.present == 0)
    fail(errc::too_few_points, "all ", total, " points are missing or have weight 0: there is nothing to approximate");
  // Data on a single line across a direction leave the fit free along it (nothing
  // fixes its slope there).
  if (!d.weight.empty())
    for (std::size_t a = 0; a < R; ++a) {
      std::size_t inner = 1;
      for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
      std::vector<bool> has(d.shape[a], false);
      for (std::size_t i = 0; i < total; ++i)
        if (d.weight[i] > 0) has[(i / inner) % d.shape[a]] = true;
      if (std::count(has.begin(), has.end(), true) < 2)
        fail(errc::too_few_points, "along ", axis_name(a), " only one line of points holds data (the others are missing ",
             "or have weight 0): an approximation needs two");
    }
  if (!d.weight.empty() && d.missing == 0 &&
        std::all_of(d.weight.begin(), d.weight.end(), [&](double w) { return w == d.weight.front(); })) {
    d.weight.clear();  // equal weights: the plain least-squares fit
    d.weight_sum = static_cast<double>(total);
  }

  Result<R> res;
  Fit<R>& f = res.fit;
  for (std::size_t a = 0; a < R; ++a) {
    set_degree<R>(f.axes[a], o, a, d.shape[a]);
    f.axes[a].t = axis_parameters<R>(d, a, o.param, f.axes[a].periodic);
  }
  check_control_points<R>(f.axes, o);
  if (o.progress) o.progress(0.0);

  if (o.tolerance) {
    solve_tolerance<R>(f, Whole<R>{nullptr, &d, std::nullopt}, *o.tolerance, o.progress);
  } else {
    set_fit_knots<R>(f.axes, o);
    if (o.auto_smoothing) solve_gcv<R>(f, d);
    else solve_once<R>(f, d, o.smoothing);
  }

  // The report.
  const Residuals<R> r = residuals<R>(f.axes, d, f.cp);
  ApproximationReport& rep = res.report;
  rep.max_error = r.max;
  rep.max_error_at = unflatten<R>(r.worst, d.shape);
  rep.rms_error = std::sqrt(r.sum_sq / static_cast<double>(d.present));
  for (std::size_t a = 0; a < R; ++a) rep.control_points.push_back(f.axes[a].c);
  rep.lambda = f.lambda;
  rep.missing = d.missing;
  rep.fits = f.fits;
  if (o.progress) o.progress(1.0);
  res.data = std::move(d);
  return res;
}

template <std::size_t R>
Grid<Vec3, R> control_net(const Fit<R>& f) {
  typename Grid<Vec3, R>::shape_type shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(f.axes[a].c);
  Grid<Vec3, R> g(shape, for_overwrite);
  std::copy_n(f.cp.data(), f.cp.size(), &g.data()->x);
  return g;
}

// A closed direction's last line that nearly repeats the first.
[[noreturn]] void refuse_closing_gap(std::size_t a) {
  fail(errc::closing_gap, "the last line of points along ", axis_name(a),
       " nearly repeats the first: repeat the first line exactly, or leave the last one out");
}

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

// A closed direction's last line, when it repeats the first (interpolation's rule),
// is left out, with its weights.
template <std::size_t R>
Data<R> closed_data(Grid<Vec3, R> points, Grid<double, R>& weights, const std::array<bool, R>& periodic) {
  Data<R> d;
  for (std::size_t a = 0; a < R; ++a) {
    if (!periodic[a] || points.extent(a) < 3) continue;
    if (std::any_of(points.values().begin(), points.values().end(), is_missing)) break;
    Closing c;
    if constexpr (R == 1) c = closing_point(std::span<const Vec3>(points.data(), points.size()));
    else c = grid_closing(points, static_cast<int>(a));
    if (c.nearly) refuse_closing_gap(a);
    if (!c.dropped) continue;
    cut_last_line<Vec3, R>(points, a);
    if (!weights.empty()) cut_last_line<double, R>(weights, a);
  }
  for (std::size_t a = 0; a < R; ++a) d.shape[a] = points.extent(a);
  d.points = std::move(points);
  return d;
}

// The power of two that brings the data's largest coordinate near 1, where their
// coordinates are so large or so small that squared distances would overflow or
// vanish (the fit's sums of squares, its rms, its search for knots); 1 otherwise,
// leaving ordinary data untouched. Scaling by it is exact both ways.
template <std::size_t R>
double data_unit(const Grid<Vec3, R>& points) {
  double top = 0;
  for (const Vec3& q : points.values())
    if (is_finite(q)) top = std::max({top, std::abs(q.x), std::abs(q.y), std::abs(q.z)});
  constexpr double low = 0x1p-64, high = 0x1p64;  // squares between 2^-128 and 2^128: far from either end of double
  if (top == 0 || (top >= low && top <= high)) return 1;
  int e = 0;
  (void)std::frexp(top, &e);
  return std::ldexp(1.0, e);
}

// Finite points scaled by 1 / unit (NaN marks a missing point; infinite ones are kept
// for approximate() to name as given).
template <std::size_t R>
void scale_points(Grid<Vec3, R>& points, double factor) {
  for (Vec3& q : points.values())
    if (is_finite(q)) q = q * factor;
}

template <std::size_t R>
Result<R> run(Grid<Vec3, R> points, const ApproximationOptions<R>& options, const char* what) {
  check_request<R>(options, [&] {
    Shape<R> shape{};
    for (std::size_t a = 0; a < R; ++a) shape[a] = points.extent(a);
    return shape;
  }(), what);
  const double unit = data_unit<R>(points);
  const bool closed = std::any_of(options.periodic.begin(), options.periodic.end(), [](bool b) { return b; });
  // A copy of the options (and their weights) only where they change.
  std::optional<ApproximationOptions<R>> changed;
  if (unit != 1 || closed) changed = options;
  if (unit != 1) {
    scale_points<R>(points, 1 / unit);
    // Below the smallest double in the data's unit it could not be met anyway: the
    // refinement goes to its finest fit and says so.
    if (changed->tolerance)
      changed->tolerance = std::max(*changed->tolerance / unit, std::numeric_limits<double>::denorm_min());
  }
  const auto given = points.shape();
  Data<R> d;
  if (closed) {
    d = closed_data<R>(std::move(points), changed->weights, changed->periodic);
  } else {
    for (std::size_t a = 0; a < R; ++a) d.shape[a] = points.extent(a);
    d.points = std::move(points);
  }
  Result<R> r = approximate<R>(std::move(d), changed ? *changed : options, what);
  // A closing line left out has the parameter one period after the first line's.
  for (std::size_t a = 0; a < R; ++a)
    if (r.fit.axes[a].n < given[a]) r.fit.axes[a].t.push_back(r.fit.axes[a].t.front() + 1.0);
  if (unit != 1) {
    for (double& x : r.fit.cp) x *= unit;
    scale_points<R>(r.data.points, unit);
    r.report.max_error *= unit;
    r.report.rms_error *= unit;
  }
  return r;
}

}  // namespace

namespace {

// The fitted data as the checks of detail/approx_check.hpp take them.
template <std::size_t R>
detail::ApproxData check_data(const Data<R>& d) {
  return {std::vector<std::size_t>(d.shape.begin(), d.shape.end()), std::span<const Vec3>(d.points.data(), d.points.size()),
          std::span<const double>(d.weight)};
}

// The checks every result passes (docs/spec-format.md, "approximate"): a sane
// control net before the spline is made of it.
template <std::size_t R>
void check_net(const Result<R>& r, const Grid<Vec3, R>& net, const char* what) {
  std::vector<std::size_t> shape;
  for (std::size_t a = 0; a < R; ++a) shape.push_back(static_cast<std::size_t>(r.fit.axes[a].c));
  detail::check_approx_net(std::span<const Vec3>(net.data(), net.size()), shape, check_data<R>(r.data), what);
}

// Then the distances, measured on the finished spline by its own evaluator: the
// report's largest one, and the tolerance kept or refused.
template <std::size_t R>
void check_distance(Result<R>& r, const detail::ApproxDistance& e, const ApproximationOptions<R>& o) {
  r.report.max_error = e.max;
  r.report.max_error_at = unflatten<R>(e.worst, r.data.shape);
  if (o.tolerance) detail::check_approx_tolerance(e, *o.tolerance, check_data<R>(r.data), r.report.control_points);
}

}  // namespace

CurveApproximation approximate_curve(std::span<const Vec3> points, const CurveApproximationOptions& options) {
  Grid<Vec3, 1> g({points.size()}, std::vector<Vec3>(points.begin(), points.end()));
  Result<1> r = run<1>(std::move(g), options, "curve");
  Grid<Vec3, 1> net = control_net<1>(r.fit);
  check_net<1>(r, net, "curve approximation");
  std::vector<Vec3> cp(net.values().begin(), net.values().end());
  Axis& u = r.fit.axes[0];
  BSplineCurve curve(u.knots, std::move(cp));
  check_distance<1>(r, detail::approx_distance(curve, u.t, check_data<1>(r.data)), options);
  return {std::move(curve), std::move(u.t), std::move(r.report)};
}

SurfaceApproximation approximate_surface(PointGrid points, const SurfaceApproximationOptions& options) {
  Result<2> r = run<2>(std::move(points), options, "surface");
  PointGrid net = control_net<2>(r.fit);
  check_net<2>(r, net, "surface approximation");
  auto& ax = r.fit.axes;
  BSplineSurface surface(ax[0].knots, ax[1].knots, std::move(net));
  check_distance<2>(r, detail::approx_distance(surface, ax[0].t, ax[1].t, check_data<2>(r.data)), options);
  return {std::move(surface), std::move(ax[0].t), std::move(ax[1].t), std::move(r.report)};
}

VolumeApproximation approximate_volume(PointGrid3 points, const VolumeApproximationOptions& options) {
  Result<3> r = run<3>(std::move(points), options, "volume");
  PointGrid3 net = control_net<3>(r.fit);
  check_net<3>(r, net, "volume approximation");
  auto& ax = r.fit.axes;
  BSplineVolume volume(ax[0].knots, ax[1].knots, ax[2].knots, std::move(net));
  check_distance<3>(r, detail::approx_distance(volume, ax[0].t, ax[1].t, ax[2].t, check_data<3>(r.data)), options);
  return {std::move(volume), std::move(ax[0].t), std::move(ax[1].t), std::move(ax[2].t), std::move(r.report)};
}


// ------------------------------------------------------------------ split between processes

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "points move between processes as triples of doubles");
const Vec3* as_points(const double* d) { return reinterpret_cast<const Vec3*>(d); }
Vec3* as_points(double* d) { return reinterpret_cast<Vec3*>(d); }

// Every point present weighs 1, a missing one 0.
struct PresentWeighsOne {
  double operator()(std::size_t, const Vec3& q) const { return is_missing(q) ? 0.0 : 1.0; }
};

// A rows × width array of points held in consecutive blocks of rows (`mine` here),
// turned into columns: every row of this process's even share of the columns. Each
// point goes as w·Q, w = weight(its index among `rows`, Q), and as zeros where w is
// 0 (a missing point): the weighted data of right_hand_side, multiplied as there.
// `packed` is called once the rows are read.
template <class Weight = PresentWeighsOne>
std::vector<double> rows_to_columns(const Vec3* rows, std::size_t mine, std::size_t width, const detail::RowTeam& team,
                                    const std::function<void()>& packed = {}, const Weight& weight = {}) {
  const std::size_t P = team.processes(), me = team.process();
  const std::vector<double> counts = team.gather(std::vector<double>{static_cast<double>(mine)});
  std::size_t total = 0;
  for (const double c : counts) total += static_cast<std::size_t>(c);
  const std::size_t C = detail::even_share(width, me, P).second;
  std::vector<double> send;
  team.run([&] {
    require_memory(mine * width + total * C, sizeof(Vec3), "a transpose of the data between processes");
    send.resize(3 * mine * width);
  });
  std::vector<std::size_t> sc(P), rc(P);
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    const std::pair<std::size_t, std::size_t> cols = detail::even_share(width, s, P);
    for (std::size_t i = 0; i < mine; ++i) {
      const Vec3* from = rows + i * width + cols.first;
      Vec3* to = as_points(send.data()) + at + i * cols.second;
      for (std::size_t k = 0; k < cols.second; ++k) {
        const double w = weight(i * width + cols.first + k, from[k]);
        for (int x = 0; x < 3; ++x) to[k][x] = w > 0 ? w * from[k][x] : 0.0;
      }
    }
    sc[s] = mine * cols.second;
    rc[s] = static_cast<std::size_t>(counts[s]) * C;
    at += sc[s];
  }
  if (packed) packed();
  std::vector<double> out;
  team.run([&] { out.resize(3 * total * C); });
  team.exchange(as_points(send.data()), sc, as_points(out.data()), rc);
  return out;
}

// The reverse with a new split: columns (total × this process's even share of the
// width) to this process's even share of the rows, whole.
std::vector<double> columns_to_rows(const std::vector<double>& cols, std::size_t total, std::size_t width,
                                    const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process();
  const std::size_t C = detail::even_share(width, me, P).second, mine = detail::even_share(total, me, P).second;
  std::vector<std::size_t> sc(P), rc(P);
  for (std::size_t s = 0; s < P; ++s) {
    sc[s] = detail::even_share(total, s, P).second * C;
    rc[s] = mine * detail::even_share(width, s, P).second;
  }
  std::vector<double> recv, out;
  team.run([&] {
    require_memory(2 * mine * width, sizeof(Vec3), "a transpose of the data between processes");
    recv.resize(3 * mine * width);
    out.resize(3 * mine * width);
  });
  // The columns are in row order: process s's rows are the s-th run of them.
  team.exchange(as_points(cols.data()), sc, as_points(recv.data()), rc);
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    const std::pair<std::size_t, std::size_t> c = detail::even_share(width, s, P);
    for (std::size_t v = 0; v < mine; ++v, at += c.second)
      std::copy_n(recv.data() + 3 * at, 3 * c.second, out.data() + 3 * (v * width + c.first));
  }
  return out;
}

// Data points [first, first + count) of an axis: its basis values there.
Axis axis_slice(const Axis& ax, std::size_t first, std::size_t count) {
  Axis s = ax;
  const auto pp = static_cast<std::size_t>(ax.p) + 1;
  auto part = [&](const auto& v, std::size_t per) {
    using V = std::decay_t<decltype(v)>;
    return V(v.begin() + static_cast<std::ptrdiff_t>(first * per), v.begin() + static_cast<std::ptrdiff_t>((first + count) * per));
  };
  s.n = count;
  s.t = part(ax.t, 1);
  s.first = part(ax.first, 1);
  s.b = part(ax.b, pp);
  s.interval = part(ax.interval, 1);
  return s;
}

// Data rows [first, first + count) of a surface's grid held by this process: their
// part of the data term Σ w B Bᵀ, summed as one process sums it (point after point)
// and gathered into st on every process. A control row's entries take sums over the
// data rows its basis functions reach, in order: the rows whose data lie in one
// process's block are summed there, all at once; those whose data straddle the
// block before (a few rows at each boundary) start from the sums the processes
// before have reached, handed on in order, and go on with this process's points.
template <class Weight>
void add_block_data(Stencil<2>& st, const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b,
                    const Weight& weight, const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process(), c0 = st.c[0], c1 = st.c[1];
  const std::size_t row_len = c1 * st.size;  // doubles of a control row of the stencil
  const std::size_t base = b.first * shape[1], mine = b.count * shape[1];
  const Axis& u = axes[0];
  // The control rows each process's data rows reach: [lo, hi], −1 for none.
  const double lo_here = b.count > 0 ? static_cast<double>(u.first[b.first]) : -1.0;
  const double hi_here = b.count > 0 ? static_cast<double>(u.first[b.first + b.count - 1] + u.p) : -1.0;
  const std::vector<double> los = team.gather(std::vector<double>{lo_here}), his = team.gather(std::vector<double>{hi_here});
  auto has = [&](std::size_t r) { return los[r] >= 0; };
  auto lo_of = [&](std::size_t r) { return static_cast<std::size_t>(los[r]); };
  auto hi_of = [&](std::size_t r) { return static_cast<std::size_t>(his[r]); };
  auto before = [&](std::size_t r) {  // the last process before r with data rows, P for none
    for (std::size_t q = r; q-- > 0;)
      if (has(q)) return q;
    return P;
  };
  auto after = [&](std::size_t r) {
    for (std::size_t q = r + 1; q < P; ++q)
      if (has(q)) return q;
    return P;
  };
  // Rows [s_lo, s_hi] of process r continue the sums of the processes before it.
  auto continued = [&](std::size_t r) -> std::pair<std::size_t, std::size_t> {
    const std::size_t q = before(r);
    if (!has(r) || q == P || hi_of(q) < lo_of(r)) return {1, 0};
    return {lo_of(r), std::min(hi_of(r), hi_of(q))};
  };
  const std::pair<std::size_t, std::size_t> mine_continued = continued(me);
  const std::size_t s_lo = mine_continued.first, s_hi = mine_continued.second;
  auto in_continued = [&](std::size_t row) { return row / c1 >= s_lo && row / c1 <= s_hi; };
  add_weighted_points<2>(st.v.data(), st, axes, shape, base, mine, weight, [&](std::size_t row) { return !in_continued(row); });
  std::size_t width = 0;
  for (std::size_t r = 0; r < P; ++r) {
    const std::pair<std::size_t, std::size_t> c = continued(r);
    if (c.second >= c.first) width = std::max(width, c.second - c.first + 1);
  }
  std::vector<double> acc(width * row_len, 0.0);
  team.fold(acc, [&](std::span<double> a) {
    if (!has(me)) return;  // hands on what it got
    if (s_hi >= s_lo) {
      std::copy_n(a.data(), (s_hi - s_lo + 1) * row_len, st.v.data() + s_lo * row_len);
      add_weighted_points<2>(st.v.data(), st, axes, shape, base, mine, weight, in_continued);
    }
    if (const std::size_t next = after(me); next < P) {
      const std::pair<std::size_t, std::size_t> c = continued(next);
      if (c.second >= c.first) std::copy_n(st.v.data() + c.first * row_len, (c.second - c.first + 1) * row_len, a.data());
    }
  });
  // Each control row from the last process that added to it: process r the rows from
  // its first (0 for the first process with data) up to the next one's first.
  std::size_t own_lo = 0, own_hi = 0;
  if (has(me)) {
    own_lo = before(me) == P ? 0 : lo_of(me);
    own_hi = after(me) == P ? c0 : lo_of(after(me));
  }
  std::vector<double> all = team.gather(std::span<const double>(st.v.data() + own_lo * row_len, (own_hi - own_lo) * row_len));
  INTERPATCH_ASSERT(all.size() == st.v.size());
  st.v = std::move(all);
}

// add_block_data along a closed u. There the basis functions of the data rows near
// the seam wrap: the first rows (of an even degree, whose period starts half a step
// in) reach the last control rows, and the last rows the first ones, so a control
// row near the seam takes the sums of two runs of data rows, one at each end, the
// earlier run first. The control rows are unwrapped (data row i reaching rows
// first_i .. first_i + p, non-decreasing in i, with c0 + L rows in all, L ≤ p) and
// summed there by add_block_data; the rows past c0 repeat rows 0 .. L − 1, and
// their run of data continues the sums the earlier run reached: the processes that
// hold it add their points again to those rows, starting from the earlier sums and
// handing them on in order. Then the rows are wrapped back.
template <class Weight>
void add_closed_block_data(Stencil<2>& st, const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b,
                           const Weight& weight, const detail::RowTeam& team) {
  const Axis& u = axes[0];
  const int c0 = u.c;
  const std::size_t n = u.n;
  // Wrapped onto the knots' period, the parameters rise, drop once (where the data
  // pass the period's start) and rise again: the rows before the drop are a period lower.
  std::size_t drop = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (u.first[i] < u.first[i - 1]) {
      INTERPATCH_ASSERT(drop == 0);
      drop = i;
    }
  std::array<Axis, 2> open = axes;
  Axis& un = open[0];
  const int low = u.first[0] - (drop > 0 ? c0 : 0);
  for (std::size_t i = 0; i < n; ++i) un.first[i] = u.first[i] - (i < drop ? c0 : 0) - low;
  un.c = std::max(c0, un.first[n - 1] + u.p + 1);
  INTERPATCH_ASSERT(un.c <= 2 * c0);  // a control row repeated at most once
  Stencil<2> sw(open);
  add_block_data(sw, open, shape, b, weight, team);

  const auto extra = static_cast<std::size_t>(un.c - c0), c = static_cast<std::size_t>(c0);
  const std::size_t c1 = sw.c[1], row_len = c1 * sw.size;
  std::vector<double> late(extra * row_len, 0.0);
  if (extra > 0) {
    const std::size_t base = b.first * shape[1], mine = b.count * shape[1];
    const bool reaches = b.count > 0 && static_cast<std::size_t>(un.first[b.first + b.count - 1] + u.p) >= c;
    const std::vector<double> all = team.gather(std::vector<double>{reaches ? 1.0 : 0.0});
    const bool first_to_reach = reaches && std::find(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(team.process()), 1.0) ==
                                               all.begin() + static_cast<std::ptrdiff_t>(team.process());
    team.fold(late, [&](std::span<double> acc) {
      if (!reaches) return;  // hands on what it got
      double* rows = sw.v.data() + c * row_len;
      std::copy_n(first_to_reach ? sw.v.data() : acc.data(), extra * row_len, rows);
      add_weighted_points<2>(sw.v.data(), sw, open, shape, base, mine, weight, [&](std::size_t row) { return row / c1 >= c; });
      std::copy_n(rows, extra * row_len, acc.data());
    });
  }
  // Unwrapped row x is control row x + low, modulo c0.
  for (std::size_t x = 0; x < c; ++x) {
    const auto row = static_cast<std::size_t>(((static_cast<long long>(x) + low) % c0 + c0) % c0);
    std::copy_n(x < extra ? late.data() + x * row_len : sw.v.data() + x * row_len, row_len, st.v.data() + row * row_len);
  }
}

// Counts held as doubles (gathered between processes), as counts.
template <class It>
std::vector<std::size_t> as_counts(It first, It last) {
  std::vector<std::size_t> c;
  for (; first != last; ++first) c.push_back(static_cast<std::size_t>(*first));
  return c;
}

// closed_data on a grid held in blocks of rows: a closed direction's last line that
// repeats the first is left out of the block (along v out of each of its rows, in
// place); one that nearly repeats it is refused. Whether each was left out.
std::array<bool, 2> close_block(detail::GridBlock& b, const std::array<bool, 2>& periodic, bool missing,
                                const detail::RowTeam& team) {
  std::array<bool, 2> dropped{};
  for (std::size_t a = 0; a < 2; ++a) {
    if (!periodic[a] || b.n[a] < 3) continue;
    if (missing) break;
    INTERPATCH_ASSERT(a > 0 || b.ends[0] != nullptr);
    const Closing c = detail::block_closing(b, a, b.ends, false, team);
    if (c.nearly) team.run([&] { refuse_closing_gap(a); });
    if (!c.dropped) continue;
    dropped[a] = true;
    const std::size_t n = b.n[a]--;
    if (a == 0) {
      b.count = b.first < n - 1 ? std::min(b.count, n - 1 - b.first) : 0;
      b.last = b.ends[2];
    } else {
      for (std::size_t r = 1; r < b.count; ++r) std::copy(b.data + r * n, b.data + r * n + n - 1, b.data + r * (n - 1));
    }
  }
  return dropped;
}

// ------------------------------------------------------------------ a fit on blocks of rows

// Bᵀ (w Q) of a grid of M columns held in blocks of rows, from its columns `cols`
// (rows_to_columns: every row of this process's even share of the columns): along u
// on the columns (`read` is called when they are read no more), along v on this
// process's even share of the control rows of the result.
std::vector<double> block_rhs(const std::array<Axis, 2>& axes, const std::vector<double>& cols, std::size_t M,
                              const detail::RowTeam& team, const std::function<void()>& read = {}) {
  const std::size_t P = team.processes(), me = team.process();
  const auto c0 = static_cast<std::size_t>(axes[0].c);
  std::vector<double> tmp, rhs;
  Shape<2> cs{axes[0].n, detail::even_share(M, me, P).second};
  basis_pass<true, 2>(axes[0], cols.data(), cs, 0, tmp);
  if (read) read();
  std::vector<double> rows = columns_to_rows(tmp, c0, M, team);
  Shape<2> rs{detail::even_share(c0, me, P).second, M};
  basis_pass<true, 2>(axes[1], rows.data(), rs, 1, rhs);
  return rhs;
}

// Both directions' factored Gram matrices (separable_fit), or none when one is
// singular: the sparse system then settles what the data leave open.
std::array<std::optional<AxisSolver>, 2> separable_solvers(const std::array<Axis, 2>& axes, const detail::RowTeam& team) {
  std::array<std::optional<AxisSolver>, 2> lu;
  team.run([&] {
    try {
      for (std::size_t a = 0; a < 2; ++a) lu[a] = factor_gram(axes[a], a);
    } catch (const error& e) {
      if (e.code() != errc::singular) throw;
      lu = {};
    }
  });
  return lu;
}

// The separable solve of the right-hand side's rows (block_rhs: this process's even
// share of the c0 control rows): its control rows, along u on columns, along v on rows.
std::vector<double> separable_rows(const std::array<std::optional<AxisSolver>, 2>& lu, const std::vector<double>& rhs,
                                   std::size_t c0, std::size_t c1, const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process(), nr = detail::even_share(c0, me, P).second;
  std::vector<double> cols = rows_to_columns(as_points(rhs.data()), nr, c1, team);
  const std::size_t cshape[2] = {c0, detail::even_share(c1, me, P).second}, rshape[2] = {nr, c1};
  std::visit([&](const auto& s) { solve_along_axis(s, cols.data(), cshape, 2, 0, 3); }, *lu[0]);
  std::vector<double> rows = columns_to_rows(cols, c0, c1, team);
  std::visit([&](const auto& s) { solve_along_axis(s, rows.data(), rshape, 2, 1, 3); }, *lu[1]);
  return rows;
}

// The sparse normal equations of a grid held in blocks of rows (b: this process's),
// its weights summing to `weight_sum`: the data term from the Gram matrices when every
// point is present with weight 1 (`uniform`), else summed over the points
// (add_block_data; add_closed_block_data along a closed u).
template <class Weight>
SparseSystem<2> block_system(const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b, bool uniform,
                             const Weight& weight, double weight_sum, const detail::RowTeam& team) {
  Stencil<2> st(axes);
  if (uniform) add_grams<2>(st, axes);
  else if (axes[0].periodic) add_closed_block_data(st, axes, shape, b, weight, team);
  else add_block_data(st, axes, shape, b, weight, team);
  return SparseSystem<2>(axes, st, weight_sum, shape[0] * shape[1]);
}

// The fitted surface of f as approximate_rows returns it, `mine` this process's even
// share of the control rows (none: f.cp holds them all).
detail::ApproxRows net_rows(const Fit<2>& f, const detail::RowTeam& team, const double* mine = nullptr) {
  detail::ApproxRows out;
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const std::pair<std::size_t, std::size_t> share = detail::even_share(c0, team.process(), team.processes());
  if (!mine) mine = f.cp.data() + 3 * share.first * c1;
  out.first = share.first;
  if (share.second > 0) out.rows.assign(as_points(mine), as_points(mine) + share.second * c1);
  for (std::size_t a = 0; a < 2; ++a) {
    out.degree[a] = f.axes[a].p;
    out.knots[a] = f.axes[a].knots.mapped(0.0, 1.0);
  }
  out.net = {c0, c1};
  return out;
}

// A surface's grid held in blocks of rows as a fit to a tolerance sees it (Whole's
// counterpart for solve_tolerance): each process fits, measures and gathers lines on
// its rows; what comes back (the control net, the maxima, the lines) is the same on
// every process, as one process finds it, so every process takes the same knot
// decisions. The block's columns (for Bᵀ w Q) are made once and kept between fits.
// Weights and closed directions as in approximate_rows: the weighted points in the
// columns, the data term summed with the weights (wrapped along a closed u), the
// weight sum added point after point in storage order.
class Block {
  // Each point's weight by its flat index in the grid, as Data::w: 1 everywhere when
  // uniform, else 0 where missing and the given weight (1 when none) elsewhere.
  [[nodiscard]] auto weight() const {
    return [this](std::size_t flat) {
      if (uniform_) return 1.0;
      const std::size_t i = flat - first_ * n_[1];
      if (!present_[i]) return 0.0;
      return w_ ? w_[i] : 1.0;
    };
  }

 public:
  // Rows [first, first + count) of a grid of `shape` at `pts` (`own` holds them for
  // a thinned grid), their weights at `w` (none: every point present weighs 1;
  // `own_w` holds them for a thinned grid). `uniform`: the grid it comes from has
  // every point and equal weights (the data term from the Gram matrices, the
  // separable fit tried first, as Data::uniform).
  Block(const detail::RowTeam& team, const Shape<2>& shape, std::shared_ptr<const std::vector<Vec3>> own, const Vec3* pts,
        std::size_t first, std::size_t count, bool uniform, std::shared_ptr<const std::vector<double>> own_w = {},
        const double* w = nullptr)
      : team_(&team), n_(shape), own_(std::move(own)), pts_(pts), first_(first), count_(count), uniform_(uniform),
        own_w_(std::move(own_w)), w_(w) {
    const std::size_t M = n_[1], base = first_ * M;
    if (!uniform_) {
      present_.resize(count_ * M);
      for (std::size_t i = 0; i < present_.size(); ++i) present_[i] = !is_missing(pts_[i]);
    }
    // Points without data (missing or of weight 0): the fill term (needs_fill).
    std::size_t empty[1] = {0};
    for (std::size_t i = 0; i < present_.size(); ++i) empty[0] += weight()(base + i) > 0 ? 0 : 1;
    team.sum(empty);
    fill_ = empty[0] > 0;
    std::vector<double> sum(1, static_cast<double>(n_[0] * M));
    if (!uniform_) {
      sum[0] = 0;
      team.fold(sum, [&](std::span<double> acc) {
        for (std::size_t i = 0; i < present_.size(); ++i)
          if (const double x = weight()(base + i); x > 0) acc[0] += x;
      });
    }
    weight_sum_ = sum[0];
    const std::vector<double> span = team.gather(std::vector<double>{static_cast<double>(first_), static_cast<double>(count_)});
    for (std::size_t s = 0; s < span.size(); s += 2) spans_.emplace_back(static_cast<std::size_t>(span[s]), static_cast<std::size_t>(span[s + 1]));
    cols_ = rows_to_columns(pts_, count_, M, team, {}, [&](std::size_t i, const Vec3&) { return weight()(base + i); });
    std::vector<double> box(6, -std::numeric_limits<double>::infinity());  // −lo, hi
    for (std::size_t i = 0; i < count_ * M; ++i)
      if (weight()(base + i) > 0)
        for (std::size_t k = 0; k < 3; ++k) {
          box[k] = std::max(box[k], -pts_[i][static_cast<int>(k)]);
          box[k + 3] = std::max(box[k + 3], pts_[i][static_cast<int>(k)]);
        }
    team.max(box);
    box_ = {Vec3{-box[0], -box[1], -box[2]}, Vec3{box[3], box[4], box[5]}};
  }

  [[nodiscard]] std::size_t size() const { return n_[0] * n_[1]; }
  [[nodiscard]] const Shape<2>& shape() const { return n_; }

  // solve_once without a smoothing weight.
  void fit(Fit<2>& f) const {
    ++f.fits;
    const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
    const std::vector<double> rhs = block_rhs(f.axes, cols_, n_[1], *team_);
    if (uniform_) {
      if (const auto lu = separable_solvers(f.axes, *team_); lu[0]) {
        f.lambda = 0;
        f.cp = team_->gather(separable_rows(lu, rhs, c0, c1, *team_));
        return;
      }
    }
    detail::GridBlock b;
    b.rank = 2;
    b.n = {n_[0], n_[1], 0};
    b.first = first_;
    b.count = count_;
    SparseSystem<2> sys = block_system(f.axes, n_, b, uniform_, weight(), weight_sum_, *team_);
    const std::vector<double> all_rhs = team_->gather(rhs);
    // The separable fit refused (uniform): the fill term settles what the data leave open.
    team_->run([&] { sparse_fit<2>(f, sys, all_rhs, std::nullopt, fill_ || uniform_); });
  }

  // Whole::sane: the box of every process's data (found when the block is made), the
  // control net whole on every process.
  [[nodiscard]] bool sane(const Fit<2>& f) const { return detail::approx_net_sane(net_points(f.cp), 2, box_); }

  // residuals(): each process its rows, the maxima and worst points merged in process
  // order (a later process's only where strictly greater: the first in one process's
  // scan wins). The sums of squares are this process's alone: the fit to a tolerance
  // reads only the maxima.
  [[nodiscard]] Residuals<2> errors(const Fit<2>& f) const {
    const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
    const Axis slice = axis_slice(f.axes[0], first_, count_);
    Shape<2> sh{c0, c1};
    std::vector<double> partial;
    basis_pass<false, 2>(slice, f.cp.data(), sh, 0, partial);
    const Residuals<2> mine =
        residual_blocks<2>(f.axes, n_, partial.data(), pts_, first_, first_, first_ + count_, weight());
    std::vector<double> pack{mine.max, static_cast<double>(mine.worst)};
    for (std::size_t a = 0; a < 2; ++a) {
      pack.insert(pack.end(), mine.interval_max[a].begin(), mine.interval_max[a].end());
      for (const std::size_t w : mine.interval_worst[a]) pack.push_back(static_cast<double>(w));
    }
    const std::vector<double> all = team_->gather(pack);
    Residuals<2> r(f.axes);
    for (std::size_t at = 0; at < all.size(); at += pack.size()) {
      Residuals<2> part(f.axes);
      const double* x = all.data() + at;
      part.max = *x++;
      part.worst = static_cast<std::size_t>(*x++);
      for (std::size_t a = 0; a < 2; ++a) {
        for (double& m : part.interval_max[a]) m = *x++;
        for (std::size_t& w : part.interval_worst[a]) w = static_cast<std::size_t>(*x++);
      }
      r.merge(part);
    }
    take_roots<2>(r);
    return r;
  }

  // line_residual at each (axis, point) of `at`: the lines gathered from the
  // processes holding them (along u a column of every process's rows, along v one
  // process's row), all in one exchange, then fitted on every process.
  [[nodiscard]] std::vector<double> line_residuals(const Fit<2>& f, const std::array<std::optional<AxisSolver>, 2>& lu,
                                                   const std::vector<std::pair<std::size_t, std::size_t>>& at) const {
    const std::size_t M = n_[1];
    const auto w = weight();
    auto holds = [&](std::size_t s, std::size_t row) { return row >= spans_[s].first && row < spans_[s].first + spans_[s].second; };
    std::vector<double> mine;
    auto put = [&](std::size_t flat) {
      const Vec3 v = point_or_fit<2>(f.axes, f.cp, n_, pts_[flat - first_ * M], w(flat) > 0, flat);
      mine.insert(mine.end(), {v.x, v.y, v.z});
    };
    for (const auto& [a, i] : at) {
      if (a == 0)
        for (std::size_t r = first_; r < first_ + count_; ++r) put(r * M + i % M);
      else if (holds(team_->process(), i / M))
        for (std::size_t j = 0; j < M; ++j) put(i / M * M + j);
    }
    const std::vector<double> all = team_->gather(mine);
    std::vector<std::vector<double>> lines;
    for (const auto& [a, i] : at) lines.emplace_back(3 * n_[a]);
    std::size_t from = 0;
    for (std::size_t s = 0; s < spans_.size(); ++s)
      for (std::size_t k = 0; k < at.size(); ++k) {
        const auto& [a, i] = at[k];
        if (a == 0) {
          std::copy_n(all.data() + from, 3 * spans_[s].second, lines[k].data() + 3 * spans_[s].first);
          from += 3 * spans_[s].second;
        } else if (holds(s, i / M)) {
          std::copy_n(all.data() + from, 3 * M, lines[k].data());
          from += 3 * M;
        }
      }
    std::vector<double> e;
    for (std::size_t k = 0; k < at.size(); ++k) {
      const auto& [a, i] = at[k];
      e.push_back(line_fit_residual(f.axes[a], *lu[a], lines[k], a == 0 ? i / M : i % M));
    }
    return e;
  }

  // Which rows and columns hold data (a point of positive weight): rows from their
  // process, columns OR-reduced.
  [[nodiscard]] std::array<std::vector<bool>, 2> has_data() const {
    std::array<std::vector<bool>, 2> has{std::vector<bool>(n_[0], true), std::vector<bool>(n_[1], true)};
    if (uniform_) return has;
    const auto w = weight();
    std::vector<double> rows(count_, 0.0), cols(n_[1], 0.0);
    for (std::size_t r = 0; r < count_; ++r)
      for (std::size_t j = 0; j < n_[1]; ++j)
        if (w((first_ + r) * n_[1] + j) > 0) rows[r] = cols[j] = 1.0;
    const std::vector<double> all = team_->gather(rows);
    team_->max(cols);
    for (std::size_t r = 0; r < n_[0]; ++r) has[0][r] = all[r] > 0;
    for (std::size_t j = 0; j < n_[1]; ++j) has[1][j] = cols[j] > 0;
    return has;
  }

  // thinned(): the kept rows in this block (a block of the thinned grid's rows, maybe
  // none), the kept columns of each, with their weights.
  [[nodiscard]] Block thinned(const std::array<std::vector<std::size_t>, 2>& kept) const {
    const auto& rows = kept[0];
    const std::size_t lo = static_cast<std::size_t>(std::lower_bound(rows.begin(), rows.end(), first_) - rows.begin());
    const std::size_t hi = static_cast<std::size_t>(std::lower_bound(rows.begin(), rows.end(), first_ + count_) - rows.begin());
    const std::size_t K = kept[1].size();
    auto own = std::make_shared<std::vector<Vec3>>((hi - lo) * K);
    auto own_w = std::make_shared<std::vector<double>>(w_ ? (hi - lo) * K : 0);
    for (std::size_t r = lo; r < hi; ++r)
      for (std::size_t k = 0; k < K; ++k) {
        const std::size_t from = (rows[r] - first_) * n_[1] + kept[1][k], to = (r - lo) * K + k;
        (*own)[to] = pts_[from];
        if (w_) (*own_w)[to] = w_[from];
      }
    const Vec3* p = own->data();
    const double* w = w_ ? own_w->data() : nullptr;
    return {*team_, {rows.size(), K}, std::move(own), p, lo, hi - lo, uniform_, std::move(own_w), w};
  }

 private:
  const detail::RowTeam* team_;
  Shape<2> n_;
  std::shared_ptr<const std::vector<Vec3>> own_;
  const Vec3* pts_;
  std::size_t first_, count_;
  bool uniform_;
  std::shared_ptr<const std::vector<double>> own_w_;
  const double* w_;               // the block's weights, none: 1 each
  bool fill_ = false;             // points without data (missing or of weight 0) in this grid
  double weight_sum_ = 0;         // of the whole grid's weights, in storage order
  std::vector<bool> present_;     // per point of the block, unless uniform
  std::vector<std::pair<std::size_t, std::size_t>> spans_;  // every process's {first, count}
  std::vector<double> cols_;      // the block's columns (rows_to_columns)
  std::array<Vec3, 2> box_{};     // the whole grid's data's box (Whole::sane)
};

// This process's rows of the data as the checks of detail/approx_check.hpp take
// them (`w` holds their weights).
template <class Weight>
detail::ApproxData block_data(const detail::GridBlock& b, const Weight& weight, std::vector<double>& w) {
  const std::size_t M = b.n[1], base = b.first * M;
  w.resize(b.count * M);
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = weight(base + i);
  return {{b.count, M}, std::span<const Vec3>(b.data, b.count * M), w};
}

// The data's bounding box over every process, as two corners (check_rows_net).
template <class Weight>
std::vector<Vec3> block_box(const detail::GridBlock& b, const Weight& weight, const detail::RowTeam& team) {
  std::vector<double> w;
  const detail::ApproxData mine = block_data(b, weight, w);
  std::vector<double> box(6, -std::numeric_limits<double>::infinity());  // −lo, hi
  for (std::size_t i = 0; i < mine.points.size(); ++i)
    if (mine.present(i))
      for (std::size_t k = 0; k < 3; ++k) {
        const double x = mine.points[i][static_cast<int>(k)];
        box[k] = std::max(box[k], -x);
        box[k + 3] = std::max(box[k + 3], x);
      }
  team.max(box);
  return {{-box[0], -box[1], -box[2]}, {box[3], box[4], box[5]}};
}

// check_approx_net on a split run, `box` from block_box: each process checks its own
// control rows (the first with a bad one reports it).
void check_rows_net(const detail::ApproxRows& out, const std::vector<Vec3>& box, const detail::RowTeam& team) {
  const detail::ApproxData corners{{box.size()}, box, {}};
  team.run([&] {
    if (out.rows.empty()) return;
    detail::check_approx_net(out.rows, {out.rows.size() / out.net[1], out.net[1]}, corners, "surface approximation");
  });
}

// The tolerance kept or refused on a split run, measured as approximate_surface
// measures it (the spline's own evaluator): each process at its rows, the worst
// over the processes (the first in row order among equals).
template <class Weight>
void check_rows_tolerance(const Fit<2>& f, const detail::GridBlock& b, const Weight& weight, double tol,
                          const detail::RowTeam& team) {
  PointGrid net({static_cast<std::size_t>(f.axes[0].c), static_cast<std::size_t>(f.axes[1].c)}, for_overwrite);
  std::copy_n(f.cp.data(), f.cp.size(), &net.data()->x);
  std::vector<double> w;
  detail::ApproxData mine = block_data(b, weight, w);
  detail::ApproxDistance e;
  team.run([&] {
    const BSplineSurface s(f.axes[0].knots, f.axes[1].knots, std::move(net));
    if (b.count > 0) {
      const std::vector<double> tu(f.axes[0].t.begin() + static_cast<std::ptrdiff_t>(b.first),
                                   f.axes[0].t.begin() + static_cast<std::ptrdiff_t>(b.first + b.count));
      e = detail::approx_distance(s, tu, f.axes[1].t, mine);
    }
  });
  const std::vector<double> all = team.gather(std::vector<double>{e.max, static_cast<double>(b.first * b.n[1] + e.worst)});
  detail::ApproxDistance worst;
  for (std::size_t k = 0; k < all.size(); k += 2)
    if (all[k] > worst.max) worst = {all[k], static_cast<std::size_t>(all[k + 1])};
  mine.shape = {b.n[0], b.n[1]};
  std::vector<int> cps{f.axes[0].c, f.axes[1].c};
  team.run([&] { detail::check_approx_tolerance(worst, tol, mine, cps); });
}

}  // namespace

namespace detail {

ApproxRows approximate_rows(const GridBlock& given, const SurfaceApproximationOptions& o, const RowTeam& team,
                            const std::function<void()>& release) {
  constexpr std::size_t R = 2;
  INTERPATCH_ASSERT(given.rank == 2);

  // Missing points (NaN); closed directions, whose closing line is looked for only
  // where none is missing (closed_data).
  std::size_t missing[1] = {0};
  for (std::size_t i = 0; i < given.count * given.n[1]; ++i) missing[0] += is_missing(given.data[i]) ? 1 : 0;
  team.sum(missing);
  GridBlock b = given;
  const std::array<bool, R> dropped = close_block(b, o.periodic, missing[0] > 0, team);
  // The weights, without the lines left out (a copy only then).
  Grid<double, R> cut;
  if (!o.weights.empty() && (dropped[0] || dropped[1])) {
    cut = o.weights;
    for (std::size_t a = 0; a < R; ++a)
      if (dropped[a]) cut_last_line<double, R>(cut, a);
  }
  const Grid<double, R>& weights = cut.empty() ? o.weights : cut;

  const Shape<R> shape{b.n[0], b.n[1]};
  const std::size_t M = shape[1], total = shape[0] * shape[1], mine = b.count * M, base = b.first * M;
  const Vec3* pts = b.data;
  team.run([&] {
    check_request<R>(o, shape, "surface");
    if (!weights.empty()) check_weights<R>(weights, shape);
  });

  // Each point's weight as approximate() finds it: 0 where missing; 1 everywhere
  // when every point is present and the weights (if any) are equal.
  const bool uniform = missing[0] == 0 && std::all_of(weights.values().begin(), weights.values().end(),
                                                      [&](double w) { return w == weights.values().front(); });
  const bool zero_weight = std::any_of(weights.values().begin(), weights.values().end(), [](double w) { return !(w > 0); });
  const bool fill = !uniform && (missing[0] > 0 || zero_weight);  // needs_fill
  // Which points are present, kept past the points themselves.
  std::vector<bool> present_here(missing[0] > 0 ? mine : 0);
  for (std::size_t i = 0; i < present_here.size(); ++i) present_here[i] = !is_missing(pts[i]);
  auto given_weight = [&](std::size_t flat) {
    if (!present_here.empty() && !present_here[flat - base]) return 0.0;
    return weights.empty() ? 1.0 : weights.values()[flat];
  };
  auto weight = [&](std::size_t flat) { return uniform ? 1.0 : given_weight(flat); };
  // The points with a positive weight, and their weights' sum in the order of the points.
  std::size_t present[1] = {0};
  for (std::size_t i = base; i < base + mine; ++i) present[0] += given_weight(i) > 0 ? 1 : 0;
  team.sum(present);
  std::vector<double> weight_sum(1, static_cast<double>(total));
  if (!uniform) {
    weight_sum[0] = 0;
    team.fold(weight_sum, [&](std::span<double> acc) {
      for (std::size_t i = base; i < base + mine; ++i)
        if (const double w = weight(i); w > 0) acc[0] += w;
    });
  }
  team.run([&] {
    if (present[0] == 0)
      fail(errc::too_few_points, "all ", total, " points are missing or have weight 0: there is nothing to approximate");
  });

  // Degrees and parameters.
  // In one process's order: the degree along u, the parameters along u, the degree
  // along v (a refusal kept until the parameters along u are found), along v.
  Fit<R> f;
  team.run([&] { set_degree<R>(f.axes[0], o, 0, shape[0]); });
  std::exception_ptr v_degree;
  try {
    set_degree<R>(f.axes[1], o, 1, shape[1]);
  } catch (const error&) {
    v_degree = std::current_exception();
  }
  const std::size_t axes = v_degree ? 1 : R;
  // As axis_parameters: interpolation's parameters along an open direction without
  // missing points, else the mean chords summed over the lines.
  std::array<bool, R> by_sums{};
  for (std::size_t a = 0; a < R; ++a) by_sums[a] = o.periodic[a] || missing[0] > 0;
  auto interpolation_parameters = [&](std::size_t a) {
    const std::vector<std::vector<double>> t = block_parameters(b, o.param, team, a + 1, a == 0);
    f.axes[a].t = t[a];
  };
  auto chord_sums = [&](std::size_t a) {
    if (a == 0) {
      // Each step's chords lie in the rows of one process (the row before the block
      // from its neighbour; the closing step, back to row 0, in the last rows) and
      // are summed over the row, as in one process.
      std::vector<double> sum0, used0;
      auto step = [&](const Vec3* prev, const Vec3* next) {
        double sum = 0;
        std::size_t used = 0;
        for (std::size_t i = 0; i < M; ++i) add_chord(prev[i], next[i], sum, used);
        sum0.push_back(sum);
        used0.push_back(static_cast<double>(used));
      };
      for (std::size_t k = b.first == 0 ? 1 : 0; k < b.count; ++k) step(k == 0 ? b.before : pts + (k - 1) * M, pts + k * M);
      if (o.periodic[0] && b.count > 0 && b.first + b.count == shape[0]) step(pts + (b.count - 1) * M, b.row0);
      const std::vector<double> all_sum0 = team.gather(sum0), all_used0 = team.gather(used0);
      team.run([&] {
        f.axes[0].t = parameters_from_sums(all_sum0, as_counts(all_used0.begin(), all_used0.end()), shape[0], 0, o.param,
                                           o.periodic[0]);
      });
      return;
    }
    // The lines along v are summed row after row, a running sum passed on in order.
    const std::size_t steps1 = o.periodic[1] ? M : M - 1;
    std::vector<double> acc1(2 * steps1, 0.0);
    team.fold(acc1, [&](std::span<double> acc) {
      for (std::size_t r = 0; r < b.count; ++r)
        for (std::size_t k = 1; k <= steps1; ++k) {
          std::size_t used = 0;
          add_chord(pts[r * M + k - 1], pts[r * M + k % M], acc[k - 1], used);
          acc[steps1 + k - 1] += static_cast<double>(used);
        }
    });
    team.run([&] {
      f.axes[1].t = parameters_from_sums(std::vector<double>(acc1.begin(), acc1.begin() + static_cast<std::ptrdiff_t>(steps1)),
                                         as_counts(acc1.begin() + static_cast<std::ptrdiff_t>(steps1), acc1.end()), shape[1], 1,
                                         o.param, o.periodic[1]);
    });
  };
  if (o.param == Parametrization::uniform) {
    for (std::size_t a = 0; a < R; ++a) f.axes[a].t = uniform_parameters(shape[a], o.periodic[a]);
  } else if (!by_sums[0] && !by_sums[1] && axes == R) {
    std::vector<std::vector<double>> t = block_parameters(b, o.param, team, axes);
    for (std::size_t a = 0; a < R; ++a) f.axes[a].t = std::move(t[a]);
  } else {
    for (std::size_t a = 0; a < axes; ++a) {
      if (by_sums[a]) chord_sums(a);
      else interpolation_parameters(a);
    }
  }
  team.run([&] {
    if (v_degree) std::rethrow_exception(v_degree);
  });
  // The data's box, taken before the points may be released.
  const std::vector<Vec3> box = block_box(b, weight, team);
  if (o.tolerance) {
    // The knots grow and are pruned on every process alike (solve_tolerance), the
    // fits and measures on the blocks (Block).
    const Block whole(team, shape, nullptr, pts, b.first, b.count, uniform, nullptr,
                      weights.empty() ? nullptr : weights.values().data() + std::min(base, weights.size()));
    solve_tolerance<R>(f, whole, *o.tolerance, {});
    check_rows_tolerance(f, b, weight, *o.tolerance, team);
    detail::ApproxRows out = net_rows(f, team);
    check_rows_net(out, box, team);
    return out;
  }
  team.run([&] {
    check_control_points<R>(f.axes, o);
    set_fit_knots<R>(f.axes, o);
  });
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);

  // Bᵀ (w Q): along u on columns of the data, along v on rows of the result.
  std::vector<double> rhs;
  {
    std::vector<double> cols = rows_to_columns(
        pts, b.count, M, team, [&] {
          if (release && !o.auto_smoothing) release();
        },
        [&](std::size_t i, const Vec3&) { return weight(base + i); });
    rhs = block_rhs(f.axes, cols, M, team, [&] { std::vector<double>().swap(cols); });
  }

  // The separable fit when it applies (separable_fit), else the sparse system, with
  // the term that fills holes where some weight is 0 or the separable fit fails.
  std::array<std::optional<AxisSolver>, R> lu;
  const bool separable = !o.smoothing && !o.auto_smoothing && uniform;
  if (separable) lu = separable_solvers(f.axes, team);
  if (lu[0]) {
    detail::ApproxRows out = net_rows(f, team, separable_rows(lu, rhs, c0, c1, team).data());
    check_rows_net(out, box, team);
    return out;
  }
  const bool filled = fill || separable;
  {  // the sparse system
    SparseSystem<R> sys = block_system(f.axes, shape, b, uniform, weight, weight_sum[0], team);
    const std::vector<double> all_rhs = team.gather(rhs);
    if (o.auto_smoothing) {
      // Σ w r² over the data: blocks of rows as in residuals(), their sums added in order.
      const Axis slice = axis_slice(f.axes[0], b.first, b.count);
      const std::vector<std::size_t> off = residual_offsets(f.axes[1]);
      std::vector<double> row(3 * M), e2(M);
      auto rss = [&](const std::vector<double>& cp) {
        Shape<R> sh{c0, c1};
        std::vector<double> partial;
        basis_pass<false, R>(slice, cp.data(), sh, 0, partial);
        std::vector<double> sums;
        for (std::size_t q = b.first; q < b.first + b.count; q += residual_block_rows) {
          Residuals<R> r(f.axes);
          residual_rows<R>(r, f.axes, shape, partial.data(), pts, b.first, q,
                           std::min(b.first + b.count, q + residual_block_rows), weight, off.data(), row.data(), e2.data());
          sums.push_back(r.weighted_sq);
        }
        std::vector<double> acc(1, 0.0);
        team.fold(acc, [&](std::span<double> a) {
          for (const double x : sums) a[0] += x;
        });
        return acc[0];
      };
      team.run([&] { gcv_fit<R>(f, sys, all_rhs, present[0], fill, rss); });
    } else {
      team.run([&] { sparse_fit<R>(f, sys, all_rhs, o.smoothing, filled); });
    }
  }
  detail::ApproxRows out = net_rows(f, team);
  check_rows_net(out, box, team);
  return out;
}

}  // namespace detail

}  // namespace interpatch
