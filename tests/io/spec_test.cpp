#include "interpatch/io/spec.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "cli_specs.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/npy.hpp"
#include "npy_util.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;
using json = nlohmann::json;

using test::TempDir;

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

json grid_json(const PointGrid& g) {
  json rows = json::array();
  for (std::size_t i = 0; i < g.extent(0); ++i) {
    json row = json::array();
    for (std::size_t j = 0; j < g.extent(1); ++j) row.push_back({g(i, j).x, g(i, j).y, g(i, j).z});
    rows.push_back(row);
  }
  return rows;
}

json interpolate_spec(const PointGrid& g) { return {{"type", "interpolate"}, {"points", grid_json(g)}}; }

// A small valid grid spec to break in one place per test.
json small_spec() {
  auto g = test::rng(7);
  return interpolate_spec(test::random_grid(g, 4, 5));
}

double max_error_at_data(const Construction& c) {
  const auto& s = std::get<BSplineSurface>(*c.exact);
  double e = 0;
  for (const DataSet& d : c.data) {
    const std::size_t nv = d.params[1].size();
    for (std::size_t i = 0; i < d.params[0].size(); ++i)
      for (std::size_t j = 0; j < nv; ++j)
        e = std::max(e, distance(s.point(d.params[0][i], d.params[1][j]), d.points[i * nv + j]));
  }
  return e;
}

// --- grids through the interpolate type ----------------------------------------

TEST(Spec, InterpolateReproducesTheDataOverRandomGrids) {
  auto g = test::rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t nu = 2 + static_cast<std::size_t>(trial % 7), nv = 2 + static_cast<std::size_t>((trial * 3) % 9);
    const PointGrid q = test::random_grid(g, nu, nv);
    json spec = interpolate_spec(q);
    spec["param"] = trial % 3 == 0 ? "uniform" : (trial % 3 == 1 ? "chord" : "centripetal");
    const Construction c = build(spec);
    EXPECT_EQ(c.type, "interpolate");
    const auto& s = std::get<BSplineSurface>(*c.exact);
    EXPECT_EQ(s.control_points().extent(0), nu);
    EXPECT_EQ(s.control_points().extent(1), nv);
    EXPECT_EQ(s.degree_u(), std::min<int>(3, static_cast<int>(nu) - 1));  // the default degree
    EXPECT_EQ(s.degree_v(), std::min<int>(3, static_cast<int>(nv) - 1));
    EXPECT_EQ(s.domain_u(), std::make_pair(0.0, 1.0));
    EXPECT_EQ(s.domain_v(), std::make_pair(0.0, 1.0));
    ASSERT_EQ(c.data.size(), 1u);
    EXPECT_EQ(c.data[0].pointer, "/points");
    EXPECT_EQ(c.data[0].points.size(), nu * nv);
    EXPECT_LT(max_error_at_data(c), 1e-12 * test::bbox_diagonal(q.values()));
    EXPECT_EQ(c.parameters["param"].get<std::string>(), spec["param"].get<std::string>());
    EXPECT_TRUE(c.warnings.empty());
  }
}

// Arrays held in memory ({"array": NAME}, BuildOptions::arrays): the same surface as
// the same points written inline; an array named once and held by nobody else is
// taken (its entry left empty), one named twice or still held by the caller copied.
TEST(Spec, ACurveSpecIsBuiltAsACurveThroughItsData) {
  const json spec = json::parse(R"({"interpolate": [[0, 0, 0], [1, 2, 0], [3, 3, 1], [4, 0, 0]], "degree": 2})");
  EXPECT_TRUE(is_curve_spec(spec));
  EXPECT_FALSE(is_curve_spec(json::parse(R"({"type": "ruled", "interpolate": []})")));
  const CurveConstruction c = build_curve(spec);
  EXPECT_EQ(c.form, "interpolate");
  EXPECT_EQ(c.curve.degree(), 2);
  EXPECT_EQ(c.curve.domain(), std::make_pair(0.0, 1.0));
  ASSERT_EQ(c.data.size(), 1u);
  EXPECT_EQ(c.data[0].pointer, "/interpolate");
  ASSERT_EQ(c.data[0].params.size(), 1u);
  const std::vector<double>& t = c.data[0].params[0];
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_EQ(t.back(), 1.0);
  for (std::size_t i = 0; i < t.size(); ++i)  // the banded solve's rounding, a few ulps of coordinates ~4
    EXPECT_LT(distance(c.curve.point(t[i]), c.data[0].points[i]), 1e-14);
  EXPECT_EQ(c.parameters["param"], "chord");
  // Its curve is the one the same curve gives inside a construction.
  const BSplineCurve inside = curve_from_json(spec);
  EXPECT_EQ(inside.control_points(), c.curve.control_points());
  // build() is for constructions; build_any() takes either.
  EXPECT_ERRC((void)build(spec), missing_field, "(top level): the spec is a curve");
  EXPECT_TRUE(std::holds_alternative<CurveConstruction>(build_any(spec, {}, {})));
  EXPECT_TRUE(std::holds_alternative<Construction>(build_any(test::square_coons(), {}, {})));
  // An array given but never named is refused as for a construction.
  BuildOptions o;
  o.arrays["extra"] = std::make_shared<PointArray>();
  EXPECT_ERRC((void)build_curve(spec, {}, o), wrong_type, "arrays: \"extra\" is given but the spec names no");
  // The exact form written as JSON reads back to the same curve, bit for bit.
  std::ostringstream text;
  write_exact_json(text, c.curve);
  const CurveConstruction again = build_curve(parse_json(text.str()));
  EXPECT_EQ(again.form, "bspline");
  EXPECT_TRUE(again.data.empty());
  for (const double u : linspace(0, 1, 33)) EXPECT_EQ(again.curve.point(u), c.curve.point(u));
}

TEST(Spec, InMemoryArraysTakenWhenNamedOnceAndHeldByNobodyElse) {
  auto g = test::rng(21);
  const PointGrid q = test::random_grid(g, 7, 5);
  const auto inline_surface = std::get<BSplineSurface>(*build(interpolate_spec(q)).exact);
  const auto array_of = [&] {
    auto a = std::make_shared<PointArray>();
    a->shape = {q.extent(0), q.extent(1)};
    a->points.assign(q.values().begin(), q.values().end());
    return a;
  };
  const auto same_net = [&](const Construction& c) {
    const auto& s = std::get<BSplineSurface>(*c.exact);
    ASSERT_EQ(s.control_points().size(), inline_surface.control_points().size());
    for (std::size_t i = 0; i < s.control_points().size(); ++i)
      EXPECT_EQ(s.control_points().data()[i], inline_surface.control_points().data()[i]) << "control point " << i;
  };
  const json spec = {{"type", "interpolate"}, {"points", {{"array", "q"}}}};

  BuildOptions taken;
  taken.arrays["q"] = array_of();
  same_net(build(spec, {}, taken));
  EXPECT_TRUE(taken.arrays.at("q")->points.empty()) << "named once, held by nobody else: taken";

  BuildOptions held;
  const auto callers = array_of();
  held.arrays["q"] = callers;
  same_net(build(spec, {}, held));
  EXPECT_EQ(callers->points.size(), q.size()) << "the caller still holds it: copied";

  // A ruled surface between two curves through the same array: both see its points.
  PointStorage row(q.values().begin(), q.values().begin() + static_cast<std::ptrdiff_t>(q.extent(1)));
  auto line_array = std::make_shared<PointArray>();
  line_array->shape = {row.size()};
  line_array->points = row;
  BuildOptions twice;
  twice.arrays["c"] = line_array;
  line_array.reset();
  const json ruled = {{"type", "ruled"},
                      {"curves", {{{"interpolate", {{"array", "c"}}}}, {{"interpolate", {{"array", "c"}}}}}}};
  const Construction r = build(ruled, {}, twice);
  const auto& s = std::get<BSplineSurface>(*r.exact);
  EXPECT_EQ(twice.arrays.at("c")->points.size(), row.size()) << "named twice: copied both times";
  for (const double u : {0.0, 0.3, 1.0}) EXPECT_EQ(s.point(u, 0.0), s.point(u, 1.0)) << "both curves the same, at u " << u;
}

// A field given one way only: an array beside a file, or an array the spec never
// names (the field given inline or from a file as well), is refused, not ignored.
TEST(Spec, AnArrayBesideAFileOrNeverNamedIsRefused) {
  auto a = std::make_shared<PointArray>();
  a->shape = {2, 2};
  a->points = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 1}};
  BuildOptions o;
  o.arrays["q"] = a;
  for (const char* file : {"npy", "csv"})
    EXPECT_ERRC((void)build({{"type", "interpolate"}, {"points", {{"array", "q"}, {file, "q.npy"}}}}, {}, o), wrong_type,
                "/points: give either \"array\" or \"" + std::string(file) + "\", not both");
  const json inline_points = {{"type", "interpolate"}, {"points", {{{0, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 1}}}}};
  EXPECT_ERRC((void)build(inline_points, {}, o), wrong_type,
              "arrays: \"q\" is given but the spec names no {\"array\": \"q\"}");
  EXPECT_NO_THROW((void)build({{"type", "interpolate"}, {"points", {{"array", "q"}}}}, {}, o));
}

// borrow_arrays: the data set of an interpolated or approximated in-memory grid names
// the array instead of copying it; filled by the caller, info reports what the copy
// gives. Arrays from anywhere else are copied as before.
TEST(Spec, BorrowedArraysLeaveTheDataPointsToTheCaller) {
  auto g = test::rng(23);
  for (const char* type : {"interpolate", "approximate"}) {
    const PointGrid q = test::random_grid(g, 9, 7);
    json spec = {{"type", type}, {"points", {{"array", "q"}}}};
    if (std::string(type) == "approximate") spec["control_points"] = {6, 5};
    const auto array_of = [&] {
      auto a = std::make_shared<PointArray>();
      a->shape = {q.extent(0), q.extent(1)};
      a->points.assign(q.values().begin(), q.values().end());
      return a;
    };
    BuildOptions copied;
    copied.arrays["q"] = array_of();
    const Construction a = build(spec, {}, copied);
    BuildOptions lent;
    lent.arrays["q"] = array_of();
    lent.borrow_arrays = true;
    Construction b = build(spec, {}, lent);
    ASSERT_EQ(a.data.size(), 1u) << type;
    ASSERT_EQ(b.data.size(), 1u) << type;
    EXPECT_TRUE(a.data[0].array.empty()) << type;
    EXPECT_EQ(a.data[0].points.size(), q.size()) << type;
    EXPECT_EQ(b.data[0].array, "q") << type;
    EXPECT_TRUE(b.data[0].points.empty()) << type;
    EXPECT_EQ(b.data[0].params, a.data[0].params) << type;
    EXPECT_EQ(info_json(b)["max_data_error"], nullptr) << type << ": no points, no check";
    b.data[0].points.assign(q.values().begin(), q.values().end());
    b.data[0].array.clear();
    EXPECT_EQ(info_json(b)["max_data_error"], info_json(a)["max_data_error"]) << type;
  }
  // Points from a file are copied even when arrays are lent.
  BuildOptions lent;
  lent.borrow_arrays = true;
  const Construction inline_points = build(interpolate_spec(test::random_grid(g, 4, 5)), {}, lent);
  ASSERT_EQ(inline_points.data.size(), 1u);
  EXPECT_TRUE(inline_points.data[0].array.empty());
  EXPECT_EQ(inline_points.data[0].points.size(), 20u);
}

