#pragma once
// Passes of a direction's basis matrix over a tensor of points or control points
// (Bᵀ from data to control points, B back), in parallel blocks that compute every
// number by the same operations whatever the thread count.

#include <algorithm>
#include <cstddef>
#include <vector>

#include "base/parallel.hpp"
#include "constructions/approximate/approx_axes.hpp"

namespace interpatch::detail::approx {

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

}  // namespace interpatch::detail::approx
