// The promise harness for loft: random rows of sections in hostile frames — open
// curves in every form of a spec (interpolate, bspline with or without weights,
// hermite, line), closed ones (periodic interpolation, periodic B-splines, NURBS
// circles, open interpolants whose ends meet), given either way round and starting
// anywhere — stacked, or round a ring for a periodic loft; 2 to 9 of them, degree 1
// to 4 across, every parametrization or given parameters, sometimes tangents. Each
// case is built through io::build as a user's spec is, and checked by the harness's
// own Cox–de Boor evaluation of the exact form against its own evaluation of each
// section (own interpolation solves, open and periodic): every section reproduced
// along v = v_k through the map info reports, its data points, the sampled data,
// C^(q−1) across (simple knots), the seams, the tangents, and info's report.
// A second family mixes closed and open sections, which must be refused.

#include <gtest/gtest.h>

#include "promise_harness.hpp"

namespace interpatch::promise {
namespace {

// Cases in the default run (times INTERPATCH_PROMISE_CASES).
constexpr std::size_t kCases = 300;
constexpr std::uint64_t kSeed = 0x10f7;

// The documented codes for well-formed input: the curve forms' (the sections and
// tangents are read first; the generator makes none of the malformed ones, but near
// coincident points may make an interpolation singular) and the loft's for input it
// may not manage: a section not reproduced (sections nearly on top of one another),
// weights falling to 0 between sections of wildly different weights. Sections that
// cannot be re-expressed within the tolerance are merged, never refused.
const std::set<errc> kLoftCodes = {errc::too_few_points, errc::zero_chord, errc::invalid_degree, errc::non_increasing,
                                   errc::invalid_knots, errc::singular, errc::ill_conditioned, errc::invalid_weight};

// ------------------------------------------------------------------ own closed interpolation

/// The closed interpolant of degree p through q at parameters t in [0, 1) (the
/// closing chord included, docs/spec-format.md "Closed curves"): knots the parameters
/// themselves for odd p, the midpoints between them for even p, repeated with period
/// 1; the cyclic collocation system solved densely. Its domain is [K0, K0 + 1], K0
/// the first knot (0 for odd p).
std::optional<Tensor> own_periodic_interpolant(const std::vector<Vec3>& q, const std::vector<double>& t, int p,
                                               double* condition) {
  const std::size_t n = q.size(), pz = static_cast<std::size_t>(p);
  std::vector<double> K(n);
  for (std::size_t i = 0; i < n; ++i) K[i] = p % 2 ? t[i] : 0.5 * (t[i] + (i + 1 < n ? t[i + 1] : 1.0));
  Tensor c;
  c.dims = 1;
  c.p[0] = p;
  c.n[0] = n;
  c.periodic[0] = true;
  auto& k = c.knots[0];
  for (std::size_t i = n - pz; i < n; ++i) k.push_back(K[i] - 1.0);
  k.insert(k.end(), K.begin(), K.end());
  k.push_back(K[0] + 1.0);
  for (std::size_t i = 1; i <= pz; ++i) k.push_back(K[i] + 1.0);
  std::vector<double> A(n * n, 0.0);
  for (std::size_t r = 0; r < n; ++r) {
    const double x = t[r] < K[0] ? t[r] + 1.0 : t[r];  // into the domain
    const Basis b = own_basis(k, p, x);
    for (std::size_t e = 0; e < b.N.size(); ++e) A[r * n + (static_cast<std::size_t>(b.first) + e) % n] += b.N[e];
  }
  // The 1-norm condition number (n <= 13 here).
  *condition = own_matrix_condition(A, n);
  if (!std::isfinite(*condition)) return std::nullopt;
  c.cp = q;
  if (!own_solve(A, c.cp)) return std::nullopt;
  return c;
}

/// A closed curve Tensor (periodic, or clamped with its ends on one point) evaluated
/// at t in [0, 1] of its domain [a, b], wrapped by whole periods.
std::function<Vec3(double)> closed_eval(Tensor c) {
  return [c = std::move(c)](double t) {
    const auto [a, b] = c.domain(0);
    double x = t - std::floor(t);
    x = a + x * (b - a);
    return c.eval(std::clamp(x, a, b)).s;
  };
}

// ------------------------------------------------------------------ the cases

/// A section as the generator made it, with what the harness knows of it.
struct Section {
  SpecCurve c;             ///< spec, own evaluation over [0, 1], data points at their parameters, box
  int degree = 1;
  bool periodic = false;   ///< a periodic curve (closed ones may instead be open-knotted)
  bool backwards = false;  ///< an open one given from its end to its start
};

struct Case {
  std::vector<Section> sections;
  std::vector<std::optional<SpecCurve>> tangents;  ///< as given: none, 2, or one per section
  std::vector<int> tangent_degree;
  bool closed = false, periodic = false, mixed = false;
  int degree = 3;                  ///< asked for (3 when the spec leaves it out)
  std::vector<double> params;      ///< given ones, or empty
  std::string param = "chord";     ///< chord, centripetal, uniform or given
  Box box;                         ///< of the sections
  double tangent_size = 0;         ///< the largest tangent control point
};

Case current;  // the case being checked, from its generator

/// The degree of a spec curve: given, or its form's default.
int spec_degree(const json& s) {
  if (s.contains("line")) return 1;
  if (s.contains("hermite")) return 3;
  if (s.contains("bspline")) return s["bspline"]["degree"].get<int>();
  if (s.contains("degree")) return s["degree"].get<int>();
  return std::min(3, static_cast<int>(s["interpolate"].size()) - 1);
}

/// Where section k goes: a point of its local frame (size about 1) to the world.
/// Stacked: turned about z, scaled, moved sideways and raised by z. Round a ring: the
/// local x radial, y up, z along the ring, at angle phi, 4 from the axis.
struct Place {
  bool ring = false;
  double angle = 0, scale = 1, phi = 0;
  Vec3 shift{};
  [[nodiscard]] Vec3 operator()(const Frame& f, const Vec3& p) const {
    if (ring) {
      const Vec3 radial{std::cos(phi), std::sin(phi), 0}, along{-std::sin(phi), std::cos(phi), 0};
      return f.at((4 + p.x) * radial + Vec3{0, 0, p.y} + p.z * along);
    }
    const Vec3 q = scale * p;
    return f.at(Vec3{q.x * std::cos(angle) - q.y * std::sin(angle), q.x * std::sin(angle) + q.y * std::cos(angle), q.z} + shift);
  }
};

/// A closed section: a wobbly loop of 4 to 12 points with a random start, placed, in
/// one of four forms. No rational form when `rational` is false.
Section closed_section(std::mt19937_64& g, const Frame& f, const Place& at, bool rational) {
  Section s;
  s.c.closed = true;
  const std::size_t n = static_cast<std::size_t>(pick(g, 4, 12));
  const double phase = uni(g, 0, 1), wobble = uni(g, 0, 0.25), psi = uni(g, 0, 6.3);
  std::vector<Vec3> q;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * (double(i) + uni(g, -0.2, 0.2) + phase) / double(n);
    const double r = 1 + wobble * std::sin(2 * a + psi);
    q.push_back(at(f, Vec3{r * std::cos(a), r * std::sin(a), 0} + local_point(g, 0.05)));
  }
  const int form = pick(g, 0, rational ? 3 : 2);
  const std::string param = std::vector<std::string>{"uniform", "chord", "centripetal"}[static_cast<std::size_t>(pick(g, 0, 2))];
  if (form == 0) {  // periodic interpolation, the closing point repeated or not
    const int p = pick(g, 1, std::min(4, static_cast<int>(n) - 1));
    json pts = json::array();
    for (const Vec3& x : q) {
      pts.push_back(to_json(x));
      s.c.box.add(x);
    }
    if (chance(g, 0.3)) pts.push_back(to_json(q.front()));
    s.c.spec = {{"interpolate", pts}, {"periodic", true}, {"param", param}, {"degree", p}};
    s.degree = p;
    s.periodic = true;
    const std::vector<double> t = own_grid_params({q}, param, true);
    for (std::size_t i = 0; i < n; ++i) s.c.data.push_back({t[i], q[i]});
    s.c.data.push_back({1.0, q.front()});
    double cond = 1;
    if (auto own = own_periodic_interpolant(q, t, p, &cond)) {
      // evaluated over [0, 1] as the reader's curve is: the own domain may start at a
      // midpoint (even degrees), the parameter wrapped into it
      const double k0 = own->knots[0][static_cast<std::size_t>(p)];
      s.c.eval = [own = std::move(*own), k0](double x) {
        double y = x - std::floor(x);
        if (y < k0) y += 1.0;
        return own.eval(y).s;
      };
      s.c.cond = cond;
    }
  } else if (form == 1) {  // a periodic B-spline over [0, 1]
    const int p = pick(g, 1, std::min(4, static_cast<int>(n) - 1));
    Tensor t = random_periodic_curve(g, p, q);
    for (const Vec3& x : q) s.c.box.add(x);
    s.c.spec = curve_spec(t);
    s.degree = p;
    s.periodic = true;
    s.c.eval = closed_eval(std::move(t));
  } else if (form == 2) {  // an open interpolant through the loop and back to its start
    const int p = pick(g, 1, std::min(3, static_cast<int>(n)));
    std::vector<Vec3> r = q;
    r.push_back(q.front());
    json pts = json::array();
    for (const Vec3& x : r) {
      pts.push_back(to_json(x));
      s.c.box.add(x);
    }
    s.c.spec = {{"interpolate", pts}, {"param", param}, {"degree", p}};
    s.degree = p;
    const std::vector<double> t = own_params(r, param);
    for (std::size_t i = 0; i < r.size(); ++i) s.c.data.push_back({t[i], r[i]});
    if (auto own = own_interpolant(r, t, p)) s.c.eval = closed_eval(std::move(*own));
    s.c.cond = own_condition(t, p);
  } else {  // a NURBS circle (open knots, ends on one point), turned by a random angle
    const double h = std::sqrt(0.5), turn = uni(g, 0, 2 * std::numbers::pi);
    Tensor t;
    t.dims = 1;
    t.p[0] = 2;
    t.n[0] = 9;
    t.knots[0] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
    const double corner[9][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}, {1, 0}};
    for (const auto& c : corner) {
      const Vec3 local{c[0] * std::cos(turn) - c[1] * std::sin(turn), c[0] * std::sin(turn) + c[1] * std::cos(turn), 0};
      t.cp.push_back(at(f, local));
      s.c.box.add(t.cp.back());
    }
    t.w = {1, h, 1, h, 1, h, 1, h, 1};
    s.c.spec = curve_spec(t);
    s.c.rational = true;
    s.degree = 2;
    s.c.eval = closed_eval(std::move(t));
  }
  return s;
}

