"""Solutions of ``x' = f(t, x)`` with any Butcher tableau, explicit or implicit,
at a fixed step or, for an embedded pair given ``rtol``/``atol``, with
step-size control.

`integrate` checks its arguments, steps the grid block by block with the
stage loop of `qc_control.numerics.stepper` (the one place a tableau's
stages are evaluated in Python; for an implicit tableau its simplified
Newton iteration), cuts a run that becomes non-finite or whose stage
equations are not solved, and returns a `Solution`; with ``events`` it
steps to each sign change of the switching functions; with
``rtol``/``atol`` it hands the run to `qc_control.numerics.adaptive`.
`integrate_stepper` gives the same checks and result to a specialised
stepper (`qc_control.numerics.interconnect.FusedSteps`, itself built on the
stage loop). The time-grid rules live here too
(`check_time_grid`, `uniform_step`, `stage_times`).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .adaptive import SCIPY_CONTROLLER, StepController, adaptive_solve, check_embedded
from .checks import ParameterError
from .limits import check_memory
from .messages import show
from .methods import ButcherTableau, get_method
from .stepper import GridSteps, ImplicitSteps, NewtonFailure, stage_plan

__all__ = [
    "Solution",
    "DivergenceWarning",
    "ConvergenceWarning",
    "integrate",
    "integrate_stepper",
    "check_time_grid",
    "check_substeps",
    "check_step_memory",
    "STEP_BLOCK",
    "uniform_step",
    "stage_times",
    "UNIFORM_RTOL",
]

#: Intervals stepped per block: between checks for a non-finite state (checking
#: every step would cost about as much as a stage; a blow-up is still cut at its
#: first bad sample). A block's step times and states are held at once.
STEP_BLOCK = 128
#: The most steps one `integrate` run takes: at the Python stage loop's few
#: microseconds a step, 1e9 steps are hours. Past it a run is refused before it
#: starts (the event and implicit paths hold no per-step table to count).
MAX_RUN_STEPS = 10**9

#: `uniform_step`'s tolerance, in units of ``eps·max|T|``: a grid point may
#: sit this far from ``T[0] + k·dt`` and the grid still counts as uniform.
UNIFORM_RTOL = 4

#: Grid points `uniform_step` checks per vectorised chunk (bounds its memory).
_CHUNK = 1 << 20


class DivergenceWarning(RuntimeWarning):
    """A fixed-step run became non-finite, or its step is beyond stability."""


class ConvergenceWarning(RuntimeWarning):
    """An implicit step's Newton iteration did not converge: the run stopped there."""


@dataclass(frozen=True, eq=False)
class Solution:
    """The result of `integrate` (and of the LTI engine, `qc_control.numerics.lti.lti_solve`).

    Attributes
    ----------
    t : ndarray, shape (N,)
        The output times: the grid given, cut at divergence.
    x : ndarray, shape (n, N), or (m, n, N) for a batch
        The state at each output time (time last, as in python-control).
        Real, or complex when ``x0`` is complex.
    nfev : int
        Right-hand-side evaluations made: ``stages * steps`` (one call of
        ``f`` per stage, whatever the batch size).
    steps : int
        Steps taken (``substeps`` per interval of the grid).
    method : ButcherTableau
    status : str
        ``'success'``, ``'diverged'`` (the state became non-finite) or
        ``'failed'`` (an implicit step's stage equations were not solved, or
        an adaptive step fell below the smallest step the time's precision
        allows).
    message : str
    t_events : ndarray, shape (k,)
        With ``events``: the times at which an event function changed sign,
        each located inside its step and stepped to exactly (see
        `integrate`); empty otherwise.
    i_events : ndarray of int, shape (k,)
        Which event function (its index in the vector ``events`` returns)
        changed sign at each of ``t_events``.
    x_events : ndarray, shape (n, k)
        The state at each of ``t_events`` (the method's step to it).
    accepted_times : ndarray or None
        An adaptive run's start and the end of each accepted step
        (``n_accepted + 1`` times, as ``solve_ivp(...).t``); None at a
        fixed step.
    n_accepted, n_rejected : int
        An adaptive run's accepted and rejected steps (``steps`` is
        ``n_accepted``); 0 at a fixed step.

    Notes
    -----
    A Solution whose ``x`` holds a nan or an inf is never a success: it
    is built with ``status='diverged'`` whatever status it was given.
    """

    t: np.ndarray
    x: np.ndarray
    nfev: int
    steps: int
    method: ButcherTableau
    status: str
    message: str
    t_events: np.ndarray = field(default_factory=lambda: np.empty(0))
    i_events: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=int))
    x_events: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    accepted_times: np.ndarray | None = None
    n_accepted: int = 0
    n_rejected: int = 0

    def __post_init__(self):
        if self.status not in ("success", "diverged", "failed"):
            raise ValueError(
                f"status must be 'success', 'diverged' or 'failed', got {self.status!r}"
            )
        if self.status == "success" and not np.all(np.isfinite(self.x)):
            object.__setattr__(self, "status", "diverged")
            note = "the state holds non-finite values"
            object.__setattr__(self, "message", "; ".join(filter(None, [self.message, note])))

    @property
    def success(self) -> bool:
        return self.status == "success"


