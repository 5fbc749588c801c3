// Residuals of the least-squares fit (approx_residuals.hpp): where each basis value
// finds its control point, and the residual of a line fitted along one direction.

#include "constructions/approximate/approx_residuals.hpp"

#include <variant>

namespace interpatch::detail::approx {

std::vector<std::size_t> residual_offsets(const Axis& last) {
  const std::size_t pp = static_cast<std::size_t>(last.p) + 1;
  std::vector<std::size_t> off(last.n * pp);
  for (std::size_t i = 0; i < last.n; ++i)
    for (std::size_t k = 0; k < pp; ++k) off[i * pp + k] = 3 * last.col(last.first[i] + static_cast<int>(k));
  return off;
}

double line_fit_residual(const Axis& ax, const AxisSolver& lu, const std::vector<double>& line, std::size_t pos) {
  const std::size_t n = ax.n;
  const auto pp = static_cast<std::size_t>(ax.p) + 1;
  std::vector<double> x(static_cast<std::size_t>(ax.c) * 3, 0.0);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t l = 0; l < pp; ++l)
      for (std::size_t m = 0; m < 3; ++m) x[3 * ax.col(ax.first[k] + static_cast<int>(l)) + m] += ax.b[k * pp + l] * line[3 * k + m];
  std::visit([&](const auto& solver) { solver.solve(x.data(), 3, 3); }, lu);
  Vec3 e{};
  for (std::size_t l = 0; l < pp; ++l)
    for (std::size_t m = 0; m < 3; ++m)
      e[static_cast<int>(m)] += ax.b[pos * pp + l] * x[3 * ax.col(ax.first[pos] + static_cast<int>(l)) + m];
  return distance(e, Vec3{line[3 * pos], line[3 * pos + 1], line[3 * pos + 2]});
}

}  // namespace interpatch::detail::approx
