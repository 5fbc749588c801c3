#pragma once
// Smooth shapes with closed forms, for bench/compare's whole-process jobs. The data
// of each job are sampled from one of them, and each is a shape its construction
// reproduces (up to the error of interpolating the data), so that every point a
// program writes can be checked against the closed form, whatever parameters the
// program used.

#include <array>
#include <cmath>
#include <numbers>

#include "interpatch/vec3.hpp"

namespace interpatch::bench {

inline constexpr double two_pi = 2 * std::numbers::pi;

// S(u, v) = (L u, L v, f(u) + g(v) + p(u) q(v)) over [0, 1]², a graph over the
// square, p a cubic. Without the product term it is a translation surface
// A(u) + B(v): a linear Coons patch of its boundary and a network of its curves
// (Gordon or Coons) reproduce it, whatever the curves' parameters as long as
// opposite curves share them (translates of one another do, chord parameters
// included). With it, a Coons patch with cross-boundary derivatives still reproduces
// it: the cubic Hermite projector along u reproduces whatever is cubic in u.
struct GraphSurface {
  static constexpr double L = 1000;
  bool product = false;

  static double f(double u) { return 60 * std::sin(two_pi * 1.3 * u); }
  static double df(double u) { return 60 * two_pi * 1.3 * std::cos(two_pi * 1.3 * u); }
  static double g(double v) { return 40 * std::cos(two_pi * 0.9 * v) + 25 * std::sin(two_pi * 2.1 * v); }
  static double dg(double v) { return -40 * two_pi * 0.9 * std::sin(two_pi * 0.9 * v) + 25 * two_pi * 2.1 * std::cos(two_pi * 2.1 * v); }
  static double p(double u) { return 80 * u * (1 - u) * (u - 0.3); }
  static double dp(double u) { return 80 * (-3 * u * u + 2.6 * u - 0.3); }
  static double q(double v) { return std::sin(two_pi * 1.7 * v); }
  static double dq(double v) { return two_pi * 1.7 * std::cos(two_pi * 1.7 * v); }

  [[nodiscard]] double height(double u, double v) const { return f(u) + g(v) + (product ? p(u) * q(v) : 0.0); }
  [[nodiscard]] Vec3 point(double u, double v) const { return {L * u, L * v, height(u, v)}; }
  [[nodiscard]] Vec3 du(double u, double v) const { return {L, 0, df(u) + (product ? dp(u) * q(v) : 0.0)}; }
  [[nodiscard]] Vec3 dv(double u, double v) const { return {0, L, dg(v) + (product ? p(u) * dq(v) : 0.0)}; }
  [[nodiscard]] Vec3 duv(double u, double v) const { return {0, 0, product ? dp(u) * dq(v) : 0.0}; }

  // How far a point is from the surface along z.
  [[nodiscard]] double height_error(const double* xyz) const { return std::abs(xyz[2] - height(xyz[0] / L, xyz[1] / L)); }
  // The unit normal, along S_u × S_v, at the point of the surface above (x, y).
  [[nodiscard]] Vec3 normal_above(double x, double y) const {
    const Vec3 n = cross(du(x / L, y / L), dv(x / L, y / L));
    return n / std::sqrt(dot(n, n));
  }
};

// A block twisted about its axis: S(u, v, w) = (R(θ w) (L (u − ½), L (v − ½)), H w).
// Its lines of constant (v, w) and (u, w) are straight and its lines of constant
// (u, v) helices, each run at constant speed: points sampled at equal parameter steps
// are equally spaced along every line, so chord parameters are those steps (a grid
// interpolation through them has the block's own parameters). It is linear in u, so
// a Coons volume of its six faces reproduces it.
struct TwistedBlock {
  static constexpr double L = 1000, H = 600, theta = 0.8;

  [[nodiscard]] static Vec3 point(double u, double v, double w) {
    const double x = L * (u - 0.5), y = L * (v - 0.5), c = std::cos(theta * w), s = std::sin(theta * w);
    return {c * x - s * y, s * x + c * y, H * w};
  }
};

// A polynomial map of degree at most 3 in each parameter, close to a scaled unit
// cube: the tricubic Hermite volume of its corner derivatives reproduces it.
struct TricubicMap {
  static constexpr double L = 1000;
  struct Term {
    int axis;  // the coordinate the term adds to
    double c;
    int a, b, e;  // c u^a v^b w^e
  };
  static constexpr std::array<Term, 9> terms{{{0, 1, 1, 0, 0}, {0, 0.2, 0, 1, 2}, {0, -0.1, 2, 1, 1},
                                              {1, 1, 0, 1, 0}, {1, 0.15, 3, 0, 1}, {1, 0.1, 1, 2, 3},
                                              {2, 1, 0, 0, 1}, {2, 0.1, 1, 1, 0}, {2, 0.05, 2, 2, 3}}};

  // ∂^(da+db+de) S / ∂u^da ∂v^db ∂w^de at (u, v, w).
  [[nodiscard]] static Vec3 derivative(int da, int db, int de, double u, double v, double w) {
    auto power = [](double t, int k, int d) {  // d-th derivative of t^k
      if (d > k) return 0.0;
      double c = 1;
      for (int i = 0; i < d; ++i) c *= k - i;
      return c * std::pow(t, k - d);
    };
    Vec3 s{0, 0, 0};
    for (const Term& t : terms) s[t.axis] += L * t.c * power(u, t.a, da) * power(v, t.b, db) * power(w, t.e, de);
    return s;
  }
  [[nodiscard]] static Vec3 point(double u, double v, double w) { return derivative(0, 0, 0, u, v, w); }
};

// The trilinear map of eight corners, corner (i, j, k) at index 4i + 2j + k: a
// leaning, tapered block.
struct TrilinearBlock {
  static constexpr std::array<Vec3, 8> corners{{{0, 0, 0}, {200, 0, 1000}, {0, 1000, 0}, {300, 900, 1100},
                                                {2000, 0, 0}, {1800, 100, 800}, {2000, 1200, 0}, {1900, 1100, 900}}};

  [[nodiscard]] static Vec3 point(double u, double v, double w) {
    Vec3 s{0, 0, 0};
    for (int c = 0; c < 8; ++c)
      s += corners[c] * ((c & 4 ? u : 1 - u) * (c & 2 ? v : 1 - v) * (c & 1 ? w : 1 - w));
    return s;
  }
};

}  // namespace interpatch::bench
