#include "interpatch/knot_vector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/text.hpp"

namespace interpatch {

using detail::fail;

namespace {

// Basis functions divide by knot spans: a span below the smallest normal double
// (2.2e-308) has a reciprocal beyond the largest, and evaluation gives NaN.
void require_normal_span(const std::vector<double>& u, std::size_t i) {
  const double span = u[i] - u[i - 1];
  if (span > 0 && span < std::numeric_limits<double>::min())
    fail(errc::invalid_knots, "knot ", i, " = ", u[i], " is only ", span, " above knot ", i - 1, " = ", u[i - 1],
         ": a knot span below ", std::numeric_limits<double>::min(),
         " (the smallest normal double) cannot be evaluated; repeat the knot or move it apart");
}

}  // namespace

KnotVector::KnotVector(int degree, std::vector<double> knots, int count, bool periodic)
    : p_(degree), u_(std::move(knots)), count_(count), end_(periodic ? count + degree : count), periodic_(periodic) {}

KnotVector::KnotVector(int degree, std::vector<double> knots) : p_(degree), u_(std::move(knots)) {
  count_ = static_cast<int>(u_.size()) - p_ - 1;
  end_ = count_;
  if (p_ < 1 || p_ > max_degree)
    fail(errc::invalid_degree, "degree ", p_, " is outside 1..", max_degree);
  const auto p = static_cast<std::size_t>(p_);
  if (u_.size() < 2 * (p + 1))
    fail(errc::invalid_knots, "degree ", p_, " needs at least ", 2 * (p + 1), " knots, got ", u_.size());
  for (std::size_t i = 0; i < u_.size(); ++i)
    if (!std::isfinite(u_[i])) fail(errc::not_finite, "knot ", i, " is ", u_[i]);
  for (std::size_t i = 1; i < u_.size(); ++i) {
    if (u_[i] < u_[i - 1])
      fail(errc::non_increasing, "knot ", i, " = ", u_[i], " is smaller than knot ", i - 1, " = ", u_[i - 1]);
    require_normal_span(u_, i);
  }
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

KnotVector KnotVector::periodic_from(int degree, std::vector<double> knots, double end) {
  if (degree < 1 || degree > max_degree) fail(errc::invalid_degree, "degree ", degree, " is outside 1..", max_degree);
  const std::size_t n = knots.size(), p = static_cast<std::size_t>(degree);
  // Fewer control points than p + 1 would make one span use a control point twice.
  if (n < p + 1)
    fail(errc::too_few_points, "a periodic knot vector of degree ", degree, " needs at least ", p + 1,
         " knots in its period, got ", n);
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(knots[i])) fail(errc::not_finite, "knot ", i, " is ", knots[i]);
  if (!std::isfinite(end)) fail(errc::not_finite, "the end of the period is ", end);
  for (std::size_t i = 1; i < n; ++i) {
    if (knots[i] < knots[i - 1])
      fail(errc::non_increasing, "knot ", i, " = ", knots[i], " is smaller than knot ", i - 1, " = ", knots[i - 1]);
    require_normal_span(knots, i);
  }
  const double a = knots.front();
  if (!(end > a)) fail(errc::invalid_knots, "the period [", a, ", ", end, ") is empty");
  if (!(knots.back() < end))
    fail(errc::invalid_knots, "knot ", n - 1, " = ", knots.back(), " is not inside the period [", a, ", ", end, ")");
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && knots[j + 1] == knots[i]) ++j;
    if (j - i + 1 > p)
      fail(errc::invalid_knots, "knot ", knots[i], " at index ", i, " has multiplicity ", j - i + 1, ", more than degree ",
           degree, " allows");
    i = j + 1;
  }
  // Extended knots: p images of the period's last knots before it, the period, its
  // end, and p images of its first knots after it.
  const double T = end - a;
  std::vector<double> u(n + 2 * p + 1);
  for (std::size_t i = 0; i < p; ++i) u[i] = knots[n - p + i] - T;
  std::copy(knots.begin(), knots.end(), u.begin() + static_cast<std::ptrdiff_t>(p));
  u[n + p] = end;
  for (std::size_t i = 1; i <= p; ++i) u[n + p + i] = knots[i] + T;
  return KnotVector(degree, std::move(u), static_cast<int>(n), true);
}

