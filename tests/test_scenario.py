"""qc_control.studies.scenario: validation, defaults from where they are defined, TOML, run.

References: the road functions of `qc_control.ride.road` called directly (road
samples), the functions' own signatures (defaults), `compare_methods` called
directly (run), and TOML read by `tomllib` (the writer's output).
"""

import inspect
import math
import re
import shlex
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from reports_shared import run_untimed

from qc_control import QuarterCarParams, compare_methods
from qc_control.cli.parser import build_parser, scenario_from_args
from qc_control.ride import road
from qc_control.ride.road import ROADS, Bump, ISO8608Road, NoRoad, Sine, Step
from qc_control.ride.road import Bump as BumpRoad
from qc_control.ride.road import Sine as SineRoad
from qc_control.ride.road import Step as StepRoad
from qc_control.studies import scenario as scenario_module
from qc_control.studies.compare import DEFAULT_H, DEFAULT_METHODS, DEFAULT_T_END, DEFAULT_X0
from qc_control.studies.scenario import NONLINEAR_ROAD, Scenario
from qc_control.studies.scenario_toml import MAX_CONFIG_BYTES, MAX_STEPS, ScenarioError, read_config

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def default(func, name):
    return inspect.signature(func).parameters[name].default


# ------------------------------------------------------------ validation

BAD = [
    (dict(methods=5), "[scenario] methods must be a list of method names, got 5"),
    (dict(methods=[1, 2]), "methods must be a list of method names, got [1, 2]"),
    (dict(methods=[]), "[scenario] methods must name at least one method"),
    (dict(methods=["rk4", "RK4"]), "methods must be distinct, got ['rk4', 'RK4']"),
    (dict(methods=["rk5"]), "unknown method 'rk5'; known methods are euler"),
    (dict(t_end=-1), "[scenario] t_end must be a finite number > 0 s, got -1"),
    (dict(t_end=float("nan")), "t_end must be a finite number > 0 s, got nan"),
    (dict(t_end=True), "t_end must be a finite number > 0 s, got True"),
    (dict(h=0), "[scenario] h must be a finite number > 0 s, got 0"),
    (dict(h="0.01"), "h must be a finite number > 0 s, got '0.01'"),
    (dict(t_end=1.234), "t_end = 1.234 s must be a whole number (at least 2) of steps h = 0.01"),
    (dict(t_end=0.01), "whole number (at least 2) of steps"),
    (dict(h=1e-320), "more than 1.8e308 steps per method"),
    (dict(t_end=1e308, h=1.0), "is 1e+308 steps per method"),
    (dict(t_end=1e6, h=0.01), "is 1e+08 steps per method (and more for the refinements"),
    (dict(t_end=1e6, h=0.01), f"above max_steps = {MAX_STEPS:,}"),
    (dict(max_steps=0), "[scenario] max_steps must be a whole number >= 2, got 0"),
    (dict(max_steps=1.5e6), "max_steps must be a whole number >= 2, got 1500000.0"),
    (dict(x0=[1, 2]), "[scenario] x0 must be 4 comma-separated numbers, all finite: vs, vu"),
    (dict(x0=[0, 0, math.inf, 0]), "x0 must be 4 comma-separated numbers"),
    (dict(x0="0,0,a,0"), "vs, vu, xs, xu [m/s, m/s, m, m]; got '0,0,a,0'"),
    (dict(road=5), "[scenario] road must be a qc_control.road.Road"),
    (dict(road=ISO8608Road(), h=0.01), "h = 0.01 s is too coarse for an ISO 8608 road at 20 m/s"),
    (dict(vehicle={"ms": -1}), "ms (sprung mass) must be a finite number > 0 kg, got -1"),
    (dict(vehicle={"ms": 1e200, "ks": 1e200}), "time scales span more than 1e+07: cs/mu"),
    (dict(vehicle={"mu": 1e-305}), "ks/mu overflows to inf"),
    (dict(vehicle=5), "vehicle must be a QuarterCarParams or a mapping"),
]


