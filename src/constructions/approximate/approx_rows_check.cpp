// The row-split fit's check of its control net (approx_rows_check.hpp).

#include "constructions/approximate/approx_rows_check.hpp"

namespace interpatch::detail::approx {

void check_rows_net(const detail::ApproxRows& out, const std::vector<Vec3>& box, const detail::RowTeam& team) {
  const detail::ApproxData corners{{box.size()}, box, {}};
  team.run([&] {
    if (out.rows.empty()) return;
    detail::check_approx_net(out.rows, {out.rows.size() / out.net[1], out.net[1]}, corners, "surface approximation");
  });
}

}  // namespace interpatch::detail::approx
