#pragma once
// Every value an output file carries is finite: a construction whose arithmetic left
// the range of a double (corners near ±1e308 whose differences overflow, weights so
// small that a rational form divides 0 by 0) is refused before its file is written,
// never written with NaN or infinity in it.

#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>

#include "base/parallel.hpp"
#include "base/text.hpp"

namespace interpatch::io::internal {

/// Throws not_finite naming the first value of v[0..n) that is NaN or infinite, by its
/// index [i, j, ...] in an array of `shape` whose value `first` is v[0]; `what` names
/// the values ("'out.npy'", "the normals of 'm.vts'").
inline void require_finite(const double* v, std::size_t n, std::size_t first, std::span<const std::size_t> shape,
                           std::string_view what) {
  if (!interpatch::detail::has_non_finite(v, n)) return;
  std::size_t k = 0;
  while (std::isfinite(v[k])) ++k;
  std::size_t at = first + k;
  std::string index;
  for (std::size_t a = shape.size(); a-- > 0;) {
    const std::size_t extent = shape[a] == 0 ? 1 : shape[a];
    index = std::to_string(at % extent) + (index.empty() ? "" : ", ") + index;
    at /= extent;
  }
  interpatch::detail::fail(errc::not_finite, what, ": the value at [", index, "] is ", v[k],
               ": the construction's arithmetic left the range of a double there (coordinates near 1e308, "
               "or weights so small they vanish); nothing was written");
}

}  // namespace interpatch::io::internal
