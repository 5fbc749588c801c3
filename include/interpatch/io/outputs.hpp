#pragma once
/// @file io/outputs.hpp
/// The files of a built construction and the checks made of them before any work:
/// counts along each direction, output formats, and the memory and disk room a
/// mesh or an evaluation grid needs. Every front end (the command line, its split
/// MPI run, the Python module) calls these, so none accepts what another refuses.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "interpatch/grading.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/progress.hpp"

namespace interpatch::io {

/// Points (or vertices) per direction of a mesh, a viewer page or an evaluation
/// grid; nw is 0 for a surface.
struct Resolution {
  std::size_t nu = 64, nv = 64, nw = 0;
};

/// The default mesh resolutions: 64 × 64 for a surface, 33 × 33 × 33 for a volume.
inline constexpr Resolution default_surface_resolution{64, 64, 0};
inline constexpr Resolution default_volume_resolution{33, 33, 33};

/// The resolution of a mesh when none is asked for: the counts the spec's "sampling"
/// (or `sampling`, when given) gives, the kind's default (64 × 64, 33 × 33 × 33)
/// along the other directions.
[[nodiscard]] Resolution default_resolution(const Construction& c, const Sampling* sampling = nullptr);

/// The parameters of `res` nodes along each direction (each over [0, 1]): the
/// construction's sampling (or `sampling`, when given) with the counts of `res`,
/// graded_parameters() of its evaluator, which reports what the nodes achieve; without
/// any sampling, even steps and an empty report.
/// @throws error as graded_parameters.
[[nodiscard]] GradedParameters sample_parameters(const Construction& c, const Resolution& res,
                                                 const Sampling* sampling = nullptr);

/// How messages name counts along each direction: the option or argument that gave
/// them, what they make and count, and how its user writes them (the command line's
/// --res '64x64', Python's res (64, 64)).
struct CountsOption {
  std::string_view name;                             ///< "--res", "res"
  std::string_view noun;                             ///< what the counts make: "mesh"
  std::string_view unit;                             ///< what they count: "vertices"
  std::string_view surface_form, volume_form;        ///< "NUxNV", "NUxNVxNW"
  std::string_view surface_example, volume_example;  ///< "64x64", "33x33x33"
  bool single = false;                               ///< "K" accepted: K along every direction
  std::string_view open = " '", separator = "x", close = "'";  ///< --res '64x64'
};

/// The counts as `option` writes them, after its name: "--res '0x5'", "res (0, 5)".
[[nodiscard]] std::string counts_text(const CountsOption& option, std::span<const std::size_t> counts);

/// The counts of a resolution, 2 for a surface (nw == 0), 3 for a volume.
[[nodiscard]] std::span<const std::size_t> counts_of(const Resolution& r) noexcept;

/// Refuse counts below 2 along any direction: a mesh, a grid or a page needs both
/// ends of each direction.
///
/// Example:
/// @code
///   constexpr interpatch::io::CountsOption res{"--res", "mesh", "vertices", "NUxNV", "NUxNVxNW", "64x64", "33x33x33"};
///   const std::size_t n[] = {0, 5};
///   interpatch::io::check_counts(n, res);  // "--res '0x5': a mesh needs at least 2 vertices along each direction"
/// @endcode
/// @throws error too_few_points, naming the counts (`given`, or counts_text when empty).
void check_counts(std::span<const std::size_t> counts, const CountsOption& option, std::string_view given = {});

/// Refuse counts whose number does not fit the construction's kind: three for a
/// surface, two for a volume. @throws error size_mismatch.
void check_counts_kind(const Construction& c, const CountsOption& option, const Resolution& counts);

/// The evaluation grid `counts` (K, NU × NV or NU × NV × NW, as `option` takes them)
/// ask of construction `c`: K becomes K × K, or K × K × K for a volume.
/// @throws error size_mismatch when two or three counts do not fit its kind
///   (check_counts_kind).
[[nodiscard]] Resolution grid_resolution(const std::vector<std::size_t>& counts, const Construction& c,
                                         const CountsOption& option);

/// Refuse (error wrong_type) an output format the file kind does not have: build
/// writes .json, .npz, .step/.stp, .igs/.iges; a mesh .obj .stl .ply .vtk .vts .xyz;
/// eval .npy or .csv; info .json; view .html or .htm. Case-insensitive.
void check_build_output(const std::filesystem::path& out);
void check_mesh_output(const std::filesystem::path& out);
void check_eval_output(const std::filesystem::path& out);
void check_info_output(const std::filesystem::path& out);
void check_view_output(const std::filesystem::path& out);

/// Refuse (error wrong_type) a mesh format that holds surfaces only for a volume, then
/// counts that do not fit the construction's kind (check_counts_kind).
void check_mesh_kind(const Construction& c, const std::filesystem::path& out, const Resolution& res,
                     const CountsOption& option);

/// Refuse (error too_large) an evaluation grid whose .npy file cannot fit on the
/// output's disk (it is written a block at a time, and a block must fit in memory) or
/// whose .csv text cannot be made in memory. A count of the largest size_t stands for
/// one too large to represent.
void require_eval_room(const Resolution& grid, const std::filesystem::path& out);

/// Refuse (error too_large) a mesh whose points and normals cannot be held in memory,
/// or, for a surface's .vts or .vtk (written a block of columns at a time), whose
/// file cannot fit on the output's disk.
void require_mesh_room(const Resolution& res, const std::filesystem::path& out);

/// Writes the exact form: .json, .npz, .step/.stp (named after the file's stem) or
/// .igs/.iges. @throws error no_exact_form, wrong_type (another format), and what the
/// writers throw.
void write_build(Construction& c, const std::filesystem::path& out);
/// A curve spec's curve, in the same formats (json_out.hpp, npz.hpp, step.hpp, iges.hpp).
/// @throws error wrong_type (another format), and what the writers throw.
void write_build(const CurveConstruction& c, const std::filesystem::path& out);

/// Writes a mesh of `res` vertices, sampled through the cheaper exact evaluator
/// (evaluator()), which may make the exact form of `c`, at the nodes
/// sample_parameters() places (the construction's sampling, or `sampling` when given).
/// Every check above comes first: the format, counts of at least 2 of the
/// construction's kind (messages naming `option`), the room. `progress` may throw to
/// stop the work.
///
/// Example:
/// @code
///   constexpr interpatch::io::CountsOption res{"res", "mesh", "vertices", "(nu, nv)", "(nu, nv, nw)", "(64, 64)",
///                                              "(33, 33, 33)", false, " (", ", ", ")"};
///   // Warnings are the writer's word to the user (an STL far from the origin for its size).
///   for (const std::string& w : interpatch::io::write_mesh(c, "patch.vts", {200, 100, 0}, res))
///     std::printf("warning: %s\n", w.c_str());
/// @endcode
/// @throws error wrong_type, too_few_points, size_mismatch, too_large, file_unwritable.
/// @returns the writer's warnings for the user (write_surface_mesh: an STL far from
///   the origin for its size), to be shown: the file is written.
[[nodiscard]] std::vector<std::string> write_mesh(Construction& c, const std::filesystem::path& out,
                                                  const Resolution& res, const CountsOption& option,
                                                  const progress_callback& progress = {},
                                                  const Sampling* sampling = nullptr);

/// Writes the points of a grid over [0, 1]^2 ([0, 1]^3 for a volume) of `grid`
/// points, at the parameters sample_parameters() places (even steps unless the spec
/// grades its sampling), u index first: a .npy of shape (NU, NV, 3) or (NU, NV, NW, 3),
/// float64, or a .csv of one row per point in the same order (write_csv_grid). It
/// samples through the cheaper exact evaluator (evaluator()), which may make the
/// exact form of `c`. Every check comes first: the format, counts of at least 2 of
/// the construction's kind (messages naming `option`), the room. `progress` reports
/// the evaluation and may throw to stop it; `evaluated`, when given, is called once
/// the points are made (a .csv is written after it).
/// @throws error wrong_type, too_few_points, size_mismatch, too_large, not_finite (a
///   point whose arithmetic overflowed, refused unwritten), file_unwritable.
void write_eval(Construction& c, const std::filesystem::path& out, const Resolution& grid, const CountsOption& option,
                const progress_callback& progress = {}, const std::function<void()>& evaluated = {});
/// A curve spec's curve at `points` uniformly spaced parameters over [0, 1]: a .npy of
/// shape (K, 3) or a .csv with the header t,x,y,z; checked and reported as above.
void write_eval(const CurveConstruction& c, const std::filesystem::path& out, std::size_t points,
                const CountsOption& option, const progress_callback& progress = {},
                const std::function<void()>& evaluated = {});

}  // namespace interpatch::io
