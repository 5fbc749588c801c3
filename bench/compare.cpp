// bench/compare: interpatch, OpenCASCADE and SISL side by side on the same data in
// one run, each next to a memcpy of the same bytes; and the whole interpatch command
// on every construction next to a pure-I/O program of the same bytes.
//
// Jobs (each selectable with --jobs):
//   interpolate  bicubic interpolation of N x N terrain grids (bench/terrain.hpp)
//                (then, for sizes N and 2N from 1024 on, interpatch on both in turn:
//                the linear-cost ratio)
//   evaluate     1000 x 1000 points on the bicubic surface through an M x M grid
//   coons        a Coons patch from four interpolated boundary curves, built and evaluated
//   process      `interpatch eval SPEC --grid K` against bench/sisl_eval, as whole processes
//   memory       peak resident memory of each library's interpolation, in a child process
//
// Whole processes of every construction (--jobs processes names them all): each job
// writes its spec and .npy data files (smooth shapes of bench/shapes.hpp, which the
// construction reproduces), then times, in turn run by run, the interpatch command
// and bench/pure_io (reads the same input files, writes an output of the same size
// as interpatch writes it, computes nothing: the floor); then, where SISL has the
// job, SISL's whole process in turn with the interpatch command again; wall clock
// from spawn to exit and peak RSS of each.
//   eval_interpolate         eval --grid 1000 of a 1024² .npy grid; SISL: sisl_eval
//   eval_coons               eval --grid 1000, linear Coons patch of four 1024-point
//                            interpolated curves; SISL: sisl_eval --coons (s1357, s1390)
//   eval_coons_hermite       eval --grid 1000, Coons patch with cross derivatives and
//                            Hermite blending, eight 256-point Hermite curves
//   eval_gordon, eval_network  eval --grid 1000, network of 12 x 12 200-point curves,
//                            method gordon, and coons_hermite (C1 Coons cells)
//   eval_interpolate_volume  eval --grid 200 of a 128³ .npy grid
//   eval_coons_volume        eval --grid 200, six faces interpolating 128² grids
//   eval_hermite_volume, eval_trilinear  eval --grid 200 (eight corners: no data files)
//   mesh                     mesh --res 1000x1000 of eval_coons's spec, to .vts
//   mesh_formats             the same mesh to .vtk, .ply, .stl, .obj and .xyz
//   build_npz                build -o .npz of an --npz-size² interpolation (8192²: a
//                            1.6 GB .npy), and eval --grid of the same spec; peak RSS
//                            against input + output bytes
//
// Every timing is the wall clock of one call (median of --reps repetitions), with the
// data built beforehand; every timed result is checked (points at the data, or against
// an independent evaluation or a closed form) so that no figure belongs to a wrong
// answer. The console gets tables; --json gets everything, read by tools/plot_bench.py.

#include <GeomAPI_Interpolate.hxx>
#include <GeomAPI_PointsToBSplineSurface.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomFill_BSplineCurves.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Standard_Failure.hxx>
#include <Standard_Version.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_HArray1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <gp_Pnt.hxx>
#include <sisl.h>
#include <sched.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <locale>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "grid_params.hpp"
#include "shapes.hpp"
#include "sisl_coons.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/npz.hpp"
#include "terrain.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
namespace ib = interpatch::bench;
using interpatch::BSplineSurface;
using interpatch::PointGrid;
using interpatch::Vec3;
using json = nlohmann::json;
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

double dist(const Vec3& a, const Vec3& b) { return std::sqrt(dot(a - b, a - b)); }
double dist(const Vec3& a, const double* b) { return dist(a, Vec3{b[0], b[1], b[2]}); }

// Relative errors are distances over the diagonal of the data's bounding box.
double diagonal(const Vec3* p, std::size_t n) {
  Vec3 lo = p[0], hi = p[0];
  for (std::size_t k = 1; k < n; ++k) {
    lo = {std::min(lo.x, p[k].x), std::min(lo.y, p[k].y), std::min(lo.z, p[k].z)};
    hi = {std::max(hi.x, p[k].x), std::max(hi.y, p[k].y), std::max(hi.z, p[k].z)};
  }
  return dist(lo, hi);
}

// A few indices spread over 0..n-1, ends included: where results are checked.
std::vector<std::size_t> sample_indices(std::size_t n) {
  std::vector<std::size_t> s{0, n / 7, n / 3, n / 2, (2 * n) / 3, n - 1};
  std::sort(s.begin(), s.end());
  s.erase(std::unique(s.begin(), s.end()), s.end());
  return s;
}

void set_threads(int threads) {
#if defined(_OPENMP)
  omp_set_num_threads(threads);
#else
  static_cast<void>(threads);
#endif
}

int max_threads() {
#if defined(_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// ---------------------------------------------------------------- options

// The whole-process jobs of every construction (--jobs processes selects them all).
const std::vector<std::string> process_jobs{"eval_interpolate",   "eval_coons",          "eval_coons_hermite",
                                            "eval_gordon",        "eval_network",        "eval_interpolate_volume",
                                            "eval_coons_volume",  "eval_hermite_volume", "eval_trilinear",
                                            "mesh",               "mesh_formats",        "build_npz"};

struct Options {
  std::vector<std::size_t> sizes{256, 1024, 2048, 4096};
  std::set<std::string> libs{"interpatch", "occt", "sisl", "memcpy"};
  std::set<std::string> jobs{"interpolate", "evaluate", "coons", "process", "memory"};
  std::vector<int> threads;
  std::vector<std::size_t> memory_sizes{2048, 4096};
  int reps = 3;
  std::size_t eval_grid = 1024, eval_points = 1000, coons_points = 1024, process_grid = 1024, npz_size = 8192;
  double occt_budget = 60;      // seconds one OpenCASCADE interpolation may be predicted to take
  double process_budget = 120;  // seconds of timed runs per whole-process job
  std::string json_out = "build/bench/compare.json";
  std::string workdir = "build/bench/compare-work";
  std::string commit;
  std::string cli = INTERPATCH_CLI_PATH, sisl_eval = SISL_EVAL_PATH, pure_io = PURE_IO_PATH;
  Options() { jobs.insert(process_jobs.begin(), process_jobs.end()); }
  bool has(const std::string& lib) const { return libs.count(lib) != 0; }
  bool job(const std::string& j) const { return jobs.count(j) != 0; }
};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

template <class T>
std::vector<T> split_numbers(const std::string& s) {
  std::vector<T> out;
  for (const auto& item : split(s)) out.push_back(static_cast<T>(std::stoll(item)));
  return out;
}

const char* usage =
    "usage: compare [--sizes 256,1024,2048,4096] [--libs interpatch,occt,sisl,memcpy]\n"
    "               [--jobs interpolate,evaluate,coons,process,memory,processes] [--reps 3] [--threads 1,2]\n"
    "               [--memory-sizes 2048,4096] [--eval-grid 1024] [--coons-points 1024]\n"
    "               [--process-grid 1024] [--npz-size 8192] [--occt-budget 60] [--process-budget 120]\n"
    "               [--json FILE] [--workdir DIR] [--commit TEXT] [--cli PATH] [--sisl-eval PATH]\n"
    "               [--pure-io PATH]\n"
    "--jobs processes stands for the whole-process jobs of every construction:\n"
    "  eval_interpolate, eval_coons, eval_coons_hermite, eval_gordon, eval_network,\n"
    "  eval_interpolate_volume, eval_coons_volume, eval_hermite_volume, eval_trilinear,\n"
    "  mesh, mesh_formats, build_npz (each may be named alone). Every job runs by default.\n";

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << usage;
      std::exit(0);
    }
    if (i + 1 >= argc) throw std::runtime_error(a + ": expected a value\n" + usage);
    const std::string v = argv[++i];
    if (a == "--sizes") o.sizes = split_numbers<std::size_t>(v);
    else if (a == "--libs") { auto l = split(v); o.libs = {l.begin(), l.end()}; }
    else if (a == "--jobs") {
      o.jobs.clear();
      for (const auto& j : split(v)) {
        if (j == "processes") o.jobs.insert(process_jobs.begin(), process_jobs.end());
        else o.jobs.insert(j);
      }
    }
    else if (a == "--reps") o.reps = std::max(1, std::stoi(v));
    else if (a == "--threads") o.threads = split_numbers<int>(v);
    else if (a == "--memory-sizes") o.memory_sizes = split_numbers<std::size_t>(v);
    else if (a == "--eval-grid") o.eval_grid = std::stoul(v);
    else if (a == "--coons-points") o.coons_points = std::stoul(v);
    else if (a == "--process-grid") o.process_grid = std::stoul(v);
    else if (a == "--npz-size") o.npz_size = std::stoul(v);
    else if (a == "--process-budget") o.process_budget = std::stod(v);
    else if (a == "--occt-budget") o.occt_budget = std::stod(v);
    else if (a == "--json") o.json_out = v;
    else if (a == "--workdir") o.workdir = v;
    else if (a == "--commit") o.commit = v;
    else if (a == "--cli") o.cli = v;
    else if (a == "--sisl-eval") o.sisl_eval = v;
    else if (a == "--pure-io") o.pure_io = v;
    else throw std::runtime_error("unknown option " + a + "\n" + usage);
  }
  std::sort(o.sizes.begin(), o.sizes.end());
  if (o.threads.empty()) {
    o.threads = {1};
    if (max_threads() > 1) o.threads.push_back(max_threads());
  }
  return o;
}

// ---------------------------------------------------------------- measuring

// One timed configuration: repetitions, the named parts of each, and its check.
struct Row {
  std::string job, library, variant;
  std::size_t n = 0;
  int threads = 1;
  std::vector<double> times;
  std::map<std::string, std::vector<double>> parts;
  double error = 0, tolerance = 0;
  std::string note;
  std::optional<double> maxrss_bytes, output_bytes;  // whole processes

  [[nodiscard]] bool ok() const { return error <= tolerance; }
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// Lap times of the parts of one repetition.
class Laps {
 public:
  void start() { t_ = clock_type::now(); }
  void lap(const std::string& name) {
    const auto now = clock_type::now();
    laps_.emplace_back(name, std::chrono::duration<double>(now - t_).count());
    t_ = now;
  }
  [[nodiscard]] const std::vector<std::pair<std::string, double>>& laps() const { return laps_; }

