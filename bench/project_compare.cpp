// bench/project_compare: interpatch's closest-point projection (SurfaceProjector)
// against OpenCASCADE's GeomAPI_ProjectPointOnSurf on the same B-spline surface and
// the same query points.
//
//   project_compare [--points N] [--occ-points M] [--occ-each-points K] [--cases near,far]
//                   [--reps R] [--seed S] [--json OUT]
//
// The surface: 64 × 64 bicubic control points x = i/63, y = j/63,
// z = 0.1·sin(6x)·cos(5y), clamped uniform knots over [0, 1] both ways; OpenCASCADE
// gets the same poles, knots and multiplicities.
//
// Cases (N points, default 1 000 000, from std::mt19937_64 with a fixed seed):
//   near  points of the surface at random (u, v), plus Gaussian noise of σ = 0.005 in
//         each coordinate: a scan of the part
//   far   uniform random in [0, 1] × [0, 1] × [-0.3, 0.3]
// OpenCASCADE is given the first M of the same points (default 20 000): it is too slow
// for all of them, and the points are independent, so the first M are a fair sample.
//
// Per case:
//   build      constructing the SurfaceProjector (best of R), and OpenCASCADE's Init
//   interpatch SurfaceProjector::closest on the whole batch, on 1 thread and on every
//              thread (best of R each); the two answers must be the same bits
//   OCC        GeomAPI_ProjectPointOnSurf(P, S) per point, as users usually write it
//              (on the first K points, default M: it costs milliseconds a point), and
//              Init(S, bounds) once then Perform(P) per point; LowerDistance() of each
//              (no point found, or an exception, counts as a failure)
//   speed      OpenCASCADE's faster pattern per point over interpatch's, 1 and all threads
//   distances  on the M points: how many of interpatch's distances exceed OpenCASCADE's
//              by more than 1e-10 of the surface's diagonal (its control points' box),
//              how many of OpenCASCADE's exceed interpatch's (a local minimum, not the
//              global one), the largest difference each way
//
// Run with OMP_PROC_BIND=true so that the threads stay on their CPUs. The console gets
// a table per case; --json gets every figure.

#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Standard_Failure.hxx>
#include <Standard_Version.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <gp_Pnt.hxx>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/projection.hpp"
#include "interpatch/threads.hpp"

#if defined(_OPENMP)
#include <omp.h>
#endif

namespace {

using interpatch::BSplineSurface;
using interpatch::SurfacePoint;
using interpatch::Vec3;
using json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;
constexpr double inf = std::numeric_limits<double>::infinity();

struct Options {
  std::size_t points = 1'000'000;
  std::size_t occ_points = 20'000;
  std::size_t occ_each_points = 0;  // 0: occ_points
  std::vector<std::string> cases{"near", "far"};
  int reps = 3;
  std::uint64_t seed = 20240611;
  std::string json_out;
};

// ---------------------------------------------------------------- threads

int max_threads() {
#if defined(_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

void set_threads(int n) {
#if defined(_OPENMP)
  omp_set_num_threads(n);
#else
  (void)n;
#endif
}

// ---------------------------------------------------------------- the surface

constexpr int grid = 64;

BSplineSurface make_surface() {
  interpatch::PointGrid cp({grid, grid});
  for (std::size_t i = 0; i < grid; ++i)
    for (std::size_t j = 0; j < grid; ++j) {
      const double x = static_cast<double>(i) / (grid - 1), y = static_cast<double>(j) / (grid - 1);
      cp(i, j) = Vec3{x, y, 0.1 * std::sin(6 * x) * std::cos(5 * y)};
    }
  return BSplineSurface(interpatch::KnotVector::uniform(3, grid), interpatch::KnotVector::uniform(3, grid), std::move(cp));
}

// The diagonal of the control points' box: the scale interpatch's tolerances refer to.
double diagonal(const BSplineSurface& s) {
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  const auto& cp = s.control_points();
  for (std::size_t i = 0; i < cp.extent(0); ++i)
    for (std::size_t j = 0; j < cp.extent(1); ++j)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], cp(i, j)[k]);
        hi[k] = std::max(hi[k], cp(i, j)[k]);
      }
  return interpatch::distance(lo, hi);
}

