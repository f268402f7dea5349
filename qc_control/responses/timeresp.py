"""Fixed-step time responses with python-control's call shape and return type.

``qc.initial_response``, ``qc.forced_response``, ``qc.step_response`` and
``qc.impulse_response`` take exactly the arguments of python-control
0.10.2's functions of the same names (positional order, keywords, aliases
such as ``T``/``U``/``X0``/``T_num``, `control.config.defaults`) and return
the same `control.TimeResponseData` (labels, ``.plot()``, ``.to_pandas()``,
tuple unpacking), or a `control.TimeResponseList` for a list of systems.
The difference is the trajectory: for a continuous-time system it is the
one the chosen fixed-step method computes. ``method``, ``substeps`` and
``engine`` are keyword-only additions; so are ``rtol`` and ``atol``, with
which an embedded pair (``'heun_euler'``, ``'bogacki_shampine'``,
``'dormand_prince'``) chooses its own steps
(`qc_control.numerics.adaptive`), never crossing a sample of the input
where its slope changes.

Which systems go where:

* continuous-time `control.StateSpace`: the fixed-step method;
* continuous-time `control.TransferFunction`: converted with `control.ss`
  (its signal names carry over), then as above;
* discrete-time systems (``dt > 0`` or ``dt=True``) and ``dt=None`` systems
  have nothing to integrate. python-control simulates them by their own
  difference equation (``dt=None`` with the grid's spacing as the sample
  time), and so do these functions, through python-control itself; the
  result's ``note`` says that no method was applied;
* `control.NonlinearIOSystem` (including an `control.InterconnectedSystem`):
  `input_output_response`, python-control's call at a fixed step, as
  control's own responses hand such systems to its
  `control.input_output_response`.
"""

from __future__ import annotations

import inspect
import math
import warnings
from dataclasses import dataclass
from typing import NamedTuple

import control
import numpy as np

# Captured at import, so that a caller who routes control's function to this
# module (as tests/peer does) still reaches control's own difference equation.
from control.nlsys import input_output_response as _control_io_response
from control.timeresp import forced_response as _control_forced_response

from .. import compat
from ..numerics.adaptive import check_embedded, slope_breakpoints
from ..numerics.checks import positive
from ..numerics.clocked import ClockedLoop, step_clocked
from ..numerics.integrate import (
    STEP_BLOCK,
    DivergenceWarning,
    check_run_steps,
    check_step_memory,
    check_substeps,
    check_time_grid,
    checked_uniform_step,
    integrate,
    integrate_stepper,
    stage_times,
    uniform_step,
)
from ..numerics.interconnect import CompiledInterconnect, FusedSteps, compile_interconnect
from ..numerics.limits import check_memory
from ..numerics.lti import array_key, is_nonlinear_system, lti_states, memo
from ..numerics.methods import TABLEAUS, ButcherTableau, get_method
from ..numerics.sampled import linear_input
from ..numerics.stability import max_stable_step, step_is_stable
from ..numerics.stepper import ImplicitSteps
from ..numerics.steps import (  # the step policy's constants, re-exported from their old home
    AUTO_STEP_LOCAL_ERROR,  # noqa: F401
    AUTO_STEP_STABILITY_FRACTION,  # noqa: F401
    auto_step,
    auto_substeps,
    substeps_for,
)
from ..numerics.trajectory_stability import (
    GROWTH_FACTOR,
    fastest_changes,
    first_unstable,
    growth_limit,
    jacobians,
)

__all__ = [
    "FixedStepResponse",
    "initial_response",
    "forced_response",
    "step_response",
    "impulse_response",
    "input_output_response",
    "auto_step",
    "check_initial_state",
    "check_input_samples",
]

_ENGINES = ("auto", "lti", "generic")


class FixedStepResponse(control.TimeResponseData):
    """A `control.TimeResponseData` that also says how it was computed.

    It has every attribute of `control.TimeResponseData`, and these besides.

    Attributes
    ----------
    method : ButcherTableau or None
        The method that computed the response; None when no method was
        applied (a discrete-time or ``dt=None`` system).
    h : float or None
        The largest step taken [s] (an interval of ``T`` over ``substeps``).
    substeps : int
        Steps per interval of the time grid.
    steps, nfev : int
        Steps taken and right-hand-side evaluations (``stages * steps``),
        summed over the traces of a step or impulse response.
    step_rule : str or None
        When the time grid was chosen automatically (``T`` None or a final
        time): which rule set ``h`` (see `auto_step`).
    note : str or None
        Anything else the reader should know, e.g. that a discrete-time
        system was simulated by its difference equation, no method applied.
    max_stable_step : float or None
        The method's stability limit for this system [s] (see
        `qc_control.max_stable_step`), computed when asked.
    t_events : ndarray
        With ``events`` (`input_output_response`): the times [s] at which
        a switching function changed sign, each stepped to exactly.
    event_labels : tuple of str
        Which switching function changed sign at each of ``t_events``.
    rtol, atol : float or None
        The tolerances of an adaptive run (an embedded pair given
        ``rtol``/``atol``); None at a fixed step.
    accepted_times : ndarray or None
        An adaptive run's start and the end of every accepted step [s]
        (as ``solve_ivp(...).t``); with several traces (a step or impulse
        response of several inputs), the last trace's. None at a fixed step.
    n_accepted, n_rejected : int
        An adaptive run's accepted and rejected steps, summed over traces
        (``steps`` is ``n_accepted``; ``nfev`` counts every evaluation,
        rejected steps' included).
    success, message
        As in python-control. ``success`` is False whenever the step
        exceeds the method's stability limit, the run diverged, or any
        state or output is NaN or inf.
    """

    method: ButcherTableau | None = None
    h: float | None = None
    substeps: int = 1
    steps: int = 0
    nfev: int = 0
    step_rule: str | None = None
    note: str | None = None
    t_events: np.ndarray = np.empty(0)
    event_labels: tuple[str, ...] = ()
    rtol: float | None = None
    atol: float | np.ndarray | None = None
    accepted_times: np.ndarray | None = None
    n_accepted: int = 0
    n_rejected: int = 0
    _eigenvalues: np.ndarray | None = None

    @property
    def max_stable_step(self) -> float | None:
        """The method's stability limit for this system [s], computed when asked."""
        if self.method is None or self._eigenvalues is None:
            return None
        return max_stable_step(self.method, self._eigenvalues)


# ---------------------------------------------------------------- input checks


def check_initial_state(X0, n: int, labels=None) -> np.ndarray:
    """``X0`` as a finite real array of shape ``(n,)``.

    A number fills every state; ``(n, 1)`` and ``(1, n)`` are flattened,
    as python-control accepts them. The one check of an initial state that
    the responses and `qc_control.sweep` share; ``labels`` (the state
    labels) name the states in its message.

    Raises
    ------
    ValueError
        Naming the shape or the values when they do not fit.
    """
    raw = np.asarray(X0)
    if raw.dtype.kind == "c":
        raise ValueError(
            f"X0 must be real: the fixed-step engines integrate real states, got {raw.tolist()}"
        )
    try:
        x0 = np.asarray(X0, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"X0 must be numbers, got {X0!r}") from None
    if x0.ndim == 0:
        x0 = np.full(n, float(x0))
    elif x0.shape in ((n, 1), (1, n)):
        x0 = x0.reshape(n)
    if x0.shape != (n,):
        states = "" if labels is None else f" {list(labels)}"
        raise ValueError(
            f"X0 must be {n} finite numbers, one per state{states}, or one number for "
            f"every state: X0 must have shape ({n},) for a system with {n} states, got {raw.shape}"
        )
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"X0 must be finite, got {x0.tolist()}")
    return x0


def check_input_samples(U, ninputs: int, nsteps: int, labels=None) -> np.ndarray:
    """``U`` as a finite real ``(ninputs, nsteps)`` array, with python-control's shapes.

    A number (or None, meaning 0) holds every input at that value; one
    input may be given as ``(nsteps,)``. The one check of input samples that
    the responses and `qc_control.sweep` share; ``labels`` (the input labels)
    name the inputs in its message.

    Raises
    ------
    ValueError
        Naming the expected and the given shape, or the bad values.
    """
    raw = np.asarray(0.0 if U is None else U)
    if raw.dtype.kind == "c":
        raise ValueError("U must be real: the fixed-step engines integrate real states")
    try:
        u = np.asarray(raw, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"U must be numbers, got an array of {raw.dtype}") from None
    if u.ndim == 0:
        if ninputs == 0 and u != 0:
            raise ValueError(
                f"U = {float(u)!r} is given but the system has no inputs "
                "(build it with quarter_car(road=True) or actuator=True)"
            )
        u = np.full((ninputs, nsteps), float(u))
    elif u.ndim == 1 and ninputs == 1:
        u = u.reshape(1, -1)
    if u.shape != (ninputs, nsteps):
        want = f"({nsteps},) or (1, {nsteps})" if ninputs == 1 else f"({ninputs}, {nsteps})"
        inputs = "" if labels is None else f" {list(labels)}"
        raise ValueError(
            f"U must be finite, of shape {want} for the inputs{inputs} on T, or one number "
            f"for every input: U must have shape {want} to match T (len {nsteps}) and the "
            f"system's {ninputs} input(s), got {raw.shape}"
        )
    if not np.all(np.isfinite(u)):
        first = np.argwhere(~np.isfinite(u))[0].tolist()
        raise ValueError(f"U must be finite; first bad sample at index {first}")
    return u


# ---------------------------------------------------------------- engines


def _linear_rhs(A, B, T, u_samples):
    """``f(t, x) = A x + B u(t)``, the input linear between its samples."""
    AT, BT = A.T.copy(), B.T.copy()
    if np.any(u_samples) and u_samples.shape[0] == 1:
        # one road: u(t) a float times B's column, the same products to the bit
        # at half the cost of the small arrays of u(t) @ Bᵀ (a stage's main cost)
        u1, b = linear_input(T, u_samples).scalar(), BT[0].copy()

        def rhs(t, x):
            return x @ AT + u1(t) * b
    elif np.any(u_samples):
        u_of_t = linear_input(T, u_samples)

        def rhs(t, x):
            return x @ AT + u_of_t(t) @ BT
    else:

        def rhs(t, x):
            return x @ AT

    return rhs


def _generic(A, B, T, u_samples, x0, tab, substeps, warn):
    """The generic stepper on ``f(t, x) = A x + B u(t)``.

    An implicit tableau's stages are linear in them here: each step is one
    solve with the factors of ``I - h a ⊗ A`` (`ImplicitSteps` with
    ``linear=True``, the Newton iteration's first correction, which solves
    them exactly), its ``s`` evaluations of ``f`` counted as any method's.
    """
    rhs = _linear_rhs(A, B, T, u_samples)
    with warnings.catch_warnings():
        if not warn:  # the step-size warning already told the user
            warnings.simplefilter("ignore", DivergenceWarning)
        if not tab.implicit:
            return integrate(rhs, T, x0, tab, substeps=substeps)
        check_run_steps(T.size - 1, substeps)
        steps = ImplicitSteps(
            tab, T.tolist(), substeps, uniform_step(T), jac=lambda t, x: A, linear=True
        )

        def run(x, out, start, stop):
            return steps.run(rhs, x, out[start:], start, stop)

        return integrate_stepper(run, T, x0, tab, substeps=substeps)


def _not_a_method(value, name: str) -> None:
    """A method given where python-control has another positional: say so.

    ``method`` was the 4th positional of qc's responses before they took
    python-control's exact signature; ``qc.initial_response(sys, T, X0,
    'rk4')`` would now ask for output 'rk4' (and ``forced_response``'s 5th
    positional is ``transpose``, where 'rk4' is silently true).
    """
    if isinstance(value, ButcherTableau) or (
        isinstance(value, str) and value.strip().lower() in TABLEAUS
    ):
        raise TypeError(
            f"{name}={value!r} looks like a method: method is keyword-only "
            f"(method={value!r}); here {name} means what it means in python-control"
        )


