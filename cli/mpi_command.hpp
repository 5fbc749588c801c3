#pragma once
// `interpatch eval` and `interpatch build` started by an MPI launcher (mpirun,
// srun): the grid interpolation split between the processes by blocks of rows
// (docs/mpi.md). Built with INTERPATCH_MPI only.

#include <functional>
#include <string>

namespace interpatch::cli {

/// Whether an MPI launcher (mpirun, mpiexec, srun with PMI or PMIx) started this
/// process: only then is MPI initialized, so that a plain run costs nothing more.
[[nodiscard]] bool mpi_launched() noexcept;
/// This process's rank as the launcher's environment gives it.
[[nodiscard]] int mpi_launched_rank() noexcept;

/// What the command line asked for.
struct MpiRequest {
  bool build = false;  ///< build (else eval)
  std::string spec, shape, out, grid;
};

/// Runs the request on every process of MPI_COMM_WORLD (MPI initialized and
/// finalized here) and returns this process's exit status, the same on every
/// process; exactly one process prints the one error line. What the split run does
/// not cover (other types, points not in an .npy file, other output formats) runs
/// as `single` on rank 0 alone, the others waiting for its status.
int mpi_command(const MpiRequest& request, const std::function<int()>& single);

}  // namespace interpatch::cli
