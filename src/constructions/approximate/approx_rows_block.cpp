// The row-split fit's data source for a fit to a tolerance (approx_rows_block.hpp).

#include "constructions/approximate/approx_rows_block.hpp"

#include <algorithm>
#include <limits>
#include <span>

#include "constructions/approximate/approx_check.hpp"
#include "constructions/approximate/approx_knots.hpp"
#include "constructions/approximate/approx_passes.hpp"
#include "constructions/approximate/approx_rows_data_term.hpp"
#include "constructions/approximate/approx_rows_solve.hpp"
#include "constructions/approximate/approx_rows_transpose.hpp"
#include "constructions/approximate/approx_smoothing.hpp"

namespace interpatch::detail::approx {

Block::Block(const detail::RowTeam& team, const Shape<2>& shape, std::shared_ptr<const std::vector<Vec3>> own, const Vec3* pts,
      std::size_t first, std::size_t count, bool uniform, std::shared_ptr<const std::vector<double>> own_w,
      const double* w)
    : team_(&team), n_(shape), own_(std::move(own)), pts_(pts), first_(first), count_(count), uniform_(uniform),
      own_w_(std::move(own_w)), w_(w) {
  const std::size_t M = n_[1], base = first_ * M;
  if (!uniform_) {
    present_.resize(count_ * M);
    for (std::size_t i = 0; i < present_.size(); ++i) present_[i] = !is_missing(pts_[i]);
  }
  // Points without data (missing or of weight 0): the fill term (needs_fill).
  std::size_t empty[1] = {0};
  for (std::size_t i = 0; i < present_.size(); ++i) empty[0] += weight()(base + i) > 0 ? 0 : 1;
  team.sum(empty);
  fill_ = empty[0] > 0;
  std::vector<double> sum(1, static_cast<double>(n_[0] * M));
  if (!uniform_) {
    sum[0] = 0;
    team.fold(sum, [&](std::span<double> acc) {
      for (std::size_t i = 0; i < present_.size(); ++i)
        if (const double x = weight()(base + i); x > 0) acc[0] += x;
    });
  }
  weight_sum_ = sum[0];
  const std::vector<double> span = team.gather(std::vector<double>{static_cast<double>(first_), static_cast<double>(count_)});
  for (std::size_t s = 0; s < span.size(); s += 2) spans_.emplace_back(static_cast<std::size_t>(span[s]), static_cast<std::size_t>(span[s + 1]));
  cols_ = rows_to_columns(pts_, count_, M, team, {}, [&](std::size_t i, const Vec3&) { return weight()(base + i); });
  std::vector<double> box(6, -std::numeric_limits<double>::infinity());  // −lo, hi
  for (std::size_t i = 0; i < count_ * M; ++i)
    if (weight()(base + i) > 0)
      for (std::size_t k = 0; k < 3; ++k) {
        box[k] = std::max(box[k], -pts_[i][static_cast<int>(k)]);
        box[k + 3] = std::max(box[k + 3], pts_[i][static_cast<int>(k)]);
      }
  team.max(box);
  box_ = {Vec3{-box[0], -box[1], -box[2]}, Vec3{box[3], box[4], box[5]}};
}

void Block::fit(Fit<2>& f) const {
  ++f.fits;
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const std::vector<double> rhs = block_rhs(f.axes, cols_, n_[1], *team_);
  if (uniform_) {
    if (const auto lu = separable_solvers(f.axes, *team_); lu[0]) {
      f.lambda = 0;
      f.cp = team_->gather(separable_rows(lu, rhs, c0, c1, *team_));
      return;
    }
  }
  detail::GridBlock b;
  b.rank = 2;
  b.n = {n_[0], n_[1], 0};
  b.first = first_;
  b.count = count_;
  SparseSystem<2> sys = block_system(f.axes, n_, b, uniform_, weight(), weight_sum_, *team_);
  const std::vector<double> all_rhs = team_->gather(rhs);
  // The separable fit refused (uniform): the fill term settles what the data leave open.
  team_->run([&] { sparse_fit<2>(f, sys, all_rhs, std::nullopt, fill_ || uniform_); });
}

Residuals<2> Block::errors(const Fit<2>& f) const {
  const auto c0 = static_cast<std::size_t>(f.axes[0].c), c1 = static_cast<std::size_t>(f.axes[1].c);
  const Axis slice = axis_slice(f.axes[0], first_, count_);
  Shape<2> sh{c0, c1};
  std::vector<double> partial;
  basis_pass<false, 2>(slice, f.cp.data(), sh, 0, partial);
  const Residuals<2> mine =
      residual_blocks<2>(f.axes, n_, partial.data(), pts_, first_, first_, first_ + count_, weight());
  std::vector<double> pack{mine.max, static_cast<double>(mine.worst)};
  for (std::size_t a = 0; a < 2; ++a) {
    pack.insert(pack.end(), mine.interval_max[a].begin(), mine.interval_max[a].end());
    for (const std::size_t w : mine.interval_worst[a]) pack.push_back(static_cast<double>(w));
  }
  const std::vector<double> all = team_->gather(pack);
  Residuals<2> r(f.axes);
  for (std::size_t at = 0; at < all.size(); at += pack.size()) {
    Residuals<2> part(f.axes);
    const double* x = all.data() + at;
    part.max = *x++;
    part.worst = static_cast<std::size_t>(*x++);
    for (std::size_t a = 0; a < 2; ++a) {
      for (double& m : part.interval_max[a]) m = *x++;
      for (std::size_t& w : part.interval_worst[a]) w = static_cast<std::size_t>(*x++);
    }
    r.merge(part);
  }
  take_roots<2>(r);
  return r;
}

std::vector<double> Block::line_residuals(const Fit<2>& f, const std::array<std::optional<AxisSolver>, 2>& lu,
                                          const std::vector<std::pair<std::size_t, std::size_t>>& at) const {
  const std::size_t M = n_[1];
  const auto w = weight();
  auto holds = [&](std::size_t s, std::size_t row) { return row >= spans_[s].first && row < spans_[s].first + spans_[s].second; };
  std::vector<double> mine;
  auto put = [&](std::size_t flat) {
    const Vec3 v = point_or_fit<2>(f.axes, f.cp, n_, pts_[flat - first_ * M], w(flat) > 0, flat);
    mine.insert(mine.end(), {v.x, v.y, v.z});
  };
  for (const auto& [a, i] : at) {
    if (a == 0)
      for (std::size_t r = first_; r < first_ + count_; ++r) put(r * M + i % M);
    else if (holds(team_->process(), i / M))
      for (std::size_t j = 0; j < M; ++j) put(i / M * M + j);
  }
  const std::vector<double> all = team_->gather(mine);
  std::vector<std::vector<double>> lines;
  for (const auto& [a, i] : at) lines.emplace_back(3 * n_[a]);
  std::size_t from = 0;
  for (std::size_t s = 0; s < spans_.size(); ++s)
    for (std::size_t k = 0; k < at.size(); ++k) {
      const auto& [a, i] = at[k];
      if (a == 0) {
        std::copy_n(all.data() + from, 3 * spans_[s].second, lines[k].data() + 3 * spans_[s].first);
        from += 3 * spans_[s].second;
      } else if (holds(s, i / M)) {
        std::copy_n(all.data() + from, 3 * M, lines[k].data());
        from += 3 * M;
      }
    }
  std::vector<double> e;
  for (std::size_t k = 0; k < at.size(); ++k) {
    const auto& [a, i] = at[k];
    e.push_back(line_fit_residual(f.axes[a], *lu[a], lines[k], a == 0 ? i / M : i % M));
  }
  return e;
}

std::array<std::vector<bool>, 2> Block::has_data() const {
  std::array<std::vector<bool>, 2> has{std::vector<bool>(n_[0], true), std::vector<bool>(n_[1], true)};
  if (uniform_) return has;
  const auto w = weight();
  std::vector<double> rows(count_, 0.0), cols(n_[1], 0.0);
  for (std::size_t r = 0; r < count_; ++r)
    for (std::size_t j = 0; j < n_[1]; ++j)
      if (w((first_ + r) * n_[1] + j) > 0) rows[r] = cols[j] = 1.0;
  const std::vector<double> all = team_->gather(rows);
  team_->max(cols);
  for (std::size_t r = 0; r < n_[0]; ++r) has[0][r] = all[r] > 0;
  for (std::size_t j = 0; j < n_[1]; ++j) has[1][j] = cols[j] > 0;
  return has;
}

Block Block::thinned(const std::array<std::vector<std::size_t>, 2>& kept) const {
  const auto& rows = kept[0];
  const std::size_t lo = static_cast<std::size_t>(std::lower_bound(rows.begin(), rows.end(), first_) - rows.begin());
  const std::size_t hi = static_cast<std::size_t>(std::lower_bound(rows.begin(), rows.end(), first_ + count_) - rows.begin());
  const std::size_t K = kept[1].size();
  auto own = std::make_shared<std::vector<Vec3>>((hi - lo) * K);
  auto own_w = std::make_shared<std::vector<double>>(w_ ? (hi - lo) * K : 0);
  for (std::size_t r = lo; r < hi; ++r)
    for (std::size_t k = 0; k < K; ++k) {
      const std::size_t from = (rows[r] - first_) * n_[1] + kept[1][k], to = (r - lo) * K + k;
      (*own)[to] = pts_[from];
      if (w_) (*own_w)[to] = w_[from];
    }
  const Vec3* p = own->data();
  const double* w = w_ ? own_w->data() : nullptr;
  return {*team_, {rows.size(), K}, std::move(own), p, lo, hi - lo, uniform_, std::move(own_w), w};
}

}  // namespace interpatch::detail::approx
