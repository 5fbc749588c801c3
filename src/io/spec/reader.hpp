#pragma once
// What every part of the spec reader shares (src/io/spec/): JSON Pointers into the
// spec, the reading context, and readers of fields that many constructions take.
// One file per part: points.cpp (point arrays), curves.cpp (curve forms),
// surfaces.cpp and volumes.cpp (constructions from corners, curves and faces),
// grids.cpp (interpolation through grids and the exact forms, surfaces and volumes
// alike), spec.cpp (the table of construction types and the public functions).

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/text.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/blended_surface.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/network.hpp"

namespace interpatch::io::reader {

using json = nlohmann::json;
using interpatch::detail::cat;
using interpatch::detail::fail;
using Clock = std::chrono::steady_clock;
using Fields = std::span<const std::string_view>;

// ---------------------------------------------------------------------------
// Places: JSON Pointers (RFC 6901) into the spec.

/// ptr + "/" + key, with '~' and '/' escaped. Pointers into absurdly deep documents
/// are shortened in messages by place(), not here.
std::string child(std::string_view ptr, std::string_view key);
std::string child(std::string_view ptr, std::size_t index);
/// ptr followed by the first n indices of idx.
std::string index_pointer(std::string_view ptr, const std::vector<std::size_t>& idx, std::size_t n);
/// The pointer as a message shows it: "(top level)" for the whole document, and at
/// most about 200 characters (the start and the end) of a pointer into a deeply
/// nested document.
std::string place(std::string_view ptr);
/// "a number", "an array", ...: what a JSON value is, for messages.
const char* kind(const json& j);
[[noreturn]] void wrong_type(std::string_view ptr, std::string_view expected, const json& got);

/// Runs a library call; an error it throws keeps its code and gets the place in front.
template <class F>
decltype(auto) at(std::string_view ptr, F&& f) {
  return interpatch::detail::prefixed(place(ptr), std::forward<F>(f));
}

constexpr const char* axis_name(std::size_t a) { return a == 0 ? "u" : (a == 1 ? "v" : "w"); }
constexpr const char* coord_name(int k) { return k == 0 ? "x" : (k == 1 ? "y" : "z"); }
/// "(3, 4)", "(5,)".
std::string shape_text(std::span<const std::size_t> shape);
/// "3x4", "3x4x5".
std::string extents_text(std::span<const std::size_t> shape);
/// The product of extents, refusing (too_large) a product that overflows.
std::size_t checked_product(std::span<const std::size_t> shape, std::string_view what);

// ---------------------------------------------------------------------------
// The reading context: where relative files are, progress, warnings, timing.

struct Context {
  std::filesystem::path base_dir;
  progress_callback progress;
  bool keep_data = true;     // copy interpolated grids into Construction::data
  bool defer_exact = false;  // leave a formula's exact form to exact_form()
  const std::map<std::string, std::shared_ptr<PointArray>, std::less<>>* arrays = nullptr;  // BuildOptions::arrays
  std::map<std::string, std::size_t, std::less<>> array_uses;  // how many times the spec names each of them
  bool borrow_arrays = false;  // BuildOptions::borrow_arrays
  std::vector<std::string> warnings;
  Clock::time_point start = Clock::now();
  std::optional<Clock::time_point> parsed_at;

