// The approximation of a surface split between processes (detail::approximate_rows,
// approx_rows.hpp): the fit of approx_fit.hpp on a grid held in blocks
// of whole rows, every sum over the data made in the single process's order.

#include "constructions/approximate/approx_rows.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <variant>
#include <vector>

#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_fit.hpp"
#include "linalg/banded.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::approx {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "points move between processes as triples of doubles");
const Vec3* as_points(const double* d) { return reinterpret_cast<const Vec3*>(d); }
Vec3* as_points(double* d) { return reinterpret_cast<Vec3*>(d); }

// Every point present weighs 1, a missing one 0.
struct PresentWeighsOne {
  double operator()(std::size_t, const Vec3& q) const { return is_missing(q) ? 0.0 : 1.0; }
};

// A rows × width array of points held in consecutive blocks of rows (`mine` here),
// turned into columns: every row of this process's even share of the columns. Each
// point goes as w·Q, w = weight(its index among `rows`, Q), and as zeros where w is
// 0 (a missing point): the weighted data of right_hand_side, multiplied as there.
// `packed` is called once the rows are read.
template <class Weight = PresentWeighsOne>
std::vector<double> rows_to_columns(const Vec3* rows, std::size_t mine, std::size_t width, const detail::RowTeam& team,
                                    const std::function<void()>& packed = {}, const Weight& weight = {}) {
  const std::size_t P = team.processes(), me = team.process();
  const std::vector<double> counts = team.gather(std::vector<double>{static_cast<double>(mine)});
  std::size_t total = 0;
  for (const double c : counts) total += static_cast<std::size_t>(c);
  const std::size_t C = detail::even_share(width, me, P).second;
  std::vector<double> send;
  team.run([&] {
    require_memory(mine * width + total * C, sizeof(Vec3), "a transpose of the data between processes");
    send.resize(3 * mine * width);
  });
  std::vector<std::size_t> sc(P), rc(P);
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    const std::pair<std::size_t, std::size_t> cols = detail::even_share(width, s, P);
    for (std::size_t i = 0; i < mine; ++i) {
      const Vec3* from = rows + i * width + cols.first;
      Vec3* to = as_points(send.data()) + at + i * cols.second;
      for (std::size_t k = 0; k < cols.second; ++k) {
        const double w = weight(i * width + cols.first + k, from[k]);
        for (int x = 0; x < 3; ++x) to[k][x] = w > 0 ? w * from[k][x] : 0.0;
      }
    }
    sc[s] = mine * cols.second;
    rc[s] = static_cast<std::size_t>(counts[s]) * C;
    at += sc[s];
  }
  if (packed) packed();
  std::vector<double> out;
  team.run([&] { out.resize(3 * total * C); });
  team.exchange(as_points(send.data()), sc, as_points(out.data()), rc);
  return out;
}

// The reverse with a new split: columns (total × this process's even share of the
// width) to this process's even share of the rows, whole.
std::vector<double> columns_to_rows(const std::vector<double>& cols, std::size_t total, std::size_t width,
                                    const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process();
  const std::size_t C = detail::even_share(width, me, P).second, mine = detail::even_share(total, me, P).second;
  std::vector<std::size_t> sc(P), rc(P);
  for (std::size_t s = 0; s < P; ++s) {
    sc[s] = detail::even_share(total, s, P).second * C;
    rc[s] = mine * detail::even_share(width, s, P).second;
  }
  std::vector<double> recv, out;
  team.run([&] {
    require_memory(2 * mine * width, sizeof(Vec3), "a transpose of the data between processes");
    recv.resize(3 * mine * width);
    out.resize(3 * mine * width);
  });
  // The columns are in row order: process s's rows are the s-th run of them.
  team.exchange(as_points(cols.data()), sc, as_points(recv.data()), rc);
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    const std::pair<std::size_t, std::size_t> c = detail::even_share(width, s, P);
    for (std::size_t v = 0; v < mine; ++v, at += c.second)
      std::copy_n(recv.data() + 3 * at, 3 * c.second, out.data() + 3 * (v * width + c.first));
  }
  return out;
}

// Data points [first, first + count) of an axis: its basis values there.
Axis axis_slice(const Axis& ax, std::size_t first, std::size_t count) {
  Axis s = ax;
  const auto pp = static_cast<std::size_t>(ax.p) + 1;
  auto part = [&](const auto& v, std::size_t per) {
    using V = std::decay_t<decltype(v)>;
    return V(v.begin() + static_cast<std::ptrdiff_t>(first * per), v.begin() + static_cast<std::ptrdiff_t>((first + count) * per));
  };
  s.n = count;
  s.t = part(ax.t, 1);
  s.first = part(ax.first, 1);
  s.b = part(ax.b, pp);
  s.interval = part(ax.interval, 1);
  return s;
}

