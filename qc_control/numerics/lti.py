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
import sys
import threading
import warnings
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any

import control
import numpy as np

from .integrate import DivergenceWarning, Solution, check_substeps, check_time_grid, uniform_step
from .methods import ButcherTableau, get_method
from .stability import stability_coefficients
from .threads import one_blas_thread

__all__ = [
    "step_matrices",
    "affine_scan",
    "OutputStream",
    "lti_trajectory",
    "lti_solve",
    "lti_states",
    "memo",
    "array_key",
    "TailBound",
    "is_nonlinear_system",
]

#: How many step maps (and free-response power tables, eigenvalues) `memo` keeps.
MEMO_SIZE = 32
_memo_store: OrderedDict = OrderedDict()
_memo_lock = threading.Lock()


def is_nonlinear_system(sys) -> bool:
    """Whether ``sys`` is a python-control nonlinear I/O system, beyond this engine.

    A `control.NonlinearIOSystem` (an `control.InterconnectedSystem`, a
    `control.nlsys`, a closed loop with a clipped controller) is stepped by
    its right-hand side; a `control.StateSpace` (which python-control 0.10
    derives from `control.NonlinearIOSystem`) or a
    `control.TransferFunction` is linear, and its step map is ``R(hA)``.

    Examples
    --------
    >>> import control
    >>> is_nonlinear_system(control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]))
    False
    >>> is_nonlinear_system(control.nlsys(lambda t, x, u, p: -x, None, states=1))
    True
    """
    return isinstance(sys, control.NonlinearIOSystem) and not isinstance(sys, control.StateSpace)


def array_key(a: np.ndarray) -> tuple:
    """A hashable key for an array's dtype, shape and values (for `memo`)."""
    a = np.asarray(a)
    return (a.dtype.str, a.shape, a.tobytes())


