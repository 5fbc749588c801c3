// STEP and IGES files written by `interpatch build` read back by OpenCASCADE's own
// readers — independent of interpatch's writers — and compared with interpatch's
// exact form point by point, face by face; OCCT's shape checker must call every
// face (and a volume's solid) valid.

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <BRepCheck_Analyzer.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <TopAbs_State.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Pnt.hxx>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/iges.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/io/step.hpp"
#include "io/closed_shapes.hpp"
#include "temp_dir.hpp"

namespace interpatch {
namespace {

namespace fs = std::filesystem;

// Points per direction on every face. 21 puts samples on knots of uniform
// 2-, 4-, 5-, 10- and 20-span vectors and inside every span of the examples.
constexpr std::size_t samples = 21;

// The files hold the control points, weights and knots digit for digit (shortest
// round-trip text), so OCCT's surface is the same surface; what is left is the two
// evaluators' rounding (de Boor in OCCT, basis functions here), ~1e-15 of the
// size. 1e-9 of the bounding-box diagonal leaves room for that and nothing else:
// one knot or control point read wrong moves points by far more.
constexpr double relative_tolerance = 1e-9;

std::string quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs `interpatch build spec -o out`; returns the exit status, stderr into `err`.
int build(const fs::path& spec, const fs::path& out, std::string* err = nullptr) {
  const fs::path err_file = out.parent_path() / (out.filename().string() + ".stderr");
  const std::string cmd = quote(INTERPATCH_CLI) + " build " + quote(spec.string()) + " -o " + quote(out.string()) +
                          " 2>" + quote(err_file.string()) + " </dev/null";
  const int rc = std::system(cmd.c_str());
  if (err) *err = test::read_text(err_file);
  fs::remove(err_file);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TopoDS_Shape read_step(const fs::path& path) {
  STEPControl_Reader reader;
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone) << path;
  EXPECT_GT(reader.TransferRoots(), 0) << path;
  return reader.OneShape();
}

struct IgesRead {
  TopoDS_Shape shape;
  std::multiset<int> entity_types;  // the type number of every entity in the file
};

IgesRead read_iges(const fs::path& path) {
  IGESControl_Reader reader;
  IgesRead r;
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone) << path;
  const Handle(IGESData_IGESModel) model = reader.IGESModel();
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) r.entity_types.insert(model->Entity(i)->TypeNumber());
  EXPECT_GT(reader.TransferRoots(), 0) << path;
  r.shape = reader.OneShape();
  return r;
}

std::vector<TopoDS_Face> faces_of(const TopoDS_Shape& shape) {
  std::vector<TopoDS_Face> faces;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) faces.push_back(TopoDS::Face(e.Current()));
  return faces;
}

std::size_t count(const TopoDS_Shape& shape, TopAbs_ShapeEnum type) {
  std::size_t n = 0;
  for (TopExp_Explorer e(shape, type); e.More(); e.Next()) ++n;
  return n;
}

using FaceGrid = std::vector<Vec3>;  // samples × samples points, first index along the face's u

// The face's underlying surface on a uniform grid over its parameter bounds (the
// bounds mapped linearly onto interpatch's [0,1]).
FaceGrid occt_grid(const TopoDS_Face& face) {
  const Handle(Geom_Surface) s = BRep_Tool::Surface(face);
  Standard_Real u0, u1, v0, v1;
  s->Bounds(u0, u1, v0, v1);
  FaceGrid g;
  for (std::size_t i = 0; i < samples; ++i)
    for (std::size_t j = 0; j < samples; ++j) {
      const double a = static_cast<double>(i) / (samples - 1), b = static_cast<double>(j) / (samples - 1);
      const gp_Pnt p = s->Value(u0 + a * (u1 - u0), v0 + b * (v1 - v0));
      g.push_back({p.X(), p.Y(), p.Z()});
    }
  return g;
}

