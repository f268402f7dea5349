"""A report's writer: figures as PNG, the document as Markdown, HTML and PDF, tables as CSV.

Any report of the package (the comparison, the controller comparison, the
identification) is written by `write_document`: ``report.html`` embeds its
figures (it can be mailed or uploaded alone) and ``report.pdf`` is drawn
with matplotlib (no browser needed). The files are built in a working copy
and swapped in whole (report/transaction.py), so a failure never leaves a
half-written report.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from .document import to_html, to_markdown
from .pdf import to_pdf
from .transaction import replace_folder

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["FORMATS", "DPI", "FigureSpec", "write_document"]

FORMATS = ("md", "html", "pdf", "csv")
#: Resolution of the PNG figures (the HTML and the PDF embed them).
DPI = 150


@dataclasses.dataclass(frozen=True)
class FigureSpec:
    """One figure of the report: its file, number, caption and how to draw it."""

    name: str
    label: str  # "Figure 3"
    caption: str
    make: Callable[[], Figure]

    @property
    def number(self) -> int:
        return int(self.label.split()[-1])


def write_document(
    out_dir,
    title: str,
    blocks: Callable[[], list],
    figures=(),
    tables: Callable[[], dict[str, pd.DataFrame]] | None = None,
    formats=FORMATS,
    *,
    extra: dict[str, str] | None = None,
    command: str | None = None,
    overwrite: bool = True,
) -> Path:
    """Write a report's files into ``out_dir``, atomically (what `write_report` does).

    ``figures`` are `FigureSpec` (drawn first, as PNG), ``blocks()`` the
    document (Markdown, HTML, PDF per ``formats``), ``tables()`` the CSV
    files by name, ``extra`` more text files by name. The directory is built
    beside the target and swapped in under a lock; an existing directory is
    replaced only if it is an earlier report holding nothing foreign
    (`check_target`). The lock is the caller's when it holds `report_lock`.
    """
    formats = tuple(formats)
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise ValueError(
            f"unknown report format {bad[0] if bad else '(none)'!r}; "
            f"choose from {', '.join(FORMATS)}"
        )
    build = functools.partial(_render, title, blocks, figures, tables, formats, extra)
    return replace_folder(out_dir, build, command=command, overwrite=overwrite)


def _render(title, blocks_of, figures, tables_of, formats, extra, tmp: Path) -> None:
    """Write a report's files into the working copy ``tmp`` (see `write_document`)."""
    for spec in figures:
        with warnings.catch_warnings():
            # errors of exactly 0 (a car at rest, an exact method) have no place
            # on a log axis: the curve is left out, which is what the figure means
            warnings.filterwarnings("ignore", "Data has no positive values", UserWarning)
            spec.make().savefig(tmp / spec.name, dpi=DPI)
    blocks = blocks_of()
    if "md" in formats:
        (tmp / "report.md").write_text(to_markdown(title, blocks), encoding="utf-8")
    if "html" in formats:
        (tmp / "report.html").write_text(to_html(title, blocks, tmp), encoding="utf-8")
    if "pdf" in formats:
        to_pdf(title, blocks, tmp, tmp / "report.pdf")
    if "csv" in formats and tables_of is not None:
        for name, frame in tables_of().items():
            frame.to_csv(tmp / name)
    for name, text in (extra or {}).items():
        (tmp / name).write_text(text, encoding="utf-8")
