#!/usr/bin/env python3
"""Independent reference values for interpatch's closed (periodic) interpolation, computed with SciPy.

Rerun (the result must agree with the checked-in file, to 1e-12 of the scale as
same_reference.py says; CTest checks it
with tests/reference_check.cmake when python3-scipy is installed):

    python3 tools/reference/make_periodic_reference.py -o tests/data/periodic_reference.json

Needs python3-numpy and python3-scipy (Debian's; SciPy 1.10 was used). Runs in a
few seconds. The JSON writer is make_reference.py's (imported from beside this
file), so both reference files have one format.

What is computed
----------------
Closed curves and grids closed in u, in v or in both, interpolated by the rules of
interpatch's interpolate_curve / interpolate_surface with `periodic`:

* Parameters over the closed polygon, closing chord included, computed here in
  double precision from the points as written to the JSON: for N distinct points
  Q_0..Q_{N-1} and Q_N := Q_0, d_k = |Q_k - Q_{k-1}| (k = 1..N; centripetal:
  sqrt(d_k); uniform: 1), t_0 = 0, t_k = (d_1 + ... + d_k) / (d_1 + ... + d_N) for
  k < N, and t_N = 1 is the first point again. A case "with a closing point" gives
  the library N + 1 points, the last an exact copy of the first; the reference is
  the same curve (the closing point is dropped).
* Grids: along a closed direction every line of points gets such parameters, lines
  of zero length are left out, the rest are averaged (sum / count); along an open
  direction the open chord parameters of every line are averaged the same way
  (The NURBS Book eq. 9.5) and the knots are the clamped averaged ones (eq. 9.8).
  A grid "with a closing line" repeats its first line of the closed direction at
  the end (exactly); that line is dropped.
* Knots of a closed direction of degree p, period [s, s + 1) extended periodically:
  odd p: the parameters t_0..t_{N-1} themselves (s = t_0 = 0); even p: the
  midpoints m_k = (t_k + t_{k+1}) / 2, k = 0..N-1, t_N = 1 (s = m_0). interpatch
  inserts 0 as an extra knot for even p, which changes no point of the curve.

How the numbers are made
------------------------
* Odd p >= 3, curves: scipy.interpolate.make_interp_spline(x, y, k=p,
  bc_type="periodic") with x = [t_0, ..., t_{N-1}, 1] and y the distinct points
  with the first repeated at the end. SciPy's periodic knots for odd k are x
  extended periodically, the same spline space as interpatch's, and SciPy solves
  the cyclic system its own way (Woodbury formula around a banded LAPACK solve).
* Every p (and the only way for p = 1 and even p, where make_interp_spline uses
  other knots: its even-k knots are x_0 and the midpoints of all intervals but the
  last): the collocation matrix on the extended knots from
  scipy.interpolate.BSpline.design_matrix, basis function i + N folded onto
  column i, solved densely with scipy.linalg.solve (LAPACK gesv). For odd p >= 3
  both ways are computed and must agree to 1e-12 of the scale (checked).
* Grids: S(u, v) = I_v[ j -> I_u[Q[., j]](u) ](v): every line along u is
  interpolated (one SciPy call on all lines at once) and evaluated at u, and the
  values along v are interpolated and evaluated at v; S_u the same with the u
  derivative. By linearity of interpolation this is the tensor-product
  interpolant; the script checks it against the opposite order (v first) to 1e-12.
* Evaluation by scipy.interpolate.BSpline with extrapolate="periodic" (SciPy's
  own de Boor evaluation and its own wrapping of t into the period), at parameters
  in [-0.3, 1.3] along closed directions (across the seam, wrapped), [0, 1] along
  open ones, the data parameters, the seam itself and points 1e-9 on either side.
* Derivatives of orders 1..p-1 are stored (continuous everywhere, so no one-sided
  ambiguity at knots); curves up to order 2, grids S_u and S_v.
* Checked here before writing (AssertionError otherwise): interpolation at every
  data point to 1e-12 of the scale, derivatives of orders 1..p-1 equal at both
  ends of the period (SciPy with extrapolate=False, evaluated at both knots of the
  seam) to 1e-9 of the largest derivative, the two solves / orders agree.
* Inputs are random but seeded (Python's random.Random, whose stream is fixed
  across Python versions), rounded to 12 significant digits so that the JSON holds
  them exactly as used. Output numbers are repr(float).

Why interpatch is compared at 1e-12 relative: both sides are double-precision
solves of the same well-conditioned system (periodic collocation of at most 40
unknowns per line; 2-norm condition numbers 1 to 31 for these cases, the largest
for degree 5 on the most uneven parameters), from the same doubles; what separates
them is rounding of order 1e-16 times that condition number. A wrong knot, a
parameter off by a closing chord or a mis-wrapped control point moves points by
1e-3 or more.

Cases
-----
curves : closed 3-D loops (perturbed ellipses, a trefoil knot, a loop with very
         uneven spacing), 5 to 40 points; degrees 1..5 (mostly 3); uniform, chord
         and centripetal parameters; with and without a closing point.
         Stored: points as given to the library, params of the distinct points,
         and C, C', C'' (orders <= p-1) at every evaluation parameter.
grids  : torus-like and pipe-like grids of 5..9 lines, closed in u, in v and in
         both, degrees (3, 3) and some (2, 3), (3, 2), (4, 3), (3, 5); some with a
         closing line along u, along v or both. Stored: the grid as given to the library (u index first),
         params of the distinct lines, S, S_u, S_v (orders <= p-1) at evaluation
         pairs.
"""

