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
#include "io/closed_shapes.hpp"
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

// How each edge is used by the loops: edge "#n" -> its ORIENTED_EDGEs' .T./.F.
std::map<std::string, std::multiset<std::string>> edge_orientations(const std::map<int, std::string>& e) {
  std::map<std::string, std::multiset<std::string>> uses;
  const std::string head = "ORIENTED_EDGE('',*,*,";
  for (const auto& [n, body] : e) {
    if (body.rfind(head, 0) != 0) continue;
    const auto comma = body.find(',', head.size());
    uses[body.substr(head.size(), comma - head.size())].insert(body.substr(comma + 1, 3));
  }
  return uses;
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

// A rational quarter circle of radius 2, and a closed cubic through four points.
BSplineCurve quarter_circle() {
  return BSplineCurve(KnotVector(2, {0, 0, 0, 1, 1, 1}), {{2, 0, 0}, {2, 2, 0}, {0, 2, 0}}, {1, std::sqrt(0.5), 1});
}

BSplineCurve closed_curve() {
  return BSplineCurve(KnotVector::periodic_from(3, {0, 0.25, 0.5, 0.75}, 1.0),
                      {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}});
}

TEST(Step, CurveIsOneBSplineCurveInAWireframeRepresentation) {
  for (const BSplineCurve& c : {quarter_circle(), closed_curve(), line({0, 0, 0}, {1, 2, 3})}) {
    std::ostringstream os;
    write_step(os, c, {.name = "part", .time_stamp = "2024-05-01T12:00:00"});
    const std::string t = os.str();
    EXPECT_EQ(t.rfind("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(", 0), 0u);
    EXPECT_TRUE(t.ends_with("ENDSEC;\nEND-ISO-10303-21;\n"));
    const auto e = entities(t);
    int expected = 1;
    for (const auto& [n, body] : e) {
      EXPECT_EQ(n, expected++);
      for (const int target : references(body)) EXPECT_LT(target, n) << "#" << n << "=" << body;
    }
    const BSplineCurve clamped = c.clamped();
    expect_counts(e, {{"CARTESIAN_POINT", clamped.control_points().size() + 1},  // and the placement's origin
                      {"B_SPLINE_CURVE_WITH_KNOTS", c.rational() ? 0u : 1u},
                      {"(BOUNDED_CURVE() B_SPLINE_CURVE(", c.rational() ? 1u : 0u},
                      {"GEOMETRIC_CURVE_SET('part',(", 1},
                      {"GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('part',(", 1},
                      {"SHAPE_DEFINITION_REPRESENTATION(", 1},
                      {"ADVANCED_FACE", 0}});
    // A closed curve is its clamped form, said to be closed.
    for (const auto& [n, body] : e) {
      if (body.find("B_SPLINE_CURVE(") == std::string::npos && body.rfind("B_SPLINE_CURVE_WITH_KNOTS(''", 0) != 0) continue;
      EXPECT_NE(body.find(std::string(",.UNSPECIFIED.,") + (c.periodic() ? ".T." : ".F.") + ",.F."), std::string::npos)
          << body;
    }
  }
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
  const auto uses = edge_orientations(e);
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

// ---------------------------------------------------------------- closed shapes

// A parameter of a Part 21 entity: an atom (a number, #n, .ENUM., 'text', $, *) or a list.
struct Param {
  std::string atom;
  std::vector<Param> list;
};

// The list opening at text[at] == '(' (at moves past its ')').
Param parse_list(const std::string& text, std::size_t& at) {
  Param p;
  EXPECT_EQ(text[at], '(');
  ++at;
  while (at < text.size() && text[at] != ')') {
    if (text[at] == ',' || text[at] == '\n' || text[at] == ' ') {
      ++at;
    } else if (text[at] == '(') {
      p.list.push_back(parse_list(text, at));
    } else {
      const std::size_t end = text.find_first_of(",)", at);
      p.list.push_back({text.substr(at, end - at), {}});
      at = end;
    }
  }
  ++at;
  return p;
}

// The parameters of (partial) entity `name` in an entity's text: NAME(...).
std::vector<Param> params_of(const std::string& body, const std::string& name) {
  const std::size_t at = body.find(name + "(");
  EXPECT_NE(at, std::string::npos) << name << " in " << body.substr(0, 80);
  if (at == std::string::npos) return {};
  std::size_t open = at + name.size();
  return parse_list(body, open).list;
}

double real_of(const Param& p) {
  EXPECT_TRUE(is_step_real(p.atom)) << p.atom;
  double v = 0;
  std::from_chars(p.atom.data(), p.atom.data() + p.atom.size(), v);
  return v;
}

int int_of(const Param& p) { return std::stoi(p.atom); }

// A clamped knot vector from a B_SPLINE_..._WITH_KNOTS pair of lists.
KnotVector knots_of(int degree, const Param& multiplicities, const Param& values) {
  EXPECT_EQ(multiplicities.list.size(), values.list.size());
  std::vector<double> k;
  for (std::size_t i = 0; i < values.list.size(); ++i)
    k.insert(k.end(), static_cast<std::size_t>(int_of(multiplicities.list[i])), real_of(values.list[i]));
  return KnotVector(degree, std::move(k));
}

Vec3 point_of(const std::map<int, std::string>& e, const Param& ref) {
  const auto p = params_of(e.at(std::stoi(ref.atom.substr(1))), "CARTESIAN_POINT");
  EXPECT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1].list.size(), 3u);
  return {real_of(p[1].list[0]), real_of(p[1].list[1]), real_of(p[1].list[2])};
}

