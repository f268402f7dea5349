"""The report's answer, stated first: what to use, at which step, how sure.

`summary` writes the paragraphs that open a method comparison's report:
first any method run beyond its stability limit; then the errors of the run
as given; then the method that reaches the asked accuracy (1 mm in the body
displacement by default) for the fewest right-hand-side evaluations, at
which step, and the run that confirmed that cost (made by the study,
`qc_control.studies.confirm`: the summary only words it).
"""

from __future__ import annotations

import math

from ..numerics.methods import get_method
from ..studies import columns as col
from .document import fmt
from .figures import body_wheel_road

__all__ = ["summary"]

#: The accuracy the summary answers for [m], in the body displacement.
SUMMARY_TOLERANCE = 1e-3


def _limits(cmp) -> list[str]:
    t = cmp.table
    beyond = [(m, r[col.H_MAX]) for m, r in t.iterrows() if not r[col.STABLE]]
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
    column = col.max_error(body, "m")
    errors = cmp.table[column] if column in cmp.table else cmp.table.iloc[:, 0]
    listed = ", ".join(f"{m} {fmt(e)} m" for m, e in errors.items())
    return f"As run (h = {fmt(cmp.h)} s), the largest |{body} error| of each method: {listed}."


def _tableau(cmp, name: str):
    """The comparison's own tableau of that name (a custom one is in no catalogue)."""
    for tab in getattr(cmp, "methods", ()):
        if getattr(tab, "name", None) == name:
            return tab
    return get_method(name)


_HOW = {
    "interpolated": "interpolated between the refinements",
    "extrapolated": "extrapolated from its order",
}


def _check_of(cmp, method: str, tol: float):
    for check in cmp.cost_checks or ():
        if check.method == method and check.tolerance == tol:
            return check
    return None


def _cheapest(cmp, body: str, tol: float) -> list[str]:
    """The cheapest method for ``tol``, with the run that confirmed its cost
    (`qc_control.studies.confirm`), and any method tied with it (as the findings
    name them); this only words the comparison's numbers."""
    if tol not in cmp.cost.index:
        return []
    costs = cmp.cost.loc[tol].dropna().sort_values()
    if costs.empty:
        return [f"No method reaches {fmt(tol * 1e3)} mm in {body} at a step it can run."]
    tied = [m for m in costs.index[1:] if costs[m] == costs.iloc[0]]
    also = f" {' and '.join(tied)} {'needs' if len(tied) == 1 else 'need'} the same count."
    return [_answer(cmp, body, tol, costs) + (also if tied else "")]


def _answer(cmp, body: str, tol: float, costs) -> str:
    """The cheapest method's step and count for ``tol``, and how it was found."""
    best, cost = costs.index[0], float(costs.iloc[0])
    span = float(cmp.T[-1] - cmp.T[0])
    target = f"To reach {fmt(tol * 1e3)} mm in {body} for the fewest RHS evaluations: {best}"
    check = _check_of(cmp, best, tol)
    if check is None or check.verdict != "confirmed":
        h_est = span / math.ceil(cost / _tableau(cmp, best).stages)
        why = (
            "the exact reference needs a linear system"
            if check is None
            else "a run that long is not made"
        )
        kind = check.estimate_kind if check is not None else cmp.cost_kind.loc[tol, best]
        return (
            f"{target} at h ≈ {fmt(h_est)} s, an estimate of about {fmt(int(cost))} "
            f"evaluations ({_HOW.get(kind, kind)}). Not checked by a run: {why}."
        )
    h = span / check.steps
    stated = f"{target} at h = {fmt(h)} s, {fmt(int(cost))} evaluations"
    if check.runs == 1:
        return (
            f"{stated} ({_HOW.get(check.estimate_kind, check.estimate_kind)}); a run at that "
            f"step confirms it: its error is {fmt(check.error * 1e3)} mm."
        )
    return (
        f"{stated}, confirmed by a run: its error is {fmt(check.error * 1e3)} mm. The estimate "
        f"{_HOW.get(check.estimate_kind, check.estimate_kind)}, about "
        f"{fmt(int(check.estimate))} evaluations, missed it: a run there gives "
        f"{fmt(check.estimate_error * 1e3)} mm."
    )


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
