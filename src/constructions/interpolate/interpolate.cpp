#include "interpatch/interpolate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <variant>

#include "linalg/banded.hpp"
#include "linalg/collocation.hpp"
#include "constructions/interpolate/grid_rows.hpp"
#include "base/kernel.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;
using detail::GridBlock;
using detail::RowTeam;

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 grids are solved as arrays of doubles");

namespace {

const char* axis_name(int axis) { return axis == 0 ? "u" : (axis == 1 ? "v" : "w"); }

// Centripetal steps are square roots of chords, and sqrt(2^k c) = 2^(k/2) sqrt(c)
// holds exactly for even k only. The chords are halved (exact) when the exponent of
// the data's scale (point_exponent, grid_exponent) is odd: scaling the data by 2^k
// then scales every halved-or-not chord by an even power of two, every step by an
// exact power of two, and leaves the parameters as they are, bit for bit.
double root_scale(int data_exponent) { return (data_exponent & 1) != 0 ? 0.5 : 1.0; }

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

// The largest coordinate extent of points: the bounding-box diagonal.
template <class PointAt>
double box_diagonal(std::size_t count, const PointAt& point) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3& q = point(i);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], q[k]);
      hi[k] = std::max(hi[k], q[k]);
    }
  }
  return norm(hi - lo);
}

// Whether the last point of each of `lines` closed lines of n points repeats the
// first (closing_point; the rule is the same for every line of a grid, and all must
// repeat for the last line to be left out). point(l, k) is point k of line l;
// diagonal() the data's bounding-box diagonal, computed only when a gap is small.
// With a near miss, `line` is the first line that misses. A grid split between the
// processes of `team`: each passes its own lines, the first being line `first_line`
// of the grid, and all agree; `mine` says whether the near miss is among them.
struct LineEnding {
  Closing closing;
  std::size_t line = 0;
  double gap = 0, adjacent = 0, tol = 0;
  bool mine = true;
};

const RowTeam solo;  // the single process

template <class PointAt, class Diagonal>
LineEnding line_ending(std::size_t lines, std::size_t n, const PointAt& point, const Diagonal& diagonal,
                       const RowTeam& team = solo, std::size_t first_line = 0) {
  if (n < 3) return {{n, false, false}};
  bool all_zero = true, near = false;
  for (std::size_t l = 0; l < lines; ++l) {
    const double gap = distance(point(l, n - 1), point(l, 0));
    if (gap == 0.0) continue;
    all_zero = false;
    const double adjacent = std::min(distance(point(l, 1), point(l, 0)), distance(point(l, n - 1), point(l, n - 2)));
    near = near || gap < 1e-3 * adjacent;
  }
  std::size_t flags[2] = {all_zero ? 0u : 1u, near ? 1u : 0u};  // lines with a gap, processes with a near one
  team.sum(flags);
  if (flags[0] == 0) return {{n - 1, true, false}};
  if (flags[1] == 0) return {{n, false, false}};
  const double tol = 1e-12 * diagonal();
  bool all_close = true;
  for (std::size_t l = 0; l < lines && all_close; ++l) all_close = distance(point(l, n - 1), point(l, 0)) <= tol;
  std::size_t open[1] = {all_close ? 0u : 1u};
  team.sum(open);
  if (open[0] == 0) return {{n - 1, true, false}};
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  LineEnding found{{n, false, false}};
  std::size_t first[1] = {none};
  for (std::size_t l = 0; l < lines; ++l) {
    const double gap = distance(point(l, n - 1), point(l, 0));
    const double adjacent = std::min(distance(point(l, 1), point(l, 0)), distance(point(l, n - 1), point(l, n - 2)));
    if (gap > tol && gap < 1e-3 * adjacent) {
      found = {{n, false, true}, first_line + l, gap, adjacent, tol};
      first[0] = found.line;
      break;
    }
  }
  team.min(first);
  if (first[0] == none) return {{n, false, false}};
  if (found.closing.nearly && found.line == first[0]) return found;
  LineEnding other{{n, false, true}, first[0]};
  other.mine = false;
  return other;
}

// line_ending, a near miss refused (by the process whose line it is); where(l) names
// line l's last point.
template <class PointAt, class Diagonal, class Where>
Closing find_closing(std::size_t lines, std::size_t n, const PointAt& point, const Diagonal& diagonal,
                     const Where& where, const RowTeam& team = solo, std::size_t first_line = 0) {
  const LineEnding e = line_ending(lines, n, point, diagonal, team, first_line);
  if (e.closing.nearly)
    team.run([&] {
      if (!e.mine) return;
      const std::size_t l = e.line - first_line;
      fail(errc::closing_gap, where(l), " = ", point(l, n - 1), " nearly repeats the first point ", point(l, 0),
           ": gap ", e.gap, ", more than the ", e.tol,
           " (1e-12 of the bounding-box diagonal) that makes it the closing point and less than ",
           "1e-3 of the chords next to it (", e.adjacent,
           "), which would leave a kink at the seam; repeat the first point "
           "exactly, or leave the last one out");
    });
  return e.closing;
}

}  // namespace

Closing closing_point(std::span<const Vec3> points) {
  return find_closing(
      1, points.size(), [&](std::size_t, std::size_t k) -> const Vec3& { return points[k]; },
      [&] { return box_diagonal(points.size(), [&](std::size_t i) -> const Vec3& { return points[i]; }); },
      [&](std::size_t) { return detail::cat("point ", points.size() - 1); });
}

namespace {

// Inserting a periodic spline's first parameter a (not a knot) and starting its
// period there: each new control point j is α P[x] + (1 − α) P[y] of the old ones
// (Boehm's rule on the periodic sequence of knots; new control point j + 1 of the
// refined spline becomes j once the period starts at a). With `knots` the refined,
// re-anchored knot vector.
struct SeamInsertion {
  struct Row {
    std::size_t x, y;
    double alpha;
  };
  std::vector<Row> rows;
  KnotVector knots;
};

SeamInsertion seam_insertion(const KnotVector& k, double a) {
  const int n = k.count(), p = k.degree();
  const auto& u = k.values();
  const int span = k.find_span(a);
  auto mod = [](int i, int m) { return static_cast<std::size_t>(((i % m) + m) % m); };
  std::vector<SeamInsertion::Row> rows(static_cast<std::size_t>(n) + 1);
  // New control points of the refined spline, window i = span − n + 1 .. span + 1.
  for (int i = span - n + 1; i <= span + 1; ++i) {
    SeamInsertion::Row r{mod(i, n), mod(i - 1, n), 1.0};
    if (i > span) r.alpha = 0.0;
    else if (i > span - p)
      r.alpha = (a - u[static_cast<std::size_t>(i)]) / (u[static_cast<std::size_t>(i + p)] - u[static_cast<std::size_t>(i)]);
    const std::size_t j = mod(i, n + 1);  // index in the refined spline; a is its knot 1
    rows[(j + static_cast<std::size_t>(n)) % (static_cast<std::size_t>(n) + 1)] = r;
  }
  std::vector<double> pk = k.period_knots();
  std::vector<double> nk{a};
  nk.insert(nk.end(), pk.begin() + 1, pk.end());
  nk.push_back(k.back());
  return {std::move(rows), KnotVector::periodic_from(p, std::move(nk), a + (k.back() - k.front()))};
}

}  // namespace

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
    SeamInsertion seam = seam_insertion(knots, t.front());
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

