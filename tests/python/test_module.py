"""The Python module against the command line, SciPy and itself.

Run by CTest (python_module) with PYTHONPATH=<build>/python, INTERPATCH_CLI (the
command) and INTERPATCH_EXAMPLES (examples/) set."""

import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import interpatch

CLI = os.environ.get("INTERPATCH_CLI", "interpatch")
EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))


def example_specs():
    return sorted(f for f in os.listdir(EXAMPLES) if f.endswith(".json"))


def cli_eval(spec_path, grid, out):
    subprocess.run([CLI, "eval", spec_path, "--grid", grid, "-o", out], check=True, capture_output=True)
    return np.load(out)


def terrain(nx=30, ny=40):
    x = np.linspace(0, 4, nx)
    y = np.linspace(0, 3, ny)
    z = np.sin(x)[:, None] * np.cos(y)[None, :] + 0.1 * x[:, None] * y[None, :]
    return np.stack(np.broadcast_arrays(x[:, None], y[None, :], z), axis=-1)


def test_version():
    assert interpatch.__version__.count(".") == 2


@pytest.mark.parametrize("name", example_specs())
def test_examples_give_the_command_lines_points(name, tmp_path):
    path = os.path.join(EXAMPLES, name)
    built = interpatch.build(path)
    if built.type == "blocks":
        pytest.skip("blocks evaluate block by block; their merged mesh is test_blocks.py's")
    # Counts whose parameters k / (n - 1) are exact in binary, so NumPy's linspace and
    # the command's are the same numbers. A graded spec's nodes are its own.
    with open(path) as f:
        sampling = json.load(f).get("sampling")  # not info(): it would make the exact form, 1 ulp off the formula
    if sampling:
        counts = [sampling[d]["count"] for d in "uvw"[:3 if isinstance(built, interpatch.Volume) else 2]]
        want = cli_eval(path, "x".join(map(str, counts)), str(tmp_path / "out.npy"))
        got = built.evaluate(*built.mesh_params())
    elif isinstance(built, interpatch.Volume):
        want = cli_eval(path, "5x3x2", str(tmp_path / "out.npy"))
        got = built.evaluate(np.linspace(0, 1, 5), np.linspace(0, 1, 3), np.linspace(0, 1, 2))
    else:
        want = cli_eval(path, "9x5", str(tmp_path / "out.npy"))
        got = built.evaluate(np.linspace(0, 1, 9), np.linspace(0, 1, 5))
    # The same library calls on the same parameters.
    assert got.shape == want.shape
    assert np.array_equal(got, want), np.abs(got - want).max()


def test_info_is_the_command_lines(tmp_path):
    path = os.path.join(EXAMPLES, "network_drawn.json")
    out = subprocess.run([CLI, "info", path], check=True, capture_output=True, text=True).stdout
    want = json.loads(out)
    got = interpatch.build(path).info()
    for key in ("type", "degree", "control_points", "knots", "max_data_error", "parameters"):
        assert got[key] == want[key], key


def test_info_checks_the_arrays_the_construction_keeps():
    # The construction keeps the caller's array, not a copy of its points: the check at
    # the data compares with the array as it is when info() is called.
    grid = terrain()
    s = interpatch.interpolate_surface(grid)
    before = s.info()["max_data_error"]
    assert before["absolute"] < 1e-12 * np.abs(grid).max()  # interpolated to rounding
    grid[7, 11, 2] += 0.5
    moved = s.info()["max_data_error"]
    assert moved["at"] == "/points/7/11"
    assert abs(moved["absolute"] - 0.5) < 1e-12
    grid[7, 11, 2] -= 0.5
    assert s.info()["max_data_error"] == before  # every call reads the array afresh
    # Any dtype and order: a float32 Fortran-order array is kept and converted each time.
    f = np.asfortranarray(terrain().astype(np.float32))
    t = interpatch.interpolate_surface(f)
    assert t.info()["max_data_error"]["absolute"] < 1e-12 * np.abs(f).max()
    # An approximation with a missing point: the check skips it, as the command line's does.
    holed = terrain()
    holed[3, 4] = np.nan
    a = interpatch.approximate_surface(holed, control_points=(8, 9))
    info = a.info()
    assert info["parameters"]["missing_points"] == 1
    # The largest error over the points given, the one the fit reports (both evaluate the
    # same surface at the same points; 1e-12 of the data's size for rounding).
    assert abs(info["max_data_error"]["absolute"] - info["parameters"]["max_error"]) < 1e-12 * np.nanmax(np.abs(holed))


