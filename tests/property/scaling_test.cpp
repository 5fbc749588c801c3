// Scale-freedom: scaling every input of a construction by a power of two s = 2^k
// scales every output point, control point, derivative, gap and tolerance by s
// exactly, bit for bit, and leaves parameters and knots as they are, for data near
// 1e±300 as for ordinary data, as long as the scaled inputs and outputs are normal
// doubles. Multiplying by a power of two is exact and commutes with every rounding in
// between; what used to break it are the squares in lengths (chords, bounding-box
// diagonals, gaps, normals, curvature), which overflow or underflow long before the
// data do, and absolute thresholds.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "base/text.hpp"
#include "constructions/network/network_curves.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/hermite.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/network.hpp"
#include "interpatch/patches.hpp"
#include "interpatch/volume_patches.hpp"
#include "surface_util.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

// 2^±500; 2^±900 near both ends of the range, with room left for what is computed
// from the data: products of small basis values with small coordinates (1e-12 ×
// 1e-3 × 2^-900 is still a normal double, 2^-1000 would not be); 2^±300, where det J
// (scaled by s³) still fits; odd powers for the square roots of centripetal
// parameters (sqrt(2^k) is no power of two for odd k).
const std::vector<int> kScales = {500, -500, 501, -501, 900, -900, 300, -300, 1};

template <class Options>
Options with_param(Parametrization p) {
  Options o;
  o.param = p;
  return o;
}

// ------------------------------------------------------------------ the data times 2^k

Vec3 sc(const Vec3& p, int k) { return ldexp(p, k); }

std::vector<Vec3> sc(std::span<const Vec3> v, int k) {
  std::vector<Vec3> out;
  for (const Vec3& p : v) out.push_back(sc(p, k));
  return out;
}

template <std::size_t Rank>
Grid<Vec3, Rank> sc(Grid<Vec3, Rank> g, int k) {
  for (Vec3& p : g.values()) p = sc(p, k);
  return g;
}

BSplineCurve sc(const BSplineCurve& c, int k) { return BSplineCurve(c.knots(), sc(c.control_points(), k), c.weights()); }

BSplineSurface sc(const BSplineSurface& s, int k) {
  return BSplineSurface(s.knots_u(), s.knots_v(), sc(s.control_points(), k), s.weights());
}

// ------------------------------------------------------------------ what a construction gives

// Every number a construction gives, each with the power of the data's scale it
// carries: 1 for points, control points, derivatives; 0 for parameters, knots,
// weights, unit normals and counts; -1 for mean and principal curvatures, -2 for the
// Gaussian curvature, 3 for det J.
class Outputs {
 public:
  void add(const std::string& what, double v, int power) { values_.push_back({what, v, power, v, power}); }
  // A value compared only where `guard` times 2^(guard_power k) is a normal double:
  // where the smallest det J is found means nothing once det J is beyond the range.
  void add_guarded(const std::string& what, std::span<const double> v, int power, double guard, int guard_power) {
    for (std::size_t i = 0; i < v.size(); ++i)
      values_.push_back({what + "[" + std::to_string(i) + "]", v[i], power, guard, guard_power});
  }
  void add(const std::string& what, const Vec3& v, int power) {
    add(what + ".x", v.x, power);
    add(what + ".y", v.y, power);
    add(what + ".z", v.z, power);
  }
  void add(const std::string& what, std::span<const double> v, int power) {
    for (std::size_t i = 0; i < v.size(); ++i) add(what + "[" + std::to_string(i) + "]", v[i], power);
  }
  void add(const std::string& what, std::span<const Vec3> v, int power) {
    for (std::size_t i = 0; i < v.size(); ++i) add(what + "[" + std::to_string(i) + "]", v[i], power);
  }

  // `scaled` is the same construction from the data times 2^k: every value must be
  // this one's times 2^(power k), bit for bit. A value whose scaled counterpart is not
  // a normal double is outside the promise and skipped (det J = s³ det beyond the
  // range at k = ±500, a coordinate that happens to be within 1e-34 of zero at 2^-900);
  // zeros must stay zero, NaNs (curvature where the surface degenerates) NaN.
  void expect_scaled_by(const Outputs& scaled, int k, const std::string& what) const {
    ASSERT_EQ(scaled.values_.size(), values_.size()) << what << " at scale 2^" << k;
    std::size_t compared = 0, linear = 0;
    for (std::size_t i = 0; i < values_.size(); ++i) {
      const Value& v = values_[i];
      const double got = scaled.values_[i].value;
      if (v.power == 0 || v.power == 1) ++linear;
      if (std::isnan(v.value)) {
        EXPECT_TRUE(std::isnan(got)) << what << ": " << v.what << " at scale 2^" << k;
        continue;
      }
      const double want = std::ldexp(v.value, v.power * k);
      if (v.value != 0 && !std::isnormal(want)) continue;
      if (v.guard != 0 && !std::isnormal(std::ldexp(v.guard, v.guard_power * k))) continue;
      ++compared;
      EXPECT_EQ(got, want) << what << ": " << v.what << " at scale 2^" << k << " (unscaled " << v.value << ")";
      if (got != want) return;  // one message per construction and scale
    }
    // Positions, derivatives and parameters of data of size ~1 stay in range at
    // every scale used: nearly all of them are compared.
    EXPECT_GE(compared, linear * 9 / 10) << what << " at scale 2^" << k;
  }

