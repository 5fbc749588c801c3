#!/usr/bin/env python3
"""Checks that a freshly generated reference file says what the checked-in one says.

    python3 tools/reference/same_reference.py CHECKED_IN.json FRESH.json

Both must have the same structure, the same keys, strings, integers and
booleans, and numbers that agree to 1e-12 of the largest magnitude in the list
that holds them (a number alone is its own scale).

Why not byte for byte: the scripts solve with NumPy/SciPy, whose LAPACK is
whichever BLAS/LAPACK Debian's alternatives point at (the reference libraries,
or OpenBLAS when some package pulls it in). Those sum in different orders, and
the last bits of a solve differ: 5.5e-14 of the scale at worst, measured on
periodic_reference.json between reference LAPACK and OpenBLAS 0.3.21. What this
check guards against is a script changed without regenerating its file, and
such changes move values by far more than 1e-12. The tests compare interpatch
with these files at 1e-12 and wider, for the reasons each script gives.

Exit status 0 when they agree; 1 with the first disagreements printed otherwise.
"""
import json
import math
import sys

RELATIVE = 1e-12  # see above: 18x the largest difference two LAPACKs gave


def compare(a, b, path, scale, problems):
    if len(problems) >= 10:
        return
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, (str, type(None))):
        if a != b or type(a) is not type(b):
            problems.append(f"{path}: {a!r} against {b!r}")
    elif isinstance(a, dict):
        if not isinstance(b, dict) or list(a) != list(b):
            problems.append(f"{path}: keys {sorted(a)} against "
                            f"{sorted(b) if isinstance(b, dict) else type(b).__name__}")
            return
        for key in a:
            compare(a[key], b[key], f"{path}/{key}", 0.0, problems)
    elif isinstance(a, list):
        if not isinstance(b, list) or len(a) != len(b):
            problems.append(f"{path}: a list of {len(a)} against "
                            f"{len(b) if isinstance(b, list) else type(b).__name__}")
            return
        numbers = [abs(x) for x in a if isinstance(x, (int, float)) and not isinstance(x, bool)]
        inner = max(numbers, default=0.0)
        for i, (x, y) in enumerate(zip(a, b)):
            compare(x, y, f"{path}/{i}", inner, problems)
    elif isinstance(a, int):
        if not isinstance(b, int) or isinstance(b, bool) or a != b:
            problems.append(f"{path}: {a!r} against {b!r}")
    elif isinstance(a, float):
        if not isinstance(b, (int, float)) or isinstance(b, bool):
            problems.append(f"{path}: {a!r} against {b!r}")
            return
        if math.isnan(a) or math.isnan(b):
            if not (math.isnan(a) and math.isnan(b)):
                problems.append(f"{path}: {a!r} against {b!r}")
            return
        bound = RELATIVE * max(scale, abs(a))
        if abs(a - b) > bound:
            problems.append(f"{path}: {a!r} against {b!r} (differ by {abs(a - b):.3g}, "
                            f"allowed {bound:.3g})")
    else:
        problems.append(f"{path}: unexpected {type(a).__name__}")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        checked_in = json.load(f)
    with open(sys.argv[2]) as f:
        fresh = json.load(f)
    problems = []
    compare(checked_in, fresh, "", 0.0, problems)
    if problems:
        print(f"{sys.argv[1]} and {sys.argv[2]} disagree:", *problems, sep="\n  ")
        sys.exit(1)


if __name__ == "__main__":
    main()