def check_time_grid(t, name: str = "T") -> np.ndarray:
    """``t`` as a float array: 1-D, at least 2 points, finite, increasing.

    Raises
    ------
    ValueError
        Naming ``name`` and the offending value.
    """
    try:
        t = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of real times [s], got {show(t)}") from None
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"{name} must be a 1-D array of at least 2 times, got shape {t.shape}")
    # the steps as a slice difference, and the ends checked as Python floats: the same
    # values as np.diff and np.isfinite at a third of their cost on the two-point grids
    # a road profile is evaluated on at every right-hand-side call of a nonlinear car
    steps = t[1:] - t[:-1]
    # finite ends and positive steps leave no room for NaN or inf in between
    # (a NaN fails every comparison): one pass over the steps on a good grid
    if math.isfinite(t[0]) and math.isfinite(t[-1]) and steps.min() > 0:
        return t
    if not np.all(np.isfinite(t)):
        i = int(np.argmin(np.isfinite(t)))
        raise ValueError(f"{name} must be finite; {name}[{i}] = {float(t[i])!r}")
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise ValueError(
            f"{name} must increase strictly: {name}[{i}] = {float(t[i])!r} "
            f"and {name}[{i + 1}] = {float(t[i + 1])!r}"
        )
    return t


def uniform_step(T) -> float | None:
    r"""The step of an evenly spaced grid ``T``, or None.

    ``T`` is uniform when every point lies on the line through its ends
    to within the rounding of the points themselves:

    .. math::

        \max_k \big|T_k - (T_0 + k\,\Delta t)\big| \le 4\,\varepsilon \max_k |T_k|,
        \qquad \Delta t = \frac{T_{N-1} - T_0}{N - 1}

    (``ε`` the double-precision machine epsilon; the factor is
    `UNIFORM_RTOL`). Every step then equals ``Δt`` to within twice that.
    A grid built as ``np.linspace``, ``np.arange`` or ``T0 + k*dt`` sits
    within about one unit in the last place (``≤ ε max|T|``) of that line,
    at any length: ``np.linspace(0, 1e6, 10**8 + 1)`` is uniform. A grid
    that was jittered, or summed step by step (``np.cumsum``, whose
    rounding drifts by hundreds of ulps), is not.

    The bound is on the points, not only on the steps, so that stepping
    with ``Δt`` puts every sample within ``4 ε max|T|`` of its time in
    ``T``. The LTI engine, which assumes ``Δt``, then reproduces the
    generic stepper on ``T`` to about ``|λ|max · 4 ε max|T|`` relative
    (about 2e-13 for the seed's car over 10 s), besides rounding.

    Parameters
    ----------
    T : array_like, shape (N,)
        Times, checked by `check_time_grid`.

    Returns
    -------
    float or None
        ``Δt``, or None when ``T`` is not uniform.

    Examples
    --------
    >>> uniform_step(np.linspace(0, 1, 101))
    0.01
    >>> T = np.linspace(0, 1, 101)
    >>> T[50] += 1e-9
    >>> uniform_step(T) is None
    True
    """
    return checked_uniform_step(check_time_grid(T, "T"))