def _stacklevel() -> int:
    """The ``stacklevel`` that points a warning at the caller's line, outside this module."""
    frame, level = inspect.currentframe(), 0
    while frame is not None and frame.f_code.co_filename == __file__:
        frame, level = frame.f_back, level + 1
    return level


class _Options:
    """The keyword-only additions, checked once per call."""

    def __init__(self, method, substeps, engine, rtol=None, atol=None):
        self.tab = get_method(method)
        self.substeps = check_substeps(substeps)
        if engine not in _ENGINES:
            raise ValueError(f"engine must be 'auto', 'lti' or 'generic', got {engine!r}")
        self.engine = engine
        self.rtol, self.atol = rtol, atol
        #: an embedded pair given rtol/atol chooses its own steps
        self.adaptive = rtol is not None or atol is not None
        if self.adaptive:
            _check_adaptive(self)


def _check_adaptive(opts: _Options) -> None:
    """rtol/atol need an embedded pair, one step per interval and the generic engine."""
    check_embedded(opts.tab)
    if opts.substeps != 1:
        raise ValueError(
            f"substeps = {opts.substeps} with rtol/atol: an adaptive run chooses its own steps"
        )
    if opts.engine == "lti":
        raise ValueError(
            "engine='lti' steps at a fixed step; rtol/atol need engine 'auto' or 'generic'"
        )
    # the tolerances themselves are checked once the states are known (integrate)


@dataclass
class _Computed:
    """How a response was computed: what `FixedStepResponse` adds to control's data."""

    method: ButcherTableau | None
    h: float | None
    substeps: int
    step_rule: str | None
    eigenvalues: np.ndarray | None
    steps: int = 0
    nfev: int = 0
    note: str | None = None
    adaptive: _AdaptiveCounts | None = None

    def stamp(self, resp: FixedStepResponse) -> FixedStepResponse:
        """``resp`` with these attributes set."""
        resp.method, resp.h, resp.substeps = self.method, self.h, self.substeps
        resp.steps, resp.nfev = self.steps, self.nfev
        resp.step_rule, resp.note, resp._eigenvalues = self.step_rule, self.note, self.eigenvalues
        if self.adaptive is not None:
            a = self.adaptive
            resp.rtol, resp.atol, resp.accepted_times = a.rtol, a.atol, a.accepted_times
            resp.n_accepted, resp.n_rejected = a.n_accepted, a.n_rejected
        return resp

    @classmethod
    def of(cls, resp: FixedStepResponse) -> _Computed:
        """What ``resp`` says about how it was computed."""
        adaptive = None
        if resp.accepted_times is not None:
            adaptive = _AdaptiveCounts(
                resp.rtol, resp.atol, resp.accepted_times, resp.n_accepted, resp.n_rejected
            )
        return cls(
            resp.method, resp.h, resp.substeps, resp.step_rule, resp._eigenvalues,
            resp.steps, resp.nfev, resp.note, adaptive,
        )  # fmt: skip

    def record(self, sol, opts: _Options) -> None:
        """The steps and evaluations of the run ``sol`` (a `Solution`); an adaptive
        run's counts, accepted times and largest step besides."""
        self.steps, self.nfev = sol.steps, sol.nfev
        if sol.accepted_times is None:
            return
        self.adaptive = _AdaptiveCounts(
            1e-3 if opts.rtol is None else opts.rtol,
            1e-6 if opts.atol is None else opts.atol,
            sol.accepted_times,
            sol.n_accepted,
            sol.n_rejected,
        )
        self.substeps = 1
        self.h = float(np.diff(sol.accepted_times).max()) if sol.n_accepted else None
        self.step_rule = (
            f"adaptive: {sol.n_accepted} steps accepted and {sol.n_rejected} rejected "
            f"at rtol {self.adaptive.rtol}, atol {_show_tolerance(self.adaptive.atol)}"
        )


@dataclass
class _AdaptiveCounts:
    """What an adaptive run adds to `_Computed`."""

    rtol: float | None
    atol: float | np.ndarray | None
    accepted_times: np.ndarray
    n_accepted: int
    n_rejected: int


def _show_tolerance(atol) -> str:
    """``atol`` for a message: a number, or the range of one per state."""
    a = np.asarray(atol, dtype=float)
    return f"{float(a):g}" if a.ndim == 0 else f"{a.min():g}..{a.max():g} (one per state)"


class _LinearRun(NamedTuple):
    """One fixed-step run of a continuous-time StateSpace (`_simulate`)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    computed: _Computed
    success: bool
    message: str
    #: the engine proved the states finite (the LTI engine's cut): `_finalise` looks at y only
    states_finite: bool = False


def _linear_step(tab: ButcherTableau, A: np.ndarray, H: float, opts: _Options, auto: bool):
    """The run's `_Computed` before stepping: eigenvalues, substeps and ``h``.

    With an automatic grid, the fewest substeps whose step meets `auto_step`'s
    rule (never fewer than asked).
    """
    # eigenvalues as computed: the stability functions settle those that rounding
    # moved off the imaginary axis (qc_control.numerics.stability, MARGINAL_RTOL)
    eig = (
        memo(("eig", array_key(A)), lambda: np.linalg.eigvals(A))
        if A.size
        else np.empty(0, complex)
    )
    substeps, step_rule = opts.substeps, None
    if auto and not opts.adaptive:  # an adaptive run sets its own step
        substeps, step_rule = auto_substeps(tab, eig, H, substeps)
    return _Computed(tab, H / substeps, substeps, step_rule, eig)


def _beyond_stability(tab: ButcherTableau, h: float, eig, A: np.ndarray, name: str) -> str:
    """The warning's words when ``h`` exceeds the method's stability limit, else ''.

    The trajectory grows iff the step map R(hA) amplifies a mode; the full
    root-finding for h_max runs only to word the warning (or when asked).
    """
    if memo(("stable", tab, h, array_key(A)), lambda: step_is_stable(tab, h, eig)):
        return ""
    message = (
        f"h = {h:.6g} s exceeds the stability limit {max_stable_step(tab, eig):.6g} s of "
        f"{tab.name} for system {name!r}: the response grows"
    )
    warnings.warn(message, DivergenceWarning, stacklevel=_stacklevel())
    return message


def _lti_run(tab, A, B, T, u_engine, x0, substeps, quiet: bool):
    """The LTI engine's states, and whether it cut a blow-up short
    (``quiet``: the step-size warning already told the user)."""
    if not quiet:
        return lti_states(tab, A, B, T, u_engine, x0, substeps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        return lti_states(tab, A, B, T, u_engine, x0, substeps)


def _simulate(ss, T, u_samples, x0, opts: _Options, auto: bool) -> _LinearRun:
    """Run the fixed-step method on a continuous-time StateSpace."""
    A, B = np.asarray(ss.A, dtype=float), np.asarray(ss.B, dtype=float)
    C, D = np.asarray(ss.C, dtype=float), np.asarray(ss.D, dtype=float)
    dt = checked_uniform_step(T)  # T passed check_time_grid in the caller
    H = dt if dt is not None else float(np.diff(T).max())
    computed = _linear_step(opts.tab, A, H, opts, auto)
    tab, substeps = opts.tab, computed.substeps
    if not computed.eigenvalues.size:  # a static gain: nothing to integrate
        y = D @ u_samples if u_samples.size else np.zeros((C.shape[0], T.size))
        computed.note = "the system has no states: y = D u, nothing was integrated"
        return _LinearRun(T, np.zeros((0, T.size)), y, u_samples, computed, True, "")
    if opts.adaptive:
        return _simulate_adaptive(A, B, C, D, (T, u_samples, x0), opts, computed)
    message = _beyond_stability(tab, H / substeps, computed.eigenvalues, A, ss.name)
    success = not message
    uniform = dt is not None
    # one look at the input: a zero input is the free response (no input scan, no D u)
    has_input = bool(u_samples.size) and bool(np.any(u_samples))
    if opts.engine == "lti" and not uniform:
        raise ValueError("engine='lti' needs a uniformly spaced T")
    lti = opts.engine == "lti" or (opts.engine == "auto" and uniform and success)
    if lti:
        x, cut = _lti_run(tab, A, B, T, u_samples if has_input else None, x0, substeps, not success)
        computed.steps = (T.size - 1) * substeps  # the engine computes every interval at once
        t, computed.nfev, ok = T[: x.shape[-1]], tab.stages * computed.steps, not cut
    else:
        sol = _generic(A, B, T, u_samples, x0, tab, substeps, warn=success)
        t, x, cut, ok = sol.t, sol.x, sol.message, sol.success
        computed.steps, computed.nfev = sol.steps, sol.nfev
    if not ok:
        success, message = False, "; ".join(filter(None, [message, cut]))
    u = u_samples[:, : t.size]
    with np.errstate(over="ignore", invalid="ignore"):
        y = C @ x + D @ u if has_input else C @ x
    # lti_states cuts before the first non-finite sample: _finalise need not look again
    return _LinearRun(t, x, y, u, computed, success, message, states_finite=lti)


def _simulate_adaptive(A, B, C, D, problem, opts: _Options, computed: _Computed) -> _LinearRun:
    """An embedded pair with step-size control on ``x' = A x + B u(t)``: the
    generic stepper, stopping at every sample where the input's slope changes."""
    T, u_samples, x0 = problem
    has_input = bool(u_samples.size) and bool(np.any(u_samples))
    breaks = slope_breakpoints(T, u_samples) if has_input else None
    rhs = _linear_rhs(A, B, T, u_samples)
    sol = integrate(rhs, T, x0, opts.tab, rtol=opts.rtol, atol=opts.atol, breakpoints=breaks)
    computed.record(sol, opts)
    u = u_samples[:, : sol.t.size]
    with np.errstate(over="ignore", invalid="ignore"):
        y = C @ sol.x + D @ u if has_input else C @ sol.x
    return _LinearRun(sol.t, sol.x, y, u, computed, sol.success, sol.message)


def _all_finite(v: np.ndarray) -> bool:
    """No NaN or inf in ``v``: its min and max propagate both, without a mask array."""
    if v.size == 0 or v.dtype == object:
        return True
    # one pass: a NaN or an inf makes the sum non-finite; a finite sum proves
    # every element finite, and only an overflowing sum needs the exact test
    with np.errstate(over="ignore", invalid="ignore"):
        total = v.sum()
    return bool(np.isfinite(total) or (np.isfinite(v.min()) and np.isfinite(v.max())))


def _finalise(resp: FixedStepResponse, states_finite: bool = False) -> FixedStepResponse:
    """The one response-level check: any NaN or inf makes ``success`` False.

    Every result passes here, whichever engine (LTI scan, generic stepper,
    python-control's difference equation) computed it. ``states_finite``: the
    engine has proven the states finite (the LTI engine's cut), so only the
    outputs are looked at.
    """
    bad = [
        name
        for name, v in (("outputs", resp.y), ("states", None if states_finite else resp.x))
        if v is not None and not _all_finite(np.asarray(v))
    ]
    if bad:
        where = np.asarray(resp.x if "states" in bad else resp.y)
        first = int(np.argmax(~np.isfinite(where).reshape(-1, where.shape[-1]).all(axis=0)))
        note = (
            f"the response's {' and '.join(bad)} hold NaN or inf "
            f"(first at t = {float(resp.t[first]):.6g} s)"
        )
        resp.success = False
        resp.message = "; ".join(filter(None, [resp.message, note]))
    return resp


