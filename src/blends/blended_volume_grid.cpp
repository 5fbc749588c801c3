// Grid evaluation of blended volumes, every term folded into planes.
//
// Each term of a blended volume (volume_terms.hpp) carries a blending function of
// at least one axis: a face of axis a is f(t_a) F(the other two), an edge of free
// axis c is s f_a(t_a) f_b(t_b) E(t_c), a corner f_u(u) f_v(v) f_w(w) P. Filing each
// term under one of its blended axes a and that axis' blend k gives
//
//   S(u, v, w) = Σ_a Σ_k f_ak(t_a) Φ_ak(the two other parameters),
//
// with at most 3 × 4 planes Φ_ak, each evaluated once on the grid of its two axes
// (faces through their surfaces' own grid evaluation). A point then costs at most 12
// products, whatever the number of faces, edges and corners; a 200³ grid is about
// the time of writing its points, where point by point it took seconds.

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "base/kernel.hpp"
#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/memory.hpp"
#include "blends/volume_terms.hpp"

namespace interpatch {

namespace detail {

// Φ_ak on the grid of the plane's two axes (o0, o1) = other_axes(a), o0 slowest;
// with derivatives, also ∂Φ/∂t_o0 and ∂Φ/∂t_o1.
struct Plane {
  std::vector<Vec3> value, d0, d1;
};

// The planes of axis u, over (v, w): the costly part of a fold (the u faces are
// evaluated on the whole v × w grid), and the same for every slab of u values a
// large grid is evaluated in. BlendedVolume keeps the last ones.
struct PlaneCache {
  struct Entry {
    std::vector<double> vs, ws;
    bool derivatives = false;
    std::vector<Plane> planes;
    // The parameters of v and w clamped and their blending values (Folded's t, f, df
    // and blends of axes 1 and 2), which every slab of u values needs again.
    std::array<std::vector<double>, 3> t, f, df;
    std::array<std::size_t, 3> blends{};
  };
  std::mutex mutex;
  std::shared_ptr<const Entry> last;
};

std::shared_ptr<PlaneCache> make_plane_cache() { return std::make_shared<PlaneCache>(); }

namespace {

struct Folded {
  std::array<std::vector<double>, 3> t;       // the parameters of each axis, clamped to [0, 1]
  std::array<std::size_t, 3> blends{};        // blending functions per axis
  std::array<std::vector<double>, 3> f, df;   // f[a][i * blends[a] + k]: blend k of axis a at t[a][i], and f'
  std::array<std::vector<Plane>, 3> planes;   // planes[a][k]; planes[0] empty, see u_planes
  std::shared_ptr<const PlaneCache::Entry> u;  // the planes of axis u
  bool derivatives = false;

