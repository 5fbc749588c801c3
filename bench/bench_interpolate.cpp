// Timings of bicubic grid interpolation and of grid evaluation, each next to a
// memcpy of the same bytes: the speed target holds the work to the memory-bandwidth limit, so
// the ratio to a memcpy says how far a call is from it. tools/bench_report.py turns
// the JSON output into the tables of docs/BENCHMARKS.md.
//
// Every benchmark times exactly one call with a wall clock (manual time): what is
// prepared for the call (a fresh copy of the grid) and what is freed after it (the
// result) stay outside the timed region, and outside the CPU time too (paused), so
// that with OMP_NUM_THREADS=1 the CPU time measures the call's work even on a busy
// machine. Counters: bytes processed is the memory a minimal implementation must
// move (read + written), items processed the points.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "interpatch/bspline_surface.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/network.hpp"
#include "terrain.hpp"

namespace {

using interpatch::BSplineSurface;
using interpatch::PointGrid;
using interpatch::Vec3;
using clock_type = std::chrono::steady_clock;

constexpr std::size_t eval_points = 1000;  // evaluation grids are 1000 x 1000

double seconds(clock_type::time_point t0, clock_type::time_point t1) {
  return std::chrono::duration<double>(t1 - t0).count();
}

// Built once per size and kept for the whole run: repetitions and the iteration
// estimate call a benchmark function several times.
const PointGrid& terrain(std::size_t n) {
  static std::map<std::size_t, PointGrid> cache;
  auto it = cache.find(n);
  if (it == cache.end()) it = cache.emplace(n, interpatch::bench::make_terrain(n)).first;
  return it->second;
}

const BSplineSurface& terrain_surface(std::size_t n) {
  static std::map<std::size_t, BSplineSurface> cache;
  auto it = cache.find(n);
  if (it == cache.end()) it = cache.emplace(n, interpatch::interpolate_surface(terrain(n)).surface).first;
  return it->second;
}

// Frees a result with the clocks stopped.
template <class T>
void discard(benchmark::State& state, T& result) {
  state.PauseTiming();
  { const T gone(std::move(result)); }
  state.ResumeTiming();
}

std::size_t arg(const benchmark::State& state) { return static_cast<std::size_t>(state.range(0)); }

void set_counters(benchmark::State& state, std::size_t points, std::size_t bytes) {
  state.SetItemsProcessed(static_cast<std::int64_t>(points) * state.iterations());
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes) * state.iterations());
  state.counters["points"] = static_cast<double>(points);
}

// ---------------------------------------------------------------- interpolation

// The caller keeps its grid: interpolate_surface takes it by value, so the call
// includes a copy into a fresh allocation.
void interpolate_copy(benchmark::State& state) {
  const std::size_t n = arg(state);
  const PointGrid& grid = terrain(n);
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    auto r = interpatch::interpolate_surface(grid);
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(r.surface.control_points().data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, r);
  }
  set_counters(state, n * n, 2 * n * n * sizeof(Vec3));
}

// The caller hands its grid over: the control points are solved in its memory.
void interpolate_move(benchmark::State& state) {
  const std::size_t n = arg(state);
  const PointGrid& grid = terrain(n);
  for (auto _ : state) {
    state.PauseTiming();
    PointGrid copy = grid;
    state.ResumeTiming();
    const auto t0 = clock_type::now();
    auto r = interpatch::interpolate_surface(std::move(copy));
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(r.surface.control_points().data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, r);
  }
  set_counters(state, n * n, 2 * n * n * sizeof(Vec3));
}