def _wrap(data: control.TimeResponseData, **meta) -> FixedStepResponse:
    """A python-control result as a FixedStepResponse (no method applied)."""
    resp = FixedStepResponse.__new__(FixedStepResponse)
    resp.__dict__.update(data.__dict__)
    resp.__dict__.update(meta)
    return _finalise(resp)


# ---------------------------------------------------------------- systems


class _Layout(NamedTuple):
    """How the caller wants the result laid out, as python-control takes it."""

    params: dict | None
    transpose: bool
    return_x: bool | None
    squeeze: bool | None


def _response(sys, data, layout: _Layout, title: str, success, message, **labels):
    """A `FixedStepResponse` of ``sys``'s signals ``data = (t, y, x, u)``.

    ``labels``: the system's ``issiso``, ``output_labels`` and
    ``input_labels`` unless given (all three, when one output or input is
    kept), and python-control's trace keywords.
    """
    if "issiso" not in labels:  # the whole system's signals
        labels.update(
            issiso=sys.issiso(), output_labels=sys.output_labels, input_labels=sys.input_labels
        )
    return FixedStepResponse(
        *data,
        params=layout.params,
        state_labels=sys.state_labels,
        sysname=sys.name,
        title=title,
        transpose=layout.transpose,
        return_x=layout.return_x,
        squeeze=layout.squeeze,
        success=success,
        message=message or None,
        **labels,
    )


def _nonlinear_response(sys, T, U, X0, layout: _Layout, opts, auto):
    """The one place nonlinear systems go from the linear responses.

    python-control's `forced_response` (and so its initial and step
    responses) hands a `control.NonlinearIOSystem` to
    `control.input_output_response` with exactly these arguments; so does
    this module, to its fixed-step `input_output_response`.
    """
    return _io_response(sys, T, U, X0, layout, _IOOptions("T", None, opts, auto))


def _check_system(sys) -> None:
    """Refuse what python-control refuses, in its own words (its tests expect them)."""
    if not isinstance(sys, (control.StateSpace, control.TransferFunction)) and not (
        is_nonlinear_system(sys)
    ):
        raise TypeError(
            "Parameter `sys`: must be a `StateSpace` or `TransferFunction`, "
            f"got {type(sys).__name__}"
        )


def _as_statespace(sys) -> control.StateSpace:
    """A continuous TransferFunction as a StateSpace, keeping its name and signal names."""
    if isinstance(sys, control.StateSpace):
        return sys
    return control.ss(sys, name=sys.name)


def _discrete_note(sys) -> str:
    if sys.dt is None:
        kind, how = (
            "of unspecified timebase (dt=None)",
            "with the grid's spacing as its sample time",
        )
    else:
        kind, how = "discrete-time", f"(dt={sys.dt!r})"
    return (
        f"system {sys.name!r} is {kind}: "
        f"simulated by its own difference equation {how}, as python-control does; "
        "no fixed-step method was applied"
    )


def _each(sysdata, respond):
    """python-control's rule for every response: a list (or tuple) of systems
    gives a `control.TimeResponseList`, one response per system."""
    if isinstance(sysdata, (list, tuple)):
        return control.TimeResponseList(respond(s) for s in sysdata)
    return respond(sysdata)


def _time_grid(sysdata, T, T_num, is_step: bool):
    """``(T, auto)``: python-control's own default grid when T is None or a final time."""
    if T is None or np.asarray(T).size == 1:
        return compat.default_time_vector(sysdata, N=T_num, tfinal=T, is_step=is_step), True
    return T, False


_NONZERO_X0_FOR_TF = (
    "Non-zero initial condition given for transfer function system. "
    "Internal conversion to state space used; may not be consistent "
    "with given X0."
)


def _transfer_function_warnings(sys, X0, return_x) -> None:
    """python-control's warnings for a TransferFunction, word for word."""
    if not isinstance(sys, control.TransferFunction):
        return
    if return_x:
        warnings.warn(
            "return_x specified for a transfer function system. Internal "
            "conversion to state space used; results may meaningless.",
            stacklevel=_stacklevel(),
        )
    if np.any(np.asarray(X0) != 0):
        warnings.warn(_NONZERO_X0_FOR_TF, stacklevel=_stacklevel())


def _difference_equation(control_response, sys, T, U, X0, layout: _Layout, **keywords):
    """A discrete-time or ``dt=None`` system: python-control's own difference
    equation, by its ``control_response`` (`control.forced_response` or
    `control.input_output_response`, whose own ``keywords`` are passed on)."""
    data = control_response(
        sys, T, U, X0, params=layout.params, transpose=layout.transpose,
        squeeze=layout.squeeze, **keywords,
    )  # fmt: skip
    return _wrap(data, note=_discrete_note(sys))


def _forced(sys, T, U, X0, layout: _Layout, interpolate, opts, auto=False, inner=False):
    """`forced_response` for one system (``inner``: a step of another response,
    which checks the result itself)."""
    _check_system(sys)
    if is_nonlinear_system(sys):
        if interpolate:  # as python-control
            warnings.warn(
                "interpolation not supported for nonlinear I/O systems", stacklevel=_stacklevel()
            )
        return _nonlinear_response(sys, T, U, X0, layout, opts, auto)
    if layout.return_x is None:
        layout = layout._replace(return_x=control.config.defaults["forced_response.return_x"])
    if not control.isctime(sys, strict=True):
        return _difference_equation(
            _control_forced_response, sys, T, U, X0, layout,
            interpolate=interpolate, return_states=layout.return_x,
        )  # fmt: skip
    _transfer_function_warnings(sys, X0, layout.return_x)
    ss = _as_statespace(sys)
    run = _linear_run(ss, T, U, X0, layout.transpose, opts, auto)
    resp = _response(
        ss,
        (run.t, run.y, run.x, run.u),
        layout,
        _title("Forced", ss.name),
        run.success,
        run.message,
        plot_inputs=True,
        trace_types=["forced"],
    )
    resp = run.computed.stamp(resp)
    return resp if inner else _finalise(resp, run.states_finite)


def _linear_run(ss, T, U, X0, transpose, opts, auto) -> _LinearRun:
    """Check ``T``, ``U`` and ``X0`` for a continuous-time StateSpace and simulate it
    (`_simulate`): the run's record, which the responses wrap."""
    if T is None:
        raise ValueError("Parameter `T` is mandatory for continuous time systems.")
    T = np.asarray(T)
    if transpose:
        T = T.T
    if T.ndim == 2 and 1 in T.shape:
        T = T.reshape(-1)
    T = check_time_grid(T, "T")
    # states, outputs and inputs over T, with the engines' working copies
    n, p, m = ss.nstates, ss.noutputs, ss.ninputs
    check_memory(
        8.0 * T.size * (3 * n + 2 * p + m + 2),
        f"a fixed-step response of {ss.name!r} on {T.size} samples",
        "use fewer samples (a coarser T; substeps refine the step without storing it)",
    )
    x0 = check_initial_state(X0, ss.nstates, ss.state_labels)
    u = np.asarray(0.0 if U is None else U)
    if transpose and u.ndim == 2:
        u = u.T
    u = check_input_samples(u, ss.ninputs, T.size, ss.input_labels)
    return _simulate(ss, T, u, x0, opts, auto)


def _title(kind: str, name: str) -> str:
    """python-control's title, word for word (its plots and tests rely on it)."""
    return f"{kind} response for {name}"


def _combine(parts: list[FixedStepResponse]) -> tuple[_Computed, bool, str | None]:
    """How several traces (inputs of a step response) were computed, together:
    the last trace's method and step, their steps and evaluations summed, and
    whether all succeeded, with their distinct messages."""
    computed = _Computed.of(parts[-1])
    computed.steps = sum(p.steps for p in parts)
    computed.nfev = sum(p.nfev for p in parts)
    if computed.adaptive is not None:
        computed.adaptive.n_accepted = sum(p.n_accepted for p in parts)
        computed.adaptive.n_rejected = sum(p.n_rejected for p in parts)
    messages = []
    for p in parts:
        if p.message and p.message not in messages:
            messages.append(p.message)
    return computed, all(p.success for p in parts), "; ".join(messages) or None


# ---------------------------------------------------------------- public functions


def _with_aliases(kwargs: dict, **named) -> dict:
    """python-control's keyword processing: aliases, legacy names and their errors."""
    compat.process_time_response_kwargs(kwargs)
    values = {
        name: compat.process_time_response_param(name, value, kwargs, sigval=sigval)
        for name, (value, sigval) in named.items()
    }
    if kwargs:
        raise TypeError(f"unrecognized keyword(s): {', '.join(sorted(kwargs))}")
    return values


def _grid_arguments(sysdata, kwargs, grid, options, is_step: bool, positional: str, **named):
    """What initial, step and impulse responses share before simulating.

    python-control's keyword processing (`_with_aliases`) of ``grid =
    (timepts, timepts_num, return_states)`` and of ``named`` (each a value
    and its sentinel); no method in the positional ``positional``; the
    keyword-only ``options = (method, substeps, engine, rtol, atol)``; and the time
    grid, python-control's own when ``T`` is None or a final time.

    Returns
    -------
    (values, opts, T, auto)
    """
    timepts, timepts_num, return_states = grid
    v = _with_aliases(
        kwargs,
        timepts=(timepts, None),
        **named,
        return_states=(return_states, False),
        timepts_num=(timepts_num, None),
    )
    _not_a_method(v[positional], positional)
    opts = _Options(*options)
    T, auto = _time_grid(sysdata, v["timepts"], v["timepts_num"], is_step=is_step)
    return v, opts, T, auto