def checked_uniform_step(T: np.ndarray) -> float | None:
    """`uniform_step` of a grid that `check_time_grid` has already passed."""
    N = T.size
    dt = (T[-1] - T[0]) / (N - 1)
    tol = UNIFORM_RTOL * np.finfo(float).eps * max(abs(T[0]), abs(T[-1]))
    if N <= _CHUNK:  # the line T0 + k·dt of a grid of this size, built once
        return float(dt) if np.max(np.abs(T - _line(float(T[0]), float(dt), N))) <= tol else None
    for lo in range(0, N, _CHUNK):  # in chunks: a 10**8-point grid needs no 800 MB copy
        k = np.arange(lo, min(lo + _CHUNK, N), dtype=float)
        if np.max(np.abs(T[lo : lo + k.size] - (T[0] + k * dt))) > tol:
            return None
    return float(dt)


@functools.lru_cache(maxsize=8)
def _line(t0: float, dt: float, n: int) -> np.ndarray:
    """``t0 + k·dt`` for k = 0 … n-1 (read-only: shared between calls)."""
    line = t0 + np.arange(n, dtype=float) * dt
    line.flags.writeable = False
    return line


def stage_times(t, method="rk4", *, substeps: int = 1) -> np.ndarray:
    """Every time at which `integrate` evaluates ``f`` on the grid ``t`` (no events).

    Shape ``(steps, stages)``: the step's start plus ``c_i h``, computed with
    the same floating-point operations as the stepper, so a right-hand side
    may precompute what it needs at these times (e.g. the interpolated input)
    and look it up by the exact time it is called with.
    """
    tab = get_method(method)
    t = check_time_grid(t, "t")
    substeps = check_substeps(substeps)
    check_step_memory(t.size - 1, substeps, stage_table_bytes(tab.stages), "the stage-times table")
    dt = uniform_step(t)
    tt = t.tolist()
    if dt is not None:
        hs = [dt / substeps] * (t.size - 1)
    else:
        hs = [(tt[i + 1] - tt[i]) / substeps for i in range(t.size - 1)]
    starts = np.array([tt[i] + sub * h for i, h in enumerate(hs) for sub in range(substeps)])
    if tab.implicit:  # every stage at t + c_i h, as `ImplicitSteps.step` computes it
        return starts[:, None] + np.repeat(hs, substeps)[:, None] * tab.c
    plan = stage_plan(tab)
    v = np.repeat(hs, substeps)[:, None] * plan.coefficients
    pcs = plan.time_positions
    return np.column_stack([starts, starts[:, None] + v[:, pcs]]) if pcs else starts[:, None]


def _failed_interval(t: np.ndarray, failure: NewtonFailure) -> int:
    """The grid interval holding the failed step's start: its samples before are kept."""
    return max(0, min(int(np.searchsorted(t, failure.t, side="right")) - 1, t.size - 2))


def _newton_message(tab, t, n_last: int, failure: NewtonFailure) -> str:
    """The one wording of a run stopped by an implicit step's Newton iteration."""
    return (
        f"{tab.name}: the simplified Newton iteration for the implicit stages did not "
        f"converge in the step from t = {failure.t:.6g} s with h = {failure.h:.6g} s "
        f"({failure.reason}); stopped after {n_last} of {t.size - 1} intervals; a smaller "
        "step (more substeps, a smaller max_step) or an explicit method may get through"
    )


def _non_finite_message(tab, t, n_last: int) -> str:
    """The one wording of a run cut at its last finite sample (both stepping loops)."""
    return (
        f"{tab.name}: the state became non-finite after t = "
        f"{t[n_last]:.6g}; stopped after {n_last} of {t.size - 1} intervals"
    )


def stage_table_bytes(stages: int) -> int:
    """Peak bytes per step while `stage_times` builds its table: the start time
    (a Python float, its list slot and its array entry), the step lengths and
    ``c_i h`` products, and the table with its temporaries. tracemalloc on a
    million steps: 40 B for Euler, 136 B for RK4; this gives 72 B and 144 B."""
    return 8 * (6 + 3 * stages)