  [[nodiscard]] std::size_t extent(int a) const { return t[static_cast<std::size_t>(a)].size(); }
  [[nodiscard]] const Plane& plane(std::size_t a, std::size_t k) const {
    return a == 0 ? u->planes[k] : planes[a][k];
  }
};

// The planes of axis a from the terms filed under it: its faces, the edges whose
// first blended axis it is, and (for u) the corners. Needs F's parameters of every
// axis and the blending values of the two axes other than a.
std::vector<Plane> planes_of(const detail::VolumeTerms& T, int a, const Folded& F) {
  const auto o = detail::other_axes(a);
  const std::size_t n0 = F.extent(o[0]), n1 = F.extent(o[1]), cells = n0 * n1;
  std::vector<Plane> planes(T.blends[static_cast<std::size_t>(a)].size());
  for (Plane& p : planes) {
    p.value.assign(cells, Vec3{});
    if (F.derivatives) {
      p.d0.assign(cells, Vec3{});
      p.d1.assign(cells, Vec3{});
    }
  }

  // Faces: f(t_a) F(t_o0, t_o1).
  const std::span<const double> s = F.t[static_cast<std::size_t>(o[0])], t = F.t[static_cast<std::size_t>(o[1])];
  for (const auto& face : T.faces) {
    if (face.axis != a) continue;
    Plane& p = planes[face.blend];
    // Values from the surface's point evaluation also when derivatives are asked
    // for: the points of a mesh are then the bits of an evaluation.
    std::vector<Vec3> values(cells);
    face.surface.evaluate_into(s, t, values);
    for (std::size_t x = 0; x < cells; ++x) p.value[x] += values[x];
    if (!F.derivatives) continue;
    const auto grid = face.surface.evaluate_derivatives(s, t);
    for (std::size_t x = 0; x < n0; ++x)
      for (std::size_t y = 0; y < n1; ++y) {
        const SurfaceDerivatives& d = grid(x, y);
        p.d0[x * n1 + y] += d.su;
        p.d1[x * n1 + y] += d.sv;
      }
  }

  // Edges: scale f_a(t_a) f_b(t_b) E(t_c) with (a, b) = other_axes(c), filed under a;
  // the plane is over b and c, in increasing order.
  for (const auto& e : T.edges) {
    const int c = e.axis;
    if (detail::other_axes(c)[0] != a) continue;
    const int b = detail::other_axes(c)[1];
    const std::size_t Kb = F.blends[static_cast<std::size_t>(b)];
    const std::vector<double>& fb = F.f[static_cast<std::size_t>(b)];
    const std::vector<double>& dfb = F.df[static_cast<std::size_t>(b)];
    std::vector<detail::IsoLine::Value> E(F.extent(c));
    for (std::size_t z = 0; z < E.size(); ++z) E[z] = e.line.eval(F.t[static_cast<std::size_t>(c)][z]);
    Plane& p = planes[e.blends[0]];
    const bool b_first = o[0] == b;
    for (std::size_t x = 0; x < n0; ++x)
      for (std::size_t y = 0; y < n1; ++y) {
        const std::size_t ib = b_first ? x : y, ic = b_first ? y : x;
        const double g = e.scale * fb[ib * Kb + e.blends[1]];
        const std::size_t at = x * n1 + y;
        p.value[at] += g * E[ic].d0;
        if (!F.derivatives) continue;
        const Vec3 along_b = (e.scale * dfb[ib * Kb + e.blends[1]]) * E[ic].d0, along_c = g * E[ic].d1;
        p.d0[at] += b_first ? along_b : along_c;
        p.d1[at] += b_first ? along_c : along_b;
      }
  }

  // Corners: f_u(u) f_v(v) f_w(w) P, filed under u; the plane is over (v, w).
  if (a != 0) return planes;
  const std::size_t Kv = F.blends[1], Kw = F.blends[2];
  for (const auto& k : T.corners) {
    Plane& p = planes[k.blends[0]];
    for (std::size_t y = 0; y < n0; ++y)
      for (std::size_t z = 0; z < n1; ++z) {
        const double fv = F.f[1][y * Kv + k.blends[1]], fw = F.f[2][z * Kw + k.blends[2]];
        const std::size_t at = y * n1 + z;
        p.value[at] += (fv * fw) * k.point;
        if (!F.derivatives) continue;
        p.d0[at] += (F.df[1][y * Kv + k.blends[1]] * fw) * k.point;
        p.d1[at] += (fv * F.df[2][z * Kw + k.blends[2]]) * k.point;
      }
  }
  return planes;
}

// Planes of the u axis kept between calls only up to this size: a large grid's
// slabs reuse them, and a volume does not hold on to much memory after its last
// evaluation.
constexpr std::size_t max_cached_plane_bytes = std::size_t{256} << 20;

// The parameters of axis a, clamped, and its blending functions there.
void set_axis(Folded& F, const detail::VolumeTerms& T, std::size_t a, std::span<const double> ts) {
  F.t[a].resize(ts.size());
  std::transform(ts.begin(), ts.end(), F.t[a].begin(), [](double x) { return std::clamp(x, 0.0, 1.0); });
  const std::size_t K = T.blends[a].size(), n = F.t[a].size();
  F.blends[a] = K;
  F.f[a].resize(n * K);
  F.df[a].resize(n * K);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < K; ++k) {
      double d[3];
      T.blends[a][k].eval(F.t[a][i], d);
      F.f[a][i * K + k] = d[0];
      F.df[a][i * K + k] = d[1];
    }
}

// The planes of u over vs × ws: the cache's last ones when they were made for the
// same parameters (with derivatives when asked), else made and kept.
std::shared_ptr<const PlaneCache::Entry> u_planes(const detail::VolumeTerms& T, std::span<const double> vs,
                                                  std::span<const double> ws, bool derivatives, PlaneCache& cache) {
  std::shared_ptr<const PlaneCache::Entry> last;
  {
    const std::lock_guard<std::mutex> lock(cache.mutex);
    last = cache.last;
  }
  const auto same = [](const std::vector<double>& kept, std::span<const double> given) {
    return std::equal(kept.begin(), kept.end(), given.begin(), given.end());
  };
  if (last && (last->derivatives || !derivatives) && same(last->vs, vs) && same(last->ws, ws)) return last;
  const std::size_t per_point = derivatives ? 3 : 1;
  require_memory(T.blends[0].size() * vs.size() * ws.size() * per_point, sizeof(Vec3),
                 detail::cat("the planes of a blended volume over ", vs.size(), "x", ws.size(), " (v, w) parameters"));
  Folded F;
  F.derivatives = derivatives;
  set_axis(F, T, 1, vs);
  set_axis(F, T, 2, ws);
  auto entry = std::make_shared<PlaneCache::Entry>();
  entry->vs.assign(vs.begin(), vs.end());
  entry->ws.assign(ws.begin(), ws.end());
  entry->derivatives = derivatives;
  entry->planes = planes_of(T, 0, F);
  for (std::size_t a = 1; a < 3; ++a) {
    entry->t[a] = std::move(F.t[a]);
    entry->f[a] = std::move(F.f[a]);
    entry->df[a] = std::move(F.df[a]);
    entry->blends[a] = F.blends[a];
  }
  const std::size_t bytes = T.blends[0].size() * vs.size() * ws.size() * sizeof(Vec3) * per_point;
  const std::lock_guard<std::mutex> lock(cache.mutex);
  cache.last = bytes <= max_cached_plane_bytes ? entry : nullptr;
  return entry;
}

// A slab of u values folded: blending values of every axis, the planes of v and w
// for the slab, the planes of u shared.
Folded fold_slab(const detail::VolumeTerms& T, std::span<const double> us, bool derivatives,
                 std::shared_ptr<const PlaneCache::Entry> u) {
  Folded F;
  F.derivatives = derivatives;
  set_axis(F, T, 0, us);
  for (std::size_t a = 1; a < 3; ++a) {  // made with the planes of u, for the same vs and ws
    F.t[a] = u->t[a];
    F.f[a] = u->f[a];
    F.df[a] = u->df[a];
    F.blends[a] = u->blends[a];
  }
  F.u = std::move(u);
  F.planes[1] = planes_of(T, 1, F);
  F.planes[2] = planes_of(T, 2, F);
  return F;
}

// Calls line_at(i, j, fu, fv) for every line along w of the grid (fu, fv: the
// blending values of u_i and v_j), split over the threads, in chunks of (i, j) pairs
// in u-major order between progress reports: a slab of a few u values still keeps
// every core busy. line_at must not throw (it only sums and stores; progress is
// called between the regions).
template <class Line>
void for_each_line_index(const Folded& F, const progress_callback& progress, const Line& line_at) {
  const std::size_t nu = F.extent(0), nv = F.extent(1), nw = F.extent(2);
  const std::size_t K = F.blends[0] + F.blends[1] + F.blends[2];
  const std::size_t lines = nu * nv, chunk = std::max<std::size_t>(nv, std::size_t{1} << 12);
  for (std::size_t l0 = 0; l0 < lines; l0 += chunk) {
    const auto l1 = static_cast<long long>(std::min(lines, l0 + chunk));
#pragma omp parallel for schedule(static) if ((std::size_t(l1) - l0) * nw * K >= detail::parallel_min_work)
    for (auto line = static_cast<long long>(l0); line < l1; ++line) {
      const std::size_t i = static_cast<std::size_t>(line) / nv, j = static_cast<std::size_t>(line) % nv;
      line_at(i, j, F.f[0].data() + i * F.blends[0], F.f[1].data() + j * F.blends[1]);
    }
    if (progress) progress(static_cast<double>(l1) / static_cast<double>(lines));
  }
}

// Calls at(i, j, k, S, S_u, S_v, S_w) for every grid point (the partials zero
// without derivatives); each point is a sum in a fixed order, so the result does not
// depend on the thread count.
template <bool derivatives, class At>
void for_each_point(const Folded& F, const progress_callback& progress, const At& at) {
  const std::size_t nv = F.extent(1), nw = F.extent(2);
  const std::size_t Ku = F.blends[0], Kv = F.blends[1], Kw = F.blends[2];
  for_each_line_index(F, progress, [&](std::size_t i, std::size_t j, const double* fu, const double* fv) {
    const double* dfu = F.df[0].data() + i * Ku;
    const double* dfv = F.df[1].data() + j * Kv;
    // Along the line: the u planes at (j, ·), the v planes at (i, ·), both
    // contiguous in k; the w planes at (i, j), the same for the whole line.
    using Row = std::array<const Vec3*, detail::max_volume_blends>;
    Row U{}, Uv{}, Uw{}, V{}, Vu{}, Vw{};
    std::array<Vec3, detail::max_volume_blends> W{}, Wu{}, Wv{};
    const auto line_of = [&](std::size_t axis, std::size_t K, std::size_t offset, Row& value, Row& d0, Row& d1) {
      for (std::size_t a = 0; a < K; ++a) {
        const Plane& p = F.plane(axis, a);
        value[a] = p.value.data() + offset;
        if constexpr (derivatives) {
          d0[a] = p.d0.data() + offset;
          d1[a] = p.d1.data() + offset;
        }
      }
    };
    line_of(0, Ku, j * nw, U, Uv, Uw);
    line_of(1, Kv, i * nw, V, Vu, Vw);
    for (std::size_t c = 0; c < Kw; ++c) {
      const Plane& p = F.plane(2, c);
      W[c] = p.value[i * nv + j];
      if constexpr (derivatives) {
        Wu[c] = p.d0[i * nv + j];
        Wv[c] = p.d1[i * nv + j];
      }
    }
    for (std::size_t k = 0; k < nw; ++k) {
      const double* fw = F.f[2].data() + k * Kw;
      Vec3 s{}, su{}, sv{}, sw{};
      for (std::size_t a = 0; a < Ku; ++a) s += fu[a] * U[a][k];
      for (std::size_t b = 0; b < Kv; ++b) s += fv[b] * V[b][k];
      for (std::size_t c = 0; c < Kw; ++c) s += fw[c] * W[c];
      if constexpr (derivatives) {
        const double* dfw = F.df[2].data() + k * Kw;
        for (std::size_t a = 0; a < Ku; ++a) {
          su += dfu[a] * U[a][k];
          sv += fu[a] * Uv[a][k];
          sw += fu[a] * Uw[a][k];
        }
        for (std::size_t b = 0; b < Kv; ++b) {
          su += fv[b] * Vu[b][k];
          sv += dfv[b] * V[b][k];
          sw += fv[b] * Vw[b][k];
        }
        for (std::size_t c = 0; c < Kw; ++c) {
          su += fw[c] * Wu[c];
          sv += fw[c] * Wv[c];
          sw += dfw[c] * W[c];
        }
      }
      at(i, j, k, s, su, sv, sw);
    }
  });
}

// The nw points of one line along w without derivatives: the sums for_each_point
// makes for S, the same products added in the same order (this file is compiled
// without fused multiply-adds, so every clone gives the same bits), four points at a
// time. Their twelve doubles are three vectors of four lanes, (x0 y0 z0 x1),
// (y1 z1 x2 y2), (z2 x3 y3 z3): a u or v term adds its plane's twelve doubles times
// one blending value; a w term its point's coordinates in that pattern times the
// four points' blending values. K = the blending functions of every axis when known
// at compile time (loops unrolled), 0 when not.
template <std::size_t K>
[[gnu::always_inline]] inline void line_points(std::size_t nw, std::size_t Ku, std::size_t Kv, std::size_t Kw,
                                               const double* fu, const double* fv, const double* fw_all,
                                               const Vec3* const* U, const Vec3* const* V, const Vec3* W, Vec3* out) {
  if constexpr (K != 0) Ku = Kv = Kw = K;
  std::size_t k = 0;
#if defined(__GNUC__)
  using v4 = double __attribute__((vector_size(32)));
  // s0..s2 += f times the twelve doubles at p.
  const auto add = [](v4& s0, v4& s1, v4& s2, double f, const Vec3* p) {
    v4 p0, p1, p2;
    std::memcpy(&p0, &p->x, sizeof p0);
    std::memcpy(&p1, &p->x + 4, sizeof p1);
    std::memcpy(&p2, &p->x + 8, sizeof p2);
    const v4 c = {f, f, f, f};
    s0 += c * p0;
    s1 += c * p1;
    s2 += c * p2;
  };
  for (; k + 4 <= nw; k += 4) {
    v4 s0 = {0, 0, 0, 0}, s1 = s0, s2 = s0;
    for (std::size_t a = 0; a < Ku; ++a) add(s0, s1, s2, fu[a], U[a] + k);
    for (std::size_t b = 0; b < Kv; ++b) add(s0, s1, s2, fv[b], V[b] + k);
    const double* f0 = fw_all + k * Kw;
    const double *f1 = f0 + Kw, *f2 = f1 + Kw, *f3 = f2 + Kw;
    for (std::size_t c = 0; c < Kw; ++c) {
      const Vec3& w = W[c];
      s0 += v4{f0[c], f0[c], f0[c], f1[c]} * v4{w.x, w.y, w.z, w.x};
      s1 += v4{f1[c], f1[c], f2[c], f2[c]} * v4{w.y, w.z, w.x, w.y};
      s2 += v4{f2[c], f3[c], f3[c], f3[c]} * v4{w.z, w.x, w.y, w.z};
    }
    double* o = &out[k].x;
    std::memcpy(o, &s0, sizeof s0);
    std::memcpy(o + 4, &s1, sizeof s1);
    std::memcpy(o + 8, &s2, sizeof s2);
  }
#endif
  for (; k < nw; ++k) {
    const double* fw = fw_all + k * Kw;
    Vec3 s{};
    for (std::size_t a = 0; a < Ku; ++a) s += fu[a] * U[a][k];
    for (std::size_t b = 0; b < Kv; ++b) s += fv[b] * V[b][k];
    for (std::size_t c = 0; c < Kw; ++c) s += fw[c] * W[c];
    out[k] = s;
  }
}

// line_points for every number of blending functions, linear (Coons, trilinear) and
// cubic Hermite blends unrolled; compiled for AVX and for the baseline.
INTERPATCH_KERNEL void line_of_points(std::size_t nw, std::size_t Ku, std::size_t Kv, std::size_t Kw, const double* fu,
                                      const double* fv, const double* fw, const Vec3* const* U, const Vec3* const* V,
                                      const Vec3* W, Vec3* out) {
  const std::size_t same = Ku == Kv && Kv == Kw ? Ku : 0;
  switch (same) {
    case 2: return line_points<2>(nw, Ku, Kv, Kw, fu, fv, fw, U, V, W, out);
    case 4: return line_points<4>(nw, Ku, Kv, Kw, fu, fv, fw, U, V, W, out);
    default: return line_points<0>(nw, Ku, Kv, Kw, fu, fv, fw, U, V, W, out);
  }
}

// The points of every line along w, without derivatives, into dest(i, j) (nw
// points), lines split over the threads as in for_each_point.
template <class Dest>
void for_each_line(const Folded& F, const progress_callback& progress, const Dest& dest) {
  const std::size_t nv = F.extent(1), nw = F.extent(2);
  const std::size_t Ku = F.blends[0], Kv = F.blends[1], Kw = F.blends[2];
  for_each_line_index(F, progress, [&](std::size_t i, std::size_t j, const double* fu, const double* fv) {
    std::array<const Vec3*, detail::max_volume_blends> U{}, V{};
    std::array<Vec3, detail::max_volume_blends> W{};
    for (std::size_t a = 0; a < Ku; ++a) U[a] = F.plane(0, a).value.data() + j * nw;
    for (std::size_t b = 0; b < Kv; ++b) V[b] = F.plane(1, b).value.data() + i * nw;
    for (std::size_t c = 0; c < Kw; ++c) W[c] = F.plane(2, c).value[i * nv + j];
    line_of_points(nw, Ku, Kv, Kw, fu, fv, F.f[2].data(), U.data(), V.data(), W.data(), dest(i, j));
  });
}

// Points of the planes of v and w a slab is given at most: the slabs of a grid of
// 10⁷ × 2 × 2 points would otherwise need planes of 4 × 10⁷. The split does not
// change a bit of the result: every point is the same sum in any slab.
constexpr std::size_t max_slab_plane_points = std::size_t{1} << 22;

// Calls visit(F, progress, i0) for every slab of u values folded, u values i0 on.
template <class Visit>
void for_each_slab(const detail::VolumeTerms& T, PlaneCache& cache, std::span<const double> us,
                   std::span<const double> vs, std::span<const double> ws, bool derivatives,
                   const progress_callback& progress, const Visit& visit) {
  const std::size_t nu = us.size();
  if (nu == 0) {  // no point: no planes to make
    if (progress) progress(1.0);
    return;
  }
  const auto u = u_planes(T, vs, ws, derivatives, cache);
  const std::size_t per_row = (T.blends[1].size() * ws.size() + T.blends[2].size() * vs.size()) * (derivatives ? 3 : 1);
  const std::size_t rows = std::max<std::size_t>(1, max_slab_plane_points / std::max<std::size_t>(1, per_row));
  for (std::size_t i0 = 0; i0 < nu; i0 += rows) {
    const std::size_t n = std::min(rows, nu - i0);
    const Folded F = fold_slab(T, us.subspan(i0, n), derivatives, u);
    progress_callback slab_progress;
    if (progress)
      slab_progress = [&](double f) { progress((static_cast<double>(i0) + f * static_cast<double>(n)) / static_cast<double>(nu)); };
    visit(F, slab_progress, i0);
  }
}

// Calls at(i, j, k, S, S_u, S_v, S_w) for every point of the grid, with derivatives.
template <class At>
void fold_and_evaluate(const detail::VolumeTerms& T, PlaneCache& cache, std::span<const double> us,
                       std::span<const double> vs, std::span<const double> ws, const progress_callback& progress,
                       const At& at) {
  for_each_slab(T, cache, us, vs, ws, true, progress, [&](const Folded& F, const progress_callback& p, std::size_t i0) {
    for_each_point<true>(F, p, [&](std::size_t i, std::size_t j, std::size_t k, const Vec3& s, const Vec3& su,
                                   const Vec3& sv, const Vec3& sw) { at(i0 + i, j, k, s, su, sv, sw); });
  });
}

// The points of the grid into out, lines along w at a time.
void fold_and_evaluate_points(const detail::VolumeTerms& T, PlaneCache& cache, std::span<const double> us,
                              std::span<const double> vs, std::span<const double> ws, std::span<Vec3> out,
                              const progress_callback& progress) {
  const std::size_t nv = vs.size(), nw = ws.size();
  for_each_slab(T, cache, us, vs, ws, false, progress, [&](const Folded& F, const progress_callback& p, std::size_t i0) {
    for_each_line(F, p, [&](std::size_t i, std::size_t j) { return out.data() + ((i0 + i) * nv + j) * nw; });
  });
}

// Whether the grid's point count, times the bytes of a point, can be addressed; the
// pointwise base versions refuse those that cannot (too_large).
bool addressable(std::size_t nu, std::size_t nv, std::size_t nw) {
  constexpr std::size_t max = std::numeric_limits<std::size_t>::max() / 64;
  return !((nv != 0 && nu > max / nv) || (nw != 0 && nu * nv > max / nw));
}

}  // namespace

}  // namespace detail

