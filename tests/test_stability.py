"""Stability functions, step limits and numerical modes against closed forms."""

import cmath
import math

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control import METHODS, max_stable_step, numerical_modes, stability_function

SEED_EIG = np.linalg.eigvals(np.asarray(qc.quarter_car().A))


@pytest.mark.parametrize("method, p", [("euler", 1), ("midpoint", 2), ("heun", 2), ("rk4", 4)])
def test_stability_function_is_taylor_for_s_equal_p(method, p):
    np.testing.assert_allclose(
        stability_function(method).coef, [1 / math.factorial(k) for k in range(p + 1)], rtol=1e-15
    )


def test_stability_function_of_a_user_tableau():
    # Ralston's 3rd-order method, s = p = 3: R = 1 + z + z^2/2 + z^3/6
    tab = qc.ButcherTableau(
        "ralston3",
        a=[[0, 0, 0], [1 / 2, 0, 0], [0, 3 / 4, 0]],
        b=[2 / 9, 1 / 3, 4 / 9],
        c=[0, 1 / 2, 3 / 4],
        order=3,
    )
    np.testing.assert_allclose(stability_function(tab).coef, [1, 1, 1 / 2, 1 / 6], rtol=1e-15)


def test_euler_limit_closed_form():
    # |1 + h lambda| = 1  <=>  h = -2 Re(lambda) / |lambda|^2
    expected = min(-2 * lam.real / abs(lam) ** 2 for lam in SEED_EIG)
    assert max_stable_step("euler", qc.quarter_car()) == pytest.approx(expected, rel=1e-12)
    assert round(expected, 5) == 0.01982


@pytest.mark.parametrize(
    "method, quoted", [("euler", 0.0198), ("midpoint", 0.0721), ("heun", 0.0721), ("rk4", 0.1085)]
)
def test_seed_limits_are_first_crossings(method, quoted):
    h = max_stable_step(method, qc.QuarterCarParams())
    assert round(h, 4) == quoted
    R = stability_function(method)
    # just below: every mode stable; at h: the worst mode sits on |R| = 1
    assert max(abs(R(0.999 * h * lam)) for lam in SEED_EIG) <= 1
    assert max(abs(R(h * lam)) for lam in SEED_EIG) == pytest.approx(1, abs=1e-10)
    assert max(abs(R(1.001 * h * lam)) for lam in SEED_EIG) > 1
    # and no smaller step is unstable (scan 2000 steps below the limit)
    for hh in np.linspace(1e-6, h, 2000)[:-1]:
        assert max(abs(R(hh * lam)) for lam in SEED_EIG) <= 1 + 1e-12


def test_undamped_modes():
    sys = qc.quarter_car(qc.QuarterCarParams(zeta=0.0))
    assert max_stable_step("euler", sys) == 0.0  # |1 + i y| > 1 for every y != 0
    wmax = max(abs(np.linalg.eigvals(np.asarray(sys.A))))
    # RK4 is stable on the imaginary axis up to |y| = 2 sqrt(2) (HW II, Fig IV.2.1)
    assert max_stable_step("rk4", sys) == pytest.approx(2 * math.sqrt(2) / wmax, rel=1e-9)


def test_eigenvalue_inputs():
    assert max_stable_step("euler", [-1.0]) == pytest.approx(2.0)
    assert max_stable_step("euler", [0.0]) == math.inf
    with pytest.raises(ValueError, match="continuous-time"):
        max_stable_step("rk4", control.c2d(qc.quarter_car(road=True), 0.01))


def test_numerical_modes_euler_closed_form():
    h = 0.01
    nm = numerical_modes("euler", h)
    for name, lam in (
        ("body bounce", qc.modal_analysis().body.eigenvalue),
        ("wheel hop", qc.modal_analysis().wheel.eigenvalue),
    ):
        lam_h = cmath.log(1 + h * lam) / h
        assert nm.loc[name, "fd_h [Hz]"] == pytest.approx(lam_h.imag / (2 * math.pi), rel=1e-12)
        assert nm.loc[name, "zeta_h"] == pytest.approx(-lam_h.real / abs(lam_h), rel=1e-12)
        assert nm.loc[name, "zeta error"] < 0  # Euler adds negative damping


