// bench/loft_compare: interpatch's loft against OpenCASCADE's BRepOffsetAPI_ThruSections
// (smooth, not ruled, not a solid) on the same section points.
//
//   loft_compare [--spec LOFT.json] [--cases wing,duct,duct_reversed] [--duct-counts 17,23,...]
//                [--reps N] [--samples M] [--tolerance T] [--json OUT]
//
// Cases:
//   wing           the sections of a loft spec (default examples/loft_wing.json), each
//                  given as {"interpolate": points, "periodic": true|false}: the points
//                  are what both tools get, as a user would give them
//   duct           closed superellipse sections along a bent spine, their exponents
//                  2 → 4 → 2.5, of --duct-counts points each (default 17, 23, 31, 40,
//                  52, 61, 75 and 90): each with its own knots, so that merged they
//                  would be 4 times the largest section's and more
//   duct_reversed  the same sections in the opposite order
//
// Each tool makes its own section curves from the points (interpatch::interpolate_curve,
// OpenCASCADE's GeomAPI_Interpolate, both closed and C2 through every point), then
// lofts them. Per tool:
//   loft  the loft alone from the tool's curves, best of --reps (OpenCASCADE: edges,
//         wires, ThruSections::Build and the faces' surfaces, as a caller with curves
//         has to do it)
//   job   the whole job from the points: section curves, then the loft, best of --reps
//   control points, along the sections × across them, as each tool stores them
//   data  the distance from every input point to the surface: the closest point, by
//         GeomAPI_ProjectPointOnSurf on both surfaces (interpatch's converted exactly
//         into a Geom_BSplineSurface), checked by a Newton search from the nearest
//         points of a dense sample of the surface; the smaller of the two is taken
//   curve the same for --samples points per section on the tool's own section curve
//   area  of the surface (Gauss–Legendre over the knot spans): a loft that twists
//         between its sections passes through them all the same, but is larger
//   apart the largest distance from OpenCASCADE's surface (a grid of 200 × 20 points a
//         face) to interpatch's, by the search: how far the two lofts differ between
//         the sections
// OpenCASCADE runs twice: with its default settings (CheckCompatibility on: the
// sections are turned and shifted to match, as interpatch does) and with
// CheckCompatibility(false) (the sections as given).
//
// Run with OMP_NUM_THREADS=1 for both libraries on one thread: ThruSections runs on
// one, and interpatch's alignment and re-expression are parallel loops. The console
// gets a table per case; --json gets every figure.

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepOffsetAPI_ThruSections.hxx>
#include <BRep_Tool.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <Standard_Version.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/loft.hpp"
#include "interpatch/threads.hpp"

