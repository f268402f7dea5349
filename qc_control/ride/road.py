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

import functools
import inspect
import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np
import scipy.special

from ..numerics import checks
from ..numerics.checks import ParameterError
from ..numerics.integrate import check_time_grid, uniform_step
from ..numerics.limits import check_memory
from .roughness import IRI_SPEED, SMOOTHING_BASE, IRISegments, golden_car_matrices, iri

__all__ = [
    "Road",
    "NoRoad",
    "Step",
    "Bump",
    "Sine",
    "ISO8608Road",
    "Profile",
    "ROADS",
    "as_road",
    "road_parameter",
    "iso8608_intensity",
    "BUMP_STEPS",
    "SINE_STEPS",
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


#: The checks of a road's numbers (`qc_control.numerics.checks`): one wording
#: everywhere a road is given, a `ParameterError` naming the value.
positive = checks.positive
finite = checks.finite


def _step_height(t, height, t0):
    """``height`` where ``t >= t0``, else 0: the one formula of a step road."""
    return np.where(t >= t0, height, 0.0)


def _bump_height(t, height, length, speed, t0):
    """The one formula of a 1 − cos bump, for an array of times or one time."""
    x = speed * (t - t0)
    inside = (x >= 0) & (x <= length)
    return np.where(inside, 0.5 * height * (1 - np.cos(2 * np.pi * x / length)), 0.0)


def _sine_height(t, amplitude, frequency):
    """The one formula of a sine road, for an array of times or one time."""
    return amplitude * np.sin(2 * np.pi * frequency * t)


def step(T, height: float = 0.05, t0: float = 0.5) -> np.ndarray:
    """A road step of ``height`` [m] at time ``t0`` [s] (a kerb).

    ``zr = height`` for ``t >= t0``, else 0. Between the two samples around
    ``t0`` the input is a ramp, as python-control interpolates it.
    """
    T = _grid(T)
    return _step_height(T, finite("height", height, "m"), finite("t0", t0, "s"))


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
    return _bump_height(T, height, length, speed, t0)


def sine(T, amplitude: float = 0.01, frequency: float = 1.0) -> np.ndarray:
    """A sinusoidal road ``zr = amplitude · sin(2π f t)`` [m], f in Hz."""
    T = _grid(T)
    amplitude = finite("amplitude", amplitude, "m")
    return _sine_height(T, amplitude, positive("frequency", frequency, "Hz"))


def road_class_psd(road_class: str) -> float:
    """Gd(n0) [m³] of an ISO 8608 class ``'A'`` ... ``'H'`` (any case), `ISO8608_CLASSES`."""
    key = road_class.strip().upper() if isinstance(road_class, str) else None
    if key not in ISO8608_CLASSES:
        raise ParameterError(
            "road_class", road_class, f"an ISO 8608 class, one of {', '.join(ISO8608_CLASSES)}"
        )
    return ISO8608_CLASSES[key]


def band_limits(band) -> tuple[float, float]:
    """``(n_min, n_max)`` [cycles/m] of a band, refused unless ``0 < n_min < n_max < inf``."""
    try:
        lo, hi = (float(b) for b in band if not isinstance(b, (bool, str)))
        ok = 0 < lo < hi and math.isfinite(hi)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ParameterError("band", band, "(n_min, n_max) with 0 < n_min < n_max cycles/m")
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
    return checks.integer("seed", seed, minimum=0)


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


def iso8608_intensity(road_class, speed: float) -> float:
    """White road-velocity intensity [m²/s] of an ISO 8608 road at ``speed`` [m/s].

    .. math:: q = 2 π^2 n_0^2 G_d(n_0)\\, v

    The displacement PSD ``Gd(n) = Gd(n0)(n/n0)^-2`` (one-sided, spatial)
    gives the road velocity ``v dz/dx`` a one-sided temporal PSD
    ``(2πf)² Gd(f/v)/v = 4π² n0² Gd(n0) v``, flat in ``f``: white noise of
    two-sided intensity ``q`` (ISO 8608:2016; Gobbi & Mastinu, 2001).

    Parameters
    ----------
    road_class : str or float
        A class ``'A'`` ... ``'H'`` (its geometric mean ``Gd(n0)``), or
        ``Gd(n0)`` [m³] itself.
    speed : float
        Vehicle speed [m/s], > 0.

    Examples
    --------
    >>> round(iso8608_intensity("C", 20.0), 6)
    0.001011
    """
    if isinstance(road_class, str):
        g0 = road_class_psd(road_class)
    else:
        g0 = positive("road_class", road_class, "m³", description="Gd(n0)")
    v = positive("speed", speed, "m/s")
    return 2.0 * math.pi**2 * ISO8608_N0**2 * g0 * v


# ----------------------------------------------------------------- the road
#
# One road concept: a `Road` is a frozen value that every API taking a road
# takes (the studies, the sweeps, the nonlinear car, the controller study,
# `Scenario` and the command line). Its numbers are written once, in the
# functions above; a kind only holds its parameters and reads them there.


def road_parameter(default, check: str, unit: str, help: str, option: str | None = None):
    """A field of a `Road` kind with what the command line and a Scenario read of it.

    Its default, its kind of check (``'finite'``, ``'positive'``, ``'class'``,
    ``'seed'``, ``'band'``; the first two are checked by `Road`, the others by
    their kind), its SI unit, its help and its command-line option (None:
    ``--road-<name>``).
    """
    return field(
        default=default, metadata={"check": check, "unit": unit, "help": help, "option": option}
    )


def _default(func, name: str):
    """The default of ``func``'s argument ``name``: a kind's defaults are its function's."""
    return inspect.signature(func).parameters[name].default


#: How `Road` checks a field by its declared kind of check.
_CHECKS = {"finite": checks.finite, "positive": checks.positive}
#: One speed default for every road that has a speed: `iso8608`'s.
_SPEED = _default(iso8608, "speed")
#: The fewest steps a bump may span: a 1 − cos pulse over fewer falls between
#: the samples (0.05 m at 30 m/s lasts 1.7 ms: at h = 10 ms every method saw
#: no bump at all). Four steps put three samples on it.
BUMP_STEPS = 4
#: The fewest steps per period of a sine road: ten, a fifth of the Nyquist
#: frequency 1/(2h). At the Nyquist frequency itself the samples can all be
#: zero; at a fifth of it linear interpolation between them is within 5 % of
#: the amplitude (1 − cos(π/10)), where the methods' stages read the input.
SINE_STEPS = 10
#: Help of the parameters that step and bump share.
_HEIGHT, _T0 = "step or bump height", "time the step or bump starts"


def _length_text(metres: float) -> str:
    """A road height for a sentence: '10 cm', '1.5 m'."""
    return f"{metres * 100:.4g} cm" if abs(metres) < 1 else f"{metres:.4g} m"


@dataclass(frozen=True)
class Road:
    """A road under the wheels: the base of every kind.

    Each kind (`Step`, `Bump`, `Sine`, `ISO8608Road`, `Profile`) is a frozen
    dataclass whose fields are its parameters, named and defaulted as the
    keyword arguments of its function in this module (`step`, `bump`, ...),
    so that ``Step(height=h, t0=t).samples(T)`` is ``step(T, h, t)`` to the
    bit. A road is also the function ``zr(t)`` of one time (``road(t)``,
    `height_at`), which the nonlinear car reads at every stage. A bad value
    is refused by `qc_control.ParameterError` naming the field.
    """

    kind: ClassVar[str] = "none"
    #: The road in a sentence's words: "a bump road".
    noun: ClassVar[str] = "no road"
    #: What to change in the road when a grid cannot resolve it.
    finer: ClassVar[str] = ""

    def __post_init__(self):
        for f in fields(self):
            name = f.metadata.get("check")
            check = _CHECKS.get(name) if name is not None else None
            if check is not None:
                value = check(f.name, getattr(self, f.name), f.metadata["unit"])
                object.__setattr__(self, f.name, value)

    def params(self) -> dict[str, Any]:
        """The parameters as a dict, in field order (without ``kind``)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def samples(self, T) -> np.ndarray | None:
        """The road height zr [m] on the time grid ``T`` [s]; None for no road."""
        return None

    def height_at(self, t: float) -> float:
        """The road height zr [m] at one time ``t`` [s]: the number `samples` gives at ``t``.

        The kinds evaluate their one formula at the single time (the same
        NumPy operations, so the same bits as the array's element); this
        fallback samples a grid of two times.
        """
        zr = self.samples(np.array([t, t + 1.0]))
        return 0.0 if zr is None else float(np.asarray(zr)[0])

    def __call__(self, t: float) -> float:
        """``zr(t)`` [m]: the road as a function of time (`height_at`)."""
        return self.height_at(t)

    @property
    def jumps(self) -> tuple[float, ...]:
        """The times [s] where the road height jumps; () for a continuous road."""
        return ()

    def describe(self) -> str:
        """The road in words, from its actual parameters; '' for no road."""
        return ""

    def largest_step(self) -> float:
        """The largest time step [s] that samples this road; inf if any step does."""
        return math.inf

    def sampled(self) -> str:
        """What `largest_step` samples, in words."""
        return self.noun

    def wheel_inputs(
        self, T, layout: str = "single", *, wheelbase=None, track=None
    ) -> tuple[np.ndarray | None, str]:
        """``(inputs on T, description)`` for a car whose wheels meet this road.

        ``layout`` is a model's `ModelEntry.road_layout`: ``'single'`` (one
        wheel: ``zr``), ``'axles'`` (``[zr_front, zr_rear]``, the rear a
        wheelbase later: `axle_inputs`) or ``'corners'`` (``[zr_fl, zr_fr,
        zr_rl, zr_rr]``: `corner_inputs`, both tracks the same road).

        Parameters
        ----------
        T : array_like
            Time grid [s].
        layout : {'single', 'axles', 'corners'}
        wheelbase, track : float, optional
            The car's ``a + b`` and front track [m], for the later layouts.
        """
        checks.choice("layout", layout, ("single", "axles", "corners"))
        zr, description = self.samples(T), self.describe()
        if zr is None or layout == "single":
            return zr, description
        speed = getattr(self, "speed", None)
        if speed is None:
            raise ParameterError(
                "road",
                self,
                f"a road with a speed (a Bump, an ISO8608Road or a Profile): the rear wheels "
                f"meet the road (a + b)/speed after the front ones, and {self.noun} has none",
            )
        wheelbase = positive("wheelbase", wheelbase, "m")
        late = f"; the rear wheels {wheelbase / speed:.4g} s later ((a + b)/speed)"
        if layout == "axles":
            return axle_inputs(T, zr, wheelbase, speed), description + late
        left, right, tracks = self._tracks(T, zr, positive("track", track, "m"))
        return corner_inputs(T, left, right, wheelbase, speed), description + tracks + late

    def _tracks(self, T, zr: np.ndarray, track: float) -> tuple[np.ndarray, np.ndarray, str]:
        """The left and right tracks ``track`` [m] apart: both this road, unless a kind
        knows how its two tracks differ (`ISO8608Road`)."""
        return zr, zr, ""


@dataclass(frozen=True)
class NoRoad(Road):
    """No road input: the free response from ``x0``."""


@dataclass(frozen=True)
class Step(Road):
    """A road step (a kerb) of ``height`` [m] at ``t0`` [s]: `step`."""

    kind: ClassVar[str] = "step"
    noun: ClassVar[str] = "a step road"
    height: float = road_parameter(_default(step, "height"), "finite", "m", _HEIGHT)
    t0: float = road_parameter(_default(step, "t0"), "finite", "s", _T0)

    def samples(self, T) -> np.ndarray:
        return step(T, height=self.height, t0=self.t0)

    def height_at(self, t: float) -> float:
        return float(_step_height(t, self.height, self.t0))

    @property
    def jumps(self) -> tuple[float, ...]:
        return (self.t0,)

    def describe(self) -> str:
        return f"a {_length_text(self.height)} road step at t = {self.t0:g} s"


@dataclass(frozen=True)
class Bump(Road):
    """A 1 − cos bump ``height`` [m] high and ``length`` [m] long, met at ``t0`` [s]: `bump`.

    Its speed defaults to the ISO 8608 road's (`iso8608`), so that every
    road with a speed has the same default; `bump`'s own default is not used.
    """

    kind: ClassVar[str] = "bump"
    noun: ClassVar[str] = "a bump road"
    finer: ClassVar[str] = "a longer bump or a lower speed"
    height: float = road_parameter(_default(bump, "height"), "finite", "m", _HEIGHT)
    length: float = road_parameter(_default(bump, "length"), "positive", "m", "bump length")
    speed: float = road_parameter(_SPEED, "positive", "m/s", "vehicle speed", "--speed")
    t0: float = road_parameter(_default(bump, "t0"), "finite", "s", _T0)

    def samples(self, T) -> np.ndarray:
        return bump(T, height=self.height, length=self.length, speed=self.speed, t0=self.t0)

    def height_at(self, t: float) -> float:
        return float(_bump_height(t, self.height, self.length, self.speed, self.t0))

    def describe(self) -> str:
        # a negative height is a pothole: "a -5 cm high bump" reads as a typo
        shape = (
            f"a {_length_text(-self.height)} deep, {self.length:g} m long 1 − cos pothole"
            if self.height < 0
            else f"a {_length_text(self.height)} high, {self.length:g} m long 1 − cos bump"
        )
        return f"{shape} met at t = {self.t0:g} s at {self.speed:g} m/s"

    def largest_step(self) -> float:
        """The bump's duration length/speed over `BUMP_STEPS`."""
        return self.length / self.speed / BUMP_STEPS

    def sampled(self) -> str:
        return (
            f"a {self.length:g} m bump at {self.speed:g} m/s, which lasts "
            f"{1e3 * self.length / self.speed:.3g} ms and needs {BUMP_STEPS} steps across it"
        )


@dataclass(frozen=True)
class Sine(Road):
    """A sinusoidal road ``zr = amplitude · sin(2π f t)`` [m], f in Hz: `sine`."""

    kind: ClassVar[str] = "sine"
    noun: ClassVar[str] = "a sine road"
    finer: ClassVar[str] = "a lower frequency"
    amplitude: float = road_parameter(_default(sine, "amplitude"), "finite", "m", "sine amplitude")
    frequency: float = road_parameter(
        _default(sine, "frequency"), "positive", "Hz", "sine frequency"
    )

    def samples(self, T) -> np.ndarray:
        return sine(T, amplitude=self.amplitude, frequency=self.frequency)

    def height_at(self, t: float) -> float:
        return float(_sine_height(t, self.amplitude, self.frequency))

    def describe(self) -> str:
        return (
            f"a sinusoidal road, {_length_text(self.amplitude)} amplitude at {self.frequency:g} Hz"
        )

    def largest_step(self) -> float:
        """One period over `SINE_STEPS`: a fifth of the Nyquist frequency 1/(2h)."""
        return 1.0 / (self.frequency * SINE_STEPS)

    def sampled(self) -> str:
        return (
            f"a {self.frequency:g} Hz sine road, which needs {SINE_STEPS} steps per period "
            f"(at most a fifth of the Nyquist frequency 1/(2h))"
        )


_ISO_DEFAULTS = inspect.signature(iso8608).parameters


@dataclass(frozen=True)
class ISO8608Road(Road):
    """A random ISO 8608 road driven at a constant speed: sampled for a simulation,
    or, for exact spectral metrics, white road velocity of its intensity.

    Over the unbounded band (waviness 2) it is white road velocity of
    intensity `iso8608_intensity` ``= 2π² n0² Gd(n0) v``: give it to
    `qc_control.sweep` as ``road=`` for a spectral sweep (no simulation), or
    to `qc_control.optimal_damping`. Its `samples` on a time grid are
    `iso8608`'s, and it is the ``iso8608`` road of a `qc_control.Scenario`.

    Parameters
    ----------
    road_class : str or float, default 'C'
        ``'A'`` ... ``'H'`` (any case), or ``Gd(n0)`` [m³] (spectral only:
        a sampled road needs a class).
    speed : float, default 20
        [m/s], > 0.
    seed : int, default 0
        The random phases' seed (>= 0) of the sampled road.
    band : (float, float), default `ISO8608_BAND`
        The sampled road's band ``(n_min, n_max)`` [cycles/m].

    Raises
    ------
    qc_control.ParameterError
        A bad value, naming the field.

    Examples
    --------
    >>> round(ISO8608Road("C", speed=20.0).intensity, 6)
    0.001011
    """

    kind: ClassVar[str] = "iso8608"
    noun: ClassVar[str] = "an iso8608 road"
    finer: ClassVar[str] = "a narrower band"

    road_class: str | float = road_parameter(
        _ISO_DEFAULTS["road_class"].default, "class", "", "ISO 8608 class A-H", "--road-class"
    )
    speed: float = road_parameter(
        _ISO_DEFAULTS["speed"].default, "positive", "m/s", "vehicle speed", "--speed"
    )
    seed: int = road_parameter(_ISO_DEFAULTS["seed"].default, "seed", "", "road seed", "--seed")
    band: tuple[float, float] = road_parameter(
        _ISO_DEFAULTS["band"].default, "band", "cycles/m", "ISO 8608 band n_min,n_max"
    )

    def __post_init__(self):
        super().__post_init__()
        put = functools.partial(object.__setattr__, self)
        cls = self.road_class
        if isinstance(cls, str):
            road_class_psd(cls)
            put("road_class", cls.strip().upper())
        else:
            put("road_class", positive("road_class", cls, "m³", description="Gd(n0)"))
        put("seed", _seed(self.seed))
        put("band", band_limits(self.band))

    @property
    def intensity(self) -> float:
        """White road-velocity intensity ``q`` [m²/s] (`iso8608_intensity`)."""
        return iso8608_intensity(self.road_class, self.speed)

    def samples(self, T) -> np.ndarray:
        """The road height zr [m] on the time grid ``T`` [s] (`iso8608`)."""
        if not isinstance(self.road_class, str):
            raise ParameterError(
                "road_class",
                self.road_class,
                "a class A-H to sample a road (Gd(n0) in m³ is a spectral road only)",
            )
        return iso8608(T, self.road_class, speed=self.speed, seed=self.seed, band=self.band)

    def describe(self) -> str:
        """The road in words, from its actual parameters.

        A class's road also states its expected International Roughness
        Index (`iso8608_iri` over the road's band): the road engineer's
        measure of the same roughness, independent of the speed driven.
        """
        lo, hi = self.band
        roughness = ""
        if isinstance(self.road_class, str):
            roughness = f", expected IRI {iso8608_iri(self.road_class, self.band):.3g} m/km"
        return (
            f"an ISO 8608 class {self.road_class} road at {self.speed:g} m/s "
            f"(seed {self.seed}, band {lo:g}–{hi:g} cycles/m{roughness})"
        )

    def largest_step(self) -> float:
        """The largest time step [s] that samples the band (`largest_step`)."""
        return largest_step(self.speed, self.band)

    def sampled(self) -> str:
        return (
            f"an ISO 8608 road at {self.speed:g} m/s, whose band reaches {self.band[1]:g} cycles/m"
        )

    def _tracks(self, T, zr: np.ndarray, track: float) -> tuple[np.ndarray, np.ndarray, str]:
        left, right = iso8608_tracks(
            T, str(self.road_class), self.speed, track, self.seed, self.band
        )
        return left, right, f", left and right tracks {track:g} m apart (isotropic road)"


@dataclass(frozen=True, eq=False)
class Profile(Road):
    """A measured road profile ``z(x)`` driven at a constant ``speed``.

    The wheel is at ``x = x[0] + speed · (t - t0)`` at time ``t``; the height
    between the profile's points is linear (as a profilometer's record is
    read), and before the first point or after the last the road keeps that
    point's height (level road).

    .. math:: z_r(t) = z\\big(x_0 + v (t - t_0)\\big)

    Parameters
    ----------
    x : array_like
        Distance along the road [m], strictly increasing, at least two points.
    z : array_like
        Road height [m] at ``x``.
    speed : float, default 20
        [m/s], > 0.
    t0 : float, default 0
        Time [s] at which the wheel is at ``x[0]``.
    name : str, default ''
        What the profile is ("the rig's measured track"), for `describe`.

    Examples
    --------
    >>> import numpy as np
    >>> p = Profile([0.0, 1.0, 2.0], [0.0, 0.01, 0.0], speed=1.0)
    >>> p.samples(np.array([0.0, 0.5, 1.0, 3.0])).tolist()
    [0.0, 0.005, 0.01, 0.0]
    """

    kind: ClassVar[str] = "profile"
    noun: ClassVar[str] = "a measured profile"
    finer: ClassVar[str] = "a lower speed"

    x: Any = road_parameter((), "profile", "m", "distance along the profile")
    z: Any = road_parameter((), "profile", "m", "profile height")
    speed: float = road_parameter(_SPEED, "positive", "m/s", "vehicle speed", "--speed")
    t0: float = road_parameter(0.0, "finite", "s", "time the wheel is at the first point")
    name: str = road_parameter("", "text", "", "what the profile is")

    def __post_init__(self):
        super().__post_init__()
        x, z = _profile_arrays(self.x, self.z)
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "z", z)
        if not isinstance(self.name, str):
            raise ParameterError("name", self.name, "a str")

    def samples(self, T) -> np.ndarray:
        T = _grid(T)
        return np.interp(self.x[0] + self.speed * (T - self.t0), self.x, self.z)

    def height_at(self, t: float) -> float:
        return float(np.interp(self.x[0] + self.speed * (t - self.t0), self.x, self.z))

    def describe(self) -> str:
        what = self.name or f"a measured {self.x[-1] - self.x[0]:g} m profile"
        return (
            f"{what} ({self.x.size} points, every {self._spacing() * 100:.3g} cm at the closest) "
            f"driven at {self.speed:g} m/s from t = {self.t0:g} s"
        )

    def _spacing(self) -> float:
        return float(np.min(np.diff(self.x)))

    def largest_step(self) -> float:
        """The time the wheel takes between the profile's two closest points:
        a coarser step would skip measured points."""
        return self._spacing() / self.speed

    def sampled(self) -> str:
        return (
            f"a profile measured every {self._spacing() * 100:.3g} cm at the closest, driven at "
            f"{self.speed:g} m/s"
        )


