"""The one fixed-step loop that runs every Butcher tableau."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .methods import ButcherTableau, get_method

__all__ = ["Solution", "DivergenceWarning", "integrate", "check_time_grid", "check_substeps"]

#: Steps between checks for a non-finite state. Checking every step would cost
#: about as much as a stage; a blow-up is still cut at its first bad sample.
_CHECK_EVERY = 64


class DivergenceWarning(RuntimeWarning):
    """A fixed-step run became non-finite, or its step is beyond stability."""


@dataclass(frozen=True, eq=False)
class Solution:
    """The result of `integrate`.

    Attributes
    ----------
    t : ndarray, shape (N,)
        The output times: the grid given, cut at divergence.
    x : ndarray, shape (n, N), or (m, n, N) for a batch
        The state at each output time (time last, as in python-control).
    nfev : int
        Right-hand-side evaluations made: ``stages * steps`` (one call of
        ``f`` per stage, whatever the batch size).
    steps : int
        Steps taken (``substeps`` per interval of the grid).
    method : ButcherTableau
    status : str
        ``'success'`` or ``'diverged'``.
    message : str
    """

    t: np.ndarray
    x: np.ndarray
    nfev: int
    steps: int
    method: ButcherTableau
    status: str
    message: str

    @property
    def success(self) -> bool:
        return self.status == "success"


def check_time_grid(t, name: str = "T") -> np.ndarray:
    """``t`` as a float array: 1-D, at least 2 points, finite, increasing."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"{name} must be a 1-D array of at least 2 times, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{name} must be finite; first bad value at index "
                         f"{int(np.argmin(np.isfinite(t)))}")
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise ValueError(f"{name} must increase strictly: {name}[{i}] = {float(t[i])!r} "
                         f"and {name}[{i + 1}] = {float(t[i + 1])!r}")
    return t


def check_substeps(substeps) -> int:
    """``substeps`` as an int >= 1, or a ValueError naming it."""
    if isinstance(substeps, bool) or not isinstance(substeps, (int, np.integer)) or substeps < 1:
        raise ValueError(f"substeps must be a positive integer, got {substeps!r}")
    return int(substeps)


def integrate(f, t, x0, method="rk4", *, substeps: int = 1) -> Solution:
    """Solve ``x' = f(t, x)`` with a fixed-step explicit Runge–Kutta method.

    Each interval ``[t[i], t[i+1]]`` of the grid is split into ``substeps``
    equal steps ``h``; one step is

    .. math::

        k_i = f\\big(t + c_i h,\\; x + h \\textstyle\\sum_{j<i} a_{ij} k_j\\big), \\qquad
        x \\leftarrow x + h \\textstyle\\sum_i b_i k_i .

    Parameters
    ----------
    f : callable ``f(t, x) -> dx/dt``
        Gets a float ``t`` and ``x`` of the shape of ``x0``; returns the
        same shape. For a batch, ``f`` sees the whole ``(m, n)`` batch.
    t : array_like, shape (N,)
        Output times, strictly increasing; need not be uniform.
    x0 : array_like, shape (n,) or (m, n)
        Initial state, or ``m`` initial states stepped together.
    method : str or ButcherTableau, default ``'rk4'``
        A name in `qc_control.METHODS` or any explicit tableau.
    substeps : int, default 1
        Steps per interval of ``t``.

    Returns
    -------
    Solution
        If the state becomes non-finite, the run stops there: a
        `DivergenceWarning` is issued and the solution holds the samples
        up to the last finite one, with ``status='diverged'``.

    Examples
    --------
    >>> import numpy as np
    >>> sol = integrate(lambda t, x: -x, np.linspace(0, 1, 11), [1.0], "rk4")
    >>> float(abs(sol.x[0, -1] - np.exp(-1))) < 1e-6, sol.nfev
    (True, 40)
    """
    tab = get_method(method)
    t = check_time_grid(t, "t")
    substeps = check_substeps(substeps)
    x = np.array(x0, dtype=float)
    if x.ndim not in (1, 2) or x.size == 0:
        raise ValueError(f"x0 must have shape (n,) or (m, n), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("x0 must be finite")

    s, c = tab.stages, tab.c.tolist()
    a_rows = [[(j, a) for j, a in enumerate(tab.a[i, :i].tolist()) if a != 0] for i in range(s)]
    b_terms = [(i, b) for i, b in enumerate(tab.b.tolist()) if b != 0]
    out = np.empty((t.size,) + x.shape)
    out[0] = x
    k = [None] * s
    h_cached, ha_rows, hb_terms = math.nan, None, None
    n_last, status, message = t.size - 1, "success", ""
    tt = t.tolist()

    with np.errstate(over="ignore", invalid="ignore"):
        for n in range(t.size - 1):
            t0 = tt[n]
            h = (tt[n + 1] - t0) / substeps
            if h != h_cached:  # uniform grids rescale once
                h_cached = h
                ha_rows = [[(j, h * a) for j, a in row] for row in a_rows]
                hb_terms = [(i, h * b) for i, b in b_terms]
            for sub in range(substeps):
                ts = t0 + sub * h if sub else t0
                for i in range(s):
                    xi = x
                    for j, ha in ha_rows[i]:
                        xi = xi + ha * k[j]
                    k[i] = f(ts + c[i] * h, xi)
                for i, hb in hb_terms:
                    x = x + hb * k[i]
            out[n + 1] = x
            if (n + 1) % _CHECK_EVERY == 0 or n + 1 == t.size - 1:
                block = out[max(n + 2 - _CHECK_EVERY, 1):n + 2]
                bad = ~np.isfinite(block.reshape(block.shape[0], -1)).all(axis=1)
                if bad.any():
                    n_last = max(n + 2 - _CHECK_EVERY, 1) + int(np.argmax(bad)) - 1
                    status = "diverged"
                    message = (f"{tab.name}: the state became non-finite after t = "
                               f"{t[n_last]:.6g}; stopped after {n_last} of {t.size - 1} "
                               f"intervals")
                    warnings.warn(message, DivergenceWarning, stacklevel=2)
                    n_computed = n + 1
                    break
        else:
            n_computed = t.size - 1
    steps = n_computed * substeps
    return Solution(
        t=t[:n_last + 1],
        x=np.moveaxis(out[:n_last + 1], 0, -1),
        nfev=s * steps,
        steps=steps,
        method=tab,
        status=status,
        message=message,
    )
