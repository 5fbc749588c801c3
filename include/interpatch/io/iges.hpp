#pragma once
/// @file io/iges.hpp
/// The exact form as an IGES 5.3 file (fixed 80-column ASCII): what
/// `interpatch build -o x.igs` writes for CAD systems.

#include <filesystem>
#include <ostream>
#include <string>

#include "interpatch/io/spec.hpp"

namespace interpatch::io {

/// What goes into the IGES start and global sections besides the geometry.
struct IgesOptions {
  /// The global section's file name and product identification.
  std::string name = "interpatch";
  /// Date and time of generation, "YYYYMMDD.HHNNSS"; empty: the current UTC time.
  /// A fixed stamp makes the output reproducible byte for byte.
  std::string time_stamp;
};

/// Writes the exact form as an IGES 5.3 file, units millimetres (unit flag 2; the
/// coordinates are written unchanged).
///
/// A surface is one entity 128 (rational B-spline surface, form 0) holding the
/// degrees, knots, weights (all 1 and PROP3 = 1 when the surface is polynomial)
/// and control points, u index fastest as IGES orders them, and its parameter
/// range; PROP1/PROP2 say whether it is closed in u/v. A surface closed (periodic)
/// in a direction is written as its clamped form (BSplineSurface::clamped: the same
/// surface, the domain's ends as (p+1)-fold knots), flagged closed (PROP1/PROP2 = 1)
/// and periodic (PROP4/PROP5 = 1) there. A volume is written as its six boundary
/// faces (u0, u1, v0, v1, w0, w1), six entities 128: IGES has no B-spline volume
/// entity that CAD systems read. A volume closed (periodic) in a direction has no
/// faces at that direction's sides (they meet inside it): a ring closed in u is
/// four entities 128, each closed and periodic along u.
///
/// Layout: 80-column lines, columns 73-80 holding the section letter (S, G, D, P,
/// T) and the line's sequence number; each entity has two directory lines and
/// parameter lines whose columns 65-72 point back to its directory entry. Every
/// number is written in the shortest form that reads back to the same double, and
/// no number is split across lines.
///
/// Example:
/// @code
///   interpatch::io::Construction c = interpatch::io::build_file("terrain.json");
///   interpatch::io::write_iges("terrain.igs", *c.exact);
/// @endcode
/// @throws error file_unwritable (the stream fails), no_exact_form (a volume closed in
///   u, v and w: it has no boundary to write).
void write_iges(std::ostream& os, const ExactForm& exact, const IgesOptions& options = {});

/// The same, written atomically to a file (nothing is left behind when it fails).
/// @throws error file_unwritable, no_exact_form.
void write_iges(const std::filesystem::path& path, const ExactForm& exact, const IgesOptions& options = {});

/// Writes a curve as an IGES 5.3 file: one entity 126 (rational B-spline curve, form
/// 0) holding the degree, knots, weights (all 1 and PROP3 = 1 when polynomial),
/// control points and parameter range. A closed (periodic) curve is written as its
/// clamped form (BSplineCurve::clamped), flagged closed (PROP2) and periodic (PROP4).
///
/// Example:
/// @code
///   interpatch::io::write_iges("edge.igs", interpatch::line({0, 0, 0}, {10, 0, 0}));
/// @endcode
/// @throws error file_unwritable.
void write_iges(std::ostream& os, const BSplineCurve& curve, const IgesOptions& options = {});
/// The same, written atomically to a file. @throws error file_unwritable.
void write_iges(const std::filesystem::path& path, const BSplineCurve& curve, const IgesOptions& options = {});

}  // namespace interpatch::io
