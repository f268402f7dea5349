r"""A ride assessed as ISO 2631-1:1997 assesses it: per axis, combined, in the standard's words.

For each axis the acceleration is weighted by its Annex A weighting
(`qc_control.weighted`, exact for an input linear between samples) and
reduced as §6 defines (``a_w(t)`` the weighted signal over ``[0, T]``):

.. math::

    a_w = \Big(\frac1T \int_0^T a_w^2(t)\,dt\Big)^{1/2} \ \text{(§6.1, eq. 1)},
    \qquad
    a_w(t_0) = \Big(\frac1τ \int_{t_0-τ}^{t_0} a_w^2(t)\,dt\Big)^{1/2},\
    \mathrm{MTVV} = \max_{t_0} a_w(t_0) \ \text{(§6.3.1, eqs. 2, 4)},

.. math::

    \mathrm{VDV} = \Big(\int_0^T a_w^4(t)\,dt\Big)^{1/4} \ \text{(§6.3.2, eq. 5)},
    \qquad
    a_v = \Big(\sum_{axes} k^2 a_w^2\Big)^{1/2} \ \text{(§6.5)},
    \qquad
    \mathrm{MSDV}_z = \Big(\int_0^T a_{wf}^2(t)\,dt\Big)^{1/2} \ \text{(§9.2.2)},

with τ = 1 s, the crest factor ``max |a_w| / a_w`` (§6.2.1), every integral
by the trapezoidal rule on the samples. `qc_control.ride.guidance` holds
the judgement: the axis rules, the comfort scale, health and sickness.

A response of a car gives its axes by the model's roles: ``z`` is the
body's (seat's) vertical acceleration; a half or full car's pitch and roll
accelerations are the seat-surface rotations ``ry`` and ``rx`` (ISO axes:
x forward, y left, z up, right-handed; the cars count pitch nose up, so
``ry = -pitch_acc``, ``rx = roll_acc``), and a seat ``h`` above the pitch
and roll axes moves fore-aft and sideways with them:
``a_x = h·a_ry = -h·θ''``, ``a_y = -h·a_rx = -h·φ''`` (small angles; the
kinematic acceleration of the seat point, the tilt's share of gravity left
out).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..models.registry import model_for_system
from ..models.vehicle import VehicleModel
from ..numerics import checks
from ..numerics.checks import ParameterError
from ..numerics.integrate import uniform_step
from . import guidance
from .guidance import AXIS_RULES, HealthGuidance
from .iso2631 import band_top, weighted

__all__ = [
    "AxisAssessment",
    "RideAssessment",
    "ride_assessment",
    "running_rms",
    "AXES",
    "axis_signals",
]

#: The axes ISO 2631-1 names (§5.2, Figure 1): translations and rotations.
AXES = ("x", "y", "z", "rx", "ry", "rz")


def running_rms(aw, T, tau: float = guidance.RUNNING_RMS_WINDOW) -> tuple[np.ndarray, np.ndarray]:
    """The running RMS of §6.3.1, eq. (2), linear integration over ``tau`` [s].

    .. math:: a_w(t_0) = \\Big(\\frac1τ \\int_{t_0-τ}^{t_0} a_w^2(t)\\,dt\\Big)^{1/2},
              \\quad t_0 \\in [t_{start} + τ, t_{end}]

    ``∫ a_w²`` is the trapezoidal cumulative integral, read at ``t_0 - τ``
    by linear interpolation (exact for the trapezoid's piecewise-linear
    ``a_w²`` when τ is a whole number of steps).

    Parameters
    ----------
    aw : array_like, shape (N,) or (m, N)
        Weighted accelerations on ``T``.
    T : array_like, shape (N,)
        Increasing times [s], spanning at least ``tau``.
    tau : float, default 1
        The integration time [s] (§6.3.1 recommends 1 s).

    Returns
    -------
    t0, rms : ndarray
        The times [s] at which a whole window lies in ``T``, ``(K,)``, and the
        running RMS there, ``(K,)`` or ``(m, K)``.
    """
    T = np.asarray(T, dtype=float)
    tau = checks.positive("tau", tau, "s")
    if T[-1] - T[0] < tau * (1 - 1e-9):
        raise ParameterError(
            "T", f"{T[-1] - T[0]:g} s", f"a record of at least the running RMS's {tau:g} s window"
        )
    sq = np.asarray(aw, dtype=float) ** 2
    steps = 0.5 * (sq[..., 1:] + sq[..., :-1]) * np.diff(T)
    cum = np.concatenate([np.zeros(sq.shape[:-1] + (1,)), np.cumsum(steps, axis=-1)], axis=-1)
    keep = T >= T[0] + tau - 1e-9 * tau
    t0 = T[keep]
    back = t0 - tau
    i = np.clip(np.searchsorted(T, back, side="right") - 1, 0, T.size - 2)
    w = np.clip((back - T[i]) / (T[i + 1] - T[i]), 0.0, 1.0)
    before = cum[..., i] * (1 - w) + cum[..., i + 1] * w
    inside = cum[..., keep] - before
    return t0, np.sqrt(np.maximum(inside, 0.0) / tau)


def _trapezoid(v: np.ndarray, dt: float) -> float:
    return float(dt * (v.sum() - 0.5 * (v[0] + v[-1])))


@dataclass(frozen=True)
class AxisAssessment:
    """One axis of a ride, reduced as ISO 2631-1:1997 §6 defines.

    Attributes
    ----------
    axis : str
        ``'x'``, ``'y'``, ``'z'``, ``'rx'``, ``'ry'`` or ``'rz'``.
    weighting : str
        The Annex A weighting applied.
    unit : str
        ``'m/s²'`` (translation) or ``'rad/s²'`` (rotation).
    a_w : float
        Weighted RMS (§6.1, eq. 1) [unit].
    peak : float
        ``max |a_w(t)|`` [unit].
    crest_factor : float
        ``peak / a_w`` [-] (§6.2.1).
    mtvv : float
        Maximum transient vibration value, the largest 1 s running RMS
        (§6.3.1, eq. 4) [unit].
    vdv : float
        Vibration dose value (§6.3.2, eq. 5) [unit·s^0.25].
    duration : float
        The measured period T [s].
    k : float
        The comfort multiplying factor of the axis [-] or [m/rad].
    clauses : Mapping[str, str]
        Per quantity, the clause it follows.
    """

    axis: str
    weighting: str
    unit: str
    a_w: float
    peak: float
    crest_factor: float
    mtvv: float
    vdv: float
    duration: float
    k: float
    clauses: Mapping[str, str] = field(default_factory=dict, repr=False)

    @property
    def mtvv_ratio(self) -> float:
        """``MTVV / a_w`` (§6.3.3, eq. 6)."""
        return self.mtvv / self.a_w if self.a_w > 0 else float("nan")

    @property
    def vdv_ratio(self) -> float:
        """``VDV / (a_w T^¼)`` (§6.3.3, eq. 7)."""
        scale = self.a_w * self.duration**0.25
        return self.vdv / scale if scale > 0 else float("nan")


_AXIS_CLAUSES = {
    "a_w": "ISO 2631-1:1997 §6.1, eq. (1)",
    "crest_factor": "ISO 2631-1:1997 §6.2.1",
    "mtvv": "ISO 2631-1:1997 §6.3.1, eqs. (2)-(4), τ = 1 s",
    "vdv": "ISO 2631-1:1997 §6.3.2, eq. (5)",
}


def _assess_axis(axis: str, aw: np.ndarray, T: np.ndarray, dt: float, rule) -> AxisAssessment:
    span = float(T[-1] - T[0])
    rms = float(np.sqrt(_trapezoid(aw * aw, dt) / span))
    peak = float(np.max(np.abs(aw)))
    _, running = running_rms(aw, T)
    sq = aw * aw
    return AxisAssessment(
        axis=axis,
        weighting=rule.weighting,
        unit=rule.unit,
        a_w=rms,
        peak=peak,
        crest_factor=peak / rms if rms > 0 else float("nan"),
        mtvv=float(running.max()),
        vdv=_trapezoid(sq * sq, dt) ** 0.25,
        duration=span,
        k=rule.k_comfort,
        clauses={**_AXIS_CLAUSES, "weighting": rule.clause},
    )


@dataclass(frozen=True)
class RideAssessment:
    """A ride assessed to ISO 2631-1:1997: per axis, combined, and judged.

    ``assessment["z"]`` is an `AxisAssessment`. Every number is in SI units
    and carries its clause in `clauses`; `verdict` says it in words.

    Attributes
    ----------
    axes : Mapping[str, AxisAssessment]
    posture : str
    a_v : float
        Vibration total value for comfort ``(Σ k² a_w²)^½`` over the
        assessed axes [m/s²] (§6.5, factors of §8.2).
    msdv : float or None
        Motion sickness dose value of the vertical, Wf-weighted [m/s^1.5]
        (§9.2.2); None without a ``z`` axis.
    illness : float or None
        Annex D's estimate of the percentage who may vomit,
        ``K_m MSDV_z`` with ``K_m = 1/3`` (mixed adult population) [%].
    crest_factor : float
        The largest crest factor over the axes [-].
    additional_methods : bool
        Whether §6.2 / §6.3.3 call for MTVV and VDV: a crest factor over
        9, ``MTVV/a_w > 1.5`` or ``VDV/(a_w T^¼) > 1.75`` on any axis.
    triggers : tuple of str
        Which of those held, on which axis, in words.
    comfort : tuple of str
        Annex C.2.3's labels for ``a_v`` (overlapping bands: all that hold).
    health : HealthGuidance
        Annex B's caution zone for the given exposure, or what it needs.
    notes : tuple of str
        What was derived or left out (e.g. no seat height: no x, y).
    clauses : Mapping[str, str]
    """

    axes: Mapping[str, AxisAssessment]
    posture: str
    a_v: float
    msdv: float | None
    illness: float | None
    crest_factor: float
    additional_methods: bool
    triggers: tuple[str, ...]
    comfort: tuple[str, ...]
    health: HealthGuidance
    notes: tuple[str, ...] = ()
    clauses: Mapping[str, str] = field(default_factory=dict, repr=False)

    def __getitem__(self, axis: str) -> AxisAssessment:
        if axis not in self.axes:
            raise KeyError(f"axis {axis!r} was not assessed; assessed: {', '.join(self.axes)}")
        return self.axes[axis]

    def __iter__(self):
        return iter(self.axes)

    def to_pandas(self) -> pd.DataFrame:
        """One row per axis: weighting, k, a_w, peak, crest factor, MTVV, VDV,
        each column named with its unit (``'a_w'`` and ``'mtvv'`` in the axis's
        unit: m/s² for translations, rad/s² for rotations; see ``unit``)."""
        rows = {
            axis: {
                "weighting": a.weighting,
                "k": a.k,
                "unit": a.unit,
                "a_w": a.a_w,
                "peak": a.peak,
                "crest_factor [-]": a.crest_factor,
                "mtvv": a.mtvv,
                "mtvv/a_w [-]": a.mtvv_ratio,
                "vdv [unit·s^¼]": a.vdv,
                "vdv/(a_w T^¼) [-]": a.vdv_ratio,
            }
            for axis, a in self.axes.items()
        }
        frame = pd.DataFrame.from_dict(rows, orient="index")
        frame.index.name = "axis"
        return frame

    def summary(self) -> pd.DataFrame:
        """The whole-ride numbers, one row each: ``value``, ``unit`` and the
        ``clause`` it follows (what a report cites beside each)."""
        h = self.health
        verdict = f"{h.rms_verdict} the caution zone" if h.rms_verdict else h.note
        rows = [
            ("a_v", self.a_v, "m/s²", self.clauses["a_v"]),
            ("comfort", " / ".join(self.comfort), "", self.clauses["comfort"]),
            ("crest_factor", self.crest_factor, "-", self.clauses["crest_factor"]),
            ("additional_methods", self.additional_methods, "", self.clauses["additional_methods"]),
            ("msdv_z", self.msdv, "m/s^1.5", self.clauses["msdv"]),
            ("illness", self.illness, "%", self.clauses["illness"]),
            ("health k·a_w", h.a_w, "m/s²", h.clause),
            ("health zone", h.zone, "m/s²", h.clause),
            # 'in' alone does not say in what: the caution zone of Figure B.1
            ("health verdict", verdict, "", h.clause),
        ]
        frame = pd.DataFrame(rows, columns=["quantity", "value", "unit", "clause"])
        return frame.set_index("quantity")

    @property
    def verdict(self) -> tuple[str, ...]:
        """The findings in the standard's words, one sentence each, with clauses.

        Where the additional methods are the assessment (§6.2, §6.3.3: a
        shock), the sentence giving MTVV and VDV comes first, the RMS-based
        a_v and comfort words after it; otherwise a_v leads."""
        c = self.clauses
        rms = (
            f"vibration total value a_v = {self.a_v:.3g} m/s² ({c['a_v']}): "
            f"{' / '.join(self.comfort)} ({c['comfort']})"
        )
        if self.additional_methods:
            # the axes the triggers name, each with its own values: the largest crest
            # factor may be on an axis whose RMS suffices
            shocks = "; ".join(
                f"{a.axis}: MTVV = {a.mtvv:.3g} {a.unit}, VDV = {a.vdv:.3g} {a.unit}·s^¼"
                for a in self.axes.values()
                if _exceeded(a)
            )
            out = [
                f"{'; '.join(self.triggers)}: the RMS underestimates the shocks, and the "
                f"assessment is MTVV and VDV ({shocks}) ({c['additional_methods']})",
                rms,
            ]
        else:
            out = [
                rms,
                f"crest factor {self.crest_factor:.3g} <= 9 and the ratios of §6.3.3 within "
                f"their limits: the basic (RMS) method suffices ({c['additional_methods']})",
            ]
        if self.msdv is not None:
            out.append(
                f"MSDV_z = {self.msdv:.3g} m/s^1.5 ({c['msdv']}): about "
                f"{self.illness:.2g} % may vomit ({c['illness']})"
            )
        h = self.health
        if h.rms_verdict is not None and h.zone is not None and h.duration is not None:
            out.append(
                f"health, {h.duration / 3600:.3g} h a day: k·a_w = {h.a_w:.3g} m/s² ({h.axis}) "
                f"is {h.rms_verdict} the caution zone {h.zone[0]:.3g}-{h.zone[1]:.3g} m/s², "
                f"daily VDV {h.vdv:.3g} m/s^1.75 {h.vdv_verdict} 8.5-17 ({h.clause})"
            )
        else:
            out.append(f"health: {h.note} ({h.clause})")
        return tuple(out + list(self.notes))


_CLAUSES = {
    "a_v": "ISO 2631-1:1997 §6.5, k of §8.2",
    "comfort": "ISO 2631-1:1997 Annex C.2.3",
    "msdv": "ISO 2631-1:1997 §9.2.2 (Wf)",
    "illness": "ISO 2631-1:1997 Annex D, K_m = 1/3",
    "additional_methods": "ISO 2631-1:1997 §6.2, §6.3.3 eqs. (6), (7)",
    "crest_factor": "ISO 2631-1:1997 §6.2.1",
}


def _grid(T, n: int) -> tuple[np.ndarray, float]:
    if T is None:
        raise ParameterError("T", T, "the time grid [s] of the acceleration samples")
    T = np.asarray(T, dtype=float)
    if T.ndim != 1 or T.size < 2 or not np.isfinite(T).all():
        raise ParameterError("T", T, "a finite, uniform time grid [s] of two samples or more")
    dt = uniform_step(T)
    if dt is None or dt <= 0:
        raise ParameterError("T", T, "a uniform, increasing time grid [s]")
    if T.size != n:
        raise ParameterError("T", f"{T.size} samples", f"one time per sample ({n})")
    if T[-1] - T[0] < guidance.RUNNING_RMS_WINDOW * (1 - 1e-9):
        raise ParameterError(
            "T",
            f"{T[-1] - T[0]:g} s",
            "a record of at least the running RMS's 1 s window (ISO 2631-1 §6.3.1)",
        )
    return T, dt


def _checked_signals(signals: Mapping, posture: str) -> dict[str, np.ndarray]:
    rules = AXIS_RULES[posture]
    out = {}
    for axis, values in signals.items():
        if axis not in AXES:
            raise ParameterError("axis", axis, f"one of ISO 2631-1's axes {', '.join(AXES)}")
        if axis not in rules:
            raise ParameterError(
                "axis", axis, f"an axis ISO 2631-1 assesses {posture}: {', '.join(rules)}"
            )
        a = np.asarray(values, dtype=float)
        if a.ndim != 1:
            raise ParameterError(axis, f"shape {a.shape}", "one acceleration sample per time")
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise ParameterError(axis, f"{a[bad[0]]} at sample {bad[0]}", "finite samples")
        out[axis] = a
    if not out:
        raise ParameterError("signals", signals, "at least one axis of acceleration samples")
    lengths = {a.size for a in out.values()}
    if len(lengths) > 1:
        raise ParameterError(
            "signals", {k: v.size for k, v in out.items()}, "the same number of samples per axis"
        )
    return out


def _check_band(axis: str, name: str, dt: float) -> None:
    top = band_top(name)
    if 1 / (2 * dt) < top:
        raise ParameterError(
            "T",
            f"step {dt:g} s",
            f"a step of at most {1 / (2 * top):g} s for {axis}: its weighting {name} "
            f"reaches {top:g} Hz",
        )


def ride_assessment(
    signals_or_response,
    *,
    T=None,
    seat: float | None = None,
    posture: str = "seated",
    duration: float | None = None,
    model: VehicleModel | None = None,
) -> RideAssessment:
    """Assess a ride to ISO 2631-1:1997: per-axis values, a_v, MSDV, comfort, health.

    Parameters
    ----------
    signals_or_response : Mapping[str, array_like] or control.TimeResponseData
        Accelerations by axis (``'x'``, ``'y'``, ``'z'`` [m/s²], ``'rx'``,
        ``'ry'``, ``'rz'`` [rad/s²]) on ``T``; or a response of a car
        (`axis_signals` reads its axes by the model's roles).
    T : array_like, optional
        The uniform time grid [s] of a mapping, at least 1 s long (the
        running RMS's window) and fine enough for each axis's weighting.
    seat : float, optional
        A response's seat height above the pitch and roll axes [m]: gives
        ``x`` and ``y`` of a half or full car. None: no fore-aft or lateral.
    posture : {'seated', 'standing'}
        Selects the axes, weightings and factors (§7.2, §8.2).
    duration : float, optional
        Daily exposure [s] for Annex B's health guidance (10 min to 24 h).
    model : VehicleModel, optional
        The car of a response (default: found by its signal labels).

    Returns
    -------
    RideAssessment

    Raises
    ------
    qc_control.ParameterError
        An axis the standard does not have (or not for ``posture``), a
        record shorter than 1 s, a step too coarse for a weighting's band,
        a non-finite sample, axes or ``T`` of different lengths.

    Examples
    --------
    A 5 Hz vertical sine of 1 m/s² for 10 s: ``a_w ≈ |Wk(5 Hz)|/√2`` (the
    filter's start-up included), "fairly uncomfortable" (Annex C.2.3).

    >>> import numpy as np
    >>> T = np.arange(0.0, 10.0, 0.001)
    >>> result = ride_assessment({"z": np.sin(2 * np.pi * 5 * T)}, T=T)
    >>> round(result["z"].a_w, 3), result.comfort
    (0.732, ('fairly uncomfortable',))
    """
    posture = checks.choice("posture", posture, guidance.POSTURES)
    notes: tuple[str, ...] = ()
    if isinstance(signals_or_response, Mapping):
        raw = dict(signals_or_response)
    else:
        raw, T, notes = axis_signals(signals_or_response, seat=seat, model=model)
        unused = [axis for axis in raw if axis not in AXIS_RULES[posture]]
        if unused:  # a car's rotations are not assessed standing (§8.2)
            raw = {k: v for k, v in raw.items() if k not in unused}
            notes += (f"{', '.join(unused)}: not assessed {posture} (ISO 2631-1 §8.2)",)
    signals = _checked_signals(raw, posture)
    T, dt = _grid(T, next(iter(signals.values())).size)
    rules = AXIS_RULES[posture]
    axes = {}
    for axis in (a for a in AXES if a in signals):
        _check_band(axis, rules[axis].weighting, dt)
        aw = weighted(signals[axis], T, rules[axis].weighting)
        axes[axis] = _assess_axis(axis, aw, T, dt, rules[axis])
    return _judged(axes, signals, T, dt, posture, duration, notes)


def _judged(axes, signals, T, dt, posture, duration, notes) -> RideAssessment:
    a_v = float(np.sqrt(sum((a.k * a.a_w) ** 2 for a in axes.values())))
    msdv = illness = None
    if "z" in signals:
        _check_band("z", "Wf", dt)
        awf = weighted(signals["z"], T, "Wf")
        msdv = float(np.sqrt(_trapezoid(awf * awf, dt)))
        illness = guidance.ILLNESS_CONSTANT * msdv
    crest = max(a.crest_factor for a in axes.values())
    triggers = _triggers(axes.values())
    span = float(T[-1] - T[0])
    health = guidance.health_guidance(
        {k: (a.a_w, a.vdv) for k, a in axes.items()}, posture, span, duration
    )
    # in the order of the fields
    judged = (crest, bool(triggers), triggers, guidance.comfort_labels(a_v), health)
    return RideAssessment(axes, posture, a_v, msdv, illness, *judged, notes, dict(_CLAUSES))


def _exceeded(a: AxisAssessment) -> list[tuple[str, float, float]]:
    """The §6.2 / §6.3.3 conditions an axis meets: ``(what, value, limit)``."""
    return [
        (what, value, limit)
        for what, value, limit in (
            ("crest factor", a.crest_factor, guidance.CREST_FACTOR_LIMIT),
            ("MTVV/a_w", a.mtvv_ratio, guidance.MTVV_RATIO_LIMIT),
            ("VDV/(a_w T^¼)", a.vdv_ratio, guidance.VDV_RATIO_LIMIT),
        )
        if value > limit
    ]


def _triggers(axes) -> tuple[str, ...]:
    """The §6.2 / §6.3.3 conditions that call for the additional methods, in words."""
    return tuple(
        f"{what} {value:.3g} > {limit:g} on {a.axis}"
        for a in axes
        for what, value, limit in _exceeded(a)
    )


#: A car's angular accelerations: (output label, velocity state, ISO axis, sign).
_ROTATIONS = (("pitch_acc", "vtheta", "ry", -1.0), ("roll_acc", "vphi", "rx", 1.0))


def axis_signals(response, *, seat: float | None = None, model: VehicleModel | None = None):
    """A car's response as ISO 2631-1 axes: ``(signals, T, notes)``.

    ``z`` is the model's body (seat) acceleration (``roles.body_acc``). A
    car that pitches or rolls gives ``ry = -pitch_acc`` and
    ``rx = roll_acc`` [rad/s²] (module docstring for the signs): its
    output if the response has it, else exactly the velocity state's
    derivative ``A[row] x + B[row] u`` from the response's states and
    inputs (never a numerical derivative). With ``seat`` = h [m]:
    ``x = h·ry`` and ``y = -h·rx``.
    """
    exact = model is not None  # the matrices are this car's only when given
    if model is None:
        entry = model_for_system(response)
        if entry is None:
            raise ParameterError(
                "signals_or_response",
                type(response).__name__,
                "a mapping of axes to accelerations, or a response of a registered car "
                "(or give model=)",
            )
        model = entry.model(road=any(str(u).startswith("zr") for u in response.input_labels))
    T = np.asarray(response.time, dtype=float)
    outputs = _traces(response.outputs, response.output_labels, T.size)
    if model.body_acc not in outputs:
        raise ParameterError("signals_or_response", list(outputs), f"an output {model.body_acc!r}")
    signals = {"z": outputs[model.body_acc]}
    for label, state, axis, sign in _ROTATIONS:
        rate = (
            _angular(response, model, outputs, label, state, T.size)
            if exact or (label in outputs)
            else None
        )
        if rate is not None:
            signals[axis] = sign * rate
    notes = []
    if seat is not None and ("rx" in signals or "ry" in signals):
        h = checks.finite("seat", seat, "m", description="seat height above the pitch/roll axes")
        if "ry" in signals:
            signals["x"] = h * signals["ry"]
        if "rx" in signals:
            signals["y"] = -h * signals["rx"]
        notes.append(f"the seat's x and y are its motion {h:g} m above the pitch and roll axes")
    elif "rx" in signals or "ry" in signals:
        notes.append("no seat height (seat=): the fore-aft and lateral axes are not assessed")
    elif seat is not None:
        notes.append(f"{model.name!r} neither pitches nor rolls: the seat height is not used")
    return signals, T, tuple(notes)


def _traces(values, labels, n: int) -> dict[str, np.ndarray]:
    y = np.asarray(values, dtype=float).reshape(len(labels), -1)
    if y.shape[1] != n:
        raise ParameterError("signals_or_response", f"shape {y.shape}", "one trace of the outputs")
    return {str(label): y[i] for i, label in enumerate(labels)}


def _angular(response, model, outputs, label, state, n) -> np.ndarray | None:
    if label in outputs:
        return outputs[label]
    sys = model.system
    if state not in sys.state_labels or model.is_nonlinear:
        return None
    x = getattr(response, "states", None)
    states = list(getattr(response, "state_labels", None) or [])
    if x is None or states[: sys.nstates] != list(sys.state_labels):
        return None
    row = list(sys.state_labels).index(state)
    X = np.asarray(x, dtype=float).reshape(len(states), -1)[: sys.nstates]
    out = np.asarray(sys.A, dtype=float)[row] @ X
    if sys.ninputs:
        inputs = _traces(response.inputs, response.input_labels, n)
        B = np.asarray(sys.B, dtype=float)[row]
        out = out + sum(B[j] * inputs[u] for j, u in enumerate(sys.input_labels) if u in inputs)
    return out
