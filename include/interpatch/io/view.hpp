#pragma once
/// @file io/view.hpp
/// The viewer page (`interpatch view`): one self-contained HTML file that shows a
/// construction in 3D in a web browser, offline, and a picture of it drawn without
/// a browser (the demo gallery's thumbnails).

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "interpatch/io/spec.hpp"

namespace interpatch::io {

/// What a viewer page shows and how finely.
struct ViewOptions {
  /// Samples along u and v of a surface (nw = 0), or along u, v and w of a volume;
  /// all zero: view_default_resolution of the construction's kind.
  std::array<std::size_t, 3> resolution{0, 0, 0};
  /// The page's title; empty: the construction's type.
  std::string title;
};

/// The samples of a page when ViewOptions::resolution is not given: the counts of the
/// spec's "sampling" where it gives them, otherwise 257 × 257 for a surface,
/// 33 × 33 × 33 for a volume.
[[nodiscard]] std::array<std::size_t, 3> view_default_resolution(const Construction& c) noexcept;

/// What a page holds at most: larger resolutions, data sets and control nets are
/// decimated for display (evenly spaced samples, the ends kept; the page says by how
/// much), never refused. Every array is in the page as base64 of little-endian
/// float32, so these bound the page at about 20 MB.
struct ViewLimits {
  std::size_t surface_samples = 512 * 512;   ///< vertices of a surface's mesh
  std::size_t volume_samples = 65 * 65 * 65; ///< samples of a volume
  std::size_t data_points = 65536;           ///< points of each data set
  std::size_t control_points = 256 * 256;    ///< points of the control net
};
inline constexpr ViewLimits view_limits{};

/// The resolution a page shows for `asked` samples (per direction, each at least 2;
/// nw = 0 for a surface): `asked` itself when its product is within `limit`, otherwise
/// each count scaled by one factor so that the product is within it — a count the
/// factor would take below 2 stays 2, and the others share the rest.
[[nodiscard]] std::array<std::size_t, 3> view_resolution(std::array<std::size_t, 3> asked, std::size_t limit) noexcept;

/// The viewer page of a construction as text: the page of viewer/src (three.js and
/// interpatch's viewer script inlined, no request to any network or file) with the
/// construction embedded as base64 float32 arrays — for a surface the mesh's points,
/// unit normals (unit_normal()), Gaussian and mean curvature (curvature()) on a
/// uniform grid over [0,1]²; for a volume the points and det J on a uniform grid over
/// [0,1]³ — the control net of the exact form (when it has one), every data set
/// (curves as polylines, grids as points), the frames (point, S_u, S_v) at the
/// corners of a Hermite patch, and the summary `interpatch info` prints (info_json()).
/// docs/spec-format.md describes the page.
/// @throws error too_large, and what evaluation throws.
[[nodiscard]] std::string view_html(const Construction& c, const ViewOptions& options = {});

/// Whether an extension names a viewer page: .html or .htm, with or without the dot,
/// in any case.
[[nodiscard]] bool is_view_format(std::string_view extension) noexcept;

/// Writes view_html() atomically to `path` (its extension is not checked).
///
/// Example:
/// @code
///   interpatch::io::Construction c = interpatch::io::build_file("coons.json");
///   interpatch::io::write_view("coons.html", c);  // open it in a browser
/// @endcode
/// @throws error file_unwritable, and what view_html throws.
void write_view(const std::filesystem::path& path, const Construction& c, const ViewOptions& options = {});

/// A picture of the construction as SVG text, `width` × `height` pixels, drawn by
/// interpatch alone: a 24 × 24 mesh of the surface (a volume: its six faces, 12 × 12
/// each) seen from above at the viewer's initial angle, its quads shaded by their
/// normals, coloured by height as the viewer colours it, and drawn back to front.
/// @throws error too_few_points (width or height below 16), and what evaluation throws.
[[nodiscard]] std::string view_thumbnail_svg(const Construction& c, std::size_t width = 240, std::size_t height = 180);

}  // namespace interpatch::io
