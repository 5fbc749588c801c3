#include "interpatch/coons_volume.hpp"

#include "interpatch/volume_patches.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

using test::faces_of;
using test::iso_surface;

VolumeCrossDerivatives cross_of(const BSplineVolume& b) {
  return {iso_surface(b, 0, 0, 1), iso_surface(b, 0, 1, 1), iso_surface(b, 1, 0, 1),
          iso_surface(b, 1, 1, 1), iso_surface(b, 2, 0, 1), iso_surface(b, 2, 1, 1)};
}

// Largest distance between two volumes over a grid of each of the six faces.
double face_distance(const Volume& a, const Volume& b, std::size_t n = 13) {
  double e = 0;
  for (double s : linspace(0, 1, n))
    for (double t : linspace(0, 1, n))
      for (double end : {0.0, 1.0}) {
        e = std::max(e, distance(a.point(end, s, t), b.point(end, s, t)));
        e = std::max(e, distance(a.point(s, end, t), b.point(s, end, t)));
        e = std::max(e, distance(a.point(s, t, end), b.point(s, t, end)));
      }
  return e;
}

BSplineSurface shifted(const BSplineSurface& s, const Vec3& d) {
  PointGrid cp = s.control_points();
  for (auto& x : cp.values()) x += d;
  return BSplineSurface(s.knots_u(), s.knots_v(), cp, s.weights());
}

TEST(CoonsVolume, LinearReproducesTrilinearVolumes) {
  auto g = test::rng(220);
  for (int trial = 0; trial < 5; ++trial) {
    std::array<Vec3, 8> c;
    for (auto& x : c) x = test::random_point(g, 2);
    const auto b = trilinear(c).to_bspline();
    const auto s = coons_volume(faces_of(b));
    EXPECT_LT(test::max_distance(s, b), 1e-14 * 16);  // 26 terms of size ~2: rounding
    EXPECT_LT(test::max_distance(s, s.to_bspline()), 1e-12 * test::scale_of(b));
  }
}

TEST(CoonsVolume, LinearTakesEveryFaceOfRandomVolumesAndConvertsExactly) {
  auto g = test::rng(221);
  for (int trial = 0; trial < 8; ++trial) {
    const auto b = test::random_bspline_volume(g, 1 + trial % 4, 1 + (trial + 1) % 4, 1 + (trial + 2) % 4, 5,
                                               6 - static_cast<std::size_t>(trial % 2), 5);
    const auto s = coons_volume(faces_of(b));
    const double scale = test::scale_of(b);
    EXPECT_LT(face_distance(s, b), 1e-14 * 4 * scale);  // 26 exact terms summed: rounding
    EXPECT_LT(test::max_distance(s, s.to_bspline()), 1e-12 * scale);
    ASSERT_FALSE(s.notes().empty());
    EXPECT_NE(s.notes()[0].find("faces meet along their edges within"), std::string::npos) << s.notes()[0];
  }
}

TEST(CoonsVolume, LinearReproducesVolumesLinearInOneDirection) {
  // (I − P_u ⊕ P_v ⊕ P_w) = (I − P_u)(I − P_v)(I − P_w): one factor annihilating S is enough.
  auto g = test::rng(222);
  for (int axis = 0; axis < 3; ++axis) {
    const int p = axis == 0 ? 1 : 3, q = axis == 1 ? 1 : 2, r = axis == 2 ? 1 : 3;
    const auto b = test::random_bspline_volume(g, p, q, r, axis == 0 ? 2 : 6, axis == 1 ? 2 : 5, axis == 2 ? 2 : 6);
    EXPECT_LT(test::max_distance(coons_volume(faces_of(b)), b), 1e-14 * 4 * test::scale_of(b)) << axis;
  }
}

TEST(CoonsVolume, CardinalPropertyTranslation) {
  // Σ of all blending products ≡ 1: moving every face by d moves the volume by d.
  auto g = test::rng(223);
  const auto b = test::random_bspline_volume(g, 2, 3, 2, 4, 5, 4);
  const Vec3 d{0.3, -2, 5};
  auto f = faces_of(b);
  const VolumeFaces m{shifted(f.u0, d), shifted(f.u1, d), shifted(f.v0, d),
                      shifted(f.v1, d), shifted(f.w0, d), shifted(f.w1, d)};
  CoonsVolumeOptions hermite;
  hermite.blend_u = hermite.blend_v = hermite.blend_w = Blend::hermite();
  for (const auto& o : {CoonsVolumeOptions{}, hermite}) {
    const auto s0 = coons_volume(f, o), s1 = coons_volume(m, o);
    for (double u : linspace(0, 1, 5))
      for (double v : linspace(0, 1, 5))
        for (double w : linspace(0, 1, 5)) EXPECT_LT(distance(s1.point(u, v, w) - d, s0.point(u, v, w)), 1e-13 * 8);
  }
}