def forced_response(
    sysdata, timepts=None, inputs=0.0, initial_state=0.0, transpose=False, params=None,
    interpolate=False, return_states=None, squeeze=None,
    *, method="rk4", substeps: int = 1, engine="auto", rtol=None, atol=None, **kwargs,
):  # fmt: skip
    """Forced response computed by a fixed-step method.

    The same call as python-control 0.10.2's `control.forced_response`
    (every positional and keyword argument, the aliases ``T``, ``U``,
    ``X0``, ``return_x`` and the `control.config.defaults` it honours). For
    a continuous-time system the input is linear between its samples,
    python-control's own assumption, so the stage at time ``t + c_i h``
    sees ``u(t + c_i h)``:

    .. math::

        k_i = A\\Big(x + h\\sum_{j<i} a_{ij}k_j\\Big) + B\\,u(t + c_i h)

    Parameters
    ----------
    sysdata : StateSpace, TransferFunction, NonlinearIOSystem or list of them
        A list gives a `control.TimeResponseList`, one response per system.
        Discrete-time and ``dt=None`` systems are simulated by their own
        difference equation, as python-control does (no method applied;
        see the result's ``note``). A nonlinear system goes to
        `input_output_response`, as python-control's does (``engine`` does
        not apply to it).
    timepts (or T) : array_like
        Sample times [s], strictly increasing. Each interval is one step
        (or ``substeps`` steps); unlike python-control, a non-uniform grid
        is accepted and stepped interval by interval. Mandatory for
        continuous-time systems, as in python-control.
    inputs (or U) : array_like or float, default 0
        Input samples, shape ``(ninputs, len(T))`` or ``(len(T),)`` for
        one input; a number holds every input at that value.
    initial_state (or X0) : array_like or float, default 0
        Initial state; a number fills every state.
    transpose : bool, default False
        Inputs and outputs time-first (MATLAB's convention), as in control.
    params : dict, optional
        Stored in the result (linear systems have no parameters).
    interpolate : bool, default False
        For discrete-time systems, as in python-control; no effect otherwise.
    return_states (or return_x) : bool, optional
        Whether the result unpacks to ``(t, y, x)``; default
        ``control.config.defaults['forced_response.return_x']``.
    squeeze : bool, optional
        As in python-control.
    method : str or ButcherTableau, default ``'rk4'``, keyword-only
        ``'euler'``, ``'midpoint'``, ``'heun'``, ``'rk4'`` or a tableau.
    substeps : int, default 1, keyword-only
        Steps per interval of ``T``.
    engine : {'auto', 'lti', 'generic'}, default 'auto', keyword-only
        How the method's trajectory is computed. ``'lti'``: the step map
        ``x_{k+1} = R(hA) x_k + Γ₀u_k + Γ₁u_{k+1}`` solved by a blocked scan
        (`qc_control.numerics.lti`), no Python loop per step; needs a uniform ``T``.
        ``'generic'``: `qc_control.numerics.integrate`, one step at a time. The two
        agree to rounding (1e-12 relative). ``'auto'`` uses ``'lti'`` on a
        uniform grid within the stability limit, ``'generic'`` otherwise
        (it stops a blow-up at its first non-finite sample).
    rtol, atol : float, optional, keyword-only
        With an embedded pair (``'heun_euler'``, ``'bogacki_shampine'``,
        ``'dormand_prince'``), step adaptively to these tolerances (either
        one given; the other takes scipy's default, rtol 1e-3 or atol 1e-6;
        atol may be one per state) with the standard controller
        (`qc_control.numerics.adaptive`, scipy's constants and first step).
        No step crosses a sample of ``U`` where the input's slope changes,
        so a short pulse on a long flat input is never stepped over; the
        outputs at ``T`` between step ends are the pair's dense output.
        The result then has ``accepted_times``, ``n_accepted``,
        ``n_rejected`` and ``nfev``; ``engine`` must not be ``'lti'`` and
        ``substeps`` must be 1. A tableau without ``b_hat`` raises a
        ValueError.

    Returns
    -------
    FixedStepResponse or control.TimeResponseList
        With outputs ``y = C x + D u``, the inputs as given, and the
        ``method``, ``h``, ``substeps``, ``nfev`` that produced them. If
        ``h`` exceeds the method's stability limit a `DivergenceWarning` is
        issued and ``success`` is False; any NaN or inf also makes
        ``success`` False.

    Examples
    --------
    A 5 cm road step at t = 0.5 s; the body settles within 20 s
    (its mode decays as e^{-0.46 t}):

    >>> import numpy as np, qc_control as qc
    >>> T = np.linspace(0, 20, 2001)
    >>> r = qc.forced_response(qc.quarter_car(road=True), T, np.where(T >= 0.5, 0.05, 0.0))
    >>> round(float(r.outputs[0, -1]), 3)   # the body ends up 5 cm higher
    0.05
    """
    v = _with_aliases(
        kwargs,
        timepts=(timepts, None),
        inputs=(inputs, 0.0),
        initial_state=(initial_state, 0.0),
        return_states=(return_states, None),
    )
    _not_a_method(transpose, "transpose")
    opts = _Options(method, substeps, engine, rtol, atol)
    T, U, X0 = v["timepts"], v["inputs"], v["initial_state"]
    layout = _Layout(params, transpose, v["return_states"], squeeze)
    return _each(sysdata, lambda s: _forced(s, T, U, X0, layout, interpolate, opts))


def initial_response(
    sysdata, timepts=None, initial_state=0, output_indices=None, timepts_num=None,
    params=None, transpose=False, return_states=False, squeeze=None,
    *, method="rk4", substeps: int = 1, engine="auto", rtol=None, atol=None, **kwargs,
):  # fmt: skip
    """Initial-condition response computed by a fixed-step method.

    The same call as python-control 0.10.2's `control.initial_response`;
    for a continuous-time system the trajectory is
    ``x_{n+1} = x_n + h Σ b_i k_i`` of the chosen method rather than the
    exact ``e^{Ah} x_n``.

    Parameters
    ----------
    sysdata : StateSpace, TransferFunction or list of them
        As in `forced_response`.
    timepts (or T) : array_like or float, optional
        Output times [s], strictly increasing; or a final time; or None.
        Given as an array, each interval is one step (or ``substeps``
        steps). None or a final time: the output grid is python-control's
        own (``control.timeresp._default_time_vector``: the final time
        from the slowest relevant mode, at most 5000 points), and each
        interval is split into the fewest substeps whose step ``h`` meets
        `auto_step`'s rule (the result's ``h``, ``substeps`` and
        ``step_rule`` say what was chosen).
    initial_state (or X0) : array_like or float, default 0
        Initial state, shape ``(nstates,)``; a number fills every state.
    output_indices (or output) : int, optional
        Keep only this output.
    timepts_num (or T_num) : int, optional
        Number of output times when ``T`` is None or a final time.
    params, transpose, squeeze
        As in python-control.
    return_states (or return_x) : bool, default False
        Whether the result unpacks to ``(t, y, x)``.
    method, substeps, engine, rtol, atol : keyword-only
        As in `forced_response`. With an automatic grid, ``substeps`` is a
        lower bound.

    Returns
    -------
    FixedStepResponse or control.TimeResponseList
        A `control.TimeResponseData` with the system's labels, outputs
        ``y = C x``, and ``method``, ``h``, ``nfev``. If ``h`` exceeds the
        method's stability limit a `DivergenceWarning` is issued and
        ``success`` is False; if the state overflows, the response stops
        at the last finite sample.

    Notes
    -----
    Midpoint and Heun give the same free response: on ``x' = Ax`` both
    steps are ``(I + hA + h²A²/2) x``. Under an input they still agree
    whenever the input is linear within each step, as python-control's
    sampled inputs are: Midpoint's ``u(t + h/2)`` equals Heun's
    ``(u(t) + u(t + h))/2``. They differ on nonlinear systems and on inputs
    that curve within a step (see `qc_control.numerics.integrate`).

    Examples
    --------
    >>> import numpy as np, control, qc_control as qc
    >>> sys = qc.quarter_car()
    >>> T = np.linspace(0, 10, 10001)
    >>> exact = control.initial_response(sys, T, [0, 0, 0.05, 0])
    >>> rk4 = qc.initial_response(sys, T, [0, 0, 0.05, 0], method="rk4")
    >>> bool(np.max(abs(rk4.outputs[0] - exact.outputs[0])) < 1e-8)
    True
    """
    v, opts, T, auto = _grid_arguments(
        sysdata, kwargs, (timepts, timepts_num, return_states),
        (method, substeps, engine, rtol, atol),
        False, "output_indices",
        initial_state=(initial_state, 0.0), output_indices=(output_indices, None),
    )  # fmt: skip
    X0, output = v["initial_state"], v["output_indices"]
    layout = _Layout(params, transpose, v["return_states"], squeeze)
    return _each(sysdata, lambda s: _initial(s, T, auto, X0, output, layout, opts))


def _initial(sys, T, auto, X0, output, layout: _Layout, opts):
    if isinstance(sys, control.StateSpace) and control.isctime(sys, strict=True):
        # the fast path: the run's arrays go into one response, not two
        run = _linear_run(sys, T, 0, X0, False, opts, auto)
    else:
        inner = _Layout(layout.params, False, None, None)
        r = _forced(sys, T, 0, X0, inner, False, opts, auto, inner=True)
        run = _LinearRun(r.t, r.x, r.y, r.u, _Computed.of(r), r.success, r.message)
    resp = _response(
        sys,
        (run.t, run.y if output is None else run.y[output], run.x, None),
        layout,
        _title("Initial", sys.name),
        run.success,
        run.message,
        issiso=sys.issiso() or output is not None,
        output_labels=sys.output_labels if output is None else sys.output_labels[output],
        input_labels=None,
        trace_types=["initial"],
    )
    return _finalise(run.computed.stamp(resp), run.states_finite)


def _single_index(index, what: str):
    """python-control's rule: one input/output index, not a list or a name."""
    if isinstance(index, (list, tuple)):
        if len(index) > 1:
            raise NotImplementedError(f"list of {what} indices not allowed")
        return index[0]
    if isinstance(index, str):
        raise NotImplementedError(f"named {what}s not allowed")
    return index


def _traces(kind, sys, T, auto, X0_of, U_of, inputs, output, opts, params):
    """Simulate each selected input of ``sys``; python-control's layout (output, input, time)."""
    ninputs = sys.ninputs if inputs is None else 1
    noutputs = sys.noutputs if output is None else 1
    yout = np.empty((noutputs, ninputs, T.size))
    xout = np.empty((sys.nstates, ninputs, T.size))
    # python-control leaves the impulse's inputs undefined (None): it has no samples
    fill = None if kind == "impulse" else 0.0
    uout = np.full((ninputs, ninputs, T.size), fill, dtype=object if fill is None else float)
    parts, labels = [], []
    for i in range(sys.ninputs):
        if isinstance(inputs, int) and i != inputs:
            continue
        labels.append(f"From {sys.input_labels[i]}")
        U = U_of(i)
        r = _forced(sys, T, U, X0_of(i), _Layout(params, False, None, True), False, opts, auto)
        if r.t.size != T.size:  # the generic engine cut a blow-up short: pad
            r = _padded(r, T)
        k = i if inputs is None else 0
        yout[:, k, :] = r.y if output is None else r.y[output]
        xout[:, k, :] = r.x
        uout[:, k, :] = U if inputs is None else U[i]
        parts.append(r)
    return yout, xout, uout, parts, labels


def _padded(r: FixedStepResponse, T: np.ndarray) -> FixedStepResponse:
    """A cut-short response on the full grid, NaN after the cut (for stacking traces)."""
    n = r.t.size
    for name in ("y", "x"):
        v = getattr(r, name)
        full = np.full(v.shape[:-1] + (T.size,), np.nan)
        full[..., :n] = v
        setattr(r, name, full)
    r.t = T
    return r


def _as_lti_statespace(sys):
    """python-control converts a TransferFunction before a step or impulse response."""
    if isinstance(sys, control.TransferFunction):
        return control.ss(sys, name=sys.name)
    return sys


def step_response(
    sysdata, timepts=None, initial_state=0.0, input_indices=None, output_indices=None,
    timepts_num=None, transpose=False, return_states=False, squeeze=None, params=None,
    *, method="rk4", substeps: int = 1, engine="auto", rtol=None, atol=None, **kwargs,
):  # fmt: skip
    """Step response computed by a fixed-step method.

    The same call as python-control 0.10.2's `control.step_response`: a
    unit step on each input in turn (or only on ``input``), all others 0,
    each trace a `forced_response` of the chosen method. The result is
    indexed (output, input, time), as python-control's.

    Parameters
    ----------
    sysdata : StateSpace, TransferFunction or list of them
    timepts (or T) : array_like or float, optional
        As in `initial_response` (automatic grid when None or a final time).
    initial_state (or X0) : array_like or float, default 0
    input_indices (or input), output_indices (or output) : int, optional
        Keep only this input / output.
    timepts_num (or T_num) : int, optional
    transpose, return_states (or return_x), squeeze, params
        As in python-control.
    method, substeps, engine, rtol, atol : keyword-only
        As in `forced_response`.

    Returns
    -------
    FixedStepResponse or control.TimeResponseList

    Examples
    --------
    >>> import control, qc_control as qc
    >>> r = qc.step_response(control.tf([1], [1, 2, 1]), 20.0)   # final time 20 s
    >>> round(float(r.outputs[-1]), 6), r.method.name, r.substeps
    (1.0, 'rk4', 2)
    """
    v, opts, T, auto = _grid_arguments(
        sysdata, kwargs, (timepts, timepts_num, return_states),
        (method, substeps, engine, rtol, atol),
        True, "input_indices", initial_state=(initial_state, 0.0),
        input_indices=(input_indices, None), output_indices=(output_indices, None),
    )  # fmt: skip
    T = np.atleast_1d(T).reshape(-1)
    args = (v["initial_state"], v["input_indices"], v["output_indices"])
    layout = _Layout(params, transpose, v["return_states"], squeeze)
    return _each(sysdata, lambda s: _step(s, T, auto, *args, layout, opts))


