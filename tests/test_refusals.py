"""Documented inputs that a tool cannot take are refused by name (issue 28, items 11 and 13).

Each case used to end in an AttributeError or ZeroDivisionError from inside
the code; the refusal now names the argument and what to do instead.
"""

import logging

import numpy as np
import pytest

import qc_control as qc
from qc_control.cli.console import main


@pytest.fixture(scope="module")
def semi_active_loop():
    car = qc.quarter_car_model(actuator=True, road=True)
    return qc.closed_loop(car, qc.skyhook(2000.0, semi_active="on-off", cmax=3000.0))


def test_optimal_damping_of_a_half_car_names_its_two_dampers():
    with pytest.raises(ValueError, match=r"cs_front, cs_rear"):
        qc.optimal_damping(qc.half_car_model(road=True), "comfort")


def test_a_half_car_spectral_sweep_over_its_dampers_works_instead():
    # the route the refusal names runs (its values are checked against the
    # Lyapunov solution in test_spectral.py); here: it gives a metric per design
    res = qc.sweep(
        {"cs_front": [800.0, 3000.0]},
        model=qc.half_car_model(road=True),
        road=qc.ISO8608Road("C", 20.0),
    )
    values = res.metrics.select_dtypes("number").to_numpy()
    assert values.shape[0] == 2 and np.all(np.isfinite(values))


@pytest.mark.parametrize(
    "call",
    [
        lambda: qc.optimal_damping(qc.nonlinear_quarter_car_model(), "comfort"),
        lambda: qc.sweep(
            {"cs": [1000.0, 2000.0]},
            model=qc.nonlinear_quarter_car_model(),
            road=qc.ISO8608Road("C", 20.0),
        ),
    ],
    ids=["optimal_damping", "spectral_sweep"],
)
def test_a_nonlinear_model_is_refused_for_spectral_metrics(call):
    with pytest.raises(ValueError, match="is nonlinear: stationary"):
        call()


def test_a_semi_active_loop_on_the_pareto_figure_is_named(semi_active_loop):
    with pytest.raises(ValueError, match=r"controllers\['sky'\].*nonlinear"):
        qc.pareto_front(controllers={"sky": semi_active_loop})


@pytest.mark.parametrize("limit", [1e-300, 1e-9])
def test_an_impossible_travel_limit_names_the_damping_it_needs(limit):
    # RMS travel sqrt(q (ms + mu) / (2 cs)) <= limit needs cs >= q (ms+mu)/(2 limit²):
    # 1.8e18 N·s/m for 1e-9 m at 3σ on class C, inf for 1e-300 m
    with pytest.raises(ValueError, match=rf"travel_limit={limit!r} m .*needs cs >="):
        qc.pareto_front(travel_limit=limit)
    with pytest.raises(ValueError, match=rf"travel_limit={limit!r} m"):
        qc.optimal_damping(travel_limit=limit)


def test_switching_functions_that_change_number_are_refused():
    calls = []

    def growing(t, x):
        calls.append(t)
        return np.zeros(1 + len(calls) % 2)

    with pytest.raises(ValueError, match=r"same number of switching functions.*shape \(1,\)"):
        qc.integrate(lambda t, x: -x, np.linspace(0.0, 1.0, 11), [1.0], events=growing)
    with pytest.raises(ValueError, match=r"shape \(2, 2\)"):
        qc.integrate(
            lambda t, x: -x, np.linspace(0.0, 1.0, 11), [1.0], events=lambda t, x: np.zeros((2, 2))
        )


def test_a_bump_stop_far_past_its_clearance_gives_inf_not_overflow_error():
    from qc_control.models.nonlinear import BumpStop

    stop = BumpStop(0.05, 1e5, cubic=1e12)
    # F = -(k p + k3 p³) in bound; p = 0.1 m: 1e4 + 1e9 N, exact in binary to 1 ulp
    assert stop.force(-0.15) == pytest.approx(-(1e5 * 0.1 + 1e12 * 0.1**3), rel=1e-12)
    assert stop.force(-1e300) == -np.inf  # a diverged state: the stop's force overflows
    assert stop.energy(-1e300) == np.inf


def test_a_rear_wheel_delay_that_overflows_names_wheelbase_and_speed():
    T = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match=r"wheelbase/speed = 1e\+300 m / 1e-300 m/s overflows"):
        qc.road.axle_inputs(T, np.zeros(11), wheelbase=1e300, speed=1e-300)


