"""Fixed-step responses against python-control's exact responses.

Tolerances used below, with their source:

* ``FINE``: RK4 at ``h·|λ|max <= 0.01`` (`fine_substeps`). Its local error on
  a mode is ``(h|λ|)⁵/120`` of the mode per step (Hairer, Nørsett & Wanner I,
  §II.3), 8.3e-13, so the error of a mode after time t is about
  ``t|λ|(h|λ|)⁴/120 e^{Re λ t}`` of its amplitude. For a decaying mode that
  peaks at ``t = 1/|Re λ|`` at ``(|λ|/|Re λ|)/e · 8.3e-11``: 8e-11 for the
  quarter car's wheel hop and the test transfer function (|λ|/|Re λ| ≈ 2.6).
  1e-8 relative to the largest sample leaves 100x margin (measured 2.8e-11 to
  7.9e-11).
* Discrete-time and ``dt=None`` systems are python-control's own difference
  equation: equal to the last bit.
"""

import inspect
import math
import warnings

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control import METHODS, DivergenceWarning
from qc_control.numerics.integrate import uniform_step
from qc_control.responses import timeresp as qr

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


# ------------------------------------------------------------------ helpers for the drop-in tests

FINE = 1e-8  # RK4 at h|λ|max <= 0.01 against control's exact response (module docstring)


def fine_substeps(sys, T, h_lam=0.01):
    """Fewest substeps with h·|λ|max <= h_lam on the grid T."""
    lam = np.max(np.abs(np.linalg.eigvals(np.asarray(control.ss(sys).A))))
    return max(1, math.ceil(float(np.max(np.diff(T))) * lam / h_lam))


def rel(ours, ref):
    ours, ref = np.asarray(ours, dtype=float), np.asarray(ref, dtype=float)
    assert ours.shape == ref.shape
    return float(np.max(np.abs(ours - ref)) / np.max(np.abs(ref)))


@pytest.fixture
def fresh_defaults():
    """Changes to control.config.defaults last only for the test."""
    yield
    control.reset_defaults()


# ------------------------------------------------------------------ call shape


@pytest.mark.parametrize(
    "name", ["initial_response", "forced_response", "step_response", "impulse_response"]
)
def test_signature_is_controls_plus_keyword_only_method(name):
    ours = inspect.signature(getattr(qc, name)).parameters.values()
    theirs = inspect.signature(getattr(control, name)).parameters.values()

    def positional(params):
        return [(p.name, p.default) for p in params if p.kind is p.POSITIONAL_OR_KEYWORD]

    assert positional(ours) == positional(theirs)
    # the keyword-only additions: the method, its steps, the engine, and the
    # tolerances of an embedded pair's step-size control (issue 24)
    assert [p.name for p in ours if p.kind is p.KEYWORD_ONLY] == [
        "method", "substeps", "engine", "rtol", "atol",
    ]  # fmt: skip
    assert [p.kind for p in ours][-1] is inspect.Parameter.VAR_KEYWORD  # control's aliases


def test_positional_arguments_mean_what_they_mean_in_control():
    sys = qc.quarter_car(road=True)
    T = grid(0.01, 2.0)
    U = 0.01 * np.sin(2 * np.pi * T)
    k = fine_substeps(sys, T)
    # initial_response(sys, T, X0, output): the 4th positional is the output index
    ours, ref = (
        qc.initial_response(sys, T, X0, 2, substeps=k),
        control.initial_response(sys, T, X0, 2),
    )
    assert ours.outputs.shape == ref.outputs.shape == (T.size,)
    assert rel(ours.outputs, ref.outputs) < FINE
    # forced_response(sys, T, U, X0, transpose): the 5th is transpose
    ours = qc.forced_response(sys, T, U, X0, True, substeps=k)
    ref = control.forced_response(sys, T, U, X0, True)
    assert ours.outputs.shape == ref.outputs.shape == (T.size, 5)
    assert rel(ours.outputs, ref.outputs) < FINE


