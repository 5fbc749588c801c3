// Graded nodes along each direction of a surface or a volume. A direction's
// distribution lives in its mean arc length σ ∈ [0, 1] (so that even steps of σ are
// cells of even length along a typical line); a physical first or last length is
// met by a search on the parameter of the node next to that end, measured as the
// longest such cell over the mesh's lines.

#include "interpatch/grading.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "base/text.hpp"
#include "interpatch/evaluate.hpp"

namespace interpatch {
namespace {

using detail::cat;
using detail::fail;
using Params = std::array<std::vector<double>, 3>;
constexpr const char* axis_name[] = {"u", "v", "w"};

// A surface or a volume as a grid evaluator: points over params[0] × ... in C order.
struct Shape {
  std::size_t dims;
  std::array<std::pair<double, double>, 3> domain;
  std::function<std::vector<Vec3>(const Params&)> grid;
};

// The lines of a grid of shape n along direction d: line l's point k is at
// start(l) + k * stride.
struct Lines {
  std::size_t count, stride, along;
  std::size_t start(std::size_t l) const { return (l / stride) * along * stride + l % stride; }
};

Lines lines_of(const Params& p, std::size_t dims, std::size_t d) {
  std::size_t total = 1, stride = 1;
  for (std::size_t a = 0; a < dims; ++a) total *= p[a].size();
  for (std::size_t a = d + 1; a < dims; ++a) stride *= p[a].size();
  return {total / p[d].size(), stride, p[d].size()};
}

// The mean arc length of direction d: at `samples` even parameters, the arc length
// from the start along each of 9 (× 9) lines, scaled to 1 on each line, averaged.
// Lines of no length (a collapsed edge) are left out; with none left, even steps.
struct Reference {
  std::vector<double> t, s;

  double sigma(double at) const {  // s at parameter `at`
    const auto k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), at) - t.begin());
    if (k == 0) return 0;
    if (k >= t.size()) return 1;
    return s[k - 1] + (s[k] - s[k - 1]) * (at - t[k - 1]) / (t[k] - t[k - 1]);
  }
  double param(double sigma) const {  // the parameter where s reaches `sigma`
    if (sigma <= 0) return t.front();
    if (sigma >= 1) return t.back();
    const auto k = static_cast<std::size_t>(std::upper_bound(s.begin(), s.end(), sigma) - s.begin());
    if (k >= s.size()) return t.back();
    const double ds = s[k] - s[k - 1];
    return ds > 0 ? t[k - 1] + (t[k] - t[k - 1]) * (sigma - s[k - 1]) / ds : t[k - 1];
  }
};

Reference reference(const Shape& shape, std::size_t d) {
  constexpr std::size_t samples = 1025, across = 9;
  Params p;
  for (std::size_t a = 0; a < shape.dims; ++a)
    p[a] = linspace(shape.domain[a].first, shape.domain[a].second, a == d ? samples : across);
  const std::vector<Vec3> x = shape.grid(p);
  const Lines lines = lines_of(p, shape.dims, d);
  Reference r{p[d], std::vector<double>(samples, 0.0)};
  std::vector<double> arc(samples);
  std::size_t used = 0;
  double longest = 0;
  std::vector<double> lengths(lines.count);
  for (std::size_t l = 0; l < lines.count; ++l) {
    double len = 0;
    for (std::size_t k = 1; k < samples; ++k)
      len += norm(x[lines.start(l) + k * lines.stride] - x[lines.start(l) + (k - 1) * lines.stride]);
    lengths[l] = len;
    longest = std::max(longest, len);
  }
  for (std::size_t l = 0; l < lines.count; ++l) {
    // A line shorter than rounding of the longest is a collapsed edge.
    if (!(lengths[l] > 1e-12 * longest)) continue;
    double len = 0;
    for (std::size_t k = 1; k < samples; ++k) {
      len += norm(x[lines.start(l) + k * lines.stride] - x[lines.start(l) + (k - 1) * lines.stride]);
      r.s[k] += len / lengths[l];
    }
    ++used;
  }
  for (std::size_t k = 0; k < samples; ++k)
    r.s[k] = used ? r.s[k] / static_cast<double>(used) : static_cast<double>(k) / static_cast<double>(samples - 1);
  r.s.front() = 0;
  r.s.back() = 1;
  return r;
}

