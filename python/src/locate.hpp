#pragma once
// Where points are, from Python: closest points on curves and surfaces, points of
// volumes, rays on surfaces; NumPy in and out, the work without the GIL.

#include <pybind11/pybind11.h>

#include "interpatch/projection.hpp"

namespace interpatch::python {

namespace py = pybind11;

/// {"params": (..., k), "points": (..., 3), "distance": (...,)} for points of shape
/// (..., 3): k = 1 on a curve, 2 on a surface.
py::dict closest_points(const CurveProjector& on, const py::handle& points);
py::dict closest_points(const SurfaceProjector& on, const py::handle& points);
/// {"params": (..., 3), "points": (..., 3), "inside": (...,) bool, "residual": (...,)}.
py::dict locate(const VolumeLocator& in, const py::handle& points);
/// Every hit of the rays origins[i] + t·directions[i] (directions (3,) for all rays
/// alike): {"ray": (H,) int64, "t": (H,), "params": (H, 2), "points": (H, 3)}, by ray,
/// then by t.
py::dict intersect(const SurfaceProjector& on, const py::handle& origins, const py::handle& directions);

}  // namespace interpatch::python
