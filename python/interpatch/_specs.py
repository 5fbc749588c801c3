"""NumPy-native constructors: each makes the spec the command line reads
(docs/spec-format.md), with its arrays passed in memory rather than written to
files, and builds it. Same semantics, defaults and errors as the command line;
the messages name the spec's fields (/points, /u_curves/2, ...)."""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from ._core import Curve
from ._core import Error as Error_
from ._core import build as _build


def _error(code: str, message: str) -> Error_:
    e = Error_(message)
    e.code = code
    return e


def _first_masked(a: Any) -> Optional[tuple[int, ...]]:
    """The index of the first masked point of a masked array (any coordinate masked), None when none is."""
    if not np.ma.isMaskedArray(a):
        return None
    mask = np.ma.getmaskarray(a)
    if mask.ndim >= 2:
        mask = mask.any(axis=-1)
    where = np.argwhere(mask)
    return tuple(int(i) for i in where[0]) if len(where) else None


def _real(x: Any, name: str) -> np.ndarray:
    """x as an array of real numbers: NumPy would drop a complex number's imaginary part
    and read True as 1, so complex, bool, object and text are refused, as are masked
    entries where nothing may be missing."""
    at = _first_masked(x)
    if at is not None:
        raise _error("wrong_type", f"{name}: masked at index {at}; this argument cannot have missing values")
    try:
        a = np.asarray(np.ma.getdata(x) if np.ma.isMaskedArray(x) else x)
    except (ValueError, TypeError) as e:
        raise _error("wrong_type", f"{name}: expected real numbers ({e})") from None
    if a.dtype.kind not in "fiu":
        raise _error("wrong_type", f"{name}: expected real numbers, got an array of dtype {a.dtype}")
    return a.astype(np.float64)


class _Arrays:
    """The arrays of one spec, each named after the argument that gave it."""

    def __init__(self) -> None:
        self.table: dict[str, Any] = {}

    def add(self, points: Any, name: str, missing: bool = False) -> dict[str, str]:
        """{"array": name} for `points`, kept as given (the module converts it and
        refuses what is not an array of real numbers). A masked point means a missing
        one: allowed where `missing` (approximations), refused elsewhere."""
        if not missing:
            at = _first_masked(points)
            if at is not None:
                raise _error("wrong_type", f"{name}: masked at index {at}; every point is needed here "
                                           "(the approximations take missing points)")
        unique, k = name, 2
        while unique in self.table:
            unique, k = f"{name}#{k}", k + 1
        self.table[unique] = points
        return {"array": unique}


def _point(p: Any, name: str) -> list[float]:
    return [float(x) for x in _real(p, name).reshape(-1)]


def _reals(x: Any, name: str) -> Any:
    return _real(x, name).tolist()


def _curve_built(make) -> Curve:
    """The curve spec make(arrays) gives, built (a Curve): the same reader as a curve
    spec file's, so the command line's `eval`, `info` and `build` of that spec agree."""
    a = _Arrays()
    return _build(make(a), ".", a.table)


