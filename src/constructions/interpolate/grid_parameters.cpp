// The parameters of grids: the finite check and the scale of the data, every row's
// step along u, grid_parameters for a whole grid and block_parameters for a grid
// held in blocks of rows.

#include <algorithm>
#include <cmath>
#include <string>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

namespace detail {

namespace {

// Point k of the whole grid (in C order) is q.
[[noreturn]] void fail_not_finite(const Vec3& q, const GridShape& g, std::size_t k) {
  std::string at;
  for (std::size_t a = g.rank, rest = k; a-- > 0; rest /= g.n[a]) at = detail::cat("[", rest % g.n[a], "]", at);
  const bool missing = std::isnan(q.x) || std::isnan(q.y) || std::isnan(q.z);
  fail(errc::not_finite, "point ", at, " is ", q,
       missing ? " (interpolation needs every point; approximation takes missing points, marked by NaN)" : "");
}

// Grids of extreme scale, coordinates beyond 2^±400 (about 1e±120), are solved
// scaled by 2^-e, e = grid_exponent: data near 1e300 or 1e-300 (or subnormal) then
// run the chord pass at full speed and their line lengths neither overflow nor lose
// their reciprocals. Parameters do not depend on the scale and the solve is linear,
// so the control points are scaled back by 2^e: exactly the ones the data give as
// they are, in the range where the arithmetic has no limits.
constexpr int extreme_exponent = 400;

}  // namespace

void check_grid_finite(const Vec3* q, const GridShape& g) {
  const std::size_t total = g.n[0] * g.row;
  if (const std::size_t k = detail::first_non_finite(q, total); k < total) fail_not_finite(q[k], g, k);
}

void check_finite(const GridBlock& b) {
  const std::size_t M = b.row_size(), total = b.count * M;
  if (const std::size_t k = first_non_finite(b.data, total); k < total)
    fail_not_finite(b.data[k], grid_shape(b), b.first * M + k);
}

int grid_exponent(const GridBlock& b, const RowTeam& team) {
  const std::size_t M = b.row_size();
  auto largest = [&](const Vec3* q, std::size_t count) {
    double m = 0;
    for (std::size_t k = 0; k < count; ++k) m = std::max(m, max_abs(q[k]));
    return m;
  };
  double m = std::max(largest(b.row0, M), largest(b.last, M));
  if (m == 0) {
    double all[1] = {largest(b.data, b.count * M)};
    team.max(all);
    m = all[0];
  }
  return scale_exponent(m);
}

int block_shift(const GridBlock& b, const RowTeam& team) {
  const int e = grid_exponent(b, team);
  return e > extreme_exponent || e < -extreme_exponent ? e : 0;
}

void scale_points(Vec3* p, std::size_t count, int k) {
  const auto n = static_cast<long long>(count);
#pragma omp parallel for schedule(static) if (count >= parallel_min_work)
  for (long long i = 0; i < n; ++i) p[i] = ldexp(p[i], k);
}

namespace {

// Every row's step along u (pass 2 without the solves).
std::vector<double> row_steps(const Vec3* q, const GridShape& g, const GridChords& chords) {
  std::vector<double> steps(g.n[0], 0.0);
  const auto n0 = static_cast<long long>(g.n[0]);
  ParallelFailure failure;  // each thread's scratch is allocated
#pragma omp parallel if (g.n[0] * g.row >= parallel_min_work / 4)
  {
    std::vector<double> scratch;
    failure.attempt(static_cast<std::size_t>(thread_index()), [&] { scratch.resize(g.row); });
#pragma omp for schedule(static)
    for (long long r = 1; r < n0; ++r) {
      if (failure.failed()) continue;
      const auto k = static_cast<std::size_t>(r);
      steps[k] = chords.row_step(q + (k - 1) * g.row, q + k * g.row, scratch.data());
    }
  }
  failure.rethrow();
  return steps;
}

template <std::size_t Rank>
std::vector<double> grid_parameters_of(const Grid<Vec3, Rank>& q, int axis, Parametrization param) {
  if (axis < 0 || axis >= static_cast<int>(Rank))
    fail(errc::out_of_domain, "axis ", axis, " is outside 0..", Rank - 1, " for a grid of rank ", Rank);
  const auto a = static_cast<std::size_t>(axis);
  if (q.extent(a) < 2) fail(errc::too_few_points, "a grid needs at least 2 points along ", axis_name(axis), ", got ", q.extent(a));
  const GridShape g = grid_shape(q.shape());
  const RowTeam alone;
  auto parameters = [&](const Grid<Vec3, Rank>& data) {
    const GridChords chords(whole_grid(data), param, {}, alone);
    if (a > 0) return chords.in_row_parameters(a);
    return chords.u_parameters(chords.uses_chords() ? row_steps(data.data(), g, chords) : std::vector<double>(g.n[0], 0.0));
  };
  const int shift = param == Parametrization::uniform ? 0 : block_shift(whole_grid(q), alone);
  if (shift == 0) return parameters(q);
  check_grid_finite(q.data(), g);  // before scaling: the message shows the point as given
  require_memory(q.size(), sizeof(Vec3), "a scaled copy of the grid");
  Grid<Vec3, Rank> scaled = q;
  scale_points(scaled.data(), scaled.size(), -shift);
  return parameters(scaled);
}

}  // namespace

}  // namespace detail