 private:
  clock_type::time_point t_ = clock_type::now();
  std::vector<std::pair<std::string, double>> laps_;
};

std::vector<Row> g_rows;

std::string format_time(double s) {
  std::ostringstream os;
  os << std::setprecision(3);
  if (!(s == s)) os << "–";
  else if (s >= 1) os << s << " s";
  else if (s >= 1e-3) os << s * 1e3 << " ms";
  else os << s * 1e6 << " µs";
  return os.str();
}

// Times `run` (which returns the result, recording lap times) `reps` times, checking
// every result with `check` (a relative error) after the clock stops and freeing it
// before the next repetition. Stops repeating once `budget` seconds have been spent.
template <class Run, class Check>
Row& measure(Row row, int reps, Run&& run, Check&& check, double budget = 1e30) {
  double spent = 0;
  for (int r = 0; r < reps; ++r) {
    Laps laps;
    const auto t0 = clock_type::now();
    laps.start();
    auto result = run(laps);
    const double t = seconds_since(t0);
    row.times.push_back(t);
    for (const auto& [name, s] : laps.laps()) row.parts[name].push_back(s);
    row.error = std::max(row.error, check(result));
    spent += t;
    if (spent > budget && r + 1 < reps) {
      row.note += (row.note.empty() ? "" : "; ") + std::to_string(r + 1) + " of " + std::to_string(reps) +
                  " repetitions (time budget)";
      break;
    }
  }
  std::cout << "  " << std::left << std::setw(12) << row.job << std::setw(6) << row.n << std::setw(12) << row.library
            << std::setw(34) << row.variant << " thr " << row.threads << "  " << std::right << std::setw(10)
            << format_time(median(row.times)) << "  check " << std::setprecision(2) << row.error
            << (row.ok() ? " ok" : " FAILED") << (row.note.empty() ? "" : "  (" + row.note + ")") << std::endl;
  g_rows.push_back(std::move(row));
  return g_rows.back();
}

Row row_of(std::string job, std::size_t n, std::string library, std::string variant, int threads, double tolerance) {
  Row r;
  r.job = std::move(job);
  r.n = n;
  r.library = std::move(library);
  r.variant = std::move(variant);
  r.threads = threads;
  r.tolerance = tolerance;
  return r;
}

json g_agreement = json::array(), g_skipped = json::array(), g_memory = json::array(), g_scaling = json::array();

void agreement(const std::string& job, std::size_t n, const std::string& what, double deviation, double tolerance,
               const std::string& note) {
  const bool ok = !(tolerance > 0) || deviation <= tolerance;
  std::cout << "  agreement " << job << " " << n << ": " << what << ": max deviation " << std::setprecision(3)
            << deviation << " of the diagonal" << (tolerance > 0 ? (ok ? " (ok)" : " (OVER TOLERANCE)") : "")
            << (note.empty() ? "" : " — " + note) << std::endl;
  g_agreement.push_back({{"job", job}, {"n", n}, {"what", what}, {"max_rel_deviation", deviation},
                         {"tolerance", tolerance > 0 ? json(tolerance) : json(nullptr)}, {"ok", ok}, {"note", note}});
}

void skipped(const std::string& job, std::size_t n, const std::string& library, const std::string& reason) {
  std::cout << "  skipped " << job << " " << n << " " << library << ": " << reason << std::endl;
  g_skipped.push_back({{"job", job}, {"n", n}, {"library", library}, {"reason", reason}});
}

// ---------------------------------------------------------------- memcpy baseline

// A memcpy of `bytes` (reading them and writing as many: the traffic of a job that
// reads its input once and writes its output once), between buffers allocated and
// touched beforehand, on one thread and on every thread of the run.
void measure_memcpy(const Options& o, const std::string& job, std::size_t n, std::size_t bytes) {
  if (!o.has("memcpy")) return;
  std::vector<std::byte> src(bytes), dst(bytes);
  for (std::size_t k = 0; k < bytes; ++k) src[k] = static_cast<std::byte>(k * 131);
  std::set<int> thread_counts{1, o.threads.back()};
  for (int threads : thread_counts) {
    auto row = row_of(job, n, "memcpy", std::to_string(bytes) + " bytes", threads, 0);
    measure(std::move(row), std::max(o.reps, 5),
            [&](Laps&) {
              ib::copy_bytes(dst.data(), src.data(), bytes, threads > 1);
              return dst.data();
            },
            [&](const std::byte* d) {
              // Every byte is compared: the copy happened, and cannot be dropped.
              return std::memcmp(d, src.data(), bytes) == 0 ? 0.0 : 1.0;
            });
  }
}

// ---------------------------------------------------------------- SISL and OpenCASCADE helpers

struct SurfDeleter {
  void operator()(SISLSurf* s) const { freeSurf(s); }
};
struct CurveDeleter {
  void operator()(SISLCurve* c) const { freeCurve(c); }
};
using SislSurface = std::unique_ptr<SISLSurf, SurfDeleter>;
using SislCurve = std::unique_ptr<SISLCurve, CurveDeleter>;

// SISL's first parameter direction runs fastest in memory, so an interpatch grid
// (first index along u, slowest) is SISL's (v, u): points pass unchanged and the
// parameter directions swap.
SislSurface sisl_interpolate(const PointGrid& grid, const std::vector<double>& pu, const std::vector<double>& pv) {
  SISLSurf* s = nullptr;
  int stat = 0;
  auto u = pu, v = pv;  // s1537 takes non-const arrays
  s1537(const_cast<double*>(&grid.data()->x), static_cast<int>(grid.extent(1)), static_cast<int>(grid.extent(0)), 3,
        v.data(), u.data(), 0, 0, 0, 0, 4, 4, 1, 1, &s, &stat);
  ib::sisl_check(stat, "s1537");
  return SislSurface(s);
}

Vec3 sisl_point(SISLSurf* s, double first, double second) {
  double par[2] = {first, second}, out[3];
  int left1 = 0, left2 = 0, stat = 0;
  s1424(s, 0, 0, par, &left1, &left2, out, &stat);
  ib::sisl_check(stat, "s1424");
  return {out[0], out[1], out[2]};
}

// An m1 x m2 grid with s1506, the first direction fastest; the output is allocated
// here, as a caller of s1506 must.
std::unique_ptr<double[]> sisl_grid(SISLSurf* s, std::vector<double>& first, std::vector<double>& second) {
  auto out = std::make_unique_for_overwrite<double[]>(3 * first.size() * second.size());
  int stat = 0;
  s1506(s, 0, static_cast<int>(first.size()), first.data(), static_cast<int>(second.size()), second.data(), out.get(),
        nullptr, &stat);
  ib::sisl_check(stat, "s1506");
  return out;
}

// The same B-spline surface as an interpatch one, in SISL (coefficients copied).
SislSurface sisl_copy(const BSplineSurface& s) {
  auto ku = s.knots_u().values(), kv = s.knots_v().values();
  const PointGrid& cp = s.control_points();
  SISLSurf* out = newSurf(static_cast<int>(cp.extent(1)), static_cast<int>(cp.extent(0)), s.degree_v() + 1,
                          s.degree_u() + 1, kv.data(), ku.data(), const_cast<double*>(&cp.data()->x), 1, 3, 1);
  if (!out) throw std::runtime_error("newSurf failed");
  return SislSurface(out);
}

// Distinct knots and multiplicities, as OpenCASCADE takes them.
std::pair<TColStd_Array1OfReal, TColStd_Array1OfInteger> occt_knots(const std::vector<double>& flat) {
  std::vector<double> k;
  std::vector<int> m;
  for (double t : flat) {
    if (!k.empty() && t == k.back()) ++m.back();
    else {
      k.push_back(t);
      m.push_back(1);
    }
  }
  TColStd_Array1OfReal knots(1, static_cast<int>(k.size()));
  TColStd_Array1OfInteger mults(1, static_cast<int>(m.size()));
  for (std::size_t i = 0; i < k.size(); ++i) {
    knots(static_cast<int>(i) + 1) = k[i];
    mults(static_cast<int>(i) + 1) = m[i];
  }
  return {knots, mults};
}

// The same B-spline surface as an interpatch one, in OpenCASCADE.
Handle(Geom_BSplineSurface) occt_copy(const BSplineSurface& s) {
  const PointGrid& cp = s.control_points();
  TColgp_Array2OfPnt poles(1, static_cast<int>(cp.extent(0)), 1, static_cast<int>(cp.extent(1)));
  for (std::size_t i = 0; i < cp.extent(0); ++i)
    for (std::size_t j = 0; j < cp.extent(1); ++j)
      poles(static_cast<int>(i) + 1, static_cast<int>(j) + 1) = gp_Pnt(cp(i, j).x, cp(i, j).y, cp(i, j).z);
  auto [ku, mu] = occt_knots(s.knots_u().values());
  auto [kv, mv] = occt_knots(s.knots_v().values());
  return new Geom_BSplineSurface(poles, ku, kv, mu, mv, s.degree_u(), s.degree_v());
}

// The point of an OpenCASCADE surface nearest to q, by Gauss-Newton from (u, v).
Vec3 occt_closest(const Geom_BSplineSurface& s, const Vec3& q, double u, double v) {
  double u0, u1, v0, v1;
  s.Bounds(u0, u1, v0, v1);
  gp_Pnt p;
  gp_Vec su, sv;
  for (int it = 0; it < 50; ++it) {
    s.D1(u, v, p, su, sv);
    const gp_Vec r(gp_Pnt(q.x, q.y, q.z), p);
    const double a = su.Dot(su), b = su.Dot(sv), c = sv.Dot(sv), ru = r.Dot(su), rv = r.Dot(sv);
    const double det = a * c - b * b;
    if (!(det > 0)) break;
    const double du = -(c * ru - b * rv) / det, dv = -(a * rv - b * ru) / det;
    u = std::clamp(u + du, u0, u1);
    v = std::clamp(v + dv, v0, v1);
    if (std::abs(du) < 1e-15 && std::abs(dv) < 1e-15) break;
  }
  s.D0(u, v, p);
  return {p.X(), p.Y(), p.Z()};
}

TColgp_Array2OfPnt occt_points(const PointGrid& g) {
  TColgp_Array2OfPnt a(1, static_cast<int>(g.extent(0)), 1, static_cast<int>(g.extent(1)));
  for (std::size_t i = 0; i < g.extent(0); ++i)
    for (std::size_t j = 0; j < g.extent(1); ++j) a(static_cast<int>(i) + 1, static_cast<int>(j) + 1) = gp_Pnt(g(i, j).x, g(i, j).y, g(i, j).z);
  return a;
}

Handle(Geom_BSplineSurface) occt_interpolate(const TColgp_Array2OfPnt& points) {
  GeomAPI_PointsToBSplineSurface api;
  api.Interpolate(points);  // degree 3, Approx_ChordLength
  if (!api.IsDone()) throw std::runtime_error("GeomAPI_PointsToBSplineSurface::Interpolate failed");
  return api.Surface();
}

// Points of a surface on a grid of its parameters, one D0 call each, u slowest.
template <class S>
std::unique_ptr<double[]> occt_grid(const S& s, const std::vector<double>& us, const std::vector<double>& vs) {
  auto out = std::make_unique_for_overwrite<double[]>(3 * us.size() * vs.size());
  gp_Pnt p;
  double* o = out.get();
  for (double u : us)
    for (double v : vs) {
      s.D0(u, v, p);
      o[0] = p.X();
      o[1] = p.Y();
      o[2] = p.Z();
      o += 3;
    }
  return out;
}

std::vector<double> linspace(std::pair<double, double> d, std::size_t n) { return interpatch::linspace(d.first, d.second, n); }

// Largest distance between a grid of points in u-slowest order and an interpatch grid.
double max_deviation(const PointGrid& ref, const double* p) {
  double e = 0;
  for (std::size_t k = 0; k < ref.size(); ++k) e = std::max(e, dist(ref.data()[k], p + 3 * k));
  return e;
}

// The same when `p` holds the grid in u-fastest order (SISL's surfaces whose first
// direction is u).
double max_deviation_transposed(const PointGrid& ref, const double* p) {
  double e = 0;
  const std::size_t nu = ref.extent(0), nv = ref.extent(1);
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) e = std::max(e, dist(ref(i, j), p + 3 * (j * nu + i)));
  return e;
}

// ---------------------------------------------------------------- job: interpolation

struct OcctGrowth {
  std::size_t n = 0;
  double seconds = 0, exponent = 2;
};

void job_interpolate(const Options& o) {
  std::cout << "\nBicubic interpolation of N x N grids (chord parameters)\n";
  OcctGrowth occt;
  for (std::size_t n : o.sizes) {
    const PointGrid grid = ib::make_terrain(n);
    const double diag = diagonal(grid.data(), grid.size());
    const auto idx = sample_indices(n);
    const double tol = 1e-9;
    // Checks at the data: S(t_i, t_j) = Q(i, j) for the sampled indices.
    auto check_at_data = [&](auto&& point_at) {
      double e = 0;
      for (std::size_t i : idx)
        for (std::size_t j : idx) e = std::max(e, dist(grid(i, j), point_at(i, j)));
      return e / diag;
    };

    if (o.has("interpatch")) {
      for (int threads : o.threads) {
        set_threads(threads);
        auto check = [&](const interpatch::SurfaceInterpolation& r) {
          return check_at_data([&](std::size_t i, std::size_t j) { return r.surface.point(r.params_u[i], r.params_v[j]); });
        };
        measure(row_of("interpolate", n, "interpatch", "interpolate_surface, copied in", threads, tol), o.reps,
                [&](Laps&) { return interpatch::interpolate_surface(grid); }, check);
        // The caller hands its grid over; the copy is made before the clock starts.
        auto row = row_of("interpolate", n, "interpatch", "interpolate_surface, moved in", threads, tol);
        std::optional<PointGrid> fresh;
        for (int r = 0; r < o.reps; ++r) {
          fresh = grid;
          const auto t0 = clock_type::now();
          auto res = interpatch::interpolate_surface(std::move(*fresh));
          row.times.push_back(seconds_since(t0));
          row.error = std::max(row.error, check(res));
        }
        measure(std::move(row), 0, [](Laps&) { return 0; }, [](int) { return 0.0; });
      }
      set_threads(o.threads.back());
    }

    if (o.has("sisl")) {
      const auto pu_ref = interpatch::grid_parameters(grid, 0, interpatch::Parametrization::chord);
      const auto pv_ref = interpatch::grid_parameters(grid, 1, interpatch::Parametrization::chord);
      std::vector<double> pu, pv;
      measure(row_of("interpolate", n, "sisl", "averaged chord parameters + s1537", 1, tol), o.reps,
              [&](Laps& laps) {
                pu = ib::averaged_chord_parameters(&grid.data()->x, n, n, 0);
                pv = ib::averaged_chord_parameters(&grid.data()->x, n, n, 1);
                laps.lap("parameters");
                auto s = sisl_interpolate(grid, pu, pv);
                laps.lap("s1537");
                return s;
              },
              [&](const SislSurface& s) {
                double dp = 0;  // the parameters are interpatch's, to rounding
                for (std::size_t k = 0; k < n; ++k) dp = std::max({dp, std::abs(pu[k] - pu_ref[k]), std::abs(pv[k] - pv_ref[k])});
                if (dp > 1e-12) return 1.0;
                return check_at_data([&](std::size_t i, std::size_t j) { return sisl_point(s.get(), pv[j], pu[i]); });
              });
    }

    if (o.has("occt")) {
      const auto pu_ref = interpatch::grid_parameters(grid, 0, interpatch::Parametrization::chord);
      const auto pv_ref = interpatch::grid_parameters(grid, 1, interpatch::Parametrization::chord);
      const double predicted = occt.n ? occt.seconds * std::pow(static_cast<double>(n) / static_cast<double>(occt.n), occt.exponent) : 0;
      if (predicted > o.occt_budget) {
        std::ostringstream why;
        why << "predicted " << std::setprecision(3) << predicted << " s for one call (t ~ N^" << occt.exponent
            << " from N = " << occt.n << "), over the --occt-budget of " << o.occt_budget << " s";
        skipped("interpolate", n, "occt", why.str());
      } else {
        const TColgp_Array2OfPnt points = occt_points(grid);
        auto& row = measure(
            row_of("interpolate", n, "occt", "GeomAPI_PointsToBSplineSurface::Interpolate", 1, tol), o.reps,
            [&](Laps&) { return occt_interpolate(points); },
            [&](const Handle(Geom_BSplineSurface)& s) {
              // OpenCASCADE chooses its own parameters: each data point is found on
              // the surface by Gauss-Newton from the averaged chord parameters.
              return check_at_data([&](std::size_t i, std::size_t j) { return occt_closest(*s, grid(i, j), pu_ref[i], pv_ref[j]); });
            },
            o.occt_budget);
        const double t = median(row.times);
        if (occt.n) occt.exponent = std::max(2.0, std::log(t / occt.seconds) / std::log(static_cast<double>(n) / static_cast<double>(occt.n)));
        occt = {n, t, occt.exponent};
      }
    }
    // The speed target measures the interpolation against a memcpy of its input plus its
    // output: the data points and the control points, N² points each.
    measure_memcpy(o, "interpolate", n, 2 * n * n * sizeof(Vec3));
  }
}