  [[nodiscard]] std::size_t size() const noexcept { return values_.size(); }

 private:
  struct Value {
    std::string what;
    double value;
    int power;
    double guard;
    int guard_power;
  };
  std::vector<Value> values_;
};

// Builds the outputs of data scaled by 2^0 and by 2^k for every k, and compares.
void expect_scale_free(const std::string& what, const std::function<Outputs(int)>& make,
                       const std::vector<int>& scales = kScales) {
  const Outputs ref = make(0);
  ASSERT_GT(ref.size(), 0u) << what;
  for (int k : scales) ref.expect_scaled_by(make(k), k, what);
}

const std::vector<double> kT = {0.0, 0.13, 0.5, 0.77, 1.0};  // where everything is evaluated

void record(Outputs& o, const std::string& what, const BSplineCurve& c) {
  o.add(what + " knots", c.knots().values(), 0);
  o.add(what + " control points", c.control_points(), 1);
  o.add(what + " weights", c.weights(), 0);
  const auto [a, b] = c.domain();
  for (double t : kT) {
    const double x = a + (b - a) * t;
    const auto d = c.derivatives(x, 2);
    for (int j = 0; j < 3; ++j) o.add(what + " C^(" + std::to_string(j) + ")(" + detail::num(x) + ")", d[static_cast<std::size_t>(j)], 1);
  }
}

void record_surface(Outputs& o, const std::string& what, const Surface& s) {
  for (double u : kT)
    for (double v : kT) {
      const std::string at = what + "(" + detail::num(u) + ", " + detail::num(v) + ")";
      const SurfaceDerivatives d = s.derivatives(u, v);
      o.add(at + " S", d.s, 1);
      o.add(at + " Su", d.su, 1);
      o.add(at + " Sv", d.sv, 1);
      o.add(at + " Suu", d.suu, 1);
      o.add(at + " Suv", d.suv, 1);
      o.add(at + " Svv", d.svv, 1);
      o.add(at + " unit normal", unit_normal(d), 0);
      const Curvature c = curvature(d);
      o.add(at + " K", c.gaussian, -2);
      o.add(at + " H", c.mean, -1);
      o.add(at + " k1", c.k1, -1);
      o.add(at + " k2", c.k2, -1);
    }
  const PointGrid batch = s.evaluate(kT, kT);  // the batch path, separate code for blended surfaces
  o.add(what + " evaluate", std::span<const Vec3>(batch.data(), batch.size()), 1);
}

void record(Outputs& o, const std::string& what, const BSplineSurface& s) {
  o.add(what + " knots u", s.knots_u().values(), 0);
  o.add(what + " knots v", s.knots_v().values(), 0);
  o.add(what + " control points", std::span<const Vec3>(s.control_points().data(), s.control_points().size()), 1);
  o.add(what + " weights", std::span<const double>(s.weights().data(), s.weights().size()), 0);
  record_surface(o, what, s);
}

void record(Outputs& o, const std::string& what, const BlendedSurface& s) {
  record_surface(o, what, s);
  if (s.has_exact_form()) record(o, what + " to_bspline", s.to_bspline());
}

void record_volume(Outputs& o, const std::string& what, const Volume& s) {
  const std::vector<double> t = {0.0, 0.3, 0.77, 1.0};
  for (double u : t)
    for (double v : t)
      for (double w : t) {
        const std::string at = what + "(" + detail::num(u) + ", " + detail::num(v) + ", " + detail::num(w) + ")";
        const VolumeDerivatives d = s.derivatives(u, v, w);
        o.add(at + " S", d.s, 1);
        o.add(at + " Su", d.su, 1);
        o.add(at + " Sv", d.sv, 1);
        o.add(at + " Sw", d.sw, 1);
        o.add(at + " det J", s.jacobian(u, v, w).determinant, 3);
      }
  const VolumeJacobians j = s.evaluate_jacobians(t, t, t);
  o.add(what + " evaluate_jacobians points", std::span<const Vec3>(j.points.data(), j.points.size()), 1);
  o.add(what + " evaluate_jacobians det", std::span<const double>(j.determinants.data(), j.determinants.size()), 3);
  const PointGrid3 batch = s.evaluate(t, t, t);
  o.add(what + " evaluate", std::span<const Vec3>(batch.data(), batch.size()), 1);
  const InvertedCells inv = inverted_cells(s, 5);
  o.add(what + " inverted points", static_cast<double>(inv.inverted_points), 0);
  o.add(what + " min det J", inv.min_determinant, 3);
  o.add(what + " max det J", inv.max_determinant, 3);
  o.add_guarded(what + " min det J at", std::span<const double>(inv.min_at), 0, inv.min_determinant, 3);
}

void record(Outputs& o, const std::string& what, const BSplineVolume& s) {
  o.add(what + " knots u", s.knots_u().values(), 0);
  o.add(what + " knots v", s.knots_v().values(), 0);
  o.add(what + " knots w", s.knots_w().values(), 0);
  o.add(what + " control points", std::span<const Vec3>(s.control_points().data(), s.control_points().size()), 1);
  o.add(what + " weights", std::span<const double>(s.weights().data(), s.weights().size()), 0);
  record_volume(o, what, s);
}

void record(Outputs& o, const std::string& what, const BlendedVolume& s) {
  record_volume(o, what, s);
  if (s.has_exact_form()) record(o, what + " to_bspline", s.to_bspline());
}