namespace {

// ------------------------------------------------------------ tensor grids
//
// Interpolation through a grid streams the grid three times and keeps no
// grid-sized temporary (fresh pages cost more than the arithmetic on them):
//  1. chord pass: finite check; along every axis inside a row (the slice of one
//     index along u: a row of a surface, a plane of a volume) each line's chords
//     and normalized running lengths, summed over the lines; along u each line's
//     length;
//  2. row pass, a few rows at a time while they are in cache: each row's averaged
//     step along u (chords to the row before, weighted by 1 / line length), then
//     the banded solves along the axes inside the rows;
//  3. the banded solve along u, in column slices that stay in cache.
// Partial sums are formed in chunks of a fixed number of rows and added in chunk
// order, so the result does not depend on the number of threads.

using detail::rows_per_chunk;
constexpr std::size_t rows_per_group = 8;
// A line shorter than 1e-14 of the longest along its axis is a collapsed row (a
// pole) within rounding: it is left out of the averaging.
constexpr double pole_ratio = 1e-14;

// Chord lengths |b[i] − a[i]| (centripetal: square roots of them times `root`, see
// root_scale) for i < count. Squares first, roots in a loop of their own, which the
// compiler vectorizes.
//
// A chord outside (2^-450, 2^511), about (3e-136, 7e153), may come from a square
// that overflowed (inf) or underflowed (below 2^-900 a component's square may have
// lost digits or all of them; a zero chord is flagged too): the root loop flags it on
// the way, two comparisons per chord, and only then is each such chord computed
// again from its components scaled by 2^-e, e the exponent of the largest, its
// root scaled back by 2^e. Scaling by a power of two is exact and sqrt(4^e x) =
// 2^e sqrt(x), so that is the value the formula has without range limits, the one
// the first loop gives in range: a chord of data scaled by 2^k is 2^k times the
// chord, bit for bit. The recomputation sits in this function so that it is
// compiled, fused multiply-adds and all, like the first loop. (In the clone with
// fused multiply-adds, whose products are exact, a component's square that
// underflowed while the sum did not can still, in principle, decide a rounding at a
// near-tie in the last bit; it needs components 2^60 apart and bits that line up.
// The flag does not look at single components: that would cost more than it saves.)
INTERPATCH_KERNEL void chord_lengths(const Vec3* a, const Vec3* b, std::size_t count, double* out, Parametrization param,
                                     double root) {
  unsigned out_of_range = 0;  // not a bool: g++ 12 vectorizes the loop with an unsigned or-reduction only
  for (std::size_t i = 0; i < count; ++i) {
    const double dx = b[i].x - a[i].x, dy = b[i].y - a[i].y, dz = b[i].z - a[i].z;
    const double c = std::sqrt(dx * dx + dy * dy + dz * dz);
    out[i] = c;
    out_of_range |= static_cast<unsigned>(c <= 0x1p-450) | static_cast<unsigned>(c >= 0x1p511);
  }
  if (out_of_range != 0)
    for (std::size_t i = 0; i < count; ++i) {
      if (out[i] > 0x1p-450 && out[i] < 0x1p511) continue;
      const Vec3 d = b[i] - a[i];
      const int e = scale_exponent(max_abs(d));
      const Vec3 u = ldexp(d, -e);
      const double dx = u.x, dy = u.y, dz = u.z;
      out[i] = std::ldexp(std::sqrt(dx * dx + dy * dy + dz * dz), e);
    }
  if (param == Parametrization::centripetal)
    for (std::size_t i = 0; i < count; ++i) out[i] = std::sqrt(out[i] * root);
}

// The weight 1 / length of a line in the averaged parameters; 0 for a line of zero
// length (left out) or one so short that its reciprocal overflows (a collapsed line
// of tiny data, left out with the other collapsed lines).
double line_weight(double length) { return length >= std::numeric_limits<double>::min() ? 1.0 / length : 0.0; }

// Σ a[i] and Σ a[i] b[i] in four interleaved partial sums: a fixed order (the same
// bits on every run) without one long chain of dependent additions.
double sum(const double* a, std::size_t n) {
  double s[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (std::size_t j = 0; j < 4; ++j) s[j] += a[i + j];
  for (; i < n; ++i) s[0] += a[i];
  return (s[0] + s[1]) + (s[2] + s[3]);
}

double dot(const double* a, const double* b, std::size_t n) {
  double s[4] = {0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4)
    for (std::size_t j = 0; j < 4; ++j) s[j] += a[i + j] * b[i + j];
  for (; i < n; ++i) s[0] += a[i] * b[i];
  return (s[0] + s[1]) + (s[2] + s[3]);
}

struct GridShape {
  std::size_t rank = 0;
  std::array<std::size_t, 3> n{};
  std::size_t row = 1;  // points in one row (every index but the first)
  // Lines along in-row axis a inside one row: outer(a) × inner(a) of them.
  [[nodiscard]] std::size_t outer(std::size_t a) const {
    std::size_t o = 1;
    for (std::size_t x = 1; x < a; ++x) o *= n[x];
    return o;
  }
  [[nodiscard]] std::size_t inner(std::size_t a) const {
    std::size_t i = 1;
    for (std::size_t x = a + 1; x < rank; ++x) i *= n[x];
    return i;
  }
  [[nodiscard]] std::size_t lines(std::size_t a) const { return outer(a) * inner(a); }
};

template <std::size_t Rank>
GridShape grid_shape(const std::array<std::size_t, Rank>& shape) {
  GridShape g;
  g.rank = Rank;
  for (std::size_t a = 0; a < Rank; ++a) g.n[a] = shape[a];
  for (std::size_t a = 1; a < Rank; ++a) g.row *= shape[a];
  return g;
}

GridShape grid_shape(const GridBlock& b) {
  GridShape g;
  g.rank = b.rank;
  g.n = b.n;
  g.row = b.row_size();
  return g;
}

// Point k of the whole grid (in C order) is q.
[[noreturn]] void fail_not_finite(const Vec3& q, const GridShape& g, std::size_t k) {
  std::string at;
  for (std::size_t a = g.rank, rest = k; a-- > 0; rest /= g.n[a]) at = detail::cat("[", rest % g.n[a], "]", at);
  const bool missing = std::isnan(q.x) || std::isnan(q.y) || std::isnan(q.z);
  fail(errc::not_finite, "point ", at, " is ", q,
       missing ? " (interpolation needs every point; approximation takes missing points, marked by NaN)" : "");
}

void check_grid_finite(const Vec3* q, const GridShape& g) {
  const std::size_t total = g.n[0] * g.row;
  if (const std::size_t k = detail::first_non_finite(q, total); k < total) fail_not_finite(q[k], g, k);
}

// The same for a block of rows.
void check_block_finite(const GridBlock& b) {
  const std::size_t M = b.row_size(), total = b.count * M;
  if (const std::size_t k = detail::first_non_finite(b.data, total); k < total)
    fail_not_finite(b.data[k], grid_shape(b), b.first * M + k);
}

// The block of every row of a grid, for the single process.
template <std::size_t Rank>
GridBlock whole_grid(const Grid<Vec3, Rank>& q) {
  GridBlock b;
  b.rank = Rank;
  for (std::size_t a = 0; a < Rank; ++a) b.n[a] = q.extent(a);
  b.data = const_cast<Vec3*>(q.data());  // NOLINT: read only where the grid is const (the parameters)
  b.count = b.n[0];
  const std::size_t M = b.row_size();
  b.row0 = b.data;
  b.last = b.data + (b.n[0] - 1) * M;
  return b;
}

// The exponent of the grid's scale: of the largest coordinate in its first and last
// rows (in every row when those are all zero), a few thousand points read at most.
// It follows the scale of the data exactly, which is all it is for.
int grid_exponent(const GridBlock& b, const RowTeam& team) {
  const std::size_t M = b.row_size();
  auto largest = [&](const Vec3* q, std::size_t count) {
    double m = 0;
    for (std::size_t k = 0; k < count; ++k) m = std::max(m, max_abs(q[k]));
    return m;
  };
  double m = std::max(largest(b.row0, M), largest(b.last, M));
  if (m == 0) {
    double all[1] = {largest(b.data, b.count * M)};
    team.max(all);
    m = all[0];
  }
  return scale_exponent(m);
}

// Grids of extreme scale, coordinates beyond 2^±400 (about 1e±120), are solved
// scaled by 2^-e, e = grid_exponent: data near 1e300 or 1e-300 (or subnormal) then
// run the chord pass at full speed and their line lengths neither overflow nor lose
// their reciprocals. Parameters do not depend on the scale and the solve is linear,
// so the control points are scaled back by 2^e: exactly the ones the data give as
// they are, in the range where the arithmetic has no limits.
constexpr int extreme_exponent = 400;

int extreme_shift(const GridBlock& b, const RowTeam& team) {
  const int e = grid_exponent(b, team);
  return e > extreme_exponent || e < -extreme_exponent ? e : 0;
}

using detail::scale_points;

// Pass 1 and what the averaged parameters need from it.
class GridChords {
 public:
  // The chords of a block of rows; every process of `team` builds its own, and
  // they agree on what is summed over the whole grid.
  GridChords(const GridBlock& b, Parametrization param, std::array<bool, 3> periodic, const RowTeam& team)
      : g_(grid_shape(b)), param_(param), root_(root_scale(grid_exponent(b, team))), periodic_(periodic) {
    const GridShape& g = g_;
    const std::size_t n0 = g.n[0], M = g.row, R = g.rank;
    if (param == Parametrization::uniform) {
      team.run([&] { check_block_finite(b); });
      return;
    }
    INTERPATCH_ASSERT(b.first % rows_per_chunk == 0 && R >= 2);
    const Vec3* q = b.data;
    const std::size_t chunks = (b.count + rows_per_chunk - 1) / rows_per_chunk;
    team.run([&] {
      std::size_t sums = chunks * M;
      for (std::size_t a = 1; a < R; ++a) sums += b.count * g.lines(a) + chunks * g.n[a];
      require_memory(sums, sizeof(double), "chord sums of the grid");
    });
    // part[c][a]: chunk c's sums; a = 0: the lengths of the lines along u (one per
    // point of a row); a ≥ 1: normalized running lengths along axis a.
    std::vector<std::vector<double>> part(chunks * R);
    line_length_.assign(R, {});
    for (std::size_t a = 1; a < R; ++a) line_length_[a].assign(b.count * g.lines(a), 0.0);
    const auto nchunks = static_cast<long long>(chunks);
    detail::ParallelFailure failure;  // the scratch and the chunks' sums are allocated
#pragma omp parallel if (b.count * M >= detail::parallel_min_work / 4)
    {
      std::vector<double> scratch;
      failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] { scratch.resize(scratch_size()); });
#pragma omp for schedule(static) nowait
      for (long long ci = 0; ci < nchunks; ++ci) {
        if (failure.failed()) continue;
        const auto c = static_cast<std::size_t>(ci);
        failure.attempt(c, [&] {
          part[c * R].assign(M, 0.0);
          for (std::size_t a = 1; a < R; ++a) part[c * R + a].assign(g.n[a], 0.0);
        });
        if (failure.failed()) continue;
        const std::size_t r1 = std::min(b.count, (c + 1) * rows_per_chunk);
        for (std::size_t r = c * rows_per_chunk; r < r1; ++r) {  // local rows; b.first + r in the grid
          const Vec3* row = q + r * M;
          if (b.first + r > 0) {
            chord_lengths(r == 0 ? b.before : row - M, row, M, scratch.data(), param, root_);
            double* t0 = part[c * R].data();
            for (std::size_t m = 0; m < M; ++m) t0[m] += scratch[m];
          }
          for (std::size_t a = 1; a < R; ++a)
            add_running_lengths(row, a, part[c * R + a].data(), line_length_[a].data() + r * g.lines(a),
                                scratch.data());
        }
      }
    }
    failure.rethrow();
    // A NaN or an infinity makes the length of its line along v NaN or infinite
    // (every point is on one, with a chord to a neighbour): only then are the points
    // searched for the first of them.
    team.run([&] {
      const auto& len = line_length_[1];
      if (std::any_of(len.begin(), len.end(), [](double l) { return !std::isfinite(l); })) check_block_finite(b);
    });
    team.run([&] {
      for (std::size_t a = 1; a < R; ++a) check_lengths(line_length_[a], a);
    });
    // Nearly collapsed lines were summed like the others: take them out again.
    std::vector<double> longest(R, 0.0);
    for (std::size_t a = 1; a < R; ++a)
      for (const double l : line_length_[a]) longest[a] = std::max(longest[a], l);
    team.max(longest);
    used_.assign(R, 0);
    for (std::size_t a = 1; a < R; ++a) {
      const auto& len = line_length_[a];
      const double cut = pole_ratio * longest[a];
      const std::size_t per_row = g.lines(a);
      for (std::size_t l = 0; l < len.size(); ++l) {
        if (len[l] > cut && line_weight(len[l]) > 0) ++used_[a];
        else if (line_weight(len[l]) > 0) remove_line(q, a, l / per_row, l % per_row, part[(l / per_row / rows_per_chunk) * R + a]);
      }
    }
    team.sum(used_);
    sums_.assign(R, {});
    for (std::size_t a = 0; a < R; ++a) {
      sums_[a].assign(a == 0 ? M : g.n[a], 0.0);
      team.fold(sums_[a], [&](std::span<double> acc) {
        for (std::size_t c = 0; c < chunks; ++c)
          for (std::size_t k = 0; k < acc.size(); ++k) acc[k] += part[c * R + a][k];
      });
    }
    if (periodic_[0]) {  // the closing chords of the lines along u: last row back to the first
      std::vector<double> closing(M);
      chord_lengths(b.last, b.row0, M, closing.data(), param, root_);
      for (std::size_t m = 0; m < M; ++m) sums_[0][m] += closing[m];
    }
    (void)n0;
    team.run([&] { check_lengths(sums_[0], 0); });
    // Along u: the weight of each line is 1 / its length, 0 for a collapsed line.
    const double cut0 = pole_ratio * *std::max_element(sums_[0].begin(), sums_[0].end());
    inv_length_.assign(M, 0.0);
    for (std::size_t m = 0; m < M; ++m)
      if (sums_[0][m] > cut0 && line_weight(sums_[0][m]) > 0) {
        inv_length_[m] = line_weight(sums_[0][m]);
        ++used_[0];
      }
  }

