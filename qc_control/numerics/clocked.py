r"""Sampled-data loops: a continuous linear plant and a controller on a clock.

An electronic control unit samples its sensors at the clock's ticks
``t_k = t_0 + k·dt``, computes a move, and holds it until the next tick
(a zero-order hold). Between ticks the plant is the linear system

.. math::

    \dot x = A x + B_w\, w(t) + B_u\, u_{held}, \qquad
    y_{out} = C x + D_w\, w + D_u\, u_{held},

with the held move constant; at a tick the law reads the measured signals
``y_k = C_m x(t_k) + D_{mw} w(t_k) + D_{mu} u_{held}(t_k^-)`` (a sensor
sampled just before the new move reaches the actuator) and returns a move.
With a computation delay of ``d`` whole ticks, the move computed at tick
``k`` is applied from tick ``k + d`` to tick ``k + d + 1``; the moves queued
before the first (the initial values of the queue) are 0 unless given.

The plant is stepped by a Runge–Kutta tableau at a fixed step ``h`` whose
steps land on every tick (``dt = m·h``, ``m`` whole). For a linear plant
a step of any tableau (explicit or implicit) is affine in the state and in
the forcing at its stages: with ``k = (k_1 … k_s)`` the stage slopes,
``k = (I_s ⊗ A)(1 ⊗ x + h (a ⊗ I) k) + g``, so

.. math::

    (I - h\, a \otimes A)\, k = (1 \otimes A)\, x + g, \qquad
    x_{n+1} = x_n + h\,(b^\top \otimes I)\, k = \Phi x_n + M g,

(Hairer & Wanner, *Solving ODEs II*, §IV.3, the stability function of a
Runge–Kutta method on a linear system). The forcing ``g`` of the road
input at every stage of every step is computed for the whole run at once;
the held move's is ``M (1 ⊗ B_u) u``, one matrix per run. Each step is
then one matrix-vector product.

Knows no vehicle: `qc_control.models.controllers.closed_loop` builds the
`ClockedLoop` of a car and a discrete controller.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import control
import numpy as np

from .. import compat
from .exact import exact_step_matrices
from .sampled import linear_input

__all__ = [
    "ClockedLaw",
    "DiscreteLaw",
    "ClockedLoop",
    "ClockedRun",
    "clock_ratio",
    "affine_step",
    "step_clocked",
    "exact_clocked",
]

#: Relative tolerance on ``dt / h`` being a whole number (rounding of the
#: grid's spacing and of the period, a few ulps of each, not more).
_WHOLE = 1e-9


class ClockedLaw(Protocol):
    """What a controller on a clock provides (the contract of `step_clocked`).

    1. ``nstates``: the number of its own states ``xc``.
    2. ``preview_ticks``: how many ticks ahead of the current one it reads
       the external inputs (0: only the current sample).
    3. ``tick(t, xc, y, ahead) -> (u, xc_next)``: the move at tick time
       ``t`` from its state ``xc``, the measured signals ``y`` and the
       external inputs ``ahead`` (``(nw, preview_ticks + 1)``: at this tick
       and the next ones, held at the last sample past the end of the run).
    4. ``reset()``: called once before a run.
    """

    nstates: int
    preview_ticks: int

    def tick(self, t: float, xc: np.ndarray, y: np.ndarray, ahead: np.ndarray): ...

    def reset(self) -> None: ...


class DiscreteLaw:
    """A discrete-time ``control`` system (``dt > 0``) as a `ClockedLaw`.

    Its difference equation, python-control's convention:
    ``xc[k+1] = f(xc[k], y[k])``, ``u[k] = g(xc[k], y[k])``; for a
    `control.StateSpace`, ``f = A xc + B y`` and ``g = C xc + D y``.
    """

    preview_ticks = 0

    def __init__(self, sys):
        self.sys = sys
        self.nstates = sys.nstates
        if isinstance(sys, control.StateSpace):
            A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
            self._update = lambda t, x, y: A @ x + B @ y
            self._output = lambda t, x, y: C @ x + D @ y
        else:
            self._update = compat.state_derivative(sys)
            self._output = compat.output_function(sys)

    def reset(self) -> None:
        """Nothing to reset: the state travels with the loop's."""

    def tick(self, t, xc, y, ahead):
        u = np.asarray(self._output(t, xc, y), dtype=float).reshape(-1)
        xn = np.asarray(self._update(t, xc, y), dtype=float).reshape(-1) if self.nstates else xc
        return u, xn