namespace {

using interpatch::BSplineCurve;
using interpatch::BSplineSurface;
using interpatch::Vec3;
using json = nlohmann::ordered_json;
constexpr double inf = std::numeric_limits<double>::infinity();

struct Section {
  std::vector<Vec3> points;
  bool periodic = false;
};

struct Case {
  std::string name, description;
  std::vector<Section> sections;
};

// ---------------------------------------------------------------- the inputs

// The sections of a loft spec whose sections are all {"interpolate": points,
// "periodic": b}: what both tools can be given alike. Anything else in the spec
// (degrees, parameters, tangents) would have no counterpart on OpenCASCADE's side.
Case read_spec(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  const nlohmann::json spec = nlohmann::json::parse(in);
  if (spec.value("type", "") != "loft") throw std::runtime_error(path + ": not a loft spec");
  for (const auto& [key, value] : spec.items())
    if (key != "type" && key != "comment" && key != "sections")
      throw std::runtime_error(path + ": \"" + key + "\" has no counterpart in OpenCASCADE's ThruSections here");
  Case c;
  c.name = "wing";
  for (const auto& s : spec.at("sections")) {
    for (const auto& [key, value] : s.items())
      if (key != "interpolate" && key != "periodic")
        throw std::runtime_error(path + ": a section's \"" + key +
                                 "\": only {\"interpolate\", \"periodic\"} sections are compared");
    Section sec;
    sec.periodic = s.value("periodic", false);
    for (const auto& p : s.at("interpolate"))
      sec.points.push_back({p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>()});
    // A closed section's last point repeating the first is its closing point:
    // interpatch leaves it out, and GeomAPI_Interpolate refuses it, so neither gets it.
    if (sec.periodic && sec.points.size() > 1 && sec.points.back() == sec.points.front()) sec.points.pop_back();
    c.sections.push_back(std::move(sec));
  }
  std::size_t total = 0;
  for (const auto& s : c.sections) total += s.points.size();
  c.description = path + ": " + std::to_string(c.sections.size()) + " sections, " + std::to_string(total) + " points";
  return c;
}

// A duct whose cross-sections change shape (superellipses |x/a|^e + |y/b|^e = 1, e from
// 2 up to 4 and back to 2.5), size and place along a bent spine, each given with its
// own number of points at even angles. Every section gets its own chord parameters,
// so the merged knots are close to the sum of all the sections' knots.
Case make_duct(const std::vector<int>& counts, bool reversed) {
  const std::size_t n = counts.size();
  if (n < 2) throw std::runtime_error("--duct-counts: at least 2 sections");
  Case c;
  c.name = reversed ? "duct_reversed" : "duct";
  std::size_t total = 0;
  std::string list;
  for (std::size_t k = 0; k < n; ++k) {
    const double s = static_cast<double>(k) / static_cast<double>(n - 1);
    const double e = s < 0.5 ? 2.0 + 4.0 * s : 4.0 - 3.0 * (s - 0.5);  // 2 → 4 → 2.5
    const double a = 1.0 - 0.35 * s, b = 0.55 + 0.25 * s;
    const double cx = 0.6 * std::sin(0.5 * std::numbers::pi * s), cz = 3.0 * s;  // the bent spine
    const double twist = 0.3 * s;  // a gentle turn of the section about the spine
    Section sec;
    sec.periodic = true;
    for (int i = 0; i < counts[k]; ++i) {
      const double t = 2 * std::numbers::pi * i / counts[k];
      const double ct = std::cos(t), st = std::sin(t);
      const double x = a * std::copysign(std::pow(std::abs(ct), 2 / e), ct);
      const double y = b * std::copysign(std::pow(std::abs(st), 2 / e), st);
      sec.points.push_back({cx + x * std::cos(twist) - y * std::sin(twist), x * std::sin(twist) + y * std::cos(twist), cz});
    }
    total += sec.points.size();
    list += (list.empty() ? "" : ", ") + std::to_string(counts[k]);
    c.sections.push_back(std::move(sec));
  }
  if (reversed) std::reverse(c.sections.begin(), c.sections.end());
  c.description = std::to_string(n) + " superellipse sections of " + list + " points" +
                  (reversed ? ", last first" : "") + ", " + std::to_string(total) + " points";
  return c;
}

// ---------------------------------------------------------------- interpatch

std::vector<BSplineCurve> ip_curves(const Case& c, double* through = nullptr) {
  std::vector<BSplineCurve> out;
  for (const Section& s : c.sections) {
    interpatch::CurveInterpolationOptions o;
    o.periodic = s.periodic;
    interpatch::CurveInterpolation r = interpatch::interpolate_curve(s.points, o);
    // How close the curve passes to its points, where it says it does.
    if (through)
      for (std::size_t i = 0; i < s.points.size(); ++i)
        *through = std::max(*through, interpatch::distance(r.curve.point(r.params[i]), s.points[i]));
    out.push_back(std::move(r.curve));
  }
  return out;
}

// interpatch's surface as OpenCASCADE's, exactly: the clamped form of each periodic
// direction (the same surface over the same domain), then knots with multiplicities.
Handle(Geom_BSplineSurface) to_occ(const BSplineSurface& periodic_or_not) {
  const BSplineSurface s = periodic_or_not.clamped();
  struct Knots {
    TColStd_Array1OfReal values;
    TColStd_Array1OfInteger mults;
  };
  auto knots = [](const interpatch::KnotVector& k) {
    std::vector<std::pair<double, int>> distinct;
    for (double t : k.values())
      if (!distinct.empty() && distinct.back().first == t)
        ++distinct.back().second;
      else
        distinct.push_back({t, 1});
    const int n = static_cast<int>(distinct.size());
    Knots out{TColStd_Array1OfReal(1, n), TColStd_Array1OfInteger(1, n)};
    for (int i = 0; i < n; ++i) {
      out.values.SetValue(i + 1, distinct[static_cast<std::size_t>(i)].first);
      out.mults.SetValue(i + 1, distinct[static_cast<std::size_t>(i)].second);
    }
    return out;
  };
  const Knots ku = knots(s.knots_u()), kv = knots(s.knots_v());
  const auto& cp = s.control_points();
  const int nu = static_cast<int>(cp.extent(0)), nv = static_cast<int>(cp.extent(1));
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  TColStd_Array2OfReal weights(1, nu, 1, nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const auto ij = std::pair{static_cast<std::size_t>(i), static_cast<std::size_t>(j)};
      const Vec3& p = cp(ij.first, ij.second);
      poles.SetValue(i + 1, j + 1, gp_Pnt(p.x, p.y, p.z));
      weights.SetValue(i + 1, j + 1, s.rational() ? s.weights()(ij.first, ij.second) : 1.0);
    }
  if (s.rational())
    return new Geom_BSplineSurface(poles, weights, ku.values, kv.values, ku.mults, kv.mults, s.degree_u(), s.degree_v());
  return new Geom_BSplineSurface(poles, ku.values, kv.values, ku.mults, kv.mults, s.degree_u(), s.degree_v());
}

// ---------------------------------------------------------------- OpenCASCADE

Handle(Geom_BSplineCurve) occ_curve(const Section& s) {
  Handle(TColgp_HArray1OfPnt) pts = new TColgp_HArray1OfPnt(1, static_cast<int>(s.points.size()));
  for (std::size_t i = 0; i < s.points.size(); ++i)
    pts->SetValue(static_cast<int>(i) + 1, gp_Pnt(s.points[i].x, s.points[i].y, s.points[i].z));
  GeomAPI_Interpolate in(pts, s.periodic, Precision::Confusion());
  in.Perform();
  if (!in.IsDone()) throw std::runtime_error("GeomAPI_Interpolate failed");
  return in.Curve();
}

std::vector<Handle(Geom_BSplineCurve)> occ_curves(const Case& c) {
  std::vector<Handle(Geom_BSplineCurve)> out;
  for (const Section& s : c.sections) out.push_back(occ_curve(s));
  return out;
}

// The surfaces of the faces ThruSections made (one face per edge of a section: one
// here, unless the compatibility check cut the sections), as B-spline surfaces.
std::vector<Handle(Geom_BSplineSurface)> occ_loft(const std::vector<Handle(Geom_BSplineCurve)>& curves, bool check) {
  BRepOffsetAPI_ThruSections thru(Standard_False, Standard_False);  // a shell, smooth; pres3d 1e-6
  thru.CheckCompatibility(check ? Standard_True : Standard_False);
  for (const auto& c : curves) thru.AddWire(BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(c).Edge()).Wire());
  thru.Build();
  if (!thru.IsDone()) throw std::runtime_error("BRepOffsetAPI_ThruSections::Build failed");
  std::vector<Handle(Geom_BSplineSurface)> out;
  for (TopExp_Explorer ex(thru.Shape(), TopAbs_FACE); ex.More(); ex.Next()) {
    TopLoc_Location loc;
    Handle(Geom_Surface) s = BRep_Tool::Surface(TopoDS::Face(ex.Current()), loc);
    if (!loc.IsIdentity()) s = Handle(Geom_Surface)::DownCast(s->Transformed(loc.Transformation()));
    if (auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(s); !t.IsNull()) s = t->BasisSurface();
    Handle(Geom_BSplineSurface) b = Handle(Geom_BSplineSurface)::DownCast(s);
    if (b.IsNull()) b = GeomConvert::SurfaceToBSplineSurface(s);
    out.push_back(b);
  }
  if (out.empty()) throw std::runtime_error("BRepOffsetAPI_ThruSections made no face");
  return out;
}

