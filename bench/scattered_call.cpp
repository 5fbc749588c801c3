// bench/scattered_call: the library call a C++ program makes for scattered points,
// timed alone (no reading of the input, no writing of the result), the threads bound
// first as threads.hpp advises.
//
//   scattered_call POINTS.npy REPEATS control_points N | tolerance D
//
// Reads an (N, 3) array, then REPEATS times: approximate_scattered with param "xy" and
// N x N control points, or tolerance D. Prints one line per repeat: the call's seconds,
// the control points reached and the largest distance.

#include <chrono>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "interpatch/approximate.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/threads.hpp"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: scattered_call POINTS.npy REPEATS control_points|tolerance VALUE\n");
    return 2;
  }
  try {
    interpatch::bind_threads();
    const auto npy = interpatch::io::read_npy(argv[1]);
    if (npy.shape.size() != 2 || npy.shape[1] != 3) throw std::runtime_error("POINTS.npy: expected shape (N, 3)");
    std::vector<interpatch::Vec3> points(npy.shape[0]);
    for (std::size_t k = 0; k < points.size(); ++k) points[k] = {npy.data[3 * k], npy.data[3 * k + 1], npy.data[3 * k + 2]};
    const int repeats = std::stoi(argv[2]);
    const std::string way = argv[3];
    interpatch::ScatteredApproximationOptions options;
    options.param = interpatch::ScatteredParam::xy;
    if (way == "control_points") options.control_points = std::array<int, 2>{std::stoi(argv[4]), std::stoi(argv[4])};
    else if (way == "tolerance") options.tolerance = std::stod(argv[4]);
    else throw std::runtime_error("the third argument is control_points or tolerance");
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto fit = interpatch::approximate_scattered(points, options);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::printf("%.6f %d %d %.9g\n", seconds, fit.report.control_points[0], fit.report.control_points[1], fit.report.max_error);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scattered_call: %s\n", e.what());
    return 1;
  }
  return 0;
}
