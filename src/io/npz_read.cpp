// Reading the exact form from an .npz archive (npz_directory.cpp finds its
// members): each member's .npy array checked against its CRC-32 as it is read,
// then the shapes, degrees, knots and weights checked against one another.

#include "interpatch/io/npz.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <istream>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "base/excerpt.hpp"
#include "base/text.hpp"
#include "io/crc32.hpp"
#include "io/npy_format.hpp"
#include "io/npz_archive.hpp"
#include "io/npz_internal.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;
using detail::cat;
using detail::fail;

namespace {

using namespace internal::npz_io;

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

class Reader {
 public:
  Reader(const Source& src, std::string name) : src_(src), name_(std::move(name)) {}

  ExactForm read(std::size_t want_dims) {
    entries_ = read_directory(src_, name_);
    const std::vector<double> deg = read_degrees();
    const std::size_t dims = deg.size();
    if (want_dims != 0 && dims != want_dims)
      fail(errc::wrong_type, name_, " holds a ", dims == 3 ? "volume" : "surface", " (degree.npy has shape (", dims,
           ",)); bspline_surface reads the archive of a surface, bspline_volume that of a volume");
    if (dims == 2 && find("knots_w.npy"))
      fail(errc::size_mismatch, name_, ": knots_w.npy is the third direction of a volume, but degree.npy has shape (2,), a surface's");
    std::vector<int> degrees;
    for (std::size_t a = 0; a < dims; ++a) {
      if (!(deg[a] >= 1 && deg[a] <= max_degree))
        fail(errc::invalid_degree, name_, ": degree.npy: degree ", integer_text(deg[a]), " along ", axis_name(a),
             " is outside 1..", max_degree);
      degrees.push_back(static_cast<int>(deg[a]));
    }
    const std::vector<bool> periodic = read_periodic(dims);
    if (dims == 2) return read_form<2>(degrees, periodic);
    return read_form<3>(degrees, periodic);
  }

 private:
  template <class... A>
  [[noreturn]] void malformed(const A&... parts) const {
    internal::npz_io::malformed(name_, parts...);
  }

  static std::string integer_text(double v) {
    return std::fabs(v) < 1e18 ? std::to_string(static_cast<long long>(v)) : detail::num(v);
  }

  [[nodiscard]] const Entry* find(std::string_view member) const {
    for (const Entry& e : entries_)
      if (e.name == member) return &e;
    return nullptr;
  }

  const Entry& require(std::string_view member) const {
    if (const Entry* e = find(member)) return *e;
    std::string present;
    for (const Entry& e : entries_) present += (present.empty() ? "" : ", ") + e.name;
    malformed("no member '", member, "' (an exact form holds ", member_list, "; this archive holds ",
              present.empty() ? "none" : present, ")");
  }

  // One member as an .npy array of the dtype kind `kind` ('f': float, 'i': integer,
  // 'b': bool) into `destination`; its checksum checked. Returns the shape.
  std::vector<std::size_t> read_member(const Entry& e, char kind, const NpyDestination& destination) const {
    const std::string where = cat(name_, ": ", e.name);
    MemberBuffer buf(src_, e.data, e.size);
    std::istream in(&buf);
    const internal::NpyHeader h = internal::read_npy_header(in, e.size, where);
    const std::optional<internal::NpyDtype> dt = internal::parse_npy_dtype(h.descr);
    const char got = !dt ? '?' : (dt->kind == 'u' ? 'i' : dt->kind);
    if (got != kind)
      fail(errc::wrong_type, where, ": dtype '", detail::excerpt(h.descr, 40), "'; expected ",
           kind == 'f' ? "float64 (or float32)" : kind == 'i' ? "integers (int64)" : "bool");
    std::optional<std::uint32_t> crc;
    const std::vector<std::size_t> shape = internal::read_npy_data(
        in, h, e.size, where, destination,
        [&](char* dst, std::size_t n, std::uint64_t offset) {
          const std::uint32_t head = buf.checksum();
          std::uint32_t body = 0;
          src_.read_bulk(dst, n, e.data + offset, &body);
          crc = internal::crc32_combine(head, body, n);
        },
        kind != 'f');
    if (!crc) crc = buf.checksum();
    if (*crc != e.crc)
      fail(errc::malformed_file, where, ": CRC-32 of its ", e.size, " bytes is ", hex32(*crc), ", the archive records ",
           hex32(e.crc), ": the file is damaged");
    return shape;
  }

  // A short 1-D member (degree, periodic) of `dims` entries, or 2 or 3 when dims is 0.
  std::vector<double> read_vector(const Entry& e, char kind, std::size_t dims) const {
    std::vector<double> v;
    read_member(e, kind, [&](std::span<const std::size_t> shape, std::size_t count) {
      const bool fits = shape.size() == 1 && (dims != 0 ? shape[0] == dims : (shape[0] == 2 || shape[0] == 3));
      if (!fits)
        fail(errc::size_mismatch, name_, ": ", e.name, " has shape ", internal::npy_shape_text(shape), "; expected ",
             dims != 0 ? cat("(", dims, ",), one entry per direction") : std::string("(2,) (a surface) or (3,) (a volume)"));
      v.resize(count);
      return v.data();
    });
    return v;
  }

  std::vector<double> read_degrees() const { return read_vector(require("degree.npy"), 'i', 0); }

