#pragma once
// The terms of a blended surface (include/interpatch/blended_surface.hpp):
//   S = Σ_k f_k(u) a_k(v) + Σ_l b_l(u) g_l(v) + Σ_kl c_kl f_k(u) g_l(v) + Gregory terms.
// Scalar functions f, g are B-spline curves whose x coordinate is the value; every
// function and curve is over [0, 1].

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "interpatch/blended_surface.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/grid.hpp"

namespace interpatch::detail {

/// Gregory's correction at corner (i, j): the twist term −β_i(u) β_j(v) T with
/// T = tv + w (tu − tv), w = |u−i| / (|u−i| + |v−j|): tv = d/du S_v(u, j) along the
/// edge u = i, tu = d/dv S_u(i, v) along v = j.
struct GregoryCorner {
  int i, j;
  Vec3 tu, tv;
};

/// A scalar function of one parameter on [0, 1]: a B-spline (exact form: its value
/// is the x coordinate), or a callable f(t, order) returning the value (order 0)
/// or a derivative (1, 2), which has no exact form.
struct Scalar {
  std::optional<BSplineCurve> spline;
  std::function<double(double, int)> fn;

  Scalar(BSplineCurve s) : spline(std::move(s)) {}  // NOLINT: a B-spline is a scalar function
  explicit Scalar(std::function<double(double, int)> f) : fn(std::move(f)) {}
  /// Value and first two derivatives at t.
  void eval(double t, double out[3]) const;
};

struct BlendedTerms {
  std::vector<Scalar> f;
  std::vector<BSplineCurve> a;  // a empty, or one curve of v per f
  std::vector<Scalar> g;
  std::vector<BSplineCurve> b;  // b empty, or one curve of u per g
  Grid<Vec3, 2> c;                 // |f| × |g| or empty
  std::vector<GregoryCorner> gregory;
  std::vector<std::string> notes;
};

/// A scalar B-spline function as a curve whose x coordinate is the value.
BSplineCurve scalar(KnotVector knots, const std::vector<double>& coefficients);
/// 1 − f for a scalar function f.
Scalar one_minus(const Scalar& f);
/// A blending function as a scalar: its B-spline, or its callable.
Scalar scalar(const Blend& f);
/// The cubic Hermite functions α0, α1, β0, β1 on [0, 1] as scalar Bézier functions
/// (α0 = B0 + B1, α1 = B2 + B3, β0 = B1/3, β1 = −B2/3).
std::vector<Scalar> hermite_scalars();
/// The curve over [0, 1].
BSplineCurve unit(const BSplineCurve& c);

/// Value and first two derivatives of a function of one parameter: of a curve (D3),
/// of a scalar (S3).
struct D3 {
  Vec3 v[3];
};
struct S3 {
  double v[3];
};

inline D3 eval(const BSplineCurve& c, double t) {
  D3 d;
  c.derivatives(t, 2, d.v);
  return d;
}

// The row kernel of the exact conversions (to_bspline of BlendedSurface and
// BlendedVolume): every control point of a row is a short sum of terms of two
// kinds, a line of points times a number and a point times a line of numbers, and
// is written once, summed in the order the terms are given, whichever thread fills
// its row.

/// s · a[i] along a row (a: three doubles a point).
struct LineTerm {
  double s;
  const double* a;
};

/// g[3i] · p along a row, each number of the line given three times (g[3i] = g[3i+1]
/// = g[3i+2]) and p four times: four points are then twelve products of equal
/// numbers with p4, as those of a line term are.
struct PointTerm {
  const double* g;
  double p4[12];
  PointTerm(const double* g3, const Vec3& p) : g(g3) {
    for (int c = 0; c < 12; ++c) p4[c] = p[c % 3];
  }
};

/// o[i] = Σ line terms + Σ point terms, in that order, i < n (o: three doubles a
/// point). Four points at a time are summed in registers over all terms, so the
/// row is read from no memory but the terms' and written once.
void sum_terms(double* o, std::size_t n, const std::vector<LineTerm>& lines, const std::vector<PointTerm>& points);

/// Fills the row o[0..n) (three doubles a point) a stretch of at most 256 points at a
/// time, so that a term of local support is left out of the stretches where it is
/// zero: terms(y0, y1, lines, points) lists, in the empty vectors, the terms over
/// [y0, y1), their lines and numbers starting at y0.
template <class Terms>
void fill_row(double* o, std::size_t n, std::vector<LineTerm>& lines, std::vector<PointTerm>& points, Terms terms) {
  constexpr std::size_t stretch = 256;
  for (std::size_t y0 = 0; y0 < n; y0 += stretch) {
    const std::size_t y1 = std::min(n, y0 + stretch);
    lines.clear();
    points.clear();
    terms(y0, y1, lines, points);
    sum_terms(o + 3 * y0, y1 - y0, lines, points);
  }
}

/// The B-spline coefficients of a scalar function, and the range [lo, hi) outside
/// which they are all zero: a blend of local support (a Coons network's cardinal
/// functions) is added only where it is not zero, and knot insertion keeps zero
/// coefficients exactly zero.
struct Coefficients {
  std::vector<double> c;  // each coefficient three times, as PointTerm takes them
  std::size_t lo = 0, hi = 0;
};
Coefficients coefficients(const BSplineCurve& f);

}  // namespace interpatch::detail
