#pragma once
// When work is split across threads. Starting OpenMP's second thread costs a few
// milliseconds on the machines interpatch is measured on (2.5–25 ms seen), so
// loops smaller than this many multiply-adds stay on the calling thread. Threads
// never change a result: every number is computed by the same operations.

#include <cstddef>

namespace interpatch::detail {

inline constexpr std::size_t parallel_min_work = std::size_t{1} << 18;

}  // namespace interpatch::detail
