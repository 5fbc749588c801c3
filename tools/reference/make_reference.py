#!/usr/bin/env python3
"""Independent reference values for interpatch, computed in exact arithmetic.

Rerun (the result must agree with the checked-in file, to 1e-12 of the scale as
same_reference.py says; CTest checks it
with tests/reference_check.cmake):

    python3 tools/reference/make_reference.py > tests/data/reference.json
    python3 tools/reference/make_reference.py -o tests/data/reference.json

Pure Python 3 standard library (fractions, decimal, json); runs in a few seconds.

How the numbers are made
------------------------
* Every input (point coordinate, knot, parameter, weight, derivative) is first
  rounded to the double that is written to the JSON file, and the reference is
  computed exactly from that double (Fraction(float(x))). The library reads the
  same doubles, so the only difference left is the library's own rounding.
* Everything rational is exact (fractions.Fraction). Square roots (chord lengths,
  centripetal parameters) are computed with the decimal module at 50 significant
  digits and converted to Fraction. Chord/centripetal parameters are then rounded
  to a multiple of 2^-128 (about 3e-39) to keep the Fractions small; both
  perturbations are more than 20 orders of magnitude below double resolution.
* Output numbers are repr(float(Fraction)): the correctly rounded double.
* Every case is checked inside this script in exact arithmetic before it is
  written (partition of unity, interpolation at the data, unchanged geometry
  after knot insertion / degree elevation, Hermite end conditions); a failed
  check aborts with an AssertionError.

Formulas (The NURBS Book, Piegl & Tiller, 2nd ed.; seeds 003/004)
--------------------------------------------------------------------
* Basis functions by the Cox-de Boor recursion written from its definition
  (eq. 2.5), not by the triangular table (A2.2) the library uses:
    N_{i,0}(t) = 1 if u_i <= t < u_{i+1} else 0; at the right end of the domain
                 the last non-empty span is closed (N = 1 there),
    N_{i,p}(t) = (t-u_i)/(u_{i+p}-u_i) N_{i,p-1}(t)
               + (u_{i+p+1}-t)/(u_{i+p+1}-u_{i+1}) N_{i+1,p-1}(t),   0/0 := 0.
  Derivatives by the textbook formula (eq. 2.7, applied k times, eq. 2.9):
    N^{(k)}_{i,p} = p ( N^{(k-1)}_{i,p-1}/(u_{i+p}-u_i)
                      - N^{(k-1)}_{i+1,p-1}/(u_{i+p+1}-u_{i+1}) ),  0/0 := 0.
  At an interior knot the values are those of the span to the right (the span
  KnotVector::find_span returns), so one-sided derivatives come from the right.
* Parameters (eq. 9.4/9.5): uniform k/n; chord d_k = |Q_k - Q_{k-1}|,
  u_k = sum_{i<=k} d_i / sum d_i; centripetal the same with sqrt(d_k).
* Knots by averaging (eq. 9.8): clamped, u_0..u_p = 0, u_{m-p}..u_m = 1 and the
  interior knots are the averages of p consecutive parameters taken from a list
    no end derivatives:            ubar_1 .. ubar_{n-1}      (eq. 9.8)
    start derivative only:         ubar_0 .. ubar_{n-1}
    end derivative only:           ubar_1 .. ubar_n
    both end derivatives:          ubar_0 .. ubar_n          (eq. 9.22)
  (every window of p consecutive entries of that list gives one interior knot).
* Curve interpolation: dense Gaussian elimination in Fractions of
  sum_i N_{i,p}(ubar_k) P_i = Q_k, plus sum_i N'_{i,p}(0) P_i = D_0 and/or
  sum_i N'_{i,p}(1) P_i = D_n when end derivatives are given.
* Surface interpolation through Q[p][q] (p = 0..n along u, q = 0..m along v),
  tensor-product interpolation: u-parameters are the averages over
  q of the parameters of the line Q[0..n][q]; v-parameters the averages over p
  of the parameters of the line Q[p][0..m]; lines of zero total length (a
  pole: all points equal) are left out of the average. Knots by averaging in
  each direction. Control points: solve every line along v (rows), then the
  i-th control points of all rows across u; in exact arithmetic this is the
  unique solution of the tensor-product collocation system, and the script
  checks S(u_p, v_q) == Q[p][q] exactly.
* Cubic Hermite functions : a0 = 1-3g^2+2g^3,
  a1 = 3g^2-2g^3, b0 = g-2g^2+g^3, b1 = -g^2+g^3 and derivatives (orders 0..3).
  Piecewise Hermite curve on params t_i with h_i = t_{i+1}-t_i, g = (t-t_i)/h_i:
  C(t) = P_i a0 + P_{i+1} a1 + h_i T_i b0 + h_i T_{i+1} b1; Catmull-Rom tangents
  T_i = (P_{i+1}-P_{i-1})/(t_{i+1}-t_{i-1}) inside and one-sided differences
  (P_1-P_0)/(t_1-t_0), (P_n-P_{n-1})/(t_n-t_{n-1}) at the ends. Exact B-spline
  form: knots t_0 x4, t_1 x2, ..., t_n x4; control points P_0, then per segment
  P_i + h_i T_i/3, P_{i+1} - h_i T_{i+1}/3, then P_n.
* Knot insertion by Boehm's formula on homogeneous points (w P, w), one knot at
  a time: for t in [u_k, u_{k+1}), Q_i = a_i P_i + (1-a_i) P_{i-1} with
  a_i = (t-u_i)/(u_{i+p}-u_i) for k-p+1 <= i <= k, Q_i = P_i below, P_{i-1} above.
* Degree elevation by t: the knot vector with every distinct knot's multiplicity
  raised by t; control points from exact least squares (normal equations in
  Fractions) on q+1 equally spaced points inside every non-empty span of the
  elevated knots (q = p+t) of the homogeneous curve. The original curve lies in
  the elevated space, so the residual is exactly zero (checked): the result is
  the unique exact elevated curve, found independently of any elevation
  algorithm (and not at Greville abscissae, which the library uses).

Cases
-----
basis      : degree 1; degree 2 on [-1, 2]; degree 2 with a double interior knot
             (C0); degree 3 uniform; degree 3 with a double interior knot (C1);
             degree 5. Every basis function, first and second derivative at the
             domain ends, at every knot and at points inside spans.
curves     : 6 points degree 3 chord; 5 points degree 2 centripetal; 7 points
             degree 3 uniform; 6 points degree 3 chord with both end derivatives;
             the same with only the start / only the end derivative; 9 points
             degree 4 chord; 6 points degree 5 chord (one Bezier segment).
             Stored: params, knots, control points, and C, C' at sample params.
surfaces   : 4x5 grid degrees (2,3) chord; 7x13 grid bicubic chord; 6x9
             hemisphere (u from the pole (0,0,1) to the equator, row p = 0 all
             equal to the pole, v once around with uneven steps) bicubic
             centripetal; 5x5 grid degrees (1,1) uniform; 6x7 grid degrees (5,5)
             chord. Stored: params, knots, control points, and S, S_u, S_v at
             sample parameters.
hermite    : the four functions and their derivatives (orders 0..3) at several g;
             piecewise curves with Catmull-Rom tangents on given params, on
             default (uniform) params, and with given tangents: tangents, params,
             exact B-spline form, and C, C', C'' at sample params (C'' only
             strictly inside segments, where it is continuous).
refinement : a cubic space curve (insert a new knot once, twice, an existing knot
             once; elevate by 1 and by 2) and a rational quadratic 240-degree arc of
             the unit circle in two 120-degree spans, weights 1, 1/2, 1, 1/2, 1
             (insert two knots; elevate by 1). Stored: exact control points and
             weights after each operation and points at many params (identical
             for every version of the curve).
"""

