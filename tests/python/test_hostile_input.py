"""The Python module keeps the command line's promises under hostile input: the same
checks of outputs (counts, formats, room), masked and complex arrays, read-only views
of a construction's memory, errors that name the argument or the JSON Pointer, and
Ctrl-C during long calls.

Run by CTest (python_module) with PYTHONPATH=<build>/python and INTERPATCH_CLI set."""

import json
import os
import subprocess
import time

import numpy as np
import pytest

import interpatch
from ctrl_c import assert_ctrl_c_stops

CLI = os.environ.get("INTERPATCH_CLI", "interpatch")
EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))


def terrain(nx=12, ny=10):
    x = np.linspace(0, 4, nx)
    y = np.linspace(0, 3, ny)
    z = np.sin(x)[:, None] * np.cos(y)[None, :]
    return np.stack(np.broadcast_arrays(x[:, None], y[None, :], z), axis=-1)


# --- the command line's checks of outputs, made by write() ---

def test_a_mesh_too_large_is_refused_before_any_work(tmp_path):
    s = interpatch.interpolate_surface(terrain())
    start = time.monotonic()
    with pytest.raises(interpatch.Error) as e:
        s.write(str(tmp_path / "x.vts"), res=[100000000, 100000000])
    assert e.value.code == "too_large"
    assert time.monotonic() - start < 2, "refused before allocating, as the command line does"
    assert not (tmp_path / "x.vts").exists()
    # The command line refuses the same mesh with the same code (exit 5).
    spec = tmp_path / "s.json"
    spec.write_text(json.dumps({"type": "interpolate", "points": terrain().tolist()}))
    r = subprocess.run([CLI, "mesh", str(spec), "-o", str(tmp_path / "y.vts"), "--res", "100000000x100000000"],
                       capture_output=True, text=True)
    assert r.returncode == 5 and "mesh of 100000000x100000000 vertices" in r.stderr
    assert "mesh of 100000000x100000000 vertices" in str(e.value)


@pytest.mark.parametrize("res,code", [([1, 1], "too_few_points"), ([0, 5], "too_few_points"),
                                      ([-1, 5], "too_few_points"), ([2 ** 63, 2], "too_large"),
                                      ([2 ** 70, 2], "too_large"), ([2.5, 3], "wrong_type"), ([True, 3], "wrong_type"),
                                      ("64x64", "wrong_type"), ([3, 3, 3], "size_mismatch"), ([3], "size_mismatch")])
def test_mesh_counts_are_checked_as_the_command_line_checks_them(res, code, tmp_path):
    s = interpatch.interpolate_surface(terrain())
    with pytest.raises(interpatch.Error) as e:
        s.write(str(tmp_path / "x.obj"), res=res)
    assert e.value.code == code, str(e.value)
    want = "mesh of " if code == "too_large" else "res"  # the command line's "mesh of 2x3 vertices: ..."
    assert str(e.value).startswith(want), str(e.value)
    assert not (tmp_path / "x.obj").exists()


