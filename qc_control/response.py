"""Fixed-step time responses with python-control's call shape and return type.

``qc.initial_response(sys, T, X0, method='heun')`` is a drop-in for
``control.initial_response(sys, T, X0)``: the same arguments, the same
`control.TimeResponseData` (labels, ``.plot()``, ``.to_pandas()``), but the
trajectory is the one the chosen fixed-step method computes.
"""

from __future__ import annotations

import bisect
import warnings

import control
import numpy as np

from .integrate import (
    DivergenceWarning,
    Solution,
    check_substeps,
    check_time_grid,
    integrate,
    uniform_step,
)
from .lti import lti_trajectory
from .methods import ButcherTableau, get_method
from .stability import amplification, max_stable_step

__all__ = ["FixedStepResponse", "initial_response", "forced_response"]

_ALIASES = {"timepts": "T", "inputs": "U", "initial_state": "X0", "return_states": "return_x"}


class FixedStepResponse(control.TimeResponseData):
    """A `control.TimeResponseData` that also says how it was computed.

    Attributes (besides those of `control.TimeResponseData`)
    ----------------------------------------------------------
    method : ButcherTableau
        The method that computed the response.
    h : float
        The largest step taken [s].
    steps, nfev : int
        Steps taken and right-hand-side evaluations (``stages * steps``).
    max_stable_step : float
        The method's stability limit for this system [s] (see
        `qc_control.max_stable_step`).
    """

    method: ButcherTableau
    h: float
    steps: int
    nfev: int
    _eigenvalues: np.ndarray

    @property
    def max_stable_step(self) -> float:
        """The method's stability limit for this system [s], computed when asked."""
        return max_stable_step(self.method, self._eigenvalues)


def _take_aliases(kwargs: dict, values: dict) -> dict:
    for alias, name in _ALIASES.items():
        if alias in kwargs:
            values[name] = kwargs.pop(alias)
    if kwargs:
        raise TypeError(f"unrecognized keyword(s): {', '.join(sorted(kwargs))}")
    return values


def _check_system(sys) -> None:
    if not isinstance(sys, control.StateSpace):
        raise TypeError(f"sys must be a control.StateSpace, got {type(sys).__name__}")
    if not control.isctime(sys, strict=True):
        raise ValueError(
            f"system {sys.name!r} must be continuous-time for a fixed-step "
            f"method, got dt={sys.dt!r}"
        )


def _initial_state(X0, n: int) -> np.ndarray:
    x0 = np.asarray(X0, dtype=float)
    if x0.ndim == 0:
        x0 = np.full(n, float(x0))
    elif x0.shape in ((n, 1), (1, n)):
        x0 = x0.reshape(n)
    if x0.shape != (n,):
        raise ValueError(
            f"X0 must have shape ({n},) for a system with {n} states, got {np.asarray(X0).shape}"
        )
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"X0 must be finite, got {x0.tolist()}")
    return x0


def _input_samples(U, ninputs: int, nsteps: int) -> np.ndarray:
    """``U`` as a ``(ninputs, nsteps)`` array, with python-control's shapes."""
    u = np.asarray(0.0 if U is None else U, dtype=float)
    if u.ndim == 0:
        if ninputs == 0 and u != 0:
            raise ValueError(
                "U is given but the system has no inputs "
                "(build it with quarter_car(road=True) or actuator=True)"
            )
        u = np.full((ninputs, nsteps), float(u))
    elif u.ndim == 1 and ninputs == 1:
        u = u.reshape(1, -1)
    if u.shape != (ninputs, nsteps):
        want = f"({nsteps},) or (1, {nsteps})" if ninputs == 1 else f"({ninputs}, {nsteps})"
        raise ValueError(
            f"U must have shape {want} to match T (len {nsteps}) and the "
            f"system's {ninputs} input(s), got {np.asarray(U).shape}"
        )
    if not np.all(np.isfinite(u)):
        raise ValueError("U must be finite")
    return u


