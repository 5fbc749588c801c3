"""Random arrays into the Python module's constructors (Hypothesis, Debian's
python3-hypothesis): any shape, dtype, memory order, mask and values (NaN, infinities,
huge, tiny). The property: a construction whose evaluation is finite, or
interpatch.Error; never another exception, never a crash.

Kept to a few seconds in `make test` (max_examples, no deadline)."""

import warnings

import numpy as np
import pytest

import interpatch

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from hypothesis.extra import numpy as hnp  # noqa: E402

SPECIAL = [np.nan, np.inf, -np.inf, 1e308, -1e308, 1e-308, 5e-324, 0.0, -0.0, 1.0, 1e154, 1e-154]
VALUES = st.one_of(st.floats(-10, 10), st.sampled_from(SPECIAL), st.floats(allow_nan=True, allow_infinity=True))
DTYPES = ["float64", "float32", "float16", "int64", "int8", "uint16", "complex128", "bool", "object", "str"]
LAYOUTS = ["c", "fortran", "strided", "masked", "list"]


@st.composite
def arrays(draw, rank):
    """An array of `rank` grid axes and (mostly) 3 per point, in any dtype and layout."""
    axes = draw(st.lists(st.integers(0, 6), min_size=rank, max_size=rank))
    last = draw(st.sampled_from([3, 3, 3, 2, 0]))
    shape = tuple(axes) + (last,)
    if draw(st.integers(0, 9)) == 0:  # a rank other than asked now and then
        shape = shape[1:] if len(shape) > 1 and draw(st.booleans()) else shape + (3,)
    a = draw(hnp.arrays(np.float64, shape, elements=VALUES))
    if draw(st.integers(0, 2)) == 0:  # mostly a smooth grid, whose constructions succeed
        a = np.cumsum(np.abs(np.nan_to_num(a, nan=1.0, posinf=1.0, neginf=1.0)) % 3 + 0.5, axis=0) if a.size else a
    dtype = draw(st.sampled_from(DTYPES))
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        if dtype == "complex128":
            a = a + 1j * draw(st.sampled_from([0.0, 1.0]))
        elif dtype == "bool":
            a = a > 0
        elif dtype in ("object", "str"):
            a = a.astype(dtype)
        else:
            a = a.astype(dtype)
    layout = draw(st.sampled_from(LAYOUTS))
    if layout == "fortran":
        a = np.asfortranarray(a)
    elif layout == "strided" and a.ndim:
        a = np.repeat(a, 2, axis=0)[::2]
    elif layout == "masked":
        mask = draw(hnp.arrays(np.bool_, a.shape))
        a = np.ma.masked_array(a, mask=mask)
    elif layout == "list":
        a = a.tolist()
    return a


def finite_or_error(make, evaluate):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy warning may stand in for an error either
        try:
            built = make()
        except interpatch.Error:
            return
        values = evaluate(built)
    assert np.all(np.isfinite(values)), "a construction whose evaluation is not finite"


T = np.linspace(0, 1, 5)
FUZZ = settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))


@FUZZ
@given(arrays(2))
def test_interpolate_surface(a):
    finite_or_error(lambda: interpatch.interpolate_surface(a), lambda s: s.evaluate(T, T))


@FUZZ
@given(arrays(2), st.sampled_from([{"tolerance": 0.5}, {"control_points": (4, 4)}, {"smoothing": 1e-3}]))
def test_approximate_surface(a, how):
    finite_or_error(lambda: interpatch.approximate_surface(a, **how), lambda s: s.evaluate(T, T))


@FUZZ
@given(st.integers(0, 60).flatmap(lambda n: hnp.arrays(np.float64, (n, 3), elements=VALUES)),
       st.sampled_from([{"tolerance": 0.5, "param": "xy"}, {"control_points": (4, 5)},
                        {"smoothing": 1e-3, "param": "xy"}, {"tolerance": 1e-3}]))
def test_approximate_scattered_points(a, how):
    finite_or_error(lambda: interpatch.approximate_surface(a, **how), lambda s: s.evaluate(T, T))


@FUZZ
@given(arrays(3))
def test_interpolate_volume(a):
    finite_or_error(lambda: interpatch.interpolate_volume(a), lambda v: v.evaluate(T, T, T))


@FUZZ
@given(arrays(1), arrays(1))
def test_ruled_between_curves(a, b):
    finite_or_error(lambda: interpatch.ruled(a, b), lambda s: s.evaluate(T, T))


SURFACE = None


@FUZZ
@given(arrays(0))
def test_evaluation_parameters(us):
    global SURFACE
    if SURFACE is None:
        x, y = np.meshgrid(np.arange(4.0), np.arange(5.0), indexing="ij")
        SURFACE = interpatch.interpolate_surface(np.stack([x, y, x * y], axis=-1))
    finite_or_error(lambda: SURFACE.evaluate(us, [0.5]), lambda g: g)
