#include "linalg/banded.hpp"

#include "base/kernel.hpp"
#include "base/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

namespace interpatch::detail {

BandedLU::BandedLU(int n, int kl, int ku)
    : n_(n), kl_(kl), ku_(ku), w_(2 * kl + ku + 1),
      a_(static_cast<std::size_t>(n) * static_cast<std::size_t>(2 * kl + ku + 1), 0.0),
      piv_(static_cast<std::size_t>(n), 0) {}

bool BandedLU::factor() {
  double scale = 0;
  for (double v : a_) scale = std::max(scale, std::abs(v));
  const double tiny = 1e-14 * scale;
  const int kuu = kl_ + ku_;  // upper bandwidth of U after row swaps
  for (int k = 0; k < n_; ++k) {
    const int last = std::min(n_ - 1, k + kl_);
    int p = k;
    double best = std::abs(at(k, k));
    for (int i = k + 1; i <= last; ++i)
      if (std::abs(at(i, k)) > best) { best = std::abs(at(i, k)); p = i; }
    piv_[static_cast<std::size_t>(k)] = p;
    swapped_ = swapped_ || p != k;
    if (!(best > tiny)) { failed_row_ = k; return false; }
    const int jlast = std::min(n_ - 1, k + kuu);
    if (p != k)
      for (int j = k; j <= jlast; ++j) std::swap(at(k, j), at(p, j));
    const double inv = 1.0 / at(k, k);
    for (int i = k + 1; i <= last; ++i) {
      const double l = at(i, k) * inv;
      at(i, k) = l;
      if (l != 0.0)
        for (int j = k + 1; j <= jlast; ++j) at(i, j) -= l * at(k, j);
    }
  }
  return true;
}

namespace {

// dst[c] = (dst[c] − Σ_t coef[t] src[t][c]) (· inv with Scale), the terms taken in
// order: the operations, and so the bits, of T updates dst[c] −= coef[t] src[t][c]
// one after another (and dst[c] *= inv), with one store instead of T + Scale.
template <int T, bool Scale>
[[gnu::always_inline]] inline void update_row(double* __restrict dst, const double* const* src, const double* coef,
                                              double inv, std::size_t width) noexcept {
  const double* s[T > 0 ? T : 1];
  double l[T > 0 ? T : 1];
  for (int t = 0; t < T; ++t) {
    s[t] = src[t];
    l[t] = coef[t];
  }
  for (std::size_t c = 0; c < width; ++c) {
    double v = dst[c];
    for (int t = 0; t < T; ++t) v -= l[t] * s[t][c];
    if constexpr (Scale) v *= inv;
    dst[c] = v;
  }
}

// The `count` updates of a row in groups of at most four, then the scaling.
[[gnu::always_inline]] inline void update_row(double* dst, const double* const* src, const double* coef, int count,
                                              bool scale, double inv, std::size_t width) noexcept {
  for (; count > 4; count -= 4, src += 4, coef += 4) update_row<4, false>(dst, src, coef, inv, width);
  switch (count * 2 + (scale ? 1 : 0)) {
    case 1: update_row<0, true>(dst, src, coef, inv, width); break;
    case 2: update_row<1, false>(dst, src, coef, inv, width); break;
    case 3: update_row<1, true>(dst, src, coef, inv, width); break;
    case 4: update_row<2, false>(dst, src, coef, inv, width); break;
    case 5: update_row<2, true>(dst, src, coef, inv, width); break;
    case 6: update_row<3, false>(dst, src, coef, inv, width); break;
    case 7: update_row<3, true>(dst, src, coef, inv, width); break;
    case 8: update_row<4, false>(dst, src, coef, inv, width); break;
    case 9: update_row<4, true>(dst, src, coef, inv, width); break;
    default: break;  // 0: nothing to do
  }
}

}  // namespace

// Row i of the forward sweep takes its updates from rows k < i in increasing k, as
// the sweep by columns gives them to it; row k of the back substitution its
// updates from rows j > k in increasing j, then the division: every number goes
// through the same operations as there. Zero entries are skipped as there (a zero
// times an infinity would be a NaN).
INTERPATCH_KERNEL void BandedLU::solve_by_rows(double* b, std::size_t width, std::size_t stride) const noexcept {
  const int kuu = kl_ + ku_;
  auto row = [&](int i) { return b + static_cast<std::size_t>(i) * stride; };
  constexpr int most = 64;  // terms gathered at once; a wider band in several passes
  const double* src[most];
  double coef[most];
  // Row r's updates from the rows of B in [first, last] with a nonzero entry in row
  // r of the factors, in increasing order; then, with `divide`, the division by the
  // diagonal. Inlined, so that it is compiled for this clone's processor (a lambda
  // left as a function of its own would not be, and would round otherwise).
  auto finish_row = [&](int r, int first, int last, bool divide) __attribute__((always_inline)) {
    int count = 0;
    for (int j = first; j <= last; ++j) {
      const double e = at(r, j);
      if (e == 0.0) continue;
      src[count] = row(j);
      coef[count++] = e;
      if (count == most) {
        update_row(row(r), src, coef, count, false, 1.0, width);
        count = 0;
      }
    }
    update_row(row(r), src, coef, count, divide, divide ? 1.0 / at(r, r) : 1.0, width);
  };
  for (int i = 1; i < n_; ++i) finish_row(i, std::max(0, i - kl_), i - 1, false);
  for (int k = n_ - 1; k >= 0; --k) finish_row(k, k + 1, std::min(n_ - 1, k + kuu), true);
}

void BandedLU::solve(double* b, std::size_t width, std::size_t stride) const noexcept {
  if (swapped_) solve_by_columns(b, width, stride);
  else solve_by_rows(b, width, stride);
}

INTERPATCH_KERNEL void BandedLU::solve_by_columns(double* b, std::size_t width, std::size_t stride) const noexcept {
  const int kuu = kl_ + ku_;
  auto row = [&](int i) { return b + static_cast<std::size_t>(i) * stride; };
  for (int k = 0; k < n_; ++k) {
    const int p = piv_[static_cast<std::size_t>(k)];
    double* bk = row(k);
    if (p != k) std::swap_ranges(bk, bk + width, row(p));
    const int last = std::min(n_ - 1, k + kl_);
    for (int i = k + 1; i <= last; ++i) {
      const double l = at(i, k);
      if (l == 0.0) continue;
      double* bi = row(i);
      for (std::size_t c = 0; c < width; ++c) bi[c] -= l * bk[c];
    }
  }
  for (int k = n_ - 1; k >= 0; --k) {
    double* bk = row(k);
    const int jlast = std::min(n_ - 1, k + kuu);
    for (int j = k + 1; j <= jlast; ++j) {
      const double u = at(k, j);
      if (u == 0.0) continue;
      const double* bj = row(j);
      for (std::size_t c = 0; c < width; ++c) bk[c] -= u * bj[c];
    }
    const double inv = 1.0 / at(k, k);
    for (std::size_t c = 0; c < width; ++c) bk[c] *= inv;
  }
}

namespace {
int modulo(int a, int n) { return ((a % n) + n) % n; }
}  // namespace

CyclicLU::CyclicLU(int n, const std::vector<std::vector<Entry>>& rows) : n_(n), rows_(rows) {}

bool CyclicLU::factor() {
  const int n = n_;
  if (n == 0) return true;
  double scale = 0;
  // The shift puts on the diagonal the entry of each row that matches its row (the
  // basis function whose support has the row's parameter inside): of the columns of
  // row 0, the one whose diagonal's smallest entry is largest. B, consecutive basis
  // functions at increasing parameters with a positive diagonal, is then totally
  // positive and regular (Schoenberg–Whitney).
  auto entry = [&](int i, int col) {
    double v = 0;
    for (const Entry& e : rows_[static_cast<std::size_t>(i)])
      if (modulo(e.col, n) == col) v += e.value;
    return std::abs(v);
  };
  double best = -1;
  for (const Entry& cand : rows_[0]) {
    const int h = modulo(cand.col, n);
    double low = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n && low > best; ++i) low = std::min(low, entry(i, modulo(i + h, n)));
    if (low > best) {
      best = low;
      h_ = h;
    }
  }
  // Offsets of the entries from the shifted diagonal, taken the short way round.
  int kl = 0, ku = 0;
  for (int i = 0; i < n; ++i)
    for (const Entry& e : rows_[static_cast<std::size_t>(i)]) {
      int d = modulo(e.col - h_ - i, n);
      if (d > n / 2) d -= n;
      kl = std::max(kl, -d);
      ku = std::max(ku, d);
      scale = std::max(scale, std::abs(e.value));
    }
  // A border of m rows and columns keeps the wrapped corners out of B, and a shift
  // of at most m (either way round) lets solve() undo it in its last pass.
  int m = std::max({kl, ku, std::min(h_, n - h_)});
  if (n <= 2 * m + 1) m = n;  // too small to have a band: all border, solved dense
  m_ = m;
  nb_ = n - m;
  const auto M = static_cast<std::size_t>(m), NB = static_cast<std::size_t>(nb_);
  b_ = BandedLU(nb_, nb_ > 0 ? kl : 0, nb_ > 0 ? ku : 0);
  y_.assign(NB * M, 0.0);
  d_.assign(M, {});
  s_.assign(M * M, 0.0);
  for (int i = 0; i < n; ++i)
    for (const Entry& e : rows_[static_cast<std::size_t>(i)]) {
      const int c = modulo(e.col - h_, n);
      if (i < nb_ && c < nb_) b_.at(i, c) += e.value;
      else if (i < nb_) y_[static_cast<std::size_t>(i) * M + static_cast<std::size_t>(c - nb_)] += e.value;
      else if (c < nb_) d_[static_cast<std::size_t>(i - nb_)].push_back({c, e.value});
      else s_[static_cast<std::size_t>(i - nb_) * M + static_cast<std::size_t>(c - nb_)] += e.value;
    }
  if (nb_ > 0) {
    if (!b_.factor()) {
      failed_row_ = modulo(b_.failed_row(), n);
      return false;
    }
    if (M > 0) b_.solve(y_.data(), M, M);
  }
  for (std::size_t r = 0; r < M; ++r)
    for (const Entry& e : d_[r])
      for (std::size_t j = 0; j < M; ++j) s_[r * M + j] -= e.value * y_[static_cast<std::size_t>(e.col) * M + j];
  // Dense LU of S with partial pivoting.
  piv_.assign(M, 0);
  const double tiny = 1e-14 * scale;
  for (std::size_t k = 0; k < M; ++k) {
    std::size_t p = k;
    for (std::size_t i = k + 1; i < M; ++i)
      if (std::abs(s_[i * M + k]) > std::abs(s_[p * M + k])) p = i;
    piv_[k] = static_cast<int>(p);
    if (!(std::abs(s_[p * M + k]) > tiny)) {
      failed_row_ = nb_ + static_cast<int>(k);
      return false;
    }
    if (p != k)
      for (std::size_t j = 0; j < M; ++j) std::swap(s_[k * M + j], s_[p * M + j]);
    const double inv = 1.0 / s_[k * M + k];
    for (std::size_t i = k + 1; i < M; ++i) {
      const double l = s_[i * M + k] * inv;
      s_[i * M + k] = l;
      if (l != 0.0)
        for (std::size_t j = k + 1; j < M; ++j) s_[i * M + j] -= l * s_[k * M + j];
    }
  }
  return true;
}