const char* name(Parametrization p) {
  return p == Parametrization::uniform ? "uniform" : (p == Parametrization::chord ? "chord" : "centripetal");
}

constexpr Parametrization kParams[] = {Parametrization::uniform, Parametrization::chord, Parametrization::centripetal};

// ------------------------------------------------------------------ curves

TEST(Scaling, CurveInterpolationEveryParametrizationAndEndDerivatives) {
  auto g = test::rng(900);
  for (int trial = 0; trial < 4; ++trial) {
    const auto q = test::random_polyline(g, 4 + 3 * static_cast<std::size_t>(trial), 0.45);
    const Vec3 d0 = test::random_point(g, 4), d1 = test::random_point(g, 4);
    for (auto param : kParams)
      for (bool ends : {false, true})
        expect_scale_free(detail::cat("curve ", trial, " ", name(param), ends ? " with end derivatives" : ""), [&](int k) {
          CurveInterpolationOptions o;
          o.param = param;
          if (ends) {
            o.start_derivative = sc(d0, k);
            o.end_derivative = sc(d1, k);
          }
          const auto r = interpolate_curve(sc(q, k), o);
          Outputs out;
          out.add("params", r.params, 0);
          out.add("curve_parameters", curve_parameters(sc(q, k), param), 0);
          record(out, "curve", r.curve);
          return out;
        });
    // Given parameters and degree.
    expect_scale_free(detail::cat("curve ", trial, " given parameters"), [&](int k) {
      CurveInterpolationOptions o;
      o.degree = 2;
      o.params = linspace(0, 1, q.size());
      Outputs out;
      record(out, "curve", interpolate_curve(sc(q, k), o).curve);
      return out;
    });
  }
}

TEST(Scaling, HermiteCurvesAndTheirExactForm) {
  auto g = test::rng(901);
  for (int trial = 0; trial < 3; ++trial) {
    const auto q = test::random_polyline(g, 3 + 2 * static_cast<std::size_t>(trial), 0.4);
    std::vector<Vec3> tangents;
    for (std::size_t i = 0; i < q.size(); ++i) tangents.push_back(test::random_point(g, 3));
    std::vector<double> params = linspace(0, 1, q.size());
    params[1] = 0.6 * params[1] + 0.4 * params[2];  // not uniform
    for (auto rule : {TangentRule::catmull_rom, TangentRule::bessel})
      for (bool given : {false, true})
        expect_scale_free(detail::cat("Hermite curve ", trial, given ? " given tangents" : " estimated tangents"),
                          [&](int k) {
                            const HermiteCurve c(sc(q, k), given ? sc(tangents, k) : std::vector<Vec3>{}, params, rule);
                            Outputs out;
                            out.add("tangents", c.tangents(), 1);
                            for (double t : kT)
                              for (int d = 0; d <= 3; ++d) out.add(detail::cat("C^(", d, ")(", t, ")"), c.derivative(t, d), 1);
                            record(out, "to_bspline", c.to_bspline());
                            return out;
                          });
  }
}

// ------------------------------------------------------------------ grid interpolation

