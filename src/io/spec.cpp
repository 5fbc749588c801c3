#include "interpatch/io/spec.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <optional>

#include "detail/parallel.hpp"
#include "detail/text.hpp"
#include "interpatch/error.hpp"
#include "interpatch/hermite.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/network.hpp"
#include "interpatch/patches.hpp"
#include "interpatch/volume_patches.hpp"
#include "interpatch/io/csv.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/memory.hpp"

namespace interpatch::io {

using json = nlohmann::json;
using detail::cat;
using detail::fail;

namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// ---------------------------------------------------------------------------
// Places: JSON Pointers (RFC 6901) into the spec.

std::string child(std::string_view ptr, std::string_view key) {
  std::string s(ptr);
  s += '/';
  for (const char c : key) {
    if (c == '~') s += "~0";
    else if (c == '/') s += "~1";
    else s += c;
  }
  return s;
}

std::string child(std::string_view ptr, std::size_t index) {
  std::string s(ptr);
  s += '/';
  s += std::to_string(index);
  return s;
}

std::string index_pointer(std::string_view ptr, const std::vector<std::size_t>& idx, std::size_t n) {
  std::string s(ptr);
  for (std::size_t k = 0; k < n; ++k) {
    s += '/';
    s += std::to_string(idx[k]);
  }
  return s;
}

// The empty pointer is the whole document; say so in words.
std::string place(std::string_view ptr) { return ptr.empty() ? std::string("(top level)") : std::string(ptr); }

const char* kind(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "a number";
    case json::value_t::string: return "a string";
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    default: return "a binary value";
  }
}

[[noreturn]] void wrong_type(std::string_view ptr, std::string_view expected, const json& got) {
  fail(errc::wrong_type, place(ptr), ": expected ", expected, ", got ", kind(got));
}

// Runs a library call; an error it throws keeps its code and gets the place in front.
template <class F>
decltype(auto) at(std::string_view ptr, F&& f) {
  try {
    return f();
  } catch (const error& e) {
    throw error(e.code(), cat(place(ptr), ": ", e.what()));
  }
}

constexpr const char* axis_name(std::size_t a) { return a == 0 ? "u" : (a == 1 ? "v" : "w"); }
constexpr const char* coord_name(int k) { return k == 0 ? "x" : (k == 1 ? "y" : "z"); }

std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + (shape.size() == 1 ? ",)" : ")");
}

// The product of extents, refusing (too_large) a product that overflows.
std::size_t checked_product(const std::vector<std::size_t>& shape, std::string_view what) {
  std::size_t n = 1;
  for (const std::size_t e : shape) {
    if (e != 0 && n > std::numeric_limits<std::size_t>::max() / e)
      fail(errc::too_large, what, ": shape ", shape_text(shape), " has more entries than can be addressed");
    n *= e;
  }
  return n;
}

// ---------------------------------------------------------------------------
// What every reader shares: where relative files are, progress, warnings, timing.

struct Context {
  std::filesystem::path base_dir;
  progress_callback progress;
  bool keep_data = true;  // copy interpolated grids into Construction::data
  std::vector<std::string> warnings;
  Clock::time_point start = Clock::now();
  std::optional<Clock::time_point> parsed_at;

  // The spec is read and checked; what follows is the construction proper.
  void parsed() { parsed_at = Clock::now(); }
  void warn(std::string w) { warnings.push_back(std::move(w)); }
  [[nodiscard]] std::filesystem::path resolve(const std::string& file) const {
    const std::filesystem::path p(file);
    return p.is_absolute() || base_dir.empty() ? p : base_dir / p;
  }
};

// ---------------------------------------------------------------------------
// Fields.

const json* find_member(const json& obj, std::string_view key) {
  const auto it = obj.find(std::string(key));
  return it == obj.end() ? nullptr : &*it;
}

// A required member; its absence names the member's pointer and what it should hold.
const json& member(const json& obj, std::string_view key, std::string_view ptr, std::string_view expected) {
  const json* m = find_member(obj, key);
  if (!m) fail(errc::missing_field, child(ptr, key), ": missing field (expected ", expected, ")");
  return *m;
}

void expect_object(const json& j, std::string_view ptr, std::string_view expected) {
  if (!j.is_object()) wrong_type(ptr, expected, j);
}

// Names a reader does not know are reported (a typo would otherwise be silently
// ignored) but not refused: newer specs may carry options this build lacks.
void check_fields(const json& obj, std::string_view ptr, std::initializer_list<std::string_view> known, Context& ctx) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const std::string& k = it.key();
    if (k == "comment" || k == "description" || k == "name") continue;
    if (std::find(known.begin(), known.end(), k) == known.end())
      ctx.warn(cat(child(ptr, k), ": unknown field, ignored"));
  }
}

double number(const json& j, std::string_view ptr) {
  if (!j.is_number()) wrong_type(ptr, "a number", j);
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(errc::not_finite, place(ptr), ": value is ", v);
  return v;
}

// An integer; a float with an integral value (3.0) is accepted.
std::int64_t integer(const json& j, std::string_view ptr, std::string_view expected) {
  if (j.is_number_unsigned()) {
    const auto u = j.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
      fail(errc::wrong_type, place(ptr), ": ", u, " is too large; expected ", expected);
    return static_cast<std::int64_t>(u);
  }
  if (j.is_number_integer()) return j.get<std::int64_t>();
  if (j.is_number_float()) {
    const double d = j.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9.0e15) return static_cast<std::int64_t>(d);
    fail(errc::wrong_type, place(ptr), ": ", d, " is not an integer; expected ", expected);
  }
  wrong_type(ptr, expected, j);
}

std::vector<double> numbers(const json& j, std::string_view ptr, std::string_view expected = "an array of numbers") {
  if (!j.is_array()) wrong_type(ptr, expected, j);
  std::vector<double> v(j.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    const json& x = j[i];
    if (x.is_number()) {
      v[i] = x.get<double>();
      if (std::isfinite(v[i])) continue;
    }
    v[i] = number(x, child(ptr, i));  // throws with the entry's place
  }
  return v;
}

int degree_value(const json& j, std::string_view ptr) {
  const std::int64_t d = integer(j, ptr, "an integer degree");
  if (d < 1 || d > max_degree) fail(errc::invalid_degree, place(ptr), ": degree ", d, " is outside 1..", max_degree);
  return static_cast<int>(d);
}

// "degree": p for every direction, or [p, q(, r)]; unset entries mean the default.
std::vector<std::optional<int>> degrees(const json& obj, std::string_view ptr, std::size_t dims) {
  std::vector<std::optional<int>> d(dims);
  const json* j = find_member(obj, "degree");
  if (!j) return d;
  const std::string at_ = child(ptr, "degree");
  if (j->is_array()) {
    if (j->size() != dims)
      fail(errc::size_mismatch, at_, ": expected ", dims, " degrees (one per direction ",
           dims == 3 ? "u, v, w" : (dims == 2 ? "u, v" : "t"), "), got ", j->size());
    for (std::size_t i = 0; i < dims; ++i) d[i] = degree_value((*j)[i], child(at_, i));
  } else if (j->is_number()) {
    const int v = degree_value(*j, at_);
    for (auto& x : d) x = v;
  } else {
    wrong_type(at_, dims == 1 ? "an integer degree" : cat("an integer degree or an array of ", dims, " degrees"), *j);
  }
  return d;
}

std::string degree_pointer(const json& obj, std::string_view ptr, std::size_t axis) {
  const json* j = find_member(obj, "degree");
  const std::string d = child(ptr, "degree");
  return j && j->is_array() ? child(d, axis) : d;
}

const char* param_name(Parametrization p) {
  switch (p) {
    case Parametrization::uniform: return "uniform";
    case Parametrization::chord: return "chord";
    case Parametrization::centripetal: return "centripetal";
  }
  return "chord";
}

Parametrization parametrization(const json& obj, std::string_view ptr) {
  const json* p = find_member(obj, "param");
  if (!p) return Parametrization::chord;
  const std::string at_ = child(ptr, "param");
  if (!p->is_string()) wrong_type(at_, "a string: uniform, chord or centripetal", *p);
  const auto& s = p->get_ref<const std::string&>();
  for (const auto v : {Parametrization::uniform, Parametrization::chord, Parametrization::centripetal})
    if (s == param_name(v)) return v;
  fail(errc::wrong_type, at_, ": unknown parametrization \"", s, "\"; expected uniform, chord or centripetal");
}

