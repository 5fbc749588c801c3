// Graded nodes along each direction of a surface or a volume. A direction's
// distribution lives in its mean arc length σ ∈ [0, 1] (so that even steps of σ are
// cells of even length along a typical line); a physical first or last length is
// met by a search on the parameter of the node next to that end, measured as the
// longest such cell over the mesh's lines.

#include "interpatch/grading.hpp"
#include "mesh/distributions.hpp"
#include "mesh/graded_blocks.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

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

// Directions of one or several shapes whose nodes move together (blocks sharing a
// face): one grading, one list of nodes τ ∈ [0, 1], each member's parameters
// t0 + τ (t1 − t0), or t1 − τ (t1 − t0) for a member that runs the other way.
using mesh::count_limit;
using mesh::count_that_fits;
using mesh::DirectionClass;
using mesh::DirectionMember;
using mesh::growth_of;
using mesh::sigma_nodes;

double member_t(const Shape& s, const DirectionMember& m, double tau) {
  const double t0 = s.domain[m.dir].first, t1 = s.domain[m.dir].second;
  return m.reversed ? t1 - tau * (t1 - t0) : t0 + tau * (t1 - t0);
}

// The class's nodes (increasing τ) as the member's parameters (increasing).
std::vector<double> member_params(const Shape& s, const DirectionMember& m, const std::vector<double>& tau) {
  std::vector<double> t(tau.size());
  for (std::size_t k = 0; k < tau.size(); ++k) t[k] = member_t(s, m, m.reversed ? tau[tau.size() - 1 - k] : tau[k]);
  t.front() = s.domain[m.dir].first;
  t.back() = s.domain[m.dir].second;
  return t;
}

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

// A class's mean arc length over τ: its members' averaged, each the right way round.
Reference class_reference(std::span<const Shape> shapes, const DirectionClass& c) {
  constexpr std::size_t samples = 1025;
  Reference r{linspace(0, 1, samples), std::vector<double>(samples, 0.0)};
  for (const DirectionMember& m : c.members) {
    const Reference own = reference(shapes[m.block], m.dir);
    for (std::size_t k = 0; k < samples; ++k) r.s[k] += m.reversed ? 1 - own.s[samples - 1 - k] : own.s[k];
  }
  for (double& v : r.s) v /= static_cast<double>(c.members.size());
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

// The longest cell of parameter width h (in τ) at the class's start (at_start) or
// end, over every member's lines.
double end_chord(std::span<const Shape> shapes, const std::vector<Params>& p, const DirectionClass& c, double h,
                 bool at_start) {
  double longest = 0;
  for (const DirectionMember& m : c.members) {
    const Shape& shape = shapes[m.block];
    const double t0 = shape.domain[m.dir].first, t1 = shape.domain[m.dir].second, w = h * (t1 - t0);
    const bool start = at_start != m.reversed;
    longest = std::max(longest, start ? longest_chord(shape, p[m.block], m.dir, t0, t0 + w)
                                      : longest_chord(shape, p[m.block], m.dir, t1 - w, t1));
  }
  return longest;
}

// The τ of the node next to the class's start (at_start) or end whose cells are at
// most `length` long over the lines, the longest of them as close to it as bisection
// gets.
double end_node(std::span<const Shape> shapes, const std::vector<Params>& p, const DirectionClass& c, double length,
                bool at_start, const char* field) {
  auto chord = [&](double h) { return end_chord(shapes, p, c, h, at_start); };
  double lo = 0, hi = 0x1p-30;
  while (chord(hi) < length) {
    lo = hi;
    if (hi >= 1) {
      double whole = 0;
      for (double h : linspace(0, 1, 65)) whole = std::max(whole, chord(h));
      fail(errc::invalid_grading, "sampling ", c.name, ": ", field, " ", length,
           " is longer than the direction: its longest chord from that end is ", whole);
    }
    hi = std::min(1.0, 2 * hi);
  }
  for (int i = 0; i < 200 && hi - lo > 1e-16; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chord(mid) <= length ? lo : hi) = mid;
  }
  if (lo <= 0)
    fail(errc::invalid_grading, "sampling ", c.name, ": ", field, " ", length,
         " is shorter than rounding allows along the direction");
  return at_start ? lo : 1 - lo;
}

void check_grading(const Grading& g, const std::string& name) {
  auto positive = [&](double v, const char* field) {
    if (!(std::isfinite(v) && v > 0))
      fail(errc::invalid_grading, "sampling ", name, ": ", field, " is ", v,
           "; it must be a positive finite number");
  };
  if (g.count < 2)
    fail(errc::too_few_points, "sampling ", name, ": count ", g.count,
         "; a mesh needs at least 2 nodes along each direction");
  if (g.ratio != 0) positive(g.ratio, "ratio");
  if (g.first != 0) positive(g.first, "first");
  if (g.last != 0) positive(g.last, "last");
  if (!(std::isfinite(g.max_growth) && g.max_growth > 1))
    fail(errc::invalid_grading, "sampling ", name, ": max_growth is ", g.max_growth,
         "; it must be a finite number above 1");
  if (g.ratio != 0 && (g.first != 0 || g.last != 0))
    fail(errc::invalid_grading, "sampling ", name,
         ": ratio is given with first or last; give the ratio, or the end lengths");
}

