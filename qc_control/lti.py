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

import numpy as np

from .methods import ButcherTableau
from .stability import stability_coefficients

__all__ = ["step_matrices", "affine_scan", "lti_trajectory"]


def step_matrices(method: ButcherTableau, A: np.ndarray, B: np.ndarray, H: float,
                  substeps: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Φ, Γ₀, Γ₁ of one interval of length H split into ``substeps`` steps.

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
    M[..., :n, n:n + m] = B
    M[..., n:n + m, n + m:] = np.eye(m) / H
    coef = stability_coefficients(method)
    hM = h * M
    step = np.broadcast_to(coef[-1] * np.eye(n + 2 * m), M.shape).copy()
    for c in coef[-2::-1]:               # Horner: R(hM) = c0 I + hM (c1 I + hM (...))
        step = hM @ step
        step[..., np.arange(n + 2 * m), np.arange(n + 2 * m)] += c
    interval = step if substeps == 1 else np.linalg.matrix_power(step, substeps)
    phi = interval[..., :n, :n]
    g_u, g_d = interval[..., :n, n:n + m], interval[..., :n, n + m:]
    return phi.copy(), g_u - g_d, g_d.copy()


def _powers(phi: np.ndarray, L: int) -> np.ndarray:
    """``P[..., j, :, :] = Φʲ`` for j = 0..L, by doubling (log2 L batched products)."""
    n = phi.shape[-1]
    P = np.empty(phi.shape[:-2] + (L + 1, n, n))
    P[..., 0, :, :] = np.eye(n)
    P[..., 1, :, :] = phi
    k = 1
    while k < L:
        top = min(2 * k, L)
        P[..., k + 1:top + 1, :, :] = P[..., 1:top - k + 1, :, :] @ P[..., k:k + 1, :, :]
        k = top
    return P


def _scan(V: np.ndarray, Q: np.ndarray) -> None:
    """In place: ``V_k <- Σ_{i<=k} Q^{k-i} V_i`` (Hillis–Steele, log2 rounds)."""
    d, total = 1, V.shape[-2]
    while d < total:
        V[..., d:, :] += V[..., :-d, :] @ np.swapaxes(Q, -1, -2)
        Q = Q @ Q
        d *= 2


def affine_scan(phi: np.ndarray, x0: np.ndarray, W: np.ndarray | None, N: int,
                block: int = 16) -> np.ndarray:
    """Solve ``x_0 = x0``, ``x_{k+1} = Φ x_k + W_k`` for k < N-1.

    Parameters
    ----------
    phi : array, shape (..., n, n)
    x0 : array, shape (..., n)
    W : array, shape (..., N-1, n), or None for ``W = 0``
    N : int
        Number of samples.
    block : int, default 16
        Block length L.

    Returns
    -------
    array, shape (..., N, n)

    Notes
    -----
    With ``c_b`` the state at the start of block ``b``,

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
    L = max(1, min(block, N - 1))
    nb = -(-(N - 1) // L)
    P = _powers(phi, L)
    # V: the carries' scan input; V_0 = x0, V_{b+1} = Y_{b,L}
    V = np.zeros(batch + (nb + 1, n))
    V[..., 0, :] = x0
    if W is not None:
        Wb = np.zeros(batch + (nb * L, n))
        Wb[..., :N - 1, :] = W
        Wb = Wb.reshape(batch + (nb, L * n))
        # M[(i, a), (q, c)] = (Φ^{q-i})[c, a] for i <= q: row block i feeds Y_{b, q+1}
        lag = np.arange(L)[None, :] - np.arange(L)[:, None]          # q - i
        M = np.swapaxes(P[..., np.clip(lag, 0, L), :, :], -1, -2)     # (..., i, q, a, c)
        M = M * (lag >= 0)[:, :, None, None]
        M = np.swapaxes(M, -3, -2).reshape(batch + (L * n, L * n))    # (..., (i,a), (q,c))
        Y = (Wb @ M).reshape(batch + (nb, L, n))                      # Y_{b, q+1}
        V[..., 1:, :] = Y[..., :, L - 1, :]
    _scan(V, P[..., L, :, :])
    # x_{bL+j} = Φ^j c_b: one product with [Φ^0ᵀ ... Φ^{L-1}ᵀ]
    stacked = np.swapaxes(np.swapaxes(P[..., :L, :, :], -1, -2), -3, -2)  # (..., a, j, c)
    body = (V[..., :nb, :] @ stacked.reshape(batch + (n, L * n))).reshape(batch + (nb, L, n))
    if W is not None:
        body[..., :, 1:, :] += Y[..., :, :L - 1, :]
    X = np.empty(batch + (nb * L + 1, n))
    X[..., :nb * L, :] = body.reshape(batch + (nb * L, n))
    X[..., nb * L, :] = V[..., nb, :]
    return X[..., :N, :]


def lti_trajectory(method: ButcherTableau, A, B, T: np.ndarray, U: np.ndarray | None,
                   x0: np.ndarray, substeps: int = 1) -> np.ndarray:
    """The method's states on a uniform grid T, shape ``(n, len(T))``.

    ``U`` is ``(ninputs, len(T))`` or None. The result equals
    `qc_control.integrate` on ``f = A x + B u(t)`` up to rounding.
    """
    H = (T[-1] - T[0]) / (T.size - 1)
    phi, g_lo, g_hi = step_matrices(method, A, B, H, substeps)
    W = None
    if U is not None and U.size and np.any(U):
        W = U[:, :-1].T @ g_lo.T + U[:, 1:].T @ g_hi.T
    # Without input there is no block-Toeplitz product, so longer blocks
    # (fewer scan rounds) win; with input, 16 keeps that product small.
    return affine_scan(phi, x0, W, T.size, block=16 if W is not None else 32).T
