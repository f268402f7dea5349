"""The nonlinear reference through many events, at rest on a kink, and when it stalls.

Issue 28 items 2 and 6. The reference (`nonlinear_reference`, DOP853 restarted
at each switching event) is checked against an independent solve of the car's
equations written out below (`by_hand`): scipy's DOP853 at rtol = atol = 1e-12,
stopped at each contact and bump-stop event and restarted 1e-9 s past it, split
at the bump's two ends; before the bump the car rests at its static equilibrium,
x = 0 exactly (no force acts), so the hand solve starts where the road rises and
never meets a switching function sitting at 0.
"""

import math
import re
import warnings

import numpy as np
import pytest
from reports_shared import quick_figures, untimed, without_pdf  # noqa: F401  (fixtures)
from scipy.integrate import solve_ivp

import qc_control as qc
from qc_control.cli.console import main
from qc_control.studies.compare import nonlinear_reference

P = qc.QuarterCarParams()
G = 9.80665
BUMP_L, SPEED, T0 = 8.0, 20.0, 0.1  # the nonlinear car's default road: the lift-off bump
TB = BUMP_L / SPEED
T_LIFT = np.linspace(0.0, 0.8, 401)  # its default grid, h = 2 ms


def bump_of(height):
    def bump(t):
        s = t - T0
        return 0.5 * height * (1 - math.cos(2 * math.pi * s / TB)) if 0 <= s <= TB else 0.0

    return bump


def road_of(height):
    """The car's road: `bump_of`'s bump as a `qc.road.Bump` (the reference keeps the function)."""
    return qc.road.Bump(height=height, length=BUMP_L, speed=SPEED, t0=T0)


def by_hand(p, clearance, stiffness, road):
    """The car's right-hand side and its two switching functions, from the equations."""
    delta0 = (p.ms + p.mu) * G / p.ku

    def rhs(t, x):
        vs, vu, xs, xu = x
        d = xs - xu
        stop = -stiffness * (-d - clearance) if -d > clearance else 0.0  # on the body
        f = p.ks * d + p.cs * (vs - vu) + stop
        tire = max(0.0, p.ku * (delta0 - (xu - road(t))))
        return [-f / p.ms, (f + tire - p.ku * delta0) / p.mu, vs, vu]

    def contact(t, x):
        return delta0 - (x[3] - road(t))

    def stop(t, x):
        return x[2] - x[3] + clearance

    contact.terminal = stop.terminal = True
    return rhs, [contact, stop]


