// A grid interpolation split between the processes: the spec's options and checks
// on the blocks as read, then detail::solve_grid_rows, the single process's steps,
// on this process's rows, and its share of the output written.

#include <optional>
#include <utility>

#include "interpatch/error.hpp"
#include "io/spec/reader.hpp"
#include "mpi/driver.hpp"

namespace interpatch::mpi {

namespace {

// The spec's options, with the checks and warnings of the single process.
template <std::size_t D>
detail::GridOptions grid_options(const Plan& plan, Held<D>& held, const Team& team, io::reader::Context& ctx) {
  std::vector<std::optional<int>> degree;
  detail::GridOptions o;
  team.run([&] {
    degree = io::reader::degrees(plan.spec, "", D);
    o.param = io::reader::parametrization(plan.spec, "");
    o.periodic = io::reader::periodic_flags(plan.spec, "", D);
  });
  for (std::size_t a = 0; a < D; ++a) o.degree[a] = degree[a];
  const char* type = D == 2 ? "interpolate" : "interpolate_volume";
  team.run([&] {
    if (team.rank() == 0) (void)io::reader::check_fields(plan.spec, "", io::reader::find_type(type)->fields, ctx);
  });
  const std::vector<std::size_t> shape(plan.header.shape.begin(), plan.header.shape.begin() + D);
  const detail::GridBlock b = held.block();
  // check_grid_axes throws on every process alike (it sees what all see).
  team.run([&] {
    (void)io::reader::check_grid_axes(plan.spec, degree, o.periodic, shape, D == 2 ? "surface" : "volume",
                                      [&](std::size_t a) { return detail::block_closing(b, a, b.ends, false, team); }, ctx);
  });
  return o;
}

// The stages the timings name.
const char* stage_name(detail::GridStep step) {
  switch (step) {
    case detail::GridStep::checks: return "checks";
    case detail::GridStep::rows: return "rows";
    case detail::GridStep::to_columns: return "to_columns";
    case detail::GridStep::solve_u: return "solve_u";
    case detail::GridStep::to_rows: return "to_rows";
    default: return nullptr;
  }
}

}  // namespace

template <std::size_t D>
int interpolate_run(const Request& r, const Plan& plan, const Team& team) {
  Stages stages(team.rank());
  io::reader::Context ctx;
  ctx.base_dir = plan.base;
  Held<D> held = read_block<D>(plan, team);
  // As the reader does: the first point that is not finite, named in the whole grid.
  team.run([&] {
    try {
      io::reader::check_finite_block({held.n.begin(), held.n.begin() + D}, {held.rows.data(), held.rows.size()},
                                     held.first * held.row_size(), "/points", plan.file);
    } catch (const error& e) {
      io::reader::rethrow_for_interpolation(e);
    }
  });
  stages.done("read");
  const detail::GridOptions options = grid_options<D>(plan, held, team, ctx);

  // The control rows this process needs: its share (build), or the window its output
  // rows' basis functions reach (eval), around a periodic u past the end. The
  // output's knots run over [0, 1].
  std::vector<KnotVector> knots;
  OutputRows orows;
  auto window = [&](const std::vector<KnotVector>& net_knots, std::size_t N) {
    team.run([&] {
      knots = net_knots;
      bool unit = true;
      for (const KnotVector& k : knots) unit = unit && k.front() == 0.0 && k.back() == 1.0;
      if (!unit)
        for (KnotVector& k : knots) k = k.mapped(0.0, 1.0);
    });
    orows = output_rows<D>(r, plan, team, knots[0], N, D == 2 ? "interpolate" : "interpolate_volume");
    return std::pair<long long, std::size_t>{orows.lo, orows.window()};
  };
  auto steps = [&](detail::GridStep step, std::uint64_t sent) {
    if (const char* name = stage_name(step)) stages.done(name, sent);
  };
  const detail::SolvedGrid<std::vector<Vec3>> s = detail::solve_grid_rows(held, options, team, steps, window);
  const std::vector<std::size_t> net_shape(s.net.begin(), s.net.begin() + D);
  write_output<D>(r, team, s.degrees, knots, net_shape, s.rows, orows, s.window, stages);
  stages.print();
  print_warnings(ctx.warnings, team);
  return 0;
}

template int interpolate_run<2>(const Request&, const Plan&, const Team&);
template int interpolate_run<3>(const Request&, const Plan&, const Team&);

}  // namespace interpatch::mpi
