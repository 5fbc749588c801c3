// Batch evaluation into the caller's memory (Surface::evaluate_into and
// Volume::evaluate_into, surface.hpp and volume.hpp), for every kind of evaluator:
// the B-spline contraction, the blended sums, and the pointwise base versions
// (Gregory-corrected Coons patches, blended volumes). The whole grid gives the bits
// evaluate() returns, into a buffer that held garbage; so does any split of the u
// values into blocks evaluated one after the other into one reused buffer, which
// writes nothing past the block. Large grids are split between threads as a whole
// and not in blocks: the bits are the same.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "base/parallel.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/volume_patches.hpp"
#include "surface_util.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

// What the caller's memory holds before an evaluation: a NaN with a payload no
// evaluation produces, so that a point left unwritten shows as differing bits.
const Vec3 garbage{std::bit_cast<double>(std::uint64_t{0x7ff8dead0000beefULL}),
                   std::bit_cast<double>(std::uint64_t{0xfff4000000c0ffeeULL}),
                   std::bit_cast<double>(std::uint64_t{0x7ff0000badbadbadULL})};

bool same_bits(std::span<const Vec3> a, std::span<const Vec3> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

// n parameters in [0, 1] in no order: both ends, the given knots (where the basis
// functions change) and uniform random values.
std::vector<double> random_parameters(std::mt19937_64& g, std::size_t n, std::span<const double> knots = {}) {
  std::vector<double> t(n);
  for (double& x : t) x = test::uniform(g, 0, 1);
  t[0] = 1;
  t[n / 2] = 0;
  for (std::size_t k = 0; k < knots.size() && 2 + 2 * k < n; ++k) t[1 + 2 * k] = knots[k];
  return t;
}

// evaluate_into(us, out) of one evaluator over fixed parameters in the other
// directions (per_row points for each u), checked against `expected`, what
// evaluate() returned for all of `us`:
//   - over the whole grid, into a buffer of garbage, with and without progress
//     reports (fractions in [0, 1], never decreasing, the last one 1);
//   - block by block along u with blocks of each size in `blocks` (the last block
//     shorter), into one buffer reused from block to block, the rest of which keeps
//     what it held.
template <class Into>
void expect_same_bits_whole_and_in_blocks(std::span<const Vec3> expected, std::span<const double> us,
                                          std::size_t per_row, std::initializer_list<std::size_t> blocks,
                                          const Into& into) {
  ASSERT_EQ(expected.size(), us.size() * per_row);
  std::vector<Vec3> whole(expected.size(), garbage);
  into(us, std::span<Vec3>(whole), progress_callback{});
  EXPECT_TRUE(same_bits(whole, expected)) << "whole grid";

  std::fill(whole.begin(), whole.end(), garbage);
  std::vector<double> reports;
  into(us, std::span<Vec3>(whole), [&](double f) { reports.push_back(f); });
  EXPECT_TRUE(same_bits(whole, expected)) << "whole grid with progress reports";
  ASSERT_FALSE(reports.empty());
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  EXPECT_GE(reports.front(), 0.0);
  EXPECT_EQ(reports.back(), 1.0);

  for (const std::size_t rows : blocks) {
    SCOPED_TRACE("blocks of " + std::to_string(rows) + " rows");
    ASSERT_TRUE(rows == 1 || us.size() % rows != 0) << "the last block should be shorter";
    std::vector<Vec3> buffer(rows * per_row, garbage);
    for (std::size_t i0 = 0; i0 < us.size(); i0 += rows) {
      const std::size_t n = std::min(rows, us.size() - i0);
      const std::vector<Vec3> before = buffer;
      into(us.subspan(i0, n), std::span<Vec3>(buffer).first(n * per_row), progress_callback{});
      EXPECT_TRUE(same_bits(std::span<const Vec3>(buffer).first(n * per_row),
                            expected.subspan(i0 * per_row, n * per_row)))
          << "rows " << i0 << " to " << i0 + n - 1;
      EXPECT_TRUE(same_bits(std::span<const Vec3>(buffer).subspan(n * per_row),
                            std::span<const Vec3>(before).subspan(n * per_row)))
          << "written past the block of rows " << i0 << " to " << i0 + n - 1;
    }
  }
}

void expect_surface_into_matches_evaluate(const Surface& s, std::span<const double> us, std::span<const double> vs,
                                          std::initializer_list<std::size_t> blocks) {
  const PointGrid expected = s.evaluate(us, vs);
  expect_same_bits_whole_and_in_blocks(std::span<const Vec3>(expected.data(), expected.size()), us, vs.size(), blocks,
                                       [&](std::span<const double> u, std::span<Vec3> out, const progress_callback& p) {
                                         s.evaluate_into(u, vs, out, p);
                                       });
  // The same through rows(vs): what depends on v worked out once for every block.
  SCOPED_TRACE("through rows(vs)");
  const auto rows = s.rows(vs);
  expect_same_bits_whole_and_in_blocks(std::span<const Vec3>(expected.data(), expected.size()), us, vs.size(), blocks,
                                       [&](std::span<const double> u, std::span<Vec3> out, const progress_callback& p) {
                                         rows->evaluate_into(u, out, p);
                                       });
}

void expect_volume_into_matches_evaluate(const Volume& v, std::span<const double> us, std::span<const double> vs,
                                         std::span<const double> ws, std::initializer_list<std::size_t> blocks) {
  const PointGrid3 expected = v.evaluate(us, vs, ws);
  expect_same_bits_whole_and_in_blocks(std::span<const Vec3>(expected.data(), expected.size()), us,
                                       vs.size() * ws.size(), blocks,
                                       [&](std::span<const double> u, std::span<Vec3> out, const progress_callback& p) {
                                         v.evaluate_into(u, vs, ws, out, p);
                                       });
}

// The same surface with random weights in [0.5, 2]: a rational one.
BSplineSurface with_random_weights(std::mt19937_64& g, const BSplineSurface& s) {
  Grid<double, 2> w(s.control_points().shape());
  for (double& x : w.values()) x = test::uniform(g, 0.5, 2.0);
  return BSplineSurface(s.knots_u(), s.knots_v(), s.control_points(), w);
}

// A bicubically blended Coons patch whose corner twist disagrees with the
// cross-derivative curves, blended by Gregory's rational terms: its evaluate_into
// is the pointwise base version.
BlendedSurface gregory_patch(const BSplineSurface& src) {
  HermiteCoonsOptions o;
  o.twist_correction = TwistCorrection::gregory;
  o.twists[0] = src.derivative(0, 0, 1, 1) + Vec3{1, 2, 3};
  return coons(test::boundary_of(src), test::cross_of(src), o);
}

// A trilinear volume of random corners near the unit cube's.
BlendedVolume random_trilinear(std::mt19937_64& g) {
  std::array<Vec3, 8> c;
  for (int n = 0; n < 8; ++n)
    c[static_cast<std::size_t>(n)] =
        Vec3{double(n >> 2), double((n >> 1) & 1), double(n & 1)} + test::random_point(g, 0.2);
  return trilinear(c);
}

// An evaluator and what it is, for the messages.
template <class T>
struct Named {
  std::string name;
  std::unique_ptr<T> evaluator;
};

template <class T, class Built>
Named<T> named(std::string name, Built built) {
  return {std::move(name), std::make_unique<Built>(std::move(built))};
}

// Every kind of surface evaluator, built from the random surface `src`.
std::vector<Named<Surface>> surfaces_of(std::mt19937_64& g, const BSplineSurface& src) {
  CoonsOptions hermite_blend;
  hermite_blend.blend_u = hermite_blend.blend_v = Blend::hermite();
  std::vector<Named<Surface>> s;
  s.push_back(named<Surface>("B-spline", src));
  s.push_back(named<Surface>("rational B-spline", with_random_weights(g, src)));
  s.push_back(named<Surface>("interpolated", interpolate_surface(test::random_grid(g, 9, 7)).surface));
  s.push_back(named<Surface>("linear Coons", coons(test::boundary_of(src))));
  s.push_back(named<Surface>("Hermite-blended Coons", coons(test::boundary_of(src), hermite_blend)));
  s.push_back(named<Surface>("bicubically blended Coons", coons(test::boundary_of(src), test::cross_of(src))));
  s.push_back(named<Surface>("Gregory-corrected Coons", gregory_patch(src)));
  return s;
}

// Every kind of volume evaluator, built from the random volume `src`.
std::vector<Named<Volume>> volumes_of(std::mt19937_64& g, const BSplineVolume& src) {
  std::vector<Named<Volume>> v;
  v.push_back(named<Volume>("B-spline", src));
  v.push_back(named<Volume>("rational B-spline", test::random_bspline_volume(g, 2, 3, 1, 5, 6, 4, 0.3, true)));
  v.push_back(named<Volume>("trilinear", random_trilinear(g)));
  v.push_back(named<Volume>("transfinite (Coons)", coons_volume(test::faces_of(src))));
  return v;
}

// Runs on_surface for every kind of small surface and on_volume for every kind of
// small volume, each over [0, 1]^2 or [0, 1]^3.
template <class OnSurface, class OnVolume>
void for_every_evaluator(unsigned seed, const OnSurface& on_surface, const OnVolume& on_volume) {
  auto g = test::rng(seed);
  for (const auto& [name, s] : surfaces_of(g, test::random_bspline_surface(g, 3, 2, 5, 4))) {
    SCOPED_TRACE(name + " surface");
    on_surface(*s);
  }
  for (const auto& [name, v] : volumes_of(g, test::random_bspline_volume(g, 2, 2, 2, 4, 4, 4))) {
    SCOPED_TRACE(name + " volume");
    on_volume(*v);
  }
}

TEST(EvaluateInto, SurfacesGiveTheBitsOfEvaluateWholeAndInBlocks) {
  auto g = test::rng(140);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const auto src = test::random_bspline_surface(g, 2 + trial, 3, 6 + static_cast<std::size_t>(trial), 5);
    const auto surfaces = surfaces_of(g, src);
    // Gregory's terms are in:
    ASSERT_FALSE(static_cast<const BlendedSurface&>(*surfaces.back().evaluator).has_exact_form());
    const auto us = random_parameters(g, 29, src.knots_u().values());
    const auto vs = random_parameters(g, 17, src.knots_v().values());
    for (const auto& [name, s] : surfaces) {
      SCOPED_TRACE(name);
      expect_surface_into_matches_evaluate(*s, us, vs, {1, 4, 7});
    }
  }
}

