#include "interpatch/knot_vector.hpp"

#include <algorithm>
#include <cmath>

#include "detail/text.hpp"

namespace interpatch {

using detail::fail;

KnotVector::KnotVector(int degree, std::vector<double> knots) : p_(degree), u_(std::move(knots)) {
  if (p_ < 1 || p_ > max_degree)
    fail(errc::invalid_degree, "degree ", p_, " is outside 1..", max_degree);
  const auto p = static_cast<std::size_t>(p_);
  if (u_.size() < 2 * (p + 1))
    fail(errc::invalid_knots, "degree ", p_, " needs at least ", 2 * (p + 1), " knots, got ", u_.size());
  for (std::size_t i = 0; i < u_.size(); ++i)
    if (!std::isfinite(u_[i])) fail(errc::not_finite, "knot ", i, " is ", u_[i]);
  for (std::size_t i = 1; i < u_.size(); ++i)
    if (u_[i] < u_[i - 1])
      fail(errc::non_increasing, "knot ", i, " = ", u_[i], " is smaller than knot ", i - 1, " = ", u_[i - 1]);
  for (std::size_t i = 1; i <= p; ++i) {
    if (u_[i] != u_[0])
      fail(errc::invalid_knots, "knot vector is not clamped at the start: knot ", i, " = ", u_[i],
           " differs from knot 0 = ", u_[0], " (the first ", p + 1, " knots must be equal)");
    const std::size_t j = u_.size() - 1 - i;
    if (u_[j] != u_.back())
      fail(errc::invalid_knots, "knot vector is not clamped at the end: knot ", j, " = ", u_[j],
           " differs from the last knot ", u_.back(), " (the last ", p + 1, " knots must be equal)");
  }
  if (!(u_.front() < u_.back())) fail(errc::invalid_knots, "knot vector has an empty domain [", u_.front(), ", ", u_.back(), "]");
  // Interior knots are indices p+1 .. n; a run there equal to an end knot means
  // the end is clamped with more than p+1 equal knots.
  const std::size_t lo = p + 1, hi = u_.size() - p - 1;
  for (std::size_t i = lo; i < hi;) {
    std::size_t j = i;
    while (j + 1 < hi && u_[j + 1] == u_[i]) ++j;
    const std::size_t mult = j - i + 1;
    if (u_[i] == u_.front() || u_[i] == u_.back())
      fail(errc::invalid_knots, "end knot ", u_[i], " appears ", mult + p + 1, " times; a clamped degree ", p_,
           " knot vector has it exactly ", p + 1, " times");
    if (mult > p)
      fail(errc::invalid_knots, "interior knot ", u_[i], " at index ", i, " has multiplicity ", mult,
           ", more than degree ", p_, " allows");
    i = j + 1;
  }
}

KnotVector KnotVector::bezier(int degree) {
  if (degree < 1 || degree > max_degree)
    detail::fail(errc::invalid_degree, "degree ", degree, " is outside 1..", max_degree);
  std::vector<double> k(2 * static_cast<std::size_t>(degree) + 2, 0.0);
  std::fill(k.begin() + degree + 1, k.end(), 1.0);
  return KnotVector(degree, std::move(k));
}

KnotVector KnotVector::uniform(int degree, int count, double a, double b) {
  if (degree < 1 || degree > max_degree) fail(errc::invalid_degree, "degree ", degree, " is outside 1..", max_degree);
  if (count <= degree) fail(errc::too_few_points, "degree ", degree, " needs at least ", degree + 1, " control points, got ", count);
  std::vector<double> u(static_cast<std::size_t>(count + degree + 1));
  const int inner = count - degree;  // number of spans
  for (std::size_t i = 0; i < u.size(); ++i) {
    const int k = std::clamp(static_cast<int>(i) - degree, 0, inner);
    u[i] = k == inner ? b : a + (b - a) * k / inner;
  }
  return KnotVector(degree, std::move(u));
}

int KnotVector::find_span(double t) const noexcept {
  const int n = count() - 1;
  if (t >= u_[static_cast<std::size_t>(n + 1)]) return n;
  if (t <= u_[static_cast<std::size_t>(p_)]) return p_;
  // upper_bound over [p, n+1]: first knot > t, the span is the one before it.
  const auto first = u_.begin() + p_;
  const auto last = u_.begin() + n + 2;
  const auto it = std::upper_bound(first, last, t);
  return static_cast<int>(it - u_.begin()) - 1;
}

void KnotVector::basis(int span, double t, double* N) const noexcept {
  double left[max_degree + 1];
  double right[max_degree + 1];
  const auto s = static_cast<std::size_t>(span);
  N[0] = 1.0;
  for (int j = 1; j <= p_; ++j) {
    left[j] = t - u_[s + 1 - static_cast<std::size_t>(j)];
    right[j] = u_[s + static_cast<std::size_t>(j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
}

void KnotVector::basis_derivatives(int span, double t, int nd, double* ders) const noexcept {
  // Triangular table: ndu[j][r] for r >= j holds basis values of degree r, for r < j
  // the knot differences the derivative formula divides by.
  const int p = p_;
  double ndu[max_degree + 1][max_degree + 1];
  double a[2][max_degree + 1];
  double left[max_degree + 1];
  double right[max_degree + 1];
  const auto s = static_cast<std::size_t>(span);
  const int w = p + 1;
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - u_[s + 1 - static_cast<std::size_t>(j)];
    right[j] = u_[s + static_cast<std::size_t>(j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      ndu[j][r] = right[r + 1] + left[j - r];
      const double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; ++j) ders[j] = ndu[j][p];
  const int nk = std::min(nd, p);
  for (int r = 0; r <= p; ++r) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= nk; ++k) {
      double d = 0.0;
      const int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      const int j1 = rk >= -1 ? 1 : -rk;
      const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; ++j) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k * w + r] = d;
      std::swap(s1, s2);
    }
  }
  double f = p;
  for (int k = 1; k <= nk; ++k) {
    for (int j = 0; j <= p; ++j) ders[k * w + j] *= f;
    f *= (p - k);
  }
  for (int k = nk + 1; k <= nd; ++k)
    for (int j = 0; j <= p; ++j) ders[k * w + j] = 0.0;
}

int KnotVector::multiplicity(double t) const noexcept {
  if (std::isnan(t)) return 0;  // equal to no knot, and unordered for the search below
  const auto [lo, hi] = std::equal_range(u_.begin(), u_.end(), t);  // the knots are sorted
  return static_cast<int>(hi - lo);
}

std::vector<std::pair<double, int>> KnotVector::interior_breaks() const {
  std::vector<std::pair<double, int>> out;
  for (std::size_t i = static_cast<std::size_t>(p_) + 1; i < static_cast<std::size_t>(count()); ++i) {
    if (!out.empty() && out.back().first == u_[i]) ++out.back().second;
    else out.emplace_back(u_[i], 1);
  }
  return out;
}

std::vector<double> KnotVector::greville() const {
  std::vector<double> g(static_cast<std::size_t>(count()));
  for (std::size_t i = 0; i < g.size(); ++i) {
    double s = 0;
    for (int k = 1; k <= p_; ++k) s += u_[i + static_cast<std::size_t>(k)];
    g[i] = s / p_;
  }
  return g;
}

KnotVector KnotVector::mapped(double a, double b) const {
  const double u0 = u_.front(), u1 = u_.back();
  std::vector<double> v(u_.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = a + (u_[i] - u0) * ((b - a) / (u1 - u0));
  v.front() = a;  // exact ends, whatever the rounding inside
  v.back() = b;
  for (int i = 1; i <= p_; ++i) {
    v[static_cast<std::size_t>(i)] = a;
    v[v.size() - 1 - static_cast<std::size_t>(i)] = b;
  }
  return KnotVector(p_, std::move(v));
}

int KnotVector::continuity() const noexcept {
  int maxm = 0;
  for (const auto& [t, m] : interior_breaks()) maxm = std::max(maxm, m);
  return p_ - maxm;
}

KnotVector merged_knots(std::span<const KnotVector> knots) {
  if (knots.empty()) detail::fail(errc::too_few_points, "no knot vectors to merge");
  int p = 0;
  for (const KnotVector& k : knots) p = std::max(p, k.degree());
  // Each vector's breaks merged in one pass (both lists are sorted); vectors met
  // before add nothing.
  std::vector<std::pair<double, int>> merged, next;
  for (std::size_t k = 0; k < knots.size(); ++k) {
    const KnotVector& kv = knots[k];
    if (std::any_of(knots.begin(), knots.begin() + static_cast<std::ptrdiff_t>(k),
                    [&](const KnotVector& o) { return o.degree() == kv.degree() && o.values() == kv.values(); }))
      continue;
    const int raise = p - kv.degree();
    auto breaks = kv.interior_breaks();
    for (auto& b : breaks) b.second += raise;
    next.clear();
    std::size_t i = 0, j = 0;
    while (i < merged.size() || j < breaks.size()) {
      if (j == breaks.size() || (i < merged.size() && merged[i].first < breaks[j].first)) {
        next.push_back(merged[i++]);
      } else if (i == merged.size() || breaks[j].first < merged[i].first) {
        next.push_back(breaks[j++]);
      } else {
        next.emplace_back(breaks[j].first, std::max(merged[i].second, breaks[j].second));
        ++i;
        ++j;
      }
    }
    merged.swap(next);
  }
  std::vector<double> u(static_cast<std::size_t>(p) + 1, knots.front().front());
  for (const auto& [x, m] : merged) u.insert(u.end(), static_cast<std::size_t>(m), x);
  u.insert(u.end(), static_cast<std::size_t>(p) + 1, knots.front().back());
  return KnotVector(p, std::move(u));
}

}  // namespace interpatch
