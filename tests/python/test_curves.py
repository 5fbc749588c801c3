"""Curves in Python against the command line, SciPy and their data.

Every curve form of a spec (docs/spec-format.md, "Curves") is made twice, from a
curve spec file and from the module's constructor, on seeded random inputs. Run by
CTest (python_module) with PYTHONPATH, INTERPATCH_CLI and INTERPATCH_EXAMPLES set."""

import json
import os
import subprocess

import numpy as np
import pytest

import interpatch
from ctrl_c import assert_ctrl_c_stops

CLI = os.environ.get("INTERPATCH_CLI", "interpatch")
RNG_SEED = 20240535


def _walk(rng, n, closed=False):
    """n points of a random space curve with chords of comparable length: a smooth
    loop when closed (its last point not repeating the first), a wandering walk otherwise."""
    if closed:
        t = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = 1 + 0.2 * rng.uniform(-1, 1, n)
        return np.stack([r * np.cos(t), r * np.sin(t), 0.3 * np.sin(2 * t)], axis=-1)
    return np.cumsum(rng.uniform(0.2, 1.0, (n, 3)) * rng.choice([-1, 1], (n, 3)), axis=0)


def _periodic_knots(rng, n, p):
    """The n + 2p + 1 extended knots of a closed curve of n control points: a random
    period over [0, 1], p knots either side repeating it one period away."""
    inner = np.sort(rng.uniform(0.05, 0.95, n - 1))
    k = np.concatenate([[0.0], inner, [1.0]])
    return np.concatenate([k[n - p:n] - 1.0, k, k[1:p + 1] + 1.0])


def _forms():
    """(name, spec, constructor) for every curve form: the spec a curve spec file holds,
    and the call that makes the same curve from arrays."""
    rng = np.random.default_rng(RNG_SEED)
    out = []
    pts = _walk(rng, 9)
    for param in ("chord", "centripetal", "uniform"):
        out.append((f"interpolate_{param}", {"interpolate": pts.tolist(), "param": param},
                    lambda p=pts, m=param: interpatch.interpolate_curve(p, param=m)))
    ends = _walk(rng, 6)
    d0, d1 = rng.normal(size=3), rng.normal(size=3)
    out.append(("interpolate_ends", {"interpolate": ends.tolist(), "degree": 2, "start_derivative": d0.tolist(),
                                     "end_derivative": d1.tolist()},
                lambda: interpatch.interpolate_curve(ends, degree=2, start_derivative=d0, end_derivative=d1)))
    loop = _walk(rng, 8, closed=True)
    for p in (2, 3):
        out.append((f"interpolate_periodic_p{p}", {"interpolate": loop.tolist(), "degree": p, "periodic": True},
                    lambda p=p: interpatch.interpolate_curve(loop, degree=p, periodic=True)))
    cp = _walk(rng, 7)
    knots = np.concatenate([[0.0] * 4, np.sort(rng.uniform(0, 3, 3)), [3.0] * 4])  # mapped onto [0, 1]
    out.append(("bspline", {"bspline": {"degree": 3, "knots": knots.tolist(), "control_points": cp.tolist()}},
                lambda: interpatch.bspline_curve(3, knots, cp)))
    w = rng.uniform(0.3, 3.0, len(cp))
    out.append(("bspline_rational", {"bspline": {"degree": 3, "knots": knots.tolist(), "control_points": cp.tolist(),
                                                 "weights": w.tolist()}},
                lambda: interpatch.bspline_curve(3, knots, cp, weights=w)))
    ring = _walk(rng, 6, closed=True)
    pk = _periodic_knots(rng, 6, 3)
    out.append(("bspline_periodic", {"bspline": {"degree": 3, "knots": pk.tolist(), "control_points": ring.tolist(),
                                                 "periodic": True}},
                lambda: interpatch.bspline_curve(3, pk, ring, periodic=True)))
    wr = rng.uniform(0.5, 2.0, len(ring))
    out.append(("bspline_periodic_rational",
                {"bspline": {"degree": 3, "knots": pk.tolist(), "control_points": ring.tolist(), "weights": wr.tolist(),
                             "periodic": True}},
                lambda: interpatch.bspline_curve(3, pk, ring, weights=wr, periodic=True)))
    hp, ht = _walk(rng, 5), rng.normal(size=(5, 3))
    hu = np.cumsum(rng.uniform(0.5, 2.0, 5)) - 1.0
    out.append(("hermite", {"hermite": {"points": hp.tolist(), "tangents": ht.tolist(), "params": hu.tolist()}},
                lambda: interpatch.hermite_curve(hp, ht, hu)))
    out.append(("hermite_catmull_rom", {"hermite": {"points": hp.tolist()}}, lambda: interpatch.hermite_curve(hp)))
    a, b = rng.normal(size=3), rng.normal(size=3)
    out.append(("line", {"line": [a.tolist(), b.tolist()]}, lambda: interpatch.line(a, b)))
    noisy = _walk(rng, 40) + rng.normal(0, 0.01, (40, 3))
    out.append(("approximate", {"approximate": noisy.tolist(), "control_points": 8},
                lambda: interpatch.approximate_curve(noisy, control_points=8)))
    out.append(("approximate_tolerance", {"approximate": noisy.tolist(), "tolerance": 0.05},
                lambda: interpatch.approximate_curve(noisy, tolerance=0.05)))
    ring_noisy = _walk(rng, 30, closed=True) + rng.normal(0, 0.01, (30, 3))
    out.append(("approximate_periodic", {"approximate": ring_noisy.tolist(), "control_points": 10, "periodic": True},
                lambda: interpatch.approximate_curve(ring_noisy, control_points=10, periodic=True)))
    return out


