#pragma once
/// @file grading.hpp
/// Graded sampling: the parameters of a mesh's nodes along each direction of a
/// surface or a volume, clustered at its ends as a viscous CFD mesh needs (a first
/// cell of a given physical length, a growth ratio) instead of even steps.

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "interpatch/surface.hpp"
#include "interpatch/volume.hpp"

namespace interpatch {

/// How the nodes of one direction are spread. With none of ratio, first and last
/// the nodes are at even parameter steps. Otherwise they follow a distribution in the
/// direction's mean arc length (the arc length along its lines, each scaled to 1,
/// averaged over a 9 × 9 set of lines): one end given (ratio, first or last) is a
/// geometric progression, both ends (first and last) Vinokur's two-sided stretching.
struct Grading {
  std::size_t count = 0;  ///< nodes along the direction, at least 2
  double ratio = 0;       ///< last cell over first (blockMesh's simpleGrading); 0: not given
  /// The physical length (chord) of the first (last) cell: the largest over the mesh's
  /// lines along this direction, so every first (last) cell is at most this long.
  /// 0: not given.
  double first = 0, last = 0;
  /// The largest ratio of two neighbouring cells along the direction's mean arc length
  /// (either way): a count that needs more is refused, naming the count that would do.
  double max_growth = 1.3;
  /// Whether any of ratio, first and last is given.
  [[nodiscard]] bool graded() const noexcept { return ratio != 0 || first != 0 || last != 0; }
};

/// The gradings of u, v and w (w unused for a surface).
using Sampling = std::array<Grading, 3>;

/// What a graded sampling achieved along one direction, measured on the mesh's own
/// lines (chords between neighbouring nodes).
struct GradingReport {
  double first = 0;   ///< the longest first cell
  double last = 0;    ///< the longest last cell
  double growth = 1;  ///< the largest ratio of neighbouring cells on one line, either way
};

/// The nodes' parameters, one list per direction (w empty for a surface), each
/// increasing from the domain's start to its end, and what they achieved. A batch
/// evaluator takes them as they are: `surface.evaluate(g.params[0], g.params[1])`,
/// `volume.evaluate_jacobians(g.params[0], g.params[1], g.params[2])`.
struct GradedParameters {
  std::array<std::vector<double>, 3> params;
  std::array<GradingReport, 3> report;
};

/// The graded nodes of a surface (directions u, v of `sampling`).
///
/// A first (last) length is met on the mesh itself: the largest first cell over every
/// line of the mesh is `first` to 1e-9 of it (or to the rounding of its coordinates,
/// 16 units in their last place, when that is more), and never more. Each direction's lines
/// are those through the other direction's nodes, so the directions are solved in
/// turn until their nodes stop moving.
///
/// Example: 41 nodes across a channel, the first cell 1e-3 long at its u = 0 wall.
/// @code
///   interpatch::Sampling s;
///   s[0] = {.count = 41, .first = 1e-3};
///   s[1] = {.count = 101};
///   interpatch::GradedParameters g = interpatch::graded_parameters(channel, s);
///   interpatch::PointGrid nodes = channel.evaluate(g.params[0], g.params[1]);
///   double achieved = g.report[0].first;  // 1e-3, to 1e-9 of it
/// @endcode
/// @throws error too_few_points (a count below 2, or too few nodes for the grading
///   within max_growth: the message names the count that would do), invalid_grading
///   (a ratio, first, last or max_growth that is not a positive finite number, max_growth
///   not above 1, ratio given with first or last, a first or last longer than its
///   direction, first and last together longer than it), and what the surface's
///   evaluation throws.
[[nodiscard]] GradedParameters graded_parameters(const Surface& surface, const Sampling& sampling);

/// The same for a volume, directions u, v and w.
[[nodiscard]] GradedParameters graded_parameters(const Volume& volume, const Sampling& sampling);

}  // namespace interpatch
