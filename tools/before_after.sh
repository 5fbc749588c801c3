#!/usr/bin/env bash
# Whole commands of two builds of the command in turn (tools/time_in_turn.py): a
# change that moves code, as the layer restructuring did, is held to the commands
# the users run before and after it. The inputs are made here, the same for both.
#
#   tools/before_after.sh BEFORE_BIN AFTER_BIN WORKDIR [ROUNDS]
set -euo pipefail
before=$(realpath "${1:?usage: before_after.sh BEFORE_BIN AFTER_BIN WORKDIR [ROUNDS]}")
after=$(realpath "${2:?usage}")
work=${3:?usage}
rounds=${4:-11}
here=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
cp "$here"/examples/{network_gordon,network_drawn,coons_volume}.json "$work"/
cd "$work"
/usr/bin/python3 - <<'PY'
import json
import numpy as np

def grid(n, m):
    X, Y = np.meshgrid(np.linspace(0, 10, n), np.linspace(0, 8, m), indexing="ij")
    return np.stack([X, Y, np.sin(X) * np.cos(Y) + 0.1 * X], -1)

for n in (1024, 2048):
    np.save(f"g{n}.npy", grid(n, n))
    json.dump({"type": "interpolate", "points": {"npy": f"g{n}.npy"}}, open(f"i{n}.json", "w"))
t = np.linspace(0, 1, 1024)
side = lambda f: {"interpolate": [[float(c) for c in f(s)] for s in t]}
z0, z1 = lambda s: 0.2 * np.sin(3 * s), lambda s: 0.1 * np.cos(2 * s)
json.dump({"type": "coons", "boundary": {
    "v0": side(lambda s: (s, 0, z0(s))), "v1": side(lambda s: (s, 1, z1(s))),
    "u0": side(lambda s: (0, s, (1 - s) * z0(0) + s * z1(0))),
    "u1": side(lambda s: (1, s, (1 - s) * z0(1) + s * z1(1)))}}, open("coons.json", "w"))
a = np.linspace(0, 1, 128)
U, V, W = np.meshgrid(a, a, a, indexing="ij")
np.save("v128.npy", np.stack([U + 0.1 * V * W, V + 0.05 * U * U, W + 0.1 * np.sin(3 * U)], -1))
json.dump({"type": "interpolate_volume", "points": {"npy": "v128.npy"}}, open("iv128.json", "w"))
g = grid(300, 300)
g[..., 2] += np.random.default_rng(1).normal(0, 0.01, g.shape[:2])
np.save("noisy.npy", g)
json.dump({"type": "approximate", "points": {"npy": "noisy.npy"}, "tolerance": 0.05}, open("approx.json", "w"))
PY
job() {
  echo "== $*"
  /usr/bin/python3 "$here/tools/time_in_turn.py" --rounds "$rounds" before="$before $*" after="$after $*"
}
job eval i1024.json --grid 1000 -o out.npy
job eval coons.json --grid 1000 -o out.npy
job eval network_gordon.json --grid 1000 -o out.npy
job eval network_drawn.json --grid 1000 -o out.npy
job eval iv128.json --grid 200 -o out.npy
job mesh coons_volume.json --res 100x100x100 -o out.vts
job build i2048.json -o out.npz
job build approx.json -o out.json
job info network_gordon.json
