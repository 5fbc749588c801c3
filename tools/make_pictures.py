"""make pictures: the README's pictures of the constructions, made from the viewer
pages `interpatch view` writes, rendered by headless Chromium (tools/viewer_browser.py),
so that they show what the code builds today.

    make_pictures.py INTERPATCH OUT_DIR [NAME ...]

Writes OUT_DIR/view_NAME.png (the 3D view of the page, without its side panel) for
each example of PICTURES, or for the NAMEs given.
"""

import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import viewer_browser as vb  # noqa: E402

EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "examples")

# example -> (colouring, control net shown, what the README says it shows)
PICTURES = {
    "ruled": ("height", True, "a ruled surface between two curves, with its control net"),
    "coons": ("height", False, "a Coons patch from four boundary curves (orange)"),
    "loft_wing": ("height", False, "a wing lofted through six airfoils given from mixed starts and directions (orange)"),
    "network_drawn": ("mean", False, "a Gordon surface through a network of curves drawn freehand, by mean curvature"),
    "pipe": ("gaussian", False, "a closed surface: a bent pipe, by Gaussian curvature"),
    "terrain": ("height", False, "terrain heights interpolated, the survey points in orange"),
    "hermite_patch": ("height", False, "a Hermite patch with its corner frames (S_u red, S_v green)"),
    "coons_volume": ("det_j", False, "a Coons volume from six faces, by det J"),
    "annular_sector": ("det_j", True, "a volume interpolating a 5 x 7 x 3 grid, with its control net"),
}


def main():
    interpatch, out_dir, only = sys.argv[1], sys.argv[2], sys.argv[3:]
    os.makedirs(out_dir, exist_ok=True)
    driver = vb.chromium(width=960, height=540)
    try:
        with tempfile.TemporaryDirectory() as work:
            for name, (colouring, net, caption) in PICTURES.items():
                if only and name not in only:
                    continue
                page = os.path.join(work, name + ".html")
                subprocess.run([interpatch, "view", os.path.join(EXAMPLES, name + ".json"), "-o", page], check=True)
                vb.open_page(driver, page)
                vb.set_colouring(driver, colouring)
                if net:
                    vb.click(driver, "show-net")
                errors = vb.console_errors(driver)
                if errors:
                    sys.exit(f"{name}: the page reports errors: {errors}")
                png = os.path.join(out_dir, f"view_{name}.png")
                vb.view_element(driver).screenshot(png)
                print(f"{png}: {caption}")
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