// The speed target asks for a cost linear in the points: t(2N × 2N) / t(N × N) ≤ 4.4 at
// N = 1024. The rows above time each size minutes apart, and on a shared machine the
// memory bandwidth left to this process changes in between; here the two sizes take
// turns, run by run (moved in, the copy made before the clock starts), so that both
// medians see the same machine. Pairs (N, 2N) of the measured sizes from N = 1024 on.
void measure_scaling(const Options& o) {
  constexpr std::size_t smallest = 1024;
  const int rounds = std::max(o.reps, 9);
  for (std::size_t k = 0; k + 1 < o.sizes.size(); ++k) {
    const std::size_t a = o.sizes[k], b = o.sizes[k + 1];
    if (a < smallest || b != 2 * a) continue;
    const std::array<PointGrid, 2> grids{ib::make_terrain(a), ib::make_terrain(b)};
    for (int threads : o.threads) {
      set_threads(threads);
      std::array<std::vector<double>, 2> times;
      double error = 0;
      std::optional<PointGrid> fresh;
      for (int r = 0; r < rounds; ++r)
        for (std::size_t s = 0; s < 2; ++s) {
          fresh = grids[s];
          const auto t0 = clock_type::now();
          auto res = interpatch::interpolate_surface(std::move(*fresh));
          times[s].push_back(seconds_since(t0));
          // The surface passes through the data: corners and the middle point.
          const std::size_t n = grids[s].extent(0), m = n / 2;
          for (const auto& [i, j] : {std::pair{std::size_t{0}, std::size_t{0}}, std::pair{n - 1, n - 1}, std::pair{m, m}})
            error = std::max(error, dist(grids[s](i, j), res.surface.point(res.params_u[i], res.params_v[j])));
        }
      std::vector<double> pair_ratios;
      for (int r = 0; r < rounds; ++r) pair_ratios.push_back(times[1][r] / times[0][r]);
      const double ratio = median(times[1]) / median(times[0]);
      const double tol = 1e-9 * diagonal(grids[1].data(), grids[1].size());
      std::cout << "  scaling     " << a << " -> " << b << " interpatch, alternated, thr " << threads << ": "
                << format_time(median(times[0])) << " and " << format_time(median(times[1])) << ", ratio "
                << std::setprecision(3) << ratio << " (median of the runs' ratios " << median(pair_ratios) << ", "
                << rounds << " rounds)" << (error <= tol ? "" : "  check FAILED") << std::endl;
      g_scaling.push_back({{"n", a}, {"n_large", b}, {"threads", threads}, {"rounds", rounds},
                           {"times_s", times[0]}, {"times_large_s", times[1]}, {"median_s", median(times[0])},
                           {"median_large_s", median(times[1])}, {"ratio_of_medians", ratio},
                           {"median_of_ratios", median(pair_ratios)}, {"check_ok", error <= tol}});
    }
  }
  set_threads(o.threads.back());
}

// ---------------------------------------------------------------- job: evaluation

void job_evaluate(const Options& o) {
  const std::size_t m = o.eval_grid, k = o.eval_points;
  std::cout << "\nEvaluation of " << k << " x " << k << " points on the bicubic surface through the " << m << " x " << m
            << " terrain\n";
  const PointGrid grid = ib::make_terrain(m);
  const double diag = diagonal(grid.data(), grid.size());
  const auto ip = interpatch::interpolate_surface(grid);
  const BSplineSurface& s = ip.surface;
  auto us = linspace(s.domain_u(), k), vs = linspace(s.domain_v(), k);
  const double tol = 1e-9;
  // interpatch's grid is checked against its own single-point evaluation; the others
  // against interpatch's grid (the same surface, so ≤ 1e-9 of the diagonal).
  const PointGrid ref = s.evaluate(us, vs);
  const auto idx = sample_indices(k);
  double self = 0;
  for (std::size_t i : idx)
    for (std::size_t j : idx) self = std::max(self, dist(ref(i, j), s.point(us[i], vs[j])));
  if (self / diag > tol) throw std::runtime_error("evaluate disagrees with point");

  if (o.has("interpatch"))
    for (int threads : o.threads) {
      set_threads(threads);
      measure(row_of("evaluate", m, "interpatch", "BSplineSurface::evaluate", threads, tol), o.reps,
              [&](Laps&) { return s.evaluate(us, vs); },
              [&](const PointGrid& g) {
                double e = 0;
                for (std::size_t i : idx)
                  for (std::size_t j : idx) e = std::max(e, dist(g(i, j), s.point(us[i], vs[j])));
                return e / diag;
              });
    }
  set_threads(o.threads.back());

  if (o.has("sisl")) {
    const auto copy = sisl_copy(s);
    measure(row_of("evaluate", m, "sisl", "s1506 (interpatch's knots and control points)", 1, tol), o.reps,
            [&](Laps&) { return sisl_grid(copy.get(), vs, us); },
            [&](const std::unique_ptr<double[]>& g) { return max_deviation(ref, g.get()) / diag; });
    // s1537 through the same data with the same parameters: SISL puts the knots of a
    // cubic at the parameters, interpatch averages them, so the two surfaces differ
    // between the data points.
    const auto own = sisl_interpolate(grid, ip.params_u, ip.params_v);
    const auto g = sisl_grid(own.get(), vs, us);
    agreement("evaluate", m, "sisl s1537 surface vs interpatch interpolate_surface", max_deviation(ref, g.get()) / diag, 0,
              "same data and parameters; SISL places a cubic's knots at the parameters, interpatch averages them (NURBS Book eq. 9.8)");
  }

  if (o.has("occt")) {
    const auto copy = occt_copy(s);
    measure(row_of("evaluate", m, "occt", "Geom_BSplineSurface::D0 loop (interpatch's surface)", 1, tol), o.reps,
            [&](Laps&) { return occt_grid(*copy, us, vs); },
            [&](const std::unique_ptr<double[]>& g) { return max_deviation(ref, g.get()) / diag; });
    const GeomAdaptor_Surface adaptor(copy);
    measure(row_of("evaluate", m, "occt", "GeomAdaptor_Surface::D0 loop (cached spans)", 1, tol), o.reps,
            [&](Laps&) { return occt_grid(adaptor, us, vs); },
            [&](const std::unique_ptr<double[]>& g) { return max_deviation(ref, g.get()) / diag; });
  }
  measure_memcpy(o, "evaluate", m, k * k * sizeof(Vec3));
}

// ---------------------------------------------------------------- job: Coons patch

void job_coons(const Options& o) {
  const std::size_t m = o.coons_points, k = o.eval_points;
  std::cout << "\nCoons patch from four " << m << "-point boundary curves, built and evaluated on " << k << " x " << k
            << " points\n";
  const PointGrid grid = ib::make_terrain(m);
  std::vector<Vec3> bottom(m), top(m), left(m), right(m);  // v = 0, v = 1, u = 0, u = 1
  for (std::size_t t = 0; t < m; ++t) {
    bottom[t] = grid(t, 0);
    top[t] = grid(t, m - 1);
    left[t] = grid(0, t);
    right[t] = grid(m - 1, t);
  }
  std::vector<Vec3> boundary;
  for (const auto* c : {&bottom, &top, &left, &right}) boundary.insert(boundary.end(), c->begin(), c->end());
  const double diag = diagonal(boundary.data(), boundary.size());
  const std::array<Vec3, 4> corners{grid(0, 0), grid(m - 1, 0), grid(0, m - 1), grid(m - 1, m - 1)};
  auto us = interpatch::linspace(0, 1, k), vs = interpatch::linspace(0, 1, k);
  const double tol = 1e-9;
  const auto idx = sample_indices(k);

  auto interpatch_patch = [&](Laps& laps) {
    auto c = [](const std::vector<Vec3>& p) { return interpatch::interpolate_curve(p).curve; };
    interpatch::CoonsBoundary b{c(bottom), c(top), c(left), c(right)};
    laps.lap("curves");
    auto patch = interpatch::coons(b);
    laps.lap("patch");
    return patch;
  };
  // Corners at the data; sampled points equal the patch's own formula.
  Laps scratch;
  const auto formula = interpatch_patch(scratch);
  auto check_interpatch = [&](const PointGrid& g) {
    double e = std::max({dist(g(0, 0), corners[0]), dist(g(k - 1, 0), corners[1]), dist(g(0, k - 1), corners[2]),
                         dist(g(k - 1, k - 1), corners[3])});
    for (std::size_t i : idx)
      for (std::size_t j : idx) e = std::max(e, dist(g(i, j), formula.point(us[i], vs[j])));
    return e / diag;
  };
  std::optional<PointGrid> ref;
  if (o.has("interpatch"))
    for (int threads : o.threads) {
      set_threads(threads);
      measure(row_of("coons", m, "interpatch", "coons + BlendedSurface::evaluate", threads, tol), o.reps,
              [&](Laps& laps) {
                auto patch = interpatch_patch(laps);
                auto g = patch.evaluate(us, vs);
                laps.lap("evaluate");
                return g;
              },
              check_interpatch);
      measure(row_of("coons", m, "interpatch", "coons + to_bspline().evaluate", threads, tol), o.reps,
              [&](Laps& laps) {
                auto patch = interpatch_patch(laps);
                auto b = patch.to_bspline();
                laps.lap("to_bspline");
                auto g = b.evaluate(us, vs);
                laps.lap("evaluate");
                return g;
              },
              check_interpatch);
    }
  set_threads(o.threads.back());
  ref = formula.evaluate(us, vs);

  if (o.has("sisl")) {
    // s1390's edges run around the patch: 1 v = 0 and 3 v = 1 along u, 2 u = 1 and
    // 4 u = 0 along v; its first parameter is u, so s1506's grid is u-fastest.
    std::array<std::vector<double>, 4> params;
    const std::array<const std::vector<Vec3>*, 4> around{&bottom, &right, &top, &left};
    auto sisl_patch = [&](Laps& laps) {
      std::array<SislCurve, 4> curves;
      for (std::size_t e = 0; e < 4; ++e) curves[e].reset(ib::sisl_interpolate_curve(&around[e]->data()->x, m, params[e]));
      laps.lap("curves");
      SislSurface surf(ib::sisl_coons_patch({curves[0].get(), curves[1].get(), curves[2].get(), curves[3].get()}));
      laps.lap("patch");
      return surf;
    };
    measure(row_of("coons", m, "sisl", "s1357 curves + s1390 + s1506", 1, tol), o.reps,
            [&](Laps& laps) {
              SislSurface surf = sisl_patch(laps);
              auto g = sisl_grid(surf.get(), us, vs);
              laps.lap("evaluate");
              return std::make_pair(std::move(surf), std::move(g));
            },
            [&](const std::pair<SislSurface, std::unique_ptr<double[]>>& r) {
              const double* g = r.second.get();
              auto at = [&](std::size_t i, std::size_t j) { return g + 3 * (j * k + i); };
              double e = std::max({dist(corners[0], at(0, 0)), dist(corners[1], at(k - 1, 0)), dist(corners[2], at(0, k - 1)),
                                   dist(corners[3], at(k - 1, k - 1))});
              // The boundary passes through the data at the curves' parameters.
              for (std::size_t t : sample_indices(m)) {
                e = std::max(e, dist(bottom[t], sisl_point(r.first.get(), params[0][t], 0.0)));
                e = std::max(e, dist(right[t], sisl_point(r.first.get(), 1.0, params[1][t])));
              }
              return e / diag;
            });
    // Deviation from interpatch's patch: the boundary curves differ between the data
    // points (knot placement) and s1390 blends its two lofts with its own weights.
    Laps none;
    const SislSurface surf = sisl_patch(none);
    auto g = sisl_grid(surf.get(), us, vs);
    agreement("coons", m, "sisl s1390 vs interpatch coons (linear blending)", max_deviation_transposed(*ref, g.get()) / diag, 0,
              "same boundary data and parameters; the curves' knots differ and s1390 is SISL's own blend of two lofts");
  }

  if (o.has("occt")) {
    std::array<Handle(TColgp_HArray1OfPnt), 4> pts;
    const std::array<const std::vector<Vec3>*, 4> edges{&bottom, &right, &top, &left};
    for (std::size_t e = 0; e < 4; ++e) {
      pts[e] = new TColgp_HArray1OfPnt(1, static_cast<int>(m));
      for (std::size_t t = 0; t < m; ++t) pts[e]->SetValue(static_cast<int>(t) + 1, gp_Pnt((*edges[e])[t].x, (*edges[e])[t].y, (*edges[e])[t].z));
    }
    auto occt_patch = [&](Laps& laps) {
      std::array<Handle(Geom_BSplineCurve), 4> c;
      for (std::size_t e = 0; e < 4; ++e) {
        const auto t = ib::chord_parameters(&(*edges[e]).data()->x, m);
        Handle(TColStd_HArray1OfReal) par = new TColStd_HArray1OfReal(1, static_cast<int>(m));
        for (std::size_t q = 0; q < m; ++q) par->SetValue(static_cast<int>(q) + 1, t[q]);
        GeomAPI_Interpolate interp(pts[e], par, Standard_False, 1e-9);
        interp.Perform();
        if (!interp.IsDone()) throw std::runtime_error("GeomAPI_Interpolate failed");
        c[e] = interp.Curve();
      }
      laps.lap("curves");
      GeomFill_BSplineCurves fill(c[0], c[1], c[2], c[3], GeomFill_CoonsStyle);
      Handle(Geom_BSplineSurface) s = fill.Surface();
      laps.lap("patch");
      return s;
    };
    std::vector<double> ou, ov;
    measure(row_of("coons", m, "occt", "GeomAPI_Interpolate + GeomFill_BSplineCurves (CoonsStyle) + D0 loop", 1, tol),
            o.reps,
            [&](Laps& laps) {
              Handle(Geom_BSplineSurface) s = occt_patch(laps);
              double u0, u1, v0, v1;
              s->Bounds(u0, u1, v0, v1);
              ou = interpatch::linspace(u0, u1, k);
              ov = interpatch::linspace(v0, v1, k);
              auto g = occt_grid(*s, ou, ov);
              laps.lap("evaluate");
              return g;
            },
            [&](const std::unique_ptr<double[]>& g) {
              // OpenCASCADE arranges the curves its own way: each corner of the grid
              // must be one of the data's corners.
              double e = 0;
              for (std::size_t c : {std::size_t{0}, k - 1, k * (k - 1), k * k - 1}) {
                double best = INFINITY;
                for (const Vec3& q : corners) best = std::min(best, dist(q, g.get() + 3 * c));
                e = std::max(e, best);
              }
              return e / diag;
            });
    // Deviation from interpatch's patch, in whichever of the eight orientations fits.
    Laps none;
    Handle(Geom_BSplineSurface) s = occt_patch(none);
    double u0, u1, v0, v1;
    s->Bounds(u0, u1, v0, v1);
    auto g = occt_grid(*s, interpatch::linspace(u0, u1, k), interpatch::linspace(v0, v1, k));
    double best = INFINITY;
    for (int flip = 0; flip < 8; ++flip) {
      double e = 0;
      for (std::size_t i = 0; i < k; i += 7)
        for (std::size_t j = 0; j < k; j += 7) {
          std::size_t a = flip & 1 ? k - 1 - i : i, b = flip & 2 ? k - 1 - j : j;
          if (flip & 4) std::swap(a, b);
          e = std::max(e, dist((*ref)(a, b), g.get() + 3 * (i * k + j)));
        }
      best = std::min(best, e);
    }
    agreement("coons", m, "occt GeomFill_BSplineCurves (CoonsStyle) vs interpatch coons", best / diag, 0,
              "every 7th point; OpenCASCADE's Coons style blends with its own functions over its own parametrization");
  }
  measure_memcpy(o, "coons", m, k * k * sizeof(Vec3));
}