/// An open section across the local frame from one end to the other (along x
/// stacked, along y round a ring), in any form of a spec, either way round.
Section open_section(std::mt19937_64& g, const Frame& f, const Place& at, bool rational, bool backwards) {
  Section s;
  const Vec3 ends[2] = {at.ring ? Vec3{0, -3, 0} : Vec3{-3, 0, 0}, at.ring ? Vec3{0, 3, 0} : Vec3{3, 0, 0}};
  Vec3 A = at(f, ends[0] + local_point(g, 0.2)), B = at(f, ends[1] + local_point(g, 0.2));
  if (backwards) std::swap(A, B);
  s.c = random_open_curve(g, f, A, B, rational);
  s.degree = spec_degree(s.c.spec);
  s.backwards = backwards;
  return s;
}

/// A tangent (∂S/∂v along its section): vectors of about the height of the stack,
/// upward with noise; of the kind its section is (closed sections: a periodic curve
/// for a periodic one, ends on one point for an open-knotted one).
SpecCurve tangent_for(std::mt19937_64& g, const Frame& f, const Section& s, double height, int* degree) {
  const Frame vectors{Vec3{}, f.scale};  // no offset: vectors, not points
  auto vec = [&] { return vectors.at(Vec3{0, 0, height} + local_point(g, 0.4 * height)); };
  if (!s.c.closed) {
    SpecCurve t = random_open_curve(g, vectors, vec(), vec(), false);
    *degree = spec_degree(t.spec);
    return t;
  }
  const int p = pick(g, 1, 3);
  const std::size_t n = static_cast<std::size_t>(p + 1 + pick(g, 0, 3));
  Tensor c;
  c.dims = 1;
  c.p[0] = p;
  c.n[0] = n;
  for (std::size_t i = 0; i < n; ++i) c.cp.push_back(vec());
  if (s.periodic) {
    c.periodic[0] = true;
    c.knots[0] = random_periodic_knots(g, p, n);
  } else {
    c.knots[0] = random_clamped_knots(g, p, n, 0.0, 1.0);
    c.cp.back() = c.cp.front();
  }
  SpecCurve t;
  t.spec = curve_spec(c);
  t.closed = true;
  for (const Vec3& x : c.cp) t.box.add(x);
  *degree = p;
  t.eval = closed_eval(std::move(c));
  return t;
}

