"""The one stage loop (qc_control.numerics.stepper, compiled_stepper) serves every path.

References: scipy's solve_ivp (DOP853 at rtol 1e-12) on the same equations,
written out here or python-control's own right-hand side (``sys._rhs``, its
iterative interconnection), and the method's order: a third-order tableau
that none of the library's methods is (Kutta's, in a form with a zero
weight) must show an error that falls 8 times per halving of the step on
every path (plain, fused interconnection, batched NumPy, compiled).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.models.nonlinear import NonlinearQuarterCarBatch
from qc_control.numerics import interconnect
from qc_control.numerics.sampled import linear_input
from qc_control.numerics.stepper import GridSteps, stage_plan
from qc_control.studies.nlsweep import simulate_batch

# Kutta's third-order method (Hairer, Nørsett & Wanner, Solving ODEs I, table II.1.1)
KUTTA3 = qc.ButcherTableau(
    "kutta3", a=[[0, 0, 0], [1 / 2, 0, 0], [-1, 2, 0]], b=[1 / 6, 2 / 3, 1 / 6]
)
A = np.asarray(qc.quarter_car().A)
X0 = np.array([0.3, -0.2, 0.05, 0.01])
DESIGNS = [dict(ms=300.0, mu=40.0, ks=ks, ku=2e5, cs=cs) for ks, cs in ((2e4, 1e3), (4e4, 2e3))]


def _reference(f, T, x0):
    """solve_ivp DOP853 at rtol 1e-12 (atol 1e-14 on states of order 0.01-1):
    its error, ~1e-12, is far below the fixed-step errors compared with it (> 1e-9)."""
    sol = solve_ivp(f, (T[0], T[-1]), x0, method="DOP853", t_eval=T, rtol=1e-12, atol=1e-14)
    assert sol.success
    return sol.y


def _order(errors):
    """The observed order from errors at h and h/2."""
    return math.log2(errors[0] / errors[1])


def test_a_batch_steps_as_its_designs_one_by_one():
    """``(n, m)`` states through the loop equal m single-state runs to 1e-14 relative.

    The loop only scales and adds whole arrays, so each column takes the same
    operations as a single state; only ``A @ X`` may sum a column in another
    order than ``A @ x`` (BLAS blocking), an ulp or so per stage, carried by a
    stable system over 1000 steps: well below 1e-14 of the largest state.
    """
    T = np.linspace(0.0, 1.0, 1001)
    X = np.column_stack([X0, 2 * X0, -X0[::-1]])  # (4, 3)
    u = linear_input(T, np.sin(2 * np.pi * 3 * T)[None])
    Bu = np.array([0.0, 1.0, 0.0, 0.0])
    grid = GridSteps(KUTTA3, T.tolist(), 2, None)
    out = np.empty((T.size, *X.shape))
    out[0] = X
    grid.run(lambda t, x: A @ x + Bu[:, None] * u(t)[0], X, out, 0, T.size - 1)
    for j in range(X.shape[1]):
        one = qc.integrate(lambda t, x: A @ x + Bu * u(t)[0], T, X[:, j], KUTTA3, substeps=2)
        assert np.max(np.abs(out[:, :, j].T - one.x)) <= 1e-14 * np.max(np.abs(one.x))


def test_integrate_takes_a_batch_through_the_same_loop():
    """`qc.integrate` on an ``(m, n)`` batch: each row is its single run (1e-14, as above)."""
    T = np.linspace(0.0, 1.0, 501)
    X = np.stack([X0, 3 * X0])
    batch = qc.integrate(lambda t, x: x @ A.T, T, X, KUTTA3)
    for j in range(2):
        one = qc.integrate(lambda t, x: A @ x, T, X[j], KUTTA3)
        assert np.max(np.abs(batch.x[j] - one.x)) <= 1e-14 * np.max(np.abs(one.x))


def test_custom_tableau_plain_path_has_its_order():
    """`qc.integrate` with Kutta 3 against solve_ivp: error falls at order 3."""
    errors = []
    for N in (201, 401):
        T = np.linspace(0.0, 1.0, N)
        ref = _reference(lambda t, x: A @ x, T, X0)
        sol = qc.integrate(lambda t, x: A @ x, T, X0, KUTTA3)
        errors.append(np.max(np.abs(sol.x - ref)) / np.max(np.abs(ref)))
    assert 2.7 < _order(errors) < 3.3  # asymptotic order 3, to ±10 %


def _smooth_skyhook():
    """The seed car closed by a smooth (tanh) skyhook: a StateSpace and a static nlsys."""
    ss = qc.quarter_car(road=True, actuator=True)
    car = control.ss(
        ss.A, ss.B, np.eye(4)[:2], np.zeros((2, 2)), inputs=["zr", "fa"],
        outputs=["vs_m", "vu_m"], states=ss.state_labels, name="car",
    )  # fmt: skip
    sky = control.nlsys(
        None, lambda t, x, u, p: [-800.0 * math.tanh(u[0] / 0.1)], inputs=["vs_m", "vu_m"],
        outputs=["fa"], name="sky",
    )  # fmt: skip
    return control.interconnect([car, sky], inputs="zr", outputs=["vs_m"], name="cl")


def test_custom_tableau_fused_interconnection_has_its_order(monkeypatch):
    """The fused interconnection steps (its stage callback in the one loop) with Kutta 3,
    against solve_ivp on python-control's own ``_rhs``: order 3."""
    cl = _smooth_skyhook()
    fused = []
    original = interconnect.CompiledInterconnect.fused
    monkeypatch.setattr(
        interconnect.CompiledInterconnect,
        "fused",
        lambda self, *a, **k: fused.append(original(self, *a, **k)) or fused[-1],
    )
    errors = []
    for N in (201, 401):
        T = np.linspace(0.0, 1.0, N)
        ref = _reference(lambda t, x: cl._rhs(t, x, np.zeros(1)), T, X0)
        r = qc.input_output_response(cl, T, 0.0, X0, method=KUTTA3)
        errors.append(np.max(np.abs(r.states - ref)) / np.max(np.abs(ref)))
    assert fused and all(f is not None for f in fused)  # the fused path ran
    assert 2.7 < _order(errors) < 3.3


