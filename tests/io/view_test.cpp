// The viewer page (io/view.hpp): what it embeds is what the library evaluates, bit
// for bit in float32; decimation keeps the page bounded and the ends of every grid;
// the summary is info_json(); the page asks for nothing outside itself; writes are
// atomic; the thumbnail is a picture of the construction. The page in a browser:
// tools/check_viewer.py (CTest viewer_browser_*).

#include "interpatch/io/view.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <regex>
#include <string>
#include <vector>

#include "interpatch/evaluate.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/volume.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

io::Construction example(const std::string& name) {
  return io::build_file(fs::path(INTERPATCH_EXAMPLES) / (name + ".json"));
}

// The page's data: the JSON inside <script id="interpatch-data">.
json page_data(const std::string& page) {
  const std::string open = R"(<script type="application/json" id="interpatch-data">)";
  const std::size_t a = page.find(open);
  const std::size_t b = page.find("</script>", a);
  EXPECT_NE(a, std::string::npos);
  return json::parse(page.substr(a + open.size(), b - a - open.size()));
}

// {"dtype": "float32", "length", "base64"} decoded independently of the writer.
std::vector<float> floats(const json& array) {
  EXPECT_EQ(array.at("dtype"), "float32");
  const std::string text = array.at("base64");
  std::vector<unsigned char> bytes;
  std::uint32_t acc = 0;
  int bits = 0;
  for (const char ch : text) {
    if (ch == '=') break;
    const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    acc = (acc << 6) | static_cast<std::uint32_t>(digits.find(ch));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes.push_back(static_cast<unsigned char>(acc >> bits));
    }
  }
  EXPECT_EQ(bytes.size(), 4 * array.at("length").get<std::size_t>());
  std::vector<float> v(bytes.size() / 4);
  for (std::size_t k = 0; k < v.size(); ++k) {
    std::uint32_t w = 0;
    for (int b = 3; b >= 0; --b) w = (w << 8) | bytes[4 * k + static_cast<std::size_t>(b)];
    v[k] = std::bit_cast<float>(w);
  }
  return v;
}

// The page's frame: float32 positions are (p - origin) / unit.
struct Frame {
  Vec3 origin;
  double unit = 1;
  [[nodiscard]] Vec3 true_point(const std::vector<float>& v, std::size_t k) const {
    return origin + Vec3{v[3 * k], v[3 * k + 1], v[3 * k + 2]} * unit;
  }
};

Frame frame_of(const json& d) {
  const json& f = d.at("frame");
  const Frame frame{{f["origin"][0].get<double>(), f["origin"][1].get<double>(), f["origin"][2].get<double>()},
                    f["unit"].get<double>()};
  // A power of two: scaling by it is exact.
  int e = 0;
  EXPECT_EQ(std::frexp(frame.unit, &e), 0.5) << frame.unit;
  return frame;
}

// The page holds p in the frame, as float32: to float32's rounding of the frame
// coordinate, plus the double rounding of p itself (the page and the test may
// evaluate the same point by different routes, one unit of p's last place apart,
// which the subtraction of the origin can bring up to float32's size).
void expect_point(const std::vector<float>& v, std::size_t k, const Vec3& p, const Frame& f) {
  for (int a = 0; a < 3; ++a) {
    const double local = (p[a] - f.origin[a]) / f.unit;
    const double slack = std::numeric_limits<float>::epsilon() * std::abs(local) +
                         4 * std::numeric_limits<double>::epsilon() * (std::abs(p[a]) + std::abs(f.origin[a])) / f.unit;
    EXPECT_NEAR(v[3 * k + static_cast<std::size_t>(a)], local, slack) << "point " << k << " coordinate " << a;
  }
}

// float32 values agree to a few units in their last place: a value computed in
// the page's frame and the same in the construction's, scaled, differ by double
// rounding, which float32's rounding can turn into one unit.
void expect_float_near(float page, double expected) {
  EXPECT_NEAR(page, expected, 4 * std::numeric_limits<float>::epsilon() * std::abs(expected) + 1e-30);
}

