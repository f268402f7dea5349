"""Controllers and closed loops against independent references.

References and tolerances:

* LQR: the gain from scipy's continuous algebraic Riccati solver with the
  cross term (``solve_continuous_are(..., s=N)``, ``K = R⁻¹(BᵀP + Nᵀ)``),
  not from control.lqr; the closed loop's poles against ``eig(A - bK)``.
  Both are well-conditioned 4x4 problems: 1e-8 relative leaves orders of
  magnitude for rounding in the two Riccati solvers.
* Linear closed loops through the fixed-step responses against
  ``control.forced_response`` (the exact solution for an input linear
  between samples): RK4 at h = 1 ms on poles up to |λ| ~ 30 1/s has local
  error (h|λ|)⁵/120 ~ 2e-10 per step of the signal; 1e-6 of the largest
  sample leaves a wide margin (measured below 1e-8).
* Semi-active passivity holds exactly: the force is ``-c·vrel`` with
  ``c >= 0``, and a product's sign is exact in floating point.
* Improvements over the passive seed car are on the same road, computed
  exactly (control.forced_response) for linear loops; the semi-active ones
  by RK4 at 1 ms, checked here against solve_ivp at rtol 1e-9.
"""

import control
import numpy as np
import pytest
import scipy.linalg

import qc_control as qc
from qc_control.models import controllers as C
from qc_control.ride import road

CAR = qc.quarter_car_model(road=True, actuator=True)
SEED = qc.quarter_car_model(road=True)
T_ROAD = np.linspace(0.0, 10.0, 2001)  # 5 ms: resolves the ISO band at 20 m/s (8.8 ms)
ZR = road.iso8608(T_ROAD, "C", speed=20.0, seed=3)
T_BUMP = np.linspace(0.0, 3.0, 3001)
BUMP = road.bump(T_BUMP)
T_SHORT = np.linspace(0.0, 1.5, 751)  # 2 ms: the nonlinear loops step in Python
BUMP_SHORT = road.bump(T_SHORT)

SEMI_ACTIVE = {
    "skyhook on-off": C.skyhook(3000.0, semi_active="on-off", cmin=100.0, cmax=4000.0),
    "skyhook continuous": C.skyhook(3000.0, semi_active="continuous", cmin=100.0, cmax=4000.0),
    "groundhook on-off": C.groundhook(3000.0, semi_active="on-off", cmin=100.0, cmax=4000.0),
    "hybrid continuous": C.hybrid(3000.0, 0.5, semi_active="continuous", cmin=100.0, cmax=4000.0),
    "ADD": C.add_damper(100.0, 4000.0),
}


def exact(model, T, U):
    return control.forced_response(model.system, T, U)


def rms(model, resp, column):
    return qc.ride_metrics(resp, model)[column]


def state(resp, label):
    return np.asarray(resp.states)[list(resp.state_labels).index(label)]


def output(resp, label):
    return np.asarray(resp.outputs)[list(resp.output_labels).index(label)]


# ---------------------------------------------------------------- LQR


def test_lqr_gain_solves_the_riccati_equation_and_places_the_poles():
    weights = {"body_acc": 1.0, "susp_travel": 1e3, "tire_defl": 1e5, "fa": 1e-6}
    ctrl = C.lqr_controller(CAR, weights)
    A = np.asarray(CAR.system.A)
    b = np.asarray(CAR.system.B)[:, [1]]
    # the cost written out independently: z = [body_acc, travel, tire_defl] at zr = 0
    Cz = np.array(
        [A[0], [0, 0, 1, -1], [0, 0, 0, 1]]
    )  # rows: body_acc = first row of A, xs - xu, xu
    Dz = np.array([[b[0, 0]], [0.0], [0.0]])
    W = np.diag([1.0, 1e3, 1e5])
    Q, R, N = Cz.T @ W @ Cz, Dz.T @ W @ Dz + 1e-6, Cz.T @ W @ Dz
    P = scipy.linalg.solve_continuous_are(A, b, Q, R, s=N)
    K = np.linalg.solve(R, b.T @ P + N.T)
    # fed back in relative coordinates z = [vs, vu, xs - xu, xu - zr] = T x (flat road)
    T = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]], dtype=float)
    np.testing.assert_allclose(-np.asarray(ctrl.D), K @ np.linalg.inv(T), rtol=1e-8)
    assert ctrl.input_labels == ["vs", "vu", "susp_travel", "tire_defl"]
    cl = qc.closed_loop(CAR, ctrl)
    assert isinstance(cl.system, control.StateSpace)
    want = np.sort_complex(np.linalg.eigvals(A - b @ K))
    np.testing.assert_allclose(np.sort_complex(cl.system.poles()), want, rtol=1e-8)
    assert np.all(want.real < 0)