void CyclicLU::solve(double* b, std::size_t width, std::size_t stride) const {
  if (n_ == 0) return;
  std::vector<double> border(static_cast<std::size_t>(m_) * width);
  solve_with(b, width, stride, border.data());
}

INTERPATCH_KERNEL void CyclicLU::solve_with(double* b, std::size_t width, std::size_t stride,
                                            double* border) const noexcept {
  const auto M = static_cast<std::size_t>(m_);
  auto row = [&](int i) { return b + static_cast<std::size_t>(i) * stride; };
  if (nb_ > 0) b_.solve(b, width, stride);
  // Border right-hand sides less D z, then the Schur complement's solve.
  for (std::size_t r = 0; r < M; ++r) {
    double* br = row(nb_ + static_cast<int>(r));
    for (const Entry& e : d_[r]) {
      const double* z = row(e.col);
      for (std::size_t c = 0; c < width; ++c) br[c] -= e.value * z[c];
    }
  }
  for (std::size_t k = 0; k < M; ++k) {
    double* bk = row(nb_ + static_cast<int>(k));
    if (const auto p = static_cast<std::size_t>(piv_[k]); p != k) std::swap_ranges(bk, bk + width, row(nb_ + static_cast<int>(p)));
    for (std::size_t i = k + 1; i < M; ++i) {
      const double l = s_[i * M + k];
      if (l == 0.0) continue;
      double* bi = row(nb_ + static_cast<int>(i));
      for (std::size_t c = 0; c < width; ++c) bi[c] -= l * bk[c];
    }
  }
  for (std::size_t k = M; k-- > 0;) {
    double* bk = row(nb_ + static_cast<int>(k));
    for (std::size_t j = k + 1; j < M; ++j) {
      const double u = s_[k * M + j];
      const double* bj = row(nb_ + static_cast<int>(j));
      for (std::size_t c = 0; c < width; ++c) bk[c] -= u * bj[c];
    }
    const double inv = 1.0 / s_[k * M + k];
    for (std::size_t c = 0; c < width; ++c) bk[c] *= inv;
  }
  // x_c = z_c − Σ_j Y[c][j] x_border[j], each moved to its control point: unknown c
  // is control point (c + h) mod n. The border is copied aside first; B's rows then
  // move in the order that reads every row before it is overwritten.
  for (std::size_t j = 0; j < M; ++j) std::copy_n(row(nb_ + static_cast<int>(j)), width, border + j * width);
  auto update = [&](int c, double* dst) {
    const double* src = row(c);
    const double* yc = y_.data() + static_cast<std::size_t>(c) * M;
    if (M == 1) {
      const double y0 = yc[0];
      for (std::size_t k = 0; k < width; ++k) dst[k] = src[k] - y0 * border[k];
      return;
    }
    for (std::size_t k = 0; k < width; ++k) dst[k] = src[k];
    for (std::size_t j = 0; j < M; ++j) {
      const double y = yc[j];
      const double* x = border + j * width;
      for (std::size_t k = 0; k < width; ++k) dst[k] -= y * x[k];
    }
  };
  const int n = n_;
  if (h_ <= n - h_) {  // right by h (descending: row c + h was read already)
    for (int c = nb_ - 1; c >= 0; --c) update(c, row(c + h_));
  } else {  // left by n − h (ascending)
    for (int c = 0; c < nb_; ++c) update(c, row(modulo(c + h_, n)));
  }
  for (std::size_t j = 0; j < M; ++j)
    std::copy_n(border + j * width, width, row(modulo(nb_ + static_cast<int>(j) + h_, n)));
}

