// The checks of outputs every front door makes (io/outputs.hpp): counts of at least 2
// of the construction's kind, output formats, the room a mesh or a grid needs, each
// refused with its code and the command line's message before any work; and the
// writers, which make the same checks themselves.

#include "interpatch/io/outputs.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {

namespace fs = std::filesystem;

constexpr CountsOption cli_res{"--res", "mesh", "vertices", "NUxNV", "NUxNVxNW", "64x64", "33x33x33"};
constexpr CountsOption cli_grid{"--grid", "grid", "points", "NUxNV", "NUxNVxNW", "100x50", "17x17x17", true};
constexpr CountsOption py_res{"res", "mesh", "vertices", "(nu, nv)", "(nu, nv, nw)", "(64, 64)", "(33, 33, 33)",
                              false, " (", ", ", ")"};

Construction example(const std::string& name) {
  return build_file(fs::path(INTERPATCH_EXAMPLES) / (name + ".json"));
}

TEST(OutputsCounts, WrittenAsTheirOptionWritesThem) {
  const std::size_t two[] = {64, 32}, three[] = {3, 4, 5};
  EXPECT_EQ(counts_text(cli_res, two), "--res '64x32'");
  EXPECT_EQ(counts_text(py_res, three), "res (3, 4, 5)");
  const Resolution surface{7, 8, 0}, volume{7, 8, 9};
  EXPECT_EQ(counts_of(surface).size(), 2u);
  EXPECT_EQ(counts_of(volume).size(), 3u);
  EXPECT_EQ(counts_of(volume)[2], 9u);
}

TEST(OutputsCounts, FewerThanTwoAlongAnyDirectionAreRefused) {
  for (const std::vector<std::size_t>& bad : {std::vector<std::size_t>{0, 5}, {5, 1}, {2, 2, 1}, {1, 1}})
    EXPECT_ERRC(check_counts(bad, cli_res), too_few_points, "a mesh needs at least 2 vertices along each direction");
  const std::size_t zero_five[] = {0, 5};
  EXPECT_ERRC(check_counts(zero_five, cli_res), too_few_points, "--res '0x5': a mesh needs");
  EXPECT_ERRC(check_counts(zero_five, py_res), too_few_points, "res (0, 5): a mesh needs");
  EXPECT_ERRC(check_counts(zero_five, cli_grid, "--grid '0x05'"), too_few_points, "--grid '0x05': a grid needs at least 2 points");
  const std::size_t fine[] = {2, 2, 2};
  EXPECT_NO_THROW(check_counts(fine, cli_res));
}

TEST(OutputsCounts, TheirNumberMustFitTheKind) {
  const Construction surface = example("coons"), volume = example("trilinear");
  EXPECT_ERRC(check_counts_kind(surface, cli_res, {3, 3, 3}), size_mismatch,
              "--res '3x3x3': a surface mesh takes two counts, NUxNV (NUxNVxNW is for volumes)");
  EXPECT_ERRC(check_counts_kind(volume, cli_grid, {3, 3, 0}), size_mismatch,
              "--grid '3x3': trilinear is a volume; its grid takes K or three counts, NUxNVxNW (e.g. 17x17x17)");
  EXPECT_ERRC(check_counts_kind(volume, py_res, {3, 3, 0}), size_mismatch, "res (3, 3): trilinear is a volume");
  EXPECT_NO_THROW(check_counts_kind(surface, cli_res, {3, 3, 0}));
  EXPECT_NO_THROW(check_counts_kind(volume, cli_res, {3, 3, 3}));
}

TEST(OutputsFormats, EachOutputKnowsItsExtensionsCaseInsensitively) {
  for (const char* ok : {"a.json", "a.NPZ", "a.step", "a.stp", "a.igs", "a.IGES"}) EXPECT_NO_THROW(check_build_output(ok));
  EXPECT_ERRC(check_build_output("a.obj"), wrong_type, "cannot tell the output format of 'a.obj': build writes .json");
  for (const char* ok : {"a.obj", "a.STL", "a.ply", "a.vtk", "a.vts", "a.xyz"}) EXPECT_NO_THROW(check_mesh_output(ok));
  EXPECT_ERRC(check_mesh_output("a.json"), wrong_type, "cannot tell the mesh format of 'a.json': use .obj");
  EXPECT_NO_THROW(check_eval_output("a.CSV"));
  EXPECT_ERRC(check_eval_output("a.txt"), wrong_type, "eval writes .npy or .csv");
  EXPECT_NO_THROW(check_info_output("a.json"));
  EXPECT_ERRC(check_info_output("a.npz"), wrong_type, "info writes .json");
  EXPECT_NO_THROW(check_view_output("a.htm"));
  EXPECT_ERRC(check_view_output("a"), wrong_type, "view writes .html (or .htm)");
}