def test_lqr_with_estimator_poles_are_regulator_and_filter_poles():
    """Separation principle: the closed loop's poles are eig(A-bK) and eig(A_z-LC_z).

    The filter runs in z = [vs, vu, travel, tire_defl], driven by the road
    velocity (intensity 1e-3 m²/s by default); its gain here from scipy's
    dual Riccati equation.
    """
    ctrl = C.lqr_controller(CAR, estimator={"outputs": ["susp_travel", "body_acc"]})
    assert ctrl.input_labels == ["susp_travel", "body_acc"] and ctrl.nstates == 4
    A, B = np.asarray(CAR.system.A), np.asarray(CAR.system.B)
    T = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]], dtype=float)
    Az = T @ A @ np.linalg.inv(T)
    G = np.array([[0.0], [0.0], [0.0], [-1.0]])  # tire_defl' = vu - zr'
    Cz = np.asarray(CAR.system.C)[[2, 4]] @ np.linalg.inv(T)
    QN, RN = np.array([[1e-3]]), np.diag([1e-7, 1e-3])
    S = scipy.linalg.solve_continuous_are(Az.T, Cz.T, G @ QN @ G.T, RN)
    L = S @ Cz.T @ np.linalg.inv(RN)
    K = -np.asarray(C.lqr_controller(CAR).D) @ T  # back in x coordinates
    want = np.concatenate([np.linalg.eigvals(A - B[:, [1]] @ K), np.linalg.eigvals(Az - L @ Cz)])
    got = qc.closed_loop(CAR, ctrl).system.poles()
    np.testing.assert_allclose(np.sort_complex(got), np.sort_complex(want), rtol=1e-7)


# ---------------------------------------------------------------- linear loops in every tool


@pytest.mark.parametrize("method", ["euler", "midpoint", "heun", "rk4"])
def test_linear_closed_loops_run_through_fixed_step_responses(method):
    """Each linear loop at h = 1 ms against the exact response.

    The global error of an order-p method is about (t·|λ|)·C·(h|λ|)^p of the
    signal; here h|λ|max <= 0.027 (fastest pole 26.5 1/s, groundhook), and
    the bounds are 3x the largest measured over the four loops (Euler 5.1e-2,
    Midpoint and Heun 2.9e-4, RK4 1.4e-8 of the largest sample).
    """
    bound = {"euler": 0.15, "midpoint": 1e-3, "heun": 1e-3, "rk4": 5e-8}[method]
    for ctrl in (C.skyhook(3e3), C.groundhook(3e3), C.hybrid(3e3), C.lqr_controller(CAR)):
        cl = qc.closed_loop(CAR, ctrl)
        ours = qc.forced_response(cl.system, T_BUMP, BUMP, method=method)
        ref = exact(cl, T_BUMP, BUMP)
        y, y_ref = np.asarray(ours.outputs), np.asarray(ref.outputs)
        scale = np.abs(y_ref).max(axis=1, keepdims=True)
        assert np.max(np.abs(y - y_ref) / scale) < bound, ctrl.name
        assert ours.output_labels == [*CAR.system.output_labels, "fa"]


