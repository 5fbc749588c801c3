#pragma once
/// @file io/npz.hpp
/// The exact B-spline form as a NumPy .npz archive: what `interpatch build -o x.npz`
/// writes and `{"type": "bspline_surface", "npz": "x.npz"}` reads back, bit for bit.
///
/// The archive is a ZIP of .npy members, stored (not compressed), that
/// `numpy.load` reads:
///
/// | member | dtype | shape (surface) | shape (volume) |
/// |---|---|---|---|
/// | `degree` | int64 | (2,) | (3,) |
/// | `knots_u`, `knots_v`, `knots_w` (volumes) | float64 | (n + p + 1,) ...; closed: (n + 2p + 1,) | ... |
/// | `control_points` | float64 | (n, m, 3) | (n, m, l, 3) |
/// | `weights` (only when rational) | float64 | (n, m) | (n, m, l) |
/// | `periodic` | bool | (2,) | (3,) |
///
/// C order, first index along u. `periodic` says which directions are closed: the
/// knots of such a direction are the extended knots of a periodic vector
/// (KnotVector::values(), n + 2p + 1 of them for n distinct control points) and its
/// control points the distinct ones, as BSplineSurface and BSplineVolume hold them;
/// an archive without it is open in every direction. Members the
/// format does not define are refused rather than ignored: a misspelled `weights`
/// would otherwise read as a polynomial form.

#include <filesystem>
#include <string_view>

#include "interpatch/io/spec.hpp"

namespace interpatch::io {

/// Writes the exact form as an .npz archive, atomically (a failed run leaves the
/// path as it was). The control points and weights go from the form's own memory to
/// the file a block at a time, each block's CRC-32 taken as it is written: no copy of
/// the net is made. ZIP64 records are used where a member or the archive passes
/// 4 GiB. The archive's dates are 1980-01-01, so equal forms give equal files.
///
/// Example:
/// @code
///   interpatch::io::Construction c = interpatch::io::build_file("terrain.json");
///   interpatch::io::write_exact_npz("terrain.npz", *c.exact);
///   // python3 -c "import numpy; print(numpy.load('terrain.npz')['control_points'].shape)"
/// @endcode
/// @throws error file_unwritable (the directory is missing or not writable, a write
///   fails), too_large (the archive needs more space than the disk has; refused
///   before writing).
void write_exact_npz(const std::filesystem::path& path, const ExactForm& exact);

/// Writes a curve as an .npz archive of the same members with one direction:
/// `degree` (1,), `knots_u`, `control_points` (n, 3), `weights` (n,) when rational,
/// `periodic` (1,). @throws error as write_exact_npz of a form.
void write_exact_npz(const std::filesystem::path& path, const BSplineCurve& curve);

/// Reads an archive written by write_exact_npz (or by `numpy.savez` with the same
/// arrays) back to the same exact form, bit for bit: the knots and control points
/// are not mapped or rounded. Degrees may be any integer dtype; knots, control points
/// and weights float64 or float32 (widened), either byte order, C or Fortran order.
/// The control points and weights are read once, in place, into the form's storage.
/// Every member's CRC-32 is checked.
///
/// Example:
/// @code
///   interpatch::io::ExactForm f = interpatch::io::read_exact_npz("terrain.npz");
///   const auto& s = std::get<interpatch::BSplineSurface>(f);
/// @endcode
/// @throws error, each message naming the file, the member and the sizes:
///   file_unreadable (cannot open or read); malformed_file (not a ZIP archive, a
///   truncated one, records or sizes that point beyond the file, a compressed or
///   encrypted member — only stored members are read —, a CRC-32 mismatch, a
///   member missing or not part of the format, a malformed .npy member);
///   wrong_type (a dtype the member cannot have, e.g. float degrees);
///   size_mismatch (a shape that does not fit: control_points not (..., 3), knots
///   that need another number of control points, weights of another shape);
///   invalid_degree (a degree outside 1..30); invalid_knots, non_increasing (the
///   knot vectors, as KnotVector and, for a closed direction,
///   KnotVector::periodic_from_extended check them); not_finite (NaN or
///   Inf in knots, control points or weights); invalid_weight (a weight <= 0);
///   too_large (the net needs more memory than available; refused before reading).
[[nodiscard]] ExactForm read_exact_npz(const std::filesystem::path& path);

/// The same as read_exact_npz, from the bytes of an archive already in memory (the
/// file reader and this one are one code path). `name` stands for the file in
/// messages.
///
/// Example:
/// @code
///   std::string bytes = load_from_somewhere();
///   interpatch::io::ExactForm f = interpatch::io::parse_exact_npz(bytes, "upload.npz");
/// @endcode
/// @throws error as read_exact_npz; file_unreadable never.
[[nodiscard]] ExactForm parse_exact_npz(std::string_view bytes, std::string_view name = "npz");

}  // namespace interpatch::io
