r"""Model predictive control of the active suspension, with road preview.

`mpc_controller` plans the actuator force over a horizon of ``N`` ticks of
its clock, applies the first move, and plans again at the next tick.

**Prediction.** The car is discretised exactly for a force held over each
tick (zero-order hold) and a road height linear between the ticks (as the
responses interpolate it; a first-order hold):

.. math::

    x_{k+1} = A_d x_k + B_d u_k + E_0 w_k + E_1 w_{k+1},

from one matrix exponential of the block matrix
``[[A, B_u, B_w, 0], [0, 0, 0, 0], [0, 0, 0, I/dt], [0, 0, 0, 0]]·dt``
(Franklin, Powell & Workman, *Digital Control of Dynamic Systems*, 3rd ed.,
§6.3.2; the same as ``control.c2d(sys, dt, 'zoh')`` for the force).

**Cost.** Horizon ``N`` means ``N`` moves ``u_0 … u_{N-1}`` and

.. math::

    J = \sum_{k=0}^{N-1} \big(z_k^\top W z_k + u_k^\top R\, u_k\big)
        + x_N^\top P_f\, x_N,

with ``z_k`` the weighted outputs (body acceleration, travel, tire
deflection: the weights of `qc_control.lqr_controller`, so that the two
compare on equal terms) or, with ``Q`` given, ``z_k = x_k`` and ``W = Q``:
python-control's ``quadratic_cost(sys, Q, R)`` summed over ``N + 1`` time
points. ``P_f`` is 0 unless a terminal cost is asked for.

**Condensed QP.** Stacking the predictions, ``X = Φ x_0 + Γ U + Λ w``, the
cost is ``UᵀHU + 2fᵀU + r`` with the constant Hessian ``H = ΓᵀΩΓ + R̄`` and
the state and the previewed road only in ``f`` (and ``r``). ``H`` is
factored once; an unconstrained controller is then the linear law
``u_0 = -K_x x_0 - K_w w`` (the finite-horizon LQ feedback with preview
feedforward). With limits, the QP goes to DAQP (Arnström, Bemporad &
Axehill, "A dual active-set solver for embedded quadratic programming using
recursive LDLᵀ updates", IEEE TAC 67(8), 2022), a dense active-set method
made for MPC, or on request to OSQP (Stellato et al., "OSQP: an operator
splitting solver for quadratic programs", Math. Prog. Comp. 12, 2020), tuned
for this QP. Either is set up once with the constant ``H`` and constraint
matrix; each tick updates the linear term and the bounds and starts from the
last tick (DAQP from its active set, OSQP from its plan and multipliers
shifted by one tick). DAQP ends on the exact solution of the optimal active
set's equations, so its plans agree with an exact QP solution to rounding
(tests/test_mpc.py: to 1e-6 N against bounded least squares); OSQP's do when
its polishing succeeds, which it did on every tick of a binding force limit
but not on every tick with the soft travel limit (plans up to 0.5 N off:
benchmarks/RESULTS.md, the solvers side by side, where DAQP is also the
faster). A tick whose
unconstrained plan already keeps every limit needs no QP: that plan is the
convex QP's optimum (with no slack), exactly.

**Constraints.** ``|u_k| <= F`` is hard. The suspension travel at the
predicted ticks ``1 … N`` is soft: ``|travel_k| <= s + σ_k``, ``σ_k >= 0``,
with the penalty ``ρ_1 Σ σ_k + ρ_2 Σ σ_k²`` (`TRAVEL_PENALTY`), so the QP
is always feasible; ρ_1 far above the travel constraint's multipliers makes
the penalty exact (the travel limit holds whenever some plan can hold it).
Each tick whose plan needed the slack is logged (``log.penalty_ticks``).

**Preview.** The road ahead over ``preview`` seconds (whole ticks, at most
the horizon) is taken from the road signal; past it the road is held at
its last previewed value. Without preview the controller assumes the road
stays where it is now.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import control
import daqp  # type: ignore[import-not-found]  # a compiled module without type hints
import numpy as np
import osqp
import scipy.linalg
import scipy.sparse as sp

from ..numerics.checks import ParameterError, choice, positive
from ..numerics.limits import check_memory
from ..numerics.threads import one_blas_thread
from .controllers import DEFAULT_LQR_WEIGHTS, lqr_weights, relative_coordinates
from .vehicle import VehicleModel

__all__ = [
    "mpc_controller",
    "sampled_lqr",
    "MPCController",
    "MPCSolution",
    "MPCLog",
    "TRAVEL_PENALTY",
]

#: The soft travel limit's penalty: ``(ρ_1, ρ_2)`` per metre and per metre²
#: of excess at a tick, in the units of the cost. ρ_1 is far above any
#: multiplier of the travel constraint met on the seed car (under 1e3 with
#: the default weights), so the soft limit acts as the hard one when a plan
#: can keep it; ρ_2 keeps the excess small when none can.
TRAVEL_PENALTY = (1e6, 1e8)
#: OSQP tuned for the condensed QP (``solver='osqp'``), whose variables are
#: already the forces in units of the limit (so a tolerance of 1e-5 is 3 mN at
#: 300 N, and the force is good to far better once polishing has solved the
#: active set's equations: measured 3e-12 N against an exact QP solution with a
#: force limit alone; with the soft travel limit polishing does not always
#: succeed, and plans were up to 0.5 N off).
#: ρ starts at 1, the size of a bound in these units, not OSQP's 0.1: on the
#: binding case (benchmarks/run.py) every tick then converges in 25 iterations
#: (one termination check), where ρ 0.1 took 25-75. ρ stays adaptive: fixed,
#: the soft travel rows (another scale) failed to converge in 4,000 iterations
#: on some ticks of a bump. Ruiz scaling stays on: it is done once, at setup.
_OSQP_SETTINGS = dict(
    eps_abs=1e-5,
    eps_rel=1e-5,
    rho=1.0,
    polishing=True,
    polish_refine_iter=3,
    max_iter=20000,
    verbose=False,
)
#: The QP solvers `mpc_controller` offers, the default first.
SOLVERS = ("daqp", "osqp")
#: A slack [m] above this counts as the travel penalty being active.
_SLACK_TOL = 1e-7


@dataclass(frozen=True, eq=False)
class MPCSolution:
    """One solve of the MPC problem.

    Attributes
    ----------
    moves : ndarray (N,)
        The planned forces ``u_0 … u_{N-1}`` [N].
    cost : float
        The optimal cost ``J`` (the travel penalty included, if any).
    solve_time : float
        Wall time of the solve [s].
    slack : ndarray (N,)
        The travel excess ``σ_k`` [m] at the predicted ticks 1 … N (zeros
        without a travel limit).
    status : str
        ``'unconstrained'`` (no limits: the linear law), ``'solved'`` (the
        unconstrained plan keeps the limits, or OSQP solved the QP), or
        OSQP's status otherwise.
    """

    moves: np.ndarray
    cost: float
    solve_time: float
    slack: np.ndarray
    status: str


@dataclass(eq=False)
class MPCLog:
    """What happened at each tick of the last run (reset at its start)."""

    solve_times: list = field(default_factory=list)
    penalty_ticks: list = field(default_factory=list)  # tick times [s] whose plan needed slack
    failures: list = field(default_factory=list)  # tick times whose QP was not solved


def _foh_model(car: VehicleModel, dt: float):
    """``(A_d, B_d, E_0, E_1)``: the force held, the road linear between ticks."""
    sys = car.system
    A = np.asarray(sys.A, float)
    B = np.asarray(sys.B, float)
    j = sys.input_labels.index("fa")
    w = [i for i in range(sys.ninputs) if i != j]
    Bu, Bw = B[:, [j]], B[:, w]
    n, nw = A.shape[0], len(w)
    size = n + 1 + 2 * nw
    big = np.zeros((size, size))
    big[:n, :n] = A
    big[:n, n : n + 1] = Bu
    big[:n, n + 1 : n + 1 + nw] = Bw
    big[n + 1 : n + 1 + nw, n + 1 + nw :] = np.eye(nw) / dt
    E = scipy.linalg.expm(big * dt)
    Ad, Bd = E[:n, :n], E[:n, n : n + 1]
    G1, G2 = E[:n, n + 1 : n + 1 + nw], E[:n, n + 1 + nw :]
    # w(t) = w_k + (w_{k+1} - w_k)·τ/dt: the G1 block carries w_k, G2 the slope
    return Ad, Bd, G1 - G2, G2


def _stage_weights(car: VehicleModel, weights, Q, R):
    """``(C_z, D_z, E_z, W, R_0)``: the stage cost ``zᵀWz + uᵀR_0u``,
    ``z = C_z x + D_z u + E_z w``."""
    sys = car.system
    n = sys.nstates
    j = sys.input_labels.index("fa")
    w_idx = [i for i in range(sys.ninputs) if i != j]
    if Q is not None:
        if weights is not None:
            raise ValueError("give either weights (on outputs) or Q and R (on states), not both")
        Q = _state_weight("Q", Q, list(sys.state_labels))
        Rm = np.array([[positive("R", _scalar(R), description="the weight on the force fa")]])
        return np.eye(n), np.zeros((n, 1)), np.zeros((n, len(w_idx))), Q, Rm
    w = dict(weights) if weights is not None else None
    lqr_weights(car, w)  # the same checks and errors as the LQR's
    w = dict(DEFAULT_LQR_WEIGHTS if w is None else w)
    wf = float(w.pop("fa", 0.0))
    rows = [car.output(label) for label in w]
    C = np.asarray(sys.C, float)[rows]
    D = np.asarray(sys.D, float)[rows]
    return C, D[:, [j]], D[:, w_idx], np.diag(list(w.values())), np.array([[wf]])


def _scalar(value):
    """A 1 × 1 array's one number (R may be given as python-control's (1, 1) R)."""
    if isinstance(value, (list, tuple, np.ndarray)) and np.size(value) == 1:
        return np.asarray(value).reshape(-1)[0]
    return 1.0 if value is None else value


def _state_weight(name: str, value, states: list) -> np.ndarray:
    """``Q`` or ``terminal``: a finite, symmetric positive semi-definite
    ``n × n`` matrix on the car's states, refused by name (numpy would say
    "matmul: Input operand 1 has a mismatch", or the Cholesky factor "leading
    minor not positive definite", naming neither)."""
    n = len(states)
    try:
        M = np.atleast_2d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        M = np.zeros((0, 0))
    if M.shape != (n, n):
        raise ParameterError(
            name, value, f"a ({n}, {n}) matrix on the car's states {states} (this one is {M.shape})"
        )
    if not np.all(np.isfinite(M)):
        raise ParameterError(name, value, "a matrix of finite numbers")
    # symmetric to rounding: the cost reads xᵀMx, but a user's asymmetric M is a slip
    if np.max(np.abs(M - M.T)) > 1e-9 * max(1.0, float(np.max(np.abs(M)))):
        raise ParameterError(name, value, "a symmetric matrix")
    lowest = float(np.linalg.eigvalsh(M).min())
    # eigenvalues to rounding: -1e-12 of the largest is a zero one
    if lowest < -1e-12 * max(1.0, float(np.max(np.abs(M)))):
        raise ParameterError(
            name, value, f"positive semi-definite (its smallest eigenvalue is {lowest:.3g})"
        )
    return M


