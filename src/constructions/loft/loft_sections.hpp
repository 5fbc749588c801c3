#pragma once
// The sections of a loft before they are made compatible (loft_sections.cpp): each
// over [0, 1], closed or open, turned round and (closed) restarted so that it follows
// the section before without twisting.

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/network.hpp"

namespace interpatch::detail {

/// C(1 − t) over [0, 1], for a curve over [0, 1]: knots mirrored, control points
/// (and weights) in the other order. A periodic curve stays periodic.
BSplineCurve reversed_curve(const BSplineCurve& c);

/// C(t + s), t in [0, 1), of a closed curve over [0, 1], s in [0, 1): s becomes a knot
/// (inserted, if it is not one, up to multiplicity p for an open-knotted curve), the
/// knots and control points start there. A periodic curve stays periodic. An
/// open-knotted one (its ends within the tolerance of each other) gets its old ends as
/// one control point, their midpoint, at a knot of multiplicity p: it moves by at most
/// half the gap of its ends.
BSplineCurve restarted_curve(const BSplineCurve& c, double s);

/// A section prepared: over [0, 1], turned and restarted as it is used.
struct PreparedSection {
  BSplineCurve curve;
  std::optional<BSplineCurve> tangent;  ///< ∂S/∂v along it, turned and restarted alike
  bool closed = false;
  bool reversed = false;
  double shift = 0;  ///< where u = 0 falls on the section (over [0, 1], after turning)
  double gap = 0;    ///< how far apart the ends of an open-knotted closed section are
};

/// How a section's own parameter follows the surface's u: over its own domain [lo, hi].
Reparametrization section_map(const PreparedSection& s, double lo, double hi);

/// Every section after the first turned round when it runs against the section before
/// (the summed squared distance between points at equal u, each section about its
/// centre, is smaller turned); closed ones also restarted at the candidate start where
/// that sum is least: its knots, and points cutting its spans evenly into 64 or more
/// candidates in all. Sections are over [0, 1]; `closed` says whether they are.
void align_sections(std::vector<PreparedSection>& sections, bool closed);

}  // namespace interpatch::detail
