#pragma once
// Grid interpolation (interpolate_surface, interpolate_volume) on a block of whole
// rows — the slices of one index along u — for callers that hold a grid split
// between processes (src/mpi/). One process holding every row is the plain case;
// the library's own interpolation runs through these same functions, so that a
// split grid gives the same numbers bit for bit.
//
// What the processes must agree on goes through a RowTeam: maxima and integer sums
// (exact in any order), running sums handed from process to process in row order
// (the fixed order of the single process), and the rows' steps gathered in order.

#include <algorithm>
#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "linalg/banded.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail {

/// Rows are handed out in chunks of this many: partial sums over the rows are formed
/// per chunk and added in chunk order, and a block of rows starts at a chunk.
inline constexpr std::size_t rows_per_chunk = 16;

/// The processes holding a grid in blocks of rows, in row order. Alone (this base
/// class) every operation is the identity.
class RowTeam {
 public:
  RowTeam() = default;
  RowTeam(const RowTeam&) = delete;
  RowTeam& operator=(const RowTeam&) = delete;
  virtual ~RowTeam() = default;
  /// Runs `step` here; when it throws on any process, it throws on every one: the
  /// first failing process (in row order) its own error, the others a peer_failure.
  virtual void run(const std::function<void()>& step) const { step(); }
  /// Element-wise maximum, minimum and sum over the processes, on every process.
  virtual void max(std::span<double> values) const { (void)values; }
  virtual void min(std::span<std::size_t> values) const { (void)values; }
  virtual void sum(std::span<std::size_t> values) const { (void)values; }
  /// `acc`, zero on entry, goes from process to process in order, each calling
  /// add(acc) on what the one before left; every process ends with the last one's.
  virtual void fold(std::span<double> acc, const std::function<void(std::span<double>)>& add) const { add(acc); }
  /// Every process's values, concatenated in order.
  [[nodiscard]] virtual std::vector<double> gather(std::span<const double> mine) const { return {mine.begin(), mine.end()}; }
  /// How many processes there are, and which one this is (row order).
  [[nodiscard]] virtual std::size_t processes() const { return 1; }
  [[nodiscard]] virtual std::size_t process() const { return 0; }
  /// Points in blocks: send[r] goes to process r, recv[r] comes from it (counted per
  /// process, the buffers laid out in process order). Alone: a copy.
  virtual void exchange(const Vec3* send, std::span<const std::size_t> send_counts, Vec3* recv,
                        std::span<const std::size_t> recv_counts) const {
    (void)recv_counts;
    std::copy_n(send, send_counts[0], recv);
  }
};

/// An even split of n items between `parts` processes: {first, count} of process k.
[[nodiscard]] inline std::pair<std::size_t, std::size_t> even_share(std::size_t n, std::size_t k, std::size_t parts) {
  const std::size_t a = n * k / parts, b = n * (k + 1) / parts;
  return {a, b - a};
}


/// Thrown on the processes whose peers failed a RowTeam::run step: the failing
/// process reports; the others end with the same exit status, silently.
struct peer_failure {
  int status = 1;
};

/// The whole grid's shape and this process's rows of it.
struct GridBlock {
  std::size_t rank = 0;              ///< 2 (surface) or 3 (volume)
  std::array<std::size_t, 3> n{};    ///< extents of the whole grid
  Vec3* data = nullptr;              ///< rows [first, first + count), C order
  std::size_t first = 0, count = 0;  ///< first is a multiple of rows_per_chunk
  const Vec3* before = nullptr;      ///< row first − 1, when first > 0
  const Vec3* row0 = nullptr;        ///< the whole grid's first row
  const Vec3* last = nullptr;        ///< and its last
  /// The whole grid's rows 0, 1, n−2 and n−1 as read, for a closing test along u
  /// (block_closing's `ends`); set where a closed u is approximated (approximate_rows).
  std::array<const Vec3*, 4> ends{};
  [[nodiscard]] std::size_t row_size() const {
    std::size_t m = 1;
    for (std::size_t a = 1; a < rank; ++a) m *= n[a];
    return m;
  }
};

/// The factored collocation system of one axis.
using AxisSolver = std::variant<BandedLU, CyclicLU>;

/// Degree `degree` or the default min(3, count − 1), checked; `where` (" in u", " around v
/// (closed)") goes into the messages.
int grid_degree(const std::optional<int>& degree, std::size_t count, const char* where);

/// The closing line along `axis` of the grid a block belongs to, and whether it is
/// dropped (find_closing): axis 0 from the whole grid's rows 0, 1, n−2, n−1 (`ends`,
/// shared by every process), an axis inside the rows from each process's own lines.
/// `refuse`: a near miss throws closing_gap (interpolation), else it is reported.
Closing block_closing(const GridBlock& b, std::size_t axis, std::span<const Vec3* const> ends, bool refuse,
                      const RowTeam& team);

/// The exponent 2^e the grid is solved at (0 unless its scale is extreme).
int block_shift(const GridBlock& b, const RowTeam& team);
/// Refuses (not_finite, naming the point in the whole grid) a NaN or infinite
/// coordinate among the block's points.
void check_finite(const GridBlock& b);
/// p[i] * 2^k for i < count, exactly.
void scale_points(Vec3* p, std::size_t count, int k);

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
void solve_columns(const AxisSolver& lu, double* data, std::size_t n, std::size_t width, bool* non_finite = nullptr);

/// Re-anchors a closed axis of even degree at its first parameter (one more control
/// point along it).
template <std::size_t Rank>
void insert_seam(Grid<Vec3, Rank>& points, std::size_t axis, KnotVector& knots, double first);
/// Leaves out the last line along `axis` (a closing line equal to the first).
template <std::size_t Rank>
void drop_last_line(Grid<Vec3, Rank>& points, std::size_t axis);

/// The parameters along the first `axes` axes of a grid held in blocks of rows, as
/// grid_parameters gives them for the whole grid (open directions, every point present);
/// without `along_u`, those along u are left empty (not measured).
std::vector<std::vector<double>> block_parameters(const GridBlock& b, Parametrization param, const RowTeam& team,
                                                  std::size_t axes, bool along_u = true);

}  // namespace interpatch::detail
