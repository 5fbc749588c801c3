#include "constructions/scattered/scattered_system.hpp"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

#include <Eigen/SparseCholesky>

#include "base/kernel.hpp"
#include "base/parallel.hpp"

namespace interpatch::detail::scattered {

Net::Net(int p_, int q_, int nu_, int nv_, std::array<double, 2> range)
    : p(p_), q(q_), nu(nu_), nv(nv_), ku(KnotVector::uniform(p_, nu_, 0, range[0])), kv(KnotVector::uniform(q_, nv_, 0, range[1])),
      inv_h{(nu_ - p_) / range[0], (nv_ - q_) / range[1]} {}

Net::Net(KnotVector u, KnotVector v, std::array<bool, 2> even_)
    : p(u.degree()), q(v.degree()), nu(u.count()), nv(v.count()), ku(std::move(u)), kv(std::move(v)), even(even_) {
  for (int a = 0; a < 2; ++a) {
    const KnotVector& k = a == 0 ? ku : kv;
    const double length = k[static_cast<std::size_t>(k.count())] - k[static_cast<std::size_t>(k.degree())];
    inv_h[static_cast<std::size_t>(a)] = (k.count() - k.degree()) / length;
  }
}

namespace {

// A direction's knots on the coarser net: every other distinct knot, the ends kept (from
// uniform knots of an even count of spans, the uniform knots of half as many, to the
// bit: 2k (b - a) / 2n rounds as k (b - a) / n). From an odd count, the widest span at
// an even index (nearest the middle among equals) stays alone, so that the spans before
// and after it pair up. `even`: whether the knots are evenly spaced, and are after.
KnotVector coarser_knots(const KnotVector& k, bool& even) {
  const int p = k.degree(), spans = k.count() - p;
  if (spans <= 4) return k;
  const std::vector<double> t(k.values().begin() + p, k.values().end() - p);  // the spans + 1 distinct knots
  int alone = -1;
  if (spans % 2 == 1) {
    double widest = -1;
    for (int a = 0; a < spans; a += 2) {
      const double w = t[static_cast<std::size_t>(a + 1)] - t[static_cast<std::size_t>(a)];
      if (w > widest || (w == widest && std::abs(2 * a + 1 - spans) < std::abs(2 * alone + 1 - spans))) widest = w, alone = a;
    }
    even = false;
  }
  std::vector<double> out(static_cast<std::size_t>(p + 1), t.front());
  for (int a = 0; a < spans;) {
    a += a == alone ? 1 : 2;
    out.push_back(t[static_cast<std::size_t>(a)]);
  }
  out.insert(out.end(), static_cast<std::size_t>(p), t.back());
  return KnotVector(p, std::move(out));
}

}  // namespace

Net Net::coarser(const Net& fine) {
  std::array<bool, 2> even_ = fine.even;
  KnotVector u = coarser_knots(fine.ku, even_[0]), v = coarser_knots(fine.kv, even_[1]);
  return Net(std::move(u), std::move(v), even_);
}

void Net::uniform_basis(const KnotVector& k, double inv_h, int span, double t, double* n) {
  // The Cox–de Boor recurrence (The NURBS Book's A2.2) on the knots span + 1 - p ..
  // span + p, which lie between the clamped ends' p + 1 fold knots.
  const int p = k.degree();
  if (span < 2 * p - 1 || span + p > k.count()) return k.basis(span, t, n);
  static constexpr auto inv = [] {
    std::array<double, max_degree + 1> out{};
    for (int j = 1; j <= max_degree; ++j) out[static_cast<std::size_t>(j)] = 1.0 / j;
    return out;
  }();
  const double s = (t - k[static_cast<std::size_t>(span)]) * inv_h;  // in the span's spacings
  n[0] = 1;
  for (int j = 1; j <= p; ++j) {
    double saved = 0;
    for (int r = 0; r < j; ++r) {
      const double temp = n[r] * inv[static_cast<std::size_t>(j)];  // over right(r + 1) + left(j - r) = j spacings
      n[r] = saved + (r + 1 - s) * temp;
      saved = (s + j - r - 1) * temp;
    }
    n[j] = saved;
  }
}

double mean_diagonal(const NetMatrix& m) {
  double sum = 0;
  for (std::size_t r = 0; r < m.rows(); ++r) sum += m.at(r, 0);
  return sum / static_cast<double>(m.rows());
}

namespace {

// How many points ahead a pass asks for the input (Samples::prefetch): a cell's sums
// take about as long per point as memory takes to answer.
constexpr std::size_t ahead = 8;

// The cell (knot span) of each point present, in u-major order, and the points of each
// cell in the order given (a counting sort).
struct Cells {
  std::vector<std::size_t> start;  // cells + 1 offsets into `order`
  std::vector<std::uint32_t> order;
};

Cells sort_by_cell(const Net& net, const Samples& s) {
  const std::size_t su = static_cast<std::size_t>(net.nu - net.p), sv = static_cast<std::size_t>(net.nv - net.q);
  const std::size_t n = s.size(), cells = su * sv;
  // Each point's cell, found once (its site read from the input and mapped) and kept
  // for the placing: 4 bytes a point while the net is assembled, below a fit's peak.
  std::vector<std::uint32_t> cell(n);
  // The points in one contiguous block a thread, each block's count of each cell, then
  // where its points of each cell go: a stable sort, whatever the blocks.
  const bool parallel = n >= parallel_min_work / 16;
  const std::size_t blocks = parallel ? max_threads() : 1;
  std::vector<std::vector<std::uint32_t>> at(blocks, std::vector<std::uint32_t>(cells, 0));
  const auto range = [&](std::size_t b) { return std::array<std::size_t, 2>{n * b / blocks, n * (b + 1) / blocks}; };
  parallel_for(blocks, parallel, Share::blocks, [&](std::size_t b) {
    const auto [lo, hi] = range(b);
    for (std::size_t k = lo; k < hi; ++k) {
      s.prefetch(k + 2 * ahead);
      if (!(s.weight_at(k) > 0)) continue;
      const std::array<double, 2> t = s.site_at(k);
      const auto a = static_cast<std::size_t>(net.span_u(t[0]) - net.p), c = static_cast<std::size_t>(net.span_v(t[1]) - net.q);
      cell[k] = static_cast<std::uint32_t>(a * sv + c);
      ++at[b][cell[k]];
    }
  });
  Cells c;
  c.start.assign(cells + 1, 0);
  for (std::size_t x = 0; x < cells; ++x) {
    std::size_t next = c.start[x];
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::uint32_t count = at[b][x];
      at[b][x] = static_cast<std::uint32_t>(next);
      next += count;
    }
    c.start[x + 1] = next;
  }
  c.order.resize(c.start.back());
  parallel_for(blocks, parallel, Share::blocks, [&](std::size_t b) {
    const auto [lo, hi] = range(b);
    for (std::size_t k = lo; k < hi; ++k)
      if (s.weight_at(k) > 0) c.order[at[b][cell[k]]++] = static_cast<std::uint32_t>(k);
  });
  return c;
}

// The sums of one cell's points x in [first, last) of its order: the (p+1)(q+1) basis
// functions' products (the upper triangle, row by row), then their products with the
// values, into `local`. Any degrees; cubics by cubic_cell_sums.
void cell_sums_of(const Net& net, const Samples& s, const Cells& cells, std::size_t a, std::size_t b, std::size_t first,
                  std::size_t last, std::span<double> local) {
  const int p = net.p, q = net.q, m = (p + 1) * (q + 1), cols = s.cols;
  const std::size_t pairs = static_cast<std::size_t>(m * (m + 1) / 2);
  std::fill(local.begin(), local.end(), 0.0);
  double nu_b[max_degree + 1], nv_b[max_degree + 1], basis[(max_degree + 1) * (max_degree + 1)];
  const int span_u = static_cast<int>(a) + p, span_v = static_cast<int>(b) + q;
  for (std::size_t x = first; x < last; ++x) {
    const std::size_t k = cells.order[x];
    if (x + ahead < last) s.prefetch(cells.order[x + ahead]);
    const std::array<double, 2> t = s.site_at(k);
    net.basis_u(span_u, t[0], nu_b);
    net.basis_v(span_v, t[1], nv_b);
    const double w = s.weight_at(k);
    double value[3];
    s.values_at(k, value);
    for (int al = 0; al <= p; ++al)
      for (int be = 0; be <= q; ++be) basis[al * (q + 1) + be] = nu_b[al] * nv_b[be];
    std::size_t e = 0;
    for (int l = 0; l < m; ++l) {
      const double wb = w * basis[l];
      for (int l2 = l; l2 < m; ++l2) local[e++] += wb * basis[l2];
      for (int c = 0; c < cols; ++c) local[pairs + static_cast<std::size_t>(l * cols + c)] += wb * value[c];
    }
  }
}

// cell_sums_of for a cubic net and C columns, in vectors: each point's 16 × 16 products
// whole, four vectors of four a basis function, where the triangle's rows of 16 down to
// 1 took a scalar step each (the same sums, in the same order); the triangle taken from
// them at the cell's end.
template <std::size_t C>
[[gnu::always_inline]] inline void cubic_cell_sums(const Net& net, const Samples& s, const Cells& cells, std::size_t a, std::size_t b,
                                                   std::size_t first, std::size_t last, double* local) {
  using v4 = double __attribute__((vector_size(32)));
  constexpr int M = 16;
  v4 full[M][4] = {};
  double rhs[M][C] = {};
  const int span_u = static_cast<int>(a) + 3, span_v = static_cast<int>(b) + 3;
  for (std::size_t x = first; x < last; ++x) {
    const std::size_t k = cells.order[x];
    if (x + ahead < last) s.prefetch(cells.order[x + ahead]);
    const std::array<double, 2> t = s.site_at(k);
    double nu_b[4], nv_b[4];
    net.basis_u(span_u, t[0], nu_b);
    net.basis_v(span_v, t[1], nv_b);
    const double w = s.weight_at(k);
    double value[3];
    s.values_at(k, value);
    const v4 along{nv_b[0], nv_b[1], nv_b[2], nv_b[3]};
    v4 basis[4];  // basis[al][be]: the function (al, be), index 4 al + be
    for (int al = 0; al < 4; ++al) basis[al] = nu_b[al] * along;
    for (int l = 0; l < M; ++l) {
      const double wb = w * basis[l / 4][l % 4];
      for (int r = 0; r < 4; ++r) full[l][r] += wb * basis[r];
      for (std::size_t c = 0; c < C; ++c) rhs[l][c] += wb * value[c];
    }
  }
  std::size_t e = 0;
  for (int l = 0; l < M; ++l)
    for (int l2 = l; l2 < M; ++l2) local[e++] = full[l][l2 / 4][l2 % 4];
  for (int l = 0; l < M; ++l)
    for (std::size_t c = 0; c < C; ++c) local[e++] = rhs[l][c];
}

[[gnu::flatten]] INTERPATCH_KERNEL void cubic_cell_sums_1(const Net& net, const Samples& s, const Cells& cells, std::size_t a,
                                                          std::size_t b, std::size_t first, std::size_t last, double* local) {
  cubic_cell_sums<1>(net, s, cells, a, b, first, last, local);
}
[[gnu::flatten]] INTERPATCH_KERNEL void cubic_cell_sums_3(const Net& net, const Samples& s, const Cells& cells, std::size_t a,
                                                          std::size_t b, std::size_t first, std::size_t last, double* local) {
  cubic_cell_sums<3>(net, s, cells, a, b, first, last, local);
}

void cell_sums(const Net& net, const Samples& s, const Cells& cells, std::size_t a, std::size_t b, std::size_t first,
               std::size_t last, std::span<double> local) {
  if (net.p == 3 && net.q == 3 && s.cols == 1) return cubic_cell_sums_1(net, s, cells, a, b, first, last, local.data());
  if (net.p == 3 && net.q == 3 && s.cols == 3) return cubic_cell_sums_3(net, s, cells, a, b, first, last, local.data());
  cell_sums_of(net, s, cells, a, b, first, last, local);
}

// Where a cell's sums go, from the cell's first control point: each pair's place in the
// matrix's upper half (row · width + offset), each basis function's row. Found once a
// net: told apart for each cell by division, they took a sixth of a cubic pass.
struct CellPattern {
  std::vector<std::size_t> pair_at, basis_row;
  CellPattern(const Net& net, const NetMatrix& a) {
    const int q = net.q, m = (net.p + 1) * (q + 1);
    const auto nv = static_cast<std::size_t>(net.nv), width = static_cast<std::size_t>(a.width());
    const auto row = [&](int l) { return static_cast<std::size_t>(l / (q + 1)) * nv + static_cast<std::size_t>(l % (q + 1)); };
    for (int l = 0; l < m; ++l) {
      basis_row.push_back(row(l));
      for (int l2 = l; l2 < m; ++l2)
        pair_at.push_back(row(l) * width + static_cast<std::size_t>(a.offset(l2 / (q + 1) - l / (q + 1), l2 % (q + 1) - l % (q + 1))));
    }
  }
};

// A cell's sums added to the system (its matrix's upper half `upper`, as
// upper_for_writing gives it), once.
void add_sums(const Net& net, const CellPattern& pattern, std::size_t a, std::size_t b, std::span<const double> local, int cols,
              double* upper, int width, std::span<double> rhs) {
  const std::size_t base = a * static_cast<std::size_t>(net.nv) + b, pairs = pattern.pair_at.size();
  double* at = upper + base * static_cast<std::size_t>(width);
  for (std::size_t e = 0; e < pairs; ++e) at[pattern.pair_at[e]] += local[e];
  const auto c = static_cast<std::size_t>(cols);
  for (std::size_t l = 0; l < pattern.basis_row.size(); ++l)
    for (std::size_t m = 0; m < c; ++m) rhs[(base + pattern.basis_row[l]) * c + m] += local[pairs + l * c + m];
}

// Cells holding more than this many points are summed in blocks of it by all the threads
// at once (a coarse net's few cells would otherwise keep one thread busy each), the
// blocks' sums then added in order: the same bits on any number of threads.
constexpr std::size_t cell_block = 2048;

}  // namespace

