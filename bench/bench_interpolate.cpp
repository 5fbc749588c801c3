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
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "interpatch/bspline_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
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