// ---------------------------------------------------------------- distances

Vec3 vec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }
gp_Pnt pnt(const Vec3& p) { return {p.x, p.y, p.z}; }

// The closest point of one B-spline surface, found two ways: OpenCASCADE's projection
// (Extrema, interior extrema only) and a Newton search kept inside the domain, started
// at the nearest points of a dense sample. deviation() takes the nearer of the two, so
// each checks the other, and counts the projections that miss (none found, or farther
// by more than 1e-9 of the surface's size).
class Closest {
 public:
  explicit Closest(Handle(Geom_BSplineSurface) s) : s_(std::move(s)) {
    s_->Bounds(u0_, u1_, v0_, v1_);
    proj_->Init(s_, u0_, u1_, v0_, v1_);
    // Samples: 6 per knot span each way, at least 200 along u and 40 along v.
    nu_ = std::max(200, 6 * (s_->NbUKnots() - 1));
    nv_ = std::max(40, 6 * (s_->NbVKnots() - 1));
    for (int i = 0; i <= nu_; ++i)
      for (int j = 0; j <= nv_; ++j) {
        const double u = u0_ + (u1_ - u0_) * i / nu_, v = v0_ + (v1_ - v0_) * j / nv_;
        samples_.push_back({vec(s_->Value(u, v)), u, v});
      }
    d2_.resize(samples_.size());
    double lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    for (const auto& x : samples_)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], x.p[a]);
        hi[a] = std::max(hi[a], x.p[a]);
      }
    size_ = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    // Closed along u (a periodic loft, clamped): the edges u0 and u1 are one line, and
    // the search goes on across it instead of stopping there.
    closed_u_ = true;
    for (int j = 0; j <= 8; ++j) {
      const double v = v0_ + (v1_ - v0_) * j / 8;
      if (interpatch::distance(vec(s_->Value(u0_, v)), vec(s_->Value(u1_, v))) > 1e-12 * size_) closed_u_ = false;
    }
  }

  double size() const { return size_; }

  // The distance by OpenCASCADE's projection (infinite when it finds no extremum).
  double projected(const Vec3& q) {
    proj_->Perform(pnt(q));
    return proj_->NbPoints() > 0 ? proj_->LowerDistance() : inf;
  }

  // The distance by the search: from each of the 8 nearest samples that are nearer than
  // their neighbours on the sample grid (one in every valley of the distance: the two
  // sides of a thin wing's trailing edge both get one), Newton's method on |S − q|²/2
  // (Gauss–Newton where its Hessian is not positive definite), each step halved until
  // it gets nearer and kept in the domain (the nearest point can lie on an edge).
  double search(const Vec3& q) const {
    for (std::size_t k = 0; k < samples_.size(); ++k) d2_[k] = dot(samples_[k].p - q, samples_[k].p - q);
    constexpr std::size_t seeds = 8;
    std::pair<double, std::size_t> near[seeds];
    std::fill(std::begin(near), std::end(near), std::pair<double, std::size_t>{inf, 0});
    const int rows = nu_ + 1, cols = nv_ + 1;
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) {
        const std::size_t k = static_cast<std::size_t>(i * cols + j);
        const double e = d2_[k];
        if (!(e < near[seeds - 1].first)) continue;
        bool valley = true;
        for (int di = -1; di <= 1 && valley; ++di)
          for (int dj = -1; dj <= 1 && valley; ++dj) {
            int a = i + di;
            const int b = j + dj;
            if (closed_u_) a = (a + rows - 1) % (rows - 1);  // the rows u0 and u1 are one
            if ((di == 0 && dj == 0) || a < 0 || a >= rows || b < 0 || b >= cols) continue;
            valley = d2_[static_cast<std::size_t>(a * cols + b)] >= e;
          }
        if (!valley) continue;
        std::size_t m = seeds - 1;
        for (; m > 0 && near[m - 1].first > e; --m) near[m] = near[m - 1];
        near[m] = {e, k};
      }
    double best = inf;
    for (const auto& [e, k] : near)
      if (e < inf) best = std::min(best, descend(q, samples_[k].u, samples_[k].v, std::sqrt(e)));
    return best;
  }

 private:
  struct Sample {
    Vec3 p;
    double u, v;
  };

  double descend(const Vec3& q, double u, double v, double d) const {
    for (int it = 0; it < 100; ++it) {
      gp_Pnt p;
      gp_Vec su, sv, suu, svv, suv;
      s_->D2(u, v, p, su, sv, suu, svv, suv);
      const Vec3 r = vec(p) - q, a{su.X(), su.Y(), su.Z()}, b{sv.X(), sv.Y(), sv.Z()};
      const Vec3 aa2{suu.X(), suu.Y(), suu.Z()}, bb2{svv.X(), svv.Y(), svv.Z()}, ab2{suv.X(), suv.Y(), suv.Z()};
      const double ga = dot(r, a), gb = dot(r, b);
      double h11 = dot(a, a) + dot(r, aa2), h12 = dot(a, b) + dot(r, ab2), h22 = dot(b, b) + dot(r, bb2);
      if (!(h11 > 0 && h11 * h22 - h12 * h12 > 0)) {  // not convex here: Gauss–Newton
        h11 = dot(a, a);
        h12 = dot(a, b);
        h22 = dot(b, b);
      }
      const double det = h11 * h22 - h12 * h12;
      if (!(det > 0)) break;
      double du = (-ga * h22 + gb * h12) / det, dv = (-gb * h11 + ga * h12) / det;
      bool improved = false;
      for (int h = 0; h < 40 && !improved; ++h, du *= 0.5, dv *= 0.5) {
        double un = u + du;
        if (closed_u_)
          un = un < u0_ ? un + (u1_ - u0_) : un > u1_ ? un - (u1_ - u0_) : un;
        un = std::clamp(un, u0_, u1_);
        const double vn = std::clamp(v + dv, v0_, v1_);
        const double dn = interpatch::distance(vec(s_->Value(un, vn)), q);
        if (dn < d) {
          improved = d - dn > 1e-15 * size_;
          u = un;
          v = vn;
          d = dn;
        }
      }
      if (!improved) break;
    }
    return d;
  }

  static double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

  Handle(Geom_BSplineSurface) s_;
  double u0_ = 0, u1_ = 0, v0_ = 0, v1_ = 0, size_ = 0;
  bool closed_u_ = false;
  int nu_ = 0, nv_ = 0;                 // the sample grid: (nu_ + 1) × (nv_ + 1), u slowest
  mutable std::vector<double> d2_;      // squared distances to the samples, per query
  // Behind a pointer: OpenCASCADE's projector cannot be moved.
  std::unique_ptr<GeomAPI_ProjectPointOnSurf> proj_ = std::make_unique<GeomAPI_ProjectPointOnSurf>();
  std::vector<Sample> samples_;
};

