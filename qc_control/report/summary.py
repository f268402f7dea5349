"""The report's answer, stated first: what to use, at which step, how sure.

`summary` writes the paragraphs that open a method comparison's report:
first any method run beyond its stability limit; then the errors of the run
as given; then the method that reaches the asked accuracy (1 mm in the body
displacement by default) for the fewest right-hand-side evaluations, at
which step, and one run at that step that checks the estimate.
"""

from __future__ import annotations

import math
import warnings

import control
import numpy as np

from ..numerics.methods import get_method
from ..numerics.reference import exact_response
from ..responses.timeresp import forced_response, initial_response
from .document import fmt
from .figures import body_wheel_road
from .plotting import output_signal

__all__ = ["summary", "checked_step"]

#: The accuracy the summary answers for [m], in the body displacement.
SUMMARY_TOLERANCE = 1e-3
#: Runs the check may take: the estimate, then a step predicted from the
#: measured error and the order, confirmed; then that step shortened again.
_CHECK_RUNS = 3


def _limits(cmp) -> list[str]:
    t = cmp.table
    beyond = [(m, r["h_max [s]"]) for m, r in t.iterrows() if not r["stable"]]
    if not beyond:
        return []
    named = ", ".join(
        f"{m} (h_max = {fmt(h)} s)" if h > 0 else f"{m} (no stable step)" for m, h in beyond
    )
    return [
        f"Warning: at h = {fmt(cmp.h)} s {named} "
        f"{'is' if len(beyond) == 1 else 'are'} beyond the stability limit: the response "
        "grows instead of decaying, its errors below measure that growth and mean nothing, "
        "and its curves are cut where they diverge. Give a smaller step to compare it."
    ]


def _as_run(cmp, body: str) -> str:
    column = f"max |{body} err| [m]"
    errors = cmp.table[column] if column in cmp.table else cmp.table.iloc[:, 0]
    listed = ", ".join(f"{m} {fmt(e)} m" for m, e in errors.items())
    return f"As run (h = {fmt(cmp.h)} s), the largest |{body} error| of each method: {listed}."


def _input_on(cmp, T: np.ndarray) -> np.ndarray:
    """The comparison's input, linearly interpolated between its samples, on ``T``."""
    U = np.atleast_2d(np.asarray(cmp.U, dtype=float))
    return np.array([np.interp(T, cmp.T, row) for row in U])


#: The largest grid the exact reference of a check is solved on, under an
#: input: it must hold both the comparison's grid and the check's.
_MAX_COMMON_STEPS = 400_000


def _carried(cmp, steps: int) -> int:
    """``steps``, or the next count whose grid and the comparison's fit in one
    uniform grid of at most `_MAX_COMMON_STEPS` steps (only under an input)."""
    if cmp.U is None:
        return steps
    fine = cmp.T.size - 1
    for n in range(steps, steps + fine + 1):
        if math.lcm(fine, n) <= _MAX_COMMON_STEPS:
            return n
    return fine  # the comparison's own grid always fits


