// Multigrid for scattered fits (src/constructions/scattered/scattered_multigrid.hpp)
// and "smoothing": "auto" (scattered_auto.cpp): the refinement between nets exact where
// the knots nest and reproducing lines where they do not, the V-cycle symmetric and
// positive (what conjugate gradients need of a preconditioner), solves equal to the
// factorization, and λ chosen by cross-validation predicting points it never saw
// about as well as the best decade of λ, the same on any thread count and in any order.
// Splines are evaluated by tests/property/promise_harness.hpp's own Cox–de Boor.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <string>

#include "constructions/scattered/scattered_fit.hpp"
#include "constructions/scattered/scattered_multigrid.hpp"
#include "constructions/scattered/scattered_smoother.hpp"
#include "interpatch/approximate.hpp"
#include "interpatch/io/spec.hpp"
#include "property/promise_harness.hpp"
#include "thread_util.hpp"

namespace interpatch {
namespace {

using namespace detail::scattered;
using promise::own_basis;

double spline_at(const KnotVector& k, std::span<const double> c, double t) {
  const promise::Basis b = own_basis(k.values(), k.degree(), t);
  double s = 0;
  for (std::size_t a = 0; a < b.N.size(); ++a) s += b.N[a] * c[static_cast<std::size_t>(b.first) + a];
  return s;
}

std::vector<double> refine(const Refinement& r, std::span<const double> coarse) {
  std::vector<double> fine(static_cast<std::size_t>(r.fine), 0.0);
  const std::size_t w = static_cast<std::size_t>(r.p + 1);
  for (std::size_t i = 0; i < fine.size(); ++i)
    for (std::size_t a = 0; a < w; ++a)
      if (r.weight[i * w + a] != 0) fine[i] += r.weight[i * w + a] * coarse[static_cast<std::size_t>(r.first[i]) + a];
  return fine;
}

// Knot insertion changes no point: the coarse spline and its refinement agree
// everywhere, to rounding (1e-13 of coefficients of size 1, at most p + 1 terms).
TEST(ScatteredMultigrid, RefinementIsExactWhereTheKnotsNest) {
  std::mt19937_64 g(31);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const int p : {1, 2, 3, 5})
    for (const int spans : {1, 4, 9, 40}) {
      const KnotVector c = KnotVector::uniform(p, spans + p, 0, 0.8), f = KnotVector::uniform(p, 2 * spans + p, 0, 0.8);
      const Refinement r = refinement(c, f);
      std::vector<double> coef(static_cast<std::size_t>(c.count()));
      for (double& x : coef) x = U(g);
      const std::vector<double> fine = refine(r, coef);
      for (int k = 0; k <= 200; ++k) {
        const double t = 0.8 * k / 200;
        EXPECT_NEAR(spline_at(c, coef, t), spline_at(f, fine, t), 1e-13) << "p " << p << ", " << spans << " spans, t " << t;
      }
    }
}

// A net's span (find_span's guess from the spacing, then its walk) is the last knot at
// or below t, found by a scan: at every knot, beside each (the next double either way),
// between them, and past both ends; on uniform nets and on the nets below them, whose
// knots are not all evenly spaced.
TEST(ScatteredMultigrid, SpansAreTheLastKnotAtOrBelow) {
  std::mt19937_64 g(40);
  std::uniform_real_distribution<double> U(-0.1, 1.1);
  for (const int degree : {1, 2, 3, 5})
    for (const int count : {degree + 1, degree + 2, 7, 64, 259, 1027})
      for (const double range : {1.0, 0.8, 0.3}) {
       for (const Net& net : hierarchy(Net(degree, degree, count, count, {range, range}), 16)) {
        std::vector<double> ts;
        for (int i = 0; i <= net.nu + degree; ++i) {
          const double k = net.ku[static_cast<std::size_t>(i)];
          ts.insert(ts.end(), {k, std::nextafter(k, -1.0), std::nextafter(k, 2.0)});
        }
        for (int i = 0; i < 200; ++i) ts.push_back(U(g) * range);
        const auto scan = [&](double t) {
          int s = degree;
          while (s + 1 < net.nu && net.ku[static_cast<std::size_t>(s + 1)] <= t) ++s;
          return s;
        };
        for (const double t : ts) ASSERT_EQ(net.span_u(t), scan(t)) << degree << " " << count << " " << range << " t " << t;
       }
      }
}

// On spans whose knots are evenly spaced the net's basis skips the knots' divisions:
// it agrees with the recurrence on the knots (an independent one here) to the knots'
// rounding, on every span of every shape, and on the nets below (not all evenly
// spaced). A knot is rounded by up to an ulp of itself,
// which moves t's place in its span by that over the spacing, about 1e-16 times the
// spans over the range; the basis functions' slopes in that place are below 2 (1e-15
// times the control points bounds it).
TEST(ScatteredMultigrid, TheNetsBasisIsTheKnotsBasis) {
  std::mt19937_64 g(41);
  std::uniform_real_distribution<double> U(0, 1);
  for (const int degree : {1, 2, 3, 4, 7})
    for (const int count : {degree + 1, degree + 3, 2 * degree + 2, 19, 260})
      for (const double range : {1.0, 0.8}) {
       for (const Net& net : hierarchy(Net(degree, degree, count, count, {range, range}), 16))
        for (int k = 0; k < 300; ++k) {
          const double t = k < 2 ? k * range : U(g) * range;
          const int span = net.span_u(t);
          double n[max_degree + 1];
          net.basis_u(span, t, n);
          const promise::Basis b = own_basis(net.ku.values(), degree, t);
          ASSERT_EQ(b.first, span - degree);
          for (int a = 0; a <= degree; ++a)
            EXPECT_NEAR(n[a], b.N[static_cast<std::size_t>(a)], 1e-15 * count) << degree << " " << count << " t " << t;
        }
      }
}

// A coarse net's data term restricted from a finer one's equals the one summed over the
// points, entry by entry, for weights of all sizes (some zero), 1 and 3 columns, and
// degrees whose matrices reach further than the data (degree 1 keeps the fairness's
// reach of 2): to 1e-12 of the largest entry (sums of a few hundred terms of one sign
// for the matrix, reordered).
TEST(ScatteredMultigrid, RestrictedDataTermsEqualTheAssembledOnes) {
  std::mt19937_64 g(42);
  std::uniform_real_distribution<double> U(0, 1);
  for (const int degree : {1, 2, 3})
    for (const int cols : {1, 3})
      for (const std::array<int, 2> spans : {std::array<int, 2>{1, 1}, {3, 5}, {12, 9}}) {
        std::vector<std::array<double, 2>> site(3000);
        std::vector<double> weight(site.size()), value(site.size() * static_cast<std::size_t>(cols));
        for (auto& st : site) st = {U(g), 0.7 * U(g)};
        for (double& w : weight) w = U(g) < 0.1 ? 0.0 : 0.1 + 3 * U(g);
        for (double& v : value) v = U(g) - 0.5;
        const auto system_on = [&](const Net& n) {
          const int h = std::max(degree, 2);
          System sys{NetMatrix(n.nu, n.nv, h, h), std::vector<double>(n.size() * static_cast<std::size_t>(cols), 0.0), cols};
          add_data_term(n, Samples{site, weight, value, cols}, sys);
          return sys;
        };
        const Net coarse(degree, degree, spans[0] + degree, spans[1] + degree, {1, 0.7});
        const Net fine(degree, degree, 2 * spans[0] + degree, 2 * spans[1] + degree, {1, 0.7});
        const System direct = system_on(coarse);
        const System restricted = restrict_system(system_on(fine), {refinement(coarse.ku, fine.ku), refinement(coarse.kv, fine.kv)});
        double size = 0, rhs_size = 0;
        for (std::size_t r = 0; r < coarse.size(); ++r) size = std::max(size, std::abs(direct.a.at(r, 0)));
        for (const double b : direct.rhs) rhs_size = std::max(rhs_size, std::abs(b));
        const int h = direct.a.hu();
        for (std::size_t r = 0; r < coarse.size(); ++r) {
          const int i = static_cast<int>(r) / coarse.nv, j = static_cast<int>(r) % coarse.nv;
          for (int di = -h; di <= h; ++di)
            for (int dj = -h; dj <= h; ++dj) {
              if (i + di < 0 || i + di >= coarse.nu || j + dj < 0 || j + dj >= coarse.nv) continue;
              ASSERT_NEAR(restricted.a.entry(r, di, dj), direct.a.entry(r, di, dj), 1e-12 * size)
                  << "degree " << degree << ", " << spans[0] << " x " << spans[1] << " spans, row " << r << " (" << di << ", " << dj << ")";
            }
        }
        for (std::size_t k = 0; k < direct.rhs.size(); ++k)
          ASSERT_NEAR(restricted.rhs[k], direct.rhs[k], 1e-12 * rhs_size) << "degree " << degree << ", value " << k;
      }
}

// What lets a tolerance skip a net's pass over the points: Σ w |S − z|² from the
// normal equations, Σ w |z|² − 2 xᵀb + xᵀAx − s xᵀFx (A = D + s F), for any x. Checked
// against the sum over the points with an independent evaluation of S, for weights of
// all sizes (some zero) and 1 and 3 columns; and xᵀFx against the assembled F. To
// 1e-11 of the terms' sizes: sums of a few thousand products, reordered.
TEST(ScatteredMultigrid, TheNormalEquationsTellTheSumOfSquares) {
  std::mt19937_64 g(43);
  std::uniform_real_distribution<double> U(0, 1);
  for (const int cols : {1, 3}) {
    const Net n(3, 3, 14, 11, {1, 0.6});
    std::vector<std::array<double, 2>> site(2500);
    std::vector<double> weight(site.size()), value(site.size() * static_cast<std::size_t>(cols));
    for (auto& st : site) st = {U(g), 0.6 * U(g)};
    for (double& w : weight) w = U(g) < 0.1 ? 0.0 : 2 * U(g);
    for (double& v : value) v = U(g) - 0.5;
    const double s = 0.37;
    System sys{NetMatrix(n.nu, n.nv, 3, 3), std::vector<double>(n.size() * static_cast<std::size_t>(cols), 0.0), cols};
    add_data_term(n, Samples{site, weight, value, cols}, sys);
    add_fairness(n, &sys.a, s);
    NetMatrix f(n.nu, n.nv, 3, 3);
    add_fairness(n, &f, 1);
    std::vector<double> x(sys.rhs.size()), ax(x.size()), fx(x.size());
    for (double& v : x) v = U(g) - 0.5;
    sys.a.multiply(x, ax, cols);
    f.multiply(x, fx, cols);
    double zz = 0, xb = 0, xax = 0, xfx = 0, direct = 0;
    for (std::size_t k = 0; k < x.size(); ++k) xb += x[k] * sys.rhs[k], xax += x[k] * ax[k], xfx += x[k] * fx[k];
    for (std::size_t k = 0; k < site.size(); ++k) {
      const promise::Basis bu = own_basis(n.ku.values(), 3, site[k][0]), bv = own_basis(n.kv.values(), 3, site[k][1]);
      for (int m = 0; m < cols; ++m) {
        double at = 0;
        for (std::size_t a = 0; a < 4; ++a)
          for (std::size_t b = 0; b < 4; ++b)
            at += bu.N[a] * bv.N[b] *
                  x[((static_cast<std::size_t>(bu.first) + a) * static_cast<std::size_t>(n.nv) + static_cast<std::size_t>(bv.first) + b) *
                        static_cast<std::size_t>(cols) + static_cast<std::size_t>(m)];
        const double z = value[k * static_cast<std::size_t>(cols) + static_cast<std::size_t>(m)];
        zz += weight[k] * z * z;
        direct += weight[k] * (at - z) * (at - z);
      }
    }
    const double energy = fairness_energy(n, x, cols);
    EXPECT_NEAR(energy, xfx, 1e-11 * xfx) << cols << " columns";
    EXPECT_NEAR(zz - 2 * xb + xax - s * energy, direct, 1e-11 * (zz + 2 * std::abs(xb) + xax + s * xfx)) << cols << " columns";
  }
}

struct Fixture {
  std::vector<Net> nets;
  std::vector<System> systems;
  std::vector<std::array<double, 2>> site;
  std::vector<double> weight, value;
};

// Random points (with a void) on a net of nu × nv, and the systems of the nets below;
// λ below 0: the fill weight of the finest net, what `control_points` fits use.
Fixture fixture(int nu, int nv, std::size_t points, double lambda, int cols, std::uint64_t seed) {
  Fixture f;
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> U(0, 1);
  while (f.site.size() < points) {
    const std::array<double, 2> s{U(g), 0.8 * U(g)};
    if (std::hypot(s[0] - 0.6, s[1] - 0.4) < 0.15) continue;  // a void held by the fairness term alone
    f.site.push_back(s);
  }
  f.weight.assign(points, 1.0);
  f.value.resize(points * static_cast<std::size_t>(cols));
  for (std::size_t k = 0; k < points; ++k)
    for (int c = 0; c < cols; ++c)
      f.value[k * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)] =
          std::sin(7 * f.site[k][0] + c) * std::cos(5 * f.site[k][1]) + 0.05 * (U(g) - 0.5);
  if (lambda < 0) {
    const Net n(3, 3, nu, nv, {1, 0.8});
    System fine{NetMatrix(nu, nv, 3, 3), std::vector<double>(n.size() * static_cast<std::size_t>(cols), 0.0), cols};
    add_data_term(n, Samples{f.site, f.weight, f.value, cols}, fine);
    lambda = fill_lambda(n, fine.a, static_cast<double>(points));
  }
  f.nets = hierarchy(Net(3, 3, nu, nv, {1, 0.8}), 4096);
  for (const Net& n : f.nets) {
    f.systems.push_back(System{NetMatrix(n.nu, n.nv, 3, 3), std::vector<double>(n.size() * static_cast<std::size_t>(cols), 0.0), cols});
    add_data_term(n, Samples{f.site, f.weight, f.value, cols}, f.systems.back());
    add_fairness(n, &f.systems.back().a, static_cast<double>(points) * lambda);
    f.systems.back().a.mirror();
  }
  return f;
}