/// A random loft spec; `mix` puts open and closed sections together on purpose.
json make_loft(std::mt19937_64& g, bool mix) {
  Case k;
  const Frame f = random_frame(g);
  const std::size_t N = static_cast<std::size_t>(pick(g, 2, 9));
  k.periodic = !mix && N >= 3 && chance(g, 0.2);
  k.closed = chance(g, 0.4);
  k.mixed = mix;
  const bool rational = chance(g, 0.5);
  const bool tangents = !mix && !k.periodic && chance(g, 0.3);
  // Places: stacked with uneven steps, or round a ring at nearly even angles.
  std::vector<Place> places(N);
  double z = 0;
  for (std::size_t i = 0; i < N; ++i) {
    Place& p = places[i];
    p.ring = k.periodic;
    p.phi = 2 * std::numbers::pi * (double(i) + uni(g, -0.1, 0.1)) / double(N);
    p.angle = uni(g, -0.3, 0.3);
    p.scale = uni(g, 0.7, 1.3);
    p.shift = {uni(g, -0.3, 0.3), uni(g, -0.3, 0.3), z};
    z += uni(g, 1.2, 2.5);
  }
  std::vector<bool> open(N, !k.closed);
  if (mix) {  // at least one of each
    const std::size_t a = static_cast<std::size_t>(pick(g, 0, static_cast<int>(N) - 1));
    std::size_t b = static_cast<std::size_t>(pick(g, 0, static_cast<int>(N) - 2));
    if (b >= a) ++b;
    for (std::size_t i = 0; i < N; ++i) open[i] = chance(g, 0.5);
    open[a] = true;
    open[b] = false;
  }
  json sections = json::array();
  for (std::size_t i = 0; i < N; ++i) {
    const bool allow_rational = rational && !tangents;
    k.sections.push_back(open[i] ? open_section(g, f, places[i], allow_rational, i > 0 && chance(g, 0.3))
                                 : closed_section(g, f, places[i], allow_rational));
    sections.push_back(k.sections.back().c.spec);
    k.box.add(k.sections.back().c.box.lo);
    k.box.add(k.sections.back().c.box.hi);
  }
  json spec = {{"type", "loft"}, {"sections", sections}};
  if (chance(g, 0.7)) {
    k.degree = tangents ? pick(g, 2, 4) : pick(g, 1, 4);  // tangents need 2 or more across
    spec["degree"] = k.degree;
  }
  const int how = pick(g, 0, 4);
  if (how == 4) {  // given: uneven gaps, the closing gap too for a periodic loft
    const std::size_t gaps = k.periodic ? N : N - 1;
    std::vector<double> v{0.0};
    for (std::size_t i = 0; i < gaps; ++i) v.push_back(v.back() + uni(g, 0.5, 1));
    const double total = v.back();
    v.resize(N);
    for (double& x : v) x /= total;
    if (!k.periodic) v.back() = 1.0;
    k.params = v;
    k.param = "given";
    spec["param"] = v;
  } else if (how > 0) {
    k.param = std::vector<std::string>{"chord", "centripetal", "uniform"}[static_cast<std::size_t>(how - 1)];
    spec["param"] = k.param;
  }
  if (k.periodic || chance(g, 0.1)) spec["periodic"] = k.periodic;
  // A tolerance of its own now and then, never below the rounding of the coordinates
  // (a closed section's ends, computed, may miss each other by that).
  if (chance(g, 0.15)) spec["tolerance"] = std::max(k.box.diagonal() * std::pow(10.0, uni(g, -9, -4)), 64 * eps * k.box.magnitude());
  if (tangents) {
    const bool both_ends = chance(g, 0.5);
    json t = json::array();
    for (std::size_t i = 0; i < (both_ends ? 2 : N); ++i) {
      const std::size_t at = both_ends ? (i == 0 ? 0 : N - 1) : i;
      if (!both_ends && chance(g, 0.3)) {
        k.tangents.push_back(std::nullopt);
        k.tangent_degree.push_back(0);
        t.push_back(nullptr);
        continue;
      }
      int d = 1;
      k.tangents.push_back(tangent_for(g, f, k.sections[at], z, &d));
      k.tangent_degree.push_back(d);
      t.push_back(k.tangents.back()->spec);
      for (const Vec3& c : {k.tangents.back()->box.lo, k.tangents.back()->box.hi}) k.tangent_size = std::max(k.tangent_size, norm(c));
    }
    spec["tangents"] = t;
  }
  current = std::move(k);
  return spec;
}

