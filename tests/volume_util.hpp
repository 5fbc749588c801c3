#pragma once
// Test helpers for volume constructions: random smooth B-spline volumes and the exact
// surfaces on them (faces and cross-derivative fields), so that consistent boundary
// data come with a volume to compare against.

#include <algorithm>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/volume_patches.hpp"
#include "test_util.hpp"

namespace interpatch::test {

/// Clamped knots over [0, 1] of degree p for n basis functions, random interior knots.
inline KnotVector random_knots(std::mt19937_64& g, int p, std::size_t n) {
  std::vector<double> u(static_cast<std::size_t>(p + 1), 0.0), in;
  for (std::size_t i = 0; i + static_cast<std::size_t>(p) + 1 < n; ++i) in.push_back(uniform(g, 0.1, 0.9));
  std::sort(in.begin(), in.end());
  u.insert(u.end(), in.begin(), in.end());
  u.insert(u.end(), static_cast<std::size_t>(p + 1), 1.0);
  return KnotVector(p, u);
}

/// A random B-spline volume over [0,1]³, degrees (p, q, r), nu × nv × nw control points
/// near the grid (i, j, k); with `rational`, weights in [0.5, 2].
inline BSplineVolume random_bspline_volume(std::mt19937_64& g, int p, int q, int r, std::size_t nu, std::size_t nv,
                                           std::size_t nw, double noise = 0.3, bool rational = false) {
  const KnotVector ku = random_knots(g, p, nu), kv = random_knots(g, q, nv), kw = random_knots(g, r, nw);
  PointGrid3 cp({nu, nv, nw});
  Grid<double, 3> w;
  if (rational) w = Grid<double, 3>({nu, nv, nw});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      for (std::size_t k = 0; k < nw; ++k) {
        cp(i, j, k) = Vec3{static_cast<double>(i), static_cast<double>(j), static_cast<double>(k)} + random_point(g, noise);
        if (rational) w(i, j, k) = uniform(g, 0.5, 2.0);
      }
  return BSplineVolume(ku, kv, kw, cp, w);
}

/// ∂^k S/∂t_axis^k on the face t_axis = t as a B-spline surface in the other two
/// parameters, in increasing order (axis 0: (v, w), 1: (u, w), 2: (u, v)). Exact for
/// polynomial volumes and any k; for rational volumes exact with k = 0 (the face keeps
/// the contracted weights).
inline BSplineSurface iso_surface(const BSplineVolume& b, int axis, double t, int k = 0) {
  const std::array<const KnotVector*, 3> ks{&b.knots_u(), &b.knots_v(), &b.knots_w()};
  const auto a = static_cast<std::size_t>(axis);
  const std::size_t o0 = axis == 0 ? 1 : 0, o1 = axis == 2 ? 1 : 2;
  const KnotVector& across = *ks[a];
  const int p = across.degree();
  const int span = across.find_span(t);
  double d[(max_degree + 1) * (max_degree + 1)];
  across.basis_derivatives(span, t, k, d);
  const auto& cp = b.control_points();
  const std::size_t n0 = cp.extent(o0), n1 = cp.extent(o1);
  PointGrid P({n0, n1});
  Grid<double, 2> W;
  if (b.rational()) W = Grid<double, 2>({n0, n1});
  for (std::size_t x = 0; x < n0; ++x)
    for (std::size_t y = 0; y < n1; ++y) {
      Vec3 s{};
      double ws = 0;
      for (int e = 0; e <= p; ++e) {
        std::array<std::size_t, 3> i{};
        i[a] = static_cast<std::size_t>(span - p + e);
        i[o0] = x;
        i[o1] = y;
        const double w = b.rational() ? b.weights()(i[0], i[1], i[2]) : 1.0;
        s += (d[k * (p + 1) + e] * w) * cp(i[0], i[1], i[2]);
        ws += d[k * (p + 1) + e] * w;
      }
      P(x, y) = b.rational() ? s / ws : s;
      if (b.rational()) W(x, y) = ws;
    }
  return BSplineSurface(*ks[o0], *ks[o1], P, W);
}

/// The six faces of a volume over [0,1]³, as a transfinite volume takes them.
inline VolumeFaces faces_of(const BSplineVolume& b) {
  return {iso_surface(b, 0, 0), iso_surface(b, 0, 1), iso_surface(b, 1, 0),
          iso_surface(b, 1, 1), iso_surface(b, 2, 0), iso_surface(b, 2, 1)};
}

/// Largest distance between two volumes on an n × n × n grid over [0,1]³.
inline double max_distance(const Volume& a, const Volume& b, std::size_t n = 11) {
  const auto t = linspace(0, 1, n);
  double e = 0;
  for (double u : t)
    for (double v : t)
      for (double w : t) e = std::max(e, distance(a.point(u, v, w), b.point(u, v, w)));
  return e;
}

/// Diagonal of the bounding box of a volume's control points: the scale of its tolerances.
inline double scale_of(const BSplineVolume& b) { return bbox_diagonal(b.control_points().values()); }

/// Central differences of S along each parameter with step h, clamped one-sided at the domain ends.
inline VolumeDerivatives finite_differences(const Volume& s, double u, double v, double w, double h = 1e-5) {
  const double x[3] = {u, v, w};
  VolumeDerivatives d{s.point(u, v, w), {}, {}, {}};
  Vec3* out[3] = {&d.su, &d.sv, &d.sw};
  const auto dom = s.domain();
  for (int a = 0; a < 3; ++a) {
    double lo[3] = {u, v, w}, hi[3] = {u, v, w};
    lo[a] = std::max(dom[static_cast<std::size_t>(a)].first, x[a] - h);
    hi[a] = std::min(dom[static_cast<std::size_t>(a)].second, x[a] + h);
    *out[a] = (s.point(hi[0], hi[1], hi[2]) - s.point(lo[0], lo[1], lo[2])) / (hi[a] - lo[a]);
  }
  return d;
}

// The point frame of a volume: its corner positions and partial derivatives.
inline std::array<HermiteVolumeCorner, 8> frame_of(const BSplineVolume& b) {
  std::array<HermiteVolumeCorner, 8> c;
  for (std::size_t n = 0; n < 8; ++n) {
    const double u = static_cast<double>(n >> 2), v = static_cast<double>((n >> 1) & 1), w = static_cast<double>(n & 1);
    c[n] = {b.derivative(u, v, w, 0, 0, 0), b.derivative(u, v, w, 1, 0, 0), b.derivative(u, v, w, 0, 1, 0),
            b.derivative(u, v, w, 0, 0, 1), b.derivative(u, v, w, 1, 1, 0), b.derivative(u, v, w, 1, 0, 1),
            b.derivative(u, v, w, 0, 1, 1), b.derivative(u, v, w, 1, 1, 1)};
  }
  return c;
}

}  // namespace interpatch::test
