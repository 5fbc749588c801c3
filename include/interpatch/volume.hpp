#pragma once
/// @file volume.hpp
/// What every trivariate volume ("body portion") of interpatch offers:
/// exact evaluation with the Jacobian, batch evaluation over parameter grids, its
/// exact B-spline form, and the search for inverted cells (det J <= 0).

#include <array>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "interpatch/grid.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch {

class BSplineVolume;

/// A volume point with its three first partial derivatives, the columns of the Jacobian.
struct VolumeDerivatives {
  Vec3 s, su, sv, sw;
};

/// The Jacobian matrix J = [S_u S_v S_w] of the map (u, v, w) → (x, y, z) and its
/// determinant det J = S_u · (S_v × S_w): positive where the volume keeps the
/// orientation of the parameter cube, zero where it degenerates, negative where it folds.
struct Jacobian {
  /// matrix[r][c]: coordinate r (x, y, z) of column c (S_u, S_v, S_w).
  std::array<std::array<double, 3>, 3> matrix;
  double determinant;
};

/// The Jacobian from the partial derivatives.
///
/// Example:
/// @code
///   interpatch::VolumeDerivatives d{{0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0, 4}};
///   double det = interpatch::jacobian(d).determinant;  // 24
/// @endcode
[[nodiscard]] Jacobian jacobian(const VolumeDerivatives& d) noexcept;

/// Points and Jacobian determinants over a parameter grid: both nu × nv × nw, first index along u.
struct VolumeJacobians {
  PointGrid3 points;
  Grid<double, 3> determinants;
};

/// A parametric volume S(u, v, w) over [0, 1]³ (B-spline volumes over their own
/// knot domain, see domain()).
class Volume {
 public:
  virtual ~Volume() = default;

  /// The parameter box [u0, u1] × [v0, v1] × [w0, w1]; [0, 1]³ unless the volume says otherwise.
  [[nodiscard]] virtual std::array<std::pair<double, double>, 3> domain() const {
    return {{{0.0, 1.0}, {0.0, 1.0}, {0.0, 1.0}}};
  }
  /// S(u, v, w). @throws error out_of_domain.
  [[nodiscard]] virtual Vec3 point(double u, double v, double w) const { return derivatives(u, v, w).s; }
  /// S and its first partial derivatives, from the construction's own formula.
  /// @throws error out_of_domain.
  [[nodiscard]] virtual VolumeDerivatives derivatives(double u, double v, double w) const = 0;
  /// The Jacobian at (u, v, w). @throws error out_of_domain.
  [[nodiscard]] Jacobian jacobian(double u, double v, double w) const;

  /// Points at every (us[i], vs[j], ws[k]): a us.size() × vs.size() × ws.size() grid,
  /// through evaluate_into(). @throws error out_of_domain, too_large.
  [[nodiscard]] PointGrid3 evaluate(std::span<const double> us, std::span<const double> vs,
                                    std::span<const double> ws, const progress_callback& progress = {}) const;
  /// Points at every (us[i], vs[j], ws[k]) into memory the caller owns:
  /// out[(i * vs.size() + j) * ws.size() + k]. Slab by slab along u into one reused
  /// buffer, a grid of any size costs memory for one slab only.
  /// @throws error out_of_domain; size_mismatch when out.size() is not the product of the sizes.
  virtual void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                             std::span<Vec3> out, const progress_callback& progress = {}) const;
  /// Points and first partials at every (us[i], vs[j], ws[k]). @throws error out_of_domain, too_large.
  [[nodiscard]] virtual Grid<VolumeDerivatives, 3> evaluate_derivatives(std::span<const double> us,
                                                                        std::span<const double> vs,
                                                                        std::span<const double> ws) const;
  /// Points and det J at every (us[i], vs[j], ws[k]): what a structured hex mesh
  /// with a Jacobian field needs, a third of the memory of evaluate_derivatives().
  /// @throws error out_of_domain, too_large.
  [[nodiscard]] virtual VolumeJacobians evaluate_jacobians(std::span<const double> us, std::span<const double> vs,
                                                           std::span<const double> ws,
                                                           const progress_callback& progress = {}) const;
  /// The same volume as a B-spline volume (polynomial or rational) that evaluates to
  /// the same points up to rounding.
  /// @throws error no_exact_form when the construction has none.
  [[nodiscard]] virtual BSplineVolume to_bspline() const = 0;

 protected:
  Volume() = default;
  Volume(const Volume&) = default;
  Volume(Volume&&) = default;
  Volume& operator=(const Volume&) = default;
  Volume& operator=(Volume&&) = default;
};

/// Where a volume folds: det J sampled on a uniform k × k × k grid of its domain.
struct InvertedCells {
  std::size_t samples = 0;         ///< k³ sample points
  std::size_t inverted_points = 0; ///< samples with det J <= 0
  std::size_t cells = 0;           ///< (k−1)³ cells of the sample grid
  std::size_t inverted_cells = 0;  ///< cells with at least one corner where det J <= 0
  double min_determinant = 0;      ///< smallest det J sampled
  double max_determinant = 0;      ///< largest det J sampled
  std::array<double, 3> min_at{};  ///< parameters (u, v, w) of the smallest det J
  /// Parameters (u, v, w) of the first inverted samples in C order (u slowest), at most `max_locations`.
  std::vector<std::array<double, 3>> locations;
};

/// Samples det J at the k × k × k points of a uniform grid over volume.domain() and
/// counts the samples and cells where it is <= 0. "<= 0" allows for rounding: a
/// sample counts when det J <= 1e-12 |S_u| |S_v| |S_w|, so a degenerate point (a
/// collapsed edge, where one column vanishes or two are parallel) counts whatever the
/// sign of the rounding. The volume is evaluated slab by slab along u: memory stays
/// bounded for any k.
///
/// Example:
/// @code
///   using namespace interpatch;
///   std::array<Vec3, 8> c;
///   for (int n = 0; n < 8; ++n) c[n] = {double(n >> 2), double((n >> 1) & 1), double(n & 1)};
///   std::swap(c[0], c[7]);                        // two corners exchanged: the cube turns inside out
///   InvertedCells r = inverted_cells(trilinear(c), 21);
///   // r.inverted_points > 0; r.locations holds the first (u, v, w) where det J <= 0
/// @endcode
/// @throws error too_few_points (k < 2), out_of_domain, too_large.
[[nodiscard]] InvertedCells inverted_cells(const Volume& volume, std::size_t k, std::size_t max_locations = 8);

}  // namespace interpatch
