#include "interpatch/io/step.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <csignal>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {

namespace fs = std::filesystem;

std::string step_text(const ExactForm& f) {
  std::ostringstream os;
  write_step(os, f, {.name = "part", .time_stamp = "2024-05-01T12:00:00"});
  return os.str();
}

// The DATA section's entities: number -> text after "#n=", without the ';'.
// Entities span lines until their ';' (B-spline nets are broken after each row).
std::map<int, std::string> entities(const std::string& text) {
  std::map<int, std::string> out;
  const auto data = text.find("DATA;\n");
  EXPECT_NE(data, std::string::npos);
  std::size_t at = data + 6;
  while (text.compare(at, 7, "ENDSEC;") != 0) {
    EXPECT_EQ(text[at], '#') << text.substr(at, 40);
    const auto eq = text.find('=', at), end = text.find(";\n", at);
    out[std::stoi(text.substr(at + 1, eq - at - 1))] = text.substr(eq + 1, end - eq - 1);
    at = end + 2;
  }
  return out;
}

std::size_t count_of(const std::map<int, std::string>& e, const std::string& prefix) {
  return static_cast<std::size_t>(
      std::count_if(e.begin(), e.end(), [&](const auto& kv) { return kv.second.rfind(prefix, 0) == 0; }));
}

// The entity numbers an entity refers to (#n).
std::vector<int> references(const std::string& body) {
  std::vector<int> out;
  for (std::size_t at = body.find('#'); at != std::string::npos; at = body.find('#', at + 1)) {
    int v = 0;
    const auto r = std::from_chars(body.data() + at + 1, body.data() + body.size(), v);
    EXPECT_NE(r.ptr, body.data() + at + 1) << body;
    out.push_back(v);
  }
  return out;
}

// The names of a complex instance's partial entities, "(A(...) B(...) ...)", in order.
std::vector<std::string> partial_entities(const std::string& body) {
  std::vector<std::string> names;
  int depth = 0;
  std::string word;
  for (const char c : body) {
    if (c == '(') {
      if (depth == 1) names.push_back(word);
      ++depth;
    } else if (c == ')') {
      --depth;
    }
    if (depth == 1 && (std::isupper(static_cast<unsigned char>(c)) || c == '_')) word += c;
    else if (depth == 1) word.clear();
  }
  return names;
}

// A real as Part 21 writes it: optional sign, digits, a decimal point, digits,
// optional exponent E with optional sign and digits.
bool is_step_real(const std::string& t) {
  std::size_t i = t[0] == '-' ? 1 : 0;
  const auto digits = [&] {
    const std::size_t from = i;
    while (i < t.size() && std::isdigit(static_cast<unsigned char>(t[i]))) ++i;
    return i > from;
  };
  if (!digits() || i == t.size() || t[i++] != '.') return false;
  digits();
  if (i == t.size()) return true;
  if (t[i++] != 'E') return false;
  if (i < t.size() && (t[i] == '-' || t[i] == '+')) ++i;
  return digits() && i == t.size();
}

// How many entities start with each prefix.
void expect_counts(const std::map<int, std::string>& e, const std::map<std::string, std::size_t>& expected) {
  for (const auto& [prefix, n] : expected) EXPECT_EQ(count_of(e, prefix), n) << prefix;
}

BSplineSurface bilinear_patch() {
  PointGrid cp({2, 2});
  cp(0, 0) = {0, 0, 0};
  cp(1, 0) = {1, 0, 0};
  cp(0, 1) = {0, 1, 0};
  cp(1, 1) = {1, 1, 1};
  return BSplineSurface(KnotVector::bezier(1), KnotVector::bezier(1), cp);
}

BSplineVolume unit_cube() {
  const KnotVector lin(1, {0, 0, 1, 1});
  PointGrid3 cp({2, 2, 2});
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) cp(i, j, k) = {double(i), double(j), double(k)};
  return BSplineVolume(lin, lin, lin, cp);
}

TEST(Step, HeaderAndSectionsFollowPart21) {
  const std::string t = step_text(bilinear_patch());
  EXPECT_EQ(t.rfind("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(", 0), 0u) << t.substr(0, 80);
  EXPECT_NE(t.find("FILE_NAME('part','2024-05-01T12:00:00',"), std::string::npos);
  EXPECT_NE(t.find("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"), std::string::npos);
  EXPECT_TRUE(t.ends_with("ENDSEC;\nEND-ISO-10303-21;\n"));
  // Millimetres, and the product a CAD system imports.
  EXPECT_NE(t.find("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.))"), std::string::npos);
  EXPECT_NE(t.find("PRODUCT('part','part','',("), std::string::npos);
  // A fixed time stamp makes the output reproducible.
  EXPECT_EQ(t, step_text(bilinear_patch()));
}

