// The coarse nets of a scattered fit's multigrid restricted from the finest one's data
// term (restrict_down, restrict_system in src/constructions/scattered/scattered_multigrid.hpp)
// rather than assembled from the points, where the knots nest: Pᵀ D P against the
// product of dense matrices built here from the refinement's weights, and against the
// coarse net's own data term; assembled where they do not.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

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

// Pᵀ D P and Pᵀ b from restrict_down, chained over nets whose knots nest (spans
// halved from even counts, or kept) against the dense products built here, each net's
// from the next finer one's: to 1e-12 of the largest entry (sums of some hundred
// products each, in another order). Where the knots do not nest (halved from an odd
// count) the net's data term is assembled instead: Pᵀ D P would couple coarse
// functions further apart than the matrix reaches.
TEST(ScatteredRestriction, RestrictedWhereTheKnotsNestAssembledElsewhere) {
  for (const int degree : {2, 3})
    for (const int cols : {1, 3}) {
      const Points pts = random_points(4000, cols, 70 + static_cast<std::uint64_t>(degree * 10 + cols));
      // 24 x 18 spans, then 12 x 9 (nested), 6 x 5 (not along v), 3 x 5 (nested: v kept).
      std::vector<Net> nets;
      for (const auto& s : {std::array<int, 2>{3, 5}, {6, 5}, {12, 9}, {24, 18}})
        nets.emplace_back(degree, degree, s[0] + degree, s[1] + degree, std::array<double, 2>{1, 0.7});
      const System top = data_term(nets.back(), pts, cols);
      std::vector<int> assembled;
      const std::vector<System> below = restrict_down(top, nets.back(), std::span<const Net>(nets).first(3), [&](const Net& n) {
        assembled.push_back(n.nv - degree);
        return data_term(n, pts, cols);
      });
      ASSERT_EQ(below.size(), 3u);
      EXPECT_EQ(assembled, std::vector<int>{5});  // 6 x 5 alone
      for (std::size_t l = 0; l < 3; ++l) {
        const System& fine = l == 2 ? top : below[l + 1];
        const Dense a = dense(fine.a);
        const Dense p = prolongation(refinement(nets[l].ku, nets[l + 1].ku), refinement(nets[l].kv, nets[l + 1].kv));
        const std::size_t nf = p.size(), nc = p[0].size();
        const bool nested = nests(nets[l].ku, nets[l + 1].ku) && nests(nets[l].kv, nets[l + 1].kv);
        EXPECT_EQ(nested, l != 1) << "level " << l;
        Dense ap(nf, std::vector<double>(nc, 0.0));
        for (std::size_t r = 0; r < nf; ++r)
          for (std::size_t k = 0; k < nf; ++k)
            if (a[r][k] != 0)
              for (std::size_t c = 0; c < nc; ++c) ap[r][c] += a[r][k] * p[k][c];
        const Dense got = dense(below[l].a), own = dense(data_term(nets[l], pts, cols).a);
        double size = 0, off = 0;
        for (std::size_t r = 0; r < nc; ++r) size = std::max(size, std::abs(own[r][r]));
        for (std::size_t r = 0; r < nc; ++r)
          for (std::size_t c = 0; c < nc; ++c) {
            double want = 0;
            for (std::size_t k = 0; k < nf; ++k) want += p[k][r] * ap[k][c];
            off = std::max(off, std::abs(want - own[r][c]));
            ASSERT_NEAR(got[r][c], own[r][c], 1e-12 * size) << "degree " << degree << ", level " << l << ", (" << r << ", " << c << ")";
            if (nested) {
              ASSERT_NEAR(got[r][c], want, 1e-12 * size) << "degree " << degree << ", level " << l << ", (" << r << ", " << c << ")";
            }
          }
        // Where nothing nests, the product is not the coarse net's own term: assembling
        // it there is what keeps the levels the same functional.
        if (!nested) {
          EXPECT_GT(off, 1e-3 * size) << "level " << l;
        }
        for (std::size_t r = 0; r < nc && nested; ++r)
          for (int m = 0; m < cols; ++m) {
            double want = 0, rhs_size = 0;
            for (std::size_t k = 0; k < nf; ++k) {
              const double b = fine.rhs[k * static_cast<std::size_t>(cols) + static_cast<std::size_t>(m)];
              want += p[k][r] * b;
              rhs_size = std::max(rhs_size, std::abs(b));
            }
            ASSERT_NEAR(below[l].rhs[r * static_cast<std::size_t>(cols) + static_cast<std::size_t>(m)], want, 1e-12 * rhs_size);
          }
      }
    }
}

}  // namespace
}  // namespace interpatch
