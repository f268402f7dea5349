"""What the linear responses and `input_output_response` share.

`qc_control.responses.timeresp` (python-control's linear call forms) and
`qc_control.responses.iosys` (its `input_output_response`) build the same
result in the same way; this module holds what they have in common:

* the result, `FixedStepResponse` (a `control.TimeResponseData` that says
  how it was computed), and the record of a run that fills it (`Computed`);
* the one check of an initial state and of input samples
  (`check_initial_state`, `check_input_samples`), which the sweeps share too;
* the keyword-only options (`StepOptions`: method, substeps, engine, tolerances)
  and the refusal of a method given where python-control has a positional;
* the result's layout as the caller asked it (`Layout`, `fixed_step_response`),
  the one response-level check (`finalise`: any NaN or inf is no success),
  and python-control's own difference equation for a discrete-time system;
* the warning for a step beyond a linear system's stability limit
  (`warn_beyond_stability`), pointed at the caller's line (`caller_stacklevel`).
"""

from __future__ import annotations

import inspect
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import control
import numpy as np

from ..numerics.adaptive import check_embedded
from ..numerics.checks import choice
from ..numerics.integrate import DivergenceWarning, check_substeps
from ..numerics.lti import array_key, memo
from ..numerics.methods import TABLEAUS, ButcherTableau, get_method
from ..numerics.stability import max_stable_step, step_is_stable

__all__ = ["FixedStepResponse", "check_initial_state", "check_input_samples"]

#: The responses' own files: a warning points past them, at the caller's line.
_RESPONSES = Path(__file__).parent


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


_ENGINES = ("auto", "lti", "generic")


def refuse_method_positional(value, name: str) -> None:
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


def caller_stacklevel() -> int:
    """The ``stacklevel`` that points a warning at the caller's line, outside
    the responses (`timeresp`, `iosys` and this module call one another)."""
    frame, level = inspect.currentframe(), 0
    while frame is not None and Path(frame.f_code.co_filename).parent == _RESPONSES:
        frame, level = frame.f_back, level + 1
    return level


class StepOptions:
    """The keyword-only additions, checked once per call."""

    def __init__(self, method, substeps, engine, rtol=None, atol=None):
        self.tab = get_method(method)
        self.substeps = check_substeps(substeps)
        self.engine = choice("engine", engine, _ENGINES)
        self.rtol, self.atol = rtol, atol
        #: an embedded pair given rtol/atol chooses its own steps
        self.adaptive = rtol is not None or atol is not None
        if self.adaptive:
            _check_adaptive(self)


def _check_adaptive(opts: StepOptions) -> None:
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


@dataclass
class Computed:
    """How a response was computed: what `FixedStepResponse` adds to control's data."""

    method: ButcherTableau | None
    h: float | None
    substeps: int
    step_rule: str | None
    eigenvalues: np.ndarray | None
    steps: int = 0
    nfev: int = 0
    note: str | None = None
    adaptive: AdaptiveCounts | None = None

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
    def of(cls, resp: FixedStepResponse) -> Computed:
        """What ``resp`` says about how it was computed."""
        adaptive = None
        if resp.accepted_times is not None:
            adaptive = AdaptiveCounts(
                resp.rtol, resp.atol, resp.accepted_times, resp.n_accepted, resp.n_rejected
            )
        return cls(
            resp.method, resp.h, resp.substeps, resp.step_rule, resp._eigenvalues,
            resp.steps, resp.nfev, resp.note, adaptive,
        )  # fmt: skip

    def record(self, sol, opts: StepOptions) -> None:
        """The steps and evaluations of the run ``sol`` (a `Solution`); an adaptive
        run's counts, accepted times and largest step besides."""
        self.steps, self.nfev = sol.steps, sol.nfev
        if sol.accepted_times is None:
            return
        self.adaptive = AdaptiveCounts(
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
class AdaptiveCounts:
    """What an adaptive run adds to `Computed`."""

    rtol: float | None
    atol: float | np.ndarray | None
    accepted_times: np.ndarray
    n_accepted: int
    n_rejected: int


def _show_tolerance(atol) -> str:
    """``atol`` for a message: a number, or the range of one per state."""
    a = np.asarray(atol, dtype=float)
    return f"{float(a):g}" if a.ndim == 0 else f"{a.min():g}..{a.max():g} (one per state)"


def warn_beyond_stability(tab: ButcherTableau, h: float, eig, A: np.ndarray, name: str) -> str:
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
    warnings.warn(message, DivergenceWarning, stacklevel=caller_stacklevel())
    return message


def _all_finite(v: np.ndarray) -> bool:
    """No NaN or inf in ``v``: its min and max propagate both, without a mask array."""
    if v.size == 0 or v.dtype == object:
        return True
    # one pass: a NaN or an inf makes the sum non-finite; a finite sum proves
    # every element finite, and only an overflowing sum needs the exact test
    with np.errstate(over="ignore", invalid="ignore"):
        total = v.sum()
    return bool(np.isfinite(total) or (np.isfinite(v.min()) and np.isfinite(v.max())))


def finalise(resp: FixedStepResponse, states_finite: bool = False) -> FixedStepResponse:
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


def _wrap_control_response(data: control.TimeResponseData, **meta) -> FixedStepResponse:
    """A python-control result as a FixedStepResponse (no method applied)."""
    resp = FixedStepResponse.__new__(FixedStepResponse)
    resp.__dict__.update(data.__dict__)
    resp.__dict__.update(meta)
    return finalise(resp)


class Layout(NamedTuple):
    """How the caller wants the result laid out, as python-control takes it."""

    params: dict | None
    transpose: bool
    return_x: bool | None
    squeeze: bool | None


def fixed_step_response(sys, data, layout: Layout, title: str, success, message, **labels):
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


def each_system(sysdata, respond):
    """python-control's rule for every response: a list (or tuple) of systems
    gives a `control.TimeResponseList`, one response per system."""
    if isinstance(sysdata, (list, tuple)):
        return control.TimeResponseList(respond(s) for s in sysdata)
    return respond(sysdata)


def difference_equation(control_response, sys, T, U, X0, layout: Layout, **keywords):
    """A discrete-time or ``dt=None`` system: python-control's own difference
    equation, by its ``control_response`` (`control.forced_response` or
    `control.input_output_response`, whose own ``keywords`` are passed on)."""
    data = control_response(
        sys, T, U, X0, params=layout.params, transpose=layout.transpose,
        squeeze=layout.squeeze, **keywords,
    )  # fmt: skip
    return _wrap_control_response(data, note=_discrete_note(sys))
