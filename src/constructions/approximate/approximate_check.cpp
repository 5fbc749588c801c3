#include "constructions/approximate/approx_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/text.hpp"

namespace interpatch::detail {

namespace {

std::string index_text(std::size_t flat, const std::vector<std::size_t>& shape) {
  std::string at;
  for (std::size_t a = shape.size(); a-- > 0; flat /= shape[a]) at = cat("[", flat % shape[a], "]", at);
  return at;
}

// Parameters as the evaluators take them: a closed direction's wrapped into the
// knots' period (a closing line's parameter is one period on).
std::vector<double> in_domain(const KnotVector& k, const std::vector<double>& t, std::size_t n) {
  std::vector<double> w(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(n));
  for (double& x : w) x = k.periodic() ? k.wrap(x) : std::clamp(x, k.front(), k.back());
  return w;
}

void take(ApproxDistance& e, const Vec3& s, const ApproxData& d, std::size_t i) {
  if (!d.present(i)) return;
  const double dist = distance(s, d.points[i]);
  // A NaN distance (a non-finite value of S) is the worst there is.
  if (!(dist <= e.max)) {
    e.max = std::isnan(dist) ? std::numeric_limits<double>::infinity() : dist;
    e.worst = i;
  }
}

// Rows along the first direction evaluated this many points at a time: the check
// holds a block of values, never the whole grid's.
constexpr std::size_t block_points = std::size_t{1} << 16;

}  // namespace

bool ApproxData::present(std::size_t i) const {
  return is_finite(points[i]) && (weights.empty() || weights[i] > 0);
}

ApproxDistance approx_distance(const BSplineCurve& c, const std::vector<double>& t, const ApproxData& d) {
  ApproxDistance e;
  const std::vector<double> u = in_domain(c.knots(), t, d.shape[0]);
  for (std::size_t i = 0; i < u.size(); ++i) take(e, c.point(u[i]), d, i);
  return e;
}

ApproxDistance approx_distance(const BSplineSurface& s, const std::vector<double>& tu, const std::vector<double>& tv,
                               const ApproxData& d) {
  ApproxDistance e;
  const std::vector<double> u = in_domain(s.knots_u(), tu, d.shape[0]), v = in_domain(s.knots_v(), tv, d.shape[1]);
  const std::size_t rows = std::max<std::size_t>(1, block_points / v.size());
  std::vector<Vec3> out;
  for (std::size_t r0 = 0; r0 < u.size(); r0 += rows) {
    const std::size_t k = std::min(rows, u.size() - r0);
    out.resize(k * v.size());
    s.evaluate_into(std::span<const double>(u).subspan(r0, k), v, out);
    for (std::size_t i = 0; i < out.size(); ++i) take(e, out[i], d, r0 * v.size() + i);
  }
  return e;
}

ApproxDistance approx_distance(const BSplineVolume& s, const std::vector<double>& tu, const std::vector<double>& tv,
                               const std::vector<double>& tw, const ApproxData& d) {
  ApproxDistance e;
  const std::vector<double> u = in_domain(s.knots_u(), tu, d.shape[0]), v = in_domain(s.knots_v(), tv, d.shape[1]),
                            w = in_domain(s.knots_w(), tw, d.shape[2]);
  const std::size_t slab = v.size() * w.size(), rows = std::max<std::size_t>(1, block_points / slab);
  std::vector<Vec3> out;
  for (std::size_t r0 = 0; r0 < u.size(); r0 += rows) {
    const std::size_t n = std::min(rows, u.size() - r0);
    out.resize(n * slab);
    s.evaluate_into(std::span<const double>(u).subspan(r0, n), v, w, out);
    for (std::size_t i = 0; i < out.size(); ++i) take(e, out[i], d, r0 * slab + i);
  }
  return e;
}

std::array<Vec3, 2> approx_box(const ApproxData& d) {
  Vec3 lo{}, hi{};
  bool any = false;
  for (std::size_t i = 0; i < d.points.size(); ++i) {
    if (!d.present(i)) continue;
    const Vec3& q = d.points[i];
    for (int k = 0; k < 3; ++k) {
      lo[k] = any ? std::min(lo[k], q[k]) : q[k];
      hi[k] = any ? std::max(hi[k], q[k]) : q[k];
    }
    any = true;
  }
  return {lo, hi};
}

namespace {

// 3^rank: interpolation of the roughest data (values alternating along a direction)
// puts control points that many diagonals out, the inverse of the cubic collocation
// matrix at even knots having norm 3, once per direction.
double net_factor(std::size_t rank) {
  double factor = 1;
  for (std::size_t a = 0; a < rank; ++a) factor *= 3;
  return factor;
}

// How far p lies outside the box, and how far it may: the diagonals allowed plus the
// rounding of coordinates of the box's magnitude (data all in one point still let the
// control points differ from it by that much).
std::pair<double, double> excess(const Vec3& p, std::size_t rank, const std::array<Vec3, 2>& box) {
  Vec3 out{};
  double magnitude = 0;
  for (int k = 0; k < 3; ++k) {
    out[k] = std::max({box[0][k] - p[k], p[k] - box[1][k], 0.0});
    magnitude = std::max({magnitude, std::abs(box[0][k]), std::abs(box[1][k])});
  }
  return {norm(out), net_factor(rank) * distance(box[0], box[1]) + 1e-9 * magnitude};
}

}  // namespace

bool approx_net_sane(std::span<const Vec3> net, std::size_t rank, const std::array<Vec3, 2>& box) {
  return std::all_of(net.begin(), net.end(), [&](const Vec3& p) {
    const auto [far, allowed] = excess(p, rank, box);
    return is_finite(p) && far <= allowed;
  });
}

void check_approx_net(std::span<const Vec3> net, const std::vector<std::size_t>& net_shape, const ApproxData& d,
                      const char* what) {
  const std::array<Vec3, 2> box = approx_box(d);
  for (std::size_t i = 0; i < net.size(); ++i) {
    const auto [far, allowed] = excess(net[i], net_shape.size(), box);
    if (!is_finite(net[i]) || !(far <= allowed))
      fail(errc::ill_conditioned, what, ": control point ", index_text(i, net_shape), " = ", net[i], " lies ", far,
           " outside the data's bounding box, more than ", net_factor(net_shape.size()), " times its diagonal ",
           distance(box[0], box[1]),
           ": the fit swings far from its data (a nearly singular least-squares system, or holes filled far past the "
           "points present)");
  }
}

void check_approx_tolerance(const ApproxDistance& e, double tolerance, const ApproxData& d,
                            const std::vector<int>& control_points) {
  if (e.max <= tolerance) return;
  std::string cps;
  for (std::size_t a = 0; a < control_points.size(); ++a) cps += cat(a > 0 ? " x " : "", control_points[a]);
  fail(errc::tolerance_not_met, "tolerance ", tolerance, " not met: point ", index_text(e.worst, d.shape), " is ", e.max,
       " from the approximation with ", cps,
       " control points, the finest the data allow (as many control points as points interpolate a complete grid; "
       "missing points and rounding can keep a fit from a tolerance)");
}

}  // namespace interpatch::detail
