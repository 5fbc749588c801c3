// Closest points on a curve: the nearest pieces first, a bounded Newton iteration in
// each piece whose box is nearer than the best answer so far.

#include <algorithm>
#include <cmath>
#include <limits>

#include "locate/search.hpp"
#include "locate/spline_eval.hpp"

namespace interpatch {

namespace detail {

namespace {

struct CurveLocal {
  double t, f;  // f = |C(t) − q|²
};

// The nearest point to q of piece pc: the best of its ends and middle, then Newton's
// iteration on f = |C − q|² bounded to the piece (Gauss–Newton where f'' <= 0); a step
// that does not lower f is halved.
CurveLocal descend(const Spline& s, const PieceNets& nets, const Piece& pc, const Vec3& q) {
  const double a = pc.lo[0], b = pc.hi[0];
  double t = a, f = std::numeric_limits<double>::infinity();
  std::array<Vec3, 3> d{};
  for (const double x : {0.5, 0.0, 1.0}) {
    const double c = a + x * (b - a);
    const auto e = piece_derivatives(s, nets, pc, c);
    if (const double g = dot(e[0] - q, e[0] - q); g < f) t = c, f = g, d = e;
  }
  for (int it = 0; it < 50; ++it) {
    const Vec3 r = d[0] - q;
    const double g = dot(d[1], r);
    if ((t <= a && g > 0) || (t >= b && g < 0)) break;
    const double j = dot(d[1], d[1]);
    double h = j + dot(d[2], r);
    if (!(h > 0)) h = j;
    if (!(h > 0)) break;  // a cusp: the curve stands still here
    const double step = -g / h;
    bool moved = false;
    double size = 0;
    for (int k = 0; k < 40; ++k) {
      const double c = std::clamp(t + std::ldexp(step, -k), a, b);
      if (c == t) break;
      const auto e = piece_derivatives(s, nets, pc, c);
      if (const double n = dot(e[0] - q, e[0] - q); n < f) {
        size = std::abs(c - t) / (b - a);
        t = c, f = n, d = e, moved = true;
        break;
      }
    }
    if (!moved || size < 1e-13) break;  // see surface_projector.cpp
  }
  return {t, f};
}

}  // namespace

CurveSearch::CurveSearch(const BSplineCurve& c) : curve(c), tree({}) {
  const BSplineCurve k = c.clamped();
  spline.dims = 1;
  spline.knots = {k.knots()};
  spline.n = {static_cast<int>(k.control_points().size()), 1, 1};
  spline.set_points(k.control_points().data(), k.rational() ? k.weights().data() : nullptr, k.control_points().size());
  pieces = make_pieces(spline, &nets);
  tree = BoxTree(pieces);
}

CurvePoint CurveSearch::closest(const Vec3& q) const {
  const Vec3 qc = spline.local(q);
  double bound2 = std::numeric_limits<double>::infinity();
  CurveLocal best{0, std::numeric_limits<double>::infinity()};
  const double slack = prune_slack * spline.diagonal;
  tree.nearest(qc, bound2, [&](std::size_t k) {
    if (pieces[k].tight.distance2(qc) >= bound2) return;
    const CurveLocal l = descend(spline, nets, pieces[k], qc);
    if (l.f < best.f) {
      best = l;
      const double b = std::sqrt(l.f) - slack;
      bound2 = b > 0 ? b * b : 0;
    }
  });
  CurvePoint out{best.t, curve.point(best.t), 0};
  out.distance = distance(out.point, q);
  if (!is_finite(out.point) || std::abs(out.distance - std::sqrt(best.f) * spline.scale) >
                                     1e-9 * spline.diagonal * spline.scale + rounding_of(q, out.point))
    fail(errc::internal, "the closest point of ", num(q), " is ", num(out.point), " on the curve but ",
         std::sqrt(best.f) * spline.scale, " away on its clamped form");
  return out;
}

}  // namespace detail

CurveProjector::CurveProjector(const BSplineCurve& curve) : s_(std::make_unique<detail::CurveSearch>(curve)) {}
CurveProjector::~CurveProjector() = default;
CurveProjector::CurveProjector(CurveProjector&&) noexcept = default;
CurveProjector& CurveProjector::operator=(CurveProjector&&) noexcept = default;

CurvePoint CurveProjector::closest(const Vec3& q) const {
  if (!is_finite(q)) detail::fail(errc::not_finite, "the point ", detail::num(q), " is not finite");
  return s_->closest(q);
}

void CurveProjector::closest(std::span<const Vec3> points, std::span<CurvePoint> out,
                             const progress_callback& progress) const {
  detail::for_each_point(points, out, progress, [&](const Vec3& q) { return s_->closest(q); });
}

}  // namespace interpatch
