#pragma once
// The data parameters of each direction and the knots of the fit: evenly spread for
// a given number of control points, and split or tested one interval at a time as a
// fit to a tolerance grows them.

#include <cstddef>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"

namespace interpatch::detail::approx {

// Uniform parameters of n points: evenly spaced over [0, 1] (closed: n steps, the
// last one back to the first at 1).
std::vector<double> uniform_parameters(std::size_t n, bool closed);

// Parameters from the chords summed per step over the lines (sum[k]: step k to
// k + 1, used[k] lines adding to it).
std::vector<double> parameters_from_sums(std::vector<double> sum, const std::vector<std::size_t>& used, std::size_t n,
                                         std::size_t a, Parametrization param, bool closed);

// The chord from p0 to p1 added to a step's sum when both are present.
inline void add_chord(const Vec3& p0, const Vec3& p1, double& sum, std::size_t& used) {
  if (is_missing(p0) || is_missing(p1)) return;
  sum += distance(p0, p1);
  ++used;
}

// Knots of a clamped spline with the given interior knots over [t.front(), t.back()].
KnotVector clamped_knots(const Axis& ax, const std::vector<double>& interior);

// The interior knots (open) or the period's knots (closed) of `c` control points
// for least squares over the data parameters. Open: c parameters spread evenly over
// the data's order (linear between data parameters), and interpolation's knots
// averaged from them (The NURBS Book eq. 9.8): every basis function has data under
// the middle of its support, so the normal equations stay as well conditioned as
// interpolation's whatever c (The NURBS Book eq. 9.69 reaches condition numbers of
// 1e16 as c nears the point count, and a fit then swings between the data). With as
// many control points as data, interpolation's knots. Closed: evenly spaced in the
// data's order, shifted by half a step for an even degree.
std::vector<double> least_squares_breaks(const Axis& ax, int c);

KnotVector knots_from_breaks(const Axis& ax, const std::vector<double>& breaks);

// Whether the clamped knots of an open axis with interior knots `breaks` (sorted)
// meet the Schoenberg–Whitney condition on the lines that hold data: basis function
// j can be given its own line i_j, i_0 < i_1 < …, inside its support. Without it
// the least-squares system is singular (more control points than data somewhere).
// The smallest line that fits each function in turn is the best choice: the
// supports' ends rise with j.
bool whitney(const Axis& ax, const std::vector<double>& breaks, const std::vector<bool>& has_data);

// Splits knot interval k of an axis at the middle of the data in it, between two
// lines across the axis that hold data (a knot between missing lines would leave
// the fairness term alone to settle a control point there); false when it holds
// fewer than 2 such lines, when the direction has as many control points as data,
// or when the new knot would break the Schoenberg–Whitney condition (whitney).
bool split_interval(const Axis& ax, std::vector<double>& breaks, int k, const std::vector<bool>& has_data);

}  // namespace interpatch::detail::approx
