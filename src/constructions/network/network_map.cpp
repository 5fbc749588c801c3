// The monotone maps from the surface's parameter to a curve's own: cubic Hermite
// pieces through the crossings, their inverse, and their evaluation.
#include <algorithm>
#include <cmath>

#include "base/text.hpp"
#include "constructions/network/network_curves.hpp"
#include "linalg/banded.hpp"

namespace interpatch::detail {

namespace {

// The value and slope on [x0, x0 + h] of the cubic Hermite piece through y0, y1 with
// slopes m0, m1, at x0 + τh.
double hermite(double y0, double y1, double m0, double m1, double h, double tau) {
  const double t2 = tau * tau, t3 = t2 * tau;
  return (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + tau) * h * m0 + (-2 * t3 + 3 * t2) * y1 + (t3 - t2) * h * m1;
}

// Whether the Hermite piece with secant slope d and end slopes m0, m1 has a slope of
// d's sign everywhere: q(τ) = 6τ(1 − τ)d + m0(1 − 4τ + 3τ²) + m1(3τ² − 2τ), a quadratic.
bool strictly_monotone(double d, double m0, double m1) {
  const double sg = d > 0 ? 1.0 : -1.0;
  const auto q = [&](double t) { return sg * (6 * t * (1 - t) * d + m0 * (1 - 4 * t + 3 * t * t) + m1 * (3 * t * t - 2 * t)); };
  if (!(q(0) > 0) || !(q(1) > 0)) return false;
  // q(τ) = Aτ² + Bτ + C with A = −6d + 3m0 + 3m1, B = 6d − 4m0 − 2m1.
  const double A = -6 * d + 3 * m0 + 3 * m1, B = 6 * d - 4 * m0 - 2 * m1;
  if (A != 0) {
    const double v = -B / (2 * A);
    if (v > 0 && v < 1 && !(q(v) > 0)) return false;
  }
  return true;
}

}  // namespace

Reparametrization monotone_map(std::vector<double> at, std::vector<double> to, bool closed) {
  const std::size_t n = at.size();
  INTERPATCH_ASSERT(n >= 2 && to.size() == n);
  std::vector<double> h(n - 1), d(n - 1), m(n);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    h[i] = at[i + 1] - at[i];
    d[i] = (to[i + 1] - to[i]) / h[i];
  }
  const auto monotone = [&] {
    for (std::size_t i = 0; i + 1 < n; ++i)
      if (!strictly_monotone(d[i], m[i], m[i + 1])) return false;
    return true;
  };
  if (n == 2) {
    m[0] = m[1] = d[0];
  } else {
    // The C2 spline's slopes: h_i m_(i−1) + 2(h_(i−1) + h_i) m_i + h_(i−1) m_(i+1) =
    // 3(h_i d_(i−1) + h_(i−1) d_i) at every inner node; natural ends (2 m_0 + m_1 = 3 d_0),
    // or closed: node 0 is node n − 1, its neighbours wrapping.
    const auto rows_of = [&](std::vector<std::vector<CyclicLU::Entry>>& rows, std::vector<double>& rhs) {
      const std::size_t k = closed ? n - 1 : n;  // unknowns
      rows.assign(k, {});
      rhs.assign(k, 0.0);
      for (std::size_t i = 0; i < k; ++i) {
        const bool inner = closed || (i > 0 && i + 1 < n);
        if (!inner) {
          const std::size_t c = i == 0 ? 0 : n - 2;  // the end interval
          const int self = static_cast<int>(i), other = i == 0 ? 1 : static_cast<int>(n - 2);
          rows[i] = {{self, 2.0}, {other, 1.0}};
          rhs[i] = 3 * d[c];
          continue;
        }
        const std::size_t ip = i == 0 ? n - 2 : i - 1;  // the interval before node i
        const int prev = static_cast<int>(i == 0 ? k - 1 : i - 1), next = static_cast<int>((i + 1) % k);
        rows[i] = {{prev, h[i]}, {static_cast<int>(i), 2 * (h[ip] + h[i])}, {next, h[ip]}};
        rhs[i] = 3 * (h[i] * d[ip] + h[ip] * d[i]);
      }
    };
    std::vector<std::vector<CyclicLU::Entry>> rows;
    std::vector<double> rhs;
    rows_of(rows, rhs);
    CyclicLU lu(static_cast<int>(rows.size()), rows);
    bool ok = lu.factor();
    if (ok) {
      lu.solve(rhs.data(), 1, 1);
      for (std::size_t i = 0; i < rhs.size(); ++i) m[i] = rhs[i];
      if (closed) m[n - 1] = m[0];
      ok = monotone();
    }
    if (!ok) {
      // Fritsch–Butland: a weighted harmonic mean of the secants next to a node, at
      // most 3 times the smaller, so every piece stays monotone (Fritsch & Carlson's
      // box 0 <= m/d <= 3); the ends of an open map take their secant.
      const auto mean = [&](std::size_t a, std::size_t b) {  // intervals a (before) and b (after)
        return 3 * (h[a] + h[b]) / ((2 * h[b] + h[a]) / d[a] + (h[b] + 2 * h[a]) / d[b]);
      };
      for (std::size_t i = 1; i + 1 < n; ++i) m[i] = mean(i - 1, i);
      if (closed) {
        m[0] = m[n - 1] = mean(n - 2, 0);
      } else {
        m[0] = d[0];
        m[n - 1] = d[n - 2];
      }
    }
  }
  Reparametrization r;
  r.at = std::move(at);
  r.to = std::move(to);
  r.slope = std::move(m);
  return r;
}