def _step(sys, T, auto, X0, inputs, output, layout: _Layout, opts):
    if isinstance(sys, control.TransferFunction) and np.any(np.asarray(X0) != 0):
        warnings.warn(_NONZERO_X0_FOR_TF, stacklevel=_stacklevel())
    _check_system(sys)
    sys = _as_lti_statespace(sys)
    inputs = _single_index(inputs, "input")
    output = _single_index(output, "output")

    def U_of(i):
        U = np.zeros((sys.ninputs, T.size))
        U[i, :] = 1.0
        return U

    traces = _traces("step", sys, T, auto, lambda i: X0, U_of, inputs, output, opts, layout.params)
    return _multi_trace("Step", sys, T, traces, inputs, output, layout)


def _multi_trace(kind, sys, T, traces, inputs, output, layout: _Layout):
    """One response of the traces `_traces` computed, laid out as asked."""
    yout, xout, uout, parts, labels = traces
    computed, success, message = _combine(parts) if parts else (None, True, None)
    resp = _response(
        sys,
        (T if not parts else parts[-1].t, yout, xout, uout),
        layout,
        _title(kind, sys.name),
        success,
        message,
        issiso=sys.issiso() or (inputs is not None and output is not None),
        output_labels=sys.output_labels if output is None else sys.output_labels[output],
        input_labels=sys.input_labels if inputs is None else sys.input_labels[inputs],
        trace_labels=labels,
        trace_types=[kind.lower()] * len(labels),
        plot_inputs=False,
    )
    return _finalise(resp if computed is None else computed.stamp(resp))


def impulse_response(
    sysdata, timepts=None, input_indices=None, output_indices=None, timepts_num=None,
    transpose=False, return_states=False, squeeze=None,
    *, method="rk4", substeps: int = 1, engine="auto", rtol=None, atol=None, **kwargs,
):  # fmt: skip
    """Impulse response computed by a fixed-step method.

    The same call as python-control 0.10.2's `control.impulse_response`.
    For a continuous-time system the impulse on input ``i`` becomes the
    initial state ``x(0) = B[:, i]`` with no input, as python-control
    does; a discrete-time system gets a unit-area pulse ``1/dt`` at the
    first sample, simulated by its difference equation.

    Parameters
    ----------
    sysdata, timepts (or T), input_indices (or input), output_indices (or output)
        As in `step_response`; there is no initial state (the impulse sets it).
    timepts_num (or T_num), transpose, return_states (or return_x), squeeze
        As in `step_response`.
    method, substeps, engine, rtol, atol : keyword-only
        As in `forced_response`.

    Returns
    -------
    FixedStepResponse or control.TimeResponseList
        Indexed (output, input, time), as python-control's.

    Examples
    --------
    >>> import control, qc_control as qc
    >>> r = qc.impulse_response(control.tf([1], [1, 1]), [0.0, 0.5, 1.0], substeps=20)
    >>> [round(float(y), 6) for y in r.outputs]   # e^{-t}
    [1.0, 0.606531, 0.367879]
    """
    v, opts, T, auto = _grid_arguments(
        sysdata, kwargs, (timepts, timepts_num, return_states),
        (method, substeps, engine, rtol, atol),
        False, "input_indices",
        input_indices=(input_indices, None), output_indices=(output_indices, None),
    )  # fmt: skip
    T = np.atleast_1d(T).reshape(-1)
    inputs, output = v["input_indices"], v["output_indices"]
    layout = _Layout(None, transpose, v["return_states"], squeeze)
    return _each(sysdata, lambda s: _impulse(s, T, auto, inputs, output, layout, opts))


def _impulse(sys, T, auto, inputs, output, layout: _Layout, opts):
    if not isinstance(sys, control.LTI):
        raise ValueError("system must be LTI system for impulse response")
    _check_system(sys)
    sys = _as_lti_statespace(sys)
    continuous = control.isctime(sys)
    if continuous and np.any(np.asarray(sys.D) != 0):
        warnings.warn(
            "System has direct feedthrough: `D != 0`. The infinite impulse at "
            "`t=0` does not appear in the output.\nResults may be meaningless!",
            stacklevel=_stacklevel(),
        )
    inputs = _single_index(inputs, "input")
    output = _single_index(output, "output")

    def X0_of(i):
        return np.asarray(sys.B)[:, i] if continuous else 0

    def U_of(i):
        U = np.zeros((sys.ninputs, T.size))
        if not continuous:
            U[i, 0] = 1.0 / sys.dt  # unit area (dt=True counts as 1)
        return U

    traces = _traces("impulse", sys, T, auto, X0_of, U_of, inputs, output, opts, None)
    return _multi_trace("Impulse", sys, T, traces, inputs, output, layout)


# ---------------------------------------------------------------- nonlinear systems

#: ``solve_ivp`` methods: python-control's ``method=`` names one of these.
_SOLVE_IVP_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")


def _check_fixed_step_method(method):
    """A solve_ivp method name where qc expects a tableau: say what ``method`` means here."""
    if isinstance(method, str) and method.strip().upper() in {
        m.upper() for m in _SOLVE_IVP_METHODS
    }:
        raise ValueError(
            f"method={method!r} is a scipy.integrate.solve_ivp method, which "
            "control.input_output_response takes; qc_control steps at a fixed step: "
            f"method must be one of {sorted(TABLEAUS)} or a ButcherTableau (RK45's pair is "
            "method='dormand_prince' with rtol/atol, RK23's 'bogacki_shampine')"
        )
    return method


def _nonlinear_inputs(sys, T: np.ndarray, U) -> np.ndarray:
    """``U`` as a finite real ``(ninputs, len(T))`` array, by python-control's rules.

    As `control.input_output_response`: a list whose length is not
    ``len(T)`` is a stack of inputs, each a number or vector broadcast over
    time or a time series; otherwise ``(len(T),)`` or ``(ninputs, len(T))``.
    """
    ntimepts = T.size
    if isinstance(U, (tuple, list)) and len(U) != ntimepts:
        rows = []
        for i, u in enumerate(U):
            u = np.array(u)
            if u.ndim == 0 or (u.ndim == 1 and u.shape[0] != ntimepts):
                u = np.outer(u, np.ones_like(T))
            elif not (u.ndim in (1, 2) and u.shape[-1] == ntimepts):
                raise ValueError(f"Input element {i} has inconsistent shape")
            rows.append(u)
        U = np.vstack(rows)
    ninputs = sys.ninputs
    legal = [(ntimepts,), (1, ntimepts)] if ninputs in (None, 1) else [(ninputs, ntimepts)]
    U = compat.check_convert_array(U, legal, "Parameter `U`: ", squeeze=False)
    if np.iscomplexobj(U):
        raise ValueError("U must be real: the fixed-step engines integrate real states")
    U = np.asarray(U, dtype=float).reshape(-1, ntimepts)
    if not np.all(np.isfinite(U)):
        first = np.argwhere(~np.isfinite(U))[0].tolist()
        raise ValueError(f"U must be finite; first bad sample at index {first}")
    return U


def _nonlinear_state(sys, X0) -> np.ndarray:
    """``X0`` by python-control's rules (lists are stacked, short ones zero-padded), checked."""
    x0, _ = compat.process_vector_argument(X0, "X0", sys.nstates)
    raw = np.asarray(x0)
    if raw.dtype.kind == "c":
        raise ValueError(
            f"X0 must be real: the fixed-step engines integrate real states, got {raw.tolist()}"
        )
    x0 = np.asarray(raw, dtype=float).reshape(-1)
    if x0.size != sys.nstates:
        raise ValueError(
            f"X0 must have {sys.nstates} elements for system {sys.name!r}, got {x0.size}"
        )
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"X0 must be finite, got {x0.tolist()}")
    return x0


def _linearised_eigenvalues(sys, t0: float, x0, u0, params):
    """``(eigenvalues, None)`` of the Jacobian at the initial point, or ``(None, why)``.

    The Jacobian is python-control's own (`NonlinearIOSystem.linearize`:
    forward differences with ``eps = 1e-6``, ``n + m + 1`` evaluations of
    the right-hand side).
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lin = sys.linearize(x0, u0, t=t0, params=params)
        A = np.asarray(lin.A, dtype=float)
    except Exception as exc:  # a right-hand side may refuse a perturbed point
        return None, f"{type(exc).__name__}: {exc}"
    if not np.all(np.isfinite(A)):
        return None, "the Jacobian at the initial point is not finite"
    return np.linalg.eigvals(A), None


def _step_grid(T: np.ndarray, substeps: int) -> np.ndarray:
    """Every step's start time: each interval of ``T`` split into ``substeps`` equal steps."""
    if substeps == 1:
        return T
    frac = np.arange(substeps) / substeps
    inner = (T[:-1, None] + np.diff(T)[:, None] * frac).reshape(-1)
    return np.append(inner, T[-1])


def _evaluation_times(t_eval, T: np.ndarray) -> np.ndarray:
    """``t_eval`` as a sorted array within ``[T[0], T[-1]]`` (solve_ivp's rule)."""
    try:
        te = np.asarray(t_eval, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"evaluation_times must be times [s], got {t_eval!r}") from None
    if te.size == 0 or not np.all(np.isfinite(te)):
        raise ValueError(f"evaluation_times must be finite times [s], got {te.tolist()}")
    if np.any(te < T[0]) or np.any(te > T[-1]):
        raise ValueError(
            f"evaluation_times must lie within [T[0], T[-1]] = [{T[0]:g}, {T[-1]:g}] s, "
            f"got values in [{te.min():g}, {te.max():g}]"
        )
    if np.any(np.diff(te) < 0):
        raise ValueError("evaluation_times must be sorted in increasing order")
    return te


def _event_function(sys, events):
    """``(g(t, x, u, params), labels)`` from ``events``, or ``(None, ())``."""
    if events is None or events is False:
        return None, ()
    if events is True:
        g = getattr(sys, "switching", None)
        if g is None:
            raise ValueError(
                f"events=True needs a system with switching functions (sys.switching, as "
                f"qc.nonlinear_quarter_car gives); system {sys.name!r} has none: pass a "
                "callable events(t, x, u, params) instead"
            )
        return g, tuple(getattr(sys, "switching_labels", ()))
    if callable(events):
        return events, ()
    raise TypeError(
        f"events must be None, True or a callable events(t, x, u, params), got {events!r}"
    )


class _IOOptions(NamedTuple):
    """`input_output_response`'s fixed-step options for one system."""

    t_eval: object  # 'T', None or times [s]
    max_step: float | None
    opts: _Options
    auto: bool  # the grid was chosen automatically: the step follows auto_step
    events: object = None
    fast: bool = True


class _IOProblem(NamedTuple):
    """A continuous-time nonlinear system's checked arguments."""

    T: np.ndarray
    u_samples: np.ndarray  # (ninputs, len(T))
    x0: np.ndarray
    noutputs: int
    params: dict | None  # the caller's, passed to the switching functions as to control's


class _IOTrajectory(NamedTuple):
    """The stepped states at the output times, and how they were stepped."""

    t: np.ndarray
    x: np.ndarray
    keep: np.ndarray  # which samples of the stepped grid are output
    computed: _Computed
    success: bool
    message: str
    t_events: np.ndarray
    event_labels: tuple[str, ...]
    fused: FusedSteps | None  # whose nonlinear outputs were kept from each step's first stage
    compiled: CompiledInterconnect | None
    x_events: np.ndarray | None = None  # (n, k): the state at each of t_events


