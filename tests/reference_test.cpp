// The library against independent reference values: tests/data/reference.json,
// produced in exact rational arithmetic by tools/reference/make_reference.py
// (Cox–de Boor from the definition, dense exact Gaussian elimination, Boehm's
// formula, exact least squares for degree elevation). The script's header lists
// the cases and formulas; CTest checks that the JSON is what the script produces.
//
// Every input in the JSON is a double, and the reference was computed exactly
// from those doubles, so a difference is the library's own rounding, or a bug.
// Set INTERPATCH_REFERENCE_JSON to compare against another file (e.g. one made by
// a deliberately wrong variant of the script, to see these tests fail).

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/hermite.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------
// Tolerances. Each states why it is as large as it is ("seen": the largest error
// measured with GCC 12 -O3 on x86-64, so the margin for other compilers and FMA
// contraction is visible). Every one is orders of magnitude below what a wrong
// formula produces: a shifted knot window, start/end derivative windows swapped,
// the pole row counted in the average, chord instead of centripetal, no averaging
// over lines, wrong Catmull–Rom end tangents all give differences >= 1e-3 (checked
// by pointing INTERPATCH_REFERENCE_JSON at the output of such mutated scripts).
// ---------------------------------------------------------------------------

/// Basis functions and their derivatives, relative to the largest |value| of that
/// order at that parameter (at least 1): the triangular algorithm combines p+1
/// terms no larger than that per level, p <= 5 levels, each rounding by 1.1e-16;
/// each derivative order adds one division by a knot difference. Seen: 8e-16.
constexpr double kBasisTol = 1e-13;

/// Parameters and knots (absolute; all lie in [0, 1] here): a parameter is a sum
/// of <= 12 correctly rounded chord lengths over their total, averaged over <= 13
/// lines, a knot the average of <= 5 of them: a few dozen roundings of 1.1e-16.
/// Seen: 2.2e-16.
constexpr double kParamTol = 1e-14;

/// Control points of interpolants, relative to the scale (the larger of the data
/// and control-net bounding-box diagonals): parameter errors of ~1e-16 and the
/// rounding of a banded LU of size <= 13, amplified by the condition number of the
/// collocation matrix (~10 for cubics, larger for the degree-5 cases whose control
/// net is 10x the data). Seen: 1.5e-15.
constexpr double kControlTol = 1e-13;

/// Points of a curve or surface at given parameters, relative to the scale: the
/// control-point error above, averaged by a partition of unity, plus one basis
/// evaluation. Seen: 3e-16.
constexpr double kPointTol = 1e-13;

/// First derivatives, relative to the larger of the scale and |reference
/// derivative|: the derivative basis carries factors p/Δu with Δu >= 0.08 here,
/// so control-point errors grow by up to ~60. Seen: 5e-15.
constexpr double kDerivTol = 1e-12;

/// Knot insertion and the Hermite-to-B-spline conversion are a few convex
/// combinations per point, no solve: a handful of roundings, relative to the
/// scale. Seen: 8e-17.
constexpr double kDirectTol = 1e-14;

/// Degree elevation solves a collocation system at the Greville abscissae of the
/// elevated knots (banded, size <= 12, condition ~10), relative to the scale.
/// Seen: 2.2e-15.
constexpr double kElevateTol = 1e-13;

const json& reference() {
  static const json doc = [] {
    const char* env = std::getenv("INTERPATCH_REFERENCE_JSON");
    const std::string path = (env != nullptr && *env != '\0') ? std::string(env)
                                                               : std::string(INTERPATCH_TEST_DATA "/reference.json");
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read " + path);
    return json::parse(in);
  }();
  return doc;
}

