// The promise harness for closest points: random B-spline surfaces (degrees 1 to 5,
// polynomial and rational, open and closed, bent hard or gently, in hostile frames),
// queries near them, far from them and on them. The oracle is the harness's own
// Cox–de Boor (Tensor::eval) on a dense grid, refined by a golden-section walk along
// the grid's best row and column, independent of the projection code and of the
// library's evaluation: no answer may be farther than the oracle's nearest point by
// more than the promised 1e-10 of the diagonal (plus the rounding of the frame), and
// each answer must be the surface's own point at its parameters.

#include <gtest/gtest.h>

#include "interpatch/projection.hpp"
#include "promise_harness.hpp"

namespace interpatch::promise {
namespace {

constexpr std::size_t kCases = 100;

struct Case {
  Tensor t;
  std::vector<Vec3> queries;
};

Case make_case(std::mt19937_64& g) {
  Case c;
  const Frame f = random_frame(g);
  int p[2] = {pick(g, 1, 5), pick(g, 1, 5)};
  bool closed[2] = {chance(g, 0.2), false};
  std::size_t n[2];
  for (int a = 0; a < 2; ++a) n[a] = static_cast<std::size_t>(pick(g, p[a] + 1 + (closed[a] ? p[a] : 0), p[a] + 9));
  // Gently bent most of the time, wildly bumpy now and then: many local minima.
  c.t = random_tensor(g, f, 2, p, n, closed, chance(g, 0.3) ? 0.6 : 0.15);
  if (chance(g, 0.3)) {
    c.t.w.resize(c.t.cp.size());
    for (double& w : c.t.w) w = uni(g, 0.3, 3);
  }
  const Box b = box_of(c.t);
  const Vec3 mid = (b.lo + b.hi) * 0.5;
  const double d = b.diagonal();
  for (int k = 0; k < 24; ++k) {
    Vec3 q;
    const int where = pick(g, 0, 2);
    if (where == 0) {  // in and around the box
      q = mid + Vec3{uni(g, -0.7, 0.7), uni(g, -0.7, 0.7), uni(g, -0.7, 0.7)} * d;
    } else if (where == 1) {  // far away
      q = mid + Vec3{uni(g, -1, 1), uni(g, -1, 1), uni(g, -1, 1)} * (5 * d);
    } else {  // on the surface, or just off it
      const auto [u0, u1] = c.t.domain(0);
      const auto [v0, v1] = c.t.domain(1);
      q = c.t.eval(uni(g, u0, u1), uni(g, v0, v1)).s + Vec3{uni(g, -1, 1), uni(g, -1, 1), uni(g, -1, 1)} * (1e-3 * d);
    }
    c.queries.push_back(q);
  }
  return c;
}

// The oracle's distance: the nearest of a 101 × 101 grid of the tensor's own points,
// then golden-section walks along u and v from it, a few rounds (every value taken is
// a true distance to a point of the surface, so the oracle never undercuts the truth).
double oracle(const Tensor& t, const Vec3& q) {
  const auto [u0, u1] = t.domain(0);
  const auto [v0, v1] = t.domain(1);
  const int m = 101;
  double bu = u0, bv = v0, best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = u0 + (u1 - u0) * i / (m - 1), v = v0 + (v1 - v0) * j / (m - 1);
      const double d = distance(t.eval(u, v).s, q);
      if (d < best) best = d, bu = u, bv = v;
    }
  const auto walk = [&](bool along_u) {
    const double h = (along_u ? u1 - u0 : v1 - v0) / (m - 1);
    double a = std::max(along_u ? u0 : v0, (along_u ? bu : bv) - h), b = std::min(along_u ? u1 : v1, (along_u ? bu : bv) + h);
    const auto f = [&](double x) { return along_u ? distance(t.eval(x, bv).s, q) : distance(t.eval(bu, x).s, q); };
    const double r = 0.5 * (std::sqrt(5.0) - 1);
    for (int it = 0; it < 60; ++it) {
      const double x1 = b - r * (b - a), x2 = a + r * (b - a);
      if (f(x1) < f(x2)) b = x2; else a = x1;
    }
    const double x = 0.5 * (a + b), fx = f(x);
    if (fx < best) best = fx, (along_u ? bu : bv) = x;
  };
  for (int round = 0; round < 3; ++round) walk(true), walk(false);
  return best;
}

TEST(PromiseProjection, NoAnswerFartherThanTheDenseOracle) {
  const std::size_t cases = case_count(kCases);
  const auto replay = replay_case();
  for (std::size_t index = 0; index < cases; ++index) {
    if (replay && *replay != index) continue;
    std::mt19937_64 g = case_rng(0x9e0c7d2b1a3f4e55ULL, index);
    const Case c = make_case(g);
    io::Construction built = io::build(surface_spec(c.t));
    const auto& s = std::get<BSplineSurface>(*built.exact);
    const SurfaceProjector on(s);
    std::vector<SurfacePoint> got(c.queries.size());
    on.closest(c.queries, got);
    const Box b = box_of(c.t);
    // The promise, plus the rounding of coordinates far from the origin.
    const double allowed = 1e-10 * b.diagonal() + rounding(b, 64);
    for (std::size_t k = 0; k < c.queries.size(); ++k) {
      const double want = oracle(c.t, c.queries[k]);
      ASSERT_EQ(got[k].point, s.point(got[k].u, got[k].v)) << "case " << index << " query " << k;
      ASSERT_LE(got[k].distance, want + allowed)
          << "case " << index << " (INTERPATCH_PROMISE_REPLAY=" << index << ") query " << k << ": degree " << c.t.p[0]
          << "x" << c.t.p[1] << (c.t.w.empty() ? "" : " rational") << (c.t.periodic[0] ? " closed" : "") << ", "
          << got[k].distance - want << " beyond the oracle's " << want;
    }
  }
}

}  // namespace
}  // namespace interpatch::promise
