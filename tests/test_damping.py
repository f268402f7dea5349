"""Damper optimisation against closed forms, an independent Lyapunov solve and scipy.

References:

* The Gobbi & Mastinu (2001) closed forms for body acceleration and travel
  under unit white road velocity, and the issue's seed optimum
  cs = ks·√((ms+mu)/kt) ≈ 3497 N·s/m (ζ ≈ 0.58).
* The tire-deflection form of `qc_control.studies.damping` against
  ``scipy.linalg.solve_continuous_lyapunov`` on the car written in relative
  coordinates here (not through `qc_control.ride.spectral`): 1e-10 relative, a
  well-conditioned 4x4 solve.
* Each closed-form optimum against ``scipy.optimize.minimize_scalar`` on
  the exact spectral metric (``method='numerical'``): the objective is flat
  at its minimum, so the located cs is good to about √eps ≈ 1e-8 of itself;
  1e-6 relative.
"""

import math

import numpy as np
import pytest
import scipy.linalg

import qc_control as qc
from qc_control.models.vehicle import STANDARD_GRAVITY
from qc_control.studies import damping as D

SEED = qc.QuarterCarParams()
C20 = qc.road.ISO8608Road("C", speed=20.0)


def lyapunov_variances(p):
    """Stationary variances of [vs, vu, travel, tire_defl] and body_acc on unit white zr'."""
    ms, mu, ks, kt, cs = p.ms, p.mu, p.ks, p.ku, p.cs
    A = np.array(
        [
            [-cs / ms, cs / ms, -ks / ms, 0.0],
            [cs / mu, -cs / mu, ks / mu, -kt / mu],
            [1.0, -1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
        ]
    )
    B = np.array([[0.0], [0.0], [0.0], [-1.0]])  # tire_defl' = vu - zr'
    P = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    acc = A[0] @ P @ A[0]
    return {"travel": P[2, 2], "tire_defl": P[3, 3], "body_acc": acc}


def test_closed_forms_match_gobbi_mastinu_and_a_lyapunov_solve():
    p = SEED
    M = p.ms + p.mu
    v = lyapunov_variances(p)
    # published closed forms (Gobbi & Mastinu 2001)
    assert math.isclose(
        v["body_acc"], (p.cs**2 * p.ku + p.ks**2 * M) / (2 * p.cs * p.ms**2), rel_tol=1e-10
    )
    assert math.isclose(v["travel"], M / (2 * p.cs), rel_tol=1e-10)
    # the module's a·cs + b/cs terms, against the same solve
    for objective, var in (
        ("comfort", v["body_acc"]),
        ("travel", v["travel"]),
        ("road_holding", v["tire_defl"] * (p.ku / (M * STANDARD_GRAVITY)) ** 2),
    ):
        a, b = D.closed_form_terms(p, objective)
        assert math.isclose(a * p.cs + b / p.cs, var, rel_tol=1e-10), objective


def test_comfort_optimum_is_the_published_closed_form():
    opt = qc.optimal_damping(SEED, "comfort")
    assert opt.method == "closed form"
    assert math.isclose(opt.cs, SEED.ks * math.sqrt((SEED.ms + SEED.mu) / SEED.ku), rel_tol=1e-12)
    assert round(opt.cs) == 3497 and round(opt.zeta, 2) == 0.58


@pytest.mark.parametrize(
    "objective",
    ["comfort", "road_holding", {"comfort": 1.0, "road_holding": 100.0, "travel": 1e4}],
)
def test_closed_form_optimum_agrees_with_scipy_on_the_spectral_metric(objective):
    closed = qc.optimal_damping(SEED, objective, road=C20)
    numeric = qc.optimal_damping(SEED, objective, road=C20, solver="numerical")
    assert numeric.method == "scipy.optimize"
    assert math.isclose(closed.cs, numeric.cs, rel_tol=1e-6)
    assert closed.value <= numeric.value * (1 + 1e-12)


def test_wk_comfort_is_optimised_numerically_and_is_a_minimum():
    opt = qc.optimal_damping(SEED, "comfort_wk", road=C20)
    assert opt.method == "scipy.optimize"

    def value(cs):
        p = qc.QuarterCarParams(ms=SEED.ms, mu=SEED.mu, ks=SEED.ks, ku=SEED.ku, cs=cs)
        row = D.spectral_ride(qc.quarter_car_model(p, road=True), C20, wk=True)
        return float(row["rms_body_acc_wk [m/s²]"].iloc[0])

    # a minimum: 1 % either side is worse
    assert value(opt.cs) < value(0.99 * opt.cs) and value(opt.cs) < value(1.01 * opt.cs)


def test_travel_limit_is_honoured():
    q = qc.spectral.iso8608_intensity("C", 20.0)
    free = qc.optimal_damping(SEED, "comfort", road=C20)
    limit = 0.9 * 3 * free.metrics["rms_susp_travel [m]"]  # tighter than the free optimum
    opt = qc.optimal_damping(SEED, "comfort", road=C20, travel_limit=limit, sigmas=3)
    assert opt.method.endswith("travel limit") and opt.cs > free.cs
    rms_travel = math.sqrt(q * (SEED.ms + SEED.mu) / (2 * opt.cs))  # closed form
    assert math.isclose(3 * rms_travel, limit, rel_tol=1e-12)
    assert math.isclose(opt.metrics["rms_susp_travel [m]"], rms_travel, rel_tol=1e-9)


def test_pareto_front_is_the_non_dominated_feasible_set():
    crit = 2 * math.sqrt(SEED.ks * SEED.ms)
    vary = {"cs": list(np.geomspace(0.1, 3.0, 12) * crit), "ks": [2e4, 3e4, 4e4, 6e4]}
    limit = 0.03
    pf = qc.pareto_front(SEED, vary, road=C20, travel_limit=limit, sigmas=3)
    allp = pf.all_designs
    x, y = "rms_body_acc [m/s²]", "rms_tire_load / static [-]"
    feasible = allp[3 * allp["rms_susp_travel [m]"] <= limit]
    assert (allp["feasible"] == (3 * allp["rms_susp_travel [m]"] <= limit)).all()
    pts = feasible[[x, y]].to_numpy()

    def dominated(v):
        return np.any(np.all(pts <= v, axis=1) & np.any(pts < v, axis=1))

    expected = {i for i, v in zip(feasible.index, pts) if not dominated(v)}
    assert set(allp.index[allp["pareto"]]) == expected
    assert (
        len(pf.designs) == len(expected) and (3 * pf.designs["rms_susp_travel [m]"] <= limit).all()
    )
    ax = pf.figure.axes[0]
    assert "[m/s²]" in ax.get_xlabel() and "[-]" in ax.get_ylabel()
    assert any(name.startswith("passive optimum: comfort") for name in pf.markers.index)


def test_pareto_marks_controllers():
    car = qc.quarter_car_model(road=True, actuator=True)
    sky = qc.closed_loop(car, qc.skyhook(3000.0))
    pf = qc.pareto_front(SEED, controllers={"skyhook": sky, "other": {"rms_body_acc [m/s²]": 1.0}})
    assert "skyhook" in pf.markers.index
    # the skyhook loop beats every passive design in comfort on this road
    assert (
        pf.markers.loc["skyhook", "rms_body_acc [m/s²]"]
        < pf.all_designs["rms_body_acc [m/s²]"].min()
    )


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: qc.optimal_damping(SEED, "travel"), "no finite"),
        (lambda: qc.optimal_damping(SEED, "speed"), "objective must be one of"),
        (lambda: qc.optimal_damping(SEED, {"comfort": -1.0}), "weight of 'comfort'"),
        (lambda: qc.optimal_damping(SEED, "comfort_wk", solver="closed form"), "no closed form"),
        (lambda: qc.optimal_damping(SEED, travel_limit=-1.0), "travel_limit"),
        (lambda: qc.pareto_front(SEED, objectives=["comfort"]), "two or more"),
        (lambda: qc.pareto_front(SEED, {"cx": [1.0]}), "cx"),
    ],
)
def test_bad_input_names_the_parameter(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_the_old_method_keyword_warns_and_means_solver():
    """Issue 38 item 7: ``method`` names an integration method everywhere else."""
    with pytest.warns(DeprecationWarning, match=r"use solver=\.\.\."):
        old = qc.optimal_damping(SEED, "comfort", method="closed form")
    assert old.cs == qc.optimal_damping(SEED, "comfort", solver="closed form").cs
    with pytest.raises(ValueError, match="give solver alone"):
        qc.optimal_damping(SEED, method="numerical", solver="numerical")


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: qc.optimal_damping(SEED, "speed"), "objective"),
        (lambda: qc.optimal_damping(SEED, {"comfort": 1.0, "speed": 1.0}), "objective['speed']"),
        (lambda: qc.optimal_damping(SEED, {"comfort": 0.0}), "objective"),
        (lambda: qc.optimal_damping(SEED, {"comfort": -1.0}), "weight of 'comfort'"),
        (lambda: qc.optimal_damping(SEED, solver="newton"), "solver"),
        (lambda: qc.optimal_damping(SEED, solver="numerical", method="numerical"), "method"),
        (lambda: qc.optimal_damping(SEED, solver="numerical", bounds=(10.0, 1.0)), "bounds"),
        (lambda: qc.optimal_damping(SEED, road=C20, sigmas=0.0), "sigmas"),
    ],
)
def test_bad_input_is_a_parameter_error_naming_it(call, name):
    with pytest.raises(qc.ParameterError) as err:
        call()
    assert err.value.name == name