// A count too small for class d's grading, and the count that would do there (0:
// none) for the other directions' nodes of the pass that found it.
struct TooFew {
  std::size_t d;
  std::string grows;
  std::size_t would;
};

// Class c's nodes τ for the other directions' nodes in p.
std::vector<double> class_nodes(std::span<const Shape> shapes, const std::vector<Params>& p, std::size_t ci,
                                const DirectionClass& c, const Reference& ref) {
  const Grading& g = c.grading;
  if (!g.graded()) return linspace(0, 1, g.count);
  double a = 0, b = 0, first_tau = 0, last_tau = 1;
  if (g.first != 0) {
    first_tau = end_node(shapes, p, c, g.first, true, "first");
    a = ref.sigma(first_tau);
  }
  if (g.last != 0) {
    last_tau = end_node(shapes, p, c, g.last, false, "last");
    b = 1 - ref.sigma(last_tau);
  }
  if (g.first != 0 && g.last != 0 && first_tau >= last_tau)
    fail(errc::invalid_grading, "sampling ", c.name, ": first ", g.first, " and last ", g.last,
         " overlap: together they are longer than the direction");
  const std::size_t m = g.count - 1;
  const std::vector<double> s = sigma_nodes(g, a, b, m);
  if (s.empty() || growth_of(s) > g.max_growth * (1 + 1e-12))
    throw TooFew{ci, s.empty() ? std::string("cannot hold the grading")
                               : cat("would grow by ", growth_of(s), " from one cell to the next"),
                 count_that_fits(g, a, b, g.count)};
  std::vector<double> t(g.count);
  for (std::size_t k = 0; k < g.count; ++k) t[k] = ref.param(s[k]);
  t.front() = 0;
  t.back() = 1;
  // The end nodes exactly where the search put them, so their cells are not longer.
  if (g.first != 0) t[1] = first_tau;
  if (g.last != 0) t[m - 1] = last_tau;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1]))
      fail(errc::invalid_grading, "sampling ", c.name, ": nodes ", k - 1, " and ", k,
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

// Nodes per shape, and per class what they achieve.
struct Graded {
  std::vector<Params> params;
  std::vector<GradingReport> report;
};

// The longest cells at a class's start and end over its members' lines, and the
// growth between neighbours on up to 64 (× 64) of them.
GradingReport class_report(std::span<const Shape> shapes, const std::vector<Params>& p, const DirectionClass& c,
                           bool growth) {
  GradingReport r;
  for (const DirectionMember& m : c.members) {
    const Shape& shape = shapes[m.block];
    const std::vector<double>& t = p[m.block][m.dir];
    const double at_start = longest_chord(shape, p[m.block], m.dir, t[0], t[1]);
    const double at_end = longest_chord(shape, p[m.block], m.dir, t[t.size() - 2], t.back());
    r.first = std::max(r.first, m.reversed ? at_end : at_start);
    r.last = std::max(r.last, m.reversed ? at_start : at_end);
    if (growth) r.growth = std::max(r.growth, measured_growth(shape, p[m.block], m.dir));
  }
  return r;
}

Graded graded(std::span<const Shape> shapes, std::span<const DirectionClass> classes) {
  for (const DirectionClass& c : classes) check_grading(c.grading, c.name);
  Graded r;
  r.params.resize(shapes.size());
  std::vector<std::vector<double>> tau(classes.size());
  const auto place = [&](std::size_t ci) {
    for (const DirectionMember& m : classes[ci].members)
      r.params[m.block][m.dir] = member_params(shapes[m.block], m, tau[ci]);
  };
  for (std::size_t ci = 0; ci < classes.size(); ++ci) {
    tau[ci] = linspace(0, 1, classes[ci].grading.count);
    place(ci);
  }
  double noise = 0;
  for (const Shape& shape : shapes) noise = std::max(noise, chord_rounding(shape));
  std::vector<Reference> refs(classes.size());
  for (std::size_t ci = 0; ci < classes.size(); ++ci)
    if (classes[ci].grading.graded()) refs[ci] = class_reference(shapes, classes[ci]);
  // A class's end cells are measured on lines through the other directions' nodes:
  // solve in turn until every end length holds on the final nodes.
  constexpr int passes = 12;
  r.report.resize(classes.size());
  for (int pass = 0;; ++pass) {
    for (std::size_t ci = 0; ci < classes.size(); ++ci)
      if (classes[ci].grading.graded()) {
        tau[ci] = class_nodes(shapes, r.params, ci, classes[ci], refs[ci]);
        place(ci);
      }
    bool met = true;
    for (std::size_t ci = 0; ci < classes.size(); ++ci) {
      r.report[ci] = class_report(shapes, r.params, classes[ci], false);
      met = met && ends_hold(r.report[ci], classes[ci].grading, noise);
    }
    if (met) break;
    if (pass + 1 == passes) {
      std::size_t ci = 0;
      while (ci + 1 < classes.size() && ends_hold(r.report[ci], classes[ci].grading, noise)) ++ci;
      fail(errc::invalid_grading, "sampling ", classes[ci].name, ": the end cells did not settle after ", passes,
           " passes over the directions (first ", r.report[ci].first, ", last ", r.report[ci].last, ")");
    }
  }
  for (std::size_t ci = 0; ci < classes.size(); ++ci) r.report[ci] = class_report(shapes, r.params, classes[ci], true);
  return r;
}

// graded(), and where a count is too small, the error naming a count that does: the
// count a class's search names was found on the other directions' nodes of that
// pass, which the final passes move a little, so it is tried before it is named.
Graded checked(std::span<const Shape> shapes, std::span<const DirectionClass> classes) {
  try {
    return graded(shapes, classes);
  } catch (const TooFew& first) {
    const DirectionClass& c = classes[first.d];
    const Grading& g = c.grading;
    std::vector<DirectionClass> trial(classes.begin(), classes.end());
    std::size_t would = first.would;
    for (int attempt = 0; attempt < 4 && would != 0; ++attempt) {
      trial[first.d].grading.count = would;
      try {
        (void)graded(shapes, trial);
        fail(errc::too_few_points, "sampling ", c.name, ": count ", g.count, " ", first.grows, " (max_growth ",
             g.max_growth, "); count ", would, " would do");
      } catch (const TooFew& again) {
        if (again.d != first.d) break;  // another direction's count: the user's next step
        would = again.would;
      }
    }
    if (would == 0)
      fail(errc::too_few_points, "sampling ", c.name, ": count ", g.count, " ", first.grows, " (max_growth ",
           g.max_growth, "), and no count from 2 to ", count_limit, " would do: allow a larger max_growth");
    fail(errc::too_few_points, "sampling ", c.name, ": count ", g.count, " ", first.grows, " (max_growth ",
         g.max_growth, "); a count near ", would, " may do");
  }
}

// One shape: each direction a class of its own, named u, v, w.
GradedParameters graded_shape(const Shape& shape, const Sampling& sampling) {
  std::vector<DirectionClass> classes;
  for (std::size_t d = 0; d < shape.dims; ++d) classes.push_back({sampling[d], {{0, d, false}}, axis_name[d]});
  Graded g = checked(std::span<const Shape>(&shape, 1), classes);
  GradedParameters r;
  r.params = std::move(g.params[0]);
  for (std::size_t d = 0; d < shape.dims; ++d) r.report[d] = g.report[d];
  return r;
}

Shape volume_shape(const Volume& volume) {
  return {3, volume.domain(), [&volume](const Params& p) {
            const PointGrid3 g = volume.evaluate(p[0], p[1], p[2]);
            return std::vector<Vec3>(g.data(), g.data() + g.size());
          }};
}

}  // namespace