// The same grid closed in u (mask 1), in v (2) or both (3); mask 0 is the open
// interpolation through the same code. With 4 added, the grid carries a closing
// line repeating the first in each closed direction (one more row and/or column),
// which the interpolation recognises and leaves out.
const PointGrid& closed_terrain(std::size_t n, int mask) {
  static std::map<std::pair<std::size_t, int>, PointGrid> cache;
  const auto key = std::make_pair(n, mask);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  const PointGrid& t = terrain(n);
  if ((mask & 4) == 0) return cache.emplace(key, t).first->second;
  const bool cu = (mask & 1) != 0, cv = (mask & 2) != 0;
  PointGrid g({n + (cu ? 1 : 0), n + (cv ? 1 : 0)});
  for (std::size_t i = 0; i < g.extent(0); ++i)
    for (std::size_t j = 0; j < g.extent(1); ++j) g(i, j) = t(i % n, j % n);
  return cache.emplace(key, std::move(g)).first->second;
}

void interpolate_closed(benchmark::State& state) {
  const std::size_t n = arg(state);
  const int mask = static_cast<int>(state.range(1));
  const PointGrid& grid = closed_terrain(n, mask);
  interpatch::SurfaceInterpolationOptions options;
  options.periodic = {(mask & 1) != 0, (mask & 2) != 0};
  for (auto _ : state) {
    state.PauseTiming();
    PointGrid copy = grid;
    state.ResumeTiming();
    const auto t0 = clock_type::now();
    auto r = interpatch::interpolate_surface(std::move(copy), options);
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(r.surface.control_points().data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, r);
  }
  set_counters(state, grid.size(), 2 * grid.size() * sizeof(Vec3));
}

// Chord parameters of both axes alone (two passes over the grid per axis).
void grid_parameters(benchmark::State& state) {
  const std::size_t n = arg(state);
  const PointGrid& grid = terrain(n);
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    auto tu = interpatch::grid_parameters(grid, 0, interpatch::Parametrization::chord);
    auto tv = interpatch::grid_parameters(grid, 1, interpatch::Parametrization::chord);
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(tu.data());
    benchmark::DoNotOptimize(tv.data());
    state.SetIterationTime(seconds(t0, t1));
  }
  set_counters(state, n * n, n * n * sizeof(Vec3));
}

// What the copy path adds: a grid copied into a fresh allocation (page faults included).
void grid_copy(benchmark::State& state) {
  const std::size_t n = arg(state);
  const PointGrid& grid = terrain(n);
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    PointGrid copy = grid;
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(copy.data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, copy);
  }
  set_counters(state, n * n, 2 * n * n * sizeof(Vec3));
}

// ---------------------------------------------------------------- memcpy baselines

// Both buffers allocated and touched before timing.
void time_memcpy(benchmark::State& state, std::size_t bytes, std::size_t points, bool threaded) {
  std::vector<std::byte> src(bytes, std::byte{1}), dst(bytes);
  for (auto _ : state) {
    benchmark::DoNotOptimize(src.data());
    const auto t0 = clock_type::now();
    interpatch::bench::copy_bytes(dst.data(), src.data(), bytes, threaded);
    benchmark::ClobberMemory();
    const auto t1 = clock_type::now();
    state.SetIterationTime(seconds(t0, t1));
  }
  set_counters(state, points, 2 * bytes);
}

// N x N points of 24 bytes: the grid read and the control net written.
void memcpy_grid(benchmark::State& state) {
  const std::size_t n = arg(state);
  time_memcpy(state, n * n * sizeof(Vec3), n * n, false);
}
void memcpy_grid_mt(benchmark::State& state) {
  const std::size_t n = arg(state);
  time_memcpy(state, n * n * sizeof(Vec3), n * n, true);
}

// The output of an evaluation: 10^6 points of `range(0)` bytes each.
void memcpy_eval(benchmark::State& state) {
  time_memcpy(state, eval_points * eval_points * arg(state), eval_points * eval_points, false);
}
void memcpy_eval_mt(benchmark::State& state) {
  time_memcpy(state, eval_points * eval_points * arg(state), eval_points * eval_points, true);
}

// ---------------------------------------------------------------- evaluation