def _io_problem(sys, T, U, X0, params) -> _IOProblem:
    """``T``, ``U`` and ``X0`` checked by python-control's rules, and the outputs' count."""
    if T is None or np.ndim(T) == 0:
        raise ValueError(
            f"T must be an array of times for a nonlinear system, got {T!r} "
            "(python-control has no default grid for it either)"
        )
    T = check_time_grid(np.asarray(T, dtype=float).reshape(-1), "T")
    u_samples = _nonlinear_inputs(sys, T, U)
    x0 = _nonlinear_state(sys, X0)
    compat.update_params(sys, params)  # as control does, before the output function is first called
    if sys.outfcn is None:
        noutputs = x0.size if sys.noutputs is None else sys.noutputs
    else:
        noutputs = np.shape(compat.output_function(sys)(T[0], x0, u_samples[:, 0]))[0]
    if sys.noutputs is not None and sys.noutputs != noutputs:
        raise RuntimeError(
            f"inconsistent size of outputs; system specified {sys.noutputs}, "
            f"output function returned {noutputs}"
        )
    return _IOProblem(T, u_samples, x0, noutputs, params)


def _io_step(sys, prob: _IOProblem, params, io: _IOOptions) -> _Computed:
    """The method, substeps and step rule (``h`` is set by `_io_grid`): `auto_step`
    on the linearisation at the initial point with an automatic grid, and
    ``max_step``'s bound."""
    tab, substeps, step_rule, eig = io.opts.tab, io.opts.substeps, None, None
    H = float(np.diff(prob.T).max())
    if io.opts.adaptive:  # the steps follow the error estimate; max_step goes to the controller
        if io.max_step is not None:
            _check_max_step(io.max_step)
        return _Computed(tab, None, 1, None, None)
    if io.auto and prob.x0.size:
        eig, why = _linearised_eigenvalues(
            sys, float(prob.T[0]), prob.x0, prob.u_samples[:, 0], params
        )
        if eig is None:
            step_rule = f"none: the system could not be linearised at the initial point ({why})"
        else:
            substeps, rule = auto_substeps(tab, eig, H, substeps)
            step_rule = f"{rule}, on the linearisation at the initial point"
    max_step = io.max_step
    by_max_step = 0
    if max_step is not None:
        by_max_step = substeps_for(H, _check_max_step(max_step))
        substeps = max(substeps, by_max_step)
    _check_io_steps(prob, io, substeps, by_max_step)
    compat.update_params(sys, params)  # linearize may have reset them
    return _Computed(tab, None, substeps, step_rule, eig)


def _check_max_step(max_step) -> float:
    """``solve_ivp_kwargs['max_step']`` as a step [s], refused unless a finite number > 0."""
    return positive("max_step", max_step, "s", description="the largest step")


def _check_io_steps(prob: _IOProblem, io: _IOOptions, substeps: int, by_max_step: int) -> None:
    """Refuse ``substeps`` (or the ``max_step`` that set them, ``by_max_step``)
    whose step tables would not fit, before any is built.

    Without events, `qc_control.numerics.integrate.integrate` holds a block of
    `STEP_BLOCK` intervals' step times and states (about ``48 + 8n`` B a step);
    with ``evaluation_times`` None or an array every step is a point of the
    stepped grid, so the whole run's times, states and outputs are held
    (``48 + 16(n + p)`` B a step: 184 B measured for the nonlinear car). With
    events the steps are taken one by one, holding nothing per step.
    """
    if io.events is not None:
        return
    cause = (
        f"max_step = {io.max_step!r} s: substeps = {substeps}" if by_max_step == substeps else ""
    )
    n, p = prob.x0.size, prob.noutputs
    if not isinstance(io.t_eval, str):  # None or times: every step is a grid point
        per_step, what = 48 + 16 * (n + p), "the times, states and outputs at every step"
        intervals = prob.T.size - 1
    else:
        per_step, what = 48 + 8 * n, "the step times and states of a block"
        intervals = min(prob.T.size - 1, STEP_BLOCK)
    check_step_memory(intervals, substeps, per_step, what, cause)


def _io_grid(T: np.ndarray, substeps: int, t_eval, adaptive: bool = False):
    """``(grid, at, n_sub)``: the times stepped between, the indices of the output
    times in it (None: all of them), and the steps per interval of ``grid``.

    An adaptive run's grid is only where it reports (its dense output): ``T``,
    or the evaluation times with ``T``'s ends."""
    if isinstance(t_eval, str) and t_eval == "T":
        return T, None, substeps
    if adaptive:
        if t_eval is None:
            raise ValueError(
                "evaluation_times=None (every step) is not available with rtol/atol: an "
                "adaptive run reports at 'T' or at given times; its steps are in the "
                "result's accepted_times"
            )
        te = _evaluation_times(t_eval, T)
        grid = np.union1d(T[[0, -1]], te)
        return grid, np.searchsorted(grid, te), 1
    grid = _step_grid(T, substeps)
    if t_eval is None:  # solve_ivp's own points: here, every step
        return grid, None, 1
    te = _evaluation_times(t_eval, T)
    grid = np.union1d(grid, te)
    return grid, np.searchsorted(grid, te), 1


def _io_static(prob: _IOProblem, grid, at, computed: _Computed) -> _IOTrajectory:
    """A static system: nothing to integrate, its output function is evaluated."""
    computed.note = (
        "the system has no states: its output function was evaluated, nothing integrated"
    )
    t_out = grid if at is None else grid[at]
    x = np.zeros((0, t_out.size))
    keep = np.empty(0, dtype=int)  # no stepped grid
    return _IOTrajectory(t_out, x, keep, computed, True, "", np.empty(0), (), None, None)


def _io_integrate(sys, prob: _IOProblem, grid, at, n_sub, computed: _Computed, io, u_of_t):
    """Step the states over ``grid``: the fused interconnection, the compiled
    right-hand side or ``sys._rhs``; with events, each kink stepped to exactly."""
    tab, T, u_samples, x0 = _method_of(computed), prob.T, prob.u_samples, prob.x0
    if io.opts.adaptive:
        return _io_adaptive(sys, prob, grid, at, computed, io, u_of_t)
    t_events: np.ndarray = np.empty(0)
    x_events: np.ndarray | None = None
    event_labels: tuple[str, ...] = ()
    compiled = compile_interconnect(sys) if io.fast else None
    fused = None
    rhs = compat.state_derivative(sys)

    def f(t, x):
        return rhs(t, x, u_of_t(t))

    g, labels = _event_function(sys, io.events)
    if compiled is not None:  # the interconnection solved once (qc_control.numerics.interconnect)
        stages = stage_times(grid, tab, substeps=n_sub)
        dt = uniform_step(grid)
        if g is None and dt is not None and not tab.implicit:  # fused: explicit stages only
            fused = compiled.fused(tab, dt / n_sub, stages, (T, u_samples), n_sub)
        if fused is None:
            f = compiled.make_rhs(u_of_t, (T, u_samples), stages)
    if fused is not None:  # whole steps at once (qc_control.numerics.interconnect.FusedSteps)
        sol = integrate_stepper(fused.stepper(), grid, x0, tab, substeps=n_sub)
    elif g is None:
        sol = integrate(f, grid, x0, tab, substeps=n_sub)
    else:
        current = compat.current_params(sys, prob.params or {})

        def switching(t, x):
            return g(t, x, u_of_t(t), current)

        sol = integrate(f, grid, x0, tab, substeps=n_sub, events=switching)
        t_events, x_events = sol.t_events, sol.x_events
        event_labels = tuple(
            labels[i] if i < len(labels) else str(i) for i in sol.i_events.tolist()
        )
    computed.steps, computed.nfev = sol.steps, sol.nfev
    keep = np.arange(sol.t.size) if at is None else at[at < sol.t.size]
    t_out, x = (sol.t, sol.x) if at is None else (sol.t[keep], sol.x[:, keep])
    return _IOTrajectory(
        t_out, x, keep, computed, sol.success, sol.message, t_events, event_labels, fused,
        compiled, x_events,
    )  # fmt: skip


def _io_adaptive(sys, prob: _IOProblem, grid, at, computed: _Computed, io, u_of_t):
    """An embedded pair with step-size control on the system's right-hand side
    (the interconnection solved once where it can be), stopping at every
    sample where the input's slope changes; the outputs at ``grid`` by the
    pair's dense output."""
    if io.events is not None:
        raise ValueError(
            f"events={io.events!r} with rtol/atol: an adaptive run does not locate "
            "events; use a fixed-step method for events"
        )
    compiled = compile_interconnect(sys) if io.fast else None
    if compiled is not None:
        f = compiled.make_rhs(u_of_t)
    else:
        rhs = compat.state_derivative(sys)

        def f(t, x):
            return rhs(t, x, u_of_t(t))

    sol = integrate(
        f, grid, prob.x0, computed.method, rtol=io.opts.rtol, atol=io.opts.atol,
        max_step=math.inf if io.max_step is None else float(io.max_step),
        breakpoints=slope_breakpoints(prob.T, prob.u_samples),
    )  # fmt: skip
    computed.record(sol, io.opts)
    keep = np.arange(sol.t.size) if at is None else at[at < sol.t.size]
    t_out, x = (sol.t, sol.x) if at is None else (sol.t[keep], sol.x[:, keep])
    return _IOTrajectory(
        t_out, x, keep, computed, sol.success, sol.message, np.empty(0), (), None, compiled
    )


def _io_signals(sys, prob: _IOProblem, traj: _IOTrajectory, u_of_t):
    """The inputs and outputs at the output times, from the stepped states."""
    t_out, x, T = traj.t, traj.x, prob.T
    u = np.empty((prob.u_samples.shape[0], t_out.size))
    y = np.empty((prob.noutputs, t_out.size))
    with np.errstate(over="ignore", invalid="ignore"):
        if t_out.size == T.size and np.array_equal(t_out, T):
            u[:] = prob.u_samples  # the samples themselves (u_of_t returns them at T)
        else:
            for i, t in enumerate(t_out.tolist()):
                u[:, i] = u_of_t(t)
        fused, compiled = traj.fused, traj.compiled
        if fused is not None:  # the nonlinear outputs kept from each step's first stage
            y[:] = fused.compiled.outputs_known(
                x, u, fused.nonlinear_outputs(traj.keep, t_out, x, u)
            )
        elif compiled is not None and prob.x0.size:
            y[:] = compiled.outputs(t_out, x, u)
        else:
            out = compat.output_function(sys)
            for i, t in enumerate(t_out.tolist()):
                y[:, i] = out(t, x[:, i], u[:, i])
    return u, y