// ---------------------------------------------------------------------------
// Rectangular arrays of nested lists.

std::string grid_form(std::size_t rank, bool points) {
  if (points && rank == 1) return "a list of points [[x, y, z], ...]";
  return cat("a ", rank == 1 ? "list" : cat(rank, "-D grid"), " of ", points ? "points" : "numbers", ": lists nested ",
             rank + (points ? 1 : 0), " deep");
}

// Walks lists nested `rank` deep whose every row has the length of the first one,
// calling leaf(entry, idx) on each entry at depth `rank` in C order. `leaf_depth`
// is how many more levels of lists an entry has (1 for a point [x, y, z], 0 for a
// number); it only serves to tell a grid of the wrong rank from a ragged one.
// Returns the shape.
template <class Leaf>
std::vector<std::size_t> walk_grid(const json& j, std::size_t rank, std::size_t leaf_depth, bool points,
                                   std::string_view ptr, std::vector<std::size_t>& idx, Leaf&& leaf) {
  std::vector<std::size_t> shape;
  std::size_t depth = 0;
  for (const json* node = &j; node->is_array(); node = &(*node)[0]) {
    if (node->empty()) {
      const std::vector<std::size_t> zeros(depth, 0);
      fail(errc::too_few_points, place(index_pointer(ptr, zeros, depth)), ": empty list; expected ",
           grid_form(rank, points));
    }
    if (depth < rank) shape.push_back(node->size());
    ++depth;
  }
  if (depth != rank + leaf_depth) {
    if (depth == 0) wrong_type(ptr, grid_form(rank, points), j);
    fail(errc::wrong_type, place(ptr), ": expected ", grid_form(rank, points), ", got lists nested ", depth, " deep");
  }
  idx.assign(rank + leaf_depth, 0);
  auto walk = [&](auto& self, const json& node, std::size_t level) -> void {
    if (level == rank) {
      leaf(node);
      return;
    }
    if (!node.is_array())
      fail(errc::wrong_type, place(index_pointer(ptr, idx, level)), ": expected a list of ",
           level + 1 < rank ? "rows" : (points ? "points" : "numbers"), ", got ", kind(node));
    if (node.size() != shape[level]) {
      std::vector<std::size_t> first(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(level));
      std::fill(first.begin(), first.end(), 0);
      fail(errc::ragged_grid, place(index_pointer(ptr, idx, level)), ": has ", node.size(),
           level + 1 < rank ? " rows" : (points ? " points" : " numbers"), ", but ",
           place(index_pointer(ptr, first, level)), " has ", shape[level]);
    }
    for (std::size_t i = 0; i < node.size(); ++i) {
      idx[level] = i;
      self(self, node[i], level + 1);
    }
  };
  walk(walk, j, 0);
  return shape;
}

PointArray inline_points(const json& j, std::size_t rank, std::string_view ptr) {
  PointArray out;
  std::vector<std::size_t> idx;
  // Size the result from the first entries before walking; the walk checks the rest.
  std::vector<std::size_t> first_shape;
  for (const json* node = &j; node->is_array() && !node->empty() && first_shape.size() < rank; node = &(*node)[0])
    first_shape.push_back(node->size());
  if (first_shape.size() == rank) {
    const std::size_t n = checked_product(first_shape, place(ptr));
    require_memory(n, sizeof(Vec3), cat(place(ptr), ": ", n, " points"));
    out.points.reserve(n);
  }
  out.shape = walk_grid(j, rank, 1, true, ptr, idx, [&](const json& node) {
    if (!node.is_array()) fail(errc::wrong_type, index_pointer(ptr, idx, rank), ": expected a point [x, y, z], got ", kind(node));
    if (node.size() != 3)
      fail(errc::ragged_grid, index_pointer(ptr, idx, rank), ": a point must be 3 numbers [x, y, z], got ",
           node.size(), node.size() == 1 ? " entry" : " entries");
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      const json& c = node[static_cast<std::size_t>(k)];
      idx[rank] = static_cast<std::size_t>(k);
      if (!c.is_number())
        fail(errc::wrong_type, index_pointer(ptr, idx, rank + 1), ": expected a number (coordinate ", coord_name(k),
             "), got ", kind(c));
      p[k] = c.get<double>();
      if (!std::isfinite(p[k]))
        fail(errc::not_finite, index_pointer(ptr, idx, rank + 1), ": coordinate ", coord_name(k), " is ", p[k]);
    }
    idx[rank] = 0;
    out.points.push_back(p);
  });
  return out;
}

template <std::size_t Rank = 2>
Grid<double, Rank> inline_number_grid(const json& j, std::string_view ptr) {
  std::vector<double> values;
  std::vector<std::size_t> idx;
  const auto shape = walk_grid(j, Rank, 0, false, ptr, idx, [&](const json& node) {
    if (!node.is_number()) fail(errc::wrong_type, index_pointer(ptr, idx, Rank), ": expected a number, got ", kind(node));
    const double v = node.get<double>();
    if (!std::isfinite(v)) fail(errc::not_finite, index_pointer(ptr, idx, Rank), ": value is ", v);
    values.push_back(v);
  });
  typename Grid<double, Rank>::shape_type sh{};
  for (std::size_t a = 0; a < Rank; ++a) sh[a] = shape[a];
  return Grid<double, Rank>(sh, std::move(values));
}

std::string expected_shape(std::size_t rank) {
  static constexpr const char* names[] = {"n", "m", "l"};
  std::string s = "(";
  for (std::size_t i = 0; i < rank; ++i) s += cat(names[std::min<std::size_t>(i, 2)], ", ");
  return s + "3)";
}

// Data from a file: check every value is finite, naming it as if it were inline.
// Refuses the first point with a NaN or Inf coordinate, naming it as a JSON Pointer
// below `ptr` (`/points/3/7/2`) and the file it came from.
void check_finite_points(const std::vector<std::size_t>& shape, const PointStorage& points, std::string_view ptr,
                         const std::string& file) {
  if (const std::size_t i = detail::first_non_finite(points.data(), points.size()); i < points.size()) {
    const Vec3& p = points[i];
    std::vector<std::size_t> idx(shape.size() + 1);
    std::size_t r = i;
    for (std::size_t a = shape.size(); a-- > 0;) {
      idx[a] = r % shape[a];
      r /= shape[a];
    }
    const int k = std::isfinite(p.x) ? (std::isfinite(p.y) ? 2 : 1) : 0;
    idx[shape.size()] = static_cast<std::size_t>(k);
    fail(errc::not_finite, index_pointer(ptr, idx, idx.size()), ": coordinate ", coord_name(k), " is ", p[k], " (in ",
         file, ")");
  }
}

std::string file_name(const json& obj, std::string_view key, std::string_view ptr) {
  const json& f = member(obj, key, ptr, "a file name");
  if (!f.is_string() || f.get_ref<const std::string&>().empty()) wrong_type(child(ptr, key), "a file name", f);
  return f.get<std::string>();
}

PointArray npy_points(const json& obj, std::size_t rank, std::string_view ptr, Context& ctx) {
  check_fields(obj, ptr, {"npy"}, ctx);
  const std::string file = file_name(obj, "npy", ptr);
  // The values land in the point storage itself: float64 triples in C order are
  // exactly a grid of Vec3.
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are read as triples of doubles");
  PointArray out;
  const std::vector<std::size_t> full = at(ptr, [&] {
    return read_npy_into(ctx.resolve(file), [&](std::span<const std::size_t> shape, std::size_t count) {
      const std::vector<std::size_t> s(shape.begin(), shape.end());
      if (s.size() != rank + 1 || s.back() != 3)
        fail(errc::size_mismatch, file, " has shape ", shape_text(s), "; expected ", expected_shape(rank), ", ",
             rank == 1 ? "a list" : cat("a ", rank, "-D grid"), " of 3-vectors");
      for (std::size_t ax = 0; ax + 1 < s.size(); ++ax)
        if (s[ax] == 0) fail(errc::too_few_points, file, " has shape ", shape_text(s), ", no points");
      resize_for_overwrite(out.points, count / 3);
      return &out.points.data()->x;
    });
  });
  out.shape.assign(full.begin(), full.end() - 1);
  check_finite_points(out.shape, out.points, ptr, file);
  return out;
}