def interpolate_curve(points: Any, degree: Optional[int] = None, param: str = "chord",
                      periodic: bool = False, start_derivative: Any = None, end_derivative: Any = None) -> Curve:
    """The B-spline curve through `points` (shape (n, 3)), as the spec's
    {"interpolate": ...} curve: degree min(3, n - 1) unless given, chord-length
    parameters unless `param` says otherwise ("uniform", "centripetal"), closed with
    periodic=True (a last point repeating the first is left out), with given end
    derivatives dC/dt (over the curve's [0, 1]) if any. C(params[i]) = points[i].

    Example::

        c = interpatch.interpolate_curve(np.array([[0, 0, 0], [1, 2, 0], [3, 3, 0]]))
        c.evaluate(np.linspace(0, 1, 20))   # (20, 3)"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        s: dict[str, Any] = {"interpolate": arrays.add(points, "points"), "param": param}
        if degree is not None:
            s["degree"] = int(degree)
        if periodic:
            s["periodic"] = True
        if start_derivative is not None:
            s["start_derivative"] = _point(start_derivative, "start_derivative")
        if end_derivative is not None:
            s["end_derivative"] = _point(end_derivative, "end_derivative")
        return s

    return _curve_built(make)


def bspline_curve(degree: int, knots: Sequence[float], control_points: Any,
                  weights: Optional[Sequence[float]] = None, periodic: bool = False) -> Curve:
    """A B-spline curve given by its degree, knots (n + p + 1 of them, clamped) and
    control points (shape (n, 3)), rational with `weights` (n,), closed with
    periodic=True (then the n + 2p + 1 extended knots): the spec's {"bspline": ...}
    curve, mapped onto [0, 1].

    Example::

        quarter = interpatch.bspline_curve(2, [0, 0, 0, 1, 1, 1], [[1, 0, 0], [1, 1, 0], [0, 1, 0]],
                                           weights=[1, 2 ** -0.5, 1])
        quarter.curvature(0.3)              # 1.0, a unit circle's"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        b: dict[str, Any] = {"degree": int(degree), "knots": _reals(knots, "knots"),
                             "control_points": arrays.add(control_points, "control_points")}
        if weights is not None:
            b["weights"] = _reals(weights, "weights")
        if periodic:
            b["periodic"] = True
        return {"bspline": b}

    return _curve_built(make)


def hermite_curve(points: Any, tangents: Any = None, params: Optional[Sequence[float]] = None) -> Curve:
    """The piecewise cubic Hermite curve through `points` with `tangents` (both shape
    (n, 3); Catmull–Rom tangents when not given) at `params` (equally spaced by
    default), mapped onto [0, 1]: C1, through points[i] at its .params[i].

    Example::

        c = interpatch.hermite_curve([[0, 0, 0], [1, 1, 0], [2, 0, 0]], [[1, 1, 0], [1, 0, 0], [1, -1, 0]])"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        h: dict[str, Any] = {"points": arrays.add(points, "points")}
        if tangents is not None:
            h["tangents"] = arrays.add(tangents, "tangents")
        if params is not None:
            h["params"] = _reals(params, "params")
        return {"hermite": h}

    return _curve_built(make)


def line(a: Any, b: Any) -> Curve:
    """The straight segment from a to b: C(t) = (1 - t) a + t b.

    Example: interpatch.line([0, 0, 0], [2, 0, 0]).point(0.5)   # [1, 0, 0]"""
    return _curve_built(lambda arrays: {"line": [_point(a, "a"), _point(b, "b")]})


def _curve(c: Any, arrays: _Arrays, name: str) -> dict[str, Any]:
    """A curve argument as a spec: a Curve by its exact form (what the surfaces take of
    it: the curve over [0, 1], bit for bit), an array of points as the curve through them."""
    if isinstance(c, Curve):
        b = c.to_bspline()
        spec: dict[str, Any] = {"degree": b["degree"], "knots": b["knots"].tolist(),
                                "control_points": arrays.add(b["control_points"], f"{name}.control_points")}
        if b["weights"] is not None:
            spec["weights"] = b["weights"].tolist()
        if b["periodic"]:
            spec["periodic"] = True
        return {"bspline": spec}
    return {"interpolate": arrays.add(c, name), "param": "chord"}


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
    spec = _options({"type": "interpolate", "points": a.add(points, "points")}, degree=degree, param=param,
                    periodic=periodic)
    return _build(spec, ".", a.table)


def _approximation(spec: dict[str, Any], control_points: Any, tolerance: Optional[float], smoothing: Any,
                   weights: Any) -> dict[str, Any]:
    spec = _options(spec, control_points=control_points, tolerance=tolerance, smoothing=smoothing)
    if weights is not None:
        spec["weights"] = _reals(weights, "weights")
    return spec