  // Averaged parameters along in-row axis a ≥ 1.
  [[nodiscard]] std::vector<double> in_row_parameters(std::size_t a) const {
    if (param_ == Parametrization::uniform) return uniform(g_.n[a], periodic_[a]);
    if (used_[a] == 0) fail_all_collapsed(a);
    std::vector<double> t(g_.n[a], 0.0);
    double s = 0;
    for (std::size_t k = 1; k < t.size(); ++k) {
      s += sums_[a][k];
      t[k] = s / static_cast<double>(used_[a]);
    }
    return finish(std::move(t), a);
  }

  // Row r's step along u: Σ over the lines along u of chord(r − 1, r) / line length.
  double row_step(const Vec3* prev, const Vec3* row, double* scratch) const {
    chord_lengths(prev, row, g_.row, scratch, param_, root_);
    return dot(scratch, inv_length_.data(), g_.row);
  }

  // Parameters along u from the rows' steps (steps[0] unused).
  [[nodiscard]] std::vector<double> u_parameters(std::span<const double> steps) const {
    if (param_ == Parametrization::uniform) return uniform(g_.n[0], periodic_[0]);
    if (used_[0] == 0) fail_all_collapsed(0);
    std::vector<double> t(g_.n[0], 0.0);
    double s = 0;
    for (std::size_t k = 1; k < t.size(); ++k) {
      s += steps[k];
      t[k] = s / static_cast<double>(used_[0]);
    }
    return finish(std::move(t), 0);
  }