PointArray csv_points(const json& obj, std::size_t rank, std::string_view ptr, Context& ctx) {
  check_fields(obj, ptr, {"csv", "shape"}, ctx);
  const std::string file = file_name(obj, "csv", ptr);
  const std::string sptr = child(ptr, "shape");
  const json& sj = member(obj, "shape", ptr, cat("the grid shape, e.g. ", expected_shape(rank)));
  if (!sj.is_array()) wrong_type(sptr, cat("an array of ", rank, " extents (a trailing 3 may follow)"), sj);
  std::vector<std::size_t> shape;
  for (std::size_t i = 0; i < sj.size(); ++i) {
    const std::int64_t e = integer(sj[i], child(sptr, i), "an integer extent");
    if (e < 1) fail(errc::too_few_points, child(sptr, i), ": extent ", e, " is below 1");
    shape.push_back(static_cast<std::size_t>(e));
  }
  if (shape.size() == rank + 1 && shape.back() == 3) shape.pop_back();
  if (shape.size() != rank)
    fail(errc::size_mismatch, sptr, ": shape ", shape_text(shape), " does not describe ", grid_form(rank, true),
         "; expected [", rank == 1 ? "n" : (rank == 2 ? "n, m" : "n, m, l"), "] or [", rank == 1 ? "n" : (rank == 2 ? "n, m" : "n, m, l"),
         ", 3]");
  const std::size_t n = checked_product(shape, sptr);
  require_memory(n, sizeof(Vec3), cat(place(ptr), ": ", n, " points from ", file));
  const std::vector<Vec3> pts = at(ptr, [&] { return read_csv_points(ctx.resolve(file), n); });
  if (pts.size() != n)
    fail(errc::size_mismatch, place(ptr), ": ", file, " has ", pts.size(), " points, shape ", shape_text(shape), " needs ", n);
  for (std::size_t i = 0; i < n; ++i)
    if (!is_finite(pts[i])) fail(errc::not_finite, place(ptr), ": ", file, " point ", i, " is ", pts[i]);
  return {shape, PointStorage(pts.begin(), pts.end())};
}

PointArray points_impl(const json& j, std::size_t rank, std::string_view ptr, Context& ctx) {
  if (j.is_object()) {
    const bool npy = j.contains("npy"), csv = j.contains("csv");
    if (npy && csv) fail(errc::wrong_type, place(ptr), ": give either \"npy\" or \"csv\", not both");
    if (npy) return npy_points(j, rank, ptr, ctx);
    if (csv) return csv_points(j, rank, ptr, ctx);
    fail(errc::missing_field, place(ptr), ": a point array given as an object needs \"npy\": file or \"csv\": file with \"shape\"");
  }
  return inline_points(j, rank, ptr);
}

// ---------------------------------------------------------------------------
// Curves, each mapped onto [0, 1].

BSplineCurve on_unit_domain(BSplineCurve c) {
  const auto [a, b] = c.domain();
  if (a == 0.0 && b == 1.0) return c;
  return c.mapped(0.0, 1.0);
}

std::vector<Vec3> curve_points(const json& j, std::string_view ptr, Context& ctx) {
  const PointArray a = points_impl(j, 1, ptr, ctx);
  if (a.points.size() < 2) fail(errc::too_few_points, place(ptr), ": a curve needs at least 2 points, got ", a.points.size());
  return {a.points.begin(), a.points.end()};
}

BSplineCurve interpolated_curve(const json& obj, std::string_view ptr, Context& ctx) {
  check_fields(obj, ptr, {"interpolate", "degree", "param"}, ctx);
  const std::string pts_at = child(ptr, "interpolate");
  const std::vector<Vec3> pts = curve_points(obj.at("interpolate"), pts_at, ctx);
  const auto degree = degrees(obj, ptr, 1)[0];
  if (degree && static_cast<std::size_t>(*degree) >= pts.size())
    fail(errc::too_few_points, degree_pointer(obj, ptr, 0), ": degree ", *degree, " needs at least ", *degree + 1,
         " points, ", pts_at, " has ", pts.size());
  const Parametrization param = parametrization(obj, ptr);
  if (param != Parametrization::uniform)
    for (std::size_t i = 1; i < pts.size(); ++i)
      if (pts[i] == pts[i - 1])
        fail(errc::zero_chord, child(pts_at, i), ": point ", i, " ", pts[i], " coincides with point ", i - 1,
             " (a zero chord); ", param_name(param), " parameters need distinct consecutive points");
  CurveInterpolationOptions options;
  options.degree = degree;
  options.param = param;
  return at(ptr, [&] { return on_unit_domain(interpolate_curve(pts, options).curve); });
}

BSplineCurve bspline_curve(const json& b, std::string_view ptr, Context& ctx) {
  expect_object(b, ptr, "an object {\"degree\", \"knots\", \"control_points\", \"weights\"}");
  check_fields(b, ptr, {"degree", "knots", "control_points", "weights"}, ctx);
  const int p = degree_value(member(b, "degree", ptr, "an integer degree"), child(ptr, "degree"));
  const std::string kptr = child(ptr, "knots"), cptr = child(ptr, "control_points"), wptr = child(ptr, "weights");
  std::vector<double> knots = numbers(member(b, "knots", ptr, "an array of knots"), kptr);
  const PointStorage cps = points_impl(member(b, "control_points", ptr, "a list of points"), 1, cptr, ctx).points;
  std::vector<Vec3> cp(cps.begin(), cps.end());
  std::vector<double> w;
  if (const json* wj = find_member(b, "weights")) w = numbers(*wj, wptr);
  KnotVector k = at(kptr, [&] { return KnotVector(p, std::move(knots)); });
  if (static_cast<std::size_t>(k.count()) != cp.size())
    fail(errc::size_mismatch, cptr, ": ", k.size(), " knots of degree ", p, " need ", k.count(), " control points, got ",
         cp.size());
  if (!w.empty() && w.size() != cp.size())
    fail(errc::size_mismatch, wptr, ": ", cp.size(), " control points need ", cp.size(), " weights, got ", w.size());
  for (std::size_t i = 0; i < w.size(); ++i)
    if (!(w[i] > 0)) fail(errc::invalid_weight, child(wptr, i), ": weight ", w[i], " is not positive");
  return at(ptr, [&] { return on_unit_domain(BSplineCurve(std::move(k), std::move(cp), std::move(w))); });
}

BSplineCurve hermite_curve(const json& h, std::string_view ptr, Context& ctx) {
  expect_object(h, ptr, "an object {\"points\", \"tangents\", \"params\"}");
  check_fields(h, ptr, {"points", "tangents", "params"}, ctx);
  const std::string pptr = child(ptr, "points"), tptr = child(ptr, "tangents"), uptr = child(ptr, "params");
  std::vector<Vec3> pts = curve_points(member(h, "points", ptr, "a list of points"), pptr, ctx);
  std::vector<Vec3> tangents;
  if (const json* t = find_member(h, "tangents")) {
    const PointStorage ts = points_impl(*t, 1, tptr, ctx).points;
    tangents.assign(ts.begin(), ts.end());
    if (tangents.size() != pts.size())
      fail(errc::size_mismatch, tptr, ": ", pts.size(), " points need ", pts.size(), " tangents, got ", tangents.size());
  }
  std::vector<double> params;
  if (const json* u = find_member(h, "params")) {
    params = numbers(*u, uptr);
    if (params.size() != pts.size())
      fail(errc::size_mismatch, uptr, ": ", pts.size(), " points need ", pts.size(), " params, got ", params.size());
    for (std::size_t i = 1; i < params.size(); ++i)
      if (!(params[i] > params[i - 1]))
        fail(errc::non_increasing, child(uptr, i), ": param ", params[i], " is not greater than the one before, ",
             params[i - 1]);
  }
  return at(ptr, [&] {
    return on_unit_domain(HermiteCurve(std::move(pts), std::move(tangents), std::move(params)).to_bspline());
  });
}

BSplineCurve line_curve(const json& l, std::string_view ptr, Context& ctx) {
  const PointStorage pts = points_impl(l, 1, ptr, ctx).points;
  if (pts.size() != 2) fail(errc::size_mismatch, place(ptr), ": a line needs exactly 2 points [A, B], got ", pts.size());
  // A == B is allowed: a collapsed boundary (a triangular patch) is a point.
  return BSplineCurve(KnotVector(1, {0.0, 0.0, 1.0, 1.0}), {pts[0], pts[1]});
}

