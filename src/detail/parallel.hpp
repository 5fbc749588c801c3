#pragma once
// When work is split across threads. Starting OpenMP's second thread costs a few
// milliseconds on the machines interpatch is measured on (2.5–25 ms seen), so
// loops smaller than this many multiply-adds stay on the calling thread. Threads
// never change a result: every number is computed by the same operations.

#include <cstddef>

#include "interpatch/vec3.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace interpatch::detail {

inline constexpr std::size_t parallel_min_work = std::size_t{1} << 18;

/// The calling thread is 0, inside or outside a parallel region.
inline int thread_index() noexcept {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

/// Threads of the innermost parallel region (1 outside one).
inline std::size_t thread_count() noexcept {
#ifdef _OPENMP
  return static_cast<std::size_t>(omp_get_num_threads());
#else
  return 1;
#endif
}

/// Index of the first point with a NaN or infinite coordinate, `count` if none:
/// both threads scan a large array, and the first in storage order is the one found
/// whatever the thread count.
inline std::size_t first_non_finite(const Vec3* p, std::size_t count) noexcept {
  const auto n = static_cast<long long>(count);
  long long first = n;
#pragma omp parallel for schedule(static) reduction(min : first) if (count >= parallel_min_work)
  for (long long i = 0; i < n; ++i)
    if (!is_finite(p[i]) && i < first) first = i;
  return static_cast<std::size_t>(first);
}

}  // namespace interpatch::detail
