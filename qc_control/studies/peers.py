"""The solvers people use, as peers of the fixed-step methods: a work–precision study.

python-control simulates every nonlinear system with ``scipy.integrate.solve_ivp``
(RK45 by default); engineers reach for LSODA, Radau or BDF when a model is
stiff. `solver_runs` runs each of them over a ladder of tolerances on the
same problem as the fixed-step methods (the same input function, linear
between samples, python-control's assumption) and measures what each run
costs and how far it lands from the reference:

- **error**: the largest body-displacement difference over the output grid
  from the comparison's reference (python-control's exact response for a
  linear car; the tight DOP853 solve for a nonlinear one), never from
  another run of the solver itself;
- **evaluations**: right-hand-side evaluations, counted as scipy counts them
  (``nfev``), plus ``n`` per Jacobian that Radau and BDF build by finite
  differences outside ``nfev`` (``njev · n``); LSODA's finite differences
  are already inside its ``nfev``. The count is taken at the right-hand
  side itself, so it also holds the few columns scipy's ``num_jac``
  evaluates again with a larger increment (a Jacobian can cost a little
  more than ``n``); it is never below ``nfev + njev · n``, which is checked;
- **wall time**: the median over ``repeats`` interleaved rounds, every run of
  the study timed once per round in turn (`qc_control.studies.timing`, the
  one timing method of the studies and reports), with the rounds' lowest and
  highest beside it (``time_low``, ``time_high``) and the CPU time
  (``cpu_time``), the columns of the comparison's convergence study.

``"control"`` is ``control.input_output_response`` at its defaults (RK45,
rtol 1e-3, atol 1e-6), the call a python-control user makes, run once. An
embedded qc tableau (``tab.embedded``) runs over the same tolerances through
``qc.forced_response(..., method=tab, rtol=..., atol=...)``.
"""

from __future__ import annotations

import functools
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import control
import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from .. import compat
from ..numerics.lti import is_nonlinear_system
from ..numerics.methods import ButcherTableau
from ..numerics.sampled import linear_input
from ..responses.timeresp import forced_response, initial_response
from .timing import Timing, interleaved_times

__all__ = [
    "SOLVERS",
    "RTOLS",
    "PEER_TOLERANCE",
    "WorkPrecision",
    "solver_runs",
    "adaptive_runs",
    "work_precision",
    "cheapest",
    "check_solvers",
    "state_scale",
]

#: The peers: scipy's solve_ivp methods and python-control's default call.
SOLVERS = ("RK45", "DOP853", "LSODA", "Radau", "BDF", "control")
#: The tolerance ladder of the peers and of the adaptive qc pairs.
RTOLS = tuple(10.0**-k for k in range(3, 11))
#: The accuracy [m] at which the report names the cheapest run and python-control's default.
PEER_TOLERANCE = 1e-6
#: solve_ivp methods whose finite-difference Jacobian is evaluated outside ``nfev``.
_JACOBIAN_APART = ("Radau", "BDF")
#: python-control's defaults for input_output_response: solve_ivp RK45 at scipy's defaults.
CONTROL_DEFAULTS = (1e-3, 1e-6)
#: The evaluations one run may spend before it is stopped and recorded as unfinished:
#: RK45 on the stiff car needs 1.4e5 per 10 s at rtol 1e-6, bounded by stability
#: not accuracy, so a 60 s road at any rtol is ~1e6; a run far past that is stalled.
MAX_EVALUATIONS = 5_000_000


class _BudgetSpent(Exception):
    """Raised inside a solve when its evaluation budget is spent."""


def check_solvers(solvers) -> tuple[str, ...]:
    """The peers by name (case as in `SOLVERS`), each once; ValueError names a bad one."""
    if solvers is None:
        return ()
    if isinstance(solvers, str):
        solvers = [s.strip() for s in solvers.split(",") if s.strip()]
    if not isinstance(solvers, (list, tuple)):
        raise TypeError(f"solvers must be a sequence of solver names, got {solvers!r}")
    known = {s.lower(): s for s in SOLVERS}
    names = []
    for s in solvers:
        if not isinstance(s, str) or s.lower() not in known:
            raise ValueError(f"unknown solver {s!r}; expected one of {', '.join(SOLVERS)}")
        names.append(known[s.lower()])
    if len(set(names)) != len(names):
        raise ValueError(f"solvers must be distinct, got {list(solvers)!r}")
    return tuple(names)


