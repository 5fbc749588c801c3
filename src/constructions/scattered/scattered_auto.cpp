// "smoothing": "auto" for scattered points: λ chosen by cross-validation. The points
// present fall into 5 folds by a hash of their coordinates (the same folds whatever
// their order; -0 and +0 alike); a fold's points are held out, the others fitted, and the held-out
// points' squared distances summed. Below 25 000 points every fold is held out in turn;
// above, one fold of about 20 % is plenty and five would cost five times as much.
// λ is searched over decades of the balance between the two terms, then refined by
// golden sections in log λ; each fit starts from the one before, the multigrid's
// matrices are the data and fairness terms made once (the coarser data terms restricted
// from the finer) and summed for each λ.

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "base/text.hpp"
#include "constructions/scattered/scattered_fit.hpp"
#include "constructions/scattered/scattered_multigrid.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::scattered {

namespace {

constexpr int fold_count = 5;
constexpr std::size_t all_folds_below = 25000;

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  h ^= h >> 31;
  h *= 0xbf58476d1ce4e5b9ULL;
  return h ^ (h >> 29);
}

// One fold's training fit: its data terms on every net, its weight sum, its solution.
struct Fold {
  int index = 0;
  std::vector<double> weight;
  double weight_sum = 0;
  std::vector<System> data;  // the coarsest net's and the finest's (one when they are one)
  std::vector<double> x;
};

struct Search {
  const Problem& pr;
  std::vector<Net> nets;  // the multigrid's coarsest net and the finest (one when they are one)
  std::vector<NetMatrix> fair, sum;  // of each net, as Fold::data
  std::vector<Fold> folds;
  std::optional<Multigrid> mg;
  int evaluations = 0;

  // The held-out points' summed squared distance from the fits at λ, every fold.
  double score(double lambda) {
    double total = 0;
    for (Fold& f : folds) {
      for (std::size_t l = 0; l < sum.size(); ++l) {
        sum[l].assign_sum(f.data[l].a, fair[l], f.weight_sum * lambda);
        sum[l].mirror();
      }
      if (!mg->factor()) return std::numeric_limits<double>::infinity();
      Multigrid& m = *mg;
      // To ten digits: stopped early, conjugate gradients smooth the fit of a small λ
      // (started from the larger λ's fit) and flatter its score; the fit kept is solved
      // again to twelve.
      const Solved sol = solve_cg(sum.back(), f.data.back().rhs, f.x, pr.cols, 1e-10, 400,
                                  [&m](std::span<const double> r, std::span<double> z, int) { m.apply(r, z); });
      if (!(sol.residual <= 1e-4)) return std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < pr.size(); ++k) {
        if (pr.fold[k] != f.index) continue;
        const double d = distance_at(pr, nets.back(), f.x, k);
        total += pr.samples().weight_at(k) * d * d;
      }
    }
    ++evaluations;
    return total;
  }
};

}  // namespace

std::uint8_t fold_of(const Vec3& point) {
  std::uint64_t h = 0;
  for (const double c : {point.x, point.y, point.z}) h = mix(h, std::bit_cast<std::uint64_t>(c + 0.0));
  return static_cast<std::uint8_t>(h % fold_count);
}

Chosen choose_lambda(const Problem& pr, const Net& net, const progress_callback& progress, double from, double to) {
  const Sites& s = *pr.sites;
  Search search{pr, {}, {}, {}, {}, std::nullopt, 0};
  const std::vector<Net> all = hierarchy(net, coarsest_net);
  search.nets = {all.front()};
  if (all.size() > 1) search.nets.push_back(all.back());
  const int evaluated = s.present < all_folds_below ? fold_count : 1;
  std::size_t rows = 0;
  for (const Net& n : search.nets) rows += n.size();
  const int hu = std::max(net.p, 2), hv = std::max(net.q, 2);
  require_memory(rows, NetMatrix::bytes_per_row(hu, hv) * static_cast<std::size_t>(evaluated + 2) + StripSmoother::bytes_per_row(hu, hv),
                 cat("cross-validation of ", evaluated, " folds on a net of ", net.nu, " x ", net.nv, " control points"));
  for (const Net& n : search.nets) {
    search.fair.emplace_back(n.nu, n.nv, hu, hv);
    add_fairness(n, &search.fair.back(), 1.0);
    search.sum.emplace_back(n.nu, n.nv, hu, hv);
  }
  for (int f = 0; f < evaluated; ++f) {
    Fold fold;
    fold.index = f;
    fold.weight.resize(pr.size());
    for (std::size_t k = 0; k < fold.weight.size(); ++k) fold.weight[k] = pr.fold[k] == f ? 0.0 : pr.samples().weight_at(k);
    fold.weight_sum = std::accumulate(fold.weight.begin(), fold.weight.end(), 0.0);
    // The finest net's data term from the points, the coarsest one's restricted from it.
    System top = data_system(pr, search.nets.back(), fold.weight);
    if (search.nets.size() > 1) fold.data.push_back(restrict_between(top, search.nets.back(), search.nets.front()));
    fold.data.push_back(std::move(top));
    fold.x.assign(net.size() * static_cast<std::size_t>(pr.cols), 0.0);
    search.folds.push_back(std::move(fold));
  }
  search.mg.emplace(search.nets.front(), search.nets.back(), &search.sum.front(), &search.sum.back(), pr.cols);

  // λ in decades of the balance, where J's diagonal equals the data term's on average:
  // from it, one decade at a time in the direction the score falls, until it rises.
  // The fill (1e-5 of the balance) bounds it below; 1e10 times it is a plane.
  const Fold& first = search.folds.front();
  const double fill = fill_lambda(net, first.data.back().a, first.weight_sum);
  const double balance = fill * 1e5;
  constexpr int lo = -5, hi = 10, golden_steps = 5;
  const double total = 6 + golden_steps;  // a typical search, for the progress shown
  const auto report = [&] {
    if (progress) progress(from + (to - from) * std::min(1.0, static_cast<double>(search.evaluations) / total));
  };
  const auto at = [&](double t) {
    const double e = search.score(balance * std::pow(10.0, t));
    report();
    return e;
  };
  int best = 0;
  double best_score = at(0);
  const double above = at(1);
  const int step = above < best_score ? 1 : -1;
  if (step == 1) best = 1, best_score = above;
  for (int t = best + step; t >= lo && t <= hi; t += step) {
    const double e = at(t);
    if (!(e < best_score)) break;
    best_score = e, best = t;
  }
  // Golden sections on [best − 1, best + 1] in log λ, ending about 0.2 decade wide.
  const double g = (std::sqrt(5.0) - 1) / 2;
  double a = std::max(best - 1, lo), b = std::min(best + 1, hi);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = at(c), fd = at(d);
  for (int i = 2; i < golden_steps; ++i) {
    if (fc <= fd) b = d, d = c, fd = fc, c = b - g * (b - a), fc = at(c);
    else a = c, c = d, fc = fd, d = a + g * (b - a), fd = at(d);
  }
  double t = best, e = best_score;
  if (fc < e) t = c, e = fc;
  if (fd < e) t = d;
  // The last fit of the first fold, near the one wanted, starts the fit of every point.
  const int fits = search.evaluations * static_cast<int>(search.folds.size());
  return {balance * std::pow(10.0, t), std::move(search.folds.front().x), fits};
}

}  // namespace interpatch::detail::scattered
