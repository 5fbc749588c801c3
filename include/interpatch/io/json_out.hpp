#pragma once
/// @file io/json_out.hpp
/// What `interpatch build -o x.json` and `interpatch info` write: the exact form as
/// a spec that reads back, and the description of a construction with its error
/// at the data.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/io/spec.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/progress.hpp"

namespace interpatch::io {

/// Writes the exact form as a spec that build() reads back to the same surface. For
/// a surface that is
/// `{"type": "bspline_surface", "degree": [p, q], "knots": {"u": [...], "v": [...]},
/// "control_points": [[[x, y, z], ...], ...], "weights": [[...], ...]}` with
/// control_points (n+1) × (m+1) × 3 (first index along u) and weights only when
/// rational. A volume is the same with three directions:
/// `{"type": "bspline_volume", "degree": [p, q, r], "knots": {"u", "v", "w"},
/// "control_points": (n+1) × (m+1) × (l+1) × 3, "weights"}`. A form closed in some
/// direction also has `"periodic": [false, true]` (one entry per direction, after
/// "degree"); the knots of a closed direction are then its extended knots
/// (KnotVector::values()) and its control points the distinct ones. Numbers are
/// written in the shortest form that reads back to the same double.
///
/// Example:
/// @code
///   std::ostringstream text;
///   interpatch::io::write_exact_json(text, *c.exact);  // a "bspline_surface" or "bspline_volume" spec
///   auto again = interpatch::io::build(interpatch::io::parse_json(text.str()));  // the same form
/// @endcode
void write_exact_json(std::ostream& os, const ExactForm& exact);

/// The same, written atomically to a file. @throws error file_unwritable.
void write_exact_json(const std::filesystem::path& path, const ExactForm& exact);

/// Writes a curve as the curve spec that build_curve() reads back to the same curve:
/// `{"bspline": {"degree": p, "periodic": true (closed curves only), "knots": [...],
/// "control_points": [[x, y, z], ...], "weights": [...] (rational curves only)}}`, the
/// knots of a closed curve its extended knots. Numbers as write_exact_json writes them.
///
/// Example:
/// @code
///   interpatch::io::write_exact_json(std::cout, interpatch::line({0, 0, 0}, {1, 0, 0}));
/// @endcode
void write_exact_json(std::ostream& os, const BSplineCurve& curve);
/// The same, written atomically to a file. @throws error file_unwritable.
void write_exact_json(const std::filesystem::path& path, const BSplineCurve& curve);

/// How far the exact form is from the data it interpolates.
struct DataError {
  double absolute = 0;   ///< the largest distance |S(params) − point|
  double relative = 0;   ///< absolute / diagonal (0 when the diagonal is 0 and so is the error)
  double diagonal = 0;   ///< diagonal of the bounding box of the data points
  std::size_t count = 0; ///< data points checked
  std::string pointer;   ///< JSON Pointer of the worst data point, e.g. "/points/3/7"
  std::vector<double> params;  ///< the parameters of the worst data point
};

/// The largest distance between the exact form evaluated at the data parameters and
/// the data points; nothing when the construction has no data (an exact spec).
/// Evaluates in blocks of rows, so the check needs little memory beyond the data.
/// @throws error too_large.
[[nodiscard]] std::optional<DataError> max_data_error(const Construction& c, const progress_callback& progress = {});

/// "C2" for a knot vector whose continuity (degree − highest interior multiplicity)
/// is 2; "Cinf" when there are no interior knots (one polynomial or rational piece).
[[nodiscard]] std::string continuity_name(const KnotVector& knots);

/// The description `interpatch info` prints, computing the data error (its time is
/// timings.check_ms):
/// `{"type", "kind": "surface", "exact_form": "bspline_surface", "degree": [p, q],
/// "control_points": [n+1, m+1], "rational", "periodic": [false, true], "knots":
/// {"u", "v"}, "continuity": {"u": "C2", "v": "C2"} (a closed direction's seam
/// counted as one of its knots), "seam_continuity": {"v": "C2"} (the closed
/// directions only), "domain", "bounding_box": {"min", "max",
/// "diagonal"} (of the control net, which contains the surface),
/// "max_data_error": {"absolute", "relative", "diagonal", "points", "at", "params"} or
/// null, "data": [{"pointer", "shape", "params": {"u", "v"}}], "parameters",
/// "warnings", "timings": {"parse_ms", "build_ms", "check_ms", "total_ms"}}`.
/// A volume has "kind": "volume", "exact_form": "bspline_volume", three entries in
/// degree, control_points, periodic, knots, continuity and domain (u, v, w), and
/// "jacobian": {"samples_per_direction": 17, "samples", "inverted_points", "cells",
/// "inverted_cells", "min_determinant", "max_determinant", "min_at", "inverted_at"}
/// from inverted_cells() on a 17 × 17 × 17 grid (its time counts into check_ms).
/// @throws error too_large.
[[nodiscard]] nlohmann::ordered_json info_json(const Construction& c, const progress_callback& progress = {});

/// The description `interpatch info` prints for a curve spec: the keys of info_json()
/// with one direction, t: `{"type": the curve's form ("interpolate", ...), "kind":
/// "curve", "exact_form": "bspline_curve", "degree": [p], "control_points": [n],
/// "rational", "periodic": [false], "knots": {"t"}, "continuity": {"t"},
/// "seam_continuity", "domain": {"t": [0, 1]}, "bounding_box", "max_data_error" (the
/// curve at its data's parameters, or null), "data": [{"pointer", "shape": [n],
/// "params": {"t"}}], "parameters", "warnings", "timings"}`.
[[nodiscard]] nlohmann::ordered_json curve_info_json(const CurveConstruction& c);

/// JSON text for people: two-space indentation, but arrays of plain values (a
/// point, a knot vector) on one line. Ends with a newline.
///
/// Example:
/// @code
///   std::cout << interpatch::io::pretty_json(interpatch::io::info_json(c));
/// @endcode
[[nodiscard]] std::string pretty_json(const nlohmann::ordered_json& j);

}  // namespace interpatch::io