def check_step_memory(
    intervals: int, substeps: int, bytes_per_step: float, table: str, cause: str = ""
) -> None:
    """Refuse a run whose per-step tables would not fit in memory, before they exist.

    The steps themselves are not stored, but the stepper's tables are per step:
    the stage times of every step (`stage_times`, whole runs), or a block of
    `STEP_BLOCK` intervals' step times, rows and end states (`integrate`).
    ``substeps = 1e9`` (or ``max_step = 1e-12``) asks for 1e11 steps on a grid
    of 100 intervals: terabytes of tables, refused here by
    `qc_control.numerics.limits.check_memory` with the count.

    Parameters
    ----------
    intervals : int
        Intervals of the grid the table covers.
    substeps : int
        Steps per interval.
    bytes_per_step : float
        The table's bytes per step.
    table : str
        What is allocated, for the message (``"the stage-times table"``).
    cause : str, optional
        Where the substeps come from, for the message (default: ``substeps``
        itself; a response names its ``max_step``).
    """
    steps = intervals * substeps
    check_memory(
        steps * bytes_per_step,
        f"{table} of {steps} steps ("
        + (cause or f"substeps = {substeps}")
        + f" in each of {intervals} intervals)",
        "use fewer substeps or a larger max_step",
    )


def check_run_steps(intervals: int, substeps: int) -> None:
    """Refuse a run of more than `MAX_RUN_STEPS` steps before it starts, naming the count."""
    steps = intervals * substeps
    if steps > MAX_RUN_STEPS:
        raise ValueError(
            f"a run of {steps} steps (substeps = {substeps} in each of {intervals} "
            f"intervals) is more than one run takes ({MAX_RUN_STEPS:.0e}, hours of "
            "stepping); use fewer substeps or a larger max_step"
        )


def check_substeps(substeps) -> int:
    """``substeps`` as an int >= 1, or a `ParameterError` naming it."""
    if isinstance(substeps, bool) or not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise ParameterError("substeps", substeps, "a positive integer")
    return int(substeps)


