// Graded meshes: the example of grading.hpp (a channel's nodes clustered at its
// wall), run and its comments checked. Links interpatch::core only.

#include <cstdio>

#include <interpatch/core.hpp>

#include "check.hpp"

namespace {

void channel_nodes(const interpatch::Surface& channel) {
  interpatch::Sampling s;
  s[0] = {.count = 41, .first = 1e-3};
  s[1] = {.count = 101};
  interpatch::GradedParameters g = interpatch::graded_parameters(channel, s);
  interpatch::PointGrid nodes = channel.evaluate(g.params[0], g.params[1]);
  double achieved = g.report[0].first;  // 1e-3, to 1e-9 of it
  example::expect(achieved <= 1e-3 && achieved >= 1e-3 * (1 - 1e-9), "1e-3, to 1e-9 of it");
  double longest = 0;
  for (std::size_t j = 0; j < 101; ++j) longest = std::max(longest, interpatch::distance(nodes(1, j), nodes(0, j)));
  example::expect_near(longest, achieved, "the report is the mesh's longest first cell", 1e-18);
  std::printf("channel: 41 x 101 nodes, first cell %s at the wall, cells grow by at most %s\n",
              example::str(achieved).c_str(), example::str(g.report[0].growth).c_str());
}

}  // namespace

int main() {
  return example::run("grading", [] {
    // A channel 0.2 wide (u) and 1 long (v), its far wall bulging.
    const interpatch::BlendedSurface channel =
        interpatch::bilinear({0, 0, 0}, {0, 1, 0}, {0.2, 0, 0}, {0.25, 1, 0});
    channel_nodes(channel);
  });
}
