"""Linear stability of the fixed-step methods on an LTI system.

On ``x' = A x`` one step of a Runge–Kutta method is
``x_{n+1} = R(hA) x_n``, where ``R`` is the method's stability function:
a polynomial for an explicit method, a rational function for an implicit
one. Along each eigenvector the step multiplies by ``R(hλ)``: the method
is stable when ``|R(hλ)| <= 1`` for every eigenvalue, and it sees the
mode with the eigenvalue ``λ_h = ln R(hλ) / h`` (Hairer & Wanner,
*Solving ODEs II*, §IV.2-IV.3). An A-stable method (``|R| <= 1`` on the
whole left half-plane) has no step limit on a stable system; an L-stable
one also has ``R(∞) = 0`` and damps the stiffest modes out.

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
from dataclasses import dataclass

import contourpy
import control
import numpy as np
import pandas as pd
from numpy.polynomial import Polynomial

from .messages import show
from .methods import get_method

__all__ = [
    "StabilityFunction",
    "stability_function",
    "stability_coefficients",
    "amplification",
    "step_is_stable",
    "max_stable_step",
    "numerical_modes",
    "stability_boundary",
    "step_verdict",
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


@dataclass(frozen=True, eq=False)
class StabilityFunction:
    """The stability function ``R(z) = P(z) / Q(z)`` of a Runge–Kutta method.

    One step on ``x' = λx`` multiplies ``x`` by ``R(hλ)``. For an
    explicit method ``Q = 1`` and ``R`` is a polynomial; for an implicit
    one ``R`` is rational (`stability_function`).

    Attributes
    ----------
    numerator, denominator : numpy.polynomial.Polynomial
        ``P`` and ``Q``, lowest power first, ``P(0) = Q(0) = 1``;
        coefficients below their rounding are zero, so the degrees are
        the true ones (``deg P < deg Q`` for an L-stable method).
    """

    numerator: Polynomial
    denominator: Polynomial

    def __call__(self, z):
        """``R(z)``, element by element; ``inf`` at a pole."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.numerator(z) / self.denominator(z)

    @property
    def is_polynomial(self) -> bool:
        """Whether ``Q = 1`` (every explicit method)."""
        return self.denominator.degree() == 0

    @property
    def coef(self) -> np.ndarray:
        """The polynomial's coefficients, lowest power first (explicit methods).

        Raises
        ------
        ValueError
            For a rational ``R``: use `numerator` and `denominator`.
        """
        if not self.is_polynomial:
            raise ValueError(
                "R(z) of an implicit method is rational: read .numerator and .denominator"
            )
        return self.numerator.coef

    @property
    def poles(self) -> np.ndarray:
        """The roots of ``Q`` (none for an explicit method)."""
        return self.denominator.roots()

    @property
    def at_infinity(self) -> float:
        """``R(∞) = lim R(z)`` as ``|z| → ∞``: 0 when ``deg P < deg Q``, the
        ratio of the leading coefficients when equal, ``inf`` when ``deg P > deg Q``."""
        dp, dq = self.numerator.degree(), self.denominator.degree()
        if dp < dq:
            return 0.0
        if dp > dq:
            return math.inf
        return float(self.numerator.coef[-1] / self.denominator.coef[-1])

    @property
    def a_stable(self) -> bool:
        """``|R(z)| <= 1`` on the whole left half-plane.

        By the maximum principle this holds if and only if ``R`` has no pole
        with ``Re z <= 0`` and ``E(y) = |Q(iy)|² - |P(iy)|² >= 0`` for every
        real ``y`` (HW II, §IV.3, Theorem 3.3, the E-polynomial). A
        non-constant polynomial is unbounded, hence never A-stable.
        """
        if self.numerator.degree() > self.denominator.degree():
            return False
        if np.any(self.poles.real <= 0):
            return False
        return _e_polynomial_nonnegative(self.numerator.coef, self.denominator.coef)

    @property
    def l_stable(self) -> bool:
        """A-stable with ``R(∞) = 0``: the stiffest modes are damped out in one step
        (HW II, §IV.3, Definition 3.7)."""
        return self.a_stable and self.at_infinity == 0.0


