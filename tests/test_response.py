"""Fixed-step responses against python-control's exact responses."""

import math
import warnings

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control import METHODS, DivergenceWarning

X0 = [0.0, 0.0, 0.05, 0.0]  # the default scenario: body released from 5 cm
ORDERS = {"euler": 1, "midpoint": 2, "heun": 2, "rk4": 4}


def grid(h, t_end=10.0):
    return np.linspace(0.0, t_end, int(round(t_end / h)) + 1)


def displacement_error(method, h, sys=None):
    sys = sys or qc.quarter_car()
    T = grid(h)
    exact = control.initial_response(sys, T, X0)
    ours = qc.initial_response(sys, T, X0, method=method)
    return np.max(np.abs(ours.outputs[:2] - exact.outputs[:2]))


def test_rk4_1ms_within_1e8_m_of_control():
    # Measured 8.6e-11 m; the bound is 1e-8 m.
    assert displacement_error("rk4", 1e-3) < 1e-8


@pytest.mark.parametrize("method", list(METHODS))
def test_observed_order(method):
    """Observed order from h, h/2, h/4 (h = 2 ms) is the method's order +-0.15.

    At h = 2 ms every method is in its asymptotic range (Euler's slope is
    1.03; at h = 10 ms it is still 1.18) and RK4's error at h/4 (1.3e-12 m)
    stays 100x above rounding.
    """
    hs = np.array([2e-3, 1e-3, 5e-4])
    errors = [displacement_error(method, h) for h in hs]
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert slope == pytest.approx(ORDERS[method], abs=0.15)


def taylor(M, p):
    term, total = np.eye(4), np.eye(4)
    for k in range(1, p + 1):
        term = term @ M / k
        total = total + term
    return total


@pytest.mark.parametrize("method", list(METHODS))
def test_one_step_is_the_taylor_polynomial(method):
    """On x' = Ax an s = p method's step is T_p(hA) x (HW II, IV.2)."""
    sys = qc.quarter_car()
    A, h = np.asarray(sys.A), 0.01
    x0 = np.array([0.3, -0.2, 0.05, 0.01])
    step = qc.initial_response(sys, [0.0, h], x0, method=method, return_x=True).states[:, 1]
    np.testing.assert_allclose(step, taylor(h * A, ORDERS[method]) @ x0, rtol=1e-14, atol=1e-17)


def test_midpoint_and_heun_coincide_on_lti_responses():
    sys = qc.quarter_car(road=True)
    T = grid(0.01, 5.0)
    free = [qc.initial_response(sys, T, X0, method=m).states for m in ("midpoint", "heun")]
    U = np.where(T >= 0.5, 0.05, 0.0)
    road = [qc.forced_response(sys, T, U, method=m).states for m in ("midpoint", "heun")]
    # Identical maps, different rounding: states O(1), 500 steps -> below 1e-13.
    np.testing.assert_allclose(free[0], free[1], rtol=0, atol=1e-13)
    np.testing.assert_allclose(road[0], road[1], rtol=0, atol=1e-13)


def test_midpoint_and_heun_differ_on_a_curved_input():
    """With u(t) = sin(2 pi t) evaluated inside the step they part: O(h^3) per step."""
    A = np.asarray(qc.quarter_car().A)
    b = np.array([0.0, 295.3, 0.0, 0.0])
    f = lambda t, x: A @ x + b * 0.01 * math.sin(2 * math.pi * 3 * t)
    T = grid(0.01, 2.0)
    mid = qc.integrate(f, T, np.zeros(4), "midpoint").x
    heun = qc.integrate(f, T, np.zeros(4), "heun").x
    assert np.max(np.abs(mid[2:] - heun[2:])) > 1e-6


def test_road_step_agrees_with_control_forced_response():
    sys = qc.quarter_car(road=True)
    T = grid(1e-3, 5.0)
    U = np.where(T >= 0.5, 0.05, 0.0)
    exact = control.forced_response(sys, T, U, 0.0)
    ours = qc.forced_response(sys, T, U, 0.0, method="rk4")
    # Measured 6.1e-11 m at h = 1 ms; the bound is the same 1e-8 m as for the free response.
    assert np.max(np.abs(ours.outputs[:4] - exact.outputs[:4])) < 1e-8
    # body_acc has D = B[0] = 0 for the road; its error is A[0] @ (state error): < 1e-5 m/s^2
    assert np.max(np.abs(ours.outputs[4] - exact.outputs[4])) < 1e-5


