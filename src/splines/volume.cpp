#include "interpatch/volume.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

using detail::fail;

namespace {

// Checked before the parallel loops: an exception must not leave an OpenMP region.
void check_domain(std::span<const double> ts, std::pair<double, double> dom, const char* dir) {
  const double slack = 1e-12 * (dom.second - dom.first);  // rounding of the caller's parameter mapping
  for (double t : ts)
    if (!(t >= dom.first - slack && t <= dom.second + slack))
      fail(errc::out_of_domain, "parameter ", dir, " = ", t, " is outside the domain [", dom.first, ", ", dom.second,
           "]");
}

void check_grid(const Volume& v, std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                std::size_t item_bytes, const char* what) {
  const auto dom = v.domain();
  check_domain(us, dom[0], "u");
  check_domain(vs, dom[1], "v");
  check_domain(ws, dom[2], "w");
  const std::size_t max = std::numeric_limits<std::size_t>::max();
  const std::size_t nu = us.size(), nv = vs.size(), nw = ws.size();
  if ((nv != 0 && nu > max / nv) || (nw != 0 && nu * nv > max / nw))
    fail(errc::too_large, what, " ", nu, "x", nv, "x", nw, " has more points than can be addressed");
  require_memory(nu * nv * nw, item_bytes, detail::cat(what, " ", nu, "x", nv, "x", nw));
}

// Pointwise evaluation of a whole grid, u rows split over the threads: at(i, j, k)
// evaluates and stores one point with the volume's own point() or derivatives(),
// which are thread-safe and allocation-free.
template <class At>
void pointwise(std::size_t nu, std::size_t nv, std::size_t nw, const progress_callback& progress, const At& at) {
  for (std::size_t r0 = 0; r0 < nu; r0 += 16) {
    const std::size_t r1 = std::min(nu, r0 + 16);
    detail::parallel_for(r1 - r0, nu * nv * nw >= detail::parallel_min_work / 16, detail::Share::blocks, [&](std::size_t r) {
      for (std::size_t j = 0; j < nv; ++j)
        for (std::size_t k = 0; k < nw; ++k) at(r0 + r, j, k);
    });
    if (progress) progress(static_cast<double>(r1) / static_cast<double>(nu));
  }
}

}  // namespace

Jacobian jacobian(const VolumeDerivatives& d) noexcept {
  Jacobian j;
  const Vec3 col[3] = {d.su, d.sv, d.sw};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      j.matrix[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)] = col[c][r];
  j.determinant = triple(d.su, d.sv, d.sw);
  return j;
}

Jacobian Volume::jacobian(double u, double v, double w) const { return interpatch::jacobian(derivatives(u, v, w)); }

PointGrid3 Volume::evaluate(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                            const progress_callback& progress) const {
  check_grid(*this, us, vs, ws, sizeof(Vec3), "volume evaluation grid");
  PointGrid3 out({us.size(), vs.size(), ws.size()}, for_overwrite);
  evaluate_into(us, vs, ws, std::span<Vec3>(out.data(), out.size()), progress);
  return out;
}

void Volume::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<const double> ws,
                           std::span<Vec3> out, const progress_callback& progress) const {
  detail::check_output_size(out.size(), {us.size(), vs.size(), ws.size()}, "volume evaluation");
  const auto dom = domain();
  check_domain(us, dom[0], "u");
  check_domain(vs, dom[1], "v");
  check_domain(ws, dom[2], "w");
  const std::size_t nv = vs.size(), nw = ws.size();
  pointwise(us.size(), nv, nw, progress, [&](std::size_t i, std::size_t j, std::size_t k) {
    out[(i * nv + j) * nw + k] = point(us[i], vs[j], ws[k]);
  });
}

Grid<VolumeDerivatives, 3> Volume::evaluate_derivatives(std::span<const double> us, std::span<const double> vs,
                                                        std::span<const double> ws) const {
  check_grid(*this, us, vs, ws, sizeof(VolumeDerivatives), "volume derivative grid");
  Grid<VolumeDerivatives, 3> out({us.size(), vs.size(), ws.size()}, for_overwrite);
  pointwise(us.size(), vs.size(), ws.size(), {},
            [&](std::size_t i, std::size_t j, std::size_t k) { out(i, j, k) = derivatives(us[i], vs[j], ws[k]); });
  return out;
}

