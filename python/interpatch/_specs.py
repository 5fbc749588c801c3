"""NumPy-native constructors: each makes the spec the command line reads
(docs/spec-format.md), with its arrays passed in memory rather than written to
files, and builds it. Same semantics, defaults and errors as the command line;
the messages name the spec's fields (/points, /u_curves/2, ...).

The volumes' constructors are in _volumes.py. A constructor is added there or here
alone: annotated, named in this __all__ (interpatch exports what it names) and
with examples that use every keyword, which tests/python/test_spec_fields.py runs
and holds to the reader's field table."""

from __future__ import annotations

from os import PathLike
from typing import Any, Callable, Optional, Sequence, Union, cast

import numpy.typing as npt

from . import _core
from ._args import _approximation, _Arrays, _curve, _options, _point, _reals, _scattered_sites
from ._core import Curve, Surface, Volume
from ._volumes import (approximate_volume, blocks, coons_volume, hermite_volume, interpolate_volume, loft_volume,
                       trilinear)

__all__ = ["build", "interpolate_surface", "bilinear", "ruled", "coons", "curve_network", "hermite_patch",
           "interpolate_volume", "trilinear", "coons_volume", "hermite_volume", "interpolate_curve", "bspline_curve",
           "hermite_curve", "line", "approximate_surface", "approximate_volume", "approximate_curve", "loft",
           "loft_volume", "blocks"]

_Path = Union[str, PathLike[str]]
_CurveLike = Union[Curve, npt.ArrayLike]


def _curve_built(make: Callable[[_Arrays], dict[str, Any]]) -> Curve:
    """The curve spec make(arrays) gives, built (a Curve): the same reader as a curve
    spec file's, so the command line's `eval`, `info` and `build` of that spec agree."""
    a = _Arrays()
    return cast(Curve, _core.build(make(a), ".", a.table))


def interpolate_curve(points: npt.ArrayLike, degree: Optional[int] = None, param: str = "chord",
                      periodic: bool = False, start_derivative: Optional[npt.ArrayLike] = None,
                      end_derivative: Optional[npt.ArrayLike] = None) -> Curve:
    """The B-spline curve through `points` (shape (n, 3)), as the spec's
    {"interpolate": ...} curve: degree min(3, n - 1) unless given, chord-length
    parameters unless `param` says otherwise ("uniform", "centripetal"), closed with
    periodic=True (a last point repeating the first is left out), with given end
    derivatives dC/dt (over the curve's [0, 1]) if any. C(params[i]) = points[i].

    Examples
    --------
    >>> c = interpatch.interpolate_curve(np.array([[0, 0, 0], [1, 2, 0], [3, 3, 0]]))
    >>> c.evaluate(np.linspace(0, 1, 20)).shape, c.point(1.0).tolist()
    ((20, 3), [3.0, 3.0, 0.0])
    >>> ring = interpatch.interpolate_curve([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [1, 0, 0]], periodic=True)
    >>> ring.to_bspline()["control_points"].shape, np.allclose(ring.point(0.25), [0, 1, 0])
    ((4, 3), True)
    >>> arch = interpatch.interpolate_curve([[0, 0, 0], [1, 1, 0], [2, 0, 0]], degree=2, param="uniform",
    ...                                     start_derivative=[0, 4, 0], end_derivative=[0, -4, 0])
    >>> np.allclose(arch.derivatives([0.0, 1.0])[:, 1], [[0, 4, 0], [0, -4, 0]])
    True"""

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


