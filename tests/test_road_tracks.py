"""Roads on several wheels: the wheelbase delay on the grid, the isotropic
coherence of two tracks, and the wheelbase-filtering notches."""

import dataclasses
import math

import numpy as np
import pytest
import scipy.integrate
import scipy.signal

import qc_control as qc
from qc_control.models.halfcar import HalfCarParams
from qc_control.ride import road


def test_delay_by_whole_steps_is_an_exact_shift():
    T = np.linspace(0.0, 2.0, 2001)  # h = 1 ms
    zr = road.bump(T, 0.05, 1.0, 10.0, 0.3)
    late = road.delay(T, zr, 0.25)  # 250 steps
    np.testing.assert_array_equal(late[250:], zr[:-250])
    np.testing.assert_array_equal(late[:250], 0.0)
    # longer than the record: the level road before the start throughout
    np.testing.assert_array_equal(road.delay(T, zr + 1.0, 5.0), 1.0)


def test_delay_between_samples_reads_the_input_linear_between_samples():
    """A ramp is linear between samples, so its delay is exact at any tau; a
    smooth bump is within the linear-interpolation bound h²/8·max|zr''|."""
    T = np.linspace(0.0, 1.0, 101)  # h = 10 ms
    ramp = 0.3 * T
    tau = 0.0237  # 2.37 steps
    late = road.delay(T, ramp, tau)
    np.testing.assert_allclose(late, np.where(T >= tau, 0.3 * (T - tau), 0.0), atol=1e-15)
    speed, length, height, h = 10.0, 1.0, 0.05, 0.01
    zr = road.bump(T, height, length, speed, 0.2)
    exact = road.bump(T, height, length, speed, 0.2 + tau)
    bound = h**2 / 8 * height / 2 * (2 * np.pi * speed / length) ** 2
    assert np.max(np.abs(road.delay(T, zr, tau) - exact)) <= bound
    # the half car's inputs: the rear is the front a wheelbase later
    U = road.axle_inputs(T, zr, 2.814, speed)
    np.testing.assert_array_equal(U[1], road.delay(T, zr, 2.814 / speed))
    U4 = road.corner_inputs(T, zr, 2 * zr, 2.814, speed)
    np.testing.assert_array_equal(U4[[0, 2]], U)
    np.testing.assert_array_equal(U4[[1, 3]], 2 * U)


@pytest.mark.parametrize("B", [0.5, 1.5])
def test_isotropic_coherence_is_the_integral_over_the_2d_spectrum(B):
    """ρ(n) = ∫ S(√(n²+m²)) cos(2πmB) dm / ∫ S(√(n²+m²)) dm with S ∝ k⁻³,
    by quadrature (scipy's QAWF for the Fourier integral)."""
    for n in (0.01, 0.1, 0.3, 1.0):

        def S(m, n=n):
            return (n * n + m * m) ** -1.5

        cross = 2 * scipy.integrate.quad(S, 0, np.inf, weight="cos", wvar=2 * np.pi * B)[0]
        auto = 2 * scipy.integrate.quad(S, 0, np.inf)[0]
        # quadrature to ~1e-10; the Bessel form is exact
        assert road.isotropic_coherence(n, B) == pytest.approx(cross / auto, rel=1e-7)
    assert road.isotropic_coherence(0.0, B) == 1.0


def test_left_and_right_tracks_have_the_psd_and_the_cross_spectrum():
    x, left, right = road.iso8608_profiles(8000.0, 0.1, 1.5, "C", seed=3)
    # the left track is the single-track profile of the same seed
    np.testing.assert_array_equal(left, road.iso8608_profile(8000.0, 0.1, "C", 3)[1])
    f, g_ll = scipy.signal.welch(left, fs=10.0, nperseg=1024)
    _, g_rr = scipy.signal.welch(right, fs=10.0, nperseg=1024)
    _, g_lr = scipy.signal.csd(left, right, fs=10.0, nperseg=1024)
    # Welch over ~155 segments: a band sum scatters by ~4 % (measured over seeds
    # 0-5: 0.94-1.06); the bounds are 15 %, about 3.5 standard deviations
    for lo, hi in ((0.03, 0.1), (0.1, 0.3)):
        band = (f > lo) & (f < hi)
        rho = road.isotropic_coherence(f[band], 1.5)
        assert np.sum(g_lr[band].real) / np.sum(rho * g_ll[band]) == pytest.approx(1, abs=0.15)
        assert np.sum(g_rr[band]) / np.sum(g_ll[band]) == pytest.approx(1, abs=0.15)
        assert np.sum(road.iso8608_psd(f[band])) / np.sum(g_ll[band]) == pytest.approx(1, abs=0.15)
    T = np.linspace(0, 10, 2001)
    tracks = road.iso8608_tracks(T, "C", 20.0, 1.5, seed=3)
    np.testing.assert_array_equal(tracks[0], road.iso8608(T, "C", 20.0, 3))


