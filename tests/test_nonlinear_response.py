"""Nonlinear and interconnected systems at a fixed step (`qc.input_output_response`).

References and tolerances, each with its source:

* **solve_ivp**: ``scipy.integrate.solve_ivp`` with DOP853 at rtol = atol =
  1e-12 on a right-hand side written out in the test (not through
  python-control). Its own error, measured against rtol = atol = 1e-14, is
  8.0e-12 on Van der Pol over 10 s.
* **RK4 at h = 1e-3 on Van der Pol** (μ = 1, x0 = (2, 0), 10 s): the global
  error is ``C h⁴`` (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.3,
  Thm 3.6); the error at h = 1e-2 (5.1e-8) gives C ≈ 5, so 5e-12 at 1e-3.
  Measured 7.3e-12, at the reference's own accuracy. The bound 1e-10 is
  20x the predicted error plus the reference's.
* **Observed orders** from h, h/2, h/4 (h = 0.01): ``log2(e(h/2)/e(h/4))``
  tends to the order p as ``p + O(h)``; measured 1.011 (Euler), 1.995
  (Midpoint), 1.994 (Heun), 3.999 (RK4). Tolerance ±0.05.
* **Midpoint vs Heun** on Van der Pol at h = 0.02 over 10 s: they differ by
  8.9e-4 in the state (measured 8.895e-4; issue 11 quotes 8.9e-4). On a
  linear system with an input linear within each step they are the same
  map, and agree to rounding (measured 4e-16; bound 1e-13 relative).
* **A linear system wrapped as nlsys** is stepped by the same formulas as
  qc's linear `forced_response`, in another order of operations: they agree
  to rounding, 1e-12 relative (measured 4.7e-14 at most, Euler).
* **Interconnection** (a damped pendulum under a tanh-saturated PI
  controller, `control.interconnect`): RK4 against solve_ivp on the
  hand-assembled closed loop; error 5.6e-9 at h = 0.01 (``C h⁴``, C ≈ 0.56),
  order 4.00 from h = 0.01 to 0.005. The reference is a ramp, which linear
  interpolation of its samples reproduces exactly, so the only error is
  the method's.
"""

import importlib.util
import warnings
from pathlib import Path

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control import DivergenceWarning
from qc_control.responses import iosys

ORDERS = {"euler": 1, "midpoint": 2, "heun": 2, "rk4": 4}
X0_VDP = [2.0, 0.0]
TIGHT = dict(method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)


def grid(h, t_end=10.0):
    return np.linspace(0.0, t_end, int(round(t_end / h)) + 1)


def vdp_rhs(t, x, u, params):
    mu = params["mu"]
    return [x[1], mu * (1 - x[0] ** 2) * x[1] - x[0]]


def van_der_pol():
    return control.nlsys(vdp_rhs, None, states=["x", "v"], name="vdp", params={"mu": 1.0})


@pytest.fixture(scope="module")
def vdp_reference():
    """Van der Pol, μ = 1, by solve_ivp (DOP853, rtol = atol = 1e-12)."""
    sol = solve_ivp(lambda t, x: vdp_rhs(t, x, None, {"mu": 1.0}), (0, 10), X0_VDP, **TIGHT)
    return sol.sol


def vdp_error(method, h, reference):
    T = grid(h)
    r = qc.input_output_response(van_der_pol(), T, X0=X0_VDP, method=method)
    assert r.success and r.t.size == T.size
    return float(np.max(np.abs(r.states - reference(T))))


def test_van_der_pol_rk4_at_1ms(vdp_reference):
    # C h^4 with C ~ 5 (see the module docstring): 5e-12; measured 7.3e-12
    assert vdp_error("rk4", 1e-3, vdp_reference) < 1e-10


@pytest.mark.parametrize("method", list(ORDERS))
def test_van_der_pol_observed_order(method, vdp_reference):
    errors = [vdp_error(method, h, vdp_reference) for h in (0.01, 0.005, 0.0025)]
    observed = np.log2(errors[1] / errors[2])
    assert abs(observed - ORDERS[method]) < 0.05, (errors, observed)