  // Refuses a grid whose lines along some axis all have zero length, axes in order.
  void check_lines() const {
    if (!uses_chords()) return;
    for (std::size_t a = 0; a < g_.rank; ++a)
      if (used_[a] == 0) fail_all_collapsed(a);
  }

  [[nodiscard]] bool uses_chords() const noexcept { return param_ != Parametrization::uniform; }
  [[nodiscard]] std::size_t scratch_size() const {
    std::size_t s = g_.row;
    for (std::size_t a = 1; a < g_.rank; ++a) s = std::max(s, (g_.n[a] + 1) * g_.inner(a));
    return s;
  }

 private:
  // Lines longer than the largest double: chords or their sums overflowed.
  static void check_lengths(const std::vector<double>& lengths, std::size_t a) {
    if (std::all_of(lengths.begin(), lengths.end(), [](double l) { return l <= std::numeric_limits<double>::max(); }))
      return;
    const char* ax = axis_name(static_cast<int>(a));
    fail(errc::not_finite, "the lines of the grid along ", ax, " are longer than ", std::numeric_limits<double>::max(),
         ": the points span more than a double holds");
  }

  [[noreturn]] static void fail_all_collapsed(std::size_t a) {
    const char* ax = axis_name(static_cast<int>(a));
    fail(errc::zero_chord, "every line of the grid along ", ax, " has zero length: all points coincide along ", ax);
  }

  // k / (n − 1), or k / n around a closed direction (1 would be the first line again).
  static std::vector<double> uniform(std::size_t n, bool closed) {
    std::vector<double> t(n);
    const double d = static_cast<double>(closed ? n : n - 1);
    for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / d;
    if (!closed) t.back() = 1.0;
    return t;
  }

  [[nodiscard]] std::vector<double> finish(std::vector<double> t, std::size_t a) const {
    if (!periodic_[a]) t.back() = 1.0;
    for (std::size_t k = 1; k < t.size(); ++k)
      if (!(t[k] > t[k - 1]))
        fail(errc::zero_chord, "grid points ", k - 1, " and ", k, " along ", axis_name(static_cast<int>(a)),
             " coincide on every line (averaged parameters ", t[k - 1], " and ", t[k], ")");
    if (periodic_[a] && !(t.back() < 1.0))
      fail(errc::zero_chord, "the last and the first grid points along ", axis_name(static_cast<int>(a)),
           " coincide on every line: the closing chord has zero length (averaged parameter ", t.back(), ")");
    return t;
  }

