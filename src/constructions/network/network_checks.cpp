// A network's surface checked against the curves given, and the notes it carries:
// how far each curve's line (and a closing curve's, on the seam) is from the curve,
// and what the construction did to the curves.
#include <algorithm>

#include "constructions/network/network_build.hpp"
#include "interpatch/evaluate.hpp"

namespace interpatch::detail {

std::vector<std::string> check_curves(const CurveNetwork& network, const Prepared& n, const Arrangement& r,
                                      const std::shared_ptr<BlendedTerms>& t, NetworkReport& rep) {
  // Each curve against the finished surface: where curves of a family lie close
  // together their cardinal functions reach about 1/the gap, and spread what the
  // crossings' mismatch left over that far onto the other curves' lines.
  const BlendedSurface finished(t);
  for (int a = 0; a < 2; ++a) {
    const auto az = static_cast<std::size_t>(a);
    const auto& given = a == 0 ? network.u_curves : network.v_curves;
    auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    for (std::size_t k = 0; k < r.order[az].size(); ++k) {
      const std::size_t j = r.order[az][k];
      const double at = r.params[az][k];
      double d = 0;
      for (double x : linspace(0, 1, 129))
        d = std::max(d, distance(a == 0 ? finished.point(x, at) : finished.point(at, x), given[j].point(reports[j].map(x))));
      reports[j].distance = std::max(reports[j].distance, d);
    }
  }
  const double strict = n.strict;
  std::vector<std::string> far;
  for (int a = 0; a < 2; ++a) {
    const auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    for (std::size_t j = 0; j < n.along[static_cast<std::size_t>(a)].size(); ++j)
      if (reports[j].distance > strict) far.push_back(cat(n.name(a, j), " by ", reports[j].distance));
  }
  return far;
}

void check_closing(const CurveNetwork& network, const Prepared& n, const Arrangement& r,
                   const std::shared_ptr<BlendedTerms>& t, NetworkReport& rep, std::vector<std::string>& far) {
  const double strict = n.strict;
  for (int a = 0; a < 2; ++a) {
    if (!n.closing[static_cast<std::size_t>(1 - a)]) continue;
    auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    const auto& given = a == 0 ? network.u_curves : network.v_curves;
    NetworkCurveReport& c = reports.back();
    const std::size_t seam = r.order[static_cast<std::size_t>(a)].front();
    c = reports[seam];
    c.closing = true;
    c.position = n.along[static_cast<std::size_t>(a)].size();
    // Plain variables, not structured bindings: the lambda below captures them.
    const double lo = given.back().domain().first, hi = given.back().domain().second;
    const double slo = given[seam].domain().first, shi = given[seam].domain().second;
    // Drawn the other way round from the seam curve: its parameter runs back.
    const auto& unit = n.input[static_cast<std::size_t>(a)];
    double ahead = 0, back = 0;
    for (double x : linspace(0, 1, 129)) {
      ahead = std::max(ahead, distance(unit[seam].point(x), unit.back().point(x)));
      back = std::max(back, distance(unit[seam].point(x), unit.back().point(1 - x)));
    }
    const bool turn = back < ahead;
    if (turn) c.reversed = !c.reversed;
    const auto move = [&](double x) {
      const double f = (x - slo) / (shi - slo);
      return lo + (turn ? 1 - f : f) * (hi - lo);
    };
    for (double& x : c.map.to) x = move(x);
    for (double& x : c.map.slope) x *= (turn ? -1 : 1) * (hi - lo) / (shi - slo);
    for (double& x : c.crossings) x = move(x);
    c.map.start = lo;
    if (c.map.period > 0) c.map.period = hi - lo;
    double d = 0;
    const BlendedSurface probe(t);
    for (double x : linspace(0, 1, 129)) {
      const Vec3 s = a == 0 ? probe.point(x, 1.0) : probe.point(1.0, x);
      d = std::max(d, distance(s, given.back().point(c.map(x))));
    }
    c.distance = d;
    if (d > strict) far.push_back(cat(n.name(a, given.size() - 1), " by ", d));
  }
}

void add_notes(const CurveNetwork& network, Prepared& n, const Arrangement& r, const NetworkReport& rep,
               const std::vector<std::string>& far, BlendedTerms& t) {
  const double strict = n.strict;
  const bool found = network.u_params.empty() || network.v_params.empty();
  t.notes = std::move(n.notes);
  if (found) t.notes.push_back("crossing parameters found from the curves");
  for (int a = 0; a < 2; ++a) {
    const auto& reports = a == 0 ? rep.u_curves : rep.v_curves;
    std::vector<std::size_t> re, turned;
    double worst = 0;
    bool sorted = true;
    for (std::size_t j = 0; j < reports.size(); ++j) {
      if (reports[j].reexpressed) {
        re.push_back(j);
        worst = std::max(worst, reports[j].fit_error);
      }
      if (reports[j].reversed) turned.push_back(j);
      if (!reports[j].closing && reports[j].position != j) sorted = false;
    }
    if (!sorted) {
      std::vector<std::size_t> o(r.order[static_cast<std::size_t>(a)]);
      t.notes.push_back(cat(curves_name(a), " sorted into the order ", index_list(o)));
    }
    if (!turned.empty()) t.notes.push_back(cat(curves_name(a), " ", index_list(turned), " turned round to run with the others"));
    if (!re.empty())
      t.notes.push_back(cat(curves_name(a), " ", index_list(re), " re-expressed with their crossings at the common "
                            "parameters, within ", worst, " of the curves given"));
  }
  if (!far.empty()) {
    std::string s;
    for (const auto& f : far) s += (s.empty() ? "" : ", ") + f;
    t.notes.push_back(cat("the surface departs from ", s, ": more than ",
                          n.strict > 1e-7 * n.diagonal ? "the rounding of its coordinates" : "1e-7 of the diagonal",
                          " (", strict, "); the tolerance ", n.tol, " lets curves miss each other by that much"));
  }
}

}  // namespace interpatch::detail
