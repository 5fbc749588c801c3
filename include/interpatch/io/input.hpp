#pragma once
/// @file io/input.hpp
/// What a front end is given to build: a spec file, or a data file of points to
/// interpolate in its place (a .npy array, or a .csv of points with the shape of its
/// grid). The command line and the split MPI run both read SPEC through these.

#include <cstddef>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/io/spec.hpp"

namespace interpatch::io {

/// A spec file (.json, or any other extension), or a data file standing for the spec
/// that interpolates its points, told apart by the extension: .npy (its shape in its
/// header) or .csv (its shape given here), case-insensitive.
struct Input {
  enum class Kind { spec, npy, csv };
  std::filesystem::path path;
  Kind kind = Kind::spec;
  std::vector<std::size_t> shape;  ///< for a .csv: N, M (a surface) or N, M, L (a volume)
};

/// The kind of input a path names, by its extension alone; opens no file.
[[nodiscard]] Input::Kind input_kind(const std::filesystem::path& path);

/// The spec a data file stands for: {"type": "interpolate", "points": {"npy": file}},
/// or {"csv": file, "shape": [N, M]}; "interpolate_volume" for an (n, m, l, 3) array
/// or an N, M, L shape. The file is named relative to its own directory, as a spec
/// beside it would name it. Reads the header of a .npy; a header that cannot be read
/// gives "interpolate", whose build then reports the problem as it would for the
/// spec. @throws error size_mismatch (a .npy of a rank other than 3 or 4).
[[nodiscard]] nlohmann::json data_file_spec(const Input& in);

/// Builds the input as given: a spec file (build_file), or the spec of a data file
/// (data_file_spec), with data files found in that file's directory.
/// @throws error as build_file() and data_file_spec() do.
[[nodiscard]] Construction build_input(const Input& in, const BuildOptions& options);

/// build_input(), or a curve when the input is a curve spec (is_curve_spec).
/// @throws error as build_input() and build_curve() do.
[[nodiscard]] Built build_any_input(const Input& in, const BuildOptions& options);

}  // namespace interpatch::io
