"""The International Roughness Index (qc_control.road.iri) against the Golden Car's
closed form (ASTM E1926, Sayers 1995)."""

from __future__ import annotations

import math

import control
import numpy as np
import pytest

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
