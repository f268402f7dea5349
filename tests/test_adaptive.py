"""Embedded pairs with step-size control (issue 24, item 2).

References: the published orders of each pair, scipy's ``solve_ivp``
(``RK45``/``RK23``: its steps, evaluations, dense output and
``select_initial_step``), python-control's exact ``forced_response`` and
``initial_response``, and closed forms.
"""

from __future__ import annotations

import inspect
import math

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.integrate._ivp.common import select_initial_step

import qc_control as qc
from qc_control.numerics.adaptive import (
    MIN_RTOL,
    StepController,
    adaptive_solve,
    initial_step,
    slope_breakpoints,
)
from qc_control.numerics.integrate import integrate
from qc_control.numerics.methods import (
    BOGACKI_SHAMPINE,
    DORMAND_PRINCE,
    HEUN_EULER,
    TABLEAUS,
    ButcherTableau,
    get_method,
)
from qc_control.numerics.sampled import linear_input

#: The seed car's free response: body lifted 5 cm, 0-10 s (the issue's case).
X0_CAR = np.array([0.0, 0.0, 0.05, 0.0])

#: scipy's accepted step times against ours, relative: the issue's 1e-9
#: where it holds. Both runs take the same steps with the same controller;
#: they differ only in rounding: the error estimate h Σ (b_i - b̂_i) k_i is
#: a sum of stages that cancel to O(h^5), so its relative rounding (about
#: eps |f| h / |err|) is far above eps, and it enters each next step
#: through ‖err‖^(-1/5). scipy forms the stages as matrix products with its
#: E; qc forms them in the stepper's one loop with b - b̂. Measured: 6e-12
#: (seed car, RK45) and 3.5e-12 (RK23) at scipy's defaults rtol 1e-3,
#: atol 1e-6; 3.6e-13 and 5.5e-12 on the pothole at rtol 1e-3 and 1e-6.
STEP_TIMES_RTOL = 1e-9
#: Where the rounding has grown past 1e-9 over thousands of steps: measured
#: 1.3e-7 (seed car, RK45, rtol 1e-6), 1.3e-9 (RK23, rtol 1e-6), 1.6e-9 and
#: 6.9e-9 (Van der Pol, rtol 1e-3 and 1e-6). With scipy's stage arithmetic
#: (matrix products over the stages) the times are equal to the last bit; with
#: scipy's E alone, 1.9e-8 and 2.3e-9. A wrong controller constant changes the
#: times by percent.
STEP_TIMES_RTOL_LONG = 1e-6


def seed_car_free(t, x, _A=np.asarray(qc.quarter_car().A, dtype=float)):
    return _A @ x


def van_der_pol(t, x, mu=2.0):
    return np.array([x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]])


def pothole():
    """The issue's pothole: the seed car at rest, 5 cm deep, 0.3 m long
    (1 - cos), at t = 1 s, 20 m/s, sampled at 1 ms over 0-3 s."""
    T = np.arange(3001) * 1e-3
    tau = (T - 1.0) / (0.3 / 20.0)
    U = np.where((tau >= 0) & (tau <= 1), -0.05 * (1 - np.cos(2 * np.pi * tau)) / 2, 0.0)
    return qc.quarter_car(road=True), T, U


# ------------------------------------------------------------------ tableaus


@pytest.mark.parametrize(
    ("tab", "p", "p_hat"),
    [(HEUN_EULER, 2, 1), (BOGACKI_SHAMPINE, 3, 2), (DORMAND_PRINCE, 5, 4)],
)
def test_pairs_have_their_published_orders(tab, p, p_hat):
    # published: Heun-Euler 2(1), Bogacki-Shampine 3(2), Dormand-Prince 5(4)
    assert (tab.order, tab.embedded_order, tab.error_order) == (p, p_hat, p_hat)
    assert tab.embedded and get_method(tab.name) is tab and TABLEAUS[tab.name] is tab


def test_seed_tableaus_have_no_estimator():
    for name in ("euler", "midpoint", "heun", "rk4"):
        tab = get_method(name)
        assert not tab.embedded and tab.b_hat is None and tab.error_order is None


@pytest.mark.parametrize(
    ("tab", "scipy_method"), [(DORMAND_PRINCE, "RK45"), (BOGACKI_SHAMPINE, "RK23")]
)
def test_error_weights_are_scipys(tab, scipy_method):
    from scipy.integrate import RK23, RK45

    E = {"RK45": RK45.E, "RK23": RK23.E}[scipy_method]
    # scipy's E is b̂ - b, each rounded once; ours b - b̂ of rounded b, b̂: a few eps
    np.testing.assert_allclose(tab.b - tab.b_hat, -E, rtol=0, atol=4 * np.finfo(float).eps)