def test_midpoint_and_heun_part_on_a_nonlinear_system():
    T = grid(0.02)
    sys = van_der_pol()
    mid = qc.input_output_response(sys, T, X0=X0_VDP, method="midpoint")
    heun = qc.input_output_response(sys, T, X0=X0_VDP, method="heun")
    difference = np.max(np.abs(mid.states - heun.states))
    assert 8.8e-4 < difference < 9.0e-4  # measured 8.895e-4
    # ... and agree on a linear one, with an input linear within each step
    lin = control.nlsys(
        lambda t, x, u, p: [x[1], -x[0] - 0.2 * x[1] + u[0]], None, inputs=1, states=2
    )
    U = np.sin(T)
    a = qc.input_output_response(lin, T, U, [1.0, 0.0], method="midpoint")
    b = qc.input_output_response(lin, T, U, [1.0, 0.0], method="heun")
    assert np.max(np.abs(a.states - b.states)) < 1e-13 * np.max(np.abs(a.states))


@pytest.mark.parametrize("method", list(ORDERS))
def test_linear_system_as_nlsys_equals_the_linear_response(method):
    ss = qc.quarter_car(road=True)
    A, B, C, D = (np.asarray(m) for m in (ss.A, ss.B, ss.C, ss.D))
    nl = control.nlsys(
        lambda t, x, u, p: A @ x + B @ u,
        lambda t, x, u, p: C @ x + D @ u,
        inputs=ss.input_labels,
        outputs=ss.output_labels,
        states=ss.state_labels,
        name="qc_nl",
    )
    T = grid(1e-3, 5.0)
    U = 0.05 * np.sin(2 * np.pi * 1.3 * T)
    X0 = [0.0, 0.0, 0.05, 0.0]
    ours = qc.input_output_response(nl, T, U, X0, method=method)
    lti = qc.forced_response(ss, T, U, X0, method=method)
    for a, b in ((ours.outputs, lti.outputs), (ours.states, lti.states)):
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(b))
    assert ours.output_labels == lti.output_labels and ours.nfev == lti.nfev


def test_params_are_honoured_as_in_control():
    def decay(t, x, u, params):
        return -params["k"] * x

    sys = control.nlsys(decay, None, states=1, name="decay", params={"k": 1.0})
    T = grid(0.01, 2.0)
    r = qc.input_output_response(sys, T, X0=1.0, params={"k": 3.0})
    # RK4's global error on x' = -3x: about t|λ|(h|λ|)^4/120 = 4e-8 (measured 2.5e-9)
    assert np.max(np.abs(r.states[0] - np.exp(-3 * T))) < 1e-7
    assert r.params == {"k": 3.0} and sys.params == {"k": 1.0}
    # without params, the system's own
    r1 = qc.input_output_response(sys, T, X0=1.0)
    assert np.max(np.abs(r1.states[0] - np.exp(-T))) < 1e-7
    # the same through the linear responses' front door, as in control
    r3 = qc.initial_response(sys, T, 1.0, params={"k": 3.0})
    np.testing.assert_array_equal(r3.states, r.states)


def _closed_loop():
    """A damped pendulum under a tanh-saturated PI controller, by control.interconnect."""
    plant = control.nlsys(
        lambda t, x, u, p: [x[1], -np.sin(x[0]) - p["c"] * x[1] + u[0]],
        lambda t, x, u, p: x[:1],
        inputs="u",
        outputs="y",
        states=["th", "om"],
        name="plant",
        params={"c": 0.1},
    )
    ctrl = control.nlsys(
        lambda t, x, u, p: [u[0] - u[1]],
        lambda t, x, u, p: [p["umax"] * np.tanh((p["kp"] * (u[0] - u[1]) + p["ki"] * x[0]) / 2)],
        inputs=["r", "y"],
        outputs="u",
        states=["z"],
        name="ctrl",
        params={"kp": 3.0, "ki": 1.0, "umax": 2.0},
    )
    return control.interconnect([plant, ctrl], inputs="r", outputs="y", name="cl")