FORMS = _forms()
NAMES = [f[0] for f in FORMS]
BY_NAME = {f[0]: f for f in FORMS}
# 65 parameters k / 64: exact in binary, so NumPy's linspace and the command's are the same numbers.
TS = np.linspace(0, 1, 65)


@pytest.fixture(params=NAMES)
def form(request, tmp_path):
    name, spec, make = BY_NAME[request.param]
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(spec))
    return name, spec, make, path


def test_every_form_the_spec_reader_knows_is_covered():
    assert {f.split("_")[0] for f in NAMES} == {"interpolate", "bspline", "hermite", "line", "approximate"}
    assert any(BY_NAME[n][1].get("periodic") or BY_NAME[n][1].get("bspline", {}).get("periodic") for n in NAMES)


def test_evaluation_is_the_command_lines_bit_for_bit(form, tmp_path):
    name, spec, make, path = form
    out = tmp_path / "out.npy"
    subprocess.run([CLI, "eval", str(path), "--grid", "65", "-o", str(out)], check=True, capture_output=True)
    want = np.load(out)
    assert want.shape == (65, 3)
    from_file, from_arrays = interpatch.build(str(path)), make()
    assert isinstance(from_file, interpatch.Curve) and from_file.type == name.split("_")[0]
    # One reader, one evaluator: the same doubles from every front door.
    assert np.array_equal(from_file.evaluate(TS), want)
    assert np.array_equal(from_arrays.evaluate(TS), want)
    assert np.array_equal(interpatch.build(spec).evaluate(TS), want)


def _scipy_points_and_derivatives(b, ts, order):
    """The exact form evaluated by SciPy: C and its derivatives up to `order` at ts.
    A closed curve's coefficients are its control points followed by its first p
    again (basis function i + n belongs to control point i); a rational one is
    A / W with A = BSpline(weighted points), W = BSpline(weights), differentiated by
    the quotient rule."""
    si = pytest.importorskip("scipy.interpolate")
    # Copies: SciPy's BSpline takes writeable arrays only.
    p, t, cp = b["degree"], np.array(b["knots"]), np.array(b["control_points"])
    w = np.ones(len(cp)) if b["weights"] is None else np.array(b["weights"])
    if b["periodic"]:
        cp, w = np.concatenate([cp, cp[:p]]), np.concatenate([w, w[:p]])
    num, den = si.BSpline(t, cp * w[:, None], p), si.BSpline(t, w, p)

    def nth(s, k):  # SciPy refuses derivatives past the degree, which are 0
        return s(ts) if k == 0 else s.derivative(k)(ts) if k <= p else np.zeros_like(s(ts))

    a = [nth(num, k) for k in range(order + 1)]
    wd = [nth(den, k)[:, None] for k in range(order + 1)]
    c = []
    for k in range(order + 1):
        # A^(k) = Σ_j binom(k, j) W^(j) C^(k-j): solve for C^(k).
        acc = a[k] - sum(float(np.math.comb(k, j)) * wd[j] * c[k - j] for j in range(1, k + 1))
        c.append(acc / wd[0])
    return c


