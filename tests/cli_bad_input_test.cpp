// Bad input as one table: every kind of bad input, run through the real
// `interpatch` command. Each row checks the exit status, that stderr is exactly one
// line naming the place and the size of the problem (a regex per row), that no
// output file appears, and — run a second time over a good output file left by an
// earlier run — that the good file is byte-for-byte unchanged. Where the failure is
// in the spec, the library is asked too, and must throw the errc the row names.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "cli_specs.hpp"
#include "exit_status.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/spec.hpp"
#include "npy_util.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

#ifdef INTERPATCH_CLI

namespace fs = std::filesystem;
using json = nlohmann::json;

// --- inputs ----------------------------------------------------------------------

json example(const std::string& name) {
  return json::parse(test::read_text(fs::path(INTERPATCH_EXAMPLES) / (name + ".json")));
}

// A 4 x 5 grid with distinct, non-collinear points: a valid bicubic interpolation.
json grid_spec() {
  json rows = json::array();
  for (int i = 0; i < 4; ++i) {
    json row = json::array();
    for (int j = 0; j < 5; ++j) row.push_back({j, i, 0.1 * ((7 * i + 3 * j) % 5)});
    rows.push_back(row);
  }
  return {{"type", "interpolate"}, {"points", rows}};
}

json with(json j, const std::function<void(json&)>& change) {
  change(j);
  return j;
}

// An approximation to a tolerance below any rounding, of heights no fit reproduces
// exactly.
json rounding_tolerance_spec() {
  return with(grid_spec(), [](json& s) {
    s["type"] = "approximate";
    s["tolerance"] = 1e-300;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 5; ++j) s["points"][i][j][2] = std::sin(7 * i + 3 * j);
  });
}

// A 100 x 5 grid with points in its first 4 rows only: the fill term carries the
// surface 25 times the data's length on, far past its box.
json far_hole_spec() {
  json rows = json::array();
  for (int i = 0; i < 100; ++i) {
    json row = json::array();
    for (int j = 0; j < 5; ++j) row.push_back(i < 4 ? json{i, j, 0.1 * i * j} : json{nullptr, nullptr, nullptr});
    rows.push_back(row);
  }
  return {{"type", "approximate"}, {"points", rows}, {"control_points", {10, 5}}};
}

using test::square_coons;
constexpr auto line = test::line_curve;

// A ruled surface whose first curve is `c` (the place of its errors is /curves/0).
std::string ruled_with(const json& c) {
  return json{{"type", "ruled"}, {"curves", {c, line({0, 1, 0}, {3, 1, 0})}}}.dump();
}

// A loft through three lines (the middle one raised), with `change` applied.
std::string loft_with(const std::function<void(json&)>& change) {
  json s{{"type", "loft"},
         {"sections", {line({0, 0, 0}, {1, 0, 0}), line({0, 1, 0.5}, {1, 1, 0.5}), line({0, 2, 0}, {1, 2, 0})}}};
  change(s);
  return s.dump();
}

json network_with_params(const json& u_params) {
  json s = example("network_gordon");
  s["u_params"] = u_params;
  s["v_params"] = {0, 1.0 / 3, 2.0 / 3, 1};
  return s;
}

using test::f8;
using test::npy_bytes;

// The (2, 3, 3) grid of points k, k+1, ... with a NaN at [1][2][0] when asked.
std::string npy_grid(bool nan) {
  std::vector<double> v;
  for (int k = 0; k < 18; ++k) v.push_back(k == 15 && nan ? std::nan("") : 0.5 * k + (k % 3) * (k % 5));
  return npy_bytes("<f8", "(2, 3, 3)", f8(v));
}

const std::string npy_spec = R"({"type": "interpolate", "points": {"npy": "grid.npy"}})";
const std::string npz_spec = R"({"type": "bspline_surface", "npz": "x.npz"})";

// The archive of a bilinear patch (tests/npy_util.hpp) with one member changed.
std::string npz_with(const std::string& member, const std::string& data) { return test::bilinear_npz_with(member, data); }

// ... or with one member labelled deflate-compressed.
std::string npz_with_compressed(const std::string& member) {
  std::vector<test::ZipMember> m = test::bilinear_members();
  for (auto& e : m)
    if (e.name == member) e.method = 8;
  return test::zip_archive(m);
}

const std::string csv_spec = R"({"type": "interpolate", "points": {"csv": "grid.csv", "shape": [2, 2]}})";

// The 4 x 5 grid approximated to a tolerance.
json approximate_spec() {
  json s = grid_spec();
  s["type"] = "approximate";
  s["tolerance"] = 0.01;
  return s;
}

// Scattered points: n survey points (x, y, z) spread by a fixed rule, "param": "xy".
json scattered_spec(std::size_t n, double tolerance) {
  json pts = json::array();
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k), x = std::fmod(t * 0.618034, 1.0) * 100, y = std::fmod(t * 0.414214, 1.0) * 80;
    pts.push_back({x, y, std::sin(x / 20) * 5});
  }
  return {{"type", "approximate"}, {"param", "xy"}, {"tolerance", tolerance}, {"points", pts}};
}

// --- the table ---------------------------------------------------------------------

using Files = std::map<std::string, std::string>;  // name -> content; a name ending in '/' is a directory

struct Row {
  std::string name;
  Files files;
  std::vector<std::string> args;
  int status;
  std::string pattern;  // searched for in the one stderr line: the place and the size
  // The code behind the failure. `in_spec`: io::build_file of args[1] throws it;
  // otherwise the failure is in the command line, and only its exit status is checked.
  std::optional<errc> code = std::nullopt;
  bool in_spec = true;
};

const char* const grid_file = "s.json";