// 1000 x 1000 points on the surface through the N x N terrain.
void evaluate(benchmark::State& state) {
  const BSplineSurface& s = terrain_surface(arg(state));
  const auto us = interpatch::linspace(s.domain_u().first, s.domain_u().second, eval_points);
  const auto vs = interpatch::linspace(s.domain_v().first, s.domain_v().second, eval_points);
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    auto out = s.evaluate(us, vs);
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(out.data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, out);
  }
  const std::size_t points = eval_points * eval_points;
  set_counters(state, points, points * sizeof(Vec3) + s.control_points().size() * sizeof(Vec3));
}

void evaluate_derivatives(benchmark::State& state) {
  const BSplineSurface& s = terrain_surface(arg(state));
  const auto us = interpatch::linspace(s.domain_u().first, s.domain_u().second, eval_points);
  const auto vs = interpatch::linspace(s.domain_v().first, s.domain_v().second, eval_points);
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    auto out = s.evaluate_derivatives(us, vs);
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(out.data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, out);
  }
  const std::size_t points = eval_points * eval_points;
  set_counters(state, points,
               points * sizeof(interpatch::SurfaceDerivatives) + s.control_points().size() * sizeof(Vec3));
}

// ---------------------------------------------------------------- exact conversion

// A curve through `points` at equally spaced parameters: curves through the rows and
// columns of one grid then cross at the grid's points, at the same parameters.
interpatch::BSplineCurve uniform_curve(const std::vector<Vec3>& points) {
  interpatch::CurveInterpolationOptions o;
  o.param = interpatch::Parametrization::uniform;
  return interpatch::interpolate_curve(points, o).curve;
}

std::vector<Vec3> terrain_row(const PointGrid& g, std::size_t j) {
  std::vector<Vec3> r(g.extent(0));
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = g(i, j);
  return r;
}

std::vector<Vec3> terrain_column(const PointGrid& g, std::size_t i) {
  return {g.data() + i * g.extent(1), g.data() + (i + 1) * g.extent(1)};
}

// The linear Coons patch of the N x N terrain's four boundary rows, each a cubic
// through N points at chord-length parameters (bench/compare's "coons" job): four
// different knot vectors, merged to about 2N control points a direction.
const interpatch::BlendedSurface& coons_patch(std::size_t n) {
  static std::map<std::size_t, interpatch::BlendedSurface> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    const PointGrid& g = terrain(n);
    auto c = [](const std::vector<Vec3>& p) { return interpatch::interpolate_curve(p).curve; };
    const interpatch::CoonsBoundary b{c(terrain_row(g, 0)), c(terrain_row(g, n - 1)), c(terrain_column(g, 0)),
                                      c(terrain_column(g, n - 1))};
    it = cache.emplace(n, interpatch::coons(b)).first;
  }
  return it->second;
}

// The network of 9 curves each way through the N x N terrain's rows and columns at
// every (N − 1)/8-th point, each curve through N points: Gordon (spline cardinal
// blends) or C1 Coons cells (Hermite blends, many terms).
const interpatch::BlendedSurface& terrain_network(std::size_t n, interpatch::NetworkMethod method) {
  static std::map<std::pair<std::size_t, int>, interpatch::BlendedSurface> cache;
  const std::pair key{n, static_cast<int>(method)};
  auto it = cache.find(key);
  if (it == cache.end()) {
    const PointGrid& g = terrain(n);
    interpatch::CurveNetwork net;
    for (std::size_t c = 0; c <= 8; ++c) {
      const std::size_t i = c * (n - 1) / 8;
      net.u_curves.push_back(uniform_curve(terrain_row(g, i)));
      net.v_curves.push_back(uniform_curve(terrain_column(g, i)));
      net.u_params.push_back(static_cast<double>(i) / static_cast<double>(n - 1));
    }
    net.v_params = net.u_params;
    it = cache.emplace(key, interpatch::curve_network(net, {method, {}, {}})).first;
  }
  return it->second;
}

// ---------------------------------------------------------------- networks as drawn