// The longest chord between parameters a and b of direction d over the lines
// through the other directions' nodes.
double longest_chord(const Shape& shape, Params p, std::size_t d, double a, double b) {
  p[d] = {a, b};
  const std::vector<Vec3> x = shape.grid(p);
  const Lines lines = lines_of(p, shape.dims, d);
  double longest = 0;
  for (std::size_t l = 0; l < lines.count; ++l)
    longest = std::max(longest, norm(x[lines.start(l) + lines.stride] - x[lines.start(l)]));
  return longest;
}

// The parameter of the node next to the start (at_start) or the end of direction d
// whose cells are at most `length` long over the lines, the longest of them as close
// to it as bisection gets.
double end_node(const Shape& shape, const Params& p, std::size_t d, double length, bool at_start,
                const char* field) {
  // Plain copies: clang before 16 cannot capture structured bindings in a lambda.
  const double t0 = shape.domain[d].first, t1 = shape.domain[d].second;
  const double span = t1 - t0;
  auto chord = [&](double h) {  // the cell of parameter width h at the end
    return at_start ? longest_chord(shape, p, d, t0, t0 + h) : longest_chord(shape, p, d, t1 - h, t1);
  };
  double lo = 0, hi = span * 0x1p-30;
  while (chord(hi) < length) {
    lo = hi;
    if (hi >= span) {
      double whole = 0;
      for (double h : linspace(0, span, 65)) whole = std::max(whole, chord(h));
      fail(errc::invalid_grading, "sampling ", axis_name[d], ": ", field, " ", length,
           " is longer than the direction: its longest chord from that end is ", whole);
    }
    hi = std::min(span, 2 * hi);
  }
  for (int i = 0; i < 200 && hi - lo > span * 1e-16; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chord(mid) <= length ? lo : hi) = mid;
  }
  if (lo <= 0)
    fail(errc::invalid_grading, "sampling ", axis_name[d], ": ", field, " ", length,
         " is shorter than rounding allows along the direction");
  return at_start ? t0 + lo : t1 - lo;
}

// The sum 1 + r + ... + r^(m-1) for r = e^x.
double geometric_sum(double x, std::size_t m) {
  if (std::fabs(x) < 1e-12) return static_cast<double>(m);
  return std::expm1(x * static_cast<double>(m)) / std::expm1(x);
}

// Cells of one end's geometric progression: first cell `a` (of a total of 1) over m cells.
std::vector<double> geometric_cells(double a, std::size_t m) {
  // a · Σ r^k = 1, increasing in x = ln r.
  double lo = -700.0 / static_cast<double>(m), hi = 700.0 / static_cast<double>(m);
  if (a * static_cast<double>(m) == 1) lo = hi = 0;
  for (int i = 0; i < 300 && hi - lo > 1e-17 * (1 + std::fabs(lo)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (a * geometric_sum(mid, m) < 1 ? lo : hi) = mid;
  }
  const double r = std::exp(0.5 * (lo + hi));
  std::vector<double> cells(m);
  double c = 1;
  for (std::size_t k = 0; k < m; ++k, c *= r) cells[k] = c;
  return cells;
}

// Vinokur's two-sided stretching over m cells with end slopes set by d0 and d1 (the
// first and last cells of a total of 1, to first order).
struct Vinokur {
  double a = 1, b = 1, delta = 0;
  std::size_t m = 1;

  Vinokur(double d0, double d1, std::size_t cells) : m(cells) {
    const double fm = static_cast<double>(m);
    b = 1 / (fm * std::sqrt(d0 * d1));
    a = std::sqrt(d1 / d0);
    if (b > 1 + 1e-12) {  // sinh(δ)/δ = b, in logarithms so that large δ stays finite
      const double lb = std::log(b);
      double lo = 0, hi = 800;
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        const double f = mid > 20 ? mid - std::log(2 * mid) : std::log(std::sinh(mid) / mid);
        (f < lb ? lo : hi) = mid;
      }
      delta = 0.5 * (lo + hi);
    } else if (b < 1 - 1e-12) {  // sin(δ)/δ = b, δ in (0, π)
      double lo = 0, hi = M_PI;
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (std::sin(mid) / mid > b ? lo : hi) = mid;
      }
      delta = 0.5 * (lo + hi);
    }
  }
  // Node k's position.
  [[nodiscard]] double node(std::size_t k) const {
    if (k == 0) return 0;
    if (k == m) return 1;
    const double xi = static_cast<double>(k) / static_cast<double>(m);
    double u = xi;
    if (b > 1 + 1e-12) u = 0.5 * (1 + std::tanh(delta * (xi - 0.5)) / std::tanh(0.5 * delta));
    else if (b < 1 - 1e-12) u = 0.5 * (1 + std::tan(delta * (xi - 0.5)) / std::tan(0.5 * delta));
    return u / (a + (1 - a) * u);
  }
};

