#include "interpatch/coons_volume.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "blends/blended_terms.hpp"
#include "base/data_scale.hpp"
#include "base/text.hpp"
#include "blends/volume_terms.hpp"

namespace interpatch {

using detail::axis_letter;
using detail::cat;
using detail::fail;

// The Boolean sum of one-dimensional projectors, one per direction, each a list of
// kinds: a blending function of t_a times the datum ∂^order S/∂t_a^order on the face
// t_a = end. The data of a kind are the given face (order 0) or cross-derivative
// field (order 1) there, a surface in the other two parameters. Products of
// projectors take their edge and corner data from every surface that holds them
// (two along an edge, three at a corner), check that those agree and use the mean.

namespace {

struct Kind {
  int end, order;
  std::size_t blend;
};

// The six faces and up to six cross-derivative fields over [0, 1]²: data[axis][end][order].
struct Data {
  std::vector<BSplineSurface> store;
  const BSplineSurface* at[3][2][2] = {};
};

std::string datum_name(int axis, int end, int order) {
  return cat(order == 0 ? "face " : "cross-derivative ", axis_letter(axis), end);
}

// "d/dv of face u0", "d2/dvdw of cross-derivative u0": a datum differentiated along `axes`.
std::string derived_name(int axis, int end, int order, const std::vector<int>& axes) {
  std::string d;
  if (axes.size() == 1) d = cat("d/d", axis_letter(axes[0]), " of ");
  if (axes.size() == 2) d = cat("d2/d", axis_letter(axes[0]), "d", axis_letter(axes[1]), " of ");
  return d + datum_name(axis, end, order);
}

// "S", "S_u", "S_vw", "S_uvw" for derivative orders per axis.
std::string quantity(const std::array<int, 3>& orders) {
  std::string s = "S";
  for (int a = 0; a < 3; ++a)
    if (orders[static_cast<std::size_t>(a)] > 0) s += (s.size() == 1 ? "_" : "") + std::string(axis_letter(a));
  return s;
}

errc code_for(int total_order) {
  return total_order == 0 ? errc::corner_gap : (total_order == 1 ? errc::tangent_mismatch : errc::incompatible_twist);
}

detail::DataScale scale_of(const Data& d) {
  detail::DataScale s;
  for (int a = 0; a < 3; ++a)
    for (int e = 0; e < 2; ++e) s.add(d.at[a][e][0]->control_points().values());
  return s;
}

// Where two lines along an edge are compared: every knot of either, and 7 points
// inside every span between them.
std::vector<double> edge_samples(const KnotVector& a, const KnotVector& b) {
  std::vector<double> k(a.values());
  k.insert(k.end(), b.values().begin(), b.values().end());
  std::sort(k.begin(), k.end());
  k.erase(std::unique(k.begin(), k.end()), k.end());
  std::vector<double> t;
  for (std::size_t i = 0; i + 1 < k.size(); ++i)
    for (int s = 0; s < 8; ++s) t.push_back(k[i] + (k[i + 1] - k[i]) * s / 8.0);
  t.push_back(k.back());
  return t;
}

// One edge datum of a product P_a P_b: ∂_a^{ka.order} ∂_b^{kb.order} S along t_c at
// t_a = ka.end, t_b = kb.end, from the data of both projectors.
struct EdgeDatum {
  int a, b, c;
  Kind ka, kb;
  detail::IsoLine line[2];
  std::string name[2];
};

class Builder {
 public:
  Builder(Data data, std::array<std::vector<Kind>, 3> kinds, std::optional<double> tolerance,
          std::shared_ptr<detail::VolumeTerms> terms)
      : d_(std::move(data)), kinds_(std::move(kinds)), t_(std::move(terms)) {
    const detail::DataScale scale = scale_of(d_);
    diag_ = scale.diagonal();
    tol_ = tolerance ? *tolerance : scale.strict();
    if (!(std::isfinite(tol_) && tol_ >= 0))
      fail(errc::out_of_domain, "tolerance ", tol_, " must be a finite number >= 0");
  }

