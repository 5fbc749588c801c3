#pragma once
// Test helpers: a call with a given number of OpenMP threads; exact forms computed with
// 1, 2 and 3 threads, compared bit for bit (tests/determinism_test.cpp does the same for
// the other threaded loops).

#include <gtest/gtest.h>

#include <cstring>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "interpatch/vec3.hpp"

namespace interpatch::test {

/// f() run with `threads` OpenMP threads (dynamic adjustment off), the setting restored.
template <class F>
auto with_threads([[maybe_unused]] int threads, F&& f) {
#ifdef _OPENMP
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
  omp_set_num_threads(threads);
#endif
  auto r = f();
#ifdef _OPENMP
  omp_set_num_threads(before);
#endif
  return r;
}

#ifdef _OPENMP
/// Expects to_bspline() of each construction to give a control net with the same
/// bits with 2 and 3 threads as with 1. `list` holds pairs whose first element is
/// the construction.
template <class List>
void expect_exact_forms_independent_of_threads(const List& list) {
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
  for (const auto& item : list) {
    omp_set_num_threads(1);
    const auto one = item.first.to_bspline().control_points();
    for (const int threads : {2, 3}) {
      omp_set_num_threads(threads);
      const auto many = item.first.to_bspline().control_points();
      ASSERT_EQ(many.shape(), one.shape());
      EXPECT_EQ(std::memcmp(many.data(), one.data(), one.size() * sizeof(Vec3)), 0) << threads << " threads";
    }
  }
  omp_set_num_threads(before);
}
#endif

}  // namespace interpatch::test