std::vector<double> grid_parameters(const PointGrid& q, int axis, Parametrization param) {
  return detail::grid_parameters_of(q, axis, param);
}

std::vector<double> grid_parameters(const PointGrid3& q, int axis, Parametrization param) {
  return detail::grid_parameters_of(q, axis, param);
}

namespace detail {

std::vector<std::vector<double>> block_parameters(const GridBlock& b, Parametrization param, const RowTeam& team,
                                                  std::size_t axes, bool along_u) {
  const std::size_t R = b.rank, M = b.row_size();
  // As grid_parameters_of: a grid of extreme scale is measured scaled by 2^-shift.
  const int shift = param == Parametrization::uniform ? 0 : block_shift(b, team);
  GridBlock s = b;
  std::vector<Vec3> scaled;
  if (shift != 0) {
    team.run([&] {
      check_finite(b);
      require_memory((b.count + 3) * M, sizeof(Vec3), "a scaled copy of the grid");
    });
    scaled.resize((b.count + 3) * M);
    Vec3* at = scaled.data();
    auto copy = [&](const Vec3* from, std::size_t rows) {
      Vec3* to = at;
      if (from != nullptr) std::copy_n(from, rows * M, to);
      at += rows * M;
      return to;
    };
    s.data = copy(b.data, b.count);
    s.before = b.first > 0 ? copy(b.before, 1) : nullptr;
    s.row0 = copy(b.row0, 1);
    s.last = copy(b.last, 1);
    scale_points(scaled.data(), static_cast<std::size_t>(at - scaled.data()), -shift);
  }
  const GridChords chords(s, param, {}, team);
  std::vector<std::vector<double>> t(R);
  std::vector<double> steps(s.count, 0.0);
  if (chords.uses_chords() && along_u) {
    std::vector<double> scratch(M);
    for (std::size_t k = s.first == 0 ? 1 : 0; k < s.count; ++k)
      steps[k] = chords.row_step(k == 0 ? s.before : s.data + (k - 1) * M, s.data + k * M, scratch.data());
  }
  const std::vector<double> all_steps = along_u ? team.gather(steps) : std::vector<double>{};
  team.run([&] {
    if (along_u) t[0] = chords.u_parameters(all_steps);
    for (std::size_t a = 1; a < std::min(R, axes); ++a) t[a] = chords.in_row_parameters(a);
  });
  return t;
}

}  // namespace detail

}  // namespace interpatch
