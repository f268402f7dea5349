"""What each method and solver costs to bring a ride metric within a target of the exact one.

A ride study asks for a number such as the Wk-weighted RMS body
acceleration (ISO 2631-1), not for a trajectory to 1e-6 m. `ride_cost`
measures, for each integrator, the cheapest setting on its ladder whose
ride metric is within ``target`` percent of the exact one:

- **fixed-step methods** over the steps h, h/2, ..., h/2**halvings (each
  run on the comparison's grid with ``substeps``, the input linear between
  samples), stopping at the first step within the target;
- **embedded qc pairs** (``tab.embedded``) also over the tolerance ladder
  with step-size control, stopping at the first tolerance within it;
- **the solve_ivp peers** (`qc_control.studies.peers.SOLVERS`) over the
  same tolerance ladder (atol = rtol · max|x_i| per state, as the
  work–precision study sets it), stopping likewise; ``'control'`` is
  python-control's default call, run once.

The exact value is ``control.forced_response`` (the matrix exponential,
exact for an input linear between samples) through
`qc_control.ride_metrics`. Each run's cost is its right-hand-side
evaluations (a peer's Jacobians counted as n each, as in
`qc_control.studies.peers`) and its wall time (a linear car's fixed-step
run through qc's default engine, which gives the same trajectory as
stepping). Since every ladder grows in cost, the first setting within the
target is the cheapest on it.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import control
import numpy as np
import pandas as pd

from ..models.vehicle import VehicleModel
from ..numerics.integrate import DivergenceWarning
from ..numerics.methods import ButcherTableau
from ..numerics.reference import exact_response
from ..responses.timeresp import forced_response
from ..ride.comfort import ride_metrics
from . import peers

__all__ = ["RIDE_METRIC", "RIDE_TARGET", "RIDE_HALVINGS", "RideCost", "ride_cost"]

#: The ride metric the cost is measured on: ISO 2631-1's comfort measure.
RIDE_METRIC = "rms_body_acc_wk [m/s²]"
#: Within this many percent of the exact value counts as reached.
RIDE_TARGET = 1.0
#: Halvings of h a fixed-step method is given: h/64 at most (5 ms down to 78 µs).
RIDE_HALVINGS = 6

_COLUMNS = ["kind", "name", "h", "rtol", "atol", "value", "error [%]", "evaluations", "time"]


@dataclass(frozen=True, eq=False)
class RideCost:
    """Every run of `ride_cost`, and the cheapest within the target per integrator.

    Attributes
    ----------
    runs : pandas.DataFrame
        One row per run, in ladder order: kind (``'method'`` at a step h,
        ``'adaptive'`` or ``'solver'`` at a tolerance), name, h [s], rtol,
        atol (largest per-state value), value (the metric; NaN for a run
        that diverged or did not finish), error [%] (signed, against the
        exact value), evaluations, time [s], success.
    metric : str
        The ride metric's column in `qc_control.ride_metrics`.
    target : float
        [%].
    exact : float
        The metric of the exact response.
    """

    runs: pd.DataFrame
    metric: str
    target: float
    exact: float

    def cheapest(self) -> pd.DataFrame:
        """Per integrator (index ``name``), its cheapest run within the target; one that
        never reaches it keeps its last run, with ``reached`` False."""
        rows = []
        for _, runs in self.runs.groupby(["kind", "name"], sort=False):
            ok = runs[_within(runs["error [%]"], self.target) & runs["success"].astype(bool)]
            row = (ok if not ok.empty else runs).iloc[0 if not ok.empty else -1]
            rows.append({**row.to_dict(), "reached": not ok.empty, "runs": len(runs)})
        frame = pd.DataFrame(rows).set_index("name")
        return frame


def _within(error: pd.Series, target: float) -> pd.Series:
    return error.abs() <= target


def _metric(response, model: VehicleModel, metric: str) -> float:
    """The ride metric of a response; NaN for one that diverged or was cut short."""
    if not getattr(response, "success", True):
        return math.nan
    with np.errstate(over="ignore", invalid="ignore"):
        value = float(ride_metrics(response, model, metrics=(_metric_name(metric),))[metric])
    return value if math.isfinite(value) else math.nan


def _metric_name(column: str) -> str:
    """``'rms_body_acc_wk'`` of the column ``'rms_body_acc_wk [m/s²]'``."""
    return column.split(" [")[0]


@dataclass(frozen=True)
class _RideProblem:
    """The car, its road, the exact metric and how to judge a run."""

    model: VehicleModel
    T: np.ndarray
    X0: np.ndarray
    U: np.ndarray
    metric: str
    exact: float
    scale: np.ndarray  # max |x_i| of the exact response, for the peers' atol
    repeats: int

    def row(self, kind, name, value, evaluations, seconds, success, h=math.nan, rtol=math.nan,
            atol=math.nan) -> dict:  # fmt: skip
        error = 100 * (value - self.exact) / self.exact if math.isfinite(value) else math.nan
        return dict(zip(_COLUMNS, (kind, name, h, rtol, atol, value, error, evaluations, seconds)),
                    success=bool(success) and math.isfinite(value))  # fmt: skip

    def reached(self, row: dict, target: float) -> bool:
        return row["success"] and abs(row["error [%]"]) <= target

    def response(self, values: np.ndarray | None):
        """Outputs ``(noutputs, N)`` as a response `qc_control.ride_metrics` reads."""
        sys = self.model.system
        if values is None:
            return None
        return control.TimeResponseData(
            self.T, values, None, self.U, output_labels=list(sys.output_labels),
            input_labels=list(sys.input_labels), sysname=sys.name,
        )  # fmt: skip


def _fixed_ladder(problem: _RideProblem, tab: ButcherTableau, substeps: int, h: float,
                  halvings: int, target: float) -> list[dict]:  # fmt: skip
    """``tab`` at h, h/2, ... until the metric is within ``target``."""
    sys, T, X0, U = problem.model.system, problem.T, problem.X0, problem.U
    rows = []
    for level in range(halvings + 1):
        k = substeps * 2**level

        def run(k=k):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DivergenceWarning)
                return forced_response(sys, T, U, X0, method=tab, substeps=k)

        resp, seconds = peers.best_of(run, problem.repeats)
        value = _metric(resp, problem.model, problem.metric)
        rows.append(
            problem.row("method", tab.name, value, resp.nfev, seconds, resp.success, h=h / 2**level)
        )
        if problem.reached(rows[-1], target):
            break
    return rows


def _adaptive_ladder(problem: _RideProblem, tab: ButcherTableau, rtols, target) -> list[dict]:
    """An embedded pair over the tolerances until the metric is within ``target``."""
    sys, T, X0, U = problem.model.system, problem.T, problem.X0, problem.U
    rows = []
    for rtol in rtols:
        atol = rtol * problem.scale

        def run(r: float = rtol, a: np.ndarray = atol):
            return forced_response(sys, T, U, X0, method=tab, rtol=r, atol=a)

        resp, seconds = peers.best_of(run, problem.repeats)
        value = _metric(resp, problem.model, problem.metric)
        row = problem.row("adaptive", tab.name, value, int(resp.nfev), seconds, resp.success,
                          rtol=rtol, atol=float(np.max(atol)))  # fmt: skip
        rows.append(row)
        if problem.reached(row, target):
            break
    return rows


def _solver_ladder(problem: _RideProblem, solver: str, rtols, target, budget) -> list[dict]:
    """A peer over the tolerances (``'control'`` once, at its defaults) until within ``target``."""
    sys, T, X0, U = problem.model.system, problem.T, problem.X0, problem.U
    f = peers.peer_derivative(sys, T, U)
    ladder = [peers.CONTROL_DEFAULTS[0]] if solver == "control" else list(rtols)
    rows = []
    run: Callable[[], tuple]
    for rtol in ladder:
        if solver == "control":
            atol = np.full(X0.size, peers.CONTROL_DEFAULTS[1])
            run = lambda: peers.control_run(sys, f, T, X0, budget)  # noqa: E731
        else:
            atol = rtol * problem.scale
            run = functools.partial(peers.ivp_run, solver, f, T, X0, rtol, atol, budget)
        (x, evaluations, _, _, _, ok), seconds = peers.best_of(run, problem.repeats)
        resp = problem.response(peers.outputs_of(sys, x, T, U))
        value = math.nan if resp is None else _metric(resp, problem.model, problem.metric)
        row = problem.row("solver", solver, value, evaluations, seconds, ok, rtol=rtol,
                          atol=float(np.max(atol)))  # fmt: skip
        rows.append(row)
        if problem.reached(row, target):
            break
    return rows


def ride_cost(
    model: VehicleModel,
    T,
    U,
    methods: Sequence[ButcherTableau],
    *,
    X0=None,
    h: float | None = None,
    solvers: Sequence[str] = (),
    rtols: Sequence[float] = peers.RTOLS,
    metric: str = RIDE_METRIC,
    target: float = RIDE_TARGET,
    halvings: int = RIDE_HALVINGS,
    repeats: int = 1,
    budget: int = peers.MAX_EVALUATIONS,
    progress: Callable[[str], None] | None = None,
) -> RideCost:
    """The cheapest setting of each integrator whose ride metric is within ``target`` %.

    Parameters
    ----------
    model : VehicleModel
        A linear vehicle with its road inputs (``model.system`` a
        `control.StateSpace`).
    T : array_like
        Uniform time grid [s].
    U : array_like
        The road samples on ``T``.
    methods : sequence of ButcherTableau
        Each over the steps h, h/2, ..., h/2**halvings; an embedded pair
        also over ``rtols`` with step-size control.
    X0 : array_like, optional
        Initial state; default at rest.
    h : float, optional
        The first step [s]; it must divide the spacing of ``T`` (default:
        the spacing).
    solvers : sequence of str
        Peers (`qc_control.studies.peers.SOLVERS`) over ``rtols``.
    rtols : sequence of float
        The tolerance ladder, loosest first (default 1e-3 ... 1e-10).
    metric : str
        A column of `qc_control.ride_metrics` (default `RIDE_METRIC`).
    target : float
        [%] > 0.
    halvings : int
        How often h is halved at most.
    repeats : int
        Each run's time is the best of this many.
    budget : int
        RHS evaluations after which a peer's run is stopped.

    Returns
    -------
    RideCost
    """
    problem, substeps, h = _ride_problem(model, T, U, X0, h, metric, repeats)
    if not (isinstance(target, (int, float)) and not isinstance(target, bool) and target > 0):
        raise ValueError(f"target must be a percentage > 0, got {target!r}")
    if isinstance(halvings, bool) or not isinstance(halvings, int) or not 0 <= halvings <= 12:
        raise ValueError(f"halvings must be an integer in 0..12, got {halvings!r}")
    rtols, names = peers.check_rtols(rtols), peers.check_solvers(solvers)
    rows: list[dict] = []
    for tab in methods:
        if progress:
            progress(f"{tab.name}: h = {h:g} s halved until {metric} is within {target:g} %")
        rows += _fixed_ladder(problem, tab, substeps, h, halvings, target)
        if tab.embedded:
            rows += _adaptive_ladder(problem, tab, rtols, target)
    for solver in names:
        if progress:
            progress(f"{solver}: rtol from {rtols[0]:g} until {metric} is within {target:g} %")
        rows += _solver_ladder(problem, solver, rtols, target, budget)
    runs = pd.DataFrame(rows, columns=[*_COLUMNS, "success"])
    return RideCost(runs, metric, float(target), problem.exact)


def _ride_problem(model, T, U, X0, h, metric, repeats) -> tuple[_RideProblem, int, float]:
    """The checked problem, the substeps per interval of ``T`` and the first step h."""
    sys = getattr(model, "system", None)
    if not isinstance(model, VehicleModel) or not isinstance(sys, control.StateSpace):
        raise TypeError(f"model must be a VehicleModel of a linear car, got {model!r}")
    T = np.asarray(T, dtype=float)
    U = np.asarray(U, dtype=float).reshape(sys.ninputs, -1)
    X0 = np.zeros(sys.nstates) if X0 is None else np.asarray(X0, dtype=float).reshape(-1)
    dt = float(T[1] - T[0]) if T.size > 1 else math.nan
    if T.ndim != 1 or T.size < 3 or not np.allclose(np.diff(T), dt, rtol=1e-9, atol=0):
        raise ValueError("T must be a uniform grid of at least 3 times")
    step = dt if h is None else h
    substeps = round(dt / step) if isinstance(step, (int, float)) and step > 0 else 0
    if substeps < 1 or abs(substeps * step - dt) > 1e-9 * dt:
        raise ValueError(f"h = {h!r} s must divide the grid spacing {dt!r} s of T")
    exact = exact_response(sys, T, X0, U)
    value = _metric(exact, model, metric)
    if not (math.isfinite(value) and value != 0):
        raise ValueError(f"the exact {metric} is {value!r}: no percentage error is defined")
    problem = _RideProblem(model, T, X0, U, metric, value, peers.state_scale(exact.states), repeats)
    return problem, substeps, dt / substeps
