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
#include "interpatch/io/project.hpp"
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
  std::string name;
  std::string about;  // the spec's "comment", to its first full stop
  std::string spec;   // the spec's text, written as NAME.spec.json
  bool every_mesh_format = false;
};

// The mesh formats every example is written in are .obj and .vtk; this one shows the others.
constexpr std::string_view every_mesh_format_example = "hemisphere";

std::string about(const ojson& spec) {
  const auto comment = spec.find("comment");
  if (comment == spec.end() || !comment->is_string()) return "a " + spec.value("type", std::string("curve")) + " spec";
  std::string text = comment->get<std::string>();
  if (const auto stop = text.find(". "); stop != std::string::npos) text.resize(stop + 1);
  return text;
}

// The examples shown: every spec of examples/, by name, then terrain's exact form read
// back from the .npz the demo wrote of it (so after terrain).
std::vector<Example> examples() {
  std::vector<Example> all;
  for (const embedded::File& f : embedded::files) {
    if (!f.name.ends_with(".json")) continue;
    std::string name(f.name.substr(0, f.name.size() - 5));
    std::string text(f.bytes());
    all.push_back({name, about(ojson::parse(text)), std::move(text), name == every_mesh_format_example});
  }
  all.push_back({"terrain_npz", "terrain.bspline.npz (the build output for NumPy) read back as a bspline_surface spec",
                 "{\n  \"type\": \"bspline_surface\",\n  \"npz\": \"terrain.bspline.npz\"\n}\n"});
  return all;
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
  std::string page;  // what the picture opens: the viewer page, or a blocks mesh's description
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
    page += "<div class=\"card\"><a href=\"" + html_text(e.page) + "\">" + e.thumbnail_svg + "<div><b>" + html_text(e.name) +
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
// and returns its path.
fs::path write_spec(const Example& ex, const fs::path& dir, std::vector<std::string>& written) {
  const std::string& text = ex.spec;
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

// A graded volume as an OpenFOAM case, NAME_case: its mesh in constant/polyMesh and
// the dictionaries checkMesh reads (`checkMesh -case NAME_case`).
void write_openfoam_case(io::Construction& c, const fs::path& dir, const std::string& name,
                         std::vector<std::string>& written) {
  const fs::path cs = dir / (name + "_case");
  fs::create_directories(cs / "constant");
  fs::create_directories(cs / "system");
  const std::string head = "FoamFile { version 2.0; format ascii; class dictionary; object ";
  write_text(cs / "system" / "controlDict",
             head + "controlDict; }\napplication potentialFoam; startFrom startTime; startTime 0; stopAt endTime;\n"
                    "endTime 1; deltaT 1; writeControl timeStep; writeInterval 1;\n");
  write_text(cs / "system" / "fvSchemes",
             head + "fvSchemes; }\nddtSchemes { default steadyState; }\ngradSchemes { default Gauss linear; }\n"
                    "divSchemes { default none; }\nlaplacianSchemes { default Gauss linear corrected; }\n"
                    "interpolationSchemes { default linear; }\nsnGradSchemes { default corrected; }\n");
  write_text(cs / "system" / "fvSolution", head + "fvSolution; }\n");
  write_mesh(c, cs / "constant" / "polyMesh", io::default_resolution(c));
  written.push_back(name + "_case/");
}

// Every output of the command line of `c` into DIR as NAME.*; returns what info prints.
ojson write_outputs(io::Construction& c, const Example& ex, const fs::path& dir,
                    std::vector<std::string>& written) {
  constexpr Resolution eval_grid{33, 33, 0}, volume_eval_grid{17, 17, 17};
  const Resolution res = io::default_resolution(c), volume_res = res;
  // The viewer pages of the demo are lighter than the command's default (257 x 257).
  constexpr std::array<std::size_t, 3> view_res{129, 129, 0}, volume_view_res{17, 17, 17};
  const auto out = [&](const std::string& suffix) {
    written.push_back(ex.name + suffix);
    return dir / (ex.name + suffix);
  };
  if (c.blocks) {  // one mesh of every block: for OpenFOAM, VTK and Gmsh
    write_openfoam_case(c, dir, ex.name, written);
    write_mesh(c, out(".vtu"), res);
    write_mesh(c, out(".msh"), res);
    ojson description = info(c);
    write_text(out(".info.json"), io::pretty_json(description));
    return description;
  }
  const bool volume = io::is_volume(c);
  if (c.exact) {
    write_build(c, out(".bspline.json"));
    write_build(c, out(".bspline.npz"));  // the same arrays for NumPy (numpy.load)
    write_build(c, out(".step"));  // a face (a closed shell of six for a volume) for CAD systems
    write_build(c, out(".igs"));
  }
  // A graded example is evaluated at its own nodes: fewer would not hold its grading.
  const Resolution grid = c.sampling ? io::default_resolution(c) : volume ? volume_eval_grid : eval_grid;
  write_eval(c, out(".eval.npy"), grid);
  write_eval(c, out(".eval.csv"), grid);
  if (volume) {
    write_mesh(c, out(".vts"), volume_res);
    write_mesh(c, out(".vtk"), volume_res);
    write_mesh(c, out(".xyz"), volume_res);
    written.push_back(ex.name + ".f");  // the Jacobian beside the Plot3D grid
    if (c.sampling) write_openfoam_case(c, dir, ex.name, written);
  } else {
    write_mesh(c, out(".obj"), res);
    write_mesh(c, out(".vtk"), res);
    if (ex.every_mesh_format)
      for (const char* ext : {".ply", ".stl", ".vts", ".xyz"}) write_mesh(c, out(ext), res);
  }
  ojson description = info(c);
  write_text(out(".info.json"), io::pretty_json(description));
  const std::array<std::size_t, 3> page = c.sampling ? io::view_default_resolution(c) : volume ? volume_view_res : view_res;
  io::write_view(out(".view.html"), c, {.resolution = page, .title = ex.name});
  return description;
}

// The example's lines in the demo's report: what it is, then what info says of it.
std::string report_lines(const io::Construction& c, const Example& ex, const ojson& description, const fs::path& dir,
                         const fs::path& spec_path) {
  std::string line = "  " + ex.name + std::string(ex.name.size() < 15 ? 15 - ex.name.size() : 1, ' ') + c.type + ": " +
                     ex.about + "\n      ";
  const auto joined = [](const ojson& a, const char* sep) {
    std::string t;
    for (const auto& e : a) t += (t.empty() ? "" : sep) + (e.is_string() ? e.get<std::string>() : e.dump());
    return t;
  };
  if (c.blocks) {  // the blocks, what they share, and the merged mesh as a solver sees it
    std::string blocks;
    for (const auto& b : description["blocks"])
      blocks += (blocks.empty() ? "" : ", ") + b["name"].get<std::string>() + " " + joined(b["nodes"], "x");
    std::string patches;
    for (const auto& [name, faces] : description["patches"].items()) patches += (patches.empty() ? "" : ", ") + name;
    const auto& mesh = description["mesh"];
    const std::size_t shared = description["shared_faces"].size();
    return line + std::to_string(description["blocks"].size()) + " blocks (" + blocks + "), " +
           std::to_string(shared) + (shared == 1 ? " shared face, " : " shared faces, ") + mesh["points"].dump() +
           " points and " + mesh["cells"].dump() + " cells, patches " + patches + "; non-orthogonality up to " +
           short_number(mesh["non_orthogonality"]["max"].get<double>()) + " deg, skewness up to " +
           short_number(mesh["max_skewness"].get<double>()) + ", " + mesh["inverted_cells"].dump() +
           " cells inverted";
  }
  const auto& err = description["max_data_error"];
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
  if (description.contains("max_closest_distance"))  // the same data by their closest points (interpatch project)
    line += ", by closest points at most " + short_number(description["max_closest_distance"]["absolute"].get<double>());
  const ojson spec = ojson::parse(ex.spec);
  if (const std::string type = spec.value("type", ""); type == "bspline_surface" || type == "bspline_volume") {
    // An exact form read back and built again: the same bytes as the file it came from.
    const fs::path original = spec.contains("npz") ? dir / spec["npz"].get<std::string>() : spec_path;
    const bool same = read_text(original) == read_text(dir / (ex.name + ".bspline" + original.extension().string()));
    line += same ? ", rebuilt identically" : ", rebuilt with differences";
  }
  if (description.contains("sampling"))  // a graded mesh: its first cells as asked
    for (const auto& [d, s] : description["sampling"].items())
      if (s.contains("first"))
        line += ", first cells along " + d + " " + short_number(s["achieved"]["first"].get<double>()) + " (asked " +
                short_number(s["first"].get<double>()) + ")";
  if (io::is_volume(c)) {
    const auto& jac = description["jacobian"];
    line += ", " + jac["inverted_cells"].dump() + " of " + jac["cells"].dump() + " cells inverted (det J from " +
            short_number(jac["min_determinant"].get<double>()) + " to " +
            short_number(jac["max_determinant"].get<double>()) + ")";
    const auto& mesh = description["mesh"];  // the cells a solver gets, in checkMesh's measures
    line += "; mesh non-orthogonality up to " + short_number(mesh["non_orthogonality"]["max"].get<double>()) +
            " deg, skewness up to " + short_number(mesh["max_skewness"].get<double>());
  }
  return line;
}

// Where points are (interpatch project): a scan of the terrain built above,
// examples/terrain_scan.csv, measured by the closest points of the surface.
std::string scan_report(const fs::path& dir, std::size_t& files) {
  write_text(dir / "terrain_scan.csv", std::string(example_file("terrain_scan.csv")));
  io::Built terrain = build_spec(dir / "terrain.spec.json");
  const io::ProjectionSummary r = io::write_projection(terrain, dir / "terrain_scan.csv", dir / "terrain_scan.project.npz");
  files += 2;
  return "project: " + std::to_string(r.points) + " scanned points (terrain_scan.csv) onto terrain, by their closest points: " +
         "the farthest " + short_number(r.max_distance) + " away\n      terrain_scan.csv terrain_scan.project.npz\n";
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
    gallery.push_back({ex.name, c.type, ex.about, io::view_thumbnail_svg(c), line.substr(line.rfind("\n      ") + 7),
                       ex.name + (c.blocks ? ".info.json" : ".view.html")});
    line += "\n      ";
    for (std::size_t i = 0; i < written.size(); ++i) line += (i ? " " : "") + written[i];
    summary += line + "\n";
    files += written.size();
  }
  summary += scan_report(dir, files);
  write_gallery(dir / "index.html", gallery);
  std::printf("interpatch demo: %zu examples\n%soutputs in %s: %zu files\nopen %s in a web browser to see every example\n",
              all.size(), summary.c_str(), dir.string().c_str(), files + 1, (dir / "index.html").string().c_str());
  return 0;
}

}  // namespace interpatch::cli