def _prediction(Ad, Bd, E0, E1, N):
    """``Φ (N+1)n×n``, ``Γ (N+1)n×N``, ``Λ (N+1)n×(N+1)nw``: ``X = Φx_0 + ΓU + Λw``."""
    n, nw = Ad.shape[0], E0.shape[1]
    Phi = np.zeros(((N + 1) * n, n))
    Gam = np.zeros(((N + 1) * n, N))
    Lam = np.zeros(((N + 1) * n, (N + 1) * nw))
    Phi[:n] = np.eye(n)
    for k in range(N):
        r0, r1 = slice(k * n, (k + 1) * n), slice((k + 1) * n, (k + 2) * n)
        Phi[r1] = Ad @ Phi[r0]
        Gam[r1] = Ad @ Gam[r0]
        Gam[r1, k] += Bd[:, 0]
        Lam[r1] = Ad @ Lam[r0]
        Lam[r1, k * nw : (k + 1) * nw] += E0
        Lam[r1, (k + 1) * nw : (k + 2) * nw] += E1
    return Phi, Gam, Lam


class MPCController(control.NonlinearIOSystem):
    """The MPC law: a discrete-time system (``dt > 0``) with output ``fa``.

    Inputs: the car's states (full-state measurement). Closed around the
    car with `qc_control.closed_loop`, it also reads the road at the ticks
    ahead (``preview_ticks``) from the loop. Called as a python-control
    system on its own, it assumes a level road at 0.

    Built by `mpc_controller`; see the module docstring. ``solve(x,
    road_ahead)`` answers one tick; ``log`` holds the last run's solve times
    and the ticks whose plan used the travel slack.
    """

    def __init__(self, qp, dt, horizon, preview_ticks, car_states, name, description):
        self._qp = qp
        self.horizon = int(horizon)
        self.preview_ticks = int(preview_ticks)
        self.description = description
        self.log = MPCLog()
        self._last_u = 0.0
        super().__init__(
            None,
            self._output,
            inputs=list(car_states),
            outputs=["fa"],
            dt=dt,
            name=name,
        )

    # -- the ClockedLaw contract (qc_control.numerics.clocked)
    def reset(self) -> None:
        """Forget the last run's log and warm start."""
        self.log = MPCLog()
        self._qp.reset()

    def tick(self, t, xc, y, ahead):
        """The first planned move at tick ``t`` (`ClockedLaw.tick`)."""
        road = ahead[0] if self.preview_ticks else np.full(1, ahead[0, 0])
        sol = self.solve(y, road)
        self.log.solve_times.append(sol.solve_time)
        if sol.slack.size and float(sol.slack.max()) > _SLACK_TOL:
            self.log.penalty_ticks.append(float(t))
        if sol.status not in ("unconstrained", "solved"):
            self.log.failures.append(float(t))
        return sol.moves[:1], xc

    def _output(self, t, x, u, params):
        return self.solve(np.asarray(u, float), None).moves[:1]

    @one_blas_thread
    def solve(self, x, road_ahead=None) -> MPCSolution:
        """Plan from the car's state ``x`` with the road ``road_ahead``.

        Parameters
        ----------
        x : array_like (n,)
            The car's states, in its order.
        road_ahead : None, float or array_like
            The road height [m] at this tick and the next ones (held at the
            last value past its end); None: a level road at 0.

        Returns
        -------
        MPCSolution
        """
        x = np.asarray(x, dtype=float).reshape(-1)
        if x.size != self.ninputs:
            raise ValueError(
                f"x must hold the car's {self.ninputs} states {self.input_labels}, got {x.size}"
            )
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:  # a NaN state would plan NaN moves and call them 'unconstrained'
            raise ValueError(
                f"x must be finite, got {self.input_labels[bad[0]]} = {float(x[bad[0]])!r}"
            )
        road = np.zeros(1) if road_ahead is None else np.atleast_1d(np.asarray(road_ahead, float))
        if road.ndim != 1 or road.size == 0 or not np.all(np.isfinite(road)):
            raise ValueError(f"road_ahead must be finite road heights [m], got {road_ahead!r}")
        N = self.horizon
        w = np.concatenate([road[: N + 1], np.full(max(0, N + 1 - road.size), road[-1])])
        return self._qp.solve(x, w)

    @property
    def gains(self):
        """``(K_x, K_w)`` of the unconstrained first move ``u_0 = -K_x x - K_w w``."""
        return self._qp.Kx, self._qp.Kw