// A grid with a pole: row 0 collapsed to one point (zero chords along v there).
PointGrid polar_grid(std::mt19937_64& g, std::size_t nu, std::size_t nv) {
  PointGrid q({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const double r = static_cast<double>(i) / static_cast<double>(nu - 1);
      const double a = 1.7 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(nv - 1);
      q(i, j) = {r * std::cos(a), r * std::sin(a), 0.5 * r * r + (i > 0 ? 0.05 * test::uniform(g) : 0.0)};
    }
  return q;
}

TEST(Scaling, SurfaceInterpolationEveryParametrization) {
  auto g = test::rng(902);
  std::vector<std::pair<std::string, PointGrid>> grids;
  grids.emplace_back("random 5x7", test::random_grid(g, 5, 7));
  grids.emplace_back("random 9x4", test::random_grid(g, 9, 4));
  grids.emplace_back("random 2x3", test::random_grid(g, 2, 3));
  grids.emplace_back("polar 6x9", polar_grid(g, 6, 9));
  for (const auto& [what, q] : grids)
    for (auto param : kParams)
      expect_scale_free(what + " " + name(param), [&](int k) {
        SurfaceInterpolationOptions o;
        o.param = param;
        const PointGrid data = sc(q, k);
        const auto r = interpolate_surface(data, o);
        Outputs out;
        out.add("params u", r.params_u, 0);
        out.add("params v", r.params_v, 0);
        out.add("grid_parameters u", grid_parameters(data, 0, param), 0);
        out.add("grid_parameters v", grid_parameters(data, 1, param), 0);
        record(out, "surface", r.surface);
        return out;
      });
}

TEST(Scaling, VolumeInterpolationEveryParametrization) {
  auto g = test::rng(903);
  for (const auto& shape : {PointGrid3::shape_type{4, 5, 3}, PointGrid3::shape_type{3, 2, 6}}) {
    PointGrid3 q(shape);
    for (std::size_t i = 0; i < shape[0]; ++i)
      for (std::size_t j = 0; j < shape[1]; ++j)
        for (std::size_t l = 0; l < shape[2]; ++l)
          q(i, j, l) = Vec3{static_cast<double>(i), static_cast<double>(j), static_cast<double>(l)} + test::random_point(g, 0.3);
    for (auto param : kParams)
      expect_scale_free(detail::cat("volume ", shape[0], "x", shape[1], "x", shape[2], " ", name(param)), [&](int k) {
        VolumeInterpolationOptions o;
        o.param = param;
        const PointGrid3 data = sc(q, k);
        const auto r = interpolate_volume(data, o);
        Outputs out;
        out.add("params u", r.params_u, 0);
        out.add("params v", r.params_v, 0);
        out.add("params w", r.params_w, 0);
        for (int a = 0; a < 3; ++a) out.add(detail::cat("grid_parameters ", a), grid_parameters(data, a, param), 0);
        record(out, "volume", r.volume);
        return out;
      });
  }
}

// Grids whose chords leave the range of their squares while the grid as a whole is
// not of extreme scale (it is solved as given, not scaled first), so that the chord
// pass's recomputation of single chords is what keeps them scale-free: at scale 2^0
// every chord takes the vectorized path, at the scales below the out-of-range ones
// are recomputed, and the two must agree to the bit (fused multiply-adds included).
// Strip: 2^-300 and 2^-301 underflow the squares to zero (the old code refused the
// grid: "every line along v has zero length"), 2^-200 leaves them normal but below
// the 2^-900 mark; bulge: 2^350 and 2^351 overflow them; odd scales for centripetal.
TEST(Scaling, GridChordsOutOfRangeInsideAnOrdinaryGrid) {
  auto g = test::rng(904);
  // A strip 2^-300 wide: scaled by 2^-300 its chords along v are near 2^-600, whose
  // squares underflow to zero, while its length along u (~8) keeps the grid ordinary.
  PointGrid strip({9, 6});
  for (std::size_t i = 0; i < 9; ++i) {
    const double x = static_cast<double>(i) + 0.3 * test::uniform(g);
    for (std::size_t j = 0; j < 6; ++j)
      strip(i, j) = {x, std::ldexp(static_cast<double>(j) + 0.3 * test::uniform(g), -300),
                     std::ldexp(0.2 * test::uniform(g), -300)};
  }
  // A bulge: first and last rows near the origin, the rows between out at 2^200.
  // Scaled by 2^350 the end rows (which give the grid its scale) stay below 2^400
  // while the chords between the inner rows, near 2^550, have squares beyond DBL_MAX.
  PointGrid bulge({7, 5});
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = 0; j < 5; ++j) {
      const bool end = i == 0 || i == 6;
      const double r = end ? 0.01 * static_cast<double>(j) : std::ldexp(1.0 + 0.2 * static_cast<double>(i), 200);
      const double a = 0.3 * static_cast<double>(j) + 0.1 * test::uniform(g);
      const double z = end ? 0.5 * static_cast<double>(i) / 6 : std::ldexp(static_cast<double>(i) + 0.2 * test::uniform(g), 200);
      bulge(i, j) = {r * std::cos(a), r * std::sin(a), z};
    }
  for (const auto& [what, q, scales] : {std::tuple{"strip", &strip, std::vector<int>{-300, -200, -301, 250}},
                                        std::tuple{"bulge", &bulge, std::vector<int>{350, 351, -150, -151}}})
    for (auto param : kParams)
      expect_scale_free(std::string(what) + " " + name(param), [&](int k) {
        SurfaceInterpolationOptions o;
        o.param = param;
        const auto r = interpolate_surface(sc(*q, k), o);
        Outputs out;
        out.add("params u", r.params_u, 0);
        out.add("params v", r.params_v, 0);
        out.add("control points", std::span<const Vec3>(r.surface.control_points().data(), r.surface.control_points().size()), 1);
        return out;
      }, scales);
}

// The reported failure: coordinates near 1e300 or 1e-300 (not powers of two)
// interpolate, and the surface passes through its points.
TEST(Scaling, GridsNear1e300And1eMinus300PassThroughTheirPoints) {
  auto g = test::rng(905);
  const PointGrid base = test::random_grid(g, 8, 6);
  PointGrid3 base3({4, 3, 5});
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t l = 0; l < 5; ++l)
        base3(i, j, l) = Vec3{static_cast<double>(i), static_cast<double>(j), static_cast<double>(l)} + test::random_point(g, 0.3);
  for (double size : {1e300, 1e-300, 1e150, 1e-160})
    for (auto param : kParams) {
      PointGrid q = base;
      for (Vec3& p : q.values()) p *= size;
      const double diag = test::bbox_diagonal(q.values());
      const auto r = interpolate_surface(q, with_param<SurfaceInterpolationOptions>(param));
      double e = 0;
      for (std::size_t i = 0; i < 8; ++i)
        for (std::size_t j = 0; j < 6; ++j) e = std::max(e, distance(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j)));
      EXPECT_LT(e, 1e-12 * diag) << size << " " << name(param);  // banded solve rounding, relative to the data

      PointGrid3 q3 = base3;
      for (Vec3& p : q3.values()) p *= size;
      const double diag3 = test::bbox_diagonal(q3.values());
      const auto r3 = interpolate_volume(q3, with_param<VolumeInterpolationOptions>(param));
      double e3 = 0;
      for (std::size_t i = 0; i < 4; ++i)
        for (std::size_t j = 0; j < 3; ++j)
          for (std::size_t l = 0; l < 5; ++l)
            e3 = std::max(e3, distance(r3.volume.point(r3.params_u[i], r3.params_v[j], r3.params_w[l]), q3(i, j, l)));
      EXPECT_LT(e3, 1e-12 * diag3) << size << " " << name(param);

      std::vector<Vec3> c(base.values().begin(), base.values().begin() + 7);
      for (Vec3& p : c) p *= size;
      const auto rc = interpolate_curve(c, with_param<CurveInterpolationOptions>(param));
      for (std::size_t i = 0; i < c.size(); ++i)
        EXPECT_LT(distance(rc.curve.point(rc.params[i]), c[i]), 1e-12 * test::bbox_diagonal(c)) << size;
    }
}

