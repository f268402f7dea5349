"""Stability functions, step limits and numerical modes against closed forms."""

import cmath
import math
import types
import warnings

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control import METHODS, max_stable_step, stability_function
from qc_control.numerics.stability import (
    MARGINAL_RTOL,
    amplification,
    eigenvalues_of,
    numerical_modes,
    step_is_stable,
)

SEED_SYS = qc.quarter_car()
SEED_EIG = np.linalg.eigvals(np.asarray(SEED_SYS.A))
SQRT8 = 2 * math.sqrt(2)  # RK4's reach on the imaginary axis, |R(iy)| <= 1 for |y| <= 2√2

RALSTON = qc.ButcherTableau("ralston", a=[[0, 0], [2 / 3, 0]], b=[1 / 4, 3 / 4], c=[0, 2 / 3])
THREE_EIGHTHS = qc.ButcherTableau(
    "3/8",
    a=[[0, 0, 0, 0], [1 / 3, 0, 0, 0], [-1 / 3, 1, 0, 0], [1, -1, 1, 0]],
    b=[1 / 8, 3 / 8, 3 / 8, 1 / 8],
    c=[0, 1 / 3, 2 / 3, 1],
)
ALL = [*METHODS.values(), RALSTON, THREE_EIGHTHS]
# Step limit on the imaginary axis, in units of 1/|λ|: |R(iy)|² - 1 is y² (Euler),
# y⁴/4 (every 2-stage order-2 method: R = 1 + z + z²/2), or -y⁶/72 + y⁸/576 (every
# 4-stage order-4 method: R = 1 + z + ... + z⁴/24); HW II, §IV.2.
AXIS_LIMIT = {
    "euler": 0.0,
    "midpoint": 0.0,
    "heun": 0.0,
    "ralston": 0.0,
    "rk4": SQRT8,
    "3/8": SQRT8,
}


SEED_CS = 0.25 * 2 * math.sqrt(30000.0 * 301.2)  # nominal ζ = 0.25: cs = 2ζ√(ks ms)


def seed_system(cs=SEED_CS, ms=301.2, mu=100.0, ks=30000.0, ku=29530.0):
    """The seed's quarter car, built here from its matrix A (no model.py)."""
    A = [
        [-cs / ms, cs / ms, -ks / ms, ks / ms],
        [cs / mu, -cs / mu, ks / mu, -(ks + ku) / mu],
        [1, 0, 0, 0],
        [0, 1, 0, 0],
    ]
    return control.ss(A, np.zeros((4, 1)), np.eye(4), np.zeros((4, 1)))


def undamped_frequencies(ms=301.2, mu=100.0, ks=30000.0, ku=29530.0):
    """ω² solves ω⁴ - (ks/ms + (ks+ku)/mu) ω² + ks ku/(ms mu) = 0 (det(K - ω² M) = 0)."""
    p = ks / ms + (ks + ku) / mu
    q = ks * ku / (ms * mu)
    root = math.sqrt(p * p / 4 - q)
    return math.sqrt(p / 2 - root), math.sqrt(p / 2 + root)


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
    assert max_stable_step("euler", seed_system()) == pytest.approx(expected, rel=1e-12)
    assert round(expected, 5) == 0.01982


@pytest.mark.parametrize(
    "method, quoted", [("euler", 0.0198), ("midpoint", 0.0721), ("heun", 0.0721), ("rk4", 0.1085)]
)
def test_seed_limits_are_first_crossings(method, quoted):
    h = max_stable_step(method, SEED_SYS)
    assert round(h, 4) == quoted
    R = stability_function(method)
    # just below: every mode stable; at h: the worst mode sits on |R| = 1
    assert max(abs(R(0.999 * h * lam)) for lam in SEED_EIG) <= 1
    assert max(abs(R(h * lam)) for lam in SEED_EIG) == pytest.approx(1, abs=1e-10)
    assert max(abs(R(1.001 * h * lam)) for lam in SEED_EIG) > 1
    # and no smaller step is unstable (scan 2000 steps below the limit)
    for hh in np.linspace(1e-6, h, 2000)[:-1]:
        assert max(abs(R(hh * lam)) for lam in SEED_EIG) <= 1 + 1e-12


# -- on and near the imaginary axis


@pytest.mark.parametrize("tab", ALL, ids=lambda t: t.name)
@pytest.mark.parametrize(
    "lam",
    [10j, -1e-9 + 10j, 1e-9 + 10j, -1e-12 + 10j, 3e-15 + 10j],
    ids=["axis", "left 1e-10", "right 1e-10", "left 1e-13", "right 3e-16"],
)
def test_limits_on_and_near_the_imaginary_axis(tab, lam):
    """|Re λ| <= 1e-8 |λ| is rounding: the limit is the axis' own, never inf."""
    h = max_stable_step(tab, [lam, lam.conjugate()])
    assert h == pytest.approx(AXIS_LIMIT[tab.name] / abs(lam), rel=1e-12, abs=0)