def _io_response(sys, T, U, X0, layout: _Layout, io: _IOOptions):
    """`input_output_response` for one system: the arguments, the step, the
    trajectory, then its signals as a `FixedStepResponse`."""
    if not isinstance(sys, control.NonlinearIOSystem):
        raise TypeError(f"System of type {type(sys)} not valid")
    if control.isdtime(sys, strict=True):
        return _difference_equation(
            _control_io_response, sys, T, U, X0, layout,
            return_x=layout.return_x, evaluation_times=io.t_eval,
        )  # fmt: skip
    if isinstance(sys, ClockedLoop):  # a controller on a clock: steps land on every tick
        return _clocked_response(sys, T, U, X0, layout, io)
    prob = _io_problem(sys, T, U, X0, layout.params)
    u_of_t = linear_input(prob.T, prob.u_samples)  # python-control's interpolation of the samples
    computed = _io_step(sys, prob, layout.params, io)
    grid, at, n_sub = _io_grid(prob.T, computed.substeps, io.t_eval, io.opts.adaptive)
    computed.h = float(np.diff(grid).max()) * (1 if n_sub == 1 else 1 / n_sub)
    if prob.x0.size == 0:
        traj = _io_static(prob, grid, at, computed)
    else:
        traj = _io_integrate(sys, prob, grid, at, n_sub, computed, io, u_of_t)
    u, y = _io_signals(sys, prob, traj, u_of_t)
    success, message = traj.success, traj.message
    if prob.x0.size and not io.opts.adaptive:
        beyond = _beyond_stability_along(sys, traj, u, u_of_t, computed.h)
        if beyond:
            success, message = False, "; ".join(filter(None, [beyond, message]))
    resp = _response(
        sys,
        (traj.t, y, traj.x if prob.x0.size else None, u),
        layout,
        "Input/output response for " + sys.name,
        success,
        message,
    )
    resp.t_events, resp.event_labels = traj.t_events, traj.event_labels
    return _finalise(traj.computed.stamp(resp))


#: At most this many located events have the Jacobian checked after them
#: (spread over the run): enough to see every branch a piecewise law has.
EVENT_CHECKS = 32
#: The Jacobian after an event is taken this fraction of a step past it, along
#: the motion: inside the branch just entered, well beyond the probe.
EVENT_NUDGE = 1e-2


def _check_samples(traj: _IOTrajectory) -> np.ndarray:
    """The output samples whose Jacobian is checked (`qc_control.numerics.
    trajectory_stability`, "Where to look"): first, last, each state's peak and
    the sample after its fastest change."""
    x = traj.x
    finite = np.all(np.isfinite(x), axis=0)
    last = int(np.flatnonzero(finite)[-1]) if np.any(finite) else 0
    picks = [np.array([0, last])]
    if last >= 1:
        xs = x[:, : last + 1]
        picks += [fastest_changes(xs), np.argmax(np.abs(xs), axis=-1)]
    return np.unique(np.concatenate(picks))


#: Of the stage states of the steps replayed around the fastest changes, this
#: many (those where the state moves fastest) have their Jacobian checked.
STAGE_CHECKS = 16


def _stage_points(rhs, traj: _IOTrajectory, u_of_t, h: float):
    """``(t, x (n, P), u (k, P))``: the states at which the method evaluated the
    right-hand side in the intervals around each state's fastest change (its
    steps taken again, `integrate`), where it moves fastest.

    A stiff branch visited only inside an interval (a stop engaged between two
    samples) is seen there: the samples on either side may both lie outside it.
    """
    x = traj.x
    finite = np.all(np.isfinite(x), axis=0)
    last = int(np.flatnonzero(finite)[-1]) if np.any(finite) else 0
    if last < 1 or _method_of(traj.computed).implicit:  # an A-stable method has no limit
        return None
    after = fastest_changes(x[:, : last + 1])
    starts = np.unique(np.concatenate([after - 1, np.minimum(after, last - 1)]))
    seen: list = []

    def recorded(t, xs):
        du = rhs(t, xs, np.asarray(u_of_t(t), dtype=float).reshape(-1))
        seen.append((t, np.array(xs), float(np.linalg.norm(du))))
        return du

    with warnings.catch_warnings(), np.errstate(over="ignore", invalid="ignore"):
        warnings.simplefilter("ignore")  # the replay of a diverging step warns again
        for k in starts.tolist():
            span = traj.t[k : k + 2]
            n_sub = max(1, round(float(span[1] - span[0]) / h))
            integrate(recorded, span, x[:, k], traj.computed.method, substeps=n_sub)
    rates = np.nan_to_num(np.array([r for _, _, r in seen]), nan=np.inf)
    keep = np.argsort(-rates, kind="stable")[:STAGE_CHECKS]
    t = np.array([seen[i][0] for i in keep])
    xs = np.stack([seen[i][1] for i in keep], axis=1)
    us = np.array([np.asarray(u_of_t(s), dtype=float).reshape(-1) for s in t]).T
    return t, xs, us.reshape(-1, t.size)


def _check_points(rhs, traj: _IOTrajectory, u: np.ndarray, u_of_t, h: float):
    """``(t, x (n, P), u (k, P))``: the samples `_check_samples` picks, the stage
    states `_stage_points` picks and, with events, the states just past (at
    most `EVENT_CHECKS` of) them, in the branch each event enters."""
    samples = _check_samples(traj)
    t, x, u_at = traj.t[samples], traj.x[:, samples], u[:, samples]
    stages = _stage_points(rhs, traj, u_of_t, h)
    if stages is not None:
        t = np.concatenate([t, stages[0]])
        x = np.concatenate([x, stages[1]], axis=1)
        u_at = np.concatenate([u_at, stages[2]], axis=1)
    xe = traj.x_events
    if xe is None or not xe.size:
        return t, x, u_at
    pick = np.unique(np.linspace(0, xe.shape[1] - 1, EVENT_CHECKS).round().astype(int))
    te = traj.t_events[pick] + EVENT_NUDGE * h
    ue = np.stack([np.asarray(u_of_t(s), dtype=float).reshape(-1) for s in te], axis=1)
    ue = ue.reshape(u.shape[0], te.size)
    with np.errstate(over="ignore", invalid="ignore"):
        moved = [
            xe[:, i] + EVENT_NUDGE * h * np.asarray(rhs(s, xe[:, i], ue[:, k]), dtype=float)
            for k, (i, s) in enumerate(zip(pick.tolist(), traj.t_events[pick].tolist()))
        ]
    return (
        np.concatenate([t, te]),
        np.concatenate([x, np.stack(moved, axis=1)], axis=1),
        np.concatenate([u_at, ue], axis=1),
    )


#: The linearisation's forcing ``f(t, x0, u(t))`` is evaluated at this many
#: output samples (evenly spread) and where each input peaks, for the growth
#: bound: a road bump lasting a 256th of the run is seen; a shorter one makes
#: the bound smaller than it is, never the step's verdict on the Jacobians.
GROWTH_SAMPLES = 256


def forcing_samples(u: np.ndarray) -> np.ndarray:
    """The samples of ``u`` ``(k, N)`` at which the growth bound's forcing is
    evaluated: `GROWTH_SAMPLES` evenly spread, and where each input peaks."""
    even = np.linspace(0, u.shape[-1] - 1, GROWTH_SAMPLES).round().astype(int)
    peaks = [np.argmax(u, axis=-1), np.argmin(u, axis=-1)] if u.size else []
    return np.unique(np.concatenate([even, *peaks]))


def _guarded(rhs, n: int):
    """``rhs`` that gives NaNs where the system's own code refuses a state (an
    interconnection's loop that does not converge at a diverged state): such a
    Jacobian is not judged (`first_unstable`)."""

    def f(t, x, u):
        try:
            return np.asarray(rhs(t, x, u), dtype=float).reshape(n)
        except Exception:  # the user's code, at a state the run may not have reached
            return np.full(n, np.nan)

    return f


def _growth_beyond(rhs, traj: _IOTrajectory, u: np.ndarray, J0: np.ndarray) -> str:
    """Words for a run that moved from its start past `growth_limit` of its
    linearisation there (`qc_control.numerics.trajectory_stability`), else ''."""
    x = traj.x
    finite = np.all(np.isfinite(x), axis=0)
    if not np.any(finite[1:]):
        return ""
    x0 = x[:, 0]
    with np.errstate(over="ignore", invalid="ignore"):
        departure = float(np.max(np.linalg.norm(x[:, finite] - x0[:, None], axis=0)))
        pick = forcing_samples(u)
        w = float(np.max([np.linalg.norm(rhs(traj.t[k], x0, u[:, k])) for k in pick.tolist()]))
    limit = float(growth_limit(J0[None], np.array([w]))[0])
    if departure <= limit:
        return ""
    return (
        f"the state moved {departure:.4g} from its start, past {limit:.4g} "
        f"({GROWTH_FACTOR:g} times what its linearisation at the start allows)"
    )


def _method_of(computed: _Computed) -> ButcherTableau:
    """The tableau of a stepped run (a difference equation has none)."""
    if computed.method is None:
        raise ValueError("this run is a difference equation: no method stepped it")
    return computed.method


def _beyond_stability_along(sys, traj: _IOTrajectory, u: np.ndarray, u_of_t, h) -> str:
    """The warning's words when the step ``h`` exceeds the method's stability
    limit of the Jacobian somewhere along the trajectory, or the state grew
    past its linearisation's bound, else ''.

    A `control.StateSpace` is its own Jacobian ``A`` (the linear engine's
    verdict, `_beyond_stability`); any other system's Jacobian is differenced
    at the points `_check_points` picks (`qc_control.numerics.trajectory_stability`).
    """
    tab = _method_of(traj.computed)
    if not h or traj.t.size == 0 or not np.all(np.isfinite(traj.x[:, 0])):
        return ""
    if isinstance(sys, control.StateSpace):
        A = np.asarray(sys.A, dtype=float)
        return _beyond_stability(tab, h, np.linalg.eigvals(A), A, sys.name)
    rhs = _guarded(compat.state_derivative(sys), traj.x.shape[0])
    t, x, u_at = _check_points(rhs, traj, u, u_of_t, h)

    def columns(_, xs, which):
        return np.stack([rhs(t[k], xs[:, k], u_at[:, k]) for k in which], axis=1)

    J = jacobians(columns, None, x, range(t.size))
    bad, h_max = first_unstable(tab, h, J)
    if bad is not None:
        message = (
            f"h = {h:.6g} s exceeds the stability limit {h_max:.6g} s of {tab.name} for "
            f"system {sys.name!r} at t = {float(t[bad]):.6g} s (the eigenvalues of the "
            "Jacobian of its right-hand side there): the response grows"
        )
    else:
        grown = _growth_beyond(rhs, traj, u, J[0])
        if not grown:
            return ""
        h_max = max_stable_step(tab, np.linalg.eigvals(J[0]))  # J[0] is finite: x0 is
        message = (
            f"{grown} at h = {h:.6g} s with {tab.name} for system {sys.name!r} (stability "
            f"limit {h_max:.6g} s at the start): the step is beyond the limit of a stiffer "
            "branch between the samples; the response grows"
        )
    warnings.warn(message, DivergenceWarning, stacklevel=_stacklevel())
    return message


def _ivp_tolerances(ivp: dict, method, rtol, atol):
    """``rtol``/``atol`` from ``solve_ivp_kwargs`` (popped from ``ivp``) for an
    embedded pair, as python-control passes them to solve_ivp; given twice,
    a ValueError. For other methods they stay in ``ivp`` (and are refused)."""
    if "rtol" not in ivp and "atol" not in ivp:
        return rtol, atol
    try:
        embedded = get_method(method).embedded
    except (TypeError, ValueError):
        return rtol, atol  # the method's own error comes later
    if not embedded:
        return rtol, atol
    given = {"rtol": rtol, "atol": atol}
    for name in ("rtol", "atol"):
        if name in ivp:
            if given[name] is not None:
                raise ValueError(f"{name} specified more than once (keyword and solve_ivp_kwargs)")
            given[name] = ivp.pop(name)
    return given["rtol"], given["atol"]