@pytest.mark.parametrize("kwargs, words", BAD)
def test_each_bad_value_is_named(kwargs, words):
    with pytest.raises(ScenarioError) as info:
        Scenario(**kwargs)
    assert words in str(info.value)
    assert isinstance(info.value, ValueError)  # callers catching ValueError still do


#: A road table of a TOML file (``[scenario.road]``), each bad value named with its
#: section; a table given to `Scenario` itself is the deprecated form (it warns).
BAD_ROAD_TABLES = [
    ({"kind": "wobble"}, "kind must be one of step, bump, sine, iso8608 or none, got"),
    (
        {"kind": "iso8608", "seed": -1},
        "[scenario.road] seed must be a whole number >= 0, got -1",
    ),
    ({"kind": "iso8608", "seed": 1.5}, "seed must be a whole number >= 0, got 1.5"),
    (
        {"kind": "iso8608", "road_class": "Z"},
        "road_class must be an ISO 8608 class, one of A, B",
    ),
    (
        {"kind": "iso8608", "band": [3, 1]},
        "band must be (n_min, n_max) with 0 < n_min < n_max cycles/m",
    ),
    ({"kind": "bump", "length": 0}, "length must be a finite number > 0 m, got 0"),
    ({"kind": "bump", "speed": -1}, "speed must be a finite number > 0 m/s, got -1"),
    ({"kind": "sine", "frequency": 0}, "frequency must be a finite number > 0 Hz"),
    ({"kind": "step", "height": "x"}, "height must be a finite number m, got 'x'"),
    (
        {"kind": "iso8608", "height": 0.1},
        "height = 0.1 does not apply to an iso8608 road: it is a parameter of step and bump",
    ),
    ({"kind": "step", "road_class": "C"}, "road_class = 'C' does not apply to a step"),
    ({"seed": 3}, "seed = 3 does not apply without a road"),
    (
        {"kind": "bump", "foo": 1},
        "unknown [scenario.road] key 'foo'; a bump road takes height",
    ),
]


@pytest.mark.parametrize("table, words", BAD_ROAD_TABLES)
def test_each_bad_value_of_a_road_table_is_named(table, words):
    with pytest.raises(ScenarioError) as info:
        Scenario.from_mapping({"scenario": {"road": table}})
    assert words in str(info.value)


# -------------------------------------------------------------- defaults


def test_defaults_are_read_from_where_they_are_defined():
    sc = Scenario()
    assert sc.vehicle == QuarterCarParams()
    assert sc.road == NoRoad()
    assert (sc.t_end, sc.h, sc.x0, sc.methods) == (
        DEFAULT_T_END,
        DEFAULT_H,
        DEFAULT_X0,
        DEFAULT_METHODS,
    )
    assert sc.steps == round(DEFAULT_T_END / DEFAULT_H)
    # under a road the car starts at rest
    assert Scenario(road=StepRoad()).x0 == (0.0, 0.0, 0.0, 0.0)
    for cls, func in ((StepRoad, road.step), (BumpRoad, road.bump), (SineRoad, road.sine)):
        for name, value in cls().params().items():
            if name != "speed":
                assert value == default(func, name), (cls, name)
    iso = ISO8608Road()
    for name in ("road_class", "speed", "seed", "band"):
        assert getattr(iso, name) == default(road.iso8608, name)
    # one speed default for every road with a speed (road.bump's own differs)
    assert BumpRoad().speed == ISO8608Road().speed == default(road.iso8608, "speed")