def integrate(
    f, t, x0, method="rk4", *, substeps: int = 1, events=None, jac=None, rtol=None,
    atol=None, first_step=None, max_step=np.inf, breakpoints=None, controller=SCIPY_CONTROLLER,
) -> Solution:  # fmt: skip
    """Solve ``x' = f(t, x)`` with a Runge–Kutta method, explicit or implicit,
    at a fixed step or (an embedded pair) with step-size control.

    Each interval ``[t[i], t[i+1]]`` of the grid is split into ``substeps``
    equal steps ``h``; on a grid that `uniform_step` finds uniform, every
    interval is taken as its step ``Δt`` (the grid's points differ from
    ``t[0] + iΔt`` only by their rounding). One step is

    .. math::

        k_i = f\\big(t + c_i h,\\; x + h \\textstyle\\sum_{j<i} a_{ij} k_j\\big), \\qquad
        x \\leftarrow x + h \\textstyle\\sum_i b_i k_i .

    With an implicit tableau the sum runs over every ``j`` and each step
    solves its stage equations by a simplified Newton iteration
    (`qc_control.numerics.stepper.ImplicitSteps`, tolerance
    `qc_control.numerics.stepper.NEWTON_RTOL`).

    Parameters
    ----------
    f : callable ``f(t, x) -> dx/dt``
        Gets a float ``t`` and ``x`` of the shape of ``x0``; returns the
        same shape. For a batch, ``f`` sees the whole ``(m, n)`` batch.
    t : array_like, shape (N,)
        Output times, strictly increasing; need not be uniform.
    x0 : array_like, shape (n,) or (m, n)
        Initial state, or ``m`` initial states stepped together. As in
        scipy's `solve_ivp`, a complex ``x0`` makes the integration
        complex; with a real ``x0``, ``f`` must return real values.
    method : str or ButcherTableau, default ``'rk4'``
        A name in `qc_control.numerics.methods.TABLEAUS` or any tableau.
        An implicit tableau needs a single ``x0`` of shape (n,).
    substeps : int, default 1
        Steps per interval of ``t``.
    events : callable ``events(t, x) -> array_like``, optional
        Switching functions: the points where one of them changes sign are
        the kinks of ``f`` (a contact made or lost, a stop engaged). After
        each step the signs are compared with those at its start; where one
        changed, the crossing time ``t*`` is found by root finding on the
        state, ``s ↦ events(t + s, Φ_s(x))`` with ``Φ_s`` the method's own
        step of length ``s`` (Brent's method, to ``1e-12`` of the step);
        the run steps from ``t`` to ``t*`` exactly, then on from ``t*``
        across the rest of the step, so that no step straddles a kink and
        the method keeps its order on a right-hand side that is smooth on
        either side (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.6,
        discontinuous right-hand sides). The times go to
        ``Solution.t_events``. A single ``x0`` only (not a batch); a zero
        touched without a sign change (grazing) is not an event.
    rtol, atol : float, optional
        Step-size control for an embedded pair (a tableau with ``b_hat``:
        ``'heun_euler'``, ``'bogacki_shampine'``, ``'dormand_prince'``):
        either one given makes the run adaptive, the other taking scipy's
        default (rtol 1e-3, atol 1e-6; atol may be one per state). The
        steps are chosen by the standard controller
        (`qc_control.numerics.adaptive`, HNW I, §II.4) and ``t`` is only
        where the solution is reported: between step ends it is the pair's
        continuous extension (dense output), so the output grid does not
        hold the steps back. rtol must be at least 100 eps, both positive
        and finite. A single ``x0`` only; no ``events``, ``substeps`` 1.
    first_step, max_step : float, optional
        An adaptive run's first step (default: HNW's starting-step rule,
        as scipy's) and largest step (default inf) [s].
    breakpoints : array_like, optional
        Times at which ``f`` is not smooth in ``t`` (a sampled input's
        kinks, `qc_control.numerics.adaptive.slope_breakpoints`): an
        adaptive step never crosses one. Ignored at a fixed step, whose
        steps end on the grid.
    controller : StepController, optional
        The controller's constants; default scipy's.
    jac : callable ``jac(t, x) -> (n, n)``, optional
        ``∂f/∂x``, for an implicit tableau's Newton iteration; by forward
        differences (n + 1 calls of ``f`` per step) when left out.

    Returns
    -------
    Solution
        If the state becomes non-finite, the run stops there: a
        `DivergenceWarning` is issued and the solution holds the samples
        up to the last finite one, with ``status='diverged'``. Every
        sample is checked; a non-finite state is never a success. If an
        implicit step's Newton iteration does not converge, the run stops
        at the start of that step's interval: a `ConvergenceWarning` is
        issued and the solution has ``status='failed'`` and a message
        naming the step's time and length. An adaptive run whose step
        underflows stops with ``status='failed'`` and a message, holding
        the samples it reached.

    Raises
    ------
    ValueError
        For a bad ``t``, ``x0``, ``substeps`` or tolerance, naming it and
        its value; for ``rtol``/``atol`` with a tableau without ``b_hat``.
    TypeError
        For an ``f`` that is not callable, or that returns complex values
        on a real state.

    Notes
    -----
    The loop (`qc_control.numerics.stepper.rk_steps`) is scipy's plain
    stage loop (``rk_step`` in ``scipy/integrate/_ivp/rk.py``) over the
    tableau as data, with the
    non-zero ``h a_ij``, ``h b_i`` and ``c_i h`` computed once per step
    size and zero entries skipped; stages of equal weight are summed
    before they are scaled.

    Examples
    --------
    >>> import numpy as np
    >>> sol = integrate(lambda t, x: -x, np.linspace(0, 1, 11), [1.0], "rk4")
    >>> float(abs(sol.x[0, -1] - np.exp(-1))) < 1e-6, sol.nfev
    (True, 40)
    """
    tab = get_method(method)
    t = check_time_grid(t, "t")
    substeps = check_substeps(substeps)
    if not callable(f):
        raise TypeError(f"f must be callable as f(t, x), got {show(f)}")
    x = _initial_state(x0)
    if jac is not None and not callable(jac):
        raise TypeError(f"jac must be callable as jac(t, x), got {show(jac)}")
    if tab.implicit and x.ndim != 1:
        raise ValueError(
            f"the implicit tableau {tab.name!r} steps a single initial state of shape (n,), "
            f"got x0 of shape {x.shape}"
        )
    if rtol is not None or atol is not None:
        return _integrate_adaptive(
            f, t, x, tab, (rtol, atol), (substeps, events),
            dict(first_step=first_step, max_step=max_step, controller=controller),
            breakpoints,
        )  # fmt: skip
    if events is not None:
        if not callable(events):
            raise TypeError(f"events must be callable as events(t, x), got {show(events)}")
        if x.ndim != 1:
            raise ValueError(f"events need a single initial state of shape (n,), got {x.shape}")
        check_run_steps(t.size - 1, substeps)  # no per-step table bounds these two paths
        return _integrate_events(f, t, x, tab, substeps, events, jac)
    if tab.implicit:
        check_run_steps(t.size - 1, substeps)
        implicit = ImplicitSteps(tab, t.tolist(), substeps, uniform_step(t), jac)

        def newton_run(x, out, start, stop):
            return implicit.run(f, x, out[start:], start, stop)

        return _blocks(newton_run, t, x, tab, substeps, stacklevel=3, nfev=lambda: implicit.nfev)

    # a uniform grid is stepped with its one step, like the LTI engine
    dt = uniform_step(t)
    grid = GridSteps(tab, t.tolist(), substeps, dt)
    check_step_memory(
        min(STEP_BLOCK, t.size - 1),
        substeps,
        grid.scratch_bytes(x),
        "the step times and states of a block",
    )

    def run(x, out, start, stop):
        return grid.run(f, x, out[start:], start, stop)

    return _blocks(run, t, x, tab, substeps, stacklevel=3)


