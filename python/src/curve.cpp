// interpatch.Curve: a curve spec, built (io::CurveConstruction), evaluated into NumPy
// arrays.

#include "curve.hpp"

#include <pybind11/numpy.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "arrays.hpp"
#include "inputs.hpp"
#include "locate.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::python {

namespace {

namespace ip = interpatch;

// f(); an error of the curve's (a parameter outside its domain) names `name`.
template <class F>
auto at_t(const std::string& name, F&& f) {
  try {
    return f();
  } catch (const ip::error& e) {
    throw ip::error(e.code(), name + ": " + e.what());
  }
}

// A curve spec, built: immutable once made, so every method runs without a lock.
class PyCurve {
 public:
  explicit PyCurve(std::shared_ptr<const ip::io::CurveConstruction> c) : c_(std::move(c)) {}

  [[nodiscard]] const std::string& type() const { return c_->form; }
  [[nodiscard]] int degree() const { return c_->curve.degree(); }

  // The projector is cheap to make (a curve's pieces), so each call makes its own.
  py::dict closest_points(const py::object& points) const {
    std::unique_ptr<ip::CurveProjector> on;
    {
      py::gil_scoped_release free;
      on = std::make_unique<ip::CurveProjector>(c_->curve);
    }
    return ip::python::closest_points(*on, points);
  }
  [[nodiscard]] py::tuple domain() const {
    const auto [a, b] = c_->curve.domain();
    return py::make_tuple(a, b);
  }

  // C(ts[i]) for every i, shape (len(ts), 3).
  py::array_t<double> evaluate(const py::object& ts_in) const {
    return sample(ts_in, [&](double t, double* out) {
      const ip::Vec3 p = c_->curve.point(t);
      out[0] = p.x, out[1] = p.y, out[2] = p.z;
    }, {});
  }

  // C and its derivatives of orders 1..order at every ts[i], shape (len(ts), order + 1, 3).
  py::array_t<double> derivatives(const py::object& ts_in, int order) const {
    if (order < 0) throw ip::error(ip::errc::wrong_type, "order: a derivative order of 0 or more, got " + std::to_string(order));
    const auto k = static_cast<std::size_t>(order) + 1;
    return sample(ts_in, [&](double t, double* out) {
      c_->curve.derivatives(t, order, reinterpret_cast<ip::Vec3*>(out));
    }, {static_cast<py::ssize_t>(k)});
  }

  py::array_t<double> point(double t) const {
    const ip::Vec3 p = at_t("t", [&] { return c_->curve.point(t); });
    return py::array_t<double>(3, &p.x);
  }

  // C'/|C'|; the zero vector where C' vanishes, as Surface.normal at a degenerate point.
  py::array_t<double> tangent(double t) const {
    const ip::Vec3 d = at_t("t", [&] { return c_->curve.derivative(t, 1); });
    const double len = ip::norm(d);
    const ip::Vec3 u = len > 0 ? d / len : ip::Vec3{0, 0, 0};
    return py::array_t<double>(3, &u.x);
  }

  // |C' × C''| / |C'|³; NaN where C' vanishes.
  double curvature(double t) const {
    ip::Vec3 d[3];
    at_t("t", [&] {
      c_->curve.derivatives(t, 2, d);
      return 0;
    });
    const double len = ip::norm(d[1]);
    return ip::norm(ip::cross(d[1], d[2])) / (len * len * len);
  }

  py::dict to_bspline() const {
    const ip::BSplineCurve& c = c_->curve;
    const py::capsule keep(new std::shared_ptr<const ip::io::CurveConstruction>(c_),
                           [](void* p) { delete static_cast<std::shared_ptr<const ip::io::CurveConstruction>*>(p); });
    const auto n = static_cast<py::ssize_t>(c.control_points().size());
    py::dict d;
    d["degree"] = c.degree();
    d["knots"] = knots_array(c.knots(), keep);
    d["control_points"] = read_only(py::array_t<double>({n, py::ssize_t{3}}, &c.control_points().data()->x, keep));
    d["weights"] = c.rational() ? py::object(read_only(py::array_t<double>(n, c.weights().data(), keep))) : py::none();
    d["periodic"] = c.periodic();
    return d;
  }

  [[nodiscard]] py::object params() const {
    if (c_->data.empty()) return py::none();
    const auto& t = c_->data.front().params.front();
    return py::array_t<double>(static_cast<py::ssize_t>(t.size()), t.data());
  }

  py::object info() const {
    nlohmann::ordered_json j;
    {
      py::gil_scoped_release free;
      j = ip::io::curve_info_json(*c_);
    }
    return to_python(j);
  }

  // Written as `interpatch build` writes a curve spec: .json .npz .step/.stp .igs/.iges.
  void write(const py::object& path_in) const {
    const std::filesystem::path path = ip::python::path_arg(path_in, "write: the path is a str or an os.PathLike");
    py::gil_scoped_release free;
    ip::io::write_build(*c_, path);
  }

  [[nodiscard]] std::string repr() const {
    return "Curve(type='" + c_->form + "', degree=" + std::to_string(degree()) +
           ", control_points=" + std::to_string(c_->curve.control_points().size()) + ")";
  }

