#include "interpatch/io/iges.hpp"

#include <charconv>
#include <cmath>
#include <map>
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

std::string iges_text(const ExactForm& f) {
  std::ostringstream os;
  write_iges(os, f, {.name = "part.igs", .time_stamp = "20240501.120000"});
  return os.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream ss(text);
  for (std::string l; std::getline(ss, l);) lines.push_back(l);
  return lines;
}

std::size_t field(const std::string& line, std::size_t index) {  // 8-column directory field, 0-based
  return std::stoul(line.substr(8 * index, 8));
}

// A rational quarter cylinder, 3 × 2 control points: enough to see the u-fastest order.
BSplineSurface quarter_cylinder() {
  PointGrid cp({3, 2});
  Grid<double, 2> w({3, 2}, 1.0);
  cp(0, 0) = {2, 0, 0}, cp(1, 0) = {2, 2, 0}, cp(2, 0) = {0, 2, 0};
  for (int i = 0; i < 3; ++i) cp(i, 1) = cp(i, 0) + Vec3{0, 0, 3};
  w(1, 0) = w(1, 1) = std::sqrt(0.5);
  return BSplineSurface(KnotVector(2, {0, 0, 0, 1, 1, 1}), KnotVector::bezier(1), cp, w);
}

BSplineSurface random_surface(unsigned seed, std::size_t n, std::size_t m) {
  auto g = test::rng(seed);
  return BSplineSurface(KnotVector::uniform(3, static_cast<int>(n)), KnotVector::uniform(2, static_cast<int>(m)),
                        test::random_grid(g, n, m));
}

struct Parsed {
  std::map<char, std::vector<std::string>> sections;  // columns 1-72 of each line, per letter
  std::string order;                                  // section letters in file order, one per section
};

// Checks the fixed-column layout of every line and splits the file into sections.
Parsed parse(const std::string& text) {
  Parsed p;
  EXPECT_TRUE(text.ends_with("\n"));
  for (const std::string& l : lines_of(text)) {
    EXPECT_EQ(l.size(), 80u) << "'" << l << "'";
    if (l.size() != 80) continue;
    const char letter = l[72];
    if (p.order.empty() || p.order.back() != letter) p.order += letter;
    auto& sec = p.sections[letter];
    sec.push_back(l.substr(0, 72));
    EXPECT_EQ(std::stoul(l.substr(73)), sec.size()) << l;  // sequence numbers count 1, 2, ... per section
    EXPECT_EQ(l.substr(73, 7).find_first_not_of(' '), 7 - std::to_string(sec.size()).size()) << l;  // right-justified
  }
  EXPECT_EQ(p.order, "SGDPT");
  return p;
}

// The free-format parameters of the entity whose directory entry is at line `de`.
std::vector<std::string> parameters(const Parsed& p, std::size_t de) {
  const auto& d = p.sections.at('D');
  const std::size_t first = field(d[de - 1], 1), count = field(d[de], 3);
  std::string data;
  for (std::size_t i = first; i < first + count; ++i) {
    const std::string& l = p.sections.at('P')[i - 1];
    EXPECT_EQ(std::stoul(l.substr(64, 8)), de) << "back-pointer of P line " << i;
    EXPECT_EQ(l[64], ' ');
    // No parameter is split: the data of a line ends with a delimiter.
    const std::string d64 = l.substr(0, 64);
    const auto last = d64.find_last_not_of(' ');
    EXPECT_TRUE(d64[last] == ',' || d64[last] == ';') << l;
    data += d64.substr(0, last + 1);
  }
  EXPECT_TRUE(data.ends_with(";"));
  std::vector<std::string> tokens;
  std::stringstream ss(data.substr(0, data.size() - 1));
  for (std::string t; std::getline(ss, t, ',');) tokens.push_back(t);
  return tokens;
}

double number(const std::string& t) {
  EXPECT_NE(t.find('.'), std::string::npos) << t;  // an IGES real has its decimal point
  double v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  EXPECT_EQ(r.ptr, t.data() + t.size()) << t;
  return v;
}

TEST(Iges, EveryLineIs80ColumnsInSectionsSGDPT) {
  const Parsed p = parse(iges_text(quarter_cylinder()));
  const auto& t = p.sections.at('T');
  ASSERT_EQ(t.size(), 1u);
  const auto n = [&](char c) { return std::to_string(p.sections.at(c).size()); };
  EXPECT_EQ(t[0].substr(0, 32), "S" + std::string(7 - n('S').size(), ' ') + n('S') + "G" +
                                    std::string(7 - n('G').size(), ' ') + n('G') + "D" +
                                    std::string(7 - n('D').size(), ' ') + n('D') + "P" +
                                    std::string(7 - n('P').size(), ' ') + n('P'));
}