def approximate_surface(points: Any, degree: Any = None, param: Optional[str] = None, periodic: Any = None,
                        control_points: Any = None, tolerance: Optional[float] = None, smoothing: Any = None,
                        weights: Any = None):
    """A B-spline surface near a grid of points, shape (n, m, 3), any float dtype and
    memory order; NaN in a point, or a masked entry of a masked array, marks it missing
    (the fairness term fills the hole).
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
    spec = _options({"type": "approximate", "points": a.add(points, "points", missing=True)}, degree=degree, param=param,
                    periodic=periodic)
    return _build(_approximation(spec, control_points, tolerance, smoothing, weights), ".", a.table)


def approximate_volume(points: Any, degree: Any = None, param: Optional[str] = None, periodic: Any = None,
                       control_points: Any = None, tolerance: Optional[float] = None, smoothing: Any = None,
                       weights: Any = None):
    """A B-spline volume near a grid of points, shape (n, m, l, 3), NaN marking missing
    points; the options of approximate_surface, one per direction u, v, w.

    Example::

        v = interpatch.approximate_volume(grid, control_points=(6, 6, 6))"""
    a = _Arrays()
    spec = _options({"type": "approximate_volume", "points": a.add(points, "points", missing=True)}, degree=degree,
                    param=param,
                    periodic=periodic)
    return _build(_approximation(spec, control_points, tolerance, smoothing, weights), ".", a.table)


def approximate_curve(points: Any, degree: Optional[int] = None, param: Optional[str] = None, periodic: bool = False,
                      control_points: Optional[int] = None, tolerance: Optional[float] = None, smoothing: Any = None,
                      weights: Any = None) -> Curve:
    """A curve near points, shape (n, 3), NaN (or a masked entry) marking missing ones:
    exactly one of `control_points`, `tolerance`, `smoothing` as for
    approximate_surface. info()["parameters"] reports max_error and rms_error.

    Example::

        c = interpatch.approximate_curve(noisy_points, tolerance=0.01)
        s = interpatch.ruled(c, other)"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        s: dict[str, Any] = _options({"approximate": arrays.add(points, "points", missing=True)}, degree=degree,
                                     param=param)
        if periodic:
            s["periodic"] = True
        return _approximation(s, control_points, tolerance, smoothing, weights)

    return _curve_built(make)


def bilinear(p00: Any, p01: Any, p10: Any, p11: Any):
    """The bilinear patch of four corners: S(0,0) = p00, S(0,1) = p01, S(1,0) = p10, S(1,1) = p11."""
    return _build({"type": "bilinear", "p00": _point(p00, "p00"), "p01": _point(p01, "p01"), "p10": _point(p10, "p10"),
                   "p11": _point(p11, "p11")}, ".", {})


def ruled(c0: Any, c1: Any):
    """The ruled surface S(u, v) = (1 - v) c0(u) + v c1(u) of two curves (Curve objects,
    or arrays of points to interpolate)."""
    a = _Arrays()
    return _build({"type": "ruled", "curves": [_curve(c0, a, "c0"), _curve(c1, a, "c1")]}, ".", a.table)


def coons(v0: Any, v1: Any, u0: Any, u1: Any, blending: Optional[str] = None,
          tolerance: Optional[float] = None):
    """The Coons patch of four boundary curves: v0 = S(u, 0), v1 = S(u, 1), u0 = S(0, v),
    u1 = S(1, v); blending "linear" (default) or "hermite"."""
    a = _Arrays()
    spec = {"type": "coons", "boundary": {"v0": _curve(v0, a, "v0"), "v1": _curve(v1, a, "v1"), "u0": _curve(u0, a, "u0"),
                                          "u1": _curve(u1, a, "u1")}}
    return _build(_options(spec, blending=blending, tolerance=tolerance), ".", a.table)