// Data rows [first, first + count) of a surface's grid held by this process: their
// part of the data term Σ w B Bᵀ, summed as one process sums it (point after point)
// and gathered into st on every process. A control row's entries take sums over the
// data rows its basis functions reach, in order: the rows whose data lie in one
// process's block are summed there, all at once; those whose data straddle the
// block before (a few rows at each boundary) start from the sums the processes
// before have reached, handed on in order, and go on with this process's points.
template <class Weight>
void add_block_data(Stencil<2>& st, const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b,
                    const Weight& weight, const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process(), c0 = st.c[0], c1 = st.c[1];
  const std::size_t row_len = c1 * st.size;  // doubles of a control row of the stencil
  const std::size_t base = b.first * shape[1], mine = b.count * shape[1];
  const Axis& u = axes[0];
  // The control rows each process's data rows reach: [lo, hi], −1 for none.
  const double lo_here = b.count > 0 ? static_cast<double>(u.first[b.first]) : -1.0;
  const double hi_here = b.count > 0 ? static_cast<double>(u.first[b.first + b.count - 1] + u.p) : -1.0;
  const std::vector<double> los = team.gather(std::vector<double>{lo_here}), his = team.gather(std::vector<double>{hi_here});
  auto has = [&](std::size_t r) { return los[r] >= 0; };
  auto lo_of = [&](std::size_t r) { return static_cast<std::size_t>(los[r]); };
  auto hi_of = [&](std::size_t r) { return static_cast<std::size_t>(his[r]); };
  auto before = [&](std::size_t r) {  // the last process before r with data rows, P for none
    for (std::size_t q = r; q-- > 0;)
      if (has(q)) return q;
    return P;
  };
  auto after = [&](std::size_t r) {
    for (std::size_t q = r + 1; q < P; ++q)
      if (has(q)) return q;
    return P;
  };
  // Rows [s_lo, s_hi] of process r continue the sums of the processes before it.
  auto continued = [&](std::size_t r) -> std::pair<std::size_t, std::size_t> {
    const std::size_t q = before(r);
    if (!has(r) || q == P || hi_of(q) < lo_of(r)) return {1, 0};
    return {lo_of(r), std::min(hi_of(r), hi_of(q))};
  };
  const std::pair<std::size_t, std::size_t> mine_continued = continued(me);
  const std::size_t s_lo = mine_continued.first, s_hi = mine_continued.second;
  auto in_continued = [&](std::size_t row) { return row / c1 >= s_lo && row / c1 <= s_hi; };
  add_weighted_points<2>(st.v.data(), st, axes, shape, base, mine, weight, [&](std::size_t row) { return !in_continued(row); });
  std::size_t width = 0;
  for (std::size_t r = 0; r < P; ++r) {
    const std::pair<std::size_t, std::size_t> c = continued(r);
    if (c.second >= c.first) width = std::max(width, c.second - c.first + 1);
  }
  std::vector<double> acc(width * row_len, 0.0);
  team.fold(acc, [&](std::span<double> a) {
    if (!has(me)) return;  // hands on what it got
    if (s_hi >= s_lo) {
      std::copy_n(a.data(), (s_hi - s_lo + 1) * row_len, st.v.data() + s_lo * row_len);
      add_weighted_points<2>(st.v.data(), st, axes, shape, base, mine, weight, in_continued);
    }
    if (const std::size_t next = after(me); next < P) {
      const std::pair<std::size_t, std::size_t> c = continued(next);
      if (c.second >= c.first) std::copy_n(st.v.data() + c.first * row_len, (c.second - c.first + 1) * row_len, a.data());
    }
  });
  // Each control row from the last process that added to it: process r the rows from
  // its first (0 for the first process with data) up to the next one's first.
  std::size_t own_lo = 0, own_hi = 0;
  if (has(me)) {
    own_lo = before(me) == P ? 0 : lo_of(me);
    own_hi = after(me) == P ? c0 : lo_of(after(me));
  }
  std::vector<double> all = team.gather(std::span<const double>(st.v.data() + own_lo * row_len, (own_hi - own_lo) * row_len));
  INTERPATCH_ASSERT(all.size() == st.v.size());
  st.v = std::move(all);
}

// add_block_data along a closed u. There the basis functions of the data rows near
// the seam wrap: the first rows (of an even degree, whose period starts half a step
// in) reach the last control rows, and the last rows the first ones, so a control
// row near the seam takes the sums of two runs of data rows, one at each end, the
// earlier run first. The control rows are unwrapped (data row i reaching rows
// first_i .. first_i + p, non-decreasing in i, with c0 + L rows in all, L ≤ p) and
// summed there by add_block_data; the rows past c0 repeat rows 0 .. L − 1, and
// their run of data continues the sums the earlier run reached: the processes that
// hold it add their points again to those rows, starting from the earlier sums and
// handing them on in order. Then the rows are wrapped back.
template <class Weight>
void add_closed_block_data(Stencil<2>& st, const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b,
                           const Weight& weight, const detail::RowTeam& team) {
  const Axis& u = axes[0];
  const int c0 = u.c;
  const std::size_t n = u.n;
  // Wrapped onto the knots' period, the parameters rise, drop once (where the data
  // pass the period's start) and rise again: the rows before the drop are a period lower.
  std::size_t drop = 0;
  for (std::size_t i = 1; i < n; ++i)
    if (u.first[i] < u.first[i - 1]) {
      INTERPATCH_ASSERT(drop == 0);
      drop = i;
    }
  std::array<Axis, 2> open = axes;
  Axis& un = open[0];
  const int low = u.first[0] - (drop > 0 ? c0 : 0);
  for (std::size_t i = 0; i < n; ++i) un.first[i] = u.first[i] - (i < drop ? c0 : 0) - low;
  un.c = std::max(c0, un.first[n - 1] + u.p + 1);
  INTERPATCH_ASSERT(un.c <= 2 * c0);  // a control row repeated at most once
  Stencil<2> sw(open);
  add_block_data(sw, open, shape, b, weight, team);

  const auto extra = static_cast<std::size_t>(un.c - c0), c = static_cast<std::size_t>(c0);
  const std::size_t c1 = sw.c[1], row_len = c1 * sw.size;
  std::vector<double> late(extra * row_len, 0.0);
  if (extra > 0) {
    const std::size_t base = b.first * shape[1], mine = b.count * shape[1];
    const bool reaches = b.count > 0 && static_cast<std::size_t>(un.first[b.first + b.count - 1] + u.p) >= c;
    const std::vector<double> all = team.gather(std::vector<double>{reaches ? 1.0 : 0.0});
    const bool first_to_reach = reaches && std::find(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(team.process()), 1.0) ==
                                               all.begin() + static_cast<std::ptrdiff_t>(team.process());
    team.fold(late, [&](std::span<double> acc) {
      if (!reaches) return;  // hands on what it got
      double* rows = sw.v.data() + c * row_len;
      std::copy_n(first_to_reach ? sw.v.data() : acc.data(), extra * row_len, rows);
      add_weighted_points<2>(sw.v.data(), sw, open, shape, base, mine, weight, [&](std::size_t row) { return row / c1 >= c; });
      std::copy_n(rows, extra * row_len, acc.data());
    });
  }
  // Unwrapped row x is control row x + low, modulo c0.
  for (std::size_t x = 0; x < c; ++x) {
    const auto row = static_cast<std::size_t>(((static_cast<long long>(x) + low) % c0 + c0) % c0);
    std::copy_n(x < extra ? late.data() + x * row_len : sw.v.data() + x * row_len, row_len, st.v.data() + row * row_len);
  }
}

