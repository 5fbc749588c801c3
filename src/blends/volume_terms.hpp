#pragma once
// The terms of a blended volume (include/interpatch/blended_volume.hpp):
//
//   S(u,v,w) = Σ faces   f_a(t_a) · F(the other two parameters)
//            + Σ edges   c · f_a(t_a) g_b(t_b) · E(t_c)
//            + Σ corners f(u) g(v) h(w) · P
//
// Blending functions are Scalars (blended_terms.hpp: a B-spline whose x coordinate is
// the value, or a callable without exact form); every function, surface and line is
// over [0, 1] (faces over [0, 1]²). A face's surface
// is parametrized by the two other axes in increasing order (face of axis u by (v, w),
// of axis v by (u, w), of axis w by (u, v)); an edge's blends belong to the two
// axes other than its free axis c, in increasing order.

#include <array>
#include <string>
#include <vector>

#include "blends/blended_terms.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"

namespace interpatch::detail {

/// ∂^order S/∂s^order of a surface S(s, t) along its line s = at (fixed = 0), or
/// ∂^order S/∂t^order along t = at (fixed = 1), as a function of the other
/// parameter (order 0 or 1). The surface's control net is contracted with the fixed
/// parameter's basis and kept homogeneous, so lines of rational surfaces are exact too.
class IsoLine {
 public:
  IsoLine(const BSplineSurface& s, int fixed, double at, int order);

  struct Value {
    Vec3 d0, d1;  ///< the line's value and its derivative along the free parameter
  };
  /// The line at t, clamped to its domain. No allocation.
  [[nodiscard]] Value eval(double t) const noexcept;
  [[nodiscard]] const KnotVector& knots() const noexcept { return k_; }
  [[nodiscard]] bool rational() const noexcept { return rational_; }
  /// The line as a B-spline curve: exact for polynomial surfaces (which is when it is used).
  [[nodiscard]] BSplineCurve curve() const;

 private:
  using H = std::array<double, 4>;
  KnotVector k_;
  int order_;
  bool rational_;
  std::vector<H> h_[2];  // the net contracted with the fixed parameter's basis: order 0, and order 1 when asked
};

/// blend(t_axis) · surface(the other two parameters).
struct VolumeFace {
  int axis;
  std::size_t blend;
  BSplineSurface surface;
  std::string name;  // for messages: "face u0", "cross-derivative w1"
};

/// scale · f(t_a) · g(t_b) · line(t_c), c = axis, a < b the other two.
struct VolumeEdge {
  int axis;
  std::array<std::size_t, 2> blends;
  IsoLine line;
  double scale;
};

/// f(u) g(v) h(w) · point.
struct VolumeCorner {
  std::array<std::size_t, 3> blends;
  Vec3 point;
};

struct VolumeTerms {
  std::array<std::vector<Scalar>, 3> blends;  // functions of u, v, w
  std::vector<VolumeFace> faces;
  std::vector<VolumeEdge> edges;
  std::vector<VolumeCorner> corners;
  std::vector<std::string> notes;
};

/// At most this many blending functions per direction (the cubic Hermite four).
inline constexpr std::size_t max_volume_blends = 4;

/// The two axes other than `axis`, in increasing order.
constexpr std::array<int, 2> other_axes(int axis) noexcept {
  return axis == 0 ? std::array{1, 2} : (axis == 1 ? std::array{0, 2} : std::array{0, 1});
}

/// "u", "v" or "w".
constexpr const char* axis_letter(int axis) noexcept { return axis == 0 ? "u" : (axis == 1 ? "v" : "w"); }

/// S, S_s, S_t of a surface at (s, t), clamped to its domain, in one pass over the net.
std::array<Vec3, 3> surface_partials(const BSplineSurface& surface, double s, double t) noexcept;

/// The surface over [0, 1]².
BSplineSurface unit(const BSplineSurface& s);

}  // namespace interpatch::detail
