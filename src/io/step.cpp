#include "interpatch/io/step.hpp"

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "io/exchange.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/atomic_file.hpp"

namespace interpatch::io {

namespace {

using detail::append_real;
using detail::real_text;

// Entities numbered in the order written, buffered and handed to the stream in
// large pieces.
class Entities {
 public:
  explicit Entities(std::ostream& os) : os_(os) {}
  Entities(const Entities&) = delete;
  Entities& operator=(const Entities&) = delete;
  ~Entities() = default;

  // Starts entity #n and returns n; the text follows through text(), close() ends it.
  int open() {
    buf_ += '#';
    buf_ += std::to_string(++count_);
    buf_ += '=';
    return count_;
  }
  Entities& text(std::string_view s) {
    buf_ += s;
    if (buf_.size() > (1u << 16)) flush();
    return *this;
  }
  Entities& ref(int id) {
    buf_ += '#';
    buf_ += std::to_string(id);
    return *this;
  }
  Entities& real(double v) {
    append_real(buf_, v);
    return *this;
  }
  int close() {
    buf_ += ";\n";
    return count_;
  }
  // A whole entity in one go.
  int add(std::string_view s) {
    open();
    text(s);
    return close();
  }
  void flush() {
    os_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    buf_.clear();
  }

 private:
  std::ostream& os_;
  std::string buf_;
  int count_ = 0;
};

std::string step_string(std::string_view s) {
  std::string q = "'";
  for (const char c : detail::printable_ascii(s)) {
    if (c == '\'' || c == '\\') q += c;  // Part 21 doubles both
    q += c;
  }
  return q + "'";
}

std::string refs(const std::vector<int>& ids) {
  std::string s = "(";
  for (std::size_t i = 0; i < ids.size(); ++i) s += (i ? ",#" : "#") + std::to_string(ids[i]);
  return s + ")";
}

std::string ints(const std::vector<int>& v) {
  std::string s = "(";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + std::to_string(v[i]);
  return s + ")";
}

std::string reals(const std::vector<double>& v) {
  std::string s = "(";
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += ',';
    append_real(s, v[i]);
  }
  return s + ")";
}

const char* logical(bool b) { return b ? ".T." : ".F."; }

// (multiplicities),(knots) as B_SPLINE_..._WITH_KNOTS lists them.
std::string knot_lists(const KnotVector& k) {
  const detail::KnotRuns r = detail::knot_runs(k);
  return ints(r.multiplicities) + "," + reals(r.values);
}

// ---------------------------------------------------------------- topology

// Side s of a face's parameter rectangle [u0,u1] x [v0,v1], counterclockwise:
// 0: v = v0, 1: u = u1, 2: v = v1, 3: u = u0. The boundary curve of a side runs
// with its parameter (u for sides 0 and 2, v for 1 and 3); the loop runs sides 0
// and 1 along their curves, 2 and 3 against them.
struct Side {
  std::vector<std::size_t> index;  // control-point indices into the face's net, in curve order
  const KnotVector* knots = nullptr;
  // The parameter line of the side: (base + t * dir) for the curve parameter t.
  std::array<double, 2> base{}, dir{};
  bool forward_in_loop = true;
  bool periodic = false;  // the face was periodic along the side: its curve is closed
};

Side side_of(const detail::Face& f, int side) {
  const BSplineSurface& s = f.surface;
  const std::size_t n = s.control_points().extent(0), m = s.control_points().extent(1);
  const auto [u0, u1] = s.domain_u();
  const auto [v0, v1] = s.domain_v();
  Side r;
  const bool along_u = side == 0 || side == 2;
  r.knots = along_u ? &s.knots_u() : &s.knots_v();
  const std::size_t count = along_u ? n : m;
  for (std::size_t t = 0; t < count; ++t) {
    switch (side) {
      case 0: r.index.push_back(t * m); break;
      case 1: r.index.push_back((n - 1) * m + t); break;
      case 2: r.index.push_back(t * m + m - 1); break;
      default: r.index.push_back(t); break;
    }
  }
  r.base = side == 0 ? std::array{0.0, v0} : side == 1 ? std::array{u1, 0.0} : side == 2 ? std::array{0.0, v1} : std::array{u0, 0.0};
  r.dir = along_u ? std::array{1.0, 0.0} : std::array{0.0, 1.0};
  r.forward_in_loop = side < 2;
  r.periodic = f.periodic[along_u ? 0 : 1];
  return r;
}

struct Use {
  int face = 0, side = 0;
  bool mirrored = false;  // the side's curve runs against the edge's curve
};

struct Edge {
  Use first;  // the side whose curve is the edge's curve
  std::vector<Use> uses;
  int start = 0, end = 0;  // vertex indices
};

struct LoopEntry {
  int edge = 0;
  bool forward = true;
};

struct Topology {
  std::vector<Vec3> vertices;
  std::vector<Edge> edges;
  std::vector<std::vector<LoopEntry>> loops;  // per face, counterclockwise about the face normal
  std::vector<bool> same_sense;               // per face: face normal along S_u x S_v
  bool closed = false;                        // every edge used twice, in opposite directions
  // The faces joined through shared edges, each set a shell; more than one when the
  // faces fall apart (a volume closed in two directions: its inner and outer skin).
  std::vector<std::vector<int>> shells;
};

class TopologyBuilder {
 public:
  TopologyBuilder(const std::vector<detail::Face>& faces, double tol) : faces_(faces), tol_(tol) {}