import argparse
import math
import sys
from decimal import Decimal, localcontext
from fractions import Fraction as F
from functools import lru_cache

DIGITS = 50          # significant digits of square roots
QUANTUM = 2 ** 128   # chord/centripetal parameters are rounded to multiples of 1/QUANTUM


# ----------------------------------------------------------------------------
# numbers
# ----------------------------------------------------------------------------

def dbl(x):
    """The exact value of the double nearest x (x: int, Fraction or float)."""
    return F(float(F(x)))


def dvec(v):
    return tuple(dbl(c) for c in v)


def sqrt_f(x):
    """sqrt of a non-negative Fraction to DIGITS significant digits, as a Fraction."""
    if x == 0:
        return F(0)
    with localcontext() as ctx:
        ctx.prec = DIGITS
        r = (Decimal(x.numerator) / Decimal(x.denominator)).sqrt()
    return F(r)


def quantize(x):
    return F(round(x * QUANTUM), QUANTUM)


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def scale(s, a):
    return tuple(s * x for x in a)


def zero(dim=3):
    return tuple(F(0) for _ in range(dim))


def dist2(a, b):
    return sum((x - y) ** 2 for x, y in zip(a, b))


# ----------------------------------------------------------------------------
# B-spline basis: Cox-de Boor from the definition
# ----------------------------------------------------------------------------

