"""The nonlinear reference under a road step at, just before or inside the run's end.

`qc-control report --model nonlinear --road step --t-end 0.5` (the step's default
t0 is 0.5 s) and the same with ``--road-t0 0.4999`` ended in "Required step size is
less than spacing between numbers": DOP853 read the road already up at a step's end
(its last stage, c = 1), or stepped across the jump of the wheel's acceleration.

The independent reference is the closed form. Before the step the car rests at its
static equilibrium, x = 0 exactly (no force acts). From the step on, its tire only
compresses further (the road rises under it), so it stays in contact, and with the
default spring and damper the car is linear: ``x' = A x + B zr`` with ``zr`` the
step's height, from rest at t0, so

    x(t) = ∫_0^{t - t0} e^{A s} ds · B · height,

computed here as a block of ``expm([[A, B·height], [0, 0]]·τ)`` (Van Loan, IEEE TAC
23(3), 1978), with A and B written out from the car's equations
(`qc_control.models.nonlinear`'s module docstring), not taken from the library.
"""

import math

import numpy as np
import pytest
import scipy.linalg
from qc_control.road import Bump, Sine, Step
from reports_shared import use_placeholders, use_untimed

import qc_control as qc
from qc_control.cli.console import main
from qc_control.studies.compare import nonlinear_reference
from qc_control.studies.scenario import Scenario

P = qc.QuarterCarParams()
HEIGHT = 0.05  # the step's default height [m]


def rest_then_step(T, t0, height=HEIGHT):
    """The car's states on T: 0 before t0, the linear car's step response from t0."""
    A = np.array(
        [
            [-P.cs / P.ms, P.cs / P.ms, -P.ks / P.ms, P.ks / P.ms],
            [P.cs / P.mu, -P.cs / P.mu, P.ks / P.mu, -(P.ks + P.ku) / P.mu],
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
        ]
    )
    M = np.zeros((5, 5))
    M[:4, :4], M[1, 4] = A, P.ku / P.mu * height
    x = np.zeros((4, T.size))
    for k, t in enumerate(T):
        if t >= t0:
            x[:, k] = scipy.linalg.expm(M * (t - t0))[:4, 4]
    return x


def assert_matches(x, expected):
    """Each state within 1e-9 of its largest value, and exactly 0 where it rests.

    The reference runs at rtol 1e-12, atol 1e-12 of each state's largest value: measured
    at most 1.4e-11 of it against the closed form (t0 = 0.25 s, 0.25 s of the step's
    response; 3e-15 over the last 1e-4 s). 1e-9 leaves a margin of ~70x for other
    platforms' rounding.
    """
    scale = np.max(np.abs(expected), axis=1, keepdims=True)
    assert np.all(scale > 0)
    np.testing.assert_allclose(x / scale, expected / scale, rtol=0, atol=1e-9)
    # at rest before the step: no force acts, so the reference is 0 there exactly
    np.testing.assert_array_equal(x[:, ~np.any(expected, axis=0)], 0.0)


def scenario_reference(t0, t_end=0.5, h=None):
    sc = Scenario(model="nonlinear", road=Step(t0=t0), t_end=t_end, h=h)
    vehicle, T, U, _ = sc.problem()
    assert U is None  # the nonlinear car takes the road as a function of time
    return T, nonlinear_reference(vehicle.system, T, 0.0, sc.x0, events=True)


def test_a_step_at_the_last_sample_moves_nothing():
    """`--road step --t-end 0.5`: the step at t0 = t_end; the state there is the left
    limit, the car at rest on [0, t_end), so the reference is 0 throughout."""
    T, ref = scenario_reference(0.5)
    assert T[-1] == 0.5
    np.testing.assert_array_equal(ref.x, 0.0)
    assert ref.t_events.size == 0 and ref.accuracy == 0.0


@pytest.mark.parametrize(
    "t0, h", [(0.4999, 0.01), (0.499, 0.01), (0.25, None)], ids=["1e-4 s", "1e-3 s", "mid"]
)
def test_a_step_before_the_end_against_the_closed_form(t0, h):
    """`--road-t0 0.4999 --h 0.01`: the step 1e-4 s before the end; and a step inside."""
    T, ref = scenario_reference(t0, h=h)
    assert ref.t_events.size == 0  # in contact throughout: the closed form holds
    assert_matches(ref.x, rest_then_step(T, t0))


