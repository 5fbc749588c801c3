#!/usr/bin/env python3
"""Reference values for approximate_test: least-squares surfaces fitted by SciPy's
FITPACK (LSQBivariateSpline), independently of interpatch's fitting code.

Each case is a grid of points with uniform parameters (point (p, q) at
(p / (n - 1), q / (m - 1))), a number of bicubic control points per direction and
optionally weights. The interior knots follow the least-squares rule interpatch
documents (c parameters s spread evenly over the data's order, knot j the mean of
s[j] .. s[j + p - 1], The NURBS Book eq. 9.8); FITPACK fits each coordinate with exactly those knots and the
largest distance |S(u_p, v_q) - Q_pq| over the grid, its place and the root mean
square of the distances are written out with the data.

    /usr/bin/python3 tools/reference/make_approximate_reference.py -o tests/data/approximate_reference.json
"""
import argparse
import json

import numpy as np
from scipy.interpolate import LSQBivariateSpline


def interior_knots(t, p, c):
    # c parameters spread evenly over the data's order (linear between data
    # parameters), interior knots the averages of p consecutive ones.
    n = len(t)
    s = []
    for j in range(c):
        x = j * (n - 1) / (c - 1)
        i = min(int(np.floor(x)), n - 1)
        a = x - i
        s.append((1 - a) * t[i] + a * t[i + 1] if a > 0 else t[i])
    return [sum(s[j:j + p]) / p for j in range(1, c - p)]


def case(name, n, m, c, seed, weighted):
    rng = np.random.default_rng(seed)
    u = np.arange(n) / (n - 1)
    v = np.arange(m) / (m - 1)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    pts = np.stack([2 * uu + 0.01 * rng.normal(size=uu.shape),
                    vv + 0.01 * rng.normal(size=uu.shape),
                    np.sin(3 * uu) * np.cos(2 * vv) + 0.3 * uu * vv + 0.02 * rng.normal(size=uu.shape)], axis=-1)
    weights = rng.uniform(0.5, 2.0, size=uu.shape) if weighted else np.ones(uu.shape)
    tx = interior_knots(u, 3, c[0])
    ty = interior_knots(v, 3, c[1])
    fitted = np.empty_like(pts)
    for k in range(3):
        # FITPACK weighs residuals as (w r)^2: the square root of interpatch's weight.
        s = LSQBivariateSpline(uu.ravel(), vv.ravel(), pts[..., k].ravel(), tx, ty, w=np.sqrt(weights.ravel()),
                               bbox=[0, 1, 0, 1], kx=3, ky=3)
        fitted[..., k] = s.ev(uu.ravel(), vv.ravel()).reshape(uu.shape)
    err = np.linalg.norm(fitted - pts, axis=-1)
    worst = np.unravel_index(np.argmax(err), err.shape)
    out = {"name": name, "shape": [n, m], "degree": [3, 3], "control_points": list(c),
           "knots_u": tx, "knots_v": ty, "points": pts.tolist(),
           "max_error": float(err.max()), "max_error_at": [int(worst[0]), int(worst[1])],
           "rms_error": float(np.sqrt(np.mean(err ** 2)))}
    if weighted:
        out["weights"] = weights.tolist()
        out["weighted_rms_error"] = float(np.sqrt(np.sum(weights * err ** 2) / np.sum(weights)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args()
    cases = [case("plain", 23, 17, (9, 7), 17, False), case("weighted", 19, 26, (8, 11), 18, True)]
    with open(args.output, "w") as f:
        json.dump({"generator": "tools/reference/make_approximate_reference.py", "cases": cases}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