  Topology build(const std::vector<bool>& same_sense) {
    t_.same_sense = same_sense;
    t_.loops.resize(faces_.size());
    for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
      for (int s = 0; s < 4; ++s) {
        const Side side = side_of(faces_[f], s);
        if (degenerate(f, side)) continue;  // a pole: the loop closes through its vertex
        const Use use = find_or_add(f, s, side);
        t_.loops[f].push_back({edge_of_last_, side.forward_in_loop != use.mirrored});
      }
      if (!same_sense[f]) {
        auto& loop = t_.loops[f];
        std::reverse(loop.begin(), loop.end());
        for (auto& e : loop) e.forward = !e.forward;
      }
    }
    t_.closed = faces_.size() > 1;
    std::vector<int> forward(t_.edges.size()), backward(t_.edges.size());
    for (const auto& loop : t_.loops)
      for (const auto& e : loop) ++(e.forward ? forward : backward)[e.edge];
    for (std::size_t e = 0; e < t_.edges.size(); ++e)
      t_.closed = t_.closed && forward[e] == 1 && backward[e] == 1;
    t_.shells = shells();
    return std::move(t_);
  }

 private:
  const Vec3& point(int f, std::size_t i) const { return faces_[f].surface.control_points().data()[i]; }
  double weight(int f, std::size_t i) const {
    const BSplineSurface& s = faces_[f].surface;
    return s.rational() ? s.weights().data()[i] : 1.0;
  }

  // Faces sharing an edge in one shell (union-find), shells in the order of their first face.
  std::vector<std::vector<int>> shells() const {
    std::vector<int> root(faces_.size());
    for (std::size_t f = 0; f < root.size(); ++f) root[f] = static_cast<int>(f);
    const auto find = [&](int f) {
      while (root[f] != f) f = root[f] = root[root[f]];
      return f;
    };
    for (const Edge& e : t_.edges)
      for (const Use& u : e.uses) {
        const int a = find(e.first.face), b = find(u.face);
        root[std::max(a, b)] = std::min(a, b);
      }
    std::vector<std::vector<int>> out;
    std::vector<int> shell_of(faces_.size(), -1);
    for (int f = 0; f < static_cast<int>(faces_.size()); ++f) {
      int& s = shell_of[find(f)];
      if (s < 0) {
        s = static_cast<int>(out.size());
        out.emplace_back();
      }
      out[s].push_back(f);
    }
    return out;
  }

  bool degenerate(int f, const Side& s) const {
    for (const std::size_t i : s.index)
      if (norm(point(f, i) - point(f, s.index.front())) > tol_) return false;
    return true;
  }

  int vertex(const Vec3& p) {
    for (std::size_t v = 0; v < t_.vertices.size(); ++v)
      if (norm(t_.vertices[v] - p) <= tol_) return static_cast<int>(v);
    t_.vertices.push_back(p);
    return static_cast<int>(t_.vertices.size()) - 1;
  }