def bspline_curve(degree: int, knots: Sequence[float], control_points: npt.ArrayLike,
                  weights: Optional[Sequence[float]] = None, periodic: bool = False) -> Curve:
    """A B-spline curve given by its degree, knots (n + p + 1 of them, clamped) and
    control points (shape (n, 3)), rational with `weights` (n,), closed with
    periodic=True (then the n + 2p + 1 extended knots): the spec's {"bspline": ...}
    curve, mapped onto [0, 1].

    Examples
    --------
    >>> quarter = interpatch.bspline_curve(2, [0, 0, 0, 1, 1, 1], [[1, 0, 0], [1, 1, 0], [0, 1, 0]],
    ...                                    weights=[1, 2 ** -0.5, 1])
    >>> round(quarter.curvature(0.3), 9)            # a unit circle's
    1.0
    >>> loop = interpatch.bspline_curve(3, [-0.75, -0.5, -0.25, 0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75],
    ...                                 [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], periodic=True)
    >>> np.allclose(loop.point(0.0), loop.point(1.0)), np.allclose(loop.point(0.0), [0, 2 / 3, 0])
    (True, True)"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        b: dict[str, Any] = {"degree": int(degree), "knots": _reals(knots, "knots"),
                             "control_points": arrays.add(control_points, "control_points")}
        if weights is not None:
            b["weights"] = _reals(weights, "weights")
        if periodic:
            b["periodic"] = True
        return {"bspline": b}

    return _curve_built(make)


def hermite_curve(points: npt.ArrayLike, tangents: Optional[npt.ArrayLike] = None,
                  params: Optional[Sequence[float]] = None) -> Curve:
    """The piecewise cubic Hermite curve through `points` with `tangents` (both shape
    (n, 3); Catmull–Rom tangents when not given) at `params` (equally spaced by
    default), mapped onto [0, 1]: C1, through points[i] at its .params[i].

    Examples
    --------
    >>> c = interpatch.hermite_curve([[0, 0, 0], [1, 1, 0], [2, 0, 0]], [[1, 1, 0], [1, 0, 0], [1, -1, 0]])
    >>> np.allclose(c.point(0.5), [1, 1, 0]), np.allclose(c.tangent(0.5), [1, 0, 0])     # the top, level
    (True, True)
    >>> c = interpatch.hermite_curve([[0, 0, 0], [1, 1, 0], [4, 0, 0]], params=[0, 1, 4])
    >>> c.params.round(6).tolist()
    [0.0, 0.25, 1.0]"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        h: dict[str, Any] = {"points": arrays.add(points, "points")}
        if tangents is not None:
            h["tangents"] = arrays.add(tangents, "tangents")
        if params is not None:
            h["params"] = _reals(params, "params")
        return {"hermite": h}

    return _curve_built(make)


def line(a: npt.ArrayLike, b: npt.ArrayLike) -> Curve:
    """The straight segment from a to b: C(t) = (1 - t) a + t b.

    Examples
    --------
    >>> interpatch.line([0, 0, 0], [2, 0, 0]).point(0.5).tolist()
    [1.0, 0.0, 0.0]"""
    return _curve_built(lambda arrays: {"line": [_point(a, "a"), _point(b, "b")]})


def interpolate_surface(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                        param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None) -> Surface:
    """The B-spline surface through a grid of points, shape (n, m, 3), any float
    dtype and memory order: bicubic unless `degree` (an int or (du, dv)) says
    otherwise, chord-length parameters averaged over the lines unless `param` is
    "uniform" or "centripetal", closed in the directions `periodic` = (pu, pv) says.
    Every point must be present (a masked entry is refused).

    Examples
    --------
    >>> x, y = np.meshgrid(np.linspace(0, 3, 30), np.linspace(0, 2, 20), indexing="ij")
    >>> grid = np.stack([x, y, np.sin(x) * np.cos(y)], axis=-1)       # (30, 20, 3)
    >>> s = interpatch.interpolate_surface(grid)
    >>> s.evaluate(np.linspace(0, 1, 200), np.linspace(0, 1, 200)).shape
    (200, 200, 3)
    >>> np.allclose(s.point(s.params_u[4], s.params_v[7]), grid[4, 7])
    True
    >>> z, t = np.meshgrid(np.linspace(0, 2, 5), np.linspace(0, 2 * np.pi, 17), indexing="ij")
    >>> pipe = np.stack([np.cos(t), np.sin(t), z], axis=-1)          # the last column repeats the first
    >>> s = interpatch.interpolate_surface(pipe, degree=(1, 3), param="centripetal", periodic=(False, True))
    >>> s.info()["control_points"], s.info()["seam_continuity"]
    ([5, 16], {'v': 'C2'})"""
    a = _Arrays()
    spec = _options({"type": "interpolate", "points": a.add(points, "points")}, degree=degree, param=param,
                    periodic=periodic)
    return cast(Surface, _core.build(spec, ".", a.table))