def test_a_method_in_controls_positional_place_is_a_clear_error():
    sys = qc.quarter_car()
    with pytest.raises(TypeError, match="method is keyword-only"):
        qc.initial_response(sys, [0, 1], X0, "euler")
    with pytest.raises(TypeError, match="method is keyword-only"):
        qc.forced_response(qc.quarter_car(road=True), [0, 1], 0.0, X0, "rk4")


def test_keyword_aliases_like_control():
    sys = qc.quarter_car()
    T = grid(0.01, 1.0)
    a = qc.initial_response(sys, timepts=T, initial_state=X0, method="euler")
    b = qc.initial_response(sys, T=T, X0=X0, method="euler")
    c = qc.initial_response(sys, T, X0, method="euler", return_x=True)
    np.testing.assert_array_equal(a.outputs, b.outputs)
    np.testing.assert_array_equal(a.outputs, c.outputs)
    assert len(c) == 3 and len(a) == 2  # return_x: unpacks to (t, y, x)
    with pytest.raises(TypeError, match="unrecognized keyword"):
        qc.initial_response(sys, T, X0, h=0.01)
    with pytest.raises(TypeError, match="multiple"):  # control's own check
        qc.initial_response(sys, T, X0, output=1, output_indices=1)
    with pytest.warns(PendingDeprecationWarning, match="legacy"):  # control's legacy x0
        d = qc.initial_response(sys, T, x0=X0, method="euler")
    np.testing.assert_array_equal(a.outputs, d.outputs)


def test_output_keyword_selects_an_output_like_control():
    sys = qc.quarter_car()
    T = grid(0.01, 3.0)
    k = fine_substeps(sys, T)
    for kw in ({"output": 1}, {"output_indices": 1}):
        ours = qc.initial_response(sys, T, X0, substeps=k, **kw)
        ref = control.initial_response(sys, T, X0, **kw)
        assert ours.output_labels == ref.output_labels == ["xu"]
        assert ours.outputs.shape == (T.size,)
        assert rel(ours.outputs, ref.outputs) < FINE


def test_config_defaults_and_legacy_unpacking_like_control(fresh_defaults):
    sys = qc.quarter_car(road=True)
    T = grid(0.01, 1.0)
    U = np.full(T.size, 0.01)
    assert len(qc.forced_response(sys, T, U)) == 2
    with pytest.warns(UserWarning, match="NumPy matrix"):
        control.use_legacy_defaults("0.8.4")
    t, y, x = qc.forced_response(sys, T, U)  # 0.8.4 returned the states too
    assert x.shape == (4, T.size)
    control.reset_defaults()
    siso = control.ss(control.tf([1], [1, 1]))
    assert qc.forced_response(siso, T, U).outputs.ndim == 1
    control.config.defaults["control.squeeze_time_response"] = False
    assert qc.forced_response(siso, T, U).outputs.shape == (1, T.size)
    control.config.defaults["forced_response.return_x"] = True
    assert len(qc.forced_response(siso, T, U)) == 3


def test_params_are_kept_in_the_result_like_control():
    sys = qc.quarter_car()
    r = qc.initial_response(sys, [0, 0.1], X0, params={"k": 1})
    assert r.params == control.initial_response(sys, [0, 0.1], X0, params={"k": 1}).params


# ------------------------------------------------------------------ systems


def test_transfer_function_is_converted_with_control_ss():
    H = control.tf([25.0], [1, 4, 25], name="H", inputs="r", outputs="y")
    T = grid(0.01, 5.0)
    U = np.where(T >= 1, 1.0, 0.0)
    k = fine_substeps(H, T)
    ours, ref = qc.forced_response(H, T, U, substeps=k), control.forced_response(H, T, U)
    assert rel(ours.outputs, ref.outputs) < FINE
    assert ours.method.name == "rk4" and ours.note is None
    assert (ours.sysname, ours.input_labels, ours.output_labels) == ("H", ["r"], ["y"])
    assert ours.sysname == ref.sysname and ours.title == ref.title
    with pytest.warns(UserWarning, match="Non-zero initial condition"):  # control's warning
        qc.forced_response(H, T, U, [1.0, 0.0])


