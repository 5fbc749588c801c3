"""The keyword constructors of volumes, as _specs.py makes those of curves and
surfaces (its docstring says how); _specs.py exports them."""

from __future__ import annotations

from typing import Any, Optional, Sequence, Union, cast

import numpy.typing as npt

from . import _core
from ._args import _approximation, _Arrays, _error, _options, _point, _real, _reals, _surface_spec, _volume_spec
from ._core import Volume

__all__ = ["interpolate_volume", "trilinear", "coons_volume", "hermite_volume", "approximate_volume", "loft_volume",
           "blocks"]


def approximate_volume(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                       param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None,
                       control_points: Union[int, Sequence[int], None] = None, tolerance: Optional[float] = None,
                       smoothing: Union[float, str, None] = None, weights: Optional[npt.ArrayLike] = None) -> Volume:
    """A B-spline volume near a grid of points, shape (n, m, l, 3), NaN (or a masked
    entry) marking missing points; the options of approximate_surface, one per
    direction u, v, w.

    Examples
    --------
    >>> u, v, w = np.meshgrid(np.linspace(0, 1, 8), np.linspace(0, 1, 7), np.linspace(0, 1, 5), indexing="ij")
    >>> block = np.stack([2 * u, v, w + 0.2 * np.sin(np.pi * u)], axis=-1)         # (8, 7, 5, 3)
    >>> interpatch.approximate_volume(block, control_points=(6, 5, 4)).info()["control_points"]
    [6, 5, 4]
    >>> noisy = block + np.random.default_rng(3).normal(0, 0.002, block.shape)
    >>> vol = interpatch.approximate_volume(noisy, degree=2, param="uniform", tolerance=0.01,
    ...                                     weights=np.where(w == 0, 4.0, 1.0))      # the base counts more
    >>> vol.info()["parameters"]["max_error"] <= 0.01
    True
    >>> r, t, z = np.meshgrid([1, 1.5, 2], np.linspace(0, 2 * np.pi, 12, endpoint=False), [0, 1, 2], indexing="ij")
    >>> ring = np.stack([r * np.cos(t), r * np.sin(t), z], axis=-1)                 # closed around v
    >>> vol = interpatch.approximate_volume(ring, periodic=(False, True, False), smoothing=1e-4)
    >>> vol.info()["periodic"]
    [False, True, False]"""
    a = _Arrays()
    spec = _options({"type": "approximate_volume", "points": a.add(points, "points", missing=True)}, degree=degree,
                    param=param,
                    periodic=periodic)
    return cast(Volume, _core.build(_approximation(spec, control_points, tolerance, smoothing, weights), ".", a.table))


def loft_volume(sections: Sequence[Any], degree: Optional[int] = None, param: Union[str, Sequence[float], None] = None,
                periodic: Optional[bool] = None) -> Volume:
    """The volume through a row of section surfaces (Surface objects, surface spec dicts,
    or grids of points (n, m, 3) to interpolate): V(u, v, w_k) = S_k(u, v), C^(q-1)
    across (docs/spec-format.md, type loft_volume). `degree` across (default 3,
    lowered for few sections); `param` "chord" (default), "centripetal", "uniform" or
    the w_k; `periodic` closes it across the sections.

    Examples
    --------
    >>> floor = interpatch.bilinear([0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0])
    >>> middle = np.array([[[0, 0, 1], [0, 0.5, 1.2], [0, 1, 1]], [[0.5, 0, 1.1], [0.5, 0.5, 1.4], [0.5, 1, 1.1]],
    ...                    [[1, 0, 1], [1, 0.5, 1.2], [1, 1, 1]]])
    >>> lid = {"type": "bilinear", "p00": [0, 0, 2], "p01": [0, 1, 2], "p10": [1, 0, 2], "p11": [1, 1, 2]}
    >>> body = interpatch.loft_volume([floor, middle, lid], degree=2, param="uniform", periodic=False)
    >>> body.point(0.5, 0.5, 0.5).round(9).tolist()                  # the middle section's top
    [0.5, 0.5, 1.4]
    >>> interpatch.loft_volume([floor, lid], param=[0, 1]).info()["degree"]    # two sections: straight across
    [1, 1, 1]"""
    a = _Arrays()
    spec: dict[str, Any] = {"type": "loft_volume",
                            "sections": [_surface_spec(s, a, f"sections[{i}]") for i, s in enumerate(sections)]}
    if param is not None and not isinstance(param, str):
        param = _reals(param, "param")
    return cast(Volume, _core.build(_options(spec, degree=degree, param=param, periodic=periodic), ".", a.table))


