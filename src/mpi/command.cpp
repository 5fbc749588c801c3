// The MPI module's entry point (loaded by the command under an MPI launcher), the
// choice between the split runs and rank 0 alone, and the runs' timings.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>

#include "base/text.hpp"
#include "exit_status.hpp"
#include "mpi/driver.hpp"

namespace interpatch::mpi {

using detail::cat;

namespace {

// A peer's failure carries the status of the process that failed first.
int status_of(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const detail::peer_failure& p) {
    return p.status;
  } catch (...) {
    return cli::exit_status(e);
  }
}

// The process's peak resident memory so far (VmHWM), MiB.
long peak_mib() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6) / 1024;
  return -1;
}

double clock_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

Stages::Stages(int rank) : rank_(rank), on_(std::getenv("INTERPATCH_MPI_TIMINGS") != nullptr), t_(clock_seconds()) {}

void Stages::done(const char* stage, std::uint64_t sent) {
  if (!on_) return;
  const double now = clock_seconds();
  text_ += cat(text_.empty() ? "" : ", ", "\"", stage, "\": [", now - t_, ", ", sent, ", ", peak_mib(), "]");
  t_ = now;
}

void Stages::print() const {
  if (on_) std::fprintf(stderr, "interpatch: rank %d stages (seconds, bytes sent, peak MiB so far): {%s}\n", rank_, text_.c_str());
}

void print_warnings(const std::vector<std::string>& warnings, const Team& team) {
  if (team.rank() == 0)
    for (const std::string& w : warnings) std::fprintf(stderr, "interpatch: warning: %s\n", w.c_str());
}

int run_command(const Request& request, const std::function<int()>& single) {
  const Session session;
  const Team team(status_of);
  try {
    Plan plan;
    team.run([&] { plan = plan_of(request, team); });
    int split[1] = {plan.split ? 1 : 0};
    {
      std::size_t s[1] = {static_cast<std::size_t>(split[0])};
      team.min(s);
      split[0] = static_cast<int>(s[0]);
    }
    if (split[0] == 0) return team.await(team.rank() == 0 ? single() : 0);
    if (plan.approximate) return approximate_run(request, plan, team);
    return plan.dims == 3 ? interpolate_run<3>(request, plan, team) : interpolate_run<2>(request, plan, team);
  } catch (const detail::peer_failure& p) {
    return p.status;
  } catch (...) {
    return cli::report_failure(std::current_exception());
  }
}

}  // namespace interpatch::mpi

/// The module's entry point, looked up by name by the command (cli/mpi_command.hpp
/// declares the same signature): the request in plain types, so that neither side
/// needs the other's headers.
extern "C" int interpatch_mpi_command(bool build, const char* spec, const char* shape, const char* out, const char* grid,
                                      const std::function<int()>* single) {
  return interpatch::mpi::run_command({build, spec, shape, out, grid}, *single);
}
