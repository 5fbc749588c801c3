#!/usr/bin/env python3
"""Loads interpatch's .npz exact forms with NumPy's own reader and compares them,
bit for bit, with the .json exact form of the same construction.

    check_npz.py INTERPATCH WORKDIR     build specs to .npz and .json with the command
    check_npz.py --pairs DIR            compare every DIR/X.npz with DIR/X.json

The first form runs `interpatch build SPEC -o X.npz` and `-o X.json` for checked-in
examples (surfaces, a closed one among them, a volume, a grid from a .npy file) and for rational surface and
volume specs it writes into WORKDIR, then `interpatch build` of
{"type": ..., "npz": "X.npz"}, whose .json must equal the first byte for byte. The
second compares archives written by the library itself (with and without ZIP64
records) with their .json. Checked for each archive: zipfile finds every member
stored (not compressed) with a correct CRC-32; numpy.load finds exactly the arrays
degree (int64), knots_u, knots_v[, knots_w], control_points, weights (float64,
only when the .json has weights) and periodic (bool: the .json's "periodic", all
False when it has none), in the shapes of the .json, holding the same doubles. Exits non-zero naming the file and the array.
Needs python3-numpy.
"""
import json
import os
import subprocess
import sys
import zipfile

import numpy as np

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")

RATIONAL_SURFACE = {
    "type": "bspline_surface",
    "degree": [2, 1],
    "knots": {"u": [0, 0, 0, 1, 1, 1], "v": [-1, -1, 2, 2]},
    "control_points": [[[1, 0, 0], [1, 0, 1]], [[1, 1, 0], [1, 1, 1]], [[0, 1, 0], [0, 1, 1]]],
    "weights": [[1, 1], [0.7071067811865476, 0.7071067811865476], [1, 1]],
}
RATIONAL_VOLUME = {
    "type": "bspline_volume",
    "degree": [2, 1, 1],
    "knots": {"u": [0, 0, 0, 1, 1, 1], "v": [0, 0, 1, 1], "w": [0, 0, 1, 1]},
    "control_points": [
        [[[0, 0, 0], [0, 0, 1]], [[0, 1, 0], [0, 1, 1]]],
        [[[1, 0, 0.5], [1, 0, 1.5]], [[1, 1, 0.5], [1, 1, 1.5]]],
        [[[2, 0, 0], [2, 0, 1]], [[2, 1, 0], [2, 1, 1]]],
    ],
    "weights": [[[1, 1], [1, 1]], [[0.5, 2], [0.25, 3]], [[1, 1], [1, 1]]],
}


def fail(path, what):
    sys.exit(f"{path}: {what}")


def run(*args):
    r = subprocess.run(list(args), capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")


def same_doubles(a, b):
    """Equal bit for bit (so -0.0 differs from 0.0, and NaN would equal NaN)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def compare(npz_path, json_path):
    with open(json_path) as f:
        # parse_int=float: "-0" is the double -0.0, not the integer 0.
        exact = json.load(f, parse_int=float)
    volume = exact["type"] == "bspline_volume"
    axes = "uvw" if volume else "uv"
    with zipfile.ZipFile(npz_path) as z:
        for info in z.infolist():
            if info.compress_type != zipfile.ZIP_STORED:
                fail(npz_path, f"member {info.filename} is compressed (method {info.compress_type})")
        bad = z.testzip()  # reads every member and checks its CRC-32
        if bad is not None:
            fail(npz_path, f"member {bad}: CRC-32 mismatch")
    with np.load(npz_path) as a:
        expected = {"degree", "control_points", "periodic"} | {f"knots_{x}" for x in axes}
        if "weights" in exact:
            expected.add("weights")
        if set(a.files) != expected:
            fail(npz_path, f"arrays {sorted(a.files)}, expected {sorted(expected)}")
        dtypes = {"degree": np.int64, "periodic": np.bool_}
        for name in a.files:
            want = dtypes.get(name, np.float64)
            if a[name].dtype != want:
                fail(npz_path, f"{name} has dtype {a[name].dtype}, expected {np.dtype(want)}")
        if a["degree"].tolist() != [int(d) for d in exact["degree"]]:
            fail(npz_path, f"degree {a['degree'].tolist()}, the .json has {exact['degree']}")
        periodic = [bool(p) for p in exact.get("periodic", [False] * len(axes))]
        if a["periodic"].shape != (len(axes),) or a["periodic"].tolist() != periodic:
            fail(npz_path, f"periodic is {a['periodic'].tolist()}, the .json says {periodic}")
        for x in axes:
            if not same_doubles(a[f"knots_{x}"], exact["knots"][x]):
                fail(npz_path, f"knots_{x} differ from the .json's")
        cp = np.array(exact["control_points"], dtype=np.float64)
        if a["control_points"].shape != cp.shape or not same_doubles(a["control_points"], cp):
            fail(npz_path, f"control_points of shape {a['control_points'].shape} differ from the .json's, shape {cp.shape}")
        if "weights" in exact and not same_doubles(a["weights"], np.array(exact["weights"], dtype=np.float64)):
            fail(npz_path, "weights differ from the .json's")


def from_specs(exe, work):
    os.makedirs(work, exist_ok=True)
    specs = [os.path.join(EXAMPLES, f"{n}.json") for n in ("terrain", "hemisphere", "half_cylinder", "annular_sector", "pipe")]
    for name, spec in (("rational_surface", RATIONAL_SURFACE), ("rational_volume", RATIONAL_VOLUME)):
        path = os.path.join(work, f"{name}.json")
        with open(path, "w") as f:
            json.dump(spec, f)
        specs.append(path)
    for spec in specs:
        base = os.path.join(work, os.path.splitext(os.path.basename(spec))[0] + ".exact")
        run(exe, "build", spec, "-o", base + ".npz")
        run(exe, "build", spec, "-o", base + ".json")
        compare(base + ".npz", base + ".json")
        # The archive read back by interpatch gives the same exact form.
        with open(base + ".json") as f:
            kind = json.load(f)["type"]
        back = base + ".back"
        with open(back + ".spec.json", "w") as f:
            json.dump({"type": kind, "npz": os.path.basename(base) + ".npz"}, f)
        run(exe, "build", back + ".spec.json", "-o", back + ".json")
        with open(base + ".json", "rb") as f1, open(back + ".json", "rb") as f2:
            if f1.read() != f2.read():
                fail(back + ".json", f"differs from {base}.json: the .npz did not read back to the same form")
    return len(specs)


def from_pairs(directory):
    pairs = sorted(n[:-4] for n in os.listdir(directory) if n.endswith(".npz"))
    if not pairs:
        sys.exit(f"{directory}: no .npz files")
    for base in pairs:
        compare(os.path.join(directory, base + ".npz"), os.path.join(directory, base + ".json"))
    return len(pairs)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--pairs":
        n = from_pairs(sys.argv[2])
    elif len(sys.argv) == 3:
        n = from_specs(sys.argv[1], sys.argv[2])
    else:
        sys.exit(__doc__)
    print(f"check_npz: {n} archives loaded by numpy {np.__version__} and equal to their .json")


if __name__ == "__main__":
    main()
