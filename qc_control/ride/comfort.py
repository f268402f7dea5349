"""Ride comfort, rattle space and road holding: transmissibility and ride metrics.

A suspension engineer judges a design on a road by three numbers: comfort
(body acceleration, ISO 2631-1 weighted), rattle space (suspension travel)
and road holding (dynamic tire load against the static wheel load).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import control
import numpy as np
import pandas as pd

from ..models.registry import vehicle_model
from ..models.vehicle import VehicleModel
from ..numerics.checks import ParameterError, positive
from ..numerics.integrate import uniform_step
from .iso2631 import wk_filter, wk_weighted
from .metrics import METRICS, RIDE_METRICS, RideSignals, evaluate
from .road import ISO8608_BAND, ISO8608_N0, ISO8608Road, Road, road_class_psd
from .spectral import (
    DEFAULT_ROAD,
    SPECTRAL_CAPABLE,
    iso8608_spelling,
    rear_delay,
    spectral_metrics,
    white_velocity_variances,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "wk_filter",
    "wk_weighted",
    "transmissibility",
    "Transmissibility",
    "ride_metrics",
    "ride_metrics_spectral",
]

_SIGNALS = ("xs", "body_acc", "susp_travel", "tire_defl")
_UNITS = {"xs": "m/m", "body_acc": "(m/s²)/m", "susp_travel": "m/m", "tire_defl": "m/m"}


def _road_system(sys: control.StateSpace) -> control.StateSpace:
    """``sys``, refused unless it has the quarter car's road input ``zr``."""
    if "zr" in sys.input_labels:
        return sys
    raise ValueError(
        f"system {sys.name!r} has no road input 'zr'; build it with quarter_car(params, road=True)"
    )


@dataclass(frozen=True, eq=False)
class Transmissibility:
    """Frequency responses from the road height to the ride signals.

    Attributes
    ----------
    freqs_hz : ndarray
    response : dict[str, ndarray]
        Complex ``H(j2πf)`` per output label: ``xs``, ``body_acc``,
        ``susp_travel``, ``tire_defl`` for a quarter car; for a vehicle on
        several wheels the body's displacement and acceleration, its pitch
        (and roll) acceleration and every corner's travel and tire deflection.
    invariant_hz : float
        ``√(ku/mu)/2π``: there ``|body_acc/zr| = ku/ms`` whatever the damping
        (a quarter car whose tire has no damping; NaN otherwise).
    invariant_gain : float
        ``ku/ms`` [1/s²] (quarter car; NaN otherwise).
    units : dict[str, str]
        The unit of each gain, e.g. ``'(m/s²)/m'``.
    delay_s : float
        The wheelbase delay ``(a + b)/V`` [s] of the rear wheels (0 for one wheel).
    """

    freqs_hz: np.ndarray
    response: dict
    invariant_hz: float
    invariant_gain: float
    units: dict = field(default_factory=lambda: dict(_UNITS))
    delay_s: float = 0.0

    def wheelbase_notches(self, signal: str = "pitch") -> np.ndarray:
        """The wheelbase-filtering frequencies in the band [Hz].

        One road under both axles, the rear ``τ`` later, excites the body
        through ``H_f + e^{-jωτ} H_r``. On a car symmetric about its CG the
        axles' heave contributions are equal and their pitch contributions
        opposite, so pitch vanishes where ``e^{-jωτ} = 1`` and heave where
        ``e^{-jωτ} = -1``:

        .. math:: f_{pitch} = \\frac{k V}{a + b}, \\qquad
                  f_{heave} = \\frac{(k + ½) V}{a + b}, \\quad k = 1, 2, \\dots

        (Gillespie, *Fundamentals of Vehicle Dynamics*, 1992, ch. 5, wheelbase
        filtering); on other cars the dips lie near these frequencies.
        """
        if self.delay_s <= 0:
            return np.array([])
        offset = {"pitch": 0.0, "heave": 0.5}[signal]
        top = self.freqs_hz.max() * self.delay_s
        k = np.arange(1 if offset == 0 else 0, int(np.floor(top - offset)) + 1) + offset
        return k[k / self.delay_s >= self.freqs_hz.min()] / self.delay_s

    def to_frame(self) -> pd.DataFrame:
        """|H| and phase [deg] per signal, indexed by frequency [Hz]."""
        cols = {}
        for name, h in self.response.items():
            cols[f"|{name}/zr| [{self.units[name]}]"] = np.abs(h)
            cols[f"phase {name} [deg]"] = np.degrees(np.angle(h))
        frame = pd.DataFrame(cols, index=pd.Index(self.freqs_hz, name="f [Hz]"))
        return frame

    def figure(self) -> Figure:
        """Bode-style plot: magnitude (log-log) and phase of each signal."""
        from matplotlib.figure import Figure  # heavy and optional: only when plotting

        rows = math.ceil(len(self.response) / 2)
        fig = Figure(figsize=(9, 3.25 * rows), layout="constrained")
        axes = fig.subplots(rows, 2, sharex=True, squeeze=False).ravel()
        for ax, (name, h) in zip(axes, self.response.items()):
            ax.loglog(self.freqs_hz, np.abs(h), color="tab:blue")
            ax.set(title=f"{name} / zr", ylabel=f"|H| [{self.units[name]}]")
            ax.grid(alpha=0.3, which="both")
            twin = ax.twinx()
            twin.semilogx(
                self.freqs_hz, np.degrees(np.unwrap(np.angle(h))), color="tab:orange", lw=0.8
            )
            twin.set_ylabel("phase [deg]", color="tab:orange")
        if math.isfinite(self.invariant_hz):
            axes[1].plot(
                [self.invariant_hz],
                [self.invariant_gain],
                "ko",
                mfc="none",
                label=f"invariant point: {self.invariant_hz:.2f} Hz, ku/ms",
            )
            axes[1].legend(fontsize="small", loc="lower left")
        for ax in axes[len(self.response) :]:
            ax.set_visible(False)
        for ax in axes[-2:]:
            ax.set_xlabel("frequency [Hz]")
        return fig