// The area of the faces: Gauss–Legendre with 4 points each way on every knot span.
double area(const std::vector<Handle(Geom_BSplineSurface)>& faces) {
  constexpr double x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  constexpr double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  double total = 0;
  for (const auto& f : faces) {
    for (int i = 1; i < f->NbUKnots(); ++i)
      for (int j = 1; j < f->NbVKnots(); ++j) {
        const double ua = f->UKnot(i), ub = f->UKnot(i + 1), va = f->VKnot(j), vb = f->VKnot(j + 1);
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            gp_Pnt p;
            gp_Vec su, sv;
            f->D1(0.5 * (ua + ub) + 0.5 * (ub - ua) * x[a], 0.5 * (va + vb) + 0.5 * (vb - va) * x[b], p, su, sv);
            total += w[a] * w[b] * 0.25 * (ub - ua) * (vb - va) * su.Crossed(sv).Magnitude();
          }
      }
  }
  return total;
}

// Points of the faces on a grid of nu × nv each.
std::vector<Vec3> grid_points(const std::vector<Handle(Geom_BSplineSurface)>& faces, int nu, int nv) {
  std::vector<Vec3> out;
  for (const auto& f : faces) {
    double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    f->Bounds(u0, u1, v0, v1);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) out.push_back(vec(f->Value(u0 + (u1 - u0) * i / (nu - 1), v0 + (v1 - v0) * j / (nv - 1))));
  }
  return out;
}

