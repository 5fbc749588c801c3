// The interpatch command (SPEC section 5): build, mesh, eval, info, demo.
// Exit status: 0 ok, 2 bad usage, 3 invalid input, 4 files, 5 too large, 1 else;
// every failure prints exactly one line on stderr, "interpatch: <message>".

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "exit_status.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/threads.hpp"

namespace {

// One line, whatever the message holds.
int fail_with(int status, std::string message) {
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  std::fprintf(stderr, "interpatch: %s\n", message.c_str());
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  namespace cli = interpatch::cli;

  CLI::App app{"interpatch: interpolating curves, surfaces and solids.\n"
               "Reads a SPEC.json describing a construction; writes its exact B-spline form,\n"
               "meshes, evaluation grids and a description.",
               "interpatch"};
  app.require_subcommand(1);
  app.footer("Exit status: 0 ok, 2 bad usage, 3 invalid input, 4 unreadable/unwritable file, 5 too large, 1 other.\n"
             "Outputs replace files atomically; INTERPATCH_SYNC=1 also waits until they are on the disk.");

  std::string spec, out, res, grid, demo_dir = "interpatch-demo";

  CLI::App* build = app.add_subcommand("build", "Write the exact B-spline form of SPEC.json (.json)");
  build->add_option("SPEC", spec, "The spec file (SPEC.json)")->required();
  build->add_option("-o,--output", out, "Output file: .json")->required();

  CLI::App* mesh = app.add_subcommand("mesh", "Tessellate the construction (.obj .stl .ply .vtk .vts .xyz)");
  mesh->add_option("SPEC", spec, "The spec file (SPEC.json)")->required();
  mesh->add_option("-o,--output", out, "Output file: .obj, .stl, .ply, .vtk, .vts or .xyz (Plot3D); volumes: .vtk, .vts or .xyz")->required();
  mesh->add_option("--res", res,
                   "Vertices along u and v, NUxNV (default 64x64); for a volume NUxNVxNW (default 33x33x33)");

  CLI::App* eval = app.add_subcommand("eval", "Evaluate on a uniform KxK grid over [0,1]^2 (KxKxK over [0,1]^3 for volumes; .npy or .csv)");
  eval->add_option("SPEC", spec, "The spec file (SPEC.json)")->required();
  eval->add_option("--grid", grid, "K: points along each direction")->required();
  eval->add_option("-o,--output", out, "Output file: .npy (K,K,3) or (K,K,K,3), u index first, or .csv (u,v[,w],x,y,z)")->required();

  CLI::App* info = app.add_subcommand("info", "Describe the construction as one JSON object on stdout");
  info->add_option("SPEC", spec, "The spec file (SPEC.json)")->required();
  std::optional<std::string> info_out;
  info->add_option("-o,--output", info_out, "Write the object to this .json file instead of stdout");

  CLI::App* demo = app.add_subcommand("demo", "Run every construction on built-in examples");
  demo->add_option("-o,--output", demo_dir, "Directory for the outputs (created if missing; its parent must exist)")
      ->capture_default_str();

  // CLI11 would call an unknown command an extra argument after a missing one.
  if (argc > 1 && argv[1][0] != '-') {
    const std::string first = argv[1];
    if (first != "build" && first != "mesh" && first != "eval" && first != "info" && first != "demo")
      return fail_with(2, "unknown command '" + first + "'; the commands are build, mesh, eval, info, demo (see interpatch --help)");
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help
    return fail_with(2, std::string(e.what()) + " (see interpatch --help)");
  }

  // Threads on CPUs of their own before the first parallel loop (threads.hpp).
  interpatch::bind_threads();
  // Outputs are always replaced atomically; INTERPATCH_SYNC=1 also waits for the disk.
  if (const char* sync = std::getenv("INTERPATCH_SYNC"); sync && std::string_view(sync) == "1")
    interpatch::io::set_durable_writes(true);

  try {
    if (*build) return cli::build_command(spec, out);
    if (*mesh) return cli::mesh_command(spec, out, res);
    if (*eval) return cli::eval_command(spec, out, grid);
    if (*info) {
      std::optional<std::filesystem::path> o;
      if (info_out) o = *info_out;
      return cli::info_command(spec, o);
    }
    if (*demo) return cli::demo_command(demo_dir);
    return fail_with(2, "no command given (see interpatch --help)");
  } catch (const interpatch::error& e) {
    return fail_with(cli::exit_status(e.code()), e.what());
  } catch (const cli::usage_error& e) {
    return fail_with(2, e.what());
  } catch (const std::bad_alloc&) {
    return fail_with(5, "out of memory");
  } catch (const std::exception& e) {
    return fail_with(1, e.what());
  }
}
