"""The viewer pages `interpatch view` writes, opened in headless Chromium (CTest:
viewer_browser_*): a surface, a network, a volume and a large grid.

    check_viewer.py INTERPATCH EXAMPLES_DIR WORK_DIR CASE

For the case's page: it loads with no console error and makes no network request;
the canvas is drawn where the model is; showing the control net and changing the
colouring (and, for a volume, showing a slice) change the picture; the summary
panel holds the same numbers as `interpatch info` on the same spec, shown to 4
significant digits with every digit in the cell's title (on hover).
"""

import json
import math
import os
import re
import subprocess
import sys

import numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import viewer_browser as vb  # noqa: E402


def large_grid(work):
    """A 400 x 400 grid of terrain-like points as .npy (a data file given directly)."""
    u = numpy.linspace(0, 1, 400)
    x, y = numpy.meshgrid(u, u, indexing="ij")
    z = 0.15 * numpy.sin(9 * x) * numpy.cos(7 * y) + 0.05 * numpy.sin(31 * x * y)
    path = os.path.join(work, "large_grid.npy")
    numpy.save(path, numpy.stack([x, y, z], axis=-1))
    return path


def far_small(work):
    """The hyperbolic paraboloid of examples/bilinear.json made 1 mm across and moved
    1e8 from the origin: in float32 its corners would be one point."""
    def corner(x, y, z):
        return [1e8 + 1e-3 * x, -2e8 + 1e-3 * y, 3e8 + 1e-3 * z]
    spec = {"type": "bilinear", "p00": corner(0, 0, 1), "p01": corner(1, 1, 1),
            "p10": corner(1, 0, 0), "p11": corner(0, 1, 0)}
    path = os.path.join(work, "far_small.json")
    with open(path, "w") as f:
        json.dump(spec, f)
    return path


def cases(examples, work):
    """name -> (input, extra arguments of `interpatch view`, colourings to try)."""
    return {
        "surface": (os.path.join(examples, "coons.json"), [], ["height", "gaussian", "mean"]),
        "network": (os.path.join(examples, "network_drawn.json"), [], ["height", "mean"]),
        "volume": (os.path.join(examples, "coons_volume.json"), [], ["det_j", "height"]),
        # A grid larger than a page holds: its data points and control net shown
        # decimated (256 x 256 of 400 x 400), never refused. (The mesh at its default
        # 257 x 257: SwiftShader draws a 512 x 512 mesh in seconds, on a busy machine
        # tens of them, for each of the pictures compared here.)
        "large_grid": (None, [], ["height", "gaussian"]),
        "far_small": (far_small(work), [], ["height", "gaussian"]),
    }


def lookup(info, key):
    value = info
    for part in key.split("."):
        value = value[part]
    return value


def readable(text, value):
    """text is value to 4 significant digits (at most 4 digits, within half a unit of the last)."""
    try:
        shown = float(text)
    except ValueError:
        return False
    mantissa = re.sub(r"e.*$", "", text).lstrip("-").replace(".", "").lstrip("0")
    last = 10.0 ** (math.floor(math.log10(abs(value))) - 3)
    return len(mantissa) <= 4 and abs(shown - value) <= 0.5 * last * (1 + 1e-9)


