"""Viewer pages in a real browser: Debian's Chromium, headless, WebGL through
SwiftShader, driven by Selenium (python3-selenium, chromium-driver).

Shared by the browser tests (tools/check_viewer.py), the pictures of the README
(tools/make_pictures.py) and the page benchmark (tools/bench_viewer.py).
"""

import json
import os
import shutil

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

# The page's background, 0x20232a (viewer/src/viewer.js, colours.background).
BACKGROUND = (0x20, 0x23, 0x2A)


def chromium(width=1100, height=800):
    """A headless Chromium whose console and network events can be read back."""
    options = Options()
    for binary in ("/usr/bin/chromium", "/usr/lib/chromium/chromium"):
        if os.path.exists(binary):
            options.binary_location = binary
            break
    for flag in ("--headless=new", "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--no-sandbox", "--disable-dev-shm-usage", "--hide-scrollbars", "--mute-audio",
                 "--no-first-run", "--disable-extensions", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--disable-default-apps",
                 f"--window-size={width},{height}", "--force-device-scale-factor=1"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    driver_path = shutil.which("chromedriver") or "/usr/bin/chromedriver"
    return webdriver.Chrome(service=Service(driver_path), options=options)


def open_page(driver, path, timeout=30):
    """Loads a page from file:// and waits until its script says it has drawn.
    Returns the seconds from the navigation's start to that moment, as the page
    measured them (performance.now() once drawn)."""
    driver.get("file://" + os.path.abspath(path))
    WebDriverWait(driver, timeout, poll_frequency=0.05).until(
        lambda d: d.execute_script("return document.body && document.body.dataset.ready === 'true'"))
    return float(driver.execute_script("return document.body.dataset.readyMs")) / 1000


def console_errors(driver):
    """The console's messages of level SEVERE (errors, uncaught exceptions)."""
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def requests(driver, page_path):
    """Every network request the page made, from the DevTools protocol's events and
    the page's resource timing: URLs other than the page itself (data: URLs, which
    hold the page's own modules, are not requests)."""
    page = "file://" + os.path.abspath(page_path)
    urls = []
    for entry in driver.get_log("performance"):
        message = json.loads(entry["message"])["message"]
        if message.get("method") == "Network.requestWillBeSent":
            urls.append(message["params"]["request"]["url"])
    urls += driver.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
    return [u for u in urls if u != page and not u.startswith("data:")]


def canvas_pixels(driver):
    """The WebGL canvas as (width, height, rgb bytes), read in the page."""
    result = driver.execute_script("""
        const c = document.querySelector('#view canvas');
        const t = document.createElement('canvas');
        t.width = c.width; t.height = c.height;
        const g = t.getContext('2d');
        g.drawImage(c, 0, 0);
        const d = g.getImageData(0, 0, t.width, t.height).data;
        let s = '';
        for (let k = 0; k < d.length; k += 4) s += String.fromCharCode(d[k], d[k + 1], d[k + 2]);
        return [t.width, t.height, btoa(s)];""")
    import base64
    return result[0], result[1], base64.b64decode(result[2])


def drawn_fraction(pixels, box=None):
    """The fraction of pixels (within box = (x0, y0, x1, y1), default all) that are
    not the background."""
    w, h, rgb = pixels
    x0, y0, x1, y1 = box or (0, 0, w, h)
    drawn = total = 0
    for y in range(y0, y1, 2):
        row = y * w * 3
        for x in range(x0, x1, 2):
            k = row + 3 * x
            total += 1
            if abs(rgb[k] - BACKGROUND[0]) + abs(rgb[k + 1] - BACKGROUND[1]) + abs(rgb[k + 2] - BACKGROUND[2]) > 12:
                drawn += 1
    return drawn / max(total, 1)


def changed_fraction(a, b):
    """The fraction of pixels that differ between two pictures of the same size."""
    assert a[:2] == b[:2]
    rgb_a, rgb_b = a[2], b[2]
    n = len(rgb_a) // 3
    changed = sum(1 for k in range(0, len(rgb_a), 3 * 7)
                  if abs(rgb_a[k] - rgb_b[k]) + abs(rgb_a[k + 1] - rgb_b[k + 1]) + abs(rgb_a[k + 2] - rgb_b[k + 2]) > 12)
    return changed / max(n // 7, 1)


def set_colouring(driver, name):
    Select(driver.find_element(By.ID, "colouring")).select_by_value(name)


def click(driver, element_id):
    driver.find_element(By.ID, element_id).click()


def info_panel(driver):
    """The summary panel's rows: {key: value} as the page holds them (JSON)."""
    rows = driver.execute_script(
        "return [...document.querySelectorAll('#info tr')].map(r => [r.dataset.key, r.cells[1].dataset.value])")
    return {k: json.loads(v) for k, v in rows}


def view_element(driver):
    """The element holding the 3D view (the canvas), for screenshots."""
    return driver.find_element(By.ID, "view")
