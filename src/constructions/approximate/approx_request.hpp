#pragma once
// What every approximation checks and sets before it fits: the request's options,
// each direction's degree, the count of control points, the weights, and the knots
// of a fit with a given number of control points; and a closed direction's
// closing line left out.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_knots.hpp"

namespace interpatch::detail::approx {

// Exactly one of the three ways, and enough points.
template <std::size_t R>
void check_request(const ApproximationOptions<R>& o, const Shape<R>& shape, const char* what) {
  // Exactly one of the three ways.
  const int ways = (o.control_points ? 1 : 0) + (o.tolerance ? 1 : 0) + ((o.smoothing || o.auto_smoothing) ? 1 : 0);
  if (ways != 1)
    fail(errc::wrong_type, what, " approximation takes exactly one of control_points, tolerance and smoothing, got ",
         ways);
  if (o.smoothing && o.auto_smoothing) fail(errc::wrong_type, "smoothing is either a number or auto, not both");
  if (o.tolerance && !(*o.tolerance > 0 && std::isfinite(*o.tolerance)))
    fail(errc::wrong_type, "tolerance ", *o.tolerance, " is not a positive distance");
  if (o.smoothing && !(*o.smoothing >= 0 && std::isfinite(*o.smoothing)))
    fail(errc::wrong_type, "smoothing ", *o.smoothing, " is not a non-negative number");
  for (std::size_t a = 0; a < R; ++a)
    if (shape[a] < 2)
      fail(errc::too_few_points, what, " approximation needs at least 2 points along ", axis_name(a), ", got ",
           shape[a]);
}

// Direction a of n data points: its degree, checked.
template <std::size_t R>
void set_degree(Axis& ax, const ApproximationOptions<R>& o, std::size_t a, std::size_t n) {
  ax.n = n;
  ax.periodic = o.periodic[a];
  const int p = o.degree[a] ? *o.degree[a] : std::min<int>(3, static_cast<int>(ax.n) - 1);
  if (p < 1 || p > max_degree)
    fail(errc::invalid_degree, "degree ", p, " along ", axis_name(a), " is outside 1..", max_degree);
  if (ax.n < static_cast<std::size_t>(p) + 1)
    fail(errc::too_few_points, "degree ", p, " along ", axis_name(a), " needs at least ", p + 1, " points, got ", ax.n);
  ax.p = p;
}

template <std::size_t R>
void check_control_points(const std::array<Axis, R>& axes, const ApproximationOptions<R>& o) {
  if (o.control_points)
    for (std::size_t a = 0; a < R; ++a) {
      const int c = (*o.control_points)[a];
      const Axis& ax = axes[a];
      if (c < ax.p + 1)
        fail(errc::too_few_points, c, " control points along ", axis_name(a), " are fewer than degree ", ax.p,
             " needs (", ax.p + 1, ")");
      if (static_cast<std::size_t>(c) > ax.n)
        fail(errc::too_few_points, c, " control points along ", axis_name(a), " are more than the ", ax.n,
             " data points there: least squares needs at least as many data as control points");
    }
}

// The knots of a fit with a given number of control points or a smoothing fit.
template <std::size_t R>
void set_fit_knots(std::array<Axis, R>& axes, const ApproximationOptions<R>& o) {
  for (std::size_t a = 0; a < R; ++a) {
    Axis& ax = axes[a];
    int c = 0;
    if (o.control_points) c = (*o.control_points)[a];
    else c = std::max(ax.p + 1, std::min(static_cast<int>(ax.n), smoothing_max_control_points));
    ax.set_knots(knots_from_breaks(ax, least_squares_breaks(ax, c)));
  }
}

// Weights of the shape of the points, finite and not negative.
template <std::size_t R>
void check_weights(const Grid<double, R>& weights, const Shape<R>& shape) {
  for (std::size_t a = 0; a < R; ++a)
    if (weights.extent(a) != shape[a])
      fail(errc::size_mismatch, "weights: ", weights.extent(a), " along ", axis_name(a), ", the points have ", shape[a]);
  for (std::size_t i = 0; i < weights.size(); ++i) {
    const double w = weights.values()[i];
    if (std::isnan(w) || std::isinf(w)) fail(errc::not_finite, "weight ", index_text<R>(i, shape), " is ", w);
    if (w < 0) fail(errc::invalid_weight, "weight ", index_text<R>(i, shape), " = ", w, " is negative");
  }
}

// A closed direction's last line that nearly repeats the first.
[[noreturn]] void refuse_closing_gap(std::size_t a);

// The grid without its last line along axis a.
template <class T, std::size_t R>
void cut_last_line(Grid<T, R>& g, std::size_t a) {
  auto shape = g.shape();
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= shape[x];
  for (std::size_t x = a + 1; x < R; ++x) inner *= shape[x];
  const std::size_t n = shape[a];
  shape[a] = n - 1;
  Grid<T, R> kept(shape, for_overwrite);
  for (std::size_t o = 0; o < outer; ++o) std::copy_n(g.data() + o * n * inner, (n - 1) * inner, kept.data() + o * (n - 1) * inner);
  g = std::move(kept);
}

}  // namespace interpatch::detail::approx
