#include "constructions/network/network_curves.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <numeric>
#include <optional>

#include "linalg/banded.hpp"
#include "linalg/collocation.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"

namespace interpatch::detail {

namespace {

// t moved by whole periods into [0, 1).
double wrap_unit(double t) {
  const double r = t - std::floor(t);
  return r < 1.0 ? r : 0.0;  // a tiny negative t rounds to 1
}

// A curve's parameter for the surface's: in a closed direction a value just past an
// end (rounding in the map, or an open curve whose ends meet) is taken around the
// curve, not refused as outside [0, 1]; in an open one it is held at the end.
double on_curve(double x, bool closed) {
  if (!closed) return std::clamp(x, 0.0, 1.0);
  return x >= 0.0 && x <= 1.0 ? x : wrap_unit(x);
}

// Gauss–Newton on F(s, t) = U(s) − V(t) from (s, t).
// With `hold`, a parameter at an open curve's end that a step would push past it is
// held there, and the other moves alone.
void newton(const BSplineCurve& U, const BSplineCurve& V, double& s, double& t, bool closed_u, bool closed_v,
            bool hold) {
  // The next parameter, and how far it moved (around the circle for a closed curve).
  const auto step = [](double x, double dx, bool closed) {
    if (!closed) {
      const double n = std::clamp(x + dx, 0.0, 1.0);
      return std::pair{n, std::abs(n - x)};
    }
    const double n = wrap_unit(x + dx), moved = std::abs(n - x);
    return std::pair{n, std::min(moved, 1.0 - moved)};
  };
  for (int it = 0; it < 50; ++it) {
    Vec3 du[2], dv[2];
    U.derivatives(s, 1, du);
    V.derivatives(t, 1, dv);
    // Normal equations of J = [U'(s), −V'(t)], with U', V' and F in units of 2^e, e the
    // exponent of the largest component of U' and V': exact, and it keeps det, a
    // product of four of them, in range at any scale of the data (and the test below
    // relative to the tangents), while the steps ds, dt come out as they are.
    const int e = scale_exponent(std::max(max_abs(du[1]), max_abs(dv[1])));
    const Vec3 Us = ldexp(du[1], -e), Vs = ldexp(dv[1], -e), F = ldexp(du[0] - dv[0], -e);
    const double a11 = dot(Us, Us), a12 = -dot(Us, Vs), a22 = dot(Vs, Vs);
    const double r1 = -dot(Us, F), r2 = dot(Vs, F);
    const double det = a11 * a22 - a12 * a12;
    if (!(std::abs(det) > 1e-300)) break;  // parallel tangents (or a point curve): keep the pair
    double ds = (r1 * a22 - a12 * r2) / det, dt = (a11 * r2 - a12 * r1) / det;
    // An open curve held at its end: the closest point of the other curve to that end,
    // by Gauss–Newton in the other parameter alone (a joint step clamped at the end
    // would stop short of the foot point, and overstate the gap).
    const auto at_end = [](double x, double dx, bool closed) { return !closed && ((x <= 0 && dx < 0) || (x >= 1 && dx > 0)); };
    const bool hold_s = hold && at_end(s, ds, closed_u), hold_t = hold && at_end(t, dt, closed_v);
    if (hold_s && hold_t) break;
    if (hold_s) {
      ds = 0;
      dt = a22 > 0 ? r2 / a22 : 0;
    } else if (hold_t) {
      dt = 0;
      ds = a11 > 0 ? r1 / a11 : 0;
    }
    const auto [ns, ms] = step(s, ds, closed_u);
    const auto [nt, mt] = step(t, dt, closed_v);
    const bool done = ms < 1e-15 && mt < 1e-15;
    s = ns;
    t = nt;
    if (done) break;
  }
}

Crossing crossing_at(const BSplineCurve& U, const BSplineCurve& V, double s, double t) {
  Crossing c{s, t, U.point(s), V.point(t), 0};
  c.gap = distance(c.a, c.b);
  return c;
}

double box_distance(const CurveSamples::Chunk& a, const CurveSamples::Chunk& b) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max({0.0, a.lo[k] - b.hi[k], b.lo[k] - a.hi[k]});
    d2 += g * g;
  }
  return std::sqrt(d2);
}

// The distinct knots of c over its domain, increasing, front and back included.
std::vector<double> breaks(const KnotVector& k) {
  std::vector<double> b{k.front()};
  for (double x : k.values())
    if (x > b.back() && x <= k.back()) b.push_back(x);
  if (b.back() != k.back()) b.push_back(k.back());
  return b;
}

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

