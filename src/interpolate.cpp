#include "interpatch/interpolate.hpp"

#include <algorithm>
#include <cmath>

#include "detail/banded.hpp"
#include "detail/collocation.hpp"
#include "detail/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 grids are solved as arrays of doubles");

namespace {

const char* axis_name(int axis) { return axis == 0 ? "u" : (axis == 1 ? "v" : "w"); }

double step(const Vec3& a, const Vec3& b, Parametrization param) {
  const double d = distance(a, b);
  return param == Parametrization::centripetal ? std::sqrt(d) : d;
}

void check_params(std::span<const double> t, const char* what) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i])) fail(errc::not_finite, what, " ", i, " is ", t[i]);
    if (i > 0 && !(t[i] > t[i - 1]))
      fail(errc::non_increasing, what, " ", i, " = ", t[i], " is not greater than ", what, " ", i - 1, " = ", t[i - 1]);
  }
}

int resolve_degree(const std::optional<int>& degree, std::size_t count, std::size_t extra, const char* where) {
  const int p = degree ? *degree : std::min<int>(3, static_cast<int>(count + extra) - 1);
  if (p < 1 || p > max_degree) fail(errc::invalid_degree, "degree ", p, where, " is outside 1..", max_degree);
  if (count + extra < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "degree ", p, where, " needs at least ", p + 1 - static_cast<int>(extra),
         " points, got ", count);
  return p;
}

}  // namespace

std::vector<double> curve_parameters(std::span<const Vec3> points, Parametrization param) {
  const std::size_t n = points.size();
  if (n < 2) fail(errc::too_few_points, "parameters need at least 2 points, got ", n);
  for (std::size_t i = 0; i < n; ++i)
    if (!is_finite(points[i])) fail(errc::not_finite, "point ", i, " is ", points[i]);
  std::vector<double> t(n, 0.0);
  if (param == Parametrization::uniform) {
    for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / static_cast<double>(n - 1);
    t.back() = 1.0;
    return t;
  }
  double total = 0;
  for (std::size_t i = 1; i < n; ++i) total += distance(points[i], points[i - 1]);
  for (std::size_t i = 1; i < n; ++i) {
    const double d = distance(points[i], points[i - 1]);
    // Chords below 1e-14 of the polyline's length are rounding noise: the two points coincide.
    if (!(d > 1e-14 * total))
      fail(errc::zero_chord, "points ", i - 1, " and ", i, " coincide (chord ", d, ", polyline length ", total,
           "): parameters must increase");
    t[i] = t[i - 1] + step(points[i - 1], points[i], param);
  }
  const double len = t.back();
  for (std::size_t i = 1; i + 1 < n; ++i) t[i] /= len;
  t.back() = 1.0;
  return t;
}

KnotVector averaged_knots(std::span<const double> params, int degree, bool extra_start, bool extra_end) {
  const std::size_t n1 = params.size();
  const int p = degree;
  const std::size_t count = n1 + (extra_start ? 1 : 0) + (extra_end ? 1 : 0);
  if (p < 1 || p > max_degree) fail(errc::invalid_degree, "degree ", p, " is outside 1..", max_degree);
  if (count < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "degree ", p, " needs ", p + 1, " conditions, got ", count);
  check_params(params, "parameter");
  // Interior knot j is the average of p consecutive parameters (The NURBS Book eq.
  // 9.8); each end condition shifts the windows to take in the end parameter.
  const std::size_t interior = count - static_cast<std::size_t>(p) - 1;
  const std::size_t first = extra_start ? 0 : 1;
  std::vector<double> u;
  u.reserve(count + static_cast<std::size_t>(p) + 1);
  u.insert(u.end(), static_cast<std::size_t>(p) + 1, params.front());
  for (std::size_t j = 0; j < interior; ++j) {
    double s = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(p); ++i) s += params[first + j + i];
    u.push_back(s / p);
  }
  u.insert(u.end(), static_cast<std::size_t>(p) + 1, params.back());
  return KnotVector(p, std::move(u));
}

