#pragma once
// The interpatch subcommands, shared by main.cpp and the demo.
// Each command checks its usage and its output path before any work, builds the
// spec, and writes through the atomic writers. Errors propagate as exceptions:
// interpatch::error (exit status from exit_status()), usage_error (exit 2).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/io/input.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/io/spec.hpp"

namespace interpatch::cli {

/// Bad usage of the command line; the command exits with 2.
class usage_error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using io::CountsOption;
using io::default_surface_resolution;
using io::default_volume_resolution;
using io::require_eval_room;
using io::require_mesh_room;
using io::Resolution;
using io::write_build;

/// The command line's options of counts, as their messages name them.
inline constexpr CountsOption res_option{"--res", "mesh", "vertices", "NUxNV", "NUxNVxNW", "64x64", "33x33x33"};
inline constexpr CountsOption grid_option{"--grid", "grid", "points", "NUxNV", "NUxNVxNW", "100x50", "17x17x17", true};
inline constexpr CountsOption view_res_option{"--res", "view", "samples", "NUxNV", "NUxNVxNW", "257x257", "33x33x33"};
inline constexpr CountsOption shape_option{"--shape", "grid of data points", "points", "NxM", "NxMxL", "40x50", "10x12x14"};

/// The one parser of counts on the command line: "NUxNV" or "NUxNVxNW" (also with
/// "X"), or "K" when the option takes one count; every count at least 2. Returns
/// the 1, 2 or 3 counts. A count too large to represent is returned as the largest
/// size_t, so the size checks refuse it (exit 5) rather than calling it bad usage.
/// @throws usage_error, naming the option and the text.
std::vector<std::size_t> parse_counts(std::string_view text, const CountsOption& option);

/// --res: NUxNV, or NUxNVxNW for a volume. @throws usage_error.
Resolution parse_resolution(std::string_view text);

/// --grid: K (K points along every direction), NUxNV or NUxNVxNW. @throws usage_error.
std::vector<std::size_t> parse_grid(std::string_view text);

/// The evaluation grid `counts` of --grid ask of construction `c`: K becomes KxK or
/// KxKxK (io::grid_resolution). @throws usage_error when the number of counts does
/// not fit its kind.
Resolution grid_resolution(const std::vector<std::size_t>& counts, const io::Construction& c);

/// Refuse (usage_error) counts of `option` whose number does not fit the kind of the
/// construction: three for a surface, two for a volume (io::check_counts_kind).
void check_counts_kind(const io::Construction& c, const CountsOption& option, const Resolution& counts);

/// What SPEC names on the command line: a spec, or a data file of points to
/// interpolate in its place (io/input.hpp).
using io::data_file_spec;
using io::Input;

/// Reads SPEC and --shape ("" when not given) without opening any file.
/// @throws usage_error: a .csv without --shape, --shape with a spec or a .npy, a
/// malformed --shape.
Input parse_input(const std::filesystem::path& spec, std::string_view shape);

/// Refuse (usage_error) an output format the command does not write, before any work
/// (io::check_build_output, ...).
void check_build_output(const std::filesystem::path& out);
void check_mesh_output(const std::filesystem::path& out);
void check_eval_output(const std::filesystem::path& out);
void check_info_output(const std::filesystem::path& out);
void check_view_output(const std::filesystem::path& out);

/// require_eval_room and require_mesh_room (io/outputs.hpp) refuse (error too_large)
/// work too large for this machine before any work.

/// Refuse (usage_error) a resolution or a mesh format that does not fit the kind of
/// the construction: NUxNVxNW for a surface, NUxNV or .obj/.stl/.ply for a volume.
void check_mesh_kind(const io::Construction& c, const std::filesystem::path& out, const Resolution& res);

/// The outputs, from a built construction: write_build (io/outputs.hpp), and these,
/// which check the kind as bad usage, then write through io::write_mesh and
/// io::write_eval with a progress line on a terminal.
void write_mesh(io::Construction& c, const std::filesystem::path& out, const Resolution& res);
/// `grid`: the points along u and v (and w, for a volume).
void write_eval(io::Construction& c, const std::filesystem::path& out, const Resolution& grid);
nlohmann::ordered_json info(const io::Construction& c);

/// Builds a spec file, showing progress on a terminal (the progress callback of
/// `options` is the terminal's). keep_data false: without the copy of the data points
/// that only `info`'s error check uses; defer_exact true: without the exact form,
/// which evaluation does without.
io::Construction build_spec(const std::filesystem::path& spec, io::BuildOptions options = {});

/// io::build_input and io::build_any_input (what eval, info and build take; mesh and
/// view refuse a curve, usage_error), showing progress on a terminal.
io::Construction build_input(const Input& in, io::BuildOptions options = {});
io::Built build_any_input(const Input& in, io::BuildOptions options = {});

/// The subcommands; each returns the exit status of success (0).
int build_command(const Input& in, const std::filesystem::path& out);
/// `res` empty: the default resolution of the construction's kind.
int mesh_command(const Input& in, const std::filesystem::path& out, std::string_view res);
int eval_command(const Input& in, const std::filesystem::path& out, std::string_view grid);
int info_command(const Input& in, const std::optional<std::filesystem::path>& out);
/// The viewer page (io::write_view); `res` empty: io::view_default_resolution.
int view_command(const Input& in, const std::filesystem::path& out, std::string_view res);
int demo_command(const std::filesystem::path& dir);
/// The closest points of the construction to the points of a file (io::write_projection).
int project_command(const Input& in, const std::filesystem::path& points, const std::filesystem::path& out);
/// The hits of the rays of a file on a surface (io::write_intersections).
int intersect_command(const Input& in, const std::filesystem::path& rays, const std::filesystem::path& out);

/// Prints the warnings of a spec (ignored fields) on stderr.
void report_warnings(const std::vector<std::string>& warnings);
/// The warnings of a construction or a curve.
const std::vector<std::string>& warnings_of(const io::Built& b);

}  // namespace interpatch::cli
