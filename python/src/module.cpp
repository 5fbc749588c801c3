// The Python module interpatch._core: specs built from dicts or files, surfaces and
// volumes evaluated into NumPy arrays that own the library's result memory.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "commands.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/spec.hpp"

namespace py = pybind11;
namespace ip = interpatch;

namespace {

// interpatch.Error, a ValueError with .code (the errc name); made at import.
PyObject* error_type = nullptr;

// A NumPy array over memory a C++ object owns: the capsule frees the object when
// the array (and every view of it) is gone, so nothing is copied.
template <class Owner>
py::array_t<double> owning_array(std::unique_ptr<Owner> owner, double* data, std::vector<py::ssize_t> shape) {
  py::capsule free_it(owner.get(), [](void* p) { delete static_cast<Owner*>(p); });
  (void)owner.release();
  return py::array_t<double>(shape, data, free_it);
}

// Parameters from any sequence or array of numbers, as float64.
std::vector<double> params(const py::handle& x) {
  const auto a = py::array_t<double, py::array::forcecast>::ensure(x);
  if (!a) throw ip::error(ip::errc::wrong_type, "expected a sequence of numbers");
  if (a.ndim() != 1) throw ip::error(ip::errc::size_mismatch, "expected a 1-D sequence of parameters, got " + std::to_string(a.ndim()) + " dimensions");
  const auto r = a.unchecked<1>();
  std::vector<double> out(static_cast<std::size_t>(r.shape(0)));
  for (py::ssize_t i = 0; i < r.shape(0); ++i) out[static_cast<std::size_t>(i)] = r(i);
  return out;
}

// A point array of any float dtype and memory order, shape (..., 3), as the library
// stores points (float64 triples in C order): the one copy an input costs.
std::shared_ptr<const ip::io::PointArray> point_array(const py::handle& x, const std::string& name) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(x);
  if (!a) throw ip::error(ip::errc::wrong_type, name + ": expected an array of points, shape (..., 3)");
  if (a.ndim() < 2 || a.shape(a.ndim() - 1) != 3) {
    std::string shape;
    for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape(k));
    throw ip::error(ip::errc::size_mismatch, name + ": expected an array of points of shape (..., 3), got (" + shape + ")");
  }
  auto out = std::make_shared<ip::io::PointArray>();
  for (py::ssize_t k = 0; k + 1 < a.ndim(); ++k) out->shape.push_back(static_cast<std::size_t>(a.shape(k)));
  const auto count = static_cast<std::size_t>(a.size() / 3);
  out->points.resize(count);
  std::memcpy(&out->points.data()->x, a.data(), count * sizeof(ip::Vec3));
  return out;
}

// A built spec: the construction, and a lock for the one step that may change it
// (making its exact form on first use) while threads evaluate without the GIL.
struct Built {
  ip::io::Construction c;
  std::mutex lock;
};

