#include "interpatch/knot_vector.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <vector>

#include "interpatch/bspline_curve.hpp"

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

}  // namespace
}  // namespace interpatch
