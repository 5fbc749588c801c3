// The approximation of a grid held in blocks of rows (src/constructions/approximate/approx_rows.hpp):
// the control points, bit for bit, of approximate_surface on the whole grid, for
// every split of the rows. The processes are threads here, sharing a RowTeam that
// does what the MPI one does (src/mpi/team.cpp): the same sums, in the same order.

#include "constructions/approximate/approx_rows.hpp"

#include <gtest/gtest.h>

#include <barrier>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <numeric>
#include <optional>
#include <thread>

#include "test_util.hpp"

namespace interpatch {
namespace {

using detail::ApproxRows;
using detail::GridBlock;
using detail::RowTeam;

// What the threads of one team share.
struct Shared {
  explicit Shared(std::size_t p) : P(p), sync(static_cast<std::ptrdiff_t>(p)), slots(p), counts(p), sends(p), failed(p) {}
  std::size_t P;
  std::barrier<> sync;
  std::vector<std::vector<double>> slots;
  std::vector<std::vector<std::size_t>> counts;
  std::vector<const Vec3*> sends;
  std::vector<char> failed;
};

// Process k of P, each a thread.
class ThreadTeam final : public RowTeam {
 public:
  ThreadTeam(Shared& s, std::size_t k) : s_(s), k_(k) {}
  void run(const std::function<void()>& step) const override {
    std::exception_ptr e;
    try {
      step();
    } catch (...) {
      e = std::current_exception();
    }
    s_.failed[k_] = e ? 1 : 0;
    s_.sync.arrive_and_wait();
    const auto first = static_cast<std::size_t>(std::find(s_.failed.begin(), s_.failed.end(), 1) - s_.failed.begin());
    s_.sync.arrive_and_wait();
    if (first == s_.P) return;
    if (first == k_) std::rethrow_exception(e);
    throw detail::peer_failure{3};
  }
  void max(std::span<double> v) const override {
    combine(v, [](double a, double b) { return std::max(a, b); });
  }
  void min(std::span<std::size_t> v) const override {
    combine_counts(v, [](std::size_t a, std::size_t b) { return std::min(a, b); });
  }
  void sum(std::span<std::size_t> v) const override {
    combine_counts(v, [](std::size_t a, std::size_t b) { return a + b; });
  }
  void fold(std::span<double> acc, const std::function<void(std::span<double>)>& add) const override {
    for (std::size_t r = 0; r < s_.P; ++r) {
      if (r == k_) {
        if (r > 0) std::copy(s_.slots[r - 1].begin(), s_.slots[r - 1].end(), acc.begin());
        add(acc);
        s_.slots[r].assign(acc.begin(), acc.end());
      }
      s_.sync.arrive_and_wait();
    }
    std::copy(s_.slots[s_.P - 1].begin(), s_.slots[s_.P - 1].end(), acc.begin());
    s_.sync.arrive_and_wait();
  }
  [[nodiscard]] std::vector<double> gather(std::span<const double> mine) const override {
    s_.slots[k_].assign(mine.begin(), mine.end());
    s_.sync.arrive_and_wait();
    std::vector<double> all;
    for (const auto& s : s_.slots) all.insert(all.end(), s.begin(), s.end());
    s_.sync.arrive_and_wait();
    return all;
  }
  [[nodiscard]] std::size_t processes() const override { return s_.P; }
  [[nodiscard]] std::size_t process() const override { return k_; }
  void exchange(const Vec3* send, std::span<const std::size_t> send_counts, Vec3* recv,
                std::span<const std::size_t> recv_counts) const override {
    s_.sends[k_] = send;
    s_.counts[k_].assign(send_counts.begin(), send_counts.end());
    s_.sync.arrive_and_wait();
    std::size_t at = 0;
    for (std::size_t r = 0; r < s_.P; ++r) {
      const std::size_t from = std::accumulate(s_.counts[r].begin(), s_.counts[r].begin() + static_cast<std::ptrdiff_t>(k_), std::size_t{0});
      EXPECT_EQ(s_.counts[r][k_], recv_counts[r]);
      std::copy_n(s_.sends[r] + from, recv_counts[r], recv + at);
      at += recv_counts[r];
    }
    s_.sync.arrive_and_wait();
  }

