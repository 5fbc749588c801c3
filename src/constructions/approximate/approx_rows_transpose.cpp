// The row-split fit's transpose from columns back to rows (approx_rows_transpose.hpp).

#include "constructions/approximate/approx_rows_transpose.hpp"

#include <algorithm>

namespace interpatch::detail::approx {

std::vector<double> columns_to_rows(const std::vector<double>& cols, std::size_t total, std::size_t width,
                                    const detail::RowTeam& team) {
  const std::size_t P = team.processes(), me = team.process();
  const std::size_t C = detail::even_share(width, me, P).second, mine = detail::even_share(total, me, P).second;
  std::vector<std::size_t> sc(P), rc(P);
  for (std::size_t s = 0; s < P; ++s) {
    sc[s] = detail::even_share(total, s, P).second * C;
    rc[s] = mine * detail::even_share(width, s, P).second;
  }
  std::vector<double> recv, out;
  team.run([&] {
    require_memory(2 * mine * width, sizeof(Vec3), "a transpose of the data between processes");
    recv.resize(3 * mine * width);
    out.resize(3 * mine * width);
  });
  // The columns are in row order: process s's rows are the s-th run of them.
  team.exchange(as_points(cols.data()), sc, as_points(recv.data()), rc);
  std::size_t at = 0;
  for (std::size_t s = 0; s < P; ++s) {
    const std::pair<std::size_t, std::size_t> c = detail::even_share(width, s, P);
    for (std::size_t v = 0; v < mine; ++v, at += c.second)
      std::copy_n(recv.data() + 3 * at, 3 * c.second, out.data() + 3 * (v * width + c.first));
  }
  return out;
}

}  // namespace interpatch::detail::approx