def check_rtols(rtols) -> tuple[float, ...]:
    """The tolerance ladder as floats in ``[1e-14, 1)``; ValueError names a bad one."""
    values = tuple(rtols)
    ok = values and all(
        isinstance(r, (int, float)) and not isinstance(r, bool) and 1e-14 <= r < 1 for r in values
    )
    if not ok:
        raise ValueError(f"rtols must be tolerances in [1e-14, 1), at least one, got {rtols!r}")
    return tuple(float(r) for r in values)


def peer_derivative(sys, T, U) -> Callable[[float, np.ndarray], np.ndarray]:
    """The state derivative ``f(t, x)`` on the comparison's input, linear between samples."""
    ninputs = sys.ninputs
    u_of_t = linear_input(T, U) if U is not None else (lambda t: np.zeros(ninputs))
    if not is_nonlinear_system(sys):
        A, B = np.asarray(sys.A, dtype=float), np.asarray(sys.B, dtype=float)
        if U is None or ninputs == 0:
            return lambda t, x: A @ x
        if ninputs == 1:  # one road: u(t) a float, the same products to the bit, cheaper
            u1, b = linear_input(T, U).scalar(), B[:, 0].copy()
            return lambda t, x: A @ x + u1(t) * b
        return lambda t, x: A @ x + B @ u_of_t(t)
    compat.update_params(sys, None)
    f = compat.state_derivative(sys)
    return lambda t, x: f(t, x, u_of_t(t))


class _Counted:
    """``f(t, x)`` that counts its calls and stops the solve beyond a budget."""

    def __init__(self, f, budget: int):
        self.f, self.budget, self.calls = f, budget, 0

    def __call__(self, t, x):
        self.calls += 1
        if self.calls > self.budget:
            raise _BudgetSpent()
        return self.f(t, x)


def state_scale(states) -> np.ndarray:
    """Each state's scale, ``max_t |x_i(t)|`` over a reference's ``states (n, N)``, for
    ``atol = rtol · scale``; a state that never moves still needs an atol > 0: the
    largest state's scale x 1e-6."""
    scale = np.max(np.abs(np.asarray(states, dtype=float)), axis=1)
    return np.maximum(scale, 1e-6 * max(float(scale.max()), 1e-12))


def _atol(rtol: float, scale: np.ndarray) -> np.ndarray:
    """``atol = rtol · max|x_i|`` per state, the states' scale read off the reference
    (so a tolerance means the same relative accuracy for a state in m and one in m/s)."""
    return rtol * scale


def ivp_run(solver, f, T, x0, rtol, atol, budget):
    """One solve_ivp run: (states on T, evaluations, nfev, njev, message, ok)."""
    counted = _Counted(f, budget)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy's rtol floor, LSODA's excess-work notes
            sol = solve_ivp(
                counted, (T[0], T[-1]), x0, method=solver, t_eval=T, rtol=rtol, atol=atol
            )
    except _BudgetSpent:
        return None, counted.calls, counted.calls, 0, f"stopped after {budget:,} evaluations", False
    n = x0.size
    njev = int(getattr(sol, "njev", 0))
    scipy_count = int(sol.nfev) + (njev * n if solver in _JACOBIAN_APART else 0)
    if counted.calls < scipy_count:  # scipy's counts, and ours, must agree
        raise RuntimeError(
            f"{solver}: nfev {sol.nfev} + njev·n {njev * n} > {counted.calls} calls counted"
        )
    x = sol.y if sol.success and sol.y.shape[1] == T.size else None
    return x, counted.calls, int(sol.nfev), njev, sol.message, bool(sol.success)


def control_run(sys, f, T, x0, budget):
    """``control.input_output_response`` at its defaults on the same right-hand side."""
    counted = _Counted(f, budget)
    n = x0.size
    plant = control.nlsys(
        lambda t, x, u, params: counted(t, x),
        None,
        inputs=0,
        states=n,
        name=f"{sys.name} (counted)",
    )
    try:
        resp = control.input_output_response(plant, T, 0.0, x0)
    except _BudgetSpent:
        return None, counted.calls, counted.calls, 0, f"stopped after {budget:,} evaluations", False
    x = np.asarray(resp.states).reshape(n, -1)
    return x, counted.calls, counted.calls, 0, "control.input_output_response defaults", True


