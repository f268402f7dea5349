"""A model against measured records: the fit of each output, the overlays.

`compare_to_measurement` simulates a car under a measurement's recorded
inputs (exactly: `qc_control.numerics.exact` for the quarter car,
python-control's exact response for a linear `VehicleModel`) and gives the
fit of each measured output (NRMSE, as MATLAB's ``compare``) with three
figures: the records overlaid, the residuals, and the power spectral
densities overlaid. It is the study behind the identification report
(`qc_control.report.identification`), which formats what it computes.

An identification's own record is compared from the state the fit started
from (``X0=ident.x0``: at rest, or the estimated state of ``x0='estimate'``),
so that its fit here is the fit the identification reports; a held-out
record starts at rest.

matplotlib is imported inside the functions that draw.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import scipy.signal

from ..models.quarter import QuarterCarParams
from ..models.vehicle import VehicleModel
from ..numerics.reference import exact_response
from .identification import OUTPUT_LABELS, PHYSICAL, Identification, nrmse_fit, simulate_quarter
from .measurement import SIGNAL_UNITS, Measurement

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["MeasurementComparison", "compare_to_measurement"]


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


def _linear_outputs(model: VehicleModel, measurement: Measurement, outputs, X0) -> np.ndarray:
    """A linear `VehicleModel`'s outputs (python-control's exact response), from ``X0``
    or at rest."""
    sys = model.system
    U = np.stack(
        [
            measurement[k] if k in measurement.signals else np.zeros(len(measurement))
            for k in sys.input_labels
        ]
    )
    rest = X0 is None and bool(U.size)
    response = exact_response(sys, measurement.t, X0=X0, U=U, at_rest=rest)
    rows = [list(sys.output_labels).index(k) for k in outputs]
    return np.atleast_2d(response.outputs)[rows]


def _outputs(model: Any, measurement: Measurement, wanted: list[str], X0) -> np.ndarray:
    """``model``'s outputs ``wanted`` under ``measurement``'s inputs, from ``X0``."""
    if isinstance(model, Identification):
        return simulate_quarter(model.values, measurement, wanted, model.gains, X0)
    if isinstance(model, VehicleModel):
        return _linear_outputs(model, measurement, wanted, X0)
    if isinstance(model, (QuarterCarParams, Mapping)):
        p = model if isinstance(model, QuarterCarParams) else QuarterCarParams.from_mapping(model)
        values = {n: float(getattr(p, n)) for n in PHYSICAL}
        return simulate_quarter(values, measurement, wanted, None, X0)
    raise TypeError(
        "model must be an Identification, QuarterCarParams, dict or VehicleModel, "
        f"got {type(model).__name__}"
    )


def compare_to_measurement(
    model: Any, measurement: Measurement, outputs=None, *, X0=None
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
    X0 : array_like, optional
        The state at the record's first sample (the quarter car's
        ``vs, q, xs, xu``; a `VehicleModel`'s state order). By default the
        car at rest in equilibrium with the first input samples, as a
        held-out record starts; an identification's own record starts from
        ``ident.x0``, the state its fit started from, so that the fit here
        is the one it reports.

    Returns
    -------
    MeasurementComparison
        The fit per output and the figures (records, residuals, PSDs).
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
    y = _outputs(model, measurement, wanted, None if X0 is None else np.asarray(X0, float))
    measured = {k: measurement[k] for k in wanted}
    simulated = {k: y[i] for i, k in enumerate(wanted)}
    fit = pd.Series({k: nrmse_fit(measured[k], simulated[k]) for k in wanted}, name="fit [%]")
    return MeasurementComparison(measurement.t, measured, simulated, fit)
