// Point arrays in a spec: nested lists, {"npy": file} and {"csv": file, "shape"}.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "base/parallel.hpp"
#include "interpatch/io/csv.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/memory.hpp"
#include "io/npy_format.hpp"
#include "io/spec/reader.hpp"
#include "io/spec/forms.hpp"

namespace interpatch::io::reader {

namespace {

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
PointArray inline_points(const json& j, std::size_t rank, std::string_view ptr, bool missing_allowed) {
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
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  out.shape = walk_grid(j, rank, 1, true, ptr, idx, [&](const json& node) {
    if (!node.is_array()) fail(errc::wrong_type, place(index_pointer(ptr, idx, rank)), ": expected a point [x, y, z], got ", kind(node));
    if (node.size() != 3)
      fail(errc::ragged_grid, place(index_pointer(ptr, idx, rank)), ": a point must be 3 numbers [x, y, z], got ",
           node.size(), node.size() == 1 ? " entry" : " entries");
    Vec3 p;
    for (int k = 0; k < 3; ++k) {
      const json& c = node[static_cast<std::size_t>(k)];
      idx[rank] = static_cast<std::size_t>(k);
      if (missing_allowed && c.is_null()) {  // a missing coordinate: the point is missing
        p[k] = nan;
        continue;
      }
      if (!c.is_number())
        fail(errc::wrong_type, place(index_pointer(ptr, idx, rank + 1)), ": expected a number (coordinate ", coord_name(k),
             "), got ", kind(c));
      p[k] = c.get<double>();
      if (!std::isfinite(p[k]))
        fail(errc::not_finite, place(index_pointer(ptr, idx, rank + 1)), ": coordinate ", coord_name(k), " is ", p[k]);
    }
    idx[rank] = 0;
    out.points.push_back(p);
  });
  return out;
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
                         const std::string& file, bool missing_allowed) {
  check_finite_block(shape, points, 0, ptr, file, missing_allowed);
}

PointArray npy_points(const json& obj, std::size_t rank, std::string_view ptr, Context& ctx, bool missing_allowed) {
  check_fields(obj, ptr, forms::npy, ctx);
  const std::string file = file_name(obj, "npy", ptr);
  // The values land in the point storage itself: float64 triples in C order are
  // exactly a grid of Vec3.
  static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are read as triples of doubles");
  PointArray out;
  // Each piece is looked at for NaN and infinities as it is read; the points are
  // scanned again, to find and name the first, only when a piece has one or the
  // file was not read in pieces.
  std::atomic<bool> piece_not_finite{false};
  std::atomic<std::size_t> bytes_seen{0};
  const internal::PieceVisitor visit = [&](const char* bytes, std::size_t n) {
    if (detail::has_non_finite(reinterpret_cast<const double*>(bytes), n / sizeof(double)))
      piece_not_finite.store(true, std::memory_order_relaxed);
    bytes_seen.fetch_add(n, std::memory_order_relaxed);
  };
  const std::vector<std::size_t> full = at(ptr, [&] {
    return internal::read_npy_visiting(ctx.resolve(file), [&](std::span<const std::size_t> shape, std::size_t count) {
      const std::vector<std::size_t> s(shape.begin(), shape.end());
      if (s.size() != rank + 1 || s.back() != 3)
        fail(errc::size_mismatch, file, " has shape ", shape_text(s), "; expected ", expected_shape(rank), ", ",
             rank == 1 ? "a list" : cat("a ", rank, "-D grid"), " of 3-vectors");
      for (std::size_t ax = 0; ax + 1 < s.size(); ++ax)
        if (s[ax] == 0) fail(errc::too_few_points, file, " has shape ", shape_text(s), ", no points");
      resize_for_overwrite(out.points, count / 3);
      return &out.points.data()->x;
    }, visit);
  });
  out.shape.assign(full.begin(), full.end() - 1);
  if (piece_not_finite.load() || bytes_seen.load() != out.points.size() * sizeof(Vec3))
    check_finite_points(out.shape, out.points, ptr, file, missing_allowed);
  return out;
}

PointArray csv_points(const json& obj, std::size_t rank, std::string_view ptr, Context& ctx, bool missing_allowed) {
  check_fields(obj, ptr, forms::csv, ctx);
  const std::string file = file_name(obj, "csv", ptr);
  const std::string sptr = child(ptr, "shape");
  const json& sj = member(obj, "shape", ptr, cat("the grid shape, e.g. ", expected_shape(rank)));
  if (!sj.is_array()) wrong_type(sptr, cat("an array of ", rank, " extents (a trailing 3 may follow)"), sj);
  std::vector<std::size_t> shape;
  for (std::size_t i = 0; i < sj.size(); ++i) {
    const std::int64_t e = integer(sj[i], child(sptr, i), "an integer extent");
    if (e < 1) fail(errc::too_few_points, place(child(sptr, i)), ": extent ", e, " is below 1");
    shape.push_back(static_cast<std::size_t>(e));
  }
  if (shape.size() == rank + 1 && shape.back() == 3) shape.pop_back();
  if (shape.size() != rank)
    fail(errc::size_mismatch, place(sptr), ": shape ", shape_text(shape), " does not describe ", grid_form(rank, true),
         "; expected [", rank == 1 ? "n" : (rank == 2 ? "n, m" : "n, m, l"), "] or [", rank == 1 ? "n" : (rank == 2 ? "n, m" : "n, m, l"),
         ", 3]");
  const std::size_t n = checked_product(shape, sptr);
  require_memory(n, sizeof(Vec3), cat(place(ptr), ": ", n, " points from ", file));
  const std::vector<Vec3> pts = at(ptr, [&] { return read_csv_points(ctx.resolve(file), n, missing_allowed); });
  if (pts.size() != n)
    fail(errc::size_mismatch, place(ptr), ": ", file, " has ", pts.size(), " points, shape ", shape_text(shape), " needs ", n);
  for (std::size_t i = 0; i < n; ++i)
    if (!is_finite(pts[i]) && !(missing_allowed && !std::isinf(pts[i].x) && !std::isinf(pts[i].y) && !std::isinf(pts[i].z)))
      fail(errc::not_finite, place(ptr), ": ", file, " point ", i, " is ", pts[i]);
  return {shape, PointStorage(pts.begin(), pts.end())};
}

}  // namespace

// {"array": NAME}: a point array the caller holds in memory (BuildOptions::arrays).
PointArray memory_points(const json& obj, std::size_t rank, std::string_view ptr, Context& ctx, bool missing_allowed) {
  check_fields(obj, ptr, forms::array, ctx);
  const std::string aptr = child(ptr, "array");
  const json& name = obj.at("array");
  if (!name.is_string()) wrong_type(aptr, "the name of an array given with the spec", name);
  const std::shared_ptr<PointArray>* given = nullptr;
  if (ctx.arrays)
    if (const auto it = ctx.arrays->find(name.get<std::string>()); it != ctx.arrays->end() && it->second) given = &it->second;
  if (!given) fail(errc::missing_field, place(aptr), ": no array named \"", name.get<std::string>(), "\" was given with the spec");
  const PointArray& a = **given;
  if (a.shape.size() != rank)
    fail(errc::size_mismatch, place(ptr), ": the array has shape ", shape_text(a.shape), " (and 3 per point); expected ",
         expected_shape(rank));
  for (std::size_t s : a.shape)
    if (s == 0) fail(errc::too_few_points, place(ptr), ": the array has shape ", shape_text(a.shape), ", no points");
  if (!a.finite) check_finite_points(a.shape, a.points, ptr, "the array", missing_allowed);
  // Named once and held by nobody else (BuildOptions::arrays): taken, not copied.
  const auto uses = ctx.array_uses.find(name.get<std::string>());
  if (given->use_count() == 1 && uses != ctx.array_uses.end() && uses->second == 1) return std::move(**given);
  return a;
}

PointArray points_impl(const json& j, std::size_t rank, std::string_view ptr, Context& ctx, bool missing_allowed) {
  if (j.is_object() && j.contains("array")) {
    // One way to give a field: a file beside the array would be silently ignored.
    for (const char* file : {"npy", "csv"})
      if (j.contains(file)) fail(errc::wrong_type, place(ptr), ": give either \"array\" or \"", file, "\", not both");
    return memory_points(j, rank, ptr, ctx, missing_allowed);
  }
  if (j.is_object()) {
    const bool npy = j.contains("npy"), csv = j.contains("csv");
    if (npy && csv) fail(errc::wrong_type, place(ptr), ": give either \"npy\" or \"csv\", not both");
    if (npy) return npy_points(j, rank, ptr, ctx, missing_allowed);
    if (csv) return csv_points(j, rank, ptr, ctx, missing_allowed);
    fail(errc::missing_field, place(ptr), ": a point array given as an object needs \"npy\": file or \"csv\": file with \"shape\"");
  }
  return inline_points(j, rank, ptr, missing_allowed);
}

std::size_t point_array_rank(const json& j, Context& ctx) {
  if (j.is_array()) {
    std::size_t depth = 0;
    for (const json* node = &j; node->is_array() && !node->empty(); node = &(*node)[0]) ++depth;
    return depth > 0 ? depth - 1 : 0;
  }
  if (!j.is_object()) return 0;
  if (const json* a = find_member(j, "array"); a && a->is_string() && ctx.arrays) {
    const auto it = ctx.arrays->find(a->get<std::string>());
    return it != ctx.arrays->end() && it->second ? it->second->shape.size() : 0;
  }
  if (const json* sh = find_member(j, "shape"); sh && sh->is_array() && find_member(j, "csv")) {
    const std::size_t n = sh->size();
    return n > 1 && sh->back() == 3 ? n - 1 : n;
  }
  const json* npy = find_member(j, "npy");
  if (!npy || !npy->is_string()) return 0;
  try {
    std::ifstream in(ctx.resolve(npy->get<std::string>()), std::ios::binary);
    in.seekg(0, std::ios::end);
    const auto size = static_cast<std::uint64_t>(in.tellg());
    in.seekg(0);
    const internal::NpyHeader h = internal::read_npy_header(in, size, npy->get<std::string>());
    return h.shape.size() > 1 && h.shape.back() == 3 ? h.shape.size() - 1 : 0;
  } catch (const std::exception&) {
    return 0;  // unreadable: the reader of the points names the problem
  }
}

DataSet grid_data(const json& points_spec, std::span<const Vec3> points, std::span<const std::size_t> shape,
                  const Context& ctx) {
  DataSet data;
  data.pointer = "/points";
  if (!ctx.keep_data) return data;
  if (ctx.borrow_arrays && points_spec.is_object() && points_spec.contains("array")) {
    data.array = points_spec.at("array").get<std::string>();  // a string: memory_points checked it
    return data;
  }
  require_memory(points.size(), sizeof(Vec3),
                 cat("/points: a copy of the ", extents_text(shape), " data points for the error check"));
  data.points.assign(points.begin(), points.end());
  return data;
}

PointArray interpolation_points(const json& j, std::size_t rank, std::string_view ptr, Context& ctx) {
  try {
    return points_impl(j, rank, ptr, ctx);
  } catch (const error& e) {
    rethrow_for_interpolation(e);
  }
}

void rethrow_for_interpolation(const error& e) {
  const std::string_view m = e.what();
  const bool nan = e.code() == errc::not_finite && (m.find(" is nan") != m.npos || m.find(" is -nan") != m.npos ||
                                                    m.find("nan,") != m.npos || m.find("'nan'") != m.npos);
  const bool null = e.code() == errc::wrong_type && m.ends_with("got null");
  if (!nan && !null) throw e;
  throw error(e.code(), cat(m, " (interpolation needs every point; \"type\": \"approximate\" takes missing points, ",
                            "NaN in a file or null in a list)"));
}

template <std::size_t Rank>
Grid<double, Rank> inline_number_grid(const json& j, std::string_view ptr) {
  std::vector<double> values;
  std::vector<std::size_t> idx;
  const auto shape = walk_grid(j, Rank, 0, false, ptr, idx, [&](const json& node) {
    if (!node.is_number()) fail(errc::wrong_type, place(index_pointer(ptr, idx, Rank)), ": expected a number, got ", kind(node));
    const double v = node.get<double>();
    if (!std::isfinite(v)) fail(errc::not_finite, place(index_pointer(ptr, idx, Rank)), ": value is ", v);
    values.push_back(v);
  });
  typename Grid<double, Rank>::shape_type sh{};
  for (std::size_t a = 0; a < Rank; ++a) sh[a] = shape[a];
  return Grid<double, Rank>(sh, std::move(values));
}

template Grid<double, 2> inline_number_grid<2>(const json& j, std::string_view ptr);
template Grid<double, 3> inline_number_grid<3>(const json& j, std::string_view ptr);

void check_finite_block(const std::vector<std::size_t>& shape, std::span<const Vec3> points, std::size_t first,
                        std::string_view ptr, const std::string& file, bool missing_allowed) {
  std::size_t i = interpatch::detail::first_non_finite(points.data(), points.size());
  if (missing_allowed)  // NaN marks a missing point; infinities are still refused
    for (; i < points.size(); ++i)
      if (std::isinf(points[i].x) || std::isinf(points[i].y) || std::isinf(points[i].z)) break;
  if (i < points.size()) {
    const Vec3& p = points[i];
    std::vector<std::size_t> idx(shape.size() + 1);
    std::size_t r = first + i;
    for (std::size_t a = shape.size(); a-- > 0;) {
      idx[a] = r % shape[a];
      r /= shape[a];
    }
    const auto bad = [&](double x) { return missing_allowed ? std::isinf(x) : !std::isfinite(x); };
    const int k = !bad(p.x) ? (!bad(p.y) ? 2 : 1) : 0;
    idx[shape.size()] = static_cast<std::size_t>(k);
    fail(errc::not_finite, place(index_pointer(ptr, idx, idx.size())), ": coordinate ", coord_name(k), " is ", p[k], " (in ",
         file, ")");
  }
}

}  // namespace interpatch::io::reader

