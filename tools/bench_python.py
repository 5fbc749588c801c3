#!/usr/bin/python3
"""interpatch from Python against the same calls from C++ and against SciPy.

    /usr/bin/python3 tools/bench_python.py [--build build/bench] [--n 1024] [--k 1000] [--rounds 7]

The job: interpolate an n x n grid of 3-D points (a terrain: x and y on an even
grid, a smooth height, chord parameters) and evaluate the surface on k x k
parameters. Three contenders, taken in turn in every round so that the machine's
load falls on all of them alike:

- python: `interpatch.interpolate_surface(grid, param=PARAM)` and `surface.evaluate(us, vs)`,
  timed in this process;
- c++: bench/same_calls, the same two calls made from C++ (the grid copied in, as
  the Python caller keeps its array), timed inside that program;
- scipy: `RectBivariateSpline(x, y, ., s=0)` for each of the three coordinates
  and their evaluation on the k x k grid, stacked into (k, k, 3), timed in this
  process (SciPy's splines are functions z(x, y), so a surface of points takes
  three of them). SciPy interpolating the height alone is timed too.

Each contender runs three times a round and keeps its fastest; the ratios are taken
within a round and the table gives their median over the rounds.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np


def terrain(n):
    x = np.linspace(0.0, 10000.0, n)
    y = np.linspace(0.0, 10000.0, n)
    z = 200.0 * np.sin(x / 1500.0)[:, None] * np.cos(y / 2100.0)[None, :] + 50.0 * np.sin((x[:, None] + y[None, :]) / 700.0)
    return x, y, np.ascontiguousarray(np.stack(np.broadcast_arrays(x[:, None], y[None, :], z), axis=-1))


def fastest(job, times=3):
    best = float("inf")
    for _ in range(times):
        t0 = time.perf_counter()
        result = job()
        best = min(best, time.perf_counter() - t0)
        del result
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build/bench", help="a build tree with python/ and bench/same_calls")
    ap.add_argument("--n", type=int, default=1024, help="grid points along each side")
    ap.add_argument("--k", type=int, default=1000, help="evaluated points along each side")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--param", default="uniform", choices=["uniform", "chord", "centripetal"],
                    help="interpatch's parameters (uniform: the same spline as SciPy's on this even grid)")
    args = ap.parse_args()

    sys.path.insert(0, os.path.join(args.build, "python"))
    import interpatch
    from scipy.interpolate import RectBivariateSpline

    same_calls = os.path.join(args.build, "bench", "same_calls")
    x, y, grid = terrain(args.n)
    us = np.linspace(0.0, 1.0, args.k)
    vs = np.linspace(0.0, 1.0, args.k)
    xs = np.linspace(x[0], x[-1], args.k)
    ys = np.linspace(y[0], y[-1], args.k)

    def python_job():
        s = interpatch.interpolate_surface(grid, param=args.param)
        return s.evaluate(us, vs)

    def scipy_job():
        splines = [RectBivariateSpline(x, y, grid[..., c], kx=3, ky=3, s=0) for c in range(3)]
        return np.stack([f(xs, ys) for f in splines], axis=-1)

    def scipy_height_job():
        return RectBivariateSpline(x, y, grid[..., 2], kx=3, ky=3, s=0)(xs, ys)

    # The contenders agree: interpatch's bicubic interpolation with uniform
    # parameters on this even grid is SciPy's not-a-knot spline (tests/python check
    # it to 1e-12 of the heights); the bound here is looser only to stay a sanity check.
    check = interpatch.interpolate_surface(grid, param="uniform").evaluate(us, vs)
    deviation = float(np.max(np.abs(check - scipy_job())))
    if deviation > 1e-6 * float(np.max(np.abs(grid))):
        sys.exit(f"bench_python: interpatch and SciPy disagree by {deviation}")

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "grid.npy")
        np.save(path, grid)
        rows = []
        for _ in range(args.rounds):
            py = fastest(python_job)
            out = subprocess.run([same_calls, path, str(args.k), "3", args.param], check=True, capture_output=True, text=True).stdout
            cpp = min(sum(float(t) for t in line.split()) for line in out.splitlines())
            sp = fastest(scipy_job, 1)
            sp_z = fastest(scipy_height_job, 1)
            rows.append((py, cpp, sp, sp_z))

    med = [statistics.median(r[i] for r in rows) for i in range(4)]
    ratio = lambda a, b: statistics.median(r[a] / r[b] for r in rows)
    load = os.getloadavg()
    threads = os.environ.get("OMP_NUM_THREADS", str(os.cpu_count()))
    print(f"interpolate {args.n}² ({args.param} parameters) + evaluate {args.k}², {args.rounds} rounds in turn, "
          f"{threads} thread(s) for interpatch, "
          f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print("| contender | median | ratio to interpatch from Python (median of rounds) |")
    print("|---|---:|---:|")
    print(f"| interpatch from Python | {1e3 * med[0]:.1f} ms | 1 |")
    print(f"| the same calls from C++ | {1e3 * med[1]:.1f} ms | Python / C++ = {ratio(0, 1):.2f} |")
    print(f"| SciPy RectBivariateSpline, x, y, z | {1e3 * med[2]:.0f} ms | SciPy / Python = {ratio(2, 0):.1f} |")
    print(f"| SciPy RectBivariateSpline, z alone | {1e3 * med[3]:.0f} ms | SciPy / Python = {ratio(3, 0):.1f} |")


if __name__ == "__main__":
    main()
