// Where a ray meets a surface: the pieces whose boxes the ray passes through, and in
// each a bounded Newton iteration on the two equations that put S(u, v) on the ray's
// line.

#include <algorithm>
#include <cmath>
#include <limits>

#include "locate/search.hpp"
#include "locate/spline_eval.hpp"

namespace interpatch::detail {

namespace {

struct Line {
  Vec3 o, d;   // about the spline's centre; d a unit vector
  Vec3 e1, e2;  // with d, an orthonormal frame
};

Line frame(const Vec3& o, const Vec3& d) {
  const Vec3 a = std::abs(d.x) <= std::abs(d.y) && std::abs(d.x) <= std::abs(d.z) ? Vec3{1, 0, 0}
                 : std::abs(d.y) <= std::abs(d.z)                                 ? Vec3{0, 1, 0}
                                                                                  : Vec3{0, 0, 1};
  const Vec3 e1 = cross(d, a) / norm(cross(d, a));
  return {o, d, e1, cross(d, e1)};
}

// Newton's iteration from (u, v) on g = ((S − o)·e1, (S − o)·e2) = 0, bounded to the
// piece; a step that does not lower |g| is halved. Whether |g| reached `tol`.
bool meet(const SurfaceSearch& S, const Piece& pc, const Line& l, double tol, double& u, double& v) {
  SurfaceDerivatives d = S.at(pc, u, v);
  const auto residual = [&](const Vec3& p) {
    const Vec3 r = p - l.o;
    return std::array<double, 2>{dot(r, l.e1), dot(r, l.e2)};
  };
  auto g = residual(d.s);
  double g2 = g[0] * g[0] + g[1] * g[1];
  // On to rounding, not only to tol: once near, each step squares the error.
  for (int it = 0; it < 60 && g2 > 0; ++it) {
    const double a = dot(d.su, l.e1), b = dot(d.sv, l.e1), c = dot(d.su, l.e2), e = dot(d.sv, l.e2);
    const double det = a * e - b * c;
    if (!(std::abs(det) > 0)) return false;  // the surface runs along the ray here
    const double du = -(e * g[0] - b * g[1]) / det, dv = -(a * g[1] - c * g[0]) / det;
    bool moved = false;
    double t = 1;
    for (int h = 0; h < 40; ++h, t *= 0.5) {
      const double nu = std::clamp(u + t * du, pc.lo[0], pc.hi[0]), nv = std::clamp(v + t * dv, pc.lo[1], pc.hi[1]);
      if (nu == u && nv == v) break;
      const SurfaceDerivatives nd = S.at(pc, nu, nv);
      const auto ng = residual(nd.s);
      const double n2 = ng[0] * ng[0] + ng[1] * ng[1];
      if (n2 < g2) {
        u = nu, v = nv, d = nd, g = ng, g2 = n2, moved = true;
        break;
      }
    }
    if (!moved) break;
  }
  return g2 <= tol * tol;
}

}  // namespace

std::vector<RayHit> SurfaceSearch::intersect(const Vec3& origin, const Vec3& direction) const {
  if (!is_finite(origin) || !is_finite(direction))
    fail(errc::not_finite, "the ray ", num(origin), " + t ", num(direction), " is not finite");
  const double len = norm(direction);
  if (!(len > 0)) fail(errc::wrong_type, "the ray from ", num(origin), " has the zero vector as its direction");
  const Line l = frame(spline.local(origin), direction / len);
  // A hit is a point within 1e-12 of the diagonal of the ray's line (rounding of the
  // evaluation, far below the 1e-10 the answers promise).
  const double tol = 1e-12 * spline.diagonal;
  std::vector<RayHit> raw;
  tree.where([&](const Box& b) { return b.meets_ray(l.o, l.d, 1e-9 * spline.diagonal); },
             [&](std::size_t k) {
               const Piece& pc = pieces[k];
               if (!pc.tight.meets_ray(l.o, l.d, 1e-9 * spline.diagonal)) return;
               // From the centre, then from the centres of the quarters: a piece turns by
               // 45° at most, so it meets a line once or twice.
               const double seeds[5][2] = {{0.5, 0.5}, {0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}, {0.75, 0.75}};
               for (const auto& sd : seeds) {
                 double u = pc.lo[0] + sd[0] * (pc.hi[0] - pc.lo[0]), v = pc.lo[1] + sd[1] * (pc.hi[1] - pc.lo[1]);
                 if (!meet(*this, pc, l, tol, u, v)) continue;
                 const Vec3 p = surface->point(u, v);
                 const double t = dot(p - origin, direction) / (len * len);
                 if (t >= -1e-12 * spline.diagonal * spline.scale / len) raw.push_back({std::max(t, 0.0), u, v, p});
               }
             });
  std::sort(raw.begin(), raw.end(), [](const RayHit& a, const RayHit& b) {
    return a.t < b.t || (a.t == b.t && (a.u < b.u || (a.u == b.u && a.v < b.v)));
  });
  std::vector<RayHit> hits;
  for (const RayHit& h : raw)
    if (hits.empty() || distance(hits.back().point, h.point) > 1e-9 * spline.diagonal * spline.scale) hits.push_back(h);
  return hits;
}

}  // namespace interpatch::detail