BSplineCurve curve_impl(const json& j, std::string_view ptr, Context& ctx) {
  static constexpr std::array<std::string_view, 4> forms{"interpolate", "bspline", "hermite", "line"};
  constexpr std::string_view expected =
      "a curve: an object with one of \"interpolate\", \"bspline\", \"hermite\", \"line\"";
  if (!j.is_object()) wrong_type(ptr, expected, j);
  std::vector<std::string_view> present;
  for (const auto f : forms)
    if (j.contains(std::string(f))) present.push_back(f);
  if (present.empty()) fail(errc::missing_field, place(ptr), ": expected ", expected);
  if (present.size() > 1)
    fail(errc::wrong_type, place(ptr), ": a curve has exactly one of \"interpolate\", \"bspline\", \"hermite\", \"line\"; got \"",
         present[0], "\" and \"", present[1], "\"");
  const std::string_view form = present[0];
  if (form == "interpolate") return interpolated_curve(j, ptr, ctx);
  check_fields(j, ptr, {form}, ctx);
  const json& body = j.at(std::string(form));
  const std::string bptr = child(ptr, form);
  if (form == "bspline") return bspline_curve(body, bptr, ctx);
  if (form == "hermite") return hermite_curve(body, bptr, ctx);
  return line_curve(body, bptr, ctx);
}

// ---------------------------------------------------------------------------
// Surfaces. Each construction type is one function from the spec to a
// Construction, listed in `construction_types` below.

BSplineSurface on_unit_domain(BSplineSurface s) {
  const auto [u0, u1] = s.domain_u();
  const auto [v0, v1] = s.domain_v();
  if (u0 == 0.0 && u1 == 1.0 && v0 == 0.0 && v1 == 1.0) return s;
  return s.mapped(0.0, 1.0, 0.0, 1.0);
}

std::vector<double> to_unit(std::vector<double> t, std::pair<double, double> domain) {
  const auto [a, b] = domain;
  if (a == 0.0 && b == 1.0) return t;
  for (double& x : t) x = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t;
}

Construction build_interpolate(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "points", "degree", "param"}, ctx);
  PointArray pts = points_impl(member(spec, "points", "", "a grid of points, (n+1) x (m+1) x 3"), 2, "/points", ctx);
  const auto degree = degrees(spec, "", 2);
  const Parametrization param = parametrization(spec, "");
  const std::size_t nu = pts.shape[0], nv = pts.shape[1];
  for (std::size_t a = 0; a < 2; ++a) {
    const std::size_t count = pts.shape[a];
    if (count < 2)
      fail(errc::too_few_points, "/points: the grid has ", count, " point", count == 1 ? "" : "s", " along ", axis_name(a),
           " (shape ", nu, "x", nv, "); interpolation needs at least 2");
    if (degree[a] && static_cast<std::size_t>(*degree[a]) >= count)
      fail(errc::too_few_points, degree_pointer(spec, "", a), ": degree ", *degree[a], " along ", axis_name(a),
           " needs at least ", *degree[a] + 1, " points, /points has ", count, " (shape ", nu, "x", nv, ")");
  }
  PointGrid grid({nu, nv}, std::move(pts.points));
  DataSet data;
  data.pointer = "/points";
  if (ctx.keep_data) {
    require_memory(grid.size(), sizeof(Vec3), cat("/points: a copy of the ", nu, "x", nv, " data points for the error check"));
    data.points.assign(grid.values().begin(), grid.values().end());
  }

  SurfaceInterpolationOptions options;
  options.degree_u = degree[0];
  options.degree_v = degree[1];
  options.param = param;
  options.progress = ctx.progress;
  ctx.parsed();
  SurfaceInterpolation r = at("/points", [&] { return interpolate_surface(std::move(grid), options); });

  data.params = {to_unit(std::move(r.params_u), r.surface.domain_u()), to_unit(std::move(r.params_v), r.surface.domain_v())};
  BSplineSurface s = on_unit_domain(std::move(r.surface));
  nlohmann::ordered_json parameters = {{"grid", {nu, nv}}, {"degree", {s.degree_u(), s.degree_v()}}, {"param", param_name(param)}};
  Construction c{"interpolate", std::move(s), {}, std::move(parameters), {}, {}, {}, {}, {}};
  if (ctx.keep_data) c.data.push_back(std::move(data));
  return c;
}

Construction build_bspline_surface(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "degree", "knots", "control_points", "weights"}, ctx);
  member(spec, "degree", "", "an integer degree or [p, q]");
  const auto degree = degrees(spec, "", 2);
  const json& knots = member(spec, "knots", "", "an object {\"u\": [...], \"v\": [...]}");
  expect_object(knots, "/knots", "an object {\"u\": [...], \"v\": [...]}");
  check_fields(knots, "/knots", {"u", "v"}, ctx);
  std::vector<double> ku = numbers(member(knots, "u", "/knots", "an array of knots"), "/knots/u");
  std::vector<double> kv = numbers(member(knots, "v", "/knots", "an array of knots"), "/knots/v");
  PointArray cp = points_impl(member(spec, "control_points", "", "a grid of control points, (n+1) x (m+1) x 3"), 2,
                              "/control_points", ctx);
  Grid<double, 2> weights;
  if (const json* w = find_member(spec, "weights")) {
    weights = inline_number_grid(*w, "/weights");
    if (weights.extent(0) != cp.shape[0] || weights.extent(1) != cp.shape[1])
      fail(errc::size_mismatch, "/weights: shape ", weights.extent(0), "x", weights.extent(1), " differs from ",
           "/control_points, ", cp.shape[0], "x", cp.shape[1]);
    for (std::size_t i = 0; i < weights.extent(0); ++i)
      for (std::size_t j = 0; j < weights.extent(1); ++j)
        if (!(weights(i, j) > 0))
          fail(errc::invalid_weight, "/weights/", i, "/", j, ": weight ", weights(i, j), " is not positive");
  }
  KnotVector knots_u = at("/knots/u", [&] { return KnotVector(*degree[0], std::move(ku)); });
  KnotVector knots_v = at("/knots/v", [&] { return KnotVector(*degree[1], std::move(kv)); });
  const KnotVector* k[2] = {&knots_u, &knots_v};
  for (std::size_t a = 0; a < 2; ++a)
    if (static_cast<std::size_t>(k[a]->count()) != cp.shape[a])
      fail(errc::size_mismatch, "/control_points: ", cp.shape[a], " control points along ", axis_name(a), " (shape ",
           cp.shape[0], "x", cp.shape[1], "), but the ", k[a]->size(), " knots of degree ", k[a]->degree(), " in /knots/",
           axis_name(a), " need ", k[a]->count());
  ctx.parsed();
  BSplineSurface s = at("/control_points", [&] {
    return BSplineSurface(std::move(knots_u), std::move(knots_v), PointGrid({cp.shape[0], cp.shape[1]}, std::move(cp.points)),
                          std::move(weights));
  });
  const auto [u0, u1] = s.domain_u();
  const auto [v0, v1] = s.domain_v();
  nlohmann::ordered_json parameters = {{"domain", {{"u", {u0, u1}}, {"v", {v0, v1}}}}};
  return Construction{"bspline_surface", on_unit_domain(std::move(s)), {}, std::move(parameters), {}, {}, {}, {}, {}};
}

// ---------------------------------------------------------------------------
// Constructions from corners and curves (coons.hpp, network.hpp, patches.hpp).
// Their data (corners, curves) are checked against the exact form by `info`, as
// curves sampled at `curve_samples` parameters.

constexpr std::size_t curve_samples = 65;

Vec3 point_value(const json& j, std::string_view ptr) {
  const std::vector<double> v = numbers(j, ptr, "a point [x, y, z]");
  if (v.size() != 3) fail(errc::wrong_type, place(ptr), ": expected a point [x, y, z], got ", v.size(), " numbers");
  return {v[0], v[1], v[2]};
}

std::optional<double> tolerance_of(const json& spec) {
  const json* t = find_member(spec, "tolerance");
  if (!t) return std::nullopt;
  const double v = number(*t, "/tolerance");
  if (!(v >= 0)) fail(errc::wrong_type, "/tolerance: must not be negative, got ", v);
  return v;
}

std::string choice(const json& obj, std::string_view key, std::string_view ptr,
                   std::initializer_list<std::string_view> allowed, std::string_view fallback) {
  const json* m = find_member(obj, key);
  if (!m) return std::string(fallback);
  std::string list;
  for (auto a : allowed) list += cat(list.empty() ? "\"" : ", \"", a, "\"");
  if (!m->is_string()) wrong_type(child(ptr, key), cat("one of ", list), *m);
  const auto& v = m->get_ref<const std::string&>();
  if (std::find(allowed.begin(), allowed.end(), v) == allowed.end())
    fail(errc::wrong_type, child(ptr, key), ": unknown value \"", v, "\"; expected one of ", list);
  return v;
}

