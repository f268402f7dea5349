"""Every registered ride metric against its definition, written out here.

Each metric of `qc_control.ride.metrics.METRICS` is evaluated on signals
whose value is known in closed form: a sine over whole periods (RMS
``a/√2``, peak ``a``, fourth-power mean ``3a⁴/8``), a first-order step
(its 2 % settling time), white noise of known variance. The reference is a
formula in this file, never another path through the registry; both the
whole-response path (`RideSignals`, what `ride_metrics` uses) and the
streamed one (`MetricStream`, what `sweep` uses) are held to it. The ISO
2631-1 weighting is written out here from the standard's Annex A
(``wk_gain``), evaluated with numpy, not with qc_control's filter.
"""

from __future__ import annotations

import numpy as np
import pytest

from qc_control.models.vehicle import Corner, SignalRoles
from qc_control.ride.iso2631 import wk_weighted
from qc_control.ride.metrics import (
    METRICS,
    WEIGHTED_ACC,
    MetricStream,
    RideSignals,
    evaluate,
    metric_columns,
)

KT, STATIC = 2.0e5, 3000.0  # tire stiffness [N/m], static wheel load [N]
ROLES = SignalRoles("acc", "z", (Corner("", "travel", "tire", None, KT, STATIC),))
LABELS = ("acc", "z", "travel", "tire")


def wk_gain(f):
    """|Wk(j2πf)| of ISO 2631-1:1997, Annex A (Table A.2's f1…f6, Q1…Q6)."""
    s = 2j * np.pi * np.asarray(f, dtype=float)
    w1, w2, w3, w4, w5, w6 = (2 * np.pi * x for x in (0.4, 100.0, 12.5, 12.5, 2.37, 3.35))
    q12, q4, q56 = 1 / np.sqrt(2), 0.63, 0.91
    high_pass = s**2 / (s**2 + w1 * s / q12 + w1**2)
    low_pass = w2**2 / (s**2 + w2 * s / q12 + w2**2)
    transition = (1 + s / w3) / (1 + s / (q4 * w4) + s**2 / w4**2)
    step = (s**2 + w5 * s / q56 + w5**2) / (s**2 + w6 * s / q56 + w6**2)
    return np.abs(high_pass * low_pass * transition * step)


def both_paths(T, signals, names):
    """Each metric's column -> value, by `RideSignals` and by `MetricStream`
    (fed in three uneven pieces, as a sweep's blocks come). A sweep streams
    the weighted acceleration through its own filter; here the stream is
    given the whole path's, so that it is held to the same formula."""
    outputs = {k: np.atleast_2d(v) for k, v in signals.items()}
    whole = evaluate(RideSignals(T, outputs, ROLES), names)
    items = metric_columns(names, ROLES)
    stream = MetricStream(items, ROLES, T, [np.array([KT])], [np.array([STATIC])])
    if stream.weighted:
        outputs[WEIGHTED_ACC] = wk_weighted(outputs["acc"], T)
    stream.start({k: v[:, -1] for k, v in outputs.items()})
    for piece in np.array_split(np.arange(T.size), [T.size // 7, T.size // 2]):
        stream.update(piece, {k: v[:, piece] for k, v in outputs.items()})
    streamed = stream.result()
    return {c: (float(whole[c][0]), float(streamed[c][0])) for c in whole}


def sine_signals(T, amplitudes, f):
    """Every signal a sine of frequency f [Hz] with its own amplitude."""
    return {k: a * np.sin(2 * np.pi * f * T) for k, a in zip(LABELS, amplitudes)}


#: 40 whole periods of 2 Hz, 200 samples per period; the sine's peak is a sample
T_SINE = np.linspace(0.0, 20.0, 8001)
F_SINE = 2.0
AMP = dict(acc=1.5, z=0.02, travel=0.03, tire=0.01)


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        # the trapezoidal mean of sin² over whole periods is ½ exactly (to rounding)
        ("rms_body_acc", AMP["acc"] / np.sqrt(2)),
        ("peak_body_acc", AMP["acc"]),
        ("rms_susp_travel", AMP["travel"] / np.sqrt(2)),
        ("peak_susp_travel", AMP["travel"]),
        ("peak_tire_defl", AMP["tire"]),
        # RMS dynamic tire load kt·a/√2 over the static load
        ("rms_tire_load / static", KT * AMP["tire"] / np.sqrt(2) / STATIC),
    ],
)
def test_rms_and_peak_of_a_sine(name, expected):
    values = both_paths(T_SINE, sine_signals(T_SINE, AMP.values(), F_SINE), [name])
    (whole, streamed) = values[METRICS[name].column()]
    # sums of 8001 squares: rounding ~1e-13 relative; sin(π/2) is exact to 1 ulp
    assert whole == pytest.approx(expected, rel=1e-12)
    assert streamed == pytest.approx(expected, rel=1e-12)


