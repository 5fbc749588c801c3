// The curves of a network placed at the common parameters: the cardinal functions
// that blend them, which curves are kept as drawn and which re-expressed through their
// crossings, and each curve's line of the surface against the curve given.
#include <algorithm>
#include <cmath>
#include <optional>

#include "base/parallel.hpp"
#include "constructions/network/network_build.hpp"
#include "interpatch/interpolate.hpp"

namespace interpatch::detail {

namespace {

// Σ_k g_k φ_k(t) for the cardinal functions φ_k (B-splines on one knot vector) as one curve.
BSplineCurve combination(const std::vector<Scalar>& phi, const std::vector<Vec3>& g) {
  const BSplineCurve& first = *phi.front().spline;
  std::vector<Vec3> cp(first.control_points().size());
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const auto& c = phi[k].spline->control_points();
    INTERPATCH_ASSERT(c.size() == cp.size());
    for (std::size_t q = 0; q < cp.size(); ++q) cp[q] += c[q].x * g[k];
  }
  return BSplineCurve(first.knots(), std::move(cp));
}

}  // namespace

std::vector<Scalar> cardinals(const std::vector<double>& t, NetworkMethod method, bool closed) {
  const std::size_t n = t.size();
  std::vector<Scalar> out;
  out.reserve(n);
  if (method == NetworkMethod::coons_linear) {
    // Hat functions; closed, basis function i of the periodic knots t peaks at t_i,
    // and the one of the last node falls to 0 at 1, where the first rises from.
    std::vector<double> k{t.front()};
    k.insert(k.end(), t.begin(), t.end());
    k.push_back(t.back());
    const KnotVector kv = closed ? KnotVector::periodic_from(1, t, 1.0) : KnotVector(1, k);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> c(n, 0.0);
      c[i] = 1.0;
      out.push_back(scalar(kv, c));
    }
  } else if (method == NetworkMethod::coons_hermite) {
    // α0/α1 of each cell in Bézier form: the two control coefficients next to node
    // i are 1, all others 0; double interior knots keep the pieces C1 (f' = 0 at nodes).
    // Closed: every node a double knot, the seam too, and the two coefficients of
    // node i are 2i + 1 and 2i + 2 (the seam's, 2n − 1 and 0, wrapped).
    std::vector<double> k;
    if (closed) {
      for (double x : t) k.insert(k.end(), 2, x);
    } else {
      k.assign(4, t.front());
      for (std::size_t i = 1; i + 1 < n; ++i) k.insert(k.end(), 2, t[i]);
      k.insert(k.end(), 4, t.back());
    }
    const KnotVector kv = closed ? KnotVector::periodic_from(3, k, 1.0) : KnotVector(3, k);
    const std::size_t shift = closed ? 1 : 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<double> c(2 * n, 0.0);
      c[(2 * i + shift) % (2 * n)] = c[(2 * i + 1 + shift) % (2 * n)] = 1.0;
      out.push_back(scalar(kv, c));
    }
  } else {
    CurveInterpolationOptions o;
    o.degree = std::min<int>(3, static_cast<int>(n) - 1);
    o.params = t;
    o.periodic = closed;
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<Vec3> e(n);
      e[i] = {1, 0, 0};
      if (!closed) {
        out.push_back(interpolate_curve(e, o).curve);
        continue;
      }
      // y = k keeps the last point from repeating the first (both 0 in x for most i),
      // which closed interpolation would take for a closing point; the x coordinates
      // are solved for independently of y, and only they are kept.
      for (std::size_t k = 0; k < n; ++k) e[k].y = static_cast<double>(k);
      const BSplineCurve c = interpolate_curve(e, o).curve;
      std::vector<double> x;
      x.reserve(c.control_points().size());
      for (const Vec3& q : c.control_points()) x.push_back(q.x);
      out.push_back(scalar(c.knots(), x));
    }
  }
  return out;
}