def _nonlinear_rhs(design, k3):
    """The nonlinear car with a cubic spring and a linear tire, no gravity, no road,
    written out: x = (vs, vu, xs, xu)."""
    ms, mu, ks, ku, cs = (design[k] for k in ("ms", "mu", "ks", "ku", "cs"))

    def f(t, x):
        vs, vu, xs, xu = x
        d = xs - xu
        force = ks * d + k3 * d**3 + cs * (vs - vu)
        return [-force / ms, (force - ku * xu) / mu, vs, vu]

    return f


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "numpy"])
def test_custom_tableau_batched_nonlinear_paths_have_its_order(compiled, monkeypatch):
    """A batch of nonlinear cars with Kutta 3, by the compiled stage loop and by the
    NumPy path, against solve_ivp on the equations written out here: order 3."""
    k3 = 3e6
    model = qc.nonlinear_quarter_car_model(spring=k3, tire="linear", gravity=False)
    if not compiled:
        monkeypatch.setattr(NonlinearQuarterCarBatch, "compiled_stepper", lambda self: None)
    errors = []
    for N in (201, 401):
        T = np.linspace(0.0, 1.0, N)
        dynamics = model.batch_dynamics(DESIGNS)
        assert (dynamics.compiled_stepper() is not None) == compiled
        batch = simulate_batch(dynamics, T, X0, None, KUTTA3)
        refs = [_reference(_nonlinear_rhs(d, k3), T, X0) for d in DESIGNS]
        errors.append(
            max(np.max(np.abs(batch.states[j] - r)) / np.max(np.abs(r)) for j, r in enumerate(refs))
        )
    assert 2.7 < _order(errors) < 3.3


def test_compiled_and_numpy_paths_agree_on_a_custom_tableau(monkeypatch):
    """Kutta 3 by both batched paths: equal to rounding (the sums in other orders;
    1e-13 of the largest state, as tests/test_nlsweep.py holds RK4)."""
    T = np.linspace(0.0, 1.0, 1001)
    model = qc.nonlinear_quarter_car_model(spring=3e6)
    zr = 0.05 * np.sin(2 * np.pi * 2 * T)
    compiled = simulate_batch(model.batch_dynamics(DESIGNS), T, X0, zr, KUTTA3, substeps=2)
    monkeypatch.setattr(NonlinearQuarterCarBatch, "compiled_stepper", lambda self: None)
    plain = simulate_batch(model.batch_dynamics(DESIGNS), T, X0, zr, KUTTA3, substeps=2)
    scale = np.max(np.abs(plain.states))
    assert np.max(np.abs(compiled.states - plain.states)) <= 1e-13 * scale


