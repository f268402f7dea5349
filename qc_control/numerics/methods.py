"""Runge–Kutta methods as data: a Butcher tableau per method.

A method with ``s`` stages advances ``x' = f(t, x)`` by one step ``h``:

.. math::

    k_i = f\\Big(t + c_i h,\\; x + h \\sum_{j} a_{ij} k_j\\Big), \\qquad
    x_{n+1} = x_n + h \\sum_i b_i k_i

(Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.1). When ``a`` is
strictly lower triangular the method is explicit and each stage follows
from the earlier ones; otherwise it is implicit and the stages solve a
system of equations (Hairer & Wanner, *Solving ODEs II*, §IV.5, §IV.8).
`qc_control.numerics.integrate` runs every tableau; the seed's four
methods are the four entries of `METHODS`, and `TABLEAUS` holds every
named tableau.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from .checks import ParameterError
from .messages import show
from .order_conditions import MAX_ORDER, check_order

__all__ = [
    "ButcherTableau",
    "METHODS",
    "TABLEAUS",
    "get_method",
    "EULER",
    "MIDPOINT",
    "HEUN",
    "RK4",
    "BACKWARD_EULER",
    "IMPLICIT_MIDPOINT",
    "TRAPEZOIDAL",
    "GAUSS2",
    "GAUSS3",
    "RADAU2",
    "RADAU3",
    "SDIRK2",
    "HEUN_EULER",
    "BOGACKI_SHAMPINE",
    "DORMAND_PRINCE",
]

_EPS = np.finfo(float).eps


def _real_array(value, what: str, where: str) -> np.ndarray:
    """``value`` as a float array, or a ValueError naming ``what`` and the value."""
    try:
        arr = np.array(value)
        if arr.dtype.kind not in "biuf":  # not bool, int or float: strings, None, complex
            raise TypeError
        arr = arr.astype(float)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: {what} must be real numbers, got {show(value)}") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{where}: {what} must be finite, got {show(value)}")
    return arr


@dataclass(frozen=True, eq=False)
class ButcherTableau:
    """A Runge–Kutta method, explicit or implicit: coefficients ``a``, ``b``, ``c``.

    Parameters
    ----------
    name : str
        Short name, used in tables and figure legends.
    a : array_like, shape (s, s)
        Stage coefficients: strictly lower triangular for an explicit
        method; any non-zero entry on or above the diagonal makes the
        method implicit (diagonally implicit when only the diagonal is
        non-zero above the lower triangle, fully implicit otherwise).
    b : array_like, shape (s,)
        Weights, summing to 1.
    c : array_like, shape (s,), optional
        Nodes; row ``i`` of ``a`` must sum to ``c[i]``. Default: those sums.
    order : int, optional
        Classical order p. Computed from the tableau when left out; when
        given, it must be the computed order.
    b_hat : array_like, shape (s,), optional
        The weights of an embedded method ``x + h Σ b̂_i k_i`` of another
        order on the same stages, summing to 1 and different from ``b``:
        ``h Σ (b_i - b̂_i) k_i`` estimates the local error at no extra
        evaluation (HNW I, §II.4), for step-size control
        (`qc_control.numerics.adaptive`). The pair's `error_order` is the
        lower of the two orders, each computed from the rooted trees.

    Raises
    ------
    ValueError
        When an entry is not a finite real number, the tableau is not
        consistent, the stated order is not its order, or ``b_hat`` is not an
        embedded method of the same stages.

    Notes
    -----
    The order is the largest ``p`` for which ``Φ(t) = 1/γ(t)`` holds on
    every rooted tree with at most ``p`` vertices (Butcher, *Numerical
    Methods for ODEs*, 3rd ed., §31-§32; HNW I, §II.2, Table 2.2), checked
    up to ``min(s, MAX_ORDER)`` for an explicit method (an explicit
    ``s``-stage method has order at most ``s``) and ``min(2s, MAX_ORDER)``
    for an implicit one (at most ``2s``, reached by Gauss–Legendre; HW II,
    §IV.5) by `qc_control.numerics.order_conditions.check_order`. The
    conditions are the same for implicit methods.

    A tableau equals another with the same name, coefficients and order,
    and equals the string of its name, so ``resp.method == "heun"`` reads
    as meant. The hash is that of the name, consistent with both.

    Examples
    --------
    Ralston's second-order method:

    >>> ralston = ButcherTableau("ralston", a=[[0, 0], [2/3, 0]], b=[1/4, 3/4],
    ...                          c=[0, 2/3])
    >>> ralston.stages, ralston.order
    (2, 2)
    >>> ralston == "ralston"
    True
    >>> ButcherTableau("bad", a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 0.5], order=2)
    Traceback (most recent call last):
    ...
    ValueError: tableau 'bad': row 1 of a sums to 1, but c[1] = 0.5
    """

    name: str
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray = None  # type: ignore[assignment]  # None: the row sums of a
    order: int = None  # type: ignore[assignment]  # None: computed
    b_hat: np.ndarray | None = None  # None: no error estimator

    if TYPE_CHECKING:  # what the generated __init__ accepts; each field ends an array/int

        def __init__(
            self,
            name: str,
            a: npt.ArrayLike,
            b: npt.ArrayLike,
            c: npt.ArrayLike | None = None,
            order: int | None = None,
            b_hat: npt.ArrayLike | None = None,
        ) -> None: ...

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"tableau name must be a non-empty string, got {show(self.name)}")
        where = f"tableau {self.name!r}"
        a = _real_array(self.a, "a", where)
        b = _real_array(self.b, "b", where)
        s = b.shape[0] if b.ndim == 1 else -1
        c = a.sum(axis=-1) if self.c is None and a.shape == (s, s) else self.c
        c = _real_array(c, "c", where)
        if s < 1 or a.shape != (s, s) or c.shape != (s,):
            raise ValueError(
                f"{where}: need a (s, s), b (s,), c (s,); got a {a.shape}, b {b.shape}, c {c.shape}"
            )
        for i in range(s):
            # rounding of the row sum: a few eps times the sum of magnitudes
            if abs(a[i].sum() - c[i]) > 64 * s * _EPS * max(1.0, np.abs(a[i]).sum()):
                raise ValueError(
                    f"{where}: row {i} of a sums to {a[i].sum():.15g}, but c[{i}] = {c[i]:.15g}"
                )
        if abs(b.sum() - 1) > 64 * s * _EPS * max(1.0, np.abs(b).sum()):
            raise ValueError(f"{where}: b sums to {b.sum():.15g}, not 1")
        claimed = self.order
        if claimed is not None and (
            isinstance(claimed, bool) or not isinstance(claimed, (int, np.integer)) or claimed < 1
        ):
            raise ValueError(f"{where}: order must be a positive integer, got {show(claimed)}")
        # the highest order an s-stage method can have: s explicit, 2s implicit
        bound = 2 * s if np.any(np.triu(a) != 0) else s
        top = min(bound, MAX_ORDER)
        if claimed is not None:
            # one order beyond the bound when more is claimed, to name the first failing tree
            top = min(max(top, min(claimed, bound + 1)), MAX_ORDER)
        found = check_order(a, b, top)
        if claimed is not None and claimed > found.order:
            if found.failing_tree is None:
                raise ValueError(
                    f"{where}: claims order {claimed}; it meets every condition up to order "
                    f"{found.order}, and orders are verified only up to {MAX_ORDER}"
                )
            kind = "an explicit" if bound == s else "an implicit"
            limit = (
                f"; {kind} method with {s} stages has order at most {bound}"
                if claimed > bound
                else ""
            )
            raise ValueError(
                f"{where}: claims order {claimed} but fails the order-{found.order + 1} "
                f"conditions ({found.failing}); its order is {found.order}{limit}"
            )
        if claimed is not None and claimed < found.order:
            raise ValueError(
                f"{where}: claims order {claimed}, but it meets every condition of order "
                f"{found.order}; give order={found.order} or leave order out"
            )
        for arr in (a, b, c):
            arr.flags.writeable = False
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "c", c)
        object.__setattr__(self, "order", found.order)
        self._set_embedded(where)

    @property
    def stages(self) -> int:
        """Number of stages s: right-hand-side evaluations per step (explicit)."""
        return self.b.shape[0]

    @property
    def implicit(self) -> bool:
        """Whether any ``a_ij`` on or above the diagonal is non-zero: the stages
        then solve equations (each step a Newton iteration on a nonlinear system)."""
        return bool(np.any(np.triu(self.a) != 0))

    def _set_embedded(self, where: str) -> None:
        """Check ``b_hat`` against ``b`` and keep the embedded method's order."""
        if self.b_hat is None:
            object.__setattr__(self, "_embedded_order", None)
            return
        b, s = self.b, self.stages
        b_hat = _real_array(self.b_hat, "b_hat", where)
        if b_hat.shape != b.shape:
            raise ValueError(f"{where}: b_hat must have shape {b.shape} like b, got {b_hat.shape}")
        if abs(b_hat.sum() - 1) > 64 * s * _EPS * max(1.0, np.abs(b_hat).sum()):
            raise ValueError(f"{where}: b_hat sums to {b_hat.sum():.15g}, not 1")
        if np.array_equal(b_hat, b):
            raise ValueError(f"{where}: b_hat equals b, so it estimates no error")
        b_hat.flags.writeable = False
        object.__setattr__(self, "b_hat", b_hat)
        found = check_order(self.a, b_hat, min(s, MAX_ORDER))
        object.__setattr__(self, "_embedded_order", found.order)

    @property
    def embedded(self) -> bool:
        """Whether the tableau carries an error estimator ``b_hat``."""
        return self.b_hat is not None

    @property
    def embedded_order(self) -> int | None:
        """The order of the embedded method ``b_hat`` (None without one)."""
        return self._embedded_order  # type: ignore[attr-defined]

    @property
    def error_order(self) -> int | None:
        """The order q of the error estimate: ``h Σ (b_i - b̂_i) k_i = O(h^{q+1})``.

        ``q = min(p, p̂)`` of the two methods (HNW I, §II.4); the step-size
        controller's exponent is ``-1/(q + 1)``. None without ``b_hat``.
        """
        p_hat = self.embedded_order
        return None if p_hat is None else min(self.order, p_hat)

    def __eq__(self, other) -> bool:
        if isinstance(other, str):
            return other == self.name
        if isinstance(other, ButcherTableau):
            return (
                other.name == self.name
                and other.order == self.order
                and np.array_equal(other.a, self.a)
                and np.array_equal(other.b, self.b)
                and np.array_equal(other.c, self.c)
                and _same_weights(other.b_hat, self.b_hat)
            )
        return NotImplemented

    def __hash__(self) -> int:
        return hash(self.name)

    def __repr__(self) -> str:
        return f"ButcherTableau({self.name!r}, order={self.order}, stages={self.stages})"