@pytest.mark.parametrize(
    ("tab", "p"), [(HEUN_EULER, 2), (BOGACKI_SHAMPINE, 3), (DORMAND_PRINCE, 5)]
)
def test_observed_order_at_a_fixed_step(tab, p):
    # Van der Pol (mu = 2) over 0-2 s against solve_ivp at rtol 1e-12, the
    # largest error over the grid at 100 and 200 steps: the asymptotic range
    # for each pair (measured slopes 2.07, 3.07, 4.99; within 0.1 of p)
    ref = solve_ivp(
        van_der_pol, (0, 2), [2.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True
    )
    errors = []
    for n in (100, 200):
        t = np.linspace(0, 2, n + 1)
        errors.append(np.abs(integrate(van_der_pol, t, [2.0, 0.0], tab).x - ref.sol(t)).max())
    assert abs(math.log2(errors[0] / errors[1]) - p) < 0.1


@pytest.mark.parametrize(
    ("b_hat", "match"),
    [
        ([1.0, 0.0, 0.0], "b_hat must have shape"),
        ([0.6, 0.6], "b_hat sums to 1.2"),
        ([0.5, 0.5], "b_hat equals b"),
        ([np.nan, 1.0], "b_hat must be finite"),
        (["x", 1.0], "b_hat must be real"),
    ],
)
def test_bad_b_hat_is_named(b_hat, match):
    with pytest.raises(ValueError, match=match):
        ButcherTableau("bad", a=[[0, 0], [1, 0]], b=[0.5, 0.5], b_hat=b_hat)


def test_b_hat_takes_part_in_equality():
    plain = ButcherTableau("heun_euler", a=[[0, 0], [1, 0]], b=[0.5, 0.5])
    assert plain != HEUN_EULER
    assert HEUN_EULER == ButcherTableau(
        "heun_euler", a=[[0, 0], [1, 0]], b=[0.5, 0.5], b_hat=[1, 0]
    )


# ------------------------------------------------------------------ scipy's steps


@pytest.mark.parametrize("problem", ["car", "van_der_pol"])
def test_initial_step_is_scipys(problem):
    f, x0, t_end = (
        (seed_car_free, X0_CAR, 10.0)
        if problem == "car"
        else (van_der_pol, np.array([2.0, 0]), 20.0)
    )
    for rtol, atol in ((1e-3, 1e-6), (1e-8, 1e-11)):
        f0 = f(0.0, x0)
        ours = initial_step(f, 0.0, x0, f0, t_end, 4, rtol, atol)
        if (
            "t_bound" in inspect.signature(select_initial_step).parameters
        ):  # newer scipy caps h at the interval
            theirs = select_initial_step(f, 0.0, x0, t_end, np.inf, f0, 1, 4, rtol, atol)
        else:  # the same rule without the cap at the interval (not reached here)
            theirs = select_initial_step(f, 0.0, x0, f0, 1, 4, rtol, atol)
        # the same formula, the same operations: equal to rounding
        assert ours == pytest.approx(theirs, rel=1e-14)


@pytest.mark.parametrize(
    ("tab", "scipy_method"), [(DORMAND_PRINCE, "RK45"), (BOGACKI_SHAMPINE, "RK23")]
)
@pytest.mark.parametrize(
    ("rtol", "atol", "times_rtol"),
    [(1e-3, 1e-6, STEP_TIMES_RTOL), (1e-6, 1e-9, STEP_TIMES_RTOL_LONG)],
)
def test_steps_are_solve_ivps_on_the_seed_car(tab, scipy_method, rtol, atol, times_rtol):
    T = np.linspace(0, 10, 1001)
    ours = qc.initial_response(qc.quarter_car(), T, X0_CAR, method=tab, rtol=rtol, atol=atol)
    ref = solve_ivp(
        seed_car_free, (0, 10), X0_CAR, method=scipy_method, rtol=rtol, atol=atol, t_eval=T
    )
    steps = solve_ivp(seed_car_free, (0, 10), X0_CAR, method=scipy_method, rtol=rtol, atol=atol)
    assert ours.success and ours.n_accepted == steps.t.size - 1
    assert ours.nfev == steps.nfev  # the same evaluations: FSAL and the first step alike
    np.testing.assert_allclose(ours.accepted_times, steps.t, rtol=times_rtol, atol=0)
    assert ours.steps == ours.n_accepted and ours.h == pytest.approx(np.diff(steps.t).max())
    # the dense output at T is scipy's (RK45's quartic, RK23's cubic Hermite):
    # the same polynomial on the same steps, to the rounding of the steps
    np.testing.assert_allclose(ours.states, ref.y, rtol=0, atol=1e-12)


@pytest.mark.parametrize(("rtol", "atol"), [(1e-3, 1e-6), (1e-6, 1e-9)])
def test_steps_are_solve_ivps_on_a_nonlinear_system(rtol, atol):
    sys = control.nlsys(lambda t, x, u, p: van_der_pol(t, x), None, inputs=0, states=2, name="vdp")
    T = np.linspace(0, 20, 401)
    ours = qc.input_output_response(
        sys, T, 0, [2.0, 0.0], method="dormand_prince", rtol=rtol, atol=atol
    )
    steps = solve_ivp(van_der_pol, (0, 20), [2.0, 0.0], method="RK45", rtol=rtol, atol=atol)
    assert ours.success and ours.n_accepted == steps.t.size - 1 and ours.nfev == steps.nfev
    assert ours.n_rejected > 0  # the controller was exercised both ways
    np.testing.assert_allclose(ours.accepted_times, steps.t, rtol=STEP_TIMES_RTOL_LONG, atol=0)


@pytest.mark.parametrize(("rtol", "atol"), [(1e-3, 1e-6), (1e-6, 1e-9)])
def test_steps_are_scipys_on_the_pothole(rtol, atol):
    # scipy's own RK45 stepper, told to stop at each sample where the road's
    # slope changes (its t_bound moved on, its step size kept), takes the same
    # steps as ours to 1e-9 relative, and the same evaluations
    from scipy.integrate import RK45

    car, T, U = pothole()
    A, B = np.asarray(car.A, dtype=float), np.asarray(car.B, dtype=float)
    u = linear_input(T, U[None])
    stops = [*slope_breakpoints(T, U[None]), T[-1]]
    solver = RK45(lambda t, x: A @ x + B @ u(t), T[0], np.zeros(4), stops[0], rtol=rtol, atol=atol)
    times = [T[0]]
    for stop in stops:
        solver.t_bound, solver.status = stop, "running"
        while solver.status == "running":
            solver.step()
            times.append(solver.t)
    ours = qc.forced_response(car, T, U, method="dormand_prince", rtol=rtol, atol=atol)
    assert ours.success and ours.n_accepted == len(times) - 1 and ours.nfev == solver.nfev
    np.testing.assert_allclose(ours.accepted_times, times, rtol=STEP_TIMES_RTOL, atol=0)


def test_solve_ivp_kwargs_carry_the_tolerances():
    sys = control.nlsys(lambda t, x, u, p: van_der_pol(t, x), None, inputs=0, states=2, name="vdp")
    T = np.linspace(0, 5, 51)
    by_keyword = qc.input_output_response(sys, T, 0, [2, 0], method="dormand_prince", rtol=1e-5)
    by_ivp = qc.input_output_response(
        sys, T, 0, [2, 0], method="dormand_prince", solve_ivp_kwargs={"rtol": 1e-5}
    )
    np.testing.assert_array_equal(by_keyword.accepted_times, by_ivp.accepted_times)
    with pytest.raises(ValueError, match="rtol specified more than once"):
        qc.input_output_response(
            sys, T, 0, [2, 0], method="dormand_prince", rtol=1e-5, solve_ivp_kwargs={"rtol": 1e-5}
        )


# ------------------------------------------------------------------ sampled inputs


def test_slope_breakpoints_closed_form():
    T = np.linspace(0, 1, 11)
    assert slope_breakpoints(T, 3.0 * T + 1.0).size == 0  # a ramp: one slope throughout
    tri = np.minimum(T, 0.6 - T).clip(0)  # kinks at 0.3 and 0.6
    np.testing.assert_allclose(slope_breakpoints(T, tri[None]), [0.3, 0.6], atol=1e-15)
    # any input row's kink counts
    U = np.vstack([3.0 * T, np.where(T > 0.45, 1.0, 0.0)])
    np.testing.assert_allclose(slope_breakpoints(T, U), [0.4, 0.5], atol=1e-15)


def test_the_pothole_is_caught():
    car, T, U = pothole()
    exact = control.forced_response(car, T, U)
    travel = car.output_labels.index("susp_travel")
    peak = np.abs(exact.outputs[travel]).max()
    assert peak == pytest.approx(2.552e-3, rel=1e-3)  # the figure
    r = qc.forced_response(car, T, U, method="dormand_prince", rtol=1e-3, atol=1e-6)
    assert r.success and r.rtol == 1e-3 and r.atol == 1e-6
    # within 1 % of the exact peak at scipy's default tolerances (measured 0.02 %)
    assert np.abs(r.outputs[travel]).max() == pytest.approx(peak, rel=0.01)
    # every sample where the road's slope changes is a step end
    kinks = slope_breakpoints(T, U[None])
    assert kinks.size == 16 and np.isin(kinks, r.accepted_times).all()
    # the same through the nonlinear path
    nl = qc.input_output_response(car, T, U, method="dormand_prince", rtol=1e-3, atol=1e-6)
    assert np.abs(nl.outputs[travel]).max() == pytest.approx(peak, rel=0.01)


def test_without_the_breakpoints_the_pothole_is_stepped_over():
    # the failure the breakpoints prevent (python-control issue #1152's kind):
    # from rest, the first steps are long and no stage lands in the 15 ms pothole
    car, T, U = pothole()
    A, B, C = (np.asarray(m, dtype=float) for m in (car.A, car.B, car.C))
    u = linear_input(T, U[None])
    sol = integrate(lambda t, x: A @ x + B @ u(t), T, np.zeros(4), DORMAND_PRINCE, rtol=1e-3)
    assert np.abs(C[2] @ sol.x).max() < 1e-4


def test_dense_output_meets_the_exact_response():
    # rtol 1e-8, atol 1e-11 on states of 5 cm: at every 1 ms sample (nearly
    # all between step ends) the displacements within 1e-9 m and the
    # velocities within 1e-8 m/s of python-control's exact free response
    # (measured 2.4e-10 m and 2.4e-9 m/s: the global error of the run)
    T = np.linspace(0, 10, 10001)
    exact = control.initial_response(qc.quarter_car(), T, X0_CAR, return_x=True)
    r = qc.initial_response(
        qc.quarter_car(), T, X0_CAR, method="dormand_prince", rtol=1e-8, atol=1e-11
    )
    assert r.n_accepted < T.size / 10  # the output grid did not set the steps
    error = np.abs(np.asarray(r.states) - np.asarray(exact.states)).max(axis=1)
    assert error[2:].max() < 1e-9 and error[:2].max() < 1e-8  # states: vs, vu, xs, xu


# ------------------------------------------------------------------ failures and bad input


def test_step_underflow_is_reported():
    # x' = x², x(0) = 1 blows up at t = 1: the step shrinks until t cannot
    # resolve it, as solve_ivp's "Required step size is less than spacing"
    sys = control.nlsys(lambda t, x, u, p: x**2, None, states=1, inputs=0, name="blowup")
    T = np.linspace(0, 2, 21)
    r = qc.input_output_response(sys, T, X0=1.0, method="dormand_prince", rtol=1e-6)
    assert not r.success and "below the smallest step" in r.message
    assert r.t[-1] == pytest.approx(1.0) and r.t.size == 11


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(method="rk4", rtol=1e-6), "'rk4' has no error estimator"),
        (dict(method="dormand_prince", rtol=0.0), r"rtol \(.*\) must be .* got 0.0"),
        (dict(method="dormand_prince", rtol=-1e-3), r"rtol \(.*\) must be .* got -0.001"),
        (dict(method="dormand_prince", rtol=math.nan), r"rtol \(.*\) must be .* got nan"),
        (dict(method="dormand_prince", rtol=math.inf), r"rtol \(.*\) must be .* got inf"),
        (dict(method="dormand_prince", rtol=1e-17), "at least 100 eps.* got 1e-17"),
        (
            dict(method="dormand_prince", rtol="tight"),
            r"rtol \(.*\) must be a number in \[.*, 1\), got 'tight'",
        ),
        (
            dict(method="dormand_prince", atol=0.0),
            "atol must be a finite absolute tolerance > 0.*, got 0.0",
        ),
        (
            dict(method="dormand_prince", atol=math.inf),
            "atol must be a finite absolute tolerance > 0.*, got inf",
        ),
        (dict(method="dormand_prince", atol=[1e-6, 1e-6]), r"atol must be .* shape \(4,\)"),
        (dict(method="dormand_prince", rtol=1e-6, substeps=2), "substeps = 2 with rtol/atol"),
        (dict(method="dormand_prince", rtol=1e-6, engine="lti"), "engine='lti'"),
    ],
)
def test_bad_tolerances_are_named(kwargs, match):
    T = np.linspace(0, 1, 11)
    with pytest.raises(ValueError, match=match):
        qc.initial_response(qc.quarter_car(), T, X0_CAR, **kwargs)


