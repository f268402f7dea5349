"""compare_methods' numbers against independent calculations."""

import control
import numpy as np
import pandas as pd
import pytest
from scipy.linalg import expm

import qc_control as qc
from qc_control.studies.compare import TOLERANCES

ORDERS = {"euler": 1, "midpoint": 2, "heun": 2, "rk4": 4}
X0 = np.array([0.0, 0.0, 0.05, 0.0])


@pytest.fixture(scope="module")
def seed_cmp():
    """The default scenario, shortened to 0-4 s to keep the suite quick; untimed (no test
    here reads a time: timing is tested by test_steps_compose_and_timing_is_optional,
    which shows every other number unchanged without it)."""
    return qc.compare_methods(qc.QuarterCarParams(), np.linspace(0, 4, 401), X0, timing=False)


def taylor_map(A, h, p):
    term, total = np.eye(4), np.eye(4)
    for k in range(1, p + 1):
        term = term @ (h * A) / k
        total = total + term
    return total


@pytest.mark.slow
def test_errors_against_an_independent_trajectory(seed_cmp):
    """For s = p methods the trajectory is x_{k+1} = T_p(hA) x_k (no stepper involved)."""
    sys = seed_cmp.system
    A, C = np.asarray(sys.A), np.asarray(sys.C)
    T = seed_cmp.T
    exact = control.initial_response(sys, T, X0).outputs
    for name, p in ORDERS.items():
        M = taylor_map(A, 0.01, p)
        x = np.empty((4, T.size))
        x[:, 0] = X0
        for k in range(T.size - 1):
            x[:, k + 1] = M @ x[:, k]
        err = C @ x - exact
        row = seed_cmp.table.loc[name]
        # two evaluations of the same map: agree to rounding, 1e-12 relative
        assert row["max |xs err| [m]"] == pytest.approx(np.max(abs(err[0])), rel=1e-9)
        assert row["rms xu err [m]"] == pytest.approx(np.sqrt(np.mean(err[1] ** 2)), rel=1e-9)
        assert row["max |body_acc err| [m/s²]"] == pytest.approx(np.max(abs(err[4])), rel=1e-9)
        assert row["final |xs err| [m]"] == pytest.approx(abs(err[0, -1]), rel=1e-6, abs=1e-15)
        assert row["RHS evals"] == p * 400 and row["steps"] == 400


@pytest.mark.slow
def test_step_limits_and_modes_from_eigenvalues(seed_cmp):
    lam = np.linalg.eigvals(np.asarray(seed_cmp.system.A))
    euler = min(-2 * l.real / abs(l) ** 2 for l in lam)  # |1 + h lambda| = 1
    assert seed_cmp.table.loc["euler", "h_max [s]"] == pytest.approx(euler, rel=1e-12)
    assert seed_cmp.table.loc["euler", "limited by"] == "body bounce"
    wn, zeta, _ = control.damp(seed_cmp.system, doprint=False)
    assert seed_cmp.modes.body.zeta == pytest.approx(min(zeta), rel=1e-12)
    nm = qc.numerical_modes("euler", 0.01, seed_cmp.modes)
    assert (
        seed_cmp.table.loc["euler", "wheel hop freq err [%]"]
        == nm.loc["wheel hop", "freq error [%]"]
    )


@pytest.mark.slow
def test_observed_orders_in_the_asymptotic_range():
    # h = 2 ms; untimed (the times were 6 of its 7 s, and the orders do not read them)
    cmp = qc.compare_methods(None, np.linspace(0, 2, 1001), X0, timing=False)
    for name, p in ORDERS.items():
        assert cmp.table.loc[name, "observed order"] == pytest.approx(p, abs=0.15)


@pytest.mark.slow
def test_reference_accuracy_is_stated_and_tiny(seed_cmp):
    # python-control's expm recurrence against the modal closed form: rounding only
    assert seed_cmp.reference_error < 1e-14
    assert "closed form" in seed_cmp.reference_description


@pytest.mark.slow
def test_cost_estimates_bracket_the_measurements(seed_cmp):
    conv = seed_cmp.convergence
    estimates = {(c.tolerance, c.method): c for c in seed_cmp.cost_checks}
    for name in ORDERS:
        rows = conv[conv["method"] == name].sort_values("nfev")
        for tol in TOLERANCES:
            check = estimates[tol, name]
            n, kind = check.estimate, check.estimate_kind
            if kind == "interpolated":
                above = rows[rows["error"] > tol]["nfev"].max()
                below = rows[rows["error"] <= tol]["nfev"].min()
                assert above <= n <= below
            else:
                assert kind == "extrapolated" and n > 0


