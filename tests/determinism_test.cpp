// Results do not depend on the number of threads: the same input
// gives bit-identical output with 1, 2 and 3 OpenMP threads, for the library's
// threaded loops and for the files the command writes. Every size below is chosen
// above the library's threshold for starting threads (detail::parallel_min_work),
// and the test checks that it is, so that a reduction whose order followed the
// split between threads would show here as differing bits.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "cli_runner.hpp"
#include "base/parallel.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/io/npy.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

namespace fs = std::filesystem;

// A wavy n x n grid: every row and column curved, no two neighbours coincident.
PointGrid wavy_grid(std::size_t n) {
  PointGrid q({n, n});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double x = static_cast<double>(i) / static_cast<double>(n - 1);
      const double y = static_cast<double>(j) / static_cast<double>(n - 1);
      q(i, j) = {x + 0.01 * std::sin(7 * y), y + 0.01 * std::cos(5 * x), std::sin(3 * x) * std::cos(4 * y)};
    }
  return q;
}

template <class T>
bool same_bits(const T* a, const T* b, std::size_t n) {
  return std::memcmp(a, b, n * sizeof(T)) == 0;
}

#ifdef _OPENMP

// Runs f with `threads` OpenMP threads, restoring the previous setting.
template <class F>
auto with_threads(int threads, F&& f) {
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
  omp_set_num_threads(threads);
  auto r = f();
  omp_set_num_threads(before);
  return r;
}

TEST(Determinism, InterpolateSurfaceAndEvaluateAreBitIdenticalForAnyThreadCount) {
  constexpr std::size_t n = 300;
  // The banded solves split n x n x 3 numbers between threads above this.
  static_assert(n * n * 3 >= detail::parallel_min_work);
  const PointGrid q = wavy_grid(n);
  const std::vector<double> t = linspace(0, 1, 701);
  // Batch evaluation splits rows between threads above this.
  ASSERT_GE(t.size() * (t.size() + n), detail::parallel_min_work);

  const auto reference = with_threads(1, [&] { return interpolate_surface(q); });
  const PointGrid reference_points = with_threads(1, [&] { return reference.surface.evaluate(t, t); });
  const PointGrid& cp = reference.surface.control_points();
  for (const int threads : {2, 3}) {
    SCOPED_TRACE(threads);
    const auto r = with_threads(threads, [&] { return interpolate_surface(q); });
    ASSERT_EQ(r.surface.control_points().size(), cp.size());
    EXPECT_TRUE(same_bits(r.surface.control_points().data(), cp.data(), cp.size()));
    EXPECT_TRUE(same_bits(r.params_u.data(), reference.params_u.data(), n));
    EXPECT_TRUE(same_bits(r.params_v.data(), reference.params_v.data(), n));
    EXPECT_EQ(r.surface.knots_u().values(), reference.surface.knots_u().values());

    const PointGrid p = with_threads(threads, [&] { return reference.surface.evaluate(t, t); });
    ASSERT_EQ(p.size(), reference_points.size());
    EXPECT_TRUE(same_bits(p.data(), reference_points.data(), p.size()));
  }
}

#endif

#ifdef INTERPATCH_CLI

// The files `interpatch` writes for the same command under OMP_NUM_THREADS = 1, 2, 3.
class CliDeterminism : public ::testing::Test {
 protected:
  void SetUp() override {
    // The 300 x 300 grid as a data file: building it is the two threaded banded solves.
    const PointGrid q = wavy_grid(300);
    std::vector<double> flat;
    for (std::size_t k = 0; k < q.size(); ++k)
      for (int c = 0; c < 3; ++c) flat.push_back(q.data()[k][c]);
    const std::size_t shape[3] = {300, 300, 3};
    io::write_npy(dir_ / "grid.npy", shape, flat);
    std::ofstream(dir_ / "grid.json") << R"({"type": "interpolate", "points": {"npy": "grid.npy"}})";
  }

  void expect_identical_outputs(std::vector<std::string> args, const std::string& out) {
    std::string reference;
    for (const int threads : {1, 2, 3}) {
      SCOPED_TRACE("OMP_NUM_THREADS=" + std::to_string(threads));
      const std::string name = std::to_string(threads) + "-" + out;
      std::vector<std::string> a = args;
      a.insert(a.end(), {"-o", name});
      const test::CliResult r =
          test::run_cli(dir_.path(), a, {"OMP_NUM_THREADS=" + std::to_string(threads), "OMP_DYNAMIC=false"});
      ASSERT_EQ(r.status, 0) << r.err;
      const std::string bytes = test::read_text(dir_ / name);
      ASSERT_FALSE(bytes.empty());
      if (threads == 1) reference = bytes;
      else EXPECT_TRUE(bytes == reference) << name << " differs from the single-threaded output";
    }
  }

  test::TempDir dir_;
};

TEST_F(CliDeterminism, BuildOfA300x300GridWritesTheSameJson) {
  static_assert(300 * 300 * 3 >= detail::parallel_min_work);  // the solves go multi-threaded
  expect_identical_outputs({"build", "grid.json"}, "exact.json");
}

TEST_F(CliDeterminism, EvalWritesTheSameNpy) {
  // 600 rows of 600 points against 300 control points: above the evaluation threshold.
  static_assert(600 * (600 + 300) >= detail::parallel_min_work);
  expect_identical_outputs({"eval", "grid.json", "--grid", "600"}, "eval.npy");
}

TEST_F(CliDeterminism, VolumeMeshWritesTheSameVts) {
  // Volume formulas split their points between threads above parallel_min_work / 16.
  static_assert(40 * 40 * 40 >= detail::parallel_min_work / 16);
  const fs::path spec = fs::path(INTERPATCH_EXAMPLES) / "coons_volume.json";
  expect_identical_outputs({"mesh", spec.string(), "--res", "40x40x40"}, "block.vts");
}

TEST_F(CliDeterminism, InterpolatedVolumeMeshWritesTheSameVts) {
  const fs::path spec = fs::path(INTERPATCH_EXAMPLES) / "annular_sector.json";
  expect_identical_outputs({"mesh", spec.string(), "--res", "70x70x70"}, "sector.vts");
}

#endif

}  // namespace
}  // namespace interpatch