// The networks of tools/make_network_bench.py, built in memory: 15 u-curves and 15
// v-curves on f(u, v) = (4u, 3v + 0.3 sin 3u, sin 2.5u cos 1.7v + 0.4uv), u-curve j
// through f(t, v_j), v-curve i through f(u_i, t), u_i = i/14, v_j = j/14.
//   common:   491 equally spaced stations (the nodes among them: 490 = 35 · 14),
//             uniform parameters: the curves cross at the common parameters.
//   drawn:    500 uneven stations (the ends, the 15 nodes, random ones), chord
//             parameters along u, centripetal along v: each curve crosses the others at
//             parameters of its own, so the network finds the crossings of every pair
//             and re-expresses the curves: the u-curves on shared knots, the v-curves
//             each on knots of its own.
//   shuffled: drawn, the families in random order and every other curve reversed.
// No crossing parameters given (as in the specs): the network finds them in every case.
enum class NetworkKind { common, drawn, shuffled };

constexpr std::size_t network_curves = 15;

Vec3 network_shape(double u, double v) {
  return {4 * u, 3 * v + 0.3 * std::sin(3 * u), std::sin(2.5 * u) * std::cos(1.7 * v) + 0.4 * u * v};
}

const interpatch::CurveNetwork& bench_network(NetworkKind kind) {
  static std::map<int, interpatch::CurveNetwork> cache;
  auto it = cache.find(static_cast<int>(kind));
  if (it != cache.end()) return it->second;
  const std::size_t n = network_curves;
  std::vector<double> nodes(n);
  for (std::size_t i = 0; i < n; ++i) nodes[i] = static_cast<double>(i) / static_cast<double>(n - 1);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto stations = [&] {
    if (kind == NetworkKind::common) return interpatch::linspace(0.0, 1.0, 35 * (n - 1) + 1);
    std::vector<double> t = nodes;  // 0 and 1 among them
    while (t.size() < 500) {
      while (t.size() < 500) t.push_back(unit(rng));
      std::sort(t.begin(), t.end());
      t.erase(std::unique(t.begin(), t.end()), t.end());
    }
    return t;
  };
  // The points of every curve first, then (shuffled) the families reordered and
  // every other list reversed, as the generator does, then the interpolation.
  auto points = [&](bool along_u, double at) {
    std::vector<Vec3> p;
    for (double t : stations()) p.push_back(along_u ? network_shape(t, at) : network_shape(at, t));
    return p;
  };
  std::vector<std::vector<Vec3>> u_points, v_points;
  for (double v : nodes) u_points.push_back(points(true, v));
  for (double u : nodes) v_points.push_back(points(false, u));
  if (kind == NetworkKind::shuffled) {
    std::shuffle(u_points.begin(), u_points.end(), rng);
    std::shuffle(v_points.begin(), v_points.end(), rng);
    for (std::size_t i = 0; i < n; i += 2) std::reverse(u_points[i].begin(), u_points[i].end());
    for (std::size_t i = 1; i < n; i += 2) std::reverse(v_points[i].begin(), v_points[i].end());
  }
  auto curve = [&](const std::vector<Vec3>& p, bool along_u) {
    interpatch::CurveInterpolationOptions o;
    o.param = kind == NetworkKind::common ? interpatch::Parametrization::uniform
              : along_u                   ? interpatch::Parametrization::chord
                                          : interpatch::Parametrization::centripetal;
    return interpatch::interpolate_curve(p, o).curve;
  };
  interpatch::CurveNetwork net;
  for (const auto& p : u_points) net.u_curves.push_back(curve(p, true));
  for (const auto& p : v_points) net.v_curves.push_back(curve(p, false));
  return cache.emplace(static_cast<int>(kind), std::move(net)).first->second;
}

// What is timed after the network is built: nothing, 1000 × 1000 points by the
// surface's formula (BlendedSurface::evaluate_into), or by its exact form
// (to_bspline, then BSplineSurface::evaluate_into). `interpatch eval` takes whichever
// costs fewer operations (io::evaluator): the exact form for the common network
// (502 × 499 control points), the formula for the drawn one (511 × 8004 for the
// spec of docs/BENCHMARKS.md: the v-curves' knots merged).
enum class NetworkSample { none, formula, exact };

