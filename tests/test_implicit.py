"""Implicit Runge–Kutta tableaus: stability functions, orders, the LTI engine, Newton.

Every check is against a reference computed apart from the code under test:
the Padé approximants of e^z in closed form (Hairer & Wanner, *Solving ODEs
II*, §IV.3, eq. 3.30), scipy's ``solve_ivp`` at rtol 1e-12, the rational
R(hA) formed from its closed-form numerator and denominator, and the
closed-form numerical eigenvalues of backward Euler and the trapezoidal rule.
"""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.numerics.integrate import ConvergenceWarning, integrate
from qc_control.numerics.lti import step_matrices
from qc_control.numerics.methods import TABLEAUS, ButcherTableau
from qc_control.numerics.stability import max_stable_step, numerical_modes, stability_function
from qc_control.numerics.stepper import ImplicitSteps, NewtonFailure

IMPLICIT = [
    "backward_euler",
    "implicit_midpoint",
    "trapezoidal",
    "gauss2",
    "gauss3",
    "radau2",
    "radau3",
    "sdirk2",
]
GAMMA = 1 - math.sqrt(2) / 2


def pade(k: int, j: int):
    """The (k, j) Padé approximant of e^z: numerator and denominator, lowest power first.

    ``P(z) = Σ_i (k+j-i)! k! / ((k+j)! i! (k-i)!) z^i`` and ``Q(z) = P_{j,k}(-z)``
    (HW II, §IV.3, eq. 3.30).
    """

    def part(k, j, sign):
        return [
            sign**i
            * math.factorial(k + j - i)
            * math.factorial(k)
            / (math.factorial(k + j) * math.factorial(i) * math.factorial(k - i))
            for i in range(k + 1)
        ]

    return part(k, j, 1), part(j, k, -1)


#: Each tableau's R = P/Q in closed form: the Padé approximants of HW II, Table 3.1
#: (Gauss: diagonal (s, s); Radau IIA: (s-1, s)), and for SDIRK with γ = 1 - √2/2
#: R = (1 + (1 - 2γ) z)/(1 - γz)² (HW II, §IV.6, from its tableau by hand).
CLOSED_FORM = {
    "backward_euler": pade(0, 1),
    "implicit_midpoint": pade(1, 1),
    "trapezoidal": pade(1, 1),
    "gauss2": pade(2, 2),
    "gauss3": pade(3, 3),
    "radau2": pade(1, 2),
    "radau3": pade(2, 3),
    "sdirk2": ([1, 1 - 2 * GAMMA], [1, -2 * GAMMA, GAMMA**2]),
}


def test_pade_helper_reproduces_the_printed_table():
    # HW II, Table 3.1: the (1, 2) and (2, 2) entries as printed
    assert pade(1, 2) == (pytest.approx([1, 1 / 3]), pytest.approx([1, -2 / 3, 1 / 6]))
    assert pade(2, 2) == (pytest.approx([1, 1 / 2, 1 / 12]), pytest.approx([1, -1 / 2, 1 / 12]))


@pytest.mark.parametrize("name", IMPLICIT)
def test_stability_function_is_the_closed_form(name):
    R = stability_function(name)
    num, den = CLOSED_FORM[name]
    # coefficients from determinants of 3x3 matrices of O(1) entries: a few
    # eps of rounding; 1e-13 absolute leaves two orders of margin
    np.testing.assert_allclose(R.numerator.coef, num, rtol=0, atol=1e-13)
    np.testing.assert_allclose(R.denominator.coef, den, rtol=0, atol=1e-13)
    z = np.array([-0.3 + 0.2j, -2.0, 1j, -50 + 7j, 0.1])
    expected = np.polynomial.polynomial.polyval(z, num) / np.polynomial.polynomial.polyval(z, den)
    np.testing.assert_allclose(R(z), expected, rtol=1e-12)
    assert TABLEAUS[name].implicit and not R.is_polynomial


def test_explicit_methods_keep_their_polynomial():
    for name in ("euler", "midpoint", "heun", "rk4"):
        R = stability_function(name)
        assert R.is_polynomial and not TABLEAUS[name].implicit
        assert not R.a_stable and R.at_infinity == math.inf
    with pytest.raises(ValueError, match="rational"):
        _ = stability_function("gauss2").coef


