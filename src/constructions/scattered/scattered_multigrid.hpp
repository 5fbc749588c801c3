#pragma once
// Multigrid for the normal equations of a scattered fit: the same functional (data term
// and fairness with the same weight) on nets of halved spans, a symmetric
// V-cycle of strip Gauss–Seidel (scattered_smoother.hpp) between them and a factored
// coarsest net, used to precondition conjugate gradients. The data term alone is a mass
// matrix whose oscillating modes a point smoother damps slowly; the fairness term across
// voids is a biharmonic one whose smooth modes only the coarse nets reach.

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "constructions/scattered/scattered_smoother.hpp"
#include "constructions/scattered/scattered_system.hpp"

namespace interpatch::detail::scattered {

/// The control points of a spline on one knot vector as those of a spline on a finer
/// one, every coarse knot a fine knot, along one direction: fine point i is
/// Σ_a weight[i·(p+1) + a] times coarse point first[i] + a (knot insertion by
/// blossoming, the Oslo algorithm); the identity when both are one.
struct Refinement {
  int p = 3, fine = 0, coarse = 0;
  std::vector<int> first;
  std::vector<double> weight;
  /// The transpose, row a of the coarse points: (fine index, weight) pairs from
  /// t_start[a] to t_start[a + 1].
  std::vector<std::size_t> t_start;
  std::vector<int> t_index;
  std::vector<double> t_weight;
};
Refinement refinement(const KnotVector& coarse, const KnotVector& fine);

/// The data term of a coarser net from a finer one's: Pᵀ A P and Pᵀ b for the
/// refinement P of `r`, in time proportional to the fine net rather than to the points.
/// Exact when every coarse knot is a fine knot: each coarse basis function is then a
/// combination of fine ones (P's columns), and so are the sums over the points. Coarse
/// functions whose supports do not meet get nothing: no fine functions refining them
/// meet either.
System restrict_system(const System& fine, const std::array<Refinement, 2>& r);

/// Whether every knot of `coarse` is a knot of `fine` (with at least its multiplicity),
/// so that refinement is knot insertion and restrict_system exact.
bool nests(const KnotVector& coarse, const KnotVector& fine);

/// The data terms of `nets` (coarsest first, each coarser than the next, the last
/// coarser than `top_net`, whose data term is `top`, their knots nested as hierarchy
/// makes them): each restricted from the next finer one's, with no pass over the
/// points.
std::vector<System> restrict_down(const System& top, const Net& top_net, std::span<const Net> nets);

/// The nets of a multigrid below `top`, coarsest first and `top` last: each
/// Net::coarser than the next (each direction's spans halved, rounded up, while above
/// 4), until a net has at most `coarsest` control points. Their knots nest.
std::vector<Net> hierarchy(const Net& top, std::size_t coarsest);

/// A V-cycle over nets whose matrices the caller owns (and may change between
/// factor() calls, as a search over the fairness weight does).
class Multigrid {
 public:
  /// nets and matrices coarsest first; the matrices outlive this object.
  Multigrid(std::vector<Net> nets, std::vector<const NetMatrix*> matrices, int cols);
  /// Factors the coarsest matrix and the finer ones' smoothers (again). False when the
  /// coarsest is not positive definite.
  bool factor();
  /// z = the V-cycle applied to r: one forward sweep of the strip smoother down, the
  /// coarsest solved, one backward sweep up, so the operator is symmetric positive
  /// definite.
  void apply(std::span<const double> r, std::span<double> z);
  [[nodiscard]] const Net& net(std::size_t level) const { return nets_[level]; }
  [[nodiscard]] std::size_t levels() const { return nets_.size(); }

 private:
  void cycle(std::size_t level, std::span<const double> b, std::span<double> x);
  std::vector<Net> nets_;
  std::vector<const NetMatrix*> a_;
  std::vector<std::array<Refinement, 2>> up_;  // up_[l]: level l - 1 to level l
  std::vector<std::vector<double>> r_, b_, x_, tmp_;
  std::optional<DirectSolver> coarsest_;
  std::vector<StripSmoother> smoothers_;  // smoothers_[l - 1]: level l's
  int cols_;
};

}  // namespace interpatch::detail::scattered
