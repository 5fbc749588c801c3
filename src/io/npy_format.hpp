#pragma once
// The .npy format's parts, for the readers and writers built on it: io/npy.hpp's
// files and the members of an .npz archive (io/npz.hpp), which are .npy files
// inside a ZIP. One header parser, one data reader and one header writer serve both.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <istream>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "interpatch/io/npy.hpp"

namespace interpatch::io::internal {

/// "(3, 4)", "(5,)": a shape as NumPy prints it.
std::string npy_shape_text(std::span<const std::size_t> shape);

/// An element type of the header's 'descr': kind 'f' (float), 'i' (signed), 'u'
/// (unsigned) or 'b' (bool), its size in bytes and its byte order.
struct NpyDtype {
  char kind = 'f';
  std::size_t size = 8;
  bool big_endian = false;
};

/// The dtype a 'descr' names, among those the readers can decode: float32 and
/// float64, integers of 1, 2, 4 or 8 bytes, bool ('|b1'); nullopt for any other.
[[nodiscard]] std::optional<NpyDtype> parse_npy_dtype(std::string_view descr);

/// What the preamble and the header dict say.
struct NpyHeader {
  std::string descr;
  bool fortran_order = false;
  std::vector<std::size_t> shape;
  std::uint64_t data_offset = 0;  ///< bytes of preamble and header: where the data start
};

/// Reads the preamble and the header dict from `in`, which holds the array's `size`
/// bytes from its start; leaves `in` at the data. `name` names the array in messages.
/// @throws error malformed_file (bad magic, version, header), file_unreadable.
NpyHeader read_npy_header(std::istream& in, std::uint64_t size, const std::string& name);

/// Reads n bytes at byte `offset` of the array (counted from its start, as in
/// read_npy_header) into dst: a faster path than the stream for the data block.
using BulkRead = std::function<void(char* dst, std::size_t n, std::uint64_t offset)>;

/// Reads the data that follow the header `h` into `destination`, as float64 in C
/// order, after checking the data's size against the shape and the memory. Accepts
/// float32 and float64, and with `integers` also integer and bool dtypes (decoded to
/// their values as doubles). Returns the shape.
/// @throws error malformed_file (another dtype, data shorter or longer than the
///   shape), too_large, file_unreadable, and what `destination` throws.
std::vector<std::size_t> read_npy_data(std::istream& in, const NpyHeader& h, std::uint64_t size, const std::string& name,
                                       const NpyDestination& destination, const BulkRead& bulk = {},
                                       bool integers = false);

/// Called by read_pieces on the thread that read a piece, while it is still in the
/// cache: `bytes` points at the piece in the destination, `n` bytes long, a multiple
/// of 8 when the whole read is.
using PieceVisitor = std::function<void(const char* bytes, std::size_t n)>;

/// Reads n bytes at `offset` of a file into dst, every thread at once in pieces of
/// 1 MiB (pread). With `crc`, also the CRC-32 of the bytes read, each piece's
/// computed while it is still in the cache; with `visit`, called on every piece
/// read whole.
/// @throws error file_unreadable (naming `name`).
void read_pieces(const std::filesystem::path& path, const std::string& name, char* dst, std::size_t n,
                 std::uint64_t offset, std::uint32_t* crc = nullptr, const PieceVisitor& visit = {});

/// read_npy_into, and `visit` on the pieces of float64 values as they are read, when
/// the file's data are read in pieces (C order, native byte order); the pieces it
/// was given add up to the whole data block exactly when they were.
std::vector<std::size_t> read_npy_visiting(const std::filesystem::path& path, const NpyDestination& destination,
                                           const PieceVisitor& visit);

/// The preamble and header of a little-endian C-order array of the given dtype
/// ('<f8', '<i8', '|b1'), format version 1.0 (2.0 for a rank too large for it),
/// padded to a multiple of 64 bytes as NumPy does.
[[nodiscard]] std::string npy_header(std::string_view descr, std::span<const std::size_t> shape);

/// Writes n doubles as little-endian float64; with `crc`, updates it with the bytes
/// written.
void write_values(std::ostream& os, const double* data, std::size_t n, std::uint32_t* crc = nullptr);

}  // namespace interpatch::io::internal
