// An allocation that fails inside one of interpatch's parallel regions comes out of
// the call as std::bad_alloc (or interpatch::error), never as std::terminate: an
// exception leaving an OpenMP region aborts the process, and in Python the
// interpreter with it. The global operator new below can be told to fail the k-th
// allocation made inside a parallel region by a thread other than the calling one,
// or by any thread; each operation runs on 2 threads, with inputs above the
// thresholds that start the second thread, in a child process of its own, so that
// an abort is reported as a failed check rather than ending the test program.
//
// A program of its own: replacing operator new would slow every other test.

#include <gtest/gtest.h>
#include <omp.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <functional>
#include <new>
#include <string>
#include <vector>

#include "interpatch/approximate.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/network.hpp"
#include "io/crc32.hpp"
#include "surface_util.hpp"
#include "temp_dir.hpp"
#include "volume_util.hpp"

namespace {

enum class Who { other_threads, any_thread };

// What operator new counts and when it fails. Counted: allocations inside an active
// parallel region while `active`; by a thread other than the region's thread 0
// (other_threads) or by any (any_thread).
struct Arm {
  std::atomic<bool> active{false};
  std::atomic<Who> who{Who::any_thread};
  std::atomic<long> fail_at{0};  // 1-based; 0: never
  std::atomic<long> seen_other{0}, seen_any{0};
  std::atomic<bool> fired{false};
};
Arm arm;

void* allocate(std::size_t n, std::size_t align) {
  if (arm.active.load(std::memory_order_relaxed) && omp_in_parallel()) {
    const long any = arm.seen_any.fetch_add(1) + 1;
    const long other = omp_get_thread_num() != 0 ? arm.seen_other.fetch_add(1) + 1 : 0;
    const long k = arm.who.load() == Who::any_thread ? any : other;
    if (k != 0 && k == arm.fail_at.load()) {
      arm.fired = true;
      throw std::bad_alloc();
    }
  }
  if (n == 0) n = 1;
  void* p = align == 0 ? std::malloc(n) : std::aligned_alloc(align, (n + align - 1) / align * align);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

void* allocate_or_null(std::size_t n, std::size_t align) noexcept {
  try {
    return allocate(n, align);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}

}  // namespace

void* operator new(std::size_t n) { return allocate(n, 0); }
void* operator new[](std::size_t n) { return allocate(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate_or_null(n, 0); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate_or_null(n, 0); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocate_or_null(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocate_or_null(n, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

namespace interpatch {
namespace {

// How an operation ended in the child, its exit status (+ fired when the armed
// allocation failed).
enum Outcome : int { completed = 0, threw_bad_alloc = 1, threw_error = 2, threw_other = 3, fired = 10 };

// Makes the inputs (unarmed) and returns the operation to run armed.
using Prepare = std::function<std::function<void()>()>;

struct Counts {
  long other = 0, any = 0;
};

// Runs prepare() and then its operation in a child process on 2 threads, failing
// allocation `fail_at` of `who` (0: none). The parent process never opens a
// parallel region: a child of a process that has run OpenMP threads cannot start
// its own.
::testing::AssertionResult run_in_child(const Prepare& prepare, Who who, long fail_at, Counts* counts = nullptr) {
  int fds[2];
  if (::pipe(fds) != 0) return ::testing::AssertionFailure() << "pipe failed";
  const pid_t pid = ::fork();
  if (pid < 0) return ::testing::AssertionFailure() << "fork failed";
  if (pid == 0) {
    ::close(fds[0]);
    omp_set_dynamic(0);
    omp_set_num_threads(2);
    int status = threw_other;
    try {
      const std::function<void()> op = prepare();
      arm.who = who;
      arm.fail_at = fail_at;
      arm.active = true;
      try {
        op();
        status = completed;
      } catch (const std::bad_alloc&) {
        status = threw_bad_alloc;
      } catch (const error&) {
        status = threw_error;
      } catch (...) {
        status = threw_other;
      }
      arm.active = false;
    } catch (...) {
      status = threw_other;  // making the inputs failed
    }
    const long seen[2] = {arm.seen_other.load(), arm.seen_any.load()};
    [[maybe_unused]] const auto written = ::write(fds[1], seen, sizeof seen);
    ::_exit(status + (arm.fired ? fired : 0));
  }
  ::close(fds[1]);
  long seen[2] = {-1, -1};
  [[maybe_unused]] const auto got = ::read(fds[0], seen, sizeof seen);
  ::close(fds[0]);
  int wstatus = 0;
  if (::waitpid(pid, &wstatus, 0) != pid) return ::testing::AssertionFailure() << "waitpid failed";
  const std::string what = std::string(who == Who::other_threads ? "allocation " : "allocation (any thread) ") +
                           std::to_string(fail_at) + " failing";
  if (WIFSIGNALED(wstatus))
    return ::testing::AssertionFailure() << what << ": the child ended by signal " << WTERMSIG(wstatus)
                                         << (WTERMSIG(wstatus) == SIGABRT ? " (SIGABRT: std::terminate)" : "");
  if (!WIFEXITED(wstatus)) return ::testing::AssertionFailure() << what << ": the child did not exit";
  const int status = WEXITSTATUS(wstatus);
  if (counts != nullptr) *counts = {seen[0], seen[1]};
  // Fired: the failure must reach the caller. Not fired (a run that allocated less
  // than the counting run): the operation completes.
  const bool ok = status >= fired ? status == fired + threw_bad_alloc || status == fired + threw_error
                                  : status == completed;
  if (!ok) return ::testing::AssertionFailure() << what << ": exit status " << status;
  return ::testing::AssertionSuccess();
}

// The allocations to fail among n: the first few, and some spread over the rest.
std::vector<long> picks(long n) {
  std::vector<long> k;
  for (const long x : {1L, 2L, 3L, n / 3, 2 * n / 3, n})
    if (x >= 1 && x <= n && std::find(k.begin(), k.end(), x) == k.end()) k.push_back(x);
  return k;
}

// The operation completes unarmed, allocating inside its regions when
// `allocates_in_regions`; failing any of several of those allocations, on another
// thread or on any, it throws to the caller.
void expect_failures_reach_the_caller(const Prepare& prepare, bool allocates_in_regions = true) {
  Counts n;
  ASSERT_TRUE(run_in_child(prepare, Who::any_thread, 0, &n));
  if (allocates_in_regions) {
    EXPECT_GT(n.any, 0) << "no allocation inside a parallel region: the parallel path was not taken";
  }
  for (const long k : picks(n.other)) EXPECT_TRUE(run_in_child(prepare, Who::other_threads, k));
  for (const long k : picks(n.any)) EXPECT_TRUE(run_in_child(prepare, Who::any_thread, k));
}

// Threads start above detail::parallel_min_work multiply-adds (2^18); the sizes
// below are chosen above it for each operation.
const std::vector<double>& t701() {
  static const std::vector<double> t = linspace(0, 1, 701);
  return t;
}
const std::vector<double>& t401() {
  static const std::vector<double> t = linspace(0, 1, 401);
  return t;
}
const std::vector<double>& t64() {
  static const std::vector<double> t = linspace(0, 1, 64);
  return t;
}

BSplineSurface surface100() {
  auto g = test::rng(1);
  return test::random_bspline_surface(g, 3, 3, 100, 100);
}

BSplineSurface rational100() {
  const BSplineSurface s = surface100();
  Grid<double, 2> w({100, 100});
  for (std::size_t k = 0; k < w.size(); ++k) w.data()[k] = 1.0 + 0.5 * static_cast<double>(k % 7) / 7.0;
  return BSplineSurface(s.knots_u(), s.knots_v(), s.control_points(), w);
}

BlendedSurface coons200() {
  auto g = test::rng(2);
  return coons(test::boundary_of(test::random_bspline_surface(g, 3, 3, 200, 700)));
}

BlendedSurface network200() {
  auto g = test::rng(3);
  const auto src = test::random_bspline_surface(g, 3, 3, 200, 700);
  return curve_network(test::network_on(src, linspace(0, 1, 7), {0, 0.2, 0.45, 0.7, 1}));
}

BSplineVolume volume30() {
  auto g = test::rng(4);
  return test::random_bspline_volume(g, 3, 3, 3, 30, 30, 30);
}

BlendedVolume coons_volume40() {
  auto g = test::rng(5);
  return coons_volume(test::faces_of(test::random_bspline_volume(g, 3, 3, 3, 40, 40, 40)));
}

// A wavy n x n grid; closed along v (its last column the first again) with `closed`.
PointGrid wavy_grid(std::size_t n, bool closed = false) {
  PointGrid q({n, n});
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double x = static_cast<double>(i) / static_cast<double>(n - 1);
      const double a = 2 * 3.141592653589793 * static_cast<double>(j % (n - 1)) / static_cast<double>(n - 1);
      q(i, j) = closed ? Vec3{std::cos(a) * (2 + 0.1 * std::sin(5 * x)), std::sin(a) * 2, x}
                       : Vec3{x + 0.01 * std::sin(7 * a), a + 0.01 * std::cos(5 * x), std::sin(3 * x) * std::cos(a)};
    }
  return q;
}

TEST(ParallelAllocFailure, BSplineSurfaceEvaluation) {
  expect_failures_reach_the_caller([] {
    return [s = surface100()] { (void)s.evaluate(t701(), t701()); };
  });
  expect_failures_reach_the_caller([] {
    return [s = rational100()] { (void)s.evaluate(t701(), t701()); };
  });
}

TEST(ParallelAllocFailure, BSplineSurfaceDerivatives) {
  expect_failures_reach_the_caller([] {
    return [s = surface100()] { (void)s.evaluate_derivatives(t701(), t701()); };
  });
}

TEST(ParallelAllocFailure, BlendedSurfaceEvaluationAndDerivatives) {
  expect_failures_reach_the_caller([] {
    return [s = coons200()] { (void)s.evaluate(t701(), t701()); };
  });
  // Nothing to allocate inside the region of the derivatives.
  expect_failures_reach_the_caller([] {
    return [s = coons200()] { (void)s.evaluate_derivatives(t701(), t701()); };
  }, false);
}

TEST(ParallelAllocFailure, ExactFormsOfCoonsAndNetworkSurfaces) {
  expect_failures_reach_the_caller([] {
    return [s = coons200()] { (void)s.to_bspline(); };
  });
  expect_failures_reach_the_caller([] {
    return [s = network200()] { (void)s.to_bspline(); };
  });
}

TEST(ParallelAllocFailure, BSplineVolumeEvaluationAndDerivatives) {
  expect_failures_reach_the_caller([] {
    return [v = volume30()] { (void)v.evaluate(t64(), t64(), t64()); };
  });
  expect_failures_reach_the_caller([] {
    return [v = volume30()] { (void)v.evaluate_derivatives(t64(), t64(), t64()); };
  });
}

TEST(ParallelAllocFailure, BlendedVolumeEvaluationDerivativesAndExactForm) {
  // The planes are made before the regions, which only sum.
  expect_failures_reach_the_caller([] {
    return [v = coons_volume40()] { (void)v.evaluate(t64(), t64(), t64()); };
  }, false);
  expect_failures_reach_the_caller([] {
    return [v = coons_volume40()] { (void)v.evaluate_jacobians(t64(), t64(), t64()); };
  }, false);
  expect_failures_reach_the_caller([] {
    return [v = coons_volume40()] { (void)v.to_bspline(); };
  });
}

TEST(ParallelAllocFailure, GridInterpolation) {
  expect_failures_reach_the_caller([] {
    return [q = wavy_grid(300)] { (void)interpolate_surface(q); };
  });
  // Closed along v: the repeated column dropped, and the cyclic solves.
  expect_failures_reach_the_caller([] {
    return [q = wavy_grid(600, true)] {
      SurfaceInterpolationOptions o;
      o.periodic = {false, true};
      (void)interpolate_surface(q, o);
    };
  });
}

TEST(ParallelAllocFailure, Approximation) {
  expect_failures_reach_the_caller([] {
    return [q = wavy_grid(700)] {
      SurfaceApproximationOptions o;
      o.control_points = std::array<int, 2>{30, 30};
      (void)approximate_surface(q, o);
    };
  });
}

TEST(ParallelAllocFailure, MeshWriting) {
  const test::TempDir dir;
  for (const char* name : {"m.obj", "m.vts", "m.stl"})
    expect_failures_reach_the_caller([&dir, name] {
      return [s = coons200(), path = dir / name] { (void)io::write_surface_mesh(path, s, t401(), t401()); };
    });
  expect_failures_reach_the_caller([&dir] {
    return [p = volume30().evaluate(t64(), t64(), t64()), path = dir / "v.vtk"] { io::write_volume_mesh(path, p); };
  });
}

TEST(ParallelAllocFailure, NpyWritingAndReading) {
  const test::TempDir dir;
  expect_failures_reach_the_caller([&dir] {
    return [s = surface100(), path = dir / "rows.npy"] {
      const auto rows = s.rows(t701());
      const std::size_t shape[3] = {701, 701, 3};
      io::write_npy_rows(path, shape, [&](std::size_t first, std::size_t count, std::span<double> out) {
        rows->evaluate_into(std::span(t701()).subspan(first, count),
                            std::span(reinterpret_cast<Vec3*>(out.data()), out.size() / 3));
      });
    };
  });
  expect_failures_reach_the_caller([&dir] {
    const std::vector<double> values(std::size_t{3} << 20, 0.5);
    const std::size_t shape[2] = {std::size_t{1} << 20, 3};
    io::write_npy(dir / "big.npy", shape, values);
    return [path = dir / "big.npy", out = std::vector<double>(values.size())]() mutable {
      (void)io::read_npy_into(path, [&](auto, std::size_t) { return out.data(); });
    };
  }, false);
}

TEST(ParallelAllocFailure, Crc32) {
  expect_failures_reach_the_caller([] {
    return [bytes = std::vector<unsigned char>(std::size_t{16} << 20, 7)] {
      if (io::internal::crc32(bytes.data(), bytes.size()) != io::internal::crc32_serial(bytes.data(), bytes.size()))
        throw std::logic_error("the checksums differ");
    };
  }, false);
}

}  // namespace
}  // namespace interpatch
