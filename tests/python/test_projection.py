"""Where points are: closest points, volume inversion and rays, against an oracle.

The oracle is independent of the projection code: a dense sample of each surface by
its own evaluation, searched by brute force (SciPy's cKDTree). The sample never comes
nearer than the true closest point, so a projection's distance must be no more than
the oracle's plus the promised 1e-10 of the diagonal; a search caught in a local
minimum is farther than the oracle by much more. Every example surface of the
project, and every example volume, is tried on seeded random points. Run by CTest
(python_module) with PYTHONPATH, INTERPATCH_CLI and INTERPATCH_EXAMPLES set."""

import json
import os
import subprocess

import numpy as np
import pytest
from scipy.spatial import cKDTree

import interpatch

CLI = os.environ.get("INTERPATCH_CLI", "interpatch")
EXAMPLES = os.environ.get("INTERPATCH_EXAMPLES", os.path.join(os.path.dirname(__file__), "..", "..", "examples"))
SEED = 20261130


def _built(name):
    return interpatch.build(os.path.join(EXAMPLES, name), base_dir=EXAMPLES)


def _examples(kind):
    out = []
    for f in sorted(os.listdir(EXAMPLES)):
        if not f.endswith(".json"):
            continue
        try:
            b = _built(f)
        except interpatch.Error:
            continue
        if isinstance(b, kind) and b.type != "blocks":  # blocks locate block by block
            out.append(f)
    return out


def _queries(box_lo, box_hi, n, rng):
    c, h = (box_lo + box_hi) / 2, (box_hi - box_lo) * 0.75 + 1e-3 * np.linalg.norm(box_hi - box_lo)
    return c + rng.uniform(-1, 1, (n, 3)) * h


@pytest.mark.parametrize("name", _examples(interpatch.Surface))
def test_every_example_surface_against_dense_samples(name):
    s = _built(name)
    g = np.linspace(0, 1, 700)
    sample = s.evaluate(g, g).reshape(-1, 3)
    lo, hi = sample.min(axis=0), sample.max(axis=0)
    diag = np.linalg.norm(hi - lo)
    rng = np.random.default_rng(SEED)
    q = _queries(lo, hi, 400, rng)
    # Points on the surface and just off it, where neighbouring pieces compete.
    uv = rng.uniform(0, 1, (100, 2))
    on = np.array([s.point(a, b) for a, b in uv])
    q = np.concatenate([q, on, on + rng.normal(0, 1e-3 * diag, on.shape)])
    r = s.closest_points(q)
    assert r["params"].shape == (len(q), 2) and r["points"].shape == (len(q), 3) and r["distance"].shape == (len(q),)
    oracle, _ = cKDTree(sample).query(q)
    worst = np.max(r["distance"] - oracle)
    assert worst <= 1e-10 * diag, f"{name}: a distance {worst:g} above the dense sample's"
    # The answer is the surface's point at its parameters (its exact form's: the
    # construction's own formula agrees to rounding) and its distance is that point's.
    mine = np.array([s.point(a, b) for a, b in r["params"]])
    assert np.max(np.linalg.norm(mine - r["points"], axis=1)) <= 1e-12 * max(diag, np.max(np.abs(sample)))
    assert np.allclose(r["distance"], np.linalg.norm(r["points"] - q, axis=1), rtol=0, atol=1e-14 * diag)