def test_the_exact_form_evaluated_by_scipy_matches(form):
    name, _, make, _ = form
    c = make()
    b = c.to_bspline()
    assert not b["control_points"].flags.writeable and not b["knots"].flags.writeable
    assert b["knots"][b["degree"]] == 0.0 and b["knots"][-b["degree"] - 1] == 1.0, "the domain is [0, 1]"
    want = _scipy_points_and_derivatives(b, TS, 2)
    got = c.derivatives(TS, 2)
    assert np.array_equal(got[:, 0], c.evaluate(TS))
    w = b["weights"]
    spread = 1.0 if w is None else w.max() / w.min()
    for k in range(3):
        # De Boor's recurrence (SciPy) and interpatch's basis functions round differently:
        # each sums p + 1 terms of a partition of unity (or its derivatives), a few ulps
        # of the largest value of that derivative apart (a rational curve's by up to the
        # spread of its weights more); 4 ulps are seen. 1e-13 is ~450 ulps: above
        # rounding, far below any wrong knot, index or weight.
        scale = max(1.0, np.abs(want[k]).max())
        err = np.abs(got[:, k] - want[k]).max()
        assert err <= 1e-13 * scale * spread, f"{name}: derivative {k} off by {err:.3g} (scale {scale:.3g})"


def test_interpolated_curves_pass_through_their_points_at_params(form):
    name, spec, make, _ = form
    c = make()
    if name.startswith(("bspline", "line")):
        assert c.params is None
        return
    body = spec.get("interpolate") or spec.get("approximate") or spec["hermite"]["points"]
    pts = np.asarray(body, dtype=float)
    assert c.params.shape == (len(pts),) and c.params[0] == 0.0
    assert np.all(np.diff(c.params) > 0) and c.params[-1] <= 1.0
    got = c.evaluate(c.params)
    err = np.linalg.norm(got - pts, axis=1).max()
    diagonal = np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))
    info = c.info()
    assert info["max_data_error"]["points"] == len(pts)
    # The command's check at the data is this distance, computed by the same evaluator.
    assert info["max_data_error"]["absolute"] == pytest.approx(err, rel=1e-12, abs=1e-300)
    if name.startswith("approximate"):
        assert err == pytest.approx(info["parameters"]["max_error"], rel=1e-9)
        return
    # A banded collocation solve (cyclic for closed curves) of a well-conditioned
    # system, or Hermite's end points themselves: the residual is rounding, about an
    # ulp of the coordinates (1e-16 of the diagonal seen); 1e-13 leaves room for it.
    assert err <= 1e-13 * diagonal, f"{name}: {err:.3g} from the data"


def test_a_closed_curve_closes_and_wraps():
    c = BY_NAME["interpolate_periodic_p3"][2]()
    assert c.to_bspline()["periodic"]
    loop = np.asarray(BY_NAME["interpolate_periodic_p3"][1]["interpolate"])
    assert np.allclose(c.point(0.0), loop[0], rtol=0, atol=1e-14) and np.allclose(c.point(1.0), loop[0], atol=1e-14)
    assert np.array_equal(c.evaluate([0.25]), c.evaluate([1.25]))
    d = c.derivatives([0.0, 1.0], 2)
    assert np.allclose(d[0], d[1], rtol=0, atol=1e-9 * np.abs(d).max()), "C2 across the seam"
    # A repeated last point is the closing point: at parameter 1.
    again = interpatch.interpolate_curve(np.concatenate([loop, loop[:1]]), periodic=True)
    assert again.params[-1] == 1.0 and np.array_equal(again.evaluate(TS), c.evaluate(TS))


def test_tangent_and_curvature_of_a_circle():
    quarter = interpatch.bspline_curve(2, [0, 0, 0, 1, 1, 1], [[2, 0, 0], [2, 2, 0], [0, 2, 0]],
                                       weights=[1, 2 ** -0.5, 1])
    for t in np.linspace(0, 1, 7):
        p = quarter.point(t)
        # A rational quadratic's evaluation: a few ulps of the radius 2.
        assert np.linalg.norm(p) == pytest.approx(2.0, abs=1e-14)
        assert abs(quarter.tangent(t) @ p) <= 1e-14 and np.linalg.norm(quarter.tangent(t)) == pytest.approx(1.0)
        assert quarter.curvature(t) == pytest.approx(0.5, rel=1e-13)
    flat = interpatch.line([0, 0, 0], [3, 4, 0])
    assert np.allclose(flat.tangent(0.5), [0.6, 0.8, 0]) and flat.curvature(0.5) == 0.0
    point = interpatch.line([1, 1, 1], [1, 1, 1])
    assert np.array_equal(point.tangent(0.5), [0, 0, 0]) and np.isnan(point.curvature(0.5))


