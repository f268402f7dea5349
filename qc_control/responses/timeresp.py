"""The linear time responses at a fixed step, with python-control's call shape.

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
  `input_output_response` (`qc_control.responses.iosys`), python-control's
  call at a fixed step, as control's own responses hand such systems to its
  `control.input_output_response`.

The result type and the checks these share with `input_output_response`
are in `qc_control.responses.common`; each is importable from here too, as
are `input_output_response` and the automatic step (`auto_step`, now in
`qc_control.numerics.steps`).
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import control
import numpy as np

# Captured at import, so that a caller who routes control's function to this
# module (as tests/peer does) still reaches control's own difference equation.
from control.timeresp import forced_response as _control_forced_response

from .. import compat
from ..numerics.adaptive import slope_breakpoints
from ..numerics.integrate import (
    DivergenceWarning,
    check_run_steps,
    check_time_grid,
    checked_uniform_step,
    integrate,
    integrate_stepper,
    uniform_step,
)
from ..numerics.limits import check_memory
from ..numerics.lti import array_key, is_nonlinear_system, lti_states, memo
from ..numerics.methods import ButcherTableau
from ..numerics.sampled import linear_input
from ..numerics.stepper import ImplicitSteps

# Names that moved to `qc_control.numerics.steps` (the step policy),
# `common` and `iosys` in the split of this module: importable from here as
# before (other modules, tests and users' scripts import them from here).
from ..numerics.steps import (
    AUTO_STEP_LOCAL_ERROR,  # noqa: F401
    AUTO_STEP_STABILITY_FRACTION,  # noqa: F401
    auto_step,  # noqa: F401
    auto_substeps,
)
from .common import (
    Computed,
    FixedStepResponse,
    Layout,
    StepOptions,
    caller_stacklevel,
    check_initial_state,
    check_input_samples,
    difference_equation,
    each_system,
    finalise,
    fixed_step_response,
    refuse_method_positional,
    warn_beyond_stability,
)
from .iosys import (
    EVENT_CHECKS,  # noqa: F401
    EVENT_NUDGE,  # noqa: F401
    GROWTH_SAMPLES,  # noqa: F401
    STAGE_CHECKS,  # noqa: F401
    IOOptions,
    forcing_samples,  # noqa: F401
    input_output_response,  # noqa: F401
    io_response,
)

__all__ = ["initial_response", "forced_response", "step_response", "impulse_response"]


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


class _LinearRun(NamedTuple):
    """One fixed-step run of a continuous-time StateSpace (`_simulate`)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    computed: Computed
    success: bool
    message: str
    #: the engine proved the states finite (the LTI engine's cut): `finalise` looks at y only
    states_finite: bool = False