def test_counts_below_two_get_the_command_lines_message(tmp_path):
    s = interpatch.interpolate_surface(terrain())
    with pytest.raises(interpatch.Error) as e:
        s.write(str(tmp_path / "x.obj"), res=(0, 5))
    assert str(e.value) == "res (0, 5): a mesh needs at least 2 vertices along each direction"
    spec = tmp_path / "s.json"
    spec.write_text(json.dumps({"type": "interpolate", "points": terrain().tolist()}))
    r = subprocess.run([CLI, "mesh", str(spec), "-o", str(tmp_path / "y.obj"), "--res", "0x5"],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert "--res '0x5': a mesh needs at least 2 vertices along each direction" in r.stderr


def test_a_viewer_page_needs_two_samples_along_each_direction(tmp_path):
    s = interpatch.interpolate_surface(terrain())
    for res in ([0, 5], [1, 1]):
        with pytest.raises(interpatch.Error) as e:
            s.write(str(tmp_path / "x.html"), res=res)
        assert e.value.code == "too_few_points" and "view needs at least 2 samples" in str(e.value)
    assert not (tmp_path / "x.html").exists()


def test_formats_and_kinds_are_checked(tmp_path):
    s = interpatch.interpolate_surface(terrain())
    with pytest.raises(interpatch.Error) as e:
        s.write(str(tmp_path / "x.json"), res=[4, 4])
    assert e.value.code == "wrong_type" and "res" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        s.write(None)
    assert e.value.code == "wrong_type" and "path" in str(e.value)
    v = interpatch.build(os.path.join(EXAMPLES, "trilinear.json"))
    with pytest.raises(interpatch.Error) as e:
        v.write(str(tmp_path / "v.obj"))
    assert e.value.code == "wrong_type" and "holds surfaces only" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        v.write(str(tmp_path / "v.vts"), res=(4, 4))
    assert e.value.code == "size_mismatch" and "trilinear is a volume" in str(e.value)
    v.write(tmp_path / "v.vts", res=(2, 3, 4))  # an os.PathLike path
    assert (tmp_path / "v.vts").stat().st_size > 0


def test_an_stl_that_cannot_hold_the_shape_warns_as_the_command_line_does(tmp_path):
    # A 0.1 mm part 1e8 from the origin: binary STL's float32 rounds its points by
    # far more than its size. The file is written; .ply keeps doubles and is quiet.
    o, d = 1e8, 1e-4
    s = interpatch.build({"type": "bilinear", "p00": [o, o, o], "p01": [o, o + d, o],
                          "p10": [o + d, o, o], "p11": [o + d, o + d, o + d]})
    with pytest.warns(UserWarning, match="holds float32 coordinates"):
        s.write(str(tmp_path / "far.stl"), res=[5, 5])
    assert (tmp_path / "far.stl").exists()
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s.write(str(tmp_path / "far.ply"), res=[5, 5])


# --- masked arrays ---

def test_masked_points_are_missing_where_missing_points_are_allowed():
    grid = terrain(16, 14)
    mask = np.zeros(grid.shape, bool)
    mask[5:8, 4:7, 2] = True  # one coordinate masked: the whole point is missing
    masked = np.ma.masked_array(np.where(mask, 1e6, grid), mask=mask)
    holed = grid.copy()
    holed[5:8, 4:7] = np.nan
    a = interpatch.approximate_surface(masked, tolerance=0.05)
    b = interpatch.approximate_surface(holed, tolerance=0.05)
    assert a.info()["parameters"]["missing_points"] == 9
    ts = np.linspace(0, 1, 7)
    assert np.array_equal(a.evaluate(ts, ts), b.evaluate(ts, ts)), "the fill value 1e6 is not fitted"
    assert np.abs(a.evaluate(ts, ts)[..., 2]).max() < 2


def test_masked_points_are_refused_where_every_point_is_needed():
    grid = terrain()
    masked = np.ma.masked_array(grid, mask=np.zeros(grid.shape, bool))
    masked[2, 3, 1] = np.ma.masked
    with pytest.raises(interpatch.Error) as e:
        interpatch.interpolate_surface(masked)
    assert e.value.code == "wrong_type"
    assert str(e.value).startswith("points: masked at index (2, 3)")
    with pytest.raises(interpatch.Error) as e:
        interpatch.ruled(masked[:, 3], interpatch.line([0, 5, 0], [4, 5, 0]))
    assert str(e.value).startswith("c0: masked at index (2,)")
    # A mask with nothing masked is no missing point.
    clear = np.ma.masked_array(grid, mask=np.zeros(grid.shape, bool))
    assert interpatch.interpolate_surface(clear).type == "interpolate"
    s = interpatch.interpolate_surface(grid)
    with pytest.raises(interpatch.Error) as e:
        s.evaluate(np.ma.masked_array([0, 0.5, 1], mask=[0, 1, 0]), [0.5])
    assert e.value.code == "wrong_type" and str(e.value).startswith("us: masked at index (1,)")


# --- dtypes that are not real numbers ---

@pytest.mark.parametrize("make,dtype", [(lambda g: g + 1j, "complex128"), (lambda g: g > 1, "bool"),
                                        (lambda g: g.astype(object), "object"), (lambda g: g.astype(str), "<U")])
def test_arrays_that_are_not_real_numbers_are_refused(make, dtype):
    with _no_warnings():
        with pytest.raises(interpatch.Error) as e:
            interpatch.interpolate_surface(make(terrain()))
    assert e.value.code == "wrong_type"
    assert str(e.value).startswith("points: expected real numbers, got an array of dtype " + dtype), str(e.value)


class _no_warnings:
    """No NumPy ComplexWarning (or any other) on the way to the error."""

    def __enter__(self):
        import warnings
        self._catch = warnings.catch_warnings()
        self._catch.__enter__()
        warnings.simplefilter("error")

    def __exit__(self, *exc):
        return self._catch.__exit__(*exc)


def test_complex_corners_parameters_and_dict_values_are_refused():
    with pytest.raises(interpatch.Error) as e:
        interpatch.bilinear([0, 0, 1j], [0, 1, 0], [1, 0, 0], [1, 1, 1])
    assert e.value.code == "wrong_type" and str(e.value).startswith("p00:")
    s = interpatch.interpolate_surface(terrain())
    with pytest.raises(interpatch.Error) as e:
        s.evaluate(np.array([0.5 + 1j]), [0.5])
    assert e.value.code == "wrong_type" and str(e.value).startswith("us:") and "complex" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "bilinear", "p00": [0, 0, 1j], "p01": [0, 1, 0], "p10": [1, 0, 0], "p11": [1, 1, 1]})
    assert e.value.code == "wrong_type" and str(e.value).startswith("/p00/2:")