// copy_point_array copies exactly and says whether every coordinate is finite; a
// non-finite one in any piece, even the last point's z, is found, and the reader's
// error for it is the same as for an array nobody checked.
TEST(Spec, CopiedPointArraysAreCheckedWhileCopied) {
  auto g = test::rng(24);
  // 300 x 200 points: more than one piece of 2^14 and enough for both threads.
  const std::vector<std::size_t> shape = {300, 200};
  std::vector<double> xyz(3 * 300 * 200);
  for (double& x : xyz) x = test::uniform(g, -5, 5);
  const PointArray a = copy_point_array(xyz.data(), shape);
  EXPECT_EQ(a.shape, shape);
  EXPECT_TRUE(a.finite);
  ASSERT_EQ(a.points.size(), 60000u);
  EXPECT_EQ(std::memcmp(a.points.data(), xyz.data(), xyz.size() * sizeof(double)), 0);
  const json spec = {{"type", "interpolate"}, {"points", {{"array", "q"}}}};
  const auto refusal = [&](const BuildOptions& o) -> std::string {
    try {
      (void)build(spec, {}, o);
    } catch (const error& e) {
      EXPECT_EQ(e.code(), errc::not_finite) << e.what();
      return e.what();
    }
    ADD_FAILURE() << "a non-finite coordinate was taken";
    return {};
  };
  const std::size_t anywhere = std::uniform_int_distribution<std::size_t>(0, xyz.size() - 1)(g);
  for (const std::size_t bad : {std::size_t{0}, std::size_t{3 * 16384 + 1}, xyz.size() - 1, anywhere}) {
    for (const double value : {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::infinity()}) {
      std::vector<double> broken = xyz;
      broken[bad] = value;
      auto checked = std::make_shared<PointArray>(copy_point_array(broken.data(), shape));
      EXPECT_FALSE(checked->finite) << "value " << bad;
      auto unchecked = std::make_shared<PointArray>(*checked);
      unchecked->finite = false;
      BuildOptions o1, o2;
      o1.arrays["q"] = checked;
      o2.arrays["q"] = unchecked;
      const std::string m1 = refusal(o1), m2 = refusal(o2);
      EXPECT_EQ(m1, m2);
      const std::string at = "/points/" + std::to_string(bad / 3 / 200) + "/" + std::to_string(bad / 3 % 200) + "/" +
                             std::to_string(bad % 3) + ":";
      EXPECT_NE(m1.find(at), std::string::npos) << m1;
    }
  }
}

// build, mesh and eval build without the copy of the data points (keep_data false):
// the same exact form, bit for bit, and no data set; info's error check needs them.
TEST(Spec, WithoutDataTheSameExactFormAndNoDataSet) {
  auto g = test::rng(2);
  const PointGrid q = test::random_grid(g, 6, 9);
  const json spec = interpolate_spec(q);
  const Construction kept = build(spec), lean = build(spec, {}, {}, false);
  EXPECT_EQ(kept.data.size(), 1u);
  EXPECT_TRUE(lean.data.empty());
  const auto& a = std::get<BSplineSurface>(*kept.exact);
  const auto& b = std::get<BSplineSurface>(*lean.exact);
  EXPECT_EQ(a.control_points().values(), b.control_points().values());
  EXPECT_EQ(a.knots_u().values(), b.knots_u().values());
}

TEST(Spec, DegreeAsOneNumberOrOnePerDirection) {
  auto g = test::rng(2);
  json spec = interpolate_spec(test::random_grid(g, 6, 7));
  spec["degree"] = 2;
  auto s = std::get<BSplineSurface>(*build(spec).exact);
  EXPECT_EQ(s.degree_u(), 2);
  EXPECT_EQ(s.degree_v(), 2);
  spec["degree"] = {1, 5};
  s = std::get<BSplineSurface>(*build(spec).exact);
  EXPECT_EQ(s.degree_u(), 1);
  EXPECT_EQ(s.degree_v(), 5);
  spec["degree"] = 3.0;  // an integral float is an integer
  EXPECT_EQ(std::get<BSplineSurface>(*build(spec).exact).degree_u(), 3);
}

TEST(Spec, UniformParametersAreEquallySpaced) {
  auto g = test::rng(3);
  json spec = interpolate_spec(test::random_grid(g, 5, 3));
  spec["param"] = "uniform";
  const Construction c = build(spec);
  const std::vector<double> expected{0, 0.25, 0.5, 0.75, 1};
  ASSERT_EQ(c.data[0].params[0].size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(c.data[0].params[0][i], expected[i], 1e-15);
}

TEST(Spec, PoleRowIsAllowed) {
  // A hemisphere-like grid: row 0 is one point repeated.
  PointGrid q({5, 9});
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 9; ++j) {
      const double t = 0.4 * static_cast<double>(i), a = 0.785 * static_cast<double>(j);
      q(i, j) = i == 0 ? Vec3{0, 0, 1} : Vec3{std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)};
    }
  json spec = interpolate_spec(q);
  spec["param"] = "centripetal";
  const Construction c = build(spec);
  EXPECT_LT(max_error_at_data(c), 1e-12);
}

TEST(Spec, UnknownFieldsAreWarnedAboutNotRefused) {
  json spec = small_spec();
  spec["degre"] = 2;
  spec["comment"] = "comments are fine";
  const Construction c = build(spec);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("/degre"), std::string::npos);
}

// Two v-curves 1e-6 apart, one bulging between the u-curves: the network passes
// through both, and its cardinal functions swing by about 1e4 between them. The
// surface is what the curves ask for, but never silently so far from them.
TEST(Spec, ANetworkThatSwingsFarFromItsCurvesIsWarnedAbout) {
  json v = json::array();
  for (double x : {0.0, 0.5, 0.500001, 1.0}) {
    if (x == 0.500001)
      v.push_back({{"interpolate", {{x, 0, 0}, {x, 0.25, 0.1}, {x, 0.5, 0}, {x, 0.75, 0.1}, {x, 1, 0}}}});
    else
      v.push_back(test::line_curve({x, 0, 0}, {x, 1, 0}));
  }
  json u = json::array();
  for (double y : {0.0, 0.5, 1.0}) u.push_back(test::line_curve({0, y, 0}, {1, y, 0}));
  const Construction swinging = build(json{{"type", "network"}, {"u_curves", u}, {"v_curves", v}});
  ASSERT_EQ(swinging.warnings.size(), 1u);
  EXPECT_NE(swinging.warnings[0].find("beyond the box of its curves"), std::string::npos) << swinging.warnings[0];
  // Spaced apart, the same curves stay near their box: no warning.
  v[2] = {{"interpolate", {{0.75, 0, 0}, {0.75, 0.25, 0.1}, {0.75, 0.5, 0}, {0.75, 0.75, 0.1}, {0.75, 1, 0}}}};
  EXPECT_TRUE(build(json{{"type", "network"}, {"u_curves", u}, {"v_curves", v}}).warnings.empty());
}

// A ruled surface between a closed polygon (degree 1, 5 points) and a closed degree-6
// curve: the formula is right, but the conversion of the two closed curves to one knot
// vector misaligns them and the exact form left the polygon by up to 0.6. Every
// conversion is checked against the formula: this one is refused, never written, and
// the construction keeps its formula for eval, mesh and view.
TEST(Spec, AnExactFormThatDiffersFromItsConstructionIsRefused) {
  const json spec = json::parse(R"({"type": "ruled", "curves": [
      {"degree": 1, "param": "uniform", "periodic": true, "interpolate": [
        [0.18579079808879073, 1.0192689718833194, 0.06107895494402585],
        [-0.7646392748472841, 0.8960185727990039, -0.01971524514099423],
        [-1.0305837589677036, -0.4033289746284871, 0.09766892952981268],
        [0.3694463060699154, -1.0651652112602599, 0.05531707094264745],
        [1.0083822812547871, -0.3077715741130244, -0.02855496332384469]]},
      {"degree": 6, "param": "chord", "periodic": true, "interpolate": [
        [1.1657316371841162, 0.5551518963674951, 1.2291921652036566],
        [0.3694093493292091, 1.0998684691189835, 1.2406522219770693],
        [-0.5365674256780528, 1.0823435600405293, 1.1284360579688897],
        [-1.2247690787961294, 0.014925743520540288, 1.2695949271028726],
        [-0.691025262674186, -1.01231854148499, 1.0679432133841225],
        [0.34634074611219506, -1.1285338448080864, 1.0968572452055614],
        [1.103086768412193, -0.4700392918661244, 1.232923090569357]]}]})");
  Construction c = build(spec);
  ASSERT_TRUE(c.formula);
  // S(0.75, 0): three quarters along the polygon's segment from point 3 to point 4
  // (uniform parameters 0.6 and 0.8 of a closed curve of 5 points).
  const Vec3 p3{0.3694463060699154, -1.0651652112602599, 0.05531707094264745};
  const Vec3 p4{1.0083822812547871, -0.3077715741130244, -0.02855496332384469};
  EXPECT_LT(distance(c.formula->point(0.75, 0.0), p3 + 0.75 * (p4 - p3)), 1e-12);
  if (c.exact) {
    // The conversion, once mended, must be right: then it passes the check.
    EXPECT_LT(distance(std::get<BSplineSurface>(*c.exact).point(0.75, 0.0), p3 + 0.75 * (p4 - p3)), 1e-9);
  } else {
    EXPECT_FALSE(has_exact_form(c));
    EXPECT_NE(c.no_exact_form.find("its B-spline form differs from it by"), std::string::npos) << c.no_exact_form;
    EXPECT_ERRC((void)exact_form(c), no_exact_form, "differs from it by");
    EXPECT_EQ(&evaluator(c, 100000, Sample::points), c.formula.get());  // the formula evaluates
  }
}

// --- the exact form reads back ------------------------------------------------

TEST(Spec, BuildOutputRoundTripsExactly) {
  auto g = test::rng(4);
  for (int trial = 0; trial < 5; ++trial) {
    json spec = interpolate_spec(test::random_grid(g, 3 + static_cast<std::size_t>(trial), 9 - static_cast<std::size_t>(trial)));
    const Construction a = build(spec);
    std::ostringstream text;
    write_exact_json(text, *a.exact);
    const Construction b = build(parse_json(text.str()));
    EXPECT_EQ(b.type, "bspline_surface");
    const auto& sa = std::get<BSplineSurface>(*a.exact);
    const auto& sb = std::get<BSplineSurface>(*b.exact);
    EXPECT_EQ(sa.knots_u(), sb.knots_u());
    EXPECT_EQ(sa.knots_v(), sb.knots_v());
    EXPECT_EQ(sa.control_points().values(), sb.control_points().values());  // bit for bit
    EXPECT_TRUE(b.data.empty());
  }
}