TEST(Iges, GlobalSectionSaysMillimetresAndIges53) {
  const Parsed p = parse(iges_text(quarter_cylinder()));
  std::string g;
  for (const auto& l : p.sections.at('G')) g += l.substr(0, l.find_last_not_of(' ') + 1);
  EXPECT_EQ(g.rfind("1H,,1H;,8Hpart.igs,8Hpart.igs,", 0), 0u) << g;
  EXPECT_NE(g.find(",1.,2,2HMM,"), std::string::npos) << g;                 // scale 1, unit flag 2 = mm
  EXPECT_NE(g.find("15H20240501.120000"), std::string::npos) << g;
  EXPECT_TRUE(g.ends_with(",11,0,15H20240501.120000;")) << g;               // version flag 11 = 5.3
}

TEST(Iges, DirectoryEntryPointsAtItsParametersAndBack) {
  const Parsed p = parse(iges_text(quarter_cylinder()));
  const auto& d = p.sections.at('D');
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(field(d[0], 0), 128u);
  EXPECT_EQ(field(d[1], 0), 128u);
  EXPECT_EQ(field(d[0], 1), 1u);                       // parameters start at P line 1
  EXPECT_EQ(field(d[1], 3), p.sections.at('P').size());  // and take every P line
  EXPECT_EQ(d[0].substr(64, 8), "00000000");           // independent, visible geometry
  EXPECT_EQ(field(d[1], 4), 0u);                       // form 0
}

// Entity 128 holds the surface digit for digit: counts, degrees, flags, knots, then
// weights and control points with the u index fastest, then the parameter range.
TEST(Iges, Entity128HoldsTheSurfaceExactlyUFastest) {
  for (const BSplineSurface& s : {quarter_cylinder(), random_surface(5, 9, 6)}) {
    const Parsed p = parse(iges_text(s));
    const auto tok = parameters(p, 1);
    const std::size_t n = s.control_points().extent(0), m = s.control_points().extent(1);
    const std::size_t nku = s.knots_u().size(), nkv = s.knots_v().size();
    ASSERT_EQ(tok.size(), 10 + nku + nkv + 4 * n * m + 4);
    EXPECT_EQ(tok[0], "128");
    EXPECT_EQ(std::stoul(tok[1]), n - 1);
    EXPECT_EQ(std::stoul(tok[2]), m - 1);
    EXPECT_EQ(std::stoi(tok[3]), s.degree_u());
    EXPECT_EQ(std::stoi(tok[4]), s.degree_v());
    EXPECT_EQ(tok[7], s.rational() ? "0" : "1");
    std::size_t at = 10;
    for (std::size_t k = 0; k < nku; ++k) EXPECT_EQ(number(tok[at++]), s.knots_u()[k]);
    for (std::size_t k = 0; k < nkv; ++k) EXPECT_EQ(number(tok[at++]), s.knots_v()[k]);
    for (std::size_t j = 0; j < m; ++j)
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(number(tok[at++]), s.rational() ? s.weights()(i, j) : 1.0);
    for (std::size_t j = 0; j < m; ++j)
      for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(number(tok[at++]), s.control_points()(i, j)[c]) << i << "," << j;
    EXPECT_EQ(number(tok[at++]), 0.0);
    EXPECT_EQ(number(tok[at++]), 1.0);
    EXPECT_EQ(number(tok[at++]), 0.0);
    EXPECT_EQ(number(tok[at++]), 1.0);
  }
}