def _e_polynomial_nonnegative(p: np.ndarray, q: np.ndarray) -> bool:
    """``|Q(iy)|² - |P(iy)|² >= 0`` for every real ``y``, within rounding.

    ``E`` is even in ``y``: with ``w = y²`` it is a real polynomial ``F(w)``,
    whose sign is constant between its positive roots; it is checked at one
    point in each stretch and beyond the last.
    """
    size = max(p.size, q.size)
    i_pow = 1j ** np.arange(size)
    pi, qi = np.zeros(size, complex), np.zeros(size, complex)
    pi[: p.size], qi[: q.size] = p * i_pow[: p.size], q * i_pow[: q.size]
    e = (np.convolve(qi, qi.conj()) - np.convolve(pi, pi.conj())).real
    scale = np.convolve(np.abs(qi), np.abs(qi)) + np.convolve(np.abs(pi), np.abs(pi))
    e[np.abs(e) <= 64 * size * _EPS * scale] = 0
    f, f_scale = e[::2], scale[::2]  # the odd powers of y cancel
    if not np.any(f):
        return True  # |R| = 1 on the whole axis (Gauss, the trapezoidal rule)
    roots = Polynomial(f).roots()
    w = np.sort(roots.real[(np.abs(roots.imag) <= 1e-9 * np.abs(roots)) & (roots.real > 0)])
    edges = np.concatenate([[0.0], w])
    probes = np.concatenate([0.5 * (edges[:-1] + edges[1:]), [2 * edges[-1] + 1]])
    values = np.polynomial.polynomial.polyval(probes, f)
    bound = np.polynomial.polynomial.polyval(probes, f_scale)
    return bool(np.all(values >= -64 * size * _EPS * bound))


def _det_polynomial(M: np.ndarray) -> np.ndarray:
    """Coefficients of ``det(I - zM)``, lowest power first (Faddeev–LeVerrier).

    ``det(λI - M) = λ^s + c₁λ^{s-1} + ... + c_s`` gives ``det(I - zM) =
    1 + c₁z + ... + c_s z^s``; the recursion ``M_k = M M_{k-1} + c_{k-1} I``,
    ``c_k = -tr(M M_k)/k`` uses products and traces only, so a nilpotent
    ``M`` gives exact zeros (Gantmacher, *Theory of Matrices* I, §IV.4).
    Coefficients below the rounding of ``|M|^k`` are set to zero.
    """
    s = M.shape[0]
    coef, Mk = [1.0], np.zeros_like(M)
    norm = max(1.0, float(np.abs(M).sum(axis=1).max()))
    for k in range(1, s + 1):
        Mk = M @ Mk + coef[-1] * np.eye(s)
        ck = -float(np.trace(M @ Mk)) / k
        coef.append(0.0 if abs(ck) <= 64 * s * k * _EPS * norm**k else ck)
    while len(coef) > 1 and coef[-1] == 0:
        coef.pop()
    return np.array(coef)


def stability_function(method) -> StabilityFunction:
    """The stability function R(z) of a Runge–Kutta method.

    .. math::

        R(z) = 1 + z\\, b^T (I - zA)^{-1} \\mathbf{1}
             = \\frac{\\det(I - zA + z \\mathbf{1} b^T)}{\\det(I - zA)}

    (HW II, §IV.3, eq. 3.3). For an explicit method ``A`` is nilpotent,
    ``det(I - zA) = 1`` and ``R`` is the polynomial
    ``1 + Σ_{k<s} z^{k+1} bᵀA^k 1`` (HW II, §IV.2, eq. 2.3), summed exactly
    that way. For an implicit method both determinants are polynomials of
    degree at most ``s``, found without eigenvalues (`_det_polynomial`).

    Returns
    -------
    StabilityFunction
        Callable on ``z``, with its numerator and denominator, its poles,
        ``R(∞)`` and whether the method is A- and L-stable.

    Examples
    --------
    >>> stability_function("rk4").coef.round(6).tolist()   # 1 + z + z²/2 + z³/6 + z⁴/24
    [1.0, 1.0, 0.5, 0.166667, 0.041667]
    >>> stability_function("euler").coef.tolist()
    [1.0, 1.0]
    >>> R = stability_function("backward_euler")            # 1/(1 - z)
    >>> R.numerator.coef.tolist(), R.denominator.coef.tolist(), R.l_stable
    ([1.0], [1.0, -1.0], True)
    >>> R = stability_function("trapezoidal")               # (1 + z/2)/(1 - z/2)
    >>> R.a_stable, R.at_infinity
    (True, -1.0)
    """
    tab = get_method(method)
    if tab.implicit:
        num = _det_polynomial(tab.a - np.outer(np.ones(tab.stages), tab.b))
        return StabilityFunction(Polynomial(num), Polynomial(_det_polynomial(tab.a)))
    coef, v = [1.0], np.ones(tab.stages)
    for _ in range(tab.stages):
        coef.append(float(tab.b @ v))
        v = tab.a @ v
    while len(coef) > 1 and coef[-1] == 0:
        coef.pop()
    return StabilityFunction(Polynomial(coef), Polynomial([1.0]))