TEST(Spec, BSplineSurfaceWithWeightsAndItsOwnDomain) {
  // A quarter cylinder as a rational quadratic in u, linear in v, over [0,2] x [0,1].
  const double w = std::sqrt(0.5);
  json spec = {{"type", "bspline_surface"},
               {"degree", {2, 1}},
               {"knots", {{"u", {0, 0, 0, 2, 2, 2}}, {"v", {0, 0, 1, 1}}}},
               {"control_points", {{{1, 0, 0}, {1, 0, 1}}, {{1, 1, 0}, {1, 1, 1}}, {{0, 1, 0}, {0, 1, 1}}}},
               {"weights", {{1, 1}, {w, w}, {1, 1}}}};
  const Construction c = build(spec);
  const auto& s = std::get<BSplineSurface>(*c.exact);
  EXPECT_TRUE(s.rational());
  EXPECT_EQ(s.domain_u(), std::make_pair(0.0, 1.0));  // mapped onto [0,1]
  EXPECT_EQ(c.parameters["domain"]["u"], nlohmann::ordered_json({0.0, 2.0}));
  for (double u : {0.0, 0.3, 0.5, 0.9}) EXPECT_NEAR(norm(s.point(u, 0.5) - Vec3{0, 0, 0.5}), 1.0, 1e-14);  // on the cylinder
}

// --- point arrays from files ---------------------------------------------------

TEST(Spec, PointsFromNpyAndCsvBesideTheSpec) {
  TempDir dir;
  auto g = test::rng(5);
  const PointGrid q = test::random_grid(g, 4, 6);
  std::vector<double> flat;
  for (const Vec3& p : q.values()) flat.insert(flat.end(), {p.x, p.y, p.z});
  const std::size_t shape[3] = {4, 6, 3};
  write_npy(dir / "grid.npy", shape, flat);
  std::ostringstream csv;
  csv.precision(17);
  csv << "x,y,z\n";
  for (const Vec3& p : q.values()) csv << p.x << "," << p.y << "," << p.z << "\n";
  write_text(dir / "grid.csv", csv.str());

  write_text(dir / "npy.json", R"({"type": "interpolate", "points": {"npy": "grid.npy"}})");
  write_text(dir / "csv.json", R"({"type": "interpolate", "points": {"csv": "grid.csv", "shape": [4, 6]}})");
  write_text(dir / "csv3.json", R"({"type": "interpolate", "points": {"csv": "grid.csv", "shape": [4, 6, 3]}})");
  const Construction inline_ = build(interpolate_spec(q));
  for (const char* name : {"npy.json", "csv.json", "csv3.json"}) {
    const Construction c = build_file(dir / name);  // relative to the spec's directory
    EXPECT_EQ(std::get<BSplineSurface>(*c.exact).control_points().values(),
              std::get<BSplineSurface>(*inline_.exact).control_points().values())
        << name;
    EXPECT_GE(c.timings.parse_ms, 0.0);
    EXPECT_GE(c.timings.build_ms, 0.0);
  }
}

TEST(Spec, PointsFromJsonOfEachRank) {
  const auto a = points_from_json(json::parse("[[0,0,0],[1,2,3]]"), 1);
  EXPECT_EQ(a.shape, std::vector<std::size_t>({2}));
  EXPECT_EQ(a.points[1], (Vec3{1, 2, 3}));
  const auto b = points_from_json(json::parse("[[[[0,0,0]],[[1,0,0]]],[[[0,1,0]],[[1,1,0]]]]"), 3);
  EXPECT_EQ(b.shape, std::vector<std::size_t>({2, 2, 1}));
  EXPECT_EQ(b.points[2], (Vec3{0, 1, 0}));  // C order, first index slowest
}

// --- curves ----------------------------------------------------------------------

TEST(SpecCurve, LineBsplineHermiteInterpolateAllOnTheUnitDomain) {
  const auto line = curve_from_json(json::parse(R"({"line": [[0,0,0], [2,0,0]]})"));
  EXPECT_EQ(line.domain(), std::make_pair(0.0, 1.0));
  EXPECT_EQ(line.point(0.5), (Vec3{1, 0, 0}));

  const auto b = curve_from_json(json::parse(
      R"({"bspline": {"degree": 2, "knots": [2,2,2,3,4,4,4], "control_points": [[0,0,0],[1,1,0],[2,1,0],[3,0,0]]}})"));
  EXPECT_EQ(b.domain(), std::make_pair(0.0, 1.0));
  const BSplineCurve original(KnotVector(2, {2, 2, 2, 3, 4, 4, 4}), {{0, 0, 0}, {1, 1, 0}, {2, 1, 0}, {3, 0, 0}});
  for (double t : {0.0, 0.25, 0.5, 0.8, 1.0}) EXPECT_LT(distance(b.point(t), original.point(2 + 2 * t)), 1e-14);

  const auto h = curve_from_json(json::parse(
      R"({"hermite": {"points": [[0,0,0],[1,1,0],[2,0,0]], "tangents": [[1,0,0],[1,0,0],[1,0,0]], "params": [0, 4, 10]}})"));
  EXPECT_EQ(h.domain(), std::make_pair(0.0, 1.0));
  EXPECT_LT(distance(h.point(0.4), Vec3{1, 1, 0}), 1e-14);
  EXPECT_LT(distance(h.point(1.0), Vec3{2, 0, 0}), 1e-14);

  const auto c = curve_from_json(json::parse(R"({"interpolate": [[0,0,0],[1,2,0],[3,3,0],[4,0,1]], "param": "uniform"})"));
  EXPECT_LT(distance(c.point(1.0 / 3.0), Vec3{1, 2, 0}), 1e-13);
  EXPECT_EQ(c.degree(), 3);
  const auto c1 = curve_from_json(json::parse(R"({"interpolate": [[0,0,0],[1,2,0]]})"));
  EXPECT_EQ(c1.degree(), 1);  // min(3, points - 1)
}

TEST(SpecCurve, ErrorsNameThePlaceUnderThePointer) {
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"interpolate": [[0,0,0],[1,0,0],[2,0,0],[2,0,0],[3,1,0]]})"), {},
                              "/boundary/u1"),
              zero_chord, "/boundary/u1/interpolate/3:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"interpolate": [[0,0,0],[1,0,0]], "degree": 2})"), {}, "/c"),
              too_few_points, "/c/degree:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"bspline": {"degree": 2, "knots": [0,0,1,1,1], "control_points": [[0,0,0],[1,0,0]]}})"),
                              {}, "/c"),
              invalid_knots, "/c/bspline/knots:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"bspline": {"degree": 1, "knots": [0,0,1,1], "control_points": [[0,0,0],[1,0,0],[2,0,0]]}})"),
                              {}, "/c"),
              size_mismatch, "/c/bspline/control_points:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"bspline": {"degree": 1, "knots": [0,0,1,1], "control_points": [[0,0,0],[1,0,0]], "weights": [1, -2]}})"),
                              {}, "/c"),
              invalid_weight, "/c/bspline/weights/1:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"bspline": {"knots": [0,0,1,1], "control_points": [[0,0,0],[1,0,0]]}})"), {}, "/c"),
              missing_field, "/c/bspline/degree:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"hermite": {"points": [[0,0,0],[1,0,0],[2,0,0]], "params": [0, 1, 1]}})"), {}, "/c"),
              non_increasing, "/c/hermite/params/2:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"hermite": {"points": [[0,0,0]]}})"), {}, "/c"), too_few_points,
              "/c/hermite/points:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"line": [[0,0,0],[1,0,0],[2,0,0]]})"), {}, "/c"), size_mismatch, "/c/line:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"line": [[0,0,0],[1,0,0]], "bspline": {}})"), {}, "/c"), wrong_type, "/c:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"lines": [[0,0,0],[1,0,0]]})"), {}, "/c"), missing_field, "/c:");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"([[0,0,0],[1,0,0]])"), {}, "/c"), wrong_type, "/c:");
}

// --- one test per error kind of a surface spec --------------------------------------

TEST(SpecErrors, InvalidJsonNamesLineAndColumn) {
  EXPECT_ERRC((void)parse_json("{\n \"a\": [1,\n 2,, 3]}", "x.json"), invalid_json, "x.json:3:4:");
  EXPECT_ERRC((void)parse_json("", "x.json"), invalid_json, "x.json:1:1:");
  EXPECT_ERRC((void)parse_json("{\"type\": \"interpolate\"", "x.json"), invalid_json, "x.json:1:");
}

// A spec that is not a regular file is parsed as it is read: a device of zeros fails
// at its first byte instead of being read forever.
TEST(SpecErrors, ADeviceThatIsNotJsonFailsAtItsFirstByte) {
  EXPECT_ERRC((void)read_json_file("/dev/zero"), invalid_json, "/dev/zero:1:1: invalid JSON");
}