class _CondensedQP:
    """The condensed problem: constant ``H``, the state and road in ``f`` and the bounds."""

    def __init__(self, model, stage, N, terminal, limits, penalty, travel_row, solver):
        Ad, Bd, E0, E1 = model
        Cz, Dz, Ez, W, R0 = stage
        n = Ad.shape[0]
        Phi, Gam, Lam = _prediction(Ad, Bd, E0, E1, N)
        nz, nw = Cz.shape[0], E0.shape[1]
        Pf = np.zeros((n, n)) if terminal is None else terminal
        # the weighted signals O = F x0 + G U + L w: z_0 … z_{N-1}, then x_N
        F = np.vstack([np.kron(np.eye(N), Cz) @ Phi[: N * n], Phi[N * n :]])
        G = np.vstack(
            [np.kron(np.eye(N), Cz) @ Gam[: N * n] + np.kron(np.eye(N), Dz), Gam[N * n :]]
        )
        Ez_all = np.hstack([np.kron(np.eye(N), Ez), np.zeros((N * nz, nw))])
        L = np.vstack([np.kron(np.eye(N), Cz) @ Lam[: N * n] + Ez_all, Lam[N * n :]])
        Om = scipy.linalg.block_diag(np.kron(np.eye(N), W), Pf)
        self.H = G.T @ Om @ G + np.kron(np.eye(N), R0)
        self.H = (self.H + self.H.T) / 2
        self._GO, self._F, self._L, self._Om = G.T @ Om, F, L, Om
        self._chol = scipy.linalg.cho_factor(self.H)
        # the unconstrained plan U = -H⁻¹ G^T Ω (F x0 + L w): one product per tick
        self._free = scipy.linalg.cho_solve(self._chol, self._GO)
        first = self._free[0]
        self.Kx, self.Kw = first @ F, first @ L
        self.N, self.n = N, n
        # the travel at ticks 1 … N: (from x0, from U, from w); zero rows without a limit
        Ct = np.kron(np.eye(N), np.zeros((1, n)) if travel_row is None else travel_row)
        self._travel = (Ct @ Phi[n:], Ct @ Gam[n:], Ct @ Lam[n:])
        self.limits, self.penalty = limits, penalty
        self._solver = None if not limits else self._setup_solver(solver)

    def _setup_solver(self, solver: str):
        """The scaled QP in ``v = [U/u_s, σ/s_s]``: ``½vᵀPv + qᵀv``, the simple bounds
        on ``v`` first, then the travel rows; handed to DAQP or OSQP, set up once."""
        N = self.N
        F_lim, s_lim = self.limits.get("fa"), self.limits.get("susp_travel")
        us = F_lim if F_lim else 1e3  # forces in units of the limit: a well-scaled QP
        self._us = us
        ns = N if s_lim is not None else 0
        ss = s_lim if s_lim else 1.0
        self._ss = ss
        Hs = us * us * self.H
        self._scale = 1.0 / float(np.max(np.diag(Hs)))
        rho1, rho2 = self.penalty
        P = np.zeros((N + ns, N + ns))
        P[:N, :N] = 2 * self._scale * Hs
        P[N:, N:] = 2 * self._scale * rho2 * ss * ss * np.eye(ns)
        box = np.inf if F_lim is None else 1.0
        lo = [np.full(N, -box), np.zeros(ns)]
        hi = [np.full(N, box), np.full(ns, np.inf)]
        rows = np.zeros((0, N + ns))
        if ns:  # travel_k ≤ s + σ_k and travel_k ≥ -s - σ_k, travel = t0 + G_t U
            Gt = self._travel[1] * us
            rows = np.vstack([np.hstack([Gt, -ss * np.eye(N)]), np.hstack([Gt, ss * np.eye(N)])])
            lo += [np.full(N, -np.inf), np.zeros(N)]
            hi += [np.zeros(N), np.full(N, np.inf)]
        self._ns, self._lo, self._hi = ns, np.concatenate(lo), np.concatenate(hi)
        self._q_slack = self._scale * rho1 * ss * np.ones(ns)
        make = _DAQPSolver if solver == "daqp" else _OSQPSolver
        return make(P, rows, self._lo, self._hi, N)

    def reset(self) -> None:
        if self._solver is not None:
            self._solver.start_at(np.zeros(self.N + self._ns))

    def solve(self, x, w) -> MPCSolution:
        start = time.perf_counter()
        o = self._F @ x + self._L @ w  # the weighted signals with no move
        f, r = self._GO @ o, float(o @ self._Om @ o)
        free = -(self._free @ o)
        travel = self._travel[0] @ x + self._travel[2] @ w + self._travel[1] @ free
        if self._solver is None or self._within_limits(free, travel):
            # the unconstrained optimum is feasible, so it is the QP's (convex) optimum
            # with no slack: exact, and no iteration needed
            cost = float(free @ self.H @ free + 2 * f @ free + r)
            status = "unconstrained" if self._solver is None else "solved"
            slack = np.zeros(self.N if "susp_travel" in self.limits else 0)
            if self._solver is not None:  # the next QP starts here: no constraint active
                self._solver.start_at(np.concatenate([free / self._us, slack / self._ss]))
            return MPCSolution(free, cost, time.perf_counter() - start, slack, status)
        U, sigma, status = self._solve_qp(x, w, f, free)
        cost = float(U @ self.H @ U + 2 * f @ U + r)
        if sigma.size:
            cost += self.penalty[0] * sigma.sum() + self.penalty[1] * sigma @ sigma
        return MPCSolution(U, cost, time.perf_counter() - start, sigma, status)

    def _within_limits(self, U, travel) -> bool:
        F, s = self.limits.get("fa"), self.limits.get("susp_travel")
        return (F is None or bool(np.all(np.abs(U) <= F))) and (
            s is None or bool(np.all(np.abs(travel) <= s))
        )

    def _solve_qp(self, x, w, f, free):
        """``(U, σ, status)`` from the solver, its linear term and bounds updated."""
        N, ns, us, ss = self.N, self._ns, self._us, self._ss
        q = np.concatenate([2 * self._scale * us * f, self._q_slack])
        lo, hi = self._lo.copy(), self._hi.copy()
        if ns:
            t0 = self._travel[0] @ x + self._travel[2] @ w
            s_lim = self.limits["susp_travel"]
            k = N + ns  # the travel rows follow the simple bounds
            hi[k : k + N] = s_lim - t0
            lo[k + N : k + 2 * N] = -s_lim - t0
        solver = self._solver
        assert solver is not None  # only called with limits, which set it up
        v, status = solver.solve(q, lo, hi)
        if not np.all(np.isfinite(v)):  # no solution: the clipped unconstrained plan
            v = np.concatenate([np.clip(free / us, -1, 1), np.zeros(ns)])
        U, sigma = v[:N] * us, np.maximum(v[N:] * ss, 0.0)
        if "fa" in self.limits:  # the box to the bit: a solver meets it to its tolerance
            U = np.clip(U, -self.limits["fa"], self.limits["fa"])
        return U, sigma, status


