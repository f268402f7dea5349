"""What every benchmark section uses: its tables, its numbers and the busy machine.

A module beside ``run.py`` (which puts this folder on ``sys.path``), so that a
section kept in a file of its own (``mpc_solvers.py``, ``explore_redraw.py``)
writes its tables and loads the machine as the others do.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time


def table(headers, rows) -> str:
    """A Markdown table; a '|' inside a cell is escaped."""

    def line(cells):
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"

    out = [line(headers), "|" + "|".join("---" for _ in headers) + "|"]
    return "\n".join(out + [line(r) for r in rows])


def section(title: str, text: str, head, rows, *notes: str) -> list[str]:
    """A results section's Markdown lines: its heading, the text saying what was
    measured and how, its table, and any paragraphs that read the table."""
    return [f"### {title}", "", text, "", table(head, rows), ""] + [
        line for note in notes for line in (note, "")
    ]


def titled(title: str, text: str, head, rows) -> tuple[list[str], list, list]:
    """A benchmark's result: its section's lines, and its table's head and rows on
    their own (RESULTS.md takes the section; a ``--only`` smoke run, the table)."""
    return section(title, text, head, rows), head, rows


def g(x, digits=3):
    return f"{x:.{digits}g}"


@contextlib.contextmanager
def other_cores_busy(busy: bool):
    """One CPU-bound process on each core but this one (at least one), as a
    laptop with a browser and a build open; nothing when ``busy`` is false."""
    hogs = []
    if busy:
        spin = [sys.executable, "-c", "while True: pass"]
        hogs = [subprocess.Popen(spin) for _ in range(max(1, (os.cpu_count() or 2) - 1))]
        time.sleep(0.3)  # every hog running before the first timed call
    try:
        yield
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