Vec3 vec(const json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

std::vector<Vec3> vecs(const json& j) {
  std::vector<Vec3> out;
  for (const auto& e : j) out.push_back(vec(e));
  return out;
}

std::vector<double> doubles(const json& j) { return j.get<std::vector<double>>(); }

PointGrid grid(const json& j) {
  PointGrid g({j.size(), j.at(0).size()});
  for (std::size_t p = 0; p < j.size(); ++p)
    for (std::size_t q = 0; q < j.at(p).size(); ++q) g(p, q) = vec(j.at(p).at(q));
  return g;
}

std::vector<Vec3> flat(const PointGrid& g) { return {g.data(), g.data() + g.size()}; }

Parametrization parametrization(const json& j) {
  const auto s = j.get<std::string>();
  if (s == "uniform") return Parametrization::uniform;
  if (s == "centripetal") return Parametrization::centripetal;
  return Parametrization::chord;
}

/// Largest |a_i − b_i|; sizes must agree (a size mismatch is reported and gives +inf).
double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size()) return HUGE_VAL;
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

double max_dist(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size()) return HUGE_VAL;
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, distance(a[i], b[i]));
  return m;
}

double scale_of(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return std::max({test::bbox_diagonal(a), test::bbox_diagonal(b), 1e-300});
}

