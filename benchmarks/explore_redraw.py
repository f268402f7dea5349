"""The explorer's redraw timed in the browser (issue 27's 300 ms; issue 40 moved it
here from the test suite, which checks what a redraw shows and never its time).

The seed's scenario (10 s at 1 ms, four methods and the exact response) served by
``qc-control explore --no-browser --port 0``, open in headless Chromium (Debian's,
driven by Playwright, every request that leaves 127.0.0.1 refused); h is entered
as 0.99 and 1 ms in turns, and each redraw is timed from the Enter key to the
second animation frame after the page's redraw stamp moved, when the figures are
painted (``tests/browser.py``: `entered`). Quiet, and busy with one CPU-bound
process on each other core. Without Playwright, Chromium or the explore extra,
the section says so in one line and times nothing.
"""

from __future__ import annotations

import importlib.util
import statistics
import sys
from pathlib import Path

from shared import g, other_cores_busy, table

TARGET_MS = 300.0


def _browser_helpers():
    """tests/browser.py, or the reason it cannot drive a browser here."""
    if importlib.util.find_spec("playwright") is None:
        return None, "Playwright is not installed (the test extra installs it)"
    if importlib.util.find_spec("panel") is None:
        return None, "Panel is not installed (the explore extra installs it)"
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    try:
        import browser
    except ImportError as missing:  # pytest or filelock: the test extra
        return None, f"tests/browser.py cannot be imported ({missing})"
    if browser.find_chromium() is None:
        return None, "no headless Chromium on this machine (`make check-html` installs it)"
    return browser, ""


def _redraws(helpers, url: str, pairs: int, busy: bool) -> list[float]:
    from playwright.sync_api import sync_playwright

    blocked: list[str] = []
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(
            executable_path=helpers.find_chromium(), args=helpers.CHROMIUM_ARGS
        )
        try:
            context = launched.new_context(viewport={"width": 1280, "height": 900})
            context.route("**/*", helpers.only_local(blocked))
            tab = context.new_page()
            tab.goto(url, wait_until="networkidle")
            tab.wait_for_function(f"({helpers.STAMP})() >= 1", timeout=60_000)
            tab.locator(".qc-status p").first.wait_for(timeout=60_000)
            with other_cores_busy(busy):
                return [helpers.entered(tab, ".qc-h", h) for h in (0.99, 1.0) * pairs]
        finally:
            launched.close()


def browser_redraw_benchmark(quick: bool) -> tuple[list[str], list[str], list[list[str]]]:
    """The section's Markdown lines, its table's head and rows (empty when skipped)."""
    heading = ["### The explorer's redraw in the browser", ""]
    helpers, reason = _browser_helpers()
    if helpers is None:
        return [*heading, f"Skipped: {reason}.", ""], [], []
    pairs = 1 if quick else 5
    machines = (False,) if quick else (False, True)  # the smoke run: its code path, quiet
    rows = []
    with helpers.explorer_server() as url:
        for busy in machines:
            times = _redraws(helpers, url, pairs, busy)
            rows.append(
                [
                    "busy" if busy else "quiet",
                    str(len(times)),
                    g(statistics.median(times)),
                    g(min(times)),
                    g(max(times)),
                ]
            )
    head = ["machine", "redraws", "median [ms]", "fastest [ms]", "slowest [ms]"]
    lines = [
        *heading,
        f"The seed's scenario, h entered as 0.99 and 1 ms in turns ({2 * pairs} redraws "
        "a row), each timed from the Enter key to the figures painted in headless "
        f"Chromium (`benchmarks/explore_redraw.py`); target: under {TARGET_MS:g} ms. "
        "The server's share is in `--only explore`'s table. Busy: one CPU-bound process "
        "on each other core.",
        "",
        table(head, rows),
        "",
    ]
    return lines, head, rows
