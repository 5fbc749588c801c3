// The banded solves of grid interpolation: the factored system of each axis, the
// solves along an axis or down columns, and passes 1 and 2 on a block of rows
// (solve_rows): parameters, knots, and the solves along the axes inside the rows.

#include <algorithm>
#include <variant>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "linalg/banded.hpp"
#include "linalg/collocation.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"

namespace interpatch::detail {

namespace {

constexpr std::size_t rows_per_group = 8;

void solve_axis(const AxisSolver& lu, double* data, const std::size_t* shape, std::size_t rank, std::size_t axis,
                std::size_t components, bool parallel = true) {
  std::visit([&](const auto& s) { solve_along_axis(s, data, shape, rank, axis, components, parallel); }, lu);
}

}  // namespace

KnotVector axis_knots(std::span<const double> params, int degree, bool closed) {
  return closed ? periodic_knots(params, degree) : averaged_knots(params, degree);
}

AxisSolver factor_axis(const KnotVector& knots, std::span<const double> params, std::size_t a) {
  try {
    if (knots.periodic()) return factor_periodic_collocation(knots, params);
    return factor_collocation(knots, params);
  } catch (const error& e) {
    fail(e.code(), "along ", axis_name(static_cast<int>(a)), ": ", e.what());
  }
}

void solve_columns(const AxisSolver& lu, double* data, std::size_t n, std::size_t width) {
  const std::size_t shape[2] = {n, width};
  solve_axis(lu, data, shape, 2, 0, 1, true);
}

RowSolution solve_rows(const GridBlock& b, std::span<const int> p, Parametrization param, std::span<const bool> periodic,
                       const RowTeam& team) {
  const std::size_t R = b.rank, M = b.row_size();
  std::array<bool, 3> closed{};
  for (std::size_t a = 0; a < R; ++a) closed[a] = periodic[a];
  const GridChords chords(b, param, closed, team);
  team.run([&] { chords.check_lines(); });

  RowSolution r;
  r.params.resize(R);
  std::vector<AxisSolver> lu;
  std::vector<KnotVector> row_knots;
  team.run([&] {  // the same on every process
    for (std::size_t a = 1; a < R; ++a) {
      r.params[a] = chords.in_row_parameters(a);
      row_knots.push_back(axis_knots(r.params[a], p[a], periodic[a]));
      lu.push_back(factor_axis(row_knots.back(), r.params[a], a));
    }
  });

  // Pass 2: groups of rows, each thread a contiguous run of them. A row's step along
  // u needs the row before it as it was, so each thread keeps a copy of the last
  // row it has read before solving it (the block's first row: the row before the
  // block).
  std::vector<double> steps(b.count, 0.0);
  Vec3* data = b.data;
  const std::size_t groups = (b.count + rows_per_group - 1) / rows_per_group;
  std::array<std::size_t, 4> group_shape{};
  for (std::size_t a = 1; a < R; ++a) group_shape[a] = b.n[a];
  group_shape[R] = 3;
  const bool uses_chords = chords.uses_chords();
  // The threads' copies and the solves (a closed axis's) allocate. A thread that
  // failed still meets the barrier; the groups after a failed one are skipped.
  ParallelFailure failure;
#pragma omp parallel if (b.count * M >= parallel_min_work / 8)
  {
    const std::size_t nt = thread_count(), t = static_cast<std::size_t>(thread_index());
    const std::size_t g0 = groups * t / nt, g1 = groups * (t + 1) / nt;
    std::vector<Vec3> prev;
    std::vector<double> scratch;
    bool ready = false;
    failure.attempt(g0, [&] {
      prev.resize(uses_chords ? M : 0);
      scratch.resize(uses_chords ? M : 0);
      ready = true;
    });
    if (ready && uses_chords && g0 < g1) {
      if (g0 > 0) std::copy_n(data + (g0 * rows_per_group - 1) * M, M, prev.data());
      else if (b.first > 0) std::copy_n(b.before, M, prev.data());
    }
#pragma omp barrier
    auto gs = group_shape;
    for (std::size_t gi = g0; gi < g1 && ready; ++gi)
      failure.attempt(gi, [&] {
        const std::size_t r0 = gi * rows_per_group, r1 = std::min(b.count, r0 + rows_per_group);
        if (uses_chords) {
          for (std::size_t k = b.first + r0 == 0 ? 1 : r0; k < r1; ++k)
            steps[k] = chords.row_step(k == r0 ? prev.data() : data + (k - 1) * M, data + k * M, scratch.data());
          std::copy_n(data + (r1 - 1) * M, M, prev.data());
        }
        gs[0] = r1 - r0;
        for (std::size_t a = 1; a < R; ++a) solve_axis(lu[a - 1], &data[r0 * M].x, gs.data(), R + 1, a, 1, false);
      });
  }
  failure.rethrow();

  // Along u: every row's step, in row order.
  const std::vector<double> all_steps = team.gather(steps);
  team.run([&] {
    r.params[0] = chords.u_parameters(all_steps);
    r.knots.push_back(axis_knots(r.params[0], p[0], periodic[0]));
  });
  for (auto& k : row_knots) r.knots.push_back(std::move(k));
  return r;
}

}  // namespace interpatch::detail