// interpatch's exact form on the same grids over its own domain: the surface, or a
// volume's boundary faces evaluated through the volume itself (u0: S(u_0, v, w),
// v0: S(u, v_0, w), w0: S(u, v, w_0), ...). A periodic direction of a volume has no
// faces: its two sides meet inside it.
std::vector<FaceGrid> reference_grids(const io::ExactForm& exact) {
  const auto grid = [](std::pair<double, double> d) { return linspace(d.first, d.second, samples); };
  if (const auto* s = std::get_if<BSplineSurface>(&exact)) {
    const PointGrid g = s->evaluate(grid(s->domain_u()), grid(s->domain_v()));
    return {FaceGrid(g.values().begin(), g.values().end())};
  }
  const auto& vol = std::get<BSplineVolume>(exact);
  const auto domain = vol.domain();
  std::vector<FaceGrid> faces;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (vol.periodic()[axis]) continue;
    const std::vector<double> ta = grid(domain[axis == 0 ? 1 : 0]), tb = grid(domain[axis == 2 ? 1 : 2]);
    for (const double at : {domain[axis].first, domain[axis].second}) {
      FaceGrid g;
      for (const double a : ta)
        for (const double b : tb)
          g.push_back(axis == 0 ? vol.point(at, a, b) : axis == 1 ? vol.point(a, at, b) : vol.point(a, b, at));
      faces.push_back(std::move(g));
    }
  }
  return faces;
}

double diagonal(const std::vector<FaceGrid>& grids) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& g : grids)
    for (const Vec3& p : g)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], p[k]);
        hi[k] = std::max(hi[k], p[k]);
      }
  return norm(hi - lo);
}

double max_distance(const FaceGrid& a, const FaceGrid& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, norm(a[i] - b[i]));
  return d;
}

// Every face read back matches a different face of the exact form (a volume's
// faces are matched by geometry: the reader need not keep their order). Returns
// the largest distance relative to the diagonal.
double compare(const std::vector<TopoDS_Face>& faces, const std::vector<FaceGrid>& reference, const std::string& what) {
  EXPECT_EQ(faces.size(), reference.size()) << what;
  const double diag = diagonal(reference);
  double worst = 0;
  std::set<std::size_t> matched;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const FaceGrid g = occt_grid(faces[f]);
    std::size_t best = reference.size();
    double best_d = HUGE_VAL;
    for (std::size_t r = 0; r < reference.size(); ++r) {
      const double d = max_distance(g, reference[r]);
      if (d < best_d) {
        best_d = d;
        best = r;
      }
    }
    EXPECT_TRUE(matched.insert(best).second) << what << ": two faces read back match reference face " << best;
    EXPECT_LE(best_d, relative_tolerance * diag) << what << ": face " << f;
    worst = std::max(worst, best_d / diag);
  }
  return worst;
}

// The numbers themselves survive the text: every pole, weight and knot of a face
// read back is, bit for bit, a control point, weight or knot of the exact form's
// clamped form, the one written (a volume's faces carry the boundary layers of its
// net). Text with fewer digits than round-trip needs fails here even where the 1e-9
// comparison would not.
void expect_exact_numbers(const std::vector<TopoDS_Face>& faces, const io::ExactForm& exact, const std::string& what) {
  std::set<std::array<double, 3>> points;
  std::set<double> weights{1.0}, knots;
  const auto add = [&](const auto& b) {
    for (const Vec3& p : b.control_points().values()) points.insert({p.x, p.y, p.z});
    for (const double w : b.weights().values()) weights.insert(w);
  };
  if (const auto* surface = std::get_if<BSplineSurface>(&exact)) {
    const BSplineSurface s = surface->clamped();
    add(s);
    for (const auto* k : {&s.knots_u(), &s.knots_v()}) knots.insert(k->values().begin(), k->values().end());
  } else {
    const BSplineVolume v = std::get<BSplineVolume>(exact).clamped();
    add(v);
    for (const auto* k : {&v.knots_u(), &v.knots_v(), &v.knots_w()}) knots.insert(k->values().begin(), k->values().end());
  }
  for (const auto& f : faces) {
    const Handle(Geom_BSplineSurface) b = Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(f));
    ASSERT_FALSE(b.IsNull()) << what << ": a face is not a B-spline surface";
    for (Standard_Integer i = 1; i <= b->NbUPoles(); ++i)
      for (Standard_Integer j = 1; j <= b->NbVPoles(); ++j) {
        const gp_Pnt p = b->Pole(i, j);
        EXPECT_TRUE(points.count({p.X(), p.Y(), p.Z()})) << what << ": pole " << i << "," << j << " changed";
        EXPECT_TRUE(weights.count(b->Weight(i, j))) << what << ": weight " << i << "," << j << " changed";
      }
    for (Standard_Integer i = 1; i <= b->NbUKnots(); ++i) EXPECT_TRUE(knots.count(b->UKnot(i))) << what << ": u knot " << i;
    for (Standard_Integer i = 1; i <= b->NbVKnots(); ++i) EXPECT_TRUE(knots.count(b->VKnot(i))) << what << ": v knot " << i;
  }
}

