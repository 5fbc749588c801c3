#!/usr/bin/env python3
"""Files and functions of interpatch's code over the sizes docs/architecture.md
allows: tools/sizes.py [--file N] [--function N] [PATH...] (default src cli python
include, 600 and 100). Function extents come from universal-ctags (Debian package
universal-ctags); lambdas count toward the function that holds them."""
import argparse, pathlib, subprocess, sys

ap = argparse.ArgumentParser()
ap.add_argument("--file", type=int, default=600)
ap.add_argument("--function", type=int, default=100)
ap.add_argument("paths", nargs="*", default=["src", "cli", "python", "include"])
a = ap.parse_args()
files = [p for d in a.paths for p in sorted(pathlib.Path(d).rglob("*"))
         if p.suffix in (".cpp", ".hpp", ".py", ".pyi") and "node_modules" not in p.parts]
over = 0
for p in files:
    n = sum(1 for _ in p.open(encoding="utf-8"))
    if n > a.file:
        print(f"{p}: {n} lines (file)"); over += 1
out = subprocess.run(["ctags", "--fields=+ne", "--kinds-c++=f", "--kinds-python=fm", "-o", "-",
                      *map(str, files)], capture_output=True, text=True, check=True).stdout
for line in out.splitlines():
    name, path, *rest = line.split("\t")
    fields = dict(f.split(":", 1) for f in rest if ":" in f and not f.startswith("/^"))
    if name.startswith("__anon") or "end" not in fields: continue
    n = int(fields["end"]) - int(fields["line"]) + 1
    if n > a.function:
        print(f"{path}:{fields['line']}: {name} {n} lines (function)"); over += 1
print(f"{over} over (files > {a.file}, functions > {a.function} lines)")
sys.exit(1 if over else 0)