def test_constructors_make_what_the_spec_makes():
    grid = terrain()
    spec = {"type": "interpolate", "points": grid.tolist()}
    a = interpatch.interpolate_surface(grid)
    b = interpatch.build(spec)
    us, vs = np.linspace(0, 1, 17), np.linspace(0, 1, 13)
    assert np.array_equal(a.evaluate(us, vs), b.evaluate(us, vs))
    assert np.array_equal(a.params_u, b.params_u)
    # Every data point on the surface, to rounding (1e-12 of the data's size).
    pts = a.evaluate(a.params_u, a.params_v)
    assert np.abs(pts - grid).max() < 1e-12 * np.abs(grid).max()

    s = interpatch.bilinear([0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 1])
    assert np.allclose(s.point(0.5, 0.5), [0.5, 0.5, 0.25], atol=1e-15)
    L = interpatch.line
    c = interpatch.coons(L([0, 0, 0], [1, 0, 0]), L([0, 1, 0], [1, 1, 1]), L([0, 0, 0], [0, 1, 0]),
                         L([1, 0, 0], [1, 1, 1]))
    assert np.allclose(c.evaluate(us, vs), s.evaluate(us, vs), atol=1e-15)
    r = interpatch.ruled(np.array([[0, 0, 0], [1, 0, 0.5], [2, 0, 0]]), L([0, 1, 0], [2, 1, 0]))
    assert np.allclose(r.point(0, 1), [0, 1, 0], atol=1e-15)
    h = interpatch.hermite_patch({k: {"p": p, "du": [1, 0, 0], "dv": [0, 1, 0]} for k, p in
                                  {"p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0], "p11": [1, 1, 0]}.items()})
    assert np.allclose(h.point(0.25, 0.75), [0.25, 0.75, 0], atol=1e-15)


def test_a_network_as_drawn():
    # Curves cut from z = x y at stations of their own, some reversed, out of order.
    rng = np.random.default_rng(5)
    def f(x, y):
        return np.stack([x, y, x * y + 0.2 * np.sin(x)], axis=-1)
    xs, ys = [0, 0.4, 1.1, 2], [0, 0.7, 1.5]
    u_curves = []
    for y in ys:
        t = np.unique(np.concatenate([[0, 2], xs, rng.uniform(0, 2, 6)]))
        u_curves.append(interpatch.interpolate_curve(f(t, np.full_like(t, y)), param="chord"))
    v_curves = []
    for x in xs:
        t = np.unique(np.concatenate([[0, 1.5], ys, rng.uniform(0, 1.5, 5)]))
        if len(v_curves) % 2:
            t = t[::-1]  # every other v-curve drawn the other way
        v_curves.append(interpatch.interpolate_curve(f(np.full_like(t, x), t), param="centripetal"))
    s = interpatch.curve_network(u_curves[::-1], v_curves[1:] + v_curves[:1])
    info = s.info()
    # Within the re-expression target of the default tolerance (1e-7 of the diagonal).
    assert info["max_data_error"]["relative"] < 1e-7
    assert any(c["reversed"] for c in info["parameters"]["network_curves"].values())


def test_any_dtype_and_memory_order_gives_the_same_surface():
    grid = terrain(12, 9)
    want = interpatch.interpolate_surface(grid).evaluate(np.linspace(0, 1, 7), np.linspace(0, 1, 5))
    strided = np.zeros((grid.shape[0], 2 * grid.shape[1], 3))
    strided[:, ::2] = grid
    for g in (np.asfortranarray(grid), grid.astype(np.longdouble), strided[:, ::2], grid.transpose(1, 0, 2).swapaxes(0, 1)):
        got = interpatch.interpolate_surface(g).evaluate(np.linspace(0, 1, 7), np.linspace(0, 1, 5))
        assert np.array_equal(got, want)
    # float32 data is another surface (the points are rounded), within float32's rounding.
    f32 = interpatch.interpolate_surface(grid.astype(np.float32)).evaluate(np.linspace(0, 1, 7), np.linspace(0, 1, 5))
    assert np.abs(f32 - want).max() < 1e-5
    # Parameters of any numeric dtype.
    a = interpatch.interpolate_surface(grid)
    assert np.array_equal(a.evaluate(np.linspace(0, 1, 7).astype(np.float32), [0, 1]),
                          a.evaluate(np.linspace(0, 1, 7).astype(np.float32).astype(np.float64), [0.0, 1.0]))


def test_results_view_the_librarys_memory():
    s = interpatch.interpolate_surface(terrain())
    pts = s.evaluate(np.linspace(0, 1, 100), np.linspace(0, 1, 50))
    assert pts.dtype == np.float64 and pts.shape == (100, 50, 3)
    assert not pts.flags.owndata and pts.base is not None  # no copy: the capsule owns the library's buffer
    cp = s.to_bspline()["control_points"]
    assert not cp.flags.owndata
    del s  # the arrays keep the construction alive
    assert np.isfinite(cp).all() and np.isfinite(pts).all()


def test_threads_evaluate_in_parallel_with_the_same_result():
    s = interpatch.interpolate_surface(terrain(60, 70))
    us, vs = np.linspace(0, 1, 300), np.linspace(0, 1, 300)
    want = s.evaluate(us, vs)
    results = [None] * 4

    def work(k):
        results[k] = s.evaluate(us, vs)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert np.array_equal(r, want)


def test_scipy_rect_bivariate_spline_is_the_same_bicubic():
    scipy_interpolate = pytest.importorskip("scipy.interpolate")
    # Evenly spaced x and y with uniform parameters: x(u) and y(v) are linear, and the
    # bicubic interpolant's z is SciPy's not-a-knot RectBivariateSpline(s=0).
    grid = terrain(20, 25)
    x, y, z = grid[:, 0, 0], grid[0, :, 1], grid[..., 2]
    s = interpatch.interpolate_surface(grid, param="uniform")
    ref = scipy_interpolate.RectBivariateSpline(x, y, z, kx=3, ky=3, s=0)
    us, vs = np.linspace(0, 1, 37), np.linspace(0, 1, 41)
    pts = s.evaluate(us, vs)
    want = ref(pts[:, 0, 0], pts[0, :, 1])
    # Two solvers of the same system: rounding of well-conditioned banded solves.
    assert np.abs(pts[..., 2] - want).max() < 1e-12 * np.abs(z).max()


ERRORS = [
    ("zero_chord", {"type": "interpolate", "points": [[[0, 0, 0], [0, 0, 0]], [[0, 0, 0], [0, 0, 0]]]}),
    ("not_finite", {"type": "bilinear", "p00": [0, 0, float("nan")], "p01": [0, 1, 0], "p10": [1, 0, 0],
                    "p11": [1, 1, 1]}),
    ("missing_field", {"type": "bilinear", "p00": [0, 0, 0]}),
    ("unknown_type", {"type": "teapot"}),
    ("wrong_type", {"type": "interpolate", "points": "many"}),
    ("too_few_points", {"type": "interpolate", "points": [[[0, 0, 0]]]}),
    ("invalid_degree", {"type": "interpolate", "points": [[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]],
                        "degree": 0}),
    ("corner_gap", {"type": "coons", "boundary": {"v0": {"line": [[0, 0, 0], [1, 0, 0]]},
                                                  "v1": {"line": [[0, 1, 0], [1, 1, 0]]},
                                                  "u0": {"line": [[0, 0, 0], [0, 1, 0]]},
                                                  "u1": {"line": [[1, 0, 1], [1, 1, 0]]}}}),
    ("invalid_knots", {"type": "ruled", "curves": [
        {"bspline": {"degree": 1, "knots": [0, 0.5, 1, 1], "control_points": [[0, 0, 0], [1, 0, 0]]}},
        {"line": [[0, 1, 0], [1, 1, 0]]}]}),
    ("invalid_weight", {"type": "ruled", "curves": [
        {"bspline": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[0, 0, 0], [1, 0, 0]],
                     "weights": [1, -1]}},
        {"line": [[0, 1, 0], [1, 1, 0]]}]}),
    ("ragged_grid", {"type": "interpolate", "points": [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0]]]}),
    ("non_increasing", {"type": "ruled", "curves": [
        {"hermite": {"points": [[0, 0, 0], [1, 1, 0], [2, 0, 0]], "params": [0, 0.6, 0.4]}},
        {"line": [[0, 1, 0], [1, 1, 0]]}]}),
    ("size_mismatch", {"type": "ruled", "curves": [
        {"hermite": {"points": [[0, 0, 0], [1, 1, 0], [2, 0, 0]], "params": [0, 1]}},
        {"line": [[0, 1, 0], [1, 1, 0]]}]}),
]


