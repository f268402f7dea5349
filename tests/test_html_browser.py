"""report.html in a real browser: headless Chromium, no network.

The page is copied alone into an empty folder (as if mailed), a small
script is appended that waits for the load event, and Chromium's
``--dump-dom`` prints the DOM with the script's verdict written into it:
every image decoded (``naturalWidth > 0``), nothing wider than the page
(``scrollWidth <= clientWidth``), and no resource fetched from anywhere.
It runs at a laptop's width and at a phone's. Skipped, with the reason,
where Chromium is not installed (``make check-html`` installs it).
"""

import html
import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import qc_control as qc
from qc_control.report import write_report

CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser", "google-chrome")
CHROMIUM = next((shutil.which(c) for c in CANDIDATES if shutil.which(c)), None)

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        CHROMIUM is None,
        reason="headless Chromium not found (/usr/bin/chromium); `make check-html` installs it",
    ),
]

PROBE = """<script>
window.addEventListener("load", () => {
  const root = document.documentElement;
  const images = Array.from(document.images);
  const verdict = {
    images: images.length,
    broken: images.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.alt.slice(0, 60)),
    scrollWidth: root.scrollWidth,
    clientWidth: root.clientWidth,
    resources: performance.getEntriesByType("resource").map(r => r.name),
  };
  const out = document.createElement("pre");
  out.id = "qc-check";
  out.textContent = JSON.stringify(verdict);
  document.body.appendChild(out);
});
</script>"""


def check_in_browser(page: Path, tmp: Path, width: int) -> dict:
    """Load ``page`` alone in headless Chromium with no network; the probe's verdict."""
    folder = tmp / f"alone-{width}"
    folder.mkdir()
    probed = folder / page.name
    probed.write_text(
        page.read_text(encoding="utf-8").replace("</body>", PROBE + "</body>"), encoding="utf-8"
    )
    run = subprocess.run(
        [
            CHROMIUM,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--no-first-run",
            f"--user-data-dir={tmp / f'profile-{width}'}",
            # no network: every host unresolvable, every request through a dead proxy
            "--host-resolver-rules=MAP * ~NOTFOUND",
            "--proxy-server=http://127.0.0.1:9",
            f"--window-size={width},900",
            "--virtual-time-budget=10000",
            "--dump-dom",
            probed.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    found = re.search(r'<pre id="qc-check">(.*?)</pre>', run.stdout, re.S)
    assert found, f"no verdict from Chromium (exit {run.returncode}): {run.stderr[-2000:]}"
    return json.loads(html.unescape(found.group(1)))


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
def test_report_html_renders_every_image_and_fits_the_page(road_report, tmp_path, width):
    verdict = check_in_browser(road_report / "report.html", tmp_path, width)
    assert verdict["images"] == len(list(road_report.glob("*.png")))
    assert verdict["broken"] == []
    assert verdict["scrollWidth"] <= verdict["clientWidth"], verdict
    assert verdict["resources"] == []  # nothing fetched: the page is self-contained


def test_the_probe_sees_broken_images_and_overflow(tmp_path):
    """The check itself is checked: a page that is wrong in both ways fails it."""
    page = tmp_path / "bad.html"
    page.write_text(
        '<!DOCTYPE html><html><body><img src="missing.png" alt="missing">'
        '<div style="width: 5000px">wide</div></body></html>',
        encoding="utf-8",
    )
    verdict = check_in_browser(page, tmp_path, 800)
    assert verdict["broken"] == ["missing"]
    assert verdict["scrollWidth"] > verdict["clientWidth"]
