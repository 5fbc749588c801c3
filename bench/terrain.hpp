#pragma once
// What the Google Benchmark program and bench/compare share, so that both time the
// same thing: the data, an n x n jittered terrain with the same points in every run
// on every machine, and the memory-bandwidth baseline, a memcpy.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numbers>

#include "interpatch/grid.hpp"

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace interpatch::bench {

// Deterministic noise in [-0.5, 0.5): the splitmix64 finalizer of the point index.
inline double noise(std::size_t i, std::size_t j, std::uint64_t channel) {
  std::uint64_t z = (static_cast<std::uint64_t>(i) << 32) ^ static_cast<std::uint64_t>(j) ^ (channel << 60);
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53 - 0.5;
}

// An n x n terrain over 10 km x 10 km: rolling hills of a few hundred metres, the
// plan positions jittered by up to ±10 % of the spacing (neighbours never coincide)
// and the heights by ±0.25 m, as in a measured survey. First index along u (x).
inline PointGrid make_terrain(std::size_t n) {
  PointGrid g({n, n});
  const double extent = 10000.0, h = extent / static_cast<double>(n - 1);
  constexpr double tau = 2 * std::numbers::pi;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double s = static_cast<double>(i) / static_cast<double>(n - 1);
      const double t = static_cast<double>(j) / static_cast<double>(n - 1);
      const double z = 120 * std::sin(tau * 1.3 * s) * std::cos(tau * 0.7 * t) +
                       40 * std::sin(tau * (3.1 * s + 2.3 * t)) + 15 * std::cos(tau * 7.9 * s * t) +
                       0.5 * noise(i, j, 2);
      g(i, j) = {static_cast<double>(i) * h + 0.2 * h * noise(i, j, 0),
                 static_cast<double>(j) * h + 0.2 * h * noise(i, j, 1), z};
    }
  return g;
}

// Copies with every OpenMP thread (each its own contiguous share), or with one: the
// bandwidth limit the library's two-core work is held against.
inline void copy_bytes(std::byte* dst, const std::byte* src, std::size_t bytes, bool threaded) {
#if defined(_OPENMP)
  if (threaded) {
#pragma omp parallel
    {
      const auto t = static_cast<std::size_t>(omp_get_thread_num());
      const auto nt = static_cast<std::size_t>(omp_get_num_threads());
      const std::size_t a = bytes / nt * t, b = t + 1 == nt ? bytes : bytes / nt * (t + 1);
      std::memcpy(dst + a, src + a, b - a);
    }
    return;
  }
#endif
  static_cast<void>(threaded);
  std::memcpy(dst, src, bytes);
}

}  // namespace interpatch::bench
