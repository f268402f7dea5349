"""Explicit Runge–Kutta methods as data: a Butcher tableau per method.

A method with ``s`` stages advances ``x' = f(t, x)`` by one step ``h``:

.. math::

    k_i = f\\Big(t + c_i h,\\; x + h \\sum_{j<i} a_{ij} k_j\\Big), \\qquad
    x_{n+1} = x_n + h \\sum_i b_i k_i

(Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.1). One loop,
`qc_control.integrate`, runs every tableau; the seed's four methods are
four entries of `METHODS`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["ButcherTableau", "METHODS", "get_method", "EULER", "MIDPOINT", "HEUN", "RK4"]

_TOL = 1e-13


def _order_conditions(a, b, c):
    """Residuals of the order conditions for orders 1..4 (HNW I, Table II.2.1)."""
    one = np.ones_like(b)
    ac = a @ c
    return {
        1: [b @ one - 1],
        2: [b @ c - 1 / 2],
        3: [b @ c**2 - 1 / 3, b @ ac - 1 / 6],
        4: [b @ c**3 - 1 / 4, b @ (c * ac) - 1 / 8, b @ (a @ c**2) - 1 / 12, b @ (a @ ac) - 1 / 24],
    }


@dataclass(frozen=True, eq=False)
class ButcherTableau:
    """An explicit Runge–Kutta method: coefficients ``a``, ``b``, ``c``.

    Parameters
    ----------
    name : str
        Short name, used in tables and figure legends.
    a : array_like, shape (s, s)
        Stage coefficients, strictly lower triangular (explicit method).
    b : array_like, shape (s,)
        Weights, summing to 1.
    c : array_like, shape (s,)
        Nodes; row ``i`` of ``a`` sums to ``c[i]``.
    order : int
        Classical order p. Checked against the order conditions up to 4.

    Raises
    ------
    ValueError
        When the tableau is not explicit, not consistent, or does not
        satisfy the conditions of the order it claims.

    Examples
    --------
    Ralston's second-order method:

    >>> ralston = ButcherTableau("ralston", a=[[0, 0], [2/3, 0]], b=[1/4, 3/4],
    ...                          c=[0, 2/3], order=2)
    >>> ralston.stages
    2
    >>> ButcherTableau("bad", a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 0.5], order=2)
    Traceback (most recent call last):
    ...
    ValueError: tableau 'bad': row 1 of a sums to 1, but c[1] = 0.5
    """

    name: str
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    order: int

    def __post_init__(self):
        a = np.array(self.a, dtype=float)
        b = np.array(self.b, dtype=float)
        c = np.array(self.c, dtype=float)
        s = b.shape[0] if b.ndim == 1 else -1
        where = f"tableau {self.name!r}"
        if s < 1 or a.shape != (s, s) or c.shape != (s,):
            raise ValueError(
                f"{where}: need a (s, s), b (s,), c (s,); got a {a.shape}, b {b.shape}, c {c.shape}"
            )
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and np.all(np.isfinite(c))):
            raise ValueError(f"{where}: coefficients must be finite")
        if np.any(np.triu(a) != 0):
            raise ValueError(f"{where}: a must be strictly lower triangular (explicit method)")
        for i in range(s):
            if abs(a[i].sum() - c[i]) > _TOL:
                raise ValueError(
                    f"{where}: row {i} of a sums to {a[i].sum():.15g}, but c[{i}] = {c[i]:.15g}"
                )
        if abs(b.sum() - 1) > _TOL:
            raise ValueError(f"{where}: b sums to {b.sum():.15g}, not 1")
        if (
            isinstance(self.order, bool)
            or not isinstance(self.order, (int, np.integer))
            or self.order < 1
        ):
            raise ValueError(f"{where}: order must be a positive integer, got {self.order!r}")
        residuals = _order_conditions(a, b, c)
        for p in range(1, min(int(self.order), 4) + 1):
            if max(abs(r) for r in residuals[p]) > _TOL:
                raise ValueError(
                    f"{where}: claims order {self.order} but fails the order-{p} conditions"
                )
        for arr in (a, b, c):
            arr.flags.writeable = False
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "c", c)
        object.__setattr__(self, "order", int(self.order))

    @property
    def stages(self) -> int:
        """Number of stages s: right-hand-side evaluations per step."""
        return self.b.shape[0]

    def __repr__(self) -> str:
        return f"ButcherTableau({self.name!r}, order={self.order}, stages={self.stages})"


#: Forward Euler: x + h f(x) (seed, 4.2.1).
EULER = ButcherTableau("euler", a=[[0.0]], b=[1.0], c=[0.0], order=1)
#: Explicit midpoint: x + h f(x + h/2 f(x)) (seed, 4.2.2).
MIDPOINT = ButcherTableau("midpoint", a=[[0, 0], [0.5, 0]], b=[0, 1], c=[0, 0.5], order=2)
#: Heun: x + h/2 (f(x) + f(x + h f(x))) (seed, 4.2.4).
HEUN = ButcherTableau("heun", a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 1], order=2)
#: Classic RK4: x + h/6 (k1 + 2 k2 + 2 k3 + k4) (seed, 4.2.3).
RK4 = ButcherTableau(
    "rk4",
    a=[[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]],
    b=[1 / 6, 1 / 3, 1 / 3, 1 / 6],
    c=[0, 0.5, 0.5, 1],
    order=4,
)

#: The seed's four methods by name.
METHODS: dict[str, ButcherTableau] = {t.name: t for t in (EULER, MIDPOINT, HEUN, RK4)}


def get_method(method) -> ButcherTableau:
    """A tableau from a name in `METHODS`, or the tableau itself.

    Raises
    ------
    ValueError
        For an unknown name; the message lists the known ones.
    TypeError
        For anything that is neither a string nor a `ButcherTableau`.
    """
    if isinstance(method, ButcherTableau):
        return method
    if isinstance(method, str):
        try:
            return METHODS[method.lower()]
        except KeyError:
            raise ValueError(
                f"unknown method {method!r}; known methods are "
                f"{', '.join(METHODS)} (or pass a ButcherTableau)"
            ) from None
    raise TypeError(f"method must be a name or a ButcherTableau, got {type(method).__name__}")