def approximate_surface(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                        param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None,
                        control_points: Union[int, Sequence[int], None] = None, tolerance: Optional[float] = None,
                        smoothing: Union[float, str, None] = None, weights: Optional[npt.ArrayLike] = None,
                        params: Optional[npt.ArrayLike] = None, domain: Optional[Sequence[Sequence[float]]] = None,
                        max_control_points: Union[int, Sequence[int], None] = None, base: Any = None) -> Surface:
    """A B-spline surface near a grid of points, shape (n, m, 3), or near scattered
    points, shape (N, 3); any float dtype and memory order. NaN in a point, or a masked
    entry of a masked array, marks it missing (the fairness term fills the hole).
    Exactly one of `control_points` ((nu, nv): least squares with that net),
    `tolerance` (the fewest control points keeping every point within that distance)
    and `smoothing` (the fairness weight, or "auto": generalized cross-validation on a
    grid, 5-fold cross-validation for scattered points); optional `weights`, one per
    point, non-negative. For a grid, `degree`,
    `param` and `periodic` as for interpolate_surface. For scattered points, `param`
    is "plane" (the default: the points' least-squares plane) or "xy" (a height field,
    u = x and v = y), or `params` gives the sites, shape (N, 2), or `base` (a Surface, spec
    or grid) the parameters of each point's closest point on it (folded sheets); `domain`
    ((u0, u1), (v0, v1)) the rectangle covered (default: the sites' bounding box) and
    `max_control_points` the largest net a tolerance may reach. The surface is over
    [0, 1]²: with "xy", x = u0 + u (u1 − u0). info()["parameters"] reports max_error
    (and max_error_at), rms_error, control_points, lambda and missing_points.

    Examples
    --------
    >>> x, y = np.meshgrid(np.linspace(0, 3, 40), np.linspace(0, 2, 30), indexing="ij")
    >>> terrain = np.stack([x, y, np.sin(x) * np.cos(y)], axis=-1)
    >>> grid = terrain + np.random.default_rng(1).normal(0, 0.01, terrain.shape)
    >>> grid[15:20, 10:15] = np.nan                                  # a void
    >>> s = interpatch.approximate_surface(grid, tolerance=0.05)
    >>> s.info()["parameters"]["max_error"] <= 0.05, s.info()["parameters"]["missing_points"]
    (True, 25)
    >>> s = interpatch.approximate_surface(terrain, degree=(3, 2), param="uniform", control_points=(8, 6),
    ...                                    weights=np.where(x < 1, 2.0, 1.0))
    >>> s.info()["control_points"], s.info()["degree"]
    ([8, 6], [3, 2])
    >>> z, t = np.meshgrid(np.linspace(0, 2, 10), np.linspace(0, 2 * np.pi, 24, endpoint=False), indexing="ij")
    >>> tube = np.stack([np.cos(t), np.sin(t), z], axis=-1)          # closed around v
    >>> s = interpatch.approximate_surface(tube, periodic=(False, True), smoothing=1e-6)
    >>> s.info()["periodic"], s.info()["parameters"]["max_error"] < 0.01
    ([False, True], True)

    Scattered survey points, a height field over a given rectangle:

    >>> rng = np.random.default_rng(2)
    >>> xy = rng.uniform((0, 0), (300, 200), (5000, 2))
    >>> survey = np.column_stack([xy, 10 * np.sin(xy[:, 0] / 50) + rng.normal(0, 0.05, 5000)])
    >>> s = interpatch.approximate_surface(survey, param="xy", tolerance=0.3, domain=((0, 300), (0, 200)),
    ...                                    max_control_points=(200, 200))
    >>> p = s.info()["parameters"]
    >>> p["max_error"] <= 0.3, p["param"], p["points"], np.round(s.point(0.5, 0.5)[:2], 9).tolist()
    (True, 'xy', 5000, [150.0, 100.0])
    >>> s = interpatch.approximate_surface(survey, param="xy", smoothing="auto")  # λ by cross-validation
    >>> p = s.info()["parameters"]
    >>> p["smoothing"], p["lambda"] > 0, p["rms_error"] < 0.1
    ('auto', True, True)
    >>> s = interpatch.approximate_surface(survey, params=xy / 100, control_points=(12, 10))
    >>> s.info()["parameters"]["param"], s.info()["control_points"]
    ('sites', [12, 10])
    >>> # A sheet wrapped 300 degrees round an axis, placed by a coarse surface round it:
    >>> t, h = np.meshgrid(np.linspace(0, 5.2, 9), [0.0, 1.0, 2.0], indexing="ij")
    >>> a, z = rng.uniform(0, 5.2, 600), rng.uniform(0, 2, 600)
    >>> s = interpatch.approximate_surface(np.column_stack([np.cos(a), np.sin(a), z]), tolerance=0.01,
    ...                                    base=np.stack([np.cos(t), np.sin(t), h], axis=-1))
    >>> s.info()["parameters"]["param"], s.info()["parameters"]["max_error"] <= 0.01
    ('base', True)"""
    a = _Arrays()
    spec = _options({"type": "approximate", "points": a.add(points, "points", missing=True)}, degree=degree, param=param,
                    periodic=periodic, domain=domain, max_control_points=max_control_points)
    _scattered_sites(spec, a, param, params, base)
    return cast(Surface, _core.build(_approximation(spec, control_points, tolerance, smoothing, weights), ".", a.table))