std::vector<Row> rows() {
  const std::string grid = grid_spec().dump();
  const std::string vol = example("trilinear").dump();
  const auto graded = [](const char* sampling) {
    nlohmann::json j = grid_spec();
    j["sampling"] = nlohmann::json::parse(sampling);
    return j.dump();
  };
  // Two unit boxes along x, the second from x = x0; each block's extra fields merged in.
  const auto two_boxes = [](double x0, const char* a = "{}", const char* b = "{}", const char* extra = "{}") {
    nlohmann::json blocks = nlohmann::json::array();
    for (int n = 0; n < 2; ++n) {
      nlohmann::json box = {{"type", "trilinear"}};
      for (int c = 0; c < 8; ++c)
        box[std::string("p") + char('0' + (c >> 2)) + char('0' + ((c >> 1) & 1)) + char('0' + (c & 1))] = {
            (n ? x0 : 0.0) + (c >> 2), (c >> 1) & 1, c & 1};
      box.update(nlohmann::json::parse(n ? b : a));
      blocks.push_back(box);
    }
    nlohmann::json j = {{"type", "blocks"}, {"blocks", blocks}};
    j.update(nlohmann::json::parse(extra));
    return j.dump();
  };
  const std::string misaligned_ruled = R"({"type": "ruled", "curves": [
      {"degree": 1, "param": "uniform", "periodic": true, "interpolate": [[0.186, 1.019, 0.061],
        [-0.765, 0.896, -0.020], [-1.031, -0.403, 0.098], [0.369, -1.065, 0.055], [1.008, -0.308, -0.029]]},
      {"degree": 6, "param": "chord", "periodic": true, "interpolate": [[1.166, 0.555, 1.229], [0.369, 1.100, 1.241],
        [-0.537, 1.082, 1.128], [-1.225, 0.015, 1.270], [-0.691, -1.012, 1.068], [0.346, -1.129, 1.097],
        [1.103, -0.470, 1.233]]}]})";
  const std::string overflowing = json{{"type", "coons"},
                                       {"boundary",
                                        {{"v0", line({-1e308, -1e308, 0}, {1e308, -1e308, 0})},
                                         {"v1", line({-1e308, 1e308, 0}, {1e308, 1e308, 1e308})},
                                         {"u0", line({-1e308, -1e308, 0}, {-1e308, 1e308, 0})},
                                         {"u1", line({1e308, -1e308, 0}, {1e308, 1e308, 1e308})}}}}
                                      .dump();
  std::vector<Row> t;
  // Made a group at a time, each in a function of its own: one initializer of every
  // row made a function that took a minute to compile under the sanitizers.
  const auto add = [&t](const auto& group) {
    for (Row& row : group()) t.push_back(std::move(row));
  };
  add([&] { return std::vector<Row>{
      // invalid JSON, types, fields
      {"InvalidJson", {{grid_file, "{\"type\": \"interpolate\",\n  \"points\": [[[0,0,0]],]\n}"}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(s\.json:2:24: invalid JSON)", errc::invalid_json},
  }; });
  add([&] { return std::vector<Row>{
      // a device that never ends: parsed as it is read, refused at its first byte
      {"SpecFromADeviceOfZeros", {}, {"info", "/dev/zero"}, 3, R"(/dev/zero:1:1: invalid JSON)", errc::invalid_json},
  }; });
  add([&] { return std::vector<Row>{
      // bytes that are not text, and nesting beyond reason: quoted short and printable
      {"BinarySpec", {{grid_file, std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR\xff\xfe", 18) + std::string(5000, '\x01')}},
       {"info", grid_file}, 3, R"(s\.json:1:1: invalid JSON: .*\\x89)", errc::invalid_json},
      {"DeeplyNestedPoints",
       {{grid_file, R"({"type": "interpolate", "points": )" + std::string(100000, '[') + std::string(100000, ']') + "}"}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points/0/0/0/0/0/0/.*\.\.\..*/0/0: empty list)",
       errc::too_few_points},
      {"UnknownType", {{grid_file, R"({"type": "coonz"})"}}, {"build", grid_file, "-o", "out.json"}, 3,
       R"(/type: unknown type "coonz"; known types: .*interpolate)", errc::unknown_type},
      {"MissingField", {{grid_file, R"({"type": "interpolate", "degree": 3})"}},
       {"eval", grid_file, "--grid", "4", "-o", "out.npy"}, 3, R"(/points: missing field .*\(n\+1\) x \(m\+1\) x 3)",
       errc::missing_field},
      {"MistypedField", {{grid_file, with(grid_spec(), [](json& s) { s["param"] = 3; }).dump()}},
       {"mesh", grid_file, "-o", "out.obj"}, 3, R"(/param: expected a string.*got a number)", errc::wrong_type},
      {"MistypedCoordinate", {{grid_file, with(grid_spec(), [](json& s) { s["points"][3][4][1] = "y"; }).dump()}},
       {"eval", grid_file, "--grid", "4", "-o", "out.csv"}, 3, R"(/points/3/4/1: expected a number \(coordinate y\))",
       errc::wrong_type},
      {"UnknownChoice", {{grid_file, with(square_coons(), [](json& s) { s["blending"] = "cubic"; }).dump()}},
       {"info", grid_file, "-o", "info.json"}, 3, R"(/blending: .*"cubic".*"hermite")", errc::wrong_type},
  }; });
  add([&] { return std::vector<Row>{
      // NaN and Inf, in JSON and in data files
      {"NanInJson", {{grid_file, "{\"type\": \"interpolate\",\n \"points\": [[[0,0,0],[1,0,0]],[[0,1,0],[1,1,NaN]]]}"}},
       {"info", grid_file}, 3, R"(s\.json:2:45: NaN is not a JSON number)", errc::not_finite},
      {"InfinityInJson",
       {{grid_file, "{\"type\": \"interpolate\",\n \"points\": [[[0,0,0],[1,0,0]],[[0,1,0],[1,1,-Infinity]]]}"}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(s\.json:2:45: -Infinity is not a JSON number)", errc::not_finite},
      {"OverflowInJson", {{grid_file, "{\"type\": \"interpolate\",\n \"points\": [[[0,0,0],[1,0,0]],[[0,1,0],[1,1,1e999]]]}"}},
       {"mesh", grid_file, "-o", "out.stl"}, 3, R"(s\.json:2:45: number 1e999 is too large for a double)", errc::not_finite},
      {"NanInNpy", {{grid_file, npy_spec}, {"grid.npy", npy_grid(true)}}, {"eval", grid_file, "--grid", "3", "-o", "out.npy"},
       3, R"(/points/1/2/0: coordinate x is nan \(in grid\.npy\))", errc::not_finite},
      {"InfInCsv", {{grid_file, csv_spec}, {"grid.csv", "x,y,z\n0,0,0\n1,0,0\n0,1,inf\n1,1,0\n"}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points: grid\.csv:4:3: 'inf' is not finite)", errc::not_finite},
  }; });
  add([&] { return std::vector<Row>{
      // ragged grids
      {"RaggedSurfaceGrid", {{grid_file, with(grid_spec(), [](json& s) { s["points"][1].erase(0); }).dump()}},
       {"eval", grid_file, "--grid", "4", "-o", "out.npy"}, 3, R"(/points/1: has 4 points, but /points/0 has 5)",
       errc::ragged_grid},
      {"RaggedVolumeGrid", {{grid_file, with(example("annular_sector"), [](json& s) { s["points"][1][2].erase(2); }).dump()}},
       {"mesh", grid_file, "-o", "out.vts", "--res", "4x4x4"}, 3, R"(/points/1/2: has 2 points, but /points/0/0 has 3)",
       errc::ragged_grid},
      {"PointOfTwoNumbers", {{grid_file, with(grid_spec(), [](json& s) { s["points"][2][3] = {1, 2}; }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points/2/3: .*2)", errc::ragged_grid},
  }; });
  add([&] { return std::vector<Row>{
      // degrees and point counts
      {"TooFewPointsForTheDegree", {{grid_file, with(grid_spec(), [](json& s) { s["degree"] = {4, 3}; }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/degree/0: degree 4 along u needs at least 5 points, /points has 4)",
       errc::too_few_points},
      {"DegreeZero", {{grid_file, ruled_with({{"interpolate", {{0, 0, 0}, {1, 0, 0}, {2, 0, 1}}}, {"degree", 0}})}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/curves/0/degree: degree 0 is outside 1\.\.30)", errc::invalid_degree},
  }; });
  add([&] { return std::vector<Row>{
      // closed (periodic) shapes
      {"PeriodicOfTheWrongLength", {{grid_file, with(grid_spec(), [](json& s) { s["periodic"] = {true}; }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/periodic: expected 2 booleans \[u, v\], one per direction, got 1)",
       errc::wrong_type},
      {"PeriodicNotABoolean", {{grid_file, with(grid_spec(), [](json& s) { s["periodic"] = {false, "yes"}; }).dump()}},
       {"eval", grid_file, "--grid", "4", "-o", "out.npy"}, 3, R"(/periodic/1: expected true or false \(is v closed\?\), got a string)",
       errc::wrong_type},
      {"TooFewPointsAroundAClosedDirection",
       {{grid_file, with(test::pipe_spec(5, 3, true), [](json& s) { s["degree"] = {3, 3}; }).dump()}},
       {"mesh", grid_file, "-o", "out.obj"}, 3,
       R"(/degree/1: degree 3 around v \(closed\) needs at least 4 distinct points, /points has 4 \(shape 5x4\), the last repeating the first)",
       errc::too_few_points},
      {"ClosingPointNearlyTheFirst",
       {{grid_file, with(test::pipe_spec(5, 6, true), [](json& s) { s["points"][2][6][0] = s["points"][2][6][0].get<double>() + 1e-9; }).dump()}},
       {"info", grid_file}, 3,
       R"(/points: point \[2\]\[6\], the last along v, = \(.*\) nearly repeats the first point .*: gap 1e-09, more than the .* \(1e-12 of the bounding-box diagonal\))",
       errc::closing_gap},
      {"ToleranceBelowRounding", {{grid_file, rounding_tolerance_spec().dump()}}, {"info", grid_file}, 3,
       R"(/points: tolerance 1e-300 not met: point \[\d\]\[\d\] is .* from the approximation with 4 x 5 control points, the finest the data allow)",
       errc::tolerance_not_met},
      {"ScatteredTooFewPoints", {{grid_file, scattered_spec(10, 0.1).dump()}}, {"info", grid_file}, 3,
       R"(/points: 10 of 10 points are present \(not missing, weight above 0\): a degree \(3, 3\) surface needs at least 16)",
       errc::too_few_points},
      {"ScatteredPointsOnALine",
       {{grid_file, with(scattered_spec(30, 0.1), [](json& s) {
           for (int k = 0; k < 30; ++k) s["points"][static_cast<std::size_t>(k)] = {double(k), 2.0 * k, std::sin(k)};
         }).dump()}},
       {"info", grid_file}, 3, R"(/points: the 30 points present in x and y all lie on one line \(their spread across it is 0, along it [0-9.]+\))",
       errc::singular},
      {"ScatteredSitesOfAnotherCount",
       {{grid_file, with(scattered_spec(30, 0.1), [](json& s) { s["param"] = {{0, 0}, {1, 1}}; }).dump()}},
       {"info", grid_file}, 3, R"(/param: 2 sites for 30 points \(/points\))", errc::size_mismatch},
      {"ScatteredParamOfAGrid",
       {{grid_file, with(scattered_spec(30, 0.1), [](json& s) { s["param"] = "chord"; }).dump()}},
       {"info", grid_file}, 3, R"(/param: "chord" is for grids; scattered points take "xy")", errc::wrong_type},
      {"ScatteredFieldOnAGrid", {{grid_file, with(approximate_spec(), [](json& s) { s["domain"] = {{0, 1}, {0, 1}}; }).dump()}},
       {"info", grid_file}, 3, R"(/domain: only scattered points \(an \(N, 3\) list\) take it; /points is a grid)", errc::wrong_type},
  }; });
  add([&] { return std::vector<Row>{
      // Two points 1e-6 apart with heights 1 apart: no net up to 8 x 8 separates them.
      {"ScatteredToleranceNotMet",
       {{grid_file, with(scattered_spec(60, 0.1), [](json& s) {
           s["points"][0] = {50.0, 40.0, 0.0};
           s["points"][1] = {50.000001, 40.0, 1.0};
           s["max_control_points"] = 8;
         }).dump()}},
       {"info", grid_file}, 3,
       R"(/points: tolerance 0.1 not met: point \[[01]\] is [0-9.]+ from the approximation with 7 x 7 control points, and doubling the knots would pass the largest net allowed \(8 x 8 control points, max_control_points\))",
       errc::tolerance_not_met},
      {"ApproximationFarPastItsData", {{grid_file, far_hole_spec().dump()}}, {"info", grid_file}, 3,
       R"(/points: surface approximation: control point \[\d+\]\[\d+\] = .* lies .* outside the data's bounding box, more than 9 times its diagonal .*: the fit swings far from its data)",
       errc::ill_conditioned},
      {"ZeroClosingChord",
       {{grid_file, ruled_with({{"interpolate", {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}, {1, 0, 0}}}, {"periodic", true}})}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/curves/0/interpolate/3: point 3 \(1, 0, 0\) coincides with point 0 \(the closing chord of a closed curve has zero length\))",
       errc::zero_chord},
      {"LoftOneSection", {{grid_file, loft_with([](json& s) { s["sections"] = json::array({s["sections"][0]}); })}}, {"info", grid_file}, 3,
       R"(/sections: a loft needs at least 2 sections, got 1)", errc::too_few_points},
      {"LoftClosedAndOpenSections",
       {{grid_file, loft_with([](json& s) {
           s["sections"][1] = {{"interpolate", {{1, 0, 1}, {0, 1, 1}, {-1, 0, 1}, {0, -1, 1}}}, {"periodic", true}};
         })}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/sections/0 is open \(its ends are 1 apart, more than the tolerance .*\) and /sections/1 is closed: a loft's sections are all closed or all open)",
       errc::closing_gap},
      {"LoftSectionsAtOnePlace", {{grid_file, loft_with([](json& s) { s["sections"][2] = s["sections"][1]; })}},
       {"info", grid_file}, 3,
       R"(/sections/2 lies on /sections/1 everywhere: two sections at one place give the loft no room between them)",
       errc::zero_chord},
      {"LoftParamsNotIncreasing", {{grid_file, loft_with([](json& s) { s["param"] = {0, 0.7, 0.5}; })}},
       {"info", grid_file}, 3, R"(/param/2 = 0.5 is not greater than /param/1 = 0.7)", errc::non_increasing},
      {"LoftParamsOfAnotherCount", {{grid_file, loft_with([](json& s) { s["param"] = {0, 1}; })}}, {"info", grid_file}, 3,
       R"(/param: 3 sections need 3 parameters, got 2)", errc::size_mismatch},
      {"LoftParamsNotFromZeroToOne", {{grid_file, loft_with([](json& s) { s["param"] = {0, 0.5, 0.9}; })}},
       {"info", grid_file}, 3, R"(/param must run from 0 to 1, got 0 to 0.9)", errc::out_of_domain},
      {"LoftOneTangent", {{grid_file, loft_with([](json& s) { s["tangents"] = {line({0, 1, 0}, {1, 1, 0})}; })}},
       {"info", grid_file}, 3, R"(/tangents: 2 \(the first and the last section\) or 3 \(one per section\), got 1)",
       errc::size_mismatch},
      {"LoftTangentOfAPeriodicLoft",
       {{grid_file, loft_with([](json& s) {
           s["periodic"] = true;
           s["tangents"] = {line({0, 1, 0}, {1, 1, 0}), nullptr};
         })}},
       {"info", grid_file}, 3, R"(/tangents/0: a periodic loft has no first or last section to join at)", errc::wrong_type},
      {"LoftVolumeSectionOfACurve",
       {{grid_file, json{{"type", "loft_volume"},
                         {"sections", {example("bilinear"), {{"type", "trilinear"}}}}}.dump()}},
       {"info", grid_file}, 3, R"(/sections/1/type: "trilinear" is not a surface type; a face takes one of .*)",
       errc::unknown_type},
      {"LoftVolumeSectionsClosedDifferently",
       {{grid_file, json{{"type", "loft_volume"}, {"sections", {example("bilinear"), example("pipe")}}}.dump()}},
       {"info", grid_file}, 3,
       R"(/sections/1 is closed in v and /sections/0 is open: a loft's sections are closed in the same directions)",
       errc::closing_gap},
      {"ClosedCurveWithAnEndDerivative",
       {{grid_file, ruled_with({{"interpolate", {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}}}, {"periodic", true}, {"start_derivative", {0, 1, 0}}})}},
       {"eval", grid_file, "--grid", "3", "-o", "out.csv"}, 3,
       R"(/curves/0/start_derivative: a closed curve \("periodic": true\) has no ends; give either "periodic" or end derivatives, not both)",
       errc::wrong_type},
  }; });
  add([&] { return std::vector<Row>{
      // coincident points, parameters, knots, weights
      {"ZeroChordInACurve", {{grid_file, ruled_with({{"interpolate", {{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {2, 0, 0}}}})}},
       {"eval", grid_file, "--grid", "3", "-o", "out.csv"}, 3,
       R"(/curves/0/interpolate/2: point 2 \(1, 0, 0\) coincides with point 1)", errc::zero_chord},
      {"ZeroChordInAGrid", {{grid_file, with(grid_spec(), [](json& s) { s["points"][2] = s["points"][1]; }).dump()}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/points: grid points 1 and 2 along u coincide on every line \(averaged parameters 0\.\d+ and 0\.\d+\))",
       errc::zero_chord},
      {"NonIncreasingParams",
       {{grid_file, ruled_with({{"hermite", {{"points", {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}}}, {"params", {0, 0.6, 0.4}}}}})}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/curves/0/hermite/params/2: param 0\.4 is not greater than the one before, 0\.6)", errc::non_increasing},
      {"NonIncreasingNetworkParams", {{grid_file, network_with_params({0, 0.25, 0.25, 0.75, 1}).dump()}},
       {"mesh", grid_file, "-o", "out.ply"}, 3, R"(u_params\[2\] = 0\.25 is not greater than u_params\[1\] = 0\.25)",
       errc::non_increasing},
      {"NetworkParamsOutsideTheDomain", {{grid_file, network_with_params({0, 0.25, 0.5, 0.75, 1.5}).dump()}},
       {"mesh", grid_file, "-o", "out.ply"}, 3, R"(u_params must run from 0 to 1, got 0 to 1\.5)", errc::out_of_domain},
      {"NonIncreasingKnots",
       {{grid_file, ruled_with({{"bspline",
                                 {{"degree", 1},
                                  {"knots", {0, 0, 0.7, 0.3, 1, 1}},
                                  {"control_points", {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}}}}})}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/curves/0/bspline/knots: knot 3 = 0\.3 is smaller than knot 2 = 0\.7)",
       errc::non_increasing},
      {"KnotCountDisagrees",
       {{grid_file, ruled_with({{"bspline",
                                 {{"degree", 1},
                                  {"knots", {0, 0, 0.3, 1, 1}},
                                  {"control_points", {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}}}}})}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/curves/0/bspline/control_points: 5 knots of degree 1 need 3 control points, got 4)", errc::size_mismatch},
      {"KnotsNotClamped",
       {{grid_file, ruled_with({{"bspline",
                                 {{"degree", 1},
                                  {"knots", {0, 0.1, 0.5, 1, 1}},
                                  {"control_points", {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}}}}})}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/curves/0/bspline/knots: knot vector is not clamped at the start: knot 1 = 0\.1 differs from knot 0 = 0)",
       errc::invalid_knots},
      {"KnotSpanBelowTheSmallestNormalDouble",
       {{grid_file, ruled_with({{"bspline",
                                 {{"degree", 1},
                                  {"knots", {0, 0, 5e-324, 1, 1}},
                                  {"control_points", {{0, 0, 0}, {0.5, 0, 0}, {1, 0, 0}}}}}})}},
       {"info", grid_file}, 3,
       R"(/curves/0/bspline/knots: knot 2 = 4\.94066e-324 is only 4\.94066e-324 above knot 1 = 0: a knot span below 2\.22507e-308 \(the smallest normal double\) cannot be evaluated)",
       errc::invalid_knots},
      {"NegativeWeight",
       {{grid_file, ruled_with({{"bspline",
                                 {{"degree", 2},
                                  {"knots", {0, 0, 0, 1, 1, 1}},
                                  {"control_points", {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}},
                                  {"weights", {1, -1, 1}}}}})}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/curves/0/bspline/weights/1: weight -1 is not positive)",
       errc::invalid_weight},
  }; });
  add([&] { return std::vector<Row>{
      // curves and faces that do not meet, twists
      {"CornersDoNotMeet",
       {{grid_file, with(square_coons(), [](json& s) { s["boundary"]["u1"] = line({1, 0, 0}, {1, 1, 1.5}); }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(v1 and u1 do not meet at corner p11: .*gap 0\.5 \(tolerance)",
       errc::corner_gap},
      {"VolumeFacesDoNotMeet",
       {{grid_file, with(example("coons_volume"), [](json& s) { s["faces"]["u1"]["p11"] = {2, 1, 1.5}; }).dump()}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/faces: faces u1 and v1 disagree along their shared edge \(u=1, v=1\) by 0\.5)", errc::corner_gap},
      {"NetworkCurvesMiss",
       {{grid_file, with(network_with_params({0, 0.25, 0.5, 0.75, 1}), [](json& s) {
           for (auto& p : s["u_curves"][2]["interpolate"]) p[2] = p[2].get<double>() + 0.125;
         }).dump()}},
       {"mesh", grid_file, "-o", "out.obj"}, 3,
       R"(/u_curves/2 and /v_curves/0 do not meet: they come closest at \(.*\) \(t = [0-9.e-]+ on /u_curves/2\) and \(.*\) \(t = [0-9.e-]+ on /v_curves/0\), 0\.1[0-9]* apart \(tolerance )", errc::network_gap},
      {"NetworkCurvesOutOfOrder",
       {{grid_file, with(network_with_params({0, 0.25, 0.5, 0.75, 1}), [](json& s) {
           // Two v-curves swapped while u_params still say where each was: the
           // crossings put them in another order than the parameters do.
           std::swap(s["v_curves"][1], s["v_curves"][2]);
         }).dump()}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/u_curves/0 crosses the v_curves in the order 0, 2, 1, 3, 4, u_params put them in the order 0, 1, 2, 3, 4)",
       errc::network_order},
      {"NetworkCurvesCrossTwice",
       {{grid_file, R"({"type": "network",
           "u_curves": [{"line": [[0, 0, 0], [3, 0, 0]]}, {"line": [[0, 1, 0], [3, 1, 0]]}, {"line": [[0, 2, 0], [3, 2, 0]]}],
           "v_curves": [{"line": [[0, 0, 0], [0, 2, 0]]},
                        {"bspline": {"degree": 1, "knots": [0, 0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 1, 1],
                                     "control_points": [[1.5, 0, 0], [1.5, 1.2, 0], [1.5, 1.2, 0.5], [1.7, 0.8, 0.5],
                                                        [1.7, 0.8, 0], [1.7, 1.2, 0], [1.5, 1.5, 0], [1.5, 2, 0]]}},
                        {"line": [[3, 0, 0], [3, 2, 0]]}]})"}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/u_curves/1 and /v_curves/1 cross 2 times \(at \(1\.5, 1, 0\), \(1\.7, 1, 0\)\): each curve of a network crosses each curve of the other family once)",
       errc::network_order},
  }; });
  add([&] { return std::vector<Row>{
      // A part 3 mm across 7e7 from the origin (case 21 of the random networks):
      // rounding keeps the re-expressed curve from half the default tolerance.
      {"NetworkCurveNotReexpressedWithinTolerance",
       {{grid_file, R"({"method":"coons_hermite","type":"network","u_curves":[{"bspline":{"control_points":[[-12313199.71421625,74038650.00214894,41544313.50982428],[-12313199.712861357,74038650.00236042,41544313.509786665],[-12313199.711648738,74038650.00222465,41544313.50961574]],"degree":1,"knots":[0.0,0.0,0.33205940020240887,1.0,1.0]}},{"bspline":{"control_points":[[-12313199.711519705,74038650.00368504,41544313.50953373],[-12313199.7129825,74038650.00400056,41544313.50979805],[-12313199.714258188,74038650.00395241,41544313.50948008]],"degree":1,"knots":[0.0,0.0,0.6679405997975911,1.0,1.0]}},{"bspline":{"control_points":[[-12313199.711759062,74038650.00063252,41544313.509841815],[-12313199.713127641,74038650.00093117,41544313.5096912],[-12313199.714397931,74038650.00052965,41544313.50990711]],"degree":1,"knots":[0.0,0.0,0.6679405997975911,1.0,1.0]}},{"bspline":{"control_points":[[-12313199.714239942,74038650.00292756,41544313.50981107],[-12313199.712861862,74038650.00301465,41544313.509813234],[-12313199.711650318,74038650.00283298,41544313.50952354]],"degree":1,"knots":[0.0,0.0,0.33205940020240887,1.0,1.0]}}],"v_curves":[{"bspline":{"control_points":[[-12313199.71285511,74038650.00397308,41544313.509775035],[-12313199.712692708,74038650.0028939,41544313.50980962],[-12313199.712788235,74038650.00195165,41544313.50974934],[-12313199.713008456,74038650.00090517,41544313.50970432]],"degree":2,"knots":[0.0,0.0,0.0,0.8853557661904754,1.0,1.0,1.0]}},{"bspline":{"control_points":[[-12313199.711759062,74038650.00063252,41544313.509841815],[-12313199.711603133,74038650.00183333,41544313.50972181],[-12313199.711736424,74038650.00277337,41544313.509442106],[-12313199.711519705,74038650.00368504,41544313.50953373]],"degree":2,"knots":[0.0,0.0,0.0,0.11464423380952464,1.0,1.0,1.0]}},{"bspline":{"control_points":[[-12313199.71264447,74038650.00082573,41544313.509744376],[-12313199.71244298,74038650.00191718,41544313.50974132],[-12313199.712414114,74038650.00285877,41544313.50970255],[-12313199.712466067,74038650.00388917,41544313.50970474]],"degree":2,"knots":[0.0,0.0,0.0,0.11464423380952464,1.0,1.0,1.0]}},{"bspline":{"control_points":[[-12313199.714397931,74038650.00052965,41544313.50990711],[-12313199.714195995,74038650.00162604,41544313.50972787],[-12313199.714247325,74038650.00289394,41544313.5100153],[-12313199.714258188,74038650.00395241,41544313.50948008]],"degree":2,"knots":[0.0,0.0,0.0,0.11464423380952464,1.0,1.0,1.0]}}]})"}},
       {"info", grid_file, "-o", "info.json"}, 3,
       R"(/v_curves/1: re-expressed at the common crossing parameters on [0-9]+ knots, it stays [0-9.e-]+ from the curve given, more than [0-9.e-]+ \(half the tolerance\))",
       errc::tolerance_not_met},
  }; });
  add([&] { return std::vector<Row>{
      // A drawn network 1e-3 across near 1e8 (case 201 of the random networks): one
      // curve arranged the wrong way round, the surface far from it.
      {"NetworkSurfaceDepartsFromACurve",
       {{grid_file, R"({"method":"gordon","type":"network","u_curves":[{"bspline":{"control_points":[[-40271575.43322228,89784587.8225911,-55283665.91255118],[-40271575.39153844,89784587.82622749,-55283665.89311275],[-40271575.36759032,89784587.81608644,-55283665.8937435],[-40271575.34732777,89784587.8156776,-55283665.908824675],[-40271575.30773699,89784587.81527485,-55283665.90453305]],"degree":2,"knots":[0.0,0.0,0.0,0.506524787777602,0.9095431054064236,1.0,1.0,1.0]}},{"bspline":{"control_points":[[-40271575.42203161,89784587.70451781,-55283665.91142187],[-40271575.3969438,89784587.7084971,-55283665.895761445],[-40271575.36089991,89784587.69805695,-55283665.89494357],[-40271575.33126036,89784587.69719276,-55283665.89703621],[-40271575.30428947,89784587.70336455,-55283665.907109275]],"degree":2,"knots":[0.0,0.0,0.0,0.506524787777602,0.9095431054064236,1.0,1.0,1.0]}},{"bspline":{"control_points":[[-40271575.304289535,89784587.70336467,-55283665.90710922],[-40271575.331260405,89784587.69719289,-55283665.897036254],[-40271575.36089993,89784587.69805712,-55283665.894943595],[-40271575.39694382,89784587.70849726,-55283665.89576144],[-40271575.42203166,89784587.70451795,-55283665.911421835]],"degree":2,"knots":[0.0,0.0,0.0,0.09045689459357642,0.493475212222398,1.0,1.0,1.0]}}],"v_curves":[{"bspline":{"control_points":[[-40271575.42203161,89784587.70451781,-55283665.91142187],[-40271575.43763899,89784587.74637517,-55283665.89873929],[-40271575.438412584,89784587.7788508,-55283665.90136191],[-40271575.43322228,89784587.8225911,-55283665.91255118]],"degree":1,"knots":[0.0,0.0,0.2954931670197439,0.8559255692532144,1.0,1.0]}},{"bspline":{"control_points":[[-40271575.30773699,89784587.81527485,-55283665.90453305],[-40271575.31402846,89784587.77992336,-55283665.895657554],[-40271575.32438532,89784587.7383803,-55283665.89202664],[-40271575.30428947,89784587.70336455,-55283665.907109275]],"degree":1,"knots":[0.0,0.0,0.1440744307467856,0.7045068329802562,1.0,1.0]}},{"bspline":{"control_points":[[-40271575.36537024,89784587.70004551,-55283665.89529346],[-40271575.372213244,89784587.74708743,-55283665.90145911],[-40271575.372473136,89784587.78596143,-55283665.90994733],[-40271575.3705093,89784587.8180567,-55283665.89497369]],"degree":1,"knots":[0.0,0.0,0.2954931670197439,0.8559255692532144,1.0,1.0]}}]})"}},
       {"info", grid_file, "-o", "info.json"}, 3,
       R"(/v_curves/0: the surface departs from this curve by up to [0-9.e-]+, more than 4 times the tolerance [0-9.e-]+ could explain: the curves are not held as given)",
       errc::tolerance_not_met},
      {"IncompatibleTwists", {{grid_file, with(example("coons_gregory"), [](json& s) { s.erase("twist_correction"); }).dump()}},
       {"info", grid_file, "-o", "info.json"}, 3, R"(incompatible twists at corner p00: .*differ by 1\b)",
       errc::incompatible_twist},
      {"CrossDerivativeAgainstTheBoundary",
       {{grid_file, with(example("coons_cross"), [](json& s) {
           s["cross_derivatives"]["u0"] = line({5, 0, 0}, {5, 0, 1});
         }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(at corner p00 the cross-derivative curve u0 gives .* boundary v0 .* differ by 4)", errc::tangent_mismatch},
      {"NoExactForm", {{grid_file, example("coons_gregory").dump()}}, {"build", grid_file, "-o", "out.json"}, 3,
       R"(^interpatch: coons: .*no exact B-spline form)", errc::no_exact_form, false},
  }; });
  add([&] { return std::vector<Row>{
      // data files
      {"NpyOfTheWrongShape", {{grid_file, npy_spec}, {"grid.npy", npy_bytes("<f8", "(2, 3, 4)", f8(std::vector<double>(24, 1.0)))}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3, R"(/points: grid\.npy has shape \(2, 3, 4\); expected \(n, m, 3\))",
       errc::size_mismatch},
      {"NotAnNpyFile", {{grid_file, npy_spec}, {"grid.npy", "0,0,0\n"}}, {"build", grid_file, "-o", "out.json"}, 3,
       R"(/points: grid\.npy: not an NPY file \(6 bytes, shorter than the NPY preamble\))", errc::malformed_file},
      {"BadNpyHeader",
       {{grid_file, npy_spec}, {"grid.npy", [] { auto b = npy_grid(false); b.replace(20, 5, "XXXXX"); return b; }()}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/points: grid\.npy: malformed NPY header: expected a dtype string in quotes at character 10 of "\{.*\}"\n)",
       errc::malformed_file},
      {"BadNpyDtype", {{grid_file, npy_spec}, {"grid.npy", npy_bytes("<i4", "(2, 3, 3)", std::string(72, '\0'))}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3, R"(/points: grid\.npy: dtype '<i4' is not supported)",
       errc::malformed_file},
      {"TruncatedNpy", {{grid_file, npy_spec}, {"grid.npy", npy_grid(false).substr(0, 128 + 100)}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/points: grid\.npy: truncated: shape \(2, 3, 3\) needs 144 bytes of data, found 100)", errc::malformed_file},
  }; });
  add([&] { return std::vector<Row>{
      // .npz exact forms
      {"TruncatedNpz", {{grid_file, npz_spec}, {"x.npz", test::zip_archive(test::bilinear_members()).substr(0, 300)}},
       {"build", grid_file, "-o", "out.json"}, 3,
       R"(/npz: x\.npz: truncated ZIP archive: no end-of-central-directory record in its last 300 of 300 bytes)",
       errc::malformed_file},
      {"NpzMemberMissing", {{grid_file, npz_spec}, {"x.npz", npz_with("knots_v.npy", "")}}, {"info", grid_file}, 3,
       R"(/npz: x\.npz: no member 'knots_v\.npy' \(an exact form holds degree, knots_u, knots_v, .*; this archive holds degree\.npy, knots_u\.npy, control_points\.npy, periodic\.npy\))",
       errc::malformed_file},
      {"NpzMemberCompressed", {{grid_file, npz_spec}, {"x.npz", npz_with_compressed("control_points.npy")}},
       {"mesh", grid_file, "-o", "out.obj"}, 3,
       R"(/npz: x\.npz: member 'control_points\.npy' is compressed \(method 8, deflate\); only stored members are read)",
       errc::malformed_file},
      {"NpzChecksumMismatch",
       {{grid_file, npz_spec}, {"x.npz", [] { auto b = test::zip_archive(test::bilinear_members()); b[40 + 130] ^= 1; return b; }()}},
       {"build", grid_file, "-o", "out.npz"}, 3,
       R"(/npz: x\.npz: degree\.npy: CRC-32 of its 144 bytes is 0x[0-9a-f]{8}, the archive records 0x[0-9a-f]{8}: the file is damaged)",
       errc::malformed_file},
      {"NpzControlPointsOfTheWrongShape",
       {{grid_file, npz_spec}, {"x.npz", npz_with("control_points.npy", npy_bytes("<f8", "(2, 2, 2)", f8(std::vector<double>(8, 1.0))))}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/npz: x\.npz: control_points\.npy has shape \(2, 2, 2\); expected \(n, m, 3\), the knots need \(2, 2, 3\))",
       errc::size_mismatch},
      {"NanInNpzControlPoints",
       {{grid_file, npz_spec},
        {"x.npz", npz_with("control_points.npy", npy_bytes("<f8", "(2, 2, 3)", f8({0, 0, 0, 0, 1, std::nan(""), 1, 0, 0, 1, 1, 1})))}},
       {"build", grid_file, "-o", "out.step"}, 3, R"(/npz: x\.npz: control_points\.npy: control point \[0\]\[1\] is \(0, 1, nan\))",
       errc::not_finite},
      {"NpzWithControlPoints",
       {{grid_file, R"({"type": "bspline_surface", "npz": "x.npz", "control_points": [[[0, 0, 0], [1, 0, 0]]]})"},
        {"x.npz", test::zip_archive(test::bilinear_members())}},
       {"build", grid_file, "-o", "out.npz"}, 3,
       R"(/npz: give either "npz" or "control_points" \(with the other fields of bspline_surface\), not both)", errc::wrong_type},
      {"ArrayBesideNpy",
       {{grid_file, R"({"type": "interpolate", "points": {"array": "g", "npy": "grid.npy"}})"}},
       {"build", grid_file, "-o", "out.npz"}, 3, R"(/points: give either "array" or "npy", not both)", errc::wrong_type},
      {"NpzOfASurfaceAsAVolume",
       {{grid_file, R"({"type": "bspline_volume", "npz": "x.npz"})"}, {"x.npz", test::zip_archive(test::bilinear_members())}},
       {"mesh", grid_file, "-o", "out.vts"}, 3,
       R"(/npz: x\.npz holds a surface \(degree\.npy has shape \(2,\)\); bspline_surface reads the archive of a surface, bspline_volume that of a volume)",
       errc::wrong_type},
      {"NpzFloatDegrees", {{grid_file, npz_spec}, {"x.npz", npz_with("degree.npy", npy_bytes("<f8", "(2,)", f8({1, 1})))}},
       {"info", grid_file, "-o", "info.json"}, 3, R"(/npz: x\.npz: degree\.npy: dtype '<f8'; expected integers \(int64\))",
       errc::wrong_type},
      {"NpzMissing", {{grid_file, npz_spec}}, {"build", grid_file, "-o", "out.npz"}, 4, R"(/npz: cannot open 'x\.npz': No such file)",
       errc::file_unreadable},
      {"CsvFieldNotANumber", {{grid_file, csv_spec}, {"grid.csv", "x,y,z\n0,0,0\n1,abc,0\n0,1,0\n1,1,0\n"}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points: grid\.csv:3:2: 'abc' is not a number)", errc::malformed_file},
      {"CsvRowOfTwoFields", {{grid_file, csv_spec}, {"grid.csv", "x,y,z\n0,0,0\n1,0\n0,1,0\n1,1,0\n"}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points: grid\.csv:3:3: 2 fields found, 3 expected)",
       errc::malformed_file},
      {"CsvPointCountDisagrees", {{grid_file, csv_spec}, {"grid.csv", "x,y,z\n0,0,0\n1,0,0\n0,1,0\n"}},
       {"eval", grid_file, "--grid", "3", "-o", "out.csv"}, 3, R"(/points: grid\.csv: 3 points found, 4 expected)",
       errc::size_mismatch},
  }; });
  add([&] { return std::vector<Row>{
      // files that cannot be read or written
      {"SpecMissing", {}, {"info", "nope.json"}, 4, R"(nope\.json: cannot read: no such file)", errc::file_unreadable},
      {"SpecIsADirectory", {{"dir.json/", ""}}, {"build", "dir.json", "-o", "out.json"}, 4,
       R"(dir\.json: cannot read: it is a directory)", errc::file_unreadable},
      {"DataFileMissing", {{grid_file, npy_spec}}, {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 4,
       R"(/points: cannot open 'grid\.npy': No such file)", errc::file_unreadable},
      {"BuildIntoAMissingDirectory", {{grid_file, grid}}, {"build", grid_file, "-o", "missing/out.json"}, 4,
       R"(cannot write 'missing/out\.json': directory 'missing' does not exist)", errc::file_unwritable, false},
      {"EvalIntoAMissingDirectory", {{grid_file, grid}}, {"eval", grid_file, "--grid", "3", "-o", "missing/out.npy"}, 4,
       R"(cannot write 'missing/out\.npy': directory 'missing' does not exist)", errc::file_unwritable, false},
      {"MeshIntoAMissingDirectory", {{grid_file, grid}}, {"mesh", grid_file, "-o", "missing/out.obj"}, 4,
       R"(cannot write 'missing/out\.obj': directory 'missing' does not exist)", errc::file_unwritable, false},
      {"PolyMeshIntoAMissingCase", {{grid_file, vol}}, {"mesh", grid_file, "-o", "case/constant/polyMesh"}, 4,
       R"(cannot write 'case/constant/polyMesh': directory 'case/constant' does not exist)", errc::file_unwritable,
       false},
      {"PolyMeshOverAFile", {{grid_file, vol}, {"polyMesh", "a file"}}, {"mesh", grid_file, "-o", "polyMesh"}, 4,
       R"(cannot write 'polyMesh': it exists and is not a directory)", errc::file_unwritable, false},
      {"InfoIntoAMissingDirectory", {{grid_file, grid}}, {"info", grid_file, "-o", "missing/info.json"}, 4,
       R"(cannot write 'missing/info\.json': directory 'missing' does not exist)", errc::file_unwritable, false},
      {"OutputIsADirectory", {{grid_file, grid}, {"out.npy/", ""}}, {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 4,
       R"(cannot write 'out\.npy': it is a directory)", errc::file_unwritable, false},
      {"OutputCheckedBeforeTheSpec", {{grid_file, "{"}}, {"build", grid_file, "-o", "missing/out.json"}, 4,
       R"(cannot write 'missing/out\.json')", errc::file_unwritable, false},
  }; });
  add([&] { return std::vector<Row>{
      // an exact form that differs from its construction (two closed curves of degrees 1
      // and 6 whose merged knots misalign): refused by build, never written
      {"ExactFormOffItsConstruction", {{grid_file, misaligned_ruled}}, {"build", grid_file, "-o", "out.step"}, 3,
       R"(ruled: its B-spline form differs from it by [0-9.e+-]+ at \(u, v\) = )", errc::no_exact_form, false},
  }; });
  add([&] { return std::vector<Row>{
      // a construction whose arithmetic overflows: corners near 1e308, whose differences
      // are infinite; refused at the first sample that is not finite, every output
      // project and intersect: the points and rays files, named by index and line
      {"ProjectNanPoint", {{grid_file, grid}, {"p.npy", npy_bytes("<f8", "(3, 3)", f8({0, 0, 1, 1, std::nan(""), 0, 2, 2, 2}))}},
       {"project", grid_file, "p.npy", "-o", "out.npz"}, 3, R"(point 1 is \(1, nan, 0\): every coordinate must be finite)",
       errc::not_finite, false},
      {"ProjectPointsOfTheWrongShape", {{grid_file, grid}, {"p.npy", npy_bytes("<f8", "(3, 2)", f8({0, 0, 1, 1, 2, 2}))}},
       {"project", grid_file, "p.npy", "-o", "out.npz"}, 3,
       R"(p\.npy: points are an array of shape \(\.\.\., 3\), got \(3, 2\))", errc::malformed_file, false},
      {"ProjectIntegerPoints", {{grid_file, grid}, {"p.npy", npy_bytes("<i8", "(1, 3)", std::string(24, '\0'))}},
       {"project", grid_file, "p.npy", "-o", "out.csv"}, 3, R"(p\.npy: points are float64 or float32, not '<i8')",
       errc::malformed_file, false},
      {"ProjectCsvLineOfTwoNumbers", {{grid_file, grid}, {"p.csv", "x,y,z\n0,0,0\n1,2\n"}},
       {"project", grid_file, "p.csv", "-o", "out.npy"}, 3, R"(p\.csv:3: expected 3 numbers \(points: x, y, z\), got 2)",
       errc::malformed_file, false},
      {"IntersectZeroDirection",
       {{grid_file, grid}, {"r.npy", npy_bytes("<f8", "(2, 2, 3)", f8({1, 1, 5, 0, 0, -1, 1, 1, 5, 0, 0, 0}))}},
       {"intersect", grid_file, "r.npy", "-o", "out.npz"}, 3, R"(ray 1: its direction is the zero vector)", errc::wrong_type,
       false},
      {"IntersectRaysOfTheWrongShape", {{grid_file, grid}, {"r.npy", npy_bytes("<f8", "(2, 3)", f8({0, 0, 0, 1, 1, 1}))}},
       {"intersect", grid_file, "r.npy", "-o", "out.npz"}, 3,
       R"(r\.npy: rays are an array of shape \(\.\.\., 2, 3\), got \(2, 3\))", errc::malformed_file, false},
      {"IntersectAVolume", {{grid_file, vol}, {"r.csv", "0,0,5,0,0,-1\n"}}, {"intersect", grid_file, "r.csv", "-o", "out.csv"}, 3,
       R"(intersect: rays meet surfaces; this is a volume construction)", errc::wrong_type, false},
      {"IntersectACurve", {{grid_file, R"({"line": [[0, 0, 0], [1, 0, 0]]})"}, {"r.csv", "0,0,5,0,0,-1\n"}},
       {"intersect", grid_file, "r.csv", "-o", "out.csv"}, 2, R"('s\.json' is a curve spec: rays meet surfaces)",
       std::nullopt, false},
      {"SamplingOnADirectionTheSurfaceLacks", {{grid_file, graded(R"({"w": {"count": 9}})")}},
       {"mesh", grid_file, "-o", "out.vts"}, 3,
       R"(/sampling/w: a surface has no direction "w"; its directions are u and v)", errc::invalid_grading},
      {"SamplingFirstNotPositive", {{grid_file, graded(R"({"u": {"count": 9, "first": -0.1}})")}},
       {"mesh", grid_file, "-o", "out.vts"}, 3, R"(/sampling/u/first: -0\.1; it must be a positive length)",
       errc::invalid_grading},
      {"SamplingCountTooSmall", {{grid_file, graded(R"({"u": {"count": 5, "first": 1e-4}})")}},
       {"mesh", grid_file, "-o", "out.vts"}, 3,
       R"(sampling u: count 5 would grow by [0-9.]+ from one cell to the next \(max_growth 1\.3\); count [0-9]+ would do)",
       errc::too_few_points, false},
      {"SamplingFirstLongerThanTheDirection", {{grid_file, graded(R"({"v": {"first": 50}})")}},
       {"eval", grid_file, "--grid", "5", "-o", "out.npy"}, 3,
       R"(sampling v: first 50 is longer than the direction: its longest chord from that end is [0-9.]+)",
       errc::invalid_grading, false},
      {"BlocksThatNearlyMeet", {{grid_file, two_boxes(1.001)}}, {"mesh", grid_file, "-o", "out.vtu"}, 3,
       R"(block 0 face u1 and block 1 face u0 nearly meet: their corners are up to 0\.001 apart \(tolerance [0-9.e-]+\); )"
       R"(move them together, or apart)",
       errc::block_mismatch, false},
      {"BlocksCountedDifferentlyAcrossAFace",
       {{grid_file, two_boxes(1, R"({"sampling": {"v": {"count": 9}}})", R"({"sampling": {"v": {"count": 11}}})")}},
       {"mesh", grid_file, "-o", "out.vtu"}, 3,
       R"(/blocks/1/sampling/v \(block1\) has count 11 and /blocks/0/sampling/v \(block0\) count 9; they are tied )"
       R"(across the faces the blocks share: give them one count)",
       errc::block_mismatch, false},
      {"BlocksGradedDifferentlyAcrossAFace",
       {{grid_file, two_boxes(1, R"({"sampling": {"w": {"first": 0.01}}})", R"({"sampling": {"w": {"ratio": 2}}})")}},
       {"info", grid_file}, 3,
       R"(/blocks/1/sampling/w \(block1\) and /blocks/0/sampling/w \(block0\) grade directions tied across the faces )"
       R"(the blocks share, differently; grade one of them)",
       errc::block_mismatch, false},
      {"BlocksPatchOnASharedFace", {{grid_file, two_boxes(1, "{}", "{}", R"({"patches": {"wall": ["block0_u1"]}})")}},
       {"mesh", grid_file, "-o", "polyMesh"}, 3,
       R"(/patches/wall names block0_u1, which another block shares: it is inside the mesh, not on its boundary)",
       errc::block_mismatch, false},
      {"BlocksPatchOfNoFace", {{grid_file, two_boxes(1, "{}", "{}", R"({"patches": {"wall": ["block0_x9"]}})")}},
       {"mesh", grid_file, "-o", "out.vtu"}, 3,
       R"(/patches/wall/0: no block face "block0_x9"; a face is a block's name and one of _u0 _u1 _v0 _v1 _w0 _w1)",
       errc::wrong_type},
      {"BlocksOfASurface", {{grid_file, R"({"type": "blocks", "blocks": [)" + grid + "]}"}},
       {"mesh", grid_file, "-o", "out.vtu"}, 3,
       R"(/blocks/0/type: a block is a volume of one of the types [a-z_, ]+ but blocks; "interpolate" is a surface)",
       errc::wrong_type},
      {"BlocksMeshedWithRes", {{grid_file, two_boxes(1)}}, {"mesh", grid_file, "-o", "out.vtu", "--res", "5x5x5"}, 2,
       R"(--res 5x5x5: a blocks spec takes its counts from each block's "sampling", tied across the faces they share)"},
      {"BlocksBuilt", {{grid_file, two_boxes(1)}}, {"build", grid_file, "-o", "out.step"}, 3,
       R"(blocks: a blocks spec has an exact form per block: build each block's spec)", errc::no_exact_form, false},
      {"BlocksEvaluated", {{grid_file, two_boxes(1)}}, {"eval", grid_file, "--grid", "5", "-o", "out.npy"}, 3,
       R"(blocks: 2 volumes, not one: they are meshed together)", errc::wrong_type, false},
      {"ProjectToAnUnknownFormat", {{grid_file, grid}, {"p.csv", "0,0,0\n"}}, {"project", grid_file, "p.csv", "-o", "out.vtk"}, 2,
       R"(project and intersect write \.npz, \.npy or \.csv)", std::nullopt, false},
      {"EvalOverflowsToNpy", {{grid_file, overflowing}}, {"eval", grid_file, "--grid", "5", "-o", "out.npy"}, 3,
       R"('out\.npy': the value at \[[0-9, ]+\] is -?(nan|inf): the construction's arithmetic left the range of a double)",
       errc::not_finite, false},
      {"EvalOverflowsToCsv", {{grid_file, overflowing}}, {"eval", grid_file, "--grid", "5", "-o", "out.csv"}, 3,
       R"('out\.csv': the value at \[[0-9, ]+\] is -?(nan|inf))", errc::not_finite, false},
      {"MeshOverflowsToObj", {{grid_file, overflowing}}, {"mesh", grid_file, "--res", "5x5", "-o", "out.obj"}, 3,
       R"(the (points|normals) of 'out\.obj': the value at \[[0-9, ]+\] is -?(nan|inf))", errc::not_finite, false},
      {"MeshOverflowsToVts", {{grid_file, overflowing}}, {"mesh", grid_file, "--res", "5x5", "-o", "out.vts"}, 3,
       R"(the (points|normals) of 'out\.vts': the value at \[[0-9, ]+\] is -?(nan|inf))", errc::not_finite, false},
  }; });
  add([&] { return std::vector<Row>{
      // the page shows the exact form's control net, which overflows first
      {"ViewOverflows", {{grid_file, overflowing}}, {"view", grid_file, "-o", "out.html"}, 3,
       R"(coons: its B-spline form's control point \[0\]\[0\] is \(-?nan)", errc::not_finite, false},
  }; });
  add([&] { return std::vector<Row>{
      // a formula (no exact form: a rational curve and a plain one) that overflows at
      // the data info measures it at: refused, never a data error that skips a NaN
      {"InfoDataErrorNotFinite",
       {{grid_file, R"({"type": "ruled", "curves": [
          {"bspline": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[-1.5e308, 0, 0], [1.5e308, 0, 0]], "weights": [1, 2]}},
          {"bspline": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 1, 0], [1, 1, 0]]}}]})"}},
       {"info", grid_file}, 3,
       R"(/curves/[01]/[0-9]+/0: the result at \([0-9.e+-]+, [01]\) is \([^)]*nan[^)]*\): the construction's arithmetic left the range of a double there)",
       errc::not_finite, false},
  }; });
  add([&] { return std::vector<Row>{
      // info reports the exact form: whose it is and why it cannot be made
      {"InfoOverflows", {{grid_file, overflowing}}, {"info", grid_file}, 3,
       R"(coons: its B-spline form's control point \[0\]\[0\] is \(-?nan, -?nan, [^)]*\): the conversion's arithmetic left the range of a double \(coordinates near 1e308\))",
       errc::not_finite, false},
  }; });
  add([&] { return std::vector<Row>{
      // too large: refused before allocating. The bytes needed are an estimate that may
  // change; what stays is the size asked for, the bytes needed and the bytes available.
      {"EvalGridTooLarge", {{grid_file, grid}}, {"eval", grid_file, "--grid", "1000000", "-o", "out.npy"}, 5,
       R"(evaluation grid 1000000x1000000 needs [0-9.]+ [TP]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available on disk in '.+' \([0-9]+ bytes\))",
       errc::too_large, false},
      {"EvalFileBeyondBytes", {{grid_file, grid}}, {"eval", grid_file, "--grid", "1000000000", "-o", "out.npy"}, 5,
       R"(evaluation grid 1000000000x1000000000: more bytes than a file can hold)", errc::too_large, false},
      {"EvalGridBeyondCounting", {{grid_file, grid}},
       {"eval", grid_file, "--grid", "123456789012345678901234567890", "-o", "out.csv"}, 5,
       R"(evaluation grid beyond 2\^64)", errc::too_large, false},
      {"VolumeEvalGridTooLarge", {{grid_file, vol}}, {"eval", grid_file, "--grid", "5000", "-o", "out.npy"}, 5,
       R"(evaluation grid 5000x5000x5000 needs [0-9.]+ [GT]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available on disk in '.+' \([0-9]+ bytes\))", errc::too_large, false},
      {"MeshTooLarge", {{grid_file, grid}}, {"mesh", grid_file, "--res", "200000x200000", "-o", "out.obj"}, 5,
       R"(mesh of 200000x200000 vertices needs [0-9.]+ [GT]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available)", errc::too_large, false},
      {"MeshVtsTooLargeForTheDisk", {{grid_file, grid}}, {"mesh", grid_file, "--res", "2000000x2000000", "-o", "out.vts"}, 5,
       R"(mesh of 2000000x2000000 vertices needs [0-9.]+ [TP]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available on disk in '.+' \([0-9]+ bytes\))",
       errc::too_large, false},
      {"MeshVtkTooLargeForTheDisk", {{grid_file, grid}}, {"mesh", grid_file, "--res", "2000000x2000000", "-o", "out.vtk"}, 5,
       R"(mesh of 2000000x2000000 vertices needs [0-9.]+ [TP]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available on disk in '.+' \([0-9]+ bytes\))",
       errc::too_large, false},
      {"VolumeMeshTooLarge", {{grid_file, vol}}, {"mesh", grid_file, "--res", "5000x5000x5000", "-o", "out.vts"}, 5,
       R"(mesh of 5000x5000x5000 vertices needs [0-9.]+ [GT]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available)", errc::too_large, false},
      {"NpyShapeTooLarge",
       {{grid_file, npy_spec}, {"grid.npy", npy_bytes("<f8", "(1000000, 1000000, 3)", std::string(72, '\0'))}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 5,
       R"(/points: grid\.npy: array of shape \(1000000, 1000000, 3\) needs [0-9.]+ [GT]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available)", errc::too_large},
      {"CsvShapeTooLarge",
       {{grid_file, R"({"type": "interpolate", "points": {"csv": "grid.csv", "shape": [1000000, 1000000]}})"},
        {"grid.csv", "0,0,0\n"}},
       {"build", grid_file, "-o", "out.json"}, 5, R"(/points: 1000000000000 points from grid\.csv needs [0-9.]+ [GT]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available)",
       errc::too_large},
  }; });
  add([&] { return std::vector<Row>{
      // bad usage
      {"NoCommand", {}, {}, 2, R"(command)"},
      {"UnknownCommand", {{grid_file, grid}}, {"frobnicate", grid_file}, 2, R"(unknown command 'frobnicate')"},
      {"UnknownOption", {{grid_file, grid}}, {"build", grid_file, "-o", "out.json", "--bogus"}, 2, R"(--bogus)"},
      {"MissingOutput", {{grid_file, grid}}, {"build", grid_file}, 2, R"(--output is required)"},
      {"MissingSpec", {}, {"build", "-o", "out.json"}, 2, R"(SPEC)"},
      {"MissingGrid", {{grid_file, grid}}, {"eval", grid_file, "-o", "out.npy"}, 2, R"(--grid)"},
      {"GridNotANumber", {{grid_file, grid}}, {"eval", grid_file, "--grid", "abc", "-o", "out.npy"}, 2,
       R"(--grid 'abc': expected a whole number K >= 2)"},
      {"GridOfOne", {{grid_file, grid}}, {"eval", grid_file, "--grid", "1", "-o", "out.npy"}, 2,
       R"(--grid '1': a grid needs at least 2 points along each direction)"},
      {"GridNegative", {{grid_file, grid}}, {"eval", grid_file, "--grid", "-3", "-o", "out.npy"}, 2, R"(-3)"},
      {"ResWithoutX", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.obj", "--res", "64"}, 2,
       R"(--res '64': expected NUxNV)"},
      {"ResOfOne", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.obj", "--res", "1x8"}, 2,
       R"(--res '1x8': a mesh needs at least 2 vertices)"},
      {"ResNotNumbers", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.obj", "--res", "axb"}, 2,
       R"(--res 'axb': expected NUxNV with whole numbers)"},
      {"ResOfFourCounts", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.obj", "--res", "8x8x8x8"}, 2,
       R"(--res '8x8x8x8': .*not more counts)"},
      {"SurfaceResOfThreeCounts", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.obj", "--res", "8x8x8"}, 2,
       R"(--res '8x8x8': a surface mesh takes two counts)"},
      {"VolumeResOfTwoCounts", {{grid_file, vol}}, {"mesh", grid_file, "-o", "out.vts", "--res", "8x8"}, 2,
       R"(--res '8x8': trilinear is a volume; its mesh takes three counts)"},
      {"VolumeMeshAsObj", {{grid_file, vol}}, {"mesh", grid_file, "-o", "out.obj"}, 2,
       R"('out\.obj': trilinear is a volume; \.obj holds surfaces only)"},
      {"SurfaceMeshAsPolyMesh", {{grid_file, grid}}, {"mesh", grid_file, "-o", "polyMesh"}, 2,
       R"('polyMesh': interpolate is a surface; an OpenFOAM polyMesh holds the cells of a volume)"},
      {"BlocksMeshAsVts", {{grid_file, two_boxes(1)}}, {"mesh", grid_file, "-o", "out.vts"}, 2,
       R"('out\.vts': blocks are meshed together as unstructured cells: \.vtu, \.msh \(Gmsh\) or a polyMesh directory)"},
      {"SurfaceMeshAsMsh", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.msh"}, 2,
       R"('out\.msh': interpolate is a surface; \.msh is written with the hexahedral cells of a volume)"},
      {"UnknownBuildExtension", {{grid_file, grid}}, {"build", grid_file, "-o", "out.txt"}, 2,
       R"(cannot tell the output format of 'out\.txt': build writes \.json, \.npz \(NumPy\), \.step/\.stp)"},
      {"UnknownEvalExtension", {{grid_file, grid}}, {"eval", grid_file, "--grid", "8", "-o", "out.txt"}, 2,
       R"(cannot tell the output format of 'out\.txt': eval writes \.npy or \.csv)"},
      {"UnknownMeshExtension", {{grid_file, grid}}, {"mesh", grid_file, "-o", "out.foo"}, 2,
       R"(cannot tell the mesh format of 'out\.foo')"},
      {"UnknownInfoExtension", {{grid_file, grid}}, {"info", grid_file, "-o", "info.txt"}, 2,
       R"(cannot tell the output format of 'info\.txt': info writes \.json)"},
  }; });
  add([&] { return std::vector<Row>{
      // --grid of counts per direction
      {"SurfaceGridOfThreeCounts", {{grid_file, grid}}, {"eval", grid_file, "--grid", "4x5x6", "-o", "out.npy"}, 2,
       R"(--grid '4x5x6': a surface grid takes K or two counts, NUxNV \(NUxNVxNW is for volumes\))"},
      {"VolumeGridOfTwoCounts", {{grid_file, vol}}, {"eval", grid_file, "--grid", "4x5", "-o", "out.csv"}, 2,
       R"(--grid '4x5': trilinear is a volume; its grid takes K or three counts, NUxNVxNW)"},
      {"GridWithAZero", {{grid_file, grid}}, {"eval", grid_file, "--grid", "0x8", "-o", "out.npy"}, 2,
       R"(--grid '0x8': a grid needs at least 2 points along each direction)"},
      {"GridWithAOne", {{grid_file, vol}}, {"eval", grid_file, "--grid", "8x8x1", "-o", "out.npy"}, 2,
       R"(--grid '8x8x1': a grid needs at least 2 points along each direction)"},
      {"GridOfLetters", {{grid_file, grid}}, {"eval", grid_file, "--grid", "8xb", "-o", "out.npy"}, 2,
       R"(--grid '8xb': expected NUxNV with whole numbers, e.g. 100x50)"},
      {"GridOfFourCounts", {{grid_file, grid}}, {"eval", grid_file, "--grid", "2x2x2x2", "-o", "out.npy"}, 2,
       R"(--grid '2x2x2x2': expected NUxNV \(a surface\) or NUxNVxNW \(a volume\), not more counts)"},
      {"EvalGridOfCountsTooLarge", {{grid_file, grid}}, {"eval", grid_file, "--grid", "4x1000000000000", "-o", "out.npy"}, 5,
       R"(evaluation grid 4x1000000000000 needs [0-9.]+ [TP]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available on disk)",
       errc::too_large, false},
      {"VolumeEvalCsvOfCountsTooLarge", {{grid_file, vol}}, {"eval", grid_file, "--grid", "2000x3000x4000", "-o", "out.csv"}, 5,
       R"(evaluation grid 2000x3000x4000 needs [0-9.]+ [GTP]B \([0-9]+ bytes\), [0-9.]+ [kMGT]?B available)", errc::too_large,
       false},
  }; });
  add([&] { return std::vector<Row>{
      // approximation
      {"ApproximateWithAllPointsMissing",
       {{grid_file, with(approximate_spec(), [](json& s) {
           for (auto& row : s["points"])
             for (auto& p : row) p[2] = nullptr;  // z missing: the point is missing
         }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points: all 20 points are missing or have weight 0)", errc::too_few_points},
      {"ApproximateToleranceZero", {{grid_file, with(approximate_spec(), [](json& s) { s["tolerance"] = 0; }).dump()}},
       {"info", grid_file}, 3, R"(/tolerance: tolerance 0 is not a positive distance)", errc::wrong_type},
      {"ApproximateTwoWays", {{grid_file, with(approximate_spec(), [](json& s) { s["smoothing"] = "auto"; }).dump()}},
       {"mesh", grid_file, "-o", "out.obj"}, 3,
       R"(/smoothing: give exactly one of "control_points", "tolerance" and "smoothing"; "tolerance" is given too)",
       errc::wrong_type},
      {"ApproximateNoWay", {{grid_file, with(approximate_spec(), [](json& s) { s.erase("tolerance"); }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(\(top level\): an approximation needs one of "control_points")",
       errc::missing_field},
      {"ApproximateMoreControlPointsThanData",
       {{grid_file, with(approximate_spec(), [](json& s) {
           s.erase("tolerance");
           s["control_points"] = {4, 6};
         }).dump()}},
       {"eval", grid_file, "--grid", "3", "-o", "out.npy"}, 3,
       R"(/control_points/1: 6 control points along v are more than the 5 data points there \(/points has shape 4x5\))",
       errc::too_few_points},
      {"ApproximateWeightsOfTheWrongShape",
       {{grid_file, with(approximate_spec(), [](json& s) { s["weights"] = json::array({{1, 1, 1, 1, 1}, {1, 1, 1, 1, 1}}); }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/weights: shape 2x5 differs from /points, 4x5)", errc::size_mismatch},
      {"ApproximateNegativeWeight",
       {{grid_file, with(approximate_spec(), [](json& s) {
           s["weights"] = json::array();
           for (int i = 0; i < 4; ++i) s["weights"].push_back({1, 1, 1, 1, 1});
           s["weights"][2][3] = -0.5;
         }).dump()}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/weights/2/3: weight -0\.5 is negative)", errc::invalid_weight},
      {"ApproximateNanWeight",
       {{grid_file, "{\"type\": \"approximate\", \"tolerance\": 0.1,\n \"points\": [[[0,0,0],[1,0,0]],[[0,1,0],[1,1,1]]],\n"
                    " \"weights\": [[1, 1], [NaN, 1]]}"}},
       {"info", grid_file}, 3, R"(s\.json:3:23: NaN is not a JSON number)", errc::not_finite},
      {"ApproximateInfinityInNpy", {{grid_file, R"({"type": "approximate", "tolerance": 0.1, "points": {"npy": "grid.npy"}})"},
                                    {"grid.npy", npy_bytes("<f8", "(2, 2, 3)", f8({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, INFINITY}))}},
       {"build", grid_file, "-o", "out.json"}, 3, R"(/points/1/1/2: coordinate z is inf \(in grid\.npy\))", errc::not_finite},
      {"InterpolateNanSaysApproximateTakesIt", {{grid_file, npy_spec}, {"grid.npy", npy_grid(true)}}, {"info", grid_file}, 3,
       R"(/points/1/2/0: coordinate x is nan \(in grid\.npy\) \(interpolation needs every point; "type": "approximate" takes missing points)",
       errc::not_finite},
  }; });
  add([&] { return std::vector<Row>{
      // the viewer page (interpatch view): the same checks, in the same order, as mesh
      {"ViewIntoAMissingDirectory", {{grid_file, grid}}, {"view", grid_file, "-o", "missing/out.html"}, 4,
       R"(cannot write 'missing/out\.html': directory 'missing' does not exist)", errc::file_unwritable, false},
      {"UnknownViewExtension", {{grid_file, grid}}, {"view", grid_file, "-o", "out.png"}, 2,
       R"(cannot tell the output format of 'out\.png': view writes \.html \(or \.htm\))"},
      {"ViewResOfOne", {{grid_file, grid}}, {"view", grid_file, "-o", "out.html", "--res", "1x8"}, 2,
       R"(--res '1x8': a view needs at least 2 samples along each direction)"},
      {"ViewResNotNumbers", {{grid_file, grid}}, {"view", grid_file, "-o", "out.html", "--res", "8xq"}, 2,
       R"(--res '8xq': expected NUxNV with whole numbers, e.g. 257x257)"},
      {"ViewSurfaceResOfThreeCounts", {{grid_file, grid}}, {"view", grid_file, "-o", "out.html", "--res", "8x8x8"}, 2,
       R"(--res '8x8x8': a surface view takes two counts, NUxNV \(NUxNVxNW is for volumes\))"},
      {"ViewVolumeResOfTwoCounts", {{grid_file, vol}}, {"view", grid_file, "-o", "out.html", "--res", "8x8"}, 2,
       R"(--res '8x8': trilinear is a volume; its view takes three counts, NUxNVxNW \(e\.g\. 33x33x33\))"},
      {"ViewOfARaggedGrid", {{grid_file, R"({"type": "interpolate", "points": [[[0,0,0],[1,0,0]], [[0,1,0]]]})"}},
       {"view", grid_file, "-o", "out.html"}, 3, R"(/points/1: has 1 points, but /points/0 has 2)", errc::ragged_grid},
  }; });
  add([&] { return std::vector<Row>{
      // a data file in place of the spec
      {"CsvWithoutShape", {{"grid.csv", "0,0,0\n1,0,0\n0,1,0\n1,1,1\n"}}, {"eval", "grid.csv", "--grid", "3", "-o", "out.npy"}, 2,
       R"('grid\.csv' is a CSV file of points: give the shape of its grid, --shape NxM \(a surface\) or --shape NxMxL)"},
      {"ShapeWithASpec", {{grid_file, grid}}, {"build", grid_file, "--shape", "4x5", "-o", "out.json"}, 2,
       R"(--shape '4x5': 's\.json' is read as a spec; --shape gives the grid of a \.csv file)"},
      {"ShapeWithAnNpy", {{"grid.npy", npy_grid(false)}}, {"info", "grid.npy", "--shape", "2x3"}, 2,
       R"(--shape '2x3': 'grid\.npy' is a \.npy file, whose header gives its shape)"},
      {"ShapeOfOneCount", {{"grid.csv", "0,0,0\n1,0,0\n0,1,0\n1,1,1\n"}}, {"mesh", "grid.csv", "--shape", "4", "-o", "out.obj"}, 2,
       R"(--shape '4': expected NxM, e.g. 40x50 \(points along u and v\), or NxMxL for a volume)"},
      {"ShapeOfLetters", {{"grid.csv", "0,0,0\n1,0,0\n0,1,0\n1,1,1\n"}}, {"mesh", "grid.csv", "--shape", "2xtwo", "-o", "out.obj"}, 2,
       R"(--shape '2xtwo': expected NxM with whole numbers)"},
      {"ShapeWithAOne", {{"grid.csv", "0,0,0\n1,0,0\n0,1,0\n1,1,1\n"}}, {"build", "grid.csv", "--shape", "1x4", "-o", "out.json"}, 2,
       R"(--shape '1x4': a grid of data points needs at least 2 points along each direction)"},
      {"NpyOfRankTwo", {{"grid.npy", npy_bytes("<f8", "(6, 3)", f8(std::vector<double>(18, 1.0)))}},
       {"eval", "grid.npy", "--grid", "3", "-o", "out.npy"}, 3,
       R"(grid\.npy has shape \(6, 3\): points to interpolate are an array of shape \(n, m, 3\) \(a surface\) or \(n, m, l, 3\) \(a volume\))",
       errc::size_mismatch, false},
      {"NpyOfRankFive", {{"data/", ""}, {"data/grid.npy", npy_bytes("<f8", "(1, 2, 2, 2, 3)", f8(std::vector<double>(24, 1.0)))}},
       {"info", "data/grid.npy", "-o", "info.json"}, 3, R"(data/grid\.npy has shape \(1, 2, 2, 2, 3\): points to interpolate)",
       errc::size_mismatch, false},
      {"NpyInPlaceOfSpecMissing", {}, {"mesh", "nope.npy", "-o", "out.obj"}, 4, R"(/points: cannot open 'nope\.npy': No such file)",
       errc::file_unreadable, false},
      {"CsvInPlaceOfSpecMissing", {}, {"build", "nope.csv", "--shape", "4x5", "-o", "out.json"}, 4,
       R"(/points: cannot open 'nope\.csv': No such file)", errc::file_unreadable, false},
  }; });
  add([&] { return std::vector<Row>{
      // ... whose errors are those of the spec that names it
      {"NanInNpyInPlaceOfSpec", {{"grid.npy", npy_grid(true)}}, {"eval", "grid.npy", "--grid", "3x4", "-o", "out.npy"}, 3,
       R"(/points/1/2/0: coordinate x is nan \(in grid\.npy\))", errc::not_finite, false},
      {"CsvInPlaceOfSpecOfTheWrongShape", {{"grid.csv", "0,0,0\n1,0,0\n0,1,0\n1,1,1\n"}},
       {"info", "grid.csv", "--shape", "2x3"}, 3, R"(/points: grid\.csv: 4 points found, 6 expected)", errc::size_mismatch, false},
  }; });
  return t;
}

// The output file a row's command would write: what follows -o.
std::optional<std::string> output_of(const Row& row) {
  const auto o = std::find(row.args.begin(), row.args.end(), "-o");
  if (o == row.args.end() || o + 1 == row.args.end()) return std::nullopt;
  return *(o + 1);
}

void write_files(const test::TempDir& dir, const Files& files) {
  for (const auto& [name, content] : files) {
    if (name.back() == '/') {
      fs::create_directories(dir / name);
    } else {
      std::ofstream out(dir / name, std::ios::binary);
      out << content;
    }
  }
}

// Every file under the directory with its bytes (directories as "/").
std::map<std::string, std::string> snapshot(const test::TempDir& dir) {
  std::map<std::string, std::string> s;
  for (const auto& e : fs::recursive_directory_iterator(dir.path()))
    s[fs::relative(e.path(), dir.path()).string()] = e.is_directory() ? std::string("/") : test::read_text(e.path());
  return s;
}

class BadInput : public ::testing::TestWithParam<Row> {};

TEST_P(BadInput, OneLineNamingPlaceAndSizeAndNothingWritten) {
  const Row& row = GetParam();
  const std::optional<std::string> output = output_of(row);

  // Twice: into an empty place, then over a good file a successful run left there.
  for (const bool existing : {false, true}) {
    SCOPED_TRACE(existing ? "over an existing output" : "with no output");
    test::TempDir dir;
    write_files(dir, row.files);
    if (existing) {
      if (!output || row.files.count(*output + "/") || row.files.count(*output) || !fs::exists((dir / *output).parent_path()))
        continue;  // the output is the row's own input (a file where a directory goes)
      if (fs::path(*output).filename() == "polyMesh") {  // a directory output: a good one there
        fs::create_directory(dir / *output);
        std::ofstream(dir / *output / "points", std::ios::binary) << "a good output of an earlier run\n";
      } else {
        std::ofstream(dir / *output, std::ios::binary) << "a good output of an earlier run\n";
      }
    }
    const auto before = snapshot(dir);
    const test::CliResult r = test::run_cli(dir.path(), row.args);

    test::expect_one_line_error(r, row.status, {});
    EXPECT_TRUE(std::regex_search(r.err, std::regex(row.pattern))) << "'" << r.err << "' does not match " << row.pattern;
    // A message a person can read whatever the input: printable ASCII (user text is
    // quoted with \xNN escapes) and short (a 100000-deep document is not echoed).
    EXPECT_TRUE(std::all_of(r.err.begin(), r.err.end() - (r.err.empty() ? 0 : 1),
                            [](char c) { return c >= 0x20 && c < 0x7f; }))
        << "not printable: '" << r.err << "'";
    EXPECT_LE(r.err.size(), 1000u) << r.err.substr(0, 300);
    // Nothing created, removed or changed: no output, no temporary file, no directory.
    EXPECT_EQ(snapshot(dir), before);

    if (row.status == 5) {
      // Refused before allocating: a 240 GB grid would take minutes and gigabytes.
      // 5 s leaves room for a loaded machine and sanitizers; 300 MB is what the
      // command needs to start under AddressSanitizer, far below any such grid.
      EXPECT_LT(r.seconds, 5.0);
      EXPECT_LT(r.max_rss_kb, 300 * 1024);
    }
  }

  if (row.code) {
    EXPECT_EQ(cli::exit_status(*row.code), row.status) << to_string(*row.code);
    if (row.in_spec) {
      test::TempDir dir;
      write_files(dir, row.files);
      try {
        (void)io::build_file(dir / row.args.at(1));
        ADD_FAILURE() << "io::build_file accepted " << row.args.at(1);
      } catch (const error& e) {
        EXPECT_EQ(e.code(), *row.code) << to_string(e.code()) << ": " << e.what();
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Cli, BadInput, ::testing::ValuesIn(rows()),
                         [](const ::testing::TestParamInfo<Row>& p) { return p.param.name; });

// The table covers every exit status of a failure, and every code the command can
// produce. The codes left out cannot come from a spec or a command line: blending
// functions are named, never given as functions (invalid_blend); internal is a bug.
TEST(BadInputTable, CoversEveryExitStatusAndEveryReachableCode) {
  std::set<int> statuses;
  std::set<errc> codes;
  for (const Row& r : rows()) {
    statuses.insert(r.status);
    if (r.code) codes.insert(*r.code);
    EXPECT_EQ(r.code.has_value(), r.status != 2) << r.name << ": usage errors have no code, every other failure has one";
  }
  EXPECT_EQ(statuses, std::set<int>({2, 3, 4, 5}));
  const std::set<errc> unreachable{errc::invalid_blend, errc::internal};
  for (int c = 0; c <= static_cast<int>(errc::internal); ++c) {
    const auto code = static_cast<errc>(c);
    EXPECT_NE(codes.count(code) + unreachable.count(code), 0u) << to_string(code) << " has no row";
  }
}

#else

TEST(BadInput, NotBuilt) { GTEST_SKIP() << "the interpatch command is not part of this build"; }

#endif

}  // namespace
}  // namespace interpatch
