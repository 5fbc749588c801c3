// The promise harness for scattered points (approximate with an (N, 3) list): random
// smooth sheets in hostile frames, sites from x and y, the least-squares plane or
// given, voids, missing points and weights, every way of asking (λ given or "auto");
// each case built through io::build as a user's spec is, and checked by the harness's
// own Cox–de Boor at every point's site: a tolerance met at every point present,
// "xy"'s x(u, v) = u, a finite control net near the data, and info's report in
// agreement.

#include <gtest/gtest.h>

#include "promise_harness.hpp"

namespace interpatch::promise {
namespace {

constexpr std::size_t kCases = 400;

// The documented codes of scattered points for well-formed input.
const std::set<errc> kScatteredCodes = {errc::too_few_points, errc::singular, errc::tolerance_not_met,
                                        errc::ill_conditioned};

struct Sheet {
  double a[6];  // z = a0 sin(a1 x + a2) cos(a3 y) + a4 x + a5 y, on x, y in [-1, 1]
  [[nodiscard]] double z(double x, double y) const { return a[0] * std::sin(a[1] * x + a[2]) * std::cos(a[3] * y) + a[4] * x + a[5] * y; }
};

json make_case(std::mt19937_64& g) {
  const Frame f = random_frame(g);
  Sheet s{};
  for (double& c : s.a) c = uni(g, -2, 2);
  const int n = pick(g, 10, 700);
  const double noise = chance(g, 0.5) ? 0.0 : uni(g, 0, 0.05);
  const bool void_too = chance(g, 0.3);
  json pts = json::array();
  json sites = json::array();
  for (int k = 0; k < n; ++k) {
    const double x = uni(g, -1, 1), y = uni(g, -0.7, 0.7);
    Vec3 p = f.at({x, y, s.z(x, y) + noise * uni(g, -1, 1)});
    json jp = to_json(p);
    if (chance(g, 0.03) || (void_too && x * x + y * y < 0.09)) jp[2] = nullptr;  // missing
    pts.push_back(jp);
    sites.push_back({x, y});
  }
  json spec = {{"type", "approximate"}, {"points", pts}};
  const int param = pick(g, 0, 2);
  if (param == 0) spec["param"] = "xy";
  else if (param == 1 && chance(g, 0.5)) spec["param"] = "plane";
  else if (param == 2) spec["param"] = sites;
  const int way = pick(g, 0, 3);
  const double size = f.scale;
  if (way <= 1) {
    spec["tolerance"] = size * std::pow(10.0, uni(g, -4, -0.5));
    if (chance(g, 0.3)) spec["max_control_points"] = pick(g, 8, 80);
  } else if (way == 2) {
    spec["control_points"] = {pick(g, 4, 30), pick(g, 4, 30)};
  } else if (chance(g, 0.3)) {
    spec["smoothing"] = "auto";
  } else {
    spec["smoothing"] = std::pow(10.0, uni(g, -9, 3));
  }
  if (chance(g, 0.3)) spec["degree"] = {pick(g, 1, 4), pick(g, 1, 4)};
  if (chance(g, 0.2)) {
    json w = json::array();
    for (int k = 0; k < n; ++k) w.push_back(chance(g, 0.05) ? 0.0 : uni(g, 0.1, 3));
    spec["weights"] = w;
  }
  return spec;
}

void check_case(const json& spec, io::Construction& c, Findings& f) {
  Box box;
  std::vector<Vec3> q;
  std::vector<bool> present;
  for (std::size_t k = 0; k < spec["points"].size(); ++k) {
    const json& p = spec["points"][k];
    const bool here = !p[2].is_null() && (!spec.contains("weights") || spec["weights"][k].get<double>() > 0);
    q.push_back(here ? from_json(p) : Vec3{});
    present.push_back(here);
    if (here) box.add(q.back());
  }
  const auto t = exact_surface(c);
  if (!t) return f.add("no exact form");
  for (const Vec3& cp : t->cp)
    if (!box.holds(cp, 9 * box.diagonal() + rounding(box, 64))) return f.near("a control point far from the data", cp, box.lo, 9 * box.diagonal());
  const auto& params = c.data.at(0).params;
  // Rounding of the two evaluations: sums of basis × control points of the data's size.
  const double slack = rounding(box, 256);
  double worst = 0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    if (!present[k]) continue;
    const double d = distance(t->eval(params[0][k], params[1][k]).s, q[k]);
    worst = std::max(worst, d);
    if (spec.contains("tolerance") && !(d <= spec["tolerance"].get<double>() + slack))
      f.add("point " + std::to_string(k) + " is " + std::to_string(d) + " from the surface, tolerance " +
            std::to_string(spec["tolerance"].get<double>()));
  }
  if (spec.value("smoothing", json()) == "auto" && !(c.parameters["lambda"].get<double>() > 0)) f.add("\"auto\" reported no λ");
  const double reported = c.parameters["max_error"].get<double>();
  if (!(std::abs(reported - worst) <= 1e-9 * box.diagonal() + slack))
    f.add("info's max_error " + std::to_string(reported) + ", own evaluation " + std::to_string(worst));
  if (spec.value("param", json("plane")) == json("xy")) {
    const auto dom = c.parameters["domain"];
    for (double u : {0.0, 0.3, 1.0})
      for (double v : {0.0, 0.7, 1.0}) {
        const Vec3 p = t->eval(u, v).s;
        const double x = dom[0][0].get<double>() + u * (dom[0][1].get<double>() - dom[0][0].get<double>());
        const double y = dom[1][0].get<double>() + v * (dom[1][1].get<double>() - dom[1][0].get<double>());
        // x(u, v) = u to rounding: a few units in the last place of the coordinates.
        f.near("x and y of the height field", {p.x, p.y, 0}, {x, y, 0}, rounding(box, 64));
      }
  }
}

TEST(PromiseScattered, ScatteredPointsKeepTheirTolerance) {
  run_family("scattered", 0x5ca7, kCases, kScatteredCodes, make_case, check_case, 0.6);
}

}  // namespace
}  // namespace interpatch::promise
