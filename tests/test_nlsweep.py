"""Batched nonlinear sweeps (issue 11 item 7): qc_control.studies.nlsweep and sweep's dispatch.

References: `qc.input_output_response` on each design's own
`nonlinear_quarter_car` (the single-system stepper, same method and step),
the linear sweep (the LTI engine: exact step map of the method) in the linear
limit, and scipy's solve_ivp (DOP853, rtol 1e-12, restarted at each contact
event) on the equations written out here.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.models.nonlinear import NonlinearQuarterCarBatch
from qc_control.models.quarter import SEED_X0
from qc_control.ride.metrics import SWEEP_METRICS, RideSignals, evaluate
from qc_control.studies.nlsweep import simulate_batch

G = 9.80665
T2 = np.linspace(0.0, 2.0, 2001)  # h = 1 ms
# a class D road at 20 m/s plus a 6 cm step: the wheel leaves the road and the
# stops engage on the soft designs, so every nonlinearity acts
ROAD = qc.road.iso8608(T2, "D", 20.0, seed=3) + 0.06 * (T2 >= 0.8)
OPTIONS = dict(
    bump_stop=qc.BumpStop(0.03, 1e5, 1e7, clearance_rebound=0.05),
    damper=qc.PiecewiseDamper(1800.0, 900.0, 0.3, 0.2, 600.0, 300.0),
    spring=3e6,
)
DESIGNS = [dict(ms=300.0, mu=40.0, ks=ks, ku=2e5, cs=1000.0) for ks in (1.2e4, 2.5e4, 4e4)] + [
    dict(ms=350.0, mu=55.0, ks=2e4, ku=1.5e5, cs=1000.0)
]
# Same arithmetic as the single car up to folded constants (-F/ms as F·(-1/ms),
# the tire's dynamic force as max(ku(zr - xu), -ku·δ0)): a few ulps per stage,
# carried over 2000 steps of a damped system (observed below 1e-14 relative).
RTOL = 1e-12


def _max_rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize(
    "method, substeps, events",
    [
        # RK4's two runs take over 2 s each; Heun and the midpoint rule keep the quick loop's
        pytest.param("rk4", 1, False, marks=pytest.mark.slow),
        ("heun", 1, False),
        ("midpoint", 2, False),
        pytest.param("rk4", 1, True, marks=pytest.mark.slow),
    ],
)
def test_each_design_is_its_own_input_output_response(method, substeps, events):
    model = qc.nonlinear_quarter_car_model(**OPTIONS)
    batch = simulate_batch(
        model.batch_dynamics(DESIGNS),
        T2,
        np.zeros(4),
        ROAD,
        method,
        substeps=substeps,
        events=events,
    )
    lifted = 0
    for j, design in enumerate(DESIGNS):
        ref = qc.input_output_response(
            model.rebuild(design).system,
            T2,
            ROAD,
            np.zeros(4),
            method=method,
            substeps=substeps,
            events=True if events else None,
        )
        assert _max_rel(batch.states[j], ref.states) < RTOL
        for i, label in enumerate(ref.output_labels):
            assert _max_rel(batch.outputs[label][j], ref.outputs[i]) < RTOL, label
        lifted += int(np.any(ref.outputs[-1] == 0.0))
        if events:  # the same kinks, located to the root finder's 1e-12 of a step
            assert batch.t_events[j].size == ref.t_events.size > 0
            assert np.max(np.abs(batch.t_events[j] - ref.t_events)) < 1e-12
    assert lifted >= 2  # the case is nonlinear: some wheels do leave the road


_RALSTON3 = qc.ButcherTableau(
    "ralston3", a=[[0, 0, 0], [1 / 2, 0, 0], [0, 3 / 4, 0]], b=[2 / 9, 1 / 3, 4 / 9]
)


@pytest.mark.parametrize(
    "method, substeps", [("euler", 1), ("heun", 2), ("rk4", 1), (_RALSTON3, 1)]
)
@pytest.mark.parametrize(
    "options",
    [
        OPTIONS,  # stops both ways, bilinear damper with knees, cubic spring
        {},  # unilateral tire only
        {"tire": "linear", "bump_stop": qc.BumpStop(0.02, 1e5)},  # bound stop only
        {"actuator": True, "damper": qc.PiecewiseDamper(1500.0, 700.0)},  # zr and fa
        {"actuator": True, "road": False, "gravity": False, "tire": "linear"},
    ],
    ids=["all", "tire", "linear-tire-bound-stop", "actuator", "actuator-no-road"],
)
def test_compiled_steps_equal_the_numpy_steps(method, substeps, options, monkeypatch):
    """`NonlinearQuarterCarBatch.compiled_stepper` (numba loops) against the NumPy
    path (`rhs` over the designs), an independent writing of the same equations:
    equal to rounding (the sums run in other orders; observed below 1e-13)."""
    model = qc.nonlinear_quarter_car_model(**options)
    dynamics = model.batch_dynamics(DESIGNS)
    assert dynamics.compiled_stepper() is not None
    k = len(dynamics.input_labels)
    force = 800.0 * np.sin(2 * np.pi * 3.0 * T2)  # an actuator force [N]
    U = (
        np.stack([ROAD, force])[-k:]
        if k == 2
        else (force if options.get("road") is False else ROAD)
    )
    compiled = simulate_batch(dynamics, T2, np.zeros(4), U, method, substeps=substeps)
    monkeypatch.setattr(NonlinearQuarterCarBatch, "compiled_stepper", lambda self: None)
    plain = simulate_batch(dynamics, T2, np.zeros(4), U, method, substeps=substeps)
    assert _max_rel(compiled.states, plain.states) < 1e-13
    assert np.array_equal(compiled.success, plain.success)
    # no design blew up; success also says the step stayed within the stability limit
    # along the trajectory, which Euler at 1 ms is not on the knee damper's softer
    # branch (body mode -0.16 ± 19.2j 1/s: Euler's limit 2·0.16/19.2² = 0.86 ms)
    assert np.isfinite(compiled.states).all()
    assert compiled.success.all() or (method == "euler" and options is OPTIONS)
    if options.get("tire", "unilateral") == "unilateral":  # a wheel does leave the road
        assert np.any(plain.outputs["tire_force"] == 0.0)


def test_compiled_steps_diverge_as_the_numpy_steps(monkeypatch):
    """A design beyond its step's stability (a 1e9 N/m spring at 1 ms) goes
    non-finite in both paths alike; the others are untouched by it."""
    model = qc.nonlinear_quarter_car_model(**OPTIONS)
    designs = [*DESIGNS[:2], {**DESIGNS[0], "ks": 1e9}]
    compiled = simulate_batch(model.batch_dynamics(designs), T2, np.zeros(4), ROAD)
    monkeypatch.setattr(NonlinearQuarterCarBatch, "compiled_stepper", lambda self: None)
    plain = simulate_batch(model.batch_dynamics(designs), T2, np.zeros(4), ROAD)
    assert compiled.success.tolist() == plain.success.tolist() == [True, True, False]
    assert _max_rel(compiled.states[:2], plain.states[:2]) < 1e-13
    assert np.array_equal(np.isfinite(compiled.states), np.isfinite(plain.states))


@pytest.mark.slow
def test_compiled_steps_without_a_writable_cache(tmp_path):
    """Where numba finds no place to cache machine code (here: no cache locator
    that accepts the package, as for a read-only installation and home),
    `qc_control.numerics.recurrence.compiled` compiles in the process instead of failing
    at import: a nonlinear batch and a free sweep (both compiled loops) give
    the same numbers as this process's cached code."""
    script = tmp_path / "run.py"
    script.write_text(
        "import numpy as np, qc_control as qc\n"
        "from qc_control.studies.nlsweep import simulate_batch\n"
        "from qc_control.numerics.recurrence import carry_scan\n"
        "from qc_control.models.quarter import SEED_X0\n"
        "T = np.linspace(0.0, 0.5, 501)\n"
        "zr = 0.06 * (T >= 0.1)\n"
        "model = qc.nonlinear_quarter_car_model(bump_stop=qc.BumpStop(0.02, 1e5))\n"
        "designs = [dict(ms=300.0, mu=40.0, ks=ks, ku=2e5, cs=1e3) for ks in (1.5e4, 4e4)]\n"
        "r = simulate_batch(model.batch_dynamics(designs), T, np.zeros(4), zr)\n"
        "s = qc.sweep({'ks': [2e4, 3e4], 'zeta': [0.2, 0.4]}, T, SEED_X0)\n"
        "print(type(carry_scan._cache).__name__)\n"
        "import sys; np.save(sys.argv[1], r.states); s.metrics.to_pickle(sys.argv[2])\n"
    )
    env = {**os.environ, "NUMBA_CACHE_LOCATOR_CLASSES": "IPythonCacheLocator"}
    args = [sys.executable, str(script), str(tmp_path / "x.npy"), str(tmp_path / "m.pkl")]
    run = subprocess.run(args, capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[-1] == "NullCache"  # it did compile without a cache
    T = np.linspace(0.0, 0.5, 501)
    model = qc.nonlinear_quarter_car_model(bump_stop=qc.BumpStop(0.02, 1e5))
    designs = [dict(ms=300.0, mu=40.0, ks=ks, ku=2e5, cs=1e3) for ks in (1.5e4, 4e4)]
    here = simulate_batch(model.batch_dynamics(designs), T, np.zeros(4), 0.06 * (T >= 0.1))
    assert np.array_equal(np.load(tmp_path / "x.npy"), here.states)  # the same machine code
    sweep = qc.sweep({"ks": [2e4, 3e4], "zeta": [0.2, 0.4]}, T, SEED_X0)
    assert pd.read_pickle(tmp_path / "m.pkl").equals(sweep.metrics)


def test_user_callables_have_no_compiled_steps():
    """A callable spring, damper or road is user Python: the NumPy path runs it."""
    for options in (
        {"spring": lambda d: 2e4 * d + 1e6 * d**3},
        {"damper": lambda v: 1500.0 * np.tanh(v)},
        {"road": qc.road.Sine(amplitude=0.01, frequency=1.0)},
    ):
        model = qc.nonlinear_quarter_car_model(**options)
        assert model.batch_dynamics(DESIGNS[:1]).compiled_stepper() is None


def test_custom_tableau_and_road_function():
    ralston = qc.ButcherTableau("ralston", a=[[0, 0], [2 / 3, 0]], b=[1 / 4, 3 / 4])

    bump = qc.road.Bump(height=0.2, length=8.0, speed=20.0, t0=0.1)
    model = qc.nonlinear_quarter_car_model(road=bump, damper=lambda v: 1500.0 * np.tanh(v))
    T = np.linspace(0.0, 0.8, 801)
    batch = simulate_batch(model.batch_dynamics(DESIGNS[:2]), T, np.zeros(4), None, ralston)
    for j, design in enumerate(DESIGNS[:2]):
        ref = qc.input_output_response(model.rebuild(design).system, T, 0.0, 0.0, method=ralston)
        assert _max_rel(batch.states[j], ref.states) < RTOL


def test_linear_limit_equals_the_linear_sweep():
    """tire='linear', gravity off, no stops: the nonlinear car is the linear one, and
    its batched RK4 the LTI engine's exact RK4 step map (to rounding)."""
    T = np.linspace(0.0, 3.0, 3001)
    road = qc.road.iso8608(T, "C", 20.0, seed=5)
    grid = {"ks": [15e3, 30e3, 45e3], "cs": [500.0, 1500.0, 3000.0]}
    nl = qc.nonlinear_quarter_car_model(tire="linear", gravity=False)
    lin = qc.quarter_car_model(road=True)
    a = qc.sweep(grid, T, SEED_X0, road, model=nl, states=True)
    b = qc.sweep(grid, T, SEED_X0, road, model=lin, states=True)
    assert _max_rel(a.states, b.states) < 1e-11  # two evaluation orders of one map
    a = qc.sweep(grid, T, SEED_X0, road, model=nl)  # streamed metrics
    b = qc.sweep(grid, T, SEED_X0, road, model=lin)
    for column in qc.DEFAULT_METRICS:
        x, y = a.metrics[column].to_numpy(float), b.metrics[column].to_numpy(float)
        if column.startswith("settling_time"):  # a threshold crossing: within a sample
            assert np.max(np.abs(x - y)) <= T[1] - T[0]
        else:
            assert np.allclose(x, y, rtol=1e-9, atol=1e-12), column
    assert a.metrics["stable"].all()


def test_streamed_metrics_equal_the_metrics_of_each_response():
    model = qc.nonlinear_quarter_car_model(**OPTIONS)
    names = [*SWEEP_METRICS, "peak_body_acc", "lift_off"]
    got = qc.sweep(DESIGNS, T2, np.zeros(4), ROAD, model=model, metrics=names)
    wk = qc.sweep(DESIGNS, T2, np.zeros(4), ROAD, model=model, metrics=["vdv"])  # whole signals
    for j, design in enumerate(DESIGNS):
        one = model.rebuild(design)
        r = qc.input_output_response(one.system, T2, ROAD, np.zeros(4))
        outputs = {label: r.outputs[i][None] for i, label in enumerate(r.output_labels)}
        want = evaluate(RideSignals(T2, outputs, one.roles), [*names, "vdv"])
        for column, value in want.items():
            frame = wk if column.startswith("vdv") else got
            # the same formulas on the same samples (to RTOL), summed in another order
            assert np.isclose(frame.metrics[column][j], value[0], rtol=1e-9, atol=1e-12), column


def test_fallback_without_a_vectorised_form():
    """A damper that does not vectorise (an ``if`` on v): one response per design,
    the same numbers as the batch with the equivalent PiecewiseDamper."""

    def scalar_damper(v):
        return 1800.0 * v if v >= 0 else 900.0 * v

    slow = qc.nonlinear_quarter_car_model(damper=scalar_damper)
    fast = qc.nonlinear_quarter_car_model(damper=qc.PiecewiseDamper(1800.0, 900.0))
    assert slow.batch_dynamics is None and fast.batch_dynamics is not None
    T = T2[:801]
    a = qc.sweep(DESIGNS[:2], T, np.zeros(4), ROAD[:801], model=slow, states=True)
    b = qc.sweep(DESIGNS[:2], T, np.zeros(4), ROAD[:801], model=fast, states=True)
    assert _max_rel(a.states, b.states) < RTOL
    for column in qc.DEFAULT_METRICS:
        assert np.allclose(a.metrics[column], b.metrics[column], rtol=1e-9, atol=1e-12)
    with pytest.raises(TypeError, match="does not vectorise"):
        NonlinearQuarterCarBatch([300.0], [40.0], [2e4], [2e5], [0.0], damper=scalar_damper)


def test_semi_active_closed_loop_sweeps_one_response_per_design():
    car = qc.quarter_car_model(road=True, actuator=True)
    loop = qc.closed_loop(car, qc.skyhook(2500.0, semi_active="on-off", cmax=4000.0))
    T = T2[:501]
    road = 0.05 * (T >= 0.1)
    x0 = np.zeros(loop.system.nstates)
    res = qc.sweep(DESIGNS[:2], T, x0, road, model=loop, metrics=["peak_susp_travel"])
    for j, design in enumerate(DESIGNS[:2]):
        r = qc.input_output_response(loop.rebuild(design).system, T, road, x0)
        travel = r.outputs[list(r.output_labels).index("susp_travel")]
        assert res.metrics["peak_susp_travel [m]"][j] == pytest.approx(np.max(np.abs(travel)))


def _reference(design, profile, T, events_on=True):
    """solve_ivp (DOP853, rtol 1e-12) on the equations, restarted at each contact."""
    ms, mu, ks, ku, cs = (design[k] for k in ("ms", "mu", "ks", "ku", "cs"))
    d0 = (ms + mu) * G / ku

    def f(t, x):
        vs, vu, xs, xu = x
        fsd = ks * (xs - xu) + cs * (vs - vu)
        ft = max(0.0, ku * (d0 - (xu - profile(t))))
        return [-fsd / ms, (fsd + ft - ku * d0) / mu, vs, vu]

    def contact(t, x):
        return d0 - (x[3] - profile(t))

    contact.terminal = True
    t0, x, out, times = T[0], np.zeros(4), [], []
    while True:
        sol = solve_ivp(
            f, (t0, T[-1]), x, "DOP853", rtol=1e-12, atol=1e-14,
            events=contact, dense_output=True,
        )  # fmt: skip
        seg = T[(T >= t0) & (T <= sol.t[-1])]
        out.append(sol.sol(seg))
        if sol.status != 1:
            break
        t0 = float(sol.t_events[0][0])
        times.append(t0)
        x = sol.y_events[0][0]
        T = T[T > seg[-1]] if seg.size else T
        t0 += 1e-14  # just past the kink: the event is not found again at once
        x = x + 1e-14 * np.asarray(f(t0, x))
    return np.concatenate(out, axis=1), np.array(times)


def test_lift_off_against_solve_ivp_with_events():
    """The README's lift-off bump (1 - cos, 20 cm, 8 m at 20 m/s) on the seed's car:
    with events, each design's RK4 at 1 ms is within RK4's error of the reference
    (about 1.5e-10 m there; bound 2e-9 m) and its contact times within 1e-9 s;
    without, only first/second order near the kinks (about 1.6e-7 m; bound 1e-6 m)."""

    def bump(t):
        s = np.clip((t - 0.1) / 0.4, 0.0, 1.0)
        return 0.5 * 0.2 * (1 - np.cos(2 * np.pi * s))

    T = np.linspace(0.0, 0.8, 801)
    designs = [
        dict(ms=301.2, mu=100.0, ks=30000.0, ku=29530.0, cs=cs) for cs in (1503.0, 2000.0, 2500.0)
    ]
    model = qc.nonlinear_quarter_car_model(
        road=qc.road.Bump(height=0.2, length=8.0, speed=20.0, t0=0.1)
    )
    dyn = model.batch_dynamics(designs)
    with_events = simulate_batch(dyn, T, np.zeros(4), events=True)
    without = simulate_batch(dyn, T, np.zeros(4))
    for j, design in enumerate(designs):
        ref, times = _reference(design, lambda t: float(bump(t)), T)
        assert times.size == 2  # the wheel leaves the road and lands
        pos = slice(2, 4)
        err = np.max(np.abs(with_events.states[j, pos] - ref[pos]))
        err_plain = np.max(np.abs(without.states[j, pos] - ref[pos]))
        assert err < 2e-9
        assert np.max(np.abs(with_events.t_events[j] - times)) < 1e-9
        assert 10 * err < err_plain < 1e-6


def test_free_flight_is_the_parabola():
    """Airborne, the wheel carries gravity and the body's static preload, (ms + mu)·g,
    and nothing else when the suspension is (almost: ks = 1e-5 N/m, cs = 0) absent:
    x_u = x0 + v0 t - ((ms + mu) g / mu) t²/2, which RK4 integrates exactly. The
    spring's 1e-5 N/m over < 0.3 m adds at most 1e-10 m in 0.05 s (bound 1e-9 m)."""
    design = dict(ms=300.0, mu=40.0, ks=1e-5, ku=2e5, cs=0.0)
    d0 = (design["ms"] + design["mu"]) * G / design["ku"]
    T = np.linspace(0.0, 0.05, 51)
    x0 = np.array([0.0, 2.0, 0.0, d0 + 1e-3])  # above the lift threshold, rising
    dyn = qc.nonlinear_quarter_car_model(road=False).batch_dynamics([design])
    r = simulate_batch(dyn, T, x0)
    a = -design["ku"] * d0 / design["mu"]  # the preload term left without the tire
    parabola = x0[3] + 2.0 * T + 0.5 * a * T**2
    airborne = r.outputs["tire_force"][0] == 0.0
    assert airborne.sum() > 10
    assert np.max(np.abs(r.states[0, 3, airborne] - parabola[airborne])) < 1e-9


def test_bad_input_names_the_value():
    with pytest.raises(ValueError, match=r"one length.*'mu': 1"):
        NonlinearQuarterCarBatch([300.0, 310.0], [40.0], [2e4, 2e4], [2e5, 2e5], [1e3, 1e3])
    with pytest.raises(
        ValueError, match=r"ms\[1\] \(sprung mass\) must be a finite number > 0 kg, got -5.0"
    ):
        NonlinearQuarterCarBatch([300.0, -5.0], [40.0] * 2, [2e4] * 2, [2e5] * 2, [1e3] * 2)
    with pytest.raises(
        ValueError,
        match=r"cs\[0\] \(suspension damping\) must be a finite number >= 0 N·s/m, got nan",
    ):
        NonlinearQuarterCarBatch([300.0], [40.0], [2e4], [2e5], [math.nan])
    model = qc.nonlinear_quarter_car_model()
    with pytest.raises(ValueError, match=r"X0 must have shape \(4,\) .* got \(2,\)"):
        simulate_batch(model.batch_dynamics(DESIGNS[:1]), T2, [0.0, 0.0])
    with pytest.raises(ValueError, match=r"U must have shape \(2001,\) or \(1, 2001\)"):
        simulate_batch(model.batch_dynamics(DESIGNS[:1]), T2, np.zeros(4), ROAD[:10])
    bad = [DESIGNS[0], {**DESIGNS[1], "ms": -1.0}]
    with pytest.warns(RuntimeWarning, match="1 of 2 designs were rejected"):
        res = qc.sweep(bad, T2[:201], np.zeros(4), ROAD[:201], model=model)
    assert "ms" in res.errors["error"][0] and "-1.0" in res.errors["error"][0]
    assert np.isnan(res.metrics["rms_body_acc [m/s²]"][1])
    assert np.isfinite(res.metrics["rms_body_acc [m/s²]"][0])
    with pytest.raises(ValueError, match="events=True applies to a nonlinear model"):
        qc.sweep(DESIGNS[:1], T2[:11], SEED_X0, events=True)


def test_executor_chunks_and_a_diverging_design():
    """Chunks on an executor give the same table; a design whose step is beyond
    stability (a 1e9 N/m spring at 1 ms) is NaN and not stable, the others untouched."""
    model = qc.nonlinear_quarter_car_model(**OPTIONS)
    designs = [*DESIGNS, {**DESIGNS[0], "ks": 1e9}]
    T, road = T2[:401], ROAD[:401]
    here = qc.sweep(designs, T, np.zeros(4), road, model=model)
    with ThreadPoolExecutor(2) as pool:
        there = qc.sweep(designs, T, np.zeros(4), road, model=model, executor=pool, chunk_size=2)
    assert here.metrics.equals(there.metrics)
    assert not here.metrics["stable"].iloc[-1] and here.metrics["stable"].iloc[:-1].all()
    assert np.isnan(here.metrics["rms_body_acc [m/s²]"].iloc[-1])
    alone = qc.sweep(DESIGNS, T, np.zeros(4), road, model=model)
    assert here.metrics.iloc[:-1].equals(alone.metrics)


def test_energy_of_an_undamped_car_with_stops_converges_at_the_methods_order():
    """No damping, a linear tire, no gravity, stops at ±1 cm: the energy
    ½ms·vs² + ½mu·vu² + ½ks·d² + E_stop(d) + ½ku·xu² is conserved by the flow. On a
    smooth oscillator RK4's energy error per step is O(h⁶) (|R(iωh)|² = 1 - (ωh)⁶/72),
    O(h⁵) over a fixed time: 32x from h = 1 ms to 0.5 ms. With the stops' kinks
    located per design the largest drift over 1 s keeps that (bound 20x); stepping
    through them, it does not (bound: a third of it)."""
    stop = qc.BumpStop(0.01, 2e5, 1e8, clearance_rebound=0.01)
    model = qc.nonlinear_quarter_car_model(tire="linear", gravity=False, road=False, bump_stop=stop)
    designs = [dict(ms=300.0, mu=40.0, ks=ks, ku=2e5, cs=0.0) for ks in (2e4, 3.5e4)]
    x0 = np.array([0.0, 0.0, 0.05, 0.0])

    def drift(n, events):
        T = np.linspace(0.0, 1.0, n + 1)
        r = simulate_batch(model.batch_dynamics(designs), T, x0, events=events)
        out = []
        for j, d in enumerate(designs):
            vs, vu, xs, xu = r.states[j]
            stops = np.array([stop.energy(v) for v in xs - xu])
            e = 0.5 * (d["ms"] * vs**2 + d["mu"] * vu**2 + d["ks"] * (xs - xu) ** 2)
            e = e + stops + 0.5 * d["ku"] * xu**2
            out.append(np.max(np.abs(e - e[0])) / e[0])
            assert r.t_events[j].size >= (4 if events else 0)  # the stops are hit
        return np.array(out)

    located = drift(1000, True) / drift(2000, True)
    plain = drift(1000, False) / drift(2000, False)
    assert np.all(located > 20)  # observed 30.3
    assert np.all(plain < located / 3)  # observed 4.9 and 2.7: order 1.4-2.3
