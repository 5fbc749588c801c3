#pragma once
// The row-split fit's transposes between processes: a grid held in blocks of rows
// turned into every row of an even share of its columns (the points weighted on the
// way), and back.

#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "constructions/approximate/approx_axes.hpp"
#include "constructions/interpolate/grid_rows.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::detail::approx {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "points move between processes as triples of doubles");
inline const Vec3* as_points(const double* d) { return reinterpret_cast<const Vec3*>(d); }
inline Vec3* as_points(double* d) { return reinterpret_cast<Vec3*>(d); }

// Every point present weighs 1, a missing one 0.
struct PresentWeighsOne {
  double operator()(std::size_t, const Vec3& q) const { return is_missing(q) ? 0.0 : 1.0; }
};

// A rows × width array of points held in consecutive blocks of rows (`mine` here),
// turned into columns: every row of this process's even share of the columns. Each
// point goes as w·Q, w = weight(its index among `rows`, Q), and as zeros where w is
// 0 (a missing point): the weighted data of right_hand_side, multiplied as there.
// `packed` is called once the rows are read.
template <class Weight = PresentWeighsOne>
std::vector<double> rows_to_columns(const Vec3* rows, std::size_t mine, std::size_t width, const detail::RowTeam& team,
                                    const std::function<void()>& packed = {}, const Weight& weight = {}) {
  const std::size_t P = team.processes(), me = team.process();
  const std::vector<double> counts = team.gather(std::vector<double>{static_cast<double>(mine)});
  std::size_t total = 0;
  for (const double c : counts) total += static_cast<std::size_t>(c);
  const std::size_t C = detail::even_share(width, me, P).second;
  std::vector<double> send;
  team.run([&] {
    require_memory(mine * width + total * C, sizeof(Vec3), "a transpose of the data between processes");
    send.resize(3 * mine * width);
  });
  std::vector<std::size_t> sc(P), rc(P);
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    const std::pair<std::size_t, std::size_t> cols = detail::even_share(width, s, P);
    for (std::size_t i = 0; i < mine; ++i) {
      const Vec3* from = rows + i * width + cols.first;
      Vec3* to = as_points(send.data()) + at + i * cols.second;
      for (std::size_t k = 0; k < cols.second; ++k) {
        const double w = weight(i * width + cols.first + k, from[k]);
        for (int x = 0; x < 3; ++x) to[k][x] = w > 0 ? w * from[k][x] : 0.0;
      }
    }
    sc[s] = mine * cols.second;
    rc[s] = static_cast<std::size_t>(counts[s]) * C;
    at += sc[s];
  }
  if (packed) packed();
  std::vector<double> out;
  team.run([&] { out.resize(3 * total * C); });
  team.exchange(as_points(send.data()), sc, as_points(out.data()), rc);
  return out;
}

// The reverse with a new split: columns (total × this process's even share of the
// width) to this process's even share of the rows, whole.
std::vector<double> columns_to_rows(const std::vector<double>& cols, std::size_t total, std::size_t width,
                                    const detail::RowTeam& team);

}  // namespace interpatch::detail::approx