// Counts held as doubles (gathered between processes), as counts.
template <class It>
std::vector<std::size_t> as_counts(It first, It last) {
  std::vector<std::size_t> c;
  for (; first != last; ++first) c.push_back(static_cast<std::size_t>(*first));
  return c;
}

// closed_data on a grid held in blocks of rows: a closed direction's last line that
// repeats the first is left out of the block (along v out of each of its rows, in
// place); one that nearly repeats it is refused. Whether each was left out.
std::array<bool, 2> close_block(detail::GridBlock& b, const std::array<bool, 2>& periodic, bool missing,
                                const detail::RowTeam& team) {
  std::array<bool, 2> dropped{};
  for (std::size_t a = 0; a < 2; ++a) {
    if (!periodic[a] || b.n[a] < 3) continue;
    if (missing) break;
    INTERPATCH_ASSERT(a > 0 || b.ends[0] != nullptr);
    const Closing c = detail::block_closing(b, a, b.ends, false, team);
    if (c.nearly) team.run([&] { refuse_closing_gap(a); });
    if (!c.dropped) continue;
    dropped[a] = true;
    const std::size_t n = b.n[a]--;
    if (a == 0) {
      b.count = b.first < n - 1 ? std::min(b.count, n - 1 - b.first) : 0;
      b.last = b.ends[2];
    } else {
      for (std::size_t r = 1; r < b.count; ++r) std::copy(b.data + r * n, b.data + r * n + n - 1, b.data + r * (n - 1));
    }
  }
  return dropped;
}

// ------------------------------------------------------------------ a fit on blocks of rows

// Bᵀ (w Q) of a grid of M columns held in blocks of rows, from its columns `cols`
// (rows_to_columns: every row of this process's even share of the columns): along u
// on the columns (`read` is called when they are read no more), along v on this
// process's even share of the control rows of the result.
std::vector<double> block_rhs(const std::array<Axis, 2>& axes, const std::vector<double>& cols, std::size_t M,
                              const detail::RowTeam& team, const std::function<void()>& read = {}) {
  const std::size_t P = team.processes(), me = team.process();
  const auto c0 = static_cast<std::size_t>(axes[0].c);
  std::vector<double> tmp, rhs;
  Shape<2> cs{axes[0].n, detail::even_share(M, me, P).second};
  basis_pass<true, 2>(axes[0], cols.data(), cs, 0, tmp);
  if (read) read();
  std::vector<double> rows = columns_to_rows(tmp, c0, M, team);
  Shape<2> rs{detail::even_share(c0, me, P).second, M};
  basis_pass<true, 2>(axes[1], rows.data(), rs, 1, rhs);
  return rhs;
}

// Both directions' factored Gram matrices (separable_fit), or none when one is
// singular: the sparse system then settles what the data leave open.
std::array<std::optional<AxisSolver>, 2> separable_solvers(const std::array<Axis, 2>& axes, const detail::RowTeam& team) {
  std::array<std::optional<AxisSolver>, 2> lu;
  team.run([&] {
    try {
      for (std::size_t a = 0; a < 2; ++a) lu[a] = factor_gram(axes[a], a);
    } catch (const error& e) {
      if (e.code() != errc::singular) throw;
      lu = {};
    }
  });
  return lu;
}

// The separable solve of the right-hand side's rows (block_rhs: this process's even
// share of the c0 control rows): its control rows, along u on columns, along v on rows.
std::vector<double> separable_rows(const std::array<std::optional<AxisSolver>, 2>& lu, const std::vector<double>& rhs,
                                   std::size_t c0, std::size_t c1, const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process(), nr = detail::even_share(c0, me, P).second;
  std::vector<double> cols = rows_to_columns(as_points(rhs.data()), nr, c1, team);
  const std::size_t cshape[2] = {c0, detail::even_share(c1, me, P).second}, rshape[2] = {nr, c1};
  std::visit([&](const auto& s) { solve_along_axis(s, cols.data(), cshape, 2, 0, 3); }, *lu[0]);
  std::vector<double> rows = columns_to_rows(cols, c0, c1, team);
  std::visit([&](const auto& s) { solve_along_axis(s, rows.data(), rshape, 2, 1, 3); }, *lu[1]);
  return rows;
}

