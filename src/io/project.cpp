// interpatch project and intersect: points (rays) read a block at a time, answered on
// every thread, and written a block at a time into an .npz, .npy or .csv.

#include "interpatch/io/project.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "base/parallel.hpp"
#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/projection.hpp"
#include "io/extension.hpp"
#include "io/npy_format.hpp"
#include "io/npz_internal.hpp"
#include "io/row_reader.hpp"

namespace interpatch::io {

namespace fs = std::filesystem;
using detail::fail;

namespace {

// Points a block: 1.5 MB of input, a few of answers.
constexpr std::size_t block = std::size_t{1} << 16;

enum class Format { npz, npy, csv };

Format format_of(const fs::path& out) {
  const std::string ext = internal::lower_extension(out);
  if (ext == ".npz") return Format::npz;
  if (ext == ".npy") return Format::npy;
  if (ext == ".csv") return Format::csv;
  fail(errc::wrong_type, "'", out.string(), "': project and intersect write .npz, .npy or .csv");
}

// One answer, whatever was asked: parameters (k of them), the point, its distance.
struct Row {
  double p[3] = {0, 0, 0};
  Vec3 x;
  double d = 0;
  bool inside = false;
};

std::string text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return {buf, r.ptr};
}

// Where the rows go, in one of the three formats. `names` are the columns of the
// parameters; a volume adds `inside`.
class Sink {
 public:
  Sink(Format f, std::vector<std::size_t> shape, std::vector<std::string> names, bool volume)
      : f_(f), shape_(std::move(shape)), names_(std::move(names)), volume_(volume) {
    n_ = 1;
    for (const std::size_t e : shape_) n_ *= e;
    if (f_ == Format::npz) {
      const auto with = [&](std::size_t last) {
        auto s = shape_;
        if (last) s.push_back(last);
        return s;
      };
      std::vector<internal::NpzColumns::Member> m{{"params", "<f8", with(names_.size() > 1 ? names_.size() : 0)},
                                                  {"points", "<f8", with(3)},
                                                  {"distance", "<f8", with(0)}};
      if (volume_) m.push_back({"inside", "|b1", with(0)});
      npz_ = std::make_unique<internal::NpzColumns>(m);
    }
  }
  [[nodiscard]] std::uintmax_t size() const {
    if (f_ == Format::npz) return npz_->total();
    if (f_ == Format::npy) return header().size() + n_ * columns() * sizeof(double);
    return 0;
  }
  void begin(std::ostream& os) const {
    if (f_ == Format::npz) npz_->begin(os);
    if (f_ == Format::npy) os << header();
    if (f_ == Format::csv) {
      std::string h;
      for (const auto& n : names_) h += n + ",";
      os << h << "x,y,z,distance" << (volume_ ? ",inside" : "") << "\n";
    }
  }
  void write(std::ostream& os, const std::vector<Row>& rows) const {
    const std::size_t k = names_.size();
    if (f_ == Format::npz) {
      std::vector<double> p, x, d;
      std::vector<unsigned char> in;
      for (const Row& r : rows) {
        p.insert(p.end(), r.p, r.p + k);
        x.insert(x.end(), {r.x.x, r.x.y, r.x.z});
        d.push_back(r.d);
        in.push_back(r.inside ? 1 : 0);
      }
      npz_->append(os, 0, p.data(), p.size() * sizeof(double));
      npz_->append(os, 1, x.data(), x.size() * sizeof(double));
      npz_->append(os, 2, d.data(), d.size() * sizeof(double));
      if (volume_) npz_->append(os, 3, in.data(), in.size());
      return;
    }
    if (f_ == Format::npy) {
      std::vector<double> v;
      for (const Row& r : rows) {
        v.insert(v.end(), r.p, r.p + k);
        v.insert(v.end(), {r.x.x, r.x.y, r.x.z, r.d});
        if (volume_) v.push_back(r.inside ? 1 : 0);
      }
      internal::write_values(os, v.data(), v.size());
      return;
    }
    std::string s;
    for (const Row& r : rows) {
      for (std::size_t a = 0; a < k; ++a) s += text(r.p[a]) + ",";
      s += text(r.x.x) + "," + text(r.x.y) + "," + text(r.x.z) + "," + text(r.d);
      if (volume_) s += r.inside ? ",1" : ",0";
      s += "\n";
    }
    os << s;
  }
  void finish(std::ostream& os) const {
    if (f_ == Format::npz) npz_->finish(os);
  }