// Subnormal coordinates (below 2.2e-308) are outside the promise of bit-exactness,
// but they are no zero-length grid either: they interpolate, to the spacing of the
// subnormal numbers near them.
TEST(Scaling, SubnormalGridsInterpolate) {
  auto g = test::rng(906);
  PointGrid q = test::random_grid(g, 6, 5);
  for (Vec3& p : q.values()) p *= 1e-310;
  const double diag = test::bbox_diagonal(q.values());
  for (auto param : kParams) {
    const auto r = interpolate_surface(q, with_param<SurfaceInterpolationOptions>(param));
    double e = 0;
    for (std::size_t i = 0; i < 6; ++i)
      for (std::size_t j = 0; j < 5; ++j) e = std::max(e, distance(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j)));
    // Subnormals near 1e-310 hold ~44 bits: a relative 1e-12 is out of reach, 1e-9 is
    // a few of their units.
    EXPECT_LT(e, 1e-9 * diag) << name(param);
  }
}

// ------------------------------------------------------------------ patches from corners and curves

TEST(Scaling, BilinearRuledAndHermitePatches) {
  auto g = test::rng(907);
  for (int trial = 0; trial < 3; ++trial) {
    const Vec3 p[4] = {test::random_point(g), test::random_point(g) + Vec3{0, 1, 0}, test::random_point(g) + Vec3{1, 0, 0},
                       test::random_point(g) + Vec3{1, 1, 0}};
    expect_scale_free(detail::cat("bilinear ", trial), [&](int k) {
      Outputs out;
      record(out, "bilinear", bilinear(sc(p[0], k), sc(p[1], k), sc(p[2], k), sc(p[3], k)));
      return out;
    });
    const auto s = test::random_bspline_surface(g, 3, 2, 5, 4);
    const auto c0 = test::iso_curve(s, 1, 0.0), c1 = test::iso_curve(s, 1, 1.0);
    expect_scale_free(detail::cat("ruled ", trial), [&](int k) {
      Outputs out;
      record(out, "ruled", ruled(sc(c0, k), sc(c1, k)));
      return out;
    });
    std::array<HermiteCorner, 4> corners;
    for (std::size_t n = 0; n < 4; ++n)
      corners[n] = {p[n], test::random_point(g, 2), test::random_point(g, 2), test::random_point(g, 2)};
    expect_scale_free(detail::cat("hermite_patch ", trial), [&](int k) {
      std::array<HermiteCorner, 4> c = corners;
      for (auto& x : c) x = {sc(x.p, k), sc(x.du, k), sc(x.dv, k), sc(x.duv, k)};
      Outputs out;
      record(out, "hermite_patch", hermite_patch(c));
      return out;
    });
  }
}

CoonsBoundary sc(const CoonsBoundary& b, int k) { return {sc(b.v0, k), sc(b.v1, k), sc(b.u0, k), sc(b.u1, k)}; }
CoonsCrossDerivatives sc(const CoonsCrossDerivatives& d, int k) {
  return {sc(d.v0, k), sc(d.v1, k), sc(d.u0, k), sc(d.u1, k)};
}

TEST(Scaling, CoonsLinearHermiteAndWithCrossDerivatives) {
  auto g = test::rng(908);
  for (int trial = 0; trial < 3; ++trial) {
    const auto s = test::random_bspline_surface(g, 3, 3, 5 + static_cast<std::size_t>(trial), 6);
    const CoonsBoundary b = test::boundary_of(s);
    const CoonsCrossDerivatives d = test::cross_of(s);
    for (bool hermite_blend : {false, true})
      expect_scale_free(detail::cat("coons ", trial, hermite_blend ? " hermite blend" : " linear"), [&](int k) {
        CoonsOptions o;
        if (hermite_blend) o.blend_u = o.blend_v = Blend::hermite();
        Outputs out;
        record(out, "coons", coons(sc(b, k), o));
        return out;
      });
    expect_scale_free(detail::cat("coons ", trial, " with cross-derivatives"), [&](int k) {
      Outputs out;
      record(out, "coons", coons(sc(b, k), sc(d, k)));
      return out;
    });
    // Given twists: the surface's own, and at p11 one that disagrees, blended by Gregory's correction.
    std::array<std::optional<Vec3>, 4> twists;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) twists[static_cast<std::size_t>(2 * i + j)] = s.derivative(i, j, 1, 1);
    expect_scale_free(detail::cat("coons ", trial, " given twists"), [&](int k) {
      HermiteCoonsOptions o;
      for (std::size_t n = 0; n < 4; ++n) o.twists[n] = sc(*twists[n], k);
      Outputs out;
      record(out, "coons", coons(sc(b, k), sc(d, k), o));
      return out;
    });
    expect_scale_free(detail::cat("coons ", trial, " Gregory"), [&](int k) {
      HermiteCoonsOptions o;
      o.twists[3] = sc(*twists[3] + Vec3{1, -2, 0.5}, k);
      o.twist_correction = TwistCorrection::gregory;
      const auto c = coons(sc(b, k), sc(d, k), o);
      EXPECT_FALSE(c.has_exact_form());
      Outputs out;
      record(out, "coons", c);
      return out;
    });
  }
}