// The sparse normal equations of a grid held in blocks of rows (b: this process's),
// its weights summing to `weight_sum`: the data term from the Gram matrices when every
// point is present with weight 1 (`uniform`), else summed over the points
// (add_block_data; add_closed_block_data along a closed u).
template <class Weight>
SparseSystem<2> block_system(const std::array<Axis, 2>& axes, const Shape<2>& shape, const detail::GridBlock& b, bool uniform,
                             const Weight& weight, double weight_sum, const detail::RowTeam& team) {
  Stencil<2> st(axes);
  if (uniform) add_grams<2>(st, axes);
  else if (axes[0].periodic) add_closed_block_data(st, axes, shape, b, weight, team);
  else add_block_data(st, axes, shape, b, weight, team);
  return SparseSystem<2>(axes, st, weight_sum, shape[0] * shape[1]);
}

// The fitted surface of f as approximate_rows returns it, `mine` this process's even
// share of the control rows (none: f.cp holds them all).
detail::ApproxRows net_rows(const Fit<2>& f, const detail::RowTeam& team, const double* mine = nullptr) {
  detail::ApproxRows out;
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const std::pair<std::size_t, std::size_t> share = detail::even_share(c0, team.process(), team.processes());
  if (!mine) mine = f.cp.data() + 3 * share.first * c1;
  out.first = share.first;
  if (share.second > 0) out.rows.assign(as_points(mine), as_points(mine) + share.second * c1);
  for (std::size_t a = 0; a < 2; ++a) {
    out.degree[a] = f.axes[a].p;
    out.knots[a] = f.axes[a].knots.mapped(0.0, 1.0);
  }
  out.net = {c0, c1};
  return out;
}

// A surface's grid held in blocks of rows as a fit to a tolerance sees it (Whole's
// counterpart for solve_tolerance): each process fits, measures and gathers lines on
// its rows; what comes back (the control net, the maxima, the lines) is the same on
// every process, as one process finds it, so every process takes the same knot
// decisions. The block's columns (for Bᵀ w Q) are made once and kept between fits.
// Weights and closed directions as in approximate_rows: the weighted points in the
// columns, the data term summed with the weights (wrapped along a closed u), the
// weight sum added point after point in storage order.
class Block {
  // Each point's weight by its flat index in the grid, as Data::w: 1 everywhere when
  // uniform, else 0 where missing and the given weight (1 when none) elsewhere.
  [[nodiscard]] auto weight() const {
    return [this](std::size_t flat) {
      if (uniform_) return 1.0;
      const std::size_t i = flat - first_ * n_[1];
      if (!present_[i]) return 0.0;
      return w_ ? w_[i] : 1.0;
    };
  }

 public:
  // Rows [first, first + count) of a grid of `shape` at `pts` (`own` holds them for
  // a thinned grid), their weights at `w` (none: every point present weighs 1;
  // `own_w` holds them for a thinned grid). `uniform`: the grid it comes from has
  // every point and equal weights (the data term from the Gram matrices, the
  // separable fit tried first, as Data::uniform).
  Block(const detail::RowTeam& team, const Shape<2>& shape, std::shared_ptr<const std::vector<Vec3>> own, const Vec3* pts,
        std::size_t first, std::size_t count, bool uniform, std::shared_ptr<const std::vector<double>> own_w = {},
        const double* w = nullptr)
      : team_(&team), n_(shape), own_(std::move(own)), pts_(pts), first_(first), count_(count), uniform_(uniform),
        own_w_(std::move(own_w)), w_(w) {
    const std::size_t M = n_[1], base = first_ * M;
    if (!uniform_) {
      present_.resize(count_ * M);
      for (std::size_t i = 0; i < present_.size(); ++i) present_[i] = !is_missing(pts_[i]);
    }
    // Points without data (missing or of weight 0): the fill term (needs_fill).
    std::size_t empty[1] = {0};
    for (std::size_t i = 0; i < present_.size(); ++i) empty[0] += weight()(base + i) > 0 ? 0 : 1;
    team.sum(empty);
    fill_ = empty[0] > 0;
    std::vector<double> sum(1, static_cast<double>(n_[0] * M));
    if (!uniform_) {
      sum[0] = 0;
      team.fold(sum, [&](std::span<double> acc) {
        for (std::size_t i = 0; i < present_.size(); ++i)
          if (const double x = weight()(base + i); x > 0) acc[0] += x;
      });
    }
    weight_sum_ = sum[0];
    const std::vector<double> span = team.gather(std::vector<double>{static_cast<double>(first_), static_cast<double>(count_)});
    for (std::size_t s = 0; s < span.size(); s += 2) spans_.emplace_back(static_cast<std::size_t>(span[s]), static_cast<std::size_t>(span[s + 1]));
    cols_ = rows_to_columns(pts_, count_, M, team, {}, [&](std::size_t i, const Vec3&) { return weight()(base + i); });
    std::vector<double> box(6, -std::numeric_limits<double>::infinity());  // −lo, hi
    for (std::size_t i = 0; i < count_ * M; ++i)
      if (weight()(base + i) > 0)
        for (std::size_t k = 0; k < 3; ++k) {
          box[k] = std::max(box[k], -pts_[i][static_cast<int>(k)]);
          box[k + 3] = std::max(box[k + 3], pts_[i][static_cast<int>(k)]);
        }
    team.max(box);
    box_ = {Vec3{-box[0], -box[1], -box[2]}, Vec3{box[3], box[4], box[5]}};
  }

  [[nodiscard]] std::size_t size() const { return n_[0] * n_[1]; }
  [[nodiscard]] const Shape<2>& shape() const { return n_; }

