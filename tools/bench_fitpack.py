#!/usr/bin/env python3
"""Approximation against SciPy's FITPACK, and against interpolation of the same grid
(docs/BENCHMARKS.md, "Approximation against FITPACK").

    /usr/bin/python3 tools/bench_fitpack.py [--size 1024] [--big 2048] [--rounds 3]
        [--interpatch build/release/interpatch] [--dir /tmp/ip-approx]

1. A noisy terrain on a size x size grid over the unit square (x = u, y = v, z with
   Gaussian noise of standard deviation sigma) is written as .npy.
2. FITPACK (scipy.interpolate.RectBivariateSpline, bicubic, s = size^2 sigma^2, the
   expected sum of squared noise) fits it; its largest error at the data and its
   number of control points are noted.
3. interpatch approximates the same grid ("param": "uniform", the same parameters
   as FITPACK's x and y; degree 3) with "tolerance" set to FITPACK's largest error:
   the same largest error at the data, and the control points it needs for it.
4. Both are timed in turn (tools/time_in_turn.py): the whole command a user runs
   (`interpatch build SPEC -o OUT.npz`; for FITPACK this script's `fit` subcommand,
   which loads the .npy, fits and saves the coefficients), and the library call
   (interpatch: the build time `info` reports; FITPACK: the fit alone, in process).
5. A big x big grid: approximation to a tolerance against interpolation, both whole
   commands, with their peak memory against the size of the input.
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

SIGMA = 0.01


def terrain(n, seed):
    u = np.linspace(0.0, 1.0, n)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    z = (np.sin(6 * uu) * np.cos(5 * vv) + 0.4 * np.exp(-((uu - 0.3) ** 2 + (vv - 0.6) ** 2) / 0.01)
         + 0.2 * uu * vv)
    z = z + np.random.default_rng(seed).normal(0.0, SIGMA, z.shape)
    return np.stack([uu, vv, z], axis=-1)


def fitpack(points, s):
    from scipy.interpolate import RectBivariateSpline
    x = points[:, 0, 0]
    y = points[0, :, 1]
    t0, c0 = time.perf_counter(), time.process_time()
    spline = RectBivariateSpline(x, y, points[..., 2], kx=3, ky=3, s=s)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    tx, ty = spline.get_knots()
    err = np.abs(spline(x, y) - points[..., 2])
    return spline, {"seconds": seconds, "cpu": cpu, "control_points": [len(tx) - 4, len(ty) - 4],
                    "max_error": float(err.max()), "rms_error": float(np.sqrt(np.mean(err ** 2)))}


def cmd_fit(args):
    # The whole FITPACK command: load, fit, save the coefficients.
    points = np.load(args.data)
    spline, _ = fitpack(points, args.s)
    tx, ty = spline.get_knots()
    np.savez(args.output, knots_u=tx, knots_v=ty, coefficients=spline.get_coeffs())


def run(cmd):
    r = subprocess.run(cmd, shell=True, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"bench_fitpack.py: '{cmd}' failed: {r.stderr}")
    return r.stdout


def time_in_turn(rounds, commands):
    here = Path(__file__).resolve().parent
    args = [sys.executable, str(here / "time_in_turn.py"), "--rounds", str(rounds), "--json", "/dev/stdout"]
    args += [f"{k}={v}" for k, v in commands.items()]
    out = subprocess.run(args, capture_output=True, text=True, check=True).stdout
    return out


def cmd_compare(args):
    d = Path(args.dir)
    d.mkdir(parents=True, exist_ok=True)
    ip = str(Path(args.interpatch).resolve())
    me = f"{sys.executable} {Path(__file__).resolve()}"
    n = args.size
    points = terrain(n, 1)
    np.save(d / "noisy.npy", points)
    s = n * n * SIGMA ** 2
    _, fp = fitpack(points, s)
    spec = {"type": "approximate", "points": {"npy": "noisy.npy"}, "param": "uniform", "degree": [3, 3],
            "tolerance": fp["max_error"]}
    (d / "approx.json").write_text(json.dumps(spec))
    info = json.loads(run(f"{ip} info {d / 'approx.json'}"))
    ours = info["parameters"]
    print(f"# {n}x{n} noisy grid, sigma {SIGMA}")
    print(f"FITPACK  s = {s:g}: {fp['control_points'][0]} x {fp['control_points'][1]} = "
          f"{fp['control_points'][0] * fp['control_points'][1]} control points, max error {fp['max_error']:.6g}, "
          f"rms {fp['rms_error']:.6g}, fit {fp['seconds']:.3f} s")
    cp = ours["control_points"]
    print(f"interpatch tolerance {fp['max_error']:.6g}: {cp[0]} x {cp[1]} = {cp[0] * cp[1]} control points, "
          f"max error {ours['max_error']:.6g}, rms {ours['rms_error']:.6g}, {ours['fits']} fits, "
          f"build {info['timings']['build_ms']} ms, parse {info['timings']['parse_ms']} ms")
    # The library calls in turn, in this process: interpatch through its Python module
    # (the array passed in memory, as NumPy holds it), FITPACK's fit; wall clock and
    # the process's CPU time of each.
    sys.path.insert(0, str(Path(ip).parent / "python"))
    import interpatch
    runs = {"interpatch": [], "fitpack": []}
    for _ in range(args.rounds):
        t0, c0 = time.perf_counter(), time.process_time()
        surface = interpatch.approximate_surface(points, param="uniform", tolerance=fp["max_error"])
        runs["interpatch"].append((time.perf_counter() - t0, time.process_time() - c0))
        assert surface.info()["parameters"]["control_points"] == cp
        _, f = fitpack(points, s)  # the fit alone, not its error check
        runs["fitpack"].append((f["seconds"], f["cpu"]))
    med = {k: (float(np.median([w for w, _ in v])), float(np.median([c for _, c in v]))) for k, v in runs.items()}
    print(f"library call, median of {args.rounds} in turn (load average {os.getloadavg()[0]:.2f}): "
          f"interpatch {med['interpatch'][0]:.3f} s wall, {med['interpatch'][1]:.3f} s CPU; "
          f"FITPACK {med['fitpack'][0]:.3f} s wall, {med['fitpack'][1]:.3f} s CPU; FITPACK / interpatch "
          f"{med['fitpack'][0] / med['interpatch'][0]:.2f} (wall), {med['fitpack'][1] / med['interpatch'][1]:.2f} (CPU)")
    print(time_in_turn(args.rounds, {
        "interpatch": f"{ip} build {d / 'approx.json'} -o {d / 'approx.npz'}",
        "fitpack": f"{me} fit {d / 'noisy.npy'} --s {s!r} -o {d / 'fitpack.npz'}"}))

    if args.big:
        b = args.big
        big = terrain(b, 2)
        np.save(d / "big.npy", big)
        del big
        input_mib = b * b * 24 / 2 ** 20
        (d / "big_interp.json").write_text(json.dumps({"type": "interpolate", "points": {"npy": "big.npy"},
                                                       "param": "uniform"}))
        (d / "big_approx.json").write_text(json.dumps({"type": "approximate", "points": {"npy": "big.npy"},
                                                       "param": "uniform", "tolerance": 6 * SIGMA}))
        ii = json.loads(run(f"{ip} info {d / 'big_interp.json'}"))
        ia = json.loads(run(f"{ip} info {d / 'big_approx.json'}"))
        pa = ia["parameters"]
        print(f"# {b}x{b}: input {input_mib:.1f} MiB; approximation to {6 * SIGMA:g} (6 sigma): "
              f"{pa['control_points']} control points, max error {pa['max_error']:.6g}, {pa['fits']} fits")
        print(f"library call: interpolation build {ii['timings']['build_ms']} ms, approximation build "
              f"{ia['timings']['build_ms']} ms, ratio {ia['timings']['build_ms'] / ii['timings']['build_ms']:.2f}")
        print(time_in_turn(args.rounds, {
            "interpolate": f"{ip} build {d / 'big_interp.json'} -o {d / 'big_interp.npz'}",
            "approximate": f"{ip} build {d / 'big_approx.json'} -o {d / 'big_approx.npz'}"}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command")
    f = sub.add_parser("fit")
    f.add_argument("data")
    f.add_argument("--s", type=float, required=True)
    f.add_argument("-o", "--output", required=True)
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--big", type=int, default=2048)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--interpatch", default="build/release/interpatch")
    ap.add_argument("--dir", default="/tmp/ip-approx")
    args = ap.parse_args()
    if args.command == "fit":
        cmd_fit(args)
    else:
        cmd_compare(args)


if __name__ == "__main__":
    main()