def memo(key: Hashable, build: Callable[[], Any]) -> Any:
    """``build()``, remembered under ``key`` (the `MEMO_SIZE` most recent keys).

    Single responses call the engine again and again on one system and grid
    (a study, a plot, a benchmark); what depends only on ``(A, B, h,
    method)`` - the step map, the eigenvalues, the free response's power
    tables - is built once. Arrays built here are made read-only, so a
    caller cannot change what the next call reads.
    """
    with _memo_lock:
        if key in _memo_store:
            _memo_store.move_to_end(key)
            return _memo_store[key]
    value = build()
    for v in value if isinstance(value, tuple) else (value,):
        if isinstance(v, np.ndarray):
            v.flags.writeable = False
    with _memo_lock:
        _memo_store[key] = value
        while len(_memo_store) > MEMO_SIZE:
            _memo_store.popitem(last=False)
    return value


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

    is autonomous and linear, and a Runge–Kutta method integrates the
    linear ``u`` exactly at every stage (``u = u_k + c_i δ h/H``, as the
    rows of ``a`` sum to ``c``), so one step is exactly ``R(hM)`` and the
    interval is ``R(hM)^s``. This is the construction python-control's
    `forced_response` uses with ``exp``. An explicit method's ``R`` is a
    polynomial, evaluated by Horner's rule; an implicit method's comes from
    one linear solve with ``I - a ⊗ hM`` (`_implicit_step_map`).
    """
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    n, m = A.shape[-1], B.shape[-1]
    batch = A.shape[:-2]
    h = H / substeps
    M = np.zeros(batch + (n + 2 * m, n + 2 * m))
    M[..., :n, :n] = A
    M[..., :n, n : n + m] = B
    M[..., n : n + m, n + m :] = np.eye(m) / H
    hM = h * M
    tab = get_method(method)
    if tab.implicit:
        step = _implicit_step_map(tab, hM)
    else:
        coef = stability_coefficients(tab)
        step = np.broadcast_to(coef[-1] * np.eye(n + 2 * m), M.shape).copy()
        for c in coef[-2::-1]:  # Horner: R(hM) = c0 I + hM (c1 I + hM (...))
            step = hM @ step
            step[..., np.arange(n + 2 * m), np.arange(n + 2 * m)] += c
    interval = step if substeps == 1 else np.linalg.matrix_power(step, substeps)
    phi = interval[..., :n, :n]
    g_u, g_d = interval[..., :n, n : n + m], interval[..., :n, n + m :]
    return phi.copy(), g_u - g_d, g_d.copy()


def _implicit_step_map(tab: ButcherTableau, hM: np.ndarray) -> np.ndarray:
    r"""``R(hM)`` of an implicit tableau: one step on ``z' = Mz``, from one linear solve.

    The stages ``Z_i = z + Σ_j a_ij hM Z_j`` of a step from ``z`` are, with
    ``K_i = hM Z_i``, the solution of

    .. math:: (I - a \otimes hM)\, K = (\mathbf{1} \otimes hM)\, z,
              \qquad z_{+} = z + (b^T \otimes I)\, K

    (HW II, §IV.5 and §IV.8), so ``R(hM) = I + (bᵀ ⊗ I)(I - a ⊗ hM)⁻¹(1 ⊗ hM)``:
    the columns of ``1 ⊗ hM`` solved for at once, for every design of a batch.
    """
    a, b, s = tab.a, tab.b, tab.stages
    N = hM.shape[-1]
    batch = hM.shape[:-2]
    big = np.eye(s * N) - np.einsum("ij,...pq->...ipjq", a, hM).reshape(batch + (s * N, s * N))
    K = np.linalg.solve(big, np.concatenate([hM] * s, axis=-2))
    step = np.broadcast_to(np.eye(N), hM.shape).copy()
    for i in range(s):
        if b[i] != 0:
            step += b[i] * K[..., i * N : (i + 1) * N, :]
    return step


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
        w = top - k
        # Φ^{k+i} = Φ^i Φ^k for i = 1..w: the w left factors stacked as one
        # (w n, n) matrix per design, one product each (not w small ones)
        left = P[..., 1 : w + 1, :, :].reshape(phi.shape[:-2] + (w * n, n))
        P[..., k + 1 : top + 1, :, :] = (left @ P[..., k, :, :]).reshape(phi.shape[:-2] + (w, n, n))
        k = top
    return P


def _scan(V: np.ndarray, Q: np.ndarray) -> None:
    """In place: ``V_k <- Σ_{i<=k} Q^{k-i} V_i`` (Hillis–Steele, log2 rounds)."""
    d, total = 1, V.shape[-2]
    while d < total:
        V[..., d:, :] += V[..., :-d, :] @ np.swapaxes(Q, -1, -2)
        Q = Q @ Q
        d *= 2


def _free_tables(phi: np.ndarray, N: int) -> tuple[np.ndarray, np.ndarray]:
    """`_free_response`'s power tables: ``Φ^b`` for ``b < nb`` and ``(Φ^nb)^j``
    for ``j < L`` (``nb ≈ √N``), which depend only on ``Φ`` and ``N``."""
    nb = max(1, math.ceil(math.sqrt(N)))
    L = math.ceil(N / nb)
    Pb = _powers(phi, nb)
    Pj = _powers(Pb[..., nb, :, :], L - 1)  # (Φ^nb)^j
    return Pb[..., :nb, :, :], Pj


def _free_response(phi, x0, N, C, time_last, tables=None):
    """``x_k = Φ^k x0`` with no recurrence: ``x_{j·nb+b} = (Φ^nb)^j Φ^b x0``.

    Two power tables of ~√N entries (`_free_tables`, or ``tables`` built
    before) and one product, whose result is laid out (signal, j, b), i.e.
    time-last in time order.
    """
    n = phi.shape[-1]
    batch = phi.shape[:-2]
    Pb, Pj = _free_tables(phi, N) if tables is None else tables
    nb, L = Pb.shape[-3], Pj.shape[-3]
    xb = (Pb @ x0[..., None, :, None])[..., 0]  # (..., b, a): Φ^b x0
    obs = Pj if C is None else C[..., None, :, :] @ Pj  # (..., j, r, a)
    p = obs.shape[-2]
    lhs = np.swapaxes(obs, -3, -2).reshape(batch + (p * L, n))  # rows (r, j)
    out = (lhs @ np.swapaxes(xb, -1, -2)).reshape(batch + (p, L * nb))[..., :N]
    return out if time_last else np.swapaxes(out, -1, -2)


def _input_matrix(P, g0, g1, L: int) -> np.ndarray:
    """`_input_offsets`' ``((L+1)k, L n)`` matrix of ``Φ^{q-r}Γ₀ [r<=q] +
    Φ^{q+1-r}Γ₁ [1<=r<=q+1]``: rows (r, input), columns (q, state)."""
    n, k = P.shape[-1], g0.shape[-1]
    batch = P.shape[:-3]
    PG0 = P[..., :L, :, :] @ g0[..., None, :, :]  # Φ^i Γ₀: (..., L, n, k)
    PG1 = P[..., :L, :, :] @ g1[..., None, :, :]
    q, r = np.meshgrid(np.arange(L), np.arange(L + 1), indexing="ij")
    E = np.zeros(batch + (L, L + 1, n, k))  # (q, r)
    lo, hi = r <= q, (r >= 1) & (r <= q + 1)
    E[..., q[lo], r[lo], :, :] += PG0[..., (q - r)[lo], :, :]
    E[..., q[hi], r[hi], :, :] += PG1[..., (q + 1 - r)[hi], :, :]
    return np.moveaxis(E, (-4, -3, -2, -1), (-2, -4, -1, -3)).reshape(batch + ((L + 1) * k, L * n))


def _input_offsets(E, U, N: int, L: int, nb: int) -> np.ndarray:
    """``Y[b, q] = Σ_{i<=q} Φ^{q-i} (Γ₀ u_{bL+i} + Γ₁ u_{bL+i+1})`` from the input samples.

    With ``k`` inputs (fewer than the ``n`` states) one product of each
    block's window ``u_{bL} .. u_{bL+L}`` with the ``((L+1)k, L n)`` matrix
    ``E`` (`_input_matrix`): ``2(L+1)kn`` flops per step instead of the
    ``2L n²`` of the Toeplitz product with ``W``.
    """
    k = U.shape[0]
    n = E.shape[-1] // L
    padded = np.zeros((nb * L + 1, k))
    padded[:N] = U.T
    windows = padded[np.arange(nb)[:, None] * L + np.arange(L + 1)].reshape(nb, (L + 1) * k)
    return (windows @ E).reshape(E.shape[:-2] + (nb, L, n))


#: For a process's first this many design-blocks (designs x blocks of a run), while
#: numba is not loaded, a stream's carries are stepped with NumPy over the designs,
#: one block at a time (`carry_scan_numpy`, the same bits as the compiled loop): the
#: first sweeps of a process then load no numba, 0.3 s of import and cache load, 40x
#: the warm sweep of a hundred designs. NumPy costs ~0.6 µs a design-block more than
#: the compiled loop: past this much work (0.3 s more in all) the loop pays its load.
NUMPY_CARRY_WORK = 500_000
_numpy_carry_work = 0


def carry_scan_numpy(Q: np.ndarray, V: np.ndarray) -> None:
    """`qc_control.numerics.recurrence.carry_scan` in NumPy, the same sums in the
    same order: in place, ``V[:, :, b+1] += Q @ V[:, :, b]``, each row's sum taken
    term by term from the first column, as the compiled loop takes it."""
    _, n, S = V.shape
    for b in range(S - 1):
        v = V[:, :, b]
        acc = Q[:, :, 0] * v[:, 0, None]
        for c in range(1, n):
            acc += Q[:, :, c] * v[:, c, None]
        V[:, :, b + 1] += acc


@one_blas_thread
def affine_scan(
    phi: np.ndarray,
    x0: np.ndarray,
    W: np.ndarray | tuple | None,
    N: int,
    block: int = 16,
    C: np.ndarray | None = None,
    time_last: bool = False,
    tables: tuple | None = None,
) -> np.ndarray:
    r"""Solve ``x_0 = x0``, ``x_{k+1} = Φ x_k + W_k`` for k < N-1; return x or C x.

    Parameters
    ----------
    phi : array, shape (..., n, n)
    x0 : array, shape (..., n)
    W : array, shape (..., N-1, n), or None for ``W = 0``
        Or a tuple ``(Γ₀, Γ₁, U)``, ``U`` of shape ``(k, N)`` and ``W_k = Γ₀
        u_k + Γ₁ u_{k+1}``: the input's effect on each block is then formed
        from windows of ``U`` (`_input_offsets`), never ``W`` itself.
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
    tables : tuple, optional
        ``(P, E)`` built before for this ``Φ`` (and ``Γ``'s) and block
        length: the powers ``Φ^0 .. Φ^L`` (`_powers`) and, for a tuple
        ``W``, the input matrix (`_input_matrix`; else None).

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
    P, E = tables if tables is not None else (_powers(phi, L), None)
    if isinstance(W, tuple):  # (Γ₀, Γ₁, U): the input's samples, not W = Γ₀u + Γ₁u⁺
        g0, g1, U = W
        E = _input_matrix(P, g0, g1, L) if E is None else E
        Y = _input_offsets(E, U, N, L, nb)
    else:
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


class OutputStream:
    r"""The outputs ``y_k = C x_k + D u_k`` of ``x_{k+1} = Φ x_k + Γ₀ u_k + Γ₁ u_{k+1}``,
    in time order, a segment at a time: nothing of length N is kept.

    For many designs (a batch of ``Φ, Γ₀, Γ₁, C, D``) driven by one input
    ``U`` that all share (a road), and for the free response (``U = None``).
    `final` is the last sample, known before the stream starts; iterating
    yields ``(index, y)``: ``y`` of shape ``(..., p) + index.shape`` holds
    the samples numbered ``index`` (every sample but the last exactly once
    over the stream). A segment of ``S`` whole blocks has ``index`` of shape
    ``(L, S)``, ``index[j, s] = (b0 + s) L + j``: the layout the products
    give without a transposing copy; the last segment, cut at sample
    ``N - 2``, has a flat ``index``. A reduction that needs time order reads
    ``index``.

    Parameters
    ----------
    phi : array, shape (..., n, n)
    x0 : array, shape (..., n)
    N : int
        Number of samples (>= 2).
    C : array, shape (..., p, n)
    D, g0, g1 : arrays, shapes (..., p, k), (..., n, k), (..., n, k), optional
        With ``U``: the feedthrough and the step's input matrices
        (`step_matrices`).
    U : array, shape (k, N), optional
        The input samples, the same for every design.
    block : int, default 32
        Block length L.
    segment : int, optional
        Samples per yielded segment (rounded to whole blocks): the memory
        bound, ``designs × p × segment`` doubles. By default about 2¹⁷
        doubles (1 MB) per segment, which stay in cache while the consumer
        reduces them.
    run : int, optional
        Segments per run of carries (by default about 2 MB of carries): the
        carries are computed a run at a time, twice (once to find the last
        sample, once while streaming), so memory does not grow with ``N``.

    Notes
    -----
    With ``c_b = x_{bL}`` the state where block ``b`` starts,

    .. math::

        y_{bL+j} = C Φ^j c_b + \sum_{r=0}^{j} G_{j,r}\, u_{bL+r}, \quad
        c_{b+1} = Φ^L c_b + \sum_{r=0}^{L} E_r\, u_{bL+r},

    with ``G_{j,r} = CΦ^{j-1-r}Γ₀ [r<j] + CΦ^{j-r}Γ₁ [1<=r<=j] + D [r=j]`` and
    ``E_r`` the same for the state at ``j = L`` (no C, no D). Because ``u`` is
    shared, the input's effect on every block of every design is one matrix
    product per design, ``(p L, (L+1)k) @ ((L+1)k, blocks)`` with the input
    windows shared: ``Γ₀u + Γ₁u⁺`` is never formed per design, and each
    product stays small enough for one BLAS thread (a chunk of designs is
    the unit of parallelism). The carries ``c_b`` are one product of the same
    kind and the recurrence ``c_{b+1} = Φ^L c_b + …`` as a compiled loop per
    design (`qc_control.numerics.recurrence.carry_scan`).
    The work per sample and design is ``2(L+1)kp`` flops for the input and
    ``2np`` for the carries: the input's part bounds a forced sweep.
    """

    def __init__(
        self,
        phi,
        x0,
        N: int,
        C,
        D=None,
        g0=None,
        g1=None,
        U=None,
        block: int = 32,
        segment: int | None = None,
        run: int | None = None,
    ):
        phi = np.asarray(phi, dtype=float)
        self.batch = phi.shape[:-2]
        n = phi.shape[-1]
        m = math.prod(self.batch)
        phi = phi.reshape(m, n, n)
        C = np.broadcast_to(np.asarray(C, dtype=float), self.batch + np.shape(C)[-2:])
        p = C.shape[-2]
        C = C.reshape(m, p, n)
        x0 = np.broadcast_to(np.asarray(x0, dtype=float), self.batch + (n,)).reshape(m, n)
        if N < 2:
            raise ValueError(f"N must be at least 2 samples, got {N}")
        L = max(1, min(block, N - 1))
        nb = -(-(N - 1) // L)  # blocks cover samples 0 .. nb L - 1, which hold 0 .. N - 2
        self.N, self.L, self.nb, self.m, self.n, self.p = N, L, nb, m, n, p
        if segment is None:
            segment = (1 << 17) // max(1, m * p)
        self.step = max(1, segment // L)
        # the carries go by longer runs of blocks (about 2 MB of them), each
        # holding whole output segments
        if run is None:
            run = max(1, (1 << 18) // max(1, m * n * self.step))
        self.run = self.step * run
        P = _powers(phi, L)  # (m, L+1, n, n)
        # C Φ^j for j < L as one product per design, C (p, n) @ [Φ^0 .. Φ^{L-1}] laid
        # (n, L n), not L broadcast 4 × 4 ones: (m, p, L, n), row (output, j)
        powers = np.ascontiguousarray(P[:, :L].transpose(0, 2, 1, 3)).reshape(m, n, L * n)
        obs = (C @ powers).reshape(m, p, L, n)
        self._obs = obs
        # the carries' product: (m, p L, n) @ V (m, n, S) -> (m, p, L, S)
        self._obs_mat: np.ndarray | None = None  # built when first streamed (`_observation`)
        self._forced = U is not None
        self._k = 0
        if self._forced:
            self._input_maps(P, C, D, g0, g1, U)
        self._Q = np.ascontiguousarray(P[:, L])
        #: while iterating: the state where the next segment starts (its first block's carry)
        self.carry: np.ndarray | None = None
        self._first_pass(x0, C)

    def _input_maps(self, P, C, D, g0, g1, U) -> None:
        """The input's maps over a block: ``E`` (to the next carry) and ``G`` (to the outputs)."""
        m, n, p, L, nb, N = self.m, self.n, self.p, self.L, self.nb, self.N
        U = np.asarray(U, dtype=float)
        k = self._k = U.shape[0]
        g0 = np.asarray(g0, dtype=float).reshape(m, n, k)
        g1 = np.asarray(g1, dtype=float).reshape(m, n, k)
        D = np.broadcast_to(np.asarray(D, dtype=float), self.batch + (p, k)).reshape(m, p, k)
        self._padded = np.zeros((k, nb * L + 1))
        self._padded[:, :N] = U
        PG0 = P[:, :L] @ g0[:, None]  # Φ^i Γ₀, i < L: (m, L, n, k)
        PG1 = P[:, :L] @ g1[:, None]
        E = np.zeros((m, L + 1, n, k))  # E_r = Φ^{L-1-r}Γ₀ [r<L] + Φ^{L-r}Γ₁ [r>=1]
        E[:, :L] += PG0[:, ::-1]
        E[:, 1:] += PG1[:, ::-1]
        self._E_mat = np.ascontiguousarray(E.transpose(0, 2, 1, 3)).reshape(m, n, (L + 1) * k)
        CPG0, CPG1 = C[:, None] @ PG0, C[:, None] @ PG1  # (m, L, p, k)
        j, r = np.meshgrid(np.arange(L), np.arange(L + 1), indexing="ij")
        G = np.zeros((m, L, L + 1, p, k))
        before, after = r < j, (r >= 1) & (r <= j)
        G[:, j[before], r[before]] += CPG0[:, (j - 1 - r)[before]]
        G[:, j[after], r[after]] += CPG1[:, (j - r)[after]]
        G[:, np.arange(L), np.arange(L)] += D[:, None]
        self._G, self._D = G, D
        # (m, p L, (L+1) k) @ windows (L+1) k x S: row (output, j), column (r, i)
        self._G_mat = np.ascontiguousarray(G.transpose(0, 3, 1, 2, 4)).reshape(
            m, p * L, (L + 1) * k
        )

    def _first_pass(self, x0, C) -> None:
        """The carries segment by segment, keeping only where each segment starts
        (memory: designs × n × segments, not × blocks), their Gram sum and the last sample."""
        m, n, p, L, nb, N = self.m, self.n, self.p, self.L, self.nb, self.N
        obs = self._obs
        starts = np.empty((m, n, -(-nb // self.run) + 1))
        c = np.asarray(x0, dtype=float).copy()
        self._gram_K = np.zeros((m, n, n))  # Σ c_b c_bᵀ over the whole blocks b < nb - 1
        b_last, jl = divmod(N - 1, L)
        carry_last = None
        # with one run, its carries are kept (no second scan while streaming)
        self._one_run: np.ndarray | None = None
        for i, b0 in enumerate(range(0, nb, self.run)):
            starts[:, :, i] = c
            V = self._carries(c, b0, min(b0 + self.run, nb))
            if self.run >= nb:
                self._one_run = V
            upto = min(V.shape[-1] - 1, nb - 1 - b0)
            if upto > 0:
                self._gram_K += V[:, :, :upto] @ np.swapaxes(V[:, :, :upto], -1, -2)
            if b0 <= b_last <= b0 + V.shape[-1] - 1:
                carry_last = V[:, :, b_last - b0].copy()
            if b0 <= nb - 1 <= b0 + V.shape[-1] - 1:
                self._c_partial = V[:, :, nb - 1 - b0].copy()
            c = V[:, :, -1].copy()
        self._starts = starts
        # the last sample, from its block's carry: y_{N-1} = CΦ^j c_b + Σ_r G_{j,r} u_{bL+r}
        assert carry_last is not None
        if jl == 0:
            last = (C @ carry_last[..., None])[..., 0]
            if self._forced:
                last = last + self._D @ self._padded[:, N - 1]
        else:
            last = (obs[:, :, jl] @ carry_last[..., None])[..., 0]
            if self._forced:
                u = self._window(b_last, b_last + 1)[:, 0].reshape(L + 1, self._k)
                last = last + np.einsum("mrpk,rk->mp", self._G[:, jl], u)
        self.final = last.reshape(self.batch + (p,))

    def _window(self, b0: int, b1: int) -> np.ndarray:
        """``((L+1)k, b1 - b0)``: column b holds ``u_{bL} .. u_{bL+L}`` (input by input)."""
        L, k = self.L, self._k
        part = self._padded[:, b0 * L : b1 * L + 1]
        view = np.lib.stride_tricks.as_strided(
            part,
            shape=(L + 1, k, b1 - b0),
            strides=(part.strides[1], part.strides[0], L * part.strides[1]),
            writeable=False,
        )
        return view.reshape((L + 1) * k, b1 - b0)

    def _run_carries(self, i: int, b0: int, b1: int) -> np.ndarray:
        """Run ``i``'s carries (blocks ``b0 .. b1``), kept or scanned again."""
        if self._one_run is not None:
            return self._one_run
        return self._carries(self._starts[:, :, i], b0, b1)

    def _carries(self, c: np.ndarray, b0: int, b1: int) -> np.ndarray:
        """``(m, n, b1 - b0 + 1)``: the carries ``c_{b0} .. c_{b1}`` from ``c = c_{b0}``.

        ``V_0 = c``, ``V_{i+1}`` = the input's effect over block ``b0 + i``,
        then ``V_{i+1} <- Q V_i + V_{i+1}`` with ``Q = Φ^L``, in order
        (`qc_control.numerics.recurrence.carry_scan`). The same arithmetic on both
        passes, so the same bits.
        """
        V = np.zeros((self.m, self.n, b1 - b0 + 1))
        V[:, :, 0] = c
        if self._forced:
            V[:, :, 1:] = np.matmul(self._E_mat, self._window(b0, b1))
        global _numpy_carry_work
        if "numba" not in sys.modules and _numpy_carry_work < NUMPY_CARRY_WORK:
            _numpy_carry_work += V.shape[0] * V.shape[2]
            carry_scan_numpy(self._Q, V)  # a cold process pays no numba for a small sweep
            return V
        # numba: ~0.5 s to import, needed only by a long stream
        from .recurrence import carry_scan

        carry_scan(self._Q, V)  # c_{b+1} = Q c_b + w_{b+1}, a compiled loop per design
        return V

    def block_carries(self) -> np.ndarray:
        """``(m, n, nb + 1)``: the state where every block starts (and the last
        block's end), from the stored run starts (memory: designs × n × blocks)."""
        out = np.empty((self.m, self.n, self.nb + 1))
        for i, r0 in enumerate(range(0, self.nb, self.run)):
            r1 = min(r0 + self.run, self.nb)
            out[:, :, r0 : r1 + 1] = self._run_carries(i, r0, r1)
        return out

    def free_samples(self, row: int, carries: np.ndarray) -> np.ndarray:
        """``(m, L, S)``: streamed output ``row`` over the blocks whose start states are
        ``carries`` ``(m, n, S)``: sample ``j`` of each block (free response only)."""
        L = self.L
        return np.matmul(self._observation()[:, row * L : (row + 1) * L], carries)

    def _observation(self) -> np.ndarray:
        """``(m, p L, n)``: the streamed rows of ``C Φ^j``, row (output, j)."""
        if self._obs_mat is None:
            self._obs_mat = self._obs.reshape(self.m, self.p * self.L, self.n)
        return self._obs_mat

    def keep_rows(self, rows) -> None:
        """Stream only these output rows (`final` keeps them all)."""
        rows = list(rows)
        self.p = len(rows)
        self._obs_mat = np.ascontiguousarray(self._obs[:, rows]).reshape(
            self.m, self.p * self.L, self.n
        )
        if self._forced:
            G = self._G[..., rows, :]
            self._G_mat = np.ascontiguousarray(G.transpose(0, 3, 1, 2, 4)).reshape(
                self.m, self.p * self.L, -1
            )

    def sum_squares(self) -> np.ndarray:
        r"""``Σ_k y_k²`` over every sample, per output, of the free response,
        without the samples: the block Gram matrices of the step map.

        .. math:: \\sum_{k<N} y_{k,r}^2 = \\sum_b c_b^T G_r c_b + y_{N-1,r}^2,
                  \\quad G_r = \\sum_{j<L} (c_r Φ^j)^T (c_r Φ^j)

        (the last, partial block with its own ``G_r``): the same finite sum,
        grouped by block, so exact to rounding, at ``O(n²)`` per block instead
        of ``O(L n)``. Only without input (``U = None``).
        """
        if self._forced:
            raise ValueError("sum_squares is the free response's: this stream has an input")
        L, nb, N = self.L, self.nb, self.N
        obs = self._obs  # (m, p, L, n): C Φ^j
        gram = np.swapaxes(obs, -1, -2) @ obs  # (m, p, n, n)
        total = (gram * self._gram_K[:, None]).sum(axis=(-2, -1))
        J = (N - 1) - (nb - 1) * L  # samples of the last block before sample N - 1
        part = np.swapaxes(obs[:, :, :J], -1, -2) @ obs[:, :, :J]
        c = self._c_partial
        total += ((part @ c[:, None, :, None])[..., 0] * c[:, None, :]).sum(axis=-1)
        final = self.final.reshape(self.m, -1)
        total += final * final
        return total.reshape(self.batch + (final.shape[-1],))

    def __iter__(self):
        """Yield ``(index, y)`` segment by segment.

        ``y`` is a view of a buffer that the next segment overwrites: reduce it
        (or copy it) before asking for the next. Reusing the buffers, rather
        than allocating a segment's outputs (about 1 MB) anew each time, spares
        the page faults of fresh memory, which cost as much as the products
        where the allocator hands large blocks back to the system at once (as
        under Dask's workers, whose ``MALLOC_TRIM_THRESHOLD_`` is set).
        """
        p, L, N = self.p, self.L, self.N
        obs = self._observation()
        full = np.empty((self.m, p * L, self.step))
        extra = np.empty_like(full) if self._forced else None
        for i, r0 in enumerate(range(0, self.nb, self.run)):
            r1 = min(r0 + self.run, self.nb)
            V = self._run_carries(i, r0, r1)
            for b0 in range(r0, r1, self.step):
                b1 = min(b0 + self.step, r1)
                S = b1 - b0
                buf = full if S == self.step else np.empty((self.m, p * L, S))
                out = np.matmul(obs, V[:, :, b0 - r0 : b1 - r0], out=buf)  # (m, p L, S)
                if self._forced:
                    add = extra if S == self.step else np.empty_like(buf)
                    out += np.matmul(self._G_mat, self._window(b0, b1), out=add)
                self.carry = V[:, :, b1 - r0]  # the state at sample b1 L
                index = np.arange(b0, b1)[None, :] * L + np.arange(L)[:, None]  # (L, S)
                y = out.reshape(self.batch + (p, L, S))
                if b1 * L > N - 1:  # the last segment: drop the padding past sample N - 2
                    keep = index < N - 1
                    index, y = index[keep], y[..., keep]
                yield index, y


class TailBound:
    r"""Bounds on every later output of a free recurrence ``x_{k+1} = Φ x_k``.

    With ``Φ = V Λ V⁻¹`` and every ``|λ_i| < 1``,

    .. math::

        y_{K+j,r} = \sum_i (C V)_{ri}\, λ_i^j\, (V^{-1} x_K)_i
        \;\Rightarrow\;
        |y_{K+j,r}| \le β_r(x_K) = \sum_i |(C V)_{ri}|\,|(V^{-1} x_K)_i|
        \quad (j \ge 0),

    the modal expansion of the free response (Kailath, *Linear Systems*,
    1980, §2.2) with ``|λ_i|^j <= 1``. A mode that decays keeps the bound
    tight (one lightly damped pair: β is its envelope). The returned bound
    carries a margin for rounding, ``β (1 + 1e-6) + 1e-12 κ(V) ‖C_r‖₁ ‖x‖∞``
    (``κ`` the 1-norm condition number of ``V``); a design whose ``Φ`` has an
    eigenvalue on or outside the unit circle, or whose ``V`` is
    ill-conditioned (``κ > 1e8``, near-defective), gets ``inf``.

    Parameters
    ----------
    phi : array, shape (m, n, n)
    C : array, shape (m, p, n)
    vectors : array, shape (m, n, n), optional
        Eigenvectors of ``Φ`` computed before: those of ``A`` for the step
        map ``Φ = R(hA)`` of a Runge–Kutta method, a polynomial in ``hA``,
        which has ``A``'s eigenvectors (one decomposition then serves the
        stability check and this bound). ``Φ``'s eigenvalues are then read
        off ``diag(V⁻¹ Φ V)``.
    """

    def __init__(self, phi: np.ndarray, C: np.ndarray, vectors: np.ndarray | None = None):
        phi, C = np.asarray(phi, dtype=float), np.asarray(C, dtype=float)
        m, n = phi.shape[0], phi.shape[-1]
        ok = np.all(np.isfinite(phi), axis=(-2, -1))
        with np.errstate(all="ignore"):
            if vectors is None:
                lam, V = np.linalg.eig(np.where(ok[:, None, None], phi, 0.0))
                ok &= np.abs(lam).max(axis=-1) < 1.0
                W = np.linalg.inv(np.where(ok[:, None, None], V, np.eye(n)))
            else:
                V = np.asarray(vectors)
                ok &= np.all(np.isfinite(V), axis=(-2, -1))
                W = np.linalg.inv(np.where(ok[:, None, None], V, np.eye(n)))
                lam = np.einsum("mij,mjk,mki->mi", W, np.where(ok[:, None, None], phi, 0.0), V)
                ok &= np.abs(lam).max(axis=-1) < 1.0
            # κ₁(V) = ‖V‖₁‖V⁻¹‖₁, the largest column sums
            cond = np.abs(V).sum(axis=-2).max(axis=-1) * np.abs(W).sum(axis=-2).max(axis=-1)
        ok &= np.isfinite(cond) & (cond < 1e8)
        V = np.where(ok[:, None, None], V, np.eye(n))
        self._W = np.where(ok[:, None, None], W, np.eye(n))
        # V⁻¹ as real rows [Re; Im], for products with real states
        self._W_ri = np.concatenate([self._W.real, self._W.imag], axis=1)  # (m, 2n, n)
        self._a = np.abs(C @ V)  # (m, p, n)
        self._abs = 1e-12 * np.where(ok, cond, 0.0)[:, None] * np.abs(C).sum(axis=-1)
        self._ok = ok
        self.m = m

    def __call__(self, x: np.ndarray, rows: slice | None = None) -> np.ndarray:
        """Bounds on ``|y_{k,r}|`` for all ``k >= K`` from ``x = x_K``: ``(m, n)`` gives
        ``(m, p)``; ``(m, n, S)`` (S states per design) gives ``(m, p, S)``.
        With ``rows`` (a slice), only those outputs' bounds."""
        n = x.shape[1]
        a, absolute = (
            (self._a, self._abs) if rows is None else (self._a[:, rows], self._abs[:, rows])
        )
        if x.ndim == 2:  # one state per design: broadcasting beats m tiny matmuls
            ri = (self._W_ri * x[:, None, :]).sum(axis=-1)  # (m, 2n)
            z = np.sqrt(ri[:, :n] ** 2 + ri[:, n:] ** 2)  # |V⁻¹ x| (np.hypot is slower)
            beta = (a * z[:, None, :]).sum(axis=-1) * (1 + 1e-6)
            beta += absolute * np.abs(x).max(axis=-1)[:, None]
            return np.where(self._ok[:, None], beta, np.inf)
        ri = self._W_ri @ x  # (m, 2n, S)
        ri *= ri
        z = np.sqrt(ri[:, :n] + ri[:, n:])
        beta = (a @ z) * (1 + 1e-6)
        beta += absolute[..., None] * np.abs(x).max(axis=-2)[:, None, :]
        return np.where(self._ok[:, None, None], beta, np.inf)


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
    `qc_control.numerics.integrate` on ``f = A x + B u(t)`` up to rounding, on any
    grid that `qc_control.numerics.integrate.uniform_step` accepts (the step is
    taken as the mean ``(T[-1] - T[0]) / (len(T) - 1)``).

    Past the method's stability limit the states overflow to inf or nan
    without a RuntimeWarning; `lti_solve` cuts them off and warns.
    """
    H = float((T[-1] - T[0]) / (T.size - 1))
    A, B = np.asarray(A, dtype=float), np.asarray(B, dtype=float)
    key = ("step", method, substeps, H, array_key(A), array_key(B))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        phi, g_lo, g_hi = memo(key, lambda: step_matrices(method, A, B, H, substeps))
        if U is None or not U.size or not np.any(U):
            # the free response: its power tables depend on Φ and N only
            tables = memo(key + ("free", T.size), lambda: _free_tables(phi, T.size))
            x0 = np.asarray(x0, dtype=float)
            if T.size == 1:
                return x0[:, None].copy()
            return _free_response(phi, x0, T.size, None, True, tables)
        n, k = phi.shape[-1], U.shape[0]
        # with input, blocks of 16 keep the block-Toeplitz product small
        L = max(1, min(16, T.size - 1))
        if k < n:  # fewer inputs than states: the windows of U carry the input, not W
            W: tuple | np.ndarray = (g_lo, g_hi, U)

            def build():
                P = _powers(phi, L)
                return P, _input_matrix(P, g_lo, g_hi, L)
        else:
            W = U[:, :-1].T @ g_lo.T + U[:, 1:].T @ g_hi.T

            def build():
                return _powers(phi, L), None

        tables = memo(key + ("forced", L, k < n), build)
        return affine_scan(phi, x0, W, T.size, block=L, time_last=True, tables=tables)


def lti_solve(method, A, B, T, U, x0, substeps: int = 1, *, uniform: bool = False) -> Solution:
    """The LTI engine as a `qc_control.numerics.integrate.Solution`, cut like `integrate`'s.

    `lti_trajectory` on the grid ``T``, which must be uniform by
    `qc_control.numerics.integrate.uniform_step`. If a state is non-finite (a step
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
        The caller has checked ``T`` with `qc_control.numerics.integrate.uniform_step`
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
    x, message = lti_states(tab, A, B, T, U, x0, substeps, stacklevel=3)
    steps = (T.size - 1) * substeps  # the engine computes every interval at once
    status = "diverged" if message else "success"
    n_keep = x.shape[-1]
    return Solution(T[:n_keep], x, tab.stages * steps, steps, tab, status, message)


def lti_states(
    tab: ButcherTableau, A, B, T, U, x0, substeps: int = 1, *, stacklevel: int = 2
) -> tuple[np.ndarray, str]:
    """`lti_solve`'s states and message without the `Solution` (for the responses).

    ``(x, message)``: ``x`` of shape ``(n, N')``, cut before the first
    non-finite sample (``N' < N``, with a `DivergenceWarning` and the
    ``message`` saying where; ``''`` when nothing was cut). ``tab``,
    ``substeps`` and the uniform ``T`` are checked by the caller.
    """
    x = lti_trajectory(tab, A, B, T, U, np.asarray(x0, dtype=float), substeps)
    # one pass on a good run: a NaN or inf makes the sum non-finite (an overflow
    # of the sum alone sends it to the sample-by-sample check, which finds none)
    with np.errstate(over="ignore", invalid="ignore"):
        suspect = not np.isfinite(x.sum())
    finite = np.isfinite(x).all(axis=0) if suspect else None
    if finite is None or finite.all():
        return x, ""
    n_keep = int(np.argmin(finite))
    message = (
        f"{tab.name}: the state became non-finite after t = {T[n_keep - 1]:.6g}; "
        f"stopped after {n_keep - 1} of {T.size - 1} intervals"
    )
    warnings.warn(message, DivergenceWarning, stacklevel=stacklevel)
    return x[:, :n_keep], message
