#include "sampling.hpp"

#include <pybind11/numpy.h>

#include "inputs.hpp"

namespace interpatch::python {

std::optional<Sampling> sampling_arg(const py::object& sampling, const io::Construction& c) {
  if (sampling.is_none()) return std::nullopt;
  return io::read_sampling(spec_json(sampling), io::is_volume(c) ? 3 : 2);
}

py::tuple mesh_params(io::Construction& c, std::mutex& lock, const py::object& res_in, const py::object& sampling_in,
                      const io::CountsOption& option) {
  const std::optional<Sampling> sampling = sampling_arg(sampling_in, c);
  std::optional<io::Resolution> res;
  if (!res_in.is_none()) {
    const std::vector<std::size_t> n = counts(res_in, "res");
    res = io::Resolution{n[0], n[1], n.size() == 3 ? n[2] : 0};
    io::check_counts(io::counts_of(*res), option);
    io::check_counts_kind(c, option, *res);
  }
  GradedParameters g;
  {
    py::gil_scoped_release free;
    std::lock_guard<std::mutex> hold(lock);
    const Sampling* s = sampling ? &*sampling : nullptr;
    g = io::sample_parameters(c, res ? *res : io::default_resolution(c, s), s);
  }
  py::list out;
  for (std::size_t d = 0; d < (io::is_volume(c) ? 3u : 2u); ++d)
    out.append(py::array_t<double>(static_cast<py::ssize_t>(g.params[d].size()), g.params[d].data()));
  return py::tuple(out);
}

}  // namespace interpatch::python
