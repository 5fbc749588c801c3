#pragma once
// Collocation systems of B-spline interpolation: row i holds the basis functions
// (or their derivatives) of a knot vector at parameter t_i.

#include <span>
#include <vector>

#include "linalg/banded.hpp"
#include "interpatch/knot_vector.hpp"

namespace interpatch::detail {

/// One condition of a collocation system: the `order`-th derivative at `t`.
struct Condition {
  double t;
  int order = 0;
};

/// The factored collocation matrix A[i][j] = N_j^{(order_i)}(t_i). Rows are the
/// conditions in order; the count must equal knots.count().
/// @throws error singular, naming the row and the parameter there.
BandedLU factor_collocation(const KnotVector& knots, std::span<const Condition> rows);

/// The same for plain point conditions.
BandedLU factor_collocation(const KnotVector& knots, std::span<const double> params);

/// The factored cyclic collocation matrix of a periodic knot vector: row i holds the
/// basis functions at params[i] (wrapped into the domain), column j the control
/// point j; params.size() must equal knots.count().
/// @throws error singular, naming the row and the parameter there.
CyclicLU factor_periodic_collocation(const KnotVector& knots, std::span<const double> params);

}  // namespace interpatch::detail