Plan plan(const Prepared& n, const Arrangement& r, int a, std::vector<NetworkCurveReport>& report) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const auto& along = n.along[az];
  const bool closed = n.closed[az];
  std::vector<double> at = r.params[bz];
  if (closed) at.push_back(1.0);
  Plan out;
  for (std::size_t k = 0; k < along.size(); ++k) {
    const std::size_t j = r.order[az][k];
    NetworkCurveReport& rep = report[j];
    rep.position = k;
    rep.reversed = r.reversed[az][j];
    rep.degenerate = r.degenerate[az][j];
    const auto& to = r.to[az][j];
    bool keep = !rep.reversed;
    for (std::size_t q = 0; keep && q < at.size() && !rep.degenerate; ++q)
      keep = distance(along[j].point(at[q]), along[j].point(to[q])) <= r.keep;
    rep.reexpressed = !keep;
    rep.map = keep ? monotone_map({0.0, 1.0}, {0.0, 1.0}, false) : monotone_map(at, to, closed);
    out.keep.push_back(keep);
    // A re-expressed curve interpolates C(map(u_i)) = C(to_i) at u_i.
    std::vector<Vec3> pts;
    for (std::size_t i = 0; i < r.params[bz].size(); ++i) pts.push_back(along[j].point(keep ? at[i] : to[i]));
    out.node.push_back(std::move(pts));
  }
  return out;
}

std::vector<BSplineCurve> place_curves(const Prepared& n, const Arrangement& r, int a, const Plan& mine,
                                       const Plan& other, const std::vector<Scalar>& phi,
                                       std::vector<NetworkCurveReport>& report) {
  const auto az = static_cast<std::size_t>(a), bz = 1 - az;
  const auto& along = n.along[az];
  const bool closed = n.closed[az];
  const double target = 0.5 * n.fit();
  std::vector<std::optional<BSplineCurve>> out(along.size());
  std::vector<std::size_t> redo;  // positions of the curves to re-express
  std::vector<FitJob> jobs;
  std::vector<BSplineCurve> G;
  G.reserve(along.size());
  for (std::size_t k = 0; k < along.size(); ++k) {
    std::vector<Vec3> g(other.node.size());
    for (std::size_t i = 0; i < g.size(); ++i) g[i] = 0.5 * (other.node[i][k] - mine.node[k][i]);
    G.push_back(combination(phi, g));
  }
  // How far each kept curve's line of the surface is from the given curve: a few
  // points per knot interval, the curves shared between the threads.
  parallel_for(along.size(), along.size() > 1, Share::one_by_one, [&](std::size_t k) {
    if (!mine.keep[k]) return;
    const std::size_t j = r.order[az][k];
    const BSplineCurve& given = n.input[az][j];
    const std::vector<double> own = check_params(along[j].knots());
    const std::vector<Vec3> line = points_at(along[j], own), g = points_at(G[k], own);
    std::vector<double> at = own;
    if (closed)
      for (double& u : at) u -= std::floor(u);
    // A curve taken as given is its line's curve: its points are those already
    // found, but where a closed curve's parameter wrapped.
    std::vector<Vec3> want;
    if (n.reshaped[az][j]) {
      want = points_at(given, at);
    } else {
      want = line;
      for (std::size_t i = 0; i < at.size(); ++i)
        if (at[i] != own[i]) want[i] = given.point(at[i]);
    }
    double d = 0;
    for (std::size_t i = 0; i < at.size(); ++i) d = std::max(d, distance(line[i] + g[i], want[i]));
    report[j].distance = d;
  });
  for (std::size_t k = 0; k < along.size(); ++k) {
    const std::size_t j = r.order[az][k];
    const BSplineCurve& given = n.input[az][j];
    if (mine.keep[k]) {
      out[k] = along[j];
      continue;
    }
    redo.push_back(k);
    jobs.push_back({&along[j], n.reshaped[az][j] ? &given : nullptr, &G[k], report[j].map});
  }
  if (!redo.empty()) {
    std::vector<Refit> fits;
    try {
      fits = refit(jobs, r.params[bz], closed, target);
    } catch (const RefitShortfall& e) {
      fail(errc::tolerance_not_met, n.name(a, r.order[az][redo[e.job()]]), ": ", e.what());
    }
    for (std::size_t q = 0; q < redo.size(); ++q) {
      auto& rep = report[r.order[az][redo[q]]];
      rep.fit_error = fits[q].error;
      rep.distance = fits[q].distance;
      out[redo[q]] = std::move(fits[q].curve);
    }
  }
  std::vector<BSplineCurve> placed;
  placed.reserve(out.size());
  for (auto& c : out) placed.push_back(std::move(*c));
  return placed;
}

}  // namespace interpatch::detail