CurveInterpolation interpolate_curve(std::span<const Vec3> points, const CurveInterpolationOptions& options) {
  const std::size_t n1 = points.size();
  if (n1 < 2) fail(errc::too_few_points, "curve interpolation needs at least 2 points, got ", n1);
  for (std::size_t i = 0; i < n1; ++i)
    if (!is_finite(points[i])) fail(errc::not_finite, "point ", i, " is ", points[i]);
  const bool ds = options.start_derivative.has_value(), de = options.end_derivative.has_value();
  if (ds && !is_finite(*options.start_derivative))
    fail(errc::not_finite, "start derivative is ", *options.start_derivative);
  if (de && !is_finite(*options.end_derivative)) fail(errc::not_finite, "end derivative is ", *options.end_derivative);
  const std::size_t extra = (ds ? 1 : 0) + (de ? 1 : 0);
  const int p = resolve_degree(options.degree, n1, extra, "");
  std::vector<double> t;
  if (!options.params.empty()) {
    if (options.params.size() != n1)
      fail(errc::size_mismatch, n1, " points need ", n1, " parameters, got ", options.params.size());
    check_params(options.params, "parameter");
    t = options.params;
  } else {
    t = curve_parameters(points, options.param);
  }
  KnotVector knots = averaged_knots(t, p, ds, de);
  // Rows in the order of the control points keep the matrix banded:
  // Q_0, D_0, Q_1 .. Q_{n-1}, D_n, Q_n.
  std::vector<detail::Condition> rows;
  std::vector<Vec3> rhs;
  rows.reserve(n1 + extra);
  rhs.reserve(n1 + extra);
  for (std::size_t i = 0; i < n1; ++i) {
    if (i + 1 == n1 && de) {
      rows.push_back({t[i], 1});
      rhs.push_back(*options.end_derivative);
    }
    rows.push_back({t[i], 0});
    rhs.push_back(points[i]);
    if (i == 0 && ds) {
      rows.push_back({t[i], 1});
      rhs.push_back(*options.start_derivative);
    }
  }
  const auto lu = detail::factor_collocation(knots, rows);
  lu.solve(&rhs.data()->x, 3, 3);
  return {BSplineCurve(std::move(knots), std::move(rhs)), std::move(t)};
}

namespace {

// Parameters along the middle axis of a grid seen as outer × n × inner points in C
// order (any rank and axis): each line along the axis gets its chord parameters;
// lines of zero length (a pole) are left out; the rest are averaged in line order
// (seed 003). Every loop runs along memory.
std::vector<double> line_parameters(const Vec3* q, std::size_t outer, std::size_t n, std::size_t inner, int axis,
                                    Parametrization param) {
  if (n < 2) fail(errc::too_few_points, "a grid needs at least 2 points along ", axis_name(axis), ", got ", n);
  std::vector<double> t(n, 0.0);
  if (param == Parametrization::uniform) {
    for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / static_cast<double>(n - 1);
    t.back() = 1.0;
    return t;
  }
  const std::size_t lines = outer * inner;
  require_memory(lines, 2 * sizeof(double) + 1, detail::cat("chord lengths of the ", lines, " grid lines along ", axis_name(axis)));
  // Pass 1: each line's length. Pass 2: each line's normalized running length,
  // summed over the lines that have a length in line order.
  std::vector<double> total(lines, 0.0), cum(lines, 0.0);
  auto d = [&](std::size_t o, std::size_t k, std::size_t i) {  // step from point k-1 to k on line (o, i)
    return step(q[(o * n + k - 1) * inner + i], q[(o * n + k) * inner + i], param);
  };
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t k = 1; k < n; ++k)
      for (std::size_t i = 0; i < inner; ++i) total[o * inner + i] += d(o, k, i);
  double maxlen = 0;
  for (double L : total) maxlen = std::max(maxlen, L);
  // A line shorter than 1e-14 of the longest is a collapsed row (pole) within rounding.
  std::vector<char> used(lines);
  std::size_t nused = 0;
  for (std::size_t l = 0; l < lines; ++l) {
    used[l] = total[l] > 1e-14 * maxlen ? 1 : 0;
    nused += used[l];
  }
  if (nused == 0)
    fail(errc::zero_chord, "every line of the grid along ", axis_name(axis),
         " has zero length: all points coincide along ", axis_name(axis));
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t k = 1; k < n; ++k)
      for (std::size_t i = 0; i < inner; ++i) {
        const std::size_t l = o * inner + i;
        cum[l] += d(o, k, i);
        if (used[l]) t[k] += cum[l] / total[l];
      }
  for (std::size_t k = 1; k < n; ++k) t[k] /= static_cast<double>(nused);
  t.back() = 1.0;
  for (std::size_t k = 1; k < n; ++k)
    if (!(t[k] > t[k - 1]))
      fail(errc::zero_chord, "grid points ", k - 1, " and ", k, " along ", axis_name(axis),
           " coincide on every line (averaged parameters ", t[k - 1], " and ", t[k], ")");
  return t;
}

template <class G>
std::vector<double> grid_parameters_of(const G& q, int axis, Parametrization param) {
  const auto& shape = q.shape();
  const auto a = static_cast<std::size_t>(axis);
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= shape[x];
  for (std::size_t x = a + 1; x < shape.size(); ++x) inner *= shape[x];
  return line_parameters(q.data(), outer, shape[a], inner, axis, param);
}

}  // namespace

