"""The LTI engine: each method's own trajectory without a Python loop per step.

On ``x' = A x + B u(t)`` with ``u`` linear between samples, one step of an
explicit Runge–Kutta method is affine in the state and in the two input
samples around it:

.. math::

    x_{k+1} = \\Phi\\, x_k + \\Gamma_0\\, u_k + \\Gamma_1\\, u_{k+1},
    \\qquad \\Phi = R(hA)

(HW II, §IV.2 for R). `step_matrices` finds Φ, Γ₀, Γ₁ exactly, as R of an
augmented matrix that carries the input (the construction python-control
uses with exp). `affine_scan` then solves
the recurrence in blocks of ``L`` steps: a table of powers Φʲ for
``j <= L`` (built by doubling), one product with a block-Toeplitz matrix
of those powers for the input's effect inside every block, and a
log-depth scan for the states where blocks start. There is no Python loop
over steps or blocks, only over the log2 rounds of the scans.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .integrate import DivergenceWarning, Solution, check_substeps, check_time_grid, uniform_step
from .methods import ButcherTableau, get_method
from .stability import stability_coefficients

__all__ = ["step_matrices", "affine_scan", "lti_trajectory", "lti_solve"]


def step_matrices(
    method: ButcherTableau, A: np.ndarray, B: np.ndarray, H: float, substeps: int = 1
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Φ, Γ₀, Γ₁ of one interval of length H split into ``substeps`` steps.

    Works on a batch: ``A`` of shape ``(..., n, n)`` and ``B`` of shape
    ``(..., n, m)`` give ``Φ (..., n, n)`` and ``Γ (..., n, m)``.

    Notes
    -----
    The input, linear over the interval, is made part of the state:
    ``z = [x, u, δ]`` with ``u' = δ/H`` and ``δ' = 0``, where
    ``δ = u_{k+1} - u_k``. Then

    .. math:: z' = M z, \quad M = \begin{bmatrix} A & B & 0 \\
              0 & 0 & I/H \\ 0 & 0 & 0 \end{bmatrix}

    is autonomous and linear, and an explicit Runge–Kutta method integrates
    the linear ``u`` exactly at every stage (``u = u_k + c_i δ h/H``), so one
    step is exactly ``R(hM)`` and the interval is ``R(hM)^s``. This is the
    construction python-control's `forced_response` uses with ``exp``.
    """
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    n, m = A.shape[-1], B.shape[-1]
    batch = A.shape[:-2]
    h = H / substeps
    M = np.zeros(batch + (n + 2 * m, n + 2 * m))
    M[..., :n, :n] = A
    M[..., :n, n : n + m] = B
    M[..., n : n + m, n + m :] = np.eye(m) / H
    coef = stability_coefficients(method)
    hM = h * M
    step = np.broadcast_to(coef[-1] * np.eye(n + 2 * m), M.shape).copy()
    for c in coef[-2::-1]:  # Horner: R(hM) = c0 I + hM (c1 I + hM (...))
        step = hM @ step
        step[..., np.arange(n + 2 * m), np.arange(n + 2 * m)] += c
    interval = step if substeps == 1 else np.linalg.matrix_power(step, substeps)
    phi = interval[..., :n, :n]
    g_u, g_d = interval[..., :n, n : n + m], interval[..., :n, n + m :]
    return phi.copy(), g_u - g_d, g_d.copy()


def _powers(phi: np.ndarray, L: int) -> np.ndarray:
    """``P[..., j, :, :] = Φʲ`` for j = 0..L, by doubling (log2 L batched products)."""
    n = phi.shape[-1]
    P = np.empty(phi.shape[:-2] + (L + 1, n, n))
    P[..., 0, :, :] = np.eye(n)
    if L == 0:
        return P
    P[..., 1, :, :] = phi
    k = 1
    while k < L:
        top = min(2 * k, L)
        P[..., k + 1 : top + 1, :, :] = P[..., 1 : top - k + 1, :, :] @ P[..., k : k + 1, :, :]
        k = top
    return P


def _scan(V: np.ndarray, Q: np.ndarray) -> None:
    """In place: ``V_k <- Σ_{i<=k} Q^{k-i} V_i`` (Hillis–Steele, log2 rounds)."""
    d, total = 1, V.shape[-2]
    while d < total:
        V[..., d:, :] += V[..., :-d, :] @ np.swapaxes(Q, -1, -2)
        Q = Q @ Q
        d *= 2


