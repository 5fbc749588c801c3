#include "interpatch/io/json_out.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_specs.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;
using json = nlohmann::json;

json grid_json(const PointGrid& g) {
  json rows = json::array();
  for (std::size_t i = 0; i < g.extent(0); ++i) {
    json row = json::array();
    for (std::size_t j = 0; j < g.extent(1); ++j) row.push_back({g(i, j).x, g(i, j).y, g(i, j).z});
    rows.push_back(row);
  }
  return rows;
}

Construction interpolated(unsigned seed, std::size_t nu, std::size_t nv) {
  auto g = test::rng(seed);
  return build(json{{"type", "interpolate"}, {"points", grid_json(test::random_grid(g, nu, nv))}});
}

TEST(JsonOut, ExactFormIsTheBsplineSurfaceSpecAndReadsBackBitForBit) {
  for (unsigned seed = 0; seed < 10; ++seed) {
    const Construction c = interpolated(seed, 3 + seed % 5, 4 + seed % 3);
    std::ostringstream os;
    write_exact_json(os, *c.exact);
    const json j = json::parse(os.str());
    EXPECT_EQ(j["type"], "bspline_surface");
    const auto& s = std::get<BSplineSurface>(*c.exact);
    EXPECT_EQ(j["degree"], json({s.degree_u(), s.degree_v()}));
    EXPECT_EQ(j["knots"]["u"].get<std::vector<double>>(), s.knots_u().values());
    EXPECT_EQ(j["control_points"].size(), s.control_points().extent(0));
    EXPECT_EQ(j["control_points"][0].size(), s.control_points().extent(1));
    EXPECT_FALSE(j.contains("weights"));
    for (std::size_t i = 0; i < s.control_points().extent(0); ++i)
      for (std::size_t k = 0; k < 3; ++k)
        EXPECT_EQ(j["control_points"][i][1][k].get<double>(), s.control_points()(i, 1)[static_cast<int>(k)]);
  }
}

TEST(JsonOut, RationalSurfacesCarryTheirWeights) {
  const json spec = {{"type", "bspline_surface"},
                     {"degree", {1, 1}},
                     {"knots", {{"u", {0, 0, 1, 1}}, {"v", {0, 0, 1, 1}}}},
                     {"control_points", {{{0, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 1}}}},
                     {"weights", {{1, 2}, {0.5, 1}}}};
  const Construction c = build(spec);
  std::ostringstream os;
  write_exact_json(os, *c.exact);
  const json j = json::parse(os.str());
  EXPECT_EQ(j["weights"], json({{1, 2}, {0.5, 1}}));
  const Construction back = build(j);
  EXPECT_EQ(std::get<BSplineSurface>(*back.exact).weights().values(), std::get<BSplineSurface>(*c.exact).weights().values());
}

TEST(JsonOut, MaxDataErrorIsAtRoundingLevelAndNamesThePoint) {
  const Construction c = interpolated(3, 9, 12);
  const auto e = max_data_error(c);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->count, 9u * 12u);
  EXPECT_LT(e->relative, 1e-12);
  EXPECT_GT(e->diagonal, 1.0);
  EXPECT_EQ(e->pointer.rfind("/points/", 0), 0u);
  EXPECT_EQ(e->params.size(), 2u);
}

TEST(JsonOut, MaxDataErrorSeesAWrongSurface) {
  Construction c = interpolated(4, 5, 5);
  c.data[0].points[2 * 5 + 3] += Vec3{0, 0, 0.5};  // one data point moved
  const auto e = max_data_error(c);
  ASSERT_TRUE(e.has_value());
  EXPECT_NEAR(e->absolute, 0.5, 1e-12);
  EXPECT_EQ(e->pointer, "/points/2/3");
}

TEST(JsonOut, ExactSpecsHaveNoDataError) {
  std::ostringstream os;
  write_exact_json(os, *interpolated(5, 4, 4).exact);
  const Construction c = build(json::parse(os.str()));
  EXPECT_FALSE(max_data_error(c).has_value());
  EXPECT_TRUE(info_json(c)["max_data_error"].is_null());
}

TEST(JsonOut, ContinuityFromKnotMultiplicities) {
  EXPECT_EQ(continuity_name(KnotVector(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1})), "C2");
  EXPECT_EQ(continuity_name(KnotVector(3, {0, 0, 0, 0, 0.5, 0.5, 1, 1, 1, 1})), "C1");
  EXPECT_EQ(continuity_name(KnotVector(3, {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1})), "C0");
  EXPECT_EQ(continuity_name(KnotVector(2, {0, 0, 0, 1, 1, 1})), "Cinf");
}

