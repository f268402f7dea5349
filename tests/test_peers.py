"""The solver peers of the work–precision study (qc_control.studies.peers).

Every count and error is checked against scipy or python-control run
directly in the test, on python-control's exact response.
"""

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.models.quarter import SEED_X0, quarter_car_model
from qc_control.studies.compare import compare_methods
from qc_control.studies.peers import SOLVERS, cheapest, check_solvers

# a short free response keeps the ladder quick: 0-2 s on 201 samples
T = np.linspace(0.0, 2.0, 201)
RTOLS = (1e-4, 1e-8)


@pytest.fixture(scope="module")
def study():
    model = quarter_car_model()
    cmp = compare_methods(
        model, T, SEED_X0, methods=("euler", "rk4"), solvers=SOLVERS, rtols=RTOLS, timing=False
    )
    exact = control.initial_response(model.system, T, SEED_X0)
    return model, cmp, exact


def test_counts_and_errors_match_scipy_run_directly(study):
    model, cmp, exact = study
    A = np.asarray(model.system.A)
    scale = np.max(np.abs(exact.states), axis=1)
    runs = cmp.peers.runs
    for solver in ("RK45", "DOP853", "LSODA", "Radau", "BDF"):
        for rtol in RTOLS:
            row = runs[(runs["name"] == solver) & (runs["rtol"] == rtol)].iloc[0]
            sol = solve_ivp(
                lambda t, x: A @ x,
                (T[0], T[-1]),
                SEED_X0,
                method=solver,
                t_eval=T,
                rtol=rtol,
                atol=rtol * scale,
            )
            assert row["atol"] == pytest.approx(rtol * scale.max(), rel=1e-15)
            # scipy's own counts: equal where it counts every call, a lower bound where
            # its finite-difference Jacobians (n calls each, or more) sit outside nfev
            if solver in ("Radau", "BDF"):
                assert row["evaluations"] >= sol.nfev + 4 * sol.njev
                assert row["nfev"] == sol.nfev and row["njev"] == sol.njev
            else:
                assert row["evaluations"] == sol.nfev
            # the same solve, measured on python-control's exact response: identical
            # arithmetic, so equal to rounding (1e-15 m on a 5 cm response)
            direct = np.max(np.abs(sol.y[2] - np.asarray(exact.outputs)[0]))
            assert row["error"] == pytest.approx(direct, rel=1e-9, abs=1e-15)


def test_tight_tolerance_reaches_the_exact_response(study):
    _, cmp, _ = study
    runs = cmp.peers.runs
    tight = runs[(runs["kind"] == "solver") & (runs["rtol"] == 1e-8)]
    # atol = 1e-8 · 5 cm per state: a global error below 1e-6 m leaves a 20x margin
    # for error growth over the 2 s run
    assert (tight["error"] < 1e-6).all(), tight[["name", "error"]]


def test_control_default_is_control_input_output_response(study):
    model, cmp, exact = study
    row = cmp.peers.control_default()
    resp = control.input_output_response(model.system, T, 0.0, SEED_X0)
    direct = np.max(np.abs(np.asarray(resp.outputs)[0] - np.asarray(exact.outputs)[0]))
    # the same solve_ivp call on the same right-hand side: equal to rounding
    assert row["error"] == pytest.approx(direct, rel=1e-9, abs=1e-15)
    assert row["rtol"] == 1e-3 and row["atol"] == 1e-6


def test_the_cheapest_run_reaches_the_tolerance_and_none_is_cheaper(study):
    _, cmp, _ = study
    runs = cmp.peers.runs
    best = cmp.peers.cheapest("evaluations", 1e-6)
    assert best["error"] <= 1e-6
    reaching = runs[(runs["error"] <= 1e-6) & runs["success"].astype(bool)]
    assert best["evaluations"] == reaching["evaluations"].min()
    assert cheapest(runs, "evaluations", 1e-30) is None
    with pytest.raises(ValueError, match="by must be"):
        cheapest(runs, "money", 1e-6)


def test_fixed_step_ladder_is_the_convergence_study(study):
    _, cmp, _ = study
    fixed = cmp.peers.runs[cmp.peers.runs["kind"] == "method"]
    assert list(fixed["evaluations"]) == list(cmp.convergence["nfev"])
    assert list(fixed["error"]) == list(cmp.convergence["error"])


def test_solver_names_are_checked():
    assert check_solvers("rk45, lsoda,Control") == ("RK45", "LSODA", "control")
    with pytest.raises(ValueError, match="unknown solver 'euler'"):
        check_solvers(["euler"])
    with pytest.raises(ValueError, match="distinct"):
        check_solvers(["BDF", "bdf"])
    with pytest.raises(TypeError, match="sequence of solver names"):
        check_solvers(3)
    with pytest.raises(ValueError, match="unknown solver"):
        compare_methods(None, T, SEED_X0, solvers=("ode45",), timing=False)


def test_report_has_both_figures_and_the_findings(study, tmp_path):
    from qc_control.report import build_blocks, figure_specs
    from qc_control.report.peers import peer_findings

    _, cmp, _ = study
    names = [spec.name for spec in figure_specs(cmp)]
    assert "peers_evaluations.png" in names and "peers_time.png" in names
    text = " ".join(peer_findings(cmp))
    assert "Cheapest to reach 1e-06 m" in text and "python-control's default call" in text
    assert build_blocks(cmp)


def test_the_adaptive_pairs_are_rows_of_the_work_precision_study():
    # an embedded pair over the tolerance ladder goes through the responses'
    # rtol/atol. Dormand-Prince with scipy's controller takes RK45's steps, so
    # each of its rows equals the RK45 row at the same tolerances (those rows
    # are checked against solve_ivp re-run in this file): the same
    # evaluations, and the same error to rounding (1e-9 relative)
    T = np.linspace(0.0, 10.0, 1001)
    cmp = compare_methods(
        None, T, SEED_X0, methods=("rk4", "dormand_prince"), solvers=("RK45",),
        rtols=(1e-4, 1e-8), timing=False,
    )  # fmt: skip
    runs = cmp.peers.runs
    ours = runs[runs["kind"] == "adaptive"].set_index("rtol")
    scipy_rows = runs[runs["name"] == "RK45"].set_index("rtol")
    assert list(ours.index) == [1e-4, 1e-8] and set(ours["name"]) == {"dormand_prince"}
    for rtol in ours.index:
        assert ours.loc[rtol, "evaluations"] == scipy_rows.loc[rtol, "evaluations"]
        assert ours.loc[rtol, "error"] == pytest.approx(scipy_rows.loc[rtol, "error"], rel=1e-9)
    # the error falls with the tolerance, and stays below the response's own size
    exact = control.initial_response(qc.quarter_car(), T, SEED_X0).outputs[0]
    assert ours.loc[1e-4, "error"] > 1e3 * ours.loc[1e-8, "error"] > 0
    assert ours.loc[1e-4, "error"] < np.abs(exact).max()
