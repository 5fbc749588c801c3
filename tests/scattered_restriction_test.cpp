// The coarse nets of a scattered fit's multigrid (hierarchy, Net::coarser) and their
// data terms restricted from the finest one's (restrict_down, restrict_system in
// src/constructions/scattered/scattered_multigrid.hpp) rather than assembled from the
// points: the knots nest on every net, also below an odd count of spans; the
// refinement P against the basis functions evaluated by the knot vectors themselves;
// Pᵀ D P against the product of dense matrices built here, and against the coarse net's
// own data term summed over the points.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>

#include "constructions/scattered/scattered_fit.hpp"
#include "constructions/scattered/scattered_multigrid.hpp"

namespace interpatch {
namespace {

using namespace detail::scattered;

struct Points {
  std::vector<std::array<double, 2>> site;
  std::vector<double> weight, value;
};

Points random_points(std::size_t n, int cols, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0, 1);
  Points p;
  for (std::size_t k = 0; k < n; ++k) {
    const std::array<double, 2> s{U(g), 0.7 * U(g)};
    if (std::hypot(s[0] - 0.3, s[1] - 0.4) < 0.12) continue;  // a void: rows held by the fairness alone
    p.site.push_back(s);
    p.weight.push_back(U(g) < 0.05 ? 0.0 : 0.2 + U(g));
    for (int c = 0; c < cols; ++c) p.value.push_back(std::sin(7 * s[0]) * std::cos(5 * s[1]) + 0.1 * c + 0.01 * (U(g) - 0.5));
  }
  return p;
}

System data_term(const Net& n, const Points& p, int cols) {
  const int h = std::max(n.p, 2);
  System sys{NetMatrix(n.nu, n.nv, h, std::max(n.q, 2)), std::vector<double>(n.size() * static_cast<std::size_t>(cols), 0.0), cols};
  add_data_term(n, Samples{p.site, p.weight, p.value, cols}, sys);
  return sys;
}

// Row-major dense n × m.
using Dense = std::vector<std::vector<double>>;

// P (fine × coarse) of two one-direction refinements: P[(i, j)][(a, b)] = Pu[i][a] Pv[j][b].
Dense prolongation(const Refinement& ru, const Refinement& rv) {
  const auto one = [](const Refinement& r) {
    Dense m(static_cast<std::size_t>(r.fine), std::vector<double>(static_cast<std::size_t>(r.coarse), 0.0));
    const std::size_t w = static_cast<std::size_t>(r.p + 1);
    for (std::size_t i = 0; i < m.size(); ++i)
      for (std::size_t e = 0; e < w; ++e) m[i][static_cast<std::size_t>(r.first[i]) + e] += r.weight[i * w + e];
    return m;
  };
  const Dense pu = one(ru), pv = one(rv);
  Dense p(pu.size() * pv.size(), std::vector<double>(pu[0].size() * pv[0].size(), 0.0));
  for (std::size_t i = 0; i < pu.size(); ++i)
    for (std::size_t j = 0; j < pv.size(); ++j)
      for (std::size_t a = 0; a < pu[0].size(); ++a)
        for (std::size_t b = 0; b < pv[0].size(); ++b) p[i * pv.size() + j][a * pv[0].size() + b] = pu[i][a] * pv[j][b];
  return p;
}

// The matrix's entries, both halves, as a dense one.
Dense dense(const NetMatrix& a) {
  const std::size_t n = a.rows();
  Dense d(n, std::vector<double>(n, 0.0));
  for (std::size_t r = 0; r < n; ++r) {
    const int i = static_cast<int>(r) / a.nv(), j = static_cast<int>(r) % a.nv();
    for (int di = -a.hu(); di <= a.hu(); ++di)
      for (int dj = -a.hv(); dj <= a.hv(); ++dj)
        if (i + di >= 0 && i + di < a.nu() && j + dj >= 0 && j + dj < a.nv())
          d[r][static_cast<std::size_t>((i + di) * a.nv() + j + dj)] = a.entry(r, di, dj);
  }
  return d;
}

// Every net below a fine one of any count of spans: its knots are knots of the next
// finer net's (nests), each direction's spans halved (rounded up) while above 4, the
// ends kept, and its spans within a factor 2.05 of each other (the multigrid's nets
// stay about uniform; 2.016 is the worst up to 600 spans, from 553 down to 5); uniform
// again, to the bit, below an even count of uniform spans.
TEST(ScatteredRestriction, CoarserNetsNestAndStayAboutUniform) {
  for (int spans = 1; spans <= 600; ++spans) {
    std::vector<Net> nets = hierarchy(Net(3, 2, spans + 3, 7, {2, 1}), 16);
    for (std::size_t l = 0; l + 1 < nets.size(); ++l) {
      const Net &coarse = nets[l], &fine = nets[l + 1];
      const int fs = fine.nu - 3, cs = coarse.nu - 3;
      ASSERT_TRUE(nests(coarse.ku, fine.ku) && nests(coarse.kv, fine.kv)) << spans << " spans, level " << l;
      ASSERT_EQ(cs, fs > 4 ? (fs + 1) / 2 : fs) << spans << " spans, level " << l;
      ASSERT_EQ(coarse.ku[0], 0.0);
      ASSERT_EQ(coarse.ku[static_cast<std::size_t>(coarse.nu)], 2.0);
      double lo = 1e300, hi = 0;
      for (int i = 3; i < coarse.nu; ++i) {
        const double h = coarse.ku[static_cast<std::size_t>(i + 1)] - coarse.ku[static_cast<std::size_t>(i)];
        lo = std::min(lo, h), hi = std::max(hi, h);
      }
      ASSERT_LE(hi, 2.05 * lo) << spans << " spans, level " << l;
      if (fs % 2 == 0 && fine.ku.values() == KnotVector::uniform(3, fine.nu, 0, 2).values()) {
        EXPECT_EQ(coarse.ku.values(), KnotVector::uniform(3, coarse.nu, 0, 2).values()) << spans << " spans, level " << l;
      }
    }
  }
}

// The refinement between nets of the hierarchy below 25 × 19 spans (odd counts, so
// that the nets below are not uniform), from each to the next finer and from each to
// the finest (several knots inserted in a span, as the coarsest net's term is restricted
// straight from the finest): each coarse B-spline is the sum of the fine ones with P's
// weights, both evaluated by KnotVector::basis at random parameters, to 1e-13 (sums of a
// few dozen products of numbers at most 1).
TEST(ScatteredRestriction, RefinementWeightsSumTheFineBasisToTheCoarse) {
  std::mt19937_64 g(5);
  std::uniform_real_distribution<double> U(0, 1);
  for (const int degree : {1, 2, 3}) {
    const std::vector<Net> nets = hierarchy(Net(degree, degree, 25 + degree, 19 + degree, {1, 0.7}), 16);
    ASSERT_GE(nets.size(), 3u);
    for (std::size_t l = 0; l + 1 < nets.size(); ++l)
      for (const std::size_t to : {l + 1, nets.size() - 1})
        for (const bool along_u : {true, false}) {
          const KnotVector& c = along_u ? nets[l].ku : nets[l].kv;
          const KnotVector& f = along_u ? nets[to].ku : nets[to].kv;
          const Refinement r = refinement(c, f);
          const double end = f[static_cast<std::size_t>(f.count())];
          for (int trial = 0; trial < 200; ++trial) {
            const double t = trial == 0 ? 0.0 : trial == 1 ? end : end * U(g);
            std::vector<double> coarse(static_cast<std::size_t>(c.count()), 0.0), fine(static_cast<std::size_t>(f.count()), 0.0);
            double nb[max_degree + 1];
            const int sc = c.find_span(t), sf = f.find_span(t);
            c.basis(sc, t, nb);
            for (int e = 0; e <= degree; ++e) coarse[static_cast<std::size_t>(sc - degree + e)] = nb[e];
            f.basis(sf, t, nb);
            for (int e = 0; e <= degree; ++e) fine[static_cast<std::size_t>(sf - degree + e)] = nb[e];
            std::vector<double> summed(coarse.size(), 0.0);
            const std::size_t w = static_cast<std::size_t>(degree + 1);
            for (std::size_t i = 0; i < fine.size(); ++i)
              for (std::size_t e = 0; e < w; ++e) summed[static_cast<std::size_t>(r.first[i]) + e] += fine[i] * r.weight[i * w + e];
            for (std::size_t a = 0; a < coarse.size(); ++a)
              ASSERT_NEAR(summed[a], coarse[a], 1e-13) << "degree " << degree << ", level " << l << " to " << to << ", t " << t << ", function " << a;
          }
        }
  }
}

// Pᵀ D P and Pᵀ b from restrict_down, chained over the hierarchy below 25 × 19 spans
// (nets not uniform below the odd counts), against the dense products built here, each
// net's from the next finer one's, and against each net's own data term summed over the
// points; and the coarsest net's straight from the finest, against its own: to 1e-12
// of the largest entry (sums of some hundred products each, in another order).
TEST(ScatteredRestriction, RestrictedTermsAreTheCoarseNetsOwn) {
  for (const int degree : {2, 3})
    for (const int cols : {1, 3}) {
      const Points pts = random_points(4000, cols, 70 + static_cast<std::uint64_t>(degree * 10 + cols));
      const std::vector<Net> nets = hierarchy(Net(degree, degree, 25 + degree, 19 + degree, {1, 0.7}), 40);
      const std::size_t levels = nets.size() - 1;
      ASSERT_GE(levels, 3u);
      const System top = data_term(nets.back(), pts, cols);
      const std::vector<System> below = restrict_down(top, nets.back(), std::span<const Net>(nets).first(levels));
      ASSERT_EQ(below.size(), levels);
      for (std::size_t l = 0; l < levels; ++l) {
        const System& fine = l + 1 == levels ? top : below[l + 1];
        const Dense a = dense(fine.a);
        const Dense p = prolongation(refinement(nets[l].ku, nets[l + 1].ku), refinement(nets[l].kv, nets[l + 1].kv));
        const std::size_t nf = p.size(), nc = p[0].size();
        Dense ap(nf, std::vector<double>(nc, 0.0));
        for (std::size_t r = 0; r < nf; ++r)
          for (std::size_t k = 0; k < nf; ++k)
            if (a[r][k] != 0)
              for (std::size_t c = 0; c < nc; ++c) ap[r][c] += a[r][k] * p[k][c];
        const System own_term = data_term(nets[l], pts, cols);
        const Dense got = dense(below[l].a), own = dense(own_term.a);
        double size = 0;
        for (std::size_t r = 0; r < nc; ++r) size = std::max(size, std::abs(own[r][r]));
        for (std::size_t r = 0; r < nc; ++r)
          for (std::size_t c = 0; c < nc; ++c) {
            double want = 0;
            for (std::size_t k = 0; k < nf; ++k) want += p[k][r] * ap[k][c];
            ASSERT_NEAR(got[r][c], own[r][c], 1e-12 * size) << "degree " << degree << ", level " << l << ", (" << r << ", " << c << ")";
            ASSERT_NEAR(got[r][c], want, 1e-12 * size) << "degree " << degree << ", level " << l << ", (" << r << ", " << c << ")";
          }
        double rhs_size = 0;
        for (const double b : own_term.rhs) rhs_size = std::max(rhs_size, std::abs(b));
        for (std::size_t r = 0; r < nc; ++r)
          for (int m = 0; m < cols; ++m) {
            double want = 0;
            for (std::size_t k = 0; k < nf; ++k) want += p[k][r] * fine.rhs[k * static_cast<std::size_t>(cols) + static_cast<std::size_t>(m)];
            const std::size_t at = r * static_cast<std::size_t>(cols) + static_cast<std::size_t>(m);
            ASSERT_NEAR(below[l].rhs[at], want, 1e-12 * rhs_size) << "degree " << degree << ", level " << l;
            ASSERT_NEAR(below[l].rhs[at], own_term.rhs[at], 1e-12 * rhs_size) << "degree " << degree << ", level " << l;
          }
      }
      // The coarsest net's term straight from the finest's, as a fit that keeps no net
      // between makes it.
      const System direct = restrict_between(top, nets.back(), nets[0]);
      const System own_term = data_term(nets[0], pts, cols);
      const Dense got = dense(direct.a), own = dense(own_term.a);
      double size = 0, rhs_size = 0;
      for (std::size_t r = 0; r < own.size(); ++r) size = std::max(size, std::abs(own[r][r]));
      for (const double b : own_term.rhs) rhs_size = std::max(rhs_size, std::abs(b));
      for (std::size_t r = 0; r < own.size(); ++r)
        for (std::size_t c = 0; c < own.size(); ++c)
          ASSERT_NEAR(got[r][c], own[r][c], 1e-12 * size) << "degree " << degree << ", straight to the coarsest, (" << r << ", " << c << ")";
      for (std::size_t k = 0; k < own_term.rhs.size(); ++k)
        ASSERT_NEAR(direct.rhs[k], own_term.rhs[k], 1e-12 * rhs_size) << "degree " << degree << ", straight to the coarsest";
    }
}

}  // namespace
}  // namespace interpatch
