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

import shutil
from pathlib import Path

import browser as chromium
import numpy as np
import pytest

import qc_control as qc
from qc_control.report import write_report

# the fixture and the test of a local address (tests/browser.py), here and in tests/test_docs.py
browser, _local = chromium.browser, chromium._local

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


def check_in_browser(browser, page: Path, tmp: Path, width: int) -> dict:
    """Open ``page`` alone at ``width`` px with no network; the verdict, and what was blocked."""
    folder = tmp / f"alone-{width}"
    folder.mkdir()
    alone = folder / page.name
    shutil.copyfile(page, alone)
    blocked: list[str] = []
    context = browser.new_context(viewport={"width": width, "height": 900})
    try:
        context.route("**/*", chromium.only_local(blocked))
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