def _same_weights(x: np.ndarray | None, y: np.ndarray | None) -> bool:
    """Equal error estimators: both absent, or equal arrays."""
    if x is None or y is None:
        return x is y
    return np.array_equal(x, y)


#: Forward Euler: x + h f(x) (seed, 4.2.1).
EULER = ButcherTableau("euler", a=[[0.0]], b=[1.0], c=[0.0], order=1)
#: Explicit midpoint: x + h f(x + h/2 f(x)) (seed, 4.2.2).
MIDPOINT = ButcherTableau(
    "midpoint", a=[[0.0, 0.0], [0.5, 0.0]], b=[0.0, 1.0], c=[0.0, 0.5], order=2
)
#: Heun: x + h/2 (f(x) + f(x + h f(x))) (seed, 4.2.4).
HEUN = ButcherTableau("heun", a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 1], order=2)
#: Classic RK4: x + h/6 (k1 + 2 k2 + 2 k3 + k4) (seed, 4.2.3).
RK4 = ButcherTableau(
    "rk4",
    a=[[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]],
    b=[1 / 6, 1 / 3, 1 / 3, 1 / 6],
    c=[0.0, 0.5, 0.5, 1.0],
    order=4,
)

#: The seed's four methods by name.
METHODS: dict[str, ButcherTableau] = {t.name: t for t in (EULER, MIDPOINT, HEUN, RK4)}

