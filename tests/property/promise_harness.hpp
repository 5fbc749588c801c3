#pragma once
// The promise harness (issue 36): seeded random specs for every construction
// family, built through io::build exactly as a user's spec is, and checked by an
// evaluation that shares no code with the construction:
//
// - an own Cox–de Boor evaluation (the recursive definition of N_i,p over the whole
//   knot vector, not the library's triangular table) of the exact form's knots,
//   control points and weights, with first derivatives;
// - own evaluations of the defining formulas (bilinear, ruled, Coons, trilinear,
//   Hermite) from the spec's own curves, which the harness evaluates itself: lines,
//   B-splines and NURBS by the same Cox–de Boor, Hermite curves by their cubics, open
//   interpolating curves by an own solve of the interpolation system (parameters from
//   the points, knots by averaging, dense elimination).
//
// Every case's generator is an std::mt19937_64 seeded from the family's fixed seed
// and the case index, so a failure prints both and INTERPATCH_PROMISE_REPLAY=<index>
// runs that case alone. INTERPATCH_PROMISE_CASES=<k> multiplies the number of cases
// (make promise; 0.2 in the sanitizer run).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::promise {

using json = nlohmann::json;
inline constexpr double eps = std::numeric_limits<double>::epsilon();

// ------------------------------------------------------------------ how many cases

/// `base` cases times INTERPATCH_PROMISE_CASES (1 when unset or not a positive
/// number), at least one: long runs multiply it (make promise); the sanitizer run,
/// which looks for memory and undefined-behaviour errors rather than for inputs the
/// Release run has not tried, takes a tenth (CMakePresets.json, test preset asan).
inline std::size_t case_count(std::size_t base) {
  const char* m = std::getenv("INTERPATCH_PROMISE_CASES");
  double k = m ? std::strtod(m, nullptr) : 1.0;
  if (!(k > 0) || !std::isfinite(k)) k = 1.0;
  return std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(static_cast<double>(base) * k)));
}

/// INTERPATCH_PROMISE_REPLAY=<index>: only that case of each family runs.
inline std::optional<std::size_t> replay_case() {
  const char* r = std::getenv("INTERPATCH_PROMISE_REPLAY");
  if (!r || !*r) return std::nullopt;
  return static_cast<std::size_t>(std::strtoull(r, nullptr, 10));
}

/// The generator of case `index` of the family seeded `seed`.
inline std::mt19937_64 case_rng(std::uint64_t seed, std::size_t index) {
  std::seed_seq s{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                  static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32)};
  return std::mt19937_64(s);
}

