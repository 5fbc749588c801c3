#!/usr/bin/python3
"""Plot and tabulate bench/compare's JSON (interpatch, OpenCASCADE, SISL, memcpy).

    python3 tools/plot_bench.py build/bench/compare.json [-o docs/bench_interpolation.png]

Draws interpolation time against N (log-log) for each library next to the memcpy of
the same bytes, and a second panel with the evaluation, Coons and whole-process jobs;
prints the Markdown tables of docs/BENCHMARKS.md, among them the whole processes of
every construction against the pure-I/O program (the "processes" key). Needs
python3-matplotlib (Debian).
"""

import argparse
import json
import math
import sys

from bench_report import fmt_time  # the same time format as the Google Benchmark tables

LIBS = ("interpatch", "occt", "sisl", "memcpy")
NAMES = {"interpatch": "interpatch", "occt": "OpenCASCADE", "sisl": "SISL", "memcpy": "memcpy", "pure_io": "pure I/O"}
COLORS = {"interpatch": "tab:blue", "occt": "tab:red", "sisl": "tab:green", "memcpy": "tab:gray"}


def fmt_ratio(r):
    return "–" if r is None else f"{r:.3g}"


def best(rows, **match):
    """The fastest matching row (by median), or None."""
    found = [r for r in rows if all(r.get(k) == v for k, v in match.items())]
    return min(found, key=lambda r: r["median_s"]) if found else None


def median_of(row):
    return None if row is None else row["median_s"]


def ratio(a, b):
    return None if a is None or b is None or b == 0 else a / b


def interpolation_table(rows, skipped, threads):
    sizes = sorted({r["n"] for r in rows if r["job"] == "interpolate"})
    t_hi = max(threads)
    head = ["N", "points", "interpatch 1 thr (copied in)", "interpatch 1 thr (moved in)"]
    if t_hi > 1:
        head += [f"interpatch {t_hi} thr (copied in)", f"interpatch {t_hi} thr (moved in)"]
    # Ratios against interpatch's fastest variant; memcpy copies input + output bytes.
    head += ["SISL", "OpenCASCADE", "memcpy", "interpatch / memcpy", "SISL / interpatch", "OpenCASCADE / interpatch"]
    out = ["| " + " | ".join(head) + " |", "|" + "---:|" * len(head)]
    for n in sizes:
        sel = [r for r in rows if r["job"] == "interpolate" and r["n"] == n]
        ip1 = median_of(best(sel, library="interpatch", threads=1, variant="interpolate_surface, copied in"))
        ip1m = median_of(best(sel, library="interpatch", threads=1, variant="interpolate_surface, moved in"))
        ipn = median_of(best(sel, library="interpatch", threads=t_hi, variant="interpolate_surface, copied in"))
        ipnm = median_of(best(sel, library="interpatch", threads=t_hi, variant="interpolate_surface, moved in"))
        known = [x for x in (ip1, ip1m, ipn, ipnm) if x is not None]
        ip = min(known) if known else None
        sisl = median_of(best(sel, library="sisl"))
        occt = median_of(best(sel, library="occt"))
        mem = median_of(best(sel, library="memcpy"))
        skip = next((s for s in skipped if s["job"] == "interpolate" and s["n"] == n and s["library"] == "occt"), None)
        cells = [f"{n}", f"{n * n:,}", fmt_time(ip1), fmt_time(ip1m)]
        if t_hi > 1:
            cells += [fmt_time(ipn), fmt_time(ipnm)]
        cells += [fmt_time(sisl), "skipped" if skip else fmt_time(occt), fmt_time(mem), fmt_ratio(ratio(ip, mem)),
                  fmt_ratio(ratio(sisl, ip)), fmt_ratio(ratio(occt, ip))]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def jobs_table(rows):
    head = ["job", "N", "library", "what is timed", "threads", "median", "parts (median)", "/ memcpy", "/ interpatch", "check"]
    out = ["| " + " | ".join(head) + " |", "|---|---:|---|---|---:|---:|---|---:|---:|---|"]
    for job in ("evaluate", "coons", "process"):
        sel = [r for r in rows if r["job"] == job]
        if not sel:
            continue
        mem = median_of(best(sel, library="memcpy"))
        ip = median_of(best(sel, library="interpatch"))
        for r in sel:
            if r["library"] == "memcpy" and r is not best(sel, library="memcpy"):
                continue
            parts = ", ".join(f"{k} {fmt_time(v)}" for k, v in r["parts_median_s"].items())
            if "maxrss_bytes" in r:
                parts = (parts + ", " if parts else "") + f"peak RSS {r['maxrss_bytes'] / 2**20:.0f} MiB"
            check = "ok" if r["check_ok"] else "FAILED"
            if r["library"] != "memcpy":
                check += f" ({r['check_max_rel_error']:.1e})"
            out.append("| " + " | ".join([job, str(r["n"]), NAMES[r["library"]], r["variant"].replace("|", "\\|"),
                                          str(r["threads"]), fmt_time(r["median_s"]), parts or "–",
                                          fmt_ratio(ratio(r["median_s"], mem)), fmt_ratio(ratio(r["median_s"], ip)),
                                          check]) + " |")
    return "\n".join(out)


