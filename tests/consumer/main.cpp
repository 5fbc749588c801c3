// Interpolates a small grid through the public API and checks the data are met.
#include <interpatch/interpatch.hpp>

#include <cmath>
#include <cstdio>

int main() {
  using namespace interpatch;
  PointGrid q({5, 6});
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 6; ++j)
      q(i, j) = {double(i), double(j), std::sin(0.7 * double(i)) * std::cos(0.4 * double(j))};
  const auto r = interpolate_surface(q);
  double err = 0;
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 6; ++j)
      err = std::fmax(err, distance(r.surface.point(r.params_u[i], r.params_v[j]), q(i, j)));
  std::printf("max error at the data: %g\n", err);
  return err < 1e-12 ? 0 : 1;
}
