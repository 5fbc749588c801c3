#pragma once
/// @file io/npy.hpp
/// NumPy .npy arrays of floating point numbers (format versions 1.0, 2.0, 3.0).

#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

#include "interpatch/progress.hpp"

namespace interpatch::io {

/// An array read from .npy: shape and values as float64 in C order.
struct NpyArray {
  std::vector<std::size_t> shape;
  std::vector<double> data;
};

/// Reads float64 or float32 (widened), little or big endian, C or Fortran order;
/// the result is always C order. The header dict may list its keys in any order,
/// with any spacing and trailing commas. Values are returned as stored (NaN
/// included); checking them is the caller's business.
///
/// Example:
/// @code
///   interpatch::io::NpyArray a = interpatch::io::read_npy("grid.npy");  // e.g. shape {40, 50, 3}
/// @endcode
/// @throws error file_unreadable (cannot open or read), malformed_file (bad magic,
///   bad header, unsupported dtype, data shorter or longer than the shape says —
///   naming the file and the sizes), too_large (the shape needs more memory than
///   available; refused before allocating).
[[nodiscard]] NpyArray read_npy(const std::filesystem::path& path);

/// The same as read_npy, from the bytes of a .npy file already in memory (the
/// file reader and this one are one code path). `name` stands for the file in
/// messages.
///
/// Example:
/// @code
///   std::string bytes = load_from_somewhere();
///   interpatch::io::NpyArray a = interpatch::io::parse_npy(bytes, "upload.npy");
/// @endcode
/// @throws error malformed_file, too_large, as read_npy; file_unreadable never.
[[nodiscard]] NpyArray parse_npy(std::string_view bytes, std::string_view name = "npy");

/// Where read_npy_into puts the values: called once, after the header is read and
/// the sizes are checked against the file and the memory, with the shape and the
/// number of values; returns memory for that many doubles, which are then written
/// in C order. It may throw to refuse the shape.
using NpyDestination = std::function<double*(std::span<const std::size_t> shape, std::size_t count)>;

/// Reads as read_npy, into memory the caller provides (the storage of a point grid,
/// say), without an intermediate copy. Returns the shape.
///
/// Example:
/// @code
///   std::vector<double> v;
///   auto shape = interpatch::io::read_npy_into("grid.npy", [&](auto, std::size_t n) {
///     v.resize(n);
///     return v.data();
///   });
/// @endcode
/// @throws error as read_npy, and whatever `destination` throws.
std::vector<std::size_t> read_npy_into(const std::filesystem::path& path, const NpyDestination& destination);

/// Writes little-endian float64 in C order, format version 1.0 (header padded to
/// 64 bytes as NumPy does), atomically.
/// @throws error file_unwritable, size_mismatch (data size is not the product of shape).
void write_npy(const std::filesystem::path& path, std::span<const std::size_t> shape, std::span<const double> data);

/// Makes the values [first, first + count) of an array, in C order, in memory of its
/// own that stays valid until the next call, and returns them.
using NpyProducer = std::function<std::span<const double>(std::size_t first, std::size_t count)>;

/// Writes as write_npy, with the values made `block` at a time by `produce` while
/// the file is written: memory for one block, never for the whole array, and each
/// block is written while it is still in the cache.
///
/// Example:
/// @code
///   const std::size_t shape[2] = {1000, 1000};
///   std::vector<double> row;
///   interpatch::io::write_npy("ramp.npy", shape, 1000, [&](std::size_t first, std::size_t count) {
///     row.resize(count);
///     for (std::size_t i = 0; i < count; ++i) row[i] = double(first + i);
///     return std::span<const double>(row);
///   });
/// @endcode
/// @throws error file_unwritable, size_mismatch (an overflowing shape, a block of 0
/// values, a block returned with the wrong count), and whatever `produce` throws;
/// the file is then left as it was.
void write_npy(const std::filesystem::path& path, std::span<const std::size_t> shape, std::size_t block,
               const NpyProducer& produce);

/// Makes the rows [first, first + count) of an array's first axis, in C order, into
/// `out` (count times the values of one row). Called on several threads at once,
/// each call for rows no other call makes.
using NpyRowsMaker = std::function<void(std::size_t first, std::size_t count, std::span<double> out)>;

/// Writes as write_npy, the rows of the array's first axis made by `make`: a block
/// of about 2^17 values (at least 2 rows) at a time, made a few rows a call by every thread while the
/// block before it is written, so that the making and the writing overlap. Memory
/// for two blocks, never for the whole array. The bytes do not depend on the
/// threads as long as make's values do not. `progress`, if given, gets the fraction
/// written after each block, from one thread at a time but not always the calling one.
///
/// Example:
/// @code
///   const std::size_t shape[2] = {1000, 1000};
///   interpatch::io::write_npy_rows("ramp.npy", shape, [](std::size_t first, std::size_t count, std::span<double> out) {
///     for (std::size_t i = 0; i < count; ++i)
///       for (std::size_t j = 0; j < 1000; ++j) out[i * 1000 + j] = double(first + i) + 0.001 * double(j);
///   });
/// @endcode
/// It writes evaluations, which are finite: a value that is NaN or infinite (a
/// construction whose arithmetic overflowed) is refused, naming its index.
/// @throws error file_unwritable, size_mismatch (an overflowing shape, or one of no
/// axis), not_finite, and whatever `make` throws (for the first rows, when several
/// calls throw); the file is then left as it was.
void write_npy_rows(const std::filesystem::path& path, std::span<const std::size_t> shape, const NpyRowsMaker& make,
                    const progress_callback& progress = {});

/// The doubles write_npy_rows holds while it writes an array of `rows` rows of
/// `per_row` values each (its two blocks), for a caller that refuses the work before
/// starting it when they do not fit in memory.
[[nodiscard]] std::size_t write_npy_rows_held(std::size_t rows, std::size_t per_row) noexcept;

}  // namespace interpatch::io
