#pragma once
// The exit status of the interpatch command for each error code (docs/spec-format.md,
// "Exit statuses"): 3 for invalid input, 4 for files that cannot be read or written,
// 5 for work too large for this machine, 1 for anything else. The library only
// names what is wrong; how a process reports it is the command's business.

#include <exception>
#include <string>

#include "interpatch/error.hpp"

namespace interpatch::cli {

constexpr int exit_status(errc code) noexcept {
  switch (code) {
    case errc::file_unreadable:
    case errc::file_unwritable: return 4;
    case errc::too_large: return 5;
    case errc::internal: return 1;
    default: return 3;
  }
}

/// The exit status of a failure: exit_status(code) for an interpatch::error, 2 for a
/// usage_error, 5 for std::bad_alloc, 1 for anything else.
int exit_status(const std::exception_ptr& failure) noexcept;

/// Print `message` as the one error line, "interpatch: <message>" on stderr (line
/// breaks made spaces, whatever the message holds), and return `status`.
int fail_with(int status, std::string message);

/// Print the failure's one error line ("out of memory" for std::bad_alloc) and
/// return its exit status. The single process and the split run (src/mpi/command.cpp)
/// both report through here, so they fail alike.
int report_failure(const std::exception_ptr& failure);

}  // namespace interpatch::cli
