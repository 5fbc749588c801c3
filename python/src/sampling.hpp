#pragma once
// Graded meshes from Python: a sampling given as a dict (a spec's "sampling"), and the
// parameters of a mesh's nodes.

#include <mutex>
#include <optional>

#include <pybind11/pybind11.h>

#include "interpatch/io/outputs.hpp"

namespace interpatch::python {

namespace py = pybind11;

/// `sampling` (None, or a dict as a spec's "sampling") read as the spec reader reads
/// it for construction `c`. @throws error as io::read_sampling.
std::optional<Sampling> sampling_arg(const py::object& sampling, const io::Construction& c);

/// The parameters of a mesh's nodes along each direction, (u, v) or (u, v, w): res
/// (None: io::default_resolution) checked as `option` names it, `c` under `lock`, the
/// work without the GIL.
py::tuple mesh_params(io::Construction& c, std::mutex& lock, const py::object& res, const py::object& sampling,
                      const io::CountsOption& option);

}  // namespace interpatch::python