std::string show(const std::vector<double>& v) {
  std::ostringstream s;
  s.precision(17);
  s << "[";
  for (std::size_t i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v[i];
  s << "]";
  return s.str();
}

// ---------------------------------------------------------------------------
// a) basis functions
// ---------------------------------------------------------------------------

TEST(ReferenceBasis, ValuesAndDerivatives) {
  const auto& cases = reference().at("basis");
  ASSERT_GE(cases.size(), 6u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const int p = c.at("degree").get<int>();
    const KnotVector k(p, doubles(c.at("knots")));
    for (const auto& s : c.at("samples")) {
      const double t = s.at("t").get<double>();
      SCOPED_TRACE("t = " + std::to_string(t));
      const int span = k.find_span(t);
      ASSERT_EQ(span, s.at("span").get<int>());
      double ders[3 * (max_degree + 1)];
      k.basis_derivatives(span, t, 2, ders);
      const char* keys[] = {"values", "d1", "d2"};
      for (int order = 0; order <= 2; ++order) {
        const auto ref = doubles(s.at(keys[order]));
        ASSERT_EQ(ref.size(), static_cast<std::size_t>(k.count()));
        double scale = 1;
        for (double r : ref) scale = std::max(scale, std::abs(r));
        std::vector<double> got(ref.size(), 0.0);  // the functions outside the span vanish
        for (int j = 0; j <= p; ++j) got[static_cast<std::size_t>(span - p + j)] = ders[order * (p + 1) + j];
        EXPECT_LE(max_abs_diff(got, ref), kBasisTol * scale)
            << "order " << order << "\n got " << show(got) << "\nwant " << show(ref);
      }
      double N[max_degree + 1];
      k.basis(span, t, N);
      for (int j = 0; j <= p; ++j)
        EXPECT_NEAR(N[j], s.at("values").at(span - p + j).get<double>(), kBasisTol) << "basis(), j = " << j;
    }
  }
}

// ---------------------------------------------------------------------------
// b) curve interpolation
// ---------------------------------------------------------------------------

CurveInterpolationOptions curve_options(const json& c) {
  CurveInterpolationOptions o;
  o.degree = c.at("degree").get<int>();
  o.param = parametrization(c.at("param"));
  if (c.contains("start_derivative")) o.start_derivative = vec(c.at("start_derivative"));
  if (c.contains("end_derivative")) o.end_derivative = vec(c.at("end_derivative"));
  return o;
}

TEST(ReferenceCurve, ParametersAndAveragedKnots) {
  for (const auto& c : reference().at("curves")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const auto q = vecs(c.at("points"));
    const auto params = curve_parameters(q, parametrization(c.at("param")));
    EXPECT_LE(max_abs_diff(params, doubles(c.at("params"))), kParamTol)
        << "\n got " << show(params) << "\nwant " << show(doubles(c.at("params")));
    // Knots from the reference parameters: isolates the averaging rule (eq. 9.8 and
    // the windows used with end derivatives) from the parameter computation.
    const auto kv = averaged_knots(doubles(c.at("params")), c.at("degree").get<int>(), c.contains("start_derivative"),
                                   c.contains("end_derivative"));
    EXPECT_LE(max_abs_diff(kv.values(), doubles(c.at("knots"))), kParamTol)
        << "\n got " << show(kv.values()) << "\nwant " << show(doubles(c.at("knots")));
  }
}

TEST(ReferenceCurve, Interpolation) {
  const auto& cases = reference().at("curves");
  ASSERT_GE(cases.size(), 8u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const auto q = vecs(c.at("points"));
    const auto r = interpolate_curve(q, curve_options(c));
    const auto want_cp = vecs(c.at("control_points"));
    const double scale = scale_of(q, want_cp);

    EXPECT_EQ(r.curve.degree(), c.at("degree").get<int>());
    EXPECT_FALSE(r.curve.rational());
    EXPECT_LE(max_abs_diff(r.params, doubles(c.at("params"))), kParamTol);
    EXPECT_LE(max_abs_diff(r.curve.knots().values(), doubles(c.at("knots"))), kParamTol)
        << "\n got " << show(r.curve.knots().values()) << "\nwant " << show(doubles(c.at("knots")));
    EXPECT_LE(max_dist(r.curve.control_points(), want_cp), kControlTol * scale);

    for (std::size_t i = 0; i < q.size() && i < r.params.size(); ++i)
      EXPECT_LE(distance(r.curve.point(r.params[i]), q[i]), kPointTol * scale) << "data point " << i;
    if (c.contains("start_derivative")) {
      EXPECT_LE(distance(r.curve.derivative(0.0, 1), vec(c.at("start_derivative"))), kDerivTol * scale);
    }
    if (c.contains("end_derivative")) {
      EXPECT_LE(distance(r.curve.derivative(1.0, 1), vec(c.at("end_derivative"))), kDerivTol * scale);
    }

    for (const auto& e : c.at("eval")) {
      const double t = e.at("t").get<double>();
      EXPECT_LE(distance(r.curve.point(t), vec(e.at("point"))), kPointTol * scale) << "t = " << t;
      const Vec3 d1 = vec(e.at("d1"));
      EXPECT_LE(distance(r.curve.derivative(t, 1), d1), kDerivTol * std::max(scale, norm(d1))) << "t = " << t;
    }
  }
}

// ---------------------------------------------------------------------------
// c) surface interpolation
// ---------------------------------------------------------------------------

TEST(ReferenceSurface, GridParameters) {
  // Includes the hemisphere, whose v-parameters must leave the pole row out.
  for (const auto& c : reference().at("surfaces")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const auto q = grid(c.at("points"));
    const auto param = parametrization(c.at("param"));
    const auto pu = grid_parameters(q, 0, param);
    const auto pv = grid_parameters(q, 1, param);
    EXPECT_LE(max_abs_diff(pu, doubles(c.at("params_u"))), kParamTol)
        << "\n got " << show(pu) << "\nwant " << show(doubles(c.at("params_u")));
    EXPECT_LE(max_abs_diff(pv, doubles(c.at("params_v"))), kParamTol)
        << "\n got " << show(pv) << "\nwant " << show(doubles(c.at("params_v")));
  }
}

TEST(ReferenceSurface, Interpolation) {
  const auto& cases = reference().at("surfaces");
  ASSERT_GE(cases.size(), 5u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const auto q = grid(c.at("points"));
    SurfaceInterpolationOptions o;
    o.degree_u = c.at("degree").at(0).get<int>();
    o.degree_v = c.at("degree").at(1).get<int>();
    o.param = parametrization(c.at("param"));
    const auto r = interpolate_surface(q, o);
    const auto& s = r.surface;
    const auto want_cp = grid(c.at("control_points"));
    const double scale = scale_of(flat(q), flat(want_cp));

    EXPECT_EQ(s.degree_u(), *o.degree_u);
    EXPECT_EQ(s.degree_v(), *o.degree_v);
    EXPECT_LE(max_abs_diff(r.params_u, doubles(c.at("params_u"))), kParamTol);
    EXPECT_LE(max_abs_diff(r.params_v, doubles(c.at("params_v"))), kParamTol);
    EXPECT_LE(max_abs_diff(s.knots_u().values(), doubles(c.at("knots_u"))), kParamTol)
        << "\n got " << show(s.knots_u().values()) << "\nwant " << show(doubles(c.at("knots_u")));
    EXPECT_LE(max_abs_diff(s.knots_v().values(), doubles(c.at("knots_v"))), kParamTol)
        << "\n got " << show(s.knots_v().values()) << "\nwant " << show(doubles(c.at("knots_v")));
    ASSERT_EQ(s.control_points().shape(), want_cp.shape());
    EXPECT_LE(max_dist(flat(s.control_points()), flat(want_cp)), kControlTol * scale);

    // Through every data point, at the reference parameters.
    const auto pu = doubles(c.at("params_u"));
    const auto pv = doubles(c.at("params_v"));
    double worst = 0;
    for (std::size_t i = 0; i < pu.size(); ++i)
      for (std::size_t j = 0; j < pv.size(); ++j) worst = std::max(worst, distance(s.point(pu[i], pv[j]), q(i, j)));
    EXPECT_LE(worst, kPointTol * scale);

    for (const auto& e : c.at("eval")) {
      const double u = e.at("u").get<double>(), v = e.at("v").get<double>();
      SCOPED_TRACE("(u, v) = (" + std::to_string(u) + ", " + std::to_string(v) + ")");
      const auto d = s.derivatives(u, v);
      EXPECT_LE(distance(d.s, vec(e.at("point"))), kPointTol * scale);
      const Vec3 du = vec(e.at("du")), dv = vec(e.at("dv"));
      EXPECT_LE(distance(d.su, du), kDerivTol * std::max(scale, norm(du)));
      EXPECT_LE(distance(d.sv, dv), kDerivTol * std::max(scale, norm(dv)));
    }
  }
}

TEST(ReferenceSurface, HemispherePoleRowIsAllPoleAndIsInterpolated) {
  // Guards the case itself: if the data ever stops having a pole row, the pole
  // handling above is no longer exercised.
  for (const auto& c : reference().at("surfaces")) {
    if (c.at("name").get<std::string>().rfind("hemisphere", 0) != 0) continue;
    const auto q = grid(c.at("points"));
    for (std::size_t j = 0; j < q.extent(1); ++j) EXPECT_EQ(q(0, j), (Vec3{0, 0, 1}));
    SurfaceInterpolationOptions o;
    o.param = Parametrization::centripetal;
    const auto r = interpolate_surface(q, o);
    for (std::size_t j = 0; j < q.extent(1); ++j)
      EXPECT_LE(distance(r.surface.point(0.0, r.params_v[j]), Vec3{0, 0, 1}), kPointTol);
    return;
  }
  FAIL() << "no hemisphere case in the reference";
}

// ---------------------------------------------------------------------------
// d) Hermite
// ---------------------------------------------------------------------------

TEST(ReferenceHermite, BasisFunctions) {
  const auto& cases = reference().at("hermite_basis");
  ASSERT_FALSE(cases.empty());
  for (const auto& c : cases) {
    const double g = c.at("g").get<double>();
    for (int order = 0; order <= 3; ++order) {
      const auto h = hermite_basis(g, order);
      const std::vector<double> got{h.a0, h.a1, h.b0, h.b1};
      const auto want = doubles(c.at("values").at(order));
      // Cubics with coefficients <= 12 at g in [0,1]: a few roundings of terms <= 12.
      // Seen: 8.9e-16.
      EXPECT_LE(max_abs_diff(got, want), 1e-14) << "g = " << g << ", order " << order;
    }
  }
}

TEST(ReferenceHermite, PiecewiseCurves) {
  const auto& cases = reference().at("hermite_curves");
  ASSERT_GE(cases.size(), 3u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const auto pts = vecs(c.at("points"));
    const std::vector<Vec3> tangents = c.contains("tangents") ? vecs(c.at("tangents")) : std::vector<Vec3>{};
    const std::vector<double> params = c.contains("params") ? doubles(c.at("params")) : std::vector<double>{};
    const HermiteCurve h(pts, tangents, params, TangentRule::catmull_rom);
    const auto want_t = vecs(c.at("expected_tangents"));
    const double scale = scale_of(pts, want_t);

    // Default parameters are k/n: one rounding each.
    EXPECT_LE(max_abs_diff(h.params(), doubles(c.at("expected_params"))), 1e-15);
    // Catmull–Rom: one difference over one parameter difference per tangent.
    EXPECT_LE(max_dist(h.tangents(), want_t), kDirectTol * scale);

    const auto b = h.to_bspline();
    EXPECT_EQ(b.degree(), 3);
    EXPECT_LE(max_abs_diff(b.knots().values(), doubles(c.at("bspline").at("knots"))), 1e-15);
    EXPECT_LE(max_dist(b.control_points(), vecs(c.at("bspline").at("control_points"))), kDirectTol * scale);

    for (const auto& e : c.at("eval")) {
      const double t = e.at("t").get<double>();
      SCOPED_TRACE("t = " + std::to_string(t));
      const Vec3 p = vec(e.at("point")), d1 = vec(e.at("d1"));
      // A cubic in g = (t − t_i)/h with coefficients bounded by the data: a few roundings.
      EXPECT_LE(distance(h.point(t), p), kDirectTol * scale);
      EXPECT_LE(distance(b.point(t), p), kPointTol * scale);
      // Derivatives divide by the segment length h >= 0.3 (once per order). Seen: 7e-16.
      EXPECT_LE(distance(h.derivative(t, 1), d1), 1e-13 * std::max(scale, norm(d1)));
      if (e.contains("d2")) {
        const Vec3 d2 = vec(e.at("d2"));
        EXPECT_LE(distance(h.derivative(t, 2), d2), 1e-13 * std::max(scale, norm(d2)));
      }
    }
  }
}

// ---------------------------------------------------------------------------
// e) knot insertion and degree elevation
// ---------------------------------------------------------------------------

BSplineCurve curve_of(const json& c, int degree) {
  std::vector<double> w = c.contains("weights") ? doubles(c.at("weights")) : std::vector<double>{};
  return BSplineCurve(KnotVector(degree, doubles(c.at("knots"))), vecs(c.at("control_points")), std::move(w));
}

void expect_same_curve(const BSplineCurve& got, const json& want, int degree, double tol, double scale) {
  EXPECT_EQ(got.degree(), degree);
  EXPECT_EQ(got.knots().values(), doubles(want.at("knots")))
      << "\n got " << show(got.knots().values()) << "\nwant " << show(doubles(want.at("knots")));
  EXPECT_LE(max_dist(got.control_points(), vecs(want.at("control_points"))), tol * scale);
  if (want.contains("weights")) {
    EXPECT_LE(max_abs_diff(got.weights(), doubles(want.at("weights"))), tol);  // weights are O(1)
  } else {
    EXPECT_FALSE(got.rational());
  }
}

TEST(ReferenceRefinement, InsertionAndElevation) {
  const auto& cases = reference().at("refinement");
  ASSERT_GE(cases.size(), 2u);
  for (const auto& c : cases) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const int p = c.at("degree").get<int>();
    const auto curve = curve_of(c, p);
    const auto ts = doubles(c.at("eval_params"));
    const auto want = vecs(c.at("eval_points"));
    const double scale = scale_of(vecs(c.at("control_points")), want);
    const auto expect_points = [&](const BSplineCurve& b, const char* what) {
      for (std::size_t i = 0; i < ts.size(); ++i)
        EXPECT_LE(distance(b.point(ts[i]), want[i]), kPointTol * scale) << what << ", t = " << ts[i];
    };
    expect_points(curve, "original");

    for (const auto& ins : c.at("insertions")) {
      const double t = ins.at("t").get<double>();
      const int times = ins.at("times").get<int>();
      SCOPED_TRACE("insert " + std::to_string(t) + " x" + std::to_string(times));
      const auto b = curve.inserted(t, times);
      expect_same_curve(b, ins, p, kDirectTol, scale);
      expect_points(b, "inserted");
    }
    for (const auto& el : c.at("elevations")) {
      const int times = el.at("times").get<int>();
      SCOPED_TRACE("elevate by " + std::to_string(times));
      const auto b = curve.elevated(times);
      expect_same_curve(b, el, p + times, kElevateTol, scale);
      expect_points(b, "elevated");
    }
  }
}

}  // namespace
}  // namespace interpatch