TEST(JsonOut, InfoHasTheFieldsOtherProgramsRead) {
  const Construction c = interpolated(6, 7, 13);
  const auto j = info_json(c);
  EXPECT_EQ(j["type"], "interpolate");
  EXPECT_EQ(j["kind"], "surface");
  EXPECT_EQ(j["degree"], nlohmann::ordered_json({3, 3}));
  EXPECT_EQ(j["control_points"], nlohmann::ordered_json({7, 13}));
  EXPECT_EQ(j["knots"]["u"].size(), 11u);
  EXPECT_EQ(j["knots"]["v"].size(), 17u);
  EXPECT_EQ(j["continuity"]["u"], "C2");
  EXPECT_EQ(j["continuity"]["v"], "C2");
  EXPECT_LT(j["max_data_error"]["relative"].get<double>(), 1e-12);
  EXPECT_EQ(j["max_data_error"]["points"], 91);
  EXPECT_EQ(j["data"][0]["shape"], nlohmann::ordered_json({7, 13}));
  EXPECT_EQ(j["data"][0]["params"]["u"].size(), 7u);
  EXPECT_EQ(j["bounding_box"]["min"].size(), 3u);
  for (const char* t : {"parse_ms", "build_ms", "check_ms", "total_ms"}) EXPECT_GE(j["timings"][t].get<double>(), 0.0) << t;
  EXPECT_EQ(j.begin().key(), "type");  // the order people read it in
}

TEST(JsonOut, InfoReportsTheClosedDirectionsAndTheContinuityAcrossTheSeam) {
  // The bicubic pipe closed around v: C2 everywhere, across the seam too.
  const auto pipe = info_json(build(test::pipe_spec(8, 12, true)));
  EXPECT_EQ(pipe["periodic"], nlohmann::ordered_json({false, true}));
  EXPECT_EQ(pipe["continuity"], nlohmann::ordered_json({{"u", "C2"}, {"v", "C2"}}));
  EXPECT_EQ(pipe["seam_continuity"], nlohmann::ordered_json({{"v", "C2"}}));
  EXPECT_EQ(pipe["control_points"], nlohmann::ordered_json({8, 12}));
  EXPECT_EQ(pipe["knots"]["v"].size(), 12u + 2 * 3 + 1);  // the extended knots
  EXPECT_EQ(pipe["domain"]["v"], nlohmann::ordered_json({0.0, 1.0}));
  // The closing column is data too, checked at v = 1: the first column, one turn on.
  EXPECT_EQ(pipe["max_data_error"]["points"], 8 * 13);
  EXPECT_LT(pipe["max_data_error"]["relative"].get<double>(), 1e-13);  // rounding of two banded solves
  EXPECT_EQ(pipe["parameters"]["periodic"], nlohmann::ordered_json({false, true}));
  EXPECT_NE(pipe["parameters"]["notes"][0].get<std::string>().find("repeats the first and is left out: 12 distinct"),
            std::string::npos);
  // Quadratic around: C1 across the seam as at every knot.
  json quadratic = test::pipe_spec(8, 12, true);
  quadratic["degree"] = {3, 2};
  const auto q = info_json(build(quadratic));
  EXPECT_EQ(q["seam_continuity"], nlohmann::ordered_json({{"v", "C1"}}));
  EXPECT_EQ(q["continuity"]["v"], "C1");
  // A knot of multiplicity 2 at the seam of a cubic: C1 there, and so in the whole direction.
  const Construction kinked = build(json::parse(R"({"type": "bspline_surface", "degree": [1, 3], "periodic": [false, true],
      "knots": {"u": [0, 0, 1, 1], "v": [-0.75, -0.5, -0.25, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1.25, 1.5]},
      "control_points": [[[1,0,0],[1,1,0],[-1,1,0],[-1,0,0],[0,-1,0]], [[1,0,1],[1,1,1],[-1,1,1],[-1,0,1],[0,-1,1]]]})"));
  const auto k = info_json(kinked);
  EXPECT_EQ(k["seam_continuity"], nlohmann::ordered_json({{"v", "C1"}}));
  EXPECT_EQ(k["continuity"]["v"], "C1");
  // Open: no seam.
  const auto open = info_json(interpolated(6, 7, 13));
  EXPECT_EQ(open["periodic"], nlohmann::ordered_json({false, false}));
  EXPECT_EQ(open["seam_continuity"], nlohmann::ordered_json::object());
  // A volume closed around v.
  const auto tube = info_json(build(test::tube_spec(3, 8, 5, true)));
  EXPECT_EQ(tube["periodic"], nlohmann::ordered_json({false, true, false}));
  EXPECT_EQ(tube["seam_continuity"], nlohmann::ordered_json({{"v", "C2"}}));
  EXPECT_EQ(tube["continuity"]["v"], "C2");
}