def _error_at(cmp, method, steps: int, body: str) -> float:
    """Largest |body error| of ``method`` in ``steps`` steps against the exact response.

    The method sees the input only at its own steps, as a run at that step
    would; the exact response (python-control's) is the one to the whole
    input, solved on the union of both grids so that a road shorter than
    the step is not lost from the reference too.
    """
    T = np.linspace(cmp.T[0], cmp.T[-1], steps + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a check step past a limit shows as a large error
        if cmp.U is None:
            run = initial_response(cmp.system, T, cmp.X0, method=method)
            exact = output_signal(exact_response(cmp.system, T, cmp.X0), body)
        else:
            run = forced_response(cmp.system, T, _input_on(cmp, T), cmp.X0, method=method)
            # a uniform grid holding both (python-control's exact solver needs one)
            fine_steps = cmp.T.size - 1
            common = math.lcm(fine_steps, steps)
            union = np.linspace(cmp.T[0], cmp.T[-1], common + 1)
            fine = exact_response(cmp.system, union, cmp.X0, _input_on(cmp, union))
            exact = output_signal(fine, body)[:: common // steps]
    with np.errstate(invalid="ignore", over="ignore"):
        return float(np.max(np.abs(output_signal(run, body) - exact)))


def _tableau(cmp, name: str):
    """The comparison's own tableau of that name (a custom one is in no catalogue)."""
    for tab in getattr(cmp, "methods", ()):
        if getattr(tab, "name", None) == name:
            return tab
    return get_method(name)


def checked_step(cmp, method: str, cost: float, tol: float = SUMMARY_TOLERANCE):
    """Check an estimated cost by running ``method`` at the step it implies.

    Returns ``(steps, error, runs)``: the steps of the last run over the
    span, its largest body-displacement error [m], and how many runs were
    needed. When the estimate misses ``tol``, the step is shortened by the
    error model ``e = C h^p`` (2 % margin) and run again, up to
    `_CHECK_RUNS` runs. ``(None, nan, 0)`` on a system python-control cannot
    solve exactly (a nonlinear one).
    """
    if not isinstance(cmp.system, control.StateSpace):
        return None, math.nan, 0
    tab = _tableau(cmp, method)
    body = body_wheel_road(cmp)[0]
    steps = _carried(cmp, max(2, math.ceil(cost / tab.stages)))
    for run in range(1, _CHECK_RUNS + 1):
        error = _error_at(cmp, tab, steps, body)
        if error <= tol or not math.isfinite(error) or run == _CHECK_RUNS:
            return steps, error, run
        steps = _carried(cmp, math.ceil(steps * (error / tol) ** (1 / tab.order) * 1.02))
    raise AssertionError("unreachable")  # pragma: no cover


def _cheapest(cmp, body: str, tol: float) -> list[str]:
    if tol not in cmp.cost.index:
        return []
    costs = cmp.cost.loc[tol].dropna().sort_values()
    if costs.empty:
        return [f"No method reaches {fmt(tol * 1e3)} mm in {body} at a step it can run."]
    best, cost = costs.index[0], float(costs.iloc[0])
    span = float(cmp.T[-1] - cmp.T[0])
    tab = _tableau(cmp, best)
    h_est = span / math.ceil(cost / tab.stages)
    kind = cmp.cost_kind.loc[tol, best]
    how = (
        "interpolated between the refinements"
        if kind == "interpolated"
        else f"{kind} from its order"
    )
    text = (
        f"To reach {fmt(tol * 1e3)} mm in {body} for the fewest RHS evaluations: {best} at "
        f"h ≈ {fmt(h_est)} s, about {fmt(int(cost))} evaluations ({how})."
    )
    steps, error, runs = checked_step(cmp, best, cost, tol)
    if steps is None:
        return [text + " Not checked by a run: the exact reference needs a linear system."]
    h = span / steps
    if runs == 1 and error <= tol:
        verdict = f"One run at that step confirms it: its error is {fmt(error * 1e3)} mm."
    elif error <= tol:
        verdict = (
            f"One run at that step missed it (the estimate is optimistic); at h = {fmt(h)} s "
            f"({fmt(steps * tab.stages)} evaluations) a run gives {fmt(error * 1e3)} mm, "
            f"within {fmt(tol * 1e3)} mm."
        )
    else:
        verdict = (
            f"Not confirmed: a run at h = {fmt(h)} s still gives {fmt(error * 1e3)} mm; "
            "take a smaller step."
        )
    return [text + " " + verdict]


def summary(cmp, tol: float = SUMMARY_TOLERANCE) -> list[str]:
    """The report's opening paragraphs: warnings, the run as given, the answer.

    Parameters
    ----------
    cmp : MethodComparison
    tol : float, default 1e-3
        The accuracy asked [m] in the body displacement; one of the
        comparison's `TOLERANCES`.

    Returns
    -------
    list of str
    """
    body = body_wheel_road(cmp)[0]
    return [*_limits(cmp), _as_run(cmp, body), *_cheapest(cmp, body, tol)]
