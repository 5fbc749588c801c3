#pragma once
// `interpatch eval` and `interpatch build` split between MPI processes (docs/mpi.md):
// what the pieces of the driver share. Each process reads its block of rows of the
// .npy points (MPI-IO), the grid is solved by the library's own steps on the blocks
// (detail::solve_grid_rows, or detail::approximate_rows), and every process writes
// its part of the output in place; rank 0 renames the file into place when all have
// succeeded.

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "constructions/interpolate/grid_rows.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/knot_vector.hpp"
#include "io/npy_format.hpp"
#include "mpi/team.hpp"

namespace interpatch::mpi {

/// What the command line asked for (the module's entry point receives it).
struct Request {
  bool build = false;  ///< build (else eval)
  std::string spec, shape, out, grid;
};

/// Runs the request on every process of MPI_COMM_WORLD (MPI initialized and
/// finalized here) and returns this process's exit status, the same on every
/// process; exactly one process prints the one error line. What the split run does
/// not cover (other types, points not in an .npy file, other output formats) runs
/// as `single` on rank 0 alone, the others waiting for its status.
int run_command(const Request& request, const std::function<int()>& single);

/// What the split run needs to know before it reads a point; `split` false: the
/// request runs on rank 0 alone.
struct Plan {
  bool split = false;
  std::size_t dims = 0;
  nlohmann::json spec;
  std::filesystem::path base, points;
  std::string file;                 // as the spec names it
  std::vector<std::size_t> counts;  // --grid
  io::internal::NpyHeader header;
  io::internal::NpyDtype dtype;
  bool approximate = false;  // an approximate spec (dims 2), its options:
  SurfaceApproximationOptions approx;
};
Plan plan_of(const Request& r, const Team& team);

/// INTERPATCH_MPI_TIMINGS=1: each process prints one line, after the output is in
/// place, of the seconds each stage took and the bytes it sent to other processes
/// (docs/BENCHMARKS.md, "Split between MPI processes").
class Stages {
 public:
  explicit Stages(int rank);
  void done(const char* stage, std::uint64_t sent = 0);
  void print() const;

 private:
  int rank_;
  bool on_;
  double t_;
  std::string text_;
};

/// This process's rows of the points, and the few rows of the others it looks at.
template <std::size_t D>
using Held = detail::HeldRows<D, std::vector<Vec3>>;
template <std::size_t D>
Held<D> read_block(const Plan& plan, const Team& team);

/// The rows of the output a process writes ({first, count}) and the control rows
/// they need, [lo, hi] (past the end around a periodic u): for build an even share of
/// the N control rows, for eval those of its share of the output grid's rows.
struct OutputRows {
  io::Resolution grid{};
  std::vector<double> us;
  std::size_t first = 0, count = 0;
  long long lo = 0, hi = -1;
  [[nodiscard]] std::size_t window() const { return hi >= lo ? static_cast<std::size_t>(hi - lo + 1) : 0; }
};
/// `type` names the spec's type in messages.
template <std::size_t D>
OutputRows output_rows(const Request& r, const Plan& plan, const Team& team, const KnotVector& ku, std::size_t N,
                       const char* type);

/// Writes the output from control rows [o.lo, o.lo + window) (around a periodic u)
/// of a net of `net_shape` points: build writes this process's even share of the
/// rows into the archive, eval its rows of the output grid, evaluated.
template <std::size_t D>
void write_output(const Request& r, const Team& team, const std::vector<int>& degrees,
                  const std::vector<KnotVector>& knots, const std::vector<std::size_t>& net_shape,
                  const std::vector<Vec3>& cp, const OutputRows& o, std::size_t window, Stages& stages);

/// The split runs: a grid interpolation (surface or volume), an approximation.
template <std::size_t D>
int interpolate_run(const Request& r, const Plan& plan, const Team& team);
int approximate_run(const Request& r, const Plan& plan, const Team& team);

/// The warnings of the spec's reading, printed once (rank 0).
void print_warnings(const std::vector<std::string>& warnings, const Team& team);

}  // namespace interpatch::mpi