double inverse(const Reparametrization& map, double y) {
  const std::size_t n = map.at.size();
  const bool up = map.to.back() > map.to.front();
  // The piece whose values span y.
  std::size_t i = 0;
  while (i + 2 < n && (up ? y > map.to[i + 1] : y < map.to[i + 1])) ++i;
  const double h = map.at[i + 1] - map.at[i];
  const double y0 = map.to[i], y1 = map.to[i + 1], m0 = map.slope[i] * h, m1 = map.slope[i + 1] * h;
  const auto f = [&](double tau) { return hermite(y0, y1, map.slope[i], map.slope[i + 1], h, tau) - y; };
  // The slope in τ: 6τ(1 − τ)(y1 − y0) + m0(1 − 4τ + 3τ²) + m1(3τ² − 2τ), of one sign on
  // the monotone piece.
  const auto df = [&](double tau) {
    return 6 * tau * (1 - tau) * (y1 - y0) + m0 * (1 - 4 * tau + 3 * tau * tau) + m1 * (3 * tau * tau - 2 * tau);
  };
  // Newton inside a bracket that shrinks every step, bisecting where Newton would
  // leave it, to the last bit.
  double lo = 0, hi = 1;
  const double flo = f(0);
  if (flo == 0) return map.at[i];
  double tau = std::clamp((y - y0) / (y1 - y0), 0.0, 1.0);
  for (int it = 0; it < 100 && hi - lo > 0; ++it) {
    const double fm = f(tau);
    if (fm == 0) break;
    if ((fm > 0) == (flo > 0)) lo = tau;
    else hi = tau;
    const double d = df(tau);
    double next = d != 0 ? tau - fm / d : lo;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (next <= lo || next >= hi || next == tau) break;
    tau = next;
  }
  return std::clamp(map.at[i] + tau * h, map.at[i], map.at[i + 1]);
}

}  // namespace interpatch::detail

namespace interpatch {

double Reparametrization::operator()(double t) const {
  const std::size_t n = at.size();
  std::size_t i = static_cast<std::size_t>(std::upper_bound(at.begin(), at.end(), t) - at.begin());
  i = std::clamp<std::size_t>(i, 1, n - 1) - 1;
  const double h = at[i + 1] - at[i];
  const double y = detail::hermite(to[i], to[i + 1], slope[i], slope[i + 1], h, (t - at[i]) / h);
  if (!(period > 0)) return y;
  const double r = y - start - std::floor((y - start) / period) * period;
  return start + (r < period ? r : 0.0);
}

}  // namespace interpatch