// ------------------------------------------------------------------- samples

void CurveSamples::make() const {
  const std::vector<double> b = breaks(c_->knots());
  constexpr int per_span = 8;
  for (std::size_t i = 0; i + 1 < b.size(); ++i)
    for (int k = 0; k < per_span; ++k) t_.push_back(b[i] + (b[i + 1] - b[i]) * k / per_span);
  t_.push_back(b.back());
  p_.reserve(t_.size());
  for (double t : t_) p_.push_back(c_->point(t));
  constexpr std::size_t chunk = 32;
  for (std::size_t first = 0; first < p_.size(); first += chunk) {
    Chunk ch{first, std::min(first + chunk, p_.size()) - 1, p_[first], p_[first]};
    for (std::size_t i = first; i <= ch.last; ++i)
      for (int k = 0; k < 3; ++k) {
        ch.lo[k] = std::min(ch.lo[k], p_[i][k]);
        ch.hi[k] = std::max(ch.hi[k], p_[i][k]);
      }
    chunks_.push_back(ch);
  }
}

const std::vector<Vec3>& CurveSamples::points() const {
  if (p_.empty()) make();
  return p_;
}
const std::vector<double>& CurveSamples::params() const {
  if (p_.empty()) make();
  return t_;
}
const std::vector<CurveSamples::Chunk>& CurveSamples::chunks() const {
  if (p_.empty()) make();
  return chunks_;
}

// ------------------------------------------------------------------- crossings

Crossing closest_points(const BSplineCurve& U, const BSplineCurve& V, bool closed_u, bool closed_v, double tol,
                        const CurveSamples& su, const CurveSamples& sv) {
  constexpr int samples = 64;
  std::array<Vec3, samples + 1> us, vs;
  for (int k = 0; k <= samples; ++k) {
    us[static_cast<std::size_t>(k)] = U.point(static_cast<double>(k) / samples);
    vs[static_cast<std::size_t>(k)] = V.point(static_cast<double>(k) / samples);
  }
  double best = std::numeric_limits<double>::infinity(), s = 0, t = 0;
  for (std::size_t a = 0; a <= samples; ++a)
    for (std::size_t b = 0; b <= samples; ++b) {
      const double d = distance(us[a], vs[b]);
      if (d < best) {
        best = d;
        s = static_cast<double>(a) / samples;
        t = static_cast<double>(b) / samples;
      }
    }
  newton(U, V, s, t, closed_u, closed_v, false);
  Crossing coarse = crossing_at(U, V, s, t);
  // Stopped at an open curve's end with a gap: the joint steps were clamped there, and
  // the foot point on the other curve is found with the end held.
  const auto at_bound = [](double x, bool closed) { return !closed && (x <= 0 || x >= 1); };
  if (coarse.gap > 1e-3 * tol && (at_bound(s, closed_u) || at_bound(t, closed_v))) {
    newton(U, V, s, t, closed_u, closed_v, true);
    const Crossing held = crossing_at(U, V, s, t);
    if (held.gap < coarse.gap) coarse = held;
  }
  if (coarse.gap <= tol) return coarse;
  // The thorough pass: pairs of sample boxes nearest first, until a box pair cannot
  // beat the closest samples found.
  const auto& cu = su.chunks();
  const auto& cv = sv.chunks();
  const auto& pu = su.points();
  const auto& pv = sv.points();
  struct Pair {
    double lower;
    std::size_t a, b;
  };
  std::vector<Pair> pairs;
  pairs.reserve(cu.size() * cv.size());
  for (std::size_t a = 0; a < cu.size(); ++a)
    for (std::size_t b = 0; b < cv.size(); ++b) pairs.push_back({box_distance(cu[a], cv[b]), a, b});
  std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.lower < y.lower; });
  best = std::numeric_limits<double>::infinity();
  std::size_t ia = 0, ib = 0;
  for (const Pair& q : pairs) {
    if (q.lower >= best) break;
    for (std::size_t i = cu[q.a].first; i <= cu[q.a].last; ++i)
      for (std::size_t j = cv[q.b].first; j <= cv[q.b].last; ++j) {
        const double d = distance(pu[i], pv[j]);
        if (d < best) {
          best = d;
          ia = i;
          ib = j;
        }
      }
  }
  s = su.params()[ia];
  t = sv.params()[ib];
  newton(U, V, s, t, closed_u, closed_v, true);
  const Crossing fine = crossing_at(U, V, s, t);
  return fine.gap < coarse.gap ? fine : coarse;
}