TEST(Iges, Entity126HoldsTheCurveExactly) {
  const BSplineCurve quarter(KnotVector(2, {0, 0, 0, 1, 1, 1}), {{2, 0, 0}, {2, 2, 0}, {0, 2, 0}}, {1, std::sqrt(0.5), 1});
  const BSplineCurve ring(KnotVector::periodic_from(3, {0, 0.25, 0.5, 0.75}, 1.0),
                          {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}});
  for (const BSplineCurve& c : {quarter, ring}) {
    std::ostringstream os;
    write_iges(os, c, {.name = "edge.igs", .time_stamp = "20240501.120000"});
    const Parsed p = parse(os.str());
    ASSERT_EQ(p.sections.at('D').size(), 2u);
    EXPECT_EQ(field(p.sections.at('D')[0], 0), 126u);
    // IGES lists every knot: a closed curve is its clamped form, flagged closed and periodic.
    const BSplineCurve k = c.clamped();
    const std::size_t n = k.control_points().size(), nk = k.knots().size();
    const auto tok = parameters(p, 1);
    ASSERT_EQ(tok.size(), 7 + nk + 4 * n + 5);
    EXPECT_EQ(tok[0], "126");
    EXPECT_EQ(std::stoul(tok[1]), n - 1);
    EXPECT_EQ(std::stoi(tok[2]), c.degree());
    EXPECT_EQ(tok[4], c.periodic() ? "1" : "0");  // closed
    EXPECT_EQ(tok[5], c.rational() ? "0" : "1");  // polynomial
    EXPECT_EQ(tok[6], c.periodic() ? "1" : "0");  // periodic
    std::size_t at = 7;
    for (std::size_t i = 0; i < nk; ++i) EXPECT_EQ(number(tok[at++]), k.knots()[i]);
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(number(tok[at++]), k.rational() ? k.weights()[i] : 1.0);
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) EXPECT_EQ(number(tok[at++]), k.control_points()[i][d]);
    EXPECT_EQ(number(tok[at++]), 0.0);
    EXPECT_EQ(number(tok[at++]), 1.0);
  }
}

TEST(Iges, ClosedSurfaceSaysSo) {
  PointGrid cp({2, 5});
  const Vec3 ring[5] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 0, 0}};
  for (int j = 0; j < 5; ++j) cp(0, j) = ring[j], cp(1, j) = ring[j] + Vec3{0, 0, 1};
  const BSplineSurface tube(KnotVector::bezier(1), KnotVector(1, {0, 0, 0.25, 0.5, 0.75, 1, 1}), cp);
  const auto tok = parameters(parse(iges_text(tube)), 1);
  EXPECT_EQ(tok[5], "0");  // not closed in u
  EXPECT_EQ(tok[6], "1");  // closed in v
}

TEST(Iges, VolumeIsSixEntities128OnItsBoundaryLayers) {
  const KnotVector lin(1, {0, 0, 1, 1});
  PointGrid3 cp({2, 2, 2});
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) cp(i, j, k) = {double(i), 2.0 * j, 3.0 * k};
  const Parsed p = parse(iges_text(BSplineVolume(lin, lin, lin, cp)));
  const auto& d = p.sections.at('D');
  ASSERT_EQ(d.size(), 12u);
  for (std::size_t e = 0; e < 6; ++e) {
    EXPECT_EQ(field(d[2 * e], 0), 128u);
    const auto tok = parameters(p, 2 * e + 1);
    // Face u0 lies in x = 0, u1 in x = 1, v0 in y = 0, ...: the fixed coordinate of
    // all four control points (u fastest) is that of the face.
    const std::size_t axis = e / 2;
    const double at = e % 2 == 0 ? 0.0 : static_cast<double>(axis + 1);
    for (std::size_t q = 0; q < 4; ++q) EXPECT_EQ(number(tok[10 + 4 + 4 + 4 + 3 * q + axis]), at) << "face " << e;
  }
}

TEST(Iges, AWriteIntoAMissingDirectoryLeavesNothing) {
  test::TempDir dir;
  EXPECT_ERRC(write_iges(dir / "missing" / "part.igs", quarter_cylinder()), file_unwritable, "missing");
  EXPECT_EQ(dir.count(), 0u);
}

TEST(Iges, AFailingStreamIsFileUnwritable) {
  std::ostringstream os;
  os.setstate(std::ios::badbit);
  EXPECT_ERRC(write_iges(os, quarter_cylinder()), file_unwritable, "IGES");
}

TEST(Iges, FileWrittenAtomicallyMatchesTheStreamForm) {
  test::TempDir dir;
  write_iges(dir / "part.igs", quarter_cylinder(), {.name = "part.igs", .time_stamp = "20240501.120000"});
  EXPECT_EQ(test::read_text(dir / "part.igs"), iges_text(quarter_cylinder()));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"part.igs"});
}

// ---------------------------------------------------------------- closed shapes

