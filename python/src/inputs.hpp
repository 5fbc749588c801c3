#pragma once
// What the Python module takes from Python, checked where it is taken: arrays of real
// numbers (never complex, bool, object or text, whose conversion would lose or guess),
// masked arrays, spec dicts as JSON, counts, paths; and the progress hook through
// which Ctrl-C stops long work. Each error names the argument or the JSON Pointer.

#include <pybind11/pybind11.h>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/io/spec.hpp"
#include "interpatch/progress.hpp"

namespace interpatch::python {

namespace py = pybind11;

/// Parameters from any sequence or array of real numbers, as float64.
/// @throws error wrong_type (not numbers, a dtype that is not real, a masked array),
/// size_mismatch (not 1-D); each naming `name`.
std::vector<double> params(const py::handle& x, std::string_view name);

/// A point array of any real dtype and memory order, shape (..., 3), as the library
/// stores points (float64 triples in C order): the one copy an input costs. A masked
/// array's masked points (any coordinate masked) become NaN, which marks a missing
/// point where the spec allows one and is refused, with its place, where it does not.
/// @throws error wrong_type, size_mismatch, naming `name`.
std::shared_ptr<io::PointArray> point_array(const py::handle& x, const std::string& name);

/// A spec dict as JSON, value by value (no text in between): a value JSON cannot
/// hold is named by its JSON Pointer (/points/3/1). NumPy arrays and scalars are
/// taken as their lists and numbers.
/// @throws error not_finite (NaN, infinity), wrong_type (another type, a key that is
/// not a string).
nlohmann::json spec_json(const py::handle& x);

/// Counts of a mesh or a page, e.g. res: 2 or 3 whole numbers; one too large to
/// represent becomes the largest size_t, which the size checks refuse as too large.
/// @throws error wrong_type (not whole numbers, a negative count), size_mismatch
/// (not 2 or 3 counts).
std::vector<std::size_t> counts(const py::handle& x, std::string_view name);

/// A path given as str or os.PathLike. @throws error wrong_type naming `what`.
std::filesystem::path path_arg(const py::handle& x, std::string_view what);

/// The progress callback of long work run without the GIL: at most every 50 ms it
/// takes the GIL and runs Python's signal handlers, and what they raise (Ctrl-C's
/// KeyboardInterrupt) stops the work and is raised by the call.
progress_callback interruptible();

/// _core.spec_fields(): the reader's own field lists, so that
/// tests/python/test_spec_fields.py holds the keyword constructors (_specs.py) to them.
void bind_spec_fields(py::module_& m);

}  // namespace interpatch::python
