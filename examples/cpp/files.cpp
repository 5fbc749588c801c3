// Files: atomic output (io/atomic_file.hpp), points as CSV (io/csv.hpp) and NumPy
// .npy (io/npy.hpp), meshes (io/mesh.hpp), and the exact form as STEP (io/step.hpp)
// and IGES (io/iges.hpp) and NumPy .npz (io/npz.hpp), the viewer page (io/view.hpp), each example run and what it writes read back. The
// examples name files relative to the working directory, so the program works in a
// scratch directory of its own, removed at the end. Links interpatch::interpatch.

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

#include <interpatch/interpatch.hpp>

#include "check.hpp"

namespace fs = std::filesystem;

namespace {

// A fresh directory (mkdtemp: one that did not exist before) made the working
// directory; on destruction the old working directory is restored and the scratch
// one removed with everything in it, whether the example succeeded or not.
class ScratchDir {
 public:
  ScratchDir() : old_(fs::current_path()) {
    std::string templ = (fs::temp_directory_path() / "interpatch-example-XXXXXX").string();
    if (::mkdtemp(templ.data()) == nullptr)
      throw fs::filesystem_error("mkdtemp", templ, std::error_code(errno, std::generic_category()));
    path_ = templ;
    fs::current_path(path_);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() {
    std::error_code ec;
    fs::current_path(old_, ec);
    fs::remove_all(path_, ec);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path old_, path_;
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

// 40 × 50 points of a wavy surface, C order: the data the CSV and NPY examples read.
std::vector<interpatch::Vec3> wave() {
  std::vector<interpatch::Vec3> pts;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 50; ++j) pts.push_back({0.1 * i, 0.1 * j, 0.3 * std::sin(0.2 * i) * std::cos(0.15 * j)});
  return pts;
}

void atomic_files() {
  interpatch::io::write_atomically("out.txt", [](std::ostream& os) { os << "hello\n"; });
  example::expect(read_text("out.txt") == "hello\n", "out.txt holds what the writer wrote");
  // A writer that fails leaves nothing behind and the old file as it was.
  try {
    interpatch::io::write_atomically("out.txt", [](std::ostream& os) {
      os << "half";
      throw std::runtime_error("the writer gives up");
    });
    example::expect(false, "the writer's exception propagates");
  } catch (const std::runtime_error&) {
  }
  example::expect(read_text("out.txt") == "hello\n", "a failed write leaves the old file");
  example::expect(std::distance(fs::directory_iterator("."), fs::directory_iterator()) == 1,
                  "a failed write leaves no temporary file");
  std::printf("write_atomically: out.txt written, a failed rewrite left it as it was\n");
}

void csv_points() {
  const auto data = wave();
  interpatch::io::write_atomically("grid.csv", [&](std::ostream& os) {
    os << "x,y,z\n";
    for (const auto& p : data) os << example::str(p.x) << ',' << example::str(p.y) << ',' << example::str(p.z) << '\n';
  });
  auto pts = interpatch::io::read_csv_points("grid.csv", 40 * 50);  // C order of shape (40, 50)
  example::expect(pts == data, "read_csv_points reads back the 40 × 50 points exactly");
  std::printf("grid.csv: %zu points read back\n", pts.size());
}

void csv_text() {
  auto pts = interpatch::io::parse_csv_points("x,y,z\n0,0,0\n1,0,0.5\n", 2, "inline.csv");
  example::expect(pts.size() == 2 && pts[1] == interpatch::Vec3{1, 0, 0.5}, "the header line is skipped");
  try {
    (void)interpatch::io::parse_csv_points("0,0,0\n1,0\n", 0, "inline.csv");
    example::expect(false, "a short row is refused");
  } catch (const interpatch::error& e) {
    example::expect(e.code() == interpatch::errc::malformed_file, "a short row is malformed_file");
    std::printf("refused: %s\n", e.what());
  }
}

void npy_arrays() {
  const auto data = wave();
  std::vector<double> xyz;
  for (const auto& p : data) xyz.insert(xyz.end(), {p.x, p.y, p.z});
  const std::size_t grid_shape[3] = {40, 50, 3};
  interpatch::io::write_npy("grid.npy", grid_shape, xyz);

  interpatch::io::NpyArray a = interpatch::io::read_npy("grid.npy");  // e.g. shape {40, 50, 3}
  example::expect(a.shape == std::vector<std::size_t>{40, 50, 3}, "grid.npy has shape {40, 50, 3}");
  example::expect(a.data == xyz, "read_npy reads back the values exactly");

  std::vector<double> v;
  auto shape = interpatch::io::read_npy_into("grid.npy", [&](auto, std::size_t n) {
    v.resize(n);
    return v.data();
  });
  example::expect(shape == a.shape && v == a.data, "read_npy_into reads into the caller's memory");
  std::printf("grid.npy: shape {%zu, %zu, %zu}\n", a.shape[0], a.shape[1], a.shape[2]);
}

void npy_bytes() {
  // Bytes from a network, a database, ...; here those of the file written above.
  const auto load_from_somewhere = [] { return read_text("grid.npy"); };
  std::string bytes = load_from_somewhere();
  interpatch::io::NpyArray a = interpatch::io::parse_npy(bytes, "upload.npy");
  const interpatch::io::NpyArray from_file = interpatch::io::read_npy("grid.npy");
  example::expect(a.shape == from_file.shape && a.data == from_file.data, "parse_npy reads the bytes as read_npy the file");
  // A message names the file by the name given.
  try {
    (void)interpatch::io::parse_npy(bytes.substr(0, bytes.size() - 8), "upload.npy");
    example::expect(false, "parse_npy refuses a truncated array");
  } catch (const interpatch::error& e) {
    example::expect(e.code() == interpatch::errc::malformed_file, "a truncated array is malformed_file");
    example::expect(std::string_view(e.what()).find("upload.npy") != std::string_view::npos, "the message names upload.npy");
    std::printf("refused: %s\n", e.what());
  }
}

void npy_blocks() {
  const std::size_t shape[2] = {1000, 1000};
  std::vector<double> row;
  interpatch::io::write_npy("ramp.npy", shape, 1000, [&](std::size_t first, std::size_t count) {
    row.resize(count);
    for (std::size_t i = 0; i < count; ++i) row[i] = double(first + i);
    return std::span<const double>(row);
  });
  const interpatch::io::NpyArray ramp = interpatch::io::read_npy("ramp.npy");
  example::expect(ramp.shape == std::vector<std::size_t>{1000, 1000}, "ramp.npy has shape {1000, 1000}");
  for (std::size_t i = 0; i < ramp.data.size(); i += 9973)
    example::expect(ramp.data[i] == double(i), "ramp.npy holds 0, 1, 2, ... in C order");
  example::expect(ramp.data.back() == 999999.0, "ramp.npy's last value");
  std::printf("ramp.npy written a row at a time: %zu values\n", ramp.data.size());
}

void npy_rows() {
  const std::size_t shape[2] = {1000, 1000};
  interpatch::io::write_npy_rows("ramp.npy", shape, [](std::size_t first, std::size_t count, std::span<double> out) {
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t j = 0; j < 1000; ++j) out[i * 1000 + j] = double(first + i) + 0.001 * double(j);
  });
  const interpatch::io::NpyArray ramp = interpatch::io::read_npy("ramp.npy");
  example::expect(ramp.shape == std::vector<std::size_t>{1000, 1000}, "ramp.npy has shape {1000, 1000}");
  for (std::size_t i = 0; i < 1000; i += 37)
    for (std::size_t j = 0; j < 1000; j += 101)
      example::expect(ramp.data[i * 1000 + j] == double(i) + 0.001 * double(j), "ramp.npy holds row i, column j");
  std::printf("ramp.npy made by rows on every thread: %zu values\n", ramp.data.size());
}

void meshes() {
  const interpatch::BlendedSurface patch =
      interpatch::bilinear({0, 0, 0}, {0, 1, 0.5}, {1, 0, 0.5}, {1, 1, 0});  // a saddle
  const interpatch::Surface& surface = patch;
  const auto t = interpatch::linspace(0, 1, 64);
  interpatch::io::SurfaceMesh m{surface.evaluate(t, t), {}};  // 64 × 64 vertices, no normals
  interpatch::io::write_surface_mesh("patch.obj", m);
  std::size_t vertices = 0, faces = 0;
  for (const auto& l : lines_of(read_text("patch.obj"))) {
    if (l.starts_with("v ")) ++vertices;
    if (l.starts_with("f ")) ++faces;
  }
  example::expect(vertices == 64 * 64, "patch.obj has 64 × 64 vertices");
  example::expect(faces == 63 * 63, "patch.obj has a quad per grid cell");
  std::printf("patch.obj: %zu vertices, %zu quads\n", vertices, faces);

  // A large mesh straight from the surface: a .vts is written a block at a time.
  const auto t1000 = interpatch::linspace(0, 1, 1000);
  interpatch::io::write_surface_mesh("patch.vts", surface, t1000, t1000);  // 10^6 points and normals
  interpatch::io::write_surface_mesh("whole.vts", interpatch::io::sample_mesh(surface, t1000, t1000));
  example::expect(read_text("patch.vts") == read_text("whole.vts"), "patch.vts has the bytes of the mesh sampled whole");
  std::printf("patch.vts: %zu bytes, written a block of columns at a time\n", read_text("patch.vts").size());
}

void step_files(const fs::path& examples) {
  fs::copy_file(examples / "hemisphere.json", "hemisphere.json");
  interpatch::io::Construction c = interpatch::io::build_file("hemisphere.json");
  std::ostringstream text;
  interpatch::io::write_step(text, *c.exact, {.name = "dome", .time_stamp = "2024-05-01T12:00:00"});
  const std::string s = text.str();
  example::expect(s.starts_with("ISO-10303-21;\n"), "a STEP file starts with ISO-10303-21;");
  example::expect(s.ends_with("END-ISO-10303-21;\n"), "and ends with END-ISO-10303-21;");
  example::expect(s.find("PRODUCT('dome'") != std::string::npos, "the product is named dome");
  example::expect(s.find("'2024-05-01T12:00:00'") != std::string::npos, "FILE_NAME has the time stamp given");
  example::expect(s.find("B_SPLINE_SURFACE_WITH_KNOTS") != std::string::npos, "the face is the B-spline surface");
  std::printf("hemisphere as STEP: %zu lines\n", lines_of(s).size());
}

void iges_files(const fs::path& examples) {
  fs::copy_file(examples / "terrain.json", "terrain.json");
  interpatch::io::Construction c = interpatch::io::build_file("terrain.json");
  interpatch::io::write_iges("terrain.igs", *c.exact);
  const auto lines = lines_of(read_text("terrain.igs"));
  for (const auto& l : lines) example::expect(l.size() == 80, "every IGES line has 80 columns");
  example::expect(lines.front()[72] == 'S' && lines.back()[72] == 'T', "sections from S (start) to T (terminate)");
  // Each entity has two directory lines (D), the first with an odd sequence number;
  // both start with the entity type.
  std::size_t entities = 0;
  for (const auto& l : lines)
    if (l[72] == 'D' && std::stoi(l.substr(73)) % 2 == 1 && l.starts_with("     128")) ++entities;
  example::expect(entities == 1, "one entity 128 for the surface");
  std::printf("terrain as IGES: %zu lines of 80 columns\n", lines.size());
}

// A curve to STEP (a B-spline curve in a wireframe representation) and to IGES
// (entity 126).
void curve_files() {
  interpatch::io::write_step("edge.step", interpatch::line({0, 0, 0}, {10, 0, 0}), {.name = "edge", .time_stamp = {}});
  example::expect(read_text("edge.step").find("B_SPLINE_CURVE_WITH_KNOTS") != std::string::npos,
                  "the edge is a B-spline curve in STEP");
  interpatch::io::write_iges("edge.igs", interpatch::line({0, 0, 0}, {10, 0, 0}));
  std::size_t entities = 0;
  for (const auto& l : lines_of(read_text("edge.igs")))
    if (l[72] == 'D' && std::stoi(l.substr(73)) % 2 == 1 && l.starts_with("     126")) ++entities;
  example::expect(entities == 1, "one entity 126 for the curve in IGES");
  std::printf("a line as STEP and IGES\n");
}

// The viewer page (io/view.hpp): one HTML file holding everything it shows.
void view_pages(const fs::path& examples) {
  fs::copy_file(examples / "coons.json", "coons.json");
  interpatch::io::Construction c = interpatch::io::build_file("coons.json");
  interpatch::io::write_view("coons.html", c);  // open it in a browser
  const std::string page = read_text("coons.html");
  example::expect(page.starts_with("<!DOCTYPE html>"), "coons.html is an HTML page");
  example::expect(page.find(R"(id="interpatch-data")") != std::string::npos, "with the construction's data inside");
  example::expect(page.find(" src=") == std::string::npos, "and no script loaded from elsewhere");
  const std::string svg = interpatch::io::view_thumbnail_svg(c);
  example::expect(svg.starts_with("<svg") && svg.find("<polygon") != std::string::npos, "the thumbnail is an SVG picture");
  std::printf("coons.html: a viewer page of %zu bytes\n", page.size());
}

// The checks every front door makes of an output (io/outputs.hpp): counts of at
// least 2, named as the caller's option writes them, and a mesh written after them.
// Runs after view_pages, which put coons.json here.
void output_checks() {
  try {
    constexpr interpatch::io::CountsOption res{"--res", "mesh", "vertices", "NUxNV", "NUxNVxNW", "64x64", "33x33x33"};
    const std::size_t n[] = {0, 5};
    interpatch::io::check_counts(n, res);  // "--res '0x5': a mesh needs at least 2 vertices along each direction"
    example::expect(false, "check_counts refuses 0 vertices");
  } catch (const interpatch::error& e) {
    example::expect(e.code() == interpatch::errc::too_few_points, "0 vertices: too_few_points");
    example::expect(std::string_view(e.what()).starts_with("--res '0x5': a mesh needs"), "the message names --res '0x5'");
    std::printf("refused: %s\n", e.what());
  }
  interpatch::io::Construction c = interpatch::io::build_file("coons.json");
  constexpr interpatch::io::CountsOption res{"res", "mesh", "vertices", "(nu, nv)", "(nu, nv, nw)", "(64, 64)",
                                             "(33, 33, 33)", false, " (", ", ", ")"};
  // Warnings are the writer's word to the user (an STL far from the origin for its size).
  for (const std::string& w : interpatch::io::write_mesh(c, "patch.vts", {200, 100, 0}, res))
    std::printf("warning: %s\n", w.c_str());
  example::expect(fs::file_size("patch.vts") > 200 * 100 * 48, "patch.vts holds 200 x 100 points and normals");
  std::printf("patch.vts: a mesh of 200 x 100 vertices\n");
}

// The exact form as a NumPy archive (io/npz.hpp): written, read back from the file
// and from bytes in memory, the same surface each time. Runs after iges_files, which
// put terrain.json here.
void npz_files() {
  {
    interpatch::io::Construction c = interpatch::io::build_file("terrain.json");
    interpatch::io::write_exact_npz("terrain.npz", *c.exact);
    // python3 -c "import numpy; print(numpy.load('terrain.npz')['control_points'].shape)"
  }
  const interpatch::io::Construction c = interpatch::io::build_file("terrain.json");
  const auto& built = std::get<interpatch::BSplineSurface>(*c.exact);
  {
    interpatch::io::ExactForm f = interpatch::io::read_exact_npz("terrain.npz");
    const auto& s = std::get<interpatch::BSplineSurface>(f);
    example::expect(s.knots_u().values() == built.knots_u().values() &&
                        s.control_points().values().size() == built.control_points().values().size(),
                    "read_exact_npz gives back the knots and the control net");
    example::expect(s.point(0.3, 0.7) == built.point(0.3, 0.7), "read_exact_npz gives back the same surface, bit for bit");
  }
  {
    const auto load_from_somewhere = [] { return read_text("terrain.npz"); };
    std::string bytes = load_from_somewhere();
    interpatch::io::ExactForm f = interpatch::io::parse_exact_npz(bytes, "upload.npz");
    example::expect(std::get<interpatch::BSplineSurface>(f).point(0.5, 0.5) == built.point(0.5, 0.5),
                    "parse_exact_npz reads the same archive from memory");
  }
  std::printf("terrain as .npz: %ju bytes\n", static_cast<std::uintmax_t>(fs::file_size("terrain.npz")));
}

}  // namespace

int main() {
  return example::run("files", [] {
    const ScratchDir dir;
    std::printf("working in %s\n", dir.path().c_str());
    atomic_files();
    csv_points();
    csv_text();
    npy_arrays();
    npy_bytes();
    npy_blocks();
    npy_rows();
    meshes();
    step_files(INTERPATCH_EXAMPLES_DIR);
    iges_files(INTERPATCH_EXAMPLES_DIR);
    curve_files();
    npz_files();
    view_pages(INTERPATCH_EXAMPLES_DIR);
    output_checks();
  });
}
