#pragma once
// The pieces every query of projection.hpp searches: an exact form as a clamped
// B-spline of 1, 2 or 3 parameters with homogeneous control points about its centre,
// cut into Bézier pieces bounded by the boxes of their control points, the boxes in a
// tree.

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <limits>
#include <utility>
#include <vector>

#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail {

/// An axis-aligned box; empty (lo > hi) until a point is added.
struct Box {
  Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()};
  Vec3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity()};
  void add(const Vec3& p) noexcept {
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  }
  void add(const Box& b) noexcept { add(b.lo), add(b.hi); }
  /// The squared distance from q to the box, 0 inside it.
  [[nodiscard]] double distance2(const Vec3& q) const noexcept {
    double s = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = q[a] < lo[a] ? lo[a] - q[a] : (q[a] > hi[a] ? q[a] - hi[a] : 0.0);
      s += d * d;
    }
    return s;
  }
  /// Whether the line o + t·d meets the box (widened by `slack`) at some t >= 0.
  [[nodiscard]] bool meets_ray(const Vec3& o, const Vec3& d, double slack) const noexcept {
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      const double l = lo[a] - slack, h = hi[a] + slack;
      if (d[a] == 0) {
        if (o[a] < l || o[a] > h) return false;
        continue;
      }
      double ta = (l - o[a]) / d[a], tb = (h - o[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    return true;
  }
};

/// A box along its own orthonormal axes: tight about a piece that is tilted or thin,
/// where the axis-aligned box is not (a gently curved piece makes a flat one).
struct OrientedBox {
  Vec3 c;
  std::array<Vec3, 3> a{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  std::array<double, 3> lo{}, hi{};
  [[nodiscard]] double distance2(const Vec3& q) const noexcept {
    const Vec3 d = q - c;
    double s = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const double x = dot(d, a[i]);
      const double e = x < lo[i] ? lo[i] - x : (x > hi[i] ? x - hi[i] : 0.0);
      s += e * e;
    }
    return s;
  }
  /// The largest distance from q to a point of the box.
  [[nodiscard]] double farthest(const Vec3& q) const noexcept {
    const Vec3 d = q - c;
    double s = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const double x = dot(d, a[i]);
      const double e = std::max(std::abs(x - lo[i]), std::abs(x - hi[i]));
      s += e * e;
    }
    return std::sqrt(s);
  }
  [[nodiscard]] bool meets_ray(const Vec3& o, const Vec3& d, double slack) const noexcept {
    Box local;
    local.lo = {lo[0], lo[1], lo[2]}, local.hi = {hi[0], hi[1], hi[2]};
    const Vec3 r = o - c;
    return local.meets_ray({dot(r, a[0]), dot(r, a[1]), dot(r, a[2])}, {dot(d, a[0]), dot(d, a[1]), dot(d, a[2])}, slack);
  }
};

/// A homogeneous control point (x w, y w, z w, w).
struct H4 {
  double x, y, z, w;
};

/// A clamped B-spline of `dims` parameters (1 curve, 2 surface, 3 volume): control
/// points n[0] × n[1] × n[2] in C order (n = 1 along unused directions), homogeneous,
/// their Euclidean points taken about `centre` (coordinates far from the origin keep
/// their digits in the differences).
struct Spline {
  int dims = 0;
  std::vector<KnotVector> knots;  // dims of them, clamped
  std::array<int, 3> n{1, 1, 1};
  std::vector<H4> cp;
  bool rational = false;
  Vec3 centre;
  /// A power of two about the size of the control points' box: the points are stored
  /// (and queries taken) as (x − centre) / scale, exact, so that squares of tiny or huge
  /// coordinates neither underflow nor overflow.
  double scale = 1;
  /// The diagonal of the control points' box over scale (about 1): every tolerance of
  /// a query is relative to it.
  double diagonal = 0;
  /// A point of space in the stored units.
  [[nodiscard]] Vec3 local(const Vec3& x) const noexcept { return (x - centre) * (1 / scale); }

  [[nodiscard]] const H4& at(int i, int j, int k) const noexcept {
    return cp[(static_cast<std::size_t>(i) * static_cast<std::size_t>(n[1]) + static_cast<std::size_t>(j)) *
                  static_cast<std::size_t>(n[2]) +
              static_cast<std::size_t>(k)];
  }
  /// Fills centre, diagonal and the homogeneous points from Euclidean points (C order)
  /// and weights (empty: all 1).
  void set_points(const Vec3* points, const double* weights, std::size_t count);
};

