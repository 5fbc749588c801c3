#include "constructions/scattered/scattered_system.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "base/kernel.hpp"
#include "base/parallel.hpp"

// NetMatrix: its forms (the upper half, whole rows, packed) and its products.

namespace interpatch::detail::scattered {

NetMatrix::NetMatrix(int nu, int nv, int hu, int hv)
    : nu_(nu), nv_(nv), hu_(hu), hv_(hv), width_(hv + 1 + hu * (2 * hv + 1)) {
  a_ = Values(rows() * static_cast<std::size_t>(width_));
  in_full_.resize(static_cast<std::size_t>(width_));
  for (int di = 0; di <= hu_; ++di)
    for (int dj = di == 0 ? 0 : -hv_; dj <= hv_; ++dj) in_full_[static_cast<std::size_t>(offset(di, dj))] = (di + hu_) * (2 * hv_ + 1) + dj + hv_;
}

void NetMatrix::mirror() {
  if (mirrored_ || stays_upper(hu_, hv_)) return;
  const int fw = (2 * hu_ + 1) * (2 * hv_ + 1);
  full_ = Values(rows() * static_cast<std::size_t>(fw));
  const std::size_t nv = static_cast<std::size_t>(nv_);
  for (int i = 0; i < nu_; ++i)
    for (int j = 0; j < nv_; ++j) {
      const std::size_t r = static_cast<std::size_t>(i) * nv + static_cast<std::size_t>(j);
      double* row = &full_[r * static_cast<std::size_t>(fw)];
      for (int di = -hu_; di <= hu_; ++di)
        for (int dj = -hv_; dj <= hv_; ++dj) {
          if (i + di < 0 || i + di >= nu_ || j + dj < 0 || j + dj >= nv_) continue;
          const bool upper = di > 0 || (di == 0 && dj >= 0);
          const std::size_t o = upper ? r : r - static_cast<std::size_t>(-di) * nv - static_cast<std::size_t>(-dj);
          row[(di + hu_) * (2 * hv_ + 1) + dj + hv_] = a_[o * static_cast<std::size_t>(width_) +
                                                           static_cast<std::size_t>(upper ? offset(di, dj) : offset(-di, -dj))];
        }
    }
  a_ = {};
  mirrored_ = true;
}

void NetMatrix::unmirror() {
  if (!mirrored_) return;
  const std::size_t w = static_cast<std::size_t>(width_), fw = full_width();
  a_ = Values(rows() * w);
  for (std::size_t r = 0; r < rows(); ++r)
    for (std::size_t k = 0; k < w; ++k) a_[r * w + k] = full_[r * fw + static_cast<std::size_t>(in_full_[k])];
  full_ = {};
  mirrored_ = false;
}

namespace {

// A packed row (NetMatrix::pack): each entry's nearest float, in the matrix's own
// memory, and apart from the floats each one's rest in steps of 2^(e - 38) as a 16-bit
// integer, e the binade of the row's largest float (kept after the rests): a rest is at
// most half a float's unit, 2^(e - 24), so at most 2^14 steps.
constexpr int rest_bits = 38;

// A packed cubic row: 25 floats, and 25 rests and the binade.
constexpr std::size_t packed_width = 25, rests_width = packed_width + 1;

inline double step_of(std::int16_t binade) {
  return std::bit_cast<double>(static_cast<std::uint64_t>(binade - rest_bits + 1023) << 52);
}

// A packed row of W entries (its floats `hi`, its rests and binade `rest`) into `out`,
// read where it lies (copied out first, the copies' stores and the wider loads after
// them stalled the product on every row). With Floats, the floats alone
// (NetMatrix::Part::floats).
template <std::size_t W, bool Floats = false>
inline void decode_row(const float* hi, const std::int16_t* rest, double* __restrict out) {
  if constexpr (Floats) {
    for (std::size_t k = 0; k < W; ++k) out[k] = static_cast<double>(hi[k]);
    return;
  }
  const double step = step_of(rest[W]);
  for (std::size_t k = 0; k < W; ++k) out[k] = static_cast<double>(hi[k]) + static_cast<double>(rest[k]) * step;
}

// How a product reads the entries: doubles, packed rows whole, or their floats alone.
enum class Form { doubles, packed, floats };

// Rows of 25 doubles packed (NetMatrix::pack) into consecutive packed rows, their floats
// into `to` and their rests into `rests`: how many before the first with an entry
// beyond 2^100 (far inside a float's range, so that every float and step is a normal
// number), `count` when none.
[[gnu::flatten]] INTERPATCH_KERNEL std::size_t pack_rows(const double* from, std::size_t count, float* to, std::int16_t* rests) {
  constexpr std::size_t w = 25;
  for (std::size_t r = 0; r < count; ++r) {
    const double* row = from + r * w;
    float hi[w];
    std::int16_t rest[w];
    float top = 0;
    bool in_range = true;
    for (std::size_t k = 0; k < w; ++k) {
      in_range = in_range && std::abs(row[k]) < 0x1p100;
      hi[k] = static_cast<float>(row[k]);
      top = std::max(top, std::abs(hi[k]));
    }
    if (!in_range) return r;
    const auto binade = static_cast<std::int16_t>(top > 0 ? std::ilogb(top) : 0);  // a row of zeros has no rest
    const double per_step = 1 / step_of(binade);  // a power of two: exact
    // At most 2^14 steps: lrint's nearest integer fits.
    for (std::size_t k = 0; k < w; ++k) rest[k] = static_cast<std::int16_t>(std::lrint((row[k] - static_cast<double>(hi[k])) * per_step));
    std::memcpy(to + r * w, hi, sizeof hi);
    std::memcpy(rests + r * rests_width, rest, sizeof rest);
    rests[r * rests_width + w] = binade;
  }
  return count;
}

}  // namespace

void NetMatrix::pack() {
  if (packed_ || mirrored_ || !stays_upper(hu_, hv_) || a_.empty()) return;
  constexpr std::size_t w = packed_width;  // the upper half of a cubic net's row
  auto* floats = reinterpret_cast<float*>(a_.data());
  // The rests apart, and the floats in place, in blocks of rows: a block packed on the
  // threads into `out`, then copied to floats 25 r, below the doubles 25 r of every row
  // not yet read. An entry out of range sends the rows packed so far back (its block is
  // still whole). The floats alone contiguous: the sweeps read them without the rests'
  // bytes between (a tenth less time than rows of both).
  constexpr std::size_t block = 8192, share = 1024;
  rests_.resize(rows() * rests_width);
  std::vector<float> out(std::min(block, rows()) * w);
  std::vector<std::size_t> done(block / share);
  for (std::size_t r0 = 0; r0 < rows(); r0 += block) {
    const std::size_t n = std::min(block, rows() - r0), shares = (n + share - 1) / share;
    parallel_for(shares, n * w >= parallel_min_work / 8, Share::blocks, [&](std::size_t t) {
      const std::size_t k0 = t * share, k = std::min(share, n - k0);
      done[t] = pack_rows(&a_[(r0 + k0) * w], k, out.data() + k0 * w, rests_.data() + (r0 + k0) * rests_width) == k ? k : 0;
    });
    for (std::size_t t = 0; t < shares; ++t)
      if (done[t] != std::min(share, n - t * share)) {
        unpack_rows(r0);
        Rests().swap(rests_);
        return;
      }
    std::memcpy(floats + r0 * w, out.data(), n * w * sizeof(float));
  }
  a_.let_go_after(rows() * w * sizeof(float));
  packed_ = true;
}

void NetMatrix::unpack() {
  if (!packed_) return;
  unpack_rows(rows());
  Rests().swap(rests_);
  packed_ = false;
}

void NetMatrix::unpack_rows(std::size_t count) {
  constexpr std::size_t w = packed_width;
  const auto* floats = reinterpret_cast<const float*>(a_.data());
  // Backwards: row r's doubles at 25 r lie at or past its floats at 25 r (in floats).
  for (std::size_t r = count; r-- > 0;) {
    double row[w];
    decode_row<w>(floats + r * w, rests_.data() + r * rests_width, row);
    std::memcpy(&a_[r * w], row, sizeof row);
  }
}

double NetMatrix::packed_at(std::size_t row, int k, Part part) const {
  const auto kk = static_cast<std::size_t>(k);
  const double hi = reinterpret_cast<const float*>(a_.data())[row * packed_width + kk];
  if (part == Part::floats) return hi;
  const std::int16_t* rest = rests_.data() + row * rests_width;
  return hi + static_cast<double>(rest[kk]) * step_of(rest[packed_width]);
}

void NetMatrix::upper_row(std::size_t row, double* out, Part part) const {
  if (packed_) {
    const float* hi = reinterpret_cast<const float*>(a_.data()) + row * packed_width;
    if (part == Part::floats) decode_row<packed_width, true>(hi, nullptr, out);
    else decode_row<packed_width>(hi, rests_.data() + row * rests_width, out);
    return;
  }
  for (int k = 0; k < width_; ++k) out[k] = at(row, k, part);
}

void NetMatrix::row_product(int i, int j, std::span<const double> x, std::size_t c, double* acc) const {
  const std::size_t nv = static_cast<std::size_t>(nv_);
  const std::size_t r = static_cast<std::size_t>(i) * nv + static_cast<std::size_t>(j);
  for (std::size_t k = 0; k < c; ++k) acc[k] = 0;
  if (mirrored_ && i >= hu_ && i + hu_ < nu_ && j >= hv_ && j + hv_ < nv_) {
    // Inside the net: the whole row, one contiguous stretch of x per di.
    const std::size_t w = static_cast<std::size_t>(2 * hv_ + 1);
    const double* row = &full_[r * w * static_cast<std::size_t>(2 * hu_ + 1)];
    const double* xs = &x[(r - static_cast<std::size_t>(hu_) * nv - static_cast<std::size_t>(hv_)) * c];
    for (int di = -hu_; di <= hu_; ++di, row += w, xs += nv * c)
      for (std::size_t k = 0; k < w; ++k)
        for (std::size_t m = 0; m < c; ++m) acc[m] += row[k] * xs[k * c + m];
    return;
  }
  for (int di = 0; di <= hu_; ++di) {
    // The upper half of row r, and row r's entries kept by the rows above it.
    const int jlo = std::max(di == 0 ? 0 : -hv_, -j), jhi = std::min(hv_, nv_ - 1 - j);
    if (i + di < nu_)
      for (int dj = jlo; dj <= jhi; ++dj) {
        const double a = at(r, offset(di, dj));
        const std::size_t s = (r + static_cast<std::size_t>(di) * nv + static_cast<std::size_t>(dj)) * c;
        for (std::size_t k = 0; k < c; ++k) acc[k] += a * x[s + k];
      }
    if (i - di < 0) continue;
    const int klo = std::max(di == 0 ? 1 : -hv_, j - (nv_ - 1)), khi = std::min(hv_, j);
    for (int dj = klo; dj <= khi; ++dj) {
      const std::size_t o = r - static_cast<std::size_t>(di) * nv - static_cast<std::size_t>(dj);
      const double a = at(o, offset(di, dj));
      for (std::size_t k = 0; k < c; ++k) acc[k] += a * x[o * c + k];
    }
  }
}

namespace {

// Four doubles as one value: the AVX2 clone keeps them in one register, the baseline in
// two. Handed between functions through references: a vector passed by value without
// AVX changes the ABI (GCC warns), even between functions inlined into one kernel.
using v4 = double __attribute__((vector_size(32)));

[[gnu::always_inline]] inline void load4(const double* p, v4& v) { std::memcpy(&v, p, sizeof v); }

// Entries k .. k + 3 of a cubic net's row r (k + 3 < 25), and k .. k + 2 with a zero,
// after row(r). A packed row is decoded whole first, in vectors (decoded as asked for,
// a product took a third longer); its floats alone are read straight from its bytes
// (through a row of doubles, the reads of four that straddle two of its stores waited
// for both: a third longer too), one by one into a vector (a vector of four floats
// converted whole went through the stack a half at a time: 7 % longer).
template <Form F>
struct RowEntries {
  const double* a;
  const float* floats;
  const std::int16_t* rests;
  double decoded[28] = {};
  const double* at = nullptr;
  const float* p = nullptr;
  [[gnu::always_inline]] void row(std::size_t r) {
    if constexpr (F == Form::doubles) {
      at = a + r * 25;
    } else if constexpr (F == Form::packed) {
      decode_row<packed_width>(floats + r * packed_width, rests + r * rests_width, decoded);
      at = decoded;
    } else {
      p = floats + r * packed_width;
    }
  }
  [[gnu::always_inline]] void four(std::size_t k, v4& v) const {
    if constexpr (F == Form::floats) {
      v = v4{static_cast<double>(p[k]), static_cast<double>(p[k + 1]), static_cast<double>(p[k + 2]), static_cast<double>(p[k + 3])};
    } else {
      load4(at + k, v);
    }
  }
  // The floats of a packed row are followed by 4 bytes more (the next row's, or past the
  // last row those of the doubles' memory the floats took half of); past the doubles'
  // last row there is nothing.
  [[gnu::always_inline]] void three(std::size_t k, v4& v) const {
    if constexpr (F == Form::floats) {
      four(k, v);
      v = __builtin_shufflevector(v, v4{}, 0, 1, 2, 4);
    } else {
      v = v4{at[k], at[k + 1], at[k + 2], 0.0};
    }
  }
};

// One net row's control points j in [j0, j1) of a one-column product, far enough from
// the sides that every (di, dj) is inside the net and the reads of dj = 4 too, in
// vectors of four. The shares of the rows below and to the right are summed in
// registers, a window of 7 places a direction that moves one place a point, each place
// written to y once complete. Scattered point by point, each sum waited on the store
// of the point before: a product on a 512² net took 3.1 ms against 2.1.
template <Form F>
[[gnu::always_inline]] inline void band_run_1(RowEntries<F>& e, std::size_t snv, int i, int j0, int j1, bool own, int dlo,
                                              int dhi, int into, const double* x, double* y) {
  constexpr int H = 3;
  const v4 zero{};
  v4 w0 = zero, wlo[H + 1] = {}, whi[H + 1] = {};
  for (int j = j0; j < j1; ++j) {
    const std::size_t r = static_cast<std::size_t>(i) * snv + static_cast<std::size_t>(j);
    const double xr = x[r];
    const v4 xv = {xr, xr, xr, xr};
    v4 ea[H + 1] = {}, eb[H + 1] = {}, e0, xa, xb;
    e.row(r);
    e.four(0, e0);
#pragma GCC unroll 3
    for (int d = 1; d <= H; ++d) {
      const auto at = static_cast<std::size_t>(H + 1 + (d - 1) * (2 * H + 1));  // offset (d, -H)
      e.four(at, ea[d]);
      e.three(at + 4, eb[d]);
    }
    const bool first = j == j0;
    if (own) {
      v4 acc;
      load4(x + r, xa);
      acc = e0 * xa;
#pragma GCC unroll 3
      for (int d = 1; d <= H; ++d) {
        if (d > dhi) continue;
        const std::size_t below = r + static_cast<std::size_t>(d) * snv;
        load4(x + below - H, xa);
        load4(x + below + 1, xb);
        acc += ea[d] * xa + eb[d] * xb;
      }
      const double pending = first ? 0.0 : w0[0];  // row r's share from the points to its left
      w0 = __builtin_shufflevector(w0, zero, 1, 2, 4, 4) + __builtin_shufflevector(e0, zero, 1, 2, 3, 4) * xv;
      y[r] += ((acc[0] + acc[1]) + (acc[2] + acc[3])) + pending;
    }
#pragma GCC unroll 3
    for (int d = 1; d <= H; ++d) {  // unrolled, so that the windows stay in registers
      if (d < dlo || d > into) continue;
      const std::size_t left = r + static_cast<std::size_t>(d) * snv - H;  // the window's first place
      if (!first) y[left - 1] += wlo[d][0];
      wlo[d] = __builtin_shufflevector(wlo[d], whi[d], 1, 2, 3, 4) + ea[d] * xv;
      whi[d] = __builtin_shufflevector(whi[d], zero, 1, 2, 4, 4) + eb[d] * xv;
    }
  }
  if (j1 <= j0) return;
  const std::size_t r = static_cast<std::size_t>(i) * snv + static_cast<std::size_t>(j1 - 1);
  if (own)
    for (std::size_t k = 0; k < 3; ++k) y[r + 1 + k] += w0[k];
  for (int d = dlo; d <= into; ++d) {
    const std::size_t left = r + static_cast<std::size_t>(d) * snv - H;
    for (std::size_t k = 0; k < 4; ++k) y[left + k] += wlo[d][k];
    for (std::size_t k = 0; k < 3; ++k) y[left + 4 + k] += whi[d][k];
  }
}

// Net rows [i0, i1) of A x from the upper half alone, row by row in memory order: each
// row's own entries times x (its upper half) and, into the rows below it, the same
// entries times its x (their lower half, A being symmetric). The hu rows above the band
// add their share too. Every entry is read once and as a contiguous stretch, where
// gathering the lower half from the rows above read it with a stride: a quarter less
// time a product on a 512² net. Whole rows (mirror()) took as long as that gather with
// twice the memory.
template <int H, int C, Form F>
void upper_band(const void* entries, const std::int16_t* rests, int nu, int nv, int i0, int i1, const double* x, double* y) {
  constexpr int W = H + 1 + H * (2 * H + 1), L = 2 * H + 1;
  const auto* a = static_cast<const double*>(entries);
  const auto* floats = static_cast<const float*>(entries);
  double decoded_row[W];
  const auto snv = static_cast<std::size_t>(nv);
  std::fill(y + static_cast<std::size_t>(i0) * snv * C, y + static_cast<std::size_t>(i1) * snv * C, 0.0);
  for (int i = std::max(0, i0 - H); i < i1; ++i) {
    const bool own = i >= i0;
    const int dlo = own ? 1 : i0 - i, dhi = std::min(H, nu - 1 - i), into = std::min(dhi, i1 - 1 - i);
    // One control point; Edge: columns near the net's sides, where some dj fall outside.
    const auto point = [&]<bool Edge>(int j) {
      const std::size_t r = static_cast<std::size_t>(i) * snv + static_cast<std::size_t>(j);
      const double* row = a + r * W;
      if constexpr (F != Form::doubles) {
        decode_row<W, F == Form::floats>(floats + r * W, rests + r * (W + 1), decoded_row);
        row = decoded_row;
      }
      double xr[C], acc[C] = {};
      for (int m = 0; m < C; ++m) xr[m] = x[r * C + m];
      const int elo = Edge ? std::max(-H, -j) : -H, ehi = Edge ? std::min(H, nv - 1 - j) : H;
      if (own) {
        for (int m = 0; m < C; ++m) acc[m] = row[0] * xr[m];
        for (int dj = 1; dj <= ehi; ++dj)
          for (int m = 0; m < C; ++m) {
            acc[m] += row[dj] * x[(r + dj) * C + m];
            y[(r + dj) * C + m] += row[dj] * xr[m];
          }
      }
      for (int di = dlo; di <= dhi; ++di) {
        const double* rk = row + H + 1 + (di - 1) * L + H;  // rk[dj]: offset (di, dj)
        const std::size_t base = r + static_cast<std::size_t>(di) * snv;
        if (own)
          for (int dj = elo; dj <= ehi; ++dj)
            for (int m = 0; m < C; ++m) acc[m] += rk[dj] * x[(base + dj) * C + m];
        if (di <= into)
          for (int dj = elo; dj <= ehi; ++dj)
            for (int m = 0; m < C; ++m) y[(base + dj) * C + m] += rk[dj] * xr[m];
      }
      if (own)
        for (int m = 0; m < C; ++m) y[r * C + m] += acc[m];
    };
    const int lo = std::min(H, nv), hi = std::max(lo, nv - H);
    for (int j = 0; j < lo; ++j) point.template operator()<true>(j);
    int from = lo;
    if constexpr (C == 1 && H == 3) {
      from = std::max(lo, nv - H - 1);  // the run reads dj = 4 too
      RowEntries<F> rows{a, floats, rests};
      band_run_1<F>(rows, snv, i, lo, from, own, dlo, dhi, into, x, y);
    }
    for (int j = from; j < hi; ++j) point.template operator()<false>(j);
    for (int j = hi; j < nv; ++j) point.template operator()<true>(j);
  }
}

// The kernels, cloned for AVX2 (vectors of four doubles in one register).
[[gnu::flatten]] INTERPATCH_KERNEL void packed_band_1(const void* e, const std::int16_t* rests, int nu, int nv, int i0, int i1, const double* x, double* y) {
  upper_band<3, 1, Form::packed>(e, rests, nu, nv, i0, i1, x, y);
}
[[gnu::flatten]] INTERPATCH_KERNEL void packed_band_3(const void* e, const std::int16_t* rests, int nu, int nv, int i0, int i1, const double* x, double* y) {
  upper_band<3, 3, Form::packed>(e, rests, nu, nv, i0, i1, x, y);
}
[[gnu::flatten]] INTERPATCH_KERNEL void floats_band_1(const void* e, const std::int16_t* rests, int nu, int nv, int i0, int i1, const double* x, double* y) {
  upper_band<3, 1, Form::floats>(e, rests, nu, nv, i0, i1, x, y);
}
[[gnu::flatten]] INTERPATCH_KERNEL void floats_band_3(const void* e, const std::int16_t* rests, int nu, int nv, int i0, int i1, const double* x, double* y) {
  upper_band<3, 3, Form::floats>(e, rests, nu, nv, i0, i1, x, y);
}
[[gnu::flatten]] INTERPATCH_KERNEL void double_band_1(const void* e, const std::int16_t* rests, int nu, int nv, int i0, int i1, const double* x, double* y) {
  upper_band<3, 1, Form::doubles>(e, rests, nu, nv, i0, i1, x, y);
}

}  // namespace

void NetMatrix::multiply_rows(int i0, int i1, std::span<const double> x, std::span<double> y, int cols, Part part) const {
  const std::size_t c = static_cast<std::size_t>(cols), nv = static_cast<std::size_t>(nv_);
  if (packed_ && part == Part::floats) {
    if (c == 1) return floats_band_1(a_.data(), rests_.data(), nu_, nv_, i0, i1, x.data(), y.data());
    if (c == 3) return floats_band_3(a_.data(), rests_.data(), nu_, nv_, i0, i1, x.data(), y.data());
  }
  if (packed_) {
    if (c == 1) return packed_band_1(a_.data(), rests_.data(), nu_, nv_, i0, i1, x.data(), y.data());
    if (c == 3) return packed_band_3(a_.data(), rests_.data(), nu_, nv_, i0, i1, x.data(), y.data());
  }
  if (!mirrored_ && !packed_ && stays_upper(hu_, hv_) && (c == 1 || c == 3)) {
    if (c == 1) return double_band_1(a_.data(), rests_.data(), nu_, nv_, i0, i1, x.data(), y.data());
    return upper_band<3, 3, Form::doubles>(a_.data(), nullptr, nu_, nv_, i0, i1, x.data(), y.data());
  }
  for (int i = i0; i < i1; ++i)
    for (int j = 0; j < nv_; ++j) {
      const std::size_t r = static_cast<std::size_t>(i) * nv + static_cast<std::size_t>(j);
      double acc[3];
      row_product(i, j, x, c, acc);
      for (std::size_t k = 0; k < c; ++k) y[r * c + k] = acc[k];
    }
}

void NetMatrix::multiply(std::span<const double> x, std::span<double> y, int cols, Part part) const {
  const bool parallel = rows() * static_cast<std::size_t>(2 * width_) * static_cast<std::size_t>(cols) >= parallel_min_work;
  const int bands = (nu_ + band_rows - 1) / band_rows;
#pragma omp parallel for schedule(static) if (parallel)
  for (int b = 0; b < bands; ++b) multiply_rows(b * band_rows, std::min(nu_, (b + 1) * band_rows), x, y, cols, part);
}

void NetMatrix::assign_sum(const NetMatrix& d, const NetMatrix& f, double s) {
  if (mirrored_ || packed_) {
    full_ = {};
    a_ = Values(rows() * static_cast<std::size_t>(width_));
    Rests().swap(rests_);
    mirrored_ = packed_ = false;
  }
  const std::size_t w = static_cast<std::size_t>(width_);
  for (std::size_t r = 0; r < rows(); ++r)
    for (std::size_t k = 0; k < w; ++k) a_[r * w + k] = d.at(r, static_cast<int>(k)) + s * f.at(r, static_cast<int>(k));
}

void NetMatrix::scale(double s) {
  make_writable();
  for (double& v : a_) v *= s;
}

}  // namespace interpatch::detail::scattered