@pytest.mark.parametrize("zeta, sign", [(0.25, -1), (0.0005, +1)])
def test_rk4_damping_error_sign_follows_the_series(zeta, sign):
    """h lambda_h = z - z^5/120 + z^6/144: RK4 damps only modes with zeta < h|lambda|/6.

    The seed (nominal 0.25: body zeta 0.068 > 0.068/6) loses a little damping;
    a nearly undamped car (body zeta 1.4e-4 < 0.011) gains a little.
    """
    h = 0.01
    params = qc.QuarterCarParams(zeta=zeta)
    nm = numerical_modes("rk4", h, params)
    lam = qc.modal_analysis(params).body.eigenvalue
    y, delta = h * abs(lam), math.asin(-lam.real / abs(lam))
    predicted = y**5 * math.sin(5 * delta) / 120 - y**6 * math.cos(6 * delta) / 144
    assert math.copysign(1, -predicted) == sign
    assert math.copysign(1, nm.loc["body bounce", "zeta error"]) == sign
    # the whole shift is below the leading term's size (h|lambda|)^4 |lambda|-scaled
    assert (nm["zeta error"].abs() < nm["h*|lambda|"] ** 4 / 10).all()


def test_low_order_methods_damping_signs():
    assert (numerical_modes("euler", 0.01)["zeta error"] < 0).all()
    assert (numerical_modes("heun", 0.01)["zeta error"] > 0).all()


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("h", [0.002, 0.01])
def test_modes_measured_from_responses(method, h):
    """Project each simulated response onto the left eigenvectors of A.

    Along a mode the method multiplies by R(h lambda) each step, so the
    ratio of successive modal coordinates measures lambda_h = ln(ratio)/h
    from the response alone; it must equal numerical_modes (rounding:
    1e-9 relative) and approach modal_analysis as h -> 0.
    """
    sys = qc.quarter_car()
    T = np.arange(0, 301) * h
    x = qc.initial_response(sys, T, [0.1, -0.3, 0.05, 0.01], method=method).states
    lam, V = np.linalg.eig(np.asarray(sys.A))
    z = np.linalg.solve(V, x)
    nm = numerical_modes(method, h, sys)
    ma = qc.modal_analysis(sys)
    for mode in ma.modes:
        i = int(np.argmin(abs(lam - mode.eigenvalue)))
        # measure while the mode is well above rounding (the wheel decays ~9% a step)
        live = np.abs(z[i]) > 1e-6 * np.abs(z[i, 0])
        n = int(np.argmin(live)) if not live.all() else live.size
        lam_h = np.mean(np.log(z[i, 1:n] / z[i, : n - 1])) / h
        fd_h, zeta_h = lam_h.imag / (2 * math.pi), -lam_h.real / abs(lam_h)
        assert fd_h == pytest.approx(nm.loc[mode.name, "fd_h [Hz]"], rel=1e-9)
        assert zeta_h == pytest.approx(nm.loc[mode.name, "zeta_h"], rel=1e-8)
        # against the exact mode: the method's own error, bounded by (h|lambda|)^p
        # (local error of R(z) against e^z is |z|^(p+1)/(p+1)!, i.e. |z|^p per unit z)
        bound = (h * abs(mode.eigenvalue)) ** METHODS[method].order
        assert abs(fd_h - mode.fd) / mode.fd < bound
        assert abs(zeta_h - mode.zeta) < bound


def test_bad_h():
    with pytest.raises(ValueError, match="h must be a finite step > 0 s, got -0.1"):
        numerical_modes("rk4", -0.1)