class Basis:
    def __init__(self, p, knots):
        self.p = p
        self.U = tuple(knots)
        self.n = len(self.U) - p - 2  # index of the last basis function
        assert self.n >= p

    def span(self, t):
        U, p = self.U, self.p
        a, b = U[p], U[self.n + 1]
        assert a <= t <= b, (t, a, b)
        if t == b:
            return max(s for s in range(p, self.n + 1) if U[s] < U[s + 1])
        return max(s for s in range(p, self.n + 1) if U[s] <= t and U[s] < U[s + 1])

    @lru_cache(maxsize=None)
    def N(self, i, p, t):
        U = self.U
        if p == 0:
            return F(1) if i == self.span(t) else F(0)
        r = F(0)
        d1 = U[i + p] - U[i]
        if d1 != 0:
            r += (t - U[i]) / d1 * self.N(i, p - 1, t)
        d2 = U[i + p + 1] - U[i + 1]
        if d2 != 0:
            r += (U[i + p + 1] - t) / d2 * self.N(i + 1, p - 1, t)
        return r

    @lru_cache(maxsize=None)
    def D(self, i, p, k, t):
        """k-th derivative of N_{i,p} at t."""
        if k == 0:
            return self.N(i, p, t)
        if k > p:
            return F(0)
        U = self.U
        r = F(0)
        d1 = U[i + p] - U[i]
        if d1 != 0:
            r += self.D(i, p - 1, k - 1, t) / d1
        d2 = U[i + p + 1] - U[i + 1]
        if d2 != 0:
            r -= self.D(i + 1, p - 1, k - 1, t) / d2
        return p * r

    def all(self, t, k=0):
        return [self.D(i, self.p, k, t) for i in range(self.n + 1)]

    def curve(self, cps, t, k=0):
        """d^k/dt^k of sum N_i P_i (polynomial or homogeneous)."""
        acc = zero(len(cps[0]))
        for i, c in enumerate(self.all(t, k)):
            if c != 0:
                acc = add(acc, scale(c, cps[i]))
        return acc


def rational_point(basis, cps, weights, t):
    h = [scale(w, c) + (w,) for c, w in zip(cps, weights)]
    a = basis.curve(h, t)
    return tuple(x / a[3] for x in a[:3])


# ----------------------------------------------------------------------------
# linear algebra: dense Gaussian elimination in Fractions
# ----------------------------------------------------------------------------

def solve(A, B):
    """Solves A X = B exactly; A is n x n, B is n rows of r-vectors (tuples)."""
    n = len(A)
    A = [list(row) for row in A]
    B = [list(row) for row in B]
    for k in range(n):
        piv = next((i for i in range(k, n) if A[i][k] != 0), None)
        assert piv is not None, "singular collocation matrix"
        A[k], A[piv] = A[piv], A[k]
        B[k], B[piv] = B[piv], B[k]
        cols = [j for j in range(k, n) if A[k][j] != 0]
        for i in range(k + 1, n):
            if A[i][k] == 0:
                continue
            f = A[i][k] / A[k][k]
            for j in cols:
                A[i][j] -= f * A[k][j]
            B[i] = [x - f * y for x, y in zip(B[i], B[k])]
    X = [None] * n
    for k in range(n - 1, -1, -1):
        acc = list(B[k])
        for j in range(k + 1, n):
            if A[k][j] != 0:
                acc = [x - A[k][j] * y for x, y in zip(acc, X[j])]
        X[k] = tuple(x / A[k][k] for x in acc)
    return X


# ----------------------------------------------------------------------------
# parameters, knots, interpolation
# ----------------------------------------------------------------------------

def line_params(pts, kind):
    """Parameters of one polyline, or None when its total length is zero."""
    n = len(pts) - 1
    if kind == "uniform":
        return [F(k, n) for k in range(n + 1)]
    d = []
    for a, b in zip(pts, pts[1:]):
        s = sqrt_f(dist2(a, b))
        if kind == "centripetal":
            s = sqrt_f(s)
        d.append(s)
    total = sum(d)
    if total == 0:
        return None
    out, acc = [F(0)], F(0)
    for s in d[:-1]:
        acc += s
        out.append(acc / total)
    out.append(F(1))
    return out


