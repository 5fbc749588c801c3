#!/usr/bin/env python3
"""interpatch under mpirun, compared byte for byte with the single process.

Runs `interpatch eval` and `interpatch build` on grids whose rows split unevenly
between 1..4 processes (chunks of 16 rows), closed directions of odd and even
degree, collapsed rows (poles), every parametrization, float32 and big-endian
input, Fortran-order input, surfaces and volumes, and approximations (a given number of control points,
the separable fit and the sparse one with holes, smoothing, smoothing "auto", a
tolerance on a grid large enough to be thinned and on small ones; weights with
zeros; closed u and v, the closing line left out or none; a tolerance with weights
and closed directions), each
checked to have run split; every output must equal the single process's, byte for
byte. Then the failures: a missing points file, a NaN in the last process's rows,
bad options, a closing line that nearly repeats the first, an output in a missing
directory; each must end every process with
the single process's exit status and error line, exactly one line on stderr, no
output file and no temporary file left, and an existing output untouched.

Usage: mpi_runs.py [--one-split] INTERPATCH [MPIRUN]

--one-split (the sanitizer build, whose processes start and run several times slower):
every case on its largest count of processes alone, every failure on 3 processes, and
the variants of cases that run left out (RELEASE_ONLY).
"""
import itertools
import json
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

ONE_SPLIT = "--one-split" in sys.argv[1:]
ARGS = [a for a in sys.argv[1:] if a != "--one-split"]
EXE = ARGS[0]
MPIRUN = ARGS[1] if len(ARGS) > 1 else "mpirun"
ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1",
           OMPI_MCA_rmaps_base_oversubscribe="1",
           # mpirun waits 2 s after a process ends with an error before it ends the others; every
           # process here ends by itself with the same status, so the failures need no wait.
           OMPI_MCA_odls_base_sigkill_timeout="0",
           # The processes share one machine and talk through shared memory (btl self,vader);
           # without this, each launch first probes UCX's devices: 0.85 s against 0.57 s for
           # 4 processes.
           OMPI_MCA_pml="ob1")
# A single process must not see the launcher's variables (it would start MPI).
SINGLE_ENV = {k: v for k, v in ENV.items() if not k.startswith(("OMPI_COMM_WORLD", "PMIX_", "PMI_"))}
PROCESSES = [1, 2, 3, 4]
# The failures: one process alone, an uneven split and the most processes (2 adds no case of its own).
FAILURE_PROCESSES = [1, 3, 4]
# Cases whose one-process run under mpirun adds nothing to the first case's.
SPLIT_ONLY = [2, 3, 4]
failures = []
# Cases the sanitizer run leaves out: each a variant (parametrization, byte order, scale,
# weights, which direction is closed) of a case that runs there and takes the same split
# code; the Release run tries every case. Each sanitized mpirun costs about 2 s.
RELEASE_ONLY = {
    "surface pole row, centripetal", "surface uniform, degree 5x2, float32 big-endian",
    "surface closed v (tube), even degree", "surface closed along u, not declared (warning), extreme scale",
    "volume closed u, centripetal",
    "approximate holes, smoothing, centripetal, float32 big-endian",
    "approximate columns of holes, as many control points as data along v",
    "approximate weights, smoothing auto", "approximate closed u, weights (the first row 0), smoothing",
    "approximate closed v (tube, closing column left out), weights, control points",
    "approximate tolerance 520x520 holes (thinned grid)", "approximate tolerance holes, centripetal, Fortran order",
    "approximate tolerance holes at 1e-200", "approximate control points at 1e+200", "approximate control points at 1e-200",
    "approximate tolerance, weights with zeros and holes", "approximate tolerance closed v (tube, closing column left out)",
}


