"""The one set of input checks: `qc.ParameterError` names the parameter and value."""

import math
import pickle

import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics import checks


def test_parameter_error_is_a_value_error_that_carries_name_value_and_expectation():
    with pytest.raises(ValueError) as info:
        checks.positive("ks", -1.0, "N/m", description="suspension stiffness")
    err = info.value
    assert isinstance(err, qc.ParameterError)
    assert (err.name, err.value) == ("ks", -1.0)
    assert str(err) == "ks (suspension stiffness) must be a finite number > 0 N/m, got -1.0"


@pytest.mark.parametrize("bad", [0.0, -1e-300, math.nan, math.inf, True, "3", None, [1.0]])
def test_positive_refuses_every_value_not_a_finite_number_above_zero(bad):
    with pytest.raises(qc.ParameterError) as info:
        checks.positive("h", bad, "s")
    assert info.value.name == "h" and info.value.value is bad


@pytest.mark.parametrize("good", [1, 2.5, np.float32(0.25), np.int64(3), 5e-324])
def test_positive_accepts_python_and_numpy_numbers_as_floats(good):
    v = checks.positive("h", good, "s")
    assert type(v) is float and v == float(good)


def test_bounds_open_closed_and_infinite():
    assert checks.nonnegative("cu", 0, "N·s/m") == 0.0
    assert checks.positive("limit", math.inf, "N", allow_inf=True) == math.inf
    assert checks.number("zeta", 1.0, low=0.0, high=1.0) == 1.0
    with pytest.raises(qc.ParameterError, match=r"in \[0, 1\)"):
        checks.number("zeta", 1.0, low=0.0, high=1.0, high_open=True)
    with pytest.raises(qc.ParameterError, match=r">= 0"):
        checks.nonnegative("cu", -0.1)


def test_integer_and_choice():
    assert checks.integer("resolution", np.int64(1), minimum=1) == 1
    for bad in (1.0, True, 0):
        with pytest.raises(qc.ParameterError):
            checks.integer("resolution", bad, minimum=1)
    assert checks.choice("method", "rk4", ("euler", "rk4")) == "rk4"
    with pytest.raises(qc.ParameterError, match="one of 'euler', 'rk4'") as info:
        checks.choice("method", "rk5", ("euler", "rk4"))
    assert info.value.name == "method"
    with pytest.raises(qc.ParameterError):
        checks.choice("method", ["unhashable"], ("euler",))


def test_fields_declared_once_validate_a_frozen_dataclass():
    from dataclasses import dataclass

    spec = {
        "m": checks.Field("mass", "kg"),
        "c": checks.Field("damping", "N·s/m", "nonneg", optional=True),
    }

    @dataclass(frozen=True)
    class P:
        m: float = 1
        c: float | None = None

        def __post_init__(self):
            checks.check_fields(self, spec)

    assert P(m=2).m == 2.0 and type(P(m=2).m) is float and P().c is None
    with pytest.raises(qc.ParameterError) as info:
        P(m=1, c=-3)
    assert (info.value.name, info.value.value) == ("c", -3)
    assert "damping" in str(info.value) and "N·s/m" in str(info.value)


def test_parameter_error_survives_pickling_for_worker_processes():
    err = checks.ParameterError("ku", 0.0, "a finite number > 0 N/m", description="tire")
    back = pickle.loads(pickle.dumps(err))
    assert (back.name, back.value, back.expected, str(back)) == (
        err.name,
        err.value,
        err.expected,
        str(err),
    )