namespace {

// How far p lies from V: from the nearest of V's samples, Newton on |V(t) − p|²
// (a step that does not bring V nearer ends it).
double distance_to(const BSplineCurve& V, bool closed, const CurveSamples& sv, const Vec3& p) {
  const auto& pv = sv.points();
  std::size_t best = 0;
  for (std::size_t j = 1; j < pv.size(); ++j)
    if (distance(pv[j], p) < distance(pv[best], p)) best = j;
  double t = sv.params()[best], d = distance(pv[best], p);
  for (int it = 0; it < 30; ++it) {
    Vec3 dv[3];
    V.derivatives(t, 2, dv);
    const Vec3 r = dv[0] - p;
    const double g = dot(dv[1], r), h = dot(dv[1], dv[1]) + dot(dv[2], r);
    const double dt = h > 0 ? -g / h : -g / std::max(dot(dv[1], dv[1]), 1e-300);
    const double next = on_curve(t + dt, closed), e = distance(V.point(next), p);
    if (!(e < d)) break;
    t = next;
    d = e;
  }
  return d;
}

}  // namespace

std::vector<Crossing> crossings(const BSplineCurve& U, const BSplineCurve& V, bool closed_u, bool closed_v, double tol,
                                const CurveSamples& su, const CurveSamples& sv) {
  const auto& pu = su.points();
  const auto& pv = sv.points();
  const auto& cu = su.chunks();
  const auto& cv = sv.chunks();
  // A crossing lies within half a sample step of a sample on each curve.
  double hu = 0, hv = 0;
  for (std::size_t i = 0; i + 1 < pu.size(); ++i) hu = std::max(hu, distance(pu[i], pu[i + 1]));
  for (std::size_t j = 0; j + 1 < pv.size(); ++j) hv = std::max(hv, distance(pv[j], pv[j + 1]));
  const double reach = hu + hv + tol;
  const auto near = [&](std::size_t i, std::size_t j) { return distance(pu[i], pv[j]); };
  // A neighbour's index, around the seam of a closed curve (whose last sample is its first).
  const auto neighbour = [](std::size_t i, int d, std::size_t n, bool closed) -> std::optional<std::size_t> {
    const auto k = static_cast<std::ptrdiff_t>(i) + d, last = static_cast<std::ptrdiff_t>(n) - 1;
    if (k >= 0 && k <= last) return static_cast<std::size_t>(k);
    if (!closed || last < 1) return std::nullopt;
    return static_cast<std::size_t>(k < 0 ? k + last : k - last);
  };
  std::vector<Crossing> found;
  // Two crossings are one where the curves stay within tol of each other between them
  // (at 7 points of U between, the shorter way round a closed U).
  const auto same = [&](const Crossing& x, const Crossing& y) {
    if (distance(x.a, y.a) <= tol) return true;
    double from = x.s, span = y.s - x.s;
    if (closed_u && std::abs(span) > 0.5) span -= std::copysign(1.0, span);
    for (int k = 1; k < 8; ++k)
      if (distance_to(V, closed_v, sv, U.point(on_curve(from + span * k / 8, closed_u))) > tol) return false;
    return true;
  };
  for (const auto& a : cu)
    for (const auto& b : cv) {
      if (box_distance(a, b) > reach) continue;
      for (std::size_t i = a.first; i <= a.last; ++i)
        for (std::size_t j = b.first; j <= b.last; ++j) {
          const double x = near(i, j);
          if (x > reach) continue;
          bool least = true;
          for (int di = -1; di <= 1 && least; ++di)
            for (int dj = -1; dj <= 1 && least; ++dj) {
              if (di == 0 && dj == 0) continue;
              const auto ii = neighbour(i, di, pu.size(), closed_u), jj = neighbour(j, dj, pv.size(), closed_v);
              if (ii && jj && near(*ii, *jj) < x) least = false;
            }
          if (!least) continue;
          double s = su.params()[i], t = sv.params()[j];
          newton(U, V, s, t, closed_u, closed_v, true);
          const Crossing c = crossing_at(U, V, s, t);
          if (!(c.gap <= tol)) continue;
          const auto known = std::find_if(found.begin(), found.end(), [&](const Crossing& f) { return same(f, c); });
          if (known == found.end()) found.push_back(c);
          else if (c.gap < known->gap) *known = c;
        }
    }
  std::sort(found.begin(), found.end(), [](const Crossing& x, const Crossing& y) { return x.gap < y.gap; });
  return found;
}

// ------------------------------------------------------------------- the map

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

// ------------------------------------------------------------------- refit

