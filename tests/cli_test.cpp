// The interpatch command as other programs use it: the real binary,
// run in a fresh directory, its outputs and exit statuses checked. Failures are the
// table in cli_bad_input_test.cpp.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "cli_specs.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/spec.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

#ifdef INTERPATCH_CLI

namespace fs = std::filesystem;
using json = nlohmann::json;

std::string read_file(const fs::path& p) { return test::read_text(p); }

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

using test::expect_one_line_error;
using Result = test::CliResult;

// A fresh working directory per test: listing it shows only what the command wrote.
class CliTest : public ::testing::Test {
 public:
  [[nodiscard]] fs::path work() const { return dir_.path(); }
  [[nodiscard]] fs::path at(const std::string& name) const { return work() / name; }

  Result run(const std::vector<std::string>& args) const { return test::run_cli(work(), args); }

 protected:

  // A valid 4x5 grid spec, written to NAME.
  void write_grid_spec(const std::string& name, unsigned seed = 1, std::size_t nu = 4, std::size_t nv = 5) const {
    write_file(at(name), grid_spec(seed, nu, nv).dump());
  }

  static json grid_json(const PointGrid& q) {
    json rows = json::array();
    for (std::size_t i = 0; i < q.extent(0); ++i) {
      json row = json::array();
      for (std::size_t j = 0; j < q.extent(1); ++j) row.push_back({q(i, j).x, q(i, j).y, q(i, j).z});
      rows.push_back(row);
    }
    return rows;
  }

  static json grid_spec(unsigned seed, std::size_t nu, std::size_t nv) {
    auto g = test::rng(seed);
    return {{"type", "interpolate"}, {"points", grid_json(test::random_grid(g, nu, nv))}};
  }

  test::TempDir dir_;
};

// --- NPY as NumPy writes it -------------------------------------------------------

struct Npy {
  std::string descr;
  bool fortran = true;
  std::vector<std::size_t> shape;
  std::vector<double> data;
};

Npy parse_npy(const std::string& bytes) {
  Npy n;
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  const int major = static_cast<unsigned char>(bytes[6]);
  const std::size_t len_size = major == 1 ? 2 : 4;
  std::size_t header_len = 0;
  for (std::size_t i = 0; i < len_size; ++i) header_len |= static_cast<std::size_t>(static_cast<unsigned char>(bytes[8 + i])) << (8 * i);
  const std::size_t start = 8 + len_size;
  EXPECT_EQ((start + header_len) % 64, 0u);  // data aligned as NumPy does
  const std::string header = bytes.substr(start, header_len);
  // The text after `key` up to the first `close` past the first `open`.
  const auto value = [&](const std::string& key, char open, char close) {
    const auto k = header.find(key);
    if (k == std::string::npos) return std::string();
    const auto a = header.find(open, k + key.size());
    const auto b = header.find(close, a + 1);
    return a == std::string::npos || b == std::string::npos ? std::string() : header.substr(a + 1, b - a - 1);
  };
  n.descr = value("'descr':", '\'', '\'');
  n.fortran = header.find("'fortran_order': True") != std::string::npos;
  std::stringstream ss(value("'shape':", '(', ')'));
  std::string item;
  while (std::getline(ss, item, ','))
    if (item.find_first_not_of(' ') != std::string::npos) n.shape.push_back(std::stoul(item));
  const std::size_t count = (bytes.size() - start - header_len) / 8;
  n.data.resize(count);
  std::memcpy(n.data.data(), bytes.data() + start + header_len, count * 8);  // little endian host
  return n;
}

// --- the subcommands on real specs ------------------------------------------------------

