#include "locate/pieces.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <numeric>

#include "base/text.hpp"

namespace interpatch::detail {

void Spline::set_points(const Vec3* points, const double* weights, std::size_t count) {
  Box b;
  for (std::size_t i = 0; i < count; ++i) b.add(points[i]);
  centre = (b.lo + b.hi) * 0.5;
  const double d = distance(b.lo, b.hi);
  scale = d > 0 && std::isfinite(d) ? std::ldexp(1.0, std::ilogb(d) + 1) : 1.0;
  diagonal = d / scale;
  rational = weights != nullptr;
  cp.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double w = weights ? weights[i] : 1.0;
    const Vec3 p = local(points[i]) * w;
    cp[i] = {p.x, p.y, p.z, w};
  }
}

namespace {

constexpr int max_cuts = 5;           // halvings of one span along one direction
const double turn_limit = 0.7853981633974483;  // 45°: more than this along a line, and the piece is halved

using Net = BezierNet;

std::size_t index(const Net& net, int i, int j, int k) noexcept {
  return (static_cast<std::size_t>(i) * static_cast<std::size_t>(net.n[1]) + static_cast<std::size_t>(j)) *
             static_cast<std::size_t>(net.n[2]) +
         static_cast<std::size_t>(k);
}

// f(first index, stride) for every line of the net along axis.
template <class F>
void lines(const Net& net, int axis, F&& f) {
  const std::size_t st = axis == 0 ? static_cast<std::size_t>(net.n[1] * net.n[2])
                                   : (axis == 1 ? static_cast<std::size_t>(net.n[2]) : 1);
  for (int i = 0; i < (axis == 0 ? 1 : net.n[0]); ++i)
    for (int j = 0; j < (axis == 1 ? 1 : net.n[1]); ++j)
      for (int k = 0; k < (axis == 2 ? 1 : net.n[2]); ++k) f(index(net, i, j, k), st);
}

H4 lerp(const H4& a, const H4& b, double t) noexcept {
  const double s = 1 - t;
  return {s * a.x + t * b.x, s * a.y + t * b.y, s * a.z + t * b.z, s * a.w + t * b.w};
}

Vec3 euclid(const H4& h) noexcept { return Vec3{h.x, h.y, h.z} / h.w; }

// The Bézier points of knot span [T[p-1], T[p]] of a degree-p spline whose p+1 local
// control points are d[0], d[st], ..., in place: point k is the blossom at
// (T[p-1] p−k times, T[p] k times), each by de Boor's triangle.
void span_to_bezier(int p, const double* T, H4* d, std::size_t st) {
  std::array<H4, max_degree + 1> in, tmp;
  for (int j = 0; j <= p; ++j) in[static_cast<std::size_t>(j)] = d[static_cast<std::size_t>(j) * st];
  const double a = T[p - 1], b = T[p];
  for (int k = 0; k <= p; ++k) {
    tmp = in;
    for (int r = 1; r <= p; ++r) {
      const double x = r <= p - k ? a : b;
      for (int j = p; j >= r; --j) {
        const double l = T[j - 1], h = T[p + j - r];
        tmp[static_cast<std::size_t>(j)] = lerp(tmp[static_cast<std::size_t>(j - 1)], tmp[static_cast<std::size_t>(j)], (x - l) / (h - l));
      }
    }
    d[static_cast<std::size_t>(k) * st] = tmp[static_cast<std::size_t>(p)];
  }
}

// The halves of a Bézier line (p+1 points at d, stride st) at 1/2: de Casteljau.
void halve_line(int p, const H4* d, std::size_t st, H4* left, H4* right, std::size_t out_st) {
  std::array<H4, max_degree + 1> t;
  for (int j = 0; j <= p; ++j) t[static_cast<std::size_t>(j)] = d[static_cast<std::size_t>(j) * st];
  for (int r = 0; r <= p; ++r) {
    left[static_cast<std::size_t>(r) * out_st] = t[0];
    right[static_cast<std::size_t>(p - r) * out_st] = t[static_cast<std::size_t>(p - r)];
    for (int j = 0; j < p - r; ++j) t[static_cast<std::size_t>(j)] = lerp(t[static_cast<std::size_t>(j)], t[static_cast<std::size_t>(j + 1)], 0.5);
  }
}

// The largest total turning of the control lines along axis, in radians.
double line_turning(const Net& net, int axis) {
  double worst = 0;
  const int m = net.n[static_cast<std::size_t>(axis)];
  lines(net, axis, [&](std::size_t first, std::size_t st) {
    double total = 0;
    Vec3 prev{};
    bool have = false;
    for (int j = 0; j + 1 < m; ++j) {
      const Vec3 leg = euclid(net.h[first + static_cast<std::size_t>(j + 1) * st]) - euclid(net.h[first + static_cast<std::size_t>(j) * st]);
      const double len = norm(leg);
      if (!(len > 0)) continue;
      const Vec3 u = leg / len;
      if (have) total += std::acos(std::clamp(dot(prev, u), -1.0, 1.0));
      prev = u, have = true;
    }
    worst = std::max(worst, total);
  });
  return worst;
}

// The box of a net along its own directions: the first from its corners along u, the
// second along v made orthogonal to it (a curve: any), the third across both. Where a
// direction vanishes (a pole) the axes of space serve.
OrientedBox oriented(const Net& net, int dims) {
  OrientedBox b;
  std::vector<Vec3> x(net.h.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = euclid(net.h[i]);
  const int nu = net.n[0] - 1, nv = net.n[1] - 1, nw = net.n[2] - 1;
  const auto at = [&](int i, int j, int k) { return x[index(net, i, j, k)]; };
  Vec3 du = at(nu, 0, 0) - at(0, 0, 0) + at(nu, nv, nw) - at(0, nv, nw);
  Vec3 dv = dims >= 2 ? at(0, nv, 0) - at(0, 0, 0) + at(nu, nv, nw) - at(nu, 0, nw) : Vec3{};
  if (dims == 3) dv = Vec3{};  // volumes: the axes of space
  const double lu = norm(du);
  if (dims < 3 && lu > 0) {
    const Vec3 e0 = du / lu;
    Vec3 e1 = dv - dot(dv, e0) * e0;
    if (!(norm(e1) > 1e-8 * lu)) {  // a curve, or a v direction along u: any normal
      const Vec3 t = std::abs(e0.x) <= std::abs(e0.y) && std::abs(e0.x) <= std::abs(e0.z) ? Vec3{1, 0, 0}
                     : std::abs(e0.y) <= std::abs(e0.z)                                 ? Vec3{0, 1, 0}
                                                                                        : Vec3{0, 0, 1};
      e1 = cross(e0, t);
    }
    e1 = e1 / norm(e1);
    b.a = {e0, e1, cross(e0, e1)};
  }
  b.c = x[0];
  for (std::size_t i = 0; i < 3; ++i) b.lo[i] = 0, b.hi[i] = 0;
  for (const Vec3& p : x)
    for (std::size_t i = 0; i < 3; ++i) {
      const double s = dot(p - b.c, b.a[i]);
      b.lo[i] = std::min(b.lo[i], s), b.hi[i] = std::max(b.hi[i], s);
    }
  return b;
}

struct Cutter {
  const Spline& s;
  std::vector<Piece>& out;
  PieceNets* nets;
  std::size_t budget;  // of H4 points the nets may take

  void cut(Net& net, Piece piece, std::array<int, 3> cuts) {
    std::array<bool, 3> halve{};
    bool any = false;
    double turn = 0;
    for (int a = 0; a < s.dims; ++a) {
      const auto A = static_cast<std::size_t>(a);
      const double t = net.n[A] > 1 ? line_turning(net, a) : 0.0;
      turn = std::max(turn, t);
      halve[A] = cuts[A] < max_cuts && t > turn_limit;
      any = any || halve[A];
    }
    if (!any) {
      for (const H4& h : net.h) piece.box.add(euclid(h));
      piece.tight = oriented(net, s.dims);
      piece.turn = turn;
      if (s.dims == 2) piece.convex = net.convex_radius(piece.hi[0] - piece.lo[0], piece.hi[1] - piece.lo[1]);
      if (nets && nets->h.size() + net.h.size() <= budget) {
        piece.net = nets->h.size();
        nets->h.insert(nets->h.end(), net.h.begin(), net.h.end());
      } else if (nets) {
        budget = 0;  // over: none kept
      }
      out.push_back(piece);
      return;
    }
    for (int a = 0; a < s.dims; ++a) {
      const auto A = static_cast<std::size_t>(a);
      if (!halve[A]) continue;
      // Halve along a, then cut each half (which may halve along the later axes).
      Net left = net, right = net;
      const int p = net.n[A] - 1;
      lines(net, a, [&](std::size_t first, std::size_t st) {
        halve_line(p, &net.h[first], st, &left.h[first], &right.h[first], st);
      });
      const double mid = 0.5 * (piece.lo[A] + piece.hi[A]);
      Piece lp = piece, rp = piece;
      lp.hi[A] = mid, rp.lo[A] = mid;
      auto c = cuts;
      ++c[A];
      cut(left, lp, c);
      cut(right, rp, c);
      return;
    }
  }
};

}  // namespace

void BezierNet::halve(int axis, BezierNet& left, BezierNet& right) const {
  left = *this, right = *this;
  const Net& net = *this;
  const int p = n[static_cast<std::size_t>(axis)] - 1;
  lines(net, axis, [&](std::size_t first, std::size_t st) { halve_line(p, &h[first], st, &left.h[first], &right.h[first], st); });
}

OrientedBox BezierNet::bounds(int dims) const { return oriented(*this, dims); }

double BezierNet::turning(int axis) const { return line_turning(*this, axis); }

double BezierNet::convex_radius(double hu, double hv) const {
  const int p = n[0] - 1, q = n[1] - 1;
  if (p < 1 || q < 1) return 0;
  for (const H4& x : h)
    if (x.w != h[0].w) return 0;  // rational: no bound here
  const auto P = [&](int i, int j) {
    const H4& x = h[index(*this, i, j, 0)];
    return Vec3{x.x, x.y, x.z} / x.w;
  };
  // The piece as a whole: a normal n0 and two directions in its plane (its box's axes).
  const OrientedBox box = bounds(2);
  const Vec3 e0 = box.a[0], e1 = box.a[1], n0 = box.a[2];
  // The nets of S_u and S_v (their points hold every value of the derivative: the convex
  // hull), and the bounds they give: the least speed along e0 and e1, the largest S_u·S_v,
  // how far the tangents rise out of the plane of n0.
  std::vector<Vec3> du, dv;
  for (int i = 0; i < p; ++i)
    for (int j = 0; j <= q; ++j) du.push_back((P(i + 1, j) - P(i, j)) * (p / hu));
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j < q; ++j) dv.push_back((P(i, j + 1) - P(i, j)) * (q / hv));
  double su = std::numeric_limits<double>::infinity(), sv = su, cross_most = 0, rise = 0;
  for (const Vec3& a : du) su = std::min(su, dot(a, e0)), rise = std::max(rise, std::abs(dot(a, n0)) / norm(a));
  for (const Vec3& b : dv) sv = std::min(sv, dot(b, e1)), rise = std::max(rise, std::abs(dot(b, n0)) / norm(b));
  for (const Vec3& a : du)
    for (const Vec3& b : dv) cross_most = std::max(cross_most, std::abs(dot(a, b)));
  if (!(su > 0 && sv > 0)) return 0;
  // λ_min(JᵀJ) by Gershgorin: the least squared speed less the largest S_u·S_v.
  const double lmin = std::min(su * su, sv * sv) - cross_most;
  if (!(lmin > 0) || !(rise < 0.5)) return 0;  // a piece whose tangents leave its plane by 30° and more
  // The second derivatives' components along the normal: along n0, plus what the
  // normal's tilt (at most `rise`) lets the whole vector add.
  double nuu = 0, nuv = 0, nvv = 0;
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= q; ++j) {
      const auto part = [&](const Vec3& x) { return std::abs(dot(x, n0)) + rise * norm(x); };
      if (i + 2 <= p) nuu = std::max(nuu, part(P(i + 2, j) - 2 * P(i + 1, j) + P(i, j)) * (p * (p - 1) / (hu * hu)));
      if (j + 2 <= q) nvv = std::max(nvv, part(P(i, j + 2) - 2 * P(i, j + 1) + P(i, j)) * (q * (q - 1) / (hv * hv)));
      if (i + 1 <= p && j + 1 <= q)
        nuv = std::max(nuv, part(P(i + 1, j + 1) - P(i + 1, j) - P(i, j + 1) + P(i, j)) * (p * q / (hu * hv)));
    }
  // The largest normal curvature: the second fundamental form's largest value over the
  // first's least, II(e, e) / I(e, e) <= m / λ_min.
  const double m = 0.5 * (nuu + nvv) + std::sqrt(0.25 * (nuu - nvv) * (nuu - nvv) + nuv * nuv);
  // Where every point of the piece is nearer to q than 1/κ, the squared distance is
  // geodesically convex on the piece (its Hessian is I − (q − S)·II > 0), so it has one
  // minimum there, whatever the parametrization; half of that for the bounds' rounding
  // and for a piece that is only nearly convex in the surface's own metric.
  if (!(m > 0)) return std::numeric_limits<double>::infinity();
  return 0.5 * lmin / m;
}

