// Closest points on a surface: the nearest pieces first, a bounded Newton iteration
// in each piece whose box is nearer than the best answer so far.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "interpatch/interpolate.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/projection.hpp"
#include "locate/search.hpp"
#include "locate/spline_eval.hpp"

namespace interpatch {

namespace detail {

namespace {

BSplineSurface exact_form(const Surface& s) {
  BSplineSurface b = s.to_bspline().clamped();
  const auto d = s.domain(), e = b.domain();
  if (d != e) b = b.mapped(d[0].first, d[0].second, d[1].first, d[1].second);
  return b;
}

struct SurfaceLocal {
  double u, v, f;  // f = |S(u, v) − q|²
};

// A box of parameters within a piece.
struct Region {
  double u0, u1, v0, v1;
};

// Where Newton's iteration starts in a region, as fractions of it: the nearest point to
// q of the bilinear patch through the corners of its Bézier net (points of the
// surface), by Gauss–Newton's iteration on that patch alone; a piece turns by 45° at
// most, so this lands near the answer at no evaluation of the surface.
std::array<double, 2> bilinear_seed(const H4* net, int nu, int nv, const Vec3& q) {
  const auto Q = static_cast<std::size_t>(nv), last = static_cast<std::size_t>(nu) * Q - 1;
  const auto at = [&](std::size_t k) { return Vec3{net[k].x, net[k].y, net[k].z} / net[k].w; };
  const Vec3 c00 = at(0), c01 = at(Q - 1), c10 = at(last + 1 - Q), c11 = at(last);
  double s = 0.5, t = 0.5;
  for (int it = 0; it < 3; ++it) {
    const Vec3 bs = (1 - t) * (c10 - c00) + t * (c11 - c01), bt = (1 - s) * (c01 - c00) + s * (c11 - c10);
    const Vec3 r = (1 - s) * ((1 - t) * c00 + t * c01) + s * ((1 - t) * c10 + t * c11) - q;
    const double a = dot(bs, bs), b = dot(bs, bt), c = dot(bt, bt), gs = dot(bs, r), gt = dot(bt, r);
    const double det = a * c - b * b;
    if (!(det > 1e-12 * (a * c) && det > 0)) break;  // a collapsed edge: the centre will do
    s = std::clamp(s - (c * gs - b * gt) / det, 0.0, 1.0);
    t = std::clamp(t - (a * gt - b * gs) / det, 0.0, 1.0);
  }
  return {s, t};
}

// The nearest point to q of region r of piece pc, from (u, v): Newton's iteration on
// f = |S − q|², bounded to the region. Where the Hessian of f is not positive
// definite, Gauss–Newton's JᵀJ (with a trace-relative shift where that too is
// singular, as at a pole); a step that does not lower f is halved.
SurfaceLocal descend(const SurfaceSearch& S, const Piece& pc, const Region& rg, double u, double v, const Vec3& q) {
  const Spline& s = S.spline;
  const double u0 = rg.u0, u1 = rg.u1, v0 = rg.v0, v1 = rg.v1;
  SurfaceDerivatives d = S.at(pc, u, v);
  double f = dot(d.s - q, d.s - q);
  for (int it = 0; it < 50; ++it) {
    const Vec3 r = d.s - q;
    const double gu = dot(d.su, r), gv = dot(d.sv, r);
    const bool fu = !((u <= u0 && gu > 0) || (u >= u1 && gu < 0));
    const bool fv = !((v <= v0 && gv > 0) || (v >= v1 && gv < 0));
    if (!fu && !fv) break;
    const double juu = dot(d.su, d.su), juv = dot(d.su, d.sv), jvv = dot(d.sv, d.sv);
    double huu = juu + dot(d.suu, r), huv = juv + dot(d.suv, r), hvv = jvv + dot(d.svv, r);
    double du = 0, dv = 0;
    // The step on the free parameters: Newton where the Hessian is positive definite.
    const auto solve = [&](double a, double b, double c) {
      if (fu && fv) {
        const double det = a * c - b * b;
        if (!(det > 0 && a > 0)) return false;
        du = -(c * gu - b * gv) / det, dv = -(a * gv - b * gu) / det;
      } else if (fu) {
        if (!(a > 0)) return false;
        du = -gu / a;
      } else {
        if (!(c > 0)) return false;
        dv = -gv / c;
      }
      return true;
    };
    if (!solve(huu, huv, hvv)) {
      const double shift = 1e-12 * (juu + jvv) + std::numeric_limits<double>::min();
      if (!solve(juu + shift, juv, jvv + shift)) break;
    }
    // Converged when the full step would move the point by less than 1e-13 of the
    // diagonal (a thousandth of the promise): evaluating it would find f unchanged to
    // rounding, and halve it forty times.
    const double moves = norm(d.su * du + d.sv * dv);
    double t = 1;
    bool moved = false;
    // Halved no further than a step of 1e-13 of the diagonal: below that, f changes
    // by its rounding alone.
    for (; t * moves >= 1e-13 * s.diagonal; t *= 0.5) {
      const double a = std::clamp(u + t * du, u0, u1), b = std::clamp(v + t * dv, v0, v1);
      if (a == u && b == v) break;
      const SurfaceDerivatives e = S.at(pc, a, b);
      const Vec3 nr = e.s - q;
      const double g = dot(nr, nr);
      if (g < f) {
        u = a, v = b, f = g, d = e, moved = true;
        break;
      }
    }
    // Newton's steps square their error: after a full step of 1e-7 of the diagonal the
    // point is within about 1e-14 of it (times the curvature over the diagonal).
    if (!moved || (t == 1 && moves < 1e-7 * s.diagonal)) break;
  }
  return {u, v, f};
}

// Whether a piece (its box, and its net's convex radius, BezierNet::convex_radius, half
// of 1/κ) may hold a point nearer to q than `found` (a minimum of f = |S − q|² in it,
// found) other than that one. No, when the ball about q through `found`, or every point
// of the piece, lies within 0.9/κ: the piece (its normals within 30° of one another)
// meets such a ball in one connected patch, on which f's Hessian I − (q − S)·II is
// positive definite, so f has one minimum there. Yes otherwise: it is searched further.
bool may_bend(const OrientedBox& box, double convex, const Vec3& q, double found) {
  return !(std::min(box.farthest(q), found) < 1.8 * convex);
}

}  // namespace

SurfaceSearch::SurfaceSearch(const BSplineSurface& b, const Surface& answers) : surface(&answers), tree({}) {
  const BSplineSurface c = b.clamped();
  spline.dims = 2;
  spline.knots = {c.knots_u(), c.knots_v()};
  spline.n = {static_cast<int>(c.control_points().extent(0)), static_cast<int>(c.control_points().extent(1)), 1};
  spline.set_points(c.control_points().data(), c.rational() ? c.weights().data() : nullptr, c.control_points().size());
  pieces = make_pieces(spline, &nets);
  tree = BoxTree(pieces);
}

namespace {

// The stand-in of a surface without an exact form: the bicubic through its points on a
// 65 × 65 grid of its parameters (uniform: the stand-in's parameters are the surface's),
// and the largest gap between the two at the centres of the grid's cells and of their
// quarters.
std::pair<BSplineSurface, double> stand_in(const Surface& s) {
  const auto d = s.domain();
  const std::size_t m = 65;
  const auto us = linspace(d[0].first, d[0].second, m), vs = linspace(d[1].first, d[1].second, m);
  SurfaceInterpolationOptions o;
  o.param = Parametrization::uniform;
  BSplineSurface b = interpolate_surface(s.evaluate(us, vs), o).surface.mapped(d[0].first, d[0].second, d[1].first, d[1].second);
  const auto half = [](std::span<const double> t) {
    std::vector<double> h;
    for (std::size_t i = 0; i + 1 < t.size(); ++i)
      for (const double f : {0.25, 0.5, 0.75}) h.push_back(t[i] + f * (t[i + 1] - t[i]));
    return h;
  };
  const auto hu = half(us), hv = half(vs);
  const PointGrid a = s.evaluate(hu, hv), c = b.evaluate(hu, hv);
  double gap = 0;
  for (std::size_t k = 0; k < a.size(); ++k) gap = std::max(gap, distance(a.values()[k], c.values()[k]));
  return {std::move(b), gap};
}

}  // namespace

SurfaceSearch::SurfaceSearch(const Surface& s) : surface(&s), tree({}) {
  std::optional<BSplineSurface> exact;
  try {
    exact = exact_form(s);
  } catch (const error& e) {
    if (e.code() != errc::no_exact_form) throw;
  }
  if (exact) {
    *this = SurfaceSearch(*exact, s);
    return;
  }
  auto [b, gap] = stand_in(s);
  SurfaceSearch near(b, s);
  *this = std::move(near);
  formula = &s;
  // Four times the gap measured: between samples it can be larger than at them.
  widen = (4 * gap + 1e-12 * spline.diagonal * spline.scale) / spline.scale;
  for (Piece& pc : pieces) {
    pc.box.lo -= Vec3{widen, widen, widen}, pc.box.hi += Vec3{widen, widen, widen};
    for (std::size_t i = 0; i < 3; ++i) pc.tight.lo[i] -= widen, pc.tight.hi[i] += widen;
    pc.convex = 0;  // the stand-in's curvature is not the surface's: search every piece further
  }
  tree = BoxTree(pieces);
}

SurfaceDerivatives SurfaceSearch::at(const Piece& pc, double u, double v) const {
  if (!formula) return piece_derivatives(spline, nets, pc, u, v);
  SurfaceDerivatives d = formula->derivatives(u, v);
  const double k = 1 / spline.scale;
  d.s = spline.local(d.s);
  d.su *= k, d.sv *= k, d.suu *= k, d.suv *= k, d.svv *= k;
  return d;
}

// A piece where f may have several minima: halved three times in both directions, the
// quarters nearest first and those whose boxes lie beyond the best distance skipped, and
// in each quarter left Newton's iteration from the bilinear seed and from its corners.
// Boxes of small quarters are tight, so few are searched.
template <class Keep>
void search_bent_in(const SurfaceSearch& S, const Piece& pc, const BezierNet& net, const Region& rg, int depth,
                    const Vec3& q, const double& bound2, Keep&& keep) {
  BezierNet a, b, parts[4];
  net.halve(0, a, b);
  a.halve(1, parts[0], parts[1]);
  b.halve(1, parts[2], parts[3]);
  const double um = 0.5 * (rg.u0 + rg.u1), vm = 0.5 * (rg.v0 + rg.v1);
  const Region r[4] = {{rg.u0, um, rg.v0, vm}, {rg.u0, um, vm, rg.v1}, {um, rg.u1, rg.v0, vm}, {um, rg.u1, vm, rg.v1}};
  std::array<std::pair<double, int>, 4> order;
  OrientedBox boxes[4];
  for (int k = 0; k < 4; ++k) {
    boxes[k] = parts[k].bounds(2);
    for (std::size_t i = 0; i < 3; ++i) boxes[k].lo[i] -= S.widen, boxes[k].hi[i] += S.widen;
    order[static_cast<std::size_t>(k)] = {boxes[k].distance2(q), k};
  }
  std::sort(order.begin(), order.end());
  for (const auto& [lb, k] : order) {
    if (lb >= bound2) continue;
    const Region& x = r[k];
    const bool bends =
        may_bend(boxes[k], parts[k].convex_radius(x.u1 - x.u0, x.v1 - x.v0), q, std::numeric_limits<double>::infinity());
    if (bends && depth + 1 < 3) {
      search_bent_in(S, pc, parts[k], x, depth + 1, q, bound2, keep);
      continue;
    }
    const auto [sa, sb] = bilinear_seed(parts[k].h.data(), parts[k].n[0], parts[k].n[1], q);
    // One minimum here, or cut as far as it goes: from the bilinear seed, and then from
    // the corners.
    const double seeds[5][2] = {{sa, sb}, {0, 0}, {1, 0}, {0, 1}, {1, 1}};
    for (int m = 0; m < (bends ? 5 : 1); ++m)
      keep(descend(S, pc, x, x.u0 + seeds[m][0] * (x.u1 - x.u0), x.v0 + seeds[m][1] * (x.v1 - x.v0), q));
  }
}

template <class Keep>
void SurfaceSearch::search_bent(const Piece& pc, const Vec3& q, const double& bound2, Keep&& keep) const {
  BezierNet net;
  net.n = nets.n;
  net.h.assign(nets.h.begin() + static_cast<std::ptrdiff_t>(pc.net),
               nets.h.begin() + static_cast<std::ptrdiff_t>(pc.net + static_cast<std::size_t>(nets.n[0] * nets.n[1])));
  search_bent_in(*this, pc, net, {pc.lo[0], pc.hi[0], pc.lo[1], pc.hi[1]}, 0, q, bound2, keep);
}

SurfacePoint SurfaceSearch::closest(const Vec3& q) const {
  const Vec3 qc = spline.local(q);
  double bound2 = std::numeric_limits<double>::infinity();
  SurfaceLocal best{0, 0, std::numeric_limits<double>::infinity()};
  const double slack = prune_slack * spline.diagonal;
  const auto keep = [&](const SurfaceLocal& l) {
    if (!(l.f < best.f)) return;
    best = l;
    const double b = std::sqrt(l.f) - slack;
    bound2 = b > 0 ? b * b : 0;
  };
  tree.nearest(qc, bound2, [&](std::size_t k) {
    const Piece& pc = pieces[k];
    if (pc.tight.distance2(qc) >= bound2) return;
    const Region whole{pc.lo[0], pc.hi[0], pc.lo[1], pc.hi[1]};
    if (!nets.kept()) {
      // Without the nets: from the centre and from each corner.
      for (const auto& [a, b] : {std::pair{0.5, 0.5}, {0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {1.0, 1.0}})
        keep(descend(*this, pc, whole, pc.lo[0] + a * (pc.hi[0] - pc.lo[0]), pc.lo[1] + b * (pc.hi[1] - pc.lo[1]), qc));
      return;
    }
    const H4* net = &nets.h[pc.net];
    const auto [a, b] = bilinear_seed(net, nets.n[0], nets.n[1], qc);
    const SurfaceLocal l = descend(*this, pc, whole, pc.lo[0] + a * (pc.hi[0] - pc.lo[0]), pc.lo[1] + b * (pc.hi[1] - pc.lo[1]), qc);
    keep(l);
    if (may_bend(pc.tight, pc.convex, qc, std::sqrt(l.f))) search_bent(pc, qc, bound2, keep);
  });
  SurfacePoint out{best.u, best.v, surface->point(best.u, best.v), 0};
  out.distance = distance(out.point, q);
  // The surface and its exact form agree to rounding; more is a defect to report.
  if (!is_finite(out.point) || std::abs(out.distance - std::sqrt(best.f) * spline.scale) >
                                     1e-9 * spline.diagonal * spline.scale + rounding_of(q, out.point))
    fail(errc::internal, "the closest point of ", num(q), " is ", num(out.point), " on the surface but ",
         std::sqrt(best.f) * spline.scale, " away on its exact form");
  return out;
}

}  // namespace detail

SurfaceProjector::SurfaceProjector(const Surface& surface) : s_(std::make_unique<detail::SurfaceSearch>(surface)) {}
SurfaceProjector::SurfaceProjector(const Surface& surface, const BSplineSurface& exact)
    : s_(std::make_unique<detail::SurfaceSearch>(exact, surface)) {}
SurfaceProjector::~SurfaceProjector() = default;
SurfaceProjector::SurfaceProjector(SurfaceProjector&&) noexcept = default;
SurfaceProjector& SurfaceProjector::operator=(SurfaceProjector&&) noexcept = default;

SurfacePoint SurfaceProjector::closest(const Vec3& q) const {
  if (!is_finite(q)) detail::fail(errc::not_finite, "the point ", detail::num(q), " is not finite");
  return s_->closest(q);
}

void SurfaceProjector::closest(std::span<const Vec3> points, std::span<SurfacePoint> out,
                               const progress_callback& progress) const {
  detail::for_each_point(points, out, progress, [&](const Vec3& q) { return s_->closest(q); });
}

std::vector<RayHit> SurfaceProjector::intersect(const Vec3& origin, const Vec3& direction) const {
  return s_->intersect(origin, direction);
}

void SurfaceProjector::intersect(std::span<const Vec3> origins, std::span<const Vec3> directions,
                                 std::span<std::vector<RayHit>> out, const progress_callback& progress) const {
  if (directions.size() != origins.size() && directions.size() != 1)
    detail::fail(errc::size_mismatch, "one direction for every ray (", origins.size(), ") or one for all, got ",
                 directions.size());
  const auto dir = [&](std::size_t i) { return directions[directions.size() == 1 ? 0 : i]; };
  if (out.size() != origins.size())
    detail::fail(errc::size_mismatch, "the output holds ", out.size(), " answers for ", origins.size(), " rays");
  for (std::size_t i = 0; i < origins.size(); ++i) {  // every ray checked before any work
    if (!is_finite(origins[i]) || !is_finite(dir(i)))
      detail::fail(errc::not_finite, "ray ", i, ": ", detail::num(origins[i]), " + t ", detail::num(dir(i)), " is not finite");
    if (!(norm(dir(i)) > 0)) detail::fail(errc::wrong_type, "ray ", i, ": its direction is the zero vector");
  }
  detail::for_each_index(origins.size(), progress, [&](std::size_t i) { out[i] = s_->intersect(origins[i], dir(i)); });
}

}  // namespace interpatch