using detail::addressable;
using detail::fold_and_evaluate;
using detail::fold_and_evaluate_points;

void BlendedVolume::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                                  std::span<Vec3> out, const progress_callback& progress) const {
  detail::check_output_size(out.size(), {us.size(), vs.size(), ws.size()}, "volume evaluation");
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  detail::check_unit_parameters(ws, "w");
  fold_and_evaluate_points(*t_, *planes_, us, vs, ws, out, progress);
}

Grid<VolumeDerivatives, 3> BlendedVolume::evaluate_derivatives(std::span<const double> us, std::span<const double> vs,
                                                               std::span<const double> ws) const {
  if (!addressable(us.size(), vs.size(), ws.size())) return Volume::evaluate_derivatives(us, vs, ws);
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  detail::check_unit_parameters(ws, "w");
  require_memory(us.size() * vs.size() * ws.size(), sizeof(VolumeDerivatives), "volume derivative grid");
  Grid<VolumeDerivatives, 3> out({us.size(), vs.size(), ws.size()}, for_overwrite);
  fold_and_evaluate(*t_, *planes_, us, vs, ws, {},
                    [&](std::size_t i, std::size_t j, std::size_t k, const Vec3& s, const Vec3& su, const Vec3& sv,
                        const Vec3& sw) { out(i, j, k) = {s, su, sv, sw}; });
  return out;
}

VolumeJacobians BlendedVolume::evaluate_jacobians(std::span<const double> us, std::span<const double> vs,
                                                  std::span<const double> ws, const progress_callback& progress) const {
  if (!addressable(us.size(), vs.size(), ws.size())) return Volume::evaluate_jacobians(us, vs, ws, progress);
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  detail::check_unit_parameters(ws, "w");
  require_memory(us.size() * vs.size() * ws.size(), sizeof(Vec3) + sizeof(double), "volume Jacobian grid");
  const std::array<std::size_t, 3> n{us.size(), vs.size(), ws.size()};
  VolumeJacobians out{PointGrid3(n, for_overwrite), Grid<double, 3>(n, for_overwrite)};
  fold_and_evaluate(*t_, *planes_, us, vs, ws, progress,
                    [&](std::size_t i, std::size_t j, std::size_t k, const Vec3& s, const Vec3& su, const Vec3& sv,
                        const Vec3& sw) {
                      out.points(i, j, k) = s;
                      out.determinants(i, j, k) = triple(su, sv, sw);
                    });
  return out;
}

}  // namespace interpatch
