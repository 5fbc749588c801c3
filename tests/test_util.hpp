#pragma once
// Shared helpers for interpatch tests: seeded random data and error-code checks.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "interpatch/error.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::test {

/// Fixed seeds: failures reproduce exactly.
inline std::mt19937_64 rng(unsigned seed) { return std::mt19937_64(0x1f2e3d4c5b6a7988ULL + seed); }

inline double uniform(std::mt19937_64& g, double a = -1.0, double b = 1.0) {
  return std::uniform_real_distribution<double>(a, b)(g);
}

inline Vec3 random_point(std::mt19937_64& g, double scale = 1.0) {
  return {scale * uniform(g), scale * uniform(g), scale * uniform(g)};
}

/// Points marching along x with noise below half the spacing: never coincident.
inline std::vector<Vec3> random_polyline(std::mt19937_64& g, std::size_t n, double noise) {
  std::vector<Vec3> q;
  for (std::size_t i = 0; i < n; ++i) q.push_back(Vec3{static_cast<double>(i), 0, 0} + random_point(g, noise));
  return q;
}

/// A smooth random-ish grid: a perturbed plane, never with coincident neighbours.
inline PointGrid random_grid(std::mt19937_64& g, std::size_t nu, std::size_t nv, double noise = 0.3) {
  PointGrid q({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      q(i, j) = Vec3{static_cast<double>(i), static_cast<double>(j), 0.0} + random_point(g, noise);
  return q;
}

/// Diagonal of the bounding box of a set of points: the scale tolerances are relative to.
template <class Range>
double bbox_diagonal(const Range& pts) {
  constexpr double inf = std::numeric_limits<double>::infinity();  // data may lie beyond 1e300
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (const Vec3& p : pts)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  return norm(hi - lo);
}

}  // namespace interpatch::test

/// Asserts that `stmt` throws interpatch::error with the given errc and a message
/// containing `fragment`.
#define EXPECT_ERRC(stmt, errcode, fragment)                                                        \
  do {                                                                                           \
    try {                                                                                        \
      stmt;                                                                                      \
      ADD_FAILURE() << "expected interpatch::error " #errcode;                                      \
    } catch (const interpatch::error& e_) {                                                      \
      EXPECT_EQ(e_.code(), interpatch::errc::errcode) << e_.what();                                 \
      EXPECT_NE(std::string(e_.what()).find(fragment), std::string::npos)                        \
          << "message '" << e_.what() << "' lacks '" << fragment << "'";                         \
    }                                                                                            \
  } while (0)