// A stream that never ends and never stops being valid JSON (white space here, a
// program writing `[1,` forever in the wild) is refused at max_streamed_spec_bytes.
TEST(SpecErrors, AStreamThatNeverEndsIsRefusedAtTheLimit) {
  const test::TempDir dir;
  const std::filesystem::path fifo = dir / "endless.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const auto before = std::signal(SIGPIPE, SIG_IGN);  // the writer learns of the close by EPIPE
  std::thread writer([&] {
    const int fd = open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    const std::string spaces(std::size_t{1} << 16, ' ');
    // Bounded, so that a reader that failed to stop cannot hang the test: twice the limit.
    for (std::size_t sent = 0; sent < 2 * io::max_streamed_spec_bytes;) {
      const ssize_t n = write(fd, spaces.data(), spaces.size());
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    close(fd);
  });
  EXPECT_ERRC((void)read_json_file(fifo), too_large, "at most 256 MiB");
  writer.join();
  std::signal(SIGPIPE, before);
}

// A regular file is measured before it is read.
TEST(SpecErrors, ASpecFileOverTheLimitIsRefusedUnread) {
  const test::TempDir dir;
  const std::filesystem::path big = dir / "big.json";
  { std::ofstream(big) << "{}"; }
  std::filesystem::resize_file(big, io::max_spec_bytes + 1);  // sparse: no disk taken
  EXPECT_ERRC((void)read_json_file(big), too_large, "more than the 1024 MiB a spec may be");
}

TEST(SpecErrors, NonFiniteLiteralsNameLineAndColumn) {
  EXPECT_ERRC((void)parse_json("{\"a\": [1,\n 2, NaN]}", "x.json"), not_finite, "x.json:2:5: NaN");
  EXPECT_ERRC((void)parse_json("{\"a\": [1,\n -Infinity]}", "x.json"), not_finite, "x.json:2:2: -Infinity");
  EXPECT_ERRC((void)parse_json("{\"a\": [1,\n 2, 1e999]}", "x.json"), not_finite, "x.json:2:5: number 1e999");
}

TEST(SpecErrors, NotAnObject) { EXPECT_ERRC((void)build(json::parse("[1, 2]")), wrong_type, "JSON object"); }

TEST(SpecErrors, MissingType) { EXPECT_ERRC((void)build(json::parse(R"({"points": []})")), missing_field, "/type:"); }

TEST(SpecErrors, TypeNotAString) { EXPECT_ERRC((void)build(json::parse(R"({"type": 3})")), wrong_type, "/type:"); }

TEST(SpecErrors, UnknownTypeListsTheKnownOnes) {
  // Every type the reader knows, in the order of its table.
  std::string listed;
  for (const auto t : known_types()) listed += (listed.empty() ? "" : ", ") + std::string(t);
  EXPECT_ERRC((void)build(json::parse(R"({"type": "coonz"})")), unknown_type, "\"coonz\"; known types: " + listed);
  EXPECT_EQ(known_types().front(), "bilinear");
  EXPECT_NE(listed.find("bilinear, ruled, coons, network, interpolate"), std::string::npos) << listed;
}

TEST(SpecErrors, MissingPoints) {
  EXPECT_ERRC((void)build(json::parse(R"({"type": "interpolate"})")), missing_field, "/points: missing field");
}

TEST(SpecErrors, MistypedFieldsNameTheExpectedType) {
  json spec = small_spec();
  spec["degree"] = "three";
  EXPECT_ERRC((void)build(spec), wrong_type, "/degree: expected an integer degree or an array of 2 degrees, got a string");
  spec["degree"] = 2.5;
  EXPECT_ERRC((void)build(spec), wrong_type, "/degree:");
  spec["degree"] = {2, 2, 2};
  EXPECT_ERRC((void)build(spec), size_mismatch, "/degree: expected 2 degrees");
  spec["degree"] = {2, 0};
  EXPECT_ERRC((void)build(spec), invalid_degree, "/degree/1: degree 0");
  spec.erase("degree");
  spec["param"] = "arc";
  EXPECT_ERRC((void)build(spec), wrong_type, "/param: unknown parametrization \"arc\"");
  spec["param"] = 1;
  EXPECT_ERRC((void)build(spec), wrong_type, "/param:");
  spec.erase("param");
  spec["points"] = "grid.npy";
  EXPECT_ERRC((void)build(spec), wrong_type, "/points: expected a 2-D grid of points");
}

TEST(SpecErrors, RaggedGridNamesTheShortRowAndBothLengths) {
  json spec = small_spec();  // 4 x 5
  spec["points"][2].erase(4);
  EXPECT_ERRC((void)build(spec), ragged_grid, "/points/2: has 4 points, but /points/0 has 5");
}

TEST(SpecErrors, PointThatIsNotThreeNumbers) {
  json spec = small_spec();
  spec["points"][1][2] = {1.0, 2.0};
  EXPECT_ERRC((void)build(spec), ragged_grid, "/points/1/2: a point must be 3 numbers");
  spec["points"][1][2] = {1.0, "2", 3.0};
  EXPECT_ERRC((void)build(spec), wrong_type, "/points/1/2/1: expected a number");
  spec["points"][1][2] = 7;
  EXPECT_ERRC((void)build(spec), wrong_type, "/points/1/2: expected a point");
}

TEST(SpecErrors, NonFiniteCoordinateNamesItsPointer) {
  json spec = small_spec();
  spec["points"][3][4][2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_ERRC((void)build(spec), not_finite, "/points/3/4/2: coordinate z is nan");
  spec["points"][3][4][2] = 0.0;
  spec["points"][0][1][0] = -std::numeric_limits<double>::infinity();
  EXPECT_ERRC((void)build(spec), not_finite, "/points/0/1/0:");
}

TEST(SpecErrors, GridOfTheWrongRank) {
  json spec = small_spec();
  spec["points"] = json::parse("[[0,0,0],[1,0,0],[2,0,0]]");
  EXPECT_ERRC((void)build(spec), wrong_type, "/points: expected a 2-D grid of points: lists nested 3 deep, got lists nested 2 deep");
}

TEST(SpecErrors, EmptyGridAndSingleRow) {
  json spec = small_spec();
  spec["points"] = json::array();
  EXPECT_ERRC((void)build(spec), too_few_points, "/points: empty list");
  spec["points"] = json::parse("[[[0,0,0],[1,0,0]]]");
  EXPECT_ERRC((void)build(spec), too_few_points, "/points: the grid has 1 point along u");
}

TEST(SpecErrors, TooFewPointsForTheDegree) {
  json spec = small_spec();  // 4 x 5
  spec["degree"] = {4, 3};
  EXPECT_ERRC((void)build(spec), too_few_points, "/degree/0: degree 4 along u needs at least 5 points, /points has 4");
  spec["degree"] = 5;
  EXPECT_ERRC((void)build(spec), too_few_points, "/degree: degree 5 along u");
}

TEST(SpecErrors, ZeroChordInEveryLine) {
  json spec = small_spec();
  spec["points"][2] = spec["points"][1];  // rows 1 and 2 coincide
  EXPECT_ERRC((void)build(spec), zero_chord, "/points: ");
}

TEST(SpecErrors, NpyFileProblems) {
  TempDir dir;
  const std::size_t shape[3] = {2, 3, 3};
  std::vector<double> data(18, 1.0);
  for (std::size_t i = 0; i < 18; ++i) data[i] = static_cast<double>(i);
  data[3 * (1 * 3 + 2) + 0] = std::numeric_limits<double>::quiet_NaN();
  write_npy(dir / "nan.npy", shape, data);
  const std::size_t flat_shape[2] = {6, 3};
  write_npy(dir / "flat.npy", flat_shape, data);
  const json nan_spec = {{"type", "interpolate"}, {"points", {{"npy", "nan.npy"}}}};
  EXPECT_ERRC((void)build(nan_spec, dir.path()), not_finite, "/points/1/2/0: coordinate x is nan (in nan.npy)");
  const json flat_spec = {{"type", "interpolate"}, {"points", {{"npy", "flat.npy"}}}};
  EXPECT_ERRC((void)build(flat_spec, dir.path()), size_mismatch, "/points: flat.npy has shape (6, 3); expected (n, m, 3)");
  const json missing = {{"type", "interpolate"}, {"points", {{"npy", "nope.npy"}}}};
  EXPECT_ERRC((void)build(missing, dir.path()), file_unreadable, "/points: ");
  write_text(dir / "garbage.npy", "not an npy file at all");
  const json garbage = {{"type", "interpolate"}, {"points", {{"npy", "garbage.npy"}}}};
  EXPECT_ERRC((void)build(garbage, dir.path()), malformed_file, "/points: ");
}

// A large .npy is looked at for NaN and infinities piece by piece as it is read (1
// MiB pieces, on both threads): a bad value anywhere, at the first or last value
// or a piece's first, is named as a scan of the whole grid names it; the first in
// storage order when there are several. A big-endian file is not read in pieces
// and is scanned whole. Approximation still takes NaN as a missing point.
TEST(SpecErrors, NonFiniteInALargeNpyIsFoundWhereverItIs) {
  TempDir dir;
  constexpr std::size_t n = 640, m = 600, values = n * m * 3;  // 9.2 MB: nine pieces, read in parallel
  const std::size_t shape[3] = {n, m, 3};
  std::vector<double> data(values);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      double* p = &data[3 * (i * m + j)];
      p[0] = static_cast<double>(i) + 0.25 * std::sin(0.1 * static_cast<double>(j));
      p[1] = static_cast<double>(j);
      p[2] = std::cos(0.05 * static_cast<double>(i + j));
    }
  const json spec = {{"type", "interpolate"}, {"points", {{"npy", "g.npy"}}}};
  write_npy(dir / "g.npy", shape, data);
  EXPECT_NO_THROW((void)build(spec, dir.path()));
  const auto pointer = [&](std::size_t k) {
    return "/points/" + std::to_string(k / 3 / m) + "/" + std::to_string(k / 3 % m) + "/" + std::to_string(k % 3);
  };
  constexpr double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  constexpr std::size_t piece = (std::size_t{1} << 20) / sizeof(double);
  for (const std::size_t k : {std::size_t{0}, piece - 1, piece, 5 * piece + 7, values - 1})
    for (const double bad : {nan, inf, -inf}) {
      std::vector<double> d = data;
      d[k] = bad;
      write_npy(dir / "g.npy", shape, d);
      const std::string shown = std::isnan(bad) ? "nan" : bad > 0 ? "inf" : "-inf";
      EXPECT_ERRC((void)build(spec, dir.path()), not_finite,
                  pointer(k) + ": coordinate " + "xyz"[k % 3] + " is " + shown + " (in g.npy)");
    }
  std::vector<double> two = data;  // one in a late piece, read first by the second thread, one in an early piece
  two[8 * piece + 1] = nan;
  two[2 * piece + 4] = inf;
  write_npy(dir / "g.npy", shape, two);
  EXPECT_ERRC((void)build(spec, dir.path()), not_finite, pointer(2 * piece + 4) + ": coordinate ");

  // Big-endian, bytes swapped by hand: read whole, then scanned.
  std::vector<double> swapped = data;
  swapped[3 * (7 * m + 11) + 1] = nan;
  std::string payload = test::f8(swapped);
  for (std::size_t k = 0; k < payload.size(); k += 8) std::reverse(payload.begin() + static_cast<long>(k), payload.begin() + static_cast<long>(k) + 8);
  write_text(dir / "big.npy", test::npy_bytes(">f8", "(640, 600, 3)", payload));
  const json big = {{"type", "interpolate"}, {"points", {{"npy", "big.npy"}}}};
  EXPECT_ERRC((void)build(big, dir.path()), not_finite, "/points/7/11/1: coordinate y is nan (in big.npy)");

  // NaN marks a missing point for approximation; an infinity is still refused.
  std::vector<double> holes = data;
  holes[3 * (300 * m + 200)] = nan;
  holes[values - 2] = nan;
  write_npy(dir / "g.npy", shape, holes);
  const json approx = {{"type", "approximate"}, {"points", {{"npy", "g.npy"}}}, {"control_points", {40, 40}}};
  EXPECT_NO_THROW((void)build(approx, dir.path()));
  holes[3 * (600 * m + 2) + 2] = -inf;
  write_npy(dir / "g.npy", shape, holes);
  EXPECT_ERRC((void)build(approx, dir.path()), not_finite, "/points/600/2/2: coordinate z is -inf (in g.npy)");
}

TEST(SpecErrors, CsvFileProblems) {
  TempDir dir;
  write_text(dir / "six.csv", "x,y,z\n0,0,0\n1,0,0\n2,0,0\n0,1,0\n1,1,1\n2,1,0\n");
  json spec = {{"type", "interpolate"}, {"points", {{"csv", "six.csv"}, {"shape", {2, 3}}}}};
  EXPECT_NO_THROW((void)build(spec, dir.path()));
  spec["points"]["shape"] = {6};
  EXPECT_ERRC((void)build(spec, dir.path()), size_mismatch, "/points/shape: shape (6,) does not describe");
  spec["points"]["shape"] = {2, 4};
  EXPECT_ERRC((void)build(spec, dir.path()), size_mismatch, "/points: ");
  spec["points"].erase("shape");
  EXPECT_ERRC((void)build(spec, dir.path()), missing_field, "/points/shape: missing field");
  spec["points"]["shape"] = {2, 3};
  spec["points"]["npy"] = "x.npy";
  EXPECT_ERRC((void)build(spec, dir.path()), wrong_type, "/points: give either \"npy\" or \"csv\"");
  spec["points"] = json::object();
  EXPECT_ERRC((void)build(spec, dir.path()), missing_field, "/points: a point array given as an object needs");
  write_text(dir / "bad.csv", "0,0,0\n1,0,abc\n2,0,0\n0,1,0\n1,1,1\n2,1,0\n");
  spec["points"] = {{"csv", "bad.csv"}, {"shape", {2, 3}}};
  EXPECT_ERRC((void)build(spec, dir.path()), malformed_file, "/points: ");
}

TEST(SpecErrors, BSplineSurfaceFieldsAreChecked) {
  const json good = {{"type", "bspline_surface"},
                     {"degree", {1, 1}},
                     {"knots", {{"u", {0, 0, 1, 1}}, {"v", {0, 0, 1, 1}}}},
                     {"control_points", {{{0, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 1}}}}};
  EXPECT_NEAR(std::get<BSplineSurface>(*build(good).exact).point(0.5, 0.5).z, 0.25, 1e-15);
  json s = good;
  s.erase("degree");
  EXPECT_ERRC((void)build(s), missing_field, "/degree: missing field");
  s = good;
  s["knots"]["u"] = {0, 0, 0.5, 1, 1};
  EXPECT_ERRC((void)build(s), size_mismatch, "/control_points: 2 control points along u");
  s = good;
  s["knots"]["v"] = {0, 1, 0, 1};
  EXPECT_ERRC((void)build(s), non_increasing, "/knots/v: ");
  s = good;
  s["knots"]["v"] = "0011";
  EXPECT_ERRC((void)build(s), wrong_type, "/knots/v: expected an array of numbers");
  s = good;
  s["knots"].erase("u");
  EXPECT_ERRC((void)build(s), missing_field, "/knots/u: missing field");
  s = good;
  s["weights"] = {{1, 0}, {1, 1}};
  EXPECT_ERRC((void)build(s), invalid_weight, "/weights/0/1: weight 0 is not positive");
  s["weights"] = {{1, 1, 1}, {1, 1, 1}};
  EXPECT_ERRC((void)build(s), size_mismatch, "/weights: shape 2x3 differs from /control_points, 2x2");
  s["weights"] = {{1, 1}, {1}};
  EXPECT_ERRC((void)build(s), ragged_grid, "/weights/1: has 1 numbers, but /weights/0 has 2");
}

TEST(SpecErrors, UnreadableSpecFile) {
  TempDir dir;
  EXPECT_ERRC((void)build_file(dir / "nope.json"), file_unreadable, "nope.json");
  EXPECT_ERRC((void)build_file(dir.path()), file_unreadable, "directory");
  write_text(dir / "bad.json", "{\"type\": \"interpolate\",\n \"points\": [}");
  EXPECT_ERRC((void)build_file(dir / "bad.json"), invalid_json, "bad.json:2:");
}

}  // namespace
}  // namespace interpatch::io