// ---------------------------------------------------------------- job: whole process

struct ProcessResult {
  int status = -1;
  double seconds = 0;
  long maxrss_kb = 0;
  std::string out;
};

// Spawns argv with OMP_NUM_THREADS set (threads > 0; 0 passes this process's
// environment on unchanged) and `extra` added to the environment, and waits for it;
// stdout captured if asked.
ProcessResult spawn_and_wait(const std::vector<std::string>& args, int threads, bool capture,
                             const std::vector<std::string>& extra = {}) {
  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e)
    if (threads == 0 || std::strncmp(*e, "OMP_NUM_THREADS=", 16) != 0) env_strings.emplace_back(*e);
  if (threads > 0) env_strings.push_back("OMP_NUM_THREADS=" + std::to_string(threads));
  env_strings.insert(env_strings.end(), extra.begin(), extra.end());
  std::vector<char*> envp, argvp;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<std::string> args_copy = args;
  for (auto& s : args_copy) argvp.push_back(s.data());
  argvp.push_back(nullptr);

  int fds[2] = {-1, -1};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (capture) {
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_addclose(&actions, fds[1]);
  }
  ProcessResult r;
  pid_t pid = 0;
  const auto t0 = clock_type::now();
  const int spawned = posix_spawn(&pid, argvp[0], &actions, nullptr, argvp.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw std::runtime_error("cannot run " + args[0]);
  if (capture) {
    close(fds[1]);
    char buf[4096];
    for (ssize_t got; (got = read(fds[0], buf, sizeof buf)) > 0;) r.out.append(buf, static_cast<std::size_t>(got));
    close(fds[0]);
  }
  int status = 0;
  rusage ru{};
  if (wait4(pid, &status, 0, &ru) != pid) throw std::runtime_error("wait4 failed");
  r.seconds = seconds_since(t0);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.maxrss_kb = ru.ru_maxrss;
  return r;
}

// `compare --time-child PROGRAM ARGS...`: runs the program and prints "seconds
// maxrss_kb status" as the last line. A child's ru_maxrss starts from the peak of the
// process it was spawned from, so the program is spawned from this small process
// rather than from the benchmark holding its grids.
int time_child(int argc, char** argv) {
  const std::vector<std::string> args(argv, argv + argc);
  // With OMP_PROC_BIND set, OpenMP pinned this helper's (and the benchmark's) main
  // thread to one CPU at start, and a spawned program inherits that mask: it would
  // run all its threads on one CPU. It gets every online CPU back.
  cpu_set_t all;
  CPU_ZERO(&all);
  for (long c = 0; c < sysconf(_SC_NPROCESSORS_ONLN) && c < CPU_SETSIZE; ++c) CPU_SET(static_cast<int>(c), &all);
  sched_setaffinity(0, sizeof all, &all);
  const auto r = spawn_and_wait(args, 0, false);
  std::cout << '\n' << r.seconds << ' ' << r.maxrss_kb << ' ' << r.status << std::endl;
  return 0;
}

// Runs a whole process with OMP_NUM_THREADS = threads through --time-child: its wall
// clock from spawn to exit, its own peak resident memory and its exit status.
ProcessResult run_process(const std::string& self, const std::vector<std::string>& args, int threads,
                          const std::vector<std::string>& env) {
  std::vector<std::string> full{self, "--time-child"};
  full.insert(full.end(), args.begin(), args.end());
  const auto helper = spawn_and_wait(full, threads, true, env);
  ProcessResult r;
  const std::size_t last = helper.out.find_last_of('\n', helper.out.size() - 2);
  std::istringstream(helper.out.substr(last == std::string::npos ? 0 : last + 1)) >> r.seconds >> r.maxrss_kb >> r.status;
  if (helper.status != 0) r.status = helper.status;
  return r;
}

// The largest distance between the points of two .npy files of the same shape.
double npy_deviation(const fs::path& a_path, const fs::path& b_path) {
  const auto a = interpatch::io::read_npy(a_path), b = interpatch::io::read_npy(b_path);
  if (a.shape != b.shape) return INFINITY;
  double e = 0;
  for (std::size_t q = 0; q < a.data.size(); q += 3) e = std::max(e, dist(Vec3{a.data[q], a.data[q + 1], a.data[q + 2]}, b.data.data() + q));
  return e;
}

// The output's largest error over the diagonal (1 when it is not what was asked).
using OutputCheck = std::function<double(const fs::path&)>;

// One program of a whole-process job, and the check of what it writes.
struct Program {
  Program(std::string library_, std::string variant_, std::vector<std::string> args_, fs::path out_, int threads_,
          OutputCheck check_, double tolerance_ = 1e-9, std::vector<std::string> env_ = {})
      : library(std::move(library_)), variant(std::move(variant_)), args(std::move(args_)), out(std::move(out_)),
        threads(threads_), check(std::move(check_)), tolerance(tolerance_), env(std::move(env_)) {}

  std::string library, variant;
  std::vector<std::string> args;
  fs::path out;
  int threads;
  OutputCheck check;
  double tolerance;
  std::vector<std::string> env;
  std::optional<ProcessResult> first;  // the untimed first run
};

// Runs the program once, its output removed first; nullopt (and a note of it among
// the skipped) when it fails.
std::optional<ProcessResult> run_program(const std::string& self, const std::string& job, std::size_t n, const Program& p) {
  fs::remove(p.out);
  const auto r = run_process(self, p.args, p.threads, p.env);
  if (r.status == 0) return r;
  skipped(job, n, p.library, p.variant + ": exited with status " + std::to_string(r.status));
  return std::nullopt;
}

// Times whole processes in turn: each program once untimed (page cache, and the size
// of its output), then `runs` rounds in which every program runs once, so that all
// of them see the same machine from minute to minute. Round r starts with program
// r mod the count, so that no program always follows the same one: on this virtual
// machine a process that has just freed much memory (SISL's, 170 MiB) slows the
// first touches of fresh memory of the process after it. Each output is removed before
// its run and checked after it. Rounds stop early once they have taken `budget`
// seconds. A program that fails is dropped (and listed among the skipped). The rows
// go to g_rows and the console; they are returned in the order of `programs`.
std::vector<Row> time_in_turn(const std::string& self, const std::string& job, std::size_t n,
                              std::vector<Program>& programs, int runs, double budget) {
  for (auto& p : programs)
    if (!p.first) p.first = run_program(self, job, n, p);
  std::erase_if(programs, [](const Program& p) { return !p.first; });
  std::vector<Row> rows;
  for (const auto& p : programs) {
    rows.push_back(row_of(job, n, p.library, p.variant, p.threads, p.tolerance));
    rows.back().maxrss_bytes = 0.0;
  }
  double spent = 0;
  int done = 0;
  std::vector<bool> failed(programs.size(), false);
  for (; done < runs && (done == 0 || spent < budget); ++done)
    for (std::size_t i = 0; i < programs.size(); ++i) {
      const std::size_t k = (i + static_cast<std::size_t>(done)) % programs.size();
      if (failed[k]) continue;
      const auto r = run_program(self, job, n, programs[k]);
      if (!r) {
        failed[k] = true;
        rows[k].error = INFINITY;
        rows[k].note = "failed in a timed run";
        continue;
      }
      rows[k].times.push_back(r->seconds);
      rows[k].maxrss_bytes = std::max(*rows[k].maxrss_bytes, 1024.0 * static_cast<double>(r->maxrss_kb));
      spent += r->seconds;
      try {
        rows[k].output_bytes = static_cast<double>(fs::file_size(programs[k].out));
        rows[k].error = std::max(rows[k].error, programs[k].check(programs[k].out));
      } catch (const std::exception& e) {
        rows[k].error = INFINITY;
        rows[k].note = std::string("output unreadable: ") + e.what();
      }
    }
  for (auto& row : rows) {
    if (done < runs) row.note += (row.note.empty() ? "" : "; ") + std::to_string(done) + " of " + std::to_string(runs) + " runs (time budget)";
    measure(row, 0, [](Laps&) { return 0; }, [](int) { return 0.0; });
  }
  return rows;
}

// A command line as shown in tables: the files by their names.
std::string shown(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += (s.empty() ? "" : " ") + (a.find('/') != std::string::npos ? fs::path(a).filename().string() : a);
  return s;
}

void job_process(const Options& o, const std::string& self) {
  const std::size_t n = o.process_grid;
  std::cout << "\nWhole process: read a " << n << " x " << n << " .npy grid, interpolate, evaluate " << n << " x " << n
            << ", write .npy\n";
  fs::create_directories(o.workdir);
  const fs::path dir = fs::absolute(o.workdir);
  const PointGrid grid = ib::make_terrain(n);
  const double diag = diagonal(grid.data(), grid.size());
  const std::array<std::size_t, 3> shape{n, n, 3};
  interpatch::io::write_npy(dir / "grid.npy", shape, std::span<const double>(&grid.data()->x, 3 * grid.size()));
  std::ofstream(dir / "spec.json") << R"({"type": "interpolate", "points": {"npy": "grid.npy"}})" << '\n';
  const std::string grid_arg = std::to_string(n);

  // The output's corners are the data's corners (the grid spans the whole domain).
  auto check_output = [&](const fs::path& out) {
    const auto a = interpatch::io::read_npy(out);
    if (a.shape != std::vector<std::size_t>{n, n, 3}) return 1.0;
    const double* p = a.data.data();
    const double e = std::max({dist(grid(0, 0), p), dist(grid(0, n - 1), p + 3 * (n - 1)),
                               dist(grid(n - 1, 0), p + 3 * n * (n - 1)), dist(grid(n - 1, n - 1), p + 3 * (n * n - 1))});
    return e / diag;
  };
  std::vector<Program> programs;
  if (o.has("interpatch")) {
    const std::vector<std::string> eval_args{o.cli,   "eval", (dir / "spec.json").string(), "--grid", grid_arg,
                                             "-o", (dir / "interpatch_out.npy").string()};
    const std::string variant = "interpatch eval spec.json --grid " + grid_arg + " -o out.npy";
    for (int threads : o.threads) programs.emplace_back("interpatch", variant, eval_args, dir / "interpatch_out.npy", threads, check_output);
    // The same with the output made durable (fsync) before the command returns.
    programs.emplace_back("interpatch", "INTERPATCH_SYNC=1 " + variant, eval_args, dir / "interpatch_sync_out.npy",
                          o.threads.back(), check_output, 1e-9, std::vector<std::string>{"INTERPATCH_SYNC=1"});
    programs.back().args.back() = programs.back().out.string();
  }
  if (o.has("sisl"))
    programs.emplace_back("sisl", "sisl_eval grid.npy out.npy " + grid_arg,
                          std::vector<std::string>{o.sisl_eval, (dir / "grid.npy").string(), (dir / "sisl_out.npy").string(), grid_arg},
                          dir / "sisl_out.npy", 1, check_output);
  // A whole process varies by several milliseconds from run to run here (page
  // cache, scheduling): at least 7 runs for its median.
  time_in_turn(self, "process", n, programs, std::max(o.reps, 7), o.process_budget);
  if (fs::exists(dir / "interpatch_out.npy") && fs::exists(dir / "sisl_out.npy")) {
    agreement("process", n, "sisl_eval output vs interpatch eval output",
              npy_deviation(dir / "interpatch_out.npy", dir / "sisl_out.npy") / diag, 0,
              "same parameters; knots at the parameters (SISL) against averaged knots (interpatch)");
  }
  if (o.has("memcpy")) {
    // The bytes a whole process cannot avoid moving: the grid read and the grid written.
    measure_memcpy(o, "process", n, n * n * sizeof(Vec3));
  }
}

