// Closed axes of a grid or curve: re-anchoring a periodic spline of even degree at
// its first parameter (the seam), and leaving out a closing line that repeats the
// first.

#include <algorithm>
#include <vector>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "base/parallel.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail {

SeamInsertion seam_insertion(const KnotVector& k, double a) {
  const int n = k.count(), p = k.degree();
  const auto& u = k.values();
  const int span = k.find_span(a);
  auto mod = [](int i, int m) { return static_cast<std::size_t>(((i % m) + m) % m); };
  std::vector<SeamInsertion::Row> rows(static_cast<std::size_t>(n) + 1);
  // New control points of the refined spline, window i = span − n + 1 .. span + 1.
  for (int i = span - n + 1; i <= span + 1; ++i) {
    SeamInsertion::Row r{mod(i, n), mod(i - 1, n), 1.0};
    if (i > span) r.alpha = 0.0;
    else if (i > span - p)
      r.alpha = (a - u[static_cast<std::size_t>(i)]) / (u[static_cast<std::size_t>(i + p)] - u[static_cast<std::size_t>(i)]);
    const std::size_t j = mod(i, n + 1);  // index in the refined spline; a is its knot 1
    rows[(j + static_cast<std::size_t>(n)) % (static_cast<std::size_t>(n) + 1)] = r;
  }
  std::vector<double> pk = k.period_knots();
  std::vector<double> nk{a};
  nk.insert(nk.end(), pk.begin() + 1, pk.end());
  nk.push_back(k.back());
  return {std::move(rows), KnotVector::periodic_from(p, std::move(nk), a + (k.back() - k.front()))};
}

// Leaves out the last line along `axis` of a grid (a closing line equal to the
// first): along u the storage just ends earlier; along an axis inside the rows each
// block of lines (one value of the axes before it) moves down to close the gap, in
// place. Blocks move in order within each thread's run; the first blocks of a run,
// whose places still hold the run before it, wait in a buffer until every thread
// has moved its others.
template <std::size_t Rank>
void drop_last_line(Grid<Vec3, Rank>& points, std::size_t axis) {
  auto shape = points.shape();
  std::size_t outer = 1, inner = 1;
  for (std::size_t a = 0; a < axis; ++a) outer *= shape[a];
  for (std::size_t a = axis + 1; a < Rank; ++a) inner *= shape[a];
  const std::size_t n = shape[axis], B = n * inner, K = (n - 1) * inner;
  auto values = std::move(points.values());
  Vec3* v = values.data();
  if (axis > 0) {
    // A thread that cannot hold its first blocks moves nothing but still meets the
    // barrier; the grid is then left empty, the values lost.
    ParallelFailure failure;
#pragma omp parallel if (values.size() >= parallel_min_work)
    {
      const std::size_t nt = thread_count(), t = static_cast<std::size_t>(thread_index());
      const std::size_t a = outer * t / nt, b = outer * (t + 1) / nt;
      // Blocks r with r·K < a·B land where the runs before this one still are.
      const std::size_t late = std::min(b, std::max(a, (a * B + K - 1) / K));
      std::vector<Vec3> held;
      bool ready = false;
      failure.attempt(t, [&] {
        held.assign(v + a * B, v + late * B);
        ready = true;
      });
      if (ready)
        for (std::size_t r = std::max<std::size_t>(late, 1); r < b; ++r) std::copy_n(v + r * B, K, v + r * K);
#pragma omp barrier
      if (ready)
        for (std::size_t r = a; r < late; ++r) std::copy_n(held.data() + (r - a) * B, K, v + r * K);
    }
    if (failure.failed()) {
      points = Grid<Vec3, Rank>();
      failure.rethrow();
    }
  }
  values.resize(outer * K);
  shape[axis] = n - 1;
  points = Grid<Vec3, Rank>(shape, std::move(values));
}

// Re-anchors a closed axis of even degree at its first parameter (seam_insertion on
// every line along it): one more control point along the axis.
template <std::size_t Rank>
void insert_seam(Grid<Vec3, Rank>& points, std::size_t axis, KnotVector& knots, double first) {
  SeamInsertion seam = seam_insertion(knots, first);
  auto shape = points.shape();
  std::size_t outer = 1, inner = 1;
  for (std::size_t a = 0; a < axis; ++a) outer *= shape[a];
  for (std::size_t a = axis + 1; a < Rank; ++a) inner *= shape[a];
  const std::size_t n = shape[axis], n1 = seam.rows.size();
  shape[axis] = n1;
  require_memory(Grid<Vec3, Rank>::count(shape), sizeof(Vec3), "a closed grid's control points");
  Grid<Vec3, Rank> out(shape, for_overwrite);
  const Vec3* in = points.data();
  Vec3* o = out.data();
  const auto no = static_cast<long long>(outer);
#pragma omp parallel for schedule(static) if (points.size() >= parallel_min_work)
  for (long long oi = 0; oi < no; ++oi) {
    const auto b = static_cast<std::size_t>(oi);
    for (std::size_t j = 0; j < n1; ++j) {
      const auto& r = seam.rows[j];
      const Vec3* x = in + (b * n + r.x) * inner;
      const Vec3* y = in + (b * n + r.y) * inner;
      Vec3* d = o + (b * n1 + j) * inner;
      for (std::size_t i = 0; i < inner; ++i) d[i] = r.alpha * x[i] + (1.0 - r.alpha) * y[i];
    }
  }
  points = std::move(out);
  knots = std::move(seam.knots);
}

template void drop_last_line<2>(Grid<Vec3, 2>&, std::size_t);
template void drop_last_line<3>(Grid<Vec3, 3>&, std::size_t);
template void insert_seam<2>(Grid<Vec3, 2>&, std::size_t, KnotVector&, double);
template void insert_seam<3>(Grid<Vec3, 3>&, std::size_t, KnotVector&, double);

}  // namespace interpatch::detail