def _body_error(A, C, x0, steps: int, span: float, p: int) -> float:
    """Max |xs error| of the one-step map ``x <- T_p(hA) x`` (an s = p method on
    x' = Ax, `taylor_map`) against the matrix exponential, over ``steps``."""
    h = span / steps
    M, E = taylor_map(A, h, p), expm(h * A)
    x = y = np.asarray(x0, dtype=float)
    worst = 0.0
    for _ in range(steps):
        x, y = M @ x, E @ y
        worst = max(worst, abs(float(C @ (x - y))))
    return worst


@pytest.mark.slow
def test_every_confirmed_cost_reaches_its_target_run_at_that_count(seed_cmp):
    """Issue 38: a cost quoted as enough must be enough. Each confirmed count,
    run by an independent one-step map, reaches its target; each is the one
    the cost table quotes (stages x steps)."""
    sys = seed_cmp.system
    A, C = np.asarray(sys.A), np.asarray(sys.C)[list(sys.output_labels).index("xs")]
    span = float(seed_cmp.T[-1] - seed_cmp.T[0])
    confirmed = [c for c in seed_cmp.cost_checks if c.verdict == "confirmed"]
    assert {c.method for c in confirmed} == set(ORDERS)
    for c in confirmed:
        error = _body_error(A, C, seed_cmp.X0, c.steps, span, ORDERS[c.method])
        # the same arithmetic up to rounding, which accumulates over the steps: at
        # most ~1e-17 m a step on this 5 cm response (175,000 steps: 2e-12 m)
        assert error == pytest.approx(c.error, rel=1e-6, abs=1e-17 * c.steps), c
        assert error <= c.tolerance, c
        assert seed_cmp.cost.loc[c.tolerance, c.method] == c.steps * qc.get_method(c.method).stages
        assert seed_cmp.cost_kind.loc[c.tolerance, c.method] == "confirmed"


@pytest.mark.slow
def test_midpoint_heun_recorded_as_coincident(seed_cmp):
    assert ("midpoint", "heun") in seed_cmp.coincident
    assert seed_cmp.coincident[("midpoint", "heun")] < 1e-12


@pytest.mark.slow
def test_forced_comparison_uses_forced_reference():
    T = np.linspace(0, 2, 201)
    U = np.where(T >= 0.5, 0.05, 0.0)
    cmp = qc.compare_methods(
        qc.quarter_car(road=True), T, np.zeros(4), U=U, methods=("heun", "rk4"), timing=False
    )
    exact = control.forced_response(qc.quarter_car(road=True), T, U, 0).outputs
    ours = qc.forced_response(qc.quarter_car(road=True), T, U, method="rk4").outputs
    assert cmp.table.loc["rk4", "max |xs err| [m]"] == pytest.approx(
        np.max(abs(ours[0] - exact[0]))
    )
    assert "lsim" in cmp.reference_description and cmp.reference_error < 1e-12


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        (dict(h=0.003), ValueError, "must divide the grid spacing"),
        (dict(h=-1.0), ValueError, "h must be a finite step"),
        (dict(methods=()), ValueError, "at least one method"),
        (dict(methods=("rk4", "rk4")), ValueError, "distinct"),
        (dict(methods=("rk5",)), ValueError, "unknown method"),
        (dict(X0=[0, 0, 0.05]), ValueError, "X0 must have shape"),
        (dict(U=np.zeros(7)), ValueError, "system has no inputs|U must have shape"),
    ],
)
def test_bad_input(kwargs, error, words):
    args = dict(T=np.linspace(0, 1, 101), X0=X0)
    args.update(kwargs)
    with pytest.raises(error, match=words):
        qc.compare_methods(qc.quarter_car(), args.pop("T"), args.pop("X0"), repeats=1, **args)


def test_non_uniform_grid_rejected():
    with pytest.raises(ValueError, match="uniformly spaced"):
        qc.compare_methods(None, [0, 0.1, 0.3], X0)


