// Where two curves of a network cross: their closest points, and every place they
// meet, by Gauss–Newton from samples.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "base/text.hpp"
#include "constructions/network/network_curves.hpp"

namespace interpatch::detail {

namespace {

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

}  // namespace

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

}  // namespace interpatch::detail
