// approximate_curve, approximate_surface and approximate_volume: the data scaled and
// checked, a closed direction's closing line left out, the fit of approx_whole.hpp
// (to a tolerance by approx_tolerance.hpp), its report, and the checks every result
// passes on the finished spline.

#include "interpatch/approximate.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_request.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/approximate/approx_tolerance.hpp"
#include "constructions/approximate/approx_whole.hpp"

namespace interpatch::detail::approx {

[[noreturn]] void refuse_closing_gap(std::size_t a) {
  fail(errc::closing_gap, "the last line of points along ", axis_name(a),
       " nearly repeats the first: repeat the first line exactly, or leave the last one out");
}

namespace {

template <std::size_t R>
struct Result {
  Fit<R> fit;
  ApproximationReport report;
  Data<R> data;  // the points fitted (a closed direction's closing line left out)
};

template <std::size_t R>
Result<R> approximate(Data<R> d, const ApproximationOptions<R>& o, const char* what) {
  check_request<R>(o, d.shape, what);

  // Missing points, weights.
  const std::size_t total = d.points.size();
  if (!o.weights.empty()) {
    check_weights<R>(o.weights, d.shape);
    d.weight.assign(o.weights.values().begin(), o.weights.values().end());
  }
  for (std::size_t i = 0; i < total; ++i) {
    const Vec3& q = d.points.data()[i];
    if (is_missing(q)) {
      if (d.weight.empty()) d.weight.assign(total, 1.0);
      d.weight[i] = 0;
      ++d.missing;
    } else if (!is_finite(q)) {
      fail(errc::not_finite, "point ", index_text<R>(i, d.shape), " is ", q, " (NaN marks a missing point; infinity is refused)");
    }
  }
  d.weight_sum = 0;
  d.present = 0;
  for (std::size_t i = 0; i < total; ++i)
    if (d.w(i) > 0) {
      d.weight_sum += d.w(i);
      ++d.present;
    }
  if (d.present == 0)
    fail(errc::too_few_points, "all ", total, " points are missing or have weight 0: there is nothing to approximate");
  // Data on a single line across a direction leave the fit free along it (nothing
  // fixes its slope there).
  if (!d.weight.empty())
    for (std::size_t a = 0; a < R; ++a) {
      std::size_t inner = 1;
      for (std::size_t x = a + 1; x < R; ++x) inner *= d.shape[x];
      std::vector<bool> has(d.shape[a], false);
      for (std::size_t i = 0; i < total; ++i)
        if (d.weight[i] > 0) has[(i / inner) % d.shape[a]] = true;
      if (std::count(has.begin(), has.end(), true) < 2)
        fail(errc::too_few_points, "along ", axis_name(a), " only one line of points holds data (the others are missing ",
             "or have weight 0): an approximation needs two");
    }
  if (!d.weight.empty() && d.missing == 0 &&
        std::all_of(d.weight.begin(), d.weight.end(), [&](double w) { return w == d.weight.front(); })) {
    d.weight.clear();  // equal weights: the plain least-squares fit
    d.weight_sum = static_cast<double>(total);
  }

  Result<R> res;
  Fit<R>& f = res.fit;
  for (std::size_t a = 0; a < R; ++a) {
    set_degree<R>(f.axes[a], o, a, d.shape[a]);
    f.axes[a].t = axis_parameters<R>(d, a, o.param, f.axes[a].periodic);
  }
  check_control_points<R>(f.axes, o);
  if (o.progress) o.progress(0.0);

  if (o.tolerance) {
    solve_tolerance<R>(f, Whole<R>{nullptr, &d, std::nullopt}, *o.tolerance, o.progress);
  } else {
    set_fit_knots<R>(f.axes, o);
    if (o.auto_smoothing) solve_gcv<R>(f, d);
    else solve_once<R>(f, d, o.smoothing);
  }

  // The report.
  const Residuals<R> r = residuals<R>(f.axes, d, f.cp);
  ApproximationReport& rep = res.report;
  rep.max_error = r.max;
  rep.max_error_at = unflatten<R>(r.worst, d.shape);
  rep.rms_error = std::sqrt(r.sum_sq / static_cast<double>(d.present));
  for (std::size_t a = 0; a < R; ++a) rep.control_points.push_back(f.axes[a].c);
  rep.lambda = f.lambda;
  rep.missing = d.missing;
  rep.fits = f.fits;
  if (o.progress) o.progress(1.0);
  res.data = std::move(d);
  return res;
}

template <std::size_t R>
Grid<Vec3, R> control_net(const Fit<R>& f) {
  typename Grid<Vec3, R>::shape_type shape{};
  for (std::size_t a = 0; a < R; ++a) shape[a] = static_cast<std::size_t>(f.axes[a].c);
  Grid<Vec3, R> g(shape, for_overwrite);
  std::copy_n(f.cp.data(), f.cp.size(), &g.data()->x);
  return g;
}

// A closed direction's last line, when it repeats the first (interpolation's rule),
// is left out, with its weights.
template <std::size_t R>
Data<R> closed_data(Grid<Vec3, R> points, Grid<double, R>& weights, const std::array<bool, R>& periodic) {
  Data<R> d;
  for (std::size_t a = 0; a < R; ++a) {
    if (!periodic[a] || points.extent(a) < 3) continue;
    if (std::any_of(points.values().begin(), points.values().end(), is_missing)) break;
    Closing c;
    if constexpr (R == 1) c = closing_point(std::span<const Vec3>(points.data(), points.size()));
    else c = grid_closing(points, static_cast<int>(a));
    if (c.nearly) refuse_closing_gap(a);
    if (!c.dropped) continue;
    cut_last_line<Vec3, R>(points, a);
    if (!weights.empty()) cut_last_line<double, R>(weights, a);
  }
  for (std::size_t a = 0; a < R; ++a) d.shape[a] = points.extent(a);
  d.points = std::move(points);
  return d;
}

// Finite points scaled by 1 / unit (NaN marks a missing point; infinite ones are kept
// for approximate() to name as given).
template <std::size_t R>
void scale_points(Grid<Vec3, R>& points, double factor) {
  for (Vec3& q : points.values())
    if (is_finite(q)) q = q * factor;
}

template <std::size_t R>
Result<R> run(Grid<Vec3, R> points, const ApproximationOptions<R>& options, const char* what) {
  check_request<R>(options, [&] {
    Shape<R> shape{};
    for (std::size_t a = 0; a < R; ++a) shape[a] = points.extent(a);
    return shape;
  }(), what);
  // Data beyond 2^±64 are fitted in a power of two of their own size (exact both ways).
  const double unit = detail::approximation_unit(detail::largest_coordinate(points.values()));
  const bool closed = std::any_of(options.periodic.begin(), options.periodic.end(), [](bool b) { return b; });
  // A copy of the options (and their weights) only where they change.
  std::optional<ApproximationOptions<R>> changed;
  if (unit != 1 || closed) changed = options;
  if (unit != 1) {
    scale_points<R>(points, 1 / unit);
    // Below the smallest double in the data's unit it could not be met anyway: the
    // refinement goes to its finest fit and says so.
    if (changed->tolerance)
      changed->tolerance = std::max(*changed->tolerance / unit, std::numeric_limits<double>::denorm_min());
  }
  const auto given = points.shape();
  Data<R> d;
  if (closed) {
    d = closed_data<R>(std::move(points), changed->weights, changed->periodic);
  } else {
    for (std::size_t a = 0; a < R; ++a) d.shape[a] = points.extent(a);
    d.points = std::move(points);
  }
  Result<R> r = approximate<R>(std::move(d), changed ? *changed : options, what);
  // A closing line left out has the parameter one period after the first line's.
  for (std::size_t a = 0; a < R; ++a)
    if (r.fit.axes[a].n < given[a]) r.fit.axes[a].t.push_back(r.fit.axes[a].t.front() + 1.0);
  if (unit != 1) {
    for (double& x : r.fit.cp) x *= unit;
    scale_points<R>(r.data.points, unit);
    r.report.max_error *= unit;
    r.report.rms_error *= unit;
  }
  return r;
}

// The fitted data as the checks of approx_check.hpp take them.
template <std::size_t R>
detail::ApproxData check_data(const Data<R>& d) {
  return {std::vector<std::size_t>(d.shape.begin(), d.shape.end()), std::span<const Vec3>(d.points.data(), d.points.size()),
          std::span<const double>(d.weight)};
}

// The checks every result passes (docs/spec-format.md, "approximate"): a sane
// control net before the spline is made of it.
template <std::size_t R>
void check_net(const Result<R>& r, const Grid<Vec3, R>& net, const char* what) {
  std::vector<std::size_t> shape;
  for (std::size_t a = 0; a < R; ++a) shape.push_back(static_cast<std::size_t>(r.fit.axes[a].c));
  detail::check_approx_net(std::span<const Vec3>(net.data(), net.size()), shape, check_data<R>(r.data), what);
}

// Then the distances, measured on the finished spline by its own evaluator: the
// report's largest one, and the tolerance kept or refused.
template <std::size_t R>
void check_distance(Result<R>& r, const detail::ApproxDistance& e, const ApproximationOptions<R>& o) {
  r.report.max_error = e.max;
  r.report.max_error_at = unflatten<R>(e.worst, r.data.shape);
  if (o.tolerance) detail::check_approx_tolerance(e, *o.tolerance, check_data<R>(r.data), r.report.control_points);
}

}  // namespace

}  // namespace interpatch::detail::approx

