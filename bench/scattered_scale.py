#!/usr/bin/env python3
"""Scattered fits at scale, whole `interpatch build` processes, one binary or two in turn.

Writes a smooth height field sampled at random sites (3 sin(2πx/400) cos(2πy/400) over
1000 × 800 m, σ = 0.05 m of noise, seed 1) and the specs below, runs each with
/usr/bin/time (wall clock, peak RSS) and prints a Markdown table:

  tol1e6      10^6 points, "tolerance": 0.3
  net512      10^6 points, "control_points": [512, 512]
  c100..c280  40 000 of them, nets of 100² to 280² (4 to 0.5 points a knot cell)

    /usr/bin/python3 bench/scattered_scale.py --interpatch build/release/interpatch \\
        [--against OLD/interpatch] [--rounds 2] [--only tol1e6,net512] [--dir DIR]
"""

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
CASES = {
    "tol1e6": ("pts.npy", {"tolerance": 0.3}),
    "net512": ("pts.npy", {"control_points": [512, 512]}),
    "c100": ("p40k.npy", {"control_points": [100, 100]}),
    "c140": ("p40k.npy", {"control_points": [140, 140]}),
    "c200": ("p40k.npy", {"control_points": [200, 200]}),
    "c280": ("p40k.npy", {"control_points": [280, 280]}),
}


def write_inputs(work: Path) -> None:
    rng = np.random.default_rng(1)
    n = 1_000_000
    x, y = rng.uniform(0, 1000, n), rng.uniform(0, 800, n)
    z = 3 * np.sin(2 * np.pi * x / 400) * np.cos(2 * np.pi * y / 400) + 0.05 * rng.standard_normal(n)
    pts = np.stack([x, y, z], 1)
    np.save(work / "pts.npy", pts)
    np.save(work / "p40k.npy", pts[rng.choice(n, 40000, replace=False)])
    for name, (data, mode) in CASES.items():
        spec = {"type": "approximate", "points": {"npy": data}, "param": "xy", **mode}
        (work / f"{name}.json").write_text(json.dumps(spec))


def run(binary: str, name: str, work: Path) -> tuple[float, float]:
    out = subprocess.run(["/usr/bin/time", "-f", "%e %M", binary, "build", f"{name}.json", "-o", f"{name}.out.json"],
                         cwd=work, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{binary} build {name}.json exited with {out.returncode}: {out.stderr.strip()}")
    seconds, kb = out.stderr.strip().splitlines()[-1].split()
    return float(seconds), float(kb) / 1000


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--interpatch", default=str(REPO / "build/release/interpatch"))
    ap.add_argument("--against", help="a second binary, run in turn with the first")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--only", default=",".join(CASES), help="comma-separated: " + ",".join(CASES))
    ap.add_argument("--dir", type=Path, help="keep the files here (default: a temporary folder)")
    args = ap.parse_args()
    names = [n for n in args.only.split(",") if n]
    for n in names:
        if n not in CASES:
            raise SystemExit(f"unknown case {n}; the cases: {', '.join(CASES)}")
    binaries = [b for b in (args.against, args.interpatch) if b]
    with tempfile.TemporaryDirectory(prefix="scattered_scale_") as tmp:
        work = args.dir or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        write_inputs(work)
        rows = {(n, b): [] for n in names for b in binaries}
        for _ in range(args.rounds):
            for n in names:
                for b in binaries:
                    rows[(n, b)].append(run(b, n, work))
        print("| case | binary | seconds (each round) | peak MB (largest) |")
        print("| --- | --- | ---: | ---: |")
        for n in names:
            for b in binaries:
                r = rows[(n, b)]
                print(f"| {n} | {b} | {', '.join(f'{s:.2f}' for s, _ in r)} | {max(m for _, m in r):.1f} |")


if __name__ == "__main__":
    main()
