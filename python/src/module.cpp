// The Python module interpatch._core: specs built from dicts or files, surfaces and
// volumes evaluated into NumPy arrays that own the library's result memory; curves
// (curve specs) in curve.cpp.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <utility>
#include <string>
#include <string_view>
#include <vector>

#include "interpatch/blended_surface.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/io/project.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/io/view.hpp"
#include "arrays.hpp"
#include "curve.hpp"
#include "locate.hpp"
#include "sampling.hpp"
#include "inputs.hpp"

namespace py = pybind11;
namespace ip = interpatch;

namespace {

// interpatch.Error, a ValueError with .code (the errc name); made at import.
PyObject* error_type = nullptr;

using ip::python::interruptible;
using ip::python::knots_array;
using ip::python::owning_array;
using ip::python::read_only;
using ip::python::to_python;
using ip::python::params;
using ip::python::point_array;

// res as Python's write() names it in messages.
constexpr ip::io::CountsOption mesh_res{"res", "mesh", "vertices", "(nu, nv)", "(nu, nv, nw)", "(64, 64)", "(33, 33, 33)",
                                        false, " (", ", ", ")"};
constexpr ip::io::CountsOption view_res{"res", "view", "samples", "(nu, nv)", "(nu, nv, nw)", "(257, 257)", "(33, 33, 33)",
                                        false, " (", ", ", ")"};

// The arrays a construction was built from, as the caller gave them (the data points
// its DataSets lend: BuildOptions::borrow_arrays).
using Sources = std::map<std::string, py::object>;

// A built spec: the construction, and a lock for the one step that may change it
// (making its exact form on first use) while threads evaluate without the GIL.
struct Built {
  ip::io::Construction c;
  std::mutex lock;
  // Made on the first query and kept: the pieces of the exact form and their tree.
  std::unique_ptr<const ip::SurfaceProjector> projector;
  std::unique_ptr<const ip::VolumeLocator> locator;
};

// "(3, 3)", as Python prints a tuple.
std::string tuple_text(const std::vector<std::size_t>& v) {
  std::string s = "(";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + ")";
}

std::vector<const ip::KnotVector*> knots_of(const ip::BSplineSurface& s) { return {&s.knots_u(), &s.knots_v()}; }
std::vector<const ip::KnotVector*> knots_of(const ip::BSplineVolume& v) {
  return {&v.knots_u(), &v.knots_v(), &v.knots_w()};
}

// What surfaces and volumes share: the built spec, its info, its files.
class PyBuilt {
 public:
  PyBuilt(std::shared_ptr<Built> b, std::shared_ptr<const Sources> sources)
      : b_(std::move(b)), sources_(std::move(sources)) {}

  py::object info() const {
    LentPoints lent = lent_data();
    nlohmann::ordered_json j;
    const ip::progress_callback progress = interruptible();  // Ctrl-C stops the conversion and the check
    {
      py::gil_scoped_release free;
      std::lock_guard<std::mutex> hold(b_->lock);
      const WithData with(b_->c, lent);
      if (ip::io::has_exact_form(b_->c)) (void)ip::io::exact_form(b_->c, progress);  // info reports it, as the command does
      j = ip::io::info_json(b_->c, progress);
    }
    return to_python(j);
  }

  [[nodiscard]] const std::string& type() const { return b_->c.type; }