TEST(EvaluateInto, VolumesGiveTheBitsOfEvaluateWholeAndInBlocks) {
  auto g = test::rng(141);
  for (int trial = 0; trial < 3; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const auto src = test::random_bspline_volume(g, 1 + trial, 3, 2, 5, 6, 4 + static_cast<std::size_t>(trial));
    const auto volumes = volumes_of(g, src);
    const auto us = random_parameters(g, 13, src.knots_u().values());
    const auto vs = random_parameters(g, 9, src.knots_v().values());
    const auto ws = random_parameters(g, 11, src.knots_w().values());
    for (const auto& [name, v] : volumes) {
      SCOPED_TRACE(name);
      expect_volume_into_matches_evaluate(*v, us, vs, ws, {1, 4, 5});
    }
  }
}

// Grids large enough for evaluate() to split their rows between threads, evaluated
// in blocks small enough to stay on one: the split does not change a bit. Each size
// is checked against the threshold of the loop it is meant for.
TEST(EvaluateInto, LargeSurfaceGridsInBlocksGiveTheBitsOfTheThreadedWholeGrid) {
  auto g = test::rng(142);
  const auto src = test::random_bspline_surface(g, 3, 3, 12, 10);
  const std::size_t rows = 7;
  {
    const auto us = random_parameters(g, 450), vs = random_parameters(g, 600);
    const std::size_t ncv = src.control_points().extent(1);
    ASSERT_GE(us.size() * (vs.size() + ncv), detail::parallel_min_work);  // BSplineSurface::evaluate_into
    ASSERT_LT(rows * (vs.size() + ncv), detail::parallel_min_work);
    expect_surface_into_matches_evaluate(src, us, vs, {rows});
    expect_surface_into_matches_evaluate(with_random_weights(g, src), us, vs, {rows});
  }
  {
    const auto us = random_parameters(g, 300), vs = random_parameters(g, 301);
    // BlendedSurface::evaluate_into; a linear Coons patch sums 4 terms a point (a
    // boundary curve in v times f_k(u) for k = 0, 1, and one in u times g_l(v) for l = 0, 1).
    ASSERT_GE(us.size() * vs.size() * 4, detail::parallel_min_work);
    ASSERT_LT(rows * vs.size() * 4, detail::parallel_min_work);
    expect_surface_into_matches_evaluate(coons(test::boundary_of(src)), us, vs, {rows});
  }
  {
    const auto us = random_parameters(g, 150), vs = random_parameters(g, 120);
    ASSERT_GE(us.size() * vs.size(), detail::parallel_min_work / 16);  // Surface::evaluate_into, pointwise
    ASSERT_LT(rows * vs.size(), detail::parallel_min_work / 16);
    expect_surface_into_matches_evaluate(gregory_patch(src), us, vs, {rows});
  }
}