void add_data_term(const Net& net, const Samples& s, System& sys) {
  double* upper = sys.a.upper_for_writing();  // the form then stays, on the threads too
  const int width = sys.a.width();
  const Cells cells = sort_by_cell(net, s);
  const CellPattern pattern(net, sys.a);
  const std::size_t su = static_cast<std::size_t>(net.nu - net.p), sv = static_cast<std::size_t>(net.nv - net.q);
  const std::size_t pu = static_cast<std::size_t>(net.p + 1), pv = static_cast<std::size_t>(net.q + 1);
  const bool parallel = cells.order.size() * pu * pv * pu * pv >= parallel_min_work;
  const std::size_t m = pu * pv, len = m * (m + 1) / 2 + m * static_cast<std::size_t>(s.cols);
  const auto count_of = [&](std::size_t cell) { return cells.start[cell + 1] - cells.start[cell]; };
  // The large cells' blocks, (cell, first point) each, their sums side by side.
  std::vector<std::array<std::size_t, 2>> blocks;
  for (std::size_t cell = 0; cell < su * sv; ++cell)
    if (count_of(cell) > cell_block)
      for (std::size_t x = cells.start[cell]; x < cells.start[cell + 1]; x += cell_block) blocks.push_back({cell, x});
  if (!blocks.empty()) {
    std::vector<double> sums(blocks.size() * len);
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (long long k = 0; k < static_cast<long long>(blocks.size()); ++k) {
      const auto [cell, x] = blocks[static_cast<std::size_t>(k)];
      cell_sums(net, s, cells, cell / sv, cell % sv, x, std::min(x + cell_block, cells.start[cell + 1]),
                std::span<double>(sums).subspan(static_cast<std::size_t>(k) * len, len));
    }
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const std::size_t cell = blocks[k][0];
      if (k > 0 && blocks[k - 1][0] == cell)
        for (std::size_t e = 0; e < len; ++e) sums[k * len + e] += sums[(k - 1) * len + e];
      if (k + 1 == blocks.size() || blocks[k + 1][0] != cell)
        add_sums(net, pattern, cell / sv, cell % sv, std::span<const double>(sums).subspan(k * len, len), s.cols, upper, width, sys.rhs);
    }
  }
  std::vector<std::vector<double>> local(parallel ? max_threads() : 1, std::vector<double>(len));
  // A task: p + 1 rows of cells, each row along b in turn, so that the control points'
  // rows it adds to stay in cache from one cell to the next. Tasks of one colour (every
  // other task) touch disjoint rows of control points. Colouring cells by (a, b) mod
  // (p + 1) instead read each control point's row of the matrix from memory once per
  // colour, 16 times a pass for cubics.
  const std::size_t tasks = (su + pu - 1) / pu;
  for (std::size_t colour = 0; colour < 2; ++colour) {
    const auto count = static_cast<long long>(tasks / 2 + (colour < tasks % 2 ? 1 : 0));
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (long long task = 0; task < count; ++task) {
      const std::size_t a0 = (2 * static_cast<std::size_t>(task) + colour) * pu, a1 = std::min(su, a0 + pu);
      for (std::size_t x = a0 * sv; x < a1 * sv; ++x) {
        const std::size_t a = x / sv, b = x % sv, cell = x, n = count_of(cell);
        if (x + 1 < a1 * sv) {
          // The next cell's first points asked for now: cells of a few points each would
          // otherwise wait on memory at every point (within a cell, cell_sums_of asks
          // ahead itself).
          for (std::size_t y = cells.start[x + 1]; y < std::min(cells.start[x + 2], cells.start[x + 1] + ahead); ++y) s.prefetch(cells.order[y]);
        }
        if (n == 0 || n > cell_block) continue;
        std::vector<double>& sums = local[static_cast<std::size_t>(thread_index())];
        cell_sums(net, s, cells, a, b, cells.start[cell], cells.start[cell + 1], sums);
        add_sums(net, pattern, a, b, sums, s.cols, upper, width, sys.rhs);
      }
    }
  }
}