TEST(ViewResolution, WithinTheLimitAsAskedAndBeyondItScaledEvenly) {
  auto g = test::rng(18);
  for (int trial = 0; trial < 500; ++trial) {
    const bool volume = trial % 2 == 1;
    const std::size_t top = volume ? 400 : 6000;
    std::array<std::size_t, 3> asked{};
    for (std::size_t a = 0; a < (volume ? 3u : 2u); ++a)
      asked[a] = 64 + static_cast<std::size_t>(test::uniform(g, 0, 1) * static_cast<double>(top));
    const std::size_t limit = volume ? io::view_limits.volume_samples : io::view_limits.surface_samples;
    const auto shown = io::view_resolution(asked, limit);
    const std::size_t dims = volume ? 3 : 2;
    std::size_t product = 1, product_next = 1, product_asked = 1;
    for (std::size_t a = 0; a < dims; ++a) {
      EXPECT_LE(shown[a], asked[a]);
      EXPECT_GE(shown[a], 2u);
      product *= shown[a];
      product_next *= shown[a] + 1;
      product_asked *= asked[a];
    }
    EXPECT_EQ(shown[2] == 0, !volume);
    if (product_asked <= limit) {
      EXPECT_EQ(shown, asked);
    } else {
      EXPECT_LE(product, limit);
      // As many as fit: one more in every direction would not.
      EXPECT_GT(product_next, limit);
    }
  }
  // Elongated requests, up to counts too large to represent (what --res passes on):
  // still within the limit, the short directions at 2 or more, the long ones given the rest.
  constexpr std::size_t huge = std::numeric_limits<std::size_t>::max();
  for (const std::array<std::size_t, 3>& asked : {std::array<std::size_t, 3>{huge, 3, 0}, {2, huge, 0}, {huge, huge, 0},
                                                  {3, 1000000000, 0}, {huge, 2, 2}, {2, 5, huge}, {huge, huge, huge}}) {
    const bool volume = asked[2] != 0;
    const std::size_t limit = volume ? io::view_limits.volume_samples : io::view_limits.surface_samples;
    const auto shown = io::view_resolution(asked, limit);
    const double product = static_cast<double>(shown[0]) * static_cast<double>(shown[1]) *
                           static_cast<double>(volume ? shown[2] : 1);
    EXPECT_LE(product, static_cast<double>(limit)) << asked[0] << " " << asked[1] << " " << asked[2];
    for (std::size_t a = 0; a < (volume ? 3u : 2u); ++a) {
      EXPECT_GE(shown[a], 2u);
      EXPECT_LE(shown[a], asked[a]);
    }
    // The long directions get what the short ones leave: more than half of it.
    EXPECT_GT(2 * product, static_cast<double>(limit)) << asked[0] << " " << asked[1] << " " << asked[2];
  }
}

TEST(ViewHtml, SurfaceSamplesAreTheLibrarysInFloat32) {
  const io::Construction c = example("coons_hermite");
  const std::string page = io::view_html(c, {.resolution = {9, 7, 0}, .title = "a <patch>"});
  const json d = page_data(page);
  EXPECT_EQ(d["format"], "interpatch-view 2");
  const Frame f = frame_of(d);
  EXPECT_EQ(d["kind"], "surface");
  EXPECT_EQ(d["title"], "a <patch>");
  EXPECT_NE(page.find("<title>a &lt;patch&gt; · interpatch</title>"), std::string::npos);
  EXPECT_EQ(d["surface"]["shape"], json({9, 7}));
  const std::vector<float> p = floats(d["surface"]["positions"]), n = floats(d["surface"]["normals"]),
                           k = floats(d["surface"]["gaussian"]), h = floats(d["surface"]["mean"]);
  ASSERT_EQ(p.size(), 9u * 7u * 3u);
  const Surface& s = io::evaluator(c);
  const std::vector<double> us = linspace(0, 1, 9), vs = linspace(0, 1, 7);
  for (std::size_t i = 0; i < 9; ++i)
    for (std::size_t j = 0; j < 7; ++j) {
      const SurfaceDerivatives x = s.derivatives(us[i], vs[j]);
      const std::size_t at = i * 7 + j;
      expect_point(p, at, x.s, f);
      for (int a = 0; a < 3; ++a) expect_float_near(n[3 * at + static_cast<std::size_t>(a)], unit_normal(x)[a]);
      // Curvatures in the frame's unit: K unit², H unit.
      expect_float_near(k[at], curvature(x).gaussian * f.unit * f.unit);
      expect_float_near(h[at], curvature(x).mean * f.unit);
    }
  // The control net, whole, in C order.
  const auto& cp = std::get<BSplineSurface>(*c.exact).control_points();
  const std::vector<float> net = floats(d["control_net"]["points"]);
  EXPECT_EQ(d["control_net"]["shape"], d["control_net"]["full_shape"]);
  ASSERT_EQ(net.size(), 3 * cp.size());
  for (std::size_t q = 0; q < cp.size(); ++q) expect_point(net, q, cp.data()[q], f);
}

