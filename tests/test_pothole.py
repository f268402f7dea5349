"""The pothole: python-control's default call steps over it; a fixed step cannot.

The exact peaks are python-control's forced_response on the same samples.
"""

import control
import numpy as np
import pytest
from conftest import gallery_run

from qc_control.models.quarter import quarter_car
from qc_control.ride.road import bump
from qc_control.studies.scenario import Scenario
from qc_control.studies.scenarios import POTHOLE, peak_table, pothole_comparison, pothole_road

T = np.linspace(0.0, 3.0, 3001)


@pytest.fixture(scope="module")
def cmp():
    return pothole_comparison(
        methods=("euler", "rk4"), solvers=("RK45", "control"), rtols=(1e-3,), timing=False
    )


def test_the_road_is_a_bump_turned_down():
    # the (1 - cos) bump of road.bump with a negative height: 5 cm down at its middle
    zr = pothole_road(T)
    # its deepest point, 1.0075 s, lies between the 1 ms samples: a 10 us grid holds it
    fine = np.linspace(1.0, 1.015, 1501)
    assert pothole_road(fine).min() == pytest.approx(-0.05, abs=1e-12)
    assert np.array_equal(zr, bump(T, height=-0.05, length=0.3, speed=20.0, t0=1.0))
    with pytest.raises(ValueError, match=r"depth \(.*\) must be a finite number > 0 m"):
        pothole_road(T, depth=-0.05)


def test_peaks_are_the_exact_ones_and_the_default_call_misses(cmp):
    exact = control.forced_response(quarter_car(road=True), T, pothole_road(T), np.zeros(4))
    peaks = peak_table(cmp)
    ref = peaks.loc["reference"]
    # python-control's exact response, to rounding; and the numbers to 0.5 um
    assert ref["peak |xs| [m]"] == pytest.approx(np.max(np.abs(exact.outputs[0])), rel=1e-12)
    assert ref["peak |xs| [m]"] == pytest.approx(2.743e-3, abs=5e-7)
    assert ref["peak |susp_travel| [m]"] == pytest.approx(2.552e-3, abs=5e-7)
    # RK4 at 1 ms: within 3e-11 m of the exact response everywhere (its error is h^4-small)
    rk4 = cmp.responses["rk4"].outputs[0]
    assert np.max(np.abs(rk4 - exact.outputs[0])) < 3e-11
    # the default call: every state stays 0, so the whole peak is missed
    assert peaks.loc["control", "peak |xs| [m]"] == 0.0
    assert peaks.loc["control", "peak |susp_travel| [m]"] == 0.0
    default = cmp.peers.control_default()
    assert default["error"] == pytest.approx(ref["peak |xs| [m]"], rel=1e-12)
    direct = control.input_output_response(quarter_car(road=True), T, pothole_road(T), 0.0)
    assert np.max(np.abs(direct.states)) == 0.0


def test_the_report_states_the_miss(cmp):
    from qc_control.report.peers import peer_findings

    text = " ".join(peer_findings(cmp))
    assert "the whole response" in text and "#1152" in text


def test_pothole_scenario_kind():
    sc = Scenario(kind="pothole")
    assert (sc.t_end, sc.h) == (POTHOLE.t_end, POTHOLE.h)
    assert sc.road.height == -0.05 and sc.road.t0 == 1.0
    assert "control" in sc.solvers
    assert Scenario.from_toml_string(sc.to_toml()) == sc
    assert "--scenario pothole" in sc.command()
    # given values win over the kind's
    assert Scenario(kind="pothole", t_end=2.0).t_end == 2.0


@pytest.mark.parametrize(
    "words, expected",
    [
        # the pothole (5 cm deep, 0.3 m long, met at 1 s) at 10 m/s: only the speed changes
        (["--speed", "10"], bump(T, height=-0.05, length=0.3, speed=10.0, t0=1.0)),
        (["--road-t0", "0.5"], bump(T, height=-0.05, length=0.3, speed=20.0, t0=0.5)),
    ],
)
def test_a_road_option_changes_only_its_parameter_of_the_kinds_road(words, expected):
    """`--scenario pothole --speed 10` was refused: the road table of --speed,
    having no kind, was read as "no road". It is the pothole at 10 m/s, every
    other parameter the run's; the reference is the 1 − cos bump written out."""
    from qc_control.cli.parser import build_parser, scenario_from_args

    sc = scenario_from_args(build_parser().parse_args(["report", "--scenario", "pothole", *words]))
    assert np.array_equal(sc.road.samples(T), expected)
    assert (sc.t_end, sc.h) == (POTHOLE.t_end, POTHOLE.h)
    # the command it writes redoes it
    again = scenario_from_args(build_parser().parse_args(sc.command().split()[1:]))
    assert again == sc


def test_a_bump_turned_down_is_described_as_a_pothole():
    """The report said 'a -5 cm high ... bump' for the pothole; a bump of
    negative height reads as the pothole's own words (`Pothole.describe`),
    and a bump of positive height as before."""
    from qc_control.ride.road import Bump

    down = Bump(height=-0.05, length=0.3, speed=20.0, t0=1.0)
    assert down.describe() == POTHOLE.describe()
    assert down.describe() == "a 5 cm deep, 0.3 m long 1 − cos pothole met at t = 1 s at 20 m/s"
    up = Bump(height=0.1, length=1.0, speed=15.0, t0=0.5)
    assert up.describe() == "a 10 cm high, 1 m long 1 − cos bump met at t = 0.5 s at 15 m/s"


def test_a_road_option_over_the_stiff_run_keeps_its_road():
    from qc_control.cli.parser import build_parser, scenario_from_args
    from qc_control.ride.road import ISO8608Road

    argv = ["report", "--scenario", "stiff", "--road-class", "D"]
    sc = scenario_from_args(build_parser().parse_args(argv))
    # the stiff run's road (ISO 8608, 20 m/s, seed 0) on class D, as written out directly
    assert sc.road == ISO8608Road("D", speed=20.0, seed=0)


@pytest.mark.slow
@pytest.mark.xdist_group("docs")  # the gallery's run of the example, once per suite
def test_the_example_prints_the_peaks_and_draws_both_figures(docs_build):
    stdout, folder = gallery_run(docs_build, "pothole")
    Te = np.linspace(0.0, 2.0, 2001)  # the example's run: 0-2 s at 1 ms
    exact = control.forced_response(quarter_car(road=True), Te, pothole_road(Te), np.zeros(4))
    peak = np.max(np.abs(exact.outputs[0]))
    # printed to 4 decimals in mm: the exact peak, and the default call's 0
    assert f"reference      {peak * 1e3:.4f} mm" in stdout
    assert "control        0.0000 mm" in stdout
    assert (folder / "pothole_evaluations.png").exists()
    assert (folder / "pothole_time.png").exists()
