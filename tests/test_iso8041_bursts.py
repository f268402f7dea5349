"""ISO 8041-1:2017's saw-tooth signal bursts through qc's ISO 2631-1 weightings.

ISO 8041-1 (human-vibration meters) clause 5.9 defines a test signal (its
Table 6, Figure 3) and prints, in Tables 8 and 9, what a conforming meter
reads when the signal passes each weighting: the weighted RMS over the
measurement, the VDV, the MTVV (1 s linear running RMS, ISO 2631-1 6.3.1)
and, for Wf, the MSDV. The standard states the values come from a digital
simulation of the filters, and grades a meter within 10 % (12 % for the VDV).

The signal: a bipolar saw-tooth of amplitude 1 m/s² (a linear rise from 0 to
+1, a vertical fall to -1, a rise back to 0), each burst starting and ending at
an upward zero crossing; bursts of 1, 2, 4, 8 and 16 cycles repeated from a
start time, and a continuous row that fills the measurement from t = 0.

What is under test is the weighting chain (`qc.weighted`, exact sampled
filters, zero initial state); the four indications are their textbook
formulas, written here: RMS ``(1/T ∫ a_w² dt)^½``, VDV ``(∫ a_w⁴ dt)^¼``,
MTVV ``max_t (1/τ ∫_{t-τ}^t a_w² dt)^½`` with τ = 1 s, MSDV
``(∫ a_w² dt)^½``.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

import qc_control as qc

#: ISO 8041-1:2017 Table 6: angular frequency [rad/s], first burst [s], repeat
#: time [s], measurement duration [s], per application.
WHOLE_BODY = (100.0, 1.0, 10.0, 60.0)
LOW_FREQUENCY = (2.5, 40.0, 400.0, 2400.0)

#: ISO 8041-1:2017 Table 8 (whole body), per weighting and burst length (None:
#: continuous): weighted RMS [m/s²], VDV [m/s^1.75], linear MTVV [m/s²].
TABLE_8 = {
    "Wc": {
        1: (0.0222, 0.244, 0.0703),
        2: (0.0292, 0.275, 0.0923),
        4: (0.0397, 0.318, 0.126),
        8: (0.055, 0.374, 0.174),
        16: (0.077, 0.445, 0.243),
        None: (0.24, 0.788, 0.243),
    },
    "Wd": {
        1: (0.00669, 0.0779, 0.0212),
        2: (0.00906, 0.0852, 0.0286),
        4: (0.0116, 0.0923, 0.0366),
        8: (0.0148, 0.101, 0.0469),
        16: (0.0197, 0.115, 0.0611),
        None: (0.059, 0.197, 0.0611),
    },
    "We": {
        1: (0.00342, 0.0409, 0.0108),
        2: (0.00478, 0.0452, 0.0151),
        4: (0.00637, 0.0493, 0.0201),
        8: (0.00816, 0.0535, 0.0255),
        16: (0.0102, 0.0592, 0.0311),
        None: (0.0295, 0.0987, 0.0311),
    },
    "Wj": {
        1: (0.0435, 0.517, 0.138),
        2: (0.0616, 0.609, 0.195),
        4: (0.0874, 0.723, 0.277),
        8: (0.124, 0.859, 0.392),
        16: (0.175, 1.02, 0.554),
        None: (0.554, 1.81, 0.555),
    },
    "Wk": {
        1: (0.0299, 0.323, 0.0944),
        2: (0.0411, 0.38, 0.13),
        4: (0.0577, 0.455, 0.182),
        8: (0.0814, 0.543, 0.257),
        16: (0.115, 0.648, 0.363),
        None: (0.362, 1.15, 0.364),
    },
}

#: ISO 8041-1:2017 Table 9 (low-frequency whole body, Wf): weighted RMS
#: [m/s²] and MSDV [m/s^1.5].
TABLE_9 = {
    1: (0.0197, 0.9651),
    2: (0.0236, 1.156),
    4: (0.0304, 1.489),
    8: (0.0416, 2.038),
    16: (0.0571, 2.797),
    None: (0.176, 8.622),
}

#: Sampling rates [Hz]: a saw-tooth's vertical fall is one sample, which
#: 8041-1 12.13 allows when shorter than 1/(5 f2) (2 ms for the 100 Hz band
#: limit, 0.3 s for Wf's 0.63 Hz); 5 kHz and 200 Hz are ten times that.
RATE_WHOLE_BODY = 5000.0
RATE_LOW_FREQUENCY = 200.0

#: The printed values have three or four significant figures (0.5 % at worst,
#: "0.0102"), and the sampled ideal saw-tooth differs from the standard's
#: simulation by a few tenths of a per cent. Measured: 34 of the 36 cells
#: within 1.1 %; two rows read low, We at 8 cycles (RMS -2.0 %) and Wf at 2
#: cycles (RMS -2.3 %), while their neighbours in the same column are within
#: 0.6 %, which points at the printed cells. 2.5 % holds all of them, four
#: times tighter than the standard's 10 % (12 % for the VDV) for a meter.
RTOL = 0.025


@functools.lru_cache(maxsize=16)
def sawtooth_bursts(application: tuple, rate: float, cycles: int | None):
    """Table 6's signal on a uniform grid: (T, acceleration [m/s²])."""
    omega, start, repeat, duration = application
    T = np.arange(round(duration * rate) + 1) / rate
    period = 2 * math.pi / omega
    if cycles is None:  # the continuous row starts at t = 0 and fills the record
        return T, 2 * ((T / period + 0.5) % 1.0) - 1
    acc = np.zeros_like(T)
    for t0 in np.arange(start, duration, repeat):
        on = (t0 <= T) & (T < t0 + cycles * period)
        acc[on] = 2 * (((T[on] - t0) / period + 0.5) % 1.0) - 1
    return T, acc


