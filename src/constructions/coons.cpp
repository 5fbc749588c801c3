#include "interpatch/coons.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "blends/blended_terms.hpp"
#include "base/data_scale.hpp"
#include "base/text.hpp"

namespace interpatch {

using detail::fail;

namespace {

detail::DataScale scale_of(std::initializer_list<const BSplineCurve*> curves) {
  detail::DataScale s;
  for (const auto* c : curves) s.add(c->control_points());
  return s;
}

// The four corners p_ij (index 2i + j), checked to meet within `tol`.
std::array<Vec3, 4> corners(const CoonsBoundary& b, double tol) {
  struct Meet {
    const char* corner;
    const char* c1;
    Vec3 a;
    const char* c2;
    Vec3 bpt;
  };
  const Meet m[4] = {{"p00", "v0", b.v0.point(0), "u0", b.u0.point(0)},
                     {"p01", "v1", b.v1.point(0), "u0", b.u0.point(1)},
                     {"p10", "v0", b.v0.point(1), "u1", b.u1.point(0)},
                     {"p11", "v1", b.v1.point(1), "u1", b.u1.point(1)}};
  std::array<Vec3, 4> p;
  for (int k = 0; k < 4; ++k) {
    const double gap = distance(m[k].a, m[k].bpt);
    if (gap > tol)
      fail(errc::corner_gap, "boundary curves ", m[k].c1, " and ", m[k].c2, " do not meet at corner ", m[k].corner,
           ": ", m[k].c1, " gives ", m[k].a, ", ", m[k].c2, " gives ", m[k].bpt, ", gap ", gap, " (tolerance ", tol, ")");
    p[static_cast<std::size_t>(k)] = 0.5 * (m[k].a + m[k].bpt);
  }
  return p;
}

CoonsBoundary on_unit(const CoonsBoundary& b) {
  return {detail::unit(b.v0), detail::unit(b.v1), detail::unit(b.u0), detail::unit(b.u1)};
}

double derivative_tolerance(const Vec3& a, const Vec3& b, double diag) {
  return 1e-7 * std::max({norm(a), norm(b), diag});  // relative to the data's size
}

}  // namespace

BlendedSurface coons(const CoonsBoundary& boundary, const CoonsOptions& options) {
  const CoonsBoundary b = on_unit(boundary);
  const double tol = options.tolerance ? *options.tolerance : scale_of({&b.v0, &b.v1, &b.u0, &b.u1}).strict();
  const auto p = corners(b, tol);
  auto t = std::make_shared<detail::BlendedTerms>();
  const detail::Scalar f = detail::scalar(options.blend_u), g = detail::scalar(options.blend_v);
  t->f = {detail::one_minus(f), f};
  t->a = {b.u0, b.u1};
  t->g = {detail::one_minus(g), g};
  t->b = {b.v0, b.v1};
  t->c = PointGrid({2, 2});
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) t->c(i, j) = -p[2 * i + j];
  return BlendedSurface(std::move(t));
}