def _closed_loop_reference(umax=2.0, r=lambda t: 0.5 + 0.1 * t, x0=(0.5, 0.0, 0.0)):
    def rhs(t, s):
        th, om, z = s
        r_t = r(t)
        u = umax * np.tanh((3.0 * (r_t - th) + 1.0 * z) / 2)
        return [om, -np.sin(th) - 0.1 * om + u, r_t - th]

    return solve_ivp(rhs, (0, 10), list(x0), **TIGHT).sol


@pytest.mark.slow
def test_interconnection_against_solve_ivp():
    cl = _closed_loop()
    assert isinstance(cl, control.InterconnectedSystem)
    reference = _closed_loop_reference()
    errors = []
    for h in (0.01, 0.005):
        T = grid(h)
        r = qc.input_output_response(cl, T, 0.5 + 0.1 * T, [0.5, 0.0, 0.0])
        ref = reference(T)
        errors.append(np.max(np.abs(r.states - ref)))
        assert np.max(np.abs(r.outputs - ref[0])) <= errors[-1]
    assert errors[0] < 2e-8  # C h^4 with C ~ 0.56: measured 5.6e-9
    assert abs(np.log2(errors[0] / errors[1]) - 4) < 0.05
    # params reach the subsystems, as control's interconnection passes them
    T = grid(0.01)
    stiff = qc.input_output_response(cl, T, 0.5 + 0.1 * T, [0.5, 0, 0], params={"umax": 0.5})
    loose = qc.input_output_response(cl, T, 0.5 + 0.1 * T, [0.5, 0, 0])
    assert np.max(np.abs(stiff.states - loose.states)) > 1e-2


def test_result_has_controls_layout():
    cl = _closed_loop()
    T = grid(0.05)
    U = 0.5 + 0.1 * T
    ours = qc.input_output_response(cl, T, U, [0.5, 0, 0], params={"umax": 2.0})
    theirs = control.input_output_response(cl, T, U, [0.5, 0, 0], params={"umax": 2.0})
    assert isinstance(ours, qc.FixedStepResponse)
    for name in (
        "title",
        "sysname",
        "output_labels",
        "input_labels",
        "state_labels",
        "params",
        "issiso",
        "ntraces",
        "trace_types",
        "squeeze",
        "transpose",
        "return_x",
    ):
        assert getattr(ours, name) == getattr(theirs, name), name
    for name in ("time", "outputs", "states", "inputs"):
        assert np.shape(getattr(ours, name)) == np.shape(getattr(theirs, name)), name
    np.testing.assert_array_equal(ours.inputs, theirs.inputs)
    assert ours.method.name == "rk4" and ours.h == pytest.approx(0.05)
    assert ours.steps == T.size - 1 and ours.nfev == 4 * ours.steps
    # tuple unpacking, transpose, a list of systems: as control
    t, y, x = qc.input_output_response(cl, T, U, [0.5, 0, 0], return_x=True, transpose=True)
    assert y.shape == (T.size,) and x.shape == (T.size, 3)
    both = qc.input_output_response([cl, van_der_pol()], T, U)
    assert isinstance(both, control.TimeResponseList) and len(both) == 2


def test_forced_and_step_responses_route_nonlinear_systems_as_control():
    cl = _closed_loop()
    T = grid(0.05)
    forced = qc.forced_response(cl, T, 0.5 + 0.1 * T, [0.5, 0, 0])
    io = qc.input_output_response(cl, T, 0.5 + 0.1 * T, [0.5, 0, 0])
    np.testing.assert_array_equal(forced.states, io.states)
    assert forced.title == control.forced_response(cl, T, 0.5 + 0.1 * T, [0.5, 0, 0]).title
    step = qc.step_response(cl, T)
    assert step.title == "Step response for cl" and step.outputs.shape == (T.size,)
    # control's own answer (RK45, rtol 1e-3) is 0.046 off here: against solve_ivp,
    # RK4 at h = 0.05 is within C h^4 ~ 0.56 * 0.05^4 = 3.5e-6 (measured 3.1e-6)
    ref = _closed_loop_reference(r=lambda t: 1.0, x0=(0.0, 0.0, 0.0))(T)
    assert np.max(np.abs(step.states - ref)) < 1e-5
    with pytest.raises(ValueError, match="must be LTI"):  # as control
        qc.impulse_response(cl, T)


