#include "interpatch/io/view.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numeric>
#include <span>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "base/text.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/memory.hpp"
#include "interpatch/volume.hpp"
#include "io/box.hpp"
#include "io/finite.hpp"
#include "io/viewer_assets.hpp"

namespace interpatch::io {

using interpatch::detail::cat;
using interpatch::detail::fail;
using ojson = nlohmann::ordered_json;

namespace {

// The colours of the page's colourings and of the thumbnails, low to high, one
// definition for both (the page reads them from its data): a perceptually even ramp
// for heights, a blue-white-red one for curvatures and det J (white at zero).
constexpr std::array<std::array<double, 3>, 6> height_palette{{{0.267, 0.005, 0.329},
                                                               {0.231, 0.322, 0.545},
                                                               {0.129, 0.569, 0.549},
                                                               {0.369, 0.788, 0.384},
                                                               {0.741, 0.875, 0.149},
                                                               {0.993, 0.906, 0.144}}};
constexpr std::array<std::array<double, 3>, 5> signed_palette{{{0.130, 0.400, 0.675},
                                                               {0.573, 0.773, 0.871},
                                                               {0.969, 0.969, 0.969},
                                                               {0.957, 0.647, 0.510},
                                                               {0.698, 0.094, 0.169}}};

template <std::size_t N>
ojson palette_json(const std::array<std::array<double, 3>, N>& p) {
  ojson j = ojson::array();
  for (const auto& c : p) j.push_back(c);
  return j;
}

// The colour at t in [0, 1] of a palette, between its stops.
template <std::size_t N>
std::array<double, 3> palette_at(const std::array<std::array<double, 3>, N>& p, double t) {
  const double x = std::clamp(t, 0.0, 1.0) * static_cast<double>(N - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), N - 2);
  const double f = x - static_cast<double>(i);
  return {p[i][0] + f * (p[i + 1][0] - p[i][0]), p[i][1] + f * (p[i + 1][1] - p[i][1]),
          p[i][2] + f * (p[i + 1][2] - p[i][2])};
}

// Bytes as base64 (RFC 4648, with padding).
std::string base64(std::span<const unsigned char> bytes) {
  static constexpr char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string s;
  s.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t w = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    for (int k = 18; k >= 0; k -= 6) s += digits[(w >> k) & 63];
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    std::uint32_t w = std::uint32_t{bytes[i]} << 16;
    if (rest == 2) w |= std::uint32_t{bytes[i + 1]} << 8;
    s += digits[(w >> 18) & 63];
    s += digits[(w >> 12) & 63];
    s += rest == 2 ? digits[(w >> 6) & 63] : '=';
    s += '=';
  }
  return s;
}