def test_info_is_the_command_lines(form):
    _, _, make, path = form
    out = subprocess.run([CLI, "info", str(path)], check=True, capture_output=True, text=True).stdout
    want, got = json.loads(out), interpatch.build(str(path)).info()
    want.pop("timings")
    got.pop("timings")
    assert got == want
    assert got["kind"] == "curve" and got["exact_form"] == "bspline_curve"
    made = make().info()
    made.pop("timings")
    assert made["degree"] == got["degree"] and made["knots"] == got["knots"]


@pytest.mark.parametrize("ext", [".json", ".npz", ".step", ".igs"])
def test_write_is_the_command_lines_build(form, tmp_path, ext):
    name, _, make, path = form
    c = make()
    mine, theirs = tmp_path / f"mine{ext}", tmp_path / f"theirs{ext}"
    c.write(str(mine))
    subprocess.run([CLI, "build", str(path), "-o", str(theirs)], check=True, capture_output=True)
    a, b = mine.read_bytes(), theirs.read_bytes()
    if ext in (".step", ".igs"):
        # The files name themselves and the time they were written: drop those lines.
        def stable(text):
            return [ln for ln in text.decode().splitlines()
                    if "FILE_NAME" not in ln and ln[72:73] != "G" and "theirs" not in ln and "mine" not in ln]
        a, b = stable(a), stable(b)
        assert (b"B_SPLINE_CURVE_WITH_KNOTS" if ext == ".step" else b"126,") in mine.read_bytes()
    assert a == b
    if ext == ".json":
        again = interpatch.build(str(mine))
        assert again.type == "bspline" and np.array_equal(again.evaluate(TS), c.evaluate(TS)), "reads back"
    if ext == ".npz":
        z, e = np.load(mine), c.to_bspline()
        assert z["degree"].tolist() == [e["degree"]] and np.array_equal(z["knots_u"], e["knots"])
        assert np.array_equal(z["control_points"], e["control_points"]) and z["periodic"].tolist() == [e["periodic"]]
        assert ("weights" in z.files) == (e["weights"] is not None)


def test_a_curve_in_a_surface_is_the_curve(form):
    """ruled() takes a Curve by its exact form: the surface is the one the spec with the
    curve's own spec inside makes, bit for bit."""
    name, spec, make, _ = form
    c = make()
    other = c.to_bspline()
    shifted = {"bspline": {"degree": other["degree"], "knots": other["knots"].tolist(),
                           "control_points": (other["control_points"] + [0, 0, 1]).tolist(),
                           "periodic": bool(other["periodic"])}}
    if other["weights"] is not None:
        shifted["bspline"]["weights"] = other["weights"].tolist()
    partner = interpatch.build(shifted)
    want = interpatch.build({"type": "ruled", "curves": [spec, shifted]})
    got = interpatch.ruled(c, partner)
    assert np.array_equal(got.evaluate(TS, [0, 0.5, 1]), want.evaluate(TS, [0, 0.5, 1]))
    assert np.array_equal(got.evaluate(TS, [0.0])[:, 0], c.evaluate(TS))


