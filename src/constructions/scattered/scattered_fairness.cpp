// The thin-plate fairness term of a scattered fit's normal equations: second divided
// differences of the control net over its Greville abscissae, as a matrix, its diagonal,
// or the energy of given values.

#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "base/parallel.hpp"
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

// The thin-plate energy's terms: second divided differences over the Greville abscissae
// along u and along v, and the twist, each weighted by the area it stands for.
struct Stencil {
  std::vector<double> gu, gv, wu, wv;
  explicit Stencil(const Net& net) : gu(net.ku.greville()), gv(net.kv.greville()), wu(greville_widths(gu)), wv(greville_widths(gv)) {}
  // Second divided difference over three abscissae around g[i] into c, and the length
  // it stands for.
  static double second(const std::vector<double>& g, int i, double c[3]) {
    const double h0 = g[static_cast<std::size_t>(i)] - g[static_cast<std::size_t>(i - 1)];
    const double h1 = g[static_cast<std::size_t>(i + 1)] - g[static_cast<std::size_t>(i)];
    const double f = 2 / (h0 + h1);
    c[0] = f / h0, c[1] = -f / h0 - f / h1, c[2] = f / h1;
    return (g[static_cast<std::size_t>(i + 1)] - g[static_cast<std::size_t>(i - 1)]) / 2;
  }
  // The twist of cell (i, j): its coefficient f (the signs f, -f, -f, f), its weight.
  [[nodiscard]] std::array<double, 2> twist(int i, int j) const {
    const double hu = gu[static_cast<std::size_t>(i + 1)] - gu[static_cast<std::size_t>(i)];
    const double hv = gv[static_cast<std::size_t>(j + 1)] - gv[static_cast<std::size_t>(j)];
    return {1 / (hu * hv), 2 * hu * hv};
  }
};

// add(control points, coefficients, weight) for each term, in order: along u, along v,
// the twists.
template <class Add>
void fairness_terms(const Net& net, Add&& add) {
  const Stencil st(net);
  for (int i = 1; i + 1 < net.nu; ++i) {
    double c[3];
    const double len = Stencil::second(st.gu, i, c);
    for (int j = 0; j < net.nv; ++j) {
      const std::array<int, 2> at[3] = {{i - 1, j}, {i, j}, {i + 1, j}};
      add(std::span<const std::array<int, 2>>(at), std::span<const double>(c), len * st.wv[static_cast<std::size_t>(j)]);
    }
  }
  for (int j = 1; j + 1 < net.nv; ++j) {
    double c[3];
    const double len = Stencil::second(st.gv, j, c);
    for (int i = 0; i < net.nu; ++i) {
      const std::array<int, 2> at[3] = {{i, j - 1}, {i, j}, {i, j + 1}};
      add(std::span<const std::array<int, 2>>(at), std::span<const double>(c), len * st.wu[static_cast<std::size_t>(i)]);
    }
  }
  for (int i = 0; i + 1 < net.nu; ++i)
    for (int j = 0; j + 1 < net.nv; ++j) {
      const auto [f, weight] = st.twist(i, j);
      const std::array<int, 2> at[4] = {{i, j}, {i, j + 1}, {i + 1, j}, {i + 1, j + 1}};
      const double c[4] = {f, -f, -f, f};
      add(std::span<const std::array<int, 2>>(at), std::span<const double>(c), weight);
    }
}

// s times the terms added to the matrix (each term's s·w c cᵀ, its upper half), each
// entry's sum in the order of fairness_terms whatever the threads. The threads take
// rows or columns of their own: along u, each column's terms write only that column;
// along v, each row's only that row; a twist writes its row and the next, so each row
// takes the twists of the row above it first, then its own.
void add_terms(const Net& net, NetMatrix& a, double s) {
  a.make_writable();  // at() below, on the threads, then never changes the form
  const Stencil st(net);
  const int nu = net.nu, nv = net.nv;
  const auto row = [nv](int i, int j) { return static_cast<std::size_t>(i) * static_cast<std::size_t>(nv) + static_cast<std::size_t>(j); };
  const bool parallel = a.rows() * 40 >= parallel_min_work;
  constexpr int block = 64;  // columns a task along u
#pragma omp parallel for schedule(static) if (parallel)
  for (int j0 = 0; j0 < nv; j0 += block)
    for (int i = 1; i + 1 < nu; ++i) {
      double c[3];
      const double len = Stencil::second(st.gu, i, c);
      for (int j = j0; j < std::min(nv, j0 + block); ++j) {
        const double w = s * (len * st.wv[static_cast<std::size_t>(j)]);
        a.at(row(i - 1, j), 0) += w * c[0] * c[0];
        a.at(row(i - 1, j), a.offset(1, 0)) += w * c[0] * c[1];
        a.at(row(i - 1, j), a.offset(2, 0)) += w * c[0] * c[2];
        a.at(row(i, j), 0) += w * c[1] * c[1];
        a.at(row(i, j), a.offset(1, 0)) += w * c[1] * c[2];
        a.at(row(i + 1, j), 0) += w * c[2] * c[2];
      }
    }
#pragma omp parallel for schedule(static) if (parallel)
  for (int i = 0; i < nu; ++i)
    for (int j = 1; j + 1 < nv; ++j) {
      double c[3];
      const double len = Stencil::second(st.gv, j, c);
      const double w = s * (len * st.wu[static_cast<std::size_t>(i)]);
      a.at(row(i, j - 1), 0) += w * c[0] * c[0];
      a.at(row(i, j - 1), 1) += w * c[0] * c[1];
      a.at(row(i, j - 1), 2) += w * c[0] * c[2];
      a.at(row(i, j), 0) += w * c[1] * c[1];
      a.at(row(i, j), 1) += w * c[1] * c[2];
      a.at(row(i, j + 1), 0) += w * c[2] * c[2];
    }
#pragma omp parallel for schedule(static) if (parallel)
  for (int i = 0; i < nu; ++i) {
    if (i > 0)  // the twists of cells (i - 1, j): their lower two control points
      for (int j = 0; j + 1 < nv; ++j) {
        const auto [f, weight] = st.twist(i - 1, j);
        const double w = s * weight, c[4] = {f, -f, -f, f};
        a.at(row(i, j), 0) += w * c[2] * c[2];
        a.at(row(i, j), 1) += w * c[2] * c[3];
        a.at(row(i, j + 1), 0) += w * c[3] * c[3];
      }
    if (i + 1 < nu)  // the twists of cells (i, j): their upper two
      for (int j = 0; j + 1 < nv; ++j) {
        const auto [f, weight] = st.twist(i, j);
        const double w = s * weight, c[4] = {f, -f, -f, f};
        a.at(row(i, j), 0) += w * c[0] * c[0];
        a.at(row(i, j), 1) += w * c[0] * c[1];
        a.at(row(i, j), a.offset(1, 0)) += w * c[0] * c[2];
        a.at(row(i, j), a.offset(1, 1)) += w * c[0] * c[3];
        a.at(row(i, j + 1), 0) += w * c[1] * c[1];
        a.at(row(i, j + 1), a.offset(1, -1)) += w * c[1] * c[2];
        a.at(row(i, j + 1), a.offset(1, 0)) += w * c[1] * c[3];
      }
  }
}

}  // namespace

void add_fairness(const Net& net, NetMatrix* a, double s, std::vector<double>* diagonal) {
  if (a) add_terms(net, *a, s);
  if (!diagonal) return;
  const std::size_t nv = static_cast<std::size_t>(net.nv);
  fairness_terms(net, [&](std::span<const std::array<int, 2>> at, std::span<const double> coef, double weight) {
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
