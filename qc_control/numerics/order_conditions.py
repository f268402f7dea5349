"""Order conditions of Runge–Kutta methods, explicit or implicit, by rooted trees.

A Runge–Kutta method with coefficients ``A``, ``b`` has order ``p`` when its
step agrees with the Taylor series of the exact solution up to ``h^p`` for
every smooth ``f``. By Butcher's theory this holds if and only if, for
every rooted tree ``t`` with ``|t| <= p`` vertices,

.. math::

    \\Phi(t) = \\frac{1}{\\gamma(t)}

(Butcher, *Numerical Methods for Ordinary Differential Equations*, 3rd ed.,
2016, §31-§32; Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.2 and its
Table 2.2). Trees are written recursively: the
single vertex ``τ``, and ``t = [t_1, ..., t_m]``, a root whose children are
the roots of the subtrees ``t_k``. Then

.. math::

    |t| = 1 + \\sum_k |t_k|, \\qquad
    \\gamma(t) = |t| \\prod_k \\gamma(t_k), \\qquad
    \\Phi(t) = b^T u(t), \\quad
    u(\\tau) = \\mathbf 1, \\quad
    u([t_1, \\dots, t_m]) = \\prod_k A\\, u(t_k)

(the product over ``k`` taken entry by entry; ``γ`` is the *density*,
``Φ`` the *elementary weight*). The number of trees of order 1, 2, ...
is 1, 1, 2, 4, 9, 20, 48, 115, 286, 719 (OEIS A000081).

The conditions do not ask ``A`` to be lower triangular: they hold as
written for implicit methods (Butcher §31; HNW I, §II.7, Theorem 7.4), so
Gauss–Legendre with three stages is found to have order 6 from the same
trees.

Here a tree is a sorted tuple of its subtrees, so ``τ = ()``,
``[τ] = ((),)`` and ``[τ, τ] = ((), ())``; equal trees are equal tuples.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Tree",
    "MAX_ORDER",
    "rooted_trees",
    "tree_order",
    "density",
    "tree_str",
    "elementary_weights",
    "OrderCheck",
    "check_order",
]

#: A rooted tree: the sorted tuple of the subtrees at its root.
Tree = tuple

#: Highest order checked. A method of order 9 or more (explicit, or implicit
#: with 5 stages or more) is not in use here; the 1,842 trees up to order 10
#: take a few milliseconds.
MAX_ORDER = 10


def tree_order(t: Tree) -> int:
    """``|t|``: the number of vertices."""
    return 1 + sum(tree_order(child) for child in t)


def density(t: Tree) -> int:
    """``γ(t) = |t| · Π γ(t_k)``, the density (Butcher §30; HNW I §II.2)."""
    g = tree_order(t)
    for child in t:
        g *= density(child)
    return g


def _graft(t: Tree) -> Iterator[Tree]:
    """Every tree made by adding one leaf to one vertex of ``t``."""
    yield tuple(sorted(t + ((),)))
    for i, child in enumerate(t):
        for g in _graft(child):
            yield tuple(sorted(t[:i] + (g,) + t[i + 1 :]))


@functools.cache
def rooted_trees(order: int) -> tuple[Tree, ...]:
    """All rooted trees with ``order`` vertices, each once, in a fixed order.

    Every tree of order ``n`` is a tree of order ``n - 1`` with one leaf
    added, so the trees of order ``n`` are the distinct graftings of those
    of order ``n - 1``.

    Examples
    --------
    >>> [len(rooted_trees(n)) for n in range(1, 9)]
    [1, 1, 2, 4, 9, 20, 48, 115]
    >>> [tree_str(t) for t in rooted_trees(3)]
    ['[τ²]', '[[τ]]']
    """
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise ValueError(f"order must be a positive integer, got {order!r}")
    if order == 1:
        return ((),)
    trees = {g for t in rooted_trees(order - 1) for g in _graft(t)}
    return tuple(sorted(trees, key=lambda t: (_depth(t), t)))


def _depth(t: Tree) -> int:
    return 1 + max((_depth(c) for c in t), default=0)


def tree_str(t: Tree) -> str:
    """Butcher's bracket notation: ``τ``, ``[τ]``, ``[τ²]``, ``[[τ], τ]``."""
    if not t:
        return "τ"
    parts, i = [], 0
    while i < len(t):
        j = i
        while j < len(t) and t[j] == t[i]:
            j += 1
        n = j - i
        sup = "".join("⁰¹²³⁴⁵⁶⁷⁸⁹"[int(d)] for d in str(n)) if n > 1 else ""
        parts.append(tree_str(t[i]) + sup)
        i = j
    return "[" + ", ".join(parts) + "]"