def test_automatic_step_from_the_linearisation():
    sys = van_der_pol()
    r = qc.initial_response(sys, 10.0, X0_VDP)  # control's grid: 50 points
    assert r.t.size == 50 and "linearisation at the initial point" in r.step_rule
    lam = np.abs(np.linalg.eigvals(control.linearize(sys, X0_VDP, None).A)).max()
    assert r.h * lam <= 0.1 * (1 + 1e-9)  # auto_step's accuracy rule for RK4
    assert r.max_stable_step is not None
    with pytest.raises(ValueError, match="non-LTI"):  # control's own refusal: no T
        qc.initial_response(sys, None, X0_VDP)


def test_divergence_makes_success_false():
    blow_up = control.nlsys(lambda t, x, u, p: x**2, None, states=1, name="blow")
    T = grid(0.01, 2.0)  # x' = x², x(0) = 1: x = 1/(1 - t), infinite at t = 1
    with pytest.warns(DivergenceWarning, match="non-finite") as record:
        r = qc.input_output_response(blow_up, T, X0=1.0)
    # ours alone: not also numpy's overflow from the step-stability check that
    # follows along the diverged trajectory
    assert [w.category for w in record] == [DivergenceWarning]
    assert not r.success and "non-finite" in r.message
    assert r.t[-1] < 1.1 and np.all(np.isfinite(r.states))


def test_evaluation_times_and_max_step():
    sys = van_der_pol()
    T = grid(0.1)
    fine = qc.input_output_response(sys, T, X0=X0_VDP, substeps=10)
    capped = qc.input_output_response(sys, T, X0=X0_VDP, solve_ivp_kwargs={"max_step": 0.01})
    assert capped.substeps == 10
    np.testing.assert_allclose(capped.states, fine.states, rtol=0, atol=1e-15)
    every = qc.input_output_response(sys, T, X0=X0_VDP, substeps=10, t_eval=None)
    assert every.t.size == 1001 and np.max(np.abs(every.states[:, ::10] - fine.states)) < 1e-14
    te = [0.0, 0.35, 2.0, 7.77]
    some = qc.input_output_response(sys, T, X0=X0_VDP, substeps=10, evaluation_times=te)
    np.testing.assert_array_equal(some.t, te)
    reference = solve_ivp(lambda t, x: vdp_rhs(t, x, None, {"mu": 1.0}), (0, 10), X0_VDP, **TIGHT)
    # h <= 0.01: C h^4 ~ 5e-8 (see the module docstring)
    assert np.max(np.abs(some.states - reference.sol(te))) < 1e-7


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(method="RK45"), "solve_ivp method"),
        (dict(solve_ivp_method="LSODA"), "does not call solve_ivp"),
        (dict(solve_ivp_kwargs={"rtol": 1e-6}), "rtol.*do not apply to a fixed-step"),
        (dict(solve_ivp_kwargs={"method": "BDF"}), "solve_ivp method"),
        (dict(solve_ivp_kwargs={"max_step": -1.0}), r"max_step .*must be a finite number > 0 s"),
        (dict(evaluation_times=[0.0, 20.0]), "within"),
        (dict(X0=[np.nan, 0.0]), "X0 must be finite"),
    ],
)
def test_what_does_not_apply_is_refused_clearly(kwargs, match):
    kwargs.setdefault("X0", X0_VDP)
    with pytest.raises(ValueError, match=match):
        qc.input_output_response(van_der_pol(), grid(0.1), **kwargs)


def test_refusals_as_control():
    with pytest.raises(ValueError, match="T must be an array"):
        qc.input_output_response(van_der_pol(), None, X0=X0_VDP)
    with pytest.raises(TypeError, match="not valid"):
        qc.input_output_response(control.tf([1], [1, 1]), grid(0.1))
    with pytest.raises(TypeError, match="unrecognized keyword"):
        qc.input_output_response(van_der_pol(), grid(0.1), bogus=1)