def _integrate_adaptive(f, t, x, tab, tol, fixed, options, breakpoints) -> Solution:
    """`integrate` with ``rtol``/``atol``: the arguments checked, the run handed
    to `qc_control.numerics.adaptive.adaptive_solve`, its result as a `Solution`."""
    substeps, events = fixed
    check_embedded(tab)
    if substeps != 1 or events is not None:
        raise ValueError(
            f"an adaptive run (rtol/atol) takes neither substeps (got {substeps}) nor events "
            f"(got {show(events)}): its steps are chosen by the error estimate"
        )
    if x.ndim != 1:
        raise ValueError(f"an adaptive run needs a single initial state (n,), got {x.shape}")
    if not isinstance(options["controller"], StepController):
        raise TypeError(f"controller must be a StepController, got {show(options['controller'])}")
    stops = np.empty(0) if breakpoints is None else _breakpoint_times(breakpoints)
    with np.errstate(over="ignore", invalid="ignore"):
        run = adaptive_solve(f, t, x, tab, *tol, breakpoints=stops, **options)
    x = np.moveaxis(run.x, 0, -1)  # time last, as every Solution
    return Solution(
        run.t, x, run.nfev, run.n_accepted, tab, run.status, run.message,
        accepted_times=run.accepted_times, n_accepted=run.n_accepted, n_rejected=run.n_rejected,
    )  # fmt: skip


def _breakpoint_times(breakpoints) -> np.ndarray:
    """``breakpoints`` as a 1-D array of finite times, or a ValueError."""
    try:
        b = np.asarray(breakpoints, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"breakpoints must be times [s], got {show(breakpoints)}") from None
    if not np.all(np.isfinite(b)):
        raise ValueError(f"breakpoints must be finite times [s], got {show(breakpoints)}")
    return b


def integrate_stepper(stepper, t, x0, method="rk4", *, substeps: int = 1) -> Solution:
    """`integrate`'s loop (divergence checks, `Solution`) around a specialised stepper.

    For a right-hand side that steps itself faster than ``f`` called
    stage by stage can (`qc_control.numerics.interconnect`'s fused steps):
    ``stepper(x, out, start, stop)`` takes the steps from ``t[start]`` to
    ``t[stop]`` with ``method`` (``substeps`` per interval), writes the
    state at the end of each interval ``i`` into ``out[i + 1]`` and
    returns the last. The run is cut,
    warned about and reported exactly as `integrate` does, and ``nfev``
    counts ``stages · steps`` as if ``f`` had been called per stage.

    Parameters
    ----------
    stepper : callable ``stepper(x, out, start, stop) -> x``
    t : array_like, shape (N,)
        Output times, strictly increasing (`check_time_grid`).
    x0 : array_like, shape (n,)
        Initial state (real).
    method : str or ButcherTableau, default ``'rk4'``
        The tableau the stepper implements (for ``nfev`` and the message).
    substeps : int, default 1
        The steps the stepper takes per interval (for ``steps`` and ``nfev``).

    Returns
    -------
    Solution
    """
    tab = get_method(method)
    t = check_time_grid(t, "t")
    if not callable(stepper):
        raise TypeError(
            f"stepper must be callable as stepper(x, out, start, stop), got {show(stepper)}"
        )
    substeps = check_substeps(substeps)
    return _blocks(stepper, t, _initial_state(x0), tab, substeps, stacklevel=3)


