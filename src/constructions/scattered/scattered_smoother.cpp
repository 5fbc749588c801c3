#include "constructions/scattered/scattered_smoother.hpp"

#include <algorithm>
#include <cmath>

#include "base/parallel.hpp"

namespace interpatch::detail::scattered {

namespace {

// Strips as wide as the matrix reaches plus one: strips two apart share no entry, so two
// colours suffice, and a strip holds every coupling of a control point to its
// neighbours across it.
int strip_width(const NetMatrix& a) { return std::max(a.hu(), a.hv()) + 1; }

}  // namespace

std::size_t StripSmoother::bytes_per_row(int hu, int hv) {
  // A strip of width w along one direction has half bandwidth h w + w - 1 across the
  // other's reach h: w (h + 1) numbers a row (the band and the inverse diagonal).
  const std::size_t w = static_cast<std::size_t>(std::max(hu, hv) + 1);
  return sizeof(double) * w * (static_cast<std::size_t>(hu) + static_cast<std::size_t>(hv) + 2);
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
      s.band = reach * s.width + s.width - 1;
      s.size = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(along);
      s.at = at;
      at += s.size * static_cast<std::size_t>(s.band + 1);
      strips_.push_back(s);
    }
  }
  factor_.assign(at, 0.0);
  const auto count = static_cast<long long>(strips_.size());
  // Each row of a band b costs about b² / 2 multiply-adds to factor.
  const auto band = static_cast<std::size_t>(std::max(a.hu(), a.hv()) * w + w);
  const bool parallel = a.rows() * band * band >= parallel_min_work;
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (long long k = 0; k < count; ++k) factor(a, strips_[static_cast<std::size_t>(k)]);
}

std::size_t StripSmoother::row_of(const Strip& s, std::size_t k) const {
  const auto w = static_cast<std::size_t>(s.width);
  const std::size_t along = k / w, across = static_cast<std::size_t>(s.first) + k % w;
  return s.dir == 0 ? across * static_cast<std::size_t>(nv_) + along : along * static_cast<std::size_t>(nv_) + across;
}

void StripSmoother::factor(const NetMatrix& a, Strip& s) {
  // Band Cholesky by rows: L[k][j] = (A[k][j] - Σ_i L[k][i] L[j][i]) / L[j][j].
  const auto band = static_cast<std::size_t>(s.band), stride = band + 1;
  double* f = &factor_[s.at];
  for (std::size_t k = 0; k < s.size; ++k) {
    const std::size_t j0 = k > band ? k - band : 0;
    double* lk = f + k * stride;  // lk[band - (k - j)] = L[k][j]
    const std::size_t rk = row_of(s, k);
    const int ik = static_cast<int>(rk / static_cast<std::size_t>(nv_)), jk = static_cast<int>(rk % static_cast<std::size_t>(nv_));
    for (std::size_t j = j0; j <= k; ++j) {
      const std::size_t rj = row_of(s, j);
      const int di = static_cast<int>(rj / static_cast<std::size_t>(nv_)) - ik, dj = static_cast<int>(rj % static_cast<std::size_t>(nv_)) - jk;
      double sum = std::abs(di) <= a.hu() && std::abs(dj) <= a.hv() ? a.entry(rk, di, dj) : 0.0;
      const double* lj = f + j * stride;
      const std::size_t i0 = std::max(j0, j > band ? j - band : 0);
      for (std::size_t i = i0; i < j; ++i) sum -= lk[band - (k - i)] * lj[band - (j - i)];
      if (j < k) {
        lk[band - (k - j)] = sum * lj[band];
      } else {
        if (!(sum > 0)) return;  // s.ok stays false
        lk[band] = 1 / std::sqrt(sum);
      }
    }
  }
  s.ok = true;
}

void StripSmoother::solve(const Strip& s, const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols,
                          std::vector<double>& r) const {
  const auto c = static_cast<std::size_t>(cols), band = static_cast<std::size_t>(s.band), stride = band + 1;
  const double* f = &factor_[s.at];
  for_each_row(s, [&](std::size_t k, int i, int j, std::size_t row) {
    double acc[3];
    a.row_product(i, j, x, c, acc);
    for (std::size_t m = 0; m < c; ++m) r[k * c + m] = b[row * c + m] - acc[m];
  });
  // L y = r, then Lᵀ z = y, in place.
  for (std::size_t k = 0; k < s.size; ++k) {
    const double* lk = f + k * stride;
    const std::size_t i0 = k > band ? k - band : 0;
    for (std::size_t m = 0; m < c; ++m) {
      double sum = r[k * c + m];
      for (std::size_t i = i0; i < k; ++i) sum -= lk[band - (k - i)] * r[i * c + m];
      r[k * c + m] = sum * lk[band];
    }
  }
  for (std::size_t k = s.size; k-- > 0;) {
    const double* lk = f + k * stride;
    const std::size_t i0 = k > band ? k - band : 0;
    for (std::size_t m = 0; m < c; ++m) {
      const double z = r[k * c + m] * lk[band];
      r[k * c + m] = z;
      for (std::size_t i = i0; i < k; ++i) r[i * c + m] -= lk[band - (k - i)] * z;
    }
  }
  for_each_row(s, [&](std::size_t k, int, int, std::size_t row) {
    for (std::size_t m = 0; m < c; ++m) x[row * c + m] += r[k * c + m];
  });
}

void StripSmoother::sweep(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols, bool backward) const {
  const std::size_t c = static_cast<std::size_t>(cols);
  std::size_t largest = 0;
  for (const Strip& s : strips_) largest = std::max(largest, s.size);
  // A colour's work: about half the net's rows, each a row of the matrix and the band.
  const std::size_t work = a.rows() / 2 * (static_cast<std::size_t>((2 * a.hu() + 1) * (2 * a.hv() + 1)) + bytes_per_row(a.hu(), a.hv()) / sizeof(double)) * c;
  const bool parallel = work >= parallel_min_work;
  std::vector<std::vector<double>> scratch(parallel ? max_threads() : 1, std::vector<double>(largest * c));
  for (int n = 0; n < 4; ++n) {
    const int step = backward ? 3 - n : n, dir = step / 2, colour = step % 2;
    std::vector<const Strip*> these;
    for (const Strip& s : strips_)
      if (s.dir == dir && s.ok && s.index % 2 == colour) these.push_back(&s);
    const auto count = static_cast<long long>(these.size());
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (long long k = 0; k < count; ++k)
      solve(*these[static_cast<std::size_t>(k)], a, b, x, cols, scratch[static_cast<std::size_t>(thread_index())]);
  }
}

}  // namespace interpatch::detail::scattered