def memory_table(memory):
    head = ["N", "library", "threads", "extra memory of the call", "input + output (2 × N² × 24 B)", "extra / (input + output)",
            "peak RSS of the process"]
    out = ["| " + " | ".join(head) + " |", "|---:|---|---:|---:|---:|---:|---:|"]
    for m in memory:
        out.append(f"| {m['n']} | {m['library']} | {m['threads']} | {m['extra_bytes'] / 2**20:,.0f} MiB | "
                   f"{m['io_bytes'] / 2**20:,.0f} MiB | {m['extra_over_io']:.2f} | {m['peak_bytes'] / 2**20:,.0f} MiB |")
    return "\n".join(out)


def scaling_table(scaling):
    """The alternated runs of N and 2N (bench/compare's measure_scaling)."""
    head = ["N → 2N", "threads", "rounds", "t(N × N), median", "t(2N × 2N), median", "ratio of the medians",
            "median of the rounds' ratios", "check"]
    out = ["| " + " | ".join(head) + " |", "|---|---:|---:|---:|---:|---:|---:|---|"]
    for s in scaling:
        out.append(f"| {s['n']} → {s['n_large']} | {s['threads']} | {s['rounds']} | {fmt_time(s['median_s'])} | "
                   f"{fmt_time(s['median_large_s'])} | {s['ratio_of_medians']:.2f} | {s['median_of_ratios']:.2f} | "
                   f"{'ok' if s['check_ok'] else 'FAILED'} |")
    return "\n".join(out)


def fmt_mib(b):
    return "–" if b is None else f"{b / 2**20:,.1f} MiB" if b < 10 * 2**20 else f"{b / 2**20:,.0f} MiB"


def processes_table(processes):
    """Whole processes of every construction (bench/compare's --jobs processes): each
    interpatch command against the pure-I/O program of the same bytes, and SISL's."""
    head = ["job", "interpatch command", "input + output", "interpatch", "pure I/O", "SISL",
            "interpatch / pure I/O (target ≤ 2)", "SISL / interpatch", "peak RSS: interpatch / pure I/O / SISL",
            "interpatch peak RSS / (input + output)", "check"]
    out = ["| " + " | ".join(head) + " |", "|---|---|---:|---:|---:|---:|---:|---:|---|---:|---|"]
    for p in processes:
        if "failed" in p:
            out.append(f"| {p['job']} | {p['what']} | – | failed: {p['failed']} |" + " – |" * 6 + " FAILED |")
            continue
        ip, io, sisl = p["interpatch"], p["pure_io"], p["sisl"]
        side = lambda s, key: None if s is None else s[key]
        rss = " / ".join(fmt_mib(side(s, "maxrss_bytes")) for s in (ip, io, sisl) if s is not None)
        rss_ratio = f"{p['rss_over_io']:.2f}"
        if p.get("target_rss_over_io") is not None:
            rss_ratio += f" (target ≤ {p['target_rss_over_io']:g})"
        check = "ok" if p["check_ok"] else "FAILED"
        check += f" ({ip['check_max_rel_error']:.1e})"
        notes = "; ".join(s["note"] for s in (ip, io, sisl) if s is not None and s["note"])
        out.append("| " + " | ".join([
            p["job"], ip["variant"].removeprefix("interpatch ").replace("|", "\\|"),
            fmt_mib(p["input_bytes"] + p["output_bytes"]), fmt_time(ip["median_s"]), fmt_time(side(io, "median_s")),
            fmt_time(side(sisl, "median_s")), fmt_ratio(p["interpatch_over_pure_io"]), fmt_ratio(p["sisl_over_interpatch"]),
            rss, rss_ratio, check + (f"; {notes}" if notes else "")]) + " |")
    out.append("")
    for job in dict.fromkeys(p["job"] for p in processes):
        what = next(p["what"] for p in processes if p["job"] == job)
        out.append(f"- **{job}**: {what}")
    return "\n".join(out)


def agreement_table(agreement):
    out = ["| job | N | compared | max deviation / diagonal | why they differ |", "|---|---:|---|---:|---|"]
    for a in agreement:
        out.append(f"| {a['job']} | {a['n']} | {a['what']} | {a['max_rel_deviation']:.2e} | {a['note']} |")
    return "\n".join(out)