// The nodes σ_0 = 0 < ... < σ_m = 1 of a distribution over m cells: a ratio, a first
// cell a, a last cell b, or both ends. Empty when none fits m cells.
std::vector<double> sigma_nodes(const Grading& g, double a, double b, std::size_t m) {
  std::vector<double> s(m + 1, 0.0);
  if (g.first != 0 && g.last != 0) {
    if (m < 2 || a + b >= 1) return {};
    // The end slopes that give the end cells asked for: a fixed point on the two
    // end nodes alone, then every node.
    double d0 = a, d1 = b;
    for (int i = 0; i < 500; ++i) {
      const Vinokur v(d0, d1, m);
      const double fa = v.node(1), fb = 1 - v.node(m - 1);
      if (!(fa > 0 && fb > 0)) return {};
      if (std::fabs(fa / a - 1) < 1e-13 && std::fabs(fb / b - 1) < 1e-13) {
        for (std::size_t k = 0; k <= m; ++k) s[k] = v.node(k);
        return s;
      }
      d0 *= a / fa;
      d1 *= b / fb;
    }
    return {};
  }
  std::vector<double> cells;
  if (g.ratio != 0) {
    const double x = m > 1 ? std::log(g.ratio) / static_cast<double>(m - 1) : 0.0;
    cells.resize(m);
    for (std::size_t k = 0; k < m; ++k) cells[k] = std::exp(x * static_cast<double>(k));
  } else {
    if (m == 1) return a < 1 || b < 1 ? std::vector<double>{} : std::vector<double>{0.0, 1.0};
    cells = geometric_cells(g.first != 0 ? a : b, m);
    if (g.first == 0) std::reverse(cells.begin(), cells.end());
  }
  double total = 0;
  for (std::size_t k = 0; k < m; ++k) total += cells[k];
  double run = 0;
  for (std::size_t k = 0; k < m; ++k) s[k + 1] = (run += cells[k]) / total;
  s.back() = 1;
  return s;
}

// The largest ratio of neighbouring cells, either way.
double growth_of(std::span<const double> s) {
  double g = 1;
  for (std::size_t k = 2; k < s.size(); ++k) {
    const double h0 = s[k - 1] - s[k - 2], h1 = s[k] - s[k - 1];
    g = std::max(g, std::max(h1 / h0, h0 / h1));
  }
  return g;
}

bool fits(const Grading& g, double a, double b, std::size_t m) {
  const std::vector<double> s = sigma_nodes(g, a, b, m);
  return !s.empty() && growth_of(s) <= g.max_growth * (1 + 1e-12);
}

// The largest count the search for one that fits tries: more nodes than any mesh
// needs along one direction.
constexpr std::size_t count_limit = 100'000;

// The count nearest `count` whose distribution fits within max_growth, or 0.
std::size_t count_that_fits(const Grading& g, double a, double b, std::size_t count) {
  constexpr std::size_t limit = count_limit;
  std::size_t hi = count;
  while (hi < limit && !fits(g, a, b, hi - 1)) hi = std::min(limit, 2 * hi);
  if (fits(g, a, b, hi - 1)) {
    std::size_t lo = count;  // does not fit
    while (hi - lo > 1) {
      const std::size_t mid = lo + (hi - lo) / 2;
      (fits(g, a, b, mid - 1) ? hi : lo) = mid;
    }
    return hi;
  }
  // Cells that must shrink (a first cell longer than an even one) fit fewer nodes:
  // the most below `count` that fit.
  if (count <= 2 || !fits(g, a, b, 1)) return 0;
  std::size_t lo = 2, up = count;  // lo fits, up does not
  while (up - lo > 1) {
    const std::size_t mid = lo + (up - lo) / 2;
    (fits(g, a, b, mid - 1) ? lo : up) = mid;
  }
  return lo;
}

void check_grading(const Grading& g, std::size_t d) {
  auto positive = [&](double v, const char* field) {
    if (!(std::isfinite(v) && v > 0))
      fail(errc::invalid_grading, "sampling ", axis_name[d], ": ", field, " is ", v,
           "; it must be a positive finite number");
  };
  if (g.count < 2)
    fail(errc::too_few_points, "sampling ", axis_name[d], ": count ", g.count,
         "; a mesh needs at least 2 nodes along each direction");
  if (g.ratio != 0) positive(g.ratio, "ratio");
  if (g.first != 0) positive(g.first, "first");
  if (g.last != 0) positive(g.last, "last");
  if (!(std::isfinite(g.max_growth) && g.max_growth > 1))
    fail(errc::invalid_grading, "sampling ", axis_name[d], ": max_growth is ", g.max_growth,
         "; it must be a finite number above 1");
  if (g.ratio != 0 && (g.first != 0 || g.last != 0))
    fail(errc::invalid_grading, "sampling ", axis_name[d],
         ": ratio is given with first or last; give the ratio, or the end lengths");
}