TEST_F(CliTest, InfoPrintsOneObjectWithTheContractFields) {
  write_grid_spec("s.json", 1, 6, 9);
  const Result r = run({"info", "s.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["type"], "interpolate");
  EXPECT_EQ(j["kind"], "surface");
  EXPECT_EQ(j["degree"], json({3, 3}));
  EXPECT_EQ(j["control_points"], json({6, 9}));
  EXPECT_EQ(j["knots"]["u"].size(), 10u);
  EXPECT_EQ(j["knots"]["v"].size(), 13u);
  EXPECT_LT(j["max_data_error"]["relative"].get<double>(), 1e-12);
  EXPECT_EQ(j["continuity"], json({{"u", "C2"}, {"v", "C2"}}));
  EXPECT_EQ(j["periodic"], json({false, false}));
  EXPECT_EQ(j["seam_continuity"], json::object());
  EXPECT_EQ(j["parameters"]["periodic"], json({false, false}));
  for (const char* t : {"parse_ms", "build_ms", "check_ms"}) EXPECT_TRUE(j["timings"][t].is_number()) << t;
}

TEST_F(CliTest, BuildWritesTheExactFormAndItRoundTrips) {
  write_grid_spec("s.json", 2, 5, 7);
  Result r = run({"build", "s.json", "-o", "exact.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const json exact = json::parse(read_file(at("exact.json")));
  EXPECT_EQ(exact["type"], "bspline_surface");
  EXPECT_EQ(exact["control_points"].size(), 5u);
  EXPECT_EQ(exact["control_points"][0].size(), 7u);

  // The written file is a spec: info on it and on the original agree exactly.
  const json a = json::parse(run({"info", "s.json"}).out);
  r = run({"info", "exact.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json b = json::parse(r.out);
  EXPECT_EQ(b["type"], "bspline_surface");
  EXPECT_EQ(a["knots"], b["knots"]);
  EXPECT_EQ(a["degree"], b["degree"]);
  EXPECT_EQ(a["bounding_box"], b["bounding_box"]);
  EXPECT_TRUE(b["max_data_error"].is_null());
  // Built again, the exact form is the same text.
  ASSERT_EQ(run({"build", "exact.json", "-o", "again.json"}).status, 0);
  EXPECT_EQ(read_file(at("exact.json")), read_file(at("again.json")));
}

TEST_F(CliTest, BuildWritesAnNpzThatReadsBackToTheSameForm) {
  write_grid_spec("s.json", 3, 6, 5);
  Result r = run({"build", "s.json", "-o", "exact.NPZ"});  // the extension in any case
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(read_file(at("exact.NPZ")).substr(0, 4), std::string("PK\x03\x04"));
  ASSERT_EQ(run({"build", "s.json", "-o", "exact.json"}).status, 0);
  write_file(at("back.json"), R"({"type": "bspline_surface", "npz": "exact.NPZ"})");
  // Every command reads it; built again it is the same exact form, to the bit.
  ASSERT_EQ(run({"build", "back.json", "-o", "again.json"}).status, 0);
  EXPECT_EQ(read_file(at("exact.json")), read_file(at("again.json")));
  ASSERT_EQ(run({"build", "back.json", "-o", "again.npz"}).status, 0);
  EXPECT_EQ(read_file(at("exact.NPZ")), read_file(at("again.npz")));
  r = run({"info", "back.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json a = json::parse(run({"info", "s.json"}).out), b = json::parse(r.out);
  EXPECT_EQ(b["type"], "bspline_surface");
  EXPECT_EQ(a["knots"], b["knots"]);
  EXPECT_EQ(a["bounding_box"], b["bounding_box"]);
  ASSERT_EQ(run({"eval", "s.json", "--grid", "9", "-o", "a.npy"}).status, 0);
  ASSERT_EQ(run({"eval", "back.json", "--grid", "9", "-o", "b.npy"}).status, 0);
  EXPECT_EQ(read_file(at("a.npy")), read_file(at("b.npy")));
  // A volume likewise.
  const fs::path vol = fs::path(INTERPATCH_EXAMPLES) / "annular_sector.json";
  ASSERT_EQ(run({"build", vol.string(), "-o", "v.npz"}).status, 0);
  ASSERT_EQ(run({"build", vol.string(), "-o", "v.json"}).status, 0);
  write_file(at("vback.json"), R"({"type": "bspline_volume", "npz": "v.npz"})");
  ASSERT_EQ(run({"build", "vback.json", "-o", "vagain.json"}).status, 0);
  EXPECT_EQ(read_file(at("v.json")), read_file(at("vagain.json")));
}

TEST_F(CliTest, EvalWritesNpyKxKx3LittleEndianCOrderUFirst) {
  const json spec = grid_spec(3, 4, 6);
  write_file(at("s.json"), spec.dump());
  const Result r = run({"eval", "s.json", "--grid", "17", "-o", "g.npy"});
  ASSERT_EQ(r.status, 0) << r.err;
  const Npy n = parse_npy(read_file(at("g.npy")));
  EXPECT_EQ(n.descr, "<f8");
  EXPECT_FALSE(n.fortran);
  EXPECT_EQ(n.shape, std::vector<std::size_t>({17, 17, 3}));
  ASSERT_EQ(n.data.size(), 17u * 17u * 3u);
  // The corners of [0,1]^2 are the corner data points: [0][16] is u = 0, v = 1.
  const auto& pts = spec["points"];
  const auto value = [&](std::size_t i, std::size_t j, std::size_t k) { return n.data[(i * 17 + j) * 3 + k]; };
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(value(0, 0, k), pts[0][0][k].get<double>(), 1e-12);
    EXPECT_NEAR(value(0, 16, k), pts[0][5][k].get<double>(), 1e-12);
    EXPECT_NEAR(value(16, 0, k), pts[3][0][k].get<double>(), 1e-12);
    EXPECT_NEAR(value(16, 16, k), pts[3][5][k].get<double>(), 1e-12);
  }
}

// The index of the first value whose bits differ between two arrays of one size;
// the size when all agree.
std::size_t first_difference(std::span<const double> got, std::span<const double> expected) {
  for (std::size_t i = 0; i < got.size(); ++i)
    if (std::memcmp(&got[i], &expected[i], sizeof(double)) != 0) return i;
  return got.size();
}

// How eval builds a construction: without its exact form, until the evaluation asks.
const io::BuildOptions evaluation_options{.progress = {}, .keep_data = false, .defer_exact = true, .arrays = {}};

// What evaluate() gives for construction c on linspace(0, 1, n) along each direction
// (two counts for a surface, three for a volume): the doubles of a C-order array.
// A surface is evaluated by what eval chooses (io::evaluator for the grid's points).
std::vector<double> library_evaluation(io::Construction c, const std::vector<std::size_t>& counts) {
  std::vector<std::vector<double>> t;
  for (const std::size_t n : counts) t.push_back(linspace(0, 1, n));
  const auto doubles = [](const Vec3* p, std::size_t n) { return std::vector<double>(&p->x, &p->x + 3 * n); };
  if (counts.size() == 3) {
    const PointGrid3 g = io::volume_evaluator(c).evaluate(t[0], t[1], t[2]);
    return doubles(g.data(), g.size());
  }
  const PointGrid g = io::evaluator(c, counts.at(0) * counts.at(1), io::Sample::points).evaluate(t.at(0), t.at(1));
  return doubles(g.data(), g.size());
}

// An evaluation .npy is the library's evaluation at the grid's counts: its shape
// (counts..., 3), and every value bit for bit.
void expect_npy_is_evaluation(const std::string& bytes, const io::Construction& c, std::vector<std::size_t> counts) {
  const Npy n = parse_npy(bytes);
  const std::vector<double> expected = library_evaluation(c, counts);
  counts.push_back(3);
  EXPECT_EQ(n.shape, counts);
  ASSERT_EQ(n.data.size(), expected.size());
  const std::size_t i = first_difference(n.data, expected);
  EXPECT_EQ(i, expected.size()) << "value " << i << " is " << n.data[i] << ", evaluate() gives " << expected[i];
}

TEST_F(CliTest, EvalToNpyInBlocksIsTheLibrarysEvaluateBitForBit) {
  // eval evaluates and writes .npy about 2^17 points at a time along u
  // (cli/commands.cpp): K = 700 is 4 blocks of 187 rows of a surface, the last one
  // shorter, and K = 70 is 3 blocks of 26 slabs of a volume. Every value is the one
  // evaluate() gives for the same construction on linspace(0, 1, K), exactly.
  write_file(at("grid.json"), grid_spec(5, 12, 9).dump());
  const fs::path examples = INTERPATCH_EXAMPLES;
  const std::vector<std::pair<fs::path, std::size_t>> cases{{at("grid.json"), 700},
                                                            {examples / "coons.json", 700},
                                                            {examples / "coons_volume.json", 70},
                                                            {examples / "annular_sector.json", 70}};
  for (const auto& [spec, k] : cases) {
    SCOPED_TRACE(spec.filename().string());
    const Result r = run({"eval", spec.string(), "--grid", std::to_string(k), "-o", "g.npy"});
    ASSERT_EQ(r.status, 0) << r.err;
    // eval evaluates through the formula, not the exact form it does not build.
    const io::Construction c = io::build_file(spec, evaluation_options);
    expect_npy_is_evaluation(read_file(at("g.npy")), c, std::vector<std::size_t>(io::is_volume(c) ? 3 : 2, k));
  }
}

TEST_F(CliTest, EvalGridOfCountsPerDirectionIsTheLibrarysEvaluateBitForBit) {
  // --grid NUxNV and NUxNVxNW: the .npy has shape (NU, NV, 3) or (NU, NV, NW, 3), u
  // index first. 300x1000 is three blocks of 131 rows (the last one of 38), 90x40x50
  // two blocks of 65 slabs, so the blocks follow the rows of unequal counts.
  write_file(at("grid.json"), grid_spec(6, 12, 9).dump());
  const fs::path examples = INTERPATCH_EXAMPLES;
  struct Case {
    fs::path spec;
    std::string grid;
    std::vector<std::size_t> counts;
  };
  const std::vector<Case> cases{{at("grid.json"), "7x13", {7, 13}},
                                {at("grid.json"), "300X1000", {300, 1000}},
                                {examples / "coons.json", "2x9", {2, 9}},
                                {examples / "coons_volume.json", "5x6x7", {5, 6, 7}},
                                {examples / "annular_sector.json", "90x40X50", {90, 40, 50}}};
  for (const Case& k : cases) {
    SCOPED_TRACE(k.spec.filename().string() + " --grid " + k.grid);
    const Result r = run({"eval", k.spec.string(), "--grid", k.grid, "-o", "g.npy"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    expect_npy_is_evaluation(read_file(at("g.npy")), io::build_file(k.spec, evaluation_options), k.counts);
  }
}

json box_trilinear();

// The rows of a .csv: its header line, then each line's numbers.
std::pair<std::string, std::vector<std::vector<double>>> read_csv(const std::string& text) {
  std::istringstream in(text);
  std::string header, line;
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) row.push_back(std::strtod(f.c_str(), nullptr));
    rows.push_back(row);
  }
  return {header, rows};
}

TEST_F(CliTest, EvalGridOfCountsPerDirectionToCsvIsOneRowPerPointInCOrder) {
  // Parameters, then the point, 17 digits that read back to the library's value.
  write_file(at("grid.json"), grid_spec(7, 5, 6).dump());
  write_file(at("box.json"), box_trilinear().dump());
  struct Case {
    std::string spec, grid, header;
    std::vector<std::size_t> counts;
  };
  for (const Case& k : {Case{"grid.json", "3x4", "u,v,x,y,z", {3, 4}}, Case{"box.json", "2x3x4", "u,v,w,x,y,z", {2, 3, 4}}}) {
    SCOPED_TRACE(k.spec + " --grid " + k.grid);
    const Result run_result = run({"eval", k.spec, "--grid", k.grid, "-o", "g.csv"});
    ASSERT_EQ(run_result.status, 0) << run_result.err;
    const auto [header, rows] = read_csv(read_file(at("g.csv")));
    EXPECT_EQ(header, k.header);
    const std::vector<double> expected = library_evaluation(io::build_file(at(k.spec), evaluation_options), k.counts);
    const std::size_t dims = k.counts.size();
    ASSERT_EQ(rows.size(), expected.size() / 3);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      ASSERT_EQ(rows[r].size(), dims + 3) << "row " << r;
      // Row r is point r in C order: its index along each axis, last axis fastest.
      for (std::size_t a = dims, rest = r; a-- > 0; rest /= k.counts[a])
        EXPECT_EQ(rows[r][a], linspace(0, 1, k.counts[a])[rest % k.counts[a]]) << "row " << r << ", axis " << a;
      for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(rows[r][dims + c], expected[3 * r + c]) << "row " << r;
    }
  }
}

TEST_F(CliTest, DurableOutputsAreTheSameBytes) {
  // INTERPATCH_SYNC=1 waits for the disk before each output is renamed into place;
  // the files are those of a run without it, and an existing file is replaced.
  write_grid_spec("s.json", 4, 30, 20);
  write_file(at("durable.npy"), "an older file\n");
  const std::vector<std::string> eval{"eval", "s.json", "--grid", "123", "-o"};
  const auto with = [&](const std::vector<std::string>& args, const std::string& out, const std::string& sync) {
    std::vector<std::string> a = args;
    a.push_back(out);
    const Result r = test::run_cli(work(), a, {"INTERPATCH_SYNC=" + sync});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(r.err.empty()) << r.err;
    return read_file(at(out));
  };
  const std::string plain = with(eval, "plain.npy", "0");
  EXPECT_EQ(parse_npy(plain).data.size(), 123u * 123u * 3u);
  EXPECT_TRUE(with(eval, "durable.npy", "1") == plain);
  const std::vector<std::string> build{"build", "s.json", "-o"};
  EXPECT_TRUE(with(build, "durable.json", "1") == with(build, "plain.json", "0"));
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(work())) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"durable.json", "durable.npy", "plain.json", "plain.npy", "s.json"}));
}

TEST_F(CliTest, EvalWritesCsvWithHeaderAndRowsUOutermost) {
  write_grid_spec("s.json", 4);
  const Result r = run({"eval", "s.json", "--grid", "5", "-o", "g.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream in(read_file(at("g.csv")));
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "u,v,x,y,z");
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) row.push_back(std::stod(f));
    EXPECT_EQ(row.size(), 5u) << line;
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 25u);
  EXPECT_EQ(rows[1][0], 0.0);   // u outermost: second row is u = 0, v = 0.25
  EXPECT_EQ(rows[1][1], 0.25);
  EXPECT_EQ(rows[5][0], 0.25);  // the next u
  EXPECT_EQ(rows[5][1], 0.0);
  EXPECT_EQ(rows[24][0], 1.0);
  EXPECT_EQ(rows[24][1], 1.0);
}

TEST_F(CliTest, MeshWritesEveryFormatAtTheRequestedResolution) {
  write_grid_spec("s.json", 5);
  for (const char* ext : {".obj", ".stl", ".ply", ".vtk", ".vts", ".xyz"}) {
    const std::string name = std::string("m") + ext;
    const Result r = run({"mesh", "s.json", "-o", name, "--res", "9x7"});
    ASSERT_EQ(r.status, 0) << ext << ": " << r.err;
    EXPECT_GT(fs::file_size(at(name)), 100u) << ext;
  }
  const std::string obj = read_file(at("m.obj"));
  std::istringstream in(obj);
  std::string line;
  std::size_t vertices = 0, normals = 0;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) == 0) ++vertices;
    if (line.rfind("vn ", 0) == 0) ++normals;
  }
  EXPECT_EQ(vertices, 63u);
  EXPECT_EQ(normals, 63u);
  EXPECT_NE(read_file(at("m.ply")).find("element vertex 63"), std::string::npos);
  // The default resolution is 64x64.
  ASSERT_EQ(run({"mesh", "s.json", "-o", "d.ply"}).status, 0);
  EXPECT_NE(read_file(at("d.ply")).find("element vertex 4096"), std::string::npos);
}

