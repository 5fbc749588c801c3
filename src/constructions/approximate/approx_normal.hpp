#pragma once
// The normal equations of the least-squares fit as a sparse symmetric system: the
// stencil of each control point's entries, the data term (from the directions' Gram
// matrices or summed point by point, in storage order, over any block of the
// points), the fairness term, and their factored sum G + λ s K.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "constructions/approximate/approx_axes.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::approx {

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

// The parts of SparseSystem the number of directions does not change.
struct SparseEquations {
  Eigen::SparseMatrix<double> data, fairness;
  double scale = 0;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool analyzed = false;

  // Factors G + λ s K (the pattern analysed once); refuses (singular) a system
  // without a unique solution.
  void factor(double lambda);
  // What makes λ s K a given fraction of the data term.
  [[nodiscard]] double diagonal_ratio() const;
  // The control points for the right-hand side `rhs` (3 doubles a control point).
  [[nodiscard]] std::vector<double> solve(const std::vector<double>& rhs) const;
  // tr(M⁻¹ λ s K), M = G + λ s K, estimated with `probes` random vectors.
  [[nodiscard]] double fairness_trace(double lambda, int probes) const;
};

// The sparse normal equations G + λ s K: G the data term, K the fairness term
// (Σ_a n_a R_a ⊗ the Gram matrices of the other directions), s = Σw / N.
template <std::size_t R>
struct SparseSystem : SparseEquations {
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
};

}  // namespace interpatch::detail::approx