def test_discrete_and_static_systems_as_control():
    logistic = control.nlsys(
        lambda t, x, u, p: 3.2 * x * (1 - x), None, states=1, dt=1, name="logistic"
    )
    T = np.arange(0, 20)
    ours = qc.input_output_response(logistic, T, X0=0.3)
    np.testing.assert_array_equal(
        ours.states, control.input_output_response(logistic, T, X0=0.3).states
    )
    assert ours.method is None and "difference equation" in ours.note
    square = control.nlsys(None, lambda t, x, u, p: u**2, inputs=1, outputs=1, name="square")
    T = grid(0.1, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        static = qc.input_output_response(square, T, T)
    np.testing.assert_allclose(static.outputs, T**2, rtol=0, atol=1e-15)
    assert static.nfev == 0 and "no states" in static.note


# ---------------------------------------------------------------- the interconnection fast path


def _benchmark_module(name: str):
    """A module of benchmarks/ (beside run.py, not a package), loaded by its path."""
    path = Path(__file__).resolve().parent.parent / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"benchmarks_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# The car and clipped skyhook benchmarks/run.py times: the fast path is checked on
# the very system whose speed-up benchmarks/RESULTS.md reports.
_skyhook_car = _benchmark_module("skyhook_car")
_car_with_velocities, _car_and_skyhook = (
    _skyhook_car.car_with_velocities,
    _skyhook_car.car_with_skyhook,
)


def test_fast_path_equals_the_rhs_path_to_rounding():
    from qc_control.numerics.interconnect import compile_interconnect

    cl = _car_and_skyhook()
    T = grid(1e-3, 2.0)
    zr = qc.road.iso8608(T, "C", 20.0, seed=3)
    fast = qc.input_output_response(cl, T, zr, [0.1, 0, 0.02, 0], params={"c_sky": 2500.0})
    slow = qc.input_output_response(
        cl, T, zr, [0.1, 0, 0.02, 0], params={"c_sky": 2500.0}, fast=False
    )
    # the same sums in another order: a few ulps per stage, grown by the dynamics
    for a, b in ((fast.states, slow.states), (fast.outputs, slow.outputs)):
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(b))
    assert compile_interconnect(cl) is not None and fast.nfev == slow.nfev
    # params reach the controller on the fast path too
    other = qc.input_output_response(cl, T, zr, [0.1, 0, 0.02, 0])
    assert np.max(np.abs(other.states - fast.states)) > 1e-4


def test_fast_path_with_stateful_subsystems_and_events():
    cl = _closed_loop()  # two nlsys subsystems with states, tanh saturation
    T = grid(0.01)
    U = 0.5 + 0.1 * T
    fast = qc.input_output_response(cl, T, U, [0.5, 0, 0])
    slow = qc.input_output_response(cl, T, U, [0.5, 0, 0], fast=False)
    np.testing.assert_allclose(fast.states, slow.states, rtol=0, atol=1e-13)
    np.testing.assert_allclose(fast.outputs, slow.outputs, rtol=0, atol=1e-13)
    # an event function on the interconnection: theta crossing 1 rad, located the same way
    ev = dict(events=lambda t, x, u, p: x[0] - 1.0)
    a = qc.input_output_response(cl, T, U, [0.5, 0, 0], **ev)
    b = qc.input_output_response(cl, T, U, [0.5, 0, 0], fast=False, **ev)
    assert a.t_events.size >= 1
    np.testing.assert_allclose(a.t_events, b.t_events, rtol=0, atol=1e-12)


def test_algebraic_loop_falls_back_to_control():
    from qc_control.numerics.interconnect import compile_interconnect

    # u = -y with y = u + x: a direct loop through a nonlinear block, which control iterates
    plant = control.nlsys(
        lambda t, x, u, p: -x + u, lambda t, x, u, p: x, inputs=1, outputs=1, states=1, name="p"
    )
    gain = control.nlsys(None, lambda t, x, u, p: 0.5 * u, inputs=1, outputs=1, name="k")
    loop = control.nlsys(None, lambda t, x, u, p: u, inputs=1, outputs=1, name="l")
    cl = control.interconnect(
        [plant, gain, loop],
        connections=[["k.u[0]", "l.y[0]"], ["l.u[0]", "k.y[0]"], ["p.u[0]", "k.y[0]"]],
        inplist=[],
        outlist=["p.y[0]"],
    )
    assert compile_interconnect(cl) is None


