// Progress callbacks that stop the work (progress.hpp): what a callback throws comes
// out of every evaluation unchanged, even from inside a parallel region, and the
// callback is not called again once it has thrown.

#include "interpatch/progress.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/spec.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

struct stop_asked {};

// Evaluates `s` on a grid large enough for both threads and many reports, with a
// callback that throws on its second report.
void expect_stopped(const Surface& s, const std::string& what) {
  const std::vector<double> ts = linspace(0, 1, 1200);
  int calls = 0, after = 0;
  bool thrown = false;
  const progress_callback stop = [&](double) {
    ++calls;
    if (thrown) ++after;
    if (calls == 2) {
      thrown = true;
      throw stop_asked{};
    }
  };
  EXPECT_THROW((void)s.evaluate(ts, ts, stop), stop_asked) << what;
  EXPECT_TRUE(thrown) << what << ": reports during the work";
  EXPECT_EQ(after, 0) << what << ": no report after the callback threw";
  EXPECT_NO_THROW((void)s.evaluate(ts, ts, [](double) {})) << what << ": the surface still evaluates";
}

TEST(Progress, AThrowingCallbackStopsEveryEvaluation) {
  io::BuildOptions lazy;
  lazy.defer_exact = true;
  io::Construction coons = io::build_file(std::filesystem::path(INTERPATCH_EXAMPLES) / "coons.json", lazy);
  expect_stopped(io::evaluator(coons), "a Coons patch by its formula");
  expect_stopped(std::get<BSplineSurface>(io::exact_form(coons)), "its exact form");
  // A rational surface: its own parallel region.
  PointGrid net({3, 3});
  Grid<double, 2> w({3, 3});
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j) {
      net(i, j) = {static_cast<double>(i), static_cast<double>(j), static_cast<double>(i * j)};
      w(i, j) = 1.0 + static_cast<double>((i + j) % 2);
    }
  const KnotVector k(2, {0, 0, 0, 1, 1, 1});
  expect_stopped(BSplineSurface(k, k, net, w), "a rational B-spline surface");
}

}  // namespace
}  // namespace interpatch