# The launcher's own event library may warn while processes that failed together
# are torn down on a loaded machine ("[warn] Epoll MOD(1) on fd 23 failed ... Bad file
# descriptor"): a line of mpirun's, not of interpatch's, left out of what is compared.
LAUNCHER_NOISE = re.compile(r"^\[warn\] Epoll [A-Z]+\(\d+\) on fd \d+ failed\..*$\n?", re.MULTILINE)


def launch(cmd, cwd=None, env=None):
    """A run with a time limit; running out of it is a failure reported like any other."""
    try:
        return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired as e:
        return subprocess.CompletedProcess(cmd, -9, "", f"timed out after {e.timeout} s: {' '.join(cmd)}\n")


def launcher_trouble(r):
    """A run that timed out, or whose stderr has a line that is not interpatch's: the
    launcher's own trouble (shared memory, its event library) on a loaded machine."""
    return r.returncode == -9 or any(not line.startswith("interpatch") for line in r.stderr.splitlines())


def run(args, processes=None, cwd=None):
    cmd = [EXE] + args if processes is None else [MPIRUN, "--oversubscribe", "-q", "--mca", "btl", "self,vader", "-np", str(processes), EXE] + args
    r = launch(cmd, cwd=cwd, env=SINGLE_ENV if processes is None else ENV)
    if processes is not None:
        r.stderr = LAUNCHER_NOISE.sub("", r.stderr)
        # Once more when the launcher, not interpatch, had trouble: said in the log, and the
        # second run is checked as any other (its output and status compared in full).
        if launcher_trouble(r):
            print(f"retried once, the launcher's trouble on {processes} processes {args}: {r.stderr!r}", flush=True)
            for name in os.listdir(cwd or "."):
                if name.startswith("out.") or name == "split.npz":
                    os.remove(os.path.join(cwd or ".", name))
            r = launch(cmd, cwd=cwd, env=ENV)
            r.stderr = LAUNCHER_NOISE.sub("", r.stderr)
    return r


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what, flush=True)


def grid(shape, rng, pole=False, close=None, scale=1.0):
    """Smooth points with noise; `close` repeats the first line along that axis at its end."""
    axes = np.meshgrid(*[np.linspace(0, 1, n) for n in shape], indexing="ij")
    base = [axes[0] * 2 + 0.3 * np.sin(3 * axes[-1]), axes[-1] + 0.2 * axes[0] ** 2,
            np.cos(2 * axes[0]) * np.sin(3 * axes[-1]) + (axes[1] if len(shape) == 3 else 0)]
    g = np.stack(base, -1) + 0.01 * rng.random(tuple(shape) + (3,))
    if len(shape) == 2 and close == 1:  # a tube: v around a circle
        t = np.linspace(0, 2 * np.pi, shape[1], endpoint=False)
        g = np.stack([np.cos(t)[None, :] * (1 + 0.3 * axes[0]), np.sin(t)[None, :] * (1 + 0.3 * axes[0]), axes[0] * 3], -1)
        g = g + 0.001 * rng.random(g.shape)
    if pole:  # the first row collapses to one point
        g[0] = g[0].mean(axis=tuple(range(g.ndim - 2)))
    if close is not None:
        first = np.take(g, [0], axis=close)
        g = np.concatenate([g, first], axis=close)
    return g * scale


def tube_along_u(shape, rng):
    """grid()'s tube closed along u instead of v, the closing row left at the end: data that
    really close along u (grid()'s close=0 repeats the first row after a jump from the last,
    which no closed fit follows: an even degree's least squares swing far past it and are
    refused as ill_conditioned)."""
    return np.ascontiguousarray(grid((shape[1], shape[0]), rng, close=1).transpose(1, 0, 2))


