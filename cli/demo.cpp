// `interpatch demo`: every construction on the examples of examples/, embedded at
// build time (cmake/examples.cmake). Each example's spec (and the data files it
// refers to) is written into the output directory first and read back from there,
// so the demo goes through exactly the path a user's spec takes; then every output
// the command line offers is written beside it.

#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "example_assets.hpp"
#include "interpatch/error.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/view.hpp"

namespace interpatch::cli {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

namespace {

// The data of the one example not in examples/: z = x² - y² + 0.3 x y³ on 8 x 8 points.
PointGrid saddle() {
  PointGrid g({8, 8});
  for (std::size_t i = 0; i < 8; ++i)
    for (std::size_t j = 0; j < 8; ++j) {
      const double x = -1 + 2 * static_cast<double>(i) / 7, y = -1 + 2 * static_cast<double>(j) / 7;
      g(i, j) = {x, y, x * x - y * y + 0.3 * x * y * y * y};
    }
  return g;
}

ojson grid_json(const PointGrid& g) {
  ojson rows = ojson::array();
  for (std::size_t i = 0; i < g.extent(0); ++i) {
    ojson row = ojson::array();
    for (std::size_t j = 0; j < g.extent(1); ++j) row.push_back({g(i, j).x, g(i, j).y, g(i, j).z});
    rows.push_back(std::move(row));
  }
  return rows;
}

bool is_point_grid(const ojson& v) {
  return v.is_array() && !v.empty() && v[0].is_array() && !v[0].empty() && v[0][0].is_array();
}

// A spec as people write them: one member per line, one grid row per line (the
// specs made here hold no lists of curves or corners).
std::string spec_text(const ojson& spec) {
  std::string s = "{\n";
  bool first = true;
  for (auto it = spec.begin(); it != spec.end(); ++it) {
    s += first ? "  " : ",\n  ";
    first = false;
    s += ojson(it.key()).dump() + ": ";
    if (is_point_grid(it.value())) {
      s += "[\n";
      for (std::size_t i = 0; i < it.value().size(); ++i) s += (i ? ",\n    " : "    ") + it.value()[i].dump();
      s += "\n  ]";
    } else {
      s += it.value().dump();
    }
  }
  return s + "\n}\n";
}

void write_text(const fs::path& path, const std::string& text) {
  io::write_atomically(path, [&](std::ostream& os) { os << text; });
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The bytes of examples/NAME as the build embedded them.
std::string_view example_file(std::string_view name) {
  for (const embedded::File& f : embedded::files)
    if (f.name == name) return f.bytes();
  throw error(errc::internal, "interpatch demo: examples/" + std::string(name) + " is not embedded in this build");
}

struct Example {
  Example(std::string n, std::string a, std::string s = {}, std::string file = {}, bool every = false)
      : name(std::move(n)), about(std::move(a)), spec(std::move(s)), spec_file(std::move(file)), every_mesh_format(every) {}
  std::string name;
  std::string about;
  std::string spec;       // written as NAME.spec.json; empty: examples/NAME.json
  std::string spec_file;  // or: an existing file in DIR is the spec
  bool every_mesh_format;
};

// The examples shown, in this order: those of examples/ by name, a saddle of degree
// 5 that is no checked-in example, and terrain's exact form read back from the files
// the demo wrote of it (so after terrain).
std::vector<Example> examples() {
  const std::string saddle_spec = spec_text({{"type", "interpolate"},
                                             {"comment", "A saddle through an 8x8 grid, degree 5 in both directions (C4)."},
                                             {"degree", {5, 5}},
                                             {"points", grid_json(saddle())}});
  const std::string npz_spec = spec_text({{"type", "bspline_surface"}, {"npz", "terrain.bspline.npz"}});
  return {
      {"hemisphere", "bicubic, centripetal, through a 9x17 grid with a pole row", "", "", true},
      {"terrain", "bicubic, chord length, through 7x13 surveyed heights"},
      {"approximate_terrain", "a noisy 60x45 survey with a void and a lost row, to a tolerance of 0.35 m"},
      {"wave", "degrees (2, 3), uniform parameters, 6x9 grid"},
      {"saddle", "degrees (5, 5) through an 8x8 grid", saddle_spec},
      {"bilinear", "Rogers & Adams Example 6-9: Q(0.5, 0.5) = (0.5, 0.5, 0.5)"},
      {"ruled", "between a line and a Hermite arc"},
      {"coons", "linear Coons patch from four boundary curves"},
      {"coons_hermite", "Coons patch with cubic Hermite blending (zero cross slopes of the blends)"},
      {"coons_cross", "bicubically blended Coons patch with cross-boundary derivatives"},
      {"coons_gregory", "incompatible twist at p00 blended by Gregory's correction (no exact form)"},
      {"network_gordon", "Gordon surface through a 4 x 5 network of curves"},
      {"network_coons", "C1 network of Coons patches with Hermite blending"},
      {"network_closed", "closed Gordon surface through 4 closed sections and 4 curves along them"},
      {"network_drawn", "Gordon surface through 5 x 4 curves drawn freehand, in no order, some reversed"},
      {"hermite_patch", "bicubic Hermite (Ferguson) patch from corner data"},
      {"pipe", "closed around v (\"periodic\": [false, true]), C2 across the seam, through 20x33 points"},
      {"half_cylinder", "11x5 grid read from half_cylinder.npy"},
      {"twisted_strip", "5x9 grid read from twisted_strip.csv"},
      {"trilinear", "a leaning, tapered block from 8 corners"},
      {"coons_volume", "transfinite volume from 6 faces (bilinear, bspline_surface, interpolate)"},
      {"hermite_volume", "tricubic Hermite volume from a point frame"},
      {"annular_sector", "tricubic/quadratic volume through a 5x7x3 grid"},
      {"terrain_exact", "terrain.bspline.json (the build output) read back as a bspline_surface spec", "",
       "terrain.bspline.json"},
      {"terrain_npz", "terrain.bspline.npz (the build output for NumPy) read back as a bspline_surface spec", npz_spec},
  };
}

fs::path prepare(fs::path dir) {
  if (!dir.has_filename()) dir = dir.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return dir;
  if (fs::exists(dir, ec))
    throw error(errc::file_unwritable, "'" + dir.string() + "': cannot write the demo there: not a directory");
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec))
    throw error(errc::file_unwritable,
                "'" + dir.string() + "': cannot create it: its parent directory '" + parent.string() + "' does not exist");
  if (!fs::create_directory(dir, ec) && ec)
    throw error(errc::file_unwritable, "'" + dir.string() + "': cannot create it: " + ec.message());
  return dir;
}

// One example in the gallery.
struct GalleryEntry {
  std::string name, type, about, thumbnail_svg, summary;
};

std::string html_text(const std::string& text) {
  std::string s;
  for (const char ch : text) {
    if (ch == '<') s += "&lt;";
    else if (ch == '>') s += "&gt;";
    else if (ch == '&') s += "&amp;";
    else if (ch == '"') s += "&quot;";
    else s += ch;
  }
  return s;
}

// DIR/index.html: a card per example, its picture (drawn by interpatch, no browser
// needed to make it) linking to its viewer page.
void write_gallery(const fs::path& path, const std::vector<GalleryEntry>& entries) {
  std::string page =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>interpatch demo</title>\n<style>\n"
      "body { margin: 0; padding: 16px 24px; background: #1b1d23; color: #e8e8e8; font: 14px/1.4 system-ui, sans-serif; }\n"
      "h1 { font-size: 20px; } .cards { display: flex; flex-wrap: wrap; gap: 16px; }\n"
      ".card { width: 240px; background: #2b2f38; border-radius: 6px; overflow: hidden; }\n"
      ".card a { color: inherit; text-decoration: none; } .card svg { display: block; }\n"
      ".card div { padding: 6px 10px 10px; } .card b { font-size: 15px; } .card small { color: #aab; display: block; }\n"
      "</style>\n</head>\n<body>\n<h1>interpatch demo</h1>\n"
      "<p>Every example of <code>interpatch demo</code>: click a picture to open its viewer page (3D, offline), "
      "made by <code>interpatch view</code>. The other outputs of each example are beside this file.</p>\n"
      "<div class=\"cards\">\n";
  for (const GalleryEntry& e : entries) {
    const std::string view = html_text(e.name) + ".view.html";
    page += "<div class=\"card\"><a href=\"" + view + "\">" + e.thumbnail_svg + "<div><b>" + html_text(e.name) +
            "</b> <small>" + html_text(e.type) + ": " + html_text(e.about) + "</small><small>" + html_text(e.summary) +
            "</small></div></a></div>\n";
  }
  page += "</div>\n</body>\n</html>\n";
  write_text(path, page);
}

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2g", v);
  return buf;
}

