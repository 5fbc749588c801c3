#pragma once
// Basis functions of many parameters, computed once per batch evaluation and
// shared by every point that uses them (surfaces and volumes alike).

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "base/text.hpp"
#include "interpatch/knot_vector.hpp"

namespace interpatch::detail {

/// Refuses a parameter outside the knot domain; 1e-12 of the domain's length of
/// slack absorbs rounding in the caller's parameter mapping. A periodic direction
/// takes every finite parameter (it wraps).
inline void check_parameter(const KnotVector& k, double t, const char* dir) {
  if (k.periodic()) {
    if (!std::isfinite(t)) fail(errc::out_of_domain, "parameter ", dir, " = ", t, " is not a number");
    return;
  }
  const double a = k.front(), b = k.back();
  const double slack = 1e-12 * (b - a);
  if (!(t >= a - slack && t <= b + slack))
    fail(errc::out_of_domain, "parameter ", dir, " = ", t, " is outside the domain [", a, ", ", b, "]");
}

/// The span of one parameter and its basis functions with derivatives up to
/// Orders − 1: d[k*(p+1) + j].
template <int Orders>
struct BasisRow {
  int span;
  double d[Orders * (max_degree + 1)];
};

/// Rows for every parameter, derivatives up to nd < Orders. Parameters are checked
/// here, before any parallel region: an exception must not leave one.
template <int Orders>
std::vector<BasisRow<Orders>> basis_table(const KnotVector& k, std::span<const double> ts, int nd, const char* dir) {
  INTERPATCH_ASSERT(nd < Orders);
  std::vector<BasisRow<Orders>> rows(ts.size());
  const int p = k.degree();
  for (std::size_t i = 0; i < ts.size(); ++i) {
    check_parameter(k, ts[i], dir);
    const double t = k.periodic() ? k.wrap(ts[i]) : std::clamp(ts[i], k.front(), k.back());
    rows[i].span = k.find_span(t);
    if (nd == 0) {
      k.basis(rows[i].span, t, rows[i].d);
    } else {
      double tmp[(max_degree + 1) * (max_degree + 1)];
      k.basis_derivatives(rows[i].span, t, nd, tmp);
      std::copy(tmp, tmp + (nd + 1) * (p + 1), rows[i].d);
    }
  }
  return rows;
}

}  // namespace interpatch::detail