struct Deviation {
  double max = 0, rms = 0;
  std::size_t points = 0, projection_missed = 0;
  json to_json() const { return {{"max", max}, {"rms", rms}, {"points", points}, {"projection_missed", projection_missed}}; }
};

// Distances to the nearest of the surfaces (the faces of one loft): the search on
// every face, then OpenCASCADE's projection on the nearest (projections cost most of
// the program's time); without `project` the search alone (for the surfaces'
// differences, far above rounding).
Deviation deviation(std::vector<Closest>& surfaces, const std::vector<Vec3>& points, bool project = true) {
  Deviation d;
  double sum2 = 0;
  for (const Vec3& q : points) {
    std::size_t nearest = 0;
    double best = inf;
    for (std::size_t i = 0; i < surfaces.size(); ++i)
      if (const double e = surfaces[i].search(q); e < best) {
        best = e;
        nearest = i;
      }
    if (project) {
      const double p = surfaces[nearest].projected(q);
      if (p > best + 1e-9 * surfaces[nearest].size()) ++d.projection_missed;
      best = std::min(best, p);
    }
    d.max = std::max(d.max, best);
    sum2 += best * best;
  }
  d.points = points.size();
  d.rms = points.empty() ? 0 : std::sqrt(sum2 / static_cast<double>(points.size()));
  return d;
}

std::vector<Vec3> data_points(const Case& c) {
  std::vector<Vec3> out;
  for (const Section& s : c.sections) out.insert(out.end(), s.points.begin(), s.points.end());
  return out;
}

// `m` points per curve at even parameters over its domain (the end of a closed one left out).
std::vector<Vec3> samples(const std::vector<BSplineCurve>& curves, int m) {
  std::vector<Vec3> out;
  for (const BSplineCurve& c : curves) {
    const auto [a, b] = c.domain();
    const int div = c.periodic() ? m : m - 1;
    for (int i = 0; i < m; ++i) out.push_back(c.point(a + (b - a) * i / div));
  }
  return out;
}
std::vector<Vec3> samples(const std::vector<Handle(Geom_BSplineCurve)>& curves, int m) {
  std::vector<Vec3> out;
  for (const auto& c : curves) {
    const double a = c->FirstParameter(), b = c->LastParameter();
    const int div = c->IsPeriodic() ? m : m - 1;
    for (int i = 0; i < m; ++i) out.push_back(vec(c->Value(a + (b - a) * i / div)));
  }
  return out;
}