class _DAQPSolver:
    """DAQP, the dual active-set method for the dense QPs of MPC (Arnström,
    Bemporad & Axehill, "A dual active-set solver for embedded quadratic
    programming using recursive LDLᵀ updates", IEEE TAC 67(8), 2022).

    Set up once (``P``'s factor included); each tick updates the linear term
    and the travel rows' bounds, and starts from the last tick's active set
    (DAQP's workspace keeps it). An active-set method ends on the optimum of
    its final active set, solved exactly, so the plan does not depend on a
    stopping tolerance, and its work is a few rank-one updates per change
    of the active set (measured: a median 9, at most 20 on the binding case).
    ``primal_tol`` 1e-6 is in units of the force limit (3e-4 N at 300 N):
    only how far outside a bound a move may be before it enters the set.
    """

    def __init__(self, P, rows, lo, hi, N):
        self._model = daqp.Model()
        n = P.shape[0]
        self._model.setup(P, np.zeros(n), np.ascontiguousarray(rows), hi, lo)

    def start_at(self, v) -> None:
        """Nothing to do: the last active set is DAQP's start, and a wrong one costs
        one iteration per constraint dropped."""

    def solve(self, q, lo, hi):
        self._model.update(f=q, bupper=hi, blower=lo)
        v, _, flag, _ = self._model.solve()
        return np.asarray(v, dtype=float), "solved" if flag > 0 else f"daqp exit flag {flag}"


