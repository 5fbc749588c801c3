#pragma once
// The distances of a fit to its data: per row of the grid, in blocks of rows summed
// in order (the same sums in one process as in a split run), the maxima per knot
// interval that tell a fit to a tolerance where to add knots, and the values the
// line fits of one direction take where a point is missing.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "base/parallel.hpp"
#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_passes.hpp"

namespace interpatch::detail::approx {

template <std::size_t R>
struct Residuals {
  double max = -1, sum_sq = 0, weighted_sq = 0;
  std::size_t worst = 0;
  std::array<std::vector<double>, R> interval_max;
  std::array<std::vector<std::size_t>, R> interval_worst;

  explicit Residuals(const std::array<Axis, R>& axes) {
    for (std::size_t a = 0; a < R; ++a) {
      interval_max[a].assign(static_cast<std::size_t>(axes[a].intervals), -1.0);
      interval_worst[a].assign(static_cast<std::size_t>(axes[a].intervals), 0);
    }
  }
  // Another block's, of later points: the same result as one pass in storage order.
  void merge(const Residuals& o) {
    sum_sq += o.sum_sq;
    weighted_sq += o.weighted_sq;
    if (o.max > max) {
      max = o.max;
      worst = o.worst;
    }
    for (std::size_t a = 0; a < R; ++a)
      for (std::size_t k = 0; k < interval_max[a].size(); ++k)
        if (o.interval_max[a][k] > interval_max[a][k]) {
          interval_max[a][k] = o.interval_max[a][k];
          interval_worst[a][k] = o.interval_worst[a][k];
        }
  }
};

// Residuals of data rows [q0, q1) (every index but the last fixed; row q of
// `partial` at partial + (q − base)·3c, of the points at pts + (q − base)·n): the
// distances, their sums in row order and the maxima, into r. off[i·(p+1) + k]: where
// basis function k of point i along the last axis finds its control point's
// coordinates in a row of `partial` (residual_offsets); `row` and `e2` are scratch
// of 3n and n doubles.
template <std::size_t R, class Weight>
void residual_rows(Residuals<R>& r, const std::array<Axis, R>& axes, const Shape<R>& shape, const double* partial,
                   const Vec3* pts_, std::size_t base, std::size_t q0, std::size_t q1, const Weight& weight,
                   const std::size_t* off, double* row, double* e2) {
  const Axis& last = axes[R - 1];
  const std::size_t n = last.n, c = static_cast<std::size_t>(last.c), pp = static_cast<std::size_t>(last.p) + 1;
  for (std::size_t q = q0; q < q1; ++q) {
    const double* src = partial + (q - base) * c * 3;
    for (std::size_t i = 0; i < n; ++i) {
      double x = 0, y = 0, z = 0;
      for (std::size_t k = 0; k < pp; ++k) {
        const double w = last.b[i * pp + k];
        const double* v = src + off[i * pp + k];
        x += w * v[0];
        y += w * v[1];
        z += w * v[2];
      }
      row[3 * i] = x, row[3 * i + 1] = y, row[3 * i + 2] = z;
    }
    // Squared distances first (a loop the compiler vectorizes), then the maxima:
    // of the row for the axes before the last, per interval along the last.
    const Vec3* pts = pts_ + (q - base) * n;
    for (std::size_t i = 0; i < n; ++i) {
      const double dx = row[3 * i] - pts[i].x, dy = row[3 * i + 1] - pts[i].y, dz = row[3 * i + 2] - pts[i].z;
      e2[i] = dx * dx + dy * dy + dz * dz;
    }
    double row_max = -1;
    std::size_t row_worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double w = weight(q * n + i);
      if (!(w > 0)) continue;
      r.sum_sq += e2[i];
      r.weighted_sq += w * e2[i];
      if (e2[i] > row_max) {
        row_max = e2[i];
        row_worst = i;
      }
      auto& m = r.interval_max[R - 1][static_cast<std::size_t>(last.interval[i])];
      if (e2[i] > m) {
        m = e2[i];
        r.interval_worst[R - 1][static_cast<std::size_t>(last.interval[i])] = q * n + i;
      }
    }
    if (row_max < 0) continue;  // every point of the row missing
    const std::size_t flat = q * n + row_worst;
    if (row_max > r.max) {
      r.max = row_max;
      r.worst = flat;
    }
    for (std::size_t a = R - 1, rest = q; a-- > 0; rest /= shape[a]) {
      const auto k = static_cast<std::size_t>(axes[a].interval[rest % shape[a]]);
      if (row_max > r.interval_max[a][k]) {
        r.interval_max[a][k] = row_max;
        r.interval_worst[a][k] = flat;
      }
    }
  }
}