@pytest.mark.parametrize("tab", ALL, ids=lambda t: t.name)
def test_limits_just_off_the_axis_are_first_crossings(tab):
    """ζ = 1e-5, above the marginal band: a genuine, small limit found by the crossing."""
    lam = 10 * cmath.exp(1j * (math.pi / 2 + math.asin(1e-5)))
    h = max_stable_step(tab, [lam])
    R = stability_function(tab)
    assert 0 < h < math.inf
    assert abs(R(h * lam)) == pytest.approx(1, abs=1e-12)
    assert abs(R(1.001 * h * lam)) > 1
    for hh in np.linspace(h / 2000, h, 2000)[:-1]:  # stable all the way up
        assert abs(R(hh * lam)) <= 1 + 1e-12
    if AXIS_LIMIT[tab.name]:
        assert h >= AXIS_LIMIT[tab.name] / 10  # damping widens RK4's interval
    else:  # |R|² - 1 ≈ -2ζy + y⁴/4 (order 2) or -2ζy + y² (Euler): tiny limits
        y = h * 10
        expected = 2e-5 if tab.name == "euler" else (8e-5) ** (1 / 3)
        assert y == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("tab", ALL, ids=lambda t: t.name)
def test_undamped_quarter_car(tab):
    """cs = 0: both modes on the axis; the stiffer (wheel hop) sets RK4's limit."""
    sys = seed_system(cs=0.0)
    w_body, w_wheel = undamped_frequencies()
    np.testing.assert_allclose(
        np.sort(np.abs(eigenvalues_of(sys))), [w_body, w_body, w_wheel, w_wheel], rtol=1e-12
    )
    assert max_stable_step(tab, sys) == pytest.approx(AXIS_LIMIT[tab.name] / w_wheel, rel=1e-12)


def test_rounding_that_puts_eigenvalues_right_of_the_axis():
    """An undamped car whose eigenvalues come out at Re λ = +1e-10|λ| (a perturbed A).

    The limits stay the axis' (not 0 for RK4, not inf for anyone), and the check for
    numerical growth is not skipped: Heun grows on an undamped mode at any step.
    """
    w_body, w_wheel = undamped_frequencies()
    # a real matrix with eigenvalues 1e-10 ω ± iω: rotation blocks, in a skewed basis
    J = np.zeros((4, 4))
    for k, w in enumerate((w_body, w_wheel)):
        J[2 * k : 2 * k + 2, 2 * k : 2 * k + 2] = [[1e-10 * w, w], [-w, 1e-10 * w]]
    V = np.array([[1, 2, 0, 1], [0, 1, 3, 0], [2, 0, 1, 1], [1, 1, 1, 4]], dtype=float)
    eig = np.linalg.eigvals(V @ J @ np.linalg.inv(V))
    assert eig.real.max() > 0 and np.all(np.abs(eig.real) <= MARGINAL_RTOL * np.abs(eig))
    assert max_stable_step("rk4", eig) == pytest.approx(SQRT8 / w_wheel, rel=1e-9)
    assert max_stable_step("heun", eig) == 0.0
    assert not step_is_stable("heun", 1e-3, eig)
    assert step_is_stable("rk4", 0.99 * SQRT8 / w_wheel, eig)
    assert not step_is_stable("rk4", 1.01 * SQRT8 / w_wheel, eig)


def test_step_is_stable_batches_and_leaves_out_growing_systems():
    eig = np.stack([SEED_EIG, seed_system(cs=0.0).poles(), SEED_EIG * 3])
    h = 0.9 * max_stable_step("rk4", SEED_EIG)
    np.testing.assert_array_equal(step_is_stable("rk4", h, eig), [True, True, False])
    np.testing.assert_array_equal(step_is_stable("heun", 1e-3, eig), [True, False, True])
    # a system that grows by itself (Re λ = +0.1|λ|) is not the method's instability
    assert step_is_stable("euler", 1e-3, [1 + 10j, 1 - 10j, -5.0])
    assert not step_is_stable("euler", 0.5, [1 + 10j, 1 - 10j, -5.0])  # |1 - 2.5| > 1
    assert step_is_stable("rk4", 0.01, SEED_SYS) is True
    with pytest.raises(ValueError, match="h must be a step >= 0 s, got -1"):
        step_is_stable("rk4", -1, SEED_EIG)