// A curve of the spec sampled for the data check: S(u, fixed) (axis 0) or S(fixed, v).
DataSet curve_data(const BSplineCurve& c, int axis, double fixed, std::string pointer) {
  DataSet d;
  const std::vector<double> t = linspace(0, 1, curve_samples);
  d.params = axis == 0 ? std::vector<std::vector<double>>{t, {fixed}} : std::vector<std::vector<double>>{{fixed}, t};
  for (double x : t) d.points.push_back(c.point(x));
  d.pointer = std::move(pointer);
  return d;
}

DataSet corner_data(const std::array<Vec3, 4>& p, std::string pointer) {
  DataSet d;
  d.params = {{0.0, 1.0}, {0.0, 1.0}};
  d.points.assign(p.begin(), p.end());  // p00, p01, p10, p11: C order of (u, v)
  d.pointer = std::move(pointer);
  return d;
}

// A blended construction (surface or volume): the formula, stored in `slot`, and
// its exact form if it has one.
template <class Formula, class Slot>
Construction blended_with(std::string_view type, Formula f, std::vector<DataSet> data, nlohmann::ordered_json parameters,
                          Slot Construction::*slot) {
  Construction c;
  c.type = type;
  auto formula = std::make_shared<const Formula>(std::move(f));
  try {
    c.exact = formula->to_bspline();
  } catch (const error& e) {
    if (e.code() != errc::no_exact_form) throw;
    c.no_exact_form = e.what();
  }
  if (!formula->notes().empty()) parameters["notes"] = formula->notes();
  c.*slot = std::move(formula);
  c.data = std::move(data);
  c.parameters = std::move(parameters);
  return c;
}

Construction blended(std::string_view type, BlendedSurface s, std::vector<DataSet> data, nlohmann::ordered_json parameters) {
  return blended_with(type, std::move(s), std::move(data), std::move(parameters), &Construction::formula);
}

Construction build_bilinear(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "p00", "p01", "p10", "p11"}, ctx);
  std::array<Vec3, 4> p;
  const char* names[4] = {"p00", "p01", "p10", "p11"};
  for (std::size_t k = 0; k < 4; ++k)
    p[k] = point_value(member(spec, names[k], "", "a point [x, y, z]"), child("", names[k]));
  ctx.parsed();
  return blended("bilinear", bilinear(p[0], p[1], p[2], p[3]), {corner_data(p, "/p00")}, nlohmann::ordered_json::object());
}

Construction build_ruled(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "curves"}, ctx);
  const json& cs = member(spec, "curves", "", "an array of two curves [c0, c1]");
  if (!cs.is_array() || cs.size() != 2) wrong_type("/curves", "an array of two curves [c0, c1]", cs);
  const BSplineCurve c0 = curve_impl(cs[0], "/curves/0", ctx), c1 = curve_impl(cs[1], "/curves/1", ctx);
  ctx.parsed();
  return blended("ruled", ruled(c0, c1), {curve_data(c0, 0, 0.0, "/curves/0"), curve_data(c1, 0, 1.0, "/curves/1")},
                 nlohmann::ordered_json::object());
}

Construction build_coons(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "boundary", "blending", "cross_derivatives", "twists", "twist_correction", "tolerance"},
               ctx);
  const char* sides[4] = {"v0", "v1", "u0", "u1"};
  auto four_curves = [&](const json& obj, const std::string& ptr) {
    expect_object(obj, ptr, "an object {\"v0\", \"v1\", \"u0\", \"u1\"} of curves");
    check_fields(obj, ptr, {"v0", "v1", "u0", "u1"}, ctx);
    std::vector<BSplineCurve> c;
    for (const char* side : sides) c.push_back(curve_impl(member(obj, side, ptr, "a curve"), child(ptr, side), ctx));
    return c;
  };
  const auto b = four_curves(member(spec, "boundary", "", "an object {\"v0\", \"v1\", \"u0\", \"u1\"} of curves"), "/boundary");
  const CoonsBoundary boundary{b[0], b[1], b[2], b[3]};
  const std::string blending = choice(spec, "blending", "", {"linear", "hermite"}, "linear");
  const std::optional<double> tol = tolerance_of(spec);
  std::vector<DataSet> data{curve_data(b[0], 0, 0.0, "/boundary/v0"), curve_data(b[1], 0, 1.0, "/boundary/v1"),
                            curve_data(b[2], 1, 0.0, "/boundary/u0"), curve_data(b[3], 1, 1.0, "/boundary/u1")};
  nlohmann::ordered_json parameters = {{"blending", blending}};
  if (const json* x = find_member(spec, "cross_derivatives")) {
    const auto d = four_curves(*x, "/cross_derivatives");
    HermiteCoonsOptions o;
    o.tolerance = tol;
    o.twist_correction = choice(spec, "twist_correction", "", {"none", "gregory"}, "none") == "gregory"
                             ? TwistCorrection::gregory
                             : TwistCorrection::none;
    if (const json* tw = find_member(spec, "twists")) {
      expect_object(*tw, "/twists", "an object {\"p00\", \"p01\", \"p10\", \"p11\"} of vectors");
      check_fields(*tw, "/twists", {"p00", "p01", "p10", "p11"}, ctx);
      const char* corners[4] = {"p00", "p01", "p10", "p11"};
      for (std::size_t k = 0; k < 4; ++k)
        if (const json* t = find_member(*tw, corners[k])) o.twists[k] = point_value(*t, child("/twists", corners[k]));
    }
    ctx.parsed();
    parameters = {{"blending", "hermite"},
                  {"cross_derivatives", true},
                  {"twist_correction", o.twist_correction == TwistCorrection::gregory ? "gregory" : "none"}};
    return blended("coons", at("", [&] { return coons(boundary, CoonsCrossDerivatives{d[0], d[1], d[2], d[3]}, o); }),
                   std::move(data), std::move(parameters));
  }
  for (const char* k : {"twists", "twist_correction"})
    if (find_member(spec, k)) ctx.warn(cat("/", k, ": ignored without \"cross_derivatives\""));
  CoonsOptions o;
  o.tolerance = tol;
  if (blending == "hermite") o.blend_u = o.blend_v = Blend::hermite();
  ctx.parsed();
  return blended("coons", at("", [&] { return coons(boundary, o); }), std::move(data), std::move(parameters));
}

Construction build_network(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "u_curves", "v_curves", "u_params", "v_params", "method", "tolerance"}, ctx);
  auto curves = [&](const char* key) {
    const std::string ptr = child("", key);
    const json& a = member(spec, key, "", "an array of curves");
    if (!a.is_array()) wrong_type(ptr, "an array of curves", a);
    std::vector<BSplineCurve> c;
    for (std::size_t i = 0; i < a.size(); ++i) c.push_back(curve_impl(a[i], child(ptr, i), ctx));
    return c;
  };
  CurveNetwork net{curves("u_curves"), curves("v_curves"), {}, {}};
  if (const json* p = find_member(spec, "u_params")) net.u_params = numbers(*p, "/u_params");
  if (const json* p = find_member(spec, "v_params")) net.v_params = numbers(*p, "/v_params");
  const std::string method = choice(spec, "method", "", {"coons_linear", "coons_hermite", "gordon"}, "gordon");
  NetworkOptions o;
  o.method = method == "coons_linear" ? NetworkMethod::coons_linear
             : method == "coons_hermite" ? NetworkMethod::coons_hermite
                                         : NetworkMethod::gordon;
  o.tolerance = tolerance_of(spec);
  ctx.parsed();
  if (net.u_params.empty() || net.v_params.empty()) {
    const auto found = at("", [&] { return network_parameters(net); });
    if (net.u_params.empty()) net.u_params = found.u_params;
    if (net.v_params.empty()) net.v_params = found.v_params;
  }
  BlendedSurface s = at("", [&] { return curve_network(net, o); });
  std::vector<DataSet> data;
  for (std::size_t j = 0; j < net.u_curves.size(); ++j)
    data.push_back(curve_data(net.u_curves[j], 0, net.v_params[j], child("/u_curves", j)));
  for (std::size_t i = 0; i < net.v_curves.size(); ++i)
    data.push_back(curve_data(net.v_curves[i], 1, net.u_params[i], child("/v_curves", i)));
  nlohmann::ordered_json parameters = {{"method", method},
                                       {"curves", {net.u_curves.size(), net.v_curves.size()}},
                                       {"u_params", net.u_params},
                                       {"v_params", net.v_params}};
  return blended("network", std::move(s), std::move(data), std::move(parameters));
}

