"""Linear stability of the fixed-step methods on an LTI system.

On ``x' = A x`` one step of an explicit Runge–Kutta method is
``x_{n+1} = R(hA) x_n``, where ``R`` is the method's stability function.
Along each eigenvector the step multiplies by ``R(hλ)``: the method is
stable when ``|R(hλ)| <= 1`` for every eigenvalue, and it sees the mode
with the eigenvalue ``λ_h = ln R(hλ) / h`` (Hairer & Wanner, *Solving
ODEs II*, §IV.2).

Systems are given as a continuous-time `control.StateSpace` (a
`control.TransferFunction` is converted with `control.ss`), as any object
with a ``system`` attribute holding one, or as their eigenvalues. Nothing
here knows about vehicles.

Marginal eigenvalues
--------------------
An undamped mode's eigenvalues lie on the imaginary axis, but ``eig``
returns them with a real part of the size of its rounding, of either
sign. An eigenvalue with ``|Re λ| <= MARGINAL_RTOL·|λ|`` (damping ratio
below 1e-8) is therefore taken to lie on the axis, ``Re λ = 0``, and one
with ``|λ| <= MARGINAL_RTOL·max|λ|`` to be 0. Any other eigenvalue with
``Re λ > 0`` belongs to a system that grows by itself.
"""

from __future__ import annotations

import functools
import math

import control
import numpy as np
import pandas as pd
from numpy.polynomial import Polynomial

from .messages import show
from .methods import get_method

__all__ = [
    "stability_function",
    "stability_coefficients",
    "amplification",
    "step_is_stable",
    "max_stable_step",
    "numerical_modes",
    "eigenvalues_of",
    "settle_marginal",
    "MARGINAL_RTOL",
    "AMPLIFICATION_MARGIN",
]

#: Relative size of a real part that is taken for rounding (module notes).
MARGINAL_RTOL = 1e-8

#: ``|R(hλ)|`` up to ``1 + AMPLIFICATION_MARGIN`` counts as not amplifying:
#: the rounding of ``R`` at the stability limit itself.
AMPLIFICATION_MARGIN = 1e-12

_EPS = np.finfo(float).eps


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


def eigenvalues_of(system_or_eigenvalues) -> np.ndarray:
    """The eigenvalues [1/s] of a continuous-time system, or the eigenvalues given.

    Parameters
    ----------
    system_or_eigenvalues : control.StateSpace, object or array_like
        A continuous-time `control.StateSpace` (or `control.TransferFunction`,
        converted with `control.ss`); any object whose ``system`` attribute
        is one; or the eigenvalues themselves, a 1-D array of numbers.

    Raises
    ------
    ValueError
        For a discrete-time system, or eigenvalues that are not finite or
        not 1-D.
    TypeError
        For anything else, naming what was given.

    Examples
    --------
    >>> import control
    >>> eigenvalues_of(control.ss([[0, 1], [-4, 0]], [[0], [1]], [[1, 0]], 0))
    array([0.+2.j, 0.-2.j])
    >>> eigenvalues_of([-1, -2 + 3j]).tolist()
    [(-1+0j), (-2+3j)]
    """
    obj = system_or_eigenvalues
    if not isinstance(obj, control.LTI) and hasattr(obj, "system"):
        obj = obj.system
        if not isinstance(obj, control.LTI):
            raise TypeError(
                f"the .system of {type(system_or_eigenvalues).__name__} must be a "
                f"control.StateSpace, got {type(obj).__name__}"
            )
    if isinstance(obj, control.TransferFunction):
        obj = control.ss(obj)
    if isinstance(obj, control.StateSpace):
        if not control.isctime(obj, strict=True):
            raise ValueError(f"system {obj.name!r} must be continuous-time, got dt={obj.dt!r}")
        return np.linalg.eigvals(np.asarray(obj.A, dtype=float))
    expected = (
        "a continuous-time control.StateSpace, an object with a .system StateSpace, "
        "or a 1-D array of eigenvalues"
    )
    if isinstance(obj, (str, bytes, dict, control.InputOutputSystem)) or obj is None:
        raise TypeError(f"expected {expected}, got {show(obj)}")
    try:
        lam = np.atleast_1d(np.asarray(obj, dtype=complex))
    except (TypeError, ValueError):
        raise TypeError(f"expected {expected}, got {show(obj)}") from None
    if lam.ndim != 1 or not np.all(np.isfinite(lam)):
        raise ValueError(f"eigenvalues must be a finite 1-D array, got {show(obj)}")
    return lam


