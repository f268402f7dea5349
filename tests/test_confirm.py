"""Confirming a cost to reach an accuracy (qc_control.studies.confirm).

The reference is python-control's exact response (the study's own) and the
counts are whole steps; what is checked here is the verdict a check gives
where no run is possible: a cost beyond the longest run is an estimate, never
a target 'missed' by runs that were not made at that cost.
"""

import math

import numpy as np

import qc_control as qc
from qc_control.studies.confirm import CONFIRM_MAX_STEPS, confirm_cost


def test_a_cost_beyond_the_longest_run_stays_an_estimate_under_an_input():
    """Euler to 1e-6 m on the seed car over a 5 cm road step: about 1.04e7 evaluations
    (the road-step report's estimate), 50x the longest check. No run is made: the
    estimate is quoted as one ('too long'), not called missed after runs on the
    comparison's own 1000 steps (the fault: 6 runs at h = 10 ms, error 1.4 cm)."""
    model = qc.quarter_car_model(qc.QuarterCarParams(), road=True)
    T = np.linspace(0.0, 10.0, 1001)
    U = qc.road.step(T, height=0.05, t0=0.5)[None, :]
    estimate = 10_356_032.0
    check = confirm_cost(
        model.system, T, np.zeros(4), U, qc.get_method("euler"), estimate, "extrapolated",
        1e-6, list(model.system.output_labels).index("xs"),
    )  # fmt: skip
    assert estimate > CONFIRM_MAX_STEPS
    assert check.verdict == "too long" and check.runs == 0
    assert check.evaluations == estimate and check.steps is None
    assert math.isnan(check.error)
