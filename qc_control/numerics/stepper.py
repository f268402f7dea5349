"""The stage loop: every explicit Runge–Kutta step taken in Python is taken here.

One step of a tableau ``(A, b, c)`` from ``(t, x)`` with step ``h`` is

.. math::

    k_i = f\\big(t + c_i h,\\; x + h \\textstyle\\sum_{j<i} a_{ij} k_j\\big), \\qquad
    x \\leftarrow x + h \\textstyle\\sum_i b_i k_i ,

scipy's ``rk_step`` (``scipy/integrate/_ivp/rk.py``) over the tableau as
data. The tableau's structure is computed once per tableau (`stage_plan`:
its non-zero entries, so zero entries cost nothing) and scaled by ``h``
once per step size (`GridSteps`). The state may be one state ``(n,)`` or a
batch ``(n, m)`` of ``m`` designs: the loop only adds and scales whole
arrays, so a batched right-hand side steps every design at once with the
same operations, in the same order, as a single one.

Two kinds of right-hand side use the loop:

* a callable ``f(t, x)``, evaluated stage by stage (`rk_steps`): plain
  responses, `qc_control.numerics.integrate.integrate` (and its events),
  the batched nonlinear sweeps' NumPy path;
* a plant that is linear in its state, closed by static nonlinear
  functions (`affine_rk_steps`): the tableau's stage sums are composed with
  the linear part once (`qc_control.numerics.interconnect.FusedSteps`), and
  each stage is then one call of the nonlinear functions, the fused stage
  callback.

Compiled right-hand sides take the same loop compiled
(`qc_control.numerics.compiled_stepper`). `GridSteps.run` takes whole
intervals of an output grid (``substeps`` steps each, every
``substeps``-th state kept) for both Python kinds.

An implicit tableau's stages depend on each other and on themselves:
`ImplicitSteps` solves them at each step by a simplified Newton iteration
(Hairer & Wanner, *Solving ODEs II*, §IV.8), over the same intervals; on a
right-hand side affine in the state, by one linear solve.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.linalg import get_lapack_funcs, lu_factor

from .methods import ButcherTableau

__all__ = [
    "StagePlan",
    "stage_plan",
    "rk_steps",
    "rk_stages",
    "rk_end",
    "affine_rk_steps",
    "GridSteps",
    "sample_steps",
    "ImplicitSteps",
    "NewtonFailure",
    "NEWTON_RTOL",
    "NEWTON_MAXITER",
    "NEWTON_REFRESH_RATE",
]


def __getattr__(name: str):
    """``substeps_for`` moved to `qc_control.numerics.steps`, the one step policy:
    the old name still answers, with a `DeprecationWarning` naming the new one."""
    if name == "substeps_for":
        warnings.warn(
            "qc_control.numerics.stepper.substeps_for moved to "
            "qc_control.numerics.steps.substeps_for",
            DeprecationWarning,
            stacklevel=2,
        )
        # deferred: steps reads stability limits (python-control), which
        # `import qc_control` must not load
        from .steps import substeps_for

        return substeps_for
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True, eq=False)
class StagePlan:
    """A tableau's non-zero entries as loop data (`stage_plan`).

    Attributes
    ----------
    coefficients : ndarray
        The non-zero ``c_i``, ``a_ij`` and ``b_i`` values, each once, after
        a leading 0.0; the rest refers to them by position ``p``. Times
        ``h``, they are one step's row (`GridSteps`).
    stages : tuple
        For each stage ``i >= 1``: ``(p of c_i, ((j, p of a_ij), ...))`` over
        the non-zero ``a_ij`` (a zero ``c_i`` points at the leading 0.0).
    first, others : tuple
        The weights as groups ``(p of b, i0, (i, ...))`` of the stages with
        equal ``b``, summed before they are scaled (RK4's step is
        ``x + h/6 (k1 + k4) + h/3 (k2 + k3)``); the first group apart.
    """

    coefficients: np.ndarray
    stages: tuple
    first: tuple
    others: tuple

    @property
    def time_positions(self) -> list[int]:
        """The positions of ``c_i`` (``i >= 1``) in a row: where each stage's time offset is."""
        return [pc for pc, _ in self.stages]