@pytest.mark.parametrize(
    "speed, band, h",
    [
        (20.0, road.ISO8608_BAND, 0.005),  # limit 8.83 ms
        (40.0, road.ISO8608_BAND, 0.002),  # limit 4.42 ms
        (5.0, road.ISO8608_BAND, DEFAULT_H),  # limit 35 ms: the default step samples it
        (1000.0, road.ISO8608_BAND, 1e-4),  # limit 0.177 ms
        (20.0, (0.011, 0.5), DEFAULT_H),  # a narrower band, a coarser limit (50 ms)
    ],
)
def test_iso_road_step_rule(speed, band, h):
    sc = Scenario(road=ISO8608Road(speed=speed, band=band))
    assert sc.h == h
    assert sc.h <= road.largest_step(speed, band)


@settings(max_examples=200, deadline=None)
@given(speed=st.floats(0.1, 1e4))
def test_iso_step_is_the_largest_1_2_5_step_within_the_limit(speed):
    sc = Scenario(road=ISO8608Road(speed=speed), t_end=1.0, max_steps=10**8)
    limit = road.largest_step(speed)
    steps = sorted(m * 10.0**e for e in range(-8, 3) for m in (1, 2, 5))
    fitting = [s for s in steps if s <= limit]
    assert sc.h == pytest.approx(min(DEFAULT_H, max(fitting)), rel=1e-12)
    assert sc.h <= limit


# ------------------------------------------------------------------ roads


def test_road_input_is_the_road_function_with_every_parameter():
    T = np.linspace(0, 3, 601)
    cases = [
        (StepRoad(height=0.1, t0=0.25), road.step(T, height=0.1, t0=0.25)),
        (
            BumpRoad(height=0.1, length=2.0, speed=15.0, t0=0.7),
            road.bump(T, height=0.1, length=2.0, speed=15.0, t0=0.7),
        ),
        (SineRoad(amplitude=0.02, frequency=3.0), road.sine(T, amplitude=0.02, frequency=3.0)),
        (
            ISO8608Road(road_class="d", speed=25.0, seed=7, band=(0.02, 2.0)),
            road.iso8608(T, "D", speed=25.0, seed=7, band=(0.02, 2.0)),
        ),
    ]
    for spec, expected in cases:
        sc = Scenario(road=spec, t_end=3.0, h=0.005)
        zr, _ = sc.road_input(T)
        np.testing.assert_array_equal(zr, expected)  # the same call: bit for bit
    assert Scenario().road_input() == (None, "")


def test_descriptions_state_the_actual_parameters():
    assert Scenario(road=BumpRoad(height=0.1, speed=15.0)).road_input()[1] == (
        "a 10 cm high, 1 m long 1 − cos bump met at t = 0.5 s at 15 m/s"
    )
    assert StepRoad(height=0.03, t0=1.0).describe() == "a 3 cm road step at t = 1 s"
    assert SineRoad(amplitude=0.002, frequency=2.5).describe() == (
        "a sinusoidal road, 0.2 cm amplitude at 2.5 Hz"
    )
    described = ISO8608Road(road_class="b", speed=30.0, seed=4).describe()
    stated = re.fullmatch(
        r"an ISO 8608 class B road at 30 m/s \(seed 4, band 0\.011–2\.83 cycles/m, "
        r"expected IRI (\d\.\d\d) m/km\)",
        described,
    )
    assert stated, described
    # the class's IRI measured on simulated profiles of it (ASTM E1926 on four 5 km
    # roads): each scatters by about 0.8 % (test_iri), their mean by about 0.4 %, so
    # 2 % is five of its SDs, plus the stated value's rounding to three digits (0.25 %)
    measured = np.mean(
        [road.iri(*road.iso8608_profile(5000.0, 0.05, "B", seed=s)) for s in range(4)]
    )
    assert float(stated.group(1)) == pytest.approx(measured, rel=0.02)
    assert StepRoad(height=1.5).describe().startswith("a 1.5 m road step")


# ----------------------------------------------------------- TOML layouts