def blocks(blocks: Sequence[Any], names: Optional[Sequence[str]] = None,
           sampling: Optional[Sequence[Optional[dict[str, Any]]]] = None,
           patches: Optional[dict[str, Sequence[str]]] = None, tolerance: Optional[float] = None) -> Volume:
    """Volumes meshed together (docs/spec-format.md, type blocks): `blocks` are Volume
    objects or volume spec dicts; `names` and `sampling` give each its name and its
    sampling (a dict per block, or None); `patches` groups outer faces ("NAME_w0") into
    named patches. The faces they share are found by geometry; write() the merged
    mesh to .vtu, .msh or CASE/constant/polyMesh.

    Examples
    --------
    >>> a = interpatch.trilinear([[[[0, 0, 0], [0, 0, 1]], [[0, 1, 0], [0, 1, 1]]],
    ...                           [[[1, 0, 0], [1, 0, 1]], [[1, 1, 0], [1, 1, 1]]]])
    >>> b = {"type": "trilinear", "p000": [1, 0, 0], "p001": [1, 0, 1], "p010": [1, 1, 0], "p011": [1, 1, 1],
    ...      "p100": [2, 0, 0], "p101": [2, 0, 1], "p110": [2, 1, 0], "p111": [2, 1, 1]}
    >>> two = interpatch.blocks([a, b], names=["left", "right"],
    ...                         sampling=[{"u": {"count": 5}, "v": {"count": 3}}, {"w": {"count": 3}}],
    ...                         patches={"ends": ["left_u0", "right_u1"]}, tolerance=1e-9)
    >>> info = two.info()                  # v and w tied across the shared face: 3 x 3 nodes on it
    >>> info["shared_faces"][0]["faces"], info["mesh"]["points"], info["patches"]["ends"]
    (['u1', 'u0'], 333, 8)"""
    a = _Arrays()
    specs = []
    for i, block in enumerate(blocks):
        spec = dict(_volume_spec(block, a, f"blocks[{i}]"))
        if names is not None:
            spec["name"] = names[i]
        if sampling is not None and sampling[i] is not None:
            spec["sampling"] = sampling[i]
        specs.append(spec)
    return cast(Volume, _core.build(_options({"type": "blocks", "blocks": specs}, patches=patches, tolerance=tolerance),
                               ".", a.table))


def interpolate_volume(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                       param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None) -> Volume:
    """The B-spline volume through a grid of points, shape (n, m, l, 3): tricubic unless
    `degree` (an int or (p, q, r)) says otherwise, parameters by `param` averaged over
    the lines, closed in the directions `periodic` = (pu, pv, pw) says.

    Examples
    --------
    >>> slab = [[[[0, 0, 0], [0, 0, 1]], [[0, 1, 0], [0, 1, 1]]],                  # an arched slab, 3 x 2 x 2
    ...         [[[1, 0, 0.2], [1, 0, 1.2]], [[1, 1, 0.2], [1, 1, 1.2]]],
    ...         [[[2, 0, 0], [2, 0, 1]], [[2, 1, 0], [2, 1, 1]]]]
    >>> vol = interpatch.interpolate_volume(slab)
    >>> vol.info()["degree"], vol.point(0.5, 0.5, 0.5).round(9).tolist()
    ([2, 1, 1], [1.0, 0.5, 0.7])
    >>> r, t, z = np.meshgrid([1, 1.5], np.linspace(0, 2 * np.pi, 9), [0, 1], indexing="ij")
    >>> wall = np.stack([r * np.cos(t), r * np.sin(t), z], axis=-1)               # a thick tube, closed around v
    >>> vol = interpatch.interpolate_volume(wall, degree=(1, 3, 1), param="centripetal", periodic=(False, True, False))
    >>> vol.info()["control_points"]
    [2, 8, 2]"""
    a = _Arrays()
    spec = _options({"type": "interpolate_volume", "points": a.add(points, "points")}, degree=degree, param=param,
                    periodic=periodic)
    return cast(Volume, _core.build(spec, ".", a.table))