class _OSQPSolver:
    """OSQP (Stellato et al., Math. Prog. Comp. 12, 2020), tuned for the small
    dense condensed QP (`_OSQP_SETTINGS`).

    Set up once with the constant ``P`` and constraint matrix, its KKT
    matrix factored once (again only when OSQP adapts ρ). Each QP
    tick starts from the last plan and its multipliers shifted by one tick
    (``u_1 … u_{N-1}, u_{N-1}``: the plan the last tick expected to apply
    now), the standard warm start of MPC; a tick whose unconstrained plan
    kept the limits starts the next from that plan with no constraint active.
    """

    #: shift the last plan by a tick to start the next (False: start where it ended)
    shift_start = True

    def __init__(self, P, rows, lo, hi, N):
        n = P.shape[0]
        self._N = N
        self._osqp = osqp.OSQP()
        A = np.vstack([np.eye(n), rows])
        self._osqp.setup(sp.csc_matrix(np.triu(P)), np.zeros(n), sp.csc_matrix(A), lo, hi,
                         **_OSQP_SETTINGS)  # fmt: skip
        self._m, self._last = lo.size, None

    def start_at(self, v) -> None:
        self._osqp.warm_start(x=v, y=np.zeros(self._m))
        self._last = None

    def solve(self, q, lo, hi):
        if self.shift_start and self._last is not None:
            self._osqp.warm_start(
                x=_shifted(self._last[0], self._N), y=_shifted(self._last[1], self._N)
            )
        self._osqp.update(q=q, l=lo, u=hi)
        res = self._osqp.solve(raise_error=False)
        v = np.asarray(res.x, dtype=float)
        self._last = (v, np.asarray(res.y, dtype=float)) if np.all(np.isfinite(v)) else None
        return v, str(res.info.status)


