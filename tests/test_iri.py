"""The International Roughness Index (qc_control.road.iri) against the Golden Car's
closed form (ASTM E1926, Sayers 1995)."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest
import scipy.linalg

import qc_control as qc

V = 80.0 / 3.6  # [m/s] ASTM E1926's speed
K1, K2, C, MU = 653.0, 63.3, 6.0, 0.15  # ku/ms, ks/ms, cs/ms, mu/ms (ASTM E1926)


def _closed_form_iri(wavelength: float, amplitude: float) -> float:
    """IRI [m/km] of z = a sin(2πx/λ) in steady state.

    The stroke velocity s(Zs - Zu)/Zr of the Golden Car (its equations of motion per
    unit sprung mass, written here from the textbook form) at ω = 2πV/λ, times the
    250 mm moving average's factor sin(πL/λ)/(πL/λ), times the mean of |sin| = 2/π,
    per speed.
    """
    s = control.tf("s")
    den = (s**2 + C * s + K2) * (MU * s**2 + C * s + K2 + K1) - (C * s + K2) ** 2
    zs = K1 * (C * s + K2) / den
    zu = K1 * (s**2 + C * s + K2) / den
    stroke_velocity = s * (zs - zu)
    omega = 2 * math.pi * V / wavelength
    arg = math.pi * 0.25 / wavelength
    smoothing = abs(math.sin(arg) / arg)
    amplitude_rate = abs(stroke_velocity(1j * omega)) * amplitude * smoothing
    return 1000.0 * (2 / math.pi) * amplitude_rate / V


@pytest.mark.parametrize("wavelength", [1.0, 2.0, 3.5, 7.0, 15.0, 30.0])
def test_sine_profile_matches_the_closed_form(wavelength):
    dx = 0.01 if wavelength < 5 else 0.025  # [m] a 250 mm base of 25 or 10 samples
    length = wavelength * math.ceil(1500 / wavelength)  # whole periods, about 1.5 km
    x = np.arange(0.0, length + dx / 2, dx)
    z = 0.004 * np.sin(2 * math.pi * x / wavelength)
    # 1 %: the bar; the start's transient (decaying within ~10 m) and the
    # sample-wise smoothing leave about 0.5 % at the long wavelengths
    assert qc.road.iri(x, z) == pytest.approx(_closed_form_iri(wavelength, 0.004), rel=0.01)


def test_straight_ramp_gives_zero():
    x = np.arange(0.0, 300.0, 0.05)
    # the car starts moving with the 11 m slope: no stroke ever (rounding only)
    assert qc.road.iri(x, 0.01 * x + 0.3) == pytest.approx(0.0, abs=1e-9)


def test_segments_average_to_the_whole():
    x = np.arange(0.0, 1000.0 + 0.025, 0.025)
    rng = np.random.default_rng(3)
    z = np.cumsum(rng.normal(scale=2e-4, size=x.size))
    whole = qc.road.iri(x, z)
    seg = qc.road.iri(x, z, segment=100.0)
    # the 250 mm average shortens the profile by its base: the last segment ends 0.225 m early
    assert (
        seg.iri.size == 10
        and seg.start[0] == 0.0
        and seg.end[-1] == pytest.approx(1000.0, abs=0.25)
    )
    # weighted by length, the segments' IRIs are the whole's (to rounding)
    assert np.average(seg.iri, weights=seg.end - seg.start) == pytest.approx(whole, rel=1e-9)
    assert seg.overall == pytest.approx(whole, rel=1e-12)


def test_iso8608_classes_rise_by_a_factor_two():
    # an ISO 8608 class is 4x the last in PSD, so 2x in RMS and in IRI
    rough = [qc.road.iri(*qc.road.iso8608_profile(2000.0, 0.05, c, seed=1)) for c in "ABC"]
    assert rough[1] / rough[0] == pytest.approx(2.0, rel=1e-9)
    assert rough[2] / rough[1] == pytest.approx(2.0, rel=1e-9)


@pytest.mark.parametrize(
    "x, z, match",
    [
        (np.arange(0, 5, 0.1), np.zeros(50), "needs more than its 11 m"),
        (np.concatenate([[0.0, 0.1, 0.1], np.arange(0.3, 20, 0.1)]), None, "x must increase"),
        (np.r_[np.arange(0, 10, 0.1), np.arange(10.2, 30, 0.1)], None, "uniform sample interval"),
        (np.arange(0, 20, 0.1), np.r_[np.zeros(10), np.nan, np.zeros(189)], "profile is not "),
    ],
)
def test_bad_profiles_are_refused(x, z, match):
    z = np.zeros_like(x) if z is None else z
    with pytest.raises(ValueError, match=match):
        qc.road.iri(x, z)


def test_bad_segment():
    x = np.arange(0, 20, 0.1)
    with pytest.raises(ValueError, match="segment must be"):
        qc.road.iri(x, np.zeros_like(x), segment=0.0)


@pytest.mark.parametrize("road_class", ["A", "C"])
def test_iso8608_class_iri_is_the_profiles_mean(road_class):
    # the spectral expectation (Gaussian stroke velocity: E|v| = σ√(2/π)) against the IRI
    # of simulated 3 km profiles of the class: 3 km spans ~100 of the body mode's
    # correlation lengths, so each profile's IRI scatters by about 1 %; 3 % is 3 SDs
    expected = qc.road.iso8608_iri(road_class)
    for seed in range(3):
        x, z = qc.road.iso8608_profile(3000.0, 0.05, road_class, seed=seed)
        assert qc.road.iri(x, z) == pytest.approx(expected, rel=0.03)


# --- ASTM E1926 at every sample interval (issue 39 item 5) -----------------------


def _astm_e1926(y: np.ndarray, dx: float) -> float:
    """IRI [m/km] as ASTM E1926 computes it (after Sayers' program in TRR 1501,
    1995), written here from the standard: the profile's slope over the base
    ``NINT(0.25/dx)·dx`` drives the Golden Car, whose states are slopes, stepped
    by its transition matrix with the slope held over each interval; both
    masses start at the slope over the first 11 m (``NINT(11/dx)`` samples);
    the IRI is the mean rectified stroke slope |z1 - z3|."""
    nint = lambda v: int(math.floor(v + 0.5))  # noqa: E731  (Fortran NINT, v > 0)
    base_n = max(1, nint(0.25 / dx))
    base = base_n * dx
    A = np.array(
        [[0, 1, 0, 0], [-K2, -C, K2, C], [0, 0, 0, 1], [K2 / MU, C / MU, -(K1 + K2) / MU, -C / MU]]
    )
    B = np.array([0.0, 0.0, 0.0, K1 / MU])
    dt = dx / V
    ST = scipy.linalg.expm(A * dt)
    PR = np.linalg.solve(A, (ST - np.eye(4)) @ B)
    i11 = nint(11.0 / dx)
    z = np.array([(y[i11] - y[0]) / 11.0, 0.0, (y[i11] - y[0]) / 11.0, 0.0])
    total, count = 0.0, 0
    for i in range(y.size - base_n):
        slope = (y[i + base_n] - y[i]) / base
        z = ST @ z + PR * slope
        total += abs(z[0] - z[2])
        count += 1
    return 1000.0 * total / count


def _probe_profile(dx_fine: float = 0.01, length: float = 1000.0):
    """A 1 km profile with a rough random part and a 1 m wavelength (where the
    sample count matters most), sampled at 10 mm."""
    x = np.arange(0.0, length + dx_fine / 2, dx_fine)
    rng = np.random.default_rng(8)
    z = np.cumsum(rng.normal(scale=1.5e-4, size=x.size)) + 0.001 * np.sin(2 * math.pi * x)
    return x, z


@pytest.mark.parametrize("dx", [0.25, 0.1, 0.05, 0.02])
def test_iri_equals_astm_e1926_at_every_sample_interval(dx):
    """At 0.1 m and 0.02 m the base is NINT(2.5) = 3 and NINT(12.5) = 13 samples;
    Python's round gave 2 and 12 (2.8 % and 0.57 % high on this profile).
    Measured within 1e-5 (the issue asks 0.1 %): both are exact for a slope
    held over each interval and differ only in where the stroke sum starts and
    ends (a few samples of 4,000-50,000), so 1e-4 leaves a factor 10."""
    x, z = _probe_profile()
    every = round(dx / 0.01)
    xs, zs = x[::every], z[::every]
    assert qc.road.iri(xs, zs) == pytest.approx(_astm_e1926(zs, dx), rel=1e-4)


def test_long_intervals_warn_or_are_refused():
    x = np.arange(0.0, 200.0, 0.5)
    with pytest.warns(UserWarning, match="over ASTM E1926's 0.3 m"):
        qc.road.iri(x, 0.001 * np.sin(x))
    x = np.arange(0.0, 200.0, 1.0)
    with pytest.raises(ValueError, match="sample interval is 1 m"):
        qc.road.iri(x, np.zeros_like(x))


def test_a_profile_in_millimetres_is_warned():
    x, z = _probe_profile(0.05, 200.0)
    with pytest.warns(UserWarning, match="in millimetres"):
        qc.road.iri(x, 1000.0 * z)


def test_a_segment_shorter_than_a_sample_is_refused_before_any_work():
    x = np.arange(0, 20, 0.1)
    with pytest.raises(ValueError, match="at least the sample interval 0.1 m, got 1e-09"):
        qc.road.iri(x, np.zeros_like(x), segment=1e-9)