namespace interpatch {

CurveApproximation approximate_curve(std::span<const Vec3> points, const CurveApproximationOptions& options) {
  using namespace detail::approx;
  Grid<Vec3, 1> g({points.size()}, std::vector<Vec3>(points.begin(), points.end()));
  Result<1> r = run<1>(std::move(g), options, "curve");
  Grid<Vec3, 1> net = control_net<1>(r.fit);
  check_net<1>(r, net, "curve approximation");
  std::vector<Vec3> cp(net.values().begin(), net.values().end());
  Axis& u = r.fit.axes[0];
  BSplineCurve curve(u.knots, std::move(cp));
  check_distance<1>(r, detail::approx_distance(curve, u.t, check_data<1>(r.data)), options);
  return {std::move(curve), std::move(u.t), std::move(r.report)};
}

SurfaceApproximation approximate_surface(PointGrid points, const SurfaceApproximationOptions& options) {
  using namespace detail::approx;
  Result<2> r = run<2>(std::move(points), options, "surface");
  PointGrid net = control_net<2>(r.fit);
  check_net<2>(r, net, "surface approximation");
  auto& ax = r.fit.axes;
  BSplineSurface surface(ax[0].knots, ax[1].knots, std::move(net));
  check_distance<2>(r, detail::approx_distance(surface, ax[0].t, ax[1].t, check_data<2>(r.data)), options);
  return {std::move(surface), std::move(ax[0].t), std::move(ax[1].t), std::move(r.report)};
}

VolumeApproximation approximate_volume(PointGrid3 points, const VolumeApproximationOptions& options) {
  using namespace detail::approx;
  Result<3> r = run<3>(std::move(points), options, "volume");
  PointGrid3 net = control_net<3>(r.fit);
  check_net<3>(r, net, "volume approximation");
  auto& ax = r.fit.axes;
  BSplineVolume volume(ax[0].knots, ax[1].knots, ax[2].knots, std::move(net));
  check_distance<3>(r, detail::approx_distance(volume, ax[0].t, ax[1].t, ax[2].t, check_data<3>(r.data)), options);
  return {std::move(volume), std::move(ax[0].t), std::move(ax[1].t), std::move(ax[2].t), std::move(r.report)};
}

}  // namespace interpatch