def approximate_curve(points: npt.ArrayLike, degree: Optional[int] = None, param: Optional[str] = None,
                      periodic: bool = False, control_points: Optional[int] = None, tolerance: Optional[float] = None,
                      smoothing: Union[float, str, None] = None, weights: Optional[npt.ArrayLike] = None) -> Curve:
    """A curve near points, shape (n, 3), NaN (or a masked entry) marking missing ones:
    exactly one of `control_points`, `tolerance`, `smoothing` as for
    approximate_surface. info()["parameters"] reports max_error and rms_error.

    Examples
    --------
    >>> t = np.linspace(0, np.pi, 50)
    >>> noisy = np.stack([t, np.sin(t), 0 * t], axis=-1) + np.random.default_rng(2).normal(0, 0.002, (50, 3))
    >>> c = interpatch.approximate_curve(noisy, tolerance=0.01)
    >>> c.info()["parameters"]["max_error"] <= 0.01
    True
    >>> interpatch.ruled(c, interpatch.line([0, 0, 1], [np.pi, 0, 1]))          # a measured edge of a surface
    Surface(type='ruled', degree=(3, 1), control_points=(..., 2))
    >>> c = interpatch.approximate_curve(noisy, degree=2, param="uniform", control_points=8,
    ...                                  weights=np.linspace(1, 2, 50))
    >>> c.info()["control_points"], c.degree
    ([8], 2)
    >>> t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    >>> circle = np.stack([np.cos(t), np.sin(t), 0 * t], axis=-1)
    >>> c = interpatch.approximate_curve(circle, periodic=True, smoothing="auto")
    >>> c.info()["periodic"], round(c.curvature(0.5), 2)
    ([True], 1.0)"""

    def make(arrays: _Arrays) -> dict[str, Any]:
        s: dict[str, Any] = _options({"approximate": arrays.add(points, "points", missing=True)}, degree=degree,
                                     param=param)
        if periodic:
            s["periodic"] = True
        return _approximation(s, control_points, tolerance, smoothing, weights)

    return _curve_built(make)


def bilinear(p00: npt.ArrayLike, p01: npt.ArrayLike, p10: npt.ArrayLike, p11: npt.ArrayLike) -> Surface:
    """The bilinear patch of four corners: S(0,0) = p00, S(0,1) = p01, S(1,0) = p10, S(1,1) = p11.

    Examples
    --------
    >>> s = interpatch.bilinear(p00=[0, 0, 0], p01=[0, 1, 0], p10=[1, 0, 0], p11=[1, 1, 1])
    >>> s.point(0.5, 0.5).tolist(), s.point(1, 1).tolist()
    ([0.5, 0.5, 0.25], [1.0, 1.0, 1.0])"""
    return cast(Surface, _core.build({"type": "bilinear", "p00": _point(p00, "p00"), "p01": _point(p01, "p01"),
                                 "p10": _point(p10, "p10"), "p11": _point(p11, "p11")}, ".", {}))