@functools.lru_cache(maxsize=64)
def stage_plan(tab: ButcherTableau) -> StagePlan:
    """The `StagePlan` of ``tab`` (computed once per tableau).

    Raises
    ------
    ValueError
        For an implicit tableau, whose stages this loop cannot evaluate one
        after another (`ImplicitSteps` steps it).
    """
    if tab.implicit:
        raise ValueError(
            f"tableau {tab.name!r} is implicit: its stages solve equations, and this stage "
            "loop (and the batched and compiled steppers built on it) takes explicit "
            "tableaus only; qc_control.integrate and the responses step implicit ones"
        )
    a, b, c = tab.a.tolist(), tab.b.tolist(), tab.c.tolist()
    coefficients: list[float] = [0.0]

    def at(value: float) -> int:
        coefficients.append(value)
        return len(coefficients) - 1

    stages = tuple(
        (at(c[i]) if c[i] else 0, tuple((j, at(a[i][j])) for j in range(i) if a[i][j] != 0))
        for i in range(1, tab.stages)
    )
    groups: dict[float, list[int]] = {}
    for i, bi in enumerate(b):
        if bi != 0:
            groups.setdefault(bi, []).append(i)
    weights = tuple((at(bi), idx[0], tuple(idx[1:])) for bi, idx in groups.items())
    return StagePlan(np.array(coefficients), stages, weights[0], weights[1:])


def rk_stages(f, t, v, x, stages, k: list) -> list:
    """The stage derivatives of one step: ``k`` (holding ``k_1 = f(t, x)``) with ``k_2 .. k_s``.

    ``v`` is the plan's coefficients times the step's ``h`` (`GridSteps`),
    ``stages`` the plan's `StagePlan.stages`. The first stage is the
    caller's, so that a step-size controller can reuse it across a rejected
    step and take it from the previous step's last stage (FSAL).
    """
    for pc, terms in stages:
        xi = x
        for j, pa in terms:
            xi = xi + v[pa] * k[j]
        k.append(f(t + v[pc], xi))
    return k


def rk_end(x, v, k: list, plan: StagePlan):
    """The step's end ``x + h Σ b_i k_i`` from its stage derivatives ``k`` (`rk_stages`)."""
    pb, i0, rest = plan.first
    ks = k[i0]
    for i in rest:
        ks = ks + k[i]
    x = x + v[pb] * ks
    for pb_, i0_, rest_ in plan.others:
        ks = k[i0_]
        for i in rest_:
            ks = ks + k[i]
        x = x + v[pb_] * ks
    return x


def rk_steps(f, ts, rows, x, out, plan: StagePlan):
    """One step from each time ``ts[k]`` with the row ``rows[k]``; ``out[k + 1]`` its end.

    The stage loop for a callable right-hand side ``f(t, x)``: `rk_stages`
    then `rk_end`. ``rows[k]`` is the plan's coefficients times the step's
    ``h`` (`GridSteps`); ``x`` is ``(n,)`` or a batch ``(n, m)`` (``f``
    then returns ``(n, m)``). Returns the last state.
    """
    stages = plan.stages
    m = 0
    for t, v in zip(ts, rows):
        x = rk_end(x, v, rk_stages(f, t, v, x, stages, [f(t, x)]), plan)
        m += 1
        out[m] = x
    return x