std::vector<double> check_params(const KnotVector& k) {
  const std::vector<double> b = breaks(k);
  std::vector<double> t;
  t.reserve(4 * b.size());
  for (std::size_t i = 0; i + 1 < b.size(); ++i)
    for (int q = 0; q < 4; ++q) t.push_back(b[i] + (b[i + 1] - b[i]) * q / 4);
  t.push_back(b.back());
  return t;
}

std::vector<Vec3> points_at(const BSplineCurve& c, std::span<const double> ts) {
  std::vector<Vec3> out(ts.size());
  const KnotVector& k = c.knots();
  if (c.rational() || k.periodic()) {
    for (std::size_t i = 0; i < ts.size(); ++i) out[i] = c.point(ts[i]);
    return out;
  }
  const int p = k.degree(), last = k.count() - 1;
  const auto& cp = c.control_points();
  int s = -1;
  double N[max_degree + 1];
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const double t = ts[i];
    if (!(t >= k.front() && t <= k.back())) {  // the slack and the errors of point()
      out[i] = c.point(t);
      s = -1;
      continue;
    }
    // find_span's span: k[s] <= t < k[s + 1], the last one for t = back().
    if (s < 0 || t < k[static_cast<std::size_t>(s)]) s = k.find_span(t);
    while (s < last && t >= k[static_cast<std::size_t>(s) + 1]) ++s;
    k.basis(s, t, N);
    Vec3 d{};
    for (int j = 0; j <= p; ++j) d += N[j] * cp[static_cast<std::size_t>(s - p + j)];
    out[i] = d;
  }
  return out;
}

namespace {

// One curve's fit on the shared interior knots (multiplicities capped at its degree):
// collocation at the Greville abscissae, the one nearest each node moved onto it.
// Empty when two nodes want one site (the caller splits between them: `clash`).
struct OneFit {
  std::optional<BSplineCurve> curve;
  std::pair<double, double> clash{0, 0};
  bool failed = false;  // no unique solution, or a weight <= 0: the caller refines
};

OneFit fit_one(const BSplineCurve& c, const Reparametrization& map, const std::vector<double>& nodes, bool closed,
               const std::vector<double>& interior) {
  const int p = c.degree();
  const auto pz = static_cast<std::size_t>(p);
  std::vector<double> knots;
  for (double x : interior) {
    const auto tail = std::min<std::size_t>(knots.size(), pz);
    if (std::count(knots.end() - static_cast<std::ptrdiff_t>(tail), knots.end(), x) < p) knots.push_back(x);
  }
  // A closed spline needs p + 1 knots in its period, an open one none.
  if (closed && knots.size() < pz + 1) return {std::nullopt, {0.0, 1.0}, true};
  KnotVector kv = closed ? KnotVector::periodic_from(p, knots, 1.0) : [&] {
    std::vector<double> all(pz + 1, 0.0);
    all.insert(all.end(), knots.begin(), knots.end());
    all.insert(all.end(), pz + 1, 1.0);
    return KnotVector(p, std::move(all));
  }();
  std::vector<double> sites = kv.greville();
  const std::vector<double> grev = sites;
  std::vector<std::ptrdiff_t> taken(sites.size(), -1);
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double u = nodes[k];
    const auto dist = [&](double g) {
      const double d = std::abs(g - u);
      return closed ? std::min(d, 1.0 - wrap_unit(d)) : d;
    };
    // Greville abscissae increase (closed: around the circle): the nearest by bisection.
    std::size_t near = static_cast<std::size_t>(std::lower_bound(grev.begin(), grev.end(), u) - grev.begin());
    std::size_t best = near < grev.size() ? near : grev.size() - 1;
    for (std::size_t q : {near == 0 ? grev.size() - 1 : near - 1, std::size_t{0}, grev.size() - 1})
      if (q < grev.size() && dist(grev[q]) < dist(grev[best])) best = q;
    if (taken[best] >= 0) return {std::nullopt, {nodes[static_cast<std::size_t>(taken[best])], u}, false};
    taken[best] = static_cast<std::ptrdiff_t>(k);
    sites[best] = closed ? u + std::round(grev[best] - u) : u;
  }
  const bool rational = c.rational();
  std::optional<BSplineCurve> den;  // the weight function Σ N w, as a curve's x
  if (rational) {
    std::vector<Vec3> wx;
    for (double x : c.weights()) wx.push_back({x, 0, 0});
    den.emplace(c.knots(), std::move(wx));
  }
  const std::size_t n = sites.size(), w = rational ? 4 : 3;
  std::vector<double> b(n * w);
  for (std::size_t k = 0; k < n; ++k) {
    const double y = on_curve(map(closed ? wrap_unit(sites[k]) : sites[k]), closed);
    // A rational curve in homogeneous coordinates: Σ N w P and Σ N w.
    const Vec3 q = c.point(y);
    const double wy = rational ? den->point(y).x : 1.0;
    b[k * w] = wy * q.x;
    b[k * w + 1] = wy * q.y;
    b[k * w + 2] = wy * q.z;
    if (rational) b[k * w + 3] = wy;
  }
  try {
    if (closed) factor_periodic_collocation(kv, sites).solve(b.data(), w, w);
    else factor_collocation(kv, sites).solve(b.data(), w, w);
  } catch (const error&) {
    return {std::nullopt, {0, 0}, true};
  }
  std::vector<Vec3> cp(n);
  std::vector<double> wt(rational ? n : 0);
  for (std::size_t k = 0; k < n; ++k) {
    const double h = rational ? b[k * w + 3] : 1.0;
    if (!(h > 0)) return {std::nullopt, {0, 0}, true};
    if (rational) wt[k] = h;
    cp[k] = Vec3{b[k * w], b[k * w + 1], b[k * w + 2]} / h;
  }
  return {BSplineCurve(kv, std::move(cp), std::move(wt)), {0, 0}, false};
}

