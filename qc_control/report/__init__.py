"""The comparison report: Markdown, HTML, PDF, CSV and PNG from a MethodComparison.

Presentation only: every number comes from the `MethodComparison`. The
package is in three parts, whose names it hands on:

- `comparison`: the comparison report's content (its blocks, tables and
  numbered figures) and `write_report`;
- `writer`: `write_document`, which writes any report's figures, document
  and tables in the `FORMATS` (``report.html`` embeds its figures,
  ``report.pdf`` is drawn with matplotlib);
- `transaction`: the report folder replaced whole under a lock, safe from
  Ctrl-C, never deleting a file it did not write (`check_target`,
  `report_lock`, `MARKER`).
"""

from __future__ import annotations

from . import comparison, document, transaction, writer
from .comparison import (
    SEED_FIGURES,
    TITLE,
    build_blocks,
    figure_specs,
    report_title,
    write_report,
)
from .document import Code, Heading, Image, Paragraph, Table, fmt
from .findings import findings
from .summary import summary
from .transaction import MARKER, ReportError, check_target, report_lock, report_path
from .writer import DPI, FORMATS, FigureSpec, write_document

__all__ = [
    "check_target",
    "report_path",
    "report_lock",
    "write_report",
    "report_title",
    "write_document",
    "build_blocks",
    "figure_specs",
    "FigureSpec",
    "ReportError",
    "MARKER",
    "FORMATS",
    "SEED_FIGURES",
]

# the package's names before its split, still importable from it: the blocks
# of a document, and `summary` and `findings` as the functions (not their modules)
_HANDED_ON = (TITLE, DPI, Code, Heading, Image, Paragraph, Table, fmt, findings, summary)


def __getattr__(name: str):
    """Every other name the package held before its split (a figure, a
    helper), from the module that now holds it."""
    for module in (comparison, writer, transaction, document):
        if name in vars(module):
            return vars(module)[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
