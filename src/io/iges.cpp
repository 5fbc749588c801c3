#include "interpatch/io/iges.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/exchange.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/atomic_file.hpp"

namespace interpatch::io {

namespace {

constexpr std::size_t line_data = 72;    // columns 1-72 of every line
constexpr std::size_t param_data = 64;   // columns 1-64 of a parameter line; 65-72 point back

// "nHtext": IGES's length-prefixed string; nothing (the default) when empty.
std::string hollerith(std::string_view s) {
  const std::string a = detail::printable_ascii(s);
  return a.empty() ? a : std::to_string(a.size()) + "H" + a;
}

// `s` right-justified in `width` columns, appended.
void append_right(std::string& out, std::string_view s, std::size_t width) {
  if (width > s.size()) out.append(width - s.size(), ' ');
  out += s;
}
void append_right(std::string& out, std::size_t v, std::size_t width) {
  char b[24];
  const auto r = std::to_chars(b, b + sizeof b, v);
  append_right(out, std::string_view(b, static_cast<std::size_t>(r.ptr - b)), width);
}
std::string right(std::size_t v, std::size_t width) {
  std::string s;
  append_right(s, v, width);
  return s;
}

// Lines of one section: columns 73-80 get the letter and the sequence number.
class Section {
 public:
  Section(std::ostream* os, char letter) : os_(os), letter_(letter) {}

  // Writes (or, without a stream, only counts) one line whose first 72 columns are `data`.
  void line(std::string_view data) {
    ++count_;
    if (!os_) return;
    buf_.assign(data);
    buf_.resize(line_data, ' ');
    buf_ += letter_;
    append_right(buf_, count_, 7);
    buf_ += '\n';
    os_->write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
  }
  [[nodiscard]] std::size_t count() const noexcept { return count_; }

 private:
  std::ostream* os_;
  char letter_;
  std::size_t count_ = 0;
  std::string buf_;
};

// Packs free-format parameters into lines of `width` columns, never splitting a
// parameter: each is followed by its delimiter (',' or, after the last, ';').
class Packer {
 public:
  Packer(Section& section, std::size_t width, std::string suffix = {})
      : section_(section), width_(width), suffix_(std::move(suffix)) {}

  void put(std::string_view token, bool last = false) {
    if (!cur_.empty() && cur_.size() + token.size() + 1 > width_) emit();
    // A Hollerith string longer than a line is the one thing that may be split.
    while (token.size() + 1 > width_) {
      cur_.assign(token.substr(0, width_));
      token.remove_prefix(width_);
      emit();
    }
    cur_ += token;
    cur_ += last ? ';' : ',';
    if (last) emit();
  }
  void put(double v, bool last = false) {
    number_.clear();
    detail::append_real(number_, v);
    put(number_, last);
  }
  void put_int(long long v, bool last = false) { put(std::to_string(v), last); }

 private:
  void emit() {
    cur_.resize(width_, ' ');
    cur_ += suffix_;
    section_.line(cur_);
    cur_.clear();
  }

