"""One road concept: `qc.road.Road` and its kinds.

References: the module's sampling functions (`qc.road.step`, `bump`, `sine`,
`iso8608`, the arrays every API gave before the kinds) to the bit, and
`numpy.interp` for a measured profile (a profile is linear between its
points, as python-control reads an input between samples).
"""

from __future__ import annotations

import numpy as np
import pytest

import qc_control as qc
from qc_control import road

T = np.linspace(0.0, 3.0, 3001)

KINDS = [
    (road.Step(height=0.03, t0=0.7), lambda T: road.step(T, 0.03, 0.7)),
    (
        road.Bump(height=0.08, length=2.0, speed=12.0, t0=0.4),
        lambda T: road.bump(T, 0.08, 2.0, 12.0, 0.4),
    ),
    (road.Sine(amplitude=0.02, frequency=1.7), lambda T: road.sine(T, 0.02, 1.7)),
    (road.ISO8608Road("D", speed=15.0, seed=3), lambda T: road.iso8608(T, "D", 15.0, 3)),
]


@pytest.mark.parametrize("kind, function", KINDS, ids=lambda k: getattr(k, "kind", ""))
def test_each_kind_samples_its_function_to_the_bit(kind, function):
    assert np.array_equal(kind.samples(T), function(T))


@pytest.mark.parametrize("kind, function", KINDS[:3], ids=lambda k: getattr(k, "kind", ""))
def test_height_at_one_time_is_the_samples_element_to_the_bit(kind, function):
    """The nonlinear car reads the road one time at a time: the same bits as the array."""
    zr = function(T)
    picked = np.arange(0, T.size, 37)
    assert all(kind(T[i]) == zr[i] for i in picked)
    assert all(kind.height_at(float(T[i])) == zr[i] for i in picked)


def test_jumps_and_steps_that_resolve_each_kind():
    assert road.Step(t0=0.3).jumps == (0.3,)
    assert road.Bump().jumps == road.Sine().jumps == road.NoRoad().jumps == ()
    # the bump lasts length/speed = 0.05 s: four steps across it (BUMP_STEPS)
    assert road.Bump(length=1.0, speed=20.0).largest_step() == pytest.approx(0.05 / 4)
    # ten steps per period of a 2 Hz sine (SINE_STEPS)
    assert road.Sine(frequency=2.0).largest_step() == pytest.approx(0.05)
    # ISO 8608's band to 2.83 cycles/m at 20 m/s: 1/(2·20·2.83) s
    assert road.ISO8608Road(speed=20.0).largest_step() == pytest.approx(1 / (2 * 20 * 2.83))
    assert road.Step().largest_step() == np.inf


def test_a_profile_is_linear_between_its_points_and_level_outside():
    x = np.array([0.0, 0.5, 1.5, 4.0])
    z = np.array([0.0, 0.02, -0.01, 0.0])
    p = road.Profile(x, z, speed=2.0, t0=0.25)
    # reference: the wheel at x = 2 (t - 0.25), read by linear interpolation
    expected = np.interp(2.0 * (T - 0.25), x, z)
    assert np.array_equal(p.samples(T), expected)
    assert p(0.5) == pytest.approx(0.02)  # x = 0.5 m
    assert p(0.0) == 0.0 and p(10.0) == 0.0  # level before and after
    # the closest points are 0.5 m apart: 0.25 s at 2 m/s
    assert p.largest_step() == pytest.approx(0.25)
    assert "4 points" in p.describe() and "2 m/s" in p.describe()
    with pytest.raises(ValueError):
        p.x[0] = 1.0  # a road is a value: its arrays cannot change under it


@pytest.mark.parametrize(
    "make, name",
    [
        (lambda: road.Step(height=np.nan), "height"),
        (lambda: road.Step(t0="0.5"), "t0"),
        (lambda: road.Bump(length=0.0), "length"),
        (lambda: road.Bump(speed=-1.0), "speed"),
        (lambda: road.Sine(frequency=np.inf), "frequency"),
        (lambda: road.Sine(amplitude=True), "amplitude"),
        (lambda: road.ISO8608Road("Z"), "road_class"),
        (lambda: road.ISO8608Road(seed=-1), "seed"),
        (lambda: road.ISO8608Road(band=(3.0, 1.0)), "band"),
        (lambda: road.Profile([0.0], [0.0]), "x"),
        (lambda: road.Profile([0.0, 1.0], [0.0]), "z"),
        (lambda: road.Profile([0.0, 1.0, 1.0], [0.0, 0.0, 0.0]), "x[2]"),
        (lambda: road.Profile([0.0, 1.0], [0.0, np.nan]), "z[1]"),
        # the entry that is not a number, in the array that holds it
        (lambda: road.Profile([0.0, 1.0, 2.0], [0.0, "a", 0.0]), "z[1]"),
        (lambda: road.Profile([0.0, "b", 2.0], [0.0, 0.0, 0.0]), "x[1]"),
        (lambda: road.Profile([0.0, 1.0], [0.0, 0.0], speed=0.0), "speed"),
    ],
)
def test_a_bad_value_is_a_parameter_error_naming_it(make, name):
    with pytest.raises(qc.ParameterError) as info:
        make()
    assert info.value.name == name
    assert name in str(info.value)


def test_rear_wheels_meet_the_road_a_wheelbase_later():
    """Reference: `axle_inputs`/`corner_inputs`, the layout the half and full cars take."""
    b = road.Bump(speed=10.0)
    U, words = b.wheel_inputs(T, "axles", wheelbase=2.5)
    assert np.array_equal(U, road.axle_inputs(T, b.samples(T), 2.5, 10.0))
    assert "0.25 s later" in words
    iso = road.ISO8608Road(speed=10.0)
    U4, words = iso.wheel_inputs(T, "corners", wheelbase=2.5, track=1.5)
    left, right = road.iso8608_tracks(T, "C", 10.0, 1.5, 0)
    assert np.array_equal(U4, road.corner_inputs(T, left, right, 2.5, 10.0))
    with pytest.raises(qc.ParameterError, match="a road with a speed"):
        road.Step().wheel_inputs(T, "axles", wheelbase=2.5)


def test_the_command_lines_names_are_the_kinds():
    """The command line's earlier names answer with the kinds, and a warning naming them."""
    from qc_control.studies import scenario

    with pytest.warns(DeprecationWarning, match=r"StepRoad is deprecated.*qc_control\.road\.Step"):
        assert scenario.StepRoad is road.Step
    with pytest.warns(DeprecationWarning, match=r"BumpRoad is deprecated.*qc_control\.road\.Bump"):
        assert scenario.BumpRoad is road.Bump
    assert qc.ISO8608Road is road.ISO8608Road
