#pragma once
/// @file io/spec.hpp
/// Reading a spec (docs/spec-format.md) into a construction: the exact B-spline
/// form, the data it interpolates, and the options in effect.
///
/// Every error names the place as a JSON Pointer into the spec (`/points/3/7/2`,
/// `/boundary/u1/interpolate/3`), or a file with row and column, and the size of
/// the problem. Errors raised by the library while building a part of the spec keep
/// their code and get the pointer of that part put in front of their message.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/allocator.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/grading.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"
#include "interpatch/vec3.hpp"
#include "interpatch/volume.hpp"

namespace interpatch::io {

/// Points in C order, in the storage grids use (so a grid takes them without a copy).
using PointStorage = std::vector<Vec3, large_allocator<Vec3>>;

/// Points a construction interpolates, as a tensor grid: `points` holds the data
/// point for every combination of the parameters in `params` (one list per
/// parameter axis: u, v[, w]), in C order, first axis slowest. The exact form
/// evaluated at (params[0][i], params[1][j]) should reproduce points[i * nv + j]
/// (for a volume, at (params[0][i], params[1][j], params[2][k]) points[(i * nv + j) * nw + k]).
struct DataSet {
  std::vector<std::vector<double>> params;
  /// The data points; empty while `array` names where they are.
  PointStorage points;
  /// Not empty when the points were left where the caller holds them
  /// (BuildOptions::borrow_arrays): the name of that in-memory array. The caller
  /// puts its points into `points` before info_json() or write_view() needs them.
  std::string array;
  /// JSON Pointer of the spec field the points came from, e.g. "/points"; the
  /// pointer of one point appends its indices ("/points/3/7").
  std::string pointer;
  /// Points without a grid: point k sits at (params[0][k], params[1][k]).
  bool scattered = false;
  /// How many points the parameters stand for: the grid's, or the scattered points'.
  [[nodiscard]] std::size_t count() const {
    if (scattered) return params.empty() ? 0 : params[0].size();
    std::size_t n = 1;
    for (const auto& p : params) n *= p.size();
    return n;
  }
};

/// The exact B-spline form of a construction: a surface over [0,1]² or a volume
/// over [0,1]³.
using ExactForm = std::variant<BSplineSurface, BSplineVolume>;

/// Wall-clock milliseconds spent on each stage.
struct Timings {
  double parse_ms = 0;  ///< reading the spec and its data files, checking fields
  double build_ms = 0;  ///< the construction itself
};

struct BlockSet;

/// A spec, built.
struct Construction {
  std::string type;        ///< the spec's "type"
  /// Exact B-spline form over the unit domain; empty when the construction has none
  /// (Gregory's twist correction), and then `no_exact_form` says why.
  std::optional<ExactForm> exact;
  std::vector<DataSet> data;  ///< what it interpolates (empty when given exactly)
  /// The options in effect, defaults filled in (degree, param, grid shape, ...).
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
  /// What the reader warns about, each "pointer: reason": fields that were ignored
  /// (unknown names), data closed in a direction not declared periodic.
  std::vector<std::string> warnings;
  Timings timings;
  /// The construction's own formula, when it is not a B-spline itself (Coons
  /// patches, networks, ...): what evaluates a construction without an exact form.
  std::shared_ptr<const Surface> formula;
  std::string no_exact_form;
  /// The same for a volume construction (trilinear, Coons and Hermite volumes).
  std::shared_ptr<const Volume> volume_formula;
  /// Built with BuildOptions::defer_exact: the conversion of the formula to its exact
  /// form, which exact_form() runs on first use (and then empties). Empty otherwise.
  std::function<ExactForm(const progress_callback&)> convert;
  /// The spec's "sampling": how mesh, eval and view place their nodes along each
  /// direction (a count 0 where the spec gives none). Empty: even steps.
  std::optional<Sampling> sampling;
  /// A "blocks" spec: its volumes, meshed together (mesh_blocks, io/blocks.hpp). It has
  /// no exact form and no evaluator of its own: each block has them.
  std::shared_ptr<const BlockSet> blocks;
};

/// The volumes of a "blocks" spec, with the names of their outer faces' patches.
struct BlockSet {
  std::vector<Construction> blocks;                  ///< each a volume, with its own "sampling"
  std::vector<std::string> names;                    ///< each block's "name", or block0, block1, ...
  std::vector<std::array<std::string, 6>> patches;   ///< the patch of each face u0 u1 v0 v1 w0 w1 (NAME_u0 unless "patches" names it)
  double tolerance = 0;                              ///< how far shared faces' nodes may be apart; 0: 1e-9 of the blocks' size
};

struct PointArray;

/// How build() builds a construction.
///
/// Example: a Coons patch sampled by its formula, its exact form made when asked.
/// @code
///   auto spec = interpatch::io::parse_json(R"({"type": "coons", "boundary": {
///       "v0": {"line": [[0,0,0], [1,0,0]]}, "v1": {"line": [[0,1,0], [1,1,1]]},
///       "u0": {"line": [[0,0,0], [0,1,0]]}, "u1": {"line": [[1,0,0], [1,1,1]]}}})");
///   interpatch::io::BuildOptions lazy;
///   lazy.defer_exact = true;
///   interpatch::io::Construction c = interpatch::io::build(spec, {}, lazy);  // c.exact is empty
///   const interpatch::Surface& s = interpatch::io::evaluator(c, 10000, interpatch::io::Sample::points);
///   interpatch::Vec3 p = s.point(0.5, 0.5);  // (0.5, 0.5, 0.25), by the formula
///   const auto& e = std::get<interpatch::BSplineSurface>(interpatch::io::exact_form(c));  // made now: 2 × 2
/// @endcode
struct BuildOptions {
  /// Gets the fraction done of long constructions.
  progress_callback progress;
  /// False leaves Construction::data empty for grid interpolations: the copy of the
  /// data points the error check at the data needs is as large as the grid, and
  /// commands that only evaluate the result do without it.
  bool keep_data = true;
  /// True leaves the exact form of a construction with its own formula (Coons
  /// patches, networks, the blended volumes) unbuilt until exact_form() asks for it.
  /// Evaluation then goes through the formula, which evaluates a grid in about the
  /// time of writing its points, while the exact form first needs a control net of
  /// the merged knots of every curve (4.2 million points for four 1024-point curves).
  bool defer_exact = false;
  /// Point arrays held in memory, which a spec names as {"array": NAME} wherever it
  /// takes a point array (in place of {"npy": FILE}): how the Python module's
  /// constructors pass NumPy arrays without writing them to a file.
  ///
  /// An array the spec names once and that nothing but this map holds
  /// (`use_count() == 1`) is taken, not copied: its points move into the
  /// construction and the map's entry is left empty. Any other array is copied.
  std::map<std::string, std::shared_ptr<PointArray>, std::less<>> arrays;
  /// With keep_data, the data points that come from `arrays` are not copied: their
  /// DataSet keeps the array's name in DataSet::array and no points, for a caller
  /// that holds the array itself (the Python module keeps the NumPy array) to fill
  /// in when the error check at the data is asked for. Saves a copy of the grid.
  bool borrow_arrays = false;
};

/// The construction's exact form, converted on first use when the build deferred it.
/// Every conversion of a formula is checked against it at a grid of parameters; one
/// that differs by more than 1e-8 of the construction's size is refused, and the
/// construction keeps its formula alone.
/// @throws error no_exact_form (saying why the construction has none, or where and by
///   how much its conversion was off).
/// `progress` hears how far a conversion has come; what it throws stops the
/// conversion, which is then made again on the next call.
[[nodiscard]] const ExactForm& exact_form(Construction& c, const progress_callback& progress = {});

/// Whether the construction has an exact form, built or still to be converted.
[[nodiscard]] bool has_exact_form(const Construction& c) noexcept;

/// Converts a deferred exact form now: true when the construction has one, false when
/// it has none or its conversion was refused (no_exact_form then says why).
bool has_exact_form_after_conversion(Construction& c, const progress_callback& progress = {});

/// Whether the construction is a volume (its exact form a BSplineVolume, or its
/// formula a Volume) rather than a surface.
[[nodiscard]] bool is_volume(const Construction& c) noexcept;

/// What evaluates a surface construction: its exact form when it is built, otherwise
/// its formula (both exact: they agree to rounding). @throws error wrong_type (a volume
/// construction).
[[nodiscard]] const Surface& evaluator(const Construction& c);

/// The same for a volume construction. @throws error wrong_type (a surface construction).
[[nodiscard]] const Volume& volume_evaluator(const Construction& c);

/// What a sampling of a construction needs at each point.
enum class Sample {
  points,       ///< the points (eval)
  derivatives,  ///< the points and their derivatives (a mesh's normals)
};

/// What evaluates a surface construction on `points` parameter pairs at the least
/// cost: its exact form when that is built, or when making it (about its control
/// points times the formula's terms) and evaluating it (about the two degrees plus 2
/// per point) costs less than the formula (its terms per point), in which case it
/// is made now; otherwise the formula. Both are exact and agree to rounding. A
/// Coons patch of four 1024-point curves (4 terms, 2044 × 2044 control points) is
/// evaluated by formula; a Gordon surface of 24 curves on shared knots (24 terms,
/// 200 × 200 control points) by its exact form. @throws error wrong_type (a volume).
[[nodiscard]] const Surface& evaluator(Construction& c, std::size_t points, Sample what);

/// The construction types a spec's "type" may name, in the order they are documented.
[[nodiscard]] std::vector<std::string_view> known_types();

/// One form of object a spec holds, with the fields it takes: a construction type
/// (kind "type": its top-level fields, "type" included), a curve form (kind
/// "curve": interpolate, bspline, hermite, line — for bspline and hermite the fields
/// of the object under that key), or a point array given as a file (kind "points":
/// npy, csv), or one direction of the "sampling" every construction takes (kind
/// "sampling", name "direction"). docs/spec-format.md documents exactly these; a
/// field not listed is reported as unknown and ignored.
struct SpecForm {
  std::string_view kind;
  std::string_view name;
  std::vector<std::string_view> fields;
};

/// Every form a spec may hold, construction types first in documented order.
[[nodiscard]] std::vector<SpecForm> spec_forms();

/// A spec's "sampling" object, {"u": {"count": 41, "first": 1e-3}, ...}, read as the
/// spec reader reads it, for a construction of `dims` (2 or 3) directions: what the
/// Python module's write(sampling=...) takes.
/// @throws error invalid_grading (a direction the construction lacks, a length,
///   ratio or max_growth out of range, ratio with an end length), too_few_points (a
///   count below 2), wrong_type.
[[nodiscard]] Sampling read_sampling(const nlohmann::json& j, std::size_t dims);

/// Parses JSON text. `source` names the text in messages (the file name).
/// NaN and Infinity literals, which some writers emit, are refused as non-finite
/// values rather than as a syntax error.
///
/// Example:
/// @code
///   auto j = interpatch::io::parse_json(R"({"type": "interpolate"})", "spec.json");
/// @endcode
/// @throws error invalid_json ("spec.json:3:14: ..." with line and column),
///   not_finite (a NaN/Infinity literal or a number too large for a double, with line and column).
[[nodiscard]] nlohmann::json parse_json(std::string_view text, std::string_view source = "spec");

/// The most bytes of JSON a spec file may hold; larger point sets go in .npy or .csv files.
inline constexpr std::size_t max_spec_bytes = std::size_t{1} << 30;
/// The most bytes read from a spec that is not a regular file (a pipe, a device), which
/// has no size to check before reading and may never end.
inline constexpr std::size_t max_streamed_spec_bytes = std::size_t{256} << 20;

/// Reads and parses a JSON file. A pipe or device is parsed as it is read, so text
/// that is not JSON fails at its first bad byte.
/// @throws error file_unreadable; too_large (a file over max_spec_bytes, a stream over
///   max_streamed_spec_bytes, or text that cannot fit in memory); and what parse_json throws.
[[nodiscard]] nlohmann::json read_json_file(const std::filesystem::path& path);

/// Builds the construction a parsed spec describes. File references inside the spec
/// (`{"npy": ...}`, `{"csv": ...}`) are relative to `base_dir`. `progress` gets
/// the fraction done of long constructions.
///
/// Example:
/// @code
///   auto spec = nlohmann::json::parse(R"({"type": "interpolate", "degree": 1,
///       "points": [[[0,0,0],[0,1,0]], [[1,0,0],[1,1,1]]]})");
///   interpatch::io::Construction c = interpatch::io::build(spec);
///   const auto& s = std::get<interpatch::BSplineSurface>(*c.exact);  // bilinear, 2 × 2 control points
/// @endcode
/// @throws error unknown_type (listing the known types), missing_field and wrong_type
///   (naming the pointer and the expected type), ragged_grid, not_finite, size_mismatch,
///   file_unreadable and malformed_file (data files), too_large, and whatever the
///   construction raises (too_few_points, invalid_degree, zero_chord, non_increasing,
///   invalid_knots, invalid_weight, singular, closing_gap, ...), prefixed with the pointer.
[[nodiscard]] Construction build(const nlohmann::json& spec, const std::filesystem::path& base_dir,
                                 const BuildOptions& options);

/// build() with the default options but for `progress` and `keep_data` (BuildOptions).
[[nodiscard]] Construction build(const nlohmann::json& spec, const std::filesystem::path& base_dir = {},
                                 const progress_callback& progress = {}, bool keep_data = true);

/// Reads a spec file and builds it; data files are found relative to the spec's
/// directory. The time spent reading and parsing the file counts into parse_ms.
/// @throws error file_unreadable, invalid_json, and what build() throws.
[[nodiscard]] Construction build_file(const std::filesystem::path& spec_path, const BuildOptions& options);

/// build_file() with the default options but for `progress` and `keep_data`.
[[nodiscard]] Construction build_file(const std::filesystem::path& spec_path, const progress_callback& progress = {},
                                      bool keep_data = true);

/// A point array read from a spec field: `shape` is the grid shape without the
/// trailing 3, `points` the points in C order (first index slowest).
struct PointArray {
  std::vector<std::size_t> shape;
  PointStorage points;
  /// Every coordinate is known to be finite (whoever made the array checked, as the
  /// Python module does while it converts a NumPy array), so the spec reader does
  /// not check again. Set it only when that is so.
  bool finite = false;
};

/// A point array of the given shape (without the trailing 3) copied from its
/// float64 triples in C order, `xyz` (a NumPy array's memory, say), on every core;
/// the same pass checks every coordinate and sets PointArray::finite when all are.
/// @throws error too_large when the copy does not fit in memory.
[[nodiscard]] PointArray copy_point_array(const double* xyz, std::vector<std::size_t> shape);

/// Reads a point array of the given rank (1: a list of points, 2: a grid, 3: a
/// volume grid) from any of its three forms: nested lists of [x, y, z],
/// `{"npy": "file.npy"}` (shape (..., 3)) or `{"csv": "file.csv", "shape": [...]}`
/// (the shape with or without the trailing 3). `pointer` is the field's place in
/// the spec, used in messages.
///
/// Example:
/// @code
///   auto a = interpatch::io::points_from_json(nlohmann::json::parse("[[0,0,0],[1,0,0]]"), 1);
///   // a.shape == {2}
/// @endcode
/// @throws error wrong_type, ragged_grid (naming the short row and both lengths, or a
///   point that is not 3 numbers), not_finite (naming the coordinate, /points/3/7/2),
///   too_few_points (an empty list), size_mismatch (a file's shape), file_unreadable,
///   malformed_file, too_large.
[[nodiscard]] PointArray points_from_json(const nlohmann::json& j, std::size_t rank,
                                          const std::filesystem::path& base_dir = {}, std::string_view pointer = "");

/// A curve spec, built: a spec whose top level is one curve in any of its forms
/// (docs/spec-format.md, "Curves") rather than a construction with a "type". What
/// `interpatch eval`, `info` and `build` make of a curve spec, and what the Python
/// module's Curve holds.
struct CurveConstruction {
  std::string form;    ///< the curve's key: "interpolate", "bspline", "hermite", "line" or "approximate"
  BSplineCurve curve;  ///< over [0, 1]: its exact form
  /// The points it was made through or near (interpolate, hermite, approximate): one
  /// data set whose one parameter list holds their parameters on [0, 1] (a missing
  /// point of an approximation is NaN); empty for bspline and line.
  std::vector<DataSet> data;
  /// The options in effect, defaults filled in (degree, param, periodic; an
  /// approximation's report), as `info` shows them.
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
  std::vector<std::string> warnings;  ///< as Construction::warnings
  Timings timings;                    ///< reading and building are one step: parse_ms holds both
};

/// Whether a spec is a curve spec: an object without "type" holding one of the keys
/// of a curve form ("interpolate", "bspline", "hermite", "line", "approximate").
[[nodiscard]] bool is_curve_spec(const nlohmann::json& spec) noexcept;

/// Builds a curve spec. Of `options` only `arrays` (named by {"array": NAME}) applies:
/// a curve keeps its data points whatever keep_data says, and its arrays are copied.
///
/// Example:
/// @code
///   auto spec = interpatch::io::parse_json(R"({"interpolate": [[0,0,0], [1,1,0], [2,0,0]], "degree": 2})");
///   interpatch::io::CurveConstruction c = interpatch::io::build_curve(spec);
///   interpatch::Vec3 p = c.curve.point(c.data[0].params[0][1]);  // (1, 1, 0) up to rounding
/// @endcode
/// @throws error what curve_from_json throws, and wrong_type for an array given but
///   never named, as build() does.
[[nodiscard]] CurveConstruction build_curve(const nlohmann::json& spec, const std::filesystem::path& base_dir = {},
                                            const BuildOptions& options = {});

/// What a spec builds to: a construction, or a curve for a curve spec.
using Built = std::variant<Construction, CurveConstruction>;

/// build() or build_curve(), as is_curve_spec() says. @throws error as they do.
[[nodiscard]] Built build_any(const nlohmann::json& spec, const std::filesystem::path& base_dir,
                              const BuildOptions& options);

/// build_file() or build_curve() of a spec file, read once. @throws error as they do.
[[nodiscard]] Built build_any_file(const std::filesystem::path& spec_path, const BuildOptions& options);

/// Reads a curve in any of its forms (docs/spec-format.md) — `{"interpolate": points,
/// "degree": p, "param": "chord", "periodic": false, "start_derivative": [x, y, z],
/// "end_derivative": [x, y, z]}`, `{"bspline": {"degree", "knots", "control_points",
/// "weights", "periodic"}}`, `{"hermite": {"points", "tangents", "params"}}`,
/// `{"line": [A, B]}` — as a B-spline curve over [0, 1] (its own domain mapped
/// linearly). `"periodic": true` makes a closed curve (BSplineCurve::periodic()).
///
/// Example:
/// @code
///   auto c = interpatch::io::curve_from_json(nlohmann::json::parse(R"({"line": [[0,0,0], [2,0,0]]})"));
///   // c.point(0.5) == (1, 0, 0)
/// @endcode
/// @throws error missing_field, wrong_type (also end derivatives of a closed curve),
///   and the codes of points_from_json and of the curve constructions (closing_gap
///   among them), each naming its place under `pointer`.
[[nodiscard]] BSplineCurve curve_from_json(const nlohmann::json& j, const std::filesystem::path& base_dir = {},
                                           std::string_view pointer = "");

}  // namespace interpatch::io