// A knot of one curve of a family, pulled back to the surface's parameter.
struct Knot {
  double x;
  int mult;
  std::size_t curve;
};

// The work of checking a fit, per span, in multiply-adds: 4 points, each 3 curve
// points of about 30 (a cubic's basis functions and their sum); for parallel_min_work.
constexpr std::size_t span_work = 4 * 3 * 30;

// Fitting every curve of a family on the union of their own knots costs up to this
// many multiply-adds a round (about a millisecond here) where the family shares them.
constexpr std::size_t merge_work = std::size_t{1} << 20;

// Knots of different curves nearer than this are one: the curves' knots at their
// crossings all pull back to the common parameter, up to rounding.
constexpr double knot_room = 1e-9;

// The union of several curves' knots: a knot as many times as the curve that has it
// most often there (not the sum: five curves' simple knots at one place are one
// simple knot of the union), increasing.
std::vector<double> merged(std::vector<Knot> k) {
  std::sort(k.begin(), k.end(), [](const Knot& a, const Knot& b) { return a.x < b.x; });
  std::vector<double> out;
  for (std::size_t i = 0; i < k.size();) {
    std::size_t e = i;
    while (e < k.size() && k[e].x - k[i].x <= knot_room) ++e;
    int most = 0;
    for (std::size_t a = i; a < e; ++a) {
      int sum = 0;
      for (std::size_t b = i; b < e; ++b)
        if (k[b].curve == k[a].curve) sum += k[b].mult;
      most = std::max(most, sum);
    }
    out.insert(out.end(), static_cast<std::size_t>(most), k[i].x);
    i = e;
  }
  return out;
}

// The breaks of interior knots over [0, 1]: 0, the distinct knots, 1.
std::vector<double> spans_of(const std::vector<double>& interior) {
  std::vector<double> b{0.0};
  for (double x : interior)
    if (x > b.back()) b.push_back(x);
  if (b.back() < 1.0) b.push_back(1.0);
  return b;
}

// One fitted curve checked against its job at 4 points of every span of `sp` (the
// next span's first is this one's end): err[i] the largest distance at the 5 points
// of span i, its ends included (too far at a knot, the spans on both sides are to
// blame). Stops early, with `stop` set, once a distance is beyond `give_up`, or when
// `stop` is set elsewhere. The distance from the curve as given (with the correction
// G) is measured only when no span is farther than `target`: a fit that is, is
// refined and measured again.
struct Checked {
  double error = 0, distance = 0;
};
Checked check_fit(const FitJob& job, const BSplineCurve& fit, const std::vector<double>& sp, bool closed,
                  double target, double give_up, std::vector<double>& err, std::atomic<bool>& stop) {
  Checked out;
  struct At {
    double u, y;
    Vec3 d, c;  // D(u) and C(y), y = map(u)
  };
  std::vector<At> at;
  at.reserve(4 * sp.size());
  for (std::size_t i = 0; i + 1 < sp.size(); ++i) {
    for (int q = 0; q <= (i + 2 == sp.size() ? 4 : 3); ++q) {
      const double u = sp[i] + (sp[i + 1] - sp[i]) * q / 4;
      const double y = on_curve(job.map(u), closed);
      const Vec3 d = fit.point(u), c = job.c->point(y);
      const double here = distance(d, c);
      err[i] = std::max(err[i], here);
      if (q == 0 && i > 0) err[i - 1] = std::max(err[i - 1], here);
      at.push_back({u, y, d, c});
    }
    out.error = std::max(out.error, err[i]);
    if (err[i] > give_up) stop = true;
    if (stop) return out;
  }
  if (out.error > target) return out;
  for (const At& a : at)
    out.distance = std::max(out.distance, distance(a.d + job.G->point(a.u), job.given ? job.given->point(a.y) : a.c));
  return out;
}

