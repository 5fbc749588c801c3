#pragma once
/// @file io/csv.hpp
/// Points as comma-separated text: one `x,y,z` line per point.

#include <cstddef>
#include <filesystem>
#include <span>
#include <vector>

#include "interpatch/vec3.hpp"

namespace interpatch::io {

/// Reads one point per line (`x,y,z`, spaces allowed around fields); an optional
/// first header line that does not parse as numbers is skipped; blank lines at
/// the end are ignored.
/// @throws error file_unreadable, malformed_file ("file:row:column: 'abc' is not a
///   number", wrong field count), not_finite (NaN or Inf, naming file:row:column),
///   size_mismatch (point count differs from `expected`, when expected > 0).
[[nodiscard]] std::vector<Vec3> read_csv_points(const std::filesystem::path& path, std::size_t expected = 0);

/// Writes an evaluation grid: a header `u,v,x,y,z` (one name per parameter axis,
/// then x,y,z), then one row per point in C order (first axis outermost). `params`
/// holds one parameter list per axis; points.size() is the product of their sizes.
/// Numbers are written with 17 significant digits, so they read back exactly.
/// Written atomically. @throws error file_unwritable, size_mismatch.
void write_csv_grid(const std::filesystem::path& path, std::span<const std::vector<double>> params,
                    std::span<const Vec3> points);

}  // namespace interpatch::io
