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
    if x[-1] - x[0] < INITIAL_LENGTH:
        raise ValueError(
            f"the profile is {x[-1] - x[0]:.6g} m long: the IRI needs more than its "
            f"{INITIAL_LENGTH:g} m start"
        )
    return x, z, float(step)


def _stroke_slopes(z: np.ndarray, dx: float) -> np.ndarray:
    """``|zs' - zu'| / V`` at each sample of the smoothed profile after the first."""
    k = max(1, round(SMOOTHING_BASE / dx))
    # the moving average of k samples (ASTM's slope over the base length is its rate)
    cumulative = np.concatenate([[0.0], np.cumsum(z)])
    smooth = (cumulative[k:] - cumulative[:-k]) / k
    a = min(round(INITIAL_LENGTH / dx), smooth.size - 1)
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
        row), a profile shorter than 11 m, or a segment <= 0.
    """
    x, z, dx = _check_profile(x, profile)
    slopes = _stroke_slopes(z, dx)
    if segment is None:
        return float(1000.0 * np.mean(slopes))
    segment = float(segment)
    if not math.isfinite(segment) or segment <= 0:
        raise ValueError(f"segment must be a length > 0 [m], got {segment!r}")
    # each stroke sample belongs to the interval that ends at it
    position = dx * np.arange(1, slopes.size + 1)
    index = np.minimum((position - 1e-9 * dx) // segment, np.inf).astype(int)
    count = np.bincount(index)
    total = np.bincount(index, weights=slopes)
    keep = count > 0
    starts = x[0] + segment * np.flatnonzero(keep)
    ends = np.minimum(starts + segment, x[0] + position[-1])
    return IRISegments(
        starts, ends, 1000.0 * total[keep] / count[keep], float(1000.0 * np.mean(slopes))
    )