TEST(CoonsVolume, HermiteBlendKeepsTheFacesAndBendsTheInterior) {
  auto g = test::rng(224);
  const auto b = test::random_bspline_volume(g, 1, 3, 3, 2, 5, 5);  // linear in u: the linear volume reproduces it
  CoonsVolumeOptions o;
  o.blend_u = Blend::hermite();
  const auto s = coons_volume(faces_of(b), o);
  const double scale = test::scale_of(b);
  EXPECT_LT(face_distance(s, b), 1e-14 * 4 * scale);
  EXPECT_GT(test::max_distance(s, b), 1e-3);  // 3u² − 2u³ in place of u moves the interior
  EXPECT_LT(test::max_distance(s, s.to_bspline()), 1e-12 * scale);
  EXPECT_EQ(s.to_bspline().degree_u(), 3);
  // A blend given as a callable: the same volume by its formula, but no exact form.
  CoonsVolumeOptions f;
  f.blend_u = Blend([](double t, int k) { return k == 0 ? t * t * (3 - 2 * t) : (k == 1 ? 6 * t * (1 - t) : 6 - 12 * t); });
  const auto c = coons_volume(faces_of(b), f);
  EXPECT_FALSE(c.has_exact_form());
  EXPECT_ERRC((void)c.to_bspline(), no_exact_form, "blending function of u is a callable");
  EXPECT_LT(test::max_distance(c, s), 1e-14 * 4 * scale);  // same functions, other evaluation
}

TEST(CoonsVolume, RationalFacesAreTakenExactlyButHaveNoExactForm) {
  auto g = test::rng(225);
  const auto b = test::random_bspline_volume(g, 2, 2, 2, 4, 4, 4, 0.3, true);
  const auto s = coons_volume(faces_of(b));
  EXPECT_LT(face_distance(s, b), 1e-14 * 4 * test::scale_of(b));  // rational faces evaluated exactly: rounding
  EXPECT_FALSE(s.has_exact_form());
  EXPECT_ERRC((void)s.to_bspline(), no_exact_form, "face u0 is a rational surface");
}

TEST(CoonsVolume, HermiteTakesFacesAndCrossDerivativesAndConvertsExactly) {
  auto g = test::rng(226);
  for (int trial = 0; trial < 6; ++trial) {
    // A smooth spline volume: its faces and cross-derivative fields are consistent data.
    const auto b = test::random_bspline_volume(g, 2 + trial % 2, 3, 2 + (trial + 1) % 3, 5, 4 + static_cast<std::size_t>(trial % 2), 5);
    const auto s = coons_volume(faces_of(b), cross_of(b));
    const double scale = test::scale_of(b);
    EXPECT_LT(face_distance(s, b), 1e-13 * scale);  // ~200 exact terms summed: rounding
    for (double x : linspace(0, 1, 7))
      for (double y : linspace(0, 1, 7))
        for (double end : {0.0, 1.0}) {
          // Derivatives of terms with factors up to ~30 (3 / knot span): more rounding.
          const auto du = s.derivatives(end, x, y), eu = b.derivatives(end, x, y);
          EXPECT_LT(distance(du.su, eu.su), 1e-11 * (scale + norm(eu.su)));
          const auto dv = s.derivatives(x, end, y), ev = b.derivatives(x, end, y);
          EXPECT_LT(distance(dv.sv, ev.sv), 1e-11 * (scale + norm(ev.sv)));
          const auto dw = s.derivatives(x, y, end), ew = b.derivatives(x, y, end);
          EXPECT_LT(distance(dw.sw, ew.sw), 1e-11 * (scale + norm(ew.sw)));
        }
    EXPECT_LT(test::max_distance(s, s.to_bspline()), 1e-12 * scale);
  }
}

TEST(CoonsVolume, HermiteReproducesVolumesCubicInADirectionWithBothFields) {
  auto g = test::rng(227);
  for (int axis = 0; axis < 3; ++axis) {
    const std::array<int, 3> deg{axis == 0 ? 3 : 2, axis == 1 ? 3 : 3, axis == 2 ? 3 : 2};
    const std::array<std::size_t, 3> n{axis == 0 ? 4u : 6u, axis == 1 ? 4u : 5u, axis == 2 ? 4u : 6u};
    const auto b = test::random_bspline_volume(g, deg[0], deg[1], deg[2], n[0], n[1], n[2]);
    const auto all = cross_of(b);
    VolumeCrossDerivatives only;  // just the two fields across `axis`
    if (axis == 0) {
      only.u0 = all.u0;
      only.u1 = all.u1;
    } else if (axis == 1) {
      only.v0 = all.v0;
      only.v1 = all.v1;
    } else {
      only.w0 = all.w0;
      only.w1 = all.w1;
    }
    const double scale = test::scale_of(b);
    EXPECT_LT(test::max_distance(coons_volume(faces_of(b), only), b), 1e-13 * scale) << axis;
    EXPECT_LT(test::max_distance(coons_volume(faces_of(b), all), b), 1e-13 * scale) << axis;
  }
}