 private:
  // A block of `row` points per parameter (shape row + (3,)), made by fill(t, block)
  // without the GIL; Ctrl-C stops it between points.
  template <class Fill>
  py::array_t<double> sample(const py::handle& ts_in, const Fill& fill, std::vector<py::ssize_t> row) const {
    const std::vector<double> ts = python::params(ts_in, "ts");
    std::size_t per = 3;
    for (const auto r : row) per *= static_cast<std::size_t>(r);
    auto out = std::make_unique<std::vector<double>>(ts.size() * per);
    const ip::progress_callback progress = interruptible();
    {
      py::gil_scoped_release free;
      for (std::size_t i = 0; i < ts.size(); ++i) {
        at_t("ts[" + std::to_string(i) + "]", [&] {
          fill(ts[i], out->data() + i * per);
          return 0;
        });
        if ((i & 4095) == 4095) progress(static_cast<double>(i) / static_cast<double>(ts.size()));
      }
    }
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(ts.size())};
    shape.insert(shape.end(), row.begin(), row.end());
    shape.push_back(3);
    double* data = out->data();
    return owning_array(std::move(out), data, std::move(shape));
  }

  std::shared_ptr<const ip::io::CurveConstruction> c_;
};

}  // namespace

py::object wrap_curve(io::CurveConstruction c) {
  return py::cast(PyCurve(std::make_shared<const io::CurveConstruction>(std::move(c))));
}

void bind_curve(py::module_& m) {
  py::class_<PyCurve>(m, "Curve",
                      "A curve C(t) over [0, 1] (every curve form is mapped onto it), built from a curve spec "
                      "(docs/spec-format.md, \"Curves\") by interpolate_curve, approximate_curve, bspline_curve, "
                      "hermite_curve, line or build; a side of ruled, coons and curve_network surfaces.\n\n"
                      "Example:\n"
                      "    c = interpatch.interpolate_curve([[0, 0, 0], [1, 2, 0], [3, 3, 0], [4, 0, 1]])\n"
                      "    c  # Curve(type='interpolate', degree=3, control_points=4)\n"
                      "    c.evaluate(np.linspace(0, 1, 50)).shape  # (50, 3)\n"
                      "    c.point(c.params[2])  # the third point, up to rounding")
      .def("__repr__", &PyCurve::repr)
      .def_property_readonly("type", &PyCurve::type,
                             "The curve's form: 'interpolate', 'approximate', 'bspline', 'hermite' or 'line'.")
      .def_property_readonly("degree", &PyCurve::degree, "The degree p of its exact B-spline form.")
      .def_property_readonly("domain", &PyCurve::domain, "(0.0, 1.0): every curve is mapped onto [0, 1].")
      .def_property_readonly("params", &PyCurve::params,
                             "The parameters of the points it was made through or near (interpolate, approximate, "
                             "hermite), shape (n,), in [0, 1]: C(params[i]) is points[i] for an interpolated curve "
                             "(a closed curve's repeated last point at 1). None for bspline and line.")
      .def("evaluate", &PyCurve::evaluate, py::arg("ts"),
           "Points C(ts[i]): a float64 array of shape (len(ts), 3). A closed curve takes any t (it wraps); an "
           "open one refuses a t outside [0, 1] ('out_of_domain', naming ts[i]).\n\n"
           "Example: c.evaluate(np.linspace(0, 1, 100))  # (100, 3)")
      .def("derivatives", &PyCurve::derivatives, py::arg("ts"), py::arg("order") = 1,
           "C and its derivatives of orders 1..order at every ts[i]: shape (len(ts), order + 1, 3), "
           "[i, k] being d^k C / dt^k at ts[i] (k = 0: the point).\n\n"
           "Example: c.derivatives([0, 0.5, 1], 2)[:, 1]  # the first derivatives, (3, 3)")
      .def("point", &PyCurve::point, py::arg("t"), "C(t), shape (3,).")
      .def("tangent", &PyCurve::tangent, py::arg("t"),
           "The unit tangent C'(t) / |C'(t)|, shape (3,); the zero vector where C' vanishes.")
      .def("curvature", &PyCurve::curvature, py::arg("t"),
           "The curvature |C' × C''| / |C'|³ at t (1 / radius); NaN where C' vanishes.")
      .def("closest_points", &PyCurve::closest_points, py::arg("points"),
           "The closest point of the curve to each point, shape (..., 3): a dict of params (...,), points "
           "(..., 3) and distance (...,). The global answer: no point of the curve is nearer than distance "
           "less 1e-10 of its diagonal.")
      .def("to_bspline", &PyCurve::to_bspline,
           "The exact B-spline form: {'degree': p, 'knots' (n + p + 1,; a closed curve's extended knots, "
           "n + 2p + 1), 'control_points' (n, 3), 'weights' (n,) or None, 'periodic': bool}; "
           "C(t) = Σ N_i,p(t) w_i P_i / Σ N_i,p(t) w_i. The arrays are read-only views of the curve's memory "
           "(copy them to change them).")
      .def("info", &PyCurve::info,
           "The dict `interpatch info` prints for the curve spec: degree, knots, continuity, bounding box, "
           "max_data_error (the curve at params against its points), parameters.")
      .def("write", &PyCurve::write, py::arg("path"),
           "Write as `interpatch build` writes a curve spec: .json (a {\"bspline\": ...} curve spec that reads back "
           "to the same curve), .npz (degree, knots_u, control_points, weights, periodic), .step/.stp or .igs/.iges; "
           "another format is refused ('wrong_type').");
}

}  // namespace interpatch::python
