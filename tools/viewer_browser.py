"""Viewer pages in a real browser: Debian's Chromium, headless, WebGL through
SwiftShader, driven by Selenium (python3-selenium, chromium-driver).

Shared by the browser tests (tools/check_viewer.py), the pictures of the README
(tools/make_pictures.py) and the page benchmark (tools/bench_viewer.py).
"""

import base64
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
    """Loads a page from file:// and waits until its script has run and its first
    picture is complete (a pixel read back from the canvas waits for the rendering,
    which SwiftShader does on the processor after the script returns). Returns the
    seconds from the navigation's start to that moment, as the page measures them
    (performance.now())."""
    driver.get("file://" + os.path.abspath(path))
    WebDriverWait(driver, timeout, poll_frequency=0.05).until(
        lambda d: d.execute_script("return document.body && document.body.dataset.ready === 'true'"))
    return float(driver.execute_script("""
        const gl = document.querySelector('#view canvas').getContext('webgl2');
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
        return performance.now();""")) / 1000


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
    """The WebGL canvas as (width, height, rgb bytes), read in the page (rows bottom
    to top, as WebGL reads them)."""
    result = driver.execute_script("""
        const c = document.querySelector('#view canvas');
        const gl = c.getContext('webgl2');
        const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
        const d = new Uint8Array(4 * w * h);
        gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, d);
        const rgb = new Uint8Array(3 * w * h);
        for (let k = 0, j = 0; k < d.length; k += 4, j += 3) { rgb[j] = d[k]; rgb[j + 1] = d[k + 1]; rgb[j + 2] = d[k + 2]; }
        let s = '';
        for (let k = 0; k < rgb.length; k += 8192) s += String.fromCharCode.apply(null, rgb.subarray(k, k + 8192));
        return [w, h, btoa(s)];""")
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


def info_shown(driver):
    """The summary panel's rows as a reader sees them: {key: (text, title or None)}."""
    rows = driver.execute_script(
        "return [...document.querySelectorAll('#info tr')]"
        ".map(r => [r.dataset.key, r.cells[1].textContent, r.cells[1].getAttribute('title')])")
    return {k: (text, title) for k, text, title in rows}


def view_element(driver):
    """The element holding the 3D view (the canvas), for screenshots."""
    return driver.find_element(By.ID, "view")
