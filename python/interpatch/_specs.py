"""NumPy-native constructors: each makes the spec the command line reads
(docs/spec-format.md), with its arrays passed in memory rather than written to
files, and builds it. Same semantics, defaults and errors as the command line;
the messages name the spec's fields (/points, /u_curves/2, ...)."""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from ._core import Error as Error_
from ._core import build as _build


class _Arrays:
    """The arrays of one spec, each named where the spec takes it."""

    def __init__(self) -> None:
        self.table: dict[str, np.ndarray] = {}

    def add(self, points: Any) -> dict[str, str]:
        name = f"a{len(self.table)}"
        self.table[name] = np.asarray(points)
        return {"array": name}


def _point(p: Any) -> list[float]:
    a = np.asarray(p, dtype=np.float64).reshape(-1)
    return [float(x) for x in a]


class Curve:
    """A curve of a spec (a Coons side, a network curve, a ruled surface's curve):
    make one with interpolate_curve, bspline_curve, hermite_curve or line."""

    def __init__(self, make) -> None:
        self._make = make

    def _spec(self, arrays: _Arrays) -> dict[str, Any]:
        return self._make(arrays)


def interpolate_curve(points: Any, degree: Optional[int] = None, param: str = "chord",
                      periodic: bool = False, start_derivative: Any = None, end_derivative: Any = None) -> Curve:
    """The B-spline curve through `points` (shape (n, 3)), as the spec's
    {"interpolate": ...} curve: degree min(3, n - 1) unless given, chord-length
    parameters unless `param` says otherwise, closed with periodic=True, with given
    end derivatives (over the curve's [0, 1]) if any.

    Example: c = interpatch.interpolate_curve(np.array([[0, 0, 0], [1, 2, 0], [3, 3, 0]]))"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        s: dict[str, Any] = {"interpolate": arrays.add(points), "param": param}
        if degree is not None:
            s["degree"] = int(degree)
        if periodic:
            s["periodic"] = True
        if start_derivative is not None:
            s["start_derivative"] = _point(start_derivative)
        if end_derivative is not None:
            s["end_derivative"] = _point(end_derivative)
        return s

    return Curve(make)


def bspline_curve(degree: int, knots: Sequence[float], control_points: Any,
                  weights: Optional[Sequence[float]] = None, periodic: bool = False) -> Curve:
    """A B-spline curve given by its degree, knots and control points (shape (n, 3)),
    rational with `weights`, closed with periodic=True (knots as the spec's
    {"bspline": ...} curve takes them)."""

    def make(arrays: _Arrays) -> dict[str, Any]:
        b: dict[str, Any] = {"degree": int(degree), "knots": [float(x) for x in knots],
                             "control_points": arrays.add(control_points)}
        if weights is not None:
            b["weights"] = [float(x) for x in weights]
        if periodic:
            b["periodic"] = True
        return {"bspline": b}

    return Curve(make)


def hermite_curve(points: Any, tangents: Any = None, params: Optional[Sequence[float]] = None) -> Curve:
    """The piecewise cubic Hermite curve through `points` with `tangents` (both shape
    (n, 3); Catmull–Rom tangents when not given) at `params` (equally spaced by default)."""

    def make(arrays: _Arrays) -> dict[str, Any]:
        h: dict[str, Any] = {"points": arrays.add(points)}
        if tangents is not None:
            h["tangents"] = arrays.add(tangents)
        if params is not None:
            h["params"] = [float(x) for x in params]
        return {"hermite": h}

    return Curve(make)


def line(a: Any, b: Any) -> Curve:
    """The straight segment from a to b."""
    return Curve(lambda arrays: {"line": [_point(a), _point(b)]})


def _curve(c: Any, arrays: _Arrays) -> dict[str, Any]:
    if isinstance(c, Curve):
        return c._spec(arrays)
    return interpolate_curve(c)._spec(arrays)  # an array of points: the curve through them


def _options(spec: dict[str, Any], **kw: Any) -> dict[str, Any]:
    for k, v in kw.items():
        if v is None:
            continue
        if isinstance(v, tuple):
            v = list(v)
        spec[k] = v
    return spec


def interpolate_surface(points: Any, degree: Any = None, param: Optional[str] = None,
                        periodic: Any = None):
    """The B-spline surface through a grid of points, shape (n, m, 3), any float
    dtype and memory order: bicubic unless `degree` (an int or (du, dv)) says
    otherwise, chord-length parameters averaged over the lines unless `param` is
    "uniform" or "centripetal", closed in the directions `periodic` = (pu, pv) says.

    Example::

        z = np.sin(x)[:, None] * np.cos(y)[None, :]
        grid = np.stack(np.broadcast_arrays(x[:, None], y[None, :], z), axis=-1)
        s = interpatch.interpolate_surface(grid)
        pts = s.evaluate(np.linspace(0, 1, 200), np.linspace(0, 1, 200))  # (200, 200, 3)"""
    a = _Arrays()
    spec = _options({"type": "interpolate", "points": a.add(points)}, degree=degree, param=param, periodic=periodic)
    return _build(spec, ".", a.table)


