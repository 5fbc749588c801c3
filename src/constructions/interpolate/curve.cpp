// Curves through points: their parameters and knots (open and closed), and the
// interpolation itself, open with optional end derivatives or closed (periodic).

#include <algorithm>
#include <cmath>
#include <limits>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "linalg/banded.hpp"
#include "linalg/collocation.hpp"
#include "base/text.hpp"
#include "interpatch/interpolate.hpp"

namespace interpatch {

using detail::fail;
using detail::resolve_degree;
using detail::root_scale;

namespace {

// The exponent of the largest coordinate of the first point that is not the origin
// (0 if all are): it follows the scale of the data exactly, which is all it is for.
int point_exponent(std::span<const Vec3> points) {
  for (const Vec3& p : points)
    if (const double m = max_abs(p); m > 0) return scale_exponent(m);
  return 0;
}

double step(const Vec3& a, const Vec3& b, Parametrization param, double root) {
  const double d = distance(a, b);
  return param == Parametrization::centripetal ? std::sqrt(d * root) : d;
}

void check_params(std::span<const double> t, const char* what) {
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i])) fail(errc::not_finite, what, " ", i, " is ", t[i]);
    if (i > 0 && !(t[i] > t[i - 1]))
      fail(errc::non_increasing, what, " ", i, " = ", t[i], " is not greater than ", what, " ", i - 1, " = ", t[i - 1]);
  }
}

}  // namespace