def linear_input(T: np.ndarray, U: np.ndarray):
    """``u(t)``, linear between the samples ``U[:, i]`` at ``T[i]``.

    This is python-control's own assumption for `forced_response`, so a
    stage at ``t + c_i h`` sees ``u(t + c_i h)``.
    """
    times = T.tolist()
    last = len(times) - 2
    rows = np.ascontiguousarray(U.T)
    slopes = np.diff(rows, axis=0) / np.diff(T)[:, None]

    def u(t):
        i = min(max(bisect.bisect_right(times, t) - 1, 0), last)
        return rows[i] + (t - times[i]) * slopes[i]

    return u


def _generic(A, B, T, u_samples, x0, tab, substeps, warn):
    """The generic stepper on ``f(t, x) = A x + B u(t)``."""
    AT, BT = A.T.copy(), B.T.copy()
    if np.any(u_samples):
        u_of_t = linear_input(T, u_samples)

        def rhs(t, x):
            return x @ AT + u_of_t(t) @ BT
    else:

        def rhs(t, x):
            return x @ AT

    with warnings.catch_warnings():
        if not warn:  # the step-size warning already told the user
            warnings.simplefilter("ignore", DivergenceWarning)
        return integrate(rhs, T, x0, tab, substeps=substeps)


def _simulate(sys, T, U, X0, method, substeps, kind, transpose, return_x, squeeze, engine="auto"):
    _check_system(sys)
    tab = get_method(method)
    T = check_time_grid(T, "T")
    A, B = np.asarray(sys.A, dtype=float), np.asarray(sys.B, dtype=float)
    C, D = np.asarray(sys.C, dtype=float), np.asarray(sys.D, dtype=float)
    x0 = _initial_state(X0, sys.nstates)
    u_samples = _input_samples(U, sys.ninputs, T.size)

    steps = np.diff(T)
    h = float(steps.max()) / check_substeps(substeps)
    eig = np.linalg.eigvals(A)
    success, message = True, ""
    # The trajectory grows iff the step map R(hA) amplifies a mode; the full
    # root-finding for h_max runs only to word the warning (or when asked).
    if amplification(tab, h, eig) > 1 + 1e-12 and np.all(eig.real <= 0):
        h_max = max_stable_step(tab, eig)
        success = False
        message = (
            f"h = {h:.6g} s exceeds the stability limit {h_max:.6g} s of "
            f"{tab.name} for system {sys.name!r}: the response grows"
        )
        warnings.warn(message, DivergenceWarning, stacklevel=3)
    # python-control's own test of an even grid: np.allclose(np.diff(T), dt)
    uniform = uniform_step(T, rtol=1e-5, atol=1e-8) is not None
    if engine not in ("auto", "lti", "generic"):
        raise ValueError(f"engine must be 'auto', 'lti' or 'generic', got {engine!r}")
    if engine == "lti" and not uniform:
        raise ValueError("engine='lti' needs a uniformly spaced T")
    if engine == "lti" or (engine == "auto" and uniform and success):
        x = lti_trajectory(tab, A, B, T, u_samples, x0, substeps)
        n_steps = (T.size - 1) * substeps
        sol = Solution(T, x, tab.stages * n_steps, n_steps, tab, "success", "")
    else:
        sol = _generic(A, B, T, u_samples, x0, tab, substeps, warn=success)
    if not sol.success:
        success, message = False, "; ".join(filter(None, [message, sol.message]))
    N = sol.t.size
    x, u = sol.x, u_samples[:, :N]
    y = C @ x + D @ u if np.any(u) else C @ x
    resp = FixedStepResponse(
        sol.t,
        y,
        x,
        u if kind == "forced" else None,
        issiso=sys.issiso(),
        output_labels=sys.output_labels,
        input_labels=sys.input_labels if kind == "forced" else None,
        state_labels=sys.state_labels,
        sysname=sys.name,
        plot_inputs=kind == "forced",
        title=f"{kind.capitalize()} response for {sys.name} ({tab.name}, h = {h:.4g} s)",
        trace_types=[kind],
        transpose=transpose,
        return_x=return_x,
        squeeze=squeeze,
        success=success,
        message=message or None,
    )
    resp.method, resp.h, resp.steps, resp.nfev = tab, h, sol.steps, sol.nfev
    resp._eigenvalues = eig
    return resp