// Writes the example's spec into DIR (with the data files it reads, from examples/)
// and returns its path; an example read from a file the demo wrote is left as it is.
fs::path write_spec(const Example& ex, const fs::path& dir, std::vector<std::string>& written) {
  if (!ex.spec_file.empty()) return dir / ex.spec_file;
  const std::string text = ex.spec.empty() ? std::string(example_file(ex.name + ".json")) : ex.spec;
  const ojson spec = ojson::parse(text);
  if (const auto pts = spec.find("points"); pts != spec.end() && pts->is_object())
    for (const char* form : {"npy", "csv"})
      if (pts->contains(form)) {
        const std::string data = (*pts)[form].get<std::string>();
        write_text(dir / data, std::string(example_file(data)));
        written.push_back(data);
      }
  const fs::path path = dir / (ex.name + ".spec.json");
  write_text(path, text);
  written.push_back(path.filename().string());
  return path;
}

// Every output of the command line of `c` into DIR as NAME.*; returns what info prints.
ojson write_outputs(io::Construction& c, const Example& ex, const fs::path& dir,
                    std::vector<std::string>& written) {
  constexpr Resolution eval_grid{33, 33, 0}, volume_eval_grid{17, 17, 17};
  const Resolution res = default_surface_resolution, volume_res = default_volume_resolution;
  // The viewer pages of the demo are lighter than the command's default (257 x 257).
  constexpr std::array<std::size_t, 3> view_res{129, 129, 0}, volume_view_res{17, 17, 17};
  const auto out = [&](const std::string& suffix) {
    written.push_back(ex.name + suffix);
    return dir / (ex.name + suffix);
  };
  const bool volume = io::is_volume(c);
  if (c.exact) {
    write_build(c, out(".bspline.json"));
    write_build(c, out(".bspline.npz"));  // the same arrays for NumPy (numpy.load)
    write_build(c, out(".step"));  // a face (a closed shell of six for a volume) for CAD systems
    write_build(c, out(".igs"));
  }
  write_eval(c, out(".eval.npy"), volume ? volume_eval_grid : eval_grid);
  write_eval(c, out(".eval.csv"), volume ? volume_eval_grid : eval_grid);
  if (volume) {
    write_mesh(c, out(".vts"), volume_res);
    write_mesh(c, out(".vtk"), volume_res);
    write_mesh(c, out(".xyz"), volume_res);
    written.push_back(ex.name + ".f");  // the Jacobian beside the Plot3D grid
  } else {
    write_mesh(c, out(".obj"), res);
    write_mesh(c, out(".vtk"), res);
    if (ex.every_mesh_format)
      for (const char* ext : {".ply", ".stl", ".vts", ".xyz"}) write_mesh(c, out(ext), res);
  }
  ojson description = info(c);
  write_text(out(".info.json"), io::pretty_json(description));
  io::write_view(out(".view.html"), c, {.resolution = volume ? volume_view_res : view_res, .title = ex.name});
  return description;
}

