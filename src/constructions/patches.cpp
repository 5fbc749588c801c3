#include "interpatch/patches.hpp"

#include "blends/blended_terms.hpp"
#include "base/text.hpp"

namespace interpatch {

using detail::fail;

namespace {

BSplineCurve linear_scalar(bool rising) { return detail::scalar(KnotVector::bezier(1), {rising ? 0.0 : 1.0, rising ? 1.0 : 0.0}); }

}  // namespace

BlendedSurface bilinear(const Vec3& p00, const Vec3& p01, const Vec3& p10, const Vec3& p11) {
  const char* names[4] = {"p00", "p01", "p10", "p11"};
  const Vec3 p[4] = {p00, p01, p10, p11};
  for (int k = 0; k < 4; ++k)
    if (!is_finite(p[k])) fail(errc::not_finite, "corner ", names[k], " is ", p[k]);
  auto t = std::make_shared<detail::BlendedTerms>();
  t->f = {linear_scalar(false), linear_scalar(true)};
  t->g = t->f;
  t->c = PointGrid({2, 2});
  t->c(0, 0) = p00;
  t->c(0, 1) = p01;
  t->c(1, 0) = p10;
  t->c(1, 1) = p11;
  return BlendedSurface(std::move(t));
}

BlendedSurface ruled(const BSplineCurve& c0, const BSplineCurve& c1) {
  auto t = std::make_shared<detail::BlendedTerms>();
  t->g = {linear_scalar(false), linear_scalar(true)};
  t->b = {detail::unit(c0), detail::unit(c1)};
  return BlendedSurface(std::move(t));
}

BlendedSurface hermite_patch(const std::array<HermiteCorner, 4>& corners) {
  const char* names[4] = {"p00", "p01", "p10", "p11"};
  for (int k = 0; k < 4; ++k) {
    const auto& c = corners[static_cast<std::size_t>(k)];
    for (const auto& [v, what] : {std::pair{c.p, "p"}, {c.du, "du"}, {c.dv, "dv"}, {c.duv, "duv"}})
      if (!is_finite(v)) fail(errc::not_finite, "corner ", names[k], " ", what, " is ", v);
  }
  auto t = std::make_shared<detail::BlendedTerms>();
  t->f = detail::hermite_scalars();  // α0, α1, β0, β1
  t->g = t->f;
  // c(k, l): k = 0,1 position/ k = 2,3 u-derivative at u = k mod 2; l likewise in v.
  t->c = PointGrid({4, 4});
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) {
      const auto& c = corners[2 * i + j];
      t->c(i, j) = c.p;
      t->c(2 + i, j) = c.du;
      t->c(i, 2 + j) = c.dv;
      t->c(2 + i, 2 + j) = c.duv;
    }
  return BlendedSurface(std::move(t));
}

}  // namespace interpatch