import argparse
import contextlib
import math
import os
import random
import sys

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline
from scipy.linalg import solve

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_reference import fmt  # noqa: E402  (the project's one JSON writer)

AGREE = 1e-12       # two independent double-precision solves, relative to the scale
SEAM = 1e-9         # derivative continuity at the seam, relative to the largest derivative


def r12(x):
    """x rounded to 12 significant digits (the double the JSON holds)."""
    return float(f"{x:.12g}")


def scale_of(pts):
    a = np.asarray(pts, dtype=float).reshape(-1, 3)
    return float(np.linalg.norm(a.max(axis=0) - a.min(axis=0)))


# ----------------------------------------------------------------------------
# parameters and knots
# ----------------------------------------------------------------------------

def chord(a, b):
    dx, dy, dz = (a[0] - b[0], a[1] - b[1], a[2] - b[2])
    return math.sqrt(dx * dx + dy * dy + dz * dz)


def steps(pts, kind, closed):
    """The N (closed) or N-1 (open) steps of a polyline, or None when it has zero length."""
    n = len(pts)
    pairs = [(pts[k - 1], pts[k % n]) for k in range(1, n + 1 if closed else n)]
    if kind == "uniform":
        return [1.0] * len(pairs)
    d = [chord(a, b) for a, b in pairs]
    if kind == "centripetal":
        d = [math.sqrt(x) for x in d]
    return d if sum(d) > 0 else None


def line_params(pts, kind, closed):
    """Parameters of one line: closed, N values in [0, 1); open, N values 0..1."""
    d = steps(pts, kind, closed)
    if d is None:
        return None
    n = len(pts)
    if kind == "uniform":
        return [k / (n if closed else n - 1) for k in range(n)]
    total, acc, out = sum(d), 0.0, [0.0]
    for s in d[:n - 1]:
        acc += s
        out.append(acc / total)
    if not closed:
        out[-1] = 1.0
    return out


def averaged(lines, kind, closed):
    ps = [lp for lp in (line_params(ln, kind, closed) for ln in lines) if lp is not None]
    assert ps, "every line has zero length"
    return [sum(col) / len(ps) for col in zip(*ps)]


def periodic_extended_knots(params, p):
    """Extended knots (N + 2p + 1) of the closed spline of degree p through params."""
    n = len(params)
    if p % 2 == 1:
        period = list(params)
    else:
        nxt = list(params[1:]) + [params[0] + 1.0]
        period = [(a + b) / 2 for a, b in zip(params, nxt)]
    start = period[0]
    end = start + 1.0
    return ([period[n - p + i] - 1.0 for i in range(p)] + period + [end]
            + [period[i] + 1.0 for i in range(1, p + 1)]), start


def open_averaged_knots(params, p):
    n = len(params) - 1
    src = params[1:n]
    interior = [sum(src[j:j + p]) / p for j in range(len(src) - p + 1)]
    return [params[0]] * (p + 1) + interior + [params[-1]] * (p + 1)


# ----------------------------------------------------------------------------
# interpolation with SciPy
# ----------------------------------------------------------------------------