  // Whether side b of face g is the curve of side a of face f, run the same way
  // or (mirrored) backwards: same knots (reflected when mirrored), weights and
  // control points.
  bool same_curve(int f, const Side& a, int g, const Side& b, bool mirrored) const {
    const std::size_t n = a.index.size();
    if (b.index.size() != n || a.knots->degree() != b.knots->degree() || a.knots->size() != b.knots->size())
      return false;
    const double lo = a.knots->front(), hi = a.knots->back(), span = hi - lo;
    const std::size_t nk = a.knots->size();
    for (std::size_t k = 0; k < nk; ++k) {
      const double kb = mirrored ? lo + hi - (*b.knots)[nk - 1 - k] : (*b.knots)[k];
      if (std::abs((*a.knots)[k] - kb) > 1e-12 * span) return false;
    }
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t kb = mirrored ? n - 1 - k : k;
      if (norm(point(f, a.index[k]) - point(g, b.index[kb])) > tol_) return false;
      if (std::abs(weight(f, a.index[k]) - weight(g, b.index[kb])) > 1e-12 * weight(f, a.index[k])) return false;
    }
    return true;
  }

  Use find_or_add(int f, int s, const Side& side) {
    for (std::size_t e = 0; e < t_.edges.size(); ++e) {
      const Use& first = t_.edges[e].first;
      const Side other = side_of(faces_[first.face], first.side);
      for (const bool mirrored : {false, true}) {
        if (!same_curve(first.face, other, f, side, mirrored)) continue;
        const Use use{f, s, mirrored};
        t_.edges[e].uses.push_back(use);
        edge_of_last_ = static_cast<int>(e);
        return use;
      }
    }
    Edge e;
    e.first = {f, s, false};
    e.uses.push_back(e.first);
    e.start = vertex(point(f, side.index.front()));
    e.end = vertex(point(f, side.index.back()));
    t_.edges.push_back(std::move(e));
    edge_of_last_ = static_cast<int>(t_.edges.size()) - 1;
    return t_.edges.back().first;
  }

  const std::vector<detail::Face>& faces_;
  double tol_;
  Topology t_;
  int edge_of_last_ = 0;
};

// Outward faces of a volume: with det J > 0, S_v x S_w points into the volume on
// face u0 and out of it on u1; S_u x S_w out of it on v0; S_u x S_v into it on w0.
std::vector<bool> outward_senses(const BSplineVolume& b) {
  const auto d = b.domain();
  const VolumeDerivatives c = b.derivatives(0.5 * (d[0].first + d[0].second), 0.5 * (d[1].first + d[1].second),
                                            0.5 * (d[2].first + d[2].second));
  const bool right_handed = triple(c.su, c.sv, c.sw) >= 0;  // triple(): no overflow at any scale of the data
  std::vector<bool> s{false, true, true, false, false, true};
  if (!right_handed)
    for (std::size_t i = 0; i < s.size(); ++i) s[i] = !s[i];
  return s;
}

// ---------------------------------------------------------------- entities

// Control points as CARTESIAN_POINTs; returns their ids in the net's C order.
std::vector<int> write_points(Entities& out, std::span<const Vec3> cp) {
  std::vector<int> ids;
  ids.reserve(cp.size());
  for (const Vec3& p : cp) {
    out.open();
    out.text("CARTESIAN_POINT('',(").real(p.x).text(",").real(p.y).text(",").real(p.z).text("))");
    ids.push_back(out.close());
  }
  return ids;
}

// The face's surface, its clamped form: u_closed/v_closed .T. in a direction that
// was periodic or whose net closes on itself (detail::closed).
int write_surface(Entities& out, const detail::Face& f, const std::vector<int>& ids, double tol) {
  const BSplineSurface& s = f.surface;
  const std::size_t n = s.control_points().extent(0), m = s.control_points().extent(1);
  const std::string flags = std::string(",.UNSPECIFIED.,") + logical(detail::closed(f, 0, tol)) + "," +
                            logical(detail::closed(f, 1, tol)) + ",.F.";
  const auto net = [&] {
    out.text("(");
    for (std::size_t i = 0; i < n; ++i) {
      out.text(i ? ",\n  (" : "(");
      for (std::size_t j = 0; j < m; ++j) out.text(j ? ",#" : "#").text(std::to_string(ids[i * m + j]));
      out.text(")");
    }
    out.text(")");
  };
  const detail::KnotRuns ku = detail::knot_runs(s.knots_u()), kv = detail::knot_runs(s.knots_v());
  const std::string with_knots = ints(ku.multiplicities) + "," + ints(kv.multiplicities) + "," + reals(ku.values) +
                                 "," + reals(kv.values) + ",.UNSPECIFIED.";
  const std::string degrees = std::to_string(s.degree_u()) + "," + std::to_string(s.degree_v()) + ",";
  out.open();
  if (!s.rational()) {
    out.text("B_SPLINE_SURFACE_WITH_KNOTS('',").text(degrees);
    net();
    out.text(flags).text(",").text(with_knots).text(")");
    return out.close();
  }
  // A complex instance: its partial entities in alphabetical order (Part 21 external mapping).
  out.text("(BOUNDED_SURFACE() B_SPLINE_SURFACE(").text(degrees);
  net();
  out.text(flags).text(")\nB_SPLINE_SURFACE_WITH_KNOTS(").text(with_knots);
  out.text(")\nGEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_SURFACE((");
  for (std::size_t i = 0; i < n; ++i) {
    out.text(i ? ",\n  (" : "(");
    for (std::size_t j = 0; j < m; ++j) {
      if (j) out.text(",");
      out.real(s.weights()(i, j));
    }
    out.text(")");
  }
  out.text("))\nREPRESENTATION_ITEM('') SURFACE())");
  return out.close();
}

