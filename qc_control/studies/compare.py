"""Compare fixed-step methods against python-control's exact response.

`compare_methods` computes every number of the comparison once; the
report writers in `qc_control.report` only format them.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple, Protocol, cast, runtime_checkable

import control
import numpy as np
import pandas as pd
import scipy
import scipy.signal
from scipy.integrate import OdeSolution, solve_ivp

from .. import compat
from ..models.modal import ModalAnalysis, modal_analysis
from ..models.quarter import (
    SEED_X0,
    as_params,
)
from ..models.registry import MODELS, model_for_params, model_for_system
from ..models.vehicle import VehicleModel
from ..numerics.checks import ParameterError
from ..numerics.clocked import ClockedLoop, exact_clocked
from ..numerics.integrate import (
    DivergenceWarning,
    check_time_grid,
    checked_uniform_step,
    uniform_step,
)
from ..numerics.limits import check_memory
from ..numerics.lti import is_nonlinear_system
from ..numerics.methods import ButcherTableau, get_method
from ..numerics.reference import exact_response
from ..numerics.sampled import linear_input
from ..numerics.stability import max_stable_step, numerical_modes, step_is_stable
from ..responses.timeresp import (
    check_initial_state,
    check_input_samples,
    forced_response,
    initial_response,
    input_output_response,
)
from ..ride.comfort import Transmissibility, ride_metrics, transmissibility
from ..ride.road import Road
from .confirm import CostCheck, confirmed_costs
from .on_road import road_problem
from .peers import RTOLS, WorkPrecision, check_solvers, work_precision
from .ride_cost import RideCost
from .timing import TIME_COLUMNS, interleaved_times

__all__ = [
    "ReferenceBudgetError",
    "MethodComparison",
    "ComparisonProblem",
    "Provenance",
    "compare_methods",
    "Reference",
    "exact_reference",
    "sampled_reference",
    "method_responses",
    "max_error",
    "error_table",
    "convergence_study",
    "ConvergencePoint",
    "observed_orders",
    "cost_to_reach",
    "mode_errors",
    "ride_comparison",
    "method_timings",
    "best_time",
    "DEFAULT_METHODS",
    "DEFAULT_X0",
    "DEFAULT_T_END",
    "DEFAULT_H",
    "TOLERANCES",
    "NonlinearReference",
    "nonlinear_reference",
    "NonlinearStudy",
    "NONLINEAR_LEVELS",
]

#: The default scenario: the seed's vehicle, body released from 5 cm, 0-10 s, h = 0.01 s.
DEFAULT_METHODS = ("euler", "midpoint", "heun", "rk4")
DEFAULT_X0 = SEED_X0
DEFAULT_T_END = 10.0
DEFAULT_H = 0.01
#: Accuracies [m] at which the report names the cheapest method.
TOLERANCES = (1e-3, 1e-6, 1e-9)
#: Refinements h, h/2, ..., h/2**_LEVELS for convergence and work-precision.
_LEVELS = 5
#: Errors below this [m] are rounding, not truncation: left out of order fits.
_ROUNDING_FLOOR = 1e-13


@runtime_checkable
class Provenance(Protocol):
    """The run a comparison came from, as a report records it.

    Whatever set the run up (the command line's Scenario is one) can say
    the command that redoes it and its whole setting as TOML; the report
    prints the one and saves the other as ``scenario.toml``.
    """

    def command(self) -> str:
        """The command that redoes the run."""
        ...

    def to_toml(self) -> str:
        """The run's whole setting: vehicle, initial state, input, time span, step, methods."""
        ...


@dataclass(eq=False)
class ComparisonProblem:
    """What every method of a comparison solves, as `compare_methods` checked it.

    Attributes
    ----------
    system : control.StateSpace or control.NonlinearIOSystem
        The vehicle's system.
    params : object
        The parameters the vehicle was built from (None for a bare system).
    model : VehicleModel
        The vehicle's description (signal roles, units).
    T : ndarray
        The uniform output grid [s].
    X0 : ndarray
        The initial state.
    U : ndarray or None
        The input samples on ``T``; None for the free response.
    h : float
        The step [s]; ``substeps`` of it per interval of ``T``.
    substeps : int
    methods : tuple of ButcherTableau
    """

    system: control.NonlinearIOSystem
    params: Any
    model: VehicleModel
    T: np.ndarray
    X0: np.ndarray
    U: np.ndarray | None
    h: float
    substeps: int
    methods: tuple[ButcherTableau, ...]


@dataclass(eq=False)
class MethodComparison(ComparisonProblem):
    """The numbers of a method comparison. See `compare_methods`.

    Its problem (system, grid, start, input, step, methods) is that of
    `ComparisonProblem`.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per method (index: method name); columns with units.
    modes : ModalAnalysis
        The exact modes (damping per mode).
    numerical_modes : dict[str, pandas.DataFrame]
        Per method, each mode's frequency and damping as the method sees it.
    convergence : pandas.DataFrame
        Long form: method, h, steps, nfev, time, error, for h, h/2, ..., h/32.
    cost : pandas.DataFrame
        RHS evaluations needed to reach each accuracy in `TOLERANCES`
        (index, max |xs error| in m) per method (columns).
    cost_kind : pandas.DataFrame
        For each entry of `cost`: ``'confirmed'`` (a run at that count
        reaches the accuracy, `cost_checks`), ``'missed'`` (runs from the
        estimate on did not: no cost), or the kind of an estimate no run
        checked (a nonlinear car; a run too long): ``'interpolated'``
        (log-log, between two refinements that bracket it) or
        ``'extrapolated'`` (``e = C h^p`` with the method's order p from
        the nearest refinement, and never a step beyond ``h_max``).
    coincident : dict
        ``{(a, b): max |x_a - x_b|}`` [m] over the states, for each pair of
        methods whose trajectories agree to 1e-12 m (e.g. Midpoint and
        Heun on linear systems).
    reference : control.TimeResponseData
        python-control's exact response on the grid.
    reference_error : float
        The reference's own accuracy [m]: its largest difference from an
        independent exact evaluation (see `compare_methods`).
    responses : dict[str, FixedStepResponse]
        Each method's response at the chosen h.
    ride : pandas.DataFrame or None
        Under a road input: `qc_control.ride_metrics` of the reference
        (first row) and of each method.
    ride_error : pandas.DataFrame or None
        Each method's ride metrics against the reference's [%].
    transmissibility : Transmissibility or None
        Under a road input: the road-to-ride frequency responses.
    scenario : Provenance or None
        The run this comparison came from, when it came from one (the
        command line's Scenario sets itself here); the report prints its
        command and saves its TOML.
    nonlinear : NonlinearStudy or None
        On a nonlinear system: events, the order with and without them,
        where Midpoint and Heun part, the linearisation behind ``modes``.
    peers : WorkPrecision or None
        With ``solvers``: every run of the work–precision study (the
        fixed-step ladder, the peers and the adaptive pairs over the
        tolerances), `qc_control.studies.peers`.
    sampled_car : control.StateSpace or None
        On a sampled-data loop: the car between the ticks, whose modes and
        step limits the comparison reports (the controller acts only at the
        ticks); the reference is then `sampled_reference`.
    ride_cost : RideCost or None
        Set by the stiff car's run (`qc_control.studies.ride_cost`): each
        method's and peer's cheapest setting whose ride metric is within a
        target of the exact one, with its evaluations and time.
    cost_checks : list of CostCheck or None
        On a linear car: the run that checked each estimate of `cost`
        (`qc_control.studies.confirm`); `cost` then holds the confirmed
        counts, and `cost_kind` says 'confirmed' or 'missed' for them.
    """

    table: pd.DataFrame
    modes: ModalAnalysis
    numerical_modes: dict
    convergence: pd.DataFrame
    cost: pd.DataFrame
    cost_kind: pd.DataFrame
    coincident: dict
    reference: control.TimeResponseData
    reference_error: float
    reference_time: float
    reference_description: str
    reference_name: str
    responses: dict
    eigenvalues: np.ndarray
    input_description: str = ""
    ride: pd.DataFrame | None = None
    ride_error: pd.DataFrame | None = None
    transmissibility: Transmissibility | None = None
    scenario: Provenance | None = None
    nonlinear: NonlinearStudy | None = None
    peers: WorkPrecision | None = None
    sampled_car: control.StateSpace | None = None
    ride_cost: RideCost | None = None
    cost_checks: list[CostCheck] | None = None

    def summary(self) -> pd.DataFrame:
        """The headline columns of `table`, for a terminal."""
        model = self.model
        errors = [f"max |{model.body_disp if model else 'xs'} err| [m]"]
        if model is not None and len(model.corners) > 1:  # each corner's travel error
            errors += [f"max |{c.susp_travel} err| [m]" for c in model.corners]
        else:
            errors.append("max |xu err| [m]")
        cols = ["order", "RHS evals", "wall time [ms]", *errors, "observed order", "h_max [s]"]
        return self.table[[c for c in cols if c in self.table.columns]]


def best_time(fn: Callable[[], object], repeats: int, warmup: bool = False) -> float:
    """Best wall time [s] of ``repeats`` calls of ``fn``: the least disturbed one.

    ``warmup`` makes one untimed call first (caches, fresh memory pages).
    """
    if warmup:
        fn()
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def _grid(T: np.ndarray, h: float | None) -> tuple[float, int]:
    """The step h and the substeps per interval of the uniform grid T."""
    dt = uniform_step(T)
    if dt is None:
        raise ValueError("T must be uniformly spaced for a method comparison")
    if h is None:
        return dt, 1
    if not (isinstance(h, (int, float)) and math.isfinite(h) and h > 0):
        raise ValueError(f"h must be a finite step > 0 s, got {h!r}")
    k = round(dt / h)
    if k < 1 or abs(k * h - dt) > 1e-9 * dt:
        raise ValueError(f"h = {h!r} s must divide the grid spacing {dt!r} s of T")
    return dt / k, int(k)


def _refined(T: np.ndarray, level: int) -> np.ndarray:
    return np.linspace(T[0], T[-1], (T.size - 1) * 2**level + 1)


def _refined_input(T, U, level):
    """U on the refined grid: linear interpolation keeps the same input function."""
    if U is None:
        return None
    return linear_input(T, U).at(_refined(T, level)).T


def _simulate(sys, T, X0, U, method, substeps, engine="auto"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        if U is None:
            return initial_response(sys, T, X0, method=method, substeps=substeps, engine=engine)
        return forced_response(sys, T, U, X0, method=method, substeps=substeps, engine=engine)


def _observed_order(hs, errors, floor: float = _ROUNDING_FLOOR) -> float:
    hs, errors = np.asarray(hs), np.asarray(errors)
    ok = np.isfinite(errors) & (errors > floor)
    if ok.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(hs[ok]), np.log(errors[ok]), 1)[0])


#: RHS evaluations beyond any run: a cost extrapolated past it is "unreached".
_MAX_COST = 1e15


