#pragma once
// The fit of the sparse normal equations with a fairness weight: a given one (at
// least the weight that fills holes in the data), or one chosen by generalized
// cross-validation.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_normal.hpp"

namespace interpatch::detail::approx {

// The fairness weight that fills holes: a fraction 1e-5 of the data term's mean
// diagonal. It keeps the system definite where there is no data and changes the fit
// elsewhere by about that fraction at the finest scale of the control net, far below
// any tolerance a user asks for.
constexpr double fill_fraction = 1e-5;

// The fit of the sparse system with fairness weight λ (none: 0), at least the
// weight that fills holes when `fill`.
template <std::size_t R>
void sparse_fit(Fit<R>& f, SparseSystem<R>& sys, const std::vector<double>& rhs, std::optional<double> lambda, bool fill) {
  const double filler = fill ? fill_fraction * sys.diagonal_ratio() : 0.0;
  f.lambda = lambda ? std::max(*lambda, filler) : filler;
  sys.factor(f.lambda);
  f.cp = sys.solve(rhs);
}

// λ by generalized cross-validation: the minimum over λ of
//   V(λ) = n Σ w r² / (n − tr H(λ))²,
// n the points present, H the map from data to fitted values (its trace estimated),
// first on a grid of one value per decade, then by golden section around the best.
// `present` points with data, `fill`: some are missing; rss(cp): the weighted sum of
// squared residuals of control points cp.
template <std::size_t R, class Rss>
void gcv_fit(Fit<R>& f, SparseSystem<R>& sys, const std::vector<double>& rhs, std::size_t present, bool fill, const Rss& rss_of) {
  const auto n = static_cast<double>(present);
  // Probes of the trace estimate: its error, about sqrt(2 / probes) of the Frobenius
  // norm of M⁻¹ λ s K (at most sqrt(C)), stays a small part of n − tr H.
  constexpr int probes = 24;
  // With holes, λ never goes below the weight that fills them.
  const double floor = fill ? fill_fraction * sys.diagonal_ratio() : 0.0;
  auto score = [&](double log_lambda) {
    ++f.fits;
    const double lambda = std::max(floor, std::pow(10.0, log_lambda));
    try {
      sys.factor(lambda);
    } catch (const error& e) {
      if (e.code() != errc::singular) throw;
      return std::numeric_limits<double>::infinity();  // too little fairness for the data: not a candidate
    }
    f.cp = sys.solve(rhs);
    const double rss = rss_of(f.cp);
    // n − tr H = n − C + tr(M⁻¹ λ s K).
    const double rest = n - static_cast<double>(sys.data.rows()) + sys.fairness_trace(lambda, probes);
    if (!(rest > 0)) return std::numeric_limits<double>::infinity();
    return n * rss / (rest * rest);
  };
  double best = -12, best_v = std::numeric_limits<double>::infinity();
  for (int e = -12; e <= 4; ++e)
    if (const double v = score(e); v < best_v) {
      best_v = v;
      best = e;
    }
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = best - 1, hi = best + 1;
  double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo);
  double v1 = score(x1), v2 = score(x2);
  for (int it = 0; it < 10; ++it) {
    if (v1 < v2) {
      hi = x2, x2 = x1, v2 = v1;
      x1 = hi - phi * (hi - lo);
      v1 = score(x1);
    } else {
      lo = x1, x1 = x2, v1 = v2;
      x2 = lo + phi * (hi - lo);
      v2 = score(x2);
    }
  }
  double x = v1 < v2 ? x1 : x2;
  if (std::min(v1, v2) > best_v) x = best;
  f.lambda = std::max(floor, std::pow(10.0, x));
  sys.factor(f.lambda);
  f.cp = sys.solve(rhs);
}

}  // namespace interpatch::detail::approx
