#pragma once
// The smoother of the scattered multigrid: block Gauss–Seidel over strips of control
// points, each strip solved exactly. With only the small fill weight, the normal
// equations of points scattered a few to a knot cell have near-null modes a few control
// points wide (clusters a handful of points hardly tell apart, the clamped edges' B-splines
// that barely reach any point). Point Gauss–Seidel damps them by a hair a sweep and the
// coarse nets cannot hold them; a strip solved whole removes them. Strips along v, then
// strips along u.

#include <algorithm>
#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "constructions/scattered/scattered_system.hpp"

namespace interpatch::detail::scattered {

/// Entries left of the diagonal kept in row k of a strip's factor (strip_row_length):
/// unknown (t, w) of a strip `width` wide couples back to (t - reach, 0) at most,
/// reach·width + w places before it, and the factor fills no place before a row's first
/// entry (the band's whole width kept a tenth more numbers, all zero).
inline std::size_t strip_row_length(std::size_t k, std::size_t reach, std::size_t width) {
  return std::min(k, reach * width + k % width);
}

/// Strips of control points max(hu, hv) + 1 wide across the whole net, along each
/// direction, every strip's matrix factored as a band (LLᵀ).
class StripSmoother {
 public:
  /// Factors the strips of `a` along both directions, its entries as they are now.
  explicit StripSmoother(const NetMatrix& a);
  /// One sweep of block Gauss–Seidel on a x = b, in place: the strips along v (if
  /// any), then those along u, each in two colours of strips that share no entry of the matrix
  /// (a colour's strips solved by the threads at once; the same bits on any number of
  /// them). `backward` runs everything in reverse order: a forward sweep then a
  /// backward one is symmetric. A strip whose matrix did not factor (not positive
  /// definite to rounding) is left out.
  /// `work` holds the strips' residuals (resized to the net's values); `from_zero` says x
  /// is zero, so the first colour's residuals are b itself.
  void sweep(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols, bool backward,
             std::vector<double>& work, bool from_zero = false) const;
  /// The bytes a control point's share of the factors takes.
  static std::size_t bytes_per_row(int hu, int hv);

 private:
  struct Strip {
    int dir = 0;  // 0: rows i in [first, first + width), every j; 1: columns j likewise
    int index = 0, first = 0, width = 0;  // index: its place along the direction (the colour's parity)
    int reach = 0;  // the matrix's reach along the strip
    int band = 0;   // half bandwidth of the strip's matrix in its own order
    std::size_t size = 0, at = 0;  // unknowns, offset of its factor in factor_
    bool ok = false;
    /// Entries of the factor's row k left of the diagonal.
    [[nodiscard]] std::size_t length(std::size_t k) const {
      return strip_row_length(k, static_cast<std::size_t>(reach), static_cast<std::size_t>(width));
    }
  };
  // f(k, i, j, row) for a strip's unknowns in order, without dividing for each.
  template <class F>
  void for_each_row(const Strip& s, F&& f) const {
    const int along = s.dir == 0 ? nv_ : nu_;
    std::size_t k = 0;
    for (int t = 0; t < along; ++t)
      for (int w = 0; w < s.width; ++w, ++k) {
        const int i = s.dir == 0 ? s.first + w : t, j = s.dir == 0 ? t : s.first + w;
        f(k, i, j, static_cast<std::size_t>(i) * static_cast<std::size_t>(nv_) + static_cast<std::size_t>(j));
      }
  }
  // A thread's room to factor a strip, made before the threads start: the band in double,
  // and each unknown's control point (i, j) and row.
  struct FactorScratch {
    std::vector<double> band;
    std::vector<std::array<int, 2>> at;
    std::vector<std::size_t> row;
  };
  void factor(const NetMatrix& a, Strip& s, FactorScratch& scratch);
  // r = b - A x at (at least) the control points of one direction's strips of one
  // colour, the matrix's rows read in memory order whatever the direction.
  void residuals(int dir, int colour, const NetMatrix& a, std::span<const double> b, std::span<const double> x, std::size_t c,
                 std::span<double> r) const;
  // The strip's correction for the residual r, added to x (its unknowns gathered into
  // `scratch` in the strip's order).
  void solve(const Strip& s, std::span<const double> r, std::span<double> x, std::size_t c, std::vector<double>& scratch) const;
  int nu_, nv_;
  std::vector<Strip> strips_;  // along u, then along v, each by first
  // Per strip, row k: L[k][k - n .. k - 1], then 1 / L[k][k], n = Strip::length(k). In single precision:
  // the sweeps read it from memory (two passes a row per sweep) at half the cost, and a
  // smoother needs no more than its seven digits.
  std::unique_ptr<float[]> factor_;
};

}  // namespace interpatch::detail::scattered