Multigrid multigrid(const Fixture& f, int cols) {
  Multigrid mg(f.nets.front(), f.nets.back(), &f.systems.front().a, &f.systems.back().a, cols);
  EXPECT_TRUE(mg.factor());
  return mg;
}

// Conjugate gradients need a symmetric positive definite preconditioner: yᵀ M r = rᵀ M y
// (to rounding of the cycle's sums, 1e-12 of the products) and rᵀ M r > 0.
TEST(ScatteredMultigrid, TheCycleIsSymmetricAndPositive) {
  const Fixture f = fixture(150, 120, 40000, 1e-7, 1, 32);
  ASSERT_GE(f.nets.size(), 3u);
  Multigrid mg = multigrid(f, 1);
  std::mt19937_64 g(33);
  std::normal_distribution<double> N(0, 1);
  const std::size_t n = f.nets.back().size();
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<double> r(n), y(n), mr(n), my(n);
    for (std::size_t i = 0; i < n; ++i) r[i] = N(g), y[i] = N(g);
    mg.apply(r, mr);
    mg.apply(y, my);
    const double a = std::inner_product(y.begin(), y.end(), mr.begin(), 0.0);
    const double b = std::inner_product(r.begin(), r.end(), my.begin(), 0.0);
    const double scale = std::sqrt(std::inner_product(r.begin(), r.end(), mr.begin(), 0.0) * std::inner_product(y.begin(), y.end(), my.begin(), 0.0));
    EXPECT_GT(std::inner_product(r.begin(), r.end(), mr.begin(), 0.0), 0.0);
    EXPECT_NEAR(a, b, 1e-12 * scale) << trial;
  }
}

