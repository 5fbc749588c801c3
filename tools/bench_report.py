#!/usr/bin/env python3
"""Markdown tables from the Google Benchmark JSON of bench/interpatch_bench.

Usage: tools/bench_report.py build/bench/results.json [--stat median|mean|min] [--time real|cpu]

Reads the aggregates of a run with --benchmark_repetitions (the chosen statistic;
median by default) or, for a run without repetitions, the fastest run of each
benchmark. Prints, for each grid size N, the interpolation time next to a memcpy of
the same bytes (the faster of the one- and the all-thread copy: the bandwidth
limit), their ratio, points per second and the growth t(N)/t(N/2), which is 4 when
the cost is linear in the number of points; then the share of the parameter
computation and the evaluation throughput. Times are wall-clock by default; --time
cpu reports the CPU time of the benchmark thread instead, which measures the work
of a run with OMP_NUM_THREADS=1 even when other processes share the cores.
Standard library only.
"""

import argparse
import json
import sys
from collections import defaultdict

UNIT_SECONDS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def load(path, stat, clock="real"):
    """{(family, arg): {"time": seconds, "cv": fraction or None}}, the run's context and
    whether the chosen aggregate was found (else the fastest run stands in)."""
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"{path}: {e}")
    field = f"{clock}_time"
    aggregate, runs, cvs = {}, defaultdict(list), {}
    for b in doc.get("benchmarks", []):
        if b.get("error_occurred"):
            print(f"warning: {b['name']} failed: {b.get('error_message', '')}", file=sys.stderr)
            continue
        parts = b.get("run_name", b["name"]).split("/")
        try:
            key = (parts[0], int(parts[1]))
        except (IndexError, ValueError):
            continue
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "cv":
                cvs[key] = b[field]  # a fraction, whatever the time unit
            elif b.get("aggregate_name") == stat:
                aggregate[key] = b[field] * UNIT_SECONDS[b.get("time_unit", "ns")]
        else:
            runs[key].append(b[field] * UNIT_SECONDS[b.get("time_unit", "ns")])
    # Without repetitions (or without the chosen aggregate) the fastest run stands in.
    data = {key: {"time": min(ts), "cv": None} for key, ts in runs.items()}
    for key, t in aggregate.items():
        data[key] = {"time": t, "cv": cvs.get(key)}
    return data, doc.get("context", {}), bool(aggregate)


def fmt_time(s):
    if s is None:
        return "–"
    if s >= 1:
        return f"{s:.2f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.3g} ms"
    return f"{s * 1e6:.3g} µs"


def fmt_ratio(a, b, digits=1):
    if a is None or b is None or b == 0:
        return "–"
    return f"{a / b:.{digits}f}"


def fmt_rate(points, s):
    if s is None or s == 0:
        return "–"
    return f"{points / s / 1e6:.1f}"


def get(data, family, arg):
    entry = data.get((family, arg))
    return entry["time"] if entry else None


def best(*ts):
    present = [t for t in ts if t is not None]
    return min(present) if present else None


def context_lines(ctx, stat, clock, aggregated):
    lines = []
    if ctx:
        lines.append(
            f"Run {ctx.get('date', '?')} on {ctx.get('host_name', '?')}: {ctx.get('num_cpus', '?')} CPUs "
            f"at {ctx.get('mhz_per_cpu', '?')} MHz, OpenMP threads {ctx.get('openmp_threads', '?')}, "
            f"load average {', '.join(f'{x:.2f}' for x in ctx.get('load_avg', []))}."
        )
    what = "wall-clock time" if clock == "real" else "CPU time of the benchmark thread"
    chosen = f"{stat} of the repetitions" if aggregated else "fastest run (no repetitions in the file)"
    lines.append(f"Statistic: {chosen}; {what}, the call alone.")
    if clock == "cpu" and str(ctx.get("openmp_threads", "1")) not in ("1", "off"):
        lines.append("Warning: CPU time of one thread undercounts a run with several OpenMP threads.")
    return lines