def _shifted(v, N: int):
    """Each block of ``N`` values (moves, slacks, a row per tick) one tick on, its
    last repeated: where the plan made at the last tick stands at this one."""
    blocks = v.reshape(-1, N)
    return np.concatenate([blocks[:, 1:], blocks[:, -1:]], axis=1).ravel()


def _check_limits(limits) -> dict:
    if limits is None:
        return {}
    if not isinstance(limits, Mapping):
        raise TypeError(f"limits must be a mapping like {{'fa': 500.0}}, got {limits!r}")
    out = {}
    for key, value in limits.items():
        if key not in ("fa", "susp_travel"):
            raise ValueError(f"unknown limit {key!r}; expected 'fa' [N] and/or 'susp_travel' [m]")
        ok = isinstance(value, (int, float, np.number)) and not isinstance(value, bool)
        if not ok or not math.isfinite(float(value)) or float(value) <= 0:
            raise ValueError(f"limits[{key!r}] must be a finite number > 0, got {value!r}")
        out[key] = float(value)
    return out


def _check_penalty(travel_penalty) -> tuple[float, float]:
    """``(ρ_1, ρ_2)``: two finite weights >= 0, not both 0 (a soft limit with
    no cost would not limit; a negative or NaN one makes the QP unbounded)."""
    try:
        rho = tuple(float(p) for p in travel_penalty)
    except (TypeError, ValueError):
        rho = ()
    if len(rho) != 2 or not all(math.isfinite(p) and p >= 0 for p in rho) or not any(rho):
        raise ValueError(
            "travel_penalty must be (rho_1, rho_2), two finite weights >= 0 and not both 0, "
            f"got {travel_penalty!r}"
        )
    return rho


