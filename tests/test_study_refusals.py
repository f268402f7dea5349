"""Every study refuses a bad argument with `qc.ParameterError` naming it.

The parameter classes and road kinds are held to their declarations in
tests/test_checks.py; this is the studies' and responses' side: a program
reads *which* argument was wrong from ``.name`` and the value given from
``.value`` (the same object), and a person reads both in the message.
"""

from __future__ import annotations

import numpy as np
import pytest

import qc_control as qc
from qc_control.studies.scenarios import pothole_road

T = np.linspace(0.0, 1.0, 101)
NAN = float("nan")


def _measurement():
    t = np.linspace(0.0, 2.0, 401)
    return qc.Measurement(t, zr=0.01 * np.sin(3 * t), body_acc=np.sin(t))


#: (call, the argument it names, the bad value given): each value is one the
#: argument's documentation rules out.
CASES = {
    "compare_methods h": (
        lambda v: qc.compare_methods(qc.quarter_car_model(), T, h=v, timing=False),
        "h",
        -1.0,
    ),
    "compare_methods methods": (
        lambda v: qc.compare_methods(qc.quarter_car_model(), T, methods=[v], timing=False),
        "method",
        "rk5",
    ),
    "compare_methods repeats": (
        lambda v: qc.compare_methods(qc.quarter_car_model(), T, repeats=v),
        "repeats",
        0,
    ),
    "forced_response method": (
        lambda v: qc.forced_response(qc.quarter_car(), T, 0.0, method=v),
        "method",
        "rk5",
    ),
    "forced_response substeps": (
        lambda v: qc.forced_response(qc.quarter_car(), T, 0.0, substeps=v),
        "substeps",
        0,
    ),
    "integrate method": (
        lambda v: qc.integrate(lambda t, x: -x, T, [1.0], method=v),
        "method",
        "rk5",
    ),
    "sweep method": (lambda v: qc.sweep({"cs": [1000.0]}, T, method=v), "method", "rk5"),
    "sweep substeps": (lambda v: qc.sweep({"cs": [1000.0]}, T, substeps=v), "substeps", 0),
    "optimal_damping objective": (
        lambda v: qc.optimal_damping(objective=v),
        "objective",
        "smooth",
    ),
    "optimal_damping travel_limit": (
        lambda v: qc.optimal_damping(travel_limit=v),
        "travel_limit",
        -0.1,
    ),
    "optimal_damping sigmas": (lambda v: qc.optimal_damping(sigmas=v), "sigmas", NAN),
    "pareto_front objectives": (
        lambda v: qc.pareto_front(objectives=v),
        "objectives",
        ["smooth", "comfort"],
    ),
    "compare_controllers cmax": (lambda v: qc.compare_controllers(cmax=v), "cmax", -1.0),
    "compare_controllers road_duration": (
        lambda v: qc.compare_controllers(road_duration=v),
        "road_duration",
        -1.0,
    ),
    "identify model": (lambda v: qc.identify(_measurement(), model=v), "model", "half"),
    "identify free": (lambda v: qc.identify(_measurement(), free=[v]), "free", "ms2"),
    "ride_assessment axis": (
        lambda v: qc.ride_assessment({v: np.zeros(2000)}, T=np.arange(2000) * 1e-3),
        "axis",
        "q",
    ),
    "pothole depth": (lambda v: pothole_road(T, depth=v), "depth", -0.05),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_study_names_the_bad_argument_and_its_value(case):
    call, name, value = CASES[case]
    with pytest.raises(qc.ParameterError) as err:
        call(value)
    assert err.value.name == name
    assert err.value.value is value or err.value.value == value
    assert isinstance(err.value, ValueError)
    assert repr(value) in str(err.value) or str(value) in str(err.value)
