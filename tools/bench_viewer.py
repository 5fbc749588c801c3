"""make bench-viewer: a 1000 x 1000 surface's viewer page — its size, the time of the
whole `interpatch view` command that writes it and of the library call alone
(io::write_view, through the Python module when it is built), beside `interpatch info` and
`interpatch mesh` of the same grid (tools/time_in_turn.py, in turn), and the time
headless Chromium takes to open and draw it (from the navigation's start until the
page's script has drawn, as the page measures it, performance.now()).

    bench_viewer.py INTERPATCH WORK_DIR [--rounds N]

The targets (docs/BENCHMARKS.md, "Viewer pages"): under 20 MB, open in under 3 s.
"""

import argparse
import os
import statistics
import subprocess
import sys

import numpy

TOOLS = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, TOOLS)
import viewer_browser as vb  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("interpatch")
    ap.add_argument("work")
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    # Terrain-like heights on a 1000 x 1000 grid: a surface interpolating 10^6 points.
    u = numpy.linspace(0, 1, 1000)
    x, y = numpy.meshgrid(u, u, indexing="ij")
    z = 0.1 * numpy.sin(11 * x) * numpy.cos(9 * y) + 0.02 * numpy.sin(57 * x * y) + 0.05 * x * y
    grid = os.path.join(a.work, "grid1000.npy")
    numpy.save(grid, numpy.stack([x, y, z], axis=-1))
    page = os.path.join(a.work, "grid1000.html")
    ip = os.path.abspath(a.interpatch)
    subprocess.run([ip, "view", grid, "-o", page], check=True)
    size = os.path.getsize(page)
    print(f"page: {size} bytes ({size / 1e6:.2f} MB), default resolution (257 x 257 mesh)")

    # The whole commands, in turn: view; info (the build and the check at the data the
    # page's summary also needs); mesh of the same 257 x 257 samples to .obj.
    subprocess.run([sys.executable, os.path.join(TOOLS, "time_in_turn.py"), "--rounds", str(a.rounds),
                    f"view={ip} view {grid} -o {page}",
                    f"info={ip} info {grid}",
                    f"mesh={ip} mesh {grid} --res 257x257 -o {os.path.join(a.work, 'grid1000.obj')}"], check=True)

    # The library call alone (io::write_view through the Python module, whose build
    # and page are those of the command), when the module is built beside INTERPATCH.
    module_dir = os.path.join(os.path.dirname(ip), "python")
    if os.path.isdir(os.path.join(module_dir, "interpatch")):
        sys.path.insert(0, module_dir)
        import time
        import interpatch
        surface = interpatch.build({"type": "interpolate", "points": {"npy": os.path.basename(grid)}}, base_dir=a.work)
        library = []
        for _ in range(a.rounds):
            t0 = time.perf_counter()
            surface.write(os.path.join(a.work, "library.html"))
            library.append(time.perf_counter() - t0)
        print("io::write_view alone (ms): " + ", ".join(f"{1000 * t:.1f}" for t in library) +
              f"; median {1000 * statistics.median(library):.1f}")

    # The most a surface's page holds: --res 1000x1000 is shown at 512 x 512.
    largest = os.path.join(a.work, "grid1000_largest.html")
    subprocess.run([ip, "view", grid, "-o", largest, "--res", "1000x1000"], check=True)
    print(f"page with --res 1000x1000 (shown 512 x 512): {os.path.getsize(largest)} bytes "
          f"({os.path.getsize(largest) / 1e6:.2f} MB)")

    driver = vb.chromium()
    try:
        for label, path in (("default", page), ("--res 1000x1000", largest)):
            times = []
            for _ in range(a.rounds):
                driver.get("about:blank")
                times.append(vb.open_page(driver, path, timeout=60))
                errors = vb.console_errors(driver)
                if errors:
                    sys.exit(f"the page reports errors: {errors}")
            print(f"open and draw in Chromium, {label} (s): " + ", ".join(f"{t:.3f}" for t in times) +
                  f"; median {statistics.median(times):.3f}")
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
