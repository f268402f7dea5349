"""Costs to reach an accuracy, confirmed by running the method at the count.

`qc_control.studies.compare.cost_to_reach` estimates the right-hand-side
evaluations a method needs for a body-displacement error of ``tol``: by
log-log interpolation between two refinements, or by the error model
``e = C h^p`` beyond them. An estimate is only a model: past the
refinements, or where a road step off the grid lowers the order a run
sees, it can be optimistic (RK4 "about 492" for 1 mm on the seed car runs
to 1.31 mm). A report quotes a cost as enough, so each estimate is run:

1. the method at the estimate's step count ``n`` over the span, the input
   sampled at its own steps as a user's run at that step would see it,
   against the exact response (`qc_control.numerics.reference`, on a grid
   holding the comparison's and the check's samples, so that the input is
   the same function for both);
2. if it misses, ``n`` grows by the error model with the order the last two
   runs show (never above the method's order, at least 5 % a run), up to
   `CONFIRM_RUNS` runs.

A count that reaches ``tol`` is 'confirmed' and replaces the estimate; one
that does not within the runs is 'missed' (no cost is quoted); a check
longer than `CONFIRM_MAX_STEPS` steps is not run and the estimate stays,
marked as such.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import control
import numpy as np
import pandas as pd

from ..numerics.methods import ButcherTableau
from ..numerics.reference import exact_output_samples, exact_response
from ..responses.timeresp import forced_response, initial_response
from . import columns as col

__all__ = ["CostCheck", "confirm_cost", "confirmed_costs", "CONFIRM_RUNS", "CONFIRM_MAX_STEPS"]

#: Runs a check may make before it calls the target missed (CONFIRM_RUNS); the
#: longest check run, in steps over the span, which is also the largest grid the
#: exact reference of a check under an input is solved on (CONFIRM_MAX_STEPS): a
#: cost beyond it stays an estimate; the least a missed run's step count grows by,
#: whatever the error model says.
CONFIRM_RUNS, CONFIRM_MAX_STEPS, _LEAST_GROWTH = 6, 200_000, 1.05


@dataclass(frozen=True)
class CostCheck:
    """One estimate of a cost, and the runs that checked it against the target.

    Attributes
    ----------
    method : str
        The method's name.
    tolerance : float
        The target [m]: the largest absolute body-displacement error.
    estimate : float
        The estimated RHS evaluations (NaN when unreached).
    estimate_kind : str
        'interpolated', 'extrapolated' or 'unreached'.
    steps : int or None
        The steps of the last run made (None: no run).
    error : float
        Its largest absolute body-displacement error [m] (NaN: no run).
    runs : int
    estimate_error : float
        The same error [m] of the first run, at the estimate (NaN: no run).
    verdict : str
        'confirmed' (the last run reaches the target), 'missed' (no run
        within `CONFIRM_RUNS` did), 'too long' (a run would exceed
        `CONFIRM_MAX_STEPS` steps) or 'unreached' (no estimate to run).
    evaluations : float
        What the report quotes: the confirmed run's evaluations; the
        estimate when too long to run; NaN when missed or unreached.
    """

    method: str
    tolerance: float
    estimate: float
    estimate_kind: str
    steps: int | None
    error: float
    runs: int
    estimate_error: float
    verdict: str
    evaluations: float


def _input_on(T_data: np.ndarray, U: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The input (linear between its samples at ``T_data``) on ``T``."""
    return np.array([np.interp(T, T_data, row) for row in np.atleast_2d(U)])


def _carried(fine: int | None, steps: int) -> int:
    """``steps``, or the next count whose grid and the comparison's ``fine`` steps
    fit in one uniform grid of at most `CONFIRM_MAX_STEPS` (only under an input).

    None fits beyond that many steps: then the next multiple of ``fine`` (its
    grid holds the comparison's), which the caller finds too long to run. (Falling
    back to ``fine`` itself ran the comparison's own grid again and again and
    called a target out of reach 'missed', e.g. Euler to 1e-6 m on a road step.)
    """
    if fine is None:
        return steps
    for n in range(steps, steps + fine + 1):
        if math.lcm(fine, n) <= CONFIRM_MAX_STEPS:
            return n
    return math.ceil(steps / fine) * fine