def _batch_eigenvalues(system_or_eigenvalues) -> np.ndarray:
    """Eigenvalues of shape ``(..., n)``: a system's, or an array as given."""
    obj = system_or_eigenvalues
    if isinstance(obj, (control.LTI, str, bytes, dict)) or hasattr(obj, "system") or obj is None:
        return eigenvalues_of(obj)
    lam = np.asarray(obj, dtype=complex)
    if lam.ndim == 0:
        lam = lam[None]
    if not np.all(np.isfinite(lam)):
        raise ValueError("eigenvalues must be finite")
    return lam


def settle_marginal(lam: np.ndarray) -> np.ndarray:
    """Marginal eigenvalues moved onto the imaginary axis, tiny ones to 0 (module notes).

    ``eig`` returns an undamped mode's eigenvalues with a real part of the size
    of its rounding, of either sign; read as damping, that is a damping ratio
    of ±1e-14 where the truth is 0 (or below what double precision resolves).
    """
    lam = np.array(lam, dtype=complex)
    size = np.abs(lam)
    rho = size.max(axis=-1, keepdims=True) if lam.size else size
    lam[size <= MARGINAL_RTOL * rho] = 0
    on_axis = np.abs(lam.real) <= MARGINAL_RTOL * size
    lam[on_axis] = 1j * lam[on_axis].imag
    return lam


def amplification(method, h: float, eigenvalues):
    """``max |R(hλ)|``: the spectral radius of the step map ``R(hA)``.

    Above 1 the method's trajectory grows along some mode at this h.
    ``eigenvalues`` of shape ``(..., n)`` give one radius per system: a
    float for one system, an array for a batch. A system (see
    `eigenvalues_of`) is accepted too.
    """
    coef = stability_coefficients(method)
    z = h * _batch_eigenvalues(eigenvalues)
    radius = np.max(np.abs(np.polynomial.polynomial.polyval(z, coef)), axis=-1)
    return float(radius) if radius.ndim == 0 else radius


def step_is_stable(method, h: float, eigenvalues):
    """Whether the step ``h`` keeps every mode that does not grow from growing.

    True when ``|R(hλ)| <= 1 + AMPLIFICATION_MARGIN`` for every eigenvalue
    with ``Re λ <= 0``, after marginal eigenvalues are put on the
    imaginary axis (module notes). Eigenvalues of a system that grows by
    itself (``Re λ > MARGINAL_RTOL·|λ|``) are left out: their growth is the
    system's, not the method's.

    Parameters
    ----------
    method : str or ButcherTableau
    h : float
        Step [s].
    eigenvalues : array_like, shape (..., n), or a system
        One system's eigenvalues, or a batch of them (last axis).

    Returns
    -------
    bool, or ndarray of bool for a batch

    Examples
    --------
    Heun gains energy on an undamped mode at every step; RK4 does not up
    to ``h|λ| = 2√2``:

    >>> step_is_stable("heun", 0.01, [10j, -10j]), step_is_stable("rk4", 0.28, [10j])
    (False, True)
    """
    if not (isinstance(h, (int, float, np.number)) and not isinstance(h, bool)) or not h >= 0:
        raise ValueError(f"h must be a step >= 0 s, got {show(h)}")
    coef = stability_coefficients(method)
    lam = settle_marginal(_batch_eigenvalues(eigenvalues))
    radius = np.abs(np.polynomial.polynomial.polyval(h * lam, coef))
    ok = (radius <= 1 + AMPLIFICATION_MARGIN) | (lam.real > 0)
    ok = np.all(ok, axis=-1)
    return bool(ok) if ok.ndim == 0 else ok


