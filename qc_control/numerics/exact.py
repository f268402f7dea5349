r"""The exact response of ``x' = A x + B u`` to inputs linear between uniform samples.

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
solved mode by mode: with ``A = V Λ V⁻¹`` each modal coordinate obeys
``z' = λ z + b u`` and steps as

.. math::

    z_{k+1} = e^{λH} z_k + b (γ_0 u_k + γ_1 u_{k+1}), \quad
    γ_1 = \frac{e^{λH} - 1 - λH}{λ^2 H}, \quad γ_0 = \frac{e^{λH} - 1}{λ} - γ_1,

a first-order recursion that `scipy.signal.lfilter` runs in compiled code
(about a millisecond for 15 000 samples of a quarter car, with no matrix
exponential per call). An ``A`` whose eigenvectors are nearly parallel (a
repeated, critically damped mode) has no trustworthy modal form: those go
through the exponential of the augmented matrix and
`qc_control.numerics.lti.affine_scan`.
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
    batch = A.shape[:-2]
    x0 = np.broadcast_to(np.asarray(x0, dtype=float), A.shape[:-1])
    B = np.broadcast_to(B, batch + B.shape[-2:])
    C = np.broadcast_to(C, batch + C.shape[-2:])
    out = np.empty(batch + (C.shape[-2], U.shape[1]))
    for index in np.ndindex(batch):
        args = (A[index], B[index], C[index], x0[index], U, H)
        y = _modal_outputs(*args)
        out[index] = _scanned_outputs(*args) if y is None else y
        out[index] += _narrow(D[index] if D.ndim > 2 else D, U)
    return out


def _modal_outputs(A, B, C, x0, U, H: float) -> np.ndarray | None:
    """``C x`` of the exact response, mode by mode; None when ``A`` has no
    well-conditioned modal form."""
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) > MODAL_CONDITION:
        return None
    Vinv = np.linalg.inv(V)
    lh = lam * H
    small = np.abs(lh) < 1e-8  # a (nearly) pure integrator: the trapezoid is exact
    em1 = np.expm1(lh)
    g1 = np.where(small, H / 2, (em1 - lh) / np.where(small, 1.0, lam * lh))
    g0 = np.where(small, H / 2, em1 / np.where(small, 1.0, lam) - g1)
    b = Vinv @ B
    # modal inputs: z_{k+1} = e^{λH} z_k + e_{k+1}, e_0 = z_0 (lfilter starts from rest)
    E = np.empty((lam.size, U.shape[1]), dtype=complex)
    E[:, 0] = Vinv @ x0
    E[:, 1:] = _narrow(b * g0[:, None], U[:, :-1]) + _narrow(b * g1[:, None], U[:, 1:])
    Z = np.empty_like(E)
    for i, root in enumerate(np.exp(lh)):
        Z[i] = scipy.signal.lfilter([1.0], [1.0, -root], E[i])
    return _narrow(C @ V, Z).real


def _narrow(M: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``M @ X`` for a small ``M`` and a long ``X``, by numpy's own loops: a BLAS call
    for a 4×2 by 2×N product costs more in threading than it computes."""
    return np.einsum("ij,jk->ik", M, X)


def _scanned_outputs(A, B, C, x0, U, H: float) -> np.ndarray:
    phi, g0, g1 = exact_step_matrices(A, B, H)
    W = U[:, :-1].T @ g0.T + U[:, 1:].T @ g1.T
    return affine_scan(phi, x0, W, U.shape[1], C=C, time_last=True)