namespace interpatch::io {
namespace {

// --- volumes --------------------------------------------------------------------

json trilinear_box() {
  json spec = {{"type", "trilinear"}};
  for (int n = 0; n < 8; ++n)
    spec["p" + std::to_string(n >> 2) + std::to_string((n >> 1) & 1) + std::to_string(n & 1)] = {
        n >> 2, 2 * ((n >> 1) & 1), 3 * (n & 1)};
  return spec;
}

json bilinear_face(const Vec3& p00, const Vec3& p01, const Vec3& p10, const Vec3& p11) {
  return {{"type", "bilinear"},
          {"p00", {p00.x, p00.y, p00.z}},
          {"p01", {p01.x, p01.y, p01.z}},
          {"p10", {p10.x, p10.y, p10.z}},
          {"p11", {p11.x, p11.y, p11.z}}};
}

// The unit cube from its six faces; face w1 interpolated through a 4x4 grid of its points.
json cube_coons() {
  json lid = json::array();
  for (int i = 0; i < 4; ++i) {
    json row = json::array();
    for (int j = 0; j < 4; ++j) row.push_back({i / 3.0, j / 3.0, 1.0});
    lid.push_back(row);
  }
  return {{"type", "coons_volume"},
          {"faces",
           {{"u0", bilinear_face({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 1, 1})},
            {"u1", bilinear_face({1, 0, 0}, {1, 0, 1}, {1, 1, 0}, {1, 1, 1})},
            {"v0", bilinear_face({0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 0, 1})},
            {"v1", bilinear_face({0, 1, 0}, {0, 1, 1}, {1, 1, 0}, {1, 1, 1})},
            {"w0", bilinear_face({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0})},
            {"w1", {{"type", "interpolate"}, {"param", "uniform"}, {"points", lid}}}}}};
}

json volume_grid_json(const PointGrid3& g) {
  json a = json::array();
  for (std::size_t i = 0; i < g.extent(0); ++i) {
    json slab = json::array();
    for (std::size_t j = 0; j < g.extent(1); ++j) {
      json row = json::array();
      for (std::size_t k = 0; k < g.extent(2); ++k) row.push_back({g(i, j, k).x, g(i, j, k).y, g(i, j, k).z});
      slab.push_back(row);
    }
    a.push_back(slab);
  }
  return a;
}

PointGrid3 curved_grid(std::size_t nu, std::size_t nv, std::size_t nw) {
  PointGrid3 q({nu, nv, nw});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      for (std::size_t k = 0; k < nw; ++k) {
        const double x = static_cast<double>(i), y = static_cast<double>(j), z = static_cast<double>(k);
        q(i, j, k) = {x + 0.1 * y * y, y + 0.2 * std::sin(x + z), z + 0.05 * x * y};
      }
  return q;
}

TEST(SpecVolume, TrilinearIsAVolumeWithItsCornersAsData) {
  const Construction c = build(trilinear_box());
  EXPECT_EQ(c.type, "trilinear");
  EXPECT_TRUE(is_volume(c));
  const auto& v = std::get<BSplineVolume>(*c.exact);
  EXPECT_EQ(v.degree_u(), 1);
  const Vec3 p = volume_evaluator(c).point(0.5, 0.5, 0.5);
  EXPECT_NEAR(distance(p, Vec3{0.5, 1, 1.5}), 0.0, 1e-15);
  ASSERT_EQ(c.data.size(), 1u);
  EXPECT_EQ(c.data[0].params.size(), 3u);
  EXPECT_EQ(c.data[0].points[5], (Vec3{1, 0, 3}));  // p101 at 4i + 2j + k
  EXPECT_ERRC((void)evaluator(c), wrong_type, "volume");
}

TEST(SpecVolume, HermiteVolumeReproducesATricubicPolynomial) {
  // (u + 0.2 v w, v + 0.1 u^2, w + 0.3 u v w) from its point frame.
  json corners = json::array();
  for (int n = 0; n < 8; ++n) {
    const double u = n >> 2, v = (n >> 1) & 1, w = n & 1;
    corners.push_back({{"p", {u + 0.2 * v * w, v + 0.1 * u * u, w + 0.3 * u * v * w}},
                       {"du", {1, 0.2 * u, 0.3 * v * w}},
                       {"dv", {0.2 * w, 1, 0.3 * u * w}},
                       {"dw", {0.2 * v, 0, 1 + 0.3 * u * v}},
                       {"duv", {0, 0, 0.3 * w}},
                       {"duw", {0, 0, 0.3 * v}},
                       {"dvw", {0.2, 0, 0.3 * u}},
                       {"duvw", {0, 0, 0.3}}});
  }
  const Construction c = build(json{{"type", "hermite_volume"}, {"corners", corners}});
  const auto& v = std::get<BSplineVolume>(*c.exact);
  const double u = 0.3, vv = 0.6, w = 0.8;
  EXPECT_NEAR(distance(v.point(u, vv, w), Vec3{u + 0.2 * vv * w, vv + 0.1 * u * u, w + 0.3 * u * vv * w}), 0.0, 1e-14);
  corners.erase(7);
  EXPECT_ERRC((void)build(json{{"type", "hermite_volume"}, {"corners", corners}}), size_mismatch, "/corners");
  corners.push_back({{"p", {1, 1, 1}}, {"du", {1, 0, 0}}, {"dv", {0, 1, 0}}});
  EXPECT_ERRC((void)build(json{{"type", "hermite_volume"}, {"corners", corners}}), missing_field, "/corners/7/dw");
}

// A face is read as the volume is: from an array given with the spec as from the
// same points written inline, to the same control net bit for bit.
TEST(SpecVolume, CoonsVolumeFaceFromAnInMemoryArray) {
  const json inline_spec = cube_coons();
  const json& lid = inline_spec["faces"]["w1"]["points"];
  auto a = std::make_shared<PointArray>();
  a->shape = {lid.size(), lid[0].size()};
  for (const auto& row : lid)
    for (const auto& p : row) a->points.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
  json spec = inline_spec;
  spec["faces"]["w1"]["points"] = {{"array", "lid"}};
  BuildOptions o;
  o.arrays["lid"] = a;
  const Construction built_from_array = build(spec, {}, o), built_inline = build(inline_spec);
  const auto& from_array = std::get<BSplineVolume>(*built_from_array.exact);
  const auto& from_inline = std::get<BSplineVolume>(*built_inline.exact);
  ASSERT_EQ(from_array.control_points().size(), from_inline.control_points().size());
  for (std::size_t i = 0; i < from_array.control_points().size(); ++i)
    EXPECT_EQ(from_array.control_points().data()[i], from_inline.control_points().data()[i]) << "control point " << i;
  // An array the face names but nobody gave is named at the face's place.
  EXPECT_ERRC((void)build(spec), missing_field, "/faces/w1/points/array: no array named \"lid\"");
}

TEST(SpecVolume, CoonsVolumeFromSurfaceSpecsTakesItsFaces) {
  const Construction c = build(cube_coons());
  EXPECT_EQ(c.type, "coons_volume");
  EXPECT_TRUE(c.exact.has_value());
  const Vec3 p = volume_evaluator(c).point(0.2, 0.3, 0.4);
  EXPECT_NEAR(distance(p, Vec3{0.2, 0.3, 0.4}), 0.0, 1e-14);
  ASSERT_EQ(c.data.size(), 6u);
  EXPECT_EQ(c.data[3].pointer, "/faces/v1");
  EXPECT_EQ(c.data[3].params[1], std::vector<double>({1.0}));
  const auto e = max_data_error(c);
  ASSERT_TRUE(e.has_value());
  EXPECT_LT(e->absolute, 1e-14);

  json spec = cube_coons();
  spec["blending"] = "hermite";
  spec["cross_derivatives"] = {{"w0", bilinear_face({0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1})}};
  const Construction h = build(spec);
  EXPECT_EQ(h.parameters["cross_derivatives"], nlohmann::ordered_json({"w0"}));
  EXPECT_NEAR(norm(volume_evaluator(h).derivatives(0.5, 0.5, 0).sw - Vec3{0, 0, 1}), 0.0, 1e-12);
}

TEST(SpecVolume, CoonsVolumeErrorsKeepTheirPointerUnderTheFace) {
  json spec = cube_coons();
  spec["faces"]["w1"]["points"][3][2] = {1, 2};
  EXPECT_ERRC((void)build(spec), ragged_grid, "/faces/w1/points/3/2: a point must be 3 numbers");
  spec = cube_coons();
  spec["faces"]["w1"]["points"][1][2][0] = nullptr;
  EXPECT_ERRC((void)build(spec), wrong_type, "/faces/w1/points/1/2/0");
  spec = cube_coons();
  spec["faces"]["u0"] = trilinear_box();
  EXPECT_ERRC((void)build(spec), unknown_type, "/faces/u0/type: \"trilinear\" is not a surface type");
  spec = cube_coons();
  spec["faces"].erase("v1");
  EXPECT_ERRC((void)build(spec), missing_field, "/faces/v1");
  spec = cube_coons();
  spec["faces"]["u1"]["p11"] = {1, 1, 1.25};
  EXPECT_ERRC((void)build(spec), corner_gap, "/faces: faces u1 and");
  spec = cube_coons();
  spec["faces"]["u0"]["bogus"] = 1;
  const Construction c = build(spec);
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_EQ(c.warnings[0], "/faces/u0/bogus: unknown field, ignored");
}

TEST(SpecVolume, InterpolateVolumeReproducesTheDataAndRoundTrips) {
  const PointGrid3 q = curved_grid(5, 4, 6);
  json spec = {{"type", "interpolate_volume"}, {"points", volume_grid_json(q)}, {"degree", {3, 2, 3}}};
  const Construction c = build(spec);
  const auto& v = std::get<BSplineVolume>(*c.exact);
  EXPECT_EQ(v.degree_v(), 2);
  ASSERT_EQ(c.data.size(), 1u);
  const DataSet& d = c.data[0];
  ASSERT_EQ(d.params.size(), 3u);
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 4; ++j)
      for (std::size_t k = 0; k < 6; ++k)
        EXPECT_LT(distance(v.point(d.params[0][i], d.params[1][j], d.params[2][k]), q(i, j, k)), 1e-12);

