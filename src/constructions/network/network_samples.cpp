// Samples of a network's curves: those the crossing search starts from, and the
// parameters at which a curve is checked against the surface.
#include <algorithm>

#include "base/text.hpp"
#include "constructions/network/network_curves.hpp"

namespace interpatch::detail {

namespace {

// The distinct knots of c over its domain, increasing, front and back included.
std::vector<double> breaks(const KnotVector& k) {
  std::vector<double> b{k.front()};
  for (double x : k.values())
    if (x > b.back() && x <= k.back()) b.push_back(x);
  if (b.back() != k.back()) b.push_back(k.back());
  return b;
}

}  // namespace

void CurveSamples::make() const {
  const std::vector<double> b = breaks(c_->knots());
  constexpr int per_span = 8;
  for (std::size_t i = 0; i + 1 < b.size(); ++i)
    for (int k = 0; k < per_span; ++k) t_.push_back(b[i] + (b[i + 1] - b[i]) * k / per_span);
  t_.push_back(b.back());
  p_.reserve(t_.size());
  for (double t : t_) p_.push_back(c_->point(t));
  constexpr std::size_t chunk = 32;
  for (std::size_t first = 0; first < p_.size(); first += chunk) {
    Chunk ch{first, std::min(first + chunk, p_.size()) - 1, p_[first], p_[first]};
    for (std::size_t i = first; i <= ch.last; ++i)
      for (int k = 0; k < 3; ++k) {
        ch.lo[k] = std::min(ch.lo[k], p_[i][k]);
        ch.hi[k] = std::max(ch.hi[k], p_[i][k]);
      }
    chunks_.push_back(ch);
  }
}

const std::vector<Vec3>& CurveSamples::points() const {
  if (p_.empty()) make();
  return p_;
}
const std::vector<double>& CurveSamples::params() const {
  if (p_.empty()) make();
  return t_;
}
const std::vector<CurveSamples::Chunk>& CurveSamples::chunks() const {
  if (p_.empty()) make();
  return chunks_;
}

std::vector<double> check_params(const KnotVector& k) {
  const std::vector<double> b = breaks(k);
  std::vector<double> t;
  t.reserve(4 * b.size());
  for (std::size_t i = 0; i + 1 < b.size(); ++i)
    for (int q = 0; q < 4; ++q) t.push_back(b[i] + (b[i + 1] - b[i]) * q / 4);
  t.push_back(b.back());
  return t;
}

std::vector<Vec3> points_at(const BSplineCurve& c, std::span<const double> ts) {
  std::vector<Vec3> out(ts.size());
  const KnotVector& k = c.knots();
  if (c.rational() || k.periodic()) {
    for (std::size_t i = 0; i < ts.size(); ++i) out[i] = c.point(ts[i]);
    return out;
  }
  const int p = k.degree(), last = k.count() - 1;
  const auto& cp = c.control_points();
  int s = -1;
  double N[max_degree + 1];
  for (std::size_t i = 0; i < ts.size(); ++i) {
    const double t = ts[i];
    if (!(t >= k.front() && t <= k.back())) {  // the slack and the errors of point()
      out[i] = c.point(t);
      s = -1;
      continue;
    }
    // find_span's span: k[s] <= t < k[s + 1], the last one for t = back().
    if (s < 0 || t < k[static_cast<std::size_t>(s)]) s = k.find_span(t);
    while (s < last && t >= k[static_cast<std::size_t>(s) + 1]) ++s;
    k.basis(s, t, N);
    Vec3 d{};
    for (int j = 0; j <= p; ++j) d += N[j] * cp[static_cast<std::size_t>(s - p + j)];
    out[i] = d;
  }
  return out;
}

}  // namespace interpatch::detail
