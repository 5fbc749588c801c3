#pragma once
// What the module's files share: NumPy arrays over memory the library owns, and
// JSON as Python objects.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/knot_vector.hpp"

namespace interpatch::python {

namespace py = pybind11;

// A NumPy array over memory a C++ object owns: the capsule frees the object when
// the array (and every view of it) is gone, so nothing is copied.
template <class Owner>
py::array_t<double> owning_array(std::unique_ptr<Owner> owner, double* data, std::vector<py::ssize_t> shape) {
  py::capsule free_it(owner.get(), [](void* p) { delete static_cast<Owner*>(p); });
  (void)owner.release();
  return py::array_t<double>(shape, data, free_it);
}

// A NumPy array over memory the construction owns, which nothing may write: the
// construction checked its numbers once, when it was built.
inline py::array_t<double> read_only(py::array_t<double> a) {
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

// A knot vector's values, over the memory `alive` keeps, read-only.
inline py::array_t<double> knots_array(const KnotVector& k, const py::capsule& alive) {
  return read_only(py::array_t<double>(static_cast<py::ssize_t>(k.size()), k.values().data(), alive));
}

// JSON as the Python objects json.loads makes of it.
inline py::object to_python(const nlohmann::ordered_json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

}  // namespace interpatch::python