  // Adds, for every line along in-row axis a of one row, its chords divided by its
  // length (the running sums of these are the line's normalized parameters, summed
  // once at the end: in_row_parameters); records each line's length.
  void add_running_lengths(const Vec3* row, std::size_t a, double* acc, double* lengths, double* scratch) const {
    const std::size_t n = g_.n[a], inner = g_.inner(a), outer = g_.outer(a);
    double* ch = scratch;  // (n − 1) × inner chords
    double* inv = ch + n * inner;
    const bool closed = periodic_[a];
    for (std::size_t o = 0; o < outer; ++o) {
      const Vec3* base = row + o * n * inner;
      if (inner == 1) {
        chord_lengths(base, base + 1, n - 1, ch, param_, root_);
        if (closed) chord_lengths(base + n - 1, base, 1, ch + n - 1, param_, root_);
        lengths[o] = sum(ch, closed ? n : n - 1);
        const double w = line_weight(lengths[o]);
        for (std::size_t k = 1; k < n; ++k) acc[k] += ch[k - 1] * w;
        continue;
      }
      for (std::size_t k = 1; k < n; ++k)
        chord_lengths(base + (k - 1) * inner, base + k * inner, inner, ch + (k - 1) * inner, param_, root_);
      if (closed) chord_lengths(base + (n - 1) * inner, base, inner, ch + (n - 1) * inner, param_, root_);
      double* len = lengths + o * inner;
      std::fill_n(len, inner, 0.0);
      for (std::size_t k = 1; k < (closed ? n + 1 : n); ++k)
        for (std::size_t i = 0; i < inner; ++i) len[i] += ch[(k - 1) * inner + i];
      for (std::size_t i = 0; i < inner; ++i) inv[i] = line_weight(len[i]);
      for (std::size_t k = 1; k < n; ++k) acc[k] += dot(ch + (k - 1) * inner, inv, inner);
    }
  }

  // Takes line l of row r along axis a back out of its chunk's sums.
  void remove_line(const Vec3* q, std::size_t a, std::size_t r, std::size_t l, std::vector<double>& acc) const {
    const std::size_t n = g_.n[a], inner = g_.inner(a);
    const Vec3* base = q + r * g_.row + (l / inner) * n * inner + l % inner;
    const double w = line_weight(line_length_[a][r * g_.lines(a) + l]);
    double d = 0;
    for (std::size_t k = 1; k < n; ++k) {
      chord_lengths(base + (k - 1) * inner, base + k * inner, 1, &d, param_, root_);
      acc[k] -= d * w;
    }
  }

  GridShape g_;
  Parametrization param_;
  double root_;                                    // see root_scale
  std::array<bool, 3> periodic_;                   // closed axes: their lines' lengths take in the closing chord
  std::vector<std::vector<double>> sums_;         // per axis: 0 → line lengths along u; a ≥ 1 → Σ over lines of chord k / line length
  std::vector<std::vector<double>> line_length_;  // per in-row axis: every line's length, row by row
  std::vector<std::size_t> used_;                  // lines averaged per axis
  std::vector<double> inv_length_;                 // per line along u: 1 / length, 0 when collapsed
};

// Every row's step along u (pass 2 without the solves).
std::vector<double> row_steps(const Vec3* q, const GridShape& g, const GridChords& chords) {
  std::vector<double> steps(g.n[0], 0.0);
  const auto n0 = static_cast<long long>(g.n[0]);
  detail::ParallelFailure failure;  // each thread's scratch is allocated
#pragma omp parallel if (g.n[0] * g.row >= detail::parallel_min_work / 4)
  {
    std::vector<double> scratch;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] { scratch.resize(g.row); });
#pragma omp for schedule(static)
    for (long long r = 1; r < n0; ++r) {
      if (failure.failed()) continue;
      const auto k = static_cast<std::size_t>(r);
      steps[k] = chords.row_step(q + (k - 1) * g.row, q + k * g.row, scratch.data());
    }
  }
  failure.rethrow();
  return steps;
}

template <std::size_t Rank>
std::vector<double> grid_parameters_of(const Grid<Vec3, Rank>& q, int axis, Parametrization param) {
  if (axis < 0 || axis >= static_cast<int>(Rank))
    fail(errc::out_of_domain, "axis ", axis, " is outside 0..", Rank - 1, " for a grid of rank ", Rank);
  const auto a = static_cast<std::size_t>(axis);
  if (q.extent(a) < 2) fail(errc::too_few_points, "a grid needs at least 2 points along ", axis_name(axis), ", got ", q.extent(a));
  const GridShape g = grid_shape(q.shape());
  const RowTeam alone;
  auto parameters = [&](const Grid<Vec3, Rank>& data) {
    const GridChords chords(whole_grid(data), param, {}, alone);
    if (a > 0) return chords.in_row_parameters(a);
    return chords.u_parameters(chords.uses_chords() ? row_steps(data.data(), g, chords) : std::vector<double>(g.n[0], 0.0));
  };
  const int shift = param == Parametrization::uniform ? 0 : extreme_shift(whole_grid(q), alone);
  if (shift == 0) return parameters(q);
  check_grid_finite(q.data(), g);  // before scaling: the message shows the point as given
  require_memory(q.size(), sizeof(Vec3), "a scaled copy of the grid");
  Grid<Vec3, Rank> scaled = q;
  scale_points(scaled.data(), scaled.size(), -shift);
  return parameters(scaled);
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
  bool finite = false;                      // the control points are known to be finite
};

using detail::AxisSolver;

void solve_axis(const AxisSolver& lu, double* data, const std::size_t* shape, std::size_t rank, std::size_t axis,
                std::size_t components, bool parallel = true, bool* non_finite = nullptr) {
  std::visit(
      [&](const auto& s) { detail::solve_along_axis(s, data, shape, rank, axis, components, parallel, non_finite); },
      lu);
}

KnotVector axis_knots(std::span<const double> params, int degree, bool closed) {
  return closed ? periodic_knots(params, degree) : averaged_knots(params, degree);
}

// Rows 0, 1, n − 2 and n − 1 of a whole grid: what the closing along u looks at.
template <std::size_t Rank>
std::array<const Vec3*, 4> end_rows(const Grid<Vec3, Rank>& points) {
  const std::size_t n = points.extent(0), M = points.size() / n;
  auto row = [&](std::size_t r) { return points.data() + std::min(r, n - 1) * M; };
  return {row(0), row(1), row(n < 2 ? 0 : n - 2), row(n - 1)};
}

