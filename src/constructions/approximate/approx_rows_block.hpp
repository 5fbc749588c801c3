#pragma once
// The row-split fit's data source for a fit to a tolerance (Block, the counterpart of
// approx_whole.hpp's Whole): fits, residuals and line fits on blocks of rows, every
// result the same on every process.

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_residuals.hpp"
#include "constructions/interpolate/grid_rows.hpp"

namespace interpatch::detail::approx {

// A surface's grid held in blocks of rows as a fit to a tolerance sees it (Whole's
// counterpart for solve_tolerance): each process fits, measures and gathers lines on
// its rows; what comes back (the control net, the maxima, the lines) is the same on
// every process, as one process finds it, so every process takes the same knot
// decisions. The block's columns (for Bᵀ w Q) are made once and kept between fits.
// Weights and closed directions as in approximate_rows: the weighted points in the
// columns, the data term summed with the weights (wrapped along a closed u), the
// weight sum added point after point in storage order.
class Block {
  // Each point's weight by its flat index in the grid, as Data::w: 1 everywhere when
  // uniform, else 0 where missing and the given weight (1 when none) elsewhere.
  [[nodiscard]] auto weight() const {
    return [this](std::size_t flat) {
      if (uniform_) return 1.0;
      const std::size_t i = flat - first_ * n_[1];
      if (!present_[i]) return 0.0;
      return w_ ? w_[i] : 1.0;
    };
  }

 public:
  // Rows [first, first + count) of a grid of `shape` at `pts` (`own` holds them for
  // a thinned grid), their weights at `w` (none: every point present weighs 1;
  // `own_w` holds them for a thinned grid). `uniform`: the grid it comes from has
  // every point and equal weights (the data term from the Gram matrices, the
  // separable fit tried first, as Data::uniform).
  Block(const detail::RowTeam& team, const Shape<2>& shape, std::shared_ptr<const std::vector<Vec3>> own, const Vec3* pts,
        std::size_t first, std::size_t count, bool uniform, std::shared_ptr<const std::vector<double>> own_w = {},
        const double* w = nullptr);

  [[nodiscard]] std::size_t size() const { return n_[0] * n_[1]; }
  [[nodiscard]] const Shape<2>& shape() const { return n_; }

  // solve_once without a smoothing weight.
  void fit(Fit<2>& f) const;

  // Whole::sane: the box of every process's data (found when the block is made), the
  // control net whole on every process.
  [[nodiscard]] bool sane(const Fit<2>& f) const { return detail::approx_net_sane(net_points(f.cp), 2, box_); }

  // residuals(): each process its rows, the maxima and worst points merged in process
  // order (a later process's only where strictly greater: the first in one process's
  // scan wins). The sums of squares are this process's alone: the fit to a tolerance
  // reads only the maxima.
  [[nodiscard]] Residuals<2> errors(const Fit<2>& f) const;

  // line_residual at each (axis, point) of `at`: the lines gathered from the
  // processes holding them (along u a column of every process's rows, along v one
  // process's row), all in one exchange, then fitted on every process.
  [[nodiscard]] std::vector<double> line_residuals(const Fit<2>& f, const std::array<std::optional<AxisSolver>, 2>& lu,
                                                   const std::vector<std::pair<std::size_t, std::size_t>>& at) const;

  // Which rows and columns hold data (a point of positive weight): rows from their
  // process, columns OR-reduced.
  [[nodiscard]] std::array<std::vector<bool>, 2> has_data() const;

  // thinned(): the kept rows in this block (a block of the thinned grid's rows, maybe
  // none), the kept columns of each, with their weights.
  [[nodiscard]] Block thinned(const std::array<std::vector<std::size_t>, 2>& kept) const;

 private:
  const detail::RowTeam* team_;
  Shape<2> n_;
  std::shared_ptr<const std::vector<Vec3>> own_;
  const Vec3* pts_;
  std::size_t first_, count_;
  bool uniform_;
  std::shared_ptr<const std::vector<double>> own_w_;
  const double* w_;               // the block's weights, none: 1 each
  bool fill_ = false;             // points without data (missing or of weight 0) in this grid
  double weight_sum_ = 0;         // of the whole grid's weights, in storage order
  std::vector<bool> present_;     // per point of the block, unless uniform
  std::vector<std::pair<std::size_t, std::size_t>> spans_;  // every process's {first, count}
  std::vector<double> cols_;      // the block's columns (rows_to_columns)
  std::array<Vec3, 2> box_{};     // the whole grid's data's box (Whole::sane)
};

}  // namespace interpatch::detail::approx