#: (A-stable, L-stable, R(∞)): HW II, §IV.3 and Table 5.13 of §IV.5
STABILITY = {
    "backward_euler": (True, True, 0.0),
    "implicit_midpoint": (True, False, -1.0),
    "trapezoidal": (True, False, -1.0),
    "gauss2": (True, False, 1.0),
    "gauss3": (True, False, -1.0),
    "radau2": (True, True, 0.0),
    "radau3": (True, True, 0.0),
    "sdirk2": (True, True, 0.0),
}


@pytest.mark.parametrize("name", IMPLICIT)
def test_a_and_l_stability_on_the_axis_and_at_infinity(name):
    a_stable, l_stable, at_inf = STABILITY[name]
    R = stability_function(name)
    assert R.a_stable is a_stable and R.l_stable is l_stable
    assert R.at_infinity == pytest.approx(at_inf, abs=1e-12)
    # on the imaginary axis |R(iy)| <= 1 (= 1 for Gauss and the trapezoidal rule,
    # whose E-polynomial vanishes): rounding of R at |z| up to 1e6 is ~1e-12
    y = np.concatenate([-np.logspace(-3, 6, 200), np.logspace(-3, 6, 200)])
    mod = np.abs(R(1j * y))
    assert np.all(mod <= 1 + 1e-12)
    if not l_stable and name != "backward_euler":
        np.testing.assert_allclose(mod, 1.0, rtol=1e-12)
    # far into the left half-plane R tends to R(∞): within 1e-6 at |z| = 1e8
    for z in (-1e8, -1e8 + 1e7j, 1e8j):
        assert abs(R(z) - at_inf) <= 1e-6 * (1 + abs(at_inf))
    # and the left half-plane itself: a grid of it never amplifies
    x = -np.logspace(-3, 4, 60)
    Z = x[None, :] + 1j * np.concatenate([[0], np.logspace(-3, 4, 60)])[:, None]
    assert np.all(np.abs(R(Z)) <= 1 + 1e-12)


def test_an_implicit_method_that_is_not_a_stable():
    # the θ-method with θ = 1/4: R = (1 + 3z/4)/(1 - z/4), |R(∞)| = 3
    theta = ButcherTableau("theta", a=[[0, 0], [0.75, 0.25]], b=[0.75, 0.25], c=[0, 1])
    assert theta.implicit and theta.order == 1
    R = stability_function(theta)
    assert not R.a_stable and R.at_infinity == pytest.approx(-3.0)
    # on x' = -x: |1 - 3h/4| = 1 + h/4 at h = 4, the step limit in closed form
    assert max_stable_step(theta, [-1.0]) == pytest.approx(4.0, rel=1e-12)
    assert max_stable_step(theta, [-10.0]) == pytest.approx(0.4, rel=1e-12)


def seed_system():
    return qc.quarter_car(road=True)


@pytest.mark.parametrize("name", IMPLICIT)
def test_a_stable_methods_have_no_step_limit_on_a_stable_system(name):
    sys = seed_system()
    assert max_stable_step(name, sys) == math.inf
    # an undamped mode too: the imaginary axis is inside every region here
    assert max_stable_step(name, [10j, -10j]) == math.inf
    # a system that grows by itself is the system's growth, as for explicit methods
    assert max_stable_step(name, [1.0]) == 0.0


# ---------------------------------------------------------------- orders


def pendulum(t, x):
    """A forced nonlinear pendulum: smooth, with a time-dependent term."""
    return np.array([x[1], -math.sin(x[0]) - 0.2 * x[1] + 0.5 * math.cos(1.3 * t)])


T_END = 2.0


