#!/usr/bin/env python3
"""Checks that every code example users read is code that is compiled and run.

Every `@code ... @endcode` block of the public headers (include/interpatch/**/*.hpp,
the leading `///` and the common indentation stripped) and every ```cpp block of
README.md must appear as a contiguous run of lines in one of the example programs
examples/cpp/*.cpp, which CTest builds with the project's warnings and runs (a
program not listed in examples/cpp/CMakeLists.txt is an error). Lines
are compared with their whitespace normalised (leading and trailing whitespace
dropped, inner runs of whitespace made one space) and blank lines left out, so
indentation may differ, but nothing else.

Usage: check_snippets.py [SOURCE_DIR]   (default: the directory above tools/)
Exit status 0 when every snippet is found, 1 otherwise, with each missing snippet,
where it is, and how far the closest example got.
"""

import re
import sys
from pathlib import Path


def normalise(line):
    return " ".join(line.split())


def header_snippets(path, text):
    """(place, lines) for each @code block of a header, `///` and indentation stripped."""
    snippets = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        if re.match(r"\s*///\s*@code\b", lines[i]):
            start = i + 1
            body = []
            i += 1
            while i < len(lines) and not re.match(r"\s*///\s*@endcode\b", lines[i]):
                m = re.match(r"\s*///(.*)$", lines[i])
                if not m:
                    raise SystemExit(f"{path}:{i + 1}: a line of a @code block that is not a /// comment")
                body.append(m.group(1))
                i += 1
            if i == len(lines):
                raise SystemExit(f"{path}:{start}: @code without @endcode")
            indent = min((len(l) - len(l.lstrip()) for l in body if l.strip()), default=0)
            snippets.append((f"{path}:{start + 1}", [l[indent:] for l in body]))
        i += 1
    return snippets


def readme_snippets(path, text):
    """(place, lines) for each ```cpp block of a Markdown file."""
    snippets = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].strip() == "```cpp":
            start = i + 1
            i += 1
            body = []
            while i < len(lines) and lines[i].strip() != "```":
                body.append(lines[i])
                i += 1
            if i == len(lines):
                raise SystemExit(f"{path}:{start}: ```cpp without a closing ```")
            snippets.append((f"{path}:{start + 1}", body))
        i += 1
    return snippets


def significant(lines):
    return [n for n in (normalise(l) for l in lines) if n]


def best_match(snippet, programs):
    """(program, lines matched in a row, the first line that differs) of the closest program."""
    best = (None, 0, snippet[0])
    for name, lines in programs.items():
        for start in range(len(lines)):
            k = 0
            while k < len(snippet) and start + k < len(lines) and lines[start + k] == snippet[k]:
                k += 1
            if k == len(snippet):
                return name, k, None
            if k > best[1]:
                best = (name, k, snippet[k])
    return best


def main():
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent
    headers = sorted((root / "include" / "interpatch").rglob("*.hpp"))
    if not headers:
        raise SystemExit(f"no headers under {root / 'include' / 'interpatch'}")
    snippets = []
    for h in headers:
        snippets += header_snippets(h.relative_to(root), h.read_text(encoding="utf-8"))
    readme = root / "README.md"
    snippets += readme_snippets(readme.relative_to(root), readme.read_text(encoding="utf-8"))
    programs = {p.relative_to(root): significant(p.read_text(encoding="utf-8").splitlines())
                for p in sorted((root / "examples" / "cpp").glob("*.cpp"))}
    if not programs:
        raise SystemExit(f"no example programs in {root / 'examples' / 'cpp'}")
    # A program CMake does not know is not compiled: its snippets would count for nothing.
    cmake = (root / "examples" / "cpp" / "CMakeLists.txt").read_text(encoding="utf-8")
    built = {name for names in re.findall(r"set\(INTERPATCH_\w+_EXAMPLES\s+([^)]*)\)", cmake) for name in names.split()}
    unbuilt = [p for p in programs if p.stem not in built]
    for p in unbuilt:
        print(f"{p}: not in a set(INTERPATCH_..._EXAMPLES ...) of examples/cpp/CMakeLists.txt, so not built",
              file=sys.stderr)
    for p in unbuilt:
        del programs[p]

    missing = 0
    for place, lines in snippets:
        snippet = significant(lines)
        if not snippet:
            print(f"{place}: an empty snippet")
            missing += 1
            continue
        program, matched, differing = best_match(snippet, programs)
        if differing is None:
            print(f"{place}: in {program}")
            continue
        missing += 1
        print(f"{place}: in no example program", file=sys.stderr)
        if program is None:
            print(f"  no program has its first line: {differing}", file=sys.stderr)
        else:
            print(f"  closest: {program}, {matched} of {len(snippet)} lines in a row, then it lacks:\n"
                  f"    {differing}", file=sys.stderr)
    print(f"{len(snippets) - missing} of {len(snippets)} snippets found in examples/cpp/*.cpp")
    return 1 if missing or unbuilt else 0


if __name__ == "__main__":
    sys.exit(main())