def test_weighted_rms_and_vdv_of_a_long_sine():
    """A sine of 4 Hz (Wk's plateau) for 400 s: a_w = |Wk(4 Hz)|·a sin(...),
    so its RMS is ``|Wk|a/√2`` and its VDV ``(∫ a_w⁴ dt)^¼ = |Wk|a(3T/8)^¼``."""
    T = np.linspace(0.0, 400.0, 400 * 200 + 1)
    a, f = 1.2, 4.0
    signals = {k: a * np.sin(2 * np.pi * f * T) for k in LABELS}
    values = both_paths(T, signals, ["rms_body_acc_wk", "vdv"])
    gain = wk_gain(f)
    # The filter starts at rest: its start-up transient (slowest poles at
    # 0.4 Hz, Q = 1/√2, time constant 0.56 s) takes about two time constants'
    # worth of the steady signal's energy, 1.1 s of 400 s: 2.8e-3 of the mean
    # square, 1.4e-3 of the RMS and the VDV (measured 1.43e-3, 1.40e-3). The
    # first-order hold of the samples changes |Wk| at 4 Hz by (2πf·dt)²/12 =
    # 5e-5. Bound: 3e-3.
    for whole, streamed in [values["rms_body_acc_wk [m/s²]"]]:
        assert whole == pytest.approx(gain * a / np.sqrt(2), rel=3e-3)
        assert streamed == pytest.approx(whole, rel=1e-9)
    for whole, streamed in [values["vdv [m/s^1.75]"]]:
        assert whole == pytest.approx(gain * a * (3 * T[-1] / 8) ** 0.25, rel=3e-3)
        assert streamed == pytest.approx(whole, rel=1e-9)


def test_the_weighting_table_of_the_standard():
    """The formula above reproduces ISO 2631-1 Table 3 (Wk ×1000 at the
    nominal one-third-octave frequencies, to one unit of its last digit): the
    check on the reference itself."""
    table = {0.5: 418, 1.0: 482, 2.0: 531, 4.0: 967, 6.3: 1054, 8.0: 1036, 16.0: 768, 31.5: 405}
    for f, w in table.items():
        assert wk_gain(f) * 1000 == pytest.approx(w, abs=1.0), f


def test_rms_of_white_noise_of_known_variance():
    """Gaussian white noise of standard deviation σ: the mean square of N
    samples has relative standard deviation √(2/N) = 3.2e-3 for N = 200 001,
    its root 1.6e-3; the bound 1e-2 on the RMS is six of those (the seed is
    fixed: measured 7e-4)."""
    rng = np.random.default_rng(2631)
    T = np.linspace(0.0, 200.0, 200_001)
    sigma = dict(acc=0.7, z=0.01, travel=0.02, tire=0.004)
    signals = {k: s * rng.standard_normal(T.size) for k, s in sigma.items()}
    values = both_paths(T, signals, ["rms_body_acc", "rms_susp_travel", "rms_tire_load / static"])
    expected = {
        "rms_body_acc [m/s²]": sigma["acc"],
        "rms_susp_travel [m]": sigma["travel"],
        "rms_tire_load / static [-]": KT * sigma["tire"] / STATIC,
    }
    for column, value in expected.items():
        whole, streamed = values[column]
        assert whole == pytest.approx(value, rel=1e-2), column
        assert streamed == pytest.approx(whole, rel=1e-12), column