// A B-spline curve over clamped `knots` on the control points `pts` (entity ids),
// rational with weights `w`.
int write_bspline_curve(Entities& out, const KnotVector& knots, const std::vector<int>& pts, const std::vector<double>& w,
                        bool closed) {
  const std::string head = std::to_string(knots.degree()) + "," + refs(pts) + ",.UNSPECIFIED.," + logical(closed) + ",.F.";
  const std::string with_knots = knot_lists(knots) + ",.UNSPECIFIED.";
  if (w.empty()) return out.add("B_SPLINE_CURVE_WITH_KNOTS(''," + head + "," + with_knots + ")");
  return out.add("(BOUNDED_CURVE() B_SPLINE_CURVE(" + head + ")\nB_SPLINE_CURVE_WITH_KNOTS(" + with_knots +
                 ")\nCURVE() GEOMETRIC_REPRESENTATION_ITEM() RATIONAL_B_SPLINE_CURVE(" + reals(w) +
                 ")\nREPRESENTATION_ITEM(''))");
}

int write_curve(Entities& out, const BSplineSurface& s, const Side& side, const std::vector<int>& ids, double tol) {
  std::vector<int> pts;
  std::vector<double> w;
  for (const std::size_t i : side.index) {
    pts.push_back(ids[i]);
    if (s.rational()) w.push_back(s.weights().data()[i]);
  }
  const bool closed =
      side.periodic || norm(s.control_points().data()[side.index.front()] - s.control_points().data()[side.index.back()]) <= tol;
  return write_bspline_curve(out, *side.knots, pts, w, closed);
}

// The side's parameter line on its face as a PCURVE, parametrized by the edge's curve.
int write_pcurve(Entities& out, int surface, const Side& side, bool mirrored, int context2d) {
  std::array<double, 2> base = side.base, dir = side.dir;
  if (mirrored) {  // t -> lo + hi - t
    const double sum = side.knots->front() + side.knots->back();
    for (int k = 0; k < 2; ++k) {
      base[k] += sum * dir[k];
      dir[k] = -dir[k];
    }
  }
  const int p = out.add("CARTESIAN_POINT('',(" + real_text(base[0]) + "," + real_text(base[1]) + "))");
  const int d = out.add("DIRECTION('',(" + real_text(dir[0]) + "," + real_text(dir[1]) + "))");
  const int v = out.add("VECTOR('',#" + std::to_string(d) + ",1.)");
  const int line = out.add("LINE('',#" + std::to_string(p) + ",#" + std::to_string(v) + ")");
  const int rep = out.add("DEFINITIONAL_REPRESENTATION('',(#" + std::to_string(line) + "),#" + std::to_string(context2d) + ")");
  return out.add("PCURVE('',#" + std::to_string(surface) + ",#" + std::to_string(rep) + ")");
}

std::string iso_time(const StepOptions& o) {
  return o.time_stamp.empty() ? detail::utc_now("%Y-%m-%dT%H:%M:%S") : o.time_stamp;
}

// What every file refers to: the product (its shape) and the representation contexts.
struct Frame {
  int shape = 0, context3d = 0, context2d = 0;
};

