#include "constructions/scattered/scattered_sites.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "base/text.hpp"
#include "interpatch/error.hpp"

namespace interpatch::detail::scattered {

namespace {

// Which points count, with their weights; an infinite coordinate or a bad weight refused.
void take_points(Sites& s, std::span<const Vec3> points, const ScatteredApproximationOptions& o) {
  const std::size_t n = points.size();
  if (!o.weights.empty() && o.weights.size() != n)
    fail(errc::size_mismatch, o.weights.size(), " weights for ", n, " points");
  if (o.param == ScatteredParam::sites && o.sites.size() != n)
    fail(errc::size_mismatch, o.sites.size(), " sites for ", n, " points: give one (u, v) per point");
  bool unit = true;  // every point present with weight 1: no weights kept
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& q = points[k];
    const bool missing = std::isnan(q.x) || std::isnan(q.y) || std::isnan(q.z);
    if (!missing && !is_finite(q))
      fail(errc::not_finite, "point [", k, "] is ", q, " (NaN marks a missing point; infinity is refused)");
    const double w = o.weights.empty() ? 1.0 : o.weights[k];
    if (std::isnan(w)) fail(errc::not_finite, "weight [", k, "] is NaN");
    if (w < 0) fail(errc::invalid_weight, "weight [", k, "] is ", w, ": weights are non-negative");
    if (!std::isfinite(w)) fail(errc::not_finite, "weight [", k, "] is ", w);
    if (missing) ++s.missing;
    unit = unit && !missing && w == 1;
    if (missing || w == 0) continue;
    s.weight_sum += w;
    ++s.present;
  }
  if (unit) return;
  s.weight.assign(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& q = points[k];
    if (!std::isnan(q.x) && !std::isnan(q.y) && !std::isnan(q.z)) s.weight[k] = o.weights.empty() ? 1.0 : o.weights[k];
  }
}

// The principal axes of the points present: origin their mean, axis_u the direction of
// largest spread, axis_v the next; each axis turned so that its largest component is
// positive (the same axes for the same points in any order, up to rounding).
void plane_axes(Sites& s, std::span<const Vec3> points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.counts(k)) mean += Eigen::Vector3d(points[k].x, points[k].y, points[k].z);
  mean /= static_cast<double>(s.present);
  // The spread in a unit of the points' own size: squares of 1e200 would overflow.
  double top = 0;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.counts(k)) top = std::max(top, (Eigen::Vector3d(points[k].x, points[k].y, points[k].z) - mean).cwiseAbs().maxCoeff());
  const double unit = top > 0 ? top : 1.0;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < points.size(); ++k)
    if (s.counts(k)) {
      const Eigen::Vector3d d = (Eigen::Vector3d(points[k].x, points[k].y, points[k].z) - mean) / unit;
      cov += d * d.transpose();
    }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  auto axis = [&](int c) {
    Eigen::Vector3d a = eig.eigenvectors().col(c).normalized();
    Eigen::Index big = 0;
    a.cwiseAbs().maxCoeff(&big);
    if (a[big] < 0) a = -a;
    return Vec3{a[0], a[1], a[2]};
  };
  s.origin = {mean[0], mean[1], mean[2]};
  s.axis_u = axis(2);  // eigenvalues ascend
  s.axis_v = axis(1);
}

// Refuses sites that all lie on one line (nothing fixes the surface across it): the
// smaller principal spread of the sites is below 1e-9 of the larger.
void check_spread(const Sites& s, const char* what) {
  const std::size_t n = s.size();
  double mu = 0, mv = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (s.counts(k)) {
      const auto uv = s.uv(k);
      mu += uv[0], mv += uv[1];
    }
  mu /= static_cast<double>(s.present), mv /= static_cast<double>(s.present);
  // In a unit of the sites' own size: squares of 1e200 would overflow.
  double top = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (s.counts(k)) {
      const auto uv = s.uv(k);
      top = std::max({top, std::abs(uv[0] - mu), std::abs(uv[1] - mv)});
    }
  const double unit = top > 0 ? top : 1.0;
  double suu = 0, suv = 0, svv = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (s.counts(k)) {
      const auto uv = s.uv(k);
      const double du = (uv[0] - mu) / unit, dv = (uv[1] - mv) / unit;
      suu += du * du, suv += du * dv, svv += dv * dv;
    }
  const double half = (suu + svv) / 2, gap = std::sqrt((suu - svv) * (suu - svv) / 4 + suv * suv);
  const double large = half + gap, small = std::max(half - gap, 0.0);
  const double present = static_cast<double>(s.present);
  if (!(std::sqrt(small) > 1e-9 * std::sqrt(large)))
    fail(errc::singular, "the ", s.present, " points present", what, " all lie on one line (their spread across it is ",
         unit * std::sqrt(small / present), ", along it ", unit * std::sqrt(large / present),
         "): a surface needs points that span a plane");
}

void set_domain(Sites& s, const ScatteredApproximationOptions& o) {
  std::array<std::array<double, 2>, 2> box{{{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()},
                                            {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}}};
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.counts(k)) {
      const auto uv = s.uv(k);
      for (int a = 0; a < 2; ++a) {
        box[a][0] = std::min(box[a][0], uv[a]);
        box[a][1] = std::max(box[a][1], uv[a]);
      }
    }
  if (!o.domain) {
    s.domain = box;
    return;
  }
  s.domain = *o.domain;
  for (int a = 0; a < 2; ++a) {
    const auto [d0, d1] = s.domain[a];
    if (!(std::isfinite(d0) && std::isfinite(d1) && d0 < d1))
      fail(errc::non_increasing, "domain along ", a == 0 ? "u" : "v", " is [", d0, ", ", d1, "]: it must increase");
  }
  for (std::size_t k = 0; k < s.size(); ++k)
    if (s.counts(k)) {
      const auto uv = s.uv(k);
      for (int a = 0; a < 2; ++a)
        if (uv[a] < s.domain[a][0] || uv[a] > s.domain[a][1])
          fail(errc::out_of_domain, "point [", k, "] sits at ", a == 0 ? "u" : "v", " = ", uv[a], ", outside the domain [",
               s.domain[a][0], ", ", s.domain[a][1], "]");
    }
}

}  // namespace

Sites scattered_sites(std::span<const Vec3> points, const ScatteredApproximationOptions& o, int p, int q) {
  Sites s;
  s.points = points;
  take_points(s, points, o);
  const std::size_t need = static_cast<std::size_t>((p + 1) * (q + 1));
  if (s.present < need)
    fail(errc::too_few_points, s.present, " of ", points.size(), " points are present (not missing, weight above 0): a degree (",
         p, ", ", q, ") surface needs at least ", need);
  s.param = o.param;
  const char* what = "";
  switch (o.param) {
    case ScatteredParam::xy:
      what = " in x and y";
      break;
    case ScatteredParam::plane:
      plane_axes(s, points);
      break;
    case ScatteredParam::sites:
      for (std::size_t k = 0; k < points.size(); ++k) {
        const auto& t = o.sites[k];
        if (!std::isfinite(t[0]) || !std::isfinite(t[1]))
          fail(errc::not_finite, "site [", k, "] is (", t[0], ", ", t[1], ")");
      }
      s.given = o.sites;
      what = " at their sites";
      break;
  }
  check_spread(s, what);
  set_domain(s, o);
  return s;
}

}  // namespace interpatch::detail::scattered