def test_weighted_rms_of_white_noise_of_known_variance():
    """Samples of white noise, linear between samples (as the weighting reads
    them): the signal's two-sided PSD is ``σ²·dt·(2 + cos ωdt)/3``, so the
    weighted mean square is ``∫ |Wk(f)|² σ² dt (2 + cos 2πf dt)/3 df`` over
    all f. Statistical bound: Wk passes about 20 Hz of the 500 Hz band, so the
    100 s record holds ~4000 independent values: 1.6e-2 relative standard
    deviation of the mean square, 8e-3 of the RMS, and 4e-2 on the RMS is
    five of them (with the filter's start-up transient, 1e-3; measured 3.3e-3)."""
    rng = np.random.default_rng(8608)
    dt, sigma = 1e-3, 2.0
    T = np.arange(100_001) * dt
    acc = sigma * rng.standard_normal(T.size)
    signals = dict(acc=acc, z=acc, travel=acc, tire=acc)
    (whole, streamed) = both_paths(T, signals, ["rms_body_acc_wk"])["rms_body_acc_wk [m/s²]"]
    # |Wk|² falls as f⁻⁶ past 100 Hz: beyond 1 kHz it adds < 1e-8 of the total
    f = np.linspace(0.0, 1000.0, 100_001)
    psd = sigma**2 * dt * (2 + np.cos(2 * np.pi * f * dt)) / 3
    mean_square = 2 * np.trapezoid(wk_gain(f) ** 2 * psd, f)
    assert whole == pytest.approx(np.sqrt(mean_square), rel=4e-2)
    assert streamed == pytest.approx(whole, rel=1e-9)


def test_settling_time_of_a_first_order_step():
    """``z = 1 - e^{-t/τ}`` on [0, t_end]: it ends at ``z_end = 1 - e^{-t_end/τ}``
    and departs most from it at t = 0; it stays within 2 % of that departure
    from ``t_s = -τ ln(0.02 + 0.98 e^{-t_end/τ})`` on. The metric gives the
    first sample after the last one outside: within one step of t_s."""
    tau, dt = 0.3, 1e-3
    T = np.arange(0, 5001) * dt
    z = 1 - np.exp(-T / tau)
    signals = dict(acc=z, z=z, travel=z, tire=z)
    whole, streamed = both_paths(T, signals, ["settling_time"])["settling_time [s]"]
    t_s = -tau * np.log(0.02 + 0.98 * np.exp(-T[-1] / tau))
    assert t_s < whole <= t_s + dt
    assert streamed == whole


def test_lift_off_of_a_sine_past_the_static_load():
    """A tire deflection ``a sin ωt`` with ``a > c = static/kt``: the wheel
    would be off the road while ``sin ωt > c/a``, a fraction
    ``½ - arcsin(c/a)/π`` of each period. Counted in samples, each of the two
    crossings per period is off by at most one step."""
    c = STATIC / KT  # 15 mm
    amplitudes = dict(acc=1.0, z=0.01, travel=0.01, tire=2 * c)
    signals = sine_signals(T_SINE, amplitudes.values(), F_SINE)
    values = both_paths(T_SINE, signals, ["lift_off", "lift_off_duration"])
    duration = T_SINE[-1] * (0.5 - np.arcsin(c / amplitudes["tire"]) / np.pi)
    dt, periods = T_SINE[1] - T_SINE[0], T_SINE[-1] * F_SINE
    for whole, streamed in [values["lift_off_duration [s]"]]:
        assert whole == pytest.approx(duration, abs=2 * periods * dt)
        assert streamed == whole
    assert values["lift_off"] == (True, True)
    # below the static load: never off the road
    amplitudes["tire"] = 0.99 * c
    signals = sine_signals(T_SINE, amplitudes.values(), F_SINE)
    values = both_paths(T_SINE, signals, ["lift_off", "lift_off_duration"])
    assert values["lift_off"] == (False, False)
    assert values["lift_off_duration [s]"] == (0.0, 0.0)