def test_layout_scenario_road_table():
    sc = Scenario.from_toml_string(
        """
ms = 350.0
zeta = 0.3

[scenario]
t_end = 4.0
h = 0.005
methods = ["heun", "rk4"]

[scenario.road]
kind = "bump"
height = 0.1
speed = 15.0
"""
    )
    assert sc.vehicle == QuarterCarParams(ms=350.0, zeta=0.3)
    assert sc.road == BumpRoad(height=0.1, speed=15.0)
    assert (sc.t_end, sc.h, sc.methods, sc.x0) == (4.0, 0.005, ("heun", "rk4"), (0.0,) * 4)


def test_flat_keys_of_earlier_versions_still_read():
    # read for one more release, each with a warning naming its [scenario.road] key
    with pytest.warns(DeprecationWarning) as caught:
        sc = Scenario.from_toml_string(
            '[scenario]\nroad = "iso8608"\nroad_class = "D"\nspeed = 25.0\nseed = 3\n'
            'methods = "heun,rk4"\nx0 = "0,0,0.01,0"\n'
        )
    assert "write road_class = 'D' in a [scenario.road] table" in str(caught[1].message)
    assert sc.road == ISO8608Road(road_class="D", speed=25.0, seed=3)
    assert sc.methods == ("heun", "rk4") and sc.x0 == (0.0, 0.0, 0.01, 0.0)
    with pytest.warns(DeprecationWarning):
        bump = Scenario.from_toml_string('[scenario]\nroad = "bump"\nspeed = 12.0\n').road
    assert bump == BumpRoad(speed=12.0)


@pytest.mark.parametrize(
    "text, words",
    [
        # issue 14 item 5: keys that do not apply are refused
        ("[scenario]\nseed = 3\n", "[scenario] seed = 3 does not apply without a road"),
        (
            '[scenario]\nroad = "step"\nroad_class = "C"\n',
            "[scenario] road_class = 'C' does not apply to a step road",
        ),
        (
            '[scenario.road]\nkind = "iso8608"\nheight = 0.1\n',
            "[scenario.road] height = 0.1 does not apply to an iso8608 road",
        ),
        ("wheelbase = 2.5\n", "unknown key 'wheelbase'; expected the vehicle's parameters"),
        ("[scenario]\nhh = 1\n", "unknown [scenario] key 'hh'; expected t_end, h, x0"),
        ('[road]\nkind = "bump"\n', "unknown key 'road' (put the road in a [scenario.road]"),
        ("[scenario]\nmethods = 5\n", "[scenario] methods must be a list of method names, got 5"),
        ('scenario = "x"\n', "'scenario' must be a table, got 'x'"),
        (
            '[scenario]\nspeed = 3.0\n[scenario.road]\nkind = "bump"\n',
            "speed beside a [scenario.road] table: put it in the table",
        ),
        ("[scenario]\nroad = 5\n", "road must be a [scenario.road] table"),
        ("ms = \n", "is not valid TOML"),
    ],
)
@pytest.mark.filterwarnings("ignore:.*is deprecated.*scenario.road:DeprecationWarning")
def test_bad_files_are_named(tmp_path, text, words):
    path = tmp_path / "car.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        Scenario.from_toml(path)
    message = str(info.value)
    assert words in message and str(path) in message, message


def test_unreadable_files_are_named(tmp_path):
    binary = tmp_path / "car.toml"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff")
    with pytest.raises(ScenarioError, match=r"car\.toml' is not a TOML text file \(not UTF-8"):
        Scenario.from_toml(binary)
    with pytest.raises(ScenarioError, match=r"missing\.toml' cannot be read"):
        Scenario.from_toml(tmp_path / "missing.toml")
    with pytest.raises(ScenarioError, match="cannot be read"):
        Scenario.from_toml(tmp_path)  # a directory


