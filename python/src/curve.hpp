#pragma once
// interpatch.Curve: a curve spec, built, with its evaluation, exact form, description
// and files.

#include <pybind11/pybind11.h>

#include "interpatch/io/spec.hpp"

namespace interpatch::python {

namespace py = pybind11;

/// The Python Curve of a built curve spec.
py::object wrap_curve(io::CurveConstruction c);

/// Adds the Curve class to the module.
void bind_curve(py::module_& m);

}  // namespace interpatch::python
