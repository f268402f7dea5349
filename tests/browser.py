"""Headless Chromium for the browser tests: Debian's build, driven by Playwright.

Also the explorer's server and its redraw stamp (`explorer_server`,
`entered`), shared by tests/test_explore.py, which checks what a redraw
shows, and benchmarks/explore_redraw.py, which times it.

Chromium comes from Debian (``apt-get install chromium``; Playwright's own
browser download needs the internet): the `browser` fixture installs it when
it is absent and the tests run as root, as in CI, so that CI never skips
them. Elsewhere, without Chromium, they skip with the reason (``make
check-html`` installs it). Shared by tests/test_html_browser.py (the report),
tests/test_docs.py (the built site) and tests/test_explore.py (the explorer).
"""

import contextlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import urlparse

import pytest
from filelock import FileLock

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


def find_chromium() -> str | None:
    """The path of a Chromium on this machine, or None."""
    return next((shutil.which(c) for c in CANDIDATES if shutil.which(c)), None)


def _install_chromium() -> None:
    """Debian's chromium, as root (CI, containers); a no-op elsewhere."""
    if shutil.which("apt-get") is None or not hasattr(os, "geteuid") or os.geteuid() != 0:
        return
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    wait = ["-o", "DPkg::Lock::Timeout=600"]  # another apt run (the machine's own) holds dpkg
    for command in (
        ["apt-get", *wait, "update", "-qq"],
        ["apt-get", *wait, "install", "-y", "-qq", "chromium"],
    ):
        run = subprocess.run(command, capture_output=True, text=True, env=env, timeout=1200)
        if run.returncode != 0:
            pytest.fail(f"{' '.join(command)} failed: {run.stderr[-2000:]}")


@pytest.fixture(scope="module")
def browser():
    """Playwright's Chromium, Debian's build, installed first where we may."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="the test extra installs it")
    chromium = find_chromium()
    if chromium is None:
        # the suite's workers may reach this at once (the report's, the site's and the
        # explorer's tests run on different workers): one installs, the others wait
        with FileLock(Path(tempfile.gettempdir()) / "qc-control-chromium-install.lock"):
            if find_chromium() is None:
                _install_chromium()
        chromium = find_chromium()
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


def only_local(blocked: list[str]):
    """A route handler: requests to 127.0.0.1 go ahead, any other is aborted and recorded."""

    def route(route):
        if _local(route.request.url):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    return route


@contextlib.contextmanager
def explorer_server():
    """``qc-control explore --no-browser --port 0`` (a subprocess, as a student starts
    it): its address once it says it, or RuntimeError with what it printed."""
    exe = Path(sys.executable).with_name("qc-control")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "qc_control.cli.console"]
    proc = subprocess.Popen(
        [*command, "explore", "--no-browser", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    url, seen = None, []
    deadline = time.monotonic() + 120  # the server's start, not a measured time
    while url is None and time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        seen.append(line)
        match = re.search(r"qc-control explore: serving (http://127\.0\.0\.1:\d+/)", line)
        url = match.group(1) if match else None
    try:
        if url is None:
            raise RuntimeError("the explorer did not say its address:\n" + "".join(seen))
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()


#: The page's redraw stamp: a data source the server updates last, in the same
#: message as the figures.
STAMP = """() => {
  const doc = window.Bokeh && Bokeh.documents[0];
  const m = doc && doc.get_model_by_name('qc-redraw-stamp');
  return m ? m.data.n[0] : null;
}"""

#: Resolves, after the Enter key, once the stamp has moved past ``before`` and two
#: frames were drawn (the figures painted): the time [ms] from the key to then.
_PAINTED = """(before) => new Promise(resolve => {
  const m = Bokeh.documents[0].get_model_by_name('qc-redraw-stamp');
  const wait = () => {
    if (window.__t0 !== undefined && m.data.n[0] > before) {
      const done = () => resolve(performance.now() - window.__t0);
      requestAnimationFrame(() => requestAnimationFrame(done));
    } else {
      requestAnimationFrame(wait);
    }
  };
  wait();
})"""

#: Notes the time of the next Enter key, at the capture phase.
_ARM = """() => {
  delete window.__t0;
  window.addEventListener('keydown', e => {
    if (e.key === 'Enter' && window.__t0 === undefined) window.__t0 = performance.now();
  }, {capture: true, once: true});
}"""


def entered(tab, css: str, value) -> float:
    """Type ``value`` into the input of the explorer's widget ``css``, press Enter
    and wait until the redraw it starts is painted; the time [ms] from the key to
    the second animation frame after the stamp moved."""
    before = tab.evaluate(STAMP)
    box = tab.locator(f"{css} input")
    box.fill(str(value))
    tab.evaluate(_ARM)
    box.press("Enter")
    return tab.evaluate(_PAINTED, before)
