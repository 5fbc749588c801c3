"""The conversions of the keyword constructors (_specs.py): arguments checked and
turned into the fields of a spec, arrays named for the module to read in memory."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._core import Curve, Surface, Volume
from ._core import Error as Error_


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


def _approximation(spec: dict[str, Any], control_points: Any, tolerance: Optional[float], smoothing: Any,
                   weights: Any) -> dict[str, Any]:
    spec = _options(spec, control_points=control_points, tolerance=tolerance, smoothing=smoothing)
    if weights is not None:
        spec["weights"] = _reals(weights, "weights")
    return spec


def _surface_spec(face: Any, arrays: _Arrays, name: str) -> dict[str, Any]:
    """A surface argument as a spec: a dict as it is, a Surface by its exact form (bit
    for bit), a grid of points (n, m, 3) as the surface through them."""
    if isinstance(face, dict):
        return face
    if isinstance(face, Surface):
        b = face.to_bspline()
        spec: dict[str, Any] = {"type": "bspline_surface", "degree": list(b["degree"]),
                                "knots": {"u": b["knots_u"].tolist(), "v": b["knots_v"].tolist()},
                                "control_points": arrays.add(b["control_points"], f"{name}.control_points"),
                                "periodic": list(b["periodic"])}
        if b["weights"] is not None:
            spec["weights"] = b["weights"].tolist()
        return spec
    return {"type": "interpolate", "points": arrays.add(face, name)}


def _volume_spec(block: Any, arrays: _Arrays, name: str) -> dict[str, Any]:
    """A volume argument as a spec: a dict as it is, a Volume by its exact form (bit
    for bit)."""
    if isinstance(block, dict):
        return block
    if isinstance(block, Volume):
        b = block.to_bspline()
        spec: dict[str, Any] = {"type": "bspline_volume", "degree": list(b["degree"]),
                                "knots": {"u": b["knots_u"].tolist(), "v": b["knots_v"].tolist(),
                                          "w": b["knots_w"].tolist()},
                                "control_points": arrays.add(b["control_points"], f"{name}.control_points"),
                                "periodic": list(b["periodic"])}
        if b["weights"] is not None:
            spec["weights"] = b["weights"].tolist()
        return spec
    raise _error("wrong_type", f"{name}: a Volume or a volume spec dict, got {type(block).__name__}")


def _scattered_sites(spec: dict[str, Any], arrays: _Arrays, param: Any, params: Any, base: Any) -> None:
    """Where scattered points sit, as approximate_surface takes it: a name (`param`,
    already in the spec), the sites (`params`, (N, 2)) or a base surface (`base`)."""
    if sum(x is not None for x in (param, params, base)) > 1:
        raise _error("wrong_type", "give one of param (a name), params (the sites) and base (a surface)")
    if params is not None:
        sites = np.asarray(params, dtype=float)
        if sites.ndim != 2 or sites.shape[1] != 2:
            raise _error("size_mismatch", f"params: shape {sites.shape}; the sites of scattered points are (N, 2)")
        spec["param"] = arrays.add(np.column_stack([sites, np.zeros(len(sites))]), "params")
    if base is not None:
        spec["param"] = {"base": _surface_spec(base, arrays, "base")}