def example(name):
    with open(os.path.join(EXAMPLES, name + ".json")) as f:
        return json.load(f)


def network_with_params(u_params):
    s = example("network_gordon")
    s["u_params"] = u_params
    s["v_params"] = [0, 1 / 3, 2 / 3, 1]
    return s


def pipe(nu=5, nv=6):
    """A pipe's wall: nu rings of nv distinct points and a closing one equal to the first."""
    t = 2 * np.pi * np.arange(nv + 1) / nv
    ring = np.stack([np.cos(t), np.sin(t), np.zeros_like(t)], axis=-1)
    ring[nv] = ring[0]
    return np.stack([ring + [0, 0, i] for i in range(nu)])


def _missing_u_curve():
    s = network_with_params([0, 0.25, 0.5, 0.75, 1])
    for p in s["u_curves"][2]["interpolate"]:
        p[2] += 0.125
    return s


def _swapped_v_curves():
    s = network_with_params([0, 0.25, 0.5, 0.75, 1])
    s["v_curves"][1], s["v_curves"][2] = s["v_curves"][2], s["v_curves"][1]
    return s


def _no_twist_correction():
    s = example("coons_gregory")
    del s["twist_correction"]
    return s


def _cross_derivative_off_the_boundary():
    s = example("coons_cross")
    s["cross_derivatives"]["u0"] = {"line": [[5, 0, 0], [5, 0, 1]]}
    return s