TEST(Step, EntitiesAreNumberedInOrderAndReferOnlyBackwards) {
  for (const ExactForm& f : {ExactForm(bilinear_patch()), ExactForm(unit_cube())}) {
    const auto e = entities(step_text(f));
    int expected = 1;
    for (const auto& [n, body] : e) {
      EXPECT_EQ(n, expected++);
      for (const int target : references(body)) {
        EXPECT_LT(target, n) << "#" << n << "=" << body;
        EXPECT_GE(target, 1);
      }
    }
  }
}

TEST(Step, SurfaceIsOneFaceBoundedByItsFourEdges) {
  const auto e = entities(step_text(bilinear_patch()));
  expect_counts(e, {{"B_SPLINE_SURFACE_WITH_KNOTS('',1,1,", 1}, {"ADVANCED_FACE(", 1}, {"VERTEX_POINT(", 4},
                    {"EDGE_CURVE(", 4}, {"PCURVE(", 4}, {"ORIENTED_EDGE(", 4}, {"OPEN_SHELL(", 1},
                    {"MANIFOLD_SURFACE_SHAPE_REPRESENTATION(", 1}, {"MANIFOLD_SOLID_BREP(", 0}});
  // Corner control points are the surface's corners: only the net's four points
  // and the placement's origin are CARTESIAN_POINTs in 3D.
  std::size_t points3d = 0;
  for (const auto& [n, body] : e)
    if (body.rfind("CARTESIAN_POINT('',(", 0) == 0 && std::count(body.begin(), body.end(), ',') == 3) ++points3d;
  EXPECT_EQ(points3d, 5u);
}

// A cone: its u = 0 row is the apex (a pole) and its v = 0 and v = 1 columns are
// the same line (a seam). The loop leaves the pole out and runs the seam twice.
TEST(Step, PoleHasNoEdgeAndSeamIsOneEdgeUsedTwice) {
  PointGrid cp({2, 5});
  const Vec3 ring[5] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 0, 0}};
  for (int j = 0; j < 5; ++j) {
    cp(0, j) = {0, 0, 1};
    cp(1, j) = ring[j];
  }
  const BSplineSurface cone(KnotVector::bezier(1), KnotVector(1, {0, 0, 0.25, 0.5, 0.75, 1, 1}), cp);
  const auto e = entities(step_text(cone));
  expect_counts(e, {{"VERTEX_POINT(", 2}, {"EDGE_CURVE(", 2}, {"SEAM_CURVE(", 1}, {"ORIENTED_EDGE(", 3},
                    {"B_SPLINE_SURFACE_WITH_KNOTS('',1,1,", 1}});
  for (const auto& [n, body] : e) {
    // Closed in v (the seam), not in u.
    if (body.rfind("B_SPLINE_SURFACE_WITH_KNOTS", 0) == 0) {
      EXPECT_NE(body.find(".UNSPECIFIED.,.F.,.T.,.F."), std::string::npos) << body;
    }
  }
}

TEST(Step, VolumeIsAClosedShellWithEveryEdgeRunBothWays) {
  const auto e = entities(step_text(unit_cube()));
  expect_counts(e, {{"ADVANCED_FACE(", 6}, {"EDGE_CURVE(", 12}, {"VERTEX_POINT(", 8}, {"CLOSED_SHELL(", 1},
                    {"MANIFOLD_SOLID_BREP(", 1}, {"ADVANCED_BREP_SHAPE_REPRESENTATION(", 1}});
  std::map<std::string, std::multiset<std::string>> uses;  // edge -> orientations
  const std::string head = "ORIENTED_EDGE('',*,*,";
  for (const auto& [n, body] : e) {
    if (body.rfind(head, 0) != 0) continue;
    const auto comma = body.find(',', head.size());
    uses[body.substr(head.size(), comma - head.size())].insert(body.substr(comma + 1, 3));
  }
  ASSERT_EQ(uses.size(), 12u);
  for (const auto& [edge, o] : uses) EXPECT_EQ(o, (std::multiset<std::string>{".F.", ".T."})) << edge;
}

