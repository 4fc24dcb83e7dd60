"""Each report page drawn in headless Chromium (Debian's chromium and chromium-driver, and
selenium): waits until its plots have rendered, checks that the console has no error and
that the page asked the network for nothing, and writes a screenshot beside it
(``PAGE.png``). Run: ``python examples/report_screenshots.py PAGE.html ... [--brush STUDY:AXIS:LO:HI ...]
[--crop SELECTOR=OUT.png ...]`` (``--crop``: also the element the CSS selector finds in the
first page, e.g. ``#front-0`` for the docs' pictures; ``--brush``: first, on the first
page, the range LO..HI brushed along axis AXIS (0: the first objective) of study STUDY's
parallel coordinates); exit 1 with the page and the problem on the first that fails."""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By


def _browser(width: int = 1400, height: int = 2000):
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                f"--window-size={width},{height}"):  # fmt: skip
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    return webdriver.Chrome(
        options=options, service=Service(shutil.which("chromedriver") or "/usr/bin/chromedriver")
    )


#: True while a parallel-coordinates plot on screen is not drawn yet (the page draws each
#: when it comes on screen, after the rest)
UNDRAWN_ON_SCREEN = (
    "return [...document.querySelectorAll('[id^=parallel-]')].some(d => {"
    " const r = d.getBoundingClientRect();"
    " return r.bottom > 0 && r.top < innerHeight && !d.hasAttribute('data-drawn'); })"
)


def _settle(browser, deadline: float) -> bool:
    """Wait until the parallel-coordinates plots on screen are drawn; False past ``deadline``."""
    while browser.execute_script(UNDRAWN_ON_SCREEN):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


def _brush(browser, study: int, axis: int, lo: float, hi: float) -> bool:
    """Brush ``lo..hi`` along ``axis`` of ``study``'s parallel coordinates (drawn first);
    False if the page has no such study or axis, or the plot does not draw in 60 s."""
    div = f"document.getElementById('parallel-{study}')"
    if not browser.execute_script(
        f"return {div} !== null && arguments[0] < window.suspoptReport.studies.length", study
    ):
        return False
    browser.execute_script(f"{div}.scrollIntoView({{block: 'center'}})")
    deadline = time.monotonic() + 60
    while not browser.execute_script(f"return {div}.hasAttribute('data-drawn')"):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    if axis >= browser.execute_script(f"return {div}.data[0].dimensions.length"):
        return False
    browser.execute_script(
        f"Plotly.restyle({div}, {{['dimensions[' + arguments[0] + '].constraintrange']:"
        " [[arguments[1], arguments[2]]]})",
        axis,
        lo,
        hi,
    )
    return True


def check(
    page: Path, crops: dict[str, str] | None = None, brushes: list[str] | None = None
) -> str | None:
    """The problem with ``page`` in the browser, or None; its screenshot is written, and
    each ``crops`` element (CSS selector -> PNG path), after the ``brushes``
    (``STUDY:AXIS:LO:HI``)."""
    browser = _browser()
    try:
        browser.get(page.resolve().as_uri())
        deadline = time.monotonic() + 120
        while not browser.execute_script("return document.body.getAttribute('data-rendered')"):
            if time.monotonic() > deadline:
                return "the plots did not render in 120 s"
            time.sleep(0.2)
        if not _settle(browser, deadline):
            return "the parallel coordinates on screen did not draw in 120 s"
        errors = [e["message"] for e in browser.get_log("browser") if e["level"] == "SEVERE"]
        if errors:
            return f"console errors: {errors[:3]}"
        urls = [
            json.loads(e["message"])["message"]["params"]["request"]["url"]
            for e in browser.get_log("performance")
            if '"Network.requestWillBeSent"' in e["message"]
        ]
        if any(url != page.resolve().as_uri() for url in urls):
            return f"network requests: {urls[:3]}"
        browser.save_screenshot(str(page.with_suffix(".png")))
        for brush in brushes or ():
            study, axis, lo, hi = brush.split(":")
            if not _brush(browser, int(study), int(axis), float(lo), float(hi)):
                return f"--brush {brush}: no such study or axis, or its plot did not draw in 60 s"
        for selector, target in (crops or {}).items():
            element = browser.find_element(By.CSS_SELECTOR, selector)
            browser.execute_script("arguments[0].scrollIntoView()", element)
            if not _settle(browser, time.monotonic() + 60):
                return f"{selector}: the parallel coordinates did not draw in 60 s"
            element.screenshot(target)
    finally:
        browser.quit()
    return None


def _brush_arg(text: str) -> str:
    """``STUDY:AXIS:LO:HI`` as ``--brush`` takes it (argparse's one-line error otherwise)."""
    parts = text.split(":")
    try:
        ok = len(parts) == 4 and int(parts[0]) >= 0 and int(parts[1]) >= 0
        ok = ok and float(parts[2]) <= float(parts[3])
    except ValueError:
        ok = False
    if not ok:
        raise argparse.ArgumentTypeError(f"{text!r}: expected STUDY:AXIS:LO:HI, LO <= HI")
    return text


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pages", nargs="+", metavar="PAGE.html")
    parser.add_argument("--crop", nargs="*", default=[], metavar="SELECTOR=OUT.png")
    parser.add_argument(
        "--brush", action="append", default=[], metavar="STUDY:AXIS:LO:HI", type=_brush_arg
    )
    args = parser.parse_args()
    crops = dict(a.split("=", 1) for a in args.crop)
    for i, name in enumerate(args.pages):
        problem = check(Path(name), crops if i == 0 else None, args.brush if i == 0 else None)
        if problem:
            sys.exit(f"{name}: {problem}")
        print(
            f"{name}: rendered, no console error, no network request; {Path(name).with_suffix('.png')}"
        )


if __name__ == "__main__":
    main()