  // solve_once without a smoothing weight.
  void fit(Fit<2>& f) const {
    ++f.fits;
    const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
    const std::vector<double> rhs = block_rhs(f.axes, cols_, n_[1], *team_);
    if (uniform_) {
      if (const auto lu = separable_solvers(f.axes, *team_); lu[0]) {
        f.lambda = 0;
        f.cp = team_->gather(separable_rows(lu, rhs, c0, c1, *team_));
        return;
      }
    }
    detail::GridBlock b;
    b.rank = 2;
    b.n = {n_[0], n_[1], 0};
    b.first = first_;
    b.count = count_;
    SparseSystem<2> sys = block_system(f.axes, n_, b, uniform_, weight(), weight_sum_, *team_);
    const std::vector<double> all_rhs = team_->gather(rhs);
    // The separable fit refused (uniform): the fill term settles what the data leave open.
    team_->run([&] { sparse_fit<2>(f, sys, all_rhs, std::nullopt, fill_ || uniform_); });
  }

  // Whole::sane: the box of every process's data (found when the block is made), the
  // control net whole on every process.
  [[nodiscard]] bool sane(const Fit<2>& f) const { return detail::approx_net_sane(net_points(f.cp), 2, box_); }

  // residuals(): each process its rows, the maxima and worst points merged in process
  // order (a later process's only where strictly greater: the first in one process's
  // scan wins). The sums of squares are this process's alone: the fit to a tolerance
  // reads only the maxima.
  [[nodiscard]] Residuals<2> errors(const Fit<2>& f) const {
    const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
    const Axis slice = axis_slice(f.axes[0], first_, count_);
    Shape<2> sh{c0, c1};
    std::vector<double> partial;
    basis_pass<false, 2>(slice, f.cp.data(), sh, 0, partial);
    const Residuals<2> mine =
        residual_blocks<2>(f.axes, n_, partial.data(), pts_, first_, first_, first_ + count_, weight());
    std::vector<double> pack{mine.max, static_cast<double>(mine.worst)};
    for (std::size_t a = 0; a < 2; ++a) {
      pack.insert(pack.end(), mine.interval_max[a].begin(), mine.interval_max[a].end());
      for (const std::size_t w : mine.interval_worst[a]) pack.push_back(static_cast<double>(w));
    }
    const std::vector<double> all = team_->gather(pack);
    Residuals<2> r(f.axes);
    for (std::size_t at = 0; at < all.size(); at += pack.size()) {
      Residuals<2> part(f.axes);
      const double* x = all.data() + at;
      part.max = *x++;
      part.worst = static_cast<std::size_t>(*x++);
      for (std::size_t a = 0; a < 2; ++a) {
        for (double& m : part.interval_max[a]) m = *x++;
        for (std::size_t& w : part.interval_worst[a]) w = static_cast<std::size_t>(*x++);
      }
      r.merge(part);
    }
    take_roots<2>(r);
    return r;
  }

  // line_residual at each (axis, point) of `at`: the lines gathered from the
  // processes holding them (along u a column of every process's rows, along v one
  // process's row), all in one exchange, then fitted on every process.
  [[nodiscard]] std::vector<double> line_residuals(const Fit<2>& f, const std::array<std::optional<AxisSolver>, 2>& lu,
                                                   const std::vector<std::pair<std::size_t, std::size_t>>& at) const {
    const std::size_t M = n_[1];
    const auto w = weight();
    auto holds = [&](std::size_t s, std::size_t row) { return row >= spans_[s].first && row < spans_[s].first + spans_[s].second; };
    std::vector<double> mine;
    auto put = [&](std::size_t flat) {
      const Vec3 v = point_or_fit<2>(f.axes, f.cp, n_, pts_[flat - first_ * M], w(flat) > 0, flat);
      mine.insert(mine.end(), {v.x, v.y, v.z});
    };
    for (const auto& [a, i] : at) {
      if (a == 0)
        for (std::size_t r = first_; r < first_ + count_; ++r) put(r * M + i % M);
      else if (holds(team_->process(), i / M))
        for (std::size_t j = 0; j < M; ++j) put(i / M * M + j);
    }
    const std::vector<double> all = team_->gather(mine);
    std::vector<std::vector<double>> lines;
    for (const auto& [a, i] : at) lines.emplace_back(3 * n_[a]);
    std::size_t from = 0;
    for (std::size_t s = 0; s < spans_.size(); ++s)
      for (std::size_t k = 0; k < at.size(); ++k) {
        const auto& [a, i] = at[k];
        if (a == 0) {
          std::copy_n(all.data() + from, 3 * spans_[s].second, lines[k].data() + 3 * spans_[s].first);
          from += 3 * spans_[s].second;
        } else if (holds(s, i / M)) {
          std::copy_n(all.data() + from, 3 * M, lines[k].data());
          from += 3 * M;
        }
      }
    std::vector<double> e;
    for (std::size_t k = 0; k < at.size(); ++k) {
      const auto& [a, i] = at[k];
      e.push_back(line_fit_residual(f.axes[a], *lu[a], lines[k], a == 0 ? i / M : i % M));
    }
    return e;
  }

  // Which rows and columns hold data (a point of positive weight): rows from their
  // process, columns OR-reduced.
  [[nodiscard]] std::array<std::vector<bool>, 2> has_data() const {
    std::array<std::vector<bool>, 2> has{std::vector<bool>(n_[0], true), std::vector<bool>(n_[1], true)};
    if (uniform_) return has;
    const auto w = weight();
    std::vector<double> rows(count_, 0.0), cols(n_[1], 0.0);
    for (std::size_t r = 0; r < count_; ++r)
      for (std::size_t j = 0; j < n_[1]; ++j)
        if (w((first_ + r) * n_[1] + j) > 0) rows[r] = cols[j] = 1.0;
    const std::vector<double> all = team_->gather(rows);
    team_->max(cols);
    for (std::size_t r = 0; r < n_[0]; ++r) has[0][r] = all[r] > 0;
    for (std::size_t j = 0; j < n_[1]; ++j) has[1][j] = cols[j] > 0;
    return has;
  }

