#include "linalg/banded.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "test_util.hpp"

namespace interpatch::detail {
namespace {

// A random n × n band matrix with kl sub- and ku super-diagonals, a fifth of its
// off-diagonal entries zero (the solves skip those). With `dominant`, each
// diagonal entry outweighs the rest of its row and column (no row is swapped);
// without, the diagonal is small, so that factor() swaps.
BandedLU random_band(std::mt19937_64& g, int n, int kl, int ku, bool dominant, std::vector<double>& dense) {
  std::uniform_real_distribution<double> entry(-1.0, 1.0), chance(0.0, 1.0);
  BandedLU lu(n, kl, ku);
  dense.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - kl); j <= std::min(n - 1, i + ku); ++j) {
      double v = entry(g);
      if (i == j) v = dominant ? 2.0 * (kl + ku + 1) + v : 0.01 * v;
      else if (chance(g) < 0.2) v = 0.0;
      lu.at(i, j) = v;
      dense[static_cast<std::size_t>(i) * static_cast<std::size_t>(n) + static_cast<std::size_t>(j)] = v;
    }
  return lu;
}

// Largest |A x − b| over the right-hand sides, x solved in `x`.
double residual(const std::vector<double>& dense, int n, const std::vector<double>& b, const std::vector<double>& x,
                std::size_t width, std::size_t stride) {
  double worst = 0;
  for (int i = 0; i < n; ++i)
    for (std::size_t c = 0; c < width; ++c) {
      double s = 0;
      for (int j = 0; j < n; ++j)
        s += dense[static_cast<std::size_t>(i) * static_cast<std::size_t>(n) + static_cast<std::size_t>(j)] *
             x[static_cast<std::size_t>(j) * stride + c];
      worst = std::max(worst, std::abs(s - b[static_cast<std::size_t>(i) * stride + c]));
    }
  return worst;
}

// The sweeps by rows make the bits of the sweeps by columns, whatever the band,
// the number of right-hand sides and their stride; zero entries are skipped alike
// (a right-hand side holding an infinity stays the same on both paths), and the
// solution solves the system.
TEST(BandedLU, SolveByRowsGivesTheBitsOfSolveByColumns) {
  auto g = test::rng(5);
  std::uniform_real_distribution<double> value(-10.0, 10.0);
  for (const int n : {1, 2, 7, 40})
    for (const int kl : {0, 1, 2, 5})
      for (const int ku : {0, 1, 3, 6})
        for (const std::size_t width : {std::size_t{1}, std::size_t{3}, std::size_t{5}, std::size_t{24}, std::size_t{37}}) {
          SCOPED_TRACE(testing::Message() << "n " << n << " kl " << kl << " ku " << ku << " width " << width);
          std::vector<double> dense;
          BandedLU lu = random_band(g, n, kl, ku, true, dense);
          ASSERT_TRUE(lu.factor());
          ASSERT_FALSE(lu.swapped());
          const std::size_t stride = width + 3;  // rows apart by more than their width
          std::vector<double> b(static_cast<std::size_t>(n) * stride);
          for (double& v : b) v = value(g);
          std::vector<double> by_rows = b, by_columns = b;
          lu.solve_by_rows(by_rows.data(), width, stride);
          lu.solve_by_columns(by_columns.data(), width, stride);
          ASSERT_EQ(std::memcmp(by_rows.data(), by_columns.data(), b.size() * sizeof(double)), 0);
          // 1e-12: the matrix is diagonally dominant (condition number below 10) and
          // the entries of b below 10 in size.
          EXPECT_LT(residual(dense, n, b, by_rows, width, stride), 1e-12);
          std::vector<double> solved = b;
          lu.solve(solved.data(), width, stride);
          EXPECT_EQ(std::memcmp(solved.data(), by_rows.data(), b.size() * sizeof(double)), 0);
          if (n > 2) {  // an infinity in the first right-hand side, beside zero entries
            std::vector<double> inf_rows = b;
            inf_rows[stride] = std::numeric_limits<double>::infinity();
            std::vector<double> inf_columns = inf_rows;
            lu.solve_by_rows(inf_rows.data(), width, stride);
            lu.solve_by_columns(inf_columns.data(), width, stride);
            EXPECT_EQ(std::memcmp(inf_rows.data(), inf_columns.data(), b.size() * sizeof(double)), 0);
          }
        }
}

// A matrix whose factorization swaps rows is solved by columns, and correctly.
TEST(BandedLU, SolveWithSwappedRowsSolvesTheSystem) {
  auto g = test::rng(6);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  int swapped = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> dense;
    const int n = 30;
    BandedLU lu = random_band(g, n, 2, 2, false, dense);
    if (!lu.factor()) continue;
    swapped += lu.swapped() ? 1 : 0;
    const std::size_t width = 4;
    std::vector<double> b(static_cast<std::size_t>(n) * width);
    for (double& v : b) v = value(g);
    std::vector<double> x = b;
    lu.solve(x.data(), width, width);
    double scale = 0;
    for (double v : x) scale = std::max(scale, std::abs(v));
    // 1e-9 relative to the solution: pivoted elimination of a 30 × 30 band whose
    // growth stays far below 1e6.
    EXPECT_LT(residual(dense, n, b, x, width, width), 1e-9 * std::max(1.0, scale));
  }
  EXPECT_GT(swapped, 10);
}

}  // namespace
}  // namespace interpatch::detail
