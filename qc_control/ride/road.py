"""Road inputs: samples of the road height zr [m] under one wheel or under several.

One track (``quarter_car(road=True)``): `step`, `bump`, `sine`, `iso8608`.
Several wheels (`qc_control.half_car`, `qc_control.full_car`): the rear wheels
meet the front wheels' road a wheelbase later (`delay`, `axle_inputs`,
`corner_inputs`), and the left and right tracks of a random road are partly
correlated (`isotropic_coherence`, `iso8608_tracks`).

A measured profile's International Roughness Index is `iri` (ASTM E1926,
in `qc_control.ride.roughness`).

Every function returns ``zr`` on a given time grid ``T`` [s]; the random
road is deterministic for a given seed. A road is an input linear between
samples (python-control's assumption), so ``control.forced_response``
stays the exact reference.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.special

from ..numerics.integrate import check_time_grid, uniform_step
from ..numerics.limits import check_memory
from .roughness import IRI_SPEED, SMOOTHING_BASE, IRISegments, golden_car_matrices, iri

__all__ = [
    "step",
    "bump",
    "sine",
    "iso8608",
    "iso8608_profile",
    "iso8608_psd",
    "ISO8608_CLASSES",
    "ISO8608_N0",
    "ISO8608_BAND",
    "largest_step",
    "positive",
    "finite",
    "road_class_psd",
    "band_limits",
    "delay",
    "axle_inputs",
    "corner_inputs",
    "isotropic_coherence",
    "iso8608_profiles",
    "iso8608_tracks",
    "iri",
    "iso8608_iri",
    "IRISegments",
]

#: Reference spatial frequency n0 [cycles/m] of ISO 8608.
ISO8608_N0 = 0.1
#: Gd(n0) [m³] of road classes A–H: the geometric mean of each class,
#: 16e-6 · 4^k (ISO 8608:2016, Table 1).
ISO8608_CLASSES = {c: 16e-6 * 4.0**k for k, c in enumerate("ABCDEFGH")}
#: The band of spatial frequencies [cycles/m] the standard classifies,
#: wavelengths from 91 m down to 0.35 m (ISO 8608, 0.011 <= n <= 2.83).
ISO8608_BAND = (0.011, 2.83)


def _grid(T) -> np.ndarray:
    return check_time_grid(T, "T")


def positive(name: str, value, unit: str) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float, np.number))
        or not math.isfinite(value)
        or value <= 0
    ):
        raise ValueError(f"{name} must be a finite number > 0 {unit}, got {value!r}")
    return float(value)


def finite(name: str, value, unit: str) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float, np.number))
        or not math.isfinite(value)
    ):
        raise ValueError(f"{name} must be a finite number [{unit}], got {value!r}")
    return float(value)


def step(T, height: float = 0.05, t0: float = 0.5) -> np.ndarray:
    """A road step of ``height`` [m] at time ``t0`` [s] (a kerb).

    ``zr = height`` for ``t >= t0``, else 0. Between the two samples around
    ``t0`` the input is a ramp, as python-control interpolates it.
    """
    T = _grid(T)
    return np.where(T >= finite("t0", t0, "s"), finite("height", height, "m"), 0.0)


def bump(
    T, height: float = 0.05, length: float = 1.0, speed: float = 10.0, t0: float = 0.5
) -> np.ndarray:
    """A 1 − cos bump of ``height`` [m] and ``length`` [m] met at ``t0`` [s].

    .. math:: z_r = \\frac{h}{2}\\Big(1 - \\cos\\frac{2\\pi x}{\\ell}\\Big),
              \\quad 0 \\le x = v (t - t_0) \\le \\ell
    """
    T = _grid(T)
    height, t0 = finite("height", height, "m"), finite("t0", t0, "s")
    length, speed = positive("length", length, "m"), positive("speed", speed, "m/s")
    x = speed * (T - t0)
    inside = (x >= 0) & (x <= length)
    return np.where(inside, 0.5 * height * (1 - np.cos(2 * np.pi * x / length)), 0.0)


def sine(T, amplitude: float = 0.01, frequency: float = 1.0) -> np.ndarray:
    """A sinusoidal road ``zr = amplitude · sin(2π f t)`` [m], f in Hz."""
    T = _grid(T)
    return finite("amplitude", amplitude, "m") * np.sin(
        2 * np.pi * positive("frequency", frequency, "Hz") * T
    )


def road_class_psd(road_class: str) -> float:
    key = str(road_class).strip().upper()
    if key not in ISO8608_CLASSES:
        raise ValueError(
            f"unknown ISO 8608 road class {road_class!r}; expected one of "
            f"{', '.join(ISO8608_CLASSES)}"
        )
    return ISO8608_CLASSES[key]


def band_limits(band) -> tuple[float, float]:
    lo, hi = (float(b) for b in band)
    if not (0 < lo < hi and math.isfinite(hi)):
        raise ValueError(
            f"band must be (n_min, n_max) with 0 < n_min < n_max cycles/m, got {band!r}"
        )
    return lo, hi


def iso8608_psd(n, road_class: str = "C") -> np.ndarray:
    """ISO 8608 displacement PSD [m³] at spatial frequencies ``n`` [cycles/m].

    .. math:: G_d(n) = G_d(n_0) \\left(\\frac{n}{n_0}\\right)^{-2}, \\quad n_0 = 0.1

    with ``Gd(n0)`` the class's geometric mean, `ISO8608_CLASSES`.
    """
    return road_class_psd(road_class) * (np.asarray(n, dtype=float) / ISO8608_N0) ** -2.0


def largest_step(speed: float, band=ISO8608_BAND) -> float:
    """The largest time step [s] that samples the band at ``speed``: 1/(2 v n_max)."""
    return 1.0 / (2.0 * positive("speed", speed, "m/s") * band_limits(band)[1])


def iso8608_profile(
    length: float, dx: float, road_class: str = "C", seed: int = 0, band=ISO8608_BAND
) -> tuple[np.ndarray, np.ndarray]:
    """A random ISO 8608 road profile in the distance domain.

    Parameters
    ----------
    length : float
        Profile length [m].
    dx : float
        Sample spacing [m]; at most ``1/(2 n_max)`` (0.177 m for the
        standard band) so that the band's shortest wavelength is resolved.
    road_class : {'A', ..., 'H'}
    seed : int
        Seed (>= 0) of the random phases: the same seed gives the same road.
    band : (n_min, n_max), default ``(0.011, 2.83)`` cycles/m

    Returns
    -------
    x, z : ndarray
        Distance [m] from 0 and road height [m].

    Notes
    -----
    The spectral method (sum of harmonics, evaluated by inverse FFT): with
    ``Δn = 1/P`` for a period ``P >= max(length, 10/n_min)``,

    .. math:: z(x) = \\sum_k \\sqrt{2 G_d(n_k) Δn}\\, \\cos(2\\pi n_k x + φ_k),
              \\quad n_k = kΔn \\in [n_{min}, n_{max}]

    with phases φ_k uniform on [0, 2π). Its one-sided PSD is ``Gd`` on the
    band (ISO 8608:2016, Annex F; Cebon, *Handbook of Vehicle-Road
    Interaction*, ch. 3) and zero outside it. The period is at least ten
    of the longest wavelengths, so the band's low end holds ten harmonics.
    """
    N, amplitude = _harmonics(length, dx, road_class, band)
    phase = np.random.default_rng(_seed(seed)).uniform(0, 2 * np.pi, amplitude.size)
    return _synthesise(N, dx, length, amplitude, np.exp(1j * phase))


def _seed(seed) -> int:
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    return int(seed)


def _harmonics(length, dx, road_class, band) -> tuple[int, np.ndarray]:
    """The period ``N`` samples and the harmonics' amplitudes ``sqrt(2 Gd(n_k) Δn)``
    (zero outside the band) of `iso8608_profile`, at ``n_k = k/(N dx)``."""
    length, dx = positive("length", length, "m"), positive("dx", dx, "m")
    lo, hi = band_limits(band)
    g0 = road_class_psd(road_class)
    if dx > 1 / (2 * hi):
        raise ValueError(
            f"dx = {dx!r} m is too coarse for the band up to {hi!r} cycles/m: "
            f"it must be <= 1/(2 n_max) = {1 / (2 * hi):.4g} m"
        )
    N = int(math.ceil(max(length, 10.0 / lo) / dx)) + 1  # (N - 1) dx >= length
    N += N % 2
    dn = 1.0 / (N * dx)
    n = np.arange(N // 2 + 1) * dn
    # the Nyquist bin is left out: irfft would halve its amplitude
    inside = (n >= lo) & (n <= hi) & (np.arange(n.size) < N // 2)
    amplitude = np.zeros_like(n)
    amplitude[inside] = np.sqrt(2 * g0 * (n[inside] / ISO8608_N0) ** -2.0 * dn)
    return N, amplitude


def _synthesise(N: int, dx: float, length: float, amplitude: np.ndarray, unit: np.ndarray):
    """``x, z`` up to ``length`` of ``Σ A_k |u_k| cos(2π n_k x + arg u_k)`` (inverse FFT)."""
    z = np.fft.irfft(0.5 * N * amplitude * unit, n=N)
    x = np.arange(N) * dx
    keep = x <= length + 1e-9 * length
    return x[keep], z[keep]


def iso8608(
    T, road_class: str = "C", speed: float = 20.0, seed: int = 0, band=ISO8608_BAND
) -> np.ndarray:
    """A random ISO 8608 road driven at ``speed`` [m/s], sampled at ``T`` [s].

    The profile of `iso8608_profile` with ``x = speed · (t - T[0])``. The
    time grid must resolve the band at this speed: every step of ``T`` at
    most `largest_step` ``= 1/(2 v n_max)`` (8.8 ms at 20 m/s for the
    standard band). Narrow ``band`` to use a coarser grid.

    Examples
    --------
    >>> import numpy as np
    >>> T = np.linspace(0, 10, 2001)
    >>> zr = iso8608(T, "C", speed=20.0, seed=1)
    >>> zr.shape, bool(np.all(zr == iso8608(T, "C", speed=20.0, seed=1)))
    ((2001,), True)
    """
    T = _grid(T)
    x, dx, lo, hi = _distance_grid(T, speed, band)
    xp, zp = iso8608_profile(max(x[-1], dx), dx, road_class, seed, (lo, hi))
    return np.interp(x, xp, zp)


def _distance_grid(T: np.ndarray, speed, band) -> tuple[np.ndarray, float, float, float]:
    """``x = v (t - T[0])``, the profile spacing ``dx`` and the band, once the grid
    is checked to resolve the band at ``speed`` (`iso8608`, `iso8608_tracks`)."""
    speed = positive("speed", speed, "m/s")
    lo, hi = band_limits(band)
    dt = float(np.max(np.diff(T)))
    limit = largest_step(speed, (lo, hi))
    if dt > limit * (1 + 1e-12):
        raise ValueError(
            f"T's step {dt:.4g} s is too coarse for an ISO 8608 road at {speed:g} m/s: it "
            f"samples the road every {speed * dt:.4g} m, but the band up to {hi:g} cycles/m "
            f"needs a step <= {limit:.4g} s (or a narrower band)"
        )
    x = speed * (T - T[0])
    # The profile's spacing follows the grid's span and mean step, never its
    # smallest gap: a uniform grid samples the profile exactly at its points,
    # and a non-uniform one (every step within the limit, checked above)
    # interpolates it linearly between samples at most 1/(2 n_max) apart.
    mean = float(T[-1] - T[0]) / (T.size - 1)
    step = uniform_step(T)
    dx = speed * (step if step is not None else mean)
    samples = max(x[-1], 10.0 / lo) / dx
    check_memory(
        samples * 8 * 6,
        f"an ISO 8608 profile of {samples:.3g} samples",
        "use a shorter or coarser time grid",
    )
    return x, dx, lo, hi


def delay(T, zr, tau: float) -> np.ndarray:
    """The input ``zr`` delayed by ``tau`` [s] on the grid ``T``: ``zr(t - tau)``.

    The rear wheel of a car at speed ``V`` meets the front wheel's road
    ``tau = (a + b)/V`` later. When ``tau`` is a whole number of steps of a
    uniform grid the samples are shifted exactly; otherwise ``zr`` is read
    between its samples by linear interpolation, the meaning python-control
    gives an input (linear between samples). Before ``T[0] + tau`` the road
    keeps its first value (a level road before the start).

    Examples
    --------
    >>> T = np.arange(6) * 0.1
    >>> delay(T, np.arange(6.0), 0.2).tolist()
    [0.0, 0.0, 0.0, 1.0, 2.0, 3.0]
    >>> delay(T, np.arange(6.0), 0.25).round(12).tolist()
    [0.0, 0.0, 0.0, 0.5, 1.5, 2.5]
    """
    T = _grid(T)
    zr = np.asarray(zr, dtype=float)
    if zr.shape != T.shape or not np.all(np.isfinite(zr)):
        raise ValueError(f"zr must be {T.size} finite samples on T, got shape {zr.shape}")
    tau = finite("tau", tau, "s")
    if tau < 0:
        raise ValueError(f"tau must be >= 0 s (a delay), got {tau!r}")
    h = uniform_step(T)
    if h is not None:
        m = round(tau / h)
        if abs(m * h - tau) <= 1e-9 * h:  # a whole number of steps: shift the samples
            out = np.full_like(zr, zr[0])
            if m < zr.size:
                out[m:] = zr[: zr.size - m]
            return out
    return np.interp(T - tau, T, zr, left=zr[0])


def axle_inputs(T, zr, wheelbase: float, speed: float) -> np.ndarray:
    """``(2, N)``: the road ``zr`` under the front wheel and, ``wheelbase/speed``
    later, under the rear one (`delay`); the inputs ``[zr_front, zr_rear]``
    of ``half_car(road=True)``."""
    tau = positive("wheelbase", wheelbase, "m") / positive("speed", speed, "m/s")
    if not math.isfinite(tau):
        raise ValueError(
            f"the rear wheel's delay wheelbase/speed = {wheelbase!r} m / {speed!r} m/s "
            "overflows; give a car's wheelbase (metres) and a speed it drives (m/s)"
        )
    return np.vstack([np.asarray(zr, dtype=float), delay(T, zr, tau)])


def corner_inputs(T, left, right, wheelbase: float, speed: float) -> np.ndarray:
    """``(4, N)``: the left and right tracks under the front wheels and, delayed
    by ``wheelbase/speed``, under the rear ones; the inputs ``[zr_fl, zr_fr,
    zr_rl, zr_rr]`` of ``full_car(road=True)``."""
    front_left, rear_left = axle_inputs(T, left, wheelbase, speed)
    front_right, rear_right = axle_inputs(T, right, wheelbase, speed)
    return np.vstack([front_left, front_right, rear_left, rear_right])


def isotropic_coherence(n, track: float) -> np.ndarray:
    """Cross-spectrum over spectrum of two parallel tracks ``track`` [m] apart.

    For an isotropic road surface whose single-track PSD is ISO 8608's
    ``Gd(n) ∝ n⁻²`` (waviness 2), the two tracks' cross-spectral density is
    real and

    .. math:: \\frac{G_{lr}(n)}{G_d(n)} = 2\\pi n B\\, K_1(2\\pi n B)

    (``K_1`` the modified Bessel function of the second kind; Dodds and
    Robson, "The description of road surface roughness", *J. Sound Vib.*
    31(2), 1973; Cebon, *Handbook of Vehicle-Road Interaction*, 1999,
    ch. 3). It is 1 at ``n = 0`` (long waves lift both wheels together) and
    falls to 0.5 near ``n ≈ 0.3/B``. The coherence is its square.

    Notes
    -----
    An isotropic surface whose 2-D spectrum is ``S(k) = (C/2) k⁻³`` has the
    track spectrum ``∫ S(√(n²+m²)) dm = C n⁻²`` and the cross-spectrum
    ``∫ S(√(n²+m²)) cos(2πmB) dm = C (2πB/n) K_1(2πnB)``.
    """
    n = np.asarray(n, dtype=float)
    if np.any(n < 0) or not np.all(np.isfinite(n)):
        raise ValueError("n must be finite spatial frequencies >= 0 cycles/m")
    x = 2 * np.pi * n * positive("track", track, "m")
    with np.errstate(invalid="ignore"):
        return np.where(x > 0, x * scipy.special.k1(np.maximum(x, 1e-300)), 1.0)


def iso8608_profiles(
    length: float,
    dx: float,
    track: float,
    road_class: str = "C",
    seed: int = 0,
    band=ISO8608_BAND,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Left and right tracks ``track`` [m] apart of one isotropic ISO 8608 road.

    Returns ``x, left, right``. The left track is `iso8608_profile` with the
    same arguments (the same seed gives the same left track); each harmonic
    of the right one is ``ρ(n)`` times the left's plus ``√(1-ρ²)`` times an
    independent one of the same amplitude,

    .. math:: c^R_k = A_k\\big(ρ(n_k) e^{iφ_k} + \\sqrt{1-ρ(n_k)^2}\\, e^{iψ_k}\\big)

    so both tracks have the PSD ``Gd`` and their cross-spectrum is
    ``ρ(n)·Gd(n)`` with ``ρ`` the `isotropic_coherence`.
    """
    N, amplitude = _harmonics(length, dx, road_class, band)
    seed = _seed(seed)
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi, amplitude.size)
    other = np.random.default_rng([seed, 1]).uniform(0, 2 * np.pi, amplitude.size)
    rho = isotropic_coherence(np.arange(amplitude.size) / (N * dx), track)
    left = np.exp(1j * phase)
    right = rho * left + np.sqrt(1 - rho**2) * np.exp(1j * other)
    x, zl = _synthesise(N, dx, length, amplitude, left)
    _, zr = _synthesise(N, dx, length, amplitude, right)
    return x, zl, zr