// Where a span [a, b] of a curve's own knots is cut into k: near a + (b − a) r / k,
// r = 1 … k − 1, within a quarter piece of there, at the nearest knot of another
// curve of the family (`others`, increasing) if there is one, else at the coarsest
// dyadic fraction i / 2^l: the union of the family's knots, the exact form's, grows
// only where no other curve has a knot, and there by points that the other curves'
// cuts nearby take as well.
void cut(double a, double b, int k, const std::vector<double>& others, std::vector<double>& into) {
  const double piece = (b - a) / k, room = 0.25 * piece;
  double last = a;
  for (int r = 1; r < k; ++r) {
    const double want = a + piece * r;
    const auto inside = [&](double x) { return x > last && x < b && std::abs(x - want) <= room; };
    double x = want, best = room;
    const auto it = std::lower_bound(others.begin(), others.end(), want);
    for (auto c : {it, it == others.begin() ? it : std::prev(it)})
      if (c != others.end() && inside(*c) && std::abs(*c - want) <= best) {
        best = std::abs(*c - want);
        x = *c;
      }
    if (x == want)
      for (int l = 0; l < 60; ++l) {
        const double step = std::ldexp(1.0, -l), d = std::round(want / step) * step;
        if (inside(d)) {
          x = d;
          break;
        }
      }
    into.push_back(x);
    last = x;
  }
}

