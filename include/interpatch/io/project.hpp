#pragma once
/// @file io/project.hpp
/// What `interpatch project` and `interpatch intersect` write: the closest points of
/// a construction to points read from a file (the points of a volume located in it),
/// and the hits of rays on a surface. Both read and write a block of points at a
/// time: a file of any length takes the memory of one block.
///
/// Points: a .npy of float64 or float32, shape (..., 3), or a .csv of x, y, z lines
/// (a header line and lines starting with # are skipped). Rays: a .npy of shape
/// (..., 2, 3), origin then direction, or a .csv of 6 numbers a line.
///
/// `project` writes (`...` the points' shape without its 3):
///
/// | file | what |
/// |---|---|
/// | .npz | `params` (..., k), `points` (..., 3), `distance` (...); volumes also `inside` (...) bool |
/// | .npy | (N, k + 4) float64: the parameters, x, y, z, distance; volumes (N, 8) with inside as 0 or 1 last |
/// | .csv | a header (t or u,v or u,v,w, then x,y,z,distance, and inside for volumes), one line a point |
///
/// k is 1 for a curve, 2 for a surface and 3 for a volume. A volume's `distance` is
/// the residual |V(u, v, w) − x|: within 1e-10 of the diagonal inside, the distance
/// to the nearest boundary point outside.
///
/// `intersect` writes, for H hits of all rays, by ray and then by t: .npz `ray` (H,)
/// int64, `t` (H,), `params` (H, 2), `points` (H, 3); .npy (H, 7) float64 of ray, t, u,
/// v, x, y, z; .csv of the same columns.

#include <cstddef>
#include <filesystem>
#include <memory>

#include "interpatch/io/spec.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/projection.hpp"

namespace interpatch::io {

/// What a projection found.
struct ProjectionSummary {
  std::size_t points = 0;
  double max_distance = 0;  ///< the largest distance (residual, for a volume)
  std::size_t outside = 0;  ///< volumes: the points outside
};

/// The projector of a surface construction: over its exact form (made now if it is
/// deferred), answering with its points; without one (Gregory's twist correction),
/// over a stand-in of its formula, answering with the formula's points (see
/// SurfaceProjector). The construction must outlive it. @throws error no_exact_form
/// when it has neither, wrong_type for a volume.
[[nodiscard]] std::unique_ptr<SurfaceProjector> surface_projector(Construction& c, const progress_callback& progress = {});

/// Refuses (error wrong_type) an output `project` or `intersect` does not write:
/// .npz, .npy and .csv.
void check_projection_output(const std::filesystem::path& out);

/// The closest points of a curve, surface or volume (located) to the points of
/// `points`, written to `out` atomically.
/// @throws error as RowReader reads (file_unreadable, malformed_file), not_finite
///   (naming the point's index), no_exact_form, file_unwritable, too_large.
ProjectionSummary write_projection(Built& built, const std::filesystem::path& points, const std::filesystem::path& out,
                                   const progress_callback& progress = {});

/// The hits of the rays of `rays` on a surface, written to `out` atomically; the
/// number of hits. @throws error as write_projection, wrong_type (a volume or a
/// curve, a ray with a zero direction, naming its index).
std::size_t write_intersections(Construction& c, const std::filesystem::path& rays, const std::filesystem::path& out,
                                const progress_callback& progress = {});

}  // namespace interpatch::io