 private:
  [[nodiscard]] std::size_t columns() const { return names_.size() + 4 + (volume_ ? 1 : 0); }
  [[nodiscard]] std::string header() const {
    const std::size_t s[2] = {n_, columns()};
    return internal::npy_header("<f8", s);
  }
  Format f_;
  std::vector<std::size_t> shape_;
  std::vector<std::string> names_;
  bool volume_;
  std::size_t n_ = 0;
  std::unique_ptr<internal::NpzColumns> npz_;
};

// The points of a block as Vec3, each checked finite (naming its index in the file).
std::vector<Vec3> as_points(const std::vector<double>& b, std::size_t n, std::size_t first) {
  std::vector<Vec3> q(n);
  for (std::size_t i = 0; i < n; ++i) {
    q[i] = {b[3 * i], b[3 * i + 1], b[3 * i + 2]};
    if (!is_finite(q[i])) fail(errc::not_finite, "point ", first + i, " is ", detail::num(q[i]), ": every coordinate must be finite");
  }
  return q;
}

}  // namespace

std::unique_ptr<SurfaceProjector> surface_projector(Construction& c, const progress_callback& progress) {
  if (has_exact_form_after_conversion(c, progress)) {
    const auto& s = std::get<BSplineSurface>(exact_form(c, progress));
    return std::make_unique<SurfaceProjector>(s, s);
  }
  // No exact form (Gregory's twists): searched through a stand-in, answered by the formula.
  if (c.formula) return std::make_unique<SurfaceProjector>(*c.formula);
  (void)exact_form(c, progress);  // says why there is none
  fail(errc::no_exact_form, c.type, ": neither an exact form nor a formula to search");
}

void check_projection_output(const fs::path& out) { (void)format_of(out); }

ProjectionSummary write_projection(Built& built, const fs::path& points, const fs::path& out,
                                   const progress_callback& progress) {
  const Format f = format_of(out);
  check_writable(out);
  internal::RowReader reader(points, 3, "points");
  // The question asked of a block of points, by kind.
  std::function<void(const std::vector<Vec3>&, std::vector<Row>&)> ask;
  std::vector<std::string> names;
  bool volume = false;
  std::unique_ptr<CurveProjector> curve;
  std::unique_ptr<SurfaceProjector> surface;
  std::unique_ptr<VolumeLocator> located;
  if (auto* cc = std::get_if<CurveConstruction>(&built)) {
    curve = std::make_unique<CurveProjector>(cc->curve);
    names = {"t"};
    ask = [&](const std::vector<Vec3>& q, std::vector<Row>& rows) {
      std::vector<CurvePoint> a(q.size());
      curve->closest(q, a);
      for (std::size_t i = 0; i < q.size(); ++i) rows[i] = {{a[i].t, 0, 0}, a[i].point, a[i].distance, false};
    };
  } else {
    Construction& c = std::get<Construction>(built);
    if (is_volume(c)) {
      const auto& v = std::get<BSplineVolume>(exact_form(c, progress));
      located = std::make_unique<VolumeLocator>(v, v);
      names = {"u", "v", "w"};
      volume = true;
      ask = [&](const std::vector<Vec3>& q, std::vector<Row>& rows) {
        std::vector<VolumePoint> a(q.size());
        located->locate(q, a);
        for (std::size_t i = 0; i < q.size(); ++i) rows[i] = {{a[i].u, a[i].v, a[i].w}, a[i].point, a[i].residual, a[i].inside};
      };
    } else {
      surface = surface_projector(c, progress);
      names = {"u", "v"};
      ask = [&](const std::vector<Vec3>& q, std::vector<Row>& rows) {
        std::vector<SurfacePoint> a(q.size());
        surface->closest(q, a);
        for (std::size_t i = 0; i < q.size(); ++i) rows[i] = {{a[i].u, a[i].v, 0}, a[i].point, a[i].distance, false};
      };
    }
  }
  const Sink sink(f, reader.shape(), names, volume);
  if (const auto size = sink.size()) check_disk_space(out, size, detail::cat("the output '", out.string(), "'"));
  ProjectionSummary summary;
  summary.points = reader.count();
  write_atomically(out, [&](std::ostream& os) {
    sink.begin(os);
    std::vector<double> buf(3 * block);
    std::vector<Row> rows;
    for (std::size_t done = 0; done < reader.count();) {
      const std::size_t n = reader.read(buf.data(), block);
      const std::vector<Vec3> q = as_points(buf, n, done);
      rows.resize(n);
      ask(q, rows);
      for (const Row& r : rows) {
        summary.max_distance = std::max(summary.max_distance, r.d);
        summary.outside += volume && !r.inside ? 1 : 0;
      }
      sink.write(os, rows);
      done += n;
      if (progress) progress(static_cast<double>(done) / static_cast<double>(reader.count()));
    }
    sink.finish(os);
  }, sink.size());
  return summary;
}

