// The files of a built construction and the checks made of them before any work,
// shared by the command line and the Python module.

#include "interpatch/io/outputs.hpp"

#include <algorithm>
#include <cctype>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/iges.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/npz.hpp"
#include "interpatch/io/step.hpp"
#include "interpatch/io/view.hpp"
#include "interpatch/memory.hpp"
#include "interpatch/mesh_quality.hpp"
#include "base/text.hpp"
#include "io/blocks_mesh.hpp"
#include "io/extension.hpp"
#include "io/mesh_formats.hpp"
#include "mesh/quality.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;

namespace {

using detail::cat;
using internal::lower_extension;

std::string resolution_text(const Resolution& r) {
  std::string t = std::to_string(r.nu) + "x" + std::to_string(r.nv);
  return r.nw ? t + "x" + std::to_string(r.nw) : t;
}

// The number of points of a grid, or nullopt when it overflows a size_t.
std::optional<std::size_t> point_count(const Resolution& r) {
  std::size_t n = 1;
  for (const std::size_t c : {r.nu, r.nv, r.nw ? r.nw : std::size_t{1}}) {
    if (c != 0 && n > std::numeric_limits<std::size_t>::max() / c) return std::nullopt;
    n *= c;
  }
  return n;
}

// Writes the mesh; a warning when cells are inverted, which a solver refuses.
std::vector<std::string> mesh_volume(const Construction& c, const fs::path& out, const Resolution& res,
                                     const progress_callback& progress, const Sampling* sampling) {
  const Volume& v = volume_evaluator(c);
  const GradedParameters p = sample_parameters(c, res, sampling);
  const VolumeJacobians j = v.evaluate_jacobians(p.params[0], p.params[1], p.params[2], progress);
  const MeshQuality q = corner_jacobians(j.points);
  write_volume_mesh(out, j.points, j.determinants);
  if (q.inverted_cells == 0) return {};
  const auto& at = q.first_inverted;
  return {cat(out.filename().string(), ": ", q.inverted_cells, " of ", q.cells,
              " cells are inverted or flat (a corner's det J against the mesh's orientation, scaled "
              "Jacobian down to ",
              q.min_scaled_jacobian, "), the first between nodes (", at[0], ", ", at[1], ", ", at[2], ") and (",
              at[0] + 1, ", ", at[1] + 1, ", ", at[2] + 1, "); a solver will refuse them")};
}

// The blocks' cells merged into one mesh; a warning when some are inverted.
std::vector<std::string> mesh_of_blocks(const Construction& c, const fs::path& out, const progress_callback& progress) {
  const internal::BlocksMesh b = internal::mesh_blocks(c, progress);
  const MeshQuality q = mesh::corner_jacobians(b.hex);
  if (is_polymesh_path(out)) internal::mesh_io::write_polymesh(out, b.hex);
  else internal::mesh_io::write_unstructured(out, lower_extension(out), b.hex, b.jacobian);
  if (q.inverted_cells == 0) return {};
  return {cat(out.filename().string(), ": ", q.inverted_cells, " of ", q.cells,
              " cells are inverted or flat (a corner's det J against the mesh's orientation, scaled Jacobian down to ",
              q.min_scaled_jacobian, "), the first cell numbered ", q.first_inverted[0], "; a solver will refuse them")};
}

}  // namespace

std::string counts_text(const CountsOption& option, std::span<const std::size_t> counts) {
  std::string t = std::string(option.name) + std::string(option.open);
  for (std::size_t k = 0; k < counts.size(); ++k) t += (k ? std::string(option.separator) : "") + std::to_string(counts[k]);
  return t + std::string(option.close);
}

Resolution default_resolution(const Construction& c, const Sampling* sampling) {
  Resolution r = is_volume(c) ? default_volume_resolution : default_surface_resolution;
  if (!sampling && c.sampling) sampling = &*c.sampling;
  if (sampling) {
    std::size_t* counts[] = {&r.nu, &r.nv, &r.nw};
    for (std::size_t d = 0; d < (is_volume(c) ? 3u : 2u); ++d)
      if ((*sampling)[d].count != 0) *counts[d] = (*sampling)[d].count;
  }
  return r;
}

GradedParameters sample_parameters(const Construction& c, const Resolution& res, const Sampling* sampling) {
  const bool volume = is_volume(c);
  const std::size_t counts[] = {res.nu, res.nv, res.nw};
  if (!sampling && !c.sampling) {  // every construction is over the unit square (cube)
    GradedParameters p;
    for (std::size_t d = 0; d < (volume ? 3u : 2u); ++d) p.params[d] = linspace(0, 1, counts[d]);
    return p;
  }
  Sampling s = sampling ? *sampling : *c.sampling;
  for (std::size_t d = 0; d < 3; ++d) s[d].count = counts[d];
  return volume ? graded_parameters(volume_evaluator(c), s) : graded_parameters(evaluator(c), s);
}

