"""The identification report (``qc-control identify``).

`write_identification_report` writes an `qc_control.identify` result as a
report: the parameters with their 95 % intervals, what the records do not
determine, the fit per output on the identification record and on a
held-out one, the figures, and the command that redoes it. The numbers and
the figures' data come from the studies
(`qc_control.studies.measured_comparison`); this module formats them.

`compare_to_measurement` and `MeasurementComparison` lived here until they
moved to `qc_control.studies.measured_comparison`: the old path still
answers, with a `DeprecationWarning` naming the new one.
"""

from __future__ import annotations

import functools
import warnings

import pandas as pd

from ..studies import measured_comparison
from ..studies.identification import Identification
from ..studies.measurement import Measurement
from .document import Code, Heading, Image, Paragraph, Table
from .writer import FORMATS, FigureSpec, write_document

__all__ = ["write_identification_report", "TITLE"]

#: The names that moved to `qc_control.studies.measured_comparison`.
_MOVED = ("MeasurementComparison", "compare_to_measurement")
# not under their own names: a module global would answer the old path without a warning
_Comparison = measured_comparison.MeasurementComparison
_compare = measured_comparison.compare_to_measurement

TITLE = "Quarter car identified from measured records"


def _figures(fitted: _Comparison, held: _Comparison | None):
    specs: list[FigureSpec] = []
    runs = [("identification record", fitted, "fit")]
    if held is not None:
        runs.append(("held-out record", held, "validation"))
    for what, cmp, stem in runs:
        for kind, caption in (
            ("records", "measured (solid) and simulated (dashed) outputs"),
            ("residuals", "residuals, measured − simulated"),
            ("psd", "power spectral densities (Welch), measured and simulated"),
        ):
            specs.append(
                FigureSpec(
                    f"{stem}_{kind}.png",
                    f"Figure {len(specs) + 1}",
                    f"The {what}: {caption}.",
                    functools.partial(getattr(cmp, f"figure_{kind}")),
                )
            )
    return specs


def _blocks(ident: Identification, fitted, held, specs, command) -> list:
    fit_table = pd.DataFrame({"identification record": fitted.fit})
    if held is not None:
        fit_table["held-out record"] = held.fit
    fit_table.index.name = "output"
    white = ident.whiteness.rename(
        columns={"lags_outside": "lags outside ±1.96/√N", "white": "white"}
    )
    blocks: list = [
        Paragraph(
            "The quarter car fitted by output error to the measured outputs "
            f"{', '.join(ident.outputs)} under the recorded inputs: each output's residual "
            "scaled by its RMS, parameters fitted as logarithms, 95 % intervals from the "
            "Jacobian at the optimum."
        ),
        Heading("Parameters"),
        Table(ident.table, "Estimates, standard errors and 95 % intervals.", "Table 1"),
    ]
    if ident.ratios is not None:
        blocks.append(Table(ident.ratios, "The ratios the records determine.", "Table 2"))
    n = 2 + (ident.ratios is not None)
    blocks += [
        Heading("Fit"),
        Table(
            fit_table,
            "NRMSE fit [%] per output (100: perfect); the identification record simulated "
            "from the state its fit started from"
            + (" (estimated)" if any(k.startswith("x0_") for k in ident.table.index) else "")
            + (", the held-out record from rest." if held is not None else "."),
            f"Table {n}",
        ),
        Table(
            white,
            "Whiteness of the residuals: the fraction of autocorrelation lags 1-25 outside "
            "the 95 % band (white: no more than 4 of 25, the binomial's 99th percentile).",
            f"Table {n + 1}",
        ),
    ]
    blocks += [Image(s.name, s.caption, s.label) for s in specs]
    notes = [Heading("Notes"), *map(Paragraph, ident.notes)] if ident.notes else []
    reproduce = [Heading("Reproduce"), Code(command, wrap=True)] if command else []
    return blocks + notes + reproduce


def write_identification_report(
    ident: Identification,
    measurement: Measurement,
    out_dir,
    *,
    validation: Measurement | None = None,
    formats=("md", "html", "csv"),
    command: str | None = None,
    overwrite: bool = True,
):
    """Write an identification as a report into ``out_dir``.

    Files: ``report.md``/``.html`` (per ``formats``, any of
    `qc_control.report.FORMATS`), the figures as PNG, and with ``'csv'``
    ``parameters.csv``, ``ratios.csv`` (when absolute values are not
    determined), ``correlation.csv`` and ``fit.csv``.
    """
    formats = tuple(f for f in formats if f in FORMATS) or ("md",)
    # the identification record from the state its fit started from (at rest, or the
    # estimated x0), so that this table is the fit the identification reports
    fitted = _compare(ident, measurement, ident.outputs, X0=ident.x0)
    held = _compare(ident, validation, ident.outputs) if validation else None
    specs = _figures(fitted, held)

    def tables() -> dict[str, pd.DataFrame]:
        found = {
            "parameters.csv": ident.table,
            "correlation.csv": ident.correlation,
            "fit.csv": pd.DataFrame(
                {"fit": fitted.fit, **({"validation": held.fit} if held else {})}
            ),
        }
        if ident.ratios is not None:
            found["ratios.csv"] = ident.ratios
        return found

    return write_document(
        out_dir,
        TITLE,
        lambda: _blocks(ident, fitted, held, specs, command),
        specs,
        tables,
        formats,
        command=command,
        overwrite=overwrite,
    )


def __getattr__(name: str):
    """`compare_to_measurement` and `MeasurementComparison` moved to the studies (they
    simulate): the old path still answers, with a `DeprecationWarning`."""
    if name in _MOVED:
        warnings.warn(
            f"qc_control.report.identification.{name} moved to "
            f"qc_control.studies.measured_comparison.{name}",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(measured_comparison, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
