"""A fixed step checked against the stability limit along a nonlinear trajectory.

On a nonlinear system ``x' = f(t, x, u)`` a fixed-step method behaves
near a state ``x*`` as on its linearisation ``x' = J x`` with the
Jacobian ``J = ∂f/∂x`` there: the step is stable where
``|R(hλ)| <= 1`` for every eigenvalue ``λ`` of ``J``
(`qc_control.numerics.stability.step_is_stable`, the linear engine's own
test). A piecewise law changes ``J`` by orders of magnitude when it
changes branch (a bump stop engaging stiffens the suspension from
``1e4`` to ``1e12`` N/m), so a step chosen at the start can be far beyond
the limit later.

Where to look
-------------
Forming ``J`` costs ``2n`` evaluations of the right-hand side, so it is
formed at a bounded set of samples of the trajectory: the first and the
last; for each state, the sample right after its largest change between
two samples (a stiff branch accelerates the state hardest, and a run that
diverges changes fastest where it diverges); for a single run also each
state's peak and the samples right after located events. A run that
passes the step unstably through a stiff branch is caught at the sample
after its fastest change; one whose stiff branch lasts less than a sample
interval and leaves no mark on the states has not been harmed by it.

Growth past the linearised response
-----------------------------------
A stiff branch visited only between two samples (a stop engaged for a
fraction of a sample interval) leaves no sample in it, but a step beyond
its limit leaves the state grown. So the run is also compared with its
linearisation at the start: with ``z = x - x0``,
``z' = J0 z + w(t)`` where ``w(t) = f(t, x0, u(t))``, and a stable ``J0``
(decay rate ``α = -max Re λ > 0``, eigenvector matrix ``V``) bounds
``‖z(t)‖₂ <= κ(V) sup‖w‖₂ / α`` whatever the input. A run whose
``‖x - x0‖₂`` exceeds `GROWTH_FACTOR` times that bound (at least
`PROBE_FLOOR`) has grown past what its linearisation allows by far more
than a stop, a lift-off or a nonlinear spring changes; an unstable or
marginal ``J0`` gives no bound.

The Jacobian by differences
---------------------------
Column ``j`` is ``(f(x + 2e_j) - f(x + e_j)) / e_j``: a forward
difference that starts one probe away from the sample, so a law with a
jump exactly at the sample (a friction term ``sign(v)`` at rest, a stop
with zero clearance at its contact point) is differenced on one side of
the jump and not read as an infinite stiffness. The probe is
``e_j = PROBE · max(|x_j|, PROBE_FLOOR)``, relative to the state at the
sample itself (not to the run's magnitude: a run that diverged would
otherwise probe from rest far across a stop's contact): the
difference's rounding is then about ``eps |f| / e_j``, far below the
stiffness that matters.
"""

from __future__ import annotations

import numpy as np

from .stability import max_stable_step, settle_marginal, step_is_stable

__all__ = [
    "PROBE",
    "PROBE_FLOOR",
    "jacobians",
    "fastest_changes",
    "first_unstable",
    "growth_limit",
    "GROWTH_FACTOR",
    "unstable_designs",
    "TrajectoryWatch",
]

#: Relative size of the difference probe (module notes): about the square root
#: of the rounding, where truncation and rounding of a forward difference balance.
PROBE = 1e-7
#: The least state magnitude the probe is scaled by (a state at rest is 0): a
#: millimetre, or a millimetre per second, for the vehicles' states.
PROBE_FLOOR = 1e-3


def jacobians(rhs, t, x: np.ndarray, u) -> np.ndarray:
    """``∂f/∂x`` of many states at once, by one-sided differences (module notes).

    Parameters
    ----------
    rhs : callable ``rhs(t, x, u) -> (p, m)``
        The right-hand side over ``m`` columns of states ``x`` ``(n, m)``.
    t, u
        Passed to ``rhs`` as they are.
    x : ndarray (n, m)

    Returns
    -------
    ndarray (m, p, n)
        One Jacobian per column of ``x`` (``p`` rows of ``rhs``: ``n`` for a
        right-hand side).
    """
    n, m = x.shape
    e = PROBE * np.maximum(np.abs(x), PROBE_FLOOR)
    cols = []
    with np.errstate(over="ignore", invalid="ignore"):
        for j in range(n):
            x1, x2 = x.copy(), x.copy()
            x1[j] += e[j]
            x2[j] += 2 * e[j]
            cols.append(((np.asarray(rhs(t, x2, u)) - np.asarray(rhs(t, x1, u))) / e[j]).T)
    return np.stack(cols, axis=-1) if cols else np.empty((m, 0, 0))


#: How far a run may move from its start, in units of its linearisation's
#: bound (module notes): the bound is a worst case already, so a hundredfold
#: excess is growth, not the nonlinearity.
GROWTH_FACTOR = 100.0