def test_integrate_refuses_what_an_adaptive_run_cannot_do():
    t = np.linspace(0, 1, 11)
    with pytest.raises(ValueError, match="neither substeps"):
        integrate(lambda t, x: -x, t, [1.0], "dormand_prince", rtol=1e-6, events=lambda t, x: x)
    with pytest.raises(ValueError, match="single initial state"):
        integrate(lambda t, x: -x, t, [[1.0], [2.0]], "dormand_prince", rtol=1e-6)
    with pytest.raises(ValueError, match="first_step must be a finite number > 0 s, got 0.0"):
        integrate(lambda t, x: -x, t, [1.0], "dormand_prince", rtol=1e-6, first_step=0.0)
    with pytest.raises(ValueError, match="breakpoints must be finite"):
        integrate(lambda t, x: -x, t, [1.0], "dormand_prince", rtol=1e-6, breakpoints=[np.nan])
    shrink = r"min_factor \(the most a step shrinks at once\)"
    with pytest.raises(ValueError, match=shrink + r" must be a number in \(0, 1\), got 1.5"):
        StepController(min_factor=1.5)


def test_fixed_step_results_carry_no_adaptive_record():
    sol = integrate(lambda t, x: -x, np.linspace(0, 1, 11), [1.0], "dormand_prince")
    assert sol.accepted_times is None and sol.n_accepted == 0 and sol.nfev == 7 * 10
    r = qc.initial_response(qc.quarter_car(), np.linspace(0, 1, 11), X0_CAR, method="rk4")
    assert r.accepted_times is None and r.rtol is None