def _nearly_closed_pipe():
    p = pipe()
    p[2, 6, 0] += 1e-9
    return {"type": "interpolate", "points": p.tolist(), "periodic": [False, True]}


def _tolerance_below_rounding():
    pts = [[[j, i, float(np.sin(7 * i + 3 * j))] for j in range(5)] for i in range(4)]
    return {"type": "approximate", "points": pts, "tolerance": 1e-300}


def _hole_filled_far_past_the_data():
    pts = [[[i, j, 0.1 * i * j] if i < 4 else [None, None, None] for j in range(5)] for i in range(100)]
    return {"type": "approximate", "points": pts, "control_points": [10, 5]}


ERRORS += [
    ("invalid_grading", {"type": "bilinear", "p00": [0, 0, 0], "p01": [0, 1, 0], "p10": [1, 0, 0], "p11": [1, 1, 0],
                         "sampling": {"u": {"count": 9, "ratio": 2, "first": 0.1}}}),
    ("out_of_domain", network_with_params([0, 0.25, 0.5, 0.75, 1.5])),
    ("tolerance_not_met", _tolerance_below_rounding()),
    ("ill_conditioned", _hole_filled_far_past_the_data()),
    ("network_gap", _missing_u_curve()),
    ("network_order", _swapped_v_curves()),
    ("incompatible_twist", _no_twist_correction()),
    ("tangent_mismatch", _cross_derivative_off_the_boundary()),
    ("closing_gap", _nearly_closed_pipe()),
]


@pytest.mark.parametrize("code,spec", ERRORS, ids=[e[0] for e in ERRORS])
def test_errors_carry_their_code_and_the_command_lines_message(code, spec, tmp_path):
    with pytest.raises(interpatch.Error) as e:
        interpatch.build(spec)
    assert e.value.code == code
    assert isinstance(e.value, ValueError)
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(spec))
    r = subprocess.run([CLI, "info", str(path)], capture_output=True, text=True)
    assert r.returncode == 3
    # The same message, but for a NaN: the file's is at a line and column of its text,
    # the dict's at the JSON Pointer of the value (a dict has no text).
    message = str(e.value)
    if code == "not_finite" and message.endswith(": value is nan"):
        assert message.startswith("/") and "NaN is not a JSON number" in r.stderr
        return
    assert message in r.stderr


