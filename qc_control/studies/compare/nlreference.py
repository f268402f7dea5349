"""The reference of a nonlinear car: solve_ivp (DOP853) restarted at each event.

There is no exact solution of a nonlinear system; `nonlinear_reference`
solves it at tight tolerance, from event to event, and estimates its own
accuracy against a second solve at 100x tighter tolerances.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass
from typing import cast

import control
import numpy as np
from scipy.integrate import OdeSolution, solve_ivp

from ... import compat
from ...numerics.integrate import (
    check_time_grid,
)
from ...numerics.sampled import linear_input
from ...responses.timeresp import (
    check_initial_state,
    check_input_samples,
)


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