def test_a_left_continuous_road_function_with_its_jump():
    """A road function that jumps after t0 (``t > t0``, not ``t >= t0``), with ``jumps``:
    each segment reads the road inside itself, so the same closed form holds."""

    def road(t):
        return HEIGHT if t > t0 else 0.0

    t0 = 0.4999
    road.jumps = (t0,)
    with pytest.warns(DeprecationWarning, match=r"plain function zr\(t\).*qc\.road\.Road"):
        car = qc.nonlinear_quarter_car(road=road)  # 0.1's form: still runs, warning
    assert car.jumps == (t0,)
    T = np.linspace(0.0, 0.5, 51)
    ref = nonlinear_reference(car, T, events=True)
    assert_matches(ref.x, rest_then_step(T, t0))


def test_the_comparison_measures_against_the_same_reference():
    """`Scenario.run` (what `qc-control report` runs) on both commands' scenarios."""
    cmp = Scenario(model="nonlinear", road=Step(t0=0.5), t_end=0.5).run()
    np.testing.assert_array_equal(np.asarray(cmp.reference.states), 0.0)
    cmp = Scenario(model="nonlinear", road=Step(t0=0.4999), t_end=0.5, h=0.01).run()
    assert_matches(np.asarray(cmp.reference.states), rest_then_step(cmp.T, 0.4999))


@pytest.mark.slow  # a whole report with its PDF: about 5 s, 2 s with placeholder figures
@pytest.mark.parametrize(
    "options, pictures",
    [([], True), (["--h", "0.01", "--road-t0", "0.4999"], False)],
    ids=["t0 = t_end", "t0 = t_end - 1e-4 s"],
)
def test_cli_report_of_a_step_at_the_end(options, pictures, tmp_path, capsys, monkeypatch):
    """Both commands exit 0 with a report (their references: the tests above).

    The first draws its figures for real: its methods' xs errors are exactly 0,
    which the convergence and work-precision figures must take. The second is
    the reference's case only, with placeholder figures and no wall-time runs
    (`reports_shared`).
    """
    if not pictures:
        use_placeholders(monkeypatch)
        use_untimed(monkeypatch)
    argv = ["report", "--model", "nonlinear", "--road", "step", "--t-end", "0.5", *options]
    code = main([*argv, "--out", str(tmp_path / "R")])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "Traceback" not in err and "internal error" not in err
    assert (tmp_path / "R" / "report.md").exists()


def test_jumps_of_the_roads():
    """A step jumps at t0; a bump, a sine road and no road are continuous."""
    assert Step(t0=0.3).jumps == (0.3,)
    assert Bump().jumps == Sine().jumps == ()
    sc = Scenario(model="nonlinear", road=Step(t0=0.3), t_end=1.0)
    assert sc.vehicle_model(road=True).system.jumps == (0.3,)
    assert qc.nonlinear_quarter_car().jumps == qc.nonlinear_quarter_car(road=False).jumps == ()


@pytest.mark.parametrize(
    "road",
    [
        Step(t0=0.3),
        Step(height=-0.02, t0=0.0),
        Bump(),
        Bump(height=0.2, length=8.0, speed=20.0, t0=0.1),  # the nonlinear car's default
        Bump(height=0.1, length=1.3, speed=15.0, t0=0.2),  # no power of 2 to divide by
        Sine(),
        Sine(amplitude=0.03, frequency=7.3),
    ],
    ids=repr,
)
def test_a_road_at_one_time_is_its_samples_to_the_last_bit(road):
    """The nonlinear car reads its road one time at a time (`Road.height_at`), the
    other cars and the report on the grid (`samples`, `qc_control.ride.road`'s
    functions): the same number at every time, bit for bit, the step's and the
    bump's edges and the floats either side of them among the times."""
    edges = [road.t0] if isinstance(road, Step) else []
    if isinstance(road, Bump):
        edges = [road.t0, road.t0 + road.length / road.speed]
    near = [np.nextafter(e, d) for e in edges for d in (-np.inf, np.inf)]
    rng = np.random.default_rng(8)
    T = np.unique(np.concatenate([np.linspace(-1.0, 2.0, 3001), rng.uniform(-1, 2, 3000)]))
    T = np.unique(np.concatenate([T, edges, near]))
    scalar = np.array([road.height_at(float(t)) for t in T])
    np.testing.assert_array_equal(scalar, road.samples(T))
    # and the base class's fallback, which samples a grid of two times, says the same
    fallback = np.array([super(type(road), road).height_at(t) for t in T[::50]])
    np.testing.assert_array_equal(fallback, scalar[::50])


@pytest.mark.parametrize("bad", [(math.nan,), (math.inf,), ("soon",), 0.5])
def test_bad_jumps_are_named(bad):
    def road(t):
        return 0.0

    road.jumps = bad
    with pytest.raises(ValueError, match=r"road\.jumps must be finite times \[s\], got"):
        with pytest.warns(DeprecationWarning, match="qc.road.Road"):
            qc.nonlinear_quarter_car(road=road)