 private:
  template <class F>
  void combine(std::span<double> v, const F& f) const {
    s_.slots[k_].assign(v.begin(), v.end());
    s_.sync.arrive_and_wait();
    for (std::size_t i = 0; i < v.size(); ++i) {
      double x = s_.slots[0][i];
      for (std::size_t r = 1; r < s_.P; ++r) x = f(x, s_.slots[r][i]);
      v[i] = x;
    }
    s_.sync.arrive_and_wait();
  }
  template <class F>
  void combine_counts(std::span<std::size_t> v, const F& f) const {
    s_.counts[k_].assign(v.begin(), v.end());
    s_.sync.arrive_and_wait();
    for (std::size_t i = 0; i < v.size(); ++i) {
      std::size_t x = s_.counts[0][i];
      for (std::size_t r = 1; r < s_.P; ++r) x = f(x, s_.counts[r][i]);
      v[i] = x;
    }
    s_.sync.arrive_and_wait();
  }
  Shared& s_;
  std::size_t k_;
};

// The block of rows of process k of P: whole chunks of rows_per_chunk rows, as the
// command splits them.
std::pair<std::size_t, std::size_t> block_of(std::size_t rows, std::size_t k, std::size_t P) {
  const std::size_t chunks = (rows + detail::rows_per_chunk - 1) / detail::rows_per_chunk;
  const std::size_t first = std::min(rows, chunks * k / P * detail::rows_per_chunk);
  return {first, std::min(rows, chunks * (k + 1) / P * detail::rows_per_chunk) - first};
}

struct Split {
  std::vector<Vec3> rows;  // every process's control rows, in order
  ApproxRows last;         // the last process's result (knots, degrees, net)
  std::string error;       // the error of the process that reported one
};

// approximate_rows on P threads, each holding its block of the rows of `points`.
Split approximate_split(const PointGrid& points, const SurfaceApproximationOptions& o, std::size_t P) {
  const std::size_t n = points.extent(0), M = points.extent(1);
  Shared shared(P);
  std::vector<ApproxRows> out(P);
  std::vector<std::string> errors(P);
  std::vector<std::thread> threads;
  auto row = [&](std::size_t r) { return points.data() + r * M; };
  for (std::size_t k = 0; k < P; ++k)
    threads.emplace_back([&, k] {
      const ThreadTeam team(shared, k);
      const std::pair<std::size_t, std::size_t> blk = block_of(n, k, P);
      std::vector<Vec3> mine(row(blk.first), row(blk.first + blk.second));
      GridBlock b;
      b.rank = 2;
      b.n = {n, M, 0};
      b.data = mine.data();
      b.first = blk.first;
      b.count = blk.second;
      b.before = blk.first > 0 ? row(blk.first - 1) : nullptr;
      b.row0 = row(0);
      b.last = row(n - 1);
      b.ends = {row(0), row(1), row(n - 2), row(n - 1)};
      try {
        out[k] = detail::approximate_rows(b, o, team);
      } catch (const error& e) {
        errors[k] = e.what();
      } catch (const detail::peer_failure&) {
        errors[k] = "peer";
      }
    });
  for (auto& t : threads) t.join();
  Split s;
  for (std::size_t k = 0; k < P; ++k) {
    s.rows.insert(s.rows.end(), out[k].rows.begin(), out[k].rows.end());
    if (!errors[k].empty() && errors[k] != "peer" && s.error.empty()) s.error = errors[k];
  }
  s.last = out[P - 1];
  return s;
}

bool same_bits(const Vec3& a, const Vec3& b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

// A smooth surface with noise: open, or a tube closed along u or v, the closing line
// repeated or not.
PointGrid surface(std::mt19937_64& g, std::size_t n, std::size_t m, int closed, bool repeat) {
  PointGrid q({n, m});
  const std::size_t steps_u = closed == 0 ? (repeat ? n - 1 : n) : n - 1, steps_v = closed == 1 ? (repeat ? m - 1 : m) : m - 1;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < m; ++j) {
      const double u = static_cast<double>(i % (closed == 0 && repeat ? n - 1 : n + 1)) / static_cast<double>(steps_u);
      const double v = static_cast<double>(j % (closed == 1 && repeat ? m - 1 : m + 1)) / static_cast<double>(steps_v);
      const double a = 2 * std::acos(-1.0) * (closed == 0 ? u : v), r = 1 + 0.3 * (closed == 0 ? v : u);
      const bool noisy = !(repeat && ((closed == 0 && i == n - 1) || (closed == 1 && j == m - 1)));
      q(i, j) = Vec3{r * std::cos(a), r * std::sin(a), 2 * (closed == 0 ? v : u) + 0.1 * std::sin(3 * a)} +
                (noisy ? 0.003 * test::random_point(g) : Vec3{});
    }
  if (repeat)  // the closing line repeats the first, noise and all
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < m; ++j) {
        if (closed == 0 && i == n - 1) q(i, j) = q(0, j);
        if (closed == 1 && j == m - 1) q(i, j) = q(i, 0);
      }
  return q;
}

// A random grid (closed along u or v, or open: `closed` -1), its closing line repeated
// or not, with random degrees; centripetal parameters in every 4th trial.
struct RandomGrid {
  PointGrid q;
  SurfaceApproximationOptions o;
  bool repeat = false;
};
RandomGrid random_grid(std::mt19937_64& g, std::size_t n, std::size_t m, int closed, int trial) {
  RandomGrid r;
  r.repeat = closed >= 0 && g() % 2 == 0;
  r.q = surface(g, n, m, std::max(closed, 0), r.repeat);
  if (closed >= 0) r.o.periodic[static_cast<std::size_t>(closed)] = true;
  r.o.degree = {static_cast<int>(2 + g() % 3), static_cast<int>(2 + g() % 2)};
  r.o.param = trial % 4 == 3 ? Parametrization::centripetal : Parametrization::chord;
  return r;
}

// Weights with some 0 (when `weighted`), and on some grids holes: a block of NaN (not
// with a repeated closing line: one is looked for only without missing points).
void weights_and_holes(std::mt19937_64& g, PointGrid& q, SurfaceApproximationOptions& o, bool weighted, bool repeat) {
  const std::size_t n = q.extent(0), m = q.extent(1);
  if (weighted) {
    o.weights = Grid<double, 2>({n, m});
    for (double& w : o.weights.values()) w = g() % 9 == 0 ? 0.0 : test::uniform(g, 0.2, 3.0);
  }
  if (!repeat && g() % 4 == 0)
    for (std::size_t i = n / 3; i < n / 3 + 4; ++i)
      for (std::size_t j = 1; j < 4; ++j) q(i, j).x = std::numeric_limits<double>::quiet_NaN();
}

// The split's control points and knots equal the whole grid's, bit for bit, on P
// processes.
void expect_single_process_bits(const PointGrid& q, const SurfaceApproximationOptions& o, const BSplineSurface& whole,
                                std::size_t P) {
  SCOPED_TRACE(P);
  const BSplineSurface unit = whole.mapped(0.0, 1.0, 0.0, 1.0);
  const PointGrid& cp = whole.control_points();
  const Split s = approximate_split(q, o, P);
  ASSERT_EQ(s.error, "");
  ASSERT_EQ(s.rows.size(), cp.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cp.size(); ++i) differ += same_bits(s.rows[i], cp.data()[i]) ? 0 : 1;
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(s.last.knots[0].values(), unit.knots_u().values());
  EXPECT_EQ(s.last.knots[1].values(), unit.knots_v().values());
  EXPECT_EQ(s.last.knots[0].periodic(), o.periodic[0]);
  EXPECT_EQ(s.last.knots[1].periodic(), o.periodic[1]);
}

// Random grids, options and splits: weights with zeros, holes, closed directions of
// odd and even degree (the closing line repeated or not), every way but a tolerance
// (ToleranceWithWeightsAndClosedDirectionsGivesTheSingleProcessBits);
// the split's control points equal the whole grid's bit for bit.
TEST(ApproximateRows, EveryProcessCountGivesTheSingleProcessBits) {
  auto g = test::rng(19);
  for (int trial = 0; trial < 24; ++trial) {
    SCOPED_TRACE(trial);
    const std::size_t n = 20 + g() % 50, m = 8 + g() % 20;
    const int closed = static_cast<int>(g() % 3) - 1;  // -1 open, 0 u, 1 v
    RandomGrid r = random_grid(g, n, m, closed, trial);
    PointGrid& q = r.q;
    SurfaceApproximationOptions& o = r.o;
    const bool repeat = r.repeat;
    // Smoothing "auto" fits some 30 times: on a few grids, one split.
    const int way = trial % 8 == 5 ? 2 : trial % 2;
    if (way == 0) o.control_points = std::array<int, 2>{static_cast<int>(5 + g() % (n / 2 - 4)), static_cast<int>(4 + g() % (m - 4))};
    if (way == 1) o.smoothing = std::pow(10.0, -1.0 - static_cast<double>(g() % 6));
    if (way == 2) o.auto_smoothing = true;
    weights_and_holes(g, q, o, g() % 3 != 0, repeat);
    std::optional<BSplineSurface> whole;
    try {
      whole = approximate_surface(q, o).surface;
    } catch (const error& e) {
      // Refused in one process (too little data under some control point): refused
      // split alike.
      for (std::size_t P = 1; P <= 4; ++P) EXPECT_EQ(approximate_split(q, o, P).error, e.what());
      continue;
    }
    for (std::size_t P = way == 2 ? 3 : 1; P <= (way == 2 ? 3u : 4u); ++P) expect_single_process_bits(q, o, *whole, P);
  }
}

// Along a closed u, few control rows: the rows near the seam take sums from the first
// and the last processes' data, and every process's rows reach them.
TEST(ApproximateRows, ClosedUWithFewControlRowsAcrossEveryProcess) {
  auto g = test::rng(23);
  for (const int degree : {2, 3, 4}) {
    SCOPED_TRACE(degree);
    const std::size_t n = 70, m = 9;
    SurfaceApproximationOptions o;
    o.periodic = {true, false};
    o.degree = {degree, 3};
    o.control_points = std::array<int, 2>{degree + 1, 6};
    o.weights = Grid<double, 2>({n, m});
    for (double& w : o.weights.values()) w = test::uniform(g, 0.5, 2.0);
    const PointGrid q = surface(g, n, m, 0, false);
    const PointGrid cp = approximate_surface(q, o).surface.control_points();
    for (std::size_t P = 2; P <= 4; ++P) {
      const Split s = approximate_split(q, o, P);
      ASSERT_EQ(s.rows.size(), cp.size());
      for (std::size_t i = 0; i < cp.size(); ++i) EXPECT_TRUE(same_bits(s.rows[i], cp.data()[i])) << P << " processes, " << i;
    }
  }
}

// A fit to a tolerance with weights (zeros among them), holes and closed directions
// (the closing line repeated or not): knots grow and are pruned on every process as
// in one, and the split's control points equal the whole grid's bit for bit.
TEST(ApproximateRows, ToleranceWithWeightsAndClosedDirectionsGivesTheSingleProcessBits) {
  auto g = test::rng(31);
  std::array<int, 3> grown{};  // fits whose knots grew, per kind: weights, closed u, closed v
  for (int trial = 0; trial < 15; ++trial) {
    SCOPED_TRACE(trial);
    const std::size_t n = 24 + g() % 40, m = 12 + g() % 24;
    const int closed = trial % 3 - 1;  // -1 open, 0 u, 1 v
    RandomGrid r = random_grid(g, n, m, closed, trial);
    PointGrid& q = r.q;
    SurfaceApproximationOptions& o = r.o;
    const bool repeat = r.repeat;
    // The surface's noise reaches 0.003 · √3: the tighter tolerances stop where no
    // interval can split any more, the looser ones within the tolerance.
    o.tolerance = std::array<double, 3>{0.03, 0.01, 0.004}[g() % 3];
    weights_and_holes(g, q, o, closed < 0 || g() % 3 != 0, repeat);  // on the open grids weights always
    std::optional<SurfaceApproximation> whole;
    try {
      whole = approximate_surface(q, o);
    } catch (const error& e) {
      for (std::size_t P = 1; P <= 3; ++P) EXPECT_EQ(approximate_split(q, o, P).error, e.what());
      continue;
    }
    const std::vector<int>& c = whole->report.control_points;
    // More control points than the fit starts from (degree + 1): the knots grew.
    if (c[0] > o.degree[0].value_or(3) + 1 || c[1] > o.degree[1].value_or(3) + 1) ++grown[static_cast<std::size_t>(closed + 1)];
    // Each grid on 2 or 3 processes and on 4 (the last ones' blocks small or empty).
    expect_single_process_bits(q, o, whole->surface, 2 + static_cast<std::size_t>(trial % 2));
    expect_single_process_bits(q, o, whole->surface, 4);
  }
  for (const int k : grown) EXPECT_GE(k, 3);
}

// A fit to a tolerance with weights along a closed u on a grid of 2^18 points or more:
// the knots first grow on the thinned grid (blocks of every 4th row and column, with
// their weights), then on the whole one.
TEST(ApproximateRows, ToleranceOnAThinnedGridWithWeightsAndAClosedU) {
  auto g = test::rng(37);
  const std::size_t n = 520, m = 512;
  const PointGrid q = surface(g, n, m, 0, false);
  SurfaceApproximationOptions o;
  o.periodic = {true, false};
  o.tolerance = 0.01;  // beyond the noise (0.003 · √3 at most): reached with few knots
  o.weights = Grid<double, 2>({n, m});
  for (double& w : o.weights.values()) w = g() % 7 == 0 ? 0.0 : test::uniform(g, 0.5, 2.0);
  const SurfaceApproximation whole = approximate_surface(q, o);
  EXPECT_LE(whole.report.max_error, *o.tolerance);
  // Knots grew past the starting net (degree + 1 = 4 control points each way).
  EXPECT_GT(whole.report.control_points[0] + whole.report.control_points[1], 8);
  expect_single_process_bits(q, o, whole.surface, 3);
}

// A closing line that nearly repeats the first is refused, by one process, with the
// single process's message.
TEST(ApproximateRows, NearlyClosingLineIsRefusedAsInOneProcess) {
  auto g = test::rng(29);
  for (const std::size_t axis : {0u, 1u}) {
    PointGrid q = surface(g, 40, 12, static_cast<int>(axis), true);
    const std::size_t n = q.extent(0), m = q.extent(1);
    for (std::size_t i = 0; i < (axis == 0 ? m : n); ++i) (axis == 0 ? q(n - 1, i) : q(i, m - 1)).z += 1e-9;
    SurfaceApproximationOptions o;
    o.periodic[axis] = true;
    o.control_points = std::array<int, 2>{10, 6};
    std::string single;
    try {
      (void)approximate_surface(q, o);
    } catch (const error& e) {
      EXPECT_EQ(e.code(), errc::closing_gap);
      single = e.what();
    }
    ASSERT_NE(single, "");
    for (std::size_t P = 1; P <= 3; ++P) EXPECT_EQ(approximate_split(q, o, P).error, single);
  }
}

}  // namespace
}  // namespace interpatch
