#pragma once
/// @file projection.hpp
/// Where is a point? The closest point on a curve or a surface, the parameters of a
/// point of a volume, and where a ray meets a surface: the global answer, not a
/// local one.
///
/// Each query object splits its construction's exact B-spline form into Bézier
/// pieces (cut further where a piece turns), bounds each piece by the box of its
/// control points (the convex-hull property), and keeps the boxes in a tree. A query
/// visits the pieces nearest first, skips every piece whose box is farther than the
/// best answer so far, and runs a bounded Newton iteration (a step that does not
/// improve is halved, the parameters never leave the piece) in each piece it keeps.
/// The answer is checked before it is returned: it is the construction's own point
/// at the parameters given, and it is finite.

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"
#include "interpatch/vec3.hpp"
#include "interpatch/volume.hpp"

namespace interpatch {

/// The closest point C(t) of a curve, and its distance.
struct CurvePoint {
  double t = 0;
  Vec3 point;
  double distance = 0;
};

/// The closest point S(u, v) of a surface, and its distance.
struct SurfacePoint {
  double u = 0, v = 0;
  Vec3 point;
  double distance = 0;
};

/// A point x of space in a volume's parameters. Inside (residual |V(u, v, w) − x|
/// within 1e-10 of the volume's diagonal): (u, v, w) with V(u, v, w) = x. Outside:
/// the closest point of the volume's boundary, `point` = V(u, v, w), and `residual`
/// its distance from x.
struct VolumePoint {
  double u = 0, v = 0, w = 0;
  Vec3 point;
  bool inside = false;
  double residual = 0;
};

/// Where a ray o + t·d (t >= 0) meets a surface: S(u, v) = point = o + t·d.
struct RayHit {
  double t = 0, u = 0, v = 0;
  Vec3 point;
};

namespace detail {
struct CurveSearch;
struct SurfaceSearch;
struct VolumeSearch;
}  // namespace detail

/// Closest points on one curve. Built once (its Bézier pieces and their boxes), then
/// asked any number of times, from any number of threads at once.
///
/// Example:
/// @code
///   interpatch::BSplineCurve c(interpatch::KnotVector::bezier(2), {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}});
///   interpatch::CurveProjector on(c);
///   interpatch::CurvePoint p = on.closest({1, 3, 0});  // t = 0.5, point (1, 1, 0), distance 2
/// @endcode
class CurveProjector {
 public:
  /// @throws error too_large when the pieces would not fit in memory.
  explicit CurveProjector(const BSplineCurve& curve);
  ~CurveProjector();
  CurveProjector(CurveProjector&&) noexcept;
  CurveProjector& operator=(CurveProjector&&) noexcept;

  /// The closest point to q: no point of the curve is nearer than `distance` less
  /// 1e-10 of the curve's diagonal. @throws error not_finite (a coordinate of q).
  [[nodiscard]] CurvePoint closest(const Vec3& q) const;
  /// closest(points[i]) into out[i], on every thread; the same bits for any thread
  /// count. @throws error size_mismatch, not_finite (naming the first such point).
  void closest(std::span<const Vec3> points, std::span<CurvePoint> out, const progress_callback& progress = {}) const;

 private:
  std::unique_ptr<const detail::CurveSearch> s_;
};

/// Closest points on one surface and the hits of rays on it. The surface must
/// outlive the projector: answers are its own points.
///
/// Example:
/// @code
///   interpatch::SurfaceProjector on(surface);
///   interpatch::SurfacePoint p = on.closest({0.3, 0.4, 2.0});
///   std::vector<interpatch::RayHit> hits = on.intersect({0.5, 0.5, 5.0}, {0, 0, -1});
/// @endcode
class SurfaceProjector {
 public:
  /// Over the surface's exact form; a surface without one (Gregory's twist correction)
  /// is searched through a stand-in, the bicubic through its points on a 65 × 65 grid
  /// of its parameters, whose boxes are widened by 4 times the largest gap measured
  /// between the two, with Newton's iteration on the surface itself.
  /// @throws error too_large.
  explicit SurfaceProjector(const Surface& surface);
  /// The same with the surface's exact form given (one made already; it is searched,
  /// and must outlive the projector too). @throws error too_large.
  SurfaceProjector(const Surface& surface, const BSplineSurface& exact);
  ~SurfaceProjector();
  SurfaceProjector(SurfaceProjector&&) noexcept;
  SurfaceProjector& operator=(SurfaceProjector&&) noexcept;

  /// The closest point to q: no point of the surface is nearer than `distance` less
  /// 1e-10 of the surface's diagonal. @throws error not_finite.
  [[nodiscard]] SurfacePoint closest(const Vec3& q) const;
  /// closest(points[i]) into out[i], on every thread; the same bits for any thread
  /// count. @throws error size_mismatch, not_finite (naming the first such point).
  void closest(std::span<const Vec3> points, std::span<SurfacePoint> out, const progress_callback& progress = {}) const;

  /// Every point where the ray origin + t·direction, t >= 0, meets the surface,
  /// sorted by t; hits closer together than 1e-9 of the diagonal count once.
  /// @throws error not_finite, wrong_type (a zero direction).
  [[nodiscard]] std::vector<RayHit> intersect(const Vec3& origin, const Vec3& direction) const;
  /// intersect(origins[i], directions[i]) into out[i] for every ray, on every thread
  /// (one direction for all rays when directions holds one). @throws error
  /// size_mismatch, not_finite, wrong_type, naming the first such ray.
  void intersect(std::span<const Vec3> origins, std::span<const Vec3> directions, std::span<std::vector<RayHit>> out,
                 const progress_callback& progress = {}) const;

 private:
  std::unique_ptr<const detail::SurfaceSearch> s_;
};

/// The parameters of points of space in one volume (the inverse of its map). The
/// volume must outlive the locator.
///
/// Example:
/// @code
///   interpatch::VolumeLocator in(volume);
///   interpatch::VolumePoint p = in.locate({0.2, 0.3, 0.4});
///   if (p.inside) use(p.u, p.v, p.w);
/// @endcode
class VolumeLocator {
 public:
  /// @throws error no_exact_form, too_large.
  explicit VolumeLocator(const Volume& volume);
  /// The same with the volume's exact form given (one made already). @throws error too_large.
  VolumeLocator(const Volume& volume, const BSplineVolume& exact);
  ~VolumeLocator();
  VolumeLocator(VolumeLocator&&) noexcept;
  VolumeLocator& operator=(VolumeLocator&&) noexcept;

  /// @throws error not_finite.
  [[nodiscard]] VolumePoint locate(const Vec3& x) const;
  /// locate(points[i]) into out[i], on every thread; the same bits for any thread
  /// count. @throws error size_mismatch, not_finite (naming the first such point).
  void locate(std::span<const Vec3> points, std::span<VolumePoint> out, const progress_callback& progress = {}) const;

 private:
  std::unique_ptr<const detail::VolumeSearch> s_;
};

}  // namespace interpatch