# --- read-only views ---

def test_to_bspline_arrays_are_read_only_views():
    s = interpatch.interpolate_surface(terrain())
    b = s.to_bspline()
    for key in ("knots_u", "knots_v", "control_points"):
        assert not b[key].flags.writeable, key
        with pytest.raises(ValueError):
            b[key][0] = np.nan
    assert np.shares_memory(b["control_points"], s.to_bspline()["control_points"]), "zero-copy"
    w = interpatch.build(os.path.join(EXAMPLES, "annular_sector.json")).to_bspline()
    if w["weights"] is not None:
        assert not w["weights"].flags.writeable
    v = interpatch.build(os.path.join(EXAMPLES, "trilinear.json")).to_bspline()
    for key in ("knots_u", "knots_v", "knots_w", "control_points"):
        assert not v[key].flags.writeable, key


# --- errors that name the argument or the field ---

def test_a_nan_in_a_dict_is_named_by_its_json_pointer():
    spec = {"type": "interpolate", "points": terrain(4, 4).tolist()}
    spec["points"][3][1][2] = float("nan")
    with pytest.raises(interpatch.Error) as e:
        interpatch.build(spec)
    assert e.value.code == "not_finite"
    assert str(e.value) == "/points/3/1/2: value is nan"
    spec["points"][3][1][2] = np.float32("inf")
    with pytest.raises(interpatch.Error) as e:
        interpatch.build(spec)
    assert str(e.value) == "/points/3/1/2: value is inf"


def test_array_errors_name_the_argument():
    with pytest.raises(interpatch.Error) as e:
        interpatch.interpolate_surface(np.zeros((3, 3, 2)))
    assert str(e.value).startswith("points: expected an array of points of shape (..., 3), got (3, 3, 2)")
    with pytest.raises(interpatch.Error) as e:
        interpatch.coons(np.zeros((4, 2)), [[0, 1, 0], [1, 1, 0]], [[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]])
    assert str(e.value).startswith("v0:"), str(e.value)
    with pytest.raises(interpatch.Error) as e:
        interpatch.interpolate_surface([[[0, 0, 0], [1, 0]], [[0, 1, 0], [1, 1, 1]]])  # ragged
    assert e.value.code == "wrong_type" and str(e.value).startswith("points:")


@pytest.mark.parametrize("spec", [None, 3, [1, 2], 4.5])
def test_build_takes_a_dict_or_a_path(spec):
    with pytest.raises(interpatch.Error) as e:
        interpatch.build(spec)
    assert e.value.code == "wrong_type"
    assert "a dict or the path of a spec file" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "bilinear"}, base_dir=None)
    assert e.value.code == "wrong_type" and "base_dir" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "bilinear"}, arrays=[1])
    assert e.value.code == "wrong_type" and "arrays" in str(e.value)


def test_a_field_given_two_ways_is_refused(tmp_path):
    grid = terrain()
    np.save(tmp_path / "g.npy", grid)
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "interpolate", "points": {"array": "g", "npy": "g.npy"}}, str(tmp_path), {"g": grid})
    assert e.value.code == "wrong_type"
    assert str(e.value) == '/points: give either "array" or "npy", not both'
    with pytest.raises(interpatch.Error) as e:
        interpatch.build({"type": "interpolate", "points": grid.tolist()}, arrays={"points": grid})
    assert e.value.code == "wrong_type" and '"points" is given but the spec names no' in str(e.value)


# --- Ctrl-C ---

def test_ctrl_c_stops_a_long_call():
    # Gregory's patch has no exact form: every call evaluates its formula, as long the
    # second time as the first (a patch with one may make it in the first call, and the
    # call then timed would be far longer than the one interrupted).
    c = interpatch.build(os.path.join(EXAMPLES, "coons_gregory.json"))
    assert_ctrl_c_stops(lambda n: c.evaluate(np.linspace(0, 1, n), np.linspace(0, 1, n)), 200, 6400)
    assert c.evaluate([0.5], [0.5]).shape == (1, 1, 3), "still usable"


def test_ctrl_c_stops_a_long_derivative_evaluation():
    c = interpatch.build(os.path.join(EXAMPLES, "coons.json"))
    assert_ctrl_c_stops(lambda n: c.evaluate_derivatives(np.linspace(0, 1, n), np.linspace(0, 1, n)), 200, 6400)
    # Evaluated a block of rows at a time, the same values as in one piece.
    t = np.linspace(0, 1, 700)
    whole = c.evaluate_derivatives(t, t)
    for k in (0, 350, 699):
        assert np.array_equal(whole[k], c.evaluate_derivatives(t[k:k + 1], t)[0])