def test_closed_form_decay_and_counts():
    # x' = -x: e^{-t} at every output time within the tolerance's order
    t = np.linspace(0, 5, 51)
    run = adaptive_solve(lambda t, x: -x, t, np.array([1.0]), HEUN_EULER, 1e-6, 1e-9)
    assert run.status == "success" and run.t.size == t.size
    assert np.abs(run.x[:, 0] - np.exp(-t)).max() < 1e-5  # Heun-Euler's global error at rtol 1e-6
    # non-FSAL: s - 1 evaluations per attempt, one more per accepted step, two at the start
    assert run.nfev == 2 + (run.n_accepted + run.n_rejected) * 1 + run.n_accepted
    assert MIN_RTOL == 100 * np.finfo(float).eps


def test_step_response_sums_the_traces():
    # two inputs, two traces; each within 1e-6 m of python-control's exact
    # step response at rtol 1e-6 (the run's global error is about 1e-8 m)
    sys = control.ss(
        np.asarray(qc.quarter_car().A), np.eye(4)[:, :2], np.eye(4)[2:], 0, name="two_inputs"
    )
    T = np.linspace(0, 5, 501)
    exact = control.step_response(sys, T)
    r = qc.step_response(sys, T, method="dormand_prince", rtol=1e-6, atol=1e-9)
    assert r.success and np.abs(r.outputs - exact.outputs).max() < 1e-6
    one = qc.step_response(sys, T, input=1, method="dormand_prince", rtol=1e-6, atol=1e-9)
    zero = qc.step_response(sys, T, input=0, method="dormand_prince", rtol=1e-6, atol=1e-9)
    assert r.n_accepted == one.n_accepted + zero.n_accepted
    assert r.nfev == one.nfev + zero.nfev
    np.testing.assert_array_equal(r.accepted_times, one.accepted_times)  # the last trace's


