// The output of a split run: which rows of it each process writes and which control
// rows those need, and the writing itself, in place in one file: build's archive of
// the control net, eval's grid of points evaluated from the process's control rows.

#include <algorithm>
#include <tuple>

#include "commands.hpp"
#include "base/text.hpp"
#include "splines/row_window.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"
#include "io/crc32.hpp"
#include "io/npz_internal.hpp"
#include "mpi/driver.hpp"

namespace interpatch::mpi {

using detail::cat;

template <std::size_t D>
OutputRows output_rows(const Request& r, const Plan& plan, const Team& team, const KnotVector& ku, std::size_t N,
                       const char* type) {
  OutputRows o;
  const int P = team.size();
  if (r.build) {
    std::tie(o.first, o.count) = even_block(N, team.rank(), P);
    o.lo = static_cast<long long>(o.first);
    o.hi = o.lo + static_cast<long long>(o.count) - 1;
    return o;
  }
  io::Resolution& grid = o.grid;
  team.run([&] {
    grid = plan.counts.size() == 1 ? io::Resolution{plan.counts[0], plan.counts[0], D == 3 ? plan.counts[0] : 0}
                                   : io::Resolution{plan.counts[0], plan.counts[1], plan.counts.size() > 2 ? plan.counts[2] : 0};
    if (plan.counts.size() > 1 && (plan.counts.size() == 3) != (D == 3)) {
      io::Construction c;
      c.type = type;
      if constexpr (D == 3) c.exact = BSplineVolume(KnotVector::bezier(1), KnotVector::bezier(1), KnotVector::bezier(1), PointGrid3({2, 2, 2}));
      else c.exact = BSplineSurface(KnotVector::bezier(1), KnotVector::bezier(1), PointGrid({2, 2}));
      cli::check_counts_kind(c, cli::grid_option, grid);
    }
    io::require_eval_room(grid, r.out);
  });
  std::tie(o.first, o.count) = even_block(grid.nu, team.rank(), P);
  const std::vector<double> all_us = linspace(0, 1, grid.nu);
  o.us.assign(all_us.begin() + static_cast<std::ptrdiff_t>(o.first),
              all_us.begin() + static_cast<std::ptrdiff_t>(o.first + o.count));
  long long prev = -1;
  for (const double u : o.us) {
    const double t = ku.periodic() ? ku.wrap(u) : std::clamp(u, ku.front(), ku.back());
    long long s = ku.find_span(t);
    if (s < prev) s += static_cast<long long>(N);  // wrapped past the end of a periodic u
    prev = s;
    if (o.hi < o.lo) o.lo = s - ku.degree();
    o.hi = s;
  }
  return o;
}

// Writes the output from control rows [o.lo, o.lo + window) (around a periodic u)
// of a net of `net_shape` points, row_size of them a row: build writes this
// process's even share of the rows into the archive, eval its rows of the output
// grid, evaluated.
template <std::size_t D>
void write_output(const Request& r, const Team& team, const std::vector<int>& degrees,
                  const std::vector<KnotVector>& knots, const std::vector<std::size_t>& net_shape,
                  const std::vector<Vec3>& cp, const OutputRows& o, std::size_t window, Stages& stages) {
  const std::size_t N = net_shape[0];
  std::size_t row_size = 1;
  for (std::size_t a = 1; a < D; ++a) row_size *= net_shape[a];
  OutputFile file(r.out, team);
  if (r.build) {
    std::vector<const KnotVector*> kp;
    for (const KnotVector& k : knots) kp.push_back(&k);
    const std::size_t bytes = cp.size() * sizeof(Vec3);
    const std::vector<std::uint64_t> crcs = team.all(io::internal::crc32(cp.data(), bytes));
    const std::vector<std::uint64_t> lens = team.all(bytes);
    std::uint32_t crc = 0;
    for (std::size_t s = 0; s < crcs.size(); ++s)
      if (lens[s]) crc = io::internal::crc32_combine(crc, static_cast<std::uint32_t>(crcs[s]), lens[s]);
    const io::internal::NpzFrame frame = io::internal::exact_npz_frame(degrees, kp, net_shape, crc);
    team.run([&] {
      if (team.rank() == 0) {
        io::check_disk_space(r.out, frame.total, cat("the archive '", r.out, "'"));
        file.write(frame.head.data(), frame.head.size(), 0);
        file.write(frame.tail.data(), frame.tail.size(), frame.points_offset + std::uint64_t{N} * row_size * sizeof(Vec3));
      }
      file.write(cp.data(), bytes, frame.points_offset + std::uint64_t{o.first} * row_size * sizeof(Vec3));
    });
  } else {
    const std::vector<double> vs = linspace(0, 1, o.grid.nv), ws = D == 3 ? linspace(0, 1, o.grid.nw) : std::vector<double>{};
    const std::size_t per_row = o.grid.nv * (D == 3 ? o.grid.nw : 1);
    std::vector<std::size_t> out_shape{o.grid.nu, o.grid.nv};
    if (D == 3) out_shape.push_back(o.grid.nw);
    out_shape.push_back(3);
    const std::string header = io::internal::npy_header("<f8", out_shape);
    team.run([&] {
      require_memory(o.count * per_row, sizeof(Vec3), "this process's rows of the evaluation grid");
      std::vector<Vec3> out(o.count * per_row);
      const detail::RowWindow w{cp.data(), o.lo, window, N, row_size};
      if (o.count > 0) {
        if constexpr (D == 2) detail::evaluate_surface_rows(knots[0], knots[1], w, o.us, vs, out);
        else detail::evaluate_volume_rows(knots[0], knots[1], knots[2], w, o.us, vs, ws, out);
      }
      if (team.rank() == 0) file.write(header.data(), header.size(), 0);
      file.write(out.data(), out.size() * sizeof(Vec3), header.size() + std::uint64_t{o.first} * per_row * sizeof(Vec3));
    });
  }
  file.commit();
  stages.done(r.build ? "write" : "evaluate_write");
}

template OutputRows output_rows<2>(const Request&, const Plan&, const Team&, const KnotVector&, std::size_t, const char*);
template OutputRows output_rows<3>(const Request&, const Plan&, const Team&, const KnotVector&, std::size_t, const char*);
template void write_output<2>(const Request&, const Team&, const std::vector<int>&, const std::vector<KnotVector>&,
                              const std::vector<std::size_t>&, const std::vector<Vec3>&, const OutputRows&, std::size_t,
                              Stages&);
template void write_output<3>(const Request&, const Team&, const std::vector<int>&, const std::vector<KnotVector>&,
                              const std::vector<std::size_t>&, const std::vector<Vec3>&, const OutputRows&, std::size_t,
                              Stages&);

}  // namespace interpatch::mpi
