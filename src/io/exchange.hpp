#pragma once
// What the STEP and IGES writers share: the faces a form is written as, the
// tolerance that decides which boundaries coincide, numbers as CAD text, the time.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <ctime>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/error.hpp"
#include "interpatch/io/spec.hpp"

namespace interpatch::io::detail {

/// The shortest decimal text that reads back to the same double, in the form
/// both STEP and IGES require of a real: a decimal point always ("1." not "1"),
/// exponent letter E ("1.E-07").
inline void append_real(std::string& out, double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  const std::string_view s(buf, static_cast<std::size_t>(r.ptr - buf));
  const auto e = s.find('e');
  const std::string_view mantissa = s.substr(0, e);
  out += mantissa;
  if (mantissa.find('.') == std::string_view::npos) out += '.';
  if (e != std::string_view::npos) {
    out += 'E';
    out += s.substr(e + 1);
  }
}

inline std::string real_text(double v) {
  std::string s;
  append_real(s, v);
  return s;
}

/// A face as the writers write it. Its surface is over clamped knots, the only
/// kind STEP's and IGES's B-spline entities list: a direction that was periodic is
/// the open surface of its period, its first and last control lines on the seam
/// (BSplineSurface::clamped). `periodic` keeps which directions were; `side` is a
/// volume's side the face lies on (0..5: u0, u1, v0, v1, w0, w1; 0 for a surface).
struct Face {
  BSplineSurface surface;
  std::array<bool, 2> periodic{};
  int side = 0;
};

/// The boundary faces of a volume in the order u0, u1, v0, v1, w0, w1, each the
/// exact B-spline surface of that side of the clamped control net, parametrized as
/// the spec's faces are: u0/u1 by (v, w), v0/v1 by (u, w), w0/w1 by (u, v). The two
/// sides of a periodic direction are no boundary (they meet inside the volume, at
/// its seam) and are left out: a ring closed in u is bounded by v0, v1, w0 and w1,
/// each closed in u.
/// @throws error no_exact_form (closed in u, v and w: no boundary at all).
inline std::vector<Face> boundary_faces(const BSplineVolume& volume) {
  const std::array<bool, 3> closed = volume.periodic();
  if (closed[0] && closed[1] && closed[2])
    throw error(errc::no_exact_form,
                "a volume closed (periodic) in u, v and w has no boundary faces; STEP and IGES hold a volume as its "
                "boundary");
  const BSplineVolume b = volume.clamped();
  const auto& cp = b.control_points();
  const auto& w = b.weights();
  const std::size_t n[3] = {cp.extent(0), cp.extent(1), cp.extent(2)};
  const KnotVector* k[3] = {&b.knots_u(), &b.knots_v(), &b.knots_w()};
  std::vector<Face> faces;
  for (int axis = 0; axis < 3; ++axis) {
    if (closed[static_cast<std::size_t>(axis)]) continue;
    // The face's two parameter axes, in increasing order.
    const int a = axis == 0 ? 1 : 0, c = axis == 2 ? 1 : 2;
    for (const std::size_t at : {std::size_t{0}, n[axis] - 1}) {
      PointGrid fp({n[a], n[c]});
      Grid<double, 2> fw = w.empty() ? Grid<double, 2>() : Grid<double, 2>({n[a], n[c]});
      for (std::size_t i = 0; i < n[a]; ++i)
        for (std::size_t j = 0; j < n[c]; ++j) {
          std::size_t idx[3];
          idx[axis] = at;
          idx[a] = i;
          idx[c] = j;
          fp(i, j) = cp(idx[0], idx[1], idx[2]);
          if (!w.empty()) fw(i, j) = w(idx[0], idx[1], idx[2]);
        }
      faces.push_back({BSplineSurface(*k[a], *k[c], std::move(fp), std::move(fw)),
                       {closed[static_cast<std::size_t>(a)], closed[static_cast<std::size_t>(c)]},
                       2 * axis + (at == 0 ? 0 : 1)});
    }
  }
  return faces;
}

/// The faces a form is written as: the surface itself, or a volume's boundary faces.
inline std::vector<Face> faces_of(const ExactForm& exact) {
  if (const auto* s = std::get_if<BSplineSurface>(&exact)) return {{s->clamped(), s->periodic(), 0}};
  return boundary_faces(std::get<BSplineVolume>(exact));
}

/// Distance below which two control points count as the same point: 1e-10 of the
/// control net's bounding-box diagonal. Rounding in the constructions (and in the
/// clamped form of a periodic direction) leaves pole rows, seams and shared
/// boundaries equal to ~1e-15 of it; real features are far above.
inline double coincidence_tolerance(const std::vector<Face>& faces) {
  Vec3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const auto& f : faces)
    for (const Vec3& p : f.surface.control_points().values())
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], p[d]);
        hi[d] = std::max(hi[d], p[d]);
      }
  return std::max(1e-10 * norm(hi - lo), 1e-300);
}

/// Whether the first and last rows (axis 0) or columns (axis 1) of the control net
/// coincide: the surface closes on itself in u (axis 0) or v (axis 1).
inline bool closed_in(const BSplineSurface& s, int axis, double tol) {
  const auto& cp = s.control_points();
  const std::size_t n = cp.extent(0), m = cp.extent(1);
  const std::size_t count = axis == 0 ? m : n;
  for (std::size_t t = 0; t < count; ++t) {
    const Vec3 a = axis == 0 ? cp(0, t) : cp(t, 0);
    const Vec3 b = axis == 0 ? cp(n - 1, t) : cp(t, m - 1);
    if (norm(a - b) > tol) return false;
  }
  return true;
}

/// Whether a face is closed in u (axis 0) or v (axis 1): periodic there, or its
/// control net closing on itself (closed_in).
inline bool closed(const Face& f, int axis, double tol) {
  return f.periodic[static_cast<std::size_t>(axis)] || closed_in(f.surface, axis, tol);
}

/// Distinct knots and their multiplicities, in order.
struct KnotRuns {
  std::vector<double> values;
  std::vector<int> multiplicities;
};

inline KnotRuns knot_runs(const KnotVector& k) {
  KnotRuns r;
  for (const double t : k.values()) {
    if (!r.values.empty() && t == r.values.back()) {
      ++r.multiplicities.back();
    } else {
      r.values.push_back(t);
      r.multiplicities.push_back(1);
    }
  }
  return r;
}

/// The current UTC time in a strftime format (std::gmtime_r: thread-safe).
inline std::string utc_now(const char* format) {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  return std::string(buf, std::strftime(buf, sizeof buf, format, &tm));
}

/// Text for a CAD header: printable ASCII kept, anything else (control
/// characters, bytes of multi-byte UTF-8) replaced by '_'.
inline std::string printable_ascii(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '_';
  return out;
}

}  // namespace interpatch::io::detail