def _invalid_json(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text('{"type": "bilinear", ')
    interpatch.build(str(path))


def _malformed_npy(tmp_path):
    (tmp_path / "grid.npy").write_bytes(b"\x93NUMPY")
    interpatch.build({"type": "interpolate", "points": {"npy": "grid.npy"}}, base_dir=str(tmp_path))


def _unwritable(tmp_path):
    interpatch.interpolate_surface(terrain(5, 5)).write(str(tmp_path / "no" / "such" / "dir" / "x.json"))


def _too_large(tmp_path):
    # 2^40 points (26 TB of output): refused before any allocation.
    ts = np.linspace(0, 1, 1 << 20)
    interpatch.interpolate_surface(terrain(5, 5)).evaluate(ts, ts)


def _no_exact_form(tmp_path):
    interpatch.build(example("coons_gregory")).to_bspline()


def _unreadable(tmp_path):
    interpatch.build(str(tmp_path / "nonexistent.json"))


def _blocks_apart(tmp_path):
    # Two unit boxes 0.001 apart along x: faces that nearly meet, found when meshed.
    def box(x0):
        return {"type": "trilinear", **{f"p{i}{j}{k}": [x0 + i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)}}
    interpatch.blocks([box(0), box(1.001)]).write(str(tmp_path / "b.vtu"))


OTHER_ERRORS = [("invalid_json", _invalid_json), ("malformed_file", _malformed_npy),
                ("file_unwritable", _unwritable), ("too_large", _too_large), ("no_exact_form", _no_exact_form),
                ("file_unreadable", _unreadable), ("block_mismatch", _blocks_apart)]


@pytest.mark.parametrize("code,make", OTHER_ERRORS, ids=[e[0] for e in OTHER_ERRORS])
def test_file_and_resource_errors_carry_their_code(code, make, tmp_path):
    with pytest.raises(interpatch.Error) as e:
        make(tmp_path)
    assert e.value.code == code, str(e.value)
    assert str(e.value), "a message naming the problem"


def test_every_code_input_can_reach_is_raised_here():
    # The codes no input reaches (the command line's bad-input table says why):
    # blending functions are named, never given as functions (invalid_blend);
    # averaged knots make every collocation system solvable (singular); internal is a bug.
    unreachable = {"invalid_blend", "singular", "internal"}
    assert unreachable <= set(interpatch.ERROR_CODES)
    tested = {code for code, _ in ERRORS} | {code for code, _ in OTHER_ERRORS}
    assert tested == set(interpatch.ERROR_CODES) - unreachable


def test_file_and_array_errors():
    with pytest.raises(interpatch.Error) as e:
        interpatch.build("/nonexistent/spec.json")
    assert e.value.code == "file_unreadable"
    with pytest.raises(interpatch.Error) as e:
        interpatch.interpolate_surface(np.zeros((3, 3, 2)))
    assert e.value.code == "size_mismatch"
    bad = terrain(5, 5)
    bad[2, 3, 1] = np.inf
    with pytest.raises(interpatch.Error) as e:
        interpatch.interpolate_surface(bad)
    assert e.value.code == "not_finite" and "/points/2/3/1" in str(e.value)
    s = interpatch.interpolate_surface(terrain(5, 5))
    with pytest.raises(interpatch.Error) as e:
        s.evaluate([1.5], [0])
    assert e.value.code == "out_of_domain"
    with pytest.raises(interpatch.Error) as e:
        s.write("/tmp/x.unknown")
    assert e.value.code == "wrong_type"


def test_write_gives_the_command_lines_files(tmp_path):
    path = os.path.join(EXAMPLES, "coons.json")
    for ext in (".json", ".npz", ".obj"):
        # A fresh object each time, as each command is a fresh process: a mesh samples
        # the formula until something has made the exact form (both exact, to rounding).
        s = interpatch.build(path)
        mine, theirs = tmp_path / ("mine" + ext), tmp_path / ("theirs" + ext)
        s.write(str(mine))
        cmd = "mesh" if ext == ".obj" else "build"
        subprocess.run([CLI, cmd, path, "-o", str(theirs)], check=True, capture_output=True)
        assert mine.read_bytes() == theirs.read_bytes(), ext


def test_the_readmes_python_example_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    import re
    readme = open(os.path.join(EXAMPLES, "..", "README.md")).read()
    code = re.search(r"## Python\n.*?```python\n(.*?)```", readme, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    scope = {}
    exec(compile(code, "README.md", "exec"), scope)
    assert scope["pts"].shape == (200, 150, 3)
    assert scope["b"]["control_points"].shape == (30, 25, 3)  # what the README says
    assert (tmp_path / "terrain.png").stat().st_size > 0 and (tmp_path / "terrain.step").stat().st_size > 0


def test_approximate_surface_fills_holes_and_reports(tmp_path):
    rng = np.random.default_rng(3)
    noisy = terrain(40, 30)
    noisy[..., 2] += rng.uniform(-0.01, 0.01, noisy.shape[:2])
    noisy[10:16, 8:14, 2] = np.nan  # a 6 x 6 void
    s = interpatch.approximate_surface(noisy, tolerance=0.03)
    p = s.info()["parameters"]
    assert p["missing_points"] == 36
    assert p["max_error"] <= 0.03
    assert p["control_points"][0] * p["control_points"][1] < 40 * 30 / 4
    # The error reported is the one at the data, checked here on its own.
    u, v = np.asarray(s.params_u), np.asarray(s.params_v)
    at = s.evaluate(u, v)
    err = np.linalg.norm(at - noisy, axis=-1)
    assert abs(np.nanmax(err) - p["max_error"]) < 1e-12
    # The same spec from a file (NaN in the .npy) gives the same surface.
    np.save(tmp_path / "noisy.npy", noisy)
    f = interpatch.build({"type": "approximate", "points": {"npy": "noisy.npy"}, "tolerance": 0.03}, str(tmp_path))
    us, vs = np.linspace(0, 1, 11), np.linspace(0, 1, 9)
    assert np.array_equal(f.evaluate(us, vs), s.evaluate(us, vs))
    # The hole is filled within the range of the heights around it (give or take 5%).
    ring = noisy[8:18, 6:16, 2]
    lo, hi = np.nanmin(ring), np.nanmax(ring)
    inside = s.evaluate(np.linspace(u[10], u[15], 9), np.linspace(v[8], v[13], 9))[..., 2]
    assert inside.min() >= lo - 0.05 * (hi - lo) and inside.max() <= hi + 0.05 * (hi - lo)


def test_approximate_scattered_points(tmp_path):
    rng = np.random.default_rng(4)
    xy = rng.uniform((0, 0), (400, 300), (3000, 2))
    pts = np.column_stack([xy, 20 * np.sin(xy[:, 0] / 60) * np.cos(xy[:, 1] / 50)])
    pts[:40, 2] = np.nan  # missing heights
    s = interpatch.approximate_surface(pts, param="xy", tolerance=0.05)
    p = s.info()["parameters"]
    assert (p["points"], p["missing_points"], p["param"]) == (3000, 40, "xy") and p["max_error"] <= 0.05
    # Every point within the tolerance at its own site, measured here point by point.
    (x0, x1), (y0, y1) = p["domain"]
    at = np.array([s.point((x - x0) / (x1 - x0), (y - y0) / (y1 - y0)) for x, y in xy[40:]])
    assert np.linalg.norm(at - pts[40:], axis=1).max() <= 0.05
    # x and y of a height field are the domain's, to rounding.
    assert np.allclose(s.point(0.25, 0.5)[:2], [x0 + 0.25 * (x1 - x0), y0 + 0.5 * (y1 - y0)], rtol=0, atol=1e-10)
    # The same spec from a file gives the same surface.
    np.save(tmp_path / "survey.npy", pts)
    f = interpatch.build({"type": "approximate", "points": {"npy": "survey.npy"}, "param": "xy", "tolerance": 0.05},
                         str(tmp_path))
    us, vs = np.linspace(0, 1, 11), np.linspace(0, 1, 9)
    assert np.array_equal(f.evaluate(us, vs), s.evaluate(us, vs))
    # Sites given: x and y scaled make the same fit as "xy" in z.
    g = interpatch.approximate_surface(pts, params=xy / 100, control_points=(9, 8))
    h = interpatch.approximate_surface(pts, param="xy", control_points=(9, 8))
    assert np.allclose(g.to_bspline()["control_points"][..., 2], h.to_bspline()["control_points"][..., 2], atol=1e-6)
    with pytest.raises(interpatch.Error) as e:
        interpatch.approximate_surface(pts, params=xy[:10], control_points=(9, 8))
    assert e.value.code == "size_mismatch" and "/param" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        interpatch.approximate_surface(pts, params=np.ones((3000, 3)), control_points=(9, 8))
    assert e.value.code == "size_mismatch"
    # smoothing="auto": λ by cross-validation; with noise of σ = 0.5 added, the fit is
    # closer to the noise-free field between the points than the noise itself.
    noisy = pts.copy()
    noisy[:, 2] += rng.normal(0, 0.5, len(pts))
    a = interpatch.approximate_surface(noisy, param="xy", smoothing="auto")
    q = a.info()["parameters"]
    assert q["smoothing"] == "auto" and q["lambda"] > 0
    (x0, x1), (y0, y1) = q["domain"]
    new = rng.uniform((x0, y0), (x1, y1), (500, 2))
    z = np.array([a.point((x - x0) / (x1 - x0), (y - y0) / (y1 - y0))[2] for x, y in new])
    truth = 20 * np.sin(new[:, 0] / 60) * np.cos(new[:, 1] / 50)
    assert np.sqrt(np.mean((z - truth) ** 2)) < 0.25
    with pytest.raises(interpatch.Error) as e:
        interpatch.approximate_surface(pts[:, [0, 0, 2]], param="xy", tolerance=0.1)  # x = y: one line
    assert e.value.code == "singular"


def test_approximate_options_and_errors():
    grid = terrain(20, 16)
    a = interpatch.approximate_surface(grid, control_points=(8, 6), param="uniform")
    assert a.to_bspline()["control_points"].shape == (8, 6, 3)
    w = np.ones(grid.shape[:2])
    w[3, 4] = 1e6
    b = interpatch.approximate_surface(grid, control_points=(8, 6), param="uniform", weights=w)
    assert not np.array_equal(a.to_bspline()["control_points"], b.to_bspline()["control_points"])
    c = interpatch.approximate_surface(grid, smoothing="auto")
    assert c.info()["parameters"]["lambda"] > 0
    vol = np.stack(np.meshgrid(np.arange(5.0), np.arange(6.0), np.arange(4.0), indexing="ij"), axis=-1)
    v = interpatch.approximate_volume(vol, control_points=(4, 4, 4))
    assert v.to_bspline()["control_points"].shape == (4, 4, 4, 3)
    curve = interpatch.approximate_curve(grid[:, 0], tolerance=0.05)
    r = interpatch.ruled(curve, interpatch.line([0, 3, 0], [4, 3, 0]))
    assert np.allclose(r.point(0, 1), [0, 3, 0], atol=1e-12)
    with pytest.raises(interpatch.Error) as e:
        interpatch.approximate_surface(grid, tolerance=0)
    assert e.value.code == "wrong_type" and "/tolerance" in str(e.value)
    with pytest.raises(interpatch.Error) as e:
        interpatch.approximate_surface(grid, tolerance=0.1, weights=np.ones((3, 3)))
    assert e.value.code == "size_mismatch"
    with pytest.raises(interpatch.Error) as e:
        interpatch.approximate_surface(np.full((4, 4, 3), np.nan), tolerance=0.1)
    assert e.value.code == "too_few_points"
    # Interpolation refuses NaN and says where to go.
    holed = grid.copy()
    holed[2, 2, 0] = np.nan
    with pytest.raises(interpatch.Error) as e:
        interpatch.interpolate_surface(holed)
    assert e.value.code == "not_finite" and "approximate" in str(e.value)


def _page_data(path):
    """The data a viewer page embeds, without the summary's timings (they differ from run to run)."""
    import json
    import re
    text = open(path, encoding="utf-8").read()
    data = json.loads(re.search(r'<script type="application/json" id="interpatch-data">(.*?)</script>', text, re.S).group(1))
    del data["info"]["timings"]
    return data


def test_write_html_gives_the_command_lines_viewer_page(tmp_path):
    for name, res in (("coons", (9, 7)), ("trilinear", (3, 4, 5))):
        path = os.path.join(EXAMPLES, name + ".json")
        s = interpatch.build(path)
        mine, theirs = tmp_path / (name + ".html"), tmp_path / "cli" / (name + ".html")
        theirs.parent.mkdir(exist_ok=True)
        s.write(str(mine), res=res)
        subprocess.run([CLI, "view", path, "-o", str(theirs), "--res", "x".join(map(str, res))], check=True,
                       capture_output=True)
        assert _page_data(mine) == _page_data(theirs), name
        assert _page_data(mine)["resolution"]["shown"][:len(res)] == list(res)
    with pytest.raises(interpatch.Error) as e:
        interpatch.build(os.path.join(EXAMPLES, "coons.json")).write(str(tmp_path / "x.html"), res=(4, 4, 4))
    assert e.value.code == "size_mismatch"
