#include "mesh/distributions.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace interpatch::mesh {

namespace {

// The sum 1 + r + ... + r^(m-1) for r = e^x.
double geometric_sum(double x, std::size_t m) {
  if (std::fabs(x) < 1e-12) return static_cast<double>(m);
  return std::expm1(x * static_cast<double>(m)) / std::expm1(x);
}

// Cells of one end's geometric progression: first cell `a` (of a total of 1) over m cells.
std::vector<double> geometric_cells(double a, std::size_t m) {
  // a · Σ r^k = 1, increasing in x = ln r.
  double lo = -700.0 / static_cast<double>(m), hi = 700.0 / static_cast<double>(m);
  if (a * static_cast<double>(m) == 1) lo = hi = 0;
  for (int i = 0; i < 300 && hi - lo > 1e-17 * (1 + std::fabs(lo)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (a * geometric_sum(mid, m) < 1 ? lo : hi) = mid;
  }
  const double r = std::exp(0.5 * (lo + hi));
  std::vector<double> cells(m);
  double c = 1;
  for (std::size_t k = 0; k < m; ++k, c *= r) cells[k] = c;
  return cells;
}

// Vinokur's two-sided stretching over m cells with end slopes set by d0 and d1 (the
// first and last cells of a total of 1, to first order).
struct Vinokur {
  double a = 1, b = 1, delta = 0;
  std::size_t m = 1;

  Vinokur(double d0, double d1, std::size_t cells) : m(cells) {
    const double fm = static_cast<double>(m);
    b = 1 / (fm * std::sqrt(d0 * d1));
    a = std::sqrt(d1 / d0);
    if (b > 1 + 1e-12) {  // sinh(δ)/δ = b, in logarithms so that large δ stays finite
      const double lb = std::log(b);
      double lo = 0, hi = 800;
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        const double f = mid > 20 ? mid - std::log(2 * mid) : std::log(std::sinh(mid) / mid);
        (f < lb ? lo : hi) = mid;
      }
      delta = 0.5 * (lo + hi);
    } else if (b < 1 - 1e-12) {  // sin(δ)/δ = b, δ in (0, π)
      double lo = 0, hi = std::numbers::pi;
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (std::sin(mid) / mid > b ? lo : hi) = mid;
      }
      delta = 0.5 * (lo + hi);
    }
  }
  // Node k's position.
  [[nodiscard]] double node(std::size_t k) const {
    if (k == 0) return 0;
    if (k == m) return 1;
    const double xi = static_cast<double>(k) / static_cast<double>(m);
    double u = xi;
    if (b > 1 + 1e-12) u = 0.5 * (1 + std::tanh(delta * (xi - 0.5)) / std::tanh(0.5 * delta));
    else if (b < 1 - 1e-12) u = 0.5 * (1 + std::tan(delta * (xi - 0.5)) / std::tan(0.5 * delta));
    return u / (a + (1 - a) * u);
  }
};

}  // namespace

// The nodes σ_0 = 0 < ... < σ_m = 1 of a distribution over m cells: a ratio, a first
// cell a, a last cell b, or both ends. Empty when none fits m cells.
std::vector<double> sigma_nodes(const Grading& g, double a, double b, std::size_t m) {
  std::vector<double> s(m + 1, 0.0);
  if (g.first != 0 && g.last != 0) {
    if (m < 2 || a + b >= 1) return {};
    // The end slopes that give the end cells asked for: a fixed point on the two
    // end nodes alone, then every node.
    double d0 = a, d1 = b;
    for (int i = 0; i < 500; ++i) {
      const Vinokur v(d0, d1, m);
      const double fa = v.node(1), fb = 1 - v.node(m - 1);
      if (!(fa > 0 && fb > 0)) return {};
      if (std::fabs(fa / a - 1) < 1e-13 && std::fabs(fb / b - 1) < 1e-13) {
        for (std::size_t k = 0; k <= m; ++k) s[k] = v.node(k);
        return s;
      }
      d0 *= a / fa;
      d1 *= b / fb;
    }
    return {};
  }
  std::vector<double> cells;
  if (g.ratio != 0) {
    const double x = m > 1 ? std::log(g.ratio) / static_cast<double>(m - 1) : 0.0;
    cells.resize(m);
    for (std::size_t k = 0; k < m; ++k) cells[k] = std::exp(x * static_cast<double>(k));
  } else {
    if (m == 1) return a < 1 || b < 1 ? std::vector<double>{} : std::vector<double>{0.0, 1.0};
    cells = geometric_cells(g.first != 0 ? a : b, m);
    if (g.first == 0) std::reverse(cells.begin(), cells.end());
  }
  double total = 0;
  for (std::size_t k = 0; k < m; ++k) total += cells[k];
  double run = 0;
  for (std::size_t k = 0; k < m; ++k) s[k + 1] = (run += cells[k]) / total;
  s.back() = 1;
  return s;
}

// The largest ratio of neighbouring cells, either way.
double growth_of(std::span<const double> s) {
  double g = 1;
  for (std::size_t k = 2; k < s.size(); ++k) {
    const double h0 = s[k - 1] - s[k - 2], h1 = s[k] - s[k - 1];
    g = std::max(g, std::max(h1 / h0, h0 / h1));
  }
  return g;
}

namespace {

bool fits(const Grading& g, double a, double b, std::size_t m) {
  const std::vector<double> s = sigma_nodes(g, a, b, m);
  return !s.empty() && growth_of(s) <= g.max_growth * (1 + 1e-12);
}

}  // namespace

// The count nearest `count` whose distribution fits within max_growth, or 0.
std::size_t count_that_fits(const Grading& g, double a, double b, std::size_t count) {
  constexpr std::size_t limit = count_limit;
  std::size_t hi = count;
  while (hi < limit && !fits(g, a, b, hi - 1)) hi = std::min(limit, 2 * hi);
  if (fits(g, a, b, hi - 1)) {
    std::size_t lo = count;  // does not fit
    while (hi - lo > 1) {
      const std::size_t mid = lo + (hi - lo) / 2;
      (fits(g, a, b, mid - 1) ? hi : lo) = mid;
    }
    return hi;
  }
  // Cells that must shrink (a first cell longer than an even one) fit fewer nodes:
  // the most below `count` that fit.
  if (count <= 2 || !fits(g, a, b, 1)) return 0;
  std::size_t lo = 2, up = count;  // lo fits, up does not
  while (up - lo > 1) {
    const std::size_t mid = lo + (up - lo) / 2;
    (fits(g, a, b, mid - 1) ? lo : up) = mid;
  }
  return lo;
}

}  // namespace interpatch::mesh
