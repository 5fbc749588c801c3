#pragma once
/// @file surface.hpp
/// What every surface of interpatch offers: exact evaluation with derivatives,
/// batch evaluation over parameter grids, and its exact B-spline form.

#include <array>
#include <memory>
#include <span>
#include <utility>

#include "interpatch/grid.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch {

class BSplineSurface;

/// A surface point with its first and second partial derivatives.
struct SurfaceDerivatives {
  Vec3 s, su, sv, suu, suv, svv;
};

/// A parametric surface S(u, v) over [0, 1]² (B-spline surfaces over their own
/// knot domain).
class Surface {
 public:
  virtual ~Surface() = default;

  /// The parameter box [u0, u1] × [v0, v1]; [0, 1]² unless the surface says otherwise
  /// (a B-spline surface: its knot domain).
  [[nodiscard]] virtual std::array<std::pair<double, double>, 2> domain() const { return {{{0.0, 1.0}, {0.0, 1.0}}}; }

  /// S(u, v). @throws error out_of_domain.
  [[nodiscard]] virtual Vec3 point(double u, double v) const { return derivatives(u, v).s; }
  /// S and its partial derivatives up to second order, from the construction's own
  /// formula. @throws error out_of_domain.
  [[nodiscard]] virtual SurfaceDerivatives derivatives(double u, double v) const = 0;
  /// Points at every (us[i], vs[j]): a us.size() × vs.size() grid, through
  /// evaluate_into(). @throws error out_of_domain, too_large.
  [[nodiscard]] PointGrid evaluate(std::span<const double> us, std::span<const double> vs,
                                   const progress_callback& progress = {}) const;
  /// Points at every (us[i], vs[j]) into memory the caller owns: out[i * vs.size() + j].
  /// A block of rows at a time into one reused buffer, or straight into a mapped
  /// file, costs no memory for the whole grid.
  ///
  /// Example:
  /// @code
  ///   std::vector<interpatch::Vec3> rows(16 * vs.size());
  ///   for (std::size_t i = 0; i < us.size(); i += 16) {
  ///     const auto block = std::span(us).subspan(i, std::min<std::size_t>(16, us.size() - i));
  ///     const auto out = std::span(rows).first(block.size() * vs.size());
  ///     surface.evaluate_into(block, vs, out);
  ///     consume(block, out);  // S(block[a], vs[b]) is out[a * vs.size() + b]
  ///   }
  /// @endcode
  /// @throws error out_of_domain; size_mismatch when out.size() != us.size() * vs.size().
  virtual void evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                             const progress_callback& progress = {}) const;
  /// Points and unit normals at every (us[i], vs[j]) into memory the caller owns,
  /// points[i * vs.size() + j] and normals[...] (unit_normal() of the derivatives
  /// there: at a pole, the limit along the vanishing direction). What a mesh with
  /// normals needs, without the grid of second derivatives evaluate_derivatives()
  /// makes (a blended surface sums its first derivatives row by row, in place).
  /// @throws error out_of_domain; size_mismatch when either output's size is not
  /// us.size() * vs.size().
  virtual void evaluate_normals_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> points,
                                     std::span<Vec3> normals, const progress_callback& progress = {}) const;
  /// Rows of points on one set of v parameters, evaluated a block of rows at a time
  /// (a file written block by block): Surface::rows() works out once what depends on
  /// v alone, which evaluate_into() would work out again for every block.
  class Rows {
   public:
    virtual ~Rows() = default;
    /// evaluate_into(us, vs, out, progress) with the vs given to rows(): the same
    /// points. @throws error out_of_domain; size_mismatch when out.size() != us.size() * vs.size().
    virtual void evaluate_into(std::span<const double> us, std::span<Vec3> out, const progress_callback& progress = {}) const = 0;
  };
  /// The rows of this surface on the parameters `vs` (copied), for evaluate_into() of
  /// block after block of u; the surface must outlive the result. A blended surface
  /// evaluates its functions of v here, once. @throws error out_of_domain, here or from
  /// Rows::evaluate_into.
  [[nodiscard]] virtual std::unique_ptr<Rows> rows(std::span<const double> vs) const;
  /// Points and unit normals on one grid us × vs, a rectangle of it at a time (a mesh
  /// written a block of columns at a time): Surface::normal_grid() works out once
  /// what depends on u alone and on v alone, which evaluate_normals_into() of each
  /// rectangle would work out again.
  class NormalGrid {
   public:
    virtual ~NormalGrid() = default;
    /// evaluate_normals_into(us[i0, i0 + ni), vs[j0, j0 + nj), points, normals) with
    /// the us and vs given to normal_grid(): the same bits as the whole grid's points
    /// and normals there, whatever the rectangle. Calls on different threads at once
    /// are safe. @throws error out_of_domain (a rectangle beyond the grid);
    /// size_mismatch when either output's size is not ni * nj.
    virtual void evaluate_into(std::size_t i0, std::size_t ni, std::size_t j0, std::size_t nj, std::span<Vec3> points,
                               std::span<Vec3> normals) const = 0;
  };
  /// The grid us × vs (both copied) for NormalGrid::evaluate_into() of rectangle after
  /// rectangle; the surface must outlive the result. A blended surface evaluates its
  /// functions of u and of v, with their derivatives, here, once.
  /// @throws error out_of_domain, here or from NormalGrid::evaluate_into.
  [[nodiscard]] virtual std::unique_ptr<NormalGrid> normal_grid(std::span<const double> us,
                                                                std::span<const double> vs) const;
  /// Points and derivatives at every (us[i], vs[j]). @throws error out_of_domain, too_large.
  [[nodiscard]] virtual Grid<SurfaceDerivatives, 2> evaluate_derivatives(std::span<const double> us,
                                                                         std::span<const double> vs) const;
  /// The same surface as a B-spline surface (polynomial or rational) that
  /// evaluates to the same points up to rounding.
  /// @throws error no_exact_form when the construction has none.
  [[nodiscard]] virtual BSplineSurface to_bspline() const = 0;

 protected:
  Surface() = default;
  Surface(const Surface&) = default;
  Surface(Surface&&) = default;
  Surface& operator=(const Surface&) = default;
  Surface& operator=(Surface&&) = default;
};

}  // namespace interpatch