TEST(EvaluateInto, LargeVolumeGridsInBlocksGiveTheBitsOfTheThreadedWholeGrid) {
  auto g = test::rng(143);
  const auto src = test::random_bspline_volume(g, 3, 3, 3, 8, 7, 6);
  const std::size_t rows = 7;
  {
    const auto us = random_parameters(g, 72), vs = random_parameters(g, 70), ws = random_parameters(g, 69);
    const std::size_t net = src.control_points().extent(1) * src.control_points().extent(2);
    ASSERT_GE(us.size() * (vs.size() * ws.size() + net), detail::parallel_min_work);  // BSplineVolume::evaluate_into
    ASSERT_LT(rows * (vs.size() * ws.size() + net), detail::parallel_min_work);
    expect_volume_into_matches_evaluate(src, us, vs, ws, {rows});
  }
  {
    const auto us = random_parameters(g, 31), vs = random_parameters(g, 30), ws = random_parameters(g, 29);
    ASSERT_GE(us.size() * vs.size() * ws.size(), detail::parallel_min_work / 16);  // Volume::evaluate_into, pointwise
    ASSERT_LT(rows * vs.size() * ws.size(), detail::parallel_min_work / 16);
    expect_volume_into_matches_evaluate(random_trilinear(g), us, vs, ws, {rows});
    expect_volume_into_matches_evaluate(coons_volume(test::faces_of(src)), us, vs, ws, {rows});
  }
}