def _step_limit(coef: np.ndarray, lam: complex) -> float:
    """The largest h with ``|R(hλ)| <= 1`` on ``(0, h]``, for one settled λ.

    With ``y = h|λ|`` and ``u = λ/|λ|``, ``P(y) = |R(yu)|² - 1`` is a real
    polynomial with ``P(0) = 0``. Coefficients below their rounding are
    zeroed; if the lowest remaining one is positive, ``|R|`` exceeds 1 for
    every small h (limit 0). Otherwise the limit is the first positive
    root of ``P`` after which ``P > 0``, checked on ``|R|`` itself.
    """
    size = abs(lam)
    if size == 0:
        return math.inf
    if lam.real > 0:
        return 0.0
    u = lam / size  # exactly 1j on the axis, so odd powers stay purely imaginary
    powers = [1.0 + 0j]
    for _ in range(coef.size - 1):
        powers.append(powers[-1] * u)
    r = coef * np.array(powers)
    p = np.convolve(r, np.conj(r)).real
    bound = np.convolve(np.abs(coef), np.abs(coef))
    p[np.abs(p) <= 64 * coef.size * _EPS * bound] = 0
    p[0] = 0.0
    nz = np.flatnonzero(p)
    if nz.size == 0:
        return math.inf  # |R| = 1 along the whole ray
    if p[nz[0]] > 0:
        return 0.0
    q = p[nz[0] :]  # P(y) / y^m, negative at y = 0
    roots = np.roots(q[::-1]) if q.size > 1 else np.array([])
    real = np.sort(roots.real[(np.abs(roots.imag) <= 1e-6 * np.abs(roots)) & (roots.real > 0)])

    def grows(y):
        return abs(np.polynomial.polynomial.polyval(y * u, coef)) > 1

    for i, y in enumerate(real):
        after = real[i + 1] if i + 1 < real.size else 2 * y
        if grows(0.5 * (y + after)):
            return float(y / size)
    return math.inf


def max_stable_step(method, sys_or_eigenvalues) -> float:
    """The largest step h [s] with ``|R(hλ)| <= 1`` for every eigenvalue.

    Parameters
    ----------
    method : str or ButcherTableau
    sys_or_eigenvalues : control.StateSpace, object with ``.system``, or array_like
        A continuous-time system, or its eigenvalues [1/s] (`eigenvalues_of`).

    Returns
    -------
    float
        ``min over λ`` of the first positive ``h`` past which
        ``|R(hλ)| > 1``; the method is stable for every step below it.
        ``inf`` if no eigenvalue limits the step; ``0.0`` if some
        eigenvalue is amplified for every ``h > 0``: on the imaginary axis
        for a method whose stability region holds no stretch of it
        (Euler, Midpoint, Heun: ``|R(iy)|² = 1 + y⁴/4``), or in the right
        half-plane (a system that grows by itself).

    Raises
    ------
    TypeError
        When the arguments are swapped or of the wrong kind.

    Notes
    -----
    Marginal eigenvalues are put on the imaginary axis first (module
    notes); there RK4's limit is ``2√2/|λ|`` (HW II, Fig. IV.2.1) and not
    the 0 or the far larger value a real part of ±1e-10|λ| would give.

    Examples
    --------
    The seed's vehicle (its eigenvalues): Euler is limited by the lightly
    damped body mode, ``h = -2 Re λ / |λ|²``:

    >>> lam = [-0.4622 + 6.8138j, -0.4622 - 6.8138j, -9.5478 + 23.226j, -9.5478 - 23.226j]
    >>> round(max_stable_step("euler", lam), 4), round(max_stable_step("rk4", lam), 4)
    (0.0198, 0.1085)
    >>> round(max_stable_step("rk4", [10j, -10j]), 6)   # 2√2/10 on the axis
    0.282843
    """
    _check_order_of_arguments("max_stable_step", method, sys_or_eigenvalues)
    coef = stability_coefficients(method)
    lam = settle_marginal(eigenvalues_of(sys_or_eigenvalues))
    lam = np.unique(np.where(lam.imag < 0, lam.conj(), lam))  # a conjugate has the same limit
    return min((_step_limit(coef, complex(x)) for x in lam), default=math.inf)


