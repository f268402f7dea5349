"""One way of timing (qc_control.studies.timing), feeding every place a time appears.

Nothing here asserts a speed: the checks are the order of the calls, what
is reported of them, and that the table and the figure read one measurement.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import qc_control as qc
from qc_control.studies import timing
from qc_control.studies.timing import Timing, interleaved_times, same_work


def test_runs_take_turns_in_each_round_and_the_order_flips(monkeypatch):
    # a turn repeats a short run until the turn time has passed: an endless turn
    # time makes every turn its most calls whatever the machine's speed
    monkeypatch.setattr(timing, "_TURN_TIME", math.inf)
    n = timing._MOST_CALLS
    calls: list[str] = []
    runs = {k: (lambda k=k: calls.append(k)) for k in "abc"}
    times = interleaved_times(runs, rounds=3, warmup=True)
    # a warm-up call each, then per round a turn each of n consecutive calls (a
    # short run's turn: its least disturbed call is kept), the order flipping
    turns = [calls[3 + n * i] for i in range(9)]
    assert calls[:3] == list("abc") and turns == list("abc") + list("cba") + list("abc")
    assert all(len(set(calls[3 + n * i : 3 + n * (i + 1)])) == 1 for i in range(9))
    assert len(calls) == 3 + 3 * 3 * n
    assert set(times) == set("abc") and all(t.rounds == 3 for t in times.values())
    for t in times.values():
        assert 0 <= t.low <= t.wall <= t.high and t.cpu >= 0


def test_bad_rounds_are_refused():
    with pytest.raises(ValueError, match="rounds must be >= 1, got 0"):
        interleaved_times({"a": lambda: None}, rounds=0)


def test_the_cost_table_and_the_figure_quote_one_measurement():
    """Issue 38: Table 6 and Figure 9 gave different times for the same runs
    (Euler 2.4 against 11.3 ms). The table's time at h is the ladder's level 0."""
    T = np.linspace(0.0, 1.0, 101)
    cmp = qc.compare_methods(qc.QuarterCarParams(), T, repeats=1)
    at_h = cmp.convergence[cmp.convergence["level"] == 0].set_index("method")
    for name, row in cmp.table.iterrows():
        assert row["wall time [ms]"] == pytest.approx(1e3 * at_h.at[name, "time"], rel=1e-12)
        assert row["wall min [ms]"] <= row["wall time [ms]"] <= row["wall max [ms]"]
        assert row["CPU time [ms]"] == pytest.approx(1e3 * at_h.at[name, "cpu_time"], rel=1e-12)


def test_same_work_says_when_a_difference_is_noise():
    table = pd.DataFrame(
        {
            "RHS evals": [2000, 2000, 2000, 4000],
            "wall time [ms]": [3.8, 4.2, 9.0, 8.0],
            "wall min [ms]": [3.7, 4.0, 8.5, 7.9],
            "wall max [ms]": [4.3, 4.6, 9.5, 8.2],
        },
        index=["midpoint", "heun", "slow", "rk4"],
    )
    pairs = {(p.first, p.second): p.noise for p in same_work(table)}
    assert pairs == {
        ("midpoint", "heun"): True,
        ("midpoint", "slow"): False,
        ("heun", "slow"): False,
    }


def test_overlapping_spreads_are_indistinguishable():
    a, b, c = (
        Timing(1.0, 0.9, 1.2, 1.0, 3),
        Timing(1.1, 1.15, 1.3, 1.1, 3),
        Timing(2, 1.5, 2.5, 2, 3),
    )
    assert a.indistinguishable_from(b) and b.indistinguishable_from(a)
    assert not a.indistinguishable_from(c)
