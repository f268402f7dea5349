"""The generic stepper: batches, counts, grids, divergence, complex states, bad input."""

import linecache
import math
import sys
import traceback
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from qc_control import METHODS, DivergenceWarning, integrate, quarter_car
from qc_control.numerics import stepper as stepper_module
from qc_control.numerics.integrate import Solution, integrate_stepper, uniform_step
from qc_control.numerics.lti import lti_trajectory
from qc_control.numerics.methods import RK4

A = np.asarray(quarter_car().A)
EPS = np.finfo(float).eps
integrate_module = sys.modules[
    "qc_control.numerics.integrate"
]  # qc_control.numerics.integrate is the function


def counting(f):
    calls = []

    def g(t, x):
        calls.append(t)
        return f(t, x)

    return g, calls


@pytest.mark.parametrize("method", list(METHODS))
def test_nfev_is_exact(method):
    f, calls = counting(lambda t, x: x @ A.T)
    sol = integrate(f, np.linspace(0, 1, 51), [0, 0, 0.05, 0], method, substeps=3)
    assert sol.nfev == len(calls) == METHODS[method].stages * 50 * 3
    assert sol.steps == 150 and sol.success


@pytest.mark.parametrize("method", list(METHODS))
def test_batch_equals_rows(method):
    rng = np.random.default_rng(1)
    X0 = rng.normal(size=(5, 4)) * 0.05
    T = np.linspace(0, 2, 201)
    batch = integrate(lambda t, x: x @ A.T, T, X0, method)
    assert batch.x.shape == (5, 4, 201)
    for i in range(5):
        row = integrate(lambda t, x: x @ A.T, T, X0[i], method)
        # The same arithmetic, but a batched matmul may add in another order:
        # states are O(0.1), one rounding is ~1e-17, 200 steps stay below 1e-14.
        np.testing.assert_allclose(batch.x[i], row.x, rtol=0, atol=1e-14)


def test_stage_times_and_nonuniform_grid():
    """x' = 3 t^2 has x = t^3: RK4 integrates cubics exactly on any grid."""
    T = np.array([0.0, 0.1, 0.35, 0.4, 1.0])
    sol = integrate(lambda t, x: np.array([3 * t * t]), T, [0.0], "rk4", substeps=2)
    np.testing.assert_allclose(sol.x[0], T**3, rtol=1e-14, atol=1e-16)


def test_substeps_equal_a_finer_grid():
    coarse = integrate(
        lambda t, x: x @ A.T, np.linspace(0, 1, 11), [0, 0, 0.05, 0], "heun", substeps=4
    )
    fine = integrate(lambda t, x: x @ A.T, np.linspace(0, 1, 41), [0, 0, 0.05, 0], "heun")
    np.testing.assert_allclose(coarse.x, fine.x[:, ::4], rtol=1e-12, atol=1e-16)


def test_blow_up_stops_at_first_non_finite_sample():
    # x' = x^2, x(0) = 1 has x = 1/(1 - t): infinite at t = 1. Euler with
    # h = 0.5 overflows a double after ~10 steps (x squares each step).
    T = np.arange(0, 200) * 0.5
    with pytest.warns(DivergenceWarning, match="non-finite"):
        sol = integrate(lambda t, x: x * x, T, [1.0], "euler")
    assert sol.status == "diverged" and not sol.success
    assert np.all(np.isfinite(sol.x)) and 2 < sol.t.size < 20
    # the next sample would have been non-finite: x + h x^2 overflows
    last = sol.x[0, -1]
    with np.errstate(over="ignore"):
        assert not np.isfinite(last + 0.5 * last * last)


@pytest.mark.parametrize(
    "t, words",
    [
        ([0.0, 1.0, 1.0], r"t\[1\] = 1.0 and t\[2\] = 1.0"),
        ([0.0, 2.0, 1.0], "must increase strictly"),
        ([0.0], "at least 2 times"),
        ([0.0, np.nan], r"must be finite; t\[1\] = nan"),
        (["a", "b"], r"t must be an array of real times \[s\], got \['a', 'b'\]"),
        ("abc", r"t must be an array of real times \[s\], got 'abc'"),
        ([0, 1j], r"t must be an array of real times \[s\], got \[0, 1j\]"),
    ],
)
def test_bad_time_grid(t, words):
    with pytest.raises(ValueError, match=words):
        integrate(lambda t, x: -x, t, [1.0])