  std::ostringstream text;
  write_exact_json(text, *c.exact);
  const Construction b = build(parse_json(text.str()));
  EXPECT_EQ(b.type, "bspline_volume");
  const auto& vb = std::get<BSplineVolume>(*b.exact);
  EXPECT_EQ(v.knots_u(), vb.knots_u());
  EXPECT_EQ(v.knots_w(), vb.knots_w());
  EXPECT_EQ(v.control_points().values(), vb.control_points().values());  // bit for bit
}

TEST(SpecVolume, InterpolateVolumeErrorsNameThePlace) {
  json spec = {{"type", "interpolate_volume"}, {"points", volume_grid_json(curved_grid(4, 3, 3))}};
  json bad = spec;
  bad["points"][2][1].erase(0);
  EXPECT_ERRC((void)build(bad), ragged_grid, "/points/2/1: has 2 points, but /points/0/0 has 3");
  bad = spec;
  bad["degree"] = {3, 3, 3};
  EXPECT_ERRC((void)build(bad), too_few_points, "/degree/1");
  bad = spec;
  bad["degree"] = {3, 3};
  EXPECT_ERRC((void)build(bad), size_mismatch, "3 degrees");
  bad = spec;
  bad["points"] = grid_json(PointGrid({3, 3}));
  EXPECT_ERRC((void)build(bad), wrong_type, "/points");
}

TEST(SpecVolume, BSplineVolumeWithWeightsAndItsOwnDomain) {
  json cp = json::array(), w = json::array();
  for (int i = 0; i < 2; ++i) {
    json slab = json::array(), ws = json::array();
    for (int j = 0; j < 2; ++j) {
      json row = json::array(), wr = json::array();
      for (int k = 0; k < 3; ++k) {
        row.push_back({i, j, k});
        wr.push_back(k == 1 ? 2.0 : 1.0);
      }
      slab.push_back(row);
      ws.push_back(wr);
    }
    cp.push_back(slab);
    w.push_back(ws);
  }
  json spec = {{"type", "bspline_volume"},
               {"degree", {1, 1, 2}},
               {"knots", {{"u", {0, 0, 2, 2}}, {"v", {0, 0, 1, 1}}, {"w", {0, 0, 0, 1, 1, 1}}}},
               {"control_points", cp},
               {"weights", w}};
  const Construction c = build(spec);
  const auto& v = std::get<BSplineVolume>(*c.exact);
  EXPECT_TRUE(v.rational());
  EXPECT_EQ(v.domain()[0], std::make_pair(0.0, 1.0));  // mapped onto [0,1]
  EXPECT_EQ(c.parameters["domain"]["u"], nlohmann::ordered_json({0.0, 2.0}));
  std::ostringstream text;
  write_exact_json(text, *c.exact);
  const Construction b = build(parse_json(text.str()));
  EXPECT_EQ(std::get<BSplineVolume>(*b.exact).weights().values(), v.weights().values());

  json bad = spec;
  bad["weights"][1][0][2] = -1;
  EXPECT_ERRC((void)build(bad), invalid_weight, "/weights/1/0/2");
  bad = spec;
  bad["knots"].erase("w");
  EXPECT_ERRC((void)build(bad), missing_field, "/knots/w");
  bad = spec;
  bad["knots"]["v"] = {0, 0, 0.5, 1, 1};
  EXPECT_ERRC((void)build(bad), size_mismatch, "/control_points: 2 control points along v");
}

TEST(SpecVolume, KnownTypesListTheVolumes) {
  const auto t = known_types();
  for (const char* name : {"trilinear", "coons_volume", "hermite_volume", "interpolate_volume", "bspline_volume"})
    EXPECT_NE(std::find(t.begin(), t.end(), name), t.end()) << name;
}

}  // namespace
}  // namespace interpatch::io

namespace interpatch::io {
namespace {

// A spec of a network of n × n curves on z = sin(3u) cos(2v) / 5, each curve m points
// interpolated at uniform parameters (so every curve has the same knots).
json network_spec(std::size_t n, std::size_t m, const char* method) {
  const auto S = [](double u, double v) { return json::array({u, v, 0.2 * std::sin(3 * u) * std::cos(2 * v)}); };
  json uc = json::array(), vc = json::array(), p = json::array();
  for (std::size_t j = 0; j < n; ++j) {
    const double c = static_cast<double>(j) / static_cast<double>(n - 1);
    json a = json::array(), b = json::array();
    for (std::size_t i = 0; i < m; ++i) {
      const double t = static_cast<double>(i) / static_cast<double>(m - 1);
      a.push_back(S(t, c));
      b.push_back(S(c, t));
    }
    uc.push_back({{"interpolate", a}, {"param", "uniform"}});
    vc.push_back({{"interpolate", b}, {"param", "uniform"}});
    p.push_back(c);
  }
  return {{"type", "network"}, {"u_curves", uc}, {"v_curves", vc}, {"u_params", p}, {"v_params", p}, {"method", method}};
}

// A network's curves are read on both threads: its warnings come in the order of
// the curves, and of two bad curves the first is the one named, as when they are
// read one after another.
TEST(Spec, NetworkCurvesReadTogetherKeepTheSpecsOrder) {
  json spec = network_spec(6, 60, "gordon");
  for (const std::size_t j : {4u, 1u, 3u}) spec["v_curves"][j]["bogus"] = j;
  const Construction c = build(spec);
  ASSERT_EQ(c.warnings.size(), 3u);
  EXPECT_EQ(c.warnings[0], "/v_curves/1/bogus: unknown field, ignored");
  EXPECT_EQ(c.warnings[1], "/v_curves/3/bogus: unknown field, ignored");
  EXPECT_EQ(c.warnings[2], "/v_curves/4/bogus: unknown field, ignored");
  for (int trial = 0; trial < 20; ++trial) {  // whichever thread fails first
    json bad = network_spec(6, 60, "gordon");
    bad["u_curves"][5]["interpolate"] = json::array({json::array({0, 0, 0})});
    bad["u_curves"][2]["interpolate"][3] = "x";
    EXPECT_ERRC((void)build(bad), wrong_type, "/u_curves/2/interpolate/3");
  }
}

// A Coons patch of four m-point curves at chord parameters (their knots differ).
json coons_spec(std::size_t m) {
  json side[4];
  for (std::size_t i = 0; i < m; ++i) {
    const double t = static_cast<double>(i) / static_cast<double>(m - 1);
    side[0].push_back({t, 0, 0.1 * std::sin(6 * t)});
    side[1].push_back({t, 1, 0.1 * std::sin(5 * t) + 0.2 * t});
    side[2].push_back({0, t, 0.05 * std::sin(3 * t) * (1 - t)});
    side[3].push_back({1, t, 0.1 * std::sin(6) * (1 - t) + t * (0.1 * std::sin(5) + 0.2) + 0.05 * std::sin(7 * t) * (1 - t) * t});
  }
  return {{"type", "coons"},
          {"boundary", {{"v0", {{"interpolate", side[0]}}}, {"v1", {{"interpolate", side[1]}}},
                        {"u0", {{"interpolate", side[2]}}}, {"u1", {{"interpolate", side[3]}}}}}};
}

// A Coons patch's four sides are read together too: a missing side and a bad one are
// reported in the order v0, v1, u0, u1, as when they are read one after another.
TEST(Spec, CoonsSidesReadTogetherKeepTheSpecsOrder) {
  ASSERT_NO_THROW((void)build(coons_spec(64)));
  json bad = coons_spec(64);
  bad["boundary"]["v0"]["interpolate"][2] = "x";
  bad["boundary"].erase("u1");
  EXPECT_ERRC((void)build(bad), wrong_type, "/boundary/v0/interpolate/2");
  bad = coons_spec(64);
  bad["boundary"].erase("v1");
  bad["boundary"]["u0"]["interpolate"][2] = "x";
  EXPECT_ERRC((void)build(bad), missing_field, "/boundary/v1");
  bad = coons_spec(64);
  bad["boundary"]["u1"]["bogus"] = 1;
  bad["boundary"]["v0"]["bogus"] = 0;
  const Construction c = build(bad);
  ASSERT_EQ(c.warnings.size(), 2u);
  EXPECT_EQ(c.warnings[0], "/boundary/v0/bogus: unknown field, ignored");
  EXPECT_EQ(c.warnings[1], "/boundary/u1/bogus: unknown field, ignored");
}

const BuildOptions deferred{.progress = {}, .keep_data = false, .defer_exact = true, .arrays = {}};

TEST(SpecExact, DeferredUntilAskedThenTheSameAsBuiltAtOnce) {
  const json spec = coons_spec(40);
  Construction c = build(spec, {}, deferred);
  EXPECT_FALSE(c.exact.has_value());
  EXPECT_TRUE(has_exact_form(c));
  EXPECT_FALSE(is_volume(c));
  EXPECT_EQ(&evaluator(c), c.formula.get());  // nothing built: the formula evaluates
  const auto& made = std::get<BSplineSurface>(exact_form(c));
  EXPECT_TRUE(c.exact.has_value());
  EXPECT_FALSE(c.convert);
  EXPECT_EQ(&evaluator(c), &made);
  const Construction at_once = build(spec);
  EXPECT_EQ(made.control_points().values(), std::get<BSplineSurface>(*at_once.exact).control_points().values());
  // A construction without one says why, deferred or not: a rational side (weights
  // 1, 2, 1) blended with polynomial ones.
  json rational = spec;
  rational["boundary"]["v0"] = {{"bspline",
                                 {{"degree", 2},
                                  {"knots", {0, 0, 0, 1, 1, 1}},
                                  {"control_points", {{0, 0, 0}, {0.5, 0, 0.1}, {1, 0, 0.1 * std::sin(6)}}},
                                  {"weights", {1, 2, 1}}}}};
  Construction r = build(rational, {}, deferred);
  EXPECT_FALSE(has_exact_form(r));
  EXPECT_FALSE(r.convert);
  EXPECT_ERRC((void)exact_form(r), no_exact_form, "coons: curve 0 of the u-direction terms is rational");
  EXPECT_EQ(&evaluator(r, 1000, Sample::points), r.formula.get());
}

// A progress callback that throws (Python's Ctrl-C, a caller's cancel) stops the
// conversion, which stays to be made: the next call makes the same exact form as a
// construction never interrupted.
TEST(SpecExact, AnInterruptedConversionIsMadeAgainInFull) {
  const json spec = coons_spec(600);  // ~1200 rows: the progress is heard before the end
  Construction c = build(spec, {}, deferred);
  struct Interrupt {};
  std::size_t heard = 0;
  const progress_callback stop = [&](double fraction) {
    ++heard;
    if (fraction < 1) throw Interrupt{};
  };
  EXPECT_THROW((void)exact_form(c, stop), Interrupt);
  EXPECT_EQ(heard, 1u);  // stopped at the first report
  EXPECT_FALSE(c.exact.has_value());
  EXPECT_TRUE(c.convert);
  std::vector<double> fractions;
  const auto& made = std::get<BSplineSurface>(exact_form(c, [&](double f) { fractions.push_back(f); }));
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  ASSERT_FALSE(fractions.empty());
  EXPECT_EQ(fractions.back(), 1.0);
  const Construction at_once = build(spec);
  EXPECT_EQ(made.control_points().values(), std::get<BSplineSurface>(*at_once.exact).control_points().values());
}

TEST(SpecExact, TheEvaluatorIsTheCheaperOfFormulaAndExactForm) {
  // A Coons patch of four 600-point curves: 4 terms per point against a ~1200² net.
  Construction coons = build(coons_spec(600), {}, deferred);
  (void)evaluator(coons, 1000 * 1000, Sample::points);
  EXPECT_FALSE(coons.exact.has_value()) << "a million points by formula";
  (void)evaluator(coons, 1000 * 1000, Sample::derivatives);
  EXPECT_FALSE(coons.exact.has_value()) << "a mesh of a million points by formula";
  // A Gordon surface of 8 × 8 curves on shared knots: 16 terms against a 60² net.
  Construction gordon = build(network_spec(8, 60, "gordon"), {}, deferred);
  (void)evaluator(gordon, 10, Sample::points);
  EXPECT_FALSE(gordon.exact.has_value()) << "ten points: not worth a net";
  const Surface& s = evaluator(gordon, 1000 * 1000, Sample::points);
  ASSERT_TRUE(gordon.exact.has_value()) << "a million points: the exact form";
  EXPECT_EQ(&s, &std::get<BSplineSurface>(*gordon.exact));
  // Both exact: the grid of each agrees with the other to rounding.
  const auto t = linspace(0, 1, 57);
  const PointGrid a = s.evaluate(t, t), b = gordon.formula->evaluate(t, t);
  double worst = 0;
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, distance(a.values()[k], b.values()[k]));
  // Curves of unit size, ~20 terms each rounded at 1.1e-16, and the exact form's
  // sums after knot insertion: well under 1e-12.
  EXPECT_LT(worst, 1e-12);
}

// --- closed (periodic) shapes ---------------------------------------------------------

PointGrid point_grid(const json& points) {
  const PointArray a = points_from_json(points, 2);
  return PointGrid({a.shape[0], a.shape[1]}, std::vector<Vec3>(a.points.begin(), a.points.end()));
}

PointGrid3 point_grid3(const json& points) {
  const PointArray a = points_from_json(points, 3);
  return PointGrid3({a.shape[0], a.shape[1], a.shape[2]}, std::vector<Vec3>(a.points.begin(), a.points.end()));
}

TEST(SpecPeriodic, ClosedSurfaceIsTheLibrarysBitForBit) {
  // Odd and even degrees around (the even ones re-anchor their period at the first
  // parameter), with and without a closing column, every parametrization.
  for (const int q : {1, 2, 3, 4}) {
    for (const bool closing : {false, true}) {
      for (const char* param : {"chord", "centripetal", "uniform"}) {
        SCOPED_TRACE(std::to_string(q) + (closing ? " closing " : " ") + param);
        json spec = test::pipe_spec(6, 9, closing);
        spec["degree"] = {3, q};
        spec["param"] = param;
        const Construction c = build(spec);
        SurfaceInterpolationOptions o;
        o.degree_u = 3;
        o.degree_v = q;
        o.param = param == std::string("chord") ? Parametrization::chord
                  : param == std::string("uniform") ? Parametrization::uniform
                                                    : Parametrization::centripetal;
        o.periodic = {false, true};
        const SurfaceInterpolation r = interpolate_surface(point_grid(spec["points"]), o);
        const auto& s = std::get<BSplineSurface>(*c.exact);
        EXPECT_EQ(s.periodic(), (std::array<bool, 2>{false, true}));
        EXPECT_EQ(s.knots_u(), r.surface.knots_u());
        EXPECT_EQ(s.knots_v(), r.surface.knots_v());
        EXPECT_EQ(s.control_points().values(), r.surface.control_points().values());  // bit for bit
        EXPECT_EQ(s.control_points().extent(1), q % 2 == 0 ? 10u : 9u);  // the distinct points; even: one more
        ASSERT_EQ(c.data.size(), 1u);
        EXPECT_EQ(c.data[0].params[1], r.params_v);
        if (closing) {
          EXPECT_EQ(c.data[0].params[1].back(), 1.0);  // the closing column: the first, one turn on
        }
        EXPECT_EQ(c.parameters["periodic"], nlohmann::ordered_json({false, true}));
        EXPECT_TRUE(c.warnings.empty()) << c.warnings[0];
        // The data, the closing column included, to rounding of the pipe's size (~5).
        EXPECT_LT(max_error_at_data(c), 1e-13);
      }
    }
  }
}

TEST(SpecPeriodic, ClosedVolumeIsTheLibrarysBitForBit) {
  for (const bool closing : {false, true}) {
    SCOPED_TRACE(closing);
    const json spec = test::tube_spec(3, 8, 5, closing);
    const Construction c = build(spec);
    VolumeInterpolationOptions o;
    o.periodic = {false, true, false};
    const VolumeInterpolation r = interpolate_volume(point_grid3(spec["points"]), o);
    const auto& v = std::get<BSplineVolume>(*c.exact);
    EXPECT_EQ(v.periodic(), (std::array<bool, 3>{false, true, false}));
    EXPECT_EQ(v.knots_u(), r.volume.knots_u());
    EXPECT_EQ(v.knots_v(), r.volume.knots_v());
    EXPECT_EQ(v.knots_w(), r.volume.knots_w());
    EXPECT_EQ(v.control_points().values(), r.volume.control_points().values());
    EXPECT_EQ(v.control_points().extent(1), 8u);
    const auto e = max_data_error(c);
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->count, 3u * (closing ? 9u : 8u) * 5u);
    EXPECT_LT(e->relative, 1e-13);  // rounding of a few solves
  }
}

