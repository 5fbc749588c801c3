// The subcommands as the command line runs them: usage checked as bad usage (exit
// 2), progress shown on a terminal, warnings printed; the work itself is io's.

#include "commands.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <system_error>
#include <variant>
#include <vector>

#include "interpatch/error.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/project.hpp"
#include "interpatch/io/view.hpp"
#include "progress.hpp"

namespace interpatch::cli {

namespace fs = std::filesystem;

namespace {

// A count on the command line: digits only. nullopt for anything else; the
// largest size_t for a count too large to represent.
std::optional<std::size_t> parse_count(std::string_view s) {
  if (s.empty() || !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; }))
    return std::nullopt;
  std::size_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range) return std::numeric_limits<std::size_t>::max();
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

// The io library's checks of usage (formats, counts) throw error; on the command
// line what they refuse is bad usage (exit 2).
template <class Check>
void as_usage(const Check& check) {
  try {
    check();
  } catch (const error& e) {
    throw usage_error(e.what());
  }
}

}  // namespace

std::vector<std::size_t> parse_counts(std::string_view text, const CountsOption& o) {
  const auto bad = [&](const std::string& why) {
    return usage_error(std::string(o.name) + " '" + std::string(text) + "': " + why);
  };
  std::vector<std::string_view> fields;
  for (std::size_t from = 0;;) {
    const auto x = text.find_first_of("xX", from);
    fields.push_back(text.substr(from, x == std::string_view::npos ? x : x - from));
    if (x == std::string_view::npos) break;
    from = x + 1;
  }
  if (fields.size() == 1 && !o.single)
    throw bad("expected " + std::string(o.surface_form) + ", e.g. " + std::string(o.surface_example) + " (" +
              std::string(o.unit) + " along u and v), or " + std::string(o.volume_form) + " for a volume");
  if (fields.size() > 3)
    throw bad("expected " + std::string(o.surface_form) + " (a surface) or " + std::string(o.volume_form) +
              " (a volume), not more counts");
  std::vector<std::size_t> counts;
  for (const std::string_view f : fields) {
    const auto n = parse_count(f);
    if (!n && fields.size() == 1)
      throw bad("expected a whole number K >= 2 (K " + std::string(o.unit) + " along each direction), " +
                std::string(o.surface_form) + " (a surface) or " + std::string(o.volume_form) + " (a volume)");
    if (!n)
      throw bad("expected " + std::string(fields.size() == 2 ? o.surface_form : o.volume_form) + " with whole numbers, e.g. " +
                std::string(fields.size() == 2 ? o.surface_example : o.volume_example));
    counts.push_back(*n);
  }
  as_usage([&] { io::check_counts(counts, o, std::string(o.name) + " '" + std::string(text) + "'"); });
  return counts;
}

Resolution parse_resolution(std::string_view text) {
  const std::vector<std::size_t> n = parse_counts(text, res_option);
  return {n[0], n[1], n.size() == 3 ? n[2] : 0};
}

std::vector<std::size_t> parse_grid(std::string_view text) { return parse_counts(text, grid_option); }

Resolution grid_resolution(const std::vector<std::size_t>& counts, const io::Construction& c) {
  Resolution grid;
  as_usage([&] { grid = io::grid_resolution(counts, c, grid_option); });
  return grid;
}

void check_counts_kind(const io::Construction& c, const CountsOption& o, const Resolution& counts) {
  as_usage([&] { io::check_counts_kind(c, o, counts); });
}

Input parse_input(const fs::path& spec, std::string_view shape) {
  Input in{spec, io::input_kind(spec), {}};
  const std::string name = "'" + spec.string() + "'";
  if (in.kind == Input::Kind::csv && shape.empty())
    throw usage_error(name + " is a CSV file of points: give the shape of its grid, --shape NxM (a surface) or "
                      "--shape NxMxL (a volume), the points one per line in C order (last index fastest)");
  if (in.kind == Input::Kind::spec && !shape.empty())
    throw usage_error("--shape '" + std::string(shape) + "': " + name +
                      " is read as a spec; --shape gives the grid of a .csv file of points given in its place "
                      "(in a spec, a CSV file's shape is its \"shape\" field)");
  if (in.kind == Input::Kind::npy && !shape.empty())
    throw usage_error("--shape '" + std::string(shape) + "': " + name + " is a .npy file, whose header gives its shape; "
                      "--shape is for .csv files");
  if (in.kind == Input::Kind::csv) in.shape = parse_counts(shape, shape_option);
  return in;
}