// OpenCASCADE takes distinct knots with their multiplicities, in 1-based arrays.
std::pair<TColStd_Array1OfReal, TColStd_Array1OfInteger> occ_knots(const interpatch::KnotVector& k) {
  std::vector<std::pair<double, int>> distinct;
  for (const double t : k.values())
    if (!distinct.empty() && distinct.back().first == t)
      ++distinct.back().second;
    else
      distinct.emplace_back(t, 1);
  const int n = static_cast<int>(distinct.size());
  std::pair<TColStd_Array1OfReal, TColStd_Array1OfInteger> out{TColStd_Array1OfReal(1, n), TColStd_Array1OfInteger(1, n)};
  for (int i = 0; i < n; ++i) {
    out.first.SetValue(i + 1, distinct[static_cast<std::size_t>(i)].first);
    out.second.SetValue(i + 1, distinct[static_cast<std::size_t>(i)].second);
  }
  return out;
}

Handle(Geom_BSplineSurface) to_occ(const BSplineSurface& s) {
  const auto& cp = s.control_points();
  const int nu = static_cast<int>(cp.extent(0)), nv = static_cast<int>(cp.extent(1));
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const Vec3& p = cp(static_cast<std::size_t>(i), static_cast<std::size_t>(j));
      poles.SetValue(i + 1, j + 1, gp_Pnt(p.x, p.y, p.z));
    }
  const auto ku = occ_knots(s.knots_u()), kv = occ_knots(s.knots_v());
  return new Geom_BSplineSurface(poles, ku.first, kv.first, ku.second, kv.second, s.degree_u(), s.degree_v());
}

// ---------------------------------------------------------------- the points

std::vector<Vec3> make_points(const std::string& name, const BSplineSurface& s, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3> out;
  out.reserve(n);
  if (name == "near") {
    std::uniform_real_distribution<double> param(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, 0.005);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = param(rng), v = param(rng);
      const Vec3 p = s.point(u, v);
      const double dx = noise(rng), dy = noise(rng), dz = noise(rng);
      out.push_back({p.x + dx, p.y + dy, p.z + dz});
    }
  } else if (name == "far") {
    std::uniform_real_distribution<double> unit(0.0, 1.0), height(-0.3, 0.3);
    for (std::size_t i = 0; i < n; ++i) {
      const double x = unit(rng), y = unit(rng), z = height(rng);
      out.push_back({x, y, z});
    }
  } else {
    throw std::runtime_error("unknown case " + name + " (near, far)");
  }
  return out;
}

std::string describe(const std::string& name) {
  return name == "near" ? "points of the surface at random (u, v) + Gaussian noise, sigma 0.005 per coordinate"
                        : "uniform random in [0,1] x [0,1] x [-0.3,0.3]";
}

// ---------------------------------------------------------------- timing

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

template <class F>
double best_seconds(int reps, F&& f) {
  double best = inf;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, seconds_since(t0));
  }
  return best;
}

struct Run {
  std::string tool;
  int threads = 1;
  std::size_t points = 0;
  double seconds = 0;
  double us_per_point() const { return 1e6 * seconds / static_cast<double>(points); }
  double per_second() const { return static_cast<double>(points) / seconds; }
  json to_json() const {
    return {{"tool", tool},         {"threads", threads},           {"points", points},
            {"seconds", seconds},   {"us_per_point", us_per_point()}, {"points_per_second", per_second()}};
  }
};

