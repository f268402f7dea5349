"""Linear stability of the fixed-step methods on an LTI system.

On ``x' = A x`` one step of an explicit Runge–Kutta method is
``x_{n+1} = R(hA) x_n``, where ``R`` is the method's stability function.
Along each eigenvector the step multiplies by ``R(hλ)``: the method is
stable when ``|R(hλ)| <= 1`` for every eigenvalue, and it sees the mode
with the eigenvalue ``λ_h = ln R(hλ) / h`` (Hairer & Wanner, *Solving
ODEs II*, §IV.2).
"""

from __future__ import annotations

import functools
import math

import control
import numpy as np
import pandas as pd
from numpy.polynomial import Polynomial

from .methods import get_method
from .model import QuarterCarParams, quarter_car

__all__ = [
    "stability_function",
    "stability_coefficients",
    "amplification",
    "max_stable_step",
    "numerical_modes",
    "eigenvalues_of",
]


def stability_function(method) -> Polynomial:
    """The stability function R(z) of an explicit Runge–Kutta method.

    .. math::

        R(z) = 1 + z\\, b^T (I - zA)^{-1} \\mathbf{1}
             = 1 + \\sum_{k=0}^{s-1} z^{k+1}\\, b^T A^k \\mathbf{1}

    The sum is exact because ``A`` is strictly lower triangular, hence
    nilpotent (HW II, §IV.2, eq. 2.3).

    Examples
    --------
    >>> stability_function("rk4").coef.round(6).tolist()   # 1 + z + z²/2 + z³/6 + z⁴/24
    [1.0, 1.0, 0.5, 0.166667, 0.041667]
    >>> stability_function("euler").coef.tolist()
    [1.0, 1.0]
    """
    tab = get_method(method)
    coef, v = [1.0], np.ones(tab.stages)
    for _ in range(tab.stages):
        coef.append(float(tab.b @ v))
        v = tab.a @ v
    while len(coef) > 1 and coef[-1] == 0:
        coef.pop()
    return Polynomial(coef)


@functools.lru_cache(maxsize=64)
def _coefficients(method) -> np.ndarray:
    coef = stability_function(method).coef
    coef.flags.writeable = False
    return coef


def stability_coefficients(method) -> np.ndarray:
    """R(z)'s coefficients, lowest power first (cached per tableau; read-only)."""
    return _coefficients(get_method(method))


def amplification(method, h: float, eigenvalues):
    """``max |R(hλ)|``: the spectral radius of the step map ``R(hA)``.

    Above 1 the method's trajectory grows along some mode at this h.
    ``eigenvalues`` of shape ``(..., n)`` give one radius per system: a
    float for one system, an array for a batch.
    """
    coef = stability_coefficients(method)
    z = h * np.asarray(eigenvalues, dtype=complex)
    radius = np.max(np.abs(np.polynomial.polynomial.polyval(z, coef)), axis=-1)
    return float(radius) if radius.ndim == 0 else radius


def eigenvalues_of(sys_or_eigenvalues) -> np.ndarray:
    """Eigenvalues from a continuous-time StateSpace, parameters, or a list."""
    if isinstance(sys_or_eigenvalues, (QuarterCarParams, dict)):
        sys_or_eigenvalues = quarter_car(sys_or_eigenvalues)
    if isinstance(sys_or_eigenvalues, control.StateSpace):
        if not control.isctime(sys_or_eigenvalues, strict=True):
            raise ValueError(
                f"system {sys_or_eigenvalues.name!r} must be continuous-time, "
                f"got dt={sys_or_eigenvalues.dt!r}"
            )
        return np.linalg.eigvals(np.asarray(sys_or_eigenvalues.A, dtype=float))
    lam = np.atleast_1d(np.asarray(sys_or_eigenvalues, dtype=complex))
    if lam.ndim != 1 or not np.all(np.isfinite(lam)):
        raise ValueError("eigenvalues must be a finite 1-D array")
    return lam


def _max_steps(R: Polynomial, lams: np.ndarray) -> np.ndarray:
    """For each λ, the smallest h > 0 where |R(hλ)| crosses 1.

    ``|R(hλ)|² - 1`` is a real polynomial in h with a root at h = 0; the
    step limit is the smallest positive real root of the quotient by h.
    All eigenvalues' quotients are solved in one batched eigenvalue call
    on their companion matrices. ``inf`` when no root bounds the step,
    ``0`` when the method is unstable for every small h.
    """
    coef = R.coef
    deg = coef.size - 1
    out = np.full(lams.size, np.inf)
    nz = lams != 0
    lam = lams[nz]
    if not lam.size or deg == 0:
        return out
    r = coef[None, :] * lam[:, None] ** np.arange(deg + 1)  # R(hλ) in powers of h
    q = np.zeros((lam.size, 2 * deg + 1))
    for a in range(deg + 1):
        q[:, a : a + deg + 1] += (r[:, a : a + 1] * np.conj(r)).real
    g = q[:, 1:]  # (|R|² - 1) / h
    d = g.shape[1] - 1
    if d == 0:
        roots = np.full((lam.size, 1), np.inf + 0j)
    else:
        comp = np.zeros((lam.size, d, d))
        comp[:, 0, :] = -g[:, -2::-1] / g[:, -1:]
        comp[:, np.arange(1, d), np.arange(d - 1)] = 1.0
        roots = np.linalg.eigvals(comp)
    scale = np.abs(roots)
    ok = (np.abs(roots.imag) <= 1e-9 * np.maximum(scale, 1e-300)) & (roots.real > 0)
    result = np.where(ok, roots.real, np.inf).min(axis=1)
    # unstable for every small h: |R|² grows from h = 0 (g(0) > 0), or g(0) = 0
    # (λ on the imaginary axis) and |R| > 1 just off the origin
    grows = g[:, 0] > 0
    flat = g[:, 0] == 0
    if flat.any():
        probe = np.abs(R(1e-6 * lam[flat] / np.abs(lam[flat]))) > 1
        grows[np.flatnonzero(flat)[probe]] = True
    result[grows] = 0.0
    out[nz] = result
    return out