def clock_ratio(dt: float, h: float) -> int:
    """``m`` with ``dt = m·h``, or a ValueError naming both.

    Parameters
    ----------
    dt : float
        The controller's sample period [s].
    h : float
        The plant's step [s] (the grid's spacing over ``substeps``).
    """
    ratio = dt / h
    m = round(ratio)
    if m < 1 or abs(ratio - m) > _WHOLE * max(1.0, ratio):
        raise ValueError(
            f"the controller's sample period dt = {dt!r} s is not a whole multiple of the "
            f"car's step h = {h!r} s (dt/h = {ratio:.12g}): choose T's spacing and substeps "
            "so that the steps land on every tick"
        )
    return m


def affine_step(A: np.ndarray, tab, h: float) -> tuple[np.ndarray, np.ndarray]:
    """``(Φ, M)`` of one step of ``tab`` on ``x' = A x + g``: ``x⁺ = Φ x + M g``.

    ``g`` stacks the forcing at the ``s`` stages (``(s·n,)``, stage by
    stage); see the module docstring.
    """
    a, b = np.asarray(tab.a, dtype=float), np.asarray(tab.b, dtype=float)
    n, s = A.shape[0], b.size
    S = np.eye(s * n) - h * np.kron(a, A)
    Bt = h * np.kron(b[None, :], np.eye(n))
    M = Bt @ np.linalg.inv(S)
    Phi = np.eye(n) + M @ np.kron(np.ones((s, 1)), A)
    return Phi, M


@dataclass(eq=False)
class ClockedRun:
    """A stepped sampled-data run, at the output samples.

    Attributes
    ----------
    x : ndarray (n, K)
        Plant states.
    xc : ndarray (nc, K)
        Controller states (constant between ticks).
    held : ndarray (nu·(delay + 1), K)
        The applied move, then the queued ones, after any tick at the sample.
    tick_times : ndarray
        Every tick of the run [s].
    moves : ndarray (nu, ticks)
        The move computed at each tick (applied ``delay`` ticks later).
    steps, nfev : int
        Steps taken and stage evaluations (``steps·s``).
    """

    x: np.ndarray
    xc: np.ndarray
    held: np.ndarray
    tick_times: np.ndarray
    moves: np.ndarray
    steps: int
    nfev: int
    notes: list = field(default_factory=list)


class ClockedLoop(control.NonlinearIOSystem):
    """A continuous linear plant closed by a controller on a clock.

    States: the plant's, the controller's, then the applied move(s)
    ``<u>_held`` and, with a delay, the queued ones ``<u>_queued<i>`` (the
    move applied ``i`` ticks later). Between ticks it is the ordinary
    differential equation of the module docstring, so python-control can
    linearise it; the ticks are applied only by
    `qc_control.input_output_response` (and the responses), which step it
    with `step_clocked`. python-control's own ``input_output_response``
    would hold the initial move for the whole run.

    Parameters
    ----------
    plant : control.StateSpace
        Continuous, inputs: the external ones then the controlled ones.
    nu : int
        The number of controlled inputs (the last ``nu`` of ``plant``).
    measured : tuple of ndarray
        ``(C_m, D_m)``: the law's inputs from the plant's states and inputs.
    law : ClockedLaw
    dt : float
        The sample period [s], > 0.
    delay : int
        Whole ticks of computation delay, >= 0.
    labels : dict
        ``inputs``, ``outputs`` (the plant's then the moves), ``states``
        (plant's and controller's), ``moves``; and ``name``.
    """

    def __init__(self, plant, nu, measured, law, dt, delay, labels, name):
        A, B = np.asarray(plant.A, float), np.asarray(plant.B, float)
        C, D = np.asarray(plant.C, float), np.asarray(plant.D, float)
        nw = B.shape[1] - nu
        n, nc = A.shape[0], law.nstates
        moves = list(labels["moves"])
        hold = [f"{u}_held" for u in moves] + [
            f"{u}_queued{i}" for i in range(1, delay + 1) for u in moves
        ]
        self.plant_matrices = (A, B[:, :nw], B[:, nw:], C, D[:, :nw], D[:, nw:])
        Cm, Dm = measured
        self.measured = (np.asarray(Cm, float), np.asarray(Dm, float)[:, :nw])
        self.measured_move = np.asarray(Dm, float)[:, nw:]
        self.law, self.period, self.delay, self.nu = law, float(dt), int(delay), nu
        self.sizes = (n, nc, nu * (delay + 1))
        super().__init__(
            self._between_ticks,
            self._loop_output,
            inputs=list(labels["inputs"]),
            outputs=[*labels["outputs"], *moves],
            states=[*labels["states"], *hold],
            name=name,
        )

    def _between_ticks(self, t, x, w, params=None):
        A, Bw, Bu = self.plant_matrices[:3]
        n = self.sizes[0]
        u = x[self.sizes[0] + self.sizes[1] :][: self.nu]
        xdot = np.zeros_like(np.asarray(x, dtype=float))
        xdot[:n] = A @ x[:n] + Bw @ np.asarray(w, float).reshape(-1) + Bu @ u
        return xdot

    def _loop_output(self, t, x, w, params=None):
        C, Dw, Du = self.plant_matrices[3:]
        n = self.sizes[0]
        u = x[self.sizes[0] + self.sizes[1] :][: self.nu]
        y = C @ x[:n] + Dw @ np.asarray(w, float).reshape(-1) + Du @ u
        return np.concatenate([y, u])

    def outputs_of(self, X: np.ndarray, W: np.ndarray) -> np.ndarray:
        """The loop's outputs ``(p + nu, K)`` at many samples: states ``X``, inputs ``W``."""
        C, Dw, Du = self.plant_matrices[3:]
        n, nc, _ = self.sizes
        U = X[n + nc : n + nc + self.nu]
        return np.vstack([C @ X[:n] + Dw @ W + Du @ U, U])


