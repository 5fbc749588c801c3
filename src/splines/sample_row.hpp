#pragma once
// The last contraction of a grid evaluation of a B-spline surface or volume: points
// along the last direction from one row of control points already contracted over
// the others (a surface's row of points, a volume's row of homogeneous points).

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

#include "splines/basis_table.hpp"

namespace interpatch::detail {

/// Basis functions of the parameters of the last direction packed for
/// sample_points: their spans, and q + 1 values a parameter one after another.
struct PackedBasis {
  std::vector<int> spans;
  std::vector<double> weights;
};

/// The values (no derivatives) of a basis table of degree q, packed.
template <int Orders>
PackedBasis packed(const std::vector<BasisRow<Orders>>& rows, int q) {
  const auto q1 = static_cast<std::size_t>(q + 1);
  PackedBasis t{std::vector<int>(rows.size()), std::vector<double>(rows.size() * q1)};
  for (std::size_t j = 0; j < rows.size(); ++j) {
    t.spans[j] = rows[j].span;
    std::copy_n(rows[j].d, q1, t.weights.data() + j * q1);
  }
  return t;
}

/// out[j] (3 doubles) = Σ_k weights[j (q + 1) + k] row[Stride (spans[j] − q + k) ..]
/// for j < n: row holds a point every Stride doubles (3, or 4 for homogeneous points)
/// and, for Stride 3, one double of slack after the last. Each point is summed in
/// four lanes (x, y, z and the next double, discarded) and stored four doubles
/// wide, the fourth overwritten by the next point; the last point is summed in the
/// same order one coordinate at a time. Q1 = q + 1 when it is known at compile time
/// (the loop over k unrolled), 0 when it is not. Called from functions compiled for
/// several processors (kernel.hpp), into which it is inlined.
template <std::size_t Q1, std::size_t Stride>
[[gnu::always_inline]] inline void sample_points(const int* spans, const double* weights, int q, std::size_t n,
                                                 const double* row, double* out) {
  const std::size_t q1 = Q1 != 0 ? Q1 : static_cast<std::size_t>(q + 1);
  std::size_t j = 0;
#if defined(__GNUC__)
  using v4 = double __attribute__((vector_size(32)));
  for (; j + 1 < n; ++j) {
    const double* h = row + Stride * static_cast<std::size_t>(spans[j] - q);
    const double* f = weights + j * q1;
    v4 acc = {0, 0, 0, 0};
    for (std::size_t k = 0; k < q1; ++k) {
      v4 p;
      std::memcpy(&p, h + Stride * k, sizeof p);
      acc += f[k] * p;
    }
    std::memcpy(out + 3 * j, &acc, sizeof acc);
  }
#endif
  for (; j < n; ++j) {
    const double* h = row + Stride * static_cast<std::size_t>(spans[j] - q);
    const double* f = weights + j * q1;
    double x = 0, y = 0, z = 0;
    for (std::size_t k = 0; k < q1; ++k) {
      x += f[k] * h[Stride * k];
      y += f[k] * h[Stride * k + 1];
      z += f[k] * h[Stride * k + 2];
    }
    out[3 * j] = x;
    out[3 * j + 1] = y;
    out[3 * j + 2] = z;
  }
}

/// sample_points with the loop over k unrolled for degrees 1 to 3 (the same sums in
/// the same order: the same bits).
template <std::size_t Stride>
[[gnu::always_inline]] inline void sample_by_degree(const int* spans, const double* weights, int q, std::size_t n,
                                                    const double* row, double* out) {
  switch (q) {
    case 3: return sample_points<4, Stride>(spans, weights, q, n, row, out);
    case 2: return sample_points<3, Stride>(spans, weights, q, n, row, out);
    case 1: return sample_points<2, Stride>(spans, weights, q, n, row, out);
    default: return sample_points<0, Stride>(spans, weights, q, n, row, out);
  }
}

}  // namespace interpatch::detail
