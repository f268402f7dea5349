"""The library behind the explorer: the comparison at one step, the error ladder,
the stability-region boundary and the verdict, against independent references.

References: the modal closed form ``C V e^{Λt} V⁻¹ x0`` of the free response,
``qc.compare_methods`` (python-control's exact response, its own convergence
study), the roots of ``|R(x)| = 1`` on the axes, and Euler's closed-form
limit ``h = -2 Re λ / |λ|²``.
"""

import math

import numpy as np
import pytest

import qc_control as qc
from qc_control.numerics.stability import stability_boundary, step_verdict
from qc_control.numerics.steps import whole_step
from qc_control.studies.quick import error_ladder, ladder_steps, quick_comparison
from qc_control.studies.scenario import Scenario

METHODS = ("euler", "midpoint", "heun", "rk4")


@pytest.fixture(scope="module")
def seed():
    """The seed's car released from 5 cm, 0-2 s at 10 ms."""
    sc = Scenario(t_end=2.0, h=0.01)
    model, T, U, _ = sc.problem()
    return sc, model, T


def closed_form(model, T, x0) -> np.ndarray:
    sys = model.system
    lam, V = np.linalg.eig(np.asarray(sys.A))
    z0 = np.linalg.solve(V, np.asarray(x0, dtype=complex))
    return np.asarray(sys.C) @ (V @ (z0[:, None] * np.exp(np.outer(lam, T)))).real


def test_the_quick_comparison_measures_against_the_exact_response(seed):
    sc, model, T = seed
    quick = quick_comparison(model, T, sc.x0, None, METHODS)
    exact = closed_form(model, T, sc.x0)
    # python-control's exact response and the closed form: both exact, they differ by
    # the rounding of 1000 matrix-exponential steps on a 5 cm response (< 1e-14 m)
    np.testing.assert_allclose(np.asarray(quick.reference.outputs)[:4], exact[:4], atol=1e-14)
    for name in METHODS:
        mine = np.abs(quick.outputs[name][:4] - exact[:4])
        np.testing.assert_allclose(quick.errors[name][:4], mine, atol=1e-14)
        assert quick.table.loc[name, "max |xs err| [m]"] == pytest.approx(
            float(np.max(quick.errors[name][0])), rel=1e-12
        )


def test_the_quick_table_is_the_full_comparisons_at_the_same_step(seed):
    sc, model, T = seed
    quick = quick_comparison(model, T, sc.x0, None, METHODS)
    full = qc.compare_methods(model, T, np.asarray(sc.x0), methods=METHODS, timing=False)
    for column in ("max |xs err| [m]", "max |body_acc err| [m/s²]", "RHS evals", "h_max [s]"):
        np.testing.assert_allclose(
            quick.table[column].astype(float), full.table[column].astype(float), rtol=1e-12
        )
    for name in METHODS:
        np.testing.assert_allclose(
            quick.numerical_modes[name]["zeta_h"], full.numerical_modes[name]["zeta_h"], rtol=1e-12
        )


def test_euler_is_beyond_its_limit_as_the_closed_form_says():
    body = qc.modal_analysis(qc.QuarterCarParams()).body.eigenvalue
    h_max = -2 * body.real / abs(body) ** 2
    for h, stable in ((0.019, True), (0.021, False)):
        sc = Scenario(t_end=2.0, h=whole_step(2.0, h))
        model, T, _, _ = sc.problem()
        quick = quick_comparison(model, T, sc.x0, None, ("euler", "rk4"))
        assert quick.table.loc["euler", "h_max [s]"] == pytest.approx(h_max, rel=1e-9)
        assert bool(quick.table.loc["euler", "stable"]) is stable
        words = quick.table.loc["euler", "verdict"]
        if stable:
            assert words == f"stable (h is {100 * sc.h / h_max:.0f} % of h_max)"
        else:
            assert words == f"beyond its limit by {100 * (sc.h / h_max - 1):.0f} %"
        assert quick.table.loc["rk4", "verdict"].startswith("stable")
        np.testing.assert_allclose(quick.scaled_eigenvalues[0], sc.h * body, rtol=1e-12)


