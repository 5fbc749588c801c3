#pragma once
// What the files of interpolate/ share: the degree rule, the seam of a closed curve,
// the grid's shape and scale, and the chord pass of grid parameters (GridChords).
// The callers outside this folder use grid_rows.hpp.

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "constructions/interpolate/grid_rows.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 grids are solved as arrays of doubles");

inline const char* axis_name(int axis) { return axis == 0 ? "u" : (axis == 1 ? "v" : "w"); }

// Centripetal steps are square roots of chords, and sqrt(2^k c) = 2^(k/2) sqrt(c)
// holds exactly for even k only. The chords are halved (exact) when the exponent of
// the data's scale (point_exponent, grid_exponent) is odd: scaling the data by 2^k
// then scales every halved-or-not chord by an even power of two, every step by an
// exact power of two, and leaves the parameters as they are, bit for bit.
inline double root_scale(int data_exponent) { return (data_exponent & 1) != 0 ? 0.5 : 1.0; }

/// Degree `degree` or the default min(3, count + extra − 1), checked: `extra` end
/// conditions beside `count` points; `where` goes into the messages.
int resolve_degree(const std::optional<int>& degree, std::size_t count, std::size_t extra, const char* where);

/// Inserting a periodic spline's first parameter a (not a knot) and starting its
/// period there: each new control point j is α P[x] + (1 − α) P[y] of the old ones
/// (Boehm's rule on the periodic sequence of knots; new control point j + 1 of the
/// refined spline becomes j once the period starts at a). With `knots` the refined,
/// re-anchored knot vector.
struct SeamInsertion {
  struct Row {
    std::size_t x, y;
    double alpha;
  };
  std::vector<Row> rows;
  KnotVector knots;
};
SeamInsertion seam_insertion(const KnotVector& k, double a);

/// The exponent 2^e the grid is solved at (0 unless its scale is extreme).
int block_shift(const GridBlock& b, const RowTeam& team);
/// Refuses (not_finite, naming the point in the whole grid) a NaN or infinite
/// coordinate among the block's points.
void check_finite(const GridBlock& b);

/// Passes 1 and 2 of the grid interpolation on a block: parameters along every axis,
/// the knots and factored systems of the axes inside the rows, the banded solves
/// along them done in place; then the parameters and knots along u.
struct RowSolution {
  std::vector<std::vector<double>> params;  ///< per axis
  std::vector<KnotVector> knots;            ///< per axis
};
RowSolution solve_rows(const GridBlock& b, std::span<const int> degrees, Parametrization param,
                       std::span<const bool> periodic, const RowTeam& team);

/// The factored system along `axis` (its name in the messages).
AxisSolver factor_axis(const KnotVector& knots, std::span<const double> params, std::size_t axis);
/// Solves every column of an n × width array of doubles in place; with
/// `non_finite`, also tells whether the solution has a NaN or an infinity.
void solve_columns(const AxisSolver& lu, double* data, std::size_t n, std::size_t width);

/// Re-anchors a closed axis of even degree at its first parameter (one more control
/// point along it).
template <std::size_t Rank>
void insert_seam(Grid<Vec3, Rank>& points, std::size_t axis, KnotVector& knots, double first);
/// Leaves out the last line along `axis` (a closing line equal to the first).
template <std::size_t Rank>
void drop_last_line(Grid<Vec3, Rank>& points, std::size_t axis);

/// Averaged knots on an open axis, periodic ones on a closed one.
KnotVector axis_knots(std::span<const double> params, int degree, bool closed);

// ------------------------------------------------------------ tensor grids
//
// Interpolation through a grid streams the grid three times and keeps no
// grid-sized temporary (fresh pages cost more than the arithmetic on them):
//  1. chord pass: finite check; along every axis inside a row (the slice of one
//     index along u: a row of a surface, a plane of a volume) each line's chords
//     and normalized running lengths, summed over the lines; along u each line's
//     length;
//  2. row pass, a few rows at a time while they are in cache: each row's averaged
//     step along u (chords to the row before, weighted by 1 / line length), then
//     the banded solves along the axes inside the rows;
//  3. the banded solve along u, in column slices that stay in cache.
// Partial sums are formed in chunks of a fixed number of rows and added in chunk
// order, so the result does not depend on the number of threads.

struct GridShape {
  std::size_t rank = 0;
  std::array<std::size_t, 3> n{};
  std::size_t row = 1;  // points in one row (every index but the first)
  // Lines along in-row axis a inside one row: outer(a) × inner(a) of them.
  [[nodiscard]] std::size_t outer(std::size_t a) const {
    std::size_t o = 1;
    for (std::size_t x = 1; x < a; ++x) o *= n[x];
    return o;
  }
  [[nodiscard]] std::size_t inner(std::size_t a) const {
    std::size_t i = 1;
    for (std::size_t x = a + 1; x < rank; ++x) i *= n[x];
    return i;
  }
  [[nodiscard]] std::size_t lines(std::size_t a) const { return outer(a) * inner(a); }
};