GradedParameters graded_parameters(const Surface& surface, const Sampling& sampling) {
  const auto dom = surface.domain();
  Shape shape{2, {dom[0], dom[1], {0.0, 1.0}}, [&](const Params& p) {
    const PointGrid g = surface.evaluate(p[0], p[1]);
    return std::vector<Vec3>(g.data(), g.data() + g.size());
  }};
  return graded_shape(shape, sampling);
}

GradedParameters graded_parameters(const Volume& volume, const Sampling& sampling) {
  return graded_shape(volume_shape(volume), sampling);
}

namespace mesh {

GradedBlocks graded_blocks(std::span<const Volume* const> blocks, std::span<const DirectionClass> classes) {
  std::vector<std::array<bool, 3>> covered(blocks.size(), std::array<bool, 3>{});
  for (const DirectionClass& c : classes)
    for (const DirectionMember& m : c.members) {
      if (m.block >= blocks.size() || m.dir > 2 || covered[m.block][m.dir])
        fail(errc::internal, "graded_blocks: block ", m.block, " direction ", m.dir, " is in no class or in two");
      covered[m.block][m.dir] = true;
    }
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (!covered[b][0] || !covered[b][1] || !covered[b][2])
      fail(errc::internal, "graded_blocks: a direction of block ", b, " is in no class");
  std::vector<Shape> shapes;
  for (const Volume* v : blocks) shapes.push_back(volume_shape(*v));
  Graded g = checked(shapes, classes);
  return {std::move(g.params), std::move(g.report)};
}

}  // namespace mesh
}  // namespace interpatch