std::string base64(std::string_view text) {
  return base64(std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

// Little-endian float32 values as base64: what the page's script turns back into a
// Float32Array.
class Float32Base64 {
 public:
  explicit Float32Base64(std::size_t values) { bytes_.reserve(4 * values); }
  void push(double v) {
    const auto bits = std::bit_cast<std::uint32_t>(static_cast<float>(v));
    for (int k = 0; k < 32; k += 8) bytes_.push_back(static_cast<unsigned char>(bits >> k));
  }
  void push(const Vec3& p) {
    push(p.x);
    push(p.y);
    push(p.z);
  }
  // {"dtype": "float32", "length": values, "base64": text}
  [[nodiscard]] ojson json() const {
    return {{"dtype", "float32"}, {"length", bytes_.size() / 4}, {"base64", base64(bytes_)}};
  }

 private:
  std::vector<unsigned char> bytes_;
};

// Where the page's float32 coordinates are measured from, and in what unit: the
// centre of the construction's box and a power of two at least half its largest side.
// float32 holds about 7 digits, so a 1 mm part 1e8 from the origin would collapse to
// one point and coordinates past 3.4e38 would become infinite; relative to its own
// box every construction keeps float32's 7 digits of its size. A power of two scales
// without rounding.
struct PageFrame {
  Vec3 origin{0, 0, 0};
  double unit = 1;

  // p / unit - origin / unit rounds as (p - origin) / unit would, and cannot overflow
  // where p - origin would (p and the origin at opposite ends of the doubles).
  [[nodiscard]] Vec3 local(const Vec3& p) const { return p / unit - origin / unit; }
  [[nodiscard]] ojson json() const { return {{"origin", {origin.x, origin.y, origin.z}}, {"unit", unit}}; }
};

// The frame of the box of the finite points shown (none: the identity).
PageFrame page_frame(const internal::Box& box) {
  if (!(box.lo.x <= box.hi.x)) return {};
  PageFrame f;
  // Halves first: (lo + hi) / 2 overflows for coordinates near the largest double.
  f.origin = box.lo / 2 + box.hi / 2;
  const double half = std::max({box.hi.x / 2 - box.lo.x / 2, box.hi.y / 2 - box.lo.y / 2, box.hi.z / 2 - box.lo.z / 2});
  if (half > 0 && std::isfinite(half)) {
    int e = 0;
    (void)std::frexp(half, &e);  // half = m 2^e with m in [0.5, 1): 2^e >= half
    f.unit = std::ldexp(1.0, e);
  }
  return f;
}

// Evenly spaced indices into n samples, at most `keep` of them, first and last kept.
std::vector<std::size_t> decimated(std::size_t n, std::size_t keep) {
  if (n <= keep || keep < 2) {
    std::vector<std::size_t> all(n);
    std::iota(all.begin(), all.end(), std::size_t{0});
    return all;
  }
  std::vector<std::size_t> idx(keep);
  for (std::size_t k = 0; k < keep; ++k) idx[k] = static_cast<std::size_t>(std::llround(
                                            static_cast<double>(k) * static_cast<double>(n - 1) / static_cast<double>(keep - 1)));
  return idx;
}

// Per-axis kept indices of a grid of `shape`, at most `limit` points in all: each
// axis keeps the same fraction of its samples (view_resolution).
std::vector<std::vector<std::size_t>> decimated_grid(const std::vector<std::size_t>& shape, std::size_t limit) {
  std::array<std::size_t, 3> asked{0, 0, 0};
  for (std::size_t a = 0; a < shape.size() && a < 3; ++a) asked[a] = shape[a];
  const std::array<std::size_t, 3> kept = view_resolution(asked, limit);
  std::vector<std::vector<std::size_t>> idx;
  for (std::size_t a = 0; a < shape.size(); ++a)
    idx.push_back(decimated(shape[a], shape[a] < 2 ? shape[a] : kept[std::min<std::size_t>(a, 2)]));
  return idx;
}

ojson shape_json(const std::vector<std::vector<std::size_t>>& idx) {
  ojson j = ojson::array();
  for (const auto& i : idx) j.push_back(i.size());
  return j;
}

// The points of a C-order grid of `shape` at the kept indices, as float32 in the page's frame.
Float32Base64 grid_points(std::span<const Vec3> points, const std::vector<std::size_t>& shape,
                          const std::vector<std::vector<std::size_t>>& idx, const PageFrame& frame) {
  std::size_t count = 1;
  for (const auto& i : idx) count *= i.size();
  Float32Base64 out(3 * count);
  std::vector<std::size_t> at(idx.size(), 0);
  for (std::size_t n = 0; n < count; ++n) {
    std::size_t offset = 0;
    for (std::size_t a = 0; a < idx.size(); ++a) offset = offset * shape[a] + idx[a][at[a]];
    out.push(frame.local(points[offset]));
    for (std::size_t a = idx.size(); a-- > 0;) {
      if (++at[a] < idx[a].size()) break;
      at[a] = 0;
    }
  }
  return out;
}

ojson data_json(const Construction& c, const PageFrame& frame) {
  ojson sets = ojson::array();
  for (const DataSet& d : c.data) {
    std::vector<std::size_t> shape;
    if (d.scattered) shape.push_back(d.params[0].size());
    else
      for (const auto& p : d.params) shape.push_back(p.size());
    const auto long_axes = std::count_if(shape.begin(), shape.end(), [](std::size_t n) { return n > 1; });
    const auto idx = decimated_grid(shape, view_limits.data_points);
    ojson full = ojson::array();
    for (const std::size_t n : shape) full.push_back(n);
    sets.push_back({{"pointer", d.pointer},
                    {"kind", long_axes == 1 && !d.scattered ? "curve" : "points"},
                    {"shape", shape_json(idx)},
                    {"full_shape", std::move(full)},
                    {"points", grid_points(d.points, shape, idx, frame).json()}});
  }
  return sets;
}

// The control net of the exact form: its points (decimated), the full shape, which
// directions are closed (the net then joins its last row to its first).
ojson control_net_json(const Construction& c, const PageFrame& frame) {
  if (!c.exact) return nullptr;
  return std::visit(
      [&](const auto& form) -> ojson {
        const auto& cp = form.control_points();
        std::vector<std::size_t> shape(cp.shape().begin(), cp.shape().end());
        const auto idx = decimated_grid(shape, view_limits.control_points);
        ojson full = ojson::array(), closed = ojson::array();
        for (const std::size_t n : shape) full.push_back(n);
        for (const bool p : form.periodic()) closed.push_back(p);
        return {{"shape", shape_json(idx)},
                {"full_shape", std::move(full)},
                {"periodic", std::move(closed)},
                {"points", grid_points(std::span<const Vec3>(cp.data(), cp.size()), shape, idx, frame).json()}};
      },
      *c.exact);
}

// The samples in the page's frame, with their curvatures in its unit (K unit², H
// unit): a 1e-200 part's curvatures would overflow float32, its own do not.
ojson surface_json(const Surface& s, const GradedParameters& p, const PageFrame& frame) {
  const std::vector<double>&us = p.params[0], &vs = p.params[1];
  const std::array<std::size_t, 3> res{us.size(), vs.size(), 0};
  const std::size_t n = res[0] * res[1];
  Float32Base64 points(3 * n), normals(3 * n), gaussian(n), mean(n);
  // A block of u rows at a time: the derivatives of the whole grid would be six
  // times its points.
  constexpr std::size_t block = 32;
  for (std::size_t i0 = 0; i0 < us.size(); i0 += block) {
    const auto rows = std::span(us).subspan(i0, std::min(block, us.size() - i0));
    const Grid<SurfaceDerivatives, 2> d = s.evaluate_derivatives(rows, vs);
    for (std::size_t k = 0; k < d.size(); ++k) {
      const SurfaceDerivatives& t = d.data()[k];
      const std::size_t shape[3] = {res[0], res[1], 3}, first = (i0 * res[1] + k) * 3;
      internal::require_finite(&t.s.x, 3, first, shape, "the surface's points on the page");
      const SurfaceDerivatives x{frame.local(t.s), t.su / frame.unit,  t.sv / frame.unit,
                                 t.suu / frame.unit, t.suv / frame.unit, t.svv / frame.unit};
      const Curvature k2 = curvature(x);
      const Vec3 normal = unit_normal(x);
      internal::require_finite(&normal.x, 3, first, shape, "the surface's normals on the page");
      points.push(x.s);
      normals.push(normal);
      gaussian.push(k2.gaussian);
      mean.push(k2.mean);
    }
  }
  return {{"shape", {res[0], res[1]}},
          {"positions", points.json()},
          {"normals", normals.json()},
          {"gaussian", gaussian.json()},
          {"mean", mean.json()}};
}

// The samples in the page's frame, det J in its unit (det J / unit³).
ojson volume_json(const Volume& v, const GradedParameters& p, const PageFrame& frame) {
  const std::vector<double>&us = p.params[0], &vs = p.params[1], &ws = p.params[2];
  const std::array<std::size_t, 3> res{us.size(), vs.size(), ws.size()};
  const VolumeJacobians j = v.evaluate_jacobians(us, vs, ws);
  const std::size_t n = j.points.size();
  const std::size_t shape[4] = {res[0], res[1], res[2], 3};
  internal::require_finite(&j.points.data()->x, 3 * n, 0, shape, "the volume's points on the page");
  Float32Base64 points(3 * n), det(n);
  const double cube = frame.unit * frame.unit * frame.unit;
  for (std::size_t k = 0; k < n; ++k) {
    points.push(frame.local(j.points.data()[k]));
    // In two steps where unit³ would overflow or vanish.
    det.push(std::isfinite(cube) && cube > 0 ? j.determinants.data()[k] / cube
                                             : j.determinants.data()[k] / frame.unit / frame.unit / frame.unit);
  }
  return {{"shape", {res[0], res[1], res[2]}}, {"positions", points.json()}, {"det_j", det.json()}};
}

// The frame of what the page shows: the box of the construction sampled 17 × 17
// (9 × 9 × 9), its control net and its data. It need not hold every sample: it only
// has to keep them near 1 in size.
PageFrame construction_frame(const Construction& c) {
  internal::Box box;
  const auto add = [&](const Vec3& p) {
    if (is_finite(p)) box.add(p);
  };
  if (is_volume(c)) {
    const std::vector<double> t = linspace(0, 1, 9);
    const PointGrid3 samples = volume_evaluator(c).evaluate(t, t, t);
    for (const Vec3& p : samples.values()) add(p);
  } else {
    const std::vector<double> t = linspace(0, 1, 17);
    const PointGrid samples = evaluator(c).evaluate(t, t);
    for (const Vec3& p : samples.values()) add(p);
  }
  if (c.exact)
    std::visit([&](const auto& form) { for (const Vec3& p : form.control_points().values()) add(p); }, *c.exact);
  for (const DataSet& d : c.data)
    for (const Vec3& p : d.points) add(p);
  return page_frame(box);
}

// A Hermite patch's (volume's) given corner derivatives are its own there.
ojson frames_json(const Construction& c) {
  const auto vec = [](const Vec3& p) { return ojson::array({p.x, p.y, p.z}); };
  ojson frames = ojson::array();
  if (c.type == "hermite_patch") {
    const Surface& s = evaluator(c);
    const char* names[4] = {"p00", "p01", "p10", "p11"};
    for (std::size_t k = 0; k < 4; ++k) {
      const SurfaceDerivatives d = s.derivatives(static_cast<double>(k / 2), static_cast<double>(k % 2));
      frames.push_back({{"at", cat("/corners/", names[k])}, {"p", vec(d.s)}, {"du", vec(d.su)}, {"dv", vec(d.sv)}});
    }
  } else if (c.type == "hermite_volume") {
    const Volume& v = volume_evaluator(c);
    for (std::size_t k = 0; k < 8; ++k) {  // corner (i, j, k) at index 4i + 2j + k, as the spec lists them
      const VolumeDerivatives d =
          v.derivatives(static_cast<double>(k / 4), static_cast<double>((k / 2) % 2), static_cast<double>(k % 2));
      frames.push_back(
          {{"at", cat("/corners/", k)}, {"p", vec(d.s)}, {"du", vec(d.su)}, {"dv", vec(d.sv)}, {"dw", vec(d.sw)}});
    }
  }
  return frames;
}

// JSON text that can sit inside a <script> element: '<' only occurs in strings, where
// \u003c stands for it, so no "</script>" or "<!--" can end or confuse the element.
std::string script_safe(const std::string& json) {
  std::string s;
  s.reserve(json.size());
  for (const char ch : json) {
    if (ch == '<') s += "\\u003c";
    else s += ch;
  }
  return s;
}

// The page template with every {{NAME}} slot filled; a slot with no value is an
// internal error (the template and this file disagree).
std::string fill(std::string_view page, std::initializer_list<std::pair<std::string_view, std::string_view>> slots) {
  std::string out;
  std::size_t at = 0;
  for (;;) {
    const std::size_t open = page.find("{{", at);
    if (open == std::string_view::npos) break;
    const std::size_t close = page.find("}}", open);
    const std::string_view name = page.substr(open + 2, close - open - 2);
    const auto slot = std::find_if(slots.begin(), slots.end(), [&](const auto& s) { return s.first == name; });
    if (close == std::string_view::npos || slot == slots.end())
      fail(errc::internal, "viewer/src/page.html: unknown slot {{", name, "}}");
    out.append(page.substr(at, open - at));
    out.append(slot->second);
    at = close + 2;
  }
  out.append(page.substr(at));
  return out;
}

std::string html_escaped(std::string_view text) {
  std::string s;
  for (const char ch : text) {
    switch (ch) {
      case '<': s += "&lt;"; break;
      case '>': s += "&gt;"; break;
      case '&': s += "&amp;"; break;
      case '"': s += "&quot;"; break;
      default: s += ch;
    }
  }
  return s;
}

}  // namespace

std::array<std::size_t, 3> view_default_resolution(const Construction& c) noexcept {
  std::array<std::size_t, 3> r = is_volume(c) ? std::array<std::size_t, 3>{33, 33, 33} : std::array<std::size_t, 3>{257, 257, 0};
  // A graded spec is shown at its own nodes.
  if (c.sampling)
    for (std::size_t d = 0; d < (is_volume(c) ? 3u : 2u); ++d)
      if ((*c.sampling)[d].count != 0) r[d] = (*c.sampling)[d].count;
  return r;
}

std::array<std::size_t, 3> view_resolution(std::array<std::size_t, 3> asked, std::size_t limit) noexcept {
  const std::size_t dims = asked[2] ? 3 : 2;
  const auto product = [&](const std::array<std::size_t, 3>& n) {
    double p = 1;
    for (std::size_t a = 0; a < dims; ++a) p *= static_cast<double>(n[a]);
    return p;
  };
  if (product(asked) <= static_cast<double>(limit)) return asked;
  // One factor for every direction; a direction it would take below 2 keeps 2, and
  // the others share what is left (a 10^9 x 3 request is not 10^5 x 2 x ...).
  std::array<std::size_t, 3> shown = asked;
  std::array<bool, 3> at_two{false, false, false};
  double budget = static_cast<double>(limit);
  for (;;) {
    double free_product = 1;
    std::size_t free = 0;
    for (std::size_t a = 0; a < dims; ++a)
      if (!at_two[a]) {
        free_product *= static_cast<double>(asked[a]);
        ++free;
      }
    if (free == 0) break;
    const double f = std::pow(budget / free_product, 1.0 / static_cast<double>(free));
    bool clamped = false;
    for (std::size_t a = 0; a < dims; ++a)
      if (!at_two[a] && static_cast<double>(asked[a]) * f < 2) {
        at_two[a] = clamped = true;
        shown[a] = 2;
        budget /= 2;
      }
    if (clamped) continue;  // the factor again, for the directions left
    for (std::size_t a = 0; a < dims; ++a)
      if (!at_two[a]) shown[a] = std::max<std::size_t>(2, static_cast<std::size_t>(static_cast<double>(asked[a]) * f));
    break;
  }
  // Rounding in pow may leave the product a little over: the largest count gives way.
  while (product(shown) > static_cast<double>(limit)) {
    std::size_t* largest = std::max_element(shown.begin(), shown.begin() + static_cast<std::ptrdiff_t>(dims));
    if (*largest <= 2) break;
    --*largest;
  }
  return shown;
}

std::string view_html(const Construction& c, const ViewOptions& options) {
  const bool volume = is_volume(c);
  std::array<std::size_t, 3> asked = options.resolution;
  if (asked == std::array<std::size_t, 3>{0, 0, 0}) asked = view_default_resolution(c);
  if (volume != (asked[2] != 0))
    fail(errc::wrong_type, c.type, volume ? " is a volume: its view takes three counts, NUxNVxNW"
                                          : " is a surface: its view takes two counts, NUxNV");
  const std::array<std::size_t, 3> res =
      view_resolution(asked, volume ? view_limits.volume_samples : view_limits.surface_samples);

  ojson data;
  data["format"] = "interpatch-view 2";
  data["title"] = options.title.empty() ? c.type : options.title;
  data["kind"] = volume ? "volume" : "surface";
  data["resolution"] = {{"asked", asked}, {"shown", res}};
  data["palettes"] = {{"height", palette_json(height_palette)}, {"signed", palette_json(signed_palette)}};
  data["info"] = info_json(c);
  const PageFrame frame = construction_frame(c);
  data["frame"] = frame.json();
  const GradedParameters nodes = sample_parameters(c, {res[0], res[1], res[2]});
  if (volume) data["volume"] = volume_json(volume_evaluator(c), nodes, frame);
  else data["surface"] = surface_json(evaluator(c), nodes, frame);
  data["control_net"] = control_net_json(c, frame);
  data["data"] = data_json(c, frame);
  data["frames"] = frames_json(c);

  const detail::ViewerAssets& a = detail::viewer_assets();
  const ojson import_map = {
      {"imports",
       {{"three", "data:text/javascript;base64," + base64(a.three)},
        {"three/addons/controls/OrbitControls.js", "data:text/javascript;base64," + base64(a.orbit_controls)}}}};
  const std::string title = html_escaped(data["title"].get<std::string>());
  return fill(a.page, {{"TITLE", title},
                       {"STYLE", a.style},
                       {"THREE_VERSION", a.three_version},
                       {"IMPORT_MAP", import_map.dump()},
                       {"DATA", script_safe(data.dump())},
                       {"SCRIPT", a.script}});
}

bool is_view_format(std::string_view extension) noexcept {
  if (extension.starts_with('.')) extension.remove_prefix(1);
  const auto is = [&](std::string_view name) {
    return extension.size() == name.size() &&
           std::equal(name.begin(), name.end(), extension.begin(),
                      [](char a, char b) { return a == (b >= 'A' && b <= 'Z' ? static_cast<char>(b - 'A' + 'a') : b); });
  };
  return is("html") || is("htm");
}

void write_view(const std::filesystem::path& path, const Construction& c, const ViewOptions& options) {
  const std::string page = view_html(c, options);
  write_atomically(path, [&](std::ostream& os) { os.write(page.data(), static_cast<std::streamsize>(page.size())); },
                   page.size());
}

std::string view_thumbnail_svg(const Construction& c, std::size_t width, std::size_t height) {
  if (width < 16 || height < 16)
    fail(errc::too_few_points, "thumbnail of ", width, " x ", height, " pixels: at least 16 x 16");
  // The patches to draw: grids of points, each (rows x cols).
  struct Patch {
    std::size_t rows, cols;
    std::vector<Vec3> points;
  };
  std::vector<Patch> patches;
  if (is_volume(c)) {  // the faces of the volume, or of every block
    std::vector<const Volume*> volumes;
    if (c.blocks)
      for (const Construction& b : c.blocks->blocks) volumes.push_back(&volume_evaluator(b));
    else
      volumes.push_back(&volume_evaluator(c));
    const std::vector<double> t = linspace(0, 1, 12), end0{0.0}, end1{1.0};
    for (const Volume* v : volumes)
      for (int axis = 0; axis < 3; ++axis)
        for (const auto* end : {&end0, &end1}) {
          const PointGrid3 g = v->evaluate(axis == 0 ? *end : t, axis == 1 ? *end : t, axis == 2 ? *end : t);
          patches.push_back({12, 12, std::vector<Vec3>(g.data(), g.data() + g.size())});
        }
  } else {
    const std::vector<double> t = linspace(0, 1, 24);
    const PointGrid g = evaluator(c).evaluate(t, t);
    patches.push_back({24, 24, std::vector<Vec3>(g.data(), g.data() + g.size())});
  }
  // The viewer's first view: from the side of -y and +x, 35 degrees above the xy plane.
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const Patch& p : patches)
    for (const Vec3& x : p.points) {
      lo = {std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
      hi = {std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
    }
  const Vec3 centre = 0.5 * (lo + hi);
  const double yaw = -0.785398163397448, pitch = 0.610865238198015;  // -45 and 35 degrees
  const Vec3 right{std::cos(yaw), -std::sin(yaw), 0};
  const Vec3 toward{std::sin(yaw) * std::cos(pitch), std::cos(yaw) * std::cos(pitch), -std::sin(pitch)};
  const Vec3 up = cross(right, toward);
  struct Quad {
    double depth;
    std::array<std::array<double, 2>, 4> xy;
    std::array<double, 3> rgb;
  };
  std::vector<Quad> quads;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  const Vec3 light = Vec3{0.3, -0.5, 0.8} / norm(Vec3{0.3, -0.5, 0.8});
  for (const Patch& p : patches)
    for (std::size_t i = 0; i + 1 < p.rows; ++i)
      for (std::size_t j = 0; j + 1 < p.cols; ++j) {
        const Vec3 q[4] = {p.points[i * p.cols + j], p.points[(i + 1) * p.cols + j], p.points[(i + 1) * p.cols + j + 1],
                           p.points[i * p.cols + j + 1]};
        Quad quad{};
        double z = 0;
        for (int k = 0; k < 4; ++k) {
          const Vec3 r = q[k] - centre;
          quad.xy[k] = {dot(r, right), -dot(r, up)};
          quad.depth += dot(r, toward);
          z += q[k].z;
          xmin = std::min(xmin, quad.xy[k][0]);
          xmax = std::max(xmax, quad.xy[k][0]);
          ymin = std::min(ymin, quad.xy[k][1]);
          ymax = std::max(ymax, quad.xy[k][1]);
        }
        const Vec3 n = cross(q[2] - q[0], q[3] - q[1]);
        const double len = norm(n);
        const double lit = len > 0 ? 0.35 + 0.65 * std::abs(dot(n, light)) / len : 0.35;
        const auto rgb = palette_at(height_palette, hi.z > lo.z ? (z / 4 - lo.z) / (hi.z - lo.z) : 0.5);
        quad.rgb = {rgb[0] * lit, rgb[1] * lit, rgb[2] * lit};
        quads.push_back(quad);
      }
  // Farthest first.
  std::sort(quads.begin(), quads.end(), [](const Quad& a, const Quad& b) { return a.depth > b.depth; });
  const double w = static_cast<double>(width), h = static_cast<double>(height), margin = 6;
  // One scale for both directions, fitting the wider one; a flat picture (a patch seen
  // edge on) is not stretched to fill the other.
  const double extent = std::max({xmax - xmin, ymax - ymin, 1e-300});
  const double scale = std::min((w - 2 * margin) / std::max(xmax - xmin, extent * 1e-9),
                                (h - 2 * margin) / std::max(ymax - ymin, extent * 1e-9));
  const double ox = w / 2 - scale * (xmin + xmax) / 2, oy = h / 2 - scale * (ymin + ymax) / 2;
  std::string svg = cat("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"", width, "\" height=\"", height,
                        "\" viewBox=\"0 0 ", width, " ", height, "\"><rect width=\"100%\" height=\"100%\" fill=\"#20232a\"/>");
  char buf[64];
  for (const Quad& q : quads) {
    const auto channel = [](double x) { return static_cast<int>(std::lround(255 * std::clamp(x, 0.0, 1.0))); };
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", channel(q.rgb[0]), channel(q.rgb[1]), channel(q.rgb[2]));
    svg += "<polygon fill=\"";
    svg += buf;
    svg += "\" stroke=\"";
    svg += buf;
    svg += "\" stroke-width=\"0.5\" points=\"";
    for (int k = 0; k < 4; ++k) {
      std::snprintf(buf, sizeof buf, "%s%.1f,%.1f", k ? " " : "", ox + scale * q.xy[k][0], oy + scale * q.xy[k][1]);
      svg += buf;
    }
    svg += "\"/>";
  }
  svg += "</svg>";
  return svg;
}

}  // namespace interpatch::io
