"""compare_methods on nonlinear systems (issue 11 item 5, issue 16 item 2).

References, each independent of the code under test:

* **The lift-off case** (as in tests/test_nonlinear.py): the seed's car,
  gravity and a unilateral tire over a 1 − cos bump 20 cm high and 8 m
  long at 20 m/s, met at 0.1 s; the road is a function of time, so no
  interpolation of samples limits the order. The equations are written out
  below (`by_hand`) and solved with scipy's DOP853 at rtol = atol = 1e-12,
  stopped at each contact event and restarted, and split at the bump's two
  ends (where the road's second derivative jumps).
* **The linear limit**: with a linear tire and no gravity, the nonlinear
  car is the seed's linear car, whose comparison has the matrix exponential
  as its reference: the two error tables agree to the two references'
  difference (each ~1e-12 m or better).
* **python-control's own solve_ivp** for a clipped-skyhook closed loop
  (`control.input_output_response` at rtol 1e-10).
"""

import math

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.ride.road import bump as road_bump
from qc_control.studies.compare import DEFAULT_X0, nonlinear_reference

# one worker builds the module's fixtures, built again on each worker otherwise
pytestmark = pytest.mark.xdist_group("test_compare_nonlinear")

P = qc.QuarterCarParams()
G = 9.80665
BUMP_H, BUMP_L, SPEED, T0 = 0.2, 8.0, 20.0, 0.1
TB = BUMP_L / SPEED
# The same bump as the car's road (`qc.road.Bump`); `bump` stays the hand-written reference.
BUMP_ROAD = qc.road.Bump(height=BUMP_H, length=BUMP_L, speed=SPEED, t0=T0)
DELTA0 = (P.ms + P.mu) * G / P.ku
T_LIFT = np.linspace(0.0, 0.8, 401)  # h = 2 ms, as the README's table


def bump(t):
    s = t - T0
    return 0.5 * BUMP_H * (1 - math.cos(2 * math.pi * s / TB)) if 0 <= s <= TB else 0.0


def by_hand(t, x):
    """The lift-off car's right-hand side, written out from the equations of motion."""
    vs, vu, xs, xu = x
    f = P.ks * (xs - xu) + P.cs * (vs - vu)
    tire = max(0.0, P.ku * (DELTA0 - (xu - bump(t))))
    return [-f / P.ms, (f + tire - P.ku * DELTA0) / P.mu, vs, vu]