def growth_limit(J0: np.ndarray, w_peak) -> np.ndarray:
    """``GROWTH_FACTOR · max(κ(V) sup‖w‖ / α, PROBE_FLOOR)`` per Jacobian (module
    notes): ``J0`` ``(m, n, n)``, ``w_peak`` ``(m,)``; ``inf`` where ``J0`` is
    not finite, not stable or has no full set of eigenvectors."""
    m = J0.shape[0]
    limit = np.full(m, np.inf)
    ok = np.all(np.isfinite(J0), axis=(1, 2)) & np.isfinite(w_peak)
    if not np.any(ok):
        return limit
    lam, V = np.linalg.eig(J0[ok])
    alpha = -np.max(settle_marginal(lam).real, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        kappa = np.linalg.cond(V)
        bound = GROWTH_FACTOR * np.maximum(kappa * np.asarray(w_peak)[ok] / alpha, PROBE_FLOOR)
    limit[ok] = np.where((alpha > 0) & np.isfinite(bound), bound, np.inf)
    return limit


def fastest_changes(x: np.ndarray) -> np.ndarray:
    """For each state, the sample right after its largest change: ``(n,)`` indices
    into the last axis of ``x`` ``(n, N)`` (``N >= 2``); non-finite changes ignored."""
    with np.errstate(invalid="ignore", over="ignore"):
        step = np.abs(np.diff(x, axis=-1))
    step[~np.isfinite(step)] = -1.0
    return np.argmax(step, axis=-1) + 1


def first_unstable(tab, h: float, J: np.ndarray):
    """``(column, h_max)`` of the first Jacobian ``J`` ``(m, n, n)`` whose
    eigenvalues put ``h`` beyond ``tab``'s stability limit, or ``(None, inf)``.

    Non-finite Jacobians (a state that already overflowed) are skipped: the
    run's NaN/inf check reports those.
    """
    ok = np.all(np.isfinite(J), axis=(1, 2))
    if not np.any(ok):
        return None, np.inf
    index = np.flatnonzero(ok)
    eig = np.linalg.eigvals(J[index])
    stable = np.atleast_1d(step_is_stable(tab, h, eig))
    if np.all(stable):
        return None, np.inf
    k = int(np.argmin(stable))
    # the limit of the modes that do not grow by themselves (step_is_stable's test)
    lam = settle_marginal(eig[k])
    return int(index[k]), max_stable_step(tab, lam[lam.real <= 0])


def unstable_designs(tab, h: float, J: np.ndarray) -> np.ndarray:
    """``(m,)`` bool: which of the Jacobians ``J`` ``(m, n, n)`` put ``h`` beyond
    ``tab``'s stability limit (non-finite ones are not judged here)."""
    ok = np.all(np.isfinite(J), axis=(1, 2))
    bad = np.zeros(J.shape[0], dtype=bool)
    if np.any(ok):
        stable = np.atleast_1d(step_is_stable(tab, h, np.linalg.eigvals(J[ok])))
        bad[ok] = ~stable
    return bad


class TrajectoryWatch:
    """Follows ``m`` trajectories block by block and keeps where to look (module notes).

    For each state ``i`` and design ``j``: the sample index right after the
    state's largest change between samples, and the whole state there and
    at the sample before (``states``, ``before``: ``[state, tracker, design]``); and
    each state's range, from which `departure` is read. Memory ``O(n² m)``,
    whatever the number of samples.

    Parameters
    ----------
    x0 : ndarray (n, m)
        The states at sample 0.
    """

    def __init__(self, x0: np.ndarray):
        x0 = np.asarray(x0, dtype=float)
        n, m = x0.shape
        self.first = x0.copy()
        self.prev = x0.copy()
        self.high, self.low = x0.copy(), x0.copy()
        self.jump = np.full((n, m), -1.0)
        self.index = np.zeros((n, m), dtype=int)
        self.states = np.broadcast_to(x0[:, None, :], (n, n, m)).copy()  # [state, tracker, design]
        self.before = self.states.copy()  # the sample before each of those

    @property
    def departure(self) -> np.ndarray:
        """``(m,)``: the 2-norm of each state's largest distance from its start, at
        least the largest ``‖x - x0‖₂`` and at most ``√n`` times it (NaN: ``inf``)."""
        with np.errstate(invalid="ignore", over="ignore"):
            far = np.maximum(self.high - self.first, self.first - self.low)
            norm = np.sqrt(np.sum(far * far, axis=0))
        return np.where(np.isnan(norm), np.inf, norm)

    def update(self, start: int, xb: np.ndarray) -> None:
        """Take in the samples ``start .. start + L - 1`` (``xb`` ``(n, m, L)``, ``start >= 1``).

        The work runs along the samples of ``(n, L, m)``: `simulate_batch`'s
        blocks are laid out so, with each sample's designs contiguous.
        """
        y = np.swapaxes(xb, 1, 2)
        n, L, m = y.shape
        step = np.empty((n, L, m))
        with np.errstate(invalid="ignore", over="ignore"):
            np.subtract(y[:, :1], self.prev[:, None], out=step[:, :1])
            np.subtract(y[:, 1:], y[:, :-1], out=step[:, 1:])
            np.abs(step, out=step)
            np.fmax(self.high, y.max(axis=1), out=self.high)
            np.fmin(self.low, y.min(axis=1), out=self.low)
        best = step.max(axis=1)  # (n, m); NaN where a design diverged: never kept
        better = best > self.jump
        if np.any(better):
            i, j = np.nonzero(better)
            k = np.argmax(step[i, :, j], axis=-1)  # only where the block holds a new largest
            self.jump[i, j] = best[i, j]
            self.index[i, j] = start + k
            self.states[:, i, j] = y[:, k, j]
            self.before[:, i, j] = np.where(k > 0, y[:, np.maximum(k - 1, 0), j], self.prev[:, j])
        self.prev = y[:, -1].copy()
