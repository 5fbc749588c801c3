// Pass 1 of grid interpolation and grid parameters: the chords of every line of
// the grid, and the averaged parameters along each axis they give (GridChords).

#include <algorithm>
#include <cmath>
#include <limits>

#include "constructions/interpolate/interpolate_internal.hpp"
#include "base/kernel.hpp"
#include "base/parallel.hpp"
#include "base/sums.hpp"
#include "base/text.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail {

namespace {

// A line shorter than 1e-14 of the longest along its axis is a collapsed row (a
// pole) within rounding: it is left out of the averaging.
constexpr double pole_ratio = 1e-14;

// Chord lengths |b[i] − a[i]| (centripetal: square roots of them times `root`, see
// root_scale) for i < count. Squares first, roots in a loop of their own, which the
// compiler vectorizes.
//
// A chord outside (2^-450, 2^511), about (3e-136, 7e153), may come from a square
// that overflowed (inf) or underflowed (below 2^-900 a component's square may have
// lost digits or all of them; a zero chord is flagged too): the root loop flags it on
// the way, two comparisons per chord, and only then is each such chord computed
// again from its components scaled by 2^-e, e the exponent of the largest, its
// root scaled back by 2^e. Scaling by a power of two is exact and sqrt(4^e x) =
// 2^e sqrt(x), so that is the value the formula has without range limits, the one
// the first loop gives in range: a chord of data scaled by 2^k is 2^k times the
// chord, bit for bit. The recomputation sits in this function so that it is
// compiled, fused multiply-adds and all, like the first loop. (In the clone with
// fused multiply-adds, whose products are exact, a component's square that
// underflowed while the sum did not can still, in principle, decide a rounding at a
// near-tie in the last bit; it needs components 2^60 apart and bits that line up.
// The flag does not look at single components: that would cost more than it saves.)
INTERPATCH_KERNEL void chord_lengths(const Vec3* a, const Vec3* b, std::size_t count, double* out, Parametrization param,
                                     double root) {
  unsigned out_of_range = 0;  // not a bool: g++ 12 vectorizes the loop with an unsigned or-reduction only
  for (std::size_t i = 0; i < count; ++i) {
    const double dx = b[i].x - a[i].x, dy = b[i].y - a[i].y, dz = b[i].z - a[i].z;
    const double c = std::sqrt(dx * dx + dy * dy + dz * dz);
    out[i] = c;
    out_of_range |= static_cast<unsigned>(c <= 0x1p-450) | static_cast<unsigned>(c >= 0x1p511);
  }
  if (out_of_range != 0)
    for (std::size_t i = 0; i < count; ++i) {
      if (out[i] > 0x1p-450 && out[i] < 0x1p511) continue;
      const Vec3 d = b[i] - a[i];
      const int e = scale_exponent(max_abs(d));
      const Vec3 u = ldexp(d, -e);
      const double dx = u.x, dy = u.y, dz = u.z;
      out[i] = std::ldexp(std::sqrt(dx * dx + dy * dy + dz * dz), e);
    }
  if (param == Parametrization::centripetal)
    for (std::size_t i = 0; i < count; ++i) out[i] = std::sqrt(out[i] * root);
}

// The weight 1 / length of a line in the averaged parameters; 0 for a line of zero
// length (left out) or one so short that its reciprocal overflows (a collapsed line
// of tiny data, left out with the other collapsed lines).
double line_weight(double length) { return length >= std::numeric_limits<double>::min() ? 1.0 / length : 0.0; }

}  // namespace

