// Evaluating surfaces: a grid of points into memory the caller owns (surface.hpp's
// example), the normal and curvatures from the derivatives (evaluate.hpp), and
// refusing work too large for the machine before allocating (memory.hpp's example).
// Links interpatch::core only.

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <span>
#include <vector>

#include <interpatch/core.hpp>

#include "check.hpp"

namespace {

void blocks_of_rows() {
  // A Coons patch evaluated through the Surface interface, as any construction would be.
  const interpatch::BlendedSurface patch = interpatch::coons(
      {interpatch::line({0, 0, 0}, {2, 0, 0}), interpatch::HermiteCurve({{0, 1, 0}, {1, 1.2, 0.5}, {2, 1, 0}}).to_bspline(),
       interpatch::line({0, 0, 0}, {0, 1, 0}), interpatch::line({2, 0, 0}, {2, 1, 0})});
  const interpatch::Surface& surface = patch;
  const auto us = interpatch::linspace(0, 1, 100), vs = interpatch::linspace(0, 1, 80);
  // What the program does with each block; here: check it against the surface point by point.
  std::size_t rows_seen = 0;
  const auto consume = [&](std::span<const double> block, std::span<const interpatch::Vec3> out) {
    example::expect(out.size() == block.size() * vs.size(), "a block holds block.size() rows of vs.size() points");
    for (std::size_t a = 0; a < block.size(); ++a)
      for (std::size_t b = 0; b < vs.size(); ++b)
        example::expect_near(out[a * vs.size() + b], surface.point(block[a], vs[b]),
                             "S(block[a], vs[b]) is out[a * vs.size() + b]");
    rows_seen += block.size();
  };
  std::vector<interpatch::Vec3> rows(16 * vs.size());
  for (std::size_t i = 0; i < us.size(); i += 16) {
    const auto block = std::span(us).subspan(i, std::min<std::size_t>(16, us.size() - i));
    const auto out = std::span(rows).first(block.size() * vs.size());
    surface.evaluate_into(block, vs, out);
    consume(block, out);  // S(block[a], vs[b]) is out[a * vs.size() + b]
  }
  // 100 rows in blocks of 16: six full blocks and one of 4.
  example::expect(rows_seen == us.size(), "every row evaluated once");
  std::printf("%zu × %zu points in blocks of 16 rows, through a buffer of %zu points\n", us.size(), vs.size(),
              rows.size());
}

void normals_and_curvature() {
  using namespace interpatch;
  // z = u v, the bilinear patch of a saddle: at the origin S_u = (1, 0, 0),
  // S_v = (0, 1, 0), S_uv = (0, 0, 1), so K = −1, H = 0, k1 = 1, k2 = −1.
  const BlendedSurface saddle = bilinear({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 1});
  const SurfaceDerivatives d = saddle.derivatives(0, 0);
  const Curvature k = curvature(d);
  example::expect_near(unit_normal(d), {0, 0, 1}, "the normal at the origin is S_u × S_v");
  example::expect_near(k.gaussian, -1, "Gaussian curvature of z = x y at the origin");
  example::expect_near(k.mean, 0, "mean curvature of z = x y at the origin");
  example::expect_near(k.k1, 1, "k1 at the origin");
  example::expect_near(k.k2, -1, "k2 at the origin");
  std::printf("saddle z = x y at the origin: normal %s, K = %g, H = %g\n", example::str(unit_normal(d)).c_str(),
              k.gaussian, k.mean);
}

void refusing_large_work() {
  const std::size_t k = 100000;  // 10^10 points of 24 bytes: 240 GB
  try {
    interpatch::require_memory(k * k, 3 * sizeof(double), "evaluation grid 100000x100000");
    // Only a machine with 240 GB to spare gets here.
    example::expect(interpatch::available_memory() / 24 >= k * k, "require_memory() passes only when the grid fits");
    std::printf("this machine has room for a 100000 × 100000 grid\n");
  } catch (const interpatch::error& e) {
    example::expect(e.code() == interpatch::errc::too_large, "require_memory() refuses with errc::too_large");
    example::expect(interpatch::available_memory() / 24 < k * k, "require_memory() refuses only what does not fit");
    std::printf("refused before allocating: %s\n", e.what());
  }
}

}  // namespace

int main() {
  return example::run("evaluation", [] {
    blocks_of_rows();
    normals_and_curvature();
    refusing_large_work();
  });
}