def test_overrides_over_a_file(tmp_path):
    path = tmp_path / "car.toml"
    path.write_text(
        'ms = 350.0\ncs = 2000.0\n[scenario]\nh = 0.005\n[scenario.road]\nkind = "bump"\n'
        "height = 0.1\nlength = 2.0\n"
    )
    # damping given as an option replaces the file's; a road of the same kind is updated
    sc = Scenario.from_toml(path, overrides={"zeta": 0.4, "scenario": {"road": {"speed": 5.0}}})
    assert sc.vehicle == QuarterCarParams(ms=350.0, zeta=0.4)
    assert sc.road == BumpRoad(height=0.1, length=2.0, speed=5.0)
    # a road of another kind replaces it, with its own defaults
    sc = Scenario.from_toml(path, overrides={"scenario": {"road": {"kind": "step"}}})
    assert sc.road == StepRoad() and sc.h == 0.005
    sc = Scenario.from_toml(path, overrides={"scenario": {"road": {"kind": "none"}}})
    assert sc.road == NoRoad() and sc.x0 == DEFAULT_X0
    # an error names the file only when the bad value came from it
    with pytest.raises(ScenarioError) as info:
        Scenario.from_toml(path, overrides={"scenario": {"road": {"length": -1.0}}})
    assert str(info.value) == ("[scenario.road] length must be a finite number > 0 m, got -1.0")
    path.write_text("ms = -3.0\n")
    with pytest.raises(ScenarioError) as info:
        Scenario.from_toml(path, overrides={"ku": 1e5})
    assert str(info.value).startswith(f"config file {str(path)!r}: ms (sprung mass)")
    with pytest.raises(ScenarioError) as info:
        Scenario.from_toml(path, overrides={"ms": -2.0})
    assert str(info.value) == "ms (sprung mass) must be a finite number > 0 kg, got -2.0"


# ------------------------------------------------ round trip and command

SCENARIOS = [
    Scenario(),
    Scenario(
        vehicle=QuarterCarParams(ms=350.0, zeta=0.3),
        road=BumpRoad(height=0.1, speed=15.0),
        t_end=3.0,
        methods=("heun", "rk4"),
    ),
    Scenario(
        vehicle=QuarterCarParams(ms=0.1 + 0.2, mu=1 / 3, ks=2.0**0.5 * 1e4, ku=1e5 / 7, cs=1e-5),
        road=ISO8608Road(road_class="e", speed=33.3, seed=12345, band=(0.1 / 3, 2.0**0.5)),
        x0=(-0.0, 1e-300, -0.05, 1 / 3),
        t_end=2.0,
    ),
    Scenario(road=StepRoad(height=-0.02, t0=0.1), x0=(-1.0, 0, 0, 0), max_steps=2_000_000),
    Scenario(road=SineRoad(amplitude=0.015, frequency=2.2), h=0.002, t_end=1.0),
]


@pytest.mark.parametrize("sc", SCENARIOS)
def test_toml_round_trip_is_bit_identical(sc):
    text = sc.to_toml()
    tomllib.loads(text)  # valid TOML
    again = Scenario.from_toml_string(text)
    assert again == sc
    # repr of every float is the same, so the bits are (repr round-trips exactly, -0.0 too)
    assert again.to_toml() == text
    assert math.copysign(1, again.x0[0]) == math.copysign(1, sc.x0[0])


@settings(max_examples=50, deadline=None)
@given(
    ms=st.floats(1.0, 1e4),
    ks=st.floats(1e3, 1e6),
    zeta=st.floats(0.0, 3.0),
    height=st.floats(-0.5, 0.5),
    speed=st.floats(0.5, 60.0),
)
def test_toml_round_trip_any_values(ms, ks, zeta, height, speed):
    sc = Scenario(
        vehicle=QuarterCarParams(ms=ms, ks=ks, zeta=zeta),
        road=BumpRoad(height=height, speed=speed),
        t_end=1.0,
    )
    assert Scenario.from_toml_string(sc.to_toml()) == sc


def parse(command: str) -> Scenario:
    words = shlex.split(command)
    assert words[:2] == ["qc-control", "report"]
    return scenario_from_args(build_parser().parse_args(words[1:]))


