#!/usr/bin/env python3
"""The README's deviation map: how far each surveyed height of examples/
approximate_terrain lies from the surface fitted to it, found by `interpatch project`
(the closest point, not the height at the point's own parameters), drawn with
matplotlib.

tools/deviation_map.py INTERPATCH OUT.png"""
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
spec = os.path.join(root, "examples", "approximate_terrain.json")
grid = np.load(os.path.join(root, "examples", "approximate_terrain.npy")).reshape(-1, 3)
points = grid[~np.isnan(grid).any(axis=1)]  # the void and the lost row: nothing surveyed there
with tempfile.TemporaryDirectory() as tmp:
    np.save(os.path.join(tmp, "survey.npy"), points)
    subprocess.run([cli, "project", spec, os.path.join(tmp, "survey.npy"), "-o", os.path.join(tmp, "dev.npz")],
                   check=True)
    dev = np.load(os.path.join(tmp, "dev.npz"))
    distance, foot = dev["distance"], dev["points"]
# Above or below the surface: the sign of the height difference at the closest point.
signed = np.where(points[:, 2] >= foot[:, 2], distance, -distance)
fig, ax = plt.subplots(figsize=(6.4, 5.2), dpi=110)
lim = float(np.max(np.abs(signed)))
sc = ax.scatter(points[:, 0], points[:, 1], c=signed, cmap="RdBu_r", vmin=-lim, vmax=lim, s=14)
ax.set_aspect("equal")
ax.set_xlabel("x (m)")
ax.set_ylabel("y (m)")
ax.set_title(f"{len(points)} surveyed heights against the fitted surface\n"
             f"largest distance {distance.max():.3f} m (tolerance 0.35 m); rms {np.sqrt(np.mean(distance ** 2)):.3f} m")
fig.colorbar(sc, ax=ax, label="distance to the surface, + above (m)")
fig.tight_layout()
fig.savefig(out)
print(f"{out}: {len(points)} points, largest distance {distance.max():.4f} m")
