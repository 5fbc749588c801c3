// A family's curves fitted on one knot vector, refined until each is within the
// target of its curve: one curve's collocation, its check, and where knots are added.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "constructions/network/network_curves.hpp"
#include "linalg/collocation.hpp"

namespace interpatch::detail {

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
    out.distance = std::max(out.distance, distance(job.G ? a.d + job.G->point(a.u) : a.d, job.given ? job.given->point(a.y) : a.c));
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

// A knot at the middle of [a, b].
void insert_mid(std::vector<double>& interior, double a, double b) {
  const double x = 0.5 * (a + b);
  interior.insert(std::upper_bound(interior.begin(), interior.end(), x), x);
}

// Two nodes that want one collocation site: a knot between them, in the widest gap
// left there (the midpoint of the two may already be a knot of full multiplicity).
void split_between(std::vector<double>& interior, double a, double b) {
  if (a > b) std::swap(a, b);
  std::vector<double> at{a};
  for (double x : interior)
    if (x > a && x < b && x > at.back()) at.push_back(x);
  at.push_back(b);
  std::size_t w = 0;
  for (std::size_t i = 0; i + 1 < at.size(); ++i)
    if (at[i + 1] - at[i] > at[w + 1] - at[w]) w = i;
  insert_mid(interior, at[w], at[w + 1]);
}

// Every span halved.
void split_all(std::vector<double>& interior) {
  const auto sp = spans_of(interior);
  for (std::size_t i = 0; i + 1 < sp.size(); ++i) insert_mid(interior, sp[i], sp[i + 1]);
}

// How far a fit on `knots` shared knots may be before the check stops. Halving a span
// divides the distance by 8 or more (cubic pieces against a function C2 between the
// curve's own knots): the most halvings worth making on shared knots are those that
// keep them fewer than the curves' own together (`all`; 0: no limit), and a distance
// that would need more stops the check at once.
double give_up_at(double target, std::size_t knots, std::size_t all) {
  double give_up = std::numeric_limits<double>::infinity();
  if (all > 0) {
    int h = 0;
    while (h < 60 && std::ldexp(static_cast<double>(knots), h + 1) <= static_cast<double>(all)) ++h;
    give_up = target * std::pow(8.0, h);
  }
  return give_up;
}

// The knots a round adds where `worst` (by span of `sp`, over the curves) is too far:
// shared knots (`others` null) halve every span beyond the target, a curve's own
// knots cut every span beyond half the target where `cut` puts the pieces.
std::vector<double> refinement(const std::vector<double>& sp, const std::vector<double>& worst, double target,
                               const std::vector<double>* others) {
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
  return cuts;
}

}  // namespace

// Declared, and described, in network_curves.hpp.
std::optional<std::vector<Refit>> fit_group(const std::vector<FitJob>& jobs, const std::vector<std::size_t>& members,
                                            std::vector<double> interior, const std::vector<double>& nodes,
                                            bool closed, double target, std::size_t all,
                                            const std::vector<double>* others) {
  const std::size_t m = members.size();
  int p_max = 1;
  for (std::size_t j : members) p_max = std::max(p_max, jobs[j].c->degree());
  std::size_t worst_job = members.front();  // the curve farthest from its fit in the last round checked
  while (closed && spans_of(interior).size() < static_cast<std::size_t>(p_max) + 2) split_all(interior);
  const std::size_t initial = std::max(interior.size(), all);
  std::vector<Refit> out;
  for (int round = 0; round < 60; ++round) {
    const double give_up = give_up_at(target, interior.size(), all);
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
      if (fits[j].failed) split_all(interior);
      else if (!fits[j].curve) split_between(interior, fits[j].clash.first, fits[j].clash.second);
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
    const std::vector<double> cuts = refinement(sp, worst, target, others);
    interior.insert(interior.end(), cuts.begin(), cuts.end());
    std::sort(interior.begin(), interior.end());
  }
  throw RefitShortfall(worst_job, cat("re-expressed at the common crossing parameters, 60 rounds of knots (", m,
                                      " curves together) did not bring it within ", target,
                                      " (half the tolerance) of the curve given: give a larger \"tolerance\""));
}

}  // namespace interpatch::detail
