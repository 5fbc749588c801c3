// Interpolates a small grid given as a spec, through the whole public API
// (interpatch::interpatch: core and io), and checks the data are met.
#include <interpatch/interpatch.hpp>

#include <cmath>
#include <cstdio>
#include <variant>

int main() {
  using namespace interpatch;
  nlohmann::json spec = {{"type", "interpolate"}, {"points", nlohmann::json::array()}};
  for (int i = 0; i < 5; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < 6; ++j) row.push_back({i, j, std::sin(0.7 * i) * std::cos(0.4 * j)});
    spec["points"].push_back(row);
  }
  const io::Construction c = io::build(spec);
  const auto& s = std::get<BSplineSurface>(*c.exact);
  const io::DataSet& d = c.data.at(0);
  double err = 0;
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 6; ++j)
      err = std::fmax(err, distance(s.point(d.params[0][i], d.params[1][j]), d.points[i * 6 + j]));
  std::printf("max error at the data: %g\n", err);
  return err < 1e-12 ? 0 : 1;
}