namespace interpatch::io {

PointArray copy_point_array(const double* xyz, std::vector<std::size_t> shape) {
  PointArray out;
  const std::size_t count = reader::checked_product(shape, "a point array");
  require_memory(count, sizeof(Vec3), detail::cat("a copy of ", reader::extents_text(shape), " points"));
  out.shape = std::move(shape);
  resize_for_overwrite(out.points, count);
  // Pieces of 2^14 points (384 KiB) are copied and then scanned while they are still
  // in the core's cache; every core takes pieces.
  constexpr std::size_t piece = std::size_t{1} << 14;
  const auto pieces = static_cast<long long>((count + piece - 1) / piece);
  Vec3* dst = out.points.data();
  long long bad = pieces;
#pragma omp parallel for schedule(static) reduction(min : bad) if (count >= detail::parallel_min_work)
  for (long long k = 0; k < pieces; ++k) {
    const std::size_t first = static_cast<std::size_t>(k) * piece, n = std::min(piece, count - first);
    std::memcpy(static_cast<void*>(dst + first), xyz + 3 * first, n * sizeof(Vec3));
    if (detail::first_non_finite(dst + first, n) < n && k < bad) bad = k;
  }
  out.finite = bad == pieces;
  return out;
}

}  // namespace interpatch::io
