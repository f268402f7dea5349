"""Passive, semi-active and active suspensions compared on one car.

`compare_controllers` builds each design on the same quarter car, runs it
over a bump and an ISO 8608 road with a fixed-step method (linear loops
through the LTI engine, semi-active ones through
`qc_control.input_output_response`), and computes:

- on the bump: peak body acceleration, peak suspension travel, the 2 %
  settling time of the body displacement (`qc_control.ride.metrics`);
- on the road: RMS and ISO 2631-1 Wk-weighted RMS body acceleration, RMS
  travel, RMS dynamic tire load over the static load, RMS actuator force
  and the mean actuator power ``⟨fa·(vs - vu)⟩`` (positive: the actuator
  delivers energy; a semi-active damper only dissipates, so its power is
  <= 0);
- any other metric of the registry `qc_control.ride.metrics` by name, on
  either run (``road_metrics=``, ``bump_metrics=``): ISO 2631-1's ``a_w_z``,
  ``a_v``, ``vdv``, ``mtvv`` and ``msdv`` for the assessment the standard
  asks for (ISO 2631-1:1997 §6.3-6.5, §9.2.2);
- the transmissibility from the road to the body acceleration and to the
  tire deflection of every linear design (``control.frequency_response``;
  a semi-active loop has none).

Every number is here; `qc_control.report.control` formats them.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import control
import numpy as np
import pandas as pd

from ..models import controllers, mpc
from ..models.controllers import closed_loop
from ..models.quarter import QuarterCarParams, as_params, quarter_car_model
from ..models.vehicle import VehicleModel
from ..numerics.checks import ParameterError, positive
from ..numerics.integrate import check_time_grid
from ..numerics.limits import check_memory
from ..numerics.steps import auto_substeps
from ..responses.timeresp import forced_response, input_output_response
from ..ride.comfort import ride_metrics
from ..ride.metrics import METRICS, mean_square
from ..ride.road import Bump, ISO8608Road, as_road
from ..ride.spectral import DEFAULT_ROAD, iso8608_spelling
from .damping import (
    ISO2631_OBJECTIVES,
    ParetoFront,
    optimal_damping,
    pareto_front,
    spectral_ride,
)

__all__ = [
    "ControlComparison",
    "compare_controllers",
    "DESIGNS",
    "BUMP_METRICS",
    "ROAD_METRICS",
    "ISO2631_METRICS",
    "DEFAULT_BUMP",
]

#: The designs compared by default, in order.
DESIGNS = (
    "passive (seed)",
    "passive optimum",
    "skyhook",
    "skyhook semi-active",
    "groundhook",
    "groundhook semi-active",
    "hybrid",
    "hybrid semi-active",
    "ADD",
    "LQR",
    "H∞",
    "LQR, sampled",
    "MPC",
    "MPC, preview 0.2 s",
    "MPC, preview 0.5 s",
)
#: The bump of the bump run: 5 cm high, 1 m long, met at 10 m/s at t = 0.5 s
#: (`qc_control.ride.road.bump`'s own length, speed and start).
DEFAULT_BUMP = Bump(height=0.05, length=1.0, speed=10.0, t0=0.5)
#: Metrics of the bump run (names of `qc_control.ride.metrics`).
BUMP_METRICS = ("peak_body_acc", "peak_susp_travel", "settling_time")
#: Metrics of the road run.
ROAD_METRICS = ("rms_body_acc", "rms_body_acc_wk", "rms_susp_travel", "rms_tire_load / static")
#: ISO 2631-1's assessment of the body's vertical, by registry name: the Wk-weighted RMS,
#: the vibration total value, VDV, MTVV (§6.1-6.5) and the motion sickness dose (§9.2.2);
#: e.g. ``compare_controllers(road_metrics=ROAD_METRICS + ISO2631_METRICS)``.
ISO2631_METRICS = ("a_w_z", "a_v", "vdv", "mtvv", "msdv")
#: The sampled-data designs: the ECU's period [s], the MPC's horizon (ticks: 0.5 s, the
#: longest preview), the actuator's force limit [N] (hard) and the travel limit [m]
#: (soft, `qc_control.models.mpc.TRAVEL_PENALTY`).
ECU_PERIOD, MPC_HORIZON, FORCE_LIMIT, TRAVEL_LIMIT = 0.01, 50, 1000.0, 0.08
#: The time steps of the road and bump runs [s] (the road's is within
#: `qc_control.ride.road.largest_step` up to 35 m/s).
DT_ROAD, DT_BUMP = 0.005, 0.002
#: Peak memory of a run per sample and per signal (state, output, input) [bytes], keyed by
#: "is the loop linear": twice what was measured (peak resident memory over 80,000 to
#: 800,000 samples: 2.5-2.8 float64s per signal and sample for a linear loop, the LTI
#: engine and the ride metrics' temporaries; 9.5-18 for a semi-active one, stepped by
#: input_output_response, the most for the ADD with its sensor state).
_BYTES_PER_SIGNAL = {True: 8 * 6, False: 8 * 36}


@dataclass(frozen=True, eq=False)
class ControlComparison:
    """Every number of the controller comparison.

    Attributes
    ----------
    params : QuarterCarParams
        The car.
    designs : dict[str, str]
        Design name -> what it is (law, gains, device range).
    table : pandas.DataFrame
        One row per design: the bump metrics (``bump: ...``) and the road
        metrics (``road: ...``), with units in the column names
        (`compare_controllers`' ``bump_metrics`` and ``road_metrics``).
    freqs_hz : ndarray
    transmissibility : dict[str, dict[str, ndarray]]
        Linear design -> ``{'body_acc': |H|, 'tire_defl': |H|}`` from the
        road height.
    bump : dict
        The bump run's `Bump`: ``height`` [m], ``length`` [m], ``speed`` [m/s],
        ``t0`` [s], and the run's ``duration`` [s].
    road : dict
        The road run's `ISO8608Road`: ``road_class``, ``speed`` [m/s], ``seed``, and
        the run's ``duration`` [s].
    method : str
    dt : dict
        The time step [s] of the bump and road runs.
    exact : pandas.DataFrame
        Linear design -> its exact stationary RMS metrics on the road's
        white road velocity (`qc_control.studies.damping.spectral_ride`: Lyapunov,
        unbounded band), free of the finite run's sampling spread; with the
        ISO 2631-1 metrics of ``road_metrics`` that have such a value
        (``a_w_z``, ``a_v``, ``a_w_ry``, ``a_w_rx``).
    pareto : ParetoFront or None
        The passive comfort / road-holding front (cs x ks around the car)
        with the linear controllers marked.
    notes : list[str]
    """

    params: QuarterCarParams
    designs: dict
    table: pd.DataFrame
    freqs_hz: np.ndarray
    transmissibility: dict
    bump: dict
    road: dict
    method: str
    dt: dict
    exact: pd.DataFrame = field(default_factory=pd.DataFrame)
    pareto: ParetoFront | None = None
    notes: list = field(default_factory=list)


def _design_set(p: QuarterCarParams, iso: ISO8608Road, cmax, which, hinf_beta):
    """name -> (VehicleModel, description): every design on the same car."""
    car = quarter_car_model(p, road=True, actuator=True)
    c_sky, c_gnd = 3000.0, 1000.0
    semi = {"semi_active": "on-off", "cmin": 0.0, "cmax": cmax}
    device = f"on-off damper 0-{cmax:.0f} N·s/m in parallel with cs"
    laws = {  # the controllers closed around the same car
        "skyhook": lambda: controllers.skyhook(c_sky),
        "skyhook semi-active": lambda: controllers.skyhook(c_sky, **semi),
        "groundhook": lambda: controllers.groundhook(c_gnd),
        "groundhook semi-active": lambda: controllers.groundhook(c_sky, **semi),
        "hybrid": lambda: controllers.hybrid(c_sky, 0.5),
        "hybrid semi-active": lambda: controllers.hybrid(c_sky, 0.5, **semi),
        "ADD": lambda: controllers.add_damper(0.0, cmax),
        "LQR": lambda: controllers.lqr_controller(car),
    }
    what = {
        "skyhook": f"ideal, c_sky = {c_sky:.0f}",
        "skyhook semi-active": f"c_sky = {c_sky:.0f}, {device}",
        "groundhook": f"ideal, c_gnd = {c_gnd:.0f} (unstable beyond ~1.2e3 on the seed car)",
        "groundhook semi-active": f"c_gnd = {c_sky:.0f}, {device}",
        "hybrid": f"ideal, c = {c_sky:.0f}, α = 0.5",
        "hybrid semi-active": f"c = {c_sky:.0f}, α = 0.5, {device}",
        "ADD": f"acceleration-driven damper, {device}, 50 Hz accelerometer",
        "LQR": "full state, default weights (1 m/s², 5 cm, 5 mm, 1 kN)",
    }
    makers: dict[str, Callable[[], tuple[VehicleModel, str]]] = {
        "passive (seed)": lambda: (quarter_car_model(p, road=True), f"cs = {p.cs:.0f} N·s/m"),
        "passive optimum": lambda: _passive_optimum(p, iso),
        **{name: _closed(car, laws[name], what[name]) for name in laws},
        "H∞": lambda: _hinf(car, hinf_beta),
        **_sampled_designs(car),
    }
    unknown = [w for w in which if w not in makers]
    if unknown:
        raise ValueError(f"unknown design {unknown[0]!r}; choose from {list(makers)}")
    return {name: makers[name]() for name in which}


def _closed(car: VehicleModel, law: Callable, what: str) -> Callable[[], tuple[VehicleModel, str]]:
    """The design that closes ``law()`` around ``car``, built when asked."""
    return lambda: (closed_loop(car, law()), what)


def _sampled_designs(car: VehicleModel) -> dict[str, Callable[[], tuple[VehicleModel, str]]]:
    """The controllers on a clock: the sampled LQR and MPC without and with preview."""
    clock = f"{ECU_PERIOD * 1e3:g} ms ZOH, |fa| ≤ {FORCE_LIMIT:g} N"

    def lqr():
        law = mpc.sampled_lqr(car, ECU_PERIOD, limit=FORCE_LIMIT)
        return closed_loop(car, law), f"LQR's weights, control.dlqr, {clock} (clipped)"

    def predictive(preview):
        law = mpc.mpc_controller(
            car,
            ECU_PERIOD,
            MPC_HORIZON,
            limits={"fa": FORCE_LIMIT, "susp_travel": TRAVEL_LIMIT},
            preview=preview,
        )
        return closed_loop(car, law), f"LQR's weights, DAQP, {law.description}"

    return {
        "LQR, sampled": lqr,
        "MPC": lambda: predictive(None),
        "MPC, preview 0.2 s": lambda: predictive(0.2),
        "MPC, preview 0.5 s": lambda: predictive(0.5),
    }


def _passive_optimum(p, iso: ISO8608Road):
    opt = optimal_damping(p, "comfort", road=iso)
    model = quarter_car_model(opt.params, road=True)
    return model, f"comfort optimum (closed form), cs = {opt.cs:.0f} N·s/m, ζ = {opt.zeta:.2f}"


def _hinf(car, beta):
    design = controllers.hinf_controller(car, beta)
    what = (
        f"MATLAB active-suspension weights, β = {beta:g}, γ = {design.gamma:.4f} "
        f"(closed-loop ‖·‖∞ {design.norm:.4f})"
    )
    return closed_loop(car, design.controller), what


def _exact_table(
    linear: dict[str, VehicleModel], iso: ISO8608Road, road_metrics: Sequence[str] = ()
) -> pd.DataFrame:
    """The exact stationary metrics of the linear designs (empty when none is chosen),
    with those of ISO 2631-1's in ``road_metrics`` that have one (``a_w_z``, ``a_v``...)."""
    named = [n for n in ISO2631_OBJECTIVES for m in road_metrics if m in (n, METRICS[n].column())]
    rows = [spectral_ride(m, iso, iso2631=named).set_axis([n]) for n, m in linear.items()]
    exact = pd.concat(rows) if rows else pd.DataFrame()
    exact.index.name = "design"
    return exact


def _run(model: VehicleModel, T, U, method: str):
    """A fixed-step run; a linear loop is substepped to `auto_step`'s rule
    (`qc_control.numerics.steps.auto_substeps`).

    (An H∞ loop has poles near -700 1/s, beyond RK4's stability at 5 ms.)
    A semi-active loop steps at the grid's spacing: its fastest mode is the
    car's wheel hop under ``cs + cmax`` (about -60 1/s) or the ADD's sensor
    (-314 1/s), within RK4's stability limit at 5 ms.
    """
    if isinstance(model.system, control.StateSpace):
        substeps, _ = auto_substeps(method, model.system.poles(), float(T[1] - T[0]))
        return forced_response(model.system, T, U, method=method, substeps=substeps)
    return input_output_response(model.system, T, U, method=method)


def _actuator(resp) -> tuple[float, float]:
    """RMS actuator force [N] and mean power [W] (0, 0 for a passive car)."""
    labels = list(resp.output_labels)
    if "fa" not in labels:
        return 0.0, 0.0
    fa = np.asarray(resp.outputs)[labels.index("fa")]
    states = list(resp.state_labels)
    x = np.asarray(resp.states)
    vrel = x[states.index("vs")] - x[states.index("vu")]
    power = fa * vrel
    mean_power = float(np.trapezoid(power, resp.time) / (resp.time[-1] - resp.time[0]))
    return float(math.sqrt(mean_square(fa))), mean_power


def _design_names(designs) -> list[str]:
    """``designs`` as a list of names, at least one (each is checked by `_design_set`)."""
    if isinstance(designs, str) or not isinstance(designs, Iterable):
        raise TypeError(
            f"designs must be a sequence of design names, got {designs!r}; "
            f"choose from {list(DESIGNS)}"
        )
    names = list(designs)
    if not names:
        raise ValueError(f"designs must name at least one design; choose from {list(DESIGNS)}")
    return names


def _check_run_length(built: dict, road_duration: float, bump_duration: float) -> None:
    """Refuse runs that cannot fit in memory, before the time grids are made.

    Each design's runs hold, per sample, its states, outputs and input and the
    engines' temporaries: `_BYTES_PER_SIGNAL` of them per signal. The samples
    are counted from the durations, so a run of 1e7 s is refused without
    allocating its 2e9-sample grid.
    """
    samples = road_duration / DT_ROAD + bump_duration / DT_BUMP + 2
    worst = max(
        _BYTES_PER_SIGNAL[isinstance(m.system, control.StateSpace)]
        * (m.system.nstates + m.system.noutputs + m.system.ninputs)
        for m, _ in built.values()
    )
    check_memory(
        worst * samples,
        f"a controller comparison over {samples:.3g} samples (a {road_duration:g} s road "
        f"run at {DT_ROAD * 1e3:g} ms and a {bump_duration:g} s bump run at "
        f"{DT_BUMP * 1e3:g} ms)",
        "use a shorter road_duration or bump_duration",
    )


def _durations(road_duration, bump_duration) -> tuple[float, float]:
    """The runs' lengths [s], each at least one step of its run, refused by name otherwise."""
    road_duration = positive("road_duration", road_duration, "s")
    bump_duration = positive("bump_duration", bump_duration, "s")
    for name, value, dt in (("road", road_duration, DT_ROAD), ("bump", bump_duration, DT_BUMP)):
        if value < dt:
            raise ValueError(
                f"{name}_duration={value!r} s is shorter than one {dt * 1e3:g} ms step of the "
                f"{name} run; give at least {dt:g} s"
            )
    return road_duration, bump_duration


def _metric_names(name: str, value) -> tuple[str, ...]:
    """``value`` as metric names of the registry (or their columns), refused by ``name``."""
    known = f"metric names of qc_control.ride.metrics ({', '.join(METRICS)})"
    if isinstance(value, str) or not isinstance(value, Iterable):
        raise ParameterError(name, value, f"a sequence of {known}")
    names = tuple(value)
    columns = {m.column() for m in METRICS.values()}
    unknown = [n for n in names if n not in METRICS and n not in columns]
    if unknown:
        raise ParameterError(
            name,
            value,
            known,
            message=f"{name}={value!r}: unknown metric {unknown[0]!r}; choose from {known}",
        )
    return names


def _measure(
    model: VehicleModel,
    runs: dict[str, tuple[np.ndarray, np.ndarray]],
    method: str,
    metrics: Mapping[str, Sequence[str]],
) -> tuple[dict, str]:
    """One design's row of ``metrics[run]`` over the bump and road runs, and a note if a
    run failed."""
    bump_resp = _run(model, *runs["bump"], method)
    bump_ecu = _ecu(model, bump_resp, "bump")
    road_resp = _run(model, *runs["road"], method)
    road_ecu = _ecu(model, road_resp, "road")
    row = {f"bump: {k}": v for k, v in ride_metrics(bump_resp, model, metrics["bump"]).items()}
    row.update(
        {f"road: {k}": v for k, v in ride_metrics(road_resp, model, metrics["road"]).items()}
    )
    row["road: rms actuator force [N]"], row["road: mean actuator power [W]"] = _actuator(road_resp)
    failed = [r for r in (bump_resp, road_resp) if not r.success]
    note = f"the fixed-step run did not succeed ({failed[0].message})" if failed else ""
    for ecu in (bump_ecu, road_ecu):
        if ecu is not None:
            row.update(ecu[0])
            note = "; ".join(filter(None, [note, ecu[1]]))
    return row, note


def _ecu(model: VehicleModel, resp, run: str) -> tuple[dict, str] | None:
    """A sampled design's largest force and travel at every tick and its solve times.

    The force is read at the ticks (the move held from each), the travel at
    every sample; the solve times are the controller's own log (an MPC's
    QP solves), None for a law without one. None for a continuous design.
    """
    law = getattr(model.system, "law", None)
    if law is None:
        return None
    travel = np.asarray(resp.outputs)[list(resp.output_labels).index("susp_travel")]
    row = {
        f"ecu: {run} max |fa| [N]": float(np.max(np.abs(resp.moves))),
        f"ecu: {run} max |susp_travel| [m]": float(np.max(np.abs(travel))),
    }
    log = getattr(law, "log", None)
    times = np.asarray(log.solve_times if log is not None else [np.nan]) * 1e3
    row[f"ecu: {run} solve median [ms]"] = float(np.median(times))
    row[f"ecu: {run} solve worst [ms]"] = float(np.max(times))
    penalty = list(log.penalty_ticks) if log is not None else []
    row[f"ecu: {run} travel penalty ticks"] = float(len(penalty))
    note = ""
    if penalty:
        note = (
            f"{run}: the soft travel limit's penalty was active on {len(penalty)} ticks, "
            f"from t = {penalty[0]:.2f} s to {penalty[-1]:.2f} s"
        )
    if log is not None and log.failures:
        note = "; ".join(filter(None, [note, f"{run}: {len(log.failures)} QPs not solved"]))
    return row, note


def _transmissibility(model: VehicleModel, f: np.ndarray) -> dict[str, np.ndarray]:
    """|H| from the road height to the body acceleration and the tire deflection at ``f`` [Hz]."""
    j = model.system.input_labels.index("zr")
    H = np.asarray(control.frequency_response(model.system, 2 * np.pi * f).complex)
    return {s: np.abs(H[model.output(s), j]) for s in ("body_acc", "tire_defl")}


def _older_roads(road, bump, road_class, speed, road_seed, bump_height) -> tuple[ISO8608Road, Bump]:
    """``(road, bump)`` from 0.1's keywords: ``road_class``, ``speed`` and ``road_seed``
    give ``ISO8608Road(road_class, speed=speed, seed=road_seed)`` and ``bump_height``
    gives `DEFAULT_BUMP` of that height, each with a DeprecationWarning naming the new form
    (at the caller of `compare_controllers`); beside ``road=`` or ``bump=`` they are
    refused by name."""
    given = {"road_class": road_class, "speed": speed, "road_seed": road_seed}
    given = {k: v for k, v in given.items() if v is not None}
    if given:
        first = next(iter(given))
        if road is not DEFAULT_ROAD:
            raise ParameterError(first, given[first], "not given beside road= (give road= alone)")
        cls = DEFAULT_ROAD.road_class if road_class is None else road_class
        v = DEFAULT_ROAD.speed if speed is None else speed
        seed = DEFAULT_ROAD.seed if road_seed is None else road_seed
        road = ISO8608Road(cls, speed=v, seed=seed)  # a bad value is refused by name
        warnings.warn(
            f"compare_controllers({'=, '.join(given)}=) is deprecated and will be removed in "
            f"the next minor release: use road={iso8608_spelling(cls, v, seed)}",
            DeprecationWarning,
            stacklevel=3,
        )
    if bump_height is not None:
        if bump is not DEFAULT_BUMP:
            raise ParameterError(
                "bump_height", bump_height, "not given beside bump= (give bump= alone)"
            )
        bump = replace(DEFAULT_BUMP, height=bump_height)  # the height refused by name
        warnings.warn(
            "compare_controllers(bump_height=) is deprecated and will be removed in the next "
            f"minor release: use bump=qc.road.Bump(height={bump_height!r}, "
            f"length={DEFAULT_BUMP.length!r}, speed={DEFAULT_BUMP.speed!r})",
            DeprecationWarning,
            stacklevel=3,
        )
    iso, pulse = as_road(road), as_road(bump, where="bump")
    if not isinstance(iso, ISO8608Road):
        raise ParameterError(
            "road", iso, "a qc.road.ISO8608Road (its RMS metrics, exact values and Pareto front)"
        )
    if not isinstance(pulse, Bump):
        raise ParameterError("bump", pulse, "a qc.road.Bump (the bump run's 1 − cos bump)")
    return iso, pulse


def compare_controllers(
    params=None,
    *,
    designs: Sequence[str] = DESIGNS,
    road: ISO8608Road = DEFAULT_ROAD,
    bump: Bump = DEFAULT_BUMP,
    road_duration: float = 10.0,
    bump_duration: float = 15.0,
    method: str = "rk4",
    cmax: float = 4000.0,
    hinf_beta: float = 0.5,
    freqs_hz=None,
    road_metrics: Sequence[str] = ROAD_METRICS,
    bump_metrics: Sequence[str] = BUMP_METRICS,
    road_class: str | None = None,
    speed: float | None = None,
    road_seed: int | None = None,
    bump_height: float | None = None,
) -> ControlComparison:
    """Run every design over a bump and an ISO 8608 road, and tabulate.

    Parameters
    ----------
    params : QuarterCarParams, dict or None
        The car; the seed's by default.
    designs : sequence of str
        A subset of `DESIGNS`, at least one (``'H∞'`` needs slycot). A
        selection without a linear design has no transmissibility and no
        exact metrics; the Pareto front is then the passive one alone.
    road : qc.road.ISO8608Road, default `DEFAULT_ROAD`
        The random road of the road run (class C at 20 m/s, seed 0),
        sampled at 5 ms (within `qc_control.ride.road.largest_step` up to
        35 m/s); its white road-velocity intensity gives the exact metrics
        and the Pareto front.
    bump : qc.road.Bump, default `DEFAULT_BUMP`
        The bump of the bump run (5 cm high, 1 m long, met at 10 m/s at
        0.5 s), sampled at 2 ms.
    road_duration, bump_duration : float
        The runs' lengths [s]; the bump run must be long enough for the body
        to settle (the seed car's body mode needs about 9 s to reach 2 %).
    method : str
        The fixed-step method of both runs.
    cmax : float
        The semi-active damper's largest damping [N·s/m].
    hinf_beta : float
        The H∞ design's travel/comfort weight (MATLAB's β).
    freqs_hz : array_like, optional
        Transmissibility frequencies; default 200 from 0.1 to 30 Hz.
    road_metrics, bump_metrics : sequence of str, default `ROAD_METRICS`, `BUMP_METRICS`
        The metrics of each run, by name from `qc_control.ride.metrics.METRICS`
        (as `qc_control.ride_metrics` takes them), each a column ``road: name
        [unit]`` or ``bump: name [unit]`` for every design, passive, active
        and semi-active alike. ISO 2631-1's assessment of the vertical
        (`ISO2631_METRICS`): ``a_w_z`` [m/s²] (Wk-weighted RMS, §6.1),
        ``a_v`` [m/s²] (vibration total value, §6.5), ``vdv`` [m/s^1.75]
        (§6.3.2), ``mtvv`` [m/s²] (largest 1 s running RMS, §6.3.1) and
        ``msdv`` [m/s^1.5] (Wf, §9.2.2), e.g. ``road_metrics=ROAD_METRICS +
        ISO2631_METRICS``; on a bump, whose crest factor is well over 9, the
        standard reports VDV and MTVV. The road run's with an exact
        stationary value (``a_w_z``, ``a_v``) are added to ``exact`` too.
    road_class, speed, road_seed, bump_height
        Deprecated: the road's class, speed [m/s] and seed, and the bump's
        height [m], the older form of ``road=qc.road.ISO8608Road(road_class,
        speed=speed, seed=road_seed)`` and ``bump=qc.road.Bump(height=...,
        length=1.0, speed=10.0)``; each warns naming that form.

    Returns
    -------
    ControlComparison

    Raises
    ------
    ValueError
        For an unknown or empty ``designs``, an unknown metric
        (`qc_control.ParameterError` naming ``road_metrics`` or
        ``bump_metrics``), a bad value
        (`qc_control.ParameterError` naming it), or runs whose samples would
        not fit in memory (`qc_control.numerics.limits.ResourceLimitError`,
        before any is made).
    TypeError
        If ``designs`` is a string or not a sequence.
    """
    iso, pulse = _older_roads(road, bump, road_class, speed, road_seed, bump_height)
    p = as_params(params)
    road_duration, bump_duration = _durations(road_duration, bump_duration)
    positive("cmax", cmax, "N·s/m")
    metrics = {
        "road": _metric_names("road_metrics", road_metrics),
        "bump": _metric_names("bump_metrics", bump_metrics),
    }
    built = _design_set(p, iso, float(cmax), _design_names(designs), hinf_beta)
    _check_run_length(built, road_duration, bump_duration)
    T_road = check_time_grid(np.arange(0.0, road_duration + DT_ROAD / 2, DT_ROAD), "T")
    T_bump = check_time_grid(np.arange(0.0, bump_duration + DT_BUMP / 2, DT_BUMP), "T")
    runs = {
        "bump": (T_bump, pulse.samples(T_bump)),
        "road": (T_road, iso.samples(T_road)),
    }
    f = np.geomspace(0.1, 30.0, 200) if freqs_hz is None else np.asarray(freqs_hz, float)
    rows, trans, notes = {}, {}, []
    for name, (model, _) in built.items():
        rows[name], note = _measure(model, runs, method, metrics)
        if note:
            notes.append(f"{name}: {note}")
        if isinstance(model.system, control.StateSpace):
            trans[name] = _transmissibility(model, f)
    linear = {n: m for n, (m, _) in built.items() if isinstance(m.system, control.StateSpace)}
    critical = 2 * math.sqrt(p.ks * p.ms)
    front = pareto_front(
        p,
        {
            "cs": list(np.geomspace(0.1, 3.0, 40) * critical),
            "ks": [k * p.ks for k in (0.5, 0.75, 1.0, 1.5, 2.0)],
        },
        road=iso,
        controllers={n: m for n, m in linear.items() if not n.startswith("passive")},
    )
    table = pd.DataFrame.from_dict(rows, orient="index").astype(float)
    table.index.name = "design"
    sampled = [n for n, (m, _) in built.items() if hasattr(m.system, "law")]
    semi = [n for n in built if n not in linear and n not in sampled]
    if sampled:
        notes.append(
            "sampled-data designs run on a clock beside the continuous car and have no "
            "transmissibility: " + ", ".join(sampled) + " appear in the tables only"
        )
    if semi:
        notes.append(
            "semi-active designs are nonlinear and have no transmissibility: "
            + ", ".join(semi)
            + " appear in the table only"
        )
    return ControlComparison(
        params=p,
        designs={name: what for name, (_, what) in built.items()},
        table=table,
        freqs_hz=f,
        transmissibility=trans,
        bump={
            "height": pulse.height,
            "length": pulse.length,
            "speed": pulse.speed,
            "t0": pulse.t0,
            "duration": bump_duration,
        },
        road={
            "road_class": iso.road_class,
            "speed": iso.speed,
            "duration": road_duration,
            "seed": iso.seed,
        },
        method=method,
        dt={"bump": DT_BUMP, "road": DT_ROAD},
        exact=_exact_table(linear, iso, metrics["road"]),
        pareto=front,
        notes=notes,
    )