TEST(EvaluateInto, EmptyGridsAreAccepted) {
  const std::vector<double> none, some{0, 0.5, 1};
  for_every_evaluator(
      144,
      [&](const Surface& s) {
        EXPECT_NO_THROW(s.evaluate_into(none, some, {}));
        EXPECT_NO_THROW(s.evaluate_into(some, none, {}));
        EXPECT_NO_THROW(s.rows(some)->evaluate_into(none, {}));
        EXPECT_NO_THROW(s.rows(none)->evaluate_into(some, {}));
      },
      [&](const Volume& v) {
        EXPECT_NO_THROW(v.evaluate_into(none, some, some, {}));
        EXPECT_NO_THROW(v.evaluate_into(some, some, none, {}));
      });
}

// evaluate_normals_into: the points evaluate() gives, and the unit normals of the
// derivatives evaluate_derivatives() gives, for every kind of surface, whole and in
// blocks; at a pole too.
void expect_normals_of_the_derivatives(const Surface& s, std::span<const double> us, std::span<const double> vs) {
  const auto d = s.evaluate_derivatives(us, vs);
  std::vector<Vec3> points(us.size() * vs.size(), garbage), normals(points.size(), garbage);
  s.evaluate_normals_into(us, vs, points, normals);
  double scale = 0;
  for (const auto& x : d.values()) scale = std::max({scale, max_abs(x.s), max_abs(x.su), max_abs(x.sv)});
  for (std::size_t q = 0; q < points.size(); ++q) {
    // The sums of a blended surface's row kernel may round differently from the
    // pointwise sums (fused multiply-adds where the processor has them): 1e-13 of
    // the surface's size; a normal, a unit vector from well-separated partials,
    // to 1e-10.
    ASSERT_LE(norm(points[q] - d.data()[q].s), 1e-13 * scale) << "point " << q;
    ASSERT_LE(norm(normals[q] - unit_normal(d.data()[q])), 1e-10) << "normal " << q;
  }
  // Blocks of 5 rows into the same place: the same bits as the whole.
  std::vector<Vec3> bp(points.size(), garbage), bn(points.size(), garbage);
  for (std::size_t i0 = 0; i0 < us.size(); i0 += 5) {
    const std::size_t n = std::min<std::size_t>(5, us.size() - i0), m = vs.size();
    s.evaluate_normals_into(us.subspan(i0, n), vs, std::span<Vec3>(bp).subspan(i0 * m, n * m),
                            std::span<Vec3>(bn).subspan(i0 * m, n * m));
  }
  EXPECT_TRUE(same_bits(bp, points));
  EXPECT_TRUE(same_bits(bn, normals));
  // Rectangles of the normal grid, columns starting anywhere (a mesh's blocks of
  // columns): the same bits as the whole, and nothing beyond the grid.
  const auto grid = s.normal_grid(us, vs);
  const std::size_t nu = us.size(), nv = vs.size();
  for (const auto [i0, ni, j0, nj] : {std::array<std::size_t, 4>{0, nu, 0, nv}, {0, nu, 3, 5}, {7, 9, 1, 1},
                                      {2, 1, 0, nv}, {nu - 3, 3, nv - 6, 6}, {5, 0, 4, 3}}) {
    std::vector<Vec3> rp(ni * nj, garbage), rn(ni * nj, garbage);
    grid->evaluate_into(i0, ni, j0, nj, rp, rn);
    for (std::size_t i = 0; i < ni; ++i)
      for (std::size_t j = 0; j < nj; ++j) {
        const std::size_t q = (i0 + i) * nv + j0 + j;
        ASSERT_EQ(std::memcmp(&rp[i * nj + j], &points[q], sizeof(Vec3)), 0) << "rectangle at " << i0 << ", " << j0;
        ASSERT_EQ(std::memcmp(&rn[i * nj + j], &normals[q], sizeof(Vec3)), 0) << "rectangle at " << i0 << ", " << j0;
      }
  }
  std::vector<Vec3> two(2), three(3);
  EXPECT_ERRC(grid->evaluate_into(nu - 1, 2, 0, 1, two, two), out_of_domain, "beyond the grid");
  EXPECT_ERRC(grid->evaluate_into(0, 1, nv, 1, two, two), out_of_domain, "beyond the grid");
  EXPECT_ERRC(grid->evaluate_into(0, 1, 0, 2, three, two), size_mismatch, "");
}

