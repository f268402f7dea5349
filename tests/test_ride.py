"""Transmissibility, ISO 2631-1 weighting and ride metrics against closed forms."""

import control
import numpy as np
import pytest

import qc_control as qc
from qc_control.models.vehicle import STANDARD_GRAVITY
from qc_control.ride import road
from qc_control.ride.comfort import (
    ride_metrics,
    ride_metrics_spectral,
    transmissibility,
    wk_filter,
)

# ISO 2631-1:1997 Table 3, Wk (factor x 1000 in the standard)
WK_TABLE = {
    0.5: 0.418,
    1.0: 0.482,
    2.0: 0.531,
    4.0: 0.967,
    6.3: 1.054,
    10.0: 0.988,
    16.0: 0.768,
    31.5: 0.405,
    63.0: 0.186,
}


def test_wk_reproduces_the_standards_table():
    """The table is the filter rounded to 3 digits: 0.5 % covers that rounding."""
    wk = wk_filter()
    for f, value in WK_TABLE.items():
        assert abs(wk(2j * np.pi * f)) == pytest.approx(value, rel=0.005)


@pytest.mark.parametrize("zeta", [0.05, 0.25, 0.8, 2.0])
def test_invariant_point_does_not_depend_on_damping(zeta):
    """At w = sqrt(ku/mu): |body_acc/zr| = ku/ms (sum of the equations of motion)."""
    p = qc.QuarterCarParams(zeta=zeta)
    f = np.sqrt(p.ku / p.mu) / (2 * np.pi)
    tr = transmissibility(p, [f])
    assert abs(tr.response["body_acc"][0]) == pytest.approx(p.ku / p.ms, rel=1e-12)
    assert tr.invariant_hz == pytest.approx(f, rel=1e-15)
    assert tr.invariant_gain == pytest.approx(p.ku / p.ms, rel=1e-12)


def test_no_invariant_point_with_tire_damping_or_other_states():
    """With tire damping cu the summed equations keep cu(xu' - zr'): at √(ku/mu) the
    gain moves with the damper (94.1, 92.6 and 95.1 (m/s²)/m at ζ = 0.1, 0.5 and 1
    with cu = 300 N·s/m, against 98.04 for all three without; 65.1 was quoted at
    another frequency): no invariant point, NaN. A system
    whose states are not the quarter car's (here the same car, states reordered)
    has other matrices: NaN, where positions read as the quarter car's gave
    numbers that mean nothing."""
    f = np.sqrt(qc.QuarterCarParams().ku / qc.QuarterCarParams().mu) / (2 * np.pi)
    gains = [
        abs(transmissibility(qc.QuarterCarParams(zeta=z, cu=300.0), [f]).response["body_acc"][0])
        for z in (0.1, 0.5)
    ]
    assert abs(gains[0] / gains[1] - 1) > 0.01  # not invariant: the damper moves it
    tr = transmissibility(qc.QuarterCarParams(cu=300.0), [f])
    assert np.isnan(tr.invariant_hz) and np.isnan(tr.invariant_gain)
    sys = qc.quarter_car(road=True)
    order = [2, 3, 0, 1]
    P = np.eye(4)[order]  # x_new = P x: positions, then velocities
    moved = control.ss(
        P @ sys.A @ P.T, P @ sys.B, sys.C @ P.T, sys.D,
        states=[sys.state_labels[i] for i in order],
        inputs=sys.input_labels, outputs=sys.output_labels,
    )  # fmt: skip
    tr = transmissibility(moved, [f])
    assert np.isnan(tr.invariant_hz)
    # the responses themselves do not depend on the states' order
    same = transmissibility(sys, [f]).response["body_acc"][0]
    assert tr.response["body_acc"][0] == pytest.approx(same, rel=1e-12)


def test_static_gains():
    tr = transmissibility(None, [1e-4])
    assert abs(tr.response["xs"][0]) == pytest.approx(1.0, abs=1e-7)  # body follows
    assert abs(tr.response["susp_travel"][0]) < 1e-7 and abs(tr.response["tire_defl"][0]) < 1e-7


def test_transmissibility_frame_and_figure():
    tr = transmissibility(qc.quarter_car(road=True))
    frame = tr.to_frame()
    assert frame.shape == (200, 8) and frame.index.name == "f [Hz]"
    fig = tr.figure()
    assert len(fig.axes) >= 4 and all(ax.get_title() for ax in fig.axes[:4])
    with pytest.raises(ValueError, match="no road input 'zr'"):
        transmissibility(qc.quarter_car())
    with pytest.raises(ValueError, match="freqs_hz"):
        transmissibility(None, [-1.0, 2.0])