GridChords::GridChords(const GridBlock& b, Parametrization param, std::array<bool, 3> periodic, const RowTeam& team)
    : g_(grid_shape(b)), param_(param), root_(root_scale(grid_exponent(b, team))), periodic_(periodic) {
  const GridShape& g = g_;
  const std::size_t M = g.row, R = g.rank;
  if (param == Parametrization::uniform) {
    team.run([&] { check_finite(b); });
    return;
  }
  INTERPATCH_ASSERT(b.first % rows_per_chunk == 0 && R >= 2);
  const std::size_t chunks = (b.count + rows_per_chunk - 1) / rows_per_chunk;
  team.run([&] {
    std::size_t sums = chunks * M;
    for (std::size_t a = 1; a < R; ++a) sums += b.count * g.lines(a) + chunks * g.n[a];
    require_memory(sums, sizeof(double), "chord sums of the grid");
  });
  ChunkSums part = chunk_sums(b, chunks);
  // A NaN or an infinity makes the length of its line along v NaN or infinite
  // (every point is on one, with a chord to a neighbour): only then are the points
  // searched for the first of them.
  team.run([&] {
    const auto& len = line_length_[1];
    if (std::any_of(len.begin(), len.end(), [](double l) { return !std::isfinite(l); })) check_finite(b);
  });
  team.run([&] {
    for (std::size_t a = 1; a < R; ++a) check_lengths(line_length_[a], a);
  });
  leave_out_collapsed(b.data, part, team);
  add_chunks(part, chunks, team);
  if (periodic_[0]) {  // the closing chords of the lines along u: last row back to the first
    std::vector<double> closing(M);
    chord_lengths(b.last, b.row0, M, closing.data(), param, root_);
    for (std::size_t m = 0; m < M; ++m) sums_[0][m] += closing[m];
  }
  team.run([&] { check_lengths(sums_[0], 0); });
  weigh_u_lines();
}

// The chord pass over the block's rows, chunk by chunk: part[c][a] holds chunk c's
// sums; a = 0: the lengths of the lines along u (one per point of a row); a ≥ 1:
// normalized running lengths along axis a. Records every in-row line's length.
GridChords::ChunkSums GridChords::chunk_sums(const GridBlock& b, std::size_t chunks) {
  const GridShape& g = g_;
  const std::size_t M = g.row, R = g.rank;
  const Vec3* q = b.data;
  ChunkSums part(chunks * R);
  line_length_.assign(R, {});
  for (std::size_t a = 1; a < R; ++a) line_length_[a].assign(b.count * g.lines(a), 0.0);
  const auto nchunks = static_cast<long long>(chunks);
  ParallelFailure failure;  // the scratch and the chunks' sums are allocated
#pragma omp parallel if (b.count * M >= parallel_min_work / 4)
  {
    std::vector<double> scratch;
    failure.attempt(static_cast<std::size_t>(thread_index()), [&] { scratch.resize(scratch_size()); });
#pragma omp for schedule(static) nowait
    for (long long ci = 0; ci < nchunks; ++ci) {
      if (failure.failed()) continue;
      const auto c = static_cast<std::size_t>(ci);
      failure.attempt(c, [&] {
        part[c * R].assign(M, 0.0);
        for (std::size_t a = 1; a < R; ++a) part[c * R + a].assign(g.n[a], 0.0);
      });
      if (failure.failed()) continue;
      const std::size_t r1 = std::min(b.count, (c + 1) * rows_per_chunk);
      for (std::size_t r = c * rows_per_chunk; r < r1; ++r) {  // local rows; b.first + r in the grid
        const Vec3* row = q + r * M;
        if (b.first + r > 0) {
          chord_lengths(r == 0 ? b.before : row - M, row, M, scratch.data(), param_, root_);
          double* t0 = part[c * R].data();
          for (std::size_t m = 0; m < M; ++m) t0[m] += scratch[m];
        }
        for (std::size_t a = 1; a < R; ++a)
          add_running_lengths(row, a, part[c * R + a].data(), line_length_[a].data() + r * g.lines(a), scratch.data());
      }
    }
  }
  failure.rethrow();
  return part;
}