def averaged_params(lines, kind):
    """Average of the parameters of every line of non-zero length."""
    ps = [lp for lp in (line_params(ln, kind) for ln in lines) if lp is not None]
    assert ps, "every line has zero length"
    avg = [sum(col) / len(ps) for col in zip(*ps)]
    if kind == "uniform":
        return avg
    avg = [quantize(x) for x in avg]
    avg[0], avg[-1] = F(0), F(1)
    return avg


def averaged_knots(params, p, start=False, end=False):
    n = len(params) - 1
    lo = 0 if start else 1
    hi = n if end else n - 1
    src = params[lo:hi + 1]
    interior = [sum(src[j:j + p]) / p for j in range(len(src) - p + 1)]
    return [params[0]] * (p + 1) + interior + [params[-1]] * (p + 1)


def interpolate(points, params, knots, p, d_start=None, d_end=None):
    b = Basis(p, knots)
    rows, rhs = [], []
    for k, (t, q) in enumerate(zip(params, points)):
        if k == len(points) - 1 and d_end is not None:
            rows.append(b.all(t, 1))
            rhs.append(d_end)
        rows.append(b.all(t))
        rhs.append(q)
        if k == 0 and d_start is not None:
            rows.append(b.all(t, 1))
            rhs.append(d_start)
    assert len(rows) == b.n + 1
    cps = solve(rows, rhs)
    for t, q in zip(params, points):
        assert b.curve(cps, t) == q
    if d_start is not None:
        assert b.curve(cps, params[0], 1) == d_start
    if d_end is not None:
        assert b.curve(cps, params[-1], 1) == d_end
    return b, cps


# ----------------------------------------------------------------------------
# output helpers
# ----------------------------------------------------------------------------

def num(x):
    return float(x)


def nums(xs):
    return [float(x) for x in xs]


def pts(ps):
    return [nums(p) for p in ps]


def sample_params(a, b, count):
    """count doubles spread unevenly over [a, b], ends included."""
    out = []
    for k in range(count):
        s = F(k, count - 1)
        s = s + s * (1 - s) * F(1, 5)   # uneven, still increasing, ends fixed
        out.append(dbl(a + (b - a) * s))
    return out


# ----------------------------------------------------------------------------
# a) basis functions
# ----------------------------------------------------------------------------

def basis_cases():
    specs = [
        ("degree1", 1, [0, 0, F(3, 10), F(1, 2), 1, 1], [F(1, 10), F(2, 5), F(9, 10)]),
        ("degree2_domain_m1_2", 2, [-1, -1, -1, 0, F(1, 2), F(5, 4), 2, 2, 2],
         [F(-7, 10), F(1, 3), F(3, 2), F(199, 100)]),
        ("degree2_double_knot", 2, [0, 0, 0, F(2, 5), F(2, 5), F(7, 10), 1, 1, 1],
         [F(1, 5), F(1, 2), F(9, 10)]),
        ("degree3_uniform", 3, [0, 0, 0, 0, F(1, 4), F(1, 2), F(3, 4), 1, 1, 1, 1],
         [F(1, 10), F(3, 8), F(2, 3), F(99, 100)]),
        ("degree3_double_knot", 3, [0, 0, 0, 0, F(1, 5), F(1, 2), F(1, 2), F(4, 5), 1, 1, 1, 1],
         [F(1, 10), F(3, 10), F(3, 5), F(19, 20)]),
        ("degree5", 5, [0] * 6 + [F(3, 10), F(11, 20), F(3, 5)] + [1] * 6,
         [F(1, 20), F(1, 5), F(9, 20), F(57, 100), F(4, 5)]),
    ]
    out = []
    for name, p, knots, extra in specs:
        U = [dbl(u) for u in knots]
        b = Basis(p, U)
        ts = sorted(set(U) | {dbl(t) for t in extra})
        samples = []
        for t in ts:
            vals = [b.all(t, k) for k in range(3)]
            assert sum(vals[0]) == 1 and sum(vals[1]) == 0 and sum(vals[2]) == 0
            assert all(v >= 0 for v in vals[0])
            samples.append({"t": num(t), "span": b.span(t),
                            "values": nums(vals[0]), "d1": nums(vals[1]), "d2": nums(vals[2])})
        out.append({"name": name, "degree": p, "knots": nums(U), "samples": samples})
    return out