def curve_network(u_curves: Sequence[Any], v_curves: Sequence[Any], method: Optional[str] = None,
                  u_params: Optional[Sequence[float]] = None, v_params: Optional[Sequence[float]] = None,
                  tolerance: Optional[float] = None, periodic: Any = None):
    """The surface through a network of curves as drawn: any order, either
    direction, crossings at different parameters (docs/spec-format.md, type
    network); method "gordon" (default), "coons_linear" or "coons_hermite"."""
    a = _Arrays()
    spec = {"type": "network", "u_curves": [_curve(c, a, f"u_curves[{i}]") for i, c in enumerate(u_curves)],
            "v_curves": [_curve(c, a, f"v_curves[{i}]") for i, c in enumerate(v_curves)]}
    if u_params is not None:
        spec["u_params"] = _reals(u_params, "u_params")
    if v_params is not None:
        spec["v_params"] = _reals(v_params, "v_params")
    return _build(_options(spec, method=method, tolerance=tolerance, periodic=periodic), ".", a.table)


def hermite_patch(corners: dict[str, dict[str, Any]]):
    """The bicubic Hermite patch of four corners, each {"p", "du", "dv", "duv"}, keyed
    "p00", "p01", "p10", "p11"."""
    spec = {"type": "hermite_patch",
            "corners": {k: {f: _point(v, f"corners[{k!r}][{f!r}]") for f, v in c.items()} for k, c in corners.items()}}
    return _build(spec, ".", {})


def interpolate_volume(points: Any, degree: Any = None, param: Optional[str] = None, periodic: Any = None):
    """The B-spline volume through a grid of points, shape (n, m, l, 3): tricubic unless
    `degree` (an int or (p, q, r)) says otherwise, parameters by `param` averaged over
    the lines, closed in the directions `periodic` = (pu, pv, pw) says."""
    a = _Arrays()
    spec = _options({"type": "interpolate_volume", "points": a.add(points, "points")}, degree=degree, param=param,
                    periodic=periodic)
    return _build(spec, ".", a.table)


def trilinear(corners: Any):
    """The trilinear volume of eight corners, shape (2, 2, 2, 3): corners[i][j][k] = S(i, j, k)."""
    c = _real(corners, "corners")
    if c.shape != (2, 2, 2, 3):
        raise _error("size_mismatch", f"corners: expected shape (2, 2, 2, 3), got {c.shape}")
    spec = {"type": "trilinear"}
    for i in range(2):
        for j in range(2):
            for k in range(2):
                spec[f"p{i}{j}{k}"] = _point(c[i, j, k], f"corners[{i}, {j}, {k}]")
    return _build(spec, ".", {})


def _surface_spec(face: Any, arrays: _Arrays, name: str) -> dict[str, Any]:
    if isinstance(face, dict):
        return face
    return {"type": "interpolate", "points": arrays.add(face, name)}


def coons_volume(faces: dict[str, Any], blending: Optional[str] = None, tolerance: Optional[float] = None):
    """The Coons volume of six faces keyed u0, u1, v0, v1, w0, w1 (S(0, v, w), S(1, v, w),
    S(u, 0, w), ...): each a grid of points (n, m, 3) to interpolate, or a surface spec dict."""
    a = _Arrays()
    spec = {"type": "coons_volume", "faces": {k: _surface_spec(f, a, f"faces[{k!r}]") for k, f in faces.items()}}
    return _build(_options(spec, blending=blending, tolerance=tolerance), ".", a.table)


def hermite_volume(corners: Sequence[dict[str, Any]]):
    """The tricubic Hermite volume of 8 corners (index 4i + 2j + k for corner (i, j, k)), each
    {"p", "du", "dv", "dw"} and optionally "duv", "duw", "dvw", "duvw"."""
    spec = {"type": "hermite_volume",
            "corners": [{f: _point(v, f"corners[{i}][{f!r}]") for f, v in c.items()} for i, c in enumerate(corners)]}
    return _build(spec, ".", {})


def build(spec: Any, base_dir: Any = ".", arrays: Optional[dict[str, Any]] = None):
    """A spec (docs/spec-format.md) as a dict, or the path of a spec file, built.
    A dict may name NumPy arrays given in `arrays` as {"array": NAME} wherever it
    takes a point array.

    Example::

        s = interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0],
                              "p10": [1, 0, 0], "p11": [1, 1, 1]})"""
    return _build(spec, base_dir, {} if arrays is None else arrays)
