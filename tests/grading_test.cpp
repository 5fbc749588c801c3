// Graded sampling: the duct of examples/duct_graded.json meets its first cells and
// grows smoothly, measured on the whole mesh here; ratios, both ends, surfaces, the
// command line's --res, and every refusal.

#include "interpatch/grading.hpp"

#include <cmath>
#include <fstream>

#include "interpatch/evaluate.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/patches.hpp"
#include "interpatch/volume_patches.hpp"
#include "test_util.hpp"

#ifndef INTERPATCH_EXAMPLES
#error "INTERPATCH_EXAMPLES must name the examples directory"
#endif

namespace interpatch {
namespace {

io::Construction example(const char* name) {
  const std::string path = std::string(INTERPATCH_EXAMPLES) + "/" + name;
  return io::build(io::read_json_file(path), std::filesystem::path(path).parent_path());
}

// Cell lengths along direction d of a point grid, line by line.
struct Cells {
  double longest_first = 0, shortest_first = 1e300, longest_last = 0, growth = 1;
};

Cells cells_of(const PointGrid3& x, std::size_t d) {
  const auto n = x.shape();
  Cells c;
  const std::size_t a = (d + 1) % 3, b = (d + 2) % 3;
  for (std::size_t i = 0; i < n[a]; ++i)
    for (std::size_t j = 0; j < n[b]; ++j) {
      auto at = [&](std::size_t k) {
        std::size_t idx[3];
        idx[d] = k, idx[a] = i, idx[b] = j;
        return x(idx[0], idx[1], idx[2]);
      };
      std::vector<double> h;
      for (std::size_t k = 1; k < n[d]; ++k) h.push_back(distance(at(k), at(k - 1)));
      c.longest_first = std::max(c.longest_first, h.front());
      c.shortest_first = std::min(c.shortest_first, h.front());
      c.longest_last = std::max(c.longest_last, h.back());
      for (std::size_t k = 1; k < h.size(); ++k) c.growth = std::max({c.growth, h[k] / h[k - 1], h[k - 1] / h[k]});
    }
  return c;
}

TEST(Grading, DuctMeetsItsFirstCellsEverywhereAndGrowsSmoothly) {
  io::Construction c = example("duct_graded.json");
  const io::Resolution res = io::default_resolution(c);
  EXPECT_EQ(res.nu, 41u);
  EXPECT_EQ(res.nv, 41u);
  EXPECT_EQ(res.nw, 61u);
  const GradedParameters g = io::sample_parameters(c, res);
  // Every node on the exact volume: the mesh is the exact form evaluated at the nodes.
  const auto& exact = std::get<BSplineVolume>(io::exact_form(c));
  const PointGrid3 x = exact.evaluate(g.params[0], g.params[1], g.params[2]);
  const Cells u = cells_of(x, 0), v = cells_of(x, 1), w = cells_of(x, 2);
  EXPECT_LE(u.longest_first, 1e-3);
  EXPECT_GE(u.longest_first, 0.9e-3);
  EXPECT_GT(u.shortest_first, 0.9e-3);  // the inner wall's lines differ little
  EXPECT_LE(u.growth, 1.3);
  EXPECT_LE(v.longest_first, 2e-3);
  EXPECT_LE(v.longest_last, 2e-3);
  EXPECT_GE(v.longest_first, 2e-3 * (1 - 1e-9));
  EXPECT_GE(v.longest_last, 2e-3 * (1 - 1e-9));
  EXPECT_LE(v.growth, 1.3);
  // w has a count alone: even parameter steps.
  for (std::size_t k = 0; k < g.params[2].size(); ++k) EXPECT_EQ(g.params[2][k], static_cast<double>(k) / 60.0);
  // The report is what the mesh shows.
  EXPECT_NEAR(g.report[0].first, u.longest_first, 1e-15);
  EXPECT_NEAR(g.report[1].last, v.longest_last, 1e-15);
  EXPECT_NEAR(g.report[0].growth, u.growth, 1e-12);
  EXPECT_NEAR(g.report[2].first, w.longest_first, 1e-15);
}

// A straight box, where every line has even speed: the cells are the distribution's.
TEST(Grading, RatioAndBothEndsOnABox) {
  const BlendedVolume box = trilinear({Vec3{0, 0, 0}, {0, 0, 3}, {0, 2, 0}, {0, 2, 3}, {1, 0, 0}, {1, 0, 3}, {1, 2, 0}, {1, 2, 3}});
  Sampling s;
  s[0] = {.count = 11, .ratio = 4};
  s[1] = {.count = 31, .first = 0.01, .last = 0.05};
  s[2] = {.count = 5};
  const GradedParameters g = graded_parameters(box, s);
  const auto& u = g.params[0];
  const double first = u[1] - u[0], last = u[10] - u[9];
  EXPECT_NEAR(last / first, 4, 1e-9);
  const double r = std::pow(4.0, 1.0 / 9);  // 10 cells: 9 steps from the first to the last
  for (std::size_t k = 2; k < u.size(); ++k) EXPECT_NEAR((u[k] - u[k - 1]) / (u[k - 1] - u[k - 2]), r, 1e-9);
  const auto& v = g.params[1];
  EXPECT_LE(2 * (v[1] - v[0]), 0.01);
  EXPECT_NEAR(2 * (v[1] - v[0]), 0.01, 1e-11);
  EXPECT_LE(2 * (v[30] - v[29]), 0.05);
  EXPECT_NEAR(2 * (v[30] - v[29]), 0.05, 1e-11);
  EXPECT_LE(g.report[1].growth, 1.3);
  EXPECT_EQ(g.params[2], linspace(0, 1, 5));
  // A ratio below 1 shrinks the cells.
  s[0].ratio = 0.25;
  const auto shrinking = graded_parameters(box, s).params[0];
  EXPECT_NEAR((shrinking[10] - shrinking[9]) / (shrinking[1] - shrinking[0]), 0.25, 1e-9);
}

TEST(Grading, SurfaceLastCellAndTheCountThatWouldDo) {
  const BlendedSurface sheet = bilinear({0, 0, 0}, {0, 5, 0}, {2, 0, 0}, {2, 5, 0});
  Sampling s;
  s[0] = {.count = 9, .last = 0.01};
  s[1] = {.count = 3};
  try {
    (void)graded_parameters(sheet, s);
    FAIL() << "9 nodes cannot grow from 0.01 to fill 2 within 1.3";
  } catch (const error& e) {
    EXPECT_EQ(e.code(), errc::too_few_points);
    EXPECT_NE(std::string(e.what()).find("sampling u: count 9 would grow by"), std::string::npos) << e.what();
    const std::string m = e.what();
    const std::size_t would = std::stoul(m.substr(m.find("; count ") + 8));
    // The count named does, and one fewer does not.
    s[0].count = would;
    const GradedParameters g = graded_parameters(sheet, s);
    EXPECT_LE(g.report[0].last, 0.01);
    EXPECT_GE(g.report[0].last, 0.01 * (1 - 1e-9));
    EXPECT_LE(g.report[0].growth, 1.3 * (1 + 1e-9));
    s[0].count = would - 1;
    EXPECT_ERRC((void)graded_parameters(sheet, s), too_few_points, "would grow by");
  }
}

TEST(Grading, Refusals) {
  const BlendedSurface sheet = bilinear({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0});
  auto refused = [&](Grading g, errc code, const char* says) {
    Sampling s;
    s[0] = g;
    s[1] = {.count = 2};
    try {
      (void)graded_parameters(sheet, s);
      ADD_FAILURE() << "accepted: " << says;
    } catch (const error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused({.count = 1}, errc::too_few_points, "count 1");
  refused({.count = 5, .first = -1}, errc::invalid_grading, "first is -1");
  refused({.count = 5, .ratio = std::nan("")}, errc::invalid_grading, "ratio is nan");
  refused({.count = 5, .first = 0.1, .max_growth = 1}, errc::invalid_grading, "max_growth is 1");
  refused({.count = 5, .ratio = 2, .last = 0.1}, errc::invalid_grading, "ratio is given with first or last");
  refused({.count = 5, .first = 3}, errc::invalid_grading, "first 3 is longer than the direction");
  refused({.count = 50, .first = 0.6, .last = 0.6, .max_growth = 100}, errc::invalid_grading, "overlap");
  // Finer than doubles can place: no parameter step above 0 gives a cell this short.
  refused({.count = 5, .first = 1e-300, .max_growth = 1e300}, errc::invalid_grading,
          "first 1e-300 is shorter than rounding allows");
}

TEST(Grading, SpecSamplingIsReadAndCheckedAsDocumented) {
  auto build = [](const char* sampling) {
    return io::build(io::parse_json(std::string(R"({"type": "bilinear", "p00": [0,0,0], "p01": [0,1,0],
        "p10": [1,0,0], "p11": [1,1,0], "sampling": )") + sampling + "}"));
  };
  const io::Construction c = build(R"({"u": {"count": 17, "first": 0.01}})");
  ASSERT_TRUE(c.sampling);
  EXPECT_EQ((*c.sampling)[0].count, 17u);
  const io::Resolution res = io::default_resolution(c);
  EXPECT_EQ(res.nu, 17u);
  EXPECT_EQ(res.nv, 64u);  // the kind's default where the spec gives no count
  // --res overrides the count, the grading stays.
  const GradedParameters g = io::sample_parameters(c, {33, 5, 0});
  EXPECT_EQ(g.params[0].size(), 33u);
  EXPECT_NEAR(g.params[0][1], 0.01, 1e-12);
  EXPECT_ERRC((void)build(R"({"w": {"count": 3}})"), invalid_grading, "/sampling/w: a surface has no direction \"w\"");
  EXPECT_ERRC((void)build(R"({"u": {"count": 1}})"), too_few_points, "/sampling/u/count: 1");
  EXPECT_ERRC((void)build(R"({"u": {"first": 0}})"), invalid_grading, "/sampling/u/first: 0");
  EXPECT_ERRC((void)build(R"({"u": {"max_growth": 0.5}})"), invalid_grading, "/sampling/u/max_growth: 0.5");
  EXPECT_ERRC((void)build(R"({"u": {"ratio": 2, "first": 0.1}})"), invalid_grading, "ratio is given with first");
  EXPECT_ERRC((void)build(R"({"u": 3})"), wrong_type, "/sampling/u");
  EXPECT_ERRC((void)build(R"([1])"), wrong_type, "/sampling");
  // An unknown field of a direction is a warning, as everywhere.
  const io::Construction typo = build(R"({"u": {"count": 5, "frist": 0.1}})");
  ASSERT_EQ(typo.warnings.size(), 1u);
  EXPECT_NE(typo.warnings[0].find("/sampling/u/frist: unknown field"), std::string::npos) << typo.warnings[0];
}

}  // namespace
}  // namespace interpatch