@pytest.mark.parametrize(("key", "step"), [("road_duration", 0.005), ("bump_duration", 0.002)])
def test_a_controller_run_shorter_than_one_step_names_its_duration(key, step):
    with pytest.raises(ValueError, match=rf"{key}=0.001 s is shorter than one {step * 1e3:g} ms"):
        qc.compare_controllers(**{key: 0.001})


def test_a_semi_active_dampers_range_follows_the_responses_params():
    # params={'cmax': ...} in a response is python-control's way to change a
    # parameter of a system: the damper then saturates at the new cmax, so its
    # force never exceeds cmax·|vrel| (checked on every sample)
    car = qc.quarter_car_model(actuator=True, road=True)
    loop = qc.closed_loop(car, qc.skyhook(2000.0, semi_active="on-off", cmax=3000.0))
    T = np.linspace(0.0, 1.0, 201)
    zr = 0.05 * (T > 0.1)
    wide = qc.input_output_response(loop.system, T, zr)
    narrow = qc.input_output_response(loop.system, T, zr, params={"cmax": 100.0})
    labels = list(loop.system.output_labels)
    states = list(loop.system.state_labels)

    def force_bound(r, cmax):
        vrel = r.states[states.index("vs")] - r.states[states.index("vu")]
        return np.abs(r.outputs[labels.index("fa")]) <= cmax * np.abs(vrel) * (1 + 1e-12)

    assert np.all(force_bound(narrow, 100.0)) and np.all(force_bound(wide, 3000.0))
    assert not np.all(force_bound(wide, 100.0))  # the wide damper does use its range


@pytest.mark.parametrize(
    ("estimator", "words"),
    [
        ({"RN": [-1.0, 1e-3]}, r"RN'\] \(sensor noise intensities\) must be finite and > 0"),
        ({"QN": -1.0}, r"QN'\] \(process noise intensity\) must be positive semi-definite"),
        ({"outputs": []}, "at least one measured output"),
    ],
)
def test_an_estimator_with_impossible_noise_is_refused(estimator, words):
    car = qc.quarter_car_model(actuator=True, road=True)
    with pytest.raises(ValueError, match=words):
        qc.lqr_controller(car, estimator=estimator)


def test_a_controller_named_car_is_refused_by_name():
    import control

    car = qc.quarter_car_model(actuator=True, road=True)
    outs = list(car.system.output_labels)
    law = control.ss([[0.0]], [[0.0] * len(outs)], [[0.0]], [[0.0] * len(outs)],
                     inputs=outs, outputs=["fa"], name="car")  # fmt: skip
    with pytest.raises(ValueError, match="controller name 'car'"):
        qc.closed_loop(car, law)


@pytest.mark.slow
def test_a_nonlinear_car_at_rest_reports_without_warnings(tmp_path, capfd, caplog):
    # every error is exactly 0 at rest: the log-scaled error figures have no
    # curve to draw, which must not come out as a warning on the terminal: not on
    # stderr (its file descriptor), and not from a logger, whose warnings a process
    # prints to stderr and pytest takes instead (a real process's whole stderr is
    # checked by tests/test_cli.py's degenerate designs)
    argv = ["report", "--model", "nonlinear", "--road", "none", "--x0", "0,0,0,0"]
    argv += ["--t-end", "1", "--out", str(tmp_path / "rest"), "--quiet"]
    status = main(argv)
    err = capfd.readouterr().err
    assert status == 0, err
    assert "warning" not in err, err
    logged = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert not logged, logged


@pytest.mark.parametrize(
    ("method", "events"),
    [("rk4", lambda t, x: x - 0.5), ("radau3", None)],
    ids=["events", "implicit"],
)
def test_a_run_of_more_steps_than_hours_allow_is_refused_before_it_starts(events, method):
    # 10 intervals x 1e9 substeps = 1e10 steps: refused at once on the event and
    # implicit paths, which hold no per-step table for the memory check to count
    with pytest.raises(ValueError, match=r"10000000000 steps \(substeps = 1000000000 in each of"):
        qc.integrate(
            lambda t, x: -x, np.linspace(0.0, 1.0, 11), [1.0], method, substeps=10**9,
            events=events,
        )  # fmt: skip