TEST(ViewHtml, TheSummaryIsInfoAndEveryDataSetIsShown) {
  for (const char* name : {"coons", "network_gordon", "hermite_patch", "terrain", "pipe", "trilinear"}) {
    SCOPED_TRACE(name);
    const io::Construction c = example(name);
    const json d = page_data(io::view_html(c));
    json info = json::parse(io::info_json(c).dump()), shown = d["info"];
    info.erase("timings");
    shown.erase("timings");
    EXPECT_EQ(shown, info);
    ASSERT_EQ(d["data"].size(), c.data.size());
    for (std::size_t k = 0; k < c.data.size(); ++k) {
      const io::DataSet& set = c.data[k];
      EXPECT_EQ(d["data"][k]["pointer"], set.pointer);
      const std::vector<float> p = floats(d["data"][k]["points"]);
      // The examples' data sets are within the limit: every point, in order.
      ASSERT_EQ(p.size(), 3 * set.points.size());
      for (std::size_t q = 0; q < set.points.size(); ++q) expect_point(p, q, set.points[q], frame_of(d));
      const long long long_axes =
          std::count_if(set.params.begin(), set.params.end(), [](const auto& t) { return t.size() > 1; });
      EXPECT_EQ(d["data"][k]["kind"], long_axes == 1 ? "curve" : "points");
    }
    EXPECT_EQ(d["frames"].size(), std::string(name) == "hermite_patch" ? 4u : 0u);
  }
  EXPECT_EQ(page_data(io::view_html(example("hermite_volume")))["frames"].size(), 8u);
}

TEST(ViewHtml, HermiteFramesAreTheGivenCornerDerivatives) {
  for (const char* name : {"hermite_patch", "hermite_volume"}) {
    const json spec = json::parse(test::read_text(fs::path(INTERPATCH_EXAMPLES) / (std::string(name) + ".json")));
    const json d = page_data(io::view_html(example(name)));
    ASSERT_FALSE(d["frames"].empty()) << name;
    for (const json& f : d["frames"]) {
      const std::string at = f["at"];
      const json& given = spec.at(json::json_pointer(at));
      for (const char* key : {"p", "du", "dv", "dw"}) {
        if (!given.contains(key)) continue;
        for (std::size_t a = 0; a < 3; ++a)
          // Hermite constructions reproduce their corner data to rounding (a few units
          // of 1e-16 of these O(1) values).
          EXPECT_NEAR(f[key][a].get<double>(), given[key][a].get<double>(), 1e-12) << at << " " << key;
      }
    }
  }
}

TEST(ViewHtml, VolumeSamplesAndDeterminants) {
  const io::Construction c = example("coons_volume");
  const json d = page_data(io::view_html(c, {.resolution = {3, 4, 5}, .title = {}}));
  EXPECT_EQ(d["kind"], "volume");
  EXPECT_EQ(d["volume"]["shape"], json({3, 4, 5}));
  const VolumeJacobians j =
      io::volume_evaluator(c).evaluate_jacobians(linspace(0, 1, 3), linspace(0, 1, 4), linspace(0, 1, 5));
  const std::vector<float> p = floats(d["volume"]["positions"]), det = floats(d["volume"]["det_j"]);
  const Frame f = frame_of(d);
  ASSERT_EQ(det.size(), 60u);
  for (std::size_t k = 0; k < 60; ++k) {
    expect_point(p, k, j.points.data()[k], f);
    expect_float_near(det[k], j.determinants.data()[k] / (f.unit * f.unit * f.unit));
  }
  EXPECT_EQ(d["info"]["jacobian"]["inverted_cells"], io::info_json(c)["jacobian"]["inverted_cells"]);
}

