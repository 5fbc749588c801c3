# Type stubs of the interpatch module: shapes in the docstrings.
from os import PathLike
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Array = npt.NDArray[np.float64]
_Params = Union[Sequence[float], npt.ArrayLike]
_Path = Union[str, PathLike[str]]

class Error(ValueError):
    """Bad input; .code names the problem (e.g. 'zero_chord'), the message the place and size:
    the argument (`points: ...`) or the spec's JSON Pointer (`/points/3/1/2: value is nan`).
    Arrays of complex, bool, object or text dtype are refused ('wrong_type'), as are masked
    entries where nothing may be missing. Ctrl-C during a long call raises KeyboardInterrupt."""
    code: str

ERROR_CODES: tuple[str, ...]
"""Every code an Error can carry (docs/spec-format.md, "Bad input")."""

class Construction:
    """What surfaces and volumes share."""
    @property
    def type(self) -> str: ...
    def info(self) -> dict[str, Any]:
        """The dict `interpatch info` prints. Its check at the data (max_data_error) compares
        with the arrays the construction was built from as they are now: it keeps them, not a copy."""
    def write(self, path: _Path, res: Optional[Sequence[int]] = None) -> None:
        """.json .npz .step .igs (the exact form), .obj .ply .stl .vtk .vts .xyz (a mesh of res vertices)
        or .html (a viewer page of res samples, as `interpatch view` writes it). Checked before any
        work as the command line checks it: res (nu, nv) for a surface, (nu, nv, nw) for a volume, each
        at least 2 ('too_few_points', 'size_mismatch'); a mesh too large for the memory or the
        disk ('too_large'); res with another format, or an unknown format ('wrong_type')."""
    @property
    def params_u(self) -> Optional[_Array]: ...
    @property
    def params_v(self) -> Optional[_Array]: ...
    @property
    def params_w(self) -> Optional[_Array]: ...

class Surface(Construction):
    """A surface over [0, 1]²; repr: Surface(type='interpolate', degree=(3, 3), control_points=(30, 25))."""
    def evaluate(self, us: _Params, vs: _Params) -> _Array:
        """Points at every (us[i], vs[j]): shape (len(us), len(vs), 3)."""
    def evaluate_derivatives(self, us: _Params, vs: _Params) -> _Array:
        """S, Su, Sv, Suu, Suv, Svv at every (us[i], vs[j]): shape (len(us), len(vs), 6, 3)."""
    def point(self, u: float, v: float) -> _Array:
        """S(u, v): shape (3,)."""
    def normal(self, u: float, v: float) -> _Array:
        """The unit normal: shape (3,)."""
    def curvature(self, u: float, v: float) -> dict[str, float]:
        """{'gaussian', 'mean', 'k1', 'k2'}."""
    def to_bspline(self) -> dict[str, Any]:
        """{'degree': (p, q), 'knots_u', 'knots_v', 'control_points' (nu, nv, 3), 'weights' (nu, nv) or None, 'periodic'};
        the arrays are read-only views of the construction's memory (copy them to change them)."""

class Volume(Construction):
    """A volume over [0, 1]³; repr: Volume(type='trilinear', degree=(1, 1, 1), control_points=(2, 2, 2))."""
    def evaluate(self, us: _Params, vs: _Params, ws: _Params) -> _Array:
        """Points: shape (len(us), len(vs), len(ws), 3)."""
    def jacobians(self, us: _Params, vs: _Params, ws: _Params) -> tuple[_Array, _Array]:
        """(points (..., 3), det J (len(us), len(vs), len(ws)))."""
    def point(self, u: float, v: float, w: float) -> _Array: ...
    def to_bspline(self) -> dict[str, Any]:
        """{'degree': (p, q, r), 'knots_u', 'knots_v', 'knots_w', 'control_points' (n0, n1, n2, 3), 'weights', 'periodic'};
        read-only views of the construction's memory."""

class Curve:
    """A curve C(t) over [0, 1], built from a curve spec: interpolate_curve, approximate_curve,
    bspline_curve, hermite_curve, line, or build() of a curve spec; repr:
    Curve(type='interpolate', degree=3, control_points=12)."""
    @property
    def type(self) -> str:
        """'interpolate', 'approximate', 'bspline', 'hermite' or 'line'."""
    @property
    def degree(self) -> int: ...
    @property
    def domain(self) -> tuple[float, float]:
        """(0.0, 1.0)."""
    @property
    def params(self) -> Optional[_Array]:
        """The parameters of its points, shape (n,) (interpolate, approximate, hermite); None otherwise."""
    def evaluate(self, ts: _Params) -> _Array:
        """C(ts[i]): shape (len(ts), 3). An open curve refuses t outside [0, 1] ('out_of_domain')."""
    def derivatives(self, ts: _Params, order: int = 1) -> _Array:
        """C and its derivatives up to `order` at every ts[i]: shape (len(ts), order + 1, 3)."""
    def point(self, t: float) -> _Array:
        """C(t): shape (3,)."""
    def tangent(self, t: float) -> _Array:
        """The unit tangent: shape (3,); zero where C' vanishes."""
    def curvature(self, t: float) -> float:
        """|C' × C''| / |C'|³; NaN where C' vanishes."""
    def to_bspline(self) -> dict[str, Any]:
        """{'degree': p, 'knots' (n + p + 1,), 'control_points' (n, 3), 'weights' (n,) or None, 'periodic'};
        read-only views of the curve's memory."""
    def info(self) -> dict[str, Any]:
        """The dict `interpatch info` prints for the curve spec."""
    def write(self, path: _Path) -> None:
        """.json .npz .step .igs, as `interpatch build` writes the curve spec ('wrong_type' for another format)."""

