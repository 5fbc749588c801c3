#!/usr/bin/env python3
"""The layering docs/architecture.md states, checked on the tree:
- a folder of src/ includes only private headers of its own layer or of the layers
  below it (LAYERS, lowest first); src/mpi/ also the command's own headers (cli/);
- the front ends (cli/, python/src/) and the public headers (include/) include no
  private header: only <interpatch/...>, the standard and external libraries, and a
  front end's own headers;
- every path docs/architecture.md names exists.
tools/check_layers.py [ROOT]; exit status 1 and one line per breach.
tools/check_layers.py --self-test: the check finds breaches planted in a small tree."""
import pathlib, re, subprocess, sys, tempfile

if sys.argv[1:] == ["--self-test"]:
    with tempfile.TemporaryDirectory() as t:
        tree = pathlib.Path(t)
        planted = {"src/base/low.cpp": '#include "io/high.hpp"\n', "src/io/high.hpp": "",
                   "cli/front.cpp": '#include "base/text.hpp"\n', "src/base/text.hpp": "",
                   "include/interpatch/api.hpp": '#include "splines/basis.hpp"\n',
                   "docs/architecture.md": "`src/gone/`\n"}
        for name, text in planted.items():
            (tree / name).parent.mkdir(parents=True, exist_ok=True)
            (tree / name).write_text(text)
        run = subprocess.run([sys.executable, __file__, t], capture_output=True, text=True)
        expected = ["src/base/low.cpp: layer base includes", "cli/front.cpp: includes the private header",
                    "include/interpatch/api.hpp: includes the private header", "names src/gone/"]
        missed = [e for e in expected if e not in run.stdout]
        print(run.stdout, end="")
        if run.returncode != 1 or missed or "4 breaches" not in run.stdout:
            sys.exit(f"the check missed: {missed or 'the count or the exit status'}")
        print("the check finds every planted breach")
        sys.exit(0)

LAYERS = ["base", "linalg", "splines", "blends", "constructions", "locate", "mesh", "io", "mpi"]
root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
src = root / "src"
include = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)
breaches = []


def includes(path):
    return include.findall(path.read_text(encoding="utf-8"))


def sources(folder):
    return [p for p in sorted(folder.rglob("*")) if p.suffix in (".cpp", ".hpp")]


top = [p.name for p in src.iterdir() if p.is_file()]
folders = [p.name for p in src.iterdir() if p.is_dir()]
for name in folders:
    if name not in LAYERS:
        breaches.append(f"src/{name}/: a folder that is not a layer ({', '.join(LAYERS)})")
if len(top) > 4:
    breaches.append(f"src/: {len(top)} files at the top (at most 4): {', '.join(sorted(top))}")

for layer in LAYERS:
    allowed = LAYERS[: LAYERS.index(layer) + 1]
    for path in sources(src / layer):
        for inc in includes(path):
            first = inc.split("/")[0]
            if inc.startswith("interpatch/"):
                continue
            if "/" not in inc:
                # The split run is the command's run under mpirun: it parses and
                # reports through the command's own headers, so it takes and fails alike.
                if layer == "mpi" and (root / "cli" / inc).exists():
                    continue
                if not (path.parent / inc).exists():
                    breaches.append(f"{path.relative_to(root)}: includes \"{inc}\", not beside it")
                continue
            if first not in allowed:
                breaches.append(f"{path.relative_to(root)}: layer {layer} includes \"{inc}\" of a layer above it")

# Headers the build generates for a front end (cmake/*.cmake writes them).
generated = {m for c in (root / "cmake").glob("*.cmake")
             for m in re.findall(r"generated/(\w+\.hpp)", c.read_text(encoding="utf-8"))}

for front in ["cli", "python/src", "include"]:
    for path in sources(root / front):
        for inc in includes(path):
            if inc.startswith("interpatch/"):
                continue
            if front != "include" and "/" not in inc and ((path.parent / inc).exists() or inc in generated):
                continue  # the front end's own header
            breaches.append(f"{path.relative_to(root)}: includes the private header \"{inc}\"")

doc = (root / "docs" / "architecture.md").read_text(encoding="utf-8")
for named in sorted(set(re.findall(r"`((?:src|cli|include|python|tests|tools|cmake|examples|viewer|bench|docs)/[^`\s*]*)`", doc))):
    if "<" in named:  # a pattern such as src/constructions/<name>.cpp: its folder must exist
        named = named[: named.index("<")]
    if not (root / named).exists():
        breaches.append(f"docs/architecture.md names {named}, which does not exist")

for b in breaches:
    print(b)
print(f"{len(breaches)} breaches of the layering")
sys.exit(1 if breaches else 0)