  // thinned(): the kept rows in this block (a block of the thinned grid's rows, maybe
  // none), the kept columns of each, with their weights.
  [[nodiscard]] Block thinned(const std::array<std::vector<std::size_t>, 2>& kept) const {
    const auto& rows = kept[0];
    const std::size_t lo = static_cast<std::size_t>(std::lower_bound(rows.begin(), rows.end(), first_) - rows.begin());
    const std::size_t hi = static_cast<std::size_t>(std::lower_bound(rows.begin(), rows.end(), first_ + count_) - rows.begin());
    const std::size_t K = kept[1].size();
    auto own = std::make_shared<std::vector<Vec3>>((hi - lo) * K);
    auto own_w = std::make_shared<std::vector<double>>(w_ ? (hi - lo) * K : 0);
    for (std::size_t r = lo; r < hi; ++r)
      for (std::size_t k = 0; k < K; ++k) {
        const std::size_t from = (rows[r] - first_) * n_[1] + kept[1][k], to = (r - lo) * K + k;
        (*own)[to] = pts_[from];
        if (w_) (*own_w)[to] = w_[from];
      }
    const Vec3* p = own->data();
    const double* w = w_ ? own_w->data() : nullptr;
    return {*team_, {rows.size(), K}, std::move(own), p, lo, hi - lo, uniform_, std::move(own_w), w};
  }

 private:
  const detail::RowTeam* team_;
  Shape<2> n_;
  std::shared_ptr<const std::vector<Vec3>> own_;
  const Vec3* pts_;
  std::size_t first_, count_;
  bool uniform_;
  std::shared_ptr<const std::vector<double>> own_w_;
  const double* w_;               // the block's weights, none: 1 each
  bool fill_ = false;             // points without data (missing or of weight 0) in this grid
  double weight_sum_ = 0;         // of the whole grid's weights, in storage order
  std::vector<bool> present_;     // per point of the block, unless uniform
  std::vector<std::pair<std::size_t, std::size_t>> spans_;  // every process's {first, count}
  std::vector<double> cols_;      // the block's columns (rows_to_columns)
  std::array<Vec3, 2> box_{};     // the whole grid's data's box (Whole::sane)
};

// This process's rows of the data as the checks of approx_check.hpp take
// them (`w` holds their weights).
template <class Weight>
detail::ApproxData block_data(const detail::GridBlock& b, const Weight& weight, std::vector<double>& w) {
  const std::size_t M = b.n[1], base = b.first * M;
  w.resize(b.count * M);
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = weight(base + i);
  return {{b.count, M}, std::span<const Vec3>(b.data, b.count * M), w};
}

// The data's bounding box over every process, as two corners (check_rows_net).
template <class Weight>
std::vector<Vec3> block_box(const detail::GridBlock& b, const Weight& weight, const detail::RowTeam& team) {
  std::vector<double> w;
  const detail::ApproxData mine = block_data(b, weight, w);
  std::vector<double> box(6, -std::numeric_limits<double>::infinity());  // −lo, hi
  for (std::size_t i = 0; i < mine.points.size(); ++i)
    if (mine.present(i))
      for (std::size_t k = 0; k < 3; ++k) {
        const double x = mine.points[i][static_cast<int>(k)];
        box[k] = std::max(box[k], -x);
        box[k + 3] = std::max(box[k + 3], x);
      }
  team.max(box);
  return {{-box[0], -box[1], -box[2]}, {box[3], box[4], box[5]}};
}

// check_approx_net on a split run, `box` from block_box: each process checks its own
// control rows (the first with a bad one reports it).
void check_rows_net(const detail::ApproxRows& out, const std::vector<Vec3>& box, const detail::RowTeam& team) {
  const detail::ApproxData corners{{box.size()}, box, {}};
  team.run([&] {
    if (out.rows.empty()) return;
    detail::check_approx_net(out.rows, {out.rows.size() / out.net[1], out.net[1]}, corners, "surface approximation");
  });
}

// The tolerance kept or refused on a split run, measured as approximate_surface
// measures it (the spline's own evaluator): each process at its rows, the worst
// over the processes (the first in row order among equals).
template <class Weight>
void check_rows_tolerance(const Fit<2>& f, const detail::GridBlock& b, const Weight& weight, double tol,
                          const detail::RowTeam& team) {
  PointGrid net({static_cast<std::size_t>(f.axes[0].c), static_cast<std::size_t>(f.axes[1].c)}, for_overwrite);
  std::copy_n(f.cp.data(), f.cp.size(), &net.data()->x);
  std::vector<double> w;
  detail::ApproxData mine = block_data(b, weight, w);
  detail::ApproxDistance e;
  team.run([&] {
    const BSplineSurface s(f.axes[0].knots, f.axes[1].knots, std::move(net));
    if (b.count > 0) {
      const std::vector<double> tu(f.axes[0].t.begin() + static_cast<std::ptrdiff_t>(b.first),
                                   f.axes[0].t.begin() + static_cast<std::ptrdiff_t>(b.first + b.count));
      e = detail::approx_distance(s, tu, f.axes[1].t, mine);
    }
  });
  const std::vector<double> all = team.gather(std::vector<double>{e.max, static_cast<double>(b.first * b.n[1] + e.worst)});
  detail::ApproxDistance worst;
  for (std::size_t k = 0; k < all.size(); k += 2)
    if (all[k] > worst.max) worst = {all[k], static_cast<std::size_t>(all[k + 1])};
  mine.shape = {b.n[0], b.n[1]};
  std::vector<int> cps{f.axes[0].c, f.axes[1].c};
  team.run([&] { detail::check_approx_tolerance(worst, tol, mine, cps); });
}

}  // namespace

}  // namespace interpatch::detail::approx

