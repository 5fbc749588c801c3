#pragma once
// Sums of many terms in four interleaved partial sums: a fixed order (the same bits on
// every run and any number of threads) without one long chain of dependent additions.

#include <cstddef>

namespace interpatch::detail {

/// Σ a[i], i < n.
inline double interleaved_sum(const double* a, std::size_t n) {
  double s[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (std::size_t j = 0; j < 4; ++j) s[j] += a[i + j];
  for (; i < n; ++i) s[0] += a[i];
  return (s[0] + s[1]) + (s[2] + s[3]);
}

/// Σ a[i] b[i], i < n.
inline double interleaved_dot(const double* a, const double* b, std::size_t n) {
  double s[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (std::size_t j = 0; j < 4; ++j) s[j] += a[i + j] * b[i + j];
  for (; i < n; ++i) s[0] += a[i] * b[i];
  return (s[0] + s[1]) + (s[2] + s[3]);
}

}  // namespace interpatch::detail