namespace {

// Dot products of the columns in blocks of a fixed size, the blocks' sums added in
// order: the same bits on any number of threads.
constexpr std::size_t dot_block = 4096;

void dots(std::span<const double> x, std::span<const double> y, int cols, double* out, std::vector<double>& partial) {
  const std::size_t c = static_cast<std::size_t>(cols), rows = x.size() / c;
  const std::size_t blocks = (rows + dot_block - 1) / dot_block;
  partial.assign(blocks * c, 0.0);
#pragma omp parallel for schedule(static) if (x.size() >= parallel_min_work / 4)
  for (long long b = 0; b < static_cast<long long>(blocks); ++b) {
    const std::size_t r0 = static_cast<std::size_t>(b) * dot_block, r1 = std::min(rows, r0 + dot_block);
    double acc[3] = {0, 0, 0};
    for (std::size_t r = r0; r < r1; ++r)
      for (std::size_t k = 0; k < c; ++k) acc[k] += x[r * c + k] * y[r * c + k];
    for (std::size_t k = 0; k < c; ++k) partial[static_cast<std::size_t>(b) * c + k] = acc[k];
  }
  for (std::size_t k = 0; k < c; ++k) out[k] = 0;
  for (std::size_t b = 0; b < blocks; ++b)
    for (std::size_t k = 0; k < c; ++k) out[k] += partial[b * c + k];
}

}  // namespace