CurveNetwork sc(const CurveNetwork& n, int k) {
  CurveNetwork m = n;
  for (auto& c : m.u_curves) c = sc(c, k);
  for (auto& c : m.v_curves) c = sc(c, k);
  return m;
}

TEST(Scaling, CurveNetworksEveryMethodCrossingsGivenAndFound) {
  auto g = test::rng(909);
  for (int trial = 0; trial < 2; ++trial) {
    const auto s = test::random_bspline_surface(g, 3, 3, 6, 5, 0.2);
    const CurveNetwork given = test::network_on(s, {0, 0.3, 0.55, 1}, {0, 0.45, 1});
    CurveNetwork found = given;
    found.u_params.clear();
    found.v_params.clear();
    expect_scale_free(detail::cat("network_parameters ", trial), [&](int k) {
      const auto p = network_parameters(sc(found, k));
      Outputs out;
      out.add("u_params", p.u_params, 0);
      out.add("v_params", p.v_params, 0);
      return out;
    });
    for (auto m : {NetworkMethod::gordon, NetworkMethod::coons_linear, NetworkMethod::coons_hermite})
      for (const CurveNetwork* n : std::initializer_list<const CurveNetwork*>{&given, &found})
        expect_scale_free(detail::cat("network ", trial, " method ", static_cast<int>(m), n == &given ? " given" : " found"),
                          [&](int k) {
                            Outputs out;
                            record(out, "network", curve_network(sc(*n, k), {m, {}, {}}));
                            return out;
                          });
  }
}

// ------------------------------------------------------------------ volumes


VolumeFaces sc(const VolumeFaces& f, int k) {
  return {sc(f.u0, k), sc(f.u1, k), sc(f.v0, k), sc(f.v1, k), sc(f.w0, k), sc(f.w1, k)};
}

VolumeCrossDerivatives cross_of(const BSplineVolume& b) {
  using test::iso_surface;
  return {iso_surface(b, 0, 0, 1), iso_surface(b, 0, 1, 1), iso_surface(b, 1, 0, 1),
          iso_surface(b, 1, 1, 1), iso_surface(b, 2, 0, 1), iso_surface(b, 2, 1, 1)};
}

VolumeCrossDerivatives sc(const VolumeCrossDerivatives& d, int k) {
  VolumeCrossDerivatives out;
  for (auto [from, to] : {std::pair{&d.u0, &out.u0}, {&d.u1, &out.u1}, {&d.v0, &out.v0}, {&d.v1, &out.v1},
                          {&d.w0, &out.w0}, {&d.w1, &out.w1}})
    if (*from) *to = sc(**from, k);
  return out;
}

TEST(Scaling, TrilinearAndHermiteVolumes) {
  auto g = test::rng(910);
  for (int trial = 0; trial < 3; ++trial) {
    std::array<Vec3, 8> corners;
    for (std::size_t n = 0; n < 8; ++n)
      corners[n] = Vec3{static_cast<double>(n >> 2), static_cast<double>((n >> 1) & 1), static_cast<double>(n & 1)} +
                   test::random_point(g, 0.25);
    expect_scale_free(detail::cat("trilinear ", trial), [&](int k) {
      std::array<Vec3, 8> c;
      for (std::size_t n = 0; n < 8; ++n) c[n] = sc(corners[n], k);
      Outputs out;
      record(out, "trilinear", trilinear(c));
      return out;
    });
    const auto frame = test::frame_of(test::random_bspline_volume(g, 3, 2, 3, 4, 3, 4, 0.3));
    expect_scale_free(detail::cat("hermite_volume ", trial), [&](int k) {
      auto c = frame;
      for (auto& x : c)
        x = {sc(x.p, k), sc(x.du, k), sc(x.dv, k), sc(x.dw, k), sc(x.duv, k), sc(x.duw, k), sc(x.dvw, k), sc(x.duvw, k)};
      Outputs out;
      record(out, "hermite_volume", hermite_volume(c));
      return out;
    });
  }
}

TEST(Scaling, CoonsVolumesLinearBlendedAndHermite) {
  auto g = test::rng(911);
  for (int trial = 0; trial < 2; ++trial) {
    const auto b = test::random_bspline_volume(g, 3, 2, 3, 4, 3, 4, 0.3);
    const VolumeFaces faces = test::faces_of(b);
    const VolumeCrossDerivatives all = cross_of(b);
    VolumeCrossDerivatives some;
    some.u0 = all.u0;
    some.w1 = all.w1;
    expect_scale_free(detail::cat("coons_volume ", trial), [&](int k) {
      Outputs out;
      record(out, "coons_volume", coons_volume(sc(faces, k)));
      return out;
    });
    expect_scale_free(detail::cat("coons_volume ", trial, " hermite blend"), [&](int k) {
      CoonsVolumeOptions o;
      o.blend_u = o.blend_w = Blend::hermite();
      Outputs out;
      record(out, "coons_volume", coons_volume(sc(faces, k), o));
      return out;
    });
    for (const VolumeCrossDerivatives* d : std::initializer_list<const VolumeCrossDerivatives*>{&all, &some})
      expect_scale_free(detail::cat("coons_volume ", trial, d == &all ? " all" : " two", " cross-derivatives"), [&](int k) {
        Outputs out;
        record(out, "coons_volume", coons_volume(sc(faces, k), sc(*d, k)));
        return out;
      });
  }
}