def test_closed_loop_in_compare_methods_and_transmissibility():
    cl = qc.closed_loop(CAR, C.skyhook(3000.0))
    T = np.linspace(0.0, 2.0, 401)
    cmp = qc.compare_methods(cl, T, U=road.bump(T), repeats=1, timing=False)
    # observed orders of the four methods on the closed loop, +-0.25
    orders = cmp.table["observed order"]
    np.testing.assert_allclose(orders.to_numpy(float), [1, 2, 2, 4], atol=0.25)
    # transmissibility of the closed loop at zr: H = C(jωI - A)⁻¹B + D by hand
    tr = qc.transmissibility(cl.system, [1.0])
    A, B = np.asarray(cl.system.A), np.asarray(cl.system.B)
    Cm, D = np.asarray(cl.system.C), np.asarray(cl.system.D)
    H = Cm @ np.linalg.solve(2j * np.pi * np.eye(4) - A, B) + D
    np.testing.assert_allclose(tr.response["body_acc"], H[cl.output("body_acc"), 0], rtol=1e-10)


def test_closed_loop_in_a_sweep():
    """The same controller closed around rebuilt cars, against exact responses.

    sweep steps RK4 at the grid's 5 ms on poles up to 25 1/s (h|λ| = 0.13):
    1e-4 relative on RMS body acceleration (measured 0.8e-6 and 1.5e-6).
    """
    cl = qc.closed_loop(CAR, C.skyhook(3000.0))
    T = np.linspace(0.0, 3.0, 601)
    U = road.bump(T)
    result = qc.sweep({"ks": [2e4, 4e4]}, T=T, X0=np.zeros(4), model=cl, U=U)
    for i, ks in enumerate([2e4, 4e4]):
        loop = cl.rebuild(qc.QuarterCarParams(ks=ks))
        exact_rms = rms(loop, exact(loop, T, U), "rms_body_acc [m/s²]")
        assert result.metrics["rms_body_acc [m/s²]"].iloc[i] == pytest.approx(exact_rms, rel=1e-4)


# ---------------------------------------------------------------- semi-active


@pytest.mark.parametrize("method", ["euler", "midpoint", "heun", "rk4"])
def test_semi_active_force_is_passive_on_every_sample(method):
    for name, ctrl in SEMI_ACTIVE.items():
        cl = qc.closed_loop(CAR, ctrl)
        assert isinstance(cl.system, control.NonlinearIOSystem)
        assert not isinstance(cl.system, control.StateSpace)
        resp = qc.input_output_response(cl.system, T_SHORT, BUMP_SHORT, method=method)
        assert resp.success, name
        fa = output(resp, "fa")
        vrel = state(resp, "vs") - state(resp, "vu")
        assert np.all(fa * vrel <= 0.0), name
        # and within the damper's range: cmin|vrel| <= |fa| <= cmax|vrel|
        assert np.all(np.abs(fa) <= 4000.0 * np.abs(vrel) * (1 + 1e-12)), name
        assert np.all(np.abs(fa) >= 100.0 * np.abs(vrel) * (1 - 1e-12)), name
        assert np.any(np.abs(fa) > 100.0 * np.abs(vrel) * 1.5), f"{name} never switched"


@pytest.mark.slow  # solve_ivp on python-control's interconnection: about 5 s
def test_semi_active_fixed_step_agrees_with_solve_ivp():
    """The continuous clipped skyhook at RK4, 1 ms, against solve_ivp.

    solve_ivp at rtol 1e-10, atol 1e-13 and at most 1 ms a step (so that it
    cannot step over the bump). The law is continuous but not smooth
    (clipping corners), which caps RK4's order; measured 5.6e-5 of the
    largest sample (on the force), bound 3e-4.
    """
    cl = qc.closed_loop(CAR, SEMI_ACTIVE["skyhook continuous"])
    ours = qc.input_output_response(cl.system, T_SHORT, BUMP_SHORT, method="rk4", substeps=2)
    ref = control.input_output_response(
        cl.system,
        T_SHORT,
        BUMP_SHORT,
        solve_ivp_kwargs={"rtol": 1e-10, "atol": 1e-13, "max_step": 1e-3},
    )
    y, y_ref = np.asarray(ours.outputs), np.asarray(ref.outputs)
    scale = np.abs(y_ref).max(axis=1, keepdims=True)
    assert np.max(np.abs(y - y_ref) / scale) < 3e-4