def test_stage_plan_is_the_tableau():
    """The plan's rows rebuild ``h a``, ``h b`` and ``c h`` exactly."""
    plan = stage_plan(KUTTA3)
    h = 0.01
    v = plan.coefficients * h
    a = np.zeros((3, 3))
    for i, (pc, terms) in enumerate(plan.stages, start=1):
        assert v[pc] == KUTTA3.c[i] * h
        for j, pa in terms:
            a[i, j] = v[pa]
    np.testing.assert_array_equal(a, KUTTA3.a * h)
    b = np.zeros(3)
    for pb, i0, rest in (plan.first, *plan.others):
        b[[i0, *rest]] = v[pb]
    np.testing.assert_array_equal(b, KUTTA3.b * h)


def test_linear_input_one_and_many_agree_and_hit_the_samples():
    """The one interpolation: a call and ``at`` give the same bits; a sample time gives
    the sample; in between, the chord (to rounding: 1e-15 of the values)."""
    T = np.linspace(0.0, 1.0, 11)
    U = np.vstack([np.sin(T), T**2])
    u = linear_input(T, U)
    times = np.array([0.0, 0.03, 0.5, 0.77, 1.0])
    many = u.at(times)
    for t, row in zip(times, many):
        np.testing.assert_array_equal(u(float(t)), row)
    np.testing.assert_array_equal(u.at(T), U.T)
    for t, row in zip(T, U.T):
        np.testing.assert_array_equal(u(float(t)), row)
    # in between: the chord through the neighbouring samples, to rounding (4 ulps)
    i = np.searchsorted(T, times[1:-1], side="right") - 1
    w = (times[1:-1] - T[i]) / (T[i + 1] - T[i])
    chord = (U[:, i] * (1 - w) + U[:, i + 1] * w).T
    np.testing.assert_allclose(many[1:-1], chord, rtol=1e-15, atol=1e-16)


def test_a_single_input_as_a_float_is_the_call_to_the_bit():
    """`SampledInput.scalar` (the linear car's cheap right-hand side on one road) reads the
    same slope and sample with the same operations: bit for bit the call's value, at the
    samples, between them, before the first and past the last; more inputs are refused."""
    T = np.linspace(0.0, 1.0, 101)
    u = linear_input(T, np.sin(7 * T)[None])
    one = u.scalar()
    times = [
        -0.5,
        0.0,
        1e-9,
        0.0137,
        0.5,
        0.73456,
        0.99999,
        1.0,
        1.5,
        *np.random.default_rng(1).random(50),
    ]
    for t in times:
        assert one(float(t)) == u(float(t))[0]  # exact: the same float operations
        assert one(np.float64(t)) == u(float(t))[0]  # the stepper's times may be NumPy floats
    with pytest.raises(ValueError, match="one input"):
        linear_input(T, np.vstack([T, T])).scalar()


_CACHED_RUN = """
import numpy as np, qc_control as qc
from qc_control.models import nlkernel
from qc_control.studies.nlsweep import simulate_batch
T = np.linspace(0.0, 0.1, 101)
design = dict(ms=300.0, mu=40.0, ks=2e4, ku=2e5, cs=1e3)
simulate_batch(qc.nonlinear_quarter_car_model().batch_dynamics([design]), T, np.zeros(4), 0.01 * T)
print(sum(nlkernel.advance.stats.cache_hits.values()))
"""


@pytest.mark.slow  # compiles the nonlinear car's steps once (several seconds)
def test_the_compiled_steps_are_cached_on_disk(tmp_path):
    """The model's function with the numerics' stage loop inlined is cached by numba:
    a second process loads its machine code (a cache hit) instead of compiling."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    hits = []
    for _ in range(2):
        args = [sys.executable, "-c", _CACHED_RUN]
        run = subprocess.run(args, capture_output=True, text=True, env=env, timeout=300)
        assert run.returncode == 0, run.stderr
        hits.append(int(run.stdout.split()[-1]))
    assert hits == [0, 1]
