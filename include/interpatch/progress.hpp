#pragma once
/// @file progress.hpp
/// Progress reports from long work. The library never prints; a caller that wants
/// to show progress passes a callback.

#include <functional>

namespace interpatch {

/// Called with the fraction of the work done, 0..1, from the calling thread; it
/// must not throw (it may run inside a parallel region).
using progress_callback = std::function<void(double)>;

}  // namespace interpatch
