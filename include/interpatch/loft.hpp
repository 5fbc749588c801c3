#pragma once
/// @file loft.hpp
/// A surface through a row of section curves (skinning, The NURBS Book §10.3): the
/// sections made compatible (one degree, one knot vector), closed ones turned and
/// shifted so that the surface does not twist, then interpolated across. A volume
/// through a row of section surfaces likewise.

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/network.hpp"

namespace interpatch {

struct LoftOptions {
  /// Degree across the sections (v); lowered to the count of conditions − 1 when there
  /// are too few sections (N sections, and the tangents given, count).
  int degree = 3;
  /// How the sections' parameters v_k follow from the distances between them, measured
  /// between points at equal u and averaged along u.
  Parametrization param = Parametrization::chord;
  /// Given v_k instead: increasing from 0 to 1, or for a periodic loft from 0 to below 1
  /// (1 is the first section again).
  std::vector<double> params;
  /// Closed across the sections: the first section follows the last (a ring of
  /// sections makes a torus), C^(q−1) across that seam too.
  bool periodic = false;
  /// How close the ends of an open-knotted section must be for it to be closed, and how
  /// far a section may move when the merged knots would grow too many and the sections
  /// are re-expressed on common knots. Unset: 1e-7 of the diagonal of the sections'
  /// control points (or 16 units in the last place of the largest coordinate, where
  /// that is more: a small part far from the origin).
  std::optional<double> tolerance;
  /// ∂S/∂v along sections: none; two, at the first and the last section; or one per
  /// section, where an empty entry leaves that section free. Polynomial curves in any
  /// form, each over its own domain, taken at the same u as its section (turned and
  /// shifted with it: a closed section's tangent is periodic when its section is, and
  /// its ends meet otherwise). Not for periodic lofts, nor for rational sections; a
  /// degree of 2 or more across. The tangents count with the sections for degree_u
  /// and the knots.
  std::vector<std::optional<BSplineCurve>> tangents;
  /// Curves that run across the sections, from the first to the last. With them the
  /// loft is the Gordon surface of the network (curve_network) whose u-curves are the
  /// sections and whose v-curves are the guides: curves in any order and direction,
  /// crossing at different parameters, re-expressed to cross at common ones; `param`
  /// and `degree` then come from the network (`params` gives the sections' v), and
  /// tangents are not taken.
  std::vector<BSplineCurve> guides;
  /// Messages name sections, tangents and given parameters as "sections[3]",
  /// "tangents[1]", "params[2]"; with spec_pointers, by JSON Pointer into a loft spec:
  /// "/sections/3", "/tangents/1", "/param/2".
  bool spec_pointers = false;
};

/// How the loft used one of its sections.
struct LoftSectionReport {
  bool closed = false;    ///< a periodic curve, or one whose ends meet within the tolerance
  bool reversed = false;  ///< turned round to run with the section before
  /// Surface parameter u → the section's own parameter: S(u, v_k) = C_k(map(u)).
  /// For a closed section map(0) is where the surface's seam falls on it.
  Reparametrization map;
  /// Largest |S(u, v_k) − C_k(map(u))| measured at 4 points of every span of the
  /// surface in u and at the section's own knots: rounding, or the re-expression's
  /// deviation when the sections were re-expressed.
  double deviation = 0;
  /// With a tangent: the largest |∂S/∂v(u, v_k) − T_k(u)| measured at 9 points.
  double tangent_deviation = 0;
};

/// What loft found and did.
struct LoftReport {
  std::vector<double> params;  ///< v_k of each section (periodic: the first section again at 1)
  std::vector<LoftSectionReport> sections;
  bool closed = false;        ///< the sections are closed: the surface is closed in u
  int degree_u = 0;           ///< the sections' common degree
  int degree_v = 0;           ///< the degree across, as used
  /// True when the merged knots would have exceeded 4 times the largest section's
  /// and the sections were re-expressed on common knots within the tolerance (on fewer
  /// knots than merging makes; otherwise they are merged).
  bool reexpressed = false;
  /// With guides: how each guide was used (its map runs along v), and what the network found.
  std::vector<LoftSectionReport> guides;
  std::optional<NetworkReport> network;
  std::size_t merged_knots = 0;   ///< the size of the knot vector merging makes (or would have made)
  std::size_t section_knots = 0;  ///< the largest section's knot count, at the common degree
  double max_deviation = 0;       ///< the largest section deviation
  double tolerance = 0;           ///< LoftOptions::tolerance in effect
  double diagonal = 0;            ///< of the sections' control points' bounding box
};

struct LoftSurface {
  BSplineSurface surface;  ///< over [0, 1]²: u along the sections, v across them
  LoftReport report;
};

/// The surface through N ≥ 2 section curves: S(u, v_k) = C_k(map_k(u)), C^(q−1) in v.
/// Each section is used over its own domain mapped onto [0, 1]. Sections are all open
/// or all closed (periodic, or ends within the tolerance). Every section after the
/// first is turned round when it runs against the one before; closed ones also start
/// where the summed squared distance, between points at equal u of the two sections
/// taken about their centres, is least, among the section's knots and points that cut
/// its spans evenly (64 or more candidates), so the surface does not twist and sections given with other
/// starts at those points or the other way round make the same surface. The first
/// section sets the seam and the direction. Periodic sections make a surface periodic
/// in u; closed open-knotted ones (or a mix of both kinds, all then taken open-knotted)
/// a surface whose edges u = 0 and u = 1 meet; restarting such a section joins its
/// ends at their midpoint, which moves it by half their gap at most.
/// Every result is checked before it is returned: each section within rounding (or
/// the re-expression's tolerance) of the surface along v = v_k.
///
/// Example: rings around z, the middle one given from another start.
/// @code
///   using namespace interpatch;
///   auto ring = [](double r, double z, int start) {
///     std::vector<Vec3> p;
///     for (int i = 0; i < 8; ++i) {
///       const double a = 0.7853981633974483 * (i + start);  // 45° steps
///       p.push_back({r * std::cos(a), r * std::sin(a), z});
///     }
///     CurveInterpolationOptions closed;
///     closed.periodic = true;
///     return interpolate_curve(p, closed).curve;
///   };
///   std::vector<BSplineCurve> sections{ring(1, 0, 0), ring(0.8, 1, 3), ring(0.5, 2, 0)};
///   LoftSurface s = loft(sections);
///   Vec3 p = s.surface.point(0.25, s.report.params[1]);  // (0, 0.8, 1): the middle ring, not twisted
///   double seam = s.report.sections[1].map(0.0);           // 0.625: where u = 0 falls on it
/// @endcode
/// @throws error too_few_points (fewer than 2 sections), invalid_degree, not_finite,
///   closing_gap (closed and open sections mixed, naming both), zero_chord (two
///   sections at the same place everywhere), non_increasing, out_of_domain and
///   size_mismatch (given parameters), size_mismatch (tangents), wrong_type
///   (tangents of a periodic loft or of rational sections), tolerance_not_met (with
///   guides, a curve the surface departs from by more than 4 times the tolerance; sections
///   that cannot be re-expressed within the tolerance are merged instead), the errors of
///   curve_network with guides (network_gap, network_order), invalid_weight (rational
///   sections whose weights, interpolated across, fall to 0), ill_conditioned (a
///   section not reproduced).
[[nodiscard]] LoftSurface loft(std::span<const BSplineCurve> sections, const LoftOptions& options = {});

struct LoftVolumeOptions {
  /// Degree across the sections (w); lowered to N − 1 for N sections.
  int degree = 3;
  /// The places w_k from the distances between points at equal (u, v) of neighbouring
  /// sections, averaged over a 17 × 17 grid of (u, v).
  Parametrization param = Parametrization::chord;
  /// Given w_k instead: increasing from 0 to 1 (periodic: from 0 to below 1).
  std::vector<double> params;
  /// Closed across the sections: the first section follows the last.
  bool periodic = false;
  /// Messages name sections as "/sections/3" rather than "sections[3]" (a spec's).
  bool spec_pointers = false;
};

struct LoftVolumeReport {
  std::vector<double> params;       ///< w_k of each section (periodic: the first again at 1)
  std::array<int, 3> degree{0, 0, 0};
  /// Largest |V(u, v, w_k) − S_k(u, v)| of each section, at 4 × 4 points of every
  /// patch of the volume's (u, v) spans.
  std::vector<double> deviation;
  double max_deviation = 0;
  double diagonal = 0;  ///< of the sections' control points
};

struct LoftVolume {
  BSplineVolume volume;  ///< over [0, 1]³: u, v along the sections, w across them
  LoftVolumeReport report;
};

/// The volume through N ≥ 2 section surfaces: V(u, v, w_k) = S_k(u, v) to rounding,
/// C^(q−1) in w. Each section is used over its own domain mapped onto [0, 1]²; the
/// sections are raised to the highest degrees among them and their knots merged in u
/// and in v (they must be closed in the same directions), then interpolated across
/// control point by control point (homogeneous when rational). Checked before it is
/// returned: every section within rounding of the volume at w = w_k.
///
/// Example: a solid between a flat square and a bulged one above it.
/// @code
///   using namespace interpatch;
///   BSplineSurface floor = bilinear({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}).to_bspline();
///   BSplineSurface lid = bilinear({0, 0, 1}, {0, 1, 1}, {1, 0, 1}, {1, 1, 1}).to_bspline().elevated(1, 1);
///   LoftVolume body = loft_volume(std::vector<BSplineSurface>{floor, lid});
///   Vec3 p = body.volume.point(0.5, 0.5, 1.0);  // (0.5, 0.5, 1): the lid
///   int q = body.report.degree[2];              // 1: two sections, straight across
/// @endcode
/// @throws error too_few_points, invalid_degree, closing_gap (sections closed in
///   different directions), zero_chord, size_mismatch, non_increasing, out_of_domain
///   (given parameters), invalid_weight, ill_conditioned (a section not reproduced).
[[nodiscard]] LoftVolume loft_volume(std::span<const BSplineSurface> sections, const LoftVolumeOptions& options = {});

}  // namespace interpatch