def symmetric_car():
    """a = b and equal axles: the axles' heave contributions are equal and
    their pitch contributions opposite."""
    p = HalfCarParams()
    return dataclasses.replace(
        p, a=1.4, b=1.4, ks_rear=p.ks_front, cs_rear=p.cs_front, mu_rear=p.mu_front
    )


def test_wheelbase_filtering_notches_of_a_symmetric_car():
    p, speed = symmetric_car(), 15.0
    L = p.a + p.b
    f = np.concatenate([np.linspace(0.5, 20, 200), [speed / L, 2 * speed / L, 1.5 * speed / L]])
    tr = qc.transmissibility(p, f, speed=speed)
    assert tr.delay_s == pytest.approx(L / speed)
    np.testing.assert_allclose(tr.wheelbase_notches("pitch")[:2], [speed / L, 2 * speed / L])
    np.testing.assert_allclose(
        tr.wheelbase_notches("heave")[:2], [0.5 * speed / L, 1.5 * speed / L]
    )
    pitch, heave = np.abs(tr.response["pitch_acc"]), np.abs(tr.response["heave_acc"])
    # 1 - e^{-j2πk} and 1 + e^{-jπ(2k+1)} vanish to rounding (|H| ~ 1e2)
    assert pitch[-3] < 1e-12 * pitch.max() and pitch[-2] < 1e-12 * pitch.max()
    assert heave[-1] < 1e-12 * heave.max()


def test_transmissibility_is_the_delayed_sum_of_the_axles():
    """Against C (jωI - A)⁻¹ B + D solved here, with the rear column delayed."""
    p, speed = HalfCarParams(seat_x=0.4), 12.0
    f = np.array([0.7, 1.3, 4.0, 11.0])
    tr = qc.transmissibility(p, f, speed=speed)
    sys = qc.half_car(p, road=True)
    A, B, C, D = (np.asarray(m) for m in (sys.A, sys.B, sys.C, sys.D))
    tau = (p.a + p.b) / speed
    for k, fk in enumerate(f):
        s = 2j * math.pi * fk
        H = C @ np.linalg.solve(s * np.eye(8) - A, B) + D
        seat = H[sys.output_labels.index("seat_acc")]
        assert tr.response["seat_acc"][k] == pytest.approx(
            seat[0] + np.exp(-s * tau) * seat[1], rel=1e-10
        )
    assert tr.units["pitch_acc"] == "(rad/s²)/m" and tr.units["susp_travel_rear"] == "m/m"
    with pytest.raises(ValueError, match="speed is required"):
        qc.transmissibility(p, f)


def test_the_right_track_is_the_documented_sum_of_harmonics():
    """iso8608_profiles' right track against its formula summed directly (no
    FFT): Σ A_k (ρ_k cos(2πn_k x + φ_k) + √(1-ρ_k²) cos(2πn_k x + ψ_k)), with
    the period, the band and the phases as the docstrings state them."""
    length, dx, track, seed = 20.0, 0.1, 1.5, 5
    x, left, right = road.iso8608_profiles(length, dx, track, "B", seed)
    N = int(np.ceil(max(length, 10 / 0.011) / dx)) + 1
    N += N % 2
    n = np.arange(N // 2 + 1) / (N * dx)
    inside = (n >= 0.011) & (n <= 2.83) & (np.arange(n.size) < N // 2)
    A = np.where(inside, np.sqrt(2 * road.iso8608_psd(np.maximum(n, 1e-9), "B") / (N * dx)), 0.0)
    phi = np.random.default_rng(seed).uniform(0, 2 * np.pi, n.size)
    psi = np.random.default_rng([seed, 1]).uniform(0, 2 * np.pi, n.size)
    rho = road.isotropic_coherence(n, track)
    arg = 2 * np.pi * np.outer(x, n)
    expected_left = np.cos(arg + phi) @ A
    expected_right = (rho * np.cos(arg + phi) + np.sqrt(1 - rho**2) * np.cos(arg + psi)) @ A
    scale = np.max(np.abs(expected_left))
    # thousands of terms summed two ways: rounding, 1e-12 of the amplitude
    np.testing.assert_allclose(left, expected_left, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(right, expected_right, rtol=0, atol=1e-12 * scale)
