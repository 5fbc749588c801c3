#include "interpatch/threads.hpp"

#include <atomic>
#include <cstdlib>
#include <vector>

#if defined(_OPENMP) && defined(__linux__)
#include <omp.h>
#include <pthread.h>
#include <sched.h>
#endif

namespace interpatch {

bool bind_threads() noexcept {
#if defined(_OPENMP) && defined(__linux__)
  for (const char* v : {"OMP_PROC_BIND", "OMP_PLACES", "GOMP_CPU_AFFINITY"})
    if (std::getenv(v) != nullptr) return false;
  if (omp_in_parallel()) return false;
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return false;
  const int threads = omp_get_max_threads();
  if (threads < 2 || CPU_COUNT(&allowed) < threads) return false;
  // This thread's CPU first, then the others in order.
  std::vector<int> cpus;
  try {
    const int here = sched_getcpu();
    if (here >= 0 && CPU_ISSET(here, &allowed)) cpus.push_back(here);
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &allowed) && c != here) cpus.push_back(c);
  } catch (...) {
    return false;
  }
  std::atomic<int> bound{0};
  std::atomic<bool> ok{true};
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), n = omp_get_num_threads();
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpus[static_cast<std::size_t>(t)], &one);
    if (pthread_setaffinity_np(pthread_self(), sizeof one, &one) != 0) ok = false;
    if (t == 0) {
      // Wait off the CPU (a futex, not a spin) until the others have moved to
      // theirs: they start on this one.
      for (int seen = bound.load(); seen < n - 1; seen = bound.load()) bound.wait(seen);
    } else {
      bound.fetch_add(1);
      bound.notify_one();
    }
  }
  return ok.load();
#else
  return false;
#endif
}

}  // namespace interpatch