TEST(SpecPeriodic, ClosedCurveIsTheLibrarysAndAsSmoothAtTheSeamAsAnywhere) {
  std::vector<Vec3> pts;
  json list = json::array();
  for (std::size_t k = 0; k < 7; ++k) {
    const json p = test::pipe_point(0.3, k, 7);
    pts.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
    list.push_back(p);
  }
  list.push_back(list[0]);  // the closing point
  for (const int p : {2, 3, 5}) {
    SCOPED_TRACE(p);
    const BSplineCurve c = curve_from_json(json{{"interpolate", list}, {"periodic", true}, {"degree", p}});
    CurveInterpolationOptions o;
    o.degree = p;
    o.periodic = true;
    const BSplineCurve r = interpolate_curve(pts, o).curve;
    EXPECT_TRUE(c.periodic());
    EXPECT_EQ(c.knots(), r.knots());
    EXPECT_EQ(c.control_points(), r.control_points());
    EXPECT_EQ(c.domain(), std::make_pair(0.0, 1.0));
    // C^(p−1) across the seam: derivatives 0..p−1 at the end and at the start agree
    // to rounding relative to their size (a derivative of order k grows like the
    // curve's size, ~1, times the number of spans to the k).
    for (int k = 0; k < p; ++k) {
      const Vec3 a = c.derivative(0.0, k), b = c.derivative(1.0, k);
      EXPECT_LT(distance(a, b), 1e-11 * std::max(1.0, norm(a))) << "order " << k;
    }
  }
  // An open curve through the same points is not closed, nor smooth where it ends.
  const BSplineCurve open = curve_from_json(json{{"interpolate", list}});
  EXPECT_FALSE(open.periodic());
  EXPECT_GT(distance(open.derivative(0.0, 1), open.derivative(1.0, 1)), 1e-3);
}

TEST(SpecPeriodic, ClosedBsplineCurveAndSurfaceFromTheirKnots) {
  // The closed uniform cubic of four control points, and the cylinder of the docs.
  const auto c = curve_from_json(json::parse(R"({"bspline": {"degree": 3, "periodic": true,
      "knots": [-0.75, -0.5, -0.25, 0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75],
      "control_points": [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]}})"));
  EXPECT_TRUE(c.periodic());
  EXPECT_EQ(c.knots().count(), 4);
  // A uniform cubic: at a knot, (P[i-1] + 4 P[i] + P[i+1]) / 6; at 0 (knot 3) the
  // point of control point 1's neighbours 0 and 2: (1, 0, 0)/6 + 4 (0, 1, 0)/6 + (-1, 0, 0)/6.
  // Unit-sized values through a few products: 1e-15 is rounding.
  EXPECT_LT(distance(c.point(0.0), Vec3{0, 4.0 / 6, 0}), 1e-15);
  EXPECT_LT(distance(c.point(1.0), c.point(0.0)), 1e-15);
  const Construction s = build(json::parse(R"({"type": "bspline_surface", "degree": [1, 3], "periodic": [false, true],
      "knots": {"u": [0, 0, 1, 1], "v": [-0.75, -0.5, -0.25, 0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75]},
      "control_points": [[[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], [[1, 0, 2], [0, 1, 2], [-1, 0, 2], [0, -1, 2]]]})"));
  const auto& b = std::get<BSplineSurface>(*s.exact);
  EXPECT_EQ(b.periodic(), (std::array<bool, 2>{false, true}));
  for (const double u : {0.0, 0.4, 1.0}) {  // closed around v, the straight lines of a cylinder along u; rounding as above
    EXPECT_LT(distance(b.point(u, 0.0), b.point(u, 1.0)), 1e-15);
    EXPECT_LT(distance(b.point(u, 0.25), c.point(0.25) + Vec3{0, 0, 2 * u}), 1e-15);
  }
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SpecPeriodic, ClosedFormsReadBackBitForBit) {
  // What build writes for closed surfaces and volumes (odd and even degrees,
  // closed in one and in two directions) reads back to the same form.
  std::vector<json> specs;
  for (const int q : {2, 3}) {
    json s = test::pipe_spec(5, 7, true);
    s["degree"] = {2, q};
    specs.push_back(s);
  }
  json torus = test::pipe_spec(6, 8, false);
  torus["periodic"] = {true, true};  // closed both ways: the pipe's last section joined back to its first
  specs.push_back(torus);
  specs.push_back(test::tube_spec(3, 6, 4, true));
  for (const json& spec : specs) {
    const Construction a = build(spec);
    std::ostringstream text;
    write_exact_json(text, *a.exact);
    EXPECT_NE(text.str().find("\"periodic\": ["), std::string::npos);
    const Construction b = build(parse_json(text.str()));
    ASSERT_EQ(a.exact->index(), b.exact->index());
    if (const auto* sa = std::get_if<BSplineSurface>(&*a.exact)) {
      const auto& sb = std::get<BSplineSurface>(*b.exact);
      EXPECT_EQ(sa->knots_u(), sb.knots_u());
      EXPECT_EQ(sa->knots_v(), sb.knots_v());
      EXPECT_EQ(sa->control_points().values(), sb.control_points().values());
    } else {
      const auto& va = std::get<BSplineVolume>(*a.exact);
      const auto& vb = std::get<BSplineVolume>(*b.exact);
      EXPECT_EQ(va.knots_u(), vb.knots_u());
      EXPECT_EQ(va.knots_v(), vb.knots_v());
      EXPECT_EQ(va.knots_w(), vb.knots_w());
      EXPECT_EQ(va.control_points().values(), vb.control_points().values());
    }
    EXPECT_TRUE(b.warnings.empty());
  }
  // An open form is written as before: without "periodic".
  std::ostringstream open;
  write_exact_json(open, *build(small_spec()).exact);
  EXPECT_EQ(open.str().find("periodic"), std::string::npos);
}

