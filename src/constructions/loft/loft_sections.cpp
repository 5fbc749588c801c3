// A loft's sections turned round and restarted: the curve operations, and the choice
// that keeps the surface from twisting.
#include <algorithm>
#include <cmath>
#include <limits>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "constructions/loft/loft_sections.hpp"

namespace interpatch::detail {

namespace {

std::vector<double> reversed_weights(const std::vector<double>& w) { return {w.rbegin(), w.rend()}; }

// t moved by whole periods into [0, 1).
double wrap01(double t) {
  const double r = t - std::floor(t);
  return r < 1.0 ? r : 0.0;
}

// The control points and weights of a periodic curve taken from index `first` on,
// cyclically: point i of the result is point (first + i) mod n.
template <class T>
std::vector<T> rotated(const std::vector<T>& v, std::size_t first) {
  if (v.empty()) return v;
  std::vector<T> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = v[(first + i) % v.size()];
  return out;
}

BSplineCurve restarted_periodic(const BSplineCurve& c, double s) {
  BSplineCurve r = c;
  std::vector<double> k = r.knots().period_knots();
  auto at = std::find(k.begin(), k.end(), s);
  if (at == k.end()) {
    r = c.inserted(s);
    k = r.knots().period_knots();
    at = std::find(k.begin(), k.end(), s);
    if (at == k.end()) fail(errc::internal, "restarting a closed curve: the inserted knot ", s, " is not in its period");
  }
  const auto j = static_cast<std::size_t>(at - k.begin());
  std::vector<double> knots(k.size());
  for (std::size_t i = 0; i < k.size(); ++i) {
    const std::size_t from = (j + i) % k.size();
    knots[i] = from >= j ? k[from] - s : k[from] + 1.0 - s;
  }
  knots.front() = 0.0;
  // Basis function i starts at extended knot i, and the new vector's knot i is the old
  // one's knot i + j: control point i is the old point i + j.
  return BSplineCurve(KnotVector::periodic_from(c.degree(), std::move(knots), 1.0), rotated(r.control_points(), j),
                      rotated(r.weights(), j));
}

BSplineCurve restarted_open(const BSplineCurve& c, double s) {
  const int p = c.degree();
  const int have = c.knots().multiplicity(s);
  const BSplineCurve r = have < p ? c.inserted(s, p - have) : c;
  const std::vector<double>& U = r.knots().values();
  const auto& P = r.control_points();
  const auto& W = r.weights();
  // The last of the p knots at s: the control point at s is the one p before it.
  std::size_t last = 0;
  for (std::size_t i = 0; i < U.size(); ++i)
    if (U[i] == s) last = i;
  const std::size_t at = last - static_cast<std::size_t>(p);
  const auto pz = static_cast<std::size_t>(p);
  // The part [s, 1], then [0, s] one period on, joined at the old ends (multiplicity p).
  std::vector<double> knots(pz + 1, 0.0);
  for (std::size_t i = last + 1; i + pz + 1 < U.size(); ++i) knots.push_back(U[i] - s);
  knots.insert(knots.end(), pz, 1.0 - s);
  for (std::size_t i = pz + 1; i <= last - pz; ++i) knots.push_back(U[i] + 1.0 - s);
  knots.insert(knots.end(), pz + 1, 1.0);
  std::vector<Vec3> cp(P.begin() + static_cast<std::ptrdiff_t>(at), P.end());
  std::vector<double> w;
  if (!W.empty()) w.assign(W.begin() + static_cast<std::ptrdiff_t>(at), W.end());
  // The old ends, within the tolerance of each other, become one point: their midpoint.
  cp.back() = 0.5 * (cp.back() + P.front());
  if (!w.empty()) w.back() = 0.5 * (w.back() + W.front());
  cp.insert(cp.end(), P.begin() + 1, P.begin() + static_cast<std::ptrdiff_t>(at) + 1);
  if (!w.empty()) w.insert(w.end(), W.begin() + 1, W.begin() + static_cast<std::ptrdiff_t>(at) + 1);
  return BSplineCurve(KnotVector(p, std::move(knots)), std::move(cp), std::move(w));
}

// The candidate starts of a closed curve over [0, 1]: its distinct knots in [0, 1),
// and points that cut each span evenly, at least 64 in all. Defined by the knots
// alone, so a curve restarted at one of them, or turned round, has the same
// candidates moved with it.
std::vector<double> candidate_starts(const BSplineCurve& c) {
  std::vector<double> breaks{0.0};
  for (const auto& [x, mult] : c.knots().interior_breaks())
    if (x > 0.0 && x < 1.0) breaks.push_back(x);
  const std::size_t spans = breaks.size();
  const std::size_t cuts = (64 + spans - 1) / spans;
  std::vector<double> out;
  out.reserve(spans * cuts);
  for (std::size_t i = 0; i < spans; ++i) {
    const double a = breaks[i], b = i + 1 < spans ? breaks[i + 1] : 1.0;
    for (std::size_t j = 0; j < cuts; ++j)
      out.push_back(a + (b - a) * static_cast<double>(j) / static_cast<double>(cuts));
  }
  return out;
}

// Points of a curve at t_i, about their centre.
void centred_samples(const BSplineCurve& c, const std::vector<double>& t, std::vector<Vec3>& out) {
  out.resize(t.size());
  Vec3 sum{0, 0, 0};
  for (std::size_t i = 0; i < t.size(); ++i) {
    out[i] = c.point(t[i]);
    sum += out[i];
  }
  const Vec3 centre = sum / static_cast<double>(t.size());
  for (Vec3& p : out) p -= centre;
}

// Σ |(C(t_i + s) − c) − ref_i|² with c the mean of the C(t_i + s) and ref centred: as
// Σ |q_i − ref_i|² − M |mean q|², q_i = C(t_i + s) − `near` (any point near the curve,
// so that nothing cancels far from the origin); one pass, nothing stored.
double twist(const BSplineCurve& c, const std::vector<double>& t, double s, bool closed, const std::vector<Vec3>& ref,
             const Vec3& near) {
  double sum = 0;
  Vec3 mean{0, 0, 0};
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Vec3 q = c.point(closed ? wrap01(t[i] + s) : t[i]) - near;
    sum += dot(q - ref[i], q - ref[i]);
    mean += q;
  }
  mean /= static_cast<double>(t.size());
  return sum - static_cast<double>(t.size()) * dot(mean, mean);
}

std::size_t span_count(const BSplineCurve& c) { return c.knots().interior_breaks().size() + 1; }

}  // namespace

