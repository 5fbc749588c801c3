// closest_points, locate and intersect: the points converted once, the queries on
// every thread without the GIL, Ctrl-C looked for between blocks.

#include "locate.hpp"

#include <pybind11/numpy.h>

#include <string>
#include <vector>

#include "inputs.hpp"
#include "interpatch/error.hpp"

namespace interpatch::python {

namespace {

std::vector<py::ssize_t> with(const std::vector<std::size_t>& shape, py::ssize_t last) {
  std::vector<py::ssize_t> s(shape.begin(), shape.end());
  if (last > 0) s.push_back(last);
  return s;
}

// The points of `x` (shape (..., 3)) and their shape without the 3.
std::shared_ptr<io::PointArray> points_of(const py::handle& x, const char* name) { return point_array(x, name); }

template <class Answer, class Run>
std::vector<Answer> run(const io::PointArray& a, Run&& query) {
  std::vector<Answer> out(a.points.size());
  const progress_callback progress = interruptible();
  py::gil_scoped_release free;
  query(std::span<const Vec3>(a.points.data(), a.points.size()), std::span<Answer>(out), progress);
  return out;
}

template <class Answer>
py::dict nearest(const std::vector<Answer>& got, const std::vector<std::size_t>& shape, int k) {
  py::array_t<double> params(with(shape, k)), points(with(shape, 3)), dist(with(shape, 0));
  double* pp = params.mutable_data();
  double* xp = points.mutable_data();
  double* dp = dist.mutable_data();
  for (std::size_t i = 0; i < got.size(); ++i) {
    if constexpr (std::is_same_v<Answer, CurvePoint>) {
      pp[i] = got[i].t;
    } else {
      pp[2 * i] = got[i].u, pp[2 * i + 1] = got[i].v;
    }
    xp[3 * i] = got[i].point.x, xp[3 * i + 1] = got[i].point.y, xp[3 * i + 2] = got[i].point.z;
    dp[i] = got[i].distance;
  }
  py::dict d;
  d["params"] = params;
  d["points"] = points;
  d["distance"] = dist;
  return d;
}

}  // namespace

py::dict closest_points(const CurveProjector& on, const py::handle& x) {
  const auto a = points_of(x, "points");
  const auto got = run<CurvePoint>(*a, [&](auto p, auto o, const auto& pr) { on.closest(p, o, pr); });
  py::dict d = nearest(got, a->shape, 0);
  return d;
}

py::dict closest_points(const SurfaceProjector& on, const py::handle& x) {
  const auto a = points_of(x, "points");
  const auto got = run<SurfacePoint>(*a, [&](auto p, auto o, const auto& pr) { on.closest(p, o, pr); });
  return nearest(got, a->shape, 2);
}

py::dict locate(const VolumeLocator& in, const py::handle& x) {
  const auto a = points_of(x, "points");
  const auto got = run<VolumePoint>(*a, [&](auto p, auto o, const auto& pr) { in.locate(p, o, pr); });
  py::array_t<double> params(with(a->shape, 3)), points(with(a->shape, 3)), res(with(a->shape, 0));
  py::array_t<bool> inside(with(a->shape, 0));
  for (std::size_t i = 0; i < got.size(); ++i) {
    const VolumePoint& g = got[i];
    double* p = params.mutable_data() + 3 * i;
    p[0] = g.u, p[1] = g.v, p[2] = g.w;
    double* x3 = points.mutable_data() + 3 * i;
    x3[0] = g.point.x, x3[1] = g.point.y, x3[2] = g.point.z;
    inside.mutable_data()[i] = g.inside;
    res.mutable_data()[i] = g.residual;
  }
  py::dict d;
  d["params"] = params;
  d["points"] = points;
  d["inside"] = inside;
  d["residual"] = res;
  return d;
}

py::dict intersect(const SurfaceProjector& on, const py::handle& origins_in, const py::handle& directions_in) {
  const auto o = points_of(origins_in, "origins");
  // One direction for every ray: (3,) taken as (1, 3).
  const py::object dirs = py::module_::import("numpy").attr("atleast_2d")(directions_in);
  const auto d = points_of(dirs, "directions");
  const std::size_t n = o->points.size();
  struct Hit {
    std::size_t ray;
    RayHit h;
  };
  std::vector<Hit> hits;
  {
    const progress_callback progress = interruptible();
    py::gil_scoped_release free;
    std::vector<std::vector<RayHit>> per(n);
    on.intersect(std::span<const Vec3>(o->points.data(), n), std::span<const Vec3>(d->points.data(), d->points.size()),
                 per, progress);
    for (std::size_t i = 0; i < n; ++i)
      for (const RayHit& h : per[i]) hits.push_back({i, h});
  }
  const auto h = static_cast<py::ssize_t>(hits.size());
  py::array_t<std::int64_t> ray(h);
  py::array_t<double> t(h), params({h, py::ssize_t{2}}), points({h, py::ssize_t{3}});
  for (std::size_t i = 0; i < hits.size(); ++i) {
    ray.mutable_data()[i] = static_cast<std::int64_t>(hits[i].ray);
    t.mutable_data()[i] = hits[i].h.t;
    params.mutable_data()[2 * i] = hits[i].h.u, params.mutable_data()[2 * i + 1] = hits[i].h.v;
    const Vec3& p = hits[i].h.point;
    points.mutable_data()[3 * i] = p.x, points.mutable_data()[3 * i + 1] = p.y, points.mutable_data()[3 * i + 2] = p.z;
  }
  py::dict out;
  out["ray"] = ray;
  out["t"] = t;
  out["params"] = params;
  out["points"] = points;
  return out;
}

}  // namespace interpatch::python