@pytest.mark.slow
def test_steps_compose_and_timing_is_optional():
    """compare_methods is its steps: each run alone gives the same numbers, and
    without timing every number but the times is unchanged."""
    from qc_control.studies import compare as cmp_mod

    T = np.linspace(0, 2, 201)
    X0 = [0.0, 0.0, 0.05, 0.0]
    timed = qc.compare_methods(qc.QuarterCarParams(), T, X0, methods=["heun", "rk4"], repeats=1)
    plain = qc.compare_methods(qc.QuarterCarParams(), T, X0, methods=["heun", "rk4"], timing=False)
    assert plain.table[["wall time [ms]", "LTI engine [ms]"]].isna().all().all()
    assert np.isnan(plain.reference_time)
    numbers = ["max |xs err| [m]", "rms body_acc err [m/s²]", "observed order", "h_max [s]"]
    pd.testing.assert_frame_equal(timed.table[numbers], plain.table[numbers])

    model = qc.quarter_car_model()
    ref = cmp_mod.exact_reference(model.system, T, np.array(X0), outputs=["xs", "xu"])
    assert ref.error == plain.reference_error
    # the modal closed form agrees to rounding: a few ulps of the 5 cm scale
    assert ref.error < 1e-15
    tabs = [qc.get_method("heun"), qc.get_method("rk4")]
    responses = cmp_mod.method_responses(model.system, T, np.array(X0), None, tabs)
    errors = cmp_mod.error_table(responses, ref, model)
    pd.testing.assert_series_equal(errors["max |xs err| [m]"], plain.table["max |xs err| [m]"])
    # every output is measured, by label, in its own unit
    assert {"max |tire_defl err| [m]", "max |body_acc err| [m/s²]"} <= set(errors.columns)


#: The convergence study's time columns (qc_control.studies.timing's measurement).
TIMES = ["time", "time_low", "time_high", "cpu_time"]


def test_a_timed_ladder_beyond_the_stability_limit_has_the_untimed_numbers():
    """Euler on the seed car at h = 40 ms and 20 ms (beyond its 19.8 ms limit), then
    stable: timed, the default engine's step-by-step run of an unstable step is the
    one run, timed once (the peers' ladder takes that time, not a best of 3); every
    number but the times is the untimed study's, to the bit (the same runs)."""
    T = np.linspace(0, 2, 51)
    X0 = [0.0, 0.0, 0.05, 0.0]
    options = dict(methods=["euler", "rk4"], solvers=("RK45",), rtols=(1e-3,), repeats=1)
    timed = qc.compare_methods(qc.QuarterCarParams(), T, X0, **options)
    plain = qc.compare_methods(qc.QuarterCarParams(), T, X0, timing=False, **options)
    conv = timed.convergence
    assert (~conv["stable"]).sum() == 2  # euler at levels 0 and 1
    pd.testing.assert_frame_equal(
        conv.drop(columns=TIMES), plain.convergence.drop(columns=TIMES), check_exact=True
    )
    assert (conv["time"] > 0).all() and plain.convergence["time"].isna().all()
    runs = timed.peers.runs[timed.peers.runs["kind"] == "method"].reset_index(drop=True)
    unstable = ~conv["stable"].to_numpy()
    np.testing.assert_array_equal(runs["time"][unstable], conv["time"][unstable])
    assert (runs["time"] > 0).all()


def test_a_cost_beyond_any_run_is_unreached_not_a_number():
    """Euler from x0 = 1e150 m errs by ~1e143 m; reaching 1e-9 m at order 1 would take
    ~1e152 RHS evaluations (e ∝ h, so n ∝ e0/tol): reported 'unreached', as for a
    method that never converges, not as an integer or an overflow (found by
    tests/test_properties.py at x0 = 1e308)."""
    T = np.arange(51) * 0.01
    cmp = qc.compare_methods(
        qc.QuarterCarParams(), T, [1e150, 0, 0, 0], methods=["euler"], timing=False
    )
    kinds = cmp.cost_kind.loc[:, "euler"]
    assert (kinds == "unreached").all(), kinds
    assert cmp.cost.loc[:, "euler"].isna().all()


# --------------------------------------------------- a bare system's vehicle


def test_a_bare_half_car_under_a_road_is_measured_as_the_half_car():
    """A half car's system without its VehicleModel is found by its signals,
    road inputs included, so the comparison computes its ride metrics as for
    the model itself (the same corners, the same columns)."""
    model = qc.half_car_model(road=True)
    T = np.linspace(0.0, 1.0, 201)
    U = np.vstack([qc.road.bump(T, height=0.02, speed=10.0)] * 2)
    X0 = np.zeros(model.system.nstates)
    bare = qc.compare_methods(model.system, T, X0, U=U, methods=["rk4"], timing=False)
    full = qc.compare_methods(model, T, X0, U=U, methods=["rk4"], timing=False)
    assert bare.model.road_inputs() == ["zr_front", "zr_rear"]
    assert bare.ride is not None
    assert list(bare.ride.columns) == list(full.ride.columns)


def test_parameters_of_another_vehicle_are_refused_naming_both():
    """A quarter car's system with a half car's parameters describes no model:
    the error names the parameters and the system's signals."""
    sys = qc.quarter_car(road=True)
    with pytest.raises(ValueError, match=r"HalfCarParams.*'quarter_car'.*\['zr'\]"):
        qc.compare_methods(sys, params=qc.HalfCarParams(), methods=["rk4"], timing=False)