template <std::size_t Rank>
Closing grid_closing_of(const Grid<Vec3, Rank>& points, int axis) {
  if (axis < 0 || axis >= static_cast<int>(Rank))
    fail(errc::out_of_domain, "axis ", axis, " is outside 0..", Rank - 1, " for a grid of rank ", Rank);
  return detail::block_closing(whole_grid(points), static_cast<std::size_t>(axis), end_rows(points), false, solo);
}

}  // namespace

namespace detail {

void scale_points(Vec3* p, std::size_t count, int k) {
  const auto n = static_cast<long long>(count);
#pragma omp parallel for schedule(static) if (count >= parallel_min_work)
  for (long long i = 0; i < n; ++i) p[i] = ldexp(p[i], k);
}

int grid_degree(const std::optional<int>& degree, std::size_t count, const char* where) {
  return resolve_degree(degree, count, 0, where);
}

int block_shift(const GridBlock& b, const RowTeam& team) { return extreme_shift(b, team); }

void check_finite(const GridBlock& b) { check_block_finite(b); }

AxisSolver factor_axis(const KnotVector& knots, std::span<const double> params, std::size_t a) {
  try {
    if (knots.periodic()) return factor_periodic_collocation(knots, params);
    return factor_collocation(knots, params);
  } catch (const error& e) {
    fail(e.code(), "along ", axis_name(static_cast<int>(a)), ": ", e.what());
  }
}

void solve_columns(const AxisSolver& lu, double* data, std::size_t n, std::size_t width, bool* non_finite) {
  const std::size_t shape[2] = {n, width};
  solve_axis(lu, data, shape, 2, 0, 1, true, non_finite);
}

Closing block_closing(const GridBlock& b, std::size_t axis, std::span<const Vec3* const> ends, bool refuse,
                      const RowTeam& team) {
  const GridShape g = grid_shape(b);
  const std::size_t M = g.row, n = g.n[axis];
  // The bounding-box diagonal of the whole grid; -max(-x) is min(x), bit for bit.
  auto diagonal = [&] {
    constexpr double inf = std::numeric_limits<double>::infinity();
    double box[6] = {-inf, -inf, -inf, -inf, -inf, -inf};  // -lo, hi
    for (std::size_t i = 0; i < b.count * M; ++i)
      for (int k = 0; k < 3; ++k) {
        box[k] = std::max(box[k], -b.data[i][k]);
        box[3 + k] = std::max(box[3 + k], b.data[i][k]);
      }
    team.max(box);
    return norm(Vec3{box[3], box[4], box[5]} - Vec3{-box[0], -box[1], -box[2]});
  };
  auto where_flat = [&](std::size_t flat) {
    std::string idx;
    for (std::size_t a = g.rank, rest = flat; a-- > 0; rest /= g.n[a]) idx = cat("[", rest % g.n[a], "]", idx);
    return cat("point ", idx, ", the last along ", axis_name(static_cast<int>(axis)), ",");
  };
  if (axis == 0) {  // every process has the rows it looks at: each finds the same
    auto point = [&](std::size_t l, std::size_t k) -> const Vec3& {
      return (k == 0 ? ends[0] : k == 1 ? ends[1] : k + 2 == n ? ends[2] : ends[3])[l];
    };
    auto where = [&](std::size_t l) { return where_flat((n - 1) * M + l); };
    Closing c;
    team.run([&] {
      c = refuse ? find_closing(M, n, point, diagonal, where) : line_ending(M, n, point, diagonal).closing;
    });
    return c;
  }
  std::size_t inner = 1;
  for (std::size_t a = axis + 1; a < g.rank; ++a) inner *= g.n[a];
  auto index = [&](std::size_t l, std::size_t k) { return (l / inner) * n * inner + k * inner + l % inner; };
  auto point = [&](std::size_t l, std::size_t k) -> const Vec3& { return b.data[index(l, k)]; };
  auto where = [&](std::size_t l) { return where_flat(b.first * M + index(l, n - 1)); };
  const std::size_t lines = b.count * M / n, first_line = b.first * M / n;
  if (!refuse) return line_ending(lines, n, point, diagonal, team, first_line).closing;
  return find_closing(lines, n, point, diagonal, where, team, first_line);
}

std::vector<std::vector<double>> block_parameters(const GridBlock& b, Parametrization param, const RowTeam& team,
                                                  std::size_t axes, bool along_u) {
  const std::size_t R = b.rank, M = b.row_size();
  // As grid_parameters_of: a grid of extreme scale is measured scaled by 2^-shift.
  const int shift = param == Parametrization::uniform ? 0 : extreme_shift(b, team);
  GridBlock s = b;
  std::vector<Vec3> scaled;
  if (shift != 0) {
    team.run([&] {
      check_block_finite(b);
      require_memory((b.count + 3) * M, sizeof(Vec3), "a scaled copy of the grid");
    });
    scaled.resize((b.count + 3) * M);
    Vec3* at = scaled.data();
    auto copy = [&](const Vec3* from, std::size_t rows) {
      Vec3* to = at;
      if (from != nullptr) std::copy_n(from, rows * M, to);
      at += rows * M;
      return to;
    };
    s.data = copy(b.data, b.count);
    s.before = b.first > 0 ? copy(b.before, 1) : nullptr;
    s.row0 = copy(b.row0, 1);
    s.last = copy(b.last, 1);
    scale_points(scaled.data(), static_cast<std::size_t>(at - scaled.data()), -shift);
  }
  const GridChords chords(s, param, {}, team);
  std::vector<std::vector<double>> t(R);
  std::vector<double> steps(s.count, 0.0);
  if (chords.uses_chords() && along_u) {
    std::vector<double> scratch(M);
    for (std::size_t k = s.first == 0 ? 1 : 0; k < s.count; ++k)
      steps[k] = chords.row_step(k == 0 ? s.before : s.data + (k - 1) * M, s.data + k * M, scratch.data());
  }
  const std::vector<double> all_steps = along_u ? team.gather(steps) : std::vector<double>{};
  team.run([&] {
    if (along_u) t[0] = chords.u_parameters(all_steps);
    for (std::size_t a = 1; a < std::min(R, axes); ++a) t[a] = chords.in_row_parameters(a);
  });
  return t;
}

RowSolution solve_rows(const GridBlock& b, std::span<const int> p, Parametrization param, std::span<const bool> periodic,
                       const RowTeam& team) {
  const std::size_t R = b.rank, M = b.row_size();
  std::array<bool, 3> closed{};
  for (std::size_t a = 0; a < R; ++a) closed[a] = periodic[a];
  const GridChords chords(b, param, closed, team);
  team.run([&] { chords.check_lines(); });

  RowSolution r;
  r.params.resize(R);
  std::vector<AxisSolver> lu;
  std::vector<KnotVector> row_knots;
  team.run([&] {  // the same on every process
    for (std::size_t a = 1; a < R; ++a) {
      r.params[a] = chords.in_row_parameters(a);
      row_knots.push_back(axis_knots(r.params[a], p[a], periodic[a]));
      lu.push_back(factor_axis(row_knots.back(), r.params[a], a));
    }
  });

  // Pass 2: groups of rows, each thread a contiguous run of them. A row's step along
  // u needs the row before it as it was, so each thread keeps a copy of the last
  // row it has read before solving it (the block's first row: the row before the
  // block).
  std::vector<double> steps(b.count, 0.0);
  Vec3* data = b.data;
  const std::size_t groups = (b.count + rows_per_group - 1) / rows_per_group;
  std::array<std::size_t, 4> group_shape{};
  for (std::size_t a = 1; a < R; ++a) group_shape[a] = b.n[a];
  group_shape[R] = 3;
  const bool uses_chords = chords.uses_chords();
  // The threads' copies and the solves (a closed axis's) allocate. A thread that
  // failed still meets the barrier; the groups after a failed one are skipped.
  ParallelFailure failure;
#pragma omp parallel if (b.count * M >= parallel_min_work / 8)
  {
    const std::size_t nt = thread_count(), t = static_cast<std::size_t>(thread_index());
    const std::size_t g0 = groups * t / nt, g1 = groups * (t + 1) / nt;
    std::vector<Vec3> prev;
    std::vector<double> scratch;
    bool ready = false;
    failure.attempt(g0, [&] {
      prev.resize(uses_chords ? M : 0);
      scratch.resize(uses_chords ? M : 0);
      ready = true;
    });
    if (ready && uses_chords && g0 < g1) {
      if (g0 > 0) std::copy_n(data + (g0 * rows_per_group - 1) * M, M, prev.data());
      else if (b.first > 0) std::copy_n(b.before, M, prev.data());
    }
#pragma omp barrier
    auto gs = group_shape;
    for (std::size_t gi = g0; gi < g1 && ready; ++gi)
      failure.attempt(gi, [&] {
        const std::size_t r0 = gi * rows_per_group, r1 = std::min(b.count, r0 + rows_per_group);
        if (uses_chords) {
          for (std::size_t k = b.first + r0 == 0 ? 1 : r0; k < r1; ++k)
            steps[k] = chords.row_step(k == r0 ? prev.data() : data + (k - 1) * M, data + k * M, scratch.data());
          std::copy_n(data + (r1 - 1) * M, M, prev.data());
        }
        gs[0] = r1 - r0;
        for (std::size_t a = 1; a < R; ++a) solve_axis(lu[a - 1], &data[r0 * M].x, gs.data(), R + 1, a, 1, false);
      });
  }
  failure.rethrow();

  // Along u: every row's step, in row order.
  const std::vector<double> all_steps = team.gather(steps);
  team.run([&] {
    r.params[0] = chords.u_parameters(all_steps);
    r.knots.push_back(axis_knots(r.params[0], p[0], periodic[0]));
  });
  for (auto& k : row_knots) r.knots.push_back(std::move(k));
  return r;
}

// Leaves out the last line along `axis` of a grid (a closing line equal to the
// first): along u the storage just ends earlier; along an axis inside the rows each
// block of lines (one value of the axes before it) moves down to close the gap, in
// place. Blocks move in order within each thread's run; the first blocks of a run,
// whose places still hold the run before it, wait in a buffer until every thread
// has moved its others.
template <std::size_t Rank>
void drop_last_line(Grid<Vec3, Rank>& points, std::size_t axis) {
  auto shape = points.shape();
  std::size_t outer = 1, inner = 1;
  for (std::size_t a = 0; a < axis; ++a) outer *= shape[a];
  for (std::size_t a = axis + 1; a < Rank; ++a) inner *= shape[a];
  const std::size_t n = shape[axis], B = n * inner, K = (n - 1) * inner;
  auto values = std::move(points.values());
  Vec3* v = values.data();
  if (axis > 0) {
    // A thread that cannot hold its first blocks moves nothing but still meets the
    // barrier; the grid is then left empty, the values lost.
    detail::ParallelFailure failure;
#pragma omp parallel if (values.size() >= detail::parallel_min_work)
    {
      const std::size_t nt = detail::thread_count(), t = static_cast<std::size_t>(detail::thread_index());
      const std::size_t a = outer * t / nt, b = outer * (t + 1) / nt;
      // Blocks r with r·K < a·B land where the runs before this one still are.
      const std::size_t late = std::min(b, std::max(a, (a * B + K - 1) / K));
      std::vector<Vec3> held;
      bool ready = false;
      failure.attempt(t, [&] {
        held.assign(v + a * B, v + late * B);
        ready = true;
      });
      if (ready)
        for (std::size_t r = std::max<std::size_t>(late, 1); r < b; ++r) std::copy_n(v + r * B, K, v + r * K);
#pragma omp barrier
      if (ready)
        for (std::size_t r = a; r < late; ++r) std::copy_n(held.data() + (r - a) * B, K, v + r * K);
    }
    if (failure.failed()) {
      points = Grid<Vec3, Rank>();
      failure.rethrow();
    }
  }
  values.resize(outer * K);
  shape[axis] = n - 1;
  points = Grid<Vec3, Rank>(shape, std::move(values));
}

// Re-anchors a closed axis of even degree at its first parameter (seam_insertion on
// every line along it): one more control point along the axis.
template <std::size_t Rank>
void insert_seam(Grid<Vec3, Rank>& points, std::size_t axis, KnotVector& knots, double first) {
  SeamInsertion seam = seam_insertion(knots, first);
  auto shape = points.shape();
  std::size_t outer = 1, inner = 1;
  for (std::size_t a = 0; a < axis; ++a) outer *= shape[a];
  for (std::size_t a = axis + 1; a < Rank; ++a) inner *= shape[a];
  const std::size_t n = shape[axis], n1 = seam.rows.size();
  shape[axis] = n1;
  require_memory(Grid<Vec3, Rank>::count(shape), sizeof(Vec3), "a closed grid's control points");
  Grid<Vec3, Rank> out(shape, for_overwrite);
  const Vec3* in = points.data();
  Vec3* o = out.data();
  const auto no = static_cast<long long>(outer);
#pragma omp parallel for schedule(static) if (points.size() >= detail::parallel_min_work)
  for (long long oi = 0; oi < no; ++oi) {
    const auto b = static_cast<std::size_t>(oi);
    for (std::size_t j = 0; j < n1; ++j) {
      const auto& r = seam.rows[j];
      const Vec3* x = in + (b * n + r.x) * inner;
      const Vec3* y = in + (b * n + r.y) * inner;
      Vec3* d = o + (b * n1 + j) * inner;
      for (std::size_t i = 0; i < inner; ++i) d[i] = r.alpha * x[i] + (1.0 - r.alpha) * y[i];
    }
  }
  points = std::move(out);
  knots = std::move(seam.knots);
}

template void drop_last_line<2>(Grid<Vec3, 2>&, std::size_t);
template void drop_last_line<3>(Grid<Vec3, 3>&, std::size_t);
template void insert_seam<2>(Grid<Vec3, 2>&, std::size_t, KnotVector&, double);
template void insert_seam<3>(Grid<Vec3, 3>&, std::size_t, KnotVector&, double);

// The B-splines of solved control nets: the scan for NaN and infinities is left out
// when the solve has made it.
struct SolvedNet {
  static BSplineSurface surface(KnotVector ku, KnotVector kv, PointGrid cp, bool finite) {
    return {std::move(ku), std::move(kv), std::move(cp), {}, !finite};
  }
  static BSplineVolume volume(KnotVector ku, KnotVector kv, KnotVector kw, PointGrid3 cp, bool finite) {
    return {std::move(ku), std::move(kv), std::move(kw), std::move(cp), {}, !finite};
  }
};

}  // namespace detail