TEST(Step, RationalSurfaceIsTheComplexEntityInAlphabeticalOrder) {
  PointGrid cp({3, 2});
  Grid<double, 2> w({3, 2}, 1.0);
  cp(0, 0) = {1, 0, 0}, cp(1, 0) = {1, 1, 0}, cp(2, 0) = {0, 1, 0};
  for (int i = 0; i < 3; ++i) cp(i, 1) = cp(i, 0) + Vec3{0, 0, 1};
  w(1, 0) = w(1, 1) = std::sqrt(0.5);
  const BSplineSurface s(KnotVector(2, {0, 0, 0, 1, 1, 1}), KnotVector::bezier(1), cp, w);
  const auto e = entities(step_text(s));
  std::string surface;
  for (const auto& [n, body] : e)
    if (body.find("RATIONAL_B_SPLINE_SURFACE") != std::string::npos) surface = body;
  ASSERT_FALSE(surface.empty());
  EXPECT_EQ(partial_entities(surface), (std::vector<std::string>{"BOUNDED_SURFACE", "B_SPLINE_SURFACE", "B_SPLINE_SURFACE_WITH_KNOTS",
                                             "GEOMETRIC_REPRESENTATION_ITEM", "RATIONAL_B_SPLINE_SURFACE",
                                             "REPRESENTATION_ITEM", "SURFACE"}));
  EXPECT_NE(surface.find("RATIONAL_B_SPLINE_SURFACE(((1.,1.),\n  (0.7071067811865476,0.7071067811865476),\n  (1.,1.)))"),
            std::string::npos)
      << surface;
  // Its four boundary curves are rational too, with the weights of their rows.
  EXPECT_EQ(count_of(e, "(BOUNDED_CURVE() B_SPLINE_CURVE("), 4u);
  EXPECT_EQ(count_of(e, "B_SPLINE_CURVE_WITH_KNOTS("), 0u);
  std::size_t arcs = 0;  // the two quarter circles, v = 0 and v = 1
  for (const auto& [n, body] : e) arcs += body.find("RATIONAL_B_SPLINE_CURVE((1.,0.7071067811865476,1.))") != std::string::npos;
  EXPECT_EQ(arcs, 2u);
}

// Every real is written as Part 21 wants it (a decimal point, exponent E) and
// reads back to the very same double.
TEST(Step, NumbersRoundTripExactly) {
  const double awkward[] = {0.1, 1.0 / 3.0, -2.5e17, 1e-300, M_PI, -0.0, 123456789.0, 5e-324, 6.02214076e23};
  PointGrid cp({3, 3});
  std::set<double> written;
  for (std::size_t i = 0; i < 9; ++i) {
    cp(i / 3, i % 3) = {awkward[i], awkward[(i + 1) % 9], awkward[(i + 4) % 9]};
    written.insert({awkward[i], awkward[(i + 1) % 9], awkward[(i + 4) % 9]});
  }
  const BSplineSurface s(KnotVector(2, {0, 0, 0, 1, 1, 1}), KnotVector(2, {0, 0, 0, 1, 1, 1}), cp);
  const auto e = entities(step_text(s));
  std::set<double> read;
  for (const auto& [n, body] : e) {
    if (body.rfind("CARTESIAN_POINT('',(", 0) != 0 || std::count(body.begin(), body.end(), ',') != 3) continue;
    const std::string list = body.substr(20, body.size() - 22);
    std::stringstream ss(list);
    for (std::string tok; std::getline(ss, tok, ',');) {
      EXPECT_TRUE(is_step_real(tok)) << tok;
      double v = 0;
      const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      EXPECT_EQ(r.ptr, tok.data() + tok.size()) << tok;
      read.insert(v);
    }
  }
  read.erase(0.0);  // the placement's origin
  written.erase(0.0);
  EXPECT_EQ(read, written);
}

TEST(Step, AFailedWriteLeavesTheGoodFileAndNothingElse) {
  test::TempDir dir;
  std::ofstream(dir / "part.step") << "precious\n";
  auto g = test::rng(7);
  const PointGrid q = test::random_grid(g, 40, 40);
  const BSplineSurface big(KnotVector::uniform(3, 40), KnotVector::uniform(3, 40), q);
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 8192;  // the file needs ~150 kB
  auto* old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  try {
    write_step(dir / "part.step", big);
  } catch (const error& e) {
    threw = true;
    EXPECT_EQ(e.code(), errc::file_unwritable) << e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(threw);
  EXPECT_EQ(test::read_text(dir / "part.step"), "precious\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"part.step"});
}

TEST(Step, AFailingStreamIsFileUnwritable) {
  std::ostringstream os;
  os.setstate(std::ios::badbit);
  EXPECT_ERRC(write_step(os, bilinear_patch()), file_unwritable, "STEP");
}

}  // namespace
}  // namespace interpatch::io