std::vector<double> grid_parameters(const PointGrid& q, int axis, Parametrization param) {
  return grid_parameters_of(q, axis, param);
}

std::vector<double> grid_parameters(const PointGrid3& q, int axis, Parametrization param) {
  return grid_parameters_of(q, axis, param);
}

SurfaceInterpolation interpolate_surface(PointGrid points, const SurfaceInterpolationOptions& options) {
  const std::size_t nu = points.extent(0), nv = points.extent(1);
  if (nu < 2 || nv < 2)
    fail(errc::too_few_points, "surface interpolation needs at least 2 x 2 points, got ", nu, " x ", nv);
  const Vec3* data = points.data();
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!is_finite(data[k])) fail(errc::not_finite, "point [", k / nv, "][", k % nv, "] is ", data[k]);
  const int p = resolve_degree(options.degree_u, nu, 0, " in u");
  const int q = resolve_degree(options.degree_v, nv, 0, " in v");
  if (options.progress) options.progress(0.0);
  auto tu = grid_parameters(points, 0, options.param);
  auto tv = grid_parameters(points, 1, options.param);
  KnotVector ku = averaged_knots(tu, p), kv = averaged_knots(tv, q);
  auto factor = [](const KnotVector& k, const std::vector<double>& t, const char* dir) {
    try {
      return detail::factor_collocation(k, t);
    } catch (const error& e) {
      fail(e.code(), "along ", dir, ": ", e.what());
    }
  };
  const auto lu_u = factor(ku, tu, "u");
  const auto lu_v = factor(kv, tv, "v");
  if (options.progress) options.progress(0.1);
  // Rows first (every line along u), then across (every line along v), in place:
  // the data become the control points.
  const std::size_t shape[2] = {nu, nv};
  detail::solve_along_axis(lu_u, &points.data()->x, shape, 2, 0, 3);
  if (options.progress) options.progress(0.55);
  detail::solve_along_axis(lu_v, &points.data()->x, shape, 2, 1, 3);
  if (options.progress) options.progress(1.0);
  return {BSplineSurface(std::move(ku), std::move(kv), std::move(points)), std::move(tu), std::move(tv)};
}

VolumeInterpolation interpolate_volume(PointGrid3 points, const VolumeInterpolationOptions& options) {
  const std::size_t nu = points.extent(0), nv = points.extent(1), nw = points.extent(2);
  if (nu < 2 || nv < 2 || nw < 2)
    fail(errc::too_few_points, "volume interpolation needs at least 2 x 2 x 2 points, got ", nu, " x ", nv, " x ", nw);
  const Vec3* data = points.data();
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!is_finite(data[k]))
      fail(errc::not_finite, "point [", k / (nv * nw), "][", k / nw % nv, "][", k % nw, "] is ", data[k]);
  const int p = resolve_degree(options.degree_u, nu, 0, " in u");
  const int q = resolve_degree(options.degree_v, nv, 0, " in v");
  const int r = resolve_degree(options.degree_w, nw, 0, " in w");
  if (options.progress) options.progress(0.0);
  auto tu = grid_parameters(points, 0, options.param);
  auto tv = grid_parameters(points, 1, options.param);
  auto tw = grid_parameters(points, 2, options.param);
  KnotVector ku = averaged_knots(tu, p), kv = averaged_knots(tv, q), kw = averaged_knots(tw, r);
  auto factor = [](const KnotVector& k, const std::vector<double>& t, const char* dir) {
    try {
      return detail::factor_collocation(k, t);
    } catch (const error& e) {
      fail(e.code(), "along ", dir, ": ", e.what());
    }
  };
  const auto lu_u = factor(ku, tu, "u");
  const auto lu_v = factor(kv, tv, "v");
  const auto lu_w = factor(kw, tw, "w");
  if (options.progress) options.progress(0.1);
  // Lines along u, then along v, then along w, in place: the data become the control points.
  const std::size_t shape[3] = {nu, nv, nw};
  detail::solve_along_axis(lu_u, &points.data()->x, shape, 3, 0, 3);
  if (options.progress) options.progress(0.4);
  detail::solve_along_axis(lu_v, &points.data()->x, shape, 3, 1, 3);
  if (options.progress) options.progress(0.7);
  detail::solve_along_axis(lu_w, &points.data()->x, shape, 3, 2, 3);
  if (options.progress) options.progress(1.0);
  return {BSplineVolume(std::move(ku), std::move(kv), std::move(kw), std::move(points)), std::move(tu), std::move(tv),
          std::move(tw)};
}

}  // namespace interpatch
