"""The exact response of ``x' = A x + B u`` to inputs linear between uniform samples.

Identification simulates a model hundreds of times under the same recorded
inputs, and the IRI runs one car over a long profile: both need the exact
trajectory (no method error to mistake for a parameter) without a Python
loop per sample. Over one interval of length ``H`` with ``u`` linear,

.. math::

    x_{k+1} = e^{AH} x_k + \\Gamma_0 u_k + \\Gamma_1 u_{k+1},

where the three matrices are blocks of the exponential of the augmented
matrix ``[[A, B, 0], [0, 0, I/H], [0, 0, 0]]`` (the construction
``control.forced_response`` uses, and `qc_control.numerics.lti.step_matrices`
with a Runge–Kutta polynomial in place of ``exp``). The recurrence is then
solved mode by mode: with ``Φ = V Λ V⁻¹`` each modal coordinate is a
first-order recursion, which `scipy.signal.lfilter` runs in compiled code
(about a millisecond for 15 000 samples of a quarter car). A ``Φ`` whose
eigenvectors are nearly parallel (a repeated, critically damped mode) has no
trustworthy modal form; `qc_control.numerics.lti.affine_scan` solves those.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
import scipy.signal

from .lti import affine_scan

__all__ = ["exact_step_matrices", "exact_outputs"]

#: The largest condition number of ``Φ``'s eigenvector matrix for which the
#: modal recursion is used: beyond it, rounding in ``V⁻¹`` would be amplified
#: by more than 1e8, i.e. to about 1e-8 relative, and the scan is used.
MODAL_CONDITION = 1e8


def exact_step_matrices(A, B, H: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``Φ = exp(AH)``, ``Γ₀`` and ``Γ₁`` of one interval of length ``H`` [s].

    ``A (..., n, n)`` and ``B (..., n, m)`` may carry a leading batch.

    Examples
    --------
    >>> phi, g0, g1 = exact_step_matrices([[-1.0]], [[1.0]], 0.5)
    >>> round(float(phi[0, 0]), 6), round(float(g0[0, 0] + g1[0, 0]), 6)  # 1 - exp(-0.5)
    (0.606531, 0.393469)
    """
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    n, m = A.shape[-1], B.shape[-1]
    M = np.zeros(A.shape[:-2] + (n + 2 * m, n + 2 * m))
    M[..., :n, :n] = A * H
    M[..., :n, n : n + m] = B * H
    M[..., n : n + m, n + m :] = np.eye(m)
    E = scipy.linalg.expm(M)
    phi = E[..., :n, :n]
    g_u, g_d = E[..., :n, n : n + m], E[..., :n, n + m :]
    return phi.copy(), g_u - g_d, g_d.copy()


def exact_outputs(A, B, C, D, H: float, U: np.ndarray, x0) -> np.ndarray:
    """``y = C x + D u`` of the exact response on a uniform grid of step ``H``.

    Parameters
    ----------
    A, B, C, D : array_like
        Shapes ``(..., n, n)``, ``(..., n, m)``, ``(..., p, n)``,
        ``(..., p, m)``, with one leading batch shape (or none).
    H : float
        The sample interval [s].
    U : ndarray, shape (m, N)
        The input samples, linear between them (the same for the batch).
    x0 : array_like, shape (..., n)

    Returns
    -------
    ndarray, shape (..., p, N)
    """
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    C, D = np.asarray(C, dtype=float), np.asarray(D, dtype=float)
    U = np.asarray(U, dtype=float)
    phi, g0, g1 = exact_step_matrices(A, B, H)
    x0 = np.broadcast_to(np.asarray(x0, dtype=float), phi.shape[:-1])
    if phi.ndim == 2:
        return _modal_outputs(phi, g0, g1, C, x0, U) + D @ U
    out = np.empty(phi.shape[:-2] + (C.shape[-2], U.shape[1]))
    for index in np.ndindex(phi.shape[:-2]):
        out[index] = _modal_outputs(phi[index], g0[index], g1[index], C[index], x0[index], U)
    return out + D @ U


def _modal_outputs(phi, g0, g1, C, x0, U) -> np.ndarray:
    """``C x`` of ``x_{k+1} = Φ x_k + Γ₀ u_k + Γ₁ u_{k+1}``, mode by mode."""
    lam, V = np.linalg.eig(phi)
    if np.linalg.cond(V) > MODAL_CONDITION:
        W = U[:, :-1].T @ g0.T + U[:, 1:].T @ g1.T
        return affine_scan(phi, x0, W, U.shape[1], C=C, time_last=True)
    Vinv = np.linalg.inv(V)
    # modal inputs: z_{k+1} = λ z_k + e_{k+1}, e_0 = z_0 (lfilter starts from rest)
    E = np.empty((lam.size, U.shape[1]), dtype=complex)
    E[:, 0] = Vinv @ x0
    E[:, 1:] = (Vinv @ g0) @ U[:, :-1] + (Vinv @ g1) @ U[:, 1:]
    Z = np.empty_like(E)
    for i, root in enumerate(lam):
        Z[i] = scipy.signal.lfilter([1.0], [1.0, -root], E[i])
    return ((C @ V) @ Z).real
