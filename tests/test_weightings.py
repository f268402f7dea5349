"""ISO 2631-1:1997 Annex A's frequency weightings (qc.weighting, qc.weighted).

References, independent of the code:
- Annex A's formulas written out here, evaluated at s = j2πf with Table A.2's
  parameters as printed;
- the standard's Table 3 (the weighting factors ×1000 at one-third-octave
  frequencies) for Wk and Wd;
- closed forms on sines: over whole periods after the filter's start-up,
  ``a_w = |W(f)| A/√2``.
"""

from __future__ import annotations

import math
import re

import control
import numpy as np
import pytest

import qc_control as qc

#: ISO 2631-1:1997 Table A.2 as printed: f1, f2, f3, f4, Q4, f5, Q5, f6, Q6 (None: ∞).
TABLE_A2 = {
    "Wk": (0.4, 100, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    "Wd": (0.4, 100, 2.0, 2.0, 0.63, None, None, None, None),
    "Wf": (0.08, 0.63, None, 0.25, 0.86, 0.0625, 0.80, 0.1, 0.80),
    "Wc": (0.4, 100, 8.0, 8.0, 0.63, None, None, None, None),
    "We": (0.4, 100, 1.0, 1.0, 0.63, None, None, None, None),
    "Wj": (0.4, 100, None, None, None, 3.75, 0.91, 5.32, 0.91),
}


def annex_a(name: str, f: float) -> float:
    """|W(j2πf)| from Annex A's equations (A.1)-(A.4), term by term."""
    f1, f2, f3, f4, q4, f5, q5, f6, q6 = TABLE_A2[name]
    s = 2j * math.pi * f
    w = lambda fi: 2 * math.pi * fi  # noqa: E731
    q = 1 / math.sqrt(2)
    hh = s**2 / (s**2 + w(f1) * s / q + w(f1) ** 2)
    hl = w(f2) ** 2 / (s**2 + w(f2) * s / q + w(f2) ** 2)
    ht = 1.0
    if f4 is not None:
        ht = (1 + (s / w(f3) if f3 is not None else 0)) / (1 + s / (q4 * w(f4)) + s**2 / w(f4) ** 2)
    hs = 1.0
    if f5 is not None:
        hs = (s**2 + w(f5) * s / q5 + w(f5) ** 2) / (s**2 + w(f6) * s / q6 + w(f6) ** 2)
    return abs(hh * hl * ht * hs)


#: The nominal one-third-octave frequencies 0.02 ... 100 Hz (IEC 61260's base-10 series).
THIRD_OCTAVES = [10 ** (k / 10) for k in range(-17, 21)]


@pytest.mark.parametrize("name", list(TABLE_A2))
def test_each_weighting_is_annex_as_formula_at_every_third_octave(name):
    """Within 0.2 % (the issue's bar; measured: rounding, ~1e-12 relative)."""
    W = qc.weighting(name)
    for f in THIRD_OCTAVES:
        assert abs(W(2j * math.pi * f)) == pytest.approx(annex_a(name, f), rel=2e-3), f


#: ISO 2631-1:1997 Table 3, factors ×1000.
TABLE_3 = {
    "Wk": {0.5: 418, 1.0: 482, 2.0: 531, 4.0: 967, 8.0: 1036, 16.0: 768},
    "Wd": {0.5: 853, 1.0: 1011, 2.0: 890, 4.0: 512, 8.0: 253},
}


@pytest.mark.parametrize("name", list(TABLE_3))
def test_the_standards_printed_factors(name):
    """To one unit of Table 3's last digit (its rounding)."""
    W = qc.weighting(name)
    for f, factor in TABLE_3[name].items():
        assert 1000 * abs(W(2j * math.pi * f)) == pytest.approx(factor, abs=1.0), f


def test_a_weighting_is_a_named_transfer_function_of_acceleration():
    W = qc.weighting("wd")  # case aside
    assert isinstance(W, control.TransferFunction) and W.name == "Wd"
    assert W.input_labels == ["acc"] and W.output_labels == ["acc_Wd"]
    assert qc.weighting("Wk") is qc.wk_filter()  # the one Wk, the metrics' too


@pytest.mark.parametrize(
    "name, f",
    [("Wk", 4.0), ("Wd", 1.0), ("Wc", 6.3), ("We", 0.8), ("Wj", 8.0), ("Wf", 0.16)],
)
def test_a_weighted_sine_has_the_closed_form_rms(name, f):
    """``a_w = |W(f)| A/√2`` over whole periods after the start-up (the slowest
    pole's transient, f1 = 0.4 Hz (Wf: 0.08 Hz, so 60 s), left out: 20 of its
    time constants). The samples' linear interpolation changes |W| by
    (2πf·dt)²/12 (3e-5 at 4 Hz, dt = 2 ms); 2 % is the issue's bar (measured
    below 1e-3)."""
    settle = 60.0 if name == "Wf" else 12.0
    periods = math.ceil(40 * f) / f if name != "Wf" else math.ceil(200 * f) / f
    dt = 0.002 if name != "Wf" else 0.05
    T = np.arange(0.0, settle + periods + dt / 2, dt)
    A = 0.8
    y = qc.weighted(A * np.sin(2 * math.pi * f * T), T, name)
    tail = y[T >= settle]
    rms = math.sqrt(np.mean(tail[:-1] ** 2))
    assert rms == pytest.approx(annex_a(name, f) * A / math.sqrt(2), rel=2e-2)


def test_wk_in_the_time_domain_is_pythoncontrols_forced_response():
    """weighted(..., 'Wk') is control.forced_response of the filter (an input
    linear between samples, zero state): within 1e-12 of its peak."""
    T = np.linspace(0.0, 5.0, 2501)
    a = np.sin(2 * math.pi * 3 * T) + 0.3 * np.sign(np.sin(2 * math.pi * 0.7 * T))
    for name in ("Wk", "Wd", "Wj"):
        exact = control.forced_response(qc.weighting(name), T, a).outputs
        np.testing.assert_allclose(qc.weighted(a, T, name), exact, atol=1e-12 * np.abs(exact).max())


@pytest.mark.parametrize("name", ["Wx", "", "k"])
def test_an_unknown_weighting_is_refused(name):
    words = f"weighting must be one of ISO 2631-1's Wk, Wd, Wf, Wc, We, Wj, got {name!r}"
    with pytest.raises(ValueError, match=re.escape(words)):
        qc.weighting(name)
    with pytest.raises(ValueError, match=re.escape(words)):
        qc.weighted(np.zeros(3), [0.0, 0.001, 0.002], name)


@pytest.mark.parametrize(
    ("call", "name", "value"),
    [
        (lambda: qc.weighting("Wx"), "weighting", "Wx"),
        (lambda: qc.weighted(np.zeros(10), np.linspace(0.0, 2.0, 201), "Wk"), "acc", (10,)),
        # Wk reaches 12.5 Hz: 50 ms samples (Nyquist 10 Hz) cannot hold it
        (lambda: qc.weighted(np.zeros(3), [0.0, 0.05, 0.1], "Wk"), "T", 0.05),
        (lambda: qc.weighted(np.zeros(4), [0.0, 0.001, 0.003, 0.004], "Wk"), "T", None),
    ],
)
def test_refusals_are_the_parameter_error_naming_the_value(call, name, value):
    """Issue 41: every bad input refused by name, through qc.ParameterError
    (these were bare ValueErrors, with no .name for a program to read)."""
    with pytest.raises(qc.ParameterError) as info:
        call()
    assert info.value.name == name
    if isinstance(value, float):
        assert info.value.value == pytest.approx(value, rel=1e-12)  # the grid's own step
    elif value is not None:
        assert info.value.value == value


def test_a_non_finite_sample_is_the_parameter_error_naming_it():
    nan = np.r_[0.0, 0.0, 0.0, np.nan, np.zeros(197)]
    with pytest.raises(qc.ParameterError, match="acc is not finite at sample 3") as info:
        qc.weighted(nan, np.linspace(0.0, 2.0, 201), "Wk")
    assert info.value.name == "acc" and np.isnan(info.value.value)


def test_bad_signals_are_refused_by_name():
    T = np.linspace(0.0, 2.0, 201)  # dt = 10 ms: Nyquist 50 Hz
    with pytest.raises(ValueError, match="acc is not finite at sample 3"):
        qc.weighted(np.r_[0.0, 0.0, 0.0, np.nan, np.zeros(197)], T, "Wk")
    with pytest.raises(ValueError, match="one sample per time of T"):
        qc.weighted(np.zeros(10), T, "Wk")
    coarse = np.linspace(0.0, 10.0, 101)  # dt = 0.1 s: Nyquist 5 Hz, below Wk's 12.5 Hz
    with pytest.raises(
        ValueError, match="dt = 0.1 s is too coarse for Wk: its band reaches 12.5 Hz"
    ):
        qc.weighted(np.zeros(101), coarse, "Wk")
    with pytest.raises(ValueError, match="uniform"):
        qc.weighted(np.zeros(3), [0.0, 0.1, 0.3], "Wd")