inline double uni(std::mt19937_64& g, double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
inline int pick(std::mt19937_64& g, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(g); }
inline bool chance(std::mt19937_64& g, double p) { return uni(g, 0, 1) < p; }

// ------------------------------------------------------------------ own Cox–de Boor

/// The nonzero B-spline basis functions of degree p at t, and their first
/// derivatives, over `knots` (clamped or the extended knots of a periodic vector), by
/// the recursive definition: N_i,0 is the indicator of the span holding t, N_i,k the
/// Cox–de Boor combination of N_i,k-1 and N_i+1,k-1 (a 0/0 term is 0). The span is
/// the last [k_s, k_s+1) with k_s <= t among those inside the domain [k_p, k_nb]; at
/// the domain's end the last non-empty one.
struct Basis {
  int first = 0;              ///< index of the first nonzero function
  std::vector<double> N, dN;  ///< N_first..N_first+p and their derivatives
};

inline Basis own_basis(const std::vector<double>& k, int p, double t) {
  const int nb = static_cast<int>(k.size()) - p - 1;  // basis functions
  int s = p;
  for (int i = p; i < nb; ++i)
    if (k[i] <= t && k[i] < k[i + 1]) s = i;
  const int len = static_cast<int>(k.size()) - 1;
  std::vector<double> lower(static_cast<std::size_t>(len), 0.0), cur;
  lower[s] = 1.0;
  auto term = [&](double num, double den, double v) { return den > 0 ? num / den * v : 0.0; };
  std::vector<double> below;  // degree p-1, for the derivatives
  for (int d = 1; d <= p; ++d) {
    cur.assign(static_cast<std::size_t>(len - d), 0.0);
    for (int i = 0; i < len - d; ++i)
      cur[i] = term(t - k[i], k[i + d] - k[i], lower[i]) + term(k[i + d + 1] - t, k[i + d + 1] - k[i + 1], lower[i + 1]);
    if (d == p) below = lower;
    lower = cur;
  }
  if (p == 0) below = lower;
  Basis b;
  b.first = s - p;
  for (int i = s - p; i <= s; ++i) {
    b.N.push_back(lower[i]);
    const double a = k[i + p] > k[i] ? p / (k[i + p] - k[i]) * below[i] : 0.0;
    const double c = k[i + p + 1] > k[i + 1] ? p / (k[i + p + 1] - k[i + 1]) * below[i + 1] : 0.0;
    b.dN.push_back(a - c);
  }
  return b;
}

/// A point with its first partial derivatives.
struct Jet {
  Vec3 s, d[3];
};

/// A tensor-product B-spline of 1, 2 or 3 parameters in plain arrays: what the
/// oracle evaluates. Control point (i, j, k) is cp[(i * n1 + j) * n2 + k] with n the
/// counts of control points (in a periodic direction the distinct ones: basis
/// function i belongs to control point i mod n).
struct Tensor {
  int dims = 0;
  int p[3] = {0, 0, 0};
  std::vector<double> knots[3];
  std::size_t n[3] = {1, 1, 1};
  std::vector<Vec3> cp;
  std::vector<double> w;  // empty: polynomial
  bool periodic[3] = {false, false, false};

  /// The point and derivatives at (t0, t1, t2), the unused ones ignored.
  [[nodiscard]] Jet eval(double t0, double t1 = 0, double t2 = 0) const {
    const double t[3] = {t0, t1, t2};
    Basis b[3];
    for (int a = 0; a < 3; ++a) {
      if (a < dims)
        b[a] = own_basis(knots[a], p[a], t[a]);
      else
        b[a] = Basis{0, {1.0}, {0.0}};
    }
    // Homogeneous sums: A = Σ N w P, W = Σ N w, and their derivatives.
    Vec3 A{}, dA[3]{};
    double W = 0, dW[3] = {0, 0, 0};
    for (std::size_t x = 0; x < b[0].N.size(); ++x)
      for (std::size_t y = 0; y < b[1].N.size(); ++y)
        for (std::size_t z = 0; z < b[2].N.size(); ++z) {
          const std::size_t i = static_cast<std::size_t>(b[0].first + static_cast<int>(x)) % n[0];
          const std::size_t j = static_cast<std::size_t>(b[1].first + static_cast<int>(y)) % n[1];
          const std::size_t l = static_cast<std::size_t>(b[2].first + static_cast<int>(z)) % n[2];
          const std::size_t at = (i * n[1] + j) * n[2] + l;
          const double wt = w.empty() ? 1.0 : w[at];
          const double f = b[0].N[x] * b[1].N[y] * b[2].N[z];
          const double df[3] = {b[0].dN[x] * b[1].N[y] * b[2].N[z], b[0].N[x] * b[1].dN[y] * b[2].N[z],
                                b[0].N[x] * b[1].N[y] * b[2].dN[z]};
          A += (f * wt) * cp[at];
          W += f * wt;
          for (int a = 0; a < 3; ++a) {
            dA[a] += (df[a] * wt) * cp[at];
            dW[a] += df[a] * wt;
          }
        }
    Jet r;
    r.s = A / W;
    for (int a = 0; a < 3; ++a) r.d[a] = (dA[a] - dW[a] * r.s) / W;
    return r;
  }

  /// The domain of direction a: [k_p, k_(count + p)] (clamped: the last knot).
  [[nodiscard]] std::pair<double, double> domain(int a) const {
    const auto& k = knots[a];
    return {k[static_cast<std::size_t>(p[a])], k[k.size() - 1 - static_cast<std::size_t>(p[a])]};
  }

  /// Largest |coordinate| of a control point: the scale of the rounding of any sum
  /// of them with weights summing to 1.
  [[nodiscard]] double magnitude() const {
    double m = 0;
    for (const Vec3& c : cp) m = std::max(m, max_abs(c));
    return m;
  }
};

inline Tensor tensor_of(const BSplineSurface& s) {
  Tensor t;
  t.dims = 2;
  t.p[0] = s.degree_u();
  t.p[1] = s.degree_v();
  t.knots[0] = s.knots_u().values();
  t.knots[1] = s.knots_v().values();
  t.n[0] = s.control_points().extent(0);
  t.n[1] = s.control_points().extent(1);
  t.cp.assign(s.control_points().data(), s.control_points().data() + s.control_points().size());
  if (s.rational()) t.w.assign(s.weights().data(), s.weights().data() + s.weights().size());
  for (int a = 0; a < 2; ++a) t.periodic[a] = s.periodic()[static_cast<std::size_t>(a)];
  return t;
}

inline Tensor tensor_of(const BSplineVolume& s) {
  Tensor t;
  t.dims = 3;
  t.p[0] = s.degree_u();
  t.p[1] = s.degree_v();
  t.p[2] = s.degree_w();
  t.knots[0] = s.knots_u().values();
  t.knots[1] = s.knots_v().values();
  t.knots[2] = s.knots_w().values();
  for (int a = 0; a < 3; ++a) {
    t.n[a] = s.control_points().extent(static_cast<std::size_t>(a));
    t.periodic[a] = s.periodic()[static_cast<std::size_t>(a)];
  }
  t.cp.assign(s.control_points().data(), s.control_points().data() + s.control_points().size());
  if (s.rational()) t.w.assign(s.weights().data(), s.weights().data() + s.weights().size());
  return t;
}

// ------------------------------------------------------------------ bounding boxes

struct Box {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi = -lo;
  void add(const Vec3& p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
  [[nodiscard]] double diagonal() const { return norm(hi - lo); }
  [[nodiscard]] double magnitude() const { return std::max(max_abs(lo), max_abs(hi)); }
  /// Inside the box grown by `margin` on every side.
  [[nodiscard]] bool holds(const Vec3& p, double margin) const {
    for (int k = 0; k < 3; ++k)
      if (!(p[k] >= lo[k] - margin && p[k] <= hi[k] + margin)) return false;
    return true;
  }
};

// ------------------------------------------------------------------ hostile placement

/// Where a case's data sit: point = offset + scale × (a point of size about 1). Half
/// the cases are ordinary; the others far from the origin (offsets up to 1e8 with
/// parts of 1e-3 to 1), tiny (1e-150 .. 1e-100) or huge (1e100 .. 1e150).
struct Frame {
  Vec3 offset{};
  double scale = 1;
  [[nodiscard]] Vec3 at(const Vec3& local) const { return offset + scale * local; }
  [[nodiscard]] std::string describe() const {
    std::ostringstream o;
    o << "offset (" << offset.x << ", " << offset.y << ", " << offset.z << "), scale " << scale;
    return o.str();
  }
};

inline Frame random_frame(std::mt19937_64& g) {
  Frame f;
  const int kind = pick(g, 0, 9);
  if (kind <= 4) {
    f.scale = std::pow(10.0, uni(g, -1, 1));
  } else if (kind <= 6) {
    f.scale = std::pow(10.0, uni(g, -3, 0));
    for (int k = 0; k < 3; ++k) f.offset[k] = uni(g, -1e8, 1e8);
  } else if (kind == 7) {
    f.scale = std::pow(10.0, uni(g, -150, -100));
    for (int k = 0; k < 3; ++k) f.offset[k] = f.scale * uni(g, -10, 10);
  } else {
    f.scale = std::pow(10.0, uni(g, 100, 150));
    for (int k = 0; k < 3; ++k) f.offset[k] = f.scale * uni(g, -10, 10);
  }
  return f;
}

inline Vec3 local_point(std::mt19937_64& g, double r = 1) { return {uni(g, -r, r), uni(g, -r, r), uni(g, -r, r)}; }

inline json to_json(const Vec3& p) { return json::array({p.x, p.y, p.z}); }
inline Vec3 from_json(const json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }


// ------------------------------------------------------------------ random B-splines of the harness

/// A clamped knot vector over [a, b] for n control points of degree p, interior
/// knots random, now and then one repeated up to p times.
inline std::vector<double> random_clamped_knots(std::mt19937_64& g, int p, std::size_t n, double a, double b) {
  std::vector<double> in;
  for (std::size_t i = 0; i + p + 1 < n; ++i) in.push_back(a + (b - a) * uni(g, 0.05, 0.95));
  std::sort(in.begin(), in.end());
  if (!in.empty() && chance(g, 0.2)) {
    // repeat one interior knot (keeping the multiplicity at most p)
    const std::size_t i = static_cast<std::size_t>(pick(g, 0, static_cast<int>(in.size()) - 1));
    for (std::size_t r = 1; r < static_cast<std::size_t>(p) && i + r < in.size(); ++r) in[i + r] = in[i];
  }
  std::vector<double> k(static_cast<std::size_t>(p + 1), a);
  k.insert(k.end(), in.begin(), in.end());
  k.insert(k.end(), static_cast<std::size_t>(p + 1), b);
  return k;
}


/// Periodic extended knots over [0, 1] for n control points of degree p (n + 2p + 1
/// knots, the period's n knots random but apart, repeated one period on either side).
inline std::vector<double> random_periodic_knots(std::mt19937_64& g, int p, std::size_t n) {
  std::vector<double> K{0.0};
  for (std::size_t i = 1; i < n; ++i) K.push_back((double(i) + uni(g, -0.3, 0.3)) / double(n));
  std::vector<double> k;
  for (std::size_t i = n - static_cast<std::size_t>(p); i < n; ++i) k.push_back(K[i] - 1.0);
  k.insert(k.end(), K.begin(), K.end());
  k.push_back(1.0);
  for (std::size_t i = 1; i <= static_cast<std::size_t>(p); ++i) k.push_back(K[i] + 1.0);
  return k;
}

/// A periodic B-spline curve of degree p on random periodic knots over [0, 1] with the
/// control points q.
inline Tensor random_periodic_curve(std::mt19937_64& g, int p, const std::vector<Vec3>& q) {
  Tensor t;
  t.dims = 1;
  t.p[0] = p;
  t.n[0] = q.size();
  t.periodic[0] = true;
  t.knots[0] = random_periodic_knots(g, p, q.size());
  t.cp = q;
  return t;
}

/// A random polynomial B-spline of `dims` parameters over [0, 1]^dims: control
/// point (i, j, k) near the frame's image of (i, j, k) / count (a gently bent
/// block), `noise` of that; a periodic direction's control points go round a
/// circle of radius 1 instead, so that the closed shape does not cross itself.
inline Tensor random_tensor(std::mt19937_64& g, const Frame& f, int dims, const int* p, const std::size_t* n,
                            const bool* periodic, double noise = 0.15) {
  Tensor t;
  t.dims = dims;
  for (int a = 0; a < dims; ++a) {
    t.p[a] = p[a];
    t.n[a] = n[a];
    t.periodic[a] = periodic[a];
    t.knots[a] = periodic[a] ? random_periodic_knots(g, p[a], n[a]) : random_clamped_knots(g, p[a], n[a], 0.0, 1.0);
  }
  t.cp.resize(t.n[0] * t.n[1] * t.n[2]);
  for (std::size_t i = 0; i < t.n[0]; ++i)
    for (std::size_t j = 0; j < t.n[1]; ++j)
      for (std::size_t k = 0; k < t.n[2]; ++k) {
        const std::size_t idx[3] = {i, j, k};
        // fractions along each direction; closed ones run once round
        double s[3] = {0, 0, 0};
        for (int a = 0; a < dims; ++a)
          s[a] = double(idx[a]) / double(std::max<std::size_t>(1, t.n[a] - (periodic[a] ? 0 : 1)));
        Vec3 q{};
        std::vector<int> open, closed;
        for (int a = 0; a < dims; ++a) (periodic[a] ? closed : open).push_back(a);
        if (closed.empty()) {
          for (int a = 0; a < dims; ++a) q[a] = s[a];
        } else {
          const double pi = std::numbers::pi;
          const double phi = 2 * pi * s[closed[0]];
          // the first open direction runs along z, the second widens the radius; a
          // second closed direction goes round the tube (a torus)
          double r = 1 + (open.size() > 1 ? 0.5 * s[open[1]] : 0.0), z = open.empty() ? 0.0 : s[open[0]];
          if (closed.size() > 1) {
            const double psi = 2 * pi * s[closed[1]];
            r = 2 + 0.6 * std::cos(psi) + (open.empty() ? 0.0 : 0.3 * s[open[0]]);
            z = 0.6 * std::sin(psi);
          }
          q = {r * std::cos(phi), r * std::sin(phi), z};
        }
        t.cp[(i * t.n[1] + j) * t.n[2] + k] = f.at(q + local_point(g, noise));
      }
  return t;
}

/// The B-spline of one parameter fewer on the line t_axis = t of `s` (or its
/// derivative across the line): the control points contracted with the basis (or its
/// derivative) along `axis`. Polynomial tensors only.
inline Tensor contract(const Tensor& s, int axis, double t, bool derivative = false) {
  const Basis b = own_basis(s.knots[axis], s.p[axis], t);
  Tensor r;
  r.dims = s.dims - 1;
  int o = 0;
  for (int a = 0; a < s.dims; ++a) {
    if (a == axis) continue;
    r.p[o] = s.p[a];
    r.knots[o] = s.knots[a];
    r.n[o] = s.n[a];
    r.periodic[o] = s.periodic[a];
    ++o;
  }
  const std::size_t na = s.n[axis];
  r.cp.assign(r.n[0] * r.n[1] * r.n[2], Vec3{});
  for (std::size_t i = 0; i < s.n[0]; ++i)
    for (std::size_t j = 0; j < s.n[1]; ++j)
      for (std::size_t k = 0; k < s.n[2]; ++k) {
        const std::size_t idx[3] = {i, j, k};
        std::size_t rest[2] = {0, 0};
        int q = 0;
        for (int a = 0; a < 3; ++a)
          if (a != axis && q < 2) rest[q++] = idx[a];
        double c = 0;
        for (std::size_t e = 0; e < b.N.size(); ++e)
          if ((static_cast<std::size_t>(b.first) + e) % na == idx[axis]) c += derivative ? b.dN[e] : b.N[e];
        if (c != 0) r.cp[rest[0] * r.n[1] + rest[1]] += c * s.cp[(i * s.n[1] + j) * s.n[2] + k];
      }
  return r;
}

/// A curve Tensor as a spec's {"bspline": ...} curve.
inline json curve_spec(const Tensor& c) {
  json cps = json::array();
  for (const Vec3& q : c.cp) cps.push_back(to_json(q));
  json inner = {{"degree", c.p[0]}, {"knots", c.knots[0]}, {"control_points", cps}};
  if (!c.w.empty()) inner["weights"] = c.w;
  if (c.periodic[0]) inner["periodic"] = true;
  return {{"bspline", inner}};
}

/// A surface Tensor as a bspline_surface spec.
inline json surface_spec(const Tensor& s) {
  json cps = json::array(), ws = json::array();
  for (std::size_t i = 0; i < s.n[0]; ++i) {
    json row = json::array(), wrow = json::array();
    for (std::size_t j = 0; j < s.n[1]; ++j) {
      row.push_back(to_json(s.cp[i * s.n[1] + j]));
      if (!s.w.empty()) wrow.push_back(s.w[i * s.n[1] + j]);
    }
    cps.push_back(row);
    ws.push_back(wrow);
  }
  json j = {{"type", "bspline_surface"},
            {"degree", {s.p[0], s.p[1]}},
            {"knots", {{"u", s.knots[0]}, {"v", s.knots[1]}}},
            {"control_points", cps}};
  if (!s.w.empty()) j["weights"] = ws;
  if (s.periodic[0] || s.periodic[1]) j["periodic"] = {s.periodic[0], s.periodic[1]};
  return j;
}

/// A bspline_volume spec of a Tensor of three parameters.
inline json volume_spec(const Tensor& t) {
  json cps = json::array(), ws = json::array();
  for (std::size_t i = 0; i < t.n[0]; ++i) {
    json a = json::array(), wa = json::array();
    for (std::size_t j = 0; j < t.n[1]; ++j) {
      json b = json::array(), wb = json::array();
      for (std::size_t k = 0; k < t.n[2]; ++k) {
        const std::size_t at = (i * t.n[1] + j) * t.n[2] + k;
        b.push_back(to_json(t.cp[at]));
        if (!t.w.empty()) wb.push_back(t.w[at]);
      }
      a.push_back(b);
      wa.push_back(wb);
    }
    cps.push_back(a);
    ws.push_back(wa);
  }
  json spec = {{"type", "bspline_volume"},
               {"degree", {t.p[0], t.p[1], t.p[2]}},
               {"knots", {{"u", t.knots[0]}, {"v", t.knots[1]}, {"w", t.knots[2]}}},
               {"control_points", cps}};
  if (!t.w.empty()) spec["weights"] = ws;
  if (t.periodic[0] || t.periodic[1] || t.periodic[2]) spec["periodic"] = {t.periodic[0], t.periodic[1], t.periodic[2]};
  return spec;
}

/// Box of a Tensor's control points.
inline Box box_of(const Tensor& t) {
  Box b;
  for (const Vec3& q : t.cp) b.add(q);
  return b;
}

// ------------------------------------------------------------------ curves of specs

/// A curve as a spec gives it, with what the harness knows of it on its own: its
/// evaluation over [0, 1] (empty for closed interpolating curves, whose periodic
/// system the harness does not solve) and the points it must pass at their
/// parameters (own computation of uniform, chord or centripetal parameters).
struct SpecCurve {
  json spec;
  bool rational = false;
  bool closed = false;
  std::function<Vec3(double)> eval;
  /// The 1-norm condition number of the own interpolation system (1 for the other
  /// forms): how much rounding of the points an interpolant between them may amplify.
  double cond = 1;
  std::vector<std::pair<double, Vec3>> data;
  Box box;  ///< of its points or control points
};

/// Parameters over [0, 1] of points by their spacing: the first at 0, the last at 1.
inline std::vector<double> own_params(const std::vector<Vec3>& q, const std::string& param) {
  std::vector<double> t(q.size(), 0.0);
  for (std::size_t i = 1; i < q.size(); ++i) {
    double d = 1;
    if (param != "uniform") {
      d = distance(q[i], q[i - 1]);
      if (param == "centripetal") d = std::sqrt(d);
    }
    t[i] = t[i - 1] + d;
  }
  for (auto& x : t) x /= t.back();
  return t;
}

/// Knots by averaging (The NURBS Book eq. 9.8) of parameters t_0..t_n for degree p.
inline std::vector<double> averaged_knots(const std::vector<double>& t, int p) {
  const std::size_t n = t.size() - 1;
  std::vector<double> k(static_cast<std::size_t>(p + 1), 0.0);
  for (std::size_t j = 1; j + p <= n; ++j) {
    double s = 0;
    for (std::size_t i = j; i < j + p; ++i) s += t[i];
    k.push_back(s / p);
  }
  k.insert(k.end(), static_cast<std::size_t>(p + 1), 1.0);
  return k;
}

/// Solves A x = b (A n × n, row-major) by Gaussian elimination with partial
/// pivoting, for each of the three coordinates. False when a pivot is 0.
inline bool own_solve(std::vector<double> A, std::vector<Vec3>& b) {
  const std::size_t n = b.size();
  for (std::size_t c = 0; c < n; ++c) {
    std::size_t piv = c;
    for (std::size_t r = c + 1; r < n; ++r)
      if (std::abs(A[r * n + c]) > std::abs(A[piv * n + c])) piv = r;
    if (A[piv * n + c] == 0) return false;
    if (piv != c) {
      for (std::size_t k = 0; k < n; ++k) std::swap(A[c * n + k], A[piv * n + k]);
      std::swap(b[c], b[piv]);
    }
    for (std::size_t r = c + 1; r < n; ++r) {
      const double f = A[r * n + c] / A[c * n + c];
      if (f == 0) continue;
      for (std::size_t k = c; k < n; ++k) A[r * n + k] -= f * A[c * n + k];
      b[r] -= f * b[c];
    }
  }
  for (std::size_t c = n; c-- > 0;) {
    for (std::size_t k = c + 1; k < n; ++k) b[c] -= A[c * n + k] * b[k];
    b[c] /= A[c * n + c];
  }
  return true;
}

/// The interpolating curve of degree p through q at `t` with averaged knots, as an
/// own Tensor (empty when the system is singular).
inline std::optional<Tensor> own_interpolant(const std::vector<Vec3>& q, const std::vector<double>& t, int p) {
  Tensor c;
  c.dims = 1;
  c.p[0] = p;
  c.knots[0] = averaged_knots(t, p);
  const std::size_t n = q.size();
  c.n[0] = n;
  std::vector<double> A(n * n, 0.0);
  for (std::size_t r = 0; r < n; ++r) {
    const Basis b = own_basis(c.knots[0], p, t[r]);
    for (std::size_t k = 0; k < b.N.size(); ++k) A[r * n + static_cast<std::size_t>(b.first) + k] = b.N[k];
  }
  c.cp = q;
  if (!own_solve(A, c.cp)) return std::nullopt;
  return c;
}

/// The 1-norm condition number ||A|| ||A^-1|| of an n × n matrix (A^-1 column by
/// column: small n only); infinite when A is singular.
inline double own_matrix_condition(const std::vector<double>& A, std::size_t n) {
  double norm_a = 0, norm_inv = 0;
  for (std::size_t c = 0; c < n; ++c) {
    double col = 0;
    for (std::size_t r = 0; r < n; ++r) col += std::abs(A[r * n + c]);
    norm_a = std::max(norm_a, col);
    std::vector<Vec3> e(n, Vec3{});
    e[c] = {1, 0, 0};
    if (!own_solve(A, e)) return std::numeric_limits<double>::infinity();
    double s = 0;
    for (const Vec3& x : e) s += std::abs(x.x);
    norm_inv = std::max(norm_inv, s);
  }
  return norm_a * norm_inv;
}

/// The 1-norm condition number of the collocation matrix of degree p at `t` with
/// averaged knots (n <= 8 here).
inline double own_condition(const std::vector<double>& t, int p) {
  const auto k = averaged_knots(t, p);
  const std::size_t n = t.size();
  std::vector<double> A(n * n, 0.0);
  for (std::size_t r = 0; r < n; ++r) {
    const Basis b = own_basis(k, p, t[r]);
    for (std::size_t j = 0; j < b.N.size(); ++j) A[r * n + static_cast<std::size_t>(b.first) + j] = b.N[j];
  }
  return own_matrix_condition(A, n);
}

/// A curve Tensor evaluated over [0, 1] mapped onto its domain.
inline std::function<Vec3(double)> unit_eval(Tensor c) {
  return [c = std::move(c)](double t) {
    const auto [a, b] = c.domain(0);
    return c.eval(a + t * (b - a)).s;
  };
}

/// Interior points of a curve from A to B: on the segment, pushed off it by up to
/// `bulge` (in the frame's units), in order along it; with `near` two of them nearly
/// coincide (1e-9 apart), a near-degenerate chord.
inline std::vector<Vec3> curve_points(std::mt19937_64& g, const Frame& f, const Vec3& A, const Vec3& B, int inner,
                                      double bulge, bool near) {
  std::vector<Vec3> q{A};
  for (int i = 1; i <= inner; ++i) {
    const double s = (i + uni(g, -0.3, 0.3)) / (inner + 1);
    q.push_back(A + s * (B - A) + f.scale * local_point(g, bulge));
  }
  q.push_back(B);
  if (near && inner >= 1) {
    const std::size_t i = static_cast<std::size_t>(pick(g, 1, inner));
    q[i] = q[i - 1] + f.scale * 1e-9 * local_point(g);
  }
  return q;
}

/// A random open curve from A to B in one of the four forms of a spec (rational
/// B-splines only with `allow_rational`).
inline SpecCurve random_open_curve(std::mt19937_64& g, const Frame& f, const Vec3& A, const Vec3& B,
                                   bool allow_rational) {
  SpecCurve c;
  const int form = pick(g, 0, 3);
  if (form == 0) {  // line
    c.spec = {{"line", json::array({to_json(A), to_json(B)})}};
    c.eval = [A, B](double t) { return (1 - t) * A + t * B; };
    c.data = {{0.0, A}, {1.0, B}};
    c.box.add(A);
    c.box.add(B);
    return c;
  }
  if (form == 1) {  // bspline, perhaps rational, over a random domain
    const int p = pick(g, 1, 4);
    const std::size_t n = static_cast<std::size_t>(p + 1 + pick(g, 0, 3));
    const double a = uni(g, -5, 5), b = a + std::pow(10.0, uni(g, -1, 1));
    Tensor t;
    t.dims = 1;
    t.p[0] = p;
    t.knots[0] = random_clamped_knots(g, p, n, a, b);
    t.n[0] = n;
    t.cp = curve_points(g, f, A, B, static_cast<int>(n) - 2, 0.5, false);
    json cps = json::array();
    for (const Vec3& q : t.cp) {
      cps.push_back(to_json(q));
      c.box.add(q);
    }
    json inner = {{"degree", p}, {"knots", t.knots[0]}, {"control_points", cps}};
    if (allow_rational && chance(g, 0.3)) {
      for (std::size_t i = 0; i < n; ++i) t.w.push_back(std::pow(10.0, uni(g, -1, 1)));
      inner["weights"] = t.w;
      c.rational = true;
    }
    c.spec = {{"bspline", inner}};
    c.data = {{0.0, A}, {1.0, B}};
    c.eval = unit_eval(std::move(t));
    return c;
  }
  if (form == 2) {  // hermite, tangents and params given or not
    const int inner = pick(g, 0, 3);
    const std::vector<Vec3> q = curve_points(g, f, A, B, inner, 0.5, false);
    const std::size_t n = q.size();
    std::vector<double> tp(n);
    const bool given_params = chance(g, 0.5);
    for (std::size_t i = 0; i < n; ++i) tp[i] = given_params ? (i == 0 ? uni(g, -3, 3) : tp[i - 1] + uni(g, 0.1, 2)) : double(i) / double(n - 1);
    std::vector<Vec3> T(n);
    const bool given_tangents = chance(g, 0.5);
    for (std::size_t i = 0; i < n; ++i) {
      if (given_tangents) {
        T[i] = (q.back() - q.front()) / (tp.back() - tp.front()) + (f.scale / (tp.back() - tp.front())) * local_point(g);
      } else {
        const std::size_t a = i == 0 ? 0 : i - 1, b = i + 1 == n ? i : i + 1;
        T[i] = (q[b] - q[a]) / (tp[b] - tp[a]);  // Catmull–Rom, one-sided at the ends
      }
    }
    json h = json::object();
    json pts = json::array(), tans = json::array();
    for (std::size_t i = 0; i < n; ++i) {
      pts.push_back(to_json(q[i]));
      tans.push_back(to_json(T[i]));
      c.box.add(q[i]);
      c.data.push_back({(tp[i] - tp[0]) / (tp.back() - tp[0]), q[i]});
    }
    h["points"] = pts;
    if (given_tangents) h["tangents"] = tans;
    if (given_params) h["params"] = tp;
    c.spec = {{"hermite", h}};
    c.eval = [q, T, tp](double t) {
      const double x = tp.front() + t * (tp.back() - tp.front());
      std::size_t i = 0;
      while (i + 2 < tp.size() && x > tp[i + 1]) ++i;
      const double h0 = tp[i + 1] - tp[i], s = (x - tp[i]) / h0;
      const double a0 = 1 - 3 * s * s + 2 * s * s * s, a1 = 3 * s * s - 2 * s * s * s;
      const double b0 = s - 2 * s * s + s * s * s, b1 = -s * s + s * s * s;
      return a0 * q[i] + a1 * q[i + 1] + (b0 * h0) * T[i] + (b1 * h0) * T[i + 1];
    };
    return c;
  }
  // interpolate: random degree (now and then above 3), parameters, a near coincidence
  const int inner = pick(g, 0, 5);
  const std::string param = std::vector<std::string>{"uniform", "chord", "centripetal"}[static_cast<std::size_t>(pick(g, 0, 2))];
  const std::vector<Vec3> q = curve_points(g, f, A, B, inner, 0.5, chance(g, 0.1));
  const int n = static_cast<int>(q.size());
  const int p = chance(g, 0.5) ? std::min(3, n - 1) : pick(g, 1, n - 1);
  json pts = json::array();
  for (const Vec3& x : q) {
    pts.push_back(to_json(x));
    c.box.add(x);
  }
  c.spec = {{"interpolate", pts}, {"param", param}};
  if (p != std::min(3, n - 1) || chance(g, 0.3)) c.spec["degree"] = p;
  const std::vector<double> t = own_params(q, param);
  for (std::size_t i = 0; i < q.size(); ++i) c.data.push_back({t[i], q[i]});
  if (auto own = own_interpolant(q, t, p)) c.eval = unit_eval(std::move(*own));
  c.cond = own_condition(t, p);
  return c;
}


// ------------------------------------------------------------------ grid parameters

/// Own parameters of a grid direction (docs/spec-format.md, type interpolate): each
/// line's uniform, chord or centripetal parameters over [0, 1], averaged over the
/// lines, lines of zero length left out. `lines[l][i]` is point i of line l, the
/// closing point (a repeat of the first) already left out; in a closed direction the
/// parameters run over the closed polygon, closing chord included, and only the
/// distinct points' are returned (the first at 0, none at 1).
inline std::vector<double> own_grid_params(const std::vector<std::vector<Vec3>>& lines, const std::string& param,
                                           bool closed) {
  const std::size_t n = lines.front().size();
  const std::size_t segments = closed ? n : n - 1;
  std::vector<double> sum(segments + 1, 0.0);
  std::size_t used = 0;
  for (const auto& q : lines) {
    std::vector<double> t(segments + 1, 0.0);
    for (std::size_t i = 1; i <= segments; ++i) {
      double d = 1;
      if (param != "uniform") {
        d = distance(q[i % n], q[i - 1]);
        if (param == "centripetal") d = std::sqrt(d);
      }
      t[i] = t[i - 1] + d;
    }
    if (!(t.back() > 0)) continue;
    for (std::size_t i = 0; i <= segments; ++i) sum[i] += t[i] / t.back();
    ++used;
  }
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = i == 0 ? 0.0 : (i == segments ? 1.0 : sum[i] / double(used));
  return out;
}

// ------------------------------------------------------------------ checking a case

/// What one case found wrong; empty when it kept every promise.
struct Findings {
  std::vector<std::string> lines;
  void add(std::string s) {
    // a replayed case shows everything it found, a run the first few of each case
    if (lines.size() < (replay_case() ? 400u : 8u)) lines.push_back(std::move(s));
  }
  /// |got − want| <= tol, with both finite.
  void near(const std::string& what, const Vec3& got, const Vec3& want, double tol) {
    const double d = distance(got, want);
    if (!is_finite(got) || !is_finite(want) || !(d <= tol)) {
      std::ostringstream o;
      o.precision(17);
      o << what << ": got (" << got.x << ", " << got.y << ", " << got.z << "), want (" << want.x << ", " << want.y
        << ", " << want.z << "), off by " << d << " > tolerance " << tol;
      add(o.str());
    }
  }
  void finite(const std::string& what, const Vec3& v) {
    if (!is_finite(v)) add(what + ": not finite");
  }
  [[nodiscard]] bool ok() const { return lines.empty(); }
};

/// Whether the library refused the construction's exact form because its conversion
/// came out off the construction (io::exact_form's run-time check): a known defect
/// said as an error, never written.
inline bool conversion_refused(const io::Construction& c) {
  return !c.exact && c.no_exact_form.find("its B-spline form differs from it by") != std::string::npos;
}

/// Tallies of a family's run, printed at its end.
struct Tally {
  std::size_t built = 0, refused = 0, failed = 0;
  std::vector<std::size_t> failing;  // every failing case, for the log
  std::map<std::string, std::size_t> refusals;  // errc name -> count
  std::map<std::string, std::size_t> first;     // errc name -> first case refused so
  std::map<std::string, std::size_t> notes;     // things worth seeing in the log (warnings)
};

/// Runs `cases` cases of a family. `make(g)` returns the spec; `check(spec, c,
/// findings)` checks the built construction. A refusal must be interpatch::error with
/// one of `allowed` codes (the family's documented codes for such input); anything
/// else — another code, another exception type, a missed promise — is reported with
/// the seed, the case index and the spec, and at most 5 failing cases are printed per
/// family. `min_built` is the fraction of cases that must build, so that a generator
/// gone wrong cannot make the family pass by refusing everything.
///
/// `known` lists the cases of the default run that hit a known library defect: they
/// are left out (and counted), each repeated verbatim in a DISABLED_..KnownDefect..
/// test that names the defect; a replay runs them all the same.
template <class Make, class Check>
Tally run_family(const std::string& family, std::uint64_t seed, std::size_t base_cases, const std::set<errc>& allowed,
                 Make make, Check check, double min_built = 0.5, const std::set<std::size_t>& known = {},
                 const std::set<std::size_t>* only_these = nullptr) {
  Tally tally;
  const auto only = replay_case();
  const std::size_t cases = case_count(base_cases);
  std::size_t left_out = 0;
  for (std::size_t index = 0; index < cases; ++index) {
    if (only && *only != index) continue;
    if (only_these && !only_these->count(index)) continue;
    if (!only && !only_these && known.count(index)) {
      ++left_out;
      continue;
    }
    auto g = case_rng(seed, index);
    json spec = make(g);
    Findings f;
    std::optional<io::Construction> c;
    try {
      c.emplace(io::build(spec));
    } catch (const error& e) {
      if (only) std::printf("[promise] case %zu refused: %s\n  spec: %s\n", index, e.what(), spec.dump().c_str());
      if (allowed.count(e.code())) {
        ++tally.refused;
        const std::string code(to_string(e.code()));
        if (!tally.refusals[code]++) tally.first[code] = index;
      } else {
        f.add("refused with undocumented code " + std::string(to_string(e.code())) + ": " + e.what());
      }
    } catch (const std::exception& e) {
      f.add(std::string("threw a ") + typeid(e).name() + " that is not interpatch::error: " + e.what());
    } catch (...) {
      f.add("threw something that is not a std::exception");
    }
    if (c) {
      ++tally.built;
      try {
        check(spec, *c, f);
      } catch (const std::exception& e) {
        f.add(std::string("checking the built construction threw: ") + e.what());
      }
      for (const auto& w : c->warnings) ++tally.notes["warning: " + w.substr(w.find(':') == std::string::npos ? 0 : w.find(':') + 2, 60)];
      if (conversion_refused(*c)) ++tally.notes["exact form refused, off its construction"];
    }
    if (!f.ok()) {
      ++tally.failed;
      tally.failing.push_back(index);
      {
        // the kind of failure, numbers left out, for the summary
        std::string k = f.lines.front().substr(0, 60);
        k.erase(std::remove_if(k.begin(), k.end(), [](char ch) { return std::isdigit(static_cast<unsigned char>(ch)); }), k.end());
        ++tally.notes["failed: " + k];
      }
      if (tally.failed <= 5) {
        std::string s = spec.dump();
        if (s.size() > 6000) s = s.substr(0, 6000) + "...";
        std::ostringstream o;
        for (const auto& l : f.lines) o << "\n  " << l;
        ADD_FAILURE() << "[promise-fail] " << family << ": seed " << seed << ", case " << index
                      << " (replay: INTERPATCH_PROMISE_REPLAY=" << index << ")" << o.str() << "\n  spec: " << s;
      }
    }
  }
  if (!only && !only_these) {
    EXPECT_GE(static_cast<double>(tally.built), min_built * static_cast<double>(cases - left_out))
        << family << ": too few cases built; the generator no longer makes what the family promises on";
  }
  std::ostringstream o;
  o << "[promise] " << family << ": " << cases << " cases, " << tally.built << " built, " << tally.refused
    << " refused";
  for (const auto& [k, v] : tally.refusals) o << " " << k << "=" << v << " (first: case " << tally.first[k] << ")";
  if (left_out) o << "; " << left_out << " known-defect cases left out";
  if (!tally.failing.empty()) {
    o << "; failing cases:";
    for (std::size_t i : tally.failing) o << " " << i;
  }
  for (const auto& [k, v] : tally.notes) o << "\n[promise]   " << v << " x " << k;
  std::printf("%s\n", o.str().c_str());
  return tally;
}

// Rounding of data of this box: a few units in the last place of its largest
// coordinate, amplified by a factor `k` that each use explains.
inline double rounding(const Box& b, double k) { return k * eps * b.magnitude(); }

// Where a surface must reproduce its data (corners, curves, grid points), computed
// by an own evaluation that sums the same numbers in another order or solves the
// same system another way: both carry rounding of the coordinates' size, amplified
// by the sums of |basis| (1 for B-splines, up to 2 for Hermite functions) and, for
// interpolation, by the condition of the collocation system, below 1e4 for the
// degrees (<= 5) and point counts (<= 8) generated, chords from 1e-9 to 1 included.
// 1e-10 of the diagonal covers the relative part of that amplification.
inline double data_tol(const Box& b) { return 1e-10 * b.diagonal() + rounding(b, 1e4); }

/// The exact form of a surface construction (built now if deferred), as an own Tensor.
inline std::optional<Tensor> exact_surface(io::Construction& c) {
  if (!io::has_exact_form(c)) return std::nullopt;
  return tensor_of(std::get<BSplineSurface>(io::exact_form(c)));
}

inline std::optional<Tensor> exact_volume(io::Construction& c) {
  if (!io::has_exact_form(c)) return std::nullopt;
  return tensor_of(std::get<BSplineVolume>(io::exact_form(c)));
}

/// Checks shared by every surface construction: the exact form (when it has one)
/// is over [0, 1]², finite, and equals the library's evaluator and its formula to
/// 1e-12 of the size of its control points, or 16 rounding steps of that size times
/// `amplification` where that is larger (how much the construction's own solve may
/// amplify rounding, 1 unless the family says why);
/// sampled on an n × n grid, every value is finite and inside the data's box grown
/// by its diagonal (unless a warning says why). Returns the exact form for the
/// family's own checks.
inline std::optional<Tensor> check_surface_common(io::Construction& c, const Box& data, Findings& f,
                                                  std::size_t n = 5, double amplification = 1) {
  std::optional<Tensor> t = exact_surface(c);
  const Surface* formula = c.formula.get();
  if (!t && !formula) {
    f.add("the construction has neither an exact form nor a formula");
    return t;
  }
  if (t) {
    for (const Vec3& q : t->cp) f.finite("an exact-form control point", q);
    for (int a = 0; a < 2; ++a) {
      const auto [lo, hi] = t->domain(a);
      // build maps every exact form onto [0, 1] (docs/spec-format.md, "Parameters")
      if (lo != 0.0 || std::abs(hi - 1.0) > 4 * eps) f.add("exact form domain not [0, 1]: " + std::to_string(lo) + " .. " + std::to_string(hi));
    }
  }
  // Two evaluations of one B-spline (or of the formula it converts exactly) agree
  // to rounding in coordinates of the control points' size: 1e-12 of it (SPEC).
  const double mag = std::max(t ? t->magnitude() : 0.0, data.magnitude());
  const double agree = std::max(1e-12 * std::max(mag, data.diagonal()), 16 * eps * mag * amplification);
  const double margin = data.diagonal();
  bool outside = false;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double u = double(i) / double(n - 1), v = double(j) / double(n - 1);
      const std::string at = "(" + std::to_string(u) + ", " + std::to_string(v) + ")";
      Vec3 s;
      if (t) {
        s = t->eval(u, v).s;
        f.near("exact form (library) vs own de Boor at " + at, std::get<BSplineSurface>(*c.exact).point(u, v), s, agree);
        if (formula) f.near("formula vs own de Boor of the exact form at " + at, formula->point(u, v), s, agree);
      } else {
        s = formula->point(u, v);
      }
      f.finite("value at " + at, s);
      if (!data.holds(s, margin)) outside = true;
    }
  if (outside && c.warnings.empty()) f.add("the surface leaves the data's box grown by its diagonal, without a warning");
  return t;
}

/// The same for a volume construction, sampled on an n × n × n grid.
inline std::optional<Tensor> check_volume_common(io::Construction& c, const Box& data, Findings& f, std::size_t n = 4) {
  std::optional<Tensor> t = exact_volume(c);
  const Volume* formula = c.volume_formula.get();
  if (!t && !formula) {
    f.add("the volume construction has neither an exact form nor a formula");
    return t;
  }
  if (t) {
    for (const Vec3& q : t->cp) f.finite("an exact-form control point", q);
    for (int a = 0; a < 3; ++a) {
      const auto [lo, hi] = t->domain(a);
      // build maps every exact form onto [0, 1] (docs/spec-format.md, "Parameters")
      if (lo != 0.0 || std::abs(hi - 1.0) > 4 * eps) f.add("exact form domain not [0, 1]: " + std::to_string(lo) + " .. " + std::to_string(hi));
    }
  }
  // as for surfaces: 1e-12 of the control points' size (SPEC)
  const double mag = std::max(t ? t->magnitude() : 0.0, data.magnitude());
  const double agree = 1e-12 * std::max(mag, data.diagonal());
  bool outside = false;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t k = 0; k < n; ++k) {
        const double u = double(i) / double(n - 1), v = double(j) / double(n - 1), w = double(k) / double(n - 1);
        const std::string at = "(" + std::to_string(u) + ", " + std::to_string(v) + ", " + std::to_string(w) + ")";
        Vec3 s;
        if (t) {
          s = t->eval(u, v, w).s;
          f.near("exact form (library) vs own de Boor at " + at, std::get<BSplineVolume>(*c.exact).point(u, v, w), s, agree);
          if (formula) f.near("formula vs own de Boor of the exact form at " + at, formula->point(u, v, w), s, agree);
        } else {
          s = formula->point(u, v, w);
        }
        f.finite("value at " + at, s);
        if (!data.holds(s, data.diagonal())) outside = true;
      }
  if (outside && c.warnings.empty()) f.add("the volume leaves the data's box grown by its diagonal, without a warning");
  return t;
}

}  // namespace interpatch::promise