// The file's one B-spline surface, read back as this test reads Part 21: its net,
// weights and knots, and its u_closed/v_closed flags.
struct SurfaceRead {
  BSplineSurface surface;
  std::array<std::string, 2> closed;
};

SurfaceRead surface_of(const std::map<int, std::string>& e) {
  std::string body;
  for (const auto& [n, b] : e)
    if (b.find("B_SPLINE_SURFACE") != std::string::npos) body = b;
  const bool rational = body.find("RATIONAL_B_SPLINE_SURFACE") != std::string::npos;
  // The simple entity lists name, degrees, net, form, flags, then the knots; the
  // complex one splits them between its partial entities.
  const auto head = params_of(body, rational ? "B_SPLINE_SURFACE" : "B_SPLINE_SURFACE_WITH_KNOTS");
  const std::size_t h = rational ? 0 : 1;
  const auto with_knots = rational ? params_of(body, "B_SPLINE_SURFACE_WITH_KNOTS")
                                   : std::vector<Param>(head.begin() + 8, head.end());
  const int du = int_of(head[h]), dv = int_of(head[h + 1]);
  const Param& net = head[h + 2];
  const std::size_t n = net.list.size(), m = net.list[0].list.size();
  PointGrid cp({n, m});
  Grid<double, 2> w = rational ? Grid<double, 2>({n, m}) : Grid<double, 2>();
  const auto weights = rational ? params_of(body, "RATIONAL_B_SPLINE_SURFACE") : std::vector<Param>{};
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      cp(i, j) = point_of(e, net.list[i].list[j]);
      if (rational) w(i, j) = real_of(weights[0].list[i].list[j]);
    }
  return {BSplineSurface(knots_of(du, with_knots[0], with_knots[2]), knots_of(dv, with_knots[1], with_knots[3]),
                         std::move(cp), std::move(w)),
          {head[h + 4].atom, head[h + 5].atom}};
}

// The clamped knots a periodic direction must be written with, worked out from its
// breaks: the domain's ends p+1 times, every other break of the period with its
// multiplicity.
std::vector<double> expected_clamped_knots(const KnotVector& k) {
  std::vector<double> out(static_cast<std::size_t>(k.degree()) + 1, k.front());
  for (const auto& [x, mult] : k.interior_breaks())
    if (x != k.front()) out.insert(out.end(), static_cast<std::size_t>(mult), x);
  out.insert(out.end(), static_cast<std::size_t>(k.degree()) + 1, k.back());
  return out;
}

const std::pair<const char*, std::array<bool, 2>> closed_directions[] = {
    {"u", {true, false}}, {"v", {false, true}}, {"uv", {true, true}}};

