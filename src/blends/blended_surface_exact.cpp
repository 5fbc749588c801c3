// A blended surface's exact B-spline form: whether it has one, its knots, and the
// conversion, every control point a short sum of the terms' coefficients.
#include <algorithm>
#include <atomic>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "blends/blended_terms.hpp"
#include "interpatch/blended_surface.hpp"

namespace interpatch {

using detail::fail;

bool BlendedSurface::has_exact_form() const noexcept {
  if (!t_->gregory.empty()) return false;
  for (const auto* list : {&t_->f, &t_->g})
    for (const auto& s : *list)
      if (!s.spline) return false;
  for (const auto* list : {&t_->a, &t_->b})
    for (const auto& c : *list)
      if (c.rational()) return false;
  return true;
}

namespace {

// Refuses, saying why, a blended surface without an exact form.
void require_exact_form(const detail::BlendedTerms& T) {
  if (!T.gregory.empty())
    fail(errc::no_exact_form, "Gregory's twist correction is a rational blend of u and v with a singular point at "
                              "each corrected corner; the patch has no exact B-spline form");
  for (const auto* list : {&T.a, &T.b})
    for (std::size_t k = 0; k < list->size(); ++k)
      if ((*list)[k].rational())
        fail(errc::no_exact_form, "curve ", k, " of the ", list == &T.a ? "v" : "u",
             "-direction terms is rational; blends of rational curves with different weights have no B-spline "
             "form of the same kind");
  for (const auto* list : {&T.f, &T.g})
    for (const auto& s : *list)
      if (!s.spline)
        fail(errc::no_exact_form, "a blending function given as a callable has no B-spline form; give it as a "
                                  "B-spline (knots and coefficients) for an exact conversion");
}

// Functions of one parameter (curves or their knot vectors) all closed or all open:
// a direction that mixes periodic ones with clamped ones (a closed boundary curve
// blended by open functions, say) merges as the clamped forms of all, the exact form
// of a surface that is closed only geometrically there.
template <class T>
void same_kind(std::vector<T>& xs) {
  const auto closed = [](const T& x) { return x.periodic(); };
  if (std::any_of(xs.begin(), xs.end(), closed) && !std::all_of(xs.begin(), xs.end(), closed))
    for (auto& x : xs) x = x.clamped();
}

}  // namespace

std::array<KnotVector, 2> BlendedSurface::exact_knots() const {
  const auto& T = *t_;
  require_exact_form(T);
  std::vector<KnotVector> ku, kv;
  for (const auto& s : T.f) ku.push_back(s.spline->knots());
  for (const auto& c : T.b) ku.push_back(c.knots());
  for (const auto& s : T.g) kv.push_back(s.spline->knots());
  for (const auto& c : T.a) kv.push_back(c.knots());
  same_kind(ku);
  same_kind(kv);
  return {merged_knots(snapped_together(ku)), merged_knots(snapped_together(kv))};  // as make_compatible
}

BSplineSurface BlendedSurface::to_bspline() const { return to_bspline(progress_callback{}); }

BSplineSurface BlendedSurface::to_bspline(const progress_callback& progress) const {
  const auto& T = *t_;
  require_exact_form(T);
  // Every function of u on one knot vector and degree, every function of v likewise.
  std::vector<BSplineCurve> us, vs;
  for (const auto& s : T.f) us.push_back(*s.spline);
  for (const auto& s : T.g) vs.push_back(*s.spline);
  us.insert(us.end(), T.b.begin(), T.b.end());
  vs.insert(vs.end(), T.a.begin(), T.a.end());
  same_kind(us);
  same_kind(vs);
  const auto cu = make_compatible(us), cv = make_compatible(vs);
  const std::size_t nf = T.f.size(), ng = T.g.size(), na = T.a.size();
  const KnotVector& ku = cu.front().knots();
  const KnotVector& kv = cv.front().knots();
  const auto nu = static_cast<std::size_t>(ku.count()), nv = static_cast<std::size_t>(kv.count());
  // With f_k = Σ_x F[x][k] N_x(u) and g_l = Σ_y G[y][l] N_y(v), control point (x, y) is
  //   Σ_k F[x][k] a_k[y] + Σ_l G[y][l] B[x][l],  B[x][l] = b_l[x] + Σ_k c_kl F[x][k],
  // B being the factor of g_l. Per u index: F and B; per v index: the curves a_k and
  // the coefficients of g_l, each over the range where they are not zero.
  std::vector<double> F(nu * nf);
  for (std::size_t k = 0; k < nf; ++k)
    for (std::size_t x = 0; x < nu; ++x) F[x * nf + k] = cu[k].control_points()[x].x;
  const std::size_t nb = T.b.empty() && T.c.empty() ? 0 : ng;
  std::vector<Vec3> B(nu * nb);
  for (std::size_t x = 0; x < nu; ++x)
    for (std::size_t l = 0; l < nb; ++l) {
      Vec3 p = l < T.b.size() ? cu[nf + l].control_points()[x] : Vec3{};
      if (!T.c.empty())
        for (std::size_t k = 0; k < nf; ++k) p += F[x * nf + k] * T.c(k, l);
      B[x * nb + l] = p;
    }
  std::vector<detail::Coefficients> G;
  for (std::size_t l = 0; l < nb; ++l) G.push_back(detail::coefficients(cv[l]));
  // One pass over the net: each control point written once, by one thread, with the
  // a_k of the nonzero F[x][k] and the g_l that are not zero over each stretch.
  PointGrid P({nu, nv}, for_overwrite);
  const auto rows = static_cast<long long>(nu);
  detail::ParallelFailure failure;  // making the terms' vectors of a thread
  detail::RegionProgress report(progress);
  std::atomic<std::size_t> done{0};
#pragma omp parallel if (nu * nv * (na + nb) >= detail::parallel_min_work)
  {
    std::vector<detail::LineTerm> lines;
    std::vector<detail::PointTerm> points;
    failure.attempt(static_cast<std::size_t>(detail::thread_index()), [&] {
      lines.reserve(na);  // a stretch's terms at most: push_back below never allocates
      points.reserve(nb);
    });
#pragma omp for schedule(static)
    for (long long r = 0; r < rows; ++r) {
      if (failure.failed() || report.stopped()) continue;  // a failure, or stopped by the progress callback
      const auto x = static_cast<std::size_t>(r);
      detail::fill_row(&P(x, 0).x, nv, lines, points, [&](std::size_t y0, std::size_t y1, auto& ls, auto& ps) {
        for (std::size_t k = 0; k < na; ++k)
          if (const double f = F[x * nf + k]; f != 0.0) ls.push_back({f, &cv[ng + k].control_points()[y0].x});
        for (std::size_t l = 0; l < nb; ++l)
          if (const Vec3& b = B[x * nb + l]; b != Vec3{} && G[l].lo < y1 && G[l].hi > y0)
            ps.emplace_back(G[l].c.data() + 3 * y0, b);
      });
      const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
      if (detail::thread_index() == 0 && d % 64 == 0) report.report(static_cast<double>(d) / static_cast<double>(nu));
    }
  }
  failure.rethrow();
  report.rethrow();
  if (progress) progress(1.0);
  return BSplineSurface(ku, kv, std::move(P));
}

}  // namespace interpatch
