// The parallel loops' one way out for an exception (src/base/parallel.hpp): thrown on
// any thread, at any index, it comes out of the loop as the exception of the lowest
// failing index, on any number of threads; every index below it has run; nothing
// reaches std::terminate.

#include "base/parallel.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "base/text.hpp"
#include "interpatch/error.hpp"

namespace interpatch {
namespace {

// The thread counts each check runs on (1 alone without OpenMP).
std::vector<int> thread_counts() {
#ifdef _OPENMP
  return {1, 2, 3};
#else
  return {1};
#endif
}

void set_threads([[maybe_unused]] int n) {
#ifdef _OPENMP
  omp_set_dynamic(0);
  omp_set_num_threads(n);
#endif
}

TEST(Parallel, TheLowestFailingIndexIsRethrownAfterTheLoop) {
  const std::size_t n = 1000;
  for (const auto share : {detail::Share::blocks, detail::Share::one_by_one})
    for (const int threads : thread_counts()) {
      set_threads(threads);
      // Failures at 700, 300 and 999: whichever thread meets one first, 300 is the error.
      std::vector<std::atomic<int>> ran(n);
      try {
        detail::parallel_for(n, true, share, [&](std::size_t i) {
          ran[i] = 1;
          if (i == 700 || i == 300 || i == 999) detail::fail(errc::out_of_domain, "index ", i);
        });
        ADD_FAILURE() << "no exception, " << threads << " threads";
      } catch (const error& e) {
        EXPECT_EQ(e.code(), errc::out_of_domain);
        EXPECT_EQ(std::string(e.what()), "index 300") << threads << " threads";
      }
      for (std::size_t i = 0; i <= 300; ++i) EXPECT_EQ(ran[i].load(), 1) << "index " << i << ", " << threads << " threads";
    }
  set_threads(1);
}

TEST(Parallel, ExceptionsOfAnyTypeLeaveTheLoop) {
  for (const int threads : thread_counts()) {
    set_threads(threads);
    EXPECT_THROW(detail::parallel_for(64, true, detail::Share::one_by_one,
                                      [](std::size_t i) {
                                        if (i % 7 == 3) throw std::bad_alloc();
                                      }),
                 std::bad_alloc);
    EXPECT_THROW(detail::parallel_threads(true,
                                          [](std::size_t t, std::size_t) {
                                            if (t == 0) throw std::runtime_error("thread 0");
                                          }),
                 std::runtime_error);
  }
  set_threads(1);
}

TEST(Parallel, EveryIndexRunsOnceWhenNothingFails) {
  for (const auto share : {detail::Share::blocks, detail::Share::one_by_one})
    for (const int threads : thread_counts()) {
      set_threads(threads);
      std::vector<std::atomic<int>> ran(5000);
      detail::parallel_for(ran.size(), true, share, [&](std::size_t i) { ran[i] += 1; });
      for (std::size_t i = 0; i < ran.size(); ++i) ASSERT_EQ(ran[i].load(), 1) << i;
      std::atomic<std::size_t> seen{0};
      detail::parallel_threads(true, [&](std::size_t t, std::size_t count) {
        EXPECT_LT(t, count);
        seen += 1;
      });
#ifdef _OPENMP
      EXPECT_EQ(seen.load(), static_cast<std::size_t>(threads));
#endif
    }
  set_threads(1);
}

}  // namespace
}  // namespace interpatch
