"""Sampled inputs, linear between their samples: the one interpolation of every engine.

python-control's `forced_response` and `input_output_response` assume an
input linear between its samples, so a Runge–Kutta stage at ``t + c_i h``
sees ``u(t + c_i h)`` on that line. Every engine reads inputs through
`linear_input`: one sample at a time (a stage's time, an event's root
finding) or many at once (every stage of a run, precomputed), with the same
formula, so both give the same bits.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable

import numpy as np

__all__ = ["SampledInput", "linear_input"]


class SampledInput:
    r"""``u(t)``, linear between the samples ``U[:, i]`` at ``T[i]``.

    .. math::

        u(t) = U_i + (t - T_i)\,\frac{U_{i+1} - U_i}{T_{i+1} - T_i}, \qquad
        T_i \le t < T_{i+1},

    held at the first and last samples beyond the ends (as `numpy.interp`;
    an engine never asks there). At a sample time it is the sample itself.

    Parameters
    ----------
    T : ndarray (N,)
        Sample times, strictly increasing, ``N >= 2``.
    U : ndarray (k, N)
        The samples, one row per input.
    """

    def __init__(self, T: np.ndarray, U: np.ndarray):
        self.T = np.asarray(T, dtype=float)
        self._times = self.T.tolist()
        self._rows = np.ascontiguousarray(np.asarray(U, dtype=float).reshape(-1, self.T.size).T)
        self._slopes = np.diff(self._rows, axis=0) / np.diff(self.T)[:, None]
        self._last = self.T.size - 2

    @property
    def size(self) -> int:
        """The number of inputs ``k``."""
        return self._rows.shape[1]

    def __call__(self, t: float) -> np.ndarray:
        """The inputs ``(k,)`` at the time ``t``."""
        i = bisect.bisect_right(self._times, t) - 1
        # a copy at the ends, as between samples: a right-hand side may change its u
        if i > self._last:  # at (or past) the last sample: the sample, as np.interp
            return self._rows[-1].copy()
        if i < 0:
            return self._rows[0].copy()
        # np.interp's own expression, slope·(t - T_i) + U_i, so that `at` agrees to the bit
        return self._slopes[i] * (t - self._times[i]) + self._rows[i]

    def scalar(self) -> Callable[[float], float]:
        """``u(t)`` of a single input as a float: the call's value to the bit, in plain floats.

        A right-hand side called once per stage (a linear car on one road,
        ``A x + b u(t)``) spends most of its time on the few small arrays
        the call builds; this reads the same slope and sample as Python
        floats (the same operations in the same order) and returns a float.

        Raises
        ------
        ValueError
            For more than one input (`size` > 1).
        """
        if self.size != 1:
            raise ValueError(f"a scalar input needs one input, this one has {self.size}")
        times, last, bisect_right = self._times, self._last, bisect.bisect_right
        rows, slopes = self._rows[:, 0].tolist(), self._slopes[:, 0].tolist()
        first_row, last_row = rows[0], rows[-1]

        def u(t: float) -> float:
            i = bisect_right(times, t) - 1
            if i > last:
                return last_row
            if i < 0:
                return first_row
            return slopes[i] * (t - times[i]) + rows[i]

        return u

    def at(self, times) -> np.ndarray:
        """The inputs at every time of ``times`` (any shape): ``(*times.shape, k)``.

        The same values as a call at each time, to the bit (`numpy.interp`
        per input, whose formula the call repeats).
        """
        times = np.asarray(times, dtype=float)
        if not self.size:
            return np.zeros((*times.shape, 0))
        return np.stack([np.interp(times, self.T, row) for row in self._rows.T], axis=-1)


def linear_input(T: np.ndarray, U: np.ndarray) -> SampledInput:
    """The input linear between its samples (`SampledInput`)."""
    return SampledInput(T, U)