# ---------------------------------------------------------------- implicit tableaus
# Sources: Hairer & Wanner, *Solving ODEs II*, 2nd ed. (HW II), §IV.3 (Table 3.1
# of Padé approximants), §IV.5 (Tables 5.1 and 5.2: Gauss and Radau IIA),
# §IV.6 (SDIRK); Butcher, *Numerical Methods for ODEs*, 3rd ed., §34.

_SQRT3, _SQRT6, _SQRT15 = np.sqrt(3.0), np.sqrt(6.0), np.sqrt(15.0)

#: Backward Euler: x + h f(t + h, x_{n+1}); order 1, L-stable, R(z) = 1/(1 - z).
BACKWARD_EULER = ButcherTableau("backward_euler", a=[[1.0]], b=[1.0], c=[1.0], order=1)
#: Implicit midpoint, the one-stage Gauss method: order 2, A-stable and symplectic,
#: R(z) = (1 + z/2)/(1 - z/2) (HW II, Table 5.1, s = 1).
IMPLICIT_MIDPOINT = ButcherTableau("implicit_midpoint", a=[[0.5]], b=[1.0], c=[0.5], order=2)
#: Trapezoidal rule (Crank–Nicolson), the two-stage Lobatto IIIA method: order 2,
#: A-stable, R(z) = (1 + z/2)/(1 - z/2) (HW II, §IV.5, Table 5.7).
TRAPEZOIDAL = ButcherTableau(
    "trapezoidal", a=[[0.0, 0.0], [0.5, 0.5]], b=[0.5, 0.5], c=[0.0, 1.0], order=2
)
#: Gauss–Legendre, two stages: order 4, A-stable, R the (2, 2) Padé approximant
#: of e^z (HW II, Table 5.1; Butcher §342).
GAUSS2 = ButcherTableau(
    "gauss2",
    a=[[1 / 4, 1 / 4 - _SQRT3 / 6], [1 / 4 + _SQRT3 / 6, 1 / 4]],
    b=[0.5, 0.5],
    c=[1 / 2 - _SQRT3 / 6, 1 / 2 + _SQRT3 / 6],
    order=4,
)
#: Gauss–Legendre, three stages: order 6, A-stable, R the (3, 3) Padé approximant
#: (HW II, Table 5.2; Butcher §342).
GAUSS3 = ButcherTableau(
    "gauss3",
    a=[
        [5 / 36, 2 / 9 - _SQRT15 / 15, 5 / 36 - _SQRT15 / 30],
        [5 / 36 + _SQRT15 / 24, 2 / 9, 5 / 36 - _SQRT15 / 24],
        [5 / 36 + _SQRT15 / 30, 2 / 9 + _SQRT15 / 15, 5 / 36],
    ],
    b=[5 / 18, 4 / 9, 5 / 18],
    c=[1 / 2 - _SQRT15 / 10, 1 / 2, 1 / 2 + _SQRT15 / 10],
    order=6,
)
#: Radau IIA, two stages: order 3, L-stable, R the (1, 2) Padé approximant
#: (HW II, Table 5.5).
RADAU2 = ButcherTableau(
    "radau2",
    a=[[5 / 12, -1 / 12], [3 / 4, 1 / 4]],
    b=[3 / 4, 1 / 4],
    c=[1 / 3, 1.0],
    order=3,
)
#: Radau IIA, three stages: order 5, L-stable, R the (2, 3) Padé approximant
#: (HW II, Table 5.6); the method of scipy's ``solve_ivp(method='Radau')``.
RADAU3 = ButcherTableau(
    "radau3",
    a=[
        [(88 - 7 * _SQRT6) / 360, (296 - 169 * _SQRT6) / 1800, (-2 + 3 * _SQRT6) / 225],
        [(296 + 169 * _SQRT6) / 1800, (88 + 7 * _SQRT6) / 360, (-2 - 3 * _SQRT6) / 225],
        [(16 - _SQRT6) / 36, (16 + _SQRT6) / 36, 1 / 9],
    ],
    b=[(16 - _SQRT6) / 36, (16 + _SQRT6) / 36, 1 / 9],
    c=[(4 - _SQRT6) / 10, (4 + _SQRT6) / 10, 1.0],
    order=5,
)
_GAMMA = 1 - np.sqrt(2.0) / 2
#: Two-stage SDIRK with γ = 1 - √2/2 (Alexander, SIAM J. Numer. Anal. 14, 1977;
#: HW II, Table 6.1 with its L-stable γ): order 2, stiffly accurate, L-stable,
#: R(z) = (1 + (1 - 2γ) z)/(1 - γz)².
SDIRK2 = ButcherTableau(
    "sdirk2",
    a=[[_GAMMA, 0.0], [1 - _GAMMA, _GAMMA]],
    b=[1 - _GAMMA, _GAMMA],
    c=[_GAMMA, 1.0],
    order=2,
)