namespace detail {

int resolve_degree(const std::optional<int>& degree, std::size_t count, std::size_t extra, const char* where) {
  const int p = degree ? *degree : std::min<int>(3, static_cast<int>(count + extra) - 1);
  if (p < 1 || p > max_degree) fail(errc::invalid_degree, "degree ", p, where, " is outside 1..", max_degree);
  if (count + extra < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "degree ", p, where, " needs at least ", p + 1 - static_cast<int>(extra),
         " points, got ", count);
  return p;
}

}  // namespace detail

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
  if (!std::isfinite(total))
    fail(errc::not_finite, "the polyline's length overflows (", total, "): the points span more than ",
         std::numeric_limits<double>::max());
  const double root = root_scale(point_exponent(points));
  for (std::size_t i = 1; i < n; ++i) {
    const double d = distance(points[i], points[i - 1]);
    // Chords below 1e-14 of the polyline's length are rounding noise: the two points coincide.
    if (!(d > 1e-14 * total))
      fail(errc::zero_chord, "points ", i - 1, " and ", i, " coincide (chord ", d, ", polyline length ", total,
           "): parameters must increase");
    t[i] = t[i - 1] + step(points[i - 1], points[i], param, root);
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

std::vector<double> closed_curve_parameters(std::span<const Vec3> points, Parametrization param) {
  const std::size_t n = points.size();
  if (n < 2) fail(errc::too_few_points, "parameters of a closed curve need at least 2 points, got ", n);
  for (std::size_t i = 0; i < n; ++i)
    if (!is_finite(points[i])) fail(errc::not_finite, "point ", i, " is ", points[i]);
  std::vector<double> t(n, 0.0);
  if (param == Parametrization::uniform) {
    for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / static_cast<double>(n);
    return t;
  }
  double total = distance(points[0], points[n - 1]);
  for (std::size_t i = 1; i < n; ++i) total += distance(points[i], points[i - 1]);
  if (!std::isfinite(total))
    fail(errc::not_finite, "the closed polygon's length overflows (", total, "): the points span more than ",
         std::numeric_limits<double>::max());
  const double root = root_scale(point_exponent(points));
  double len = 0;
  for (std::size_t i = 1; i <= n; ++i) {
    const std::size_t j = i % n;
    const double d = distance(points[j], points[i - 1]);
    // Chords below 1e-14 of the polygon's length are rounding noise: the two points coincide.
    if (!(d > 1e-14 * total))
      fail(errc::zero_chord, "points ", i - 1, " and ", j, j == 0 ? " (the closing chord)" : "", " coincide (chord ", d,
           ", closed polygon length ", total, "): parameters must increase");
    const double st = step(points[i - 1], points[j], param, root);
    if (i < n) t[i] = t[i - 1] + st;
    else len = t[i - 1] + st;  // back at the first point: the whole closed polygon's steps
  }
  for (std::size_t i = 1; i < n; ++i) t[i] /= len;
  return t;
}

KnotVector periodic_knots(std::span<const double> params, int degree) {
  const std::size_t n = params.size();
  const int p = degree;
  if (p < 1 || p > max_degree) fail(errc::invalid_degree, "degree ", p, " is outside 1..", max_degree);
  if (n < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "a closed spline of degree ", p, " needs at least ", p + 1, " distinct points, got ", n);
  check_params(params, "parameter");
  const double a = params.front(), b = a + 1.0;
  if (!(params.back() < b))
    fail(errc::out_of_domain, "parameter ", n - 1, " = ", params.back(), " is not inside the period [", a, ", ", b, ")");
  if (p % 2 == 1) return KnotVector::periodic_from(p, {params.begin(), params.end()}, b);
  // Even degree: midpoints; the period starts at the last one, one period back.
  std::vector<double> k(n);
  const double last = 0.5 * (params.back() + b);
  k[0] = last - 1.0;
  for (std::size_t i = 0; i + 1 < n; ++i) k[i + 1] = 0.5 * (params[i] + params[i + 1]);
  return KnotVector::periodic_from(p, std::move(k), last);
}

namespace {

CurveInterpolation interpolate_closed_curve(std::span<const Vec3> all, const CurveInterpolationOptions& options) {
  if (options.start_derivative || options.end_derivative)
    fail(errc::wrong_type, "a closed curve has no ends: start and end derivatives do not apply to a periodic curve");
  const std::size_t given = all.size();
  if (given < 2) fail(errc::too_few_points, "curve interpolation needs at least 2 points, got ", given);
  for (std::size_t i = 0; i < given; ++i)
    if (!is_finite(all[i])) fail(errc::not_finite, "point ", i, " is ", all[i]);
  const Closing closing = closing_point(all);
  const std::span<const Vec3> points = all.first(closing.count);
  const std::size_t n = points.size();
  const int p = options.degree ? *options.degree : std::min<int>(3, static_cast<int>(n) - 1);
  if (p < 1 || p > max_degree) fail(errc::invalid_degree, "degree ", p, " is outside 1..", max_degree);
  if (n < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "a closed curve of degree ", p, " needs at least ", p + 1, " distinct points, got ", n,
         closing.dropped ? " (the last point repeats the first and is left out)" : "");
  std::vector<double> t;
  if (!options.params.empty()) {
    if (options.params.size() != given)
      fail(errc::size_mismatch, given, " points need ", given, " parameters, got ", options.params.size());
    check_params(options.params, "parameter");
    t.assign(options.params.begin(), options.params.begin() + static_cast<std::ptrdiff_t>(n));
  } else {
    t = closed_curve_parameters(points, options.param);
  }
  KnotVector knots = periodic_knots(t, p);
  std::vector<Vec3> cp(points.begin(), points.end());
  detail::factor_periodic_collocation(knots, t).solve(&cp.data()->x, 3, 3);
  if (p % 2 == 0) {  // the domain starts at a midpoint: start it at the first parameter
    detail::SeamInsertion seam = detail::seam_insertion(knots, t.front());
    std::vector<Vec3> q(seam.rows.size());
    for (std::size_t j = 0; j < q.size(); ++j) {
      const auto& r = seam.rows[j];
      q[j] = r.alpha * cp[r.x] + (1.0 - r.alpha) * cp[r.y];
    }
    cp = std::move(q);
    knots = std::move(seam.knots);
  }
  if (closing.dropped) t.push_back(t.front() + 1.0);
  return {BSplineCurve(std::move(knots), std::move(cp)), std::move(t)};
}

}  // namespace

CurveInterpolation interpolate_curve(std::span<const Vec3> points, const CurveInterpolationOptions& options) {
  if (options.periodic) return interpolate_closed_curve(points, options);
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

}  // namespace interpatch