// ---------------------------------------------------------------- jobs: whole processes against pure I/O

// An (..., 3) .npy of points.
void write_points(const fs::path& path, std::vector<std::size_t> shape, std::span<const Vec3> points) {
  shape.push_back(3);
  interpatch::io::write_npy(path, shape, std::span<const double>(&points.data()->x, 3 * points.size()));
}

// The .npy a program wrote as a grid of points, when it has the expected shape
// (without the trailing 3) and every value is finite.
std::optional<interpatch::io::NpyArray> read_output(const fs::path& path, std::vector<std::size_t> shape) {
  shape.push_back(3);
  auto a = interpatch::io::read_npy(path);
  if (a.shape != shape || !std::all_of(a.data.begin(), a.data.end(), [](double x) { return std::isfinite(x); }))
    return std::nullopt;
  return a;
}

// Every `stride`-th index of 0..n-1 along each direction, the last one included.
std::vector<std::size_t> strided(std::size_t n, std::size_t stride) {
  std::vector<std::size_t> s;
  for (std::size_t i = 0; i < n; i += stride) s.push_back(i);
  if (s.back() != n - 1) s.push_back(n - 1);
  return s;
}

double param(std::size_t i, std::size_t n) { return static_cast<double>(i) / static_cast<double>(n - 1); }

// Checks a K x K x K volume grid in a .npy against the shape it must reproduce, at
// every third point along each direction.
OutputCheck volume_check(std::size_t k, double diag, Vec3 (*shape)(double, double, double)) {
  return [=](const fs::path& out) {
    const auto a = read_output(out, {k, k, k});
    if (!a) return 1.0;
    double e = 0;
    const auto idx = strided(k, 3);
    for (std::size_t i : idx)
      for (std::size_t j : idx)
        for (std::size_t l : idx)
          e = std::max(e, dist(shape(param(i, k), param(j, k), param(l, k)), a->data.data() + 3 * ((i * k + j) * k + l)));
    return e / diag;
  };
}

// What run_process_job needs of a job.
struct ProcessJob {
  ProcessJob(std::string name_, std::string what_, std::size_t n_, fs::path dir_, std::vector<fs::path> inputs_,
             std::vector<std::string> command_, fs::path out_, OutputCheck check_, double tolerance_)
      : name(std::move(name_)), what(std::move(what_)), n(n_), dir(std::move(dir_)), inputs(std::move(inputs_)),
        command(std::move(command_)), out(std::move(out_)), check(std::move(check_)), tolerance(tolerance_) {}

  std::string name, what;
  std::size_t n;                     // the size shown (data points along a direction)
  fs::path dir;                      // where its files are
  std::vector<fs::path> inputs;      // the spec, then every data file it names
  std::vector<std::string> command;  // interpatch's arguments
  fs::path out;
  OutputCheck check;
  double tolerance;
  std::vector<Program> others;       // SISL's whole process, another interpatch command
  int runs = 0;                      // 0: max(--reps, 5)
  std::optional<double> rss_target;  // peak RSS over input + output bytes
};

json g_processes = json::array();

std::uintmax_t total_size(const std::vector<fs::path>& files) {
  std::uintmax_t s = 0;
  for (const auto& f : files) s += fs::file_size(f);
  return s;
}

// The job's interpatch command(s), the pure-I/O program of the same input files and
// output size, and the job's other programs, timed in turn; one summary per
// interpatch command.
void run_process_job(const Options& o, const std::string& self, ProcessJob job) {
  const int threads = o.threads.back();
  std::vector<std::string> args{o.cli};
  args.insert(args.end(), job.command.begin(), job.command.end());
  std::vector<Program> programs{{"interpatch", "interpatch " + shown(job.command), args, job.out, threads, job.check, job.tolerance}};
  programs[0].first = run_program(self, job.name, job.n, programs[0]);
  if (!programs[0].first) {
    g_processes.push_back({{"job", job.name}, {"n", job.n}, {"what", job.what}, {"failed", g_skipped.back()["reason"]},
                           {"check_ok", false}});
    return;
  }
  const std::uintmax_t in_bytes = total_size(job.inputs), out_bytes = fs::file_size(job.out);
  std::vector<std::string> io_args{o.pure_io, (job.dir / "pure_io_out").string(), std::to_string(out_bytes)};
  for (const auto& f : job.inputs) io_args.push_back(f.string());
  programs.push_back({"pure_io",
                      "pure_io: " + std::to_string(job.inputs.size()) + " input files, " + std::to_string(out_bytes) +
                          " bytes out",
                      io_args, job.dir / "pure_io_out", threads,
                      [out_bytes](const fs::path& out) { return fs::file_size(out) == out_bytes ? 0.0 : 1.0; }, 0});
  // SISL's process is timed in rounds of its own, in turn with the first interpatch
  // command again, not between interpatch and pure I/O: on this virtual machine a
  // process that has just freed much memory (SISL's, 170 MiB) slows the first
  // touches of fresh memory of the process after it, by as much as a whole pure-I/O
  // run, whichever program that is.
  std::vector<Program> with_sisl;
  for (const auto& p : job.others) (p.library == "sisl" ? with_sisl : programs).push_back(p);
  const int runs = job.runs ? job.runs : std::max(o.reps, 5);
  const auto rows = time_in_turn(self, job.name, job.n, programs, runs, o.process_budget);
  std::vector<Row> sisl_rows;
  if (!with_sisl.empty()) {
    with_sisl.insert(with_sisl.begin(), programs.front());
    with_sisl.front().variant += " (in turn with SISL)";
    sisl_rows = time_in_turn(self, job.name, job.n, with_sisl, runs, o.process_budget);
  }

  auto find = [&](const std::vector<Row>& in, const std::string& library) -> const Row* {
    for (const auto& r : in)
      if (r.library == library) return &r;
    return nullptr;
  };
  auto side = [](const Row* r) {
    if (!r) return json(nullptr);
    return json{{"variant", r->variant}, {"median_s", median(r->times)}, {"maxrss_bytes", r->maxrss_bytes.value_or(0)},
                {"output_bytes", r->output_bytes.value_or(0)}, {"check_ok", r->ok()},
                {"check_max_rel_error", r->error}, {"runs", r->times.size()}, {"note", r->note}};
  };
  const Row *io = find(rows, "pure_io"), *sisl = find(sisl_rows, "sisl"), *beside_sisl = find(sisl_rows, "interpatch");
  for (const auto& r : rows) {
    if (r.library != "interpatch") continue;
    const double t = median(r.times), io_t = io ? median(io->times) : NAN, sisl_t = sisl ? median(sisl->times) : NAN;
    // Against SISL: the first command's median in the rounds with SISL.
    const double t_sisl = beside_sisl && &r == &rows.front() ? median(beside_sisl->times) : t;
    const double written = r.output_bytes.value_or(0);
    const double rss_over_io = r.maxrss_bytes.value_or(0) / (static_cast<double>(in_bytes) + written);
    json entry{{"job", job.name}, {"n", job.n}, {"what", job.what}, {"threads", r.threads},
               {"input_files", job.inputs.size()}, {"input_bytes", in_bytes}, {"output_bytes", written},
               {"interpatch", side(&r)}, {"pure_io", side(io)}, {"sisl", side(sisl)},
               {"interpatch_over_pure_io", io ? json(t / io_t) : json(nullptr)}, {"target_over_pure_io", 2},
               {"sisl_over_interpatch", sisl ? json(sisl_t / t_sisl) : json(nullptr)},
               {"rss_over_io", rss_over_io},
               {"target_rss_over_io", job.rss_target && &r == &rows.front() ? json(*job.rss_target) : json(nullptr)},
               {"check_ok", r.ok() && (!io || io->ok()) && (!sisl || sisl->ok())}};
    g_processes.push_back(entry);
    std::cout << "  => " << job.name << ": " << r.variant.substr(0, 70) << "  " << format_time(t) << " = "
              << std::setprecision(3) << t / io_t << " x pure I/O (" << format_time(io_t) << ")";
    if (sisl) std::cout << ", SISL " << format_time(sisl_t) << " = " << sisl_t / t_sisl << " x of " << format_time(t_sisl);
    std::cout << "; peak RSS " << std::setprecision(4) << r.maxrss_bytes.value_or(0) / 1048576 << " MiB = "
              << std::setprecision(3) << rss_over_io << " x input + output" << std::endl;
  }
}

// The four boundary curves of the linear Coons job, 1024 points each, from the
// translation surface (each side's points equally spaced in its parameter): the
// files, and the diagonal of the points.
struct CoonsData {
  fs::path spec;
  std::vector<fs::path> inputs;
  double diag = 0;
};

CoonsData write_coons_data(const fs::path& dir, std::size_t m) {
  const ib::GraphSurface shape{};
  std::vector<Vec3> all;
  CoonsData d{dir / "coons.json", {dir / "coons.json"}, 0};
  json boundary = json::object();
  for (const char* side : {"v0", "v1", "u0", "u1"}) {
    std::vector<Vec3> p(m);
    for (std::size_t t = 0; t < m; ++t) {
      const double s = param(t, m), end = side[1] == '0' ? 0.0 : 1.0;
      p[t] = side[0] == 'v' ? shape.point(s, end) : shape.point(end, s);
    }
    const std::string file = std::string("coons_") + side + ".npy";
    write_points(dir / file, {m}, p);
    d.inputs.push_back(dir / file);
    boundary[side] = {{"interpolate", {{"npy", file}}}};
    all.insert(all.end(), p.begin(), p.end());
  }
  std::ofstream(d.spec) << json{{"type", "coons"}, {"boundary", boundary}}.dump(2) << '\n';
  d.diag = diagonal(all.data(), all.size());
  return d;
}

// The corners of a K x K grid in a .npy against the surface's corners.
double corner_error(const double* g, std::size_t k, const std::array<Vec3, 4>& corners) {
  return std::max({dist(corners[0], g), dist(corners[1], g + 3 * (k - 1)), dist(corners[2], g + 3 * k * (k - 1)),
                   dist(corners[3], g + 3 * (k * k - 1))});
}

// Corners S(0, 0), S(0, 1), S(1, 0), S(1, 1): the order of a u-slowest grid's corners.
template <class S>
std::array<Vec3, 4> corners_of(const S& s) {
  return {s.point(0, 0), s.point(0, 1), s.point(1, 0), s.point(1, 1)};
}

// Points on the graph surface, at its corners: what a Coons patch or a network of its
// curves must give, whatever their parameters.
OutputCheck graph_check(const ib::GraphSurface& shape, std::size_t k, double diag) {
  const auto corners = corners_of(shape);
  return [=](const fs::path& out) {
    const auto a = read_output(out, {k, k});
    if (!a) return 1.0;
    double e = corner_error(a->data.data(), k, corners);
    for (std::size_t q = 0; q < k * k; ++q) e = std::max(e, shape.height_error(a->data.data() + 3 * q));
    return e / diag;
  };
}

void job_eval_interpolate(const Options& o, const std::string& self, const fs::path& dir) {
  const std::size_t n = o.process_grid, k = o.eval_points;
  const PointGrid grid = ib::make_terrain(n);
  write_points(dir / "grid.npy", {n, n}, std::span<const Vec3>(grid.data(), grid.size()));
  std::ofstream(dir / "interpolate.json") << R"({"type": "interpolate", "points": {"npy": "grid.npy"}})" << '\n';
  const double diag = diagonal(grid.data(), grid.size());
  // interpatch's output: the data's corners at the corners, and at sampled points the
  // library's own interpolation of the same grid (through its API, not the command).
  const auto ip = interpatch::interpolate_surface(grid);
  const auto idx = sample_indices(k);
  std::map<std::pair<std::size_t, std::size_t>, Vec3> ref;
  const auto [u0, u1] = ip.surface.domain_u();
  const auto [v0, v1] = ip.surface.domain_v();
  for (std::size_t i : idx)
    for (std::size_t j : idx) ref[{i, j}] = ip.surface.point(u0 + (u1 - u0) * param(i, k), v0 + (v1 - v0) * param(j, k));
  const std::array<Vec3, 4> corners{grid(0, 0), grid(0, n - 1), grid(n - 1, 0), grid(n - 1, n - 1)};
  auto check = [=](const fs::path& out) {
    const auto a = read_output(out, {k, k});
    if (!a) return 1.0;
    double e = corner_error(a->data.data(), k, corners);
    for (const auto& [ij, p] : ref) e = std::max(e, dist(p, a->data.data() + 3 * (ij.first * k + ij.second)));
    return e / diag;
  };
  auto corners_only = [=](const fs::path& out) {
    const auto a = read_output(out, {k, k});
    return a ? corner_error(a->data.data(), k, corners) / diag : 1.0;
  };
  ProcessJob job{"eval_interpolate", "bicubic interpolation of a " + std::to_string(n) + "² .npy grid, " + std::to_string(k) + "² points",
                 n, dir, {dir / "interpolate.json", dir / "grid.npy"},
                 {"eval", (dir / "interpolate.json").string(), "--grid", std::to_string(k), "-o", (dir / "interpatch_out.npy").string()},
                 dir / "interpatch_out.npy", check, 1e-9};
  if (o.has("sisl"))
    job.others.push_back({"sisl", "sisl_eval grid.npy out.npy " + std::to_string(k),
                          {o.sisl_eval, (dir / "grid.npy").string(), (dir / "sisl_out.npy").string(), std::to_string(k)},
                          dir / "sisl_out.npy", 1, corners_only});
  run_process_job(o, self, std::move(job));
  if (fs::exists(dir / "interpatch_out.npy") && fs::exists(dir / "sisl_out.npy"))
    agreement("eval_interpolate", n, "sisl_eval output vs interpatch eval output",
              npy_deviation(dir / "interpatch_out.npy", dir / "sisl_out.npy") / diag, 0,
              "same parameters; knots at the parameters (SISL) against averaged knots (interpatch)");
}