def _check_size(N: int, nz: int, n: int, dt: float) -> None:
    """Refuse a horizon whose condensed matrices would not fit in memory, before
    any is made: the dense output weight Ω is (N·nz + n)², the block matrices
    diag(C_z) and G (N·nz) × (N·n) and N × (N·nz + n); 8 bytes each entry."""
    rows = N * nz + n
    nbytes = 8.0 * (rows * rows + 2 * (N * nz) * (N * n) + 3 * N * rows)
    check_memory(
        nbytes,
        f"an MPC of horizon {N:,} ({N * dt:g} s at dt = {dt:g} s)",
        "use a shorter horizon or a longer dt",
    )


def _preview_ticks(preview, dt: float, horizon: int) -> int:
    if preview is None or preview == 0:
        return 0
    ok = isinstance(preview, (int, float, np.number)) and not isinstance(preview, bool)
    ticks = round(float(preview) / dt) if ok and math.isfinite(float(preview)) else -1
    if ticks < 0 or abs(ticks * dt - float(preview)) > 1e-9 * max(1.0, float(preview)):
        raise ValueError(
            f"preview must be a whole number of controller samples dt = {dt!r} s [s], "
            f"got {preview!r}"
        )
    if ticks > horizon:
        raise ValueError(
            f"preview = {preview!r} s is {ticks} samples, beyond the horizon of {horizon} samples"
        )
    return ticks


def mpc_controller(
    model: VehicleModel,
    dt: float,
    horizon: int,
    *,
    weights: Mapping[str, float] | None = None,
    Q=None,
    R=None,
    terminal=None,
    limits: Mapping[str, float] | None = None,
    preview: float | None = None,
    travel_penalty: tuple[float, float] = TRAVEL_PENALTY,
    solver: str = "daqp",
    name: str = "mpc",
) -> MPCController:
    """A model predictive controller of the actuator force, with road preview.

    See the module docstring for the prediction, the cost, the constraints
    and the preview.

    Parameters
    ----------
    model : VehicleModel
        A linear car with the inputs ``'zr'`` and ``'fa'`` (e.g.
        ``quarter_car_model(params, road=True, actuator=True)``).
    dt : float
        The controller's sample period [s] (> 0).
    horizon : int
        ``N``: the moves planned, ``N >= 1``.
    weights : mapping, optional
        Output label (or ``'fa'``) -> weight, as `qc_control.lqr_controller`
        (its defaults when neither ``weights`` nor ``Q`` is given).
    Q, R : array_like, optional
        Instead of ``weights``: the cost on the car's states (in their
        order) and on the force, python-control's ``quadratic_cost``.
    terminal : array_like, optional
        ``P_f``: a terminal cost ``x_Nᵀ P_f x_N`` (none by default).
    limits : mapping, optional
        ``{'fa': F}``: ``|fa| <= F`` [N], hard; ``{'susp_travel': s}``:
        ``|travel| <= s`` [m], soft with ``travel_penalty``.
    preview : float, optional
        Seconds of road seen ahead: a whole number of ``dt``, at most
        ``horizon·dt``. None: the road is assumed to stay where it is.
    travel_penalty : (float, float)
        ``(ρ_1, ρ_2)`` of the soft travel limit.
    solver : {'daqp', 'osqp'}
        The QP solver used when there are limits: DAQP, a dual active-set
        method made for MPC (the default: on the benchmark's binding case a
        median tick of 0.06 ms against OSQP's 0.25-0.37 ms, and plans equal
        to an exact QP solution to 1e-11 N), or OSQP tuned for this QP
        (`_OSQP_SETTINGS`).
    name : str

    Returns
    -------
    MPCController
    """
    if not isinstance(model, VehicleModel):
        raise TypeError(f"model must be a VehicleModel, got {type(model).__name__}")
    sys = model.system
    if not isinstance(sys, control.StateSpace) or sorted(sys.input_labels) != ["fa", "zr"]:
        raise ValueError(
            f"model {model.name!r} must be a linear car with the inputs 'zr' and 'fa' "
            "(quarter_car_model(params, road=True, actuator=True)), got inputs "
            f"{list(sys.input_labels)}"
        )
    ok = isinstance(dt, (int, float, np.number)) and not isinstance(dt, bool)
    if not ok or not math.isfinite(float(dt)) or float(dt) <= 0:
        raise ValueError(f"dt must be a sample period > 0 [s], got {dt!r}")
    if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
        raise ValueError(f"horizon must be a whole number of samples >= 1, got {horizon!r}")
    choice("solver", solver, SOLVERS)
    dt, N = float(dt), int(horizon)
    lim = _check_limits(limits)
    ticks = _preview_ticks(preview, dt, N)
    stage = _stage_weights(model, weights, Q, R)
    Pf = None if terminal is None else _state_weight("terminal", terminal, list(sys.state_labels))
    travel = None
    if "susp_travel" in lim:
        row = model.output("susp_travel")
        travel = np.asarray(sys.C, float)[[row]]
    penalty = _check_penalty(travel_penalty)
    _check_size(N, stage[0].shape[0], sys.nstates, dt)
    qp = _CondensedQP(_foh_model(model, dt), stage, N, Pf, lim, penalty, travel, solver)
    what = (
        f"N = {N} × {dt * 1e3:g} ms"
        + (f", |fa| ≤ {lim['fa']:g} N" if "fa" in lim else "")
        + (f", travel ≤ {lim['susp_travel'] * 1e3:g} mm (soft)" if "susp_travel" in lim else "")
        + (f", preview {ticks * dt:g} s" if ticks else ", no preview")
    )
    return MPCController(qp, dt, N, ticks, sys.state_labels, name, what)