def _clocked_response(sys: ClockedLoop, T, U, X0, layout: _Layout, io: _IOOptions):
    """A sampled-data loop (`qc_control.numerics.clocked`): the car stepped at
    ``h = ΔT / substeps``, the controller updated at its ticks, its move held.

    The result also carries ``tick_times`` [s] and ``moves`` (the move
    computed at each tick, before any delay).
    """
    if not (isinstance(io.t_eval, str) and io.t_eval == "T"):
        raise ValueError(
            f"evaluation_times={io.t_eval!r}: a sampled-data loop is output at the times of T"
        )
    if io.events is not None:
        raise ValueError("events= does not apply to a sampled-data loop (a linear car)")
    if io.opts.adaptive:
        raise ValueError(
            "rtol/atol: a sampled-data loop is stepped at a fixed step that lands on every "
            "clock tick; give method and substeps instead"
        )
    prob = _io_problem(sys, T, U, X0, layout.params)
    computed = _io_step(sys, prob, layout.params, io)
    computed.h = float(np.diff(prob.T).max()) / computed.substeps
    run = step_clocked(sys, computed.method, prob.T, prob.u_samples, prob.x0, computed.substeps)
    computed.steps, computed.nfev = run.steps, run.nfev
    x = np.vstack([run.x, run.xc, run.held])
    y = sys.outputs_of(x, prob.u_samples)
    computed.note = (
        f"sampled-data loop: controller every {sys.period:g} s (zero-order hold, delay "
        f"{sys.delay} samples), car stepped at h = {computed.h:.6g} s"
    )
    resp = _response(
        sys,
        (prob.T, y, x, prob.u_samples),
        layout,
        "Input/output response for " + sys.name,
        True,
        None,
    )
    resp.tick_times, resp.moves = run.tick_times, run.moves
    resp.t_events, resp.event_labels = np.empty(0), ()
    return _finalise(computed.stamp(resp))


def input_output_response(
    sys, timepts=None, inputs=0.0, initial_state=0.0, params=None, ignore_errors=False,
    transpose=False, return_states=False, squeeze=None, solve_ivp_kwargs=None,
    evaluation_times="T",
    *, method="rk4", substeps: int = 1, events=None, fast: bool = True, rtol=None, atol=None,
    **kwargs,
):  # fmt: skip
    """Response of a nonlinear (or any) input/output system, at a fixed step.

    The same call as python-control 0.10.2's
    `control.input_output_response`, for any `control.NonlinearIOSystem`
    (an `control.InterconnectedSystem` from `control.interconnect`, a
    `control.nlsys`, or a `control.StateSpace`), with the same
    `control.TimeResponseData` layout, labels and title. Instead of
    ``scipy.integrate.solve_ivp``, the state is stepped by the fixed-step
    method (`qc_control.numerics.integrate`) on

    .. math::

        \\dot x = f\\big(t, x, u(t); p\\big), \\qquad y = g\\big(t, x, u(t); p\\big),

    where ``f`` and ``g`` are the system's update and output functions
    (``sys._rhs`` and ``sys._out``, as control calls them), ``p`` the
    system's parameters updated by ``params`` (``sys._update_params``, as
    control does; an interconnection passes them to every subsystem), and
    ``u(t)`` the input samples interpolated linearly between the times of
    ``T`` (control's own ``ufun``), so that a stage at ``t + c_i h`` sees
    ``u(t + c_i h)``. The outputs are computed from the stepped states.

    Parameters
    ----------
    sys : NonlinearIOSystem or list of them
        A list gives a `control.TimeResponseList`. A discrete-time system
        (``dt > 0`` or True) is simulated by its own difference equation,
        through python-control (no method applied; see the result's ``note``).
    timepts (or T) : array_like
        Input sample times [s], strictly increasing (need not be uniform).
        Each interval is ``substeps`` steps.
    inputs (or U) : array_like, list or float, default 0
        As in python-control: ``(ninputs, len(T))``, ``(len(T),)`` for one
        input, a number, or a list of parts stacked (and broadcast over time).
    initial_state (or X0) : array_like, list or float, default 0
        As in python-control: lists are stacked and zero-padded.
    params : dict, optional
        Parameter values, overriding the system's own (as in control).
    ignore_errors : bool, default False
        Accepted for python-control's signature. A fixed-step run cannot
        fail as ``solve_ivp`` can (a step-size underflow); a state that
        becomes NaN or inf ends the run, with a `DivergenceWarning` and
        ``success`` False, whatever this says. An adaptive run (``rtol``/
        ``atol``) whose step underflows ends there too, with ``success``
        False and a message, rather than control's RuntimeError.
    transpose, squeeze : bool, optional
        As in python-control.
    return_states (or return_x) : bool, default False
        Whether the result unpacks to ``(t, y, x)``.
    solve_ivp_kwargs : dict, optional
        Only the options that mean something at a fixed step: ``t_eval``
        (as ``evaluation_times``) and ``max_step`` (the step is at most
        this: ``substeps`` is raised until it is); with an embedded pair
        also ``rtol`` and ``atol`` (as the keywords), and ``max_step``
        bounds the adaptive step. Any other (``method``, ``events``, ...)
        raises a ValueError naming it.
    evaluation_times (or t_eval) : array_like, 'T' or None, default 'T'
        Output times. ``'T'``: the times of ``T``. An array (sorted, within
        ``[T[0], T[-1]]``): the steps are taken on the union of these times
        and the step grid (each interval of ``T`` split in ``substeps``),
        so every output time is a step end and no output is interpolated.
        None: every step's end (solve_ivp returns its own steps).
    method : str or ButcherTableau, default ``'rk4'``, keyword-only
        ``'euler'``, ``'midpoint'``, ``'heun'``, ``'rk4'`` or a tableau. A
        solve_ivp method name (``'RK45'``, ...), which control's
        ``method=`` means, raises a ValueError saying so; so does
        ``solve_ivp_method``.
    substeps : int, default 1, keyword-only
        Steps per interval of ``T``.
    events : None, True or callable, keyword-only
        Switching functions ``events(t, x, u, params) -> array_like`` whose
        sign changes are the kinks of the right-hand side (a wheel leaving
        the road, a bump stop engaging). Each crossing is located inside its
        step and stepped to exactly (`qc_control.numerics.integrate`'s ``events``),
        which keeps the method's order across the kink; the times are in
        the result's ``t_events`` (and ``event_labels``). True: the
        system's own ``sys.switching`` (`qc_control.nonlinear_quarter_car`
        has them). None (default): no event handling, as control.
    fast : bool, default True, keyword-only
        For an `control.InterconnectedSystem`: solve the interconnection
        once (`qc_control.numerics.interconnect`: linear subsystems eliminated as
        matrix products, the others' functions called directly) instead of
        calling ``sys._rhs``, which re-solves it at every stage. The same
        trajectory to rounding. Falls back to ``sys._rhs`` by itself where
        the interconnection has an algebraic loop.
    rtol, atol : float, optional, keyword-only
        With an embedded pair, step adaptively to these tolerances, as in
        `forced_response` (no step crosses a sample of ``U`` where its slope
        changes; the outputs at ``T`` or ``evaluation_times`` are the pair's
        dense output; no ``events``, ``substeps`` 1, ``evaluation_times``
        not None). The result has ``accepted_times``, ``n_accepted``,
        ``n_rejected`` and ``nfev``; a step that underflows ends the run
        with ``success`` False and a message.

    Returns
    -------
    FixedStepResponse or control.TimeResponseList
        With ``method``, ``h`` (the largest step), ``substeps``, ``steps``,
        ``nfev``, ``t_events`` and ``event_labels``; ``success`` False with
        a ``message`` if the state became non-finite (the response then
        stops at the last finite sample), or, at a fixed step with an
        explicit method, if the step exceeds the method's stability limit
        of the Jacobian along the trajectory or the state grew past its
        linearisation's bound (a `DivergenceWarning` names the method,
        ``h`` and the limit; see
        `qc_control.numerics.trajectory_stability`). A
        `control.StateSpace` is judged on its ``A``, as `initial_response`
        judges it.

    Notes
    -----
    When `initial_response` or `step_response` get a nonlinear system with
    ``T`` a final time, the grid is python-control's (50 points), and the
    step is `auto_step`'s rule applied to the eigenvalues of the system's
    linearisation at the initial point (python-control's
    `~control.NonlinearIOSystem.linearize`). Away from that point the
    Jacobian changes, so this is a guide, not a bound: give ``substeps`` or
    ``max_step`` when the dynamics speed up along the trajectory. The run
    is then checked where the Jacobian matters (the start, the end, each
    state's peak and fastest change, the stages of the steps around it, the
    states just past each located event): a stop that engages beyond the
    step's limit makes ``success`` False.

    Unlike on a linear system, Midpoint and Heun differ here: they agree on
    ``x' = Ax + Bu`` with ``u`` linear within a step, not on a nonlinear
    right-hand side (on Van der Pol, μ = 1, at h = 0.02 over 10 s, by
    8.9e-4 in the state).

    Examples
    --------
    A pendulum, ``θ'' = -(g/l) sin θ``, from 1 rad; ``l`` a parameter:

    >>> import numpy as np, control, qc_control as qc
    >>> def pendulum(t, x, u, params):
    ...     return [x[1], -9.81 / params.get("l", 1.0) * np.sin(x[0])]
    >>> sys = control.nlsys(pendulum, None, states=["theta", "omega"], name="pendulum")
    >>> T = np.linspace(0, 2, 201)
    >>> r = qc.input_output_response(sys, T, X0=[1.0, 0.0], params={"l": 2.0})
    >>> r.method.name, r.nfev, r.output_labels
    ('rk4', 800, ['theta', 'omega'])
    >>> ref = control.input_output_response(
    ...     sys, T, X0=[1.0, 0.0], params={"l": 2.0},
    ...     solve_ivp_kwargs=dict(method="DOP853", rtol=1e-12, atol=1e-12))
    >>> bool(np.max(abs(r.states - ref.states)) < 1e-7)
    True
    """
    compat.process_time_response_kwargs(kwargs)
    T = compat.process_time_response_param("timepts", timepts, kwargs)
    U = compat.process_time_response_param("inputs", inputs, kwargs, sigval=0.0)
    X0 = compat.process_time_response_param("initial_state", initial_state, kwargs, sigval=0.0)
    return_x = compat.process_time_response_param(
        "return_states", return_states, kwargs, sigval=False
    )
    t_eval = compat.process_time_response_param(
        "evaluation_times", evaluation_times, kwargs, sigval="T"
    )
    if "solve_ivp_method" in kwargs:
        value = kwargs.pop("solve_ivp_method")
        raise ValueError(
            f"solve_ivp_method={value!r}: qc_control does not call solve_ivp; "
            f"choose the fixed-step method with method= (one of {sorted(TABLEAUS)} "
            "or a ButcherTableau)"
        )
    if kwargs:
        raise TypeError(f"unrecognized keyword(s): {', '.join(sorted(kwargs))}")
    ivp = dict(solve_ivp_kwargs or {})
    if "method" in ivp:
        _check_fixed_step_method(ivp["method"])
        raise ValueError(
            f"solve_ivp_kwargs['method'] = {ivp['method']!r}: give the fixed-step "
            "method as the keyword method= instead"
        )
    if ivp.get("t_eval") is not None:
        if not (isinstance(t_eval, str) and t_eval == "T"):
            raise ValueError("t_eval specified more than once")
        t_eval = ivp.pop("t_eval")
    ivp.pop("t_eval", None)
    max_step = ivp.pop("max_step", None)
    rtol, atol = _ivp_tolerances(ivp, method, rtol, atol)
    if ivp:
        raise ValueError(
            f"solve_ivp_kwargs {sorted(ivp)} do not apply to a fixed-step method: "
            "only t_eval and max_step do (the accuracy is set by method and the "
            "step: substeps or max_step)"
        )
    _not_a_method(transpose, "transpose")
    opts = _Options(_check_fixed_step_method(method), substeps, "generic", rtol, atol)
    layout = _Layout(params, transpose, return_x, squeeze)
    io = _IOOptions(t_eval, max_step, opts, False, events, fast)
    return _each(sys, lambda s: _io_response(s, T, U, X0, layout, io))