def test_step_is_stable_agrees_with_amplification_off_the_axis():
    rng = np.random.default_rng(5)
    lam = -rng.uniform(0.1, 5, 200) + 1j * rng.uniform(-30, 30, 200)
    for m in METHODS:
        for h in (0.01, 0.05, 0.2):
            for x in lam:
                assert step_is_stable(m, h, [x]) == (amplification(m, h, [x]) <= 1 + 1e-12)


def test_eigenvalue_inputs():
    assert max_stable_step("euler", [-1.0]) == pytest.approx(2.0)
    assert max_stable_step("euler", [0.0]) == math.inf
    assert max_stable_step("euler", [-1.0, 1e-12]) == pytest.approx(2.0)  # rounding of a 0
    assert max_stable_step("euler", [0.5, -1.0]) == 0.0  # a system that grows by itself
    with pytest.raises(ValueError, match="continuous-time"):
        max_stable_step("rk4", control.c2d(qc.quarter_car(road=True), 0.01))


def test_systems_in_every_form():
    """A StateSpace, a TransferFunction, or any object with a .system StateSpace."""
    h = max_stable_step("rk4", SEED_SYS)
    assert max_stable_step("rk4", types.SimpleNamespace(system=SEED_SYS)) == h
    tf = control.tf([1], [1, 2 * 0.1 * 5, 25])  # ω = 5, ζ = 0.1
    lam = np.roots([1, 1, 25])
    assert max_stable_step("euler", tf) == pytest.approx(-2 * lam[0].real / 25, rel=1e-12)
    with pytest.raises(TypeError, match="the .system of SimpleNamespace must be a control"):
        max_stable_step("rk4", types.SimpleNamespace(system="car"))
    with pytest.raises(
        TypeError, match="expected a continuous-time control.StateSpace.*got {'ms': 300.0}"
    ):
        max_stable_step("rk4", {"ms": 300.0})
    with pytest.raises(ValueError, match="eigenvalues must be a finite 1-D array"):
        max_stable_step("rk4", [[-1.0, -2.0]])


def test_swapped_arguments_say_so():
    with pytest.raises(TypeError, match=r"max_stable_step\(method, system.*method comes first"):
        max_stable_step(SEED_SYS, "heun")
    with pytest.raises(TypeError, match=r"numerical_modes\(method, system.*method comes first"):
        numerical_modes(SEED_SYS, 0.01, "heun")
    with pytest.raises(TypeError, match="method must be a name in METHODS.*got a StateSpace"):
        max_stable_step(SEED_SYS, SEED_SYS)


# -- numerical modes


def test_numerical_modes_euler_closed_form():
    h = 0.01
    ma = qc.modal_analysis(SEED_SYS)
    nm = numerical_modes("euler", h, ma)
    for name, lam in (("body bounce", ma.body.eigenvalue), ("wheel hop", ma.wheel.eigenvalue)):
        lam_h = cmath.log(1 + h * lam) / h
        assert nm.loc[name, "fd_h [Hz]"] == pytest.approx(lam_h.imag / (2 * math.pi), rel=1e-12)
        assert nm.loc[name, "zeta_h"] == pytest.approx(-lam_h.real / abs(lam_h), rel=1e-12)
        assert nm.loc[name, "sigma_h [1/s]"] == pytest.approx(-lam_h.real, rel=1e-12)
        assert nm.loc[name, "zeta error"] < 0  # Euler removes damping
        assert nm.loc[name, "decay rate error [%]"] < 0


def test_numerical_modes_of_a_bare_system():
    """One row per eigenvalue, a conjugate pair once, by increasing |λ|."""
    nm = numerical_modes("rk4", 0.01, SEED_SYS)
    assert list(nm.index) == ["mode 1", "mode 2"]
    named = numerical_modes("rk4", 0.01, qc.modal_analysis(SEED_SYS))
    np.testing.assert_array_equal(nm.to_numpy(), named.loc[["body bounce", "wheel hop"]].to_numpy())
    real = numerical_modes("rk4", 0.01, [-3.0, -1 + 2j, -1 - 2j, -40.0])
    assert list(real["fd [Hz]"] > 0) == [True, False, False]  # |-1 + 2j| < 3 < 40
    assert real["sigma [1/s]"].tolist() == [1.0, 3.0, 40.0]


