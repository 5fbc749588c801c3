#pragma once
// What each query object of projection.hpp keeps: the exact form as a Spline, its
// pieces and their tree, and what the answers are evaluated on.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/projection.hpp"
#include "locate/pieces.hpp"

namespace interpatch::detail {

/// Pieces farther than the best distance so far less this share of the diagonal are
/// skipped: what they could hold is no more than that nearer, well inside the
/// 1e-10 of the diagonal the answers promise.
inline constexpr double prune_slack = 1e-11;

/// What the evaluation of points at q and p rounds by, and so how far an answer's
/// distance (from the construction's own point) may differ from the search's (about
/// the centre): 64 roundings of their largest coordinate.
inline double rounding_of(const Vec3& q, const Vec3& p) noexcept {
  return 64 * std::numeric_limits<double>::epsilon() * std::max(max_abs(q), max_abs(p));
}

struct CurveSearch {
  BSplineCurve curve;  // the answers' points
  Spline spline;
  PieceNets nets;
  std::vector<Piece> pieces;
  BoxTree tree;
  explicit CurveSearch(const BSplineCurve& c);
  [[nodiscard]] CurvePoint closest(const Vec3& q) const;
};

struct SurfaceSearch {
  const Surface* surface;  // the answers' points
  Spline spline;
  PieceNets nets;
  std::vector<Piece> pieces;
  BoxTree tree;
  /// A surface without an exact form is searched through a stand-in, a bicubic through
  /// its points on a grid of its parameters: the stand-in's pieces, their boxes widened
  /// by `widen` (4 times the largest gap measured between the two, in the spline's
  /// units), and Newton's iteration on the surface itself (`formula`).
  const Surface* formula = nullptr;
  double widen = 0;
  explicit SurfaceSearch(const Surface& s);
  /// A search on b, whose answers are points of `answers` (b's own, or a surface b is
  /// the exact form of); both outlive the search.
  SurfaceSearch(const BSplineSurface& b, const Surface& answers);
  /// S and its derivatives at (u, v) of piece pc, in the spline's units.
  [[nodiscard]] SurfaceDerivatives at(const Piece& pc, double u, double v) const;
  [[nodiscard]] SurfacePoint closest(const Vec3& q) const;
  /// The rest of a piece where the distance may have several minima (cut further).
  template <class Keep>
  void search_bent(const Piece& pc, const Vec3& q, const double& bound2, Keep&& keep) const;
  [[nodiscard]] std::vector<RayHit> intersect(const Vec3& origin, const Vec3& direction) const;
};

struct VolumeSearch {
  const Volume* volume;
  Spline spline;
  std::vector<Piece> pieces;
  BoxTree tree;
  // The boundary: each face of a direction that is not closed, with the direction
  // and end it lies at.
  struct Face {
    std::unique_ptr<BSplineSurface> surface;
    std::unique_ptr<SurfaceSearch> search;
    int axis;
    double at;
  };
  std::vector<Face> faces;
  explicit VolumeSearch(const Volume& v);
  /// e: v's exact form over v's domain.
  VolumeSearch(const Volume& v, const BSplineVolume& e);
  [[nodiscard]] VolumePoint locate(const Vec3& x) const;
};

/// f(i) for every i < n, on every thread in chunks of indices taken in turn (their
/// work differs).
template <class F>
void for_each_index(std::size_t n, const progress_callback& progress, F&& f) {
  constexpr std::size_t chunk = 256;
  const std::size_t chunks = (n + chunk - 1) / chunk;
  RegionProgress report(progress);
  std::atomic<std::size_t> done{0};
  parallel_for(chunks, chunks > 1, Share::one_by_one, [&](std::size_t c) {
    if (report.stopped()) return;
    const std::size_t end = std::min(n, (c + 1) * chunk);
    for (std::size_t i = c * chunk; i < end; ++i) f(i);
    const std::size_t d = done.fetch_add(1, std::memory_order_relaxed) + 1;
    if (thread_index() == 0) report.report(static_cast<double>(d) / static_cast<double>(chunks));
  });
  report.rethrow();
}

/// f(points[i]) into out[i] for every i, on every thread, after every point is found
/// finite.
template <class T, class F>
void for_each_point(std::span<const Vec3> points, std::span<T> out, const progress_callback& progress, F&& f) {
  if (out.size() != points.size())
    fail(errc::size_mismatch, "the output holds ", out.size(), " answers for ", points.size(), " points");
  if (const std::size_t k = first_non_finite(points.data(), points.size()); k < points.size())
    fail(errc::not_finite, "point ", k, " is ", num(points[k]), ": every coordinate must be finite");
  // In the order of a curve through space (Morton's), so that queries one after the
  // other visit the same pieces while their nets are in the cache; each answer still
  // goes to its own place, computed as it would be alone.
  const std::vector<std::uint32_t> order = spatial_order(points);
  for_each_index(points.size(), progress, [&](std::size_t k) {
    const std::size_t i = order.empty() ? k : order[k];
    out[i] = f(points[i]);
  });
}

}  // namespace interpatch::detail
