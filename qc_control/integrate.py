"""The one fixed-step loop that runs every Butcher tableau."""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np

from .methods import ButcherTableau, get_method

__all__ = [
    "Solution",
    "DivergenceWarning",
    "integrate",
    "check_time_grid",
    "check_substeps",
    "uniform_step",
]

#: Intervals between checks for a non-finite state. Checking every step would
#: cost about as much as a stage; a blow-up is still cut at its first bad sample.
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
        raise ValueError(
            f"{name} must be finite; first bad value at index {int(np.argmin(np.isfinite(t)))}"
        )
    steps = np.diff(t)
    if np.any(steps <= 0):
        i = int(np.argmax(steps <= 0))
        raise ValueError(
            f"{name} must increase strictly: {name}[{i}] = {float(t[i])!r} "
            f"and {name}[{i + 1}] = {float(t[i + 1])!r}"
        )
    return t


def _loop_source(tab: ButcherTableau, substeps: bool) -> str:
    """Python source of the stepping loop for one tableau, stages unrolled.

    The coefficients are data, but a loop over them per step costs as much
    as a stage; writing them into the code once gives the loop a hand-written
    one would have. Stages of equal weight share one multiplication.
    """
    s = tab.stages
    a, b, c = tab.a.tolist(), tab.b.tolist(), tab.c.tolist()
    coef = []
    lines = [
        "def run(f, tt, x, out, start, stop, substeps):",
        "    h_prev = None",
        "    for n in range(start, stop):",
        "        t = tt[n]",
        "        h = (tt[n + 1] - t) / substeps" if substeps else "        h = tt[n + 1] - t",
        "        if h != h_prev:",
        "            h_prev = h",
    ]
    for i in range(s):
        if c[i] not in (0.0, 1.0):
            coef.append(f"            hc{i} = h * {c[i]!r}")
        for j in range(i):
            if a[i][j]:
                coef.append(f"            ha{i}_{j} = h * {a[i][j]!r}")
    weights: dict[float, list[int]] = {}
    for i in range(s):
        if b[i]:
            weights.setdefault(b[i], []).append(i)
    for g, w in enumerate(weights):
        coef.append(f"            hb{g} = h * {w!r}")
    lines += coef
    body = []
    if substeps:
        body += [
            "        t0 = t",
            "        for sub in range(substeps):",
            "            t = t0 + sub * h",
        ]
    pad = "            " if substeps else "        "
    for i in range(s):
        ti = "t" if c[i] == 0.0 else "t + h" if c[i] == 1.0 else f"t + hc{i}"
        xi = "x" + "".join(f" + ha{i}_{j} * k{j}" for j in range(i) if a[i][j])
        body.append(f"{pad}k{i} = f({ti}, {xi})")
    terms = []
    for g, idx in enumerate(weights.values()):
        ks = " + ".join(f"k{i}" for i in idx)
        terms.append(f"hb{g} * ({ks})" if len(idx) > 1 else f"hb{g} * {ks}")
    body.append(f"{pad}x = x + " + " + ".join(terms))
    lines += body + ["        out[n + 1] = x", "    return x", ""]
    return "\n".join(lines)


@functools.lru_cache(maxsize=64)
def _compiled_loop(tab: ButcherTableau, substeps: bool):
    namespace: dict = {}
    exec(compile(_loop_source(tab, substeps), f"<qc_control loop: {tab.name}>", "exec"), namespace)
    return namespace["run"]


def uniform_step(T: np.ndarray, rtol: float = 1e-9, atol: float = 0.0) -> float | None:
    """The step of an evenly spaced grid T, or None if a step departs from
    the mean ``(T[-1] - T[0])/(N - 1)`` by more than ``atol + rtol·dt``."""
    dt = (T[-1] - T[0]) / (T.size - 1)
    return float(dt) if np.max(np.abs(np.diff(T) - dt)) <= atol + rtol * abs(dt) else None


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

    run = _compiled_loop(tab, substeps > 1)
    out = np.empty((t.size,) + x.shape)
    out[0] = x
    tt = t.tolist()
    n_last, n_computed, status, message = t.size - 1, t.size - 1, "success", ""
    with np.errstate(over="ignore", invalid="ignore"):
        for start in range(0, t.size - 1, _CHECK_EVERY):
            stop = min(start + _CHECK_EVERY, t.size - 1)
            x = run(f, tt, x, out, start, stop, substeps)
            block = out[start + 1 : stop + 1]
            bad = ~np.isfinite(block.reshape(block.shape[0], -1)).all(axis=1)
            if bad.any():
                n_last = start + int(np.argmax(bad))
                n_computed = stop
                status = "diverged"
                message = (
                    f"{tab.name}: the state became non-finite after t = "
                    f"{t[n_last]:.6g}; stopped after {n_last} of {t.size - 1} intervals"
                )
                warnings.warn(message, DivergenceWarning, stacklevel=2)
                break
    steps = n_computed * substeps
    return Solution(
        t=t[: n_last + 1],
        x=np.moveaxis(out[: n_last + 1], 0, -1),
        nfev=tab.stages * steps,
        steps=steps,
        method=tab,
        status=status,
        message=message,
    )
