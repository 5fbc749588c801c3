#include "linalg/collocation.hpp"

#include <algorithm>

#include "base/text.hpp"

namespace interpatch::detail {

BandedLU factor_collocation(const KnotVector& knots, std::span<const Condition> rows) {
  const int n = knots.count();
  const int p = knots.degree();
  INTERPATCH_ASSERT(static_cast<int>(rows.size()) == n);
  std::vector<int> spans(rows.size());
  int kl = 0, ku = 0;
  for (int i = 0; i < n; ++i) {
    const int s = knots.find_span(rows[static_cast<std::size_t>(i)].t);
    spans[static_cast<std::size_t>(i)] = s;
    kl = std::max(kl, i - (s - p));
    ku = std::max(ku, s - i);
  }
  BandedLU lu(n, kl, ku);
  double ders[(max_degree + 1) * (max_degree + 1)];
  for (int i = 0; i < n; ++i) {
    const auto& c = rows[static_cast<std::size_t>(i)];
    const int s = spans[static_cast<std::size_t>(i)];
    knots.basis_derivatives(s, c.t, c.order, ders);
    for (int j = 0; j <= p; ++j) lu.at(i, s - p + j) = ders[c.order * (p + 1) + j];
  }
  if (!lu.factor()) {
    const auto r = static_cast<std::size_t>(lu.failed_row());
    fail(errc::singular, "collocation matrix is singular at row ", r, " (parameter ", rows[r].t,
         "): the parameters do not fit the knots (Schoenberg-Whitney condition fails)");
  }
  return lu;
}

BandedLU factor_collocation(const KnotVector& knots, std::span<const double> params) {
  std::vector<Condition> rows(params.size());
  for (std::size_t i = 0; i < params.size(); ++i) rows[i] = {params[i], 0};
  return factor_collocation(knots, rows);
}

CyclicLU factor_periodic_collocation(const KnotVector& knots, std::span<const double> params) {
  const int n = knots.count(), p = knots.degree();
  INTERPATCH_ASSERT(knots.periodic() && static_cast<int>(params.size()) == n);
  std::vector<std::vector<CyclicLU::Entry>> rows(params.size());
  double N[max_degree + 1];
  for (std::size_t i = 0; i < params.size(); ++i) {
    const double t = knots.wrap(params[i]);
    const int s = knots.find_span(t);
    knots.basis(s, t, N);
    for (int j = 0; j <= p; ++j)
      if (N[j] != 0.0) rows[i].push_back({knots.wrap_index(s - p + j), N[j]});
  }
  CyclicLU lu(n, rows);
  if (!lu.factor()) {
    const auto r = static_cast<std::size_t>(lu.failed_row());
    fail(errc::singular, "periodic collocation matrix is singular at row ", r, " (parameter ", params[r],
         "): the parameters do not fit the knots (Schoenberg-Whitney condition fails)");
  }
  return lu;
}

}  // namespace interpatch::detail
