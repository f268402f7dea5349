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


def test_no_cost_is_quoted_above_a_refinement_that_reached_it():
    """The half car on a class C road at 20 m/s, 0-10 s at h = 5 ms: RK4's own run
    there (8,000 evaluations) is within 1e-6 m of python-control's exact response,
    yet the check from the estimate (about 4,860, a coarser step that resamples the
    road) missed and climbed to 130,000 'confirmed' evaluations, 16 times the run
    the report's convergence table showed reaching it. A refinement is a run at
    that count against the exact response: the cost quoted is never above it."""
    import control
    import pandas as pd

    from qc_control.studies import columns as col
    from qc_control.studies.confirm import confirmed_costs

    model = qc.half_car_model(road=True)
    T = np.linspace(0.0, 10.0, 2001)
    road = qc.road.ISO8608Road("C", speed=20.0, seed=0)
    U, _ = road.wheel_inputs(T, "axles", wheelbase=model.params.a + model.params.b)
    z = list(model.system.output_labels).index("z")
    exact = control.forced_response(model.system, T, U, np.zeros(8)).outputs[z]
    rk4 = qc.forced_response(model.system, T, U, np.zeros(8), method="rk4").outputs[z]
    error = float(np.max(np.abs(rk4 - exact)))
    assert error < 1e-6  # the run the report's convergence table holds (1.36e-7 m)
    runs = pd.DataFrame(
        {col.METHOD: ["rk4"], col.STEPS: [2000], col.NFEV: [8000], col.ERROR: [error]}
    )
    cost = pd.DataFrame({"rk4": {1e-6: 4860.0}})
    kind = pd.DataFrame({"rk4": {1e-6: "extrapolated"}})
    quoted, verdict, (check,) = confirmed_costs(
        model.system, T, np.zeros(8), U, [qc.get_method("rk4")], cost, kind, "z", runs=runs
    )
    assert quoted.loc[1e-6, "rk4"] <= 8000 and verdict.loc[1e-6, "rk4"] == "confirmed"
    assert check.error <= 1e-6 and check.evaluations == quoted.loc[1e-6, "rk4"]
