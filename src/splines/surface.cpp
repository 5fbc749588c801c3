#include "interpatch/surface.hpp"

#include <algorithm>
#include <memory>
#include <vector>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/memory.hpp"

namespace interpatch {

PointGrid Surface::evaluate(std::span<const double> us, std::span<const double> vs,
                            const progress_callback& progress) const {
  require_memory(us.size() * vs.size(), sizeof(Vec3), "surface evaluation grid");
  PointGrid out({us.size(), vs.size()}, for_overwrite);
  evaluate_into(us, vs, std::span<Vec3>(out.data(), out.size()), progress);
  return out;
}

namespace {

// Rows evaluated by the surface's evaluate_into, the vs kept.
class DirectRows final : public Surface::Rows {
 public:
  DirectRows(const Surface& s, std::span<const double> vs) : s_(s), vs_(vs.begin(), vs.end()) {}
  void evaluate_into(std::span<const double> us, std::span<Vec3> out, const progress_callback& progress) const override {
    s_.evaluate_into(us, vs_, out, progress);
  }

 private:
  const Surface& s_;
  std::vector<double> vs_;
};

}  // namespace

void Surface::evaluate_normals_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> points,
                                    std::span<Vec3> normals, const progress_callback& progress) const {
  detail::check_output_size(points.size(), {us.size(), vs.size()}, "surface evaluation (points)");
  detail::check_output_size(normals.size(), {us.size(), vs.size()}, "surface evaluation (normals)");
  const std::size_t nu = us.size(), nv = vs.size();
  // Blocks of 2^17 points (18 MiB of derivatives): each block works out the surface's
  // functions of v again, so blocks of many rows.
  const std::size_t block = std::max<std::size_t>(1, (std::size_t{1} << 17) / std::max<std::size_t>(1, nv));
  for (std::size_t i0 = 0; i0 < nu; i0 += block) {
    const std::size_t nb = std::min(block, nu - i0);
    const auto d = evaluate_derivatives(us.subspan(i0, nb), vs);
    detail::parallel_for(nb * nv, nb * nv >= detail::parallel_min_work / 16, detail::Share::blocks, [&](std::size_t q) {
      points[i0 * nv + q] = d.data()[q].s;
      normals[i0 * nv + q] = unit_normal(d.data()[q]);
    });
    if (progress) progress(static_cast<double>(i0 + nb) / static_cast<double>(nu));
  }
  if (progress && nu == 0) progress(1.0);
}

std::unique_ptr<Surface::Rows> Surface::rows(std::span<const double> vs) const {
  return std::make_unique<DirectRows>(*this, vs);
}

namespace {

// A rectangle of the grid by the surface's evaluate_normals_into, the parameters kept.
class DirectNormalGrid final : public Surface::NormalGrid {
 public:
  DirectNormalGrid(const Surface& s, std::span<const double> us, std::span<const double> vs)
      : s_(s), us_(us.begin(), us.end()), vs_(vs.begin(), vs.end()) {}
  void evaluate_into(std::size_t i0, std::size_t ni, std::size_t j0, std::size_t nj, std::span<Vec3> points,
                     std::span<Vec3> normals) const override {
    detail::check_rectangle(i0, ni, j0, nj, us_.size(), vs_.size());
    s_.evaluate_normals_into(std::span(us_).subspan(i0, ni), std::span(vs_).subspan(j0, nj), points, normals);
  }

 private:
  const Surface& s_;
  std::vector<double> us_, vs_;
};

}  // namespace

std::unique_ptr<Surface::NormalGrid> Surface::normal_grid(std::span<const double> us, std::span<const double> vs) const {
  return std::make_unique<DirectNormalGrid>(*this, us, vs);
}

void Surface::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                            const progress_callback& progress) const {
  detail::check_output_size(out.size(), {us.size(), vs.size()}, "surface evaluation");
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  const std::size_t nv = vs.size();
  // point() of a surface of the user's own may throw: through parallel_for.
  const std::size_t nu = us.size();
  for (std::size_t r0 = 0; r0 < nu; r0 += 64) {
    const std::size_t r1 = std::min(nu, r0 + 64);
    detail::parallel_for(r1 - r0, nu * nv >= detail::parallel_min_work / 16, detail::Share::blocks, [&](std::size_t k) {
      const std::size_t i = r0 + k;
      for (std::size_t j = 0; j < nv; ++j) out[i * nv + j] = point(us[i], vs[j]);
    });
    if (progress) progress(static_cast<double>(r1) / static_cast<double>(nu));
  }
}

Grid<SurfaceDerivatives, 2> Surface::evaluate_derivatives(std::span<const double> us,
                                                          std::span<const double> vs) const {
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  require_memory(us.size() * vs.size(), sizeof(SurfaceDerivatives), "surface derivative grid");
  Grid<SurfaceDerivatives, 2> out({us.size(), vs.size()}, for_overwrite);
  detail::parallel_for(us.size(), us.size() * vs.size() >= detail::parallel_min_work / 16, detail::Share::blocks,
                       [&](std::size_t i) {
                         for (std::size_t j = 0; j < vs.size(); ++j) out(i, j) = derivatives(us[i], vs[j]);
                       });
  return out;
}

}  // namespace interpatch