// The shape is one solid, oriented outward (positive volume), with `centre` (the
// volume's own centre) classified inside it.
void expect_solid_around(const TopoDS_Shape& shape, const Vec3& centre, const std::string& what) {
  ASSERT_EQ(count(shape, TopAbs_SOLID), 1u) << what;
  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props);
  EXPECT_GT(props.Mass(), 0) << what << ": faces oriented inward";
  // 1e-7: the files' uncertainty (confusion accuracy, mm); the centre lies far deeper inside.
  BRepClass3d_SolidClassifier inside(shape, gp_Pnt(centre.x, centre.y, centre.z), 1e-7);
  EXPECT_EQ(inside.State(), TopAbs_IN) << what;
}

// The figures docs/interop.md quotes: printed, one line per file.
void report(const std::string& what, double rel) {
  std::printf("[ readback ] %-34s max |OCCT - interpatch| / diagonal = %.2e\n", what.c_str(), rel);
}

struct Case {
  std::string name;
  fs::path spec;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> example_cases() {
  std::vector<Case> cases;
  for (const auto& e : fs::directory_iterator(INTERPATCH_EXAMPLES))
    // A blocks spec is several volumes meshed together, with no one exact form to
    // write as STEP or IGES (the command refuses it; tests/cli_bad_input_test.cpp).
    if (e.path().extension() == ".json" && e.path().stem() != "coons_gregory" &&
        io::read_json_file(e.path()).value("type", "") != "blocks")
      cases.push_back({e.path().stem().string(), e.path()});
  std::sort(cases.begin(), cases.end(), [](const Case& a, const Case& b) { return a.name < b.name; });
  return cases;
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

// Rational specs no example has: a quarter cylinder (radius 2, height 3; degree 2
// in u with weights 1, √2/2, 1) and a quarter of a thick cylindrical shell as a
// rational volume (radii 1 and 2, height 1).
void write_rational_specs(const fs::path& dir) {
  write_text(dir / "quarter_cylinder.json", R"({"type": "bspline_surface", "degree": [2, 1],
    "knots": {"u": [0, 0, 0, 1, 1, 1], "v": [0, 0, 1, 1]},
    "control_points": [[[2, 0, 0], [2, 0, 3]], [[2, 2, 0], [2, 2, 3]], [[0, 2, 0], [0, 2, 3]]],
    "weights": [[1, 1], [0.70710678118654757, 0.70710678118654757], [1, 1]]})");
  write_text(dir / "quarter_shell.json", R"({"type": "bspline_volume", "degree": [2, 1, 1],
    "knots": {"u": [0, 0, 0, 1, 1, 1], "v": [0, 0, 1, 1], "w": [0, 0, 1, 1]},
    "control_points": [
      [[[1, 0, 0], [1, 0, 1]], [[2, 0, 0], [2, 0, 1]]],
      [[[1, 1, 0], [1, 1, 1]], [[2, 2, 0], [2, 2, 1]]],
      [[[0, 1, 0], [0, 1, 1]], [[0, 2, 0], [0, 2, 1]]]],
    "weights": [[[1, 1], [1, 1]], [[0.70710678118654757, 0.70710678118654757], [0.70710678118654757, 0.70710678118654757]], [[1, 1], [1, 1]]]})");
}

class OcctReadback : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    // OCCT's readers keep the file's millimetres as they are.
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    built_ = io::build_file(GetParam().spec);
    ASSERT_TRUE(built_.exact) << GetParam().name;
  }

  // Runs `interpatch build SPEC -o NAME.ext` and returns the output path.
  fs::path written(const std::string& ext) {
    const fs::path out = dir_ / (GetParam().name + ext);
    std::string err;
    EXPECT_EQ(build(GetParam().spec, out, &err), 0) << err;
    return out;
  }

  // The faces read back are the exact form's: its points, and its numbers bit for bit.
  void expect_faces_match(const std::vector<TopoDS_Face>& faces, const std::string& ext) const {
    const std::string what = GetParam().name + ext;
    report(what, compare(faces, reference_grids(*built_.exact), what));
    expect_exact_numbers(faces, *built_.exact, what);
  }

  test::TempDir dir_;
  io::Construction built_;
};