namespace {

// The tensor-product interpolation behind surfaces and volumes, in the
// three passes described above. The data become the control points.
template <std::size_t Rank>
GridSolution solve_grid(Grid<Vec3, Rank>& points, const std::array<std::optional<int>, Rank>& degree,
                        Parametrization param, const progress_callback& progress, const char* what,
                        const std::array<bool, Rank>& periodic) {
  auto dims = [&](bool wanted) {  // "2 x 2 x 2" or the actual "nu x nv x nw"
    std::string s;
    for (std::size_t a = 0; a < Rank; ++a) s += detail::cat(a ? " x " : "", wanted ? std::size_t{2} : points.shape()[a]);
    return s;
  };
  if (std::any_of(points.shape().begin(), points.shape().end(), [](std::size_t n) { return n < 2; }))
    fail(errc::too_few_points, what, " interpolation needs at least ", dims(true), " points, got ", dims(false));
  // Closed directions: a last line repeating the first is left out.
  std::array<bool, Rank> dropped{};
  for (std::size_t a = 0; a < Rank; ++a)
    if (periodic[a])
      if (const Closing c = detail::block_closing(whole_grid(points), a, end_rows(points), true, solo); c.dropped) {
        detail::drop_last_line(points, a);
        dropped[a] = true;
      }
  const auto& shape = points.shape();
  static constexpr const char* in_axis[3] = {" in u", " in v", " in w"};
  static constexpr const char* around_axis[3] = {" around u (closed)", " around v (closed)", " around w (closed)"};
  std::array<int, Rank> p{};
  for (std::size_t a = 0; a < Rank; ++a) p[a] = resolve_degree(degree[a], shape[a], 0, periodic[a] ? around_axis[a] : in_axis[a]);
  if (progress) progress(0.0);

  // Passes 1 and 2, the knots and factorizations of the axes inside the rows.
  const GridShape g = grid_shape(shape);
  const GridBlock block = whole_grid(points);
  const int shift = param == Parametrization::uniform ? 0 : extreme_shift(block, solo);
  if (shift != 0) {
    check_grid_finite(points.data(), g);  // before scaling: the message shows the point as given
    scale_points(points.data(), points.size(), -shift);
  }
  detail::RowSolution rows = detail::solve_rows(block, p, param, periodic, solo);
  if (progress) progress(0.6);

  // Pass 3: along u.
  GridSolution r{std::move(rows.knots), std::move(rows.params)};
  const AxisSolver lu0 = detail::factor_axis(r.knots[0], r.params[0], 0);
  Vec3* data = points.data();
  // The solution is looked at for NaN and infinities as it is made (a solve can
  // overflow), so that the B-spline need not read it again; a solution scaled back,
  // or re-anchored at a seam, is read again there.
  bool non_finite = true;
  detail::solve_columns(lu0, &data->x, g.n[0], 3 * g.row, &non_finite);
  r.finite = !non_finite && shift == 0;
  if (shift != 0) scale_points(data, points.size(), shift);
  // Closed axes of even degree start their period at their first parameter.
  for (std::size_t a = 0; a < Rank; ++a)
    if (periodic[a] && p[a] % 2 == 0) {
      detail::insert_seam(points, a, r.knots[a], r.params[a].front());
      r.finite = false;
    }
  for (std::size_t a = 0; a < Rank; ++a)
    if (dropped[a]) r.params[a].push_back(r.params[a].front() + 1.0);
  if (progress) progress(1.0);
  return r;
}

}  // namespace

Closing grid_closing(const PointGrid& points, int axis) { return grid_closing_of(points, axis); }
Closing grid_closing(const PointGrid3& points, int axis) { return grid_closing_of(points, axis); }

SurfaceInterpolation interpolate_surface(PointGrid points, const SurfaceInterpolationOptions& options) {
  GridSolution s = solve_grid<2>(points, {options.degree_u, options.degree_v}, options.param, options.progress, "surface",
                                 options.periodic);
  return {detail::SolvedNet::surface(std::move(s.knots[0]), std::move(s.knots[1]), std::move(points), s.finite),
          std::move(s.params[0]), std::move(s.params[1])};
}

VolumeInterpolation interpolate_volume(PointGrid3 points, const VolumeInterpolationOptions& options) {
  GridSolution s = solve_grid<3>(points, {options.degree_u, options.degree_v, options.degree_w}, options.param,
                                 options.progress, "volume", options.periodic);
  return {detail::SolvedNet::volume(std::move(s.knots[0]), std::move(s.knots[1]), std::move(s.knots[2]),
                                    std::move(points), s.finite),
          std::move(s.params[0]), std::move(s.params[1]), std::move(s.params[2])};
}

}  // namespace interpatch