@pytest.mark.parametrize("method", list(METHODS))
def test_forced_response_converges_at_the_order(method):
    sys = qc.quarter_car(road=True)
    errors = []
    hs = [2e-3, 1e-3, 5e-4]
    for h in hs:
        T = grid(h, 5.0)
        U = 0.01 * np.sin(2 * np.pi * 1.5 * T)
        exact = control.forced_response(sys, T, U, 0.0).outputs[0]
        errors.append(
            np.max(np.abs(qc.forced_response(sys, T, U, method=method).outputs[0] - exact))
        )
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert slope == pytest.approx(ORDERS[method], abs=0.15)


def test_returns_time_response_data_like_control():
    sys = qc.quarter_car(road=True)
    T = grid(0.01, 1.0)
    U = np.full(T.size, 0.01)
    ours = qc.forced_response(sys, T, U, X0, method="heun")
    ref = control.forced_response(sys, T, U, X0)
    assert isinstance(ours, control.TimeResponseData)
    assert ours.output_labels == ref.output_labels and ours.state_labels == ref.state_labels
    assert ours.input_labels == ref.input_labels == ["zr"]
    assert ours.outputs.shape == ref.outputs.shape and ours.inputs.shape == ref.inputs.shape
    assert list(ours.to_pandas().columns) == list(ref.to_pandas().columns)
    t, y = ours  # unpacks like control's
    assert t.shape == T.shape and y.shape == (5, T.size)
    assert ours.nfev == 2 * 100 and ours.method.name == "heun" and ours.h == pytest.approx(0.01)
    assert ours.plot() is not None
    free = qc.initial_response(sys, T, X0)
    assert free.inputs is None


def test_keyword_aliases_like_control():
    sys = qc.quarter_car()
    T = grid(0.01, 1.0)
    a = qc.initial_response(sys, timepts=T, initial_state=X0, method="euler")
    b = qc.initial_response(sys, T, X0, "euler")
    np.testing.assert_array_equal(a.outputs, b.outputs)
    with pytest.raises(TypeError, match="unrecognized keyword"):
        qc.initial_response(sys, T, X0, h=0.01)


def test_euler_beyond_limit_is_flagged_not_crashed():
    sys = qc.quarter_car()
    T = np.arange(0, 401) * 0.025  # h = 0.025 s > 0.0198 s
    with pytest.warns(DivergenceWarning, match="exceeds the stability limit 0.0198"):
        r = qc.initial_response(sys, T, X0, method="euler")
    assert not r.success and "exceeds" in r.message
    assert np.all(np.isfinite(r.outputs)) and r.time.size == T.size
    # the body mode grows: |1 + h lambda| = 1.0025 per step
    assert np.max(np.abs(r.outputs[0, -40:])) > 0.05


def test_step_just_inside_the_limit_does_not_warn():
    sys = qc.quarter_car()
    h = 0.99 * qc.max_stable_step("euler", sys)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DivergenceWarning)
        r = qc.initial_response(sys, np.arange(0, 101) * h, X0, method="euler")
    assert r.success


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda s: qc.initial_response(s, [0, 1, 1, 2], X0), ValueError, "must increase strictly"),
        (
            lambda s: qc.initial_response(s, [0, 1], [0, 0, 0.05]),
            ValueError,
            r"X0 must have shape \(4,\)",
        ),
        (
            lambda s: qc.initial_response(s, [0, 1], [0, 0, np.nan, 0]),
            ValueError,
            "X0 must be finite",
        ),
        (
            lambda s: qc.initial_response(s, [0, 1], X0, method="rk45"),
            ValueError,
            "known methods are euler, midpoint, heun, rk4",
        ),
        (
            lambda s: qc.initial_response(control.c2d(s, 0.01), [0, 0.01], X0),
            ValueError,
            "must be continuous-time",
        ),
        (lambda s: qc.initial_response("sys", [0, 1], X0), TypeError, "control.StateSpace"),
        (lambda s: qc.forced_response(s, [0, 1], 0.05), ValueError, "system has no inputs"),
        (
            lambda s: qc.forced_response(qc.quarter_car(road=True), [0, 1, 2], [0, 1]),
            ValueError,
            r"U must have shape \(3,\) or \(1, 3\)",
        ),
        (lambda s: qc.initial_response(s, [0, 1], X0, substeps=0), ValueError, "substeps"),
    ],
)
def test_bad_input(call, error, words):
    with pytest.raises(error, match=words):
        call(qc.quarter_car())