// A 1 mm part 1e8 from the origin: binary STL's float32 cannot hold its shape. The
// file is written and the command says so; .ply keeps doubles and says nothing.
TEST_F(CliTest, MeshWarnsWhenStlCannotHoldTheShape) {
  write_file(at("far.json"), R"({"type": "bilinear", "p00": [1e8, 1e8, 1e8], "p01": [1e8, 1.000000000001e8, 1e8],
                             "p10": [1.000000000001e8, 1e8, 1e8], "p11": [1.000000000001e8, 1.000000000001e8, 1.00000000001e8]})");
  const Result stl = run({"mesh", "far.json", "-o", "far.stl", "--res", "5x5"});
  ASSERT_EQ(stl.status, 0) << stl.err;
  EXPECT_NE(stl.err.find("interpatch: warning: 'far.stl' holds float32 coordinates"), std::string::npos) << stl.err;
  EXPECT_TRUE(fs::exists(at("far.stl")));
  const Result ply = run({"mesh", "far.json", "-o", "far.ply", "--res", "5x5"});
  ASSERT_EQ(ply.status, 0) << ply.err;
  EXPECT_EQ(ply.err.find("warning"), std::string::npos) << ply.err;
}

// The viewer page decimates what it cannot hold, never refuses it: counts too large
// to represent and very elongated requests alike.
TEST_F(CliTest, ViewDecimatesRatherThanRefuses) {
  write_grid_spec("s.json", 3, 6, 9);
  for (const char* res : {"100000000x3", "99999999999999999999999x99999999999999999999999", "700x700"}) {
    const Result r = run({"view", "s.json", "-o", "page.html", "--res", res});
    ASSERT_EQ(r.status, 0) << res << ": " << r.err;
    const std::string page = read_file(at("page.html"));
    const std::size_t a = page.find(R"("shown":[)") + 9;
    const json shown = json::parse("[" + page.substr(a, page.find(']', a) - a) + "]");
    EXPECT_LE(shown[0].get<std::size_t>() * shown[1].get<std::size_t>(), 512u * 512u) << res;
    EXPECT_GE(shown[1].get<std::size_t>(), 2u) << res;
  }
}

