"""The one set of input checks: `qc.ParameterError` names the parameter and value."""

import math
import pickle
from dataclasses import fields as _dataclass_fields

import numpy as np
import pytest

import qc_control as qc
from qc_control.models.controllers import HinfWeights
from qc_control.numerics import checks
from qc_control.numerics.adaptive import StepController


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


# ------------------------------------------------- every parameter class and road kind
#
# Each class declares its fields once (`spec()`: a `checks.Field` per field);
# the test reads each field's range from that declaration with plain
# comparisons of its own, and gives every field the same bad values, chosen
# without looking at any declaration. Where the declaration says a value is
# out of range, the class must refuse it with a ParameterError naming the
# field and the value.

#: The bad values: negative, zero, not a number, infinite, a string, a bool,
#: None (given to each field independently of its declaration).
BAD_VALUES = (-1.0, 0.0, math.nan, math.inf, -math.inf, "3", True, None)

#: Each parameter class and the arguments it needs besides the one under test.
PARAMETER_CLASSES = {
    qc.QuarterCarParams: {},
    qc.HalfCarParams: {},
    qc.FullCarParams: {},
    qc.PiecewiseDamper: {"rebound": 1500.0, "bound": 1000.0},
    qc.BumpStop: {"clearance_bound": 0.05, "stiffness": 1e5},
    HinfWeights: {},
    StepController: {},
}
#: `PiecewiseDamper`'s documented "unset" high-speed coefficient: NaN, like
#: None, means the low-speed one (its docstring), so NaN is not refused there.
NAN_MEANS_UNSET = {(qc.PiecewiseDamper, "rebound_high"), (qc.PiecewiseDamper, "bound_high")}


def _declared_out_of_range(field: checks.Field, value) -> bool:
    """Whether ``value`` lies outside ``field``'s declared range, read here from
    the declaration's attributes (not through `Field.check`)."""
    if value is None:
        return not field.optional
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return True
    if math.isnan(value) or (math.isinf(value) and not field.allow_inf):
        return True
    low, high = field.bounds["low"], field.bounds["high"]
    if low is not None and (value < low or (field.bounds["low_open"] and value == low)):
        return True
    return high is not None and (value > high or (field.bounds["high_open"] and value == high))


def _parameter_cases():
    for cls, base in PARAMETER_CLASSES.items():
        for name, field in cls.spec().items():
            for value in BAD_VALUES:
                unset = (cls, name) in NAN_MEANS_UNSET and isinstance(value, float)
                if _declared_out_of_range(field, value) and not (unset and math.isnan(value)):
                    yield pytest.param(
                        cls, base, name, value, id=f"{cls.__name__}.{name}={value!r}"
                    )


def test_every_parameter_class_declares_each_of_its_fields_once():
    for cls in PARAMETER_CLASSES:
        declared = set(cls.spec())
        numbers = {f.name for f in _dataclass_fields(cls)}
        if cls is HinfWeights:  # its filters are (num, den) pairs, checked as such
            numbers -= {"actuator", "handling", "comfort"}
        assert declared == numbers, cls
        for field in cls.spec().values():
            assert field.description and isinstance(field.unit, str)


@pytest.mark.parametrize(("cls", "base", "name", "value"), list(_parameter_cases()))
def test_a_bad_value_of_any_declared_field_is_refused_naming_field_and_value(
    cls, base, name, value
):
    with pytest.raises(qc.ParameterError) as info:
        cls(**{**base, name: value})
    err = info.value
    assert isinstance(err, ValueError)
    assert err.name == name and err.value is value
    # the message starts with the field and its meaning, ends with the value given
    assert str(err).startswith(f"{name} (") and str(err).endswith(f", got {value!r}")
    assert err.expected in str(err)


def test_there_are_cases_of_every_kind_for_the_parameter_classes():
    # the generator above is not vacuous: each bad value is refused somewhere
    cases = [p.values for p in _parameter_cases()]
    assert {type(v) for *_, v in cases} >= {float, str, bool, type(None)}
    assert {cls for cls, *_ in cases} == set(PARAMETER_CLASSES)
    assert len(cases) > 100


#: Each road kind and the arguments it needs besides the field under test.
ROAD_KINDS = {
    qc.road.Step: {},
    qc.road.Bump: {},
    qc.road.Sine: {},
    qc.road.ISO8608Road: {},
    qc.road.Profile: {"x": [0.0, 1.0, 2.0], "z": [0.0, 0.01, 0.0]},
}