std::vector<std::size_t> residual_offsets(const Axis& last);

// Data rows are taken in blocks of this many, each block's sums formed on its own
// and the blocks' added in order (in one process as in a split run).
constexpr std::size_t residual_block_rows = 16;

// Residuals of data rows [q0, q1) (row q of `partial` at partial + (q − base)·3c, of
// the points at pts + (q − base)·n, as residual_rows): blocks of
// residual_block_rows rows from q0 in parallel, merged in order.
template <std::size_t R, class Weight>
Residuals<R> residual_blocks(const std::array<Axis, R>& axes, const Shape<R>& shape, const double* partial, const Vec3* pts,
                             std::size_t base, std::size_t q0, std::size_t q1, const Weight& weight) {
  const std::size_t n = axes[R - 1].n, pp = static_cast<std::size_t>(axes[R - 1].p) + 1;
  const std::size_t blocks = (q1 - q0 + residual_block_rows - 1) / residual_block_rows;
  std::vector<Residuals<R>> part(blocks, Residuals<R>(axes));
  const auto nb = static_cast<long long>(blocks);
  const std::vector<std::size_t> off = residual_offsets(axes[R - 1]);
  detail::ParallelFailure failure;  // allocating a thread's scratch
#pragma omp parallel if ((q1 - q0) * n * pp * 3 >= parallel_work)
  {
    std::vector<double> row, e2;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      row.resize(3 * n);
      e2.resize(n);
    });
#pragma omp for schedule(static)
    for (long long bi = 0; bi < nb; ++bi) {
      if (failure.failed()) continue;
      const std::size_t b0 = q0 + static_cast<std::size_t>(bi) * residual_block_rows;
      residual_rows<R>(part[static_cast<std::size_t>(bi)], axes, shape, partial, pts, base, b0,
                       std::min(q1, b0 + residual_block_rows), weight, off.data(), row.data(), e2.data());
    }
  }
  failure.rethrow();
  Residuals<R> all(axes);
  for (const auto& r : part) all.merge(r);
  return all;
}

// Squares were compared; distances are reported.
template <std::size_t R>
void take_roots(Residuals<R>& r) {
  r.max = r.max < 0 ? 0.0 : std::sqrt(r.max);
  for (std::size_t a = 0; a < R; ++a)
    for (double& m : r.interval_max[a]) m = m < 0 ? m : std::sqrt(m);
}

// S at one data point (its flat index), from the control net.
template <std::size_t R>
Vec3 value_at(const std::array<Axis, R>& axes, const std::vector<double>& cp, std::size_t flat, const Shape<R>& data_shape) {
  const std::vector<std::size_t> idx = unflatten<R>(flat, data_shape);
  std::array<std::size_t, R> pp{}, k{};
  for (std::size_t a = 0; a < R; ++a) pp[a] = static_cast<std::size_t>(axes[a].p) + 1;
  Vec3 s{};
  for (;;) {
    double w = 1;
    std::size_t at = 0;
    for (std::size_t a = 0; a < R; ++a) {
      const Axis& ax = axes[a];
      w *= ax.b[idx[a] * pp[a] + k[a]];
      at = at * static_cast<std::size_t>(ax.c) + ax.col(ax.first[idx[a]] + static_cast<int>(k[a]));
    }
    s = s + w * Vec3{cp[3 * at], cp[3 * at + 1], cp[3 * at + 2]};
    std::size_t a = R;
    while (a-- > 0) {
      if (++k[a] < pp[a]) break;
      k[a] = 0;
    }
    if (a == static_cast<std::size_t>(-1)) return s;
  }
}

// The residual at point `pos` of `line` (n points along axis `ax`, 3 doubles each)
// of the least-squares fit along that axis alone: whether the direction lacks knots
// there.
double line_fit_residual(const Axis& ax, const AxisSolver& lu, const std::vector<double>& line, std::size_t pos);

// A data point for a line fit: the point where present, else the approximation's
// value there (cp: the control net).
template <std::size_t R>
Vec3 point_or_fit(const std::array<Axis, R>& axes, const std::vector<double>& cp, const Shape<R>& shape, const Vec3& q,
                  bool present, std::size_t flat) {
  return present ? q : value_at<R>(axes, cp, flat, shape);
}

}  // namespace interpatch::detail::approx