def _check_grid(T: np.ndarray) -> float:
    H = np.diff(T)
    if H.size == 0 or np.ptp(H) > 1e-9 * H.max():
        raise ValueError(
            "a sampled-data loop needs a uniform time grid T (steps that land on every "
            f"tick), got spacings from {H.min():.6g} to {H.max():.6g} s"
        )
    return float(H.mean())


def _stage_forcing(loop: ClockedLoop, tab, T, W, h, steps, M):
    """The road's forcing term ``M g_w`` of every step at once, ``(steps, n)``."""
    Bw = loop.plant_matrices[1]
    c = np.asarray(tab.c, dtype=float)
    starts = T[0] + h * np.arange(steps)
    stage_t = np.minimum(starts[:, None] + h * c[None, :], T[-1])
    Wst = linear_input(T, W).at(stage_t)  # (steps, s, nw)
    g = (Wst @ Bw.T).reshape(steps, -1)  # (steps, s·n): stage by stage
    return g @ M.T


def _ahead(road, t: float, dt: float, ticks: int, t_end: float) -> np.ndarray:
    """The external inputs at this tick and the next ``ticks``, held past ``t_end``."""
    times = np.minimum(t + dt * np.arange(ticks + 1), t_end)
    return road.at(times).T


def _interval_maps(Phi: np.ndarray, Mu: np.ndarray, m: int):
    """``Φ^j`` and ``S_j = Σ_{i<j} Φ^i M_u`` for ``j = 0 … m``: a held move's steps."""
    n = Phi.shape[0]
    P = np.empty((m + 1, n, n))
    S = np.empty((m + 1, n, Mu.shape[1]))
    P[0], S[0] = np.eye(n), 0.0
    for j in range(m):
        P[j + 1] = Phi @ P[j]
        S[j + 1] = S[j] + P[j] @ Mu
    return P, S


def _road_within(gw: np.ndarray, Phi: np.ndarray, m: int, intervals: int) -> np.ndarray:
    """``R[k, j]``: the road's part of the state ``j`` steps into tick interval ``k``,
    from 0 at the tick (all intervals at once, one step of each per pass)."""
    n = Phi.shape[0]
    flat = np.zeros((intervals * m, n))
    flat[: gw.shape[0]] = gw
    G = flat.reshape(intervals, m, n)
    R = np.zeros((intervals, m + 1, n))
    for j in range(m):
        R[:, j + 1] = R[:, j] @ Phi.T + G[:, j]
    return R


def step_clocked(loop: ClockedLoop, tab, T, W, x0, substeps: int = 1) -> ClockedRun:
    """Step ``loop`` over the uniform grid ``T`` with the tableau ``tab``.

    The steps are affine (`affine_step`), so within a tick interval the
    state ``j`` steps after tick ``k`` is ``Φ^j x_k + R_{k,j} + S_j u_k``
    (``R`` the road's part, the same for every run of the law): the loop
    over the ticks is one product per tick, and the states at the output
    samples are then formed all at once. The same values as stepping one
    step at a time, in another order of the sums.

    Parameters
    ----------
    loop : ClockedLoop
    tab : ButcherTableau
    T : ndarray (K,)
        Uniform output times [s]; the plant's step is ``h = ΔT / substeps``
        and the controller's period must be a whole multiple of it.
    W : ndarray (nw, K)
        External inputs at ``T``, linear between the samples.
    x0 : ndarray
        The loop's initial state (plant, controller, held and queued moves).
    substeps : int

    Returns
    -------
    ClockedRun

    Raises
    ------
    ValueError
        For a non-uniform ``T`` or a period that is not a whole multiple of ``h``.
    """
    T = np.asarray(T, dtype=float)
    h = _check_grid(T) / substeps
    steps = (T.size - 1) * substeps
    A, _, Bu = loop.plant_matrices[:3]
    Phi, M = affine_step(A, tab, h)
    s = np.asarray(tab.b).size
    Mu = M @ np.kron(np.ones((s, 1)), Bu)
    gw = _stage_forcing(loop, tab, T, W, h, steps, M)
    return _affine_run(loop, T, W, x0, substeps, (Phi, Mu, gw), s)


