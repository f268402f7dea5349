"""The ride-metric registry: each metric defined once, batched over designs.

A metric has a name, a unit and one batched formula ``f(signals, corner)``
that maps the responses of ``m`` designs (a `RideSignals`) to ``m`` values.
`qc_control.ride_metrics` (one response) and `qc_control.sweep` (thousands)
both evaluate the formulas here, so their columns carry the same names:
``"rms_body_acc [m/s²]"`` is the same number from either.

A metric about a wheel (``per_corner``) is evaluated at every corner of the
model, with the corner's name in its column (``"peak_susp_travel front [m]"``
on a half car, ``"peak_susp_travel [m]"`` on a quarter car).

Add a metric by adding one `Metric` to `METRICS`. Its formula reads the
signals through reductions (mean square, peak, ...), which `RideSignals`
computes on whole responses and `MetricStream` as a sweep's blocks go by.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..models.vehicle import Corner, SignalRoles
from .assessment import running_rms
from .guidance import AXIS_RULES
from .iso2631 import weighted, wk_weighted

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
    "MetricStream",
    "WEIGHTED_ACC",
]

#: The name under which a metric reads the ISO 2631-1 Wk-weighted body
#: acceleration (`RideSignals.weighted_acc`, or the streamed filter's output).
WEIGHTED_ACC = "(Wk-weighted body acceleration)"


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
        self._by_weighting: dict[tuple[str, str], np.ndarray] = {}

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

    def weighted_output(self, label: str, name: str) -> np.ndarray:
        """An output ``(m, N)`` weighted by ISO 2631-1's ``name`` (`weighted`), once.

        A whole signal, not a reduction: a formula that reads it is not
        streamed (a sweep simulates its designs' whole responses for it).
        """
        key = (label, name)
        if key not in self._by_weighting:
            self._by_weighting[key] = weighted(self.output(label), self.T, name)
        return self._by_weighting[key]

    def corner(self, i: int) -> Corner:
        return self.roles.corners[i]

    # -- the reductions a registered metric is written with; `MetricStream`
    # -- computes the same ones block by block
    def _signal(self, label: str) -> np.ndarray:
        return self.weighted_acc if label == WEIGHTED_ACC else self.output(label)

    def mean_square(self, label: str) -> np.ndarray:
        """Trapezoidal time mean of the squared signal (`mean_square`), ``(m,)``."""
        return mean_square(self._signal(label))

    def peak(self, label: str) -> np.ndarray:
        """``max |v|`` (`peak`), ``(m,)``."""
        return peak(self._signal(label))

    def quartic_integral(self, label: str) -> np.ndarray:
        """Trapezoidal ``∫ v⁴ dt`` on the uniform grid, ``(m,)``."""
        v4 = self._signal(label) ** 4
        return self.dt * (v4.sum(axis=-1) - 0.5 * (v4[..., 0] + v4[..., -1]))

    def settling_time(self, label: str) -> np.ndarray:
        """First time after which the signal stays within 2 % of its largest
        excursion from its final value (the 2 % settling criterion), ``(m,)``."""
        T, y = self.T, self._signal(label)
        dev = y - y[..., -1:]
        np.abs(dev, out=dev)
        outside = dev > 0.02 * dev.max(axis=-1, keepdims=True)
        # the last sample outside, found from the end on a reversed view (no copy)
        from_end = np.argmax(outside[..., ::-1], axis=-1)
        settle = np.minimum(np.where(outside.any(axis=-1), T.size - from_end, 0), T.size - 1)
        return T[settle]

    def lifted_count(self, i: int) -> np.ndarray:
        """Samples where corner ``i``'s dynamic tire load ``-kt·tire_defl``
        unloads the tire by more than the static load (``kt·tire_defl > static``)."""
        lifted = self.output(self.corner(i).tire_defl) > _lift_threshold(self, i)[..., None]
        return np.count_nonzero(lifted, axis=-1)


def _lift_threshold(s, i: int) -> np.ndarray:
    """The tire deflection [m] beyond which corner ``i`` would leave the road."""
    return np.asarray(s.static_load[i] / s.tire_stiffness[i])


def _rms_tire_load(s, i: int) -> np.ndarray:
    c = s.corner(i)
    return s.tire_stiffness[i] * np.sqrt(s.mean_square(c.tire_defl)) / s.static_load[i]


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
        Written with the signals' reductions (``s.mean_square(label)``,
        ``s.peak``, ``s.quartic_integral``, ``s.settling_time``,
        ``s.lifted_count``), so that a sweep can evaluate the same formula on
        a `MetricStream`; one that reads ``s.output(label)`` whole works too,
        and sweeps then materialise their chunks for it.
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


def _at_corner(signal: str, reduction: str, then=lambda v: v):
    """A wheel metric's formula: ``then`` of the ``reduction`` of the corner's ``signal``."""
    return lambda s, i: then(getattr(s, reduction)(getattr(s.corner(i), signal)))


#: ISO 2631-1's seat-surface rotations a car may give, as outputs: ISO axis ->
#: (output label, the corner word that shows the car has it). The cars count
#: pitch nose up, ISO's ry nose down: the sign does not change an RMS.
_ROTATION_OUTPUTS = {"rx": ("roll_acc", "left"), "ry": ("pitch_acc", "rear")}


def _weighted_rms(s, label: str, name: str) -> np.ndarray:
    return np.sqrt(mean_square(s.weighted_output(label, name)))


def _rotates(roles: SignalRoles, axis: str) -> bool:
    """Whether a car's body has the rotation ``axis``, read from its corners'
    names (a ``rear`` wheel: two axles, so pitch; a ``left`` one: roll)."""
    word = _ROTATION_OUTPUTS[axis][1]
    return any(word in c.name for c in roles.corners)


def _rotation_rms(axis: str):
    """The We-weighted RMS of a rotation; zero on a car whose body cannot turn
    that way (a quarter car neither pitches nor rolls)."""
    label, name = _ROTATION_OUTPUTS[axis][0], AXIS_RULES["seated"][axis].weighting

    def formula(s, _) -> np.ndarray:
        if not _rotates(s.roles, axis):  # zero per design, through a reduction: it streams
            return 0.0 * s.peak(s.roles.body_acc)
        if label not in s.outputs:
            raise ValueError(
                f"a_w_{axis} reads the output {label!r}, which these signals do not carry "
                f"(they have {', '.join(s.outputs)}); pass the model's every output, as "
                "ride_metrics does"
            )
        return _weighted_rms(s, label, name)

    return formula


def _a_v(s, _) -> np.ndarray:
    """Seated comfort's vibration total value of the body's axes: the vertical
    (Wk) and, on a car with two axles or two sides, its pitch and roll (We,
    k = 0.4 and 0.63 m/rad): ISO 2631-1:1997 §6.5, §8.2. Which rotations
    a car has is read from its corners' names (``rear``: pitch, ``left``:
    roll), so a response without the output is refused, never left out."""
    rules = AXIS_RULES["seated"]
    total = s.mean_square(WEIGHTED_ACC)
    for axis in _ROTATION_OUTPUTS:
        if _rotates(s.roles, axis):
            total = total + (rules[axis].k_comfort * _rotation_rms(axis)(s, 0)) ** 2
    return np.sqrt(total)


def _mtvv(s, _) -> np.ndarray:
    """The largest 1 s running RMS of the Wk-weighted body acceleration (§6.3.1)."""
    return running_rms(s.weighted_output(s.roles.body_acc, "Wk"), s.T)[1].max(axis=-1)


def _msdv(s, _) -> np.ndarray:
    """``(∫ a_wf² dt)^½`` of the Wf-weighted body acceleration (§9.2.2)."""
    awf = s.weighted_output(s.roles.body_acc, "Wf")
    return np.sqrt(mean_square(awf) * (s.T[-1] - s.T[0]))


# fmt: off
_ALL = (
    Metric("rms_body_acc", "m/s²", "RMS body acceleration (trapezoidal time mean): comfort",
           lambda s, _: np.sqrt(s.mean_square(s.roles.body_acc))),
    Metric("peak_body_acc", "m/s²", "largest |body acceleration|",
           lambda s, _: s.peak(s.roles.body_acc)),
    Metric("rms_body_acc_wk", "m/s²",
           "ISO 2631-1 Wk-weighted RMS body acceleration (ISO 2631-1:1997, 6.4)",
           lambda s, _: np.sqrt(s.mean_square(WEIGHTED_ACC))),
    Metric("vdv", "m/s^1.75", "vibration dose value (∫ a_w⁴ dt)^¼ (ISO 2631-1:1997, 6.3.2)",
           lambda s, _: s.quartic_integral(WEIGHTED_ACC) ** 0.25),
    Metric("a_w_z", "m/s²", "ISO 2631-1 weighted RMS of the seat's vertical, Wk "
           "(ISO 2631-1:1997, 6.1 eq. 1, 8.2)",
           lambda s, _: np.sqrt(s.mean_square(WEIGHTED_ACC))),
    Metric("a_w_rx", "rad/s²", "ISO 2631-1 weighted RMS of the body's roll acceleration, We "
           "(ISO 2631-1:1997, 8.2)", _rotation_rms("rx")),
    Metric("a_w_ry", "rad/s²", "ISO 2631-1 weighted RMS of the body's pitch acceleration, We "
           "(ISO 2631-1:1997, 8.2)", _rotation_rms("ry")),
    Metric("a_v", "m/s²", "ISO 2631-1 vibration total value for comfort of the body's axes: "
           "z and the rotations (ISO 2631-1:1997, 6.5, 8.2)", _a_v),
    Metric("mtvv", "m/s²", "maximum transient vibration value: the largest 1 s running RMS "
           "of the Wk-weighted vertical (ISO 2631-1:1997, 6.3.1)", _mtvv),
    Metric("msdv", "m/s^1.5", "motion sickness dose value of the Wf-weighted vertical "
           "(ISO 2631-1:1997, 9.2.2)", _msdv),
    Metric("settling_time", "s", "2 % settling time of the body displacement",
           lambda s, _: s.settling_time(s.roles.body_disp)),
    Metric("rms_susp_travel", "m", "RMS suspension travel",
           _at_corner("susp_travel", "mean_square", np.sqrt), per_corner=True),
    Metric("peak_susp_travel", "m", "largest |suspension travel|: the rattle space needed",
           _at_corner("susp_travel", "peak"), per_corner=True),
    Metric("peak_tire_defl", "m", "largest |dynamic tire deflection|",
           _at_corner("tire_defl", "peak"), per_corner=True),
    Metric("rms_tire_load / static", "-",
           "RMS dynamic tire load kt·|tire_defl| over the static wheel load: road holding",
           _rms_tire_load, per_corner=True),
    Metric("lift_off", "", "whether the dynamic load ever exceeds the static wheel load "
           "(the wheel would leave the road; a linear model does not represent it)",
           lambda s, i: np.asarray(s.lifted_count(i) > 0), per_corner=True),
    Metric("lift_off_duration", "s", "total time the wheel would be off the road",
           lambda s, i: s.lifted_count(i) * s.dt, per_corner=True),
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


class _NotStreamable(Exception):
    """A formula read a whole output, not one of the reductions."""


class _Recorder:
    """Runs a formula once to learn which reductions it reads (returns zeros)."""

    def __init__(self, roles: SignalRoles, tire_stiffness, static_load, dt: float):
        self.roles, self.dt = roles, dt
        self.tire_stiffness, self.static_load = tire_stiffness, static_load
        self.needs: set[tuple[str, object]] = set()

    def corner(self, i: int) -> Corner:
        return self.roles.corners[i]

    def _note(self, kind: str, key) -> np.ndarray:
        self.needs.add((kind, key))
        return np.zeros(1)

    def mean_square(self, label):
        return self._note("sumsq", label)

    def peak(self, label):
        return self._note("peak", label)

    def quartic_integral(self, label):
        return self._note("quartic", label)

    def settling_time(self, label):
        return self._note("settle", label)

    def lifted_count(self, i):
        return self._note("lifted", i)

    def __getattr__(self, name):  # output(), body_acc, T ...: a whole signal
        raise _NotStreamable(name)


class MetricStream:
    """Registered metrics computed as the samples go by, from running reductions.

    Nothing of the length of the response is kept: per design and signal a
    sum of squares, a sum of fourth powers, a running peak, a count, or for
    the settling time the largest excursion from the final value and the
    last sample outside 2 % of it. The results equal the metrics of
    `RideSignals` on the whole response (same formulas, same reductions) to
    rounding, whatever the order and size of the pieces.

    Parameters
    ----------
    items : sequence of ``(column, Metric, corner)``
        As `metric_columns` gives them.
    roles, T, tire_stiffness, static_load
        As for `RideSignals`.

    Use ``start(final)`` with each signal's last sample (the settling time
    measures from it), then ``update(index, values)`` for each piece (the
    sample numbers and ``{label: (m, len)}``; the last sample too), then
    ``result()``.
    """

    def __init__(self, items, roles: SignalRoles, T: np.ndarray, tire_stiffness, static_load):
        self.items = list(items)
        self.roles, self.T, self.N = roles, T, T.size
        self.dt = float((T[-1] - T[0]) / (T.size - 1))
        self.tire_stiffness, self.static_load = tuple(tire_stiffness), tuple(static_load)
        rec = _Recorder(roles, self.tire_stiffness, self.static_load, self.dt)
        for _, metric, corner in self.items:
            metric.formula(rec, corner)
        self.needs = rec.needs
        labels = {
            roles.corners[key].tire_defl if isinstance(key, int) else str(key)
            for _, key in self.needs
        }
        #: whether the Wk-weighted body acceleration is read (under `WEIGHTED_ACC`)
        self.weighted = WEIGHTED_ACC in labels
        #: the output labels read, the weighted acceleration left out
        self.labels = tuple(sorted(str(x) for x in labels - {WEIGHTED_ACC}))
        self._acc: dict = {}
        self._given: set = set()
        self._scratch: dict = {}

    def _buffer(self, shape, dtype=float) -> np.ndarray:
        """A scratch array, reused from piece to piece: fresh memory for every
        piece's temporaries costs page faults comparable to the arithmetic."""
        key = (tuple(shape), np.dtype(dtype).str)
        buf = self._scratch.get(key)
        if buf is None:
            buf = self._scratch[key] = np.empty(shape, dtype)
        return buf

    @staticmethod
    def supports(items, roles: SignalRoles) -> bool:
        """Whether every metric is written with the reductions (a formula that
        reads a whole output cannot be streamed)."""
        rec = _Recorder(
            roles, (np.ones(1),) * len(roles.corners), (np.ones(1),) * len(roles.corners), 1.0
        )
        try:
            for _, metric, corner in items:
                metric.formula(rec, corner)
        except _NotStreamable:
            return False
        return True

    def kinds(self, label: str) -> set[str]:
        """The reductions the metrics read of ``label`` (``'sumsq'``, ``'peak'``, ...)."""
        return {
            kind
            for kind, key in self.needs
            if (self.roles.corners[key].tire_defl if isinstance(key, int) else key) == label
        }

    def only_mean_square(self, label: str) -> bool:
        """Whether the metrics read ``label`` only through its mean square."""
        return self.kinds(label) == {"sumsq"}

    def settled(self, bound: Mapping[str, np.ndarray], *, band: bool = True) -> np.ndarray:
        """Per design, ``(m,)``: whether no later sample can change a reduction,
        given that every later sample of each streamed label satisfies
        ``|v| <= bound[label]`` (e.g. `qc_control.numerics.lti.TailBound`).

        A peak stays when ``bound <= peak``; a lift-off count when ``bound <=``
        the threshold (no later ``v`` exceeds it); the settling time when
        ``(bound + |final|)(1 + 1e-12) <= 0.02 M`` with ``M`` the largest
        excursion from the final value so far (no later deviation is outside
        the band, and ``M`` does not grow; the factor covers the rounding of
        ``v - final``); with ``band=False`` only ``M`` must be final
        (``(bound + |final|)(1 + 1e-12) <= M``), the last sample outside the
        band being found otherwise (`settling_state`, `set_last_outside`).
        Sums of squares and fourth powers need every sample,
        unless given in closed form (`start`'s ``sums``). Call after the
        first `update`.
        """
        acc = self._acc
        m = len(next(iter(self._final.values()))) if self._final else 0
        ok = np.ones(m, dtype=bool)
        for kind, key in self.needs:
            label = self.roles.corners[key].tire_defl if isinstance(key, int) else str(key)
            if kind == "sumsq" and label in self._given:
                continue
            if kind in ("sumsq", "quartic"):
                return np.zeros(m, dtype=bool)
            b = bound[label]
            if kind == "peak":
                here = b <= acc[("peak", key)]
            elif kind == "lifted" and isinstance(key, int):
                here = b <= _lift_threshold(self, key)
            elif kind == "settle":
                reach = (b + np.abs(self._final[label])) * (1 + 1e-12)
                here = reach <= (0.02 if band else 1.0) * acc[("settle_max", label)]
            else:  # pragma: no cover - every kind is listed above
                raise AssertionError(kind)
            ok &= here
        return ok

    def start(self, final: Mapping[str, np.ndarray], sums=None) -> None:
        """Begin: each signal's last sample; optionally ``{label: (Σ v², v_0)}``
        known in closed form (then its samples are not needed)."""
        self._final = final
        self._acc = {}
        self._given = set(sums or ())
        for label, (total, first) in (sums or {}).items():
            self._acc[("sumsq", label)] = total
            self._acc[("first", label)] = first

    def update(self, index: np.ndarray, values: Mapping[str, np.ndarray]) -> None:
        """Fold in one piece: ``values[label]`` of shape ``(m,) + index.shape``
        holds the samples numbered ``index`` (any order, any shape)."""
        acc = self._acc
        index = np.asarray(index)
        flat = index.reshape(-1)
        first = np.flatnonzero(flat == 0)
        for kind, key in self.needs:
            label = self.roles.corners[key].tire_defl if isinstance(key, int) else str(key)
            if kind == "sumsq" and label in self._given:
                continue
            v = values[label]
            if kind == "settle":
                self._settle(label, v, index)
                continue
            v = v.reshape(v.shape[: v.ndim - index.ndim] + (-1,))  # a view: pieces are contiguous
            if first.size and kind in ("sumsq", "quartic"):
                acc[("first", label)] = v[..., first[0]]
            if kind == "sumsq":
                acc[(kind, key)] = acc.get((kind, key), 0.0) + np.vecdot(v, v)
            elif kind == "quartic":
                v2 = np.multiply(v, v, out=self._buffer(v.shape))
                acc[(kind, key)] = acc.get((kind, key), 0.0) + np.vecdot(v2, v2)
            elif kind == "peak":
                top = np.maximum(v.max(axis=-1), -v.min(axis=-1))
                acc[(kind, key)] = np.maximum(acc[(kind, key)], top) if (kind, key) in acc else top
            elif kind == "lifted" and isinstance(key, int):
                over = np.greater(
                    v, _lift_threshold(self, key)[..., None], out=self._buffer(v.shape, bool)
                )
                acc[(kind, key)] = acc.get((kind, key), 0) + np.count_nonzero(over, axis=-1)

    def _settle(self, label: str, v: np.ndarray, index: np.ndarray) -> None:
        """The last sample outside 2 % of the largest excursion from the final
        value so far (this piece's included). Over the whole stream it is the
        last outside 2 % of the final largest excursion: the sample where that
        occurs is itself outside, and after it the threshold no longer moves."""
        acc = self._acc
        final = self._final[label]
        dev = np.subtract(
            v, final.reshape(final.shape + (1,) * index.ndim), out=self._buffer(v.shape)
        )
        np.abs(dev, out=dev)
        m = dev.shape[0]
        if index.ndim == 2:  # (L, S) blocks: find the last block column outside, then the sample
            cols = dev.max(axis=-2)  # (m, S)
            M = cols.max(axis=-1)
        else:
            M = dev.max(axis=-1)
        M = np.maximum(acc[("settle_max", label)], M) if ("settle_max", label) in acc else M
        threshold = 0.02 * M
        if index.ndim == 2:
            out_cols = cols > threshold[:, None]
            S = out_cols.shape[-1]
            s_last = S - 1 - np.argmax(out_cols[:, ::-1], axis=-1)
            column = dev[np.arange(m), :, s_last]  # (m, L)
            L = column.shape[-1]
            j_last = L - 1 - np.argmax((column > threshold[:, None])[:, ::-1], axis=-1)
            last = np.where(out_cols.any(axis=-1), index[j_last, s_last], -1)
        else:
            last = np.where(dev > threshold[:, None], index, -1).max(axis=-1, initial=-1)
        prev = acc.get(("settle", label), np.full(M.shape, -1))
        acc[("settle_max", label)] = M
        acc[("settle", label)] = np.maximum(prev, last)

    def settling_state(self, label: str) -> tuple[np.ndarray, np.ndarray]:
        """``(final, M)``: the final value and the largest excursion from it so far."""
        return self._final[label], self._acc[("settle_max", label)]

    def set_last_outside(self, label: str, last: np.ndarray) -> None:
        """Set the settling time's last sample outside the band (-1: none), found
        by a search of its own (`qc_control.studies.sweeps`' backward search)."""
        self._acc[("settle", label)] = np.asarray(last)

    def _ends(self, label):
        return self._acc[("first", label)], self._final[label]

    def mean_square(self, label):
        v0, vn = self._ends(label)
        return (self._acc[("sumsq", label)] - 0.5 * (v0**2 + vn**2)) / (self.N - 1)

    def peak(self, label):
        return self._acc[("peak", label)]

    def quartic_integral(self, label):
        v0, vn = self._ends(label)
        return self.dt * (self._acc[("quartic", label)] - 0.5 * (v0**4 + vn**4))

    def settling_time(self, label):
        last = self._acc[("settle", label)]
        return self.T[np.minimum(np.where(last >= 0, last + 1, 0), self.N - 1)]

    def lifted_count(self, i):
        return self._acc[("lifted", i)]

    def corner(self, i: int) -> Corner:
        return self.roles.corners[i]

    def result(self) -> dict[str, np.ndarray]:
        """Each metric's column -> values ``(m,)``."""
        return {col: np.asarray(metric.formula(self, i)) for col, metric, i in self.items}