def test_stage_times_are_the_steppers_own():
    from qc_control.numerics.integrate import stage_times

    seen = []

    def f(t, x):
        seen.append(t)
        return -x

    for T, substeps in ((grid(0.1, 1.0), 1), (np.array([0.0, 0.1, 0.35, 1.0]), 3)):
        seen.clear()
        qc.integrate(f, T, [1.0], "rk4", substeps=substeps)
        assert np.array_equal(np.array(seen), stage_times(T, "rk4", substeps=substeps).ravel())


# ------------------------------ fused steps (qc_control.numerics.interconnect.FusedSteps)
#
# A linear plant closed by static nonlinear subsystems is stepped a whole step at a
# time: the stage values come from precomputed matrices (A_l, B_lr of FusedSteps), not
# from the stage-by-stage formula. The two are the same sums in another order, so the
# fused run equals the generic one (`fast=False`, `sys._rhs` per stage) to rounding:
# measured 2.4e-14 of the largest state over 10 s (car + clipped skyhook, every method);
# the bound 1e-12 relative leaves room for the growth of rounding over the run.

RK38 = qc.ButcherTableau(  # Kutta's 3/8 rule: a_31, a_41, a_42 non-zero, a negative entry
    "rk38",
    a=[[0, 0, 0, 0], [1 / 3, 0, 0, 0], [-1 / 3, 1, 0, 0], [1, -1, 1, 0]],
    b=[1 / 8, 3 / 8, 3 / 8, 1 / 8],
)


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("method", ["euler", "midpoint", "heun", "rk4", RK38])
def test_fused_steps_equal_the_rhs_path_for_every_tableau(method, monkeypatch):
    cl = _car_and_skyhook()
    sky = cl.syslist[1]
    law, calls, checking = sky.outfcn, [0], [False]

    def counted(t, x, u, p):
        calls[0] += 0 if checking[0] else 1  # the stepping's calls, not the stability check's
        return law(t, x, u, p)

    sky.outfcn = counted
    check = iosys._beyond_stability_along

    def uncounted(*args):
        checking[0] = True
        try:
            return check(*args)
        finally:
            checking[0] = False

    monkeypatch.setattr(iosys, "_beyond_stability_along", uncounted)
    T = grid(1e-3, 2.0)
    zr = qc.road.iso8608(T, "C", 20.0, seed=3)
    x0, params = [0.1, 0, 0.02, 0], {"c_sky": 2500.0}
    cl._update_params(params)
    cl._out(0.0, np.array(x0, dtype=float), zr[:1])  # as input_output_response sizes y
    sizing = calls[0]
    calls[0] = 0
    fast = qc.input_output_response(cl, T, zr, x0, params=params, method=method)
    fused_calls = calls[0]
    slow = qc.input_output_response(cl, T, zr, x0, params=params, method=method, fast=False)
    assert _rel(fast.states, slow.states) <= 1e-12
    assert _rel(fast.outputs, slow.outputs) <= 1e-12
    assert fast.nfev == slow.nfev == (T.size - 1) * fast.method.stages
    # the controller runs once per stage, once for the last sample's output and as often
    # as control's _out calls it to size the output: the other samples' outputs reuse the
    # first stage's value, which is the controller at the sample itself
    assert fused_calls == fast.nfev + 1 + sizing


@pytest.mark.parametrize(
    "options",
    [
        dict(substeps=3),  # every third step kept
        dict(substeps=3, evaluation_times=None),  # every step returned
        dict(evaluation_times=np.linspace(0.0, 1.0, 126)[1::5]),  # points of the grid
    ],
    ids=["substeps", "every-step", "evaluation-times"],
)
def test_fused_steps_with_substeps_and_evaluation_times(options):
    cl = _car_and_skyhook()
    T = grid(4e-3, 1.0)
    zr = qc.road.iso8608(T, "C", 20.0, seed=5)
    fast = qc.input_output_response(cl, T, zr, [0.1, 0, 0.02, 0], **options)
    slow = qc.input_output_response(cl, T, zr, [0.1, 0, 0.02, 0], fast=False, **options)
    np.testing.assert_array_equal(fast.t, slow.t)
    assert _rel(fast.states, slow.states) <= 1e-12  # measured 2.6e-14 at most
    assert _rel(fast.outputs, slow.outputs) <= 1e-12
    assert fast.nfev == slow.nfev