namespace interpatch::detail {

ApproxRows approximate_rows(const GridBlock& given, const SurfaceApproximationOptions& o, const RowTeam& team,
                            const std::function<void()>& release) {
  using namespace approx;  // the fit the single process runs (approx_fit.hpp)
  constexpr std::size_t R = 2;
  INTERPATCH_ASSERT(given.rank == 2);

  // Missing points (NaN); closed directions, whose closing line is looked for only
  // where none is missing (closed_data).
  std::size_t missing[1] = {0};
  for (std::size_t i = 0; i < given.count * given.n[1]; ++i) missing[0] += is_missing(given.data[i]) ? 1 : 0;
  team.sum(missing);
  GridBlock b = given;
  const std::array<bool, R> dropped = close_block(b, o.periodic, missing[0] > 0, team);
  // The weights, without the lines left out (a copy only then).
  Grid<double, R> cut;
  if (!o.weights.empty() && (dropped[0] || dropped[1])) {
    cut = o.weights;
    for (std::size_t a = 0; a < R; ++a)
      if (dropped[a]) cut_last_line<double, R>(cut, a);
  }
  const Grid<double, R>& weights = cut.empty() ? o.weights : cut;

  const Shape<R> shape{b.n[0], b.n[1]};
  const std::size_t M = shape[1], total = shape[0] * shape[1], mine = b.count * M, base = b.first * M;
  const Vec3* pts = b.data;
  team.run([&] {
    check_request<R>(o, shape, "surface");
    if (!weights.empty()) check_weights<R>(weights, shape);
  });

  // Each point's weight as approximate() finds it: 0 where missing; 1 everywhere
  // when every point is present and the weights (if any) are equal.
  const bool uniform = missing[0] == 0 && std::all_of(weights.values().begin(), weights.values().end(),
                                                      [&](double w) { return w == weights.values().front(); });
  const bool zero_weight = std::any_of(weights.values().begin(), weights.values().end(), [](double w) { return !(w > 0); });
  const bool fill = !uniform && (missing[0] > 0 || zero_weight);  // needs_fill
  // Which points are present, kept past the points themselves.
  std::vector<bool> present_here(missing[0] > 0 ? mine : 0);
  for (std::size_t i = 0; i < present_here.size(); ++i) present_here[i] = !is_missing(pts[i]);
  auto given_weight = [&](std::size_t flat) {
    if (!present_here.empty() && !present_here[flat - base]) return 0.0;
    return weights.empty() ? 1.0 : weights.values()[flat];
  };
  auto weight = [&](std::size_t flat) { return uniform ? 1.0 : given_weight(flat); };
  // The points with a positive weight, and their weights' sum in the order of the points.
  std::size_t present[1] = {0};
  for (std::size_t i = base; i < base + mine; ++i) present[0] += given_weight(i) > 0 ? 1 : 0;
  team.sum(present);
  std::vector<double> weight_sum(1, static_cast<double>(total));
  if (!uniform) {
    weight_sum[0] = 0;
    team.fold(weight_sum, [&](std::span<double> acc) {
      for (std::size_t i = base; i < base + mine; ++i)
        if (const double w = weight(i); w > 0) acc[0] += w;
    });
  }
  team.run([&] {
    if (present[0] == 0)
      fail(errc::too_few_points, "all ", total, " points are missing or have weight 0: there is nothing to approximate");
  });

  // Degrees and parameters.
  // In one process's order: the degree along u, the parameters along u, the degree
  // along v (a refusal kept until the parameters along u are found), along v.
  Fit<R> f;
  team.run([&] { set_degree<R>(f.axes[0], o, 0, shape[0]); });
  std::exception_ptr v_degree;
  try {
    set_degree<R>(f.axes[1], o, 1, shape[1]);
  } catch (const error&) {
    v_degree = std::current_exception();
  }
  const std::size_t axes = v_degree ? 1 : R;
  // As axis_parameters: interpolation's parameters along an open direction without
  // missing points, else the mean chords summed over the lines.
  std::array<bool, R> by_sums{};
  for (std::size_t a = 0; a < R; ++a) by_sums[a] = o.periodic[a] || missing[0] > 0;
  auto interpolation_parameters = [&](std::size_t a) {
    const std::vector<std::vector<double>> t = block_parameters(b, o.param, team, a + 1, a == 0);
    f.axes[a].t = t[a];
  };
  auto chord_sums = [&](std::size_t a) {
    if (a == 0) {
      // Each step's chords lie in the rows of one process (the row before the block
      // from its neighbour; the closing step, back to row 0, in the last rows) and
      // are summed over the row, as in one process.
      std::vector<double> sum0, used0;
      auto step = [&](const Vec3* prev, const Vec3* next) {
        double sum = 0;
        std::size_t used = 0;
        for (std::size_t i = 0; i < M; ++i) add_chord(prev[i], next[i], sum, used);
        sum0.push_back(sum);
        used0.push_back(static_cast<double>(used));
      };
      for (std::size_t k = b.first == 0 ? 1 : 0; k < b.count; ++k) step(k == 0 ? b.before : pts + (k - 1) * M, pts + k * M);
      if (o.periodic[0] && b.count > 0 && b.first + b.count == shape[0]) step(pts + (b.count - 1) * M, b.row0);
      const std::vector<double> all_sum0 = team.gather(sum0), all_used0 = team.gather(used0);
      team.run([&] {
        f.axes[0].t = parameters_from_sums(all_sum0, as_counts(all_used0.begin(), all_used0.end()), shape[0], 0, o.param,
                                           o.periodic[0]);
      });
      return;
    }
    // The lines along v are summed row after row, a running sum passed on in order.
    const std::size_t steps1 = o.periodic[1] ? M : M - 1;
    std::vector<double> acc1(2 * steps1, 0.0);
    team.fold(acc1, [&](std::span<double> acc) {
      for (std::size_t r = 0; r < b.count; ++r)
        for (std::size_t k = 1; k <= steps1; ++k) {
          std::size_t used = 0;
          add_chord(pts[r * M + k - 1], pts[r * M + k % M], acc[k - 1], used);
          acc[steps1 + k - 1] += static_cast<double>(used);
        }
    });
    team.run([&] {
      f.axes[1].t = parameters_from_sums(std::vector<double>(acc1.begin(), acc1.begin() + static_cast<std::ptrdiff_t>(steps1)),
                                         as_counts(acc1.begin() + static_cast<std::ptrdiff_t>(steps1), acc1.end()), shape[1], 1,
                                         o.param, o.periodic[1]);
    });
  };
  if (o.param == Parametrization::uniform) {
    for (std::size_t a = 0; a < R; ++a) f.axes[a].t = uniform_parameters(shape[a], o.periodic[a]);
  } else if (!by_sums[0] && !by_sums[1] && axes == R) {
    std::vector<std::vector<double>> t = block_parameters(b, o.param, team, axes);
    for (std::size_t a = 0; a < R; ++a) f.axes[a].t = std::move(t[a]);
  } else {
    for (std::size_t a = 0; a < axes; ++a) {
      if (by_sums[a]) chord_sums(a);
      else interpolation_parameters(a);
    }
  }
  team.run([&] {
    if (v_degree) std::rethrow_exception(v_degree);
  });
  // The data's box, taken before the points may be released.
  const std::vector<Vec3> box = block_box(b, weight, team);
  if (o.tolerance) {
    // The knots grow and are pruned on every process alike (solve_tolerance), the
    // fits and measures on the blocks (Block).
    const Block whole(team, shape, nullptr, pts, b.first, b.count, uniform, nullptr,
                      weights.empty() ? nullptr : weights.values().data() + std::min(base, weights.size()));
    solve_tolerance<R>(f, whole, *o.tolerance, {});
    check_rows_tolerance(f, b, weight, *o.tolerance, team);
    detail::ApproxRows out = net_rows(f, team);
    check_rows_net(out, box, team);
    return out;
  }
  team.run([&] {
    check_control_points<R>(f.axes, o);
    set_fit_knots<R>(f.axes, o);
  });
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);