Solved solve_cg(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols, double rel, int max_iter,
                const Preconditioner& precondition, const KeepGoing& keep_going, std::span<double> residual_room) {
  const std::size_t c = static_cast<std::size_t>(cols), n = a.rows(), len = n * c;
  // z = M⁻¹ r and A p take turns in one vector: A p is spent once r is updated, before z
  // is made, and z once it is in p (a net's values fewer at the peak of a large fit).
  std::vector<double> inv, own_r, p(len), zap(len), partial;
  if (residual_room.size() != len) own_r.resize(len);
  const std::span<double> r = residual_room.size() == len ? residual_room : std::span<double>(own_r);
  std::vector<double>& z = zap;
  std::vector<double>& ap = zap;
  if (!precondition) {
    inv.resize(n);
    for (std::size_t i = 0; i < n; ++i) inv[i] = a.at(i, 0) > 0 ? 1 / a.at(i, 0) : 1.0;
  }
  const auto apply = [&] {
    if (precondition) precondition(r, z, cols);
    else
      for (std::size_t i = 0; i < len; ++i) z[i] = r[i] * inv[i / c];
  };
  double bb[3], rz[3], rr[3], pap[3];
  dots(b, b, cols, bb, partial);  // before r, which may be b itself
  a.multiply(x, ap, cols);
  for (std::size_t i = 0; i < len; ++i) r[i] = b[i] - ap[i];
  apply();
  p = z;
  dots(r, z, cols, rz, partial);
  bool active[3] = {true, true, true};
  Solved out;
  auto worst = [&] {
    dots(r, r, cols, rr, partial);
    double w = 0;
    for (std::size_t k = 0; k < c; ++k) {
      const double rel_k = bb[k] > 0 ? std::sqrt(rr[k] / bb[k]) : std::sqrt(rr[k]);
      active[k] = rel_k > rel;
      w = std::max(w, rel_k);
    }
    return w;
  };
  out.residual = worst();
  const auto go_on = [&] { return out.iterations < max_iter && out.residual > rel && (!keep_going || keep_going(out.iterations, out.residual)); };
  for (; go_on(); ++out.iterations) {
    a.multiply(p, ap, cols);
    dots(p, ap, cols, pap, partial);
    double alpha[3] = {0, 0, 0};
    for (std::size_t k = 0; k < c; ++k) alpha[k] = active[k] && pap[k] > 0 ? rz[k] / pap[k] : 0.0;
    // Value by value, no sums: the threads change no bit.
#pragma omp parallel for schedule(static) if (len >= parallel_min_work / 4)
    for (std::size_t i = 0; i < len; ++i) {
      x[i] += alpha[i % c] * p[i];
      r[i] -= alpha[i % c] * ap[i];
    }
    apply();
    double rz_new[3];
    dots(r, z, cols, rz_new, partial);
    for (std::size_t k = 0; k < c; ++k) {
      const double beta = rz[k] > 0 ? rz_new[k] / rz[k] : 0.0;
      rz[k] = rz_new[k];
#pragma omp parallel for schedule(static) if (len >= parallel_min_work / 4)
      for (std::size_t i = k; i < len; i += c) p[i] = z[i] + beta * p[i];
    }
    out.residual = worst();
  }
  return out;
}