@pytest.mark.parametrize(
    "wrap",
    [list, np.array, float, lambda v: np.array([[v]]), lambda v: np.float64(v)],
    ids=["list", "array", "float", "array-1x1", "float64"],
)
def test_fused_steps_take_any_one_output_control_takes(wrap):
    # control reads an output function's value as asarray(r).reshape(-1): a list, an
    # array of any shape with one element, a number. The fused steps read the value
    # directly in the common cases; each must give the sys._rhs path's run (to rounding).
    ss, car = _car_with_velocities()

    def law(t, x, u, p):
        value = -3000.0 * u[0] * np.tanh(50.0 * u[0] * (u[0] - u[1]))
        return wrap([value]) if wrap is list else wrap(value)

    ctrl = control.nlsys(None, law, inputs=["vs_m", "vu_m"], outputs=["fa"], name="law")
    cl = control.interconnect([car, ctrl], inputs="zr", outputs=ss.output_labels)
    T = grid(1e-3, 0.5)
    zr = qc.road.iso8608(T, "C", 20.0, seed=6)
    fast = qc.input_output_response(cl, T, zr, [0.1, 0, 0.02, 0])
    slow = qc.input_output_response(cl, T, zr, [0.1, 0, 0.02, 0], fast=False)
    assert _rel(fast.states, slow.states) <= 1e-12
    assert _rel(fast.outputs, slow.outputs) <= 1e-12


def _car_sensor_law():
    """The seed car under two chained static nlsys blocks (a sensor feeding a smooth law)."""
    ss, car = _car_with_velocities()
    sensor = control.nlsys(
        None,
        lambda t, x, u, p: [u[0], u[0] - u[1]],
        inputs=["vs_m", "vu_m"],
        outputs=["vs", "vrel"],
        name="sensor",
    )
    law = control.nlsys(
        None,
        lambda t, x, u, p: [-p["fmax"] * np.tanh((p["c_sky"] * u[0] + p["c"] * u[1]) / p["fmax"])],
        inputs=["vs", "vrel"],
        outputs=["fa"],
        name="law",
        params={"c_sky": 3000.0, "c": 500.0, "fmax": 2000.0},
    )
    outputs = [*ss.output_labels, "fa", "vrel"]
    return control.interconnect([car, sensor, law], inputs="zr", outputs=outputs, name="cl3")


@pytest.mark.slow
def test_fused_steps_with_chained_static_subsystems_against_control():
    # Two static blocks, the second fed by the first (several outputs: the general loop),
    # the controller smooth (tanh), so that solve_ivp at tight tolerance is a reference.
    cl = _car_sensor_law()
    x0 = [0.0, 0.0, 0.05, 0.0]  # body released from 5 cm, no road: a smooth solution
    T = grid(1e-3, 2.0)
    zr = qc.road.iso8608(T, "C", 20.0, seed=4)
    fast = qc.input_output_response(cl, T, zr, x0, params={"c": 800.0})
    slow = qc.input_output_response(cl, T, zr, x0, params={"c": 800.0}, fast=False)
    assert _rel(fast.states, slow.states) <= 1e-12  # measured 5e-15
    assert _rel(fast.outputs, slow.outputs) <= 1e-12
    # control's own solution, DOP853 at rtol = 1e-12, atol = 1e-14: within 5.1e-12 of the
    # same at rtol = 1e-13, atol = 1e-15. RK4's error is C h^4: measured 1.32e-8 at
    # h = 2 ms and 8.2e-10 at 1 ms (ratio 16.1, order 4.01); bounds 2x those.
    ref = control.input_output_response(
        cl,
        T,
        0.0,
        x0,
        solve_ivp_method="DOP853",
        solve_ivp_kwargs=dict(rtol=1e-12, atol=1e-14),
    )
    errors = []
    for every in (2, 1):
        r = qc.input_output_response(cl, T[::every], 0.0, x0)
        errors.append(float(np.max(np.abs(r.states - ref.states[:, ::every]))))
        # outputs from the states and the kept controller values: the force (up to 572 N)
        # within the same relative error as the states (measured 1.6e-6 N at 1 ms)
        out_err = np.max(np.abs(r.outputs - ref.outputs[:, ::every]), axis=1)
        assert np.all(out_err <= 1e-6 * np.max(np.abs(ref.outputs), axis=1) + 1e-12)
    assert errors[0] < 2.6e-8 and errors[1] < 1.7e-9
    assert abs(np.log2(errors[0] / errors[1]) - 4) < 0.1