@pytest.mark.parametrize(
    "x0, words",
    [
        ([np.inf], r"x0 must be finite, got \[inf\]"),
        (np.zeros((2, 2, 2)), "shape"),
        ([], "shape"),
        (["a", "b"], r"x0 must be an array of real or complex numbers, got \['a', 'b'\]"),
        ("abc", r"x0 must be an array of real or complex numbers, got 'abc'"),
        ([[1.0], [1.0, 2.0]], "x0 must be an array of real or complex numbers"),
    ],
)
def test_bad_x0(x0, words):
    with pytest.raises(ValueError, match=words):
        integrate(lambda t, x: -x, [0, 1], x0)


@pytest.mark.parametrize("bad", [0, -1, 1.5, True])
def test_bad_substeps(bad):
    with pytest.raises(ValueError, match="substeps must be a positive integer"):
        integrate(lambda t, x: -x, [0, 1], [1.0], substeps=bad)


def test_f_must_be_callable():
    with pytest.raises(TypeError, match="f must be callable as f\\(t, x\\), got 'A x'"):
        integrate("A x", [0, 1], [1.0])


# -- complex states (scipy's solve_ivp convention: a complex x0 integrates in complex)

LAM = -0.5 + 3j


@pytest.mark.parametrize("method", list(METHODS))
def test_complex_linear_equation_against_its_closed_form(method):
    """y' = λy, y(0) = 1+2j, λ complex: y = e^{λt}(1+2j).

    Exactly, the method gives y_n = R(hλ)^n y0 (to rounding: 100 steps, 1e-13);
    against e^{λt} its global error is about t|λ| (h|λ|)^p / (p+1)! relative,
    so (h|λ|)^p t|λ| bounds it. Before, the imaginary part was dropped.
    """
    h, x0 = 0.01, 1 + 2j
    T = np.arange(101) * h
    sol = integrate(lambda t, y: LAM * y, T, [x0], method)
    assert sol.x.dtype == complex and sol.success
    p = METHODS[method].order
    z = h * LAM
    R = sum(z**k / math.factorial(k) for k in range(p + 1))  # s = p: the Taylor polynomial
    np.testing.assert_allclose(sol.x[0], R ** np.arange(101) * x0, rtol=1e-13)
    exact = np.exp(LAM * T) * x0
    bound = (h * abs(LAM)) ** p * T[-1] * abs(LAM)
    assert np.max(np.abs(sol.x[0] - exact) / np.abs(exact)) < bound


def test_complex_batch_and_solve_ivp():
    """A batch of complex states, against scipy's solve_ivp (DOP853, rtol 1e-12) on the
    same complex problem: RK4 at h = 1 ms is within 1e-10 (its error, (h|λ|)^4 ~ 1e-10)."""
    x0 = np.array([[1 + 2j, -1j], [0.5, 2 - 1j]])
    M = np.array([[LAM, 1], [0, -1 + 1j]])
    T = np.linspace(0, 1, 1001)
    sol = integrate(lambda t, y: y @ M.T, T, x0, "rk4")
    for i in range(2):
        ref = solve_ivp(
            lambda t, y: M @ y, (0, 1), x0[i], "DOP853", t_eval=T, rtol=1e-12, atol=1e-14
        )
        np.testing.assert_allclose(sol.x[i], ref.y, rtol=0, atol=1e-10)


def test_a_complex_f_on_a_real_state_is_refused():
    with pytest.raises(TypeError, match="f returned complex values for a real x0"):
        integrate(lambda t, y: LAM * y, [0, 0.1, 0.2], [1.0])


# -- divergence: a non-finite state is never a success


@pytest.mark.parametrize("bad_at", [1, 5, 63, 64, 65, 130])
def test_nan_at_any_sample_is_cut_and_reported(bad_at):
    """f turns NaN (not inf) at one sample, in one member of a batch only."""
    T = np.arange(200) * 0.01

    def f(t, x):
        out = -x
        if t >= T[bad_at - 1] - 1e-12:
            out = out.copy()
            out[1, 0] = np.nan
        return out

    with pytest.warns(DivergenceWarning, match="non-finite"):
        sol = integrate(f, T, np.ones((3, 2)), "euler")
    assert sol.status == "diverged" and not sol.success
    assert sol.t.size == bad_at and np.all(np.isfinite(sol.x))


