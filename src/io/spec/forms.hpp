#pragma once
// The fields each form of a spec object takes: the readers check objects against
// these lists, and io::spec_forms() publishes them (docs/spec-format.md and the
// Python keyword constructors, tests/python/test_spec_fields.py, are tested against
// it). Adding a field to a form means adding it here.

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

// Construction types: the top-level fields, "type" included.
inline constexpr auto bilinear = std::to_array({"type"sv, "p00"sv, "p01"sv, "p10"sv, "p11"sv});
inline constexpr auto ruled = std::to_array({"type"sv, "curves"sv});
inline constexpr auto coons = std::to_array(
    {"type"sv, "boundary"sv, "blending"sv, "cross_derivatives"sv, "twists"sv, "twist_correction"sv, "tolerance"sv});
inline constexpr auto network =
    std::to_array({"type"sv, "u_curves"sv, "v_curves"sv, "u_params"sv, "v_params"sv, "method"sv, "tolerance"sv,
                   "periodic"sv});
inline constexpr auto interpolate = std::to_array({"type"sv, "points"sv, "degree"sv, "param"sv, "periodic"sv});
inline constexpr auto hermite_patch = std::to_array({"type"sv, "corners"sv});
// approximate and approximate_volume.
inline constexpr auto approximate = std::to_array({"type"sv, "points"sv, "degree"sv, "param"sv, "periodic"sv, "weights"sv,
                                                   "control_points"sv, "tolerance"sv, "smoothing"sv});
// bspline_surface and bspline_volume: the form by its fields, or "npz", an archive
// that holds them all (and excludes the others).
inline constexpr auto bspline =
    std::to_array({"type"sv, "degree"sv, "knots"sv, "control_points"sv, "weights"sv, "periodic"sv, "npz"sv});
inline constexpr auto trilinear = std::to_array(
    {"type"sv, "p000"sv, "p001"sv, "p010"sv, "p011"sv, "p100"sv, "p101"sv, "p110"sv, "p111"sv});
inline constexpr auto coons_volume = std::to_array({"type"sv, "faces"sv, "blending"sv, "cross_derivatives"sv, "tolerance"sv});
inline constexpr auto hermite_volume = std::to_array({"type"sv, "corners"sv});

}  // namespace interpatch::io::reader::forms