def ruled(c0: _CurveLike, c1: _CurveLike) -> Surface:
    """The ruled surface S(u, v) = (1 - v) c0(u) + v c1(u) of two curves (Curve objects,
    or arrays of points to interpolate).

    Examples
    --------
    >>> arc = interpatch.hermite_curve([[0, 1, 1], [1, 1.4, 1.5], [2, 1.4, 1.5], [3, 1, 1]])
    >>> s = interpatch.ruled(c0=interpatch.line([0, 0, 0], [3, 0, 0]), c1=arc)
    >>> s.point(0.5, 0.5).round(6).tolist()                          # halfway up the middle line
    [1.5, 0.725, 0.78125]
    >>> s = interpatch.ruled([[0, 0, 0], [1, 0, 0.3], [2, 0, 0]], [[0, 2, 0], [1, 2, 0.3], [2, 2, 0]])
    >>> s.point(0.5, 0.5).round(6).tolist()
    [1.0, 1.0, 0.3]"""
    a = _Arrays()
    return cast(Surface, _core.build({"type": "ruled", "curves": [_curve(c0, a, "c0"), _curve(c1, a, "c1")]}, ".", a.table))


def coons(v0: _CurveLike, v1: _CurveLike, u0: _CurveLike, u1: _CurveLike, blending: Optional[str] = None,
          tolerance: Optional[float] = None) -> Surface:
    """The Coons patch of four boundary curves: v0 = S(u, 0), v1 = S(u, 1), u0 = S(0, v),
    u1 = S(1, v); blending "linear" (default) or "hermite"; `tolerance`: how far apart
    two sides may end at a shared corner (the corner is then the mean of the two ends).

    Examples
    --------
    >>> v1 = interpatch.line([0, 1, 0], [1, 1, 0.5])
    >>> u0 = interpatch.line([0, 0, 0], [0, 1, 0])
    >>> u1 = interpatch.hermite_curve([[1, 0, 0], [1, 0.5, 0.4], [1, 1, 0.5]])
    >>> s = interpatch.coons([[0, 0, 0], [0.5, 0, 0.1], [1, 0, 0]], v1, u0, u1, blending="hermite")
    >>> s.point(0.5, 0.5).round(6).tolist(), s.info()["parameters"]["blending"]
    ([0.5, 0.5, 0.25], 'hermite')
    >>> v1 = interpatch.line([0, 1, 0], [1, 1, 0.5004])                    # misses u1's end by 0.0004
    >>> try:
    ...     interpatch.coons(interpatch.line([0, 0, 0], [1, 0, 0]), v1, u0, u1)
    ... except interpatch.Error as e:
    ...     print(e.code)
    corner_gap
    >>> s = interpatch.coons(interpatch.line([0, 0, 0], [1, 0, 0]), v1, u0, u1, tolerance=0.001)
    >>> s.point(1, 1).round(6).tolist()
    [1.0, 1.0, 0.5002]"""
    a = _Arrays()
    spec = {"type": "coons", "boundary": {"v0": _curve(v0, a, "v0"), "v1": _curve(v1, a, "v1"), "u0": _curve(u0, a, "u0"),
                                          "u1": _curve(u1, a, "u1")}}
    return cast(Surface, _core.build(_options(spec, blending=blending, tolerance=tolerance), ".", a.table))