Construction build_hermite_patch(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "corners"}, ctx);
  const json& cs = member(spec, "corners", "", "an object {\"p00\", \"p01\", \"p10\", \"p11\"} of corners");
  expect_object(cs, "/corners", "an object {\"p00\", \"p01\", \"p10\", \"p11\"} of corners");
  check_fields(cs, "/corners", {"p00", "p01", "p10", "p11"}, ctx);
  std::array<HermiteCorner, 4> c{};
  std::array<Vec3, 4> p;
  const char* names[4] = {"p00", "p01", "p10", "p11"};
  for (std::size_t k = 0; k < 4; ++k) {
    const std::string ptr = child("/corners", names[k]);
    const json& o = member(cs, names[k], "/corners", "a corner {\"p\", \"du\", \"dv\", \"duv\"}");
    expect_object(o, ptr, "a corner {\"p\", \"du\", \"dv\", \"duv\"}");
    check_fields(o, ptr, {"p", "du", "dv", "duv"}, ctx);
    c[k].p = point_value(member(o, "p", ptr, "a point [x, y, z]"), child(ptr, "p"));
    c[k].du = point_value(member(o, "du", ptr, "a vector [x, y, z]"), child(ptr, "du"));
    c[k].dv = point_value(member(o, "dv", ptr, "a vector [x, y, z]"), child(ptr, "dv"));
    if (const json* t = find_member(o, "duv")) c[k].duv = point_value(*t, child(ptr, "duv"));
    p[k] = c[k].p;
  }
  ctx.parsed();
  return blended("hermite_patch", hermite_patch(c), {corner_data(p, "/corners")}, nlohmann::ordered_json::object());
}

// ---------------------------------------------------------------------------
// Volumes (SPEC section 3): from corners, from six boundary surfaces, through a
// grid of points, and the exact form build writes.

BSplineVolume on_unit_domain(BSplineVolume v) {
  const auto d = v.domain();
  if (d[0] == std::pair{0.0, 1.0} && d[1] == std::pair{0.0, 1.0} && d[2] == std::pair{0.0, 1.0}) return v;
  return v.mapped(0.0, 1.0, 0.0, 1.0, 0.0, 1.0);
}

Construction blended_volume(std::string_view type, BlendedVolume v, std::vector<DataSet> data,
                            nlohmann::ordered_json parameters) {
  return blended_with(type, std::move(v), std::move(data), std::move(parameters), &Construction::volume_formula);
}

// The 8 corners of a volume as data: (i, j, k) at index 4i + 2j + k, the C order of (u, v, w).
DataSet volume_corner_data(const std::array<Vec3, 8>& p, std::string pointer) {
  DataSet d;
  d.params = {{0.0, 1.0}, {0.0, 1.0}, {0.0, 1.0}};
  d.points.assign(p.begin(), p.end());
  d.pointer = std::move(pointer);
  return d;
}

// Samples per direction of a boundary surface checked against a Coons volume.
constexpr std::size_t face_samples = 17;

// A face of a volume sampled for the data check: face u_i at (i, v, w), v_j at
// (u, j, w), w_k at (u, v, k), the face's own parameters running over [0, 1]².
DataSet face_data(const BSplineSurface& f, std::size_t axis, double fixed, std::string pointer) {
  DataSet d;
  const std::vector<double> t = linspace(0, 1, face_samples);
  const PointGrid g = f.evaluate(t, t);
  d.params.assign(3, t);
  d.params[axis] = {fixed};
  d.points.assign(g.values().begin(), g.values().end());
  d.pointer = std::move(pointer);
  return d;
}

BSplineSurface face_surface(const json& j, const std::string& ptr, Context& ctx);

Construction build_trilinear(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "p000", "p001", "p010", "p011", "p100", "p101", "p110", "p111"}, ctx);
  std::array<Vec3, 8> p;
  for (std::size_t n = 0; n < 8; ++n) {
    const std::string name = cat("p", n >> 2, (n >> 1) & 1, n & 1);
    p[n] = point_value(member(spec, name, "", "a point [x, y, z]"), child("", name));
  }
  ctx.parsed();
  return blended_volume("trilinear", at("", [&] { return trilinear(p); }), {volume_corner_data(p, "/p000")},
                        nlohmann::ordered_json::object());
}

Construction build_hermite_volume(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "corners"}, ctx);
  constexpr std::string_view expected = "an array of 8 corners {\"p\", \"du\", \"dv\", \"dw\"}, corner (i,j,k) at index 4i+2j+k";
  const json& cs = member(spec, "corners", "", expected);
  if (!cs.is_array()) wrong_type("/corners", expected, cs);
  if (cs.size() != 8) fail(errc::size_mismatch, "/corners: expected 8 corners (corner (i,j,k) at index 4i+2j+k), got ", cs.size());
  std::array<HermiteVolumeCorner, 8> c{};
  std::array<Vec3, 8> p;
  for (std::size_t n = 0; n < 8; ++n) {
    const std::string ptr = child("/corners", n);
    const json& o = cs[n];
    expect_object(o, ptr, "a corner {\"p\", \"du\", \"dv\", \"dw\", \"duv\", \"duw\", \"dvw\", \"duvw\"}");
    check_fields(o, ptr, {"p", "du", "dv", "dw", "duv", "duw", "dvw", "duvw"}, ctx);
    c[n].p = point_value(member(o, "p", ptr, "a point [x, y, z]"), child(ptr, "p"));
    c[n].du = point_value(member(o, "du", ptr, "a vector [x, y, z]"), child(ptr, "du"));
    c[n].dv = point_value(member(o, "dv", ptr, "a vector [x, y, z]"), child(ptr, "dv"));
    c[n].dw = point_value(member(o, "dw", ptr, "a vector [x, y, z]"), child(ptr, "dw"));
    if (const json* t = find_member(o, "duv")) c[n].duv = point_value(*t, child(ptr, "duv"));
    if (const json* t = find_member(o, "duw")) c[n].duw = point_value(*t, child(ptr, "duw"));
    if (const json* t = find_member(o, "dvw")) c[n].dvw = point_value(*t, child(ptr, "dvw"));
    if (const json* t = find_member(o, "duvw")) c[n].duvw = point_value(*t, child(ptr, "duvw"));
    p[n] = c[n].p;
  }
  ctx.parsed();
  return blended_volume("hermite_volume", at("/corners", [&] { return hermite_volume(c); }),
                        {volume_corner_data(p, "/corners")}, nlohmann::ordered_json::object());
}

Construction build_coons_volume(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "faces", "blending", "cross_derivatives", "tolerance"}, ctx);
  static constexpr const char* names[6] = {"u0", "u1", "v0", "v1", "w0", "w1"};
  constexpr std::string_view expected = "an object {\"u0\", \"u1\", \"v0\", \"v1\", \"w0\", \"w1\"} of surface specs";
  const json& fj = member(spec, "faces", "", expected);
  expect_object(fj, "/faces", expected);
  check_fields(fj, "/faces", {"u0", "u1", "v0", "v1", "w0", "w1"}, ctx);
  std::vector<BSplineSurface> f;
  for (const char* n : names) f.push_back(face_surface(member(fj, n, "/faces", "a surface spec"), child("/faces", n), ctx));
  const VolumeFaces faces{f[0], f[1], f[2], f[3], f[4], f[5]};
  std::string blending = choice(spec, "blending", "", {"linear", "hermite"}, "linear");
  const std::optional<double> tol = tolerance_of(spec);
  std::vector<DataSet> data;
  for (std::size_t n = 0; n < 6; ++n) data.push_back(face_data(f[n], n / 2, static_cast<double>(n % 2), child("/faces", names[n])));
  if (const json* x = find_member(spec, "cross_derivatives")) {
    constexpr std::string_view cexpected = "an object with any of \"u0\", \"u1\", \"v0\", \"v1\", \"w0\", \"w1\": surface specs";
    expect_object(*x, "/cross_derivatives", cexpected);
    check_fields(*x, "/cross_derivatives", {"u0", "u1", "v0", "v1", "w0", "w1"}, ctx);
    VolumeCrossDerivatives cross;
    std::optional<BSplineSurface>* slots[6] = {&cross.u0, &cross.u1, &cross.v0, &cross.v1, &cross.w0, &cross.w1};
    nlohmann::ordered_json given = nlohmann::ordered_json::array();
    for (std::size_t n = 0; n < 6; ++n)
      if (const json* s = find_member(*x, names[n])) {
        *slots[n] = face_surface(*s, child("/cross_derivatives", names[n]), ctx);
        given.push_back(names[n]);
      }
    if (blending == "linear" && find_member(spec, "blending"))
      ctx.warn("/blending: \"linear\" ignored with \"cross_derivatives\" (the volume is Hermite-blended)");
    HermiteCoonsVolumeOptions o;
    o.tolerance = tol;
    ctx.parsed();
    nlohmann::ordered_json parameters = {{"blending", "hermite"}, {"cross_derivatives", given}};
    return blended_volume("coons_volume", at("", [&] { return coons_volume(faces, cross, o); }), std::move(data),
                          std::move(parameters));
  }
  CoonsVolumeOptions o;
  o.tolerance = tol;
  if (blending == "hermite") o.blend_u = o.blend_v = o.blend_w = Blend::hermite();
  ctx.parsed();
  nlohmann::ordered_json parameters = {{"blending", blending}};
  return blended_volume("coons_volume", at("/faces", [&] { return coons_volume(faces, o); }), std::move(data),
                        std::move(parameters));
}