std::size_t write_intersections(Construction& c, const fs::path& rays, const fs::path& out, const progress_callback& progress) {
  const Format f = format_of(out);
  check_writable(out);
  if (is_volume(c)) fail(errc::wrong_type, "intersect: rays meet surfaces; this is a volume construction");
  internal::RowReader reader(rays, 6, "rays");
  const std::unique_ptr<SurfaceProjector> projector = surface_projector(c, progress);
  const SurfaceProjector& on = *projector;
  // The hits of every block, kept in a file of their own until their number is known.
  struct Hit {
    double ray, t, u, v, x, y, z;
  };
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> spill(std::tmpfile(), &std::fclose);
  if (!spill) fail(errc::file_unwritable, "intersect: cannot make a temporary file for the hits");
  std::size_t hits = 0;
  std::vector<double> buf(6 * block);
  for (std::size_t done = 0; done < reader.count();) {
    const std::size_t n = reader.read(buf.data(), block);
    std::vector<Vec3> o(n), d(n);
    for (std::size_t i = 0; i < n; ++i) {
      o[i] = {buf[6 * i], buf[6 * i + 1], buf[6 * i + 2]};
      d[i] = {buf[6 * i + 3], buf[6 * i + 4], buf[6 * i + 5]};
    }
    std::vector<std::vector<RayHit>> per(n);
    try {
      on.intersect(o, d, per);
    } catch (const error& e) {
      // Name the ray by its index in the file, not in the block.
      std::string m = e.what();
      if (m.rfind("ray ", 0) == 0) {
        const std::size_t k = std::stoul(m.substr(4));
        m = "ray " + std::to_string(done + k) + m.substr(m.find(':'));
      }
      throw error(e.code(), m);
    }
    std::vector<Hit> h;
    for (std::size_t i = 0; i < n; ++i)
      for (const RayHit& r : per[i])
        h.push_back({static_cast<double>(done + i), r.t, r.u, r.v, r.point.x, r.point.y, r.point.z});
    if (!h.empty() && std::fwrite(h.data(), sizeof(Hit), h.size(), spill.get()) != h.size())
      fail(errc::file_unwritable, "intersect: cannot write the hits to a temporary file");
    hits += h.size();
    done += n;
    if (progress) progress(static_cast<double>(done) / static_cast<double>(reader.count()));
  }
  // From the kept hits, one member (or all columns) at a time.
  const auto each = [&](const std::function<void(const std::vector<Hit>&)>& use) {
    std::rewind(spill.get());
    std::vector<Hit> h(block);
    for (std::size_t left = hits; left > 0;) {
      const std::size_t n = std::min(left, block);
      if (std::fread(h.data(), sizeof(Hit), n, spill.get()) != n)
        fail(errc::file_unreadable, "intersect: cannot read back the hits from a temporary file");
      h.resize(n);
      use(h);
      h.resize(block);
      left -= n;
    }
  };
  if (f == Format::npz) {
    internal::NpzColumns npz({{"ray", "<i8", {hits}}, {"t", "<f8", {hits}}, {"params", "<f8", {hits, 2}}, {"points", "<f8", {hits, 3}}});
    check_disk_space(out, npz.total(), detail::cat("the output '", out.string(), "'"));
    write_atomically(out, [&](std::ostream& os) {
      npz.begin(os);
      each([&](const std::vector<Hit>& h) {
        std::vector<std::int64_t> ray;
        std::vector<double> t, p, x;
        for (const Hit& r : h) {
          ray.push_back(static_cast<std::int64_t>(r.ray));
          t.push_back(r.t);
          p.insert(p.end(), {r.u, r.v});
          x.insert(x.end(), {r.x, r.y, r.z});
        }
        npz.append(os, 0, ray.data(), ray.size() * sizeof(std::int64_t));
        npz.append(os, 1, t.data(), t.size() * sizeof(double));
        npz.append(os, 2, p.data(), p.size() * sizeof(double));
        npz.append(os, 3, x.data(), x.size() * sizeof(double));
      });
      npz.finish(os);
    }, npz.total());
  } else if (f == Format::npy) {
    const std::size_t shape[2] = {hits, 7};
    const std::string header = internal::npy_header("<f8", shape);
    write_atomically(out, [&](std::ostream& os) {
      os << header;
      each([&](const std::vector<Hit>& h) { internal::write_values(os, &h.front().ray, 7 * h.size()); });
    }, header.size() + hits * sizeof(Hit));
  } else {
    write_atomically(out, [&](std::ostream& os) {
      os << "ray,t,u,v,x,y,z\n";
      each([&](const std::vector<Hit>& h) {
        std::string s;
        for (const Hit& r : h)
          s += std::to_string(static_cast<std::int64_t>(r.ray)) + "," + text(r.t) + "," + text(r.u) + "," + text(r.v) + "," +
               text(r.x) + "," + text(r.y) + "," + text(r.z) + "\n";
        os << s;
      });
    });
  }
  return hits;
}

}  // namespace interpatch::io