def _numbers(name: str, values, what: str) -> np.ndarray:
    """``values`` as a float array; a `ParameterError` naming ``name`` (and, for a
    sequence, the first entry that is not a number) otherwise."""
    try:
        return np.array(values, dtype=float)
    except (TypeError, ValueError):
        pass
    try:
        for i, v in enumerate(values):
            try:
                float(v)
            except (TypeError, ValueError):
                raise ParameterError(f"{name}[{i}]", v, f"a number: {name} is {what}") from None
    except TypeError:  # not a sequence at all
        pass
    raise ParameterError(name, values, f"{what} as numbers")


def _profile_arrays(x, z) -> tuple[np.ndarray, np.ndarray]:
    """``x, z`` of a `Profile` as read-only float arrays, refused by name unless
    finite, of one length of at least two, and ``x`` strictly increasing."""
    xa, za = _numbers("x", x, "distances [m]"), _numbers("z", z, "heights [m]")
    if xa.ndim != 1 or xa.size < 2:
        raise ParameterError("x", x, "at least two distances [m] in a 1-D array")
    if za.shape != xa.shape:
        raise ParameterError("z", z, f"{xa.size} heights [m], one per distance x")
    for name, a in (("x", xa), ("z", za)):
        if not np.all(np.isfinite(a)):
            i = int(np.flatnonzero(~np.isfinite(a))[0])
            raise ParameterError(f"{name}[{i}]", a[i], "a finite number m")
    if np.any(np.diff(xa) <= 0):
        i = int(np.flatnonzero(np.diff(xa) <= 0)[0]) + 1
        raise ParameterError(f"x[{i}]", xa[i], f"a distance > x[{i - 1}] = {xa[i - 1]!r} m")
    xa.setflags(write=False)
    za.setflags(write=False)
    return xa, za


#: Every kind of road, by its ``kind``.
ROADS: dict[str, type[Road]] = {
    cls.kind: cls for cls in (NoRoad, Step, Bump, Sine, ISO8608Road, Profile)
}


def as_road(road, *, where: str = "road") -> Road:
    """``road`` if it is a `Road`; a `ParameterError` naming ``where`` otherwise."""
    if isinstance(road, Road):
        return road
    kinds = ", ".join(c.__name__ for c in ROADS.values() if c is not NoRoad)
    raise ParameterError(where, road, f"a qc_control.road.Road ({kinds})")