Construction build_interpolate_volume(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "points", "degree", "param"}, ctx);
  PointArray pts =
      points_impl(member(spec, "points", "", "a volume grid of points, (n+1) x (m+1) x (l+1) x 3"), 3, "/points", ctx);
  const auto degree = degrees(spec, "", 3);
  const Parametrization param = parametrization(spec, "");
  const std::size_t nu = pts.shape[0], nv = pts.shape[1], nw = pts.shape[2];
  const std::string shape = cat(nu, "x", nv, "x", nw);
  for (std::size_t a = 0; a < 3; ++a) {
    const std::size_t count = pts.shape[a];
    if (count < 2)
      fail(errc::too_few_points, "/points: the grid has ", count, " point", count == 1 ? "" : "s", " along ", axis_name(a),
           " (shape ", shape, "); interpolation needs at least 2");
    if (degree[a] && static_cast<std::size_t>(*degree[a]) >= count)
      fail(errc::too_few_points, degree_pointer(spec, "", a), ": degree ", *degree[a], " along ", axis_name(a),
           " needs at least ", *degree[a] + 1, " points, /points has ", count, " (shape ", shape, ")");
  }
  PointGrid3 grid({nu, nv, nw}, std::move(pts.points));
  DataSet data;
  data.pointer = "/points";
  if (ctx.keep_data) {
    require_memory(grid.size(), sizeof(Vec3), cat("/points: a copy of the ", shape, " data points for the error check"));
    data.points.assign(grid.values().begin(), grid.values().end());
  }

  VolumeInterpolationOptions options;
  options.degree_u = degree[0];
  options.degree_v = degree[1];
  options.degree_w = degree[2];
  options.param = param;
  options.progress = ctx.progress;
  ctx.parsed();
  VolumeInterpolation r = at("/points", [&] { return interpolate_volume(std::move(grid), options); });
  const auto dom = r.volume.domain();
  data.params = {to_unit(std::move(r.params_u), dom[0]), to_unit(std::move(r.params_v), dom[1]),
                 to_unit(std::move(r.params_w), dom[2])};
  BSplineVolume v = on_unit_domain(std::move(r.volume));
  nlohmann::ordered_json parameters = {{"grid", {nu, nv, nw}},
                                       {"degree", {v.degree_u(), v.degree_v(), v.degree_w()}},
                                       {"param", param_name(param)}};
  Construction c;
  c.type = "interpolate_volume";
  c.exact = std::move(v);
  c.parameters = std::move(parameters);
  if (ctx.keep_data) c.data.push_back(std::move(data));
  return c;
}

Construction build_bspline_volume(const json& spec, Context& ctx) {
  check_fields(spec, "", {"type", "degree", "knots", "control_points", "weights"}, ctx);
  member(spec, "degree", "", "an integer degree or [p, q, r]");
  const auto degree = degrees(spec, "", 3);
  constexpr std::string_view kexpected = "an object {\"u\": [...], \"v\": [...], \"w\": [...]}";
  const json& knots = member(spec, "knots", "", kexpected);
  expect_object(knots, "/knots", kexpected);
  check_fields(knots, "/knots", {"u", "v", "w"}, ctx);
  std::vector<double> kv[3];
  for (std::size_t a = 0; a < 3; ++a)
    kv[a] = numbers(member(knots, axis_name(a), "/knots", "an array of knots"), child("/knots", axis_name(a)));
  PointArray cp = points_impl(member(spec, "control_points", "", "a grid of control points, (n+1) x (m+1) x (l+1) x 3"),
                              3, "/control_points", ctx);
  const std::string shape = cat(cp.shape[0], "x", cp.shape[1], "x", cp.shape[2]);
  Grid<double, 3> weights;
  if (const json* w = find_member(spec, "weights")) {
    weights = inline_number_grid<3>(*w, "/weights");
    if (weights.extent(0) != cp.shape[0] || weights.extent(1) != cp.shape[1] || weights.extent(2) != cp.shape[2])
      fail(errc::size_mismatch, "/weights: shape ", weights.extent(0), "x", weights.extent(1), "x", weights.extent(2),
           " differs from /control_points, ", shape);
    for (std::size_t i = 0; i < weights.extent(0); ++i)
      for (std::size_t j = 0; j < weights.extent(1); ++j)
        for (std::size_t k = 0; k < weights.extent(2); ++k)
          if (!(weights(i, j, k) > 0))
            fail(errc::invalid_weight, "/weights/", i, "/", j, "/", k, ": weight ", weights(i, j, k), " is not positive");
  }
  std::vector<KnotVector> k;
  for (std::size_t a = 0; a < 3; ++a)
    k.push_back(at(child("/knots", axis_name(a)), [&] { return KnotVector(*degree[a], std::move(kv[a])); }));
  for (std::size_t a = 0; a < 3; ++a)
    if (static_cast<std::size_t>(k[a].count()) != cp.shape[a])
      fail(errc::size_mismatch, "/control_points: ", cp.shape[a], " control points along ", axis_name(a), " (shape ",
           shape, "), but the ", k[a].size(), " knots of degree ", k[a].degree(), " in /knots/", axis_name(a), " need ",
           k[a].count());
  ctx.parsed();
  BSplineVolume v = at("/control_points", [&] {
    return BSplineVolume(std::move(k[0]), std::move(k[1]), std::move(k[2]),
                         PointGrid3({cp.shape[0], cp.shape[1], cp.shape[2]}, std::move(cp.points)), std::move(weights));
  });
  const auto d = v.domain();
  nlohmann::ordered_json parameters = {
      {"domain", {{"u", {d[0].first, d[0].second}}, {"v", {d[1].first, d[1].second}}, {"w", {d[2].first, d[2].second}}}}};
  Construction c;
  c.type = "bspline_volume";
  c.exact = on_unit_domain(std::move(v));
  c.parameters = std::move(parameters);
  return c;
}

struct ConstructionType {
  std::string_view name;
  Construction (*build)(const json& spec, Context& ctx);
  int dims;  // 2: a surface, 3: a volume
};

// Adding a construction: one function above, one line here.
constexpr ConstructionType construction_types[] = {
    {"bilinear", build_bilinear, 2},
    {"ruled", build_ruled, 2},
    {"coons", build_coons, 2},
    {"network", build_network, 2},
    {"interpolate", build_interpolate, 2},
    {"hermite_patch", build_hermite_patch, 2},
    {"bspline_surface", build_bspline_surface, 2},
    {"trilinear", build_trilinear, 3},
    {"coons_volume", build_coons_volume, 3},
    {"hermite_volume", build_hermite_volume, 3},
    {"interpolate_volume", build_interpolate_volume, 3},
    {"bspline_volume", build_bspline_volume, 3},
};