// network_surface (what `interpatch eval` and `info` call: the surface and its report,
// the crossings of every u-curve × v-curve pair, the re-expression, the distance of the
// surface from every curve), Gordon, then the sampling; the output is allocated and
// touched before the clock starts, the curves are made before it starts.
void network_as_drawn(benchmark::State& state, NetworkKind kind, NetworkSample sample) {
  const interpatch::CurveNetwork& net = bench_network(kind);
  const auto us = interpatch::linspace(0.0, 1.0, eval_points), vs = us;
  const bool evaluate = sample != NetworkSample::none;
  std::vector<Vec3> out(evaluate ? eval_points * eval_points : 0, Vec3{1, 1, 1});
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    auto r = interpatch::network_surface(net, {interpatch::NetworkMethod::gordon, {}, {}});
    if (sample == NetworkSample::formula) r.surface.evaluate_into(us, vs, out);
    if (sample == NetworkSample::exact) r.surface.to_bspline().evaluate_into(us, vs, out);
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(out.data());
    state.SetIterationTime(seconds(t0, t1));
    discard(state, r);
  }
  set_counters(state, evaluate ? eval_points * eval_points : 0, out.size() * sizeof(Vec3));
}

// The linear Coons volume of six faces, each a bicubic through an N x N grid of a
// smooth map of the unit cube at equally spaced parameters: faces that share an edge
// share its samples and its parameters, hence its curve.
const interpatch::BlendedVolume& coons_volume_of(std::size_t n) {
  static std::map<std::size_t, interpatch::BlendedVolume> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    auto map = [](double u, double v, double w) {
      return Vec3{u + 0.1 * std::sin(3 * v + w), v + 0.1 * std::cos(2 * u * w), w + 0.1 * std::sin(u + 4 * v)};
    };
    auto face = [&](int axis, double t) {
      PointGrid q({n, n});
      for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = 0; b < n; ++b) {
          const double s = static_cast<double>(a) / static_cast<double>(n - 1);
          const double r = static_cast<double>(b) / static_cast<double>(n - 1);
          q(a, b) = axis == 0 ? map(t, s, r) : (axis == 1 ? map(s, t, r) : map(s, r, t));
        }
      interpatch::SurfaceInterpolationOptions o;
      o.param = interpatch::Parametrization::uniform;
      return interpatch::interpolate_surface(std::move(q), o).surface;
    };
    it = cache.emplace(n, interpatch::coons_volume({face(0, 0), face(0, 1), face(1, 0), face(1, 1), face(2, 0),
                                                    face(2, 1)})).first;
  }
  return it->second;
}

// One to_bspline per iteration, next to a two-thread memcpy of its control net's
// bytes timed right after it (counter memcpy_ms, and the ratio x_memcpy): the
// conversion writes every control point once, so a memcpy of the net is its floor.
template <class Blended>
void time_to_bspline(benchmark::State& state, const Blended& blended) {
  std::size_t points = 0;
  double call = 0, copy = 0;
  std::vector<std::byte> src, dst;
  for (auto _ : state) {
    const auto t0 = clock_type::now();
    auto b = blended.to_bspline();
    const auto t1 = clock_type::now();
    benchmark::DoNotOptimize(b.control_points().data());
    state.SetIterationTime(seconds(t0, t1));
    state.PauseTiming();
    points = b.control_points().size();
    const std::size_t bytes = points * sizeof(Vec3);
    if (src.size() != bytes) {
      src.assign(bytes, std::byte{1});
      dst.assign(bytes, std::byte{0});
    }
    { const auto gone(std::move(b)); }
    const auto t2 = clock_type::now();
    interpatch::bench::copy_bytes(dst.data(), src.data(), bytes, true);
    benchmark::ClobberMemory();
    const auto t3 = clock_type::now();
    call += seconds(t0, t1);
    copy += seconds(t2, t3);
    state.ResumeTiming();
  }
  set_counters(state, points, points * sizeof(Vec3));
  state.counters["memcpy_ms"] = 1e3 * copy / static_cast<double>(state.iterations());
  state.counters["x_memcpy"] = call / copy;
}

