"""Road inputs the time grid cannot carry are refused, or the default step refined.

The thresholds (`BUMP_STEPS` steps across a bump, `SINE_STEPS` steps per
period of a sine) are checked against closed forms: the largest sample of a
1 − cos pulse and the worst error of linear interpolation of a sine.
"""

import math

import numpy as np
import pytest
from qc_control.road import Bump, Sine

from qc_control.cli import parser
from qc_control.ride.road import BUMP_STEPS, SINE_STEPS
from qc_control.studies.scenario import Scenario
from qc_control.studies.scenario_toml import ScenarioError

SHORT_BUMP = Bump(length=0.05, speed=30.0)  # 1.67 ms long
FAST_SINE = Sine(frequency=80.0)  # above the 50 Hz Nyquist limit of h = 10 ms


def test_the_issues_short_bump_falls_between_the_samples_of_ten_ms():
    # the reproduction: at h = 10 ms every sample of this bump is zero
    T = np.linspace(0.0, 10.0, 1001)
    assert np.max(Bump(length=0.05, speed=30.0).samples(T)) == 0.0


@pytest.mark.parametrize(
    "road, words",
    [
        (SHORT_BUMP, "needs 4 steps across it: it must be <= 0.0004167 s"),
        (FAST_SINE, "needs 10 steps per period"),
    ],
)
def test_a_given_step_too_coarse_for_the_road_is_refused(road, words):
    with pytest.raises(ScenarioError, match="too coarse") as info:
        Scenario(road=road, h=0.01)
    assert words in str(info.value)


@pytest.mark.parametrize("road", [SHORT_BUMP, FAST_SINE])
def test_the_default_step_is_refined_with_a_note(road):
    sc = Scenario(road=road)
    assert sc.h <= sc.road.largest_step()
    assert sc.step_note().startswith(f"h = {sc.h:g} s, below the default 0.01 s, to sample")


def test_the_thresholds_are_exact():
    bump = Bump(length=1.0, speed=20.0)  # 50 ms
    assert bump.largest_step() == pytest.approx(0.05 / BUMP_STEPS, rel=1e-15)
    Scenario(road=bump, h=0.0125, t_end=10.0)  # exactly four steps across it
    with pytest.raises(ScenarioError, match="too coarse"):
        Scenario(road=bump, h=0.0125 * 1.01, t_end=0.0125 * 1.01 * 800)
    sine = Sine(frequency=10.0)
    assert sine.largest_step() == pytest.approx(0.01, rel=1e-15)  # ten steps per 0.1 s period
    Scenario(road=sine, h=0.01)


def test_four_steps_across_a_bump_catch_most_of_its_height():
    # a 1 − cos pulse spanning N steps has a sample within half a step of its
    # peak, so its largest sample is at least (1 + cos(π/N))/2 of the height
    floor = (1 + math.cos(math.pi / BUMP_STEPS)) / 2  # 0.854
    bump = Bump(height=0.05, length=0.05, speed=30.0)
    h = bump.largest_step()
    for t0 in np.linspace(0.1, 0.1 + h, 7):  # every phase of the grid against the bump
        T = np.arange(0.0, 0.2, h)
        zr = Bump(height=0.05, length=0.05, speed=30.0, t0=t0).samples(T)
        assert zr.max() >= floor * 0.05 * (1 - 1e-12)


def test_ten_steps_per_period_interpolate_a_sine_within_five_percent():
    # linear interpolation between samples θ = 2π/N apart errs by at most
    # A(1 − cos(θ/2)); for N = 10 that is 4.9 % of the amplitude
    sine = Sine(amplitude=0.01, frequency=7.0)
    h = sine.largest_step()
    T = np.arange(0.0, 1.0 + h / 2, h)
    fine = np.linspace(0.0, T[-1], 20001)
    err = np.max(np.abs(np.interp(fine, T, sine.samples(T)) - sine.samples(fine)))
    bound = 0.01 * (1 - math.cos(math.pi / SINE_STEPS))
    assert err <= bound * (1 + 1e-3)  # the fine grid may miss the worst point by 1e-3
    assert err >= 0.9 * bound  # and the bound is the one reached


@pytest.mark.parametrize(
    "road_args",
    [
        ["--road", "bump", "--road-length", "0.05", "--speed", "30"],
        ["--road", "sine", "--road-frequency", "80"],
    ],
)
def test_the_issues_commands_are_refused_before_any_work(road_args, capsys, tmp_path):
    status = parser.run(["report", *road_args, "--h", "0.01", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert status == 2 and "too coarse" in err and "--h" in err
    assert not (tmp_path / "r").exists()