def test_evaluation_times_and_max_step():
    sys = control.nlsys(lambda t, x, u, p: van_der_pol(t, x), None, inputs=0, states=2, name="vdp")
    T = np.linspace(0, 10, 11)
    te = np.array([0.25, 2.5, 7.75])
    r = qc.input_output_response(
        sys, T, 0, [2.0, 0.0], method="dormand_prince", rtol=1e-8, atol=1e-10,
        evaluation_times=te, solve_ivp_kwargs={"max_step": 0.05},
    )  # fmt: skip
    ref = solve_ivp(van_der_pol, (0, 10), [2.0, 0.0], method="RK45", rtol=1e-8, atol=1e-10,
                    max_step=0.05, t_eval=te)  # fmt: skip
    np.testing.assert_array_equal(r.t, te)
    # the same steps and dense output as scipy's with the same max_step (rounding)
    np.testing.assert_allclose(r.states, ref.y, rtol=0, atol=1e-9)
    # each step at most max_step; differences of times up to 10 s round by ~2e-15 s
    assert np.diff(r.accepted_times).max() <= 0.05 + 1e-14
    with pytest.raises(ValueError, match="evaluation_times=None"):
        qc.input_output_response(
            sys, T, 0, [2.0, 0.0], method="dormand_prince", rtol=1e-6, evaluation_times=None
        )
