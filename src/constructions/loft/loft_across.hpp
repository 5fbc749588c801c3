#pragma once
// What a loft of curves (loft.cpp) and a loft of surfaces (loft_volume.cpp) share
// (loft_across.cpp): the places of the sections across, and one collocation system
// across them solved for every control point at once.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"
#include "linalg/collocation.hpp"

namespace interpatch::detail {

/// The places v_k of n sections across: the chord (or its root, or uniform steps)
/// between point(k, i) and point(k + 1, i), i one of `lines` lines across (points at
/// equal parameters of the sections), each line scaled to run from 0 to 1 and the lines
/// averaged; lines of zero length (an apex the sections share) are left out. Periodic:
/// the closing chord too, v in [0, 1). `largest`: the data's largest coordinate, whose
/// exponent keeps centripetal places exact under scaling by powers of two (root_scale).
/// name(k) names section k in messages.
/// @throws error zero_chord (two neighbouring sections at one place on every line).
std::vector<double> across_params(std::size_t n, std::size_t lines,
                                  const std::function<Vec3(std::size_t, std::size_t)>& point, Parametrization param,
                                  bool periodic, double largest, const std::function<std::string(std::size_t)>& name);

/// Given places: n of them, finite, increasing, from 0 to 1 (periodic: to below 1).
/// at(k) names entry k, `whole` the array.
/// @throws error size_mismatch, not_finite, non_increasing, out_of_domain.
void check_given_params(const std::vector<double>& v, std::size_t n, bool periodic,
                        const std::function<std::string(std::size_t)>& at, const char* whole);

/// 4 points of every span of a knot vector over [0, 1] (its distinct breaks), and 1:
/// where a loft checks its sections.
std::vector<double> span_samples(const KnotVector& k);

/// `rows` holds one block of `width` doubles per condition of `conds` (a value, or a
/// first derivative where derivative[k], at v_k; in the order Q_0, D_0, ..., D_{n−1},
/// Q_{n−1}); solved in place into the control points across, degree q, and their knots
/// returned: open (averaged knots, each derivative site counted twice) or periodic (a
/// periodic spline through the values; for an even q one more row, its domain starting
/// at v_0).
KnotVector interpolate_across(std::vector<double>& rows, std::size_t width, const std::vector<double>& v,
                              const std::vector<bool>& derivative, const std::vector<Condition>& conds, int q,
                              bool periodic);

}  // namespace interpatch::detail
