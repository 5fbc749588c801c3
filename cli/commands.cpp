#include "commands.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <variant>
#include <vector>

#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/csv.hpp"
#include "interpatch/io/iges.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/step.hpp"
#include "interpatch/memory.hpp"
#include "progress.hpp"

namespace interpatch::cli {

namespace fs = std::filesystem;

namespace {

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A count on the command line: digits only. nullopt for anything else; the
// largest size_t for a count too large to represent.
std::optional<std::size_t> parse_count(std::string_view s) {
  if (s.empty() || !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; }))
    return std::nullopt;
  std::size_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range) return std::numeric_limits<std::size_t>::max();
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::string what_size(std::size_t a, std::size_t b) { return std::to_string(a) + "x" + std::to_string(b); }
std::string what_size(std::size_t a, std::size_t b, std::size_t c) { return what_size(a, b) + "x" + std::to_string(c); }

std::string resolution_text(const Resolution& r) { return r.nw ? what_size(r.nu, r.nv, r.nw) : what_size(r.nu, r.nv); }

// Points as float64 triples in C order, for .npy: a grid's own memory (Vec3 is
// three doubles), written without a copy.
std::span<const double> flat_points(const Vec3* p, std::size_t n) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 grids are written as arrays of doubles");
  return {&p->x, 3 * n};
}

// An evaluation grid written to .npy block by block along u: evaluate(us, out) fills
// out with the points of the u values `us` (per_row points each). A block is about
// 2^17 points (3 MiB): work enough for both threads, still in the cache when it is
// written, and the whole grid is never held in memory.
template <class Evaluate>
void write_npy_by_rows(const fs::path& out, std::span<const std::size_t> shape, std::span<const double> us,
                       std::size_t per_row, const progress_callback& progress, const Evaluate& evaluate) {
  const std::size_t rows = std::max<std::size_t>(1, (std::size_t{1} << 17) / per_row);
  std::vector<Vec3> block(std::min(rows, us.size()) * per_row);
  io::write_npy(out, shape, 3 * rows * per_row, [&](std::size_t first, std::size_t count) {
    const std::size_t r0 = first / (3 * per_row), n = count / (3 * per_row);
    const std::span<Vec3> points(block.data(), n * per_row);
    evaluate(us.subspan(r0, n), points);
    if (progress) progress(static_cast<double>(r0 + n) / static_cast<double>(us.size()));
    return flat_points(points.data(), points.size());
  });
}

void mesh_volume(const io::Construction& c, const fs::path& out, const Resolution& res) {
  const Volume& v = io::volume_evaluator(c);
  // Every construction is over the unit cube.
  const std::vector<double> us = linspace(0, 1, res.nu), vs = linspace(0, 1, res.nv), ws = linspace(0, 1, res.nw);
  ProgressLine progress("meshing");
  const VolumeJacobians j = v.evaluate_jacobians(us, vs, ws, progress.callback());
  progress.clear();
  io::write_volume_mesh(out, j.points, j.determinants);
}

void eval_volume(const io::Construction& c, const fs::path& out, std::size_t k) {
  const Volume& v = io::volume_evaluator(c);
  const std::vector<std::vector<double>> params{linspace(0, 1, k), linspace(0, 1, k), linspace(0, 1, k)};
  ProgressLine progress("evaluating");
  if (lower_extension(out) == ".npy") {
    const std::size_t shape[4] = {k, k, k, 3};
    write_npy_by_rows(out, shape, params[0], k * k, progress.callback(),
                      [&](std::span<const double> us, std::span<Vec3> points) {
                        v.evaluate_into(us, params[1], params[2], points);
                      });
    progress.clear();
    return;
  }
  const PointGrid3 g = v.evaluate(params[0], params[1], params[2], progress.callback());
  progress.clear();
  io::write_csv_grid(out, params, std::span<const Vec3>(g.data(), g.size()));
}

}  // namespace

Resolution parse_resolution(std::string_view text) {
  const auto x = text.find_first_of("xX");
  const auto bad = [&](std::string_view why) {
    return usage_error("--res '" + std::string(text) + "': " + std::string(why));
  };
  if (x == std::string_view::npos)
    throw bad("expected NUxNV, e.g. 64x64 (vertices along u and v), or NUxNVxNW for a volume");
  const auto x2 = text.find_first_of("xX", x + 1);
  if (x2 != std::string_view::npos) {
    if (text.find_first_of("xX", x2 + 1) != std::string_view::npos)
      throw bad("expected NUxNV (a surface) or NUxNVxNW (a volume), not more counts");
    const auto nu = parse_count(text.substr(0, x)), nv = parse_count(text.substr(x + 1, x2 - x - 1)),
               nw = parse_count(text.substr(x2 + 1));
    if (!nu || !nv || !nw) throw bad("expected NUxNVxNW with whole numbers, e.g. 33x33x33");
    if (*nu < 2 || *nv < 2 || *nw < 2) throw bad("a mesh needs at least 2 vertices along each direction");
    return {*nu, *nv, *nw};
  }
  const auto nu = parse_count(text.substr(0, x)), nv = parse_count(text.substr(x + 1));
  if (!nu || !nv) throw bad("expected NUxNV with whole numbers, e.g. 64x64");
  if (*nu < 2 || *nv < 2) throw bad("a mesh needs at least 2 vertices along each direction");
  return {*nu, *nv, 0};
}

