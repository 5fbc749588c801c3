#pragma once
// Chord-length parameters computed by plain code over raw coordinates, as a user of
// a C library that takes parameters (SISL's s1357/s1537) computes them. The same
// definition as interpatch's: each line of points gets chord parameters, lines of
// zero length are left out, the rest are averaged. Used by bench/compare and
// bench/sisl_eval; compare checks them against interpatch::grid_parameters.

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace interpatch::bench {

inline double distance3(const double* a, const double* b) {
  const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Parameters in [0, 1] of n points xyz[3 * stride * k], first 0, last 1.
inline std::vector<double> chord_parameters(const double* xyz, std::size_t n, std::size_t stride = 1) {
  std::vector<double> t(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) t[k] = t[k - 1] + distance3(xyz + 3 * stride * (k - 1), xyz + 3 * stride * k);
  const double total = t[n - 1];
  if (!(total > 0)) throw std::runtime_error("chord_parameters: a polyline of zero length");
  for (double& x : t) x /= total;
  t[n - 1] = 1.0;
  return t;
}

// Averaged chord parameters of an nu x nv grid of points (C order, u index slowest)
// along axis 0 (u: lines of fixed v) or 1 (v: lines of fixed u).
inline std::vector<double> averaged_chord_parameters(const double* xyz, std::size_t nu, std::size_t nv, int axis) {
  std::vector<double> t(axis == 0 ? nu : nv, 0.0);
  std::size_t lines = 0;
  if (axis == 1) {
    // Each line is a contiguous row: one pass.
    std::vector<double> cum(nv);
    for (std::size_t i = 0; i < nu; ++i) {
      const double* row = xyz + 3 * nv * i;
      cum[0] = 0;
      for (std::size_t j = 1; j < nv; ++j) cum[j] = cum[j - 1] + distance3(row + 3 * (j - 1), row + 3 * j);
      if (!(cum[nv - 1] > 0)) continue;
      const double inv = 1.0 / cum[nv - 1];
      for (std::size_t j = 1; j < nv; ++j) t[j] += cum[j] * inv;
      ++lines;
    }
  } else {
    // Lines run across rows: the line lengths first, then the normalized chords,
    // both passes reading the grid row by row.
    std::vector<double> length(nv, 0.0), cum(nv, 0.0);
    for (std::size_t i = 1; i < nu; ++i)
      for (std::size_t j = 0; j < nv; ++j) length[j] += distance3(xyz + 3 * (nv * (i - 1) + j), xyz + 3 * (nv * i + j));
    std::vector<double> inv(nv, 0.0);
    for (std::size_t j = 0; j < nv; ++j)
      if (length[j] > 0) {
        inv[j] = 1.0 / length[j];
        ++lines;
      }
    for (std::size_t i = 1; i < nu; ++i) {
      double sum = 0;
      for (std::size_t j = 0; j < nv; ++j) {
        cum[j] += distance3(xyz + 3 * (nv * (i - 1) + j), xyz + 3 * (nv * i + j));
        sum += cum[j] * inv[j];
      }
      t[i] = sum;
    }
  }
  if (lines == 0) throw std::runtime_error("averaged_chord_parameters: every line has zero length");
  for (double& x : t) x /= static_cast<double>(lines);
  t.front() = 0.0;
  t.back() = 1.0;
  return t;
}

}  // namespace interpatch::bench