def annex_a_gain(f, f1, f2, f3, f4, q4, f5=None, q5=None, f6=None, q6=None):
    """|W(j2πf)| of ISO 2631-1:1997 Annex A for Table A.2's row (None: ∞)."""
    s = 2j * np.pi * np.asarray(f, dtype=float)
    w = lambda x: 2 * np.pi * x  # noqa: E731
    q12 = 1 / np.sqrt(2)
    h = s**2 / (s**2 + w(f1) * s / q12 + w(f1) ** 2)
    h = h * w(f2) ** 2 / (s**2 + w(f2) * s / q12 + w(f2) ** 2)
    h = h * (1 + (s / w(f3) if f3 else 0)) / (1 + s / (q4 * w(f4)) + s**2 / w(f4) ** 2)
    if f5 is not None:
        h = h * (s**2 + w(f5) * s / q5 + w(f5) ** 2) / (s**2 + w(f6) * s / q6 + w(f6) ** 2)
    return np.abs(h)


#: Table A.2's We (rotations) and Wf (motion sickness) rows
WE = (0.4, 100.0, 1.0, 1.0, 0.63)
WF = (0.08, 0.63, None, 0.25, 0.86, 0.0625, 0.80, 0.1, 0.80)
#: a car that pitches and rolls: its corners are named as the full car's
CAR_ROLES = SignalRoles(
    "acc",
    "z",
    tuple(Corner(n, "travel", "tire", None, KT, STATIC) for n in ("front left", "rear right")),
)


def test_iso_axes_and_a_v_of_long_sines():
    """Sines for 400 s, tapered in over 3 s so the filters' start-up rings
    little: the vertical at 4 Hz, pitch at 2 Hz, roll at 1.5 Hz. Each a_w is
    ``|W(f)| a/√2`` (the taper's missing energy, (1 - 3/8)·3 s / 400 s, is
    0.47 % of the mean square, 0.23 % of the RMS; with the filters' ringing
    measured 0.37 % at most: bound 6e-3), and a_v is ``(a_wz² + (0.4 a_wry)² +
    (0.63 a_wrx)²)^½`` (ISO 2631-1 §8.2's k, typed here) to rounding. The
    quarter car's roles give a_v = a_w_z and no rotation."""
    T = np.linspace(0.0, 400.0, 400 * 200 + 1)
    ramp = np.where(T < 3.0, 0.5 - 0.5 * np.cos(np.pi * np.minimum(T, 3.0) / 3.0), 1.0)
    signals = {label: np.zeros_like(T) for label in LABELS}
    signals["acc"] = 1.2 * ramp * np.sin(2 * np.pi * 4.0 * T)
    signals["pitch_acc"] = 2.0 * ramp * np.sin(2 * np.pi * 2.0 * T)
    signals["roll_acc"] = 3.0 * ramp * np.sin(2 * np.pi * 1.5 * T)
    outputs = {k: v[None, :] for k, v in signals.items()}
    names = ["a_w_z", "a_w_rx", "a_w_ry", "a_v"]
    got = {k: float(v[0]) for k, v in evaluate(RideSignals(T, outputs, CAR_ROLES), names).items()}
    assert got["a_w_z [m/s²]"] == pytest.approx(wk_gain(4.0) * 1.2 / np.sqrt(2), rel=6e-3)
    assert got["a_w_ry [rad/s²]"] == pytest.approx(
        annex_a_gain(2.0, *WE) * 2 / np.sqrt(2), rel=6e-3
    )
    assert got["a_w_rx [rad/s²]"] == pytest.approx(
        annex_a_gain(1.5, *WE) * 3 / np.sqrt(2), rel=6e-3
    )
    a_v = np.sqrt(
        got["a_w_z [m/s²]"] ** 2
        + (0.4 * got["a_w_ry [rad/s²]"]) ** 2
        + (0.63 * got["a_w_rx [rad/s²]"]) ** 2
    )
    assert got["a_v [m/s²]"] == pytest.approx(a_v, rel=1e-12)
    quarter = evaluate(RideSignals(T, outputs, ROLES), names)
    assert float(quarter["a_v [m/s²]"][0]) == pytest.approx(got["a_w_z [m/s²]"], rel=1e-12)
    assert float(quarter["a_w_ry [rad/s²]"][0]) == 0.0
    # a car that pitches, its pitch not given: refused by name, never left out of a_v
    without = {k: v for k, v in outputs.items() if k != "pitch_acc"}
    with pytest.raises(ValueError, match="'pitch_acc'"):
        evaluate(RideSignals(T, without, CAR_ROLES), ["a_v"])
    # the rotations are whole signals: a sweep does not stream them
    assert not MetricStream.supports(metric_columns(["a_w_ry"], CAR_ROLES), CAR_ROLES)


