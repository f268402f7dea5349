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

import numpy as np

__all__ = ["SampledInput", "linear_input"]


class SampledInput:
    r"""``u(t)``, linear between the samples ``U[:, i]`` at ``T[i]``.

    .. math::

        u(t) = U_i + (t - T_i)\,\frac{U_{i+1} - U_i}{T_{i+1} - T_i}, \qquad
        T_i \le t < T_{i+1},

    extended linearly beyond the ends by the first and last intervals (an
    engine never asks there). At a sample time it is the sample itself.

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
        i = min(max(bisect.bisect_right(self._times, t) - 1, 0), self._last)
        return self._rows[i] + (t - self._times[i]) * self._slopes[i]

    def at(self, times) -> np.ndarray:
        """The inputs at every time of ``times`` (any shape): ``(*times.shape, k)``.

        The same formula as a call, element by element.
        """
        times = np.asarray(times, dtype=float)
        i = np.clip(np.searchsorted(self.T, times, side="right") - 1, 0, self._last)
        return self._rows[i] + (times - self.T[i])[..., None] * self._slopes[i]


def linear_input(T: np.ndarray, U: np.ndarray) -> SampledInput:
    """The input linear between its samples (`SampledInput`)."""
    return SampledInput(T, U)
