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
/// A volume has no B-spline entity that CAD systems read, so it is written as its
/// six boundary faces (u0, u1, v0, v1, w0, w1, each the exact B-spline surface of
/// that side of the control net), sharing their 12 edges and 8 vertices, oriented
/// outward by the sign of the Jacobian: a CLOSED_SHELL in a MANIFOLD_SOLID_BREP /
/// ADVANCED_BREP_SHAPE_REPRESENTATION. Where the faces do not close (a collapsed or
/// doubled face, so that an edge is not shared by exactly two faces in opposite
/// directions) the same faces go into an OPEN_SHELL as for a surface.
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
/// @throws error file_unwritable (the stream fails).
void write_step(std::ostream& os, const ExactForm& exact, const StepOptions& options = {});

/// The same, written atomically to a file (nothing is left behind when it fails).
/// @throws error file_unwritable.
void write_step(const std::filesystem::path& path, const ExactForm& exact, const StepOptions& options = {});

}  // namespace interpatch::io