def curve_network(u_curves: Sequence[_CurveLike], v_curves: Sequence[_CurveLike], method: Optional[str] = None,
                  u_params: Optional[Sequence[float]] = None, v_params: Optional[Sequence[float]] = None,
                  tolerance: Optional[float] = None, periodic: Optional[Sequence[bool]] = None) -> Surface:
    """The surface through a network of curves as drawn: any order, either
    direction, crossings at different parameters (docs/spec-format.md, type
    network); method "gordon" (default), "coons_linear" or "coons_hermite";
    `u_params`/`v_params` where the v_curves/u_curves lie (found when not given),
    `tolerance` how far crossing curves may miss each other, `periodic` = (pu, pv)
    the closed directions.

    Examples
    --------
    >>> u_curves = [interpatch.interpolate_curve([[0, v, 0], [0.5, v, v / 4], [1, v, v]], degree=2, param="uniform")
    ...             for v in (0, 0.5, 1)]
    >>> v_curves = [interpatch.line([u, 0, 0], [u, 1, u * u]) for u in (0, 0.5, 1)]
    >>> s = interpatch.curve_network(u_curves, v_curves, method="gordon", u_params=[0, 0.5, 1], v_params=[0, 0.5, 1])
    >>> s.point(0.25, 0.5).round(9).tolist()                          # (u, v, u²v)
    [0.25, 0.5, 0.03125]
    >>> square = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]])
    >>> sections = [interpatch.interpolate_curve(r * square + [0, 0, z], periodic=True)
    ...             for r, z in ((1, 0), (1.5, 1), (1, 2))]
    >>> profiles = [[[x, y, 0], [1.5 * x, 1.5 * y, 1], [x, y, 2]] for x, y in square[:, :2]]
    >>> tube = interpatch.curve_network(sections, profiles, method="coons_hermite", tolerance=1e-6,
    ...                                 periodic=(True, False))
    >>> tube.info()["periodic"], np.allclose(tube.point(0.25, 0.5), [0, 1.5, 1])
    ([True, False], True)"""
    a = _Arrays()
    spec = {"type": "network", "u_curves": [_curve(c, a, f"u_curves[{i}]") for i, c in enumerate(u_curves)],
            "v_curves": [_curve(c, a, f"v_curves[{i}]") for i, c in enumerate(v_curves)]}
    if u_params is not None:
        spec["u_params"] = _reals(u_params, "u_params")
    if v_params is not None:
        spec["v_params"] = _reals(v_params, "v_params")
    return cast(Surface, _core.build(_options(spec, method=method, tolerance=tolerance, periodic=periodic), ".", a.table))


def loft(sections: Sequence[_CurveLike], degree: Optional[int] = None, param: Union[str, Sequence[float], None] = None,
         periodic: Optional[bool] = None, tolerance: Optional[float] = None,
         tangents: Optional[Sequence[Optional[_CurveLike]]] = None,
         guides: Optional[Sequence[_CurveLike]] = None) -> Surface:
    """The surface through a row of section curves (Curve objects, or arrays of points
    to interpolate): S(u, v_k) = C_k(u), C^(q-1) across (docs/spec-format.md, type
    loft). Closed sections given from other starts or the other way round are turned
    and shifted to follow the first, so the surface does not twist. `degree` across
    (default 3, lowered for few sections); `param` "chord" (default), "centripetal",
    "uniform" or the v_k; `periodic` closes it across the sections; `tolerance` for
    closed ends and the re-expression of sections with unrelated knots; `tangents`
    dS/dv at the first and last section, or one per section (None for none); `guides`
    curves across the sections: the loft is then the Gordon surface of sections and
    guides (as curve_network).

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    >>> def ring(r, z, start=0, turned=False):
    ...     p = np.column_stack([r * np.cos(t), r * np.sin(t), np.full(12, z)])
    ...     p = np.roll(p, -start, axis=0)
    ...     return interpatch.interpolate_curve(p[::-1] if turned else p, periodic=True)
    >>> s = interpatch.loft([ring(1, 0), ring(0.7, 1, start=4), ring(0.5, 2, start=9, turned=True)],
    ...                     degree=2, param="centripetal", tolerance=1e-9)
    >>> u_line = np.array([s.point(0.25, v) for v in np.linspace(0, 1, 5)])
    >>> np.allclose(u_line[:, 0], 0, atol=1e-9)                      # no twist: u = 0.25 stays at x = 0
    True
    >>> [sec["reversed"] for sec in s.info()["parameters"]["loft_sections"].values()]
    [False, False, True]
    >>> duct = interpatch.loft([[[0, 0, 0], [1, 0, 0]], [[0, 0, 1], [1, 0, 1]]], param=[0, 1], periodic=False,
    ...                        tangents=[interpatch.line([0, 1, 0], [0, 1, 0]), interpatch.line([0, -1, 0], [0, -1, 0])])
    >>> duct.point(0.5, 0.5).round(6).tolist()                        # bulges by a quarter of the tangent
    [0.5, 0.25, 0.5]
    >>> arch = interpatch.loft([[[0, 0, 0], [1, 0, 0]], [[1, 2, 0], [0, 2, 0]]],   # the second given the other way
    ...                        guides=[[[0, 0, 0], [0, 1, 1], [0, 2, 0]], [[1, 0, 0], [1, 1, 1], [1, 2, 0]]])
    >>> arch.point(0.5, 0.5).round(6).tolist(), arch.info()["parameters"]["loft_sections"]["/sections/1"]["reversed"]
    ([0.5, 1.0, 1.0], True)"""
    a = _Arrays()
    spec: dict[str, Any] = {"type": "loft", "sections": [_curve(c, a, f"sections[{i}]") for i, c in enumerate(sections)]}
    if tangents is not None:
        spec["tangents"] = [None if c is None else _curve(c, a, f"tangents[{i}]") for i, c in enumerate(tangents)]
    if guides is not None:
        spec["guides"] = [_curve(c, a, f"guides[{i}]") for i, c in enumerate(guides)]
    if param is not None and not isinstance(param, str):
        param = _reals(param, "param")
    return cast(Surface, _core.build(_options(spec, degree=degree, param=param, periodic=periodic, tolerance=tolerance), ".",
                                a.table))


