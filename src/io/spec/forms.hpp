#pragma once
// The fields each form of a curve or point array takes: the readers check objects
// against these lists, and io::spec_forms() publishes them with the construction
// types' (types.def); docs/spec-format.md and the Python keyword constructors
// (tests/python/test_spec_fields.py) are tested against it. Adding a field to a
// form means adding it here.

#include <array>
#include <string_view>

namespace interpatch::io::reader::forms {

using std::string_view_literals::operator""sv;

// Point arrays given as files.
inline constexpr auto npy = std::to_array({"npy"sv});
inline constexpr auto array = std::to_array({"array"sv});
inline constexpr auto csv = std::to_array({"csv"sv, "shape"sv});

// Curves: the fields of the curve object ("interpolate", "line"), or of the object
// under its key ("bspline": {...}, "hermite": {...}).
inline constexpr auto interpolate_curve = std::to_array(
    {"interpolate"sv, "degree"sv, "param"sv, "periodic"sv, "start_derivative"sv, "end_derivative"sv});
inline constexpr auto bspline_curve =
    std::to_array({"degree"sv, "knots"sv, "control_points"sv, "weights"sv, "periodic"sv});
inline constexpr auto hermite_curve = std::to_array({"points"sv, "tangents"sv, "params"sv});
inline constexpr auto line_curve = std::to_array({"line"sv});
inline constexpr auto approximate_curve =
    std::to_array({"approximate"sv, "degree"sv, "param"sv, "periodic"sv, "weights"sv, "control_points"sv, "tolerance"sv,
                   "smoothing"sv});

// One direction of a spec's "sampling".
inline constexpr auto sampling_direction =
    std::to_array({"count"sv, "ratio"sv, "first"sv, "last"sv, "max_growth"sv});

}  // namespace interpatch::io::reader::forms
