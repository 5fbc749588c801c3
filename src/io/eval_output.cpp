// Evaluation grids written to a file by its extension: .npy, evaluated a block of
// rows at a time while the block before is written, or .csv, one row per point.

#include <span>
#include <string>
#include <vector>

#include "interpatch/evaluate.hpp"
#include "interpatch/io/csv.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/outputs.hpp"
#include "io/extension.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;

namespace {

using internal::lower_extension;

// The float64 triples of a .npy block as the points they hold.
std::span<Vec3> points_of(std::span<double> values) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 grids are written as arrays of doubles");
  return {reinterpret_cast<Vec3*>(values.data()), values.size() / 3};
}

void tell(const std::function<void()>& evaluated) {
  if (evaluated) evaluated();
}

void eval_volume(const Construction& c, const fs::path& out, const Resolution& grid, const progress_callback& progress,
                 const std::function<void()>& evaluated) {
  const Volume& v = volume_evaluator(c);
  const GradedParameters graded = sample_parameters(c, grid);
  const std::vector<std::vector<double>> params(graded.params.begin(), graded.params.end());
  if (lower_extension(out) == ".npy") {
    const std::size_t shape[4] = {grid.nu, grid.nv, grid.nw, 3};
    // A few u values a call, on every thread, while the block before is written.
    write_npy_rows(out, shape, [&](std::size_t first, std::size_t count, std::span<double> values) {
      v.evaluate_into(std::span<const double>(params[0]).subspan(first, count), params[1], params[2], points_of(values));
    }, progress);
    tell(evaluated);
    return;
  }
  const PointGrid3 g = v.evaluate(params[0], params[1], params[2], progress);
  tell(evaluated);
  write_csv_grid(out, params, std::span<const Vec3>(g.data(), g.size()));
}

void eval_surface(Construction& c, const fs::path& out, const Resolution& grid, const progress_callback& progress,
                  const std::function<void()>& evaluated) {
  const Surface& s = evaluator(c, grid.nu * grid.nv, Sample::points);
  const GradedParameters graded = sample_parameters(c, grid);
  const std::vector<std::vector<double>> params{graded.params[0], graded.params[1]};
  if (lower_extension(out) == ".npy") {
    const std::size_t shape[3] = {grid.nu, grid.nv, 3};
    const auto rows = s.rows(params[1]);  // what depends on v alone, once for every block
    // A few rows of points a call, on every thread, while the block before is written.
    write_npy_rows(out, shape, [&](std::size_t first, std::size_t count, std::span<double> values) {
      rows->evaluate_into(std::span<const double>(params[0]).subspan(first, count), points_of(values));
    }, progress);
    tell(evaluated);
    return;
  }
  const PointGrid g = s.evaluate(params[0], params[1], progress);
  tell(evaluated);
  write_csv_grid(out, params, std::span<const Vec3>(g.data(), g.size()));
}

}  // namespace

Resolution grid_resolution(const std::vector<std::size_t>& counts, const Construction& c, const CountsOption& option) {
  if (counts.size() == 1) return {counts[0], counts[0], is_volume(c) ? counts[0] : 0};
  const Resolution grid{counts.at(0), counts.at(1), counts.size() == 3 ? counts[2] : 0};
  check_counts_kind(c, option, grid);
  return grid;
}

void write_eval(Construction& c, const fs::path& out, const Resolution& grid, const CountsOption& option,
                const progress_callback& progress, const std::function<void()>& evaluated) {
  check_eval_output(out);
  check_counts(counts_of(grid), option);
  check_counts_kind(c, option, grid);
  require_eval_room(grid, out);
  if (is_volume(c)) return eval_volume(c, out, grid, progress, evaluated);
  eval_surface(c, out, grid, progress, evaluated);
}

void write_eval(const CurveConstruction& c, const fs::path& out, std::size_t points, const CountsOption& option,
                const progress_callback& progress, const std::function<void()>& evaluated) {
  check_eval_output(out);
  check_counts(std::span<const std::size_t>(&points, 1), option);
  require_eval_room({points, 1, 0}, out);
  const BSplineCurve& curve = c.curve;
  const std::vector<double> ts = linspace(0, 1, points);
  if (lower_extension(out) == ".npy") {
    const std::size_t shape[2] = {points, 3};
    write_npy_rows(out, shape, [&](std::size_t first, std::size_t count, std::span<double> values) {
      const std::span<Vec3> at = points_of(values);
      for (std::size_t i = 0; i < count; ++i) at[i] = curve.point(ts[first + i]);
    }, progress);
    tell(evaluated);
    return;
  }
  std::vector<Vec3> at(points);
  for (std::size_t i = 0; i < points; ++i) at[i] = curve.point(ts[i]);
  tell(evaluated);
  const std::vector<double> params[1] = {ts};
  write_csv_grid(out, params, at);
}

}  // namespace interpatch::io