// Curves of one family (`members` of `jobs`) fitted on one knot vector, starting from
// `interior`, until every one is within `target` of its curve. Shared knots
// (`others` null): every span where some curve is farther halved; empty when `all`
// (the count of the curves' own knots together) is not 0 and the halvings the error
// calls for would make more knots than that, so the caller takes the curves' own
// knots instead. One curve on its own knots (`others`: the family's own knots, all
// curves'): a span farther than half the target by a factor f is cut into about
// f^(1/4) pieces (the distance falls with the fourth power of the span, the curve C2
// between its own knots; aiming at half, the cut spans' neighbours, which the new fit
// moves a little, rarely need another round), where `cut` puts them.
std::optional<std::vector<Refit>> fit_group(const std::vector<FitJob>& jobs, const std::vector<std::size_t>& members,
                                            std::vector<double> interior, const std::vector<double>& nodes,
                                            bool closed, double target, std::size_t all,
                                            const std::vector<double>* others) {
  const std::size_t m = members.size();
  const auto insert_mid = [&](double a, double b) {
    const double x = 0.5 * (a + b);
    interior.insert(std::upper_bound(interior.begin(), interior.end(), x), x);
  };
  // Two nodes that want one collocation site: a knot between them, in the widest gap
  // left there (the midpoint of the two may already be a knot of full multiplicity).
  const auto split_between = [&](double a, double b) {
    if (a > b) std::swap(a, b);
    std::vector<double> at{a};
    for (double x : interior)
      if (x > a && x < b && x > at.back()) at.push_back(x);
    at.push_back(b);
    std::size_t w = 0;
    for (std::size_t i = 0; i + 1 < at.size(); ++i)
      if (at[i + 1] - at[i] > at[w + 1] - at[w]) w = i;
    insert_mid(at[w], at[w + 1]);
  };
  const auto split_all = [&] {
    const auto sp = spans_of(interior);
    for (std::size_t i = 0; i + 1 < sp.size(); ++i) insert_mid(sp[i], sp[i + 1]);
  };
  int p_max = 1;
  for (std::size_t j : members) p_max = std::max(p_max, jobs[j].c->degree());
  std::size_t worst_job = members.front();  // the curve farthest from its fit in the last round checked
  while (closed && spans_of(interior).size() < static_cast<std::size_t>(p_max) + 2) split_all();
  const std::size_t initial = std::max(interior.size(), all);
  std::vector<Refit> out;
  for (int round = 0; round < 60; ++round) {
    // Halving a span divides the distance by 8 or more (cubic pieces against a
    // function C2 between the curve's own knots): the most halvings worth making on
    // shared knots are those that keep them fewer than the curves' own together, and
    // a distance that would need more stops the check at once.
    double give_up = std::numeric_limits<double>::infinity();
    if (all > 0) {
      int h = 0;
      while (h < 60 && std::ldexp(static_cast<double>(interior.size()), h + 1) <= static_cast<double>(all)) ++h;
      give_up = target * std::pow(8.0, h);
    }
    // Every curve fitted and checked, in parallel (the check only reads).
    const auto sp = spans_of(interior);
    std::vector<OneFit> fits(m);
    std::vector<std::vector<double>> err(m, std::vector<double>(sp.size(), 0.0));
    std::vector<Checked> checked(m);
    std::atomic<bool> stop{false};
    parallel_for(m, m * sp.size() * span_work >= parallel_min_work, Share::one_by_one, [&](std::size_t j) {
      const FitJob& job = jobs[members[j]];
      if (stop) return;
      fits[j] = fit_one(*job.c, job.map, nodes, closed, interior);
      if (fits[j].curve) checked[j] = check_fit(job, *fits[j].curve, sp, closed, target, give_up, err[j], stop);
    });
    // Whether some curve was too far to go on is the same on any number of threads:
    // the curve that stopped the others stops the check on one thread as well.
    if (stop) return std::nullopt;
    // The last round's knots are refused only when its fits are not all within the
    // target: a round that got there on the limit is kept.
    double farthest = 0;
    bool fitted = true;
    for (std::size_t j = 0; j < m; ++j) {
      fitted = fitted && fits[j].curve.has_value();
      for (double e : err[j])
        if (e > farthest) {
          farthest = e;
          worst_job = members[j];
        }
    }
    if (interior.size() > 64 * initial + 4096 && !(fitted && farthest <= target))
      throw RefitShortfall(worst_job, cat("re-expressed at the common crossing parameters on ", interior.size(),
                                          " knots, it stays ", farthest, " from the curve given, more than ", target,
                                          " (half the tolerance): the curves are too rough or too far from the origin "
                                          "for their size to be held that close; give a larger \"tolerance\""));
    bool again = false;
    for (std::size_t j = 0; j < m && !again; ++j) {
      if (fits[j].failed) split_all();
      else if (!fits[j].curve) split_between(fits[j].clash.first, fits[j].clash.second);
      again = !fits[j].curve;
    }
    if (again) continue;
    std::vector<double> worst(sp.size(), 0.0);  // by span, over the curves
    out.clear();
    for (std::size_t j = 0; j < m; ++j) {
      for (std::size_t i = 0; i < sp.size(); ++i) worst[i] = std::max(worst[i], err[j][i]);
      out.push_back({std::move(*fits[j].curve), checked[j].error, checked[j].distance});
    }
    if (std::none_of(worst.begin(), worst.end(), [&](double e) { return e > target; })) return out;
    std::vector<double> cuts;
    for (std::size_t i = 0; i + 1 < sp.size(); ++i) {
      if (!(worst[i] > (others ? 0.5 * target : target))) continue;
      if (!others) {
        cuts.push_back(0.5 * (sp[i] + sp[i + 1]));
        continue;
      }
      const double pieces = std::ceil(std::pow(2 * worst[i] / target, 0.25));
      cut(sp[i], sp[i + 1], static_cast<int>(std::clamp(pieces, 2.0, 8.0)), *others, cuts);
    }
    interior.insert(interior.end(), cuts.begin(), cuts.end());
    std::sort(interior.begin(), interior.end());
  }
  throw RefitShortfall(worst_job, cat("re-expressed at the common crossing parameters, 60 rounds of knots (", m,
                                      " curves together) did not bring it within ", target,
                                      " (half the tolerance) of the curve given: give a larger \"tolerance\""));
}

}  // namespace