// A message of a nested spec, whose places are pointers from the nested object,
// placed under `ptr`: "/points/3: ..." becomes "/faces/u1/points/3: ...".
std::string rebased(std::string_view message, std::string_view ptr) {
  constexpr std::string_view top = "(top level)";
  if (message.substr(0, top.size()) == top) return cat(ptr, message.substr(top.size()));
  if (!message.empty() && message[0] == '/') return cat(ptr, message);
  return cat(ptr, ": ", message);
}

// A surface spec inside a volume spec (a face, a cross-derivative field): built by
// the surface constructions, used by its exact form over [0, 1]².
BSplineSurface face_surface(const json& j, const std::string& ptr, Context& ctx) {
  std::string surfaces;
  for (const auto& t : construction_types)
    if (t.dims == 2) surfaces += cat(surfaces.empty() ? "" : ", ", t.name);
  if (!j.is_object()) wrong_type(ptr, cat("a surface spec: an object with a \"type\", one of ", surfaces), j);
  const json& t = member(j, "type", ptr, cat("a string, one of ", surfaces));
  if (!t.is_string()) wrong_type(child(ptr, "type"), cat("a string, one of ", surfaces), t);
  const auto& name = t.get_ref<const std::string&>();
  const auto it = std::find_if(std::begin(construction_types), std::end(construction_types),
                               [&](const ConstructionType& c) { return c.name == name; });
  if (it == std::end(construction_types) || it->dims != 2)
    fail(errc::unknown_type, child(ptr, "type"), ": \"", name, "\" is not a surface type; a face takes one of ", surfaces);
  Context sub;
  sub.base_dir = ctx.base_dir;
  Construction c;
  try {
    c = it->build(j, sub);
  } catch (const error& e) {
    throw error(e.code(), rebased(e.what(), ptr));
  }
  for (const std::string& w : sub.warnings) ctx.warn(rebased(w, ptr));
  if (!c.exact)
    fail(errc::no_exact_form, place(ptr), ": the ", name, " surface has no exact B-spline form (", c.no_exact_form,
         "); a face needs one");
  return std::get<BSplineSurface>(*c.exact);
}

std::string type_list() {
  std::string s;
  for (const auto& t : construction_types) s += cat(s.empty() ? "" : ", ", t.name);
  return s;
}

Construction build_impl(const json& spec, Context& ctx) {
  if (!spec.is_object())
    fail(errc::wrong_type, "(top level): the spec must be a JSON object with a \"type\", got ", kind(spec));
  const json& t = member(spec, "type", "", cat("a string, one of ", type_list()));
  if (!t.is_string()) wrong_type("/type", cat("a string, one of ", type_list()), t);
  const auto& name = t.get_ref<const std::string&>();
  const auto it = std::find_if(std::begin(construction_types), std::end(construction_types),
                               [&](const ConstructionType& c) { return c.name == name; });
  if (it == std::end(construction_types))
    fail(errc::unknown_type, "/type: unknown type \"", name, "\"; known types: ", type_list());
  Construction c = it->build(spec, ctx);
  const auto done = Clock::now();
  const auto parsed = ctx.parsed_at.value_or(done);
  c.type = name;
  c.warnings = std::move(ctx.warnings);
  c.timings.parse_ms = ms_between(ctx.start, parsed);
  c.timings.build_ms = ms_between(parsed, done);
  return c;
}

std::pair<std::size_t, std::size_t> line_column(std::string_view text, std::size_t pos) {
  pos = std::min(pos, text.size());
  std::size_t line = 1, start = 0;
  for (std::size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') {
      ++line;
      start = i + 1;
    }
  return {line, pos - start + 1};
}

}  // namespace

std::vector<std::string_view> known_types() {
  std::vector<std::string_view> v;
  for (const auto& t : construction_types) v.push_back(t.name);
  return v;
}

json parse_json(std::string_view text, std::string_view source) {
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the last character read.
    std::size_t pos = e.byte == 0 ? 0 : std::min<std::size_t>(e.byte - 1, text.size());
    // A literal the lexer stopped in: back up to where the word starts.
    std::size_t start = pos;
    while (start > 0 && std::isalpha(static_cast<unsigned char>(text[start - 1]))) --start;
    std::size_t end = start;
    while (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) ++end;
    const std::string_view word = text.substr(start, end - start);
    if (word == "NaN" || word == "nan" || word == "Infinity" || word == "inf" || word == "infinity" || word == "Inf") {
      const bool minus = start > 0 && text[start - 1] == '-';
      const auto [line, col] = line_column(text, minus ? start - 1 : start);
      fail(errc::not_finite, source, ":", line, ":", col, ": ", minus ? "-" : "", word,
           " is not a JSON number; coordinates, knots and weights must be finite");
    }
    const auto [line, col] = line_column(text, pos);
    std::string what = e.what();
    // Keep nlohmann's description, drop its prefix with its own position.
    if (const auto c = what.find("column "); c != std::string::npos)
      if (const auto colon = what.find(": ", c); colon != std::string::npos) what = what.substr(colon + 2);
    fail(errc::invalid_json, source, ":", line, ":", col, ": invalid JSON: ", what);
  } catch (const json::out_of_range& e) {
    // A number beyond the range of double (1e999); nlohmann names the token only.
    const std::string what = e.what();
    std::string token;
    if (const auto q = what.find('\''); q != std::string::npos)
      if (const auto q2 = what.find('\'', q + 1); q2 != std::string::npos) token = what.substr(q + 1, q2 - q - 1);
    const std::size_t pos = token.empty() ? std::string_view::npos : text.find(token);
    if (pos == std::string_view::npos) fail(errc::not_finite, source, ": a number is too large for a double");
    const auto [line, col] = line_column(text, pos);
    fail(errc::not_finite, source, ":", line, ":", col, ": number ", token, " is too large for a double");
  }
}

json read_json_file(const std::filesystem::path& path) {
  std::error_code ec;
  const std::string name = path.string();
  if (!std::filesystem::exists(path, ec)) fail(errc::file_unreadable, name, ": cannot read: no such file");
  if (std::filesystem::is_directory(path, ec)) fail(errc::file_unreadable, name, ": cannot read: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(errc::file_unreadable, name, ": cannot open: ", std::strerror(errno));
  const auto size = std::filesystem::file_size(path, ec);
  // The parsed document takes a few times the text; refuse what cannot fit.
  if (!ec) require_memory(static_cast<std::size_t>(size), 4, cat(name, ": a JSON spec of ", size, " bytes"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) fail(errc::file_unreadable, name, ": read error: ", std::strerror(errno));
  return parse_json(text, name);
}

bool is_volume(const Construction& c) noexcept {
  return c.exact ? std::holds_alternative<BSplineVolume>(*c.exact) : c.volume_formula != nullptr;
}

const Surface& evaluator(const Construction& c) {
  if (is_volume(c)) fail(errc::wrong_type, c.type, ": the construction is a volume, not a surface");
  if (c.exact) return std::get<BSplineSurface>(*c.exact);
  if (!c.formula) fail(errc::internal, c.type, ": the construction has neither an exact form nor a formula");
  return *c.formula;
}

const Volume& volume_evaluator(const Construction& c) {
  if (!is_volume(c)) fail(errc::wrong_type, c.type, ": the construction is a surface, not a volume");
  if (c.exact) return std::get<BSplineVolume>(*c.exact);
  return *c.volume_formula;
}

Construction build(const json& spec, const std::filesystem::path& base_dir, const progress_callback& progress,
                   bool keep_data) {
  Context ctx;
  ctx.base_dir = base_dir;
  ctx.progress = progress;
  ctx.keep_data = keep_data;
  return build_impl(spec, ctx);
}

Construction build_file(const std::filesystem::path& spec_path, const progress_callback& progress, bool keep_data) {
  Context ctx;  // starts the clock: reading the file counts as parsing
  const json spec = read_json_file(spec_path);
  ctx.base_dir = spec_path.parent_path();
  ctx.progress = progress;
  ctx.keep_data = keep_data;
  return build_impl(spec, ctx);
}

PointArray points_from_json(const json& j, std::size_t rank, const std::filesystem::path& base_dir, std::string_view pointer) {
  if (rank < 1 || rank > 3) fail(errc::internal, "points_from_json: rank ", rank, " is outside 1..3");
  Context ctx;
  ctx.base_dir = base_dir;
  return points_impl(j, rank, pointer, ctx);
}

BSplineCurve curve_from_json(const json& j, const std::filesystem::path& base_dir, std::string_view pointer) {
  Context ctx;
  ctx.base_dir = base_dir;
  return curve_impl(j, pointer, ctx);
}

}  // namespace interpatch::io
