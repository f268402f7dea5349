r"""ISO 2631-1 frequency weightings: the standard's filters, exact on sampled signals.

ISO 2631-1:1997 Annex A writes every weighting as one product of four
filters of the Laplace variable ``s`` (Table A.2 gives their frequencies
and quality factors): a band limit, a high pass ``H_h`` at ``f1`` and a low
pass ``H_l`` at ``f2`` (both second-order Butterworth, ``Q1 = Q2 = 1/√2``),
then the weighting proper, an acceleration-velocity transition ``H_t``
(``f3``, ``f4``, ``Q4``) and an upward step ``H_s`` (``f5``, ``Q5``, ``f6``,
``Q6``):

.. math::

    H_h = \frac{s^2}{s^2 + ω_1 s/Q_1 + ω_1^2}, \quad
    H_l = \frac{ω_2^2}{s^2 + ω_2 s/Q_2 + ω_2^2}, \quad
    H_t = \frac{1 + s/ω_3}{1 + s/(Q_4 ω_4) + s^2/ω_4^2}, \quad
    H_s = \frac{s^2 + ω_5 s/Q_5 + ω_5^2}{s^2 + ω_6 s/Q_6 + ω_6^2}

with ``ω_i = 2π f_i``; a frequency of ∞ in Table A.2 leaves its factor out
(``1 + s/ω_3 → 1``; ``H_s = 1``). `WEIGHTINGS` holds the table.
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import control
import numpy as np
import scipy.linalg
import scipy.signal

from ..numerics.checks import ParameterError
from ..numerics.integrate import uniform_step
from ..numerics.lti import affine_scan

__all__ = [
    "WEIGHTINGS",
    "USES",
    "Weighting",
    "weighting",
    "weighted",
    "weighting_discrete",
    "band_top",
    "wk_filter",
    "wk_weighted",
    "wk_discrete",
]


class Weighting(NamedTuple):
    """One row of ISO 2631-1:1997 Table A.2 (frequencies [Hz]; ``inf``: no factor)."""

    f1: float
    f2: float
    f3: float
    f4: float
    Q4: float
    f5: float
    Q5: float
    f6: float
    Q6: float


_INF = math.inf
#: ISO 2631-1:1997 Table A.2. A Q beside an infinite frequency is unused.
WEIGHTINGS: dict[str, Weighting] = {
    #               f1    f2     f3    f4    Q4    f5      Q5    f6    Q6
    "Wk": Weighting(0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    "Wd": Weighting(0.4, 100.0, 2.0, 2.0, 0.63, _INF, 1.0, _INF, 1.0),
    "Wf": Weighting(0.08, 0.63, _INF, 0.25, 0.86, 0.0625, 0.80, 0.1, 0.80),
    "Wc": Weighting(0.4, 100.0, 8.0, 8.0, 0.63, _INF, 1.0, _INF, 1.0),
    "We": Weighting(0.4, 100.0, 1.0, 1.0, 0.63, _INF, 1.0, _INF, 1.0),
    "Wj": Weighting(0.4, 100.0, _INF, _INF, 1.0, 3.75, 0.91, 5.32, 0.91),
}  # fmt: skip
#: What each weighting is applied to (ISO 2631-1:1997 Tables 1 and 2, §9).
USES = {
    "Wk": "vertical (z) at the seat surface, the feet, recumbent",
    "Wd": "horizontal (x, y) at the seat surface; recumbent x, y",
    "Wf": "vertical (z), for motion sickness",
    "Wc": "fore-aft (x) at the seat back",
    "We": "rotations (rx, ry, rz) at the seat surface",
    "Wj": "vertical under the head, recumbent",
}


def _name(name: str) -> str:
    key = {k.lower(): k for k in WEIGHTINGS}.get(str(name).strip().lower())
    if key is None:
        raise ParameterError("weighting", name, f"one of ISO 2631-1's {', '.join(WEIGHTINGS)}")
    return key


@functools.cache
def _weighting(key: str) -> control.TransferFunction:
    p = WEIGHTINGS[key]
    s = control.tf("s")
    w = {k: 2 * math.pi * f for k, f in zip(range(1, 7), (p.f1, p.f2, p.f3, p.f4, p.f5, p.f6))}
    q = 1 / math.sqrt(2)
    tf = s**2 / (s**2 + w[1] * s / q + w[1] ** 2) * (w[2] ** 2 / (s**2 + w[2] * s / q + w[2] ** 2))
    if math.isfinite(w[4]):
        numerator = 1 + s / w[3] if math.isfinite(w[3]) else 1
        tf = tf * (numerator / (1 + s / (p.Q4 * w[4]) + s**2 / w[4] ** 2))
    if math.isfinite(w[5]):
        tf = tf * ((s**2 + w[5] * s / p.Q5 + w[5] ** 2) / (s**2 + w[6] * s / p.Q6 + w[6] ** 2))
    tf = control.minreal(tf, verbose=False)
    return control.tf(tf.num, tf.den, name=key, inputs=["acc"], outputs=[f"acc_{key}"])


def weighting(name: str) -> control.TransferFunction:
    """An ISO 2631-1 frequency weighting as a transfer function.

    The product ``H_h H_l H_t H_s`` of the module docstring with the
    parameters of ISO 2631-1:1997 Table A.2 (`WEIGHTINGS`).

    Parameters
    ----------
    name : {'Wk', 'Wd', 'Wf', 'Wc', 'We', 'Wj'}
        Case aside.

    Returns
    -------
    control.TransferFunction
        Acceleration to weighted acceleration (both in m/s²).

    Examples
    --------
    >>> import numpy as np
    >>> round(float(abs(weighting("Wd")(2j * np.pi * 1.0))), 3)   # Table 3: 1.011 at 1 Hz
    1.011
    """
    return _weighting(_name(name))


def wk_filter() -> control.TransferFunction:
    """ISO 2631-1 frequency weighting Wk (vertical, seated): ``weighting('Wk')``.

    It reproduces the standard's Table 3 to 0.1 %.

    Examples
    --------
    >>> import numpy as np
    >>> round(float(abs(wk_filter()(2j * np.pi * 1.0))), 3)     # Table 3: 0.482 at 1 Hz
    0.482
    """
    return weighting("Wk")


@functools.lru_cache(maxsize=64)
def weighting_discrete(name: str, dt: float):
    """A weighting sampled at ``dt`` [s], exactly, for an input linear between samples.

    python-control's exact recursion for an input linear between samples,
    ``x_{k+1} = A_d x_k + B_0 u_k + B_1 u_{k+1}``, ``y_k = C x_k + D u_k``,
    becomes with ``x̃ = x - B_1 u`` the ordinary ``x̃_{k+1} = A_d x̃_k + B̃ u_k``,
    ``y_k = C x̃_k + D̃ u_k``, started from ``x̃_0 = -B_1 u_0`` (zero initial
    state of the filter). Exact, not bilinear: the sampled filter's gain is
    the continuous one's for the samples' linear interpolant, with no
    frequency warping near the band's top.

    Returns
    -------
    Ad, Bt, C, Dt, B1
        ``A_d (n, n)``, ``B̃ = A_d B_1 + B_0 (n,)``, ``C (1, n)``,
        ``D̃ = C B_1 + D`` and ``B_1 (n,)``. The filter's state can be carried
        from one block of samples to the next (a streamed sweep does).
    """
    sys = control.ss(weighting(name))
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    M = np.zeros((n + 2, n + 2))
    M[:n, :n], M[:n, n] = A * dt, B[:, 0] * dt
    M[n, n + 1] = 1.0
    E = scipy.linalg.expm(M)
    Ad, B1 = E[:n, :n], E[:n, n + 1]
    B0 = E[:n, n] - B1
    return Ad, Ad @ B1 + B0, C, float(C[0] @ B1 + D[0, 0]), B1


def wk_discrete(dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray]:
    """Wk sampled at ``dt`` [s]: ``weighting_discrete('Wk', dt)``."""
    return weighting_discrete("Wk", dt)


@functools.lru_cache(maxsize=16)
def _impulse(name: str, dt: float, N: int) -> tuple[np.ndarray, np.ndarray]:
    """Impulse response h and initial-input response v of a weighting sampled at
    dt: with `weighting_discrete`'s recursion, ``y = h * u + u_0 v``, ``h = [D̃,
    C B̃, C A_d B̃, ...]`` and ``v_k = C A_d^k x̃_0`` for ``x̃_0 = -B_1``. (A
    transfer-function form would lose four digits to the spread of the
    poles, 0.4 to 100 Hz for Wk.)
    """
    Ad, Bt, C, Dt, B1 = weighting_discrete(name, dt)
    h = np.empty(N)
    h[0] = Dt
    if N > 1:
        h[1:] = affine_scan(Ad, Bt, None, N - 1, C=C)[:, 0]
    v = affine_scan(Ad, -B1, None, N, C=C)[:, 0]
    return h, v


def band_top(key: str) -> float:
    """The highest frequency [Hz] of the weighting proper (f3 ... f6, not the band
    limit f2): a grid whose Nyquist frequency is below it cannot carry the band."""
    p = WEIGHTINGS[key]
    return max(f for f in (p.f3, p.f4, p.f5, p.f6) if math.isfinite(f))


def weighted(acc, T, name: str) -> np.ndarray:
    """An acceleration weighted by an ISO 2631-1 weighting, in the time domain.

    Exactly as ``control.forced_response`` of `weighting` computes it (input
    linear between samples, zero initial state), evaluated as an FFT
    convolution with the sampled filter's impulse response (`_impulse`).

    Parameters
    ----------
    acc : array_like, shape (N,) or (m, N)
        Accelerations [m/s²] on ``T``.
    T : array_like, shape (N,)
        A uniform grid [s] whose Nyquist frequency ``1/(2 dt)`` reaches the
        weighting's band (Wk: 12.5 Hz, so dt <= 40 ms).
    name : {'Wk', 'Wd', 'Wf', 'Wc', 'We', 'Wj'}

    Returns
    -------
    ndarray, shaped as ``acc``
    """
    key = _name(name)
    T = np.asarray(T, dtype=float)
    a = np.atleast_2d(np.asarray(acc, dtype=float))
    if T.ndim != 1 or T.size < 2 or a.shape[-1] != T.size:
        raise ParameterError(
            "acc",
            np.shape(acc),
            f"one sample per time of T ({T.size})",
            message=f"acc must have one sample per time of T ({T.size}), got shape {np.shape(acc)}",
        )
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        at = int(bad[0, -1])
        raise ParameterError(
            "acc", a[tuple(bad[0])], "finite samples", message=f"acc is not finite at sample {at}"
        )
    dt = _uniform(T, key)
    top = band_top(key)
    if 1 / (2 * dt) < top:
        raise ParameterError(
            "T",
            dt,
            f"samples at most {1 / (2 * top):g} s apart",
            message=f"dt = {dt:g} s is too coarse for {key}: its band reaches {top:g} Hz, so "
            f"the samples must be at most {1 / (2 * top):g} s apart",
        )
    return _convolved(key, a, T, dt).reshape(np.shape(acc))


def _uniform(T: np.ndarray, key: str) -> float:
    dt = uniform_step(T)
    if dt is None:
        raise ParameterError(
            "T",
            "a non-uniform grid",
            f"uniform for the ISO 2631 weighting {key}",
            message=f"T must be uniform for the ISO 2631 weighting {key}",
        )
    return dt


def _convolved(key: str, a: np.ndarray, T: np.ndarray, dt: float) -> np.ndarray:
    """``(m, N)`` signals weighted by ``key``: `_impulse`'s convolution."""
    h, v = _impulse(key, round(dt, 15), T.size)
    return scipy.signal.oaconvolve(a, h[None, :], axes=-1)[:, : T.size] + a[:, :1] * v


def wk_weighted(acc, T) -> np.ndarray:
    """ISO 2631-1 Wk-weighted acceleration, exactly as ``control.forced_response``
    of `wk_filter` computes it (input linear between samples, zero initial
    state), for one signal ``(N,)`` or many ``(m, N)`` on a uniform grid T.

    `weighted` with ``'Wk'``, on any uniform grid (a coarse one too: the
    metrics of a 10 ms run are Wk-weighted as they always were).
    """
    T = np.asarray(T, dtype=float)
    a = np.atleast_2d(np.asarray(acc, dtype=float))
    return _convolved("Wk", a, T, _uniform(T, "Wk")).reshape(np.shape(acc))