def transmissibility(sys_or_params=None, freqs_hz=None, *, speed=None) -> Transmissibility:
    """Transmissibility from the road to the ride signals.

    Computed with ``control.frequency_response``: of ``quarter_car(road=True)``
    to xs, body_acc, susp_travel and tire_defl; of a vehicle on several wheels
    (a half or full car) from one road under every wheel, the rear wheels
    meeting it ``τ = (a + b)/V`` later, to the body's displacement and
    accelerations and every corner's travel and tire deflection:

    .. math:: H_y(j\\omega) = \\sum_{front} H_{y,i}(j\\omega)
              + e^{-j\\omega\\tau} \\sum_{rear} H_{y,i}(j\\omega)

    The delay is exact (``e^{-jωτ}``, no Padé approximation); the same road
    under the left and right wheels (a fully correlated road, the worst case
    for heave and pitch: it excites no roll).

    Parameters
    ----------
    sys_or_params : vehicle parameters, dict, VehicleModel, control.StateSpace or None
        A vehicle (`QuarterCarParams`, `HalfCarParams`, `FullCarParams`), a
        model of one, or a quarter-car system with the road input ``'zr'``.
    freqs_hz : array_like, optional
        Frequencies [Hz] > 0; default 200 points from 0.1 to 100 Hz.
    speed : float, optional
        Vehicle speed [m/s]; required for a vehicle on several axles.

    Notes
    -----
    Adding the two equations of motion gives
    ``ms xs'' + mu xu'' = -ku (xu - zr)``; at ``ω² = ku/mu`` the wheel's
    terms cancel and ``-ω² Xs / Zr = ku/ms``: an invariant point of the
    body-acceleration transmissibility, the same for every damper
    (Hedrick & Butsuen, 1990).
    """
    f = np.logspace(-1, 2, 200) if freqs_hz is None else np.asarray(freqs_hz, dtype=float)
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ValueError("freqs_hz must be a 1-D array of finite frequencies > 0 Hz")
    if not isinstance(sys_or_params, (VehicleModel, control.StateSpace)):
        sys_or_params = vehicle_model(sys_or_params, road=True)
    if isinstance(sys_or_params, VehicleModel) and len(sys_or_params.corners) > 1:
        return _axle_transmissibility(sys_or_params, f, speed)
    if isinstance(sys_or_params, VehicleModel):
        sys_or_params = sys_or_params.system
    sys = _road_system(sys_or_params)
    fr = control.frequency_response(sys, 2 * np.pi * f)
    j = sys.input_labels.index("zr")
    H = np.asarray(fr.complex)
    response = {name: H[sys.output_labels.index(name), j] for name in _SIGNALS}
    return Transmissibility(f, response, *_invariant_point(sys, j))


