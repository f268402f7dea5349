"""The Scenario and the command line on the half and full car."""

import math
import shlex

import numpy as np
import pytest

import qc_control as qc
from qc_control.cli.parser import build_parser, run, scenario_from_args
from qc_control.models.halfcar import FullCarParams, HalfCarParams
from qc_control.ride import road
from qc_control.ride.road import Bump as BumpRoad
from qc_control.ride.road import ISO8608Road
from qc_control.ride.road import Step as StepRoad
from qc_control.studies.scenario import Scenario
from qc_control.studies.scenario_toml import ScenarioError


def test_model_defaults_and_the_free_release():
    sc = Scenario(model="half")
    assert sc.vehicle == HalfCarParams()
    # the body released from 5 cm, as the quarter car's default
    states = qc.half_car().state_labels
    assert sc.x0 == tuple(0.05 if s == "z" else 0.0 for s in states)
    assert Scenario(vehicle=FullCarParams()).model == "full"
    assert Scenario().model == "quarter" and Scenario().vehicle == qc.QuarterCarParams()
    with pytest.raises(ScenarioError, match="model must be one of 'quarter', 'half', 'full'"):
        Scenario(model="bicycle")


def test_half_car_road_is_the_front_road_a_wheelbase_later():
    sc = Scenario(model="half", road=BumpRoad(height=0.05, speed=12.0), t_end=2.0, h=0.002)
    T = sc.time_grid()
    U, text = sc.road_input(T)
    p = sc.vehicle
    tau = (p.a + p.b) / 12.0
    np.testing.assert_array_equal(U[0], road.bump(T, 0.05, 1.0, 12.0, 0.5))
    np.testing.assert_array_equal(U[1], road.delay(T, U[0], tau))
    # and within the linear-interpolation bound h²/8·max|zr''| of the bump met tau later
    exact = road.bump(T, 0.05, 1.0, 12.0, 0.5 + tau)
    assert np.max(np.abs(U[1] - exact)) <= 0.002**2 / 8 * 0.025 * (2 * math.pi * 12.0) ** 2
    assert f"{tau:.4g} s later" in text


def test_full_car_iso_road_has_two_tracks():
    sc = Scenario(model="full", road=ISO8608Road(speed=20.0, seed=4), t_end=1.0)
    T = sc.time_grid()
    U, text = sc.road_input(T)
    assert U.shape == (4, T.size)
    np.testing.assert_array_equal(U[0], road.iso8608(T, "C", 20.0, 4))
    left, right = road.iso8608_tracks(T, "C", 20.0, sc.vehicle.track_front, 4)
    np.testing.assert_array_equal(U[1], right)
    tau = (sc.vehicle.a + sc.vehicle.b) / 20.0
    np.testing.assert_array_equal(U[3], road.delay(T, right, tau))
    assert "isotropic" in text


def test_roads_without_speed_and_parameters_of_another_model_are_refused():
    with pytest.raises(ScenarioError, match="a step road has no speed"):
        Scenario(model="half", road=StepRoad())
    with pytest.raises(ScenarioError, match="Iy is a parameter of the half and full car"):
        Scenario.from_mapping({"Iy": 1000.0})
    with pytest.raises(ScenarioError, match="track_front is a parameter of the full car"):
        Scenario.from_mapping({"track_front": 1.5, "scenario": {"model": "half"}})
    with pytest.raises(ScenarioError, match=r"cs_rear \(rear suspension damping"):
        Scenario.from_mapping({"cs_rear": -1.0, "scenario": {"model": "half"}})


@pytest.mark.parametrize("model", ["half", "full"])
def test_toml_and_command_round_trip(model):
    sc = Scenario.from_mapping(
        {"ms": 900.0, "scenario": {"model": model, "t_end": 1.0, "road": {"kind": "bump"}}}
    )
    assert sc.vehicle.ms == 900.0
    assert Scenario.from_toml_string(sc.to_toml()) == sc
    argv = shlex.split(sc.command())[1:]
    assert f"--model {model}" in sc.command()
    assert scenario_from_args(build_parser().parse_args(argv)) == sc


def test_modes_command_prints_the_named_modes(capsys):
    assert run(["modes", "--model", "full", "--arb-front", "20000"]) == 0
    out = capsys.readouterr().out
    for name in ("bounce", "pitch", "roll", "front axle tramp"):
        assert name in out
    assert run(["modes", "--Iy", "1000"]) == 2
    assert "--model half" in capsys.readouterr().err
