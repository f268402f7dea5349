"""The generic stepper: batches, counts, grids, divergence, bad input."""

import numpy as np
import pytest

from qc_control import METHODS, DivergenceWarning, integrate, quarter_car

A = np.asarray(quarter_car().A)


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
        ([0.0, np.nan], "must be finite"),
    ],
)
def test_bad_time_grid(t, words):
    with pytest.raises(ValueError, match=words):
        integrate(lambda t, x: -x, t, [1.0])


@pytest.mark.parametrize(
    "x0, words",
    [
        ([np.inf], "x0 must be finite"),
        (np.zeros((2, 2, 2)), "shape"),
        ([], "shape"),
    ],
)
def test_bad_x0(x0, words):
    with pytest.raises(ValueError, match=words):
        integrate(lambda t, x: -x, [0, 1], x0)


@pytest.mark.parametrize("bad", [0, -1, 1.5, True])
def test_bad_substeps(bad):
    with pytest.raises(ValueError, match="substeps must be a positive integer"):
        integrate(lambda t, x: -x, [0, 1], [1.0], substeps=bad)