std::size_t parse_grid(std::string_view text) {
  const auto k = parse_count(text);
  if (!k) throw usage_error("--grid '" + std::string(text) + "': expected a whole number K >= 2 (a KxK grid)");
  if (*k < 2) throw usage_error("--grid " + std::string(text) + ": a grid needs at least 2 points along each direction");
  return *k;
}

void check_build_output(const fs::path& out) {
  const std::string ext = lower_extension(out);
  if (ext == ".json" || ext == ".step" || ext == ".stp" || ext == ".igs" || ext == ".iges") return;
  throw usage_error("cannot tell the output format of '" + out.string() +
                    "': build writes .json, .step/.stp (STEP AP214) or .igs/.iges (IGES 5.3)");
}

void check_mesh_output(const fs::path& out) {
  if (io::is_mesh_format(out.extension().string())) return;
  throw usage_error("cannot tell the mesh format of '" + out.string() + "': use .obj, .stl, .ply, .vtk, .vts or .xyz");
}

void check_eval_output(const fs::path& out) {
  const std::string ext = lower_extension(out);
  if (ext == ".npy" || ext == ".csv") return;
  throw usage_error("cannot tell the output format of '" + out.string() + "': eval writes .npy or .csv");
}

void check_info_output(const fs::path& out) {
  if (lower_extension(out) == ".json") return;
  throw usage_error("cannot tell the output format of '" + out.string() + "': info writes .json");
}

void require_eval_room(std::size_t k, const fs::path& out, int dims) {
  const std::string size = dims == 3 ? what_size(k, k, k) : what_size(k, k);
  const std::string what = "evaluation grid " + (k == std::numeric_limits<std::size_t>::max() ? std::string("beyond 2^64") : size);
  if (k >= (std::size_t{1} << (dims == 3 ? 21 : 32))) throw error(errc::too_large, what + ": more points than can be addressed");
  const std::size_t points = dims == 3 ? k * k * k : k * k;
  if (lower_extension(out) == ".npy") {
    // Evaluated and written a block at a time: the memory of one block, the disk
    // space of the whole file (the header is at most a few hundred bytes).
    if (points > (std::numeric_limits<std::size_t>::max() - 4096) / sizeof(Vec3))
      throw error(errc::too_large, what + ": more bytes than a file can hold");
    io::check_disk_space(out, points * sizeof(Vec3) + 4096, what);
    return;
  }
  // The points, plus the text of a row for .csv.
  require_memory(points, sizeof(Vec3) + 8, what);
}

void require_mesh_memory(const Resolution& res) {
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
  // Points and normals, plus room for the writers' faces (two triangles per vertex in STL).
  require_memory(res.nu * res.nv, 2 * sizeof(Vec3) + 2 * 50, what);
}

void check_mesh_kind(const io::Construction& c, const fs::path& out, const Resolution& res) {
  const std::string r = resolution_text(res);
  if (!io::is_volume(c)) {
    if (res.nw) throw usage_error("--res '" + r + "': a surface mesh takes two counts, NUxNV (NUxNVxNW is for volumes)");
    return;
  }
  const std::string ext = lower_extension(out);
  if (ext != ".vts" && ext != ".vtk" && ext != ".xyz")
    throw usage_error("'" + out.string() + "': " + c.type + " is a volume; " + ext +
                      " holds surfaces only, a volume mesh is written to .vts, .vtk or .xyz (Plot3D)");
  if (!res.nw) throw usage_error("--res '" + r + "': " + c.type + " is a volume; its mesh takes three counts, NUxNVxNW (e.g. 33x33x33)");
}

void write_build(const io::Construction& c, const fs::path& out) {
  if (!c.exact) throw error(errc::no_exact_form, c.type + ": " + c.no_exact_form);
  const std::string ext = lower_extension(out);
  // The product (STEP) or file (IGES) is named after the output file.
  const std::string name = out.stem().string();
  if (ext == ".step" || ext == ".stp") return io::write_step(out, *c.exact, {.name = name, .time_stamp = {}});
  if (ext == ".igs" || ext == ".iges") return io::write_iges(out, *c.exact, {.name = out.filename().string(), .time_stamp = {}});
  io::write_exact_json(out, *c.exact);
}