void check_build_output(const fs::path& out) { as_usage([&] { io::check_build_output(out); }); }
void check_mesh_output(const fs::path& out) { as_usage([&] { io::check_mesh_output(out); }); }
void check_eval_output(const fs::path& out) { as_usage([&] { io::check_eval_output(out); }); }
void check_info_output(const fs::path& out) { as_usage([&] { io::check_info_output(out); }); }
void check_view_output(const fs::path& out) { as_usage([&] { io::check_view_output(out); }); }

void check_mesh_kind(const io::Construction& c, const fs::path& out, const Resolution& res) {
  as_usage([&] { io::check_mesh_kind(c, out, res, res_option); });
}

void write_mesh(io::Construction& c, const fs::path& out, const Resolution& res) {
  check_mesh_kind(c, out, res);
  ProgressLine progress("meshing");
  report_warnings(io::write_mesh(c, out, res, res_option, progress.callback()));
}

void write_eval(io::Construction& c, const fs::path& out, const Resolution& grid) {
  cli::check_counts_kind(c, grid_option, grid);
  ProgressLine progress("evaluating");
  io::write_eval(c, out, grid, grid_option, progress.callback(), [&] { progress.clear(); });
}

nlohmann::ordered_json info(const io::Construction& c) {
  ProgressLine progress("checking");
  return io::info_json(c, progress.callback());
}

namespace {

// What `build` makes of `options`, with the progress line of a terminal.
template <class Build>
auto with_progress(io::BuildOptions& options, const Build& build) {
  ProgressLine progress("building");
  options.progress = progress.callback();
  return build(options);
}

}  // namespace

io::Construction build_spec(const fs::path& spec, io::BuildOptions options) {
  return with_progress(options, [&](const io::BuildOptions& o) { return io::build_file(spec, o); });
}

io::Built build_any_input(const Input& in, io::BuildOptions options) {
  return with_progress(options, [&](const io::BuildOptions& o) { return io::build_any_input(in, o); });
}

const io::CurveConstruction* curve_of(const io::Built& b) { return std::get_if<io::CurveConstruction>(&b); }

void refuse_curve(const Input& in, const io::Built& b, std::string_view command) {
  if (curve_of(b))
    throw usage_error("'" + in.path.string() + "' is a curve spec: " + std::string(command) +
                      " takes surfaces and volumes; eval, info and build take curves");
}

io::Construction build_input(const Input& in, io::BuildOptions options) {
  return with_progress(options, [&](const io::BuildOptions& o) { return io::build_input(in, o); });
}

void report_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::fprintf(stderr, "interpatch: warning: %s\n", w.c_str());
}

const std::vector<std::string>& warnings_of(const io::Built& b) {
  return std::visit([](const auto& c) -> const std::vector<std::string>& { return c.warnings; }, b);
}

int build_command(const Input& in, const fs::path& out) {
  check_build_output(out);
  io::check_writable(out);
  io::Built b = cli::build_any_input(in, {.progress = {}, .keep_data = false, .defer_exact = false, .arrays = {}});
  std::visit([&](auto& c) { write_build(c, out); }, b);
  report_warnings(warnings_of(b));
  return 0;
}

int mesh_command(const Input& in, const fs::path& out, std::string_view res_text) {
  const std::optional<Resolution> given = res_text.empty() ? std::nullopt : std::optional(parse_resolution(res_text));
  check_mesh_output(out);
  if (io::is_polymesh_path(out)) io::check_writable_directory(out);
  else io::check_writable(out);
  if (given) require_mesh_room(*given, out);
  // A mesh samples the construction; its exact form is made only if that costs less.
  io::Built b = cli::build_any_input(in, {.progress = {}, .keep_data = false, .defer_exact = true, .arrays = {}});
  refuse_curve(in, b, "mesh");
  io::Construction& c = std::get<io::Construction>(b);
  if (given && c.blocks)
    throw usage_error("--res " + std::string(res_text) +
                      ": a blocks spec takes its counts from each block's \"sampling\", tied across the faces they share");
  const Resolution res = given ? *given : io::default_resolution(c);
  check_mesh_kind(c, out, res);
  if (!given) require_mesh_room(res, out);
  write_mesh(c, out, res);
  report_warnings(c.warnings);
  return 0;
}

