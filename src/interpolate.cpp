#include "interpatch/interpolate.hpp"

#include <algorithm>
#include <array>
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

namespace {

struct GridSolution {
  std::vector<KnotVector> knots;           // one per axis
  std::vector<std::vector<double>> params;  // one per axis
};

// The tensor-product interpolation behind surfaces and volumes (seed 003): parameters
// averaged over the lines along each axis, knots by averaging, then one in-place
// banded pass along each axis, each factored once. The data become the control points.
template <std::size_t Rank>
GridSolution solve_grid(Grid<Vec3, Rank>& points, const std::array<std::optional<int>, Rank>& degree,
                        Parametrization param, const progress_callback& progress, const char* what) {
  const auto& shape = points.shape();
  auto dims = [&](bool wanted) {  // "2 x 2 x 2" or the actual "nu x nv x nw"
    std::string s;
    for (std::size_t a = 0; a < Rank; ++a) s += detail::cat(a ? " x " : "", wanted ? std::size_t{2} : shape[a]);
    return s;
  };
  if (std::any_of(shape.begin(), shape.end(), [](std::size_t n) { return n < 2; }))
    fail(errc::too_few_points, what, " interpolation needs at least ", dims(true), " points, got ", dims(false));
  const Vec3* data = points.data();
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!is_finite(data[k])) {
      std::string at;
      for (std::size_t a = Rank, rest = k; a-- > 0; rest /= shape[a]) at = detail::cat("[", rest % shape[a], "]", at);
      fail(errc::not_finite, "point ", at, " is ", data[k]);
    }
  static constexpr const char* in_axis[3] = {" in u", " in v", " in w"};
  std::array<int, Rank> p{};
  for (std::size_t a = 0; a < Rank; ++a) p[a] = resolve_degree(degree[a], shape[a], 0, in_axis[a]);
  if (progress) progress(0.0);
  GridSolution r;
  std::vector<detail::BandedLU> lu;
  for (std::size_t a = 0; a < Rank; ++a) {
    r.params.push_back(grid_parameters(points, static_cast<int>(a), param));
    r.knots.push_back(averaged_knots(r.params[a], p[a]));
    try {
      lu.push_back(detail::factor_collocation(r.knots[a], r.params[a]));
    } catch (const error& e) {
      fail(e.code(), "along ", axis_name(static_cast<int>(a)), ": ", e.what());
    }
  }
  if (progress) progress(0.1);
  for (std::size_t a = 0; a < Rank; ++a) {
    detail::solve_along_axis(lu[a], &points.data()->x, shape.data(), Rank, a, 3);
    if (progress) progress(0.1 + 0.9 * static_cast<double>(a + 1) / Rank);
  }
  return r;
}

}  // namespace

SurfaceInterpolation interpolate_surface(PointGrid points, const SurfaceInterpolationOptions& options) {
  GridSolution s = solve_grid<2>(points, {options.degree_u, options.degree_v}, options.param, options.progress, "surface");
  return {BSplineSurface(std::move(s.knots[0]), std::move(s.knots[1]), std::move(points)), std::move(s.params[0]),
          std::move(s.params[1])};
}

VolumeInterpolation interpolate_volume(PointGrid3 points, const VolumeInterpolationOptions& options) {
  GridSolution s = solve_grid<3>(points, {options.degree_u, options.degree_v, options.degree_w}, options.param,
                                 options.progress, "volume");
  return {BSplineVolume(std::move(s.knots[0]), std::move(s.knots[1]), std::move(s.knots[2]), std::move(points)),
          std::move(s.params[0]), std::move(s.params[1]), std::move(s.params[2])};
}

}  // namespace interpatch
