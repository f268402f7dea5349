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
the output the inputs explain. The estimate of ``H_j``, input ``j``'s
column, has a relative error of variance

.. math:: \\varepsilon_j^2 = \\frac{(1 - γ^2)\\, S_{yy}}{2 (n_d - q)\\, S_{jj·}\\, |H_j|^2},
   \\qquad S_{jj·} = 1 / [S_{uu}^{-1}]_{jj}

per real component for ``n_d`` averages and ``q`` inputs (Bendat &
Piersol, §7.3 and §9.3: ``S_jj·`` is input ``j``'s auto-spectrum
conditioned on the other inputs, what of it they do not explain; for one
input this is their ``(1 - γ²) / (2 n_d γ²)``). Each bin's misfit is
divided by that standard deviation: a bin where noise or leakage rules
counts little, and so does an input's column at frequencies where that
input has no power of its own. Without the conditioned spectrum a rig's
force chirp swept over 0.5-15 Hz, with the road's random motion up to
20 Hz, gave the force's column above 15 Hz the road's coherence, near 1,
and a transmissibility estimated from no force at all: 400 s of
noise-free records then missed every parameter by 30-70 %.

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

from ..numerics.checks import positive
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
    output_power : ndarray, shape (outputs, F), optional
        Each output's auto-spectrum ``S_yy``.
    input_power : ndarray, shape (inputs, F), optional
        Each input's auto-spectrum conditioned on the others, ``S_jj·`` (module
        note): its power the other inputs do not explain.
    """

    frequency: np.ndarray
    response: np.ndarray
    coherence: np.ndarray
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    averages: int
    resolution: float
    output_power: np.ndarray | None = None
    input_power: np.ndarray | None = None


def _segment(measurement: Measurement, resolution: float | None) -> tuple[int, int]:
    """The Welch segment length for ``resolution`` and the averages it gives."""
    n, fs = len(measurement), 1.0 / measurement.dt
    if resolution is None:
        nperseg = 2 * n // (DEFAULT_AVERAGES + 1)
    else:
        # any real number, a NumPy one too (np.int64(1) was refused)
        resolution = positive("resolution", resolution, "Hz")
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
    try:
        Ht = np.linalg.solve(Suu, Suy)  # (F, q, p): Hᵀ
    except np.linalg.LinAlgError:  # numpy's "Singular matrix" names none of the records
        raise ValueError(
            f"the inputs {', '.join(inputs)} move together (their cross-spectral matrix is "
            "singular): the records cannot tell their effects apart; excite them "
            "independently, or leave one out"
        ) from None
    explained = np.einsum("fij,fij->fj", np.conj(Ht), Suy).real  # diag(H Suu Hᴴ)
    auto = np.real(np.diagonal(Syy, axis1=1, axis2=2))
    with np.errstate(invalid="ignore", divide="ignore"):
        coherence = np.clip(np.where(auto > 0, explained / auto, 0.0), 0.0, 1.0)
    # S_jj· = 1 / [S_uu⁻¹]_jj: the part of input j the other inputs do not explain
    conditioned = 1.0 / np.real(np.diagonal(np.linalg.inv(Suu), axis1=1, axis2=2))
    return Transmissibility(
        frequency=f[1:],
        response=np.transpose(Ht, (2, 1, 0)),
        coherence=coherence.T,
        inputs=inputs,
        outputs=outputs,
        averages=averages,
        resolution=float(f[1] - f[0]),
        output_power=auto.T,
        input_power=np.clip(conditioned, 0.0, None).T,
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
    """Each bin's weight ``(outputs, inputs, F)`` (module note): 1 / SD of its
    relative error, 0 outside ``band``.

    Raises
    ------
    ValueError
        For a band that holds no bin of the estimate.
    """
    f = estimate.frequency
    inside = (f >= band[0]) & (f <= band[1])
    if not inside.any():
        raise ValueError(
            f"band {band[0]:g}-{band[1]:g} Hz holds no bin of the {estimate.resolution:.4g} Hz "
            f"resolution (bins at {f[0]:.4g}, {f[0] + estimate.resolution:.4g}, ... Hz): "
            "widen the band or make the resolution finer"
        )
    q = len(estimate.inputs)
    g2 = np.minimum(estimate.coherence, COHERENCE_CAP)[:, None, :]
    dof = max(estimate.averages - q, 1)
    magnitude = np.abs(estimate.response)
    with np.errstate(divide="ignore", invalid="ignore"):
        if estimate.output_power is None or estimate.input_power is None:
            # the one-input form: the SD of H's error is |H| √((1 - γ²) / (2 n γ²))
            variance = (1.0 - g2) / (2.0 * dof * np.maximum(g2, 1e-12)) * magnitude**2
        else:  # (1 - γ²) S_yy / (2 n S_jj·): |H| cancels from the relative form
            Syy = estimate.output_power[:, None, :]
            Sjj = estimate.input_power[None, :, :]
            variance = (1.0 - g2) * Syy / (2.0 * dof * Sjj)
        w = np.where((variance > 0) & np.isfinite(variance), 1.0 / np.sqrt(variance), 0.0)
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
