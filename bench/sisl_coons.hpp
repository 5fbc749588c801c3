#pragma once
// SISL's Coons patch from four boundary point lists, built as a user of SISL builds
// it: each list interpolated by a cubic B-spline curve at its chord parameters
// (s1357), then the patch of the four curves (s1390). bench/compare's in-library
// `coons` job and bench/sisl_eval's whole process (`--coons`) time the same calls.

#include <sisl.h>

#include <array>
#include <cstddef>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "grid_params.hpp"

namespace interpatch::bench {

inline void sisl_check(int stat, const char* what) {
  if (stat < 0) throw std::runtime_error(std::string(what) + " failed with status " + std::to_string(stat));
}

// The cubic through n points (3 n coordinates) at their chord parameters, which are
// returned in `params`: s1357, open, no end conditions. Freed with freeCurve.
inline SISLCurve* sisl_interpolate_curve(const double* xyz, std::size_t n, std::vector<double>& params) {
  params = chord_parameters(xyz, n);
  std::vector<double> points(xyz, xyz + 3 * n);  // s1357 takes non-const arrays
  std::vector<int> types(n, 1);
  SISLCurve* c = nullptr;
  double* gpar = nullptr;
  double end = 0;
  int npar = 0, stat = 0;
  s1357(points.data(), static_cast<int>(n), 3, types.data(), params.data(), 0, 0, 1, 4, 0.0, &end, &c, &gpar, &npar,
        &stat);
  std::free(gpar);
  sisl_check(stat, "s1357");
  return c;
}

// s1390's patch of four curves given in its order around the patch: v = 0 and
// u = 1, v = 1, u = 0, each running with its parameter (v = 0 and v = 1 along u,
// u = 1 and u = 0 along v). The surface's first parameter is u. Freed with freeSurf.
inline SISLSurf* sisl_coons_patch(const std::array<SISLCurve*, 4>& around) {
  SISLCurve* curves[4] = {around[0], around[1], around[2], around[3]};
  int nder[4] = {1, 1, 1, 1}, stat = 0;
  SISLSurf* s = nullptr;
  s1390(curves, &s, nder, &stat);
  sisl_check(stat, "s1390");
  return s;
}

}  // namespace interpatch::bench
