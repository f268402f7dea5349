"""The quarter car with its damper on a top mount (a Maxwell element): the stiff car.

The mode and the step limit are checked against the eigenvalues of the
equations of motion written out in this file.
"""

import math

import control
import numpy as np
import pytest
from conftest import gallery_run
from reports_shared import placeholder_figures, untimed, without_pdf  # noqa: F401  (fixtures)

import qc_control as qc
from qc_control.cli.parser import run
from qc_control.models.modal import modal_analysis
from qc_control.models.quarter import QuarterCarParams, quarter_car, quarter_car_model
from qc_control.numerics.stability import max_stable_step
from qc_control.studies.compare import compare_methods
from qc_control.studies.scenario import Scenario


def _maxwell_matrix(p: QuarterCarParams, km: float) -> np.ndarray:
    """The equations of motion by hand: F = km (xs - xd) = cs (xd' - xu')."""
    ms, mu, ks, ku, cs = p.ms, p.mu, p.ks, p.ku, p.cs
    return np.array(
        [
            [0, 0, -(ks + km) / ms, ks / ms, km / ms],
            [0, 0, (ks + km) / mu, -(ks + ku) / mu, -km / mu],
            [1, 0, 0, 0, 0],
            [0, 1, 0, 0, 0],
            [0, 1, km / cs, 0, -km / cs],
        ]
    )


@pytest.mark.parametrize("km, mode", [(1e6, -644.7), (1e7, -6633.3)])
def test_the_mount_adds_a_real_mode(km, mode):
    p = QuarterCarParams()
    sys = quarter_car(p, road=True, mount_stiffness=km)
    assert list(sys.state_labels) == ["vs", "vu", "xs", "xu", "xd"]
    np.testing.assert_allclose(sys.A, _maxwell_matrix(p, km), rtol=1e-15)
    ma = modal_analysis(quarter_car_model(p, road=True, mount_stiffness=km))
    fast = min(np.linalg.eigvals(_maxwell_matrix(p, km)).real)
    assert ma["top mount"].eigenvalue.real == pytest.approx(fast, rel=1e-9)
    assert fast == pytest.approx(mode, abs=0.1)  # the issue's -645 and -6,633 1/s
    assert [m.name for m in ma.modes] == ["body bounce", "wheel hop", "top mount"]
    # the body mode barely moves: within 1 % of the seed car's frequency
    assert ma.body.fn == pytest.approx(modal_analysis(p).body.fn, rel=1e-2)


def test_rk4_step_limit_falls_to_the_mounts_mode():
    # RK4's real-axis stability limit is 2.785 on |h·lambda|: 0.42 ms at -6,633 1/s
    eig = np.linalg.eigvals(_maxwell_matrix(QuarterCarParams(), 1e7))
    h_max = max_stable_step("rk4", eig)
    assert h_max == pytest.approx(2.785293563 / 6633.29, rel=1e-3)
    assert h_max < 0.43e-3


def test_without_a_mount_the_seed_car_is_unchanged():
    seed = quarter_car(road=True)
    assert seed.nstates == 4
    np.testing.assert_array_equal(quarter_car(road=True, mount_stiffness=None).A, seed.A)
    assert quarter_car_model().rebuild_batch is not None


def test_bad_mount_is_refused_by_name():
    with pytest.raises(
        ValueError,
        match=r"mount_stiffness \(the damper.s top mount\) must be a finite number > 0 N/m",
    ):
        quarter_car(mount_stiffness=-1.0)
    with pytest.raises(ValueError, match="mount_stiffness .* must be a finite number"):
        quarter_car(mount_stiffness="stiff")
    with pytest.raises(ValueError, match="needs a damper"):
        quarter_car({"cs": 0.0}, mount_stiffness=1e6)


@pytest.mark.slow
def test_an_explicit_method_above_its_limit_diverges_against_the_exact_response():
    # 2 s of a bump: RK4 at 1 ms (> 0.42 ms) blows up; at 0.25 ms it is within 1e-6 m
    model = quarter_car_model(road=True, mount_stiffness=1e7)
    T = np.linspace(0.0, 1.0, 1001)
    U = 0.05 * (T > 0.2)
    cmp = compare_methods(model, T, np.zeros(5), U=U, methods=("rk4",), timing=False)
    assert not cmp.table.loc["rk4", "stable"]
    assert math.isinf(cmp.convergence["error"].iloc[0]) or cmp.convergence["error"].iloc[0] > 1
    fine = cmp.convergence[cmp.convergence["h"] < 0.42e-3]
    assert (fine["error"] < 1e-6).all()
    assert cmp.modes["top mount"].eigenvalue.real == pytest.approx(-6633.3, abs=0.1)


