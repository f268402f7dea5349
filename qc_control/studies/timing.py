"""Wall times every study and report quotes, measured one way.

A report compares methods by their wall time, and students read a 2x gap
between Midpoint and Heun (the same evaluations) as a fact about the methods.
On a shared machine it is the machine: timed back to back, each method's runs
meet a different load. So the runs are timed **in interleaved rounds**: every
run once per round, in turn (the order reversed every other round, so that
none always follows the same one), a short run's turn the least of a few
consecutive calls (Python's ``timeit`` advice: the slower calls measure other
processes), the **median** of the rounds quoted with the lowest and highest
beside it, and the process's **CPU time** too, which other processes do not
inflate. The BLAS runs on one thread meanwhile
(`qc_control.numerics.threads`), as the library's hot paths do.

One measurement per run feeds every place it appears: the cost table and the
work-precision figure read the same numbers (`qc_control.studies.compare`).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass
from typing import TypeVar

from ..numerics.threads import blas_single_thread
from . import columns as col
from .columns import TIME_COLUMNS  # handed on: its home before the columns had one

__all__ = ["TIME_COLUMNS", "Timing", "interleaved_times", "SameWork", "same_work"]

K = TypeVar("K", bound=Hashable)


@dataclass(frozen=True)
class Timing:
    """One run's times over the rounds [s].

    Attributes
    ----------
    wall : float
        The median wall time.
    low, high : float
        The lowest and highest wall time: their spread is the machine's noise.
    cpu : float
        The median CPU time of this process.
    rounds : int
    """

    wall: float
    low: float
    high: float
    cpu: float
    rounds: int

    def indistinguishable_from(self, other: Timing) -> bool:
        """Whether the two medians lie within each other's spread: a difference
        the machine's noise could make."""
        return self.low <= other.high and other.low <= self.high


#: A turn of a short run repeats it until this much time [s] has passed (at most
#: `_MOST_CALLS` calls) and keeps its least disturbed call, as ``timeit`` advises: a
#: 2 ms run met by one scheduler tick otherwise reads 10 ms.
_TURN_TIME, _MOST_CALLS = 0.02, 5


def _one_turn(run: Callable[[], object]) -> tuple[float, float]:
    """(wall, CPU) [s] of one turn: the least of consecutive calls (`_TURN_TIME`)."""
    best_wall = best_cpu = float("inf")
    spent = 0.0
    for _ in range(_MOST_CALLS):
        wall, cpu = time.perf_counter(), time.process_time()
        run()
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        best_wall, best_cpu, spent = min(best_wall, wall), min(best_cpu, cpu), spent + wall
        if spent >= _TURN_TIME:
            break
    return best_wall, best_cpu


def interleaved_times(
    runs: Mapping[K, Callable[[], object]], rounds: int, warmup: bool = True
) -> dict[K, Timing]:
    """Time each run once per round, in turns (module docstring).

    Parameters
    ----------
    runs : mapping
        A key (a method, a method and a level) -> the call to time.
    rounds : int
        Rounds (>= 1).
    warmup : bool
        One untimed call of each first (caches, fresh memory pages).
    """
    if rounds < 1:
        raise ValueError(f"rounds must be >= 1, got {rounds!r}")
    keys = list(runs)
    walls: dict[K, list[float]] = {k: [] for k in keys}
    cpus: dict[K, list[float]] = {k: [] for k in keys}
    with blas_single_thread():
        if warmup:
            for key in keys:
                runs[key]()
        for r in range(rounds):
            for key in keys if r % 2 == 0 else reversed(keys):
                wall, cpu = _one_turn(runs[key])
                walls[key].append(wall)
                cpus[key].append(cpu)
    return {
        k: Timing(
            statistics.median(walls[k]),
            min(walls[k]),
            max(walls[k]),
            statistics.median(cpus[k]),
            rounds,
        )
        for k in keys
    }


@dataclass(frozen=True)
class SameWork:
    """Two methods that make the same RHS evaluations, and what their times say."""

    first: str
    second: str
    evaluations: int
    times: tuple[float, float]  # median wall times [s]
    noise: bool  # the medians lie within each other's spread of rounds


def same_work(table) -> list[SameWork]:
    """Pairs of methods with equal ``RHS evals`` in a comparison's table, each with
    whether their wall times differ by no more than the spread of the rounds
    (the columns ``wall time``, ``wall min`` and ``wall max [ms]``): a
    difference the machine makes, not the methods."""
    needed = {col.RHS_EVALS, col.WALL_TIME, col.WALL_MIN, col.WALL_MAX}
    if not needed <= set(table.columns):
        return []
    rows = table.dropna(subset=sorted(needed))
    names = list(rows.index)
    found = []
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            if rows.at[a, col.RHS_EVALS] != rows.at[b, col.RHS_EVALS]:
                continue
            low, high, wall = (rows[c] for c in (col.WALL_MIN, col.WALL_MAX, col.WALL_TIME))
            noise = bool(low[a] <= high[b] and low[b] <= high[a])  # as `indistinguishable_from`
            times = (float(wall[a]) / 1e3, float(wall[b]) / 1e3)
            found.append(SameWork(a, b, int(rows.at[a, col.RHS_EVALS]), times, noise))
    return found
