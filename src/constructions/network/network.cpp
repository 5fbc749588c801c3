// A curve network's surface as drawn: the stages run in order (network_build.hpp),
// the report filled in, and the public entry points.
#include "interpatch/network.hpp"

#include <algorithm>
#include <memory>
#include <optional>

#include "constructions/network/network_build.hpp"

namespace interpatch {

namespace {

using detail::Arrangement;
using detail::Plan;
using detail::Prepared;

// The report as the arrangement gives it: the common parameters per curve as given
// (a closing curve: 1), and how far every pair of curves misses each other.
NetworkReport arranged_report(const CurveNetwork& network, const Prepared& n, const Arrangement& r) {
  NetworkReport rep;
  rep.tolerance = n.tol;
  rep.diagonal = n.diagonal;
  rep.strict = n.strict;
  rep.u_curves.resize(network.u_curves.size());
  rep.v_curves.resize(network.v_curves.size());
  for (int a = 0; a < 2; ++a) {
    const auto az = static_cast<std::size_t>(a);
    auto& out = a == 0 ? rep.v_params : rep.u_params;  // the parameters of family a
    out.assign((a == 0 ? network.u_curves : network.v_curves).size(), 1.0);
    for (std::size_t k = 0; k < r.order[az].size(); ++k) out[r.order[az][k]] = r.params[az][k];
  }
  for (std::size_t j = 0; j < r.X.size(); ++j)
    for (std::size_t i = 0; i < r.X[j].size(); ++i) {
      const double g = r.X[j][i].gap;
      rep.u_curves[j].max_gap = std::max(rep.u_curves[j].max_gap, g);
      rep.v_curves[i].max_gap = std::max(rep.v_curves[i].max_gap, g);
      if (g > rep.max_gap) {
        rep.max_gap = g;
        rep.max_gap_at = {j, i};
      }
    }
  return rep;
}

// Own parameters of the crossings, in the given curves' domains, and the maps.
void in_given_domains(const CurveNetwork& network, const Prepared& n, const Arrangement& r, NetworkReport& rep) {
  for (int a = 0; a < 2; ++a) {
    const auto az = static_cast<std::size_t>(a);
    const auto& given = a == 0 ? network.u_curves : network.v_curves;
    auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    for (std::size_t j = 0; j < n.along[az].size(); ++j) {
      const auto [lo, hi] = given[j].domain();
      auto& c = reports[j];
      c.crossings.clear();
      for (std::size_t k = 0; k < r.order[1 - az].size(); ++k)
        c.crossings.push_back(lo + detail::crossing_param(r, a, j, r.order[1 - az][k]) * (hi - lo));
      for (double& x : c.map.to) x = lo + x * (hi - lo);
      for (double& x : c.map.slope) x *= hi - lo;
      c.map.start = lo;
      c.map.period = n.closed[az] ? hi - lo : 0.0;
    }
  }
}

struct Built {
  std::optional<BlendedSurface> surface;
  NetworkReport report;
};

// The construction; with `fit` false only the parameters of the report.
Built build(const CurveNetwork& network, const NetworkOptions& options, bool fit) {
  Prepared n = detail::prepare(network, options);
  Arrangement r = detail::arrangement(n, network);
  NetworkReport rep = arranged_report(network, n, r);
  if (!fit) return {std::nullopt, std::move(rep)};
  const auto& tu = r.params[1];  // u of the v-curves, by position
  const auto& tv = r.params[0];
  auto t = std::make_shared<detail::BlendedTerms>();
  t->f = detail::cardinals(tu, options.method, n.closed[0]);
  t->g = detail::cardinals(tv, options.method, n.closed[1]);
  const Plan pu = detail::plan(n, r, 0, rep.u_curves), pv = detail::plan(n, r, 1, rep.v_curves);
  std::vector<BSplineCurve> U = detail::place_curves(n, r, 0, pu, pv, t->f, rep.u_curves);
  std::vector<BSplineCurve> V = detail::place_curves(n, r, 1, pv, pu, t->g, rep.v_curves);
  const std::size_t nu = V.size(), nv = U.size();
  t->c = PointGrid({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) t->c(i, j) = -0.5 * (U[j].point(tu[i]) + V[i].point(tv[j]));
  in_given_domains(network, n, r, rep);
  t->a = std::move(V);
  t->b = std::move(U);
  std::vector<std::string> far = detail::check_curves(network, n, r, t, rep);
  detail::check_closing(network, n, r, t, rep, far);
  detail::add_notes(network, n, r, rep, far, *t);
  return {BlendedSurface(std::move(t)), std::move(rep)};
}

}  // namespace

NetworkParameters network_parameters(const CurveNetwork& network, const NetworkOptions& options) {
  auto r = build(network, options, false).report;
  return {std::move(r.u_params), std::move(r.v_params)};
}

NetworkSurface network_surface(const CurveNetwork& network, const NetworkOptions& options) {
  auto b = build(network, options, true);
  return {std::move(*b.surface), std::move(b.report)};
}

BlendedSurface curve_network(const CurveNetwork& network, const NetworkOptions& options) {
  return std::move(*build(network, options, true).surface);
}

}  // namespace interpatch
