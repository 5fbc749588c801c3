// A blended volume's exact B-spline form: whether it has one, its knots, and the
// conversion, every control point a short sum of the terms on the common knots.
#include <algorithm>
#include <atomic>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "blends/volume_terms.hpp"
#include "interpatch/blended_volume.hpp"

namespace interpatch {

using detail::fail;

namespace {

// The knots of the exact form along u, v and w: every function of one direction
// on one knot vector and degree (merged_knots), blends, faces and edges alike.
std::array<KnotVector, 3> exact_knots(const detail::VolumeTerms& T) {
  std::array<std::vector<KnotVector>, 3> ks;
  for (std::size_t a = 0; a < 3; ++a)
    for (const auto& b : T.blends[a]) ks[a].push_back(b.spline->knots());
  for (const auto& face : T.faces) {
    const auto o = detail::other_axes(face.axis);
    ks[static_cast<std::size_t>(o[0])].push_back(face.surface.knots_u());
    ks[static_cast<std::size_t>(o[1])].push_back(face.surface.knots_v());
  }
  for (const auto& e : T.edges) ks[static_cast<std::size_t>(e.axis)].push_back(e.line.knots());
  return {merged_knots(ks[0]), merged_knots(ks[1]), merged_knots(ks[2])};
}

// Knots to insert into `k`, once elevated to the target's degree, to reach the target.
std::vector<double> missing_knots(const KnotVector& k, const KnotVector& target) {
  const int t = target.degree() - k.degree();
  std::vector<double> out;
  for (const auto& [x, m] : target.interior_breaks()) {
    const int have = k.multiplicity(x);
    out.insert(out.end(), static_cast<std::size_t>(m - (have > 0 ? have + t : 0)), x);
  }
  return out;
}

BSplineCurve fitted(const BSplineCurve& f, const KnotVector& target) {
  BSplineCurve c = f.elevated(target.degree() - f.degree());
  const auto add = missing_knots(f.knots(), target);
  if (!add.empty()) c = c.refined(add);
  INTERPATCH_ASSERT(c.knots().count() == target.count());
  return c;
}

BSplineSurface fitted(const BSplineSurface& s, const KnotVector& ku, const KnotVector& kv) {
  const auto au = missing_knots(s.knots_u(), ku), av = missing_knots(s.knots_v(), kv);
  return s.elevated(ku.degree() - s.degree_u(), kv.degree() - s.degree_v()).refined(au, av);
}

// Refuses, saying why, a blended volume without an exact form.
void require_exact_form(const detail::VolumeTerms& T) {
  for (std::size_t a = 0; a < 3; ++a)
    for (const auto& b : T.blends[a])
      if (!b.spline)
        fail(errc::no_exact_form, "the blending function of ", detail::axis_letter(static_cast<int>(a)),
             " is a callable; only B-spline blends have an exact B-spline form");
  for (std::size_t k = 0; k < T.faces.size(); ++k)
    if (T.faces[k].surface.rational())
      fail(errc::no_exact_form, T.faces[k].name, " is a rational surface; blends of rational surfaces with "
           "different weights have no B-spline form of the same kind");
  for (std::size_t k = 0; k < T.edges.size(); ++k)
    if (T.edges[k].line.rational())
      fail(errc::no_exact_form, "edge line ", k, " along ", detail::axis_letter(T.edges[k].axis),
           " lies on a rational surface; blends of rational data have no B-spline form of the same kind");
}

// The terms on the common knots: each blend's coefficients, each face's net and each
// edge's line; n: the control points along u, v and w.
struct OnKnots {
  std::array<std::vector<detail::Coefficients>, 3> coef;
  std::vector<BSplineSurface> refit;  // the faces not on the common knots already, fitted there
  std::vector<const PointGrid*> Q;    // every face's net on the common knots
  std::vector<std::vector<Vec3>> E;
  std::array<std::size_t, 3> n{};
};

OnKnots on_common_knots(const detail::VolumeTerms& T, const std::array<KnotVector, 3>& target) {
  OnKnots k;
  auto& coef = k.coef;
  for (std::size_t a = 0; a < 3; ++a)
    for (const auto& b : T.blends[a]) coef[a].push_back(detail::coefficients(fitted(*b.spline, target[a])));
  // A face on the common knots already is used as it is: no copy of its net.
  k.refit.reserve(T.faces.size());
  for (const auto& face : T.faces) {
    const auto o = detail::other_axes(face.axis);
    const KnotVector& ku = target[static_cast<std::size_t>(o[0])];
    const KnotVector& kv = target[static_cast<std::size_t>(o[1])];
    const bool fits = face.surface.knots_u().values() == ku.values() && face.surface.knots_v().values() == kv.values();
    k.Q.push_back(fits ? &face.surface.control_points()
                       : &k.refit.emplace_back(fitted(face.surface, ku, kv)).control_points());
  }
  for (const auto& e : T.edges)
    k.E.push_back(fitted(e.line.curve(), target[static_cast<std::size_t>(e.axis)]).control_points());
  k.n = {static_cast<std::size_t>(target[0].count()), static_cast<std::size_t>(target[1].count()),
         static_cast<std::size_t>(target[2].count())};
  return k;
}

// Control point (x, y, z) is a sum over the terms of rows along w: a line along w
// times a number of (x, y) (faces of u and v, edges along w), or a point of (x, y)
// times a blend of w (faces of w, edges along u and v, corners), the points of one
// blend of w added first. Each control point is written once, by one thread, each
// point's terms added in one order.
struct RowTerm {  // scale · fu[x] · fv[y] (a missing blend is 1) times the line or point at base + x sx + y sy
  double scale;
  const detail::Coefficients *fu, *fv;
  const Vec3* base;
  std::size_t sx, sy, blend;  // blend: of w, for points
};

struct RowTerms {
  std::vector<RowTerm> lines, points;
  std::vector<PointGrid> R;  // the grids of (v, w) that the line terms of u read
};

RowTerms row_terms(const detail::VolumeTerms& T, const OnKnots& on) {
  const auto& coef = on.coef;
  const auto& Q = on.Q;
  const auto& E = on.E;
  const auto& n = on.n;
  RowTerms out;
  auto& line_terms = out.lines;
  auto& point_terms = out.points;
  auto blend = [&coef](std::size_t axis, std::size_t k) { return &coef[axis][k]; };
  // The faces of u and the edges along w of one blend of u first make one grid of
  // (v, w), R_i = Σ faces + Σ scale g_b(v) E(w), so rows take one term for them.
  auto& R = out.R;
  R.reserve(T.blends[0].size());
  for (std::size_t i = 0; i < T.blends[0].size(); ++i) {
    std::vector<std::size_t> faces, edges;
    for (std::size_t k = 0; k < T.faces.size(); ++k)
      if (T.faces[k].axis == 0 && T.faces[k].blend == i) faces.push_back(k);
    for (std::size_t k = 0; k < T.edges.size(); ++k)
      if (T.edges[k].axis == 2 && T.edges[k].blends[0] == i) edges.push_back(k);
    if (faces.empty() && edges.empty()) continue;
    PointGrid& g = R.emplace_back(PointGrid::shape_type{n[1], n[2]}, for_overwrite);
    for (std::size_t y = 0; y < n[1]; ++y)
      for (std::size_t z = 0; z < n[2]; ++z) {
        Vec3 p{};
        for (std::size_t k : faces) p += (*Q[k])(y, z);
        for (std::size_t k : edges) p += (T.edges[k].scale * coef[1][T.edges[k].blends[1]].c[3 * y]) * E[k][z];
        g(y, z) = p;
      }
    line_terms.push_back({1.0, blend(0, i), nullptr, g.data(), 0, n[2], 0});
  }
  for (std::size_t k = 0; k < T.faces.size(); ++k) {
    const auto& f = T.faces[k];
    const Vec3* q = Q[k]->data();
    if (f.axis == 1) line_terms.push_back({1.0, nullptr, blend(1, f.blend), q, n[2], 0, 0});
    if (f.axis == 2) point_terms.push_back({1.0, nullptr, nullptr, q, n[1], 1, f.blend});
  }
  for (std::size_t k = 0; k < T.edges.size(); ++k) {
    const auto& e = T.edges[k];
    const Vec3* l = E[k].data();
    if (e.axis == 0) point_terms.push_back({e.scale, nullptr, blend(1, e.blends[0]), l, 1, 0, e.blends[1]});
    if (e.axis == 1) point_terms.push_back({e.scale, blend(0, e.blends[0]), nullptr, l, 0, 1, e.blends[1]});
  }
  for (const auto& k : T.corners)
    point_terms.push_back({1.0, blend(0, k.blends[0]), blend(1, k.blends[1]), &k.point, 0, 0, k.blends[2]});
  return out;
}

// The net filled row by row along w, the rows shared between the threads.
PointGrid3 fill_net(const RowTerms& terms, const OnKnots& on, std::size_t nh, const progress_callback& progress) {
  const auto& coef = on.coef;
  const auto& n = on.n;
  const auto& line_terms = terms.lines;
  const auto& point_terms = terms.points;
  PointGrid3 P(n, for_overwrite);
  const auto rows = static_cast<long long>(n[0] * n[1]);
  detail::ParallelFailure failure;  // making the terms' vectors of a thread
  detail::RegionProgress report(progress);
  std::atomic<std::size_t> done{0};
#pragma omp parallel if (n[0] * n[1] * n[2] * (line_terms.size() + nh) >= detail::parallel_min_work)
  {
    std::vector<detail::LineTerm> lines;
    std::vector<detail::PointTerm> points;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      lines.reserve(line_terms.size());  // a stretch's terms at most: push_back below never allocates
      points.reserve(nh);
    });
    std::array<Vec3, detail::max_volume_blends> h;  // the point of each blend of w
#pragma omp for schedule(static)
    for (long long r = 0; r < rows; ++r) {
      if (failure.failed() || report.stopped()) continue;  // a failure, or stopped by the progress callback
      const std::size_t x = static_cast<std::size_t>(r) / n[1], y = static_cast<std::size_t>(r) % n[1];
      auto factor = [x, y](const RowTerm& t) {
        const double a = t.fu ? t.scale * t.fu->c[3 * x] : t.scale;
        return t.fv ? a * t.fv->c[3 * y] : a;
      };
      h.fill(Vec3{});
      for (const auto& t : point_terms) h[t.blend] += factor(t) * t.base[x * t.sx + y * t.sy];
      detail::fill_row(&P(x, y, 0).x, n[2], lines, points, [&](std::size_t z0, std::size_t z1, auto& ls, auto& ps) {
        for (const auto& t : line_terms)
          if (const double f = factor(t); f != 0.0) ls.push_back({f, &t.base[x * t.sx + y * t.sy + z0].x});
        for (std::size_t b = 0; b < nh; ++b)
          if (h[b] != Vec3{} && coef[2][b].lo < z1 && coef[2][b].hi > z0)
            ps.emplace_back(coef[2][b].c.data() + 3 * z0, h[b]);
      });
      const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (detail::thread_index() == 0 && d % 256 == 0)
        report.report(static_cast<double>(d) / static_cast<double>(n[0] * n[1]));
    }
  }
  failure.rethrow();
  report.rethrow();
  if (progress) progress(1.0);
  return P;
}

}  // namespace

bool BlendedVolume::has_exact_form() const noexcept {
  for (const auto& list : t_->blends)
    for (const auto& b : list)
      if (!b.spline) return false;
  for (const auto& face : t_->faces)
    if (face.surface.rational()) return false;
  for (const auto& e : t_->edges)
    if (e.line.rational()) return false;
  return true;
}

BSplineVolume BlendedVolume::to_bspline() const { return to_bspline(progress_callback{}); }

BSplineVolume BlendedVolume::to_bspline(const progress_callback& progress) const {
  const auto& T = *t_;
  require_exact_form(T);
  // Every function of u on one knot vector and degree, likewise v and w.
  const std::array<KnotVector, 3> target = exact_knots(T);
  const OnKnots on = on_common_knots(T, target);
  const RowTerms terms = row_terms(T, on);
  PointGrid3 P = fill_net(terms, on, T.blends[2].size(), progress);
  return BSplineVolume(target[0], target[1], target[2], std::move(P));
}

}  // namespace interpatch
