// Grid evaluation of the blended constructions (BlendedSurface::evaluate_derivatives,
// BlendedVolume::evaluate_into / evaluate_derivatives / evaluate_jacobians): sums
// of factors evaluated once per parameter, against the pointwise formula
// (derivatives()), for every kind of blended surface and volume on random data and
// parameters that include the ends and odd grid sizes. The grids sum the same terms
// in another order, so they agree to rounding and not bit for bit; a volume's grid
// gives the same bits however its u values are split into calls, whatever grid was
// evaluated before, and for any thread count.

#include <omp.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "interpatch/blended_surface.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/network.hpp"
#include "interpatch/volume_patches.hpp"
#include "surface_util.hpp"
#include "volume_util.hpp"

namespace interpatch {
namespace {

using test::iso_surface;

// n parameters in [0, 1], both ends among them, in no order.
std::vector<double> parameters(std::mt19937_64& g, std::size_t n) {
  std::vector<double> t(n);
  for (double& x : t) x = test::uniform(g, 0, 1);
  t[0] = 1;
  if (n > 2) t[n / 2] = 0;
  return t;
}

struct NamedVolume {
  std::string name;
  BlendedVolume volume;
  double scale;  // the size of the data: the bounding box diagonal of the control points
};

// Every kind of blended volume, on a random B-spline volume (so that faces, edges and
// cross derivatives agree).
std::vector<NamedVolume> blended_volumes(std::mt19937_64& g) {
  std::vector<NamedVolume> out;
  const BSplineVolume b = test::random_bspline_volume(g, 3, 2, 3, 5, 4, 6);
  const double scale = test::scale_of(b);
  std::array<Vec3, 8> c;
  for (auto& x : c) x = test::random_point(g, 2);
  out.push_back({"trilinear", trilinear(c), 4});
  out.push_back({"coons_volume linear", coons_volume(test::faces_of(b)), scale});
  CoonsVolumeOptions hermite_blend;
  hermite_blend.blend_u = hermite_blend.blend_v = hermite_blend.blend_w = Blend::hermite();
  out.push_back({"coons_volume hermite blending", coons_volume(test::faces_of(b), hermite_blend), scale});
  const VolumeCrossDerivatives cross{iso_surface(b, 0, 0, 1), iso_surface(b, 0, 1, 1), iso_surface(b, 1, 0, 1),
                                     iso_surface(b, 1, 1, 1), iso_surface(b, 2, 0, 1), iso_surface(b, 2, 1, 1)};
  out.push_back({"coons_volume with cross derivatives", coons_volume(test::faces_of(b), cross), scale});
  out.push_back({"hermite_volume", hermite_volume(test::frame_of(b)), scale});
  return out;
}

bool same_bits(std::span<const Vec3> a, std::span<const Vec3> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

TEST(BlendedGrid, VolumeGridsAgreeWithThePointwiseFormula) {
  auto g = test::rng(900);
  for (int trial = 0; trial < 4; ++trial)
    for (const auto& [name, v, scale] : blended_volumes(g)) {
      const auto us = parameters(g, 5), vs = parameters(g, 3), ws = parameters(g, 7);
      const PointGrid3 pts = v.evaluate(us, vs, ws);
      const auto der = v.evaluate_derivatives(us, vs, ws);
      const auto jac = v.evaluate_jacobians(us, vs, ws);
      // The same terms summed in another order: at most ~40 terms, each within a few
      // times the data's size (derivatives: within ~10 times), rounded at 1.1e-16.
      const double tol = 1e-13 * scale, dtol = 1e-12 * scale;
      for (std::size_t i = 0; i < us.size(); ++i)
        for (std::size_t j = 0; j < vs.size(); ++j)
          for (std::size_t k = 0; k < ws.size(); ++k) {
            const VolumeDerivatives d = v.derivatives(us[i], vs[j], ws[k]);
            const std::string at = name + " at (" + std::to_string(us[i]) + ", " + std::to_string(vs[j]) + ", " +
                                   std::to_string(ws[k]) + ")";
            EXPECT_LT(distance(pts(i, j, k), d.s), tol) << at;
            EXPECT_EQ(der(i, j, k).s, pts(i, j, k)) << at;
            EXPECT_LT(distance(der(i, j, k).su, d.su), dtol) << at;
            EXPECT_LT(distance(der(i, j, k).sv, d.sv), dtol) << at;
            EXPECT_LT(distance(der(i, j, k).sw, d.sw), dtol) << at;
            EXPECT_EQ(jac.points(i, j, k), pts(i, j, k)) << at;
            const double det = triple(d.su, d.sv, d.sw);
            // det J is a product of three derivatives: relative error three times theirs.
            EXPECT_NEAR(jac.determinants(i, j, k), det, 3e-12 * (1 + std::abs(det)) * scale * scale * scale) << at;
          }
    }
}

TEST(BlendedGrid, VolumeGridIsTheSameWhateverTheSlabsAndWhateverCameBefore) {
  auto g = test::rng(901);
  for (const auto& [name, v, scale] : blended_volumes(g)) {
    const auto us = parameters(g, 9), vs = parameters(g, 6), ws = parameters(g, 8);
    const std::size_t per_row = vs.size() * ws.size();
    const PointGrid3 whole = v.evaluate(us, vs, ws);
    // u by u into one buffer, with other grids evaluated in between (which replace
    // the kept planes of u) and a derivative grid (whose planes serve values too).
    std::vector<Vec3> rows(whole.size());
    const auto other = parameters(g, 4);
    for (std::size_t i = 0; i < us.size(); ++i) {
      if (i % 3 == 1) (void)v.evaluate(us, other, ws);
      if (i % 3 == 2) (void)v.evaluate_jacobians(std::span<const double>(us).subspan(i, 1), vs, ws);
      v.evaluate_into(std::span<const double>(us).subspan(i, 1), vs, ws,
                      std::span<Vec3>(rows).subspan(i * per_row, per_row));
    }
    EXPECT_TRUE(same_bits(rows, std::span<const Vec3>(whole.data(), whole.size()))) << name;
    // A copy shares the kept planes; a fresh volume of the same terms has none.
    const BlendedVolume copy = v;
    const PointGrid3 again = copy.evaluate(us, vs, ws);
    EXPECT_TRUE(same_bits(std::span<const Vec3>(again.data(), again.size()),
                          std::span<const Vec3>(whole.data(), whole.size())))
        << name;
  }
}

TEST(BlendedGrid, VolumeGridIsTheSameForAnyThreadCount) {
  auto g = test::rng(902);
  const auto volumes = blended_volumes(g);
  const NamedVolume& v = volumes[3];  // cross derivatives: the most terms
  // 48³ points × 12 blends is above the threshold for starting threads.
  const auto t = parameters(g, 48);
  std::vector<PointGrid3> grids;
  std::vector<Grid<double, 3>> dets;
  for (int threads : {1, 2, 3}) {
    const int before = omp_get_max_threads();
    omp_set_dynamic(0);
    omp_set_num_threads(threads);
    grids.push_back(v.volume.evaluate(t, t, t));
    dets.push_back(v.volume.evaluate_jacobians(t, t, t).determinants);
    omp_set_num_threads(before);
  }
  for (std::size_t r = 1; r < grids.size(); ++r) {
    EXPECT_TRUE(same_bits(std::span<const Vec3>(grids[r].data(), grids[r].size()),
                          std::span<const Vec3>(grids[0].data(), grids[0].size())));
    EXPECT_EQ(0, std::memcmp(dets[r].data(), dets[0].data(), dets[0].size() * sizeof(double)));
  }
}

TEST(BlendedGrid, VolumeGridReportsProgressAndRefusesBadInput) {
  auto g = test::rng(903);
  const auto volumes = blended_volumes(g);
  const BlendedVolume& v = volumes[1].volume;
  const auto t = parameters(g, 30);
  std::vector<double> reports;
  (void)v.evaluate_jacobians(t, t, t, [&](double f) { reports.push_back(f); });
  ASSERT_FALSE(reports.empty());
  EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end()));
  EXPECT_EQ(reports.back(), 1.0);
  const std::vector<double> ok{0, 1}, bad{1.5};
  std::vector<Vec3> out(4);
  EXPECT_ERRC(v.evaluate_into(ok, bad, ok, std::span<Vec3>(out)), out_of_domain, "parameter v = 1.5");
  EXPECT_ERRC(v.evaluate_into(ok, ok, ok, std::span<Vec3>(out)), size_mismatch, "the output holds 4 points");
  EXPECT_ERRC((void)v.evaluate_derivatives(ok, ok, bad), out_of_domain, "parameter w = 1.5");
  // One u value over 10⁵ × 10⁵ (v, w): the planes of u (two blends, 480 GB) are
  // refused before anything is made or written (the caller's memory is never touched).
  const std::vector<double> many = linspace(0, 1, 100000), one{0.5};
  const std::span<Vec3> huge(out.data(), many.size() * many.size());
  EXPECT_ERRC(v.evaluate_into(one, many, many, huge), too_large,
              "the planes of a blended volume over 100000x100000 (v, w) parameters");
  // No u value: nothing to make, whatever vs and ws.
  EXPECT_NO_THROW(v.evaluate_into({}, many, many, std::span<Vec3>()));
}

TEST(BlendedGrid, SurfaceDerivativeGridsAgreeWithThePointwiseFormula) {
  auto g = test::rng(904);
  for (int trial = 0; trial < 4; ++trial) {
    const BSplineSurface b = test::random_bspline_surface(g, 3, 3, 7, 6);
    const double scale = test::bbox_diagonal(b.control_points().values());
    CoonsOptions hermite_blend;
    hermite_blend.blend_u = hermite_blend.blend_v = Blend::hermite();
    const std::vector<std::pair<std::string, BlendedSurface>> surfaces{
        {"coons linear", coons(test::boundary_of(b))},
        {"coons hermite blending", coons(test::boundary_of(b), hermite_blend)},
        {"coons with cross derivatives", coons(test::boundary_of(b), test::cross_of(b))},
        {"network", curve_network(test::network_on(b, {0, 0.3, 0.7, 1}, {0, 0.5, 1}))},
    };
    for (const auto& [name, s] : surfaces) {
      const auto us = parameters(g, 6), vs = parameters(g, 9);
      const auto grid = s.evaluate_derivatives(us, vs);
      // The same terms in another order: ~20 terms within a few times the data's
      // size, second derivatives within ~100 times, rounded at 1.1e-16.
      const double tol = 1e-13 * scale, dtol = 1e-11 * scale;
      for (std::size_t i = 0; i < us.size(); ++i)
        for (std::size_t j = 0; j < vs.size(); ++j) {
          const SurfaceDerivatives d = s.derivatives(us[i], vs[j]), e = grid(i, j);
          const std::string at = name + " at (" + std::to_string(us[i]) + ", " + std::to_string(vs[j]) + ")";
          EXPECT_LT(distance(e.s, d.s), tol) << at;
          EXPECT_LT(distance(e.su, d.su), dtol) << at;
          EXPECT_LT(distance(e.sv, d.sv), dtol) << at;
          EXPECT_LT(distance(e.suu, d.suu), dtol) << at;
          EXPECT_LT(distance(e.suv, d.suv), dtol) << at;
          EXPECT_LT(distance(e.svv, d.svv), dtol) << at;
        }
    }
  }
}

TEST(BlendedGrid, GregoryPatchesGoPointByPoint) {
  auto g = test::rng(905);
  const BSplineSurface b = test::random_bspline_surface(g, 3, 3, 6, 6);
  // S_u(0, v) bent near v = 0 with its end values kept: the twists at p00 disagree,
  // and Gregory's correction blends them.
  auto x = test::cross_of(b);
  auto cp = x.u0.control_points();
  cp[1].z += 0.1;
  x.u0 = BSplineCurve(x.u0.knots(), cp);
  HermiteCoonsOptions o;
  o.twist_correction = TwistCorrection::gregory;
  const BlendedSurface s = coons(test::boundary_of(b), x, o);
  ASSERT_FALSE(s.has_exact_form());  // the Gregory term is there
  const auto us = parameters(g, 5), vs = parameters(g, 4);
  const auto grid = s.evaluate_derivatives(us, vs);
  for (std::size_t i = 0; i < us.size(); ++i)
    for (std::size_t j = 0; j < vs.size(); ++j) {
      const SurfaceDerivatives d = s.derivatives(us[i], vs[j]);  // the same code per point: equal
      EXPECT_EQ(grid(i, j).s, d.s);
      EXPECT_EQ(grid(i, j).suv, d.suv);
    }
  const std::vector<double> bad{-0.5};
  EXPECT_ERRC((void)s.evaluate_derivatives(bad, vs), out_of_domain, "parameter u = -0.5");
}

}  // namespace
}  // namespace interpatch
