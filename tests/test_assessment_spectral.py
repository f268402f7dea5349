"""Exact spectral ISO 2631-1 a_w per axis against long time-domain simulations.

Reference, independent of the Lyapunov solution: the car simulated by
python-control's exact first-order-hold discretisation (``control.c2d``,
``method='foh'``: exact for a road linear between samples) on a sampled
random road whose velocity is white, piecewise constant over each 2 ms step
with variance ``q/dt`` (the ISO 8608 class C road at 20 m/s, waviness 2),
weighted in the time domain by `qc.weighted` (itself held to Annex A in
test_weightings.py), its mean square taken after a 20 s start-up.

The statistical error of a finite record is estimated by batch means (20
batches); a tolerance is 1 % where that error is below a third of it, else
three of those errors, stated beside each check.
"""

from __future__ import annotations

import warnings

import control
import numpy as np
import pytest
import scipy.signal

import qc_control as qc
from qc_control.ride.iso2631_spectral import spectral_a_v, spectral_axis_rms

DT = 0.002
#: ISO 8608 class C at 20 m/s: white road velocity of this intensity [m²/s].
Q = qc.ISO8608Road("C", speed=20.0).intensity


def _simulated(model, rows: dict, span: float, seed: int, lag: int = 0, q: float = Q) -> dict:
    """Per axis ``(a_w, relative statistical error)`` of a simulated ride; ``rows``
    maps an axis to ``(weighting, {output label: factor})``. ``lag``: a two-axle
    car on one track, the rear wheel meeting the front wheel's road ``lag``
    steps later; else each road input its own track."""
    N = int(round(span / DT)) + 1
    T = np.arange(N) * DT
    roads = len(model.road_inputs())
    rng = np.random.default_rng(seed)
    if lag:
        one = rng.standard_normal(N - 1 + lag) * np.sqrt(q / DT)
        velocity = np.stack([one[lag:], one[: N - 1]])  # rear(t) = front(t - lag·DT)
    else:
        velocity = rng.standard_normal((roads, N - 1)) * np.sqrt(q / DT)
    zr = np.concatenate([np.zeros((roads, 1)), np.cumsum(velocity * DT, axis=1)], axis=1)
    labels = list(model.system.output_labels)
    wanted = sorted({label for _, parts in rows.values() for label in parts})
    sys = model.system[[labels.index(label) for label in wanted], :]
    d = control.c2d(sys, DT, method="foh")
    y = scipy.signal.dlsim((d.A, d.B, d.C, d.D, DT), zr.T)[1].T
    start = int(round(20.0 / DT))
    out = {}
    for axis, (name, parts) in rows.items():
        acc = sum(factor * y[wanted.index(label)] for label, factor in parts.items())
        aw = qc.weighted(acc, T, name)[start:]
        batches = (aw[: aw.size // 20 * 20] ** 2).reshape(20, -1).mean(axis=1)
        error = batches.std(ddof=1) / np.sqrt(20) / batches.mean() / 2  # of the RMS: half
        out[axis] = (float(np.sqrt(np.mean(aw**2))), float(error))
    return out


def test_half_car_z_and_pitch_against_240_s():
    """The half car's seat (Wk) and pitch (We) within three statistical errors of
    240 s (measured: the seat's error about 0.9 %, the pitch's about 3 %: its
    1-2 Hz mode decorrelates slowly)."""
    model = qc.half_car_model(road=True)
    exact = spectral_axis_rms(model, Q)
    rows = {"z": ("Wk", {"seat_acc": 1.0}), "ry": ("We", {"pitch_acc": -1.0})}
    sim = _simulated(model, rows, 240.0, 1)
    assert sim["z"][1] < 0.01
    for axis, (value, error) in sim.items():
        assert exact[axis] == pytest.approx(value, rel=3 * error), axis


@pytest.mark.filterwarnings("ignore::qc_control.ride.spectral.IndependentTracksWarning")
@pytest.mark.slow
def test_full_car_every_axis_against_1200_s():
    """The full car, seat 0.5 m above the axes: z within 1 % of 1200 s (its
    statistical error measured 0.47 %, so 1 % is two of them; the difference
    measured 0.01 % and, for another seed, 0.06 %); the slower pitch and roll
    axes (We, and x, y from them) within three of their statistical errors
    (measured 0.7-1.3 %; the differences 0.3-1.3 %)."""
    h = 0.5
    model = qc.full_car_model(road=True)
    exact = spectral_axis_rms(model, Q, seat=h)
    assert list(exact) == ["x", "y", "z", "rx", "ry"]
    rows = {
        "x": ("Wd", {"pitch_acc": -h}),
        "y": ("Wd", {"roll_acc": -h}),
        "z": ("Wk", {"seat_acc": 1.0}),
        "rx": ("We", {"roll_acc": 1.0}),
        "ry": ("We", {"pitch_acc": -1.0}),
    }
    sim = _simulated(model, rows, 1200.0, 2)
    assert sim["z"][1] < 0.005
    assert exact["z"] == pytest.approx(sim["z"][0], rel=0.01)
    for axis in ("x", "y", "rx", "ry"):
        value, error = sim[axis]
        assert exact[axis] == pytest.approx(value, rel=3 * error), axis
    k = {"x": 1.0, "y": 1.0, "z": 1.0, "rx": 0.63, "ry": 0.4}  # §8.2, seated
    expected = np.sqrt(sum((k[a] * exact[a]) ** 2 for a in k))
    assert spectral_a_v(exact) == pytest.approx(expected, rel=1e-12)


def test_refuses_a_nonlinear_car_and_a_bad_intensity():
    with pytest.raises(qc.ParameterError) as err:
        spectral_axis_rms(qc.half_car_model(road=True), -1.0)
    assert err.value.name == "intensity"
    with pytest.raises(ValueError, match="nonlinear"):
        spectral_axis_rms(qc.get_model("nonlinear").model(road=True), Q)


#: The frequency-domain integral, on 10,001 log-spaced points from 1e-5 to
#: 1e5 rad/s (trapezoids in ln ω): the integrand |H|² grows as ω² below the
#: weightings' 0.4 Hz high-pass and falls at least as ω⁻² above their band
#: limit, so the tails cut off are negligible, and the trapezoid rule on a
#: smooth integrand that vanishes at both ends converges fast (measured:
#: 10,001 and 400,001 points agree to 1e-15, and either to the Lyapunov
#: value to 4e-13, which bounds what both leave out).
OMEGA = np.logspace(-5.0, 5.0, 10_001)


def _by_quadrature(model, rows: dict, tau: float | None = None, q: float = Q) -> dict:
    """Per axis ``a_w = (q/π ∫₀^∞ Σ_tracks |W(jω) Σ_i G_i(jω) e^{-jωτ_i} / jω|² dω)^½``:
    the car's acceleration per road velocity (``G_i/s``: the road is a
    displacement) of each road input ``i``, through the Annex A weighting ``W``
    (`qc.weighting`, held to the standard's formula in test_weightings.py), for
    white velocities of intensity ``q``: Parseval, no Lyapunov equation. With
    ``tau`` the rear inputs (the second half of them, in the cars' order
    front..., rear...) repeat their side's front one ``tau`` [s] later, the
    exact delay ``e^{-jωτ}``; without, every input is its own track."""
    labels = list(model.system.output_labels)
    s = 1j * OMEGA
    out = {}
    for axis, (name, parts) in rows.items():
        G = sum(
            factor * model.system[labels.index(label), :](1j * OMEGA)[0]
            for label, factor in parts.items()
        )  # (road inputs, ω)
        if tau is not None:
            half = G.shape[0] // 2
            G = G[:half] + G[half:] * np.exp(-s * tau)  # (tracks, ω)
        W = qc.weighting(name)(1j * OMEGA)
        power = np.sum(np.abs(W * G / s) ** 2, axis=0)
        variance = q / np.pi * np.trapezoid(power * OMEGA, np.log(OMEGA))
        out[axis] = float(np.sqrt(variance))
    return out


#: Speeds [m/s] of the checks with the rear wheels' delay: slow, the issue's
#: 20 m/s, and fast (the pitch's error from independent tracks: 0.82, 1.7, 1.9);
#: None, every road input its own track.
SPEEDS = (None, 5.0, 20.0, 30.0)


@pytest.mark.filterwarnings("ignore::qc_control.ride.spectral.IndependentTracksWarning")
@pytest.mark.parametrize("speed", SPEEDS)
@pytest.mark.parametrize("kind", ["half", "full"])
def test_every_axis_equals_the_frequency_domain_integral(kind, speed):
    """Every seat axis of the half and full car, the slow pitch and roll too,
    within 1e-9 of Parseval's integral (measured: 5e-13 at worst; 1e-9 leaves
    room for another BLAS's rounding). With a speed the rear wheels meet the
    front wheels' profile (a + b)/v later: the Lyapunov values' cross-Gramian
    and e^{Aτ} against the integral's exact e^{-jωτ}, no Padé approximation.
    The time-domain checks are bounded by their records' statistics (about
    1 % for pitch and roll at 1,200 s); this one, independent of the Lyapunov
    equation too, is not."""
    h = 0.5
    model = qc.get_model(kind).model(road=True)
    rows = {
        "x": ("Wd", {"pitch_acc": -h}),
        "z": ("Wk", {"seat_acc": 1.0}),
        "ry": ("We", {"pitch_acc": -1.0}),
    }
    if kind == "full":
        rows |= {"y": ("Wd", {"roll_acc": -h}), "rx": ("We", {"roll_acc": 1.0})}
    q = Q if speed is None else qc.ISO8608Road("C", speed=speed).intensity
    tau = None if speed is None else (model.params.a + model.params.b) / speed
    exact = spectral_axis_rms(model, q, seat=h, speed=speed)
    integral = _by_quadrature(model, rows, tau=tau, q=q)
    for axis, value in integral.items():
        assert exact[axis] == pytest.approx(value, rel=1e-9), axis


def test_half_car_with_the_delay_against_a_simulated_road():
    """The half car driven over one simulated road, its rear wheel 70 steps (0.14 s)
    behind the front one (20.1 m/s for its 2.814 m wheelbase), 240 s: the seat
    (Wk) and the pitch (We) within three statistical errors of the Lyapunov
    values with the delay; the independent tracks' pitch, 1.7 times larger,
    is far outside them."""
    model = qc.half_car_model(road=True)
    lag = 70
    speed = (model.params.a + model.params.b) / (lag * DT)
    q = qc.ISO8608Road("C", speed=speed).intensity
    exact = spectral_axis_rms(model, q, speed=speed)
    rows = {"z": ("Wk", {"seat_acc": 1.0}), "ry": ("We", {"pitch_acc": -1.0})}
    sim = _simulated(model, rows, 240.0, 3, lag=lag, q=q)
    for axis, (value, error) in sim.items():
        assert exact[axis] == pytest.approx(value, rel=3 * error), axis
    independent = spectral_axis_rms(model, q)["ry"]
    assert abs(independent / sim["ry"][0] - 1) > 10 * sim["ry"][1]


def test_a_car_on_four_corners_is_warned_of_its_independent_sides():
    """A full car's left and right tracks are independent in the spectral values,
    which an ISO 8608 road's are not: the values say so (and how far off: the
    roll 1.8 times and the heave 0.92 times a simulated ride, measured on class C
    at 20 m/s over 300 s, two seeds); one-track cars are not warned."""
    from qc_control.ride.spectral import IndependentTracksWarning

    with pytest.warns(IndependentTracksWarning, match="left and right tracks"):
        spectral_axis_rms(qc.full_car_model(road=True), Q, speed=20.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", IndependentTracksWarning)
        spectral_axis_rms(qc.half_car_model(road=True), Q, speed=20.0)
        spectral_axis_rms(qc.quarter_car_model(road=True), Q)