  Section& section_;
  std::size_t width_;
  std::string suffix_;
  std::string cur_, number_;
};

// Entity 128's parameters (IGES 5.3, section 4.24): counts, degrees, flags, both
// knot vectors, weights and control points with the u index fastest, parameter range.
// The surface is the face's clamped form (IGES lists every knot, the ends p+1
// times); a direction that was periodic is flagged closed (PROP1/PROP2) and
// periodic (PROP4/PROP5).
void put_surface(Packer& p, const detail::Face& f, double tol) {
  const BSplineSurface& s = f.surface;
  const auto& cp = s.control_points();
  const std::size_t n = cp.extent(0), m = cp.extent(1);
  p.put_int(128);
  p.put_int(static_cast<long long>(n) - 1);
  p.put_int(static_cast<long long>(m) - 1);
  p.put_int(s.degree_u());
  p.put_int(s.degree_v());
  p.put_int(detail::closed(f, 0, tol) ? 1 : 0);
  p.put_int(detail::closed(f, 1, tol) ? 1 : 0);
  p.put_int(s.rational() ? 0 : 1);  // PROP3: 1 = polynomial
  p.put_int(f.periodic[0] ? 1 : 0);  // PROP4: periodic in u
  p.put_int(f.periodic[1] ? 1 : 0);  // PROP5: periodic in v
  for (const double k : s.knots_u().values()) p.put(k);
  for (const double k : s.knots_v().values()) p.put(k);
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t i = 0; i < n; ++i) p.put(s.rational() ? s.weights()(i, j) : 1.0);
  for (std::size_t j = 0; j < m; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      p.put(cp(i, j).x);
      p.put(cp(i, j).y);
      p.put(cp(i, j).z);
    }
  p.put(s.domain_u().first);
  p.put(s.domain_u().second);
  p.put(s.domain_v().first);
  p.put(s.domain_v().second, true);
}

// Entity 126's parameters (IGES 5.3, section 4.23): upper index, degree, flags, the
// knots, weights and control points, parameter range, and the plane's normal (none:
// PROP1 says the curve is not planar). The curve is clamped (IGES lists every knot);
// one that was periodic is flagged closed (PROP2) and periodic (PROP4).
void put_curve(Packer& p, const BSplineCurve& c, bool periodic) {
  const std::vector<Vec3>& cp = c.control_points();
  p.put_int(126);
  p.put_int(static_cast<long long>(cp.size()) - 1);
  p.put_int(c.degree());
  p.put_int(0);                      // PROP1: not declared planar
  p.put_int(periodic ? 1 : 0);       // PROP2: closed
  p.put_int(c.rational() ? 0 : 1);   // PROP3: 1 = polynomial
  p.put_int(periodic ? 1 : 0);       // PROP4: periodic
  for (const double k : c.knots().values()) p.put(k);
  for (std::size_t i = 0; i < cp.size(); ++i) p.put(c.rational() ? c.weights()[i] : 1.0);
  for (const Vec3& q : cp) {
    p.put(q.x);
    p.put(q.y);
    p.put(q.z);
  }
  p.put(c.domain().first);
  p.put(c.domain().second);
  for (int k = 0; k < 3; ++k) p.put(0.0, k == 2);  // no plane
}

std::string timestamp(const IgesOptions& o) {
  return o.time_stamp.empty() ? detail::utc_now("%Y%m%d.%H%M%S") : o.time_stamp;
}

// A file of `count` entities of type `type`, entity e's parameters put by put(p, e):
// the start section's two lines say what it holds, max_coord is the largest coordinate.
void write_file(std::ostream& os, const IgesOptions& options, int type, std::size_t count,
                const std::function<void(Packer&, std::size_t)>& put, double max_coord,
                std::string_view start1, std::string_view start2) {
  // The directory needs each entity's parameter line count: count them first.
  std::vector<std::size_t> param_lines;
  {
    Section counter(nullptr, 'P');
    for (std::size_t e = 0; e < count; ++e) {
      const std::size_t before = counter.count();
      Packer p(counter, param_data);
      put(p, e);
      param_lines.push_back(counter.count() - before);
    }
  }

  Section start(&os, 'S');
  start.line(start1);
  start.line(start2);

  const std::string when = timestamp(options);
  Section global(&os, 'G');
  {
    Packer g(global, line_data);
    g.put("1H,");
    g.put("1H;");
    g.put(hollerith(options.name));               // product id from the sender
    g.put(hollerith(options.name));               // file name
    g.put(hollerith("interpatch"));               // native system
    g.put(hollerith("interpatch IGES writer"));   // preprocessor version
    g.put_int(32);                                // bits in an integer
    g.put_int(38);                                // single precision: largest power of ten
    g.put_int(6);                                 //   and significant digits
    g.put_int(308);                               // double precision: largest power of ten
    g.put_int(17);                                //   and the digits written here
    g.put(hollerith(options.name));               // product id for the receiver
    g.put(1.0);                                   // model space scale
    g.put_int(2);                                 // unit flag: millimetres
    g.put("2HMM");
    g.put_int(1);                                 // line weight gradations
    g.put(1.0);                                   // maximum line width
    g.put(hollerith(when));                       // date and time of generation
    g.put(1e-7);                                  // resolution, the 1e-7 mm CAD systems use
    g.put(max_coord);                             // largest coordinate
    g.put(hollerith(""));                         // author
    g.put(hollerith(""));                         // organization
    g.put_int(11);                                // IGES 5.3
    g.put_int(0);                                 // no drafting standard
    g.put(hollerith(when), true);                 // model created or changed
  }

  Section directory(&os, 'D');
  std::size_t first_param = 1;
  for (std::size_t e = 0; e < count; ++e) {
    directory.line(right(type, 8) + right(first_param, 8) + right(0, 8) + right(0, 8) + right(0, 8) + right(0, 8) +
                   right(0, 8) + right(0, 8) + "00000000");
    directory.line(right(type, 8) + right(0, 8) + right(0, 8) + right(param_lines[e], 8) + right(0, 8) +
                   std::string(24, ' ') + right(0, 8));
    first_param += param_lines[e];
  }

  Section parameters(&os, 'P');
  for (std::size_t e = 0; e < count; ++e) {
    Packer p(parameters, param_data, " " + right(2 * e + 1, 7));  // back-pointer to the directory entry
    put(p, e);
  }

  Section terminate(&os, 'T');
  terminate.line("S" + right(start.count(), 7) + "G" + right(global.count(), 7) + "D" + right(directory.count(), 7) +
                 "P" + right(parameters.count(), 7));
  os.flush();
  if (!os) throw error(errc::file_unwritable, "IGES output: write failed");
}

double largest_coordinate(std::span<const Vec3> points, double max_coord = 0) {
  for (const Vec3& q : points) max_coord = std::max({max_coord, std::abs(q.x), std::abs(q.y), std::abs(q.z)});
  return max_coord;
}

}  // namespace

void write_iges(std::ostream& os, const ExactForm& exact, const IgesOptions& options) {
  const std::vector<detail::Face> faces = detail::faces_of(exact);
  const double tol = detail::coincidence_tolerance(faces);
  double max_coord = 0;
  for (const auto& f : faces) max_coord = largest_coordinate(f.surface.control_points().values(), max_coord);
  write_file(os, options, 128, faces.size(), [&](Packer& p, std::size_t e) { put_surface(p, faces[e], tol); }, max_coord,
             "interpatch: the exact B-spline form of a construction as rational",
             "B-spline surfaces (entity 128); lengths in millimetres.");
}

void write_iges(std::ostream& os, const BSplineCurve& curve, const IgesOptions& options) {
  const BSplineCurve c = curve.clamped();
  write_file(os, options, 126, 1, [&](Packer& p, std::size_t) { put_curve(p, c, curve.periodic()); },
             largest_coordinate(c.control_points()), "interpatch: a curve as a rational B-spline curve (entity 126);",
             "lengths in millimetres.");
}

void write_iges(const std::filesystem::path& path, const BSplineCurve& curve, const IgesOptions& options) {
  write_atomically(path, [&](std::ostream& os) { write_iges(os, curve, options); });
}

void write_iges(const std::filesystem::path& path, const ExactForm& exact, const IgesOptions& options) {
  write_atomically(path, [&](std::ostream& os) { write_iges(os, exact, options); });
}

}  // namespace interpatch::io