def initial_response(
    sys,
    T=None,
    X0=0.0,
    method="rk4",
    substeps: int = 1,
    *,
    engine="auto",
    transpose=False,
    return_x=False,
    squeeze=None,
    **kwargs,
):
    """Initial-condition response computed by a fixed-step method.

    The same call as ``control.initial_response(sys, T, X0)``; the
    trajectory is ``x_{n+1} = x_n + h Σ b_i k_i`` of the chosen method
    rather than the exact ``e^{Ah} x_n``.

    Parameters
    ----------
    sys : control.StateSpace
        A continuous-time system.
    T : array_like
        Output times [s], strictly increasing. Each interval is one step
        (or ``substeps`` steps). Alias: ``timepts``.
    X0 : array_like or float, default 0
        Initial state, shape ``(nstates,)``; a number fills every state.
        Alias: ``initial_state``.
    method : str or ButcherTableau, default ``'rk4'``
        ``'euler'``, ``'midpoint'``, ``'heun'``, ``'rk4'`` or a tableau.
    substeps : int, default 1
        Steps per interval of ``T``.
    engine : {'auto', 'lti', 'generic'}, default 'auto'
        How the method's trajectory is computed. ``'lti'``: the step map
        ``x_{k+1} = R(hA) x_k + Γ₀u_k + Γ₁u_{k+1}`` solved by a blocked scan
        (`qc_control.lti`), no Python loop per step; needs a uniform ``T``.
        ``'generic'``: `qc_control.integrate`, one step at a time. The two
        agree to rounding (1e-12 relative). ``'auto'`` uses ``'lti'`` on a
        uniform grid within the stability limit, ``'generic'`` otherwise
        (it stops a blow-up at its first non-finite sample).
    transpose, return_x, squeeze
        As in python-control.

    Returns
    -------
    FixedStepResponse
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
    that curve within a step (see `qc_control.integrate`).

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
    values = _take_aliases(kwargs, {"T": T, "X0": X0, "return_x": return_x})
    return _simulate(
        sys,
        values["T"],
        0.0,
        values["X0"],
        method,
        substeps,
        "initial",
        transpose,
        values["return_x"],
        squeeze,
        engine,
    )


def forced_response(
    sys,
    T=None,
    U=0.0,
    X0=0.0,
    method="rk4",
    substeps: int = 1,
    *,
    engine="auto",
    transpose=False,
    return_x=None,
    squeeze=None,
    **kwargs,
):
    """Forced response computed by a fixed-step method.

    The same call as ``control.forced_response(sys, T, U, X0)``. The input
    is linear between its samples, python-control's own assumption, so the
    stage at time ``t + c_i h`` sees ``u(t + c_i h)``:

    .. math::

        k_i = A\\Big(x + h\\sum_{j<i} a_{ij}k_j\\Big) + B\\,u(t + c_i h)

    Parameters
    ----------
    sys : control.StateSpace
        A continuous-time system.
    T : array_like
        Sample times [s], strictly increasing. Alias: ``timepts``.
    U : array_like or float, default 0
        Input samples, shape ``(ninputs, len(T))`` or ``(len(T),)`` for
        one input; a number holds every input at that value.
        Alias: ``inputs``.
    X0 : array_like or float, default 0
        Initial state. Alias: ``initial_state``.
    method, substeps, engine, transpose, return_x, squeeze
        As in `initial_response`.

    Returns
    -------
    FixedStepResponse
        With outputs ``y = C x + D u`` and the inputs as given.

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
    values = _take_aliases(kwargs, {"T": T, "U": U, "X0": X0, "return_x": return_x})
    return _simulate(
        sys,
        values["T"],
        values["U"],
        values["X0"],
        method,
        substeps,
        "forced",
        transpose,
        values["return_x"],
        squeeze,
        engine,
    )


#: The input checks, public for the layers above (compare); see the functions.
check_initial_state = _initial_state
check_input_samples = _input_samples