def indications(aw: np.ndarray, dt: float) -> dict[str, float]:
    """RMS, VDV, 1 s linear MTVV and MSDV of a weighted record (rectangle rule)."""
    square = np.concatenate([[0.0], np.cumsum(aw**2) * dt])
    window = round(1.0 / dt)
    running = np.sqrt((square[window:] - square[:-window]) / 1.0)
    return {
        "rms": math.sqrt(square[-1] / (aw.size * dt)),
        "vdv": float(np.sum(aw**4) * dt) ** 0.25,
        "mtvv": float(running.max()),
        "msdv": math.sqrt(square[-1]),
    }


@pytest.mark.parametrize("cycles", [1, 2, 4, 8, 16, None])
@pytest.mark.parametrize("name", sorted(TABLE_8))
def test_whole_body_bursts_read_as_iso_8041_table_8(name, cycles):
    T, acc = sawtooth_bursts(WHOLE_BODY, RATE_WHOLE_BODY, cycles)
    got = indications(qc.weighted(acc, T, name), T[1] - T[0])
    rms, vdv, mtvv = TABLE_8[name][cycles]
    assert got["rms"] == pytest.approx(rms, rel=RTOL)
    assert got["vdv"] == pytest.approx(vdv, rel=RTOL)
    assert got["mtvv"] == pytest.approx(mtvv, rel=RTOL)


@pytest.mark.parametrize("cycles", [1, 2, 4, 8, 16, None])
def test_low_frequency_bursts_read_as_iso_8041_table_9(cycles):
    T, acc = sawtooth_bursts(LOW_FREQUENCY, RATE_LOW_FREQUENCY, cycles)
    got = indications(qc.weighted(acc, T, "Wf"), T[1] - T[0])
    rms, msdv = TABLE_9[cycles]
    assert got["rms"] == pytest.approx(rms, rel=RTOL)
    assert got["msdv"] == pytest.approx(msdv, rel=RTOL)