std::vector<Refit> refit(const std::vector<FitJob>& jobs, const std::vector<double>& nodes, bool closed, double target) {
  const std::size_t m = jobs.size();
  // The knots of each curve, pulled back through its map: its corners (multiple knots)
  // and its simple knots.
  std::vector<Knot> corners;
  std::vector<std::vector<double>> simple(m);
  std::size_t most = 0;
  for (std::size_t j = 0; j < m; ++j) {
    Reparametrization unwrapped = jobs[j].map;
    unwrapped.period = 0;
    const double lo = std::min(unwrapped(0.0), unwrapped(1.0)), hi = std::max(unwrapped(0.0), unwrapped(1.0));
    for (const auto& [kappa, mult] : jobs[j].c->knots().interior_breaks())
      for (int shift = closed ? -1 : 0; shift <= (closed ? 2 : 0); ++shift) {
        const double y = kappa + shift;
        if (!(closed ? y >= lo && y < hi : y > lo && y < hi)) continue;
        double x = inverse(unwrapped, y);
        // A knot at a crossing (an interpolant's knots are often its data's parameters)
        // pulls back to the common parameter up to rounding: put it there, where the
        // cardinal functions have theirs, so the exact form has one knot, not two.
        for (double u : nodes)
          if (std::abs(x - u) <= knot_room) x = u;
        if (closed && (x < knot_room || x > 1 - knot_room)) x = 0;  // at the seam
        if (!closed && (x <= knot_room || x >= 1 - knot_room)) continue;
        if (mult > 1) corners.push_back({x, mult, j});
        else simple[j].push_back(x);
      }
    std::sort(simple[j].begin(), simple[j].end());
    most = std::max(most, simple[j].size());
  }
  // First the family on shared knots (so the exact form of the surface has about as
  // many control points as the densest curve, not the sum of all): every curve's
  // corners, and its simple knots averaged over the family quantile by quantile.
  std::vector<double> interior = merged(corners);
  const double room = 0.25 / static_cast<double>(most + 1);  // a simple knot this near a corner is left out
  for (std::size_t k = 1; k <= most; ++k) {
    const double q = static_cast<double>(k) / static_cast<double>(most + 1);
    double sum = 0;
    std::size_t count = 0;
    for (const auto& s : simple) {
      if (s.empty()) continue;
      // The q-quantile of this curve's knots, between its neighbours (0 and 1 at the ends).
      const double pos = q * static_cast<double>(s.size() + 1) - 1;
      const auto at = [&](std::ptrdiff_t i) {
        return i < 0 ? 0.0 : i >= static_cast<std::ptrdiff_t>(s.size()) ? 1.0 : s[static_cast<std::size_t>(i)];
      };
      const auto i0 = static_cast<std::ptrdiff_t>(std::floor(pos));
      const double f = pos - static_cast<double>(i0);
      sum += (1 - f) * at(i0) + f * at(i0 + 1);
      ++count;
    }
    const double x = sum / static_cast<double>(count);
    if (std::none_of(corners.begin(), corners.end(), [&](const Knot& c) { return std::abs(c.x - x) < room; }))
      interior.push_back(x);
  }
  if (closed && std::find(interior.begin(), interior.end(), 0.0) == interior.end()) interior.push_back(0.0);
  std::sort(interior.begin(), interior.end());
  // Each curve's own knots (with the seam of a closed one): where it has its breaks,
  // so its fit converges at once.
  std::vector<std::vector<double>> own(m);
  std::size_t all = 0;
  for (std::size_t j = 0; j < m; ++j) {
    std::vector<Knot> k;
    for (const Knot& c : corners)
      if (c.curve == j) k.push_back(c);
    for (double x : simple[j]) k.push_back({x, 1, j});
    if (closed) k.push_back({0.0, 1, m});
    own[j] = merged(std::move(k));
    all += own[j].size();
  }
  std::vector<std::size_t> family(m);
  std::iota(family.begin(), family.end(), 0);
  if (auto shared = fit_group(jobs, family, interior, nodes, closed, target, all, nullptr)) return std::move(*shared);
  // The shared knots would need more halvings than all curves' own knots make (curves
  // whose parameters are irregular, e.g. centripetal through unevenly spaced points,
  // break where the average does not). Where fitting every curve on all the curves'
  // knots is little work (under about a millisecond a round), they share those, which
  // keeps the exact form smallest; otherwise every curve goes on its own knots,
  // refined alone: the surface's formula does not need shared knots, and its exact
  // form merges them.
  std::vector<Knot> every;
  for (std::size_t j = 0; j < m; ++j)
    for (double x : own[j]) every.push_back({x, 1, j});
  const std::vector<double> union_of_own = merged(std::move(every));
  if (m * union_of_own.size() * span_work <= merge_work)
    return std::move(*fit_group(jobs, family, union_of_own, nodes, closed, target, 0, nullptr));
  std::vector<std::optional<Refit>> fitted(m);
  parallel_for(m, all * span_work >= parallel_min_work, Share::one_by_one, [&](std::size_t j) {
    fitted[j] = std::move(fit_group(jobs, {j}, own[j], nodes, closed, target, 0, &union_of_own)->front());
  });
  std::vector<Refit> out;
  out.reserve(m);
  for (auto& f : fitted) out.push_back(std::move(*f));
  return out;
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
