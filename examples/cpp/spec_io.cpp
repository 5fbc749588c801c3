// Specs (docs/spec-format.md) read and built in memory, and the exact form and the
// `interpatch info` description written as JSON: the examples of io/spec.hpp and
// io/json_out.hpp, each run and its comments checked. No files are written.
// Links interpatch::interpatch (the io library).

#include <cstdio>
#include <iostream>
#include <sstream>
#include <variant>
#include <vector>

#include <interpatch/interpatch.hpp>

#include "check.hpp"

namespace {

void parsing() {
  auto j = interpatch::io::parse_json(R"({"type": "interpolate"})", "spec.json");
  example::expect(j["type"] == "interpolate", "parse_json reads the object");
  // NaN is refused as a non-finite value, with the place named.
  try {
    (void)interpatch::io::parse_json("{\"x\": NaN}", "spec.json");
    example::expect(false, "parse_json refuses NaN");
  } catch (const interpatch::error& e) {
    example::expect(e.code() == interpatch::errc::not_finite, "NaN is refused as not_finite");
    std::printf("refused: %s\n", e.what());
  }
}

void building() {
  auto spec = nlohmann::json::parse(R"({"type": "interpolate", "degree": 1,
      "points": [[[0,0,0],[0,1,0]], [[1,0,0],[1,1,1]]]})");
  interpatch::io::Construction c = interpatch::io::build(spec);
  const auto& s = std::get<interpatch::BSplineSurface>(*c.exact);  // bilinear, 2 × 2 control points
  example::expect(s.degree_u() == 1 && s.degree_v() == 1, "degree 1: bilinear");
  example::expect(s.control_points().shape() == interpatch::PointGrid::shape_type{2, 2}, "2 × 2 control points");
  example::expect_near(s.point(0.5, 0.5), {0.5, 0.5, 0.25}, "the bilinear surface of the four points");

  std::ostringstream text;
  interpatch::io::write_exact_json(text, *c.exact);  // a "bspline_surface" or "bspline_volume" spec
  auto again = interpatch::io::build(interpatch::io::parse_json(text.str()));  // the same form
  example::expect(again.type == "bspline_surface", "write_exact_json writes a bspline_surface spec");
  const auto& t = std::get<interpatch::BSplineSurface>(*again.exact);
  example::expect(t.control_points().values() == s.control_points().values() && t.knots_u() == s.knots_u() &&
                      t.knots_v() == s.knots_v(),
                  "the spec builds back to the same knots and control points");
  std::printf("the exact form as a spec:\n%s\n", text.str().c_str());

  std::cout << interpatch::io::pretty_json(interpatch::io::info_json(c));
  const auto info = interpatch::io::info_json(c);
  example::expect(info["kind"] == "surface" && info["degree"] == nlohmann::json::array({1, 1}),
                  "info_json: kind and degree");
  example::expect(info["max_data_error"]["points"] == 4, "info_json checks the 4 data points");
  example::expect(info["max_data_error"]["absolute"].get<double>() <= 1e-15,
                  "info_json: the surface passes through its data");
}

void sampling() {
  auto spec = interpatch::io::parse_json(R"({"type": "coons", "boundary": {
      "v0": {"line": [[0,0,0], [1,0,0]]}, "v1": {"line": [[0,1,0], [1,1,1]]},
      "u0": {"line": [[0,0,0], [0,1,0]]}, "u1": {"line": [[1,0,0], [1,1,1]]}}})");
  interpatch::io::BuildOptions lazy;
  lazy.defer_exact = true;
  interpatch::io::Construction c = interpatch::io::build(spec, {}, lazy);  // c.exact is empty
  const interpatch::Surface& s = interpatch::io::evaluator(c, 10000, interpatch::io::Sample::points);
  interpatch::Vec3 p = s.point(0.5, 0.5);  // (0.5, 0.5, 0.25), by the formula
  const auto& e = std::get<interpatch::BSplineSurface>(interpatch::io::exact_form(c));  // made now: 2 × 2
  // The evaluator was the formula: the exact form did not exist until exact_form().
  example::expect(&s == c.formula.get(), "evaluated by the formula");
  example::expect_near(p, {0.5, 0.5, 0.25}, "(0.5, 0.5, 0.25)");
  example::expect(c.exact.has_value() && &e == &std::get<interpatch::BSplineSurface>(*c.exact), "made now");
  example::expect(e.control_points().shape() == interpatch::PointGrid::shape_type{2, 2}, "2 × 2 control points");
  example::expect_near(e.point(0.5, 0.5), p, "the exact form gives the same point");
}

void point_arrays() {
  auto a = interpatch::io::points_from_json(nlohmann::json::parse("[[0,0,0],[1,0,0]]"), 1);
  // a.shape == {2}
  example::expect(a.shape == std::vector<std::size_t>{2}, "a.shape == {2}");
  example::expect(a.points[1] == interpatch::Vec3{1, 0, 0}, "the second point is (1, 0, 0)");
  // A ragged grid is refused with the place named.
  try {
    (void)interpatch::io::points_from_json(nlohmann::json::parse("[[[0,0,0],[1,0,0]], [[0,1,0]]]"), 2, {}, "/points");
    example::expect(false, "points_from_json refuses a ragged grid");
  } catch (const interpatch::error& e) {
    example::expect(e.code() == interpatch::errc::ragged_grid, "a ragged grid is refused as ragged_grid");
    std::printf("refused: %s\n", e.what());
  }
}

void curves() {
  auto c = interpatch::io::curve_from_json(nlohmann::json::parse(R"({"line": [[0,0,0], [2,0,0]]})"));
  // c.point(0.5) == (1, 0, 0)
  example::expect_near(c.point(0.5), {1, 0, 0}, "c.point(0.5) == (1, 0, 0)");
  // Every form comes back over [0, 1].
  auto h = interpatch::io::curve_from_json(
      nlohmann::json::parse(R"({"hermite": {"points": [[0,0,0], [1,1,0], [3,0,0]], "params": [0, 2, 5]}})"));
  example::expect(h.domain() == std::pair<double, double>{0, 1}, "curve_from_json maps the domain onto [0, 1]");
  example::expect_near(h.point(0.4), {1, 1, 0}, "the middle point at its parameter 2 of [0, 5]");
  std::printf("line as a curve: C(0.5) = %s\n", example::str(c.point(0.5)).c_str());
}

// A curve spec at the top level: the curve, and its data with their parameters.
void curve_specs() {
  auto spec = interpatch::io::parse_json(R"({"interpolate": [[0,0,0], [1,1,0], [2,0,0]], "degree": 2})");
  interpatch::io::CurveConstruction c = interpatch::io::build_curve(spec);
  interpatch::Vec3 p = c.curve.point(c.data[0].params[0][1]);  // (1, 1, 0) up to rounding
  example::expect_near(p, {1, 1, 0}, "the curve passes its middle point at its parameter");
  // Its exact form as a {"bspline": ...} curve spec.
  std::ostringstream text;
  interpatch::io::write_exact_json(text, interpatch::line({0, 0, 0}, {1, 0, 0}));
  example::expect(text.str().find("\"bspline\"") != std::string::npos, "a curve's exact form is a bspline curve spec");
  interpatch::io::write_exact_json(std::cout, interpatch::line({0, 0, 0}, {1, 0, 0}));
  std::printf("\n");
}

}  // namespace

int main() {
  return example::run("spec_io", [] {
    parsing();
    building();
    sampling();
    point_arrays();
    curves();
    curve_specs();
  });
}
