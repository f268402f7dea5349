"""The measures every path of a comparison shares: errors, orders, costs to reach.

The linear, nonlinear and sampled-data comparisons differ in their reference
and in how a method is run; what they measure of each run is here, once: the
error table, the convergence ladder (`convergence_points`), the observed
orders, the cost to reach each of `TOLERANCES`, coincident pairs, each
method's view of the modes and the ride metrics.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import control
import numpy as np
import pandas as pd

from ...models.modal import ModalAnalysis
from ...models.vehicle import VehicleModel
from ...numerics.methods import ButcherTableau
from ...numerics.sampled import linear_input
from ...numerics.stability import max_stable_step, numerical_modes
from ...ride.comfort import ride_metrics
from .. import columns as col
from .problem import (
    ROUNDING_FLOOR,
    TOLERANCES,
    ComparisonProblem,
)


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


def refined(T: np.ndarray, level: int) -> np.ndarray:
    return np.linspace(T[0], T[-1], (T.size - 1) * 2**level + 1)


def refined_input(T, U, level):
    """U on the refined grid: linear interpolation keeps the same input function."""
    if U is None:
        return None
    return linear_input(T, U).at(refined(T, level)).T


def _observed_order(hs, errors, floor: float = ROUNDING_FLOOR) -> float:
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
        (conv[col.METHOD] == method.name)
        & conv[col.STABLE]
        & np.isfinite(conv[col.ERROR])
        & (conv[col.ERROR] > ROUNDING_FLOOR)
    ].sort_values(col.NFEV)
    result = {}
    if rows.empty:
        return {tol: (math.nan, "unreached") for tol in TOLERANCES}
    log_n, log_e = np.log(rows[col.NFEV].to_numpy(float)), np.log(rows[col.ERROR].to_numpy())
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


def coincident(responses: dict) -> dict:
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


def padded_outputs(resp, n: int) -> np.ndarray:
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
            err = padded_outputs(resp, ref.shape[1]) - ref
            row = {}
            for i, label in enumerate(labels):
                unit = model.unit(label)
                row[col.max_error(label, unit)] = float(np.max(np.abs(err[i])))
                row[col.rms_error(label, unit)] = float(np.sqrt(np.mean(err[i] ** 2)))
        row[col.final_error(model.body_disp, model.unit(model.body_disp))] = float(
            abs(err[body, -1])
        )
        rows[name] = row
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = col.METHOD
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


class Refinement(NamedTuple):
    """A method's run on one refined grid, and what it is measured against there."""

    response: Any  # FixedStepResponse
    reference: np.ndarray  # the body displacement of the reference on the same grid [m]
    seconds: float  # wall time of one run [s]; NaN untimed


#: How a path runs a method on a refined grid: ``run(method, level, T, U)``.
RefinementRun = Callable[[ButcherTableau, int, np.ndarray, np.ndarray | None], Refinement]


def max_error(y: np.ndarray, reference: np.ndarray, samples: int) -> float:
    """Largest ``|y - reference|`` over ``samples`` samples; infinite for a run cut
    short by a divergence (fewer samples) or one that overflowed."""
    if y.size != samples:
        return math.inf
    # a run that overflowed is infinitely wrong, whatever its samples' arithmetic gives
    with np.errstate(invalid="ignore", over="ignore"):
        error = float(np.max(np.abs(y - reference)))
    return error if math.isfinite(error) else math.inf


def convergence_points(
    tab: ButcherTableau,
    T: np.ndarray,
    U: np.ndarray | None,
    h: float,
    levels: int,
    h_max: float,
    body: int,
    run: RefinementRun,
) -> tuple[list[ConvergencePoint], Any]:
    """One method's max body-displacement error at h, h/2, ..., h/2**levels, and its run at h.

    The linear and the nonlinear comparison differ only in ``run``: how the
    method is stepped and what reference it meets on each refined grid.
    """
    points, at_h = [], None
    for level in range(levels + 1):
        Tl, Ul = refined(T, level), refined_input(T, U, level)
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


def convergence_ladder(
    methods: Sequence[ButcherTableau],
    T: np.ndarray,
    U: np.ndarray | None,
    h: float,
    levels: int,
    eig: np.ndarray,
    body: int,
    run: RefinementRun,
    progress: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Every method's `convergence_points` (long form), each limited by its stable
    step on the eigenvalues ``eig``: the ladder of the linear and sampled paths."""
    points: list[ConvergencePoint] = []
    for tab in methods:
        if progress:
            progress(
                f"{tab.name}: h = {h:g} s, then {levels} halvings of h for the convergence study"
            )
        mine, _ = convergence_points(tab, T, U, h, levels, max_stable_step(tab, eig), body, run)
        points += mine
    return pd.DataFrame(points)


def observed_orders(
    convergence: pd.DataFrame, levels: int = 2, floor: float = ROUNDING_FLOOR
) -> pd.Series:
    """Least-squares slope of log error against log h over the first ``levels + 1``
    steps, per method; NaN when a step is unstable or errors are below ``floor``
    (rounding, or within reach of a reference's own error)."""
    out = {}
    for name, rows in convergence.groupby(col.METHOD, sort=False):
        mine = rows[rows[col.LEVEL] <= levels]
        out[name] = (
            _observed_order(mine[col.H], mine[col.ERROR], floor)
            if mine[col.STABLE].all()
            else math.nan
        )
    return pd.Series(out, name=col.OBSERVED_ORDER, dtype=float)


def cost_to_reach(
    convergence: pd.DataFrame, methods: Sequence[ButcherTableau], span: float, h_max: dict
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """RHS evaluations to reach each of `TOLERANCES`, and how each was found.

    Returns ``(cost, kind)``, indexed by tolerance [m], a column per method.
    """
    reach = {tab.name: _cost_to_reach(convergence, tab, span, h_max[tab.name]) for tab in methods}
    cost = pd.DataFrame({m: {tol: v[0] for tol, v in r.items()} for m, r in reach.items()})
    kind = pd.DataFrame({m: {tol: v[1] for tol, v in r.items()} for m, r in reach.items()})
    cost.index.name = kind.index.name = col.TOLERANCE
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
            col.H_MAX: h_max,
            col.LIMITED_BY: _limiting_mode(tab, modes),
            col.STABLE: bool(h <= h_max),
        }
        for mode_name, mrow in nm.iterrows():
            row[col.freq_error(str(mode_name))] = mrow["freq error [%]"]
            row[col.zeta_error(str(mode_name))] = mrow["zeta error"]
        rows[tab.name] = row
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = col.METHOD
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


def on_road(problem: ComparisonProblem) -> bool:
    """Whether the input is the vehicle's road, one height per wheel: ride metrics apply."""
    roads = problem.model.road_inputs()
    return problem.U is not None and bool(roads) and list(problem.system.input_labels) == roads