void to_bspline_coons(benchmark::State& state) { time_to_bspline(state, coons_patch(arg(state))); }
void to_bspline_gordon(benchmark::State& state) {
  time_to_bspline(state, terrain_network(arg(state), interpatch::NetworkMethod::gordon));
}
void to_bspline_network_c1(benchmark::State& state) {
  time_to_bspline(state, terrain_network(arg(state), interpatch::NetworkMethod::coons_hermite));
}
void to_bspline_coons_volume(benchmark::State& state) { time_to_bspline(state, coons_volume_of(arg(state))); }

// ---------------------------------------------------------------- registration

// The fastest repetition next to mean/median/stddev: on a shared machine noise only
// ever adds time.
void common(benchmark::internal::Benchmark* b) {
  b->UseManualTime()->Unit(benchmark::kMillisecond)->ComputeStatistics("min", [](const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
  });
}

void grid_sizes(benchmark::internal::Benchmark* b) {
  common(b);
  for (std::int64_t n = 64; n <= 2048; n *= 2) b->Arg(n);
}

void surface_sizes(benchmark::internal::Benchmark* b) {
  common(b);
  b->Arg(64)->Arg(1024);
}

BENCHMARK(interpolate_copy)->Apply(grid_sizes);
BENCHMARK(interpolate_move)->Apply(grid_sizes);
BENCHMARK(memcpy_grid)->Apply(grid_sizes);
BENCHMARK(memcpy_grid_mt)->Apply(grid_sizes);
BENCHMARK(grid_copy)->Apply(grid_sizes);
BENCHMARK(interpolate_closed)->Apply(common)->ArgsProduct({{1024, 2048}, {0, 1, 2, 3, 5, 6, 7}});
BENCHMARK(grid_parameters)->Apply(common)->Arg(1024)->Arg(2048);
BENCHMARK(evaluate)->Apply(surface_sizes);
BENCHMARK(evaluate_derivatives)->Apply(surface_sizes);
BENCHMARK(memcpy_eval)
    ->Apply(common)
    ->Arg(static_cast<std::int64_t>(sizeof(Vec3)))
    ->Arg(static_cast<std::int64_t>(sizeof(interpatch::SurfaceDerivatives)));
BENCHMARK(memcpy_eval_mt)
    ->Apply(common)
    ->Arg(static_cast<std::int64_t>(sizeof(Vec3)))
    ->Arg(static_cast<std::int64_t>(sizeof(interpatch::SurfaceDerivatives)));
// A second or less each: run them with repetitions and
// --benchmark_enable_random_interleaving=true so that the kinds take turns
// (docs/BENCHMARKS.md, "Networks as drawn against common parameters").
BENCHMARK_CAPTURE(network_as_drawn, build_common, NetworkKind::common, NetworkSample::none)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, build_drawn, NetworkKind::drawn, NetworkSample::none)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, build_shuffled, NetworkKind::shuffled, NetworkSample::none)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, eval_common, NetworkKind::common, NetworkSample::formula)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, eval_drawn, NetworkKind::drawn, NetworkSample::formula)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, eval_shuffled, NetworkKind::shuffled, NetworkSample::formula)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, exact_common, NetworkKind::common, NetworkSample::exact)->Apply(common);
BENCHMARK_CAPTURE(network_as_drawn, exact_drawn, NetworkKind::drawn, NetworkSample::exact)->Apply(common);
BENCHMARK(to_bspline_coons)->Apply(common)->Arg(1024);
BENCHMARK(to_bspline_gordon)->Apply(common)->Arg(1024);
BENCHMARK(to_bspline_network_c1)->Apply(common)->Arg(1024);
BENCHMARK(to_bspline_coons_volume)->Apply(common)->Arg(128);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
#if defined(_OPENMP)
  benchmark::AddCustomContext("openmp_threads", std::to_string(omp_get_max_threads()));
#else
  benchmark::AddCustomContext("openmp_threads", "off");
#endif
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
