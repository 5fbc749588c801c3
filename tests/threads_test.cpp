// bind_threads() (threads.hpp) pins threads for the rest of the process, so every
// check runs in a child process of its own: a death test in the threadsafe style,
// which starts the test binary afresh for the child, with no OpenMP threads yet and
// nothing bound. The child reports what went wrong on stderr and exits with 1;
// the parent expects exit code 0.

#include "interpatch/threads.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(_OPENMP) && defined(__linux__)
#include <sched.h>
#endif

#include "interpatch/interpolate.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

// Ends the child: 0 when every check held, 1 after naming the first that did not.
[[noreturn]] void exit_child(const std::string& failure) {
  if (!failure.empty()) std::fprintf(stderr, "%s\n", failure.c_str());
  std::fflush(stderr);
  std::_Exit(failure.empty() ? 0 : 1);
}

#if defined(_OPENMP) && defined(__linux__)

// Whether the environment binds threads already (threads.hpp).
bool user_binds_threads() {
  for (const char* v : {"OMP_PROC_BIND", "OMP_PLACES", "GOMP_CPU_AFFINITY"})
    if (std::getenv(v) != nullptr) return true;
  return false;
}

cpu_set_t own_affinity() {
  cpu_set_t s;
  CPU_ZERO(&s);
  if (sched_getaffinity(0, sizeof s, &s) != 0) CPU_ZERO(&s);
  return s;
}

// The bicubic interpolant of a random 300 x 300 grid, large enough for its solves to
// run on every thread.
PointGrid interpolated_control_points() {
  auto g = test::rng(150);
  return interpolate_surface(test::random_grid(g, 300, 300)).surface.control_points();
}

// In the child: bind_threads() returns true exactly when nothing forbids it; then
// every thread of the next parallel region runs on one CPU of its own among those
// the process may use, and an interpolation gives the bits it gave before.
std::string bind_and_check() {
  const cpu_set_t allowed = own_affinity();
  const int threads = omp_get_max_threads();
  const bool expected = !user_binds_threads() && threads >= 2 && CPU_COUNT(&allowed) >= threads;
  const PointGrid before = interpolated_control_points();
  const bool bound = bind_threads();
  if (bound != expected)
    return "bind_threads() returned " + std::to_string(bound) + " with " + std::to_string(threads) + " threads and " +
           std::to_string(CPU_COUNT(&allowed)) + " CPUs";
  if (bound) {
    std::vector<int> cpus(static_cast<std::size_t>(threads), -1), counts(cpus.size(), 0);
    int team = 0;
#pragma omp parallel
    {
      const cpu_set_t mine = own_affinity();
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      if (t == 0) team = omp_get_num_threads();
      if (t < cpus.size()) {
        counts[t] = CPU_COUNT(&mine);
        for (int c = 0; c < CPU_SETSIZE; ++c)
          if (CPU_ISSET(c, &mine)) cpus[t] = c;
      }
    }
    if (team != threads) return "a team of " + std::to_string(team) + " threads, not " + std::to_string(threads);
    std::set<int> distinct;
    for (std::size_t t = 0; t < cpus.size(); ++t) {
      if (counts[t] != 1) return "thread " + std::to_string(t) + " may run on " + std::to_string(counts[t]) + " CPUs";
      if (!CPU_ISSET(cpus[t], &allowed))
        return "thread " + std::to_string(t) + " is on CPU " + std::to_string(cpus[t]) +
               ", not one the process may use";
      distinct.insert(cpus[t]);
    }
    if (distinct.size() != cpus.size()) return "two threads share a CPU";
  }
  const PointGrid after = interpolated_control_points();
  if (after.size() != before.size() || std::memcmp(after.data(), before.data(), after.size() * sizeof(Vec3)) != 0)
    return "the interpolation differs after binding";
  return {};
}

// In the child: bind_threads() returns false and leaves the calling thread's
// affinity as it was.
std::string refuse_and_check() {
  const cpu_set_t allowed = own_affinity();
  if (bind_threads()) return "bind_threads() returned true";
  const cpu_set_t now = own_affinity();
  if (!CPU_EQUAL(&now, &allowed)) return "the calling thread's affinity changed";
  return {};
}

TEST(BindThreads, EachThreadRunsOnACpuOfItsOwnAndResultsDoNotChange) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(exit_child(bind_and_check()), ::testing::ExitedWithCode(0), "");
}

TEST(BindThreads, DoesNothingWhenTheUserBindsThreads) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  for (const char* variable : {"OMP_PROC_BIND", "OMP_PLACES", "GOMP_CPU_AFFINITY"}) {
    SCOPED_TRACE(variable);
    // Set in the child only, after its OpenMP runtime has read the environment.
    EXPECT_EXIT(
        {
          ::setenv(variable, "false", 1);
          exit_child(refuse_and_check());
        },
        ::testing::ExitedWithCode(0), "");
  }
}

TEST(BindThreads, DoesNothingWithOneThreadOrMoreThreadsThanCpus) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        omp_set_num_threads(1);
        exit_child(refuse_and_check());
      },
      ::testing::ExitedWithCode(0), "");
  EXPECT_EXIT(
      {
        const cpu_set_t allowed = own_affinity();
        omp_set_num_threads(CPU_COUNT(&allowed) + 1);
        exit_child(refuse_and_check());
      },
      ::testing::ExitedWithCode(0), "");
}

#else

TEST(BindThreads, DoesNothingWithoutOpenMP) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(exit_child(bind_threads() ? "bind_threads() returned true" : ""), ::testing::ExitedWithCode(0), "");
}

#endif

}  // namespace
}  // namespace interpatch
