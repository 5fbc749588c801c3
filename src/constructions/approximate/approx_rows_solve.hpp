#pragma once
// The row-split fit's solves: the right-hand side Bᵀ (w Q) from the data's columns,
// the separable fit along u on columns and along v on rows, and the fitted net's
// control rows as approximate_rows returns them.

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/interpolate/grid_rows.hpp"

namespace interpatch::detail::approx {

// Data points [first, first + count) of an axis: its basis values there.
Axis axis_slice(const Axis& ax, std::size_t first, std::size_t count);

// Bᵀ (w Q) of a grid of M columns held in blocks of rows, from its columns `cols`
// (rows_to_columns: every row of this process's even share of the columns): along u
// on the columns (`read` is called when they are read no more), along v on this
// process's even share of the control rows of the result.
std::vector<double> block_rhs(const std::array<Axis, 2>& axes, const std::vector<double>& cols, std::size_t M,
                              const detail::RowTeam& team, const std::function<void()>& read = {});

// Both directions' factored Gram matrices (separable_fit), or none when one is
// singular: the sparse system then settles what the data leave open.
std::array<std::optional<AxisSolver>, 2> separable_solvers(const std::array<Axis, 2>& axes, const detail::RowTeam& team);

// The separable solve of the right-hand side's rows (block_rhs: this process's even
// share of the c0 control rows): its control rows, along u on columns, along v on rows.
std::vector<double> separable_rows(const std::array<std::optional<AxisSolver>, 2>& lu, const std::vector<double>& rhs,
                                   std::size_t c0, std::size_t c1, const detail::RowTeam& team);

// The fitted surface of f as approximate_rows returns it, `mine` this process's even
// share of the control rows (none: f.cp holds them all).
detail::ApproxRows net_rows(const Fit<2>& f, const detail::RowTeam& team, const double* mine = nullptr);

}  // namespace interpatch::detail::approx