// interpatch's surface along its own section lines: the distance from q to the curve
// S(·, v_k), found by sampling it and narrowing down by golden sections. It bounds the
// distance to the surface from above: a check of the closest-point figure.
double along_line(const BSplineSurface& s, double v, const Vec3& q) {
  constexpr int n = 4096;
  const auto [u0, u1] = s.domain_u();
  auto f = [&](double u) { return interpatch::distance(s.point(std::clamp(u, u0, u1), v), q); };
  int best = 0;
  double d = inf;
  for (int i = 0; i <= n; ++i)
    if (const double e = f(u0 + (u1 - u0) * i / n); e < d) {
      d = e;
      best = i;
    }
  double a = u0 + (u1 - u0) * std::max(best - 1, 0) / n, b = u0 + (u1 - u0) * std::min(best + 1, n) / n;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 80; ++it) {
    const double c = b - g * (b - a), e = a + g * (b - a);
    if (f(c) < f(e))
      b = e;
    else
      a = c;
  }
  return std::min(d, f(0.5 * (a + b)));
}

// ---------------------------------------------------------------- timing

template <class F>
double best_ms(int reps, F&& f) {
  double best = inf;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  return best;
}

struct Options {
  std::string spec = INTERPATCH_SOURCE_DIR "/examples/loft_wing.json";
  std::vector<std::string> cases{"wing", "duct", "duct_reversed"};
  std::vector<int> duct_counts{17, 23, 31, 40, 52, 61, 75, 90};
  int reps = 20;
  int samples = 400;
  std::string json_out;
  std::optional<double> tolerance;  // interpatch's loft tolerance (its default: 1e-7 of the diagonal)
};

std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

// ---------------------------------------------------------------- one case