def exact_clocked(loop: ClockedLoop, T, W, x0, substeps: int = 1) -> ClockedRun:
    """The exact response of ``loop`` on the uniform grid ``T``, tick by tick.

    Between two ticks the plant is linear and time-invariant, its move
    held and the road linear between its samples, so over each of the
    steps ``h = ΔT / substeps`` (which land on every tick and every sample)
    its state follows the exact step
    ``x⁺ = e^{Ah} x + Γ₀ w_i + Γ₁ w_{i+1} + (Γ₀ + Γ₁) u`` (`exact_step_matrices`,
    the matrix exponential python-control's ``forced_response`` uses). The
    law is updated at the ticks from this exact state, with the same hold
    and delay queue as `step_clocked`: what every method's run converges to.

    Parameters and raises as `step_clocked` (without the tableau); the
    run's ``steps`` count the exact steps and ``nfev`` is 0.
    """
    T = np.asarray(T, dtype=float)
    h = _check_grid(T) / substeps
    steps = (T.size - 1) * substeps
    A, Bw, Bu = loop.plant_matrices[:3]
    nw = Bw.shape[1]
    Phi, G0, G1 = exact_step_matrices(A, np.hstack([Bw, Bu]), h)
    fine = np.minimum(T[0] + h * np.arange(steps + 1), T[-1])
    Wf = linear_input(T, W).at(fine)  # (steps + 1, nw): the road at every step's ends
    gw = Wf[:-1] @ G0[:, :nw].T + Wf[1:] @ G1[:, :nw].T
    return _affine_run(loop, T, W, x0, substeps, (Phi, G0[:, nw:] + G1[:, nw:], gw), 0)


def _affine_run(loop: ClockedLoop, T, W, x0, substeps: int, step, stages: int) -> ClockedRun:
    """The run of affine steps ``x⁺ = Φ x + g_w[i] + M_u u`` (``step = (Φ, M_u, g_w)``)
    whose law acts at every tick, at the output samples of ``T``."""
    Phi, Mu, gw = step
    h = _check_grid(T) / substeps
    m = clock_ratio(loop.period, h)
    steps = gw.shape[0]
    intervals = -(-steps // m)
    R = _road_within(gw, Phi, m, intervals)
    P, S = _interval_maps(Phi, Mu, m)
    ticks = steps // m + 1
    tick_x, tick_xc, tick_q, moves = _tick_loop(loop, T, W, x0, (P[m], S[m], R[:, m]), ticks)
    # the output samples: step i = j·substeps lies r = i mod m steps after tick i // m
    i = np.arange(T.size) * substeps
    k, r = i // m, i % m
    X = np.einsum("kij,kj->ik", P[r], tick_x[k]) + R[np.minimum(k, intervals - 1), r].T
    X += np.einsum("kij,kj->ik", S[r], tick_q[k, : loop.nu])
    tick_times = T[0] + loop.period * np.arange(ticks)
    return ClockedRun(X, tick_xc[k].T, tick_q[k].T, tick_times, moves, steps, steps * stages)


def _tick_loop(loop: ClockedLoop, T, W, x0, interval, ticks: int):
    """The law at every tick: the states at the ticks, the moves, the hold after each tick."""
    Pm, Sm, Rm = interval
    n, nc, nh = loop.sizes
    nu, d = loop.nu, loop.delay
    road = linear_input(T, W)
    Cm, Dmw = loop.measured
    Dmu = loop.measured_move
    law = loop.law
    law.reset()
    x = np.array(x0[:n], dtype=float)
    xc = np.array(x0[n : n + nc], dtype=float)
    queue = np.array(x0[n + nc :], dtype=float).reshape(d + 1, nu)
    tick_x, tick_xc = np.empty((ticks, n)), np.empty((ticks, nc))
    tick_q, moves = np.empty((ticks, nh)), np.empty((nu, ticks))
    t_end = float(T[-1])
    for k in range(ticks):
        t = float(T[0] + k * loop.period)
        y = Cm @ x + Dmw @ road(t) + Dmu @ queue[0]
        ahead = _ahead(road, t, loop.period, law.preview_ticks, t_end)
        tick_x[k], tick_xc[k] = x, xc
        u, xc = law.tick(t, xc, y, ahead)
        moves[:, k] = u
        queue = np.vstack([queue[1:], u[None, :]]) if d else u[None, :].copy()
        tick_q[k] = queue.reshape(-1)
        if k < Rm.shape[0]:
            x = Pm @ x + Rm[k] + Sm @ queue[0]
    return tick_x, tick_xc, tick_q, moves