std::vector<Piece> make_pieces(const Spline& s, PieceNets* nets) {
  std::array<int, 3> deg{0, 0, 0}, spans{1, 1, 1};
  for (int a = 0; a < s.dims; ++a) {
    const auto A = static_cast<std::size_t>(a);
    deg[A] = s.knots[A].degree();
    spans[A] = s.n[A];  // span indices run p .. n-1 over a clamped vector
  }
  std::vector<Piece> out;
  std::size_t budget = (std::size_t{256} << 20) / sizeof(H4);
  try {
    Net net;
    for (int a = 0; a < 3; ++a) net.n[static_cast<std::size_t>(a)] = deg[static_cast<std::size_t>(a)] + 1;
    net.h.resize(static_cast<std::size_t>(net.n[0] * net.n[1] * net.n[2]));
    std::array<int, 3> i{};
    for (i[0] = deg[0]; i[0] < spans[0]; ++i[0]) {
      for (i[1] = deg[1]; i[1] < spans[1]; ++i[1]) {
        for (i[2] = deg[2]; i[2] < spans[2]; ++i[2]) {
          Piece piece;
          bool empty = false;
          for (int a = 0; a < s.dims; ++a) {
            const auto A = static_cast<std::size_t>(a);
            const auto& k = s.knots[A];
            piece.span[A] = i[A];
            piece.lo[A] = k[static_cast<std::size_t>(i[A])];
            piece.hi[A] = k[static_cast<std::size_t>(i[A] + 1)];
            empty = empty || !(piece.lo[A] < piece.hi[A]);
          }
          if (empty) continue;
          for (int a = 0; a < net.n[0]; ++a)
            for (int b = 0; b < net.n[1]; ++b)
              for (int c = 0; c < net.n[2]; ++c)
                net.h[index(net, a, b, c)] = s.at(i[0] - deg[0] + a, i[1] - deg[1] + b, i[2] - deg[2] + c);
          for (int a = 0; a < s.dims; ++a) {
            const auto A = static_cast<std::size_t>(a);
            const double* T = s.knots[A].values().data() + (i[A] - deg[A] + 1);
            lines(net, a, [&](std::size_t first, std::size_t st) { span_to_bezier(deg[A], T, &net.h[first], st); });
          }
          Net copy = net;
          Cutter c{s, out, nets, budget};
          c.cut(copy, piece, {0, 0, 0});
          budget = c.budget;
        }
      }
    }
    if (nets) {
      nets->n = net.n;
      if (budget == 0) nets->h = {};
    }
  } catch (const std::bad_alloc&) {
    fail(errc::too_large, "the pieces of the exact form do not fit in memory (", out.size(), " made)");
  }
  return out;
}