# ----------------------------------------------------------------------------
# b) curve interpolation
# ----------------------------------------------------------------------------

def curve_cases():
    P6 = [(0, 0, 0), (1, 2, 0), (3, 3, F(1, 2)), (4, 1, 1), (6, 0, F(1, 2)), (7, F(5, 2), 0)]
    P5 = [(0, 0, 0), (F(1, 2), 2, 0), (3, F(5, 2), F(1, 4)), (F(7, 2), 0, 1), (6, F(1, 8), 0)]
    P7 = [(k, (k * k) % 5 - F(3, 2), F(k, 4) - (k % 2)) for k in range(7)]
    P9 = [(k + F(k * k, 16), 3 * ((k * 3) % 4) - k, F((k * 5) % 7, 8)) for k in range(9)]
    specs = [
        ("six_points_degree3_chord", P6, 3, "chord", None, None),
        ("five_points_degree2_centripetal", P5, 2, "centripetal", None, None),
        ("seven_points_degree3_uniform", P7, 3, "uniform", None, None),
        ("six_points_degree3_chord_both_derivatives", P6, 3, "chord", (10, 8, 0), (5, 9, -2)),
        ("six_points_degree3_chord_start_derivative", P6, 3, "chord", (10, 8, 0), None),
        ("six_points_degree3_chord_end_derivative", P6, 3, "chord", None, (5, 9, -2)),
        ("nine_points_degree4_chord", P9, 4, "chord", None, None),
        ("six_points_degree5_chord", P6, 5, "chord", None, None),
    ]
    out = []
    for name, P, p, kind, ds, de in specs:
        Q = [dvec(q) for q in P]
        ds = dvec(ds) if ds is not None else None
        de = dvec(de) if de is not None else None
        params = line_params(Q, kind)
        if kind != "uniform":
            params = [quantize(x) for x in params]
        knots = averaged_knots(params, p, ds is not None, de is not None)
        b, cps = interpolate(Q, params, knots, p, ds, de)
        evals = []
        for t in sample_params(0, 1, 9):
            evals.append({"t": num(t), "point": nums(b.curve(cps, t)), "d1": nums(b.curve(cps, t, 1))})
        case = {"name": name, "degree": p, "param": kind, "points": pts(Q)}
        if ds is not None:
            case["start_derivative"] = nums(ds)
        if de is not None:
            case["end_derivative"] = nums(de)
        case.update({"params": nums(params), "knots": nums(knots), "control_points": pts(cps), "eval": evals})
        out.append(case)
    return out


# ----------------------------------------------------------------------------
# c) surface interpolation
# ----------------------------------------------------------------------------

def grid_a(p, q):    # 4 x 5
    return (p + F(p * p, 8), q + F(p * q, 16), F((p + 2 * q) % 5, 4))


def grid_b(p, q):    # 7 x 13
    return (p + F(p * p, 16), F(3 * q, 4) + F(p % 2, 8), F((p * p + 3 * q) % 7, 8) - F(q, 16))


def grid_c(p, q):    # 5 x 5
    return (p + F(q, 4), q - F(p, 8), F((p * q) % 3, 2))


def grid_d(p, q):    # 6 x 7
    return (p + F(q * q, 16), q + F(p * p, 32), F((2 * p + q) % 4, 4))


# Hemisphere: latitude from tan(phi/2) = 0, 1/5, ..., 1 (pole to equator, uneven
# steps); longitude once around through rational points of the unit circle.
HEMI_LAT = [F(k, 5) for k in range(6)]
HEMI_LON = [(1, 0), (F(12, 13), F(5, 13)), (F(3, 5), F(4, 5)), (0, 1), (F(-15, 17), F(8, 17)),
            (-1, 0), (F(-4, 5), F(-3, 5)), (0, -1), (1, 0)]


def grid_hemisphere(p, q):
    t = HEMI_LAT[p]
    s, c = 2 * t / (1 + t * t), (1 - t * t) / (1 + t * t)   # sin(phi), cos(phi)
    x, y = HEMI_LON[q]
    return (s * x, s * y, c)


