"""No run past a method's stability limit without a word (issue: the hand-in).

The default step of a report stays within every requested method's limit,
checked against Euler's closed form ``h ≤ −2·Re λ/|λ|²`` over the
eigenvalues of the car's A; a step given beyond it is warned about in one
line before anything is computed; and a diverged curve is cut where it
leaves ten times the exact response's range.
"""

import math

import numpy as np
import pytest

import qc_control as qc
from qc_control.cli import parser
from qc_control.report.figures import DIVERGED_RANGE, diverged_at, overlay_figure
from qc_control.studies.scenario import Scenario

BUMP = qc.road.Bump(speed=10.0)


def euler_limit(system) -> float:
    lam = np.linalg.eigvals(system.A)
    lam = lam[lam.real < 0]
    return float(np.min(-2 * lam.real / np.abs(lam) ** 2))


@pytest.mark.parametrize("model", ["half", "full"])
def test_the_default_step_is_within_eulers_limit_on_the_half_and_full_car(model):
    sc = Scenario(model=model, road=BUMP)
    h_max = euler_limit(sc.entry.model(sc.vehicle).system)
    assert h_max == pytest.approx(0.0068, abs=5e-5)  # the 6.8 ms
    # the largest 1-2-5 step (…, 2, 5, 10 ms) below it: 5 ms, not the old 10 ms
    assert sc.h == 0.005 and sc.h <= h_max
    assert sc.beyond_limits() == {}


def test_the_quarter_cars_default_step_is_unchanged():
    # Euler's limit on the seed's car is 19.8 ms: the seed's 10 ms stays
    assert Scenario().h == 0.01


def test_a_given_step_beyond_a_limit_is_kept_and_named():
    sc = Scenario(model="half", road=BUMP, h=0.01)
    assert sc.h == 0.01
    beyond = sc.beyond_limits()
    assert list(beyond) == ["euler"]
    assert beyond["euler"] == pytest.approx(euler_limit(sc.entry.model(sc.vehicle).system))


def test_the_readme_half_car_command_warns_before_computing(monkeypatch, capsys, tmp_path):
    """`qc-control report --model half --road bump --speed 10 --h 0.01`: one warning
    line on Euler (h, h_max) before the run starts."""

    class Stop(Exception):
        pass

    def no_run(self, progress=None):
        raise Stop

    monkeypatch.setattr(Scenario, "run", no_run)
    argv = ["report", "--model", "half", "--road", "bump", "--speed", "10", "--h", "0.01"]
    with pytest.raises(Stop):
        parser.run([*argv, "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err.splitlines()
    warned = [line for line in err if "warning" in line]
    assert len(warned) == 1
    line = warned[0]
    assert "euler" in line and "h = 0.01 s" in line and "h_max = 0.00681 s" in line
    assert err.index(line) < next(i for i, e in enumerate(err) if "qc-control report:" in e)


def test_a_default_run_says_nothing_about_limits():
    assert parser.beyond_limit_warnings(Scenario(model="half", road=BUMP)) == []


def test_a_curve_is_cut_where_it_leaves_ten_times_the_exact_range():
    t = np.linspace(0.0, 5.0, 5001)
    exact = np.sin(2 * np.pi * t)  # range 1
    grown = np.exp(t)  # leaves 10 at t = ln 10
    cut = diverged_at(t, grown, exact)
    assert t[cut] == pytest.approx(math.log(DIVERGED_RANGE), abs=1e-3)  # one sample, 1 ms
    assert diverged_at(t, 0.5 * exact, exact) is None
    assert t[diverged_at(t, np.where(t < 2, exact, np.nan), exact)] == pytest.approx(2.0, abs=1e-3)


def test_the_overlay_of_a_diverged_method_keeps_the_others_readable():
    sys = qc.quarter_car(qc.QuarterCarParams())
    T = np.linspace(0.0, 10.0, 301)  # h = 33 ms: Euler's limit is 19.8 ms
    cmp = qc.compare_methods(sys, T, [0.0, 0.0, 0.05, 0.0], methods=["euler", "rk4"])
    euler = cmp.responses["euler"].outputs[list(sys.output_labels).index("xs")]
    assert np.max(np.abs(euler)) > 100 * 0.05  # it did diverge, far past the cut
    fig = overlay_figure(cmp)
    ax = fig.axes[0]
    low, high = ax.get_ylim()
    # the exact response spans ±50 mm; the axis stays within the cut (10x) plus margins
    assert max(abs(low), abs(high)) <= 1.2 * DIVERGED_RANGE * 50.0
    texts = [t.get_text() for t in ax.texts] + [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(t.startswith("diverged at t = ") for t in texts)


def test_an_undamped_car_is_warned_about_in_words_not_a_division():
    # zeta = 0: the body mode sits on the imaginary axis, where |1 + hλ| > 1 for every h
    sc = Scenario(vehicle=qc.QuarterCarParams(zeta=0.0), t_end=1.0)
    lines = parser.beyond_limit_warnings(sc)
    assert sc.h == 0.01  # no step to lower to: the default stays
    assert any(line.startswith("h = 0.01 s: euler has no stable step") for line in lines)