TEST(JsonOut, PrettyJsonKeepsPlainArraysOnOneLineAndParsesBack) {
  const auto j = info_json(interpolated(7, 4, 5));
  const std::string text = pretty_json(j);
  EXPECT_EQ(nlohmann::ordered_json::parse(text), j);
  EXPECT_NE(text.find("\"degree\": [3, 3]"), std::string::npos) << text;
  EXPECT_EQ(text.back(), '\n');
}

}  // namespace
}  // namespace interpatch::io

namespace interpatch::io {
namespace {

json corners_spec(bool folded) {
  json spec = {{"type", "trilinear"}};
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n) c[static_cast<std::size_t>(n)] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
  if (folded) std::swap(c[0], c[7]);
  for (std::size_t n = 0; n < 8; ++n)
    spec["p" + std::to_string(n >> 2) + std::to_string((n >> 1) & 1) + std::to_string(n & 1)] = {c[n].x, c[n].y, c[n].z};
  return spec;
}

TEST(JsonOutVolume, InfoDescribesAVolumeAndItsJacobian) {
  const auto j = info_json(build(corners_spec(false)));
  EXPECT_EQ(j["kind"], "volume");
  EXPECT_EQ(j["exact_form"], "bspline_volume");
  EXPECT_EQ(j["degree"], nlohmann::ordered_json({1, 1, 1}));
  EXPECT_EQ(j["control_points"], nlohmann::ordered_json({2, 2, 2}));
  EXPECT_EQ(j["knots"]["w"].size(), 4u);
  EXPECT_EQ(j["continuity"]["w"], "Cinf");
  EXPECT_EQ(j["domain"]["w"], nlohmann::ordered_json({0.0, 1.0}));
  EXPECT_EQ(j["max_data_error"]["points"], 8);
  EXPECT_EQ(j["max_data_error"]["params"].size(), 3u);
  const auto& jac = j["jacobian"];
  EXPECT_EQ(jac["samples_per_direction"], 17);
  EXPECT_EQ(jac["samples"], 4913);
  EXPECT_EQ(jac["cells"], 4096);
  EXPECT_EQ(jac["inverted_cells"], 0);
  EXPECT_DOUBLE_EQ(jac["min_determinant"].get<double>(), 1.0);  // the identity map
  EXPECT_TRUE(jac["inverted_at"].empty());
  EXPECT_EQ(j["data"][0]["shape"], nlohmann::ordered_json({2, 2, 2}));

  const auto f = info_json(build(corners_spec(true)));
  EXPECT_GT(f["jacobian"]["inverted_cells"].get<std::size_t>(), 0u);
  EXPECT_LE(f["jacobian"]["min_determinant"].get<double>(), 0.0);
  EXPECT_EQ(f["jacobian"]["inverted_at"][0].size(), 3u);
  EXPECT_EQ(f["jacobian"]["min_at"].size(), 3u);
}

TEST(JsonOutVolume, MaxDataErrorNamesTheVolumePoint) {
  Construction c = build(corners_spec(false));
  c.data[0].points[6] += Vec3{0, 0.25, 0};  // corner p110 moved
  const auto e = max_data_error(c);
  ASSERT_TRUE(e.has_value());
  EXPECT_NEAR(e->absolute, 0.25, 1e-15);
  EXPECT_EQ(e->pointer, "/p000/1/1/0");
  EXPECT_EQ(e->params, std::vector<double>({1.0, 1.0, 0.0}));
}

TEST(JsonOutVolume, ExactVolumeJsonReadsBackBitForBit) {
  const Construction c = build(corners_spec(false));
  std::ostringstream os;
  write_exact_json(os, *c.exact);
  const json j = json::parse(os.str());
  EXPECT_EQ(j["type"], "bspline_volume");
  EXPECT_EQ(j["degree"], json({1, 1, 1}));
  EXPECT_EQ(j["control_points"][1][0][1], json({1, 0, 1}));
  EXPECT_FALSE(j.contains("weights"));
  const Construction back = build(j);
  EXPECT_EQ(std::get<BSplineVolume>(*back.exact).control_points().values(),
            std::get<BSplineVolume>(*c.exact).control_points().values());
}

}  // namespace
}  // namespace interpatch::io