namespace {

// Columns of wide lines solved together, a slice of them at a time. The forward and
// the back sweep each stream through the slice's n rows (the rows of the band stay
// in cache between uses). When a slice 512 doubles wide (4 KiB of each row) still
// fits in a quarter of a 32 MiB L3 cache with its n rows, the slices are that narrow
// and the back sweep finds them in cache: one pass over memory instead of two
// (2048² surface grids: the u-solve 9.5 → 8.6 ms on 2 threads). Longer lines get
// slices a quarter of the row wide, where long streams beat narrow slices that no
// longer fit (4096²: 40 ms against 44). Narrow slices come in a multiple of the
// thread count, so that each thread gets as many.
std::size_t slice_width(std::size_t inner, std::size_t n) {
  constexpr std::size_t min_width = 512, cache_bytes = std::size_t{8} << 20;
  std::size_t w = std::max(min_width, (inner + 3) / 4);
  if (n * min_width * sizeof(double) <= cache_bytes) {
#ifdef _OPENMP
    const auto threads = static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
#else
    const std::size_t threads = 1;
#endif
    std::size_t slices = (inner + min_width - 1) / min_width;
    if (slices > 1) slices = (slices + threads - 1) / threads * threads;
    w = (inner + slices - 1) / slices;
  }
  return w + (8 - w % 8) % 8;
}

// Eight narrow lines (the last axis: 3 doubles a row) side by side in `buf` give each
// row operation 24 independent columns instead of one dependent chain of scalar
// operations; every number still goes through the same operations.
constexpr std::size_t narrow_group = 8;

// Copies the m lines (rows of `inner` doubles, `block` apart) side by side into buf
// (Gather) or back out of it: plain loops, with the row's length known at compile
// time for the usual 3 doubles a row (Inner = 3; 0: inner given at run time).
template <bool Gather, std::size_t Inner>
[[gnu::always_inline]] inline void shuffle(double* data, std::size_t n, std::size_t inner, std::size_t block,
                                           std::size_t m, double* buf) {
  if constexpr (Inner != 0) inner = Inner;
  const std::size_t width = m * inner;
  for (std::size_t l = 0; l < m; ++l) {
    double* line = data + l * block;
    double* side = buf + l * inner;
    if constexpr (Inner != 0) {  // a row as one block of bytes: two moves instead of three
      for (std::size_t k = 0; k < n; ++k) {
        if constexpr (Gather) std::memcpy(side + k * width, line + k * Inner, Inner * sizeof(double));
        else std::memcpy(line + k * Inner, side + k * width, Inner * sizeof(double));
      }
      continue;
    }
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t c = 0; c < inner; ++c) {
        if constexpr (Gather) side[k * width + c] = line[k * inner + c];
        else line[k * inner + c] = side[k * width + c];
      }
  }
}

