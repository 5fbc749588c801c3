#pragma once
// `interpatch eval` and `interpatch build` started by an MPI launcher (mpirun,
// srun): the grid interpolation split between the processes by blocks of rows
// (docs/mpi.md). Built with INTERPATCH_MPI into the module interpatch-mpi.so, which
// the command loads only when a launcher started it: a plain run does not even load
// MPI's libraries.

#include <cstdlib>
#include <functional>
#include <string>

namespace interpatch::cli {

/// Whether an MPI launcher (mpirun, mpiexec, srun with PMI or PMIx) started this
/// process: only then is MPI initialized, so that a plain run costs nothing more.
inline bool mpi_launched() noexcept {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr ||
         std::getenv("PMI_RANK") != nullptr;
}
/// This process's rank as the launcher's environment gives it.
inline int mpi_launched_rank() noexcept {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return 0;
}

/// What the command line asked for.
struct MpiRequest {
  bool build = false;  ///< build (else eval)
  std::string spec, shape, out, grid;
};

/// The module's entry point, looked up by name (interpatch_mpi_command): runs the
/// request on every process of MPI_COMM_WORLD (MPI initialized and finalized there)
/// and returns this process's exit status, the same on every process; exactly one
/// process prints the one error line. What the split run does not cover (other
/// types, points not in an .npy file, other output formats) runs as `single` on rank
/// 0 alone, the others waiting for its status. The request goes in plain types, so
/// that the module (src/mpi/command.cpp, which defines it) and the command share no
/// header.
using MpiEntry = int (*)(bool build, const char* spec, const char* shape, const char* out, const char* grid,
                         const std::function<int()>* single);

}  // namespace interpatch::cli