def test_bad_input_is_refused_with_its_place(tmp_path):
    c = interpatch.interpolate_curve([[0, 0, 0], [1, 1, 0], [2, 0, 0]])
    cases = [
        (lambda: c.evaluate([0.5, 1.5]), "out_of_domain", "ts[1]: parameter 1.5 is outside the domain [0, 1]"),
        (lambda: c.evaluate([float("nan")]), "out_of_domain", "ts[0]: parameter nan"),
        (lambda: c.point(-0.25), "out_of_domain", "t: parameter -0.25 is outside"),
        (lambda: c.evaluate(np.array([0.5 + 1j])), "wrong_type", "ts: expected real numbers, got an array of dtype complex128"),
        (lambda: c.evaluate(np.ma.masked_array([0, 0.5], mask=[0, 1])), "wrong_type", "ts: masked at index (1,)"),
        (lambda: c.evaluate([[0.5]]), "size_mismatch", "ts: expected a 1-D sequence of parameters, got 2 dimensions"),
        (lambda: c.derivatives([0.5], -1), "wrong_type", "order: a derivative order of 0 or more, got -1"),
        (lambda: c.write(str(tmp_path / "c.obj")), "wrong_type", ""),
        (lambda: c.write(str(tmp_path / "missing" / "c.json")), "file_unwritable", ""),
        (lambda: interpatch.interpolate_curve([[0, 0, 0]]), "too_few_points", "/interpolate: a curve needs at least 2 points"),
        (lambda: interpatch.interpolate_curve(np.zeros((3, 3)) + 1j), "wrong_type", "points: expected real numbers"),
        (lambda: interpatch.interpolate_curve(np.ma.masked_array(np.ones((3, 3)), mask=np.eye(3, dtype=bool))),
         "wrong_type", "points: masked at index (0,)"),
        (lambda: interpatch.interpolate_curve([[0, 0, 0], [0, 0, 0], [1, 0, 0]]), "zero_chord", "/interpolate/1: point 1"),
        (lambda: interpatch.bspline_curve(2, [0, 0, 0, 1, 1, 1], [[0, 0, 0], [1, 0, 0]]), "size_mismatch",
         "/bspline/control_points: 6 knots of degree 2 need 3 control points, got 2"),
        (lambda: interpatch.bspline_curve(1, [0, 0, 1, 1], [[0, 0, 0], [1, 0, 0]], weights=[1, -1]), "invalid_weight",
         "/bspline/weights/1: weight -1 is not positive"),
        (lambda: interpatch.hermite_curve([[0, 0, 0], [1, 0, 0]], params=[1, 0]), "non_increasing", "/hermite/params/1"),
        (lambda: interpatch.build({"interpolate": [[0, 0, 0], [1, 0, 0]], "line": [[0, 0, 0], [1, 0, 0]]}),
         "wrong_type", "(top level): a curve has exactly one of"),
    ]
    for call, code, message in cases:
        with pytest.raises(interpatch.Error) as e:
            call()
        assert e.value.code == code, (code, str(e.value))
        assert str(e.value).startswith(message), str(e.value)


def test_the_command_line_refuses_what_a_curve_is_not(tmp_path):
    path = tmp_path / "c.json"
    path.write_text(json.dumps(BY_NAME["line"][1]))
    for args in (["eval", str(path), "--grid", "5x5", "-o", str(tmp_path / "g.npy")],
                 ["mesh", str(path), "-o", str(tmp_path / "m.obj")],
                 ["view", str(path), "-o", str(tmp_path / "v.html")]):
        r = subprocess.run([CLI] + args, capture_output=True, text=True)
        assert r.returncode == 2 and "is a curve spec" in r.stderr, (args, r.stderr)
    r = subprocess.run([CLI, "eval", str(path), "--grid", "3", "-o", str(tmp_path / "g.csv")], check=True)
    assert (tmp_path / "g.csv").read_text().splitlines()[0] == "t,x,y,z"


def test_ctrl_c_stops_a_long_evaluation():
    # Degree 20: a point costs ~0.5 us, so a call long enough to interrupt holds
    # (at most 2^22 points) 100 MB.
    cp = _walk(np.random.default_rng(RNG_SEED), 60)
    c = interpatch.interpolate_curve(cp, degree=20, param="uniform")
    assert_ctrl_c_stops(lambda n: c.evaluate(np.linspace(0, 1, n)), 1 << 16, 1 << 22)
    assert c.evaluate([0.5]).shape == (1, 3), "still usable"


def test_the_readmes_curve_example_runs(tmp_path, monkeypatch):
    import re
    readme = open(os.path.join(os.path.dirname(__file__), "..", "..", "README.md")).read()
    code = re.search(r"Curves are objects of their own.*?```python\n(.*?)```", readme, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    scope = {"np": np, "interpatch": interpatch}
    exec(compile(code, "README.md", "exec"), scope)
    # What the README's comments say.
    assert repr(scope["c"]) == "Curve(type='interpolate', degree=3, control_points=8)"
    assert scope["pts"].shape == (400, 3) and scope["d"].shape == (2, 3, 3)
    # "~1e-16": a few ulps of a ring of radius 1.
    assert np.abs(scope["c"].evaluate(scope["c"].params) - scope["ring"]).max() < 1e-15
    assert (tmp_path / "ring.igs").stat().st_size > 0 and isinstance(scope["lid"], interpatch.Surface)