std::span<const std::size_t> counts_of(const Resolution& r) noexcept { return {&r.nu, r.nw ? 3u : 2u}; }

void check_counts(std::span<const std::size_t> counts, const CountsOption& o, std::string_view given) {
  if (std::none_of(counts.begin(), counts.end(), [](std::size_t n) { return n < 2; })) return;
  throw error(errc::too_few_points, (given.empty() ? counts_text(o, counts) : std::string(given)) + ": a " +
                                        std::string(o.noun) + " needs at least 2 " + std::string(o.unit) +
                                        " along each direction");
}

void check_counts_kind(const Construction& c, const CountsOption& o, const Resolution& counts) {
  const std::string given = counts_text(o, counts_of(counts)) + ": ";
  const std::string k_or = o.single ? "K or " : "";
  if (!is_volume(c) && counts.nw)
    throw error(errc::size_mismatch, given + "a surface " + std::string(o.noun) + " takes " + k_or + "two counts, " +
                                         std::string(o.surface_form) + " (" + std::string(o.volume_form) + " is for volumes)");
  if (is_volume(c) && !counts.nw)
    throw error(errc::size_mismatch, given + c.type + " is a volume; its " + std::string(o.noun) + " takes " + k_or +
                                         "three counts, " + std::string(o.volume_form) + " (e.g. " +
                                         std::string(o.volume_example) + ")");
}

void check_build_output(const fs::path& out) {
  const std::string ext = lower_extension(out);
  if (ext == ".json" || ext == ".npz" || ext == ".step" || ext == ".stp" || ext == ".igs" || ext == ".iges") return;
  throw error(errc::wrong_type, "cannot tell the output format of '" + out.string() +
                                    "': build writes .json, .npz (NumPy), .step/.stp (STEP AP214) or .igs/.iges (IGES 5.3)");
}

void check_mesh_output(const fs::path& out) {
  if (is_mesh_format(out.extension().string()) || is_polymesh_path(out)) return;
  throw error(errc::wrong_type, "cannot tell the mesh format of '" + out.string() +
                                    "': use .obj, .stl, .ply, .vtk, .vts, .xyz, .vtu or .msh, or a directory "
                                    "CASE/constant/polyMesh");
}

void check_eval_output(const fs::path& out) {
  const std::string ext = lower_extension(out);
  if (ext == ".npy" || ext == ".csv") return;
  throw error(errc::wrong_type, "cannot tell the output format of '" + out.string() + "': eval writes .npy or .csv");
}

void check_info_output(const fs::path& out) {
  if (lower_extension(out) == ".json") return;
  throw error(errc::wrong_type, "cannot tell the output format of '" + out.string() + "': info writes .json");
}

void check_view_output(const fs::path& out) {
  if (is_view_format(out.extension().string())) return;
  throw error(errc::wrong_type,
              "cannot tell the output format of '" + out.string() + "': view writes .html (or .htm)");
}

void check_mesh_kind(const Construction& c, const fs::path& out, const Resolution& res, const CountsOption& option) {
  const std::string ext = lower_extension(out);
  if (c.blocks && !(ext == ".vtu" || ext == ".msh" || is_polymesh_path(out)))
    throw error(errc::wrong_type, "'" + out.string() +
                                      "': blocks are meshed together as unstructured cells: .vtu, .msh (Gmsh) or a "
                                      "polyMesh directory (OpenFOAM); each block's own spec gives its structured grid");
  if (!is_volume(c) && is_polymesh_path(out))
    throw error(errc::wrong_type, "'" + out.string() + "': " + c.type +
                                      " is a surface; an OpenFOAM polyMesh holds the cells of a volume");
  const bool volume_format = ext == ".vts" || ext == ".vtk" || ext == ".xyz" || ext == ".vtu" || ext == ".msh" ||
                             is_polymesh_path(out);
  if (is_volume(c) && !volume_format)
    throw error(errc::wrong_type, "'" + out.string() + "': " + c.type + " is a volume; " + ext +
                                      " holds surfaces only, a volume mesh is written to .vts, .vtk, .xyz (Plot3D), "
                                      ".vtu, .msh (Gmsh) or a polyMesh directory (OpenFOAM)");
  if (!is_volume(c) && (ext == ".vtu" || ext == ".msh"))
    throw error(errc::wrong_type, "'" + out.string() + "': " + c.type + " is a surface; " + ext +
                                      " is written with the hexahedral cells of a volume");
  check_counts_kind(c, option, res);
}