int eval_command(const Input& in, const fs::path& out, std::string_view grid_text) {
  const std::vector<std::size_t> counts = parse_grid(grid_text);
  check_eval_output(out);
  io::check_writable(out);
  // Before the build, the grid as given (K: a curve's K points, the least it can be);
  // after it, the grid of the spec's kind (K of a surface: KxK, of a volume: KxKxK).
  require_eval_room({counts[0], counts.size() > 1 ? counts[1] : 1, counts.size() > 2 ? counts[2] : 0}, out);
  // Evaluation samples the construction; its exact form is made only if that costs less.
  io::Built b = cli::build_any_input(in, {.progress = {}, .keep_data = false, .defer_exact = true, .arrays = {}});
  if (const io::CurveConstruction* curve = curve_of(b)) {
    if (counts.size() != 1)
      throw usage_error("--grid '" + std::string(grid_text) + "': '" + in.path.string() +
                        "' is a curve spec, evaluated at K points: give --grid K");
    {
      ProgressLine progress("evaluating");
      io::write_eval(*curve, out, counts[0], grid_option, progress.callback(), [&] { progress.clear(); });
    }
    report_warnings(warnings_of(b));
    return 0;
  }
  io::Construction& c = std::get<io::Construction>(b);
  const Resolution grid = grid_resolution(counts, c);
  require_eval_room(grid, out);
  write_eval(c, out, grid);
  report_warnings(c.warnings);
  return 0;
}

int info_command(const Input& in, const std::optional<fs::path>& out) {
  if (out) {
    check_info_output(*out);
    io::check_writable(*out);
  }
  const io::Built b = cli::build_any_input(in);
  const io::CurveConstruction* curve = curve_of(b);
  const std::string text = io::pretty_json(curve ? io::curve_info_json(*curve) : info(std::get<io::Construction>(b)));
  if (out) {
    io::write_atomically(*out, [&](std::ostream& os) { os << text; });
  } else {
    std::cout << text << std::flush;
    if (!std::cout) throw error(errc::file_unwritable, "standard output: write failed");
  }
  report_warnings(warnings_of(b));
  return 0;
}

namespace {

// What project and intersect share: the output's format checked first, the
// construction built with its exact form deferred (the query makes it), the work under
// a progress line.
template <class Work>
int query_command(const Input& in, const fs::path& out, const char* doing, Work&& work) {
  as_usage([&] { io::check_projection_output(out); });
  io::check_writable(out);
  io::Built b = cli::build_any_input(in, {.progress = {}, .keep_data = false, .defer_exact = true, .arrays = {}});
  {
    ProgressLine progress(doing);
    work(b, progress.callback());
  }
  report_warnings(warnings_of(b));
  return 0;
}

}  // namespace

int project_command(const Input& in, const fs::path& points, const fs::path& out) {
  return query_command(in, out, "projecting", [&](io::Built& b, const progress_callback& progress) {
    (void)io::write_projection(b, points, out, progress);
  });
}

int intersect_command(const Input& in, const fs::path& rays, const fs::path& out) {
  return query_command(in, out, "intersecting", [&](io::Built& b, const progress_callback& progress) {
    if (curve_of(b)) throw usage_error("'" + in.path.string() + "' is a curve spec: rays meet surfaces");
    (void)io::write_intersections(std::get<io::Construction>(b), rays, out, progress);
  });
}

int view_command(const Input& in, const fs::path& out, std::string_view res_text) {
  std::optional<Resolution> given;
  if (!res_text.empty()) {
    const std::vector<std::size_t> n = parse_counts(res_text, view_res_option);
    given = Resolution{n[0], n[1], n.size() == 3 ? n[2] : 0};
  }
  check_view_output(out);
  io::check_writable(out);
  // The page holds what `info` prints, whose error at the data needs the data.
  const io::Built b = cli::build_any_input(in);
  refuse_curve(in, b, "view");
  const io::Construction& c = std::get<io::Construction>(b);
  io::ViewOptions options;
  if (given) {
    cli::check_counts_kind(c, view_res_option, *given);
    options.resolution = {given->nu, given->nv, given->nw};
  }
  options.title = in.path.stem().string();
  io::write_view(out, c, options);
  report_warnings(c.warnings);
  return 0;
}

}  // namespace interpatch::cli