// Nearly collapsed lines were summed like the others: take them out again.
void GridChords::leave_out_collapsed(const Vec3* q, ChunkSums& part, const RowTeam& team) {
  const std::size_t R = g_.rank;
  std::vector<double> longest(R, 0.0);
  for (std::size_t a = 1; a < R; ++a)
    for (const double l : line_length_[a]) longest[a] = std::max(longest[a], l);
  team.max(longest);
  used_.assign(R, 0);
  for (std::size_t a = 1; a < R; ++a) {
    const auto& len = line_length_[a];
    const double cut = pole_ratio * longest[a];
    const std::size_t per_row = g_.lines(a);
    for (std::size_t l = 0; l < len.size(); ++l) {
      if (len[l] > cut && line_weight(len[l]) > 0) ++used_[a];
      else if (line_weight(len[l]) > 0) remove_line(q, a, l / per_row, l % per_row, part[(l / per_row / rows_per_chunk) * R + a]);
    }
  }
  team.sum(used_);
}

// The chunks' sums added in chunk order, the processes' in row order.
void GridChords::add_chunks(const ChunkSums& part, std::size_t chunks, const RowTeam& team) {
  const std::size_t R = g_.rank;
  sums_.assign(R, {});
  for (std::size_t a = 0; a < R; ++a) {
    sums_[a].assign(a == 0 ? g_.row : g_.n[a], 0.0);
    team.fold(sums_[a], [&](std::span<double> acc) {
      for (std::size_t c = 0; c < chunks; ++c)
        for (std::size_t k = 0; k < acc.size(); ++k) acc[k] += part[c * R + a][k];
    });
  }
}

// Along u: the weight of each line is 1 / its length, 0 for a collapsed line.
void GridChords::weigh_u_lines() {
  const std::size_t M = g_.row;
  const double cut0 = pole_ratio * *std::max_element(sums_[0].begin(), sums_[0].end());
  inv_length_.assign(M, 0.0);
  for (std::size_t m = 0; m < M; ++m)
    if (sums_[0][m] > cut0 && line_weight(sums_[0][m]) > 0) {
      inv_length_[m] = line_weight(sums_[0][m]);
      ++used_[0];
    }
}

// Averaged parameters along in-row axis a ≥ 1.
std::vector<double> GridChords::in_row_parameters(std::size_t a) const {
  if (param_ == Parametrization::uniform) return uniform(g_.n[a], periodic_[a]);
  if (used_[a] == 0) fail_all_collapsed(a);
  std::vector<double> t(g_.n[a], 0.0);
  double s = 0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    s += sums_[a][k];
    t[k] = s / static_cast<double>(used_[a]);
  }
  return finish(std::move(t), a);
}

// Row r's step along u: Σ over the lines along u of chord(r − 1, r) / line length.
double GridChords::row_step(const Vec3* prev, const Vec3* row, double* scratch) const {
  chord_lengths(prev, row, g_.row, scratch, param_, root_);
  return interleaved_dot(scratch, inv_length_.data(), g_.row);
}

// Parameters along u from the rows' steps (steps[0] unused).
std::vector<double> GridChords::u_parameters(std::span<const double> steps) const {
  if (param_ == Parametrization::uniform) return uniform(g_.n[0], periodic_[0]);
  if (used_[0] == 0) fail_all_collapsed(0);
  std::vector<double> t(g_.n[0], 0.0);
  double s = 0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    s += steps[k];
    t[k] = s / static_cast<double>(used_[0]);
  }
  return finish(std::move(t), 0);
}

// Refuses a grid whose lines along some axis all have zero length, axes in order.
void GridChords::check_lines() const {
  if (!uses_chords()) return;
  for (std::size_t a = 0; a < g_.rank; ++a)
    if (used_[a] == 0) fail_all_collapsed(a);
}

// Lines longer than the largest double: chords or their sums overflowed.
void GridChords::check_lengths(const std::vector<double>& lengths, std::size_t a) {
  if (std::all_of(lengths.begin(), lengths.end(), [](double l) { return l <= std::numeric_limits<double>::max(); }))
    return;
  const char* ax = axis_name(static_cast<int>(a));
  fail(errc::not_finite, "the lines of the grid along ", ax, " are longer than ", std::numeric_limits<double>::max(),
       ": the points span more than a double holds");
}