// The example's lines in the demo's report: what it is, then what info says of it.
std::string report_lines(const io::Construction& c, const Example& ex, const ojson& description, const fs::path& dir,
                         const fs::path& spec_path) {
  const auto& err = description["max_data_error"];
  std::string line = "  " + ex.name + std::string(ex.name.size() < 15 ? 15 - ex.name.size() : 1, ' ') + c.type + ": " +
                     ex.about + "\n      ";
  const auto joined = [](const ojson& a, const char* sep) {
    std::string t;
    for (const auto& e : a) t += (t.empty() ? "" : sep) + (e.is_string() ? e.get<std::string>() : e.dump());
    return t;
  };
  if (c.exact)
    line += joined(description["control_points"], "x") + " control points, degree " +
            joined(description["degree"], "x") + ", continuity " + joined(description["continuity"], "/");
  else
    line += "no exact B-spline form (evaluated by its formula)";
  if (err.is_object())
    line += ", max error at the data " + short_number(err["absolute"].get<double>()) + " (relative " +
            short_number(err["relative"].get<double>()) + ")";
  if (const auto& par = description["parameters"]; par.contains("rms_error"))  // an approximation
    line += " at " + par["max_error_at"].get<std::string>() + ", rms " + short_number(par["rms_error"].get<double>()) +
            ", " + par["missing_points"].dump() + " missing points filled";
  const ojson spec = ex.spec.empty() ? ojson::object() : ojson::parse(ex.spec);
  if (!ex.spec_file.empty() || spec.contains("npz")) {
    // An exact form read back and built again: the same bytes as the file it came from.
    const fs::path original = ex.spec_file.empty() ? dir / spec["npz"].get<std::string>() : spec_path;
    const bool same = read_text(original) == read_text(dir / (ex.name + ".bspline" + original.extension().string()));
    line += same ? ", rebuilt identically" : ", rebuilt with differences";
  }
  if (io::is_volume(c)) {
    const auto& jac = description["jacobian"];
    line += ", " + jac["inverted_cells"].dump() + " of " + jac["cells"].dump() + " cells inverted (det J from " +
            short_number(jac["min_determinant"].get<double>()) + " to " +
            short_number(jac["max_determinant"].get<double>()) + ")";
  }
  return line;
}

}  // namespace

int demo_command(const fs::path& requested) {
  const fs::path dir = prepare(requested);
  std::size_t files = 0;
  std::string summary;
  std::vector<GalleryEntry> gallery;
  const std::vector<Example> all = examples();
  for (const Example& ex : all) {
    std::vector<std::string> written;
    const fs::path spec_path = write_spec(ex, dir, written);
    io::Construction c = build_spec(spec_path);
    const ojson description = write_outputs(c, ex, dir, written);
    report_warnings(c.warnings);
    std::string line = report_lines(c, ex, description, dir, spec_path);
    gallery.push_back({ex.name, c.type, ex.about, io::view_thumbnail_svg(c), line.substr(line.rfind("\n      ") + 7)});
    line += "\n      ";
    for (std::size_t i = 0; i < written.size(); ++i) line += (i ? " " : "") + written[i];
    summary += line + "\n";
    files += written.size();
  }
  write_gallery(dir / "index.html", gallery);
  std::printf("interpatch demo: %zu examples\n%soutputs in %s: %zu files\nopen %s in a web browser to see every example\n",
              all.size(), summary.c_str(), dir.string().c_str(), files + 1, (dir / "index.html").string().c_str());
  return 0;
}

}  // namespace interpatch::cli