def _blocks(run, t, x, tab, substeps, stacklevel, nfev=None) -> Solution:
    """Run ``run(x, out, start, stop)`` block by block, checking for a non-finite state.

    A `NewtonFailure` (an implicit step) stops the run at the start of the
    interval it happened in, as ``status='failed'``. ``nfev()``, if given,
    counts the evaluations made (else ``stages`` per step).
    """
    out = np.empty((t.size,) + x.shape, dtype=x.dtype)
    out[0] = x
    n_last, n_computed, status, message = t.size - 1, t.size - 1, "success", ""
    with np.errstate(over="ignore", invalid="ignore"), warnings.catch_warnings():
        # a complex f on a real state would lose its imaginary part in `out`
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        for start in range(0, t.size - 1, STEP_BLOCK):
            stop = min(start + STEP_BLOCK, t.size - 1)
            try:
                x = run(x, out, start, stop)
            except np.exceptions.ComplexWarning:
                raise TypeError(
                    "f returned complex values for a real x0; pass a complex x0 (e.g. "
                    "x0 + 0j) to integrate in complex arithmetic, as scipy's solve_ivp does"
                ) from None
            except NewtonFailure as failure:
                n_last = n_computed = _failed_interval(t, failure)
                status, message = "failed", _newton_message(tab, t, n_last, failure)
                warnings.warn(message, ConvergenceWarning, stacklevel=stacklevel)
                break
            block = out[start + 1 : stop + 1]
            if np.isfinite(block).all():
                continue
            bad = ~np.isfinite(block.reshape(block.shape[0], -1)).all(axis=1)
            if bad.any():
                n_last = start + int(np.argmax(bad))
                n_computed = stop
                status = "diverged"
                message = _non_finite_message(tab, t, n_last)
                warnings.warn(message, DivergenceWarning, stacklevel=stacklevel)
                break
    steps = n_computed * substeps
    return Solution(
        t=t[: n_last + 1],
        x=np.moveaxis(out[: n_last + 1], 0, -1),
        nfev=tab.stages * steps if nfev is None else nfev(),
        steps=steps,
        method=tab,
        status=status,
        message=message,
    )


