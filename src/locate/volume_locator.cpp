// The parameters of a point of space in a volume: the pieces whose boxes hold the
// point, a bounded Newton iteration on V(u, v, w) = x in each until one reaches it;
// a point no piece reaches is outside, and its answer is the nearest point of the
// boundary's faces.

#include <algorithm>
#include <cmath>
#include <limits>

#include "interpatch/bspline_volume.hpp"
#include "locate/search.hpp"
#include "locate/spline_eval.hpp"

namespace interpatch {

namespace detail {

namespace {

// A point within this share of the diagonal of V(u, v, w) is V(u, v, w): the
// promise of VolumePoint.
constexpr double inside_share = 1e-10;

BSplineVolume exact_form(const Volume& v) {
  BSplineVolume b = v.to_bspline();
  const auto d = v.domain(), e = b.domain();
  if (d != e) b = b.mapped(d[0].first, d[0].second, d[1].first, d[1].second, d[2].first, d[2].second);
  return b;
}

// The face of c (clamped) at the first (end 0) or last (end 1) control layer along axis.
BSplineSurface face(const BSplineVolume& c, int axis, int end) {
  const auto& cp = c.control_points();
  const std::array<std::size_t, 3> n{cp.extent(0), cp.extent(1), cp.extent(2)};
  const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;
  const auto A = static_cast<std::size_t>(a), B = static_cast<std::size_t>(b);
  PointGrid pts({n[A], n[B]});
  Grid<double, 2> w;
  if (c.rational()) w = Grid<double, 2>({n[A], n[B]});
  for (std::size_t i = 0; i < n[A]; ++i)
    for (std::size_t j = 0; j < n[B]; ++j) {
      std::array<std::size_t, 3> at{};
      at[static_cast<std::size_t>(axis)] = end == 0 ? 0 : n[static_cast<std::size_t>(axis)] - 1;
      at[A] = i, at[B] = j;
      pts(i, j) = cp(at[0], at[1], at[2]);
      if (c.rational()) w(i, j) = c.weights()(at[0], at[1], at[2]);
    }
  const std::array<const KnotVector*, 3> k{&c.knots_u(), &c.knots_v(), &c.knots_w()};
  return BSplineSurface(*k[A], *k[B], std::move(pts), std::move(w));
}

// Gauss–Newton's iteration on |V(u, v, w) − x|² from the piece's centre, bounded to
// the piece (a trace-relative shift of JᵀJ where J is singular, as on a collapsed
// edge); a step that does not lower the residual is halved. The parameters and the
// squared residual reached.
std::array<double, 4> reach(const Spline& s, const Piece& pc, const Vec3& x, double tol) {
  std::array<double, 3> p{};
  for (std::size_t a = 0; a < 3; ++a) p[a] = 0.5 * (pc.lo[a] + pc.hi[a]);
  VolumeDerivatives d = volume_derivatives(s, pc.span, p[0], p[1], p[2]);
  Vec3 r = x - d.s;
  double f = dot(r, r);
  // On to rounding once within reach: each step squares the error.
  for (int it = 0; it < 60 && f > 0; ++it) {
    const Vec3 J[3] = {d.su, d.sv, d.sw};
    double M[3][3], g[3];
    double trace = 0;
    for (int i = 0; i < 3; ++i) {
      g[i] = dot(J[i], r);
      for (int j = 0; j < 3; ++j) M[i][j] = dot(J[i], J[j]);
      trace += M[i][i];
    }
    const double shift = 1e-14 * trace + std::numeric_limits<double>::min();
    for (int i = 0; i < 3; ++i) M[i][i] += shift;
    const Vec3 c0{M[0][0], M[1][0], M[2][0]}, c1{M[0][1], M[1][1], M[2][1]}, c2{M[0][2], M[1][2], M[2][2]};
    const Vec3 gv{g[0], g[1], g[2]};
    const double det = triple(c0, c1, c2);
    if (!(std::abs(det) > 0)) break;
    const std::array<double, 3> step{triple(gv, c1, c2) / det, triple(c0, gv, c2) / det, triple(c0, c1, gv) / det};
    bool moved = false;
    for (int h = 0; h < 40; ++h) {
      std::array<double, 3> n{};
      bool same = true;
      for (std::size_t a = 0; a < 3; ++a) {
        n[a] = std::clamp(p[a] + std::ldexp(step[a], -h), pc.lo[a], pc.hi[a]);
        same = same && n[a] == p[a];
      }
      if (same) break;
      const VolumeDerivatives e = volume_derivatives(s, pc.span, n[0], n[1], n[2]);
      const Vec3 nr = x - e.s;
      if (const double nf = dot(nr, nr); nf < f) {
        p = n, d = e, r = nr, f = nf, moved = true;
        break;
      }
    }
    if (!moved) break;
    // Far from x after many steps: not in this piece (each step here costs a solve).
    if (it >= 12 && f > tol * tol) break;
  }
  return {p[0], p[1], p[2], f};
}

}  // namespace

VolumeSearch::VolumeSearch(const Volume& v) : VolumeSearch(v, exact_form(v)) {}

VolumeSearch::VolumeSearch(const Volume& v, const BSplineVolume& e) : volume(&v), tree({}) {
  const BSplineVolume c = e.clamped();
  const auto& cp = c.control_points();
  spline.dims = 3;
  spline.knots = {c.knots_u(), c.knots_v(), c.knots_w()};
  spline.n = {static_cast<int>(cp.extent(0)), static_cast<int>(cp.extent(1)), static_cast<int>(cp.extent(2))};
  spline.set_points(cp.data(), c.rational() ? c.weights().data() : nullptr, cp.size());
  pieces = make_pieces(spline);
  tree = BoxTree(pieces);
  const auto closed = e.periodic();
  const auto dom = c.domain();
  for (int axis = 0; axis < 3; ++axis) {
    if (closed[static_cast<std::size_t>(axis)]) continue;  // a closed direction has no faces
    for (int end = 0; end < 2; ++end) {
      Face f;
      f.surface = std::make_unique<BSplineSurface>(face(c, axis, end));
      f.search = std::make_unique<SurfaceSearch>(*f.surface, *f.surface);
      f.axis = axis;
      f.at = end == 0 ? dom[static_cast<std::size_t>(axis)].first : dom[static_cast<std::size_t>(axis)].second;
      faces.push_back(std::move(f));
    }
  }
}

VolumePoint VolumeSearch::locate(const Vec3& x) const {
  const Vec3 xc = spline.local(x);
  const double tol = inside_share * spline.diagonal;  // in the spline's units
  // Newton's iteration aims well inside the promise, so that the volume's own point
  // (its rounding differs from the exact form's) still keeps it.
  const double aim = 0.25 * tol;
  bool found = false;
  std::array<double, 4> at{};
  tree.where([&](const Box& b) { return !found && b.distance2(xc) <= tol * tol; },
             [&](std::size_t k) {
               if (found || pieces[k].tight.distance2(xc) > tol * tol) return;
               const auto r = reach(spline, pieces[k], xc, aim);
               if (r[3] <= aim * aim) found = true, at = r;
             });
  VolumePoint out;
  if (found) {
    out.u = at[0], out.v = at[1], out.w = at[2];
  } else {
    // Outside: the nearest point of the faces.
    double best = std::numeric_limits<double>::infinity();
    for (const Face& f : faces) {
      const SurfacePoint s = f.search->closest(x);
      if (!(s.distance < best)) continue;
      best = s.distance;
      std::array<double, 3> p{};
      const int a = f.axis == 0 ? 1 : 0, b = f.axis == 2 ? 1 : 2;
      p[static_cast<std::size_t>(f.axis)] = f.at, p[static_cast<std::size_t>(a)] = s.u, p[static_cast<std::size_t>(b)] = s.v;
      out.u = p[0], out.v = p[1], out.w = p[2];
    }
  }
  out.point = volume->point(out.u, out.v, out.w);
  out.residual = distance(out.point, x);
  if (!is_finite(out.point)) fail(errc::internal, "the volume's point at the parameters of ", num(x), " is not finite");
  out.inside = out.residual <= tol * spline.scale;
  return out;
}

}  // namespace detail

VolumeLocator::VolumeLocator(const Volume& volume) : s_(std::make_unique<detail::VolumeSearch>(volume)) {}
VolumeLocator::VolumeLocator(const Volume& volume, const BSplineVolume& exact)
    : s_(std::make_unique<detail::VolumeSearch>(volume, exact)) {}
VolumeLocator::~VolumeLocator() = default;
VolumeLocator::VolumeLocator(VolumeLocator&&) noexcept = default;
VolumeLocator& VolumeLocator::operator=(VolumeLocator&&) noexcept = default;

VolumePoint VolumeLocator::locate(const Vec3& x) const {
  if (!is_finite(x)) detail::fail(errc::not_finite, "the point ", detail::num(x), " is not finite");
  return s_->locate(x);
}

void VolumeLocator::locate(std::span<const Vec3> points, std::span<VolumePoint> out, const progress_callback& progress) const {
  detail::for_each_point(points, out, progress, [&](const Vec3& x) { return s_->locate(x); });
}

}  // namespace interpatch