void GridChords::fail_all_collapsed(std::size_t a) {
  const char* ax = axis_name(static_cast<int>(a));
  fail(errc::zero_chord, "every line of the grid along ", ax, " has zero length: all points coincide along ", ax);
}

// k / (n − 1), or k / n around a closed direction (1 would be the first line again).
std::vector<double> GridChords::uniform(std::size_t n, bool closed) {
  std::vector<double> t(n);
  const double d = static_cast<double>(closed ? n : n - 1);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i) / d;
  if (!closed) t.back() = 1.0;
  return t;
}

std::vector<double> GridChords::finish(std::vector<double> t, std::size_t a) const {
  if (!periodic_[a]) t.back() = 1.0;
  for (std::size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1]))
      fail(errc::zero_chord, "grid points ", k - 1, " and ", k, " along ", axis_name(static_cast<int>(a)),
           " coincide on every line (averaged parameters ", t[k - 1], " and ", t[k], ")");
  if (periodic_[a] && !(t.back() < 1.0))
    fail(errc::zero_chord, "the last and the first grid points along ", axis_name(static_cast<int>(a)),
         " coincide on every line: the closing chord has zero length (averaged parameter ", t.back(), ")");
  return t;
}

// Adds, for every line along in-row axis a of one row, its chords divided by its
// length (the running sums of these are the line's normalized parameters, summed
// once at the end: in_row_parameters); records each line's length.
void GridChords::add_running_lengths(const Vec3* row, std::size_t a, double* acc, double* lengths, double* scratch) const {
  const std::size_t n = g_.n[a], inner = g_.inner(a), outer = g_.outer(a);
  double* ch = scratch;  // (n − 1) × inner chords
  double* inv = ch + n * inner;
  const bool closed = periodic_[a];
  for (std::size_t o = 0; o < outer; ++o) {
    const Vec3* base = row + o * n * inner;
    if (inner == 1) {
      chord_lengths(base, base + 1, n - 1, ch, param_, root_);
      if (closed) chord_lengths(base + n - 1, base, 1, ch + n - 1, param_, root_);
      lengths[o] = interleaved_sum(ch, closed ? n : n - 1);
      const double w = line_weight(lengths[o]);
      for (std::size_t k = 1; k < n; ++k) acc[k] += ch[k - 1] * w;
      continue;
    }
    for (std::size_t k = 1; k < n; ++k)
      chord_lengths(base + (k - 1) * inner, base + k * inner, inner, ch + (k - 1) * inner, param_, root_);
    if (closed) chord_lengths(base + (n - 1) * inner, base, inner, ch + (n - 1) * inner, param_, root_);
    double* len = lengths + o * inner;
    std::fill_n(len, inner, 0.0);
    for (std::size_t k = 1; k < (closed ? n + 1 : n); ++k)
      for (std::size_t i = 0; i < inner; ++i) len[i] += ch[(k - 1) * inner + i];
    for (std::size_t i = 0; i < inner; ++i) inv[i] = line_weight(len[i]);
    for (std::size_t k = 1; k < n; ++k) acc[k] += interleaved_dot(ch + (k - 1) * inner, inv, inner);
  }
}

// Takes line l of row r along axis a back out of its chunk's sums.
void GridChords::remove_line(const Vec3* q, std::size_t a, std::size_t r, std::size_t l, std::vector<double>& acc) const {
  const std::size_t n = g_.n[a], inner = g_.inner(a);
  const Vec3* base = q + r * g_.row + (l / inner) * n * inner + l % inner;
  const double w = line_weight(line_length_[a][r * g_.lines(a) + l]);
  double d = 0;
  for (std::size_t k = 1; k < n; ++k) {
    chord_lengths(base + (k - 1) * inner, base + k * inner, 1, &d, param_, root_);
    acc[k] -= d * w;
  }
}

}  // namespace interpatch::detail
