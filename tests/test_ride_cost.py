"""The cost of a ride answer on the stiff car (issue 24, item 4).

References: the Wk-weighted RMS body acceleration of ``control.forced_response``
(exact for the sampled road) computed here through `qc.ride_metrics`; the
eigenvalues of the car's A for RK4's step limit; first order's halving of
the error for backward Euler; ``solve_ivp`` run here for the BDF peer.
"""

import math

import control
import numpy as np
import pytest
from reports_shared import placeholder_figures  # noqa: F401  (a fixture)
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.numerics.methods import get_method
from qc_control.numerics.sampled import linear_input
from qc_control.ride import road as roads
from qc_control.studies.ride_cost import RIDE_METRIC, ride_cost
from qc_control.studies.scenarios import STIFF_CAR, StiffCar, stiff_car_comparison, stiff_car_model

#: RK4's stability limit on the negative real axis, |h λ| (the root of |R(z)| = 1).
RK4_REAL_LIMIT = 2.785293563


def _road(t_end: float):
    case = STIFF_CAR
    T = np.linspace(0.0, t_end, round(t_end / case.h) + 1)
    return T, roads.iso8608(T, case.road_class, case.speed, case.seed)


def _exact(model, T, U):
    """The exact metric and each state's scale max_t |x_i| (the peers' atol rule)."""
    resp = control.forced_response(model.system, T, U, return_x=True)
    return float(qc.ride_metrics(resp, model)[RIDE_METRIC]), np.abs(resp.states).max(axis=1)


@pytest.mark.slow
def test_the_stiff_car_costs_against_the_exact_ride_metric():
    # the run: 60 s of class C road at 20 m/s, 1e7 N/m mount, h = 5 ms
    model = stiff_car_model()
    T, U = _road(STIFF_CAR.t_end)
    exact, scale = _exact(model, T, U)
    tabs = [get_method(m) for m in ("backward_euler", "sdirk2", "radau2", "rk4")]
    cost = ride_cost(model, T, U, tabs, solvers=("BDF",))
    assert cost.exact == pytest.approx(exact, rel=1e-12)  # the same formula on the same response
    runs, best = cost.runs, cost.cheapest()
    # every reported error is the value against the exact metric computed here
    ok = runs["success"]
    np.testing.assert_allclose(
        runs.loc[ok, "error [%]"], 100 * (runs.loc[ok, "value"] - exact) / exact, rtol=1e-9
    )
    steps = round(STIFF_CAR.t_end / STIFF_CAR.h)
    # L-stable implicit methods at 5 ms, first try: within 1 % (measured 0.004 %, 0.001 %)
    for name, stages in (("sdirk2", 2), ("radau2", 2)):
        row = best.loc[name]
        assert row["reached"] and row["runs"] == 1 and row["h"] == STIFF_CAR.h
        assert abs(row["value"] - exact) <= 0.01 * exact
        assert row["evaluations"] == stages * steps  # stages x steps
    # backward Euler: 10 % off at 5 ms (the figure), first order, so each
    # halving halves the error until it is within 1 %: log2 of each ratio within
    # 0.15 of 1 (measured 0.89 from 5 ms, then 0.94, 0.97, 0.98 as h enters the
    # asymptotic range)
    be = runs[runs["name"] == "backward_euler"]
    assert be["error [%]"].iloc[0] == pytest.approx(-10.4, abs=0.1)
    assert (np.abs(-np.diff(np.log2(np.abs(be["error [%]"]))) - 1) < 0.15).all()
    assert (be["error [%]"].abs().iloc[:-1] > 1).all() and abs(be["error [%]"].iloc[-1]) <= 1
    assert best.loc["backward_euler", "h"] == be["h"].iloc[-1] < STIFF_CAR.h
    # RK4: every step above its limit 2.785/|λ_max| diverges; the first below it is reached
    eig = np.linalg.eigvals(np.asarray(model.system.A, dtype=float))
    h_max = RK4_REAL_LIMIT / np.abs(eig.real).max()
    rk4 = runs[runs["name"] == "rk4"]
    assert not rk4.loc[rk4["h"] > h_max, "success"].any()
    first = rk4[rk4["h"] <= h_max].iloc[0]
    assert first["success"] and abs(first["error [%]"]) <= 1
    assert first["evaluations"] == 4 * round(STIFF_CAR.t_end / first["h"])
    # BDF: its cheapest run solved again here reports the same metric
    row = best.loc["BDF"]
    A, B = (np.asarray(m, dtype=float) for m in (model.system.A, model.system.B))
    C, D = (np.asarray(m, dtype=float) for m in (model.system.C, model.system.D))
    u = linear_input(T, U[None])
    sol = solve_ivp(
        lambda t, x: A @ x + B @ u(t),
        (T[0], T[-1]),
        np.zeros(5),
        method="BDF",
        t_eval=T,
        rtol=row["rtol"],
        atol=row["rtol"] * np.maximum(scale, 1e-6 * scale.max()),
    )
    y = C @ sol.y + D @ U[None]
    again = qc.ride_metrics(
        control.TimeResponseData(T, y, None, U, output_labels=list(model.system.output_labels)),
        model,
    )[RIDE_METRIC]
    assert row["value"] == pytest.approx(again, rel=1e-12)  # a deterministic solve
    assert row["reached"] and abs(again - exact) <= 0.01 * exact
    assert row["evaluations"] >= sol.nfev + sol.njev * 5  # Jacobians as n evaluations each


