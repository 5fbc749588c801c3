#pragma once
// Multigrid for the normal equations of a scattered fit: the same functional (data term
// and fairness with the same weight) on nets of halved spans, a strip Gauss–Seidel
// smoother (scattered_smoother.hpp) on the finest and a factored coarsest net, used to
// precondition conjugate gradients. The data term alone is a mass matrix whose
// oscillating modes a point smoother damps slowly; the fairness term across voids is a
// biharmonic one whose smooth modes only the coarse net reaches.

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

/// The preconditioner: one forward sweep of the strip smoother on the finest net, the
/// residual carried down the nets below by Pᵀ to the coarsest and solved there by its
/// factor, the correction carried back up by P, one backward sweep. The nets between
/// are not smoothed: their knot cells hold four times the points of the next finer
/// one's or more, and smoothing them changed no step count (15 on 10^6 points and a
/// 512 × 512 net, 9 on the terrain's 259 × 259, 23 on 140 × 140, 42 on 700 × 700; 58
/// against 59 on 4·10^6 points and 1 400 × 1 400) for a tenth of the time and their
/// factors' memory. Their matrices serve only to restrict the coarsest one's.
class Multigrid {
 public:
  /// nets coarsest first; the two matrices, of the first and the last net (the same one
  /// when there is one net), outlive this object and may change between factor() calls,
  /// as a search over the fairness weight does.
  Multigrid(std::vector<Net> nets, const NetMatrix* coarsest, const NetMatrix* finest, int cols);
  /// Factors the coarsest matrix and the finest one's strips (again). False when the
  /// coarsest is not positive definite.
  bool factor();
  /// z = the preconditioner applied to r: symmetric positive definite, the backward
  /// sweep the forward one's adjoint.
  void apply(std::span<const double> r, std::span<double> z);
  [[nodiscard]] const Net& net(std::size_t level) const { return nets_[level]; }
  [[nodiscard]] std::size_t levels() const { return nets_.size(); }

 private:
  std::vector<Net> nets_;
  const NetMatrix* coarsest_a_;
  const NetMatrix* finest_a_;
  std::vector<std::array<Refinement, 2>> up_;  // up_[l]: level l - 1 to level l
  std::vector<std::vector<double>> b_, x_;  // below the finest net: the residual, the correction
  std::vector<double> r_, tmp_;
  std::optional<DirectSolver> coarsest_;
  std::optional<StripSmoother> smoother_;
  int cols_;
};

}  // namespace interpatch::detail::scattered