TEST(ViewHtml, LargeGridsAreDecimatedKeepingTheirEnds) {
  auto g = test::rng(7);
  const PointGrid q = test::random_grid(g, 300, 280, 0.2);
  json rows = json::array();
  for (std::size_t i = 0; i < 300; ++i) {
    json row = json::array();
    for (std::size_t j = 0; j < 280; ++j) row.push_back({q(i, j).x, q(i, j).y, q(i, j).z});
    rows.push_back(row);
  }
  const io::Construction c = io::build(json{{"type", "interpolate"}, {"degree", {1, 1}}, {"points", rows}});
  const json d = page_data(io::view_html(c, {.resolution = {3000, 2000, 0}, .title = {}}));
  EXPECT_EQ(d["resolution"]["asked"], json({3000, 2000, 0}));
  const auto shown = d["resolution"]["shown"].get<std::vector<std::size_t>>();
  EXPECT_LE(shown[0] * shown[1], io::view_limits.surface_samples);
  EXPECT_EQ(floats(d["surface"]["positions"]).size(), 3 * shown[0] * shown[1]);
  const json& data = d["data"][0];
  EXPECT_EQ(data["full_shape"], json({300, 280}));
  const auto kept = data["shape"].get<std::vector<std::size_t>>();
  EXPECT_LE(kept[0] * kept[1], io::view_limits.data_points);
  EXPECT_LT(kept[0], 300u);
  const std::vector<float> p = floats(data["points"]);
  ASSERT_EQ(p.size(), 3 * kept[0] * kept[1]);
  const Frame f = frame_of(d);
  expect_point(p, 0, q(0, 0), f);
  expect_point(p, kept[1] - 1, q(0, 279), f);
  expect_point(p, kept[0] * kept[1] - 1, q(299, 279), f);
  // The degree 1 net is the data: decimated the same way, within its own limit.
  const auto net = d["control_net"]["shape"].get<std::vector<std::size_t>>();
  EXPECT_EQ(d["control_net"]["full_shape"], json({300, 280}));
  EXPECT_LE(net[0] * net[1], io::view_limits.control_points);
}

// float32 holds 7 digits: a page in absolute coordinates collapsed a 1 mm part 1e8
// from the origin to one point, and made coordinates of 1e40 infinite. In the page's
// frame every part keeps float32's precision of its own size, at any offset and scale.
TEST(ViewHtml, PartsFarFromTheOriginAndAtExtremeScalesKeepTheirShape) {
  auto g = test::rng(41);
  for (int trial = 0; trial < 40; ++trial) {
    const double size = std::pow(10.0, test::uniform(g, -200, 40));
    const double offset = trial % 2 ? size * std::pow(10.0, test::uniform(g, 0, 12)) : 0.0;
    const Vec3 o{offset, -offset / 3, offset / 7};
    std::array<Vec3, 4> corner;
    for (Vec3& c : corner) c = o + Vec3{test::uniform(g, -1, 1), test::uniform(g, -1, 1), test::uniform(g, -1, 1)} * size;
    const auto point = [](const Vec3& p) { return json::array({p.x, p.y, p.z}); };
    const io::Construction c = io::build(json{{"type", "bilinear"},
                                              {"p00", point(corner[0])},
                                              {"p01", point(corner[1])},
                                              {"p10", point(corner[2])},
                                              {"p11", point(corner[3])}});
    SCOPED_TRACE(testing::Message() << "size " << size << " offset " << offset);
    const json d = page_data(io::view_html(c, {.resolution = {9, 9, 0}, .title = {}}));
    const Frame f = frame_of(d);
    const std::vector<float> p = floats(d["surface"]["positions"]), k = floats(d["surface"]["gaussian"]),
                             h = floats(d["surface"]["mean"]);
    const std::vector<double> t = linspace(0, 1, 9);
    const Surface& s = io::evaluator(c);
    double diagonal = 0;
    for (const Vec3& a : corner)
      for (const Vec3& b : corner) diagonal = std::max(diagonal, norm(a - b));
    for (std::size_t i = 0; i < 9; ++i)
      for (std::size_t j = 0; j < 9; ++j) {
        const std::size_t at = i * 9 + j;
        // What the page draws, back in the construction's coordinates: within
        // float32's precision (6e-8) of the part's size, 1e-6 leaving room for the
        // frame's unit being up to twice half the size; plus the rounding of doubles
        // at the offset, which bounds any result at that offset (4 units of its last place).
        EXPECT_LE(norm(f.true_point(p, at) - s.point(t[i], t[j])),
                  1e-6 * diagonal + 4 * std::numeric_limits<double>::epsilon() * norm(o)) << at;
        ASSERT_TRUE(std::isfinite(k[at]) && std::isfinite(h[at])) << at;
      }
    // The part is drawn at its size: the page's corners are as far apart as its own.
    EXPECT_NEAR(norm(f.true_point(p, 0) - f.true_point(p, 80)), norm(corner[0] - corner[3]),
                1e-6 * diagonal + 8 * std::numeric_limits<double>::epsilon() * norm(o));
  }
}