json run_case(const Case& c, const Options& o) {
  std::printf("\n== %s: %s\n", c.name.c_str(), c.description.c_str());
  const std::vector<Vec3> data = data_points(c);
  json out = {{"case", c.name}, {"description", c.description}, {"sections", c.sections.size()}, {"points", data.size()}};
  json counts = json::array();
  for (const auto& s : c.sections) counts.push_back(s.points.size());
  out["points_per_section"] = counts;
  json rows = json::array();
  struct Row {
    std::string tool;
    double loft_ms = 0, job_ms = 0;
    std::string cps;
    Deviation data, curve;
    double area = 0, apart = -1;
    std::string note;
  };
  std::vector<Row> table;

  // The section curves of both tools, and how close each passes to its points.
  double ip_through = 0, occ_through = 0, apart_curves = 0;
  const std::vector<BSplineCurve> ip = ip_curves(c, &ip_through);
  const std::vector<Handle(Geom_BSplineCurve)> occ = occ_curves(c);
  for (std::size_t k = 0; k < ip.size(); ++k) {
    GeomAPI_ProjectPointOnCurve pc;
    pc.Init(occ[k], occ[k]->FirstParameter(), occ[k]->LastParameter());
    for (const Vec3& q : c.sections[k].points) {
      pc.Perform(pnt(q));
      occ_through = std::max(occ_through, pc.NbPoints() > 0 ? pc.LowerDistance() : inf);
    }
    // Same points, chord parameters and cubics both; OpenCASCADE's closed curve also
    // takes a tangent at its first point from a local cubic through its neighbours,
    // so the two curves differ between the points.
    for (const Vec3& q : samples(std::vector<BSplineCurve>{ip[k]}, o.samples)) {
      pc.Perform(pnt(q));
      apart_curves = std::max(apart_curves, pc.NbPoints() > 0 ? pc.LowerDistance() : inf);
    }
  }
  out["section_curves"] = {{"interpatch_through_points", ip_through},
                           {"occ_through_points", occ_through},
                           {"interpatch_from_occ", apart_curves},
                           {"occ_degree", occ.front()->Degree()}};
  std::printf("section curves: through their points within %.1e (interpatch) and %.1e (OpenCASCADE, degree %d); "
              "interpatch's within %.2g of OpenCASCADE's\n",
              ip_through, occ_through, occ.front()->Degree(), apart_curves);

  // interpatch.
  std::vector<Closest> ip_closest;
  {
    std::optional<interpatch::LoftSurface> made;
    interpatch::LoftOptions lo;
    lo.tolerance = o.tolerance;
    const double loft_ms = best_ms(o.reps, [&] { made = interpatch::loft(ip, lo); });
    const double job_ms = best_ms(o.reps, [&] {
      const auto cs = ip_curves(c);
      made = interpatch::loft(cs, lo);
    });
    const BSplineSurface& s = made->surface;
    const interpatch::LoftReport& r = made->report;
    const Handle(Geom_BSplineSurface) occ_form = to_occ(s);
    // The conversion is exact: both forms agree at random parameters up to rounding.
    double conversion = 0;
    unsigned seed = 12345;
    auto rnd = [&] { return (seed = seed * 1103515245u + 12345u) / 4294967296.0; };
    for (int i = 0; i < 2000; ++i) {
      const double u = rnd(), v = rnd();
      conversion = std::max(conversion, interpatch::distance(s.point(u, v), vec(occ_form->Value(u, v))));
    }
    ip_closest.emplace_back(occ_form);
    const Deviation dd = deviation(ip_closest, data);
    const Deviation dc = deviation(ip_closest, samples(ip, o.samples));
    // Along the surface's own section lines S(·, v_k): an upper bound of the data figure.
    double line_max = 0;
    for (std::size_t k = 0; k < c.sections.size(); ++k)
      for (const Vec3& q : c.sections[k].points) line_max = std::max(line_max, along_line(s, r.params[k], q));
    const double a = area({occ_form});
    const auto shape = s.control_points().shape();
    const std::size_t clamped_u = shape[0] + (s.periodic()[0] ? static_cast<std::size_t>(s.degree_u()) : 0);
    Row row{"interpatch loft", loft_ms, job_ms, std::to_string(shape[0]) + " x " + std::to_string(shape[1]), dd, dc, a, -1, ""};
    row.note = "degrees " + std::to_string(s.degree_u()) + "x" + std::to_string(s.degree_v()) +
               (s.periodic()[0] ? ", periodic in u (" + std::to_string(clamped_u) + " along u when clamped)" : "") +
               "; merged knots " + std::to_string(r.merged_knots) + " vs largest section's " +
               std::to_string(r.section_knots) + (r.reexpressed ? ": re-expressed" : ": merged") +
               ", section deviation " + fmt("%.2g", r.max_deviation) + " (tolerance " + fmt("%.2g", r.tolerance) +
               "); along its section lines max " + fmt("%.2g", line_max) + "; conversion to OCC " + fmt("%.1g", conversion);
    table.push_back(row);
    json reversed = json::array(), seams = json::array();
    for (const auto& sec : r.sections) {
      reversed.push_back(sec.reversed);
      seams.push_back(sec.closed ? sec.map(0.0) : 0.0);
    }
    rows.push_back({{"tool", "interpatch"},
                    {"loft_ms", loft_ms},
                    {"job_ms", job_ms},
                    {"control_points", {shape[0], shape[1]}},
                    {"control_points_u_clamped", clamped_u},
                    {"degree", {s.degree_u(), s.degree_v()}},
                    {"periodic", {s.periodic()[0], s.periodic()[1]}},
                    {"merged_knots", r.merged_knots},
                    {"section_knots", r.section_knots},
                    {"reexpressed", r.reexpressed},
                    {"section_deviation", r.max_deviation},
                    {"tolerance", r.tolerance},
                    {"diagonal", r.diagonal},
                    {"params", r.params},
                    {"reversed", reversed},
                    {"seam", seams},
                    {"data", dd.to_json()},
                    {"curve", dc.to_json()},
                    {"area", a},
                    {"along_section_lines_max", line_max},
                    {"conversion_max", conversion}});
  }

  // OpenCASCADE, with and without its compatibility check.
  for (const bool check : {true, false}) {
    const std::string name = check ? "OCC ThruSections (default)" : "OCC ThruSections, no check";
    const char* key = check ? "occ" : "occ_no_check";
    try {
      std::vector<Handle(Geom_BSplineSurface)> faces;
      const double loft_ms = best_ms(o.reps, [&] { faces = occ_loft(occ, check); });
      const double job_ms = best_ms(o.reps, [&] { faces = occ_loft(occ_curves(c), check); });
      std::vector<Closest> closest;
      std::string cps, note;
      json per_face = json::array();
      for (const auto& f : faces) {
        closest.emplace_back(f);
        cps += (cps.empty() ? "" : " + ") + std::to_string(f->NbUPoles()) + " x " + std::to_string(f->NbVPoles());
        per_face.push_back({{"control_points", {f->NbUPoles(), f->NbVPoles()}},
                            {"degree", {f->UDegree(), f->VDegree()}},
                            {"periodic", {bool(f->IsUPeriodic()), bool(f->IsVPeriodic())}},
                            {"rational", bool(f->IsURational() || f->IsVRational())}});
        note += (note.empty() ? "" : "; ") + std::string("degrees ") + std::to_string(f->UDegree()) + "x" +
                std::to_string(f->VDegree()) + (f->IsUPeriodic() ? ", periodic in u" : "") +
                (f->IsURational() || f->IsVRational() ? ", rational" : "");
      }
      if (faces.size() > 1) note += "; " + std::to_string(faces.size()) + " faces";
      const Deviation dd = deviation(closest, data);
      const Deviation dc = deviation(closest, samples(occ, o.samples));
      const double a = area(faces);
      const Deviation apart = deviation(ip_closest, grid_points(faces, 200, 20), false);
      table.push_back({name, loft_ms, job_ms, cps, dd, dc, a, apart.max, note});
      rows.push_back({{"tool", key},
                      {"loft_ms", loft_ms},
                      {"job_ms", job_ms},
                      {"faces", per_face},
                      {"data", dd.to_json()},
                      {"curve", dc.to_json()},
                      {"area", a},
                      {"from_interpatch", apart.to_json()}});
    } catch (const Standard_Failure& e) {
      table.push_back({name, 0, 0, "failed", {}, {}, 0, -1, e.GetMessageString()});
      rows.push_back({{"tool", key}, {"failed", e.GetMessageString()}});
    } catch (const std::exception& e) {
      table.push_back({name, 0, 0, "failed", {}, {}, 0, -1, e.what()});
      rows.push_back({{"tool", key}, {"failed", e.what()}});
    }
  }
  out["tools"] = rows;

  std::printf("%-27s %8s %8s %18s %9s %9s %9s %9s %9s %9s\n", "", "loft ms", "job ms", "control pts", "data max",
              "data rms", "curve max", "curve rms", "area", "apart");
  for (const Row& r : table) {
    if (r.cps == "failed") {
      std::printf("%-27s failed: %s\n", r.tool.c_str(), r.note.c_str());
      continue;
    }
    std::printf("%-27s %8.2f %8.2f %18s %9.2e %9.2e %9.2e %9.2e %9.5f %9s\n", r.tool.c_str(), r.loft_ms, r.job_ms,
                r.cps.c_str(), r.data.max, r.data.rms, r.curve.max, r.curve.rms, r.area,
                r.apart < 0 ? "-" : fmt("%.2e", r.apart).c_str());
  }
  for (const Row& r : table) {
    if (r.cps == "failed") continue;
    std::printf("  %s: %s", r.tool.c_str(), r.note.c_str());
    if (r.data.projection_missed + r.curve.projection_missed > 0)
      std::printf("; projection missed %zu data and %zu curve points (the search found them)", r.data.projection_missed,
                  r.curve.projection_missed);
    std::printf("\n");
  }
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--spec") {
      o.spec = value();
    } else if (a == "--cases") {
      o.cases.clear();
      std::stringstream ss(value());
      for (std::string x; std::getline(ss, x, ',');) o.cases.push_back(x);
    } else if (a == "--duct-counts") {
      o.duct_counts.clear();
      std::stringstream ss(value());
      for (std::string x; std::getline(ss, x, ',');) o.duct_counts.push_back(std::max(4, std::stoi(x)));
    } else if (a == "--reps") {
      o.reps = std::max(1, std::stoi(value()));
    } else if (a == "--samples") {
      o.samples = std::max(2, std::stoi(value()));
    } else if (a == "--json") {
      o.json_out = value();
    } else if (a == "--tolerance") {
      o.tolerance = std::stod(value());
    } else {
      throw std::runtime_error("usage: loft_compare [--spec LOFT.json] [--cases wing,duct,duct_reversed] "
                               "[--duct-counts 17,23,...] [--reps N] [--samples M] [--tolerance T] [--json OUT]");
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options o = parse(argc, argv);
    interpatch::bind_threads();
    std::printf("loft_compare: OpenCASCADE %s; best of %d runs; %d samples per section curve\n", OCC_VERSION_COMPLETE,
                o.reps, o.samples);
    json all = {{"occ_version", OCC_VERSION_COMPLETE}, {"reps", o.reps}, {"samples", o.samples}, {"cases", json::array()}};
    for (const std::string& name : o.cases) {
      Case c;
      if (name == "wing")
        c = read_spec(o.spec);
      else if (name == "duct" || name == "duct_reversed")
        c = make_duct(o.duct_counts, name == "duct_reversed");
      else
        throw std::runtime_error("unknown case " + name + " (wing, duct, duct_reversed)");
      all["cases"].push_back(run_case(c, o));
    }
    if (!o.json_out.empty()) {
      std::ofstream f(o.json_out);
      f << all.dump(2) << "\n";
      if (!f) throw std::runtime_error(o.json_out + ": cannot be written");
    }
  } catch (const Standard_Failure& e) {
    std::fprintf(stderr, "loft_compare: OpenCASCADE: %s\n", e.GetMessageString());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loft_compare: %s\n", e.what());
    return 1;
  }
  return 0;
}
