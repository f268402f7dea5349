"""The transmissibility of a rig test, estimated from its records for a frequency-domain fit.

For a sine-sweep or random rig test the records' frequency response is the
natural evidence: `transmissibility` estimates it, and
``qc_control.identify(..., domain="frequency")`` fits the quarter car's
exact response (`sampled_response`) to it, each bin weighted by
`bin_weights`. The result is the same `Identification` as the time-domain
fit's, its fit table computed on the time records.

The estimate is the multi-input H1 estimator (Bendat & Piersol, *Random
Data*, 4th ed., §7.3): with every recorded input ``u`` (road ``zr`` and
force ``fa``) and an output ``y``, Welch's averaged cross-spectra give, at
each frequency,

.. math:: H(f) = S_{yu}(f)\\, S_{uu}(f)^{-1}

with ``S_uu`` the inputs' cross-spectral matrix. A rig that drives the car
by the base plate and an actuator at once needs it: the single-input
``S_yx / S_xx`` of one input counts the other input's share of the output
as that input's, a bias no averaging removes when the inputs are
correlated, and an error that needs many more averages when they are not.
The multiple coherence ``γ² = S_yu S_uu⁻¹ S_uy / S_yy`` says how much of
the output the inputs explain; the relative error of the estimate has the
variance ``(1 - γ²) / (2 (n_d - q) γ²)`` per real component for ``n_d``
averages and ``q`` inputs (Bendat & Piersol, eq. 9.90 and §9.3), so each
frequency's misfit is divided by its standard deviation: a bin where noise
or leakage rules counts little.

The fit is of complex transmissibilities (magnitude and phase: the phase
separates a stiffness from a damping), parameters as logarithms. What the
records determine (ratios only for a road-only record or a force of free
gain) and the intervals follow the time-domain fit
(`qc_control.studies.identification`); neighbouring bins of a
Hann-windowed Welch estimate with 50 % overlap are correlated, so the
intervals are narrower than the estimates' scatter.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.signal

from ..numerics.exact import exact_step_matrices
from .measurement import Measurement

__all__ = [
    "Transmissibility",
    "transmissibility",
    "sampled_response",
    "bin_weights",
    "check_band",
    "MIN_AVERAGES",
]

#: Welch averages below which a cross-spectral matrix is refused: with ``q``
#: inputs ``S_uu`` is singular below ``q`` averages, and the estimate's
#: variance ``∝ 1/(n_d - q)`` is useless within a few of it.
MIN_AVERAGES = 8
#: Coherence is capped here before weighting: a noise-free record's 1 would
#: give an infinite weight, and below this cap a bin's leakage, not noise,
#: sets its error.
COHERENCE_CAP = 0.9999
#: The default resolution gives this many Welch averages (50 % overlap).
DEFAULT_AVERAGES = 16


@dataclass
class Transmissibility:
    """The records' frequency response estimated by the multi-input H1 estimator.

    Attributes
    ----------
    frequency : ndarray, shape (F,)
        [Hz], the bins used (DC excluded).
    response : ndarray, shape (outputs, inputs, F)
        Complex ``H`` from each recorded input to each output.
    coherence : ndarray, shape (outputs, F)
        The multiple coherence of each output with all inputs.
    inputs, outputs : tuple of str
    averages : int
        The number of Welch segments averaged.
    resolution : float
        [Hz], the bin spacing.
    """

    frequency: np.ndarray
    response: np.ndarray
    coherence: np.ndarray
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    averages: int
    resolution: float


def _segment(measurement: Measurement, resolution: float | None) -> tuple[int, int]:
    """The Welch segment length for ``resolution`` and the averages it gives."""
    n, fs = len(measurement), 1.0 / measurement.dt
    if resolution is None:
        nperseg = 2 * n // (DEFAULT_AVERAGES + 1)
    else:
        if not (isinstance(resolution, (int, float)) and math.isfinite(resolution)) or (
            resolution <= 0
        ):
            raise ValueError(f"resolution must be a frequency > 0 Hz, got {resolution!r}")
        nperseg = int(math.ceil(fs / resolution))
    averages = (n - nperseg) // (nperseg // 2) + 1 if nperseg <= n and nperseg >= 2 else 0
    if averages < MIN_AVERAGES:
        duration = n * measurement.dt
        needed = (MIN_AVERAGES + 1) / 2 * nperseg / fs
        raise ValueError(
            f"the record of {duration:g} s is too short for a resolution of "
            f"{fs / max(nperseg, 1):.4g} Hz: it gives {max(averages, 0)} Welch averages, "
            f"at least {MIN_AVERAGES} are needed (a record of {needed:.4g} s or more, "
            f"or a coarser resolution)"
        )
    return nperseg, averages


def transmissibility(
    measurement: Measurement,
    inputs: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    *,
    resolution: float | None = None,
) -> Transmissibility:
    """The multi-input H1 estimate of the records' frequency response (module note).

    Parameters
    ----------
    measurement : Measurement
    inputs, outputs : sequence of str, optional
        Default every recorded input and every recorded output.
    resolution : float, optional
        Bin spacing [Hz]; default the one giving 16 Welch averages. A
        resolution the record cannot give `MIN_AVERAGES` averages of is
        refused.

    Returns
    -------
    Transmissibility

    Raises
    ------
    ValueError
        For a record too short for the resolution, or an unknown label.
    """
    inputs = tuple(measurement.inputs if inputs is None else inputs)
    outputs = tuple(measurement.outputs if outputs is None else outputs)
    for label in (*inputs, *outputs):
        if label not in measurement.signals:
            raise ValueError(f"the measurement has no signal {label!r}")
    if not inputs or not outputs:
        raise ValueError("the transmissibility needs at least one input and one output")
    nperseg, averages = _segment(measurement, resolution)
    fs = 1.0 / measurement.dt
    u = np.stack([measurement[k] for k in inputs])
    y = np.stack([measurement[k] for k in outputs])
    signals = np.concatenate([u, y])
    # every cross-spectrum S_ab = E[conj(A) B] at once: csd(x, y) estimates conj(X) Y
    f, S = scipy.signal.csd(
        signals[:, None, :], signals[None, :, :], fs=fs, nperseg=nperseg, detrend="constant"
    )
    S = np.moveaxis(S, -1, 0)[1:]  # (F, n, n), DC dropped (the rig's static offsets)
    q = len(inputs)
    Suu, Suy, Syy = S[:, :q, :q], S[:, :q, q:], S[:, q:, q:]
    # y = H u gives Suy[i, k] = E[conj(u_i) y_k] = Σ_j Suu[i, j] H[k, j]: Suu Hᵀ = Suy
    Ht = np.linalg.solve(Suu, Suy)  # (F, q, p): Hᵀ
    explained = np.einsum("fij,fij->fj", np.conj(Ht), Suy).real  # diag(H Suu Hᴴ)
    auto = np.real(np.diagonal(Syy, axis1=1, axis2=2))
    with np.errstate(invalid="ignore", divide="ignore"):
        coherence = np.clip(np.where(auto > 0, explained / auto, 0.0), 0.0, 1.0)
    return Transmissibility(
        frequency=f[1:],
        response=np.transpose(Ht, (2, 1, 0)),
        coherence=coherence.T,
        inputs=inputs,
        outputs=outputs,
        averages=averages,
        resolution=float(f[1] - f[0]),
    )


def sampled_response(A, B, C, D, frequency, dt: float) -> np.ndarray:
    """The exact frequency response ``(F, outputs, inputs)`` of ``x' = Ax + Bu``,
    ``y = Cx + Du`` between samples ``dt`` apart, the inputs linear between them.

    Records simulated or sampled under that convention (`exact_outputs`,
    ``control.forced_response``) obey, sample to sample,

    .. math:: x_{k+1} = Φ x_k + Γ_0 u_k + Γ_1 u_{k+1}, \\quad y_k = C x_k + D u_k

    whose response at ``z = e^{j2πf Δt}`` is ``C (zI - Φ)⁻¹ (Γ₀ + z Γ₁) + D``.
    It is the continuous ``C (j2πf I - A)⁻¹ B + D`` times the linear hold's
    ``sinc²(f Δt)`` (3 % at a tenth of the sampling rate) plus its aliases:
    a difference a fit would otherwise take for the system.
    """
    phi, g0, g1 = exact_step_matrices(A, B, dt)
    z = np.exp(2j * np.pi * np.asarray(frequency) * dt)[:, None, None]
    X = np.linalg.solve(z * np.eye(A.shape[0]) - phi, g0 + z * g1)
    return C @ X + D


def bin_weights(estimate: Transmissibility, band) -> np.ndarray:
    """Each bin's weight (module note): 1 / SD of its relative error, 0 outside ``band``."""
    q = len(estimate.inputs)
    g2 = np.minimum(estimate.coherence, COHERENCE_CAP)
    dof = max(estimate.averages - q, 1)
    with np.errstate(divide="ignore"):
        sd = np.sqrt((1.0 - g2) / (2.0 * dof * np.maximum(g2, 1e-12)))
    magnitude = np.abs(estimate.response)
    f = estimate.frequency
    inside = (f >= band[0]) & (f <= band[1])
    w = np.where(magnitude > 0, 1.0 / (sd[:, None, :] * np.where(magnitude > 0, magnitude, 1)), 0)
    return w * inside


def check_band(band, measurement: Measurement) -> tuple[float, float]:
    nyquist = 0.5 / measurement.dt
    if band is None:
        return 0.0, nyquist
    try:
        lo, hi = (float(b) for b in band)
    except (TypeError, ValueError):
        lo, hi = math.nan, math.nan
    if not (0 <= lo < hi <= nyquist):
        raise ValueError(
            f"band must be (f_low, f_high) in Hz with 0 <= f_low < f_high <= {nyquist:g} "
            f"(the Nyquist frequency), got {band!r}"
        )
    return lo, hi
