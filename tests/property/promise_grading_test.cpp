// The promise harness for graded sampling: random B-spline surfaces and volumes
// (degrees 1 to 3, some closed, some rational) in hostile frames, each given a
// random "sampling" per direction: a count alone, a ratio, a first or last cell
// length, or both ends, sometimes a max_growth. Each case is built through io::build
// as a user's spec is, and its nodes taken as mesh, eval and view take them
// (io::sample_parameters at io::default_resolution). The harness then evaluates the
// whole mesh by its own Cox–de Boor evaluation and checks what
// docs/spec-format.md promises:
// - the nodes run from 0 to 1, increasing; a direction with a count alone has even steps;
// - the longest first (last) cell over every line of the mesh is the length asked
//   for, to 1e-9 of it, never more (both up to the rounding of the coordinates);
// - along the direction's mean arc length (the harness's own, from its own points),
//   neighbouring cells grow by at most max_growth, and a ratio is last over first;
// - info's report is what the mesh shows;
// - a count refused as too small names a count that is then accepted.

#include <gtest/gtest.h>

#include <numeric>
#include <sstream>

#include "interpatch/io/outputs.hpp"
#include "promise_harness.hpp"

namespace interpatch::promise {
namespace {

// Cases in the default run (times INTERPATCH_PROMISE_CASES): about a fifth are
// volumes, whose own mean arc length is 83 000 own evaluations a direction.
constexpr std::size_t kCases = 60;
constexpr std::uint64_t kSeed = 0x9ad3;

template <class... A>
std::string cat(const A&... a) {
  std::ostringstream o;
  o.precision(10);
  (o << ... << a);
  return o.str();
}

// The surface or volume the spec gives, as the harness evaluates it over [0, 1]^dims.
struct Case {
  Tensor t;
  json sampling;
  [[nodiscard]] Vec3 at(const double* x) const {
    double k[3] = {0, 0, 0};
    for (int a = 0; a < t.dims; ++a) {
      const auto [lo, hi] = t.domain(a);
      k[a] = x[a] >= 1 ? hi : lo + x[a] * (hi - lo);
    }
    return t.eval(k[0], k[1], k[2]).s;
  }
};
Case current;

json tensor_spec(const Tensor& t) { return t.dims == 2 ? surface_spec(t) : volume_spec(t); }

// The points of the grid params[0] × params[1] (× params[2]), C order, by the harness.
std::vector<Vec3> own_grid(const Case& c, const std::array<std::vector<double>, 3>& p) {
  const std::size_t dims = static_cast<std::size_t>(c.t.dims);
  const std::size_t n2 = dims == 3 ? p[2].size() : 1;
  std::vector<Vec3> x;
  x.reserve(p[0].size() * p[1].size() * n2);
  for (double u : p[0])
    for (double v : p[1])
      for (std::size_t k = 0; k < n2; ++k) {
        const double at[3] = {u, v, dims == 3 ? p[2][k] : 0.0};
        x.push_back(c.at(at));
      }
  return x;
}

// Chords of the cells along direction d, line by line.
std::vector<std::vector<double>> own_cells(const std::vector<Vec3>& x, const std::array<std::vector<double>, 3>& p,
                                           std::size_t dims, std::size_t d) {
  std::size_t total = 1, stride = 1;
  for (std::size_t a = 0; a < dims; ++a) total *= p[a].size();
  for (std::size_t a = d + 1; a < dims; ++a) stride *= p[a].size();
  const std::size_t along = p[d].size();
  std::vector<std::vector<double>> lines;
  for (std::size_t l = 0; l < total / along; ++l) {
    const std::size_t start = (l / stride) * along * stride + l % stride;
    std::vector<double> h;
    for (std::size_t k = 1; k < along; ++k) h.push_back(distance(x[start + k * stride], x[start + (k - 1) * stride]));
    lines.push_back(std::move(h));
  }
  return lines;
}

// The harness's own mean arc length of direction d at parameters `at`: 9 (× 9) lines
// of 1025 even samples, each line's arc length scaled to 1 (lines shorter than 1e-12
// of the longest left out), averaged, and read between samples linearly.
std::vector<double> own_sigma(const Case& c, std::size_t d, const std::vector<double>& at) {
  const std::size_t dims = static_cast<std::size_t>(c.t.dims);
  std::array<std::vector<double>, 3> p;
  for (std::size_t a = 0; a < dims; ++a) {
    const std::size_t n = a == d ? 1025 : 9;
    for (std::size_t k = 0; k < n; ++k) p[a].push_back(static_cast<double>(k) / static_cast<double>(n - 1));
  }
  const std::vector<Vec3> x = own_grid(c, p);
  const auto lines = own_cells(x, p, dims, d);
  double longest = 0;
  for (const auto& h : lines) longest = std::max(longest, std::accumulate(h.begin(), h.end(), 0.0));
  std::vector<double> s(1025, 0.0);
  std::size_t used = 0;
  for (const auto& h : lines) {
    const double len = std::accumulate(h.begin(), h.end(), 0.0);
    if (!(len > 1e-12 * longest)) continue;
    double run = 0;
    for (std::size_t k = 1; k < 1025; ++k) s[k] += (run += h[k - 1]) / len;
    ++used;
  }
  std::vector<double> out;
  for (double t : at) {
    if (!used) {
      out.push_back(t);
      continue;
    }
    const double f = t * 1024;
    const std::size_t k = std::min<std::size_t>(1023, static_cast<std::size_t>(f));
    const double a = s[k] / static_cast<double>(used), b = k + 1 == 1024 ? 1.0 : s[k + 1] / static_cast<double>(used);
    out.push_back(a + (b - a) * (f - static_cast<double>(k)));
  }
  out.front() = 0;
  out.back() = 1;
  return out;
}

json random_sampling(std::mt19937_64& g, const Case& c) {
  const std::size_t dims = static_cast<std::size_t>(c.t.dims);
  json s = json::object();
  for (std::size_t d = 0; d < dims; ++d) {
    // A typical line's length along d: the middle line's, by 65 chords.
    std::array<std::vector<double>, 3> p;
    for (std::size_t a = 0; a < dims; ++a)
      for (std::size_t k = 0; k < (a == d ? 65u : 1u); ++k) p[a].push_back(a == d ? static_cast<double>(k) / 64 : 0.5);
    const auto h = own_cells(own_grid(c, p), p, dims, d);
    const double len = std::accumulate(h[0].begin(), h[0].end(), 0.0);
    json o = {{"count", pick(g, 2, dims == 3 ? 16 : 40)}};
    const int mode = pick(g, 0, 4);
    if (mode == 1) o["ratio"] = std::pow(10.0, uni(g, -2, 2));
    if (mode == 2 || mode == 4) o["first"] = len * std::pow(10.0, uni(g, -4, -0.5));
    if (mode == 3 || mode == 4) o["last"] = len * std::pow(10.0, uni(g, -4, -0.5));
    if (mode != 0 && chance(g, 0.3)) o["max_growth"] = uni(g, 1.05, 3);
    if (chance(g, 0.15)) o.erase("count");  // the kind's default count
    s[std::string(1, "uvw"[d])] = o;
  }
  return s;
}

// Checks the nodes of `sampling` (with counts `res`) against the harness's mesh.
void check_nodes(io::Construction& c, const io::Resolution& res, Findings& f) {
  const Case& k = current;
  const std::size_t dims = static_cast<std::size_t>(k.t.dims);
  const GradedParameters g = io::sample_parameters(c, res);
  const std::size_t counts[] = {res.nu, res.nv, res.nw};
  // Rounding of the coordinates, in a chord of two points: a few units in the last
  // place of the largest, times 64 for the evaluations' sums.
  const double noise = rounding(box_of(k.t), 64);
  const std::vector<Vec3> x = own_grid(k, g.params);
  for (std::size_t d = 0; d < dims; ++d) {
    const auto& t = g.params[d];
    const char* dir = d == 0 ? "u" : d == 1 ? "v" : "w";
    const json& o = k.sampling.value(dir, json::object());
    if (t.size() != counts[d]) f.add(cat(dir, ": ", t.size(), " nodes, not ", counts[d]));
    if (t.empty()) continue;
    if (t.front() != 0 || t.back() != 1) f.add(cat(dir, ": the nodes run from ", t.front(), " to ", t.back()));
    for (std::size_t i = 1; i < t.size(); ++i)
      if (!(t[i] > t[i - 1])) f.add(cat(dir, ": node ", i, " does not follow node ", i - 1));
    const bool graded = o.contains("ratio") || o.contains("first") || o.contains("last");
    if (!graded) {
      for (std::size_t i = 0; i < t.size(); ++i)
        if (t[i] != static_cast<double>(i) / static_cast<double>(t.size() - 1))
          f.add(cat(dir, ": a count alone, yet node ", i, " is at ", t[i]));
      continue;
    }
    const auto lines = own_cells(x, g.params, dims, d);
    double first = 0, last = 0;
    for (const auto& h : lines) first = std::max(first, h.front()), last = std::max(last, h.back());
    for (const char* end : {"first", "last"}) {
      if (!o.contains(end)) continue;
      const double asked = o[end].get<double>(), got = end[0] == 'f' ? first : last;
      if (!(got <= asked + noise && got >= asked * (1 - 1e-9) - noise))
        f.add(cat(dir, ": the longest ", end, " cell is ", got, ", asked ", asked, " (rounding ", noise, ")"));
    }
    const GradingReport& r = g.report[d];
    if (!(std::fabs(r.first - first) <= noise && std::fabs(r.last - last) <= noise))
      f.add(cat(dir, ": the report says first ", r.first, " last ", r.last, ", the mesh shows ", first, " and ", last));
    // The distribution along the harness's own mean arc length. Its samples differ
    // from the library's by rounding: σ sums up to 1024 chords, each off by `noise`,
    // so a cell of σ is off by up to 2048 noise over the line, relative to the cell's
    // own length (hmin, the shortest); 1e-6 for the rest (σ read between samples).
    double hmin = std::numeric_limits<double>::max();
    for (const auto& h : lines)
      for (double cell : h) hmin = std::min(hmin, cell);
    const double rel = 1e-6 + 4096 * noise / hmin;
    const std::vector<double> s = own_sigma(k, d, t);
    const double max_growth = o.value("max_growth", 1.3);
    for (std::size_t i = 2; i < s.size(); ++i) {
      const double h0 = s[i - 1] - s[i - 2], h1 = s[i] - s[i - 1];
      if (!(std::max(h1 / h0, h0 / h1) <= max_growth * (1 + rel)))
        f.add(cat(dir, ": cells ", i - 2, " and ", i - 1, " of the mean arc length grow by ", std::max(h1 / h0, h0 / h1),
                  " > max_growth ", max_growth));
    }
    if (o.contains("ratio") && s.size() > 2) {
      const double ratio = (s[s.size() - 1] - s[s.size() - 2]) / (s[1] - s[0]);
      if (!(std::fabs(ratio / o["ratio"].get<double>() - 1) <= rel))
        f.add(cat(dir, ": last over first cell ", ratio, ", asked ", o["ratio"].get<double>()));
    }
  }
}

TEST(PromiseGrading, MeshNodesKeepTheirLengthsAndGrowth) {
  std::size_t too_few = 0, too_long = 0, no_count = 0;
  run_family(
      "graded sampling", kSeed, kCases, {},
      [&](std::mt19937_64& g) {
        const Frame fr = random_frame(g);
        const int dims = chance(g, 0.2) ? 3 : 2;
        int p[3];
        std::size_t n[3];
        bool periodic[3];
        for (int a = 0; a < 3; ++a) {
          periodic[a] = a < dims && chance(g, 0.15);
          p[a] = pick(g, 1, 3);
          n[a] = static_cast<std::size_t>(p[a] + 1 + pick(g, 0, 3));
        }
        current.t = random_tensor(g, fr, dims, p, n, periodic, 0.2);
        if (chance(g, 0.2))
          for (std::size_t i = 0; i < current.t.cp.size(); ++i) current.t.w.push_back(std::pow(10.0, uni(g, -1, 1)));
        current.sampling = random_sampling(g, current);
        json spec = tensor_spec(current.t);
        spec["sampling"] = current.sampling;
        return spec;
      },
      [&](const json&, io::Construction& c, Findings& f) {
        const io::Resolution res = io::default_resolution(c);
        try {
          check_nodes(c, res, f);
        } catch (const error& e) {
          const std::string m = e.what();
          if (e.code() == errc::invalid_grading && m.find("is longer than the direction") != std::string::npos) {
            ++too_long;  // a random first or last length past a short line's end
            return;
          }
          // A count no count fits, or one the library could not confirm (another
          // direction's count then too small as well): said as such.
          if (e.code() == errc::too_few_points &&
              (m.find("no count from 2 to") != std::string::npos || m.find("may do") != std::string::npos)) {
            ++no_count;
            return;
          }
          if (e.code() != errc::too_few_points || m.find("would do") == std::string::npos) {
            f.add("refused: " + m);
            return;
          }
          ++too_few;
          // The count named must do: the same sampling with it is accepted.
          const std::size_t d = static_cast<std::size_t>(m[9] - 'u');
          const std::size_t would = std::stoul(m.substr(m.rfind("; count ") + 8));
          io::Resolution again = res;
          (d == 0 ? again.nu : d == 1 ? again.nv : again.nw) = would;
          try {
            check_nodes(c, again, f);
          } catch (const error& e2) {
            if (std::string(e2.what()).rfind(cat("sampling ", "uvw"[d]), 0) == 0)
              f.add(cat("the count named, ", would, ", is refused too: ", e2.what()));
          }
        }
      });
  std::printf("[promise] graded sampling: %zu counts refused as too small (each named count rechecked), "
              "%zu with no count that fits, %zu lengths past a line's end\n", too_few, no_count, too_long);
}

}  // namespace
}  // namespace interpatch::promise
