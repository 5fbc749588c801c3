#pragma once
// The least-squares fit's model of the data and its directions, shared by the fit in
// one process (approximate.cpp) and the fit split between processes by rows
// (approximate_rows.cpp): the data and their weights, each direction's parameters,
// knots and basis values, its Gram and fairness bands, and the state of a fit.

#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "base/text.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/knot_vector.hpp"
#include "linalg/banded.hpp"

namespace interpatch::detail::approx {

// ------------------------------------------------------------------ data
//
// Every array of points or control points is a C-order array of doubles whose last
// axis holds the 3 coordinates; shapes count points, not doubles.

template <std::size_t R>
using Shape = std::array<std::size_t, R>;

template <std::size_t R>
std::size_t count_of(const Shape<R>& s) {
  std::size_t n = 1;
  for (auto e : s) n *= e;
  return n;
}

constexpr const char* axis_name(std::size_t a) { return a == 0 ? "u" : (a == 1 ? "v" : "w"); }

inline bool is_missing(const Vec3& q) { return std::isnan(q.x) || std::isnan(q.y) || std::isnan(q.z); }

template <std::size_t R>
std::string index_text(std::size_t flat, const Shape<R>& s) {
  std::string at;
  for (std::size_t a = R; a-- > 0; flat /= s[a]) at = detail::cat("[", flat % s[a], "]", at);
  return at;
}

template <std::size_t R>
std::vector<std::size_t> unflatten(std::size_t flat, const Shape<R>& s) {
  std::vector<std::size_t> idx(R);
  for (std::size_t a = R; a-- > 0; flat /= s[a]) idx[a] = flat % s[a];
  return idx;
}

// The data as the fit sees it: points, each point's weight (0 where missing).
template <std::size_t R>
struct Data {
  Shape<R> shape{};
  Grid<Vec3, R> points;
  std::vector<double> weight;  // empty: every point present with weight 1
  std::size_t missing = 0;
  std::size_t present = 0;  // points with a positive weight
  double weight_sum = 0;
  [[nodiscard]] bool uniform() const { return weight.empty(); }
  [[nodiscard]] double w(std::size_t i) const { return weight.empty() ? 1.0 : weight[i]; }
};

// ------------------------------------------------------------------ one direction

// A band of a symmetric matrix along one direction: entry (i, i + d) for |d| <= h,
// the column taken modulo c in a closed direction.
struct Band {
  int c = 0, h = 0;
  std::vector<double> v;  // c × (2h + 1)
  Band() = default;
  Band(int count, int half) : c(count), h(half), v(static_cast<std::size_t>(count) * static_cast<std::size_t>(2 * half + 1), 0.0) {}
  double& at(int i, int d) { return v[static_cast<std::size_t>(i) * static_cast<std::size_t>(2 * h + 1) + static_cast<std::size_t>(d + h)]; }
  [[nodiscard]] double at(int i, int d) const {
    return v[static_cast<std::size_t>(i) * static_cast<std::size_t>(2 * h + 1) + static_cast<std::size_t>(d + h)];
  }
};

struct Axis {
  std::size_t n = 0;  // data points along it
  int p = 1;
  bool periodic = false;
  std::vector<double> t;  // data parameters
  KnotVector knots = KnotVector::bezier(1);
  int c = 0;                 // control points
  std::vector<int> first;    // per data point: its first basis function (unwrapped)
  std::vector<double> b;     // per data point: p + 1 basis values
  std::vector<int> interval; // per data point: the knot interval it lies in
  int intervals = 0;

  [[nodiscard]] std::size_t col(int i) const { return static_cast<std::size_t>(i >= c ? i - c : i); }

  // The knots, the control point count, and each data point's basis values and knot
  // interval.
  void set_knots(KnotVector k);

  // The Gram matrix Σ_i B(t_i) B(t_i)ᵀ of the basis at the data parameters.
  [[nodiscard]] Band gram(int h) const;

  // Σ ω_i d_i d_iᵀ: d_i the second divided difference of the control polygon at
  // Greville abscissa i, ω_i half the distance of its neighbours (∫ f''² in effect).
  [[nodiscard]] Band fairness(int h) const;
};

using AxisSolver = std::variant<detail::BandedLU, detail::CyclicLU>;

// The factored Gram matrix of a direction (the least-squares system along it).
AxisSolver factor_gram(const Axis& ax, std::size_t a);

// A fit in progress: the directions, the control net (C order, 3 doubles a point),
// the fairness weight it was made with and the fits made so far.
template <std::size_t R>
struct Fit {
  std::array<Axis, R> axes;
  std::vector<double> cp;
  double lambda = 0;
  int fits = 0;
};

// A control net's doubles as points.
std::span<const Vec3> net_points(const std::vector<double>& cp);

}  // namespace interpatch::detail::approx