TEST(EvaluateInto, NormalsAreThoseOfTheDerivatives) {
  auto g = test::rng(147);
  const std::vector<double> us = random_parameters(g, 23), vs = random_parameters(g, 17);
  for_every_evaluator(
      148, [&](const Surface& s) { expect_normals_of_the_derivatives(s, us, vs); }, [](const Volume&) {});
  // A Coons patch whose side u = 0 is one point: a pole, where S_v vanishes and the
  // normal is the limit along the row (unit_normal's rule).
  const BSplineSurface src = test::random_bspline_surface(g, 3, 3, 5, 5);
  CoonsBoundary b = test::boundary_of(src);
  const Vec3 pole = src.point(0, 0);
  b.u0 = BSplineCurve(b.u0.knots(), std::vector<Vec3>(b.u0.control_points().size(), pole));
  b.v1 = BSplineCurve(KnotVector(1, {0, 0, 1, 1}), {pole, src.point(1, 1)});
  b.u1 = BSplineCurve(KnotVector(1, {0, 0, 1, 1}), {src.point(1, 0), src.point(1, 1)});
  b.v0 = BSplineCurve(KnotVector(1, {0, 0, 1, 1}), {pole, src.point(1, 0)});
  const BlendedSurface cone = coons(b);
  expect_normals_of_the_derivatives(cone, us, vs);
  std::vector<Vec3> p(vs.size()), n(vs.size()), inside(vs.size()), in_n(vs.size());
  const std::vector<double> at_pole{0.0}, near_pole{1e-7};
  cone.evaluate_normals_into(at_pole, vs, p, n);
  cone.evaluate_normals_into(near_pole, vs, inside, in_n);
  for (std::size_t j = 0; j < vs.size(); ++j) {
    EXPECT_LE(norm(p[j] - pole), 1e-14) << "v " << vs[j];
    // The limit: the normal a ten-millionth inside, to within the distance (1e-7
    // times the curvature of the row, of order one here).
    EXPECT_LE(norm(n[j] - in_n[j]), 1e-5) << "v " << vs[j];
  }
}

// --- errors ------------------------------------------------------------------------