def _free_response(phi, x0, N, C, time_last):
    """``x_k = Φ^k x0`` with no recurrence: ``x_{j·nb+b} = (Φ^nb)^j Φ^b x0``.

    Two power tables of ~√N entries and one product, whose result is laid
    out (signal, j, b), i.e. time-last in time order.
    """
    n = phi.shape[-1]
    batch = phi.shape[:-2]
    nb = max(1, math.ceil(math.sqrt(N)))
    L = math.ceil(N / nb)
    Pb = _powers(phi, nb)
    xb = (Pb[..., :nb, :, :] @ x0[..., None, :, None])[..., 0]  # (..., b, a): Φ^b x0
    Pj = _powers(Pb[..., nb, :, :], L - 1)  # (Φ^nb)^j
    obs = Pj if C is None else C[..., None, :, :] @ Pj  # (..., j, r, a)
    p = obs.shape[-2]
    lhs = np.swapaxes(obs, -3, -2).reshape(batch + (p * L, n))  # rows (r, j)
    out = (lhs @ np.swapaxes(xb, -1, -2)).reshape(batch + (p, L * nb))[..., :N]
    return out if time_last else np.swapaxes(out, -1, -2)


def affine_scan(
    phi: np.ndarray,
    x0: np.ndarray,
    W: np.ndarray | None,
    N: int,
    block: int = 16,
    C: np.ndarray | None = None,
    time_last: bool = False,
) -> np.ndarray:
    r"""Solve ``x_0 = x0``, ``x_{k+1} = Φ x_k + W_k`` for k < N-1; return x or C x.

    Parameters
    ----------
    phi : array, shape (..., n, n)
    x0 : array, shape (..., n)
    W : array, shape (..., N-1, n), or None for ``W = 0``
    N : int
        Number of samples.
    block : int, default 16
        Block length L.
    C : array, shape (..., p, n), optional
        Return ``y_k = C x_k`` instead of the states, computed without
        forming them (``C Φ^j`` is folded into the last product).
    time_last : bool, default False
        Return ``(..., p, N)`` (time last, contiguous per signal) instead
        of ``(..., N, p)``, without a separate transposing copy.

    Returns
    -------
    array, shape (..., N, p): p = n, or the rows of ``C``

    Notes
    -----
    Without input (``W = None``) there is no recurrence to solve:
    ``x_{j·nb+b} = (Φ^nb)^j Φ^b x0`` with ``nb ≈ √N``. With input, and
    ``c_b`` the state at the start of block ``b``,

    .. math::

        x_{bL+j} = Φ^j c_b + Y_{b,j}, \quad
        Y_{b,j} = \sum_{i<j} Φ^{j-1-i} W_{bL+i}, \quad
        c_{b+1} = Φ^L c_b + Y_{b,L}.

    ``Y`` for every block is one product with the block-Toeplitz matrix of
    powers ``Φ^{q-i}``; the carries ``c_b`` are a log-depth scan with
    powers of ``Φ^L``; the states are one product with ``[Φ^0 ... Φ^{L-1}]``.
    """
    n = phi.shape[-1]
    batch = phi.shape[:-2]
    x0 = np.broadcast_to(np.asarray(x0, dtype=float), batch + (n,))
    if N == 1:
        return x0[..., None, :].copy()
    if W is None:
        return _free_response(phi, x0, N, C, time_last)
    L = max(1, min(block, N - 1))
    nb = -(-(N - 1) // L)
    P = _powers(phi, L)
    # Y_{b, q+1} for every block: one product with the block-Toeplitz matrix
    # M[(i, a), (q, c)] = (Φ^{q-i})[c, a] for i <= q (row block i feeds Y_{b, q+1})
    Wb = np.zeros(batch + (nb * L, n))
    Wb[..., : N - 1, :] = W
    lag = np.arange(L)[None, :] - np.arange(L)[:, None]  # q - i
    M = np.swapaxes(P[..., np.clip(lag, 0, L), :, :], -1, -2)  # (..., i, q, a, c)
    M = np.swapaxes(M * (lag >= 0)[:, :, None, None], -3, -2).reshape(batch + (L * n, L * n))
    Y = (Wb.reshape(batch + (nb, L * n)) @ M).reshape(batch + (nb, L, n))
    # the carries c_b: V_0 = x0, V_{b+1} = Y_{b,L}, scanned with powers of Φ^L
    V = np.empty(batch + (nb + 1, n))
    V[..., 0, :] = x0
    V[..., 1:, :] = Y[..., :, L - 1, :]
    _scan(V, P[..., L, :, :])
    # x_{bL+j} = Φ^j c_b + Y_{b,j}: one product with [Φ^0ᵀ ... Φ^{L-1}ᵀ] (or [(CΦ^j)ᵀ])
    obs = P[..., :L, :, :] if C is None else C[..., None, :, :] @ P[..., :L, :, :]
    p = obs.shape[-2]
    stacked = np.swapaxes(np.swapaxes(obs, -1, -2), -3, -2)  # (..., a, j, r)
    body = (V[..., :nb, :] @ stacked.reshape(batch + (n, L * p))).reshape(batch + (nb, L, p))
    body[..., :, 1:, :] += (Y if C is None else Y @ np.swapaxes(C, -1, -2)[..., None, :, :])[
        ..., :, : L - 1, :
    ]
    last = V[..., nb, :]
    last = last if C is None else (C @ last[..., None])[..., 0]
    if time_last:
        out = np.empty(batch + (p, nb * L + 1))
        out[..., : nb * L].reshape(batch + (p, nb, L))[...] = np.moveaxis(body, -1, -3)
        out[..., nb * L] = last
        return out[..., :N]
    out = np.empty(batch + (nb * L + 1, p))
    out[..., : nb * L, :] = body.reshape(batch + (nb * L, p))
    out[..., nb * L, :] = last
    return out[..., :N, :]


def lti_trajectory(
    method: ButcherTableau,
    A,
    B,
    T: np.ndarray,
    U: np.ndarray | None,
    x0: np.ndarray,
    substeps: int = 1,
) -> np.ndarray:
    """The method's states on a uniform grid T, shape ``(n, len(T))``.

    ``U`` is ``(ninputs, len(T))`` or None. The result equals
    `qc_control.integrate` on ``f = A x + B u(t)`` up to rounding, on any
    grid that `qc_control.integrate.uniform_step` accepts (the step is
    taken as the mean ``(T[-1] - T[0]) / (len(T) - 1)``).

    Past the method's stability limit the states overflow to inf or nan
    without a RuntimeWarning; `lti_solve` cuts them off and warns.
    """
    H = (T[-1] - T[0]) / (T.size - 1)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        phi, g_lo, g_hi = step_matrices(method, A, B, H, substeps)
        W = None
        if U is not None and U.size and np.any(U):
            W = U[:, :-1].T @ g_lo.T + U[:, 1:].T @ g_hi.T
        # Without input there is no block-Toeplitz product, so longer blocks
        # (fewer scan rounds) win; with input, 16 keeps that product small.
        return affine_scan(phi, x0, W, T.size, block=16 if W is not None else 32).T


def lti_solve(method, A, B, T, U, x0, substeps: int = 1, *, uniform: bool = False) -> Solution:
    """The LTI engine as a `qc_control.integrate.Solution`, cut like `integrate`'s.

    `lti_trajectory` on the grid ``T``, which must be uniform by
    `qc_control.integrate.uniform_step`. If a state is non-finite (a step
    past the stability limit overflows), the solution ends at the last
    finite sample, a `DivergenceWarning` is issued and ``status`` is
    ``'diverged'``: the same contract as the generic stepper's, and no
    numpy RuntimeWarning.

    Parameters
    ----------
    method : str or ButcherTableau
    A : array_like, shape (n, n)
    B : array_like, shape (n, m)
    T : array_like, shape (N,)
        Uniform time grid [s].
    U : ndarray, shape (m, N), or None
        Input samples, linear between them.
    x0 : array_like, shape (n,)
    substeps : int, default 1
    uniform : bool, default False
        The caller has checked ``T`` with `qc_control.integrate.uniform_step`
        already (the responses do); skip checking it again.

    Returns
    -------
    Solution
        ``x`` of shape ``(n, N')``, ``N' <= N``; ``steps`` are those of the
        whole grid (the engine computes every interval at once) and
        ``nfev = stages * steps``, as the generic stepper would count them.

    Raises
    ------
    ValueError
        When ``T`` is not uniform, or a bad ``T`` or ``substeps``.
    """
    tab = get_method(method)
    substeps = check_substeps(substeps)
    if not uniform:
        T = check_time_grid(T, "T")
        if uniform_step(T) is None:
            raise ValueError("the LTI engine needs a uniformly spaced T (see uniform_step)")
    x = lti_trajectory(tab, A, B, T, U, np.asarray(x0, dtype=float), substeps)
    finite = np.isfinite(x).all(axis=0)
    n_keep, status, message = T.size, "success", ""
    if not finite.all():
        n_keep = int(np.argmin(finite))
        status = "diverged"
        message = (
            f"{tab.name}: the state became non-finite after t = {T[n_keep - 1]:.6g}; "
            f"stopped after {n_keep - 1} of {T.size - 1} intervals"
        )
        warnings.warn(message, DivergenceWarning, stacklevel=2)
    steps = (T.size - 1) * substeps  # the engine computes every interval at once
    return Solution(T[:n_keep], x[:, :n_keep], tab.stages * steps, steps, tab, status, message)