@functools.lru_cache(maxsize=64)
def _rational(method) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(P, Q, (P - Q)/z)``'s coefficients of R = P/Q, read-only (cached per tableau).

    The third, ``R - 1 = z · ((P - Q)/z) / Q``, is R's departure from 1
    without cancellation near ``z = 0`` (`_numerical_eigenvalue`).
    """
    R = stability_function(method)
    p, q = R.numerator.coef.copy(), R.denominator.coef.copy()
    diff = np.zeros(max(p.size, q.size))
    diff[: p.size] += p
    diff[: q.size] -= q
    excess = diff[1:] if diff.size > 1 else np.zeros(1)
    for arr in (p, q, excess):
        arr.flags.writeable = False
    return p, q, excess


def _r_of(method, z):
    """``R(z)`` of ``method`` from its cached coefficients (``inf`` at a pole)."""
    p, q, _ = _rational(method)
    # a step far outside the region (hλ of a diverged state's Jacobian) overflows
    # R to inf, read as unstable: the right answer, not a numerical fault to warn of
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        num = np.polynomial.polynomial.polyval(z, p)
        if q.size == 1:
            return num
        return num / np.polynomial.polynomial.polyval(z, q)


@functools.lru_cache(maxsize=64)
def _coefficients(method) -> np.ndarray:
    tab = get_method(method)
    if tab.implicit:
        # R's Taylor series 1 + Σ z^{k+1} bᵀA^k 1 through z^{2s+1}: past the
        # order (at most 2s) by one, enough for the error constant
        terms, v = [1.0], np.ones(tab.stages)
        for _ in range(2 * tab.stages + 1):
            terms.append(float(tab.b @ v))
            v = tab.a @ v
        coef = np.array(terms)
    else:
        coef = stability_function(method).coef
    coef.flags.writeable = False
    return coef


def stability_coefficients(method) -> np.ndarray:
    """R(z)'s coefficients, lowest power first (cached per tableau; read-only).

    For an explicit method, the polynomial itself. For an implicit method,
    whose ``R`` is rational, the Taylor coefficients of ``R`` at 0 through
    ``z^{2s+1}`` (one past the highest order an ``s``-stage method can
    have), from which the order and the error constant are read; evaluate
    ``R`` itself with `stability_function`.
    """
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
    z = h * _batch_eigenvalues(eigenvalues)
    radius = np.max(np.abs(_r_of(get_method(method), z)), axis=-1)
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
    tab = get_method(method)
    lam = settle_marginal(_batch_eigenvalues(eigenvalues))
    radius = np.abs(_r_of(tab, h * lam))
    ok = (radius <= 1 + AMPLIFICATION_MARGIN) | (lam.real > 0)
    ok = np.all(ok, axis=-1)
    return bool(ok) if ok.ndim == 0 else ok


@functools.lru_cache(maxsize=1024)  # pure; the explorer asks again at every redraw
def _step_limit(tab, lam: complex) -> float:
    """The largest h with ``|R(hλ)| <= 1`` on ``(0, h]``, for one settled λ.

    With ``y = h|λ|``, ``u = λ/|λ|`` and ``R = N/D``,
    ``P(y) = |N(yu)|² - |D(yu)|²`` (``|R|² - 1`` for an explicit method,
    ``D = 1``) is a real polynomial with ``P(0) = 0`` and the sign of
    ``|R(yu)| - 1``. Coefficients below their rounding are zeroed; if the
    lowest remaining one is positive, ``|R|`` exceeds 1 for every small h
    (limit 0). Otherwise the limit is the first positive root of ``P``
    after which ``P > 0``, checked on ``|R|`` itself.
    """
    size = abs(lam)
    if size == 0:
        return math.inf
    if lam.real > 0:
        return 0.0
    num, den, _ = _rational(tab)
    width = max(num.size, den.size)
    u = lam / size  # exactly 1j on the axis, so odd powers stay purely imaginary
    terms = [1.0 + 0j]
    for _ in range(width - 1):
        terms.append(terms[-1] * u)
    powers = np.array(terms)
    p, bound = np.zeros(2 * width - 1), np.zeros(2 * width - 1)
    for poly, sign in ((num, 1.0), (den, -1.0)):
        r = poly * powers[: poly.size]
        p[: 2 * poly.size - 1] += sign * np.convolve(r, np.conj(r)).real
        bound[: 2 * poly.size - 1] += np.convolve(np.abs(poly), np.abs(poly))
    p[np.abs(p) <= 64 * width * _EPS * bound] = 0
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
        return abs(_r_of(tab, y * u)) > 1

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
        ``inf`` if no eigenvalue limits the step (every eigenvalue of a
        stable system under an A-stable method: backward Euler, Gauss,
        Radau IIA, the trapezoidal rule, SDIRK); ``0.0`` if some
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
    tab = get_method(method)
    lam = settle_marginal(eigenvalues_of(sys_or_eigenvalues))
    lam = np.unique(np.where(lam.imag < 0, lam.conj(), lam))  # a conjugate has the same limit
    return min((_step_limit(tab, complex(x)) for x in lam), default=math.inf)


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


def _numerical_eigenvalue(tab, h: float, lam: complex) -> tuple[complex, float]:
    """``λ_h = ln R(hλ) / h`` and ``|R(hλ)|``, accurate when ``R(hλ)`` is near 1.

    With ``R - 1 = w = x + iy`` formed from ``z·(c₁ + c₂z + ...) / D(z)``
    (``R = N/D``, ``N - D = z (c₁ + c₂z + ...)``: no cancellation),
    ``ln R = ½ log1p(2x + x² + y²) + i atan2(y, 1 + x)``. A plain
    ``log(R)`` loses ``eps/|hλ|`` relative: 1e-11 at ``h|λ| = 1e-5``.
    """
    _, den, excess = _rational(tab)
    z = h * lam
    w = complex(z * np.polynomial.polynomial.polyval(z, excess))
    if den.size > 1:
        w = w / complex(np.polynomial.polynomial.polyval(z, den))
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

    Backward Euler, ``R = 1/(1 - z)``, adds damping: on an undamped mode
    ``iω`` its decay rate is ``ln(1 + ω²h²)/(2h)`` and its frequency
    ``atan(ωh)/h``. The trapezoidal rule and implicit midpoint,
    ``R = (1 + z/2)/(1 - z/2)``, keep ``|R| = 1`` on the imaginary axis (no
    damping added or removed) and warp the frequency to
    ``(2/h) atan(ωh/2)``, the bilinear (Tustin) map's warping.

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
    tab = get_method(method)
    rows = {}
    for name, lam, mode_zeta in _mode_rows(modes):
        lam_h, mu = _numerical_eigenvalue(tab, h, lam)
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


def stability_boundary(method, x, y) -> list[np.ndarray]:
    """The boundary ``|R(z)| = 1`` of a method's stability region in a window.

    The level curve 1 of ``|R|`` on the grid ``x + iy`` (``z = hλ``), traced
    by marching squares (``contourpy``, matplotlib's contouring): each curve
    is accurate to about the grid's spacing. An implicit method's poles,
    where ``|R|`` is infinite, are held at 1e6, which draws the same curve.

    Parameters
    ----------
    method : str or ButcherTableau
    x, y : array_like, 1-D, increasing
        The window's real and imaginary parts of ``z = hλ``.

    Returns
    -------
    list of ndarray of complex
        The boundary's pieces within the window, each a connected curve.

    Examples
    --------
    Euler's region is the disc ``|1 + z| <= 1``:

    >>> x = np.linspace(-2.5, 0.5, 301)
    >>> (curve,) = stability_boundary("euler", x, x + 1.0)
    >>> bool(np.all(np.abs(np.abs(1 + curve) - 1) < 0.01))
    True
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.ndim != 1 or y.ndim != 1 or x.size < 2 or y.size < 2:
        raise ValueError(
            f"x and y must be 1-D grids of at least 2 points, got shapes {x.shape} and {y.shape}"
        )
    z = x[None, :] + 1j * y[:, None]
    size = np.minimum(np.abs(_r_of(get_method(method), z)), 1e6)
    lines = contourpy.contour_generator(x, y, size).lines(1.0)  # LineType.Separate: (n, 2) each
    curves = [np.asarray(line, dtype=float) for line in lines]
    return [c[:, 0] + 1j * c[:, 1] for c in curves]


def step_verdict(h: float, h_max: float) -> str:
    """A method's step against its stability limit, in words.

    ``'stable (h is 62 % of h_max)'``, ``'beyond its limit by 23 %'``
    (``100 (h/h_max - 1)``), ``'stable at every step'`` (``h_max`` infinite)
    or ``'no stable step (h_max = 0)'``; stable means ``h <= h_max``, as in
    the comparison's ``stable`` column.

    Examples
    --------
    >>> step_verdict(0.0246, 0.02), step_verdict(0.01, 0.02)
    ('beyond its limit by 23 %', 'stable (h is 50 % of h_max)')
    """
    if math.isinf(h_max):
        return "stable at every step"
    if h_max <= 0:
        return "no stable step (h_max = 0)"
    if h <= h_max:
        return f"stable (h is {100 * h / h_max:.0f} % of h_max)"
    return f"beyond its limit by {100 * (h / h_max - 1):.0f} %"
