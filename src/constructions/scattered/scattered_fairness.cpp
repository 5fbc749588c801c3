// The thin-plate fairness term of a scattered fit's normal equations: second divided
// differences of the control net over its Greville abscissae, as a matrix, its diagonal,
// or the energy of given values.

#include <array>
#include <span>
#include <vector>

#include "constructions/scattered/scattered_system.hpp"

namespace interpatch::detail::scattered {

namespace {

// Δ of the Greville abscissae around each control point: half the distance between its
// neighbours (one neighbour at an end), the length of line each control point stands for.
std::vector<double> greville_widths(const std::vector<double>& g) {
  std::vector<double> w(g.size(), 0.0);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double lo = i == 0 ? g[0] : (g[i - 1] + g[i]) / 2, hi = i + 1 == g.size() ? g[i] : (g[i] + g[i + 1]) / 2;
    w[i] = hi - lo;
  }
  return w;
}

// add(control points, coefficients, weight) for each term of the thin-plate energy:
// second divided differences over the Greville abscissae along u and along v, and the
// twist, each weighted by the area it stands for.
template <class Add>
void fairness_terms(const Net& net, Add&& add) {
  const std::vector<double> gu = net.ku.greville(), gv = net.kv.greville();
  const std::vector<double> wu = greville_widths(gu), wv = greville_widths(gv);
  // Second divided difference over three abscissae, weighted by the length it stands for.
  auto second = [](const std::vector<double>& g, int i, double out[3]) {
    const double h0 = g[static_cast<std::size_t>(i)] - g[static_cast<std::size_t>(i - 1)];
    const double h1 = g[static_cast<std::size_t>(i + 1)] - g[static_cast<std::size_t>(i)];
    const double f = 2 / (h0 + h1);
    out[0] = f / h0, out[1] = -f / h0 - f / h1, out[2] = f / h1;
  };
  for (int i = 1; i + 1 < net.nu; ++i) {
    double c[3];
    second(gu, i, c);
    const double len = (gu[static_cast<std::size_t>(i + 1)] - gu[static_cast<std::size_t>(i - 1)]) / 2;
    for (int j = 0; j < net.nv; ++j) {
      const std::array<int, 2> at[3] = {{i - 1, j}, {i, j}, {i + 1, j}};
      add(std::span<const std::array<int, 2>>(at), std::span<const double>(c), len * wv[static_cast<std::size_t>(j)]);
    }
  }
  for (int j = 1; j + 1 < net.nv; ++j) {
    double c[3];
    second(gv, j, c);
    const double len = (gv[static_cast<std::size_t>(j + 1)] - gv[static_cast<std::size_t>(j - 1)]) / 2;
    for (int i = 0; i < net.nu; ++i) {
      const std::array<int, 2> at[3] = {{i, j - 1}, {i, j}, {i, j + 1}};
      add(std::span<const std::array<int, 2>>(at), std::span<const double>(c), len * wu[static_cast<std::size_t>(i)]);
    }
  }
  for (int i = 0; i + 1 < net.nu; ++i)
    for (int j = 0; j + 1 < net.nv; ++j) {
      const double hu = gu[static_cast<std::size_t>(i + 1)] - gu[static_cast<std::size_t>(i)];
      const double hv = gv[static_cast<std::size_t>(j + 1)] - gv[static_cast<std::size_t>(j)];
      const double f = 1 / (hu * hv);
      const std::array<int, 2> at[4] = {{i, j}, {i, j + 1}, {i + 1, j}, {i + 1, j + 1}};
      const double c[4] = {f, -f, -f, f};
      add(std::span<const std::array<int, 2>>(at), std::span<const double>(c), 2 * hu * hv);
    }
}

}  // namespace

void add_fairness(const Net& net, NetMatrix* a, double s, std::vector<double>* diagonal) {
  const std::size_t nv = static_cast<std::size_t>(net.nv);
  fairness_terms(net, [&](std::span<const std::array<int, 2>> at, std::span<const double> coef, double weight) {
    if (a) a->add_outer(at, coef, s * weight);
    if (diagonal)
      for (std::size_t x = 0; x < at.size(); ++x)
        (*diagonal)[static_cast<std::size_t>(at[x][0]) * nv + static_cast<std::size_t>(at[x][1])] += weight * coef[x] * coef[x];
  });
}

double fairness_energy(const Net& net, std::span<const double> x, int cols) {
  const std::size_t nv = static_cast<std::size_t>(net.nv), c = static_cast<std::size_t>(cols);
  double sum = 0;
  fairness_terms(net, [&](std::span<const std::array<int, 2>> at, std::span<const double> coef, double weight) {
    for (std::size_t m = 0; m < c; ++m) {
      double d = 0;
      for (std::size_t k = 0; k < at.size(); ++k)
        d += coef[k] * x[(static_cast<std::size_t>(at[k][0]) * nv + static_cast<std::size_t>(at[k][1])) * c + m];
      sum += weight * d * d;
    }
  });
  return sum;
}

}  // namespace interpatch::detail::scattered