VolumeJacobians Volume::evaluate_jacobians(std::span<const double> us, std::span<const double> vs,
                                           std::span<const double> ws, const progress_callback& progress) const {
  check_grid(*this, us, vs, ws, sizeof(Vec3) + sizeof(double), "volume Jacobian grid");
  VolumeJacobians out{PointGrid3({us.size(), vs.size(), ws.size()}), Grid<double, 3>({us.size(), vs.size(), ws.size()})};
  pointwise(us.size(), vs.size(), ws.size(), progress, [&](std::size_t i, std::size_t j, std::size_t k) {
    const VolumeDerivatives d = derivatives(us[i], vs[j], ws[k]);
    out.points(i, j, k) = d.s;
    out.determinants(i, j, k) = triple(d.su, d.sv, d.sw);
  });
  return out;
}

InvertedCells inverted_cells(const Volume& volume, std::size_t k, std::size_t max_locations) {
  if (k < 2) fail(errc::too_few_points, "the Jacobian check needs at least 2 samples per direction, got ", k);
  const auto dom = volume.domain();
  std::array<std::vector<double>, 3> t;
  for (std::size_t a = 0; a < 3; ++a) {
    t[a].resize(k);
    for (std::size_t i = 0; i < k; ++i)
      t[a][i] = dom[a].first + (dom[a].second - dom[a].first) * static_cast<double>(i) / static_cast<double>(k - 1);
    t[a].back() = dom[a].second;
  }
  InvertedCells r;
  r.samples = k * k * k;
  r.cells = (k - 1) * (k - 1) * (k - 1);
  r.min_determinant = std::numeric_limits<double>::infinity();
  r.max_determinant = -std::numeric_limits<double>::infinity();
  // Slabs of u layers of at most ~2^20 samples; a cell between two slabs sees the
  // last layer of the one before through `prev`.
  const std::size_t layer = k * k;
  const std::size_t slab = std::max<std::size_t>(1, (std::size_t{1} << 20) / layer);
  std::vector<char> prev(layer, 0), cur(layer, 0);
  for (std::size_t i0 = 0; i0 < k; i0 += slab) {
    const std::size_t i1 = std::min(k, i0 + slab);
    const auto d = volume.evaluate_derivatives(std::span<const double>(t[0]).subspan(i0, i1 - i0), t[1], t[2]);
    for (std::size_t i = i0; i < i1; ++i) {
      for (std::size_t j = 0; j < k; ++j)
        for (std::size_t m = 0; m < k; ++m) {
          const VolumeDerivatives& x = d(i - i0, j, m);
          // On the columns each scaled by a power of two to a largest component in
          // [1, 2) (exact): the product of their norms stays in range, the test does
          // not depend on the scale of the data, and det J is scaled back exactly.
          const int eu = scale_exponent(max_abs(x.su)), ev = scale_exponent(max_abs(x.sv)), ew = scale_exponent(max_abs(x.sw));
          const Vec3 su = ldexp(x.su, -eu), sv = ldexp(x.sv, -ev), sw = ldexp(x.sw, -ew);
          const double unit_det = triple(su, sv, sw);
          // Zero within rounding: a determinant's error is ~1e-16 of the columns' product.
          const bool bad = unit_det <= 1e-12 * norm(su) * norm(sv) * norm(sw);
          const double det = std::ldexp(unit_det, eu + ev + ew);
          cur[j * k + m] = bad ? 1 : 0;
          if (det < r.min_determinant) {
            r.min_determinant = det;
            r.min_at = {t[0][i], t[1][j], t[2][m]};
          }
          r.max_determinant = std::max(r.max_determinant, det);
          if (bad) {
            ++r.inverted_points;
            if (r.locations.size() < max_locations) r.locations.push_back({t[0][i], t[1][j], t[2][m]});
          }
        }
      if (i > 0)
        for (std::size_t j = 0; j + 1 < k; ++j)
          for (std::size_t m = 0; m + 1 < k; ++m) {
            const std::size_t a = j * k + m;
            if (prev[a] | prev[a + 1] | prev[a + k] | prev[a + k + 1] | cur[a] | cur[a + 1] | cur[a + k] | cur[a + k + 1])
              ++r.inverted_cells;
          }
      std::swap(prev, cur);
    }
  }
  return r;
}

}  // namespace interpatch