def _cost_to_reach(conv: pd.DataFrame, method: ButcherTableau, span: float, h_max: float) -> dict:
    """RHS evaluations for max |xs error| = tol, for each tolerance.

    Inside the refinements: log-log interpolation between the two levels
    that bracket the tolerance ('interpolated'). Outside: the error model
    ``e = C h^p`` with the method's order p through the nearest level,
    never beyond the stability limit ('extrapolated').
    """
    rows = conv[
        (conv["method"] == method.name)
        & conv["stable"]
        & np.isfinite(conv["error"])
        & (conv["error"] > _ROUNDING_FLOOR)
    ].sort_values("nfev")
    result = {}
    if rows.empty:
        return {tol: (math.nan, "unreached") for tol in TOLERANCES}
    log_n, log_e = np.log(rows["nfev"].to_numpy(float)), np.log(rows["error"].to_numpy())
    fewest = method.stages * math.ceil(span / h_max) if h_max > 0 else math.inf
    for tol in TOLERANCES:
        lt = math.log(tol)
        if log_e[-1] <= lt <= log_e[0] and len(rows) > 1:
            # errors fall as nfev grows: interpolate on the reversed (increasing) arrays
            log_cost = float(np.interp(lt, log_e[::-1], log_n[::-1]))
            kind = "interpolated"
        else:
            i = 0 if lt > log_e[0] else -1
            log_cost = log_n[i] + (log_e[i] - lt) / method.order
            kind = "extrapolated"
        if log_cost > math.log(_MAX_COST):  # e.g. errors of 1e300 from an x0 of 1e308
            result[tol] = (math.nan, "unreached")
            continue
        result[tol] = (int(max(math.ceil(math.exp(log_cost)), fewest)), kind)
    return result


def _coincident(responses: dict) -> dict:
    names, pairs = list(responses), {}
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            xa, xb = responses[a].states, responses[b].states
            if xa.shape == xb.shape:
                gap = float(np.max(np.abs(xa - xb)))
                if gap <= 1e-12:
                    pairs[(a, b)] = gap
    return pairs


def _limiting_mode(method, modes: ModalAnalysis) -> str:
    """The mode whose eigenvalue sets the method's step limit."""
    limits = {
        m.name: max_stable_step(method, [m.eigenvalue, m.eigenvalue.conjugate()])
        for m in modes.modes
    }
    return min(limits, key=limits.__getitem__)


@dataclass(frozen=True, eq=False)
class Reference:
    """The exact response every method is measured against, and its own accuracy.

    Attributes
    ----------
    response : control.TimeResponseData
        python-control's exact response on the grid.
    error : float
        Its largest difference from an independent exact evaluation, over
        the outputs measured (see `exact_reference`).
    description : str
        What that independent evaluation is.
    name : str
        What computed the reference (with python-control's version).
    time : float
        Its best wall time [s]; NaN when not timed.
    """

    response: control.TimeResponseData
    error: float
    description: str
    name: str
    time: float = math.nan


def exact_reference(sys, T, X0, U=None, *, outputs=None, repeats: int = 0) -> Reference:
    """python-control's exact response and its accuracy against an independent one.

    The accuracy is the largest difference over the output labels in
    ``outputs`` (all outputs by default; `compare_methods` measures the
    displacements, in metres).

    Free response: the modal closed form ``C V e^{Λt} V⁻¹ x0`` at every t
    (no recurrence, so no accumulated rounding). Forced response:
    ``scipy.signal.lsim``, an independent implementation of the same exact
    solution for an input linear between samples. ``repeats > 0`` also
    times ``control``'s call (best of ``repeats``).
    """
    reference = exact_response(sys, T, X0, U)
    A, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.C, sys.D))
    if U is None:
        lam, V = np.linalg.eig(A)
        z0 = np.linalg.solve(V, np.asarray(X0, dtype=complex))
        other = C @ (V @ (z0[:, None] * np.exp(np.outer(lam, T - T[0])))).real
        how = "the modal closed form C·V·exp(Λt)·V⁻¹·x0"
    else:
        lti = (A, np.asarray(sys.B, dtype=float), C, D)  # lsim builds its StateSpace from these
        _, y, _ = scipy.signal.lsim(lti, U.T if U.shape[0] > 1 else U[0], T - T[0], X0=X0)
        other = np.atleast_2d(y.T) if y.ndim > 1 else y[None]
        how = "scipy.signal.lsim"
    labels = list(sys.output_labels)
    rows = [labels.index(label) for label in (labels if outputs is None else outputs)]
    ours = np.asarray(reference.outputs).reshape(other.shape)
    error = float(np.max(np.abs(ours[rows] - other[rows])))
    elapsed = best_time(lambda: exact_response(sys, T, X0, U), repeats) if repeats else math.nan
    name = (
        f"control.{'initial' if U is None else 'forced'}_response "
        f"(python-control {control.__version__})"
    )
    return Reference(reference, error, how, name, elapsed)


def method_responses(
    sys,
    T,
    X0,
    U,
    methods: Sequence[ButcherTableau],
    substeps: int = 1,
    progress: Callable[[str], None] | None = None,
) -> dict:
    """Each method's response at the grid's step: ``{name: FixedStepResponse}``."""
    out = {}
    for tab in methods:
        if progress:
            progress(f"{tab.name}: simulating")
        out[tab.name] = _simulate(sys, T, X0, U, tab, substeps)
    return out


def _outputs(resp, n: int) -> np.ndarray:
    """``(outputs, N)`` padded with inf after a divergence cut at ``resp.time.size``."""
    y = np.asarray(resp.outputs).reshape(len(resp.output_labels), -1)
    if y.shape[1] < n:  # diverged: the missing samples count as infinitely wrong
        y = np.concatenate([y, np.full((y.shape[0], n - y.shape[1]), np.inf)], axis=1)
    return y


def error_table(responses: dict, reference: Reference, model: VehicleModel) -> pd.DataFrame:
    """Per method (rows): max and RMS error of every output, and the final body error.

    Columns ``max |label err| [unit]`` and ``rms label err [unit]`` for each
    output label, in the model's units, and ``final |body err| [m]``.
    """
    ref = np.asarray(reference.response.outputs)
    labels = list(reference.response.output_labels)
    ref = ref.reshape(len(labels), -1)
    body = labels.index(model.body_disp)
    rows = {}
    for name, resp in responses.items():
        # a diverged run's errors are inf (or overflow to it): that is the answer
        with np.errstate(invalid="ignore", over="ignore"):
            err = _outputs(resp, ref.shape[1]) - ref
            row = {}
            for i, label in enumerate(labels):
                unit = model.unit(label)
                row[f"max |{label} err| [{unit}]"] = float(np.max(np.abs(err[i])))
                row[f"rms {label} err [{unit}]"] = float(np.sqrt(np.mean(err[i] ** 2)))
        row[f"final |{model.body_disp} err| [{model.unit(model.body_disp)}]"] = float(
            abs(err[body, -1])
        )
        rows[name] = row
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = "method"
    return frame


class ConvergencePoint(NamedTuple):
    """One method's run at one refinement of the grid: a row of the convergence study."""

    method: str
    level: int
    h: float
    steps: int
    nfev: int
    time: float
    error: float
    stable: bool


class _Refinement(NamedTuple):
    """A method's run on one refined grid, and what it is measured against there."""

    response: Any  # FixedStepResponse
    reference: np.ndarray  # the body displacement of the reference on the same grid [m]
    seconds: float  # wall time of one run [s]; NaN untimed


#: How a path runs a method on a refined grid: ``run(method, level, T, U)``.
_RefinementRun = Callable[[ButcherTableau, int, np.ndarray, np.ndarray | None], _Refinement]


def max_error(y: np.ndarray, reference: np.ndarray, samples: int) -> float:
    """Largest ``|y - reference|`` over ``samples`` samples; infinite for a run cut
    short by a divergence (fewer samples) or one that overflowed."""
    if y.size != samples:
        return math.inf
    # a run that overflowed is infinitely wrong, whatever its samples' arithmetic gives
    with np.errstate(invalid="ignore", over="ignore"):
        error = float(np.max(np.abs(y - reference)))
    return error if math.isfinite(error) else math.inf


def _convergence_points(
    tab: ButcherTableau,
    T: np.ndarray,
    U: np.ndarray | None,
    h: float,
    levels: int,
    h_max: float,
    body: int,
    run: _RefinementRun,
) -> tuple[list[ConvergencePoint], Any]:
    """One method's max body-displacement error at h, h/2, ..., h/2**levels, and its run at h.

    The linear and the nonlinear comparison differ only in ``run``: how the
    method is stepped and what reference it meets on each refined grid.
    """
    points, at_h = [], None
    for level in range(levels + 1):
        Tl, Ul = _refined(T, level), _refined_input(T, U, level)
        refinement = run(tab, level, Tl, Ul)
        response = refinement.response
        if level == 0:
            at_h = response
        y = np.asarray(response.outputs)[body]
        points.append(
            ConvergencePoint(
                method=tab.name,
                level=level,
                h=h / 2**level,
                steps=response.steps,
                nfev=response.nfev,
                time=refinement.seconds,
                error=max_error(y, refinement.reference, Tl.size),
                stable=h / 2**level <= h_max,
            )
        )
    return points, at_h


def _stepped_by_default(tab: ButcherTableau, T: np.ndarray, substeps: int, eig) -> bool:
    """Whether the responses' default engine steps this run step by step: on a uniform
    grid, exactly when the step is beyond the method's stability limit (the responses'
    own test, `step_is_stable` on ``A``'s eigenvalues), where the LTI engine hands
    the diverging run to the generic stepper."""
    dt = checked_uniform_step(T)
    return dt is not None and not step_is_stable(tab, dt / substeps, eig)


def _linear_refinement(
    sys, X0, substeps: int, body: int, timing: bool, eig, exact_at: dict, tab, level, T, U
) -> _Refinement:
    """A method on a refined grid of a linear system, against the exact response there.

    The exact response on each refined grid is the same for every method:
    computed for the first and kept in ``exact_at`` (by level) for the others.
    Its time is a run step by step (``engine='generic'``, whose time follows
    the RHS evaluations), as `method_timings` measures: a second run, unless
    the default engine steps this one step by step itself (a step beyond the
    stability limit), when the one run is that run, timed.
    """
    if level not in exact_at:
        exact_at[level] = np.asarray(exact_response(sys, T, X0, U).outputs)[body]
    exact = exact_at[level]
    if timing and _stepped_by_default(tab, T, substeps, eig):
        start = time.perf_counter()
        response = _simulate(sys, T, X0, U, tab, substeps, "generic")
        return _Refinement(response, exact, time.perf_counter() - start)
    response = _simulate(sys, T, X0, U, tab, substeps)
    seconds = (
        best_time(lambda: _simulate(sys, T, X0, U, tab, substeps, "generic"), 1)
        if timing
        else math.nan
    )
    return _Refinement(response, exact, seconds)


