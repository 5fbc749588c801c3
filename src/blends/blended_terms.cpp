// The terms of blended surfaces and volumes (blended_terms.hpp): scalar functions,
// and the row kernel of the exact conversions.
#include <algorithm>
#include <cstring>

#include "base/kernel.hpp"
#include "blends/blended_terms.hpp"

namespace interpatch::detail {

BSplineCurve scalar(KnotVector knots, const std::vector<double>& coefficients) {
  std::vector<Vec3> cp(coefficients.size());
  for (std::size_t i = 0; i < cp.size(); ++i) cp[i] = {coefficients[i], 0, 0};
  return BSplineCurve(std::move(knots), std::move(cp));
}

void Scalar::eval(double t, double out[3]) const {
  if (spline) {
    Vec3 d[3];
    spline->derivatives(t, 2, d);
    for (int k = 0; k < 3; ++k) out[k] = d[k].x;
  } else {
    for (int k = 0; k < 3; ++k) out[k] = fn(t, k);
  }
}

Scalar one_minus(const Scalar& f) {
  if (!f.spline) {
    auto fn = f.fn;
    return Scalar(std::function<double(double, int)>([fn](double t, int k) { return (k == 0 ? 1.0 : 0.0) - fn(t, k); }));
  }
  std::vector<Vec3> cp = f.spline->control_points();
  for (auto& x : cp) x = {1.0 - x.x, 0, 0};
  return BSplineCurve(f.spline->knots(), std::move(cp));
}

Scalar scalar(const Blend& f) {
  if (f.is_spline()) return scalar(f.knots(), f.coefficients());
  return Scalar(f.function());
}

std::vector<Scalar> hermite_scalars() {
  const KnotVector k(3, {0, 0, 0, 0, 1, 1, 1, 1});
  return {scalar(k, {1, 1, 0, 0}), scalar(k, {0, 0, 1, 1}), scalar(k, {0, 1.0 / 3, 0, 0}), scalar(k, {0, 0, -1.0 / 3, 0})};
}

BSplineCurve unit(const BSplineCurve& c) {
  return c.domain() == std::pair<double, double>{0.0, 1.0} ? c : c.mapped(0.0, 1.0);
}

INTERPATCH_KERNEL void sum_terms(double* o, std::size_t n, const std::vector<LineTerm>& lines,
                                 const std::vector<PointTerm>& points) {
  std::size_t i = 0;
#if defined(__GNUC__)
  using v4 = double __attribute__((vector_size(32)));
  for (; i + 4 <= n; i += 4) {
    // Twelve doubles, three vectors, each loaded and stored by a memcpy of its own:
    // one of the whole array goes through the stack in halves.
    v4 s0 = {}, s1 = {}, s2 = {}, a0, a1, a2, p0, p1, p2;
    for (const auto& t : lines) {
      const double* a = t.a + 3 * i;
      std::memcpy(&a0, a, sizeof a0);
      std::memcpy(&a1, a + 4, sizeof a1);
      std::memcpy(&a2, a + 8, sizeof a2);
      s0 += t.s * a0;
      s1 += t.s * a1;
      s2 += t.s * a2;
    }
    for (const auto& t : points) {
      const double* g = t.g + 3 * i;
      std::memcpy(&a0, g, sizeof a0);
      std::memcpy(&a1, g + 4, sizeof a1);
      std::memcpy(&a2, g + 8, sizeof a2);
      std::memcpy(&p0, t.p4, sizeof p0);
      std::memcpy(&p1, t.p4 + 4, sizeof p1);
      std::memcpy(&p2, t.p4 + 8, sizeof p2);
      s0 += a0 * p0;
      s1 += a1 * p1;
      s2 += a2 * p2;
    }
    std::memcpy(o + 3 * i, &s0, sizeof s0);
    std::memcpy(o + 3 * i + 4, &s1, sizeof s1);
    std::memcpy(o + 3 * i + 8, &s2, sizeof s2);
  }
#endif
  for (; i < n; ++i) {  // the same operations, one point at a time
    double acc[3] = {};
    for (const auto& t : lines)
      for (std::size_t c = 0; c < 3; ++c) acc[c] += t.s * t.a[3 * i + c];
    for (const auto& t : points)
      for (std::size_t c = 0; c < 3; ++c) acc[c] += t.g[3 * i + c] * t.p4[c];
    for (std::size_t c = 0; c < 3; ++c) o[3 * i + c] = acc[c];
  }
}

Coefficients coefficients(const BSplineCurve& f) {
  const auto& cp = f.control_points();
  Coefficients r;
  r.c.resize(3 * cp.size());
  for (std::size_t i = 0; i < cp.size(); ++i) r.c[3 * i] = r.c[3 * i + 1] = r.c[3 * i + 2] = cp[i].x;
  const auto nz = [](const Vec3& p) { return p.x != 0.0; };
  const auto first = std::find_if(cp.begin(), cp.end(), nz);
  if (first == cp.end()) return r;
  r.lo = static_cast<std::size_t>(first - cp.begin());
  r.hi = cp.size() - static_cast<std::size_t>(std::find_if(cp.rbegin(), cp.rend(), nz) - cp.rbegin());
  return r;
}

}  // namespace interpatch::detail
