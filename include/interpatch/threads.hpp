#pragma once
/// @file threads.hpp
/// Where interpatch's threads run.

namespace interpatch {

/// Gives each thread of interpatch's parallel loops a CPU of its own for the rest
/// of the process: the calling thread keeps the CPU it is on, the others take the
/// next CPUs the process may use. Call it once, early, from the thread that will
/// call interpatch (the interpatch command does it at start).
///
/// Why: OpenMP starts its second thread on the CPU of the first, and a first thread
/// that spins while it waits keeps it from running until the scheduler moves it,
/// 5–10 ms on a virtual machine; the same can happen whenever a sleeping thread is
/// woken. Bound threads start and wake on their own CPUs, and every parallel loop
/// starts in microseconds.
///
/// Does nothing, and returns false, when the user binds threads already
/// (OMP_PROC_BIND, OMP_PLACES or GOMP_CPU_AFFINITY set; OMP_PROC_BIND=false turns
/// this off), with one thread, when there are more threads than CPUs, and in builds
/// without OpenMP. Returns true when every thread was bound.
///
/// Example:
/// @code
///   int main() {
///     interpatch::bind_threads();  // first, before any of interpatch's parallel loops
///     return run();                // the program's work: interpolate_surface(...), ...
///   }
/// @endcode
bool bind_threads() noexcept;

}  // namespace interpatch