  // The spec is read and checked; what follows is the construction proper.
  void parsed() { parsed_at = Clock::now(); }
  void warn(std::string w) { warnings.push_back(std::move(w)); }
  [[nodiscard]] std::filesystem::path resolve(const std::string& file) const;
};

// ---------------------------------------------------------------------------
// Fields.

const json* find_member(const json& obj, std::string_view key);
/// A required member; its absence names the member's pointer and what it should hold.
const json& member(const json& obj, std::string_view key, std::string_view ptr, std::string_view expected);
void expect_object(const json& j, std::string_view ptr, std::string_view expected);
/// Names a reader does not know are reported (a typo would otherwise be silently
/// ignored) but not refused: newer specs may carry options this build lacks.
/// "comment", "description" and "name" are always allowed.
void check_fields(const json& obj, std::string_view ptr, Fields known, Context& ctx);
inline void check_fields(const json& obj, std::string_view ptr, std::initializer_list<std::string_view> known,
                         Context& ctx) {
  check_fields(obj, ptr, Fields(known.begin(), known.size()), ctx);
}

/// The name of a data file in obj[key] (relative to the spec's directory): a
/// non-empty string, else wrong_type naming the field.
std::string file_name(const json& obj, std::string_view key, std::string_view ptr);
double number(const json& j, std::string_view ptr);
/// An integer; a float with an integral value (3.0) is accepted.
std::int64_t integer(const json& j, std::string_view ptr, std::string_view expected);
std::vector<double> numbers(const json& j, std::string_view ptr, std::string_view expected = "an array of numbers");
Vec3 point_value(const json& j, std::string_view ptr);
int degree_value(const json& j, std::string_view ptr);
/// "degree": p for every direction, or [p, q(, r)]; unset entries mean the default.
std::vector<std::optional<int>> degrees(const json& obj, std::string_view ptr, std::size_t dims);
/// Where the degree of `axis` is in the spec (the array entry, or the single number).
std::string degree_pointer(const json& obj, std::string_view ptr, std::size_t axis);
const char* param_name(Parametrization p);
/// "param": uniform, chord (default) or centripetal.
Parametrization parametrization(const json& obj, std::string_view ptr);
/// "periodic": which directions are closed. A curve (dims 1) takes true or false; a
/// grid or an exact form an array of `dims` booleans, one per direction u, v(, w).
/// Absent: none. Entries past `dims` are false.
std::array<bool, 3> periodic_flags(const json& obj, std::string_view ptr, std::size_t dims);
/// "[false, true]": the flags of `dims` directions as a spec writes them.
std::string periodic_text(const std::array<bool, 3>& flags, std::size_t dims);
/// A knot vector as a spec gives it: clamped, or the extended knots of a periodic one
/// (KnotVector::periodic_from_extended), as build writes them.
KnotVector knot_vector(int degree, std::vector<double> knots, bool periodic);
/// "6 knots of degree 2", "13 periodic knots of degree 3": knots in a message.
std::string knots_text(const KnotVector& k);
/// "tolerance": a non-negative number, or nothing.
std::optional<double> tolerance_of(const json& spec);
/// A string member that must be one of `allowed`; `fallback` when absent.
std::string choice(const json& obj, std::string_view key, std::string_view ptr,
                   std::initializer_list<std::string_view> allowed, std::string_view fallback);

// ---------------------------------------------------------------------------
// Point arrays (points.cpp) and curves (curves.cpp).

/// A point array of the given rank in any of its forms (inline lists, npy, csv).
/// With `missing_allowed` (approximation only), a missing point is NaN: null for a
/// coordinate of an inline list, NaN in a file; infinities are refused still.
PointArray points_impl(const json& j, std::size_t rank, std::string_view ptr, Context& ctx, bool missing_allowed = false);
/// The rank of a point array as given (1: a list, 2: a grid, ...), from its nesting, its
/// "shape", its in-memory array or its .npy header, without reading the points; 0 when
/// it cannot tell (points_impl then says what is wrong).
std::size_t point_array_rank(const json& j, Context& ctx);
/// points_impl for interpolation's data: a missing point (NaN in a file, null in a
/// list) is refused, and the message says that approximation takes missing points.
PointArray interpolation_points(const json& j, std::size_t rank, std::string_view ptr, Context& ctx);
/// The data set of the grid at `/points` a construction interpolates or approximates,
/// for the error check at the data (params left to the caller): a copy of `points`;
/// no points without keep_data; the array's name and no points when they came from
/// an in-memory array the caller holds and lends (borrow_arrays).
DataSet grid_data(const json& points_spec, std::span<const Vec3> points, std::span<const std::size_t> shape,
                  const Context& ctx);
/// A grid of numbers (weights) given as nested lists, Rank 2 or 3.
template <std::size_t Rank>
Grid<double, Rank> inline_number_grid(const json& j, std::string_view ptr);
/// A curve as its spec gives it: the curve mapped onto [0, 1]; for the forms made
/// through or near points (interpolate, approximate, hermite) those points and their
/// parameters on [0, 1] (a missing point of an approximation is NaN); and the options
/// in effect, defaults filled in, as info shows them.
struct SpecCurve {
  explicit SpecCurve(BSplineCurve c, std::vector<double> t = {}, std::vector<Vec3> data = {},
                     nlohmann::ordered_json options = nlohmann::ordered_json::object())
      : curve(std::move(c)), params(std::move(t)), points(std::move(data)), parameters(std::move(options)) {}
  BSplineCurve curve;
  std::vector<double> params;
  std::vector<Vec3> points;
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
  std::string_view form;  ///< its key: "interpolate", "bspline", ... (read_curve sets it)
};
/// A curve in any of its forms (docs/spec-format.md, "Curves").
SpecCurve read_curve(const json& j, std::string_view ptr, Context& ctx);
/// read_curve's curve alone, for the constructions made of curves.
BSplineCurve curve_impl(const json& j, std::string_view ptr, Context& ctx);
/// The curves at items[i] (null: none there, an empty entry), each as curve_impl reads
/// it at ptrs[i]: on every thread when the spec names no in-memory arrays, their
/// warnings and the first error in the spec's order (surfaces.cpp).
std::vector<std::optional<BSplineCurve>> read_curve_list(const std::vector<const json*>& items,
                                                         const std::vector<std::string>& ptrs, Context& ctx);
/// A surface spec inside another spec (a volume's face, a loft's section, a
/// cross-derivative field): built by the surface constructions, its exact form over
/// [0, 1]²; its messages and warnings placed under `ptr` (volumes.cpp).
BSplineSurface face_surface(const json& j, const std::string& ptr, Context& ctx);
/// A surface sampled on 17 × 17 of its own parameters for the data check: at (i, v, w)
/// (axis 0, i = fixed), (u, j, w) (axis 1) or (u, v, k) (axis 2) of a volume.
DataSet face_data(const BSplineSurface& f, std::size_t axis, double fixed, std::string pointer);
/// A curve of the spec sampled for the data check (65 points): S(u, fixed) (axis 0) or
/// S(fixed, v) against the curve at map(u), or at u itself without a map.
DataSet curve_data(const BSplineCurve& c, int axis, double fixed, std::string pointer,
                   const std::optional<Reparametrization>& map = std::nullopt);

// ---------------------------------------------------------------------------
// Construction types (types.def lists them, spec.cpp holds their table).

struct ConstructionType {
  std::string_view name;
  Construction (*build)(const json& spec, Context& ctx);
  int dims;       // 2: a surface, 3: a volume
  Fields fields;  // the top-level fields, "type" included
};

/// The type of that name; nullptr when there is none.
const ConstructionType* find_type(std::string_view name);
/// A block of a "blocks" spec at `pointer`: a volume spec built as a spec of its own,
/// its errors and warnings placed under `pointer` (spec.cpp).
Construction build_block(const json& spec, std::string_view pointer, Context& ctx);
// A spec's "sampling" (at `ptr`) for a construction of `dims` directions.
Sampling read_sampling(const json& j, std::string_view ptr, std::size_t dims, Context& ctx);
/// The names of the types, comma-separated; only those of `dims` dimensions when it is not 0.
std::string type_list(int dims = 0);

/// The builders, build_<name> for each line of types.def (surfaces.cpp, grids.cpp,
/// approximate.cpp, volumes.cpp). The caller has checked the top-level fields against
/// the type's list.
#define INTERPATCH_SPEC_TYPE(name, dims, ...) Construction build_##name(const json& spec, Context& ctx);
#include "io/spec/types.def"
#undef INTERPATCH_SPEC_TYPE
/// Refuses the first point with a NaN or Inf coordinate among `points`, which are
/// the points from index `first` on of a grid of `shape` read from `file`, naming
/// it as a JSON Pointer below `ptr` (`/points/3/7/2`) and the file.
/// With `missing_allowed` (approximation) NaN marks a missing point and only
/// infinities are refused.
void check_finite_block(const std::vector<std::size_t>& shape, std::span<const Vec3> points, std::size_t first,
                        std::string_view ptr, const std::string& file, bool missing_allowed = false);
/// `e` thrown again, with the note that approximation takes missing points when it is
/// about a NaN (or null) point: what interpolation_points says, for readers of grids
/// that do not go through it (the run split between processes).
[[noreturn]] void rethrow_for_interpolation(const error& e);
/// build_interpolate's checks of a grid of `shape` before it is solved (at least 2
/// points along each axis, enough distinct lines for each degree), its warnings
/// (data closed along an axis not declared periodic) into ctx and its notes as
/// returned; closing(a) is the grid's closing along axis a (grid_closing). Shared
/// with the run split between processes (src/mpi/), which has no grid in one piece.
nlohmann::ordered_json check_grid_axes(const json& spec, const std::vector<std::optional<int>>& degree,
                                       const std::array<bool, 3>& periodic, std::span<const std::size_t> shape,
                                       const char* kind, const std::function<Closing(std::size_t)>& closing,
                                       Context& ctx);
/// The options of an approximation (`ptr` the object holding its fields), checked
/// against the points' shape; `pts_at` names the points in messages.
template <std::size_t D>
ApproximationOptions<D> approximation_options(const json& obj, std::string_view ptr, const std::vector<std::size_t>& shape,
                                              std::string_view pts_at);
/// {"approximate": points, ...} as a curve (approximate.cpp), mapped onto [0, 1].
SpecCurve approximated_curve(const json& obj, std::string_view ptr, Context& ctx);

/// Construction helpers shared by the builders.
/// A blended surface or volume construction: the formula, and its exact form if it has one.
Construction blended(std::string_view type, BlendedSurface s, std::vector<DataSet> data,
                     nlohmann::ordered_json parameters);
Construction blended(std::string_view type, BlendedVolume v, std::vector<DataSet> data,
                     nlohmann::ordered_json parameters);
/// Parameters t mapped from `domain` onto [0, 1].
std::vector<double> to_unit(std::vector<double> t, std::pair<double, double> domain);

}  // namespace interpatch::io::reader