class _Weights:
    """``Φ(t)`` of a tableau, tree by tree, sharing the vectors ``u`` of subtrees."""

    def __init__(self, a, b):
        self.a = np.asarray(a, dtype=float)
        self.b = np.asarray(b, dtype=float)
        self.abs_a, self.abs_b = np.abs(self.a), np.abs(self.b)
        ones = np.ones(self.b.size)
        self.u: dict[Tree, tuple[np.ndarray, np.ndarray]] = {(): (ones, ones)}

    def vec(self, t: Tree) -> tuple[np.ndarray, np.ndarray]:
        if t not in self.u:
            v = w = np.ones(self.b.size)
            for child in t:
                cv, cw = self.vec(child)
                v = v * (self.a @ cv)
                w = w * (self.abs_a @ cw)
            self.u[t] = (v, w)
        return self.u[t]

    def __call__(self, t: Tree) -> tuple[float, float]:
        v, w = self.vec(t)
        return float(self.b @ v), float(self.abs_b @ w)


def elementary_weights(a, b, order: int) -> dict[Tree, tuple[float, float]]:
    """``Φ(t)`` for every tree up to ``order``, with its rounding scale.

    Returns ``{t: (Φ(t), Φ̄(t))}``, where ``Φ̄`` is ``Φ`` computed from
    ``|A|`` and ``|b|``: the sum of the magnitudes that make up ``Φ(t)``,
    which bounds its rounding error by a few ``|t|·eps·Φ̄(t)``.

    Examples
    --------
    Heun's method, ``b = (1/2, 1/2)``, ``c = (0, 1)``: ``Φ([τ]) = b·c = 1/2``.

    >>> w = elementary_weights([[0, 0], [1, 0]], [0.5, 0.5], 2)
    >>> w[((),)]
    (0.5, 0.5)
    """
    weights = _Weights(a, b)
    return {t: weights(t) for n in range(1, order + 1) for t in rooted_trees(n)}


@dataclass(frozen=True)
class OrderCheck:
    """The order of a tableau, and the first condition it fails.

    Attributes
    ----------
    order : int
        The largest ``p <= max_order`` for which every tree with
        ``|t| <= p`` satisfies ``Φ(t) = 1/γ(t)`` to rounding; 0 if even
        ``b·1 = 1`` fails.
    failing_tree : Tree or None
        The first tree of order ``order + 1`` whose condition fails; None
        when every condition up to ``max_order`` holds.
    residual : float
        ``Φ(t) - 1/γ(t)`` for that tree (nan if none).
    max_order : int
        The highest order checked.
    """

    order: int
    failing_tree: Tree | None
    residual: float
    max_order: int

    @property
    def failing(self) -> str:
        """The failed condition in words, or ``''``."""
        t = self.failing_tree
        if t is None:
            return ""
        return (
            f"at the tree {tree_str(t)}: Φ(t) - 1/γ(t) = {self.residual:+.3g}, γ(t) = {density(t)}"
        )


def check_order(a, b, max_order: int = MAX_ORDER) -> OrderCheck:
    """The order of the Runge–Kutta method ``(A, b)``, explicit or implicit.

    Each condition ``Φ(t) = 1/γ(t)`` is taken to hold when
    ``|Φ(t) - 1/γ(t)| <= 64·|t|·eps·Φ̄(t)``, where ``Φ̄(t)`` is the
    elementary weight of ``|A|``, ``|b|`` (a bound on the rounding of
    ``Φ(t)`` in double precision, with room for coefficients that are
    themselves rounded to double). A method of order ``p`` misses its
    order-``p+1`` conditions by far more: RK4 by ``1/120`` or more.

    Parameters
    ----------
    a : array_like, shape (s, s)
    b : array_like, shape (s,)
    max_order : int, default `MAX_ORDER`

    Examples
    --------
    >>> rk4 = check_order([[0, 0, 0, 0], [.5, 0, 0, 0], [0, .5, 0, 0], [0, 0, 1, 0]],
    ...                   [1/6, 1/3, 1/3, 1/6])
    >>> rk4.order, rk4.failing
    (4, 'at the tree [τ⁴]: Φ(t) - 1/γ(t) = +0.00833, γ(t) = 5')
    """
    eps = np.finfo(float).eps
    weights = _Weights(a, b)
    for n in range(1, max_order + 1):
        for t in rooted_trees(n):
            phi, scale = weights(t)
            residual = phi - 1.0 / density(t)
            if not abs(residual) <= 64 * n * eps * scale:
                return OrderCheck(n - 1, t, float(residual), max_order)
    return OrderCheck(max_order, None, float("nan"), max_order)