def max_stable_step(method, sys_or_eigenvalues) -> float:
    """The largest step h [s] with ``|R(hλ)| <= 1`` for every eigenvalue.

    Parameters
    ----------
    method : str or ButcherTableau
    sys_or_eigenvalues : control.StateSpace, QuarterCarParams or array_like
        A continuous-time system, a vehicle, or its eigenvalues [1/s].

    Returns
    -------
    float
        ``min over λ`` of the first positive root of ``|R(hλ)|² = 1``; the
        method is stable for every step below it. ``inf`` if no eigenvalue
        limits the step, ``0.0`` if some eigenvalue is unstable for every
        ``h > 0`` (e.g. Euler on an undamped mode).

    Examples
    --------
    The seed's vehicle: Euler is limited by the lightly damped body mode,
    ``h = -2 Re λ / |λ|²``:

    >>> round(max_stable_step("euler", QuarterCarParams()), 5)
    0.01982
    >>> round(max_stable_step("rk4", QuarterCarParams()), 4)
    0.1085
    """
    lam = eigenvalues_of(sys_or_eigenvalues)
    lam = np.unique(np.where(lam.imag < 0, lam.conj(), lam))  # a conjugate has the same limit
    return float(_max_steps(stability_function(method), lam).min())


def numerical_modes(method, h: float, sys_or_params=None) -> pd.DataFrame:
    """Each mode's frequency and damping as the method sees it at step h.

    The method maps a mode ``e^{λt}`` to ``R(hλ)^n``, i.e. to the
    continuous eigenvalue

    .. math:: \\lambda_h = \\frac{\\ln R(h\\lambda)}{h}

    (principal logarithm). From ``λ_h`` come the numerical damped frequency
    ``Im λ_h / 2π`` and damping ratio ``-Re λ_h / |λ_h|``.

    Parameters
    ----------
    method : str or ButcherTableau
    h : float
        Step size [s], > 0.
    sys_or_params : control.StateSpace or QuarterCarParams, optional
        A quarter car; the seed's by default.

    Returns
    -------
    pandas.DataFrame
        One row per mode (body bounce, wheel hop) with the exact and the
        numerical ``fd [Hz]`` and ``zeta``, the frequency error [%]
        (negative: the method's oscillation is slow, its period long),
        the damping error ``zeta_h - zeta`` (negative: the method adds
        negative damping), ``|R(hλ)|`` and ``h*|λ|``.

    Notes
    -----
    Euler's ``|1 + hλ|`` exceeds ``e^{h Re λ}`` and adds negative damping;
    Midpoint and Heun add positive damping. For RK4,
    ``h λ_h = z - z^5/120 + z^6/144 + O(z^7)`` with ``z = hλ``; writing
    ``z = y e^{i(π/2 + δ)}`` (``sin δ = ζ``) the decay rate changes by
    ``(y^5 sin 5δ / 120 - y^6 cos 6δ / 144) / h``. RK4 therefore adds a
    little positive damping only to modes with ``ζ ≲ h|λ|/6`` (near the
    imaginary axis) and removes a little from better-damped ones, such as
    both modes of the seed's vehicle. When ``h Im λ`` nears π the
    logarithm aliases and the frequency error is meaningless; the column
    ``h*|lambda|`` shows how close that is.
    """
    from .modal import modal_analysis

    if not (isinstance(h, (int, float, np.floating)) and math.isfinite(h) and h > 0):
        raise ValueError(f"h must be a finite step > 0 s, got {h!r}")
    R = stability_function(method)
    rows = {}
    for mode in modal_analysis(sys_or_params).modes:
        lam = mode.eigenvalue
        mu = complex(R(h * lam))
        lam_h = complex(np.log(mu)) / h if mu != 0 else complex(-math.inf)
        wn_h = abs(lam_h)
        fd, fd_h = lam.imag / (2 * math.pi), lam_h.imag / (2 * math.pi)
        zeta_h = -lam_h.real / wn_h if wn_h > 0 else math.nan
        rows[mode.name] = {
            "fd [Hz]": fd,
            "fd_h [Hz]": fd_h,
            "freq error [%]": 100 * (fd_h - fd) / fd if fd else math.nan,
            "zeta": mode.zeta,
            "zeta_h": zeta_h,
            "zeta error": zeta_h - mode.zeta,
            "|R(h*lambda)|": abs(mu),
            "h*|lambda|": h * abs(lam),
        }
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = "mode"
    return frame
