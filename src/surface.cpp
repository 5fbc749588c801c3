#include "interpatch/surface.hpp"

#include <algorithm>
#include <memory>
#include <vector>

#include "detail/parallel.hpp"
#include "detail/text.hpp"
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

std::unique_ptr<Surface::Rows> Surface::rows(std::span<const double> vs) const {
  return std::make_unique<DirectRows>(*this, vs);
}

void Surface::evaluate_into(std::span<const double> us, std::span<const double> vs, std::span<Vec3> out,
                            const progress_callback& progress) const {
  detail::check_output_size(out.size(), {us.size(), vs.size()}, "surface evaluation");
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  const std::size_t nv = vs.size();
  const auto nu = static_cast<long long>(us.size());
  for (long long r0 = 0; r0 < nu; r0 += 64) {
    const long long r1 = std::min(nu, r0 + 64);
#pragma omp parallel for schedule(static) if (us.size() * nv >= detail::parallel_min_work / 16)
    for (long long i = r0; i < r1; ++i)
      for (std::size_t j = 0; j < nv; ++j)
        out[static_cast<std::size_t>(i) * nv + j] = point(us[static_cast<std::size_t>(i)], vs[j]);
    if (progress) progress(static_cast<double>(r1) / static_cast<double>(nu));
  }
}

Grid<SurfaceDerivatives, 2> Surface::evaluate_derivatives(std::span<const double> us,
                                                          std::span<const double> vs) const {
  detail::check_unit_parameters(us, "u");
  detail::check_unit_parameters(vs, "v");
  require_memory(us.size() * vs.size(), sizeof(SurfaceDerivatives), "surface derivative grid");
  Grid<SurfaceDerivatives, 2> out({us.size(), vs.size()}, for_overwrite);
  const auto nu = static_cast<long long>(us.size());
#pragma omp parallel for schedule(static) if (us.size() * vs.size() >= detail::parallel_min_work / 16)
  for (long long i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < vs.size(); ++j)
      out(static_cast<std::size_t>(i), j) = derivatives(us[static_cast<std::size_t>(i)], vs[j]);
  return out;
}

}  // namespace interpatch
