"""ButcherTableau checks, order conditions by rooted trees, and the seed's four formulas."""

import dataclasses
import functools
from collections import Counter
from math import factorial, prod

import numpy as np
import pytest
from scipy.integrate._ivp import dop853_coefficients, rk

from qc_control import METHODS, ButcherTableau, get_method, integrate
from qc_control.numerics.methods import HEUN, RK4
from qc_control.numerics.order_conditions import check_order, density, rooted_trees, tree_str
from qc_control.numerics.stability import stability_coefficients

# Published tableaus (exact fractions, rounded once to double).
RALSTON = dict(a=[[0, 0], [2 / 3, 0]], b=[1 / 4, 3 / 4], c=[0, 2 / 3])
THREE_EIGHTHS = dict(
    a=[[0, 0, 0, 0], [1 / 3, 0, 0, 0], [-1 / 3, 1, 0, 0], [1, -1, 1, 0]],
    b=[1 / 8, 3 / 8, 3 / 8, 1 / 8],
    c=[0, 1 / 3, 2 / 3, 1],
)
KUTTA3 = dict(a=[[0, 0, 0], [1 / 2, 0, 0], [-1, 2, 0]], b=[1 / 6, 2 / 3, 1 / 6], c=[0, 1 / 2, 1])
# Cash & Karp (1990), ACM TOMS 16(3), Table: the 5th-order weights and the embedded 4th.
CASH_KARP_A = [
    [0, 0, 0, 0, 0, 0],
    [1 / 5, 0, 0, 0, 0, 0],
    [3 / 40, 9 / 40, 0, 0, 0, 0],
    [3 / 10, -9 / 10, 6 / 5, 0, 0, 0],
    [-11 / 54, 5 / 2, -70 / 27, 35 / 27, 0, 0],
    [1631 / 55296, 175 / 512, 575 / 13824, 44275 / 110592, 253 / 4096, 0],
]
CASH_KARP_B5 = [37 / 378, 0, 250 / 621, 125 / 594, 0, 512 / 1771]
CASH_KARP_B4 = [2825 / 27648, 0, 18575 / 48384, 13525 / 55296, 277 / 14336, 1 / 4]


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
        # an entry above the diagonal makes a valid implicit method, here of order 2
        (
            dict(a=[[0, 1], [0, 0]], b=[0.5, 0.5], c=[1, 0], order=1),
            "meets every condition of order 2",
        ),
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
    with pytest.raises(TypeError, match="got 4"):
        get_method(4)


# -- rooted trees and order conditions (Butcher 2016, §30-§32; HNW I, §II.2)


def test_tree_counts_are_the_published_ones():
    """Rooted trees per order: OEIS A000081, the counts quoted in HNW I, §II.2."""
    assert [len(rooted_trees(n)) for n in range(1, 11)] == [1, 1, 2, 4, 9, 20, 48, 115, 286, 719]
    for n in range(1, 11):  # each tree once
        assert len(set(rooted_trees(n))) == len(rooted_trees(n))


def test_densities_of_the_low_order_trees():
    """γ(t) as tabulated in HNW I, §II.2, Table 2.2 (orders 1-4), and order 5 by hand."""
    got = {n: sorted(density(t) for t in rooted_trees(n)) for n in range(1, 6)}
    assert got == {
        1: [1],
        2: [2],
        3: [3, 6],
        4: [4, 8, 12, 24],
        5: [5, 10, 15, 20, 20, 30, 40, 60, 120],
    }
    assert {tree_str(t): density(t) for t in rooted_trees(4)} == {
        "[τ³]": 4,
        "[τ, [τ]]": 8,
        "[[τ²]]": 12,
        "[[[τ]]]": 24,
    }


def _symmetry(t):
    """σ(t): the tree's automorphisms, computed here independently of the module."""
    return prod(_symmetry(child) ** m * factorial(m) for child, m in Counter(t).items())


@pytest.mark.parametrize("n", range(1, 11))
def test_densities_count_the_monotone_labellings(n):
    """Σ over trees of order n of α(t) = n!/(σ(t) γ(t)) is (n-1)!.

    α(t) counts the labellings of t's vertices by 1..n that increase away from the
    root (HNW I, §II.2), and there are (n-1)! such increasingly labelled trees in all
    (each vertex k > 1 picks its parent among 1..k-1). With σ computed here, this
    checks every γ up to order 10."""
    assert sum(factorial(n) // (_symmetry(t) * density(t)) for t in rooted_trees(n)) == factorial(
        n - 1
    )


