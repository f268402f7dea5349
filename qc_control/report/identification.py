"""A model against measurement, and the identification report (``qc-control identify``).

`compare_to_measurement` simulates a car under a measurement's recorded
inputs and gives the fit of each measured output (NRMSE, as MATLAB's
``compare``) with three figures: the records overlaid, the residuals, and
the power spectral densities overlaid. `write_identification_report` writes
an `qc_control.identify` result as a report: the parameters with their 95 %
intervals, what the records do not determine, the fit per output on the
identification record and on a held-out one, the figures, and the command
that redoes it.

matplotlib is imported inside the functions that draw.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import scipy.signal

from ..models.quarter import QuarterCarParams
from ..models.vehicle import VehicleModel
from ..numerics.reference import exact_response
from ..studies.identification import OUTPUT_LABELS, Identification, nrmse_fit, simulate_quarter
from ..studies.measurement import SIGNAL_UNITS, Measurement
from .document import Code, Heading, Image, Paragraph, Table
from .writer import FORMATS, FigureSpec, write_document

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "MeasurementComparison",
    "compare_to_measurement",
    "write_identification_report",
    "TITLE",
]

TITLE = "Quarter car identified from measured records"


@dataclass
class MeasurementComparison:
    """A model's outputs against a measurement's.

    Attributes
    ----------
    t : ndarray
        Time [s].
    measured, simulated : dict
        ``{label: samples}`` of each compared output.
    fit : pandas.Series
        NRMSE fit [%] of each output.
    """

    t: np.ndarray
    measured: dict[str, np.ndarray]
    simulated: dict[str, np.ndarray]
    fit: pd.Series

    @property
    def residuals(self) -> dict[str, np.ndarray]:
        """Measured minus simulated, per output."""
        return {k: self.measured[k] - self.simulated[k] for k in self.measured}

    def figure_records(self) -> Figure:
        """The measured and simulated records overlaid, one panel per output."""
        t, measured, simulated = self.t, self.measured, self.simulated
        return _panels(self, lambda ax, k: _overlay(ax, t, measured[k], simulated[k]))

    def figure_residuals(self) -> Figure:
        """The residuals (measured − simulated), one panel per output."""
        return _panels(self, lambda ax, k: ax.plot(self.t, self.residuals[k], lw=0.6))

    def figure_psd(self) -> Figure:
        """The PSDs of the measured and simulated outputs (Welch), one panel per output."""
        fs = 1.0 / (self.t[1] - self.t[0])

        def draw(ax, k):
            for signal, style, name in (
                (self.measured[k], "-", "measured"),
                (self.simulated[k], "--", "simulated"),
            ):
                f, p = scipy.signal.welch(signal, fs=fs, nperseg=min(signal.size, 2048))
                ax.loglog(f[1:], p[1:], style, lw=0.9, label=name)
            ax.legend(fontsize="small")

        return _panels(self, draw, xlabel="frequency [Hz]", psd=True)

    @property
    def figures(self) -> dict[str, Figure]:
        """The three figures by name: ``records``, ``residuals``, ``psd``."""
        return {
            "records": self.figure_records(),
            "residuals": self.figure_residuals(),
            "psd": self.figure_psd(),
        }


def _overlay(ax, t, measured, simulated) -> None:
    ax.plot(t, measured, lw=0.8, label="measured")
    ax.plot(t, simulated, "--", lw=0.8, label="simulated")
    ax.legend(fontsize="small", loc="upper right")


def _panels(cmp: MeasurementComparison, draw, xlabel: str = "t [s]", psd: bool = False):
    from matplotlib.figure import Figure  # heavy and optional: only when plotting

    labels = list(cmp.measured)
    fig = Figure(figsize=(8, 2.2 * len(labels) + 0.6), layout="constrained")
    axes = fig.subplots(len(labels), 1, squeeze=False)[:, 0]
    for ax, k in zip(axes, labels):
        draw(ax, k)
        unit = SIGNAL_UNITS.get(k, "")
        ax.set_ylabel(f"{k} [({unit})²/Hz]" if psd else f"{k} [{unit}]")
        ax.set_title(f"{k}: fit {cmp.fit[k]:.1f} %", fontsize="medium")
    axes[-1].set_xlabel(xlabel)
    return fig


def _linear_outputs(model: VehicleModel, measurement: Measurement, outputs) -> np.ndarray:
    """A linear `VehicleModel`'s outputs (python-control's exact response), at rest."""
    sys = model.system
    U = np.stack(
        [
            measurement[k] if k in measurement.signals else np.zeros(len(measurement))
            for k in sys.input_labels
        ]
    )
    response = exact_response(sys, measurement.t, U=U, at_rest=bool(U.size))
    rows = [list(sys.output_labels).index(k) for k in outputs]
    return np.atleast_2d(response.outputs)[rows]


def compare_to_measurement(
    model: Any, measurement: Measurement, outputs=None
) -> MeasurementComparison:
    """Simulate ``model`` under ``measurement``'s inputs and compare its outputs.

    Parameters
    ----------
    model : Identification, QuarterCarParams, mapping or VehicleModel
        An identification (its gains applied), a quarter car's parameters,
        or a linear `VehicleModel` whose inputs are labelled as the
        measurement's (``zr``, ``fa``; an absent one is zero).
    measurement : Measurement
    outputs : sequence of str, optional
        The outputs compared; by default every measured output the model gives.

    Returns
    -------
    MeasurementComparison
        The fit per output and the figures (records, residuals, PSDs). The
        record is taken to start at rest.
    """
    if not isinstance(measurement, Measurement):
        raise TypeError(f"measurement must be a Measurement, got {type(measurement).__name__}")
    if isinstance(model, VehicleModel):
        given = set(model.system.output_labels)
    else:
        given = set(OUTPUT_LABELS)
    wanted = [k for k in measurement.outputs if k in given] if outputs is None else list(outputs)
    missing = [k for k in wanted if k not in given or k not in measurement.signals]
    if missing or not wanted:
        raise ValueError(
            f"cannot compare output(s) {missing or '(none)'}: the model gives "
            f"{sorted(given)}, the measurement has {list(measurement.outputs)}"
        )
    if isinstance(model, Identification):
        y = model.simulate(measurement) if set(wanted) == set(model.outputs) else None
        if y is None:
            y = simulate_quarter(model.values, measurement, wanted, model.gains)
        else:
            y = y[[list(model.outputs).index(k) for k in wanted]]
    elif isinstance(model, VehicleModel):
        y = _linear_outputs(model, measurement, wanted)
    elif isinstance(model, (QuarterCarParams, Mapping)):
        p = model if isinstance(model, QuarterCarParams) else QuarterCarParams.from_mapping(model)
        values = {n: float(getattr(p, n)) for n in ("ms", "mu", "ks", "ku", "cs", "cu")}
        y = simulate_quarter(values, measurement, wanted)
    else:
        raise TypeError(
            "model must be an Identification, QuarterCarParams, dict or VehicleModel, "
            f"got {type(model).__name__}"
        )
    measured = {k: measurement[k] for k in wanted}
    simulated = {k: y[i] for i, k in enumerate(wanted)}
    fit = pd.Series({k: nrmse_fit(measured[k], simulated[k]) for k in wanted}, name="fit [%]")
    return MeasurementComparison(measurement.t, measured, simulated, fit)


def _figures(fitted: MeasurementComparison, held: MeasurementComparison | None):
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
        Table(fit_table, "NRMSE fit [%] per output (100: perfect).", f"Table {n}"),
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
    fitted = compare_to_measurement(ident, measurement, ident.outputs)
    held = compare_to_measurement(ident, validation, ident.outputs) if validation else None
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
