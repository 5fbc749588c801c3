// The interpatch command: build, mesh, eval, info, view, project, intersect, demo.
// Exit status: 0 ok, 2 bad usage, 3 invalid input, 4 files, 5 too large, 1 else;
// every failure prints exactly one line on stderr, "interpatch: <message>".

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "exit_status.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/threads.hpp"
#ifdef INTERPATCH_MPI
#include <dlfcn.h>

#include <cstring>

#include "mpi_command.hpp"
#endif

#ifndef INTERPATCH_VERSION
#error "INTERPATCH_VERSION (the CMake project version) is defined by CMakeLists.txt"
#endif

namespace {

#ifdef INTERPATCH_MPI
// eval or build under an MPI launcher: through the module interpatch-mpi.so, beside
// the command or where it is installed. Without it, rank 0 runs the command alone.
int mpi_run(const interpatch::cli::MpiRequest& request, const std::function<int()>& single) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  std::string why = "no path to the command";
  for (const fs::path& d : {dir, dir / INTERPATCH_MPI_MODULE_DIR}) {
    void* module = ::dlopen((d / "interpatch-mpi.so").c_str(), RTLD_NOW | RTLD_LOCAL);
    if (module == nullptr) {
      why = ::dlerror();
      continue;
    }
    void* symbol = ::dlsym(module, "interpatch_mpi_command");
    interpatch::cli::MpiEntry entry = nullptr;
    static_assert(sizeof entry == sizeof symbol);
    std::memcpy(&entry, &symbol, sizeof entry);
    if (entry != nullptr)
      return entry(request.build, request.spec.c_str(), request.shape.c_str(), request.out.c_str(), request.grid.c_str(),
                   &single);
    why = "interpatch-mpi.so has no entry point interpatch_mpi_command";
  }
  if (interpatch::cli::mpi_launched_rank() != 0) return 0;
  std::fprintf(stderr, "interpatch: warning: started by an MPI launcher, but its MPI part cannot be loaded (%s): rank 0 runs the command alone\n",
               why.c_str());
  return single();
}
#endif

// What the command line gives the subcommands.
struct Options {
  std::string spec, shape, out, res, grid, points, demo_dir = "interpatch-demo";
  std::optional<std::string> info_out;
};

// The subcommands, of which CLI11 marks the one given.
struct Commands {
  CLI::App *build, *mesh, *eval, *info, *view, *project, *intersect, *demo;
};

// SPEC and --shape, the same for the four commands that read a construction.
void add_input(CLI::App* command, Options& o, const std::string& footer) {
  command->add_option("SPEC", o.spec,
                      "A spec .json (the format: docs/spec-format.md) or a .npy/.csv data file of points to\n"
                      "interpolate: .npy of shape (n,m,3) (a surface) or (n,m,l,3) (a volume); .csv with --shape")
      ->required();
  command->add_option("--shape", o.shape,
                      "The grid of a .csv SPEC: NxM (a surface) or NxMxL (a volume), one x,y,z line per point\n"
                      "in C order (the last index fastest)");
  command->footer("SPEC as a data file stands for {\"type\": \"interpolate\", \"points\": {\"npy\": FILE}} (or\n"
                  "{\"csv\": FILE, \"shape\": [N, M]}; \"interpolate_volume\" for 3-D grids) with default options.\n"
                  "The spec format: docs/spec-format.md\n\n" +
                  footer);
}

// build, mesh and eval: what they write.
void add_writers(CLI::App& app, Commands& c, Options& o, const std::string& footer) {
  c.build = app.add_subcommand("build", "Write the exact B-spline form (.json, .npz, .step/.stp, .igs/.iges)");
  add_input(c.build, o, footer);
  c.build->add_option("-o,--output", o.out,
                      "Output file: .json (a bspline_surface or bspline_volume spec), .npz (the same arrays for\n"
                      "NumPy: numpy.load; read back by {\"type\": \"bspline_surface\", \"npz\": FILE}),\n"
                      ".step or .stp (STEP AP214), .igs or .iges (IGES 5.3)")
      ->required();

  c.mesh = app.add_subcommand("mesh", "Tessellate the construction (surfaces .obj .stl .ply .vtk .vts .xyz; volumes .vtk .vts .xyz)");
  add_input(c.mesh, o, footer);
  c.mesh->add_option("-o,--output", o.out,
                     "Output file: .obj, .stl, .ply, .vtk, .vts or .xyz (Plot3D); volumes: .vtk, .vts or .xyz\n"
                     "(with the Jacobian determinant; beside .xyz in a .f file)")
      ->required();
  c.mesh->add_option("--res", o.res,
                     "Vertices along u and v, NUxNV (default 64x64); for a volume NUxNVxNW (default 33x33x33)");

  c.eval = app.add_subcommand("eval", "Evaluate on a uniform grid over [0,1]^2, [0,1]^3 for volumes, [0,1] for a curve spec (.npy, .csv)");
  add_input(c.eval, o, footer);
  c.eval->add_option("--grid", o.grid,
                     "Points along each direction: K (KxK, KxKxK for a volume, K for a curve), NUxNV (a surface)\n"
                     "or NUxNVxNW (a volume)")
      ->required();
  c.eval->add_option("-o,--output", o.out,
                     "Output file: .npy of shape (NU,NV,3) or (NU,NV,NW,3), u index first, float64;\n"
                     "or (K,3) for a curve; or .csv, one row per point in the same order, header u,v,x,y,z,\n"
                     "u,v,w,x,y,z or t,x,y,z")
      ->required();
}