@pytest.mark.slow
# what is checked is the scenario and the report's sections and files: its figures are
# placeholders (this car's peers' figures are drawn by its example, in
# test_the_example_shows_the_mount_mode below; the others by tests/test_report.py),
# the methods' wall times are left out (none is read) and no PDF is written
@pytest.mark.usefixtures("placeholder_figures", "untimed", "without_pdf")
def test_stiff_scenario_kind_and_the_command_line(tmp_path):
    sc = Scenario(kind="stiff")
    assert sc.option("mount_stiffness") == 1e7 and len(sc.x0) == 5
    assert (sc.t_end, sc.h, sc.road.kind) == (60.0, 0.005, "iso8608")
    assert Scenario.from_toml_string(sc.to_toml()) == sc
    assert Scenario(model_options={"mount_stiffness": 1e6}).x0 == (0.0, 0.0, 0.05, 0.0, 0.0)
    with pytest.raises(ValueError, match="kind must be one of pothole, stiff"):
        Scenario(kind="bumpy")
    # the command line: a short stiff run with two peers writes the peers' section
    out = tmp_path / "r"
    code = run(
        [
            "report", "--scenario", "stiff", "--t-end", "0.5", "--h", "0.005",
            "--methods", "rk4", "--solvers", "BDF,control", "--out", str(out), "-q",
        ]
    )  # fmt: skip
    assert code == 0
    text = (out / "report.md").read_text(encoding="utf-8")
    assert "The solvers people use" in text and "top mount" in text
    assert (out / "work_precision.csv").exists()
    # the scenario's run carries the cost of a ride answer within 1 %
    assert "The cost of a ride answer" in text and (out / "ride_cost.csv").exists()


def test_a_bare_mounted_system_is_not_taken_for_the_seed_car():
    # its signals are the quarter car's, its states are not: the roles need the model
    sys = quarter_car(road=True, mount_stiffness=1e6)
    T = np.linspace(0.0, 1.0, 101)
    with pytest.raises(ValueError, match="not a known vehicle: pass a VehicleModel"):
        compare_methods(sys, T, np.zeros(5), U=np.zeros(101), timing=False)


@pytest.mark.slow
@pytest.mark.xdist_group("docs")  # the gallery's run of the example, once per suite
def test_the_example_shows_the_mount_mode(docs_build):
    stdout, folder = gallery_run(docs_build, "stiff_car")
    fast = min(np.linalg.eigvals(_maxwell_matrix(QuarterCarParams(), 1e7)).real)
    import re

    printed = float(re.search(r"top mount\s+(-[\d.]+)\+", stdout).group(1))
    assert printed == pytest.approx(fast, abs=1e-4)  # printed to 4 decimals
    assert (folder / "stiff_evaluations.png").exists() and (folder / "stiff_time.png").exists()


@pytest.mark.parametrize("method", ["sdirk2", "radau2", "radau3"])
def test_an_l_stable_method_at_5_ms_meets_the_stiff_car_target(method):
    # Issue 24, item 4: 60 s of class C road at 20 m/s on the 1e7 N/m mount;
    # an L-stable implicit method at h = 5 ms (12x RK4's 0.42 ms limit) gives
    # the Wk-weighted RMS body acceleration within 1 % of the exact value of
    # control.forced_response on the same sampled road (measured: sdirk2
    # +0.004 %, radau2 -0.001 %, radau3 < 1e-4 %)
    from qc_control.ride import road as roads
    from qc_control.studies.scenarios import STIFF_CAR, stiff_car_model

    case = STIFF_CAR
    T = np.linspace(0.0, case.t_end, round(case.t_end / case.h) + 1)
    assert case.h == 0.005 and case.mount_stiffness == 1e7
    U = roads.iso8608(T, case.road_class, case.speed, case.seed)
    model = stiff_car_model()
    key = "rms_body_acc_wk [m/s²]"
    exact = qc.ride_metrics(control.forced_response(model.system, T, U), model)[key]
    ours = qc.forced_response(model.system, T, U, method=method)
    assert ours.success
    assert qc.ride_metrics(ours, model)[key] == pytest.approx(exact, rel=0.01)
    with pytest.warns(qc.DivergenceWarning):
        assert not qc.forced_response(model.system, T, U, method="rk4").success
