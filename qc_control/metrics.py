"""The ride-metric registry: each metric defined once, batched over designs.

A metric has a name, a unit and one batched formula ``f(signals, corner)``
that maps the responses of ``m`` designs (a `RideSignals`) to ``m`` values.
`qc_control.ride_metrics` (one response) and `qc_control.sweep` (thousands)
both evaluate the formulas here, so their columns carry the same names:
``"rms_body_acc [m/s²]"`` is the same number from either.

A metric about a wheel (``per_corner``) is evaluated at every corner of the
model, with the corner's name in its column (``"peak_susp_travel front [m]"``
on a half car, ``"peak_susp_travel [m]"`` on a quarter car).

Add a metric by adding one `Metric` to `METRICS`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .iso2631 import wk_weighted
from .vehicle import Corner, SignalRoles

__all__ = [
    "Metric",
    "RideSignals",
    "METRICS",
    "RIDE_METRICS",
    "SWEEP_METRICS",
    "mean_square",
    "peak",
    "evaluate",
    "metric_columns",
]


def mean_square(v: np.ndarray) -> np.ndarray:
    """Trapezoidal time mean of ``v²`` along the last axis of a uniform grid.

    .. math:: \\overline{v^2} = \\frac{1}{N-1}\\Big(\\sum_{k=0}^{N-1} v_k^2
              - \\frac{v_0^2 + v_{N-1}^2}{2}\\Big)
              = \\frac{1}{t_{N-1} - t_0}\\int v^2\\,dt \\ \\text{(trapezoidal)}

    (no ``v²`` temporary: one dot product per signal).
    """
    squares = np.vecdot(v, v) - 0.5 * (v[..., 0] ** 2 + v[..., -1] ** 2)
    return squares / (v.shape[-1] - 1)


def peak(v: np.ndarray) -> np.ndarray:
    """``max |v|`` along the last axis, without an ``|v|`` temporary."""
    return np.maximum(v.max(axis=-1), -v.min(axis=-1))


class RideSignals:
    """What a metric sees: the responses of ``m`` designs of one model.

    Parameters
    ----------
    T : ndarray, shape (N,)
        The uniform time grid [s].
    outputs : Mapping[str, ndarray]
        Output label -> samples of shape ``(m, N)``.
    roles : SignalRoles
        Which labels are the body acceleration and the wheels
        (``VehicleModel.roles``).
    tire_stiffness, static_load : sequence of ndarray (m,), optional
        Per corner, each design's tire stiffness [N/m] and static wheel load
        [N]; by default the model's own (every design the same).
    """

    def __init__(
        self,
        T: np.ndarray,
        outputs: Mapping[str, np.ndarray],
        roles: SignalRoles,
        tire_stiffness: Sequence[np.ndarray] | None = None,
        static_load: Sequence[np.ndarray] | None = None,
    ):
        self.T = T
        self.outputs = outputs
        self.roles = roles
        self.tire_stiffness = (
            tuple(np.asarray(c.tire_stiffness) for c in roles.corners)
            if tire_stiffness is None
            else tuple(tire_stiffness)
        )
        self.static_load = (
            tuple(np.asarray(c.static_load) for c in roles.corners)
            if static_load is None
            else tuple(static_load)
        )
        self._weighted: np.ndarray | None = None

    @property
    def dt(self) -> float:
        return float((self.T[-1] - self.T[0]) / (self.T.size - 1))

    def output(self, label: str) -> np.ndarray:
        """The samples ``(m, N)`` of an output, by label."""
        try:
            return self.outputs[label]
        except KeyError:
            raise ValueError(f"no output {label!r}; outputs are {list(self.outputs)}") from None

    @property
    def body_acc(self) -> np.ndarray:
        return self.output(self.roles.body_acc)

    @property
    def body_disp(self) -> np.ndarray:
        return self.output(self.roles.body_disp)

    @property
    def weighted_acc(self) -> np.ndarray:
        """ISO 2631-1 Wk-weighted body acceleration ``(m, N)``, computed once."""
        if self._weighted is None:
            self._weighted = wk_weighted(self.body_acc, self.T)
        return self._weighted

    def corner(self, i: int) -> Corner:
        return self.roles.corners[i]


def _rms(v: np.ndarray) -> np.ndarray:
    return np.sqrt(mean_square(v))


def _settling_time(s: RideSignals, _: int) -> np.ndarray:
    """First time after which the body stays within 2 % of its largest
    excursion from its final value (the 2 % settling criterion)."""
    T, y = s.T, s.body_disp
    dev = y - y[..., -1:]
    np.abs(dev, out=dev)
    outside = dev > 0.02 * dev.max(axis=-1, keepdims=True)
    # the last sample outside, found from the end on a reversed view (no copy)
    from_end = np.argmax(outside[..., ::-1], axis=-1)
    settle = np.minimum(np.where(outside.any(axis=-1), T.size - from_end, 0), T.size - 1)
    return T[settle]


def _lifted(s: RideSignals, i: int) -> np.ndarray:
    """Samples where the dynamic tire load ``-kt·tire_defl`` unloads the tire by
    more than the static load: ``kt·tire_defl > static``."""
    c = s.corner(i)
    return s.output(c.tire_defl) > (s.static_load[i] / s.tire_stiffness[i])[..., None]


def _rms_tire_load(s: RideSignals, i: int) -> np.ndarray:
    return s.tire_stiffness[i] * _rms(s.output(s.corner(i).tire_defl)) / s.static_load[i]


def _vdv(s: RideSignals, _: int) -> np.ndarray:
    return np.trapezoid(s.weighted_acc**4, s.T, axis=-1) ** 0.25


@dataclass(frozen=True)
class Metric:
    """One ride metric: a name, a unit and a batched formula.

    Attributes
    ----------
    name : str
        snake_case, the same in every table.
    unit : str
        SI unit, ``'-'`` for a ratio, ``''`` for a flag.
    description : str
        One line, with its source where there is one.
    formula : callable ``(RideSignals, corner index) -> ndarray (m,)``
    per_corner : bool
        Evaluated at every corner (a wheel's metric) or once (the body's).
    """

    name: str
    unit: str
    description: str
    formula: Callable[[RideSignals, int], np.ndarray]
    per_corner: bool = False

    def column(self, corner: Corner | None = None) -> str:
        """The column label: ``name[ corner] [unit]``."""
        where = corner.suffix() if (self.per_corner and corner is not None) else ""
        return f"{self.name}{where} [{self.unit}]" if self.unit else f"{self.name}{where}"


def _at_corner(signal: str, reduce: Callable[[np.ndarray], np.ndarray]):
    """A wheel metric's formula: ``reduce`` of the corner's ``signal`` output."""
    return lambda s, i: reduce(s.output(getattr(s.corner(i), signal)))


# fmt: off
_ALL = (
    Metric("rms_body_acc", "m/s²", "RMS body acceleration (trapezoidal time mean): comfort",
           lambda s, _: _rms(s.body_acc)),
    Metric("peak_body_acc", "m/s²", "largest |body acceleration|",
           lambda s, _: peak(s.body_acc)),
    Metric("rms_body_acc_wk", "m/s²",
           "ISO 2631-1 Wk-weighted RMS body acceleration (ISO 2631-1:1997, 6.4)",
           lambda s, _: _rms(s.weighted_acc)),
    Metric("vdv", "m/s^1.75", "vibration dose value (∫ a_w⁴ dt)^¼ (ISO 2631-1:1997, 6.3.2)",
           _vdv),
    Metric("settling_time", "s", "2 % settling time of the body displacement", _settling_time),
    Metric("rms_susp_travel", "m", "RMS suspension travel",
           _at_corner("susp_travel", _rms), per_corner=True),
    Metric("peak_susp_travel", "m", "largest |suspension travel|: the rattle space needed",
           _at_corner("susp_travel", peak), per_corner=True),
    Metric("peak_tire_defl", "m", "largest |dynamic tire deflection|",
           _at_corner("tire_defl", peak), per_corner=True),
    Metric("rms_tire_load / static", "-",
           "RMS dynamic tire load kt·|tire_defl| over the static wheel load: road holding",
           _rms_tire_load, per_corner=True),
    Metric("lift_off", "", "whether the dynamic load ever exceeds the static wheel load "
           "(the wheel would leave the road; a linear model does not represent it)",
           lambda s, i: np.asarray(_lifted(s, i).any(axis=-1)), per_corner=True),
    Metric("lift_off_duration", "s", "total time the wheel would be off the road",
           lambda s, i: np.count_nonzero(_lifted(s, i), axis=-1) * s.dt, per_corner=True),
)
# fmt: on

#: Every registered metric, by name.
METRICS: dict[str, Metric] = {m.name: m for m in _ALL}
#: What `ride_metrics` reports by default: comfort, rattle space, road holding.
RIDE_METRICS = (
    "rms_body_acc",
    "rms_body_acc_wk",
    "vdv",
    "rms_susp_travel",
    "peak_susp_travel",
    "rms_tire_load / static",
    "lift_off",
    "lift_off_duration",
)
#: What `sweep` computes by default: all but the Wk-weighted ones, which cost an
#: FFT convolution per design (about as much as the simulation itself).
SWEEP_METRICS = (
    "peak_susp_travel",
    "rms_body_acc",
    "settling_time",
    "peak_tire_defl",
    "rms_tire_load / static",
    "lift_off_duration",
)


def metric_columns(names: Sequence[str], roles: SignalRoles) -> list[tuple[str, Metric, int]]:
    """``(column, metric, corner index)`` for each named metric on a model's ``roles``.

    A metric is named by its name (``'rms_body_acc'``) or its column
    (``'rms_body_acc [m/s²]'``). Raises ``ValueError`` naming an unknown
    metric and listing the known ones.
    """
    out = []
    by_column = {m.column(): m for m in METRICS.values()}
    for name in names:
        metric = METRICS.get(name) or by_column.get(name)
        if metric is None:
            raise ValueError(f"unknown metric {name!r}; known: {', '.join(METRICS)}")
        corners = range(len(roles.corners)) if metric.per_corner else [0]
        out += [
            (metric.column(roles.corners[i] if metric.per_corner else None), metric, i)
            for i in corners
        ]
    return out


def evaluate(signals: RideSignals, names: Sequence[str]) -> dict[str, np.ndarray]:
    """Each named metric's column -> values ``(m,)`` (bool for flags)."""
    return {
        col: np.asarray(metric.formula(signals, i))
        for col, metric, i in metric_columns(names, signals.roles)
    }