def _approximation(spec: dict[str, Any], control_points: Any, tolerance: Optional[float], smoothing: Any,
                   weights: Any) -> dict[str, Any]:
    spec = _options(spec, control_points=control_points, tolerance=tolerance, smoothing=smoothing)
    if weights is not None:
        spec["weights"] = np.asarray(weights, dtype=np.float64).tolist()
    return spec


def approximate_surface(points: Any, degree: Any = None, param: Optional[str] = None, periodic: Any = None,
                        control_points: Any = None, tolerance: Optional[float] = None, smoothing: Any = None,
                        weights: Any = None):
    """A B-spline surface near a grid of points, shape (n, m, 3), any float dtype and
    memory order; NaN in a point marks it missing (the fairness term fills the hole).
    Exactly one of `control_points` ((nu, nv): least squares with that net),
    `tolerance` (the fewest control points keeping every point within that distance)
    and `smoothing` (the fairness weight, or "auto" for generalized cross-validation);
    optional `weights`, shape (n, m), non-negative. `degree`, `param` and `periodic` as
    for interpolate_surface. info()["parameters"] reports max_error (and max_error_at),
    rms_error, control_points, lambda and missing_points.

    Example::

        grid = terrain + np.random.default_rng(1).normal(0, 0.01, terrain.shape)
        grid[40:60, 30:50] = np.nan                       # a void
        s = interpatch.approximate_surface(grid, tolerance=0.03)
        s.info()["parameters"]["max_error"]               # <= 0.03"""
    a = _Arrays()
    spec = _options({"type": "approximate", "points": a.add(points)}, degree=degree, param=param, periodic=periodic)
    return _build(_approximation(spec, control_points, tolerance, smoothing, weights), ".", a.table)


def approximate_volume(points: Any, degree: Any = None, param: Optional[str] = None, periodic: Any = None,
                       control_points: Any = None, tolerance: Optional[float] = None, smoothing: Any = None,
                       weights: Any = None):
    """A B-spline volume near a grid of points, shape (n, m, l, 3), NaN marking missing
    points; the options of approximate_surface, one per direction u, v, w.

    Example::

        v = interpatch.approximate_volume(grid, control_points=(6, 6, 6))"""
    a = _Arrays()
    spec = _options({"type": "approximate_volume", "points": a.add(points)}, degree=degree, param=param,
                    periodic=periodic)
    return _build(_approximation(spec, control_points, tolerance, smoothing, weights), ".", a.table)


