#pragma once
/// @file io/csv.hpp
/// Points as comma-separated text: one `x,y,z` line per point.

#include <cstddef>
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "interpatch/vec3.hpp"

namespace interpatch::io {

/// Reads one point per line (`x,y,z`, spaces or tabs allowed around fields, `\r\n`
/// line ends, a UTF-8 byte order mark). Numbers are parsed independently of the
/// locale (std::from_chars; a leading '+' and surrounding double quotes allowed).
/// The first line is a header, and skipped, when none of its fields is or starts
/// like a number (`x,y,z`); blank lines and lines starting with '#' (as
/// numpy.savetxt writes its header) are ignored. Rows in messages are line numbers
/// in the file, columns are field numbers, both from 1.
///
/// Example:
/// @code
///   auto pts = interpatch::io::read_csv_points("grid.csv", 40 * 50);  // C order of shape (40, 50)
/// @endcode
/// @throws error file_unreadable, malformed_file ("file:row:column: 'abc' is not a
///   number", "file:row:column: 2 fields found, 3 expected"), not_finite (NaN, Inf or
///   overflow, naming file:row:column), size_mismatch (point count differs from
///   `expected`, when expected > 0; both counts named). With `allow_nan`, a NaN field
///   (`nan`) is read as NaN, a missing coordinate (approximation takes missing points).
[[nodiscard]] std::vector<Vec3> read_csv_points(const std::filesystem::path& path, std::size_t expected = 0,
                                                bool allow_nan = false);

/// The same as read_csv_points, from text already in memory (the file reader and
/// this one are one code path). `name` stands for the file in messages.
///
/// Example:
/// @code
///   auto pts = interpatch::io::parse_csv_points("x,y,z\n0,0,0\n1,0,0.5\n", 2, "inline.csv");
/// @endcode
/// @throws error malformed_file, not_finite, size_mismatch, as read_csv_points.
[[nodiscard]] std::vector<Vec3> parse_csv_points(std::string_view text, std::size_t expected = 0,
                                                 std::string_view name = "csv", bool allow_nan = false);

/// Writes an evaluation grid: a header `u,v,x,y,z` (one name per parameter axis,
/// then x,y,z; a curve's one axis is t: `t,x,y,z`), then one row per point in C order (first axis outermost). `params`
/// holds one parameter list per axis; points.size() is the product of their sizes.
/// Numbers are written with 17 significant digits, so they read back exactly.
/// Written atomically. @throws error file_unwritable, size_mismatch (params.size()
/// not 1..3, or points.size() not the product of the parameter counts), not_finite
/// (a point with NaN or infinity: an evaluation that overflowed, refused unwritten).
void write_csv_grid(const std::filesystem::path& path, std::span<const std::vector<double>> params,
                    std::span<const Vec3> points);

}  // namespace interpatch::io