TEST(ViewHtml, AsksForNothingOutsideThePage) {
  const std::string page = io::view_html(example("bilinear"));
  // Four script elements (the import map, the data, the viewer's module), each closed once.
  const auto count = [&](const std::string& s) {
    std::size_t n = 0;
    for (std::size_t at = page.find(s); at != std::string::npos; at = page.find(s, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<script"), 3u);
  EXPECT_EQ(count("</script>"), 3u);
  EXPECT_EQ(count(" src="), 0u);
  EXPECT_EQ(count("<link"), 0u);
  // The modules the viewer imports come from the import map, as data: URLs.
  const std::string open = R"(<script type="importmap">)";
  const std::size_t a = page.find(open), b = page.find("</script>", a);
  ASSERT_NE(a, std::string::npos);
  const json map = json::parse(page.substr(a + open.size(), b - a - open.size()));
  ASSERT_EQ(map["imports"].size(), 2u);
  for (const auto& [name, url] : map["imports"].items())
    EXPECT_EQ(url.get<std::string>().rfind("data:text/javascript;base64,", 0), 0u) << name;
}

// The page without the summary's timings, which differ from run to run.
json without_timings(const std::string& page) {
  json d = page_data(page);
  d["info"].erase("timings");
  return d;
}

TEST(WriteView, AtomicAndRefusingAMissingDirectory) {
  test::TempDir dir;
  const io::Construction c = example("bilinear");
  io::write_view(dir / "page.html", c);
  const std::string written = test::read_text(dir / "page.html");
  EXPECT_TRUE(without_timings(written) == without_timings(io::view_html(c)));
  EXPECT_ERRC(io::write_view(dir / "missing" / "page.html", c), file_unwritable, "missing");
  // A failure before writing leaves an existing page as it was.
  EXPECT_ERRC(io::write_view(dir / "page.html", c, {.resolution = {4, 4, 4}, .title = {}}), wrong_type,
              "bilinear is a surface: its view takes two counts");
  EXPECT_TRUE(test::read_text(dir / "page.html") == written);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"page.html"});
}

TEST(ViewThumbnail, AShadedPictureOfEveryQuad) {
  const std::regex polygon(R"(<polygon fill="#[0-9a-f]{6}")");
  const auto polygons = [&](const std::string& svg) {
    return std::distance(std::sregex_iterator(svg.begin(), svg.end(), polygon), std::sregex_iterator());
  };
  const std::string surface = io::view_thumbnail_svg(example("hemisphere"), 200, 150);
  EXPECT_EQ(surface.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"200\" height=\"150\"", 0), 0u);
  EXPECT_EQ(polygons(surface), 23 * 23);
  EXPECT_EQ(polygons(io::view_thumbnail_svg(example("trilinear"))), 6 * 11 * 11);
  // Every vertex inside the picture.
  const std::regex vertex(R"(([0-9.-]+),([0-9.-]+))");
  for (auto it = std::sregex_iterator(surface.begin(), surface.end(), vertex); it != std::sregex_iterator(); ++it) {
    EXPECT_GE(std::stod((*it)[1]), 0.0);
    EXPECT_LE(std::stod((*it)[1]), 200.0);
    EXPECT_GE(std::stod((*it)[2]), 0.0);
    EXPECT_LE(std::stod((*it)[2]), 150.0);
  }
  EXPECT_ERRC((void)io::view_thumbnail_svg(example("bilinear"), 8, 100), too_few_points, "8 x 100 pixels");
}

}  // namespace
}  // namespace interpatch
