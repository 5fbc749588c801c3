#include "interpatch/knot_vector.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/evaluate.hpp"

#include "test_util.hpp"

namespace interpatch {
namespace {

KnotVector random_knots(std::mt19937_64& g, int p, int count) {
  std::vector<double> interior;
  for (int i = 0; i < count - p - 1; ++i) interior.push_back(test::uniform(g, 0.0, 1.0));
  std::sort(interior.begin(), interior.end());
  std::vector<double> u(static_cast<std::size_t>(p + 1), 0.0);
  u.insert(u.end(), interior.begin(), interior.end());
  u.insert(u.end(), static_cast<std::size_t>(p + 1), 1.0);
  return KnotVector(p, u);
}

TEST(KnotVector, PartitionOfUnityAndNonNegativity) {
  auto g = test::rng(1);
  for (int trial = 0; trial < 200; ++trial) {
    const int p = 1 + trial % 7;
    const auto k = random_knots(g, p, p + 1 + trial % 11);
    for (int s = 0; s < 20; ++s) {
      const double t = test::uniform(g, 0.0, 1.0);
      double N[max_degree + 1];
      k.basis(k.find_span(t), t, N);
      double sum = 0;
      for (int j = 0; j <= p; ++j) {
        EXPECT_GE(N[j], -1e-15);  // non-negative up to rounding
        sum += N[j];
      }
      EXPECT_NEAR(sum, 1.0, 1e-14);  // partition of unity: a sum of p+1 terms in [0,1]
    }
  }
}

TEST(KnotVector, DerivativesMatchBasisAndFiniteDifferences) {
  auto g = test::rng(2);
  for (int trial = 0; trial < 100; ++trial) {
    const int p = 1 + trial % 6;
    const auto k = random_knots(g, p, p + 3 + trial % 5);
    const double t = test::uniform(g, 0.05, 0.95);
    const int s = k.find_span(t);
    double d[(max_degree + 1) * (max_degree + 1)];
    k.basis_derivatives(s, t, p + 1, d);
    double N[max_degree + 1];
    k.basis(s, t, N);
    double dsum = 0;
    for (int j = 0; j <= p; ++j) {
      EXPECT_NEAR(d[j], N[j], 1e-15);
      dsum += d[(p + 1) + j];
      EXPECT_EQ(d[(p + 1) * (p + 1) + j], 0.0);  // order p+1 vanishes
    }
    EXPECT_NEAR(dsum, 0.0, 1e-9);  // derivative of the constant 1; scale ~ 1/min span
    // First derivative against a central difference inside the same span.
    const double h = 1e-6 * (k[static_cast<std::size_t>(s) + 1] - k[static_cast<std::size_t>(s)]);
    if (t - h <= k[static_cast<std::size_t>(s)] || t + h >= k[static_cast<std::size_t>(s) + 1]) continue;
    double Np[max_degree + 1], Nm[max_degree + 1];
    k.basis(s, t + h, Np);
    k.basis(s, t - h, Nm);
    for (int j = 0; j <= p; ++j) {
      const double fd = (Np[j] - Nm[j]) / (2 * h);
      EXPECT_NEAR(d[(p + 1) + j], fd, 1e-5 * (1 + std::abs(fd)));  // O(h^2) truncation + rounding/h
    }
  }
}

TEST(KnotVector, FindSpanAtEndsAndKnots) {
  KnotVector k(2, {0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1});
  EXPECT_EQ(k.count(), 6);
  EXPECT_EQ(k.find_span(0.0), 2);
  EXPECT_EQ(k.find_span(0.25), 3);
  EXPECT_EQ(k.find_span(0.5), 5);
  EXPECT_EQ(k.find_span(0.75), 5);
  EXPECT_EQ(k.find_span(1.0), 5);
  EXPECT_EQ(k.multiplicity(0.5), 2);
  EXPECT_EQ(k.continuity(), 0);
  const auto br = k.interior_breaks();
  ASSERT_EQ(br.size(), 2u);
  EXPECT_EQ(br[1], (std::pair<double, int>{0.5, 2}));
}

// find_span's guess from t's place in the domain and its walk to the span agree with a
// scan for the last knot <= t, on uniform knots (where the guess is right), random ones
// (where it walks or searches), repeated knots, clustered ones (the guess far off), and
// periodic vectors, at random parameters, at every knot and next to it, and at the ends.
TEST(KnotVector, FindSpanIsTheLastKnotAtOrBelow) {
  auto g = test::rng(41);
  const auto scan = [](const KnotVector& k, double t) {
    const int p = k.degree(), n = k.count() - 1;
    if (t >= k.back()) return n;
    if (t <= k.front()) return p;
    int s = p;
    while (s < n && k[static_cast<std::size_t>(s) + 1] <= t) ++s;
    return s;
  };
  for (int trial = 0; trial < 300; ++trial) {
    const int p = 1 + trial % 5, count = p + 1 + trial % 40;
    KnotVector k = KnotVector::uniform(p, count, -2.0, 3.0);
    if (trial % 4 == 1) k = random_knots(g, p, count);
    if (trial % 4 == 2 && p >= 2) {  // pairs of equal knots
      std::vector<double> u(static_cast<std::size_t>(p + 1), 0.0);
      for (int i = 0; i < count - p - 1; ++i) u.push_back(static_cast<double>((i + 2) / 2) / (count - p));
      u.insert(u.end(), static_cast<std::size_t>(p + 1), 1.0);
      k = KnotVector(p, u);
    }
    if (trial % 4 == 3) {  // most knots crowded near one end
      std::vector<double> u(static_cast<std::size_t>(p + 1), 0.0);
      for (int i = 0; i < count - p - 1; ++i) u.push_back(std::pow(static_cast<double>(i + 1) / (count - p), 6));
      u.insert(u.end(), static_cast<std::size_t>(p + 1), 1.0);
      k = KnotVector(p, u);
    }
    std::vector<double> ts = {k.front(), k.back(), k.front() - 1, k.back() + 1};
    for (int s = 0; s < 50; ++s) ts.push_back(test::uniform(g, k.front(), k.back()));
    for (const double knot : k.values()) ts.insert(ts.end(), {knot, std::nextafter(knot, -1e9), std::nextafter(knot, 1e9)});
    for (const double t : ts) ASSERT_EQ(k.find_span(t), scan(k, t)) << "degree " << p << ", " << count << " control points, t = " << t;
  }
  const auto periodic = KnotVector::periodic_from(3, {0, 0.1, 0.15, 0.5, 0.9}, 1.0);
  for (int s = 0; s < 1000; ++s) {  // over [front, back)
    const double t = s / 1000.0;
    const int span = periodic.find_span(t);
    EXPECT_LE(periodic[static_cast<std::size_t>(span)], t) << t;
    EXPECT_GT(periodic[static_cast<std::size_t>(span) + 1], t) << t;
  }
}

TEST(KnotVector, UniformAndMapped) {
  const auto k = KnotVector::uniform(3, 7, 0.0, 2.0);
  EXPECT_EQ(k.values(), (std::vector<double>{0, 0, 0, 0, 0.5, 1, 1.5, 2, 2, 2, 2}));
  const auto m = k.mapped(-1.0, 1.0);
  EXPECT_EQ(m.front(), -1.0);
  EXPECT_EQ(m.back(), 1.0);
  EXPECT_DOUBLE_EQ(m[5], 0.0);
  const auto gr = k.greville();
  EXPECT_DOUBLE_EQ(gr[0], 0.0);
  EXPECT_DOUBLE_EQ(gr[3], 1.0);
  EXPECT_DOUBLE_EQ(gr[6], 2.0);
}

TEST(KnotVector, InvalidInput) {
  EXPECT_ERRC(KnotVector(0, {0, 0, 1, 1}), invalid_degree, "degree 0");
  EXPECT_ERRC(KnotVector(3, {0, 0, 0, 1, 1, 1}), invalid_knots, "at least 8 knots");
  EXPECT_ERRC(KnotVector(1, {0, 0, 0.7, 0.5, 1, 1}), non_increasing, "knot 3 = 0.5");
  EXPECT_ERRC(KnotVector(2, {0, 0, 0.1, 0.5, 1, 1, 1}), invalid_knots, "not clamped at the start");
  EXPECT_ERRC(KnotVector(2, {0, 0, 0, 0.5, 1, 1, 2}), invalid_knots, "not clamped at the end");
  EXPECT_ERRC(KnotVector(2, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}), invalid_knots, "multiplicity 3");
  EXPECT_ERRC(KnotVector(1, {0, 0, std::nan(""), 1, 1}), not_finite, "knot 2");
  EXPECT_ERRC(KnotVector(1, {1, 1, 1, 1}), invalid_knots, "empty domain");
  EXPECT_ERRC(KnotVector::uniform(3, 3), too_few_points, "at least 4");
}

TEST(KnotVector, MergedKnotsAreTheKnotsOfCurvesMadeCompatible) {
  auto g = test::rng(31);
  for (int trial = 0; trial < 50; ++trial) {
    // Random degrees and knots, some shared (repeated vectors add nothing), some
    // with a break of multiplicity above 1.
    std::vector<KnotVector> ks;
    const int n = 1 + static_cast<int>(test::uniform(g, 0, 4));
    for (int k = 0; k < n; ++k) {
      const int p = 1 + static_cast<int>(test::uniform(g, 0, 3));
      if (k > 0 && test::uniform(g, 0, 1) < 0.3) {
        ks.push_back(ks.back());
        continue;
      }
      KnotVector kv = random_knots(g, p, p + 1 + static_cast<int>(test::uniform(g, 0, 6)));
      if (test::uniform(g, 0, 1) < 0.3 && p > 1) {
        std::vector<double> u = kv.values();
        u.insert(u.begin() + p + 1, 2, 0.5);  // a break at 0.5 of multiplicity 2 (or more)
        std::sort(u.begin(), u.end());
        kv = KnotVector(p, u);
      }
      ks.push_back(kv);
    }
    std::vector<BSplineCurve> curves;
    for (const KnotVector& kv : ks) {
      std::vector<Vec3> cp(static_cast<std::size_t>(kv.count()));
      for (Vec3& x : cp) x = test::random_point(g);
      curves.emplace_back(kv, cp);
    }
    const KnotVector merged = merged_knots(ks);
    // Counted here on their own: the highest degree, each break with its highest
    // multiplicity once raised to that degree.
    int p = 0;
    for (const KnotVector& kv : ks) p = std::max(p, kv.degree());
    std::map<double, int> want;
    for (const KnotVector& kv : ks)
      for (const auto& [x, m] : kv.interior_breaks()) want[x] = std::max(want[x], m + p - kv.degree());
    EXPECT_EQ(merged.degree(), p) << "trial " << trial;
    const auto got = merged.interior_breaks();
    const std::map<double, int> have(got.begin(), got.end());
    EXPECT_EQ(have, want) << "trial " << trial;
    // Every curve made compatible has exactly these knots, and its shape.
    const auto compatible = make_compatible(curves);
    for (std::size_t k = 0; k < curves.size(); ++k) {
      EXPECT_EQ(compatible[k].knots(), merged) << "trial " << trial << ", curve " << k;
      for (double t : {0.0, 0.13, 0.5, 0.77, 1.0})  // knot insertion and elevation: rounding only
        EXPECT_LT(distance(compatible[k].point(t), curves[k].point(t)), 1e-12) << "trial " << trial;
    }
  }
  EXPECT_ERRC((void)merged_knots({}), too_few_points, "no knot vectors to merge");
}

// The same knot reached by different computations differs by rounding. Curves made
// compatible take it as one knot (their exact form's space stays well conditioned):
// random clamped and periodic vectors whose shared knots are moved by a few ulps
// merge to the vector of the unmoved ones, and every curve keeps its shape.
TEST(KnotVector, KnotsARoundingApartAreOne) {
  auto g = test::rng(32);
  for (int trial = 0; trial < 60; ++trial) {
    const bool periodic = trial % 2 == 1;
    const int p = 2 + static_cast<int>(test::uniform(g, 0, 2));
    const int n = 2 + static_cast<int>(test::uniform(g, 0, 4));
    // A common set of interior knots; each vector holds all of them, some moved by up
    // to 8 units in the last place, and a knot of its own.
    std::vector<double> common;
    for (int k = 1; k < 6; ++k) common.push_back(k / 6.0 + test::uniform(g, -0.02, 0.02));
    std::vector<KnotVector> exact, moved;
    for (int k = 0; k < n; ++k) {
      std::vector<double> a = common, b = common;
      const double own = test::uniform(g, 0.05, 0.95);
      a.push_back(own);
      b.push_back(own);
      for (double& x : b) x += static_cast<double>(static_cast<int>(test::uniform(g, -8, 9))) * std::numeric_limits<double>::epsilon() * 0.5;
      if (periodic) {
        // The seam starts the period; on every other vector a second knot there,
        // which the moved vector has a rounding after it.
        a.push_back(0.0);
        b.push_back(0.0);
        if (k % 2 == 0) {
          a.push_back(0.0);
          b.push_back(4 * std::numeric_limits<double>::epsilon());
        }
      }
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      if (periodic) {
        exact.push_back(KnotVector::periodic_from(p, a, 1.0));
        moved.push_back(KnotVector::periodic_from(p, b, 1.0));
      } else {
        std::vector<double> ua(static_cast<std::size_t>(p) + 1, 0.0), ub = ua;
        ua.insert(ua.end(), a.begin(), a.end());
        ub.insert(ub.end(), b.begin(), b.end());
        ua.insert(ua.end(), static_cast<std::size_t>(p) + 1, 1.0);
        ub.insert(ub.end(), static_cast<std::size_t>(p) + 1, 1.0);
        exact.emplace_back(p, ua);
        moved.emplace_back(p, ub);
      }
    }
    SCOPED_TRACE(testing::Message() << "trial " << trial << (periodic ? " periodic" : " clamped"));
    const KnotVector want = merged_knots(exact), got = merged_knots(snapped_together(moved));
    EXPECT_EQ(got.count(), want.count());
    const auto wb = want.interior_breaks(), gb = got.interior_breaks();
    ASSERT_EQ(gb.size(), wb.size());
    for (std::size_t q = 0; q < wb.size(); ++q) {
      EXPECT_NEAR(gb[q].first, wb[q].first, 16 * std::numeric_limits<double>::epsilon());
      EXPECT_EQ(gb[q].second, wb[q].second);
    }
    // The curves made compatible: one knot vector, each curve's shape to rounding.
    std::vector<BSplineCurve> curves;
    for (const KnotVector& kv : moved) {
      std::vector<Vec3> cp(static_cast<std::size_t>(kv.count()));
      for (Vec3& x : cp) x = test::random_point(g);
      curves.emplace_back(kv, cp);
    }
    const auto compatible = make_compatible(curves);
    for (std::size_t k = 0; k < curves.size(); ++k) {
      EXPECT_EQ(compatible[k].knots(), got) << "curve " << k;
      // Knots moved by 8 ulps move a curve of O(1) control points by about as much
      // times its basis functions' slope (up to (p / h) with spans h > 1/50); 1e-12.
      for (double t : linspace(0, periodic ? 0.999 : 1, 37))
        EXPECT_LT(distance(compatible[k].point(t), curves[k].point(t)), 1e-12) << "curve " << k << " t " << t;
    }
  }
}

}  // namespace
}  // namespace interpatch