  // Which directions are closed; none without the member (an archive of numpy.savez).
  std::vector<bool> read_periodic(std::size_t dims) const {
    std::vector<bool> periodic(dims, false);
    if (const Entry* e = find("periodic.npy")) {
      const std::vector<double> flags = read_vector(*e, 'b', dims);
      for (std::size_t a = 0; a < dims; ++a) periodic[a] = flags[a] != 0;
    }
    return periodic;
  }

  // The knots of a closed direction are the extended ones (KnotVector::values()).
  template <std::size_t D>
  ExactForm read_form(const std::vector<int>& degrees, const std::vector<bool>& periodic) const {
    std::vector<KnotVector> knots;
    for (std::size_t a = 0; a < D; ++a) {
      const Entry& e = require(knots_member(a));
      std::vector<double> values;
      read_member(e, 'f', [&](std::span<const std::size_t> shape, std::size_t count) {
        if (shape.size() != 1)
          fail(errc::size_mismatch, name_, ": ", e.name, " has shape ", internal::npy_shape_text(shape),
               "; expected a 1-D array of knots");
        values.resize(count);
        return values.data();
      });
      knots.push_back(detail::prefixed(cat(name_, ": ", e.name), [&] {
        return periodic[a] ? KnotVector::periodic_from_extended(degrees[a], values) : KnotVector(degrees[a], std::move(values));
      }));
    }

    using Shape = typename Grid<Vec3, D>::shape_type;
    Shape shape{};
    for (std::size_t a = 0; a < D; ++a) shape[a] = static_cast<std::size_t>(knots[a].count());
    const auto expected = [&] {
      std::string s = "(";
      for (std::size_t a = 0; a < D; ++a) s += cat(shape[a], ", ");
      return s;
    };
    Grid<Vec3, D> points;
    const Entry& cp = require("control_points.npy");
    read_member(cp, 'f', [&](std::span<const std::size_t> s, std::size_t) {
      if (s.size() != D + 1 || s[D] != 3)
        fail(errc::size_mismatch, name_, ": control_points.npy has shape ", internal::npy_shape_text(s), "; expected ",
             D == 2 ? "(n, m, 3)" : "(n, m, l, 3)", ", the knots need ", expected(), "3)");
      for (std::size_t a = 0; a < D; ++a)
        if (s[a] != shape[a])
          fail(errc::size_mismatch, name_, ": control_points.npy has shape ", internal::npy_shape_text(s), ", but the ",
               knots[a].size(), knots[a].periodic() ? " periodic knots" : " knots", " of degree ", knots[a].degree(), " in ",
               knots_member(a), " need ", shape[a],
               " control points along ", axis_name(a), ", ", expected(), "3)");
      points = Grid<Vec3, D>(shape, for_overwrite);
      static_assert(sizeof(Vec3) == 3 * sizeof(double), "control points are read as triples of doubles");
      return &points.data()->x;
    });

    Grid<double, D> weights;
    if (const Entry* w = find("weights.npy")) {
      read_member(*w, 'f', [&](std::span<const std::size_t> s, std::size_t) {
        if (!std::equal(s.begin(), s.end(), shape.begin(), shape.end()))
          fail(errc::size_mismatch, name_, ": weights.npy has shape ", internal::npy_shape_text(s),
               "; the control points need one weight each, ", expected().substr(0, expected().size() - 2), ")");
        weights = Grid<double, D>(shape, for_overwrite);
        return weights.data();
      });
      check_weights(weights);
    }
    return detail::prefixed(cat(name_, ": control_points.npy"), [&]() -> ExactForm {
      if constexpr (D == 2) {
        return BSplineSurface(std::move(knots[0]), std::move(knots[1]), std::move(points), std::move(weights));
      } else {
        return BSplineVolume(std::move(knots[0]), std::move(knots[1]), std::move(knots[2]), std::move(points),
                             std::move(weights));
      }
    });
  }

  // The first weight that is not finite or not positive, named by its indices.
  template <std::size_t D>
  void check_weights(const Grid<double, D>& w) const {
    const auto* bad = std::find_if(w.data(), w.data() + w.size(), [](double x) { return !(std::isfinite(x) && x > 0); });
    if (bad == w.data() + w.size()) return;
    std::string index;
    for (std::size_t a = D, r = static_cast<std::size_t>(bad - w.data()); a-- > 0; r /= w.extent(a))
      index.insert(0, cat("[", r % w.extent(a), "]"));
    if (!std::isfinite(*bad)) fail(errc::not_finite, name_, ": weights.npy: weight ", index, " is ", *bad);
    fail(errc::invalid_weight, name_, ": weights.npy: weight ", index, " is ", *bad, "; weights must be positive");
  }

  const Source& src_;
  std::string name_;
  std::vector<Entry> entries_;
};

}  // namespace

namespace internal {

ExactForm read_exact_npz(const fs::path& path, std::size_t dims) {
  const FileSource src(path, path.string());
  return Reader(src, path.string()).read(dims);
}

}  // namespace internal

ExactForm read_exact_npz(const fs::path& path) { return internal::read_exact_npz(path, 0); }

ExactForm parse_exact_npz(std::string_view bytes, std::string_view name) {
  const MemorySource src(bytes);
  return Reader(src, std::string(name)).read(0);
}

}  // namespace interpatch::io
