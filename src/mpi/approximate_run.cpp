// An approximation split between the processes: detail::approximate_rows on the
// blocks of rows, then each process's window of the control rows gathered from the
// processes that fitted them, and the output written as for an interpolation.

#include <algorithm>
#include <limits>

#include "constructions/approximate/approx_rows.hpp"
#include "io/spec/reader.hpp"
#include "mpi/driver.hpp"

namespace interpatch::mpi {

namespace {

// Gives a buffer's memory back now (v = {} would keep its capacity).
void release(std::vector<Vec3>& v) { std::vector<Vec3>().swap(v); }

// The control rows [lo, lo + window) of a net of N rows of `width` points (modulo N
// around a periodic u), from the processes holding them: this one rows
// [first, first + mine.size() / width).
std::vector<Vec3> window_rows(const std::vector<Vec3>& mine, std::size_t first, std::size_t N, std::size_t width, long long lo,
                              std::size_t window, const Team& team) {
  const auto P = static_cast<std::size_t>(team.size());
  const std::vector<std::uint64_t> los = team.all(static_cast<std::uint64_t>(lo)), counts = team.all(window);
  const std::vector<std::uint64_t> firsts = team.all(first), held = team.all(width ? mine.size() / width : 0);
  auto row_of = [&](long long v) {
    const auto n = static_cast<long long>(N);
    return static_cast<std::size_t>(((v % n) + n) % n);
  };
  auto owner = [&](std::size_t g) {
    std::size_t s = 0;
    while (s + 1 < P && !(g >= firsts[s] && g < firsts[s] + held[s])) ++s;
    return s;
  };
  std::vector<Vec3> send, recv(window * width), out(window * width);
  std::vector<std::size_t> sc(P, 0), rc(P, 0);
  for (std::size_t s = 0; s < P; ++s)
    for (std::uint64_t v = 0; v < counts[s]; ++v) {
      const std::size_t g = row_of(static_cast<long long>(los[s]) + static_cast<long long>(v));
      if (g < first || g >= first + held[static_cast<std::size_t>(team.rank())]) continue;
      send.insert(send.end(), mine.begin() + static_cast<std::ptrdiff_t>((g - first) * width),
                  mine.begin() + static_cast<std::ptrdiff_t>((g - first + 1) * width));
      sc[s] += width;
    }
  for (std::size_t v = 0; v < window; ++v) rc[owner(row_of(lo + static_cast<long long>(v)))] += width;
  team.exchange(send.data(), sc, recv.data(), rc);
  // From each process its rows of the window, in window order.
  std::vector<std::size_t> at(P, 0);
  for (std::size_t s = 1; s < P; ++s) at[s] = at[s - 1] + rc[s - 1];
  for (std::size_t v = 0; v < window; ++v) {
    const std::size_t s = owner(row_of(lo + static_cast<long long>(v)));
    std::copy_n(recv.data() + at[s], width, out.data() + v * width);
    at[s] += width;
  }
  return out;
}

}  // namespace

// An approximation split between the processes: detail::approximate_rows on the
// blocks of rows, then the output as for an interpolation.
int approximate_run(const Request& r, const Plan& plan, const Team& team) {
  Stages stages(team.rank());
  io::reader::Context ctx;
  ctx.base_dir = plan.base;
  team.run([&] {
    if (team.rank() == 0) (void)io::reader::check_fields(plan.spec, "", io::reader::find_type("approximate")->fields, ctx);
  });
  Held<2> rb = read_block<2>(plan, team);
  // As the reader does: NaN marks a missing point, infinity is refused.
  team.run([&] {
    io::reader::check_finite_block({rb.n[0], rb.n[1]}, {rb.rows.data(), rb.rows.size()}, rb.first * rb.row_size(),
                                   "/points", plan.file, true);
  });
  stages.done("read");
  const detail::GridBlock b = rb.block();
  // As in one process: data beyond 2^±64 are fitted in a power of two of their own
  // size (exact both ways), the unit agreed over every process's rows.
  double top[1] = {detail::largest_coordinate(rb.rows)};
  team.max(top);
  const double unit = detail::approximation_unit(top[0]);
  SurfaceApproximationOptions options = plan.approx;
  if (unit != 1) {
    for (Vec3& q : rb.rows) q = q * (1 / unit);
    for (auto& h : rb.halo)
      for (Vec3& q : h) q = q * (1 / unit);
    if (options.tolerance)
      options.tolerance = std::max(*options.tolerance / unit, std::numeric_limits<double>::denorm_min());
  }
  detail::ApproxRows fit;
  io::reader::at("/points", [&] { fit = detail::approximate_rows(b, options, team, [&] { release(rb.rows); }); });
  release(rb.rows);
  for (Vec3& q : fit.rows) q = q * unit;
  stages.done("fit");
  const std::size_t N = fit.net[0], width = fit.net[1];
  const OutputRows o = output_rows<2>(r, plan, team, fit.knots[0], N, "approximate");
  const std::size_t window = o.window();
  const std::vector<Vec3> cp = window_rows(fit.rows, fit.first, N, width, o.lo, window, team);
  stages.done("to_rows");
  write_output<2>(r, team, {fit.degree[0], fit.degree[1]}, {fit.knots[0], fit.knots[1]}, {N, width}, cp, o, window, stages);
  stages.print();
  print_warnings(ctx.warnings, team);
  return 0;
}

}  // namespace interpatch::mpi
