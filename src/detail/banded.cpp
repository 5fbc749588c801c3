#include "detail/banded.hpp"

#include "detail/kernel.hpp"
#include "detail/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace interpatch::detail {

BandedLU::BandedLU(int n, int kl, int ku)
    : n_(n), kl_(kl), ku_(ku), w_(2 * kl + ku + 1),
      a_(static_cast<std::size_t>(n) * static_cast<std::size_t>(2 * kl + ku + 1), 0.0),
      piv_(static_cast<std::size_t>(n), 0) {}

bool BandedLU::factor() {
  double scale = 0;
  for (double v : a_) scale = std::max(scale, std::abs(v));
  const double tiny = 1e-14 * scale;
  const int kuu = kl_ + ku_;  // upper bandwidth of U after row swaps
  for (int k = 0; k < n_; ++k) {
    const int last = std::min(n_ - 1, k + kl_);
    int p = k;
    double best = std::abs(at(k, k));
    for (int i = k + 1; i <= last; ++i)
      if (std::abs(at(i, k)) > best) { best = std::abs(at(i, k)); p = i; }
    piv_[static_cast<std::size_t>(k)] = p;
    if (!(best > tiny)) { failed_row_ = k; return false; }
    const int jlast = std::min(n_ - 1, k + kuu);
    if (p != k)
      for (int j = k; j <= jlast; ++j) std::swap(at(k, j), at(p, j));
    const double inv = 1.0 / at(k, k);
    for (int i = k + 1; i <= last; ++i) {
      const double l = at(i, k) * inv;
      at(i, k) = l;
      if (l != 0.0)
        for (int j = k + 1; j <= jlast; ++j) at(i, j) -= l * at(k, j);
    }
  }
  return true;
}

INTERPATCH_KERNEL void BandedLU::solve(double* b, std::size_t width, std::size_t stride) const noexcept {
  const int kuu = kl_ + ku_;
  auto row = [&](int i) { return b + static_cast<std::size_t>(i) * stride; };
  for (int k = 0; k < n_; ++k) {
    const int p = piv_[static_cast<std::size_t>(k)];
    double* bk = row(k);
    if (p != k) std::swap_ranges(bk, bk + width, row(p));
    const int last = std::min(n_ - 1, k + kl_);
    for (int i = k + 1; i <= last; ++i) {
      const double l = at(i, k);
      if (l == 0.0) continue;
      double* bi = row(i);
      for (std::size_t c = 0; c < width; ++c) bi[c] -= l * bk[c];
    }
  }
  for (int k = n_ - 1; k >= 0; --k) {
    double* bk = row(k);
    const int jlast = std::min(n_ - 1, k + kuu);
    for (int j = k + 1; j <= jlast; ++j) {
      const double u = at(k, j);
      if (u == 0.0) continue;
      const double* bj = row(j);
      for (std::size_t c = 0; c < width; ++c) bk[c] -= u * bj[c];
    }
    const double inv = 1.0 / at(k, k);
    for (std::size_t c = 0; c < width; ++c) bk[c] *= inv;
  }
}

namespace {

// Columns of wide lines solved together, a slice of them at a time. The forward and
// the back sweep each stream through the slice's n rows (the rows of the band stay
// in cache between uses). When a slice 512 doubles wide (4 KiB of each row) still
// fits in a quarter of a 32 MiB L3 cache with its n rows, the slices are that narrow
// and the back sweep finds them in cache: one pass over memory instead of two
// (2048² surface grids: the u-solve 9.5 → 8.6 ms on 2 threads). Longer lines get
// slices a quarter of the row wide, where long streams beat narrow slices that no
// longer fit (4096²: 40 ms against 44). Narrow slices come in a multiple of the
// thread count, so that each thread gets as many.
std::size_t slice_width(std::size_t inner, std::size_t n) {
  constexpr std::size_t min_width = 512, cache_bytes = std::size_t{8} << 20;
  std::size_t w = std::max(min_width, (inner + 3) / 4);
  if (n * min_width * sizeof(double) <= cache_bytes) {
#ifdef _OPENMP
    const auto threads = static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
#else
    const std::size_t threads = 1;
#endif
    std::size_t slices = (inner + min_width - 1) / min_width;
    if (slices > 1) slices = (slices + threads - 1) / threads * threads;
    w = (inner + slices - 1) / slices;
  }
  return w + (8 - w % 8) % 8;
}

// Eight narrow lines (the last axis: 3 doubles a row) side by side in `buf` give each
// row operation 24 independent columns instead of one dependent chain of scalar
// operations; every number still goes through the same operations.
constexpr std::size_t narrow_group = 8;

// Copies the m lines (rows of `inner` doubles, `block` apart) side by side into buf
// (Gather) or back out of it: plain loops, which the compiler unrolls for the usual
// 3 doubles a row.
template <bool Gather>
INTERPATCH_KERNEL void shuffle_lines(double* data, std::size_t n, std::size_t inner, std::size_t block, std::size_t m,
                                     double* buf) {
  const std::size_t width = m * inner;
  for (std::size_t l = 0; l < m; ++l) {
    double* line = data + l * block;
    double* side = buf + l * inner;
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t c = 0; c < inner; ++c) {
        if constexpr (Gather) side[k * width + c] = line[k * inner + c];
        else line[k * inner + c] = side[k * width + c];
      }
  }
}

void solve_narrow_group(const BandedLU& lu, double* data, std::size_t n, std::size_t inner, std::size_t block,
                        std::size_t m, double* buf) {
  shuffle_lines<true>(data, n, inner, block, m, buf);
  lu.solve(buf, m * inner, m * inner);
  shuffle_lines<false>(data, n, inner, block, m, buf);
}

}  // namespace

void solve_along_axis(const BandedLU& lu, double* data, const std::size_t* shape, std::size_t rank,
                      std::size_t axis, std::size_t components, bool parallel) {
  std::size_t outer = 1, inner = components;
  for (std::size_t a = 0; a < axis; ++a) outer *= shape[a];
  for (std::size_t a = axis + 1; a < rank; ++a) inner *= shape[a];
  const std::size_t n = shape[axis];
  const std::size_t block = n * inner;
  [[maybe_unused]] const bool threads = parallel && block * outer >= parallel_min_work;
  if (inner < 64 && outer > 1) {
    const auto groups = static_cast<long long>((outer + narrow_group - 1) / narrow_group);
#pragma omp parallel if (threads)
    {
      std::vector<double> buf(n * narrow_group * inner);
#pragma omp for schedule(static)
      for (long long g = 0; g < groups; ++g) {
        const std::size_t o0 = static_cast<std::size_t>(g) * narrow_group;
        solve_narrow_group(lu, data + o0 * block, n, inner, block, std::min(narrow_group, outer - o0), buf.data());
      }
    }
    return;
  }
  const std::size_t slice = slice_width(inner, n);
  const std::size_t slices = (inner + slice - 1) / slice;
  const auto tasks = static_cast<long long>(outer * slices);
#pragma omp parallel for schedule(static) if (tasks > 1 && threads)
  for (long long t = 0; t < tasks; ++t) {
    const std::size_t o = static_cast<std::size_t>(t) / slices;
    const std::size_t s = static_cast<std::size_t>(t) % slices;
    const std::size_t c0 = s * slice;
    const std::size_t width = std::min(slice, inner - c0);
    lu.solve(data + o * block + c0, width, inner);
  }
}

}  // namespace interpatch::detail
