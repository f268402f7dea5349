"""ButcherTableau checks and the seed's four formulas."""

import dataclasses

import numpy as np
import pytest

from qc_control import METHODS, ButcherTableau, get_method, integrate


def test_registry_names():
    assert list(METHODS) == ["euler", "midpoint", "heun", "rk4"]
    assert [METHODS[m].order for m in METHODS] == [1, 2, 2, 4]
    assert [METHODS[m].stages for m in METHODS] == [1, 2, 2, 4]


def one_step(method, f, x, h):
    return integrate(lambda t, y: f(y), [0.0, h], x, method).x[:, -1]


@pytest.mark.parametrize(
    "seed_formula, method",
    [
        (lambda f, x, h: x + h * f(x), "euler"),
        (lambda f, x, h: x + h * f(x + h / 2 * f(x)), "midpoint"),
        (lambda f, x, h: x + h / 2 * (f(x) + f(x + h * f(x))), "heun"),
    ],
)
def test_seed_formulas_on_a_nonlinear_rhs(seed_formula, method):
    """Each method is the seed's formula exactly (section 4.2), on a nonlinear f."""
    f = lambda x: np.array([x[1], -np.sin(x[0]) - 0.3 * x[1] ** 3])
    x = np.array([0.7, -0.2])
    np.testing.assert_allclose(
        one_step(method, f, x, 0.1), seed_formula(f, x, 0.1), rtol=1e-15, atol=1e-15
    )


def test_rk4_is_classic():
    f = lambda x: np.array([x[1], -np.sin(x[0])])
    x, h = np.array([0.7, -0.2]), 0.1
    k1 = f(x)
    k2 = f(x + h / 2 * k1)
    k3 = f(x + h / 2 * k2)
    k4 = f(x + h * k3)
    np.testing.assert_allclose(
        one_step("rk4", f, x, h), x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), rtol=1e-15, atol=1e-15
    )


def test_user_tableau_three_eighths_rule():
    tab = ButcherTableau(
        "3/8",
        a=[[0, 0, 0, 0], [1 / 3, 0, 0, 0], [-1 / 3, 1, 0, 0], [1, -1, 1, 0]],
        b=[1 / 8, 3 / 8, 3 / 8, 1 / 8],
        c=[0, 1 / 3, 2 / 3, 1],
        order=4,
    )
    assert get_method(tab) is tab
    # exp(-1) with 10 steps: 4th order, error ~ h^4/120 ~ 1e-6
    sol = integrate(lambda t, x: -x, np.linspace(0, 1, 11), [1.0], tab)
    assert abs(sol.x[0, -1] - np.exp(-1)) < 1e-6


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(a=[[0, 1], [0, 0]], b=[0.5, 0.5], c=[1, 0], order=1), "strictly lower triangular"),
        (dict(a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 0.5], order=2), "row 1 of a sums to 1"),
        (dict(a=[[0, 0], [1, 0]], b=[0.5, 0.6], c=[0, 1], order=2), "b sums to 1.1"),
        (dict(a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 1], order=3), "fails the order-3 conditions"),
        (dict(a=[[0, 0], [1, 0]], b=[0.5, 0.5], c=[0, 1], order=0), "order must be a positive"),
        (dict(a=[[0, 0]], b=[0.5, 0.5], c=[0, 1], order=2), "need a (s, s)"),
    ],
)
def test_bad_tableaus_fail_when_built(kwargs, words):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(")", r"\)")):
        ButcherTableau("bad", **kwargs)


def test_tableau_is_immutable():
    with pytest.raises(ValueError):
        METHODS["rk4"].b[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        METHODS["rk4"].order = 3


def test_unknown_method_lists_known_ones():
    with pytest.raises(ValueError, match="unknown method 'rk5'.*euler, midpoint, heun, rk4"):
        get_method("rk5")
    with pytest.raises(TypeError, match="got int"):
        get_method(4)