// A surface closed in u, v or both is written as its clamped form — the same surface,
// the domain's ends as (p+1)-fold knots, first and last control lines on the seam —
// and declared closed in exactly those directions.
TEST(Step, ClosedSurfaceIsItsClampedFormDeclaredClosed) {
  for (const auto& [tag, periodic] : closed_directions)
    for (unsigned seed = 1; seed <= 4; ++seed)
      for (const bool rational : {false, true}) {
        SCOPED_TRACE(std::string(tag) + " seed " + std::to_string(seed) + (rational ? " rational" : ""));
        const BSplineSurface s = test::closed_surface(periodic, seed, rational);
        const SurfaceRead r = surface_of(entities(step_text(s)));
        EXPECT_EQ(r.closed[0], periodic[0] ? ".T." : ".F.");
        EXPECT_EQ(r.closed[1], periodic[1] ? ".T." : ".F.");
        EXPECT_EQ(r.surface.knots_u().values(), expected_clamped_knots(s.knots_u()));
        EXPECT_EQ(r.surface.knots_v().values(), expected_clamped_knots(s.knots_v()));
        EXPECT_EQ(r.surface.rational(), rational);
        // The clamped form is the periodic one up to the rounding of the banded solve
        // that makes it (~1e-15 of the size); 1e-12 leaves room for that and nothing else.
        const double tol = 1e-12 * test::bbox_diagonal(s.control_points().values());
        auto g = test::rng(seed);
        const auto [u0, u1] = s.domain_u();
        const auto [v0, v1] = s.domain_v();
        for (int k = 0; k < 200; ++k) {
          const double u = test::uniform(g, u0, u1), v = test::uniform(g, v0, v1);
          EXPECT_LE(norm(r.surface.point(u, v) - s.point(u, v)), tol) << u << ", " << v;
        }
        const auto& cp = r.surface.control_points();
        const std::size_t n = cp.extent(0), m = cp.extent(1);
        for (std::size_t j = 0; periodic[0] && j < m; ++j) EXPECT_LE(norm(cp(0, j) - cp(n - 1, j)), tol) << j;
        for (std::size_t i = 0; periodic[1] && i < n; ++i) EXPECT_LE(norm(cp(i, 0) - cp(i, m - 1)), tol) << i;
      }
}

// The face of a surface closed in one direction is a pipe: one seam edge used twice
// and two closed boundary curves; closed in both, a torus: two seams, one vertex.
TEST(Step, ClosedSurfaceFaceHasItsSeamsAndClosedEdges) {
  for (const auto& [tag, periodic] : closed_directions) {
    SCOPED_TRACE(tag);
    const bool torus = periodic[0] && periodic[1];
    const auto e = entities(step_text(test::closed_surface(periodic, 5)));
    expect_counts(e, {{"ADVANCED_FACE(", 1}, {"SEAM_CURVE(", torus ? 2u : 1u}, {"SURFACE_CURVE(", torus ? 0u : 2u},
                      {"EDGE_CURVE(", torus ? 2u : 3u}, {"VERTEX_POINT(", torus ? 1u : 2u},
                      {"ORIENTED_EDGE(", 4}, {"OPEN_SHELL(", 1}});
    // B_SPLINE_CURVE_WITH_KNOTS('', degree, points, form, closed_curve, ...): the
    // circles about a closed direction are closed, the seam across an open one is not.
    std::size_t closed = 0, open = 0;
    for (const auto& [n, body] : e) {
      if (body.rfind("B_SPLINE_CURVE_WITH_KNOTS(", 0) != 0) continue;
      const std::string flag = params_of(body, "B_SPLINE_CURVE_WITH_KNOTS")[4].atom;
      ++(flag == ".T." ? closed : open);
    }
    EXPECT_EQ(closed, 2u);
    EXPECT_EQ(open, torus ? 0u : 1u);
  }
}

// A volume closed in u is a ring: no faces at u0 and u1 (they meet inside it), the
// other four closing into one solid. Closed in u and v, a thick torus shell: its
// inner and outer skins, two closed shells. Closed in all three, it has no boundary.
TEST(Step, ClosedVolumeHasNoFacesAcrossItsSeam) {
  const auto ring = entities(step_text(test::closed_volume({true, false}, 1)));
  expect_counts(ring, {{"ADVANCED_FACE(", 4}, {"SEAM_CURVE(", 4}, {"CLOSED_SHELL(", 1}, {"MANIFOLD_SOLID_BREP(", 1},
                       {"OPEN_SHELL(", 0}});
  for (const auto& [edge, o] : edge_orientations(ring)) EXPECT_EQ(o, (std::multiset<std::string>{".F.", ".T."})) << edge;

  const auto shell = entities(step_text(test::closed_volume({true, true}, 2)));
  expect_counts(shell, {{"ADVANCED_FACE(", 2}, {"CLOSED_SHELL(", 2}, {"MANIFOLD_SOLID_BREP(", 0},
                        {"SHELL_BASED_SURFACE_MODEL(", 1}});
  for (const auto& [n, body] : shell) {
    if (body.rfind("SHELL_BASED_SURFACE_MODEL(", 0) == 0) {
      EXPECT_EQ(references(body).size(), 2u) << body;
    }
  }

  EXPECT_ERRC(step_text(test::volume_closed_everywhere()), no_exact_form, "closed (periodic) in u, v and w");
}

}  // namespace
}  // namespace interpatch::io
