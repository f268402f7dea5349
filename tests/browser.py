"""Headless Chromium for the browser tests: Debian's build, driven by Playwright.

Chromium comes from Debian (``apt-get install chromium``; Playwright's own
browser download needs the internet): the `browser` fixture installs it when
it is absent and the tests run as root, as in CI, so that CI never skips
them. Elsewhere, without Chromium, they skip with the reason (``make
check-html`` installs it). Shared by tests/test_html_browser.py (the report),
tests/test_docs.py (the built site) and tests/test_explore.py (the explorer).
"""

import os
import shutil
import subprocess
import tempfile
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


def _find_chromium() -> str | None:
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
    chromium = _find_chromium()
    if chromium is None:
        # the suite's workers may reach this at once (the report's, the site's and the
        # explorer's tests run on different workers): one installs, the others wait
        with FileLock(Path(tempfile.gettempdir()) / "qc-control-chromium-install.lock"):
            if _find_chromium() is None:
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


def only_local(blocked: list[str]):
    """A route handler: requests to 127.0.0.1 go ahead, any other is aborted and recorded."""

    def route(route):
        if _local(route.request.url):
            route.continue_()
        else:
            blocked.append(route.request.url)
            route.abort()

    return route
