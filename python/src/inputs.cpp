// What the Python module takes from Python, checked where it is taken.

#include "inputs.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "interpatch/error.hpp"

namespace interpatch::python {

namespace {

[[noreturn]] void fail(errc code, const std::string& message) { throw error(code, message); }

std::string type_name(const py::handle& x) { return py::str(py::type::handle_of(x).attr("__name__")).cast<std::string>(); }

// NumPy converts complex (dropping the imaginary part), bool, object and text arrays
// to float64 with at most a warning: only real numbers are taken.
void require_real(const py::array& a, std::string_view name) {
  const char kind = a.dtype().kind();
  if (kind == 'f' || kind == 'i' || kind == 'u') return;
  fail(errc::wrong_type, std::string(name) + ": expected real numbers, got an array of dtype " +
                             py::str(a.dtype()).cast<std::string>());
}

// Any array-like as an array of its own dtype, refused unless its numbers are real.
py::array real_array(const py::handle& x, std::string_view name, std::string_view expected) {
  py::array a = py::array::ensure(x);
  if (!a) fail(errc::wrong_type, std::string(name) + ": expected " + std::string(expected) + ", got a " + type_name(x));
  require_real(a, name);
  return a;
}

bool is_masked(const py::handle& x) {
  return py::module_::import("numpy.ma").attr("isMaskedArray")(x).cast<bool>();
}

// The index of the first masked entry of a masked array, as NumPy prints it: (2, 3).
std::string first_masked(const py::handle& x) {
  const py::object mask = py::module_::import("numpy.ma").attr("getmaskarray")(x);
  const py::object where = py::module_::import("numpy").attr("argwhere")(mask);
  if (py::len(where) == 0) return {};
  py::tuple index = py::tuple(where[py::int_(0)].attr("tolist")());
  return py::str(index).cast<std::string>();
}

std::string pointer_child(const std::string& ptr, std::string_view key) {
  std::string out = ptr + "/";
  for (const char c : key) out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
  return out;
}

std::string place(const std::string& ptr) { return ptr.empty() ? "(top level)" : ptr; }

nlohmann::json json_number(const py::handle& x, const std::string& ptr) {
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(x.ptr(), &overflow);
  if (overflow == 0 && !(v == -1 && PyErr_Occurred())) return v;
  PyErr_Clear();
  if (overflow > 0) {
    const unsigned long long u = PyLong_AsUnsignedLongLong(x.ptr());
    if (!PyErr_Occurred()) return u;
    PyErr_Clear();
  }
  const double d = PyLong_AsDouble(x.ptr());
  if (d == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    fail(errc::not_finite, place(ptr) + ": value " + py::str(x).cast<std::string>().substr(0, 40) +
                               " is too large for a double");
  }
  return d;
}

nlohmann::json to_json(const py::handle& x, const std::string& ptr) {
  if (x.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(x)) return x.cast<bool>();  // before int: a bool is an int
  if (py::isinstance<py::int_>(x)) return json_number(x, ptr);
  if (py::isinstance<py::float_>(x)) {
    const double d = x.cast<double>();
    if (!std::isfinite(d))
      fail(errc::not_finite, place(ptr) + ": value is " + (std::isnan(d) ? "nan" : d > 0 ? "inf" : "-inf"));
    return d;
  }
  if (py::isinstance<py::str>(x)) return x.cast<std::string>();
  if (py::isinstance<py::dict>(x)) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& [k, v] : py::reinterpret_borrow<py::dict>(x)) {
      if (!py::isinstance<py::str>(k))
        fail(errc::wrong_type, place(ptr) + ": keys are field names (strings), got the " + type_name(k) + " " +
                                   py::repr(k).cast<std::string>());
      const auto key = k.cast<std::string>();
      out[key] = to_json(v, pointer_child(ptr, key));
    }
    return out;
  }
  if (py::isinstance<py::list>(x) || py::isinstance<py::tuple>(x)) {
    nlohmann::json out = nlohmann::json::array();
    std::size_t i = 0;
    for (const auto& v : x) out.push_back(to_json(v, pointer_child(ptr, std::to_string(i++))));
    return out;
  }
  const py::module_ np = py::module_::import("numpy");
  if (is_masked(x))
    fail(errc::wrong_type, place(ptr) + ": a masked array in a spec dict; give it in `arrays`, where masked points are missing");
  if (py::isinstance<py::array>(x)) {
    const char kind = py::reinterpret_borrow<py::array>(x).dtype().kind();
    if (kind != 'b') require_real(py::reinterpret_borrow<py::array>(x), place(ptr));
    return to_json(x.attr("tolist")(), ptr);
  }
  if (py::isinstance(x, np.attr("generic"))) {
    const py::object item = x.attr("item")();
    if (!py::isinstance<py::bool_>(item) && !py::isinstance<py::int_>(item) && !py::isinstance<py::float_>(item))
      fail(errc::wrong_type, place(ptr) + ": expected a number, got the NumPy " + type_name(x) + " " + py::repr(x).cast<std::string>());
    return to_json(item, ptr);
  }
  fail(errc::wrong_type, place(ptr) + ": a " + type_name(x) +
                             " is not a spec value (numbers, strings, lists, dicts, True, False, None)");
}

}  // namespace