// Preconditioned by the cycle, conjugate gradients reach the factorization's solution
// (to 1e-9 of its size: a residual of 1e-13 times a condition number below 1e4) in a
// few dozen steps, for one column and for three.
TEST(ScatteredMultigrid, SolvesEqualTheFactorization) {
  for (const int cols : {1, 3}) {
    const Fixture f = fixture(90, 75, 30000, 1e-8, cols, 34 + static_cast<std::uint64_t>(cols));
    Multigrid mg = multigrid(f, cols);
    const System& top = f.systems.back();
    std::vector<double> x(top.rhs.size(), 0.0), direct(top.rhs.size(), 0.0);
    const Solved s = solve_cg(top.a, top.rhs, x, cols, 1e-13, 200,
                              [&mg](std::span<const double> r, std::span<double> z, int) { mg.apply(r, z); });
    EXPECT_LE(s.residual, 1e-13);
    EXPECT_LE(s.iterations, 80) << cols << " columns";
    ASSERT_TRUE(solve_direct(top.a, top.rhs, direct, cols));
    double size = 0, worst = 0;
    for (std::size_t i = 0; i < x.size(); ++i) size = std::max(size, std::abs(direct[i])), worst = std::max(worst, std::abs(x[i] - direct[i]));
    EXPECT_LE(worst, 1e-9 * size) << cols << " columns";
  }
}

