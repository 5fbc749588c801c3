// bench/same_calls: the calls tools/bench_python.py makes from Python, made from C++
// in the same way, so the two are compared call for call.
//
//   same_calls GRID.npy K REPEATS PARAM
//
// Reads an (n, m, 3) grid, then REPEATS times: interpolate_surface of the grid with
// PARAM parameters (uniform, chord or centripetal; copied in: the caller keeps its
// grid, as a Python caller keeps its array), then evaluate on
// K × K parameters spread evenly over the domain. Prints one line per repeat: the
// seconds of the interpolation and of the evaluation.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <utility>

#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/io/npy.hpp"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: same_calls GRID.npy K REPEATS uniform|chord|centripetal\n");
    return 2;
  }
  try {
    using clock_type = std::chrono::steady_clock;
    const auto npy = interpatch::io::read_npy(argv[1]);
    if (npy.shape.size() != 3 || npy.shape[2] != 3) throw std::runtime_error("GRID.npy: expected shape (n, m, 3)");
    interpatch::PointGrid grid({npy.shape[0], npy.shape[1]});
    for (std::size_t i = 0; i < grid.size(); ++i)
      grid.data()[i] = {npy.data[3 * i], npy.data[3 * i + 1], npy.data[3 * i + 2]};
    const auto k = static_cast<std::size_t>(std::stoul(argv[2]));
    const int repeats = std::stoi(argv[3]);
    const std::string name = argv[4];
    interpatch::SurfaceInterpolationOptions options;
    options.param = name == "uniform"       ? interpatch::Parametrization::uniform
                    : name == "centripetal" ? interpatch::Parametrization::centripetal
                                            : interpatch::Parametrization::chord;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = clock_type::now();
      auto fit = interpatch::interpolate_surface(grid, options);
      const auto t1 = clock_type::now();
      const auto [u0, u1] = fit.surface.domain_u();
      const auto [v0, v1] = fit.surface.domain_v();
      const auto points = fit.surface.evaluate(interpatch::linspace(u0, u1, k), interpatch::linspace(v0, v1, k));
      const auto t2 = clock_type::now();
      if (points.size() != k * k) throw std::runtime_error("evaluate gave the wrong number of points");
      std::printf("%.6f %.6f\n", std::chrono::duration<double>(t1 - t0).count(),
                  std::chrono::duration<double>(t2 - t1).count());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "same_calls: %s\n", e.what());
    return 1;
  }
  return 0;
}