  // Written as the commands write: .json .npz .step/.stp .igs/.iges (the exact form),
  // a mesh (.obj .ply .stl .vtk .vts .xyz) of `res` vertices, or a viewer page (.html)
  // of `res` samples; checked as the command line checks them (io/outputs.hpp).
  void write(const py::object& path_in, const py::object& res_in, const py::object& sampling_in) const {
    namespace io = ip::io;
    const std::filesystem::path path = ip::python::path_arg(path_in, "write: the path is a str or an os.PathLike");
    const std::string ext = path.extension().string();
    const bool mesh = io::is_mesh_format(ext) || io::is_polymesh_path(path), view = io::is_view_format(ext);
    std::optional<io::Resolution> res;
    if (!res_in.is_none()) {
      if (!mesh && !view)
        throw ip::error(ip::errc::wrong_type, "res: only a mesh or a viewer page has a resolution, not '" + path.string() + "'");
      const std::vector<std::size_t> n = ip::python::counts(res_in, "res");
      res = io::Resolution{n[0], n[1], n.size() == 3 ? n[2] : 0};
      io::check_counts(io::counts_of(*res), view ? view_res : mesh_res);
      if (mesh) io::require_mesh_room(*res, path);  // before the lock and any work
    }
    if (!mesh && !view) io::check_build_output(path);
    // Read as the spec's "sampling" is, for this write alone.
    if (!sampling_in.is_none() && !mesh)
      throw ip::error(ip::errc::wrong_type, "sampling: only a mesh places its nodes by a sampling, not '" +
                                                path.string() + "'");
    const std::optional<ip::Sampling> sampling = ip::python::sampling_arg(sampling_in, b_->c);
    // A viewer page shows the data points.
    LentPoints lent = view ? lent_data() : LentPoints();
    const ip::progress_callback progress = interruptible();
    std::vector<std::string> warned;
    {
      py::gil_scoped_release free;
      std::lock_guard<std::mutex> hold(b_->lock);
      const WithData with(b_->c, lent);
      if (mesh) {
        const io::Resolution r = res ? *res : io::default_resolution(b_->c, sampling ? &*sampling : nullptr);
        warned = io::write_mesh(b_->c, path, r, mesh_res, progress, sampling ? &*sampling : nullptr);
      } else if (view) {
        if (io::has_exact_form(b_->c)) (void)io::exact_form(b_->c, progress);  // the page shows it, as the command does
        const auto d = io::view_default_resolution(b_->c);
        const io::Resolution r = res ? *res : io::Resolution{d[0], d[1], d[2]};
        io::check_counts_kind(b_->c, view_res, r);
        io::write_view(path, b_->c, {.resolution = {r.nu, r.nv, r.nw}, .title = path.stem().string()});
      } else {
        io::write_build(b_->c, path);
      }
    }
    // What the command line prints as "interpatch: warning: ...", as Python warnings.
    for (const std::string& w : warned)
      if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
  }

  // Surface(type='interpolate', degree=(3, 3), control_points=(30, 25)): the exact
  // form's degrees and net. A surface whose exact form is deferred gives them from its
  // knots alone; a volume's is made now; one without an exact form says so.
  [[nodiscard]] std::string repr(const char* kind) const {
    std::vector<std::size_t> degree, size;
    const ip::progress_callback progress = interruptible();  // a volume's exact form is made now
    {
      py::gil_scoped_release free;
      std::lock_guard<std::mutex> hold(b_->lock);
      ip::io::Construction& c = b_->c;
      const auto* blended = dynamic_cast<const ip::BlendedSurface*>(c.formula.get());
      if (!c.exact && c.convert && blended && blended->has_exact_form()) {
        for (const ip::KnotVector& k : blended->exact_knots()) {
          degree.push_back(static_cast<std::size_t>(k.degree()));
          size.push_back(static_cast<std::size_t>(k.count()));
        }
      } else if (ip::io::has_exact_form_after_conversion(c, progress)) {
        std::visit([&](const auto& e) {
          for (const ip::KnotVector* k : knots_of(e)) {
            degree.push_back(static_cast<std::size_t>(k->degree()));
            size.push_back(static_cast<std::size_t>(k->count()));
          }
        }, *c.exact);
      }
    }
    std::string out = std::string(kind) + "(type='" + b_->c.type + "'";
    if (degree.empty()) return out + ", exact_form=None)";
    return out + ", degree=" + tuple_text(degree) + ", control_points=" + tuple_text(size) + ")";
  }

  // The data's parameters along an axis, where the construction has data.
  // The parameters of a mesh's nodes, as write() places them: a tuple (u, v[, w]).
  [[nodiscard]] py::tuple mesh_params(const py::object& res, const py::object& sampling) const {
    return ip::python::mesh_params(b_->c, b_->lock, res, sampling, mesh_res);
  }