@pytest.mark.parametrize(
    "a, b, order",
    [
        ([[0]], [1], 1),
        (METHODS["midpoint"].a, METHODS["midpoint"].b, 2),
        (RALSTON["a"], RALSTON["b"], 2),
        (KUTTA3["a"], KUTTA3["b"], 3),
        (RK4.a, RK4.b, 4),
        (THREE_EIGHTHS["a"], THREE_EIGHTHS["b"], 4),
        (CASH_KARP_A, CASH_KARP_B4, 4),
        (CASH_KARP_A, CASH_KARP_B5, 5),
        # Dormand & Prince (1980), RK5(4)7M: scipy's RK45 tableau (its last stage unused here)
        (np.pad(rk.RK45.A, ((0, 0), (0, 1))), rk.RK45.B, 5),
        # DOP853 (HNW I §II.10): its 12-stage 8th-order weights, taken from scipy
        (
            dop853_coefficients.A[: dop853_coefficients.N_STAGES, : dop853_coefficients.N_STAGES],
            dop853_coefficients.B,
            8,
        ),
    ],
    ids=["euler", "midpoint", "ralston", "kutta3", "rk4", "3/8", "ck4", "ck5", "dopri5", "dop853"],
)
def test_order_of_published_tableaus(a, b, order):
    found = check_order(a, b)
    assert found.order == order
    # the next order fails by far more than rounding (1e-7 for DOP853's order 9)
    assert abs(found.residual) > 1e-8, found.failing
    c = np.asarray(a, dtype=float).sum(axis=1)
    assert ButcherTableau("t", a=a, b=b, c=c).order == order  # computed when left out
    assert ButcherTableau("t", a=a, b=b, c=c, order=order).order == order


def test_a_false_order_claim_names_the_first_failing_order():
    with pytest.raises(
        ValueError, match=r"claims order 5 but fails the order-5 conditions.*its order is 4"
    ):
        ButcherTableau("x", RK4.a, RK4.b, RK4.c, order=5)
    with pytest.raises(ValueError, match=r"claims order 99 but fails the order-5 conditions"):
        ButcherTableau("x", RK4.a, RK4.b, RK4.c, order=99)
    # a 4-stage method that meets the order-3 conditions but not all of order 4:
    # Kutta's 3rd-order method padded with a zero-weight stage (its b·c³ = 1/4 holds)
    with pytest.raises(
        ValueError, match=r"fails the order-4 conditions \(at the tree \[τ, \[τ\]\]"
    ):
        ButcherTableau("k3+", a=np.pad(KUTTA3["a"], ((0, 1), (0, 1))), b=KUTTA3["b"] + [0], order=4)
    with pytest.raises(ValueError, match="meets every condition of order 4; give order=4"):
        ButcherTableau("x", RK4.a, RK4.b, RK4.c, order=3)


def test_order_is_verified_to_rounding_not_to_typed_digits():
    """Seven typed digits are not 1/6: b·c² misses 1/3 by 1.7e-8, far above rounding
    (64·3·eps·b̄ ≈ 1e-14), so RK4 so written is second order as a tableau."""
    b = [0.1666667, 0.3333333, 0.3333333, 0.1666667]
    with pytest.raises(ValueError, match=r"fails the order-3 conditions .* its order is 2"):
        ButcherTableau("rk4-7digits", RK4.a, b, RK4.c, order=4)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(a=[["a"]], b=[1], c=[0]), "tableau 'bad': a must be real numbers, got [['a']]"),
        (dict(a=[[0]], b="abc", c=[0]), "tableau 'bad': b must be real numbers, got 'abc'"),
        (dict(a=[[0]], b=[1], c=[None]), "tableau 'bad': c must be real numbers, got [None]"),
        (dict(a=[[0]], b=[1j], c=[0]), "tableau 'bad': b must be real numbers, got [1j]"),
        (dict(a=[[0]], b=[np.inf], c=[0]), "tableau 'bad': b must be finite, got [inf]"),
        (dict(a=[[0]], b=[1], c=[0], order="1"), "order must be a positive integer, got '1'"),
    ],
)
def test_bad_entries_name_the_parameter_and_value(kwargs, words):
    with pytest.raises(ValueError) as info:
        ButcherTableau("bad", **kwargs)
    assert str(info.value) == words or words in str(info.value)


def test_bad_name():
    with pytest.raises(ValueError, match="tableau name must be a non-empty string, got 5"):
        ButcherTableau(5, a=[[0]], b=[1], c=[0])


# -- equality: resp.method == 'heun'


def test_a_tableau_equals_its_name():
    assert HEUN == "heun" and "heun" == HEUN and HEUN != "rk4" and HEUN != "Heun"
    assert hash(HEUN) == hash("heun")  # consistent with == (a dict finds it by name)
    assert {HEUN: 1}["heun"] == 1


def test_tableaus_equal_by_value_and_caches_agree():
    copy = ButcherTableau("heun", a=HEUN.a.tolist(), b=HEUN.b.tolist(), c=HEUN.c.tolist())
    assert copy == HEUN and hash(copy) == hash(HEUN) and copy is not HEUN
    other = ButcherTableau("heun", **RALSTON)  # same name, other coefficients
    assert other != HEUN and other == "heun"
    # the lru_cache keyed on tableaus must not hand Ralston Heun's coefficients
    np.testing.assert_array_equal(stability_coefficients(copy), stability_coefficients(HEUN))
    assert stability_coefficients(other)[2] == pytest.approx(0.5)
    assert HEUN != 2 and HEUN != None  # noqa: E711


@functools.lru_cache
def _cached(tab):
    return tab.name


def test_equal_tableaus_share_a_cache_entry():
    assert _cached(HEUN) == _cached(ButcherTableau("heun", HEUN.a, HEUN.b, HEUN.c)) == "heun"
    assert _cached.cache_info().currsize == 1