def iso8608_tracks(
    T,
    road_class: str = "C",
    speed: float = 20.0,
    track: float = 1.5,
    seed: int = 0,
    band=ISO8608_BAND,
) -> np.ndarray:
    """``(2, N)``: the left and right tracks of a random ISO 8608 road at ``speed``.

    `iso8608_profiles` driven at ``speed`` [m/s] and sampled at ``T`` as
    `iso8608` samples one track (the left track is `iso8608`'s road). Give
    them to `corner_inputs` for a full car's four wheels.
    """
    T = _grid(T)
    x, dx, lo, hi = _distance_grid(T, speed, band)
    xp, zl, zr = iso8608_profiles(max(x[-1], dx), dx, track, road_class, seed, (lo, hi))
    return np.vstack([np.interp(x, xp, zl), np.interp(x, xp, zr)])


def iso8608_iri(road_class: str = "C", band=None) -> float:
    """The expected IRI [m/km] of an ISO 8608 road class, from its spectrum.

    The stroke velocity of the Golden Car on a Gaussian road is Gaussian,
    so its mean absolute value is ``σ √(2/π)``, with

    .. math:: σ^2 = \\int |H(j 2π n V)|^2\\, \\mathrm{sinc}^2(n L)\\, G_d(n)\\, dn

    over the class's band of spatial frequencies ``n`` [cycles/m]: ``H`` is the
    road-to-stroke-velocity response, ``sinc(nL)`` the 250 mm moving average
    and ``G_d(n) = G_d(n_0) (n/n_0)^{-2}`` the class's displacement PSD
    (ISO 8608; `iso8608_psd`). The IRI of a long profile of
    the class (`iso8608_profile`) scatters about it.

    Parameters
    ----------
    road_class : {'A', ..., 'H'}
    band : (float, float), optional
        Spatial frequencies [cycles/m]; default `ISO8608_BAND`.

    Examples
    --------
    >>> round(iso8608_iri("A") * 4, 6) == round(iso8608_iri("C"), 6)  # 4x the RMS
    True
    """
    low, high = band_limits(ISO8608_BAND if band is None else band)
    n = np.geomspace(low, high, 4000)
    A, B, C = golden_car_matrices()
    s = 2j * np.pi * n * IRI_SPEED
    rhs = np.broadcast_to(B, (n.size, 4, 1))
    H = (C @ np.linalg.solve(s[:, None, None] * np.eye(4) - A, rhs))[:, 0, 0]
    integrand = np.abs(H) ** 2 * np.sinc(n * SMOOTHING_BASE) ** 2 * iso8608_psd(n, road_class)
    variance = float(np.sum(np.diff(n) * (integrand[1:] + integrand[:-1]) / 2))
    return 1000.0 * math.sqrt(variance) * math.sqrt(2 / math.pi) / IRI_SPEED