def _check_order_of_arguments(fname: str, method, system) -> None:
    """A clear TypeError for ``f(system, 'heun')`` instead of ``f('heun', system)``."""
    if isinstance(system, str) and not isinstance(method, str):
        raise TypeError(
            f"{fname}(method, system, ...): the method comes first; got method of type "
            f"{type(method).__name__} and system {system!r}"
        )
    get_method(method)


def _mode_rows(modes_or_system):
    """``[(name, eigenvalue, zeta)]`` from a ``.modes`` object, or one row per eigenvalue."""
    if hasattr(modes_or_system, "modes"):
        rows = []
        for mode in modes_or_system.modes:
            lam = complex(mode.eigenvalue)
            zeta = getattr(mode, "zeta", None)
            rows.append((str(mode.name), lam, None if zeta is None else float(zeta)))
        if not rows:
            raise ValueError(f"{type(modes_or_system).__name__}.modes is empty")
        return rows
    eig = eigenvalues_of(modes_or_system)
    reps = np.unique(np.where(eig.imag < 0, eig.conj(), eig))  # each pair once
    ordered = sorted((complex(x) for x in reps), key=lambda x: (abs(x), x.imag))
    return [(f"mode {i + 1}", x, None) for i, x in enumerate(ordered)]


def _numerical_eigenvalue(coef: np.ndarray, h: float, lam: complex) -> tuple[complex, float]:
    """``λ_h = ln R(hλ) / h`` and ``|R(hλ)|``, accurate when ``R(hλ)`` is near 1.

    With ``R - 1 = w = x + iy`` formed from ``z·(c₁ + c₂z + ...)`` (no
    cancellation), ``ln R = ½ log1p(2x + x² + y²) + i atan2(y, 1 + x)``.
    A plain ``log(R)`` loses ``eps/|hλ|`` relative: 1e-11 at ``h|λ| = 1e-5``.
    """
    z = h * lam
    w = complex(z * np.polynomial.polynomial.polyval(z, coef[1:]))
    x, y = w.real, w.imag + 0.0
    g = 2 * x + x * x + y * y  # |R|² - 1
    if g <= -1:
        return complex(-math.inf, 0.0), 0.0
    log_r = complex(0.5 * math.log1p(g), math.atan2(y, 1 + x))
    return log_r / h, math.sqrt(1 + g)