def affine_rk_steps(stage, G, pre, C, times, x, out, first, base, start, stop, width):
    r"""Steps ``start .. stop - 1`` of a plant linear in its state; step ``k``'s end in
    ``out[k + 1 - base]``.

    For ``x' = F x + g(t) + N φ(t, P x + q(t))`` every stage's input is
    affine in the step's start and the earlier stages' values: with the
    tableau composed with ``F`` once (`qc_control.numerics.interconnect.FusedSteps`),
    ``z = G x + pre[k]`` holds every stage's input ``z_i`` (``width`` rows
    each) and, last, the step's end before the stages' values are added.
    Stage ``i`` is then the fused stage callback ``y_i = stage(t_i, z_i)``,
    added to the later stages and the end through ``C[i]`` (``z += C_i y_i``).
    The first stage is at the step's start: its value goes to ``first[k]``
    (the nonlinear functions' value at each sample, kept for the outputs).

    ``C[i]`` may be a column (one scalar output) or a matrix; ``stage``
    returns a number or a vector to match.
    """
    columns = C[0].ndim == 1
    z0, C0 = slice(0, width), C[0]
    later = [(i, slice(i * width, (i + 1) * width), Ci) for i, Ci in enumerate(C)][1:]
    end = len(C) * width
    for k in range(start, stop):
        z = G @ x + pre[k]
        ts = times[k]
        y = first[k] = stage(ts[0], z[z0])
        if columns:
            z += C0 * y
            for i, zi, Ci in later:
                z += Ci * stage(ts[i], z[zi])
        else:
            z += C0 @ y
            for i, zi, Ci in later:
                z += Ci @ stage(ts[i], z[zi])
        x = out[k + 1 - base] = z[end:]
    return x


class GridSteps:
    """A tableau's steps over the intervals of an output grid.

    Each interval ``[t[i], t[i+1]]`` is split into ``substeps`` equal steps
    ``h``; on a uniform grid (``dt`` its step, `qc_control.numerics.integrate.uniform_step`)
    every interval is taken as ``dt``. The rows of coefficients times ``h``
    are formed once for a uniform grid, else once per block of intervals in
    one vectorised product.

    Parameters
    ----------
    tab : ButcherTableau
    t : list of float
        The grid.
    substeps : int
    dt : float or None
    """

    def __init__(self, tab: ButcherTableau, t, substeps: int = 1, dt: float | None = None):
        self.plan = stage_plan(tab)
        self.t, self.substeps, self.dt = t, substeps, dt
        if dt is not None:
            self._row = (self.plan.coefficients * (dt / substeps)).tolist()

    def scratch_bytes(self, x: np.ndarray) -> int:
        """Peak bytes per step of `run`'s block: the step's start time (a Python
        float and its list slot), its row (a shared list on a uniform grid, else
        its own list of floats) and its end state in `sample_steps`' buffer.
        tracemalloc, 100 intervals of 10,000 steps, four states: 72 B uniform,
        424 B for RK4 on a non-uniform grid; this gives 80 B and 504 B."""
        row = 0 if self.dt is not None else 64 + 40 * self.plan.coefficients.size
        return 48 + x.nbytes + row

    def steps(self, start: int, stop: int):
        """``(ts, rows)``: every step's start time and row for intervals ``start .. stop - 1``."""
        tt, ns = self.t, self.substeps
        if self.dt is not None:
            hs = [self.dt / ns] * (stop - start)
            rows = [self._row] * ((stop - start) * ns)
        else:
            hs = [(tt[i + 1] - tt[i]) / ns for i in range(start, stop)]
            rows = (np.repeat(hs, ns)[:, None] * self.plan.coefficients).tolist()
        if ns == 1:
            return tt[start:stop], rows
        return [tt[i] + sub * h for i, h in zip(range(start, stop), hs) for sub in range(ns)], rows

    def run(self, f, x, out, start: int, stop: int):
        """Step ``f`` from ``t[start]`` to ``t[stop]``; ``out[l + 1]`` at ``t[start + l + 1]``.

        Returns the last state (`sample_steps`).
        """
        ts, rows = self.steps(start, stop)
        return sample_steps(
            lambda x, buf: rk_steps(f, ts, rows, x, buf, self.plan),
            x,
            out,
            stop - start,
            self.substeps,
        )

    def step(self, f, t: float, x, h: float, buf):
        """One step of length ``h`` from ``(t, x)`` (event location); ``buf`` ``(2, *x.shape)``."""
        return rk_steps(f, [t], [(self.plan.coefficients * h).tolist()], x, buf, self.plan).copy()