// ------------------------------------------------------------------ the checks

// info's report of a section and of the knots: the brief's keys ("sections" keyed by
// pointer, "merged_knots", "section_knots", "reexpressed") or the reader's as first
// written ("loft_sections", "knots": {"merged", "largest_section", "reexpressed"}).
const nlohmann::ordered_json& section_info(const nlohmann::ordered_json& P, const std::string& ptr) {
  return P.at("loft_sections").at(ptr);
}

const nlohmann::ordered_json& knots_info(const nlohmann::ordered_json& P, const char* key) {
  return P.at("knots").at(key);
}

/// The summed squared distance between two rows of points about their centres.
double centred_sum(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  Vec3 ca{}, cb{};
  for (std::size_t i = 0; i < a.size(); ++i) {
    ca += a[i] / double(a.size());
    cb += b[i] / double(b.size());
  }
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Vec3 d = (a[i] - ca) - (b[i] - cb);
    s += dot(d, d);
  }
  return s;
}

void check_loft(const json& spec, io::Construction& c, Findings& f) {
  const Case& k = current;
  const std::size_t N = k.sections.size();
  // Tangents pull the surface out of the sections' box by up to |T| / 4 per Hermite
  // term (as for hermite_patch): the sane box grows by the largest tangent.
  Box grown = k.box;
  const double ts = k.tangent_size;
  grown.add(k.box.lo - Vec3{ts, ts, ts});
  grown.add(k.box.hi + Vec3{ts, ts, ts});
  // Rational sections: rounding of homogeneous sums grows by the spread of the weights.
  double spread = 1;
  if (c.exact && std::get<BSplineSurface>(*c.exact).rational()) {
    const auto& w = std::get<BSplineSurface>(*c.exact).weights();
    spread = *std::max_element(w.data(), w.data() + w.size()) / *std::min_element(w.data(), w.data() + w.size());
  }
  const auto t = check_surface_common(c, grown, f, 5, spread);
  if (!t) return f.add("a loft without an exact form");
  const auto& P = c.parameters;
  const bool reexpressed = knots_info(P, "reexpressed").get<bool>();
  const double tolerance = P.at("tolerance").get<double>();
  if (spec.contains("tolerance") && tolerance != spec["tolerance"].get<double>()) f.add("info's tolerance is not the spec's");

  // Degrees: along u the highest of the sections' and tangents'; across the asked
  // one, lowered to the count of conditions − 1.
  int p = 0;
  std::size_t conditions = N;
  for (const Section& s : k.sections) p = std::max(p, s.degree);
  for (std::size_t i = 0; i < k.tangents.size(); ++i)
    if (k.tangents[i]) {
      p = std::max(p, k.tangent_degree[i]);
      ++conditions;
    }
  const int q = std::min(k.degree, static_cast<int>(conditions) - 1);
  if (t->p[0] != p) f.add("degree along the sections " + std::to_string(t->p[0]) + ", want " + std::to_string(p));
  if (t->p[1] != q) f.add("degree across " + std::to_string(t->p[1]) + ", want " + std::to_string(q));
  if (P.at("degree")[0].get<int>() != t->p[0] || P.at("degree")[1].get<int>() != t->p[1]) f.add("info's degree is not the exact form's");

  // C^(q−1) across: every knot of the v direction inside the domain (a periodic
  // one's period, the seam included) is simple.
  {
    const auto& kv = t->knots[1];
    const std::size_t pq = static_cast<std::size_t>(t->p[1]);
    const std::size_t last = t->periodic[1] ? pq + t->n[1] : kv.size() - pq - 1;
    for (std::size_t i = t->periodic[1] ? pq : pq + 1; i < last; ++i)
      if (kv[i] == kv[i - 1] && (t->periodic[1] || (kv[i] > kv[pq] && kv[i] < kv[kv.size() - 1 - pq])))
        f.add("a v knot of multiplicity above 1 at " + std::to_string(kv[i]) + ": less than C^(q-1) across");
  }
  if (t->periodic[1] != k.periodic) f.add("periodic across: " + std::to_string(t->periodic[1]) + ", spec " + std::to_string(k.periodic));
  bool all_periodic = k.closed;
  for (const Section& s : k.sections) all_periodic = all_periodic && s.periodic;
  if (t->periodic[0] != all_periodic) f.add("periodic along the sections differs from the sections being periodic");
  if (P.at("closed").get<bool>() != k.closed) f.add("info's closed differs from the sections'");

  // The parameters across: from 0, increasing, to 1 (periodic: to below 1, and
  // perhaps 1 for the first section again); the given ones as given, uniform ones k / gaps.
  std::vector<double> v = P.at("params").get<std::vector<double>>();
  if (v.size() != N && !(k.periodic && v.size() == N + 1 && v.back() == 1.0))
    return f.add("info's params: " + std::to_string(v.size()) + " for " + std::to_string(N) + " sections");
  v.resize(N);
  if (v.front() != 0.0) f.add("the first section not at v = 0");
  for (std::size_t i = 1; i < N; ++i)
    if (!(v[i] > v[i - 1])) f.add("params not increasing at " + std::to_string(i));
  if (!k.periodic && v.back() != 1.0) f.add("the last section not at v = 1");
  if (k.periodic && !(v.back() < 1.0)) f.add("a periodic loft's last section not below v = 1");
  for (std::size_t i = 0; i < N; ++i) {
    const double gaps = double(k.periodic ? N : N - 1);
    const double want = k.param == "given" ? k.params[i] : k.param == "uniform" ? double(i) / gaps : v[i];
    if (!(std::abs(v[i] - want) <= 4 * eps)) f.add("v_" + std::to_string(i) + " = " + std::to_string(v[i]) + ", want " + std::to_string(want));
  }
  double dv = 1;
  for (std::size_t i = 1; i < N; ++i) dv = std::min(dv, v[i] - v[i - 1]);
  if (k.periodic) dv = std::min(dv, 1 - v.back());

  // Knots along u: merged as they are while that makes at most 4 times the largest
  // section's; beyond that re-expressed within the tolerance on fewer knots than
  // merging makes, or merged after all where the tolerance needs as many (sections
  // with many corners, polylines raised to a higher degree: no count is promised).
  const std::size_t merged = knots_info(P, "merged").get<std::size_t>();
  const std::size_t largest = knots_info(P, "largest_section").get<std::size_t>();
  const std::size_t made = t->knots[0].size();
  if (reexpressed && merged <= 4 * largest) f.add("re-expressed although merging makes at most 4 × the largest section's knots");
  if (!reexpressed && made != merged)
    f.add("knots along u: " + std::to_string(made) + ", the merged count " + std::to_string(merged) + " without re-expression");
  if (reexpressed && made >= merged)
    f.add("re-expressed on " + std::to_string(made) + " knots along u, no fewer than merging's " + std::to_string(merged));
  const double max_dev = P.at("max_deviation").get<double>();
  if (reexpressed && !(max_dev <= tolerance)) f.add("info's max_deviation above the tolerance");

  // Tolerances. Where the section's own evaluation sums the same numbers as the
  // surface's, data_tol (rounding of the data, amplified as the harness explains);
  // between an interpolating section's points, what its collocation system may
  // amplify too (check_curve_on); rational sections by the spread of the weights;
  // re-expressed sections by the tolerance besides.
  const double moved = reexpressed ? tolerance : 0.0;
  const double tol = moved + data_tol(k.box) * spread;
  const auto S = [&](double u, double vv) { return t->eval(u, vv).s; };

  for (std::size_t i = 0; i < N; ++i) {
    const Section& s = k.sections[i];
    const std::string ptr = "/sections/" + std::to_string(i);
    const auto& r = section_info(P, ptr);
    const bool closed = r.at("closed").get<bool>(), rev = r.at("reversed").get<bool>();
    if (closed != s.c.closed) f.add(ptr + ": reported closed " + std::to_string(closed));
    if (i == 0 && rev) f.add("the first section turned round: it sets the direction");
    // The section's parameter over [0, 1] at surface parameter u (the reader's curves,
    // like these, are over [0, 1]): turned, and for a closed one started at the seam.
    const double seam = closed ? r.at("seam").get<double>() : 0.0;
    if (i == 0 && closed && seam != 0.0) f.add("the first section's seam moved: it sets the seam");
    const auto along = [&](double u) {
      if (!closed) return rev ? 1 - u : u;
      const double x = rev ? seam - u : seam + u;
      return x - std::floor(x);
    };
    const auto inverse = [&](double x) {
      if (!closed) return rev ? 1 - x : x;
      const double u = rev ? seam - x : x - seam;
      return u - std::floor(u);
    };
    const double between = tol + s.c.cond * spread * (rounding(k.box, 8) + 1e-15 * k.box.diagonal());
    if (s.c.eval)
      for (int j = 0; j <= 16; ++j) {
        const double u = j / 16.0;
        f.near(ptr + " at u = " + std::to_string(u), S(u, v[i]), s.c.eval(along(u)), between);
      }
    for (std::size_t j = 0; j < s.c.data.size(); ++j)
      f.near(ptr + " data point " + std::to_string(j), S(inverse(s.c.data[j].first), v[i]), s.c.data[j].second, tol);
    // The sampled data (the section as given, through the reported map).
    if (i < c.data.size()) {
      const io::DataSet& d = c.data[i];
      if (d.params.size() != 2 || d.params[1].size() != 1 || d.points.size() != d.params[0].size()) {
        f.add(ptr + ": data not a row of samples on one v");
      } else {
        if (!(std::abs(d.params[1][0] - v[i]) <= 4 * eps)) f.add(ptr + ": data not at v_k");
        for (std::size_t j = 0; j < d.points.size(); j += 4)
          f.near(ptr + " sample " + std::to_string(j), S(d.params[0][j], v[i]), d.points[j], tol);
      }
    }
    // The turn of an open section, where the user's view of it is clear: the
    // generator's truth (given backwards or not, against the first) agrees with the
    // summed squared distance to the section before about their centres, which one
    // way round is at most 2/3 of the other.
    if (!s.c.closed && i > 0 && s.c.eval && k.sections[i - 1].c.eval) {
      const bool truth = s.backwards != k.sections[0].backwards;
      std::vector<Vec3> before, same, turned;
      const auto& prev = section_info(P, "/sections/" + std::to_string(i - 1));
      const bool prev_rev = prev.at("reversed").get<bool>();
      for (int j = 0; j <= 128; ++j) {
        const double u = j / 128.0;
        before.push_back(k.sections[i - 1].c.eval(prev_rev ? 1 - u : u));
        same.push_back(s.c.eval(u));
        turned.push_back(s.c.eval(1 - u));
      }
      const double a = centred_sum(same, before), b = centred_sum(turned, before);
      const bool clear = truth ? b <= a * 2 / 3 : a <= b * 2 / 3;
      if (clear && rev != truth) f.add(ptr + ": turned round " + std::to_string(rev) + ", but it runs " + (truth ? "against" : "with") + " the section before");
    }
    // Tangents: ∂S/∂v along the section at the section's own parameter. The derivative
    // rows of the solve across have entries of about q / Δv: rounding of the data and
    // of the tangents grows by that (4 q / Δv), and a re-expression moves it by up to
    // the tolerance over the same spacing. The own evaluation of an interpolating
    // tangent differs from the library's as a section's does (its condition).
    // Its tangent's slot as given: two (first and last) or one per section.
    const std::size_t none = k.tangents.size();
    const std::size_t slot = k.tangents.size() == 2 && N > 2 ? (i == 0 ? 0 : (i + 1 == N ? 1 : none)) : i;
    if (slot < none && k.tangents[slot] && k.tangents[slot]->eval) {
      const SpecCurve& T = *k.tangents[slot];
      const double amp = 4.0 * q / dv;
      const double dtol = (data_tol(k.box) + 1e-10 * ts + moved) * amp + data_tol(T.box) +
                          T.cond * (rounding(T.box, 8) + 1e-15 * T.box.diagonal());
      for (int j = 0; j <= 8; ++j) {
        const double u = j / 8.0;
        f.near(ptr + " tangent at u = " + std::to_string(u), t->eval(u, v[i]).d[1], T.eval(along(u)), dtol);
      }
    }
  }
  // Closed sections: the edges u = 0 and u = 1 meet (a periodic surface wraps; an
  // open-knotted one's edge columns are the sections' common ends).
  if (k.closed)
    for (double x : {0.0, 0.3, 0.7, 1.0}) f.near("edges u = 0 and 1 at v = " + std::to_string(x), S(0, x), S(1, x), tol);
  // A periodic loft closes across: v = 0 and v = 1 are the first section, both sides
  // of the seam (the own evaluation at 1 takes the last span), to rounding; and from
  // degree 2 on the derivative across too (rounding amplified by q / Δv).
  if (k.periodic)
    for (double u : {0.0, 0.4, 0.9}) {
      const Jet a = t->eval(u, 0.0), b = t->eval(u, 1.0);
      f.near("seam across at u = " + std::to_string(u), a.s, b.s, tol);
      if (q >= 2) f.near("∂S/∂v across the seam at u = " + std::to_string(u), a.d[1], b.d[1], (tol + data_tol(k.box)) * 4 * q / dv);
    }
}

TEST(PromiseLoft, SectionsReproducedSmoothAcross) {
  run_family("loft", kSeed, kCases, kLoftCodes, [](std::mt19937_64& g) { return make_loft(g, false); }, check_loft, 0.6);
}

TEST(PromiseLoft, ClosedAndOpenSectionsMixedAreRefused) {
  run_family(
      // closing_gap; or a curve the reader cannot interpolate: near-coincident points
      // (rounded onto each other far from the origin)
      "loft_mixed", kSeed + 1, kCases / 5, {errc::closing_gap, errc::singular, errc::zero_chord},
      [](std::mt19937_64& g) { return make_loft(g, true); },
      [](const json&, io::Construction&, Findings& f) { f.add("built, although closed and open sections are mixed"); }, 0.0);
}

}  // namespace
}  // namespace interpatch::promise