def discrete_quarter_car(dt):
    sysd = control.c2d(qc.quarter_car(road=True), 0.01)
    if dt is True:
        return control.ss(sysd.A, sysd.B, sysd.C, sysd.D, True)
    return sysd


@pytest.mark.parametrize("dt", [0.01, True])
def test_discrete_time_is_controls_difference_equation(dt):
    sysd = discrete_quarter_car(dt)
    T = np.arange(301) * (0.01 if dt is not True else 1.0)
    U = np.where(np.arange(301) >= 50, 0.05, 0.0)
    ours, ref = qc.forced_response(sysd, T, U, X0), control.forced_response(sysd, T, U, X0)
    np.testing.assert_array_equal(ours.outputs, ref.outputs)
    np.testing.assert_array_equal(ours.states, ref.states)
    assert ours.method is None and ours.h is None and ours.nfev == 0
    assert "no fixed-step method was applied" in ours.note and ours.success
    for f in ("initial_response", "step_response", "impulse_response"):
        a = getattr(qc, f)(sysd, T)
        b = getattr(control, f)(sysd, T)
        np.testing.assert_array_equal(a.outputs, b.outputs)
        assert "difference equation" in a.note


def test_discrete_interpolate_like_control():
    sysd = discrete_quarter_car(0.01)
    T = np.arange(0, 2.0001, 0.05)  # 5 samples of the system per input sample
    U = 0.01 * np.sin(2 * np.pi * T)
    a = qc.forced_response(sysd, T, U, interpolate=True)
    b = control.forced_response(sysd, T, U, interpolate=True)
    np.testing.assert_array_equal(a.time, b.time)
    np.testing.assert_array_equal(a.outputs, b.outputs)


def test_dt_none_is_treated_as_control_treats_it():
    """control simulates a dt=None system as discrete, with the grid's spacing."""
    sysd = discrete_quarter_car(0.01)
    sysn = control.ss(sysd.A, sysd.B, sysd.C, sysd.D, None)
    T = np.arange(101) * 0.5
    ours, ref = qc.forced_response(sysn, T, 0.01), control.forced_response(sysn, T, 0.01)
    np.testing.assert_array_equal(ours.outputs, ref.outputs)
    assert "dt=None" in ours.note and ours.method is None


def test_a_static_gain_has_nothing_to_integrate():
    # dt=0 made explicit: control gives a static system dt=None (see the dt=None test)
    gain = control.ss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[2.0]], dt=0)
    T = grid(0.1, 1.0)
    U = np.sin(T)
    ours = qc.forced_response(gain, T, U)
    np.testing.assert_array_equal(ours.outputs, control.forced_response(gain, T, U).outputs)
    assert "no states" in ours.note


def test_list_of_systems_gives_a_time_response_list():
    systems = [qc.quarter_car(), qc.quarter_car(qc.QuarterCarParams(zeta=0.5))]
    T = grid(0.01, 3.0)
    k = max(fine_substeps(s, T) for s in systems)
    ours, ref = (
        qc.initial_response(systems, T, X0, substeps=k),
        control.initial_response(systems, T, X0),
    )
    assert isinstance(ours, control.TimeResponseList) and len(ours) == 2
    for a, b in zip(ours, ref):
        assert isinstance(a, qc.FixedStepResponse) and rel(a.outputs, b.outputs) < FINE
    # with T=None, one grid for all of them, as control chooses it
    auto = qc.initial_response(systems, initial_state=X0)
    for a, b in zip(auto, control.initial_response(systems, initial_state=X0)):
        np.testing.assert_array_equal(a.time, b.time)
    assert isinstance(qc.forced_response(systems, T, 0.0, X0), control.TimeResponseList)