def _invariant_point(sys: control.StateSpace, j: int) -> tuple[float, float]:
    """``(√(ku/mu)/2π, ku/ms)`` read from the quarter car's matrices, or NaNs where
    there is no such point: a tire with damping ``cu`` adds ``cu(xu' - zr')`` to
    the summed equations, so no frequency is the same for every damper, and a
    system with other states (another one-wheel model) has other matrices."""
    A, B = np.asarray(sys.A), np.asarray(sys.B)
    if list(sys.state_labels) != ["vs", "vu", "xs", "xu"] or A[1, 0] + A[1, 1] != 0.0:
        return math.nan, math.nan  # A[1, :2] = [cs/mu, -(cs + cu)/mu]: cu = 0 only
    ku_over_mu = B[1, j]
    # body_acc row: A[0] = [-cs/ms, cs/ms, -ks/ms, ks/ms]; ku/ms = ku/mu * mu/ms and
    # mu/ms = (ks/ms)/(ks/mu) = A[0,3]/A[1,2]
    return math.sqrt(ku_over_mu) / (2 * math.pi), ku_over_mu * A[0, 3] / A[1, 2]


def _axle_transmissibility(model: VehicleModel, f: np.ndarray, speed) -> Transmissibility:
    """`transmissibility` of a vehicle on several axles: one road, the rear later."""
    if speed is None:
        raise ValueError(
            f"speed is required for the transmissibility of {model.name!r}: its rear wheels "
            "meet the road (a + b)/speed after the front ones"
        )
    speed = positive("speed", speed, "m/s")
    roads = model.road_inputs()
    if len(roads) != len(model.corners):
        raise ValueError(
            f"model {model.name!r} has no road input under every wheel; build it with road=True"
        )
    wheelbase = float(model.params.a + model.params.b)
    tau = wheelbase / speed
    sys = model.system
    H = np.asarray(control.frequency_response(sys, 2 * np.pi * f).complex)
    H = H.reshape(sys.noutputs, sys.ninputs, f.size)
    late = np.exp(-2j * np.pi * f * tau)
    weights = [late if c.name.startswith("rear") else np.ones_like(late) for c in model.corners]
    columns = [sys.input_labels.index(c.road) for c in model.corners]
    combined = sum(w * H[:, j] for w, j in zip(weights, columns))
    outputs = list(sys.output_labels)
    wanted = [model.body_disp, model.body_acc]
    wanted += [label for label in ("heave_acc", "pitch_acc", "roll_acc") if label in outputs]
    wanted += [c.susp_travel for c in model.corners] + [c.tire_defl for c in model.corners]
    wanted = list(dict.fromkeys(wanted))
    response = {label: combined[outputs.index(label)] for label in wanted}
    units = {label: _gain_unit(model.unit(label)) for label in wanted}
    return Transmissibility(f, response, math.nan, math.nan, units, tau)


def _gain_unit(unit: str) -> str:
    return f"({unit})/m" if "/" in unit else f"{unit}/m"


def ride_metrics(response, params=None, metrics=RIDE_METRICS) -> pd.Series:
    """Comfort, rattle space and road holding of a road response.

    Parameters
    ----------
    response : control.TimeResponseData
        A response of the vehicle on a road, from qc_control or
        python-control, on a uniform time grid, with the model's outputs.
    params : vehicle parameters, dict or VehicleModel, optional
        The vehicle (tire stiffness, static wheel load, which output is
        which); the seed's quarter car by default. Wheel metrics are given
        per corner (``peak_susp_travel front [m]`` on a half car).
    metrics : sequence of str, default `qc_control.ride.metrics.RIDE_METRICS`
        Names from `qc_control.ride.metrics.METRICS`.

    Returns
    -------
    pandas.Series
        One entry per metric column, named as in `qc_control.sweep`:

        - ``rms_body_acc [m/s²]``;
        - ``rms_body_acc_wk [m/s²]``: ISO 2631-1 weighted, the body
          acceleration through `wk_filter` (`wk_weighted`: exact for an
          input linear between samples, as ``control.forced_response``);
        - ``vdv [m/s^1.75]``: ``(∫ a_w⁴ dt)^{1/4}`` (ISO 2631-1, 6.3.2);
        - ``rms_susp_travel [m]``, ``peak_susp_travel [m]``;
        - ``rms_tire_load / static [-]``: the dynamic tire force
          ``ku·(zr - xu)`` over the static wheel load ``(ms + mu)·g``;
        - ``lift_off``: whether the dynamic load ever unloads the tire by
          more than the static load (the wheel would leave the road, which
          the linear model does not represent), and
          ``lift_off_duration [s]``, for how long in all.

    RMS values are time averages over the response (trapezoidal rule); the
    formulas are those of `qc_control.ride.metrics`.
    """
    model = vehicle_model(params, road=True)
    T = np.asarray(response.time, dtype=float)
    if uniform_step(T) is None:
        raise ValueError("the response's time grid must be uniform for the ride metrics")
    labels = list(response.output_labels)
    y = np.asarray(response.outputs).reshape(len(labels), -1)
    outputs = {label: y[i][None, :] for i, label in enumerate(labels)}
    signals = RideSignals(T, outputs, model.roles)
    values = evaluate(signals, metrics)
    return pd.Series(
        {col: (bool(v[0]) if v.dtype == bool else float(v[0])) for col, v in values.items()},
        dtype=object,
    )