KnotVector KnotVector::periodic_from_extended(int degree, const std::vector<double>& knots) {
  if (degree < 1 || degree > max_degree) fail(errc::invalid_degree, "degree ", degree, " is outside 1..", max_degree);
  const auto p = static_cast<std::size_t>(degree);
  if (knots.size() < 3 * p + 2)
    fail(errc::invalid_knots, "a periodic knot vector of degree ", degree, " needs at least ", 3 * p + 2,
         " extended knots (degree + 1 control points), got ", knots.size());
  const std::size_t n = knots.size() - 2 * p - 1;
  KnotVector k = periodic_from(degree, std::vector<double>(knots.begin() + static_cast<std::ptrdiff_t>(p),
                                                           knots.begin() + static_cast<std::ptrdiff_t>(p + n)),
                               knots[p + n]);
  // Other programs compute the images by their own additions: 1e-12 of the period
  // covers their rounding and nothing more.
  const double tol = 1e-12 * (k.back() - k.front());
  for (std::size_t i = 0; i < knots.size(); ++i)
    if (!(std::abs(knots[i] - k.u_[i]) <= tol))
      fail(errc::invalid_knots, "knot ", i, " = ", knots[i], " does not repeat the period: a periodic knot vector has ",
           k.u_[i], " there (the period ", k.back() - k.front(), " on from knot ", i < p ? i + n : i - n, ")");
  return k;
}

double KnotVector::wrap(double t) const noexcept {
  const double a = front(), b = back();
  if (!periodic_ || (t >= a && t <= b) || !std::isfinite(t)) return t;
  const double T = b - a;
  double r = a + (t - a - T * std::floor((t - a) / T));
  if (r >= b) r = a;  // rounding of the last step
  if (r < a) r = a;
  return r;
}

std::vector<double> KnotVector::period_knots() const {
  if (!periodic_) return {};
  return {u_.begin() + p_, u_.begin() + p_ + count_};
}

KnotVector KnotVector::clamped() const {
  if (!periodic_) return *this;
  std::vector<double> u(static_cast<std::size_t>(p_) + 1, front());
  for (int i = p_; i < p_ + count_; ++i)
    if (u_[static_cast<std::size_t>(i)] != front()) u.push_back(u_[static_cast<std::size_t>(i)]);
  u.insert(u.end(), static_cast<std::size_t>(p_) + 1, back());
  return KnotVector(p_, std::move(u));
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
  const int n = end_ - 1;
  if (t >= u_[static_cast<std::size_t>(n + 1)]) return n;
  // A clamped vector's first span is p; a periodic one's domain may start at a knot
  // of any multiplicity, so t there is searched for like any other.
  if (t < u_[static_cast<std::size_t>(p_)] || (!periodic_ && t == u_[static_cast<std::size_t>(p_)])) return p_;
  // The last knot <= t in [p, n]: first guessed from t's place in the domain, right at
  // once on evenly spaced knots and within a few on most others (a tenth of the time of
  // the search on a 512-span vector, which checking a fit at 10^6 points feels), then
  // searched for when the guess is farther off.
  const double a = u_[static_cast<std::size_t>(p_)], b = u_[static_cast<std::size_t>(n + 1)];
  const double guess = (t - a) / (b - a) * (n + 1 - p_);  // in [0, n + 1 - p] here, or NaN
  int s = guess >= 0 ? std::min(p_ + static_cast<int>(std::min(guess, static_cast<double>(n - p_))), n) : p_;
  for (int step = 0; step < 4 && guess >= 0; ++step) {
    if (u_[static_cast<std::size_t>(s)] > t) --s;
    else if (u_[static_cast<std::size_t>(s + 1)] <= t) ++s;
    else return s;
  }
  // upper_bound over [p, n+1]: first knot > t, the span is the one before it.
  const auto first = u_.begin() + p_;
  const auto last = u_.begin() + n + 2;
  const auto it = std::upper_bound(first, last, t);
  return static_cast<int>(it - u_.begin()) - 1;
}

namespace {

// The Cox–de Boor triangle for degree P (0: the degree p given at run time), with
// the loops unrolled when P is known: the same operations in the same order.
template <int P>
[[gnu::always_inline]] inline void basis_of(const double* u, int p, std::size_t s, double t, double* N) {
  const int deg = P != 0 ? P : p;
  double left[max_degree + 1];
  double right[max_degree + 1];
  N[0] = 1.0;
  for (int j = 1; j <= deg; ++j) {
    left[j] = t - u[s + 1 - static_cast<std::size_t>(j)];
    right[j] = u[s + static_cast<std::size_t>(j)] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double temp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    N[j] = saved;
  }
}

}  // namespace