  BlendedVolume build() {
    collect_edges();
    for (int order = 0; order <= 2; ++order)  // positions first: a gap explains what follows from it
      for (const auto& e : edges_)
        if (e.ka.order + e.kb.order == order) check_edge(e);
    std::vector<std::pair<std::array<std::size_t, 3>, Vec3>> corners;
    for (int order = 0; order <= 3; ++order)
      for (const Kind& ku : kinds_[0])
        for (const Kind& kv : kinds_[1])
          for (const Kind& kw : kinds_[2])
            if (ku.order + kv.order + kw.order == order) corners.push_back({{ku.blend, kv.blend, kw.blend}, corner({ku, kv, kw})});
    for (int a = 0; a < 3; ++a)
      for (const Kind& k : kinds_[static_cast<std::size_t>(a)])
        t_->faces.push_back({a, k.blend, *d_.at[a][k.end][k.order], datum_name(a, k.end, k.order)});
    for (auto& e : edges_)
      for (int s = 0; s < 2; ++s) t_->edges.push_back({e.c, {e.ka.blend, e.kb.blend}, e.line[s], -0.5});
    for (const auto& [blends, p] : corners) t_->corners.push_back({blends, p});
    t_->notes.push_back(cat("faces meet along their edges within ", max_gap_, max_gap_where_, " (tolerance ", tol_, ")"));
    return BlendedVolume(std::move(t_));
  }

 private:
  void collect_edges() {
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b) {
        const int c = 3 - a - b;
        for (const Kind& ka : kinds_[static_cast<std::size_t>(a)])
          for (const Kind& kb : kinds_[static_cast<std::size_t>(b)]) {
            // From the datum of a: a surface in (b, c) or (c, b) order, fixed in b.
            const int fb = detail::other_axes(a)[0] == b ? 0 : 1;
            const int fa = detail::other_axes(b)[0] == a ? 0 : 1;
            std::vector<int> da, db;
            if (kb.order) da.push_back(b);
            if (ka.order) db.push_back(a);
            edges_.push_back({a, b, c, ka, kb,
                              {detail::IsoLine(*d_.at[a][ka.end][ka.order], fb, kb.end, kb.order),
                               detail::IsoLine(*d_.at[b][kb.end][kb.order], fa, ka.end, ka.order)},
                              {derived_name(a, ka.end, ka.order, da), derived_name(b, kb.end, kb.order, db)}});
          }
      }
  }

  [[nodiscard]] double derivative_tolerance(const Vec3& x, const Vec3& y) const {
    return std::max(tol_, 1e-7 * std::max(norm(x), norm(y)));  // relative to the data's size
  }

  void check_edge(const EdgeDatum& e) {
    const int order = e.ka.order + e.kb.order;
    const std::string edge = cat("(", axis_letter(e.a), "=", e.ka.end, ", ", axis_letter(e.b), "=", e.kb.end, ")");
    double worst = -1, worst_t = 0, worst_tol = 0;
    Vec3 wx, wy;
    for (double t : edge_samples(e.line[0].knots(), e.line[1].knots())) {
      const Vec3 x = e.line[0].eval(t).d0, y = e.line[1].eval(t).d0;
      const double gap = distance(x, y);
      if (order == 0 && gap > max_gap_) {
        max_gap_ = gap;
        max_gap_where_ = cat(" (largest along the edge ", edge, " at ", axis_letter(e.c), " = ", t, ")");
      }
      const double tol = order == 0 ? tol_ : derivative_tolerance(x, y);
      if (gap > tol && gap > worst) {
        worst = gap;
        worst_t = t;
        worst_tol = tol;
        wx = x;
        wy = y;
      }
    }
    if (worst < 0) return;
    if (order == 0)
      fail(errc::corner_gap, "faces ", axis_letter(e.a), e.ka.end, " and ", axis_letter(e.b), e.kb.end,
           " disagree along their shared edge ", edge, " by ", worst, " at ", axis_letter(e.c), " = ", worst_t,
           " (tolerance ", worst_tol, ")");
    std::array<int, 3> orders{};
    orders[static_cast<std::size_t>(e.a)] = e.ka.order;
    orders[static_cast<std::size_t>(e.b)] = e.kb.order;
    fail(code_for(order), quantity(orders), " along the edge ", edge, ": ", e.name[0], " gives ", wx, " but ",
         e.name[1], " gives ", wy, " at ", axis_letter(e.c), " = ", worst_t, "; they differ by ", worst,
         " (tolerance ", worst_tol, ")");
  }