TEST_P(OcctReadback, StepFacesMatchTheExactFormAndAreValid) {
  const std::string& name = GetParam().name;
  const TopoDS_Shape shape = read_step(written(".step"));
  ASSERT_FALSE(shape.IsNull());
  const auto faces = faces_of(shape);
  expect_faces_match(faces, ".step");
  EXPECT_TRUE(BRepCheck_Analyzer(shape).IsValid()) << name << ".step: OCCT's checker finds the shape invalid";
  for (const auto& f : faces) EXPECT_TRUE(BRepCheck_Analyzer(f).IsValid()) << name << ".step: a face is invalid";

  if (io::is_volume(built_)) {
    // The six faces close into one solid.
    expect_solid_around(shape, io::volume_evaluator(built_).point(0.5, 0.5, 0.5), name);
  }
}

TEST_P(OcctReadback, IgesEntities128MatchTheExactForm) {
  const std::string& name = GetParam().name;
  const IgesRead r = read_iges(written(".igs"));
  const std::size_t expected = io::is_volume(built_) ? 6 : 1;
  EXPECT_EQ(r.entity_types.count(128), expected) << name;
  EXPECT_EQ(r.entity_types.size(), expected) << name << ": entities other than 128";
  ASSERT_FALSE(r.shape.IsNull());
  const auto faces = faces_of(r.shape);
  expect_faces_match(faces, ".igs");
  for (const auto& f : faces) EXPECT_TRUE(BRepCheck_Analyzer(f).IsValid()) << name << ".igs: a face is invalid";
}

