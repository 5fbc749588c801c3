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

/// `fine_term`, the data term of `fine`, restricted to `coarse`, whose knots are all
/// knots of `fine`'s (any number of nets apart): restrict_system with the refinement
/// between them.
System restrict_between(const System& fine_term, const Net& fine, const Net& coarse);

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
/// residual carried to the coarsest net of its hierarchy by Pᵀ (knot insertion from the
/// coarsest knots to the finest, p + 1 weights a fine row whatever the nets between)
/// and solved there by its factor, the correction carried back by P, one backward
/// sweep. The nets between are not smoothed: their knot cells hold four times the
/// points of the next finer one's or more, and smoothing them changed no step count (15
/// on 10^6 points and a 512 × 512 net, 9 on the terrain's 259 × 259, 23 on 140 × 140,
/// 42 on 700 × 700; 58 against 59 on 4·10^6 points and 1 400 × 1 400) for a tenth of
/// the time and their factors' memory.
///
/// The sweeps, their strips' factors and the residual carried down read a packed
/// matrix's floats alone (NetMatrix::Part::floats), a third less time than its entries
/// whole: the cycle is then the same one for the matrix F of those floats, symmetric,
/// and positive definite whenever the strips' own blocks of F are (a forward sweep's M
/// has M + Mᵀ − F = those blocks, which their factoring checks), F itself or not.
/// Conjugate gradients' products read the entries whole.
class Multigrid {
 public:
  /// The coarsest net and the finest (one net: the finest factored), and their
  /// matrices, which outlive this object and may change between factor() calls, as a
  /// search over the fairness weight does.
  Multigrid(const Net& coarsest, const Net& finest, const NetMatrix* coarsest_a, const NetMatrix* finest_a, int cols);
  /// Factors the coarsest matrix and the finest one's strips (again). False when the
  /// coarsest is not positive definite.
  bool factor();
  /// z = the preconditioner applied to r: symmetric positive definite, the backward
  /// sweep the forward one's adjoint.
  void apply(std::span<const double> r, std::span<double> z);
  /// x = P A_c⁻¹ Pᵀ b: the coarsest net's solution refined onto the finest, where
  /// conjugate gradients with nothing better start (a step fewer on 10^6 points and a
  /// 512 × 512 net than from zero). Nothing when there is one net.
  void coarse_guess(std::span<const double> b, std::span<double> x);

 private:
  const NetMatrix* coarsest_a_;
  const NetMatrix* finest_a_;
  bool one_net_;
  std::array<Refinement, 2> up_;  // the coarsest net to the finest
  // The finest net's residual (and the sweeps' room); the coarsest's problem and solution;
  // a pass of the restriction or the prolongation.
  std::vector<double> r_, b_, x_, tmp_;
  std::optional<DirectSolver> coarsest_;
  std::optional<StripSmoother> smoother_;
  int cols_;
};

}  // namespace interpatch::detail::scattered