# ---------------------------------------------------------------- what each law is for


def test_skyhook_improves_the_body_on_an_iso_road():
    """Skyhook's purpose: RMS body acceleration on a class C road at 20 m/s.

    Ideal: exact response (measured 0.57 against 1.01 m/s² passive); the
    semi-active devices (in parallel with the seed's damper, so the total
    damping is between cs and cs + cmax) by RK4 at the road's 5 ms (h|λ| <=
    0.2 on the car's modes; the ADD's 50 Hz sensor pole at h|λ| = 1.6 is
    within RK4's stability limit 2.78).
    """
    passive = rms(SEED, exact(SEED, T_ROAD, ZR), "rms_body_acc [m/s²]")
    sky = qc.closed_loop(CAR, C.skyhook(3000.0))
    assert rms(sky, exact(sky, T_ROAD, ZR), "rms_body_acc [m/s²]") < 0.7 * passive
    for law in (
        C.skyhook(3000.0, semi_active="on-off", cmax=4000.0),
        C.add_damper(0.0, 4000.0),
    ):
        cl = qc.closed_loop(CAR, law)
        resp = qc.input_output_response(cl.system, T_ROAD, ZR, method="rk4")
        assert rms(cl, resp, "rms_body_acc [m/s²]") < 0.95 * passive, law.name


def test_groundhook_improves_the_tire_load_at_wheel_hop():
    """Groundhook's purpose: the dynamic tire load in the wheel-hop band.

    On the seed car the tire is as soft as the suspension spring (ku ≈ ks),
    so on an ISO road the body mode carries most of the tire load and
    groundhook, which gives up body damping, does not lower its RMS (see the
    control report); in the wheel-hop band it does. Ideal law: the peak of
    |tire_defl/zr| over 3-10 Hz from control.frequency_response (measured
    1.17 against 1.30); semi-active on-off: RMS tire load on a 5 Hz sine
    road, RK4 at 2 ms (measured 0.058 against 0.068 passive, exact).
    """
    f = np.linspace(3.0, 10.0, 141)
    w = 2 * np.pi * f

    def peak(model):
        j = model.system.input_labels.index("zr")
        H = np.asarray(control.frequency_response(model.system, w).complex)
        return np.abs(H[model.output("tire_defl"), j]).max()

    gnd = qc.closed_loop(CAR, C.groundhook(1000.0))  # the ideal law is unstable beyond ~1.2e3
    assert peak(gnd) < 0.95 * peak(SEED)
    T = np.linspace(0.0, 4.0, 2001)
    U = road.sine(T, 0.01, 5.0)
    passive = rms(SEED, exact(SEED, T, U), "rms_tire_load / static [-]")
    cl = qc.closed_loop(CAR, C.groundhook(1000.0, semi_active="on-off", cmax=4000.0))
    resp = qc.input_output_response(cl.system, T, U, method="rk4")
    assert rms(cl, resp, "rms_tire_load / static [-]") < 0.9 * passive


# ---------------------------------------------------------------- H-infinity


def test_hinf_gamma_is_the_closed_loop_norm():
    pytest.importorskip("slycot")
    design = C.hinf_controller(CAR, beta=0.5)
    P, K = design.plant, design.K
    # the weighted closed loop by hand (lower LFT, positive feedback as sb10ad)
    Pn = control.ss(P, name="P")
    Kn = control.ss(K.A, K.B, K.C, K.D, inputs=["y1", "y2"], outputs=["u"], name="K")
    cl = control.interconnect(
        [Pn, Kn],
        inplist=["d1", "d2", "d3"],
        outlist=["e1", "e2", "e3"],
        connections=[["P.u", "K.u"], ["K.y1", "P.y1"], ["K.y2", "P.y2"]],
    )
    assert np.max(cl.poles().real) < 0
    # the H-infinity norm as the largest singular value on a dense grid
    w = np.logspace(-3, 4, 20000)
    H = np.asarray(control.frequency_response(cl, w).complex).transpose(2, 0, 1)
    sweep = np.linalg.svd(H, compute_uv=False).max()
    assert abs(design.gamma - sweep) <= 0.01 * sweep
    assert design.norm <= design.gamma * (1 + 1e-6)
    # the physical closed loop: stable and damped (every pole ζ >= 0.2)
    poles = qc.closed_loop(CAR, design.controller).system.poles()
    assert np.all(poles.real < 0)
    assert np.min(-poles.real / np.abs(poles)) > 0.2