namespace {

struct Builder {
  const std::vector<Piece>& pieces;
  std::vector<int>& order;
  std::vector<Box>& boxes;  // node boxes
  std::vector<std::array<int, 2>>& kids;

  int build(std::size_t b, std::size_t e) {
    const int me = static_cast<int>(boxes.size());
    boxes.emplace_back();
    kids.push_back({0, 0});
    Box box, centres;
    for (std::size_t i = b; i < e; ++i) {
      const Box& pb = pieces[static_cast<std::size_t>(order[i])].box;
      box.add(pb);
      centres.add((pb.lo + pb.hi) * 0.5);
    }
    boxes[static_cast<std::size_t>(me)] = box;
    if (e - b == 1) {
      kids[static_cast<std::size_t>(me)] = {-1 - order[b], 0};
      return me;
    }
    const Vec3 ext = centres.hi - centres.lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const std::size_t m = b + (e - b) / 2;
    std::nth_element(order.begin() + static_cast<std::ptrdiff_t>(b), order.begin() + static_cast<std::ptrdiff_t>(m),
                     order.begin() + static_cast<std::ptrdiff_t>(e), [&](int x, int y) {
                       const Box& bx = pieces[static_cast<std::size_t>(x)].box;
                       const Box& by = pieces[static_cast<std::size_t>(y)].box;
                       const double cx = bx.lo[axis] + bx.hi[axis], cy = by.lo[axis] + by.hi[axis];
                       return cx < cy || (cx == cy && x < y);
                     });
    const int l = build(b, m);
    const int r = build(m, e);
    kids[static_cast<std::size_t>(me)] = {l, r};
    return me;
  }
};

}  // namespace