// With only the fill weight and about four points a knot cell, the normal equations
// have near-null modes a few control points wide (clusters of points the basis hardly
// tells apart, the edges' B-splines that barely reach a point). Strips solved whole
// keep conjugate gradients to a few dozen steps: 13 on this net, where Gauss–Seidel
// point by point took 244 on the same kind of net.
TEST(ScatteredMultigrid, FourPointsACellWithOnlyTheFillTakeFewSteps) {
  const Fixture f = fixture(100, 100, 36000, -1, 1, 37);
  Multigrid mg = multigrid(f, 1);
  const System& top = f.systems.back();
  std::vector<double> x(top.rhs.size(), 0.0);
  const Solved s = solve_cg(top.a, top.rhs, x, 1, 1e-12, 300, [&mg](std::span<const double> r, std::span<double> z, int) { mg.apply(r, z); });
  EXPECT_LE(s.residual, 1e-12);
  EXPECT_LE(s.iterations, 30);
}

// A strip as wide as the net is the whole net: with four rows (one strip along u, after
// the strips along v) or four columns (one along v, solved first), a sweep from
// zero gives the factorization's solution to the strip factor's single precision: 1e-5
// of its size (6e-8 times the strip's condition, below 100 on this well-filled net;
// 1.3e-6 measured). A second sweep refines it as one step of iterative refinement does:
// 1e-9 (the first's error squared, over the double factorization's rounding).
TEST(ScatteredMultigrid, AStripAsWideAsTheNetSolvesIt) {
  for (const auto& [nu, nv] : {std::array<int, 2>{4, 40}, std::array<int, 2>{40, 4}})
    for (const int cols : {1, 3}) {
      std::mt19937_64 g(static_cast<std::uint64_t>(nu * 10 + cols));
      std::uniform_real_distribution<double> U(0, 1);
      const Net n(3, 3, nu, nv);
      std::vector<std::array<double, 2>> site(3000);
      std::vector<double> weight(site.size(), 1.0), value(site.size() * static_cast<std::size_t>(cols));
      for (auto& st : site) st = {U(g), U(g)};
      for (double& v : value) v = U(g);
      System sys{NetMatrix(nu, nv, 3, 3), std::vector<double>(n.size() * static_cast<std::size_t>(cols), 0.0), cols};
      add_data_term(n, Samples{site, weight, value, cols}, sys);
      add_fairness(n, &sys.a, 1e-6 * static_cast<double>(site.size()));
      sys.a.mirror();
      std::vector<double> x(sys.rhs.size(), 0.0), direct(sys.rhs.size(), 0.0);
      ASSERT_TRUE(solve_direct(sys.a, sys.rhs, direct, cols));
      {
        const StripSmoother smoother(sys.a);
        std::vector<double> work;
        std::fill(x.begin(), x.end(), 0.0);
        const auto off = [&] {
          double size = 0, worst = 0;
          for (std::size_t i = 0; i < x.size(); ++i) size = std::max(size, std::abs(direct[i])), worst = std::max(worst, std::abs(x[i] - direct[i]));
          return worst / size;
        };
        smoother.sweep(sys.a, sys.rhs, x, cols, false, work, true);
        EXPECT_LE(off(), 1e-5) << nu << " x " << nv << ", " << cols << " columns, one sweep";
        smoother.sweep(sys.a, sys.rhs, x, cols, false, work);
        EXPECT_LE(off(), 1e-9) << nu << " x " << nv << ", " << cols << " columns, two sweeps";
      }
    }
}