def _track_power(H: np.ndarray, f: np.ndarray, followers, tau) -> np.ndarray:
    """``Σ |H|²`` over a car's tracks ``(outputs, f)`` from its responses to each
    road input ``H (outputs, inputs, f)``: a rear input ``j`` following ``i`` by
    ``τ`` (`qc_control.ride.spectral.rear_delay`) adds as ``|H_i + H_j e^{-j2πfτ}|²``,
    the independent tracks' powers add."""
    power = np.zeros((H.shape[0], f.size))
    alone = set(range(H.shape[1]))
    for i, j in followers:
        power += np.abs(H[:, i] + H[:, j] * np.exp(-2j * np.pi * f * tau)) ** 2
        alone -= {i, j}
    for i in sorted(alone):
        power += np.abs(H[:, i]) ** 2
    return power


def _older_road(road, speed, band, road_class) -> ISO8608Road:
    """The `ISO8608Road` of `ride_metrics_spectral`'s arguments: ``road`` itself, or
    from 0.1's ``road_class, speed, band`` (positional or by name) with a
    DeprecationWarning naming the new form at the caller's caller."""
    if road_class is not None:
        if road is not None:
            raise ParameterError("road_class", road_class, "not given beside road= (give road=)")
        road = road_class
    if isinstance(road, ISO8608Road) or (road is None and speed is None and band is None):
        if speed is not None or band is not None:
            name, value = ("speed", speed) if speed is not None else ("band", band)
            raise ParameterError(name, value, "not given beside road= (the road holds it)")
        return DEFAULT_ROAD if road is None else road
    if isinstance(road, Road):  # a step or a bump has no stationary spectrum
        raise ParameterError("road", road, "a qc.road.ISO8608Road (a random road's spectrum)")
    cls = DEFAULT_ROAD.road_class if road is None else road
    v = DEFAULT_ROAD.speed if speed is None else speed
    band = ISO8608_BAND if band is None else band
    new = ISO8608Road(cls, speed=v, band=band)  # a bad class, speed or band refused by name
    warnings.warn(
        "ride_metrics_spectral(params, road_class, speed, band) is deprecated and will be "
        f"removed in the next minor release: use road={iso8608_spelling(cls, v, 0, band)}",
        DeprecationWarning,
        stacklevel=3,
    )
    return new