def test_fused_steps_cut_a_divergent_run_as_integrate_does():
    # x' = u, u = x^2 (a static nlsys): x = 1/(1 - t), infinite at t = 1. control's own
    # interconnection refuses the non-finite values ("algebraic loop detected"), so the
    # reference is qc.integrate on x' = x^2 itself: the same RK4 steps, cut at the same
    # sample, equal to rounding (1e-12 relative, as above) while x is moderate (t <= 0.9,
    # x <= 10). Near the pole each step multiplies a rounding difference by about
    # 1 + 2hx (x = 1e13 at the last samples), so there only the cut is compared.
    plant = control.ss(0.0, 1.0, 1.0, 0.0, inputs="u", outputs="y", states="x", name="p")
    square = control.nlsys(None, lambda t, x, u, p: u**2, inputs="y", outputs="u", name="sq")
    cl = control.interconnect([plant, square], inplist=[], outlist="y", name="blow")
    T = grid(0.01, 2.0)
    with pytest.warns(DivergenceWarning, match="non-finite"):
        r = qc.input_output_response(cl, T, 0.0, 1.0)
    with pytest.warns(DivergenceWarning, match="non-finite"):
        ref = qc.integrate(lambda t, x: x**2, T, [1.0], "rk4")
    assert not r.success and ref.message in r.message
    assert r.t.size == ref.t.size and 1.0 < r.t[-1] < 1.1
    x, y = np.asarray(r.states).reshape(-1), np.asarray(r.outputs).reshape(-1)
    early = r.t <= 0.9
    np.testing.assert_allclose(x[early], ref.x[0, early], rtol=1e-12, atol=0)
    assert np.all(np.isfinite(x)) and np.array_equal(y, x)  # y = x, from the states


def _wired(plant, ctrl):
    """``plant`` under ``ctrl``, with outputs that name a subsystem input."""
    return control.interconnect(
        [plant, ctrl],
        connections=[["ctrl.y", "plant.y"], ["plant.u", "ctrl.u"]],
        inplist=["ctrl.r"],
        outlist=["plant.y", "plant.u", "ctrl.r"],
        name="cl",
    )


@pytest.mark.parametrize("fused", [True, False])
def test_outputs_that_name_subsystem_inputs_are_controls_outputs(fused):
    """An interconnection's outputs may name subsystem inputs (the input
    columns of control's ``output_map``). At qc's own states and inputs they
    equal python-control's public ``sys.output`` to rounding (1e-12 relative:
    the same sums in another order), for a linear plant under a static
    controller (whole steps fused) and under one with a state (the compiled
    right-hand side)."""
    plant = control.ss(
        [[0.0, 1.0], [-4.0, -0.4]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]],
        inputs="u", outputs="y", name="plant",
    )  # fmt: skip
    ctrl = control.nlsys(
        None if fused else (lambda t, x, u, p: [u[0] - u[1]]),
        lambda t, x, u, p: [-np.tanh(3.0 * (u[0] - u[1]) + (0.0 if fused else x[0]))],
        inputs=["r", "y"],
        outputs="u",
        states=None if fused else ["z"],
        name="ctrl",
    )
    cl = _wired(plant, ctrl)
    x0 = [0.5, 0.0] if fused else [0.5, 0.0, 0.0]
    T = grid(0.01, 2.0)
    r = qc.input_output_response(cl, T, 0.5 + 0.1 * T, x0)
    theirs = np.array([cl.output(t, r.states[:, k], r.inputs[:, k]) for k, t in enumerate(T)]).T
    np.testing.assert_allclose(r.outputs, theirs, rtol=1e-12, atol=1e-14)