// What `info` says of a checked-in example: a blocks example shares its faces within its
// tolerance and inverts no cell; an approximation passes within its tolerance, or as
// near as its λ lets it; a network drawn freehand (its curves re-expressed) passes its
// curves within 1e-7 of the diagonal; every other construction interpolates to rounding.
void expect_example_info(const json& j, const std::string& name) {
  if (j["type"] == "blocks") {
    EXPECT_FALSE(j["shared_faces"].empty()) << name;
    for (const auto& f : j["shared_faces"]) EXPECT_LE(f["gap"].get<double>(), j["tolerance"].get<double>()) << name;
    EXPECT_EQ(j["mesh"]["inverted_cells"], 0) << name;
    return;
  }
  bool reexpressed = false;
  if (j["parameters"].contains("network_curves"))
    for (const auto& c : j["parameters"]["network_curves"]) reexpressed |= c["reexpressed"].get<bool>();
  if (j["parameters"].contains("tolerance")) {
    EXPECT_LE(j["max_data_error"]["absolute"].get<double>(), j["parameters"]["tolerance"].get<double>()) << name;
  } else if (j["parameters"].contains("smoothing")) {
    // info measures what the fit reported: two evaluations of one spline, to rounding
    // of the data's size.
    EXPECT_NEAR(j["max_data_error"]["absolute"].get<double>(), j["parameters"]["max_error"].get<double>(),
                1e-9 * (1 + j["parameters"]["max_error"].get<double>())) << name;
    EXPECT_GT(j["parameters"]["lambda"].get<double>(), 0.0) << name;
  } else if (!j["max_data_error"].is_null()) {
    EXPECT_LT(j["max_data_error"]["relative"].get<double>(), reexpressed ? 1e-7 : 1e-12) << name;
  }
}

TEST_F(CliTest, DemoWritesEveryExampleAndSaysWhere) {
  const Result r = run({"demo", "-o", "out"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("outputs in out"), std::string::npos) << r.out;
  // The gallery: for every example a picture linking to its viewer page; the last line
  // says to open it.
  const std::string last_line = "open " + (fs::path("out") / "index.html").string() + " in a web browser to see every example\n";
  ASSERT_GE(r.out.size(), last_line.size());
  EXPECT_EQ(r.out.substr(r.out.size() - last_line.size()), last_line);
  const std::size_t example_count = std::stoul(r.out.substr(r.out.find(": ") + 2));
  const std::string gallery = read_file(at("out") / "index.html");
  // A blocks example has no viewer page yet: its picture opens its description.
  const std::regex card(R"re(<a href="([a-z_0-9]+\.(view\.html|info\.json))"><svg )re");
  std::size_t cards = 0;
  for (auto it = std::sregex_iterator(gallery.begin(), gallery.end(), card); it != std::sregex_iterator(); ++it, ++cards)
    EXPECT_TRUE(fs::exists(at("out") / (*it)[1].str())) << (*it)[1];
  EXPECT_EQ(cards, example_count);
  for (const char* name : {"hemisphere", "terrain", "wave", "saddle", "pipe", "half_cylinder", "twisted_strip"}) {
    for (const char* suffix :
         {".spec.json", ".bspline.json", ".bspline.npz", ".step", ".igs", ".eval.npy", ".eval.csv", ".obj", ".vtk",
          ".info.json"})
      EXPECT_TRUE(fs::exists(at("out") / (std::string(name) + suffix))) << name << suffix;
    const json info = json::parse(read_file(at("out") / (std::string(name) + ".info.json")));
    EXPECT_LT(info["max_data_error"]["relative"].get<double>(), 1e-12) << name;
  }
  EXPECT_TRUE(fs::exists(at("out") / "half_cylinder.npy"));
  EXPECT_TRUE(fs::exists(at("out") / "twisted_strip.csv"));
  EXPECT_TRUE(fs::exists(at("out") / "hemisphere.stl"));
  // The pipe: closed around v, C2 across the seam, its spec the checked-in example.
  const json pipe = json::parse(read_file(at("out") / "pipe.info.json"));
  EXPECT_EQ(pipe["periodic"], json({false, true}));
  EXPECT_EQ(pipe["seam_continuity"], json({{"v", "C2"}}));
  EXPECT_EQ(pipe["control_points"], json({20, 32}));
  EXPECT_TRUE(pipe["warnings"].empty());
  EXPECT_EQ(json::parse(read_file(at("out") / "pipe.bspline.json"))["periodic"], json({false, true}));
  // The hemisphere's data close around v, undeclared: the demo shows the warning.
  EXPECT_NE(r.err.find("warning: /points: the data close along v"), std::string::npos) << r.err;
  for (const char* name : {"trilinear", "coons_volume", "hermite_volume", "annular_sector"}) {
    for (const char* suffix : {".spec.json", ".bspline.json", ".bspline.npz", ".step", ".igs", ".eval.npy", ".eval.csv", ".vts",
                               ".vtk", ".xyz", ".info.json"})
      EXPECT_TRUE(fs::exists(at("out") / (std::string(name) + suffix))) << name << suffix;
    const json info = json::parse(read_file(at("out") / (std::string(name) + ".info.json")));
    EXPECT_EQ(info["kind"], "volume") << name;
    EXPECT_LT(info["max_data_error"]["relative"].get<double>(), 1e-12) << name;
    EXPECT_EQ(info["jacobian"]["inverted_cells"], 0) << name;
    EXPECT_EQ(info["mesh"]["inverted_cells"], 0) << name;
    EXPECT_GT(info["mesh"]["min_scaled_jacobian"].get<double>(), 0.0) << name;
  }
  EXPECT_EQ(r.out.find("rebuilt with differences"), std::string::npos) << r.out;
  // The demo shows the checked-in examples, embedded when it was built: the specs and
  // data files it writes are those of examples/, byte for byte.
  std::vector<std::string> shown;  // "  NAME   type: about" opens each example's lines
  std::string line_text;
  for (std::istringstream lines(r.out); std::getline(lines, line_text);)
    if (line_text.starts_with("  ") && line_text[2] != ' ') shown.push_back(line_text.substr(2, line_text.find(' ', 2) - 2));
  EXPECT_EQ(shown.size(), example_count);
  std::vector<std::string> checked_in;
  for (const auto& e : fs::directory_iterator(INTERPATCH_EXAMPLES)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".json") checked_in.push_back(e.path().stem().string());
    if (e.path().extension() == ".npy" || e.path().extension() == ".csv") {
      EXPECT_EQ(read_file(at("out") / name), read_file(e.path())) << name;
    }
  }
  for (const std::string& name : shown) {
    // The one example that is no file of examples/: terrain's exact form read back from
    // the .npz the demo wrote of terrain.
    if (name == "terrain_npz") continue;
    EXPECT_TRUE(std::ranges::find(checked_in, name) != checked_in.end()) << name << " is not in examples/";
    EXPECT_EQ(read_file(at("out") / (name + ".spec.json")), read_file(fs::path(INTERPATCH_EXAMPLES) / (name + ".json")))
        << name;
  }
  // Every checked-in example is in the demo, and builds as its description says (the
  // demo writes what `info` prints for it).
  EXPECT_GE(checked_in.size(), 3u);
  for (const std::string& name : checked_in) {
    EXPECT_TRUE(std::ranges::find(shown, name) != shown.end()) << name << " is not in the demo";
    expect_example_info(json::parse(read_file(at("out") / (name + ".info.json"))), name);
  }
  // The network drawn freehand: sorted, turned and re-expressed, within 1e-7 of the
  // diagonal of the curves given, and without a warning.
  const json drawn = json::parse(read_file(at("out") / "network_drawn.info.json"));
  EXPECT_TRUE(drawn["warnings"].empty()) << drawn["warnings"];
  EXPECT_LE(drawn["max_data_error"]["relative"].get<double>(), 1e-7);
  EXPECT_EQ(drawn["parameters"]["network_curves"]["/u_curves/1"]["reversed"], true);
  EXPECT_EQ(drawn["parameters"]["network_curves"]["/v_curves/0"]["reexpressed"], true);
  EXPECT_EQ(r.err.find("_curves/"), std::string::npos) << r.err;  // no network warns
  for (const char* name : {"terrain_exact", "terrain_npz"}) {
    const std::size_t at = r.out.find(std::string("  ") + name + " ");
    ASSERT_NE(at, std::string::npos) << name;
    EXPECT_NE(r.out.find("rebuilt identically", at), std::string::npos) << name << ": " << r.out;
  }
  EXPECT_EQ(read_file(at("out") / "terrain_npz.bspline.json"), read_file(at("out") / "terrain.bspline.json"));
  const json exact = json::parse(read_file(at("out") / "wave.bspline.json"));
  EXPECT_EQ(exact["degree"], json({2, 3}));
  const json saddle = json::parse(read_file(at("out") / "saddle.info.json"));
  EXPECT_EQ(saddle["degree"], json({5, 5}));
  // A demo directory whose parent is missing is refused, not created.
  expect_one_line_error(run({"demo", "-o", "no/such/dir"}), 4, {"no/such"});
  EXPECT_FALSE(fs::exists(at("no")));
}