def sample_steps(advance, x, out, intervals: int, substeps: int):
    """Keep the state at the end of each interval: ``out[l + 1]`` for ``l < intervals``.

    ``advance(x, buf)`` takes ``intervals · substeps`` steps, writing step
    ``q``'s end into ``buf[q + 1]``, and returns the last state. With one
    step per interval ``buf`` is ``out``; otherwise a scratch buffer of
    which every ``substeps``-th state is kept.
    """
    if substeps == 1:
        return advance(x, out)
    buf = np.empty((intervals * substeps + 1,) + x.shape, dtype=out.dtype)
    x = advance(x, buf)
    out[1 : intervals + 1] = buf[substeps::substeps]
    return x


#: The simplified Newton iteration has converged when its last correction is at
#: most this times the size of the state or of the stage increments, whichever is
#: larger (max-norm): 1e4 times the rounding of double precision, far below the
#: local error of any step worth taking.
NEWTON_RTOL = 1e-12

#: Iterations of one step's simplified Newton iteration before it is declared
#: not converged. Converging at the rate θ (each correction θ times the last),
#: the iteration is also given up as soon as ``θ^k/(1 - θ)`` times the last
#: correction, for the ``k`` iterations left, cannot reach the tolerance (HW II,
#: §IV.8, eq. 8.14); at θ = 0.5 from a correction of the state's size, 40 are needed.
NEWTON_MAXITER = 50

#: A step whose simplified Newton iteration contracts by less than this per
#: iteration (each correction more than this times the last) has the Jacobian
#: formed anew for the next step; a faster one keeps it (HW II, §IV.8, where
#: RADAU5 keeps it below 1e-3 with an error-controlled tolerance).
NEWTON_REFRESH_RATE = 0.1


class NewtonFailure(ArithmeticError):
    """The stages of one implicit step could not be solved.

    Attributes
    ----------
    t, h : float
        The step's start [s] and length [s].
    reason : str
        Why, in words.
    """

    def __init__(self, t: float, h: float, reason: str):
        super().__init__(f"Newton iteration failed at t = {t:.6g} s, h = {h:.6g} s: {reason}")
        self.t, self.h, self.reason = t, h, reason