def hand_reference(T, p=P, clearance=math.inf, stiffness=0.0, height=0.2):
    """DOP853 (rtol = atol = 1e-12) from rest at T0, restarted 1e-9 s past each event."""
    rhs, events = by_hand(p, clearance, stiffness, bump_of(height))
    if math.isinf(clearance):
        events = events[:1]
    out, found = np.zeros((4, T.size)), []
    x, t = np.zeros(4), T0
    kw = dict(method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
    for t_stop in (T0 + TB, T[-1]):
        while t < t_stop:
            sol = solve_ivp(rhs, (t, t_stop), x, events=events, **kw)
            pieces = [sol]
            t, x = sol.t[-1], sol.y[:, -1]
            if sol.status == 1:
                if not found or t - found[-1] > 2e-9:  # a kink sat on is one event
                    found.append(t)
                pieces.append(solve_ivp(rhs, (t, min(t + 1e-9, t_stop)), x, **kw))
                t, x = pieces[-1].t[-1], pieces[-1].y[:, -1]
            for piece in pieces:
                inside = (T >= piece.t[0]) & (T <= piece.t[-1])
                if inside.any():
                    out[:, inside] = piece.sol(T[inside])
    return out, np.array(found)


def assert_matches_hand(x, T, **car):
    """The reference's states against the hand solve: within 1e-9 m and 1e-7 m/s.

    Two DOP853 solves at 1e-12 of the same equations, each locating the events to
    ~1e-11 s: measured at most 7.6e-12 m and 4.2e-10 m/s apart over these cases (the
    velocities carry the jump in acceleration at each root times the roots' difference).
    The bounds leave a margin of ~100x for other platforms' rounding.
    """
    hand, events = hand_reference(T, **car)
    np.testing.assert_allclose(x[2:], hand[2:], rtol=0, atol=1e-9)
    np.testing.assert_allclose(x[:2], hand[:2], rtol=0, atol=1e-7)
    return events


@pytest.mark.parametrize(
    "clearance, stiffness, height",
    [(0.0, 1e5, 0.2), (0.0, 1e6, 0.3), (0.05, 1e10, 0.2)],
    ids=["clearance 0", "clearance 0, 30 cm bump", "1e10 N/m stop"],
)
def test_reference_through_bump_stop_events(clearance, stiffness, height):
    """The CLI's `--bump-stop 0,1e5`, `0,1e6 --bump-height 0.3` and `0.05,1e10` runs."""
    car = qc.nonlinear_quarter_car(
        bump_stop=qc.BumpStop(clearance, stiffness), road=road_of(height)
    )
    ref = nonlinear_reference(car, T_LIFT, events=True)
    events = assert_matches_hand(
        ref.x, T_LIFT, clearance=clearance, stiffness=stiffness, height=height
    )
    # the same events, to the roots' accuracy (a root to ~1e-12 m over a speed of ~1 m/s),
    # but for the stop of clearance 0: both name the moment its travel leaves 0 as the
    # road rises (the hand solve at T0, where it starts on the kink; the reference within
    # the DOP853 step that straddles the road's kink there, where its interpolant first
    # turns negative: the travel grows as (t - T0)**4, so 1e-3 s is ~1e-13 m of it)
    assert ref.t_events.size == events.size
    leaving = clearance == 0
    if leaving:
        assert events[0] == T0 and abs(ref.t_events[0] - T0) < 1e-3
    np.testing.assert_allclose(ref.t_events[leaving:], events[leaving:], rtol=0, atol=1e-9)
    assert np.all(np.isfinite(ref.x)) and 0 < ref.accuracy < 1e-9


@pytest.mark.slow
def test_reference_of_a_tire_of_1e9():
    """The CLI's `--ku 1e9`: the wheel bounces off the road, ~20 contacts in 0.8 s."""
    p = qc.QuarterCarParams(ku=1e9)
    car = qc.nonlinear_quarter_car(p, road=road_of(0.2))
    T = T_LIFT[:201]  # 0-0.4 s: the first flights, under 2 s
    ref = nonlinear_reference(car, T, events=True)
    events = assert_matches_hand(ref.x, T, p=p)
    assert events.size >= 2
    # At ku = 1e9 the later contacts graze: the wheel closes on the road at only
    # 6.5e-4 to 1.5e-3 m/s (measured from the hand solve). Two solves whose states
    # agree to ~1e-11 m place such a root up to ~1e-11 / 6.5e-4 = 1.5e-8 s apart
    # (measured 9.5e-9 s on one CPU, 2e-11 s on another); 1e-7 s leaves a margin
    # of ~6x for that rounding (the first three contacts agree to 2e-11 s).
    np.testing.assert_allclose(ref.t_events, events, rtol=0, atol=1e-7)


def test_two_samples_hold_all_events():
    """`compare_methods(nonlinear model, [0, 0.8], zeros)`: events between two samples."""
    model = qc.nonlinear_quarter_car_model(road=road_of(0.2))
    cmp = qc.compare_methods(model, np.array([0, 0.8]), np.zeros(4), timing=False)
    T = cmp.T
    # refined to 5 samples 0.2 s apart: lift-off and landing fall between two of them
    assert T.size == 2 and cmp.nonlinear.t_events.size == 2
    hand, events = hand_reference(np.linspace(0, 0.8, 5))
    np.testing.assert_allclose(cmp.nonlinear.t_events, events, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        np.asarray(cmp.reference.states)[2:], hand[2:, [0, -1]], rtol=0, atol=1e-9
    )


def test_a_car_at_rest_has_an_exact_reference():
    """`compare_methods(qc.nonlinear_quarter_car_model(), [0, 0.8], zeros)`: no input, at
    rest, the static equilibrium x = 0 throughout; its accuracy 0, not 0/0."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        cmp = qc.compare_methods(
            qc.nonlinear_quarter_car_model(), np.array([0, 0.8]), np.zeros(4), timing=False
        )
    assert np.all(np.asarray(cmp.reference.states) == 0.0)
    assert cmp.reference_error == 0.0 and cmp.nonlinear.t_events.size == 0


@pytest.mark.slow
def test_scenario_with_a_stop_of_clearance_0():
    """`Scenario(model='nonlinear', bump_stop=(0, 1e5)).run()`, against the hand solve."""
    from qc_control.studies.scenario import Scenario

    cmp = Scenario(model="nonlinear", bump_stop=(0, 1e5)).run()
    x = np.asarray(cmp.reference.states)
    assert_matches_hand(x, cmp.T, clearance=0.0, stiffness=1e5)
    labels = cmp.nonlinear.event_labels
    assert labels.count("bump stop") == 2 and labels.count("contact") == 2
    # engaged as the road rises, released; the wheel leaves the road, lands
    assert cmp.nonlinear.event_signs == (-1, 1, -1, 1)


@pytest.mark.slow
# The claim is the exit and the report: its figures (the events' and the parting's among
# them) are still drawn, through the same artists and layout, at 40 dpi; the wall-time runs
# are left out (no time is read; they were a tenth of each run). One run writes the PDF
# too: the car of most events (~20 contacts: the longest events table to lay out); the
# others every format but the PDF (`without_pdf`: 1-2.5 CPU-s a run), whose pages differ
# from it only by their numbers.
@pytest.mark.usefixtures("quick_figures", "untimed")
@pytest.mark.parametrize(
    "options, pdf",
    [
        (["--bump-stop", "0,1e5"], False),
        (["--bump-stop", "0,1e6", "--bump-height", "0.3"], False),
        (["--ku", "1e9"], True),
        (["--bump-stop", "0.05,1e10"], False),
    ],
    ids=lambda o: " ".join(o) if isinstance(o, list) else ("pdf" if o else "no pdf"),
)
def test_cli_report_of_the_nonlinear_car(options, pdf, tmp_path, capsys, request):
    """The CLI's reproductions exit 0 with a report (their references: the tests above)."""
    if not pdf:
        request.getfixturevalue("without_pdf")
    code = main(["report", "--model", "nonlinear", *options, "-q", "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "Traceback" not in err
    assert (tmp_path / "r" / "report.md").exists()
    assert (tmp_path / "r" / "report.pdf").exists() == pdf


# ------------------------------------------------------------------ the budget

FRICTION = dict(damper=lambda v: 1500 * v + 300 * np.sign(v), road=road_of(0.2))


def test_friction_without_a_switching_function_stops_with_its_cause():
    """DOP853 at a Coulomb term stalls in its first stick after the bump (item 6)."""
    car = qc.nonlinear_quarter_car(**FRICTION)
    # 20,000 evaluations: the same car without friction needs ~2,000 on this grid
    with pytest.raises(ValueError) as info:
        nonlinear_reference(car, T_LIFT, events=True, max_nfev=20_000)
    message = str(info.value)
    assert "budget of 20000" in message and "without a switching function" in message
    assert "tanh" in message and "max_nfev" in message
    # the same car with the law smoothed (the message's advice) runs within that budget
    smooth = qc.nonlinear_quarter_car(
        damper=lambda v: 1500 * v + 300 * np.tanh(v / 0.01), road=road_of(0.2)
    )
    ref = nonlinear_reference(smooth, T_LIFT, events=True, max_nfev=20_000)
    assert np.all(np.isfinite(ref.x))


@pytest.mark.parametrize("bad", [0, -5, 1.5, True, "many"])
def test_bad_budget_is_named(bad):
    car = qc.nonlinear_quarter_car(road=road_of(0.2))
    with pytest.raises(ValueError, match="max_nfev must be a positive integer or None"):
        nonlinear_reference(car, T_LIFT, max_nfev=bad)


def test_friction_comparison_ends_with_a_value_error():
    """The issue's reproduction with the default budget: a ValueError, not a run for ever.

    On the issue's grid (T_LIFT, refined to 1601 samples: a budget of 1.7 million
    evaluations) this takes ~17 s; the default budget grows with the samples (1000 each
    and 100,000) while the stall does not depend on them (DOP853 crawls at the bump's
    start, t = 0.1000 s, on either grid), so two samples [0, 0.8] s, refined to 5, show
    the same end after the default 105,000 evaluations in ~1 s.
    """
    model = qc.nonlinear_quarter_car_model(**FRICTION)
    with pytest.raises(ValueError, match="without a switching function") as info:
        qc.compare_methods(model, np.array([0.0, 0.8]), np.zeros(4))
    message = str(info.value)
    assert "budget of 105000 " in message  # the default: 1000 x 5 samples + 100,000
    # stalled within 1 ms of the bump's start, T0 (measured 0.100025 s; 0.100094 s after
    # 400,000 evaluations): where the damper first moves and sign(v) starts to chatter
    reached = float(re.search(r"reached only t = (\S+) s", message).group(1))
    assert T0 <= reached < T0 + 1e-3


def test_a_road_far_faster_than_the_samples_stops_with_the_other_cause():
    """A 1e4 Hz road under samples 2 ms apart: the wheel leaves and meets it every period."""
    car = qc.nonlinear_quarter_car(road=qc.road.Sine(amplitude=0.01, frequency=1e4))
    with pytest.raises(ValueError, match="far faster than the samples") as info:
        nonlinear_reference(car, T_LIFT, events=True, max_nfev=20_000)
    assert "smaller h" in str(info.value) and " events." in str(info.value)