TEST(OutputsFormats, AVolumeMeshIsWrittenToVolumeFormatsOnly) {
  const Construction volume = example("trilinear");
  EXPECT_ERRC(check_mesh_kind(volume, "v.obj", {3, 3, 3}, cli_res), wrong_type,
              "'v.obj': trilinear is a volume; .obj holds surfaces only");
  EXPECT_NO_THROW(check_mesh_kind(volume, "v.vts", {3, 3, 3}, cli_res));
}

TEST(OutputsRoom, MeshesBeyondMemoryOrDiskAreRefusedBeforeAnyWork) {
  test::TempDir dir;
  // 10^16 vertices of a .vts: 480 PB on the disk.
  EXPECT_ERRC(require_mesh_room({100000000, 100000000, 0}, dir.path() / "x.vts"), too_large, "mesh of 100000000x100000000");
  EXPECT_ERRC(require_mesh_room({std::size_t{1} << 32, 2, 0}, dir.path() / "x.obj"), too_large,
              "more vertices than can be addressed");
  EXPECT_ERRC(require_mesh_room({std::size_t{1} << 21, 2, 2}, dir.path() / "x.vts"), too_large,
              "more vertices than can be addressed");
  EXPECT_ERRC(require_mesh_room({1000000, 1000000, 0}, dir.path() / "x.obj"), too_large, "mesh of 1000000x1000000 vertices");
  EXPECT_NO_THROW(require_mesh_room({64, 64, 0}, dir.path() / "x.obj"));
}

TEST(OutputsRoom, GridsBeyondMemoryOrDiskAreRefusedBeforeAnyWork) {
  test::TempDir dir;
  constexpr std::size_t beyond = std::numeric_limits<std::size_t>::max();
  EXPECT_ERRC(require_eval_room({beyond, 2, 0}, dir.path() / "x.npy"), too_large, "evaluation grid beyond 2^64");
  EXPECT_ERRC(require_eval_room({std::size_t{1} << 40, std::size_t{1} << 40, 0}, dir.path() / "x.npy"), too_large,
              "more points than can be addressed");
  EXPECT_ERRC(require_eval_room({100000000, 100000000, 0}, dir.path() / "x.csv"), too_large, "evaluation grid 100000000x100000000");
  EXPECT_NO_THROW(require_eval_room({100, 50, 0}, dir.path() / "x.npy"));
}

// write_mesh makes every check itself: a caller that skips them (as the Python module
// once did) still gets the command line's refusals.
TEST(OutputsWriteMesh, ChecksEverythingBeforeWriting) {
  test::TempDir dir;
  Construction surface = example("coons");
  EXPECT_ERRC((void)write_mesh(surface, dir.path() / "x.obj", {1, 1, 0}, py_res), too_few_points, "res (1, 1): a mesh needs");
  EXPECT_ERRC((void)write_mesh(surface, dir.path() / "x.obj", {0, 5, 0}, cli_res), too_few_points, "--res '0x5'");
  EXPECT_ERRC((void)write_mesh(surface, dir.path() / "x.obj", {3, 3, 3}, py_res), size_mismatch, "a surface mesh takes two counts");
  EXPECT_ERRC((void)write_mesh(surface, dir.path() / "x.json", {3, 3, 0}, py_res), wrong_type, "cannot tell the mesh format");
  EXPECT_ERRC((void)write_mesh(surface, dir.path() / "x.vts", {100000000, 100000000, 0}, py_res), too_large, "mesh of");
  EXPECT_FALSE(fs::exists(dir.path() / "x.obj"));
  EXPECT_FALSE(fs::exists(dir.path() / "x.vts"));
  Construction volume = example("trilinear");
  EXPECT_ERRC((void)write_mesh(volume, dir.path() / "v.stl", {3, 3, 3}, py_res), wrong_type, "holds surfaces only");

  (void)write_mesh(surface, dir.path() / "x.obj", {3, 2, 0}, py_res);
  std::ifstream in(dir.path() / "x.obj");
  std::size_t vertices = 0;
  for (std::string line; std::getline(in, line);) vertices += line.rfind("v ", 0) == 0;
  EXPECT_EQ(vertices, 6u);
}

TEST(OutputsWriteBuild, WritesTheExactFormOrSaysWhyNot) {
  test::TempDir dir;
  Construction coons = example("coons");
  EXPECT_ERRC(write_build(coons, dir.path() / "x.obj"), wrong_type, "build writes .json");
  write_build(coons, dir.path() / "x.json");
  EXPECT_GT(fs::file_size(dir.path() / "x.json"), 0u);
  Construction gregory = example("coons_gregory");
  EXPECT_ERRC(write_build(gregory, dir.path() / "g.json"), no_exact_form, "coons");
  EXPECT_FALSE(fs::exists(dir.path() / "g.json"));
}

}  // namespace
}  // namespace interpatch::io