_CurveLike = Union[Curve, npt.ArrayLike]

def build(spec: Union[dict[str, Any], _Path], base_dir: _Path = ".",
          arrays: Optional[dict[str, npt.ArrayLike]] = None) -> Union[Surface, Volume, Curve]:
    """A spec as a dict (arrays named {"array": NAME}) or the path of a spec file, built (a Curve for a
    curve spec: a curve at the top level, without "type"); anything else is refused ('wrong_type'). Every array in `arrays` must be named by the spec, and a field
    names an array or a file, not both. A masked array's masked points are missing (NaN)."""
def interpolate_surface(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                        param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None) -> Surface:
    """Through a grid of points, shape (n, m, 3), every one present (a masked entry is refused)."""
def interpolate_volume(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                       param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None) -> Volume:
    """Through a grid of points, shape (n, m, l, 3)."""
def approximate_surface(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                        param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None,
                        control_points: Union[int, Sequence[int], None] = None, tolerance: Optional[float] = None,
                        smoothing: Union[float, str, None] = None, weights: Optional[npt.ArrayLike] = None) -> Surface:
    """Near a grid of points, shape (n, m, 3), NaN (or a masked entry) marking missing points; exactly one of
    control_points, tolerance, smoothing (a number or "auto")."""
def approximate_volume(points: npt.ArrayLike, degree: Union[int, Sequence[int], None] = None,
                       param: Optional[str] = None, periodic: Optional[Sequence[bool]] = None,
                       control_points: Union[int, Sequence[int], None] = None, tolerance: Optional[float] = None,
                       smoothing: Union[float, str, None] = None, weights: Optional[npt.ArrayLike] = None) -> Volume:
    """Near a grid of points, shape (n, m, l, 3), NaN (or a masked entry) marking missing points."""
def approximate_curve(points: npt.ArrayLike, degree: Optional[int] = None, param: Optional[str] = None,
                      periodic: bool = False, control_points: Optional[int] = None, tolerance: Optional[float] = None,
                      smoothing: Union[float, str, None] = None, weights: Optional[npt.ArrayLike] = None) -> Curve:
    """A curve near points, shape (n, 3), NaN marking missing ones; exactly one of control_points,
    tolerance, smoothing."""
def bilinear(p00: npt.ArrayLike, p01: npt.ArrayLike, p10: npt.ArrayLike, p11: npt.ArrayLike) -> Surface: ...
def ruled(c0: _CurveLike, c1: _CurveLike) -> Surface: ...
def coons(v0: _CurveLike, v1: _CurveLike, u0: _CurveLike, u1: _CurveLike, blending: Optional[str] = None,
          tolerance: Optional[float] = None) -> Surface: ...
def curve_network(u_curves: Sequence[_CurveLike], v_curves: Sequence[_CurveLike], method: Optional[str] = None,
                  u_params: Optional[Sequence[float]] = None, v_params: Optional[Sequence[float]] = None,
                  tolerance: Optional[float] = None, periodic: Optional[Sequence[bool]] = None) -> Surface: ...
def hermite_patch(corners: dict[str, dict[str, npt.ArrayLike]]) -> Surface: ...
def trilinear(corners: npt.ArrayLike) -> Volume:
    """Corners of shape (2, 2, 2, 3): corners[i][j][k] = S(i, j, k)."""
def coons_volume(faces: dict[str, Any], blending: Optional[str] = None, tolerance: Optional[float] = None) -> Volume: ...
def hermite_volume(corners: Sequence[dict[str, npt.ArrayLike]]) -> Volume: ...
def interpolate_curve(points: npt.ArrayLike, degree: Optional[int] = None, param: str = "chord",
                      periodic: bool = False, start_derivative: Optional[npt.ArrayLike] = None,
                      end_derivative: Optional[npt.ArrayLike] = None) -> Curve:
    """Through points, shape (n, 3): C(params[i]) = points[i]."""
def bspline_curve(degree: int, knots: Sequence[float], control_points: npt.ArrayLike,
                  weights: Optional[Sequence[float]] = None, periodic: bool = False) -> Curve:
    """Knots (n + p + 1; closed: n + 2p + 1), control points (n, 3), weights (n,)."""
def hermite_curve(points: npt.ArrayLike, tangents: Optional[npt.ArrayLike] = None,
                  params: Optional[Sequence[float]] = None) -> Curve:
    """Piecewise cubic through points (n, 3) with tangents (n, 3) at params (n,)."""
def line(a: npt.ArrayLike, b: npt.ArrayLike) -> Curve: ...