// A count too small for direction d's grading, and the count that would do there
// (0: none) for the other directions' nodes of the pass that found it.
struct TooFew {
  std::size_t d;
  std::string grows;
  std::size_t would;
};

struct Solved {
  double first_t = 0, last_t = 0;  // the end nodes' parameters, when first (last) is given
};

// Direction d's nodes for the other directions' nodes in p.
std::vector<double> direction_nodes(const Shape& shape, const Params& p, std::size_t d, const Grading& g,
                                    const Reference& ref, Solved& solved) {
  const auto [t0, t1] = shape.domain[d];
  if (!g.graded()) return linspace(t0, t1, g.count);
  double a = 0, b = 0;
  if (g.first != 0) {
    solved.first_t = end_node(shape, p, d, g.first, true, "first");
    a = ref.sigma(solved.first_t);
  }
  if (g.last != 0) {
    solved.last_t = end_node(shape, p, d, g.last, false, "last");
    b = 1 - ref.sigma(solved.last_t);
  }
  if (g.first != 0 && g.last != 0 && solved.first_t >= solved.last_t)
    fail(errc::invalid_grading, "sampling ", axis_name[d], ": first ", g.first, " and last ", g.last,
         " overlap: together they are longer than the direction");
  const std::size_t m = g.count - 1;
  const std::vector<double> s = sigma_nodes(g, a, b, m);
  if (s.empty() || growth_of(s) > g.max_growth * (1 + 1e-12))
    throw TooFew{d, s.empty() ? std::string("cannot hold the grading")
                              : cat("would grow by ", growth_of(s), " from one cell to the next"),
                 count_that_fits(g, a, b, g.count)};
  std::vector<double> t(g.count);
  for (std::size_t k = 0; k < g.count; ++k) t[k] = ref.param(s[k]);
  t.front() = t0;
  t.back() = t1;
  // The end nodes exactly where the search put them, so their cells are not longer.
  if (g.first != 0) t[1] = solved.first_t;
  if (g.last != 0) t[m - 1] = solved.last_t;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1]))
      fail(errc::invalid_grading, "sampling ", axis_name[d], ": nodes ", k - 1, " and ", k,
           " coincide in parameter (", t[k], "); the grading is finer than rounding allows");
  return t;
}

// Up to 64 evenly chosen indices of n, both ends included.
std::vector<double> some_of(const std::vector<double>& t) {
  if (t.size() <= 64) return t;
  std::vector<double> r(64);
  for (std::size_t k = 0; k < 64; ++k) r[k] = t[k * (t.size() - 1) / 63];
  return r;
}

// The largest ratio of neighbouring cells along direction d, on up to 64 (× 64) of
// the mesh's lines.
double measured_growth(const Shape& shape, const Params& p, std::size_t d) {
  Params q = p;
  for (std::size_t a = 0; a < shape.dims; ++a)
    if (a != d) q[a] = some_of(p[a]);
  const std::vector<Vec3> x = shape.grid(q);
  const Lines lines = lines_of(q, shape.dims, d);
  double g = 1;
  for (std::size_t l = 0; l < lines.count; ++l)
    for (std::size_t k = 2; k < lines.along; ++k) {
      const std::size_t i = lines.start(l) + k * lines.stride;
      const double h0 = norm(x[i - lines.stride] - x[i - 2 * lines.stride]), h1 = norm(x[i] - x[i - lines.stride]);
      if (h0 > 0 && h1 > 0) g = std::max(g, std::max(h1 / h0, h0 / h1));
    }
  return g;
}

// Within 1e-9 below the length asked for, never above it; below by the rounding of
// a chord at most (`noise`: a part far from the origin for its size measures its
// chords to that).
bool holds(double got, double asked, double noise) {
  return asked == 0 || (got <= asked && got >= asked * (1 - 1e-9) - noise);
}

bool ends_hold(const GradingReport& r, const Grading& g, double noise) {
  return holds(r.first, g.first, noise) && holds(r.last, g.last, noise);
}

