"""report.html in a real browser: Playwright driving Debian's headless Chromium.

The page is copied alone into an empty folder (as if mailed) and opened
with every request that leaves 127.0.0.1 aborted and recorded. Once it has
loaded, a script reads the verdict: every image decoded
(``naturalWidth > 0``), nothing wider than the page
(``scrollWidth <= clientWidth``), and no resource fetched from anywhere.
It runs at a laptop's width and at a phone's.

Chromium comes from Debian (``apt-get install chromium``; Playwright's own
browser download needs the internet): the fixture installs it when it is
absent and the tests run as root, as in CI, so that CI never skips them.
Elsewhere, without Chromium, they skip with the reason (``make check-html``
installs it).
"""

import os
import shutil
import subprocess
from pathlib import Path
from urllib.parse import urlparse

import numpy as np
import pytest

import qc_control as qc
from qc_control.report import write_report

CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser", "google-chrome")
#: The flags a headless Chromium needs on a closed network, as root.
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]

pytestmark = pytest.mark.slow

VERDICT = """() => {
  const root = document.documentElement;
  const images = Array.from(document.images);
  return {
    images: images.length,
    broken: images.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.alt.slice(0, 60)),
    scrollWidth: root.scrollWidth,
    clientWidth: root.clientWidth,
    resources: performance.getEntriesByType("resource").map(r => r.name),
  };
}"""


def _find_chromium() -> str | None:
    return next((shutil.which(c) for c in CANDIDATES if shutil.which(c)), None)


def _install_chromium() -> None:
    """Debian's chromium, as root (CI, containers); a no-op elsewhere."""
    if shutil.which("apt-get") is None or not hasattr(os, "geteuid") or os.geteuid() != 0:
        return
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    for command in (["apt-get", "update", "-qq"], ["apt-get", "install", "-y", "-qq", "chromium"]):
        run = subprocess.run(command, capture_output=True, text=True, env=env, timeout=1200)
        if run.returncode != 0:
            pytest.fail(f"{' '.join(command)} failed: {run.stderr[-2000:]}")


@pytest.fixture(scope="module")
def browser():
    """Playwright's Chromium, Debian's build, installed first where we may."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="the test extra installs it")
    chromium = _find_chromium()
    if chromium is None:
        _install_chromium()
        chromium = _find_chromium()
    if chromium is None:
        pytest.skip("headless Chromium not found; `make check-html` installs it")
    with sync_api.sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        yield launched
        launched.close()


def _local(url: str) -> bool:
    parsed = urlparse(url)
    local_host = parsed.hostname in ("127.0.0.1", "localhost")
    return parsed.scheme in ("file", "data", "blob") or local_host


def check_in_browser(browser, page: Path, tmp: Path, width: int) -> dict:
    """Open ``page`` alone at ``width`` px with no network; the verdict, and what was blocked."""
    folder = tmp / f"alone-{width}"
    folder.mkdir()
    alone = folder / page.name
    shutil.copyfile(page, alone)
    blocked: list[str] = []

    def only_local(route):
        if _local(route.request.url):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    context = browser.new_context(viewport={"width": width, "height": 900})
    try:
        context.route("**/*", only_local)
        tab = context.new_page()
        tab.goto(alone.as_uri(), wait_until="load")
        verdict = tab.evaluate(VERDICT)
    finally:
        context.close()
    verdict["blocked"] = blocked
    return verdict


@pytest.fixture(scope="module")
def road_report(tmp_path_factory):
    """A report with every kind of figure and table, the road section included."""
    params = qc.QuarterCarParams()
    T = np.linspace(0.0, 2.0, 401)
    cmp = qc.compare_methods(
        params,
        T,
        (0.0, 0.0, 0.0, 0.0),
        U=qc.road.bump(T, height=0.1, speed=15.0),
        params=params,
        repeats=1,
        input_description="a 10 cm bump at 15 m/s",
    )
    out = tmp_path_factory.mktemp("browser") / "report"
    return write_report(cmp, out, formats=("html",))


@pytest.mark.parametrize("width", [1280, 420])
def test_report_html_renders_every_image_and_fits_the_page(browser, road_report, tmp_path, width):
    verdict = check_in_browser(browser, road_report / "report.html", tmp_path, width)
    assert verdict["images"] == len(list(road_report.glob("*.png")))
    assert verdict["broken"] == []
    assert verdict["scrollWidth"] <= verdict["clientWidth"], verdict
    assert verdict["resources"] == []  # nothing fetched: the page is self-contained
    assert verdict["blocked"] == []


def _page(folder: Path, body: str) -> Path:
    """A small page with ``body``, written into ``folder``."""
    page = folder / "page.html"
    page.write_text(f"<!DOCTYPE html><html><body>{body}</body></html>", encoding="utf-8")
    return page


def test_the_probe_sees_broken_images_and_overflow(browser, tmp_path):
    """The check itself is checked: a page that is wrong in both ways fails it."""
    body = '<img src="missing.png" alt="missing"><div style="width: 5000px">wide</div>'
    verdict = check_in_browser(browser, _page(tmp_path, body), tmp_path, 800)
    assert verdict["broken"] == ["missing"]
    assert verdict["scrollWidth"] > verdict["clientWidth"]


def test_requests_off_the_machine_are_blocked(browser, tmp_path):
    """A page that reaches for the internet is held to 127.0.0.1: the request
    is aborted, recorded, and its image does not load."""
    body = '<img src="https://example.org/x.png" alt="remote">'
    verdict = check_in_browser(browser, _page(tmp_path, body), tmp_path, 800)
    assert verdict["blocked"] == ["https://example.org/x.png"]
    assert verdict["broken"] == ["remote"]