TEST(EvaluateInto, OutputOfTheWrongSizeIsSizeMismatch) {
  const std::vector<double> u3{0, 0.5, 1}, v4{0, 0.25, 0.75, 1}, w2{0.1, 0.9}, none;
  std::vector<Vec3> buffer(64, garbage);
  const auto first = [&](std::size_t n) { return std::span<Vec3>(buffer).first(n); };
  for_every_evaluator(
      145,
      [&](const Surface& s) {
        EXPECT_ERRC(s.evaluate_into(u3, v4, first(11)), size_mismatch,
                    "the output holds 11 points, the 3x4 grid has 12");
        EXPECT_ERRC(s.evaluate_into(u3, v4, first(13)), size_mismatch,
                    "the output holds 13 points, the 3x4 grid has 12");
        EXPECT_ERRC(s.evaluate_into(u3, v4, first(0)), size_mismatch, "the output holds 0 points, the 3x4 grid has 12");
        EXPECT_ERRC(s.evaluate_into(v4, u3, first(3)), size_mismatch, "the 4x3 grid has 12");
        EXPECT_ERRC(s.evaluate_into(none, v4, first(1)), size_mismatch,
                    "the output holds 1 points, the 0x4 grid has 0");
        EXPECT_ERRC(s.rows(v4)->evaluate_into(u3, first(11)), size_mismatch,
                    "the output holds 11 points, the 3x4 grid has 12");
        EXPECT_ERRC(s.rows(u3)->evaluate_into(v4, first(3)), size_mismatch, "the 4x3 grid has 12");
        std::vector<Vec3> twelve(12);
        EXPECT_ERRC(s.evaluate_normals_into(u3, v4, first(11), twelve), size_mismatch,
                    "surface evaluation (points): the output holds 11 points, the 3x4 grid has 12");
        EXPECT_ERRC(s.evaluate_normals_into(u3, v4, twelve, first(13)), size_mismatch,
                    "surface evaluation (normals): the output holds 13 points, the 3x4 grid has 12");
      },
      [&](const Volume& v) {
        EXPECT_ERRC(v.evaluate_into(u3, v4, w2, first(23)), size_mismatch,
                    "the output holds 23 points, the 3x4x2 grid has 24");
        EXPECT_ERRC(v.evaluate_into(u3, v4, w2, first(25)), size_mismatch,
                    "the output holds 25 points, the 3x4x2 grid has 24");
        EXPECT_ERRC(v.evaluate_into(u3, v4, w2, first(12)), size_mismatch, "the 3x4x2 grid has 24");
        EXPECT_ERRC(v.evaluate_into(u3, none, w2, first(6)), size_mismatch, "the 3x0x2 grid has 0");
      });
}

TEST(EvaluateInto, ParameterOutsideTheDomainIsOutOfDomain) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> good{0, 0.5, 1}, above{0, 1.5, 1}, below{-0.25, 0.5}, not_a_number{0.5, nan};
  std::vector<Vec3> out;
  const auto sized = [&](std::size_t n) {
    out.assign(n, garbage);
    return std::span<Vec3>(out);
  };
  for_every_evaluator(
      146,
      [&](const Surface& s) {
        EXPECT_ERRC(s.evaluate_into(above, good, sized(9)), out_of_domain, "parameter u = 1.5 is outside the domain");
        EXPECT_ERRC(s.evaluate_into(good, below, sized(6)), out_of_domain, "parameter v = -0.25 is outside the domain");
        EXPECT_ERRC(s.evaluate_into(not_a_number, good, sized(6)), out_of_domain, "parameter u = ");
        EXPECT_ERRC(s.evaluate_into(good, not_a_number, sized(6)), out_of_domain, "parameter v = ");
        // Through rows(): refused by rows() itself or by the evaluation after it.
        EXPECT_ERRC(s.rows(good)->evaluate_into(above, sized(9)), out_of_domain, "parameter u = 1.5 is outside the domain");
        EXPECT_ERRC(s.rows(below)->evaluate_into(good, sized(6)), out_of_domain,
                    "parameter v = -0.25 is outside the domain");
        EXPECT_ERRC(s.rows(not_a_number)->evaluate_into(good, sized(6)), out_of_domain, "parameter v = ");
        std::vector<Vec3> normals(9);
        EXPECT_ERRC(s.evaluate_normals_into(above, good, sized(9), normals), out_of_domain,
                    "parameter u = 1.5 is outside the domain");
        normals.resize(6);
        EXPECT_ERRC(s.evaluate_normals_into(good, below, sized(6), normals), out_of_domain,
                    "parameter v = -0.25 is outside the domain");
      },
      [&](const Volume& v) {
        EXPECT_ERRC(v.evaluate_into(above, good, good, sized(27)), out_of_domain,
                    "parameter u = 1.5 is outside the domain");
        EXPECT_ERRC(v.evaluate_into(good, below, good, sized(18)), out_of_domain,
                    "parameter v = -0.25 is outside the domain");
        EXPECT_ERRC(v.evaluate_into(good, good, above, sized(27)), out_of_domain,
                    "parameter w = 1.5 is outside the domain");
        EXPECT_ERRC(v.evaluate_into(good, good, not_a_number, sized(18)), out_of_domain, "parameter w = ");
      });
}

}  // namespace
}  // namespace interpatch