BSplineCurve reversed_curve(const BSplineCurve& c) {
  const KnotVector& k = c.knots();
  const std::vector<double>& u = k.values();
  std::vector<double> m(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) m[i] = 1.0 - u[u.size() - 1 - i];
  if (!c.periodic()) {
    m.front() = 0.0;
    m.back() = 1.0;
    std::vector<Vec3> cp(c.control_points().rbegin(), c.control_points().rend());
    return BSplineCurve(KnotVector(k.degree(), std::move(m)), std::move(cp), reversed_weights(c.weights()));
  }
  // Extended knot i of the mirrored vector is the old knot N + 2p − i, mirrored; basis
  // function i there is the old function N + p − 1 − i: control point (N + p − 1 − i) mod N.
  const std::size_t n = c.control_points().size(), p = static_cast<std::size_t>(k.degree());
  std::vector<Vec3> cp(n);
  std::vector<double> w(c.weights().empty() ? 0 : n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t from = (n + p - 1 - i) % n;
    cp[i] = c.control_points()[from];
    if (!w.empty()) w[i] = c.weights()[from];
  }
  return BSplineCurve(KnotVector::periodic_from_extended(k.degree(), m), std::move(cp), std::move(w));
}

BSplineCurve restarted_curve(const BSplineCurve& c, double s) {
  if (s == 0.0) return c;
  return c.periodic() ? restarted_periodic(c, s) : restarted_open(c, s);
}