def ride_metrics_spectral(
    params=None,
    road: ISO8608Road | None = None,
    speed: float | None = None,
    band=None,
    points: int = 4000,
    *,
    exact: bool = False,
    road_class: str | None = None,
) -> pd.Series:
    """RMS ride metrics on an ISO 8608 road: band-limited, or exact over the unbounded band.

    Two values of the same stationary RMS, which differ only by the band:

    - ``exact=False`` (default): the road's spectrum restricted to its band
      of spatial frequencies (``road.band``, by default the standard's
      0.011–2.83 cycles/m), integrated against the vehicle's frequency
      response:

      .. math:: σ_y^2 = \\int_{v n_{min}}^{v n_{max}} \\sum_{\\text{tracks}}
                \\big|H_{y,\\text{front}} + H_{y,\\text{rear}}\\, e^{-j2πfτ}\\big|^2
                G_t(f)\\, df, \\qquad G_t(f) = \\frac{G_d(f/v)}{v}

      (``τ = (a + b)/v``; one wheel: ``|H_y|²``)

      (trapezoidal rule in ``ln f`` on ``points`` log-spaced frequencies),
      what a road sampled by ``road.samples`` (`qc_control.ride.road.iso8608`)
      on that band gives;
    - ``exact=True``: the same spectrum over all frequencies, which is white
      road velocity of intensity ``q = 2π² n0² Gd(n0) v``
      (``road.intensity``), from the Lyapunov equation
      (`qc_control.ride.spectral.white_velocity_variances`): no quadrature, exact
      to rounding; the band and ``points`` are not used.

    For the seed's car on class C at 20 m/s the band changes the RMS body
    acceleration by about 1e-4 relative (1.25911 exact, 1.25899 in band)
    and the RMS tire load by about 2e-3. The Wk-weighted value uses
    ``|W_k H_{acc}|²`` (band) or the car in series with `wk_filter` (exact).

    Parameters
    ----------
    params : vehicle parameters, dict or VehicleModel, optional
        The vehicle (its registered model with road inputs,
        `qc_control.models.registry.vehicle_model`); a `VehicleModel` with
        road inputs. Its rear wheels meet the front wheels' road
        ``(a + b)/speed`` later (`qc_control.ride.spectral.rear_delay`); a full
        car's left and right tracks are independent. The seed's car by default.
    road : qc.road.ISO8608Road, optional
        The road: its class, speed [m/s] and band; default
        `qc_control.ride.spectral.DEFAULT_ROAD` (class C at 20 m/s).
    speed, band, road_class
        Deprecated: 0.1's ``ride_metrics_spectral(params, road_class, speed,
        band)``, read as ``road=qc.road.ISO8608Road(road_class, speed=speed,
        band=band)`` with a DeprecationWarning naming it.
    points : int, default 4000
    exact : bool, default False

    Returns
    -------
    pandas.Series
        ``rms_body_acc [m/s²]``, ``rms_body_acc_wk [m/s²]``, and per corner
        ``rms_susp_travel [m]`` and ``rms_tire_load / static [-]`` (the names
        of `qc_control.ride.metrics`), and the body displacement's RMS
        (``rms_xs [m]`` on the quarter car; ``inf`` when ``exact``: over the
        unbounded band the road height is a random walk). ``.attrs["band"]``
        says which value it is.
    """
    road = _older_road(road, speed, band, road_class)
    speed = road.speed
    model = vehicle_model(params, road=True)
    q = road.intensity
    roles = model.roles
    labels = [roles.body_acc]
    labels += [label for c in roles.corners for label in (c.susp_travel, c.tire_defl)]
    labels.append(roles.body_disp)
    labels = list(dict.fromkeys(labels))
    if exact:
        values = spectral_metrics(model, q, SPECTRAL_CAPABLE, speed=speed)
        body = f"rms_{roles.body_disp} [{model.unit(roles.body_disp)}]"
        # the body's height follows the road's random walk: inf
        values[body] = math.sqrt(white_velocity_variances(model)[roles.body_disp])
        series = pd.Series(values)
        series.attrs["band"] = "exact: Lyapunov, unbounded band (white road velocity)"
        return series
    lo, hi = road.band
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or points < 2:
        raise ValueError(
            f"points must be an integer >= 2 (frequencies in the band), got {points!r}"
        )
    if not isinstance(road.road_class, str):
        raise ParameterError(
            "road_class",
            road.road_class,
            "a class A-H for the band's value (Gd(n0) in m³ gives the exact one alone)",
        )
    g0 = road_class_psd(road.road_class)
    f = np.geomspace(speed * lo, speed * hi, points)
    sys = model.system
    roads = [list(sys.input_labels).index(r) for r in model.road_inputs()]
    if not roads:
        raise ValueError(f"model {model.name!r} has no road input: build it with road=True")
    H = np.asarray(control.frequency_response(sys, 2 * np.pi * f).complex)
    H = H.reshape(sys.noutputs, sys.ninputs, f.size)[:, roads]
    gain = _track_power(H, f, *rear_delay(model, speed))
    road_psd = g0 * ((f / speed) / ISO8608_N0) ** -2.0 / speed  # one-sided, m²/Hz
    wk = np.abs(np.asarray(wk_filter()(2j * np.pi * f))).reshape(-1)
    log_f = np.log(f)

    def integral(h2):
        return float(np.trapezoid(h2 * road_psd * f, log_f))

    out = list(sys.output_labels)
    var = {label: integral(gain[out.index(label)]) for label in labels}
    var_wk = integral(wk**2 * gain[out.index(roles.body_acc)])
    source = f"ISO 8608 band {lo:g}-{hi:g} cycles/m (quadrature, {points} points)"
    values = {
        METRICS["rms_body_acc"].column(): math.sqrt(var[roles.body_acc]),
        METRICS["rms_body_acc_wk"].column(): math.sqrt(var_wk),
    }
    for c in roles.corners:
        values[METRICS["rms_susp_travel"].column(c)] = math.sqrt(var[c.susp_travel])
        values[METRICS["rms_tire_load / static"].column(c)] = (
            c.tire_stiffness * math.sqrt(var[c.tire_defl]) / c.static_load
        )
    values[f"rms_{roles.body_disp} [{model.unit(roles.body_disp)}]"] = math.sqrt(
        var[roles.body_disp]
    )
    series = pd.Series(values)
    series.attrs["band"] = source
    return series