Run time_interpatch(const interpatch::SurfaceProjector& on, const std::vector<Vec3>& points, int threads, int reps,
                    std::vector<SurfacePoint>& out) {
  set_threads(threads);
  out.assign(points.size(), SurfacePoint{});
  const double s = best_seconds(reps, [&] { on.closest(points, out); });
  return {"interpatch closest (batch)", threads, points.size(), s};
}

// OpenCASCADE's answers: the distance per point, NaN where it found none.
struct OccResult {
  Run run;
  std::vector<double> distance;
  std::size_t failures = 0;
};

double lower_distance(const GeomAPI_ProjectPointOnSurf& proj) {
  return proj.NbPoints() > 0 ? proj.LowerDistance() : std::numeric_limits<double>::quiet_NaN();
}

// The usual user code: a projector per point, the surface's bounds taken from it.
OccResult occ_each(const Handle(Geom_BSplineSurface)& s, const std::vector<Vec3>& points) {
  OccResult r;
  r.distance.resize(points.size());
  const auto t0 = Clock::now();
  for (std::size_t i = 0; i < points.size(); ++i) {
    try {
      const GeomAPI_ProjectPointOnSurf proj(gp_Pnt(points[i].x, points[i].y, points[i].z), s);
      r.distance[i] = lower_distance(proj);
    } catch (const Standard_Failure&) {
      r.distance[i] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  r.run = {"OCC ProjectPointOnSurf(P, S)", 1, points.size(), seconds_since(t0)};
  for (const double d : r.distance) r.failures += std::isnan(d) ? 1 : 0;
  return r;
}

// The re-use pattern: Init once with the bounds (its time returned apart), Perform per point.
OccResult occ_reuse(const Handle(Geom_BSplineSurface)& s, const std::vector<Vec3>& points, double& init_seconds) {
  OccResult r;
  r.distance.resize(points.size());
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  s->Bounds(u0, u1, v0, v1);
  auto t0 = Clock::now();
  GeomAPI_ProjectPointOnSurf proj;
  proj.Init(s, u0, u1, v0, v1);
  init_seconds = seconds_since(t0);
  t0 = Clock::now();
  for (std::size_t i = 0; i < points.size(); ++i) {
    try {
      proj.Perform(gp_Pnt(points[i].x, points[i].y, points[i].z));
      r.distance[i] = lower_distance(proj);
    } catch (const Standard_Failure&) {
      r.distance[i] = std::numeric_limits<double>::quiet_NaN();
    }
  }
  r.run = {"OCC Init once, Perform(P)", 1, points.size(), seconds_since(t0)};
  for (const double d : r.distance) r.failures += std::isnan(d) ? 1 : 0;
  return r;
}

// ---------------------------------------------------------------- distances

struct Agreement {
  std::size_t points = 0, interpatch_larger = 0, occ_larger = 0, occ_failures = 0;
  double max_interpatch_larger = 0, max_occ_larger = 0;  // the largest difference each way (0: never)
  json to_json() const {
    return {{"points", points},
            {"interpatch_larger", interpatch_larger},
            {"occ_larger", occ_larger},
            {"occ_failures", occ_failures},
            {"max_interpatch_larger", max_interpatch_larger},
            {"max_occ_larger", max_occ_larger}};
  }
};

Agreement agree(const std::vector<SurfacePoint>& ip, const OccResult& occ, double tol) {
  Agreement a;
  a.points = occ.distance.size();
  for (std::size_t i = 0; i < occ.distance.size(); ++i) {
    const double d = occ.distance[i];
    if (std::isnan(d)) {
      ++a.occ_failures;
      continue;
    }
    const double diff = ip[i].distance - d;
    a.max_interpatch_larger = std::max(a.max_interpatch_larger, diff);
    a.max_occ_larger = std::max(a.max_occ_larger, -diff);
    a.interpatch_larger += diff > tol ? 1 : 0;
    a.occ_larger += -diff > tol ? 1 : 0;
  }
  return a;
}

// Points whose answers differ between two runs in any bit of (u, v, point, distance).
std::size_t differing(const std::vector<SurfacePoint>& a, const std::vector<SurfacePoint>& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    n += (a[i].u != b[i].u || a[i].v != b[i].v || a[i].point != b[i].point || a[i].distance != b[i].distance) ? 1 : 0;
  return n;
}

// ---------------------------------------------------------------- one case

void print_table(const std::vector<Run>& runs, const Run& occ_best) {
  std::printf("%-30s %7s %9s %10s %11s %13s %13s\n", "", "threads", "points", "total s", "us/point", "points/s",
              "OCC best / it");
  for (const Run& r : runs) {
    const bool ip = r.tool.rfind("interpatch", 0) == 0;
    char ratio[32] = "-";
    if (ip) std::snprintf(ratio, sizeof ratio, "%.1f", occ_best.us_per_point() / r.us_per_point());
    std::printf("%-30s %7d %9zu %10.3f %11.4f %13.0f %13s\n", r.tool.c_str(), r.threads, r.points, r.seconds,
                r.us_per_point(), r.per_second(), ratio);
  }
}

void print_agreement(const char* tool, const Agreement& a) {
  std::printf("  %-30s interpatch farther: %zu (max %.2e); OCC farther: %zu (max %.2e); OCC failures: %zu of %zu\n",
              tool, a.interpatch_larger, a.max_interpatch_larger, a.occ_larger, a.max_occ_larger, a.occ_failures,
              a.points);
}

json run_case(const std::string& name, std::uint64_t seed, const BSplineSurface& s,
              const Handle(Geom_BSplineSurface)& occ_surface, const Options& o) {
  const std::vector<Vec3> points = make_points(name, s, o.points, seed);
  const std::size_t m = std::min(o.occ_points, points.size());
  const std::vector<Vec3> sample(points.begin(), points.begin() + static_cast<std::ptrdiff_t>(m));
  const std::size_t k = o.occ_each_points > 0 ? std::min(o.occ_each_points, m) : m;
  const std::vector<Vec3> each_sample(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(k));
  std::printf("\n== %s: %zu points, %s; OpenCASCADE on the first %zu (a projector per point: %zu)\n", name.c_str(),
              points.size(), describe(name).c_str(), m, k);

  std::optional<interpatch::SurfaceProjector> on;
  const double build_s = best_seconds(o.reps, [&] {
    on.reset();
    on.emplace(s);
  });

  const int all = max_threads();
  std::vector<SurfacePoint> one, many;
  std::vector<Run> runs{time_interpatch(*on, points, 1, o.reps, one)};
  if (all > 1) runs.push_back(time_interpatch(*on, points, all, o.reps, many));
  set_threads(all);
  const std::size_t thread_diff = all > 1 ? differing(one, many) : 0;

  double init_s = 0;
  const OccResult each = occ_each(occ_surface, each_sample);
  const OccResult reuse = occ_reuse(occ_surface, sample, init_s);
  runs.push_back(each.run);
  runs.push_back(reuse.run);
  const Run& best = reuse.run.us_per_point() <= each.run.us_per_point() ? reuse.run : each.run;

  const double diag = diagonal(s), tol = 1e-10 * diag;
  const Agreement a_each = agree(one, each, tol), a_reuse = agree(one, reuse, tol);

  print_table(runs, best);
  const double ratio_one = best.us_per_point() / runs.front().us_per_point();
  const double ratio_all = best.us_per_point() / runs[all > 1 ? 1 : 0].us_per_point();
  std::printf("  speed: OCC's best (%s) takes %.1fx interpatch's time per point on 1 thread, %.1fx on %d threads\n",
              best.tool.c_str(), ratio_one, ratio_all, all);
  std::printf("  build: SurfaceProjector %.3f ms (best of %d); OCC Init %.3f ms\n", 1e3 * build_s, o.reps, 1e3 * init_s);
  std::printf("  interpatch 1 thread vs %d threads: %zu of %zu answers differ in any bit\n", all, thread_diff,
              points.size());
  std::printf("  distances on the OCC points, tolerance 1e-10 x diagonal %.4f = %.2e:\n", diag, tol);
  print_agreement(each.run.tool.c_str(), a_each);
  print_agreement(reuse.run.tool.c_str(), a_reuse);

  json runs_json = json::array();
  for (const Run& r : runs) runs_json.push_back(r.to_json());
  return {{"case", name},
          {"description", describe(name)},
          {"seed", seed},
          {"points", points.size()},
          {"occ_points", m},
          {"occ_each_points", k},
          {"diagonal", diag},
          {"tolerance", tol},
          {"interpatch_build_seconds", build_s},
          {"occ_init_seconds", init_s},
          {"runs", runs_json},
          {"occ_best", best.tool},
          {"ratio_occ_best_vs_interpatch_1_thread", ratio_one},
          {"ratio_occ_best_vs_interpatch_all_threads", ratio_all},
          {"interpatch_threads_differing", thread_diff},
          {"agreement", {{"occ_each", a_each.to_json()}, {"occ_reuse", a_reuse.to_json()}}}};
}

// ---------------------------------------------------------------- the program

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--points") {
      o.points = std::max<std::size_t>(1, std::stoull(value()));
    } else if (a == "--occ-points") {
      o.occ_points = std::max<std::size_t>(1, std::stoull(value()));
    } else if (a == "--occ-each-points") {
      o.occ_each_points = std::max<std::size_t>(1, std::stoull(value()));
    } else if (a == "--cases") {
      o.cases.clear();
      std::stringstream ss(value());
      for (std::string x; std::getline(ss, x, ',');) o.cases.push_back(x);
    } else if (a == "--reps") {
      o.reps = std::max(1, std::stoi(value()));
    } else if (a == "--seed") {
      o.seed = std::stoull(value());
    } else if (a == "--json") {
      o.json_out = value();
    } else {
      throw std::runtime_error("usage: project_compare [--points N] [--occ-points M] [--occ-each-points K] "
                               "[--cases near,far] [--reps R] [--seed S] [--json OUT]");
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    interpatch::bind_threads();
    const BSplineSurface s = make_surface();
    const Handle(Geom_BSplineSurface) occ_surface = to_occ(s);
    // The same surface on both sides: its points agree at random parameters up to rounding.
    double conversion = 0;
    std::mt19937_64 rng(o.seed);
    std::uniform_real_distribution<double> param(0.0, 1.0);
    for (int i = 0; i < 1000; ++i) {
      const double u = param(rng), v = param(rng);
      const gp_Pnt q = occ_surface->Value(u, v);
      conversion = std::max(conversion, interpatch::distance(s.point(u, v), Vec3{q.X(), q.Y(), q.Z()}));
    }
    std::printf("project_compare: OpenCASCADE %s; %d x %d bicubic surface; %d threads; interpatch best of %d runs; "
                "surfaces agree within %.1e\n",
                OCC_VERSION_COMPLETE, grid, grid, max_threads(), o.reps, conversion);
    json all = {{"occ_version", OCC_VERSION_COMPLETE},
                {"control_points", {grid, grid}},
                {"degree", {3, 3}},
                {"threads", max_threads()},
                {"reps", o.reps},
                {"conversion_max", conversion},
                {"cases", json::array()}};
    // Each case its own stream, whatever cases are asked for and in what order.
    for (const std::string& name : o.cases)
      all["cases"].push_back(run_case(name, o.seed + (name == "far" ? 1 : 0), s, occ_surface, o));
    if (!o.json_out.empty()) {
      std::ofstream f(o.json_out);
      f << all.dump(2) << "\n";
      if (!f) throw std::runtime_error(o.json_out + ": cannot be written");
    }
  } catch (const Standard_Failure& e) {
    std::fprintf(stderr, "project_compare: OpenCASCADE: %s\n", e.GetMessageString());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "project_compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