// ------------------------------------------------------------------ errors scale too

// The message of the error `f()` throws, or "" (and a failure) when it throws none.
std::string message_of(const std::function<void()>& f, errc code) {
  try {
    f();
  } catch (const error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected interpatch::error " << to_string(code);
  return "";
}

// The faces of the unit cube, as in the example of coons_volume.hpp: bilinear, every
// point of them computed exactly.
BSplineSurface box_face(int axis, double t, double shift = 0) {
  const KnotVector lin(1, {0, 0, 1, 1});
  PointGrid cp({2, 2});
  for (std::size_t a = 0; a < 2; ++a)
    for (std::size_t b = 0; b < 2; ++b) {
      Vec3 p;
      p[axis] = t + shift;
      p[axis == 0 ? 1 : 0] = static_cast<double>(a);
      p[axis == 2 ? 1 : 2] = static_cast<double>(b);
      cp(a, b) = p;
    }
  return BSplineSurface(lin, lin, cp);
}

// Errors at every scale of kScales but -900 and -501: there the tolerances, 1e-7
// of the data's size, would be subnormal (2^-900 × 1e-7 is, with the gap below it).
const std::vector<int> kErrorScales = {500, -500, 501, 900, 300, -300, 1};

// A gap of 1.5 times the default tolerance is refused at every scale, the message
// naming the gap and the tolerance scaled; one of 0.5 times it is accepted.
TEST(Scaling, GapsAndTolerancesScaleWithTheData) {
  auto g = test::rng(912);
  const auto s = test::random_bspline_surface(g, 3, 3, 5, 5);
  const CoonsBoundary b = test::boundary_of(s);
  auto diagonal_of = [](std::initializer_list<const BSplineCurve*> cs) {
    std::vector<Vec3> p;
    for (const auto* c : cs) p.insert(p.end(), c->control_points().begin(), c->control_points().end());
    return test::bbox_diagonal(p);
  };
  for (double factor : {1.5, 0.5}) {
    SCOPED_TRACE(detail::cat(factor, " times the tolerance"));
    // Coons: corner p00 of u0 moved along z. The gap and the tolerance are computed
    // as the library does: the ends of a clamped curve are its end control points.
    CoonsBoundary moved = b;
    std::vector<Vec3> cp = moved.u0.control_points();
    cp.front().z += factor * 1e-7 * diagonal_of({&b.v0, &b.v1, &b.u0, &b.u1});
    moved.u0 = BSplineCurve(moved.u0.knots(), cp);
    const double gap = distance(moved.v0.control_points().front(), moved.u0.control_points().front());
    const double tol = 1e-7 * diagonal_of({&moved.v0, &moved.v1, &moved.u0, &moved.u1});
    for (int k : kErrorScales) {
      const auto f = [&] { (void)coons(sc(moved, k)); };
      if (factor < 1) {
        EXPECT_NO_THROW(f()) << k;
        continue;
      }
      const std::string m = message_of(f, errc::corner_gap);
      const std::string want = "gap " + detail::num(std::ldexp(gap, k)) + " (tolerance " + detail::num(std::ldexp(tol, k)) + ")";
      EXPECT_NE(m.find(want), std::string::npos) << m << "\nlacks " << want << " at scale 2^" << k;
    }

    // Network: v_curves[1] moved along z; the first node it misses is (1, 0).
    CurveNetwork n = test::network_on(s, {0, 0.4, 1}, {0, 0.5, 1});
    std::vector<Vec3> all;
    for (const auto* list : {&n.u_curves, &n.v_curves})
      for (const auto& c : *list) all.insert(all.end(), c.control_points().begin(), c.control_points().end());
    std::vector<Vec3> vp = n.v_curves[1].control_points();
    for (Vec3& p : vp) p.z += factor * 1e-7 * test::bbox_diagonal(all);
    n.v_curves[1] = BSplineCurve(n.v_curves[1].knots(), vp);
    // The gap named is the closest distance of the two curves, found as the library
    // finds it; its search scales exactly with the data (powers of two).
    const detail::CurveSamples s0(n.u_curves[0]), s1(n.v_curves[1]);
    const double ngap = detail::closest_points(n.u_curves[0], n.v_curves[1], false, false, 0.0, s0, s1).gap;
    std::vector<Vec3> moved_all;  // the tolerance is the library's: of the curves as moved
    for (const auto* list : {&n.u_curves, &n.v_curves})
      for (const auto& c : *list) moved_all.insert(moved_all.end(), c.control_points().begin(), c.control_points().end());
    const double ntol = 1e-7 * test::bbox_diagonal(moved_all);
    for (int k : kErrorScales) {
      const auto f = [&] { (void)curve_network(sc(n, k)); };
      if (factor < 1) {
        EXPECT_NO_THROW(f()) << k;
        continue;
      }
      const std::string m = message_of(f, errc::network_gap);
      const std::string want = detail::num(std::ldexp(ngap, k)) + " apart (tolerance " + detail::num(std::ldexp(ntol, k)) + ")";
      EXPECT_NE(m.find(want), std::string::npos) << m << "\nlacks " << want << " at scale 2^" << k;
    }

    // Hermite Coons: cross-derivative u0 off the boundary tangent S_u at p00 by
    // `factor` times the derivative tolerance 1e-7 max(|a|, |b|, diagonal) (|b| grows
    // by far less than the margin). Gregory's correction: the twists this moves too
    // are no error.
    CoonsCrossDerivatives d = test::cross_of(s);
    const Vec3 su = b.v0.derivative(0, 1);
    std::vector<Vec3> dp = d.u0.control_points();
    dp.front().z += factor * 1e-7 * std::max(norm(su), diagonal_of({&b.v0, &b.v1, &b.u0, &b.u1}));
    d.u0 = BSplineCurve(d.u0.knots(), dp);
    const double differ = distance(su, d.u0.control_points().front());
    HermiteCoonsOptions gregory;
    gregory.twist_correction = TwistCorrection::gregory;
    for (int k : kErrorScales) {
      const auto f = [&] { (void)coons(sc(b, k), sc(d, k), gregory); };
      if (factor < 1) {
        EXPECT_NO_THROW(f()) << k;
        continue;
      }
      const std::string m = message_of(f, errc::tangent_mismatch);
      const std::string want = "they differ by " + detail::num(std::ldexp(differ, k));
      EXPECT_NE(m.find(want), std::string::npos) << m << "\nlacks " << want << " at scale 2^" << k;
    }

    // Coons volume: the unit cube with face u0 moved inwards by `shift` along x; the
    // bounding box stays the unit cube, the gap along each edge of u0 is the shift.
    const double vtol = 1e-7 * norm(Vec3{1, 1, 1});
    const double shift = factor * vtol;
    const VolumeFaces faces{box_face(0, 0, shift), box_face(0, 1), box_face(1, 0), box_face(1, 1), box_face(2, 0), box_face(2, 1)};
    for (int k : kErrorScales) {
      const auto f = [&] { (void)coons_volume(sc(faces, k)); };
      if (factor < 1) {
        EXPECT_NO_THROW(f()) << k;
        continue;
      }
      const std::string m = message_of(f, errc::corner_gap);
      // The first edge checked is (u=0, v=0), along w.
      for (const std::string& want : {"(u=0, v=0) by " + detail::num(std::ldexp(shift, k)) + " at w = ",
                                      "(tolerance " + detail::num(std::ldexp(vtol, k)) + ")"})
        EXPECT_NE(m.find(want), std::string::npos) << m << "\nlacks " << want << " at scale 2^" << k;
    }
  }

  // Coincident points of a curve: the polyline's length in the message, scaled.
  std::vector<Vec3> q = test::random_polyline(g, 6, 0.3);
  q[3] = q[2];
  double length = 0;
  for (std::size_t i = 1; i < q.size(); ++i) length += distance(q[i], q[i - 1]);
  for (int k : kScales) {
    const std::string m = message_of([&] { (void)interpolate_curve(sc(q, k)); }, errc::zero_chord);
    const std::string want = "points 2 and 3 coincide (chord 0, polyline length " + detail::num(std::ldexp(length, k)) + ")";
    EXPECT_NE(m.find(want), std::string::npos) << m << "\nlacks " << want << " at scale 2^" << k;
  }

  // A grid of extreme scale (solved scaled) names a non-finite point as given.
  PointGrid grid = sc(test::random_grid(g, 4, 5), 600);
  grid(2, 3).x = NAN;
  const std::string m = message_of([&] { (void)interpolate_surface(grid); }, errc::not_finite);
  EXPECT_NE(m.find("point [2][3] is " + detail::num(grid(2, 3))), std::string::npos) << m;
}

// ------------------------------------------------------------------ the primitives

TEST(Scaling, NormDistanceAndTripleProductAtTheEndsOfTheRange) {
  auto g = test::rng(913);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a = test::random_point(g, 10), b = test::random_point(g, 10), c = test::random_point(g, 10);
    for (int k : {1000, 600, 520, 511, 500, -500, -520, -540, -560, -600, -1000}) {
      EXPECT_EQ(norm(sc(a, k)), std::ldexp(norm(a), k)) << k;
      EXPECT_EQ(distance(sc(a, k), sc(b, k)), std::ldexp(distance(a, b), k)) << k;
      // Each column at its own scale; det scaled by the product where that is a normal double.
      const int k2 = k / 2, k3 = -k / 3;
      const double want = std::ldexp(triple(a, b, c), k + k2 + k3);
      if (std::isnormal(want)) {
        EXPECT_EQ(triple(sc(a, k), sc(b, k2), sc(c, k3)), want) << k;
      }
    }
  }
  EXPECT_EQ(norm(Vec3{0x1p1000 * 3, 0x1p1000 * 4, 0}), 0x1p1000 * 5);  // the squares are 2^2000: beyond DBL_MAX
  EXPECT_EQ(norm(Vec3{0x1p-1000 * 3, 0, 0x1p-1000 * 4}), 0x1p-1000 * 5);  // the squares underflow to zero
  EXPECT_EQ(norm(Vec3{}), 0.0);
  EXPECT_TRUE(std::isnan(norm(Vec3{NAN, 1, 1})));
  EXPECT_EQ(norm(Vec3{INFINITY, 1, 1}), INFINITY);
}

}  // namespace
}  // namespace interpatch
