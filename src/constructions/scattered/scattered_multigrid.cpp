#include "constructions/scattered/scattered_multigrid.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "base/kernel.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"

namespace interpatch::detail::scattered {

namespace {

// Fine point i of the coarse spline by blossoming: the coarse polynomial piece on the
// span holding fine knot i, blossomed at the fine knots i + 1 .. i + p (de Boor's
// recurrence with a new argument at each level), kept as weights of the p + 1 coarse
// points.
void blossom_row(const KnotVector& t, const KnotVector& tau, int i, int& first, double* w) {
  const int p = t.degree();
  const int mu = t.find_span(tau[static_cast<std::size_t>(i)]);
  double c[max_degree + 1][max_degree + 1] = {};
  for (int a = 0; a <= p; ++a) c[a][a] = 1;  // c[a]: coarse point mu - p + a, as weights
  for (int r = 1; r <= p; ++r) {
    const double x = tau[static_cast<std::size_t>(i + r)];
    for (int j = mu; j >= mu - p + r; --j) {
      const double lo = t[static_cast<std::size_t>(j)], hi = t[static_cast<std::size_t>(j + p + 1 - r)];
      const double alpha = (x - lo) / (hi - lo);
      const int a = j - (mu - p);
      for (int k = 0; k <= p; ++k) c[a][k] = alpha * c[a][k] + (1 - alpha) * c[a - 1][k];
    }
  }
  first = mu - p;
  for (int k = 0; k <= p; ++k) w[k] = c[p][k];
}

}  // namespace

Refinement refinement(const KnotVector& coarse, const KnotVector& fine) {
  if (!nests(coarse, fine))
    fail(errc::internal, "scattered multigrid: a coarse net's knots (", coarse.count(), " control points) are not knots of the finer net's (",
         fine.count(), ")");
  Refinement r;
  r.p = coarse.degree(), r.fine = fine.count(), r.coarse = coarse.count();
  const std::size_t width = static_cast<std::size_t>(r.p + 1);
  r.first.assign(static_cast<std::size_t>(r.fine), 0);
  r.weight.assign(static_cast<std::size_t>(r.fine) * width, 0.0);
  for (int i = 0; i < r.fine; ++i) {
    double* w = &r.weight[static_cast<std::size_t>(i) * width];
    int& first = r.first[static_cast<std::size_t>(i)];
    if (r.fine == r.coarse) {
      first = std::min(i, r.coarse - r.p - 1);
      w[i - first] = 1;
    } else {
      blossom_row(coarse, fine, i, first, w);
    }
  }
  // The transpose, gathered per coarse point in increasing fine order.
  r.t_start.assign(static_cast<std::size_t>(r.coarse) + 1, 0);
  for (int i = 0; i < r.fine; ++i)
    for (std::size_t a = 0; a < width; ++a)
      if (r.weight[static_cast<std::size_t>(i) * width + a] != 0)
        ++r.t_start[static_cast<std::size_t>(r.first[static_cast<std::size_t>(i)]) + a + 1];
  for (std::size_t a = 0; a < static_cast<std::size_t>(r.coarse); ++a) r.t_start[a + 1] += r.t_start[a];
  r.t_index.resize(r.t_start.back());
  r.t_weight.resize(r.t_start.back());
  std::vector<std::size_t> next(r.t_start.begin(), r.t_start.end() - 1);
  for (int i = 0; i < r.fine; ++i)
    for (std::size_t a = 0; a < width; ++a) {
      const double w = r.weight[static_cast<std::size_t>(i) * width + a];
      if (w == 0) continue;
      const std::size_t row = static_cast<std::size_t>(r.first[static_cast<std::size_t>(i)]) + a;
      r.t_index[next[row]] = i;
      r.t_weight[next[row]++] = w;
    }
  return r;
}

bool nests(const KnotVector& coarse, const KnotVector& fine) {
  return coarse.degree() == fine.degree() &&
         std::includes(fine.values().begin(), fine.values().end(), coarse.values().begin(), coarse.values().end());
}

System restrict_between(const System& fine_term, const Net& fine, const Net& coarse) {
  return restrict_system(fine_term, {refinement(coarse.ku, fine.ku), refinement(coarse.kv, fine.kv)});
}

std::vector<System> restrict_down(const System& top, const Net& top_net, std::span<const Net> nets) {
  std::vector<System> out;  // finest first while made
  out.reserve(nets.size());
  for (std::size_t l = nets.size(); l-- > 0;)
    out.push_back(restrict_between(out.empty() ? top : out.back(), l + 1 < nets.size() ? nets[l + 1] : top_net, nets[l]));
  std::reverse(out.begin(), out.end());
  return out;
}

std::vector<Net> hierarchy(const Net& top, std::size_t coarsest) {
  std::vector<Net> out{top};
  while (out.back().size() > coarsest && (out.back().nu - top.p > 4 || out.back().nv - top.q > 4)) out.push_back(Net::coarser(out.back()));
  std::reverse(out.begin(), out.end());
  return out;
}

namespace {

// x_f += P x_c: a coarse net's values (cols per control point) refined onto the fine net.
void prolong(const std::array<Refinement, 2>& r, std::span<const double> coarse, std::span<double> fine, int cols,
             std::vector<double>& tmp) {
  const Refinement &ru = r[0], &rv = r[1];
  const std::size_t c = static_cast<std::size_t>(cols), wu = static_cast<std::size_t>(ru.p + 1), wv = static_cast<std::size_t>(rv.p + 1);
  const std::size_t cu = static_cast<std::size_t>(ru.coarse), cv = static_cast<std::size_t>(rv.coarse);
  const std::size_t fu = static_cast<std::size_t>(ru.fine), fv = static_cast<std::size_t>(rv.fine);
  tmp.assign(cu * fv * c, 0.0);
  const bool parallel = fu * fv * c * (wu + wv) >= parallel_min_work;
#pragma omp parallel for schedule(static) if (parallel)
  for (long long a = 0; a < static_cast<long long>(cu); ++a)
    for (std::size_t j = 0; j < fv; ++j) {
      const std::size_t b0 = static_cast<std::size_t>(rv.first[j]);
      for (std::size_t b = 0; b < wv; ++b) {
        const double w = rv.weight[j * wv + b];
        if (w == 0) continue;
        const std::size_t from = (static_cast<std::size_t>(a) * cv + b0 + b) * c, to = (static_cast<std::size_t>(a) * fv + j) * c;
        for (std::size_t k = 0; k < c; ++k) tmp[to + k] += w * coarse[from + k];
      }
    }
#pragma omp parallel for schedule(static) if (parallel)
  for (long long i = 0; i < static_cast<long long>(fu); ++i) {
    const std::size_t ii = static_cast<std::size_t>(i), a0 = static_cast<std::size_t>(ru.first[ii]);
    for (std::size_t a = 0; a < wu; ++a) {
      const double w = ru.weight[ii * wu + a];
      if (w == 0) continue;
      for (std::size_t j = 0; j < fv * c; ++j) fine[ii * fv * c + j] += w * tmp[(a0 + a) * fv * c + j];
    }
  }
}

// b_c = Pᵀ r_f, each coarse value gathered from the fine ones in a fixed order.
void restrict_to(const std::array<Refinement, 2>& r, std::span<const double> fine, std::span<double> coarse, int cols,
                 std::vector<double>& tmp) {
  const Refinement &ru = r[0], &rv = r[1];
  const std::size_t c = static_cast<std::size_t>(cols);
  const std::size_t cu = static_cast<std::size_t>(ru.coarse), cv = static_cast<std::size_t>(rv.coarse);
  const std::size_t fu = static_cast<std::size_t>(ru.fine), fv = static_cast<std::size_t>(rv.fine);
  tmp.assign(fu * cv * c, 0.0);
  const bool parallel = fu * fv * c * 8 >= parallel_min_work;
#pragma omp parallel for schedule(static) if (parallel)
  for (long long i = 0; i < static_cast<long long>(fu); ++i)
    for (std::size_t b = 0; b < cv; ++b)
      for (std::size_t e = rv.t_start[b]; e < rv.t_start[b + 1]; ++e) {
        const double w = rv.t_weight[e];
        const std::size_t from = (static_cast<std::size_t>(i) * fv + static_cast<std::size_t>(rv.t_index[e])) * c;
        const std::size_t to = (static_cast<std::size_t>(i) * cv + b) * c;
        for (std::size_t k = 0; k < c; ++k) tmp[to + k] += w * fine[from + k];
      }
#pragma omp parallel for schedule(static) if (parallel)
  for (long long a = 0; a < static_cast<long long>(cu); ++a) {
    const std::size_t aa = static_cast<std::size_t>(a);
    std::fill(coarse.begin() + static_cast<std::ptrdiff_t>(aa * cv * c), coarse.begin() + static_cast<std::ptrdiff_t>((aa + 1) * cv * c), 0.0);
    for (std::size_t e = ru.t_start[aa]; e < ru.t_start[aa + 1]; ++e) {
      const double w = ru.t_weight[e];
      const std::size_t from = static_cast<std::size_t>(ru.t_index[e]) * cv * c;
      for (std::size_t j = 0; j < cv * c; ++j) coarse[aa * cv * c + j] += w * tmp[from + j];
    }
  }
}

// For each fine column j, the weights that take the entries of a row (i, j) with its
// neighbours (·, j + dj) to the coarse functions b' those neighbours refine: zlo[j] the
// first such b', w[(j · (2hv + 1) + dj + hv) · width + b' - zlo[j]] = Pv[j + dj][b']
// (zero where j + dj does not refine b' or falls outside). The same for every fine row
// and every di: made once.
struct Gather {
  std::vector<int> zlo, count;
  std::vector<double> w;
  std::size_t width = 0;
  // width: the coarse functions a row's neighbours refine at most, rounded up to whole
  // vectors of four (zeros past them).
  Gather(const Refinement& rv, int hv) : width(static_cast<std::size_t>(2 * hv + rv.p + 2 + 3) / 4 * 4) {
    const auto fv = static_cast<std::size_t>(rv.fine), pv = static_cast<std::size_t>(rv.p + 1), wv = static_cast<std::size_t>(2 * hv + 1);
    zlo.resize(fv), count.resize(fv);
    w.assign(fv * wv * width, 0.0);
    for (std::size_t j = 0; j < fv; ++j) {
      const int jlo = std::max(-hv, -static_cast<int>(j)), jhi = std::min(hv, static_cast<int>(fv - 1 - j));
      zlo[j] = rv.first[static_cast<std::size_t>(static_cast<int>(j) + jlo)];
      count[j] = rv.first[static_cast<std::size_t>(static_cast<int>(j) + jhi)] + rv.p + 1 - zlo[j];
      for (int dj = jlo; dj <= jhi; ++dj) {
        const auto j2 = static_cast<std::size_t>(static_cast<int>(j) + dj);
        double* to = &w[(j * wv + static_cast<std::size_t>(dj + hv)) * width + static_cast<std::size_t>(rv.first[j2] - zlo[j])];
        for (std::size_t e2 = 0; e2 < pv; ++e2) to[e2] = rv.weight[j2 * pv + e2];
      }
    }
  }
};

// restrict_system's pass along v over fine row i (v refined by rv):
// t[b][(di, db)] = Σ_j Σ_j' Pv[j][b] A[(i, j)][(i + di, j')] Pv[j'][b + db], both halves,
// in a fixed order: first z = the row's entries times Pv (the coarse functions b' that
// (i, j)'s neighbours refine, from zlo on; each z a sum over the neighbours held in a
// register, where adding each neighbour's share into z in memory waited on the last
// store), then Pv[j][b] z into t (about half the products of both at once); tb likewise
// for the right-hand sides. Without `matrix`, tb alone (restrict_row_cubic makes t).
void restrict_row_along_v(const System& fine, const Refinement& rv, const Gather& gather, std::size_t i, double* t, double* tb,
                          std::vector<double>& z, bool matrix) {
  const NetMatrix& a = fine.a;
  const int hu = a.hu(), hv = a.hv(), wu = 2 * hu + 1, wv = 2 * hv + 1;
  const auto c = static_cast<std::size_t>(fine.cols), band = static_cast<std::size_t>(wu * wv);
  const auto fu = static_cast<std::size_t>(a.nu()), fv = static_cast<std::size_t>(rv.fine), cv = static_cast<std::size_t>(rv.coarse);
  const auto pv = static_cast<std::size_t>(rv.p + 1);
  if (matrix) std::fill(t, t + cv * band, 0.0);
  std::fill(tb, tb + cv * c, 0.0);
  for (std::size_t j = 0; j < fv; ++j) {
    const std::size_t row = i * fv + j;
    const double* wj = &rv.weight[j * pv];
    const int fj = rv.first[j];
    for (std::size_t e = 0; e < pv; ++e) {
      const std::size_t b = static_cast<std::size_t>(fj) + e;
      for (std::size_t m = 0; m < c && wj[e] != 0; ++m) tb[b * c + m] += wj[e] * fine.rhs[row * c + m];
    }
    if (!matrix) continue;
    const int jlo = std::max(-hv, -static_cast<int>(j)), jhi = std::min(hv, static_cast<int>(fv - 1 - j));
    const int zlo = gather.zlo[j], zhi = zlo + gather.count[j] - 1;
    const auto zn = static_cast<std::size_t>(gather.count[j]);
    const double* gw = &gather.w[j * static_cast<std::size_t>(wv) * gather.width];
    double v[2 * max_degree + 1];
    for (int di = -hu; di <= hu; ++di) {
      if (static_cast<long long>(i) + di < 0 || static_cast<long long>(i) + di >= static_cast<long long>(fu)) continue;
      bool any = false;
      for (int dj = -hv; dj <= hv; ++dj) {
        v[dj + hv] = dj >= jlo && dj <= jhi ? a.entry(row, di, dj) : 0.0;
        any = any || v[dj + hv] != 0;
      }
      if (!any) continue;
      for (std::size_t k = 0; k < zn; ++k) {
        double sum = 0;
        for (int d = 0; d < wv; ++d) sum += v[d] * gw[static_cast<std::size_t>(d) * gather.width + k];
        z[k] = sum;
      }
      for (std::size_t e = 0; e < pv; ++e) {
        if (wj[e] == 0) continue;
        const int b = fj + static_cast<int>(e);
        // Coarse functions more than hv apart: zero (the header says why).
        const int lo = std::max(zlo, b - hv), hi = std::min(zhi, b + hv);
        double* to = &t[(static_cast<std::size_t>(b) * static_cast<std::size_t>(wu) + static_cast<std::size_t>(di + hu)) * static_cast<std::size_t>(wv) +
                        static_cast<std::size_t>(hv - b)];
        for (int bb = lo; bb <= hi; ++bb) to[bb] += wj[e] * z[static_cast<std::size_t>(bb - zlo)];
      }
    }
  }
}

// restrict_row_along_v for a cubic net's matrix in the upper form (reach 3, 4 weights a
// fine point, the gather 12 wide): the same sums in the same order, the seven rows di
// at once and in vectors, each entry read straight from its row (where entry() and
// loops as long as each point's share took three times as long). t's rows di are 8
// places apart (the last one unused), so that each takes two whole vectors.
[[gnu::flatten]] INTERPATCH_KERNEL void restrict_row_cubic(const NetMatrix& a, const Refinement& rv, const Gather& gather, std::size_t i,
                                                           double* t) {
  constexpr int H = 3, L = 2 * H + 1, K = 12, P = 4, T = 8;
  using v4 = double __attribute__((vector_size(32)));
  const auto fu = static_cast<long long>(a.nu());
  const auto fv = static_cast<std::size_t>(rv.fine), cv = static_cast<std::size_t>(rv.coarse);
  std::fill(t, t + cv * L * T, 0.0);
  // zp[di][H + k]: the row's entries to (i + di, ·) times the refinement, coarse function
  // zlo + k; zeros either side, where t's band reaches past them (set once here).
  alignas(32) double zp[L][K + 2 * H + 3] = {};
  const auto nv = static_cast<std::ptrdiff_t>(fv), width = static_cast<std::ptrdiff_t>(a.width());
  for (std::size_t j = 0; j < fv; ++j) {
    const std::size_t row = i * fv + j;
    const int jlo = std::max(-H, -static_cast<int>(j)), jhi = std::min(H, static_cast<int>(fv - 1 - j));
    const double* gw = &gather.w[j * L * K];
    const double* own = a.upper(row);
    for (int di = -H; di <= H; ++di) {
      v4 z[K / 4] = {};
      if (static_cast<long long>(i) + di >= 0 && static_cast<long long>(i) + di < fu) {
        double v[L] = {};
        if (di > 0 && jlo == -H && jhi == H) {
          std::memcpy(v, own + a.offset(di, -H), sizeof v);
        } else {
          for (int dj = jlo; dj <= jhi; ++dj) {
            const bool upper = di > 0 || (di == 0 && dj >= 0);
            v[dj + H] = upper ? own[a.offset(di, dj)] : own[(di * nv + dj) * width + a.offset(-di, -dj)];
          }
        }
        for (int d = 0; d < L; ++d)
          for (int q = 0; q < K / 4; ++q) {
            v4 g;
            std::memcpy(&g, gw + d * K + 4 * q, sizeof g);
            z[q] += v[d] * g;
          }
      }
      std::memcpy(&zp[di + H][H], z, sizeof z);
    }
    const double* wj = &rv.weight[j * P];
    const int zlo = gather.zlo[j];
    for (int e = 0; e < P; ++e) {
      if (wj[e] == 0) continue;
      const int b = rv.first[j] + e, at = b - zlo;  // zp[·][at + db]: coarse b + db - H
      double* to = &t[static_cast<std::size_t>(b) * L * T];
      const v4 w{wj[e], wj[e], wj[e], wj[e]};
      for (int di = 0; di < L; ++di)
        for (int q = 0; q < 2; ++q) {
          v4 from, sum;
          std::memcpy(&from, &zp[di][at + 4 * q], sizeof from);
          std::memcpy(&sum, to + di * T + 4 * q, sizeof sum);
          sum += w * from;
          std::memcpy(to + di * T + 4 * q, &sum, sizeof sum);
        }
    }
  }
}

}  // namespace

System restrict_system(const System& fine, const std::array<Refinement, 2>& r) {
  const NetMatrix& a = fine.a;
  const Refinement &ru = r[0], &rv = r[1];
  const int hu = a.hu(), hv = a.hv(), wu = 2 * hu + 1, wv = 2 * hv + 1;
  const auto c = static_cast<std::size_t>(fine.cols), band = static_cast<std::size_t>(wu * wv);
  const auto fu = static_cast<std::size_t>(ru.fine), fv = static_cast<std::size_t>(rv.fine);
  const auto cu = static_cast<std::size_t>(ru.coarse), cv = static_cast<std::size_t>(rv.coarse);
  const auto pu = static_cast<std::size_t>(ru.p + 1), pv = static_cast<std::size_t>(rv.p + 1);
  // Along u, each coarse row a from the fine rows i that refine it (the transpose), in
  // their order, into the upper half (offsets da >= 0, neighbours inside the net). The
  // coarse rows in blocks, each with the fine rows it needs done along v (a few of them
  // twice, at the blocks' edges): a few MB a thread, where all of them took as many
  // bytes as the fine matrix.
  System out{NetMatrix(ru.coarse, rv.coarse, hu, hv), std::vector<double>(cu * cv * c, 0.0), fine.cols};
  // At most 16 coarse rows a block, and as many blocks as a multiple of the threads,
  // even in size: with 16 rows, a 35-row coarsest net made blocks of 16, 16 and 3, and
  // one thread did nearly all the work. Each coarse entry's sum runs in the same order
  // whatever the blocks: the same bits on any number of threads.
  const bool parallel = fu * fv * band * pv >= parallel_min_work;
  const std::size_t threads = parallel ? max_threads() : 1;
  const std::size_t blocks = ((cu + 15) / 16 + threads - 1) / threads * threads, block = (cu + blocks - 1) / blocks;
  // Each block's fine rows [ilo, ihi], and a thread's buffers for the most of them,
  // made before the threads start (nothing allocates inside them).
  std::vector<std::array<std::size_t, 2>> rows(blocks, {fu, 0});
  std::size_t most = 0;
  for (std::size_t bk = 0; bk < blocks; ++bk) {
    const std::size_t a0 = std::min(cu, bk * block), a1 = std::min(cu, a0 + block);
    for (std::size_t x = ru.t_start[a0]; x < ru.t_start[a1]; ++x) {
      rows[bk][0] = std::min(rows[bk][0], static_cast<std::size_t>(ru.t_index[x]));
      rows[bk][1] = std::max(rows[bk][1], static_cast<std::size_t>(ru.t_index[x]));
    }
    if (rows[bk][0] <= rows[bk][1]) most = std::max(most, rows[bk][1] - rows[bk][0] + 1);
  }
  struct Buffers {
    std::vector<double> t, tb, z;
  };
  const Gather gather(rv, hv);
  const bool cubic = hu == 3 && hv == 3 && rv.p == 3 && a.upper(0) != nullptr && gather.width == 12;
  // t's places a fine row, coarse column and di: the band's 2hv + 1, or 8 for the
  // cubic kernel's two vectors of four.
  const std::size_t tw = cubic ? 8 : static_cast<std::size_t>(wv), tband = static_cast<std::size_t>(wu) * tw;
  std::vector<Buffers> buffers(parallel ? max_threads() : 1);
  for (Buffers& buf : buffers) buf = {std::vector<double>(most * cv * tband), std::vector<double>(most * cv * c), std::vector<double>(static_cast<std::size_t>(2 * hv) + pv + 1)};
#pragma omp parallel if (parallel)
  {
    Buffers& buf = buffers[static_cast<std::size_t>(thread_index())];
    std::vector<double> &t = buf.t, &tb = buf.tb;
#pragma omp for schedule(static)
    for (long long bk = 0; bk < static_cast<long long>(blocks); ++bk) {
      const std::size_t a0 = std::min(cu, static_cast<std::size_t>(bk) * block), a1 = std::min(cu, a0 + block);
      const auto [ilo, ihi] = rows[static_cast<std::size_t>(bk)];
      if (ilo > ihi) continue;
      for (std::size_t i = ilo; i <= ihi; ++i) {
        restrict_row_along_v(fine, rv, gather, i, &t[(i - ilo) * cv * tband], &tb[(i - ilo) * cv * c], buf.z, !cubic);
        if (cubic) restrict_row_cubic(a, rv, gather, i, &t[(i - ilo) * cv * tband]);
      }
      for (std::size_t ca = a0; ca < a1; ++ca)
        for (std::size_t x = ru.t_start[ca]; x < ru.t_start[ca + 1]; ++x) {
          const auto i = static_cast<std::size_t>(ru.t_index[x]);
          const double w = ru.t_weight[x];
          for (std::size_t b = 0; b < cv; ++b)
            for (std::size_t m = 0; m < c; ++m) out.rhs[(ca * cv + b) * c + m] += w * tb[((i - ilo) * cv + b) * c + m];
          // Each entry's sum in the order of i, di, e2 as before; the coarse columns b
          // innermost but one, each (da, db) run a contiguous stretch of its row.
          for (int di = -hu; di <= hu; ++di) {
            const long long i2 = static_cast<long long>(i) + di;
            if (i2 < 0 || i2 >= static_cast<long long>(fu)) continue;
            for (std::size_t e2 = 0; e2 < pu; ++e2) {
              const double w2 = w * ru.weight[static_cast<std::size_t>(i2) * pu + e2];
              const int da = ru.first[static_cast<std::size_t>(i2)] + static_cast<int>(e2) - static_cast<int>(ca);
              if (w2 == 0 || da < 0 || da > hu || ca + static_cast<std::size_t>(da) >= cu) continue;  // the upper half is all that is kept
              for (std::size_t b = 0; b < cv; ++b) {
                const double* from = &t[(((i - ilo) * cv + b) * static_cast<std::size_t>(wu) + static_cast<std::size_t>(di + hu)) * tw];
                const int lo = std::max(da == 0 ? 0 : -hv, -static_cast<int>(b)), hi = std::min(hv, static_cast<int>(cv - 1 - b));
                double* to = &out.a.at(ca * cv + b, out.a.offset(da, lo)) - lo;  // to[db]: offset (da, db)
                for (int db = lo; db <= hi; ++db) to[db] += w2 * from[db + hv];
              }
            }
          }
        }
    }
  }
  return out;
}

Multigrid::Multigrid(const Net& coarsest, const Net& finest, const NetMatrix* coarsest_a, const NetMatrix* finest_a, int cols)
    : coarsest_a_(coarsest_a), finest_a_(finest_a), one_net_(coarsest.same_knots(finest)), cols_(cols) {
  if (one_net_) return;
  up_ = {refinement(coarsest.ku, finest.ku), refinement(coarsest.kv, finest.kv)};
  r_.assign(finest.size() * static_cast<std::size_t>(cols), 0.0);
  b_.assign(coarsest.size() * static_cast<std::size_t>(cols), 0.0);
  x_.assign(b_.size(), 0.0);
}

bool Multigrid::factor() {
  coarsest_.emplace(*coarsest_a_);
  smoother_.reset();
  if (!one_net_) smoother_.emplace(*finest_a_);
  return coarsest_->ok();
}

void Multigrid::coarse_guess(std::span<const double> b, std::span<double> x) {
  if (one_net_) return;
  std::fill(x.begin(), x.end(), 0.0);
  restrict_to(up_, b, b_, cols_, tmp_);
  coarsest_->solve(b_, x_, cols_);
  prolong(up_, x_, x, cols_, tmp_);
}

void Multigrid::apply(std::span<const double> r, std::span<double> z) {
  if (one_net_) {
    coarsest_->solve(r, z, cols_);
    return;
  }
  std::fill(z.begin(), z.end(), 0.0);
  // r_ is also the sweeps' room for their residuals: each sweep is done with it before
  // the next use (tmp_, the restriction's and the prolongation's, is a coarse row's size).
  smoother_->sweep(*finest_a_, r, z, cols_, false, r_, true);
  finest_a_->multiply(z, r_, cols_, NetMatrix::Part::floats);
#pragma omp parallel for schedule(static) if (r_.size() >= parallel_min_work / 4)
  for (std::size_t k = 0; k < r_.size(); ++k) r_[k] = r[k] - r_[k];
  restrict_to(up_, r_, b_, cols_, tmp_);
  coarsest_->solve(b_, x_, cols_);
  prolong(up_, x_, z, cols_, tmp_);
  smoother_->sweep(*finest_a_, r, z, cols_, true, r_);
}

}  // namespace interpatch::detail::scattered