def _initial_state(x0) -> np.ndarray:
    """``x0`` as a float (or, if complex, complex) array of shape (n,) or (m, n)."""
    try:
        x = np.array(x0)
        x = x.astype(complex if np.iscomplexobj(x) else float)
    except (TypeError, ValueError):
        raise ValueError(
            f"x0 must be an array of real or complex numbers, got {show(x0)}"
        ) from None
    if x.ndim not in (1, 2) or x.size == 0:
        raise ValueError(f"x0 must have shape (n,) or (m, n), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"x0 must be finite, got {show(x0)}")
    return x


#: Most events located inside one step before the rest of it is taken as it is.
_MAX_EVENTS_PER_STEP = 16


def _integrate_events(f, t, x, tab, substeps, events, jac=None) -> Solution:
    """`integrate` with switching functions: step to each sign change exactly."""
    out = np.empty((t.size,) + x.shape, dtype=x.dtype)
    out[0] = x
    dt = uniform_step(t)
    tt = t.tolist()
    run = _EventSteps(f, tab, x, events, jac)
    sign = np.sign(run.switch(tt[0], x))
    n_last, status, message = t.size - 1, "success", ""
    with np.errstate(over="ignore", invalid="ignore"):
        for i in range(t.size - 1):
            h = ((tt[i + 1] - tt[i]) if dt is None else dt) / substeps
            try:
                for sub in range(substeps):
                    ta = tt[i] + sub * h
                    x = run.across(ta, tt[i + 1] if sub == substeps - 1 else ta + h, x, sign)
            except NewtonFailure as failure:
                n_last, status = i, "failed"
                message = _newton_message(tab, t, n_last, failure)
                warnings.warn(message, ConvergenceWarning, stacklevel=3)
                break
            out[i + 1] = x
            if not np.all(np.isfinite(x)):
                n_last, status = i, "diverged"
                message = _non_finite_message(tab, t, n_last)
                warnings.warn(message, DivergenceWarning, stacklevel=3)
                break
    return Solution(
        t=t[: n_last + 1],
        x=np.moveaxis(out[: n_last + 1], 0, -1),
        nfev=run.calls,
        steps=run.steps,
        method=tab,
        status=status,
        message=message,
        t_events=np.array(run.t_events),
        i_events=np.array(run.i_events, dtype=int),
        x_events=np.array(run.x_events).reshape(len(run.x_events), x.size).T,
    )


class _EventSteps:
    """The steps of an `integrate` run with events: each step cut at the sign changes.

    Counts the right-hand side's calls (``calls``) and the steps taken
    (``steps``: a step cut at an event counts as two), and collects the
    located events (``t_events``, ``i_events``).
    """

    def __init__(self, f, tab, x, events, jac=None):
        self._f, self._events = f, events
        # an implicit tableau's step is its Newton iteration, same call shape
        self._grid = ImplicitSteps(tab, [], jac=jac) if tab.implicit else GridSteps(tab, [])
        self._buf = np.empty((2,) + x.shape, dtype=x.dtype)
        self.calls = self.steps = 0
        self.t_events: list[float] = []
        self.i_events: list[int] = []
        self.x_events: list[np.ndarray] = []
        self._shape: tuple[int, ...] | None = None  # of the switching functions

    def _counted(self, t, x):
        self.calls += 1
        return self._f(t, x)

    def step(self, t0, x0, h):
        """The method's own step of length ``h`` from ``(t0, x0)``."""
        return self._grid.step(self._counted, t0, x0, h, self._buf)

    def switch(self, t, x):
        g = np.atleast_1d(np.asarray(self._events(t, x), dtype=float))
        # a sign change is tracked per function: their number and order must not change
        if g.ndim != 1 or g.shape != (self._shape or g.shape):
            raise ValueError(
                f"events(t, x) must return the same number of switching functions at every "
                f"call (a 1-D array); it returned shape {g.shape} at t = {t:.6g} s"
                + (f", after {self._shape}" if self._shape else "")
            )
        self._shape = g.shape
        return g

    def across(self, ta, tb, x, sign):
        """The state at ``tb`` from ``(ta, x)``, stepping to each event inside first.

        ``sign`` (the switching functions' signs at ``ta``) is updated to ``tb``.
        """
        for located in range(_MAX_EVENTS_PER_STEP + 1):
            xb = self.step(ta, x, tb - ta)
            self.steps += 1
            sb = np.sign(self.switch(tb, xb))
            unset = sign == 0
            sign[unset] = sb[unset]
            changed = np.flatnonzero((sb != sign) & (sb != 0))
            if changed.size == 0 or located == _MAX_EVENTS_PER_STEP or not np.all(np.isfinite(xb)):
                sign[changed] = sb[changed]
                return xb
            root = self._first_root(ta, tb, x, changed, sign, sb)
            if root is None:
                return xb
            s_root, k = root
            sign[k] = sb[k]
            if s_root <= 0.0:  # at the step's start: nothing to step to
                continue
            x = self.step(ta, x, s_root)
            self.steps += 1
            ta = ta + s_root
            self.t_events.append(ta)
            self.i_events.append(k)
            self.x_events.append(np.array(x))
            if ta >= tb:
                return x
        return xb

    def _first_root(self, ta, tb, x, changed, sign, sb):
        """``(s, k)``: the earliest crossing ``ta + s`` among the functions ``changed``, or None.

        Brent's method on ``s ↦ events(ta + s, Φ_s(x))``, to ``1e-12`` of the
        step; a function already on its new side at ``ta`` (rounding) only
        has its sign updated.
        """
        # scipy.optimize costs a third of a second to import; only runs with
        # contact events need its root finder, so they pay for it.
        from scipy.optimize import brentq

        ga = self.switch(ta, x)
        roots = []
        for k in changed.tolist():
            if np.sign(ga[k]) != sign[k]:  # on its new side already (rounding)
                sign[k] = sb[k]
                continue

            def phi(s, k=k):
                return self.switch(ta + s, self.step(ta, x, s))[k]

            roots.append((brentq(phi, 0.0, tb - ta, xtol=1e-12 * (tb - ta)), k))
        return min(roots) if roots else None