// Entity 128's surface, read back from its parameters as this test reads IGES.
BSplineSurface surface_of(const std::vector<std::string>& tok) {
  const std::size_t n = std::stoul(tok[1]) + 1, m = std::stoul(tok[2]) + 1;
  const int du = std::stoi(tok[3]), dv = std::stoi(tok[4]);
  std::size_t at = 10;
  const auto knots = [&](int p, std::size_t count) {
    std::vector<double> k;
    for (std::size_t i = 0; i < count + static_cast<std::size_t>(p) + 1; ++i) k.push_back(number(tok[at++]));
    return KnotVector(p, std::move(k));
  };
  const KnotVector ku = knots(du, n), kv = knots(dv, m);
  Grid<double, 2> w({n, m});
  PointGrid cp({n, m});
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t i = 0; i < n; ++i) w(i, j) = number(tok[at++]);
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) cp(i, j)[c] = number(tok[at++]);
  return BSplineSurface(ku, kv, std::move(cp), tok[7] == "1" ? Grid<double, 2>() : std::move(w));
}

// A surface closed in u, v or both is entity 128 of its clamped form — the same
// surface, its knots clamped — flagged closed (PROP1/PROP2) and periodic
// (PROP4/PROP5) in exactly those directions.
TEST(Iges, ClosedSurfaceIsItsClampedFormFlaggedClosedAndPeriodic) {
  const std::pair<const char*, std::array<bool, 2>> directions[] = {
      {"u", {true, false}}, {"v", {false, true}}, {"uv", {true, true}}};
  for (const auto& [tag, periodic] : directions)
    for (unsigned seed = 1; seed <= 4; ++seed)
      for (const bool rational : {false, true}) {
        SCOPED_TRACE(std::string(tag) + " seed " + std::to_string(seed) + (rational ? " rational" : ""));
        const BSplineSurface s = test::closed_surface(periodic, seed, rational);
        const auto tok = parameters(parse(iges_text(s)), 1);
        EXPECT_EQ(tok[5], periodic[0] ? "1" : "0");  // PROP1: closed in u
        EXPECT_EQ(tok[6], periodic[1] ? "1" : "0");  // PROP2: closed in v
        EXPECT_EQ(tok[7], rational ? "0" : "1");     // PROP3: polynomial
        EXPECT_EQ(tok[8], periodic[0] ? "1" : "0");  // PROP4: periodic in u
        EXPECT_EQ(tok[9], periodic[1] ? "1" : "0");  // PROP5: periodic in v
        const BSplineSurface r = surface_of(tok);
        EXPECT_EQ(r.knots_u(), s.knots_u().clamped());
        EXPECT_EQ(r.knots_v(), s.knots_v().clamped());
        EXPECT_EQ(r.domain_u(), s.domain_u());  // the parameter range closes the entity
        EXPECT_EQ(r.domain_v(), s.domain_v());
        // The clamped form is the periodic one up to the rounding of the banded solve
        // that makes it (~1e-15 of the size); 1e-12 leaves room for that and nothing else.
        const double tol = 1e-12 * test::bbox_diagonal(s.control_points().values());
        auto g = test::rng(seed);
        for (int k = 0; k < 200; ++k) {
          const double u = test::uniform(g, r.domain_u().first, r.domain_u().second);
          const double v = test::uniform(g, r.domain_v().first, r.domain_v().second);
          EXPECT_LE(norm(r.point(u, v) - s.point(u, v)), tol) << u << ", " << v;
        }
      }
}

// A volume closed in u has no faces at u0 and u1 (they meet inside it): four
// entities 128, each closed and periodic along the volume's u. Closed in u and v,
// two (its inner and outer skins), closed and periodic both ways.
TEST(Iges, ClosedVolumeIsItsBoundaryFacesFlaggedClosed) {
  for (const auto& periodic : {std::array{true, false}, std::array{false, true}, std::array{true, true}}) {
    const BSplineVolume vol = test::closed_volume(periodic, 4);
    const Parsed p = parse(iges_text(vol));
    const std::size_t faces = periodic[0] && periodic[1] ? 2 : 4;
    ASSERT_EQ(p.sections.at('D').size(), 2 * faces);
    for (std::size_t e = 0; e < faces; ++e) {
      const auto tok = parameters(p, 2 * e + 1);
      // Each face spans both of the volume's directions but its own: closed and
      // periodic in as many directions as the volume.
      const int expected = int{periodic[0]} + int{periodic[1]};
      EXPECT_EQ(std::stoi(tok[5]) + std::stoi(tok[6]), expected) << "face " << e;
      EXPECT_EQ(std::stoi(tok[8]) + std::stoi(tok[9]), expected) << "face " << e;
      EXPECT_EQ(tok[5], tok[8]) << "face " << e;
      EXPECT_EQ(tok[6], tok[9]) << "face " << e;
    }
  }
  EXPECT_ERRC(iges_text(test::volume_closed_everywhere()), no_exact_form, "closed (periodic) in u, v and w");
}

}  // namespace
}  // namespace interpatch::io