  [[nodiscard]] py::object data_params(std::size_t axis) const {
    const auto& data = b_->c.data;
    if (data.empty() || data.front().params.size() <= axis) return py::none();
    const auto& p = data.front().params[axis];
    return py::array_t<double>(static_cast<py::ssize_t>(p.size()), p.data());
  }

 protected:
  // The data points the build left in the caller's arrays (BuildOptions::borrow_arrays),
  // copied from them as they are now (the GIL held): data set index and points.
  using LentPoints = std::vector<std::pair<std::size_t, ip::io::PointStorage>>;
  [[nodiscard]] LentPoints lent_data() const {
    LentPoints out;
    const auto& data = b_->c.data;  // set at build; only `points` of lent sets change, under the lock
    for (std::size_t i = 0; i < data.size(); ++i) {
      if (data[i].array.empty()) continue;
      const auto it = sources_ ? sources_->find(data[i].array) : Sources::const_iterator();
      if (!sources_ || it == sources_->end())
        throw ip::error(ip::errc::internal, "the array \"" + data[i].array + "\" is not kept");
      auto a = point_array(it->second, data[i].array);
      const std::size_t expected = data[i].count();
      if (a->points.size() != expected)
        throw ip::error(ip::errc::size_mismatch, data[i].array + ": the array holds " + std::to_string(a->points.size()) +
                                                     " points now; the construction was built from " + std::to_string(expected));
      out.emplace_back(i, std::move(a->points));
    }
    return out;
  }

  // Lent data points in the construction while the lock is held, gone again after.
  class WithData {
   public:
    WithData(ip::io::Construction& c, LentPoints& lent) : c_(c), lent_(lent) {
      for (auto& [i, points] : lent_) std::swap(c_.data[i].points, points);
    }
    ~WithData() {
      for (auto& [i, points] : lent_) std::swap(c_.data[i].points, points);
    }
    WithData(const WithData&) = delete;
    WithData& operator=(const WithData&) = delete;

   private:
    ip::io::Construction& c_;
    LentPoints& lent_;
  };

  // A capsule that keeps the construction alive while arrays view its memory.
  [[nodiscard]] py::capsule alive() const {
    return py::capsule(new std::shared_ptr<Built>(b_), [](void* p) { delete static_cast<std::shared_ptr<Built>*>(p); });
  }
  template <class Exact>
  const Exact& exact() const {
    const ip::progress_callback progress = interruptible();  // Ctrl-C stops a long conversion
    py::gil_scoped_release free;
    std::lock_guard<std::mutex> hold(b_->lock);
    return std::get<Exact>(ip::io::exact_form(b_->c, progress));
  }
  std::shared_ptr<Built> b_;
  std::shared_ptr<const Sources> sources_;
};

class PySurface : public PyBuilt {
 public:
  using PyBuilt::PyBuilt;

  py::array_t<double> evaluate(const py::object& us_in, const py::object& vs_in) const {
    auto us = params(us_in, "us"), vs = params(vs_in, "vs");
    std::unique_ptr<ip::PointGrid> out;
    const ip::progress_callback progress = interruptible();
    {
      py::gil_scoped_release free;
      const ip::Surface& s = surface(us.size() * vs.size(), ip::io::Sample::points);
      out = std::make_unique<ip::PointGrid>(s.evaluate(us, vs, progress));  // its pages first touched by the threads that fill them
    }
    double* data = &out->data()->x;
    return owning_array(std::move(out), data, {static_cast<py::ssize_t>(us.size()), static_cast<py::ssize_t>(vs.size()), 3});
  }