struct DirectSolver::Factor {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper> ldlt;
  Eigen::Index n = 0;
  bool ok = false;
};

DirectSolver::DirectSolver(const NetMatrix& a) : f_(std::make_unique<Factor>()) {
  const auto n = static_cast<Eigen::Index>(a.rows());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(a.rows() * static_cast<std::size_t>(2 * a.hu() * a.hv() + a.hu() + a.hv() + 1));
  for (int i = 0; i < a.nu(); ++i)
    for (int j = 0; j < a.nv(); ++j) {
      const std::size_t r = static_cast<std::size_t>(i) * static_cast<std::size_t>(a.nv()) + static_cast<std::size_t>(j);
      for (int di = 0; di <= a.hu() && i + di < a.nu(); ++di)
        for (int dj = di == 0 ? 0 : std::max(-a.hv(), -j); dj <= std::min(a.hv(), a.nv() - 1 - j); ++dj) {
          const double v = a.at(r, a.offset(di, dj));
          if (v == 0) continue;
          const auto c = static_cast<Eigen::Index>(r + static_cast<std::size_t>(di) * static_cast<std::size_t>(a.nv())) + dj;
          entries.emplace_back(static_cast<Eigen::Index>(r), c, v);  // upper triangle: row < column
        }
    }
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(entries.begin(), entries.end());
  f_->n = n;
  f_->ldlt.compute(m);
  f_->ok = f_->ldlt.info() == Eigen::Success && f_->ldlt.vectorD().minCoeff() > 0;
}

DirectSolver::~DirectSolver() = default;
DirectSolver::DirectSolver(DirectSolver&&) noexcept = default;
DirectSolver& DirectSolver::operator=(DirectSolver&&) noexcept = default;

bool DirectSolver::ok() const { return f_->ok; }

void DirectSolver::solve(std::span<const double> b, std::span<double> x, int cols) const {
  const std::size_t c = static_cast<std::size_t>(cols);
  Eigen::VectorXd rhs(f_->n);
  for (std::size_t k = 0; k < c; ++k) {
    for (Eigen::Index r = 0; r < f_->n; ++r) rhs[r] = b[static_cast<std::size_t>(r) * c + k];
    const Eigen::VectorXd sol = f_->ldlt.solve(rhs);
    for (Eigen::Index r = 0; r < f_->n; ++r) x[static_cast<std::size_t>(r) * c + k] = sol[r];
  }
}

bool solve_direct(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols) {
  const DirectSolver d(a);
  if (!d.ok()) return false;
  d.solve(b, x, cols);
  return true;
}

}  // namespace interpatch::detail::scattered
