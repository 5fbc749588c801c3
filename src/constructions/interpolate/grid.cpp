// Surfaces and volumes through grids of points: interpolate_surface and
// interpolate_volume, the single process running solve_grid_rows on the whole grid.

#include <utility>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "interpatch/interpolate.hpp"

namespace interpatch {

namespace {

using GridValues = Grid<Vec3, 2>::storage_type;

// The tensor-product interpolation behind surfaces and volumes, on the whole grid
// in place: the data become the control points.
template <std::size_t Rank>
detail::SolvedGrid<GridValues> solve_grid(Grid<Vec3, Rank>& points, const std::array<std::optional<int>, Rank>& degree,
                                          Parametrization param, const progress_callback& progress,
                                          const std::array<bool, Rank>& periodic) {
  detail::HeldRows<Rank, GridValues> held;
  for (std::size_t a = 0; a < Rank; ++a) held.n[a] = points.extent(a);
  held.count = held.n[0];
  held.rows = std::move(points.values());
  points = Grid<Vec3, Rank>();
  detail::GridOptions options;
  options.param = param;
  for (std::size_t a = 0; a < Rank; ++a) {
    options.degree[a] = degree[a];
    options.periodic[a] = periodic[a];
  }
  auto steps = [&](detail::GridStep step, std::uint64_t) {
    if (!progress) return;
    if (step == detail::GridStep::degrees) progress(0.0);
    else if (step == detail::GridStep::rows) progress(0.6);
    else if (step == detail::GridStep::done) progress(1.0);
  };
  auto every_row = [](const std::vector<KnotVector>&, std::size_t rows) { return std::pair<long long, std::size_t>{0, rows}; };
  const detail::RowTeam alone;
  detail::SolvedGrid<GridValues> s = detail::solve_grid_rows(held, options, alone, steps, every_row);
  typename Grid<Vec3, Rank>::shape_type net{};
  for (std::size_t a = 0; a < Rank; ++a) net[a] = s.net[a];
  points = Grid<Vec3, Rank>(net, std::move(s.rows));
  return s;
}

}  // namespace

SurfaceInterpolation interpolate_surface(PointGrid points, const SurfaceInterpolationOptions& options) {
  auto s = solve_grid<2>(points, {options.degree_u, options.degree_v}, options.param, options.progress, options.periodic);
  return {BSplineSurface(std::move(s.knots[0]), std::move(s.knots[1]), std::move(points)),
          std::move(s.params[0]), std::move(s.params[1])};
}

VolumeInterpolation interpolate_volume(PointGrid3 points, const VolumeInterpolationOptions& options) {
  auto s = solve_grid<3>(points, {options.degree_u, options.degree_v, options.degree_w}, options.param, options.progress,
                         options.periodic);
  return {BSplineVolume(std::move(s.knots[0]), std::move(s.knots[1]), std::move(s.knots[2]), std::move(points)),
          std::move(s.params[0]), std::move(s.params[1]), std::move(s.params[2])};
}

}  // namespace interpatch
