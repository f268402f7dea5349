"""Step-size control for embedded Runge–Kutta pairs: steps chosen by the error.

A tableau with an error estimator ``b̂`` (`ButcherTableau.b_hat`) gives, from
the stages of one step, both the step ``x + h Σ b_i k_i`` and the estimate
of its local error

.. math::

    \\mathrm{err} = h \\sum_i (b_i - \\hat b_i)\\, k_i = O(h^{q+1}),
    \\qquad q = \\min(p, \\hat p) .

The standard controller (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4,
"Automatic step size control") measures it in the norm

.. math::

    \\|\\mathrm{err}\\| = \\sqrt{\\frac1n \\sum_j \\Big(\\frac{\\mathrm{err}_j}
    {\\mathrm{atol}_j + \\mathrm{rtol}\\,\\max(|x_j|, |x^{new}_j|)}\\Big)^2},

accepts the step when ``‖err‖ < 1`` and sets the next step to
``h · min(facmax, max(facmin, fac · ‖err‖^{-1/(q+1)}))``, never growing
right after a rejection. The constants are scipy's (``rk.py``: fac 0.9,
facmin 0.2, facmax 10), as are the first step (`initial_step`, HNW I,
§II.4, "Starting step size"), the smallest step (ten units in the last
place of ``t``) and the reuse of the last stage as the next first stage on
FSAL pairs: with `DORMAND_PRINCE` the accepted steps are those of
``scipy.integrate.solve_ivp(method='RK45')``, step for step.

The stages are those of every other run: `qc_control.numerics.stepper`'s
`rk_stages` and `rk_end`, with the first stage passed in, so that a
rejected step reuses it and an FSAL pair takes it from the previous step.

Inputs sampled in time make ``f`` only piecewise smooth in ``t``: where the
slope of a linearly interpolated input changes (`slope_breakpoints`), the
solution's second derivative jumps. A step never crosses such a time; it
stops there and the run goes on from it (HNW I, §II.6, discontinuities).
Without this, a step that starts on a flat stretch of road can pass over a
pothole without any stage seeing it, and the error estimate sees nothing.

Outputs between step ends come from the pair's continuous extension:
Dormand–Prince's quartic (Shampine, Math. Comp. 46, 1986; scipy's RK45
``P``), and otherwise the cubic Hermite polynomial through both ends of
the step (Bogacki–Shampine's own interpolant, scipy's RK23 ``P``). Output
times do not stop the steps: stopping at every sample of a 1 ms grid would
force 1 ms steps and the controller would never be in charge.
"""

from __future__ import annotations

import bisect
import math
from array import array
from dataclasses import dataclass

import numpy as np

from .checks import Field, ParameterError, check_fields, number, positive
from .methods import DORMAND_PRINCE, ButcherTableau
from .stepper import rk_end, rk_stages, stage_plan

__all__ = [
    "StepController",
    "SCIPY_CONTROLLER",
    "AdaptiveRun",
    "adaptive_solve",
    "check_tolerances",
    "check_embedded",
    "initial_step",
    "slope_breakpoints",
    "MIN_RTOL",
    "MAX_STEPS",
]

_EPS = np.finfo(float).eps

#: The smallest relative tolerance: below ``100 ε`` the error estimate is
#: rounding, not truncation (scipy raises such an rtol to this value; here
#: it is refused).
MIN_RTOL = 100 * _EPS

#: Step attempts after which a run gives up (a run this long has a
#: tolerance its problem cannot meet in reasonable time; its accepted
#: times alone would take 80 MB).
MAX_STEPS = 10_000_000