void job_eval_coons(const Options& o, const std::string& self, const fs::path& dir) {
  const std::size_t m = o.coons_points, k = o.eval_points;
  const auto d = write_coons_data(dir, m);
  const ib::GraphSurface shape{};
  const auto corners = corners_of(shape);
  ProcessJob job{"eval_coons", "linear Coons patch of four " + std::to_string(m) + "-point interpolated curves (.npy), " + std::to_string(k) + "² points",
                 m, dir, d.inputs,
                 {"eval", d.spec.string(), "--grid", std::to_string(k), "-o", (dir / "interpatch_out.npy").string()},
                 dir / "interpatch_out.npy", graph_check(shape, k, d.diag), 1e-7};
  if (o.has("sisl"))
    job.others.push_back({"sisl", "sisl_eval --coons v0.npy v1.npy u0.npy u1.npy out.npy " + std::to_string(k),
                          {o.sisl_eval, "--coons", (dir / "coons_v0.npy").string(), (dir / "coons_v1.npy").string(),
                           (dir / "coons_u0.npy").string(), (dir / "coons_u1.npy").string(),
                           (dir / "sisl_out.npy").string(), std::to_string(k)},
                          dir / "sisl_out.npy", 1,
                          [=](const fs::path& out) {
                            const auto a = read_output(out, {k, k});
                            return a ? corner_error(a->data.data(), k, corners) / d.diag : 1.0;
                          }});
  run_process_job(o, self, std::move(job));
  if (fs::exists(dir / "interpatch_out.npy") && fs::exists(dir / "sisl_out.npy")) {
    agreement("eval_coons", m, "sisl_eval --coons output vs interpatch eval output",
              npy_deviation(dir / "interpatch_out.npy", dir / "sisl_out.npy") / d.diag, 0,
              "the same boundary points and chord parameters; s1390 is SISL's own blend of two lofts");
    // interpatch's check holds its output to the surface (to 1e-7); SISL's is shown.
    const auto a = interpatch::io::read_npy(dir / "sisl_out.npy");
    double e = 0;
    for (std::size_t q = 0; q < a.data.size(); q += 3) e = std::max(e, shape.height_error(a.data.data() + q));
    agreement("eval_coons", m, "sisl_eval --coons output vs the translation surface of the boundary", e / d.diag, 0,
              "a linear Coons patch reproduces z = f(x) + g(y) from its boundary (interpatch's output: within its check)");
  }
}

void job_eval_coons_hermite(const Options& o, const std::string& self, const fs::path& dir) {
  constexpr std::size_t m = 256;
  const std::size_t k = o.eval_points;
  const ib::GraphSurface shape{true};
  std::vector<fs::path> inputs{dir / "coons_hermite.json"};
  std::vector<Vec3> all;
  // Each side as a Hermite curve: points and tangents (derivatives along the side),
  // at equally spaced parameters; the cross derivatives likewise.
  auto hermite = [&](const std::string& name, auto&& value, auto&& tangent) {
    std::vector<Vec3> p(m), t(m);
    for (std::size_t q = 0; q < m; ++q) {
      p[q] = value(param(q, m));
      t[q] = tangent(param(q, m));
    }
    write_points(dir / (name + "_points.npy"), {m}, p);
    write_points(dir / (name + "_tangents.npy"), {m}, t);
    inputs.push_back(dir / (name + "_points.npy"));
    inputs.push_back(dir / (name + "_tangents.npy"));
    if (name.starts_with("boundary")) all.insert(all.end(), p.begin(), p.end());
    return json{{"hermite", {{"points", {{"npy", name + "_points.npy"}}}, {"tangents", {{"npy", name + "_tangents.npy"}}}}}};
  };
  json boundary = json::object(), cross = json::object();
  for (const double e : {0.0, 1.0}) {
    const std::string end = e == 0 ? "0" : "1";
    boundary["v" + end] = hermite("boundary_v" + end, [&](double u) { return shape.point(u, e); }, [&](double u) { return shape.du(u, e); });
    boundary["u" + end] = hermite("boundary_u" + end, [&](double v) { return shape.point(e, v); }, [&](double v) { return shape.dv(e, v); });
    cross["v" + end] = hermite("cross_v" + end, [&](double u) { return shape.dv(u, e); }, [&](double u) { return shape.duv(u, e); });
    cross["u" + end] = hermite("cross_u" + end, [&](double v) { return shape.du(e, v); }, [&](double v) { return shape.duv(e, v); });
  }
  std::ofstream(inputs[0]) << json{{"type", "coons"}, {"blending", "hermite"}, {"boundary", boundary}, {"cross_derivatives", cross}}.dump(2) << '\n';
  run_process_job(o, self,
                  {"eval_coons_hermite", "Coons patch with cross derivatives, Hermite blending, eight " + std::to_string(m) + "-point Hermite curves (.npy), " + std::to_string(k) + "² points",
                   m, dir, inputs,
                   {"eval", inputs[0].string(), "--grid", std::to_string(k), "-o", (dir / "interpatch_out.npy").string()},
                   dir / "interpatch_out.npy", graph_check(shape, k, diagonal(all.data(), all.size())), 1e-7});
}

// A network of 12 x 12 curves of 200 points from the translation surface, each curve
// interpolated at equally spaced parameters through points at equally spaced
// stations; the curves cross at stations, whose parameters are given.
void job_eval_network(const Options& o, const std::string& self, const fs::path& dir, const std::string& name,
                      const std::string& method) {
  constexpr std::size_t curves = 12, m = 200;
  const std::size_t k = o.eval_points;
  const ib::GraphSurface shape{};
  std::vector<fs::path> inputs{dir / (name + ".json")};
  std::vector<double> crossing(curves);
  for (std::size_t c = 0; c < curves; ++c) crossing[c] = param((c * (m - 1) + (curves - 1) / 2) / (curves - 1), m);
  std::vector<Vec3> all;
  auto family = [&](char dir_name) {
    json list = json::array();
    for (std::size_t c = 0; c < curves; ++c) {
      std::vector<Vec3> p(m);
      for (std::size_t q = 0; q < m; ++q)
        p[q] = dir_name == 'u' ? shape.point(param(q, m), crossing[c]) : shape.point(crossing[c], param(q, m));
      const std::string file = std::string("network_") + dir_name + std::to_string(c) + ".npy";
      write_points(dir / file, {m}, p);
      inputs.push_back(dir / file);
      all.insert(all.end(), p.begin(), p.end());
      list.push_back({{"interpolate", {{"npy", file}}}, {"param", "uniform"}});
    }
    return list;
  };
  const json spec{{"type", "network"}, {"method", method}, {"u_curves", family('u')}, {"v_curves", family('v')},
                  {"u_params", crossing}, {"v_params", crossing}};
  std::ofstream(inputs[0]) << spec.dump(2) << '\n';
  run_process_job(o, self,
                  {name, "network, method " + method + ", " + std::to_string(curves) + " x " + std::to_string(curves) + " curves of " + std::to_string(m) + " points (.npy), " + std::to_string(k) + "² points",
                   m, dir, inputs,
                   {"eval", inputs[0].string(), "--grid", std::to_string(k), "-o", (dir / "interpatch_out.npy").string()},
                   dir / "interpatch_out.npy", graph_check(shape, k, diagonal(all.data(), all.size())), 1e-7});
}

constexpr std::size_t volume_data = 128, volume_grid = 200;

double twisted_block_diagonal() {
  std::vector<Vec3> c;
  for (int q = 0; q < 8; ++q) c.push_back(ib::TwistedBlock::point(q & 4 ? 1 : 0, q & 2 ? 1 : 0, q & 1 ? 1 : 0));
  return diagonal(c.data(), c.size());
}

std::vector<std::string> eval_volume_command(const fs::path& spec, const fs::path& out) {
  return {"eval", spec.string(), "--grid", std::to_string(volume_grid), "-o", out.string()};
}

void job_eval_interpolate_volume(const Options& o, const std::string& self, const fs::path& dir) {
  constexpr std::size_t n = volume_data;
  std::vector<Vec3> p(n * n * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t l = 0; l < n; ++l) p[(i * n + j) * n + l] = ib::TwistedBlock::point(param(i, n), param(j, n), param(l, n));
  write_points(dir / "block.npy", {n, n, n}, p);
  std::ofstream(dir / "interpolate_volume.json") << R"({"type": "interpolate_volume", "points": {"npy": "block.npy"}})" << '\n';
  run_process_job(o, self,
                  {"eval_interpolate_volume", "tricubic interpolation of a " + std::to_string(n) + "³ .npy grid, " + std::to_string(volume_grid) + "³ points",
                   n, dir, {dir / "interpolate_volume.json", dir / "block.npy"},
                   eval_volume_command(dir / "interpolate_volume.json", dir / "interpatch_out.npy"), dir / "interpatch_out.npy",
                   volume_check(volume_grid, twisted_block_diagonal(), &ib::TwistedBlock::point), 1e-7});
}

void job_eval_coons_volume(const Options& o, const std::string& self, const fs::path& dir) {
  constexpr std::size_t n = volume_data;
  std::vector<fs::path> inputs{dir / "coons_volume.json"};
  json faces = json::object();
  // Face u0 is S(0, v, w) by (v, w), v0 is S(u, 0, w) by (u, w), w0 S(u, v, 0) by (u, v).
  for (int axis = 0; axis < 3; ++axis)
    for (const double e : {0.0, 1.0}) {
      std::vector<Vec3> p(n * n);
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
          const double a = param(i, n), b = param(j, n);
          p[i * n + j] = axis == 0 ? ib::TwistedBlock::point(e, a, b)
                         : axis == 1 ? ib::TwistedBlock::point(a, e, b)
                                     : ib::TwistedBlock::point(a, b, e);
        }
      const std::string face = std::string(1, "uvw"[axis]) + (e == 0 ? "0" : "1");
      write_points(dir / ("face_" + face + ".npy"), {n, n}, p);
      inputs.push_back(dir / ("face_" + face + ".npy"));
      faces[face] = {{"type", "interpolate"}, {"points", {{"npy", "face_" + face + ".npy"}}}};
    }
  std::ofstream(inputs[0]) << json{{"type", "coons_volume"}, {"faces", faces}}.dump(2) << '\n';
  run_process_job(o, self,
                  {"eval_coons_volume", "Coons volume of six faces interpolating " + std::to_string(n) + "² .npy grids, " + std::to_string(volume_grid) + "³ points",
                   n, dir, inputs, eval_volume_command(inputs[0], dir / "interpatch_out.npy"), dir / "interpatch_out.npy",
                   volume_check(volume_grid, twisted_block_diagonal(), &ib::TwistedBlock::point), 1e-7});
}

void job_eval_hermite_volume(const Options& o, const std::string& self, const fs::path& dir) {
  auto vec = [](const Vec3& v) { return json{v.x, v.y, v.z}; };
  json corners = json::array();
  for (int c = 0; c < 8; ++c) {
    const double u = c & 4 ? 1 : 0, v = c & 2 ? 1 : 0, w = c & 1 ? 1 : 0;
    auto d = [&](int a, int b, int e) { return vec(ib::TricubicMap::derivative(a, b, e, u, v, w)); };
    corners.push_back({{"p", d(0, 0, 0)}, {"du", d(1, 0, 0)}, {"dv", d(0, 1, 0)}, {"dw", d(0, 0, 1)}, {"duv", d(1, 1, 0)},
                       {"duw", d(1, 0, 1)}, {"dvw", d(0, 1, 1)}, {"duvw", d(1, 1, 1)}});
  }
  const fs::path spec = dir / "hermite_volume.json";
  std::ofstream(spec) << json{{"type", "hermite_volume"}, {"corners", corners}}.dump(2) << '\n';
  std::vector<Vec3> c;
  for (int q = 0; q < 8; ++q) c.push_back(ib::TricubicMap::point(q & 4 ? 1 : 0, q & 2 ? 1 : 0, q & 1 ? 1 : 0));
  run_process_job(o, self,
                  {"eval_hermite_volume", "tricubic Hermite volume of eight corners (inline: the form takes no data files), " + std::to_string(volume_grid) + "³ points",
                   8, dir, {spec}, eval_volume_command(spec, dir / "interpatch_out.npy"), dir / "interpatch_out.npy",
                   volume_check(volume_grid, diagonal(c.data(), c.size()), &ib::TricubicMap::point), 1e-12});
}