template <bool Gather>
INTERPATCH_KERNEL void shuffle_lines(double* data, std::size_t n, std::size_t inner, std::size_t block, std::size_t m,
                                     double* buf) {
  if (inner == 3) return shuffle<Gather, 3>(data, n, inner, block, m, buf);
  shuffle<Gather, 0>(data, n, inner, block, m, buf);
}

// Returns whether the group's solution has a NaN or an infinity when `check`.
template <class Solver>
void solve_narrow_group(const Solver& lu, double* data, std::size_t n, std::size_t inner, std::size_t block,
                        std::size_t m, double* buf) {
  shuffle_lines<true>(data, n, inner, block, m, buf);
  lu.solve(buf, m * inner, m * inner);
  shuffle_lines<false>(data, n, inner, block, m, buf);
}

}  // namespace

template <class Solver>
void solve_along_axis(const Solver& lu, double* data, const std::size_t* shape, std::size_t rank, std::size_t axis,
                      std::size_t components, bool parallel) {
  std::size_t outer = 1, inner = components;
  for (std::size_t a = 0; a < axis; ++a) outer *= shape[a];
  for (std::size_t a = axis + 1; a < rank; ++a) inner *= shape[a];
  const std::size_t n = shape[axis];
  if (outer == 0 || inner == 0) return;  // nothing to solve (a process of a split run holding no columns)
  const std::size_t block = n * inner;
  [[maybe_unused]] const bool threads = parallel && block * outer >= parallel_min_work;
  // A thread's buffer and CyclicLU::solve allocate: a failure skips the work left
  // and is rethrown after the region.
  ParallelFailure failure;
  if (inner < 64 && outer > 1) {
    const auto groups = static_cast<long long>((outer + narrow_group - 1) / narrow_group);
#pragma omp parallel if (threads)
    {
      // Not zeroed: every group writes the part it reads (solve_rows calls this for
      // every few rows, and zeroing the buffer each time cost a tenth of an eval).
      std::unique_ptr<double[]> buf;
      failure.attempt(static_cast<std::size_t>(thread_index()),
                      [&] { buf = std::make_unique_for_overwrite<double[]>(n * narrow_group * inner); });
#pragma omp for schedule(static)
      for (long long g = 0; g < groups; ++g) {
        if (!buf) continue;
        failure.attempt(static_cast<std::size_t>(g), [&] {
          const std::size_t o0 = static_cast<std::size_t>(g) * narrow_group;
          solve_narrow_group(lu, data + o0 * block, n, inner, block, std::min(narrow_group, outer - o0), buf.get());
        });
      }
    }
    failure.rethrow();
    return;
  }
  const std::size_t slice = slice_width(inner, n);
  const std::size_t slices = (inner + slice - 1) / slice;
  const auto tasks = static_cast<long long>(outer * slices);
#pragma omp parallel for schedule(static) if (tasks > 1 && threads)
  for (long long t = 0; t < tasks; ++t)
    failure.attempt(static_cast<std::size_t>(t), [&] {
      const std::size_t o = static_cast<std::size_t>(t) / slices;
      const std::size_t s = static_cast<std::size_t>(t) % slices;
      const std::size_t c0 = s * slice;
      const std::size_t width = std::min(slice, inner - c0);
      double* first = data + o * block + c0;
      lu.solve(first, width, inner);
    });
  failure.rethrow();
}

template void solve_along_axis<BandedLU>(const BandedLU&, double*, const std::size_t*, std::size_t, std::size_t,
                                        std::size_t, bool);
template void solve_along_axis<CyclicLU>(const CyclicLU&, double*, const std::size_t*, std::size_t, std::size_t,
                                        std::size_t, bool);

}  // namespace interpatch::detail
