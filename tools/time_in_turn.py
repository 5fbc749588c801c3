#!/usr/bin/env python3
"""Times whole commands in turn, round by round, so that every command sees the same
machine (docs/BENCHMARKS.md: the machine is shared, and its load changes from minute
to minute), and prints the median wall clock, user and system time of each, and each
median's ratio to the first command's, with the median of the rounds' own ratios (each run against the
first command's run of the same round).

    time_in_turn.py [--rounds N] [--json OUT] NAME=COMMAND NAME=COMMAND ...

COMMAND is run by the shell, its output thrown away; a command that fails stops the
run. Each command runs once untimed first, then N rounds (7 by default) of every
command in turn. Wall clock from spawn to exit; user and system time and peak RSS of
the child from wait4 (the child starts as a fork of this script, so its peak RSS is
at least the script's own, about 12 MiB here). --json writes every run's figures.

Example (the "Networks as drawn" section):

    tools/time_in_turn.py --rounds 7 \\
      common='build/release/interpatch eval common.json --grid 1000 -o /tmp/c.npy' \\
      drawn='build/release/interpatch eval drawn.json --grid 1000 -o /tmp/d.npy'
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time


def run(command):
    t0 = time.perf_counter()
    p = subprocess.Popen(command, shell=True, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        sys.exit(f"time_in_turn.py: '{command}' exited with {p.returncode}")
    return {"wall": wall, "user": usage.ru_utime, "sys": usage.ru_stime, "max_rss_kib": usage.ru_maxrss}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--json")
    ap.add_argument("commands", nargs="+", metavar="NAME=COMMAND")
    a = ap.parse_args()
    named = []
    for c in a.commands:
        name, sep, command = c.partition("=")
        if not sep or not name:
            sys.exit(f"time_in_turn.py: '{c}' is not NAME=COMMAND")
        named.append((name, command))
    runs = {name: [] for name, _ in named}
    for _, command in named:
        run(command)  # untimed: files into the page cache, the binary loaded
    load0 = os.getloadavg()
    for _ in range(a.rounds):
        for name, command in named:
            runs[name].append(run(command))
    load1 = os.getloadavg()
    print(f"{a.rounds} rounds in turn; load average {load0[0]:.2f} at the start, {load1[0]:.2f} at the end")
    first = None
    print(f"{'command':<16} {'wall (median)':>14} {'min':>9} {'max':>9} {'user':>9} {'sys':>9} {'ratio':>7} "
          f"{'rounds':>7} {'peak RSS':>10}")
    base = runs[named[0][0]]
    summary = {}
    for name, _ in named:
        r = runs[name]
        wall = statistics.median(x["wall"] for x in r)
        first = first or wall
        summary[name] = {k: statistics.median(x[k] for x in r) for k in ("wall", "user", "sys", "max_rss_kib")}
        summary[name]["ratio_of_medians"] = wall / first
        summary[name]["median_of_ratios"] = statistics.median(x["wall"] / b["wall"] for x, b in zip(r, base))
        print(f"{name:<16} {wall * 1e3:11.1f} ms {min(x['wall'] for x in r) * 1e3:6.1f} ms "
              f"{max(x['wall'] for x in r) * 1e3:6.1f} ms {summary[name]['user'] * 1e3:6.1f} ms "
              f"{summary[name]['sys'] * 1e3:6.1f} ms {wall / first:7.2f} {summary[name]['median_of_ratios']:7.2f} "
              f"{summary[name]['max_rss_kib'] / 1024:7.1f} MiB")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"rounds": a.rounds, "load": [load0, load1], "commands": dict(named), "runs": runs,
                       "median": summary}, f, indent=1)


if __name__ == "__main__":
    main()