def _error_at(sys, T_data, X0, U, tab: ButcherTableau, steps: int, body: int) -> float:
    """The largest absolute body-displacement error [m] of ``tab`` in ``steps``
    steps over ``T_data``'s span."""
    T = np.linspace(T_data[0], T_data[-1], steps + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a run past a limit shows as a large error
        if U is None:
            run = initial_response(sys, T, X0, method=tab)
            exact = np.asarray(exact_response(sys, T, X0).outputs)[body]
        else:
            run = forced_response(sys, T, _input_on(T_data, U, T), X0, method=tab)
            common = math.lcm(T_data.size - 1, steps)
            union = np.linspace(T_data[0], T_data[-1], common + 1)
            fine = exact_output_samples(sys, union, X0, _input_on(T_data, U, union))
            exact = fine[body][:: common // steps]
    y = np.asarray(run.outputs)[body]
    if y.size < exact.size:  # the run diverged and was cut where it did
        return math.inf
    with np.errstate(invalid="ignore", over="ignore"):
        error = float(np.max(np.abs(y - exact)))
    return error if math.isfinite(error) else math.inf


def confirm_cost(
    sys, T, X0, U, tab: ButcherTableau, estimate: float, kind: str, tol: float, body: int
) -> CostCheck:
    """Run ``tab`` at the estimated cost and on until it reaches ``tol`` (module docstring).

    Parameters
    ----------
    sys : control.StateSpace
    T, X0, U : the comparison's grid, initial state and input samples (or None)
    tab : ButcherTableau
    estimate : float
        Estimated RHS evaluations (NaN: nothing to check).
    kind : str
        How the estimate was found.
    tol : float
        The target [m].
    body : int
        The row of the body displacement among ``sys``'s outputs.
    """
    T = np.asarray(T, dtype=float)
    if not math.isfinite(estimate):
        return CostCheck(
            tab.name, tol, estimate, kind, None, math.nan, 0, math.nan, "unreached", math.nan
        )
    fine = None if U is None else T.size - 1
    steps = _carried(fine, max(2, math.ceil(estimate / tab.stages)))
    tried: list[tuple[int, float]] = []
    for run in range(1, CONFIRM_RUNS + 1):
        first = tried[0][1] if tried else math.nan
        if steps > CONFIRM_MAX_STEPS:
            last_steps, last_error = tried[-1] if tried else (None, math.nan)
            return CostCheck(
                tab.name, tol, estimate, kind, last_steps, last_error, run - 1, first,
                "too long", estimate,
            )  # fmt: skip
        error = _error_at(sys, T, X0, U, tab, steps, body)
        tried.append((steps, error))
        if error <= tol:
            evaluations = steps * tab.stages
            first = tried[0][1]
            return CostCheck(
                tab.name, tol, estimate, kind, steps, error, run, first, "confirmed", evaluations
            )
        steps = _carried(fine, math.ceil(steps * _growth(tried, tol, tab.order)))
    (last_steps, last_error), first = tried[-1], tried[0][1]
    return CostCheck(
        tab.name, tol, estimate, kind, last_steps, last_error, CONFIRM_RUNS, first, "missed",
        math.nan,
    )  # fmt: skip


def _growth(tried: list[tuple[int, float]], tol: float, order: int) -> float:
    """How much to multiply the steps by after a miss: ``(e/tol)^(1/p)`` with
    ``p`` the order the last two runs show (at most the method's), 2 % over."""
    steps, error = tried[-1]
    if not math.isfinite(error):
        return 2.0
    p = float(order)
    if len(tried) > 1:
        (n0, e0), (n1, e1) = tried[-2], tried[-1]
        if e0 > e1 > 0 and n1 > n0:
            p = min(p, max(0.5, math.log(e0 / e1) / math.log(n1 / n0)))
    return max(_LEAST_GROWTH, (error / tol) ** (1.0 / p) * 1.02)


def _no_dearer_than_the_runs(check: CostCheck, runs: pd.DataFrame | None) -> CostCheck:
    """``check``, or the fewest-evaluation run of the comparison's own refinements
    (``runs``: the convergence table) that reaches its target, where that is cheaper.

    Under a sampled road, a check at a step coarser than the comparison's sees the
    road resampled at that step and can miss, then climb to a count far above a
    refinement that already reached the target (RK4 to 1e-6 m on a class C road:
    130,000 evaluations quoted where its 8,000 reached 1.4e-7 m). A refinement is
    a run at that count against the exact response: it confirms as well.
    """
    if runs is None:
        return check
    reached = runs[
        (runs[col.METHOD] == check.method) & (runs[col.ERROR] <= check.tolerance)
    ].sort_values(col.NFEV)
    if reached.empty:
        return check
    best = reached.iloc[0]
    evaluations = float(best[col.NFEV])
    if math.isfinite(check.evaluations) and check.evaluations <= evaluations:
        return check
    return dataclasses.replace(
        check,
        steps=int(best[col.STEPS]),
        error=float(best[col.ERROR]),
        verdict="confirmed",
        evaluations=evaluations,
    )


def confirmed_costs(
    sys, T, X0, U, methods, cost: pd.DataFrame, kind: pd.DataFrame, body: str, runs=None
) -> tuple[pd.DataFrame, pd.DataFrame, list[CostCheck]]:
    """Each estimate of ``cost`` checked (`confirm_cost`); returns what a report
    quotes: ``(cost, kind, checks)``, kind being each check's verdict for a
    confirmed or missed one and the estimate's kind otherwise ('extrapolated,
    too long to run' reads 'extrapolated'). ``runs``, the comparison's
    convergence table: no quoted cost exceeds a refinement that reached it."""
    if not isinstance(sys, control.StateSpace):
        raise TypeError("costs are confirmed against the exact response of a linear system")
    row = list(sys.output_labels).index(body)
    checks = [
        _no_dearer_than_the_runs(
            confirm_cost(sys, T, X0, U, tab, float(cost.loc[tol, tab.name]),
                         str(kind.loc[tol, tab.name]), float(tol), row),
            runs,
        )
        for tab in methods
        for tol in cost.index
    ]  # fmt: skip
    new_cost, new_kind = cost.astype(float).copy(), kind.copy()
    for c in checks:
        new_cost.loc[c.tolerance, c.method] = c.evaluations
        if c.verdict in ("confirmed", "missed"):
            new_kind.loc[c.tolerance, c.method] = c.verdict
    return new_cost, new_kind, checks