  py::array_t<double> evaluate_derivatives(const py::object& us_in, const py::object& vs_in) const {
    auto us = params(us_in, "us"), vs = params(vs_in, "vs");
    std::unique_ptr<ip::Grid<ip::SurfaceDerivatives, 2>> out;
    const ip::progress_callback progress = interruptible();
    {
      py::gil_scoped_release free;
      const ip::Surface& s = surface(us.size() * vs.size(), ip::io::Sample::derivatives);
      // A block of u rows at a time (about 2^16 points, a few milliseconds), Ctrl-C
      // looked for between blocks: the surfaces' derivative grids take no callback.
      const std::size_t rows = std::max<std::size_t>(1, (std::size_t{1} << 16) / std::max<std::size_t>(1, vs.size()));
      if (us.size() <= rows) {
        out = std::make_unique<ip::Grid<ip::SurfaceDerivatives, 2>>(s.evaluate_derivatives(us, vs));
      } else {
        out = std::make_unique<ip::Grid<ip::SurfaceDerivatives, 2>>(
            ip::Grid<ip::SurfaceDerivatives, 2>::shape_type{us.size(), vs.size()}, ip::for_overwrite);
        for (std::size_t i0 = 0; i0 < us.size(); i0 += rows) {
          const auto block = std::span<const double>(us).subspan(i0, std::min(rows, us.size() - i0));
          const ip::Grid<ip::SurfaceDerivatives, 2> d = s.evaluate_derivatives(block, vs);
          std::copy(d.values().begin(), d.values().end(), out->data() + i0 * vs.size());
          progress(static_cast<double>(i0 + block.size()) / static_cast<double>(us.size()));
        }
      }
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

  // The exact B-spline form: degree, knots, and control points (and weights) as arrays
  // over the construction's own memory.
  py::dict to_bspline() const {
    const ip::BSplineSurface* e = &exact<ip::BSplineSurface>();
    const py::capsule keep = alive();
    const auto nu = static_cast<py::ssize_t>(e->control_points().shape()[0]);
    const auto nv = static_cast<py::ssize_t>(e->control_points().shape()[1]);
    py::dict d;
    d["degree"] = py::make_tuple(e->knots_u().degree(), e->knots_v().degree());
    d["knots_u"] = knots_array(e->knots_u(), keep);
    d["knots_v"] = knots_array(e->knots_v(), keep);
    d["control_points"] = read_only(py::array_t<double>({nu, nv, py::ssize_t{3}}, &e->control_points().data()->x, keep));
    d["weights"] = e->rational() ? py::object(read_only(py::array_t<double>({nu, nv}, e->weights().data(), keep))) : py::none();
    d["periodic"] = py::make_tuple(e->knots_u().periodic(), e->knots_v().periodic());
    return d;
  }

  py::dict closest_points(const py::object& points) const { return ip::python::closest_points(projector(), points); }
  py::dict intersect(const py::object& origins, const py::object& directions) const {
    return ip::python::intersect(projector(), origins, directions);
  }

 private:
  // The projector (io::surface_projector), made on the first query and kept.
  const ip::SurfaceProjector& projector() const {
    const ip::progress_callback progress = interruptible();  // Ctrl-C stops a long conversion
    py::gil_scoped_release free;
    std::lock_guard<std::mutex> hold(b_->lock);
    if (!b_->projector) b_->projector = ip::io::surface_projector(b_->c, progress);
    return *b_->projector;
  }
  const ip::Surface& surface(std::size_t points, ip::io::Sample what) const {
    std::lock_guard<std::mutex> hold(b_->lock);
    return ip::io::evaluator(b_->c, points, what);
  }
};

class PyVolume : public PyBuilt {
 public:
  using PyBuilt::PyBuilt;

  py::array_t<double> evaluate(const py::object& us_in, const py::object& vs_in, const py::object& ws_in) const {
    auto us = params(us_in, "us"), vs = params(vs_in, "vs"), ws = params(ws_in, "ws");
    std::unique_ptr<ip::PointGrid3> out;
    const ip::progress_callback progress = interruptible();
    {
      py::gil_scoped_release free;
      out = std::make_unique<ip::PointGrid3>(ip::io::volume_evaluator(b_->c).evaluate(us, vs, ws, progress));
    }
    double* data = &out->data()->x;
    return owning_array(std::move(out), data,
                        {static_cast<py::ssize_t>(us.size()), static_cast<py::ssize_t>(vs.size()),
                         static_cast<py::ssize_t>(ws.size()), 3});
  }

  py::tuple jacobians(const py::object& us_in, const py::object& vs_in, const py::object& ws_in) const {
    auto us = params(us_in, "us"), vs = params(vs_in, "vs"), ws = params(ws_in, "ws");
    std::unique_ptr<ip::VolumeJacobians> j;
    const ip::progress_callback progress = interruptible();
    {
      py::gil_scoped_release free;
      j = std::make_unique<ip::VolumeJacobians>(ip::io::volume_evaluator(b_->c).evaluate_jacobians(us, vs, ws, progress));
    }
    const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(us.size()), static_cast<py::ssize_t>(vs.size()),
                                         static_cast<py::ssize_t>(ws.size())};
    std::shared_ptr<ip::VolumeJacobians> owner(std::move(j));
    py::capsule keep(new std::shared_ptr<ip::VolumeJacobians>(owner),
                     [](void* p) { delete static_cast<std::shared_ptr<ip::VolumeJacobians>*>(p); });
    auto points_shape = shape;
    points_shape.push_back(3);
    return py::make_tuple(py::array_t<double>(points_shape, &owner->points.data()->x, keep),
                          py::array_t<double>(shape, owner->determinants.data(), keep));
  }

  py::array_t<double> point(double u, double v, double w) const {
    const ip::Vec3 p = ip::io::volume_evaluator(b_->c).point(u, v, w);
    return py::array_t<double>(3, &p.x);
  }

  py::dict to_bspline() const {
    const ip::BSplineVolume* e = &exact<ip::BSplineVolume>();
    const py::capsule keep = alive();
    const auto& sh = e->control_points().shape();
    const auto n0 = static_cast<py::ssize_t>(sh[0]), n1 = static_cast<py::ssize_t>(sh[1]), n2 = static_cast<py::ssize_t>(sh[2]);
    py::dict d;
    d["degree"] = py::make_tuple(e->knots_u().degree(), e->knots_v().degree(), e->knots_w().degree());
    d["knots_u"] = knots_array(e->knots_u(), keep);
    d["knots_v"] = knots_array(e->knots_v(), keep);
    d["knots_w"] = knots_array(e->knots_w(), keep);
    d["control_points"] = read_only(py::array_t<double>({n0, n1, n2, py::ssize_t{3}}, &e->control_points().data()->x, keep));
    d["weights"] =
        e->rational() ? py::object(read_only(py::array_t<double>({n0, n1, n2}, e->weights().data(), keep))) : py::none();
    d["periodic"] = py::make_tuple(e->knots_u().periodic(), e->knots_v().periodic(), e->knots_w().periodic());
    return d;
  }

  py::dict locate(const py::object& points) const {
    const ip::BSplineVolume& e = exact<ip::BSplineVolume>();
    const ip::VolumeLocator* in = nullptr;
    {
      py::gil_scoped_release free;
      std::lock_guard<std::mutex> hold(b_->lock);
      if (!b_->locator) b_->locator = std::make_unique<const ip::VolumeLocator>(e, e);
      in = b_->locator.get();
    }
    return ip::python::locate(*in, points);
  }
};

py::object wrap(ip::io::Built built, std::shared_ptr<const Sources> sources) {
  if (auto* curve = std::get_if<ip::io::CurveConstruction>(&built)) return ip::python::wrap_curve(std::move(*curve));
  auto b = std::make_shared<Built>();
  b->c = std::move(std::get<ip::io::Construction>(built));
  if (ip::io::is_volume(b->c)) {
    // A volume's formula evaluates without the lock: make its exact form now if it has one
    // and the formula is not kept (volume_evaluator needs one of them).
    return py::cast(PyVolume(std::move(b), std::move(sources)));
  }
  return py::cast(PySurface(std::move(b), std::move(sources)));
}

py::object build(const py::object& spec, const py::object& base_dir_in, const py::object& arrays) {
  const std::filesystem::path base_dir =
      ip::python::path_arg(base_dir_in, "build: base_dir is the directory data files are named from, a str or an os.PathLike");
  if (!py::isinstance<py::dict>(arrays))
    throw ip::error(ip::errc::wrong_type, "build: arrays is a dict of NumPy arrays by name, got a " +
                                              py::str(py::type::handle_of(arrays).attr("__name__")).cast<std::string>());
  ip::io::BuildOptions o;
  o.defer_exact = true;
  // The data points stay in the caller's arrays until info() asks for the check at the
  // data: the object keeps the arrays rather than a copy of the grid.
  o.borrow_arrays = true;
  o.progress = interruptible();
  auto sources = std::make_shared<Sources>();
  for (const auto& [k, v] : py::reinterpret_borrow<py::dict>(arrays)) {
    if (!py::isinstance<py::str>(k))
      throw ip::error(ip::errc::wrong_type, "build: the names of arrays are strings, got " + py::repr(k).cast<std::string>());
    const auto name = k.cast<std::string>();
    o.arrays[name] = point_array(v, name);
    (*sources)[name] = py::reinterpret_borrow<py::object>(v);
  }
  std::optional<ip::io::Built> c;
  if (py::isinstance<py::dict>(spec)) {
    const nlohmann::json j = ip::python::spec_json(spec);
    py::gil_scoped_release free;
    c = ip::io::build_any(j, base_dir, o);
  } else {
    const std::filesystem::path path =
        ip::python::path_arg(spec, "build: the spec is a dict or the path of a spec file (a str or an os.PathLike)");
    py::gil_scoped_release free;
    c = ip::io::build_any_file(path, o);
  }
  return wrap(std::move(*c), std::move(sources));
}

// interpatch.Error, with its codes, and the translation of the library's exceptions.
void bind_errors(py::module_& m) {
  error_type = PyErr_NewExceptionWithDoc("interpatch.Error",
                                         "Bad input: .code is the error's name (e.g. 'zero_chord'), the message "
                                         "names the place and the size of the problem, as the command line does.",
                                         PyExc_ValueError, nullptr);
  m.attr("Error") = py::handle(error_type);
  // Every code an Error can carry, in the order of interpatch::errc.
  py::list codes;
  for (int k = 0; k <= static_cast<int>(ip::errc::internal); ++k)
    codes.append(std::string(ip::to_string(static_cast<ip::errc>(k))));
  m.attr("ERROR_CODES") = py::tuple(codes);
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
}

// Construction and its Surface and Volume.
void bind_constructions(py::module_& m) {
  py::class_<PyBuilt>(m, "Construction", "What surfaces and volumes share.")
      .def_property_readonly("type", &PyBuilt::type, "The spec's \"type\".")
      .def("info", &PyBuilt::info,
           "The dict `interpatch info` prints for this construction. Its check at the data "
           "(max_data_error) compares with the NumPy arrays the construction was built from as they "
           "are when info() is called: the construction keeps those arrays, not a copy of them.")
      .def("write", &PyBuilt::write, py::arg("path"), py::arg("res") = py::none(), py::arg("sampling") = py::none(),
           "Write as `interpatch build` (.json .npz .step .igs: the exact form), `interpatch mesh` "
           "(.obj .ply .stl .vtk .vts .xyz: res = (nu, nv) vertices, 64 x 64 by default; a volume's "
           "(nu, nv, nw), 33 x 33 x 33) or `interpatch view` (.html: a viewer page of res samples, "
           "257 x 257 by default, a volume's 33 x 33 x 33) would. A mesh's nodes follow `sampling`, a dict "
           "as a spec's \"sampling\" (e.g. {'w': {'count': 41, 'first': 1e-3}}), or else the spec's own.")
      .def("mesh_params", &PyBuilt::mesh_params, py::arg("res") = py::none(), py::arg("sampling") = py::none(),
           "The parameters of the nodes write() places along each direction for a mesh of res vertices "
           "(the spec's sampling counts, or the kind's default): a tuple of arrays (u, v) or (u, v, w), graded "
           "as `sampling` (or else the spec's \"sampling\") says, even steps otherwise. "
           "Example: s.evaluate(*s.mesh_params()) gives the mesh's points.")
      .def_property_readonly("params_u", [](const PyBuilt& s) { return s.data_params(0); },
                             "Parameters of the data along u (None without data).")
      .def_property_readonly("params_v", [](const PyBuilt& s) { return s.data_params(1); },
                             "Parameters of the data along v (None without data).")
      .def_property_readonly("params_w", [](const PyBuilt& s) { return s.data_params(2); },
                             "Parameters of a volume's data along w (None without data).");

  py::class_<PySurface, PyBuilt>(m, "Surface",
                                 "A surface S(u, v) over [0, 1]², built from a spec or a constructor.\n\n"
                                 "Example:\n"
                                 "    s = interpatch.bilinear([0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 1])\n"
                                 "    s  # Surface(type='bilinear', degree=(1, 1), control_points=(2, 2))\n"
                                 "    s.evaluate([0, 0.5, 1], [0, 1]).shape  # (3, 2, 3)")
      .def("__repr__", [](const PySurface& s) { return s.repr("Surface"); })
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
      .def("closest_points", &PySurface::closest_points, py::arg("points"),
           "The closest point of the surface to each point, shape (..., 3): a dict of params (..., 2),\n"
           "points (..., 3) and distance (...,). The global answer: no point of the surface is nearer than\n"
           "distance less 1e-10 of its diagonal. Example: s.closest_points(scan)['distance'].max()")
      .def("intersect", &PySurface::intersect, py::arg("origins"), py::arg("directions"),
           "Every point where the rays origins[i] + t * directions[i], t >= 0, meet the surface\n"
           "(origins (n, 3); directions (n, 3), or (3,) for all): a dict of ray (h,) int64, t (h,),\n"
           "params (h, 2) and points (h, 3), by ray and then by t.")
      .def("to_bspline", &PySurface::to_bspline,
           "The exact B-spline form: {'degree': (p, q), 'knots_u', 'knots_v', 'control_points' (shape (nu, nv, 3)), "
           "'weights' (shape (nu, nv), or None), 'periodic': (bool, bool)}; the arrays view the construction's memory.")
      ;

  py::class_<PyVolume, PyBuilt>(m, "Volume",
                                "A volume S(u, v, w) over [0, 1]³, built from a spec or a constructor.\n\n"
                                "Example:\n"
                                "    v = interpatch.trilinear(np.indices((2, 2, 2)).transpose(1, 2, 3, 0))\n"
                                "    v  # Volume(type='trilinear', degree=(1, 1, 1), control_points=(2, 2, 2))\n"
                                "    v.evaluate([0, 1], [0, 1], [0, 0.5, 1]).shape  # (2, 2, 3, 3)")
      .def("__repr__", [](const PyVolume& v) { return v.repr("Volume"); })
      .def("evaluate", &PyVolume::evaluate, py::arg("us"), py::arg("vs"), py::arg("ws"),
           "Points at every (us[i], vs[j], ws[k]): shape (len(us), len(vs), len(ws), 3), over the library's memory.")
      .def("jacobians", &PyVolume::jacobians, py::arg("us"), py::arg("vs"), py::arg("ws"),
           "(points, det J) at every (us[i], vs[j], ws[k]): shapes (..., 3) and (len(us), len(vs), len(ws)); "
           "det J < 0 where the volume folds.")
      .def("point", &PyVolume::point, py::arg("u"), py::arg("v"), py::arg("w"), "S(u, v, w), shape (3,).")
      .def("to_bspline", &PyVolume::to_bspline,
           "The exact B-spline form: degree (p, q, r), knots_u/v/w, control_points (n0, n1, n2, 3), weights or None.")
      .def("locate", &PyVolume::locate, py::arg("points"),
           "The parameters of points of space, shape (..., 3): a dict of params (..., 3), points (..., 3),\n"
           "inside (...,) bool and residual (...,). Inside: V(params) = the point within 1e-10 of the\n"
           "diagonal; outside: params and points of the nearest point of the boundary, residual its distance.");
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "interpatch: interpolating curves, surfaces and solids, evaluated exactly.";
  bind_errors(m);
  bind_constructions(m);
  ip::python::bind_curve(m);
  ip::python::bind_spec_fields(m);
  m.def("build", &build, py::arg("spec"), py::arg("base_dir") = py::str("."), py::arg("arrays") = py::dict(),
        "A spec (docs/spec-format.md) as a dict, or the path of a spec file, built: a Surface, a Volume, or "
        "a Curve for a curve spec (a curve at the top level, without \"type\").\n\n"
        "Example: s = interpatch.build({'type': 'bilinear', 'p00': [0, 0, 0], 'p01': [0, 1, 0], "
        "'p10': [1, 0, 0], 'p11': [1, 1, 1]})");
}