def cases(rng):
    yield "surface 53x37 (uneven rows)", grid((53, 37), rng), {}, "61"
    yield "surface pole row, centripetal", grid((40, 21), rng, pole=True), {"param": "centripetal", "degree": [3, 2]}, "45x7", \
        SPLIT_ONLY
    yield "surface uniform, degree 5x2, float32 big-endian", grid((35, 9), rng).astype(">f4"), \
        {"param": "uniform", "degree": [5, 2]}, "33", SPLIT_ONLY
    yield "surface closed u, even degree", grid((47, 19), rng, close=0), {"periodic": [True, False], "degree": [2, 3]}, "40"
    yield "surface closed v (tube), even degree", grid((50, 24), rng, close=1), {"periodic": [False, True], "degree": [3, 4]}, "41", \
        SPLIT_ONLY
    yield "surface closed along u, not declared (warning), extreme scale", grid((33, 12), rng, close=0, scale=1e300), {}, "30"
    yield "volume closed w, even degree", grid((38, 7, 8), rng, close=2), {"periodic": [False, False, True], "degree": [3, 2, 2]}, \
        "29x33x17"
    yield "surface Fortran order, float32", np.asfortranarray(grid((37, 22), rng).astype("<f4")), {"degree": [3, 2]}, "29", \
        [2, 3]
    yield "volume Fortran order, big-endian", np.asfortranarray(grid((34, 6, 5), rng).astype(">f8")), {"degree": [3, 2, 2]}, \
        "13x9x7", [3]
    yield "volume closed u, centripetal", grid((36, 5, 4), rng, close=0), \
        {"periodic": [True, False, False], "degree": [3, 2, 2], "param": "centripetal"}, "9"


