#pragma once
/// @file io/step.hpp
/// The exact form as a STEP file (ISO 10303-21 text, AP214 automotive_design
/// schema): what `interpatch build -o x.step` writes for CAD systems.

#include <filesystem>
#include <ostream>
#include <string>

#include "interpatch/io/spec.hpp"

namespace interpatch::io {

/// What goes into the STEP header and product entities besides the geometry.
struct StepOptions {
  /// The product's name (PRODUCT id and name) and FILE_NAME's name.
  std::string name = "interpatch";
  /// FILE_NAME's time stamp, ISO 8601 ("2024-05-01T12:00:00"); empty: the current
  /// UTC time. A fixed stamp makes the output reproducible byte for byte.
  std::string time_stamp;
};

/// Writes the exact form as a STEP AP214 file, lengths in millimetres (the
/// coordinates are written unchanged and declared as mm), uncertainty 1e-7 mm.
///
/// A surface becomes one ADVANCED_FACE on the B-spline surface itself —
/// B_SPLINE_SURFACE_WITH_KNOTS, or the complex rational form (BOUNDED_SURFACE
/// B_SPLINE_SURFACE B_SPLINE_SURFACE_WITH_KNOTS ... RATIONAL_B_SPLINE_SURFACE) when
/// it has weights — bounded by one EDGE_LOOP of its four boundary curves
/// (B-spline curves taken exactly from the boundary rows of the control net), each
/// with its parameter line on the surface as a PCURVE, in an OPEN_SHELL /
/// SHELL_BASED_SURFACE_MODEL / MANIFOLD_SURFACE_SHAPE_REPRESENTATION. A boundary
/// that collapses to a point (a pole) has no edge: the loop closes through its
/// vertex. Two opposite boundaries that coincide (a surface closed around an
/// axis) are one SEAM_CURVE edge used twice.
///
/// A surface closed (periodic) in a direction is written as its clamped form
/// (BSplineSurface::clamped: the same surface over the domain, the ends as (p+1)-fold
/// knots, its first and last control lines on the seam), declared closed there
/// (u_closed / v_closed .T.; .F. in an open direction unless its net closes on
/// itself), the seam one SEAM_CURVE edge used twice and the boundary curves across
/// it closed (closed_curve .T.).
///
/// A volume has no B-spline entity that CAD systems read, so it is written as its
/// six boundary faces (u0, u1, v0, v1, w0, w1, each the exact B-spline surface of
/// that side of the control net), sharing their 12 edges and 8 vertices, oriented
/// outward by the sign of the Jacobian: a CLOSED_SHELL in a MANIFOLD_SOLID_BREP /
/// ADVANCED_BREP_SHAPE_REPRESENTATION. Where the faces do not close (a collapsed or
/// doubled face, so that an edge is not shared by exactly two faces in opposite
/// directions) the same faces go into an OPEN_SHELL as for a surface.
///
/// A volume closed (periodic) in a direction has no faces at that direction's two
/// sides, which meet inside it: a ring closed in u is its v0, v1, w0 and w1 faces,
/// each closed in u, one solid. Faces that fall apart into sets sharing no edge (a
/// volume closed in two directions: its inner and outer skins) are one shell each
/// in the SHELL_BASED_SURFACE_MODEL, CLOSED_SHELLs when every edge is used twice.
///
/// Every number is written in the shortest form that reads back to the same double.
/// Entities are numbered #1, #2, ... in the order written, each referring only to
/// entities before it.
///
/// Example:
/// @code
///   interpatch::io::Construction c = interpatch::io::build_file("hemisphere.json");
///   std::ostringstream text;
///   interpatch::io::write_step(text, *c.exact, {.name = "dome", .time_stamp = "2024-05-01T12:00:00"});
/// @endcode
/// @throws error file_unwritable (the stream fails), no_exact_form (a volume closed in
///   u, v and w: it has no boundary to write).
void write_step(std::ostream& os, const ExactForm& exact, const StepOptions& options = {});

/// The same, written atomically to a file (nothing is left behind when it fails).
/// @throws error file_unwritable, no_exact_form.
void write_step(const std::filesystem::path& path, const ExactForm& exact, const StepOptions& options = {});

/// Writes a curve as a STEP AP214 file: one B_SPLINE_CURVE_WITH_KNOTS (the complex
/// rational form when it has weights) in a GEOMETRIC_CURVE_SET of a
/// GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION, with the product structure,
/// units and uncertainty of a form's file. A closed (periodic) curve is written as its
/// clamped form (BSplineCurve::clamped), closed_curve .T..
///
/// Example:
/// @code
///   interpatch::io::write_step("edge.step", interpatch::line({0, 0, 0}, {10, 0, 0}), {.name = "edge", .time_stamp = {}});
/// @endcode
/// @throws error file_unwritable.
void write_step(std::ostream& os, const BSplineCurve& curve, const StepOptions& options = {});
/// The same, written atomically to a file. @throws error file_unwritable.
void write_step(const std::filesystem::path& path, const BSplineCurve& curve, const StepOptions& options = {});

}  // namespace interpatch::io
