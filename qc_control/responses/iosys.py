"""`input_output_response` at a fixed step: python-control's ``nlsys`` call.

Any `control.NonlinearIOSystem` (an `control.InterconnectedSystem` from
`control.interconnect`, a `control.nlsys`, a `control.StateSpace`) is
stepped on its right-hand side ``x' = f(t, x, u(t); p)`` by a fixed-step
method (`qc_control.numerics.integrate`), or adaptively by an embedded pair
given ``rtol``/``atol``; ``events`` step to each kink; a
`qc_control.numerics.clocked.ClockedLoop` is stepped so that its steps land
on every tick of its controller. The run is then checked where the
Jacobian matters (`qc_control.numerics.trajectory_stability`): a step
beyond the method's stability limit along the trajectory makes ``success``
False. The linear responses (`qc_control.responses.timeresp`) hand a
nonlinear system here, as python-control's do.
"""

from __future__ import annotations

import math
import warnings
from typing import NamedTuple

import control
import numpy as np

# Captured at import, so that a caller who routes control's function to this
# module (as tests/peer does) still reaches control's own difference equation.
from control.nlsys import input_output_response as _control_io_response

from .. import compat
from ..numerics.adaptive import slope_breakpoints
from ..numerics.checks import positive
from ..numerics.clocked import ClockedLoop, step_clocked
from ..numerics.integrate import (
    STEP_BLOCK,
    DivergenceWarning,
    check_step_memory,
    check_time_grid,
    integrate,
    integrate_stepper,
    stage_times,
    uniform_step,
)
from ..numerics.interconnect import CompiledInterconnect, FusedSteps, compile_interconnect
from ..numerics.methods import TABLEAUS, ButcherTableau, get_method
from ..numerics.sampled import linear_input
from ..numerics.stability import max_stable_step
from ..numerics.steps import auto_substeps, substeps_for
from ..numerics.trajectory_stability import (
    GROWTH_FACTOR,
    fastest_changes,
    first_unstable,
    growth_limit,
    jacobians,
)
from . import common

__all__ = ["input_output_response"]

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


class IOOptions(NamedTuple):
    """`input_output_response`'s fixed-step options for one system."""

    t_eval: object  # 'T', None or times [s]
    max_step: float | None
    opts: common.StepOptions
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
    computed: common.Computed
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


def _io_step(sys, prob: _IOProblem, params, io: IOOptions) -> common.Computed:
    """The method, substeps and step rule (``h`` is set by `_io_grid`): `auto_step`
    on the linearisation at the initial point with an automatic grid, and
    ``max_step``'s bound."""
    tab, substeps, step_rule, eig = io.opts.tab, io.opts.substeps, None, None
    H = float(np.diff(prob.T).max())
    if io.opts.adaptive:  # the steps follow the error estimate; max_step goes to the controller
        if io.max_step is not None:
            _check_max_step(io.max_step)
        return common.Computed(tab, None, 1, None, None)
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
    return common.Computed(tab, None, substeps, step_rule, eig)


def _check_max_step(max_step) -> float:
    """``solve_ivp_kwargs['max_step']`` as a step [s], refused unless a finite number > 0."""
    return positive("max_step", max_step, "s", description="the largest step")


def _check_io_steps(prob: _IOProblem, io: IOOptions, substeps: int, by_max_step: int) -> None:
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


def _io_static(prob: _IOProblem, grid, at, computed: common.Computed) -> _IOTrajectory:
    """A static system: nothing to integrate, its output function is evaluated."""
    computed.note = (
        "the system has no states: its output function was evaluated, nothing integrated"
    )
    t_out = grid if at is None else grid[at]
    x = np.zeros((0, t_out.size))
    keep = np.empty(0, dtype=int)  # no stepped grid
    return _IOTrajectory(t_out, x, keep, computed, True, "", np.empty(0), (), None, None)


def _io_integrate(sys, prob: _IOProblem, grid, at, n_sub, computed: common.Computed, io, u_of_t):
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


def _io_adaptive(sys, prob: _IOProblem, grid, at, computed: common.Computed, io, u_of_t):
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


def io_response(sys, T, U, X0, layout: common.Layout, io: IOOptions):
    """`input_output_response` for one system: the arguments, the step, the
    trajectory, then its signals as a `FixedStepResponse`."""
    if not isinstance(sys, control.NonlinearIOSystem):
        raise TypeError(f"System of type {type(sys)} not valid")
    if control.isdtime(sys, strict=True):
        return common.difference_equation(
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
    resp = common.fixed_step_response(
        sys,
        (traj.t, y, traj.x if prob.x0.size else None, u),
        layout,
        "Input/output response for " + sys.name,
        success,
        message,
    )
    resp.t_events, resp.event_labels = traj.t_events, traj.event_labels
    return common.finalise(traj.computed.stamp(resp))


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


def _method_of(computed: common.Computed) -> ButcherTableau:
    """The tableau of a stepped run (a difference equation has none)."""
    if computed.method is None:
        raise ValueError("this run is a difference equation: no method stepped it")
    return computed.method


def _beyond_stability_along(sys, traj: _IOTrajectory, u: np.ndarray, u_of_t, h) -> str:
    """The warning's words when the step ``h`` exceeds the method's stability
    limit of the Jacobian somewhere along the trajectory, or the state grew
    past its linearisation's bound, else ''.

    A `control.StateSpace` is its own Jacobian ``A`` (the linear engine's
    verdict, `common.warn_beyond_stability`); any other system's Jacobian is differenced
    at the points `_check_points` picks (`qc_control.numerics.trajectory_stability`).
    """
    tab = _method_of(traj.computed)
    if not h or traj.t.size == 0 or not np.all(np.isfinite(traj.x[:, 0])):
        return ""
    if isinstance(sys, control.StateSpace):
        A = np.asarray(sys.A, dtype=float)
        return common.warn_beyond_stability(tab, h, np.linalg.eigvals(A), A, sys.name)
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
    warnings.warn(message, DivergenceWarning, stacklevel=common.caller_stacklevel())
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


def _clocked_response(sys: ClockedLoop, T, U, X0, layout: common.Layout, io: IOOptions):
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
    resp = common.fixed_step_response(
        sys,
        (prob.T, y, x, prob.u_samples),
        layout,
        "Input/output response for " + sys.name,
        True,
        None,
    )
    resp.tick_times, resp.moves = run.tick_times, run.moves
    resp.t_events, resp.event_labels = np.empty(0), ()
    return common.finalise(computed.stamp(resp))


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
    common.refuse_method_positional(transpose, "transpose")
    opts = common.StepOptions(_check_fixed_step_method(method), substeps, "generic", rtol, atol)
    layout = common.Layout(params, transpose, return_x, squeeze)
    io = IOOptions(t_eval, max_step, opts, False, events, fast)
    return common.each_system(sys, lambda s: io_response(s, T, U, X0, layout, io))
