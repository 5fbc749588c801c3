#pragma once
// When work is split across threads. Starting OpenMP's second thread costs a few
// milliseconds on the machines interpatch is measured on (2.5–25 ms seen), so
// loops smaller than this many multiply-adds stay on the calling thread. Threads
// never change a result: every number is computed by the same operations.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>

#include "interpatch/progress.hpp"
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

/// The most threads a parallel region opened here can have (1 without OpenMP):
/// what memory kept per thread, taken before the region, is sized by.
inline std::size_t max_threads() noexcept {
#ifdef _OPENMP
  return static_cast<std::size_t>(omp_get_max_threads());
#else
  return 1;
#endif
}

/// What went wrong on the threads of a parallel loop, carried out of it: an exception
/// that leaves an OpenMP region calls std::terminate (an abort, on one thread too).
/// Each iteration runs through `attempt`, which catches; the exception of the lowest
/// index is kept, so the error reported is the same on any number of threads.
class ParallelFailure {
 public:
  /// Runs f() for index i unless an index below i already failed; catches what f throws.
  template <class F>
  void attempt(std::size_t i, F&& f) noexcept {
    if (i > first_.load(std::memory_order_relaxed)) return;
    try {
      f();
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (i < first_.load(std::memory_order_relaxed)) {
        error_ = std::current_exception();
        first_.store(i, std::memory_order_relaxed);
      }
    }
  }
  /// Whether some iteration has failed (the others may stop early).
  bool failed() const noexcept { return first_.load(std::memory_order_relaxed) != none; }
  /// Rethrows the kept exception, outside the region.
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  static constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
  std::atomic<std::size_t> first_{none};
  std::mutex mutex_;
  std::exception_ptr error_;
};

/// Progress reported from inside a parallel region by the calling thread (thread 0).
/// A callback may throw to stop the work (progress.hpp), but no exception may leave
/// a parallel region: the first is kept, every thread's remaining iterations see
/// stopped() and skip their work, and rethrow() after the region throws it.
class RegionProgress {
 public:
  explicit RegionProgress(const progress_callback& progress) noexcept : progress_(progress) {}
  void report(double fraction) noexcept {
    if (!progress_ || stopped()) return;
    try {
      progress_(fraction);
    } catch (...) {
      error_ = std::current_exception();  // thread 0 alone reports
      stop_.store(true, std::memory_order_relaxed);
    }
  }
  [[nodiscard]] bool stopped() const noexcept { return stop_.load(std::memory_order_relaxed); }
  /// After the region: what a callback threw, if it did.
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  const progress_callback& progress_;
  std::exception_ptr error_;
  std::atomic<bool> stop_{false};
};

/// How the iterations of parallel_for are shared: `blocks`, one contiguous block a
/// thread (even work); `one_by_one`, each iteration to the next free thread (uneven work).
enum class Share { blocks, one_by_one };

/// body(i) for i in [0, n), on every thread when `parallel`. An exception thrown by
/// body is caught on its thread and the one of the lowest index rethrown after the
/// loop; iterations above a failed one are skipped. Every parallel loop of interpatch
/// whose body can throw goes through this.
template <class F>
void parallel_for(std::size_t n, bool parallel, Share share, F&& body) {
  ParallelFailure failure;
  const auto count = static_cast<long long>(n);
  if (share == Share::one_by_one) {
#pragma omp parallel for schedule(dynamic, 1) if (parallel && n > 1)
    for (long long k = 0; k < count; ++k) failure.attempt(static_cast<std::size_t>(k), [&] { body(static_cast<std::size_t>(k)); });
  } else {
#pragma omp parallel for schedule(static) if (parallel && n > 1)
    for (long long k = 0; k < count; ++k) failure.attempt(static_cast<std::size_t>(k), [&] { body(static_cast<std::size_t>(k)); });
  }
  failure.rethrow();
}

/// body(thread, threads) once on each thread of a parallel region (once, as thread 0
/// of 1, when not `parallel`), for regions that share their work themselves: the
/// body must contain no barrier or worksharing construct that a failed thread would
/// leave the others waiting at. Exceptions as in parallel_for, by thread.
template <class F>
void parallel_threads(bool parallel, F&& body) {
  ParallelFailure failure;
#pragma omp parallel if (parallel)
  failure.attempt(static_cast<std::size_t>(thread_index()), [&] { body(static_cast<std::size_t>(thread_index()), thread_count()); });
  failure.rethrow();
}

/// Whether any of n doubles is a NaN or an infinity, scanned without a branch (x * 0
/// is 0 for a finite x, NaN otherwise; the comparisons vectorize).
inline bool has_non_finite(const double* d, std::size_t n) noexcept {
  std::size_t t = 0;
  bool bad = false;
#if defined(__GNUC__)
  // Two doubles a vector: the comparison the baseline processor (SSE2) has.
  using v2 = double __attribute__((vector_size(16)));
  using m2 = long long __attribute__((vector_size(16)));
  m2 any = {0, 0};
  for (; t + 2 <= n; t += 2) {
    v2 x;
    std::memcpy(&x, d + t, sizeof x);
    any |= (x * 0.0) != 0.0;
  }
  bad = (any[0] | any[1]) != 0;
#endif
  for (; t < n; ++t) bad |= d[t] * 0.0 != 0.0;
  return bad;
}

/// Index of the first point with a NaN or infinite coordinate, `count` if none:
/// the threads scan a large array, and the first in storage order is the one found
/// whatever the thread count.
inline std::size_t first_non_finite(const Vec3* p, std::size_t count) noexcept {
  // Pieces of 1024 points, each scanned by has_non_finite, and only a piece that has
  // one is searched point by point.
  constexpr std::size_t piece = 1024;
  const auto pieces = static_cast<long long>((count + piece - 1) / piece);
  long long first = static_cast<long long>(count);
#pragma omp parallel for schedule(static) reduction(min : first) if (count >= parallel_min_work)
  for (long long k = 0; k < pieces; ++k) {
    const std::size_t i0 = static_cast<std::size_t>(k) * piece, n = std::min(piece, count - i0);
    if (!has_non_finite(&p[i0].x, 3 * n)) continue;
    for (std::size_t i = i0; i < i0 + n; ++i)
      if (!is_finite(p[i])) {
        if (static_cast<long long>(i) < first) first = static_cast<long long>(i);
        break;
      }
  }
  return static_cast<std::size_t>(first);
}

}  // namespace interpatch::detail