// A matrix's products equal the sums over its entries (taken one by one, from either
// half) to rounding, 1e-14 of their largest size times 49 terms, for 1 and 3 columns:
// cubic nets from the upper half alone, other reaches from whole rows once mirrored;
// mirroring (or not, for cubics) and going back change no entry. The nets are one band
// of multiply() and several; every band of rows multiply_rows takes, down to one net row
// (thinner than the matrix reaches), writes its rows and no other.
TEST(ScatteredMultigrid, ProductsReadEitherHalfAsTheEntries) {
  std::mt19937_64 g(39);
  std::uniform_real_distribution<double> U(-1, 1);
  for (const auto& [hu, hv] : {std::array<int, 2>{3, 3}, {2, 2}, {3, 2}})
    for (const int cols : {1, 3})
      for (const int nu : {12, 2 * NetMatrix::band_rows + 5}) {
        const int nv = 15;
        NetMatrix m(nu, nv, hu, hv);
        for (std::size_t r = 0; r < m.rows(); ++r)
          for (int di = 0; di <= hu; ++di)
            for (int dj = di == 0 ? 0 : -hv; dj <= hv; ++dj) {
              const int i = static_cast<int>(r) / nv + di, j = static_cast<int>(r) % nv + dj;
              if (i < nu && j >= 0 && j < nv) m.at(r, m.offset(di, dj)) = U(g);
            }
        const auto c = static_cast<std::size_t>(cols);
        std::vector<double> upper, x(m.rows() * c), want(x.size(), 0.0), got(x.size());
        const int width = hv + 1 + hu * (2 * hv + 1);
        for (std::size_t r = 0; r < m.rows(); ++r)
          for (int k = 0; k < width; ++k) upper.push_back(m.at(r, k));
        for (double& v : x) v = U(g);
        // A x from the entries one by one, either half.
        const auto product_of_entries = [&](const NetMatrix& read, NetMatrix::Part part = NetMatrix::Part::whole) {
          std::fill(want.begin(), want.end(), 0.0);
          for (std::size_t r = 0; r < read.rows(); ++r) {
            const int i = static_cast<int>(r) / nv, j = static_cast<int>(r) % nv;
            for (int di = -hu; di <= hu; ++di)
              for (int dj = -hv; dj <= hv; ++dj) {
                if (i + di < 0 || i + di >= nu || j + dj < 0 || j + dj >= nv) continue;
                const std::size_t o = static_cast<std::size_t>((i + di) * nv + j + dj);
                for (std::size_t k = 0; k < c; ++k) want[r * c + k] += read.entry(r, di, dj, part) * x[o * c + k];
              }
          }
        };
        product_of_entries(m);
        const auto same_entries = [&] {
          std::size_t e = 0, moved = 0;
          const NetMatrix& read = m;
          for (std::size_t r = 0; r < m.rows(); ++r)
            for (int k = 0; k < width; ++k) moved += read.at(r, k) != upper[e++];
          return moved;
        };
        for (const char* form : {"as assembled", "mirrored"}) {
          if (std::string(form) == "mirrored") m.mirror();
          m.multiply(x, got, cols);
          for (std::size_t k = 0; k < got.size(); ++k)
            ASSERT_NEAR(got[k], want[k], 1e-14 * 49) << hu << " x " << hv << ", " << cols << " columns, " << form << ", value " << k;
          EXPECT_EQ(same_entries(), 0u) << form;
          const std::size_t per_row = static_cast<std::size_t>(nv) * c;  // values a net row
          for (int i0 = 0; i0 < nu; ++i0)
            for (const int i1 : {i0 + 1, i0 + 2, i0 + 4, i0 + 7, nu}) {
              if (i1 > nu) continue;
              std::fill(got.begin(), got.end(), std::numeric_limits<double>::quiet_NaN());
              m.multiply_rows(i0, i1, x, got, cols);
              for (std::size_t k = 0; k < got.size(); ++k) {
                const bool inside = k >= static_cast<std::size_t>(i0) * per_row && k < static_cast<std::size_t>(i1) * per_row;
                if (inside) ASSERT_NEAR(got[k], want[k], 1e-14 * 49) << hu << " x " << hv << ", rows " << i0 << ".." << i1 << ", value " << k;
                else ASSERT_TRUE(std::isnan(got[k])) << hu << " x " << hv << ", rows " << i0 << ".." << i1 << " wrote value " << k;
              }
            }
        }
        m.unmirror();
        EXPECT_EQ(same_entries(), 0u) << "back to the upper half";
        // Packed (cubic nets only): each entry within 2^-39 of its row's largest, the
        // products those of the entries decoded, and writing goes back to doubles.
        m.pack();
        ASSERT_EQ(m.packed(), hu == 3 && hv == 3);
        if (!m.packed()) continue;
        const NetMatrix& read = m;
        std::vector<double> decoded;
        for (std::size_t r = 0, e = 0; r < m.rows(); ++r, e += static_cast<std::size_t>(width)) {
          double top = 0;
          for (int k = 0; k < width; ++k) top = std::max(top, std::abs(upper[e + static_cast<std::size_t>(k)]));
          for (int k = 0; k < width; ++k) {
            decoded.push_back(read.at(r, k));
            ASSERT_LE(std::abs(decoded.back() - upper[e + static_cast<std::size_t>(k)]), 0x1p-39 * top) << "row " << r << ", entry " << k;
          }
        }
        product_of_entries(read);
        const std::size_t per_row = static_cast<std::size_t>(nv) * c;
        for (int i0 = 0; i0 < nu; ++i0)
          for (const int i1 : {i0 + 1, i0 + 3, nu}) {
            if (i1 > nu) continue;
            std::fill(got.begin(), got.end(), std::numeric_limits<double>::quiet_NaN());
            m.multiply_rows(i0, i1, x, got, cols);
            for (std::size_t k = 0; k < got.size(); ++k) {
              const bool inside = k >= static_cast<std::size_t>(i0) * per_row && k < static_cast<std::size_t>(i1) * per_row;
              if (inside) ASSERT_NEAR(got[k], want[k], 1e-14 * 49) << "packed, rows " << i0 << ".." << i1 << ", value " << k;
              else ASSERT_TRUE(std::isnan(got[k])) << "packed, rows " << i0 << ".." << i1 << " wrote value " << k;
            }
          }
        // The floats alone, what the preconditioner reads: each entry's nearest float.
        for (std::size_t r = 0, e = 0; r < m.rows(); ++r)
          for (int k = 0; k < width; ++k, ++e)
            ASSERT_EQ(read.at(r, k, NetMatrix::Part::floats), static_cast<double>(static_cast<float>(upper[e]))) << "row " << r << ", entry " << k;
        product_of_entries(read, NetMatrix::Part::floats);
        for (int i0 = 0; i0 < nu; i0 += 5) {
          const int i1 = std::min(nu, i0 + 1 + i0 % 7);
          std::fill(got.begin(), got.end(), std::numeric_limits<double>::quiet_NaN());
          m.multiply_rows(i0, i1, x, got, cols, NetMatrix::Part::floats);
          for (std::size_t k = 0; k < got.size(); ++k) {
            const bool inside = k >= static_cast<std::size_t>(i0) * per_row && k < static_cast<std::size_t>(i1) * per_row;
            if (inside) ASSERT_NEAR(got[k], want[k], 1e-14 * 49) << "floats, rows " << i0 << ".." << i1 << ", value " << k;
            else ASSERT_TRUE(std::isnan(got[k])) << "floats, rows " << i0 << ".." << i1 << " wrote value " << k;
          }
        }
        m.at(0, 0) += 0.0;  // a write: back to doubles, those decoded
        EXPECT_FALSE(m.packed());
        for (std::size_t r = 0, e = 0; r < m.rows(); ++r)
          for (int k = 0; k < width; ++k, ++e) ASSERT_EQ(m.at(r, k), decoded[e]) << "row " << r << ", entry " << k;
      }
}