def outputs_of(sys, x: np.ndarray | None, T, U) -> np.ndarray | None:
    """The outputs ``(noutputs, N)`` along the states ``x (n, N)``: a linear car's ``C x + D u``."""
    if x is None:
        return None
    u = np.zeros((sys.ninputs, T.size)) if U is None else U
    if not is_nonlinear_system(sys):
        return np.asarray(sys.C, dtype=float) @ x + np.asarray(sys.D, dtype=float) @ u
    g = compat.output_function(sys)
    return np.column_stack([g(t, x[:, k], u[:, k]) for k, t in enumerate(T)])


def _error(y: np.ndarray | None, reference: np.ndarray) -> float:
    if y is None:
        return math.inf
    with np.errstate(invalid="ignore", over="ignore"):
        e = float(np.max(np.abs(y - reference)))
    return e if math.isfinite(e) else math.inf


@dataclass(frozen=True)
class _Problem:
    """What every peer solves: the system, its grid, start and input, and the reference."""

    sys: Any
    T: np.ndarray
    X0: np.ndarray
    U: np.ndarray | None
    body: int  # row of the body displacement among the outputs
    reference: np.ndarray  # the body displacement of the reference on T [m]
    scale: np.ndarray  # max |x_i| of the reference per state, for atol


def timed_in_rounds(
    runs: dict, repeats: int, progress: Callable[[str], None] | None = None
) -> tuple[dict, dict[Any, Timing]]:
    """Each run's result and its `Timing` over ``repeats`` interleaved rounds
    (`interleaved_times`: every run once per round, in turns, so a drift of the
    machine's load reaches all alike). The timed calls give the results (no
    extra untimed call: a peer's run can take seconds); ``progress`` hears of
    each run's first call, keyed by its key's words."""
    results: dict = {}

    def keeping(key, run):
        def call():
            if progress and key not in results:
                progress(key if isinstance(key, str) else ": ".join(map(str, key)))
            results[key] = run()

        return call

    timings = interleaved_times(
        {key: keeping(key, run) for key, run in runs.items()}, max(repeats, 1), warmup=False
    )
    return results, timings


def _time_columns(timing: Timing) -> dict:
    """The time columns, named as the comparison's convergence study names them."""
    return {
        "time": timing.wall,
        "time_low": timing.low,
        "time_high": timing.high,
        "cpu_time": timing.cpu,
    }


def best_of(run: Callable[[], Any], repeats: int) -> tuple[Any, float]:
    """The run's result and its best wall time [s] over ``repeats`` runs."""
    best, result = math.inf, None
    for _ in range(max(repeats, 1)):
        start = time.perf_counter()
        result = run()
        best = min(best, time.perf_counter() - start)
    return result, best


def solver_runs(
    problem: _Problem,
    solvers: Sequence[str] = SOLVERS,
    rtols: Sequence[float] = RTOLS,
    *,
    repeats: int = 1,
    budget: int = MAX_EVALUATIONS,
    progress: Callable[[str], None] | None = None,
) -> tuple[pd.DataFrame, dict]:
    """Each peer over the tolerance ladder (``control`` once, at its defaults).

    Returns a long frame: kind (``'solver'``), name, rtol, atol (the largest
    of the per-state values), h (NaN), error [m], evaluations, nfev, njev,
    time [s], success, message, default (python-control's default call);
    and per peer the outputs ``(noutputs, N)`` of its loosest run (None
    where it did not finish).
    """
    f = peer_derivative(problem.sys, problem.T, problem.U)
    runs: dict[tuple[str, str], Callable[[], tuple]] = {}
    atols: dict[tuple[str, str], np.ndarray] = {}
    for solver in check_solvers(solvers):
        ladder = [CONTROL_DEFAULTS[0]] if solver == "control" else list(check_rtols(rtols))
        for rtol in ladder:
            key = (solver, f"rtol {rtol!r}")
            if solver == "control":
                atols[key] = np.full(problem.X0.size, CONTROL_DEFAULTS[1])
                runs[key] = functools.partial(
                    control_run, problem.sys, f, problem.T, problem.X0, budget
                )
            else:
                atols[key] = _atol(rtol, problem.scale)
                runs[key] = functools.partial(
                    ivp_run, solver, f, problem.T, problem.X0, rtol, atols[key], budget
                )
    results, timings = timed_in_rounds(runs, repeats, progress)
    rows: list[dict] = []
    loosest: dict[str, np.ndarray | None] = {}
    for key in runs:
        solver, rtol = key[0], float(key[1].split()[1])  # the rtol's repr, exactly
        x, evaluations, nfev, njev, message, ok = results[key]
        y = outputs_of(problem.sys, x, problem.T, problem.U)
        loosest.setdefault(solver, y)
        rows.append(
            {
                "kind": "solver",
                "name": solver,
                "rtol": CONTROL_DEFAULTS[0] if solver == "control" else rtol,
                "atol": float(np.max(atols[key])),
                "h": math.nan,
                "error": _error(None if y is None else y[problem.body], problem.reference),
                "evaluations": evaluations,
                "nfev": nfev,
                "njev": njev,
                **_time_columns(timings[key]),
                "success": ok,
                "message": str(message),
                "default": solver == "control",
            }
        )
    return pd.DataFrame(rows), loosest