def closed_by_collocation(params, Y, p):
    """Closed spline through Y (N rows, any trailing shape) by a folded collocation solve."""
    Y = np.asarray(Y, dtype=float)
    n = len(params)
    t, start = periodic_extended_knots(params, p)
    t = np.asarray(t)
    x = np.array([s + 1.0 if s < start else s for s in params])
    A = BSpline.design_matrix(x, t, p).toarray()
    assert A.shape == (n, n + p)
    for i in range(p):
        A[:, i] += A[:, n + i]
    c = solve(A[:, :n], Y.reshape(n, -1)).reshape(Y.shape)
    return BSpline(t, np.concatenate([c, c[:p]]), p, extrapolate="periodic")


def closed_by_make_interp_spline(params, Y, p):
    Y = np.asarray(Y, dtype=float)
    x = np.array(list(params) + [params[0] + 1.0])
    return make_interp_spline(x, np.concatenate([Y, Y[:1]]), k=p, bc_type="periodic")


def check_close(a, b, scale, what):
    err = float(np.max(np.abs(np.asarray(a) - np.asarray(b))))
    assert err <= AGREE * scale, f"{what}: {err} > {AGREE} * {scale}"


def interp_closed(params, Y, p, scale):
    """The closed spline: make_interp_spline for odd p >= 3 (checked against the
    collocation solve), the collocation solve otherwise."""
    col = closed_by_collocation(params, Y, p)
    if p % 2 == 1 and p >= 3:
        mis = closed_by_make_interp_spline(params, Y, p)
        probe = np.linspace(-0.3, 1.3, 97)
        check_close(mis(probe), col(probe), scale, "make_interp_spline vs collocation")
        return mis
    return col


def interp_open(params, Y, p):
    Y = np.asarray(Y, dtype=float)
    return make_interp_spline(np.asarray(params), Y, k=p, t=np.asarray(open_averaged_knots(params, p)))


def check_curve(spl, params, Y, p, scale):
    """Interpolation at the data and C^(p-1) across the seam."""
    check_close(spl(np.asarray(params)), Y, scale, "interpolation at the data")
    bare = BSpline(spl.t, spl.c, spl.k, extrapolate=False)
    n = len(spl.t) - p - 1
    a, b = spl.t[p], spl.t[n]
    assert abs((b - a) - 1.0) < 1e-14
    for k in range(1, p):
        d = bare.derivative(k)
        big = float(np.max(np.abs(d(np.linspace(a, b, 257)))))
        jump = float(np.max(np.abs(d(a) - d(b))))
        assert jump <= SEAM * big, f"derivative {k} jumps by {jump} across the seam"


# ----------------------------------------------------------------------------
# data
# ----------------------------------------------------------------------------

def loop_points(rng, n, shape):
    """n distinct points around a closed 3-D loop, rounded to 12 digits."""
    r = rng.uniform(0.5, 3.0)
    pts = []
    if shape == "uneven":
        # angles with steps varying by a factor ~20: chord, centripetal and uniform differ a lot
        w = [rng.uniform(0.1, 2.0) for _ in range(n)]
        acc, ang = 0.0, []
        for x in w:
            ang.append(acc)
            acc += x
        ang = [2 * math.pi * a / acc for a in ang]
    else:
        ang = [2 * math.pi * (k + rng.uniform(-0.3, 0.3)) / n for k in range(n)]
    for a in ang:
        if shape == "trefoil":
            p = (math.sin(a) + 2 * math.sin(2 * a), math.cos(a) - 2 * math.cos(2 * a), -math.sin(3 * a))
        else:
            p = (1.6 * math.cos(a), math.sin(a), 0.4 * math.sin(2 * a))
        noise = (0.01 if shape == "uneven" else 0.1) * math.pi / n   # well below the smallest step
        pts.append(tuple(r12(r * (c + rng.uniform(-noise, noise)) + off)
                         for c, off in zip(p, (0.5, -1.25, 2.0))))
    return pts


def closed_grid(rng, nu, nv, periodic):
    """A (nu, nv) grid, closed along u and/or v: a torus, or a pipe (closed in one)."""
    R, r = rng.uniform(2.0, 4.0), rng.uniform(0.5, 1.5)
    q = np.zeros((nu, nv, 3))
    for i in range(nu):
        for j in range(nv):
            su = (i + rng.uniform(-0.25, 0.25)) / nu
            sv = (j + rng.uniform(-0.25, 0.25)) / nv
            if periodic == (True, True):
                a, b = 2 * math.pi * su, 2 * math.pi * sv
                p = ((R + r * math.cos(b)) * math.cos(a), (R + r * math.cos(b)) * math.sin(a), r * math.sin(b))
            else:
                # the closed direction goes around, the open one along the axis
                a = 2 * math.pi * (su if periodic[0] else sv)
                h = 3.0 * (sv if periodic[0] else su)
                rad = r * (1.0 + 0.3 * h)
                p = (rad * math.cos(a), 0.7 * rad * math.sin(a), h + 0.2 * math.sin(a))
            q[i, j] = [r12(c + rng.uniform(-0.05, 0.05)) for c in p]
    return q