BlendedSurface coons(const CoonsBoundary& boundary, const CoonsCrossDerivatives& cross, const HermiteCoonsOptions& options) {
  const CoonsBoundary b = on_unit(boundary);
  const CoonsCrossDerivatives d{detail::unit(cross.v0), detail::unit(cross.v1), detail::unit(cross.u0),
                                detail::unit(cross.u1)};
  const detail::DataScale scale = scale_of({&b.v0, &b.v1, &b.u0, &b.u1});
  const double diag = scale.diagonal();
  const double tol = options.tolerance ? *options.tolerance : scale.strict();
  const auto p = corners(b, tol);
  const BSplineCurve* ucurve[2] = {&b.u0, &b.u1};  // S(i, v)
  const BSplineCurve* vcurve[2] = {&b.v0, &b.v1};  // S(u, j)
  const BSplineCurve* ucross[2] = {&d.u0, &d.u1};  // S_u(i, v)
  const BSplineCurve* vcross[2] = {&d.v0, &d.v1};  // S_v(u, j)
  const char* uname[2] = {"u0", "u1"};
  const char* vname[2] = {"v0", "v1"};
  auto t = std::make_shared<detail::BlendedTerms>();
  t->c = PointGrid({4, 4});
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const std::string corner = detail::cat("p", i, j);
      const auto ui = static_cast<std::size_t>(i), vj = static_cast<std::size_t>(j);
      // Tangents at the corner: along the boundary, and from the cross-derivative curve.
      const Vec3 su = vcurve[j]->derivative(i, 1), su_cross = ucross[i]->point(j);
      const Vec3 sv = ucurve[i]->derivative(j, 1), sv_cross = vcross[j]->point(i);
      if (distance(su, su_cross) > derivative_tolerance(su, su_cross, diag))
        fail(errc::tangent_mismatch, "at corner ", corner, " the cross-derivative curve ", uname[i], " gives S_u = ",
             su_cross, " but boundary ", vname[j], " has tangent ", su, ": they differ by ", distance(su, su_cross));
      if (distance(sv, sv_cross) > derivative_tolerance(sv, sv_cross, diag))
        fail(errc::tangent_mismatch, "at corner ", corner, " the cross-derivative curve ", vname[j], " gives S_v = ",
             sv_cross, " but boundary ", uname[i], " has tangent ", sv, ": they differ by ", distance(sv, sv_cross));
      // Twists: d/dv of S_u(i, v) and d/du of S_v(u, j) must agree.
      const Vec3 tu = ucross[i]->derivative(j, 1), tv = vcross[j]->derivative(i, 1);
      const auto& given = options.twists[2 * ui + vj];
      const bool gregory = options.twist_correction == TwistCorrection::gregory;
      Vec3 twist = 0.5 * (tu + tv);
      auto check = [&](const Vec3& a, const char* an, const Vec3& bb, const char* bn) {
        const double diff = distance(a, bb);
        if (diff > derivative_tolerance(a, bb, diag) && !gregory)
          fail(errc::incompatible_twist, "incompatible twists at corner ", corner, ": ", an, " gives ", a, ", ", bn,
               " gives ", bb, ", they differ by ", diff, " (use \"twist_correction\": \"gregory\" to blend them)");
        return diff <= derivative_tolerance(a, bb, diag);
      };
      bool compatible = true;
      if (given) {
        compatible = check(*given, "the given twist", tu, detail::cat("d/dv of cross-derivative ", uname[i]).c_str()) &&
                     check(*given, "the given twist", tv, detail::cat("d/du of cross-derivative ", vname[j]).c_str());
        if (compatible) twist = *given;
      } else {
        compatible = check(tu, detail::cat("d/dv of cross-derivative ", uname[i]).c_str(), tv,
                           detail::cat("d/du of cross-derivative ", vname[j]).c_str());
        t->notes.push_back(detail::cat("twist at ", corner, " taken from the cross-derivative curves: ", twist));
      }
      t->c(ui, vj) = -p[2 * ui + vj];
      t->c(2 + ui, vj) = -su;
      t->c(ui, 2 + vj) = -sv;
      if (compatible) {
        t->c(2 + ui, 2 + vj) = -twist;
      } else {
        t->gregory.push_back({i, j, tu, tv});
        t->notes.push_back(detail::cat("Gregory's correction at ", corner, ": twists ", tu, " (along u = ", i, ") and ",
                                       tv, " (along v = ", j, ") differ by ", distance(tu, tv)));
      }
    }
  t->f = detail::hermite_scalars();
  t->g = t->f;
  t->a = {b.u0, b.u1, d.u0, d.u1};
  t->b = {b.v0, b.v1, d.v0, d.v1};
  return BlendedSurface(std::move(t));
}

}  // namespace interpatch
