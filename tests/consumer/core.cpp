// Interpolates a small grid with the core library alone (interpatch::core): no
// JSON library, no file formats.
#include <interpatch/core.hpp>

#ifdef NLOHMANN_JSON_VERSION_MAJOR
#error "interpatch/core.hpp pulled in nlohmann-json"
#endif

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
  // A Coons patch of four straight sides reproduces its corners.
  const BlendedSurface s = coons({line({0, 0, 0}, {1, 0, 0}), line({0, 1, 0}, {1, 1, 1}), line({0, 0, 0}, {0, 1, 0}),
                                  line({1, 0, 0}, {1, 1, 1})});
  err = std::fmax(err, distance(s.point(1, 1), Vec3{1, 1, 1}));
  std::printf("core: max error at the data: %g\n", err);
  return err < 1e-12 ? 0 : 1;
}