@pytest.mark.parametrize("name", _examples(interpatch.Volume))
def test_every_example_volume_finds_its_own_points(name):
    v = _built(name)
    rng = np.random.default_rng(SEED)
    uvw = rng.uniform(0, 1, (300, 3))
    x = np.array([v.point(*p) for p in uvw])
    g = np.linspace(0, 1, 41)
    cloud = v.evaluate(g, g, g).reshape(-1, 3)
    diag = np.linalg.norm(cloud.max(axis=0) - cloud.min(axis=0))
    r = v.locate(x)
    assert r["inside"].all(), f"{name}: {np.sum(~r['inside'])} of its own points called outside"
    back = np.array([v.point(*p) for p in r["params"]])
    assert np.max(np.linalg.norm(back - x, axis=1)) <= 1e-10 * diag
    assert np.max(r["residual"]) <= 1e-10 * diag
    # Far outside: flagged, and the nearest boundary point is no farther than the
    # nearest of a dense sample of the boundary.
    faces = []
    t = np.linspace(0, 1, 161)
    for axis in range(3):
        for end in (0.0, 1.0):
            a = [t, t, t]
            a[axis] = np.array([end])
            faces.append(v.evaluate(*a).reshape(-1, 3))
    faces = np.concatenate(faces)
    lo, hi = cloud.min(axis=0), cloud.max(axis=0)
    d = rng.normal(size=(100, 3))
    far = (lo + hi) / 2 + d / np.linalg.norm(d, axis=1)[:, None] * diag
    out = v.locate(far)
    assert not out["inside"].any()
    oracle, _ = cKDTree(faces).query(far)
    assert np.max(out["residual"] - oracle) <= 1e-10 * diag


def test_curve_closest_points_against_dense_samples():
    rng = np.random.default_rng(SEED)
    pts = np.cumsum(rng.uniform(-1, 1, (12, 3)), axis=0)
    for c in (interpatch.interpolate_curve(pts), interpatch.interpolate_curve(pts[:8], periodic=True, degree=3)):
        sample = c.evaluate(np.linspace(0, 1, 200001))
        diag = np.linalg.norm(sample.max(axis=0) - sample.min(axis=0))
        q = sample.mean(axis=0) + rng.uniform(-1, 1, (300, 3)) * diag
        r = c.closest_points(q)
        assert r["params"].shape == (300,)
        oracle, _ = cKDTree(sample).query(q)
        assert np.max(r["distance"] - oracle) <= 1e-10 * diag
        assert np.array_equal(c.evaluate(r["params"]), r["points"])


def test_rays_meet_a_height_field_once_and_on_the_ray():
    s = _built("terrain.json")
    g = np.linspace(0, 1, 200)
    sample = s.evaluate(g, g).reshape(-1, 3)
    lo, hi = sample.min(axis=0), sample.max(axis=0)
    rng = np.random.default_rng(SEED)
    inner = lo + (hi - lo) * rng.uniform(0.02, 0.98, (200, 3))
    origins = inner.copy()
    origins[:, 2] = hi[2] + 1.0
    hits = s.intersect(origins, [0.0, 0.0, -1.0])
    assert np.array_equal(hits["ray"], np.arange(200)), "one hit a ray"
    diag = np.linalg.norm(hi - lo)
    assert np.max(np.abs(hits["points"][:, :2] - origins[:, :2])) <= 1e-9 * diag
    assert np.allclose(hits["t"], origins[:, 2] - hits["points"][:, 2], rtol=0, atol=1e-9 * diag)
    # Pointing away, nothing.
    assert len(s.intersect(origins, [0.0, 0.0, 1.0])["ray"]) == 0


def test_the_command_writes_what_python_finds(tmp_path):
    rng = np.random.default_rng(SEED)
    q = rng.uniform(-1, 2, (5000, 3))
    np.save(tmp_path / "q.npy", q)
    spec = os.path.join(EXAMPLES, "saddle.json")
    for ext in ("npz", "npy", "csv"):
        subprocess.run([CLI, "project", spec, str(tmp_path / "q.npy"), "-o", str(tmp_path / f"o.{ext}")], check=True)
    r = _built("saddle.json").closest_points(q)
    z = np.load(tmp_path / "o.npz")
    for k in ("params", "points", "distance"):
        assert np.array_equal(z[k], r[k]), k
    rows = np.load(tmp_path / "o.npy")
    assert np.array_equal(rows, np.column_stack([r["params"], r["points"], r["distance"]]))
    text = np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1)
    assert np.array_equal(text, rows), "the CSV's shortest round-trip digits read back to the same doubles"


