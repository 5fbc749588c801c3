#pragma once
// Closed (periodic) B-spline surfaces and volumes built by hand for the writers'
// tests: control nets around a torus, uneven knots, optional weights.

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "test_util.hpp"

namespace interpatch::test {

/// The knots of one direction, n control points of degree p over [a, b]: periodic
/// (n knots of one period, uneven, the third one doubled when `doubled`) or clamped
/// (uniform).
inline KnotVector closed_shape_knots(std::mt19937_64& g, bool periodic, int p, int n, double a, double b,
                                     bool doubled = false) {
  if (!periodic) return KnotVector::uniform(p, n, a, b);
  std::vector<double> gaps;
  for (int i = 0; i < n; ++i) gaps.push_back(uniform(g, 0.5, 1.5));
  if (doubled) gaps[2] = 0;
  double total = 0;
  for (const double d : gaps) total += d;
  std::vector<double> knots;
  double at = 0;
  for (int i = 0; i < n; ++i) {
    knots.push_back(a + (b - a) * at / total);
    at += gaps[static_cast<std::size_t>(i)];
  }
  return KnotVector::periodic_from(p, std::move(knots), b);
}

/// The angle of control point i of n: a whole turn shared by n points when the
/// direction is periodic, three quarters of a turn from end to end when it is open.
inline double closed_shape_angle(bool periodic, std::size_t i, std::size_t n) {
  const double t = static_cast<double>(i);
  return periodic ? 2 * std::numbers::pi * t / static_cast<double>(n)
                  : 1.5 * std::numbers::pi * t / static_cast<double>(n - 1);
}

/// A point of the torus of radii 3 (about the z axis, angle a) and r (about the
/// tube, angle t).
inline Vec3 torus_point(double a, double t, double r) {
  const double rho = 3 + r * std::cos(t);
  return {rho * std::cos(a), rho * std::sin(a), r * std::sin(t)};
}

/// A surface about a torus: u about the z axis (cubic, 9 control points, over
/// [0, 1]), v about the tube (quadratic, 7 control points, over [0.5, 2.5]), each
/// direction closed when `periodic` says so and three quarters of a turn otherwise.
/// Control points moved off the torus by up to 0.1; `seed` also picks uneven
/// periodic knots, a doubled knot (odd seeds) and weights in [0.5, 2] (`rational`).
inline BSplineSurface closed_surface(std::array<bool, 2> periodic, unsigned seed, bool rational = false) {
  auto g = rng(seed);
  const std::size_t n = 9, m = 7;
  const KnotVector ku = closed_shape_knots(g, periodic[0], 3, n, 0.0, 1.0, seed % 2 == 1);
  const KnotVector kv = closed_shape_knots(g, periodic[1], 2, m, 0.5, 2.5);
  PointGrid cp({n, m});
  Grid<double, 2> w = rational ? Grid<double, 2>({n, m}) : Grid<double, 2>();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      cp(i, j) = torus_point(closed_shape_angle(periodic[0], i, n), closed_shape_angle(periodic[1], j, m), 1.0) +
                 random_point(g, 0.1);
      if (rational) w(i, j) = uniform(g, 0.5, 2.0);
    }
  return BSplineSurface(ku, kv, std::move(cp), std::move(w));
}

/// A thick torus shell: u about the z axis (cubic, 8 control points), v about the
/// tube (cubic, 6), w across the wall from tube radius 0.5 to 1 (linear), all over
/// [0, 1]; u and v closed when `periodic` says so, three quarters of a turn
/// otherwise. Right-handed (det J > 0) for every choice.
inline BSplineVolume closed_volume(std::array<bool, 2> periodic, unsigned seed) {
  auto g = rng(seed);
  const std::size_t n = 8, m = 6;
  const KnotVector ku = closed_shape_knots(g, periodic[0], 3, n, 0.0, 1.0);
  const KnotVector kv = closed_shape_knots(g, periodic[1], 3, m, 0.0, 1.0);
  PointGrid3 cp({n, m, 2});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j)
      for (std::size_t k = 0; k < 2; ++k)
        cp(i, j, k) = torus_point(closed_shape_angle(periodic[0], i, n), closed_shape_angle(periodic[1], j, m),
                                  k == 0 ? 0.5 : 1.0) +
                      random_point(g, 0.05);
  return BSplineVolume(ku, kv, KnotVector::bezier(1), std::move(cp));
}

/// A volume closed in u, v and w (linear, two control points each way): it has no
/// boundary at all.
inline BSplineVolume volume_closed_everywhere() {
  const KnotVector k = KnotVector::periodic_from(1, {0, 0.5}, 1);
  PointGrid3 cp({2, 2, 2});
  for (std::size_t i = 0; i < 8; ++i) cp.data()[i] = {double(i / 4), double(i / 2 % 2), double(i % 2)};
  return BSplineVolume(k, k, k, std::move(cp));
}

}  // namespace interpatch::test