#: Every named tableau: the seed's four, then the implicit ones.
TABLEAUS: dict[str, ButcherTableau] = {
    **METHODS,
    **{
        t.name: t
        for t in (
            BACKWARD_EULER,
            IMPLICIT_MIDPOINT,
            TRAPEZOIDAL,
            GAUSS2,
            GAUSS3,
            RADAU2,
            RADAU3,
            SDIRK2,
        )
    },
}


def get_method(method) -> ButcherTableau:
    """A tableau from a name in `TABLEAUS`, or the tableau itself.

    Raises
    ------
    qc_control.ParameterError
        For an unknown name (a ValueError); the message lists the known ones.
    TypeError
        For anything that is neither a string nor a `ButcherTableau`.
    """
    if isinstance(method, ButcherTableau):
        return method
    if isinstance(method, str):
        try:
            return TABLEAUS[method.lower()]
        except KeyError:
            known = ", ".join(TABLEAUS)
            raise ParameterError(
                "method",
                method,
                f"one of {known} or a ButcherTableau",
                message=f"unknown method {method!r}; known methods are {known} "
                "(or pass a ButcherTableau)",
            ) from None
    raise TypeError(
        f"method must be a name in METHODS or TABLEAUS ({', '.join(TABLEAUS)}) or a "
        f"ButcherTableau, got {show(method)}"
    )