def plot(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = data["rows"]
    threads = data["meta"]["threads"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2))
    series = [("interpatch", {"threads": 1, "variant": "interpolate_surface, copied in"}, "interpatch, 1 thread", "-")]
    if max(threads) > 1:
        series.append(("interpatch", {"threads": max(threads), "variant": "interpolate_surface, copied in"},
                       f"interpatch, {max(threads)} threads", "--"))
    series += [("sisl", {}, "SISL s1537 (+ parameters)", "-"), ("occt", {}, "OpenCASCADE PointsToBSplineSurface", "-"),
               ("memcpy", {}, "memcpy of input + output bytes", ":")]
    sizes = sorted({r["n"] for r in rows if r["job"] == "interpolate"})
    for lib, match, label, style in series:
        xs, ys = [], []
        for n in sizes:
            r = best([r for r in rows if r["job"] == "interpolate" and r["n"] == n], library=lib, **match)
            if r:
                xs.append(n * n)
                ys.append(r["median_s"])
        if xs:
            ax1.loglog(xs, ys, style, marker="o", color=COLORS[lib], label=label)
    ax1.set_xlabel("points (N × N)")
    ax1.set_ylabel("wall-clock time, median [s]")
    ax1.set_title("Bicubic interpolation of N × N grids")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=8)

    jobs = [("evaluate", "evaluate\n10⁶ points"), ("coons", "Coons patch\nbuild + 10⁶ points"),
            ("process", "whole process\n`eval`, .npy in/out")]
    width = 0.2
    tallest = 0.0
    for k, lib in enumerate(LIBS):
        xs, ys = [], []
        for j, (job, _) in enumerate(jobs):
            r = best([r for r in rows if r["job"] == job], library=lib)
            if r:
                xs.append(j + (k - 1.5) * width)
                ys.append(r["median_s"])
        if xs:
            ax2.bar(xs, ys, width, color=COLORS[lib], label=NAMES[lib] + (" (fastest variant)" if lib == "interpatch" else ""))
            tallest = max([tallest] + ys)
            for x, y in zip(xs, ys):
                ax2.text(x, y * 1.08, fmt_time(y), ha="center", va="bottom", fontsize=6.5, rotation=90)
    ax2.set_yscale("log")
    ax2.set_ylim(top=tallest * 20)  # room for the labels above the bars
    ax2.set_xticks(range(len(jobs)))
    ax2.set_xticklabels([label for _, label in jobs], fontsize=8)
    ax2.set_ylabel("wall-clock time, median [s]")
    ax2.set_title("Evaluation, Coons patch, whole process")
    ax2.grid(True, axis="y", which="both", alpha=0.3)
    ax2.legend(fontsize=8)
    meta = data["meta"]
    fig.suptitle(f"interpatch {meta['interpatch_commit']} vs OpenCASCADE {meta['occt_version']} and SISL "
                 f"{meta['sisl_version']} — {meta['cpu']}, {meta['nproc']} CPUs, {meta['date'][:10]}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json", help="bench/compare's --json output")
    ap.add_argument("-o", "--output", default="docs/bench_interpolation.png", help="the figure (PNG)")
    ap.add_argument("--no-plot", action="store_true", help="print the tables only")
    args = ap.parse_args()
    with open(args.json) as f:
        data = json.load(f)
    meta, rows = data["meta"], data["rows"]
    print(f"Run {meta['date']} on {meta['cpu']}: {meta['nproc']} CPUs at {meta['mhz']} MHz, "
          f"load average {', '.join(meta['load_average'].split()[:3])} at the start, "
          f"{', '.join(meta['load_average_end'].split()[:3])} at the end.")
    print(f"interpatch {meta['interpatch_commit']}, OpenCASCADE {meta['occt_version']}, SISL {meta['sisl_version']}, "
          f"g++ {meta['compiler']}; OpenMP threads {meta['threads']} (OMP_PROC_BIND={meta['omp_proc_bind'] or 'unset'}); "
          f"median of {meta['reps']} repetitions, wall clock.\n")
    print("### Bicubic interpolation of N × N grids\n")
    print(interpolation_table(rows, data["skipped"], meta["threads"]) + "\n")
    if data.get("scaling"):
        print("### Linear cost: N × N and 2N × 2N grids interpolated in turn\n")
        print(scaling_table(data["scaling"]) + "\n")
    print("### Evaluation, Coons patch, whole process\n")
    print(jobs_table(rows) + "\n")
    if data.get("processes"):
        print("### Whole processes of every construction against pure I/O of the same bytes\n")
        print(processes_table(data["processes"]) + "\n")
    if data["memory"]:
        print("### Peak memory of one interpolation\n")
        print(memory_table(data["memory"]) + "\n")
    if data["agreement"]:
        print("### How far the libraries' surfaces are from interpatch's\n")
        print(agreement_table(data["agreement"]) + "\n")
    for s in data["skipped"]:
        print(f"- skipped: {s['job']} N = {s['n']}, {NAMES.get(s['library'], s['library'])}: {s['reason']}")
    failed = [r for r in rows if not r["check_ok"]]
    for r in failed:
        print(f"- CHECK FAILED: {r['job']} {r['n']} {r['library']} {r['variant']}: {r['check_max_rel_error']:.3g}")
    for p in data.get("processes", []):
        if "failed" in p:
            print(f"- FAILED: {p['job']}: {p['failed']}")
            failed.append(p)
    if not args.no_plot:
        plot(data, args.output)
        print(f"\nwrote {args.output}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
