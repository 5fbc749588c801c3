#pragma once
// Banded LU with partial pivoting, factored once and applied to any number of
// right-hand sides laid out as rows of doubles. Collocation matrices of B-spline
// interpolation are banded and totally positive (de Boor), so pivoting rarely
// swaps; it is kept for the rows of end-derivative conditions.

#include <cstddef>
#include <vector>

namespace interpatch::detail {

class BandedLU {
 public:
  /// An n × n zero matrix with kl sub- and ku super-diagonals.
  BandedLU(int n, int kl, int ku);

  [[nodiscard]] int size() const noexcept { return n_; }
  /// Entry (i, j), |i − j| inside the band. Set entries before factor().
  double& at(int i, int j) noexcept { return a_[idx(i, j)]; }
  [[nodiscard]] double at(int i, int j) const noexcept { return a_[idx(i, j)]; }

  /// LU with partial pivoting. Returns false when a pivot is zero or below
  /// 1e-14 × the largest entry (the system has no unique solution); `failed_row`
  /// then tells where.
  bool factor();
  [[nodiscard]] int failed_row() const noexcept { return failed_row_; }

  /// Solves A X = B in place. B has n rows; row i starts at b + i*stride and
  /// holds `width` doubles, one per right-hand side. By rows when factor() swapped
  /// none, else by columns.
  void solve(double* b, std::size_t width, std::size_t stride) const noexcept;

  /// The sweeps column by column: each elimination step updates the rows below
  /// (back substitution: each row its own updates), one pass over a row per update.
  void solve_by_columns(double* b, std::size_t width, std::size_t stride) const noexcept;
  /// The sweeps row by row, each row finished in one pass (its updates in registers,
  /// one store): the same operations in the same order, so the same bits, as
  /// solve_by_columns; only when factor() swapped no rows.
  void solve_by_rows(double* b, std::size_t width, std::size_t stride) const noexcept;
  /// Whether factor() swapped rows.
  [[nodiscard]] bool swapped() const noexcept { return swapped_; }

 private:
  [[nodiscard]] std::size_t idx(int i, int j) const noexcept {
    return static_cast<std::size_t>(i) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(j - i + kl_);
  }
  int n_, kl_, ku_, w_;  // w_ = 2*kl + ku + 1 columns per row: pivoting widens U by kl
  std::vector<double> a_;
  std::vector<int> piv_;
  int failed_row_ = -1;
  bool swapped_ = false;  // factor() swapped rows
};

/// A cyclic banded matrix: row i has its entries near column i + h modulo n, for
/// one shift h — the collocation matrix of a periodic spline. Solved as a bordered
/// system: the leading (n − m) block B, banded and without the wrapped corners, is
/// factored with BandedLU; the m border unknowns come from the small dense Schur
/// complement S = E − D B⁻¹ C; Y = B⁻¹ C is kept. A right-hand side costs one banded
/// solve, m·n more multiply-adds and one move of every row (the shift h undone),
/// fused into one pass. Factored once, applied to any number of right-hand sides
/// in place, like BandedLU.
class CyclicLU {
 public:
  struct Entry {
    int col;  ///< taken modulo n
    double value;
  };
  /// The n × n matrix whose row i holds rows[i]. Entries sharing a place add up.
  CyclicLU(int n, const std::vector<std::vector<Entry>>& rows);

  [[nodiscard]] int size() const noexcept { return n_; }
  /// False when a pivot is zero or below 1e-14 × the largest entry; `failed_row`
  /// tells where.
  bool factor();
  [[nodiscard]] int failed_row() const noexcept { return failed_row_; }
  /// Solves A X = B in place, laid out as for BandedLU::solve.
  void solve(double* b, std::size_t width, std::size_t stride) const;

 private:
  // The solve with `border` (m × width doubles) as scratch: the kernel, which must
  // not allocate (base/kernel.hpp).
  void solve_with(double* b, std::size_t width, std::size_t stride, double* border) const noexcept;

  int n_, h_ = 0, m_ = 0, nb_ = 0;  // shift, border size, size of B
  std::vector<std::vector<Entry>> rows_;
  BandedLU b_{0, 0, 0};
  std::vector<double> y_;                   // nb × m, row-major: B⁻¹ C
  std::vector<std::vector<Entry>> d_;       // border rows' entries in columns < nb
  std::vector<double> s_;                   // m × m: the factored Schur complement
  std::vector<int> piv_;
  int failed_row_ = -1;
};

/// Solves along one axis of a C-order array of `shape` (doubles, last axis the
/// `components` of each value) in place: every line along `axis` is a right-hand
/// side of `lu`. With `parallel`, threads split independent lines and column
/// slices; without, the calling thread does all (for callers already inside a
/// parallel region). Every number is computed by the same operations whatever the
/// thread count.
template <class Solver>
void solve_along_axis(const Solver& lu, double* data, const std::size_t* shape, std::size_t rank, std::size_t axis,
                      std::size_t components, bool parallel = true);

}  // namespace interpatch::detail
