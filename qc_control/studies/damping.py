"""Passive damper optimisation on exact spectral metrics, and the Pareto front.

On white road velocity of intensity ``q`` (an ISO 8608 road of waviness 2
at a constant speed, `qc_control.ride.spectral.iso8608_intensity`), the quarter
car's stationary variances are exact closed forms (Gobbi & Mastinu,
"Analytical description and optimization of the dynamic behaviour of
passively suspended road vehicles", J. Sound Vib. 245(3), 2001; Dahlberg,
"An optimized speed-controlled suspension of a 2-DOF vehicle travelling
on a randomly profiled road", J. Sound Vib. 58(2), 1978), each of the form
``a·cs + b/cs``:

.. math::

    σ^2_{\\ddot x_s} = q\\,\\frac{c_s^2 k_t + k_s^2 (m_s + m_u)}{2 c_s m_s^2},
    \\qquad σ^2_{travel} = q\\,\\frac{m_s + m_u}{2 c_s},

    σ^2_{tire} = q\\,\\frac{c_s^2 k_t M^2 + k_s^2 M^3
        - 2 k_s k_t m_s m_u M + k_t^2 m_s^2 m_u}{2 c_s k_t^2 m_s^2},
    \\quad M = m_s + m_u

(``kt`` is the tire stiffness ``ku``; the tire-deflection form is this
module's solution of the same Lyapunov equation, checked against it in the
tests). A weighted sum ``Σ w_i σ²_i = A·cs + B/cs`` is least at
``cs = √(B/A)``: comfort alone gives ``cs = ks·√((ms + mu)/kt)``, road
holding alone ``cs = √(ks² M³ - 2 ks kt ms mu M + kt² ms² mu)/(√kt · M)``.
Travel alone falls as ``1/cs`` and has no finite optimum; as a constraint
(RMS or 3σ travel within a rattle-space limit) it bounds ``cs`` from
below, and the objective being convex in ``cs``, the constrained optimum
is the larger of the two.

Objectives without a closed form (the ISO 2631-1 Wk-weighted comfort, or a
vehicle other than the quarter car) are minimised by
``scipy.optimize.minimize_scalar`` on the exact Lyapunov metric
(`qc_control.ride.spectral`). ISO 2631-1's stationary metrics are objectives
by their registry names (`qc_control.ride.metrics`): ``a_w_z``, the
Wk-weighted RMS vertical acceleration, and ``a_v``, the vibration total
value ``(Σ k² a_w²)^½`` (ISO 2631-1:1997 §6.4-6.5, §8.2), each the exact
weighting-augmented Lyapunov value of
`qc_control.ride.spectral.spectral_metrics`; like every objective they enter
the weighted sum as their squares, ``a_w² = σ²`` of the weighted signal. The
body's pitch and roll, ``a_w_ry`` and ``a_w_rx`` (We, k = 0.4 and 0.63 m/rad
in ``a_v``), are objectives of a car that has them: `pareto_front` of a half
or full car; `optimal_damping` varies the quarter car's one damper.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import scipy.optimize

from ..models.quarter import QuarterCarParams, as_params, quarter_car_model
from ..models.registry import model_for_params, vehicle_model
from ..models.vehicle import STANDARD_GRAVITY, VehicleModel
from ..numerics.checks import ParameterError, choice, positive
from ..ride.metrics import METRICS
from ..ride.road import ISO8608Road
from ..ride.spectral import (
    DEFAULT_ROAD,
    ISO2631_SPECTRAL,
    require_linear,
    road_intensity,
    spectral_metrics,
    spectral_road,
    white_velocity_variances,
    white_velocity_wk_variance,
)
from .sweeps import design_grid

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "OBJECTIVES",
    "ISO2631_OBJECTIVES",
    "DampingOptimum",
    "ParetoFront",
    "spectral_ride",
    "closed_form_terms",
    "optimal_damping",
    "pareto_front",
]

#: Objective name -> (metric column, what it is). Variances of these are minimised.
OBJECTIVES = {
    "comfort": ("rms_body_acc [m/s²]", "RMS body acceleration"),
    "comfort_wk": ("rms_body_acc_wk [m/s²]", "ISO 2631-1 Wk-weighted RMS body acceleration"),
    "road_holding": ("rms_tire_load / static [-]", "RMS dynamic tire load over the static load"),
    "travel": ("rms_susp_travel [m]", "RMS suspension travel"),
    # ISO 2631-1's exact stationary values, under their registry names and columns
    "a_w_z": (METRICS["a_w_z"].column(), "ISO 2631-1 Wk-weighted RMS vertical acceleration"),
    "a_v": (METRICS["a_v"].column(), "ISO 2631-1 vibration total value"),
    "a_w_ry": (METRICS["a_w_ry"].column(), "ISO 2631-1 We-weighted RMS pitch acceleration"),
    "a_w_rx": (METRICS["a_w_rx"].column(), "ISO 2631-1 We-weighted RMS roll acceleration"),
}
#: The objectives computed by `qc_control.ride.spectral.spectral_metrics` (no closed form).
ISO2631_OBJECTIVES = tuple(name for name in OBJECTIVES if name in ISO2631_SPECTRAL)
#: ISO 2631-1's body rotations -> (the car's output that has it, the verb): an objective
#: only of a car that pitches or rolls (a half or full car's `pareto_front`).
_ROTATIONS = {"a_w_ry": ("pitch_acc", "pitches"), "a_w_rx": ("roll_acc", "rolls")}


def spectral_ride(
    model: VehicleModel, road=None, *, batch=None, wk: bool = False, iso2631: Sequence[str] = ()
) -> pd.DataFrame:
    """Exact RMS ride metrics of linear designs on white road velocity.

    Parameters
    ----------
    model : VehicleModel
        A linear vehicle with a road input (one corner is read: the first).
    road : None, ISO8608Road or float
        Unit intensity (None), an ISO 8608 road (`qc_control.road.ISO8608Road`:
        its intensity ``2π² n0² Gd(n0) v``), or an intensity ``q`` [m²/s]
        (`qc_control.ride.spectral.road_intensity`). A ``(class, speed)``
        pair still works, with a DeprecationWarning naming the ISO8608Road.
        On an ISO 8608 road a car's rear wheels meet the front wheels' road
        ``(a + b)/speed`` later (`qc_control.ride.spectral.rear_delay`); an
        intensity alone has no speed, and its tracks are independent.
    batch : BatchedModel, optional
        Many designs of ``model`` at once.
    wk : bool
        Also the Wk-weighted comfort (one more Lyapunov solve of 4 more states).
    iso2631 : sequence of str, default ()
        Also these of `ISO2631_OBJECTIVES` (``'a_w_z'``, ``'a_v'``), the exact
        stationary ISO 2631-1 values of `qc_control.ride.spectral.spectral_metrics`
        (the car in series with each axis's Annex A weighting, one Lyapunov
        solve per axis).

    Returns
    -------
    pandas.DataFrame
        One row per design: the columns of `OBJECTIVES` (Wk only with ``wk``,
        ISO 2631-1's only as ``iso2631`` names them).
    """
    road = spectral_road(road, stacklevel=2)
    q = road_intensity(road)
    # an ISO 8608 road has a speed: a car's rear wheels meet it a wheelbase later
    speed = road.speed if isinstance(road, ISO8608Road) else None
    corner = model.corners[0]
    var = white_velocity_variances(
        model,
        intensity=q,
        outputs=[model.body_acc, corner.susp_travel, corner.tire_defl],
        batch=batch,
        speed=speed,
    )
    kt = corner.tire_stiffness if batch is None else batch.tire_stiffness[0]
    load = corner.static_load if batch is None else batch.static_load[0]
    cols = {
        OBJECTIVES["comfort"][0]: np.sqrt(var[model.body_acc]),
        OBJECTIVES["road_holding"][0]: kt * np.sqrt(var[corner.tire_defl]) / load,
        OBJECTIVES["travel"][0]: np.sqrt(var[corner.susp_travel]),
    }
    if wk:
        cols[OBJECTIVES["comfort_wk"][0]] = np.sqrt(
            white_velocity_wk_variance(model, intensity=q, batch=batch, speed=speed)
        )
    if iso2631:
        cols.update(spectral_metrics(model, q, list(iso2631), batch=batch, speed=speed))
    return pd.DataFrame({k: np.atleast_1d(v) for k, v in cols.items()})


def closed_form_terms(p: QuarterCarParams, objective: str) -> tuple[float, float]:
    """``(a, b)`` with ``σ² = a·cs + b/cs`` at unit intensity (module formulas)."""
    ms, mu, ks, kt = p.ms, p.mu, p.ks, p.ku
    M = ms + mu
    if objective == "comfort":
        return kt / (2 * ms**2), ks**2 * M / (2 * ms**2)
    if objective == "travel":
        return 0.0, M / 2
    if objective == "road_holding":
        tire = kt / (M * STANDARD_GRAVITY)  # tire load / static per metre of deflection
        a = M**2 / (2 * kt * ms**2)
        b = (ks**2 * M**3 - 2 * ks * kt * ms * mu * M + kt**2 * ms**2 * mu) / (2 * kt**2 * ms**2)
        return tire**2 * a, tire**2 * b
    raise KeyError(objective)


@dataclass(frozen=True)
class DampingOptimum:
    """The damping that minimises an objective.

    Attributes
    ----------
    cs : float
        Optimal damping [N·s/m].
    zeta : float
        ``cs / (2√(ks·ms))`` [-].
    params : QuarterCarParams or object
        The vehicle with that damping.
    value : float
        The objective at the optimum: the weighted sum of variances
        ``Σ wᵢ σᵢ²`` of the `OBJECTIVES` metrics at intensity ``q``.
    metrics : pandas.Series
        The RMS metrics (`OBJECTIVES` columns) at the optimum.
    method : str
        ``'closed form'``, ``'closed form, travel limit'`` (the travel
        constraint is active) or ``'scipy.optimize'``.
    """

    cs: float
    zeta: float
    params: Any
    value: float
    metrics: pd.Series
    method: str


def _refuse_rotation(name: str, value, objective, model: VehicleModel | None = None) -> None:
    """ISO 2631-1's pitch or roll, refused by name on a car without it: ``model``'s
    outputs say; without a model, the quarter car `optimal_damping` varies (one damper
    ``cs``), which neither pitches nor rolls."""
    if objective not in _ROTATIONS:
        return
    label, verb = _ROTATIONS[objective]
    if model is not None and label in model.system.output_labels:
        return
    car = "the quarter car optimal_damping varies" if model is None else repr(model.name)
    raise ParameterError(
        name,
        value,
        f"one of {sorted(OBJECTIVES)}",
        message=(
            f"{name}={value!r}: {objective!r} needs a car whose body {verb}, which {car} "
            "does not; draw a half or full car's front by its parameters, e.g. "
            "qc.pareto_front(qc.HalfCarParams(), {'cs_front': [...], 'cs_rear': [...]}, "
            f"('a_w_z', 'a_w_ry')). Objectives: {sorted(OBJECTIVES)}"
        ),
    )


def _weights(objective) -> dict[str, float]:
    if isinstance(objective, str):
        _refuse_rotation("objective", objective, objective)
        if objective not in OBJECTIVES:
            raise ParameterError(
                "objective", objective, f"one of {sorted(OBJECTIVES)} or a mapping of weights"
            )
        return {objective: 1.0}
    if not isinstance(objective, Mapping) or not objective:
        raise TypeError(
            f"objective must be a name from {sorted(OBJECTIVES)} or a non-empty mapping "
            f"name -> weight, got {objective!r}"
        )
    out = {}
    for k, v in objective.items():
        _refuse_rotation(f"objective[{k!r}]", k, k)
        if k not in OBJECTIVES:
            raise ParameterError(f"objective[{k!r}]", k, f"one of {sorted(OBJECTIVES)}")
        out[k] = positive(f"weight of {k!r}", v, "") if v != 0 else 0.0
    if not any(out.values()):
        raise ParameterError("objective", dict(objective), "weights not all zero")
    return out


def _with_cs(params, cs: float):
    """``params`` with the damping ``cs`` [N·s/m], rebuilt (and checked) by its own class."""
    return type(params).from_mapping({**params.to_dict(changing=["cs"]), "cs": cs})


def _travel_floor(p: QuarterCarParams, q: float, travel_limit, sigmas: float) -> float:
    """The least cs whose RMS travel ``√(q M/(2 cs))`` is within ``travel_limit/sigmas``."""
    if travel_limit is None:
        return 0.0
    limit = positive("travel_limit", travel_limit, "m") / sigmas
    floor = q * (p.ms + p.mu) / 2 / limit / limit  # inf, not ZeroDivisionError, on underflow
    try:  # the damping it asks for must still make a car the model can resolve
        _with_cs(p, floor)
    except ValueError:
        raise ValueError(
            f"travel_limit={travel_limit!r} m ({sigmas:g}σ) needs cs >= {floor:.3g} N·s/m "
            "(RMS travel √(q(ms + mu)/(2 cs))), beyond any damper this car's model can "
            "resolve; give a travel limit of a real rattle space (centimetres)"
        ) from None
    return floor


def optimal_damping(
    params=None,
    objective="comfort",
    *,
    road=None,
    travel_limit: float | None = None,
    sigmas: float = 1.0,
    solver: str = "auto",
    bounds: tuple[float, float] | None = None,
    method: str | None = None,
) -> DampingOptimum:
    """The passive damping ``cs`` that minimises a ride objective on a random road.

    Parameters
    ----------
    params : QuarterCarParams, dict, VehicleModel or None
        The vehicle (its ``cs`` is what changes); the seed's by default. A
        `VehicleModel` (with a road input) is optimised numerically through
        its ``rebuild``.
    objective : str or mapping
        ``'comfort'``, ``'comfort_wk'``, ``'road_holding'``, ISO 2631-1's
        ``'a_w_z'`` (Wk-weighted RMS vertical acceleration, m/s²) or
        ``'a_v'`` (vibration total value, m/s²; on a quarter car, which
        neither pitches nor rolls, equal to ``a_w_z``), or weights
        ``{'comfort': 1, 'road_holding': 50, 'travel': 0}`` of the summed
        variances (``'travel'`` alone has no finite optimum: ValueError); an
        RMS objective such as ``a_w_z`` enters as its square. ``'a_w_ry'`` and
        ``'a_w_rx'`` are refused (`qc_control.ParameterError` naming
        ``objective``): the quarter car neither pitches nor rolls.
    road : None, ISO8608Road or float
        See `spectral_ride`; it scales every variance by ``q`` and so moves
        the optimum only through ``travel_limit``.
    travel_limit : float, optional
        Rattle space [m]: ``sigmas`` times the RMS travel must stay within it.
    sigmas : float, default 1
        1 for an RMS limit, 3 for a 3σ limit.
    solver : 'auto', 'closed form' or 'numerical'
        ``'auto'`` uses the closed form where one exists (the quarter car,
        any weights without ``comfort_wk`` or an ISO 2631-1 metric).
    bounds : (float, float), optional
        The numerical search's ``cs`` interval [N·s/m]; default 0.01 to 100
        times the critical damping ``2√(ks·ms)``.
    method : str, optional
        Deprecated spelling of ``solver`` (a ``method`` elsewhere in
        qc_control is an integration method): it warns and is read as
        ``solver``.

    Returns
    -------
    DampingOptimum

    Examples
    --------
    >>> round(optimal_damping().cs, 1)   # ks·√((ms + mu)/kt), seed car
    3496.8
    """
    weights = _weights(objective)
    if set(weights) == {"travel"} or not any(w for k, w in weights.items() if k != "travel"):
        raise ValueError(
            "travel alone falls monotonically with cs ((ms + mu)/(2 cs)): it has no finite "
            "optimum; weigh it with comfort or road_holding, or give it as travel_limit"
        )
    if method is not None:
        if solver != "auto":
            raise ParameterError("method", method, "not given beside solver: give solver alone")
        warnings.warn(
            "optimal_damping(method=...) is deprecated and will be removed in the next minor "
            "release: use solver=... (method names an integration method elsewhere)",
            DeprecationWarning,
            stacklevel=2,
        )
        solver = method
    method = solver
    choice("solver", method, ("auto", "closed form", "numerical"))
    sigmas = positive("sigmas", sigmas, "")
    road = spectral_road(road, stacklevel=2)
    model = (
        params
        if isinstance(params, VehicleModel)
        else quarter_car_model(as_params(params), road=True)
    )
    p = model.params
    if not model.is_nonlinear and not hasattr(p, "cs"):
        raise ValueError(
            f"optimal_damping varies one damper, cs; {type(p).__name__} has one per axle "
            "(cs_front, cs_rear): sweep them with qc.sweep({'cs_front': [...], 'cs_rear': "
            "[...]}, model=..., road=qc.ISO8608Road(...))"
        )
    weighted = {"comfort_wk", *ISO2631_OBJECTIVES}  # a weighting filter: no closed form
    closed = isinstance(p, QuarterCarParams) and not weighted & set(weights)
    closed = closed and not isinstance(params, VehicleModel) and not p.cu  # seed's tire
    if method == "closed form" and not closed:
        raise ValueError(
            "no closed form for this objective or vehicle (an ISO 2631-1 weighting, or not "
            "a quarter car): use solver='numerical' or 'auto'"
        )
    use_closed = closed and method != "numerical"
    wk = "comfort_wk" in weights
    iso = [k for k in ISO2631_OBJECTIVES if k in weights]

    def objective_value(m: VehicleModel) -> tuple[float, pd.Series]:
        row = spectral_ride(m, road, wk=wk, iso2631=iso).iloc[0]
        return sum(w * row[OBJECTIVES[k][0]] ** 2 for k, w in weights.items()), row

    if use_closed:
        a = b = 0.0
        for k, w in weights.items():
            ak, bk = closed_form_terms(p, k)
            a, b = a + w * ak, b + w * bk
        cs = math.sqrt(b / a)
        how = "closed form"
    else:
        critical = 2 * math.sqrt(p.ks * p.ms)
        lo, hi = bounds if bounds is not None else (0.01 * critical, 100 * critical)
        lo, hi = positive("bounds[0]", lo, "N·s/m"), positive("bounds[1]", hi, "N·s/m")
        if hi <= lo:
            raise ParameterError("bounds", bounds, "(low, high) with low < high N·s/m")

        def f(log_cs: float) -> float:
            return objective_value(model.rebuild(_with_cs(p, math.exp(log_cs))))[0]

        res = scipy.optimize.minimize_scalar(
            f, bounds=(math.log(lo), math.log(hi)), method="bounded", options={"xatol": 1e-9}
        )
        cs = math.exp(float(res.x))
        how = "scipy.optimize"
    if travel_limit is not None:
        floor = _travel_floor(p, road_intensity(road), travel_limit, sigmas)
        if cs < floor:
            cs, how = floor, f"{how}, travel limit"
    best = model.rebuild(_with_cs(p, cs))
    value, row = objective_value(best)
    zeta = cs / (2 * math.sqrt(p.ks * p.ms))
    return DampingOptimum(cs, zeta, best.params, float(value), row, how)


# ---------------------------------------------------------------- the Pareto front


def _non_dominated(values: np.ndarray) -> np.ndarray:
    """Mask of the rows of ``values (m, k)`` that no other row dominates (all minimised)."""
    order = np.lexsort(values.T[::-1])
    keep = np.zeros(len(values), dtype=bool)
    front: list[np.ndarray] = []
    for i in order:
        v = values[i]
        if not any(np.all(f <= v) and np.any(f < v) for f in front):
            keep[i] = True
            front = [f for f in front if not (np.all(v <= f) and np.any(v < f))] + [v]
    return keep


@dataclass(frozen=True, eq=False)
class ParetoFront:
    """Non-dominated passive designs, and the figure.

    Attributes
    ----------
    designs : pandas.DataFrame
        The non-dominated, feasible designs: their varied parameters and
        `OBJECTIVES` metrics, sorted by the first objective.
    all_designs : pandas.DataFrame
        Every design, with ``feasible`` (travel limit) and ``pareto`` flags.
    markers : pandas.DataFrame
        The marked points (passive optimum, the seed, controllers) and
        their metrics.
    figure : matplotlib.figure.Figure
    """

    designs: pd.DataFrame
    all_designs: pd.DataFrame
    markers: pd.DataFrame
    figure: Figure


def pareto_front(
    params=None,
    vary: Mapping[str, Sequence[float]] | None = None,
    objectives: Sequence[str] = ("comfort", "road_holding"),
    *,
    road: ISO8608Road | float | None = DEFAULT_ROAD,
    travel_limit: float | None = None,
    sigmas: float = 3.0,
    controllers: Mapping[str, Any] | None = None,
) -> ParetoFront:
    """The comfort / road-holding Pareto front of passive designs.

    Every design of the grid ``vary`` (e.g. ``{'cs': [...], 'ks': [...]}``,
    `qc_control.design_grid`) is evaluated exactly (`spectral_ride`, one
    batched Lyapunov solve); designs whose ``sigmas``·RMS travel exceeds
    ``travel_limit`` are infeasible; the front is the feasible designs no
    other feasible design beats in every objective.

    Parameters
    ----------
    params : QuarterCarParams, HalfCarParams, FullCarParams, dict or None
        The base vehicle (a dict or None: the quarter car's). On a half or
        full car the body's metrics are the whole car's and ``'road_holding'``
        and ``'travel'`` are the first corner's (the front), as `spectral_ride`
        reads them.
    vary : mapping
        Parameter name -> values; for the quarter car, default ``cs`` from
        0.05 to 4 times critical damping (60 values); a half or full car's
        must be given (e.g. ``{'cs_front': [...], 'cs_rear': [...]}``).
    objectives : sequence of str
        Two or more of `OBJECTIVES` (``'comfort'``, ``'comfort_wk'``,
        ``'road_holding'``, ``'travel'``, and ISO 2631-1's exact ``'a_w_z'``
        and ``'a_v'`` [m/s²], and of a car that pitches or rolls ``'a_w_ry'``
        and ``'a_w_rx'`` [rad/s²]; e.g. ``('a_w_z', 'road_holding')``); the
        figure plots the first two.
    road : None, ISO8608Road or float
        See `spectral_ride`; default `qc_control.ride.spectral.DEFAULT_ROAD`, ISO 8608
        class C at 20 m/s.
    travel_limit : float, optional
        Rattle space [m].
    sigmas : float, default 3
        The travel limit holds ``sigmas`` standard deviations.
    controllers : mapping, optional
        Name -> a linear closed loop (`VehicleModel`, evaluated exactly) or
        a mapping of `OBJECTIVES` columns to values (e.g. from a simulation),
        marked on the figure.

    Returns
    -------
    ParetoFront
    """
    p, model, vary = _pareto_car(params, vary)
    road = spectral_road(road, stacklevel=2)  # read once: every design sees the same road
    objectives = list(objectives)
    for o in objectives:
        _refuse_rotation("objectives", objectives, o, model)
    if len(objectives) < 2 or any(o not in OBJECTIVES for o in objectives):
        raise ParameterError(
            "objectives",
            objectives,
            f"two or more of {sorted(OBJECTIVES)}",
            message=f"objectives must be two or more of {sorted(OBJECTIVES)}, got {objectives!r}",
        )
    designs = design_grid(vary, p)
    batch = model.batch([type(p).from_mapping(d) for d in designs])
    wk, iso = "comfort_wk" in objectives, [o for o in ISO2631_OBJECTIVES if o in objectives]

    def ride(m: VehicleModel, batch=None) -> pd.DataFrame:
        """The objectives' metrics of ``m`` (or its designs) on this road."""
        return spectral_ride(m, road, batch=batch, wk=wk, iso2631=iso)

    table = ride(model, batch)
    frame = pd.concat([pd.DataFrame(designs)[list(vary)], table], axis=1)
    travel = frame[OBJECTIVES["travel"][0]].to_numpy()
    feasible = np.ones(len(frame), dtype=bool)
    if travel_limit is not None:
        feasible = positive("sigmas", sigmas, "") * travel <= positive(
            "travel_limit", travel_limit, "m"
        )
    cols = [OBJECTIVES[o][0] for o in objectives]
    pareto = np.zeros(len(frame), dtype=bool)
    if feasible.any():
        pareto[np.flatnonzero(feasible)[_non_dominated(frame.loc[feasible, cols].to_numpy())]] = (
            True
        )
    frame["feasible"], frame["pareto"] = feasible, pareto
    front = frame[pareto].sort_values(cols[0]).reset_index(drop=True)

    marks: dict[str, pd.Series] = {}
    seed_row = ride(model).iloc[0]
    marks["passive (this car)"] = seed_row
    for goal in ("comfort", "road_holding") if isinstance(p, QuarterCarParams) else ():
        opt = optimal_damping(p, goal, road=road, travel_limit=travel_limit, sigmas=sigmas)
        marks[f"passive optimum: {goal} (cs={opt.cs:.0f})"] = ride(
            quarter_car_model(opt.params, road=True)
        ).iloc[0]
    for name, ctrl in (controllers or {}).items():
        if isinstance(ctrl, VehicleModel):
            require_linear(ctrl, f"controllers[{name!r}]: the closed loop")
            marks[name] = ride(ctrl).iloc[0]
        else:
            marks[name] = pd.Series(dict(ctrl))
    markers = pd.DataFrame(marks).T
    fig = _pareto_figure(frame, front, markers, cols, travel_limit, sigmas)
    return ParetoFront(front, frame, markers, fig)


def _pareto_car(params, vary) -> tuple[Any, VehicleModel, Mapping[str, Sequence[float]]]:
    """``(params, model, vary)``: a registered vehicle's parameters (a half or full car)
    as given, anything else read as the quarter car's (`as_params`); the quarter car's
    default grid is ``cs`` from 0.05 to 4 times critical damping (60 values)."""
    if model_for_params(params) is None or isinstance(params, QuarterCarParams):
        p = as_params(params)
        model = quarter_car_model(p, road=True)
    else:
        p, model = params, vehicle_model(params, road=True)
    if vary is None:
        if not isinstance(p, QuarterCarParams):
            raise ParameterError(
                "vary",
                vary,
                f"a grid of {type(p).__name__}'s parameters, e.g. "
                "{'cs_front': [...], 'cs_rear': [...]}",
            )
        critical = 2 * math.sqrt(p.ks * p.ms)
        vary = {"cs": list(np.geomspace(0.05, 4.0, 60) * critical)}
    return p, model, vary


def _pareto_figure(frame, front, markers, cols, travel_limit, sigmas) -> Figure:
    from matplotlib.figure import Figure  # heavy and optional: only when plotting

    fig = Figure(figsize=(8, 6), layout="constrained")
    ax = fig.subplots()
    x, y = cols[0], cols[1]
    tcol = OBJECTIVES["travel"][0]
    ax.scatter(frame[x], frame[y], s=8, color="0.8", label="all designs")
    if (~frame["feasible"]).any():
        bad = frame[~frame["feasible"]]
        ax.scatter(bad[x], bad[y], s=10, marker="x", color="0.6", label="travel limit exceeded")
    sc = ax.scatter(front[x], front[y], c=front[tcol], cmap="viridis", s=28, zorder=3)
    ax.plot(front[x], front[y], color="0.3", lw=0.8, zorder=2, label="Pareto front")
    fig.colorbar(sc, ax=ax, label=tcol.replace("rms_susp_travel", "RMS suspension travel"))
    markers_cycle = ["*", "D", "s", "^", "v", "P", "X", "o", "<", ">", "h"]
    for i, (name, row) in enumerate(markers.iterrows()):
        if x in row and y in row and pd.notna(row[x]) and pd.notna(row[y]):
            ax.scatter(
                [row[x]],
                [row[y]],
                marker=markers_cycle[i % len(markers_cycle)],
                s=90,
                edgecolor="k",
                zorder=4,
                label=name,
            )
    ax.set_xlabel(f"{OBJECTIVES[_name_of(x)][1]} [{x.split('[')[-1]}")
    ax.set_ylabel(f"{OBJECTIVES[_name_of(y)][1]} [{y.split('[')[-1]}")
    # the objectives by name ("comfort", "road holding", ISO 2631-1's "a_w_ry" ...)
    x_name, y_name = (_name_of(c).replace("road_holding", "road holding") for c in (x, y))
    title = f"Passive designs: {x_name} against {y_name}"
    if travel_limit is not None:
        title += f" ({sigmas:g}σ travel <= {1e3 * travel_limit:g} mm)"
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="best")
    return fig


def _name_of(column: str) -> str:
    return next(k for k, (c, _) in OBJECTIVES.items() if c == column)
