// Parameters and knots of the least-squares fit (approx_knots.hpp).

#include "constructions/approximate/approx_knots.hpp"

#include <algorithm>
#include <cmath>

namespace interpatch::detail::approx {

std::vector<double> uniform_parameters(std::size_t n, bool closed) {
  const std::size_t steps = closed ? n : n - 1;
  std::vector<double> t(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / static_cast<double>(steps);
  if (!closed) t.back() = 1.0;
  return t;
}

std::vector<double> parameters_from_sums(std::vector<double> sum, const std::vector<std::size_t>& used, std::size_t n,
                                         std::size_t a, Parametrization param, bool closed) {
  const std::size_t steps = sum.size();
  double known = 0;
  std::size_t known_count = 0;
  for (std::size_t k = 0; k < steps; ++k)
    if (used[k] > 0) {
      sum[k] /= static_cast<double>(used[k]);
      known += sum[k];
      ++known_count;
    }
  if (known_count == 0) return uniform_parameters(n, closed);
  for (std::size_t k = 0; k < steps; ++k) {
    if (used[k] == 0) sum[k] = known / static_cast<double>(known_count);
    // Means below 1e-14 of the total are rounding noise: the points coincide in every line.
    if (!(sum[k] > 1e-14 * known))
      fail(errc::zero_chord, "along ", axis_name(a), ": points ", k, " and ", (k + 1) % n,
           " coincide in every line (mean chord ", sum[k], "): parameters must increase");
    if (param == Parametrization::centripetal) sum[k] = std::sqrt(sum[k]);
  }
  double total = 0;
  for (std::size_t k = 0; k < steps; ++k) total += sum[k];
  std::vector<double> t(n, 0.0);
  for (std::size_t k = 1; k < n; ++k) t[k] = t[k - 1] + sum[k - 1];
  for (std::size_t k = 1; k < n; ++k) t[k] /= total;
  if (!closed) t.back() = 1.0;
  return t;
}

KnotVector clamped_knots(const Axis& ax, const std::vector<double>& interior) {
  std::vector<double> u(static_cast<std::size_t>(ax.p) + 1, ax.t.front());
  u.insert(u.end(), interior.begin(), interior.end());
  u.insert(u.end(), static_cast<std::size_t>(ax.p) + 1, ax.t.back());
  return KnotVector(ax.p, std::move(u));
}

std::vector<double> least_squares_breaks(const Axis& ax, int c) {
  const auto& t = ax.t;
  const auto n = static_cast<double>(ax.n);
  std::vector<double> k;
  if (ax.periodic) {
    auto at = [&](double x) {  // the data parameters extended periodically, linear between
      const double f = std::floor(x);
      const auto i = static_cast<long long>(f);
      auto tt = [&](long long j) {
        const auto m = static_cast<long long>(ax.n);
        const long long q = (j % m + m) % m;
        return t[static_cast<std::size_t>(q)] + static_cast<double>((j - q) / m);
      };
      return tt(i) + (x - f) * (tt(i + 1) - tt(i));
    };
    const double shift = ax.p % 2 == 0 ? 0.5 : 0.0;
    for (int j = 0; j < c; ++j) k.push_back(at(j * n / c + shift));
    return k;
  }
  std::vector<double> s(static_cast<std::size_t>(c));
  for (int j = 0; j < c; ++j) {
    // j (n − 1) / (c − 1) is exact at c = n: the data parameters themselves.
    const double x = static_cast<double>(j) * (n - 1) / static_cast<double>(c - 1);
    const auto i = std::min(static_cast<std::size_t>(std::floor(x)), ax.n - 1);
    const double alpha = x - static_cast<double>(i);
    s[static_cast<std::size_t>(j)] = alpha > 0 ? (1 - alpha) * t[i] + alpha * t[i + 1] : t[i];
  }
  const KnotVector avg = averaged_knots(s, ax.p);
  const auto& u = avg.values();
  return {u.begin() + ax.p + 1, u.end() - ax.p - 1};
}

KnotVector knots_from_breaks(const Axis& ax, const std::vector<double>& breaks) {
  if (ax.periodic) return KnotVector::periodic_from(ax.p, breaks, breaks.front() + 1.0);
  return clamped_knots(ax, breaks);
}

bool whitney(const Axis& ax, const std::vector<double>& breaks, const std::vector<bool>& has_data) {
  std::vector<double> u(static_cast<std::size_t>(ax.p) + 1, ax.t.front());
  u.insert(u.end(), breaks.begin(), breaks.end());
  u.insert(u.end(), static_cast<std::size_t>(ax.p) + 1, ax.t.back());
  const std::size_t c = breaks.size() + static_cast<std::size_t>(ax.p) + 1, p1 = static_cast<std::size_t>(ax.p) + 1;
  std::size_t i = 0;
  for (std::size_t j = 0; j < c; ++j) {
    const double lo = u[j], hi = u[j + p1];
    while (i < ax.n && (!has_data[i] || ax.t[i] < lo || (ax.t[i] == lo && j > 0))) ++i;
    if (i == ax.n || !(ax.t[i] < hi || (j + 1 == c && ax.t[i] == hi))) return false;
    ++i;
  }
  return true;
}

bool split_interval(const Axis& ax, std::vector<double>& breaks, int k, const std::vector<bool>& has_data) {
  if (static_cast<std::size_t>(ax.c) >= ax.n) return false;
  std::vector<std::size_t> in;  // the lines across the axis in the interval that hold data
  for (std::size_t i = 0; i < ax.n; ++i)
    if (ax.interval[i] == k && has_data[i]) in.push_back(i);
  if (in.size() < 2) return false;
  // In a closed direction, the order along the interval is that of the parameters
  // wrapped into the period: the interval across the seam holds the last lines and
  // then the first.
  auto at = [&](std::size_t i) { return ax.periodic ? ax.knots.wrap(ax.t[i]) : ax.t[i]; };
  if (ax.periodic) std::stable_sort(in.begin(), in.end(), [&](std::size_t x, std::size_t y) { return at(x) < at(y); });
  const std::size_t mid = in.size() / 2;
  const double knot = 0.5 * (at(in[mid - 1]) + at(in[mid]));
  if (!ax.periodic) {
    std::vector<double> next = breaks;  // this round's earlier knots at its end
    next.push_back(knot);
    std::sort(next.begin(), next.end());
    if (!whitney(ax, next, has_data)) return false;
  }
  breaks.push_back(knot);
  return true;
}

}  // namespace interpatch::detail::approx
