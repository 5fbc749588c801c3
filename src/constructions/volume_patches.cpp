#include "interpatch/volume_patches.hpp"

#include "blends/blended_terms.hpp"
#include "base/text.hpp"
#include "blends/volume_terms.hpp"

namespace interpatch {

using detail::fail;

namespace {

std::string corner_name(std::size_t n) { return detail::cat("p", n >> 2, (n >> 1) & 1, n & 1); }

}  // namespace

BlendedVolume trilinear(const std::array<Vec3, 8>& corners) {
  for (std::size_t n = 0; n < 8; ++n)
    if (!is_finite(corners[n])) fail(errc::not_finite, "corner ", corner_name(n), " is ", corners[n]);
  auto t = std::make_shared<detail::VolumeTerms>();
  const BSplineCurve rise = detail::scalar(KnotVector::bezier(1), {0, 1});
  for (auto& b : t->blends) b = {detail::one_minus(rise), rise};
  for (std::size_t n = 0; n < 8; ++n) t->corners.push_back({{n >> 2, (n >> 1) & 1, n & 1}, corners[n]});
  return BlendedVolume(std::move(t));
}

BlendedVolume hermite_volume(const std::array<HermiteVolumeCorner, 8>& corners) {
  for (std::size_t n = 0; n < 8; ++n) {
    const auto& c = corners[n];
    for (const auto& [v, what] : {std::pair{c.p, "p"}, {c.du, "du"}, {c.dv, "dv"}, {c.dw, "dw"}, {c.duv, "duv"},
                                  {c.duw, "duw"}, {c.dvw, "dvw"}, {c.duvw, "duvw"}})
      if (!is_finite(v)) fail(errc::not_finite, "corner ", corner_name(n), " ", what, " is ", v);
  }
  auto t = std::make_shared<detail::VolumeTerms>();
  for (auto& b : t->blends) b = detail::hermite_scalars();  // α0, α1, β0, β1
  // Blend index per direction: the end i for a position (α_i), 2 + i for a derivative (β_i).
  for (std::size_t n = 0; n < 8; ++n) {
    const auto& c = corners[n];
    const std::size_t i = n >> 2, j = (n >> 1) & 1, k = n & 1;
    const Vec3 data[8] = {c.p, c.du, c.dv, c.duv, c.dw, c.duw, c.dvw, c.duvw};  // index 4c + 2b + a
    for (std::size_t kind = 0; kind < 8; ++kind) {
      if (data[kind] == Vec3{}) continue;  // omitted derivatives add nothing
      const std::size_t a = kind & 1, b = (kind >> 1) & 1, d = kind >> 2;
      t->corners.push_back({{i + 2 * a, j + 2 * b, k + 2 * d}, data[kind]});
    }
  }
  return BlendedVolume(std::move(t));
}

}  // namespace interpatch
