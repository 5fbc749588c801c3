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
#include <cstdint>
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
  /// Every process's count, in order.
  [[nodiscard]] virtual std::vector<std::uint64_t> all(std::uint64_t mine) const { return {mine}; }
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

/// The closing line along `axis` of the grid a block belongs to, and whether it is
/// dropped (find_closing): axis 0 from the whole grid's rows 0, 1, n−2, n−1 (`ends`,
/// shared by every process), an axis inside the rows from each process's own lines.
/// `refuse`: a near miss throws closing_gap (interpolation), else it is reported.
Closing block_closing(const GridBlock& b, std::size_t axis, std::span<const Vec3* const> ends, bool refuse,
                      const RowTeam& team);

/// p[i] * 2^k for i < count, exactly.
void scale_points(Vec3* p, std::size_t count, int k);

/// The rows of a grid one process holds while it is interpolated — every row when
/// it is alone — and, split, copies of the few rows of the others it looks at.
/// Values: the grid's own storage (alone, solved in place) or a plain vector (split:
/// a Grid's buffer, freed, is kept for reuse, which would hold a second share of the
/// data there).
template <std::size_t Rank, class Values>
struct HeldRows {
  std::array<std::size_t, 3> n{};    ///< extents of the whole grid
  std::size_t first = 0, count = 0;  ///< rows [first, first + count); first a multiple of rows_per_chunk
  Values rows;                       ///< C order
  /// Split: the row before the block, then the grid's rows 0, 1, n−2 and n−1, as read.
  /// Alone: empty (the rows are the whole grid).
  std::array<Values, 5> halo;

  [[nodiscard]] bool whole() const { return halo[1].empty(); }
  [[nodiscard]] std::size_t row_size() const {
    std::size_t m = 1;
    for (std::size_t a = 1; a < Rank; ++a) m *= n[a];
    return m;
  }
  /// The block these rows are, with `ends` set.
  [[nodiscard]] GridBlock block() {
    GridBlock b;
    b.rank = Rank;
    b.n = n;
    b.data = rows.data();
    b.first = first;
    b.count = count;
    if (whole()) {
      const std::size_t M = row_size();
      auto row = [&](std::size_t r) -> const Vec3* { return rows.data() + std::min(r, n[0] - 1) * M; };
      b.row0 = row(0);
      b.last = row(n[0] - 1);
      b.ends = {row(0), row(1), row(n[0] < 2 ? 0 : n[0] - 2), row(n[0] - 1)};
      return b;
    }
    b.before = halo[0].data();
    b.row0 = halo[1].data();
    b.last = halo[4].data();
    b.ends = {halo[1].data(), halo[2].data(), halo[3].data(), halo[4].data()};
    return b;
  }
};

/// What a grid interpolation is asked for, per axis.
struct GridOptions {
  std::array<std::optional<int>, 3> degree{};
  Parametrization param{};
  std::array<bool, 3> periodic{};
};

/// The steps of a grid solve, each reported as it ends (for progress and timings)
/// with the bytes it sent to other processes.
enum class GridStep { degrees, checks, rows, to_columns, solve_u, to_rows, done };
using GridSteps = std::function<void(GridStep step, std::uint64_t sent)>;

/// The control rows a process keeps at the end, {lo, window}: rows [lo, lo + window)
/// of the net, modulo its `rows` around a periodic u, from its knots (seams inserted).
using ControlWindow =
    std::function<std::pair<long long, std::size_t>(const std::vector<KnotVector>& knots, std::size_t rows)>;

/// A solved grid: the control net's knots and extents, and the process's window of it.
template <class Values>
struct SolvedGrid {
  std::vector<int> degrees;
  std::vector<KnotVector> knots;            ///< per axis, seams inserted
  std::vector<std::vector<double>> params;  ///< per axis; a dropped closing line's parameter appended
  std::array<std::size_t, 3> net{};         ///< the control net's extents
  long long lo = 0;                         ///< the window: control rows [lo, lo + window)
  std::size_t window = 0;
  Values rows;  ///< the window's control rows, whole rows, C order
};

/// The grid interpolation of interpolate_surface and interpolate_volume on the rows
/// a process holds, the same steps for one process and for many: the closing lines
/// left out, the degrees, the scale, passes 1 and 2 on the rows (solve_rows), the
/// rows turned into columns for the solve along u, the seams of closed axes of even
/// degree, and the control rows `window` asks for turned back into rows. The held
/// rows are used up.
template <std::size_t Rank, class Values>
SolvedGrid<Values> solve_grid_rows(HeldRows<Rank, Values>& held, const GridOptions& options, const RowTeam& team,
                                   const GridSteps& steps, const ControlWindow& window);

/// The parameters along the first `axes` axes of a grid held in blocks of rows, as
/// grid_parameters gives them for the whole grid (open directions, every point present);
/// without `along_u`, those along u are left empty (not measured).
std::vector<std::vector<double>> block_parameters(const GridBlock& b, Parametrization param, const RowTeam& team,
                                                  std::size_t axes, bool along_u = true);

}  // namespace interpatch::detail