#: Shampine's quartic continuous extension of Dormand–Prince 5(4):
#: ``x(t + θh) = x + h Σ_i k_i Σ_j P_ij θ^{j+1}`` (Shampine, Math. Comp. 46,
#: 1986, with the c_6 of Dormand & Prince; scipy's ``RK45.P``).
_DOPRI_DENSE = np.array(
    [
        [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
        [0, 0, 0, 0],
        [
            0,
            131558114200 / 32700410799,
            -68118460800 / 10900136933,
            87487479700 / 32700410799,
        ],
        [
            0,
            -1754552775 / 470086768,
            14199869525 / 1410260304,
            -10690763975 / 1880347072,
        ],
        [
            0,
            127303824393 / 49829197408,
            -318862633887 / 49829197408,
            701980252875 / 199316789632,
        ],
        [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
        [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
    ]
)

#: Continuous extensions by tableau; any other pair gets the cubic Hermite.
_DENSE = {DORMAND_PRINCE: _DOPRI_DENSE}


#: `StepController`'s constants, declared once: what each does, its range.
_CONTROLLER_SPEC = {
    "safety": Field("the fraction of the largest step the estimate allows", "", high=1.0),
    "min_factor": Field("the most a step shrinks at once", "", high=1.0, high_open=True),
    "max_factor": Field("the most a step grows at once", "", "finite", low=1.0, low_open=True),
}


@dataclass(frozen=True)
class StepController:
    """The standard step-size controller's constants (HNW I, §II.4, (4.13)).

    After a step with error norm ``e`` the next step is ``h · factor``:

    .. math::

        \\text{factor} = \\min\\big(\\text{max\\_factor},\\,
        \\max(\\text{min\\_factor},\\, \\text{safety} \\cdot e^{-1/(q+1)})\\big),

    at most 1 right after a rejection, ``max_factor`` when ``e = 0``.

    Parameters
    ----------
    safety : float, default 0.9
        In (0, 1]: aims below the largest step the estimate allows, so
        that the next step is seldom rejected.
    min_factor : float, default 0.2
        In (0, 1): the most a step shrinks at once.
    max_factor : float, default 10
        Greater than 1: the most a step grows at once.

    The defaults are scipy's (``scipy/integrate/_ivp/rk.py``: ``SAFETY``,
    ``MIN_FACTOR``, ``MAX_FACTOR``); HNW's DOPRI5 code uses 0.9, 0.2 and 10
    too.
    """

    safety: float = 0.9
    min_factor: float = 0.2
    max_factor: float = 10.0

    def __post_init__(self):
        check_fields(self, _CONTROLLER_SPEC)

    @classmethod
    def spec(cls) -> dict[str, Field]:
        """The fields, declared: ``{name: Field}`` (description, range)."""
        return dict(_CONTROLLER_SPEC)

    def factor(self, error_norm: float, exponent: float, rejected: bool) -> float:
        """The factor on ``h`` after an accepted step (``error_norm < 1``)."""
        if error_norm == 0:
            grow = self.max_factor
        else:
            grow = min(self.max_factor, self.safety * error_norm**exponent)
        return min(1.0, grow) if rejected else grow

    def shrink(self, error_norm: float, exponent: float) -> float:
        """The factor on ``h`` after a rejected step (``error_norm >= 1``, or NaN)."""
        return max(self.min_factor, self.safety * error_norm**exponent)


#: scipy's constants (the default).
SCIPY_CONTROLLER = StepController()


def _rms(v: np.ndarray) -> float:
    """The root-mean-square norm (HNW I, §II.4, (4.11); scipy's ``norm``)."""
    return float(np.linalg.norm(v) / math.sqrt(v.size))


def check_embedded(tab: ButcherTableau) -> None:
    """Refuse ``rtol``/``atol`` with a tableau that has no error estimator."""
    if not tab.embedded:
        raise ValueError(
            f"rtol/atol need an embedded pair (heun_euler, bogacki_shampine, dormand_prince "
            f"or a tableau with b_hat); {tab.name!r} has no error estimator: drop rtol/atol "
            "to step it at a fixed step"
        )


#: What ``rtol`` and ``atol`` are, for their refusals.
_RTOL = "relative tolerance: at least 100 eps, below which the error estimate is rounding"
_ATOL = "a finite absolute tolerance > 0, a number or one per state"


def check_tolerances(rtol, atol, n: int) -> tuple[float, np.ndarray | float]:
    """``(rtol, atol)`` checked: rtol a number in ``[MIN_RTOL, 1)``, atol
    positive and finite, a number or one per state.

    Parameters
    ----------
    rtol, atol : float or None
        None takes scipy's default (1e-3, 1e-6).
    n : int
        The number of states.

    Raises
    ------
    ValueError
        Naming the value and what was expected.
    """
    rtol = 1e-3 if rtol is None else rtol
    atol = 1e-6 if atol is None else atol
    rtol = number("rtol", rtol, low=MIN_RTOL, high=1.0, high_open=True, description=_RTOL)
    if isinstance(atol, (bool, np.bool_)):  # not a tolerance, though NumPy reads it as 1.0
        raise ParameterError("atol", atol, _ATOL)
    try:
        a = np.asarray(atol, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("atol", atol, _ATOL) from None
    if a.ndim > 1 or (a.ndim == 1 and a.size != n):
        raise ParameterError("atol", atol, f"a number or one per state, shape ({n},)")
    if not (np.all(np.isfinite(a)) and np.all(a > 0)):
        raise ParameterError("atol", atol, _ATOL)
    return rtol, (float(a) if a.ndim == 0 else a)


def initial_step(f, t0, x0, f0, t_bound, error_order, rtol, atol, max_step=math.inf) -> float:
    """The first step's size: HNW I, §II.4, "Starting step size", as scipy's
    ``select_initial_step`` (``scipy/integrate/_ivp/common.py``).

    With ``sc = atol + rtol |x0|``, ``d0 = ‖x0/sc‖``, ``d1 = ‖f0/sc‖``:
    ``h0 = 0.01 d0/d1`` (1e-6 if either is below 1e-5), capped at the
    interval; one explicit Euler step gives ``d2 = ‖(f(t0 + h0, x0 + h0 f0)
    - f0)/sc‖ / h0``; then ``h1 = (0.01 / max(d1, d2))^{1/(q+1)}`` (or
    ``max(1e-6, 1e-3 h0)`` when both are below 1e-15), and the step is
    ``min(100 h0, h1, t_bound - t0, max_step)``. One evaluation of ``f``.
    """
    length = abs(t_bound - t0)
    if x0.size == 0:
        return math.inf
    if length == 0.0:
        return 0.0
    scale = atol + np.abs(x0) * rtol
    d0, d1 = _rms(x0 / scale), _rms(f0 / scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, length)
    f1 = f(t0 + h0, x0 + h0 * f0)
    d2 = _rms((f1 - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1 / (error_order + 1))
    return min(100 * h0, h1, length, max_step)


def slope_breakpoints(T, U) -> np.ndarray:
    """The sample times at which an input linear between its samples changes slope.

    ``T[i]`` (``0 < i < N-1``) is a breakpoint when, for some input row,
    the slopes on either side differ by more than their rounding: more than
    ``16 ε (max(|U_{i-1}|, |U_i|, |U_{i+1}|) / min(ΔT) + |s_{i-1}| + |s_i|)``.
    A ramp sampled on a grid has none; a road profile has nearly all.

    Parameters
    ----------
    T : ndarray (N,)
        Sample times, strictly increasing.
    U : ndarray (k, N)
        The samples, one row per input.

    Returns
    -------
    ndarray
        The breakpoints, increasing.

    Examples
    --------
    >>> T = np.linspace(0, 4, 5)
    >>> slope_breakpoints(T, np.array([[0, 0, 1, 2, 2.0]])).tolist()
    [1.0, 3.0]
    """
    T = np.asarray(T, dtype=float)
    U = np.asarray(U, dtype=float).reshape(-1, T.size)
    if T.size < 3 or U.shape[0] == 0:
        return np.empty(0)
    dT = np.diff(T)
    slopes = np.diff(U, axis=1) / dT
    kink = np.abs(np.diff(slopes, axis=1))
    mag = np.maximum(np.maximum(np.abs(U[:, :-2]), np.abs(U[:, 1:-1])), np.abs(U[:, 2:]))
    noise = (
        16
        * _EPS
        * (mag / np.minimum(dT[:-1], dT[1:]) + np.abs(slopes[:, :-1]) + np.abs(slopes[:, 1:]))
    )
    return T[1:-1][np.any(kink > noise, axis=0)]


@dataclass(frozen=True, eq=False)
class AdaptiveRun:
    """The result of `adaptive_solve`.

    Attributes
    ----------
    t : ndarray (N,)
        The output times reached (all of them unless the run failed).
    x : ndarray (N, n)
        The state at each (time first).
    accepted_times : ndarray
        The start and the end of every accepted step: ``n_accepted + 1``
        times, as ``solve_ivp(...).t`` without ``t_eval``.
    n_accepted, n_rejected, nfev : int
        Accepted and rejected steps; right-hand-side evaluations.
    h_max : float
        The largest accepted step [s].
    status : str
        ``'success'`` or ``'failed'`` (the step underflowed or the run
        took `MAX_STEPS` attempts).
    message : str
    """

    t: np.ndarray
    x: np.ndarray
    accepted_times: np.ndarray
    n_accepted: int
    n_rejected: int
    nfev: int
    h_max: float
    status: str
    message: str


class _Loop:
    """One adaptive run: the state, its stages, the counts and the outputs."""

    def __init__(self, f, t_out, x0, tab: ButcherTableau, tol, controller, max_step):
        self.f, self.tab, self.controller, self.max_step = f, tab, controller, max_step
        self.rtol, self.atol = tol
        self.plan = stage_plan(tab)
        self.error_weights = tab.b - tab.b_hat
        self.exponent = -1.0 / (_error_order(tab) + 1)
        # FSAL: the last stage is f at the step's end (last row of a = b, c = 1)
        self.fsal = bool(tab.c[-1] == 1 and np.array_equal(tab.a[-1], tab.b))
        self.dense = _DENSE.get(tab)
        self.t_out = t_out.tolist()
        self.out = np.empty((t_out.size, x0.size), dtype=x0.dtype)
        self.out[0] = x0
        self.j = 1  # the next output to fill
        self.t, self.x = self.t_out[0], x0
        self.k1 = f(self.t, x0)
        self.nfev, self.n_accepted, self.n_rejected, self.h_max = 1, 0, 0, 0.0
        self.accepted = array("d", [self.t])

    def attempt(self, h: float):
        """``(x_new, k, error_norm)`` of a step ``h`` from the current state."""
        v = (self.plan.coefficients * h).tolist()
        k = rk_stages(self.f, self.t, v, self.x, self.plan.stages, [self.k1])
        self.nfev += len(k) - 1
        x_new = rk_end(self.x, v, k, self.plan)
        err = h * (self.error_weights @ np.array(k))
        scale = self.atol + self.rtol * np.maximum(np.abs(self.x), np.abs(x_new))
        return x_new, k, _rms(err / scale)

    def step(self, h_abs: float, t_bound: float):
        """Take one accepted step towards ``t_bound``: the next ``h_abs``, or a failure message."""
        t = self.t
        min_step = 10 * abs(np.nextafter(t, math.inf) - t)
        h_abs = self.max_step if h_abs > self.max_step else max(h_abs, min_step)
        rejected = False
        while True:
            if h_abs < min_step:
                return None, (
                    f"{self.tab.name}: the step fell to {h_abs:.3g} s at t = {t:.9g} s, below "
                    f"the smallest step {min_step:.3g} s the time's precision allows"
                )
            if self.n_accepted + self.n_rejected >= MAX_STEPS:
                return None, (
                    f"{self.tab.name}: gave up after {MAX_STEPS} steps at t = {t:.9g} s; "
                    "loosen rtol/atol"
                )
            t_new = min(t + h_abs, t_bound)
            h = t_new - t
            x_new, k, error_norm = self.attempt(h)
            if error_norm < 1:
                break
            h_abs = abs(h) * self.controller.shrink(error_norm, self.exponent)
            self.n_rejected += 1
            rejected = True
        f_new = k[-1] if self.fsal else self._counted(t_new, x_new)
        self.emit(t, h, x_new, k, f_new)
        self.t, self.x, self.k1 = t_new, x_new, f_new
        self.n_accepted += 1
        self.h_max = max(self.h_max, h)
        self.accepted.append(t_new)
        return abs(h) * self.controller.factor(error_norm, self.exponent, rejected), None

    def _counted(self, t, x):
        self.nfev += 1
        return self.f(t, x)

    def emit(self, t: float, h: float, x_new, k, f_new) -> None:
        """Fill the outputs inside ``(t, t + h]`` from the step's continuous extension."""
        t_new = t + h
        j, stop = self.j, bisect.bisect_right(self.t_out, t_new)
        if stop == j:
            return
        end = stop - 1 if self.t_out[stop - 1] == t_new else stop  # a step end: the state
        if end > j:
            theta = (np.asarray(self.t_out[j:end]) - t) / h
            self.out[j:end] = self.between(h, theta, x_new, k, f_new).T
        if end < stop:
            self.out[end] = x_new
        self.j = stop

    def between(self, h: float, theta: np.ndarray, x_new, k, f_new) -> np.ndarray:
        """The states ``(n, m)`` at ``t + θh`` (``θ``: ``(m,)``) inside the step just accepted."""
        x = self.x[:, None]
        if self.dense is not None:
            powers = np.cumprod(np.broadcast_to(theta, (self.dense.shape[1], theta.size)), axis=0)
            return x + h * ((np.array(k).T @ self.dense) @ powers)
        # cubic Hermite through (x, f) and (x_new, f_new) (HNW I, §II.6, (6.7))
        x1, f0, f1 = x_new[:, None], self.k1[:, None], f_new[:, None]
        return (
            (1 - theta) * x
            + theta * x1
            + theta
            * (theta - 1)
            * ((1 - 2 * theta) * (x1 - x) + (theta - 1) * h * f0 + theta * h * f1)
        )


def _error_order(tab: ButcherTableau) -> int:
    """The pair's error order q (`ButcherTableau.error_order`); a ValueError without ``b_hat``."""
    check_embedded(tab)
    return int(tab.error_order)  # type: ignore[arg-type]  # embedded: an int


def _stops(t0: float, t_end: float, breakpoints) -> list[float]:
    """The times no step crosses: the breakpoints inside ``(t0, t_end)``, then ``t_end``."""
    b = np.unique(np.asarray(breakpoints, dtype=float).reshape(-1))
    return [*b[(b > t0) & (b < t_end)].tolist(), t_end]


def adaptive_solve(
    f,
    t_out: np.ndarray,
    x0: np.ndarray,
    tab: ButcherTableau,
    rtol=None,
    atol=None,
    *,
    first_step: float | None = None,
    max_step: float = math.inf,
    breakpoints=(),
    controller: StepController = SCIPY_CONTROLLER,
) -> AdaptiveRun:
    """Solve ``x' = f(t, x)`` over ``[t_out[0], t_out[-1]]`` with step-size control.

    Parameters
    ----------
    f : callable ``f(t, x) -> dx/dt``
    t_out : ndarray (N,)
        Output times, strictly increasing (checked by the caller); the
        first is the start, the last the end.
    x0 : ndarray (n,)
        Initial state (real or complex).
    tab : ButcherTableau
        An embedded pair (``tab.embedded``).
    rtol, atol : float, optional
        Tolerances (`check_tolerances`; None: scipy's 1e-3 and 1e-6).
    first_step : float, optional
        The first step's size; default `initial_step`.
    max_step : float, default inf
        The largest step.
    breakpoints : array_like, optional
        Times at which ``f`` is not smooth in ``t``; no step crosses one.
    controller : StepController, default `SCIPY_CONTROLLER`

    Returns
    -------
    AdaptiveRun
    """
    tol = check_tolerances(rtol, atol, x0.size)
    max_step = positive("max_step", max_step, "s", allow_inf=True)
    loop = _Loop(f, t_out, x0, tab, tol, controller, max_step)
    stops = _stops(loop.t, float(t_out[-1]), breakpoints)
    if first_step is None:
        h_abs = initial_step(f, loop.t, x0, loop.k1, stops[0], _error_order(tab), *tol, max_step)
        loop.nfev += 1
    else:
        h_abs = positive("first_step", first_step, "s")
    status, message = "success", ""
    for t_bound in stops:
        while status == "success" and loop.t < t_bound:
            h_abs, failure = loop.step(h_abs, t_bound)
            if failure is not None:
                status, message = "failed", failure
    return AdaptiveRun(
        t=t_out[: loop.j],
        x=loop.out[: loop.j],
        accepted_times=np.frombuffer(loop.accepted, dtype=float).copy(),
        n_accepted=loop.n_accepted,
        n_rejected=loop.n_rejected,
        nfev=loop.nfev,
        h_max=loop.h_max,
        status=status,
        message=message,
    )
