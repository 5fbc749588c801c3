# Type stubs of the compiled module interpatch._core: shapes in the docstrings. The
# package re-exports its classes and constants (__init__.pyi); the keyword
# constructors and build() are _specs.py, annotated where they are defined.
from os import PathLike
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

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
    def write(self, path: _Path, res: Optional[Sequence[int]] = None,
              sampling: Optional[dict[str, dict[str, float]]] = None) -> None:
        """.json .npz .step .igs (the exact form), .obj .ply .stl .vtk .vts .xyz (a mesh of res vertices)
        or .html (a viewer page of res samples, as `interpatch view` writes it). Checked before any
        work as the command line checks it: res (nu, nv) for a surface, (nu, nv, nw) for a volume, each
        at least 2 ('too_few_points', 'size_mismatch'); a mesh too large for the memory or the
        disk ('too_large'); res with another format, or an unknown format ('wrong_type').
        A mesh's nodes follow `sampling`, a dict as a spec's "sampling" ({'w': {'count': 41,
        'first': 1e-3}}), or else the spec's own; its counts give way to res."""
    def mesh_params(self, res: Optional[Sequence[int]] = None,
                    sampling: Optional[dict[str, dict[str, float]]] = None) -> tuple[_Array, ...]:
        """The parameters of the nodes write() places along each direction for a mesh of res
        vertices (the spec's sampling counts, or the kind's default): (u, v) or (u, v, w), graded
        as `sampling` (or else the spec's "sampling") says, even steps otherwise.
        Example: s.evaluate(*s.mesh_params()) gives the mesh's points."""
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
    def closest_points(self, points: npt.ArrayLike) -> dict[str, _Array]:
        """The closest point of the surface to each of points (..., 3): {'params' (..., 2), 'points' (..., 3),
        'distance' (...,)}; global: nothing on the surface is nearer than distance less 1e-10 of its diagonal.
        A NaN point is refused naming its index ('not_finite'); no exact form: 'no_exact_form'."""
    def intersect(self, origins: npt.ArrayLike, directions: npt.ArrayLike) -> dict[str, Any]:
        """Every hit of the rays origins[i] + t * directions[i], t >= 0 (origins (n, 3), directions (n, 3) or (3,)):
        {'ray' (h,) int64, 't' (h,), 'params' (h, 2), 'points' (h, 3)}, by ray, then by t. A zero direction:
        'wrong_type', naming the ray."""

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
    def locate(self, points: npt.ArrayLike) -> dict[str, Any]:
        """Where the volume holds each of points (..., 3): {'params' (..., 3), 'points' (..., 3), 'inside' (...,) bool,
        'residual' (...,)}; inside: V(params) is the point within 1e-10 of the diagonal; outside: the nearest
        point of the boundary and its distance."""

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
    def closest_points(self, points: npt.ArrayLike) -> dict[str, _Array]:
        """The closest point of the curve to each of points (..., 3): {'params' (...,), 'points' (..., 3),
        'distance' (...,)}; global, as Surface.closest_points."""

def build(spec: Union[dict[str, Any], _Path], base_dir: _Path = ".",
          arrays: dict[str, npt.ArrayLike] = ...) -> Union[Surface, Volume, Curve]:
    """A spec as a dict (arrays named {"array": NAME}, given in `arrays`) or the path of a
    spec file, built; interpatch.build (_specs.py) is this with `arrays` optional."""
def spec_fields() -> dict[str, dict[str, tuple[str, ...]]]:
    """Every form a spec may hold, as the reader checks it: {kind: {name: (field, ...)}}, kind
    'type' (construction types), 'curve' (curve forms) or 'points' (point arrays given as files)."""
