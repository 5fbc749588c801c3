#include "exit_status.hpp"

#include <gtest/gtest.h>

namespace interpatch {
namespace {

// The command line's contract (docs/spec-format.md, "Exit statuses"): 3 invalid
// input, 4 files, 5 too large, 1 anything else — for every code there is.
TEST(CliExitStatus, FollowsTheCommandLineContract) {
  for (int i = 0; i <= static_cast<int>(errc::internal); ++i) {
    const auto c = static_cast<errc>(i);
    const int expected = c == errc::file_unreadable || c == errc::file_unwritable ? 4
                         : c == errc::too_large                                    ? 5
                         : c == errc::internal                                     ? 1
                                                                                   : 3;
    EXPECT_EQ(cli::exit_status(c), expected) << to_string(c);
  }
  EXPECT_EQ(cli::exit_status(errc::zero_chord), 3);
  EXPECT_EQ(cli::exit_status(errc::file_unwritable), 4);
}

}  // namespace
}  // namespace interpatch