def test_nonlinear_systems_go_to_input_output_response_as_in_control():
    # the responses themselves: tests/test_nonlinear_response.py
    nl = control.nlsys(lambda t, x, u, params: -x + u, None, inputs=1, states=1, name="nl")
    for r in (
        qc.initial_response(nl, [0, 1], 1.0),
        qc.forced_response(nl, [0, 1], 0.0),
        qc.step_response(nl, [0, 1]),
    ):
        assert isinstance(r, qc.FixedStepResponse) and r.method.name == "rk4"
    with pytest.raises(ValueError, match="must be LTI"):  # control's own refusal
        qc.impulse_response(nl, [0, 1])


def test_bad_system_gets_controls_error():
    for f in (qc.forced_response, control.forced_response):
        with pytest.raises(TypeError, match="must be a `StateSpace` or `TransferFunction`"):
            f("sys", [0, 1])


# ------------------------------------------------------------------ T optional


def test_T_none_uses_controls_grid_and_says_which_step_it_chose():
    """The output grid is control's own; each interval is split to meet auto_step.

    RK4 at h|λ|max = 0.1 has local error 8.3e-8 per step on the fastest mode.
    The error of a mode λ grows as t|λ|(h|λ|)⁴/120 while the mode decays as
    e^{Re λ t}; the product peaks at t = 1/|Re λ| at (|λ|/|Re λ|)/e · 8.3e-7
    of the mode's amplitude, 8e-7 for the wheel hop (|λ|/|Re λ| = 2.6). So
    5e-6 relative to the largest state (measured 7.1e-7).
    """
    sys = qc.quarter_car()
    ours = qc.initial_response(sys, initial_state=X0)
    ref = control.initial_response(sys, initial_state=X0)
    np.testing.assert_array_equal(ours.time, ref.time)
    lam = np.max(np.abs(np.linalg.eigvals(np.asarray(sys.A))))
    assert ours.h * lam <= 0.1 * (1 + 1e-12)
    assert ours.h * lam > 0.1 * (ours.substeps - 1) / ours.substeps  # the fewest substeps
    assert ours.h * ours.substeps == pytest.approx(ref.time[1] - ref.time[0], rel=1e-12)
    assert ours.step_rule.startswith("accuracy")
    assert rel(ours.states, ref.states) < 5e-6


def test_final_time_and_T_num_like_control():
    sys = qc.quarter_car()
    ours = qc.initial_response(sys, 3.0, X0, T_num=301)
    ref = control.initial_response(sys, 3.0, X0, T_num=301)
    np.testing.assert_array_equal(ours.time, ref.time)
    assert ours.time.size == 301 and ours.substeps == 3  # 0.01 s · 25.1/s = 0.25 -> 3 substeps
    assert rel(ours.states, ref.states) < 5e-6  # as for T=None
    sr = qc.step_response(qc.quarter_car(road=True), 2.0, timepts_num=201)
    np.testing.assert_array_equal(sr.time, np.linspace(0, 2.0, 201))


# ------------------------------------------------------------------ step and impulse responses


def test_step_and_impulse_responses_match_control():
    sys = qc.quarter_car(road=True, actuator=True)
    T = grid(0.01, 3.0)
    k = fine_substeps(sys, T)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # D != 0: both warn for the impulse
        for f in ("step_response", "impulse_response"):
            ours, ref = getattr(qc, f)(sys, T, substeps=k), getattr(control, f)(sys, T)
            assert ours.outputs.shape == ref.outputs.shape == (5, 2, T.size)
            assert ours.trace_labels == ref.trace_labels and ours.title == ref.title
            assert rel(ours.outputs, ref.outputs) < FINE
            assert ours.nfev == 2 * 4 * k * (T.size - 1)  # two traces
            one = getattr(qc, f)(sys, T, input=1, output=0, substeps=k)
            ref1 = getattr(control, f)(sys, T, input=1, output=0)
            assert one.outputs.shape == (T.size,)
            assert rel(one.outputs, ref1.outputs) < FINE
    with pytest.warns(UserWarning, match="direct feedthrough"):
        qc.impulse_response(sys, T)


# ------------------------------------------------------------------ success means finite