def hermite_patch(corners: dict[str, dict[str, npt.ArrayLike]]) -> Surface:
    """The bicubic Hermite patch of four corners, each {"p", "du", "dv", "duv"}, keyed
    "p00", "p01", "p10", "p11".

    Examples
    --------
    >>> s = interpatch.hermite_patch(corners={
    ...     "p00": {"p": [0, 0, 0], "du": [1, 0, 0], "dv": [0, 1, 0], "duv": [0, 0, 1.1]},
    ...     "p01": {"p": [0, 1, 0], "du": [1, 0, 0.3], "dv": [0, 1, 0], "duv": [0, 0, -0.5]},
    ...     "p10": {"p": [1, 0, 0], "du": [1, 0, 0], "dv": [0, 1, 0.5], "duv": [0, 0, -0.1]},
    ...     "p11": {"p": [1, 1, 0.5], "du": [1, 0, 0.7], "dv": [0, 1, 0.5], "duv": [0, 0, 1.5]}})
    >>> s.point(1, 1).tolist(), s.evaluate_derivatives([0], [1])[0, 0, 1].round(9).tolist()  # S(1, 1), Su(0, 1)
    ([1.0, 1.0, 0.5], [1.0, 0.0, 0.3])"""
    spec = {"type": "hermite_patch",
            "corners": {k: {f: _point(v, f"corners[{k!r}][{f!r}]") for f, v in c.items()} for k, c in corners.items()}}
    return cast(Surface, _core.build(spec, ".", {}))


def build(spec: Union[dict[str, Any], _Path], base_dir: _Path = ".",
          arrays: Optional[dict[str, npt.ArrayLike]] = None) -> Union[Surface, Volume, Curve]:
    """A spec (docs/spec-format.md) as a dict, or the path of a spec file, built (a
    Curve for a curve spec: a curve at the top level, without "type"); anything else
    is refused ('wrong_type'). A dict may name NumPy arrays given in `arrays` as
    {"array": NAME} wherever it takes a point array; every array given must be named
    by the spec, and a field names an array or a file, not both. A masked array's
    masked points are missing (NaN). Files a dict names are found from `base_dir`.

    Examples
    --------
    >>> interpatch.build({"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0], "p11": [1, 1, 1]})
    Surface(type='bilinear', degree=(1, 1), control_points=(2, 2))
    >>> interpatch.build({"line": [[0, 0, 0], [1, 1, 1]]})
    Curve(type='line', degree=1, control_points=2)
    >>> x, y = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 7), indexing="ij")
    >>> s = interpatch.build({"type": "approximate", "points": {"array": "survey"}, "control_points": [5, 4]},
    ...                      arrays={"survey": np.stack([x, y, x * y], axis=-1)})
    >>> import os, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     s.write(os.path.join(d, "fit.npz"))
    ...     back = interpatch.build({"type": "bspline_surface", "npz": "fit.npz"}, base_dir=d)
    >>> back, np.array_equal(back.to_bspline()["control_points"], s.to_bspline()["control_points"])
    (Surface(type='bspline_surface', degree=(3, 3), control_points=(5, 4)), True)"""
    return _core.build(spec, base_dir, {} if arrays is None else arrays)
