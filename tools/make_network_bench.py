#!/usr/bin/env python3
"""Prints a curve-network spec for the benchmark "Networks as drawn against common
parameters" of docs/BENCHMARKS.md. bench/bench_interpolate.cpp builds the same networks
in memory for the library's benchmark (`bench_network`, timed by `network_as_drawn`),
with random stations of its own.

    make_network_bench.py SEED U_CURVES V_CURVES POINTS [drawn|common|shuffle] > spec.json

Every curve interpolates POINTS points of the smooth surface

    f(u, v) = (4u, 3v + 0.3 sin 3u, sin 2.5u cos 1.7v + 0.4uv),   (u, v) in [0, 1]^2:

u_curves[j] runs through f(t, v_j) at v_j = j / (U_CURVES - 1), v_curves[i] through
f(u_i, t) at u_i = i / (V_CURVES - 1), at stations t from 0 to 1.

- drawn (the default): uneven stations, the ends, every node (the u_i along a
  u-curve, the v_j along a v-curve) and random ones, POINTS in all; u-curves with
  "param": "chord", v-curves with "centripetal". The curves pass through the nodes,
  but at parameters that differ from curve to curve, so the network must find its
  crossings and re-express the curves (the u-curves on shared knots, the v-curves
  each on knots of its own).
- common: POINTS equally spaced stations and "param": "uniform". The nodes must be
  stations, (POINTS - 1) a multiple of U_CURVES - 1 and of V_CURVES - 1 (15 x 15
  curves: POINTS = 35 * 14 + 1 = 491, say); the curves then cross at the common
  parameters, as given.
- shuffle: drawn, the families in random order and every other curve reversed
  (u_curves[0], [2], ... and v_curves[1], [3], ... as listed).

SEED makes the random stations and the shuffle; the same arguments print the same
spec. The spec names no method: gordon, the default.

Example (the benchmark's three specs):

    python3 tools/make_network_bench.py 2 15 15 500 > drawn.json
    python3 tools/make_network_bench.py 2 15 15 491 common > common.json
    python3 tools/make_network_bench.py 2 15 15 500 shuffle > shuffled.json
"""
import json
import math
import random
import sys


def f(u, v):
    return [4 * u, 3 * v + 0.3 * math.sin(3 * u), math.sin(2.5 * u) * math.cos(1.7 * v) + 0.4 * u * v]


def usage(message):
    sys.exit(f"make_network_bench.py: {message}\n"
             "usage: make_network_bench.py SEED U_CURVES V_CURVES POINTS [drawn|common|shuffle]")


def main(argv):
    if len(argv) not in (5, 6):
        usage("expected 4 or 5 arguments")
    try:
        seed, n_u, n_v, points = (int(a) for a in argv[1:5])
    except ValueError:
        usage("SEED, U_CURVES, V_CURVES and POINTS are integers")
    mode = argv[5] if len(argv) == 6 else "drawn"
    if mode not in ("drawn", "common", "shuffle"):
        usage(f"unknown mode '{mode}'")
    if n_u < 2 or n_v < 2:
        usage("at least 2 curves a family")
    rng = random.Random(seed)
    v_nodes = [j / (n_u - 1) for j in range(n_u)]  # where the u-curves lie
    u_nodes = [i / (n_v - 1) for i in range(n_v)]  # where the v-curves lie

    if mode == "common":
        for k in (n_u, n_v):
            if (points - 1) % (k - 1) != 0:
                usage(f"common: POINTS - 1 = {points - 1} is not a multiple of {k - 1}, the nodes would not be stations")
        stations = [k / (points - 1) for k in range(points)]
        u_curves = [{"interpolate": [f(t, v) for t in stations], "param": "uniform"} for v in v_nodes]
        v_curves = [{"interpolate": [f(u, t) for t in stations], "param": "uniform"} for u in u_nodes]
    else:
        def stations(nodes):
            s = set([0.0, 1.0] + nodes)
            if points < len(s):
                usage(f"POINTS must be at least the {len(s)} nodes")
            while len(s) < points:
                s.add(rng.random())
            return sorted(s)

        u_curves = [{"interpolate": [f(t, v) for t in stations(u_nodes)], "param": "chord"} for v in v_nodes]
        v_curves = [{"interpolate": [f(u, t) for t in stations(v_nodes)], "param": "centripetal"} for u in u_nodes]
        if mode == "shuffle":
            rng.shuffle(u_curves)
            rng.shuffle(v_curves)
            for c in u_curves[::2]:
                c["interpolate"].reverse()
            for c in v_curves[1::2]:
                c["interpolate"].reverse()

    print(json.dumps({"type": "network", "u_curves": u_curves, "v_curves": v_curves}))


if __name__ == "__main__":
    main(sys.argv)