TEST(SpecPeriodic, DataClosedInADirectionNotDeclaredPeriodicAreReported) {
  // A pipe whose sections repeat their first point, without "periodic".
  const Construction c = build(test::pipe_spec(5, 8, true, false));
  ASSERT_EQ(c.warnings.size(), 1u);
  EXPECT_NE(c.warnings[0].find("/points: the data close along v"), std::string::npos) << c.warnings[0];
  EXPECT_NE(c.warnings[0].find("\"periodic\": [false, true]"), std::string::npos) << c.warnings[0];
  ASSERT_TRUE(c.parameters.contains("notes"));
  EXPECT_NE(c.parameters["notes"][0].get<std::string>().find("close along v"), std::string::npos);
  EXPECT_EQ(c.parameters["periodic"], nlohmann::ordered_json({false, false}));
  // Closing points off by rounding (within 1e-12 of the diagonal) close the data too.
  json rounded = test::pipe_spec(5, 8, true, false);
  for (auto& row : rounded["points"]) row[8][2] = row[8][2].get<double>() * (1 + 1e-15);
  const Construction r = build(rounded);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("close along v"), std::string::npos);
  // Declared periodic, or open data: nothing to say.
  for (const json& quiet : {test::pipe_spec(5, 8, true), test::pipe_spec(5, 8, false, false), small_spec()}) {
    const Construction q = build(quiet);
    EXPECT_TRUE(q.warnings.empty()) << q.warnings[0];
    EXPECT_FALSE(q.parameters.contains("notes") &&
                 q.parameters["notes"].dump().find("is not periodic") != std::string::npos);
  }
  // Closed in one direction declared and one not: the suggestion keeps the first.
  json both = test::pipe_spec(5, 8, true);
  both["points"].push_back(both["points"][0]);  // the first section again at the end: closed along u too
  const Construction b = build(both);
  ASSERT_EQ(b.warnings.size(), 1u);
  EXPECT_NE(b.warnings[0].find("close along u"), std::string::npos) << b.warnings[0];
  EXPECT_NE(b.warnings[0].find("\"periodic\": [true, true]"), std::string::npos) << b.warnings[0];
  // A volume closed along v, not declared: named with its three directions.
  const Construction v = build(test::tube_spec(3, 6, 4, true, false));
  ASSERT_EQ(v.warnings.size(), 1u);
  EXPECT_NE(v.warnings[0].find("close along v"), std::string::npos) << v.warnings[0];
  EXPECT_NE(v.warnings[0].find("the volume meets itself"), std::string::npos) << v.warnings[0];
  EXPECT_NE(v.warnings[0].find("\"periodic\": [false, true, false]"), std::string::npos) << v.warnings[0];
}

TEST(SpecPeriodic, ErrorsNameThePlace) {
  const json pipe = test::pipe_spec(5, 6, true);
  const auto with_periodic = [](json s, const json& periodic) {
    s["periodic"] = periodic;
    return s;
  };
  const auto with = [&](const std::function<void(json&)>& change) {
    json s = pipe;
    change(s);
    return s;
  };
  EXPECT_ERRC((void)build(with([](json& s) { s["periodic"] = {true}; })), wrong_type,
              "/periodic: expected 2 booleans [u, v], one per direction, got 1");
  EXPECT_ERRC((void)build(with([](json& s) { s["periodic"] = true; })), wrong_type,
              "/periodic: expected an array of 2 booleans [u, v], one per direction, got a boolean");
  EXPECT_ERRC((void)build(with([](json& s) { s["periodic"] = {false, 1}; })), wrong_type,
              "/periodic/1: expected true or false (is v closed?), got a number");
  EXPECT_ERRC((void)build(with_periodic(test::tube_spec(3, 4, 3, false), {false, true})), wrong_type,
              "/periodic: expected 3 booleans [u, v, w], one per direction, got 2");
  // Too few distinct points around for the degree: 3 after the closing one is left out.
  EXPECT_ERRC((void)build(with([](json& s) { s["points"] = test::pipe_points(5, 3, true); s["degree"] = 3; })), too_few_points,
              "/degree: degree 3 around v (closed) needs at least 4 distinct points, /points has 4 (shape 5x4), the last "
              "repeating the first");
  // A closing column off by more than rounding, less than a chord: a kink at the seam.
  EXPECT_ERRC((void)build(with([](json& s) { s["points"][2][6][1] = s["points"][2][6][1].get<double>() + 1e-9; })),
              closing_gap, "/points: point [2][6], the last along v,");
  EXPECT_ERRC((void)build(json::parse(R"({"type": "bspline_surface", "npz": "x.npz", "periodic": [false, true]})")), wrong_type,
              "/npz: give either \"npz\" or \"periodic\"");
  // A periodic direction whose knots are clamped.
  EXPECT_ERRC((void)build(json::parse(R"({"type": "bspline_surface", "degree": 1, "periodic": [false, true],
      "knots": {"u": [0, 0, 1, 1], "v": [0, 0, 1, 1]}, "control_points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]]})")),
              invalid_knots, "/knots/v:");

  // Curves: the same rules, and no end derivatives on a closed curve.
  const json ring = json::parse(R"([[1,0,0], [0,1,0], [-1,0,0], [0,-1,0], [1,0,0]])");
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", ring}, {"periodic", "yes"}}, {}, "/c"), wrong_type,
              "/c/periodic: expected true or false, got a string");
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", ring}, {"periodic", true}, {"degree", 4}}, {}, "/c"), too_few_points,
              "/c/degree: degree 4 of a closed curve needs at least 5 distinct points, /c/interpolate has 4 (its last point "
              "repeats the first and is left out)");
  json near = ring;
  near[4][1] = 1e-9;
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", near}, {"periodic", true}}, {}, "/c"), closing_gap,
              "/c/interpolate: point 4 = ");
  json twice = ring;
  twice.push_back(ring[0]);
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", twice}, {"periodic", true}}, {}, "/c"), zero_chord,
              "/c/interpolate/4: point 4 (1, 0, 0) coincides with point 0 (the closing chord of a closed curve has zero length)");
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", ring}, {"periodic", true}, {"end_derivative", {0, 1, 0}}}, {}, "/c"),
              wrong_type, "/c/end_derivative: a closed curve (\"periodic\": true) has no ends");
  EXPECT_ERRC((void)curve_from_json(json::parse(R"({"bspline": {"degree": 1, "periodic": true, "knots": [-0.5, 0, 0.5, 1, 1.5],
      "control_points": [[0,0,0], [1,0,0], [2,0,0]]}})"), {}, "/c"),
              size_mismatch, "/c/bspline/control_points: 5 periodic knots of degree 1 need 2 control points, got 3");
}

TEST(SpecPeriodic, RuledBetweenClosedCurvesIsATube) {
  const json c0 = json::parse(R"({"interpolate": [[1,0,0], [0,1,0], [-1,0,0], [0,-1,0], [1,0,0]], "periodic": true})");
  const json c1 = json::parse(R"({"interpolate": [[2,0,1], [0,2,1], [-2,0,1], [0,-2,1]], "periodic": true})");
  const Construction c = build(json{{"type", "ruled"}, {"curves", {c0, c1}}});
  const auto& s = std::get<BSplineSurface>(*c.exact);
  EXPECT_EQ(s.periodic(), (std::array<bool, 2>{true, false}));
  const BSplineCurve a = curve_from_json(c0), b = curve_from_json(c1);
  for (const double u : {0.0, 0.3, 0.75, 1.0}) {
    // Straight lines between the curves' points at u, closed across u = 0 and 1;
    // to rounding of the unit-sized curves.
    EXPECT_LT(distance(s.point(u, 0.0), a.point(u)), 1e-14);
    EXPECT_LT(distance(s.point(u, 0.4), 0.6 * a.point(u) + 0.4 * b.point(u)), 1e-14);
  }
  EXPECT_LT(distance(s.derivative(0.0, 0.5, 2, 0), s.derivative(1.0, 0.5, 2, 0)), 1e-12);  // C2 across the seam
  // A closed and an open curve make no ruled surface; a closed curve no side of a Coons patch.
  EXPECT_ERRC((void)build(json{{"type", "ruled"}, {"curves", {c0, test::line_curve({0, 0, 1}, {1, 0, 1})}}}), invalid_knots,
              "/curves/1: the curve is open and /curves/0 is closed");
  json coons = test::square_coons();
  coons["boundary"]["v1"] = c1;
  EXPECT_ERRC((void)build(coons), invalid_knots, "/boundary/v1: a closed curve (\"periodic\": true) cannot be a side");
}

TEST(SpecCurve, EndDerivativesAreTakenByTheInterpolation) {
  const json pts = json::parse(R"([[0,0,0], [1,1,0], [2,0,0]])");
  const BSplineCurve c = curve_from_json(json{{"interpolate", pts}, {"start_derivative", {0, 4, 0}}, {"end_derivative", {4, 0, 0}}});
  // Two conditions more: cubic (min(3, points + derivatives − 1)), five control points.
  // The derivatives and the end point to rounding: derivatives of size 4 come out of
  // one small solve, the end point is the last control point.
  EXPECT_EQ(c.degree(), 3);
  EXPECT_EQ(c.control_points().size(), 5u);
  EXPECT_LT(distance(c.derivative(0.0, 1), Vec3{0, 4, 0}), 1e-13);
  EXPECT_LT(distance(c.derivative(1.0, 1), Vec3{4, 0, 0}), 1e-13);
  EXPECT_LT(distance(c.point(1.0), Vec3{2, 0, 0}), 1e-15);
  // A degree the points alone could not carry, with the derivatives they can.
  EXPECT_EQ(curve_from_json(json{{"interpolate", pts}, {"degree", 4}, {"start_derivative", {0, 4, 0}},
                                 {"end_derivative", {4, 0, 0}}}).degree(), 4);
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", pts}, {"degree", 4}, {"start_derivative", {0, 4, 0}}}, {}, "/c"),
              too_few_points, "/c/degree: degree 4 needs at least 4 points besides its 1 end derivative, /c/interpolate has 3");
  EXPECT_ERRC((void)curve_from_json(json{{"interpolate", pts}, {"start_derivative", {0, 4}}}, {}, "/c"), wrong_type,
              "/c/start_derivative: expected a point [x, y, z], got 2 numbers");
}

}  // namespace
}  // namespace interpatch::io
