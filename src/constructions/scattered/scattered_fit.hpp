#pragma once
// A scattered fit's problem in its own frame and one net's solve: the normal equations
// (scattered_system.hpp) with a fairness weight, solved directly or by conjugate
// gradients with multigrid (scattered_multigrid.hpp).

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "constructions/scattered/scattered_sites.hpp"
#include "constructions/scattered/scattered_system.hpp"
#include "interpatch/bspline_surface.hpp"

namespace interpatch::detail::scattered {

// The fit in its own frame: the points present (FitPoints: their unit sites, their
// values centred on the points' mean and scaled into a power of two near their size, so
// that sums of squares neither overflow nor vanish) in the order of a Z-curve over the
// domain, so that each knot cell's points come one after another on any net: the net's
// values and matrix rows a pass touches stay in cache, while the points themselves are
// asked for from the input ahead of their use (FitPoints::prefetch).
struct Problem : FitPoints {
  int p = 3, q = 3;
  std::vector<double> weight;  // in `order`; empty when every weight is 1
  std::vector<std::uint8_t> fold;  // for cross-validation (when asked): fold_of(the point)
  std::span<const Vec3> points;  // as given
  double unit_length = 1;  // 1 / scale
  double aspect = 1;  // the domain's extent along u over its extent along v
  /// The points with weights `weight` (the problem's own when empty).
  [[nodiscard]] Samples samples(std::span<const double> w) const { return Samples{{}, w, {}, cols, this}; }
  [[nodiscard]] Samples samples() const { return samples(weight); }
};

/// Nets up to this many control points are factored (milliseconds); larger ones go by
/// conjugate gradients preconditioned by multigrid down to a net this size.
inline constexpr std::size_t coarsest_net = 4096;

/// Refuses (too_large) more points than 32-bit indices reach: the sorts by cell index
/// the points in 32 bits.
void require_indexable(std::size_t points);

/// The problem of `points` at sites `s` (one column, z, when `xy`), with each point's
/// fold when `folds`. The points present in the order of a Z-curve over the domain with
/// `z_curve` (their knot cells' points together on every net a fit tries), otherwise
/// in the order given (a fit on one net, which sorts them by its knot cells alone).
Problem frame(std::span<const Vec3> points, const Sites& s, int p, int q, bool xy, bool folds = false, bool z_curve = true);

/// A point's fold of the cross-validation, from the bits of its coordinates as given:
/// anything computed from them (the centre, the plane) is summed in the points' order
/// and would move the folds when the points are shuffled.
std::uint8_t fold_of(const Vec3& point);

/// A net's values (cols per control point) as a surface over the net's domain (one
/// column: in z).
BSplineSurface unit_surface(const Net& net, std::span<const double> x, int cols);

struct Level {
  std::vector<double> x;
  double lambda = 0;  // in E's units: the weight of J against the mean squared distance
  double x_a_x = 0, x_b = 0;  // xᵀ A x and xᵀ b of the system solved (kept fits only)
};

/// The data term of the points of nonzero `weight` on one net.
System data_system(const Problem& pr, const Net& net, std::span<const double> weight);

/// The small fairness weight that fills voids and makes the system definite: J's
/// diagonal on average 1e-5 of the data term's, far below any smoothing asked for.
double fill_lambda(const Net& net, const NetMatrix& data, double weight_sum);

/// The matrices of nets already solved on the same points and weights, each with the
/// fairness weight summed into it: a finer net's multigrid takes them for its coarse
/// nets, the weight moved by adding the difference times the fairness term, where a
/// pass over the points would assemble them again (the tolerance's refinement solves
/// every net of a finer one's hierarchy before it).
class KeptMatrices {
 public:
  /// The matrix of a net of the same knots moved out, summed with fairness at `scaled`, if kept.
  std::optional<NetMatrix> take(const Net& net, double scaled);
  void keep(const Net& net, NetMatrix a, double scaled);
  [[nodiscard]] bool has(const Net& net) const;

 private:
  struct Entry {
    Net net;
    double scaled = 0;
    NetMatrix a;
  };
  std::vector<Entry> kept_;
};

/// Solves one net's system (fairness added at `scaled`, λ times the weight sum) from
/// the x given (when all zero, conjugate gradients start from the coarsest net's
/// solution), to a residual of 1e-12 of the right-hand side. Factored when small,
/// otherwise by conjugate gradients preconditioned by multigrid over the coarser nets
/// of its hierarchy, whose coarsest matrix `kept` holds (restricted from this one's)
/// and keeps afterwards; factored after all when they stall on a net the factorization still
/// takes, an error past it. Without `rhs_after`, sys.rhs may be spent (emptied).
void solve_net(const Problem& pr, const Net& net, System& sys, double scaled, std::vector<double>& x, KeptMatrices& kept,
               bool rhs_after = true);

/// The distance of a value (cols numbers) from the fit whose net holds `x` (cols per
/// control point) at a unit site, in the fit's frame: the basis there times the net's values.
double distance_of(const Net& net, std::span<const double> x, int cols, std::array<double, 2> site, const double* value);
/// The same for the problem's point k.
inline double distance_at(const Problem& pr, const Net& net, std::span<const double> x, std::size_t k) {
  double v[3];
  pr.value(k, v);
  return distance_of(net, x, pr.cols, pr.unit(k), v);
}

/// One net solved on every point present: λ at least the fill, started from `start`
/// (the net's values), or the coarser fit's values at this net's Greville abscissae,
/// or zero. Its matrices are left in `kept` when given; its data term is `data` when
/// given (made already), otherwise assembled. The nets of its multigrid that `kept`
/// lacks are restricted from its data term (Pᵀ D P, restrict_system), not assembled
/// from the points.
Level solve_level(const Problem& pr, const Net& net, std::optional<double> smoothing, const BSplineSurface* coarser,
                  std::vector<double> start = {}, KeptMatrices* kept = nullptr, std::optional<System> data = std::nullopt);

/// λ chosen by cross-validation and the last fit of the search (of most points).
struct Chosen {
  double lambda = 0;
  std::vector<double> x;
  int fits = 0;  ///< of the folds, over every λ tried
};

/// λ for `net` chosen by cross-validation (the points in 5 folds by their
/// coordinates), reported through `progress` from `from` to `to`.
Chosen choose_lambda(const Problem& pr, const Net& net, const progress_callback& progress, double from, double to);

}  // namespace interpatch::detail::scattered