def _road_cases():
    """A road field's declared check: 'finite' or 'positive' (a value > 0)."""
    for kind, base in ROAD_KINDS.items():
        for f in _dataclass_fields(kind):
            check = f.metadata.get("check")
            if check not in ("finite", "positive"):
                continue
            for value in BAD_VALUES:
                real = isinstance(value, (int, float)) and not isinstance(value, bool)
                refused = not real or not math.isfinite(value)
                refused = refused or (check == "positive" and value <= 0)
                if refused:
                    yield pytest.param(
                        kind, base, f.name, value, id=f"{kind.__name__}.{f.name}={value!r}"
                    )


@pytest.mark.parametrize(("kind", "base", "name", "value"), list(_road_cases()))
def test_a_bad_value_of_any_road_field_is_refused_naming_field_and_value(kind, base, name, value):
    with pytest.raises(qc.ParameterError) as info:
        kind(**{**base, name: value})
    assert info.value.name == name and info.value.value is value
    assert name in str(info.value) and repr(value) in str(info.value)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"road_class": "Q"}, "road_class"),
        ({"road_class": -1.0}, "road_class"),
        ({"road_class": True}, "road_class"),
        ({"seed": -1}, "seed"),
        ({"seed": 1.5}, "seed"),
        ({"seed": True}, "seed"),
        ({"band": (1.0, 0.1)}, "band"),
    ],
)
def test_an_iso8608_road_names_a_bad_class_seed_or_band(kwargs, name):
    with pytest.raises(qc.ParameterError) as info:
        qc.road.ISO8608Road(**kwargs)
    assert info.value.name == name and info.value.value is kwargs[name]
    assert repr(kwargs[name]) in str(info.value)


def test_a_profile_names_the_bad_point():
    with pytest.raises(qc.ParameterError) as info:
        qc.road.Profile([0.0, math.nan, 2.0], [0.0, 0.01, 0.0], speed=1.0)
    assert info.value.name == "x[1]" and math.isnan(info.value.value)


def test_the_parameter_error_is_the_packages_one():
    assert qc.ParameterError is checks.ParameterError
    assert issubclass(qc.ParameterError, ValueError)
    assert "ParameterError" in qc.__all__


@pytest.mark.parametrize(
    ("build", "name", "words"),
    [
        # cs and zeta both given: cs = 2·0.3·√(30000·301.2) = 1805.6 N·s/m, not 100
        (lambda: qc.QuarterCarParams(zeta=0.3, cs=100.0), "cs", "cs=100.0 and zeta=0.3 disagree"),
        # ks/mu = 30000/1e-305 overflows: mu, 307 orders of magnitude from its default, is named
        (lambda: qc.QuarterCarParams(mu=1e-305), "mu", "ks/mu overflows to inf"),
        # a seat 100 m ahead of a 2.814 m wheelbase is outside the car (ten wheelbases)
        (lambda: qc.HalfCarParams(seat_x=100.0), "seat_x", "within 28.14 m of the CG"),
        (lambda: qc.FullCarParams(seat_y=-20.0), "seat_y", "within 15.22 m of the CG"),
        # a track 1e-8 m against a 2.814 m wheelbase: more than 1e7 times shorter
        (lambda: qc.FullCarParams(track_front=1e-8), "track_front", "times shorter"),
        (lambda: qc.PiecewiseDamper(1.0, 1.0, knee_bound=0.0), "knee_bound", "> 0 m/s"),
        (lambda: qc.quarter_car({"cs": 0.0}, mount_stiffness=1e6), "cs", "needs a damper"),
        (lambda: qc.quarter_car({"cu": 10.0}, mount_stiffness=1e6), "mount_stiffness", "cu=10.0"),
        (lambda: qc.nonlinear_quarter_car({"cu": 10.0}), "cu", "no tire damping"),
        (lambda: qc.nonlinear_quarter_car(tire="soft"), "tire", "'unilateral'"),
        (lambda: qc.nonlinear_quarter_car(spring=-1.0), "spring", "k3"),
        (lambda: qc.skyhook(1.0, semi_active="on-off", cmin=5.0, cmax=2.0), "cmax", "> cmin"),
        (lambda: qc.hybrid(1.0, alpha=1.5), "alpha", "[0, 1]"),
    ],
)
def test_checks_across_fields_name_the_field(build, name, words):
    with pytest.raises(qc.ParameterError) as info:
        build()
    assert info.value.name == name and str(info.value).startswith(name)
    assert words in str(info.value)


def test_a_field_holds_an_array_of_designs_by_the_declared_range():
    # the batch path (thousands of designs at once) against this test's own reading
    # of each declaration, for numbers in and out of range
    values = [-1.0, 0.0, 0.5, 1.0, 1.5, 3e4, math.nan, math.inf, -math.inf]
    for cls in PARAMETER_CLASSES:
        for field in cls.spec().values():
            want = [not _declared_out_of_range(field, v) for v in values]
            assert field.holds(values).tolist() == want, (cls, field)