@pytest.mark.parametrize("sc", SCENARIOS)
def test_command_redoes_the_scenario(sc, tmp_path):
    assert parse(sc.command()) == sc
    path = tmp_path / "scenario.toml"
    path.write_text(sc.to_toml())
    command = sc.command(config=path, out=tmp_path / "R")
    assert shlex.split(command)[2:] == ["--config", str(path), "--out", str(tmp_path / "R")]
    assert parse(command) == sc


# -------------------------------------------------------------------- run


@pytest.mark.slow
def test_run_is_compare_methods_on_the_scenario():
    sc = Scenario(road=BumpRoad(height=0.1, speed=15.0), t_end=1.0, methods=("heun", "rk4"))
    cmp = sc.run()
    assert cmp.scenario is sc
    T = np.linspace(0.0, 1.0, 101)
    U = road.bump(T, height=0.1, length=1.0, speed=15.0, t0=0.5)
    direct = compare_methods(  # its wall times are not compared: not measured either
        sc.vehicle, T, np.zeros(4), U=U, methods=("heun", "rk4"), input_description="x",
        timing=False,
    )  # fmt: skip
    np.testing.assert_array_equal(cmp.T, T)
    np.testing.assert_array_equal(cmp.U, np.atleast_2d(U))
    assert cmp.input_description == "a 10 cm high, 1 m long 1 − cos bump met at t = 0.5 s at 15 m/s"
    # every number but the wall times is the same computation
    timing = [c for c in cmp.table.columns if "time" in c.lower() or "[ms]" in c]
    pd.testing.assert_frame_equal(
        cmp.table.drop(columns=timing), direct.table.drop(columns=timing), check_exact=True
    )


#: Each older form of a scenario's road beside the `Road` it stands for: a kind's
#: name, a table (the nonlinear car's takes what it omits from its default bump).
OLDER_ROAD_FORMS = [
    ("quarter", {"kind": "bump", "height": 0.1, "speed": 15.0}, Bump(height=0.1, speed=15.0)),
    ("quarter", "step", Step()),
    ("half", {"kind": "bump", "speed": 10.0}, Bump(speed=10.0)),
    ("nonlinear", {"kind": "bump", "height": 0.05}, replace(NONLINEAR_ROAD, height=0.05)),
]


@pytest.mark.parametrize("model, older, new", OLDER_ROAD_FORMS)
def test_a_road_gives_the_report_numbers_of_the_older_form_to_the_bit(model, older, new):
    """``Scenario(road=Road)`` and the older form it replaces run the same comparison:
    the reference is the older API's own result, every number of the table bit for bit
    (but the wall times, which are not run: `run_untimed`)."""
    grid = dict(model=model, t_end=1.0, h=0.01, methods=("heun", "rk4"))
    if model == "nonlinear":
        grid.update(t_end=0.2, h=0.002)
    with pytest.warns(DeprecationWarning, match=r"give a qc_control\.road\.Road, road=qc_"):
        old = Scenario(road=older, **grid)
    sc = Scenario(road=new, **grid)
    assert sc == old
    cmp, before = run_untimed(sc), run_untimed(old)
    np.testing.assert_array_equal(cmp.T, before.T)
    if before.U is not None:
        np.testing.assert_array_equal(cmp.U, before.U)
    assert cmp.input_description == before.input_description
    pd.testing.assert_frame_equal(cmp.table, before.table, check_exact=True)


def test_the_older_forms_warn_naming_the_road_to_give():
    with pytest.warns(DeprecationWarning) as seen:
        Scenario(road={"kind": "sine", "frequency": 2.0})
    assert str(seen[0].message).endswith("road=qc_control.road.Sine(amplitude=0.01, frequency=2.0)")
    assert seen[0].filename == __file__  # the user's line, not the package's
    for name, kind in [("StepRoad", Step), ("BumpRoad", Bump), ("SineRoad", Sine)]:
        with pytest.warns(DeprecationWarning, match=rf"{name} is deprecated.*qc_control\.road\."):
            assert getattr(scenario_module, name) is kind
    # a TOML file's road table is its format: read without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        sc = Scenario.from_toml_string('[scenario.road]\nkind = "bump"\nspeed = 15.0\n')
        assert sc.road == Bump(speed=15.0)
        assert Scenario(road=Bump(speed=15.0)) == sc