Reparametrization section_map(const PreparedSection& s, double lo, double hi) {
  Reparametrization m;
  // Turned: C(1 − t) restarted at the shift, so u = 0 is the section's 1 − shift.
  const double len = hi - lo, from = lo + (s.reversed ? 1.0 - s.shift : s.shift) * len;
  const double to = s.reversed ? from - len : from + len;
  m.at = {0.0, 1.0};
  m.to = {from, to};
  m.slope = {to - from, to - from};
  if (s.closed) {
    m.start = lo;
    m.period = len;
  }
  return m;
}

namespace {

// Points t_i along a section: closed, m of them over [0, 1); open, from 0 to 1.
std::vector<double> sample_params(std::size_t m, bool closed) {
  std::vector<double> t(m);
  for (std::size_t i = 0; i < m; ++i)
    t[i] = closed ? static_cast<double>(i) / static_cast<double>(m) : static_cast<double>(i) / static_cast<double>(m - 1);
  return t;
}

struct Candidate {
  bool reversed;
  double start;
  double sum = 0;
};

// Each candidate's sum against the reference's samples at t, in its own slot: the same
// bits for any thread count.
void score(std::vector<Candidate>& cands, const BSplineCurve& given, const BSplineCurve& turned,
           const std::vector<double>& t, bool closed, const std::vector<Vec3>& ref, const Vec3& near) {
  const std::size_t work = cands.size() * t.size() * 60;
  parallel_for(cands.size(), work >= parallel_min_work, Share::blocks, [&](std::size_t i) {
    Candidate& cd = cands[i];
    cd.sum = twist(cd.reversed ? turned : given, t, cd.start, closed, ref, near);
  });
}

}  // namespace

void align_sections(std::vector<PreparedSection>& sections, bool closed) {
  // Every candidate is scored at 32 points first, and the 8 best again at 128 or more
  // (4 a span of the denser of the two sections): the best start is far ahead of the
  // others at either count, and most of the evaluations are saved.
  constexpr std::size_t coarse = 32, kept = 8;
  std::vector<Vec3> ref, ref_coarse;
  const std::vector<double> tc = sample_params(coarse, closed);
  for (std::size_t k = 1; k < sections.size(); ++k) {
    PreparedSection& s = sections[k];
    const std::size_t m = std::max<std::size_t>({128, 4 * span_count(sections[k - 1].curve), 4 * span_count(s.curve)});
    const std::vector<double> t = sample_params(m, closed);
    centred_samples(sections[k - 1].curve, t, ref);
    centred_samples(sections[k - 1].curve, tc, ref_coarse);
    const BSplineCurve turned = reversed_curve(s.curve);
    Vec3 near{0, 0, 0};
    for (const Vec3& p : s.curve.control_points()) near += p / static_cast<double>(s.curve.control_points().size());
    std::vector<Candidate> cands;
    for (bool rev : {false, true}) {
      const BSplineCurve& c = rev ? turned : s.curve;
      if (!closed) cands.push_back({rev, 0.0});
      else
        for (double x : candidate_starts(c)) cands.push_back({rev, x});
    }
    if (cands.size() > kept) {
      score(cands, s.curve, turned, tc, closed, ref_coarse, near);
      // The kept ones in their order as candidates, so that ties fall the same way.
      std::vector<std::size_t> order(cands.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::partial_sort(order.begin(), order.begin() + kept, order.end(), [&](std::size_t x, std::size_t y) {
        return cands[x].sum < cands[y].sum || (cands[x].sum == cands[y].sum && x < y);
      });
      order.resize(kept);
      std::sort(order.begin(), order.end());
      std::vector<Candidate> best;
      for (std::size_t i : order) best.push_back(cands[i]);
      cands = std::move(best);
    }
    score(cands, s.curve, turned, t, closed, ref, near);
    std::size_t best = 0;
    for (std::size_t i = 1; i < cands.size(); ++i)
      if (cands[i].sum < cands[best].sum) best = i;
    const Candidate& b = cands[best];
    if (b.reversed) {
      s.curve = turned;
      if (s.tangent) s.tangent = reversed_curve(*s.tangent);
      s.reversed = true;
    }
    if (b.start != 0.0) {
      s.curve = restarted_curve(s.curve, b.start);
      if (s.tangent) s.tangent = restarted_curve(*s.tangent, b.start);
      s.shift = b.start;
    }
  }
}

}  // namespace interpatch::detail