def hand_reference(T):
    """DOP853 (rtol = atol = 1e-12), restarted at the bump's ends and at each contact."""

    def contact(t, x):
        return DELTA0 - (x[3] - bump(t))

    contact.terminal = True
    out, events = np.empty((4, T.size)), []
    x, t = np.zeros(4), 0.0
    for t_stop in (T0, T0 + TB, T[-1]):
        while t < t_stop:
            kw = dict(method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
            sol = solve_ivp(by_hand, (t, t_stop), x, events=contact, **kw)
            inside = (T >= t) & (T <= sol.t[-1])
            out[:, inside] = sol.sol(T[inside])
            t, x = sol.t[-1], sol.y[:, -1]
            if sol.status == 1:
                events.append(t)
                nxt = solve_ivp(by_hand, (t, t + 1e-9), x, method="DOP853", rtol=1e-13, atol=1e-15)
                t, x = nxt.t[-1], nxt.y[:, -1]
    return out, np.array(events)


@pytest.fixture(scope="module")
def lift_off():
    model = qc.nonlinear_quarter_car_model(road=BUMP_ROAD)
    return qc.compare_methods(model, T_LIFT, np.zeros(4), timing=False)


def test_lift_off_reference_against_hand_written_solve_ivp(lift_off):
    hand, events = hand_reference(T_LIFT)
    nl = lift_off.nonlinear
    assert events.size == 2
    # both locate the contact roots to the states' accuracy over the wheel's speed (~1 m/s)
    np.testing.assert_allclose(nl.t_events, events, rtol=0, atol=1e-9)
    assert nl.event_labels == ("contact", "contact")
    x = np.asarray(lift_off.reference.states)
    # two DOP853 solutions at 1e-12 of the same equations: ~1e-12 m apart in position;
    # the reference's own estimate (against a 100x tighter solve) is of that size too
    assert np.max(np.abs(x[2:] - hand[2:])) < 1e-10
    assert 0 < lift_off.reference_error < 1e-10
    # the outputs are the car's own, from the reference's states: xs and the tire force,
    # which is 0 N while the wheel is airborne
    np.testing.assert_array_equal(np.asarray(lift_off.reference.outputs)[0], x[2])
    t = lift_off.T
    air = (t > events[0] + 1e-6) & (t < events[1] - 1e-6)
    assert np.all(np.asarray(lift_off.reference.outputs)[5][air] == 0.0)


def test_lift_off_orders_with_and_without_events(lift_off):
    orders = lift_off.nonlinear.orders
    # the README's table: RK4 4.01/4.00 with events, 1.77/2.15 without (measured on both
    # displacements; here on xs: 4.01 and 2.27)
    assert orders.loc["rk4", "with events"] >= 3.5
    assert orders.loc["rk4", "without events"] < 3.0
    # the low-order methods keep their order either way: their error is not the kink's
    for name, p in (("euler", 1), ("midpoint", 2), ("heun", 2)):
        assert abs(orders.loc[name, "with events"] - p) < 0.15, orders
    t = lift_off.table
    assert t.loc["rk4", "observed order"] == t.loc["rk4", "observed order (events)"]
    conv = lift_off.nonlinear.convergence
    rk4 = conv[conv["method"] == "rk4"].set_index(["events", "level"])["error"]
    # the kink stepped across costs 100x and more in accuracy at every step
    assert all(rk4[False, lvl] > 100 * rk4[True, lvl] for lvl in range(3))
    # every method's run at h located both contacts, each to its own accuracy: RK4's
    # position error (6.5e-10 m) over the wheel's speed (~1 m/s); Euler's (4 mm) shifts
    # the landing by 1.6 ms
    events = lift_off.nonlinear.method_events
    for name, (times, labels) in events.items():
        assert labels == ("contact", "contact"), name
        np.testing.assert_allclose(times, lift_off.nonlinear.t_events, atol=5e-3)
    np.testing.assert_allclose(events["rk4"][0], lift_off.nonlinear.t_events, atol=1e-8)


def test_lift_off_midpoint_and_heun_part_where_the_road_rises(lift_off):
    part = lift_off.nonlinear.parting
    # at rest on a flat road both give x = 0 exactly; from the bump (0.1 s) on the road
    # curves within each step, and Midpoint and Heun sample it at different stages
    assert T0 <= part["from [s]"] <= T0 + 0.01
    assert 1e-7 < part["max [m]"] < 1e-3
    assert part["at [s]"] > T0
    assert lift_off.nonlinear.parting_gap.shape == T_LIFT.shape
    assert not lift_off.coincident  # so the report does not draw them as one


def test_lift_off_modes_are_the_linearisation_at_rest(lift_off):
    lin = lift_off.nonlinear.linearization
    # the static point is in contact: the linearisation is the seed's linear car
    np.testing.assert_allclose(lin.A, qc.quarter_car(P).A, rtol=0, atol=1e-6)
    exact = qc.modal_analysis(P)
    assert lift_off.modes.body.fn == pytest.approx(exact.body.fn, rel=1e-8)
    assert "linearisation at the static equilibrium" in lift_off.nonlinear.linearization_note


@pytest.mark.parametrize("forced", [False, True])
def test_linear_limit_gives_the_linear_error_table(forced):
    """Every nonlinearity off: the same error table as the linear comparison."""
    T = np.linspace(0, 2, 201)
    U, X0 = (road_bump(T, 0.05, 1.0, 10.0, 0.5), np.zeros(4)) if forced else (None, DEFAULT_X0)
    lin = qc.compare_methods(qc.quarter_car_model(P, road=forced), T, X0, U=U, timing=False)
    nl_model = qc.nonlinear_quarter_car_model(P, tire="linear", gravity=False, road=forced)
    nl = qc.compare_methods(nl_model, T, X0, U=U, timing=False)
    cols = [c for c in lin.table.columns if "err" in c and "freq" not in c and "zeta" not in c]
    diff = (nl.table[cols] - lin.table[cols]).abs()
    # the two references differ by their own errors (matrix exponential ~1e-16 m, DOP853
    # ~1e-13 m), and the methods' trajectories by rounding: measured 3e-12 at most
    assert diff.max().max() < 1e-10
    np.testing.assert_allclose(nl.table[cols], lin.table[cols], rtol=1e-5, atol=1e-10)
    np.testing.assert_allclose(
        nl.table["observed order"], lin.table["observed order"], rtol=0, atol=1e-3
    )
    assert nl.nonlinear.switching_labels == () and nl.nonlinear.t_events.size == 0


@pytest.fixture(scope="module")
def skyhook_loop():
    car = qc.quarter_car_model(P, road=True, actuator=True)
    sky = qc.skyhook(2000.0, semi_active="continuous", cmax=4000.0)
    T = np.linspace(0, 1.5, 151)
    zr = road_bump(T, 0.05, 1.0, 10.0, 0.5)
    return qc.closed_loop(car, sky), T, zr


@pytest.mark.slow
def test_semi_active_closed_loop_runs_through_compare_methods(skyhook_loop):
    loop, T, zr = skyhook_loop
    assert isinstance(loop.system, control.InterconnectedSystem)
    cmp = qc.compare_methods(loop, T, np.zeros(4), U=zr, timing=False)
    ctrl = control.input_output_response(
        loop.system,
        T,
        zr,
        np.zeros(4),
        solve_ivp_method="DOP853",
        solve_ivp_kwargs=dict(rtol=1e-10, atol=1e-12, max_step=T[1] - T[0]),
    )
    # python-control's own solve at rtol 1e-10, measured 5e-10 m away (not restarted at
    # the clip's kinks; max_step the sample spacing, or its first step leaps over the
    # bump after 0.5 s at rest)
    ours = np.asarray(cmp.reference.outputs)
    assert np.max(np.abs(ours[:4] - np.asarray(ctrl.outputs)[:4])) < 1e-8
    assert list(cmp.reference.output_labels)[-1] == "fa"
    # the methods converge on it: RK4 at h = 10 ms is within 0.1 mm, Euler much further
    err = cmp.table["max |xs err| [m]"]
    assert err["rk4"] < 1e-4 < err["euler"]
    # no switching functions: the clip's kinks are stepped across; the low orders hold
    assert cmp.nonlinear.switching_labels == () and not cmp.nonlinear.events
    assert abs(cmp.table.loc["euler", "observed order"] - 1) < 0.2
    assert cmp.ride is not None and "max |fa err| [N]" in cmp.table.columns
    # the bare system: the quarter car's labels give the same roles and the same numbers
    bare = qc.compare_methods(loop.system, T, np.zeros(4), U=zr, timing=False, params=P)
    np.testing.assert_array_equal(bare.table["max |xs err| [m]"], err)


def test_bare_nonlinear_car_takes_its_params_from_the_system():
    car = qc.nonlinear_quarter_car({"cs": 2000.0}, road=BUMP_ROAD)
    cmp = qc.compare_methods(car, T_LIFT[:101], np.zeros(4), timing=False, methods=["rk4"])
    assert cmp.params.cs == 2000.0 and cmp.model.body_disp == "xs"
    assert cmp.model.unit("tire_force") == "N"


def test_bad_nonlinear_arguments_are_named(skyhook_loop):
    loop, T, zr = skyhook_loop
    with pytest.raises(ValueError, match="events=True needs switching functions"):
        qc.compare_methods(loop, T, np.zeros(4), U=zr, events=True, timing=False)
    with pytest.raises(ValueError, match="levels must be an integer from 1 to 6, got 0"):
        qc.compare_methods(loop, T, np.zeros(4), U=zr, levels=0, timing=False)
    with pytest.raises(ValueError, match="events and levels apply to nonlinear systems only"):
        qc.compare_methods(qc.quarter_car_model(P), events=True, timing=False)
    other = control.nlsys(lambda t, x, u, p: -x, None, states=["a"], name="decay")
    with pytest.raises(ValueError, match="'decay' is not a known vehicle"):
        qc.compare_methods(other, T, [1.0], timing=False)


def test_nonlinear_reference_names_its_events():
    car = qc.nonlinear_quarter_car(road=BUMP_ROAD)
    ref = nonlinear_reference(car, T_LIFT, events=True, rtol=1e-10)
    assert ref.event_labels == ("contact", "contact")
    assert ref.state_accuracy.shape == (4,)
    assert np.max(ref.state_accuracy) == pytest.approx(ref.accuracy * np.max(np.abs(ref.x)))


# ---------------------------------------------------------------- the report


def test_report_has_the_nonlinear_section(lift_off):
    from qc_control.report import build_blocks, figure_specs
    from qc_control.report.document import fmt, to_markdown

    md = to_markdown("t", build_blocks(lift_off))
    nl = lift_off.nonlinear
    assert "Nonlinear system: events and order" in md
    # the contact times, the orders both ways, the reference's own accuracy, the parting
    for t in nl.t_events:
        assert fmt(t) in md
    assert "contact lost (the wheel leaves the road)" in md
    assert fmt(nl.orders.loc["rk4", "with events"]) in md
    assert fmt(nl.orders.loc["rk4", "without events"]) in md
    assert f"by at most {fmt(lift_off.reference_error)} m in displacement" in md
    assert f"They part at t = {fmt(nl.parting['from [s]'])} s" in md
    assert "linearisation at the static equilibrium" in md
    # the section's figures have labelled axes with SI units
    specs = {spec.name: spec for spec in figure_specs(lift_off)}
    for name in ("events_convergence.png", "parting.png"):
        fig = specs[name].make()
        axes = [ax for ax in fig.axes if ax.get_ylabel()]
        assert axes and all("[" in ax.get_ylabel() for ax in axes), name
        assert "[s]" in fig.axes[-1].get_xlabel()


@pytest.mark.slow
def test_write_report_of_a_nonlinear_comparison(lift_off, tmp_path):
    out = qc.write_report(lift_off, tmp_path / "report", formats=("md", "html", "csv"))
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "Nonlinear system: events and order" in html and "contact regained" in html
    events = (out / "events.csv").read_text().splitlines()
    assert len(events) == 3 and "contact" in events[1]
    assert (out / "parting.png").exists() and (out / "events_convergence.png").exists()


@pytest.mark.slow
def test_scenario_with_a_bump_stop_steps_to_every_event():
    """The Scenario's nonlinear car: the lift-off bump with a 5 cm bump stop of 1e5 N/m.

    The stop engages and releases in compression before the wheel flies; with events
    RK4 keeps order 4 (measured 3.94), stepping across the stop's kink it falls to 0.47.
    """
    from qc_control.studies.scenario import Scenario

    cmp = Scenario(model="nonlinear", bump_stop=(0.05, 1e5)).run()
    nl = cmp.nonlinear
    assert nl.event_labels == ("bump stop", "bump stop", "contact", "contact")
    assert nl.event_signs == (-1, 1, -1, 1)  # engaged, released; contact lost, regained
    assert nl.orders.loc["rk4", "with events"] >= 3.5
    assert nl.orders.loc["rk4", "without events"] < 2.0
    assert cmp.scenario.bump_stop == (0.05, 1e5)