def _linear_step(tab: ButcherTableau, A: np.ndarray, H: float, opts: StepOptions, auto: bool):
    """The run's `Computed` before stepping: eigenvalues, substeps and ``h``.

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
    return Computed(tab, H / substeps, substeps, step_rule, eig)


def _lti_run(tab, A, B, T, u_engine, x0, substeps, quiet: bool):
    """The LTI engine's states, and whether it cut a blow-up short
    (``quiet``: the step-size warning already told the user)."""
    if not quiet:
        return lti_states(tab, A, B, T, u_engine, x0, substeps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DivergenceWarning)
        return lti_states(tab, A, B, T, u_engine, x0, substeps)


def _simulate(ss, T, u_samples, x0, opts: StepOptions, auto: bool) -> _LinearRun:
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
    message = warn_beyond_stability(tab, H / substeps, computed.eigenvalues, A, ss.name)
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
    # lti_states cuts before the first non-finite sample: finalise need not look again
    return _LinearRun(t, x, y, u, computed, success, message, states_finite=lti)


def _simulate_adaptive(A, B, C, D, problem, opts: StepOptions, computed: Computed) -> _LinearRun:
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


def _nonlinear_response(sys, T, U, X0, layout: Layout, opts, auto):
    """The one place nonlinear systems go from the linear responses.

    python-control's `forced_response` (and so its initial and step
    responses) hands a `control.NonlinearIOSystem` to
    `control.input_output_response` with exactly these arguments; so does
    this module, to the fixed-step `input_output_response`
    (`qc_control.responses.iosys.io_response`).
    """
    return io_response(sys, T, U, X0, layout, IOOptions("T", None, opts, auto))


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
            stacklevel=caller_stacklevel(),
        )
    if np.any(np.asarray(X0) != 0):
        warnings.warn(_NONZERO_X0_FOR_TF, stacklevel=caller_stacklevel())


def _forced(sys, T, U, X0, layout: Layout, interpolate, opts, auto=False, inner=False):
    """`forced_response` for one system (``inner``: a step of another response,
    which checks the result itself)."""
    _check_system(sys)
    if is_nonlinear_system(sys):
        if interpolate:  # as python-control
            warnings.warn(
                "interpolation not supported for nonlinear I/O systems",
                stacklevel=caller_stacklevel(),
            )
        return _nonlinear_response(sys, T, U, X0, layout, opts, auto)
    if layout.return_x is None:
        layout = layout._replace(return_x=control.config.defaults["forced_response.return_x"])
    if not control.isctime(sys, strict=True):
        return difference_equation(
            _control_forced_response, sys, T, U, X0, layout,
            interpolate=interpolate, return_states=layout.return_x,
        )  # fmt: skip
    _transfer_function_warnings(sys, X0, layout.return_x)
    ss = _as_statespace(sys)
    run = _linear_run(ss, T, U, X0, layout.transpose, opts, auto)
    resp = fixed_step_response(
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
    return resp if inner else finalise(resp, run.states_finite)


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


def _combine(parts: list[FixedStepResponse]) -> tuple[Computed, bool, str | None]:
    """How several traces (inputs of a step response) were computed, together:
    the last trace's method and step, their steps and evaluations summed, and
    whether all succeeded, with their distinct messages."""
    computed = Computed.of(parts[-1])
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
    refuse_method_positional(v[positional], positional)
    opts = StepOptions(*options)
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
    refuse_method_positional(transpose, "transpose")
    opts = StepOptions(method, substeps, engine, rtol, atol)
    T, U, X0 = v["timepts"], v["inputs"], v["initial_state"]
    layout = Layout(params, transpose, v["return_states"], squeeze)
    return each_system(sysdata, lambda s: _forced(s, T, U, X0, layout, interpolate, opts))


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
    layout = Layout(params, transpose, v["return_states"], squeeze)
    return each_system(sysdata, lambda s: _initial(s, T, auto, X0, output, layout, opts))


def _initial(sys, T, auto, X0, output, layout: Layout, opts):
    if isinstance(sys, control.StateSpace) and control.isctime(sys, strict=True):
        # the fast path: the run's arrays go into one response, not two
        run = _linear_run(sys, T, 0, X0, False, opts, auto)
    else:
        inner = Layout(layout.params, False, None, None)
        r = _forced(sys, T, 0, X0, inner, False, opts, auto, inner=True)
        run = _LinearRun(r.t, r.x, r.y, r.u, Computed.of(r), r.success, r.message)
    resp = fixed_step_response(
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
    return finalise(run.computed.stamp(resp), run.states_finite)


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
        r = _forced(sys, T, U, X0_of(i), Layout(params, False, None, True), False, opts, auto)
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
    layout = Layout(params, transpose, v["return_states"], squeeze)
    return each_system(sysdata, lambda s: _step(s, T, auto, *args, layout, opts))


def _step(sys, T, auto, X0, inputs, output, layout: Layout, opts):
    if isinstance(sys, control.TransferFunction) and np.any(np.asarray(X0) != 0):
        warnings.warn(_NONZERO_X0_FOR_TF, stacklevel=caller_stacklevel())
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


def _multi_trace(kind, sys, T, traces, inputs, output, layout: Layout):
    """One response of the traces `_traces` computed, laid out as asked."""
    yout, xout, uout, parts, labels = traces
    computed, success, message = _combine(parts) if parts else (None, True, None)
    resp = fixed_step_response(
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
    return finalise(resp if computed is None else computed.stamp(resp))


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
    layout = Layout(None, transpose, v["return_states"], squeeze)
    return each_system(sysdata, lambda s: _impulse(s, T, auto, inputs, output, layout, opts))


def _impulse(sys, T, auto, inputs, output, layout: Layout, opts):
    if not isinstance(sys, control.LTI):
        raise ValueError("system must be LTI system for impulse response")
    _check_system(sys)
    sys = _as_lti_statespace(sys)
    continuous = control.isctime(sys)
    if continuous and np.any(np.asarray(sys.D) != 0):
        warnings.warn(
            "System has direct feedthrough: `D != 0`. The infinite impulse at "
            "`t=0` does not appear in the output.\nResults may be meaningless!",
            stacklevel=caller_stacklevel(),
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
