#!/usr/bin/env python3
"""The README's graded duct: the nodes `interpatch eval` places by the sampling of
examples/duct_graded.json, drawn with matplotlib: the duct's floor seen from above,
and the corner at its inner wall where the first cells are 1e-3 long.

tools/graded_duct.py INTERPATCH OUT.png"""
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

cli, out = sys.argv[1], sys.argv[2]
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
spec = os.path.join(root, "examples", "duct_graded.json")
with tempfile.TemporaryDirectory() as tmp:
    subprocess.run([cli, "eval", spec, "--grid", "41x41x61", "-o", os.path.join(tmp, "nodes.npy")], check=True)
    x = np.load(os.path.join(tmp, "nodes.npy"))  # (u across the bend, v up, w along the flow, xyz)
floor = x[:, 0, :, :2]
first = np.linalg.norm(x[1] - x[0], axis=-1)
fig, (whole, near) = plt.subplots(1, 2, figsize=(9.6, 4.8), dpi=110)
for ax in (whole, near):
    for i in range(floor.shape[0]):
        ax.plot(floor[i, :, 0], floor[i, :, 1], color="#1f4e79", lw=0.4)
    for k in range(floor.shape[1]):
        ax.plot(floor[:, k, 0], floor[:, k, 1], color="#1f4e79", lw=0.4)
    ax.set_aspect("equal")
whole.set_title("floor of the duct: 41 x 61 of its 41 x 41 x 61 nodes")
near.set_xlim(0.55, 0.95)
near.set_ylim(0.62, 0.92)
near.set_title(f"at the inner wall: first cells {first.min():.6f} to {first.max():.6f}")
fig.tight_layout()
fig.savefig(out)
print(f"{out}: first cells from {first.min():.6g} to {first.max():.6g}")