// --- closed (periodic) shapes ------------------------------------------------------------

TEST_F(CliTest, ClosedPipeFromTheCommandLine) {
  write_file(at("pipe.json"), test::pipe_spec(12, 16, true).dump());
  // info: closed around v, C2 across the seam, the closing column checked as data.
  const Result i = run({"info", "pipe.json"});
  ASSERT_EQ(i.status, 0) << i.err;
  EXPECT_TRUE(i.err.empty()) << i.err;
  const json info = json::parse(i.out);
  EXPECT_EQ(info["periodic"], json({false, true}));
  EXPECT_EQ(info["seam_continuity"], json({{"v", "C2"}}));
  EXPECT_EQ(info["continuity"]["v"], "C2");
  EXPECT_EQ(info["control_points"], json({12, 16}));
  EXPECT_EQ(info["max_data_error"]["points"], 12 * 17);
  EXPECT_LT(info["max_data_error"]["relative"].get<double>(), 1e-13);  // rounding of the banded solves
  // eval samples [0, 1] in v too: its first and last columns are one seam, and every
  // value is the library's.
  ASSERT_EQ(run({"eval", "pipe.json", "--grid", "9x21", "-o", "g.npy"}).status, 0);
  const std::string npy = read_file(at("g.npy"));
  expect_npy_is_evaluation(npy, io::build_file(at("pipe.json"), evaluation_options), {9, 21});
  const Npy n = parse_npy(npy);
  for (std::size_t row = 0; row < 9; ++row)
    for (std::size_t k = 0; k < 3; ++k)  // v = 1 wraps to v = 0: the same point to rounding of the pipe's size (~5)
      EXPECT_NEAR(n.data[(row * 21 + 20) * 3 + k], n.data[(row * 21) * 3 + k], 1e-14) << row;
  // build: the exact form as .json and .npz, each read back and written again
  // byte for byte, and both the same form.
  for (const char* ext : {".json", ".npz"}) {
    ASSERT_EQ(run({"build", "pipe.json", "-o", std::string("e") + ext}).status, 0) << ext;
    const std::string again = std::string(ext) == ".json" ? "e.json" : "from_npz.json";
    if (std::string(ext) == ".npz") write_file(at(again), R"({"type": "bspline_surface", "npz": "e.npz"})");
    ASSERT_EQ(run({"build", again, "-o", std::string("again") + ext}).status, 0) << ext;
    EXPECT_EQ(read_file(at(std::string("again") + ext)), read_file(at(std::string("e") + ext))) << ext;
  }
  EXPECT_EQ(json::parse(read_file(at("e.json")))["periodic"], json({false, true}));
  ASSERT_EQ(run({"build", "from_npz.json", "-o", "npz_as.json"}).status, 0);
  EXPECT_EQ(read_file(at("npz_as.json")), read_file(at("e.json")));
  ASSERT_EQ(run({"mesh", "pipe.json", "-o", "m.obj", "--res", "8x8"}).status, 0);
}