def test_every_kind_is_registered():
    assert set(ROADS) == {"none", "step", "bump", "sine", "iso8608", "profile"}
    assert all(cls.kind == kind for kind, cls in ROADS.items())


# Issue 28 item 5: configs that are not files of text are refused in one line naming them.

#: A stream without end where the system has one (the tests use a large file elsewhere).
DEVICES = [d for d in ("/dev/zero", "/dev/urandom") if Path(d).exists()]


def nested_arrays(tmp_path, depth=100_000):
    path = tmp_path / "deep.toml"
    path.write_text("a = " + "[" * depth + "]" * depth + "\n")  # 200 kB, valid TOML
    return path


@pytest.mark.parametrize("read", [Scenario.from_toml, read_config])
def test_nesting_beyond_the_parser_is_named(tmp_path, read):
    """100k nested arrays were a RecursionError traceback out of tomllib."""
    path = nested_arrays(tmp_path)
    with pytest.raises(ValueError, match="nested more deeply than the TOML reader") as info:
        read(path)
    assert f"config file {str(path)!r} is not a scenario config" in str(info.value)


@pytest.mark.parametrize("read", [Scenario.from_toml, read_config])
@pytest.mark.parametrize("source", [*DEVICES, "large file"])
def test_a_config_larger_than_the_limit_is_refused_having_read_at_most_it(
    tmp_path, monkeypatch, read, source
):
    """/dev/zero was read until MemoryError, /dev/urandom without end. No more than
    MAX_CONFIG_BYTES + 1 bytes are read from anything (counted at the file object)."""
    if source == "large file":
        path = tmp_path / "big.toml"
        path.write_text("# " + "x" * MAX_CONFIG_BYTES + "\n")
    else:
        path = Path(source)
    asked = []
    real_open = Path.open

    def counting_open(self, *args, **kwargs):
        fh = real_open(self, *args, **kwargs)
        real_read = fh.read
        fh.read = lambda n=-1: asked.append(n) or real_read(n)
        return fh

    monkeypatch.setattr(Path, "open", counting_open)
    with pytest.raises(ValueError, match=f"holds more than {MAX_CONFIG_BYTES:,} bytes") as info:
        read(path)
    assert f"config file {str(path)!r} is not a scenario config" in str(info.value)
    # a regular file is measured, not opened; a device is read once, by a bounded read
    assert asked == ([] if source == "large file" else [MAX_CONFIG_BYTES + 1])


def test_a_config_of_exactly_the_limit_is_read(tmp_path):
    """The bound is the file's bytes: MAX_CONFIG_BYTES of comment and a value is read."""
    path = tmp_path / "padded.toml"
    head = "ms = 350.0\n# "
    path.write_bytes((head + "x" * (MAX_CONFIG_BYTES - len(head) - 1) + "\n").encode())
    assert path.stat().st_size == MAX_CONFIG_BYTES
    assert Scenario.from_toml(path).vehicle == QuarterCarParams(ms=350.0)
    assert read_config(path) == ({"ms": 350.0}, {})


def test_bytes_that_are_not_utf8_after_a_valid_start_are_named(tmp_path):
    """Bytes that are not UTF-8 past a valid start: the file and the byte are named."""
    path = tmp_path / "half.toml"
    path.write_bytes(b"ms = 350.0\n\xff\xfe")
    with pytest.raises(ScenarioError, match=r"half\.toml' is not a TOML text file .*0xff"):
        Scenario.from_toml(path)
    with pytest.raises(ValueError, match="not a TOML text file"):
        read_config(path)