def numerical_modes(method, h: float, modes) -> pd.DataFrame:
    """Each mode's frequency, damping and decay rate as the method sees it at step h.

    The method maps a mode ``e^{λt}`` to ``R(hλ)^n``, i.e. to the
    continuous eigenvalue

    .. math:: \\lambda_h = \\frac{\\ln R(h\\lambda)}{h}

    (principal logarithm). From ``λ_h`` come the numerical damped frequency
    ``Im λ_h / 2π``, damping ratio ``-Re λ_h / |λ_h|`` and decay rate
    ``σ_h = -Re λ_h = -ln|R(hλ)| / h``.

    Parameters
    ----------
    method : str or ButcherTableau
    h : float
        Step size [s], > 0.
    modes : object with ``.modes``, control.StateSpace, or eigenvalues
        Named modes: any object whose ``modes`` are objects with ``.name``
        and ``.eigenvalue`` (and optionally ``.zeta``), such as
        `qc_control.modal_analysis`'s result; one row per mode, indexed by
        name. Or a system or its eigenvalues (`eigenvalues_of`): one row
        per eigenvalue, a conjugate pair once (Im > 0), named ``mode 1``,
        ``mode 2``, ... by increasing ``|λ|``.

    Returns
    -------
    pandas.DataFrame
        Indexed by mode, with the exact and the numerical ``fd [Hz]``,
        ``zeta`` and decay rate ``sigma [1/s]``; the frequency error [%]
        (negative: the method's oscillation is slow); the damping error
        ``zeta_h - zeta`` (negative: the method removes damping); the
        ``decay rate error [%]`` ``100 (σ_h - σ)/σ``; ``|R(hλ)|`` and
        ``h|λ|``.

    Notes
    -----
    A real eigenvalue (an overdamped mode) does not oscillate: its
    ``fd`` is 0, so the frequency error is nan, and its numerical
    counterpart has ``ζ_h = 1`` (or, when ``R(hλ) < 0``, an alias at the
    Nyquist frequency ``1/2h``) whatever the step. Comparing that with a
    mode's ζ > 1 says nothing about accuracy, so for a real eigenvalue
    ``zeta_h`` and ``zeta error`` are nan and the accuracy is in the
    ``decay rate error [%]``. (The ``zeta`` column keeps the mode's own
    ζ when ``modes`` gives it, e.g. the overdamped pair's ζ > 1.)

    Euler's ``|1 + hλ|`` exceeds ``e^{h Re λ}`` and removes damping;
    Midpoint and Heun add damping. For RK4,
    ``h λ_h = z - z^5/120 + z^6/144 + O(z^7)`` with ``z = hλ``; writing
    ``z = y e^{i(π/2 + δ)}`` (``sin δ = ζ``) the decay rate changes by
    ``(y^5 sin 5δ / 120 - y^6 cos 6δ / 144) / h``. RK4 therefore adds a
    little damping only to modes with ``ζ ≲ h|λ|/6`` (near the
    imaginary axis) and removes a little from better-damped ones. When
    ``h Im λ`` nears π the logarithm aliases and the frequency error is
    meaningless; the column ``h*|lambda|`` shows how close that is.

    Examples
    --------
    Euler at h = 10 ms on the seed's body mode and on a real eigenvalue:

    >>> nm = numerical_modes("euler", 0.01, [-0.4622 + 6.8138j, -0.4622 - 6.8138j, -50.0])
    >>> body, real = nm.loc["mode 1"], nm.loc["mode 2"]
    >>> round(float(body["zeta error"]), 3), round(float(real["decay rate error [%]"]), 1)
    (-0.034, 38.6)
    >>> bool(np.isnan(real["zeta error"]))  # a real eigenvalue: compare decay rates
    True
    """
    _check_order_of_arguments("numerical_modes", method, modes)
    if (
        isinstance(h, bool)
        or not isinstance(h, (int, float, np.integer, np.floating))
        or not math.isfinite(h)
        or h <= 0
    ):
        raise ValueError(f"h must be a finite step > 0 s, got {show(h)}")
    coef = stability_coefficients(method)
    rows = {}
    for name, lam, mode_zeta in _mode_rows(modes):
        lam_h, mu = _numerical_eigenvalue(coef, h, lam)
        wn, wn_h = abs(lam), abs(lam_h)
        real = lam.imag == 0
        zeta = mode_zeta if mode_zeta is not None else (-lam.real / wn if wn > 0 else math.nan)
        zeta_h = -lam_h.real / wn_h if wn_h > 0 and not real else math.nan
        sigma, sigma_h = -lam.real, -lam_h.real
        fd, fd_h = lam.imag / (2 * math.pi), lam_h.imag / (2 * math.pi)
        rows[name] = {
            "fd [Hz]": fd,
            "fd_h [Hz]": fd_h,
            "freq error [%]": 100 * (fd_h - fd) / fd if fd else math.nan,
            "zeta": zeta,
            "zeta_h": zeta_h,
            "zeta error": zeta_h - zeta if not real else math.nan,
            "sigma [1/s]": sigma,
            "sigma_h [1/s]": sigma_h,
            "decay rate error [%]": 100 * (sigma_h - sigma) / sigma if sigma else math.nan,
            "|R(h*lambda)|": mu,
            "h*|lambda|": h * wn,
        }
    frame = pd.DataFrame.from_dict(rows, orient="index")
    frame.index.name = "mode"
    return frame
