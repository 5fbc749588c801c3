// A family's curves re-expressed over the surface's parameter: the knots they start
// from (pulled back through their maps, shared or each curve's own) and the choice
// between fitting them on shared knots and on their own.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "constructions/network/network_curves.hpp"

namespace interpatch::detail {

namespace {

// A knot of one curve of a family, pulled back to the surface's parameter.
struct Knot {
  double x;
  int mult;
  std::size_t curve;
};

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

}  // namespace

FamilyKnots family_knots(const std::vector<FitJob>& jobs, const std::vector<double>& nodes, bool closed) {
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
  return {std::move(interior), std::move(own), all};
}

std::vector<Refit> refit(const std::vector<FitJob>& jobs, const std::vector<double>& nodes, bool closed, double target) {
  const std::size_t m = jobs.size();
  // Not structured bindings: the lambda below captures `own` (clang before 16 refuses a binding).
  const FamilyKnots knots = family_knots(jobs, nodes, closed);
  const std::vector<double>& interior = knots.interior;
  const std::vector<std::vector<double>>& own = knots.own;
  const std::size_t all = knots.all;
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