TEST(CoonsVolume, HermiteWithOneFieldMeetsItAndKeepsTheFaces) {
  auto g = test::rng(228);
  const auto b = test::random_bspline_volume(g, 3, 3, 3, 5, 5, 6);
  VolumeCrossDerivatives d;
  d.w0 = cross_of(b).w0;
  const auto s = coons_volume(faces_of(b), d);
  const double scale = test::scale_of(b);
  EXPECT_LT(face_distance(s, b), 1e-13 * scale);
  for (double x : linspace(0, 1, 9))
    for (double y : linspace(0, 1, 9)) {
      const Vec3 e = b.derivatives(x, y, 0).sw;
      EXPECT_LT(distance(s.derivatives(x, y, 0).sw, e), 1e-11 * (scale + norm(e)));  // as above
    }
  EXPECT_LT(test::max_distance(s, s.to_bspline()), 1e-12 * scale);
}

TEST(CoonsVolume, FacesThatDoNotMeetAreNamedWithTheGap) {
  auto g = test::rng(229);
  const auto b = test::random_bspline_volume(g, 2, 2, 3, 4, 4, 5);
  auto f = faces_of(b);
  f.u0 = shifted(f.u0, {0, 0.25, 0});  // moves all of u0: it leaves its four neighbours by 0.25
  EXPECT_ERRC((void)coons_volume(f), corner_gap, "faces u0 and v0 disagree along their shared edge (u=0, v=0) by 0.25 at w = ");
  EXPECT_ERRC((void)coons_volume(f), corner_gap, "(tolerance 6.9");  // 1e-7 x the diagonal of the faces' control points, 6.9 for this volume
  CoonsVolumeOptions loose;
  loose.tolerance = 0.3;
  const auto s = coons_volume(f, loose);
  EXPECT_NE(s.notes()[0].find("within 0.25"), std::string::npos) << s.notes()[0];
  // Edge curves and corners are means of the faces holding them: on the edge (u=0, v=0)
  // the moved face counts fully in U, by ½ in UV and UW and by ⅓ in UVW, so the volume
  // moves by 0.25 (1 − ½ − ½ + ⅓) = 0.25 / 3 there.
  EXPECT_NEAR(distance(s.point(0, 0, 0.5), b.point(0, 0, 0.5)), 0.25 / 3, 1e-14);
  CoonsVolumeOptions negative;
  negative.tolerance = -1;
  EXPECT_ERRC((void)coons_volume(faces_of(b), negative), out_of_domain, "tolerance -1 must be a finite number >= 0");
}

TEST(CoonsVolume, CrossDerivativesThatDisagreeWithTheFacesAreNamed) {
  auto g = test::rng(230);
  const auto b = test::random_bspline_volume(g, 3, 3, 3, 5, 5, 6);
  auto d = cross_of(b);
  d.u0 = shifted(*d.u0, {1, 0, 0});
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), tangent_mismatch,
              "S_u along the edge (u=0, v=0): cross-derivative u0 gives");
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), tangent_mismatch, "but d/du of face v0 gives");
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), tangent_mismatch, "they differ by 1 (tolerance");
}

TEST(CoonsVolume, IncompatibleMixedDerivativesAlongAnEdgeAreNamed) {
  // Bend S_u on u = 0 across v = 0 without moving it on its boundary: control points of
  // row v = 1 away from the w ends change d/dv of the field along the edge (u=0, v=0),
  // where it must equal d/du of the field on v = 0.
  auto g = test::rng(231);
  const auto b = test::random_bspline_volume(g, 3, 3, 3, 5, 5, 7);
  auto d = cross_of(b);
  PointGrid cp = d.u0->control_points();
  for (std::size_t k = 2; k + 2 < cp.extent(1); ++k) cp(1, k).z += 0.5;
  d.u0 = BSplineSurface(d.u0->knots_u(), d.u0->knots_v(), cp);
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), incompatible_twist,
              "S_uv along the edge (u=0, v=0): d/dv of cross-derivative u0 gives");
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), incompatible_twist, "but d/du of cross-derivative v0 gives");
}

TEST(CoonsVolume, IncompatibleThirdDerivativesAtACornerAreNamed) {
  // A bump of size 2e-10 in S_u on u = 0, confined near the corner by knots at 0.001 and
  // 0.002 in both v and w: its values and first slopes along every edge stay below the
  // tolerance (~8e-7; the edge checks still pass with a bump 5 times larger), but its
  // mixed slope d2/dvdw at the corner is (3/0.001)² × 2e-10 = 1.8e-3, against a
  // tolerance of 1e-7 × |S_uvw| = 1.6e-5 (the check still fires at a tenth of the bump).
  auto g = test::rng(232);
  const auto b = test::random_bspline_volume(g, 3, 3, 3, 5, 5, 5);
  auto d = cross_of(b);
  const std::vector<double> near{0.001, 0.002};
  const auto r = d.u0->refined(near, near);
  PointGrid cp = r.control_points();
  cp(1, 1) += Vec3{2e-10, 0, 0};
  d.u0 = BSplineSurface(r.knots_u(), r.knots_v(), cp);
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), incompatible_twist,
              "at corner p000, S_uvw from d2/dvdw of cross-derivative u0 is");
  EXPECT_ERRC((void)coons_volume(faces_of(b), d), incompatible_twist, "but from d2/dudw of cross-derivative v0 it is");
}

}  // namespace
}  // namespace interpatch