def surface_cases():
    specs = [
        ("grid4x5_degree2x3_chord", grid_a, 4, 5, (2, 3), "chord"),
        ("grid7x13_bicubic_chord", grid_b, 7, 13, (3, 3), "chord"),
        ("hemisphere6x9_bicubic_centripetal", grid_hemisphere, 6, 9, (3, 3), "centripetal"),
        ("grid5x5_degree1x1_uniform", grid_c, 5, 5, (1, 1), "uniform"),
        ("grid6x7_degree5x5_chord", grid_d, 6, 7, (5, 5), "chord"),
    ]
    out = []
    for name, f, nu, nv, (du, dv), kind in specs:
        Q = [[dvec(f(p, q)) for q in range(nv)] for p in range(nu)]
        if f is grid_hemisphere:
            assert all(Q[0][q] == (0, 0, 1) for q in range(nv))
        pu = averaged_params([[Q[p][q] for p in range(nu)] for q in range(nv)], kind)
        pv = averaged_params([[Q[p][q] for q in range(nv)] for p in range(nu)], kind)
        ku = averaged_knots(pu, du)
        kv = averaged_knots(pv, dv)
        bu, bv = Basis(du, ku), Basis(dv, kv)
        Av = [bv.all(t) for t in pv]
        Au = [bu.all(t) for t in pu]
        rows = [solve(Av, Q[p]) for p in range(nu)]                       # stage 1: along v
        cols = [solve(Au, [rows[p][j] for p in range(nu)]) for j in range(nv)]  # stage 2: across
        P = [[cols[j][i] for j in range(nv)] for i in range(nu)]

        def S(u, v, ku_=0, kv_=0):
            Nu, Nv = bu.all(u, ku_), bv.all(v, kv_)
            acc = zero()
            for i, a in enumerate(Nu):
                if a == 0:
                    continue
                for j, c in enumerate(Nv):
                    if c != 0:
                        acc = add(acc, scale(a * c, P[i][j]))
            return acc

        for p in range(nu):
            for q in range(nv):
                assert S(pu[p], pv[q]) == Q[p][q], (name, p, q)
        evals = []
        for u, v in zip(sample_params(0, 1, 6), reversed(sample_params(0, 1, 6))):
            evals.append({"u": num(u), "v": num(v), "point": nums(S(u, v)),
                          "du": nums(S(u, v, 1, 0)), "dv": nums(S(u, v, 0, 1))})
        out.append({"name": name, "degree": [du, dv], "param": kind,
                    "points": [pts(row) for row in Q],
                    "params_u": nums(pu), "params_v": nums(pv),
                    "knots_u": nums(ku), "knots_v": nums(kv),
                    "control_points": [pts(row) for row in P], "eval": evals})
    return out


# ----------------------------------------------------------------------------
# d) Hermite
# ----------------------------------------------------------------------------

def hermite_functions(g, order):
    """(a0, a1, b0, b1) or their order-th derivative at g."""
    polys = {  # coefficients of 1, g, g^2, g^3
        "a0": [1, 0, -3, 2], "a1": [0, 0, 3, -2], "b0": [0, 1, -2, 1], "b1": [0, 0, -1, 1]}
    out = []
    for key in ("a0", "a1", "b0", "b1"):
        c = [F(x) for x in polys[key]]
        for _ in range(order):
            c = [k * c[k] for k in range(1, len(c))] or [F(0)]
        out.append(sum(ck * g ** k for k, ck in enumerate(c)))
    return out


def hermite_basis_cases():
    out = []
    for g in [F(0), F(1, 8), F(1, 4), F(1, 3), F(1, 2), F(7, 10), F(1)]:
        g = dbl(g)
        vals = [hermite_functions(g, k) for k in range(4)]
        assert vals[0][0] + vals[0][1] == 1
        out.append({"g": num(g), "values": [nums(v) for v in vals]})
    return out


def hermite_eval(P, T, t_nodes, t, order):
    n = len(P) - 1
    i = max(k for k in range(n) if t_nodes[k] <= t) if t < t_nodes[-1] else n - 1
    h = t_nodes[i + 1] - t_nodes[i]
    g = (t - t_nodes[i]) / h
    a0, a1, b0, b1 = hermite_functions(g, order)
    r = add(add(scale(a0, P[i]), scale(a1, P[i + 1])), add(scale(h * b0, T[i]), scale(h * b1, T[i + 1])))
    return scale(1 / h ** order, r)


def catmull_rom(P, t):
    n = len(P) - 1
    T = [scale(1 / (t[1] - t[0]), sub(P[1], P[0]))]
    for i in range(1, n):
        T.append(scale(1 / (t[i + 1] - t[i - 1]), sub(P[i + 1], P[i - 1])))
    T.append(scale(1 / (t[n] - t[n - 1]), sub(P[n], P[n - 1])))
    return T


