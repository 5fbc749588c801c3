// The plan of a split run: what the request asks for, and whether the split run
// reads it (the points an .npy grid of doubles or floats, the output the format it
// writes) or rank 0 runs it alone.

#include <algorithm>
#include <cctype>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "io/spec/reader.hpp"
#include "mpi/driver.hpp"

namespace interpatch::mpi {

namespace fs = std::filesystem;

Plan plan_of(const Request& r, const Team& team) {
  Plan plan;
  const cli::Input in = cli::parse_input(r.spec, r.shape);
  const fs::path out = r.out;
  if (r.build) cli::check_build_output(out);
  else {
    plan.counts = cli::parse_grid(r.grid);
    cli::check_eval_output(out);
  }
  io::check_writable(out);
  std::string ext = out.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != (r.build ? ".npz" : ".npy") || in.kind == cli::Input::Kind::csv) return plan;
  plan.spec = in.kind == cli::Input::Kind::npy ? cli::data_file_spec(in) : io::read_json_file(in.path);
  plan.base = in.path.parent_path();
  const nlohmann::json& s = plan.spec;
  if (!s.is_object() || !s.contains("type") || !s["type"].is_string()) return plan;
  const std::string type = s["type"].get<std::string>();
  const bool approx = type == "approximate";
  plan.dims = type == "interpolate" || approx ? 2 : type == "interpolate_volume" ? 3 : 0;
  if (plan.dims == 0 || !s.contains("points") || !s["points"].is_object() || !s["points"].contains("npy")) return plan;
  io::reader::Context ctx;
  ctx.base_dir = plan.base;
  plan.file = io::reader::file_name(s["points"], "npy", "/points");
  plan.points = ctx.resolve(plan.file);
  // The header, read by every process; anything the split run does not read (other
  // dtypes, Fortran order, a shape that is not a grid, short data) is left to the
  // single process, which says what is wrong.
  std::string head;
  const std::uint64_t size = io::reader::at("/points", [&] {
    const InputFile file(plan.points, team);
    head.resize(static_cast<std::size_t>(std::min<std::uint64_t>(file.size(), 1 << 20)));
    file.read(head.data(), head.size(), 0);
    return file.size();
  });
  std::istringstream is(head);
  try {
    plan.header = io::internal::read_npy_header(is, size, plan.points.string());
  } catch (const error&) {
    return plan;
  }
  const auto dt = io::internal::parse_npy_dtype(plan.header.descr);
  const auto& shape = plan.header.shape;
  if (!dt || dt->kind != 'f' || shape.size() != plan.dims + 1 || shape.back() != 3)
    return plan;
  plan.dtype = *dt;
  std::uint64_t count = 1;
  for (const std::size_t e : shape) {
    if (e != 0 && count > (std::uint64_t{1} << 62) / e) return plan;
    count *= e;
  }
  if (count == 0 || plan.header.data_offset + count * dt->size != size) return plan;
  if (approx) {
    // Options the single process refuses run there.
    try {
      io::reader::Context fields;
      fields.base_dir = plan.base;
      (void)io::reader::check_fields(s, "", io::reader::find_type("approximate")->fields, fields);
      const std::vector<std::size_t> grid(shape.begin(), shape.begin() + 2);
      if (grid[0] < 2 || grid[1] < 2) return plan;
      plan.approx = io::reader::approximation_options<2>(s, "", grid, "/points");
    } catch (const error&) {
      return plan;
    }
    plan.approximate = true;
  }
  plan.split = true;
  return plan;
}

}  // namespace interpatch::mpi
