"""The International Roughness Index of a measured road profile (ASTM E1926).

The IRI is a quarter car: the Golden Car, whose parameters per unit sprung
mass are ``ku/ms = 653 s⁻²``, ``ks/ms = 63.3 s⁻²``, ``cs/ms = 6.0 s⁻¹`` and
``mu/ms = 0.15`` (Sayers, *On the calculation of International Roughness
Index from longitudinal road profile*, TRR 1501, 1995), driven at 80 km/h
over the profile smoothed by a 250 mm moving average, and started with both
masses moving with the profile's mean slope over its first 11 m. The IRI is
the suspension stroke accumulated per distance travelled, in m/km
(equivalently mm/m): the mean of ``|x_s' - x_u'| / V``.

The car is stepped exactly (`qc_control.numerics.exact`) with the smoothed
profile linear between samples, which is ASTM E1926's own assumption (its
input is the slope, constant over each sample interval).

Examples
--------
>>> import numpy as np
>>> x = np.arange(0, 200, 0.05)
>>> iri(x, 0.002 * x) < 1e-9   # a straight ramp: no stroke, IRI 0 (to rounding)
True
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..numerics.exact import exact_outputs

__all__ = [
    "iri",
    "IRISegments",
    "GOLDEN_CAR",
    "IRI_SPEED",
    "golden_car_matrices",
]

#: The Golden Car per unit sprung mass (ASTM E1926, Sayers 1995).
GOLDEN_CAR = {"ku/ms": 653.0, "ks/ms": 63.3, "cs/ms": 6.0, "mu/ms": 0.15}
#: The simulated speed [m/s]: 80 km/h.
IRI_SPEED = 80.0 / 3.6
#: The base length of the moving average [m] (ASTM E1926, 250 mm).
SMOOTHING_BASE = 0.25
#: The length [m] over which the initial slope is taken (ASTM E1926, 11 m).
INITIAL_LENGTH = 11.0
#: The longest sample interval [m] ASTM E1926 accepts (300 mm), and the one
#: from which the smoothing no longer works at all (Sayers' code refuses 1 m).
LONGEST_INTERVAL, REFUSED_INTERVAL = 0.3, 1.0
#: An IRI above this [m/km] is no road's (a rough unpaved road is ~20): the
#: profile is probably in millimetres.
IMPLAUSIBLE_IRI = 50.0


def nint(value: float) -> int:
    """Fortran's NINT, as ASTM E1926 and Sayers' code count samples: the nearest
    integer, halves away from zero (Python's ``round`` takes 2.5 to 2)."""
    # the 1e-9 absorbs a quotient such as 0.25/0.1 landing a hair below the half
    return int(math.floor(abs(value) + 0.5 + 1e-9)) * (1 if value >= 0 else -1)


def golden_car_matrices() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``A, B`` of the Golden Car with states ``[zs, zs', zu, zu']`` and input
    the road height, and ``C`` giving the stroke velocity ``zs' - zu'``."""
    k1, k2 = GOLDEN_CAR["ku/ms"], GOLDEN_CAR["ks/ms"]
    c, mu = GOLDEN_CAR["cs/ms"], GOLDEN_CAR["mu/ms"]
    A = np.array(
        [
            [0.0, 1.0, 0.0, 0.0],
            [-k2, -c, k2, c],
            [0.0, 0.0, 0.0, 1.0],
            [k2 / mu, c / mu, -(k1 + k2) / mu, -c / mu],
        ]
    )
    B = np.array([[0.0], [0.0], [0.0], [k1 / mu]])
    C = np.array([[0.0, 1.0, 0.0, -1.0]])
    return A, B, C


@dataclass(frozen=True)
class IRISegments:
    """The IRI per segment of a profile.

    Attributes
    ----------
    start, end : ndarray
        Each segment's first and last position [m].
    iri : ndarray
        Each segment's IRI [m/km].
    overall : float
        The IRI of the whole profile [m/km]: the segments' values averaged
        with their lengths as weights.
    """

    start: np.ndarray
    end: np.ndarray
    iri: np.ndarray
    overall: float


def _check_profile(x, profile) -> tuple[np.ndarray, np.ndarray, float]:
    x = np.asarray(x, dtype=float)
    z = np.asarray(profile, dtype=float)
    if x.ndim != 1 or z.shape != x.shape:
        raise ValueError(
            f"x and profile must be 1-D of one length, got shapes {x.shape} and {z.shape}"
        )
    for name, v in (("x", x), ("profile", z)):
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValueError(f"{name} is not finite at row {bad[0]}")
    if x.size < 3:
        raise ValueError(f"the profile needs at least 3 samples, got {x.size}")
    dx = np.diff(x)
    if np.any(dx <= 0):
        i = int(np.argmax(dx <= 0)) + 1
        raise ValueError(f"x must increase: x[{i}] = {x[i]!r} after x[{i - 1}] = {x[i - 1]!r}")
    step = (x[-1] - x[0]) / (x.size - 1)
    if np.max(np.abs(dx - step)) > 1e-6 * step + 1e-9:
        i = int(np.argmax(np.abs(dx - step))) + 1
        raise ValueError(
            f"the IRI needs a uniform sample interval (ASTM E1926); x[{i}] - x[{i - 1}] = "
            f"{dx[i - 1]:.6g} m against {step:.6g} m: resample the profile"
        )
    if step >= REFUSED_INTERVAL:
        raise ValueError(
            f"the profile's sample interval is {step:.6g} m: the IRI needs at most "
            f"{LONGEST_INTERVAL:g} m (ASTM E1926), and at {REFUSED_INTERVAL:g} m or more it "
            "misses the wavelengths it weighs most"
        )
    if step > LONGEST_INTERVAL:
        warnings.warn(
            f"the profile's sample interval is {step:.6g} m, over ASTM E1926's "
            f"{LONGEST_INTERVAL:g} m: the IRI misses short wavelengths and reads low",
            stacklevel=3,
        )
    if x[-1] - x[0] < INITIAL_LENGTH:
        raise ValueError(
            f"the profile is {x[-1] - x[0]:.6g} m long: the IRI needs more than its "
            f"{INITIAL_LENGTH:g} m start"
        )
    return x, z, float(step)


def _stroke_slopes(z: np.ndarray, dx: float) -> np.ndarray:
    """``|zs' - zu'| / V`` at each sample of the smoothed profile after the first."""
    k = max(1, nint(SMOOTHING_BASE / dx))
    # the moving average of k samples (ASTM's slope over the base length is its rate)
    cumulative = np.concatenate([[0.0], np.cumsum(z)])
    smooth = (cumulative[k:] - cumulative[:-k]) / k
    a = min(nint(INITIAL_LENGTH / dx), smooth.size - 1)
    slope0 = (smooth[a] - smooth[0]) / (a * dx)
    A, B, C = golden_car_matrices()
    # both masses moving with the mean slope, springs undeflected (ASTM E1926, 8.3)
    x0 = np.array([smooth[0], IRI_SPEED * slope0, smooth[0], IRI_SPEED * slope0])
    stroke = exact_outputs(A, B, C, np.zeros((1, 1)), dx / IRI_SPEED, smooth[None, :], x0)[0]
    return np.abs(stroke[1:]) / IRI_SPEED


def iri(x, profile, *, segment: float | None = None) -> float | IRISegments:
    """The International Roughness Index [m/km] of a longitudinal profile.

    Parameters
    ----------
    x : array_like, shape (N,)
        Positions along the road [m], uniformly spaced (ASTM E1926 asks for
        an interval of 300 mm or less; 250 mm or less keeps the smoothing).
    profile : array_like, shape (N,)
        The profile's elevation [m].
    segment : float, optional
        A segment length [m]: the IRI of each consecutive segment (the last
        one may be shorter) instead of the whole profile's.

    Returns
    -------
    float or IRISegments
        The IRI [m/km] (numerically mm/m).

    Raises
    ------
    ValueError
        For a non-finite value, x not increasing or not uniform (naming the
        row), a sample interval of 1 m or more, a profile shorter than 11 m,
        or a segment shorter than the sample interval.

    Warns
    -----
    UserWarning
        For a sample interval over ASTM's 0.3 m (the IRI reads low), and an
        IRI over 50 m/km (a profile in millimetres, most likely).

    Notes
    -----
    The moving average spans ``NINT(0.25 m / dx)`` samples and the initial
    slope ``NINT(11 m / dx)``, with NINT rounding halves up as ASTM E1926 and
    Sayers' code do: at dx = 0.1 m the base is 3 samples (0.3 m), not 2.
    """
    x, z, dx = _check_profile(x, profile)
    if segment is not None:
        # checked before the work: a segment shorter than a sample would make one
        # bin per sample at best, and a tiny one terabytes of empty bins
        segment = float(segment)
        if not math.isfinite(segment) or segment < dx:
            raise ValueError(
                f"segment must be a length of at least the sample interval {dx:.6g} m, "
                f"got {segment!r}"
            )
    slopes = _stroke_slopes(z, dx)
    overall = float(1000.0 * np.mean(slopes))
    if overall > IMPLAUSIBLE_IRI:
        warnings.warn(
            f"IRI {overall:.4g} m/km is more than any road's (a rough unpaved road is about "
            "20): is the profile in millimetres? Elevations are in metres (--z-scale 0.001 "
            "converts mm)",
            stacklevel=2,
        )
    if segment is None:
        return overall
    # each stroke sample belongs to the interval that ends at it
    position = dx * np.arange(1, slopes.size + 1)
    index = np.minimum((position - 1e-9 * dx) // segment, np.inf).astype(int)
    count = np.bincount(index)
    total = np.bincount(index, weights=slopes)
    keep = count > 0
    starts = x[0] + segment * np.flatnonzero(keep)
    ends = np.minimum(starts + segment, x[0] + position[-1])
    return IRISegments(starts, ends, 1000.0 * total[keep] / count[keep], overall)