def convergence_study(
    sys,
    T,
    X0,
    U,
    methods: Sequence[ButcherTableau],
    h: float,
    substeps: int,
    model: VehicleModel,
    *,
    levels: int = _LEVELS,
    timing: bool = True,
    progress: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Max body-displacement error at h, h/2, ..., h/2**levels, per method (long form).

    Columns (`ConvergencePoint`): method, level, h, steps, nfev, time
    (step-by-step wall time of one run [s], NaN without ``timing``), error
    [m], stable (h within the method's stability limit). The input is
    refined by linear interpolation, which is the same input function.
    """
    eig = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    body = list(sys.output_labels).index(model.body_disp)
    run = functools.partial(_linear_refinement, sys, X0, substeps, body, timing, eig, {})
    points: list[ConvergencePoint] = []
    for tab in methods:
        if progress:
            progress(
                f"{tab.name}: h = {h:g} s, then {levels} halvings of h for the convergence study"
            )
        mine, _ = _convergence_points(tab, T, U, h, levels, max_stable_step(tab, eig), body, run)
        points += mine
    return pd.DataFrame(points)


def observed_orders(
    convergence: pd.DataFrame, levels: int = 2, floor: float = _ROUNDING_FLOOR
) -> pd.Series:
    """Least-squares slope of log error against log h over the first ``levels + 1``
    steps, per method; NaN when a step is unstable or errors are below ``floor``
    (rounding, or within reach of a reference's own error)."""
    out = {}
    for name, rows in convergence.groupby("method", sort=False):
        mine = rows[rows["level"] <= levels]
        out[name] = (
            _observed_order(mine["h"], mine["error"], floor) if mine["stable"].all() else math.nan
        )
    return pd.Series(out, name="observed order", dtype=float)


def cost_to_reach(
    convergence: pd.DataFrame, methods: Sequence[ButcherTableau], span: float, h_max: dict
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """RHS evaluations to reach each of `TOLERANCES`, and how each was found.

    Returns ``(cost, kind)``, indexed by tolerance [m], a column per method.
    """
    reach = {tab.name: _cost_to_reach(convergence, tab, span, h_max[tab.name]) for tab in methods}
    cost = pd.DataFrame({m: {tol: v[0] for tol, v in r.items()} for m, r in reach.items()})
    kind = pd.DataFrame({m: {tol: v[1] for tol, v in r.items()} for m, r in reach.items()})
    cost.index.name = kind.index.name = "tolerance [m]"
    return cost, kind


def mode_errors(
    methods: Sequence[ButcherTableau], h: float, sys, modes: ModalAnalysis
) -> tuple[dict, pd.DataFrame]:
    """Each method's view of the modes at h, and its step limit.

    Returns ``(numerical_modes per method, frame)`` where the frame has, per
    method, ``h_max [s]``, the mode that limits it, whether h is stable, and
    each mode's frequency and damping error.
    """
    eig = np.linalg.eigvals(np.asarray(sys.A, dtype=float))
    per_method, rows = {}, {}
    for tab in methods:
        nm = numerical_modes(tab, h, modes)
        per_method[tab.name] = nm
        h_max = max_stable_step(tab, eig)
        row = {
            "h_max [s]": h_max,
            "limited by": _limiting_mode(tab, modes),
            "stable": bool(h <= h_max),
        }
        for mode_name, mrow in nm.iterrows():
            row[f"{mode_name} freq err [%]"] = mrow["freq error [%]"]
            row[f"{mode_name} zeta err"] = mrow["zeta error"]
        rows[tab.name] = row
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = "method"
    return per_method, frame


def ride_comparison(
    reference: Reference, responses: dict, model: VehicleModel
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """`ride_metrics` of the reference (first row) and of each method, and each
    method's numeric metrics against the reference's [%]."""
    # a diverged method's metrics overflow to inf or NaN: that is its answer, not a fault
    with np.errstate(over="ignore", invalid="ignore"):
        ride = pd.DataFrame(
            {
                "reference": ride_metrics(reference.response, model),
                **{m: ride_metrics(r, model) for m, r in responses.items()},
            }
        ).T
    ride.index.name = "response"
    flags = [c for c in ride.columns if ride[c].map(lambda v: isinstance(v, bool)).all()]
    numeric = ride.drop(columns=flags).astype(float)
    ref = numeric.loc["reference"]
    error = 100 * (numeric.drop(index="reference") - ref) / ref.where(ref != 0)
    error.columns = [c.split(" [")[0] + " [% off]" for c in error.columns]
    return ride.astype({c: float for c in numeric.columns}), error


def method_timings(
    sys, T, X0, U, methods: Sequence[ButcherTableau], substeps: int, repeats: int
) -> pd.DataFrame:
    """Median wall time [ms] of each method step by step (``engine='generic'``, the
    seed's loop, whose time follows the RHS evaluations) and with the LTI engine,
    over ``repeats`` interleaved rounds (`qc_control.studies.timing`)."""
    runs = {
        (tab.name, engine): functools.partial(_simulate, sys, T, X0, U, tab, substeps, engine)
        for tab in methods
        for engine in ("generic", "auto")
    }
    times = interleaved_times(runs, max(1, repeats))
    return pd.DataFrame.from_dict(
        {
            tab.name: {
                "wall time [ms]": 1e3 * times[tab.name, "generic"].wall,
                "LTI engine [ms]": 1e3 * times[tab.name, "auto"].wall,
            }
            for tab in methods
        },
        orient="index",
    )


def _as_model(sys, U, params) -> tuple[control.NonlinearIOSystem, VehicleModel | None, Any]:
    """(system, model, params) from a system, parameters, a model, or None.

    Parameters are built by their registry entry (`qc_control.models.registry`);
    a bare system gets the roles of the registered model whose signals it has.
    """
    if isinstance(sys, VehicleModel):
        return sys.system, sys, sys.params
    if is_nonlinear_system(sys):
        model = _nonlinear_model(sys, params)
        return sys, model, None if model is None else model.params
    if sys is None or isinstance(sys, dict):
        sys = as_params(sys)
    entry = model_for_params(sys)
    if entry is not None:
        model = entry.model(sys, road=U is not None)
        return model.system, model, model.params
    if not isinstance(sys, control.StateSpace):
        raise TypeError(
            f"sys must be a control.StateSpace, a control.NonlinearIOSystem, a VehicleModel "
            f"or the parameters of a registered model ({', '.join(MODELS)}), "
            f"got {type(sys).__name__}"
        )
    if params is not None:  # the vehicle behind the system is given
        p = as_params(params) if isinstance(params, dict) else params
        like = model_for_params(p)
    else:  # the labels give the roles even without the parameters
        p, like = None, model_for_system(sys)
    if like is None:
        return sys, None, None
    model = _model_like(like, p, sys)
    if model is None and params is not None:
        raise ValueError(
            f"params ({type(params).__name__}) do not describe system {sys.name!r}: no "
            f"{like.name} model has its inputs {list(sys.input_labels)} and outputs "
            f"{list(sys.output_labels)}"
        )
    return sys, model, None if model is None else params


def _model_like(entry, params, sys) -> VehicleModel | None:
    """The entry's model (of ``params``) with exactly the system's inputs and
    outputs, with or without its road and actuator inputs; None if none has."""
    signals = (list(sys.input_labels), list(sys.output_labels))
    for road, actuator in itertools.product((False, True), repeat=2):
        try:
            model = entry.model(params, road=road, actuator=actuator)
        except (TypeError, ValueError):  # a model without that input
            continue
        same = (list(model.system.input_labels), list(model.system.output_labels)) == signals
        # and the same states: a model option (a damper top mount) may add one
        if same and model.system.nstates == sys.nstates:
            return model
    return None


def _tableaus(methods: Sequence) -> tuple[ButcherTableau, ...]:
    """The methods by name or tableau: at least one, each once."""
    tabs = tuple(get_method(m) for m in methods)
    if not tabs:
        raise ValueError("methods must name at least one method")
    names = [t.name for t in tabs]
    if len(set(names)) != len(names):
        raise ValueError(f"methods must be distinct, got {names}")
    return tabs


def _default_grid() -> np.ndarray:
    """The comparison's time grid unless one is given: 0-10 s at 0.01 s."""
    return np.linspace(0, DEFAULT_T_END, 1001)


def _checked_problem(
    sys, model, params, T, X0, U, methods: Sequence, h, repeats
) -> ComparisonProblem:
    """The comparison's arguments checked, each error naming the value and what was expected."""
    if model is None:
        raise ValueError(
            f"system {sys.name!r} is not a known vehicle: pass a VehicleModel "
            "(e.g. qc.quarter_car_model(params, road=True)) so that the "
            "comparison knows which output is which"
        )
    T = check_time_grid(_default_grid() if T is None else T, "T")
    h, substeps = _grid(T, h)
    tabs = _tableaus(methods)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats must be a positive integer, got {repeats!r}")
    X0 = check_initial_state(X0, sys.nstates)
    if U is not None:
        U = check_input_samples(U, sys.ninputs, T.size)
    # the finest refinement holds 2**levels times the samples, states and outputs, in the
    # method's response and the exact one, with the scans' temporaries
    finest = (T.size - 1) * 2**_LEVELS + 1
    check_memory(
        6 * finest * (sys.nstates + sys.noutputs + sys.ninputs) * 8,
        f"a method comparison over {T.size - 1} steps (refined down to h/{2**_LEVELS})",
        "use a shorter run or a larger step",
    )
    return ComparisonProblem(sys, params, model, T, X0, U, h, substeps, tabs)


@dataclass(frozen=True, eq=False)
class _Measured:
    """What the linear or the nonlinear path measured, for `_comparison` to assemble.

    ``linear`` is the system itself, or its linearisation at rest: its
    eigenvalues give the modes, the step limits and the numerical modes.
    ``orders`` holds the ``observed order`` column(s) of the table.
    """

    reference: Reference
    responses: dict
    linear: control.StateSpace
    modes: ModalAnalysis
    convergence: pd.DataFrame
    orders: pd.DataFrame
    times: pd.DataFrame
    transmissibility: Transmissibility | None = None
    nonlinear: NonlinearStudy | None = None


def _on_road(problem: ComparisonProblem) -> bool:
    """Whether the input is the vehicle's road, one height per wheel: ride metrics apply."""
    roads = problem.model.road_inputs()
    return problem.U is not None and bool(roads) and list(problem.system.input_labels) == roads


#: Rounds the convergence ladder is timed in: its 24 runs take a second a round on
#: the seed's grid, and the median of 3 already sets Midpoint and Heun (the same
#: evaluations) within their spread of each other.
LADDER_ROUNDS = 3


def _timed_ladder(
    problem: ComparisonProblem, convergence: pd.DataFrame, rounds: int
) -> pd.DataFrame:
    """The convergence study's runs timed step by step (``engine='generic'``, the
    seed's loop, whose time follows the RHS evaluations), all of them in
    interleaved rounds (`qc_control.studies.timing`): the one measurement the
    cost table (level 0) and the work-precision figure both quote."""
    tabs = {t.name: t for t in problem.methods}
    sys, X0, substeps = problem.system, problem.X0, problem.substeps
    runs = {
        (method, level): functools.partial(
            _simulate, sys, _refined(problem.T, level), X0,
            _refined_input(problem.T, problem.U, level), tabs[method], substeps, "generic",
        )
        for method, level in zip(convergence["method"], convergence["level"])
    }  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        # no warm-up: the convergence study has just made each run
        times = interleaved_times(runs, max(1, rounds), warmup=False)
    keyed = [times[key] for key in zip(convergence["method"], convergence["level"])]
    return convergence.assign(
        time=[t.wall for t in keyed],
        time_low=[t.low for t in keyed],
        time_high=[t.high for t in keyed],
        cpu_time=[t.cpu for t in keyed],
    )


def _linear_times(
    problem: ComparisonProblem,
    reference: Reference,
    repeats: int,
    timing: bool,
    convergence: pd.DataFrame,
) -> pd.DataFrame:
    """The wall-time columns of a linear comparison (NaN without ``timing``): the
    step-by-step times are the ladder's at h (`_timed_ladder`), the LTI engine's
    `method_timings`'."""
    names = [t.name for t in problem.methods]
    if not timing:
        return pd.DataFrame(math.nan, index=names, columns=TIME_COLUMNS)
    at_h = convergence[convergence["level"] == 0].set_index("method").reindex(names)
    sys, T, X0, U = problem.system, problem.T, problem.X0, problem.U
    lti = method_timings(sys, T, X0, U, problem.methods, problem.substeps, repeats)[
        "LTI engine [ms]"
    ]
    times = pd.DataFrame(
        {
            "wall time [ms]": 1e3 * at_h["time"],
            "wall min [ms]": 1e3 * at_h["time_low"],
            "wall max [ms]": 1e3 * at_h["time_high"],
            "CPU time [ms]": 1e3 * at_h["cpu_time"],
            "LTI engine [ms]": lti,
        },
        index=names,
    )
    times["time / control"] = times["wall time [ms]"] / (1e3 * reference.time)
    return times


def _measure_linear(
    problem: ComparisonProblem, repeats: int, timing: bool, progress: Callable[[str], None] | None
) -> _Measured:
    """The linear path: python-control's exact response, each method at h and refined."""
    sys, model, T, X0, U = problem.system, problem.model, problem.T, problem.X0, problem.U
    modes = modal_analysis(model)  # its corners name the modes of any registered model
    metres = [label for label in sys.output_labels if model.unit(label) == "m"]
    reference = exact_reference(sys, T, X0, U, outputs=metres, repeats=repeats if timing else 0)
    responses = method_responses(sys, T, X0, U, problem.methods, problem.substeps)
    convergence = convergence_study(
        sys,
        T,
        X0,
        U,
        problem.methods,
        problem.h,
        problem.substeps,
        model,
        timing=False,  # timed below, every run of the ladder in turns
        progress=progress,
    )
    if timing:
        convergence = _timed_ladder(problem, convergence, min(repeats, LADDER_ROUNDS))
    else:
        convergence = convergence.assign(time_low=math.nan, time_high=math.nan, cpu_time=math.nan)
    # one road input: the quarter car's transmissibility (a car on several axles
    # needs the speed for its wheelbase delay: qc.transmissibility(model, speed=V))
    one_road = _on_road(problem) and len(model.road_inputs()) == 1
    return _Measured(
        reference,
        responses,
        sys,
        modes,
        convergence,
        observed_orders(convergence).to_frame(),
        _linear_times(problem, reference, repeats, timing, convergence),
        transmissibility(sys) if one_road and problem.params is not None else None,
    )


def _cost_columns(problem: ComparisonProblem, responses: dict) -> pd.DataFrame:
    """Each method's order, stages, step and what its run at h cost."""
    tabs, names = problem.methods, [t.name for t in problem.methods]
    return pd.DataFrame(
        {
            "order": [t.order for t in tabs],
            "stages": [t.stages for t in tabs],
            "h [s]": problem.h,
            "steps": [responses[n].steps for n in names],
            "RHS evals": [responses[n].nfev for n in names],
        },
        index=names,
    )


def _comparison(
    problem: ComparisonProblem, measured: _Measured, input_description: str
) -> MethodComparison:
    """The comparison from what either path measured: errors, modes, cost, ride."""
    reference, responses, tabs = measured.reference, measured.responses, problem.methods
    numerical, stability = mode_errors(tabs, problem.h, measured.linear, measured.modes)
    span = float(problem.T[-1] - problem.T[0])
    cost, cost_kind = cost_to_reach(
        measured.convergence, tabs, span, stability["h_max [s]"].to_dict()
    )
    checks = None
    if isinstance(problem.system, control.StateSpace):  # an exact reference to run against
        cost, cost_kind, checks = confirmed_costs(
            problem.system, problem.T, problem.X0, problem.U, tabs, cost, cost_kind,
            problem.model.body_disp,
        )  # fmt: skip
    table = pd.concat(
        [
            _cost_columns(problem, responses),
            measured.times,
            error_table(responses, reference, problem.model),
            measured.orders,
            stability,
        ],
        axis=1,
    )
    table.index.name = "method"
    ride, ride_error = (
        ride_comparison(reference, responses, problem.model) if _on_road(problem) else (None, None)
    )
    return MethodComparison(
        **vars(problem),
        table=table,
        modes=measured.modes,
        numerical_modes=numerical,
        convergence=measured.convergence,
        cost=cost,
        cost_kind=cost_kind,
        cost_checks=checks,
        coincident=_coincident(responses),
        reference=reference.response,
        reference_error=reference.error,
        reference_time=reference.time,
        reference_description=reference.description,
        reference_name=reference.name,
        responses=responses,
        eigenvalues=np.linalg.eigvals(np.asarray(measured.linear.A, dtype=float)),
        input_description=input_description,
        ride=ride,
        ride_error=ride_error,
        transmissibility=measured.transmissibility,
        nonlinear=measured.nonlinear,
    )


def compare_methods(
    sys,
    T=None,
    X0=DEFAULT_X0,
    *,
    road: Road | None = None,
    U=None,
    methods: Sequence = DEFAULT_METHODS,
    h: float | None = None,
    repeats: int = 5,
    timing: bool = True,
    progress: Callable[[str], None] | None = None,
    input_description: str = "",
    params: Any = None,
    events: bool | None = None,
    levels: int | None = None,
    solvers: Sequence[str] | None = None,
    rtols: Sequence[float] = RTOLS,
) -> MethodComparison:
    """Compare fixed-step methods with python-control's exact response.

    The comparison is composed of steps that can be run alone:
    `exact_reference`, `method_responses`, `error_table`,
    `convergence_study`, `observed_orders`, `cost_to_reach`, `mode_errors`,
    `ride_comparison` and (optionally) `method_timings`.

    Parameters
    ----------
    sys : control.StateSpace, control.NonlinearIOSystem, VehicleModel, or parameters
        The vehicle. The parameters of a registered model
        (`QuarterCarParams`, `HalfCarParams`, `FullCarParams`, or a model
        added with `qc_control.register_model`) build it through its
        registry entry, with its road inputs when ``U`` is given; a half or
        full car then needs ``X0`` of its 8 or 14 states. A bare system with
        the signals of a registered model gets that model's roles. A
        `VehicleModel` whose ``system`` is a `control.NonlinearIOSystem`
        (`qc_control.nonlinear_quarter_car_model`, or `closed_loop` with a
        semi-active controller), or such a bare system, is compared against
        a tight ``solve_ivp`` (see Notes); a sampled-data loop against its
        exact response tick by tick.
    T : array_like, optional
        Uniform output grid [s]; default 0-10 s at 0.01 s.
    X0 : array_like, default ``(0, 0, 0.05, 0)``
        Initial state [m/s, m/s, m, m].
    road : qc_control.road.Road, optional
        The road the car drives, sampled on ``T`` under every wheel in the
        car's layout (`qc_control.studies.on_road.road_problem`: the rear
        wheels a wheelbase later). It gives ``U`` and
        ``input_description``; give it instead of them.
    U : array_like, optional
        Input samples on ``T`` (python-control's shapes); ``None`` for the
        free response.
    methods : sequence of str or ButcherTableau
    h : float, optional
        Step [s]; it must divide the spacing of ``T``. Default: the spacing.
    repeats : int, default 5
        Wall times are the best of this many runs: ``wall time`` of the
        step-by-step stepper (``engine='generic'``, the seed's loop, whose
        time follows the RHS evaluations) and ``LTI engine`` of the default
        engine, which gives the same trajectory.
    timing : bool, default True
        Measure wall times at all; without, the time columns are NaN and
        the comparison's numbers do not depend on the machine.
    progress : callable, optional
        Called with a short message as each step starts.
    input_description : str, optional
        What the input is (e.g. "ISO 8608 class C road at 20 m/s"), for
        the report.
    params : parameters of a registered model, optional
        The vehicle behind a bare ``sys`` (the ride metrics need its masses
        for the static wheel load); the model they build must have the
        system's inputs and outputs, or ``ValueError`` says which differ.
    events : bool, optional
        Nonlinear systems only: whether the methods step to each switching
        time (``qc.input_output_response(..., events=True)``). Default: when
        the system has switching functions (``sys.switching``). The
        convergence study runs both ways regardless.
    levels : int, optional
        Nonlinear systems only: refinements h, h/2, ..., h/2**levels of the
        convergence study (default `NONLINEAR_LEVELS`, 2; a linear
        comparison always refines 5 times).
    solvers : sequence of str, optional
        Peers to run beside the methods (`qc_control.studies.peers.SOLVERS`:
        ``'RK45'``, ``'DOP853'``, ``'LSODA'``, ``'Radau'``, ``'BDF'`` through
        ``solve_ivp``, ``'control'`` through ``control.input_output_response``
        at its defaults), each over ``rtols``, measured against the same
        reference; ``cmp.peers`` holds the work–precision study.
    rtols : sequence of float, default 1e-3, 1e-4, ..., 1e-10
        The peers' tolerance ladder (and the embedded qc pairs').

    Returns
    -------
    MethodComparison

    Notes
    -----
    The reference is ``control.initial_response`` (or ``forced_response``),
    the exact solution for an input linear between samples, via the matrix
    exponential. Errors are the largest (``max``) and root-mean-square
    (``rms``) differences over ``T`` of every output, and the difference
    of the body displacement at the last time. The observed order is the
    least-squares slope of log max-error against log h over h, h/2 and
    h/4, leaving out errors below 1e-13 m (rounding). Each mode's error is
    ``numerical_modes`` at the chosen h. Under a road input the comparison
    also holds `qc_control.ride_metrics` of the reference and of each
    method, and the transmissibility.

    **Nonlinear systems.** There is no exact solution: the reference is
    `nonlinear_reference` (DOP853 at rtol 1e-12, restarted at each
    switching event), computed once on the finest grid, with its own error
    estimated against a solve at 100x tighter tolerances. The methods run
    through `qc_control.input_output_response` (with ``events=True`` when
    the system has switching functions). The convergence study runs every
    method with and without events over h, h/2, ..., h/2**levels and fits
    an observed order to each (``table`` columns ``observed order
    (events)`` and ``(no events)``), leaving out errors within 10x of the
    reference's own. Modes, step limits and numerical modes are those of
    the linearisation at the static equilibrium (`control.linearize`).
    Wall times are one run each (no LTI engine); ``nonlinear`` holds the
    event times, the orders and where Midpoint and Heun part.

    **Sampled-data loops** (`qc_control.closed_loop` with a discrete
    controller). The reference is `sampled_reference`: between two ticks
    the car is linear with its move held, so the exact loop is the car's
    matrix-exponential step interval by interval, the law updated at each
    tick from that exact state (its own accuracy: against
    ``control.forced_response`` run tick interval by tick interval). The
    car's step ``h`` must land on every tick. Modes, step limits and
    numerical modes are the car's own (``sampled_car``): the controller
    acts only at the ticks. Wall times are one run each (no LTI engine);
    ``solvers``, ``events`` and ``levels`` do not apply.
    """
    if road is not None:
        if U is not None or input_description:
            raise ParameterError(
                "road", road, "given alone: the road gives U and input_description"
            )
        T = _default_grid() if T is None else T
        sys, U, input_description = road_problem(sys, road, T, params)
    sys, model, params = _as_model(sys, U, params)
    problem = _checked_problem(sys, model, params, T, X0, U, methods, h, repeats)
    peers = check_solvers(solvers)
    if _is_sampled(sys):
        if events is not None or levels is not None or peers:
            raise ValueError(
                "events, levels and solvers do not apply to a sampled-data loop: its car is "
                "linear between the ticks, refined five times, and no solve_ivp peer knows "
                "the clock"
            )
        measured = _measure_sampled(problem, repeats, timing, progress)
        cmp = _comparison(problem, measured, input_description)
        cmp.sampled_car = measured.linear
        return cmp
    elif is_nonlinear_system(sys):
        measured = _measure_nonlinear(problem, events, levels, timing, progress)
    else:
        if events is not None or levels is not None:
            raise ValueError(
                "events and levels apply to nonlinear systems only: a linear comparison has "
                "no switching and always refines h five times"
            )
        measured = _measure_linear(problem, repeats, timing, progress)
    cmp = _comparison(problem, measured, input_description)
    if peers:
        cmp.peers = _peer_study(problem, measured, peers, rtols, progress)
    return cmp


def _engine_times(problem: ComparisonProblem, convergence: pd.DataFrame) -> pd.DataFrame:
    """The fixed-step ladder timed as a user runs it: a linear car through the LTI engine
    (qc's default for it, the same trajectory), best of 3; a nonlinear one as stepped.

    A step beyond a method's stability limit is one the default engine steps step
    by step (a diverging run, never among the cheapest): its time is the
    convergence study's, which timed that same run.
    """
    if is_nonlinear_system(problem.system) or convergence["time"].isna().all():
        return convergence
    tabs = {t.name: t for t in problem.methods}
    eig = np.linalg.eigvals(np.asarray(problem.system.A, dtype=float))
    times = []
    for method, level, stepped in zip(
        convergence["method"], convergence["level"], convergence["time"]
    ):
        T, U = _refined(problem.T, level), _refined_input(problem.T, problem.U, level)
        if _stepped_by_default(tabs[method], T, problem.substeps, eig):
            times.append(stepped)
            continue
        run = functools.partial(
            _simulate, problem.system, T, problem.X0, U, tabs[method], problem.substeps
        )
        times.append(best_time(run, 3, warmup=True))
    return convergence.assign(time=times)


def _peer_study(
    problem: ComparisonProblem, measured: _Measured, solvers, rtols, progress
) -> WorkPrecision:
    """The work–precision study: the peers beside the methods' convergence ladder."""
    sys = problem.system
    return work_precision(
        sys,
        problem.T,
        problem.X0,
        problem.U,
        measured.reference.response,
        list(sys.output_labels).index(problem.model.body_disp),
        _engine_times(problem, measured.convergence),
        methods=problem.methods,
        solvers=solvers,
        rtols=rtols,
        reference_name=measured.reference.name,
        progress=progress,
    )


# ---------------------------------------------------------------- nonlinear systems


@dataclass(frozen=True)
class NonlinearReference:
    """A tight solve_ivp solution of a nonlinear system, and its own accuracy.

    Attributes
    ----------
    t : ndarray (N,)
    x : ndarray (n, N)
        States at ``t``.
    t_events : ndarray
        Where a switching function changed sign (each a restart).
    accuracy : float
        Largest difference from the second solution at 100x tighter
        tolerances, relative to the largest state: the reference's own error.
    rtol : float
    atol : ndarray (n,)
    nfev : int
    event_labels : tuple of str
        Which switching function changed sign at each of ``t_events``
        (``sys.switching_labels`` for ``events=True``, else ``'event k'``).
    state_accuracy : ndarray (n,)
        Per state, the largest difference from the tighter solution, in the
        state's unit (e.g. m for a displacement).
    """

    t: np.ndarray
    x: np.ndarray
    t_events: np.ndarray
    accuracy: float
    rtol: float
    atol: np.ndarray
    nfev: int
    event_labels: tuple[str, ...] = ()
    state_accuracy: np.ndarray = dataclasses.field(default_factory=lambda: np.empty(0))


#: The evaluation budget of one solve of `nonlinear_reference`: this many right-hand-side
#: evaluations per output sample, plus `_BUDGET_BASE` (see there for the measurements).
_BUDGET_PER_SAMPLE = 1000
_BUDGET_BASE = 100_000
#: The value an event function takes where its switching function is exactly 0: the
#: segment's side, as the smallest normal number (scipy only compares signs and brackets).
_ON_THE_KINK = float(np.finfo(float).tiny)


class _BudgetSpent(Exception):
    """Raised inside a solve when the reference's evaluation budget is spent."""

    def __init__(self, t: float, events: int):
        super().__init__(t, events)
        self.t = t
        self.events = events


def _sided_events(switching, sides: np.ndarray, t_start: float) -> list:
    """Terminal event functions for one segment of the piecewise solve.

    Each reports a sign change of its switching function *away from the side
    ``sides[k]`` the segment starts on*: at ``t_start`` it takes that side
    whatever its value (a restart just after a root may sit a rounding on the
    old side, and scipy would find the same root again at the start, for ever),
    and wherever the function is exactly 0 it keeps the side too (a state
    resting on a kink, e.g. a bump stop of clearance 0 at rest, has not crossed
    it: scipy counts a 0 as a crossing at every step).
    """
    funcs = []
    for k, side in enumerate(sides):

        def g(t, x, k=k, side=side):
            value = float(switching(t, x)[k])
            if t == t_start or value == 0.0:
                return value if value * side > 0.0 else side * _ON_THE_KINK
            return value

        g.terminal = True  # type: ignore[attr-defined]
        funcs.append(g)
    return funcs


def _read_inside(f, t_start: float, t_stop: float):
    """``f(t, x)`` read on the open segment ``(t_start, t_stop)``: at an end, one ulp in.

    The state at a segment's ends is the limit from inside it, so the right-hand
    side there is too: a road that jumps at a break (a step, ``zr = height`` for
    ``t >= t0``) is read before the jump by the segment that ends at ``t0`` and
    after it by the one that starts there. DOP853's last stage sits at the step's
    end (c = 1): read after a jump, it kicks the state by ``h·Δa`` (a 5 cm kerb:
    Δa = ku·0.05/mu = 15 m/s² on the seed's wheel) however small ``h``, and a
    car at rest until then has a tolerance of ~1e-24 that no step meets.
    For a continuous right-hand side it moves the time by one ulp.
    """
    lo, hi = float(np.nextafter(t_start, math.inf)), float(np.nextafter(t_stop, -math.inf))

    def inside(t, x):
        return f(min(max(t, lo), hi), x)

    return inside


def _piecewise_ivp(rhs, switching, T, x0, rtol, atol, breaks, budget):
    """DOP853 from event to event: no step straddles a kink of the right-hand side.

    Each segment ends at the first sign change of a switching function (a
    terminal event); the next starts at that root, on the function's other
    side (`_sided_events`), so any number of events between two samples, or
    at the same instant, each get their restart and every sample is read from
    the segment that holds it. ``breaks``: times where the input's slope jumps
    (samples of a piecewise-linear input) or the right-hand side jumps in time
    (a road function's step); each is a restart too, so no step straddles one
    or steps over an input that starts after a quiet stretch, and each
    segment reads the right-hand side inside itself (`_read_inside`).
    ``budget``: right-hand-side evaluations, over all segments, after which
    `_BudgetSpent` is raised (a stalled solve).
    """
    spent = 0
    events: list[float] = []
    which: list[int] = []

    def counted(t, x):
        nonlocal spent
        spent += 1
        if spent > budget:
            raise _BudgetSpent(t, len(events))
        return rhs(t, x)

    t, x = float(T[0]), np.asarray(x0, dtype=float)
    # a switching function exactly 0 at the start has no side yet: the free side (+1, a
    # stop not engaged, a tire in contact) costs at most one restart if it leaves to the other
    sides: np.ndarray = (
        np.where(np.atleast_1d(switching(t, x)) < 0.0, -1.0, 1.0) if switching else np.empty(0)
    )
    out = np.empty((x.size, T.size))
    kw = dict(method="DOP853", rtol=rtol, atol=atol, dense_output=True)
    stops = sorted({float(b) for b in breaks if T[0] < b < T[-1]} | {float(T[-1])})
    for t_stop in stops:
        while t < t_stop:
            rhs_in = _read_inside(counted, t, t_stop)
            on = _read_inside(switching, t, t_stop) if switching else None
            funcs = _sided_events(on, sides, t) if on else None
            sol = solve_ivp(rhs_in, (t, t_stop), x, events=funcs or None, **kw)
            if not sol.success and sol.status != 1:
                raise RuntimeError(
                    f"the reference solve_ivp failed at t = {t:.6g} s: {sol.message}"
                )
            t_end = float(sol.t[-1])
            inside = (T >= t) & (T <= t_end)
            if inside.any():  # a root within rounding of the last one holds no sample
                out[:, inside] = cast(OdeSolution, sol.sol)(T[inside])
            t, x = t_end, sol.y[:, -1]
            if sol.status != 1:
                break
            fired = [k for k, te in enumerate(sol.t_events or []) if te.size and te[-1] == t_end]
            sides[fired] = -sides[fired]
            events.append(t_end)
            which.append(fired[0] if fired else -1)
    return out, np.array(events), spent, which


def _checked_budget(max_nfev, samples: int) -> int:
    """The evaluation budget of one solve: ``max_nfev``, or the default for ``samples``."""
    if max_nfev is None:
        return _BUDGET_PER_SAMPLE * samples + _BUDGET_BASE
    if isinstance(max_nfev, bool) or not isinstance(max_nfev, (int, np.integer)) or max_nfev < 1:
        raise ValueError(f"max_nfev must be a positive integer or None, got {max_nfev!r}")
    return int(max_nfev)


class ReferenceBudgetError(ValueError):
    """The nonlinear reference spent its evaluation budget: the system, not the
    code, is the cause (a jump without a switching function, or motion far
    faster than the samples), so the command line reports it as bad input."""


def _stalled(spent: _BudgetSpent, T, budget: int) -> ReferenceBudgetError:
    """The error for a reference solve that spent its budget: the likely causes, and cures."""
    return ReferenceBudgetError(
        f"the nonlinear reference (DOP853, restarted at each event) spent its budget of "
        f"{budget} right-hand-side evaluations (1000 per sample and 100000; max_nfev) and "
        f"reached only t = {spent.t:.6g} s of {T[0]:g}-{T[-1]:g} s, after {spent.events} "
        "events. Either its steps shrank without end, as they do at a force law that jumps "
        "without a switching function (e.g. a friction term c·sign(v) in a damper or "
        "spring): smooth the law (e.g. c·tanh(v/0.01) for c·sign(v)), or, if the state "
        "crosses the jump rather than sticking at it, give the system a switching function "
        "that changes sign there (sys.switching, or events=); or the motion is far faster "
        "than the samples (e.g. a road of kHz, an event every few µs): sample it finer "
        "(a smaller h) or pass a larger max_nfev"
    )


def _refined_solves(rhs, switching, T, x0, rtol: float, breaks, budget: int):
    """The reference solve at ``rtol`` and the same at 100x tighter tolerances.

    ``atol = rtol · max|x_i|`` per state, the scale from a first solve at rtol 1e-6.
    Returns ``(x, tighter, t_events, nfev, which, atol)``.
    """
    try:
        rough, _, _, _ = _piecewise_ivp(rhs, switching, T, x0, 1e-6, 1e-9, breaks, budget)
        scale = np.maximum(np.max(np.abs(rough), axis=1), 1e-12)
        atol = rtol * scale
        x, t_events, nfev, which = _piecewise_ivp(rhs, switching, T, x0, rtol, atol, breaks, budget)
        with warnings.catch_warnings():
            # scipy raises an rtol below 100·eps (2.2e-14) to it, and says so
            warnings.filterwarnings("ignore", "At least one element of `rtol` is too small")
            tighter, _, _, _ = _piecewise_ivp(
                rhs, switching, T, x0, rtol / 100, atol / 100, breaks, budget
            )
    except _BudgetSpent as spent:
        raise _stalled(spent, T, budget) from None
    return x, tighter, t_events, nfev, which, atol


def nonlinear_reference(
    sys,
    T,
    U=0.0,
    X0=0.0,
    *,
    events=None,
    params=None,
    rtol: float = 1e-12,
    max_nfev: int | None = None,
) -> NonlinearReference:
    """The reference for a nonlinear system: solve_ivp (DOP853) restarted at each event.

    There is no exact solution to compare fixed-step methods with, so the
    reference is scipy's DOP853 at ``rtol`` with ``atol = rtol · max|x_i|``
    per state (the scale from a first solve at ``rtol = 1e-6``), stopped at
    every sign change of the switching functions (``events``, as in
    `qc_control.input_output_response`) and restarted at the root on the
    function's other side, so that no step straddles a kink (any number of
    events between two samples each get their restart; a state resting on
    a kink, where a function is exactly 0, has not crossed it). The input
    is python-control's: linear between the samples; the solve also
    restarts at each sample where the input's slope changes (a kink in
    time, and no first step that leaps over a bump after a quiet stretch),
    and at each of the system's ``jumps`` when it has them: the times [s]
    where its right-hand side jumps in time (`qc_control.nonlinear_quarter_car`
    lists its road function's, e.g. a step's). Each segment reads the
    right-hand side inside itself, at its ends by the limit from inside (one
    ulp in time), as the state there is: a road step at the last sample
    moves nothing before it.
    Its own accuracy is estimated, as the matrix exponential's is for
    linear systems, against a second solve at ``rtol / 100`` and ``atol /
    100`` (scipy raises an rtol below 100·eps, 2.2e-14, to it).

    Each of the three solves has a budget of right-hand-side evaluations:
    by default 1000 per sample of ``T`` plus 100,000. The nonlinear car's
    runs measured 0.6-33 per sample (33 with a tire of 1e9 N/m, its wheel
    hop at 800 Hz against samples 0.5 ms apart; 10 with a 1e12 N/m bump
    stop; 4 on an ISO 8608 road restarted at every sample), so the default
    leaves a margin of 30x, and costs about 20 s at the car's ~10 µs per
    evaluation for 1601 samples. A solve that spends it has stalled: DOP853
    at a force that jumps without a switching function (a friction term
    ``sign(v)``) shrinks its steps without end; or it meets motion far
    faster than its samples (a 1e4 Hz road under samples 0.5 ms apart, the
    wheel leaving and meeting it in every period), which no fixed-step
    method on that grid follows either.

    Parameters
    ----------
    sys : control.NonlinearIOSystem
        Optionally with ``jumps``: the times [s] where its right-hand side
        jumps in time, each a restart (above).
    T, U, X0, params
        As for `qc_control.input_output_response`.
    events : None, True or callable ``events(t, x, u, params)``
    rtol : float, default 1e-12
    max_nfev : int, optional
        The evaluation budget of each solve (default above).

    Returns
    -------
    NonlinearReference

    Raises
    ------
    ValueError
        For a bad argument, naming it; or when a solve spends its budget,
        naming the likely cause (a jump without a switching function) and
        what to do.
    """
    if not isinstance(sys, control.NonlinearIOSystem):
        raise TypeError(f"sys must be a control.NonlinearIOSystem, got {type(sys).__name__}")
    if not (isinstance(rtol, float) and 1e-14 <= rtol < 1e-3):
        raise ValueError(f"rtol must be a float in [1e-14, 1e-3), got {rtol!r}")
    T = check_time_grid(T, "T")
    budget = _checked_budget(max_nfev, T.size)
    x0 = check_initial_state(X0, sys.nstates)
    u = check_input_samples(U, sys.ninputs, T.size)
    u_of_t = linear_input(T, u)
    compat.update_params(sys, params)
    current = compat.current_params(sys, params or {})
    if events is True:
        g = getattr(sys, "switching", None)
        if g is None:
            raise ValueError(f"events=True needs sys.switching; system {sys.name!r} has none")
    elif events is None or callable(events):
        g = events
    else:
        raise TypeError(f"events must be None, True or a callable, got {events!r}")

    derivative = compat.state_derivative(sys)

    def rhs(t, x):
        return derivative(t, x, u_of_t(t))

    switching = None if g is None else (lambda t, x: np.atleast_1d(g(t, x, u_of_t(t), current)))
    # the input is linear between samples: its slope jumps where its second difference is
    # not 0 (beyond rounding: a grid refined by interpolation adds no kinks)
    tiny = 64 * np.finfo(float).eps * np.max(np.abs(u), axis=1, initial=0.0)[:, None]
    kinks = np.flatnonzero(np.any(np.abs(np.diff(u, 2, axis=1)) > tiny, axis=0)) + 1
    # and where the system's right-hand side jumps in time (a road function's step)
    breaks = [*T[kinks], *getattr(sys, "jumps", ())]
    x, tighter, t_events, nfev, which, atol = _refined_solves(
        rhs, switching, T, x0, rtol, breaks, budget
    )
    per_state = np.max(np.abs(x - tighter), axis=1)
    # a car at rest throughout has x = 0 exactly in both solves: no error, not 0/0
    largest = float(np.max(np.abs(tighter)))
    accuracy = float(np.max(per_state)) / largest if largest > 0 else 0.0
    names = tuple(getattr(sys, "switching_labels", ())) if events is True else ()
    labels = tuple(
        names[k] if 0 <= k < len(names) else (f"event {k}" if k >= 0 else "event") for k in which
    )
    return NonlinearReference(T, x, t_events, accuracy, rtol, atol, nfev, labels, per_state)


# ------------------------------------------------- method comparison on a nonlinear system

#: Refinements h, h/2, ..., h/2**levels of a nonlinear comparison (each a solve per method
#: with and without events; the observed order is fitted over these three).
NONLINEAR_LEVELS = 2
#: Errors within this factor of the reference's own are not fitted for an order.
_REFERENCE_MARGIN = 10.0
#: Midpoint and Heun "part" where their displacements first differ by more than this [m].
_PARTING = 1e-12


@dataclass(frozen=True, eq=False)
class NonlinearStudy:
    """What a comparison on a nonlinear system adds. See `compare_methods`.

    Attributes
    ----------
    events : bool
        Whether the methods' responses (``MethodComparison.responses``,
        ``.table``, ``.convergence``) located the switching times
        (``qc.input_output_response(..., events=True)``).
    switching_labels : tuple of str
        The system's switching functions (``sys.switching_labels``); empty
        when it has none (then the study with and without events is one).
    t_events, event_labels
        Where the reference's switching functions changed sign [s] and
        which (e.g. ``'contact'``: the wheel leaving or regaining the road).
    event_signs : tuple of int
        The sign each switching function has just after its event (+1 or
        -1): for ``'contact'`` -1 is contact lost, +1 regained; for a stop
        -1 is engaged, +1 released.
    airborne : tuple of (float, float)
        The reference's flights: each ``(contact lost, contact regained)``
        [s], the second NaN when the wheel is still in the air at the end.
    method_events : dict
        Per method, ``(t_events, event_labels)`` of its run at h with events.
    convergence : pandas.DataFrame
        Long form over both modes: method, events, level, h, steps, nfev,
        time, error (the largest absolute body-displacement error [m]), stable.
    orders : pandas.DataFrame
        Per method (index): ``with events`` and ``without events``, the
        least-squares slope of log error against log h over h, h/2, h/4
        (NaN without switching functions, or where the errors are within
        ``error_floor`` of the reference).
    parting : dict
        Where Midpoint and Heun part (when both ran): ``max [m]`` (their
        largest displacement difference), ``at [s]`` (its time), ``from [s]``
        (the first sample where they differ by more than 1e-12 m; NaN when
        they never do).
    parting_gap : ndarray or None
        Their displacement difference [m] at every sample of ``T``.
    reference : NonlinearReference
        The DOP853 reference on the finest grid (``T`` refined ``2**levels``
        times).
    error_floor : float
        Errors below this [m] (10x the reference's own error) are not used
        in an order fit.
    linearization : control.StateSpace
        The system linearised at the static equilibrium (``x = 0``,
        ``u = 0``; `control.linearize`): its modes and eigenvalues are the
        comparison's ``modes``, step limits and numerical modes.
    linearization_note : str
        What the linearisation is and where it does not hold.
    """

    events: bool
    switching_labels: tuple[str, ...]
    t_events: np.ndarray
    event_labels: tuple[str, ...]
    event_signs: tuple[int, ...]
    airborne: tuple[tuple[float, float], ...]
    method_events: dict
    convergence: pd.DataFrame
    orders: pd.DataFrame
    parting: dict
    parting_gap: np.ndarray | None
    reference: NonlinearReference
    error_floor: float
    linearization: control.StateSpace
    linearization_note: str


def _switching_labels(sys) -> tuple[str, ...]:
    if getattr(sys, "switching", None) is None:
        return ()
    return tuple(getattr(sys, "switching_labels", ()))


def _bare_rebuild(name: str, params) -> VehicleModel:
    raise ValueError(
        f"system {name!r} was passed bare: build it as a VehicleModel "
        "(qc.nonlinear_quarter_car_model, qc.closed_loop) to rebuild it from other parameters"
    )


def _nonlinear_model(sys, params) -> VehicleModel | None:
    """Roles for a bare NonlinearIOSystem with the signals of a registered model
    (the nonlinear car's, or the quarter car's closed loop)."""
    entry = model_for_system(sys)
    if entry is None:
        return None
    if params is None:
        own = getattr(sys, "params", None) or {}
        names = [k for k in entry.keys() if k in own and k != "zeta"]  # cs states the damping
        params = {k: own[k] for k in names} or None
    if isinstance(params, dict):
        params = entry.params.from_mapping(params)
    p = entry.params() if params is None else params
    like = entry.model(p, road=True)  # the car whose labels these are, with or without road
    if not set(like.road_inputs()) <= set(sys.input_labels):
        like = entry.model(p)
    units = {**like.units, "fa": "N"}
    units.update({s: units.get(s, "-") for s in sys.state_labels})
    units.update({u: units.get(u, "-") for u in sys.input_labels})
    return VehicleModel(sys, p, units, like.roles, functools.partial(_bare_rebuild, sys.name))


def _linearization(sys, params) -> tuple[control.StateSpace, ModalAnalysis, str]:
    """The system linearised at its static equilibrium, its modes, and what they are."""
    lin = control.linearize(sys, np.zeros(sys.nstates), np.zeros(sys.ninputs))
    lin = control.ss(
        lin.A,
        lin.B,
        lin.C,
        lin.D,
        states=list(sys.state_labels),
        inputs=list(sys.input_labels),
        outputs=list(sys.output_labels),
        name=f"{sys.name} (linearised)",
    )
    note = (
        "Modes, eigenvalues and step limits are those of the linearisation at the static "
        "equilibrium (x = 0, u = 0; control.linearize, a finite-difference Jacobian). They "
        "hold near that point only: a wheel in the air, a stop engaged or a clipped damper "
        "changes the local dynamics, and where a kink sits at the equilibrium (a semi-active "
        "law at zero velocity) the difference takes one side of it."
    )
    try:
        modes = modal_analysis(lin)
    except ValueError:
        if params is None:
            raise
        modes = modal_analysis(params)
        note += (
            " The linearisation is not in vehicle form (it has the controller's states), "
            "so the modes named are the passive car's."
        )
    return lin, modes, note


def _event_signs(sys, T, X0, U, ref: NonlinearReference, switching) -> tuple:
    """Each event's new sign (from the signs at T[0], flipped per crossing), and flights."""
    if not switching:
        return (), ()
    u0 = np.zeros(sys.ninputs) if U is None else U[:, 0]
    start = np.sign(np.atleast_1d(sys.switching(T[0], X0, u0, getattr(sys, "params", {}))))
    sign = {label: int(v) or 1 for label, v in zip(switching, start)}
    signs, flights, lost = [], [], math.nan
    for t, label in zip(ref.t_events, ref.event_labels):
        sign[label] = -sign.get(label, 1)
        signs.append(sign[label])
        if label == "contact":
            if sign[label] < 0:
                lost = float(t)
            elif not math.isnan(lost):
                flights.append((lost, float(t)))
                lost = math.nan
    if not math.isnan(lost):
        flights.append((lost, math.nan))
    return tuple(signs), tuple(flights)


def _run_nonlinear(sys, T, X0, U, tab, substeps, events: bool):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        return input_output_response(
            sys,
            T,
            0.0 if U is None else U,
            X0,
            method=tab,
            substeps=substeps,
            events=True if events else None,
        )


def _outputs_along(sys, T, x, U) -> np.ndarray:
    """The system's outputs ``(noutputs, N)`` at the states ``x (n, N)`` and inputs on ``T``."""
    u = np.zeros((sys.ninputs, T.size)) if U is None else U
    return np.column_stack([sys.output(t, x[:, k], u[:, k]) for k, t in enumerate(T)])


def _parting(cmp_responses: dict, sys, model: VehicleModel, T) -> tuple[dict, np.ndarray | None]:
    """Where Midpoint and Heun part: their largest displacement difference and when."""
    if not {"midpoint", "heun"} <= set(cmp_responses):
        return {}, None
    metres = [i for i, label in enumerate(sys.output_labels) if model.unit(label) == "m"]
    a = _outputs(cmp_responses["midpoint"], T.size)[metres]
    b = _outputs(cmp_responses["heun"], T.size)[metres]
    with np.errstate(invalid="ignore"):
        gap = np.nan_to_num(np.max(np.abs(a - b), axis=0), nan=np.inf)
    apart = np.flatnonzero(gap > _PARTING)
    return {
        "pair": ("midpoint", "heun"),
        "max [m]": float(gap.max()),
        "at [s]": float(T[int(np.argmax(gap))]),
        "from [s]": float(T[apart[0]]) if apart.size else math.nan,
    }, gap


def _checked_events(sys, events, switching: tuple[str, ...]) -> bool:
    """Whether the methods step to each switching time: by default, when there are any."""
    if events is None:
        return bool(switching)
    if not isinstance(events, bool):
        raise TypeError(f"events must be None, True or False, got {events!r}")
    if events and not switching:
        raise ValueError(
            f"events=True needs switching functions; system {sys.name!r} has none "
            "(sys.switching, as qc.nonlinear_quarter_car gives)"
        )
    return events


def _checked_levels(levels) -> int:
    levels = NONLINEAR_LEVELS if levels is None else levels
    if isinstance(levels, bool) or not isinstance(levels, int) or not 1 <= levels <= 6:
        raise ValueError(f"levels must be an integer from 1 to 6, got {levels!r}")
    return levels


class _SolvedReference(NamedTuple):
    """The DOP853 reference, and what the comparison reads of it."""

    solution: NonlinearReference  # on T refined 2**levels times
    reference: Reference  # on T: the errors at h and the report's figures
    body: np.ndarray  # the body displacement on the finest grid [m]
    floor: float  # errors below this [m] are not fitted for an order


def _reference_response(sys, T, x, U) -> control.TimeResponseData:
    """The reference's states ``x`` on ``T`` as a response, with the outputs along them."""
    return control.TimeResponseData(
        T,
        _outputs_along(sys, T, x, U),
        x,
        U if U is not None else np.zeros((sys.ninputs, T.size)),
        output_labels=list(sys.output_labels),
        state_labels=list(sys.state_labels),
        input_labels=list(sys.input_labels),
        sysname=sys.name,
        title=f"DOP853 reference for {sys.name}",
        issiso=sys.ninputs == 1 and sys.noutputs == 1,
    )


def _displacement_accuracy(sys, model: VehicleModel, ref: NonlinearReference) -> float:
    """The reference's own error on the displacements [m], which the methods' are measured on."""
    metre_states = [i for i, s in enumerate(sys.state_labels) if model.unit(s) == "m"]
    if metre_states:
        return float(np.max(ref.state_accuracy[metre_states]))
    return ref.accuracy * float(np.max(np.abs(ref.x)))


def _solve_reference(problem: ComparisonProblem, levels: int, switching) -> _SolvedReference:
    """DOP853 once on the finest grid (restarted at each event), timed, with its accuracy."""
    sys, T, U = problem.system, problem.T, problem.U
    fine_T, fine_U = _refined(T, levels), _refined_input(T, U, levels)
    start = time.perf_counter()
    solution = nonlinear_reference(
        sys,
        fine_T,
        0.0 if fine_U is None else fine_U,
        problem.X0,
        events=True if switching else None,
    )
    seconds = time.perf_counter() - start
    error = _displacement_accuracy(sys, problem.model, solution)
    name = (
        "scipy.integrate.solve_ivp (DOP853, rtol 1e-12, atol 1e-12·max|x_i| per state, "
        f"restarted at every switching event; scipy {scipy.__version__})"
    )
    reference = Reference(
        _reference_response(sys, T, solution.x[:, :: 2**levels], U),
        error,
        "the same solve at rtol and atol 100x tighter",
        name,
        seconds,
    )
    body = list(sys.output_labels).index(problem.model.body_disp)
    fine_body = _outputs_along(sys, fine_T, solution.x, fine_U)[body]
    floor = max(_ROUNDING_FLOOR, _REFERENCE_MARGIN * error)
    return _SolvedReference(solution, reference, fine_body, floor)


def _nonlinear_refinement(
    sys,
    X0,
    substeps: int,
    events: bool,
    fine_body,
    levels: int,
    timing: bool,
    tab,
    level,
    T,
    U,
) -> _Refinement:
    """A method on a refined grid of a nonlinear system, against the reference's samples there.

    Its time is the run itself (there is no LTI engine to compare with).
    """
    start = time.perf_counter()
    response = _run_nonlinear(sys, T, X0, U, tab, substeps, events)
    seconds = time.perf_counter() - start if timing else math.nan
    return _Refinement(response, fine_body[:: 2 ** (levels - level)], seconds)


class _EventConvergence(NamedTuple):
    """The convergence study run with and without events."""

    frame: pd.DataFrame  # long form: method, events, level, h, steps, nfev, time, error, stable
    at_h: dict  # (method, events) -> its response at h


def _event_convergence(
    problem: ComparisonProblem,
    solved: _SolvedReference,
    levels: int,
    ways: tuple[bool, ...],
    eig: np.ndarray,
    timing: bool,
    progress: Callable[[str], None] | None,
) -> _EventConvergence:
    """Every method over h, h/2, ..., h/2**levels, each way of stepping in ``ways``."""
    sys, h = problem.system, problem.h
    body = list(sys.output_labels).index(problem.model.body_disp)
    rows: list[tuple[bool, ConvergencePoint]] = []
    at_h = {}
    for tab in problem.methods:
        h_max = max_stable_step(tab, eig)
        for events in ways:
            if progress:
                with_events = " with events" if events else ""
                progress(f"{tab.name}{with_events}: h = {h:g} s and {levels} halvings")
            run = functools.partial(
                _nonlinear_refinement,
                sys,
                problem.X0,
                problem.substeps,
                events,
                solved.body,
                levels,
                timing,
            )
            points, at_h[tab.name, events] = _convergence_points(
                tab, problem.T, problem.U, h, levels, h_max, body, run
            )
            rows += [(events, point) for point in points]
    frame = pd.DataFrame([point for _, point in rows])
    frame.insert(1, "events", [events for events, _ in rows])
    return _EventConvergence(frame, at_h)


def _event_orders(convergence: pd.DataFrame, names: list[str], floor: float, levels: int):
    """Per method, the observed order with and without events over every refinement."""
    orders = pd.DataFrame(
        {
            column: observed_orders(
                convergence[convergence["events"] == events], levels, floor
            ).reindex(names)
            for events, column in ((True, "with events"), (False, "without events"))
        }
    )
    orders.index.name = "method"
    return orders


def _nonlinear_times(convergence: pd.DataFrame, names: list[str]) -> pd.DataFrame:
    """The wall-time columns: each method's run at h; no LTI engine, no exact call."""
    at_h = convergence[convergence["level"] == 0].set_index("method")
    return pd.DataFrame(
        {
            "wall time [ms]": 1e3 * at_h["time"].reindex(names),
            "LTI engine [ms]": math.nan,
            "time / control": math.nan,
        },
        index=names,
    )


def _method_events(at_h: dict, names: list[str], switching) -> dict:
    """Per method, ``(t_events, event_labels)`` of its run at h with events."""
    if not switching:
        return {name: (np.empty(0), ()) for name in names}
    return {name: (at_h[name, True].t_events, at_h[name, True].event_labels) for name in names}


def _measure_nonlinear(
    problem: ComparisonProblem, events, levels, timing: bool, progress: Callable[[str], None] | None
) -> _Measured:
    """The nonlinear path: a DOP853 reference, each method with and without events."""
    sys, T = problem.system, problem.T
    switching = _switching_labels(sys)
    events = _checked_events(sys, events, switching)
    levels = _checked_levels(levels)
    lin, modes, note = _linearization(sys, problem.params)
    if progress:
        progress("reference: solve_ivp DOP853 at rtol 1e-12 (and 1e-14 for its own accuracy)")
    solved = _solve_reference(problem, levels, switching)
    ways = (True, False) if switching else (False,)
    eig = np.linalg.eigvals(np.asarray(lin.A, dtype=float))
    runs = _event_convergence(problem, solved, levels, ways, eig, timing, progress)
    names = [t.name for t in problem.methods]
    responses = {name: runs.at_h[name, events] for name in names}
    long = runs.frame
    convergence = long[long["events"] == events].drop(columns="events").reset_index(drop=True)
    orders = _event_orders(long, names, solved.floor, levels)
    parting, gap = _parting(responses, sys, problem.model, T)
    signs, flights = _event_signs(sys, T, problem.X0, problem.U, solved.solution, switching)
    study = NonlinearStudy(
        events=events,
        switching_labels=switching,
        t_events=solved.solution.t_events,
        event_labels=solved.solution.event_labels,
        event_signs=signs,
        airborne=flights,
        method_events=_method_events(runs.at_h, names, switching),
        convergence=long,
        orders=orders,
        parting=parting,
        parting_gap=gap,
        reference=solved.solution,
        error_floor=solved.floor,
        linearization=lin,
        linearization_note=note,
    )
    main = "with events" if events else "without events"
    table_orders = pd.DataFrame(
        {
            "observed order": orders[main],
            "observed order (events)": orders["with events"],
            "observed order (no events)": orders["without events"],
        }
    )
    times = _nonlinear_times(convergence, names)
    return _Measured(
        solved.reference, responses, lin, modes, convergence, table_orders, times, None, study
    )


# ---------------------------------------------------------------- sampled-data loops


def _is_sampled(sys) -> bool:
    """Whether ``sys`` is a car closed by a controller on a clock (`numerics.clocked`)."""
    return isinstance(sys, ClockedLoop)


def _road_samples(sys: ClockedLoop, T: np.ndarray, U) -> np.ndarray:
    """The loop's external inputs on ``T`` (zeros for a free response)."""
    return (
        np.zeros((sys.ninputs, T.size)) if U is None else np.asarray(U, float).reshape(-1, T.size)
    )


def _sampled_response(sys: ClockedLoop, T, U, x: np.ndarray, title: str):
    """States ``x`` of the loop on ``T`` as a response, with the loop's outputs along them."""
    W = _road_samples(sys, T, U)
    return control.TimeResponseData(
        T,
        sys.outputs_of(x, W),
        x,
        W,
        output_labels=list(sys.output_labels),
        state_labels=list(sys.state_labels),
        input_labels=list(sys.input_labels),
        sysname=sys.name,
        title=title,
        issiso=False,
    )


def _exact_sampled(sys: ClockedLoop, T, X0, U, substeps: int) -> np.ndarray:
    """The exact loop's states on ``T`` (`exact_clocked`): plant, controller, hold."""
    run = exact_clocked(sys, T, _road_samples(sys, T, U), X0, substeps)
    return np.vstack([run.x, run.xc, run.held])


def _tickwise_control(sys: ClockedLoop, T, X0, U) -> np.ndarray:
    """The loop's plant states on ``T`` by python-control: ``control.forced_response``
    of the car over each tick interval, its move held, the law updated at each tick
    from the state python-control reached (an evaluation independent of
    `exact_clocked`'s steps)."""
    A, Bw, Bu, *_ = sys.plant_matrices
    n, nc, _ = sys.sizes
    car = control.ss(A, np.hstack([Bw, Bu]), np.eye(n), 0)
    W = _road_samples(sys, T, U)
    road = linear_input(T, W)
    Cm, Dmw = sys.measured
    law, d, dt = sys.law, sys.delay, sys.period
    law.reset()
    x, xc = np.array(X0[:n], float), np.array(X0[n : n + nc], float)
    queue = np.array(X0[n + nc :], float).reshape(d + 1, sys.nu)
    X = np.empty((n, T.size))
    ticks = int(math.floor((T[-1] - T[0]) / dt * (1 + 1e-12))) + 1
    for k in range(ticks):
        t0 = T[0] + k * dt
        y = Cm @ x + Dmw @ road(t0) + sys.measured_move @ queue[0]
        ahead = road.at(np.minimum(t0 + dt * np.arange(law.preview_ticks + 1), T[-1])).T
        u, xc = law.tick(t0, xc, y, ahead)
        queue = np.vstack([queue[1:], np.reshape(u, (1, -1))])
        t1 = min(t0 + dt, T[-1]) if k < ticks - 1 else T[-1]
        inside = (T >= t0 - 1e-9 * dt) & (T < t1 - 1e-9 * dt) | (k == ticks - 1) & (T >= t0)
        times = np.sort(np.concatenate([[t0], T[inside], [t1]]))
        # a sample within rounding of a tick is that tick (no sliver of an interval)
        times = times[np.concatenate([[True], np.diff(times) > 1e-9 * dt])]
        held = np.repeat(queue[0][:, None], times.size, axis=1)
        inputs = np.vstack([road.at(times).T, held])
        r = control.forced_response(car, times - t0, inputs, x) if times.size > 1 else None
        states = x[:, None] if r is None else np.asarray(r.states).reshape(n, -1)
        X[:, inside] = states[:, np.searchsorted(times, T[inside] - 1e-9 * dt)]
        x = states[:, -1]
    return X


def sampled_reference(sys: ClockedLoop, T, X0, U=None, *, substeps: int = 1, outputs=None,
                      repeats: int = 0) -> Reference:  # fmt: skip
    """The exact response of a sampled-data loop, and its accuracy.

    The reference is `qc_control.numerics.clocked.exact_clocked`: the car's
    exact (matrix-exponential) step between the ticks, the move held, the
    law updated at each tick. Its accuracy is the largest difference over
    the output labels in ``outputs`` (all by default) from
    ``control.forced_response`` run tick interval by tick interval.
    ``repeats > 0`` also times the reference (best of ``repeats``).
    """
    T = np.asarray(T, dtype=float)
    x = _exact_sampled(sys, T, X0, U, substeps)
    response = _sampled_response(sys, T, U, x, f"Tick-by-tick exact response of {sys.name}")
    n = sys.sizes[0]
    other = x.copy()
    other[:n] = _tickwise_control(sys, T, X0, U)
    W = _road_samples(sys, T, U)
    labels = list(sys.output_labels)
    rows = [labels.index(label) for label in (labels if outputs is None else outputs)]
    error = float(np.max(np.abs(sys.outputs_of(x, W)[rows] - sys.outputs_of(other, W)[rows])))
    run = functools.partial(_exact_sampled, sys, T, X0, U, substeps)
    elapsed = best_time(run, repeats) if repeats else math.nan
    name = (
        f"the car's exact step (matrix exponential) between clock ticks, the move held, "
        f"the controller updated every {sys.period:g} s (delay {sys.delay} samples)"
    )
    how = (
        "control.forced_response tick interval by tick interval "
        f"(python-control {control.__version__})"
    )
    return Reference(response, error, how, name, elapsed)


def _run_sampled(sys, T, X0, U, tab, substeps):
    """A method's run of the loop, its steps landing on every tick."""
    return input_output_response(sys, T, 0.0 if U is None else U, X0, method=tab, substeps=substeps)


def _sampled_refinement(sys, X0, substeps: int, body: int, timing: bool, tab, level, T, U):
    """A method on a refined grid of a sampled loop, against the exact loop there."""
    exact = sys.outputs_of(_exact_sampled(sys, T, X0, U, substeps), _road_samples(sys, T, U))
    response = _run_sampled(sys, T, X0, U, tab, substeps)
    run = functools.partial(_run_sampled, sys, T, X0, U, tab, substeps)
    seconds = best_time(run, 1) if timing else math.nan
    return _Refinement(response, exact[body], seconds)


def _sampled_car(sys: ClockedLoop) -> control.StateSpace:
    """The car inside the loop: between ticks it moves with its own modes."""
    A, Bw, Bu, C, Dw, Du = sys.plant_matrices
    n = sys.sizes[0]
    return control.ss(
        A,
        np.hstack([Bw, Bu]),
        C,
        np.hstack([Dw, Du]),
        states=list(sys.state_labels[:n]),
        name=f"{sys.name} (the car between ticks)",
    )


def _measure_sampled(
    problem: ComparisonProblem, repeats: int, timing: bool, progress: Callable[[str], None] | None
) -> _Measured:
    """The sampled-data path: the tick-by-tick exact loop, each method at h and refined.

    Modes, step limits and numerical modes are the car's own: the controller
    acts only at the ticks and does not move them between.
    """
    sys, model, T, X0, U = problem.system, problem.model, problem.T, problem.X0, problem.U
    car = _sampled_car(sys)
    metres = [label for label in sys.output_labels if model.unit(label) == "m"]
    if progress:
        progress("reference: the exact loop, tick by tick")
    reference = sampled_reference(
        sys, T, X0, U, substeps=problem.substeps, outputs=metres,
        repeats=repeats if timing else 0,
    )  # fmt: skip
    responses = {
        tab.name: _run_sampled(sys, T, X0, U, tab, problem.substeps) for tab in problem.methods
    }
    eig = np.linalg.eigvals(np.asarray(car.A, dtype=float))
    body = list(sys.output_labels).index(model.body_disp)
    run = functools.partial(_sampled_refinement, sys, X0, problem.substeps, body, timing)
    points: list[ConvergencePoint] = []
    for tab in problem.methods:
        if progress:
            progress(f"{tab.name}: h = {problem.h:g} s, then {_LEVELS} halvings of h")
        mine, _ = _convergence_points(
            tab, T, U, problem.h, _LEVELS, max_stable_step(tab, eig), body, run
        )
        points += mine
    convergence = pd.DataFrame(points)
    return _Measured(
        reference,
        responses,
        car,
        modal_analysis(car),
        convergence,
        observed_orders(convergence).to_frame(),
        _sampled_times(problem, convergence, reference),
    )


def _sampled_times(
    problem: ComparisonProblem, convergence: pd.DataFrame, reference
) -> pd.DataFrame:
    """The wall-time columns: each method's run at h against the exact loop's."""
    names = [t.name for t in problem.methods]
    at_h = convergence[convergence["level"] == 0].set_index("method")["time"].reindex(names)
    return pd.DataFrame(
        {
            "wall time [ms]": 1e3 * at_h,
            "LTI engine [ms]": math.nan,
            "time / control": at_h / reference.time,
        },
        index=names,
    )