  // The corner datum of P_u P_v P_w for kinds k[0..2] from the three data holding it,
  // checked pairwise; their mean.
  Vec3 corner(const std::array<Kind, 3>& k) {
    std::array<int, 3> orders{}, ends{};
    for (std::size_t a = 0; a < 3; ++a) {
      orders[a] = k[a].order;
      ends[a] = k[a].end;
    }
    Vec3 x[3];
    std::string name[3];
    for (int a = 0; a < 3; ++a) {
      const auto o = detail::other_axes(a);
      const auto o0 = static_cast<std::size_t>(o[0]), o1 = static_cast<std::size_t>(o[1]);
      const auto& ka = k[static_cast<std::size_t>(a)];
      x[a] = d_.at[a][ka.end][ka.order]->derivative(ends[o0], ends[o1], orders[o0], orders[o1]);
      std::vector<int> along;
      if (orders[o0]) along.push_back(o[0]);
      if (orders[o1]) along.push_back(o[1]);
      name[a] = derived_name(a, ka.end, ka.order, along);
    }
    const int order = orders[0] + orders[1] + orders[2];
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j) {
        const double gap = distance(x[i], x[j]);
        const double tol = order == 0 ? tol_ : derivative_tolerance(x[i], x[j]);
        if (gap > tol)
          fail(code_for(order), "at corner p", ends[0], ends[1], ends[2], ", ", quantity(orders), " from ", name[i],
               " is ", x[i], " but from ", name[j], " it is ", x[j], ": they differ by ", gap, " (tolerance ", tol, ")");
      }
    return (x[0] + x[1] + x[2]) / 3.0;
  }

  Data d_;
  std::array<std::vector<Kind>, 3> kinds_;
  std::shared_ptr<detail::VolumeTerms> t_;
  std::vector<EdgeDatum> edges_;
  double diag_ = 0, tol_ = 0, max_gap_ = 0;
  std::string max_gap_where_;
};

Data face_data(const VolumeFaces& f, const VolumeCrossDerivatives* cross) {
  Data d;
  d.store.reserve(12);  // pointers into it stay valid
  const BSplineSurface* faces[3][2] = {{&f.u0, &f.u1}, {&f.v0, &f.v1}, {&f.w0, &f.w1}};
  for (int a = 0; a < 3; ++a)
    for (int e = 0; e < 2; ++e) {
      d.store.push_back(detail::unit(*faces[a][e]));
      d.at[a][e][0] = &d.store.back();
    }
  if (cross) {
    const std::optional<BSplineSurface>* fields[3][2] = {
        {&cross->u0, &cross->u1}, {&cross->v0, &cross->v1}, {&cross->w0, &cross->w1}};
    for (int a = 0; a < 3; ++a)
      for (int e = 0; e < 2; ++e)
        if (*fields[a][e]) {
          d.store.push_back(detail::unit(**fields[a][e]));
          d.at[a][e][1] = &d.store.back();
        }
  }
  return d;
}

}  // namespace

BlendedVolume coons_volume(const VolumeFaces& faces, const CoonsVolumeOptions& options) {
  auto t = std::make_shared<detail::VolumeTerms>();
  const Blend* blends[3] = {&options.blend_u, &options.blend_v, &options.blend_w};
  std::array<std::vector<Kind>, 3> kinds;
  for (std::size_t a = 0; a < 3; ++a) {
    const auto f = detail::scalar(*blends[a]);
    t->blends[a] = {detail::one_minus(f), f};
    kinds[a] = {{0, 0, 0}, {1, 0, 1}};
  }
  return Builder(face_data(faces, nullptr), std::move(kinds), options.tolerance, std::move(t)).build();
}

BlendedVolume coons_volume(const VolumeFaces& faces, const VolumeCrossDerivatives& cross,
                           const HermiteCoonsVolumeOptions& options) {
  auto t = std::make_shared<detail::VolumeTerms>();
  Data d = face_data(faces, &cross);
  std::array<std::vector<Kind>, 3> kinds;
  for (std::size_t a = 0; a < 3; ++a) {
    t->blends[a] = detail::hermite_scalars();  // α0, α1, β0, β1
    kinds[a] = {{0, 0, 0}, {1, 0, 1}};
    for (int e = 0; e < 2; ++e)
      if (d.at[a][e][1]) kinds[a].push_back({e, 1, 2 + static_cast<std::size_t>(e)});
  }
  return Builder(std::move(d), std::move(kinds), options.tolerance, std::move(t)).build();
}

}  // namespace interpatch