def eval_params(rng, closed, params, count):
    """Evaluation parameters: spread over [-0.3, 1.3] (closed) or [0, 1] (open), the
    data parameters, the seam and 1e-9 either side of it (closed)."""
    lo, hi = (-0.3, 1.3) if closed else (0.0, 1.0)
    ts = [lo + (hi - lo) * (k + rng.uniform(0.0, 1.0)) / count for k in range(count)]
    ts += list(params)
    if closed:
        ts += [0.0, 1.0, -1e-9, 1e-9, 1.0 - 1e-9, 1.0 + 1e-9, params[1] + 1.0, params[-1] - 1.0]
    else:
        ts += [0.0, 1.0]
    return sorted(set(float(t) for t in ts))


# ----------------------------------------------------------------------------
# cases
# ----------------------------------------------------------------------------

CURVES = [
    # name, seed, points, degree, parametrization, shape, closing point
    ("ellipse5_deg3_chord", 1, 5, 3, "chord", "ellipse", False),
    ("ellipse6_deg3_uniform_closing", 2, 6, 3, "uniform", "ellipse", True),
    ("ellipse7_deg3_centripetal", 3, 7, 3, "centripetal", "ellipse", False),
    ("trefoil12_deg3_chord_closing", 4, 12, 3, "chord", "trefoil", True),
    ("trefoil17_deg3_centripetal_closing", 5, 17, 3, "centripetal", "trefoil", True),
    ("uneven9_deg3_chord", 6, 9, 3, "chord", "uneven", False),
    ("uneven25_deg3_centripetal", 7, 25, 3, "centripetal", "uneven", False),
    ("uneven11_deg3_uniform", 8, 11, 3, "uniform", "uneven", False),
    ("trefoil40_deg3_chord", 9, 40, 3, "chord", "trefoil", False),
    ("ellipse33_deg3_uniform_closing", 10, 33, 3, "uniform", "ellipse", True),
    ("ellipse8_deg1_chord", 11, 8, 1, "chord", "ellipse", False),
    ("ellipse5_deg2_chord", 12, 5, 2, "chord", "ellipse", False),
    ("uneven10_deg2_centripetal_closing", 13, 10, 2, "centripetal", "uneven", True),
    ("trefoil14_deg4_chord", 14, 14, 4, "chord", "trefoil", False),
    ("ellipse6_deg5_uniform", 15, 6, 5, "uniform", "ellipse", False),
    ("uneven20_deg5_chord_closing", 16, 20, 5, "chord", "uneven", True),
]

GRIDS = [
    # name, seed, (nu, nv), (pu, pv), periodic (u, v), parametrization, closing line (u, v)
    ("pipe_u_7x5_deg33_chord", 21, (7, 5), (3, 3), (True, False), "chord", (False, False)),
    ("pipe_v_5x8_deg33_centripetal_closing", 22, (5, 8), (3, 3), (False, True), "centripetal", (False, True)),
    ("torus_6x7_deg33_chord", 23, (6, 7), (3, 3), (True, True), "chord", (False, False)),
    ("torus_8x6_deg33_uniform_closing_both", 24, (8, 6), (3, 3), (True, True), "uniform", (True, True)),
    ("pipe_v_6x9_deg23_chord", 25, (6, 9), (2, 3), (False, True), "chord", (False, False)),
    ("pipe_u_9x5_deg32_centripetal_closing", 26, (9, 5), (3, 2), (True, False), "centripetal", (True, False)),
    ("torus_7x6_deg43_centripetal", 27, (7, 6), (4, 3), (True, True), "centripetal", (False, False)),
    ("torus_6x8_deg35_chord_closing_v", 28, (6, 8), (3, 5), (True, True), "chord", (False, True)),
]