TEST_F(CliTest, ClosedDataNotDeclaredPeriodicAreWarnedAboutByEveryCommand) {
  write_file(at("closed.json"), test::pipe_spec(6, 8, true, false).dump());
  write_file(at("declared.json"), test::pipe_spec(6, 8, true).dump());
  write_file(at("open.json"), test::pipe_spec(6, 8, false, false).dump());
  const std::vector<std::vector<std::string>> commands{{"build", "X", "-o", "b.json"},
                                                       {"mesh", "X", "-o", "m.obj", "--res", "6x6"},
                                                       {"eval", "X", "--grid", "5", "-o", "e.npy"},
                                                       {"info", "X"}};
  for (std::vector<std::string> args : commands) {
    SCOPED_TRACE(args[0]);
    args[1] = "closed.json";
    const Result closed = run(args);
    ASSERT_EQ(closed.status, 0) << closed.err;
    EXPECT_EQ(closed.err,
              "interpatch: warning: /points: the data close along v (the last line of points repeats the first), but v is "
              "not periodic: the surface meets itself there with a crease; \"periodic\": [false, true] makes it smooth "
              "across the seam\n");
    for (const char* quiet : {"declared.json", "open.json"}) {
      args[1] = quiet;
      const Result r = run(args);
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_TRUE(r.err.empty()) << quiet << ": " << r.err;
    }
  }
  const json info = json::parse(run({"info", "closed.json"}).out);
  ASSERT_EQ(info["warnings"].size(), 1u);
  EXPECT_EQ(info["parameters"]["notes"], json::array({info["warnings"][0].get<std::string>().substr(std::string("/points: ").size())}));
  // A data file in place of the spec is warned about the same way.
  const io::PointArray a = io::points_from_json(test::pipe_points(6, 8, true), 2);
  std::vector<double> flat;
  for (const Vec3& p : a.points) flat.insert(flat.end(), {p.x, p.y, p.z});
  const std::size_t shape[3] = {6, 9, 3};
  io::write_npy(at("closed.npy"), shape, flat);
  const Result npy = run({"info", "closed.npy"});
  ASSERT_EQ(npy.status, 0) << npy.err;
  EXPECT_NE(npy.err.find("warning: /points: the data close along v"), std::string::npos) << npy.err;
}

// --- failures: one table in cli_bad_input_test.cpp; here what it does not cover ----------

TEST_F(CliTest, HelpExits0AndListsTheCommands) {
  const Result help = run({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("build"), std::string::npos);
  EXPECT_NE(help.out.find("INTERPATCH_SYNC=1"), std::string::npos) << help.out;  // the one environment switch
}

// The project version, as the top-level CMakeLists.txt declares it.
std::string project_version() {
  const std::string cmake = read_file(fs::path(INTERPATCH_EXAMPLES).parent_path() / "CMakeLists.txt");
  const std::string key = "project(interpatch VERSION ";
  const auto at = cmake.find(key);
  if (at == std::string::npos) {
    ADD_FAILURE() << "CMakeLists.txt declares no project version";
    return "";
  }
  const auto from = at + key.size();
  return cmake.substr(from, cmake.find_first_of(" )\n", from) - from);
}

TEST_F(CliTest, VersionPrintsTheProjectVersion) {
  const Result r = run({"--version"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "interpatch " + project_version() + "\n");
  EXPECT_TRUE(r.err.empty()) << r.err;
}

TEST_F(CliTest, HelpOfEveryCommandNamesTheSpecFormatAndTheFormatsItWrites) {
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> formats;
  };
  const std::vector<Case> cases{
      {{"--help"}, {".json", ".npz", ".step/.stp", ".igs/.iges", ".obj .stl .ply .vtk .vts .xyz", "volumes .vtk .vts .xyz", ".npy", ".csv"}},
      {{"build", "--help"}, {".json", ".npz", "numpy.load", ".step", ".stp", ".igs", ".iges"}},
      {{"mesh", "--help"}, {".obj", ".stl", ".ply", ".vtk", ".vts", ".xyz"}},
      {{"eval", "--help"}, {".npy", ".csv"}},
      {{"info", "--help"}, {"stdout", ".json"}},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.args.front());
    const Result r = run(k.args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("docs/spec-format.md"), std::string::npos) << r.out;
    for (const std::string& f : k.formats) EXPECT_NE(r.out.find(f), std::string::npos) << f << " in " << r.out;
    if (k.args.size() > 1) {  // SPEC may be a data file, and --shape says how to read a .csv
      EXPECT_NE(r.out.find(".npy/.csv"), std::string::npos) << r.out;
      EXPECT_NE(r.out.find("--shape"), std::string::npos) << r.out;
    }
    for (const char* gone : {"SPEC section", "seed"}) EXPECT_EQ(r.out.find(gone), std::string::npos) << gone;
  }
}