def hermite_curve_cases():
    specs = [
        ("catmull_rom_given_params",
         [(0, 0, 0), (1, 2, 0), (3, F(5, 2), 1), (4, 0, F(1, 2)), (F(11, 2), 1, 0)],
         [-1, F(-1, 2), F(1, 4), 1, 2], None),
        ("catmull_rom_uniform_params",
         [(0, 0, 0), (2, 1, 0), (3, 3, 1), (1, 4, 2)], None, None),
        ("given_tangents",
         [(0, 0, 0), (1, 1, 0), (2, 0, 1)], [0, F(3, 10), 1],
         [(1, 0, 0), (F(1, 2), -2, 1), (0, 1, F(1, 4))]),
    ]
    out = []
    for name, Praw, traw, Traw in specs:
        P = [dvec(x) for x in Praw]
        n = len(P) - 1
        t = [dbl(x) for x in traw] if traw is not None else [dbl(F(k, n)) for k in range(n + 1)]
        T = [dvec(x) for x in Traw] if Traw is not None else catmull_rom(P, t)
        for i in range(n + 1):
            assert hermite_eval(P, T, t, t[i], 0) == P[i]
            assert hermite_eval(P, T, t, t[i], 1) == T[i]
        # exact cubic B-spline form, interior knots doubled
        knots = [t[0]] * 4 + [x for x in t[1:-1] for _ in range(2)] + [t[-1]] * 4
        cps = [P[0]]
        for i in range(n):
            h = t[i + 1] - t[i]
            cps.append(add(P[i], scale(h / 3, T[i])))
            cps.append(sub(P[i + 1], scale(h / 3, T[i + 1])))
        cps.append(P[n])
        bs = Basis(3, knots)
        evals = []
        for x in sorted(set(sample_params(t[0], t[-1], 11)) | set(t)):
            e = {"t": num(x), "point": nums(hermite_eval(P, T, t, x, 0)),
                 "d1": nums(hermite_eval(P, T, t, x, 1))}
            if x not in t:
                e["d2"] = nums(hermite_eval(P, T, t, x, 2))
            assert bs.curve(cps, x) == hermite_eval(P, T, t, x, 0)
            assert bs.curve(cps, x, 1) == hermite_eval(P, T, t, x, 1)
            evals.append(e)
        case = {"name": name, "points": pts(P)}
        if traw is not None:
            case["params"] = nums(t)
        if Traw is not None:
            case["tangents"] = pts(T)
        case.update({"expected_params": nums(t), "expected_tangents": pts(T),
                     "bspline": {"knots": nums(knots), "control_points": pts(cps)}, "eval": evals})
        out.append(case)
    return out


# ----------------------------------------------------------------------------
# e) knot insertion and degree elevation
# ----------------------------------------------------------------------------

def homogeneous(cps, w):
    return [scale(wi, c) + (wi,) for c, wi in zip(cps, w)]


def cartesian(h):
    return [tuple(x / c[3] for x in c[:3]) for c in h], [c[3] for c in h]


def boehm(p, U, H, t):
    """Insert t once (Boehm): new knots and homogeneous control points."""
    k = max(s for s in range(p, len(U) - p - 1) if U[s] <= t and U[s] < U[s + 1])
    Q = []
    for i in range(len(H) + 1):
        if i <= k - p:
            Q.append(H[i])
        elif i >= k + 1:
            Q.append(H[i - 1])
        else:
            a = (t - U[i]) / (U[i + p] - U[i])
            Q.append(add(scale(a, H[i]), scale(1 - a, H[i - 1])))
    return U[:k + 1] + [t] + U[k + 1:], Q


def elevate(p, U, H, times):
    q = p + times
    V = []
    for u in sorted(set(U)):
        V += [u] * (U.count(u) + times)
    bo, bn = Basis(p, U), Basis(q, V)
    sites = []
    for s in range(q, len(V) - q - 1):
        if V[s] < V[s + 1]:
            sites += [V[s] + (V[s + 1] - V[s]) * F(j + 1, q + 2) for j in range(q + 1)]
    A = [bn.all(x) for x in sites]
    B = [bo.curve(H, x) for x in sites]
    m = bn.n + 1
    AtA = [[sum(A[r][i] * A[r][j] for r in range(len(A))) for j in range(m)] for i in range(m)]
    AtB = [tuple(sum(A[r][i] * B[r][c] for r in range(len(A))) for c in range(4)) for i in range(m)]
    G = solve(AtA, AtB)
    for x, b in zip(sites, B):
        assert bn.curve(G, x) == b, "elevated curve differs from the original"
    return V, G