void job_eval_trilinear(const Options& o, const std::string& self, const fs::path& dir) {
  json spec{{"type", "trilinear"}};
  for (int c = 0; c < 8; ++c) {
    const Vec3& p = ib::TrilinearBlock::corners[c];
    spec["p" + std::to_string(c >> 2) + std::to_string((c >> 1) & 1) + std::to_string(c & 1)] = {p.x, p.y, p.z};
  }
  const fs::path path = dir / "trilinear.json";
  std::ofstream(path) << spec.dump(2) << '\n';
  const auto& c = ib::TrilinearBlock::corners;
  run_process_job(o, self,
                  {"eval_trilinear", "trilinear volume of eight corners (inline: the form takes no data files), " + std::to_string(volume_grid) + "³ points",
                   8, dir, {path}, eval_volume_command(path, dir / "interpatch_out.npy"), dir / "interpatch_out.npy",
                   volume_check(volume_grid, diagonal(c.data(), c.size()), &ib::TrilinearBlock::point), 1e-12});
}

// A whole file.
std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {(std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()};
}

// The points and normals of a surface mesh in a .vts (VTK XML, raw appended arrays,
// UInt64 byte counts, u index fastest), as interpatch writes them; empty when the
// file is not of that form.
std::pair<std::vector<double>, std::vector<double>> read_vts(const fs::path& path, std::size_t points) {
  const std::string text = file_bytes(path);
  const std::size_t data = text.find("<AppendedData encoding=\"raw\">");
  const std::size_t start = data == std::string::npos ? data : text.find('_', data);
  auto array = [&](const std::string& name) {
    std::vector<double> v;
    const std::size_t at = text.find("Name=\"" + name + "\"");
    const std::size_t off = at == std::string::npos ? at : text.find("offset=\"", at);
    if (start == std::string::npos || off == std::string::npos || off > data) return v;
    const std::size_t pos = start + 1 + std::strtoull(text.c_str() + off + 8, nullptr, 10);
    std::uint64_t bytes = 0;
    if (pos + 8 > text.size()) return v;
    std::memcpy(&bytes, text.data() + pos, 8);
    if (bytes != 24 * points || pos + 8 + bytes > text.size()) return v;
    v.resize(3 * points);
    std::memcpy(v.data(), text.data() + pos + 8, bytes);
    return v;
  };
  return {array("Points"), array("Normals")};
}

// A surface mesh's points and normals (three doubles each) as a file holds them,
// and the order of its vertices: u fastest (the structured formats) or v fastest
// (the vertex lists of .obj and .ply). Empty points when the file is not of the form
// interpatch writes.
struct MeshRead {
  std::vector<double> points, normals;
  bool u_fastest = true;
};

template <class T>
T from_bytes(const std::string& s, std::size_t at, std::endian order) {
  char b[sizeof(T)];
  std::memcpy(b, s.data() + at, sizeof(T));
  if (order != std::endian::native) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

// Legacy VTK: big-endian points after "POINTS n double", normals after "NORMALS".
MeshRead read_legacy_vtk(const fs::path& path, std::size_t n) {
  const std::string s = file_bytes(path);
  MeshRead m;
  auto array = [&](const std::string& line, std::vector<double>& out) {
    const std::size_t at = s.find(line);
    if (at == std::string::npos || at + line.size() + 24 * n > s.size()) return;
    out.resize(3 * n);
    for (std::size_t k = 0; k < 3 * n; ++k) out[k] = from_bytes<double>(s, at + line.size() + 8 * k, std::endian::big);
  };
  array("POINTS " + std::to_string(n) + " double\n", m.points);
  array("NORMALS normals double\n", m.normals);
  return m;
}

// PLY, binary little endian: each vertex x y z nx ny nz as doubles after the header.
MeshRead read_ply(const fs::path& path, std::size_t n) {
  const std::string s = file_bytes(path);
  MeshRead m;
  m.u_fastest = false;
  const std::size_t at = s.find("end_header\n");
  if (s.find("element vertex " + std::to_string(n) + "\n") == std::string::npos || at == std::string::npos ||
      at + 11 + 48 * n > s.size())
    return m;
  for (std::size_t q = 0; q < n; ++q)
    for (std::size_t c = 0; c < 6; ++c)
      (c < 3 ? m.points : m.normals).push_back(from_bytes<double>(s, at + 11 + 48 * q + 8 * c, std::endian::little));
  return m;
}

// Binary STL: the corners of every triangle (single precision); the facet normals
// are the triangles', not the surface's, and are left out. `triangles` is what the
// header must count.
MeshRead read_stl(const fs::path& path, std::size_t triangles) {
  const std::string s = file_bytes(path);
  MeshRead m;
  if (s.size() != 84 + 50 * triangles || from_bytes<std::uint32_t>(s, 80, std::endian::little) != triangles) return m;
  for (std::size_t t = 0; t < triangles; ++t)
    for (std::size_t c = 0; c < 9; ++c) m.points.push_back(from_bytes<float>(s, 84 + 50 * t + 12 + 4 * c, std::endian::little));
  return m;
}

// Wavefront OBJ: the "v" and "vn" lines.
MeshRead read_obj(const fs::path& path) {
  std::ifstream in(path);
  MeshRead m;
  m.u_fastest = false;
  for (std::string line; std::getline(in, line);) {
    const bool v = line.rfind("v ", 0) == 0, vn = line.rfind("vn ", 0) == 0;
    if (!v && !vn) continue;
    std::istringstream fields(line.substr(v ? 2 : 3));
    fields.imbue(std::locale::classic());
    for (int c = 0; c < 3; ++c) {
      double x = std::numeric_limits<double>::quiet_NaN();
      fields >> x;
      (v ? m.points : m.normals).push_back(x);
    }
  }
  return m;
}

// Plot3D, ASCII, one grid: every x, every y, every z, u fastest.
MeshRead read_plot3d(const fs::path& path, std::size_t n) {
  std::ifstream in(path);
  in.imbue(std::locale::classic());
  MeshRead m;
  std::size_t grids = 0, ni = 0, nj = 0, nk = 0;
  in >> grids >> ni >> nj >> nk;
  if (grids != 1 || ni * nj * nk != n) return m;
  std::vector<double> v(3 * n);
  for (double& x : v) in >> x;
  if (!in) return m;
  m.points.resize(3 * n);
  for (std::size_t q = 0; q < n; ++q)
    for (std::size_t c = 0; c < 3; ++c) m.points[3 * q + c] = v[c * n + q];
  return m;
}

// The check of a mesh of the Coons patch of write_coons_data on k × k vertices:
// every point on the surface, every normal the surface's (to the error of the
// boundary curves), the corners in place. Without normals (STL), no normal check;
// without an order (STL's triangles), no corner check.
double mesh_error(const MeshRead& m, std::size_t k, double diag, bool corners_in_place) {
  const ib::GraphSurface shape{};
  const auto corners = corners_of(shape);
  const auto& p = m.points;
  const std::size_t n = p.size() / 3;
  if (p.empty() || (!m.normals.empty() && m.normals.size() != p.size()) ||
      !std::all_of(p.begin(), p.end(), [](double x) { return std::isfinite(x); }))
    return 1.0;
  double e = 0;
  if (corners_in_place) {
    if (n != k * k) return 1.0;
    // Corner (u, v) = (1, 0) is vertex k − 1 when u is fastest, vertex k(k − 1) when v is.
    const std::size_t u1v0 = m.u_fastest ? k - 1 : k * (k - 1), u0v1 = m.u_fastest ? k * (k - 1) : k - 1;
    e = std::max({dist(corners[0], p.data()), dist(corners[2], p.data() + 3 * u1v0), dist(corners[1], p.data() + 3 * u0v1),
                  dist(corners[3], p.data() + 3 * (k * k - 1))}) / diag;
  }
  for (std::size_t q = 0; q < n; ++q) {
    e = std::max(e, shape.height_error(p.data() + 3 * q) / diag);
    if (!m.normals.empty()) e = std::max(e, dist(shape.normal_above(p[3 * q], p[3 * q + 1]), m.normals.data() + 3 * q));
  }
  return e;
}

void job_mesh(const Options& o, const std::string& self, const fs::path& dir) {
  const std::size_t m = o.coons_points, k = o.eval_points;
  const auto d = write_coons_data(dir, m);
  // The normals' error (a difference of unit vectors) reaches 7e-8 at the corners,
  // where the boundary curves' derivatives are least accurate.
  auto check = [=](const fs::path& out) {
    const auto [points, normals] = read_vts(out, k * k);
    return mesh_error({points, normals, true}, k, d.diag, true);
  };
  const std::string res = std::to_string(k) + "x" + std::to_string(k);
  run_process_job(o, self,
                  {"mesh", "mesh of the linear Coons patch (eval_coons's spec), " + res + " vertices with normals, .vts",
                   m, dir, d.inputs, {"mesh", d.spec.string(), "--res", res, "-o", (dir / "interpatch_out.vts").string()},
                   dir / "interpatch_out.vts", check, 1e-6});
}

// The same mesh in the other formats, each against pure I/O of the bytes it writes.
void job_mesh_formats(const Options& o, const std::string& self, const fs::path& dir) {
  const std::size_t m = o.coons_points, k = o.eval_points, n = k * k, triangles = 2 * (k - 1) * (k - 1);
  const auto d = write_coons_data(dir, m);
  const std::string res = std::to_string(k) + "x" + std::to_string(k);
  struct Format {
    const char* ext;
    const char* what;
    std::function<MeshRead(const fs::path&)> read;
  };
  const Format formats[] = {
      {".vtk", "legacy VTK, binary, points and normals", [=](const fs::path& f) { return read_legacy_vtk(f, n); }},
      {".ply", "binary PLY, vertices with normals, quads", [=](const fs::path& f) { return read_ply(f, n); }},
      {".stl", "binary STL, two triangles a cell", [=](const fs::path& f) { return read_stl(f, triangles); }},
      {".obj", "Wavefront OBJ text: vertices, texture coordinates, normals, quads", [](const fs::path& f) { return read_obj(f); }},
      {".xyz", "Plot3D ASCII, coordinates as the shortest text that reads back exactly", [=](const fs::path& f) { return read_plot3d(f, n); }},
  };
  for (const Format& f : formats) {
    const fs::path out = dir / (std::string("interpatch_out") + f.ext);
    const bool stl = std::string_view(f.ext) == ".stl";
    // STL holds single precision: its points are on the surface to 6e-8 of their size
    // (float rounding), within the tolerance of the normals' error (7e-8, job mesh).
    auto check = [=, read = f.read](const fs::path& file) { return mesh_error(read(file), k, d.diag, !stl); };
    run_process_job(o, self,
                    {std::string("mesh") + f.ext, "mesh of the linear Coons patch, " + res + " vertices, " + f.what, m, dir,
                     d.inputs, {"mesh", d.spec.string(), "--res", res, "-o", out.string()}, out, check, 1e-6});
    fs::remove(out);
  }
}

void job_build_npz(const Options& o, const std::string& self, const fs::path& dir) {
  const std::size_t n = o.npz_size;
  std::cout << "  (making the " << n << " x " << n << " terrain, writing its .npy and interpolating it for the checks)" << std::endl;
  PointGrid grid = ib::make_terrain(n);
  write_points(dir / "grid.npy", {n, n}, std::span<const Vec3>(grid.data(), grid.size()));
  std::ofstream(dir / "interpolate.json") << R"({"type": "interpolate", "points": {"npy": "grid.npy"}})" << '\n';
  const double diag = diagonal(grid.data(), grid.size());
  // The checks: the exact form passes through sampled data points at their
  // parameters (computed here by plain code) and is at the corners; eval's output
  // agrees at sampled points with the library's interpolation of the same grid.
  const auto idx = sample_indices(n);
  const auto pu = ib::averaged_chord_parameters(&grid.data()->x, n, n, 0), pv = ib::averaged_chord_parameters(&grid.data()->x, n, n, 1);
  std::vector<std::tuple<double, double, Vec3>> at_data;
  for (std::size_t i : idx)
    for (std::size_t j : idx) at_data.emplace_back(pu[i], pv[j], grid(i, j));
  const std::array<Vec3, 4> corners{grid(0, 0), grid(0, n - 1), grid(n - 1, 0), grid(n - 1, n - 1)};
  std::vector<std::tuple<std::size_t, std::size_t, Vec3>> at_grid;
  {
    const auto ip = interpatch::interpolate_surface(std::move(grid));
    for (std::size_t i : idx)
      for (std::size_t j : idx) at_grid.emplace_back(i, j, ip.surface.point(param(i, n), param(j, n)));
  }
  auto check_npz = [=](const fs::path& out) {
    const auto form = interpatch::io::read_exact_npz(out);
    const auto* s = std::get_if<BSplineSurface>(&form);
    if (!s || s->control_points().extent(0) != n || s->control_points().extent(1) != n) return 1.0;
    double e = std::max({dist(corners[0], s->point(0, 0)), dist(corners[1], s->point(0, 1)), dist(corners[2], s->point(1, 0)),
                         dist(corners[3], s->point(1, 1))});
    for (const auto& [u, v, p] : at_data) e = std::max(e, dist(p, s->point(u, v)));
    return e / diag;
  };
  auto check_eval = [=](const fs::path& out) {
    const auto a = read_output(out, {n, n});
    if (!a) return 1.0;
    double e = corner_error(a->data.data(), n, corners);
    for (const auto& [i, j, p] : at_grid) e = std::max(e, dist(p, a->data.data() + 3 * (i * n + j)));
    return e / diag;
  };
  const fs::path spec = dir / "interpolate.json";
  ProcessJob job{"build_npz", "exact form of the bicubic interpolation of a " + std::to_string(n) + "² .npy grid, written as .npz",
                 n, dir, {spec, dir / "grid.npy"}, {"build", spec.string(), "-o", (dir / "interpatch_out.npz").string()},
                 dir / "interpatch_out.npz", check_npz, 1e-9};
  const std::vector<std::string> eval{"eval", spec.string(), "--grid", std::to_string(n), "-o", (dir / "interpatch_eval.npy").string()};
  std::vector<std::string> eval_args{o.cli};
  eval_args.insert(eval_args.end(), eval.begin(), eval.end());
  job.others.emplace_back("interpatch", "interpatch " + shown(eval), eval_args, dir / "interpatch_eval.npy", o.threads.back(), check_eval);
  job.runs = std::min(o.reps, 3);
  job.rss_target = 1.2;
  run_process_job(o, self, std::move(job));
  // Gigabytes each: not kept.
  for (const char* f : {"grid.npy", "interpatch_out.npz", "interpatch_eval.npy", "pure_io_out"}) fs::remove(dir / f);
}

void job_processes(const Options& o, const std::string& self) {
  if (!o.has("interpatch")) return;
  std::cout << "\nWhole processes of every construction against pure I/O of the same bytes (and SISL's process)\n";
  for (const auto& name : process_jobs) {
    if (!o.job(name)) continue;
    const fs::path dir = fs::absolute(fs::path(o.workdir) / name);
    fs::create_directories(dir);
    if (name == "eval_interpolate") job_eval_interpolate(o, self, dir);
    else if (name == "eval_coons") job_eval_coons(o, self, dir);
    else if (name == "eval_coons_hermite") job_eval_coons_hermite(o, self, dir);
    else if (name == "eval_gordon") job_eval_network(o, self, dir, name, "gordon");
    else if (name == "eval_network") job_eval_network(o, self, dir, name, "coons_hermite");
    else if (name == "eval_interpolate_volume") job_eval_interpolate_volume(o, self, dir);
    else if (name == "eval_coons_volume") job_eval_coons_volume(o, self, dir);
    else if (name == "eval_hermite_volume") job_eval_hermite_volume(o, self, dir);
    else if (name == "eval_trilinear") job_eval_trilinear(o, self, dir);
    else if (name == "mesh") job_mesh(o, self, dir);
    else if (name == "mesh_formats") job_mesh_formats(o, self, dir);
    else job_build_npz(o, self, dir);
  }
}

// ---------------------------------------------------------------- job: peak memory

long status_kb(const char* field) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(std::strlen(field)));
  return -1;
}