def holes(g, rng):
    """NaN (missing points) scattered, in a block and in a whole row: approximation's holes."""
    g = g.copy()
    n0, n1 = g.shape[:2]
    g[n0 // 3:n0 // 3 + 6, n1 // 4:n1 // 4 + 5] = np.nan
    g[n0 - 2, :, 0] = np.nan
    for i, j in zip(rng.integers(0, n0, 12), rng.integers(0, n1, 12)):
        g[i, j, rng.integers(0, 3)] = np.nan
    return g


def approximate_cases(rng):
    """(name, points, options, eval grid, process counts): the split approximation's
    ways, the separable fit and the sparse system with and without holes; the slower
    cases on fewer process counts."""
    yield "approximate 53x37 control points (separable)", grid((53, 37), rng), {"control_points": [20, 15]}, "61", PROCESSES
    yield "approximate 70x29 holes, control points, Fortran order", np.asfortranarray(holes(grid((70, 29), rng), rng)), \
        {"control_points": [24, 12]}, "40x23", [2, 4]
    yield "approximate holes, smoothing, centripetal, float32 big-endian", holes(grid((45, 30), rng), rng).astype(">f4"), \
        {"smoothing": 1e-3, "param": "centripetal", "degree": [3, 2]}, "35", [3]
    g = grid((40, 20), rng)
    g[:, 5:9] = np.nan  # control points with no data under them: the fill term settles them
    yield "approximate columns of holes, as many control points as data along v", g, {"control_points": [5, 20]}, "11", [3]
    yield "approximate smoothing auto, uniform", grid((40, 25), rng), {"smoothing": "auto", "param": "uniform"}, "30", [3]


def weighted_closed_cases(rng):
    """(name, points, options, eval grid, process counts): weights (zeros among them,
    with holes), closed u and v (a closing line repeating the first, left out, and
    none), each on one split of the rows."""
    g = holes(grid((53, 37), rng), rng)
    w = 0.2 + 2 * rng.random((53, 37))
    w[10:14, 5:30] = 0  # zero weights beside the holes
    yield "approximate weights with zeros and holes, control points", g, \
        {"control_points": [20, 15], "weights": w.round(3).tolist()}, "29", [3]
    w = 0.5 + rng.random((40, 25))
    yield "approximate weights, smoothing auto", grid((40, 25), rng), {"smoothing": "auto", "weights": w.round(3).tolist()}, \
        "17", [2]
    yield "approximate closed u (closing row left out), even degree, control points (cyclic separable)", \
        tube_along_u((50, 20), rng), {"periodic": [True, False], "degree": [2, 3], "control_points": [12, 8]}, "31", [4]
    w = 0.5 + rng.random((51, 20))
    w[0, :] = 0
    yield "approximate closed u, weights (the first row 0), smoothing", tube_along_u((50, 20), rng), \
        {"periodic": [True, False], "smoothing": 1e-4, "weights": w.round(3).tolist()}, "23", [2]
    yield "approximate closed u, holes, as few control rows as degree 3 allows", holes(grid((70, 12), rng), rng), \
        {"periodic": [True, False], "control_points": [4, 6]}, "15", [4]
    yield "approximate closed v (tube, closing column left out), weights, control points", grid((45, 24), rng, close=1), \
        {"periodic": [False, True], "degree": [3, 4], "control_points": [10, 9],
         "weights": (0.5 + rng.random((45, 25))).round(3).tolist()}, "21", [3]


def tolerance_weighted_closed_cases(rng):
    """(name, points, options, eval grid, process counts): the fit to a tolerance with weights
    (zeros among them, with holes) and along closed u and v, each on one split of the rows."""
    w = 0.2 + 2 * rng.random((60, 45))
    w[10:14, 5:30] = 0  # zero weights beside the holes
    yield "approximate tolerance, weights with zeros and holes", holes(bumps((60, 45), rng), rng), \
        {"tolerance": 2e-3, "weights": w.round(3).tolist()}, "29", [3]
    # grid()'s noise reaches 0.01 per coordinate: a tolerance above it.
    yield "approximate tolerance closed u (closing row left out), weights, even degree", tube_along_u((50, 20), rng), \
        {"periodic": [True, False], "degree": [2, 3], "tolerance": 0.02,
         "weights": (0.5 + rng.random((51, 20))).round(3).tolist()}, "31", [4]
    yield "approximate tolerance closed v (tube, closing column left out)", grid((45, 24), rng, close=1), \
        {"periodic": [False, True], "degree": [3, 4], "tolerance": 2e-3}, "21", [2]


def bumps(shape, rng):
    """A smooth sheet with a narrow bump and noise of 5e-4: knots grow where the bump is, and a
    tolerance of 2e-3 is reached (the noise of grid() would stop it short)."""
    u, v = np.meshgrid(np.linspace(0, 1, shape[0]), np.linspace(0, 1, shape[1]), indexing="ij")
    z = np.cos(5 * u) * np.sin(7 * v) + 0.2 * np.exp(-80 * ((u - 0.4) ** 2 + (v - 0.6) ** 2))
    g = np.stack([2 * u + 0.3 * np.sin(3 * v), v + 0.2 * u ** 2, z], -1)
    return g + 5e-4 * rng.random(g.shape)


def tolerance_cases(rng):
    """The fit to a tolerance: grids of 2^18 points or more grow their first knots on a thinned
    grid (every 4th row and column: blocks of it on every process, some empty), smaller ones
    on the whole grid; the separable fit and the sparse one with holes; row splits uneven."""
    yield "approximate tolerance 520x520 (thinned grid)", bumps((520, 520), rng), {"tolerance": 2e-3}, "70", [1, 4]
    yield "approximate tolerance 520x520 holes (thinned grid)", holes(bumps((520, 520), rng), rng), {"tolerance": 2e-3}, \
        "45x61", [3]
    yield "approximate tolerance 40x6600 holes: thinned along v alone, processes with no rows", \
        holes(bumps((40, 6600), rng), rng), {"tolerance": 2e-3, "degree": [2, 3]}, "9x50", [4]
    # 3 control columns at first: a process holds none in the separable solve.
    yield "approximate tolerance 53x37, fewer control columns than processes", bumps((53, 37), rng), \
        {"tolerance": 2e-3, "degree": [3, 2]}, "40", [4]
    yield "approximate tolerance holes, centripetal, Fortran order", np.asfortranarray(holes(bumps((70, 45), rng), rng)), \
        {"tolerance": 2e-3, "param": "centripetal"}, "33", [2]
    # Data beyond 2^±64 are fitted in a power of two of their own size, on the split
    # path as in one process: squared distances would overflow at 1e200 and vanish at 1e-200.
    for scale in (1e200, 1e-200):
        yield f"approximate tolerance holes at {scale:g}", holes(bumps((60, 45), rng), rng) * scale, \
            {"tolerance": 2e-3 * scale}, "30", [3]
        yield f"approximate control points at {scale:g}", bumps((53, 37), rng) * scale, {"control_points": [20, 15]}, \
            "30", [2]



def tolerance_failure():
    """A fit to a tolerance refused on the split path as in one process: one line, its status, no output."""
    with tempfile.TemporaryDirectory() as d:
        np.save(os.path.join(d, "points.npy"), np.full((40, 20, 3), np.nan))
        with open(os.path.join(d, "spec.json"), "w") as f:
            json.dump({"type": "approximate", "points": {"npy": "points.npy"}, "tolerance": 1e-3}, f)
        same_failure(d, "approximate tolerance: every point missing", ["build", "spec.json", "-o", "good.npz"], 3, [3])


def split_ran(d, spec_file):
    """Whether a run on 2 processes was split (rank 1 reports its stages) rather than run on rank 0 alone."""
    env = dict(ENV, INTERPATCH_MPI_TIMINGS="1")
    cmd = [MPIRUN, "--oversubscribe", "-q", "--mca", "btl", "self,vader", "-np", "2", "-x", "INTERPATCH_MPI_TIMINGS", EXE,
           "build", spec_file, "-o", "split.npz"]
    r = launch(cmd, cwd=d, env=env)
    os.path.exists(os.path.join(d, "split.npz")) and os.remove(os.path.join(d, "split.npz"))
    return r.returncode == 0 and "rank 1 stages" in r.stderr


def same_outputs(d, name, spec_file, eval_grid, processes=PROCESSES):
    if ONE_SPLIT:
        processes = [max(processes)]
    for args in [["build", spec_file, "-o", "out.npz"], ["eval", spec_file, "--grid", eval_grid, "-o", "out.npy"]]:
        out = os.path.join(d, args[-1])
        one = run(args, cwd=d)
        check(one.returncode == 0, f"{name}: single process {args}: {one.stderr}")
        want = open(out, "rb").read()
        os.remove(out)
        for p in processes:
            r = run(args, p, cwd=d)
            check(r.returncode == 0, f"{name}: {p} processes {args}: status {r.returncode}: {r.stderr}")
            check(r.stderr == one.stderr, f"{name}: {p} processes {args}: stderr {r.stderr!r}, single {one.stderr!r}")
            got = open(out, "rb").read() if os.path.exists(out) else b""
            check(got == want, f"{name}: {p} processes {args}: output differs ({len(got)} bytes, single {len(want)})")
            if os.path.exists(out):
                os.remove(out)
        check(sorted(os.listdir(d)) == sorted([spec_file, "points.npy"]), f"{name}: files left: {os.listdir(d)}")


def same_failure(d, name, args, status, processes=FAILURE_PROCESSES):
    if ONE_SPLIT:
        processes = [3]
    good = os.path.join(d, "good" + os.path.splitext(args[args.index("-o") + 1])[1])
    one = run(args, cwd=d)
    check(one.returncode == status, f"{name}: single process status {one.returncode}, expected {status}: {one.stderr}")
    before = sorted(os.listdir(d))
    for p in processes:
        r = run(args, p, cwd=d)
        lines = r.stderr.splitlines()
        check(r.returncode == status, f"{name}: {p} processes: status {r.returncode}, expected {status}: {r.stderr}")
        check(len(lines) == 1, f"{name}: {p} processes: {len(lines)} lines on stderr: {r.stderr!r}")
        check(r.stderr == one.stderr, f"{name}: {p} processes: {r.stderr!r}, single {one.stderr!r}")
        check(sorted(os.listdir(d)) == before, f"{name}: {p} processes: files {sorted(os.listdir(d))}, before {before}")
    if os.path.exists(good):
        check(open(good, "rb").read() == b"good", f"{name}: the existing output was changed")


def a_rank_cannot_read(d, rng):
    """Ranks 1 and 2 run in a directory where the points file cannot be read (it is a
    directory there): the first of them reports, all three end with status 4, and no
    output appears."""
    a, b = os.path.join(d, "a"), os.path.join(d, "b")
    os.makedirs(a)
    os.makedirs(os.path.join(b, "points.npy"))
    np.save(os.path.join(a, "points.npy"), grid((50, 20), rng))
    for w in (a, b):
        with open(os.path.join(w, "spec.json"), "w") as f:
            json.dump({"type": "interpolate", "points": {"npy": "points.npy"}}, f)
    out = os.path.join(d, "split.npz")
    args = ["build", "spec.json", "-o", out]
    cmd = [MPIRUN, "--oversubscribe", "-q", "--mca", "btl", "self,vader", "-np", "1", "--wdir", a, EXE] + args + \
          [":", "-np", "2", "--wdir", b, EXE] + args
    r = launch(cmd, env=ENV)
    lines = r.stderr.splitlines()
    check(r.returncode == 4, f"a rank cannot read: status {r.returncode}, expected 4: {r.stderr}")
    check(len(lines) == 1 and "cannot" in r.stderr and "points.npy" in r.stderr,
          f"a rank cannot read: stderr {r.stderr!r}")
    check(not os.path.exists(out) and not [f for f in os.listdir(d) if "interpatch" in f],
          f"a rank cannot read: files left: {os.listdir(d)}")


def main():
    rng = np.random.default_rng(19)
    every = np.random.default_rng(0)
    names = {c[0] for c in itertools.chain(cases(every), approximate_cases(every), tolerance_cases(every),
                                            weighted_closed_cases(every), tolerance_weighted_closed_cases(every))}
    check(RELEASE_ONLY <= names, f"RELEASE_ONLY names no case: {sorted(RELEASE_ONLY - names)}")
    for name, points, options, eval_grid, *processes in cases(rng):
        if ONE_SPLIT and name in RELEASE_ONLY:
            continue
        began = time.monotonic()
        with tempfile.TemporaryDirectory() as d:
            np.save(os.path.join(d, "points.npy"), points)
            spec_type = "interpolate_volume" if points.ndim == 4 else "interpolate"
            with open(os.path.join(d, "spec.json"), "w") as f:
                json.dump(dict({"type": spec_type, "points": {"npy": "points.npy"}}, **options), f)
            if points.flags.f_contiguous and not points.flags.c_contiguous:  # read split, not by rank 0 alone
                check(split_ran(d, "spec.json"), f"{name}: not split between the processes")
            same_outputs(d, name, "spec.json", eval_grid, *processes)
            print(f"ok: {name} ({time.monotonic() - began:.1f} s)", flush=True)
    approximations = itertools.chain(approximate_cases(rng), tolerance_cases(rng), weighted_closed_cases(rng),
                                     tolerance_weighted_closed_cases(rng))
    for name, points, options, eval_grid, processes in approximations:
        if ONE_SPLIT and name in RELEASE_ONLY:
            continue
        began = time.monotonic()
        with tempfile.TemporaryDirectory() as d:
            np.save(os.path.join(d, "points.npy"), points)
            with open(os.path.join(d, "spec.json"), "w") as f:
                json.dump(dict({"type": "approximate", "points": {"npy": "points.npy"}}, **options), f)
            check(split_ran(d, "spec.json"), f"{name}: not split between the processes")
            same_outputs(d, name, "spec.json", eval_grid, processes)
            print(f"ok: {name} ({time.monotonic() - began:.1f} s)", flush=True)
    with tempfile.TemporaryDirectory() as d:
        for axis, processes in [(0, [3]), (1, [2])]:  # a closing line off the first by a rounding error
            g = grid((40, 20), rng, close=axis)
            if axis == 0:
                g[-1, :, 2] += 1e-9
            else:
                g[:, -1, 2] += 1e-9
            np.save(os.path.join(d, "points.npy"), g)
            with open(os.path.join(d, "spec.json"), "w") as f:
                json.dump({"type": "approximate", "points": {"npy": "points.npy"}, "periodic": [axis == 0, axis == 1],
                           "control_points": [8, 6]}, f)
            same_failure(d, f"approximate: the last line along {'uv'[axis]} nearly repeats the first",
                         ["eval", "spec.json", "--grid", "9", "-o", "good.npy"], 3, processes)
    tolerance_failure()
    with tempfile.TemporaryDirectory() as d:
        g = np.full((40, 20, 3), np.nan)
        np.save(os.path.join(d, "points.npy"), g)
        with open(os.path.join(d, "spec.json"), "w") as f:
            json.dump({"type": "approximate", "points": {"npy": "points.npy"}, "control_points": [5, 5]}, f)
        same_failure(d, "approximate: every point missing", ["build", "spec.json", "-o", "good.npz"], 3, [2])
        g = grid((40, 20), rng)
        g[17, :] = g[16, :]  # rows 16 and 17 coincide: zero chords along u, and a degree along v too high
        np.save(os.path.join(d, "points.npy"), g)
        with open(os.path.join(d, "spec.json"), "w") as f:
            json.dump({"type": "approximate", "points": {"npy": "points.npy"}, "smoothing": 0.1, "degree": [3, 25]}, f)
        same_failure(d, "approximate: two faults, the first in one process's order", ["build", "spec.json", "-o", "good.npz"], 3,
                     [2])
        g = grid((40, 20), rng)
        g[38, 3, 2] = np.inf  # in the last process's rows
        np.save(os.path.join(d, "points.npy"), g)
        same_failure(d, "approximate: infinity in the last rows", ["eval", "spec.json", "--grid", "9", "-o", "good.npy"], 3,
                     [3])
    with tempfile.TemporaryDirectory() as d:
        g = grid((50, 20), rng)
        g[49, 7, 1] = np.nan  # in the last process's rows for every count of processes
        np.save(os.path.join(d, "points.npy"), g)
        with open(os.path.join(d, "good.npy"), "wb") as f:
            f.write(b"good")
        same_failure(d, "NaN in the last rows", ["eval", "points.npy", "--grid", "20", "-o", "good.npy"], 3)
        np.save(os.path.join(d, "points.npy"), grid((50, 20), rng))
        with open(os.path.join(d, "spec.json"), "w") as f:
            json.dump({"type": "interpolate", "points": {"npy": "missing.npy"}}, f)
        same_failure(d, "missing points file", ["build", "spec.json", "-o", "good.npz"], 4)
        with open(os.path.join(d, "spec.json"), "w") as f:
            json.dump({"type": "interpolate", "points": {"npy": "points.npy"}, "degree": [3, 30]}, f)
        same_failure(d, "degree too high", ["build", "spec.json", "-o", "good.npz"], 3)
        same_failure(d, "bad --grid", ["eval", "spec.json", "--grid", "1", "-o", "good.npy"], 2)
        same_failure(d, "output in a missing directory", ["eval", "spec.json", "--grid", "5", "-o", "no/dir/x.npy"], 4)
        a_rank_cannot_read(d, rng)
        print("ok: failures", flush=True)
    if failures:
        # Again at the end, where a log read from its end shows them.
        print(f"{len(failures)} failures:")
        for what in failures:
            print("  ", what[:2000])
        return 1
    print("all outputs equal the single process's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