@pytest.mark.slow
def test_hinf_reproduces_matlab_example_gammas():
    """MATLAB's published γ for its own car (mb 300, mw 60, bs 1000, ks 16000, kt 190000).

    The example reports γ = 0.9405, 0.6727, 0.8892 for β = 0.01, 0.5, 0.99
    (hinfsyn's default relative tolerance is 1%, so 1% here).
    """
    pytest.importorskip("slycot")
    params = qc.QuarterCarParams(ms=300.0, mu=60.0, ks=16000.0, ku=190000.0, cs=1000.0)
    car = qc.quarter_car_model(params, road=True, actuator=True)
    for beta, published in ((0.01, 0.9405), (0.5, 0.6727), (0.99, 0.8892)):
        gamma = C.hinf_controller(car, beta).gamma
        assert abs(gamma - published) <= 0.01 * published, (beta, gamma)


def test_hinf_without_slycot_says_how_to_install(monkeypatch):
    monkeypatch.setattr(C, "slycot", None)
    with pytest.raises(ImportError, match=r"qc-control\[robust\]"):
        C.hinf_controller(CAR)


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: C.skyhook(-1.0), "c_sky"),
        (lambda: C.skyhook(1.0, semi_active="maybe"), "semi_active"),
        (lambda: C.skyhook(1.0, semi_active="on-off"), "cmax"),
        (
            lambda: C.groundhook(1.0, semi_active="on-off", cmin=5.0, cmax=2.0),
            r"cmax \(.*\) must be > cmin = 5.0 N·s/m, got 2.0",
        ),
        (lambda: C.hybrid(1.0, alpha=1.5), "alpha"),
        (lambda: C.add_damper(0.0, 10.0, sensor_hz=0.0), "sensor_hz"),
        (lambda: C.lqr_controller(CAR, {"nope": 1.0}), "nope"),
        (lambda: C.hinf_controller(CAR, beta=1.5), "beta"),
        (lambda: C.hinf_controller(CAR, rtol=2.0), "rtol"),
        (lambda: C.lqr_controller(SEED), "actuator input 'fa'"),
        (lambda: qc.closed_loop(SEED, C.skyhook(1.0)), "actuator input 'fa'"),
        (
            lambda: qc.closed_loop(CAR, control.ss([], [], [], [[1.0]], inputs="q", outputs="fa")),
            "'q'",
        ),
        (
            lambda: qc.closed_loop(CAR, control.ss([], [], [], [[1.0]], inputs="vs", outputs="f")),
            "output 'fa'",
        ),
    ],
)
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


@pytest.mark.parametrize("mode", ["on-off", "continuous"])
def test_semi_active_coefficient_one_sample_equals_the_definition(mode):
    """The float path (one stage of a run) against the law written out, and the array path.

    The law (Karnopp et al. 1974, clipped): c = cmax (on-off) or
    clip(-f/v, cmin, cmax) (continuous) where f·v < 0, else cmin. Equality is
    exact: the same comparisons and one division.
    """
    rng = np.random.default_rng(3)
    f = np.concatenate([rng.normal(scale=3e3, size=200), [0.0, 1.0, -1.0, np.nan]])
    v = np.concatenate([rng.normal(scale=1.0, size=200), [1.0, 0.0, -0.0, 0.5]])
    cmin, cmax = 300.0, 4000.0
    arrays = C.semi_active_coefficient(f, v, cmin, cmax, mode)
    for fi, vi, ca in zip(f, v, arrays):
        if fi * vi < 0:
            want = cmax if mode == "on-off" else min(max(-fi / vi, cmin), cmax)
        else:
            want = cmin
        got = C.semi_active_coefficient(float(fi), float(vi), cmin, cmax, mode)
        assert got == want == ca
