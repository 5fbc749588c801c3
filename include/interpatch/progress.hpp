#pragma once
/// @file progress.hpp
/// Progress reports from long work. The library never prints; a caller that wants
/// to show progress passes a callback.

#include <functional>

namespace interpatch {

/// Called with the fraction of the work done, 0..1, from the calling thread. It may
/// throw to stop the work (the Python module does when Ctrl-C is pressed): the work
/// stops at its next report, makes no result, and the exception propagates to the
/// caller unchanged.
using progress_callback = std::function<void(double)>;

}  // namespace interpatch