def trilinear(corners: npt.ArrayLike) -> Volume:
    """The trilinear volume of eight corners, shape (2, 2, 2, 3): corners[i][j][k] = S(i, j, k).

    Examples
    --------
    >>> block = interpatch.trilinear(corners=[[[[0, 0, 0], [0.2, 0, 1]], [[0, 1, 0], [0.3, 0.9, 1.1]]],
    ...                                       [[[2, 0, 0], [1.8, 0.1, 0.8]], [[2, 1.2, 0], [1.9, 1.1, 0.9]]]])
    >>> block.point(1, 1, 1).tolist(), block.point(0.5, 0.5, 0.5).round(9).tolist()
    ([1.9, 1.1, 0.9], [1.025, 0.5375, 0.475])"""
    c = _real(corners, "corners")
    if c.shape != (2, 2, 2, 3):
        raise _error("size_mismatch", f"corners: expected shape (2, 2, 2, 3), got {c.shape}")
    spec: dict[str, Any] = {"type": "trilinear"}
    for i in range(2):
        for j in range(2):
            for k in range(2):
                spec[f"p{i}{j}{k}"] = _point(c[i, j, k], f"corners[{i}, {j}, {k}]")
    return cast(Volume, _core.build(spec, ".", {}))


def coons_volume(faces: dict[str, Any], blending: Optional[str] = None, tolerance: Optional[float] = None) -> Volume:
    """The Coons volume of six faces keyed u0, u1, v0, v1, w0, w1 (S(0, v, w), S(1, v, w),
    S(u, 0, w), ...): each a grid of points (n, m, 3) to interpolate, or a surface spec dict.

    Examples
    --------
    >>> def quad(p00, p01, p10, p11):
    ...     return {"type": "bilinear", "p00": p00, "p01": p01, "p10": p10, "p11": p11}
    >>> bulge = np.array([[[0, 1, 0], [0, 1, 0.5], [0, 1, 1]],  # face v1 by (u, w), interpolated
    ...                   [[1, 1, 0], [1, 1.5, 0.5], [1, 1, 1]], [[2, 1, 0], [2, 1, 0.5], [2, 1, 1]]])
    >>> box = interpatch.coons_volume({"u0": quad([0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1]),
    ...                                "u1": quad([2, 0, 0], [2, 0, 1], [2, 1, 0], [2, 1, 1]),
    ...                                "v0": quad([0, 0, 0], [0, 0, 1], [2, 0, 0], [2, 0, 1]), "v1": bulge,
    ...                                "w0": quad([0, 0, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]),
    ...                                "w1": quad([0, 0, 1], [0, 1, 1], [2, 0, 1], [2, 1, 1])},
    ...                               blending="hermite", tolerance=1e-6)
    >>> box.point(0.5, 1, 0.5).round(9).tolist(), box.point(0.5, 0.5, 0.5).round(9).tolist()
    ([1.0, 1.5, 0.5], [1.0, 0.75, 0.5])"""
    a = _Arrays()
    spec = {"type": "coons_volume", "faces": {k: _surface_spec(f, a, f"faces[{k!r}]") for k, f in faces.items()}}
    return cast(Volume, _core.build(_options(spec, blending=blending, tolerance=tolerance), ".", a.table))


def hermite_volume(corners: Sequence[dict[str, npt.ArrayLike]]) -> Volume:
    """The tricubic Hermite volume of 8 corners (index 4i + 2j + k for corner (i, j, k)), each
    {"p", "du", "dv", "dw"} and optionally "duv", "duw", "dvw", "duvw".

    Examples
    --------
    >>> corners = [{"p": [2 * i, j, k], "du": [2, 0, 0], "dv": [0, 1, 0], "dw": [0, 0, 1 + i]}
    ...            for i in (0, 1) for j in (0, 1) for k in (0, 1)]                 # corner (i, j, k) at 4i + 2j + k
    >>> vol = interpatch.hermite_volume(corners=corners)
    >>> vol.point(0.5, 0.5, 0.5).round(9).tolist(), vol.point(1, 1, 1).tolist()
    ([1.0, 0.5, 0.5], [2.0, 1.0, 1.0])"""
    spec = {"type": "hermite_volume",
            "corners": [{f: _point(v, f"corners[{i}][{f!r}]") for f, v in c.items()} for i, c in enumerate(corners)]}
    return cast(Volume, _core.build(spec, ".", {}))