def adaptive_runs(
    problem: _Problem,
    methods: Sequence[ButcherTableau],
    rtols: Sequence[float] = RTOLS,
    *,
    repeats: int = 1,
    progress: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Each embedded qc tableau over the tolerance ladder, with step-size control.

    Runs ``qc.forced_response`` (``initial_response`` without an input) with
    ``method=tab, rtol=rtol, atol=atol``; the response's ``nfev`` is its cost.
    Methods without an error estimator (``tab.embedded`` false) are left to
    the fixed-step ladder.
    """
    sys, T, X0, U = problem.sys, problem.T, problem.X0, problem.U
    runs, atols = {}, {}
    for tab in methods:
        if not getattr(tab, "embedded", False):
            continue
        for rtol in check_rtols(rtols):
            key = (tab.name, f"rtol {rtol!r} (step-size control)")
            atols[key] = atol = _atol(rtol, problem.scale)

            def run(tab=tab, rtol=rtol, atol=atol):
                if U is None:
                    return initial_response(sys, T, X0, method=tab, rtol=rtol, atol=atol)
                return forced_response(sys, T, U, X0, method=tab, rtol=rtol, atol=atol)

            runs[key] = run
    results, timings = timed_in_rounds(runs, repeats, progress)
    rows = []
    for key, resp in results.items():
        y = np.asarray(resp.outputs).reshape(sys.noutputs, -1)[problem.body]
        rows.append(
            {
                "kind": "adaptive",
                "name": key[0],
                "rtol": float(key[1].split()[1]),  # the rtol's repr, exactly
                "atol": float(np.max(atols[key])),
                "h": math.nan,
                "error": _error(y if y.size == T.size else None, problem.reference),
                "evaluations": int(resp.nfev),
                "nfev": int(resp.nfev),
                "njev": 0,
                **_time_columns(timings[key]),
                "success": bool(getattr(resp, "success", True)),
                "message": f"{getattr(resp, 'n_accepted', '?')} steps accepted, "
                f"{getattr(resp, 'n_rejected', '?')} rejected",
                "default": False,
            }
        )
    return pd.DataFrame(rows)


def _fixed_rows(convergence: pd.DataFrame) -> pd.DataFrame:
    """The fixed-step ladder (the comparison's convergence study) in the same columns."""
    return pd.DataFrame(
        {
            "kind": "method",
            "name": convergence["method"],
            "rtol": math.nan,
            "atol": math.nan,
            "h": convergence["h"],
            "error": convergence["error"],
            "evaluations": convergence["nfev"],
            "nfev": convergence["nfev"],
            "njev": 0,
            "time": convergence["time"],
            "success": convergence["stable"],
            "message": "",
            "default": False,
        }
    )


@dataclass(frozen=True, eq=False)
class WorkPrecision:
    """The work–precision study: every run's error, evaluations and wall time.

    Attributes
    ----------
    runs : pandas.DataFrame
        Long form, one row per run: kind (``'method'``: a fixed-step
        method at a step h of the convergence ladder; ``'solver'``: a peer
        at a tolerance; ``'adaptive'``: an embedded qc tableau at a
        tolerance), name, rtol, atol [largest per-state value], h [s],
        error (the largest absolute body-displacement error [m]), evaluations (RHS, with
        Jacobians counted as n each), nfev, njev, time [s], success,
        message, default (python-control's default call).
    reference_name : str
        What the errors are measured against.
    atol_rule : str
        How each run's atol was set.
    loosest_outputs : dict
        Per peer, the outputs ``(noutputs, N)`` of its run at the loosest
        tolerance (``'control'``: its defaults); None where it did not finish.
    tolerance : float
        The accuracy [m] `cheapest` names a winner for (`PEER_TOLERANCE`).
    """

    runs: pd.DataFrame
    reference_name: str
    atol_rule: str
    loosest_outputs: dict = field(default_factory=dict)
    tolerance: float = PEER_TOLERANCE

    def cheapest(self, by: str = "evaluations", tolerance: float | None = None) -> pd.Series | None:
        """The run that reaches ``tolerance`` [m] at the least ``by`` (or None)."""
        return cheapest(self.runs, by, self.tolerance if tolerance is None else tolerance)

    def control_default(self) -> pd.Series | None:
        """python-control's default call's row (None when ``'control'`` did not run)."""
        rows = self.runs[self.runs["default"].astype(bool)]
        return None if rows.empty else rows.iloc[0]

    def best_per_name(self, tolerance: float | None = None) -> pd.DataFrame:
        """Per method or solver: its cheapest run (in evaluations) to reach ``tolerance``,
        with its wall time; the names that never reach it are left out."""
        tol = self.tolerance if tolerance is None else tolerance
        ok = self.runs[(self.runs["error"] <= tol) & self.runs["success"].astype(bool)]
        if ok.empty:
            return ok
        best = ok.loc[ok.groupby("name", sort=False)["evaluations"].idxmin()]
        return best.sort_values("evaluations").set_index("name")


def cheapest(runs: pd.DataFrame, by: str, tolerance: float) -> pd.Series | None:
    """The run with error <= ``tolerance`` and the least ``by`` (``'evaluations'``
    or ``'time'``), or None when none reaches it."""
    if by not in ("evaluations", "time"):
        raise ValueError(f"by must be 'evaluations' or 'time', got {by!r}")
    ok = runs[(runs["error"] <= tolerance) & runs["success"].astype(bool) & runs[by].notna()]
    if ok.empty:
        return None
    return ok.loc[ok[by].astype(float).idxmin()]


def work_precision(
    sys,
    T: np.ndarray,
    X0: np.ndarray,
    U: np.ndarray | None,
    reference,
    body: int,
    convergence: pd.DataFrame,
    *,
    methods: Sequence[ButcherTableau] = (),
    solvers: Sequence[str] = SOLVERS,
    rtols: Sequence[float] = RTOLS,
    repeats: int = 1,
    reference_name: str = "",
    progress: Callable[[str], None] | None = None,
) -> WorkPrecision:
    """Fixed-step methods, adaptive qc pairs and the peers on one work–precision set.

    Parameters
    ----------
    sys : control.StateSpace or control.NonlinearIOSystem
    T, X0, U
        The comparison's grid, start and input samples (None: free response).
    reference : control.TimeResponseData
        The comparison's reference on ``T`` (its states give each state's
        scale for atol; its body displacement is what every error is
        measured against).
    body : int
        The body displacement's row among the outputs.
    convergence : pandas.DataFrame
        The comparison's fixed-step ladder (`convergence_study`).
    methods : sequence of ButcherTableau
        The embedded ones also run over ``rtols`` with step-size control.
    solvers : sequence of str
        Names in `SOLVERS`.
    rtols : sequence of float
        The tolerance ladder, default 1e-3 ... 1e-10.
    repeats : int
        The interleaved rounds each peer's run is timed in (its time the median).
    """
    T = np.asarray(T, dtype=float)
    scale = state_scale(np.asarray(reference.states, dtype=float).reshape(np.size(X0), -1))
    ref_body = np.asarray(reference.outputs, dtype=float).reshape(sys.noutputs, -1)[body]
    problem = _Problem(sys, T, np.asarray(X0, dtype=float), U, body, ref_body, scale)
    peers, loosest = solver_runs(problem, solvers, rtols, repeats=repeats, progress=progress)
    frames = [
        _fixed_rows(convergence),
        adaptive_runs(problem, methods, rtols, repeats=repeats, progress=progress),
        peers,
    ]
    runs = pd.concat([f for f in frames if not f.empty], ignore_index=True)
    return WorkPrecision(
        runs,
        reference_name,
        "atol = rtol · max|x_i| per state over the reference (python-control's default "
        "call keeps scipy's atol 1e-6)",
        loosest,
    )