def approximate_curve(points: Any, degree: Optional[int] = None, param: Optional[str] = None, periodic: bool = False,
                      control_points: Optional[int] = None, tolerance: Optional[float] = None, smoothing: Any = None,
                      weights: Any = None) -> Curve:
    """A curve near points, shape (n, 3), NaN marking missing ones: exactly one of
    `control_points`, `tolerance`, `smoothing` as for approximate_surface.

    Example::

        c = interpatch.approximate_curve(noisy_points, tolerance=0.01)
        s = interpatch.ruled(c, other)"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        s: dict[str, Any] = _options({"approximate": arrays.add(points)}, degree=degree, param=param)
        if periodic:
            s["periodic"] = True
        return _approximation(s, control_points, tolerance, smoothing, weights)

    return Curve(make)


def bilinear(p00: Any, p01: Any, p10: Any, p11: Any):
    """The bilinear patch of four corners: S(0,0) = p00, S(0,1) = p01, S(1,0) = p10, S(1,1) = p11."""
    return _build({"type": "bilinear", "p00": _point(p00), "p01": _point(p01), "p10": _point(p10),
                   "p11": _point(p11)}, ".", {})


def ruled(c0: Any, c1: Any):
    """The ruled surface S(u, v) = (1 - v) c0(u) + v c1(u) of two curves (Curve objects,
    or arrays of points to interpolate)."""
    a = _Arrays()
    return _build({"type": "ruled", "curves": [_curve(c0, a), _curve(c1, a)]}, ".", a.table)


def coons(v0: Any, v1: Any, u0: Any, u1: Any, blending: Optional[str] = None,
          tolerance: Optional[float] = None):
    """The Coons patch of four boundary curves: v0 = S(u, 0), v1 = S(u, 1), u0 = S(0, v),
    u1 = S(1, v); blending "linear" (default) or "hermite"."""
    a = _Arrays()
    spec = {"type": "coons", "boundary": {"v0": _curve(v0, a), "v1": _curve(v1, a), "u0": _curve(u0, a),
                                          "u1": _curve(u1, a)}}
    return _build(_options(spec, blending=blending, tolerance=tolerance), ".", a.table)


def curve_network(u_curves: Sequence[Any], v_curves: Sequence[Any], method: Optional[str] = None,
                  u_params: Optional[Sequence[float]] = None, v_params: Optional[Sequence[float]] = None,
                  tolerance: Optional[float] = None, periodic: Any = None):
    """The surface through a network of curves as drawn: any order, either
    direction, crossings at different parameters (docs/spec-format.md, type
    network); method "gordon" (default), "coons_linear" or "coons_hermite"."""
    a = _Arrays()
    spec = {"type": "network", "u_curves": [_curve(c, a) for c in u_curves],
            "v_curves": [_curve(c, a) for c in v_curves]}
    if u_params is not None:
        spec["u_params"] = [float(x) for x in u_params]
    if v_params is not None:
        spec["v_params"] = [float(x) for x in v_params]
    return _build(_options(spec, method=method, tolerance=tolerance, periodic=periodic), ".", a.table)


def hermite_patch(corners: dict[str, dict[str, Any]]):
    """The bicubic Hermite patch of four corners, each {"p", "du", "dv", "duv"}, keyed
    "p00", "p01", "p10", "p11"."""
    spec = {"type": "hermite_patch",
            "corners": {k: {f: _point(v) for f, v in c.items()} for k, c in corners.items()}}
    return _build(spec, ".", {})


def interpolate_volume(points: Any, degree: Any = None, param: Optional[str] = None, periodic: Any = None):
    """The B-spline volume through a grid of points, shape (n, m, l, 3): tricubic unless
    `degree` (an int or (p, q, r)) says otherwise, parameters by `param` averaged over
    the lines, closed in the directions `periodic` = (pu, pv, pw) says."""
    a = _Arrays()
    spec = _options({"type": "interpolate_volume", "points": a.add(points)}, degree=degree, param=param,
                    periodic=periodic)
    return _build(spec, ".", a.table)


def trilinear(corners: Any):
    """The trilinear volume of eight corners, shape (2, 2, 2, 3): corners[i][j][k] = S(i, j, k)."""
    c = np.asarray(corners, dtype=np.float64)
    if c.shape != (2, 2, 2, 3):
        raise Error_(f"trilinear: corners must have shape (2, 2, 2, 3), got {c.shape}")
    spec = {"type": "trilinear"}
    for i in range(2):
        for j in range(2):
            for k in range(2):
                spec[f"p{i}{j}{k}"] = _point(c[i, j, k])
    return _build(spec, ".", {})


def _surface_spec(face: Any, arrays: _Arrays) -> dict[str, Any]:
    if isinstance(face, dict):
        return face
    return {"type": "interpolate", "points": arrays.add(face)}


def coons_volume(faces: dict[str, Any], blending: Optional[str] = None, tolerance: Optional[float] = None):
    """The Coons volume of six faces keyed u0, u1, v0, v1, w0, w1 (S(0, v, w), S(1, v, w),
    S(u, 0, w), ...): each a grid of points (n, m, 3) to interpolate, or a surface spec dict."""
    a = _Arrays()
    spec = {"type": "coons_volume", "faces": {k: _surface_spec(f, a) for k, f in faces.items()}}
    return _build(_options(spec, blending=blending, tolerance=tolerance), ".", a.table)


def hermite_volume(corners: Sequence[dict[str, Any]]):
    """The tricubic Hermite volume of 8 corners (index 4i + 2j + k for corner (i, j, k)), each
    {"p", "du", "dv", "dw"} and optionally "duv", "duw", "dvw", "duvw"."""
    spec = {"type": "hermite_volume", "corners": [{f: _point(v) for f, v in c.items()} for c in corners]}
    return _build(spec, ".", {})


def build(spec: Any, base_dir: Any = ".", arrays: Optional[dict[str, Any]] = None):
    """A spec (docs/spec-format.md) as a dict, or the path of a spec file, built.
    A dict may name NumPy arrays given in `arrays` as {"array": NAME} wherever it
    takes a point array.

    Example::

        s = interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0],
                              "p10": [1, 0, 0], "p11": [1, 1, 1]})"""
    return _build(spec, base_dir, arrays or {})