// An entry beyond 2^100 leaves the whole matrix in doubles, the rows packed before it
// (the blocks of 8 192 before its own) back to their values to within the packing's
// precision; the next pack takes it once the entry is back in range.
TEST(ScatteredMultigrid, PackingLeavesHugeEntriesInDoubles) {
  std::mt19937_64 g(40);
  std::uniform_real_distribution<double> U(0.5, 2);
  NetMatrix m(100, 97, 3, 3);  // 9 700 rows: two blocks
  std::vector<double> was;
  for (std::size_t r = 0; r < m.rows(); ++r)
    for (int k = 0; k < 25; ++k) was.push_back(m.at(r, k) = U(g));
  const std::size_t late = m.rows() - 5;
  m.at(late, 3) = 0x1p101;
  m.pack();
  EXPECT_FALSE(m.packed());
  for (std::size_t r = 0, e = 0; r < m.rows(); ++r)
    for (int k = 0; k < 25; ++k, ++e) {
      const double v = m.at(r, k), expected = r == late && k == 3 ? 0x1p101 : was[e];
      ASSERT_LE(std::abs(v - expected), r < late ? 0x1p-38 : 0.0) << "row " << r << ", entry " << k;
    }
  m.at(late, 3) = 1;
  m.pack();
  EXPECT_TRUE(m.packed());
}

