#!/usr/bin/env python3
"""Print the end of each failed test's output again, after the whole run.

`ctest -j` prints a failed test's output where the test ended, often hundreds of
lines before the summary; a log read from its end (a CI page) then shows which
tests failed but not why. This reads CTest's record of the last run and repeats,
for every failed test, the last lines of what it printed.

Usage: failed_tests.py BUILD_DIR [LINES]
"""
import os
import re
import sys


def main():
    build = sys.argv[1]
    keep = int(sys.argv[2]) if len(sys.argv) > 2 else 60
    temporary = os.path.join(build, "Testing", "Temporary")
    try:
        with open(os.path.join(temporary, "LastTestsFailed.log")) as f:
            failed = [line.strip().split(":", 1)[1] for line in f if ":" in line]
        with open(os.path.join(temporary, "LastTest.log"), errors="replace") as f:
            log = f.read()
    except OSError as e:
        print(f"failed_tests.py: no record of the last run: {e}")
        return 0
    for name in failed:
        # One block per test: from its "Test: NAME" line to the end of its output.
        block = re.search(r"^\d+/\d+ Test: " + re.escape(name) + r"\n.*?^Output:\n-+\n(.*?)<end of output>",
                          log, re.MULTILINE | re.DOTALL)
        lines = block.group(1).splitlines() if block else ["(its output is not in the record)"]
        print(f"==== {name}: the last {min(keep, len(lines))} of {len(lines)} lines it printed")
        print("\n".join(lines[-keep:]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
