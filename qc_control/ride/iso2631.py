"""ISO 2631-1 frequency weighting Wk: the comfort filter, exact on sampled signals."""

from __future__ import annotations

import functools
import math

import control
import numpy as np
import scipy.linalg
import scipy.signal

from ..numerics.integrate import uniform_step
from ..numerics.lti import affine_scan

__all__ = ["wk_filter", "wk_weighted", "wk_discrete"]


def wk_filter() -> control.TransferFunction:
    """ISO 2631-1 frequency weighting Wk (vertical, seated) as a transfer function.

    .. math::

        W_k(s) = H_h H_l H_t H_s, \\quad
        H_h = \\frac{s^2}{s^2 + ω_1 s/Q_1 + ω_1^2}, \\quad
        H_l = \\frac{ω_2^2}{s^2 + ω_2 s/Q_2 + ω_2^2},

        H_t = \\frac{1 + s/ω_3}{1 + s/(Q_4 ω_4) + s^2/ω_4^2}, \\quad
        H_s = \\frac{s^2 + ω_5 s/Q_5 + ω_5^2}{s^2 + ω_6 s/Q_6 + ω_6^2}

    with f1 = 0.4, f2 = 100, f3 = f4 = 12.5, f5 = 2.37, f6 = 3.35 Hz,
    Q1 = Q2 = 1/√2, Q4 = 0.63, Q5 = Q6 = 0.91 (ISO 2631-1:1997, Annex A,
    Table A.2). It reproduces the standard's Table 3 to 0.1 %.

    Examples
    --------
    >>> import numpy as np
    >>> round(float(abs(wk_filter()(2j * np.pi * 1.0))), 3)     # Table 3: 0.482 at 1 Hz
    0.482
    """
    s = control.tf("s")
    w = {
        k: 2 * math.pi * f
        for k, f in {1: 0.4, 2: 100.0, 3: 12.5, 4: 12.5, 5: 2.37, 6: 3.35}.items()
    }
    q1 = q2 = 1 / math.sqrt(2)
    hh = s**2 / (s**2 + w[1] * s / q1 + w[1] ** 2)
    hl = w[2] ** 2 / (s**2 + w[2] * s / q2 + w[2] ** 2)
    ht = (1 + s / w[3]) / (1 + s / (0.63 * w[4]) + s**2 / w[4] ** 2)
    hs = (s**2 + w[5] * s / 0.91 + w[5] ** 2) / (s**2 + w[6] * s / 0.91 + w[6] ** 2)
    return control.minreal(hh * hl * ht * hs, verbose=False)


@functools.lru_cache(maxsize=16)
def wk_discrete(dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray]:
    """Wk sampled at ``dt`` [s], exactly, for an input linear between samples.

    python-control's exact recursion for an input linear between samples,
    ``x_{k+1} = A_d x_k + B_0 u_k + B_1 u_{k+1}``, ``y_k = C x_k + D u_k``,
    becomes with ``x̃ = x - B_1 u`` the ordinary ``x̃_{k+1} = A_d x̃_k + B̃ u_k``,
    ``y_k = C x̃_k + D̃ u_k``, started from ``x̃_0 = -B_1 u_0`` (zero initial
    state of the filter).

    Returns
    -------
    Ad, Bt, C, Dt, B1
        ``A_d (n, n)``, ``B̃ = A_d B_1 + B_0 (n,)``, ``C (1, n)``,
        ``D̃ = C B_1 + D`` and ``B_1 (n,)``. The filter's state can be carried
        from one block of samples to the next (a streamed sweep does).
    """
    sys = control.ss(wk_filter())
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n], M[:n, n] = A * dt, B[:, 0] * dt
    M[n, n + 1] = 1.0
    E = scipy.linalg.expm(M)
    Ad, B1 = E[:n, :n], E[:n, n + 1]
    B0 = E[:n, n] - B1
    return Ad, Ad @ B1 + B0, C, float(C[0] @ B1 + D[0, 0]), B1


@functools.lru_cache(maxsize=16)
def _wk_impulse(dt: float, N: int) -> tuple[np.ndarray, np.ndarray]:
    """Impulse response h and initial-input response v of Wk sampled at dt:
    with `wk_discrete`'s recursion, ``y = h * u + u_0 v``, ``h = [D̃, C B̃,
    C A_d B̃, ...]`` and ``v_k = C A_d^k x̃_0`` for ``x̃_0 = -B_1``. (A
    transfer-function form would lose four digits to the spread of Wk's
    poles, 0.4 to 100 Hz.)
    """
    Ad, Bt, C, Dt, B1 = wk_discrete(dt)
    h = np.empty(N)
    h[0] = Dt
    if N > 1:
        h[1:] = affine_scan(Ad, Bt, None, N - 1, C=C)[:, 0]
    v = affine_scan(Ad, -B1, None, N, C=C)[:, 0]
    return h, v


def wk_weighted(acc, T) -> np.ndarray:
    """ISO 2631-1 Wk-weighted acceleration, exactly as ``control.forced_response``
    of `wk_filter` computes it (input linear between samples, zero initial
    state), for one signal ``(N,)`` or many ``(m, N)`` on a uniform grid T.

    Evaluated as an FFT convolution with the sampled filter's impulse
    response (see `_wk_impulse`): agrees with control to ~1e-15 relative.
    """
    T = np.asarray(T, dtype=float)
    a = np.atleast_2d(np.asarray(acc, dtype=float))
    dt = uniform_step(T)
    if dt is None:
        raise ValueError("T must be uniform for the ISO 2631 weighting")
    h, v = _wk_impulse(round(dt, 15), T.size)
    out = scipy.signal.oaconvolve(a, h[None, :], axes=-1)[:, : T.size] + a[:, :1] * v
    return out.reshape(np.shape(acc))