TEST_F(CliTest, UnknownFieldIsAWarningNotAFailure) {
  json spec = grid_spec(1, 4, 5);
  spec["degre"] = 2;
  write_file(at("s.json"), spec.dump());
  const Result r = run({"build", "s.json", "-o", "o.json"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.err.find("warning: /degre"), std::string::npos) << r.err;
}


// --- constructions from corners and curves ---------------------------------------------

using test::square_coons;

TEST_F(CliTest, EveryConstructionTypeEvaluatesFromTheCommandLine) {
  // The seed's bilinear example through the whole pipeline: eval at the centre.
  write_file(at("b.json"), R"({"type": "bilinear", "p00": [0,0,1], "p01": [1,1,1], "p10": [1,0,0], "p11": [0,1,0]})");
  ASSERT_EQ(run({"eval", "b.json", "--grid", "3", "-o", "b.csv"}).status, 0);
  EXPECT_NE(read_file(at("b.csv")).find("\n0.5,0.5,0.5,0.5,0.5\n"), std::string::npos);
  // A Coons patch of four lines is the bilinear patch of its corners: z = u v.
  write_file(at("c.json"), square_coons().dump());
  ASSERT_EQ(run({"eval", "c.json", "--grid", "5", "-o", "c.csv"}).status, 0);
  EXPECT_NE(read_file(at("c.csv")).find("\n0.25,0.75,0.25,0.75,0.1875\n"), std::string::npos);
  const Result info = run({"info", "c.json"});
  ASSERT_EQ(info.status, 0) << info.err;
  const json j = json::parse(info.out);
  EXPECT_EQ(j["degree"], json({1, 1}));
  EXPECT_LT(j["max_data_error"]["absolute"].get<double>(), 1e-15);
  ASSERT_EQ(run({"build", "c.json", "-o", "c.bspline.json"}).status, 0);
  ASSERT_EQ(run({"mesh", "c.json", "-o", "c.obj", "--res", "4x4"}).status, 0);
}

TEST_F(CliTest, GregoryCorrectionEvaluatesButHasNoExactForm) {
  // Without the correction the twists are refused (the bad-input table); with it the
  // patch evaluates, and build refuses with nothing written.
  const fs::path ex = fs::path(INTERPATCH_EXAMPLES) / "coons_gregory.json";
  ASSERT_EQ(run({"eval", ex.string(), "--grid", "4", "-o", "g.npy"}).status, 0);
  expect_one_line_error(run({"build", ex.string(), "-o", "g.json"}), 3, {"no exact B-spline form"});
  EXPECT_FALSE(fs::exists(at("g.json")));
}

// --- volumes -----------------------------------------------------------------------------

// The trilinear volume of the corners (i, 2j, 3k): the box [0,1] x [0,2] x [0,3].
json box_trilinear() {
  json spec = {{"type", "trilinear"}};
  for (int n = 0; n < 8; ++n)
    spec["p" + std::to_string(n >> 2) + std::to_string((n >> 1) & 1) + std::to_string(n & 1)] = {
        n >> 2, 2 * ((n >> 1) & 1), 3 * (n & 1)};
  return spec;
}

const char* const volume_examples[] = {"trilinear", "coons_volume", "hermite_volume", "annular_sector"};

TEST_F(CliTest, EveryVolumeTypeEvaluatesMeshesDescribesAndBuilds) {
  for (const char* name : volume_examples) {
    SCOPED_TRACE(name);
    const fs::path spec = fs::path(INTERPATCH_EXAMPLES) / (std::string(name) + ".json");
    Result r = run({"eval", spec.string(), "--grid", "5", "-o", "g.npy"});
    ASSERT_EQ(r.status, 0) << r.err;
    const Npy n = parse_npy(read_file(at("g.npy")));
    EXPECT_EQ(n.shape, std::vector<std::size_t>({5, 5, 5, 3}));
    EXPECT_EQ(n.data.size(), 5u * 5u * 5u * 3u);

    for (const char* ext : {".vts", ".vtk", ".xyz"}) {
      r = run({"mesh", spec.string(), "-o", std::string("m") + ext, "--res", "4x5x6"});
      ASSERT_EQ(r.status, 0) << ext << ": " << r.err;
      EXPECT_GT(fs::file_size(at(std::string("m") + ext)), 100u) << ext;
    }
    EXPECT_NE(read_file(at("m.vtk")).find("DIMENSIONS 4 5 6"), std::string::npos);
    EXPECT_NE(read_file(at("m.vtk")).find("POINTS 120 double"), std::string::npos);
    EXPECT_NE(read_file(at("m.vts")).find("WholeExtent=\"0 3 0 4 0 5\""), std::string::npos);
    EXPECT_NE(read_file(at("m.vts")).find("Name=\"jacobian\""), std::string::npos);
    EXPECT_TRUE(fs::exists(at("m.f")));  // the Jacobian beside the Plot3D grid

    r = run({"info", spec.string()});
    ASSERT_EQ(r.status, 0) << r.err;
    const json a = json::parse(r.out);
    EXPECT_EQ(a["type"], name == std::string("annular_sector") ? "interpolate_volume" : name);
    EXPECT_EQ(a["kind"], "volume");
    EXPECT_EQ(a["exact_form"], "bspline_volume");
    EXPECT_EQ(a["degree"].size(), 3u);
    EXPECT_EQ(a["control_points"].size(), 3u);
    for (const char* axis : {"u", "v", "w"}) {
      EXPECT_TRUE(a["knots"][axis].is_array()) << axis;
      EXPECT_TRUE(a["continuity"][axis].is_string()) << axis;
    }
    EXPECT_LT(a["max_data_error"]["relative"].get<double>(), 1e-12);
    EXPECT_EQ(a["jacobian"]["samples_per_direction"], 17);
    EXPECT_EQ(a["jacobian"]["samples"], 17 * 17 * 17);
    EXPECT_EQ(a["jacobian"]["cells"], 16 * 16 * 16);
    EXPECT_EQ(a["jacobian"]["inverted_cells"], 0);
    EXPECT_GT(a["jacobian"]["min_determinant"].get<double>(), 0.0);

    // The exact form reads back as a bspline_volume spec with the same knots and control net.
    ASSERT_EQ(run({"build", spec.string(), "-o", "exact.json"}).status, 0);
    const json exact = json::parse(read_file(at("exact.json")));
    EXPECT_EQ(exact["type"], "bspline_volume");
    r = run({"info", "exact.json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const json b = json::parse(r.out);
    EXPECT_EQ(b["type"], "bspline_volume");
    EXPECT_EQ(a["knots"], b["knots"]);
    EXPECT_EQ(a["degree"], b["degree"]);
    EXPECT_EQ(a["control_points"], b["control_points"]);
    EXPECT_EQ(a["bounding_box"], b["bounding_box"]);
    EXPECT_EQ(a["jacobian"], b["jacobian"]);
    ASSERT_EQ(run({"build", "exact.json", "-o", "again.json"}).status, 0);
    EXPECT_EQ(read_file(at("exact.json")), read_file(at("again.json")));
  }
}

TEST_F(CliTest, TrilinearVolumeEvaluatesToItsCornersAndCentre) {
  write_file(at("t.json"), box_trilinear().dump());
  ASSERT_EQ(run({"eval", "t.json", "--grid", "3", "-o", "t.npy"}).status, 0);
  const Npy n = parse_npy(read_file(at("t.npy")));
  ASSERT_EQ(n.shape, std::vector<std::size_t>({3, 3, 3, 3}));
  const auto value = [&](std::size_t i, std::size_t j, std::size_t k, std::size_t c) {
    return n.data[((i * 3 + j) * 3 + k) * 3 + c];
  };
  EXPECT_DOUBLE_EQ(value(1, 1, 1, 0), 0.5);  // the centre
  EXPECT_DOUBLE_EQ(value(1, 1, 1, 1), 1.0);
  EXPECT_DOUBLE_EQ(value(1, 1, 1, 2), 1.5);
  EXPECT_DOUBLE_EQ(value(2, 0, 2, 0), 1.0);  // corner p101, u index first
  EXPECT_DOUBLE_EQ(value(2, 0, 2, 1), 0.0);
  EXPECT_DOUBLE_EQ(value(2, 0, 2, 2), 3.0);
  ASSERT_EQ(run({"eval", "t.json", "--grid", "3", "-o", "t.csv"}).status, 0);
  const std::string csv = read_file(at("t.csv"));
  EXPECT_EQ(csv.rfind("u,v,w,x,y,z\n", 0), 0u) << csv;
  EXPECT_NE(csv.find("\n0.5,0.5,0.5,0.5,1,1.5\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n0,0,0.5,0,0,1.5\n"), std::string::npos) << csv;  // w fastest
  // The default volume mesh is 33x33x33.
  ASSERT_EQ(run({"mesh", "t.json", "-o", "t.vtk"}).status, 0);
  EXPECT_NE(read_file(at("t.vtk")).find("DIMENSIONS 33 33 33"), std::string::npos);
}

TEST_F(CliTest, FoldedTrilinearVolumeReportsInvertedCells) {
  json spec = box_trilinear();
  std::swap(spec["p000"], spec["p111"]);  // the box turned inside out
  write_file(at("t.json"), spec.dump());
  const Result r = run({"info", "t.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_GT(j["jacobian"]["inverted_cells"].get<int>(), 0);
  EXPECT_GT(j["jacobian"]["inverted_points"].get<int>(), 0);
  EXPECT_LE(j["jacobian"]["min_determinant"].get<double>(), 0.0);
  EXPECT_FALSE(j["jacobian"]["inverted_at"].empty());
  // The mesh `mesh` writes by default has them too, and writing it warns.
  EXPECT_GT(j["mesh"]["inverted_cells"].get<int>(), 0);
  EXPECT_LE(j["mesh"]["min_scaled_jacobian"].get<double>(), 0.0);  // flat or turned
  EXPECT_EQ(j["mesh"]["first_inverted"].size(), 3u);
  const Result m = run({"mesh", "t.json", "-o", "t.vts"});
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_NE(m.err.find("interpatch: warning: t.vts: " + std::to_string(j["mesh"]["inverted_cells"].get<int>()) +
                       " of 32768 cells are inverted"),
            std::string::npos)
      << m.err;
}

// --- a data file in place of the spec ------------------------------------------------------

void write_npy_points(const fs::path& p, const std::vector<std::size_t>& grid_shape, const std::vector<Vec3>& points) {
  std::vector<std::size_t> shape = grid_shape;
  shape.push_back(3);
  io::write_npy(p, shape, std::span<const double>(&points.data()->x, 3 * points.size()));
}

void write_csv_points(const fs::path& p, const std::vector<Vec3>& points) {
  std::string text = "x,y,z\n";
  char line[128];
  for (const Vec3& q : points) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", q.x, q.y, q.z);
    text += line;
  }
  write_file(p, text);
}

// Points i, j[, k] along x, y[, z] with noise below half the spacing, in C order.
std::vector<Vec3> noisy_grid_points(const std::vector<std::size_t>& shape, unsigned seed) {
  auto g = test::rng(seed);
  std::size_t n = 1;
  for (const std::size_t e : shape) n *= e;
  std::vector<Vec3> points;
  for (std::size_t r = 0; r < n; ++r) {
    Vec3 p{0, 0, 0};
    for (std::size_t a = shape.size(), rest = r; a-- > 0; rest /= shape[a]) p[static_cast<int>(a)] = static_cast<double>(rest % shape[a]);
    points.push_back(p + test::random_point(g, 0.3));
  }
  return points;
}

// What info prints, without the timings, which differ from run to run.
json description(const Result& r) {
  EXPECT_EQ(r.status, 0) << r.err;
  json j = json::parse(r.out);
  j.erase("timings");
  return j;
}

// Runs eval, mesh, build and info on `data` (a data file and --shape when it takes
// one) and on `spec` (a spec naming that file), and expects the same outputs: the
// same bytes from eval, mesh and build, the same description from info. Returns
// the description.
json expect_data_file_acts_as_spec(const CliTest& t, const std::vector<std::string>& data, const std::string& spec,
                                   bool volume) {
  const auto with = [](std::vector<std::string> args, const std::vector<std::string>& input) {
    args.insert(args.begin() + 1, input.begin(), input.end());
    return args;
  };
  const std::vector<std::vector<std::string>> commands{
      {"eval", "--grid", "6", "-o", "OUT.npy"},
      {"eval", "--grid", volume ? "3x4x5" : "7x5", "-o", "OUT.csv"},
      {"mesh", "--res", volume ? "4x5x6" : "9x7", "-o", volume ? "OUT.vts" : "OUT.obj"},
      {"build", "-o", "OUT.json"},
  };
  for (const auto& command : commands) {
    SCOPED_TRACE(command.front() + " " + command[command.size() - 1]);
    const std::string out = command.back();
    std::vector<std::string> from_data = with(command, data), from_spec = with(command, {spec});
    from_data.back() = "data-" + out;
    from_spec.back() = "spec-" + out;
    const Result a = t.run(from_data), b = t.run(from_spec);
    EXPECT_EQ(a.status, 0) << a.err;
    EXPECT_EQ(b.status, 0) << b.err;
    // No warning of its own: the same as the spec's (a noisy volume may warn of folded
    // cells), its output named alike.
    std::string a_err = a.err;
    for (std::size_t at = a_err.find("data-" + out); at != std::string::npos; at = a_err.find("data-" + out))
      a_err.replace(at, 5, "spec-");
    EXPECT_EQ(a_err, b.err);
    if (a.status != 0 || b.status != 0) continue;
    const std::string got = read_file(t.at("data-" + out));
    EXPECT_GT(got.size(), 100u);
    EXPECT_TRUE(got == read_file(t.at("spec-" + out))) << out << " differs";
  }
  const json a = description(t.run(with({"info"}, data)));
  EXPECT_EQ(a, description(t.run({"info", spec})));
  return a;
}

TEST_F(CliTest, NpyOrCsvInPlaceOfTheSpecActsAsItsSpec) {
  // In a directory of their own: the data file is found beside itself, as a spec
  // beside it names it. The extension decides, in any case.
  fs::create_directory(at("data"));
  const std::vector<Vec3> points = noisy_grid_points({4, 5}, 11);
  write_npy_points(at("data/grid.npy"), {4, 5}, points);
  write_npy_points(at("data/GRID.NPY"), {4, 5}, points);
  write_csv_points(at("data/grid.csv"), points);
  write_file(at("data/npy.json"), R"({"type": "interpolate", "points": {"npy": "grid.npy"}})");
  write_file(at("data/upper.json"), R"({"type": "interpolate", "points": {"npy": "GRID.NPY"}})");
  write_file(at("data/csv.json"), R"({"type": "interpolate", "points": {"csv": "grid.csv", "shape": [4, 5]}})");
  for (const auto& [data, spec] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"data/grid.npy"}, "data/npy.json"},
           {{"data/GRID.NPY"}, "data/upper.json"},
           {{"data/grid.csv", "--shape", "4x5"}, "data/csv.json"}}) {
    SCOPED_TRACE(data.front());
    const json info = expect_data_file_acts_as_spec(*this, data, spec, false);
    EXPECT_EQ(info["type"], "interpolate");
    EXPECT_EQ(info["kind"], "surface");
    EXPECT_EQ(info["control_points"], json({4, 5}));
    EXPECT_LT(info["max_data_error"]["relative"].get<double>(), 1e-12);
  }
}

TEST_F(CliTest, FourDimensionalNpyOrCsvOfThreeCountsIsAVolume) {
  fs::create_directory(at("data"));
  const std::vector<Vec3> points = noisy_grid_points({3, 4, 5}, 12);
  write_npy_points(at("data/solid.npy"), {3, 4, 5}, points);
  write_csv_points(at("data/solid.csv"), points);
  write_file(at("data/npy.json"), R"({"type": "interpolate_volume", "points": {"npy": "solid.npy"}})");
  write_file(at("data/csv.json"), R"({"type": "interpolate_volume", "points": {"csv": "solid.csv", "shape": [3, 4, 5]}})");
  for (const auto& [data, spec] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"data/solid.npy"}, "data/npy.json"}, {{"data/solid.csv", "--shape", "3x4x5"}, "data/csv.json"}}) {
    SCOPED_TRACE(data.front());
    const json info = expect_data_file_acts_as_spec(*this, data, spec, true);
    EXPECT_EQ(info["type"], "interpolate_volume");
    EXPECT_EQ(info["kind"], "volume");
    EXPECT_EQ(info["control_points"], json({3, 4, 5}));
    // --grid K is KxKxK for the volume.
    std::vector<std::string> eval{"eval"};
    eval.insert(eval.end(), data.begin(), data.end());
    eval.insert(eval.end(), {"--grid", "4", "-o", "k.npy"});
    const Result r = run(eval);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(parse_npy(read_file(at("k.npy"))).shape, std::vector<std::size_t>({4, 4, 4, 3}));
  }
}

#else

TEST(Cli, NotBuilt) { GTEST_SKIP() << "the interpatch command is not part of this build"; }

#endif

}  // namespace
}  // namespace interpatch