def sampled_lqr(
    model: VehicleModel,
    dt: float,
    *,
    weights: Mapping[str, float] | None = None,
    limit: float | None = None,
    name: str = "lqr_sampled",
):
    """The LQR on a clock: `qc_control.lqr_controller`'s weights, discretised.

    The discrete LQR (``control.dlqr``) of the car held over ``dt`` (ZOH),
    in the coordinates ``z = [vs, vu, susp_travel, tire_defl]``
    (`qc_control.models.controllers.relative_coordinates`: the road enters
    only through its velocity, which the law does not see), with the cost
    summed at the ticks, ``Σ (z_kᵀ W z_k + w_f u_k²)`` on the weighted
    outputs: the stage cost of `mpc_controller` with the same weights, so
    this is its infinite-horizon, unconstrained, preview-free limit.

    Parameters
    ----------
    model : VehicleModel
        A linear car with the inputs ``'zr'`` and ``'fa'``.
    dt : float
        Sample period [s].
    weights : mapping, optional
        As `qc_control.lqr_controller`.
    limit : float, optional
        The actuator's force limit [N]: the move is clipped to ``±limit``.
    name : str

    Returns
    -------
    control.StateSpace or control.NonlinearIOSystem
        Discrete (``dt``), inputs ``['vs', 'vu', 'susp_travel',
        'tire_defl']``, output ``['fa']``; nonlinear (a clipped gain) with a
        ``limit``.
    """
    ok = isinstance(dt, (int, float, np.number)) and not isinstance(dt, bool)
    if not ok or not math.isfinite(float(dt)) or float(dt) <= 0:
        raise ValueError(f"dt must be a sample period > 0 [s], got {dt!r}")
    Q, R, Nx = lqr_weights(model, weights)
    labels, Tz, _, Az, bz = relative_coordinates(model)
    Ti = np.linalg.inv(Tz)
    # the weighted outputs depend on z alone: the road's terms cancel in these coordinates
    Qz, Nz = Ti.T @ Q @ Ti, Ti.T @ Nx
    d = control.c2d(control.ss(Az, bz, np.eye(Az.shape[0]), 0), float(dt), "zoh")
    K, _, _ = control.dlqr(d.A, d.B, Qz, R, Nz)
    K = np.asarray(K, dtype=float)
    if limit is None:
        return control.ss([], [], [], -K, dt=float(dt), inputs=labels, outputs=["fa"], name=name)
    F = _check_limits({"fa": limit})["fa"]

    def clipped(t, x, u, params):
        return np.clip(-K @ np.asarray(u, float), -F, F)

    return control.nlsys(None, clipped, inputs=labels, outputs=["fa"], dt=float(dt), name=name)
