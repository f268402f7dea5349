r"""ISO 2631-1 weighted RMS on an ISO 8608 road, exactly: every axis, every linear car.

On white road velocity of intensity ``q`` (an ISO 8608 road of waviness 2
at constant speed, `qc_control.ride.road.iso8608_intensity`), the car of
`qc_control.ride.spectral.white_velocity_system`, ``x̃' = A x̃ + A⁻¹B_r w``,
has a stationary acceleration ``a = c x̃`` on each ISO axis (``c`` a row of
its ``C``, or a combination: the seat's fore-aft ``x = -h θ''``). Put in
series with the axis's Annex A weighting ``(A_w, b_w, c_w, d_w)``
(`qc_control.weighting`), the augmented system

.. math:: A_c = \begin{bmatrix} A & 0 \\ b_w c & A_w \end{bmatrix}, \quad
          B_c = \begin{bmatrix} A^{-1} B_r \\ 0 \end{bmatrix}, \quad
          c_c = [\,d_w c \;\; c_w\,]

gives the weighted RMS ``a_w = (q · c_c P c_cᵀ)^½`` with
``A_c P + P A_cᵀ + B_c B_cᵀ = 0`` (Lyapunov): exact over the unbounded
band, no simulation. The tracks are independent white road velocities, as
in `qc_control.ride.spectral.white_velocity_variances` (a rear wheel
following the front one a wheelbase later is not represented).
"""

from __future__ import annotations

import functools

import control
import numpy as np

from ..models.vehicle import VehicleModel
from ..numerics import checks
from ..numerics.checks import ParameterError
from .assessment import AXES
from .guidance import AXIS_RULES, POSTURES
from .iso2631 import weighting
from .spectral import lyapunov_variances, white_velocity_system

__all__ = ["spectral_axis_rms", "spectral_a_v"]


@functools.lru_cache(maxsize=8)
def _weighting_matrices(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    sys = control.ss(weighting(name))
    A, B, C, D = (np.asarray(getattr(sys, k), dtype=float) for k in "ABCD")
    return A, B[:, 0], C[0], float(D[0, 0])


def _axis_rows(model: VehicleModel, C: np.ndarray, seat) -> dict[str, np.ndarray]:
    """Each ISO axis's acceleration as rows ``(..., n)`` of the car's ``C``."""
    labels = list(model.system.output_labels)
    rows = {"z": C[..., labels.index(model.body_acc), :]}
    if "pitch_acc" in labels:  # ISO ry is nose down; the cars count pitch nose up
        rows["ry"] = -C[..., labels.index("pitch_acc"), :]
    if "roll_acc" in labels:
        rows["rx"] = C[..., labels.index("roll_acc"), :]
    if seat is not None:
        h = checks.finite("seat", seat, "m", description="seat height above the pitch/roll axes")
        if "ry" in rows:
            rows["x"] = h * rows["ry"]
        if "rx" in rows:
            rows["y"] = -h * rows["rx"]
    return rows


def _weighted_variance(A, Bw, c, name: str, q: float):
    """``q c_c P c_cᵀ`` of the car's row ``c`` in series with weighting ``name``."""
    Aw, bw, cw, dw = _weighting_matrices(name)
    n, nw = A.shape[-1], Aw.shape[0]
    batch = A.shape[:-2]
    Ac = np.zeros(batch + (n + nw, n + nw))
    Ac[..., :n, :n] = A
    Ac[..., n:, :n] = bw[:, None] * c[..., None, :]
    Ac[..., n:, n:] = Aw
    Bc = np.zeros(batch + (n + nw, Bw.shape[-1]))
    Bc[..., :n, :] = Bw
    Cc = np.zeros(batch + (1, n + nw))
    Cc[..., 0, :n] = dw * c
    Cc[..., 0, n:] = cw
    return q * lyapunov_variances(Ac, Bc, Cc)[..., 0]


def spectral_axis_rms(
    model: VehicleModel,
    intensity: float,
    *,
    seat: float | None = None,
    posture: str = "seated",
    batch=None,
) -> dict:
    """Exact stationary ISO 2631-1 weighted RMS ``a_w`` of each axis on white road velocity.

    Parameters
    ----------
    model : VehicleModel
        A linear car with road inputs (``road=True``).
    intensity : float
        ``q`` [m²/s], e.g. ``ISO8608Road('C', speed=20).intensity``.
    seat : float, optional
        Seat height above the pitch and roll axes [m]: adds ``x`` and ``y``
        (as `qc_control.ride.assessment.axis_signals` derives them).
    posture : {'seated', 'standing'}
        The weighting of each axis (`qc_control.ride.guidance.AXIS_RULES`).
    batch : BatchedModel, optional
        Many designs: each value is then an array ``(m,)``.

    Returns
    -------
    dict[str, float or ndarray]
        ``a_w`` by axis, in ISO order: m/s² for x, y, z; rad/s² for rx, ry.

    Examples
    --------
    >>> from qc_control.models.quarter import quarter_car_model
    >>> from qc_control.ride.road import ISO8608Road
    >>> q = ISO8608Road("C", speed=20.0).intensity
    >>> round(spectral_axis_rms(quarter_car_model(road=True), q)["z"], 3)
    0.665
    """
    q = checks.positive("intensity", intensity, "m²/s")
    posture = checks.choice("posture", posture, POSTURES)
    A, Bw, C, gain = white_velocity_system(model, batch)
    rules = AXIS_RULES[posture]
    rows = _axis_rows(model, C, seat)
    out: dict = {}
    for axis in (a for a in AXES if a in rows and a in rules):
        var = _weighted_variance(A, Bw, rows[axis], rules[axis].weighting, q)
        out[axis] = float(np.sqrt(var)) if np.ndim(var) == 0 else np.sqrt(var)
    if not out:
        raise ParameterError("posture", posture, f"a posture with the axes of {model.name!r}")
    return out


def spectral_a_v(per_axis, posture: str = "seated"):
    """The vibration total value ``(Σ k² a_w²)^½`` (ISO 2631-1:1997 §6.5, k of
    §8.2.3) of `spectral_axis_rms`' values [m/s²]."""
    rules = AXIS_RULES[checks.choice("posture", posture, POSTURES)]
    return np.sqrt(sum((rules[a].k_comfort * v) ** 2 for a, v in per_axis.items()))