def curve_cases():
    out = []
    for name, seed, n, p, kind, shape, closing in CURVES:
        rng = random.Random(seed)
        Q = loop_points(rng, n, shape)
        Y = np.array(Q)
        scale = scale_of(Q)
        t = line_params(Q, kind, True)
        spl = interp_closed(t, Y, p, scale)
        check_curve(spl, t, Y, p, scale)
        ts = eval_params(rng, True, t, 61)
        ev = {"t": ts, "points": spl(np.array(ts)).tolist()}
        for k in range(1, min(p - 1, 2) + 1):
            ev[f"d{k}"] = spl.derivative(k)(np.array(ts)).tolist()
        given = Q + [Q[0]] if closing else Q
        out.append({"name": name, "degree": p, "param": kind, "closing_point": closing,
                    "points": [list(q) for q in given], "params": t, "eval": ev})
    return out


def tensor_eval(q, degrees, per, params, uv, scale, first):
    """S(u, v) and its partials (uv = (u, v)) from interpolating along `first`
    (0: u) then along the other direction."""
    def interp(axis, Y):
        if per[axis]:
            return interp_closed(params[axis], Y, degrees[axis], scale)
        return interp_open(params[axis], Y, degrees[axis])
    second = 1 - first
    lines = interp(first, q if first == 0 else np.swapaxes(q, 0, 1))  # every line along `first` at once
    across = interp(second, lines(uv[first]))  # through the lines' points at uv[first]
    res = {"point": across(uv[second])}
    names = ("du", "dv")
    if degrees[second] >= 2:
        res[names[second]] = across.derivative(1)(uv[second])
    if degrees[first] >= 2:
        res[names[first]] = interp(second, lines.derivative(1)(uv[first]))(uv[second])
    return res


def grid_cases():
    out = []
    for name, seed, (nu, nv), (pu, pv), per, kind, closing in GRIDS:
        rng = random.Random(seed)
        q = closed_grid(rng, nu, nv, per)
        scale = scale_of(q)
        lines_u = [[tuple(q[i, j]) for i in range(nu)] for j in range(nv)]
        lines_v = [[tuple(q[i, j]) for j in range(nv)] for i in range(nu)]
        params = (averaged(lines_u, kind, per[0]), averaged(lines_v, kind, per[1]))
        for i in range(nu):
            for j in range(nv):
                got = tensor_eval(q, (pu, pv), per, params, (params[0][i], params[1][j]), scale, 0)
                check_close(got["point"], q[i, j], scale, f"{name}: interpolation at [{i}][{j}]")
        us = eval_params(rng, per[0], params[0], 9)
        vs = eval_params(rng, per[1], params[1], 9)
        pairs = [(u, v) for u in us for v in vs]
        pairs = [pr for k, pr in enumerate(pairs) if k % 3 == 0]   # a third of the product
        ev = {"u": [], "v": [], "points": []}
        if pu >= 2:
            ev["du"] = []
        if pv >= 2:
            ev["dv"] = []
        for u, v in pairs:
            a = tensor_eval(q, (pu, pv), per, params, (u, v), scale, 0)
            b = tensor_eval(q, (pu, pv), per, params, (u, v), scale, 1)
            check_close(a["point"], b["point"], scale, f"{name}: u first vs v first")
            ev["u"].append(u)
            ev["v"].append(v)
            ev["points"].append(a["point"].tolist())
            for key in ("du", "dv"):
                if key in a:
                    check_close(a[key], b[key], scale * 100, f"{name}: {key} u first vs v first")
                    ev[key].append(a[key].tolist())
        given = q
        if closing[0]:
            given = np.concatenate([given, given[:1]], axis=0)
        if closing[1]:
            given = np.concatenate([given, given[:, :1]], axis=1)
        out.append({"name": name, "degree": [pu, pv], "periodic": list(per), "param": kind,
                    "closing_line": list(closing), "shape": list(given.shape[:2]),
                    "points": given.reshape(-1, 3).tolist(),
                    "params_u": params[0], "params_v": params[1], "eval": ev})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("-o", "--output", help="write here instead of standard output")
    args = ap.parse_args()
    doc = {"generator": "tools/reference/make_periodic_reference.py", "format": 1,
           "curves": curve_cases(), "grids": grid_cases()}
    sink = open(args.output, "w", encoding="ascii", newline="\n") if args.output else contextlib.nullcontext(sys.stdout)
    with sink as f:
        f.write(fmt(doc) + "\n")


if __name__ == "__main__":
    main()