  // Bᵀ (w Q): along u on columns of the data, along v on rows of the result.
  std::vector<double> rhs;
  {
    std::vector<double> cols = rows_to_columns(
        pts, b.count, M, team, [&] {
          if (release && !o.auto_smoothing) release();
        },
        [&](std::size_t i, const Vec3&) { return weight(base + i); });
    rhs = block_rhs(f.axes, cols, M, team, [&] { std::vector<double>().swap(cols); });
  }

  // The separable fit when it applies (separable_fit), else the sparse system, with
  // the term that fills holes where some weight is 0 or the separable fit fails.
  std::array<std::optional<AxisSolver>, R> lu;
  const bool separable = !o.smoothing && !o.auto_smoothing && uniform;
  if (separable) lu = separable_solvers(f.axes, team);
  if (lu[0]) {
    detail::ApproxRows out = net_rows(f, team, separable_rows(lu, rhs, c0, c1, team).data());
    check_rows_net(out, box, team);
    return out;
  }
  const bool filled = fill || separable;
  {  // the sparse system
    SparseSystem<R> sys = block_system(f.axes, shape, b, uniform, weight, weight_sum[0], team);
    const std::vector<double> all_rhs = team.gather(rhs);
    if (o.auto_smoothing) {
      // Σ w r² over the data: blocks of rows as in residuals(), their sums added in order.
      const Axis slice = axis_slice(f.axes[0], b.first, b.count);
      const std::vector<std::size_t> off = residual_offsets(f.axes[1]);
      std::vector<double> row(3 * M), e2(M);
      auto rss = [&](const std::vector<double>& cp) {
        Shape<R> sh{c0, c1};
        std::vector<double> partial;
        basis_pass<false, R>(slice, cp.data(), sh, 0, partial);
        std::vector<double> sums;
        for (std::size_t q = b.first; q < b.first + b.count; q += residual_block_rows) {
          Residuals<R> r(f.axes);
          residual_rows<R>(r, f.axes, shape, partial.data(), pts, b.first, q,
                           std::min(b.first + b.count, q + residual_block_rows), weight, off.data(), row.data(), e2.data());
          sums.push_back(r.weighted_sq);
        }
        std::vector<double> acc(1, 0.0);
        team.fold(acc, [&](std::span<double> a) {
          for (const double x : sums) a[0] += x;
        });
        return acc[0];
      };
      team.run([&] { gcv_fit<R>(f, sys, all_rhs, present[0], fill, rss); });
    } else {
      team.run([&] { sparse_fit<R>(f, sys, all_rhs, o.smoothing, filled); });
    }
  }
  detail::ApproxRows out = net_rows(f, team);
  check_rows_net(out, box, team);
  return out;
}

}  // namespace interpatch::detail
