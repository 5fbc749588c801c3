#pragma once
// The exit status of the interpatch command for each error code (docs/spec-format.md,
// "Exit statuses"): 3 for invalid input, 4 for files that cannot be read or written,
// 5 for work too large for this machine, 1 for anything else. The library only
// names what is wrong; how a process reports it is the command's business.

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

}  // namespace interpatch::cli