def test_ride_metrics_by_hand_on_a_road_step():
    p = qc.QuarterCarParams()
    T = np.linspace(0, 5, 5001)
    r = control.forced_response(qc.quarter_car(p, road=True), T, road.step(T))
    m = ride_metrics(r, p)
    y = dict(zip(r.output_labels, r.outputs))
    rms = lambda v: np.sqrt(np.trapezoid(v**2, T) / 5.0)  # noqa: E731
    assert m["rms_body_acc [m/s²]"] == pytest.approx(rms(y["body_acc"]), rel=1e-12)
    assert m["peak_susp_travel [m]"] == pytest.approx(np.max(np.abs(y["susp_travel"])))
    static = (p.ms + p.mu) * STANDARD_GRAVITY
    assert m["rms_tire_load / static [-]"] == pytest.approx(rms(p.ku * y["tire_defl"]) / static)
    # the Wk-weighted signal: the filter run by scipy.signal.lsim independently
    import scipy.signal

    num, den = wk_filter().num[0][0], wk_filter().den[0][0]
    _, aw, _ = scipy.signal.lsim((num, den), y["body_acc"], T)
    assert m["rms_body_acc_wk [m/s²]"] == pytest.approx(rms(aw), rel=1e-6)
    assert m["vdv [m/s^1.75]"] == pytest.approx(np.trapezoid(aw**4, T) ** 0.25, rel=1e-6)
    assert not m["lift_off"]


def test_lift_off_is_flagged_on_a_tall_kerb():
    """A 30 cm step unloads the tire by more than (ms + mu) g."""
    T = np.linspace(0, 3, 3001)
    r = qc.forced_response(qc.quarter_car(road=True), T, road.step(T, height=-0.3))
    m = ride_metrics(r)
    assert m["lift_off"] and m["lift_off_duration [s]"] > 0


def test_spectral_rms_agrees_with_long_simulated_iso_roads():
    """200 s of a class C road at 20 m/s (4 km): spectral and simulated RMS within 3 %.

    Measured 0.6 %. The generated road has deterministic harmonic amplitudes,
    so the simulated RMS differs from the integral only by the start-up
    transient (the first 10 s are dropped) and the discrete harmonics.
    """
    p = qc.QuarterCarParams()
    T = np.arange(0, 200.0 + 1e-9, 0.002)
    zr = road.iso8608(T, "C", 20.0, seed=3)
    r = qc.forced_response(qc.quarter_car(p, road=True), T, zr, method="rk4")
    keep = T >= 10.0
    window = control.TimeResponseData(
        r.time[keep], r.outputs[:, keep], issiso=False, output_labels=r.output_labels
    )
    sim = ride_metrics(window, p)
    spec = ride_metrics_spectral(p, road.ISO8608Road("C", speed=20.0))
    for key in (
        "rms_body_acc [m/s²]",
        "rms_body_acc_wk [m/s²]",
        "rms_susp_travel [m]",
        "rms_tire_load / static [-]",
    ):
        assert sim[key] == pytest.approx(spec[key], rel=0.03), key


def test_bad_inputs():
    T = np.linspace(0, 1, 101)
    other = control.TimeResponseData(
        T, np.zeros((5, T.size)), issiso=False, output_labels=["xs", "xu", "a", "b", "c"]
    )
    with pytest.raises(ValueError, match="no output 'body_acc'"):
        ride_metrics(other)
    Tn = np.array([0.0, 0.1, 0.3])
    uneven = control.TimeResponseData(
        Tn, np.zeros((5, 3)), issiso=False, output_labels=list(qc.OUTPUTS)
    )
    with pytest.raises(ValueError, match="must be uniform"):
        ride_metrics(uneven)
    with pytest.raises(
        ValueError,
        match="road_class must be an ISO 8608 class, one of A, B, C, D, E, F, G, H, got 'Q'",
    ):
        ride_metrics_spectral(None, road.ISO8608Road("Q"))
    with pytest.raises(ValueError, match="speed must be a finite number > 0 m/s, got 0.0"):
        ride_metrics_spectral(None, road.ISO8608Road("C", speed=0.0))


@pytest.mark.parametrize("cu", [0.0, 300.0])
def test_the_transmissibility_figure_marks_an_invariant_point_only_where_there_is_one(cu):
    """The report's figure: the circle and its legend entry with the quarter car's
    invariant point, neither (no "nan Hz") with tire damping."""
    from types import SimpleNamespace

    from qc_control.report.figures import transmissibility_figure

    p = qc.QuarterCarParams(cu=cu)
    cmp = SimpleNamespace(transmissibility=transmissibility(p), model=None)
    fig = transmissibility_figure(cmp)
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    marked = any("invariant point" in label for label in labels)
    assert marked == (cu == 0.0)
    assert not any("nan" in label for label in labels)