void require_eval_room(const Resolution& grid, const fs::path& out) {
  constexpr std::size_t beyond = std::numeric_limits<std::size_t>::max();  // a count too large to represent
  const bool uncountable = grid.nu == beyond || grid.nv == beyond || grid.nw == beyond;
  const std::string what = "evaluation grid " + (uncountable ? std::string("beyond 2^64") : resolution_text(grid));
  const std::optional<std::size_t> points = point_count(grid);
  if (uncountable || !points) throw error(errc::too_large, what + ": more points than can be addressed");
  if (lower_extension(out) == ".npy") {
    // Evaluated and written a block at a time: the disk space of the whole file (the
    // header is at most a few hundred bytes), the memory of one block.
    if (*points > (std::numeric_limits<std::size_t>::max() - 4096) / sizeof(Vec3))
      throw error(errc::too_large, what + ": more bytes than a file can hold");
    check_disk_space(out, *points * sizeof(Vec3) + 4096, what);
    const std::size_t per_row = *points / grid.nu;
    require_memory(write_npy_rows_held(grid.nu, 3 * per_row), sizeof(double), what + ", two blocks of u values");
    return;
  }
  // The points, plus the text of a row for .csv.
  require_memory(*points, sizeof(Vec3) + 8, what);
}

void require_mesh_room(const Resolution& res, const fs::path& out) {
  const std::string what = "mesh of " + resolution_text(res) + " vertices";
  if (res.nw) {
    constexpr std::size_t limit = std::size_t{1} << 21;
    if (res.nu >= limit || res.nv >= limit || res.nw >= limit)
      throw error(errc::too_large, what + ": more vertices than can be addressed");
    // Points and Jacobian determinants, plus the text of a vertex in the ASCII formats.
    require_memory(res.nu * res.nv * res.nw, sizeof(Vec3) + sizeof(double) + 80, what);
    return;
  }
  if (res.nu >= (std::size_t{1} << 32) || res.nv >= (std::size_t{1} << 32))
    throw error(errc::too_large, what + ": more vertices than can be addressed");
  if (const std::string ext = lower_extension(out); ext == ".vts" || ext == ".vtk") {
    // Written a block of columns at a time: the disk space of the file (points and
    // normals, 48 bytes a vertex, and at most a few kilobytes of XML or header).
    const std::size_t n = res.nu * res.nv;
    if (n > (std::numeric_limits<std::size_t>::max() - 4096) / (2 * sizeof(Vec3)))
      throw error(errc::too_large, what + ": more bytes than a file can hold");
    check_disk_space(out, n * 2 * sizeof(Vec3) + 4096, what);
    return;
  }
  // Points and normals, plus room for the writers' faces (two triangles per vertex in STL).
  require_memory(res.nu * res.nv, 2 * sizeof(Vec3) + 2 * 50, what);
}

namespace {

// An exact form or a curve in the format the extension names (checked before).
template <class Form>
void write_exact(const Form& form, const fs::path& out) {
  const std::string ext = lower_extension(out);
  // The product (STEP) or file (IGES) is named after the output file.
  if (ext == ".step" || ext == ".stp") return write_step(out, form, {.name = out.stem().string(), .time_stamp = {}});
  if (ext == ".igs" || ext == ".iges") return write_iges(out, form, {.name = out.filename().string(), .time_stamp = {}});
  if (ext == ".npz") return write_exact_npz(out, form);
  write_exact_json(out, form);
}

}  // namespace

void write_build(Construction& c, const fs::path& out) {
  check_build_output(out);
  write_exact(exact_form(c), out);
}

void write_build(const CurveConstruction& c, const fs::path& out) {
  check_build_output(out);
  write_exact(c.curve, out);
}

std::vector<std::string> write_mesh(Construction& c, const fs::path& out, const Resolution& res,
                                    const CountsOption& option, const progress_callback& progress,
                                    const Sampling* sampling) {
  check_mesh_output(out);
  check_counts(counts_of(res), option);
  check_mesh_kind(c, out, res, option);
  require_mesh_room(res, out);
  if (c.blocks) {
    if (sampling)
      throw error(errc::wrong_type, "sampling: a blocks spec's nodes come from each block's \"sampling\", tied across "
                                    "the faces they share");
    return mesh_of_blocks(c, out, progress);
  }
  if (is_volume(c)) {
    return mesh_volume(c, out, res, progress, sampling);
  }
  const Surface& s = evaluator(c, res.nu * res.nv, Sample::derivatives);
  const GradedParameters p = sample_parameters(c, res, sampling);
  return write_surface_mesh(out, s, p.params[0], p.params[1], progress);  // a .vts or .vtk a block at a time
}

}  // namespace interpatch::io
