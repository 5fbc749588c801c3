#pragma once
// The fit to a tolerance: knots grown where the error is largest (first on a thinned
// grid when the data are large), more control points everywhere when growth stalls,
// then the knots that cost least pruned while the fit stays within the tolerance.
// Every decision is taken from what the data source returns, the same on every
// process of a split run.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/approximate/approx_knots.hpp"
#include "constructions/approximate/approx_residuals.hpp"

namespace interpatch::detail::approx {

// What removing each interior knot of an open axis a would cost, estimated from the
// fit: the largest jump, over the lines of the control net along a, of the p-th
// derivative at the knot (where the two polynomial pieces differ), times the p-th
// power of the two intervals beside it (The NURBS Book §5.4: the deviation a
// removal brings is of that order).
template <std::size_t R>
std::vector<double> removal_costs(const Fit<R>& f, std::size_t a, const std::vector<double>& breaks) {
  const Axis& ax = f.axes[a];
  const int p = ax.p;
  const auto pp = static_cast<std::size_t>(p) + 1;
  std::vector<double> u{ax.t.front()};
  u.insert(u.end(), breaks.begin(), breaks.end());
  u.push_back(ax.t.back());
  const std::size_t pieces = u.size() - 1;
  // The p-th derivatives of the basis on each piece (constant there).
  std::vector<int> first(pieces);
  std::vector<double> der(pieces * pp);
  double tmp[(max_degree + 1) * (max_degree + 1)];
  for (std::size_t j = 0; j < pieces; ++j) {
    const double mid = 0.5 * (u[j] + u[j + 1]);
    const int span = ax.knots.find_span(mid);
    ax.knots.basis_derivatives(span, mid, p, tmp);
    first[j] = span - p;
    std::copy(tmp + static_cast<std::size_t>(p) * pp, tmp + static_cast<std::size_t>(p + 1) * pp, der.begin() + static_cast<std::ptrdiff_t>(j * pp));
  }
  std::size_t outer = 1, inner = 1;
  for (std::size_t x = 0; x < a; ++x) outer *= static_cast<std::size_t>(f.axes[x].c);
  for (std::size_t x = a + 1; x < R; ++x) inner *= static_cast<std::size_t>(f.axes[x].c);
  const auto c = static_cast<std::size_t>(ax.c);
  std::vector<double> jump(breaks.size(), 0.0);
  std::vector<Vec3> d(pieces);
  for (std::size_t o = 0; o < outer; ++o)
    for (std::size_t in = 0; in < inner; ++in) {
      for (std::size_t j = 0; j < pieces; ++j) {
        Vec3 v{};
        for (std::size_t k = 0; k < pp; ++k) {
          const std::size_t i = (o * c + static_cast<std::size_t>(first[j]) + k) * inner + in;
          v = v + der[j * pp + k] * Vec3{f.cp[3 * i], f.cp[3 * i + 1], f.cp[3 * i + 2]};
        }
        d[j] = v;
      }
      for (std::size_t k = 0; k < breaks.size(); ++k) jump[k] = std::max(jump[k], distance(d[k + 1], d[k]));
    }
  for (std::size_t k = 0; k < breaks.size(); ++k) jump[k] *= std::pow(u[k + 2] - u[k], p);
  return jump;
}

// Growth from the knots in `breaks`: knots go where the error is largest, in every
// interval whose worst point is beyond the tolerance, in the directions along which
// that point's line, fitted on its own, misses it by more than half the tolerance
// (where neither does, in every direction). True when the fit is within the
// tolerance; false when no interval can split any more. `s`: the data (Whole, or a
// block of a split run), every decision here the same on every process.
template <std::size_t R, class Source>
bool grow(Fit<R>& f, const Source& s, double tol, std::array<std::vector<double>, R>& breaks,
          const progress_callback& progress) {
  const std::array<std::vector<bool>, R> has_data = s.has_data();
  for (;;) {
    s.fit(f);
    if (progress) progress(std::min(0.9, 0.1 + 0.04 * f.fits));
    const Residuals<R> r = s.errors(f);
    // Within the tolerance but swinging between the data (knots that leave a basis
    // function little data): climb() takes the least-squares knots instead.
    if (r.max <= tol) return s.sane(f);
    // The intervals beyond the tolerance; those of a direction with a line fit are
    // decided by it, all lines of one round at once.
    std::array<std::vector<int>, R> bad;
    std::array<std::optional<AxisSolver>, R> lu;
    std::vector<std::pair<std::size_t, std::size_t>> lines;
    for (std::size_t a = 0; a < R; ++a) {
      const Axis& ax = f.axes[a];
      if (static_cast<std::size_t>(ax.c) >= ax.n) continue;
      // A direction whose knots outnumber the data under them (the fit then leans on
      // the fairness term) has no line fit of its own: every bad interval of it splits.
      try {
        lu[a] = factor_gram(ax, a);
      } catch (const error& e) {
        if (e.code() != errc::singular) throw;
      }
      for (int k = 0; k < ax.intervals; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        if (!(r.interval_max[a][kk] > tol)) continue;
        bad[a].push_back(k);
        if (R > 1 && lu[a]) lines.emplace_back(a, r.interval_worst[a][kk]);
      }
    }
    const std::vector<double> line_error = s.line_residuals(f, lu, lines);
    std::array<std::vector<int>, R> split;
    bool any = false;
    std::size_t next = 0;
    for (std::size_t a = 0; a < R; ++a)
      for (const int k : bad[a])
        if (R == 1 || !lu[a] || line_error[next++] > 0.5 * tol) {
          split[a].push_back(k);
          any = true;
        }
    if (!any) {
      const std::vector<std::size_t> w = unflatten<R>(r.worst, s.shape());
      for (std::size_t a = 0; a < R; ++a) split[a].push_back(f.axes[a].interval[w[a]]);
    }
    bool added = false;
    for (std::size_t a = 0; a < R; ++a) {
      const std::size_t before = breaks[a].size();
      for (int k : split[a])
        if (split_interval(f.axes[a], breaks[a], k, has_data[a])) added = true;
      if (breaks[a].size() != before) {
        std::sort(breaks[a].begin(), breaks[a].end());
        f.axes[a].set_knots(knots_from_breaks(f.axes[a], breaks[a]));
      }
    }
    if (!added) return false;  // every interval is as fine as the data allow
  }
}

// Growth stalled (no interval beyond the tolerance can split): the knots of the
// least-squares rule (least_squares_breaks), half as many more control points again
// along every direction each time, up to as many as data points (interpolation, which
// meets any tolerance on a complete grid but for rounding). True when the fit is
// within the tolerance; false with the fit of the most control points (the caller's
// check then refuses it, naming the worst point).
template <std::size_t R, class Source>
bool climb(Fit<R>& f, const Source& s, double tol, std::array<std::vector<double>, R>& breaks,
           const progress_callback& progress) {
  for (;;) {
    // A direction growth left with as many control points as data takes
    // interpolation's knots too: growth's may be poorly conditioned there.
    bool more = false;
    for (std::size_t a = 0; a < R; ++a) {
      Axis& ax = f.axes[a];
      const int n = static_cast<int>(ax.n), c = ax.c < n ? std::max(ax.c + 1, ax.c + ax.c / 2) : n;
      std::vector<double> next = least_squares_breaks(ax, std::min(n, c));
      if (next == breaks[a]) continue;
      more = true;
      breaks[a] = std::move(next);
      ax.set_knots(knots_from_breaks(ax, breaks[a]));
    }
    if (!more) return false;
    s.fit(f);
    if (progress) progress(std::min(0.9, 0.1 + 0.04 * f.fits));
    if (s.errors(f).max <= tol && s.sane(f)) return true;
  }
}

// A large grid grows its first knots on every 4th line of directions with 128 or
// more points (a sixteenth of a surface's work per fit): the coarse knots a smooth
// part of the data needs show on it as well. The whole grid then refines them.
// `coarse` and `sub` get the thinned grid's fit and data, for pruning to try
// removals on first.
template <std::size_t R, class Source>
void grow_thinned(Fit<R>& f, const Source& s, double tol, std::array<std::vector<double>, R>& breaks, Fit<R>& coarse,
                  std::optional<Source>& sub) {
  constexpr std::size_t thin = 4, thin_from = 128;
  std::array<std::vector<std::size_t>, R> kept;
  for (std::size_t a = 0; a < R; ++a) {
    const std::size_t n = s.shape()[a], step = n >= thin_from ? thin : 1;
    for (std::size_t i = 0; i < n; i += step) kept[a].push_back(i);
    if (!f.axes[a].periodic && kept[a].back() != n - 1) kept[a].push_back(n - 1);
    Axis& ax = coarse.axes[a];
    ax.n = kept[a].size();
    ax.p = f.axes[a].p;
    ax.periodic = f.axes[a].periodic;
    for (std::size_t i : kept[a]) ax.t.push_back(f.axes[a].t[i]);
    ax.set_knots(knots_from_breaks(ax, breaks[a]));
  }
  sub.emplace(s.thinned(kept));
  (void)grow<R>(coarse, *sub, tol, breaks, {});
  f.fits += coarse.fits;
  coarse.fits = 0;
  for (std::size_t a = 0; a < R; ++a) f.axes[a].set_knots(knots_from_breaks(f.axes[a], breaks[a]));
}

// Pruning: growth splits several intervals at once and overshoots. The knots whose
// removal costs least go, as long as the refit stays within the tolerance: first
// a quarter of them at once, half as many after each refusal, one at a time at
// the end; a few refused single removals end it. On a large grid a removal is
// first tried on the thinned grid (a sixteenth of the work): one that fails there
// is refused without the whole grid's fit.
// `coarse` and `sub`: the thinned grid's fit and data (none when not thinned).
template <std::size_t R, class Source>
void prune(Fit<R>& f, const Source& s, double tol, std::array<std::vector<double>, R>& breaks, Fit<R>& coarse,
           const std::optional<Source>& sub, const progress_callback& progress) {
  auto max_error = [&] {
    s.fit(f);
    if (progress) progress(std::min(0.9, 0.1 + 0.04 * f.fits));
    return s.errors(f);
  };
  constexpr int refusals = 3;
  std::vector<std::pair<std::size_t, double>> refused;
  std::size_t total = 0;
  for (std::size_t a = 0; a < R; ++a) total += f.axes[a].periodic ? 0 : breaks[a].size();
  std::size_t batch = std::max<std::size_t>(1, total / 4);
  while (static_cast<int>(refused.size()) < refusals) {
    struct Candidate {
      double cost;
      std::size_t axis;
      double knot;
    };
    std::vector<Candidate> cand;
    for (std::size_t a = 0; a < R; ++a) {
      if (f.axes[a].periodic) continue;
      const std::vector<double> cost = removal_costs<R>(f, a, breaks[a]);
      for (std::size_t k = 0; k < cost.size(); ++k)
        if (std::none_of(refused.begin(), refused.end(),
                         [&](const auto& x) { return x.first == a && x.second == breaks[a][k]; }))
          cand.push_back({cost[k], a, breaks[a][k]});
    }
    if (cand.empty()) return;
    std::stable_sort(cand.begin(), cand.end(), [](const Candidate& x, const Candidate& y) { return x.cost < y.cost; });
    batch = std::min(batch, cand.size());
    const Fit<R> kept = f;
    const std::array<std::vector<double>, R> kept_breaks = breaks;
    std::array<bool, R> changed{};
    for (std::size_t k = 0; k < batch; ++k) {
      auto& b = breaks[cand[k].axis];
      b.erase(std::find(b.begin(), b.end(), cand[k].knot));
      changed[cand[k].axis] = true;
    }
    for (std::size_t a = 0; a < R; ++a)
      if (changed[a]) f.axes[a].set_knots(knots_from_breaks(f.axes[a], breaks[a]));
    bool within = true;
    if (sub) {
      for (std::size_t a = 0; a < R; ++a) coarse.axes[a].set_knots(knots_from_breaks(coarse.axes[a], breaks[a]));
      sub->fit(coarse);
      within = sub->errors(coarse).max <= tol;
      f.fits += coarse.fits;
      coarse.fits = 0;
    }
    if (within && max_error().max <= tol && s.sane(f)) continue;
    const int fits = f.fits;
    f = kept;
    f.fits = fits;
    breaks = kept_breaks;
    if (batch == 1) refused.emplace_back(cand[0].axis, cand[0].knot);
    batch = std::max<std::size_t>(1, batch / 2);
  }
}

// The fit to a tolerance of the data `s` (Whole, or a block of a split run).
template <std::size_t R, class Source>
void solve_tolerance(Fit<R>& f, const Source& s, double tol, const progress_callback& progress) {
  std::array<std::vector<double>, R> breaks;
  for (std::size_t a = 0; a < R; ++a) {
    Axis& ax = f.axes[a];
    breaks[a] = ax.periodic ? least_squares_breaks(ax, ax.p + 1) : std::vector<double>{};
    ax.set_knots(knots_from_breaks(ax, breaks[a]));
  }
  Fit<R> coarse;
  std::optional<Source> sub;
  if (s.size() >= (std::size_t{1} << 18)) grow_thinned<R>(f, s, tol, breaks, coarse, sub);
  if (!grow<R>(f, s, tol, breaks, progress) && !climb<R>(f, s, tol, breaks, progress)) return;
  prune<R>(f, s, tol, breaks, coarse, sub, progress);
}

}  // namespace interpatch::detail::approx