@pytest.fixture(scope="module")
def pendulum_reference():
    sol = solve_ivp(pendulum, (0, T_END), [1.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14)
    return sol.y[:, -1]


#: steps (h, h/2) in the asymptotic range, above the reference's ~1e-12 and the
#: Newton tolerance's 1e-12 relative per step: the high orders need the large steps
ORDER_STEPS = {
    "backward_euler": (0.01, 0.005),
    "implicit_midpoint": (0.02, 0.01),
    "trapezoidal": (0.02, 0.01),
    "gauss2": (0.1, 0.05),
    "gauss3": (0.4, 0.2),
    "radau2": (0.05, 0.025),
    "radau3": (0.2, 0.1),
    "sdirk2": (0.02, 0.01),
}


@pytest.mark.parametrize("name", IMPLICIT)
def test_observed_order_on_a_nonlinear_problem(name, pendulum_reference):
    tab = TABLEAUS[name]
    errors = []
    for h in ORDER_STEPS[name]:
        T = np.linspace(0, T_END, round(T_END / h) + 1)
        sol = integrate(pendulum, T, [1.0, 0.0], tab)
        assert sol.success, sol.message
        errors.append(np.max(np.abs(sol.x[:, -1] - pendulum_reference)))
    observed = math.log2(errors[0] / errors[1])
    # the bar: within 0.1 of the order the tableau claims
    assert observed == pytest.approx(tab.order, abs=0.1), (errors, observed)
    # and well above the reference's own error, so the ratio is the method's
    assert errors[1] > 1e-10


def test_orders_come_from_the_trees():
    expected = {"backward_euler": 1, "implicit_midpoint": 2, "trapezoidal": 2, "gauss2": 4}
    expected.update({"gauss3": 6, "radau2": 3, "radau3": 5, "sdirk2": 2})
    assert {name: TABLEAUS[name].order for name in IMPLICIT} == expected
    with pytest.raises(ValueError, match="implicit method with 1 stages has order at most 2"):
        ButcherTableau("bad", a=[[0.5]], b=[1.0], c=[0.5], order=3)


# ---------------------------------------------------------------- linear systems


@pytest.mark.parametrize("name", IMPLICIT)
def test_step_map_is_the_rational_function_of_hA(name):
    sys = seed_system()
    A, B = np.asarray(sys.A), np.asarray(sys.B)
    h = 0.05
    phi, g0, g1 = step_matrices(TABLEAUS[name], A, B, h)
    num, den = CLOSED_FORM[name]

    def poly(coef):
        return sum(c * np.linalg.matrix_power(h * A, k) for k, c in enumerate(coef))

    expected = np.linalg.solve(poly(den), poly(num))  # P and Q commute: Q⁻¹P = PQ⁻¹
    # h|λ|max ≈ 1.3: a solve with a condition number of a few; 1e-12 relative
    np.testing.assert_allclose(phi, expected, rtol=1e-12, atol=1e-13)
    # the input gains: a step from rest with u going 1 -> 0 isolates Γ0
    step = qc.forced_response(sys, [0.0, h], [1.0, 0.0], 0.0, method=name, engine="generic")
    np.testing.assert_allclose(g0[:, 0], step.states[:, 1], rtol=1e-12, atol=1e-16)


@pytest.mark.parametrize("name", IMPLICIT)
def test_lti_engine_equals_stepping(name):
    sys = seed_system()
    T = np.linspace(0, 2, 401)
    road = 0.05 * np.sin(2 * np.pi * 1.5 * T) * (T > 0.2)
    x0 = [0.1, -0.2, 0.01, 0.0]
    lti = qc.forced_response(sys, T, road, x0, method=name, engine="lti", return_states=True)
    gen = qc.forced_response(sys, T, road, x0, method=name, engine="generic", return_states=True)
    assert lti.success and gen.success
    # the engine's powers of Φ against steps that solve the linear stage equations
    # with the factors of I - h a ⊗ A: rounding of 400 steps, far below 1e-12 of
    # the states' size
    scale = np.max(np.abs(gen.states), axis=1, keepdims=True)
    assert np.max(np.abs(lti.states - gen.states) / scale) < 1e-12
    # one solve per step: s evaluations of f, as the engine counts them
    assert gen.nfev == lti.nfev == TABLEAUS[name].stages * (T.size - 1)


@pytest.mark.parametrize("name", IMPLICIT)
def test_a_linear_right_hand_side_is_solved_as_newton_solves_it(name):
    """``ImplicitSteps(linear=True)``: one linear solve per step, against the simplified
    Newton iteration run to convergence on the same affine f, and both against
    solve_ivp. The stage equations are linear, so the two differ by the Newton
    iteration's later corrections, rounding: 1e-12 of the states' size."""
    A = np.array([[0.0, 1.0], [-400.0, -4.0]])  # a 3.2 Hz mode, ζ = 0.1

    def f(t, x):
        return A @ x + np.array([0.0, 100.0 * math.sin(2 * math.pi * 1.5 * t)])

    T = np.linspace(0, 1, 201)
    x0 = np.array([0.01, 0.0])
    runs = {}
    for linear in (True, False):
        steps = ImplicitSteps(TABLEAUS[name], T.tolist(), 2, 0.005, lambda t, x: A, linear)
        out = np.empty((T.size, 2))
        out[0] = x0
        steps.run(f, x0, out, 0, T.size - 1)
        runs[linear] = (out, steps)
    (one, solved), (newton, iterated) = runs[True], runs[False]
    scale = np.max(np.abs(newton), axis=0)
    assert np.max(np.abs(one - newton) / scale) < 1e-12
    assert solved.iterations == 400 and solved.nfev == 400 * TABLEAUS[name].stages
    assert iterated.iterations > solved.iterations  # Newton confirms with a second pass
    # against solve_ivp at rtol 1e-12: the method's own error at its order p, below
    # 2 (h|λ|)^p of the response at h|λ| = 0.05 (measured 0.07 for backward Euler,
    # 6e-4 for the second-order ones, down to 3.5e-11 for gauss3)
    exact = solve_ivp(f, (0, 1), x0, t_eval=T, rtol=1e-12, atol=1e-15, method="DOP853").y.T
    h_lambda = 0.0025 * np.abs(np.linalg.eigvals(A)).max()
    assert np.max(np.abs(one - exact) / scale) < 2 * h_lambda ** TABLEAUS[name].order


def test_a_linear_step_needs_the_matrix_and_refuses_an_overflow():
    with pytest.raises(ValueError, match="needs jac"):
        ImplicitSteps(TABLEAUS["radau3"], [0.0, 1.0], linear=True)
    steps = ImplicitSteps(TABLEAUS["radau3"], [], jac=lambda t, x: np.array([[1e10]]), linear=True)
    # integrate's blocks step under np.errstate too: an overflow is reported, not warned
    with (
        pytest.raises(NewtonFailure, match="non-finite"),
        np.errstate(over="ignore", invalid="ignore"),
    ):
        steps.step(lambda t, x: 1e10 * x, 0.0, np.array([1e308]), 1.0)


def test_implicit_forced_response_converges_to_the_exact_one():
    sys = seed_system()
    T = np.linspace(0, 2, 2001)
    road = 0.05 * np.sin(2 * np.pi * 1.5 * T)
    exact = control.forced_response(sys, T, road).outputs
    scale = np.max(np.abs(exact), axis=1, keepdims=True)
    # gauss3 at h = 1 ms: error ~ (h|λ|)^6 ~ 1e-13 relative per unit time (measured
    # 8e-14); the linear interpolation of the input is exact in both; 1e-11 is 100x above
    resp = qc.forced_response(sys, T, road, method="gauss3")
    assert np.max(np.abs(resp.outputs - exact) / scale) < 1e-11


# ---------------------------------------------------------------- numerical modes


@pytest.mark.parametrize("h", [0.001, 0.01, 0.1])
def test_backward_euler_adds_damping_in_closed_form(h):
    omega, sigma = 20.0, 1.5
    lam = complex(-sigma, omega)
    nm = numerical_modes("backward_euler", h, [lam, lam.conjugate(), 1j * omega, -1j * omega])
    # R = 1/(1 - hλ): λ_h = -ln(1 - hλ)/h, so σ_h = ln|1 - hλ|/h, ω_h = -arg(1 - hλ)/h
    for name, lam_ in (("mode 1", 1j * omega), ("mode 2", lam)):
        row = nm.loc[name]
        lam_h = -np.log(1 - h * lam_) / h
        assert row["sigma_h [1/s]"] == pytest.approx(-lam_h.real, rel=1e-12)
        assert row["fd_h [Hz]"] == pytest.approx(lam_h.imag / (2 * math.pi), rel=1e-12)
    # on the axis: decay ln(1 + ω²h²)/(2h) > 0 where the system has none
    undamped = nm.loc["mode 1"]
    assert undamped["sigma_h [1/s]"] == pytest.approx(
        math.log1p((omega * h) ** 2) / (2 * h), rel=1e-12
    )
    assert undamped["fd_h [Hz]"] == pytest.approx(math.atan(omega * h) / (2 * math.pi * h))
    assert undamped["zeta error"] > 0


@pytest.mark.parametrize("name", ["trapezoidal", "implicit_midpoint"])
@pytest.mark.parametrize("h", [0.001, 0.01, 0.1])
def test_trapezoidal_keeps_the_amplitude_and_warps_the_frequency(name, h):
    omega = 20.0
    nm = numerical_modes(name, h, [1j * omega, -1j * omega])
    row = nm.loc["mode 1"]
    # |R(iωh)| = 1 and arg R = 2 atan(ωh/2): ω_h = (2/h) atan(ωh/2), the bilinear
    # (Tustin) warping; the decay rate is 0 to rounding (1e-12 of ω)
    assert row["|R(h*lambda)|"] == pytest.approx(1.0, abs=1e-14)
    assert abs(row["sigma_h [1/s]"]) < 1e-12 * omega
    assert row["fd_h [Hz]"] == pytest.approx(
        2 / h * math.atan(omega * h / 2) / (2 * math.pi), rel=1e-12
    )
    assert row["freq error [%]"] < 0  # the trapezoidal rule's oscillation is slow


# ---------------------------------------------------------------- Newton


def test_newton_failure_is_reported_not_a_silent_number():
    # backward Euler on x' = x², x(0) = 1, h = 0.6: X = 1 + 0.6 X² has no real root
    T = np.linspace(0, 1.2, 3)
    with pytest.warns(ConvergenceWarning, match="did not converge"):
        sol = integrate(lambda t, x: x**2, T, [1.0], "backward_euler")
    assert not sol.success and sol.status == "failed"
    assert "t = 0 s" in sol.message and "h = 0.6 s" in sol.message
    assert sol.t.size == 1 and sol.x.shape == (1, 1)  # only the initial sample


def test_newton_failure_through_a_response():
    blowup = control.nlsys(lambda t, x, u, p: x**2, None, states=1, inputs=0, outputs=1)
    T = np.linspace(0, 1.2, 7)  # h = 0.2: X = x + 0.2 X² solvable until x > 1.25
    with pytest.warns(ConvergenceWarning):
        resp = qc.input_output_response(blowup, T, 0, X0=1.0, method="backward_euler")
    assert not resp.success
    assert "did not converge" in resp.message and "h = 0.2 s" in resp.message
    # what was computed before the failure is the exact backward-Euler recursion
    x = 1.0
    for k in range(1, 7):
        disc = 1 - 4 * 0.2 * x
        if disc < 0:
            break
        x = (1 - math.sqrt(disc)) / (2 * 0.2)
        assert resp.states[0, k] == pytest.approx(x, rel=1e-12)


def test_newton_uses_a_given_jacobian():
    A = np.array([[0.0, 1.0], [-100.0, -0.5]])
    T = np.linspace(0, 1, 51)
    fd = integrate(lambda t, x: A @ x, T, [1.0, 0.0], "radau3")
    exact = integrate(lambda t, x: A @ x, T, [1.0, 0.0], "radau3", jac=lambda t, x: A)
    # the same stage equations solved to 1e-12: the same trajectory to ~1e-12
    np.testing.assert_allclose(fd.x, exact.x, rtol=0, atol=1e-11)
    assert exact.nfev < fd.nfev  # no differences to evaluate
    with pytest.raises(TypeError, match="jac must be callable"):
        integrate(lambda t, x: A @ x, T, [1.0, 0.0], "radau3", jac=A)
    with pytest.raises(ValueError, match="single initial state"):
        integrate(lambda t, x: -x, T, np.ones((2, 3)), "gauss2")


def test_a_stiff_system_at_a_step_far_beyond_explicit_stability():
    # eigenvalues -1 and -1e4: RK4's limit is 2.79e-4 s; L-stable radau3 at h = 0.05
    A = np.array([[-1.0, 0.0], [1.0, -1e4]])
    T = np.linspace(0, 2, 41)
    sys = control.ss(A, np.zeros((2, 1)), np.eye(2), 0)
    x0 = [1.0, 1.0]
    exact = control.initial_response(sys, T, x0).states
    resp = qc.initial_response(sys, T, x0, method="radau3", return_states=True)
    assert resp.success and max_stable_step("rk4", sys) == pytest.approx(2.785e-4, rel=1e-3)
    # each step multiplies the fast mode by R(-500) ≈ -3/500 (R(∞) = 0, L-stable):
    # the first sample holds it at that size, the fourth at 0.006⁴ ≈ 1e-9, where
    # the slow mode's error at h|λ| = 0.05 (order 5) is below 1e-10
    err = np.max(np.abs(resp.states - exact), axis=0)
    R = stability_function("radau3")(-500.0)
    assert err[1] == pytest.approx(abs(R) * (1 - 1 / 9999), rel=1e-3)
    assert np.max(err[4:]) < 1e-7


def test_a_stable_but_not_l_stable_keeps_the_stiff_mode_ringing():
    # the same system under the trapezoidal rule: R(-500) = (1 - 250)/(1 + 250) ≈ -0.992
    # (closed form), so the fast mode, decayed to nothing in the exact response,
    # flips sign each step and is still at 0.992^k of its size
    A = np.array([[-1.0, 0.0], [1.0, -1e4]])
    T = np.linspace(0, 2, 41)
    sys = control.ss(A, np.zeros((2, 1)), np.eye(2), 0)
    exact = control.initial_response(sys, T, [1.0, 1.0]).states
    resp = qc.initial_response(sys, T, [1.0, 1.0], method="trapezoidal", return_states=True)
    assert resp.success  # stable, and wrong: why L-stability matters for stiff models
    fast = (np.asarray(resp.states) - exact)[1]
    k = np.arange(1, 11)
    # the slow mode's own error (order 2 at h = 0.05) is below 1e-3 of the fast one
    np.testing.assert_allclose(fast[k], (1 - 1 / 9999) * (-249 / 251) ** k, rtol=1e-3)


# ---------------------------------------------------------------- events


def lift_off_bump(t):
    """A 0.2 m high, 8 m long (1 - cos) bump at 20 m/s from t = 0.1 s: the wheel leaves it."""
    s = t - 0.1
    return 0.1 * (1 - math.cos(2 * math.pi * s / 0.4)) if 0 <= s <= 0.4 else 0.0


@pytest.fixture(scope="module")
def lift_off_reference():
    from qc_control.studies.compare import nonlinear_reference

    car = qc.nonlinear_quarter_car(road=qc.road.Bump(height=0.2, length=8.0, speed=20.0, t0=0.1))
    T = np.linspace(0.0, 0.8, 401)
    # DOP853 at rtol 1e-10, restarted at each contact event (tested against a
    # hand-written solve_ivp in test_compare_nonlinear)
    return car, T, nonlinear_reference(car, T, events=True, rtol=1e-10)


#: measured at h = 2 ms, largest relative state error with events: radau3 1.1e-9,
#: gauss2 7.1e-9, sdirk2 8.1e-5; each bound 10x above (the reference's is ~1e-10)
EVENT_TOL = {"radau3": 1e-8, "gauss2": 1e-7, "sdirk2": 1e-3}


@pytest.mark.parametrize("name, tol", list(EVENT_TOL.items()))
def test_implicit_methods_with_events_on_the_nonlinear_car(name, tol, lift_off_reference):
    car, T, ref = lift_off_reference
    assert ref.t_events.size == 2  # contact lost, then made again
    resp = qc.input_output_response(car, T, 0, X0=np.zeros(4), method=name, events=True)
    assert resp.success, resp.message
    assert resp.t_events.size == 2
    x = np.asarray(resp.states)
    scale = np.max(np.abs(ref.x), axis=1)
    err = np.max(np.abs(x - ref.x), axis=1) / scale
    # h = 2 ms with every contact stepped to: the method's own accuracy, ~h^p,
    # relative to each state's largest value
    assert np.max(err) < tol, err
    # the contact times to the states' accuracy over the wheel's speed (~1 m/s)
    np.testing.assert_allclose(resp.t_events, ref.t_events, rtol=0, atol=tol)
    if TABLEAUS[name].order > 2:
        # a step across a kink is first order there: without events radau3 and
        # gauss2 are at ~1e-5 (measured 9.2e-6, 1.7e-5), stepping to it restores the order
        plain = qc.input_output_response(car, T, 0, X0=np.zeros(4), method=name)
        assert np.max(np.abs(np.asarray(plain.states) - ref.x).max(axis=1) / scale) > 100 * tol


def test_batched_nonlinear_runs_refuse_an_implicit_tableau():
    from qc_control.models.nonlinear import NonlinearQuarterCarBatch
    from qc_control.studies.nlsweep import simulate_batch

    batch = NonlinearQuarterCarBatch([300.0, 310.0], [40.0] * 2, [2e4] * 2, [2e5] * 2, [1e3] * 2)
    T = np.linspace(0, 0.1, 11)
    # the batched loops evaluate stages one after another: never a silent wrong number
    with pytest.raises(ValueError, match="'radau3' is implicit.*input_output_response"):
        simulate_batch(batch, T, np.zeros(4), np.zeros((1, T.size)), "radau3")
    with pytest.raises(ValueError, match="'gauss2' is implicit"):
        qc.numerics.stepper.stage_plan(TABLEAUS["gauss2"])