// The header, then the product structure and contexts: what CAD systems need to import a part.
Frame write_frame(std::ostream& os, Entities& out, const StepOptions& options) {
  const std::string name = step_string(options.name);
  const auto r = [](int id) { return "#" + std::to_string(id); };
  os << "ISO-10303-21;\nHEADER;\n"
     << "FILE_DESCRIPTION(('interpatch exact B-spline form'),'2;1');\n"
     << "FILE_NAME(" << name << ",'" << iso_time(options) << "',(''),(''),'interpatch','interpatch','');\n"
     << "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\n"
     << "ENDSEC;\nDATA;\n";
  const int app = out.add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')");
  out.add("APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000," + r(app) + ")");
  const int pctx = out.add("PRODUCT_CONTEXT(''," + r(app) + ",'mechanical')");
  const int product = out.add("PRODUCT(" + name + "," + name + ",'',(" + r(pctx) + "))");
  out.add("PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(" + r(product) + "))");
  const int formation = out.add("PRODUCT_DEFINITION_FORMATION('',''," + r(product) + ")");
  const int pdctx = out.add("PRODUCT_DEFINITION_CONTEXT('part definition'," + r(app) + ",'design')");
  const int pdef = out.add("PRODUCT_DEFINITION('design',''," + r(formation) + "," + r(pdctx) + ")");
  const int pdshape = out.add("PRODUCT_DEFINITION_SHAPE('',''," + r(pdef) + ")");
  const int mm = out.add("(LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.))");
  const int rad = out.add("(NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.))");
  const int sr = out.add("(NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT())");
  const int unc = out.add("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07)," + r(mm) +
                          ",'distance_accuracy_value','confusion accuracy')");
  const int ctx3 = out.add("(GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((" + r(unc) +
                           ")) GLOBAL_UNIT_ASSIGNED_CONTEXT((" + r(mm) + "," + r(rad) + "," + r(sr) +
                           ")) REPRESENTATION_CONTEXT('3D','3D context with units and uncertainty'))");
  const int ctx2 = out.add("(GEOMETRIC_REPRESENTATION_CONTEXT(2) PARAMETRIC_REPRESENTATION_CONTEXT() "
                           "REPRESENTATION_CONTEXT('2D','parameter space'))");
  return {pdshape, ctx3, ctx2};
}

// The shape's representation, made of `items` (after a placement at the origin),
// and the end of the file.
void finish(std::ostream& os, Entities& out, const Frame& frame, const std::string& representation,
            const std::string& name, const std::vector<int>& items) {
  const auto r = [](int id) { return "#" + std::to_string(id); };
  const int origin = out.add("CARTESIAN_POINT('',(0.,0.,0.))");
  const int zdir = out.add("DIRECTION('',(0.,0.,1.))");
  const int xdir = out.add("DIRECTION('',(1.,0.,0.))");
  const int placement = out.add("AXIS2_PLACEMENT_3D(''," + r(origin) + "," + r(zdir) + "," + r(xdir) + ")");
  std::vector<int> all{placement};
  all.insert(all.end(), items.begin(), items.end());
  const int rep = out.add(representation + "(" + name + "," + refs(all) + "," + r(frame.context3d) + ")");
  out.add("SHAPE_DEFINITION_REPRESENTATION(" + r(frame.shape) + "," + r(rep) + ")");
  out.text("ENDSEC;\nEND-ISO-10303-21;\n");
  out.flush();
  os.flush();
  if (!os) throw error(errc::file_unwritable, "STEP output: write failed");
}

}  // namespace