BoxTree::BoxTree(const std::vector<Piece>& pieces) {
  if (pieces.empty()) return;
  std::vector<int> order(pieces.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<Box> boxes;
  std::vector<std::array<int, 2>> kids;
  boxes.reserve(2 * pieces.size());
  kids.reserve(2 * pieces.size());
  Builder{pieces, order, boxes, kids}.build(0, pieces.size());
  nodes_.resize(boxes.size());
  for (std::size_t k = 0; k < boxes.size(); ++k) nodes_[k] = {boxes[k], kids[k][0], kids[k][1]};
}

}  // namespace interpatch::detail

namespace interpatch::detail {

namespace {
// The bits of x (< 2^21) spread to every third place.
std::uint64_t spread(std::uint64_t x) noexcept {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}
}  // namespace

std::vector<std::uint32_t> spatial_order(std::span<const Vec3> points) {
  if (points.size() < 4096 || points.size() > 0xffffffffULL) return {};
  Box b;
  for (const Vec3& p : points) b.add(p);
  const Vec3 ext = b.hi - b.lo;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(points.size());
  const auto cell = [](double x, double lo, double e) {
    return e > 0 ? static_cast<std::uint64_t>(std::min(2097151.0, (x - lo) / e * 2097151.0)) : std::uint64_t{0};
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    keys[i] = {spread(cell(p.x, b.lo.x, ext.x)) | spread(cell(p.y, b.lo.y, ext.y)) << 1 | spread(cell(p.z, b.lo.z, ext.z)) << 2,
               static_cast<std::uint32_t>(i)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<std::uint32_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = keys[i].second;
  return order;
}

}  // namespace interpatch::detail
