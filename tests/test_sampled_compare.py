"""compare_methods on a sampled-data loop: the tick-aware exact reference.

Between two ticks the car is linear with its move held, so its exact
response is the matrix exponential interval by interval. The reference is
checked against two independent evaluations: the exact discrete equivalent
``control.c2d(car, dt, 'zoh')`` closed with the same discrete law at the
ticks, and a fine-step RK4 run of the car alone between the ticks.
"""

from __future__ import annotations

import numpy as np
import pytest

# the ECU's clock, the released body, the discrete LQR of the car's ZOH equivalent
# and that equivalent closed with it at the ticks, as tests/test_sampled.py builds them
from test_sampled import DT, X0, _dlqr_law, _exact_ticks

import qc_control as qc
from qc_control.numerics.clocked import exact_clocked
from qc_control.studies.compare import sampled_reference


@pytest.fixture(scope="module")
def car():
    return qc.quarter_car_model(road=True, actuator=True)


@pytest.fixture(scope="module")
def law(car):
    """A discrete LQR of the car's ZOH equivalent, and its gain."""
    return _dlqr_law(car)


@pytest.mark.parametrize("delay", [0, 2])
@pytest.mark.parametrize("substeps", [1, 10])
def test_the_reference_is_the_zoh_equivalent_at_the_ticks(car, law, substeps, delay):
    """Free response, 2 s: the reference at the ticks equals the discrete
    equivalent to 1e-12 (both exact; they differ only by the rounding of
    e^{Ah} formed once per step against once per tick, ~1e-15 per step)."""
    ss, K = law
    loop = qc.closed_loop(car, ss, delay=delay).system
    T = np.arange(0, 201) * DT
    run = exact_clocked(loop, T, np.zeros((1, T.size)), [*X0, *[0.0] * (delay + 1)], substeps)
    exact = _exact_ticks(car, K, T.size, delay)
    assert np.max(np.abs(run.x - exact)) < 1e-12


def test_the_reference_is_a_fine_rk4_run_between_the_ticks(car, law):
    """Over the 5 cm bump: the reference against the car alone stepped by RK4 at
    20 µs between the ticks (landing on every road sample), the force held at
    -K x_k from its own state at each tick, the road linear between its
    samples. RK4's global error at 20 µs is ~ (ωh)^4 ≈ (60·2e-5)^4 ≈ 2e-12 of the
    5 cm motion (ω ≈ 60 rad/s the wheel hop), so 1e-10 (m, m/s) is rounding and
    truncation with a margin of ten."""
    ss, K = law
    loop = qc.closed_loop(car, ss).system
    T = np.arange(0, 101) * 0.005
    zr = qc.road.bump(T, height=0.05)
    run = exact_clocked(loop, T, zr[None], [*X0, 0.0], substeps=2)
    sys = car.system
    A = np.asarray(sys.A)
    bw = np.asarray(sys.B)[:, sys.input_labels.index("zr")]
    bu = np.asarray(sys.B)[:, sys.input_labels.index("fa")]
    h, x, xs = 2e-5, np.array(X0, float), {}
    per_tick = round(DT / h)
    for k in range(round((T[-1] - T[0]) / DT) + 1):
        xs[k] = x.copy()
        fa = float((-K @ x)[0])
        t0 = k * DT
        for j in range(per_tick if k * DT < T[-1] - 1e-12 else 0):
            t = t0 + j * h

            def f(t, x, fa=fa):
                return A @ x + bw * np.interp(t, T, zr) + bu * fa

            k1 = f(t, x)
            k2 = f(t + h / 2, x + h / 2 * k1)
            k3 = f(t + h / 2, x + h / 2 * k2)
            k4 = f(t + h, x + h * k3)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    ticks = np.array([xs[k] for k in sorted(xs)]).T
    assert np.max(np.abs(run.x[:4, ::2] - ticks)) < 1e-10


@pytest.fixture(scope="module")
def comparison(car, law):
    ss, _ = law
    loop = qc.closed_loop(car, ss)
    T = np.arange(0, 61) * DT
    zr = qc.road.bump(T, height=0.05)
    return qc.compare_methods(
        loop, T, [*X0, 0.0], U=zr, h=DT / 5, methods=("heun", "rk4"), timing=False
    )


def test_compare_methods_takes_a_sampled_loop(comparison):
    """The reference's own error against python-control tick by tick: both exact,
    so rounding only (1e-12 m leaves a factor ~100 over the ~1e-14 measured)."""
    assert comparison.reference_error < 1e-12
    assert "clock ticks" in comparison.reference_name
    # on the road, the ride metrics of the reference and of each method, as for any car
    assert list(comparison.ride.index) == ["reference", "heun", "rk4"]


def test_rk4_and_heun_show_their_order_at_the_ticks(comparison):
    """The sampled loop adds no error of its own beyond the method's: the fitted
    slope over h, h/2, h/4 is within 0.1 of the classical order."""
    orders = comparison.table["observed order"]
    assert orders["rk4"] == pytest.approx(4, abs=0.1)
    assert orders["heun"] == pytest.approx(2, abs=0.1)


def test_the_modes_are_the_cars_own(comparison, car):
    """Between the ticks the car moves with the passive car's eigenvalues."""
    eig = np.sort_complex(np.linalg.eigvals(np.asarray(car.system.A)))
    assert np.allclose(np.sort_complex(comparison.eigenvalues), eig, rtol=1e-12)


@pytest.mark.slow
def test_the_report_of_a_sampled_comparison_is_written(comparison, tmp_path):
    """The report names the tick-by-tick reference and the car's own matrices.

    Its Markdown only (with the figures, always drawn): the text is what is read, and
    the HTML and PDF of a report are tested on their own (tests/test_report*.py).
    """
    qc.write_report(comparison, tmp_path, formats=("md",))
    text = "".join(p.read_text(encoding="utf-8") for p in tmp_path.rglob("*.md"))
    assert "clock ticks" in text and "sampled-data loop" in text


def test_a_previewing_mpc_with_delay_is_compared_against_python_control_tick_by_tick(car):
    """An MPC with 0.1 s of road preview, its force limited, one tick of delay, over
    the bump: the reference agrees with control.forced_response run tick interval by
    tick interval, its law fed the road ahead from the same signal (both exact:
    1e-12 m is rounding with a margin of ~100; the limit makes the law nonlinear, so
    a difference in the state would show as a different move)."""
    mpc = qc.mpc_controller(car, DT, 10, preview=0.1, limits={"fa": 300.0})
    loop = qc.closed_loop(car, mpc, delay=1)
    T = np.arange(0, 51) * DT
    zr = qc.road.bump(T, height=0.05)
    x0 = [*X0, *[0.0] * (loop.system.nstates - 4)]
    metres = [s for s in loop.system.output_labels if loop.unit(s) == "m"]
    ref = sampled_reference(loop.system, T, x0, zr[None], substeps=2, outputs=metres)
    assert ref.error < 1e-12
    fa = np.asarray(ref.response.outputs)[loop.system.output_labels.index("fa")]
    assert np.max(np.abs(fa)) <= 300.0 * (1 + 1e-6)  # the limit held (QP tolerance)
    assert np.max(np.abs(fa)) > 100.0  # and the law did act