void write_mesh(const io::Construction& c, const fs::path& out, const Resolution& res) {
  check_mesh_kind(c, out, res);
  if (io::is_volume(c)) return mesh_volume(c, out, res);
  const Surface& s = io::evaluator(c);
  constexpr double u0 = 0, u1 = 1, v0 = 0, v1 = 1;  // every construction is over the unit square
  const std::vector<double> us = linspace(u0, u1, res.nu), vs = linspace(v0, v1, res.nv);
  io::SurfaceMesh mesh{PointGrid({res.nu, res.nv}), PointGrid({res.nu, res.nv})};
  ProgressLine progress("meshing");
  // Derivatives a block of rows at a time: the full grid of them would be six
  // times the size of the mesh.
  const std::size_t block = std::max<std::size_t>(1, (std::size_t{1} << 15) / res.nv);
  for (std::size_t i0 = 0; i0 < res.nu; i0 += block) {
    const std::size_t nb = std::min(block, res.nu - i0);
    const auto d = s.evaluate_derivatives(std::span<const double>(us).subspan(i0, nb), vs);
    for (std::size_t i = 0; i < nb; ++i)
      for (std::size_t j = 0; j < res.nv; ++j) {
        mesh.points(i0 + i, j) = d(i, j).s;
        mesh.normals(i0 + i, j) = unit_normal(d(i, j));
      }
    progress.update(static_cast<double>(i0 + nb) / static_cast<double>(res.nu));
  }
  progress.clear();
  io::write_surface_mesh(out, mesh);
}

void write_eval(const io::Construction& c, const fs::path& out, std::size_t k) {
  if (io::is_volume(c)) return eval_volume(c, out, k);
  const Surface& s = io::evaluator(c);
  constexpr double u0 = 0, u1 = 1, v0 = 0, v1 = 1;  // every construction is over the unit square
  std::vector<std::vector<double>> params{linspace(u0, u1, k), linspace(v0, v1, k)};
  ProgressLine progress("evaluating");
  if (lower_extension(out) == ".npy") {
    const std::size_t shape[3] = {k, k, 3};
    write_npy_by_rows(out, shape, params[0], k, progress.callback(),
                      [&](std::span<const double> us, std::span<Vec3> points) { s.evaluate_into(us, params[1], points); });
    progress.clear();
    return;
  }
  const PointGrid g = s.evaluate(params[0], params[1], progress.callback());
  progress.clear();
  io::write_csv_grid(out, params, std::span<const Vec3>(g.data(), g.size()));
}

nlohmann::ordered_json info(const io::Construction& c) {
  ProgressLine progress("checking");
  return io::info_json(c, progress.callback());
}

io::Construction build_spec(const fs::path& spec, bool keep_data) {
  ProgressLine progress("building");
  return io::build_file(spec, progress.callback(), keep_data);
}

void report_warnings(const io::Construction& c) {
  for (const std::string& w : c.warnings) std::fprintf(stderr, "interpatch: warning: %s\n", w.c_str());
}

int build_command(const fs::path& spec, const fs::path& out) {
  check_build_output(out);
  io::check_writable(out);
  const io::Construction c = build_spec(spec, false);
  write_build(c, out);
  report_warnings(c);
  return 0;
}

int mesh_command(const fs::path& spec, const fs::path& out, std::string_view res_text) {
  const std::optional<Resolution> given = res_text.empty() ? std::nullopt : std::optional(parse_resolution(res_text));
  check_mesh_output(out);
  io::check_writable(out);
  if (given) require_mesh_memory(*given);
  const io::Construction c = build_spec(spec, false);
  const Resolution res = given ? *given : (io::is_volume(c) ? default_volume_resolution : default_surface_resolution);
  check_mesh_kind(c, out, res);
  if (!given) require_mesh_memory(res);
  write_mesh(c, out, res);
  report_warnings(c);
  return 0;
}

int eval_command(const fs::path& spec, const fs::path& out, std::string_view grid) {
  const std::size_t k = parse_grid(grid);
  check_eval_output(out);
  io::check_writable(out);
  require_eval_room(k, out);
  const io::Construction c = build_spec(spec, false);
  if (io::is_volume(c)) require_eval_room(k, out, 3);
  write_eval(c, out, k);
  report_warnings(c);
  return 0;
}

int info_command(const fs::path& spec, const std::optional<fs::path>& out) {
  if (out) {
    check_info_output(*out);
    io::check_writable(*out);
  }
  const io::Construction c = build_spec(spec);
  const std::string text = io::pretty_json(info(c));
  if (out) {
    io::write_atomically(*out, [&](std::ostream& os) { os << text; });
  } else {
    std::cout << text << std::flush;
    if (!std::cout) throw error(errc::file_unwritable, "standard output: write failed");
  }
  report_warnings(c);
  return 0;
}

}  // namespace interpatch::cli
