"""One road object through every API that takes a road (issue 38, item 2).

Reference: the older form of each call (the road's samples as ``U`` with
their description, a plain function of time, an intensity or a
``(class, speed)`` pair, flat keywords), which every API still takes. The
road object must give the same result to the bit, since it is the same
numbers reaching the same code; the older forms must warn naming the new one.
"""

from __future__ import annotations

import numpy as np
import pytest

import qc_control as qc
from qc_control import road

T = np.linspace(0.0, 2.0, 201)
X0 = np.zeros(4)
STEP = road.Step(height=0.05, t0=0.5)
BUMP = road.Bump(height=0.05, length=1.0, speed=10.0, t0=0.3)


def test_compare_methods_on_a_road_is_the_comparison_on_its_samples():
    p = qc.QuarterCarParams()
    on_road = qc.compare_methods(p, T, X0, road=STEP, methods=["heun", "rk4"], timing=False)
    U, words = STEP.wheel_inputs(T)
    sampled = qc.compare_methods(
        qc.quarter_car_model(p, road=True),
        T,
        X0,
        U=U,
        input_description=words,
        methods=["heun", "rk4"],
        timing=False,
    )
    assert on_road.input_description == sampled.input_description == words
    assert on_road.table["max |xs err| [m]"].equals(sampled.table["max |xs err| [m]"])
    for name, response in on_road.responses.items():
        assert np.array_equal(response.states, sampled.responses[name].states)


def test_compare_methods_half_car_road_reaches_the_rear_a_wheelbase_later():
    p = qc.HalfCarParams()
    on_road = qc.compare_methods(p, T, np.zeros(8), road=BUMP, methods=["rk4"], timing=False)
    U, words = BUMP.wheel_inputs(T, "axles", wheelbase=p.a + p.b)
    sampled = qc.compare_methods(
        qc.half_car_model(p, road=True),
        T,
        np.zeros(8),
        U=U,
        input_description=words,
        methods=["rk4"],
        timing=False,
    )
    assert np.array_equal(on_road.responses["rk4"].states, sampled.responses["rk4"].states)


def test_a_road_with_its_samples_as_well_is_refused_by_name():
    with pytest.raises(qc.ParameterError, match="road") as err:
        qc.compare_methods(None, T, X0, road=STEP, U=STEP.samples(T))
    assert err.value.name == "road"