template <std::size_t Rank>
GridShape grid_shape(const std::array<std::size_t, Rank>& shape) {
  GridShape g;
  g.rank = Rank;
  for (std::size_t a = 0; a < Rank; ++a) g.n[a] = shape[a];
  for (std::size_t a = 1; a < Rank; ++a) g.row *= shape[a];
  return g;
}

inline GridShape grid_shape(const GridBlock& b) {
  GridShape g;
  g.rank = b.rank;
  g.n = b.n;
  g.row = b.row_size();
  return g;
}

// The block of every row of a grid, for the single process.
template <std::size_t Rank>
GridBlock whole_grid(const Grid<Vec3, Rank>& q) {
  GridBlock b;
  b.rank = Rank;
  for (std::size_t a = 0; a < Rank; ++a) b.n[a] = q.extent(a);
  b.data = const_cast<Vec3*>(q.data());  // NOLINT: read only where the grid is const (the parameters)
  b.count = b.n[0];
  const std::size_t M = b.row_size();
  b.row0 = b.data;
  b.last = b.data + (b.n[0] - 1) * M;
  return b;
}

// Rows 0, 1, n − 2 and n − 1 of a whole grid: what the closing along u looks at.
template <std::size_t Rank>
std::array<const Vec3*, 4> end_rows(const Grid<Vec3, Rank>& points) {
  const std::size_t n = points.extent(0), M = points.size() / n;
  auto row = [&](std::size_t r) { return points.data() + std::min(r, n - 1) * M; };
  return {row(0), row(1), row(n < 2 ? 0 : n - 2), row(n - 1)};
}

/// Refuses the first NaN or infinite point (not_finite, naming it in the whole grid)
/// among the n[0] × row points of a whole grid at q.
void check_grid_finite(const Vec3* q, const GridShape& g);

/// The exponent of the grid's scale: of the largest coordinate in its first and last
/// rows (in every row when those are all zero), a few thousand points read at most.
/// It follows the scale of the data exactly, which is all it is for.
int grid_exponent(const GridBlock& b, const RowTeam& team);

/// Pass 1 and what the averaged parameters need from it.
class GridChords {
 public:
  /// The chords of a block of rows; every process of `team` builds its own, and
  /// they agree on what is summed over the whole grid.
  GridChords(const GridBlock& b, Parametrization param, std::array<bool, 3> periodic, const RowTeam& team);

  /// Averaged parameters along in-row axis a ≥ 1.
  [[nodiscard]] std::vector<double> in_row_parameters(std::size_t a) const;
  /// Row r's step along u: Σ over the lines along u of chord(r − 1, r) / line length.
  double row_step(const Vec3* prev, const Vec3* row, double* scratch) const;
  /// Parameters along u from the rows' steps (steps[0] unused).
  [[nodiscard]] std::vector<double> u_parameters(std::span<const double> steps) const;
  /// Refuses a grid whose lines along some axis all have zero length, axes in order.
  void check_lines() const;

  [[nodiscard]] bool uses_chords() const noexcept { return param_ != Parametrization::uniform; }
  [[nodiscard]] std::size_t scratch_size() const {
    std::size_t s = g_.row;
    for (std::size_t a = 1; a < g_.rank; ++a) s = std::max(s, (g_.n[a] + 1) * g_.inner(a));
    return s;
  }

 private:
  using ChunkSums = std::vector<std::vector<double>>;
  ChunkSums chunk_sums(const GridBlock& b, std::size_t chunks);
  void leave_out_collapsed(const Vec3* q, ChunkSums& part, const RowTeam& team);
  void add_chunks(const ChunkSums& part, std::size_t chunks, const RowTeam& team);
  void weigh_u_lines();
  static void check_lengths(const std::vector<double>& lengths, std::size_t a);
  [[noreturn]] static void fail_all_collapsed(std::size_t a);
  static std::vector<double> uniform(std::size_t n, bool closed);
  [[nodiscard]] std::vector<double> finish(std::vector<double> t, std::size_t a) const;
  void add_running_lengths(const Vec3* row, std::size_t a, double* acc, double* lengths, double* scratch) const;
  void remove_line(const Vec3* q, std::size_t a, std::size_t r, std::size_t l, std::vector<double>& acc) const;

  GridShape g_;
  Parametrization param_;
  double root_;                                    // see root_scale
  std::array<bool, 3> periodic_;                   // closed axes: their lines' lengths take in the closing chord
  std::vector<std::vector<double>> sums_;         // per axis: 0 → line lengths along u; a ≥ 1 → Σ over lines of chord k / line length
  std::vector<std::vector<double>> line_length_;  // per in-row axis: every line's length, row by row
  std::vector<std::size_t> used_;                  // lines averaged per axis
  std::vector<double> inv_length_;                 // per line along u: 1 / length, 0 when collapsed
};

}  // namespace interpatch::detail