// The rounding of a chord between two points of the shape: 16 units in the last
// place of its largest coordinate (each point's sums round by a few).
double chord_rounding(const Shape& shape) {
  Params p;
  for (std::size_t a = 0; a < shape.dims; ++a) p[a] = linspace(shape.domain[a].first, shape.domain[a].second, 9);
  double m = 0;
  for (const Vec3& x : shape.grid(p)) m = std::max({m, std::fabs(x.x), std::fabs(x.y), std::fabs(x.z)});
  return 16 * std::numeric_limits<double>::epsilon() * m;
}

GradedParameters graded(const Shape& shape, const Sampling& sampling) {
  for (std::size_t d = 0; d < shape.dims; ++d) check_grading(sampling[d], d);
  GradedParameters r;
  Params& p = r.params;
  for (std::size_t d = 0; d < shape.dims; ++d)
    p[d] = linspace(shape.domain[d].first, shape.domain[d].second, sampling[d].count);
  const double noise = chord_rounding(shape);
  std::array<Reference, 3> refs;
  for (std::size_t d = 0; d < shape.dims; ++d)
    if (sampling[d].graded()) refs[d] = reference(shape, d);
  // A direction's end cells are measured on lines through the other directions' nodes:
  // solve in turn until every end length holds on the final nodes.
  constexpr int passes = 12;
  for (int pass = 0;; ++pass) {
    for (std::size_t d = 0; d < shape.dims; ++d) {
      Solved solved;
      if (sampling[d].graded()) p[d] = direction_nodes(shape, p, d, sampling[d], refs[d], solved);
    }
    bool met = true;
    for (std::size_t d = 0; d < shape.dims; ++d) {
      const Grading& g = sampling[d];
      const auto [t0, t1] = shape.domain[d];
      GradingReport& rep = r.report[d];
      rep.first = longest_chord(shape, p, d, t0, p[d][1]);
      rep.last = longest_chord(shape, p, d, p[d][p[d].size() - 2], t1);
      met = met && ends_hold(rep, g, noise);
    }
    if (met) break;
    if (pass + 1 == passes) {
      std::size_t d = 0;
      while (d + 1 < shape.dims && ends_hold(r.report[d], sampling[d], noise)) ++d;
      fail(errc::invalid_grading, "sampling ", axis_name[d], ": the end cells did not settle after ", passes,
           " passes over the directions (first ", r.report[d].first, ", last ", r.report[d].last, ")");
    }
  }
  for (std::size_t d = 0; d < shape.dims; ++d) r.report[d].growth = measured_growth(shape, p, d);
  return r;
}

}  // namespace

// graded(), and where a count is too small, the error naming a count that does: the
// count a direction's search names was found on the other directions' nodes of that
// pass, which the final passes move a little, so it is tried before it is named.
GradedParameters checked(const Shape& shape, const Sampling& sampling) {
  try {
    return graded(shape, sampling);
  } catch (const TooFew& first) {
    const Grading& g = sampling[first.d];
    Sampling trial = sampling;
    std::size_t would = first.would;
    for (int attempt = 0; attempt < 4 && would != 0; ++attempt) {
      trial[first.d].count = would;
      try {
        (void)graded(shape, trial);
        fail(errc::too_few_points, "sampling ", axis_name[first.d], ": count ", g.count, " ", first.grows,
             " (max_growth ", g.max_growth, "); count ", would, " would do");
      } catch (const TooFew& again) {
        if (again.d != first.d) break;  // another direction's count: the user's next step
        would = again.would;
      }
    }
    if (would == 0)
      fail(errc::too_few_points, "sampling ", axis_name[first.d], ": count ", g.count, " ", first.grows,
           " (max_growth ", g.max_growth, "), and no count from 2 to ", count_limit,
           " would do: allow a larger max_growth");
    fail(errc::too_few_points, "sampling ", axis_name[first.d], ": count ", g.count, " ", first.grows, " (max_growth ",
         g.max_growth, "); a count near ", would, " may do");
  }
}

GradedParameters graded_parameters(const Surface& surface, const Sampling& sampling) {
  const auto dom = surface.domain();
  Shape shape{2, {dom[0], dom[1], {0.0, 1.0}}, [&](const Params& p) {
    const PointGrid g = surface.evaluate(p[0], p[1]);
    return std::vector<Vec3>(g.data(), g.data() + g.size());
  }};
  return checked(shape, sampling);
}

GradedParameters graded_parameters(const Volume& volume, const Sampling& sampling) {
  Shape shape{3, volume.domain(), [&](const Params& p) {
    const PointGrid3 g = volume.evaluate(p[0], p[1], p[2]);
    return std::vector<Vec3>(g.data(), g.data() + g.size());
  }};
  return checked(shape, sampling);
}

}  // namespace interpatch