void write_step(std::ostream& os, const ExactForm& exact, const StepOptions& options) {
  const std::vector<detail::Face> faces = detail::faces_of(exact);
  const double tol = detail::coincidence_tolerance(faces);
  std::vector<bool> same_sense(faces.size(), true);
  if (const auto* volume = std::get_if<BSplineVolume>(&exact)) {
    const std::vector<bool> outward = outward_senses(*volume);
    for (std::size_t f = 0; f < faces.size(); ++f) same_sense[f] = outward[static_cast<std::size_t>(faces[f].side)];
  }
  const Topology topo = TopologyBuilder(faces, tol).build(same_sense);
  const std::string name = step_string(options.name);
  const auto r = [](int id) { return "#" + std::to_string(id); };
  Entities out(os);
  const Frame frame = write_frame(os, out, options);
  const int ctx2 = frame.context2d;

  // Geometry: control nets and surfaces.
  std::vector<std::vector<int>> point_ids;
  std::vector<int> surfaces;
  for (const auto& f : faces) {
    point_ids.push_back(write_points(out, f.surface.control_points().values()));
    surfaces.push_back(write_surface(out, f, point_ids.back(), tol));
  }

  // Topology: vertices on the corner control points, edges on the boundary rows.
  std::vector<int> vertex_ids(topo.vertices.size(), 0);
  std::vector<int> edge_ids;
  for (const Edge& e : topo.edges) {
    const Side side = side_of(faces[e.first.face], e.first.side);
    const auto& ids = point_ids[e.first.face];
    for (const auto& [v, corner] : {std::pair{e.start, side.index.front()}, std::pair{e.end, side.index.back()}})
      if (!vertex_ids[v]) vertex_ids[v] = out.add("VERTEX_POINT(''," + r(ids[corner]) + ")");
    const int curve = write_curve(out, faces[e.first.face].surface, side, ids, tol);
    std::vector<int> pcurves;
    bool seam = false;
    for (const Use& u : e.uses) {
      pcurves.push_back(write_pcurve(out, surfaces[u.face], side_of(faces[u.face], u.side), u.mirrored, ctx2));
      for (const Use& o : e.uses) seam = seam || (&o != &u && o.face == u.face);
    }
    const int geometry = out.add(std::string(seam ? "SEAM_CURVE" : "SURFACE_CURVE") + "(''," + r(curve) + "," +
                                 refs(pcurves) + ",.CURVE_3D.)");
    edge_ids.push_back(out.add("EDGE_CURVE(''," + r(vertex_ids[e.start]) + "," + r(vertex_ids[e.end]) + "," +
                               r(geometry) + ",.T.)"));
  }

  std::vector<int> face_ids;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    std::vector<int> oriented;
    for (const LoopEntry& e : topo.loops[f])
      oriented.push_back(out.add("ORIENTED_EDGE('',*,*," + r(edge_ids[e.edge]) + "," + logical(e.forward) + ")"));
    const int loop = out.add("EDGE_LOOP(''," + refs(oriented) + ")");
    const int bound = out.add("FACE_OUTER_BOUND(''," + r(loop) + ",.T.)");
    face_ids.push_back(out.add("ADVANCED_FACE('',(" + r(bound) + ")," + r(surfaces[f]) + "," +
                               logical(topo.same_sense[f]) + ")"));
  }

  if (topo.closed && topo.shells.size() == 1) {
    const int shell = out.add("CLOSED_SHELL(''," + refs(face_ids) + ")");
    const int solid = out.add("MANIFOLD_SOLID_BREP(" + name + "," + r(shell) + ")");
    finish(os, out, frame, "ADVANCED_BREP_SHAPE_REPRESENTATION", name, {solid});
  } else {
    // One shell per set of connected faces; closed ones (a volume's inner and outer
    // skin when it is closed in two directions) say so.
    std::vector<int> shells;
    for (const std::vector<int>& members : topo.shells) {
      std::vector<int> ids;
      for (const int f : members) ids.push_back(face_ids[static_cast<std::size_t>(f)]);
      shells.push_back(out.add(std::string(topo.closed ? "CLOSED_SHELL" : "OPEN_SHELL") + "(''," + refs(ids) + ")"));
    }
    const int model = out.add("SHELL_BASED_SURFACE_MODEL(" + name + "," + refs(shells) + ")");
    finish(os, out, frame, "MANIFOLD_SURFACE_SHAPE_REPRESENTATION", name, {model});
  }
}

void write_step(std::ostream& os, const BSplineCurve& curve, const StepOptions& options) {
  // STEP's B-spline curves list every knot: a closed curve is written as its clamped
  // form, flagged closed.
  const BSplineCurve c = curve.clamped();
  const std::string name = step_string(options.name);
  Entities out(os);
  const Frame frame = write_frame(os, out, options);
  const int id = write_bspline_curve(out, c.knots(), write_points(out, c.control_points()), c.weights(), curve.periodic());
  const int set = out.add("GEOMETRIC_CURVE_SET(" + name + ",(#" + std::to_string(id) + "))");
  finish(os, out, frame, "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION", name, {set});
}

void write_step(const std::filesystem::path& path, const BSplineCurve& curve, const StepOptions& options) {
  write_atomically(path, [&](std::ostream& os) { write_step(os, curve, options); });
}

void write_step(const std::filesystem::path& path, const ExactForm& exact, const StepOptions& options) {
  write_atomically(path, [&](std::ostream& os) { write_step(os, exact, options); });
}

}  // namespace interpatch::io
