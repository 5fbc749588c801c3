#pragma once
/// @file evaluate.hpp
/// Differential geometry of a surface from its partial derivatives.

#include <span>
#include <vector>

#include "interpatch/bspline_surface.hpp"

namespace interpatch {

/// Unit normal Su × Sv / |Su × Sv|. Where the parametrization degenerates (a pole:
/// Su or Sv vanishes) the limit along the vanishing direction is used,
/// Su × Suv or Suv × Sv; the zero vector when that too vanishes. "Vanishes" means
/// |Su × Sv| <= 1e-10 max(|Su|, |Sv|)².
[[nodiscard]] Vec3 unit_normal(const SurfaceDerivatives& d) noexcept;

/// Gaussian and mean curvature and the principal curvatures k1 >= k2 with respect
/// to unit_normal(): K = (LN − M²)/(EG − F²), H = (EN − 2FM + GL) / (2(EG − F²)).
struct Curvature {
  double gaussian, mean, k1, k2;
};
/// NaN everywhere where the first fundamental form is singular (EG − F² = 0).
[[nodiscard]] Curvature curvature(const SurfaceDerivatives& d) noexcept;

/// n uniformly spaced parameters covering [a, b], ends exact.
[[nodiscard]] std::vector<double> linspace(double a, double b, std::size_t n);

}  // namespace interpatch
