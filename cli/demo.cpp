// `interpatch demo`: every construction on built-in examples. Each example's spec
// (and the data files it refers to) is written into the output directory first and
// read back from there, so the demo goes through exactly the path a user's spec
// takes; then every output the command line offers is written beside it.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "commands.hpp"
#include "interpatch/error.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/view.hpp"

namespace interpatch::cli {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;

namespace {

constexpr double pi = std::numbers::pi;

// A fixed pseudo-random value in [-0.5, 0.5) per grid node: "measurement noise"
// that is the same on every run and every machine.
double noise(std::size_t i, std::size_t j) {
  std::uint64_t h = (i + 1) * 0x9e3779b97f4a7c15ULL ^ (j + 7) * 0xc2b2ae3d27d4eb4fULL;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  return static_cast<double>(h % 100000) / 100000.0 - 0.5;
}

double round_to(double v, double step) { return std::round(v / step) * step; }

// A hemisphere of radius r: u from the pole (a row of n+1 equal points) to the
// equator, v once around (the first and last columns coincide).
PointGrid hemisphere(std::size_t nu, std::size_t nv, double r) {
  PointGrid g({nu, nv});
  for (std::size_t i = 0; i < nu; ++i)
    for (std::size_t j = 0; j < nv; ++j) {
      const double theta = 0.5 * pi * static_cast<double>(i) / static_cast<double>(nu - 1);
      const double phi = 2 * pi * static_cast<double>(j) / static_cast<double>(nv - 1);
      g(i, j) = i == 0 ? Vec3{0, 0, r} : Vec3{r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi), r * std::cos(theta)};
    }
  return g;
}

// Heights surveyed on a 40 m × 30 m grid, to the centimetre: a ridge, a knoll, noise.
PointGrid terrain() {
  PointGrid g({7, 13});
  for (std::size_t i = 0; i < 7; ++i)
    for (std::size_t j = 0; j < 13; ++j) {
      const double x = static_cast<double>(i), y = static_cast<double>(j);
      const double z = 312 + 24 * std::sin(0.9 * x + 0.4) * std::cos(0.42 * y) +
                       9 * std::exp(-((x - 4) * (x - 4) + (y - 8) * (y - 8) / 4) / 3) + 1.5 * noise(i, j);
      g(i, j) = {40 * x, 30 * y, round_to(z, 0.01)};
    }
  return g;
}

// Heights surveyed every 10 m on a 60 x 45 grid, with up to 0.25 m of measurement
// noise, a 12 x 9 void (a pond the survey could not reach) and one row lost: the
// missing heights are NaN.
PointGrid noisy_terrain() {
  const double missing = std::numeric_limits<double>::quiet_NaN();
  PointGrid g({60, 45});
  for (std::size_t i = 0; i < 60; ++i)
    for (std::size_t j = 0; j < 45; ++j) {
      const double x = static_cast<double>(i) / 8, y = static_cast<double>(j) / 3.5;
      const double z = 312 + 24 * std::sin(0.9 * x + 0.4) * std::cos(0.42 * y) +
                       9 * std::exp(-((x - 4) * (x - 4) + (y - 8) * (y - 8) / 4) / 3) + 0.5 * noise(i, j);
      const bool lost = (i >= 30 && i < 42 && j >= 20 && j < 29) || i == 12;
      g(i, j) = {10.0 * static_cast<double>(i), 10.0 * static_cast<double>(j), lost ? missing : round_to(z, 0.01)};
    }
  return g;
}

PointGrid wave() {
  PointGrid g({6, 9});
  for (std::size_t i = 0; i < 6; ++i)
    for (std::size_t j = 0; j < 9; ++j) {
      const double x = 0.8 * static_cast<double>(i), y = 0.6 * static_cast<double>(j);
      g(i, j) = {x, y, 0.5 * std::sin(1.1 * x) * std::cos(0.9 * y)};
    }
  return g;
}

PointGrid saddle() {
  PointGrid g({8, 8});
  for (std::size_t i = 0; i < 8; ++i)
    for (std::size_t j = 0; j < 8; ++j) {
      const double x = -1 + 2 * static_cast<double>(i) / 7, y = -1 + 2 * static_cast<double>(j) / 7;
      g(i, j) = {x, y, x * x - y * y + 0.3 * x * y * y * y};
    }
  return g;
}

// Half a cylinder of radius 2: u around (11 points), v along the axis (5 points).
PointGrid half_cylinder() {
  PointGrid g({11, 5});
  for (std::size_t i = 0; i < 11; ++i)
    for (std::size_t j = 0; j < 5; ++j) {
      const double a = pi * static_cast<double>(i) / 10;
      g(i, j) = {2 * std::cos(a), 2 * std::sin(a), 0.5 * static_cast<double>(j)};
    }
  return g;
}

// A strip 1 wide and 3 long with a quarter twist: u across (5), v along (9).
PointGrid twisted_strip() {
  PointGrid g({5, 9});
  for (std::size_t i = 0; i < 5; ++i)
    for (std::size_t j = 0; j < 9; ++j) {
      const double s = -0.5 + static_cast<double>(i) / 4, t = static_cast<double>(j) / 8, a = 0.5 * pi * t;
      g(i, j) = {3 * t, s * std::cos(a), s * std::sin(a)};
    }
  return g;
}

// A pipe bent through a quarter turn of radius 3 about the y axis, its circular
// cross-section swelling from radius 0.5 at the ends to 0.8 in the middle: u along
// the pipe (nu sections), v around it (nv points, the last repeating the first, as
// a scanner that closes each section writes it).
PointGrid bent_pipe(std::size_t nu, std::size_t nv) {
  PointGrid g({nu, nv});
  for (std::size_t i = 0; i < nu; ++i) {
    const double s = static_cast<double>(i) / static_cast<double>(nu - 1), a = 0.5 * pi * s;
    const double r = 0.5 + 0.3 * std::sin(pi * s);
    const Vec3 centre{3 * std::sin(a), 0, 3 * (1 - std::cos(a))}, normal{-std::sin(a), 0, std::cos(a)}, binormal{0, 1, 0};
    for (std::size_t j = 0; j + 1 < nv; ++j) {
      const double phi = 2 * pi * static_cast<double>(j) / static_cast<double>(nv - 1);
      g(i, j) = centre + r * std::cos(phi) * normal + r * std::sin(phi) * binormal;
    }
    g(i, nv - 1) = g(i, 0);
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

bool is_object_list(const ojson& v) { return v.is_array() && !v.empty() && v[0].is_object(); }

// A spec as people write them: one member per line, one grid row or object (a curve,
// a corner) per line.
std::string spec_text(const ojson& spec) {
  std::string s = "{\n";
  bool first = true;
  for (auto it = spec.begin(); it != spec.end(); ++it) {
    s += first ? "  " : ",\n  ";
    first = false;
    s += ojson(it.key()).dump() + ": ";
    if (is_point_grid(it.value()) || is_object_list(it.value())) {
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

std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

void write_points_npy(const fs::path& path, const PointGrid& g) {
  std::vector<double> flat;
  flat.reserve(3 * g.size());
  for (const Vec3& p : g.values()) flat.insert(flat.end(), {p.x, p.y, p.z});
  const std::size_t shape[3] = {g.extent(0), g.extent(1), 3};
  io::write_npy(path, shape, flat);
}

void write_points_csv(const fs::path& path, const PointGrid& g) {
  std::string text = "x,y,z\n";
  for (const Vec3& p : g.values()) text += number_text(p.x) + "," + number_text(p.y) + "," + number_text(p.z) + "\n";
  write_text(path, text);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

ojson point_json(const Vec3& p) { return {p.x, p.y, p.z}; }

// A curve spec interpolating `f` at `n` uniformly spaced parameters: with uniform
// parameters an interpolating spline of degree 3 reproduces any cubic f exactly.
ojson sampled_curve(const std::function<Vec3(double)>& f, std::size_t n, int degree = 3) {
  ojson pts = ojson::array();
  for (std::size_t k = 0; k < n; ++k) pts.push_back(point_json(f(static_cast<double>(k) / static_cast<double>(n - 1))));
  return {{"interpolate", pts}, {"degree", degree}, {"param", "uniform"}};
}

// A bicubic polynomial surface with a twist, and its partial derivatives: data
// whose boundary curves, cross derivatives and corners all agree.
Vec3 dome(double u, double v) { return {u, v, 0.3 * u * v + 0.8 * u * (1 - u) * v * (1 - v) + 0.2 * u * u * v}; }
Vec3 dome_u(double u, double v) { return {1, 0, 0.3 * v + 0.8 * (1 - 2 * u) * v * (1 - v) + 0.4 * u * v}; }
Vec3 dome_v(double u, double v) { return {0, 1, 0.3 * u + 0.8 * u * (1 - u) * (1 - 2 * v) + 0.2 * u * u}; }
Vec3 dome_uv(double u, double v) { return {0, 0, 0.3 + 0.8 * (1 - 2 * u) * (1 - 2 * v) + 0.4 * u}; }

// A smooth hill over [0, 4] x [0, 3]: the surface the network's curves are cut from.
Vec3 hill(double u, double v) {
  const double x = 4 * u, y = 3 * v;
  return {x, y, std::sin(0.8 * x) * std::cos(0.7 * y) + 0.1 * x * y};
}

ojson coons_boundary(const std::function<Vec3(double, double)>& f) {
  return {{"v0", sampled_curve([&](double t) { return f(t, 0); }, 7)},
          {"v1", sampled_curve([&](double t) { return f(t, 1); }, 7)},
          {"u0", sampled_curve([&](double t) { return f(0, t); }, 7)},
          {"u1", sampled_curve([&](double t) { return f(1, t); }, 7)}};
}

ojson dome_cross(double bend) {
  // S_v along v = 0 and 1, S_u along u = 0 and 1; `bend` adds a term to S_u(0, v)
  // that vanishes at both ends but changes its slope at v = 0 (a twist that the
  // other cross-derivative curve does not share).
  return {{"v0", sampled_curve([](double t) { return dome_v(t, 0); }, 5)},
          {"v1", sampled_curve([](double t) { return dome_v(t, 1); }, 5)},
          {"u0", sampled_curve([bend](double t) { return dome_u(0, t) + Vec3{0, 0, bend * t * (1 - t) * (1 - t)}; }, 5)},
          {"u1", sampled_curve([](double t) { return dome_u(1, t); }, 5)}};
}

ojson network_spec(const char* method) {
  ojson u_curves = ojson::array(), v_curves = ojson::array();
  const double vs[4] = {0, 1.0 / 3, 2.0 / 3, 1}, us[5] = {0, 0.25, 0.5, 0.75, 1};
  // 13 samples along u include every u_i, 10 along v every v_j: the curves cross at the nodes.
  for (double v : vs) u_curves.push_back(sampled_curve([v](double t) { return hill(t, v); }, 13));
  for (double u : us) v_curves.push_back(sampled_curve([u](double t) { return hill(u, t); }, 10));
  return {{"type", "network"},
          {"comment", "Curves cut from a hill at u = 0, 1/4, 1/2, 3/4, 1 and v = 0, 1/3, 2/3, 1; crossings found from the curves."},
          {"method", method},
          {"u_curves", u_curves},
          {"v_curves", v_curves}};
}

// A duct closed around u: four elliptic sections (closed curves through 8 points
// each, uniform parameters, so the points at 0, 90, 180 and 270 degrees sit at
// u = 0, 1/4, 1/2, 3/4) and four curves along it through those points.
ojson closed_network_spec() {
  auto section_point = [](double angle, double z) {
    const double r = 1 + 0.35 * std::sin(std::numbers::pi * z / 3);
    return Vec3{1.3 * r * std::cos(angle), r * std::sin(angle), z + 0.15 * std::sin(2 * angle) * z};
  };
  ojson u_curves = ojson::array(), v_curves = ojson::array();
  for (int k = 0; k < 4; ++k) {
    ojson pts = ojson::array();
    for (int j = 0; j < 8; ++j) pts.push_back(point_json(section_point(j * std::numbers::pi / 4, k)));
    u_curves.push_back({{"interpolate", pts}, {"periodic", true}, {"param", "uniform"}});
  }
  for (int i = 0; i < 4; ++i) {
    ojson pts = ojson::array();
    for (int k = 0; k < 4; ++k) pts.push_back(point_json(section_point(i * std::numbers::pi / 2, k)));
    v_curves.push_back({{"interpolate", pts}, {"param", "uniform"}});
  }
  return {{"type", "network"},
          {"comment", "A duct: four closed elliptic sections along it (u around, closed) and four curves along it; "
                      "the Gordon surface is closed in u and C2 across the seam."},
          {"method", "gordon"},
          {"periodic", {true, false}},
          {"u_curves", u_curves},
          {"v_curves", v_curves},
          {"u_params", {0, 0.25, 0.5, 0.75}},
          {"v_params", {0, 1.0 / 3, 2.0 / 3, 1}}};
}

// A network drawn freehand on a sheet over about [0, 4] x [0, 3]: 5 u_curves and 4
// v_curves, as a designer sketches sections. The crossing (i, j) of v-curve i and
// u-curve j lies off the sheet's iso-lines, and each curve runs through its crossings
// and a few points between them, unevenly spaced, slightly bowed and rounded to 3
// decimals; a crossing is a point of both curves, so the two meet exactly. Chord
// parameters on the u_curves and centripetal ones on the v_curves put the crossings at
// different parameters on every curve; the curves are listed out of order, and some
// run the other way.
Vec3 sheet(double a, double b) {
  const double x = 4 * a, y = 3 * b;
  return {x + 0.25 * std::sin(2.1 * b), y + 0.15 * std::sin(1.7 * a),
          0.9 * std::sin(0.8 * x) * std::cos(0.6 * y) + 0.08 * x * y};
}

ojson drawn_network_spec() {
  constexpr int nu = 5, nv = 4;  // u_curves, v_curves
  const auto cross = [](int i, int j) {  // (a, b) of the crossing of v-curve i and u-curve j
    const bool inner_i = i > 0 && i < nv - 1, inner_j = j > 0 && j < nu - 1;
    const double a = i / double(nv - 1) + (inner_i ? 0.04 * std::sin(1.3 * j + 0.7 * i) : 0.02 * std::sin(2.0 * j + i));
    const double b = j / double(nu - 1) + (inner_j ? 0.03 * std::cos(0.9 * i + 1.1 * j) : 0.015 * std::cos(1.5 * i + j));
    return std::array<double, 2>{a, b};
  };
  const std::vector<std::vector<double>> between{{0.45}, {0.3, 0.72}, {0.2, 0.5, 0.85}, {0.6}, {0.35, 0.8}, {0.15, 0.55}};
  const auto point = [](double a, double b) {
    const Vec3 p = sheet(a, b);
    return ojson{std::round(p.x * 1000) / 1000, std::round(p.y * 1000) / 1000, std::round(p.z * 1000) / 1000};
  };
  // From crossing p to crossing q: the points at fractions s of the way, bowed sideways.
  const auto stroke = [&](ojson& pts, std::array<double, 2> p, std::array<double, 2> q, const std::vector<double>& s,
                          std::size_t count, double bow) {
    const double da = q[0] - p[0], db = q[1] - p[1], len = std::hypot(da, db);
    for (std::size_t k = 0; k < count; ++k) {
      const double side = bow * std::sin(pi * s[k]) / len;
      pts.push_back(point(p[0] + s[k] * da - side * db, p[1] + s[k] * db + side * da));
    }
  };
  std::vector<ojson> u(nu), v(nv);
  for (int j = 0; j < nu; ++j) {
    u[j] = ojson::array();
    for (int i = 0; i < nv; ++i) {
      const auto c = cross(i, j);
      u[j].push_back(point(c[0], c[1]));
      const auto& s = between[(i + 2 * j) % 6];
      if (i + 1 < nv) stroke(u[j], c, cross(i + 1, j), s, s.size(), 0.012 * std::sin(j + 2 * i + 1));
    }
  }
  for (int i = 0; i < nv; ++i) {
    v[i] = ojson::array();
    for (int j = 0; j < nu; ++j) {
      const auto c = cross(i, j);
      v[i].push_back(point(c[0], c[1]));
      const auto& s = between[(3 * i + j + 1) % 6];
      const std::size_t count = std::min<std::size_t>(s.size(), j % 2 ? 2 : 1);
      if (j + 1 < nu) stroke(v[i], c, cross(i, j + 1), s, count, 0.01 * std::cos(i + j));
    }
  }
  const auto reversed = [](const ojson& pts) {
    ojson r = ojson::array();
    for (auto it = pts.rbegin(); it != pts.rend(); ++it) r.push_back(*it);
    return r;
  };
  ojson u_curves = ojson::array(), v_curves = ojson::array();
  for (int j : {2, 0, 4, 1, 3})
    u_curves.push_back({{"interpolate", j == 0 || j == 3 ? reversed(u[j]) : u[j]}, {"param", "chord"}});
  for (int i : {1, 3, 0, 2})
    v_curves.push_back({{"interpolate", i == 2 ? reversed(v[i]) : v[i]}, {"param", "centripetal"}});
  return {{"type", "network"},
          {"comment", "Curves drawn freehand on a sheet, 5 u_curves and 4 v_curves: listed out of order, some drawn the "
                      "other way, through unevenly spaced points (chord parameters on the u_curves, centripetal on the "
                      "v_curves), so that they cross at different parameters on every curve. interpatch sorts and turns "
                      "them, and re-expresses each with its crossings at common parameters."},
          {"u_curves", u_curves},
          {"v_curves", v_curves}};
}

ojson hermite_corners() {
  ojson c = ojson::object();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      c["p" + std::to_string(i) + std::to_string(j)] = {{"p", point_json(dome(i, j))},
                                                        {"du", point_json(dome_u(i, j))},
                                                        {"dv", point_json(dome_v(i, j))},
                                                        {"duv", point_json(dome_uv(i, j))}};
  return c;
}

// --- volumes ---------------------------------------------------------------------

ojson corner_name_points(const std::array<Vec3, 8>& c) {
  ojson j = ojson::object();
  for (std::size_t n = 0; n < 8; ++n)
    j["p" + std::to_string(n >> 2) + std::to_string((n >> 1) & 1) + std::to_string(n & 1)] = point_json(c[n]);
  return j;
}

// A hexahedral block, leaning and tapered: eight corners, (i, j, k) at index 4i + 2j + k.
ojson trilinear_spec() {
  const std::array<Vec3, 8> c{Vec3{0, 0, 0}, Vec3{0.2, 0, 1}, Vec3{0, 1, 0}, Vec3{0.3, 0.9, 1.1},
                              Vec3{2, 0, 0}, Vec3{1.8, 0.1, 0.8}, Vec3{2, 1.2, 0}, Vec3{1.9, 1.1, 0.9}};
  ojson spec = {{"type", "trilinear"},
                {"comment", "A leaning, tapered block from its 8 corners p_ijk (corner (i,j,k) of the parameter cube)."}};
  spec.update(corner_name_points(c));
  return spec;
}

// A box [0,2] x [0,1] x [0,1] whose wall y = 1 bulges out and whose lid z = 1 bulges
// up, from its six faces given as three kinds of surface spec. Every face meets its
// neighbours exactly along the shared edges (the bulges vanish there).
ojson coons_volume_spec() {
  auto bilinear_face = [](const Vec3& p00, const Vec3& p01, const Vec3& p10, const Vec3& p11) {
    return ojson{{"type", "bilinear"}, {"p00", point_json(p00)}, {"p01", point_json(p01)}, {"p10", point_json(p10)},
                 {"p11", point_json(p11)}};
  };
  // Wall v = 1, by (u, w): a biquadratic Bezier patch with its middle control point pushed out.
  ojson wall = ojson::array();
  for (int a = 0; a < 3; ++a) {
    ojson row = ojson::array();
    for (int b = 0; b < 3; ++b) row.push_back({a, a == 1 && b == 1 ? 1.5 : 1.0, 0.5 * b});
    wall.push_back(row);
  }
  // Lid w = 1, by (u, v): interpolated through a 7 x 7 grid of z = 1 + 4.8 u(1-u) v(1-v);
  // uniform parameters keep its straight edges parametrized like the neighbours'.
  ojson lid = ojson::array();
  for (int i = 0; i < 7; ++i) {
    ojson row = ojson::array();
    for (int j = 0; j < 7; ++j) {
      const double u = i / 6.0, v = j / 6.0;
      row.push_back({2 * u, v, 1 + 4.8 * u * (1 - u) * v * (1 - v)});
    }
    lid.push_back(row);
  }
  return {{"type", "coons_volume"},
          {"comment", "A box with a bulging wall (v1, a bspline_surface) and a domed lid (w1, interpolated); the other "
                      "faces are bilinear. Face u0 is S(0,v,w) by (v,w), v0 is S(u,0,w) by (u,w), w0 is S(u,v,0) by (u,v)."},
          {"blending", "linear"},
          {"faces",
           {{"u0", bilinear_face({0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 1, 1})},
            {"u1", bilinear_face({2, 0, 0}, {2, 0, 1}, {2, 1, 0}, {2, 1, 1})},
            {"v0", bilinear_face({0, 0, 0}, {0, 0, 1}, {2, 0, 0}, {2, 0, 1})},
            {"v1",
             {{"type", "bspline_surface"},
              {"degree", {2, 2}},
              {"knots", {{"u", {0, 0, 0, 1, 1, 1}}, {"v", {0, 0, 0, 1, 1, 1}}}},
              {"control_points", wall}}},
            {"w0", bilinear_face({0, 0, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0})},
            {"w1", {{"type", "interpolate"}, {"degree", 3}, {"param", "uniform"}, {"points", lid}}}}}};
}

// The point frame of the tricubic polynomial volume
// (u + 0.2 v w, v + 0.1 u^2, w + 0.3 u v w): the Hermite volume reproduces it.
ojson hermite_volume_spec() {
  ojson corners = ojson::array();
  for (int n = 0; n < 8; ++n) {
    const double u = n >> 2, v = (n >> 1) & 1, w = n & 1;
    corners.push_back({{"p", {u + 0.2 * v * w, v + 0.1 * u * u, w + 0.3 * u * v * w}},
                       {"du", {1, 0.2 * u, 0.3 * v * w}},
                       {"dv", {0.2 * w, 1, 0.3 * u * w}},
                       {"dw", {0.2 * v, 0, 1 + 0.3 * u * v}},
                       {"duv", {0, 0, 0.3 * w}},
                       {"duw", {0, 0, 0.3 * v}},
                       {"dvw", {0.2, 0, 0.3 * u}},
                       {"duvw", {0, 0, 0.3}}});
  }
  return {{"type", "hermite_volume"},
          {"comment", "Positions and derivatives at the 8 corners (index 4i+2j+k) of (u + 0.2vw, v + 0.1u^2, w + 0.3uvw)."},
          {"corners", corners}};
}

// A thick quarter annulus: radius 1..2 (u, 5 points), angle 0..90 degrees (v, 7), height 0..0.5 (w, 3).
ojson annular_sector_spec() {
  ojson g = ojson::array();
  for (int i = 0; i < 5; ++i) {
    ojson slab = ojson::array();
    for (int j = 0; j < 7; ++j) {
      ojson row = ojson::array();
      for (int k = 0; k < 3; ++k) {
        const double r = 1 + i / 4.0, a = 0.5 * pi * j / 6.0, z = 0.25 * k;
        row.push_back({r * std::cos(a), r * std::sin(a), z});
      }
      slab.push_back(row);
    }
    g.push_back(slab);
  }
  return {{"type", "interpolate_volume"},
          {"comment", "A thick quarter annulus through a 5x7x3 grid: radius (u), angle (v), height (w); degree 2 along w."},
          {"degree", {3, 3, 2}},
          {"param", "chord"},
          {"points", g}};
}

struct Example {
  std::string name;
  std::string about;
  ojson spec;                                    // written as NAME.spec.json
  std::function<void(const fs::path&)> data;     // data files the spec refers to
  std::string spec_file;                         // or: an existing file in DIR is the spec
  bool every_mesh_format = false;
};

std::vector<Example> examples() {
  std::vector<Example> ex;
  ex.push_back({"hemisphere", "bicubic, centripetal, through a 9x17 grid with a pole row",
                {{"type", "interpolate"},
                 {"comment", "A unit hemisphere: u from the pole (a row of equal points) to the equator, v around."},
                 {"degree", 3},
                 {"param", "centripetal"},
                 {"points", grid_json(hemisphere(9, 17, 1.0))}},
                nullptr, "", true});
  ex.push_back({"terrain", "bicubic, chord length, through 7x13 surveyed heights",
                {{"type", "interpolate"},
                 {"comment", "Heights surveyed every 40 m (u) by 30 m (v), to the centimetre."},
                 {"param", "chord"},
                 {"points", grid_json(terrain())}},
                nullptr, "", false});
  ex.push_back({"approximate_terrain", "a noisy 60x45 survey with a void and a lost row, to a tolerance of 0.35 m",
                {{"type", "approximate"},
                 {"comment", "Heights every 10 m with up to 0.25 m of noise; NaN where the survey has none (a 12 x 9 void, "
                             "row 12): the fewest control points keeping every height within 0.35 m, the gaps filled."},
                 {"tolerance", 0.35},
                 {"points", {{"npy", "approximate_terrain.npy"}}}},
                [](const fs::path& dir) { write_points_npy(dir / "approximate_terrain.npy", noisy_terrain()); }, "", false});
  ex.push_back({"wave", "degrees (2, 3), uniform parameters, 6x9 grid",
                {{"type", "interpolate"},
                 {"comment", "A wave: quadratic along u, cubic along v, uniformly spaced parameters."},
                 {"degree", {2, 3}},
                 {"param", "uniform"},
                 {"points", grid_json(wave())}},
                nullptr, "", false});
  ex.push_back({"saddle", "degrees (5, 5) through an 8x8 grid",
                {{"type", "interpolate"},
                 {"comment", "A saddle through an 8x8 grid, degree 5 in both directions (C4)."},
                 {"degree", {5, 5}},
                 {"points", grid_json(saddle())}},
                nullptr, "", false});
  ex.push_back({"bilinear", "Rogers & Adams Example 6-9: Q(0.5, 0.5) = (0.5, 0.5, 0.5)",
                {{"type", "bilinear"},
                 {"comment", "The hyperbolic paraboloid of Rogers & Adams, Mathematical Elements for Computer Graphics, Example 6-9."},
                 {"p00", {0, 0, 1}},
                 {"p01", {1, 1, 1}},
                 {"p10", {1, 0, 0}},
                 {"p11", {0, 1, 0}}},
                nullptr, "", false});
  ex.push_back({"ruled", "between a line and a Hermite arc",
                {{"type", "ruled"},
                 {"comment", "r(u,v) = (1-v) c0(u) + v c1(u): a straight edge and a Catmull-Rom arc above it."},
                 {"curves",
                  {{{"line", {{0, 0, 0}, {3, 0, 0}}}},
                   {{"hermite", {{"points", {{0, 1, 1}, {1, 1.4, 1.5}, {2, 1.4, 1.5}, {3, 1, 1}}}}}}}}},
                nullptr, "", false});
  ex.push_back({"coons", "linear Coons patch from four boundary curves",
                {{"type", "coons"},
                 {"comment", "The boundary of a bicubic dome; the linear Coons patch fills it in."},
                 {"blending", "linear"},
                 {"boundary", coons_boundary(dome)}},
                nullptr, "", false});
  ex.push_back({"coons_hermite", "Coons patch with cubic Hermite blending (zero cross slopes of the blends)",
                {{"type", "coons"}, {"blending", "hermite"}, {"boundary", coons_boundary(dome)}}, nullptr, "", false});
  ex.push_back({"coons_cross", "bicubically blended Coons patch with cross-boundary derivatives",
                {{"type", "coons"},
                 {"comment", "Boundary and cross-boundary derivatives of a bicubic dome: the patch is the dome itself."},
                 {"boundary", coons_boundary(dome)},
                 {"cross_derivatives", dome_cross(0.0)}},
                nullptr, "", false});
  ex.push_back({"coons_gregory", "incompatible twist at p00 blended by Gregory's correction (no exact form)",
                {{"type", "coons"},
                 {"comment", "S_u(0, v) bent near v = 0: the twists at p00 disagree by 1; Gregory's rational blend meets both."},
                 {"boundary", coons_boundary(dome)},
                 {"cross_derivatives", dome_cross(1.0)},
                 {"twist_correction", "gregory"}},
                nullptr, "", false});
  ex.push_back({"network_gordon", "Gordon surface through a 4 x 5 network of curves", network_spec("gordon"), nullptr, "",
                false});
  ex.push_back({"network_coons", "C1 network of Coons patches with Hermite blending", network_spec("coons_hermite"),
                nullptr, "", false});
  ex.push_back({"network_closed", "closed Gordon surface through 4 closed sections and 4 curves along them",
                closed_network_spec(), nullptr, "", false});
  ex.push_back({"network_drawn", "Gordon surface through 5 x 4 curves drawn freehand, in no order, some reversed",
                drawn_network_spec(), nullptr, "", false});
  ex.push_back({"hermite_patch", "bicubic Hermite (Ferguson) patch from corner data",
                {{"type", "hermite_patch"},
                 {"comment", "Positions, tangents and twists at the corners of a bicubic dome."},
                 {"corners", hermite_corners()}},
                nullptr, "", false});
  ex.push_back({"pipe", "closed around v (\"periodic\": [false, true]), C2 across the seam, through 20x33 points",
                {{"type", "interpolate"},
                 {"comment", "A bent pipe whose cross-section swells in the middle: u along the pipe (20 sections), v around "
                             "it (33 points, the last repeating the first and left out)."},
                 {"periodic", {false, true}},
                 {"points", grid_json(bent_pipe(20, 33))}},
                nullptr, "", false});
  ex.push_back({"half_cylinder", "11x5 grid read from half_cylinder.npy",
                {{"type", "interpolate"},
                 {"comment", "Half a cylinder, 11 points around (u) by 5 along the axis (v), from the .npy beside this file."},
                 {"degree", {3, 3}},
                 {"points", {{"npy", "half_cylinder.npy"}}}},
                [](const fs::path& dir) { write_points_npy(dir / "half_cylinder.npy", half_cylinder()); }, "", false});
  ex.push_back({"twisted_strip", "5x9 grid read from twisted_strip.csv",
                {{"type", "interpolate"},
                 {"comment", "A strip with a quarter twist, 5 points across (u) by 9 along (v), one x,y,z line per point "
                             "in C order in the .csv beside this file."},
                 {"param", "centripetal"},
                 {"points", {{"csv", "twisted_strip.csv"}, {"shape", {5, 9, 3}}}}},
                [](const fs::path& dir) { write_points_csv(dir / "twisted_strip.csv", twisted_strip()); }, "", false});
  ex.push_back({"trilinear", "a leaning, tapered block from 8 corners", trilinear_spec(), nullptr, "", false});
  ex.push_back({"coons_volume", "transfinite volume from 6 faces (bilinear, bspline_surface, interpolate)",
                coons_volume_spec(), nullptr, "", false});
  ex.push_back({"hermite_volume", "tricubic Hermite volume from a point frame", hermite_volume_spec(), nullptr, "", false});
  ex.push_back({"annular_sector", "tricubic/quadratic volume through a 5x7x3 grid", annular_sector_spec(), nullptr, "",
                false});
  ex.push_back({"terrain_exact", "terrain.bspline.json (the build output) read back as a bspline_surface spec", nullptr,
                nullptr, "terrain.bspline.json", false});
  ex.push_back({"terrain_npz", "terrain.bspline.npz (the build output for NumPy) read back as a bspline_surface spec",
                {{"type", "bspline_surface"}, {"npz", "terrain.bspline.npz"}}, nullptr, "", false});
  return ex;
}

// The output directory is created (one level) when missing; its parent must exist.
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

}  // namespace

int demo_command(const fs::path& requested) {
  const fs::path dir = prepare(requested);
  constexpr Resolution eval_grid{33, 33, 0}, volume_eval_grid{17, 17, 17};
  const Resolution res = default_surface_resolution, volume_res = default_volume_resolution;

  // The viewer pages of the demo are lighter than the command's default (257 x 257).
  constexpr std::array<std::size_t, 3> view_res{129, 129, 0}, volume_view_res{17, 17, 17};

  std::size_t files = 0;
  std::string summary;
  std::vector<GalleryEntry> gallery;
  for (const Example& ex : examples()) {
    std::vector<std::string> written;
    fs::path spec_path;
    if (ex.spec_file.empty()) {
      if (ex.data) {
        ex.data(dir);
        const auto& pts = ex.spec.at("points");
        written.push_back(pts.contains("npy") ? pts["npy"].get<std::string>() : pts["csv"].get<std::string>());
      }
      spec_path = dir / (ex.name + ".spec.json");
      write_text(spec_path, spec_text(ex.spec));
      written.push_back(spec_path.filename().string());
    } else {
      spec_path = dir / ex.spec_file;
    }

    io::Construction c = build_spec(spec_path);
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
    const ojson description = info(c);
    write_text(out(".info.json"), io::pretty_json(description));
    io::write_view(out(".view.html"), c, {.resolution = volume ? volume_view_res : view_res, .title = ex.name});
    report_warnings(c.warnings);

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
    if (!ex.spec_file.empty() || ex.spec.contains("npz")) {
      // An exact form read back and built again: the same bytes as the file it came from.
      const fs::path original = ex.spec_file.empty() ? dir / ex.spec["npz"].get<std::string>() : spec_path;
      const bool same = read_text(original) == read_text(dir / (ex.name + ".bspline" + original.extension().string()));
      line += same ? ", rebuilt identically" : ", rebuilt with differences";
    }
    if (volume) {
      const auto& jac = description["jacobian"];
      line += ", " + jac["inverted_cells"].dump() + " of " + jac["cells"].dump() + " cells inverted (det J from " +
              short_number(jac["min_determinant"].get<double>()) + " to " +
              short_number(jac["max_determinant"].get<double>()) + ")";
    }
    gallery.push_back({ex.name, c.type, ex.about, io::view_thumbnail_svg(c), line.substr(line.rfind("\n      ") + 7)});
    line += "\n      ";
    for (std::size_t i = 0; i < written.size(); ++i) line += (i ? " " : "") + written[i];
    summary += line + "\n";
    files += written.size();
  }
  write_gallery(dir / "index.html", gallery);
  std::printf("interpatch demo: %zu examples\n%soutputs in %s: %zu files\nopen %s in a web browser to see every example\n",
              examples().size(), summary.c_str(), dir.string().c_str(), files + 1, (dir / "index.html").string().c_str());
  return 0;
}

}  // namespace interpatch::cli