def test_the_ladder_gives_the_convergence_studys_error_at_each_step(seed):
    sc, model, _ = seed
    ladder = error_ladder(model, 2.0, sc.x0, lambda T: None, METHODS, [200, 400])
    for n in (200, 400):
        T = np.linspace(0.0, 2.0, n + 1)
        full = qc.compare_methods(model, T, np.asarray(sc.x0), methods=METHODS, timing=False)
        at_h = full.convergence[full.convergence["level"] == 0].set_index("method")
        mine = ladder[ladder["h"] == pytest.approx(2.0 / n)].set_index("method")
        # two exact responses (python-control's recurrence, the modal one) agree to
        # rounding: 1e-14 m on errors from 1e-3 (Euler) down to 1e-10 m (RK4)
        np.testing.assert_allclose(mine["error"], at_h.loc[mine.index, "error"], atol=1e-14)
        assert (mine["nfev"] == at_h.loc[mine.index, "nfev"]).all()


def test_the_ladder_shows_each_methods_order():
    sc = Scenario(t_end=2.0, h=0.01)
    model = sc.problem()[0]
    ladder = error_ladder(model, 2.0, sc.x0, lambda T: None, METHODS, [400, 800])
    for name, order in (("euler", 1), ("heun", 2), ("rk4", 4)):
        e = ladder[ladder["method"] == name].sort_values("h")["error"].to_numpy()
        # halving h divides the error by 2^p, to within the next term's share (10 %)
        assert math.log2(e[1] / e[0]) == pytest.approx(order, abs=0.1)


def test_the_ladder_steps_span_the_slider_and_bound_the_work():
    steps = ladder_steps(10.0)
    assert steps[0] == 50  # 200 ms
    assert max(steps) < 20_000 and steps == sorted(set(steps))
    assert ladder_steps(0.1)[0] == 2  # never fewer than two steps
    with pytest.raises(ValueError, match="t_end must be a finite time > 0 s, got -1"):
        ladder_steps(-1.0)


def test_the_boundary_of_eulers_region_is_the_unit_circle_around_minus_one():
    x, y = np.linspace(-2.5, 0.5, 601), np.linspace(-1.5, 1.5, 601)
    (curve,) = stability_boundary("euler", x, y)
    # marching squares interpolates linearly between grid points 0.005 apart: the
    # curve is within a fraction of that spacing of |1 + z| = 1
    np.testing.assert_allclose(np.abs(1 + curve), 1.0, atol=1e-3)
    assert curve.real.min() == pytest.approx(-2.0, abs=1e-3)


def test_the_boundary_of_rk4s_region_crosses_the_axes_where_r_says():
    x, y = np.linspace(-3.2, 0.6, 761), np.linspace(-3.2, 3.2, 1281)
    curve = np.concatenate(stability_boundary("rk4", x, y))
    # on the real axis: the negative root of 1 + x + x²/2 + x³/6 + x⁴/24 = 1
    roots = np.roots([1 / 24, 1 / 6, 1 / 2, 1, 0])
    left = min(r.real for r in roots if abs(r.imag) < 1e-12)
    assert left == pytest.approx(-2.785293563, abs=1e-8)
    near_axis = curve[np.abs(curve.imag) < 0.01]
    assert near_axis.real.min() == pytest.approx(left, abs=5e-3)
    # on the imaginary axis: |R(iy)| = 1 at y = 2√2 (HW II, Fig. IV.2.1)
    on_axis = curve[np.abs(curve.real) < 2e-3]
    assert np.max(np.abs(on_axis.imag)) == pytest.approx(2 * math.sqrt(2), abs=5e-3)


def test_a_bad_window_is_refused():
    with pytest.raises(ValueError, match="x and y must be 1-D grids of at least 2 points"):
        stability_boundary("rk4", [0.0], [0.0, 1.0])


def test_the_verdict_in_words():
    assert step_verdict(0.0246, 0.02) == "beyond its limit by 23 %"
    assert step_verdict(0.01, 0.02) == "stable (h is 50 % of h_max)"
    assert step_verdict(1.0, math.inf) == "stable at every step"
    assert step_verdict(0.01, 0.0) == "no stable step (h_max = 0)"


def test_the_whole_step_divides_the_run():
    for t_end, h in ((10.0, 0.0198), (2.0, 0.021), (1.0, 0.9)):
        step = whole_step(t_end, h)
        n = t_end / step
        assert n == pytest.approx(round(n), abs=1e-9) and round(n) >= 2
        assert abs(step - h) <= max(step, h) ** 2 / t_end  # the nearest such step
