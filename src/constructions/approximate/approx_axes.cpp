// The directions of the least-squares fit (approx_axes.hpp): basis values at the data
// parameters, the Gram and fairness bands, and the factored Gram matrix of a direction.

#include "constructions/approximate/approx_axes.hpp"

#include <algorithm>
#include <utility>

namespace interpatch::detail::approx {

void Axis::set_knots(KnotVector k) {
  knots = std::move(k);
  c = knots.count();
  const auto pp = static_cast<std::size_t>(p) + 1;
  first.assign(n, 0);
  b.assign(n * pp, 0.0);
  interval.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = knots.periodic() ? knots.wrap(t[i]) : std::clamp(t[i], knots.front(), knots.back());
    const int span = knots.find_span(x);
    knots.basis(span, x, &b[i * pp]);
    first[i] = span - p;
    interval[i] = span - p;
  }
  intervals = periodic ? c : c - p;
}

Band Axis::gram(int h) const {
  Band g(c, h);
  const auto pp = static_cast<std::size_t>(p) + 1;
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k <= p; ++k)
      for (int l = 0; l <= p; ++l)
        g.at(static_cast<int>(col(first[i] + k)), l - k) += b[i * pp + static_cast<std::size_t>(k)] * b[i * pp + static_cast<std::size_t>(l)];
  return g;
}

Band Axis::fairness(int h) const {
  Band r(c, h);
  const auto& u = knots.values();
  auto greville = [&](int i) {  // i may be -1 or c in a closed direction
    const double period = knots.back() - knots.front();
    const int j = i < 0 ? i + c : (i >= c ? i - c : i);
    double s = 0;
    for (int k = 1; k <= p; ++k) s += u[static_cast<std::size_t>(j + k)];
    return s / p + (i < 0 ? -period : (i >= c ? period : 0.0));
  };
  const int lo = periodic ? 0 : 1, hi = periodic ? c : c - 1;
  for (int i = lo; i < hi; ++i) {
    const double g0 = greville(i - 1), g1 = greville(i), g2 = greville(i + 1);
    const double h1 = g1 - g0, h2 = g2 - g1, span = g2 - g0;
    if (!(h1 > 0 && h2 > 0)) continue;  // coincident abscissae: no curvature to measure there
    const double alpha = 2.0 / span, omega = 0.5 * span;
    const double d[3] = {alpha / h1, -alpha * (1.0 / h1 + 1.0 / h2), alpha / h2};
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        const int row = i - 1 + k;
        r.at(static_cast<int>(col(row < 0 ? row + c : row)), l - k) += omega * d[k] * d[l];
      }
  }
  return r;
}

AxisSolver factor_gram(const Axis& ax, std::size_t a) {
  const Band g = ax.gram(ax.p);
  auto singular = [&](int row) {
    fail(errc::singular, "along ", axis_name(a), ": the least-squares system of ", ax.c, " control points over ", ax.n,
         " data points has no unique solution (control point ", row, " has no data under it)");
  };
  if (ax.periodic) {
    std::vector<std::vector<detail::CyclicLU::Entry>> rows(static_cast<std::size_t>(ax.c));
    for (int i = 0; i < ax.c; ++i)
      for (int d = -ax.p; d <= ax.p; ++d)
        if (const double v = g.at(i, d); v != 0.0) rows[static_cast<std::size_t>(i)].push_back({((i + d) % ax.c + ax.c) % ax.c, v});
    detail::CyclicLU lu(ax.c, rows);
    if (!lu.factor()) singular(lu.failed_row());
    return lu;
  }
  detail::BandedLU lu(ax.c, ax.p, ax.p);
  for (int i = 0; i < ax.c; ++i)
    for (int d = -ax.p; d <= ax.p; ++d)
      if (i + d >= 0 && i + d < ax.c) lu.at(i, i + d) = g.at(i, d);
  if (!lu.factor()) singular(lu.failed_row());
  return lu;
}

std::span<const Vec3> net_points(const std::vector<double>& cp) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "a control net is triples of doubles");
  return {reinterpret_cast<const Vec3*>(cp.data()), cp.size() / 3};
}

}  // namespace interpatch::detail::approx
