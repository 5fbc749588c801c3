#include "constructions/scattered/scattered_smoother.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "base/kernel.hpp"
#include "base/parallel.hpp"
#include "base/sums.hpp"

namespace interpatch::detail::scattered {

namespace {

// Strips as wide as the matrix reaches plus one: strips two apart share no entry, so two
// colours suffice, and a strip holds every coupling of a control point to its
// neighbours across it.
int strip_width(const NetMatrix& a) { return std::max(a.hu(), a.hv()) + 1; }

// A strip's factor as the factoring and the band solves take it: its unknowns, and the
// reach and width that give each row's length (strip_row_length).
struct Band {
  std::size_t size, reach, width;
  [[nodiscard]] std::size_t length(std::size_t k) const { return strip_row_length(k, reach, width); }
};

// In place, the band Cholesky factor of the matrix held in `f` (row k's entries A[k][j],
// j from k - length(k) to k, at f[k (band + 1) + band - (k - j)]): L[k][j] =
// (A[k][j] - Σ_i L[k][i] L[j][i]) / L[j][j] for j < k, and 1 / L[k][k] in the
// diagonal's place. False at a pivot not positive. Column by column: the sums of a
// column's rows do not wait on each other, where by rows each waited on the last (and
// each sum in four interleaved parts, not waiting on one adder).
[[gnu::flatten]] INTERPATCH_KERNEL bool factor_band(double* f, Band s, std::size_t band) {
  const std::size_t stride = band + 1;
  for (std::size_t j = 0; j < s.size; ++j) {
    double* lj = f + j * stride;  // lj[band - (j - i)] = L[j][i]
    const std::size_t nj = s.length(j);
    const double pivot = lj[band] - interleaved_dot(lj + band - nj, lj + band - nj, nj);
    if (!(pivot > 0)) return false;
    const double inverse = 1 / std::sqrt(pivot);
    lj[band] = inverse;
    for (std::size_t k = j + 1; k < std::min(s.size, j + band + 1); ++k) {
      const std::size_t first = k - s.length(k);
      if (first > j) continue;  // L[k][j] is 0, left of row k's first entry
      double* lk = f + k * stride;
      const std::size_t i0 = std::max(first, j - nj), n = j - i0;
      lk[band - (k - j)] = (lk[band - (k - j)] - interleaved_dot(lk + band - (k - i0), lj + band - n, n)) * inverse;
    }
  }
  return true;
}

}  // namespace

std::size_t StripSmoother::bytes_per_row(int hu, int hv) {
  // A strip of width w along a direction of reach h keeps h w + (w - 1) / 2 entries a
  // row on average, and the inverse diagonal (Strip::length): along both directions,
  // (hu + hv) w + w + 1 numbers, rounded up.
  const std::size_t w = static_cast<std::size_t>(std::max(hu, hv) + 1);
  return sizeof(float) * ((static_cast<std::size_t>(hu) + static_cast<std::size_t>(hv)) * w + w + 1);
}

StripSmoother::StripSmoother(const NetMatrix& a) : nu_(a.nu()), nv_(a.nv()) {
  const int w = strip_width(a);
  std::size_t at = 0;
  for (int dir = 0; dir < 2; ++dir) {
    const int across = dir == 0 ? nu_ : nv_, along = dir == 0 ? nv_ : nu_;
    const int reach = dir == 0 ? a.hv() : a.hu();  // the coupling along the strip
    for (int first = 0; first < across; first += w) {
      Strip s;
      s.dir = dir, s.index = first / w, s.first = first, s.width = std::min(w, across - first);
      s.reach = reach;
      s.band = reach * s.width + s.width - 1;
      s.size = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(along);
      s.at = at;
      for (std::size_t k = 0; k < s.size; ++k) at += s.length(k) + 1;
      strips_.push_back(s);
    }
  }
  // Not zeroed: each strip writes its own (or is left out, never read). Zeroing 34 MB
  // on one thread first took most of the factoring's time.
  factor_.reset(new float[at]);
  const auto count = static_cast<long long>(strips_.size());
  // Each row of a band b costs about b² / 2 multiply-adds to factor.
  const auto band = static_cast<std::size_t>(std::max(a.hu(), a.hv()) * w + w);
  const bool parallel = a.rows() * band * band >= parallel_min_work;
  std::size_t largest = 0;
  for (const Strip& s : strips_) largest = std::max(largest, s.size * static_cast<std::size_t>(s.band + 1));
  std::size_t longest = 0;
  for (const Strip& s : strips_) longest = std::max(longest, s.size);
  std::vector<FactorScratch> scratch(parallel ? max_threads() : 1);
  for (FactorScratch& f : scratch) f = {std::vector<double>(largest), std::vector<std::array<int, 2>>(longest), std::vector<std::size_t>(longest)};
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (long long k = 0; k < count; ++k) factor(a, strips_[static_cast<std::size_t>(k)], scratch[static_cast<std::size_t>(thread_index())]);
}

void StripSmoother::factor(const NetMatrix& a, Strip& s, FactorScratch& scratch) {
  // The strip's entries into the band, factored there in double, then kept in single
  // precision. Each unknown's control point is found once, and its row of the upper
  // half read whole, its entries to the strip's unknowns placed in the later one's row
  // of the band (an entry at a time took a third of the factoring).
  const auto band = static_cast<std::size_t>(s.band), stride = band + 1;
  double* f = scratch.band.data();
  std::vector<std::array<int, 2>>& at = scratch.at;
  std::vector<std::size_t>& row = scratch.row;
  for_each_row(s, [&](std::size_t k, int i, int j, std::size_t r) { at[k] = {i, j}, row[k] = r; });
  for (std::size_t k = 0; k < s.size; ++k) std::fill(f + k * stride + band - s.length(k), f + (k + 1) * stride, 0.0);
  const int hu = a.hu(), hv = a.hv(), w = s.width;
  double entries[NetMatrix::max_width];
  for (std::size_t k = 0; k < s.size; ++k) {
    a.upper_row(row[k], entries, NetMatrix::Part::floats);
    const auto [i, j] = at[k];
    for (int di = 0; di <= hu; ++di)
      for (int dj = di == 0 ? 0 : -hv; dj <= hv; ++dj) {
        // The neighbour's place in the strip: across it (w wide), and along it.
        const int across = s.dir == 0 ? i + di - s.first : j + dj - s.first, along = s.dir == 0 ? j + dj : i + di;
        if (across < 0 || across >= w || along < 0 || along >= (s.dir == 0 ? nv_ : nu_)) continue;
        const auto kn = static_cast<std::size_t>(along) * static_cast<std::size_t>(w) + static_cast<std::size_t>(across);
        const std::size_t later = std::max(k, kn), gap = later - std::min(k, kn);
        if (gap <= s.length(later)) f[later * stride + band - gap] = entries[a.offset(di, dj)];
      }
  }
  if (!factor_band(f, Band{s.size, static_cast<std::size_t>(s.reach), static_cast<std::size_t>(s.width)}, band)) return;  // s.ok stays false
  float* out = factor_.get() + s.at;
  for (std::size_t k = 0; k < s.size; ++k) {
    const std::size_t n = s.length(k);
    out = std::copy(f + k * stride + band - n, f + k * stride + band + 1, out);
  }
  s.ok = true;
}

void StripSmoother::residuals(int dir, int colour, const NetMatrix& a, std::span<const double> b, std::span<const double> x,
                              std::size_t c, std::span<double> r) const {
  // Along u, the rows of the colour's strips, a strip a task; along v, every row, in
  // multiply()'s bands: reading the matrix in stretches of w rows with gaps as long
  // took a third longer than reading it whole.
  std::vector<std::array<int, 2>> bands;
  if (dir == 0) {
    for (const Strip& s : strips_)
      if (s.dir == 0 && s.index % 2 == colour) bands.push_back({s.first, s.first + s.width});
  } else {
    for (int i = 0; i < nu_; i += NetMatrix::band_rows) bands.push_back({i, std::min(nu_, i + NetMatrix::band_rows)});
  }
  const std::size_t work = a.rows() * static_cast<std::size_t>((2 * a.hu() + 1) * (2 * a.hv() + 1)) * c;
  const auto count = static_cast<long long>(bands.size());
  const auto nv = static_cast<std::size_t>(nv_);
#pragma omp parallel for schedule(static) if (work >= parallel_min_work)
  for (long long k = 0; k < count; ++k) {
    const auto [i0, i1] = bands[static_cast<std::size_t>(k)];
    a.multiply_rows(i0, i1, x, r, static_cast<int>(c), NetMatrix::Part::floats);
    for (std::size_t e = static_cast<std::size_t>(i0) * nv * c; e < static_cast<std::size_t>(i1) * nv * c; ++e) r[e] = b[e] - r[e];
  }
}

namespace {

// L y = r, then Lᵀ z = y, in place, for c interleaved columns (row k of the factor:
// L[k][k - n .. k - 1], then 1 / L[k][k], n = s.length(k)); the forward sums in four
// interleaved parts so that they do not wait on one adder.
[[gnu::flatten]] INTERPATCH_KERNEL void solve_band(const float* f, Band s, std::size_t c, double* r) {
  std::size_t at = 0;
  for (std::size_t k = 0; k < s.size; ++k) {
    const std::size_t n = s.length(k);
    const float* lk = f + at;  // lk[n - (k - i)] = L[k][i]
    for (std::size_t m = 0; m < c; ++m) {
      double part[4] = {r[k * c + m], 0, 0, 0};
      std::size_t i = k - n;
      for (; i + 4 <= k; i += 4)
        for (std::size_t e = 0; e < 4; ++e) part[e] -= lk[n - (k - i - e)] * r[(i + e) * c + m];
      for (; i < k; ++i) part[0] -= lk[n - (k - i)] * r[i * c + m];
      r[k * c + m] = ((part[0] + part[1]) + (part[2] + part[3])) * lk[n];
    }
    at += n + 1;
  }
  for (std::size_t k = s.size; k-- > 0;) {
    const std::size_t n = s.length(k);
    at -= n + 1;
    const float* lk = f + at;
    for (std::size_t m = 0; m < c; ++m) {
      const double z = r[k * c + m] * lk[n];
      r[k * c + m] = z;
      for (std::size_t i = k - n; i < k; ++i) r[i * c + m] -= lk[n - (k - i)] * z;
    }
  }
}

// The same for one column: each row's band one contiguous stretch of the factor and of
// r (vectors for the compiler), and the term of the row just solved taken last, so that
// the others need not wait on it (the conjugate gradients of a 512² net a tenth faster).
[[gnu::flatten]] INTERPATCH_KERNEL void solve_band_one(const float* f, Band s, double* r) {
  std::size_t at = 0;
  for (std::size_t k = 0; k < s.size; ++k) {
    const std::size_t n = s.length(k);
    const float* l = f + at;  // l[t] = L[k][k - n + t], l[n] = 1 / L[k][k]
    const double* y = r + (k - n);
    double part[4] = {0, 0, 0, 0};
    std::size_t t = 0;
    for (; t + 5 <= n; t += 4)
      for (std::size_t e = 0; e < 4; ++e) part[e] += l[t + e] * y[t + e];
    for (; t + 1 < n; ++t) part[0] += l[t] * y[t];
    double sum = r[k] - ((part[0] + part[1]) + (part[2] + part[3]));
    if (n > 0) sum -= l[n - 1] * y[n - 1];
    r[k] = sum * l[n];
    at += n + 1;
  }
  for (std::size_t k = s.size; k-- > 0;) {
    const std::size_t n = s.length(k);
    at -= n + 1;
    const float* l = f + at;
    double* y = r + (k - n);
    const double z = r[k] * l[n];
    r[k] = z;
    for (std::size_t t = 0; t < n; ++t) y[t] -= l[t] * z;
  }
}

}  // namespace

void StripSmoother::solve(const Strip& s, std::span<const double> all, std::span<double> x, std::size_t c,
                          std::vector<double>& scratch) const {
  const float* f = &factor_[s.at];
  double* r = scratch.data();
  // A strip along v has its rows a net row apart in memory, each on a page of its own
  // on large nets, where the hardware does not look ahead: the values and the x of the
  // rows 8 ahead are asked for as each row is read (the sweeps of a 512² net waited on
  // them a third of their solves' time).
  const std::size_t ahead = s.dir == 1 ? 8 * static_cast<std::size_t>(nv_) * c : 0;
  for_each_row(s, [&](std::size_t k, int, int, std::size_t row) {
    if (ahead != 0 && k % static_cast<std::size_t>(s.width) == 0 && row * c + ahead < all.size()) {
      __builtin_prefetch(all.data() + row * c + ahead);
      __builtin_prefetch(x.data() + row * c + ahead, 1);
    }
    for (std::size_t m = 0; m < c; ++m) r[k * c + m] = all[row * c + m];
  });
  const Band band{s.size, static_cast<std::size_t>(s.reach), static_cast<std::size_t>(s.width)};
  if (c == 1) solve_band_one(f, band, r);
  else solve_band(f, band, c, r);
  for_each_row(s, [&](std::size_t k, int, int, std::size_t row) {
    for (std::size_t m = 0; m < c; ++m) x[row * c + m] += r[k * c + m];
  });
}

void StripSmoother::sweep(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols, bool backward,
                          std::vector<double>& work, bool from_zero) const {
  const std::size_t c = static_cast<std::size_t>(cols);
  work.resize(a.rows() * c);
  // A colour's band solves: about half the net's rows, each the band twice.
  const std::size_t solves = a.rows() * bytes_per_row(a.hu(), a.hv()) / sizeof(float) * c;
  std::size_t largest = 0;
  for (const Strip& s : strips_) largest = std::max(largest, s.size);
  std::vector<std::vector<double>> scratch(solves >= parallel_min_work ? max_threads() : 1, std::vector<double>(largest * c));
  // Along v first: its residuals are computed on every row (see residuals), which the
  // first pass from zero skips; along u, on half of them. A step of the multigrid then
  // reads the matrix 6 times instead of 6.5, in the same steps.
  constexpr int passes = 4;
  for (int n = 0; n < passes; ++n) {
    const int step = backward ? passes - 1 - n : n, dir = 1 - step / 2, colour = step % 2;
    std::vector<const Strip*> these;
    for (const Strip& s : strips_)
      if (s.dir == dir && s.ok && s.index % 2 == colour) these.push_back(&s);
    if (!(n == 0 && from_zero)) residuals(dir, colour, a, b, x, c, work);
    const std::span<const double> r = n == 0 && from_zero ? b : std::span<const double>(work);
    const auto count = static_cast<long long>(these.size());
#pragma omp parallel for schedule(dynamic, 1) if (solves >= parallel_min_work)
    for (long long k = 0; k < count; ++k)
      solve(*these[static_cast<std::size_t>(k)], r, x, c, scratch[static_cast<std::size_t>(thread_index())]);
  }
}

}  // namespace interpatch::detail::scattered