std::vector<double> params(const py::handle& x, std::string_view name) {
  if (is_masked(x))
    if (const std::string at = first_masked(x); !at.empty())
      fail(errc::wrong_type, std::string(name) + ": masked at index " + at + "; parameters cannot be missing");
  const py::array any = real_array(x, name, "a sequence of numbers");
  const auto a = py::array_t<double, py::array::forcecast>::ensure(any);
  if (a.ndim() != 1)
    fail(errc::size_mismatch, std::string(name) + ": expected a 1-D sequence of parameters, got " + std::to_string(a.ndim()) +
                                  " dimensions");
  const auto r = a.unchecked<1>();
  std::vector<double> out(static_cast<std::size_t>(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i) out[static_cast<std::size_t>(i)] = r(i);
  return out;
}

std::shared_ptr<io::PointArray> point_array(const py::handle& x, const std::string& name) {
  py::object source = py::reinterpret_borrow<py::object>(x);
  if (is_masked(x)) {
    require_real(py::reinterpret_borrow<py::array>(x), name);
    // Masked points are missing points: NaN, as in a .npy file.
    const py::module_ np = py::module_::import("numpy");
    source = np.attr("array")(py::module_::import("numpy.ma").attr("getdata")(x), py::arg("dtype") = "float64");
    if (py::len(source.attr("shape")) >= 2) {
      const py::object mask = py::module_::import("numpy.ma").attr("getmaskarray")(x).attr("any")(py::arg("axis") = -1);
      source.attr("__setitem__")(mask, std::numeric_limits<double>::quiet_NaN());
    }
  }
  const py::array any = real_array(source, name, "an array of points, shape (..., 3)");
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(any);
  if (!a) fail(errc::wrong_type, name + ": expected an array of points, shape (..., 3)");
  if (a.ndim() < 2 || a.shape(a.ndim() - 1) != 3) {
    std::string shape;
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
    if (a.ndim() == 1) shape += ",";
    fail(errc::size_mismatch, name + ": expected an array of points of shape (..., 3), got (" + shape + ")");
  }
  std::vector<std::size_t> shape;
  for (py::ssize_t k = 0; k + 1 < a.ndim(); ++k) shape.push_back(static_cast<std::size_t>(a.shape(k)));
  py::gil_scoped_release free;  // `a` keeps the memory alive
  return std::make_shared<io::PointArray>(io::copy_point_array(a.data(), std::move(shape)));
}

nlohmann::json spec_json(const py::handle& x) { return to_json(x, ""); }

std::vector<std::size_t> counts(const py::handle& x, std::string_view name) {
  const std::string n(name);
  if (!py::isinstance<py::sequence>(x) || py::isinstance<py::str>(x))
    fail(errc::wrong_type, n + ": expected (nu, nv) or (nu, nv, nw) counts, got a " + type_name(x));
  std::vector<std::size_t> out;
  for (const auto& item : x) {
    if (py::isinstance<py::bool_>(item) || !PyIndex_Check(item.ptr()))
      fail(errc::wrong_type, n + ": counts are whole numbers, got " + py::repr(item).cast<std::string>());
    const py::int_ k = py::reinterpret_steal<py::int_>(PyNumber_Index(item.ptr()));
    if (!k) throw py::error_already_set();
    if (k < py::int_(0))
      fail(errc::too_few_points, n + ": counts are whole numbers of at least 2, got " + py::repr(k).cast<std::string>());
    const std::size_t c = PyLong_AsSize_t(k.ptr());
    if (c == static_cast<std::size_t>(-1) && PyErr_Occurred()) PyErr_Clear();  // too large: the size checks refuse it
    out.push_back(c);
  }
  if (out.size() != 2 && out.size() != 3)
    fail(errc::size_mismatch, n + ": (nu, nv) for a surface or (nu, nv, nw) for a volume, got " + std::to_string(out.size()) +
                                  " counts");
  return out;
}

std::filesystem::path path_arg(const py::handle& x, std::string_view what) {
  if (py::isinstance<py::str>(x) || py::isinstance<py::bytes>(x) || py::hasattr(x, "__fspath__")) {
    try {
      return x.cast<std::filesystem::path>();
    } catch (const py::cast_error&) {
    }
  }
  fail(errc::wrong_type, std::string(what) + ", got a " + type_name(x));
}

progress_callback interruptible() {
  using clock = std::chrono::steady_clock;
  auto last = std::make_shared<clock::time_point>(clock::now());
  return [last](double) {
    const clock::time_point now = clock::now();
    if (now - *last < std::chrono::milliseconds(50)) return;
    *last = now;
    py::gil_scoped_acquire hold;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  };
}

void bind_spec_fields(py::module_& m) {
  m.def("spec_fields", [] {
    py::dict forms;
    for (const io::SpecForm& f : io::spec_forms()) {
      const py::str kind(f.kind.data(), f.kind.size());
      if (!forms.contains(kind)) forms[kind] = py::dict();
      py::list fields;
      for (std::string_view field : f.fields) fields.append(py::str(field.data(), field.size()));
      py::dict of_kind = forms[kind];
      of_kind[py::str(f.name.data(), f.name.size())] = py::tuple(fields);
    }
    return forms;
  }, "Every form a spec may hold, as the reader checks it: {kind: {name: (field, ...)}}, kind 'type' (the "
     "construction types, their top-level fields, \"type\" included), 'curve' (the curve forms) or 'points' (point "
     "arrays given as files).");
}


}  // namespace interpatch::python