// In a child process (`compare --memory-child LIBRARY N`): build the data and the
// library's own input, reset the peak-RSS mark, interpolate, report "baseline peak" in
// kB: the peak minus the baseline is the memory the call itself needed.
int memory_child(const std::string& library, std::size_t n) {
  PointGrid grid = ib::make_terrain(n);
  std::optional<TColgp_Array2OfPnt> points;
  if (library == "occt") points.emplace(occt_points(grid));
  std::ofstream("/proc/self/clear_refs") << "5" << std::flush;  // resets VmHWM to the current RSS
  const long baseline = status_kb("VmHWM:");
  std::size_t keep = 0;
  if (library == "interpatch-copy") {
    auto r = interpatch::interpolate_surface(grid);
    keep = r.surface.control_points().size();
  } else if (library == "interpatch-move") {
    auto r = interpatch::interpolate_surface(std::move(grid));
    keep = r.surface.control_points().size();
  } else if (library == "sisl") {
    auto pu = ib::averaged_chord_parameters(&grid.data()->x, n, n, 0);
    auto pv = ib::averaged_chord_parameters(&grid.data()->x, n, n, 1);
    auto s = sisl_interpolate(grid, pu, pv);
    keep = static_cast<std::size_t>(s->in1) * static_cast<std::size_t>(s->in2);
  } else if (library == "occt") {
    auto s = occt_interpolate(*points);
    keep = static_cast<std::size_t>(s->NbUPoles()) * static_cast<std::size_t>(s->NbVPoles());
  } else {
    std::cerr << "unknown library " << library << '\n';
    return 2;
  }
  std::cout << baseline << ' ' << status_kb("VmHWM:") << ' ' << keep << std::endl;
  return 0;
}

void job_memory(const Options& o, const std::string& self) {
  std::cout << "\nPeak memory of one interpolation (child process; extra = peak RSS − RSS with the data built)\n";
  const int threads = o.threads.back();
  for (std::size_t n : o.memory_sizes) {
    std::vector<std::string> libs;
    if (o.has("interpatch")) libs.insert(libs.end(), {"interpatch-copy", "interpatch-move"});
    if (o.has("sisl")) libs.push_back("sisl");
    if (o.has("occt")) {
      bool timed = false;
      for (const auto& r : g_rows) timed = timed || (r.job == "interpolate" && r.library == "occt" && r.n == n);
      if (timed || !o.job("interpolate")) libs.push_back("occt");
      else skipped("memory", n, "occt", "not measured: its interpolation at this size was skipped for time");
    }
    for (const auto& lib : libs) {
      const auto r = spawn_and_wait({self, "--memory-child", lib, std::to_string(n)}, threads, true);
      long baseline = 0, peak = 0;
      std::size_t poles = 0;
      std::istringstream(r.out) >> baseline >> peak >> poles;
      if (r.status != 0 || peak <= 0) {
        skipped("memory", n, lib, "child failed with status " + std::to_string(r.status));
        continue;
      }
      const double io_bytes = 2.0 * static_cast<double>(n * n * sizeof(Vec3));
      const double extra = 1024.0 * static_cast<double>(peak - baseline);
      std::cout << "  memory " << n << " " << std::left << std::setw(16) << lib << std::right << " extra "
                << std::setprecision(4) << extra / 1048576 << " MiB = " << std::setprecision(3) << extra / io_bytes
                << " x (input + output " << io_bytes / 1048576 << " MiB); peak RSS " << peak / 1024 << " MiB, "
                << r.seconds << " s" << std::endl;
      g_memory.push_back({{"n", n}, {"library", lib}, {"threads", lib.rfind("interpatch", 0) == 0 ? threads : 1},
                          {"baseline_bytes", 1024.0 * static_cast<double>(baseline)},
                          {"peak_bytes", 1024.0 * static_cast<double>(peak)}, {"extra_bytes", extra},
                          {"io_bytes", io_bytes}, {"extra_over_io", extra / io_bytes}, {"poles", poles},
                          {"seconds", r.seconds}});
    }
  }
}

// ---------------------------------------------------------------- report

std::string shell_output(const std::string& cmd) {
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

json machine(const Options& o) {
  std::string cpu, mhz;
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (cpu.empty() && line.rfind("model name", 0) == 0) cpu = line.substr(line.find(':') + 2);
    if (mhz.empty() && line.rfind("cpu MHz", 0) == 0) mhz = line.substr(line.find(':') + 2);
  }
  std::string load;
  std::getline(std::ifstream("/proc/loadavg"), load);
  const std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return {{"date", date}, {"cpu", cpu}, {"mhz", mhz}, {"nproc", sysconf(_SC_NPROCESSORS_ONLN)},
          {"memory_kb", shell_output("awk '/MemTotal/ {print $2}' /proc/meminfo")}, {"load_average", load},
          {"openmp_max_threads", max_threads()}, {"threads", o.threads},
          {"omp_proc_bind", std::getenv("OMP_PROC_BIND") ? std::getenv("OMP_PROC_BIND") : ""},
          {"interpatch_commit", o.commit.empty() ? shell_output("git describe --always --dirty 2>/dev/null") : o.commit},
          {"occt_version", OCC_VERSION_COMPLETE},
          {"sisl_version", shell_output("dpkg-query -W -f='${Version}' libsisl-dev 2>/dev/null")},
          {"compiler", __VERSION__}, {"reps", o.reps}, {"eval_points", o.eval_points}};
}

json row_json(const Row& r) {
  json parts = json::object();
  for (const auto& [name, v] : r.parts) parts[name] = median(v);
  json j = {{"job", r.job}, {"n", r.n}, {"library", r.library}, {"variant", r.variant}, {"threads", r.threads},
            {"times_s", r.times}, {"median_s", median(r.times)},
            {"min_s", r.times.empty() ? NAN : *std::min_element(r.times.begin(), r.times.end())},
            {"parts_median_s", parts}, {"check_max_rel_error", r.error}, {"check_tolerance", r.tolerance},
            {"check_ok", r.ok()}, {"note", r.note}};
  if (r.maxrss_bytes) j["maxrss_bytes"] = *r.maxrss_bytes;
  if (r.output_bytes) j["output_bytes"] = *r.output_bytes;
  return j;
}

// The console summary: each row against the fastest baseline of its job and size (a
// memcpy of the same bytes, or for the whole processes of every construction the
// pure-I/O program), and against interpatch's fastest row there.
void print_summary() {
  std::cout << "\nSummary (median wall clock; ratios to the faster memcpy or pure I/O of the same bytes and to interpatch's fastest)\n";
  std::map<std::pair<std::string, std::size_t>, double> best_baseline, best_interpatch;
  for (const auto& r : g_rows) {
    const bool baseline = r.library == "memcpy" || r.library == "pure_io";
    if (!baseline && r.library != "interpatch") continue;
    auto& m = baseline ? best_baseline : best_interpatch;
    const auto key = std::make_pair(r.job, r.n);
    m[key] = m.count(key) ? std::min(m[key], median(r.times)) : median(r.times);
  }
  std::cout << std::left << std::setw(24) << "job" << std::setw(6) << "N" << std::setw(12) << "library" << std::setw(64)
            << "variant" << std::setw(5) << "thr" << std::right << std::setw(11) << "median" << std::setw(11) << "/baseline"
            << std::setw(13) << "/interpatch" << "  check\n";
  for (const auto& r : g_rows) {
    const auto key = std::make_pair(r.job, r.n);
    const double t = median(r.times);
    std::cout << std::left << std::setw(24) << r.job << std::setw(6) << r.n << std::setw(12) << r.library << std::setw(64)
              << r.variant.substr(0, 63) << std::setw(5) << r.threads << std::right << std::setw(11) << format_time(t)
              << std::setw(11) << std::setprecision(3) << (best_baseline.count(key) ? t / best_baseline[key] : NAN) << std::setw(13)
              << (best_interpatch.count(key) ? t / best_interpatch[key] : NAN) << "  " << (r.ok() ? "ok" : "FAILED") << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 4 && std::string(argv[1]) == "--memory-child") return memory_child(argv[2], std::stoul(argv[3]));
    if (argc >= 3 && std::string(argv[1]) == "--time-child") return time_child(argc - 2, argv + 2);
    const Options o = parse(argc, argv);
    const json meta = machine(o);
    std::cout << "bench/compare: " << meta["cpu"].get<std::string>() << ", " << meta["nproc"] << " CPUs, OpenMP threads "
              << max_threads() << " (interpatch measured with " << json(o.threads).dump() << "), load "
              << meta["load_average"].get<std::string>() << "\ninterpatch " << meta["interpatch_commit"].get<std::string>()
              << ", OpenCASCADE " << OCC_VERSION_COMPLETE << ", SISL " << meta["sisl_version"].get<std::string>()
              << "; median of " << o.reps << " repetitions" << std::endl;
    const std::string self = fs::canonical("/proc/self/exe").string();
    if (o.job("interpolate")) {
      job_interpolate(o);
      if (o.has("interpatch")) measure_scaling(o);
    }
    if (o.job("evaluate")) job_evaluate(o);
    if (o.job("coons")) job_coons(o);
    if (o.job("process")) job_process(o, self);
    job_processes(o, self);
    if (o.job("memory")) job_memory(o, self);
    print_summary();

    json rows = json::array();
    bool all_ok = true;
    for (const auto& r : g_rows) {
      rows.push_back(row_json(r));
      all_ok = all_ok && r.ok();
    }
    for (const auto& sc : g_scaling) all_ok = all_ok && sc["check_ok"].get<bool>();
    for (const auto& p : g_processes) all_ok = all_ok && p["check_ok"].get<bool>();
    json out = {{"meta", meta}, {"rows", rows}, {"agreement", g_agreement}, {"memory", g_memory}, {"skipped", g_skipped},
                {"scaling", g_scaling}, {"processes", g_processes}};
    out["meta"]["load_average_end"] = shell_output("cat /proc/loadavg");
    if (!o.json_out.empty()) {
      fs::path p(o.json_out);
      if (p.has_parent_path()) fs::create_directories(p.parent_path());
      std::ofstream(p) << out.dump(2) << '\n';
      std::cout << "\nwrote " << o.json_out << '\n';
    }
    if (!all_ok) {
      std::cerr << "compare: some results failed their checks (see FAILED above)\n";
      return 1;
    }
  } catch (const Standard_Failure& e) {
    std::cerr << "compare: OpenCASCADE: " << e.GetMessageString() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "compare: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
