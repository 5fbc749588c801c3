#pragma once
// The interpatch subcommands (SPEC section 5), shared by main.cpp and the demo.
// Each command checks its usage and its output path before any work, builds the
// spec, and writes through the atomic writers. Errors propagate as exceptions:
// interpatch::error (exit status from exit_status()), usage_error (exit 2).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "interpatch/io/spec.hpp"

namespace interpatch::cli {

/// Bad usage of the command line; the command exits with 2.
class usage_error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Vertices per direction of a mesh; nw is 0 for a surface mesh.
struct Resolution {
  std::size_t nu = 64, nv = 64, nw = 0;
};

/// The default resolutions: 64x64 for a surface, 33x33x33 for a volume.
inline constexpr Resolution default_surface_resolution{64, 64, 0};
inline constexpr Resolution default_volume_resolution{33, 33, 33};

/// "NUxNV" or, for volumes, "NUxNVxNW" (also with "X"), every count at least 2.
/// @throws usage_error.
Resolution parse_resolution(std::string_view text);

/// "K", at least 2. A K too large to count is returned as the largest size_t, so
/// the memory check refuses it (exit 5) rather than calling it bad usage.
/// @throws usage_error.
std::size_t parse_grid(std::string_view text);

/// Refuse an output format the command does not write (usage_error), then an output
/// path that cannot be written (error file_unwritable), before any work.
void check_build_output(const std::filesystem::path& out);
void check_mesh_output(const std::filesystem::path& out);
void check_eval_output(const std::filesystem::path& out);
void check_info_output(const std::filesystem::path& out);

/// Refuse (error too_large) an evaluation grid whose .npy file cannot fit on the
/// output's disk (it is written a block at a time) or whose .csv text cannot be made
/// in memory. `dims` is 2 for a K×K grid, 3 for K×K×K.
void require_eval_room(std::size_t k, const std::filesystem::path& out, int dims = 2);
void require_mesh_memory(const Resolution& res);

/// Refuse (usage_error) a resolution or a mesh format that does not fit the kind of
/// the construction: NUxNVxNW for a surface, NUxNV or .obj/.stl/.ply for a volume.
void check_mesh_kind(const io::Construction& c, const std::filesystem::path& out, const Resolution& res);

/// The outputs, from a built construction.
void write_build(const io::Construction& c, const std::filesystem::path& out);
void write_mesh(const io::Construction& c, const std::filesystem::path& out, const Resolution& res);
void write_eval(const io::Construction& c, const std::filesystem::path& out, std::size_t k);
nlohmann::ordered_json info(const io::Construction& c);

/// Builds a spec file, showing progress on a terminal. `keep_data` false: without the
/// copy of the data points that only `info`'s error check uses.
io::Construction build_spec(const std::filesystem::path& spec, bool keep_data = true);

/// The subcommands; each returns the exit status of success (0).
int build_command(const std::filesystem::path& spec, const std::filesystem::path& out);
/// `res` empty: the default resolution of the construction's kind.
int mesh_command(const std::filesystem::path& spec, const std::filesystem::path& out, std::string_view res);
int eval_command(const std::filesystem::path& spec, const std::filesystem::path& out, std::string_view grid);
int info_command(const std::filesystem::path& spec, const std::optional<std::filesystem::path>& out);
int demo_command(const std::filesystem::path& dir);

/// Prints the warnings of a construction (ignored fields) on stderr.
void report_warnings(const io::Construction& c);

}  // namespace interpatch::cli