/// One Bézier piece: its knot spans, its parameter box and a box holding all its points.
struct Piece {
  std::array<int, 3> span{};
  std::size_t net = 0;  // where its Bézier net starts in PieceNets::h, when they are kept
  std::array<double, 3> lo{}, hi{};
  Box box;
  OrientedBox tight;  // along the piece's own directions
  double turn = 0;    // the most its control lines turn along one direction, radians
  double convex = 0;  // BezierNet::convex_radius of its net
};

/// A Bézier net: n[0] × n[1] × n[2] homogeneous points in C order, which can be
/// halved and bounded (a piece cut further while a query searches it).
struct BezierNet {
  std::array<int, 3> n{1, 1, 1};
  std::vector<H4> h;
  /// The halves at the middle of `axis`.
  void halve(int axis, BezierNet& left, BezierNet& right) const;
  /// The box along the net's own directions (dims: 1, 2 or 3 parameters).
  [[nodiscard]] OrientedBox bounds(int dims) const;
  /// The most its control lines along `axis` turn, radians.
  [[nodiscard]] double turning(int axis) const;
  /// For a polynomial surface net over a parameter box hu × hv: a distance r such that
  /// for every point q closer than r to every point of the piece, |S − q|² is strictly
  /// convex over the box, so that it has one minimum there. From bounds of the second
  /// derivatives (the nets of the second differences) and of the Jacobian's smallest
  /// singular value (at the centre, less what the second derivatives can change it):
  /// Hess ≥ (σ − ε)² − r·m2 > 0. 0 for a rational net, or where the bound says nothing.
  [[nodiscard]] double convex_radius(double hu, double hv) const;
};

/// The Bézier nets of the pieces, (p+1) × (q+1) × (r+1) homogeneous points each in C
/// order: a piece's points and derivatives from its net cost no knot arithmetic.
struct PieceNets {
  std::vector<H4> h;
  std::array<int, 3> n{1, 1, 1};
  [[nodiscard]] bool kept() const noexcept { return !h.empty(); }
};

/// The pieces of s: one per non-empty knot span, each halved (recursively, up to five
/// times) along every direction whose control lines turn by more than 45°, so that a
/// piece holds one bend at most and a Newton iteration started inside it finds its
/// nearest point. @throws error too_large.
/// With `nets`, their Bézier nets too while they take at most 256 MiB (otherwise
/// nets stays empty). @throws error too_large.
[[nodiscard]] std::vector<Piece> make_pieces(const Spline& s, PieceNets* nets = nullptr);

/// The points' indices sorted along Morton's curve through their box (empty for fewer
/// than 4096 points, or more than 2^32, which are taken in their own order).
[[nodiscard]] std::vector<std::uint32_t> spatial_order(std::span<const Vec3> points);

/// A binary tree of the pieces' boxes, split at the median of the longest side.
class BoxTree {
 public:
  explicit BoxTree(const std::vector<Piece>& pieces);

  /// visit(piece index) for the pieces whose box is nearer to q than sqrt(bound2), the
  /// nearest boxes first; visit may lower bound2 (the best distance so far, squared).
  template <class Visit>
  void nearest(const Vec3& q, double& bound2, Visit&& visit) const {
    if (nodes_.empty()) return;
    int node[128];  // uninitialized: a query's stack costs nothing to set up
    double dist[128];
    int top = 0;
    node[top] = 0, dist[top++] = nodes_[0].box.distance2(q);
    while (top > 0) {
      --top;
      int k = node[top];
      double d2 = dist[top];
      while (true) {
        if (d2 >= bound2) break;
        const Node& n = nodes_[static_cast<std::size_t>(k)];
        if (n.left < 0) {
          visit(static_cast<std::size_t>(-1 - n.left));
          break;
        }
        const double dl = nodes_[static_cast<std::size_t>(n.left)].box.distance2(q);
        const double dr = nodes_[static_cast<std::size_t>(n.right)].box.distance2(q);
        const bool left_first = dl <= dr;
        // The farther child waits; the nearer one is followed now.
        node[top] = left_first ? n.right : n.left, dist[top++] = left_first ? dr : dl;
        k = left_first ? n.left : n.right;
        d2 = left_first ? dl : dr;
      }
    }
  }

  /// visit(piece index) for every piece whose box, and every box above it, passes
  /// test(box), in the tree's order.
  template <class Test, class Visit>
  void where(Test&& test, Visit&& visit) const {
    if (nodes_.empty()) return;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
      if (!test(n.box)) continue;
      if (n.left < 0) {
        visit(static_cast<std::size_t>(-1 - n.left));
        continue;
      }
      stack[top++] = n.right;
      stack[top++] = n.left;
    }
  }

 private:
  struct Node {
    Box box;
    int left = 0, right = 0;  // a leaf: left = -1 - its piece
  };
  std::vector<Node> nodes_;
};

}  // namespace interpatch::detail