def test_inf_with_substeps_is_cut():
    with pytest.warns(DivergenceWarning):
        sol = integrate(lambda t, x: x * x, np.arange(50) * 0.5, [1.0], "rk4", substeps=3)
    assert not sol.success and np.all(np.isfinite(sol.x))


def test_a_solution_holding_nan_is_never_a_success():
    """Whoever builds a Solution (the LTI path in response.py does), it checks itself."""
    x = np.array([[0.0, 1.0, np.nan]])
    sol = Solution(np.arange(3.0), x, 12, 3, RK4, "success", "")
    assert sol.status == "diverged" and not sol.success and "non-finite" in sol.message
    with pytest.raises(ValueError, match="status must be"):
        Solution(np.arange(3.0), x, 12, 3, RK4, "ok", "")


# -- the loop is plain Python: tracebacks show its source (issue 9 item 5)


def test_a_traceback_through_the_loop_shows_source():
    def f(t, x):
        if t > 0.05:
            raise RuntimeError("boom")
        return -x

    with pytest.raises(RuntimeError, match="boom") as info:
        integrate(f, np.linspace(0, 1, 11), [1.0])
    frames = traceback.extract_tb(info.tb)
    loop = [fr for fr in frames if fr.filename == stepper_module.__file__ and fr.name == "rk_steps"]
    assert loop and loop[0].line  # a real file and line, not "<qc_control loop: rk4>"
    assert "f(" in linecache.getline(loop[0].filename, loop[0].lineno)


# -- the one uniform-grid rule


def test_uniform_grids_of_any_length_and_offset():
    assert uniform_step(np.linspace(0, 1, 101)) == 0.01
    assert uniform_step(np.arange(0, 10, 0.001)) is not None
    assert uniform_step(1000 + np.arange(10001) * 1e-3) is not None
    assert uniform_step(np.linspace(-5, 5, 1001)) is not None
    # np.linspace(0, 1e6, 10**8 + 1) has steps of 0.01 s at ulp(1e6) = 1.2e-10 s: a
    # relative jitter of 1.2e-8 of the step, which the old 1e-9 rule refused. Same
    # ratio on 2e6 points (the memory of 10**8 would be 800 MB):
    T = np.linspace(1e6, 1e6 + 2e4, 2 * 10**6 + 1)
    assert np.ptp(np.diff(T)) > 1e-9 * 0.01  # the old rule's tolerance is exceeded
    assert uniform_step(T) == pytest.approx(0.01, rel=1e-12)


def test_uniform_step_checks_in_chunks(monkeypatch):
    monkeypatch.setattr(integrate_module, "_CHUNK", 7)
    T = np.linspace(0, 1, 101)
    assert uniform_step(T) == 0.01
    T[99] += 1e-12
    assert uniform_step(T) is None


def test_jittered_and_summed_grids_are_not_uniform():
    rng = np.random.default_rng(7)
    T = np.arange(1001) * 0.01
    jittered = T + rng.uniform(-4e-8, 4e-8, T.size)  # issue 9: ±4e-8 s on a 10 ms grid
    assert uniform_step(jittered) is None
    summed = np.concatenate([[0.0], np.cumsum(np.full(10000, 0.001))])  # drifts ~500 ulps
    assert uniform_step(summed) is None
    assert uniform_step([0.0, 1.0, 3.0]) is None
    with pytest.raises(ValueError, match="T must increase strictly"):
        uniform_step([0.0, 1.0, 1.0])


def _edge_grid(T0, dt, N, sign_pattern):
    """A grid whose points sit 0.9 of the tolerance off T0 + k dt, by a pattern."""
    T = T0 + np.arange(N) * dt
    tol = integrate_module.UNIFORM_RTOL * EPS * max(abs(T[0]), abs(T[-1]))
    off = 0.9 * tol * sign_pattern(np.arange(N))
    off[0] = off[-1] = 0
    return T + off