def main():
    interpatch, examples, work, case = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    spec, extra, colourings = cases(examples, work)[case]
    if spec is None and case == "large_grid":
        spec = large_grid(work)
    page = os.path.join(work, case + ".html")
    subprocess.run([interpatch, "view", spec, "-o", page, *extra], check=True)
    info = json.loads(subprocess.run([interpatch, "info", spec], check=True, capture_output=True, text=True).stdout)
    failures = []

    def expect(ok, what):
        if not ok:
            failures.append(what)

    # A small window: fewer pixels to read back and compare, the model still hundreds wide.
    driver = vb.chromium(width=900, height=600)
    try:
        vb.open_page(driver, page, timeout=60)
        expect(not vb.console_errors(driver), f"console errors: {vb.console_errors(driver)}")
        expect(not vb.requests(driver, page), f"network requests: {vb.requests(driver, page)}")

        # The model fills the middle of the view: most of the central region is drawn
        # (a quarter is far below any model seen whole, far above stray lines).
        first = vb.canvas_pixels(driver)
        w, h = first[:2]
        middle = vb.drawn_fraction(first, (w // 3, h // 3, 2 * w // 3, 2 * h // 3))
        expect(middle > 0.25, f"the middle of the canvas is {middle:.0%} drawn")
        expect(vb.drawn_fraction(first) < 0.95, "the whole canvas is drawn over: no background left")

        # Each change must alter at least 0.2% of the pixels: the control net of the
        # smallest example (a 2 x 2 x 2 net's 12 lines) covers more than that.
        if info.get("exact_form"):
            vb.click(driver, "show-net")
            with_net = vb.canvas_pixels(driver)
            expect(vb.changed_fraction(first, with_net) > 0.002, "showing the control net changed nothing")
            vb.click(driver, "show-net")
            expect(vb.changed_fraction(first, vb.canvas_pixels(driver)) < 0.002,
                   "hiding the control net again did not give the first picture back")
        before = vb.canvas_pixels(driver)
        for name in colourings[1:]:
            vb.set_colouring(driver, name)
            after = vb.canvas_pixels(driver)
            expect(vb.changed_fraction(before, after) > 0.002, f"colouring by {name} changed nothing")
            before = after
        if case == "volume":
            vb.click(driver, "show-faces")
            vb.click(driver, "slice-u-on")
            sliced = vb.canvas_pixels(driver)
            expect(vb.changed_fraction(before, sliced) > 0.002, "a slice in place of the faces changed nothing")
            expect(vb.drawn_fraction(sliced) > 0.01, "the slice is not drawn")
        expect(not vb.console_errors(driver), f"console errors after the changes: {vb.console_errors(driver)}")

        # The summary: the numbers `interpatch info` prints, exactly.
        panel = vb.info_panel(driver)
        for key in ("type", "degree", "control_points"):
            expect(key in panel, f"the summary has no {key}")
        if info["max_data_error"] is not None:
            expect("max_data_error.absolute" in panel, "the summary has no error at the data")
        if "jacobian" in info:
            expect("jacobian.inverted_cells" in panel, "the summary has no inverted cells")
        for key, value in panel.items():
            if key == "warnings":
                expect(value == ("; ".join(info["warnings"]) or "none"), f"warnings: {value!r}")
            elif key == "max_data_error":
                expect(info["max_data_error"] is None, "the summary says there are no data points")
            else:
                expect(lookup(info, key) == value, f"{key}: the page says {value!r}, interpatch info {lookup(info, key)!r}")
        # As read: counts whole, other numbers to 4 significant digits, every digit on hover.
        rounded = 0
        for key, (text, title) in vb.info_shown(driver).items():
            value = panel[key]
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                continue
            if isinstance(value, int) or value.is_integer():
                expect(text == str(int(value)) and title is None, f"{key}: {value!r} shown as {text!r} (title {title!r})")
                continue
            expect(readable(text, value), f"{key}: {value!r} shown as {text!r}, not to 4 significant digits")
            if readable(text, value) and float(text) != value:
                rounded += 1
                expect(title is not None and float(title) == value, f"{key}: the title {title!r} is not {value!r}")
        expect(rounded > 0, "no number of the summary is rounded: nothing to check the formatting on")
    finally:
        driver.quit()
    for f in failures:
        print(f"{case}: {f}", file=sys.stderr)
    if failures:
        sys.exit(1)
    print(f"{case}: page {os.path.getsize(page)} bytes; console, requests, drawing, toggles and summary as expected")


if __name__ == "__main__":
    main()