def interpolation_table(data):
    sizes = sorted(arg for (family, arg) in data if family in ("interpolate_move", "interpolate_copy"))
    sizes = sorted(set(sizes))
    out = [
        "| N | points | moved in | copied in | grid copy | memcpy (1 thr / all) | moved / memcpy "
        "| copied / memcpy | Mpoints/s (moved) | t(N)/t(N/2) moved | t(N)/t(N/2) copied |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    prev = None
    for n in sizes:
        moved, copied = get(data, "interpolate_move", n), get(data, "interpolate_copy", n)
        m1, mt = get(data, "memcpy_grid", n), get(data, "memcpy_grid_mt", n)
        limit = best(m1, mt)
        grow_m = grow_c = "–"
        if prev is not None and prev * 2 == n:
            grow_m = fmt_ratio(moved, get(data, "interpolate_move", prev), 2)
            grow_c = fmt_ratio(copied, get(data, "interpolate_copy", prev), 2)
        out.append(
            f"| {n} | {n * n:,} | {fmt_time(moved)} | {fmt_time(copied)} | {fmt_time(get(data, 'grid_copy', n))} "
            f"| {fmt_time(m1)} / {fmt_time(mt)} | {fmt_ratio(moved, limit)} | {fmt_ratio(copied, limit)} "
            f"| {fmt_rate(n * n, moved)} | {grow_m} | {grow_c} |"
        )
        prev = n
    return out


def parameters_table(data):
    sizes = sorted(arg for (family, arg) in data if family == "grid_parameters")
    out = [
        "| N | grid_parameters (u and v) | interpolation, moved in | share | memcpy of the grid (best) | ratio to memcpy |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for n in sizes:
        par, moved = get(data, "grid_parameters", n), get(data, "interpolate_move", n)
        share = f"{100 * par / moved:.0f} %" if par and moved else "–"
        limit = best(get(data, "memcpy_grid", n), get(data, "memcpy_grid_mt", n))
        out.append(
            f"| {n} | {fmt_time(par)} | {fmt_time(moved)} | {share} | {fmt_time(limit)} | {fmt_ratio(par, limit)} |"
        )
    return out


def evaluation_table(data):
    points = 1000 * 1000
    out = [
        "| call (1000 × 1000 points) | surface | time | Mpoints/s | memcpy of the output (1 thr / all) | ratio |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for family, bytes_per_point in (("evaluate", 24), ("evaluate_derivatives", 144)):
        m1, mt = get(data, "memcpy_eval", bytes_per_point), get(data, "memcpy_eval_mt", bytes_per_point)
        for n in sorted(arg for (f, arg) in data if f == family):
            t = get(data, family, n)
            out.append(
                f"| `{family}` ({bytes_per_point} B/point) | {n} × {n} net | {fmt_time(t)} | {fmt_rate(points, t)} "
                f"| {fmt_time(m1)} / {fmt_time(mt)} | {fmt_ratio(t, best(m1, mt))} |"
            )
    return out


def noise_lines(data):
    cvs = [(entry["cv"], key) for key, entry in data.items() if entry["cv"] is not None]
    if not cvs:
        return []
    worst = max(cvs)
    return [
        f"Largest coefficient of variation over the repetitions: {100 * worst[0]:.0f} % "
        f"({worst[1][0]}/{worst[1][1]})."
    ]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="JSON written with --benchmark_out_format=json")
    parser.add_argument("--stat", default="median", choices=["median", "mean", "min"],
                        help="aggregate to report when the run has repetitions (default: median)")
    parser.add_argument("--time", default="real", choices=["real", "cpu"],
                        help="wall-clock (default) or CPU time of the benchmark thread")
    args = parser.parse_args()
    data, ctx, aggregated = load(args.results, args.stat, args.time)
    if not data:
        sys.exit(f"{args.results}: no interpatch benchmarks found")
    sections = [
        context_lines(ctx, args.stat, args.time, aggregated) + noise_lines(data),
        ["### Bicubic interpolation of N × N grids (chord parameters)", ""] + interpolation_table(data),
        ["### Parameter computation alone", ""] + parameters_table(data),
        ["### Evaluation", ""] + evaluation_table(data),
    ]
    print("\n\n".join("\n".join(s) for s in sections))


if __name__ == "__main__":
    main()