#: A valid design whose eigenvalues rounding puts on the imaginary axis
#: (max Re λ = +1.1e-10): before, RK4 at h = 1e-5 gave success=True and NaN.
NAN_DESIGN = {"ms": 5056.9, "mu": 0.01235, "ks": 4.4827e8, "ku": 153.69, "zeta": 0.0208}


@pytest.mark.parametrize("engine", ["auto", "lti", "generic"])
def test_nan_never_passes_as_success(engine):
    sys = qc.quarter_car(qc.QuarterCarParams(**NAN_DESIGN))
    T = np.arange(2001) * 1e-5
    with pytest.warns(DivergenceWarning, match="exceeds the stability limit"):
        r = qc.initial_response(sys, T, X0, method="rk4", engine=engine)
    assert not r.success
    if not np.all(np.isfinite(r.states)):
        assert "NaN or inf" in r.message


@pytest.mark.parametrize("engine", ["lti", "generic"])
def test_overflow_of_an_unstable_system_is_not_success(engine):
    """x' = 800 x: the exact response overflows too, so no step-size warning; the
    non-finite samples alone must make success False."""
    sys = control.ss([[800.0]], [[0.0]], [[1.0]], [[0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = qc.initial_response(sys, np.linspace(0, 10, 101), 1.0, engine=engine)
    assert not r.success and r.message


def test_non_finite_discrete_response_is_not_success():
    sysd = control.ss([[1e100]], [[0.0]], [[1.0]], [[0.0]], 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = qc.initial_response(sysd, np.arange(6.0), 1e100)
    assert not r.success and "NaN or inf" in r.message


def test_input_checks_are_public():
    np.testing.assert_array_equal(qr.check_initial_state([[1.0], [2.0]], 2), [1.0, 2.0])
    assert qr.check_input_samples(0.5, 2, 3).shape == (2, 3)
    with pytest.raises(ValueError, match="X0 must be real"):
        qr.check_initial_state([1 + 2j], 1)


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
        (lambda s: qc.initial_response("sys", [0, 1], X0), TypeError, "`StateSpace`"),
        (lambda s: qc.forced_response(s, [0, 1], 0.05), ValueError, "system has no inputs"),
        (
            lambda s: qc.forced_response(qc.quarter_car(road=True), [0, 1, 2], [0, 1]),
            ValueError,
            r"U must have shape \(3,\) or \(1, 3\)",
        ),
        (lambda s: qc.initial_response(s, [0, 1], X0, substeps=0), ValueError, "substeps"),
        (lambda s: qc.initial_response(s, [0, 1], X0, engine="fast"), ValueError, "engine"),
        (lambda s: qc.forced_response(s, None), ValueError, "`T` is mandatory"),
    ],
)
def test_bad_input(call, error, words):
    with pytest.raises(error, match=words):
        call(qc.quarter_car())


def test_outputs_whose_sum_overflows_are_still_finite():
    """The finiteness check sums first (one pass); a sum that overflows on finite
    outputs (here ~5e306 on 10,001 samples) must fall back to the exact test,
    not call the run failed."""
    car = qc.quarter_car()
    # the body displacement alone, scaled: 5e306 at the release, finite on every sample
    big = control.ss(car.A, np.zeros((4, 1)), 1e308 * np.asarray(car.C)[[0]], 0.0)
    T = np.linspace(0, 10, 10001)
    r = qc.initial_response(big, T, [0, 0, 0.05, 0])
    with np.errstate(over="ignore", invalid="ignore"):  # the premise: the sum overflows
        assert np.all(np.isfinite(r.outputs)) and not np.isfinite(np.sum(r.outputs))
    assert r.success


def test_uniform_step_of_a_grid_is_unchanged_by_the_cached_line():
    """Checking a grid against the shared line t0 + k·dt must neither change the
    verdict for a jittered grid nor let a caller alter the line."""
    T = np.linspace(0, 1, 101)
    assert uniform_step(T) == pytest.approx(0.01, rel=1e-15)
    T2 = T.copy()
    T2[50] += 1e-9
    assert uniform_step(T2) is None
    assert uniform_step(T) is not None  # the first grid, again