def refinement_cases():
    sqrt3 = F(math.sqrt(3))  # IEEE sqrt is correctly rounded: the same double everywhere
    specs = [
        ("cubic_space_curve", 3, [0, 0, 0, 0, F(3, 10), F(1, 2), 1, 1, 1, 1],
         [(0, 0, 0), (1, 2, 0), (F(5, 2), 3, 1), (4, F(3, 2), 2), (5, -1, 1), (7, 0, 0)], None,
         [(F(7, 10), 1), (F(7, 10), 2), (F(1, 2), 1)], [1, 2]),
        ("rational_circle_arc_240deg", 2, [0, 0, 0, F(1, 2), F(1, 2), 1, 1, 1],
         [(F(-1, 2), -sqrt3 / 2, 0), (1, -sqrt3, 0), (1, 0, 0), (1, sqrt3, 0), (F(-1, 2), sqrt3 / 2, 0)],
         [1, F(1, 2), 1, F(1, 2), 1],
         [(F(1, 4), 1), (F(3, 4), 1)], [1]),
    ]
    out = []
    for name, p, knots, cp_raw, w_raw, inserts, elevations in specs:
        U = [dbl(u) for u in knots]
        C = [dvec(c) for c in cp_raw]
        W = [dbl(w) for w in w_raw] if w_raw is not None else [F(1)] * len(C)
        H = homogeneous(C, W)
        b = Basis(p, U)
        ts = sample_params(U[0], U[-1], 17)
        ref = [rational_point(b, C, W, x) for x in ts]
        rational = w_raw is not None

        def record(p_, V, G):
            cps, ws = cartesian(G)
            bb = Basis(p_, V)
            for x, r in zip(ts, ref):
                assert rational_point(bb, cps, ws, x) == r
            d = {"knots": nums(V), "control_points": pts(cps)}
            if rational:
                d["weights"] = nums(ws)
            else:
                assert all(wi == 1 for wi in ws)
            return d

        ins = []
        for t, times in inserts:
            t = dbl(t)
            V, G = list(U), H
            for _ in range(times):
                V, G = boehm(p, V, G, t)
            ins.append(dict({"t": num(t), "times": times}, **record(p, V, G)))
        els = []
        for times in elevations:
            V, G = elevate(p, U, H, times)
            els.append(dict({"times": times}, **record(p + times, V, G)))
        case = {"name": name, "degree": p, "knots": nums(U), "control_points": pts(C)}
        if rational:
            case["weights"] = nums(W)
            assert all(abs(dist2(r, (0, 0, 0)) - 1) < F(1, 10 ** 15) for r in ref)  # on the unit circle
        case.update({"eval_params": nums(ts), "eval_points": pts(ref), "insertions": ins, "elevations": els})
        out.append(case)
    return out


# ----------------------------------------------------------------------------
# JSON writer: deterministic, lists of numbers on one line
# ----------------------------------------------------------------------------

def fmt(x, indent=0):
    pad = " " * indent
    if isinstance(x, bool) or x is None:
        return {True: "true", False: "false", None: "null"}[x]
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        r = repr(x)
        assert r not in ("nan", "inf", "-inf")
        return r
    if isinstance(x, str):
        assert x.isascii() and '"' not in x and "\\" not in x
        return '"' + x + '"'
    if isinstance(x, dict):
        if not x:
            return "{}"
        items = [pad + "  " + fmt(k) + ": " + fmt(v, indent + 2) for k, v in x.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(x, list):
        inline = "[" + ", ".join(fmt(v) for v in x) + "]"
        if not any(isinstance(v, dict) for v in x) and "\n" not in inline and len(inline) <= 100:
            return inline
        items = [pad + "  " + fmt(v, indent + 2) for v in x]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    raise TypeError(type(x))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", help="write here instead of standard output")
    args = ap.parse_args()
    doc = {
        "generator": "tools/reference/make_reference.py",
        "format": 1,
        "basis": basis_cases(),
        "curves": curve_cases(),
        "surfaces": surface_cases(),
        "hermite_basis": hermite_basis_cases(),
        "hermite_curves": hermite_curve_cases(),
        "refinement": refinement_cases(),
    }
    text = fmt(doc) + "\n"
    if args.output:
        with open(args.output, "w", encoding="ascii", newline="\n") as f:
            f.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