class ImplicitSteps:
    r"""An implicit tableau's steps over the intervals of an output grid.

    One step from ``(t, x)`` solves for the stage increments
    ``Z_i = X_i - x``,

    .. math:: Z_i = h \sum_j a_{ij}\, f(t + c_j h,\; x + Z_j),

    by the simplified Newton iteration of HW II, §IV.8 (eq. 8.2): from
    ``Z = 0``, each iteration solves
    ``(I - h\,a \otimes J)\,ΔZ = -(Z - h (a \otimes I) F(Z))`` with one LU
    factorisation per Jacobian and step size, ``J = ∂f/∂x`` at the start
    of a step (kept for later steps while the iteration converges fast:
    `step`): from ``jac`` if given, else by forward differences with
    increments ``√ε · max(1, |x_k|)``. It has converged when ``‖ΔZ‖∞ <=``
    `NEWTON_RTOL` ``· max(‖x‖∞, ‖Z‖∞)``; a correction that does not shrink,
    a non-finite one, or `NEWTON_MAXITER` iterations without convergence
    raise `NewtonFailure`. The end of the step is
    ``x + Σ d_i Z_i`` with ``dᵀ = bᵀA⁻¹`` when ``A`` is invertible (HW II,
    eq. 8.2b), else ``x + h Σ b_i f(t + c_i h, x + Z_i)``.

    With ``linear=True`` the right-hand side is affine in the state,
    ``f(t, x) = J x + g(t)`` with ``J`` the constant ``jac``: the stage
    equations are then linear, and the iteration's first correction from
    ``Z = 0``, ``(I - h\,a \otimes J)\,Z = h (a \otimes I) F(0)``, solves
    them exactly (the later ones are rounding). Each step is that one
    solve with the factors of its step size: ``s`` calls of ``f``, all at
    the step's start, and no convergence test; without ``d`` the end's
    stage derivatives are ``f(t + c_i h, x) + J Z_i``, without calling
    ``f`` again. A non-finite solution raises `NewtonFailure`, as a
    non-finite correction does.

    Parameters
    ----------
    tab : ButcherTableau
        An implicit tableau.
    t : list of float
        The grid.
    substeps : int, default 1
    dt : float or None
        The grid's step if uniform (`qc_control.numerics.integrate.uniform_step`).
    jac : callable ``jac(t, x) -> (n, n)``, optional
        The Jacobian of ``f``.
    linear : bool, default False
        ``f`` is affine in ``x`` and ``jac`` (then required) its constant
        Jacobian: one linear solve per step (class notes).

    Attributes
    ----------
    nfev : int
        Calls of ``f`` made, the Jacobian's differences included.
    jacobians, iterations : int
        Jacobians formed and Newton iterations taken.
    """

    def __init__(
        self, tab: ButcherTableau, t, substeps: int = 1, dt=None, jac=None, linear: bool = False
    ):
        if linear and jac is None:
            raise ValueError("linear=True needs jac, the affine right-hand side's constant matrix")
        self.tab, self.t, self.substeps, self.dt, self.jac = tab, t, substeps, dt, jac
        self.linear = linear
        self.nfev = self.jacobians = self.iterations = 0
        self._J: np.ndarray | None = None  # the Jacobian in use, and its factorisation at _lu_h
        self._lu: tuple[np.ndarray, np.ndarray] | None = None
        self._getrs: Any = None  # LAPACK's solve with those factors, for their dtype
        self._lu_h: float | None = None
        self._c, self._b = tab.c.tolist(), tab.b
        # d = A^-T b when A is safely invertible: the step's end without s more calls of f
        cond = np.linalg.cond(tab.a)
        self._d = np.linalg.solve(tab.a.T, tab.b) if cond < 1e8 else None

    def _jacobian(self, f, t, x) -> np.ndarray:
        if self.jac is not None:
            return np.asarray(self.jac(t, x), dtype=x.dtype).reshape(x.size, x.size)
        f0 = np.asarray(f(t, x))
        delta = np.sqrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(x))
        J = np.empty((x.size, x.size), dtype=np.result_type(x, f0))
        for k in range(x.size):
            xk = x.copy()
            xk[k] += delta[k]
            J[:, k] = (np.asarray(f(t, xk)) - f0) / delta[k]
        self.nfev += x.size + 1
        return J

    def step(self, f, t: float, x, h: float, buf=None):
        """One step of length ``h`` from ``(t, x)``: the new state (``buf`` unused).

        The Jacobian of an earlier step is used again while the iteration
        converges fast with it (HW II, §IV.8: it need only be near ``∂f/∂x``);
        it is formed anew at ``(t, x)`` for the first step, after a step whose
        iteration contracted by less than `NEWTON_REFRESH_RATE` per iteration,
        and before retrying a step that failed with an older one.

        Raises
        ------
        NewtonFailure
            When the stage equations are not solved with a Jacobian formed
            at the step's start (class notes).
        """
        fresh = self._J is None
        if fresh:
            self._refresh(f, t, x)
        if self.linear:
            return self._linear_step(f, t, x, h)
        try:
            return self._newton(f, t, x, h)
        except NewtonFailure:
            if fresh:
                raise
            self._refresh(f, t, x)  # an older Jacobian: one more try with the current one
            return self._newton(f, t, x, h)

    def _refresh(self, f, t, x) -> None:
        self._J = self._jacobian(f, t, x)
        self._lu_h = None
        self.jacobians += 1

    def _factors(self, h: float, n: int):
        """``(J, ha, lu, piv, getrs)``: the kept Jacobian, ``h a`` and the LU factors of
        ``I - h a ⊗ J``, factorised once per Jacobian and step size."""
        J = self._J
        if J is None:  # step makes one before the first iteration
            raise ValueError("the Newton iteration needs a Jacobian: _refresh first")
        ha = h * self.tab.a
        if self._lu is None or self._lu_h != h:
            self._lu = lu_factor(np.eye(self.tab.stages * n) - np.kron(ha, J))
            self._lu_h = h
            funcs: Any = get_lapack_funcs(("getrs",), (self._lu[0],))  # a list, for a tuple
            self._getrs = funcs[0]
        return J, ha, self._lu[0], self._lu[1], self._getrs

    def _linear_step(self, f, t: float, x, h: float):
        """One step of an affine right-hand side: the linear stage equations solved once
        (class notes); the Newton iteration's first correction, to the bit."""
        s, n = self.tab.stages, x.size
        J, ha, lu, piv, getrs = self._factors(h, n)
        F = np.array([f(t + h * c, x) for c in self._c])  # stage_times' operations
        self.nfev += s
        self.iterations += 1
        Z = getrs(lu, piv, (ha @ F).reshape(-1))[0].reshape(s, n)
        if not np.isfinite(Z).all():
            raise NewtonFailure(t, h, "a correction became non-finite")
        if self._d is not None:
            return x + self._d @ Z
        return x + h * (self._b @ (F + Z @ J.T))  # f(t_i, x + Z_i) = f(t_i, x) + J Z_i

    def _newton(self, f, t: float, x, h: float):
        """The simplified Newton iteration of one step with the kept Jacobian."""
        s, n = self.tab.stages, x.size
        times = [t + h * c for c in self._c]  # stage_times' operations: exact input look-ups
        J, ha, lu, piv, getrs = self._factors(h, n)
        Z = np.zeros((s, n), dtype=J.dtype)
        scale, previous, slowest = float(np.max(np.abs(x), initial=0.0)), math.inf, 0.0
        for k in range(NEWTON_MAXITER):
            F = np.array([f(times[j], x + Z[j]) for j in range(s)])
            self.nfev += s
            self.iterations += 1
            # LAPACK's getrs, as scipy.linalg.lu_solve calls it (the same solution to
            # the bit) without lu_solve's checks, which cost 20 times the solve of
            # these few unknowns: this is the implicit step's inner loop
            dZ = getrs(lu, piv, -(Z - ha @ F).reshape(-1))[0].reshape(s, n)
            Z += dZ
            size = float(np.max(np.abs(dZ)))
            if not math.isfinite(size):
                raise NewtonFailure(t, h, "a correction became non-finite")
            tol = NEWTON_RTOL * max(scale, float(np.max(np.abs(Z))))
            if size <= tol:
                break
            self._check_rate(t, h, size, previous, k, tol)
            slowest = max(slowest, size / previous if math.isfinite(previous) else 0.0)
            previous = size
        else:
            raise NewtonFailure(
                t, h, f"not converged in {NEWTON_MAXITER} iterations (last correction {size:.3g})"
            )
        if slowest > NEWTON_REFRESH_RATE:
            self._J = None  # slow: a Jacobian at the next step's start
        if self._d is not None:
            return x + self._d @ Z
        F = np.array([f(times[j], x + Z[j]) for j in range(s)])
        self.nfev += s
        return x + h * (self._b @ F)

    @staticmethod
    def _check_rate(t, h, size, previous, k, tol) -> None:
        """Raise `NewtonFailure` if the iteration diverges, or converges too slowly
        to reach ``tol`` in the iterations left (HW II, §IV.8, eq. 8.14)."""
        if not math.isfinite(previous):
            return
        rate = size / previous if previous > 0 else 0.0
        if rate >= 1:
            raise NewtonFailure(
                t, h, f"the correction grew from {previous:.3g} to {size:.3g} (diverging)"
            )
        left = NEWTON_MAXITER - 1 - k
        if rate**left / (1 - rate) * size > tol:
            raise NewtonFailure(
                t,
                h,
                f"converging too slowly (rate {rate:.3g}) to reach the tolerance in "
                f"{NEWTON_MAXITER} iterations",
            )

    def run(self, f, x, out, start: int, stop: int):
        """Step ``f`` from ``t[start]`` to ``t[stop]``; ``out[l + 1]`` at ``t[start + l + 1]``.

        Each interval's end is written as soon as it is reached, so a
        `NewtonFailure` leaves every sample before the failing interval in
        ``out``. Returns the last state.
        """
        tt, ns = self.t, self.substeps
        for l, i in enumerate(range(start, stop)):
            h = (self.dt if self.dt is not None else tt[i + 1] - tt[i]) / ns
            for sub in range(ns):
                x = self.step(f, tt[i] + sub * h if ns > 1 else tt[i], x, h)
            out[l + 1] = x
        return x