@pytest.mark.parametrize(
    "T",
    [
        np.linspace(0, 10, 10001),
        np.arange(10001) * 1e-3,
        _edge_grid(0.0, 1e-3, 10001, lambda k: np.where(k < 5000, 1.0, -1.0)),
        _edge_grid(0.0, 1e-3, 10001, lambda k: (-1.0) ** k),
        _edge_grid(3.0, 1e-3, 10001, lambda k: np.sin(k / 300)),
    ],
    ids=["linspace", "arange", "edge-step", "edge-alternating", "edge-offset"],
)
@pytest.mark.parametrize("method", list(METHODS))
def test_whatever_is_uniform_the_lti_engine_reproduces(T, method):
    """Every grid uniform_step accepts, including ones built at its tolerance's edge:
    the LTI engine (which assumes the mean step) equals the generic stepper to 1e-12
    relative (the issue's bound), and equals stepping every interval by its own length
    to 1e-12 too: the points differ from T0 + k dt by at most 4 eps max|T| = 9e-15 s,
    which moves a state by |λ|max · 9e-15 ~ 2e-13 of its size."""
    assert uniform_step(T) is not None
    sys = quarter_car(road=True)
    Am, B = np.asarray(sys.A), np.asarray(sys.B)
    U = np.where(T >= T[0] + 0.5, 0.05, 0.0)[None]
    x0 = np.array([0.1, -0.3, 0.05, 0.01])

    def u(t):  # the input, linear between the samples (python-control's convention)
        return np.interp(t, T, U[0])

    def f(t, x):
        return Am @ x + B[:, 0] * u(t)

    lti = lti_trajectory(METHODS[method], Am, B, T, U, x0)
    generic = integrate(f, T, x0, method).x
    scale = np.max(np.abs(generic))
    assert np.max(np.abs(lti - generic)) / scale < 1e-12
    # interval by interval, each stepped with its own length (not dt); the first
    # 1000 intervals suffice, since the points' offsets do not accumulate
    x, own = x0, [x0]
    for k in range(1000):
        x = integrate(f, T[k : k + 2], x, method).x[:, -1]
        own.append(x)
    own = np.array(own).T
    assert np.max(np.abs(lti[:, : own.shape[1]] - own)) / scale < 1e-12


def test_jittered_grid_takes_the_generic_engine():
    """Issue 9 item 6: a 10 ms grid jittered by ±4e-8 s made engine='auto' pick the LTI
    engine, 7.2e-7 off the generic one. It is not uniform now, so auto steps it interval
    by interval, exactly as engine='generic'."""
    import qc_control as qc

    rng = np.random.default_rng(0)
    T = np.arange(1001) * 0.01 + np.r_[0, rng.uniform(-4e-8, 4e-8, 999), 0]
    sys = quarter_car()
    X0 = [0.0, 0.0, 0.05, 0.0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        auto = qc.initial_response(sys, T, X0)
    np.testing.assert_array_equal(
        auto.states, qc.initial_response(sys, T, X0, engine="generic").states
    )


def test_integrate_stepper_is_integrates_loop_around_a_given_stepper():
    # A stepper doing Euler's x + h f(t, x) by hand must give integrate's Euler run bit for
    # bit (the same operations), the same nfev, and the same cut and warning on a blow-up
    # (x' = x^2 from x = 1: x = 1/(1 - t), infinite at t = 1).
    t = np.linspace(0.0, 2.0, 401)
    h = float(t[1] - t[0])

    def f(tt, x):
        return x * x

    def euler(x, out, start, stop):
        for k in range(start, stop):
            x = x + h * f(t[k], x)
            out[k + 1] = x
        return x

    with pytest.warns(DivergenceWarning, match="non-finite"):
        ref = integrate(f, t, [1.0], "euler")
    with pytest.warns(DivergenceWarning, match="non-finite"):
        sol = integrate_stepper(euler, t, [1.0], "euler")
    assert sol.status == ref.status == "diverged" and sol.message == ref.message
    assert sol.nfev == ref.nfev and sol.steps == ref.steps
    np.testing.assert_array_equal(sol.t, ref.t)
    np.testing.assert_array_equal(sol.x, ref.x)
    with pytest.raises(TypeError, match="stepper must be callable"):
        integrate_stepper(None, t, [1.0])