def test_msdv_of_a_slow_heave():
    """``MSDV = (∫ a_wf² dt)^½ = |Wf(f)| a (T/2)^½`` for a 0.2 Hz sine over 600 s;
    Wf's start-up (poles down to 0.08 Hz) takes about 2 % of the dose: 2.5e-2."""
    T = np.linspace(0.0, 600.0, 600 * 20 + 1)
    signals = {label: np.zeros_like(T) for label in LABELS}
    signals["acc"] = 0.8 * np.sin(2 * np.pi * 0.2 * T)
    values = evaluate(RideSignals(T, {k: v[None] for k, v in signals.items()}, ROLES), ["msdv"])
    expected = annex_a_gain(0.2, *WF) * 0.8 * np.sqrt(600.0 / 2)
    assert float(values["msdv [m/s^1.5]"][0]) == pytest.approx(expected, rel=2.5e-2)


def test_mtvv_of_a_burst_is_the_largest_one_second_window():
    """MTVV against a running RMS summed here window by window (1 s = 200
    samples, trapezoid ends) of the Wk-weighted signal: 1e-9 (rounding)."""
    dt = 0.005
    T = np.arange(0.0, 8.0 + dt / 2, dt)
    signals = {label: np.zeros_like(T) for label in LABELS}
    signals["acc"] = np.where((T > 3) & (T < 3.4), 2.5 * np.sin(2 * np.pi * 5 * T), 0.0)
    outputs = {k: v[None] for k, v in signals.items()}
    values = evaluate(RideSignals(T, outputs, ROLES), ["mtvv"])
    aw = wk_weighted(signals["acc"], T)
    n = 200
    direct = max(
        np.sqrt(dt * (np.sum(aw[i - n : i + 1] ** 2) - 0.5 * (aw[i - n] ** 2 + aw[i] ** 2)))
        for i in range(n, T.size)
    )
    assert float(values["mtvv [m/s²]"][0]) == pytest.approx(direct, rel=1e-9)


#: the metric each test above holds to its definition
CHECKED = {
    "rms_body_acc",
    "peak_body_acc",
    "rms_susp_travel",
    "peak_susp_travel",
    "peak_tire_defl",
    "rms_tire_load / static",
    "rms_body_acc_wk",
    "vdv",
    "settling_time",
    "lift_off",
    "lift_off_duration",
    "a_w_z",
    "a_w_rx",
    "a_w_ry",
    "a_v",
    "mtvv",
    "msdv",
}


def test_every_registered_metric_has_a_reference_here():
    """A metric added to the registry needs its definition written out above."""
    assert set(METRICS) == CHECKED