def test_bad_points_are_named():
    s = _built("saddle.json")
    q = np.zeros((5, 3))
    q[3, 1] = np.nan
    with pytest.raises(interpatch.Error, match=r"point 3 is .*nan"):
        s.closest_points(q)
    with pytest.raises(interpatch.Error, match=r"points: expected an array of points of shape \(\.\.\., 3\), got \(5, 2\)"):
        s.closest_points(np.zeros((5, 2)))
    with pytest.raises(interpatch.Error, match=r"ray 1: its direction is the zero vector"):
        s.intersect(np.zeros((2, 3)), [[0, 0, 1], [0, 0, 0]])
    with pytest.raises(interpatch.Error, match=r"give one of param \(a name\), params \(the sites\) and base"):
        interpatch.approximate_surface(np.zeros((20, 3)), param="xy", base=s, tolerance=0.1)


def test_the_readmes_projection_example_runs(tmp_path, monkeypatch):
    import re
    readme = open(os.path.join(os.path.dirname(__file__), "..", "..", "README.md")).read()
    blocks = [re.search(start + r".*?```python\n(.*?)```", readme, re.S).group(1)
              for start in ("A terrain grid to a surface", "Curves are objects of their own", "Where points are, on every")]
    monkeypatch.chdir(tmp_path)
    scope = {}
    for code in blocks:  # the surface s and the ring c of the blocks before
        exec(compile(code, "README.md", "exec"), scope)
    assert scope["near"]["params"].shape == (49, 2) and scope["near"]["distance"].shape == (49,)
    assert np.array_equal(scope["hits"]["ray"], np.arange(49)), "one hit a ray, straight down"
    assert np.abs(scope["hits"]["points"][:, :2] - scope["probes"][:, :2]).max() < 1e-14
    assert 4.7 < scope["far"][0] < 5.3, "the wavy ring of radius 1 lies about 5 below"


@pytest.mark.parametrize("name", ["approximate_terrain.json", "approximate_scattered.json"])
def test_info_measures_an_approximation_by_closest_points(name):
    s = _built(name)
    info = s.info()
    closest = info["max_closest_distance"]
    # The closest point is never farther than the point at the datum's own parameters.
    assert closest["absolute"] <= info["max_data_error"]["absolute"] * (1 + 1e-12)
    spec = json.load(open(os.path.join(EXAMPLES, name)))
    pts = np.load(os.path.join(EXAMPLES, spec["points"]["npy"])).reshape(-1, 3)
    pts = pts[~np.isnan(pts).any(axis=1)]
    assert closest["absolute"] == s.closest_points(pts)["distance"].max()


def test_scattered_points_of_a_folded_sheet_take_their_sites_from_a_base_surface():
    # A sheet that wraps 300 degrees round an axis: it folds over every plane, so
    # neither "xy" nor "plane" can place its points; a coarse base surface near it can.
    rng = np.random.default_rng(SEED)
    a, z = rng.uniform(0, 5.2, 800), rng.uniform(0, 2, 800)
    r = 1 + 0.05 * np.sin(3 * a) * np.cos(2 * z)
    pts = np.stack([r * np.cos(a), r * np.sin(a), z], axis=-1)
    ring = [[float(np.cos(t)), float(np.sin(t)), 0.0] for t in np.linspace(0, 5.2, 9)]
    top = [[x, y, 2.0] for x, y, _ in ring]
    base = {"type": "ruled", "curves": [{"interpolate": ring}, {"interpolate": top}]}
    s = interpatch.build({"type": "approximate", "param": {"base": base}, "tolerance": 0.01, "points": pts.tolist()})
    info = s.info()
    assert info["parameters"]["param"] == "base"
    assert info["max_data_error"]["absolute"] <= 0.01
    assert s.closest_points(pts)["distance"].max() <= 0.01