# ---------------------------------------------------------------- embedded pairs
# Each carries b_hat, an embedded method on the same stages whose difference
# from b estimates the local error (HNW I, §II.4; step-size control in
# qc_control.numerics.adaptive). The steps are taken with b, the higher order
# ("local extrapolation"), as scipy does. Bogacki–Shampine and Dormand–Prince
# are FSAL: their last stage is f at the step's end (last row of a = b,
# c = 1), the next step's first stage.

#: Heun–Euler 2(1): Heun's step, Euler's as the estimator (HNW I, §II.4).
HEUN_EULER = ButcherTableau(
    "heun_euler", a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 1], order=2, b_hat=[1, 0]
)
#: Bogacki–Shampine 3(2), FSAL (Bogacki & Shampine, Appl. Math. Lett. 2(4),
#: 1989; scipy's RK23, whose E is b - b_hat).
BOGACKI_SHAMPINE = ButcherTableau(
    "bogacki_shampine",
    a=np.array([[0, 0, 0, 0], [1 / 2, 0, 0, 0], [0, 3 / 4, 0, 0], [2 / 9, 1 / 3, 4 / 9, 0]]),
    b=[2 / 9, 1 / 3, 4 / 9, 0],
    c=[0, 1 / 2, 3 / 4, 1],
    order=3,
    b_hat=[7 / 24, 1 / 4, 1 / 3, 1 / 8],
)
#: Dormand–Prince 5(4), FSAL (Dormand & Prince, J. Comput. Appl. Math. 6(1),
#: 1980; HNW I, §II.5, Table 5.2; scipy's RK45 and MATLAB's ode45).
DORMAND_PRINCE = ButcherTableau(
    "dormand_prince",
    a=np.array(
        [
            [0, 0, 0, 0, 0, 0, 0],
            [1 / 5, 0, 0, 0, 0, 0, 0],
            [3 / 40, 9 / 40, 0, 0, 0, 0, 0],
            [44 / 45, -56 / 15, 32 / 9, 0, 0, 0, 0],
            [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0, 0, 0],
            [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0, 0],
            [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0],
        ]
    ),
    b=[35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0],
    c=[0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1],
    order=5,
    b_hat=[5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40],
)

TABLEAUS.update({t.name: t for t in (HEUN_EULER, BOGACKI_SHAMPINE, DORMAND_PRINCE)})