std::vector<Case> all_cases() {
  static const test::TempDir specs;  // lives for the whole run
  write_rational_specs(specs.path());
  std::vector<Case> cases = example_cases();
  cases.push_back({"quarter_cylinder", specs / "quarter_cylinder.json"});
  cases.push_back({"quarter_shell", specs / "quarter_shell.json"});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Every, OcctReadback, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

TEST(OcctReadbackCli, NoExactFormIsRefusedWithExit3AndNoFile) {
  test::TempDir dir;
  for (const char* ext : {".step", ".igs"}) {
    const fs::path out = dir / (std::string("gregory") + ext);
    std::string err;
    EXPECT_EQ(build(fs::path(INTERPATCH_EXAMPLES) / "coons_gregory.json", out, &err), 3) << ext;
    EXPECT_NE(err.find("coons"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out)) << ext;
  }
}

// .stp and .iges are the same formats as .step and .igs, in any case.
TEST(OcctReadbackCli, ExtensionAliasesWriteTheSameFormats) {
  test::TempDir dir;
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  const fs::path spec = fs::path(INTERPATCH_EXAMPLES) / "ruled.json";
  ASSERT_EQ(build(spec, dir / "a.stp"), 0);
  ASSERT_EQ(build(spec, dir / "b.STEP"), 0);
  ASSERT_EQ(build(spec, dir / "c.iges"), 0);
  ASSERT_EQ(build(spec, dir / "d.IGS"), 0);
  EXPECT_EQ(faces_of(read_step(dir / "a.stp")).size(), 1u);
  EXPECT_EQ(faces_of(read_step(dir / "b.STEP")).size(), 1u);
  EXPECT_EQ(read_iges(dir / "c.iges").entity_types, std::multiset<int>{128});
  EXPECT_EQ(read_iges(dir / "d.IGS").entity_types, std::multiset<int>{128});
}

// The hemisphere has a pole (its u = 0 row is one point) and a seam (its v = 0
// and v = 1 boundaries are the same meridian). The file leaves the pole out of the
// loop and writes the meridian once, as a SEAM_CURVE used in both directions; OCCT
// must read a degenerated edge at the pole and the seam as one edge closed on the face.
TEST(OcctReadbackTopology, HemispherePoleAndSeam) {
  test::TempDir dir;
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  const fs::path out = dir / "dome.step";
  ASSERT_EQ(build(fs::path(INTERPATCH_EXAMPLES) / "hemisphere.json", out), 0);
  const TopoDS_Shape shape = read_step(out);
  const auto faces = faces_of(shape);
  ASSERT_EQ(faces.size(), 1u);
  std::size_t degenerated = 0, seams = 0;
  for (TopExp_Explorer e(faces[0], TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& edge = TopoDS::Edge(e.Current());
    if (BRep_Tool::Degenerated(edge)) ++degenerated;
    if (BRep_Tool::IsClosed(edge, faces[0])) ++seams;
  }
  EXPECT_EQ(degenerated, 1u);
  EXPECT_EQ(seams, 2u);  // the seam edge, met once in each direction
  EXPECT_TRUE(BRepCheck_Analyzer(shape).IsValid());
}

// ---------------------------------------------------------------- closed shapes

// Surfaces closed in u, in v and in both, polynomial and rational, and volumes
// closed in one direction (a solid ring) or two (a thick torus shell): periodic
// B-splines built by hand (tests/io/closed_shapes.hpp), written by interpatch's
// writers, read back by OCCT. The files hold their clamped forms, which interpatch
// makes by interpolation exact up to rounding (~1e-15 of the size): the same
// 1e-9 relative tolerance as above holds, and a wrong seam, knot or flag moves
// points by far more.
struct ClosedCase {
  std::string name;
  io::ExactForm form;
  std::array<bool, 2> periodic{};  // a surface's u and v, a volume's u and v (w is open)
};

void PrintTo(const ClosedCase& c, std::ostream* os) { *os << c.name; }

std::vector<ClosedCase> closed_cases() {
  std::vector<ClosedCase> cases;
  const std::pair<const char*, std::array<bool, 2>> directions[] = {
      {"u", {true, false}}, {"v", {false, true}}, {"uv", {true, true}}};
  for (const auto& [tag, periodic] : directions) {
    for (const unsigned seed : {1u, 2u})
      for (const bool rational : {false, true})
        cases.push_back({std::string("surface_") + tag + "_" + std::to_string(seed) + (rational ? "_rational" : ""),
                         test::closed_surface(periodic, seed, rational), periodic});
    cases.push_back({std::string("volume_") + tag, test::closed_volume(periodic, 3), periodic});
  }
  return cases;
}

// Many parameters besides the grids: OCCT's surface at random (u, v) of the domain,
// and at the seam's two sides (front and back of a closed direction), against
// interpatch's own surface there. Faces are those of a surface form (one face).
void expect_surface_points(const TopoDS_Face& face, const BSplineSurface& s, const std::string& what) {
  const Handle(Geom_Surface) g = BRep_Tool::Surface(face);
  Standard_Real u0, u1, v0, v1;
  g->Bounds(u0, u1, v0, v1);
  EXPECT_EQ(u0, s.domain_u().first) << what;  // the parametrization is the form's own
  EXPECT_EQ(u1, s.domain_u().second) << what;
  EXPECT_EQ(v0, s.domain_v().first) << what;
  EXPECT_EQ(v1, s.domain_v().second) << what;
  const auto ref = s.evaluate(linspace(u0, u1, samples), linspace(v0, v1, samples));
  const double tol = relative_tolerance * test::bbox_diagonal(ref.values());
  auto rng = test::rng(11);
  for (int k = 0; k < 500; ++k) {
    const double u = test::uniform(rng, u0, u1), v = test::uniform(rng, v0, v1);
    const gp_Pnt p = g->Value(u, v);
    EXPECT_LE(norm(Vec3{p.X(), p.Y(), p.Z()} - s.point(u, v)), tol) << what << " at " << u << ", " << v;
  }
  for (const double t : linspace(0, 1, samples)) {
    const double u = u0 + t * (u1 - u0), v = v0 + t * (v1 - v0);
    const gp_Pnt a = g->Value(u0, v), b = g->Value(u1, v), c = g->Value(u, v0), d = g->Value(u, v1);
    if (s.periodic()[0]) {
      EXPECT_LE(a.Distance(b), tol) << what << ": the u seam opens at v = " << v;
    }
    if (s.periodic()[1]) {
      EXPECT_LE(c.Distance(d), tol) << what << ": the v seam opens at u = " << u;
    }
  }
}

// Each face read back is closed (OCCT's own test on its surface) in as many
// directions as the form is periodic: a surface in exactly its periodic ones; a
// volume's faces each span both of the volume's directions but the face's own.
void expect_closed_faces(const std::vector<TopoDS_Face>& faces, const ClosedCase& c, const std::string& what) {
  for (const auto& f : faces) {
    const Handle(Geom_Surface) g = BRep_Tool::Surface(f);
    if (std::holds_alternative<BSplineSurface>(c.form)) {
      EXPECT_EQ(g->IsUClosed(), c.periodic[0]) << what;
      EXPECT_EQ(g->IsVClosed(), c.periodic[1]) << what;
    } else {
      EXPECT_EQ(int{g->IsUClosed()} + int{g->IsVClosed()}, int{c.periodic[0]} + int{c.periodic[1]}) << what;
    }
  }
}

class OcctReadbackClosed : public ::testing::TestWithParam<ClosedCase> {
 protected:
  void SetUp() override { Interface_Static::SetCVal("xstep.cascade.unit", "MM"); }
  test::TempDir dir_;
};

TEST_P(OcctReadbackClosed, StepIsTheSameClosedShapeAndValid) {
  const ClosedCase& c = GetParam();
  const fs::path out = dir_ / (c.name + ".step");
  io::write_step(out, c.form, {.name = c.name, .time_stamp = "2024-05-01T12:00:00"});
  const TopoDS_Shape shape = read_step(out);
  ASSERT_FALSE(shape.IsNull());
  const auto faces = faces_of(shape);
  report(c.name + ".step", compare(faces, reference_grids(c.form), c.name));
  expect_exact_numbers(faces, c.form, c.name);
  expect_closed_faces(faces, c, c.name);
  EXPECT_TRUE(BRepCheck_Analyzer(shape).IsValid()) << c.name << ": OCCT's checker finds the shape invalid";
  for (const auto& f : faces) EXPECT_TRUE(BRepCheck_Analyzer(f).IsValid()) << c.name << ": a face is invalid";

  // Every closed direction of a face has its seam: one edge met twice on the face.
  std::size_t seams = 0;
  for (const auto& f : faces)
    for (TopExp_Explorer e(f, TopAbs_EDGE); e.More(); e.Next()) seams += BRep_Tool::IsClosed(TopoDS::Edge(e.Current()), f);
  const std::size_t closed_directions = std::size_t{c.periodic[0]} + std::size_t{c.periodic[1]};
  EXPECT_EQ(seams, 2 * closed_directions * faces.size()) << c.name;

  if (const auto* s = std::get_if<BSplineSurface>(&c.form)) {
    ASSERT_EQ(faces.size(), 1u);
    expect_surface_points(faces[0], *s, c.name);
    return;
  }
  const auto& vol = std::get<BSplineVolume>(c.form);
  if (closed_directions == 1) {
    // A ring: its four faces close into one solid.
    const auto d = vol.domain();
    expect_solid_around(shape, vol.point(0.5 * (d[0].first + d[0].second), 0.5 * (d[1].first + d[1].second),
                                         0.5 * (d[2].first + d[2].second)),
                        c.name);
  } else {
    // A thick torus shell: its inner and outer skins, two closed shells apart.
    EXPECT_EQ(count(shape, TopAbs_SOLID), 0u) << c.name;
    ASSERT_EQ(count(shape, TopAbs_SHELL), 2u) << c.name;
    for (TopExp_Explorer e(shape, TopAbs_SHELL); e.More(); e.Next())
      EXPECT_TRUE(BRep_Tool::IsClosed(e.Current())) << c.name << ": a shell has free edges";
  }
}

TEST_P(OcctReadbackClosed, IgesIsTheSameClosedShape) {
  const ClosedCase& c = GetParam();
  const fs::path out = dir_ / (c.name + ".igs");
  io::write_iges(out, c.form, {.name = c.name, .time_stamp = "20240501.120000"});
  const IgesRead r = read_iges(out);
  const std::size_t expected = reference_grids(c.form).size();
  EXPECT_EQ(r.entity_types.count(128), expected) << c.name;
  EXPECT_EQ(r.entity_types.size(), expected) << c.name << ": entities other than 128";
  ASSERT_FALSE(r.shape.IsNull());
  const auto faces = faces_of(r.shape);
  report(c.name + ".igs", compare(faces, reference_grids(c.form), c.name));
  expect_exact_numbers(faces, c.form, c.name);
  expect_closed_faces(faces, c, c.name);
  for (const auto& f : faces) EXPECT_TRUE(BRepCheck_Analyzer(f).IsValid()) << c.name << ".igs: a face is invalid";
  if (const auto* s = std::get_if<BSplineSurface>(&c.form)) {
    ASSERT_EQ(faces.size(), 1u);
    expect_surface_points(faces[0], *s, c.name);
  }
}

INSTANTIATE_TEST_SUITE_P(Closed, OcctReadbackClosed, ::testing::ValuesIn(closed_cases()),
                         [](const ::testing::TestParamInfo<ClosedCase>& i) { return i.param.name; });

}  // namespace
}  // namespace interpatch