// The points present are visited along a Z-curve over the domain (cells of a 1024 ×
// 1024 grid, the bits of their indices interleaved), in the order given within a cell:
// the fit's order equals a stable sort of the points present by that key, made here
// bit by bit, on 1, 2 and 3 threads; missing points and points of weight 0 left out.
TEST(ScatteredMultigrid, PointsAreVisitedAlongAZCurve) {
  std::mt19937_64 g(43);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Vec3> points(60000);
  ScatteredApproximationOptions o;
  o.param = ScatteredParam::xy;
  o.weights.assign(points.size(), 1.0);
  for (std::size_t k = 0; k < points.size(); ++k) {
    points[k] = {3 + 2 * U(g), -1 + U(g) * U(g), U(g)};  // crowded towards y = -1
    if (k % 97 == 5) points[k].z = std::numeric_limits<double>::quiet_NaN();
    if (k % 89 == 7) o.weights[k] = 0;
  }
  for (std::size_t k = 0; k < 500; ++k) points[k] = points[k + 1000];  // whole cells shared
  for (const int threads : {1, 2, 3}) {
    const Sites s = scattered_sites(points, o, 3, 3);
    const Problem pr = test::with_threads(threads, [&] { return frame(points, s, 3, 3, true); });
    std::vector<std::uint32_t> expected;
    std::vector<std::uint32_t> key(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (std::isnan(points[k].z) || o.weights[k] == 0) continue;
      const std::array<double, 2> u = pr.input_unit(k);
      std::uint32_t cell[2];
      for (int a = 0; a < 2; ++a) cell[a] = static_cast<std::uint32_t>(std::clamp(u[a] / pr.range[a] * 1024, 0.0, 1023.0));
      for (int b = 0; b < 10; ++b) key[k] |= ((cell[0] >> b) & 1U) << (2 * b + 1) | ((cell[1] >> b) & 1U) << (2 * b);
      expected.push_back(static_cast<std::uint32_t>(k));
    }
    std::stable_sort(expected.begin(), expected.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
    ASSERT_EQ(pr.order.size(), expected.size()) << threads << " threads";
    EXPECT_TRUE(pr.order == expected) << threads << " threads";
  }
}

// Points are indexed in 32 bits: one more than they reach is refused, by name and count.
TEST(ScatteredMultigrid, MorePointsThan32BitIndicesAreRefused) {
  EXPECT_NO_THROW(require_indexable(std::size_t{4294967295}));
  try {
    require_indexable(std::size_t{4294967296});
    ADD_FAILURE() << "no error";
  } catch (const error& e) {
    EXPECT_EQ(e.code(), errc::too_large);
    EXPECT_STREQ(e.what(), "scattered approximation of 4294967296 points: at most 4294967295 (points are indexed in 32 bits)");
  }
}

// A net's matrix kept with one fairness weight and taken with another is the matrix
// assembled with the other, to rounding (1e-13 of the largest entry: two sums of a
// few dozen terms each), and a net not kept is not there.
TEST(ScatteredMultigrid, KeptMatricesTakeTheNewFairnessWeight) {
  std::mt19937_64 g(38);
  std::uniform_real_distribution<double> U(0, 1);
  const Net n(3, 3, 30, 25), other(3, 3, 25, 30);
  std::vector<std::array<double, 2>> site(4000);
  std::vector<double> weight(site.size(), 1.0), value(site.size());
  for (auto& st : site) st = {U(g), U(g)};
  for (double& v : value) v = U(g);
  const auto assembled = [&](double scaled) {
    System sys{NetMatrix(n.nu, n.nv, 3, 3), std::vector<double>(n.size(), 0.0), 1};
    add_data_term(n, Samples{site, weight, value, 1}, sys);
    add_fairness(n, &sys.a, scaled);
    return std::move(sys.a);
  };
  KeptMatrices kept;
  kept.keep(n, assembled(0.5), 0.5);
  EXPECT_FALSE(kept.take(other, 3.0).has_value());
  const std::optional<NetMatrix> got = kept.take(n, 3.0);
  ASSERT_TRUE(got.has_value());
  const NetMatrix want = assembled(3.0);
  double top = 0, worst = 0;
  for (std::size_t r = 0; r < want.rows(); ++r)
    for (int di = 0; di <= 3; ++di)
      for (int dj = di == 0 ? 0 : -3; dj <= 3; ++dj) {
        const int k = want.offset(di, dj);
        top = std::max(top, std::abs(want.at(r, k)));
        worst = std::max(worst, std::abs(want.at(r, k) - got->at(r, k)));
      }
  EXPECT_LE(worst, 1e-13 * top);
  EXPECT_FALSE(kept.take(n, 3.0).has_value());  // taken out
}

// A smooth field with noise σ = 2 at scattered sites.
double field(double x, double y) { return 40 * std::sin(x / 170) * std::cos(y / 130) + 0.02 * x + 5 * std::sin((x + y) / 90); }

std::vector<Vec3> noisy_survey(std::mt19937_64& g, std::size_t n, double sigma) {
  std::uniform_real_distribution<double> ux(0, 1000), uy(0, 800);
  std::normal_distribution<double> e(0, sigma);
  std::vector<Vec3> q(n);
  for (Vec3& p : q) {
    const double x = ux(g), y = uy(g);
    p = {x, y, field(x, y) + e(g)};
  }
  return q;
}

// RMS of the fit against the noise-free field at sites the fit never saw.
double unseen_rms(const ScatteredApproximation& r, std::mt19937_64& g) {
  const promise::Tensor t = promise::tensor_of(r.surface);
  std::uniform_real_distribution<double> ux(0, 1000), uy(0, 800);
  double sq = 0;
  constexpr int n = 3000;
  for (int k = 0; k < n; ++k) {
    const double x = ux(g), y = uy(g);
    const Vec3 s = t.eval(x, y).s;
    sq += (s.z - field(x, y)) * (s.z - field(x, y));
  }
  return std::sqrt(sq / n);
}

ScatteredApproximationOptions xy_auto() {
  ScatteredApproximationOptions o;
  o.param = ScatteredParam::xy;
  o.auto_smoothing = true;
  return o;
}

// λ chosen by cross-validation predicts the field between the points within 10 % of the
// best of six decades of λ tried afterwards with the truth known (the search's own
// spread: its folds are one sample of the noise), and well inside the noise itself.
TEST(ScatteredMultigrid, AutoSmoothingPredictsUnseenPointsAsTheBestLambda) {
  for (const std::size_t n : {3000u, 30000u}) {
    std::mt19937_64 g(40 + n);
    const auto q = noisy_survey(g, n, 2.0);
    const auto chosen = approximate_scattered(q, xy_auto());
    std::mt19937_64 h(41);
    const double got = unseen_rms(chosen, h);
    double best = std::numeric_limits<double>::infinity();
    for (int t = -6; t <= -1; ++t) {
      ScatteredApproximationOptions o;
      o.param = ScatteredParam::xy;
      o.smoothing = std::pow(10.0, t);
      std::mt19937_64 h2(41);
      best = std::min(best, unseen_rms(approximate_scattered(q, o), h2));
    }
    EXPECT_LE(got, 1.1 * best) << n << " points, λ " << chosen.report.lambda;
    EXPECT_LT(got, 1.0) << n << " points";  // σ = 2: most of the noise is gone
    EXPECT_GT(chosen.report.lambda, 0.0);
  }
}

// The folds follow the points' coordinates, not their order: shuffled, the same λ
// (to the rounding of sums taken in another order) and the same surface.
TEST(ScatteredMultigrid, AutoSmoothingIgnoresTheOrderOfThePoints) {
  std::mt19937_64 g(42);
  auto q = noisy_survey(g, 5000, 2.0);
  const auto a = approximate_scattered(q, xy_auto());
  std::shuffle(q.begin(), q.end(), g);
  const auto b = approximate_scattered(q, xy_auto());
  EXPECT_NEAR(a.report.lambda, b.report.lambda, 1e-6 * a.report.lambda);
  const auto& ca = a.surface.control_points().values();
  const auto& cb = b.surface.control_points().values();
  ASSERT_EQ(ca.size(), cb.size());
  double worst = 0;
  for (std::size_t i = 0; i < ca.size(); ++i) worst = std::max(worst, distance(ca[i], cb[i]));
  EXPECT_LE(worst, 1e-6);  // heights of about 50 m; solves to 1e-12 of the data
}

using test::with_threads;

// Past the factored nets (about 25 000 points, 160 x 130 control points): the search
// and the fit give the same bits on one, two and three threads.
TEST(ScatteredMultigrid, AutoSmoothingGivesTheSameBitsOnAnyThreadCount) {
  std::mt19937_64 g(43);
  const auto q = noisy_survey(g, 26000, 2.0);
  std::vector<ScatteredApproximation> r;
  for (const int threads : {1, 2, 3}) r.push_back(with_threads(threads, [&] { return approximate_scattered(q, xy_auto()); }));
  for (std::size_t t = 1; t < r.size(); ++t) {
    EXPECT_EQ(r[t].report.lambda, r[0].report.lambda);
    const auto& a = r[0].surface.control_points().values();
    const auto& b = r[t].surface.control_points().values();
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3))) << t + 1 << " threads";
  }
}

// The spec: "smoothing": "auto" on scattered points, the chosen λ in the report.
TEST(ScatteredMultigrid, AutoSmoothingFromASpec) {
  std::mt19937_64 g(44);
  nlohmann::json pts = nlohmann::json::array();
  for (const Vec3& p : noisy_survey(g, 800, 2.0)) pts.push_back({p.x, p.y, p.z});
  const nlohmann::json spec = {{"type", "approximate"}, {"param", "xy"}, {"smoothing", "auto"}, {"points", pts}};
  const io::Construction c = io::build(spec);
  EXPECT_EQ(c.parameters.at("smoothing"), "auto");
  EXPECT_GT(c.parameters.at("lambda").get<double>(), 0.0);
}

}  // namespace
}  // namespace interpatch