@pytest.mark.parametrize("method", list(METHODS))
def test_overdamped_mode_compares_decay_rates(method):
    """ζ = 5 (issue 14 item 1): real eigenvalues. The old table said Δζ = -8.97 for
    every method and step; the decay rate of each real eigenvalue is what a method
    gets right or wrong, measured here from integrate itself: x_{n+1}/x_n = R(hλ)."""
    ms, ks = 301.2, 30000.0
    sys = seed_system(cs=2 * 5 * math.sqrt(ks * ms))
    ma = qc.modal_analysis(sys)
    # the overdamped one is the relative motion (wheel hop); the car bounces on its tire
    body = next(m for m in ma.modes if m.eigenvalue.imag == 0)
    assert body.name == "wheel hop" and body.zeta > 1
    for h in (1e-5, 1e-3):
        nm = numerical_modes(method, h, ma)
        row = nm.loc[body.name]
        assert math.isnan(row["zeta error"]) and math.isnan(row["zeta_h"])
        assert row["zeta"] == body.zeta  # the pair's own ζ is kept for reference
        lam = body.eigenvalue.real
        x1 = integrate_decay(method, lam, h)[1]  # one step from x0 = 1: R(hλ)
        # x1 is rounded to eps, so the measured ln(x1) carries eps/(h|λ|) relative
        assert row["sigma_h [1/s]"] == pytest.approx(
            -np.log1p(x1 - 1) / h, rel=4 * np.finfo(float).eps / (h * abs(lam)) + 1e-14
        )
        # the method's error in the decay rate is O((h|λ|)^p): below (h|λ|)^p relative,
        # or 1e-13 (the rounding of σ_h from ln R, computed without cancellation)
        bound = 100 * max((h * abs(lam)) ** METHODS[method].order, 1e-13)
        assert abs(row["decay rate error [%]"]) < bound
    nm = numerical_modes(method, 1e-5, sys)  # the bare system: every real eigenvalue a row
    assert nm["fd [Hz]"].eq(0).sum() >= 2 and nm["zeta error"].isna().sum() >= 2


def integrate_decay(method, lam, h):
    return qc.integrate(lambda t, x: lam * x, [0.0, h], [1.0], method).x[0]


@pytest.mark.parametrize("zeta, sign", [(0.25, -1), (0.0005, +1)])
def test_rk4_damping_error_sign_follows_the_series(zeta, sign):
    """h lambda_h = z - z^5/120 + z^6/144: RK4 damps only modes with zeta < h|lambda|/6.

    The seed (nominal 0.25: body zeta 0.068 > 0.068/6) loses a little damping;
    a nearly undamped car (body zeta 1.4e-4 < 0.011) gains a little.
    """
    h = 0.01
    ma = qc.modal_analysis(seed_system(cs=zeta * 2 * math.sqrt(30000.0 * 301.2)))
    nm = numerical_modes("rk4", h, ma)
    lam = ma.body.eigenvalue
    y, delta = h * abs(lam), math.asin(-lam.real / abs(lam))
    predicted = y**5 * math.sin(5 * delta) / 120 - y**6 * math.cos(6 * delta) / 144
    assert math.copysign(1, -predicted) == sign
    assert math.copysign(1, nm.loc["body bounce", "zeta error"]) == sign
    # the whole shift is below the leading term's size (h|lambda|)^4 |lambda|-scaled
    assert (nm["zeta error"].abs() < nm["h*|lambda|"] ** 4 / 10).all()


def test_low_order_methods_damping_signs():
    assert (numerical_modes("euler", 0.01, SEED_SYS)["zeta error"] < 0).all()
    assert (numerical_modes("heun", 0.01, SEED_SYS)["zeta error"] > 0).all()


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("h", [0.002, 0.01])
def test_modes_measured_from_responses(method, h):
    """Project each simulated response onto the left eigenvectors of A.

    Along a mode the method multiplies by R(h lambda) each step, so the
    ratio of successive modal coordinates measures lambda_h = ln(ratio)/h
    from the response alone; it must equal numerical_modes (rounding:
    1e-9 relative) and approach modal_analysis as h -> 0.
    """
    sys = SEED_SYS
    T = np.arange(0, 301) * h
    A = np.asarray(sys.A)
    x = qc.integrate(lambda t, x: A @ x, T, [0.1, -0.3, 0.05, 0.01], method).x
    lam, V = np.linalg.eig(A)
    z = np.linalg.solve(V, x)
    ma = qc.modal_analysis(sys)
    nm = numerical_modes(method, h, ma)
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
        numerical_modes("rk4", -0.1, SEED_SYS)
    with pytest.raises(ValueError, match="h must be a finite step > 0 s, got '0.1'"):
        numerical_modes("rk4", "0.1", SEED_SYS)


def test_no_warnings_from_the_limits():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for tab in ALL:
            max_stable_step(tab, seed_system(cs=0.0))
            max_stable_step(tab, [0.0, 1e-300 + 1j, -1e300])
