#!/usr/bin/env python3
"""Checks that the umbrella headers list every public header.

interpatch/core.hpp must include every core header (include/interpatch/*.hpp but
the two umbrellas) and no io header; interpatch/interpatch.hpp must include every
public header, directly or through core.hpp. Neither may include a header that
does not exist.

Usage: check_umbrellas.py SOURCE_DIR
"""

import re
import sys
from pathlib import Path

CORE, ALL = "interpatch/core.hpp", "interpatch/interpatch.hpp"


def includes(path):
    return {m.group(1) for m in re.finditer(r'^\s*#\s*include\s*["<](interpatch/[^">]+)[">]', path.read_text(encoding="utf-8"), re.M)}


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    include = Path(sys.argv[1]) / "include"
    headers = {p.relative_to(include).as_posix() for p in (include / "interpatch").rglob("*.hpp")}
    core_headers = {h for h in headers if not h.startswith("interpatch/io/")} - {CORE, ALL}
    io_headers = {h for h in headers if h.startswith("interpatch/io/")}

    core_includes = includes(include / CORE)
    all_includes = includes(include / ALL)
    reached = all_includes | (core_includes if CORE in all_includes else set())

    problems = []
    for h in sorted(core_headers - core_includes):
        problems.append(f"{CORE} does not include {h}")
    for h in sorted(core_includes & io_headers):
        problems.append(f"{CORE} includes the io header {h} (interpatch::core does not link io)")
    for h in sorted((core_headers | io_headers) - reached):
        problems.append(f"{ALL} does not include {h}, directly or through {CORE}")
    for h in sorted((core_includes | all_includes) - headers):
        problems.append(f"an umbrella includes {h}, which is not a public header")
    for p in problems:
        print(p, file=sys.stderr)
    print(f"{len(core_headers)} core and {len(io_headers)} io headers; "
          f"{len(problems)} problem{'s' if len(problems) != 1 else ''}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