// info, view and demo.
void add_viewers(CLI::App& app, Commands& c, Options& o, const std::string& footer) {
  c.info = app.add_subcommand("info", "Describe the construction as one JSON object (stdout, or .json)");
  add_input(c.info, o, footer);
  c.info->add_option("-o,--output", o.info_out, "Write the object to this .json file instead of stdout");

  c.view = app.add_subcommand("view", "Write a viewer page: one self-contained .html file showing it in 3D in a browser");
  add_input(c.view, o, footer);
  c.view->add_option("-o,--output", o.out, "Output file: .html (or .htm), which loads nothing from a network or another file")
      ->required();
  c.view->add_option("--res", o.res,
                     "Samples along u and v, NUxNV (default 257x257); for a volume NUxNVxNW (default 33x33x33);\n"
                     "more than the page holds (512x512, 65x65x65) are decimated for display");

  // project and intersect: SPEC, a file of points (rays), -o.
  const auto query = [&](const char* name, const char* about, const char* input, const char* input_help,
                         const char* output_help) {
    CLI::App* command = app.add_subcommand(name, about);
    add_input(command, o, footer);
    command->add_option(input, o.points, input_help)->required();
    command->add_option("-o,--output", o.out, output_help)->required();
    return command;
  };
  c.project = query("project", "The closest point of a curve or surface to each point of a file, or where a volume holds it",
                    "POINTS", "Points: .npy of shape (..., 3) (float64 or float32), or .csv of x,y,z lines",
                    "Output file: .npz (params, points, distance; volumes also inside), .npy (one row a point:\n"
                    "the parameters, x, y, z, distance[, inside]) or .csv (the same with a header)");
  c.intersect = query("intersect", "Every point where each ray of a file meets a surface", "RAYS",
                      "Rays: .npy of shape (..., 2, 3), origin then direction, or .csv of 6 numbers a line",
                      "Output file: .npz (ray, t, params, points; by ray, then t), .npy (one row a hit: ray, t,\n"
                      "u, v, x, y, z) or .csv (the same with a header)");

  c.demo = app.add_subcommand("demo", "Run every construction on built-in examples");
  c.demo->add_option("-o,--output", o.demo_dir, "Directory for the outputs (created if missing; its parent must exist)")
      ->capture_default_str();
}

// The command as one process runs it.
int run(const Commands& c, const Options& o) {
  namespace cli = interpatch::cli;
  try {
    if (*c.demo) return cli::demo_command(o.demo_dir);
    const cli::Input input = cli::parse_input(o.spec, o.shape);
    if (*c.build) return cli::build_command(input, o.out);
    if (*c.mesh) return cli::mesh_command(input, o.out, o.res);
    if (*c.eval) return cli::eval_command(input, o.out, o.grid);
    if (*c.view) return cli::view_command(input, o.out, o.res);
    if (*c.project) return cli::project_command(input, o.points, o.out);
    if (*c.intersect) return cli::intersect_command(input, o.points, o.out);
    if (*c.info) {
      std::optional<std::filesystem::path> out;
      if (o.info_out) out = *o.info_out;
      return cli::info_command(input, out);
    }
    return cli::fail_with(2, "no command given (see interpatch --help)");
  } catch (const std::exception&) {
    return cli::report_failure(std::current_exception());
  }
}

}  // namespace

int main(int argc, char** argv) {
  namespace cli = interpatch::cli;

  CLI::App app{"interpatch: interpolating curves, surfaces and solids.\n"
               "Reads SPEC, a spec (.json) describing a construction, or a grid of points to interpolate\n"
               "(.npy, or .csv with --shape); writes its exact B-spline form, meshes, evaluation grids\n"
               "and a description. The spec format: docs/spec-format.md",
               "interpatch"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "interpatch " INTERPATCH_VERSION, "Print the version and exit");
  // Set before the subcommands are added: they inherit it, and add their own lines.
  const std::string footer =
      "Exit status: 0 ok, 2 bad usage, 3 invalid input, 4 unreadable/unwritable file, 5 too large, 1 other.\n"
      "Outputs replace files atomically; INTERPATCH_SYNC=1 also waits until they are on the disk.";
  app.footer(footer);

  Options o;
  Commands c{};
  add_writers(app, c, o, footer);
  add_viewers(app, c, o, footer);

  // CLI11 would call an unknown command an extra argument after a missing one.
  if (argc > 1 && argv[1][0] != '-') {
    const std::string first = argv[1];
    if (first != "build" && first != "mesh" && first != "eval" && first != "info" && first != "view" &&
        first != "project" && first != "intersect" && first != "demo")
      return cli::fail_with(2, "unknown command '" + first +
                                   "'; the commands are build, mesh, eval, info, view, project, intersect, demo (see interpatch --help)");
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help
    return cli::fail_with(2, std::string(e.what()) + " (see interpatch --help)");
  }

  // Threads on CPUs of their own before the first parallel loop (threads.hpp).
  interpatch::bind_threads();
  // Outputs are always replaced atomically; INTERPATCH_SYNC=1 also waits for the disk.
  if (const char* sync = std::getenv("INTERPATCH_SYNC"); sync && std::string_view(sync) == "1")
    interpatch::io::set_durable_writes(true);

  // Under an MPI launcher, eval and build are split between the processes
  // (docs/mpi.md) and the other commands run on rank 0.
  const auto single = [&]() -> int { return run(c, o); };
#ifdef INTERPATCH_MPI
  if (cli::mpi_launched()) {
    if (*c.eval || *c.build) return mpi_run({static_cast<bool>(*c.build), o.spec, o.shape, o.out, o.grid}, single);
    if (cli::mpi_launched_rank() != 0) return 0;
  }
#endif
  return single();
}