py::object to_python(const nlohmann::ordered_json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

class PySurface {
 public:
  explicit PySurface(std::shared_ptr<Built> b) : b_(std::move(b)) {}

  py::array_t<double> evaluate(const py::handle& us_in, const py::handle& vs_in) const {
    auto us = params(us_in), vs = params(vs_in);
    auto out = std::make_unique<std::vector<ip::Vec3>>(us.size() * vs.size());
    {
      py::gil_scoped_release free;
      const ip::Surface& s = surface(out->size(), ip::io::Sample::points);
      s.evaluate_into(us, vs, *out);
    }
    double* data = &(*out)[0].x;
    return owning_array(std::move(out), data, {static_cast<py::ssize_t>(us.size()), static_cast<py::ssize_t>(vs.size()), 3});
  }

  py::array_t<double> evaluate_derivatives(const py::handle& us_in, const py::handle& vs_in) const {
    auto us = params(us_in), vs = params(vs_in);
    std::unique_ptr<ip::Grid<ip::SurfaceDerivatives, 2>> out;
    {
      py::gil_scoped_release free;
      const ip::Surface& s = surface(us.size() * vs.size(), ip::io::Sample::derivatives);
      out = std::make_unique<ip::Grid<ip::SurfaceDerivatives, 2>>(s.evaluate_derivatives(us, vs));
    }
    static_assert(sizeof(ip::SurfaceDerivatives) == 18 * sizeof(double));
    double* data = &out->data()->s.x;
    return owning_array(std::move(out), data,
                        {static_cast<py::ssize_t>(us.size()), static_cast<py::ssize_t>(vs.size()), 6, 3});
  }

  py::array_t<double> point(double u, double v) const {
    const ip::Vec3 p = surface(1, ip::io::Sample::points).point(u, v);
    return py::array_t<double>(3, &p.x);
  }

  py::array_t<double> normal(double u, double v) const {
    const ip::Vec3 n = ip::unit_normal(surface(1, ip::io::Sample::derivatives).derivatives(u, v));
    return py::array_t<double>(3, &n.x);
  }

  py::dict curvature(double u, double v) const {
    const ip::Curvature k = ip::curvature(surface(1, ip::io::Sample::derivatives).derivatives(u, v));
    py::dict d;
    d["gaussian"] = k.gaussian;
    d["mean"] = k.mean;
    d["k1"] = k.k1;
    d["k2"] = k.k2;
    return d;
  }

  py::object info() const {
    nlohmann::ordered_json j;
    {
      py::gil_scoped_release free;
      std::lock_guard<std::mutex> hold(b_->lock);
      if (ip::io::has_exact_form(b_->c)) (void)ip::io::exact_form(b_->c);  // info reports it, as the command does
      j = ip::io::info_json(b_->c);
    }
    return to_python(j);
  }

  [[nodiscard]] const std::string& type() const { return b_->c.type; }

  // The exact B-spline form: degree, knots, and control points (and weights) as arrays
  // over the construction's own memory.
  py::dict to_bspline() const {
    const ip::BSplineSurface* e = nullptr;
    {
      py::gil_scoped_release free;
      std::lock_guard<std::mutex> hold(b_->lock);
      e = &std::get<ip::BSplineSurface>(ip::io::exact_form(b_->c));
    }
    py::capsule alive(new std::shared_ptr<Built>(b_), [](void* p) { delete static_cast<std::shared_ptr<Built>*>(p); });
    const auto nu = static_cast<py::ssize_t>(e->control_points().shape()[0]);
    const auto nv = static_cast<py::ssize_t>(e->control_points().shape()[1]);
    py::dict d;
    d["degree"] = py::make_tuple(e->knots_u().degree(), e->knots_v().degree());
    d["knots_u"] = py::array_t<double>(static_cast<py::ssize_t>(e->knots_u().size()), e->knots_u().values().data(), alive);
    d["knots_v"] = py::array_t<double>(static_cast<py::ssize_t>(e->knots_v().size()), e->knots_v().values().data(), alive);
    d["control_points"] = py::array_t<double>({nu, nv, py::ssize_t{3}}, &e->control_points().data()->x, alive);
    d["weights"] = e->rational() ? py::object(py::array_t<double>({nu, nv}, e->weights().data(), alive)) : py::none();
    d["periodic"] = py::make_tuple(e->knots_u().periodic(), e->knots_v().periodic());
    return d;
  }

  // Written as the commands write: .json .npz .step/.stp .igs/.iges (the exact form) or
  // a mesh (.obj .ply .stl .vtk .vts ...) of `res` vertices.
  void write(const std::filesystem::path& path, const std::optional<std::pair<std::size_t, std::size_t>>& res) const {
    namespace cli = ip::cli;
    py::gil_scoped_release free;
    std::lock_guard<std::mutex> hold(b_->lock);
    try {
      if (ip::io::is_mesh_format(path.extension().string())) {
        cli::Resolution r = cli::default_surface_resolution;
        if (res) r = {res->first, res->second, 0};
        cli::write_mesh(b_->c, path, r);
        return;
      }
      cli::check_build_output(path);
      if (ip::io::has_exact_form(b_->c)) (void)ip::io::exact_form(b_->c);
      cli::write_build(b_->c, path);
    } catch (const cli::usage_error& e) {
      throw ip::error(ip::errc::wrong_type, e.what());
    }
  }

  // The data's parameters along u and v, where the construction has data.
  [[nodiscard]] py::object data_params(std::size_t axis) const {
    const auto& data = b_->c.data;
    if (data.empty() || data.front().params.size() <= axis) return py::none();
    const auto& p = data.front().params[axis];
    return py::array_t<double>(static_cast<py::ssize_t>(p.size()), p.data());
  }

 private:
  const ip::Surface& surface(std::size_t points, ip::io::Sample what) const {
    std::lock_guard<std::mutex> hold(b_->lock);
    return ip::io::evaluator(b_->c, points, what);
  }
  std::shared_ptr<Built> b_;
};

py::object wrap(ip::io::Construction c) {
  auto b = std::make_shared<Built>();
  b->c = std::move(c);
  if (ip::io::is_volume(b->c)) throw ip::error(ip::errc::wrong_type, "volumes are not yet available from Python");
  return py::cast(PySurface(std::move(b)));
}

py::object build(const py::object& spec, const std::filesystem::path& base_dir, const py::dict& arrays) {
  ip::io::BuildOptions o;
  o.defer_exact = true;
  for (const auto& [k, v] : arrays) o.arrays[k.cast<std::string>()] = point_array(v, k.cast<std::string>());
  if (py::isinstance<py::dict>(spec)) {
    const std::string text = py::module_::import("json").attr("dumps")(spec).cast<std::string>();
    const nlohmann::json j = ip::io::parse_json(text, "spec");
    ip::io::Construction c;
    {
      py::gil_scoped_release free;
      c = ip::io::build(j, base_dir, o);
    }
    return wrap(std::move(c));
  }
  const auto path = spec.cast<std::filesystem::path>();
  ip::io::Construction c;
  {
    py::gil_scoped_release free;
    c = ip::io::build_file(path, o);
  }
  return wrap(std::move(c));
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "interpatch: interpolating curves, surfaces and solids, evaluated exactly.";
  error_type = PyErr_NewExceptionWithDoc("interpatch.Error",
                                         "Bad input: .code is the error's name (e.g. 'zero_chord'), the message "
                                         "names the place and the size of the problem, as the command line does.",
                                         PyExc_ValueError, nullptr);
  m.attr("Error") = py::handle(error_type);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ip::error& e) {
      py::object inst = py::reinterpret_steal<py::object>(PyObject_CallFunction(error_type, "s", e.what()));
      if (!inst) return;  // the call set its own exception
      inst.attr("code") = std::string(ip::to_string(e.code()));
      PyErr_SetObject(error_type, inst.ptr());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "interpatch: out of memory");
    }
  });

  py::class_<PySurface>(m, "Surface", "A surface over [0, 1]², built from a spec or a constructor.")
      .def_property_readonly("type", &PySurface::type, "The spec's \"type\".")
      .def("evaluate", &PySurface::evaluate, py::arg("us"), py::arg("vs"),
           "Points at every (us[i], vs[j]): a float64 array of shape (len(us), len(vs), 3) over the "
           "library's own result memory.\n\nExample: s.evaluate(np.linspace(0, 1, 100), np.linspace(0, 1, 50))")
      .def("evaluate_derivatives", &PySurface::evaluate_derivatives, py::arg("us"), py::arg("vs"),
           "Points and derivatives at every (us[i], vs[j]): shape (len(us), len(vs), 6, 3), the six being "
           "S, Su, Sv, Suu, Suv, Svv.")
      .def("point", &PySurface::point, py::arg("u"), py::arg("v"), "S(u, v), shape (3,).")
      .def("normal", &PySurface::normal, py::arg("u"), py::arg("v"), "The unit normal Su × Sv / |Su × Sv|, shape (3,).")
      .def("curvature", &PySurface::curvature, py::arg("u"), py::arg("v"),
           "{'gaussian', 'mean', 'k1', 'k2'} at (u, v), with respect to normal().")
      .def("info", &PySurface::info, "The dict `interpatch info` prints for this construction.")
      .def("to_bspline", &PySurface::to_bspline,
           "The exact B-spline form: {'degree': (p, q), 'knots_u', 'knots_v', 'control_points' (shape (nu, nv, 3)), "
           "'weights' (shape (nu, nv), or None), 'periodic': (bool, bool)}; the arrays view the construction's memory.")
      .def("write", &PySurface::write, py::arg("path"), py::arg("res") = py::none(),
           "Write as `interpatch build` (.json .npz .step .igs: the exact form) or `interpatch mesh` "
           "(.obj .ply .stl .vtk .vts: res = (nu, nv) vertices, 64 x 64 by default) would.")
      .def_property_readonly("params_u", [](const PySurface& s) { return s.data_params(0); },
                             "Parameters of the data along u (None without data).")
      .def_property_readonly("params_v", [](const PySurface& s) { return s.data_params(1); },
                             "Parameters of the data along v (None without data).");

  m.def("build", &build, py::arg("spec"), py::arg("base_dir") = std::filesystem::path("."), py::arg("arrays") = py::dict(),
        "A spec (docs/spec-format.md) as a dict, or the path of a spec file, built.\n\n"
        "Example: s = interpatch.build({'type': 'bilinear', 'p00': [0, 0, 0], 'p01': [0, 1, 0], "
        "'p10': [1, 0, 0], 'p11': [1, 1, 1]})");
}