def test_on_a_short_road_each_cheapest_run_is_within_the_target():
    # 2 s of the same road: every integrator's cheapest run within 1 % of the
    # exact metric computed here, and every looser run on its ladder outside it
    model = stiff_car_model()
    T, U = _road(2.0)
    exact, _ = _exact(model, T, U)
    tabs = [get_method(m) for m in ("heun", "radau3", "bogacki_shampine")]
    cost = ride_cost(model, T, U, tabs, solvers=("LSODA",), rtols=(1e-2, 1e-3, 1e-4))
    best = cost.cheapest()
    assert best["reached"].all() and (np.abs(best["value"] - exact) <= 0.01 * exact).all()
    assert set(best["kind"]) == {"method", "adaptive", "solver"}  # the pair both ways
    for _, runs in cost.runs.groupby(["kind", "name"]):
        looser = runs.iloc[:-1]
        assert not (looser["success"] & (np.abs(looser["value"] - exact) <= 0.01 * exact)).any()


@pytest.mark.slow
# the report's section and table are checked, not its pictures (drawn by tests/test_report.py)
@pytest.mark.usefixtures("placeholder_figures")
def test_a_short_stiff_run_reaches_the_target_and_reports_it(tmp_path):
    # 2 s of the same road: the comparison carries the cost, the report shows it
    from qc_control.report import write_report

    cmp = stiff_car_comparison(
        StiffCar(grid=(2.0, 0.005)),
        methods=("rk4", "radau2"),
        solvers=("BDF",),
        rtols=(1e-3, 1e-5),
        timing=False,
        repeats=1,
    )
    exact, _ = _exact(cmp.model, cmp.T, cmp.U)
    best = cmp.ride_cost.cheapest()
    assert list(best.index) == ["rk4", "radau2", "BDF"] and best["reached"].all()
    assert (np.abs(best["value"] - exact) <= 0.01 * exact).all()  # within 1 %
    assert best.loc["radau2", "h"] == 0.005 and best.loc["rk4", "h"] < 0.42e-3
    out = write_report(cmp, tmp_path / "r", formats=("md", "csv"))
    text = (out / "report.md").read_text(encoding="utf-8")
    assert "The cost of a ride answer" in text and "radau2 at h = 0.005 s" in text
    assert (out / "ride_cost.csv").exists()
    # the comparison without the target leaves the cost out
    none = stiff_car_comparison(
        StiffCar(grid=(0.5, 0.005)), methods=("radau2",), solvers=None, timing=False,
        ride_target=None,
    )  # fmt: skip
    assert none.ride_cost is None


def test_a_fixed_step_that_never_reaches_it_keeps_its_last_run():
    # Euler with no halving on 1 s: unstable at 5 ms (2/|λ_max| = 0.3 ms): not reached
    model = stiff_car_model()
    T, U = _road(1.0)
    cost = ride_cost(model, T, U, [get_method("euler")], halvings=0)
    row = cost.cheapest().loc["euler"]
    assert not row["reached"] and row["runs"] == 1 and math.isnan(row["value"])


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        (dict(target=0.0), ValueError, "target must be a percentage > 0, got 0.0"),
        (dict(halvings=-1), ValueError, "halvings must be an integer in 0..12, got -1"),
        (dict(h=0.003), ValueError, r"h = 0.003 s must divide the grid spacing"),
        (dict(rtols=(2.0,)), ValueError, "rtols must be tolerances"),
        (dict(solvers=("Euler",)), ValueError, "unknown solver 'Euler'"),
    ],
)
def test_bad_arguments_are_named(kwargs, error, match):
    model = stiff_car_model()
    T, U = _road(0.1)
    with pytest.raises(error, match=match):
        ride_cost(model, T, U, [get_method("radau2")], **kwargs)


def test_a_nonlinear_car_is_refused():
    T, U = _road(0.1)
    with pytest.raises(TypeError, match="model must be a VehicleModel of a linear car"):
        ride_cost(qc.nonlinear_quarter_car_model(), T, U, [get_method("rk4")])