void KnotVector::basis(int span, double t, double* N) const noexcept {
  const auto s = static_cast<std::size_t>(span);
  switch (p_) {
    case 3: return basis_of<3>(u_.data(), p_, s, t, N);
    case 2: return basis_of<2>(u_.data(), p_, s, t, N);
    case 1: return basis_of<1>(u_.data(), p_, s, t, N);
    default: return basis_of<0>(u_.data(), p_, s, t, N);
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
  const std::size_t first = periodic_ ? static_cast<std::size_t>(p_) : static_cast<std::size_t>(p_) + 1;
  for (std::size_t i = first; i < static_cast<std::size_t>(end_); ++i) {
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
  if (periodic_) {
    const double u0 = front(), u1 = back();
    std::vector<double> k = period_knots();
    for (double& x : k) x = a + (x - u0) * ((b - a) / (u1 - u0));
    k.front() = a;
    for (std::size_t i = 1; i < k.size() && u_[static_cast<std::size_t>(p_) + i] == u0; ++i) k[i] = a;
    return periodic_from(p_, std::move(k), b);
  }
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

std::vector<KnotVector> snapped_together(std::span<const KnotVector> knots) {
  std::vector<KnotVector> out(knots.begin(), knots.end());
  if (knots.empty()) return out;
  const double a = knots.front().front(), b = knots.front().back();
  const double room = 256 * std::numeric_limits<double>::epsilon() * std::max({std::abs(a), std::abs(b), b - a});
  const bool periodic = knots.front().periodic();
  // Where a knot goes: the smallest knot of its cluster (knots each within `room` of
  // the next). Knots keep their order, so control points keep their places.
  std::vector<double> all;
  for (const KnotVector& k : knots)
    for (const auto& [x, m] : k.interior_breaks()) all.push_back(x);
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  std::vector<double> to(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) to[i] = i > 0 && all[i] - all[i - 1] <= room ? to[i - 1] : all[i];
  const auto target = [&](double x) {
    return to[static_cast<std::size_t>(std::lower_bound(all.begin(), all.end(), x) - all.begin())];
  };
  for (KnotVector& k : out) {
    const auto breaks = k.interior_breaks();
    if (std::all_of(breaks.begin(), breaks.end(), [&](const auto& br) { return target(br.first) == br.first; })) continue;
    std::vector<double> moved;
    if (periodic) {
      for (double x : k.period_knots()) moved.push_back(target(x));
    } else {
      moved = k.values();
      for (std::size_t i = static_cast<std::size_t>(k.degree()) + 1; i + static_cast<std::size_t>(k.degree()) + 1 < moved.size(); ++i)
        moved[i] = target(moved[i]);
    }
    // A knot more often than the degree allows: this vector keeps its own knots.
    bool fits = true;
    for (std::size_t i = 0, j = 0; i < moved.size(); i = j) {
      while (j < moved.size() && moved[j] == moved[i]) ++j;
      const bool end = !periodic && (moved[i] == a || moved[i] == b);
      if (!end && static_cast<int>(j - i) > k.degree()) fits = false;
    }
    if (!fits) continue;
    k = periodic ? KnotVector::periodic_from(k.degree(), std::move(moved), b) : KnotVector(k.degree(), std::move(moved));
  }
  return out;
}

KnotVector merged_knots(std::span<const KnotVector> knots) {
  if (knots.empty()) detail::fail(errc::too_few_points, "no knot vectors to merge");
  int p = 0;
  for (const KnotVector& k : knots) p = std::max(p, k.degree());
  const bool periodic = knots.front().periodic();
  for (std::size_t k = 1; k < knots.size(); ++k)
    if (knots[k].periodic() != periodic)
      detail::fail(errc::invalid_knots, "knot vector ", k, " is ", knots[k].periodic() ? "periodic" : "clamped",
                   " and knot vector 0 is not: closed and open splines do not merge");
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
  if (periodic) {
    std::vector<double> u;
    // The seam: a break only where some vector has a knot there; the merged period
    // starts with it either way.
    if (merged.empty() || merged.front().first != knots.front().front()) u.push_back(knots.front().front());
    for (const auto& [x, m] : merged) u.insert(u.end(), static_cast<std::size_t>(m), x);
    return KnotVector::periodic_from(p, std::move(u), knots.front().back());
  }
  std::vector<double> u(static_cast<std::size_t>(p) + 1, knots.front().front());
  for (const auto& [x, m] : merged) u.insert(u.end(), static_cast<std::size_t>(m), x);
  u.insert(u.end(), static_cast<std::size_t>(p) + 1, knots.front().back());
  return KnotVector(p, std::move(u));
}

}  // namespace interpatch
